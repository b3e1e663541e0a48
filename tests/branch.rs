//! Branches through the C API (issue 13 item 6): re-solves continue the orbit along its branch,
//! jump where it ends at a fold, and report the orbit's Floquet stability. References: the
//! damped linear oscillator's multipliers e^{−cT/2m} (a contact-free orbit), its grazing
//! frequency |1 − ω² + icω| = F/gap (where the contact-free branch of a run-down ends), and the
//! contact-free amplitude after the run-up's jump.
use periodic_contact::analysis::continuation::{self, ContinuationSettings, Parameter};
use periodic_contact::capi::*;
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
}

/// Solves at each frequency in turn on one problem handle.
fn ramp(omegas: &[f64]) -> Vec<Step> {
    let text = CString::new(DEMO).unwrap();
    unsafe {
        let p = pc_problem_from_scene_text(text.as_ptr());
        assert!(!p.is_null());
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
                pc_result_free(r);
                Step { jumped: jumped == 1, fold, from, to, stable: stable == 1, multiplier: mu }
            })
            .collect();
        pc_problem_free(p);
        steps
    }
}

#[test]
fn a_contact_free_orbit_has_the_multipliers_of_its_damping() {
    let s = ramp(&[1.3]);
    let exact = (-C / 2.0 * 2.0 * std::f64::consts::PI / 1.3).exp();
    assert!((s[0].multiplier - exact).abs() <= 1e-4, "{} vs e^(-cT/2) = {exact}", s[0].multiplier);
    assert!(s[0].stable);
}

#[test]
fn a_run_up_and_a_run_down_jump_once_at_their_folds() {
    let n = 900;
    let up: Vec<f64> = (0..=n).map(|i| 1.0 + 0.45 * i as f64 / n as f64).collect();
    let down: Vec<f64> = up.iter().rev().copied().collect();
    let dw = 0.45 / n as f64;

    // The run-up stays on the contact branch up to its fold, then falls to the contact-free orbit.
    let s = ramp(&up);
    let jumps: Vec<usize> = (0..s.len()).filter(|&i| s[i].jumped).collect();
    assert_eq!(jumps.len(), 1, "run-up jumps at {:?}", jumps.iter().map(|&i| up[i]).collect::<Vec<_>>());
    let j = &s[jumps[0]];
    // The fold of the continued branch (periodic-contact continue): the contact branch's largest
    // frequency (the branch goes on through the unstable orbits and the contact-free ones to 1.45).
    let p = Scene::parse(DEMO, "demo").unwrap().to_problem("demo").unwrap();
    let b = continuation::run(&p, Parameter::Frequency, 1.0, 1.45, &ContinuationSettings::default(), &|_| {}).unwrap();
    let fold = b.points.iter().filter(|q| q.amplitude[0] > 2.0).map(|q| q.parameter).fold(0.0, f64::max);
    let located = b.events().filter(|q| q.event == Some(continuation::EventKind::Fold)).map(|q| q.parameter).fold(0.0, f64::max);
    assert!((located - fold).abs() <= 1e-4 * fold, "the fold event at {located} vs the resonance tip {fold}");
    // Within the width that tells a fold from a wiggle of the discrete branch (1e-3 relative) and a step.
    assert!((j.fold - fold).abs() <= 1e-3 * fold + dw, "run-up jump at {} vs the continuation's fold {fold}", j.fold);
    assert!(j.from > 2.5 && (j.to - linear(up[jumps[0]])).abs() <= 1e-3 * j.to, "amplitudes {} -> {} (linear {})", j.from, j.to, linear(up[jumps[0]]));
    assert!(s[..jumps[0]].iter().all(|x| x.stable), "the followed branch is stable");

    // The run-down stays on the contact-free orbit down to its grazing, then jumps up.
    let s = ramp(&down);
    let jumps: Vec<usize> = (0..s.len()).filter(|&i| s[i].jumped).collect();
    assert_eq!(jumps.len(), 1, "run-down jumps at {:?}", jumps.iter().map(|&i| down[i]).collect::<Vec<_>>());
    let j = &s[jumps[0]];
    // |1 − ω² + icω| = F/gap: ω² = (1.9975 + √0.15000625)/2.
    let grazing = ((1.9975 + 0.150_006_25f64.sqrt()) / 2.0).sqrt();
    assert!((j.fold - grazing).abs() <= 1e-3 * grazing + dw, "run-down jump at {} vs grazing {grazing}", j.fold);
    assert!((j.from - 1.0).abs() < 0.01 && j.to > 1.2, "amplitudes {} -> {}", j.from, j.to);
    assert!(s.iter().all(|x| x.stable), "both branches of the run-down are stable");
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
    assert!(middle.len() > 20 && middle.iter().all(|q| !q.stable && q.max_multiplier > 1.0), "{} middle points", middle.len());
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
