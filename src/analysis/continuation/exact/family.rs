//! The exact orbits of one event signature as the parameter varies: unknowns, residual,
//! Jacobian, corrector and tangent, and the solved point (its orbit, multipliers and touches).
//!
//! Unknowns w = (y0/y_s, θ, λ/ρ): the state just after event 0 over a state scale, the event
//! times as fractions of the period (τ_e = θ_e·T(λ)), the parameter over its range. Equations:
//! the polish's shooting residual (periodicity over y_s, and an event condition per event: the
//! clearance 0 at a compliant switch), as COCO's `hspo` (Dankowicz & Schilder, "Recipes for
//! Continuation", ch. 19) with a fixed segment signature.
use super::super::{Parameter, floquet};
use crate::analysis::polish::{Event, PolishedOrbit, Touch};
use crate::model::Model;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// The event signature: the events in time order (their seeds unused) and the contacts closed
/// all period long.
#[derive(Clone, Debug)]
pub(super) struct Signature {
    pub events: Vec<Event>,
    pub always: Vec<usize>,
}

/// Newton's last defect (‖F‖∞, F over the state scale) and its iterations.
const TOLERANCE: f64 = 1e-11;
const MAX_ITERATIONS: usize = 12;
/// Newton at its round-off floor: a step this small (scaled unknowns) and a defect below
/// [`ROUND_OFF_DEFECT`] is a solution. The stiff phases' exponentials carry ~1e-11 relative
/// round-off (the coarse blade's contact modes, ω_max/ω ≈ 270) into the velocity rows, where
/// Newton then hovers at ‖F‖ of 1e-11 to 2e-10 with steps of 1e-11 (the stall at 2214 rad/s).
const ROUND_OFF_STEP: f64 = 1e-10;
const ROUND_OFF_DEFECT: f64 = 1e-9;
/// Central-difference step of the Jacobian (unknowns are O(1)).
const DIFF: f64 = 1e-7;

pub(super) struct Family {
    base: Model,
    pub param: Parameter,
    pub rho: f64,
    pub ys: f64,
    pub sig: Signature,
    n2: usize,
    /// The corrector's last solution and its Jacobian, for the point's tangent.
    last_jacobian: std::cell::RefCell<Option<(Vec<f64>, DMatrix<f64>)>>,
}

/// A solved point with its unit tangent (oriented along the branch), orbit, multipliers and the
/// contacts' touches.
#[derive(Clone, Debug)]
pub(super) struct Node {
    pub w: Vec<f64>,
    pub tangent: Vec<f64>,
    pub orbit: PolishedOrbit,
    pub mu: Vec<Complex64>,
    pub touches: Vec<Touch>,
}

impl Node {
    pub fn lambda(&self, rho: f64) -> f64 {
        self.w[self.w.len() - 1] * rho
    }
    /// The smallest signed clearance between a contact's events (negative: not admissible).
    pub fn worst_touch(&self) -> Option<&Touch> {
        self.touches.iter().min_by(|a, b| a.value.total_cmp(&b.value))
    }
}

impl Family {
    pub fn new(base: &Model, param: Parameter, rho: f64, ys: f64, sig: Signature) -> Family {
        Family { base: base.clone(), param, rho, ys, sig, n2: 2 * base.n(), last_jacobian: Default::default() }
    }

    /// The scene's model at λ.
    pub fn model_at(&self, lambda: f64) -> Model {
        let mut m = self.base.clone();
        match self.param {
            Parameter::Frequency => m.frequency = lambda,
            Parameter::Speed { lobes } => m.frequency = f64::from(lobes) * lambda,
            Parameter::ForceScale => m.forces.iter_mut().for_each(|f| f.term.amplitude *= lambda),
            Parameter::GapOffset => m.contacts.iter_mut().for_each(|c| c.gap += lambda),
            Parameter::NormalForce => m.frictions.iter_mut().for_each(|f| f.normal_force = lambda),
        }
        m
    }

    pub fn ne(&self) -> usize {
        self.sig.events.len()
    }
    pub fn dim(&self) -> usize {
        self.n2 + self.ne() + 1
    }

    /// The unknowns of `orbit` at λ.
    pub fn pack(&self, orbit: &PolishedOrbit, lambda: f64) -> Vec<f64> {
        let t = orbit.period();
        let mut w: Vec<f64> = orbit.initial_state().iter().map(|y| y / self.ys).collect();
        if self.ne() > 0 {
            w.extend(orbit.times().iter().map(|s| s / t));
        }
        w.push(lambda / self.rho);
        w
    }

    fn orbit(&self, lambda: f64) -> Option<PolishedOrbit> {
        if !lambda.is_finite() {
            return None;
        }
        PolishedOrbit::unsolved(&self.model_at(lambda), self.sig.events.clone(), &self.sig.always).ok()
    }

    fn unpack(&self, w: &[f64], period: f64) -> (Vec<f64>, Vec<f64>) {
        let y: Vec<f64> = w[..self.n2].iter().map(|v| v * self.ys).collect();
        let times: Vec<f64> = if self.ne() == 0 { vec![0.0] } else { w[self.n2..self.n2 + self.ne()].iter().map(|s| s * period).collect() };
        (y, times)
    }

    fn residual_with(&self, orbit: &PolishedOrbit, w: &[f64]) -> Option<DVector<f64>> {
        let (y, times) = self.unpack(w, orbit.period());
        let r = orbit.shooting_residual(&y, &times)? / self.ys;
        r.iter().all(|v| v.is_finite()).then_some(r)
    }

