//! Exact references for Coulomb friction (src/formulation.md §9), independent of the crate's
//! periodic assembly, LCP and time schemes.
//!
//! - [`den_hartog_amplitude`]: J. P. Den Hartog, "Forced vibrations with combined Coulomb and
//!   viscous friction", Trans. ASME APM-53-9 (1931) 107–115: the closed form of
//!   m x'' + k x = P cos Ωt − F sgn ẋ in continuous motion (no stops, c = 0), derived below.
//! - [`FrictionOrbit`]: an event-driven exact simulation of any small linear structure with one
//!   Coulomb contact (rigid, or a Jenkins element): piecewise-linear flows in closed form (the
//!   matrix exponential of the phase's linear system, the cosine forcing carried as an
//!   oscillator in the state), stick while the required force stays below μN, slip with the
//!   sign of the velocity, switching times by bisection on the closed-form flow, marched to the
//!   periodic steady state.
//!
//! Sign convention (as `model::Friction`): the friction force f acts on the structure as −e_d f,
//! f = μN·sign(ẋ_d) in slip, so f·ẋ_d ≥ 0.
use super::ExactError;
use crate::model::{Force, Friction, Harmonic, Matrix, Model, Structure};
use std::f64::consts::PI;

/// Den Hartog's steady amplitude X of m x'' + k x = P cos Ωt − F sgn ẋ in continuous motion:
///
/// X = √( R² − (F/k)² (ω_n/Ω)² tan²(π ω_n / 2Ω) ),   R = P / (k − m Ω²),  ω_n = √(k/m).
///
/// Derivation: on the half period t ∈ [0, π/Ω] with ẋ ≥ 0 from x = −X to x = X,
/// x = A cos ω_n t + B sin ω_n t + R cos(Ωt + φ) − F/k; the four end conditions give A = F/k,
/// R sin φ = (F/k)(ω_n/Ω) tan(π ω_n/2Ω) and X = −R cos φ. Checked: the motion must be
/// continuous (ẋ ≥ 0 on the half period, no stop at the reversals); otherwise an error.
pub fn den_hartog_amplitude(mass: f64, stiffness: f64, force: f64, slip_force: f64, omega: f64) -> Result<f64, ExactError> {
    let wn = (stiffness / mass).sqrt();
    let r = force / (stiffness - mass * omega * omega);
    let t1 = PI / omega;
    let s = slip_force / stiffness * wn / omega * (wn * t1 / 2.0).tan();
    if !(r * r > s * s) || !r.is_finite() {
        return Err(ExactError::NoSolution(format!("no continuous motion: the friction force {slip_force} is too large for the load {force} at Ω = {omega}")));
    }
    let c = -(r * r - s * s).sqrt();
    let x = -c;
    // Continuity: ẋ ≥ 0 on (0, π/Ω), and the reversal at t = 0 does not stick.
    let (a, b) = (slip_force / stiffness, s * omega / wn);
    let v = |t: f64| -a * wn * (wn * t).sin() + b * wn * (wn * t).cos() - c * omega * (omega * t).sin() - s * omega * (omega * t).cos();
    if (1..1000).any(|i| v(i as f64 * t1 / 1000.0) < 0.0) {
        return Err(ExactError::NoSolution(
            "the motion has stops (ẋ changes sign within a half period): Den Hartog's continuous solution does not apply".into(),
        ));
    }
    // At t = 0 (x = −X, at rest) the load and the spring must overcome friction: |P cos φ + k X| > F.
    if ((stiffness - mass * omega * omega) * c + stiffness * x).abs() <= slip_force {
        return Err(ExactError::NoSolution("the mass sticks at the reversals: the motion is not continuous".into()));
    }
    Ok(x)
}

