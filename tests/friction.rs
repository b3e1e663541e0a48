//! Coulomb friction in the periodic LCP (src/formulation.md §9) against independent references
//! (`exact::friction`): Den Hartog's closed form (c = 0, continuous motion) and event-driven
//! exact simulations (closed-form flows, exact switching times) for damping, Jenkins elements,
//! stick-slip and a 2-DOF chain. The LCP's friction rows use bds1 (first order), so each case
//! checks the error at k/2 and k, its order, and the Richardson extrapolation 2x(k) − x(k/2).
use periodic_contact::analysis::hysteresis::{friction_loop, loop_area};
use periodic_contact::exact::*;
use periodic_contact::model::*;
use periodic_contact::periodic::*;
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;
use periodic_contact::time::{Discretization, Scheme};

fn solve(model: Model, steps: usize) -> Response {
    solve_by(model, Scheme::Bds1, steps)
}

fn solve_by(model: Model, scheme: Scheme, steps: usize) -> Response {
    let n = model.n();
    let outputs = OutputSelection { displacement: (0..n).collect(), velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme, steps, pairing: None };
    PeriodicProblem::new(model, disc, outputs, SolverSettings::default()).expect("problem").solve().expect("solve")
}

fn amplitude(r: &Response, dof: usize) -> f64 {
    0.5 * Response::peak_to_peak(&r.displacement[&dof.to_string()])
}

fn stuck_fraction(r: &Response) -> f64 {
    let s = &r.friction[0].stuck;
    s.iter().filter(|v| **v).count() as f64 / s.len() as f64
}

pub(crate) fn oscillator(c: f64, omega: f64, slip: f64, kt: Option<f64>) -> FrictionOscillator {
    FrictionOscillator {
        mass: vec![vec![1.0]],
        damping: vec![vec![c]],
        stiffness: vec![vec![1.0]],
        force: vec![1.0],
        omega,
        dof: 0,
        slip_force: slip,
        tangential_stiffness: kt,
    }
}

/// Ground–k1–m1–k2–m2, the load on m1, friction (μN = 0.25, rigid Coulomb) on m2.
pub(crate) fn chain_oscillator(omega: f64) -> FrictionOscillator {
    FrictionOscillator {
        mass: vec![vec![1.0, 0.0], vec![0.0, 0.5]],
        damping: vec![vec![0.06, -0.02], vec![-0.02, 0.02]],
        stiffness: vec![vec![2.0, -1.0], vec![-1.0, 1.0]],
        force: vec![1.0, 0.0],
        omega,
        dof: 1,
        slip_force: 0.25,
        tangential_stiffness: None,
    }
}

/// The LCP's solutions at k/2 and k.
fn pair(model: &Model, k: usize) -> (Response, Response) {
    (solve(model.clone(), k / 2), solve(model.clone(), k))
}

/// Relative amplitude errors of DOF `dof` against `exact`: at k/2, at k, and of the Richardson
/// extrapolation 2x(k) − x(k/2) (order 1).
fn errors((coarse, fine): &(Response, Response), dof: usize, exact: f64) -> [f64; 3] {
    let (a, b) = (amplitude(coarse, dof), amplitude(fine, dof));
    let rel = |x: f64| (x - exact).abs() / exact;
    [rel(a), rel(b), rel(2.0 * b - a)]
}

fn convergence(model: &Model, k: usize, dof: usize, exact: f64) -> ([f64; 3], Response) {
    let p = pair(model, k);
    (errors(&p, dof, exact), p.1)
}

#[test]
fn den_hartog_closed_form_agrees_with_the_event_driven_simulation() {
    // Two independent derivations of the same orbit: below and above resonance.
    for (omega, slip) in [(0.6, 0.3), (1.7, 0.2), (0.45, 0.1)] {
        let x = den_hartog_amplitude(1.0, 1.0, 1.0, slip, omega).expect("continuous motion");
        let orbit = FrictionOrbit::solve(&oscillator(0.0, omega, slip, None), 2000, 1e-11, 20000).expect("orbit");
        let a = orbit.amplitude(0, 4000);
        assert!((a - x).abs() < 1e-6 * x, "Ω = {omega}: simulation {a} against Den Hartog {x}");
        // Continuous motion: never stuck; ∮ f v dt = 4 F X.
        assert!(orbit.stuck_fraction == 0.0);
        assert!((orbit.dissipated_energy - 4.0 * slip * x).abs() < 1e-6 * x, "energy {}", orbit.dissipated_energy);
    }
    // With stops Den Hartog's continuous solution does not apply, and says so.
    assert!(den_hartog_amplitude(1.0, 1.0, 1.0, 0.9, 0.6).is_err());
}

