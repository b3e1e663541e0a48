//! Studies of what accuracy costs (issue 6): the accuracy–cost study against the exact references
//! of src/formulation.md §6 with the explicit time-marching reference on the same axes, and warm starts.
//!
//! Everything is measured on one thread (`SolverSettings::parallel = false`, the marcher is
//! single-threaded), so that the times are CPU times.
pub mod accuracy;
pub mod chain;
pub mod families;
pub mod honesty;
pub mod peers;
pub mod warmstart;

use crate::Error;
use crate::exact::{CompliantStopOrbit, LinearOrbit, Oscillator, RigidStopOrbit};
use crate::model::{Compliance, Model};
use crate::periodic::{LcpMethod, OutputSelection, PeriodicProblem, SolverSettings};
use crate::time::{Discretization, Pairing, Scheme};
use chain::MarchedReference;

/// The exact references of src/formulation.md §6 used by the studies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Case {
    /// §6.2: m = 1, c = 0.05, k = 1, k_c = 10, g0 = 1, F = 1, Ω = 1.3.
    Compliant,
    /// §6.3: m = 1, c = 0.1, k = 1, F = 1, g0 = 0.5, Ω = 1 (sticking; plastic impact).
    Rigid,
    /// §6.1: the oscillator of the compliant case without the stop.
    Linear,
    /// §6.3 without sticking (pure impacts, first order for every scheme): m = 1, c = 0.1, k = 1,
    /// F = 0.5, Ω = 0.8, g0 = 0.6 (the case of tests/convergence.rs). Not one of the three
    /// references the issue lists: added because its transient decays slowly (no sticking resets
    /// the state), which is where marching is expensive.
    Impacting,
    /// A 2-DOF chain with a compliant stop on the second mass (tests/polish.rs): no closed form,
    /// the reference is long time integration ([`chain`]).
    Chain,
}

/// The compliant-stop oscillator of src/formulation.md §6.2 (also the linear case's).
pub const COMPLIANT_OSC: Oscillator = Oscillator { mass: 1.0, damping: 0.05, stiffness: 1.0, force: 1.0, omega: 1.3 };
/// Contact stiffness and gap of src/formulation.md §6.2.
pub const COMPLIANT_STIFFNESS: f64 = 10.0;
pub const COMPLIANT_GAP: f64 = 1.0;
/// The rigid stop with sticking of src/formulation.md §6.3.
pub const RIGID_OSC: Oscillator = Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 1.0, omega: 1.0 };
pub const RIGID_GAP: f64 = 0.5;
/// The pure-impact rigid stop (see [`Case::Impacting`]).
pub const IMPACTING_OSC: Oscillator = Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 0.5, omega: 0.8 };
pub const IMPACTING_GAP: f64 = 0.6;

impl Case {
    pub const ALL: [Case; 5] = [Case::Compliant, Case::Rigid, Case::Impacting, Case::Chain, Case::Linear];

    pub fn name(self) -> &'static str {
        match self {
            Case::Compliant => "compliant",
            Case::Rigid => "rigid",
            Case::Linear => "linear",
            Case::Impacting => "impacting",
            Case::Chain => "chain",
        }
    }

    pub fn parse(s: &str) -> Result<Case, Error> {
        Case::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| Error::input(format!("unknown case \"{s}\"; expected compliant, rigid, impacting, chain or linear")))
    }

    pub fn title(self) -> &'static str {
        match self {
            Case::Compliant => "compliant stop (src/formulation.md §6.2)",
            Case::Rigid => "rigid stop with sticking (src/formulation.md §6.3)",
            Case::Linear => "linear oscillator (src/formulation.md §6.1)",
            Case::Impacting => "rigid stop, pure impacts (no sticking)",
            Case::Chain => "2-DOF compliant chain (reference: long time integration)",
        }
    }

    /// The 1-DOF oscillator of the case; `None` for the chain.
    pub fn oscillator(self) -> Option<Oscillator> {
        match self {
            Case::Compliant | Case::Linear => Some(COMPLIANT_OSC),
            Case::Rigid => Some(RIGID_OSC),
            Case::Impacting => Some(IMPACTING_OSC),
            Case::Chain => None,
        }
    }

    /// The model of the case.
    pub fn model(self) -> Model {
        let Some(osc) = self.oscillator() else { return chain::model() };
        match self {
            Case::Compliant => osc.model(vec![Oscillator::stop(COMPLIANT_GAP, Compliance::Compliant { stiffness: COMPLIANT_STIFFNESS })]),
            Case::Rigid => osc.model(vec![Oscillator::stop(RIGID_GAP, Compliance::Rigid)]),
            Case::Impacting => osc.model(vec![Oscillator::stop(IMPACTING_GAP, Compliance::Rigid)]),
            Case::Linear | Case::Chain => osc.model(vec![]),
        }
    }

    /// The displacement DOFs compared with the reference.
    pub fn dofs(self) -> Vec<usize> {
        (0..self.model().n()).collect()
    }

    /// Whether the case has a contact (and so an LCP, a pairing and an impulse).
    pub fn has_contact(self) -> bool {
        self != Case::Linear
    }

    /// The schemes and pairings studied: every pairing for a contact case.
    pub fn methods(self) -> Vec<(Scheme, Option<Pairing>)> {
        let mut v = Vec::new();
        for s in Scheme::ALL {
            if self.has_contact() {
                v.push((s, Some(Pairing::Same)));
                v.push((s, Some(Pairing::Forward)));
            } else {
                v.push((s, None));
            }
        }
        v
    }

    /// Whether (scheme, pairing) converges to the exact orbit (src/formulation.md §3 findings; the README table).
    pub fn converges(self, scheme: Scheme, pairing: Option<Pairing>) -> bool {
        match self {
            Case::Linear | Case::Compliant | Case::Chain => true,
            Case::Rigid | Case::Impacting => matches!(
                (scheme, pairing),
                (Scheme::Bds1, Some(Pairing::Same)) | (Scheme::Cds, Some(Pairing::Forward)) | (Scheme::Galerkin, Some(Pairing::Forward))
            ),
        }
    }

    /// The problem at k instants, one thread, `auto` LCP method unless told.
    pub fn problem(self, scheme: Scheme, pairing: Option<Pairing>, k: usize, method: LcpMethod) -> Result<PeriodicProblem, Error> {
        let outputs = OutputSelection { displacement: self.dofs(), velocity: vec![], acceleration: vec![], contacts: self.has_contact() };
        let solver = SolverSettings { method, parallel: false, ..SolverSettings::default() };
        PeriodicProblem::new(self.model(), Discretization { scheme, steps: k, pairing }, outputs, solver).map_err(Error::from)
    }

    /// The exact reference.
    pub fn reference(self) -> Result<Reference, Error> {
        Ok(match self {
            Case::Compliant => {
                Reference::Compliant(CompliantStopOrbit::solve(&COMPLIANT_OSC, COMPLIANT_STIFFNESS, COMPLIANT_GAP, None).map_err(reference_error)?)
            }
            Case::Rigid => Reference::Rigid(RigidStopOrbit::solve(&RIGID_OSC, RIGID_GAP).map_err(reference_error)?),
            Case::Impacting => Reference::Rigid(RigidStopOrbit::solve(&IMPACTING_OSC, IMPACTING_GAP).map_err(reference_error)?),
            Case::Linear => Reference::Linear(LinearOrbit::solve(&COMPLIANT_OSC).map_err(reference_error)?),
            Case::Chain => Reference::Marched(chain::reference()?),
        })
    }
}