/// A small linear structure M x'' + C x' + K x = F cos Ωt − e_d f with one friction contact on
/// DOF d (slip force μN; a Jenkins element of stiffness k_t if given).
#[derive(Clone, Debug)]
pub struct FrictionOscillator {
    pub mass: Vec<Vec<f64>>,
    pub damping: Vec<Vec<f64>>,
    pub stiffness: Vec<Vec<f64>>,
    /// Amplitudes of F cos Ωt per DOF.
    pub force: Vec<f64>,
    pub omega: f64,
    pub dof: usize,
    pub slip_force: f64,
    pub tangential_stiffness: Option<f64>,
}

impl FrictionOscillator {
    /// The same system as a [`Model`] with one friction contact (μ = 1, N = μN).
    pub fn model(&self) -> Model {
        let m = |a: &Vec<Vec<f64>>| Matrix::from_rows(a);
        let damped = self.damping.iter().flatten().any(|&v| v != 0.0);
        Model {
            structure: Structure { mass: m(&self.mass), stiffness: m(&self.stiffness), damping: damped.then(|| m(&self.damping)) },
            forces: self
                .force
                .iter()
                .enumerate()
                .filter(|(_, a)| **a != 0.0)
                .map(|(dof, &amplitude)| Force { dof, term: Harmonic { amplitude, harmonic: 1, phase: 0.0 } })
                .collect(),
            contacts: Vec::new(),
            frequency: self.omega,
            frictions: vec![Friction::on_dof(self.dof, 1.0, self.slip_force, self.tangential_stiffness)],
            rubbing: Vec::new(),
        }
    }
    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }
}

/// The three phases of the contact.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Stick,
    Slip(f64),
}

/// One closed-form piece of the orbit: from `start`, state `y` (augmented), in `phase`.
#[derive(Clone, Debug)]
struct Segment {
    start: f64,
    phase: usize,
    y: Vec<f64>,
}

/// The periodic steady state found by event-driven simulation.
#[derive(Clone, Debug)]
pub struct FrictionOrbit {
    sys: Flows,
    segments: Vec<Segment>,
    period: f64,
    /// Fraction of the period spent stuck.
    pub stuck_fraction: f64,
    /// ∮ f v dt over one period (≥ 0).
    pub dissipated_energy: f64,
    /// Periods simulated before the orbit repeated.
    pub periods: usize,
}

/// The augmented systems ỹ' = Ã ỹ of the phases, ỹ = [x; v; s0; cos Ωt; sin Ωt; 1] (s0: a
/// Jenkins slider's position while stuck), and the event forms.
#[derive(Clone, Debug)]
struct Flows {
    n: usize,
    dim: usize,
    /// Ã of Stick, Slip(+1), Slip(−1).
    a: [Vec<f64>; 3],
    /// The force f of a stuck contact as a linear form of ỹ.
    stick_force: Vec<f64>,
    /// Fixed marching step and its propagators e^{Ã Δ}.
    step: f64,
    e_step: [Vec<f64>; 3],
    slip_force: f64,
    kt: Option<f64>,
    dof: usize,
}

fn phase_index(p: Phase) -> usize {
    match p {
        Phase::Stick => 0,
        Phase::Slip(s) if s > 0.0 => 1,
        Phase::Slip(_) => 2,
    }
}

