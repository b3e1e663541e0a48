//! One linear phase between events, solved exactly: the contacts stuck on their obstacle and the
//! compliant contacts closed are fixed, so M x'' + C x' + K x = f(t) is linear with harmonic
//! forcing. The stuck contacts follow their obstacle, B_S x = gap_S(t); with the stuck rows
//! orthonormal (unit normals on disjoint DOFs) x = B_Sᵀ gap_S(t) + N x_f, N an orthonormal basis
//! of B_S's null space (the free DOFs' unit vectors when every stuck row is one DOF), and the
//! free coordinates obey Nᵀ M N x_f'' + Nᵀ C N x_f' + Nᵀ K N x_f = Nᵀ (f − M x_c'' − C x_c' − K x_c),
//! x_c = B_Sᵀ gap_S, whose flow is the periodic particular solution plus e^{Aτ} applied to the rest
//! (the matrix exponential of the first-order form, as in src/formulation.md §6.2 for one DOF).
//! Massless free coordinates x_b (a massless boundary, src/formulation.md §4.1: no mass, no
//! damping) answer statically, K_ba x_a + K_bb x_b = g_b(t): they are condensed, the closed
//! compliant springs on them included, and the state that flows is the massive [x_a; v_a] only.
use super::eigen_flow::EigenFlow;
use crate::model::{Compliance, Model};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;
use std::sync::{Arc, OnceLock};

// The closed-form signals' parts of a phase (its transient and particular solution): a child
// module, for the phase's fields.
mod particular;
pub(super) use particular::Transient;
// The massive coordinates' basis and lift, for the variation carried in them.
mod massive;
// The particular solution at a frequency, and a phase re-tuned to another one.
mod tuning;
use tuning::{ReducedLoads, Tuning, loads};

/// Complex amplitudes of a harmonic signal: value(t) = Re Σ_p amp_p e^{i p ω t}.
pub(super) type Harmonics = Vec<(u32, DVector<C>)>;

/// One phase's exact flow.
#[derive(Clone, Debug)]
pub(super) struct Phase {
    pub n: usize,
    omega: f64,
    /// The massive free coordinates' basis N_a (n × n_a, orthonormal columns) and the stuck contacts.
    /// This and the other ω-independent matrices are shared: a walk's build clones ~50 phases.
    free: Arc<DMatrix<f64>>,
    stuck: Vec<usize>,
    /// Rows of B of the stuck contacts, dense (|stuck| × n).
    b_stuck: Arc<DMatrix<f64>>,
    /// Closed compliant contacts.
    closed: Vec<usize>,
    /// The full-model matrices of this phase (K with the closed compliant springs), shared by
    /// its clones and re-tunings (a sweep re-tunes ~37 phases per point).
    m: Arc<DMatrix<f64>>,
    c: Arc<DMatrix<f64>>,
    k: Arc<DMatrix<f64>>,
    /// f(t) with the closed springs' obstacle terms, full model.
    force: Harmonics,
    /// Prescribed displacement of every DOF (nonzero only at stuck DOFs).
    presc: Harmonics,
    /// First-order form of the free DOFs, balanced: ŷ = [x_f; v_f/speed] (see [`Phase::exp`]).
    a: Arc<DMatrix<f64>>,
    /// The balancing rate [rad/s]: √‖M_ff⁻¹K_ff‖∞ ≥ ω_max of the phase.
    speed: f64,
    /// ‖Â‖₁, which sets the Taylor substeps of a short flow ([`Phase::flow`]).
    a_norm: f64,
    mff_inv: Arc<DMatrix<f64>>,
    /// Particular periodic solution of the massive free state [x_a; v_a].
    part: Harmonics,
    /// The massless free coordinates' basis N_b (n × n_b), their static condensation
    /// x_b = S x_a + (particular part), S = −K_bb⁻¹ K_ba, and their particular solution X_b.
    slave: Arc<DMatrix<f64>>,
    slave_map: Arc<DMatrix<f64>>,
    slave_part: Harmonics,
    /// What the particular solution needs at any ω (tuning.rs), shared by the phase's clones.
    tuning: Arc<Tuning>,
    /// K x_p, M x_p, C x_p of the prescribed motion's harmonics (tuning.rs), shared by the
    /// phase's re-tunings while their prescribed motion is bitwise the same.
    reduced_loads: Arc<ReducedLoads>,
    /// Â's eigendecomposition, made at the first flow and shared by the phase's clones (a
    /// reordered orbit's, a continuation step's); `None` inside where Â is refused
    /// ([`EigenFlow::new`]): the Padé and Taylor paths then.
    eigen: Arc<OnceLock<Option<EigenFlow>>>,
    /// [`Phase::stuck_force_gradient`], made at its first use.
    force_gradient: Arc<OnceLock<DMatrix<f64>>>,
    /// The lift L = N_a + N_b S and e^{Ah} at one step h, made at their first use and shared by
    /// the phase's clones and re-tunings (neither depends on ω).
    lift: Arc<OnceLock<DMatrix<f64>>>,
    grid_step: Arc<OnceLock<(f64, DMatrix<f64>)>>,
    /// M⁻¹ of the full model, made at the first plastic impact's reset and shared likewise.
    mass_inverse: Arc<OnceLock<Option<DMatrix<f64>>>>,
}

