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
        assert!(ex < 1e-8, "{scheme}: x error {ex:.2e}, {wall:.3} s");
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
        assert!(ex < 1e-8, "{scheme}: x error {ex:.2e}, {wall:.3} s");
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
        assert!(ex < 1e-8, "{scheme}: x error {ex:.2e}, {wall:.3} s");
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
    let p = crate::common::compliant_chain();
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

// ---------------------------------------------------------------------------------------------
// Contacts along any unit normal (issue 23 item 2): a change of basis changes nothing.

use periodic_contact::model::{Force, Harmonic, Matrix, Model, Structure};

/// Two 2-D nodes P (DOFs 0, 1) and Q (DOFs 2, 3) in their own axes: an x-chain P–Q, y-springs,
/// an x–y coupling, forces on P, a compliant stop on Q:x (+1) and a rigid stop on P:y (−1).
fn planar_pair() -> Model {
    let k = [[2.0, 0.2, -1.0, 0.0], [0.2, 3.0, 0.0, -0.5], [-1.0, 0.0, 2.0, 0.0], [0.0, -0.5, 0.0, 1.5]];
    let rows = |a: [[f64; 4]; 4]| Matrix::from_rows(&a.iter().map(|r| r.to_vec()).collect::<Vec<_>>());
    let eye = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];
    let force = |dof, amplitude| Force { dof, term: Harmonic { amplitude, harmonic: 1, phase: 0.0 } };
    Model {
        structure: Structure { mass: rows(eye), stiffness: rows(k), damping: Some(rows(eye.map(|r| r.map(|v| 0.1 * v)))) },
        forces: vec![force(0, 1.0), force(1, 0.6)],
        contacts: vec![
            Contact { row: vec![(2, 1.0)], gap: 0.2, compliance: Compliance::Compliant { stiffness: 20.0 }, motion: vec![] },
            Contact { row: vec![(1, -1.0)], gap: 0.1, compliance: Compliance::Rigid, motion: vec![] },
        ],
        frequency: 1.2,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    }
}

/// R = diag(R(α), R(β)) over (P, Q): the rotated model has M' = R M Rᵀ, K' = R K Rᵀ,
/// C' = R C Rᵀ, f' = R f and rows B' = B Rᵀ, whose orbit is x' = R x.
fn rotate(model: &Model, alpha: f64, beta: f64) -> (Model, [[f64; 4]; 4]) {
    let (sa, ca) = alpha.sin_cos();
    let (sb, cb) = beta.sin_cos();
    let r = [[ca, -sa, 0.0, 0.0], [sa, ca, 0.0, 0.0], [0.0, 0.0, cb, -sb], [0.0, 0.0, sb, cb]];
    let conj = |m: &Matrix| {
        Matrix::from_rows(
            &(0..4)
                .map(|i| (0..4).map(|j| (0..4).flat_map(|a| (0..4).map(move |b| (a, b))).map(|(a, b)| r[i][a] * m.get(a, b) * r[j][b]).sum()).collect())
                .collect::<Vec<_>>(),
        )
    };
    let s = &model.structure;
    let forces = model
        .forces
        .iter()
        .flat_map(|f| {
            (0..4)
                .filter(|&i| r[i][f.dof] != 0.0)
                .map(move |i| Force { dof: i, term: Harmonic { amplitude: r[i][f.dof] * f.term.amplitude, ..f.term.clone() } })
        })
        .collect();
    let contacts = model
        .contacts
        .iter()
        .map(|c| Contact { row: (0..4).map(|i| (i, c.row.iter().map(|&(d, v)| r[i][d] * v).sum::<f64>())).filter(|e| e.1 != 0.0).collect(), ..c.clone() })
        .collect();
    let structure = Structure { mass: conj(&s.mass), stiffness: conj(&s.stiffness), damping: s.damping.as_ref().map(conj) };
    (Model { structure, forces, contacts, ..model.clone() }, r)
}

fn every_dof(model: Model, scheme: Scheme, k: usize) -> PeriodicProblem {
    let outputs = OutputSelection { displacement: (0..model.n()).collect(), velocity: vec![], acceleration: vec![], contacts: true };
    PeriodicProblem::new(model, Discretization { scheme, steps: k, pairing: None }, outputs, SolverSettings::default()).unwrap()
}