#[test]
fn den_hartog_oscillator_converges_at_first_order() {
    // Measured relative amplitude errors (k = 256, k = 512, extrapolated; order):
    // Ω = 1.7: 9.68e-3, 4.12e-3, 1.45e-3 (1.23); Ω = 0.6: 1.52e-2, 7.73e-3, 2.2e-4 (0.98).
    for (omega, slip) in [(0.6, 0.3), (1.7, 0.2), (0.45, 0.1)] {
        let exact = den_hartog_amplitude(1.0, 1.0, 1.0, slip, omega).unwrap();
        let ([e1, e2, er], r) = convergence(&oscillator(0.0, omega, slip, None).model(), 512, 0, exact);
        let order = (e1 / e2).log2();
        println!("Den Hartog Ω = {omega}: errors {e1:.3e} (k = 256), {e2:.3e} (k = 512), order {order:.2}, extrapolated {er:.3e}");
        assert!((0.7..1.4).contains(&order), "order {order}");
        assert!(e2 < 1.5e-2 && er < 2e-3, "errors {e2:.3e}, extrapolated {er:.3e}");
        // ∮ f v dt = 4 F X, and the force never exceeds μN.
        let f = &r.friction[0];
        assert!((f.dissipated_energy - 4.0 * slip * exact).abs() < 2.0 * e2 * 4.0 * slip * exact + 1e-3, "energy {}", f.dissipated_energy);
        assert!(f.force.iter().all(|v| v.abs() <= slip * (1.0 + 1e-9)));
        assert!(f.force.iter().zip(&f.slip_velocity).all(|(f, v)| f * v >= -1e-12), "f·v ≥ 0");
    }
}

/// max_j |x_j − x(t_j)| over DOF `dof` against the event-driven orbit, relative to `scale`.
fn error_at_instants(r: &Response, orbit: &FrictionOrbit, period: f64, dof: usize, scale: f64) -> f64 {
    let x = &r.displacement[&dof.to_string()];
    let h = period / x.len() as f64;
    x.iter().enumerate().map(|(j, v)| (v - orbit.displacement(j as f64 * h)[dof]).abs()).fold(0.0, f64::max) / scale
}

