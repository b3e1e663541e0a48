//! A phase's flow split for the closed-form signals ([`super::super::signals`]): its transient
//! from a state, Σ_j q_j e^{λ_j (t − a)}, and its periodic particular solution.
use super::{Harmonics, Phase, eval};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;

/// A phase's transient from a state at `a`: the massive free state's deviation from the
/// particular solution as Σ_j q_j e^{λ_j (t − a)} (columns q_j in [x_a; v_a], Â's eigenvalues λ_j),
/// and the lift L = N_a + N_b S that carries it to every DOF ([`Phase::transient`]).
pub(in crate::analysis::polish) struct Transient {
    pub lambda: Vec<C>,
    q: DMatrix<C>,
    lift: DMatrix<f64>,
}

impl Transient {
    /// The m_j of ρ·y(t) = ρ·P(t) + Re Σ_j m_j e^{λ_j (t − a)} for a row ρ on the full state
    /// [x; v] (P the periodic particular solution, [`Phase::particular`]).
    pub fn coefficients(&self, rho: &DVector<f64>) -> Vec<C> {
        let (n, nf) = (self.lift.nrows(), self.lift.ncols());
        let (rx, rv) = (self.lift.tr_mul(&rho.rows(0, n)), self.lift.tr_mul(&rho.rows(n, n)));
        (0..self.lambda.len()).map(|j| (0..nf).map(|i| self.q[(i, j)] * rx[i] + self.q[(nf + i, j)] * rv[i]).sum()).collect()
    }
}

/// A DOF's column in a basis of unit columns (`Some(None)`: not in it), `None` where the basis is not.
type Column = Option<Option<usize>>;

impl Phase {
    /// The phase's transient from the full state `y` at `a` ([`Transient`]): Â's eigenvectors
    /// weighted by the modal coordinates of D⁻¹(N_aᵀ y − p(a)), scaled back by D (see
    /// [`Self::exp`]). `None` where Â has no accepted eigendecomposition (the Padé path).
    pub fn transient(&self, a: f64, y: &DVector<f64>) -> Option<Transient> {
        let nf = self.free.ncols();
        let lift = self.lifted().clone();
        if nf == 0 {
            return Some(Transient { lambda: vec![], q: DMatrix::zeros(0, 0), lift });
        }
        let (lambda, q) = self.modes_of(&self.homogeneous(a, y))?;
        Some(Transient { lambda, q, lift })
    }

    /// The massive free state's deviation from the particular solution at `t`, z = N_aᵀ y − p(t)
    /// (what e^{Aτ} carries: [`Self::flow`]).
    pub fn homogeneous(&self, t: f64, y: &DVector<f64>) -> DVector<f64> {
        self.free_state(y) - eval(&self.part, self.omega, t, 0, 2 * self.free.ncols())
    }

    /// Â's eigenvalues λ_j and the columns q_j (in [x_a; v_a]) with e^{Aτ} z = Re Σ_j q_j e^{λ_j τ}
    /// (V weighted by the modal coordinates of D⁻¹z, scaled back by D: see [`Self::exp`]); `None`
    /// where Â has no accepted eigendecomposition.
    pub fn modes_of(&self, z: &DVector<f64>) -> Option<(Vec<C>, DMatrix<C>)> {
        let nf = self.free.ncols();
        let f = self.eigen()?;
        let mut u = z.clone();
        u.rows_mut(nf, nf).scale_mut(1.0 / self.speed);
        let (lambda, mut q) = f.modal(&u);
        q.rows_mut(nf, nf).iter_mut().for_each(|z| *z *= self.speed);
        Some((lambda, q))
    }

    /// The periodic particular solution of every DOF, P(t) = Re Σ_p P̂_p e^{ipωt} (full state
    /// [x; v]): the stuck DOFs' prescribed motion, the massive free coordinates' particular
    /// solution and the massless ones' condensation of it (what [`Self::flow`] gives with no transient).
    pub fn particular(&self) -> Harmonics {
        let (n, nf, nb) = (self.n, self.free.ncols(), self.slave.ncols());
        let mut orders: Vec<u32> = self.part.iter().chain(&self.presc).map(|(p, _)| *p).collect();
        orders.sort_unstable();
        orders.dedup();
        let find = |h: &Harmonics, p: u32, len: usize| h.iter().find(|(q, _)| *q == p).map_or_else(|| DVector::zeros(len), |(_, v)| v.clone());
        let cplx = |a: &DMatrix<f64>| a.map(|v| C::new(v, 0.0));
        let (free, slave) = (cplx(&self.free), cplx(&self.slave));
        orders
            .into_iter()
            .map(|p| {
                let xa = find(&self.part, p, 2 * nf).rows(0, nf).into_owned();
                let x = find(&self.presc, p, n) + &free * xa + &slave * find(&self.slave_part, p, nb);
                let mut y = DVector::zeros(2 * n);
                y.rows_mut(n, n).copy_from(&(&x * C::new(0.0, p as f64 * self.omega)));
                y.rows_mut(0, n).copy_from(&x);
                (p, y)
            })
            .collect()
    }

