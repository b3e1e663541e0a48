//! The continuation's map and its Newton corrector on the bordered system.
//!
//! Unknowns v = (s_0, λ/ρ) (ρ the parameter's range, so that both parts count alike in the
//! arclength), residual F(v) = P(s_0; λ) − s_0 with P the period map of the step map rebuilt at
//! λ. dF/ds_0 = J_s − I with J_s the period Jacobian on the march's active sets (exact: P is
//! affine on a piece); dF/dλ by a central difference of two marches from the same state and
//! sets (P is smooth in λ on a piece).
use super::Parameter;
use crate::error::Error;
use crate::periodic::{PeriodicProblem, StepMapLcp, Tuning, step_map};
use crate::time::Discretization;
use nalgebra::{DMatrix, DVector};

/// Relative defect accepted when Newton stalls at a kink of the discrete map (NLvib 03, 2T
/// branch at k = 4096: stalls between 8e-11 and 3e-9 of the state where the tolerance asked
/// 1e-10; the orbits' discretisation error is O(h²) ≈ 1e-4 there).
const STALL_FLOOR: f64 = 1e-8;

/// What λ moves: a parameter of the problem, or the straight path between two tunings of a base
/// problem (λ = 0 at `from`, 1 at `to`: a front end's re-solve after its knobs changed).
#[derive(Clone, Copy, Debug)]
pub(super) enum Path {
    Parameter(Parameter),
    Tuning { from: Tuning, to: Tuning, disc: Discretization },
}

impl Path {
    fn apply(&self, base: &PeriodicProblem, lambda: f64) -> Result<PeriodicProblem, Error> {
        match *self {
            Path::Parameter(param) => {
                let mut p = base.clone();
                param.apply(&mut p, lambda)?;
                Ok(p)
            }
            Path::Tuning { from, to, disc } => {
                let t = from.towards(&to, lambda);
                t.apply(base, disc).map_err(Error::from)
            }
        }
    }
}

/// The orbits of one problem as the parameter varies.
pub(super) struct Family {
    base: PeriodicProblem,
    path: Path,
    /// The parameter's range |to − from|: λ enters the unknowns as λ/ρ.
    pub rho: f64,
    /// Relative defect ‖F‖∞ / max(‖s_0‖∞, scale) at which the corrector stops.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Marches made (the cost).
    pub marches: usize,
    /// Width of the stability monodromy's differences ([`Family::smoothed_monodromy`]).
    pub smoothing: f64,
    /// Blocks of the state (x, ∇x, …): the scheme's order.
    pub blocks: usize,
}

/// A solved point of the family: the state, the parameter, the active sets, the Jacobian
/// [dF/ds_0 | dF/d(λ/ρ)] and the discrete monodromy dP/ds_0.
#[derive(Clone, Debug)]
pub(super) struct Solved {
    pub v: Vec<f64>,
    pub masks: Vec<u64>,
    pub jacobian: DMatrix<f64>,
    pub monodromy: DMatrix<f64>,
}

impl Solved {
    pub fn parameter(&self, rho: f64) -> f64 {
        self.v[self.v.len() - 1] * rho
    }
    /// The sign of det [dF; tᵀ]: constant along a regular branch, also across the kinks of a
    /// piecewise-affine map (Allgower & Georg 1990, §12.1), where tᵀ·(the last tangent) is not.
    pub fn orientation(&self, tangent: &[f64]) -> f64 {
        bordered(&self.jacobian, tangent).determinant().signum()
    }

    /// The unit tangent of the branch: [dF; borderᵀ] t = e_last, normalised (so tᵀ·border > 0).
    pub fn tangent(&self, border: &[f64]) -> Option<Vec<f64>> {
        let n = self.v.len();
        let a = bordered(&self.jacobian, border);
        let t = a.lu().solve(&DVector::from_fn(n, |i, _| if i + 1 == n { 1.0 } else { 0.0 }))?;
        let norm = t.norm();
        (norm.is_finite() && norm > 0.0).then(|| t.iter().map(|v| v / norm).collect())
    }
}

/// A kink of the map crossed by [`Family::cross_kink`].
pub(super) struct Kink {
    /// The orbit a step beyond it, on the next piece.
    pub next: Solved,
    /// The next piece's unit tangent, oriented along the branch.
    pub turn: Vec<f64>,
}

