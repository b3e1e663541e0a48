//! A cold `auto` solve that shooting misses, re-tried from a bds1 pilot's active sets on the same
//! grid (`src/periodic/pilot.rs`'s `solve_after_cold_miss`), against dense lexicographic Lemke's
//! certified answer. The model is the compliant real blade's at 2535.5 rad/s in small: a mass on
//! a spring with a massless contact point behind a stiffer spring (a massless boundary), lightly
//! damped and forced above its resonance, where the offset homotopy from the contact-free orbit
//! does not reach the orbit (found by scanning ω, the gap and k_c; not tuned to the pilot).
use crate::common::compare::{difference, max_abs};
use periodic_contact::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};
use periodic_contact::periodic::{LcpMethod, OutputSelection, PeriodicProblem, SolverSettings};
use periodic_contact::time::{Discretization, Scheme};

/// The mass (DOF 0, m = 1, k1 = 1, c = 0.01) and the massless point (DOF 1) behind k2 = 30, a
/// compliant stop k_c = 30 at `gap` on the point, unit force at `omega` (tests/massless_polish.rs's model).
fn point_on_a_stop(gap: f64, omega: f64) -> Model {
    let rows = |a: [[f64; 2]; 2]| Matrix::from_rows(&a.iter().map(|r| r.to_vec()).collect::<Vec<_>>());
    let (c, k2) = (0.01, 30.0);
    Model {
        structure: Structure {
            mass: rows([[1.0, 0.0], [0.0, 0.0]]),
            stiffness: rows([[1.0 + k2, -k2], [-k2, k2]]),
            damping: Some(rows([[c, 0.0], [0.0, 0.0]])),
        },
        forces: vec![Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } }],
        contacts: vec![Contact::on_dof(1, 1.0, gap, Compliance::Compliant { stiffness: 30.0 })],
        frequency: omega,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    }
}

fn with(method: LcpMethod) -> PeriodicProblem {
    at(3.0, 1.12, method)
}

fn at(gap: f64, omega: f64, method: LcpMethod) -> PeriodicProblem {
    let outputs = OutputSelection { displacement: vec![0, 1], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Cds, steps: 128, pairing: None };
    PeriodicProblem::new(point_on_a_stop(gap, omega), disc, outputs, SolverSettings { method, ..SolverSettings::default() }).unwrap()
}

#[test]
fn a_cold_shooting_miss_is_solved_from_a_bds1_pilot_and_agrees_with_lemke() {
    // The premise: cold shooting alone (contact-free start, offset homotopy) misses here.
    let alone = with(LcpMethod::Shooting).solve();
    assert!(alone.is_err(), "cold shooting solved it: the case no longer tests the pilot");
    let piloted = with(LcpMethod::Auto).solve().unwrap();
    let lemke = with(LcpMethod::Lemke).solve().unwrap();
    let d = difference(&piloted, &lemke);
    eprintln!("{}; residual {:.1e}; lemke {} pivots; difference {d:.1e}", piloted.lcp.path, piloted.lcp.residual, lemke.lcp.pivots);
    assert!(piloted.lcp.path.contains("bds1 pilot") && !piloted.lcp.path.contains("fallback"), "{}", piloted.lcp.path);
    assert!(max_abs(&piloted.contacts[0].force) > 0.0, "the stop is never reached");
    assert!(d <= 1e-10, "the piloted solve differs from lemke by {d:.3e}");
}

/// Where the pilot misses too (gap 1, ω = 1.39: bds1's cold shooting misses as cds's does, found
/// by the same scan), `auto` falls back to dense Lemke as before the pilot (at N = 128 before the
/// neighbouring ω's: dense Lemke is the cheaper there): the path shows the
/// missed shooting and the fallback, and the answer is certified.
#[test]
fn where_the_pilot_misses_too_auto_falls_back_to_lemke() {
    assert!(at(1.0, 1.39, LcpMethod::Shooting).solve().is_err(), "cold shooting solved it");
    let r = at(1.0, 1.39, LcpMethod::Auto).solve().unwrap();
    eprintln!("{}", r.lcp.path);
    let (first, fallback) = r.lcp.path.split_once("; fallback: ").expect("a fallback");
    assert!(first.contains("shooting") && !first.ends_with("→ solved"), "{}", r.lcp.path);
    assert!(fallback.starts_with("dense lexicographic Lemke") && fallback.contains("→ solved"), "{}", r.lcp.path);
    assert!(r.lcp.residual <= 1e-9);
}

/// Where cold shooting and the bds1 pilot miss and dense Lemke is dear (N = 4096 here: ≈ 7 s
/// projected), `auto` solves cold at a neighbouring ω (± 0.5 … 2 %) and steps back warm
/// (`pilot.rs`'s `from_neighbour`): certified, equal to dense Lemke, no dense fallback. Found by
/// scanning gap ∈ {0.5, 1, 1.5, 2, 3}, ω ∈ [0.9, 1.7) at k = 128 (8 such cases, within 5e-14 of
/// Lemke there), then k = 4096; the real blade, N = 17 408, is where Lemke is refused
/// (validation/RECORD.md "Cold misses").
#[test]
fn where_the_pilot_misses_a_neighbouring_cold_solve_is_stepped_back_and_agrees_with_lemke() {
    let at = |gap: f64, omega: f64, method: LcpMethod| {
        let outputs = OutputSelection { displacement: vec![0, 1], velocity: vec![], acceleration: vec![], contacts: true };
        let disc = Discretization { scheme: Scheme::Cds, steps: 4096, pairing: None };
        PeriodicProblem::new(point_on_a_stop(gap, omega), disc, outputs, SolverSettings { method, ..SolverSettings::default() }).unwrap()
    };
    for (gap, omega) in [(0.5, 1.48), (1.5, 1.27)] {
        assert!(at(gap, omega, LcpMethod::Shooting).solve().is_err(), "gap {gap}, ω {omega}: cold shooting solved it");
        let r = at(gap, omega, LcpMethod::Auto).solve().unwrap();
        let lemke = at(gap, omega, LcpMethod::Lemke).solve().unwrap();
        let d = difference(&r, &lemke);
        eprintln!("gap {gap}, ω {omega}: {}; difference {d:.1e}", r.lcp.path);
        assert!(r.lcp.path.contains("reached from a cold solve at ω") && !r.lcp.path.contains("fallback"), "{}", r.lcp.path);
        assert!(max_abs(&r.contacts[0].force) > 0.0, "the stop is never reached");
        assert!(d <= 1e-10 && r.lcp.residual <= 1e-9, "gap {gap}, ω {omega}: differs from lemke by {d:.3e}");
    }
}
