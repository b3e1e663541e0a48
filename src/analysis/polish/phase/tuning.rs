//! A phase's periodic particular solution at its frequency, and the phase re-tuned to another
//! frequency: its matrices, basis, condensation and Â (so its eigendecomposition) do not depend on
//! ω; only the loads' harmonics and the particular solution do (one n_a-sized complex solve per
//! harmonic), so a sweep makes each contact set's phase once and re-tunes it per point.
use super::{Harmonics, Phase, add, force_harmonics, gap_harmonics};
use crate::model::{Compliance, Model};
use nalgebra::{DMatrix, DVector, Dyn, LU};
use num_complex::Complex64 as C;
use std::sync::Arc;

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
    /// The static harmonic's load g_a and solution x_a: its operator is K_cond at any ω, so a
    /// re-tuning with the same load (bit for bit) reuses it (an LU per stuck phase and λ before).
    pub statics: std::sync::OnceLock<(DVector<C>, DVector<C>)>,
}

/// A phase's loads reduced to the free coordinates, per harmonic p, as three ω-independent parts:
/// with r_p(w) = f_p − (K − w² M + i w C) x_p (x_p the prescribed motion) and the massless rows
/// condensed, y_b = K_bb⁻¹ N_bᵀ r_p and g_a = N_aᵀ r_p − K_ab y_b are linear in r_p, so each is
/// v₀ + w² v₂ − i w v₁ with v₀, v₂, v₁ the images of f_p − K x_p, M x_p and C x_p. With the same
/// loads (a frequency walk) re-tunings reuse them: the massless solves and products were most of
/// a re-tuning (the real blade's n_b = 49 against n_a = 20; its walk's builds, validation/RECORD.md).
#[derive(Clone, Debug, Default)]
pub(super) struct ReducedLoads {
    force: Harmonics,
    presc: Harmonics,
    /// Per harmonic (ascending): p, the parts of y_b, those of g_a.
    parts: Vec<(u32, Parts, Parts)>,
}

/// A reduced load's parts [v₀, v₂, v₁] ([`ReducedLoads`]).
type Parts = [DVector<C>; 3];

impl ReducedLoads {
    fn new(phase: &Phase) -> Option<ReducedLoads> {
        let n = phase.n;
        let mut ps: Vec<u32> = phase.force.iter().chain(&phase.presc).map(|(p, _)| *p).collect();
        ps.sort_unstable();
        ps.dedup();
        let mut parts = Vec::with_capacity(ps.len());
        for p in ps {
            let f = phase.force.iter().find(|(q, _)| *q == p).map_or_else(|| DVector::zeros(n), |(_, v)| v.clone());
            let (r0, r2, r1) = match phase.presc.iter().find(|(q, _)| *q == p) {
                Some((_, xp)) => (f - times(&phase.k, xp), times(&phase.m, xp), times(&phase.c, xp)),
                None => (f, DVector::zeros(n), DVector::zeros(n)),
            };
            let ((b0, a0), (b2, a2), (b1, a1)) = (phase.reduced(&r0)?, phase.reduced(&r2)?, phase.reduced(&r1)?);
            parts.push((p, [b0, b2, b1], [a0, a2, a1]));
        }
        Some(ReducedLoads { force: phase.force.clone(), presc: phase.presc.clone(), parts })
    }

    /// Whether these are the parts of the loads `force` and `presc`: bit for bit (−0.0 ≠ 0.0),
    /// so reuse cannot change a result.
    fn is_for(&self, force: &Harmonics, presc: &Harmonics) -> bool {
        // Compared in place: this runs at every re-tuning (no allocation on the walk's hot path).
        let same = |x: &Harmonics, y: &Harmonics| x.len() == y.len() && x.iter().zip(y).all(|((p, a), (q, b))| p == q && same_bits(a, b));
        same(&self.force, force) && same(&self.presc, presc)
    }
}

/// v₀ + w² v₂ − i w v₁ of the parts [v₀, v₂, v₁] ([`ReducedLoads`]).
fn at_frequency(v: &Parts, w: f64) -> DVector<C> {
    DVector::from_fn(v[0].len(), |i, _| v[0][i] + v[1][i] * (w * w) - C::new(0.0, w) * v[2][i])
}

