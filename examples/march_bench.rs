//! The periodic LCP against explicit time marching at EQUAL ACCURACY on one reduced scene at one ω
//! (issue 23): a reference orbit, then for each target error (relative to the largest output's
//! peak-to-peak amplitude) the cheapest run of each method that reaches it, end to end.
//!
//! - set-up: reading the CalculiX matrices and reducing, once (both methods need it);
//! - reference: the scene's policy (`scheme = "auto"`) at `REF_K` instants, polished by the
//!   event-fitted polish (exact to its Newton residual) when it succeeds, else the LCP at `REF_K`
//!   (its own Richardson estimate is printed: the reference's uncertainty);
//! - ours: `scheme_auto::solve_to_tolerance` at each tolerance (what `solve` with
//!   `scheme = "auto"` runs), cold;
//! - march: `marching::march` from rest (central differences, the stable step of the reduction
//!   and its multiples) at each N in `MARCH_N` and each periodicity-defect tolerance in
//!   `MARCH_TOL` (a tolerance ladder per N stops once the error no longer falls: the step is then
//!   the limit).
//!
//! Errors: max over the outputs and over the instants common to the run's grid and the
//! reference's of |x − x_ref|, divided by the reference's largest peak-to-peak amplitude.
//! Times: process CPU (user + system, /proc/self/stat) and wall.
//!
//! `cargo run --release --example march_bench -- SCENE OMEGA REF_K OURS_TOLS MARCH_N MARCH_TOL`
//! (lists comma-separated; MARCH_N entries `sN` mean N × the stable steps, rounded up to 256;
//! MARCH_N = `none` skips the march).
//! The scene must have `scheme = "auto"`. Driver: validation/march_bench.sh.
use periodic_contact::analysis::{polish, scheme_auto};
use periodic_contact::marching::{MarchSettings, march, stable_omega_max};
use periodic_contact::periodic::PeriodicProblem;
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;
use periodic_contact::time::Discretization;
use std::path::Path;
use std::time::Instant;

/// Process CPU time (all threads, user + system) [s], from /proc/self/stat (clock ticks of 10 ms).
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat");
    let after = &stat[stat.rfind(')').expect("stat format") + 2..];
    let f: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 of proc(5) are utime and stime; `after` starts at field 3.
    (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) / 100.0
}

fn list<T: std::str::FromStr>(s: &str) -> Vec<T> {
    s.split(',').filter(|x| !x.is_empty()).map(|x| x.parse().ok().expect("a number")).collect()
}

/// The displacement outputs of a response, in the problem's order.
fn lcp_outputs(p: &PeriodicProblem, r: &Response) -> Vec<Vec<f64>> {
    p.outputs().displacement.iter().map(|d| r.displacement[&d.to_string()].clone()).collect()
}