/// cds's default friction, the event-fitted half steps by shooting (src/formulation.md §9
/// "Event-fitted half steps"): each slip end's step takes the law v̄ = c + ε s fitted from the
/// previous orbit, which restores order 2. Against the event-driven simulation at the instants
/// (max |x_j − x(t_j)| over the amplitude) and Den Hartog's closed form; Richardson at order 2
/// from k = 256 to 512 (|x_2j(512) − x_j(256)|/3) against the true error at 512. Den Hartog c = 0
/// (continuous motion, the closed form), damped with stops, and the 2-DOF chain (friction on m2).
/// Measured (this test, load 20): Den Hartog Ω = 0.6, μN = 0.3: 6.77e-5 → 1.98e-5 (k = 256 → 512,
/// order 1.78, estimate/true 0.92); Ω = 1.7, μN = 0.2: 1.11e-4 → 2.56e-5 (2.11, 1.11); damped
/// c = 0.1, Ω = 0.7, μN = 0.6: 1.49e-4 → 6.0e-5 (1.31, 0.71); long stick c = 0.167, Ω = 1.324,
/// μN = 0.885: 1.82e-3 → 1.89e-4 (3.26, 2.89; load 13); the others in validation/RECORD.md "Friction".
#[test]
fn event_fitted_half_steps_are_second_order_and_within_1e_3_at_k_512() {
    // The 2-DOF chain of validation/peers/friction_half_steps_family.py (seed 11, rounded).
    let chain = FrictionOscillator {
        mass: vec![vec![1.0, 0.0], vec![0.0, 1.0]],
        damping: vec![vec![0.057, 0.0], vec![0.0, 0.057]],
        stiffness: vec![vec![2.0, -1.0], vec![-1.0, 1.0]],
        force: vec![0.0, 1.0],
        omega: 1.02,
        dof: 1,
        slip_force: 0.487,
        tangential_stiffness: None,
    };
    let cases = [
        ("Den Hartog", oscillator(0.0, 0.6, 0.3, None)),
        ("Den Hartog", oscillator(0.0, 1.7, 0.2, None)),
        ("c = 0 with stops", oscillator(0.0, 1.438, 0.818, None)),
        ("damped", oscillator(0.1, 0.7, 0.6, None)),
        // Stuck 52 % (seed 11): the stop's law drifted off the stuck force (1.84e-3 at k = 512).
        ("damped, long stick", oscillator(0.167, 1.324, 0.885, None)),
        // Seed 11: Newton from bds1's laws cycled at k = 256 (I − P near singular); it solves
        // from bds1's orbit alone, whose laws end 1.18e-4 → 5.74e-5 (order 1.04: k = 256's
        // error is low, not 512's high), so its order is not asserted.
        ("Den Hartog, k = 256 from bds1 alone", oscillator(0.0, 1.506, 0.51, None)),
        // Seed 23: bds1 reverses 2 steps before the half steps at k = 512, its laws missed the
        // event and Newton wandered (periodicity 1.4e-3 after 60 iterations); k/2's laws hold it.
        ("Den Hartog, k = 512 from the laws at k/2", oscillator(0.0, 1.310, 0.647, None)),
        // Seed 37: at k = 256 Newton stalled at periodicity 1.9e-5 on bds1's laws (4 steps off
        // the reversal); the laws refitted to the stalled iterate converge: 2.10e-4 → 7.31e-5.
        ("Den Hartog, k = 256 refitted after a stall", oscillator(0.0, 0.924, 0.665, None)),
        ("chain", chain),
    ];
    for (name, osc) in cases {
        let orbit = FrictionOrbit::solve(&osc, 2000, 1e-11, 20000).expect("orbit");
        let dof = osc.dof;
        let exact = orbit.amplitude(dof, 4000);
        // Continuous motion at c = 0: Den Hartog's closed form, and order 2 (measured 1.78, 2.11).
        let closed = den_hartog_amplitude(1.0, 1.0, 1.0, osc.slip_force, osc.omega).ok().filter(|_| osc.damping[0][0] == 0.0);
        if let Some(x) = closed {
            assert!((x - exact).abs() < 1e-6 * x);
        }
        let runs: Vec<Response> = [256, 512].iter().map(|&k| solve_by(osc.model(), Scheme::Cds, k)).collect();
        let e: Vec<f64> = runs.iter().map(|r| error_at_instants(r, &orbit, osc.period(), dof, exact)).collect();
        let order = (e[0] / e[1]).log2();
        // Richardson, order 2, at the common instants, over the DOFs.
        let estimate = (0..osc.mass.len())
            .map(|d| {
                let (c, f) = (&runs[0].displacement[&d.to_string()], &runs[1].displacement[&d.to_string()]);
                c.iter().enumerate().map(|(j, v)| (f[2 * j] - v).abs()).fold(0.0, f64::max) / 3.0
            })
            .fold(0.0, f64::max);
        let truth = (0..osc.mass.len()).map(|d| error_at_instants(&runs[1], &orbit, osc.period(), d, 1.0)).fold(0.0, f64::max);
        println!(
            "{name} c = {}, Ω = {}, μN = {} (stuck {:.3}): {:.3e} → {:.3e} (order {order:.2}); estimate/true at 512 {:.2}; {}",
            osc.damping[0][0],
            osc.omega,
            osc.slip_force,
            orbit.stuck_fraction,
            e[0],
            e[1],
            estimate / truth,
            runs[1].lcp.path
        );
        assert!(runs[1].lcp.path.contains("event-fitted laws"), "{}", runs[1].lcp.path);
        assert!(e[1] < 1e-3, "k = 512: {:.3e}", e[1]);
        // The order with stops or damping wanders (0.94–2.57 over the family, validation/RECORD.md "Friction").
        // The members whose k = 256 needed a fallback start: 256 → 512 is off the asymptote
        // (measured 1.04 and 1.52; 512 → 1024 by validation/peers: 3.45 and 2.34).
        assert!(closed.is_none() || name.contains("k = 256") || order > 1.6, "order {order:.2}");
        if name.contains("at k/2") {
            assert!(runs[1].lcp.path.contains("from the laws of its orbit at k/2"), "{}", runs[1].lcp.path);
        }
        assert!((0.1..10.0).contains(&(estimate / truth)), "estimate {estimate:.3e} against {truth:.3e}");
    }
}