/// `a` and `b` bit for bit (−0.0 ≠ 0.0).
fn same_bits(a: &DVector<C>, b: &DVector<C>) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.re.to_bits() == y.re.to_bits() && x.im.to_bits() == y.im.to_bits())
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
        let nf = self.free.ncols();
        if !self.reduced_loads.is_for(&self.force, &self.presc) {
            self.reduced_loads = Arc::new(ReducedLoads::new(self)?);
        }
        let t = &self.tuning;
        let (mut part, mut slave_part) = (Vec::new(), Vec::new());
        for (p, b, a) in &self.reduced_loads.parts {
            let (p, w) = (*p, *p as f64 * self.omega);
            let yb = at_frequency(b, w);
            let xa = if nf == 0 {
                DVector::zeros(0)
            } else {
                let ga = at_frequency(a, w);
                match t.statics.get().filter(|(g, _)| p == 0 && same_bits(g, &ga)) {
                    Some((_, x)) => x.clone(),
                    None => {
                        let op = DMatrix::from_fn(nf, nf, |i, j| C::new(t.k_cond[(i, j)] - w * w * t.m_aa[(i, j)], w * t.c_aa[(i, j)]));
                        let x = op.lu().solve(&ga)?;
                        if p == 0 {
                            let _ = t.statics.set((ga, x.clone()));
                        }
                        x
                    }
                }
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

    /// The load r (complex, full model) condensed: y_b = K_bb⁻¹ N_bᵀ r (the massless rows' static
    /// answer to it) and g_a = N_aᵀ r − K_ab y_b (the massive rows' load), per the module doc of
    /// [`Phase::tune`]; `None` where K_bb's solve fails.
    fn reduced(&self, r: &DVector<C>) -> Option<(DVector<C>, DVector<C>)> {
        let (t, nb) = (&self.tuning, self.slave.ncols());
        let yb = match &t.k_bb {
            Some(lu) => {
                let gb = projected(&self.slave, t.slave_rows.as_deref(), r);
                let (re, im) = (lu.solve(&gb.map(|z| z.re))?, lu.solve(&gb.map(|z| z.im))?);
                DVector::from_fn(nb, |i, _| C::new(re[i], im[i]))
            }
            None => DVector::zeros(nb),
        };
        let ga = if self.free.ncols() == 0 { DVector::zeros(0) } else { projected(&self.free, t.free_rows.as_deref(), r) - times(&t.k_ab, &yb) };
        Some((yb, ga))
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

#[cfg(test)]
mod tests {
    use super::Phase;
    use crate::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};
    use std::sync::Arc;

    /// A 2-DOF model (masses 1 and 2, springs 2 and 1, stiffness-proportional damping 5 %) with a
    /// rigid moving stop on DOF 1 (stuck, it has a prescribed motion with a static and a first
    /// harmonic), forced on DOF 0, at ω.
    fn chain(omega: f64, motion: f64) -> Model {
        let mut stop = Contact::on_dof(1, 1.0, 0.3, Compliance::Rigid);
        stop.motion = vec![Harmonic { amplitude: motion, harmonic: 1, phase: 0.4 }];
        let stiffness = [vec![3.0, -1.0], vec![-1.0, 1.0]];
        let damping: Vec<Vec<f64>> = stiffness.iter().map(|row| row.iter().map(|v| 0.05 * v).collect()).collect();
        let structure = Structure {
            mass: Matrix::from_rows(&[vec![1.0, 0.0], vec![0.0, 2.0]]),
            stiffness: Matrix::from_rows(&stiffness),
            damping: Some(Matrix::from_rows(&damping)),
        };
        let force = Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } };
        Model { structure, forces: vec![force], contacts: vec![stop], frequency: omega, frictions: Vec::new(), rubbing: Vec::new() }
    }

    /// A re-tuned phase's particular solution (its loads' reduced parts reused, [`super::ReducedLoads`])
    /// against the closed form, on a unit mass (k = 2 to ground through a massless DOF: K = [[3, −1],
    /// [−1, 1]], c = 0.15) forced on both DOFs, 1·cos ωt on the massless one and 0.5·cos 2ωt on the
    /// mass: per harmonic w = pω, x₀ = (f₀ + f₁)/(2 − w² + 0.15 i w) (the massless row condensed,
    /// x₁ = f₁ + x₀), re-tuned from ω = 1.2 to 1.7.
    #[test]
    fn a_retuned_phase_with_a_massless_dof_matches_its_closed_form_harmonic_response() {
        use num_complex::Complex64 as C;
        let model = |omega: f64| {
            let structure = Structure {
                mass: Matrix::from_rows(&[vec![1.0, 0.0], vec![0.0, 0.0]]),
                stiffness: Matrix::from_rows(&[vec![3.0, -1.0], vec![-1.0, 1.0]]),
                damping: Some(Matrix::from_rows(&[vec![0.15, 0.0], vec![0.0, 0.0]])),
            };
            let forces = vec![
                Force { dof: 1, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } },
                Force { dof: 0, term: Harmonic { amplitude: 0.5, harmonic: 2, phase: 0.0 } },
            ];
            Model { structure, forces, contacts: Vec::new(), frequency: omega, frictions: Vec::new(), rubbing: Vec::new() }
        };
        let omega = 1.7;
        let made = Phase::new(&model(1.2), &[], &[]).expect("the free phase");
        let retuned = made.retuned(&model(omega)).expect("re-tuned");
        assert!(Arc::ptr_eq(&made.reduced_loads, &retuned.reduced_loads), "the same loads: the parts are reused");
        for (p, f0, f1) in [(1, 0.0, 1.0), (2, 0.5, 0.0)] {
            let w = p as f64 * omega;
            let x0 = C::new(f0 + f1, 0.0) / C::new(2.0 - w * w, 0.15 * w);
            let x1 = x0 + f1;
            let at = |h: &super::Harmonics| h.iter().find(|(q, _)| *q == p).expect("the harmonic").1[0];
            let (e0, e1) = ((at(&retuned.part) - x0).norm() / x0.norm(), (at(&retuned.slave_part) - x1).norm() / x1.norm());
            assert!(e0 < 1e-14 && e1 < 1e-14, "harmonic {p}: mass {e0:e}, massless DOF {e1:e}");
        }
    }

    #[test]
    fn retuned_reuses_presc_products_only_for_the_same_motion_and_matches_a_phase_made_anew() {
        let made = Phase::new(&chain(1.2, 0.05), &[0], &[]).expect("the stuck phase");
        assert!(made.presc.len() == 2, "the stuck DOF's motion has harmonics 0 and 1");
        let bits = |p: &Phase| {
            p.part
                .iter()
                .chain(&p.slave_part)
                .flat_map(|(_, v)| v.iter().flat_map(|z| [z.re.to_bits(), z.im.to_bits()]).collect::<Vec<_>>())
                .collect::<Vec<_>>()
        };
        // Another ω, the same motion: the products are shared and the result is the uncached one's.
        let retuned = made.retuned(&chain(1.7, 0.05)).expect("re-tuned");
        assert!(Arc::ptr_eq(&made.reduced_loads, &retuned.reduced_loads));
        let anew = Phase::new(&chain(1.7, 0.05), &[0], &[]).expect("made anew");
        assert_eq!(bits(&retuned), bits(&anew));
        // A perturbed motion must invalidate them: else the particular solution keeps the old load.
        let moved = made.retuned(&chain(1.7, 0.05 * (1.0 + 1e-9))).expect("re-tuned, moved");
        assert!(!Arc::ptr_eq(&made.reduced_loads, &moved.reduced_loads));
        let anew = Phase::new(&chain(1.7, 0.05 * (1.0 + 1e-9)), &[0], &[]).expect("made anew, moved");
        assert_eq!(bits(&moved), bits(&anew));
        assert_ne!(bits(&moved), bits(&retuned));
    }
}
