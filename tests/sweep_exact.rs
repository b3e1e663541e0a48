//! `sweep --exact` (src/analysis/sweep/exact.rs) against closed forms: a mass on a spring k1 with
//! a massless contact point behind a spring k2 on a compliant stop k_c, so the mass sees the 1-DOF
//! stop of `exact::CompliantStopOrbit` (src/formulation.md §6.2) with the series stiffness
//! k_c k2 / (k_c + k2) (tests/massless_polish.rs). The sweep crosses the frequency where the
//! contact vanishes (a grazing), so the switch-detecting shooting must drop both switches.
use periodic_contact::analysis::polish;
use periodic_contact::exact::{CompliantStopOrbit, Oscillator};
use periodic_contact::model::Compliance;
use periodic_contact::periodic::{OutputSelection, PeriodicProblem, SolverSettings};
use periodic_contact::sweep::{self, SweepSettings};
use periodic_contact::time::{Discretization, Scheme};

use crate::massless_polish::{F, G0, K1, K2, M, damped_point_model};

/// Damping high enough that the contact's hardening bends no fold into the range: one orbit per ω
/// (the sweeps up and down agree to 2e-15), so the closed form's is the sweep's.
const C: f64 = 0.5;
const KC: f64 = 15.0;

fn problem(omega: f64) -> PeriodicProblem {
    let model = damped_point_model(Compliance::Compliant { stiffness: KC }, C, omega);
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Cds, steps: 256, pairing: None };
    PeriodicProblem::new(model, disc, outputs, SolverSettings::default()).unwrap()
}

/// The closed form's amplitude (peak-to-peak / 2) of the mass at `omega`, and whether it touches.
fn closed_form(omega: f64) -> (f64, bool) {
    let exact = CompliantStopOrbit::solve(&Oscillator::new(M, C, K1, F, omega), KC * K2 / (KC + K2), G0, None).unwrap();
    (exact.peak_to_peak() / 2.0, exact.has_contact())
}

#[test]
fn an_exact_sweep_across_a_vanishing_contact_is_the_closed_form_at_every_point() {
    // 1.0 → 1.6 rad/s: the contact shrinks and vanishes near 1.32 (the linear amplitude
    // F/|k1 − ω²m + iωc| is 1 at ω² = 1.75).
    let freqs: Vec<f64> = (0..25).map(|j| 1.0 + 0.025 * j as f64).collect();
    let settings = SweepSettings { threads: 1, ..SweepSettings::default() };
    let points = sweep::exact::run(&problem(freqs[0]), &freqs, &settings, &|_| {}).unwrap();
    let (mut worst, mut touching, mut free) = (0.0f64, 0, 0);
    for p in &points {
        let (want, contact) = closed_form(p.frequency);
        if contact {
            touching += 1
        } else {
            free += 1
        }
        // The first point is the grid's answer polished: its amplitude too is the orbit's own
        // extrema, not the k = 256 instants' (those sit (2π/256)²/8 ≈ 7.5e-5 below).
        let err = (p.amplitude[0] - want).abs() / want;
        worst = worst.max(err);
        eprintln!(
            "ω = {:.3}: {} ({}), amplitude {:.12e} vs closed form {want:.12e}: {err:.1e}",
            p.frequency,
            p.source,
            if contact { "contact" } else { "free" },
            p.amplitude[0]
        );
        assert!(err < 1e-10, "ω = {}: {err:.2e} of the closed form's amplitude", p.frequency);
    }
    assert!(touching >= 3 && free >= 3, "the range crosses the grazing: {touching} in contact, {free} free");
    // The first point starts on the grid and is polished; every later one follows exactly.
    assert_eq!(points[0].source, "polished");
    assert!(points[1..].iter().all(|p| p.source == "exact"), "sources: {:?}", points.iter().map(|p| p.source.as_str()).collect::<Vec<_>>());
    eprintln!("worst {worst:.1e}");
}

#[test]
fn switch_detecting_shooting_finds_the_polished_orbit_from_a_distant_start() {
    // From the orbit at 1.10 to 1.16 rad/s in one step, started from the old state at t = 0.
    let (a, b) = (problem(1.10), problem(1.16));
    let mut r = a.solve().unwrap();
    let prev = polish::apply(&a, &mut r).expect("polished");
    let got = polish::follow_detected(b.model(), &prev, prev.state(0.0).as_slice()).unwrap();
    let mut rb = b.solve().unwrap();
    let want = polish::apply(&b, &mut rb).expect("polished");
    let period = b.model().period();
    let sorted = |o: &polish::PolishedOrbit| {
        let mut t: Vec<f64> = o.times().iter().map(|t| t.rem_euclid(period)).collect();
        t.sort_by(f64::total_cmp);
        t
    };
    assert_eq!(got.events().len(), 2, "contact on, off");
    assert_eq!(got.events().len(), want.events().len());
    for (x, y) in sorted(&got).iter().zip(&sorted(&want)) {
        assert!((x - y).abs() < 1e-10 * period, "switch at {x} vs the polish's {y}");
    }
    let (amp, _) = closed_form(1.16);
    let ours = got.amplitude(None, 0).unwrap();
    assert!((ours - amp).abs() < 1e-10 * amp, "{ours} vs the closed form's {amp}");
}