/// The longest span ‖Â τ‖₁ that [`Phase::flow`] takes by the Taylor action rather than the
/// matrix exponential (at most this many substeps of ~20 matrix-vector products each).
const SHORT_SPAN: f64 = 8.0;

fn eval(h: &Harmonics, omega: f64, t: f64, order: u32, len: usize) -> DVector<f64> {
    let mut out = DVector::zeros(len);
    for (p, amp) in h {
        let w = *p as f64 * omega;
        let e = C::from_polar(1.0, w * t) * C::new(0.0, w).powu(order);
        for i in 0..len {
            out[i] += (amp[i] * e).re;
        }
    }
    out
}

/// Harmonic amplitudes of f(t) (full model).
pub(super) fn force_harmonics(model: &Model) -> Harmonics {
    let mut h: Harmonics = Vec::new();
    for f in &model.forces {
        add(&mut h, f.term.harmonic, f.dof, C::from_polar(f.term.amplitude, f.term.phase), model.n());
    }
    h
}

/// Harmonic amplitudes of gap_i(t) (a 1-vector).
pub(super) fn gap_harmonics(model: &Model, i: usize) -> Harmonics {
    let c = &model.contacts[i];
    let mut h: Harmonics = vec![(0, DVector::from_element(1, C::new(c.gap, 0.0)))];
    for m in &c.motion {
        add(&mut h, m.harmonic, 0, C::from_polar(m.amplitude, m.phase), 1);
    }
    h
}

fn add(h: &mut Harmonics, p: u32, i: usize, v: C, len: usize) {
    match h.iter_mut().find(|(q, _)| *q == p) {
        Some((_, a)) => a[i] += v,
        None => {
            let mut a = DVector::zeros(len);
            a[i] = v;
            h.push((p, a));
        }
    }
}

