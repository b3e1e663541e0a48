//! Friction contacts by shooting on the bds1 step map (src/periodic/friction_shooting.rs): the
//! same LCP as the dense friction path, so on small scenes both must give the same orbit to
//! round-off; on a large one (N > FRICTION_DENSE_MAX, where the dense path refuses) the orbit is
//! certified on the full LCP and converges at first order to the event-driven exact simulation.
use periodic_contact::exact::*;
use periodic_contact::model::*;
use periodic_contact::periodic::*;
use periodic_contact::response::Response;
use periodic_contact::time::{Discretization, Scheme};

use crate::friction::{chain_oscillator, oscillator};

fn solve(model: Model, steps: usize, method: LcpMethod) -> Response {
    let n = model.n();
    let outputs = OutputSelection { displacement: (0..n).collect(), velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Bds1, steps, pairing: None };
    let settings = SolverSettings { method, ..SolverSettings::default() };
    PeriodicProblem::new(model, disc, outputs, settings).expect("problem").solve().expect("solve")
}

/// Ground–k1–m1–k2–m2, the load on m1 (tests/friction.rs's chain), friction on m2 and, with
/// `both`, a Jenkins element on m1 too.
fn chain(omega: f64, both: bool) -> Model {
    let mut model = chain_oscillator(omega).model();
    if both {
        model.frictions.push(Friction::on_dof(0, 1.0, 0.3, Some(1.5)));
    }
    model
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0f64, |acc, (x, y)| acc.max((x - y).abs()))
}

#[test]
fn shooting_equals_the_dense_lemke_on_small_friction_scenes() {
    let cases: Vec<(&str, Model)> = vec![
        ("Den Hartog c = 0, Ω = 0.6, μN = 0.3", oscillator(0.0, 0.6, 0.3, None).model()),
        ("Den Hartog c = 0, Ω = 1.7, μN = 0.2", oscillator(0.0, 1.7, 0.2, None).model()),
        ("Jenkins c = 0.1, Ω = 0.8, μN = 0.5, k_t = 2", oscillator(0.1, 0.8, 0.5, Some(2.0)).model()),
        ("rigid stick-slip c = 0.1, Ω = 0.7, μN = 0.6", oscillator(0.1, 0.7, 0.6, None).model()),
        ("2-DOF chain Ω = 0.4", chain(0.4, false)),
        ("2-DOF chain Ω = 1.2", chain(1.2, false)),
        ("2-DOF chain Ω = 0.8, Coulomb + Jenkins", chain(0.8, true)),
    ];
    for (name, model) in cases {
        let k = 128;
        let dense = solve(model.clone(), k, LcpMethod::Lemke);
        let shot = solve(model, k, LcpMethod::Shooting);
        assert!(shot.lcp.path.contains("shooting"), "{}", shot.lcp.path);
        let mut worst = 0.0f64;
        for (dof, x) in &dense.displacement {
            let scale = 1.0f64.max(0.5 * Response::peak_to_peak(x));
            worst = worst.max(max_diff(x, &shot.displacement[dof]) / scale);
        }
        for (fd, fs) in dense.friction.iter().zip(&shot.friction) {
            worst = worst.max(max_diff(&fd.force, &fs.force) / fd.normal_force.max(1.0));
            worst = worst.max(max_diff(&fd.slip_velocity, &fs.slip_velocity));
            assert_eq!(fd.stuck, fs.stuck, "{name}: stuck flags");
        }
        let stuck: usize = shot.friction.iter().map(|f| f.stuck.iter().filter(|s| **s).count()).sum();
        println!("{name}: shooting − dense Lemke {worst:.2e}, {stuck} stuck instants; {}", shot.lcp.path);
        assert!(worst < 1e-10, "{name}: shooting and dense Lemke differ by {worst:.3e}");
    }
}

#[test]
fn a_friction_problem_beyond_the_dense_limit_is_certified_and_converges_to_the_exact_orbit() {
    // The Jenkins damper of tests/friction.rs (stick–slip) and the 2-DOF chain with two friction
    // contacts; the event-driven simulation is the reference. bds1 is first order: at k = 512 the
    // damper is off by 1.6e-2 (tests/friction.rs), so k = 4096 is expected at ≈ 2e-3.
    let o = oscillator(0.1, 0.8, 0.5, Some(2.0));
    let exact = FrictionOrbit::solve(&o, 2000, 1e-11, 5000).expect("orbit").amplitude(0, 4000);
    let coarse = solve(o.model(), 2048, LcpMethod::Shooting);
    let fine = solve(o.model(), 4096, LcpMethod::Auto);
    assert!(fine.lcp.size > FRICTION_DENSE_MAX && fine.lcp.path.contains("shooting"), "{}", fine.lcp.path);
    let amp = |r: &Response| 0.5 * Response::peak_to_peak(&r.displacement["0"]);
    let (e1, e2) = ((amp(&coarse) - exact).abs() / exact, (amp(&fine) - exact).abs() / exact);
    let extrapolated = ((2.0 * amp(&fine) - amp(&coarse)) - exact).abs() / exact;
    println!("Jenkins damper: errors k = 2048 {e1:.3e}, k = 4096 {e2:.3e}, extrapolated {extrapolated:.3e}; {}", fine.lcp.path);
    assert!(fine.lcp.residual < 1e-8, "certified: residual {}", fine.lcp.residual);
    assert!(e2 < 4e-3 && e2 < 0.7 * e1 && extrapolated < 0.3 * e2, "errors {e1:.3e}, {e2:.3e}, extrapolated {extrapolated:.3e}");
    // Two friction contacts at k = 2048: N = 8192.
    let r = solve(chain(0.8, true), 2048, LcpMethod::Auto);
    println!("2-DOF chain, two friction contacts, k = 2048: {}", r.lcp.path);
    assert!(r.lcp.size == 8192 && r.lcp.path.contains("shooting"));
    let law = r.friction.iter().all(|f| f.force.iter().zip(&f.slip_velocity).all(|(f, v)| f * v >= -1e-12));
    assert!(law, "f·v ≥ 0 at every instant");
}

