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

/// Member 3 of the random family of validation/RECORD.md "Friction" (`coupled_family.py 2031`): k_xy −0.633,
/// k_c 23.95, μ 0.450, N0 1.496, N1 1.190, drive 0.496, Ω 1.778 (κ 0.229), at `steps` instants.
fn member_3(steps: usize, method: &str) -> Result<Response, SolveError> {
    let text = format!(
        "[structure]\nmass = [[1.0, 0.0], [0.0, 1.0]]\nstiffness = [[1.2154554809953746, -0.6333612913271878], [-0.6333612913271878, 0.9230558344173412]]\n\
         [damping]\nmatrix = [[0.0537599634228028, 0.0], [0.0, 0.3290668897126871]]\n[excitation]\nfrequency = 1.7781499846080084\n\
         [[force]]\ndof = 1\namplitude = -1.4958370127908591\nharmonic = 0\n[[force]]\ndof = 1\namplitude = -1.1901095446349745\n\
         [[force]]\ndof = 0\namplitude = 0.4960366656681321\nphase = -1.5707963267948966\n\
         [[contact]]\ndof = 1\ndirection = -1\ngap = 0.0\nstiffness = 23.9484460780964\n\
         [[friction]]\ndof = 0\ncoefficient = 0.4497335632928946\ncontact = 0\n\
         [discretization]\nscheme = \"bds1\"\nsteps = {steps}\nerror_estimate = \"none\"\n[solver]\nmethod = \"{method}\"\n[output]\ndisplacement = [0, 1]\n"
    );
    Scene::parse(&text, "member3.toml").unwrap().to_problem("member3.toml").unwrap().solve()
}

/// Member 3's two exact periodic orbits, x, y and λ_n at t = iT/16, by the event-driven simulation
/// (validation/peers/coupled_exact.py, shooting residual ≤ 4e-15): `PRESSED`, reached by marching
/// from the static equilibrium (always pressed, stuck 50 %: events at t/T = 0.30605 slip+,
/// 0.57215 slip−, 0.80366 stick), and `BOUNCING`, reached by marching from cold Lemke's k = 1024
/// state (lifted off 56 % in two flights: 8 events from t/T = 0.09702 to 0.94855).
const PRESSED: [[f64; 16]; 3] = [
    [
        -2.562475270731e-02,
        -2.562475270731e-02,
        -2.562475270731e-02,
        -2.562475270731e-02,
        -2.562475270731e-02,
        -2.562324290907e-02,
        -2.408541916383e-02,
        -1.726046697164e-02,
        -6.453500679441e-03,
        1.128126820474e-03,
        -9.371467445632e-04,
        -9.531763717177e-03,
        -2.073259520296e-02,
        -2.562475270731e-02,
        -2.562475270731e-02,
        -2.562475270731e-02,
    ],
    [
        -1.153504188495e-01,
        -1.113572509294e-01,
        -1.002475731716e-01,
        -8.340683053965e-02,
        -6.282366902537e-02,
        -4.141373369766e-02,
        -2.277804586098e-02,
        -1.020768908360e-02,
        -5.607980746963e-03,
        -9.258830361919e-03,
        -2.038608321416e-02,
        -3.760658945079e-02,
        -5.872808442039e-02,
        -8.053426309673e-02,
        -9.914815843483e-02,
        -1.112879233709e-01,
    ],
    [
        2.762463285904e+00,
        2.666833119288e+00,
        2.400773600559e+00,
        1.997463983724e+00,
        1.504529250082e+00,
        9.917945683511e-01,
        5.454988030661e-01,
        2.444582916007e-01,
        1.343024245257e-01,
        2.217345996687e-01,
        4.882150145978e-01,
        9.006193796434e-01,
        1.406446363012e+00,
        1.928670457211e+00,
        2.374444326019e+00,
        2.665172831991e+00,
    ],
];
const BOUNCING: [[f64; 16]; 3] = [
    [
        -1.967264837919e-01,
        -1.967264837919e-01,
        -1.951736754765e-01,
        -1.698490169908e-01,
        -1.097881924786e-01,
        -1.778108925934e-02,
        8.265700949126e-02,
        1.327039320574e-01,
        1.343485992265e-01,
        1.294917995048e-01,
        1.115031024957e-01,
        7.682261091641e-02,
        2.411018323081e-02,
        -4.547182358997e-02,
        -1.286074672326e-01,
        -1.946344769321e-01,
    ],
    [
        -3.105143190186e-01,
        -1.625964018076e-01,
        3.214425120266e-02,
        1.151213289334e-01,
        9.129961305557e-02,
        -7.934609646623e-03,
        -1.206938598930e-01,
        -1.241214831195e-01,
        -1.016203713827e-02,
        1.151682452132e-01,
        2.112655041527e-01,
        2.634869812221e-01,
        2.537210664903e-01,
        1.640889206960e-01,
        -1.902938925827e-02,
        -2.444528334459e-01,
    ],
    [
        7.436335425495e+00,
        3.893931161181e+00,
        0.0,
        0.0,
        0.0,
        1.900215712729e-01,
        2.890430395604e+00,
        2.972516645622e+00,
        2.433649984494e-01,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        4.557243025508e-01,
        5.854265500418e+00,
    ],
];

