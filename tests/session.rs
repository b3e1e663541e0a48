//! The solver session keeps its assembly across re-solves (issue 12 item 2): a gap change or a
//! common scale of the forces re-solves without re-assembling, and the answer is the one a fresh
//! problem with those values gives (the independent reference: a new solve from scratch).
use periodic_contact::periodic::{PeriodicProblem, PeriodicSolver, Tuning};
use periodic_contact::scene::Scene;

use crate::common::compare;
use compare::difference;

const CHAIN: &str = include_str!("../fmu/scenes/chain-3dof-two-stops.toml");

fn chain() -> PeriodicProblem {
    Scene::parse(CHAIN, "chain").unwrap().to_problem("chain").unwrap()
}

fn fresh(p: &PeriodicProblem) -> periodic_contact::response::Response {
    p.solve().unwrap()
}

#[test]
fn gap_and_force_scale_changes_reuse_the_assembly() {
    let base = chain();
    let mut session = PeriodicSolver::new(base.clone());
    session.solve().unwrap();
    assert_eq!(session.assemblies(), 1);

    // New clearances: the same assembly, the answer of a fresh problem with those gaps.
    let gaps: Vec<f64> = base.model().contacts.iter().map(|c| c.gap * 0.9).collect();
    session.update_gaps(&gaps).unwrap();
    let r = session.solve().unwrap();
    assert_eq!(session.assemblies(), 1, "a gap change re-assembled");
    let mut model = base.model().clone();
    model.contacts.iter_mut().zip(&gaps).for_each(|(c, &g)| c.gap = g);
    let reference = fresh(&base.with_model(model, base.discretization()).unwrap());
    let d = difference(&r, &reference);
    assert!(d <= 1e-10, "after update_gaps: {d:e}");

    // Every force × 1.2: still the same assembly (X_lin is linear in the forces).
    let amplitudes: Vec<f64> = base.model().forces.iter().map(|f| f.term.amplitude * 1.2).collect();
    session.update_forces(&amplitudes).unwrap();
    let r = session.solve().unwrap();
    assert_eq!(session.assemblies(), 1, "a common force scale re-assembled");
    let mut model = base.model().clone();
    model.contacts.iter_mut().zip(&gaps).for_each(|(c, &g)| c.gap = g);
    model.forces.iter_mut().zip(&amplitudes).for_each(|(f, &a)| f.term.amplitude = a);
    let reference = fresh(&base.with_model(model, base.discretization()).unwrap());
    let d = difference(&r, &reference);
    assert!(d <= 1e-10, "after update_forces: {d:e}");

    // A new frequency is a new assembly.
    session.update_frequency(base.model().frequency * 1.01).unwrap();
    session.solve().unwrap();
    assert_eq!(session.assemblies(), 2);

    // Wrong lengths are refused, naming the call.
    let e = session.update_gaps(&[1.0]).unwrap_err().to_string();
    assert!(e.contains("update_gaps") && e.contains("2 contacts"), "{e}");
}

/// The FMU's and C API's path: a tuned problem handed to `update_problem`. A gap offset or a force
/// scale re-uses the assembly; the frequency does not.
#[test]
fn tuned_problems_reuse_the_assembly() {
    let base = chain();
    let mut session = PeriodicSolver::new(base.clone());
    session.solve().unwrap();
    let tuning = Tuning { gap_offset: 0.02, force_scale: 0.8, ..Tuning::of(&base) };
    let tuned = tuning.apply(&base, base.discretization()).unwrap();
    session.update_problem(tuned.clone());
    let r = session.solve().unwrap();
    assert_eq!(session.assemblies(), 1);
    assert!(difference(&r, &fresh(&tuned)) <= 1e-10);
    let tuning = Tuning { frequency: base.model().frequency * 0.99, ..tuning };
    session.update_problem(tuning.apply(&base, base.discretization()).unwrap());
    session.solve().unwrap();
    assert_eq!(session.assemblies(), 2);
}