/// max_j |Rᵀ x'_j − x_j| over every DOF, relative to the axis-aligned peak-to-peak amplitude.
fn rotated_back_error(axis: &[Vec<f64>], rotated: &[Vec<f64>], r: &[[f64; 4]; 4]) -> f64 {
    let ptp = (0..4).map(|d| Response::peak_to_peak(&axis.iter().map(|x| x[d]).collect::<Vec<_>>())).fold(0.0, f64::max);
    let mut e = 0.0f64;
    for (x, y) in axis.iter().zip(rotated) {
        for d in 0..4 {
            e = e.max(((0..4).map(|a| r[a][d] * y[a]).sum::<f64>() - x[d]).abs());
        }
    }
    e / ptp
}

fn states(r: &Response) -> Vec<Vec<f64>> {
    (0..r.steps).map(|j| (0..4).map(|d| r.displacement[&d.to_string()][j]).collect()).collect()
}

/// The rotated model (contacts along rotated normals mixing x and y) gives the axis-aligned orbit
/// rotated, through the LCP solve (cds and bds2 at k/2, k, 2k), the event-fitted polish and time
/// marching, over a family of frame angles; contact forces and gaps are the same.
#[test]
fn a_rotated_model_has_the_axis_aligned_orbit() {
    use periodic_contact::marching::{MarchSettings, march};
    let axis = planar_pair();
    let mut worst = [0.0f64; 4];
    for (alpha, beta) in [(0.3, 1.1), (2.5, -0.7), (-2.0, 0.05), (0.9, 3.0)] {
        let (rotated, r) = rotate(&axis, alpha, beta);
        rotated.validate().unwrap();
        assert!(rotated.contacts.iter().all(|c| c.row.len() == 2), "the normals mix x and y");
        for (scheme, k) in [(Scheme::Cds, 128), (Scheme::Cds, 256), (Scheme::Cds, 512), (Scheme::Bds2, 256)] {
            let (a, b) = (every_dof(axis.clone(), scheme, k).solve().unwrap(), every_dof(rotated.clone(), scheme, k).solve().unwrap());
            worst[0] = worst[0].max(rotated_back_error(&states(&a), &states(&b), &r));
            let fmax = a.contacts.iter().flat_map(|c| c.force.iter()).fold(1.0f64, |m, f| m.max(f.abs()));
            for (ca, cb) in a.contacts.iter().zip(&b.contacts) {
                let df = ca.force.iter().zip(&cb.force).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / fmax;
                let dg = ca.gap.iter().zip(&cb.gap).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
                worst[1] = worst[1].max(df).max(dg);
            }
            let touched: Vec<f64> = a.contacts.iter().map(|c| c.force.iter().fold(0.0f64, |m, &f| m.max(f))).collect();
            assert!(touched.iter().all(|&f| f > 0.0), "both stops are touched: max forces {touched:?}");
        }
        // The polish of both, at k = 256.
        let (pa, pb) = (every_dof(axis.clone(), Scheme::Cds, 256), every_dof(rotated.clone(), Scheme::Cds, 256));
        let (mut a, mut b) = (pa.solve().unwrap(), pb.solve().unwrap());
        polish::apply(&pa, &mut a);
        polish::apply(&pb, &mut b);
        for x in [&a, &b] {
            let s = x.polish.as_ref().unwrap();
            assert_eq!(s.status, "polished", "{}", s.reason);
        }
        worst[2] = worst[2].max(rotated_back_error(&states(&a), &states(&b), &r));
        // Time marching of both, N = 2048 steps per period.
        let settings = MarchSettings { steps_per_period: 2048, max_periods: 3000, tolerance: 1e-12, ..MarchSettings::default() };
        let (ma, mb) = (march(&axis, &settings).unwrap(), march(&rotated, &settings).unwrap());
        assert!(ma.converged && mb.converged);
        worst[3] = worst[3].max(rotated_back_error(&ma.displacement, &mb.displacement, &r));
    }
    eprintln!(
        "rotated vs axis-aligned, worst over 4 frames: solve {:.1e}, forces/gaps {:.1e}, polish {:.1e}, march {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    assert!(worst[0] < 1e-10 && worst[1] < 1e-10, "solve: {worst:?}");
    assert!(worst[2] < 1e-8, "polish: {worst:?}");
    assert!(worst[3] < 1e-8, "march: {worst:?}");
}

/// A mass moving only along a normal n (force along n, K = k nnᵀ + k_t(I − nnᵀ), C = c I) against
/// a rigid stop along n is the one-DOF rigid stop of src/exact (closed form): the polished normal
/// displacement n·x is the exact orbit to 1e-8 of its peak-to-peak amplitude, the tangential
/// motion vanishes, and the raw solve's n·x is the one-DOF model's solve to round-off.
#[test]
fn a_mass_along_a_normal_is_the_one_dof_rigid_stop() {
    let osc = Oscillator::new(1.0, 0.1, 1.0, 1.0, 1.0);
    let exact = RigidStopOrbit::solve(&osc, 0.5).unwrap();
    let one = problem(&osc, Oscillator::stop(0.5, Compliance::Rigid), Scheme::Cds, 256).solve().unwrap();
    for n in [vec![0.6, 0.8], vec![-0.28, 0.96], vec![2.0 / 7.0, -3.0 / 7.0, 6.0 / 7.0], vec![-0.48, 0.6, 0.64]] {
        let dim = n.len();
        let kt = 3.0;
        let entry = |i: usize, j: usize, along: f64, across: f64| {
            let nn = n[i] * n[j];
            along * nn + across * (if i == j { 1.0 } else { 0.0 } - nn)
        };
        let mat = |along: f64, across: f64| Matrix::from_rows(&(0..dim).map(|i| (0..dim).map(|j| entry(i, j, along, across)).collect()).collect::<Vec<_>>());
        let model = Model {
            structure: Structure { mass: mat(osc.mass, osc.mass), stiffness: mat(osc.stiffness, kt), damping: Some(mat(osc.damping, osc.damping)) },
            forces: (0..dim).map(|d| Force { dof: d, term: Harmonic { amplitude: osc.force * n[d], harmonic: 1, phase: 0.0 } }).collect(),
            contacts: vec![Contact { row: n.iter().copied().enumerate().collect(), gap: 0.5, compliance: Compliance::Rigid, motion: vec![] }],
            frequency: osc.omega,
            frictions: Vec::new(),
            rubbing: Vec::new(),
        };
        let outputs = OutputSelection { displacement: (0..dim).collect(), velocity: vec![], acceleration: vec![], contacts: true };
        let p = PeriodicProblem::new(model, Discretization { scheme: Scheme::Cds, steps: 256, pairing: None }, outputs, SolverSettings::default()).unwrap();
        let raw = p.solve().unwrap();
        let along = |r: &Response, j: usize| (0..dim).map(|d| n[d] * r.displacement[&d.to_string()][j]).sum::<f64>();
        let ptp = exact.peak_to_peak();
        let solve_gap = (0..raw.steps).map(|j| (along(&raw, j) - one.displacement["0"][j]).abs()).fold(0.0, f64::max) / ptp;
        let normal_reported = (0..raw.steps).map(|j| (raw.contacts[0].normal_displacement[j] - along(&raw, j)).abs()).fold(0.0, f64::max) / ptp;
        let mut r = raw.clone();
        polish::apply(&p, &mut r);
        assert_eq!(r.polish.as_ref().unwrap().status, "polished", "{}", r.polish.as_ref().unwrap().reason);
        let (mut ex, mut across) = (0.0f64, 0.0f64);
        for (j, &t) in r.time.iter().enumerate() {
            let xn = along(&r, j);
            ex = ex.max((xn - exact.eval(t).0).abs());
            across = across.max((0..dim).map(|d| (r.displacement[&d.to_string()][j] - n[d] * xn).abs()).fold(0.0, f64::max));
        }
        eprintln!("normal {n:?}: polished n·x vs exact {:.1e}, tangential {:.1e}, raw vs one-DOF {solve_gap:.1e} of ptp", ex / ptp, across / ptp);
        assert!(ex / ptp < 1e-8 && across / ptp < 1e-8, "{n:?}: {:.1e} {:.1e}", ex / ptp, across / ptp);
        assert!(solve_gap < 1e-10 && normal_reported < 1e-12, "{n:?}: {solve_gap:.1e} {normal_reported:.1e}");
    }
}
