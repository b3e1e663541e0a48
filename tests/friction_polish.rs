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

#[test]
fn polish_fits_orbits_whose_topology_the_lcp_misses_or_that_never_slip() {
    // The 2-DOF chain at k = 512 where the LCP's phases are not the exact orbit's: Ω = 0.5949
    // stops mid-swing twice a period (8 events; bds1's damping hides the short stops), found by
    // marching the exact flows; Ω = 2.541 never slips (0 events), and the Jenkins damper under a
    // load that holds it (μN = 1.5 > k_t·X): the stuck system's linear orbit. Against the
    // event-driven simulation; a stuck orbit's position is unique only up to the slider's
    // constant, so it is compared up to each DOF's mean.
    use crate::friction::chain_oscillator;
    let damper = oscillator(0.1, 0.8, 1.5, Some(2.0));
    let cases = [(chain_oscillator(0.5948717948717949), 8), (chain_oscillator(2.541025641025641), 0), (damper, 0)];
    for (o, events) in cases {
        let n = o.mass.len();
        let reference = FrictionOrbit::solve(&o, 1000, 1e-13, 20000).expect("reference orbit");
        let outputs = OutputSelection { displacement: (0..n).collect(), velocity: vec![], acceleration: vec![], contacts: true };
        let disc = Discretization { scheme: Scheme::Bds1, steps: 512, pairing: None };
        let problem = PeriodicProblem::new(o.model(), disc, outputs, SolverSettings::default()).expect("problem");
        let r = problem.solve().expect("solve");
        let orbit = polish::friction::polish(&problem, &r).unwrap_or_else(|e| panic!("Ω = {}: {e}", o.omega));
        let times: Vec<f64> = (0..257).map(|i| i as f64 * o.period() / 257.0).collect();
        let mean = |f: &dyn Fn(f64) -> f64| if events == 0 { times.iter().map(|&t| f(t)).sum::<f64>() / times.len() as f64 } else { 0.0 };
        let (mut err, mut scale) = (0.0f64, 0.0f64);
        for d in 0..n {
            let (ours, exact) = (|t: f64| orbit.state(t)[d], |t: f64| reference.displacement(t)[d]);
            let (m_ours, m_exact) = (mean(&ours), mean(&exact));
            scale = scale.max(reference.amplitude(d, 512));
            err = times.iter().map(|&t| ((ours(t) - m_ours) - (exact(t) - m_exact)).abs()).fold(err, f64::max);
        }
        let holding = times.iter().map(|&t| orbit.contact(t).0.abs()).fold(0.0, f64::max);
        println!(
            "Ω = {:.4} (μN = {}): {} events (exact {events}), displacement error {:.2e} of the amplitude, stuck fraction {:.6} (exact {:.6}), max |f| {holding:.6} against μN {}",
            o.omega,
            o.slip_force,
            orbit.times.len(),
            err / scale,
            orbit.stuck_fraction(),
            reference.stuck_fraction,
            o.slip_force
        );
        assert_eq!(orbit.times.len(), events);
        assert!(err < 1e-8 * scale, "error {:.2e}", err / scale);
        assert!((orbit.stuck_fraction() - reference.stuck_fraction).abs() < 1e-8);
        assert!(holding <= o.slip_force * (1.0 + 1e-9), "|f| {holding} > μN");
    }
}

