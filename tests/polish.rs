//! The event-fitted polish (`analysis::polish`) against the exact orbits of src/formulation.md §6
//! (`periodic_contact::exact`, independent closed-form references) at k = 256: within 1e-8 of
//! the peak-to-peak amplitude, in under a second each, and against long time integration on a
//! 2-DOF compliant chain (`periodic_contact::marching`).
use periodic_contact::analysis::polish;
use periodic_contact::exact::{CompliantStopOrbit, Oscillator, RigidRegime, RigidStopOrbit};
use periodic_contact::model::{Compliance, Contact};
use periodic_contact::periodic::{OutputSelection, PeriodicProblem, SolverSettings};
use periodic_contact::response::Response;
use periodic_contact::time::{Discretization, Scheme};
use std::time::Instant;

fn problem(osc: &Oscillator, contact: Contact, scheme: Scheme, k: usize) -> PeriodicProblem {
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![0], acceleration: vec![], contacts: true };
    PeriodicProblem::new(osc.model(vec![contact]), Discretization { scheme, steps: k, pairing: None }, outputs, SolverSettings::default()).unwrap()
}

/// Solves at k = 256, polishes, and returns (max error of x and of v at the t_j relative to the
/// peak-to-peak amplitude, wall time of solve + polish, the response).
fn polished(p: &PeriodicProblem, exact: impl Fn(f64) -> (f64, f64), ptp: f64) -> (f64, f64, f64, Response) {
    let t0 = Instant::now();
    let mut r = p.solve().unwrap();
    polish::apply(p, &mut r);
    let wall = t0.elapsed().as_secs_f64();
    let s = r.polish.as_ref().expect("polish ran");
    assert_eq!(s.status, "polished", "fell back: {}", s.reason);
    let (mut ex, mut ev) = (0.0f64, 0.0f64);
    for (j, &t) in r.time.iter().enumerate() {
        let (x, v) = exact(t);
        ex = ex.max((r.displacement["0"][j] - x).abs());
        ev = ev.max((r.velocity["0"][j] - v).abs());
    }
    (ex / ptp, ev / ptp, wall, r)
}

#[test]
fn rigid_stop_with_sticking_is_polished_to_1e_8() {
    let osc = Oscillator::new(1.0, 0.1, 1.0, 1.0, 1.0);
    let exact = RigidStopOrbit::solve(&osc, 0.5).unwrap();
    assert_eq!(exact.regime(), RigidRegime::Sticking);
    for scheme in [Scheme::Cds, Scheme::Bds1] {
        let p = problem(&osc, Oscillator::stop(0.5, Compliance::Rigid), scheme, 256);
        let (ex, ev, wall, r) = polished(&p, |t| (exact.eval(t).0, exact.eval(t).1), exact.peak_to_peak());
        // h·Σ force: the polished force samples are impulse per step divided by h.
        let impulse = r.impulse_per_period(0);
        let s = r.polish.unwrap();
        eprintln!("rigid+sticking {scheme}: x error {ex:.2e}, v error {ev:.2e} of ptp, {wall:.3} s, events {:?}", s.events);
        assert!(ex < 1e-8 && wall < 1.0, "{scheme}: x error {ex:.2e}, {wall:.3} s");
        assert!(s.events.iter().any(|e| e.kind == "release"), "a sticking arc");
        // The impulse per period (impact impulse + ∫ force over the arc) is the exact orbit's.
        let rel = (impulse - exact.impulse_per_period()).abs() / exact.impulse_per_period();
        assert!(rel < 1e-8, "{scheme}: impulse per period {impulse} vs exact {}", exact.impulse_per_period());
        if let Some(ti) = exact.impact_time() {
            let got = s.events.iter().find(|e| e.kind == "impact").unwrap().time;
            let d = (got - ti).rem_euclid(exact.period());
            assert!(d.min(exact.period() - d) < 1e-8 * exact.period(), "impact at {got} vs exact {ti}");
        }
    }
}

#[test]
fn pure_impacts_are_polished_to_1e_8() {
    let osc = Oscillator::new(1.0, 0.1, 1.0, 0.5, 0.8);
    let exact = RigidStopOrbit::solve(&osc, 0.6).unwrap();
    assert_eq!(exact.regime(), RigidRegime::Impacting);
    for scheme in [Scheme::Cds, Scheme::Galerkin, Scheme::Bds1] {
        let p = problem(&osc, Oscillator::stop(0.6, Compliance::Rigid), scheme, 256);
        let (ex, ev, wall, r) = polished(&p, |t| (exact.eval(t).0, exact.eval(t).1), exact.peak_to_peak());
        let s = r.polish.unwrap();
        eprintln!("pure impacts {scheme}: x error {ex:.2e}, v error {ev:.2e} of ptp, {wall:.3} s, events {:?}", s.events);
        assert!(ex < 1e-8 && wall < 1.0, "{scheme}: x error {ex:.2e}, {wall:.3} s");
        assert_eq!(s.events.len(), 1, "one impact per period");
        let rel = (s.events[0].impulse - exact.impact_impulse()).abs() / exact.impact_impulse();
        assert!(rel < 1e-8, "impulse {} vs exact {}", s.events[0].impulse, exact.impact_impulse());
    }
}

