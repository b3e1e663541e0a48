//! Coupled normal–tangential friction (src/formulation.md §9): a unit mass on a compliant plane,
//! pressed by a harmonic normal load, its tangential and normal directions coupled by an inclined
//! spring, the slip force μ·λ_n of the plane's contact (examples/friction/coupled.toml).
//!
//! The reference is the exact periodic orbit of an event-driven simulation (closed-form flows of
//! the free, stick, slip+ and slip− phases, exact switching times, Newton shooting), independent
//! of the crate: validation/peers/coupled_exact.py. Its samples at t = iT/16 (instants of every
//! grid below) were printed by `cd validation && python -m peers.coupled_exact` (shooting residual
//! 1e-15; events at t/T = 0.18369 slip+, 0.45509 lift-off, 0.80123 slip−, 0.93868 stick).
use periodic_contact::periodic::SolveError;
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;

const SCENE: &str = include_str!("../examples/friction/coupled.toml");

/// x (tangential), y (normal) and λ_n at t = iT/16, i = 0…15, of the exact orbit.
const EXACT_X: [f64; 16] = [
    -1.187677043224e-01,
    -1.187677043224e-01,
    -1.187677043224e-01,
    -1.187664679349e-01,
    -1.133254008548e-01,
    -8.677933664249e-02,
    -3.702297489943e-02,
    2.814690660094e-02,
    9.919805122033e-02,
    1.610244099852e-01,
    1.960306484115e-01,
    1.908987495869e-01,
    1.395665062949e-01,
    4.516605125800e-02,
    -6.472494812469e-02,
    -1.187459609526e-01,
];
const EXACT_Y: [f64; 16] = [
    -3.269436465624e-01,
    -2.778506762669e-01,
    -1.844943333161e-01,
    -9.853871868035e-02,
    -4.920918088693e-02,
    -3.271704688921e-02,
    -2.556258861209e-02,
    -7.654336521695e-03,
    2.323421599936e-02,
    6.188552396814e-02,
    9.670713119192e-02,
    1.081823409081e-01,
    7.445860276150e-02,
    -2.272926769110e-02,
    -1.695792318761e-01,
    -2.900470180466e-01,
];
const EXACT_LAMBDA: [f64; 16] = [
    3.269436465624e+00,
    2.778506762669e+00,
    1.844943333161e+00,
    9.853871868035e-01,
    4.920918088693e-01,
    3.271704688921e-01,
    2.556258861209e-01,
    7.654336521695e-02,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    2.272926769110e-01,
    1.695792318761e+00,
    2.900470180466e+00,
];
/// The exact orbit's stuck and lifted-off fractions of the period (from the events above).
const EXACT_STUCK: f64 = 1.0 + 0.1836914827 - 0.9386757155;
const EXACT_FREE: f64 = 0.8012347463 - 0.4550937950;

fn solve(text: &str, steps: usize) -> Result<Response, SolveError> {
    let text = text.replacen("steps = 256", &format!("steps = {steps}"), 1);
    Scene::parse(&text, "coupled.toml").unwrap().to_problem("coupled.toml").unwrap().solve()
}

/// Max relative errors of x, y, λ_n at t = iT/16 (each against the exact series' largest |value|).
fn errors(r: &Response) -> [f64; 3] {
    let k = r.displacement["0"].len();
    let series = [&r.displacement["0"], &r.displacement["1"], &r.contacts[0].force];
    let exact = [&EXACT_X, &EXACT_Y, &EXACT_LAMBDA];
    std::array::from_fn(|s| {
        let scale = exact[s].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        (0..16).map(|i| (series[s][i * k / 16] - exact[s][i]).abs()).fold(0.0, f64::max) / scale
    })
}

fn fraction(flags: impl Iterator<Item = bool>, k: usize) -> f64 {
    flags.filter(|v| *v).count() as f64 / k as f64
}

