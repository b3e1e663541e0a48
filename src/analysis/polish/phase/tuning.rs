//! A phase's periodic particular solution at its frequency, and the phase re-tuned to another
//! frequency: its matrices, basis, condensation and Â (so its eigendecomposition) do not depend on
//! ω; only the loads' harmonics and the particular solution do (one n_a-sized complex solve per
//! harmonic), so a sweep makes each contact set's phase once and re-tunes it per point.
use super::super::eigen_flow::EigenFlow;
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

/// The products K x_p, M x_p, C x_p of each harmonic x_p of a phase's prescribed motion: with
/// the same loads they do not depend on ω (a frequency walk), so re-tunings reuse them.
#[derive(Clone, Debug, Default)]
pub(super) struct PrescTerms {
    presc: Harmonics,
    kmc: Vec<[DVector<C>; 3]>,
}

impl PrescTerms {
    fn new(phase: &Phase) -> PrescTerms {
        let kmc = phase.presc.iter().map(|(_, xp)| [times(&phase.k, xp), times(&phase.m, xp), times(&phase.c, xp)]).collect();
        PrescTerms { presc: phase.presc.clone(), kmc }
    }

    /// Whether these are the products of `presc`: bit for bit (−0.0 ≠ 0.0), so reuse cannot
    /// change a result.
    fn is_for(&self, presc: &Harmonics) -> bool {
        // Compared in place: this runs at every re-tuning (no allocation on the walk's hot path).
        self.presc.len() == presc.len() && self.presc.iter().zip(presc).all(|((p, a), (q, b))| p == q && same_bits(a, b))
    }
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

/// (K_cond − w² M_aa + i w C_aa) x = g by Â's modes, O(n_a²) where an LU is O(n_a³): the
/// first-order form's x rows of (iw − A)⁻¹ [0; M_aa⁻¹ g] (balanced: the velocity rows over the
/// speed s; [`EigenFlow::resolvent`]), then one step of iterative refinement on the operator
/// itself (Higham, "Accuracy and Stability of Numerical Algorithms", ch. 12). Alone, the modal
/// solve carries the balanced Â's eigenvalue error, ε(s/ω₁)² relative for a slow mode (eigen_flow.rs),
/// 2e-11 on the coarse blade (its events moved by 6e-8 rad/s); one refinement brings it to the
/// residual's round-off, an LU's accuracy, while the modal error is far below 1.
fn modal_solve(f: &EigenFlow, t: &Tuning, mff_inv: &DMatrix<f64>, speed: f64, w: f64, g: &DVector<C>) -> Option<DVector<C>> {
    let nf = g.len();
    let solve = |g: &DVector<C>| {
        let u: Vec<C> = (0..nf).map(|i| (0..nf).map(|k| g[k] * mff_inv[(i, k)]).sum::<C>() / speed).collect();
        f.resolvent(w, &u, nf)
    };
    let x = solve(g)?;
    // r = g − (K_cond x − w² M_aa x + i w C_aa x).
    let (kx, mx, cx) = (times(&t.k_cond, &x), times(&t.m_aa, &x), times(&t.c_aa, &x));
    let r = DVector::from_fn(nf, |i, _| g[i] - kx[i] + mx[i] * (w * w) - cx[i] * C::new(0.0, w));
    Some(x + solve(&r)?)
}

impl Phase {
    /// The particular solution of the phase's loads at its ω (`part`, `slave_part`): per harmonic,
    /// g = Nᵀ(f − (−(pω)² M + ipω C + K) x_presc); the massless rows are static,
    /// K_ba x_a + K_bb x_b = g_b, so x_b = K_bb⁻¹ g_b + S x_a, and the massive ones solve
    /// (−(pω)² M_aa + ipω C_aa + K_cond) x_a = g_a − K_ab K_bb⁻¹ g_b. `None` when that operator
    /// is singular (an undamped resonance).
    pub(super) fn tune(&mut self) -> Option<()> {
        let (nf, nb) = (self.free.ncols(), self.slave.ncols());
        if !self.presc_terms.is_for(&self.presc) {
            self.presc_terms = Arc::new(PrescTerms::new(self));
        }
        let t = &self.tuning;
        // Â's eigendecomposition where it is made and accepted (a re-tuned phase's: [`Phase::retuned`]).
        let eigen = Arc::clone(&self.eigen);
        let modes = eigen.get().and_then(|f| f.as_ref());
        let mut ps: Vec<u32> = self.force.iter().chain(&self.presc).map(|(p, _)| *p).collect();
        ps.sort_unstable();
        ps.dedup();
        let (mut part, mut slave_part) = (Vec::new(), Vec::new());
        for p in ps {
            let w = p as f64 * self.omega;
            let mut r = self.force.iter().find(|(q, _)| *q == p).map_or_else(|| DVector::zeros(self.n), |(_, v)| v.clone());
            if let Some(j) = self.presc.iter().position(|(q, _)| *q == p) {
                let [kx, mx, cx] = &self.presc_terms.kmc[j];
                r -= kx - mx * C::new(w * w, 0.0) + cx * C::new(0.0, w);
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
                match (t.statics.get().filter(|(g, _)| p == 0 && same_bits(g, &ga)), modes) {
                    (Some((_, x)), _) => x.clone(),
                    (None, Some(f)) => modal_solve(f, t, &self.mff_inv, self.speed, w, &ga)?,
                    (None, None) => {
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

    /// This phase at `model`'s frequency and loads, `model` being the phase's own at another
    /// frequency (the same structure and contacts): the particular solution made again, the rest
    /// (the eigendecomposition included) shared. `None` as for [`Phase::new`].
    pub fn retuned(&self, model: &Model) -> Option<Phase> {
        let mut p = self.clone();
        // A re-tuned phase flows (a sweep's, a walk's): its eigendecomposition is made here if
        // not yet, for the particular solution by modes (`tune`). A phase made anew takes the LU:
        // some only give their forces (a hold phase's), and never need the decomposition.
        let _ = p.eigen();
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

    /// A re-tuned phase's particular solution is the modal one ([`super::modal_solve`]): on the
    /// chain with DOF 1 stuck (a 1-DOF phase: m = 1, k = 3, c = 0.15, driven by the unit force and
    /// by the stop's motion X₁ through K₀₁ = −1, C₀₁ = −0.05), against the closed form
    /// X₀ = (F − (K₀₁ + ipω C₀₁) X₁) / (3 − (pω)² + 0.15 ipω) per harmonic, and against the LU
    /// of a phase made anew at that ω.
    #[test]
    fn a_retuned_one_dof_phase_matches_its_closed_form_harmonic_response() {
        use num_complex::Complex64 as C;
        let (omega, motion) = (1.7, 0.05);
        let retuned = Phase::new(&chain(1.2, motion), &[0], &[]).expect("the stuck phase").retuned(&chain(omega, motion)).expect("re-tuned");
        assert!(retuned.eigen.get().is_some_and(|f| f.is_some()), "the re-tuning takes the modal path");
        let anew = Phase::new(&chain(omega, motion), &[0], &[]).expect("made anew (LU)");
        let exact = |p: u32| {
            let w = p as f64 * omega;
            let (f, x1) = if p == 0 { (C::new(0.0, 0.0), C::new(0.3, 0.0)) } else { (C::new(1.0, 0.0), C::from_polar(motion, 0.4)) };
            (f - C::new(-1.0, -0.05 * w) * x1) / C::new(3.0 - w * w, 0.15 * w)
        };
        for p in [0, 1] {
            let at = |ph: &Phase| ph.part.iter().find(|(q, _)| *q == p).expect("the harmonic")[0].1[0];
            let x = exact(p);
            let (modal, lu) = ((at(&retuned) - x).norm() / x.norm(), (at(&anew) - x).norm() / x.norm());
            println!("harmonic {p}: modal {modal:.1e}, LU {lu:.1e} relative to the closed form");
            assert!(modal < 1e-14 && lu < 1e-14, "harmonic {p}: modal {modal:e}, LU {lu:e}");
        }
    }

    /// The modal solve against the LU and the closed form on a stiff spread: a unit mass (k = 1,
    /// c = 0.1) carrying a tip of 1e-6 on a spring of 100 (its mode at 1e4 rad/s, the balancing
    /// speed s = 1.4e4) at ω = 0.9, s/ω ≈ 1.6e4 (a Craig–Bampton blade's 3.6e3 beyond): the modal
    /// solve alone is off by ≈ ε(s/ω)² (eigen_flow.rs), the refined one must be at an LU's
    /// accuracy. Closed form: Cramer's rule on the 2 × 2 operator.
    #[test]
    fn the_refined_modal_solve_matches_the_lu_on_a_stiff_spread() {
        use crate::model::Model;
        use nalgebra::DVector;
        use num_complex::Complex64 as C;
        let (m1, ks, omega) = (1e-6, 100.0, 0.9);
        let structure = Structure {
            mass: Matrix::from_rows(&[vec![1.0, 0.0], vec![0.0, m1]]),
            stiffness: Matrix::from_rows(&[vec![1.0 + ks, -ks], vec![-ks, ks]]),
            damping: Some(Matrix::from_rows(&[vec![0.1, 0.0], vec![0.0, 0.0]])),
        };
        let force = Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } };
        let model = Model { structure, forces: vec![force], contacts: Vec::new(), frequency: omega, frictions: Vec::new(), rubbing: Vec::new() };
        let phase = Phase::new(&model, &[], &[]).expect("the free phase");
        let f = phase.eigen().expect("Â's modes accepted");
        let op = [[C::new(1.0 + ks - omega * omega, 0.1 * omega), C::new(-ks, 0.0)], [C::new(-ks, 0.0), C::new(ks - m1 * omega * omega, 0.0)]];
        let det = op[0][0] * op[1][1] - op[0][1] * op[1][0];
        let exact = [op[1][1] / det, -op[1][0] / det];
        let g = DVector::from_column_slice(&[C::new(1.0, 0.0), C::new(0.0, 0.0)]);
        let error = |x: &DVector<C>| ((x[0] - exact[0]).norm().max((x[1] - exact[1]).norm())) / exact[0].norm().max(exact[1].norm());
        let u: Vec<C> = (0..2).map(|i| (0..2).map(|k| g[k] * phase.mff_inv[(i, k)]).sum::<C>() / phase.speed).collect();
        let alone = error(&f.resolvent(omega, &u, 2).expect("not an eigenvalue"));
        let refined = error(&super::modal_solve(f, &phase.tuning, &phase.mff_inv, phase.speed, omega, &g).expect("not an eigenvalue"));
        let lu = error(&phase.part[0].1.rows(0, 2).into_owned());
        println!("s/ω = {:.1e}: modal alone {alone:.1e}, refined {refined:.1e}, LU {lu:.1e} relative to Cramer's rule", phase.speed / omega);
        assert!(refined < 1e-13 && lu < 1e-13, "refined {refined:e}, LU {lu:e}");
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
        assert!(Arc::ptr_eq(&made.presc_terms, &retuned.presc_terms));
        // Made anew and re-tuned at its own ω: the particular solution by the same (modal) path.
        let anew = Phase::new(&chain(1.7, 0.05), &[0], &[]).and_then(|p| p.retuned(&chain(1.7, 0.05))).expect("made anew");
        assert_eq!(bits(&retuned), bits(&anew));
        // A perturbed motion must invalidate them: else the particular solution keeps the old load.
        let moved = made.retuned(&chain(1.7, 0.05 * (1.0 + 1e-9))).expect("re-tuned, moved");
        assert!(!Arc::ptr_eq(&made.presc_terms, &moved.presc_terms));
        let anew = Phase::new(&chain(1.7, 0.05 * (1.0 + 1e-9)), &[0], &[]).and_then(|p| p.retuned(&chain(1.7, 0.05 * (1.0 + 1e-9)))).expect("made anew, moved");
        assert_eq!(bits(&moved), bits(&anew));
        assert_ne!(bits(&moved), bits(&retuned));
    }
}