/// A failure of a semi-analytic reference (whatever its error type): the study cannot run.
fn reference_error(e: impl std::fmt::Display) -> Error {
    Error::solve(format!("the exact reference: {e}"))
}

/// A method label: "cds/forward", or "cds" without contact.
pub fn method_label(scheme: Scheme, pairing: Option<Pairing>) -> String {
    match pairing {
        Some(p) => format!("{scheme}/{p}"),
        None => scheme.to_string(),
    }
}

/// An exact periodic orbit.
#[derive(Clone, Debug)]
pub enum Reference {
    Compliant(CompliantStopOrbit),
    Rigid(RigidStopOrbit),
    Linear(LinearOrbit),
    Marched(MarchedReference),
}

impl Reference {
    /// x_dof(t); the marched reference only at the instants of its grid.
    pub fn displacement(&self, dof: usize, t: f64) -> f64 {
        match self {
            Reference::Compliant(o) => o.eval(t).0,
            Reference::Rigid(o) => o.eval(t).0,
            Reference::Linear(o) => o.eval(t).0,
            Reference::Marched(o) => o.displacement(dof, t),
        }
    }
    /// Largest peak-to-peak amplitude over the DOFs.
    pub fn peak_to_peak(&self) -> f64 {
        match self {
            Reference::Compliant(o) => o.peak_to_peak(),
            Reference::Rigid(o) => o.peak_to_peak(),
            Reference::Linear(o) => o.peak_to_peak(),
            Reference::Marched(o) => o.peak_to_peak(),
        }
    }
    /// The reference's own error relative to the peak-to-peak amplitude (0 for the closed forms,
    /// whose Newton solves reach round-off).
    pub fn uncertainty(&self) -> f64 {
        match self {
            Reference::Marched(o) => o.uncertainty() / o.peak_to_peak(),
            _ => 0.0,
        }
    }
    /// Impulse per period; None without contact.
    pub fn impulse(&self) -> Option<f64> {
        match self {
            Reference::Compliant(o) => Some(o.impulse_per_period()),
            Reference::Rigid(o) => Some(o.impulse_per_period()),
            Reference::Linear(_) | Reference::Marched(_) => None,
        }
    }

    /// max over the DOFs and samples of |x_j − x(t_j)| / peak-to-peak; `x[d]` is DOF d's series.
    pub fn max_error(&self, t: &[f64], x: &[&[f64]]) -> f64 {
        let mut e = 0.0f64;
        for (dof, x) in x.iter().enumerate() {
            e = t.iter().zip(x.iter()).map(|(&t, &v)| (v - self.displacement(dof, t)).abs()).fold(e, f64::max);
        }
        e / self.peak_to_peak()
    }

    /// [`Reference::max_error`] of a response's displacement outputs (DOFs 0, 1, … in order).
    pub fn response_error(&self, r: &crate::response::Response) -> f64 {
        let x: Vec<&[f64]> = (0..r.displacement.len()).map(|d| r.displacement[&d.to_string()].as_slice()).collect();
        self.max_error(&r.time, &x)
    }

    /// |I − I_exact| / I_exact; None without contact.
    pub fn impulse_error(&self, impulse: f64) -> Option<f64> {
        self.impulse().map(|i| (impulse - i).abs() / i.abs())
    }
}

/// Least-squares slope of −log e against log k (the observed order), over points with e > 0.
pub fn fitted_order(points: &[(usize, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points.iter().filter(|(_, e)| e.is_finite() && *e > 0.0).map(|&(k, e)| ((k as f64).ln(), -e.ln())).collect();
    if pts.len() < 3 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    Some(sxy / sxx)
}

/// "1.23e-4"-style formatting for tables; "—" for None or non-finite.
pub fn sci(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:.2e}"),
        _ => "—".to_string(),
    }
}
