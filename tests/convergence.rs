//! Contact cases against semi-analytic periodic orbits (src/formulation.md §6; `periodic_contact::exact`):
//! convergence orders of each scheme, error bounds, impulse per period, persistent contact.
use periodic_contact::exact::{CompliantStopOrbit, Oscillator, PersistentContact, RigidRegime, RigidStopOrbit};
use periodic_contact::model::{Compliance, Harmonic};
use periodic_contact::periodic::{OutputSelection, PeriodicProblem, SolveError, SolverSettings, step_map};
use periodic_contact::response::Response;
use periodic_contact::time::{Discretization, Pairing, Scheme};

fn problem(osc: &Oscillator, contact: periodic_contact::model::Contact, scheme: Scheme, k: usize, pairing: Option<Pairing>) -> PeriodicProblem {
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    PeriodicProblem::new(osc.model(vec![contact]), Discretization { scheme, steps: k, pairing }, outputs, SolverSettings::default()).unwrap()
}

/// max_j |x_j − x(t_j)| / peak-to-peak, and the relative error of the impulse per period.
fn errors(r: &Response, exact_x: impl Fn(f64) -> f64, ptp: f64, impulse: f64) -> (f64, f64) {
    let x = &r.displacement["0"];
    let e = r.time.iter().zip(x).map(|(&t, &v)| (v - exact_x(t)).abs()).fold(0.0, f64::max) / ptp;
    (e, (r.impulse_per_period(0) - impulse).abs() / impulse)
}

/// Least-squares slope of −log e against log k: the observed order over several grids
/// (errors of contact problems oscillate with the position of the switches on the grid).
fn fitted_order(ks: &[usize], e: &[f64]) -> f64 {
    let x: Vec<f64> = ks.iter().map(|&k| (k as f64).ln()).collect();
    let y: Vec<f64> = e.iter().map(|v| -v.ln()).collect();
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    sxy / sxx
}

const COMPLIANT: Oscillator = Oscillator { mass: 1.0, damping: 0.05, stiffness: 1.0, force: 1.0, omega: 1.3 };

#[test]
fn compliant_stop_converges_at_each_schemes_order() {
    let exact = CompliantStopOrbit::solve(&COMPLIANT, 10.0, 1.0, None).unwrap();
    let ptp = exact.peak_to_peak();
    let stop = || Oscillator::stop(1.0, Compliance::Compliant { stiffness: 10.0 });
    for scheme in Scheme::ALL {
        let ks = [128, 256, 512, 1024];
        let e: Vec<f64> = ks
            .iter()
            .map(|&k| {
                let r = problem(&COMPLIANT, stop(), scheme, k, None).solve().unwrap();
                assert_eq!(r.pairing, "same", "compliant contacts default to same pairing");
                assert!(r.warnings.is_empty(), "{scheme}: {:?}", r.warnings);
                errors(&r, |t| exact.eval(t).0, ptp, exact.impulse_per_period()).0
            })
            .collect();
        let p = fitted_order(&ks, &e);
        eprintln!("compliant {scheme}: errors {e:?}, fitted order {p:.2}");
        match scheme.order() {
            Some(1) => assert!((0.85..1.2).contains(&p), "{scheme}: order {p}"),
            Some(2) => assert!((1.8..2.4).contains(&p), "{scheme}: order {p}"),
            _ => assert!(p > 1.5, "fourier: order {p} (the kink of the force limits it to about 2)"),
        }
        if scheme != Scheme::Bds1 {
            assert!(e[3] < 1e-3, "{scheme}: error at k = 1024 is {:.3e} of the peak-to-peak amplitude", e[3]);
        }
    }
}

const STICKING: Oscillator = Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 1.0, omega: 1.0 };

