//! Compliant unilateral stops among the friction contacts of the stick–slip polish (issue 25:
//! "a contact is a row along any normal; friction is one more kind of row").
//!
//! A stop along the unit normal c with clearance gap is closed while its penetration
//! cᵀx − gap > 0 and then pushes back with λ = k_c (cᵀx − gap) along −c (the penalty law of
//! src/formulation.md §4, README "Scene file"); open it carries nothing. In a mode each stop is
//! one more entry after the friction contacts' phases ([`Slide::Open`], [`Slide::Closed`]): a
//! closed stop adds k_c c cᵀ to K and k_c gap c to the load, so every mode stays linear and
//! flows exactly. Its events (closing and opening) are cᵀx − gap = 0, with no jump of the state
//! (the saltation of a continuous force is the identity). A rigid stop (no `stiffness`) holds
//! cᵀv = 0 while closed as one more row of the constraint of multi.rs (its reaction λ ≥ 0), is
//! closed by a plastic impact (the velocity projected in the mass metric, e = 0 as the LCP) and
//! opens at λ = 0. Moving obstacles are refused by name: the LCP's orbit is kept.
use super::super::super::PolishFailure;
use super::super::Slide;
use super::{Mode, MultiFlows};
use crate::model::{Compliance, Model};
use crate::response::Response;
use nalgebra::{DMatrix, DVector};

/// A compliant stop of the model.
#[derive(Clone, Debug)]
pub struct Stop {
    pub normal: DVector<f64>,
    pub gap: f64,
    /// k_c; `None`: rigid.
    pub stiffness: Option<f64>,
}

impl Stop {
    /// The model's unilateral contacts as stops; a rigid or moving one is refused by name.
    pub fn from_model(model: &Model) -> Result<Vec<Stop>, PolishFailure> {
        let refuse = |i: usize, w: &str| {
            Err(PolishFailure(format!(
                "stick–slip polish (contact[{i}] {w}: with friction contacts only static stops are fitted in this version); the LCP's orbit is kept"
            )))
        };
        let mut stops = Vec::with_capacity(model.contacts.len());
        for (i, c) in model.contacts.iter().enumerate() {
            let stiffness = match c.compliance {
                Compliance::Compliant { stiffness } => Some(stiffness),
                Compliance::Rigid => None,
            };
            if !c.motion.is_empty() {
                return refuse(i, "has a moving obstacle (`motion`)");
            }
            let mut normal = DVector::zeros(model.n());
            c.row.iter().for_each(|&(d, a)| normal[d] += a);
            stops.push(Stop { normal, gap: c.gap, stiffness });
        }
        Ok(stops)
    }

    /// The penetration cᵀx − gap at the augmented state `y` (> 0: closed).
    pub fn penetration(&self, y: &DVector<f64>) -> f64 {
        self.normal.dot(&y.rows(0, self.normal.len())) - self.gap
    }

    /// Whether `phase` (open or closed) contradicts the penetration at `y` beyond `tol`.
    pub fn breaks(&self, phase: Slide, y: &DVector<f64>, tol: f64) -> bool {
        let p = self.penetration(y);
        (phase == Slide::Open && p > tol) || (phase == Slide::Closed && p < -tol)
    }

    pub fn rigid(&self) -> bool {
        self.stiffness.is_none()
    }

    /// Adds the closed stop's force −c k_c (cᵀx − gap) to `h` (n × dim, the forces as linear
    /// forms of ỹ, `ione` the index of the constant 1) and returns λ as a linear form of ỹ.
    pub fn close(&self, h: &mut DMatrix<f64>, ione: usize) -> DVector<f64> {
        // A rigid stop's force is a reaction of the constraint (multi.rs), not a spring.
        let Some(k) = self.stiffness else { return DVector::zeros(h.ncols()) };
        let (n, c) = (self.normal.len(), &self.normal);
        let mut x = h.view_mut((0, 0), (n, n));
        x -= c * c.transpose() * k;
        let mut one = h.column_mut(ione);
        one += c * (k * self.gap);
        let mut lambda = DVector::zeros(h.ncols());
        lambda.rows_mut(0, n).copy_from(&(c * k));
        lambda[ione] = -k * self.gap;
        lambda
    }
}

/// Each stop's phase at the LCP's instants: closed where its clearance is negative (compliant)
/// or its force is above 1e-9 of its largest (rigid: the clearance is 0 while pressed).
pub fn series(r: &Response, stops: &[Stop]) -> Vec<Vec<Slide>> {
    let phase = |closed: bool| if closed { Slide::Closed } else { Slide::Open };
    r.contacts
        .iter()
        .zip(stops)
        .map(|(c, s)| match s.rigid() {
            true => {
                let top = c.force.iter().fold(0.0f64, |a, f| a.max(f.abs()));
                c.force.iter().map(|&f| phase(f > 1e-9 * top)).collect()
            }
            false => c.gap.iter().map(|&g| phase(g < 0.0)).collect(),
        })
        .collect()
}

/// Adds `col` to the orthonormal `basis` if it is independent of it (a residual above 1e-9 of
/// its norm); returns whether it was.
pub fn extend_basis(basis: &mut Vec<DVector<f64>>, col: &DVector<f64>) -> bool {
    let r = basis.iter().fold(col.clone(), |r, q| &r - q * q.dot(&r));
    let independent = r.norm() > 1e-9 * col.norm();
    if independent {
        basis.push(r.normalize());
    }
    independent
}

impl MultiFlows {
    /// Whether rigid friction contact `i`'s direction lies in the span of the closed rigid stops'
    /// normals of `mode`: pressed on the stop it cannot slide.
    pub fn pinned(&self, mode: &[Slide], i: usize) -> bool {
        let nb = self.b.len();
        if i >= nb || self.kt[i].is_some() {
            return false;
        }
        let mut basis = Vec::new();
        for (j, s) in self.stops.iter().enumerate() {
            if s.rigid() && mode[nb + j] == Slide::Closed {
                extend_basis(&mut basis, &s.normal);
            }
        }
        !basis.is_empty() && !extend_basis(&mut basis, &self.b[i])
    }

    /// `mode` with its pinned friction contacts stuck (the plastic impact ends their slip in the
    /// same instant).
    pub fn pin_to_stops(&self, mut mode: Mode) -> Mode {
        for i in 0..self.b.len() {
            if self.pinned(&mode, i) {
                mode[i] = Slide::Stick;
            }
        }
        mode
    }
}
