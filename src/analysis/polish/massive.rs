//! The one-period variation carried in the massive state (d = 2 n_a) where the model has massless
//! DOFs: every phase flows the same massive coordinates x_a = N_aᵀ x, v_a = N_aᵀ v, and the stuck
//! and massless DOFs are recovered from them algebraically (src/formulation.md §4.1). A phase's
//! transition is L_e e^{A_e τ} R with R = diag(N_aᵀ, N_aᵀ) and L_e = diag(N_a + N_b S_e, ·), and
//! R L_e = I (N orthonormal), so a chain of them is L_last (Π e^{A_e τ_e}) R: the 2n-row variation
//! (138 × 191 per phase on the real blade, lifted and projected at every phase) becomes a
//! d-row one (40 × 93), lifted once at the end. Exact where every event's state map is the
//! identity (compliant switches, a massless contact's closing and release); a plastic impact on
//! a massive DOF keeps the full-state path (rigid.rs).
use super::events::EventKind;
use super::orbit::PolishedOrbit;
use super::rigid::Variation;
use nalgebra::{DMatrix, DVector, RowDVector};

/// [x; v] ↦ [N_aᵀ x; N_aᵀ v].
fn project(basis: &DMatrix<f64>, f: &DVector<f64>) -> DVector<f64> {
    let (n, nf) = basis.shape();
    let mut out = DVector::zeros(2 * nf);
    out.rows_mut(0, nf).copy_from(&basis.tr_mul(&f.rows(0, n)));
    out.rows_mut(nf, nf).copy_from(&basis.tr_mul(&f.rows(n, n)));
    out
}

/// The d-row columns `z` carried back to [x; v] by L = diag(lift, lift): 2n rows.
fn lifted(lift: &DMatrix<f64>, z: &DMatrix<f64>) -> DMatrix<f64> {
    let (n, nf) = lift.shape();
    let mut out = DMatrix::zeros(2 * n, z.ncols());
    out.rows_mut(0, n).copy_from(&(lift * z.rows(0, nf)));
    out.rows_mut(n, n).copy_from(&(lift * z.rows(nf, nf)));
    out
}

/// Columns [X | rest] with X on the massive coordinates (d columns) expanded to the full state's
/// columns, [X R | rest] (X R = [X_x N_aᵀ, X_v N_aᵀ]).
fn expanded(basis: &DMatrix<f64>, z: &DMatrix<f64>) -> DMatrix<f64> {
    let (n, nf) = basis.shape();
    let rest = z.ncols() - 2 * nf;
    let mut out = DMatrix::zeros(z.nrows(), 2 * n + rest);
    out.columns_mut(0, n).copy_from(&(z.columns(0, nf) * basis.transpose()));
    out.columns_mut(n, n).copy_from(&(z.columns(nf, nf) * basis.transpose()));
    out.columns_mut(2 * n, rest).copy_from(&z.columns(2 * nf, rest));
    out
}

impl PolishedOrbit {
    /// Whether the variation can be carried in the massive state: some DOF is massless or
    /// stuck (else the massive state is the full one), every phase flows the same massive
    /// coordinates (its stuck contacts on massless DOFs) and no event resets velocities (a plastic
    /// impact on a massive DOF).
    pub(super) fn massive_reducible(&self) -> bool {
        let basis = self.phases[0].massive_basis();
        let resets = self.events.iter().any(|e| matches!(e.kind, EventKind::Impact { .. }) && !self.model.contact_is_massless(&self.model.contacts[e.contact]));
        basis.ncols() > 0 && basis.ncols() < self.model.n() && !resets && self.phases.iter().all(|p| p.massive_basis() == basis)
    }

    /// The one-period transition from just after event 0 over the spans `spans` of the phases,
    /// L_last (Π e^{A_e τ_e}) R (2n × 2n), for a [`Self::massive_reducible`] orbit.
    pub(super) fn massive_transition(&self, spans: &[f64]) -> DMatrix<f64> {
        let basis = self.phases[0].massive_basis();
        let d = 2 * basis.ncols();
        let mut p = DMatrix::identity(d, d);
        for (ph, &span) in self.phases.iter().zip(spans) {
            p = ph.exp(span) * p;
        }
        let last = &self.phases[spans.len() - 1];
        expanded(basis, &lifted(&last.lift(), &p))
    }