#[test]
#[ignore = "opt-in, 32 s at load 15 (about 150 LCP solves and polishes): cargo test --release --test suite friction_polish::peak_over -- --ignored --nocapture"]
fn peak_over_frequency_at_a_normal_load_meets_closed_forms_and_the_simulation() {
    // One point of the optimal-normal-load curve (`continue --peak-over`): the peak over
    // ω ∈ [0.5, 2.5] of the Jenkins damper (m = k = 1, c = 0.1, k_t = 2, μ = 1) on the polished
    // orbit, at k = 128. Free (N = 0) and stuck (N = 12 > k_t·X) it is the linear oscillator's
    // resonance peak 1/(c·√(k_eff/m − c²/4m²)), k_eff = k and k + k_t; in between (N = 0.8) the
    // event-driven simulation at the peak frequency found, and the peak a maximum there.
    use periodic_contact::analysis::continuation::optimal_load::peak_at;
    let (c, kt) = (0.1, 2.0);
    let closed = |k_eff: f64| 1.0 / (c * (k_eff - c * c / 4.0).sqrt());
    let problem = |slip: f64| {
        let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
        let disc = Discretization { scheme: Scheme::Bds1, steps: 128, pairing: None };
        PeriodicProblem::new(oscillator(c, 1.0, slip, Some(kt)).model(), disc, outputs, SolverSettings::default()).expect("problem")
    };
    for (n, k_eff) in [(0.0, 1.0), (12.0, 1.0 + kt)] {
        let p = peak_at(&problem(n), n, (0.5, 2.5), true).expect("peak");
        let err = (p.amplitude[0] - closed(k_eff)).abs() / closed(k_eff);
        println!(
            "N = {n}: peak {:.12} at ω = {:.9} (closed form {:.12}), error {err:.2e}, polished {}",
            p.amplitude[0],
            p.frequency,
            closed(k_eff),
            p.polished
        );
        assert!(err < 1e-8 && p.polished && !p.at_end, "error {err:.2e}");
    }
    let n = 0.8;
    let p = peak_at(&problem(n), n, (0.5, 2.5), true).expect("peak");
    // The simulation's half peak-to-peak: 1024 samples, each extreme refined by golden section.
    let exact = |w: f64| {
        let o = FrictionOrbit::solve(&oscillator(c, w, n, Some(kt)), 1000, 1e-13, 20000).expect("reference orbit");
        let (period, x) = (2.0 * std::f64::consts::PI / w, |t: f64| o.displacement(t)[0]);
        let h = period / 1024.0;
        let extreme = |sign: f64| {
            let i = (0..1024).max_by(|&a, &b| (sign * x(a as f64 * h)).total_cmp(&(sign * x(b as f64 * h)))).unwrap_or(0);
            let (mut lo, mut hi) = ((i as f64 - 1.0) * h, (i as f64 + 1.0) * h);
            for _ in 0..80 {
                let (a, b) = (hi - 0.618_033_988_75 * (hi - lo), lo + 0.618_033_988_75 * (hi - lo));
                if sign * x(a) > sign * x(b) { hi = b } else { lo = a }
            }
            x(0.5 * (lo + hi))
        };
        0.5 * (extreme(1.0) - extreme(-1.0))
    };
    let (here, below, above) = (exact(p.frequency), exact(p.frequency - 1e-3), exact(p.frequency + 1e-3));
    let err = (p.amplitude[0] - here).abs() / here;
    println!(
        "N = {n}: peak {:.12} at ω = {:.9}; the simulation there {here:.12} (error {err:.2e}), at ω ∓ 1e-3 {below:.12}, {above:.12}",
        p.amplitude[0], p.frequency
    );
    assert!(err < 1e-8 && p.polished, "error {err:.2e}");
    assert!(here > below && here > above, "not a maximum of the simulation's amplitude");
    assert!(p.amplitude[0] < closed(1.0 + kt) && p.amplitude[0] < closed(1.0), "friction damps below both linear peaks");
}

/// Den Hartog's c = 0 oscillator "with stops" (his term: the mass comes to rest within a half
/// period, here the stuck phases of rigid Coulomb friction; not a unilateral stop): the family's
/// member of tests/friction.rs (Ω = 1.438, μN = 0.818), then `draws` members drawn by seed `seed`
/// (Ω ∈ [0.3, 2.2], μN ∈ [0.3, 0.95], kept where Den Hartog's continuous motion does not apply and
/// the simulation sticks part of the period), polished from the LCP at k = 128 against the
/// event-driven simulation at 97 times. Rows, or the failures.
struct StopsRow {
    /// max |x − x_exact| at 97 times over the amplitude.
    err: f64,
    omega: f64,
    slip: f64,
    stuck_err: f64,
    /// Event counts: the polish's and the simulation's.
    events: (usize, usize),
    stuck: f64,
}

