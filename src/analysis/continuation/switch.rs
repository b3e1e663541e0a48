//! Branch switching at a period doubling: from the T branch onto the 2T branch.
//!
//! At a period doubling of the T branch the T monodromy has a multiplier −1 with eigenvector v,
//! so the 2T map's monodromy (its square) has +1 there and the 2T family's Jacobian
//! [dF₂/ds_0 | dF₂/dλ] has a two-dimensional kernel: the T branch's tangent and (v, 0) (a branch
//! point of the 2T map; Kuznetsov, "Elements of Applied Bifurcation Theory", §10.2, and
//! Doedel's AUTO notes on period doubling). The 2T branch leaves along the kernel direction
//! transverse to the T branch, w = (v, 0) minus its component along the T tangent. Its first
//! point is the 2T orbit on the hyperplane wᵀ(u − u*) = ε through u* + ε·w; from there
//! pseudo-arclength on the 2T map as on any branch, until the branch meets the T branch again
//! (its orbit becomes T-periodic: P_T(s) − s, the half-period shift, passes through zero, at the
//! other period doubling) or leaves the range. v comes from the smoothed monodromy, the one the
//! period doubling was located with ([`Family::smoothed_monodromy`]).
use super::corrector::Family;
use super::events::Node;
use super::{Branch, BranchPoint, ContinuationSettings, EventKind, Parameter, Walk, family, point, run_discrete};
use crate::error::Error;
use crate::periodic::{PeriodicProblem, PeriodicSolver};
use nalgebra::DMatrix;

/// Size of the first step off the T branch along w, relative to the largest displacement of
/// the orbit's state. Why 2 %: the discrete map is piecewise affine with kinks O(h) apart in the
/// state; the step must cross many of them to see the 2T branch and not the kinks (NLvib 03,
/// k = 4096: the 2T orbit at 2 % of the amplitude lies 1.2e-4 in Ω past the doubling).
const FIRST_STEP: f64 = 2e-2;

/// Continues the T branch of `problem` from `from` to `to` on the grid ([`run_discrete`]: the
/// switch needs the discrete orbit's active sets), then, at each of its
/// period doublings that no branch found so far has rejoined, switches to the 2T branch
/// ([`switch_at`]) and continues it within [from, to]. Returns the branches, the T branch first,
/// and why a switch failed where one did (the other branches are kept).
pub fn run_switching(
    problem: &PeriodicProblem,
    param: Parameter,
    from: f64,
    to: f64,
    settings: &ContinuationSettings,
    on_point: &dyn Fn(&BranchPoint),
) -> Result<(Vec<Branch>, Vec<String>), Error> {
    let t = run_discrete(problem, param, from, to, settings, on_point)?;
    let mut branches = vec![t];
    let doublings: Vec<usize> = (0..branches[0].points.len()).filter(|&i| branches[0].points[i].event == Some(EventKind::PeriodDoubling)).collect();
    // Where a 2T branch ended on the T branch: a doubling there is that branch's other end.
    let mut joined: Vec<f64> = Vec::new();
    let mut failures = Vec::new();
    let close = settings.fold_merge * (to - from).abs();
    for i in doublings {
        let at = branches[0].points[i].parameter;
        if joined.iter().any(|j| (j - at).abs() < close) {
            continue;
        }
        match switch_at(problem, param, &branches[0], i, (from, to), settings, on_point) {
            Ok(b) => {
                if let Some(end) = b.points.last().filter(|p| !p.detail.is_empty()) {
                    joined.push(end.parameter);
                }
                branches.push(b);
            }
            Err(e) => failures.push(e.to_string()),
        }
    }
    Ok((branches, failures))
}