    pub fn residual(&self, w: &[f64]) -> Option<DVector<f64>> {
        self.residual_with(&self.orbit(w[w.len() - 1] * self.rho)?, w)
    }

    /// [∂F/∂w]: the state and time columns from the variational flow of one period
    /// ([`PolishedOrbit::shooting_jacobian`]; ∂τ_e/∂θ_e = T), the λ column by central differences
    /// on orbits rebuilt at λ ± h·ρ. By central differences throughout where the variational flow
    /// does not apply.
    pub fn jacobian(&self, w: &[f64]) -> Option<DMatrix<f64>> {
        let d = self.dim();
        let lambda = w[d - 1] * self.rho;
        let here = self.orbit(lambda)?;
        let (y, times) = self.unpack(w, here.period());
        let mut j = DMatrix::zeros(d - 1, d);
        if let Some((_, dr)) = here.shooting_jacobian(&y, &times) {
            for c in 0..d - 1 {
                let scale = if c < self.n2 { 1.0 } else { here.period() / self.ys };
                j.set_column(c, &(dr.column(c) * scale));
            }
            let (mut up, mut dn) = (w.to_vec(), w.to_vec());
            up[d - 1] += DIFF;
            dn[d - 1] -= DIFF;
            let col = (self.residual(&up)? - self.residual(&dn)?) / (2.0 * DIFF);
            j.set_column(d - 1, &col);
            return Some(j);
        }
        for c in 0..d - 1 {
            let (mut up, mut dn) = (w.to_vec(), w.to_vec());
            up[c] += DIFF;
            dn[c] -= DIFF;
            let col = (self.residual_with(&here, &up)? - self.residual_with(&here, &dn)?) / (2.0 * DIFF);
            j.set_column(c, &col);
        }
        let (mut up, mut dn) = (w.to_vec(), w.to_vec());
        up[d - 1] += DIFF;
        dn[d - 1] -= DIFF;
        let col = (self.residual_with(&self.orbit(up[d - 1] * self.rho)?, &up)? - self.residual_with(&self.orbit(dn[d - 1] * self.rho)?, &dn)?) / (2.0 * DIFF);
        j.set_column(d - 1, &col);
        Some(j)
    }

    /// Newton on F(w) = 0, normal·w = target, from `pred`.
    pub fn correct(&self, pred: &[f64], normal: &[f64], target: f64) -> Option<Vec<f64>> {
        let d = self.dim();
        let mut w = pred.to_vec();
        for _ in 0..MAX_ITERATIONS {
            let f = self.residual(&w)?;
            let jac = self.jacobian(&w)?;
            let mut a = DMatrix::zeros(d, d);
            a.view_mut((0, 0), (d - 1, d)).copy_from(&jac);
            let mut rhs = DVector::zeros(d);
            rhs.rows_mut(0, d - 1).copy_from(&(-&f));
            for c in 0..d {
                a[(d - 1, c)] = normal[c];
            }
            rhs[d - 1] = target - normal.iter().zip(&w).map(|(n, x)| n * x).sum::<f64>();
            let dw = a.lu().solve(&rhs)?;
            w.iter_mut().zip(dw.iter()).for_each(|(x, s)| *x += s);
            let step = dw.amax();
            if !step.is_finite() || step > 1.0 {
                return None;
            }
            if step < 1e-9 {
                let f = self.residual(&w)?;
                if f.amax() < TOLERANCE || (step < ROUND_OFF_STEP && f.amax() < ROUND_OFF_DEFECT) {
                    // The Jacobian of the last iterate, 1e-9 away: the tangent's.
                    self.last_jacobian.replace(Some((w.clone(), jac)));
                    return Some(w);
                }
            }
        }
        None
    }

    /// The unit tangent of the branch at w: [J; prevᵀ] t = e_last, oriented along `prev`.
    pub fn tangent(&self, jac: &DMatrix<f64>, prev: &[f64]) -> Option<Vec<f64>> {
        let d = self.dim();
        let mut a = DMatrix::zeros(d, d);
        a.view_mut((0, 0), (d - 1, d)).copy_from(jac);
        for c in 0..d {
            a[(d - 1, c)] = prev[c];
        }
        let mut e = DVector::zeros(d);
        e[d - 1] = 1.0;
        let t = a.lu().solve(&e)?;
        let norm = t.norm();
        (norm.is_finite() && norm > 0.0).then(|| t.iter().map(|x| x / norm).collect())
    }

    /// The point at the solution `w`: its tangent (oriented along `prev`), orbit, multipliers and
    /// touches (none unless `touches`: a bisection for a multiplier event does not need them).
    pub fn node(&self, w: Vec<f64>, prev: &[f64]) -> Option<Node> {
        self.node_with(w, prev, true)
    }

    pub fn node_with(&self, w: Vec<f64>, prev: &[f64], touches: bool) -> Option<Node> {
        let lambda = w[w.len() - 1] * self.rho;
        let jac = match self.last_jacobian.take() {
            Some((at, j)) if at == w => j,
            _ => self.jacobian(&w)?,
        };
        let tangent = self.tangent(&jac, prev)?;
        let orbit = self.orbit(lambda)?;
        let (y, times) = self.unpack(&w, orbit.period());
        let defect = self.residual_with(&orbit, &w)?.amax() * self.ys;
        let orbit = orbit.at(&y, &times, defect).ok()?;
        let mu = floquet::multipliers(orbit.monodromy());
        let touches = if touches { orbit.touches() } else { Vec::new() };
        Some(Node { w, tangent, orbit, mu, touches })
    }
}
