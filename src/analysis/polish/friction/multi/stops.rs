//! Compliant unilateral stops among the friction contacts of the stick–slip polish (issue 25:
//! "a contact is a row along any normal; friction is one more kind of row").
//!
//! A stop along the unit normal c with clearance gap is closed while its penetration
//! cᵀx − gap > 0 and then pushes back with λ = k_c (cᵀx − gap) along −c (the penalty law of
//! src/formulation.md §4, README "Scene file"); open it carries nothing. In a mode each stop is
//! one more entry after the friction contacts' phases ([`Slide::Open`], [`Slide::Closed`]): a
//! closed stop adds k_c c cᵀ to K and k_c gap c to the load, so every mode stays linear and
//! flows exactly. Its events (closing and opening) are cᵀx − gap = 0, with no jump of the state
//! (the saltation of a continuous force is the identity). Rigid stops and moving obstacles are
//! refused by name: the LCP's orbit is kept.
use super::super::super::PolishFailure;
use super::super::Slide;
use crate::model::{Compliance, Model};
use crate::response::Response;
use nalgebra::{DMatrix, DVector};

/// A compliant stop of the model.
#[derive(Clone, Debug)]
pub struct Stop {
    pub normal: DVector<f64>,
    pub gap: f64,
    pub stiffness: f64,
}

impl Stop {
    /// The model's unilateral contacts as stops; a rigid or moving one is refused by name.
    pub fn from_model(model: &Model) -> Result<Vec<Stop>, PolishFailure> {
        let refuse = |i: usize, w: &str| {
            Err(PolishFailure(format!(
                "stick–slip polish (contact[{i}] {w}: with friction contacts only static compliant stops are fitted in this version); the LCP's orbit is kept"
            )))
        };
        let mut stops = Vec::with_capacity(model.contacts.len());
        for (i, c) in model.contacts.iter().enumerate() {
            let Compliance::Compliant { stiffness } = c.compliance else { return refuse(i, "is rigid (no `stiffness`)") };
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

    /// Adds the closed stop's force −c k_c (cᵀx − gap) to `h` (n × dim, the forces as linear
    /// forms of ỹ, `ione` the index of the constant 1) and returns λ as a linear form of ỹ.
    pub fn close(&self, h: &mut DMatrix<f64>, ione: usize) -> DVector<f64> {
        let (n, k, c) = (self.normal.len(), self.stiffness, &self.normal);
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

/// Each stop's phase at the LCP's instants: closed where its clearance is negative.
pub fn series(r: &Response) -> Vec<Vec<Slide>> {
    r.contacts.iter().map(|c| c.gap.iter().map(|&g| if g < 0.0 { Slide::Closed } else { Slide::Open }).collect()).collect()
}
