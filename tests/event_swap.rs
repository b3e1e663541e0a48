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
        let want: Vec<num_complex::Complex64> = forms.iter().flat_map(|o| o.floquet_multipliers()).collect();
        let got: Vec<num_complex::Complex64> = q.multipliers.iter().copied().filter(|z| z.norm() > 1e-9).collect();
        assert_eq!(got.len(), 4, "ω = {w}: four nonzero multipliers, {got:?}");
        mult = mult.max(multiplier_distance(&got, &want));
    }
    eprintln!("largest amplitude error {amp:.1e} (relative), multiplier error {mult:.1e}");
    assert!(amp < 1e-9, "amplitudes off the closed form by {amp:.1e}");
    assert!(mult < 1e-7, "multipliers off the closed form by {mult:.1e}");
}

/// The gap of the grazing branch: the linear orbit's peak reaches it at ω_g below resonance.
const GRAZE_GAP: f64 = 2.0;

/// One mass (DOF 0) with a massless contact point (DOF 1) behind K2 and a rigid stop GRAZE_GAP
/// away: the 1-DOF stop of stiffness K2 (`exact::CompliantStopOrbit`).
fn grazing_model(omega: f64) -> Model {
    let rows = |a: [[f64; 2]; 2]| Matrix::from_rows(&a.iter().map(|r| r.to_vec()).collect::<Vec<_>>());
    Model {
        structure: Structure {
            mass: rows([[1.0, 0.0], [0.0, 0.0]]),
            stiffness: rows([[K1[0] + K2, -K2], [-K2, K2]]),
            damping: Some(rows([[C, 0.0], [0.0, 0.0]])),
        },
        forces: vec![Force { dof: 0, term: Harmonic { amplitude: F, harmonic: 1, phase: 0.0 } }],
        contacts: vec![Contact::on_dof(1, 1.0, GRAZE_GAP, Compliance::Rigid)],
        frequency: omega,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    }
}

/// The walk from 0.6 to 0.8 rad/s: below ω_g the point never reaches the stop (the linear
/// orbit, amplitude F/√((k1 − ω²)² + (cω)²)); at ω_g its clearance touches zero, and a closing
/// and a release are born together there (no impulse: the point is massless) with a held arc of
/// zero length between them that grows. The grazing lies where the linear amplitude is the gap
/// (closed form: (k1 − u)² + c²u = (F/g)², u = ω²), and the branch past it is the closed form's
/// held-arc orbit, continued on the exact orbit (not restarted from the grid).
#[test]
fn a_massless_contact_grazing_starts_its_held_arc_on_the_exact_branch() {
    check_grazing_walk(0.6, 0.8);
}

/// The same branch walked down, from 0.75 to 0.6 rad/s (at 0.8 the grid's cold solve settles on
/// another orbit): the held arc shrinks to nothing at ω_g
/// as √(ω − ω_g) (the free clearance's minimum is quadratic in time), so the held family's λ
/// turns there (its tangent's λ component vanishes with the arc); the walk must not report that
/// turn as a fold and turn back (the real blade at 2298.19 rad/s), but remove the closing and the
/// release (the point flies free) and go on down on the linear orbit.
#[test]
fn a_massless_contact_held_arc_vanishing_ends_in_flight_on_the_exact_branch() {
    check_grazing_walk(0.75, 0.6);
}

