//! Branches through the C API (issue 13 item 6, issue 24 item 4): re-solves continue the orbit
//! along its exact branch, jump where it ends at a fold, and report the orbit's Floquet stability. References: the
//! damped linear oscillator's multipliers e^{−cT/2m} (a contact-free orbit), its grazing
//! frequency |1 − ω² + icω| = F/gap (where the contact-free branch of a run-down ends), the
//! contact-free amplitude after the run-up's jump, and the closed-form impact oscillator of
//! src/exact/rigid.rs (its orbits and the fold of its stable impacting orbit).
use periodic_contact::analysis::continuation::{self, ContinuationSettings, Parameter};
use periodic_contact::capi::*;
use periodic_contact::exact::{Oscillator, RigidRegime, RigidStopOrbit};
use periodic_contact::scene::Scene;
use std::ffi::CString;

/// The drop-in demo's oscillator (validation/demo/runup.py): m = 1, k = 1, c = 0.05,
/// F = 0.2 cos ωt, a compliant stop (stiffness 10) at clearance 1; cds, k = 256.
const DEMO: &str = "[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n[damping]\nmatrix = [[0.05]]\n[excitation]\nfrequency = 1.0\n\
[[force]]\ndof = 0\namplitude = 0.2\n[[contact]]\ndof = 0\ndirection = 1\ngap = 1.0\nstiffness = 10.0\n\
[discretization]\nscheme = \"cds\"\nsteps = 256\nerror_estimate = \"none\"\n[output]\ndisplacement = [0]\nstability = true\n";
const C: f64 = 0.05;
const F: f64 = 0.2;

/// Contact-free amplitude F/|1 − ω² + icω|.
fn linear(w: f64) -> f64 {
    F / ((1.0 - w * w).powi(2) + (C * w).powi(2)).sqrt()
}

struct Step {
    jumped: bool,
    fold: f64,
    from: f64,
    to: f64,
    stable: bool,
    multiplier: f64,
    /// Half the peak-to-peak of displacement 0 over the k instants.
    amplitude: f64,
    /// (t_j, displacement 0) at the k instants.
    samples: Vec<(f64, f64)>,
}

/// The demo's scene on k instants.
fn demo(k: usize) -> String {
    DEMO.replace("steps = 256", &format!("steps = {k}"))
}

/// Solves `scene` at each frequency in turn on one problem handle.
fn ramp_scene(scene: &str, omegas: &[f64]) -> Vec<Step> {
    let text = CString::new(scene).unwrap();
    unsafe {
        let p = pc_problem_from_scene_text(text.as_ptr());
        assert!(!p.is_null());
        assert_eq!(pc_problem_set_stability(p, 1), PC_OK);
        let steps = omegas
            .iter()
            .map(|&w| {
                assert_eq!(pc_problem_set_frequency(p, w), PC_OK);
                let r = pc_problem_solve(p);
                assert!(!r.is_null(), "solve at {w}");
                let (mut jumped, mut fold, mut from, mut to, mut n) = (0, 0.0, 0.0, 0.0, 0usize);
                assert_eq!(pc_result_jump(r, &mut jumped, &mut fold, &mut from, &mut to, &mut n), PC_OK);
                let (mut computed, mut stable, mut mu) = (0, 0, 0.0);
                assert_eq!(pc_result_stability(r, &mut computed, &mut stable, &mut mu, std::ptr::null_mut()), PC_OK);
                assert_eq!(computed, 1, "stability at {w}");
                let k = pc_result_steps(r);
                let mut x = vec![0.0; k];
                assert_eq!(pc_result_displacement(r, 0, x.as_mut_ptr(), k), PC_OK);
                let amplitude = (x.iter().fold(f64::MIN, |a, &b| a.max(b)) - x.iter().fold(f64::MAX, |a, &b| a.min(b))) / 2.0;
                let mut time = vec![0.0; k];
                assert_eq!(pc_result_time(r, time.as_mut_ptr(), k), PC_OK);
                let samples = time.into_iter().zip(x).collect();
                pc_result_free(r);
                Step { jumped: jumped == 1, fold, from, to, stable: stable == 1, multiplier: mu, amplitude, samples }
            })
            .collect();
        pc_problem_free(p);
        steps
    }
}

fn ramp(omegas: &[f64]) -> Vec<Step> {
    ramp_scene(DEMO, omegas)
}

/// From `a` to `b` by `coarse`, then from `b` to `c` by `fine` (each end included once).
fn path(a: f64, b: f64, c: f64, coarse: f64, fine: f64) -> Vec<f64> {
    let leg = |x: f64, y: f64, h: f64| {
        let n = ((y - x).abs() / h).ceil() as usize;
        (0..n).map(move |i| x + (y - x) * i as f64 / n as f64)
    };
    leg(a, b, coarse).chain(leg(b, c, fine)).chain([c]).collect()
}

