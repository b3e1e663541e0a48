//! Scheme limits known before solving (issue 11): ω_max against analytic spectra, the cds and
//! galerkin thresholds against the one-step transition matrices of their recurrences, and the
//! refusal of a problem past its limit in every checked way in (new, set_frequency,
//! set_discretization, with_model).
use faer::sparse::{SparseColMat, Triplet};
use num_complex::Complex64 as C;
use periodic_contact::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};
use periodic_contact::periodic::{OutputSelection, PeriodicProblem, SolveError, SolverSettings, limits};
use periodic_contact::time::{Discretization, Scheme};

fn chain_model(n: usize, sparse: bool, contacts: Vec<Contact>, frequency: f64) -> Model {
    let mut mt = Vec::new();
    let mut kt = Vec::new();
    for i in 0..n {
        mt.push(Triplet::new(i, i, 1.0));
        kt.push(Triplet::new(i, i, 2.0));
        if i + 1 < n {
            kt.push(Triplet::new(i, i + 1, -1.0));
            kt.push(Triplet::new(i + 1, i, -1.0));
        }
    }
    let to = |t: &[Triplet<usize, usize, f64>]| {
        let s = SparseColMat::try_new_from_triplets(n, n, t).unwrap();
        if sparse { Matrix::Sparse(s) } else { Matrix::Dense(s.to_dense()) }
    };
    Model {
        structure: Structure { mass: to(&mt), stiffness: to(&kt), damping: None },
        forces: vec![Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } }],
        contacts,
        frequency,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    }
}

fn stop(dof: usize, compliance: Compliance) -> Contact {
    Contact { row: vec![(dof, 1.0)], gap: 0.5, compliance, motion: vec![] }
}

/// ω_max of the fixed–fixed unit chain: eigenvalues 2 − 2cos(jπ/(n+1)) (analytic), dense and
/// sparse (the sparse path above 400 DOFs runs Lanczos, whose Ritz value approaches from below;
/// the chain's top eigenvalues are 2.5e-6 apart, its hardest case, within 1e-5); with a compliant contact closed, the 2×2
/// [[2 + k_c, −1], [−1, 2]] has the largest eigenvalue 2 + k_c/2 + √(k_c²/4 + 1).
#[test]
fn omega_max_matches_analytic_spectra() {
    for (n, sparse) in [(5, false), (300, true), (2000, true)] {
        let w = chain_model(n, sparse, vec![], 1.0).omega_max().unwrap();
        let exact = (2.0 + 2.0 * (std::f64::consts::PI / (n + 1) as f64).cos()).sqrt();
        let tol = if n > 400 { 1e-5 } else { 1e-10 };
        assert!((w - exact).abs() <= tol * exact && w <= exact * (1.0 + 1e-12), "n = {n}: ω_max = {w}, exact {exact}");
    }
    let kc = 10.0;
    let w = chain_model(2, false, vec![stop(0, Compliance::Compliant { stiffness: kc })], 1.0).omega_max().unwrap();
    let exact = (2.0 + kc / 2.0 + (kc * kc / 4.0 + 1.0).sqrt()).sqrt();
    assert!((w - exact).abs() <= 1e-12 * exact, "compliant: {w} vs {exact}");
    // A rigid contact adds no stiffness.
    let w = chain_model(2, false, vec![stop(0, Compliance::Rigid)], 1.0).omega_max().unwrap();
    assert!((w - 3f64.sqrt()).abs() < 1e-12);
}

/// Spectral radius of the one-step transition matrix [[a, −1], [1, 0]] of x_{j+1} = a x_j − x_{j−1}:
/// the roots of λ² − aλ + 1.
fn spectral_radius(a: f64) -> f64 {
    let d = C::new(a * a - 4.0, 0.0).sqrt();
    ((C::new(a, 0.0) + d) / 2.0).norm().max(((C::new(a, 0.0) - d) / 2.0).norm())
}

/// The thresholds of `Scheme::stability_limit` against the recurrences of one undamped mode,
/// Ω = ω h: cds x_{j+1} − 2x_j + x_{j−1} + Ω² x_j = 0; galerkin (Newmark β = 1/6)
/// x_{j+1} − 2x_j + x_{j−1} + Ω² (x_{j+1} + 4x_j + x_{j−1})/6 = 0. Just below the limit every root
/// is on the unit circle; just above, one is outside.
#[test]
fn cds_and_galerkin_thresholds_match_the_transition_matrices() {
    let cds = |o: f64| 2.0 - o * o;
    let galerkin = |o: f64| (2.0 - 4.0 * o * o / 6.0) / (1.0 + o * o / 6.0);
    for (scheme, a) in [(Scheme::Cds, &cds as &dyn Fn(f64) -> f64), (Scheme::Galerkin, &galerkin)] {
        let limit = scheme.stability_limit().unwrap();
        for f in [0.1, 0.5, 0.9, 0.999] {
            assert!(spectral_radius(a(f * limit)) <= 1.0 + 1e-12, "{scheme} stable at {f}·limit");
        }
        for f in [1.001, 1.1, 2.0] {
            assert!(spectral_radius(a(f * limit)) > 1.0 + 1e-3, "{scheme} unstable at {f}·limit");
        }
    }
    assert!((Scheme::Galerkin.stability_limit().unwrap() - 12f64.sqrt()).abs() < 1e-15);
    for s in [Scheme::Bds1, Scheme::Bds2, Scheme::Fourier] {
        assert_eq!(s.stability_limit(), None);
    }
}