/// The 2T branch that starts at the period doubling `branch.points[at]` of the T branch of
/// `problem`, continued within the range (from, to) of the T branch's continuation.
pub fn switch_at(
    problem: &PeriodicProblem,
    param: Parameter,
    branch: &Branch,
    at: usize,
    (from, to): (f64, f64),
    settings: &ContinuationSettings,
    on_point: &dyn Fn(&BranchPoint),
) -> Result<Branch, Error> {
    let pd = &branch.points[at];
    if pd.event != Some(EventKind::PeriodDoubling) || branch.period_multiple != 1 {
        return Err(Error::input(format!("branch switching: point {at} of the {} branch is not a period doubling of a T branch", branch.label)));
    }
    let name = param.name();
    let rho = (to - from).abs();
    let mut fam1 = family(problem, param, rho, settings);
    let mut doubled = problem.clone();
    doubled.set_period_multiple(2).map_err(|e| Error::from(e).context("the 2T problem of the branch switch"))?;
    let mut fam2 = family(&doubled, param, rho, settings);
    let d = pd.state.len();
    let mut star = pd.state.clone();
    star.push(pd.parameter / rho);
    let fail = |why: &str| Error::solve(format!("branch switching at the period doubling {name} = {}: {why}", pd.parameter));
    // The T orbit at the doubling, its smoothed monodromy and the eigenvector of μ ≈ −1.
    let e_lambda: Vec<f64> = (0..=d).map(|i| if i == d { 1.0 } else { 0.0 }).collect();
    let (solved1, _) = fam1.correct(&star, &e_lambda, &pd.masks).ok_or_else(|| fail("the T orbit does not close there"))?;
    let blocks = fam1.blocks;
    let mono = fam1.smoothed_monodromy(&solved1, blocks, settings.smoothing.max(1e-6)).ok_or_else(|| fail("no monodromy"))?;
    let v = null_vector(&(mono + DMatrix::identity(d, d))).ok_or_else(|| fail("no eigenvector of the multiplier −1"))?;
    // w: (v, 0) without its component along the T branch's tangent.
    let t = &pd.tangent;
    let along: f64 = v.iter().zip(t).map(|(a, b)| a * b).sum();
    let mut w: Vec<f64> = (0..=d).map(|i| if i < d { v[i] } else { 0.0 } - along * t[i]).collect();
    let norm = w.iter().map(|x| x * x).sum::<f64>().sqrt();
    w.iter_mut().for_each(|x| *x /= norm);
    let masks2: Vec<u64> = pd.masks.iter().chain(&pd.masks).copied().collect();
    let (start2, _) = fam2.correct(&star, &w, &masks2).ok_or_else(|| fail("the T orbit does not close as a 2T orbit"))?;
    let mut solver = PeriodicSolver::new(fam2.problem_at(pd.parameter)?);
    let head = Node::new(&mut fam2, start2, w.clone());
    let mut points: Vec<BranchPoint> =
        vec![point(&fam2, &mut solver, &head, None, format!("starts at the period doubling of the T branch, {name} = {}", pd.parameter))?];
    // The first 2T orbit: ε along w, either sign, halved until the corrector lands off the T branch.
    let n = problem.model().n();
    let size = pd.state[..n.min(d)].iter().fold(0.0f64, |a, x| a.max(x.abs())).max(1e-12);
    let doublings = branch.events().filter(|p| p.event == Some(EventKind::PeriodDoubling)).map(|p| (p.parameter, p.state.clone(), p.masks.clone())).collect();
    let mut rejoin = Rejoin { fam1: &mut fam1, largest: 0.0, last: Vec::new(), doublings };
    let mut first = None;
    'tries: for scale in [1.0, 0.5, 0.25, 2.0] {
        for sign in [1.0, -1.0] {
            let eps = sign * scale * FIRST_STEP * size;
            let pred: Vec<f64> = star.iter().zip(&w).map(|(s, x)| s + eps * x).collect();
            let Some((s1, _)) = fam2.correct(&pred, &w, &masks2) else { continue };
            let Some(shift) = rejoin.shift(&s1) else { continue };
            // Off the T branch: the half-period shift is of the size of the step taken.
            if norm_inf(&shift) > 1e-3 * scale * FIRST_STEP * size {
                // The secant from the doubling: the tangent off the T branch (see `Walk::secant`).
                let away: Vec<f64> = s1.v.iter().zip(&star).map(|(a, b)| a - b).collect();
                let len = away.iter().map(|x| x * x).sum::<f64>().sqrt();
                first = Some((s1, away.iter().map(|x| x / len).collect::<Vec<f64>>(), shift));
                break 'tries;
            }
        }
    }
    let (s1, tangent, shift) = first.ok_or_else(|| {
        fail("no 2T orbit near the T orbit along the eigenvector of −1 (the doubling may be degenerate, or kinks of the discrete map hide it: increase steps)")
    })?;
    rejoin.largest = norm_inf(&shift);
    rejoin.last = shift;
    let here = Node::new(&mut fam2, s1, tangent);
    let first = point(&fam2, &mut solver, &here, None, String::new())?;
    on_point(&first);
    points.push(first);
    let walk = Walk { from, to, secant: true, settings, on_point, until: None };
    let super::Walked { points, stop, .. } = walk.follow(&mut fam2, &mut solver, here, points, Some(&mut rejoin))?;
    let marches = fam2.marches + fam1.marches;
    Ok(Branch { parameter: param, points, stop, marches, period_multiple: 2, label: format!("2T from {name} = {:.7}", pd.parameter) })
}

