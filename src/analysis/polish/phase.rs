//! One linear phase between events, solved exactly: the contacts stuck on their obstacle and the
//! compliant contacts closed are fixed, so M x'' + C x' + K x = f(t) is linear with harmonic
//! forcing. The stuck DOFs follow their obstacle, x_c = s·gap(t); the free DOFs obey
//! M_ff x_f'' + C_ff x_f' + K_ff x_f = f_f − M_fc x_c'' − C_fc x_c' − K_fc x_c, whose flow is the
//! periodic particular solution plus e^{Aτ} applied to the rest (the matrix exponential of the
//! first-order form, as in src/formulation.md §6.2 for one DOF).
use crate::model::{Compliance, Model};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;

/// Complex amplitudes of a harmonic signal: value(t) = Re Σ_p amp_p e^{i p ω t}.
pub(super) type Harmonics = Vec<(u32, DVector<C>)>;

/// One phase's exact flow.
#[derive(Clone, Debug)]
pub(super) struct Phase {
    pub n: usize,
    omega: f64,
    /// Free DOFs and the stuck contacts (DOF, direction, contact index).
    free: Vec<usize>,
    stuck: Vec<(usize, f64, usize)>,
    /// Closed compliant contacts.
    closed: Vec<usize>,
    /// The full-model matrices of this phase (K with the closed compliant springs).
    m: DMatrix<f64>,
    c: DMatrix<f64>,
    k: DMatrix<f64>,
    /// f(t) with the closed springs' obstacle terms, full model.
    force: Harmonics,
    /// Prescribed displacement of every DOF (nonzero only at stuck DOFs).
    presc: Harmonics,
    /// First-order form of the free DOFs, balanced: ŷ = [x_f; v_f/speed] (see [`Phase::exp`]).
    a: DMatrix<f64>,
    /// The balancing rate [rad/s]: √‖M_ff⁻¹K_ff‖∞ ≥ ω_max of the phase.
    speed: f64,
    mff_inv: DMatrix<f64>,
    /// Particular periodic solution of the free state [x_f; v_f].
    part: Harmonics,
}

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
        let mut force = force_harmonics(model);
        for &i in closed {
            let ct = &model.contacts[i];
            let Compliance::Compliant { stiffness } = ct.compliance else { continue };
            k[(ct.dof, ct.dof)] += stiffness;
            for (p, g) in gap_harmonics(model, i) {
                add(&mut force, p, ct.dof, g[0] * stiffness * ct.direction, n);
            }
        }
        let stuck: Vec<(usize, f64, usize)> = stuck.iter().map(|&i| (model.contacts[i].dof, model.contacts[i].direction, i)).collect();
        let mut presc: Harmonics = Vec::new();
        for &(d, dir, i) in &stuck {
            for (p, g) in gap_harmonics(model, i) {
                add(&mut presc, p, d, g[0] * dir, n);
            }
        }
        let free: Vec<usize> = (0..n).filter(|d| !stuck.iter().any(|s| s.0 == *d)).collect();
        let nf = free.len();
        let sub = |a: &DMatrix<f64>, r: &[usize], cl: &[usize]| DMatrix::from_fn(r.len(), cl.len(), |i, j| a[(r[i], cl[j])]);
        let mff_inv = if nf == 0 { DMatrix::zeros(0, 0) } else { sub(&m, &free, &free).try_inverse()? };
        let mut a = DMatrix::zeros(2 * nf, 2 * nf);
        let mut speed = 1.0;
        if nf > 0 {
            let mk = -&mff_inv * sub(&k, &free, &free);
            let norm = mk.row_iter().map(|r| r.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
            speed = if norm > 0.0 && norm.is_finite() { norm.sqrt() } else { 1.0 };
            a.view_mut((0, nf), (nf, nf)).fill_with_identity();
            a.view_mut((nf, 0), (nf, nf)).copy_from(&mk);
            a.view_mut((nf, nf), (nf, nf)).copy_from(&(-&mff_inv * sub(&c, &free, &free)));
        }
        // Free forcing per harmonic: f_f − (−(pω)² M_f· + ipω C_f· + K_f·) x_presc.
        let mut ps: Vec<u32> = force.iter().chain(&presc).map(|(p, _)| *p).collect();
        ps.sort_unstable();
        ps.dedup();
        let mut part = Vec::new();
        let ac = a.map(|v| C::new(v, 0.0));
        for p in ps {
            let w = p as f64 * omega;
            let fp = force.iter().find(|(q, _)| *q == p).map_or_else(|| DVector::zeros(n), |(_, v)| v.clone());
            let xp = presc.iter().find(|(q, _)| *q == p).map_or_else(|| DVector::zeros(n), |(_, v)| v.clone());
            let dyn_op = m.map(|v| C::new(-w * w * v, 0.0)) + c.map(|v| C::new(0.0, w * v)) + k.map(|v| C::new(v, 0.0));
            let rhs = fp - dyn_op * xp;
            let g = DVector::from_fn(nf, |i, _| rhs[free[i]]);
            let acc = mff_inv.map(|v| C::new(v, 0.0)) * g;
            let mut b = DVector::zeros(2 * nf);
            if nf > 0 {
                b.rows_mut(nf, nf).copy_from(&acc);
            }
            let op = DMatrix::from_diagonal_element(2 * nf, 2 * nf, C::new(0.0, w)) - &ac;
            let y = if nf == 0 { b } else { op.lu().solve(&b)? };
            if !y.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
                return None;
            }
            part.push((p, y));
        }
        // The particular solution above uses the unbalanced A; the exponential the balanced one.
        if nf > 0 {
            a.view_mut((0, nf), (nf, nf)).scale_mut(speed);
            a.view_mut((nf, 0), (nf, nf)).scale_mut(1.0 / speed);
        }
        Some(Phase { n, omega, free, stuck, closed: closed.to_vec(), m, c, k, force, presc, a, speed, mff_inv, part })
    }

    /// Whether compliant contact `i` is closed in this phase.
    pub fn closed(&self, i: usize) -> bool {
        self.closed.contains(&i)
    }

    /// The phase's fastest rate [rad/s] (the balancing speed, ≥ its ω_max): for sampling.
    pub fn speed_hint(&self) -> f64 {
        self.speed
    }

    /// No contact is stuck: the exponential acts on the whole state [x; v].
    pub fn all_free(&self) -> bool {
        self.stuck.is_empty()
    }

    pub fn stuck_contacts(&self) -> impl Iterator<Item = usize> + '_ {
        self.stuck.iter().map(|s| s.2)
    }

    /// e^{A τ} of the free state [x_f; v_f], computed as D e^{Â τ} D⁻¹ with D = diag(I, speed·I):
    /// in [x; v] a stiff phase's A has entries up to ω_max² beside 1, and scaling and squaring
    /// (nalgebra's Padé `exp`) then loses about ω_max/ω_ref digits; balanced, ‖Â‖ ≈ ω_max
    /// (Higham, "Functions of Matrices", §10.3; the coarse blade's stall at ω_max = 6.3e5 rad/s).
    pub fn exp(&self, tau: f64) -> DMatrix<f64> {
        let nf = self.free.len();
        let mut e = (&self.a * tau).exp();
        if nf > 0 {
            e.view_mut((0, nf), (nf, nf)).scale_mut(1.0 / self.speed);
            e.view_mut((nf, 0), (nf, nf)).scale_mut(self.speed);
        }
        e
    }

    fn free_state(&self, y: &DVector<f64>) -> DVector<f64> {
        let nf = self.free.len();
        DVector::from_fn(2 * nf, |i, _| if i < nf { y[self.free[i]] } else { y[self.n + self.free[i - nf]] })
    }

    /// The full state [x; v] at `t1`, from the full state `y0` at `t0` (stuck DOFs of `y0` are
    /// ignored: they follow the obstacle); `e` is `self.exp(t1 − t0)`.
    pub fn flow_with(&self, e: &DMatrix<f64>, t0: f64, y0: &DVector<f64>, t1: f64) -> DVector<f64> {
        let nf2 = 2 * self.free.len();
        let p0 = eval(&self.part, self.omega, t0, 0, nf2);
        let p1 = eval(&self.part, self.omega, t1, 0, nf2);
        let yf = p1 + e * (self.free_state(y0) - p0);
        self.assemble(&yf, t1)
    }

    pub fn flow(&self, t0: f64, y0: &DVector<f64>, t1: f64) -> DVector<f64> {
        self.flow_with(&self.exp(t1 - t0), t0, y0, t1)
    }

    fn assemble(&self, yf: &DVector<f64>, t: f64) -> DVector<f64> {
        let (n, nf) = (self.n, self.free.len());
        let mut y = DVector::zeros(2 * n);
        let x = eval(&self.presc, self.omega, t, 0, n);
        let v = eval(&self.presc, self.omega, t, 1, n);
        for &(d, _, _) in &self.stuck {
            y[d] = x[d];
            y[n + d] = v[d];
        }
        for (i, &d) in self.free.iter().enumerate() {
            y[d] = yf[i];
            y[n + d] = yf[nf + i];
        }
        y
    }

    /// Acceleration of every DOF in state `y` at `t`.
    pub fn acceleration(&self, y: &DVector<f64>, t: f64) -> DVector<f64> {
        let n = self.n;
        let (x, v) = (y.rows(0, n).into_owned(), y.rows(n, n).into_owned());
        let mut acc = eval(&self.presc, self.omega, t, 2, n);
        let rhs = eval(&self.force, self.omega, t, 0, n) - &self.c * &v - &self.k * &x - &self.m * &acc;
        let g = DVector::from_fn(self.free.len(), |i, _| rhs[self.free[i]]);
        let af = &self.mff_inv * g;
        for (i, &d) in self.free.iter().enumerate() {
            acc[d] = af[i];
        }
        acc
    }

    /// Compressive force of each stuck contact (contact index, force) in state `y` at `t`:
    /// z = s·(f − M a − C v − K x) at its DOF.
    pub fn stuck_forces(&self, y: &DVector<f64>, t: f64) -> Vec<(usize, f64)> {
        let n = self.n;
        let acc = self.acceleration(y, t);
        let (x, v) = (y.rows(0, n).into_owned(), y.rows(n, n).into_owned());
        let r = eval(&self.force, self.omega, t, 0, n) - &self.m * acc - &self.c * v - &self.k * x;
        self.stuck.iter().map(|&(d, s, i)| (i, s * r[d])).collect()
    }
}

/// The model's matrix as dense.
pub(super) fn dense(a: &crate::model::Matrix, n: usize) -> DMatrix<f64> {
    DMatrix::from_fn(n, n, |i, j| a.get(i, j))
}