#[test]
fn rigid_stop_with_sticking_converges_bds1_first_cds_galerkin_second_order() {
    let exact = RigidStopOrbit::solve(&STICKING, 0.5).unwrap();
    assert_eq!(exact.regime(), RigidRegime::Sticking);
    let (ptp, impulse) = (exact.peak_to_peak(), exact.impulse_per_period());
    for (scheme, expected) in [(Scheme::Bds1, 1.0), (Scheme::Cds, 2.0), (Scheme::Galerkin, 2.0)] {
        let ks = [128, 256, 512, 1024];
        let e: Vec<(f64, f64)> = ks
            .iter()
            .map(|&k| {
                let r = problem(&STICKING, Oscillator::stop(0.5, Compliance::Rigid), scheme, k, None).solve().unwrap();
                assert!(r.warnings.is_empty(), "{scheme} with its default pairing converges: {:?}", r.warnings);
                errors(&r, |t| exact.eval(t).0, ptp, impulse)
            })
            .collect();
        let ex: Vec<f64> = e.iter().map(|v| v.0).collect();
        let ei: Vec<f64> = e.iter().map(|v| v.1).collect();
        let (px, pi) = (fitted_order(&ks, &ex), fitted_order(&ks, &ei));
        eprintln!("rigid+sticking {scheme}: errors (x, impulse) {e:?}, fitted orders x {px:.2}, impulse {pi:.2}");
        assert!((expected - 0.2..expected + 0.4).contains(&px), "{scheme}: displacement order {px}");
        assert!(pi > expected - 0.3, "{scheme}: impulse order {pi}");
        // Error bounds at k = 1024, from the orders: C·h^p with C measured once (×3 margin).
        let bound = if expected == 1.0 { 0.02 } else { 2e-5 };
        assert!(ex[3] < bound && ei[3] < bound, "{scheme}: errors at k = 1024: {:?}", e[3]);
    }
}

/// Without a sticking phase every fixed-grid scheme is first order: the impact instant falls
/// between samples and shifts the next free flight.
#[test]
fn pure_impacts_are_first_order_for_every_converging_scheme() {
    let osc = Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 0.5, omega: 0.8 };
    let exact = RigidStopOrbit::solve(&osc, 0.6).unwrap();
    assert_eq!(exact.regime(), RigidRegime::Impacting);
    let ptp = exact.peak_to_peak();
    for scheme in [Scheme::Bds1, Scheme::Cds, Scheme::Galerkin] {
        let ks = [256, 512, 1024, 2048, 4096];
        let e: Vec<f64> = ks
            .iter()
            .map(|&k| {
                let r = problem(&osc, Oscillator::stop(0.6, Compliance::Rigid), scheme, k, None).solve().unwrap();
                errors(&r, |t| exact.eval(t).0, ptp, exact.impulse_per_period()).0
            })
            .collect();
        let p = fitted_order(&ks, &e);
        eprintln!("pure impacts {scheme}: errors {e:?}, fitted order {p:.2}");
        assert!((0.6..1.4).contains(&p), "{scheme}: order {p}");
        // First-order bound: e ≤ C/k with C = 8 (measured e·k ≤ 4 for bds1, ≤ 1.3 for cds).
        for (k, v) in ks.iter().zip(&e) {
            assert!(v * (*k as f64) < 8.0, "{scheme}: error {v:.3e} at k = {k}");
        }
    }
}

/// Same-instant pairing with cds or fourier on a rigid contact is solved with a warning or
/// refused with a typed diagnostic, never reported as a good answer.
#[test]
fn same_pairing_with_cds_or_fourier_is_warned_or_refused() {
    for scheme in [Scheme::Cds, Scheme::Fourier, Scheme::Bds2, Scheme::Galerkin] {
        let p = problem(&STICKING, Oscillator::stop(0.5, Compliance::Rigid), scheme, 128, Some(Pairing::Same));
        assert!(!p.warnings().is_empty(), "{scheme}: the problem warns before solving");
        match p.solve() {
            Ok(r) => {
                assert!(r.warnings.iter().any(|w| w.contains("pairing = \"forward\"")), "{scheme}: the warning says what to use: {:?}", r.warnings);
                assert!(r.displacement["0"].iter().all(|v| v.is_finite()));
            }
            Err(SolveError::Lcp { outcome, .. }) => eprintln!("{scheme}/same refused: {}", outcome.name()),
            Err(e) => panic!("{scheme}: unexpected error {e}"),
        }
    }
}