/// Why the half steps need the event laws (src/formulation.md §9 "Why not a second-order
/// pairing"): on Den Hartog's oscillator the relay half steps of cds are as large as O(h) but
/// erratic in k (the error follows where the reversal falls in its step), while bds1's is a steady
/// first-order term. Opt-in: `PERIODIC_CONTACT_FRICTION_RELAY_HALF_STEPS=1 cargo test --release
/// --test suite friction::half_step -- --ignored --nocapture`.
#[test]
#[ignore]
fn half_step_pairing_errors_are_erratic_in_k_and_bds1_errors_are_first_order() {
    assert!(std::env::var_os(RELAY_HALF_STEPS_ENV).is_some(), "set {RELAY_HALF_STEPS_ENV}=1: the half steps take the event laws without it");
    let steps = [200, 220, 240, 256, 280, 300, 320];
    for (omega, slip) in [(0.6, 0.3), (1.7, 0.2)] {
        let exact = den_hartog_amplitude(1.0, 1.0, 1.0, slip, omega).unwrap();
        let errors = |scheme: Scheme| -> Vec<f64> {
            steps.iter().map(|&k| (amplitude(&solve_by(oscillator(0.0, omega, slip, None).model(), scheme, k), 0) - exact) / exact).collect()
        };
        let (half, bds1) = (errors(Scheme::Cds), errors(Scheme::Bds1));
        let show = |v: &[f64]| v.iter().map(|e| format!("{e:.2e}")).collect::<Vec<_>>().join(", ");
        println!("Den Hartog Ω = {omega}, μN = {slip}, k = {steps:?}:\n  cds half steps {}\n  bds1 {}", show(&half), show(&bds1));
        // bds1: k·error stays within ±25 % of its mean (a first-order term dominates).
        let scaled: Vec<f64> = bds1.iter().zip(steps).map(|(e, k)| e * k as f64).collect();
        let mean = scaled.iter().sum::<f64>() / scaled.len() as f64;
        assert!(scaled.iter().all(|s| (s - mean).abs() < 0.25 * mean.abs()), "bds1 k·error {scaled:.3?}");
        // Half steps: smaller than bds1 but not monotone in k, so no order for Richardson.
        assert!(half.iter().zip(&bds1).all(|(h, b)| h.abs() < b.abs()), "half steps {}", show(&half));
        let turns = half.windows(3).filter(|w| (w[1].abs() - w[0].abs()) * (w[2].abs() - w[1].abs()) < 0.0).count();
        assert!(turns >= 2, "the half-step errors turn {turns} times: {}", show(&half));
    }
}

#[test]
fn jenkins_damper_against_the_event_driven_simulation() {
    // (c, Ω, μN, k_t): stick-slip with a Jenkins element, below and above resonance; rigid
    // Coulomb with damping and stick-slip.
    for (c, omega, slip, kt) in [(0.1, 0.8, 0.5, Some(2.0)), (0.05, 1.3, 0.4, Some(5.0)), (0.1, 0.7, 0.6, None)] {
        let o = oscillator(c, omega, slip, kt);
        let orbit = FrictionOrbit::solve(&o, 2000, 1e-11, 5000).expect("orbit");
        let exact = orbit.amplitude(0, 4000);
        let ([e1, e2, er], r) = convergence(&o.model(), 512, 0, exact);
        let stuck = stuck_fraction(&r);
        let e_rel = (r.friction[0].dissipated_energy - orbit.dissipated_energy).abs() / orbit.dissipated_energy;
        println!(
            "c {c} Ω {omega} μN {slip} k_t {kt:?}: amplitude errors {e1:.3e}, {e2:.3e}, extrapolated {er:.3e}; stuck {stuck:.4} (exact {:.4}); energy error {e_rel:.2e}",
            orbit.stuck_fraction
        );
        assert!(kt.is_none() || orbit.stuck_fraction > 0.05, "the reference sticks");
        assert!(e2 < 3e-2 && er < 5e-3, "errors {e2:.3e}, extrapolated {er:.3e}");
        assert!((stuck - orbit.stuck_fraction).abs() < 0.02, "stuck fraction {stuck} against {}", orbit.stuck_fraction);
        assert!(e_rel < 5e-2, "energy {e_rel}");
    }
}