impl Phase {
    /// `stuck` and `closed` are contact indices. `None` when the free system's operator is
    /// singular at a forcing harmonic (an undamped resonance).
    pub fn new(model: &Model, stuck: &[usize], closed: &[usize]) -> Option<Phase> {
        let n = model.n();
        let (omega, s) = (model.frequency, &model.structure);
        let m = dense(&s.mass, n);
        let c = s.damping.as_ref().map_or_else(|| DMatrix::zeros(n, n), |d| dense(d, n));
        let mut k = dense(&s.stiffness, n);
        // A closed compliant contact adds k_c B_iᵀ B_i to K (and k_c B_iᵀ gap_i(t) to f: `loads`).
        for &i in closed {
            let ct = &model.contacts[i];
            let Compliance::Compliant { stiffness } = ct.compliance else { continue };
            for &(a, ca) in &ct.row {
                for &(b, cb) in &ct.row {
                    k[(a, b)] += stiffness * ca * cb;
                }
            }
        }
        let (force, presc) = loads(model, stuck, closed);
        let b_stuck = DMatrix::from_fn(stuck.len(), n, |r, d| model.contacts[stuck[r]].row.iter().find(|e| e.0 == d).map_or(0.0, |e| e.1));
        let all = null_basis(model, stuck);
        let ff = |a: &DMatrix<f64>| all.transpose() * a * &all;
        let (m_ff, c_ff, k_ff) = (ff(&m), ff(&c), ff(&k));
        // Massless free coordinates (a massless boundary, src/formulation.md §4.1): no mass and
        // no damping, condensed statically; a column mixing mass and no mass is not supported.
        let massless: Vec<usize> = (0..all.ncols()).filter(|&j| m_ff.column(j).iter().all(|v| *v == 0.0)).collect();
        let massive: Vec<usize> = (0..all.ncols()).filter(|j| !massless.contains(j)).collect();
        if massless.iter().any(|&j| c_ff.column(j).iter().any(|v| *v != 0.0)) {
            return None;
        }
        let (free, slave) = (all.select_columns(&massive), all.select_columns(&massless));
        let (nf, nb) = (massive.len(), massless.len());
        let k_bb = k_ff.select_rows(&massless).select_columns(&massless);
        let k_ba = k_ff.select_rows(&massless).select_columns(&massive);
        let k_bb_lu = k_bb.lu();
        let slave_map = if nb == 0 { DMatrix::zeros(0, nf) } else { -k_bb_lu.solve(&k_ba)? };
        // K_aa − K_ab K_bb⁻¹ K_ba: the massive coordinates' condensed stiffness (Guyan's, exact
        // here since the condensed DOFs carry no inertia).
        let k_cond = k_ff.select_rows(&massive).select_columns(&massive) + k_ff.select_rows(&massive).select_columns(&massless) * &slave_map;
        let sub = |a: &DMatrix<f64>| a.select_rows(&massive).select_columns(&massive);
        let mff_inv = if nf == 0 { DMatrix::zeros(0, 0) } else { sub(&m_ff).try_inverse()? };
        let mut a = DMatrix::zeros(2 * nf, 2 * nf);
        let mut speed = 1.0;
        if nf > 0 {
            let mk = -&mff_inv * &k_cond;
            let norm = mk.row_iter().map(|r| r.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
            speed = if norm > 0.0 && norm.is_finite() { norm.sqrt() } else { 1.0 };
            a.view_mut((0, nf), (nf, nf)).fill_with_identity();
            a.view_mut((nf, 0), (nf, nf)).copy_from(&mk);
            a.view_mut((nf, nf), (nf, nf)).copy_from(&(-&mff_inv * sub(&c_ff)));
        }
        // A was built in [x; v]; the exponential takes the balanced one (see `exp`).
        if nf > 0 {
            a.view_mut((0, nf), (nf, nf)).scale_mut(speed);
            a.view_mut((nf, 0), (nf, nf)).scale_mut(1.0 / speed);
        }
        let a_norm = a.column_iter().map(|c| c.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
        let tuning = Arc::new(Tuning {
            k_bb: (nb > 0).then_some(k_bb_lu),
            k_ab: k_ff.select_rows(&massive).select_columns(&massless),
            m_aa: sub(&m_ff),
            c_aa: sub(&c_ff),
            k_cond,
            free_rows: tuning::unit_rows(&free),
            slave_rows: tuning::unit_rows(&slave),
            statics: Default::default(),
        });
        let mut phase = Phase {
            n,
            omega,
            free: Arc::new(free),
            stuck: stuck.to_vec(),
            b_stuck: Arc::new(b_stuck),
            closed: closed.to_vec(),
            m: Arc::new(m),
            c: Arc::new(c),
            k: Arc::new(k),
            force,
            presc,
            a: Arc::new(a),
            speed,
            a_norm,
            mff_inv: Arc::new(mff_inv),
            part: Vec::new(),
            slave: Arc::new(slave),
            slave_map: Arc::new(slave_map),
            slave_part: Vec::new(),
            tuning,
            reduced_loads: Arc::default(),
            eigen: Arc::default(),
            force_gradient: Arc::default(),
            lift: Arc::default(),
            grid_step: Arc::default(),
            mass_inverse: Arc::default(),
        };
        phase.tune()?;
        Some(phase)
    }

    /// Whether this is the phase of the stuck contacts `stuck` and the closed compliant ones
    /// `closed` (both ascending): a reordered orbit reuses it.
    pub fn is_for(&self, stuck: &[usize], closed: &[usize]) -> bool {
        self.stuck == stuck && self.closed == closed
    }

    /// Whether `other` flows by the same matrix Â (the same contact sets on the same structure).
    pub fn same_matrix(&self, other: &Phase) -> bool {
        self.stuck == other.stuck && self.closed == other.closed && self.speed == other.speed && self.a == other.a && self.b_stuck == other.b_stuck
    }

    /// Shares `other`'s eigendecomposition and force gradient (made or to be made once for both):
    /// only for a phase of [`Self::same_matrix`] and the same M, C, K.
    pub fn share_modes(&mut self, other: &Phase) {
        // Already shared (a clone or re-tuning of `other`, or shared before): nothing to compare.
        let shared = Arc::ptr_eq(&self.eigen, &other.eigen)
            && Arc::ptr_eq(&self.force_gradient, &other.force_gradient)
            && Arc::ptr_eq(&self.lift, &other.lift)
            && Arc::ptr_eq(&self.grid_step, &other.grid_step);
        if !shared && self.same_matrix(other) && self.m == other.m && self.c == other.c && self.k == other.k {
            self.eigen = Arc::clone(&other.eigen);
            self.force_gradient = Arc::clone(&other.force_gradient);
            self.lift = Arc::clone(&other.lift);
            self.grid_step = Arc::clone(&other.grid_step);
        }
    }

    /// Whether compliant contact `i` is closed in this phase.
    pub fn closed(&self, i: usize) -> bool {
        self.closed.contains(&i)
    }

    /// M⁻¹ of the full model (`None`: singular), made once for the phase and its clones and
    /// re-tunings: each plastic impact's reset inverted M anew, 8 % of the rigid blade's walk.
    pub fn mass_inverse(&self) -> Option<&DMatrix<f64>> {
        self.mass_inverse.get_or_init(|| (*self.m).clone().try_inverse()).as_ref()
    }

    /// The phase's fastest rate [rad/s] (the balancing speed, ≥ its ω_max): for sampling.
    pub fn speed_hint(&self) -> f64 {
        self.speed
    }

    pub fn stuck_contacts(&self) -> impl Iterator<Item = usize> + '_ {
        self.stuck.iter().copied()
    }

    /// e^{A τ} of the free state [x_f; v_f], computed as D e^{Â τ} D⁻¹ with D = diag(I, speed·I):
    /// in [x; v] a stiff phase's A has entries up to ω_max² beside 1, and scaling and squaring
    /// (nalgebra's Padé `exp`) then loses about ω_max/ω_ref digits; balanced, ‖Â‖ ≈ ω_max
    /// (Higham, "Functions of Matrices", §10.3; the coarse blade's stall at ω_max = 6.3e5 rad/s).
    /// With Â's eigendecomposition ([`EigenFlow`]) when it is well conditioned.
    pub fn exp(&self, tau: f64) -> DMatrix<f64> {
        self.unbalanced(match self.eigen() {
            Some(f) => f.exp(tau),
            None => (&*self.a * tau).exp(),
        })
    }

    /// D E D⁻¹, D = diag(I, speed·I): an exponential of Â back in [x; v] (see [`Self::exp`]).
    fn unbalanced(&self, mut e: DMatrix<f64>) -> DMatrix<f64> {
        let nf = self.free.ncols();
        if nf > 0 {
            e.view_mut((0, nf), (nf, nf)).scale_mut(1.0 / self.speed);
            e.view_mut((nf, 0), (nf, nf)).scale_mut(self.speed);
        }
        e
    }

    /// Â's eigendecomposition, made once per phase (shared by its clones); `None` where refused.
    fn eigen(&self) -> Option<&EigenFlow> {
        self.eigen.get_or_init(|| EigenFlow::new(&self.a)).as_ref()
    }

    /// Every DOF free and massive: N_a = I, no prescribed motion, nothing condensed.
    fn plain(&self) -> bool {
        self.stuck.is_empty() && self.slave.ncols() == 0
    }

    /// [N_aᵀ x; N_aᵀ v] of the full state [x; v]: the massive free coordinates.
    fn free_state(&self, y: &DVector<f64>) -> DVector<f64> {
        if self.plain() {
            return y.clone();
        }
        let (n, nf) = (self.n, self.free.ncols());
        if let Some(rows) = &self.tuning.free_rows {
            // N_a's columns are unit vectors e_d: N_aᵀ y is a gather (the product's exact value).
            return DVector::from_iterator(2 * nf, rows.iter().map(|&d| y[d]).chain(rows.iter().map(|&d| y[n + d])));
        }
        let mut out = DVector::zeros(2 * nf);
        out.rows_mut(0, nf).copy_from(&self.free.tr_mul(&y.rows(0, n)));
        out.rows_mut(nf, nf).copy_from(&self.free.tr_mul(&y.rows(n, n)));
        out
    }

    /// x + N u for the basis N (`basis`, its unit columns' DOFs `rows` when known): a scatter-add
    /// where N's columns are unit vectors (the product's exact value), else the product.
    fn add_in_basis(x: &mut DVector<f64>, basis: &DMatrix<f64>, rows: Option<&[usize]>, u: &nalgebra::DVectorView<f64>) {
        match rows {
            Some(rows) => rows.iter().zip(u.iter()).for_each(|(&d, v)| x[d] += v),
            None => x.gemv(1.0, basis, u, 1.0),
        }
    }

    /// The full state [x; v] at `t1`, from the full state `y0` at `t0` (stuck DOFs of `y0` are
    /// ignored: they follow the obstacle; so are massless DOFs: condensed); `e` is `self.exp(t1 − t0)`.
    pub fn flow_with(&self, e: &DMatrix<f64>, t0: f64, y0: &DVector<f64>, t1: f64) -> DVector<f64> {
        let nf2 = 2 * self.free.ncols();
        let p0 = eval(&self.part, self.omega, t0, 0, nf2);
        let p1 = eval(&self.part, self.omega, t1, 0, nf2);
        let yf = p1 + e * (self.free_state(y0) - p0);
        self.assemble(&yf, t1)
    }

    /// The states at t0 + j·h, j < `count` (the first `y0` itself), flowed in this phase: e^{Ah}
    /// once, then the free state's homogeneous part z = y_f − p(t) stepped by z ← e^{Ah} z, one
    /// product per sample (a flow per sample, [`Self::flow_with`], also projected and re-formed
    /// the state and evaluated the particular solution twice: most of the exact walk's time).
    pub fn samples(&self, t0: f64, y0: &DVector<f64>, h: f64, count: usize) -> Vec<DVector<f64>> {
        let nf2 = 2 * self.free.ncols();
        let mut out = Vec::with_capacity(count);
        out.push(y0.clone());
        if count < 2 {
            return out;
        }
        let step = self.exp(h);
        let mut z = self.free_state(y0) - eval(&self.part, self.omega, t0, 0, nf2);
        let mut next = DVector::zeros(nf2);
        for j in 1..count {
            let t = t0 + h * j as f64;
            next.gemv(1.0, &step, &z, 0.0);
            std::mem::swap(&mut z, &mut next);
            out.push(self.assemble(&(eval(&self.part, self.omega, t, 0, nf2) + &z), t));
        }
        out
    }

    /// A short span (‖Â τ‖₁ ≤ [`SHORT_SPAN`]) is flowed by the Taylor series on the vector, whose
    /// terms cost O(n²) where the Padé exponential costs O(n³) (the sampled orbit's states and
    /// golden sections: thousands of short flows on the coarse blade); a longer one by `exp`.
    /// With Â's eigendecomposition, any span costs O(n_a²) ([`EigenFlow::apply`]).
    pub fn flow(&self, t0: f64, y0: &DVector<f64>, t1: f64) -> DVector<f64> {
        let tau = t1 - t0;
        if self.eigen().is_none() && self.a_norm * tau.abs() > SHORT_SPAN {
            return self.flow_with(&self.exp(tau), t0, y0, t1);
        }
        let nf2 = 2 * self.free.ncols();
        let p0 = eval(&self.part, self.omega, t0, 0, nf2);
        let p1 = eval(&self.part, self.omega, t1, 0, nf2);
        let yf = p1 + self.exp_times(tau, self.free_state(y0) - p0);
        self.assemble(&yf, t1)
    }

    /// e^{Aτ} u for a short span: D e^{Âτ} D⁻¹ u (see [`Self::exp`]) with e^{Âτ} by its Taylor
    /// series in substeps of ‖Âh‖₁ ≤ 1 (Al-Mohy & Higham, SIAM J. Sci. Comput. 33, 2011: the
    /// truncated Taylor action, truncated here when a term falls below round-off).
    fn exp_times(&self, tau: f64, mut u: DVector<f64>) -> DVector<f64> {
        let nf = self.free.ncols();
        if nf == 0 {
            return u;
        }
        u.rows_mut(nf, nf).scale_mut(1.0 / self.speed);
        if let Some(f) = self.eigen() {
            let mut out = f.apply(tau, &u);
            out.rows_mut(nf, nf).scale_mut(self.speed);
            return out;
        }
        let substeps = (self.a_norm * tau.abs()).ceil().max(1.0);
        let h = tau / substeps;
        for _ in 0..substeps as usize {
            let mut term = u.clone();
            for k in 1..=40 {
                term = &*self.a * term * (h / k as f64);
                u += &term;
                if term.amax() <= 1e-18 * u.amax() {
                    break;
                }
            }
        }
        u.rows_mut(nf, nf).scale_mut(self.speed);
        u
    }

    /// [x_c + N_a x_a + N_b x_b; v_c + N_a v_a + N_b v_b], the massless coordinates condensed:
    /// x_b = X_b(t) + S (x_a − X_a(t)) (the particular solution and S = −K_bb⁻¹ K_ba).
    fn assemble(&self, yf: &DVector<f64>, t: f64) -> DVector<f64> {
        if self.plain() {
            return yf.clone();
        }
        let (n, nf) = (self.n, self.free.ncols());
        let mut y = DVector::zeros(2 * n);
        let (free_rows, slave_rows) = (self.tuning.free_rows.as_deref(), self.tuning.slave_rows.as_deref());
        let mut x = eval(&self.presc, self.omega, t, 0, n);
        let mut v = eval(&self.presc, self.omega, t, 1, n);
        Self::add_in_basis(&mut x, &self.free, free_rows, &yf.rows(0, nf));
        Self::add_in_basis(&mut v, &self.free, free_rows, &yf.rows(nf, nf));
        if self.slave.ncols() > 0 {
            let (nb, pa) = (self.slave.ncols(), eval(&self.part, self.omega, t, 0, 2 * nf));
            let xb = eval(&self.slave_part, self.omega, t, 0, nb) + &*self.slave_map * (yf.rows(0, nf) - pa.rows(0, nf));
            let vb = eval(&self.slave_part, self.omega, t, 1, nb) + &*self.slave_map * (yf.rows(nf, nf) - pa.rows(nf, nf));
            Self::add_in_basis(&mut x, &self.slave, slave_rows, &xb.rows(0, nb));
            Self::add_in_basis(&mut v, &self.slave, slave_rows, &vb.rows(0, nb));
        }
        y.rows_mut(0, n).copy_from(&x);
        y.rows_mut(n, n).copy_from(&v);
        y
    }

    /// `y` with its stuck DOFs on the obstacle and its massless DOFs condensed from its massive
    /// ones at `t`, as the flow takes it (a Newton iterate's entries there are free unknowns,
    /// and a state just before a massless contact closes has that DOF off the obstacle).
    fn condensed(&self, y: &DVector<f64>, t: f64) -> DVector<f64> {
        if self.slave.ncols() == 0 && self.stuck.is_empty() { y.clone() } else { self.assemble(&self.free_state(y), t) }
    }

    /// The derivative of the full state at the phase's end by the full state at its start,
    /// 2n × 2n, from `e` = `self.exp(τ)`: L e R with R = diag(N_aᵀ, N_aᵀ) and
    /// L = diag(N_a + N_b S, N_a + N_b S) (stuck DOFs follow the obstacle, massless ones their
    /// condensation: neither carries state). `e` itself when every DOF is free and massive.
    pub fn transition(&self, e: &DMatrix<f64>) -> DMatrix<f64> {
        let (n, nf) = (self.n, self.free.ncols());
        if self.plain() {
            return e.clone();
        }
        let lift = self.lifted();
        let mut out = DMatrix::zeros(2 * n, 2 * n);
        for (r, c) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let block = lift * e.view((r * nf, c * nf), (nf, nf)) * self.free.transpose();
            out.view_mut((r * n, c * n), (n, n)).copy_from(&block);
        }
        out
    }