#[test]
fn persistent_contact_follows_the_obstacle_and_the_force_converges() {
    let osc = Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 0.2, omega: 0.9 };
    let motion = vec![Harmonic { amplitude: 0.05, harmonic: 2, phase: 0.3 }];
    // A constant load of 1 keeps the mass pressed on the obstacle.
    let build = |k: usize| {
        let mut model =
            osc.model(vec![periodic_contact::model::Contact { row: vec![(0, 1.0)], gap: 0.2, compliance: Compliance::Rigid, motion: motion.clone() }]);
        model.forces.push(periodic_contact::model::Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 0, phase: 0.0 } });
        let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
        PeriodicProblem::new(model, Discretization { scheme: Scheme::Cds, steps: k, pairing: None }, outputs, SolverSettings::default()).unwrap()
    };
    let exact_osc = Oscillator { force: 0.2, ..osc };
    let exact = PersistentContact::solve(&exact_osc, 1.0, 0.2, &motion).unwrap();
    let mut force_errors = Vec::new();
    for k in [128, 256, 512] {
        let r = build(k).solve().unwrap();
        let c = &r.contacts[0];
        // Every gap is closed (forward pairing closes gap(t_{j+1}) for every j: all of them).
        assert!(c.gap.iter().all(|g| g.abs() < 1e-9), "k = {k}: max gap {:e}", c.gap.iter().fold(0.0f64, |m, g| m.max(g.abs())));
        for (&t, &x) in r.time.iter().zip(&r.displacement["0"]) {
            let obstacle = 0.2 + 0.05 * (2.0 * 0.9 * t + 0.3).cos();
            assert!((x - obstacle).abs() < 1e-9);
        }
        // Exact force: the constant load adds 1 to the oscillator's own.
        let e = r.time.iter().zip(&c.force).map(|(&t, &f)| (f - (exact.eval(t).2 + 1.0)).abs()).fold(0.0, f64::max);
        force_errors.push(e);
    }
    let p = fitted_order(&[128, 256, 512], &force_errors);
    eprintln!("persistent contact: force errors {force_errors:?}, order {p:.2}");
    assert!((1.8..2.3).contains(&p), "force order {p}");
}

/// The periodic LCP with cds and forward pairing is the steady state of the explicit
/// central-difference marcher with forward-increment multipliers (src/formulation.md §5) on the same grid:
/// marching from rest until the transients die must land on the same samples.
#[test]
fn cds_forward_equals_the_steady_state_of_explicit_time_marching() {
    use periodic_contact::marching::{MarchSettings, march};
    let cases = [("pure impacts", Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 0.5, omega: 0.8 }, 0.6), ("sticking", STICKING, 0.5)];
    for (name, osc, gap) in cases {
        for k in [256usize, 1024] {
            let model = osc.model(vec![Oscillator::stop(gap, Compliance::Rigid)]);
            let r = problem(&osc, Oscillator::stop(gap, Compliance::Rigid), Scheme::Cds, k, None).solve().unwrap();
            let m = march(&model, &MarchSettings { steps_per_period: k, tolerance: 1e-12, max_periods: 5000, ..Default::default() }).unwrap();
            assert!(m.converged, "{name} k={k}: the marcher did not reach a steady state");
            let shift = (m.time[0] / (r.period / k as f64)).round() as usize % k;
            let d = (0..k).map(|j| (r.displacement["0"][(j + shift) % k] - m.displacement[j][0]).abs()).fold(0.0, f64::max);
            eprintln!("{name} k={k}: periodic LCP vs marcher steady state {d:.2e} ({} periods, {:.3} s)", m.periods, m.cpu_time_s);
            assert!(d < 1e-9, "{name} k={k}: {d:e}");
        }
    }
}