#[test]
fn compliant_stop_is_polished_to_1e_8() {
    let osc = Oscillator::new(1.0, 0.05, 1.0, 1.0, 1.3);
    let exact = CompliantStopOrbit::solve(&osc, 10.0, 1.0, None).unwrap();
    for scheme in [Scheme::Cds, Scheme::Bds1, Scheme::Fourier] {
        let p = problem(&osc, Oscillator::stop(1.0, Compliance::Compliant { stiffness: 10.0 }), scheme, 256);
        let (ex, ev, wall, r) = polished(&p, |t| (exact.eval(t).0, exact.eval(t).1), exact.peak_to_peak());
        let s = r.polish.unwrap();
        eprintln!("compliant {scheme}: x error {ex:.2e}, v error {ev:.2e} of ptp, {wall:.3} s, events {:?}", s.events);
        assert!(ex < 1e-8 && wall < 1.0, "{scheme}: x error {ex:.2e}, {wall:.3} s");
        let on = s.events.iter().find(|e| e.kind == "contact_on").unwrap().time;
        let t0 = exact.entry_time().unwrap().rem_euclid(exact.period());
        assert!((on - t0).abs() < 1e-8 * exact.period(), "entry {on} vs exact {t0}");
    }
}

/// A 2-DOF chain with a compliant stop on the second mass: the polished orbit agrees with long
/// explicit time integration from rest (the marcher's own error is O(h²): the gap must shrink
/// about 4× when its step halves, and be small at the finer step).
#[test]
fn two_dof_compliant_chain_agrees_with_long_time_integration() {
    use periodic_contact::marching::{MarchSettings, march};
    let scene = r#"
[structure]
mass = [[1.0, 0.0], [0.0, 1.0]]
stiffness = [[2.0, -1.0], [-1.0, 2.0]]
[damping]
matrix = [[0.1, 0.0], [0.0, 0.1]]
[excitation]
frequency = 1.2
[[force]]
dof = 0
amplitude = 1.0
[[contact]]
dof = 1
gap = 0.3
stiffness = 20.0
[discretization]
scheme = "cds"
steps = 256
"#;
    let p = periodic_contact::scene::Scene::parse(scene, "chain").unwrap().to_problem("chain").unwrap();
    let t0 = Instant::now();
    let mut r = p.solve().unwrap();
    polish::apply(&p, &mut r);
    let wall = t0.elapsed().as_secs_f64();
    let s = r.polish.clone().unwrap();
    assert_eq!(s.status, "polished", "{}", s.reason);
    assert!(s.events.len() >= 2, "the stop is touched: {:?}", s.events);
    let ptp = r.displacement.values().map(|x| Response::peak_to_peak(x)).fold(0.0, f64::max);
    let mut diffs = vec![];
    for n in [8192, 16384] {
        let settings = MarchSettings { steps_per_period: n, max_periods: 3000, tolerance: 1e-10, ..MarchSettings::default() };
        let m = march(p.model(), &settings).unwrap();
        assert!(m.converged, "marching converged (defect {:.2e})", m.defect);
        let stride = n / r.steps;
        let mut d = 0.0f64;
        for (j, _) in r.time.iter().enumerate() {
            for dof in 0..2 {
                d = d.max((r.displacement[&dof.to_string()][j] - m.displacement[j * stride][dof]).abs());
            }
        }
        diffs.push(d / ptp);
    }
    eprintln!("2-DOF chain: polish {wall:.3} s, events {:?}; |polish − march| / ptp at N = 8192, 16384: {:.2e}, {:.2e}", s.events, diffs[0], diffs[1]);
    assert!(diffs[1] < 1e-6, "{diffs:?}");
    assert!((2.5..6.0).contains(&(diffs[0] / diffs[1])), "the difference is the marcher's O(h²) error: {diffs:?}");
}