    /// [`Self::transition`] applied to the columns of `dy` without forming it: L (e (R dy)), in
    /// O(n n_a) per column where the 2n × 2n transition costs O(n²) per column and O(n² n_a) to form.
    pub fn transition_times(&self, e: &DMatrix<f64>, dy: &DMatrix<f64>) -> DMatrix<f64> {
        let (n, nf) = (self.n, self.free.ncols());
        if self.stuck.is_empty() && self.slave.ncols() == 0 {
            return e * dy;
        }
        // N_a's columns unit vectors: R dy a gather, and L = N_a without massless DOFs a scatter
        // (the products' exact values: the variation's products by N_a were a sixth of the rigid walk).
        let rows = self.tuning.free_rows.as_deref();
        let reduced = match rows {
            Some(rows) => dy.select_rows(rows.iter().copied().chain(rows.iter().map(|d| n + d)).collect::<Vec<_>>().iter()),
            None => {
                let mut reduced = DMatrix::zeros(2 * nf, dy.ncols());
                reduced.rows_mut(0, nf).copy_from(&self.free.tr_mul(&dy.rows(0, n)));
                reduced.rows_mut(nf, nf).copy_from(&self.free.tr_mul(&dy.rows(n, n)));
                reduced
            }
        };
        let moved = e * reduced;
        let mut out = DMatrix::zeros(2 * n, dy.ncols());
        if let Some(rows) = rows.filter(|_| self.slave.ncols() == 0) {
            for (k, &d) in rows.iter().enumerate() {
                out.row_mut(d).copy_from(&moved.row(k));
                out.row_mut(n + d).copy_from(&moved.row(nf + k));
            }
            return out;
        }
        let lift = self.lifted();
        out.rows_mut(0, n).copy_from(&(lift * moved.rows(0, nf)));
        out.rows_mut(n, n).copy_from(&(lift * moved.rows(nf, nf)));
        out
    }

