//! The paper's case, the coarse blade with rigid tip contacts (fmu/scenes/blade-casing-rigid.toml):
//! with `steps = "auto"` a sweep across the first bending resonance (2 265 rad/s) solves and
//! certifies at every point; the same scene with cds at k = 512 is refused before solving with
//! the limit named (src/formulation.md §7: ω_max·h ≈ 3.2, 31 477 pivots and the pivot limit when tried).
use periodic_contact::periodic::{PeriodicSolver, SolveError};
use periodic_contact::scene::{Scene, SceneError};
use periodic_contact::sweep;
use std::path::Path;
use std::time::Instant;

fn scene_text() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-rigid.toml")).unwrap()
}

fn build(text: &str) -> Result<periodic_contact::periodic::PeriodicProblem, SceneError> {
    Scene::parse(text, "blade-casing-rigid.toml")?.build_in("blade-casing-rigid.toml", Path::new(".")).map(|b| b.problem)
}

/// Every point of a coarse sweep 2200–2400 rad/s solves; each answer is certified independently
/// (force ≥ 0, gap ≥ 0 and force·gap = 0 on the paired samples, gaps from the recovered motion).
#[test]
fn sweep_across_the_resonance_solves_and_certifies_every_point() {
    let mut p = build(&scene_text()).unwrap();
    assert!(p.steps_auto());
    let freqs = sweep::linspace(2200.0, 2400.0, 9);
    p.fit_auto_steps(2200.0, "test").unwrap();
    let k = p.discretization().steps;
    // Independent: ω_max·T/k ≤ 0.9·2 at the lowest frequency, and not at k/2.
    let h = |k: usize| 2.0 * std::f64::consts::PI / (2200.0 * k as f64);
    assert!(p.omega_max() * h(k) <= 1.8 && p.omega_max() * h(k / 2) > 1.8, "k = {k}, ω_max = {}", p.omega_max());
    let mut solver = PeriodicSolver::new(p.clone());
    let mut peak: (f64, f64) = (0.0, 0.0);
    for &w in &freqs {
        let t = Instant::now();
        solver.update_frequency(w).unwrap();
        let r = solver.solve().unwrap_or_else(|e| panic!("ω = {w}: {e}"));
        assert_eq!(r.lcp.status, "solved");
        let mut worst = 0.0f64;
        for (c, contact) in r.contacts.iter().zip(&p.model().contacts) {
            let s = p.pairing_of(contact).offset();
            for j in 0..k {
                let (z, g) = (c.force[j], c.gap[(j + s) % k]);
                worst = worst.max(z.min(g).abs()).max((-z).max(0.0)).max((-g).max(0.0));
            }
        }
        let scale = r.contacts.iter().flat_map(|c| c.gap.iter()).fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(worst <= 1e-8 * scale.max(1e-12), "ω = {w}: complementarity violated by {worst:e}");
        // The contact-free response of the same assembly: its peak is the linear resonance.
        let amp = r.linear_displacement.values().map(|x| periodic_contact::response::Response::peak_to_peak(x) / 2.0).fold(0.0, f64::max);
        if amp > peak.1 {
            peak = (w, amp);
        }
        println!("rigid blade ω = {w}: k = {k}, pivots {}, {:.3} s", r.lcp.pivots, t.elapsed().as_secs_f64());
    }
    // The sweep crosses the resonance: the linear peak is inside, not at an end.
    assert!(peak.0 > 2200.0 && peak.0 < 2400.0, "linear peak at {}", peak.0);
}

/// cds at k = 512 near resonance is refused before solving: the message names ω_max·h > 2 and
/// the smallest k (recomputed here from the ω_max it reports), and proposes the schemes that fit.
#[test]
fn cds_at_512_is_refused_with_the_limit_named() {
    let text = scene_text().replace("steps = \"auto\"", "steps = 512");
    let t = Instant::now();
    let msg = build(&text).unwrap_err().to_string();
    assert!(t.elapsed().as_secs_f64() < 30.0);
    let number = |after: &str| -> f64 {
        let rest = &msg[msg.find(after).unwrap_or_else(|| panic!("no {after:?} in {msg}")) + after.len()..];
        rest.split([' ', ';', ',']).next().unwrap().parse().unwrap()
    };
    let wmax = number("ω_max = ");
    let wh = number("give ω_max·h = ");
    assert!(wh > 2.0, "{msg}");
    let expected = wmax * 2.0 * std::f64::consts::PI / (2300.0 * 512.0);
    assert!((wh - expected).abs() < 1e-3 * expected, "{msg}");
    let k_min = (wmax * 2.0 * std::f64::consts::PI / (2300.0 * 2.0)).floor() as usize + 1;
    assert!(msg.contains(&format!("steps ≥ {k_min}")) && msg.contains("cds") && msg.contains("bds1"), "{msg}");
    // The typed error, as every front end sees it.
    let p = build(&scene_text()).unwrap();
    let mut p2 = p.clone();
    let disc = p.discretization();
    let e = p2.set_discretization(periodic_contact::time::Discretization { steps: 512, ..disc }).unwrap_err();
    assert!(matches!(e, SolveError::Limit(_)), "{e}");
}