/// The walk from `from` to `to` over the grazing of [`grazing_model`]: one grazing at the closed
/// form's ω_g, no fold, every point exact, amplitudes and multipliers the closed form's.
fn check_grazing_walk(from: f64, to: f64) {
    let (lo, hi) = (from.min(to), from.max(to));
    let graze = graze_at(GRAZE_GAP);
    let linear = |w: f64| F / ((K1[0] - w * w).powi(2) + (C * w).powi(2)).sqrt();
    assert!(linear(lo) < GRAZE_GAP && linear(hi) > GRAZE_GAP, "the grazing must lie in the range");
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Cds, steps: 256, pairing: None };
    let p = PeriodicProblem::new(grazing_model(from), disc, outputs, SolverSettings::default()).unwrap();
    let start = std::time::Instant::now();
    let b = continuation::run(&p, Parameter::Frequency, from, to, &ContinuationSettings::default(), &|_| {}).unwrap();
    eprintln!("{} points in {:.2} s: {}", b.points.len(), start.elapsed().as_secs_f64(), b.stop);
    for e in b.events() {
        eprintln!("event at ω = {}: {:?} {}", e.parameter, e.event, e.detail);
    }
    assert!(b.reached(), "{}", b.stop);
    assert!(b.points.iter().all(|q| q.source == Source::Exact), "{}", b.stop);
    assert!(b.events().all(|e| e.event != Some(EventKind::Fold)), "no fold on this branch");
    let grazings: Vec<f64> = b.events().filter(|e| e.event == Some(EventKind::Grazing)).map(|e| e.parameter).collect();
    assert_eq!(grazings.len(), 1, "one grazing: {grazings:?}");
    eprintln!("grazing at {:.12} (closed form {graze:.12})", grazings[0]);
    assert!((grazings[0] - graze).abs() < 1e-8, "grazing at {} instead of {graze}", grazings[0]);
    assert!(b.events().all(|e| !e.detail.contains("not traced")), "the branch past the grazing is the exact orbit's");
    let (mut amp, mut mult, mut held, mut free) = (0.0f64, 0.0f64, 0, 0);
    // The closed form's held-arc orbits from hi down, each Newton seeded by the one before (past
    // the period doubling near ω_g the simulation that seeds it by default settles elsewhere).
    let mut points: Vec<&periodic_contact::analysis::continuation::BranchPoint> = b.points.iter().filter(|q| (q.parameter - graze).abs() > 1e-6).collect();
    points.sort_by(|a, b| b.parameter.total_cmp(&a.parameter));
    let mut seed = None;
    for q in points {
        let w = q.parameter;
        let osc = Oscillator::new(1.0, C, K1[0], F, w);
        let o = if w > graze {
            CompliantStopOrbit::solve(&osc, K2, GRAZE_GAP, seed).unwrap()
        } else {
            CompliantStopOrbit::solve(&osc, K2, GRAZE_GAP, None).unwrap()
        };
        assert_eq!(o.has_contact(), w > graze, "ω = {w}: the closed form's contact");
        if w > graze {
            seed = Some([o.entry_time().unwrap(), o.exit_time().unwrap(), o.entry_velocity().unwrap()]);
        }
        let want = if w > graze { 0.5 * o.peak_to_peak() } else { linear(w) };
        amp = amp.max((q.amplitude[0] - want).abs() / want);
        if w > graze {
            held += 1;
            let got: Vec<num_complex::Complex64> = q.multipliers.iter().copied().filter(|z| z.norm() > 1e-9).collect();
            assert_eq!(got.len(), 2, "ω = {w}: two nonzero multipliers, {got:?}");
            mult = mult.max(multiplier_distance(&got, &o.floquet_multipliers()));
            // At the period doubling itself (|μ| = 1 within the multipliers' tolerance) either side is right.
            let on_circle = o.floquet_multipliers().iter().any(|z| (z.norm() - 1.0).abs() < 1e-7);
            assert!(on_circle || q.stable == o.is_stable(), "ω = {w}: stability against the closed form's");
        } else {
            free += 1;
        }
    }
    eprintln!("{held} points with the held arc, {free} free; largest amplitude error {amp:.1e} (relative), multiplier error {mult:.1e}");
    assert!(held >= 3 && free >= 3, "both sides of the grazing are walked");
    assert!(amp < 1e-9, "amplitudes off the closed form by {amp:.1e}");
    assert!(mult < 1e-7, "multipliers off the closed form by {mult:.1e}");
}

/// The largest distance from a multiplier of `a` to the nearest of `b`, and from `b` to `a`
/// (equal moduli make any sort order fragile).
fn multiplier_distance(a: &[num_complex::Complex64], b: &[num_complex::Complex64]) -> f64 {
    let one_way = |x: &[num_complex::Complex64], y: &[num_complex::Complex64]| {
        x.iter().map(|p| y.iter().map(|q| (p - q).norm()).fold(f64::MAX, f64::min)).fold(0.0f64, f64::max)
    };
    one_way(a, b).max(one_way(b, a))
}

/// Mass B's gap in [`inside_model`]: B is in contact all over the walk (one held arc a period;
/// at 1.0 its point hits twice), A grazes at GRAZE_GAP.
const B_GAP: f64 = 1.8;

/// Two uncoupled masses with massless contact points (as [`model`], both of spring K1[0]): A's
/// stop GRAZE_GAP away, B's B_GAP, B's forcing leading A's by `lead` of the period.
fn inside_model(omega: f64, lead: f64) -> Model {
    let mut m = model(omega);
    let mut k: Vec<Vec<f64>> = (0..4).map(|i| (0..4).map(|j| m.structure.stiffness.get(i, j)).collect()).collect();
    k[2][2] = K1[0] + K2;
    m.structure.stiffness = Matrix::from_rows(&k);
    m.contacts[0].gap = GRAZE_GAP;
    m.contacts[1].gap = B_GAP;
    m.forces[1].term.phase = 2.0 * std::f64::consts::PI * lead;
    m
}

/// A's held arc vanishing with B's closing inside it (the real blade at 2278.97466 rad/s:
/// contact 13's arc with contact 15's landing in it, which the walk did not see, the events not
/// being adjacent, and stalled on). B's forcing is phased so that its closing falls at A's
/// grazing instant at ω_g (closed forms: the linear orbit's peak at ψ/ω, ψ = atan2(cω, k1 − ω²);
/// B's entry time), so that A's arc, √(ω − ω_g) wide, keeps B's closing (moving linearly in ω)
/// inside it down to ω_g. The walk from 0.75 to 0.6 must record that grazing at the closed form's
/// ω_g (the linear amplitude equal to the gap), and B's own further down at its gap's, every point
/// exact (measured: 1.2e-12 and 4.6e-13 from the closed forms, 61 points, 0.5 s).
#[test]
fn a_massless_held_arc_vanishing_with_another_contacts_closing_inside_it() {
    let graze = graze_at(GRAZE_GAP);
    let psi = (C * graze).atan2(K1[0] - graze * graze);
    let ob = CompliantStopOrbit::solve(&Oscillator::new(1.0, C, K1[0], F, graze), K2, B_GAP, None).unwrap();
    let lead = (ob.entry_time().unwrap() / ob.period() - psi / (2.0 * std::f64::consts::PI)).rem_euclid(1.0);
    eprintln!("lead {lead:.6}");
    // A's arc vanishing (B's closing inside it), then B's own at its gap's ω_g further down.
    let br = walk_two_grazings(inside_model(0.75, lead), (0.75, 0.6), (graze, graze_at(B_GAP)));
    assert!(br.events().all(|e| !e.detail.contains("not traced")), "the branch past the grazing is the exact orbit's");
}