#[test]
fn a_contact_free_orbit_has_the_multipliers_of_its_damping() {
    let s = ramp(&[1.3]);
    let exact = (-C / 2.0 * 2.0 * std::f64::consts::PI / 1.3).exp();
    assert!((s[0].multiplier - exact).abs() <= 1e-4, "{} vs e^(-cT/2) = {exact}", s[0].multiplier);
    assert!(s[0].stable);
}

/// Issue 24 (Must show): at k = 256, 512 and 1024 the run-up and the run-down follow the exact
/// branch and jump at the first step past its fold, which they report within 1e-4 (relative) of
/// the continuation's fold; the run-down's fold is next to the analytic grazing of the
/// contact-free orbit, |1 − ω² + icω| = F/gap. Ramps: 0.01 rad/s steps, 1e-4 rad/s near the folds.
#[test]
fn a_run_up_and_a_run_down_jump_once_at_their_folds() {
    // |1 − ω² + icω| = F/gap: ω² = (1.9975 + √0.15000625)/2.
    let grazing = ((1.9975 + 0.150_006_25f64.sqrt()) / 2.0).sqrt();
    let fine = 1e-4;
    for k in [256, 512, 1024] {
        let scene = demo(k);
        let p = Scene::parse(&scene, "demo").unwrap().to_problem("demo").unwrap();
        let b = continuation::run(&p, Parameter::Frequency, 1.0, 1.45, &ContinuationSettings::default(), &|_| {}).unwrap();
        let folds: Vec<f64> = b.events().filter(|q| q.event == Some(continuation::EventKind::Fold)).map(|q| q.parameter).collect();
        let (tip, lower) = (folds.iter().fold(0.0f64, |a, &f| a.max(f)), folds.iter().fold(f64::MAX, |a, &f| a.min(f)));
        assert!((lower - grazing).abs() <= 1e-4 * grazing, "k = {k}: the lower fold {lower} vs grazing {grazing}");

        // The run-up stays on the contact branch up to its tip, then falls to the contact-free orbit.
        let up = path(1.0, 1.365, 1.375, 0.01, fine);
        let s = ramp_scene(&scene, &up);
        let jumps: Vec<usize> = (0..s.len()).filter(|&i| s[i].jumped).collect();
        assert_eq!(jumps.len(), 1, "k = {k}: run-up jumps at {:?}", jumps.iter().map(|&i| up[i]).collect::<Vec<_>>());
        let (i, j) = (jumps[0], &s[jumps[0]]);
        assert!((j.fold - tip).abs() <= 1e-4 * tip, "k = {k}: run-up jump at {} vs the continuation's fold {tip}", j.fold);
        assert!(up[i - 1] <= tip && tip <= up[i], "k = {k}: the jump at {} is not the first step past the fold {tip}", up[i]);
        assert!(j.from > 2.5 && (j.to - linear(up[i])).abs() <= 1e-3 * j.to, "k = {k}: amplitudes {} -> {} (linear {})", j.from, j.to, linear(up[i]));
        assert!(s[..i].iter().all(|x| x.stable), "k = {k}: the followed branch is stable");

        // The run-down stays on the contact-free orbit down to its grazing, then jumps up.
        let down = path(1.45, 1.095, 1.085, 0.01, fine);
        let s = ramp_scene(&scene, &down);
        let jumps: Vec<usize> = (0..s.len()).filter(|&i| s[i].jumped).collect();
        assert_eq!(jumps.len(), 1, "k = {k}: run-down jumps at {:?}", jumps.iter().map(|&i| down[i]).collect::<Vec<_>>());
        let (i, j) = (jumps[0], &s[jumps[0]]);
        assert!((j.fold - lower).abs() <= 1e-4 * lower, "k = {k}: run-down jump at {} vs the continuation's fold {lower}", j.fold);
        assert!(down[i] <= lower && lower <= down[i - 1], "k = {k}: the jump at {} is not the first step past the fold {lower}", down[i]);
        assert!((j.from - 1.0).abs() < 0.01 && j.to > 1.2, "k = {k}: amplitudes {} -> {}", j.from, j.to);
        assert!(s.iter().all(|x| x.stable), "k = {k}: both branches of the run-down are stable");
    }
}