fn den_hartog_with_stops(draws: usize, seed: u64) -> (Vec<StopsRow>, Vec<String>) {
    let mut draw = Draw(seed);
    let mut cases = vec![(1.438, 0.818)];
    let (mut rows, mut failures) = (Vec::new(), Vec::new());
    let mut tries = 0;
    while rows.len() + failures.len() < draws + 1 && tries < 50 * (draws + 1) {
        tries += 1;
        let (omega, slip) = if cases.is_empty() { (draw.next(0.3, 2.2), draw.next(0.3, 0.95)) } else { cases.remove(0) };
        if den_hartog_amplitude(1.0, 1.0, 1.0, slip, omega).is_ok() {
            continue;
        }
        let o = oscillator(0.0, omega, slip, None);
        let Ok(reference) = FrictionOrbit::solve(&o, 1000, 1e-13, 20000) else { continue };
        if !(0.0..1.0).contains(&reference.stuck_fraction) || reference.stuck_fraction == 0.0 {
            continue;
        }
        match polished(&o, 128).1 {
            Ok(orbit) => {
                let scale = reference.amplitude(0, 256);
                let err =
                    (0..97).map(|i| i as f64 * o.period() / 97.0).map(|t| (orbit.state(t)[0] - reference.displacement(t)[0]).abs()).fold(0.0, f64::max) / scale;
                let stuck = (orbit.stuck_fraction() - reference.stuck_fraction).abs();
                let events = (orbit.times.len(), reference.events().len());
                rows.push(StopsRow { err, omega, slip, stuck_err: stuck, events, stuck: reference.stuck_fraction });
            }
            Err(e) => failures.push(format!("Ω = {omega:.4}, μN = {slip:.4} (stuck {:.3}): {e}", reference.stuck_fraction)),
        }
    }
    rows.sort_by(|a, b| b.err.total_cmp(&a.err));
    for StopsRow { err, omega, slip, stuck_err: stuck, events: (events, exact), stuck: frac } in &rows {
        println!(
            "c = 0 with stops, Ω = {omega:.4}, μN = {slip:.4}: displacement error {err:.2e} of the amplitude, {events} events (simulation {exact}), stuck fraction {frac:.6} (error {stuck:.1e})"
        );
    }
    failures.iter().for_each(|f| println!("not polished: {f}"));
    (rows, failures)
}

#[test]
fn polish_meets_den_hartog_with_stops_at_c_0() {
    let (rows, failures) = den_hartog_with_stops(2, 31);
    assert!(failures.is_empty(), "{failures:?}");
    assert_eq!(rows.len(), 3);
    for StopsRow { err, stuck_err: stuck, events: (events, exact), .. } in &rows {
        assert!(*err < 1e-8 && *stuck < 1e-8 && events == exact, "error {err:.2e}, stuck fraction error {stuck:.1e}, {events} events against {exact}");
    }
}

/// The c = 0 family with stops over PC_FRICTION_STOPS_FAMILY draws (e.g. 20): how many polish to
/// 1e-8, the worst error. Opt-in: `PC_FRICTION_STOPS_FAMILY=20 cargo test --release --test suite
/// friction_polish::den_hartog_stops_family -- --ignored --nocapture`.
#[test]
#[ignore = "opt-in: PC_FRICTION_STOPS_FAMILY=20"]
fn den_hartog_stops_family() {
    let draws: usize =
        std::env::var("PC_FRICTION_STOPS_FAMILY").ok().and_then(|v| v.parse().ok()).expect("set PC_FRICTION_STOPS_FAMILY to the number of draws");
    let (rows, failures) = den_hartog_with_stops(draws, 2029);
    let within = rows.iter().filter(|r| r.err < 1e-8 && r.stuck_err < 1e-8).count();
    println!(
        "{within} of {} polish to 1e-8; worst {:.2e}; {} not polished",
        rows.len() + failures.len(),
        rows.first().map_or(f64::NAN, |r| r.err),
        failures.len()
    );
    assert_eq!(within, draws + 1, "{failures:?}");
}
