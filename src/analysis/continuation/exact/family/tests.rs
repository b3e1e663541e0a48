//! The family's tests and the exact walk's small test models.
use super::{Failure, Family, Signature, lambda_axis};
use crate::analysis::continuation::Parameter;
use crate::analysis::polish;
use crate::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};
use crate::periodic::{OutputSelection, PeriodicProblem, PeriodicSolver, SolverSettings};
use crate::time::{Discretization, Scheme};
use num_complex::Complex64;

/// A model forced by cos Ωt on DOF 0, with a rigid stop (plastic impacts) on `stop_dof` at
/// clearance `gap`, bds1 with `steps` steps: the exact walk's small test models.
pub(crate) fn forced_with_rigid_stop(structure: Structure, stop_dof: usize, gap: f64, steps: usize, omega: f64) -> PeriodicProblem {
    let force = Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } };
    let stop = Contact::on_dof(stop_dof, 1.0, gap, Compliance::Rigid);
    let model = Model { structure, forces: vec![force], contacts: vec![stop], frequency: omega, frictions: Vec::new(), rubbing: Vec::new() };
    let disc = Discretization { scheme: Scheme::Bds1, steps, pairing: None };
    let outputs = OutputSelection { displacement: vec![0], contacts: true, ..OutputSelection::default() };
    PeriodicProblem::new(model, disc, outputs, SolverSettings::default()).expect("the test model's problem")
}

/// A unit mass (k = 1, c = 0.1, forced by cos Ωt) carrying a light tip (m = 1e-4) on a stiff
/// spring (100: its mode at ≈ 1000, far above the metric's cut-off), the tip's rigid stop
/// far away (never touched): the contact-free orbit, linear in closed form.
fn tipped(omega: f64) -> PeriodicProblem {
    let (m1, ks) = (1e-4, 100.0);
    let structure = Structure {
        mass: Matrix::from_rows(&[vec![1.0, 0.0], vec![0.0, m1]]),
        stiffness: Matrix::from_rows(&[vec![1.0 + ks, -ks], vec![-ks, ks]]),
        damping: Some(Matrix::from_rows(&[vec![0.1, 0.0], vec![0.0, 0.0]])),
    };
    forced_with_rigid_stop(structure, 1, 100.0, 256, omega)
}

/// The state at t = 0 of the linear forced response: x = Re(X e^{iΩt}), X = (K − Ω²M + iΩC)⁻¹ F.
fn closed_form(omega: f64) -> Vec<f64> {
    let (m1, ks) = (1e-4, 100.0);
    let a = [
        [Complex64::new(1.0 + ks - omega * omega, 0.1 * omega), Complex64::new(-ks, 0.0)],
        [Complex64::new(-ks, 0.0), Complex64::new(ks - m1 * omega * omega, 0.0)],
    ];
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let x = [a[1][1] / det, -a[1][0] / det];
    let i_omega = Complex64::new(0.0, omega);
    vec![x[0].re, x[1].re, (i_omega * x[0]).re, (i_omega * x[1]).re]
}