    /// B P̂_p of the row `row` (a contact's) on the particular solution's displacement, per
    /// harmonic ([`Self::particular`]'s orders), from the rows of N_a, N_b and the prescribed
    /// motion at the row's DOFs only (O(n_a + n_b) per harmonic where the full P̂_p is O(n n_a)).
    pub fn particular_along(&self, row: &[(usize, f64)]) -> Vec<(u32, C)> {
        let (nf, nb) = (self.free.ncols(), self.slave.ncols());
        let mut orders: Vec<u32> = self.part.iter().chain(&self.presc).map(|(p, _)| *p).collect();
        orders.sort_unstable();
        orders.dedup();
        fn find(h: &Harmonics, p: u32) -> Option<&DVector<C>> {
            h.iter().find(|(q, _)| *q == p).map(|(_, v)| v)
        }
        // Where N_a's (N_b's) columns are unit vectors e_d, the row's DOF d is the column k with
        // rows[k] = d or none: the sum over k has that one term (its exact value).
        let column = |rows: &Option<Vec<usize>>, d: usize| rows.as_ref().map(|r| r.iter().position(|&e| e == d));
        let at_row: Vec<(usize, Column, Column)> =
            row.iter().map(|&(d, _)| (d, column(&self.tuning.free_rows, d), column(&self.tuning.slave_rows, d))).collect();
        orders
            .into_iter()
            .map(|p| {
                let (xa, xb, xp) = (find(&self.part, p), find(&self.slave_part, p), find(&self.presc, p));
                let at = |(d, ka, kb): (usize, Column, Column)| {
                    let mut v = xp.map_or(C::new(0.0, 0.0), |x| x[d]);
                    if let Some(xa) = xa {
                        v += match ka {
                            Some(k) => k.map_or(C::new(0.0, 0.0), |k| xa[k]),
                            None => (0..nf).map(|k| xa[k] * self.free[(d, k)]).sum::<C>(),
                        };
                    }
                    if let Some(xb) = xb {
                        v += match kb {
                            Some(k) => k.map_or(C::new(0.0, 0.0), |k| xb[k]),
                            None => (0..nb).map(|k| xb[k] * self.slave[(d, k)]).sum::<C>(),
                        };
                    }
                    v
                };
                (p, row.iter().zip(&at_row).map(|(&(_, c), &r)| at(r) * c).sum())
            })
            .collect()
    }

    /// B P̂_p for the rows B on the particular solution's displacement, per harmonic, given as
    /// B N_a (`on_massive`) and B N_b (`on_massless`): B N_a X̂_a + B N_b X̂_b. Only for a phase
    /// without stuck contacts (no prescribed motion), as the switch search's.
    pub fn particular_on(&self, on_massive: &DMatrix<f64>, on_massless: &DMatrix<f64>) -> Vec<(u32, DVector<C>)> {
        debug_assert!(self.stuck.is_empty());
        let nf = self.free.ncols();
        let times = |a: &DMatrix<f64>, x: &nalgebra::DVectorView<C>| {
            let (re, im) = (a * x.map(|z| z.re), a * x.map(|z| z.im));
            DVector::from_fn(a.nrows(), |i, _| C::new(re[i], im[i]))
        };
        let mut out: Vec<(u32, DVector<C>)> = self.part.iter().map(|(p, y)| (*p, times(on_massive, &y.rows(0, nf)))).collect();
        for (p, xb) in &self.slave_part {
            let v = times(on_massless, &xb.rows(0, xb.len()));
            match out.iter_mut().find(|(q, _)| q == p) {
                Some((_, x)) => *x += v,
                None => out.push((*p, v)),
            }
        }
        out
    }

    /// The stuck contacts' forces along the particular solution `part` ([`Self::particular`]),
    /// per harmonic: B_S (f_p − (−(pω)² M + ipω C + K) X̂_p) (its acceleration is (ipω)² X̂_p,
    /// the equations of motion holding exactly on it).
    pub fn stuck_force_particular(&self, part: &Harmonics) -> Harmonics {
        let n = self.n;
        let times = |a: &DMatrix<f64>, x: &DVector<C>| {
            let (re, im) = (a * x.map(|z| z.re), a * x.map(|z| z.im));
            DVector::from_fn(a.nrows(), |i, _| C::new(re[i], im[i]))
        };
        part.iter()
            .map(|(p, y)| {
                let w = *p as f64 * self.omega;
                let x = y.rows(0, n).into_owned();
                let f = self.force.iter().find(|(q, _)| q == p).map_or_else(|| DVector::zeros(n), |(_, v)| v.clone());
                let r = f - times(&self.k, &x) + times(&self.m, &x) * C::new(w * w, 0.0) - times(&self.c, &x) * C::new(0.0, w);
                (*p, times(&self.b_stuck, &r))
            })
            .collect()
    }
}