/// Issue 24: NLvib 03's slow run-up from 0.64 to 0.72 rad/s (C API, 0.001 rad/s steps) stays on
/// the upper branch at k = 256 and 512, where the discrete follow fell to the lower one (0.348).
/// Reference: the exact-flow shooting of validation/nlvib03 (reference.json, `checks`: the upper
/// orbit at 0.72, A0 = 1.284995). Tolerance: the grid's O(h²) error, 1e-3 (measured 4.1e-4 at
/// k = 256).
#[test]
fn nlvib03_slow_run_up_stays_on_the_upper_branch() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/validation/nlvib03/reference.json")).unwrap();
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    let upper = reference["checks"]["stable_reached"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["omega"].as_f64() == Some(0.72))
        .map(|c| c["amplitude_0"].as_f64().unwrap())
        .fold(0.0f64, f64::max);
    assert!(upper > 1.0, "the reference's upper orbit at 0.72: {upper}");
    let scene = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/validation/nlvib03/nlvib03.toml")).unwrap();
    let omegas: Vec<f64> = (0..=80).map(|i| 0.64 + 0.08 * i as f64 / 80.0).collect();
    for k in [256, 512] {
        let scene = scene.replace("steps = 4096", &format!("steps = {k}")) + "\n[output]\ndisplacement = [0, 1]\n";
        let s = ramp_scene(&scene, &omegas);
        let end = s.last().unwrap().amplitude;
        assert!(s.iter().all(|x| !x.jumped), "k = {k}: jumps at {:?}", s.iter().filter(|x| x.jumped).map(|x| x.fold).collect::<Vec<_>>());
        assert!((end - upper).abs() <= 1e-3 * upper, "k = {k}: the run-up ends at amplitude {end}, the upper orbit's is {upper}");
    }
}

/// One continuation walks the demo's whole S-curve, 1.0 → 1.45: up the stable contact branch,
/// around its resonance tip (a turn across kinks of the discrete map, where the hyperplane ahead
/// meets no orbit and the path crosses onto the next piece), down the unstable middle branch, and
/// around the fold at grazing onto the contact-free branch up to 1.45. Two folds and one grazing
/// are reported, not the wiggles of the discrete branch; the lower fold sits at the analytic
/// grazing; the middle branch is unstable; the contact-free orbits have the damped oscillator's
/// multiplier e^(−cT/2) and its amplitude F/|1 − ω² + icω|.
#[test]
fn one_walk_turns_at_both_folds_of_the_demo() {
    let p = Scene::parse(DEMO, "demo").unwrap().to_problem("demo").unwrap();
    let b = continuation::run(&p, Parameter::Frequency, 1.0, 1.45, &ContinuationSettings::default(), &|_| {}).unwrap();
    assert!(b.reached(), "{}", b.stop);
    let folds: Vec<usize> = (0..b.points.len()).filter(|&i| b.points[i].event == Some(continuation::EventKind::Fold)).collect();
    let grazings = b.events().filter(|q| q.event == Some(continuation::EventKind::Grazing)).count();
    let at: Vec<f64> = folds.iter().map(|&i| b.points[i].parameter).collect();
    assert_eq!((folds.len(), grazings), (2, 1), "folds at {at:?}");
    let grazing = ((1.9975 + 0.150_006_25f64.sqrt()) / 2.0).sqrt();
    assert!(at[0] > 1.36 && b.points[folds[0]].amplitude[0] > 2.5, "the resonance tip at {} ({})", at[0], b.points[folds[0]].amplitude[0]);
    assert!((at[1] - grazing).abs() <= 1e-4 * grazing, "the lower fold at {} vs grazing {grazing}", at[1]);
    // Between the folds: unstable, 1 % of the range off the lower fold and 2 % off the tip (there
    // the two sides nearly coincide, and the smoothed monodromy of the middle branch's pieces that
    // wiggle back up in ω reads |μ| < 1: measured down to 0.0072 below the tip).
    let middle: Vec<&continuation::BranchPoint> =
        b.points[folds[0]..folds[1]].iter().filter(|q| q.certified && q.parameter < at[0] - 0.009 && q.parameter > at[1] + 0.0045).collect();
    // (12 such points since the exact walk's state scale follows the orbit: longer steps.)
    assert!(middle.len() >= 10 && middle.iter().all(|q| !q.stable && q.max_multiplier > 1.0), "{} middle points", middle.len());
    // Past the lower fold, off the stop: the linear orbit, stable with |μ| = e^(−cT/2).
    let free: Vec<&continuation::BranchPoint> = b.points[folds[1]..].iter().filter(|q| q.certified && q.parameter > grazing + 0.01).collect();
    assert!(free.len() > 5);
    for q in free {
        let w = q.parameter;
        let mu = (-C / 2.0 * 2.0 * std::f64::consts::PI / w).exp();
        assert!((q.max_multiplier - mu).abs() <= 1e-3 && q.stable, "ω = {w}: |μ| {} vs {mu}", q.max_multiplier);
        assert!((q.amplitude[0] - linear(w)).abs() <= 1e-3 * linear(w), "ω = {w}: {} vs {}", q.amplitude[0], linear(w));
    }
}

