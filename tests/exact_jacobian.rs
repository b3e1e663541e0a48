//! The exact walk's Jacobian (`PolishedOrbit::shooting_jacobian`: the variational flow of one
//! period, state and event-time columns) against central differences of the shooting residual
//! it differentiates, on a 2-DOF compliant chain and on the coarse blade's reduced model
//! (23 DOFs, 46 states, three compliant tip contacts of 1e7 N/m).
use periodic_contact::analysis::polish::{self, PolishedOrbit};
use periodic_contact::periodic::PeriodicProblem;
use std::time::Instant;

/// The variational Jacobian against central differences at the polished orbit's own (state,
/// event times) and at a point off the orbit (moved by `nudge` of the scales), both in the
/// Newton's units: columns times the unknowns' scales (the largest state |y|, the period),
/// rows as the polish weighs them (velocity of DOF d over ω_d = max(√(K_dd/M_dd), ω); a stiff
/// DOF's velocity rows carry the round-off of its exponential, ~1e-11 relative on the coarse
/// blade, which no difference step resolves). Returns the largest difference in the state
/// columns and in the event-time columns, each over the largest entry of its block.
fn block_errors(p: &PeriodicProblem, orbit: &PolishedOrbit, nudge: f64) -> (f64, f64, usize) {
    let (y0, times) = (orbit.initial_state().to_vec(), orbit.times().to_vec());
    let ys = y0.iter().fold(0.0f64, |m, y| m.max(y.abs()));
    let t = orbit.period();
    let y: Vec<f64> = y0.iter().enumerate().map(|(i, v)| v + nudge * ys * ((i % 7) as f64 - 3.0) / 3.0).collect();
    let tau: Vec<f64> = times.iter().enumerate().map(|(e, v)| v + nudge * t * if e % 2 == 0 { 1.0 } else { -0.5 }).collect();
    let (r, jac) = orbit.shooting_jacobian(&y, &tau).expect("a compliant orbit has the variational Jacobian");
    let r_plain = orbit.shooting_residual(&y, &tau).unwrap();
    assert!((&r - &r_plain).amax() <= 1e-9 * ys * p.model().frequency.max(1.0), "the residual beside the Jacobian is the shooting residual");
    let (m, n2) = (p.model(), y.len());
    let n = n2 / 2;
    let rate = |d: usize| (m.structure.stiffness.get(d, d) / m.structure.mass.get(d, d)).abs().sqrt().max(m.frequency);
    let row_weight = |i: usize| if (n..n2).contains(&i) { 1.0 / rate(i - n) } else { 1.0 };
    let (mut err, mut size) = ([0.0f64; 2], [0.0f64; 2]);
    for c in 0..jac.ncols() {
        // Five-point differences (error O(h⁴)); an event time's step 1e-5 of the period keeps the
        // round-off of the stiff flows (~1e-11 / (h·ω)) below 1e-6.
        let (h, scale) = if c < n2 { (1e-6 * ys, ys) } else { (1e-5 * t, t) };
        let at = |s: f64| {
            let (mut yy, mut tt) = (y.clone(), tau.clone());
            if c < n2 {
                yy[c] += s * h;
            } else {
                tt[c - n2] += s * h;
            }
            orbit.shooting_residual(&yy, &tt).unwrap()
        };
        let fd = (at(-2.0) - at(2.0) + (at(1.0) - at(-1.0)) * 8.0) / (12.0 * h);
        let block = usize::from(c >= n2);
        for i in 0..fd.len() {
            let w = row_weight(i) * scale;
            err[block] = err[block].max((jac[(i, c)] - fd[i]).abs() * w);
            size[block] = size[block].max(fd[i].abs() * w);
        }
    }
    (err[0] / size[0], err[1] / size[1], jac.ncols() - n2)
}

pub(crate) fn check(name: &str, p: &PeriodicProblem) {
    let r = p.solve().unwrap();
    let orbit = polish::polish(p, &r).unwrap();
    assert!(!orbit.events().is_empty(), "{name}: the contact is touched");
    for nudge in [0.0, 1e-3] {
        let t0 = Instant::now();
        let (state, time, ne) = block_errors(p, &orbit, nudge);
        eprintln!(
            "{name} ({} states, {ne} events, nudge {nudge:e}): variational vs central differences: {state:.2e} (state columns), {time:.2e} (event-time columns); {:.2} s",
            2 * p.model().n(),
            t0.elapsed().as_secs_f64()
        );
        assert!(state < 1e-6 && time < 1e-6, "{name}: {state:.2e}, {time:.2e}");
    }
}

#[test]
fn variational_jacobian_matches_central_differences_on_a_compliant_chain() {
    let p = crate::common::compliant_chain();
    check("2-DOF chain", &p);
}

#[test]
fn variational_jacobian_matches_central_differences_on_the_coarse_blade() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-coarse.toml");
    let (scene, dir) = periodic_contact::scene::Scene::load(&path).unwrap();
    let p = scene.build_in("blade", &dir).unwrap().problem;
    check("coarse blade", &p);
}