impl Flows {
    fn new(sys: &FrictionOscillator, substeps: usize) -> Result<Self, ExactError> {
        let n = sys.mass.len();
        let dim = 2 * n + 4;
        let (is0, ic, is, i1) = (2 * n, 2 * n + 1, 2 * n + 2, 2 * n + 3);
        let d = sys.dof;
        let minv = invert(&sys.mass).ok_or_else(|| ExactError::param("mass", "is singular"))?;
        let kt = sys.tangential_stiffness;
        let mut k_stick = sys.stiffness.clone();
        if let Some(kt) = kt {
            k_stick[d][d] += kt;
        }
        // Rigid stick: ẍ = P(F − Kx − Cv), P = M⁻¹ − M⁻¹e (eᵀM⁻¹e)⁻¹ eᵀM⁻¹, reaction
        // f = eᵀM⁻¹(F − Kx − Cv)/(eᵀM⁻¹e).
        let med = minv[d][d];
        let p: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| minv[i][j] - minv[i][d] * minv[d][j] / med).collect()).collect();
        let build = |phase: Phase| -> Vec<f64> {
            let mut a = vec![0.0; dim * dim];
            let rigid_stick = phase == Phase::Stick && kt.is_none();
            let acc = if rigid_stick { &p } else { &minv };
            let kk = if phase == Phase::Stick { &k_stick } else { &sys.stiffness };
            for i in 0..n {
                a[i * dim + n + i] = 1.0;
                for j in 0..n {
                    for l in 0..n {
                        a[(n + i) * dim + j] -= acc[i][l] * kk[l][j];
                        a[(n + i) * dim + n + j] -= acc[i][l] * sys.damping[l][j];
                    }
                    a[(n + i) * dim + ic] += acc[i][j] * sys.force[j];
                }
                match phase {
                    Phase::Slip(s) => a[(n + i) * dim + i1] -= minv[i][d] * s * sys.slip_force,
                    Phase::Stick => {
                        if let Some(kt) = kt {
                            a[(n + i) * dim + is0] += minv[i][d] * kt;
                        }
                    }
                }
            }
            a[ic * dim + is] = -sys.omega;
            a[is * dim + ic] = sys.omega;
            a
        };
        let mut stick_force = vec![0.0; dim];
        match kt {
            Some(kt) => {
                stick_force[d] = kt;
                stick_force[is0] = -kt;
            }
            None => {
                for l in 0..n {
                    let w = minv[d][l] / med;
                    for j in 0..n {
                        stick_force[j] -= w * sys.stiffness[l][j];
                        stick_force[n + j] -= w * sys.damping[l][j];
                    }
                    stick_force[ic] += w * sys.force[l];
                }
            }
        }
        let a = [build(Phase::Stick), build(Phase::Slip(1.0)), build(Phase::Slip(-1.0))];
        let step = sys.period() / substeps as f64;
        let e_step = [expm(&a[0], dim, step), expm(&a[1], dim, step), expm(&a[2], dim, step)];
        Ok(Flows { n, dim, a, stick_force, step, e_step, slip_force: sys.slip_force, kt, dof: d })
    }

    fn propagate(&self, phase: usize, y: &[f64], tau: f64) -> Vec<f64> {
        matvec(&expm(&self.a[phase], self.dim, tau), y)
    }

    /// Event function of a phase: > 0 while it lasts.
    fn event(&self, phase: Phase, y: &[f64]) -> f64 {
        match phase {
            Phase::Slip(s) => s * y[self.n + self.dof],
            Phase::Stick => self.slip_force - dot(&self.stick_force, y).abs(),
        }
    }

    /// The phase that follows the end of `phase` at state `y` (which it may adjust: a stuck
    /// velocity is exactly 0, a Jenkins slider is placed).
    fn next(&self, phase: Phase, y: &mut [f64]) -> Phase {
        let (n, d) = (self.n, self.dof);
        match (phase, self.kt) {
            (Phase::Stick, _) => Phase::Slip(dot(&self.stick_force, y).signum()),
            (Phase::Slip(s), Some(kt)) => {
                y[n + d] = 0.0;
                y[2 * n] = y[d] - s * self.slip_force / kt;
                Phase::Stick
            }
            (Phase::Slip(_), None) => {
                y[n + d] = 0.0;
                let f = dot(&self.stick_force, y);
                if f.abs() < self.slip_force { Phase::Stick } else { Phase::Slip(f.signum()) }
            }
        }
    }
}

