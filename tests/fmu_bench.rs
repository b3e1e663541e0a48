//! Performance figures (ignored by default; they print, they do not assert speed):
//!
//!   cargo build --release
//!   cargo test --release --test suite fmu_bench:: -- --ignored --nocapture --test-threads 1
//!
//! - `fmi2DoStep` throughput over 10⁶ steps of the packaged binary (and with `fmi2GetReal` of
//!   every output after each step);
//! - a re-solve after a small change of frequency, warm-started from the previous active set,
//!   against a cold solve of the same problem (library API with the reused FFT plan, and
//!   through the FMU: `fmi2ExitInitializationMode` vs the `fmi2DoStep` that re-solves).
use crate::common;

use common::host::*;
use periodic_contact::fmu_model::Tuning;
use periodic_contact::periodic::PeriodFft;
use periodic_contact::scene::Scene;
use std::path::Path;
use std::time::Instant;

fn scene_path(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes").join(name)
}

#[test]
#[ignore]
fn do_step_throughput() {
    println!("\nfmi2DoStep throughput, 10^6 steps, binary {}", fmu_binary().display());
    println!("{:<28} {:>7} {:>14} {:>10} {:>22}", "scene", "outputs", "steps/s", "ns/step", "with GetReal: steps/s");
    for (name, text) in [
        ("linear-2dof (cds)", std::fs::read_to_string(scene_path("linear-2dof.toml")).unwrap()),
        ("rigid-stop (cds)", std::fs::read_to_string(scene_path("rigid-stop.toml")).unwrap()),
        (
            "stop k_c=100 (fourier)",
            std::fs::read_to_string(scene_path("rigid-stop.toml"))
                .unwrap()
                .replace("\"cds\"", "\"fourier\"")
                .replace("[[contact]]\ndof = 0\ndirection = 1\ngap = 0.5", "[[contact]]\ndof = 0\ndirection = 1\ngap = 0.5\nstiffness = 100.0"),
        ),
        ("chain-3dof-two-stops", std::fs::read_to_string(scene_path("chain-3dof-two-stops.toml")).unwrap()),
    ] {
        let tag = name.split_whitespace().next().unwrap().to_string() + if name.contains("fourier") { "-fourier" } else { "" };
        let fmu = Fmu::package(&format!("bench-{tag}"), &text);
        let s = fmu.instantiate("bench").unwrap();
        s.init(0.0);
        let outputs: Vec<u32> = {
            let mut v: Vec<(u32, bool)> =
                fmu.vars.iter().filter(|(n, _)| fmu.xml.contains(&format!("name=\"{n}\""))).map(|(n, vr)| (*vr, is_real_output(&fmu.xml, n))).collect();
            v.sort();
            v.into_iter().filter(|(_, o)| *o).map(|(vr, _)| vr).collect()
        };
        let h = 1e-3;
        let n = 1_000_000;
        let mut t = 0.0;
        for i in 0..1000 {
            assert_eq!(s.step(i as f64 * h, h), OK);
        }
        t += 1000.0 * h;
        let start = Instant::now();
        for i in 0..n {
            if s.step(t + i as f64 * h, h) != OK {
                panic!("step {i} failed");
            }
        }
        let dt = start.elapsed().as_secs_f64();
        t += n as f64 * h;
        let mut values = vec![0.0; outputs.len()];
        let start = Instant::now();
        for i in 0..n {
            let st = s.step(t + i as f64 * h, h);
            let g = unsafe { (fmu.api.get_real)(s.c, outputs.as_ptr(), outputs.len(), values.as_mut_ptr()) };
            if st != OK || g != OK {
                panic!("step {i} failed");
            }
        }
        let dt2 = start.elapsed().as_secs_f64();
        println!("{:<28} {:>7} {:>14.0} {:>10.1} {:>22.0}", name, outputs.len(), n as f64 / dt, dt / n as f64 * 1e9, n as f64 / dt2);
    }
}

fn is_real_output(xml: &str, name: &str) -> bool {
    let i = xml.find(&format!("name=\"{name}\"")).unwrap();
    let tag = &xml[i..i + xml[i..].find("</ScalarVariable>").unwrap()];
    tag.contains("causality=\"output\"") && tag.contains("<Real")
}

fn best<T>(n: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..n {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed().as_secs_f64());
        last = Some(r);
    }
    (best, last.unwrap())
}

#[test]
#[ignore]
fn warm_started_re_solve_against_a_cold_solve() {
    println!("\nre-solve after frequency × (1 + δ): cold (no warm start) vs warm (previous active set), same FFT plan, sequential, best of 5");
    println!("{:<22} {:>5} {:>6} {:>10} {:>7} {:>10} {:>7} {:>5} {:>10}", "scene", "k·m", "δ", "cold [s]", "pivots", "warm [s]", "pivots", "used", "max|Δx|");
    for name in ["rigid-stop.toml", "compliant-stop.toml", "moving-obstacle.toml", "chain-3dof-two-stops.toml"] {
        let (scene, _) = Scene::load(&scene_path(name)).unwrap();
        let mut p = scene.to_problem(name).unwrap();
        p.set_parallel(false);
        let fft = PeriodFft::new(p.discretization().steps);
        let r0 = p.solve_with(&fft, None).unwrap();
        for delta in [1e-3, 1e-2] {
            let mut t = Tuning::of(&p);
            t.frequency *= 1.0 + delta;
            let q = t.apply(&p, p.discretization()).unwrap();
            let (cold_t, cold) = best(5, || q.solve_with(&fft, None).unwrap());
            let (warm_t, warm) = best(5, || q.solve_with(&fft, Some(&r0.active_set)).unwrap());
            let dx =
                cold.displacement.values().zip(warm.displacement.values()).flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs())).fold(0.0, f64::max);
            println!(
                "{:<22} {:>5} {:>6.0e} {:>10.5} {:>7} {:>10.5} {:>7} {:>5} {:>10.1e}",
                name.trim_end_matches(".toml"),
                cold.lcp.size,
                delta,
                cold_t,
                cold.lcp.pivots,
                warm_t,
                warm.lcp.pivots,
                warm.lcp.warm_start_used,
                dx
            );
        }
    }
    // Through the FMU: fmi2ExitInitializationMode (cold solve with assembly) against the
    // fmi2DoStep that re-solves after frequency × 1.001 (warm-started).
    let fmu = Fmu::package("bench-resolve", &std::fs::read_to_string(scene_path("rigid-stop.toml")).unwrap());
    let (mut init_t, mut step_t) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..5 {
        let s = fmu.instantiate("resolve").unwrap();
        assert_eq!(s.setup(0.0), OK);
        assert_eq!(s.enter(), OK);
        let t = Instant::now();
        assert_eq!(s.exit(), OK);
        init_t = init_t.min(t.elapsed().as_secs_f64());
        assert_eq!(s.set_real("frequency", 1.001), OK);
        let t = Instant::now();
        assert_eq!(s.step(0.0, 0.01), OK);
        step_t = step_t.min(t.elapsed().as_secs_f64());
    }
    println!("FMU rigid-stop: fmi2ExitInitializationMode (cold solve) {init_t:.5} s; fmi2DoStep re-solving after frequency 1 → 1.001 (warm) {step_t:.5} s");
}
