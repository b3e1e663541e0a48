//! Events of different contacts passing each other on the exact branch (issue 24; the real
//! blade's 17 tips on a massless boundary): not a change of topology. Two uncoupled masses,
//! each with a massless contact point behind a spring k2 resting on a rigid stop (no impulse at
//! the closing, a held arc, a release: identity state maps), forced at different phases. Each
//! mass is the 1-DOF compliant stop of stiffness k2 (`exact::CompliantStopOrbit`, closed form:
//! tests/massless_polish.rs), so the orbit, its events and multipliers are known on the whole
//! branch. Between ω = 1.2 and 1.3 mass B's closing passes mass A's, and so does its release.
use periodic_contact::analysis::continuation::{self, ContinuationSettings, EventKind, Parameter, Source};
use periodic_contact::exact::{CompliantStopOrbit, Oscillator};
use periodic_contact::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};
use periodic_contact::periodic::{OutputSelection, PeriodicProblem, SolverSettings};
use periodic_contact::time::{Discretization, Scheme};

const C: f64 = 0.05;
/// The masses' own springs (A, B): B's events move faster with ω than A's.
const K1: [f64; 2] = [1.0, 0.8];
const K2: f64 = 30.0;
const G0: f64 = 1.0;
const F: f64 = 1.0;
/// B's forcing leads A's by this fraction of the period: its events come that much earlier.
const LEAD: f64 = 0.0095;

/// DOFs: mass A, its point, mass B, its point; the stops on the points.
fn model(omega: f64) -> Model {
    let mut k = vec![vec![0.0; 4]; 4];
    let mut m = vec![vec![0.0; 4]; 4];
    let mut c = vec![vec![0.0; 4]; 4];
    for (b, k1) in K1.iter().enumerate() {
        let (x, p) = (2 * b, 2 * b + 1);
        k[x][x] = k1 + K2;
        k[x][p] = -K2;
        k[p][x] = -K2;
        k[p][p] = K2;
        m[x][x] = 1.0;
        c[x][x] = C;
    }
    let force = |dof: usize, phase: f64| Force { dof, term: Harmonic { amplitude: F, harmonic: 1, phase } };
    Model {
        structure: Structure { mass: Matrix::from_rows(&m), stiffness: Matrix::from_rows(&k), damping: Some(Matrix::from_rows(&c)) },
        forces: vec![force(0, 0.0), force(2, 2.0 * std::f64::consts::PI * LEAD)],
        contacts: vec![Contact::on_dof(1, 1.0, G0, Compliance::Rigid), Contact::on_dof(3, 1.0, G0, Compliance::Rigid)],
        frequency: omega,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    }
}

/// Mass `b`'s closed-form orbit at ω (B's a fraction LEAD of the period earlier).
fn closed_form(b: usize, omega: f64) -> CompliantStopOrbit {
    CompliantStopOrbit::solve(&Oscillator::new(1.0, C, K1[b], F, omega), K2, G0, None).unwrap()
}

/// Closing and release times of mass `b` as fractions of the period.
fn events(b: usize, omega: f64) -> (f64, f64) {
    let o = closed_form(b, omega);
    let shift = if b == 1 { LEAD } else { 0.0 };
    let t = o.period();
    ((o.entry_time().unwrap() / t - shift).rem_euclid(1.0), (o.exit_time().unwrap() / t - shift).rem_euclid(1.0))
}

/// The walk from 1.2 to 1.3 passes both swaps on the exact orbit, with no event of the branch
/// (a swap is no grazing), and every point's amplitudes and nonzero multipliers are the closed
/// forms' (the multipliers are the monodromy's, the Jacobian's state block at the point: a
/// discontinuous Jacobian at the swap would show there).
#[test]
#[ignore = "not yet: the crossing with event 0 at ω = 1.24906 stalls the corrector and restarts from the grid (README: The real blade's exact branch)"]
fn events_of_two_massless_contacts_pass_each_other_on_the_exact_branch() {
    let (lo, hi) = (1.2, 1.3);
    // The precondition, from the closed forms: B's closing and release come before A's at 1.2, after at 1.3.
    let (a0, b0) = (events(0, lo), events(1, lo));
    let (a1, b1) = (events(0, hi), events(1, hi));
    eprintln!("closing A/B {:.4}/{:.4} → {:.4}/{:.4}; release {:.4}/{:.4} → {:.4}/{:.4}", a0.0, b0.0, a1.0, b1.0, a0.1, b0.1, a1.1, b1.1);
    assert!(b0.0 < a0.0 && b1.0 > a1.0 && b0.1 < a0.1 && b1.1 > a1.1, "the closings and releases must cross in the range");

    let outputs = OutputSelection { displacement: vec![0, 2], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Cds, steps: 256, pairing: None };
    let p = PeriodicProblem::new(model(lo), disc, outputs, SolverSettings::default()).unwrap();
    let start = std::time::Instant::now();
    let b = continuation::run(&p, Parameter::Frequency, lo, hi, &ContinuationSettings::default(), &|_| {}).unwrap();
    eprintln!("{} points in {:.2} s: {}", b.points.len(), start.elapsed().as_secs_f64(), b.stop);
    assert!(b.reached(), "{}", b.stop);
    assert!(b.points.iter().all(|q| q.source == Source::Exact), "{}", b.stop);
    for e in b.events() {
        eprintln!("event at ω = {}: {:?} {}", e.parameter, e.event, e.detail);
    }
    let kinds: Vec<EventKind> = b.events().filter_map(|e| e.event).collect();
    assert!(kinds.is_empty(), "no event on this branch: {kinds:?}");
    let (mut amp, mut mult) = (0.0f64, 0.0f64);
    for q in &b.points {
        let w = q.parameter;
        let forms = [closed_form(0, w), closed_form(1, w)];
        for (j, o) in forms.iter().enumerate() {
            amp = amp.max((q.amplitude[j] - 0.5 * o.peak_to_peak()).abs() / (0.5 * o.peak_to_peak()));
        }
        let mut want: Vec<num_complex::Complex64> = forms.iter().flat_map(|o| o.floquet_multipliers()).collect();
        let mut got: Vec<num_complex::Complex64> = q.multipliers.iter().copied().filter(|z| z.norm() > 1e-9).collect();
        let key = |c: &num_complex::Complex64| (c.norm(), c.im);
        got.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
        want.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
        assert_eq!(got.len(), 4, "ω = {w}: four nonzero multipliers, {got:?}");
        mult = got.iter().zip(&want).fold(mult, |m, (g, x)| m.max((g - x).norm()));
    }
    eprintln!("largest amplitude error {amp:.1e} (relative), multiplier error {mult:.1e}");
    assert!(amp < 1e-9, "amplitudes off the closed form by {amp:.1e}");
    assert!(mult < 1e-7, "multipliers off the closed form by {mult:.1e}");
}