#[test]
fn friction_with_a_unilateral_contact_beyond_the_dense_limit_is_refused_with_the_reason() {
    let mut model = oscillator(0.1, 0.8, 0.5, Some(2.0)).model();
    model.contacts.push(Contact::on_dof(0, 1.0, 2.0, Compliance::Rigid));
    let problem = |steps: usize, method: LcpMethod| {
        let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
        let disc = Discretization { scheme: Scheme::Bds1, steps, pairing: None };
        PeriodicProblem::new(model.clone(), disc, outputs, SolverSettings { method, ..SolverSettings::default() }).expect("problem")
    };
    // k·(1 + 2) = 6144 > 4096 unknowns: the dense path refuses, and shooting does not apply.
    let e = problem(2048, LcpMethod::Auto).solve().unwrap_err().to_string();
    assert!(e.contains("6144 unknowns") && e.contains("1365 or fewer") && e.contains("shooting does not apply") && e.contains("unilateral"), "{e}");
    let e = problem(64, LcpMethod::Shooting).solve().unwrap_err().to_string();
    assert!(e.contains("solver.method") && e.contains("unilateral"), "{e}");
}

/// Harmonic `h` of samples `s` over one period: (2/k) Σ s_j e^(−2πi h j/k).
fn harmonic(s: &[f64], h: usize) -> num_complex::Complex64 {
    let k = s.len() as f64;
    s.iter().enumerate().map(|(j, &v)| v * num_complex::Complex64::from_polar(2.0 / k, -std::f64::consts::TAU * (h * j) as f64 / k)).sum()
}

#[test]
fn a_contact_stuck_all_period_leaves_a_family_whose_velocities_are_the_held_chains_closed_form() {
    // Ground–k1–m1–k2–m2, the load on m2, rigid Coulomb on m1 with μN = 4: the periodic state
    // holds m1 (its largest static force ≈ 3.6 < μN), at any offset c with |mean force c| ≤ μN −
    // 3.6, so I − P is singular along c. From rest the transient slips (up to ≈ 7 > μN), so Newton
    // starts outside the family. Reference: with m1 held, m2 is a linear oscillator (m2, c22, k22),
    // and bds1's periodic answer to F cos Ωt has the closed transfer
    // X = F / (m2 (1 − z⁻¹)²/h² + c22 (1 − z⁻¹)/h + k22), z = e^(iΩh) (implicit Euler, z-transform),
    // velocity V = X (1 − z⁻¹)/h.
    let (k, omega) = (512, 1.2);
    let o = FrictionOscillator { force: vec![0.0, 1.0], dof: 0, slip_force: 4.0, ..chain_oscillator(omega) };
    let r = solve(o.model(), k, LcpMethod::Shooting);
    println!("{}", r.lcp.path);
    assert!(r.lcp.residual < 1e-8, "certified: residual {}", r.lcp.residual);
    assert!(r.lcp.path.contains("1-parameter family"), "the family is named: {}", r.lcp.path);
    assert!(r.lcp.pivots <= 6, "Newton took {} iterations", r.lcp.pivots);
    let held = &r.friction[0];
    assert!(held.stuck.iter().all(|s| *s) && held.slip_velocity.iter().all(|v| v.abs() < 1e-12), "m1 is held all period");
    let x = &r.displacement["1"];
    assert_eq!(x.len(), k);
    let h = o.period() / k as f64;
    let v: Vec<f64> = (0..k).map(|j| (x[j] - x[(j + k - 1) % k]) / h).collect();
    let z_inv = num_complex::Complex64::from_polar(1.0, -omega * h);
    let d = (1.0 - z_inv) / h;
    let exact = (d / (0.5 * d * d + 0.02 * d + 1.0)).norm();
    let got = harmonic(&v, 1).norm();
    let others = (2..k / 2).map(|m| harmonic(&v, m).norm()).fold(harmonic(&v, 0).norm(), f64::max);
    println!("velocity amplitude of m2: {got:.15} (closed form {exact:.15}), other harmonics ≤ {others:.1e}");
    assert!((got - exact).abs() < 1e-9 * exact, "velocity amplitude {got} against the closed form {exact}");
    assert!(others < 1e-9 * exact, "m2 moves at the forcing harmonic only: {others:.3e}");
}