impl FrictionOrbit {
    /// Marches from rest with `substeps` per period (events found by bisection to round-off)
    /// until the state at the period boundaries repeats to `tol` (relative), at most `max_periods`.
    pub fn solve(sys: &FrictionOscillator, substeps: usize, tol: f64, max_periods: usize) -> Result<Self, ExactError> {
        let n = sys.mass.len();
        if sys.dof >= n || sys.force.len() != n || !(sys.slip_force >= 0.0) || !(sys.omega > 0.0) {
            return Err(ExactError::param("friction", "dof, force length, slip force ≥ 0 or Ω > 0 out of range"));
        }
        let fl = Flows::new(sys, substeps)?;
        let period = sys.period();
        let mut y = vec![0.0; fl.dim];
        y[2 * n + 1] = 1.0;
        y[2 * n + 3] = 1.0;
        let mut phase = if fl.event(Phase::Stick, &y) > 0.0 { Phase::Stick } else { fl.next(Phase::Stick, &mut y) };
        let mut prev = y.clone();
        for p in 1..=max_periods {
            let mut segments = vec![Segment { start: 0.0, phase: phase_index(phase), y: y.clone() }];
            for i in 0..substeps {
                let mut t = i as f64 * fl.step;
                let end = (i + 1) as f64 * fl.step;
                loop {
                    let pi = phase_index(phase);
                    let full = end - t == fl.step;
                    let y1 = if full { matvec(&fl.e_step[pi], &y) } else { fl.propagate(pi, &y, end - t) };
                    if fl.event(phase, &y1) > 0.0 {
                        y = y1;
                        break;
                    }
                    // The phase ends in (t, end]: bisect on the closed-form flow.
                    let (mut lo, mut hi) = (0.0, end - t);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        if fl.event(phase, &fl.propagate(pi, &y, mid)) > 0.0 { lo = mid } else { hi = mid }
                    }
                    y = fl.propagate(pi, &y, hi);
                    t += hi;
                    phase = fl.next(phase, &mut y);
                    segments.push(Segment { start: t, phase: phase_index(phase), y: y.clone() });
                    if hi == 0.0 && segments.len() > 4 * substeps {
                        return Err(ExactError::NoSolution("the event-driven simulation chatters (events without time between them)".into()));
                    }
                }
            }
            // Back on the forcing's phase exactly: cos = 1, sin = 0 at t = pT.
            y[2 * n + 1] = 1.0;
            y[2 * n + 2] = 0.0;
            let scale = y.iter().take(2 * n + 1).fold(1e-300f64, |a, v| a.max(v.abs()));
            let change = y.iter().zip(&prev).take(2 * n + 1).fold(0.0f64, |a, (u, v)| a.max((u - v).abs()));
            prev.clone_from(&y);
            if change <= tol * scale {
                let mut orbit = FrictionOrbit { sys: fl, segments, period, stuck_fraction: 0.0, dissipated_energy: 0.0, periods: p };
                orbit.measure();
                return Ok(orbit);
            }
        }
        Err(ExactError::NoSolution(format!("the simulation did not reach a periodic orbit in {max_periods} periods (tolerance {tol})")))
    }

    /// Stuck fraction and dissipated energy from the segments: a slip phase of sign s moves
    /// the slider by Δx_d at the force sμN, so ∮ f v dt = μN Σ |Δx_d|.
    fn measure(&mut self) {
        let (mut stuck, mut energy) = (0.0, 0.0);
        for (i, s) in self.segments.iter().enumerate() {
            let end = self.segments.get(i + 1).map_or(self.period, |n| n.start);
            if s.phase == 0 {
                stuck += end - s.start;
            } else {
                let y1 = self.sys.propagate(s.phase, &s.y, end - s.start);
                energy += self.sys.slip_force * (y1[self.sys.dof] - s.y[self.sys.dof]).abs();
            }
        }
        self.stuck_fraction = stuck / self.period;
        self.dissipated_energy = energy;
    }

    fn state(&self, t: f64) -> (usize, Vec<f64>) {
        let t = t.rem_euclid(self.period);
        let i = self.segments.partition_point(|s| s.start <= t).max(1) - 1;
        let s = &self.segments[i];
        (s.phase, self.sys.propagate(s.phase, &s.y, t - s.start))
    }

    /// Displacements x(t) of every DOF.
    pub fn displacement(&self, t: f64) -> Vec<f64> {
        self.state(t).1[..self.sys.n].to_vec()
    }

    /// The friction force f(t) (μN·s in slip, the holding force while stuck).
    pub fn force(&self, t: f64) -> f64 {
        let (phase, y) = self.state(t);
        match phase {
            0 => dot(&self.sys.stick_force, &y),
            1 => self.sys.slip_force,
            _ => -self.sys.slip_force,
        }
    }

    /// Whether the contact is stuck at t.
    pub fn stuck(&self, t: f64) -> bool {
        self.state(t).0 == 0
    }

    /// Half the peak-to-peak displacement of `dof`, sampled at `samples` points per period.
    pub fn amplitude(&self, dof: usize, samples: usize) -> f64 {
        let (lo, hi) = (0..samples)
            .map(|j| self.displacement(j as f64 * self.period / samples as f64)[dof])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
        0.5 * (hi - lo)
    }

    /// The times at which the phase changes, in [0, T).
    pub fn events(&self) -> Vec<f64> {
        self.segments.iter().skip(1).map(|s| s.start).collect()
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn matvec(a: &[f64], y: &[f64]) -> Vec<f64> {
    let n = y.len();
    (0..n).map(|i| dot(&a[i * n..(i + 1) * n], y)).collect()
}

fn matmul(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut c = vec![0.0; n * n];
    for i in 0..n {
        for l in 0..n {
            let x = a[i * n + l];
            if x != 0.0 {
                for j in 0..n {
                    c[i * n + j] += x * b[l * n + j];
                }
            }
        }
    }
    c
}

/// e^{A τ} by scaling and squaring of a degree-20 Taylor sum (‖Aτ/2^s‖₁ ≤ 1/2: truncation
/// below 1e-25, far under round-off).
fn expm(a: &[f64], n: usize, tau: f64) -> Vec<f64> {
    let norm = (0..n).map(|j| (0..n).map(|i| (a[i * n + j] * tau).abs()).sum::<f64>()).fold(0.0, f64::max);
    let s = if norm > 0.5 { (norm / 0.5).log2().ceil() as i32 } else { 0 };
    let scale = tau / 2f64.powi(s);
    let x: Vec<f64> = a.iter().map(|v| v * scale).collect();
    let mut e = vec![0.0; n * n];
    let mut term = vec![0.0; n * n];
    for i in 0..n {
        e[i * n + i] = 1.0;
        term[i * n + i] = 1.0;
    }
    for k in 1..=20 {
        term = matmul(&term, &x, n);
        term.iter_mut().for_each(|v| *v /= k as f64);
        e.iter_mut().zip(&term).for_each(|(e, t)| *e += t);
    }
    for _ in 0..s {
        e = matmul(&e, &e, n);
    }
    e
}

/// The inverse of a small matrix by Gauss–Jordan with partial pivoting; `None` if singular.
fn invert(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let mut m: Vec<Vec<f64>> = a.iter().enumerate().map(|(i, r)| r.iter().copied().chain((0..n).map(|j| f64::from(u8::from(i == j)))).collect()).collect();
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        if m[p][c] == 0.0 {
            return None;
        }
        m.swap(c, p);
        let piv = m[c][c];
        m[c].iter_mut().for_each(|v| *v /= piv);
        for r in 0..n {
            if r != c {
                let f = m[r][c];
                let row = m[c].clone();
                m[r].iter_mut().zip(&row).for_each(|(v, w)| *v -= f * w);
            }
        }
    }
    Some(m.into_iter().map(|r| r[n..].to_vec()).collect())
}