fn problem(model: Model, scheme: Scheme, k: usize) -> Result<PeriodicProblem, SolveError> {
    PeriodicProblem::new(model, Discretization { scheme, steps: k, pairing: None }, OutputSelection::default(), SolverSettings::default())
}

/// A stiff compliant stop (k_c = 1e4, ω_max ≈ 100.02) at ω = 1: k = 256 gives ω_max·h ≈ 2.455,
/// past cds's 2 and below galerkin's 3.46. Refused with ω_max, h, the product, the smallest k
/// (ω_max·T/2 < k: 315) and the schemes that fit; accepted by galerkin, bds1 and at k = 512.
#[test]
fn past_the_limit_is_refused_before_solving() {
    let kc = 1e4;
    let model = chain_model(2, false, vec![stop(0, Compliance::Compliant { stiffness: kc })], 1.0);
    let wmax = (2.0 + kc / 2.0 + (kc * kc / 4.0 + 1.0).sqrt()).sqrt();
    let k_min = (wmax * 2.0 * std::f64::consts::PI / 2.0).floor() as usize + 1;
    let err = problem(model.clone(), Scheme::Cds, 256).unwrap_err();
    assert!(matches!(err, SolveError::Limit(_)), "{err}");
    let msg = err.to_string();
    let wh = wmax * 2.0 * std::f64::consts::PI / 256.0;
    for part in
        ["cds", "ω_max·h < 2.000", &format!("{wmax:.4e} rad/s"), &format!("ω_max·h = {wh:.3}"), &format!("steps ≥ {k_min}"), "bds1", "galerkin (ω_max·h"]
    {
        assert!(msg.contains(part), "missing {part:?} in: {msg}");
    }
    assert!(problem(model.clone(), Scheme::Cds, k_min).is_ok());
    assert!(problem(model.clone(), Scheme::Cds, k_min - 1).is_err());
    for s in [Scheme::Galerkin, Scheme::Bds1, Scheme::Bds2, Scheme::Fourier] {
        assert!(problem(model.clone(), s, 256).is_ok(), "{s}");
    }

    // Every updater checks it, and leaves the problem unchanged on error.
    let mut p = problem(model.clone(), Scheme::Cds, 512).unwrap();
    assert!((p.omega_max() - wmax).abs() < 1e-9 * wmax);
    assert!(matches!(p.set_frequency(0.5), Err(SolveError::Limit(_))));
    assert_eq!(p.model().frequency, 1.0);
    let disc = p.discretization();
    assert!(matches!(p.set_discretization(Discretization { steps: 256, ..disc }), Err(SolveError::Limit(_))));
    assert_eq!(p.discretization().steps, 512);
    let mut slow = model.clone();
    slow.frequency = 0.5;
    assert!(matches!(p.with_model(slow, disc), Err(SolveError::Limit(_))));
}

/// `steps = "auto"`: the smallest power of two ≥ 256 with ω_max·h ≤ 0.9·limit; the floor for
/// schemes without a limit.
#[test]
fn auto_steps_choose_the_smallest_stable_power_of_two() {
    let kc = 1e4;
    let model = chain_model(2, false, vec![stop(0, Compliance::Compliant { stiffness: kc })], 1.0);
    let wmax = model.omega_max().unwrap();
    let (k, note) = limits::auto_steps(&model, Scheme::Cds, wmax, 1.0);
    // ω_max·T/(0.9·2) = 349.2 → 512.
    assert_eq!(k, 512, "{note}");
    assert!(wmax * 2.0 * std::f64::consts::PI / k as f64 <= 0.9 * 2.0);
    assert!(note.contains("k = 512") && note.contains("cds"), "{note}");
    assert_eq!(limits::auto_steps(&model, Scheme::Bds1, wmax, 1.0).0, limits::AUTO_FLOOR);
    assert_eq!(limits::auto_steps(&model, Scheme::Cds, wmax, 0.25).0, 2048);
    let p = PeriodicProblem::new_auto(
        model,
        Discretization { scheme: Scheme::Galerkin, steps: 0, pairing: None },
        OutputSelection::default(),
        SolverSettings::default(),
    )
    .unwrap();
    assert_eq!(p.discretization().steps, 256);
    assert!(p.steps_auto() && p.warnings()[0].contains("steps = \"auto\""));
}
