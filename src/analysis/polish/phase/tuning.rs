//! A phase's periodic particular solution at its frequency, and the phase re-tuned to another
//! frequency: its matrices, basis, condensation and Â (so its eigendecomposition) do not depend on
//! ω; only the loads' harmonics and the particular solution do (one n_a-sized complex solve per
//! harmonic), so a sweep makes each contact set's phase once and re-tunes it per point.
use super::{Harmonics, Phase, add, force_harmonics, gap_harmonics};
use crate::model::{Compliance, Model};
use nalgebra::{DMatrix, DVector, Dyn, LU};
use num_complex::Complex64 as C;

/// What the particular solution needs at any ω: K_bb's LU (massless coordinates), K_ab, and the
/// massive coordinates' M_aa, C_aa and condensed stiffness (phase.rs).
#[derive(Clone, Debug)]
pub(super) struct Tuning {
    pub k_bb: Option<LU<f64, Dyn, Dyn>>,
    pub k_ab: DMatrix<f64>,
    pub m_aa: DMatrix<f64>,
    pub c_aa: DMatrix<f64>,
    pub k_cond: DMatrix<f64>,
    /// The DOF of each column of N_a (N_b) where every column is a unit vector e_d (no stuck
    /// contact over several DOFs): Nᵀ r is then a gather of r, not a product.
    pub free_rows: Option<Vec<usize>>,
    pub slave_rows: Option<Vec<usize>>,
}

/// The DOF d of each column of `basis` when every column is a unit vector e_d.
pub(super) fn unit_rows(basis: &DMatrix<f64>) -> Option<Vec<usize>> {
    basis
        .column_iter()
        .map(|c| {
            let mut nonzero = c.iter().enumerate().filter(|(_, v)| **v != 0.0);
            match (nonzero.next(), nonzero.next()) {
                (Some((d, v)), None) if *v == 1.0 => Some(d),
                _ => None,
            }
        })
        .collect()
}

/// Nᵀ x for the basis `basis` (its unit columns' DOFs `rows`, when known) and complex x.
fn projected(basis: &DMatrix<f64>, rows: Option<&[usize]>, x: &DVector<C>) -> DVector<C> {
    match rows {
        Some(rows) => DVector::from_iterator(rows.len(), rows.iter().map(|&d| x[d])),
        None => tr_times(basis, x),
    }
}

/// The full model's forcing with the closed springs' obstacle terms (k_c B_iᵀ gap_i(t) each) and
/// the stuck DOFs' prescribed motion, as harmonics at `model`'s frequency.
pub(super) fn loads(model: &Model, stuck: &[usize], closed: &[usize]) -> (Harmonics, Harmonics) {
    let n = model.n();
    let mut force = force_harmonics(model);
    for &i in closed {
        let ct = &model.contacts[i];
        let Compliance::Compliant { stiffness } = ct.compliance else { continue };
        for (p, g) in gap_harmonics(model, i) {
            for &(d, cd) in &ct.row {
                add(&mut force, p, d, g[0] * stiffness * cd, n);
            }
        }
    }
    let mut presc: Harmonics = Vec::new();
    for &i in stuck {
        for (p, g) in gap_harmonics(model, i) {
            for &(d, cd) in &model.contacts[i].row {
                add(&mut presc, p, d, g[0] * cd, n);
            }
        }
    }
    (force, presc)
}

/// A x for real A and complex x.
fn times(a: &DMatrix<f64>, x: &DVector<C>) -> DVector<C> {
    let (re, im) = (a * x.map(|z| z.re), a * x.map(|z| z.im));
    DVector::from_fn(a.nrows(), |i, _| C::new(re[i], im[i]))
}

/// Aᵀ x for real A and complex x.
fn tr_times(a: &DMatrix<f64>, x: &DVector<C>) -> DVector<C> {
    let (re, im) = (a.tr_mul(&x.map(|z| z.re)), a.tr_mul(&x.map(|z| z.im)));
    DVector::from_fn(a.ncols(), |i, _| C::new(re[i], im[i]))
}

impl Phase {
    /// The particular solution of the phase's loads at its ω (`part`, `slave_part`): per harmonic,
    /// g = Nᵀ(f − (−(pω)² M + ipω C + K) x_presc); the massless rows are static,
    /// K_ba x_a + K_bb x_b = g_b, so x_b = K_bb⁻¹ g_b + S x_a, and the massive ones solve
    /// (−(pω)² M_aa + ipω C_aa + K_cond) x_a = g_a − K_ab K_bb⁻¹ g_b. `None` when that operator
    /// is singular (an undamped resonance).
    pub(super) fn tune(&mut self) -> Option<()> {
        let (nf, nb) = (self.free.ncols(), self.slave.ncols());
        let t = &self.tuning;
        let mut ps: Vec<u32> = self.force.iter().chain(&self.presc).map(|(p, _)| *p).collect();
        ps.sort_unstable();
        ps.dedup();
        let (mut part, mut slave_part) = (Vec::new(), Vec::new());
        for p in ps {
            let w = p as f64 * self.omega;
            let mut r = self.force.iter().find(|(q, _)| *q == p).map_or_else(|| DVector::zeros(self.n), |(_, v)| v.clone());
            if let Some((_, xp)) = self.presc.iter().find(|(q, _)| *q == p) {
                r -= times(&self.k, xp) - times(&self.m, xp) * C::new(w * w, 0.0) + times(&self.c, xp) * C::new(0.0, w);
            }
            let yb = match &t.k_bb {
                Some(lu) => {
                    let gb = projected(&self.slave, t.slave_rows.as_deref(), &r);
                    let (re, im) = (lu.solve(&gb.map(|z| z.re))?, lu.solve(&gb.map(|z| z.im))?);
                    DVector::from_fn(nb, |i, _| C::new(re[i], im[i]))
                }
                None => DVector::zeros(nb),
            };
            let xa = if nf == 0 {
                DVector::zeros(0)
            } else {
                let ga = projected(&self.free, t.free_rows.as_deref(), &r) - times(&t.k_ab, &yb);
                let op = DMatrix::from_fn(nf, nf, |i, j| C::new(t.k_cond[(i, j)] - w * w * t.m_aa[(i, j)], w * t.c_aa[(i, j)]));
                op.lu().solve(&ga)?
            };
            let xb = yb + times(&self.slave_map, &xa);
            if !xa.iter().chain(xb.iter()).all(|v| v.re.is_finite() && v.im.is_finite()) {
                return None;
            }
            let mut y = DVector::zeros(2 * nf);
            y.rows_mut(0, nf).copy_from(&xa);
            y.rows_mut(nf, nf).copy_from(&(xa * C::new(0.0, w)));
            part.push((p, y));
            slave_part.push((p, xb));
        }
        (self.part, self.slave_part) = (part, slave_part);
        Some(())
    }

    /// This phase at `model`'s frequency and loads, `model` being the phase's own at another
    /// frequency (the same structure and contacts): the particular solution made again, the rest
    /// (the eigendecomposition included) shared. `None` as for [`Phase::new`].
    pub fn retuned(&self, model: &Model) -> Option<Phase> {
        let mut p = self.clone();
        p.omega = model.frequency;
        (p.force, p.presc) = loads(model, &self.stuck, &self.closed);
        p.tune()?;
        Some(p)
    }
}