#[test]
fn two_dof_chain_with_friction_on_one_mass_against_the_event_driven_simulation() {
    // Ground–k1–m1–k2–m2, the load on m1, friction on m2; a sweep over both sides of the modes
    // (0.77, 1.85 rad/s). At the first resonance (Ω = 0.8) bds1 is off by 9.6e-2 at k = 512
    // (extrapolated 8.5e-3): its numerical damping, not the friction.
    for omega in [0.4, 1.2] {
        let o = chain_oscillator(omega);
        let orbit = FrictionOrbit::solve(&o, 2000, 1e-11, 5000).expect("orbit");
        let p = pair(&o.model(), 512);
        let r = &p.1;
        for dof in [0, 1] {
            let exact = orbit.amplitude(dof, 4000);
            let [e1, e2, er] = errors(&p, dof, exact);
            println!(
                "chain Ω {omega} DOF {dof}: errors {e1:.3e}, {e2:.3e}, extrapolated {er:.3e}; stuck {:.4} (exact {:.4})",
                stuck_fraction(r),
                orbit.stuck_fraction
            );
            assert!(e2 < 5e-2 && er < 1e-2, "errors {e2:.3e}, extrapolated {er:.3e}");
            assert!((stuck_fraction(r) - orbit.stuck_fraction).abs() < 0.02);
        }
    }
}

const SCENE: &str = r#"[structure]
mass = [[1.0]]
stiffness = [[1.0]]

[excitation]
frequency = 0.6

[[force]]
dof = 0
amplitude = 1.0

[[friction]]
dof = 0
coefficient = 0.3
normal_force = 1.0

[discretization]
scheme = "bds1"
steps = 128
"#;

#[test]
fn scene_friction_solves_and_refuses_what_is_not_yet_supported() {
    let r = Scene::parse(SCENE, "f.toml").unwrap().to_problem("f.toml").unwrap().solve().unwrap();
    assert_eq!(r.friction.len(), 1);
    assert!(r.effects.iter().any(|e| e == "friction"));
    let json = serde_json::to_value(&r).unwrap();
    for key in ["force", "slip_velocity", "stuck", "dissipated_energy"] {
        assert!(json["friction"][0].get(key).is_some(), "{key} in the JSON");
    }
    let exact = den_hartog_amplitude(1.0, 1.0, 1.0, 0.3, 0.6).unwrap();
    assert!((amplitude(&r, 0) - exact).abs() < 0.05 * exact);
    // Keys of the interface that are not solved yet are refused by name, never ignored.
    for (key, value) in [("sliding_velocity", "8.4e5"), ("node", "\"LE\""), ("direction", "[1.0, 0.0, 0.0]")] {
        let text = SCENE.replacen("coefficient = 0.3", &format!("coefficient = 0.3\n{key} = {value}"), 1);
        let e = Scene::parse(&text, "f.toml").unwrap().to_problem("f.toml").unwrap_err().to_string();
        assert!(e.contains(&format!("friction[0].{key}")) && e.contains("not yet supported"), "{e}");
    }
    let e = Scene::parse(&SCENE.replacen("normal_force = 1.0", "normal_force = -1.0", 1), "f.toml").unwrap().to_problem("f.toml").unwrap_err().to_string();
    assert!(e.contains("friction[0].normal_force") && e.contains("-1"), "{e}");
    // cds takes rigid Coulomb (the event-fitted half steps); a Jenkins element needs bds1.
    let cds = SCENE.replacen("\"bds1\"", "\"cds\"", 1);
    let r = Scene::parse(&cds, "f.toml").unwrap().to_problem("f.toml").unwrap().solve().unwrap();
    assert!((amplitude(&r, 0) - exact).abs() < 1e-3 * exact, "cds {}", amplitude(&r, 0));
    let p = Scene::parse(&cds.replacen("normal_force = 1.0", "normal_force = 1.0\nstiffness = 2.0", 1), "f.toml").unwrap().to_problem("f.toml").unwrap();
    let e = p.solve().unwrap_err().to_string();
    assert!(e.contains("discretization.scheme") && e.contains("bds1") && e.contains("Jenkins"), "{e}");
}