/// [dF; borderᵀ], (d+1)×(d+1).
fn bordered(jacobian: &DMatrix<f64>, border: &[f64]) -> DMatrix<f64> {
    let n = border.len();
    DMatrix::from_fn(n, n, |i, j| if i + 1 < n { jacobian[(i, j)] } else { border[j] })
}

impl Family {
    /// The continued parameter's name ("knobs" for a front end's tuning path).
    pub fn name(&self) -> &'static str {
        match self.path {
            Path::Parameter(p) => p.name(),
            Path::Tuning { .. } => "knobs",
        }
    }

    pub fn new(base: &PeriodicProblem, path: Path, rho: f64) -> Self {
        let mut base = base.clone();
        // One orbit per call: the solver's inner parallelism would only compete with itself.
        base.set_parallel(false);
        let mut fam = Family { base, path, rho, tolerance: 1e-10, max_iterations: 12, marches: 0, smoothing: 0.0, blocks: 2 };
        // The base as it is for a parameter (its λ may be any value), the path's start for tunings.
        let start = if matches!(path, Path::Tuning { .. }) { fam.problem_at(0.0).ok() } else { Some(fam.base.clone()) };
        // The state holds the DOFs with mass only (massless ones are condensed in each step).
        let sized = start.and_then(|p| step_map(&p).ok().map(|sm| sm.state_size() / (p.model().n() - p.model().massless_dofs().len()).max(1)));
        fam.blocks = sized.unwrap_or(2).max(1);
        fam
    }

    /// The problem at parameter λ.
    pub fn problem_at(&self, lambda: f64) -> Result<PeriodicProblem, Error> {
        self.path.apply(&self.base, lambda)
    }

    /// The step map at λ.
    pub fn map_at(&self, lambda: f64) -> Result<StepMapLcp, Error> {
        let p = self.problem_at(lambda)?;
        step_map(&p).map_err(|e| {
            Error::input(format!(
                "continuation needs the time-stepping map of a difference scheme: {}; set [discretization] scheme = \"cds\" \
                 (or bds1, bds2, galerkin), or trace the scene with `sweep`, which takes every scheme",
                e.0
            ))
        })
    }

    /// F, its Jacobian and the active sets at v (the march tries `guess` first per step).
    fn evaluate(&mut self, v: &[f64], guess: &[u64]) -> Option<(Vec<f64>, Solved)> {
        let d = v.len() - 1;
        let lambda = v[d] * self.rho;
        let sm = self.map_at(lambda).ok()?;
        let (end, masks, _) = sm.march_period(&v[..d], Some(guess))?;
        let j = sm.period_jacobian(&masks);
        // Central difference in λ, same state, the sets of the march at λ tried first.
        let eps = 1e-6 * lambda.abs().max(1e-3 * self.rho);
        let mut ends = [Vec::new(), Vec::new()];
        for (e, sign) in ends.iter_mut().zip([1.0, -1.0]) {
            let smp = self.map_at(lambda + sign * eps).ok()?;
            *e = smp.march_period(&v[..d], Some(&masks))?.0;
        }
        self.marches += 3;
        let monodromy = DMatrix::from_fn(d, d, |r, c| j[(r, c)]);
        let jacobian = DMatrix::from_fn(d, d + 1, |r, c| {
            if c < d { monodromy[(r, c)] - if r == c { 1.0 } else { 0.0 } } else { (ends[0][r] - ends[1][r]) / (2.0 * eps) * self.rho }
        });
        let f: Vec<f64> = (0..d).map(|i| end[i] - v[i]).collect();
        Some((f, Solved { v: v.to_vec(), masks, jacobian, monodromy }))
    }

    /// Newton on [F(v); nᵀ(v − pred)] = 0 from `pred`: the point of the family on the hyperplane
    /// through `pred` normal to `normal`. Returns it and the iterations, `None` when Newton does
    /// not converge in `max_iterations` (the caller shortens the step). A step that does not
    /// lower the defect is halved (up to 4 times): near a kink of the piecewise-affine map, full
    /// steps can cycle between two pieces, each piece's root lying in the other (met on the 2T
    /// branch of NLvib 03 at k = 4096, where the steps halved down to the smallest).
    pub fn correct(&mut self, pred: &[f64], normal: &[f64], guess: &[u64]) -> Option<(Solved, usize)> {
        let n = pred.len();
        let mut v = pred.to_vec();
        let (mut f, mut solved) = self.evaluate(&v, guess)?;
        for iteration in 0..=self.max_iterations {
            let along: f64 = (0..n).map(|i| normal[i] * (v[i] - pred[i])).sum();
            let size = v[..n - 1].iter().fold(1e-3f64, |a, x| a.max(x.abs()));
            let defect = f.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if defect <= self.tolerance * size && along.abs() <= 1e-12 * size.max(1.0) {
                return Some((solved, iteration));
            }
            if iteration == self.max_iterations {
                // At a kink Newton can stall between two pieces with a tiny defect: accept it
                // below the floor, far under the O(h²) error of the orbit.
                if defect <= STALL_FLOOR * size && along.abs() <= 1e-12 * size.max(1.0) {
                    return Some((solved, iteration));
                }
                break;
            }
            let a = bordered(&solved.jacobian, normal);
            let rhs = DVector::from_fn(n, |i, _| if i + 1 < n { -f[i] } else { -along });
            let dv = a.lu().solve(&rhs)?;
            if !dv.iter().all(|x| x.is_finite()) {
                return None;
            }
            let merit = defect.max(along.abs());
            let mut step = 1.0;
            let (trial, ft, st) = loop {
                let trial: Vec<f64> = v.iter().zip(dv.iter()).map(|(x, d)| x + step * d).collect();
                let evaluated = self.evaluate(&trial, &solved.masks);
                if let Some((ft, st)) = evaluated {
                    let along_t: f64 = (0..n).map(|i| normal[i] * (trial[i] - pred[i])).sum();
                    let m_t = ft.iter().fold(along_t.abs(), |a, x| a.max(x.abs()));
                    if m_t < merit || step < 0.1 {
                        break (trial, ft, st);
                    }
                } else if step < 0.1 {
                    return None;
                }
                step /= 2.0;
            };
            v = trial;
            f = ft;
            solved = st;
        }
        None
    }

    /// [dF/ds_0 | dF/d(λ/ρ)] at v on the piece of `masks` (the sets imposed, not solved for).
    fn frozen_jacobian(&mut self, v: &[f64], masks: &[u64]) -> Option<DMatrix<f64>> {
        let d = v.len() - 1;
        let lambda = v[d] * self.rho;
        let j = self.map_at(lambda).ok()?.period_jacobian(masks);
        let eps = 1e-6 * lambda.abs().max(1e-3 * self.rho);
        let up = self.map_at(lambda + eps).ok()?.march_frozen(&v[..d], masks)?;
        let down = self.map_at(lambda - eps).ok()?.march_frozen(&v[..d], masks)?;
        self.marches += 2;
        Some(DMatrix::from_fn(d, d + 1, |r, c| if c < d { j[(r, c)] - if r == c { 1.0 } else { 0.0 } } else { (up[r] - down[r]) / (2.0 * eps) * self.rho }))
    }

    /// The active sets of the march from the state of v at its λ, `guess` tried first.
    fn masks_at(&mut self, v: &[f64], guess: &[u64]) -> Option<Vec<u64>> {
        let d = v.len() - 1;
        let sm = self.map_at(v[d] * self.rho).ok()?;
        self.marches += 1;
        Some(sm.march_period(&v[..d], Some(guess))?.1)
    }

    /// Crosses the kink of the map that the step `ds` along `tangent` from `here` runs into,
    /// when it is one pair's change of status at one step: returns the orbit a step of at most
    /// `ds` beyond it on the next piece, and that piece's tangent. Why: where the branch turns
    /// back at a kink by more than a right angle (a nonsmooth fold: the coarse blade's contact
    /// branch at ω ≈ 2796 rad/s, where the next piece's line runs back almost along this one),
    /// the hyperplane ahead meets no orbit and the corrector fails at every step. The next piece's direction is the one that keeps the
    /// sign of det [dF; tᵀ], the orientation of a piecewise-linear path (Allgower & Georg,
    /// *Numerical Continuation Methods*, 1990, §12.1); its λ turns back at a fold.
    pub fn cross_kink(&mut self, here: &Solved, tangent: &[f64], ds: f64) -> Option<Kink> {
        let at = |tau: f64| -> Vec<f64> { here.v.iter().zip(tangent).map(|(v, t)| v + tau * t).collect() };
        let beyond = self.masks_at(&at(ds), &here.masks)?;
        let changed: usize = here.masks.iter().zip(&beyond).map(|(a, b)| (a ^ b).count_ones() as usize).sum();
        if changed != 1 {
            return None;
        }
        let (mut lo, mut hi) = (0.0, ds);
        while hi - lo > 1e-12 * ds {
            let mid = 0.5 * (lo + hi);
            if self.masks_at(&at(mid), &here.masks)? == here.masks {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let next_sets = self.masks_at(&at(hi), &here.masks)?;
        let (_, kink) = self.evaluate(&at(lo), &here.masks)?;
        if kink.masks != here.masks || next_sets == here.masks {
            return None;
        }
        let next_jacobian = self.frozen_jacobian(&kink.v, &next_sets)?;
        let on_next = Solved { v: kink.v.clone(), masks: next_sets.clone(), jacobian: next_jacobian, monodromy: kink.monodromy.clone() };
        let turn = on_next.tangent(tangent)?;
        let sign = if on_next.orientation(&turn) == kink.orientation(tangent) { 1.0 } else { -1.0 };
        let turn: Vec<f64> = turn.iter().map(|t| sign * t).collect();
        // A step that stays on the next piece: near a fold the pieces are short (NLvib-like
        // zigzags of the discrete branch), and a longer step would skip the next turn.
        let mut step = ds;
        let along = |step: f64| -> Vec<f64> { kink.v.iter().zip(&turn).map(|(v, t)| v + step * t).collect() };
        while self.masks_at(&along(step), &next_sets)? != next_sets {
            step /= 2.0;
            if step < 1e-6 * ds {
                return None;
            }
        }
        let (next, _) = self.correct(&along(step), &turn, &next_sets)?;
        (next.masks != here.masks).then_some(Kink { next, turn })
    }

    /// The monodromy for stability: central differences of P over a width δ·(the state block's
    /// size), δ = `smoothing`. Why not the piece's Jacobian alone: the discrete P has a kink
    /// wherever a contact gains or loses a step, and the piece Jacobians on either side differ
    /// by far more than the O(h²) error (measured on NLvib 03 at k = 2048: −1.13 and −1.57 for
    /// the same orbit's multiplier); the difference across a few kinks averages them and follows
    /// the continuous multipliers (tests/continuation.rs).
    pub fn smoothed_monodromy(&mut self, solved: &Solved, blocks: usize, smoothing: f64) -> Option<DMatrix<f64>> {
        let d = solved.v.len() - 1;
        let sm = self.map_at(solved.parameter(self.rho)).ok()?;
        let n = d / blocks.max(1);
        let scale: Vec<f64> = (0..blocks).map(|b| solved.v[b * n..(b + 1) * n].iter().fold(1e-12f64, |a, x| a.max(x.abs()))).collect();
        let mut m = DMatrix::zeros(d, d);
        for c in 0..d {
            let eps = smoothing * scale[(c / n).min(blocks - 1)];
            let mut ends = [Vec::new(), Vec::new()];
            for (e, sign) in ends.iter_mut().zip([1.0, -1.0]) {
                let mut s = solved.v[..d].to_vec();
                s[c] += sign * eps;
                *e = sm.march_period(&s, Some(&solved.masks))?.0;
            }
            for r in 0..d {
                m[(r, c)] = (ends[0][r] - ends[1][r]) / (2.0 * eps);
            }
        }
        self.marches += 2 * d;
        Some(m)
    }

    /// The orbit at λ with these active sets: the fixed point of their affine piece of P,
    /// s = (I − J_s)⁻¹ P_frozen(0), then corrected at fixed λ.
    pub fn start(&mut self, lambda: f64, masks: &[u64]) -> Option<Solved> {
        let sm = self.map_at(lambda).ok()?;
        let d = sm.state_size();
        let b = sm.march_frozen(&vec![0.0; d], masks)?;
        let j = sm.period_jacobian(masks);
        let a = DMatrix::from_fn(d, d, |r, c| if r == c { 1.0 } else { 0.0 } - j[(r, c)]);
        let s = a.lu().solve(&DVector::from_column_slice(&b))?;
        let mut pred: Vec<f64> = s.iter().copied().collect();
        pred.push(lambda / self.rho);
        let normal: Vec<f64> = (0..=d).map(|i| if i == d { 1.0 } else { 0.0 }).collect();
        self.correct(&pred, &normal, masks).map(|(p, _)| p)
    }
}