/// The polish's monodromy gives the Floquet multipliers of the exact compliant orbit
/// (`exact::CompliantStopOrbit::floquet_multipliers`, its own closed-form flows).
#[test]
fn monodromy_gives_the_exact_floquet_multipliers() {
    let osc = Oscillator::new(1.0, 0.05, 1.0, 1.0, 1.3);
    let exact = CompliantStopOrbit::solve(&osc, 10.0, 1.0, None).unwrap();
    let p = problem(&osc, Oscillator::stop(1.0, Compliance::Compliant { stiffness: 10.0 }), Scheme::Cds, 256);
    let r = p.solve().unwrap();
    let orbit = polish::polish(&p, &r).unwrap();
    let mut got: Vec<num_complex::Complex64> = orbit.monodromy().complex_eigenvalues().iter().copied().collect();
    let mut want = exact.floquet_multipliers().to_vec();
    let key = |c: &num_complex::Complex64| (c.norm(), c.im);
    got.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
    want.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
    eprintln!("multipliers: polish {got:?}, exact {want:?}");
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).norm() < 1e-6 * w.norm().max(1e-3), "{g} vs {w}");
    }
}

/// The coarse blade (23 DOFs after Craig–Bampton, three compliant tip contacts of 1e7 N/m, ω_max
/// = 6.3e5 rad/s against ω = 2300 rad/s) is polished, and explicit time marching
/// (`periodic_contact::marching`, started on the polished state) converges to it: the
/// difference falls at each halving of the marcher's step, and the polished orbit is closer to
/// the finest march than the two finest marches are to each other (the marcher is only first
/// order on the stiff contact DOFs here: its successive differences halve). Before the flows
/// were balanced and the Newton residual weighted, Newton stalled here on the round-off of the
/// stiff exponentials and on the velocity residuals of the stiff modes.
#[test]
fn coarse_blade_is_polished_and_time_marching_converges_to_it() {
    use periodic_contact::marching::{MarchSettings, march};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-coarse.toml");
    let (scene, dir) = periodic_contact::scene::Scene::load(&path).unwrap();
    let p = scene.build_in("blade", &dir).unwrap().problem;
    let mut r = p.solve().unwrap();
    let lcp = r.clone();
    let t0 = Instant::now();
    polish::apply(&p, &mut r);
    let wall = t0.elapsed().as_secs_f64();
    let s = r.polish.clone().unwrap();
    assert_eq!(s.status, "polished", "{}", s.reason);
    assert!(s.events.len() >= 2, "the casing is touched: {:?}", s.events);
    let orbit = polish::polish(&p, &lcp).unwrap();
    let n = p.model().n();
    let y0 = orbit.state(0.0);
    let k = 512;
    let states: Vec<_> = (0..k).map(|j| orbit.state(j as f64 * orbit.period() / k as f64)).collect();
    let ptp = (0..n).map(|d| states.iter().map(|y| y[d]).fold(f64::MIN, f64::max) - states.iter().map(|y| y[d]).fold(f64::MAX, f64::min)).fold(0.0, f64::max);
    let max_diff = |a: &dyn Fn(usize, usize) -> f64| (0..k).flat_map(|j| (0..n).map(move |d| (j, d))).map(|(j, d)| a(j, d).abs()).fold(0.0, f64::max) / ptp;
    let mut marches = vec![];
    for steps in [4096, 8192, 16384] {
        let settings = MarchSettings {
            steps_per_period: steps,
            max_periods: 3000,
            tolerance: 1e-11,
            initial_displacement: Some(y0.rows(0, n).iter().copied().collect()),
            initial_velocity: Some(y0.rows(n, n).iter().copied().collect()),
            ..MarchSettings::default()
        };
        let m = march(p.model(), &settings).unwrap();
        assert!(m.converged, "marching at N = {steps} converged (defect {:.2e})", m.defect);
        marches.push((0..k).map(|j| m.displacement[j * steps / k].clone()).collect::<Vec<_>>());
    }
    let to_polish: Vec<f64> = marches.iter().map(|m| max_diff(&|j, d| m[j][d] - states[j][d])).collect();
    let between = max_diff(&|j, d| marches[1][j][d] - marches[2][j][d]);
    eprintln!(
        "coarse blade: polish {wall:.3} s, {} iterations, events {:?}; |polish − march| / ptp at N = 4096, 8192, 16384: {}; |march 8192 − march 16384| / ptp: {between:.2e}",
        s.iterations,
        s.events,
        to_polish.iter().map(|e| format!("{e:.2e}")).collect::<Vec<_>>().join(", ")
    );
    assert!(to_polish.windows(2).all(|w| w[0] > 1.6 * w[1]), "the marches approach the polished orbit: {to_polish:?}");
    assert!(to_polish[2] < between, "the polished orbit is the marches' limit: {:.2e} vs {between:.2e}", to_polish[2]);
}