    /// Acceleration of every DOF in state `y` at `t` (its massless DOFs condensed first).
    pub fn acceleration(&self, y: &DVector<f64>, t: f64) -> DVector<f64> {
        self.acceleration_condensed(&self.condensed(y, t), t)
    }

    /// [`Self::acceleration`] of a state already condensed ([`Self::condensed`]).
    fn acceleration_condensed(&self, y: &DVector<f64>, t: f64) -> DVector<f64> {
        let n = self.n;
        let (x, v) = (y.rows(0, n).into_owned(), y.rows(n, n).into_owned());
        let acc = eval(&self.presc, self.omega, t, 2, n);
        let rhs = eval(&self.force, self.omega, t, 0, n) - &*self.c * &v - &*self.k * &x - &*self.m * &acc;
        // N_aᵀ rhs a gather, + N_a a_f a scatter-add (their exact values) where N_a's columns are unit vectors.
        let rows = self.tuning.free_rows.as_deref();
        let projected = rows.map_or_else(|| self.free.transpose() * &rhs, |r| DVector::from_iterator(r.len(), r.iter().map(|&d| rhs[d])));
        let af = &*self.mff_inv * projected;
        let mut out = acc;
        match rows {
            Some(rows) => rows.iter().zip(af.iter()).for_each(|(&d, a)| out[d] += a),
            None => out += &*self.free * &af,
        }
        if self.slave.ncols() > 0 {
            // ẍ_b = Ẍ_b(t) + S (ẍ_a − Ẍ_a(t)).
            let nf = self.free.ncols();
            let pa = eval(&self.part, self.omega, t, 1, 2 * nf);
            out += &*self.slave * (eval(&self.slave_part, self.omega, t, 2, self.slave.ncols()) + &*self.slave_map * (af - pa.rows(nf, nf)));
        }
        out
    }