/// Watches a 2T branch for its return to the T branch: the half-period shift P_T(s) − s of its
/// orbits goes through zero there (and flips sign past it, onto the same orbits shifted by T).
pub(super) struct Rejoin<'a> {
    fam1: &'a mut Family,
    /// The largest ‖P_T(s) − s‖∞ seen along the branch.
    largest: f64,
    /// P_T(s) − s at the last point.
    last: Vec<f64>,
    /// The T branch's period doublings (λ, s_0, active sets): where a 2T branch can end.
    doublings: Vec<(f64, Vec<f64>, Vec<u64>)>,
}

impl Rejoin<'_> {
    /// P_T(s) − s of a 2T orbit (the T map at its parameter, its first half's active sets tried first).
    fn shift(&mut self, s: &super::corrector::Solved) -> Option<Vec<f64>> {
        let d = s.v.len() - 1;
        let sm = self.fam1.map_at(s.parameter(self.fam1.rho)).ok()?;
        let half = &s.masks[..s.masks.len() / 2];
        let (end, _, _) = sm.march_period(&s.v[..d], Some(half))?;
        self.fam1.marches += 1;
        Some(end.iter().zip(&s.v).map(|(e, x)| e - x).collect())
    }

    /// The node where the branch meets the T branch between `here` and `next`, if it does: the
    /// shift turns against the last one while small (a fifth of the largest seen), or vanishes.
    /// The branch ends there at the T branch's period doubling nearest in λ, taken as a 2T orbit
    /// (a secant across the crossing would land on the T branch beside it, not at the doubling).
    pub fn check(&mut self, fam2: &mut Family, here: &Node, next: &Node) -> Option<Node> {
        let shift = self.shift(&next.solved)?;
        let size = norm_inf(&shift);
        let dot: f64 = shift.iter().zip(&self.last).map(|(a, b)| a * b).sum();
        let turned = dot < 0.0 && size.min(norm_inf(&self.last)) < 0.2 * self.largest;
        let vanished = size < 1e-6 * self.largest;
        self.largest = self.largest.max(size);
        if !(turned || vanished) {
            self.last = shift;
            return None;
        }
        let rho = fam2.rho;
        let lambda = next.solved.parameter(rho);
        let Some((at, state, masks)) = self.doublings.iter().min_by(|a, b| (a.0 - lambda).abs().total_cmp(&(b.0 - lambda).abs())) else {
            return Some(next.clone());
        };
        let mut star = state.clone();
        star.push(at / rho);
        let masks2: Vec<u64> = masks.iter().chain(masks).copied().collect();
        let sec: Vec<f64> = star.iter().zip(&here.solved.v).map(|(b, a)| b - a).collect();
        let len = sec.iter().map(|x| x * x).sum::<f64>().sqrt();
        let tangent: Vec<f64> = sec.iter().map(|x| x / len).collect();
        let node = fam2.correct(&star, &tangent, &masks2).map(|(s, _)| Node::new(fam2, s, tangent));
        Some(node.unwrap_or_else(|| next.clone()))
    }
}

/// The unit vector x minimising ‖A x‖ (the right singular vector of the smallest singular value).
fn null_vector(a: &DMatrix<f64>) -> Option<Vec<f64>> {
    let svd = a.clone().svd(false, true);
    let vt = svd.v_t?;
    let i = (0..svd.singular_values.len()).min_by(|&x, &y| svd.singular_values[x].total_cmp(&svd.singular_values[y]))?;
    Some(vt.row(i).iter().copied().collect())
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}