/// The impact oscillator of tests/rigid_branch.rs: m = 1, c = 0.1, k = 1, F = cos ωt, a rigid stop
/// (plastic impacts) at clearance 1.5; bds1, k = 512, each answer polished.
const IMPACT: &str = "[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n[damping]\nmatrix = [[0.1]]\n[excitation]\nfrequency = 1.3\n\
[[force]]\ndof = 0\namplitude = 1.0\n[[contact]]\ndof = 0\ngap = 1.5\n\
[discretization]\nscheme = \"bds1\"\nsteps = 512\npolish = true\n[output]\ndisplacement = [0]\nstability = true\n";

/// The largest difference between a step's displacement at the instants and `orbit`'s.
fn off_closed_form(s: &Step, orbit: &RigidStopOrbit) -> f64 {
    s.samples.iter().map(|&(t, x)| (x - orbit.eval(t).0).abs()).fold(0.0, f64::max)
}

/// Issue 24 items 3–4 (rigid contact): a run-up through the fold of the impact oscillator's stable
/// impacting orbit and a run-down through the grazing of its contact-free orbit (where the
/// impacting branch born there turns back) follow the exact branch through the C API and jump once
/// each, at the first step past the closed form's fold (bisection on the existence of its stable
/// impacting orbit, src/exact/rigid.rs) and at the analytic grazing F/|1 − ω² + icω| = gap, within
/// 1e-4 (relative); before and after each jump the answer is the closed-form orbit (polished,
/// within 1e-6 of the gap at the instants). Ramps of 0.01 rad/s, 1e-4 near the fold.
#[test]
fn an_impact_oscillator_jumps_once_each_way_at_its_exact_fold() {
    let (gap, osc) = (1.5, |w: f64| Oscillator::new(1.0, 0.1, 1.0, 1.0, w));
    let impacting = |w: f64| RigidStopOrbit::with_contact(&osc(w), gap).ok().filter(|o| o.regime() == RigidRegime::Impacting);
    let (mut lo, mut hi) = (1.35, 1.45);
    assert!(impacting(lo).is_some() && impacting(hi).is_none());
    while hi - lo > 1e-10 {
        let mid = 0.5 * (lo + hi);
        if impacting(mid).is_some() { lo = mid } else { hi = mid }
    }
    let fold = lo;
    // |1 − ω² + icω| = F/gap: ω⁴ − (2 − c²)ω² + 1 − (F/gap)² = 0, the larger root.
    let (b, q) = (2.0 - 0.01, 1.0 - (1.0f64 / gap).powi(2));
    let grazing = ((b + (b * b - 4.0 * q).sqrt()) / 2.0).sqrt();
    let free = |w: f64| RigidStopOrbit::solve(&osc(w), gap).ok().filter(|o| o.regime() == RigidRegime::NoContact);
    // The orbit with contact (the stable impacting one) or the contact-free one, at ω.
    let closed_form = |contact: bool, w: f64| if contact { impacting(w) } else { free(w) }.unwrap_or_else(|| panic!("no closed-form orbit at {w}"));
    for (name, omegas, at, contact_before) in
        [("run-up", path(1.2, 1.375, 1.385, 0.01, 1e-4), fold, true), ("run-down", path(1.45, 1.29, 1.28, 0.01, 1e-4), grazing, false)]
    {
        let s = ramp_scene(IMPACT, &omegas);
        let jumps: Vec<usize> = (0..s.len()).filter(|&i| s[i].jumped).collect();
        assert_eq!(jumps.len(), 1, "{name}: jumps at {:?}", jumps.iter().map(|&i| omegas[i]).collect::<Vec<_>>());
        let (i, j) = (jumps[0], &s[jumps[0]]);
        eprintln!("{name}: jump at ω = {}, fold {:.9} (reference {at:.9}), amplitude {} -> {}", omegas[i], j.fold, j.from, j.to);
        assert!((j.fold - at).abs() <= 1e-4 * at, "{name}: the jump's fold {} vs the reference's {at}", j.fold);
        assert!((omegas[i - 1] - at) * (omegas[i] - at) <= 0.0, "{name}: the jump at {} is not the first step past {at}", omegas[i]);
        let x = off_closed_form(&s[i - 1], &closed_form(contact_before, omegas[i - 1]));
        let y = off_closed_form(j, &closed_form(!contact_before, omegas[i]));
        eprintln!("{name}: off the closed form by {x:.1e} before the jump, {y:.1e} after");
        assert!(x <= 1e-6 * gap && y <= 1e-6 * gap, "{name}: the answers off the closed-form orbits by {x:.1e} before, {y:.1e} after the jump");
    }
}