    /// Compressive force of each stuck contact (contact index, force) in state `y` at `t`:
    /// z = B_S (f − M a − C v − K x) (the residual is B_Sᵀ z, and B_S B_Sᵀ = I).
    pub fn stuck_forces(&self, y: &DVector<f64>, t: f64) -> Vec<(usize, f64)> {
        let n = self.n;
        let y = self.condensed(y, t);
        let acc = self.acceleration_condensed(&y, t);
        let (x, v) = (y.rows(0, n).into_owned(), y.rows(n, n).into_owned());
        let r = eval(&self.force, self.omega, t, 0, n) - &*self.m * acc - &*self.c * v - &*self.k * x;
        let z = &*self.b_stuck * r;
        self.stuck.iter().enumerate().map(|(a, &i)| (i, z[a])).collect()
    }
}

impl Phase {
    /// The stuck contacts' forces' gradient in the full state y = [x; v] (|stuck| × 2n, rows in
    /// [`Self::stuck_contacts`]' order): [`Self::stuck_forces`] is affine in y, z(y, t) = z(0, t) + G y.
    /// With L = N_a + N_b S (the condensed lift) and the massive coordinates x_a = N_aᵀ x,
    /// v_a = N_aᵀ v: a = L a_a, a_a = −M_aa⁻¹ N_aᵀ (K L x_a + C L v_a), so
    /// G = −B_S [(K L − M L M_aa⁻¹ N_aᵀ K L) N_aᵀ, (C L − M L M_aa⁻¹ N_aᵀ C L) N_aᵀ]
    /// (the terms of [`Self::stuck_forces`], linear part). Made once per phase: a release's
    /// variation took one force evaluation per column (2n + ne + 1 of them) per Newton iteration.
    pub fn stuck_force_gradient(&self) -> &DMatrix<f64> {
        self.force_gradient.get_or_init(|| {
            let n = self.n;
            let lift = self.lifted();
            let ml = &*self.m * lift;
            let block = |a: &DMatrix<f64>| {
                let al = a * lift;
                let acc = &*self.mff_inv * (self.free.transpose() * &al);
                -(&*self.b_stuck * (al - &ml * acc)) * self.free.transpose()
            };
            let mut g = DMatrix::zeros(self.stuck.len(), 2 * n);
            g.columns_mut(0, n).copy_from(&block(&self.k));
            g.columns_mut(n, n).copy_from(&block(&self.c));
            g
        })
    }
}