/// Mass m on spring k1, and through spring k2 a massless contact point against a rigid stop at
/// g0 (src/formulation.md §4.1). Free: the point follows the mass; in contact it is held at g0,
/// so the mass sees k1 + k2 with the offset k2·g0: exactly the bilinear oscillator of §6.2 with
/// k = k1, k_c = k2, whose orbit `CompliantStopOrbit` gives without any time grid.
fn massless_contact_point(osc: &Oscillator, k2: f64, gap: f64, contact: Compliance) -> periodic_contact::model::Model {
    use periodic_contact::model::{Contact, Force, Matrix, Model, Structure};
    let k1 = osc.stiffness;
    Model {
        structure: Structure {
            mass: Matrix::from_rows(&[vec![osc.mass, 0.0], vec![0.0, 0.0]]),
            stiffness: Matrix::from_rows(&[vec![k1 + k2, -k2], vec![-k2, k2]]),
            damping: Some(Matrix::from_rows(&[vec![osc.damping, 0.0], vec![0.0, 0.0]])),
        },
        forces: vec![Force { dof: 0, term: Harmonic { amplitude: osc.force, harmonic: 1, phase: 0.0 } }],
        contacts: vec![Contact::on_dof(1, 1.0, gap, contact)],
        frequency: osc.omega,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    }
}

