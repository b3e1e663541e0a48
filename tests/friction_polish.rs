//! The stick–slip polish (src/analysis/polish/friction.rs) against independent references:
//! Den Hartog's closed form (c = 0, continuous motion) and the event-driven exact simulation
//! (`exact::friction`, closed-form flows, switching times by bisection) for damping, stops and
//! Jenkins elements. Parameters are drawn by a fixed-seed generator, not tuned; the worst case
//! is printed first.
use periodic_contact::analysis::polish::{self, friction::StickSlipOrbit};
use periodic_contact::exact::*;
use periodic_contact::periodic::*;
use periodic_contact::response::Response;
use periodic_contact::time::{Discretization, Scheme};

/// A small linear congruential generator: reproducible draws in [lo, hi).
struct Draw(u64);
impl Draw {
    fn next(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

// The unit oscillator with friction: the same one tests/friction.rs checks the LCP on.
use crate::friction::oscillator;

/// The LCP at k = `steps` (bds1) and its stick–slip polish.
fn polished(o: &FrictionOscillator, steps: usize) -> (Response, Result<StickSlipOrbit, polish::PolishFailure>) {
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Bds1, steps, pairing: None };
    let problem = PeriodicProblem::new(o.model(), disc, outputs, SolverSettings::default()).expect("problem");
    let mut r = problem.solve().expect("solve");
    let orbit = polish::friction::polish(&problem, &r);
    polish::apply(&problem, &mut r);
    (r, orbit)
}

fn spectral_radius(o: &StickSlipOrbit) -> f64 {
    o.multipliers().iter().map(|z| z.norm()).fold(0.0, f64::max)
}

#[test]
fn polish_meets_den_hartog_closed_form_to_1e_8() {
    let mut draw = Draw(25);
    let mut rows = Vec::new();
    while rows.len() < 6 {
        let (omega, slip) = (draw.next(0.35, 2.2), draw.next(0.05, 0.5));
        let Ok(exact) = den_hartog_amplitude(1.0, 1.0, 1.0, slip, omega) else { continue };
        let (r, orbit) = polished(&oscillator(0.0, omega, slip, None), 128);
        let orbit = orbit.unwrap_or_else(|e| panic!("Ω = {omega}, μN = {slip}: {e}"));
        let err = (orbit.amplitude(0) - exact).abs() / exact;
        let energy = (r.friction[0].dissipated_energy - 4.0 * slip * exact).abs() / (4.0 * slip * exact);
        rows.push((err, omega, slip, energy, orbit.times.len(), orbit.stuck_fraction(), spectral_radius(&orbit), r.polish.map(|p| p.status)));
    }
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (err, omega, slip, energy, events, stuck, rho, status) in &rows {
        println!(
            "Den Hartog Ω = {omega:.4}, μN = {slip:.4}: amplitude error {err:.2e}, energy error {energy:.2e}, {events} events, stuck fraction {stuck:.1}, spectral radius {rho:.6}, {status:?}"
        );
        assert!(*err < 1e-8 && *energy < 1e-8, "error {err:.2e}, energy {energy:.2e}");
        assert!(*stuck == 0.0 && *events == 2, "continuous motion: two reversals, no stick");
        assert_eq!(status.as_deref(), Some("polished"));
    }
}

#[test]
fn polish_meets_the_event_driven_simulation_with_damping_stops_and_jenkins() {
    let mut draw = Draw(2025);
    let mut rows = Vec::new();
    for case in 0..6 {
        let jenkins = case % 2 == 1;
        let (c, omega, slip) = (draw.next(0.02, 0.2), draw.next(0.4, 1.8), draw.next(0.1, 0.7));
        let kt = jenkins.then(|| draw.next(1.0, 6.0));
        let o = oscillator(c, omega, slip, kt);
        let reference = FrictionOrbit::solve(&o, 1000, 1e-13, 20000).expect("reference orbit");
        let (_, orbit) = polished(&o, 128);
        let orbit = orbit.unwrap_or_else(|e| panic!("c {c} Ω {omega} μN {slip} k_t {kt:?}: {e}"));
        let scale = reference.amplitude(0, 256);
        let err = (0..97).map(|i| i as f64 * o.period() / 97.0).map(|t| (orbit.state(t)[0] - reference.displacement(t)[0]).abs()).fold(0.0, f64::max) / scale;
        let stuck = (orbit.stuck_fraction() - reference.stuck_fraction).abs();
        rows.push((
            err,
            c,
            omega,
            slip,
            kt,
            stuck,
            orbit.stuck_fraction(),
            spectral_radius(&orbit),
            orbit.multipliers().iter().filter(|z| z.norm() < 1e-8).count(),
        ));
    }
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (err, c, omega, slip, kt, stuck, frac, rho, zeros) in &rows {
        println!(
            "c {c:.3} Ω {omega:.3} μN {slip:.3} k_t {kt:?}: displacement error {err:.2e} of the amplitude, stuck fraction {frac:.6} (error {stuck:.1e}), spectral radius {rho:.6}, {zeros} zero multiplier(s)"
        );
        assert!(*err < 1e-8 && *stuck < 1e-8, "error {err:.2e}, stuck fraction error {stuck:.2e}");
        // Damped and passive: the orbit attracts (the reference simulation converged onto it).
        assert!(*rho < 1.0, "spectral radius {rho}");
    }
}

#[test]
fn bds1_error_estimate_within_10x_of_the_true_error_on_a_random_family() {
    // The Richardson estimate (order 1, a second solve at k/2) against the true error max_j
    // |x_j − x(t_j)| from the event-driven simulation, on Den Hartog's oscillator (c = 0) and
    // damped stick–slip, rigid and Jenkins.
    let mut draw = Draw(7);
    let mut rows = Vec::new();
    for case in 0..6 {
        let c = if case < 2 { 0.0 } else { draw.next(0.02, 0.2) };
        let (omega, slip) = (draw.next(0.4, 1.8), draw.next(0.05, 0.6));
        let kt = (case % 3 == 2).then(|| draw.next(1.0, 6.0));
        let o = oscillator(c, omega, slip, kt);
        let Ok(reference) = FrictionOrbit::solve(&o, 500, 1e-10, 20000) else { continue };
        let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
        let disc = Discretization { scheme: Scheme::Bds1, steps: 256, pairing: None };
        let problem = PeriodicProblem::new(o.model(), disc, outputs, SolverSettings::default()).expect("problem");
        let r = problem.solve().expect("solve");
        let estimate = periodic_contact::analysis::accuracy::estimate(&problem, &r).estimate.expect("an estimate");
        let truth = r.time.iter().zip(&r.displacement["0"]).map(|(&t, x)| (x - reference.displacement(t)[0]).abs()).fold(0.0, f64::max);
        rows.push((estimate / truth, c, omega, slip, kt, estimate, truth));
    }
    rows.sort_by(|a, b| (b.0.ln().abs()).total_cmp(&a.0.ln().abs()));
    for (ratio, c, omega, slip, kt, estimate, truth) in &rows {
        println!("c {c:.3} Ω {omega:.3} μN {slip:.3} k_t {kt:?}, k = 256: estimate {estimate:.3e}, true error {truth:.3e}, ratio {ratio:.2}");
        assert!((0.1..10.0).contains(ratio), "estimate {estimate:.3e} against the true error {truth:.3e}");
    }
    assert!(rows.len() >= 5, "the references converged");
}