/// An orthonormal basis N of the null space of the stuck rows, whose rows are unit normals on
/// disjoint DOFs: e_d for every DOF no stuck row touches (ascending, so the free DOFs themselves
/// when every stuck row is one DOF), then per stuck row over r > 1 DOFs the last r − 1 columns of
/// the Householder reflection H = I − 2wwᵀ/wᵀw, w = n − σe_1, σ = −sign(n_1): H e_1 = σn, so its
/// other columns are orthonormal and orthogonal to n (Golub & Van Loan §5.1.2).
fn null_basis(model: &Model, stuck: &[usize]) -> DMatrix<f64> {
    let n = model.n();
    let touched = |d: usize| stuck.iter().any(|&i| model.contacts[i].row.iter().any(|e| e.0 == d));
    let mut cols: Vec<DVector<f64>> = (0..n).filter(|&d| !touched(d)).map(|d| DVector::from_fn(n, |r, _| if r == d { 1.0 } else { 0.0 })).collect();
    for &i in stuck {
        let row = &model.contacts[i].row;
        if row.len() < 2 {
            continue;
        }
        let sigma = if row[0].1 >= 0.0 { -1.0 } else { 1.0 };
        let w: Vec<f64> = row.iter().enumerate().map(|(a, e)| if a == 0 { e.1 - sigma } else { e.1 }).collect();
        let ww: f64 = w.iter().map(|v| v * v).sum();
        for b in 1..row.len() {
            let mut col = DVector::zeros(n);
            for (a, e) in row.iter().enumerate() {
                col[e.0] = if a == b { 1.0 } else { 0.0 } - 2.0 * w[a] * w[b] / ww;
            }
            cols.push(col);
        }
    }
    if cols.is_empty() { DMatrix::zeros(n, 0) } else { DMatrix::from_columns(&cols) }
}

/// The model's matrix as dense.
pub(super) fn dense(a: &crate::model::Matrix, n: usize) -> DMatrix<f64> {
    DMatrix::from_fn(n, n, |i, j| a.get(i, j))
}