/// A friction element driven through a displacement amplitude X: a unit mass on a spring k_s =
/// 10⁴ (10⁴ × k_t and more), forced by X·(k_s − Ω²) cos Ωt, so that x = X cos Ωt up to μN/k_s.
fn imposed_motion(x: f64, slip: f64, kt: Option<f64>) -> Model {
    let (ks, omega) = (1e4, 1.0);
    FrictionOscillator {
        mass: vec![vec![1.0]],
        damping: vec![vec![0.0]],
        stiffness: vec![vec![ks]],
        force: vec![x * (ks - omega * omega)],
        omega,
        dof: 0,
        slip_force: slip,
        tangential_stiffness: kt,
    }
    .model()
}

#[test]
fn energy_per_cycle_is_masings_loop_and_the_slip_distance_times_the_slip_force() {
    // Independent references (no simulation): a Jenkins element cycled through ±X dissipates
    // 4·μN·(X − μN/k_t) per cycle (Masing's parallelogram: the slider travels 2(X − μN/k_t) each
    // way at |f| = μN); a rigid Coulomb slider in gross slip travels 4X per cycle at μN: 4·μN·X.
    // The drive holds x = X cos Ωt only to μN/k_s, so the energy can be right to μN/(k_s·X).
    // Measured worst: energy 2.67e-4 (drive bound 2.67e-4; X 0.3, μN 0.8, rigid) at k = 256 and
    // 512; the loop's area ∮ f du (trapezoids) 3.8e-4 → 2.9e-4, its distance to the energy
    // (h·Σ f v) halving with k.
    let mut worst = (0.0f64, String::new());
    for (x, slip, kt) in [(1.0, 0.5, Some(2.0)), (0.6, 0.2, Some(1.5)), (2.0, 0.3, Some(0.5)), (1.0, 0.5, None), (0.3, 0.8, None)] {
        let exact = match kt {
            Some(kt) => 4.0 * slip * (x - slip / kt),
            None => 4.0 * slip * x,
        };
        let case = format!("X {x} μN {slip} k_t {kt:?}");
        let drive = slip / (1e4 * x);
        let mut gaps = Vec::new();
        for k in [256, 512] {
            let r = solve(imposed_motion(x, slip, kt), k);
            let f = &r.friction[0];
            let area = loop_area(&friction_loop(f));
            let (e, ea) = ((f.dissipated_energy - exact).abs() / exact, (area - exact).abs() / exact);
            println!("{case} k {k}: energy {:.6} (loop area {area:.6}), Masing/Coulomb {exact:.6}: errors {e:.2e}, {ea:.2e}", f.dissipated_energy);
            assert!(e < 2.0 * drive, "{case} k = {k}: energy {} against {exact} (error {e:.2e}, drive bound {drive:.2e})", f.dissipated_energy);
            assert!(ea < 1e-3, "{case} k = {k}: the loop's area {area} against {exact}");
            if e.max(ea) > worst.0 {
                worst = (e.max(ea), format!("{case} k = {k}"));
            }
            gaps.push((area - f.dissipated_energy).abs());
        }
        // The trapezoidal area differs from h·Σ f v by O(h): first order.
        assert!(gaps[1] < 0.75 * gaps[0] || gaps[1] < 1e-9 * exact, "{case}: |area − energy| {gaps:?} does not fall with k");
    }
    println!("worst: {:.2e} ({})", worst.0, worst.1);
}