/// (k1 − u)² + c²u − (F/g)² = 0, the root below resonance: where A's linear amplitude is the gap g.
fn graze_at(g: f64) -> f64 {
    let (b, c0) = (C * C - 2.0 * K1[0], K1[0] * K1[0] - (F / g).powi(2));
    ((-b - (b * b - 4.0 * c0).sqrt()) / 2.0).sqrt()
}

/// The walk of the two-mass `model` over `from → to`, every point exact and the range reached,
/// with one grazing of each contact, at `want` (A's, B's) within 1e-8.
fn walk_two_grazings(model: Model, (from, to): (f64, f64), want: (f64, f64)) -> continuation::Branch {
    let outputs = OutputSelection { displacement: vec![0, 2], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Cds, steps: 256, pairing: None };
    let p = PeriodicProblem::new(model, disc, outputs, SolverSettings::default()).unwrap();
    let start = std::time::Instant::now();
    let br = continuation::run(&p, Parameter::Frequency, from, to, &ContinuationSettings::default(), &|_| {}).unwrap();
    eprintln!("{} points in {:.2} s: {}", br.points.len(), start.elapsed().as_secs_f64(), br.stop);
    for e in br.events() {
        eprintln!("event at ω = {:.12}: {:?} {}", e.parameter, e.event, e.detail);
    }
    assert!(br.reached(), "{}", br.stop);
    assert!(br.points.iter().all(|q| q.source == Source::Exact), "{}", br.stop);
    let grazings: Vec<(f64, bool)> =
        br.events().filter(|e| e.event == Some(EventKind::Grazing)).map(|e| (e.parameter, e.detail.starts_with("contact 0"))).collect();
    assert_eq!(grazings.len(), 2, "two grazings: {grazings:?}");
    for (at, a) in grazings {
        let want = if a { want.0 } else { want.1 };
        eprintln!("grazing of {} at {at:.12} (closed form {want:.12})", if a { "A" } else { "B" });
        assert!((at - want).abs() < 1e-8, "grazing at {at} instead of {want}");
    }
    br
}

/// Mass B's spring in [`next_model`]: its resonance (√0.05 ≈ 0.22 rad/s) well below A's grazing,
/// so that B's free amplitude grows as ω falls there (with 0.3 B's branch folds 3e-6 rad/s past its
/// grazing, a real fold: |μ| through 1).
const K1_NEXT: f64 = 0.05;

/// Two uncoupled masses with massless contact points: A as [`grazing_model`]'s (stop GRAZE_GAP
/// away), B of spring K1_NEXT with its stop `gap_b` away.
fn next_model(omega: f64, gap_b: f64) -> Model {
    let mut m = inside_model(omega, 0.0);
    let mut k: Vec<Vec<f64>> = (0..4).map(|i| (0..4).map(|j| m.structure.stiffness.get(i, j)).collect()).collect();
    k[2][2] = K1_NEXT + K2;
    m.structure.stiffness = Matrix::from_rows(&k);
    m.contacts[1].gap = gap_b;
    m
}

/// A's held arc vanishing with another contact's change a short way on (the real blade at
/// 1124.25 rad/s: contact 16's held arc merged, the walk then turned back up and retraced its
/// events). Walking down, A's arc vanishes at A's ω_g; B (above its resonance) is free there and
/// its clearance touches zero 2e-5 rad/s lower, at ω_B (its gap is its linear amplitude there,
/// F/√((k1 − ω²)² + (cω)²)). The orbit without A's arc is admissible where the walk merges it;
/// the change sought ahead of that point must be A's, not B's (found 1e-3 of the range on):
/// both grazings at their closed forms, λ falling at every point, the range reached.
#[test]
fn a_massless_held_arc_vanishing_just_before_another_contacts_grazing() {
    let graze = graze_at(GRAZE_GAP);
    let next = graze - 2e-5;
    let gap_b = F / ((K1_NEXT - next * next).powi(2) + (C * next).powi(2)).sqrt();
    eprintln!("gap B {gap_b:.9}");
    let br = walk_two_grazings(next_model(0.75, gap_b), (0.75, 0.7), (graze, next));
    let turned = br.points.windows(2).find(|w| w[1].parameter > w[0].parameter + 1e-12);
    assert!(turned.is_none(), "λ turned back: {:?}", turned.map(|w| (w[0].parameter, w[1].parameter)));
}