#[test]
fn coupled_friction_converges_to_the_exact_orbit_at_first_order() {
    let (coarse, fine) = (solve(SCENE, 128).expect("k = 128"), solve(SCENE, 256).expect("k = 256"));
    let (e1, e2) = (errors(&coarse), errors(&fine));
    println!(
        "coupled friction, errors at t = iT/16 (x, y, λ_n): k = 128 {e1:?}, k = 256 {e2:?}; times {:.3} s, {:.3} s",
        coarse.timing_s.total, fine.timing_s.total
    );
    // validation/peers/coupled_exact.py measured the same errors (x 0.163, 0.0868; y 0.0577, 0.0319).
    for s in 0..3 {
        let order = (e1[s] / e2[s]).log2();
        assert!(e2[s] < [0.1, 0.04, 0.04][s], "series {s}: error {:.3e} at k = 256", e2[s]);
        assert!((0.8..1.3).contains(&order), "series {s}: order {order:.2} (errors {:.3e}, {:.3e})", e1[s], e2[s]);
    }
    // The events: the stuck and lifted-off fractions of the period, within a few instants.
    let f = &fine.friction[0];
    let k = f.force.len();
    let stuck = fraction(f.stuck.iter().copied(), k);
    let free = fraction(fine.contacts[0].force.iter().map(|l| *l == 0.0), k);
    println!("stuck {stuck:.4} (exact {EXACT_STUCK:.4}), lifted off {free:.4} (exact {EXACT_FREE:.4})");
    assert!((stuck - EXACT_STUCK).abs() < 0.03 && (free - EXACT_FREE).abs() < 0.03, "stuck {stuck}, free {free}");
    // Coulomb's law at every instant: |f| ≤ μλ_n, f = μλ_n·sign(v) while slipping, f = 0 off the plane.
    let mu = f.coefficient;
    for j in 0..k {
        let (force, lam, v) = (f.force[j], fine.contacts[0].force[j], f.slip_velocity[j]);
        assert!(force.abs() <= mu * lam * (1.0 + 1e-9) + 1e-12, "instant {j}: |f| = {force} > μλ = {}", mu * lam);
        if v.abs() > 1e-9 && lam > 0.0 {
            assert!((force - mu * lam * v.signum()).abs() < 1e-9 * (1.0 + lam), "instant {j}: slipping at {v} with f = {force}, μλ = {}", mu * lam);
        }
    }
    assert_eq!(f.contact, Some(0));
    assert!(f.dissipated_energy > 0.0);
}

#[test]
fn a_jamming_coupling_is_a_typed_diagnosis_not_an_answer() {
    // μ = 2 and k_xy = 0.9: the static flexibilities G_nn = K⁻¹_yy + 1/k_c and G_nt = −K⁻¹_yx give
    // κ = μ·|G_nt|/G_nn = 2·(0.9/0.19)/(1/0.19 + 0.1) = 1.766 > 1 (closed form, K = [[1, .9], [.9, 1]]).
    let text = SCENE.replacen("coefficient = 0.6", "coefficient = 2.0", 1).replacen("[[1.0, 0.4], [0.4, 1.0]]", "[[1.0, 0.9], [0.9, 1.0]]", 1);
    let kappa = 2.0 * (0.9 / 0.19) / (1.0 / 0.19 + 0.1);
    let e = solve(&text, 128).expect_err("Lemke ends on a ray");
    let SolveError::Lcp { outcome, ref hint, .. } = e else { panic!("a typed LCP outcome, got {e}") };
    println!("{outcome:?}: {hint}");
    assert_eq!(e.kind(), periodic_contact::ErrorKind::Solve);
    assert!(hint.contains("friction[0] on contact[0]") && hint.contains(&format!("κ = μ·|G_nt|/G_nn = {kappa:.3}")), "{hint}");
    assert!(hint.contains("Remedies"), "{hint}");
}

#[test]
fn coupled_friction_scene_keys_are_checked() {
    let with = |key: &str| SCENE.replacen("contact = 0\n", &format!("contact = 0\n{key}\n"), 1);
    for key in ["normal_force = 1.0", "stiffness = 2.0"] {
        let e = Scene::parse(&with(key), "c.toml").unwrap().to_problem("c.toml").unwrap_err().to_string();
        let field = key.split(' ').next().unwrap();
        assert!(e.contains(&format!("friction[0].{field}")) && e.contains("coupled"), "{e}");
    }
    let e = Scene::parse(&SCENE.replacen("contact = 0\n", "contact = 3\n", 1), "c.toml").unwrap().to_problem("c.toml").unwrap_err().to_string();
    assert!(e.contains("friction[0].contact") && e.contains('3'), "{e}");
}