/// A point's tangent is oriented along the walk's sense in the arclength's metric, whatever
/// the stiff components (which the metric leaves out) of the tangent it is oriented along:
/// the coarse rigid blade's located points took the reverse sense there, and six folds were
/// recorded with λ increasing (validation/RECORD.md, issue 24). Reference: the secant of the closed-form
/// linear orbits at Ω ± δ (λ increasing); the previous tangent given is that sense plus a
/// large stiff-mode component against it in the unknowns' own product.
#[test]
fn a_tangent_keeps_the_walks_sense_in_the_metric() {
    let omega = 0.9;
    let p = tipped(omega);
    let r = PeriodicSolver::new(p.clone()).solve().expect("the grid solve");
    let orbit = polish::polish(&p, &r).expect("the polish of the contact-free orbit");
    assert!(orbit.events().is_empty(), "the stop is never touched");
    let sig = Signature { events: Vec::new(), always: orbit.always_closed().to_vec() };
    let mut fam = Family::new(p.model(), Parameter::Frequency, 1.0, 1.0, sig);
    fam.ys = fam.scale_of(orbit.initial_state());
    let d = fam.dim();
    let w = fam.correct(&fam.pack(&orbit, omega), &lambda_axis(d), omega).expect("closed at Ω = 0.9");
    let jac = fam.jacobian(&w).expect("the Jacobian");
    // The closed form's secant in the unknowns, λ increasing.
    let h = 1e-5;
    let (up, dn) = (fam.scaled(&closed_form(omega + h)), fam.scaled(&closed_form(omega - h)));
    let mut secant: Vec<f64> = up.iter().zip(&dn).map(|(a, b)| (a - b) / (2.0 * h)).collect();
    secant.push(1.0);
    // A displacement direction the metric does not see (the stiff mode's): its null vector
    // in the displacement block, from the Gram matrix of the two unit displacements.
    let unit = |i: usize| (0..d).map(|j| if j == i { 1.0 } else { 0.0 }).collect::<Vec<f64>>();
    let (e0, e1) = (unit(0), unit(1));
    let (g00, g01) = (fam.metric.dot(&e0, &e0), fam.metric.dot(&e0, &e1));
    let stiff: Vec<f64> = (0..d).map(|j| [-g01, g00].get(j).copied().unwrap_or(0.0)).collect();
    assert!(fam.metric.norm(&stiff) < 1e-9 * stiff.iter().map(|x| x * x).sum::<f64>().sqrt(), "the metric sees the stiff direction");
    let raw = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    // The walk's sense plus the stiff direction, large enough to reverse the unknowns' product.
    let c = -3.0 * raw(&secant, &secant) / raw(&stiff, &secant);
    let prev: Vec<f64> = secant.iter().zip(&stiff).map(|(s, q)| s + c * q).collect();
    assert!(raw(&prev, &secant) < 0.0 && fam.metric.dot(&prev, &secant) > 0.0, "prev reverses the raw product only");
    let t = fam.tangent(&jac, &prev).expect("the tangent");
    let cos = fam.metric.dot(&t, &secant) / (fam.metric.norm(&t) * fam.metric.norm(&secant));
    eprintln!("tangent vs the closed form's secant: cos {cos:.9} in the metric, λ component {:e}", t[d - 1]);
    assert!(cos > 1.0 - 1e-6, "the tangent points against (or off) the closed form's branch: cos {cos}");
    assert!(t[d - 1] > 0.0, "λ increases along the branch here");
}

/// A corrector's failure names its cause: on the contact-free tipped oscillator at Ω fixed the
/// shooting residual is affine in the state, so Newton's first correction is the predictor's
/// error itself, known from the closed-form orbit. A predictor 2 (scaled unknowns) off in the
/// first displacement fails at iteration 1 as diverged with that correction (Newton's basin is
/// capped at 1); one 0.5 off converges on the closed form.
#[test]
fn a_corrector_far_from_the_orbit_fails_as_diverged_by_its_error() {
    let omega = 0.9;
    let p = tipped(omega);
    let sig = Signature { events: Vec::new(), always: Vec::new() };
    let mut fam = Family::new(p.model(), Parameter::Frequency, 1.0, 1.0, sig);
    let exact = closed_form(omega);
    fam.ys = fam.scale_of(&exact);
    let d = fam.dim();
    let mut w = fam.scaled(&exact);
    w.push(omega);
    let off = |by: f64| -> Vec<f64> { w.iter().enumerate().map(|(i, x)| if i == 0 { x + by } else { *x }).collect() };
    match fam.correct(&off(2.0), &lambda_axis(d), omega) {
        Err(Failure::Diverged { iteration: 1, correction }) => {
            assert!((correction - 2.0).abs() < 1e-6, "the first correction {correction}, the predictor's error 2")
        }
        other => panic!("a predictor 2 off: expected a divergence at iteration 1 by 2, got {other:?}"),
    }
    let near = fam.correct(&off(0.5), &lambda_axis(d), omega).expect("a predictor 0.5 off converges");
    let error = near.iter().zip(&w).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(error < 1e-8, "converged {error:e} from the closed form");
}