    /// [`Self::variation`] carried in the massive state (module doc), for a
    /// [`Self::massive_reducible`] orbit with events: the same columns (y0, τ_0 as phase 0's
    /// start, τ_1 … τ_{ne−1}, the return time of event 0) and rows, expanded at the end.
    pub(super) fn massive_variation(&self, y0: &DVector<f64>, tau: &[f64], ret: f64) -> Option<Variation> {
        let (n, ne) = (self.model.n(), self.events.len());
        let basis = self.phases[0].massive_basis();
        let nf = basis.ncols();
        let (n2, d) = (2 * n, 2 * nf);
        // Columns: the start state's massive coordinates (the y0 columns are these times R),
        // then the ne + 1 times.
        let cols = d + ne + 1;
        let field = |e: usize, y: &DVector<f64>, t: f64| self.vector_field(e, y, t);
        let mut y = y0.clone();
        // z = R dy before the phase's event; the full variation at an event is L z + f₁ δ_endᵀ.
        let mut z = DMatrix::identity(d, cols);
        let (mut g, mut dg) = (DVector::zeros(ne), DMatrix::zeros(ne, cols));
        let mut d_end = DMatrix::zeros(n2, cols);
        for e in 0..ne {
            let ph = &self.phases[e];
            let (t0, t1) = (tau[e], if e + 1 < ne { tau[e + 1] } else { ret });
            let ex = ph.exp(t1 - t0);
            let ym = ph.flow_with(&ex, t0, &y, t1);
            z = &ex * &z;
            let (next, end_col) = ((e + 1) % ne, if e + 1 < ne { d + e + 1 } else { d + ne });
            let f0 = &ex * project(basis, &field(e, &y, t0));
            let mut start = z.column_mut(d + e);
            start -= f0;
            let f1 = field(e, &ym, t1);
            let lift = ph.lift();
            let ev = self.events[next];
            let c = ev.contact;
            if ev.kind == EventKind::Release {
                // The held force is affine in y with the phase's gradient G = G' R (phase.rs), so
                // G L = G': G's x and v columns times the lift.
                let row = ph.stuck_contacts().position(|k| k == c)?;
                let grad = ph.stuck_force_gradient().row(row).into_owned();
                let mut reduced = RowDVector::zeros(d);
                reduced.columns_mut(0, nf).copy_from(&(grad.columns(0, n) * &lift));
                reduced.columns_mut(nf, nf).copy_from(&(grad.columns(n, n) * &lift));
                let (force, rate) = self.held_force(e, c, &ym, t1)?;
                g[next] = force;
                dg.row_mut(next).copy_from(&(reduced * &z));
                dg[(next, end_col)] += (&grad * &f1)[0] + rate;
            } else {
                let contact = &self.model.contacts[c];
                let mut normal = RowDVector::zeros(nf);
                for &(dof, coef) in &contact.row {
                    normal += lift.row(dof) * coef;
                }
                g[next] = self.clearance(c, &ym, t1);
                dg.row_mut(next).copy_from(&(-(normal * z.rows(0, nf))));
                dg[(next, end_col)] += self.gap(c, t1, 1) - contact.along(|k| f1[k]);
            }
            if e + 1 == ne {
                d_end = lifted(&lift, &z);
                let mut back = d_end.column_mut(end_col);
                back += &f1;
            }
            let mut end = z.column_mut(end_col);
            end += project(basis, &f1);
            y = ym;
        }
        let (d_end, d_conditions) = (expanded(basis, &d_end), expanded(basis, &dg));
        let all = y.iter().chain(g.iter()).chain(d_end.iter()).chain(d_conditions.iter()).all(|v| v.is_finite());
        all.then_some(Variation { end: y, conditions: g, d_end, d_conditions })
    }
}