#[test]
fn massless_contact_point_converges_to_the_compliant_orbit() {
    use periodic_contact::periodic::LcpMethod;
    let (k2, g0) = (10.0, 1.0);
    let exact = CompliantStopOrbit::solve(&COMPLIANT, k2, g0, None).unwrap();
    let ptp = exact.peak_to_peak();
    let outputs = OutputSelection { displacement: vec![0, 1], velocity: vec![], acceleration: vec![], contacts: true };
    let solve = |model, scheme, k, method| {
        let settings = SolverSettings { method, ..SolverSettings::default() };
        PeriodicProblem::new(model, Discretization { scheme, steps: k, pairing: None }, outputs.clone(), settings).and_then(|p| p.solve())
    };
    // ω_max over the finite eigenvalues: the mass on k1 (rigid stop open), on k1 plus k2 in series
    // with a compliant stop k_c (closed).
    let p = PeriodicProblem::new(
        massless_contact_point(&COMPLIANT, k2, g0, Compliance::Rigid),
        Discretization { scheme: Scheme::Cds, steps: 64, pairing: None },
        outputs.clone(),
        SolverSettings::default(),
    )
    .unwrap();
    assert!((p.omega_max() - 1.0).abs() < 1e-9, "ω_max = {}", p.omega_max());
    let kc = 30.0;
    let p = PeriodicProblem::new(
        massless_contact_point(&COMPLIANT, k2, g0, Compliance::Compliant { stiffness: kc }),
        Discretization { scheme: Scheme::Cds, steps: 64, pairing: None },
        outputs.clone(),
        SolverSettings::default(),
    )
    .unwrap();
    let series = (1.0 + k2 * kc / (k2 + kc)).sqrt();
    assert!((p.omega_max() - series).abs() < 1e-9 * series, "ω_max = {} vs {series}", p.omega_max());

    for scheme in [Scheme::Cds, Scheme::Galerkin, Scheme::Bds1, Scheme::Bds2] {
        let ks = [256, 512, 1024];
        let mut e = Vec::new();
        for &k in &ks {
            let r = solve(massless_contact_point(&COMPLIANT, k2, g0, Compliance::Rigid), scheme, k, LcpMethod::Lemke).unwrap();
            assert_eq!(r.pairing, "same", "a rigid contact on a massless DOF defaults to same pairing");
            assert!(r.warnings.is_empty(), "{scheme}: {:?}", r.warnings);
            // The contact force is the spring's, finite: k2·(x_mass − g0) while in contact.
            let x = &r.displacement["0"];
            let fmax = r.contacts[0].force.iter().fold(0.0f64, |a, &v| a.max(v));
            let xmax = x.iter().fold(f64::MIN, |a, &v| a.max(v));
            assert!((fmax - k2 * (xmax - g0)).abs() < 0.05 * fmax, "{scheme}, k = {k}: force {fmax} vs k2·(x − g0) = {}", k2 * (xmax - g0));
            e.push(errors(&r, |t| exact.eval(t).0, ptp, exact.impulse_per_period()).0);
            // For cds and bds the discrete orbit is the 1-DOF compliant stop's to round-off (the
            // condensation is exact algebra), and so is the condensed step map: its march from any
            // state equals the 1-DOF model's. Galerkin weighs k2 by (1, 4, 1)/6 and has no step map.
            let one_dof = problem(&COMPLIANT, Oscillator::stop(g0, Compliance::Compliant { stiffness: k2 }), scheme, k, None);
            let two_dof = PeriodicProblem::new(
                massless_contact_point(&COMPLIANT, k2, g0, Compliance::Rigid),
                Discretization { scheme, steps: k, pairing: None },
                outputs.clone(),
                SolverSettings::default(),
            )
            .unwrap();
            if scheme == Scheme::Galerkin {
                let why = step_map(&two_dof).unwrap_err();
                assert!(why.0.contains("massless"), "{why}");
                continue;
            }
            let x1 = &one_dof.solve().unwrap().displacement["0"];
            let d_one = x.iter().zip(x1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / ptp;
            assert!(d_one < 1e-9, "{scheme}, k = {k}: against the 1-DOF compliant stop {d_one:e}");
            let (m1, m2) = (step_map(&one_dof).unwrap(), step_map(&two_dof).unwrap());
            assert_eq!(m1.state_size(), m2.state_size(), "the massless DOF is not in the state");
            let s0: Vec<f64> = (0..m1.state_size()).map(|i| 0.3 - 0.2 * i as f64).collect();
            let (e1, _, z1) = m1.march_period(&s0, None).unwrap();
            let (e2, _, z2) = m2.march_period(&s0, None).unwrap();
            let gap = e1.iter().zip(&e2).chain(z1.iter().zip(&z2)).map(|(a, b)| (a - b).abs() / (1.0 + a.abs())).fold(0.0, f64::max);
            assert!(gap < 1e-10, "{scheme}, k = {k}: step maps differ by {gap:e}");
            // Shooting on it, certified on the stacked LCP (bds: the shooting solver reaches the
            // cds orbit of this case neither for the 1-DOF model).
            if scheme != Scheme::Cds {
                let s = solve(massless_contact_point(&COMPLIANT, k2, g0, Compliance::Rigid), scheme, k, LcpMethod::Shooting).unwrap();
                let d_shoot = x.iter().zip(&s.displacement["0"]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / ptp;
                assert!(d_shoot < 1e-9, "{scheme}, k = {k}: shooting {d_shoot:e}");
            }
        }
        let p = fitted_order(&ks, &e);
        eprintln!("massless contact point, {scheme}: errors {e:?} at k = {ks:?}, fitted order {p:.2}");
        match scheme.order() {
            Some(1) => assert!((0.85..1.2).contains(&p), "{scheme}: order {p}"),
            _ => assert!((1.8..2.4).contains(&p), "{scheme}: order {p}"),
        }
    }
}

/// Explicit marching of a model with a massless DOF (the massless DOFs condensed statically at
/// each instant, the rigid contact on it enforced at that instant): its steady state converges
/// at second order to the exact orbit of the equivalent bilinear oscillator (no time grid), and
/// is the periodic cds LCP's orbit at the same k to the march's tolerance (the same recurrence,
/// reached by marching instead of by one LCP). The stable step counts the closed contact:
/// ω_max = √((k1 + k2)/m), not the open √(k1/m).
#[test]
fn massless_contact_point_marches_to_the_exact_orbit_at_second_order() {
    use periodic_contact::marching::{MarchSettings, march, stable_omega_max};
    let (k2, g0) = (10.0, 1.0);
    let model = massless_contact_point(&COMPLIANT, k2, g0, Compliance::Rigid);
    let w = stable_omega_max(&model).unwrap();
    assert!((w - 11f64.sqrt()).abs() < 1e-5, "ω_max for marching {w} vs √11");
    let exact = CompliantStopOrbit::solve(&COMPLIANT, k2, g0, None).unwrap();
    // The force is finite and the contact point is held at the stop while it acts.
    march_the_massless_point(&model, &exact, |x, f| {
        assert!(f >= 0.0 && (f == 0.0 || (x[1] - g0).abs() < 1e-12), "force {f} at x = {}", x[1]);
    });
    // Below the closed contact's limit the march is refused, naming the steps needed.
    let period = 2.0 * std::f64::consts::PI / COMPLIANT.omega;
    let few = (period * w / 2.0).floor() as usize - 1;
    let err = march(&model, &MarchSettings { steps_per_period: few, ..Default::default() }).unwrap_err().to_string();
    assert!(err.contains("contacts closed") && err.contains("steps per period"), "{err}");
}

/// The march of a compliant contact on a massless DOF (its spring k_c in series in the step's
/// statics): the steady state converges at second order to the exact orbit of the bilinear
/// oscillator with the series stiffness k2·k_c/(k2 + k_c) (no time grid), and equals the periodic
/// cds LCP's orbit at the same k (the same recurrence, reached by marching instead of one LCP).
#[test]
fn a_compliant_contact_on_a_massless_point_marches_to_the_series_spring_orbit() {
    use periodic_contact::marching::stable_omega_max;
    let (k2, kc, g0) = (10.0, 30.0, 1.0);
    let model = massless_contact_point(&COMPLIANT, k2, g0, Compliance::Compliant { stiffness: kc });
    let series = k2 * kc / (k2 + kc);
    let w = stable_omega_max(&model).unwrap();
    assert!((w - (1.0 + series).sqrt()).abs() < 1e-9, "ω_max for marching {w} vs √(1 + k_s)");
    let exact = CompliantStopOrbit::solve(&COMPLIANT, series, g0, None).unwrap();
    // The force is the springs': k_c times the point's penetration, k2 times the stretch.
    march_the_massless_point(&model, &exact, |x, f| {
        let (pen, stretch) = ((x[1] - g0).max(0.0), x[0] - x[1]);
        assert!((f - kc * pen).abs() < 1e-9 && (f == 0.0 || (f - k2 * stretch).abs() < 1e-9), "force {f} at x = {x:?}");
    });
}

/// Marches `model` (the massless contact point) at k = 128, 256, 512: each steady state equals the
/// cds LCP's orbit at the same k to 1e-9 of the amplitude, its error against `exact` falls at
/// second order, and `check_force(x_j, force_j)` holds at every sample.
fn march_the_massless_point(model: &periodic_contact::model::Model, exact: &CompliantStopOrbit, check_force: impl Fn(&[f64], f64)) {
    use periodic_contact::marching::{MarchSettings, march};
    let ptp = exact.peak_to_peak();
    let ks = [128, 256, 512];
    let mut e = Vec::new();
    for &k in &ks {
        let m = march(model, &MarchSettings { steps_per_period: k, tolerance: 1e-12, max_periods: 5000, ..Default::default() }).unwrap();
        assert!(m.converged, "k = {k}: no steady state in {} periods", m.periods);
        let err = m.time.iter().zip(&m.displacement).map(|(&t, x)| (x[0] - exact.eval(t).0).abs()).fold(0.0, f64::max) / ptp;
        let outputs = OutputSelection { displacement: vec![0, 1], velocity: vec![], acceleration: vec![], contacts: true };
        let r = PeriodicProblem::new(model.clone(), Discretization { scheme: Scheme::Cds, steps: k, pairing: None }, outputs, SolverSettings::default())
            .unwrap()
            .solve()
            .unwrap();
        let d = (0..k)
            .map(|j| (r.displacement["0"][j] - m.displacement[j][0]).abs().max((r.displacement["1"][j] - m.displacement[j][1]).abs()))
            .fold(0.0, f64::max);
        for (x, f) in m.displacement.iter().zip(&m.contact_force) {
            check_force(x, f[0]);
        }
        eprintln!("massless march k = {k}: error {err:.3e} of ptp vs exact, {d:.2e} vs the cds LCP, {} periods", m.periods);
        assert!(d < 1e-9 * ptp, "k = {k}: march vs LCP {d:e}");
        e.push(err);
    }
    let order = fitted_order(&ks, &e);
    assert!(order > 1.8, "observed order {order:.2}: {e:?}");
}
