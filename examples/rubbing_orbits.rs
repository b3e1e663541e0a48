//! The rubbing real blade's orbits at one frequency (validation/RECORD.md "Friction", issue 23): the sweep's
//! (walked up warm from 2270 rad/s, jumping the fold near 2278 rad/s by warm Newton from the
//! last orbit before it, as the sweep does) and the lone solve's (`auto`: its μ-homotopy and
//! frequency walk). For each: the flap amplitude (`6843:y`), the Floquet multipliers of the
//! discrete monodromy (`continuation::stability`, what `continue` reports), and the error
//! estimate's neighbour at k/2: warm shooting from the orbit's active set carried to k/2, then
//! cold shooting, each with its time.
//!
//! `cargo run --release --example rubbing_orbits -- SCENE [FREQUENCY]` (the scene's own ω by default)
use periodic_contact::analysis::{accuracy, continuation};
use periodic_contact::periodic::{PeriodicSolver, carried_active_set};
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;
use std::path::Path;
use std::time::Instant;

fn flap(r: &Response) -> f64 {
    // `6843:y` is the model DOF 20272.
    r.displacement.get("20272").map_or(f64::NAN, |s| Response::peak_to_peak(s) / 2.0)
}

/// Walks `session` up from `from` to `to` by `step`, halving a missed step down to 0.3 rad/s;
/// returns the last frequency solved.
fn walk_up(session: &mut PeriodicSolver, from: f64, to: f64, mut step: f64) -> f64 {
    let mut here = from;
    while step >= 0.3 && here < to {
        let next = (here + step).min(to);
        session.update_frequency(next).unwrap();
        match session.solve_by_shooting(true) {
            Ok(r) => {
                eprintln!("walk {next:.4} {:.9e}", flap(&r));
                here = next;
            }
            Err(_) => step /= 2.0,
        }
    }
    here
}

fn report(name: &str, session: &PeriodicSolver, r: &Response) {
    let problem = session.problem();
    println!("{name}: 6843:y amplitude {:.10e} m, {} active of N = {}", flap(r), r.active_set.len(), r.lcp.size);
    let t = Instant::now();
    match continuation::stability(problem, &r.active_set) {
        Ok(s) => {
            let top: Vec<String> = s.multipliers.iter().take(4).map(|m| format!("{:.6}{:+.6}i (|μ| {:.6})", m.re, m.im, m.norm())).collect();
            println!("{name}: Floquet largest |μ| = {:.6}, stable = {} ({:.1} s); leading: {}", s.largest, s.stable, t.elapsed().as_secs_f64(), top.join(", "));
        }
        Err(e) => println!("{name}: stability not computed: {e}"),
    }
    let Ok((second, note)) = accuracy::second_grid(problem, r) else { return println!("{name}: no second grid") };
    let k = problem.instants();
    let carried = carried_active_set(&r.active_set, r.lcp.size / k, k, second.instants());
    let mut s = PeriodicSolver::new(second);
    for warm in [true, false] {
        s.set_warm_start(&carried);
        let t = Instant::now();
        match s.solve_by_shooting(warm) {
            Ok(rs) => {
                println!("{name}: neighbour {note}, warm {warm}: solved in {:.1} s, 6843:y {:.6e}, {}", t.elapsed().as_secs_f64(), flap(&rs), rs.lcp.path)
            }
            Err(e) => println!("{name}: neighbour {note}, warm {warm}: missed in {:.1} s: {e}", t.elapsed().as_secs_f64()),
        }
    }
}

fn main() {
    let scene = std::env::args().nth(1).expect("SCENE");
    let (s, dir) = Scene::load(Path::new(&scene)).unwrap();
    let built = s.build_in(&scene, &dir).unwrap();
    let mut problem = built.problem;
    let at: f64 = std::env::args().nth(2).map_or(problem.model().frequency, |w| w.parse().unwrap());
    problem.set_parallel(false);
    let mut session = PeriodicSolver::new(problem.clone());
    // The sweep's route: the lower branch up to its fold, then warm Newton from its last orbit at
    // the next 5 rad/s points (the sweep's jump), then up the upper branch.
    session.update_frequency(2270.0).unwrap();
    session.solve_by_shooting(false).unwrap();
    let fold = walk_up(&mut session, 2270.0, 2300.0, 5.0);
    let near_fold = session.warm_start().unwrap().to_vec();
    // Warm Newton from the last orbit before the fold, else Newton from the contact-free orbit
    // (the guarded sweep's cold try), at points 1 rad/s apart, until one lands above the lower
    // branch's amplitude.
    session.update_frequency(fold).unwrap();
    let lower = flap(&session.solve_by_shooting(true).unwrap());
    let jump = (1..=22).map(|i| fold + f64::from(i)).find(|&w| {
        session.set_warm_start(&near_fold);
        session.update_frequency(w).unwrap();
        let r = session.solve_by_shooting(true).or_else(|_| session.solve_by_shooting_with(false, false));
        r.is_ok_and(|r| flap(&r) > 1.2 * lower)
    });
    eprintln!("lower branch to {fold:.4}, jumped at {jump:?}");
    let top = walk_up(&mut session, jump.expect("no jump"), at, 5.0);
    assert!(top == at, "the upper branch walk stopped at {top}");
    session.update_frequency(at).unwrap();
    let swept = session.solve_by_shooting(true).unwrap();
    report("sweep's orbit", &session, &swept);
    // The lone solve (cold, `auto`).
    let mut lone = PeriodicSolver::new(problem);
    lone.update_frequency(at).unwrap();
    let r = lone.solve().unwrap();
    println!("lone solve's path: {}", r.lcp.path);
    report("lone solve's orbit", &lone, &r);
}