/// Max error over outputs and the instants common to `x` (n per period) and the reference (kr),
/// relative to the reference's largest peak-to-peak amplitude.
fn error(x: &[Vec<f64>], reference: &[Vec<f64>]) -> f64 {
    let (n, kr) = (x[0].len(), reference[0].len());
    let common = gcd(n, kr);
    assert!(common >= 64, "only {common} common instants between {n} and {kr}");
    let top = reference.iter().map(|r| Response::peak_to_peak(r)).fold(0.0, f64::max);
    let (s, sr) = (n / common, kr / common);
    x.iter().zip(reference).map(|(x, r)| (0..common).map(|j| (x[j * s] - r[j * sr]).abs()).fold(0.0, f64::max)).fold(0.0, f64::max) / top
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

#[path = "../src/bin/periodic-contact/malloc.rs"]
mod malloc;

fn main() {
    // Before any allocation of the set-up: the CLI's allocator settings, so the timings are the CLI's.
    malloc::keep_freed_memory();
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 7 {
        eprintln!("usage: march_bench SCENE OMEGA REF_K OURS_TOLS MARCH_N MARCH_TOL");
        std::process::exit(2);
    }
    let omega: f64 = a[2].parse().unwrap();
    let ref_k: usize = a[3].parse().unwrap();
    let ours_tols: Vec<f64> = list(&a[4]);
    let march_tols: Vec<f64> = list(&a[6]);

    let (c0, t0) = (cpu_s(), Instant::now());
    let (mut scene, dir) = Scene::load(Path::new(&a[1])).unwrap();
    scene.set_frequency(omega);
    let built = scene.build_in(&a[1], &dir).unwrap();
    let (setup_cpu, setup_wall) = (cpu_s() - c0, t0.elapsed().as_secs_f64());
    let base = built.problem;
    let target = built.accuracy_target.expect("the scene must have scheme = \"auto\"");
    let choice = built.scheme_choice.unwrap_or_default();
    let d = base.discretization();
    let tm = &built.timings;
    println!(
        "# scene {} omega {omega} setup cpu {setup_cpu:.2} s wall {setup_wall:.2} s (wall: structure read {:.2} s, reduction {:.2} s)",
        a[1], tm.structure, tm.reduction
    );
    println!("# auto: {:?} k0 = {} ({choice})", d.scheme, d.steps);

    // The reference.
    let (c0, t0) = (cpu_s(), Instant::now());
    let mut rp = base.clone();
    rp.set_discretization(Discretization { steps: ref_k, ..d }).unwrap();
    let mut rr = rp.solve().expect("reference LCP");
    let mut rr_est = periodic_contact::analysis::accuracy::estimate(&rp, &rr);
    let orbit = polish::apply(&rp, &mut rr);
    let status = rr.polish.as_ref().map(|p| format!("{} {} (residual {:.1e})", p.status, p.reason, p.residual)).unwrap_or_default();
    if orbit.is_some() {
        rr_est = rr.accuracy.clone();
    }
    let reference = lcp_outputs(&rp, &rr);
    let top = reference.iter().map(|r| Response::peak_to_peak(r)).fold(0.0, f64::max);
    println!(
        "# reference k = {ref_k}: polish {status}; estimate {:?}; p2p {top:.4e}; cpu {:.1} s wall {:.1} s",
        rr_est.estimate,
        cpu_s() - c0,
        t0.elapsed().as_secs_f64()
    );

    println!("method reduction_run target_or_setting k_or_N march_tol periods converged error cpu_s wall_s");
    for &tol in &ours_tols {
        let mut p = base.clone();
        let t = periodic_contact::periodic::limits::AccuracyTarget { tolerance: tol, ..target };
        let (c0, t0) = (cpu_s(), Instant::now());
        match scheme_auto::solve_to_tolerance(&mut p, &t, &choice) {
            Ok(r) => {
                let (cpu, wall) = (cpu_s() - c0, t0.elapsed().as_secs_f64());
                let e = error(&lcp_outputs(&p, &r), &reference);
                let met = r.scheme_choice.as_ref().is_some_and(|s| s.met);
                println!("ours auto tol={tol:.0e} {} - - met={met} {e:.3e} {cpu:.2} {wall:.2}", r.steps);
                if let Some(c) = r.scheme_choice.as_ref().filter(|c| !c.met) {
                    let tried: Vec<String> =
                        c.tried.iter().map(|t| format!("k={} est={:?} bound={:?} {:.2}s", t.steps, t.estimate, t.bound, t.seconds)).collect();
                    println!("#   not met: {}; tried {}", c.why, tried.join(", "));
                }
            }
            Err(e) => println!("ours auto tol={tol:.0e} - - - failed:{e} nan nan nan"),
        }
    }

    // Ours at the polished orbit's accuracy: `auto` at the loosest tolerance, then the polish.
    if let Some(&tol) = ours_tols.iter().fold(None, |m: Option<&f64>, t| Some(m.map_or(t, |m| if t > m { t } else { m }))) {
        let mut p = base.clone();
        let t = periodic_contact::periodic::limits::AccuracyTarget { tolerance: tol, ..target };
        let (c0, t0) = (cpu_s(), Instant::now());
        if let Ok(mut r) = scheme_auto::solve_to_tolerance(&mut p, &t, &choice) {
            let polished = polish::apply(&p, &mut r).is_some();
            let (cpu, wall) = (cpu_s() - c0, t0.elapsed().as_secs_f64());
            let e = error(&lcp_outputs(&p, &r), &reference);
            let how = r.polish.as_ref().map(|p| format!("{}:{}", p.status, p.reason.replace(' ', "_"))).unwrap_or_default();
            println!("ours auto+polish tol={tol:.0e} {} - - polished={polished}({how}) {e:.3e} {cpu:.2} {wall:.2}", r.steps);
        }
    }

    // MARCH_N = none: the set-up, the reference and ours only (the march's recorded figures stand).
    if a[5] == "none" {
        return;
    }
    let model = base.model();
    let wmax = stable_omega_max(model).unwrap();
    let period = 2.0 * std::f64::consts::PI / omega;
    let n_stable = (period * wmax / 2.0).ceil() as usize;
    println!("# march: omega_max {wmax:.4e} rad/s, stable N > {n_stable}");
    for n_arg in a[5].split(',') {
        let n = match n_arg.strip_prefix('s') {
            Some(f) => ((f.parse::<f64>().unwrap() * n_stable as f64).ceil() as usize).div_ceil(256) * 256,
            None => n_arg.parse().unwrap(),
        };
        let mut last = f64::INFINITY;
        for &mt in &march_tols {
            let s = MarchSettings { steps_per_period: n, max_periods: 20_000, tolerance: mt, ..Default::default() };
            let (c0, t0) = (cpu_s(), Instant::now());
            let m = match march(model, &s) {
                Ok(m) => m,
                Err(e) => {
                    println!("march explicit N={n} {n} {mt:.0e} - - failed:{e} nan nan");
                    break;
                }
            };
            let (cpu, wall) = (cpu_s() - c0, t0.elapsed().as_secs_f64());
            let xm: Vec<Vec<f64>> = base
                .outputs()
                .displacement
                .iter()
                .map(|d| {
                    let terms: Vec<(usize, f64)> = match base.output_map() {
                        Some(map) => map.rows[d].clone(),
                        None => vec![(*d, 1.0)],
                    };
                    m.displacement.iter().map(|x| terms.iter().map(|&(q, c)| c * x[q]).sum()).collect()
                })
                .collect();
            let e = error(&xm, &reference);
            println!("march explicit N={n} {n} {mt:.0e} {} {} {e:.3e} {cpu:.2} {wall:.2}", m.periods, m.converged);
            // The step limits the error once a tighter tolerance gains less than 20 %.
            if e > 0.8 * last {
                break;
            }
            last = e;
        }
    }
}