/// The largest of the relative errors of x, y, λ_n at t = iT/16 against an exact orbit's samples.
fn worst_error(r: &Response, exact: &[[f64; 16]; 3]) -> f64 {
    let k = r.displacement["0"].len();
    let series = [&r.displacement["0"], &r.displacement["1"], &r.contacts[0].force];
    (0..3)
        .map(|s| {
            let scale = exact[s].iter().fold(0.0f64, |a, v| a.max(v.abs()));
            (0..16).map(|i| (series[s][i * k / 16] - exact[s][i]).abs()).fold(0.0, f64::max) / scale
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_k_continuation_follows_the_pressed_orbit_where_cold_lemke_takes_the_bouncing_one() {
    // "auto": the orbit continued from k = 128, pressed all period, converging at first order
    // onto the exact pressed orbit (coupled_family.py: x 1.01e-1 → 4.20e-2, k = 256 → 512).
    let (r256, r512) = (member_3(256, "auto").expect("k = 256"), member_3(512, "auto").expect("k = 512"));
    let (e256, e512) = (worst_error(&r256, &PRESSED), worst_error(&r512, &PRESSED));
    let order = (e256 / e512).log2();
    println!("member 3, auto: error against the pressed orbit {e256:.3e} (k = 256), {e512:.3e} (k = 512), order {order:.2}; {}", r512.lcp.path);
    assert!(e512 < 6e-2 && (0.7..1.6).contains(&order), "errors {e256:.3e}, {e512:.3e}");
    assert!(r512.contacts[0].force.iter().all(|l| *l > 0.0), "pressed all period, as the exact orbit");
    assert!(r512.lcp.path.contains("k-continuation") && r512.lcp.path.contains("warm at 512"), "{}", r512.lcp.path);
    // Cold Lemke at k = 512 ends on the discretisation of the second exact orbit (bouncing), a
    // certified solution too: the coupled LCP holds both.
    let cold = member_3(512, "lemke").expect("cold Lemke at k = 512");
    let (to_pressed, to_bouncing) = (worst_error(&cold, &PRESSED), worst_error(&cold, &BOUNCING));
    let free = cold.contacts[0].force.iter().filter(|l| **l == 0.0).count() as f64 / 512.0;
    println!(
        "member 3, cold Lemke at k = 512: error {to_pressed:.3e} against the pressed orbit, {to_bouncing:.3e} against the bouncing one; lifted off {free:.3} (exact 0.561)"
    );
    assert!(to_bouncing < to_pressed && (free - 0.561).abs() < 0.05, "cold Lemke's solution at k = 512");
    assert!(cold.lcp.path.contains("several periodic orbits"), "the cold path says so: {}", cold.lcp.path);
}
