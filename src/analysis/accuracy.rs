//! An error estimate on every result: a second solve at k/2 and Richardson's extrapolation with
//! the order the scheme has on this kind of contact (src/formulation.md §3, README "Which scheme and pairing
//! converge"). If the error is e_k ≈ C·h^p, then x_{k/2} − x_k ≈ C·h^p·(2^p − 1), so
//! e_k ≈ max_j |x_{2j}^{(k)} − x_j^{(k/2)}| / (2^p − 1).
//!
//! Cost: the k/2 problem has half the LCP unknowns, so the estimate adds roughly a third to half
//! of a solve; `[discretization] error_estimate = "none"` (CLI `--no-estimate`) skips it. When
//! k/2 breaks the scheme's stability limit (the coarse blade under cds at k = 1024), the second
//! solve is at 2k instead: dearer (twice the unknowns), but the only one that is honest there.
use crate::model::Compliance;
use crate::periodic::{PeriodicProblem, PeriodicSolver, SolveError};
use crate::response::{Accuracy, Response};
use crate::time::{Discretization, Pairing, Scheme};

/// Fewest forced instants in a row that count as a sticking arc (a pure impact loads one or two
/// instants of a forward-paired scheme, its impulse spread over at most two steps).
const STICK_RUN: usize = 4;

/// The order of convergence of `problem`'s scheme on `r`'s contact regime and why (src/formulation.md §3);
/// `None` when the combination is known not to converge.
pub fn expected_order(problem: &PeriodicProblem, r: &Response) -> (Option<f64>, String) {
    let scheme = problem.discretization().scheme;
    let smooth = scheme.order().map_or(2.0, f64::from); // fourier: ≈ 2 at the kink of a compliant force
    let mut order = if scheme == Scheme::Fourier && r.contacts.is_empty() { 4.0 } else { smooth };
    let mut why = vec![];
    for (i, c) in problem.model().contacts.iter().enumerate() {
        let pairing = problem.pairing_at(i);
        let (p, what) = match c.compliance {
            Compliance::Compliant { .. } if pairing == Pairing::Forward => (Some(1.0), "compliant, forward: lags one step"),
            // Measured on the compliant family (validation/study/accuracy.md): fourier's error at
            // the force's kink is not C·h^p (observed orders −0.6 … 5.7 between k/2 and k).
            Compliance::Compliant { .. } if scheme == Scheme::Fourier => (
                Some(smooth),
                "compliant (fourier converges erratically at the force's kink: the estimate follows the error's envelope, 0.1–24× the error measured)",
            ),
            Compliance::Compliant { .. } => (Some(smooth), "compliant"),
            // A stop the orbit never touches does not limit the order: the response is linear there.
            Compliance::Rigid if r.contacts.get(i).is_some_and(|rc| rc.force.iter().all(|&f| f == 0.0)) => (Some(smooth), "rigid, never touched"),
            // A massless contact DOF transmits a finite force through its static stiffness, like a
            // compliant contact (src/formulation.md §4.1; tests/convergence.rs measures the orders).
            Compliance::Rigid if problem.model().contact_is_massless(c) && pairing == Pairing::Forward => {
                (Some(1.0), "rigid on a massless DOF, forward: lags one step")
            }
            Compliance::Rigid if problem.model().contact_is_massless(c) => (Some(smooth), "rigid on a massless DOF (a finite force)"),
            Compliance::Rigid => match (scheme, pairing) {
                (Scheme::Bds1, Pairing::Same) => (Some(1.0), "rigid"),
                (Scheme::Cds | Scheme::Galerkin, Pairing::Forward) => {
                    if r.contacts.get(i).is_some_and(|rc| longest_run(&rc.force) >= STICK_RUN) {
                        (Some(2.0), "rigid with sticking")
                    } else {
                        (Some(1.0), "rigid, pure impacts: first order at best")
                    }
                }
                _ => (None, "rigid: this scheme and pairing do not converge"),
            },
        };
        match p {
            Some(p) => order = order.min(p),
            None => return (None, format!("contact[{i}] {what} ({scheme}, {pairing})")),
        }
        why.push(format!("contact[{i}] {what}"));
    }
    let why = if why.is_empty() { "no contact".to_string() } else { why.join(", ") };
    (Some(order), why)
}

/// The longest run of instants with a positive force, cyclically.
fn longest_run(force: &[f64]) -> usize {
    let k = force.len();
    if force.iter().all(|&f| f > 0.0) {
        return k;
    }
    let (mut best, mut run) = (0, 0);
    for j in 0..2 * k {
        run = if force[j % k] > 0.0 { run + 1 } else { 0 };
        best = best.max(run);
    }
    best
}

/// Estimates the error of `r` (solved from `problem`) by a second solve at k/2; when k/2 breaks
/// the scheme's stability limit (ω_max·h ≥ limit: cds, galerkin on stiff models) by a second
/// solve at 2k instead, and `method` says so. With e ≈ C·h^p: from k/2,
/// e_k ≈ max_j |x_{2j}^{(k)} − x_j^{(k/2)}| / (2^p − 1); from 2k, e_k ≈ max_j |x_j^{(k)} −
/// x_{2j}^{(2k)}| · 2^p / (2^p − 1). The estimate is `None`, with the reason in `method`, when k
/// is odd or too small, the scheme does not converge for this contact, or the second solve is
/// refused or fails.
pub fn estimate(problem: &PeriodicProblem, r: &Response) -> Accuracy {
    let instants = problem.instants();
    estimate_with(problem, r, &mut |second| {
        // Warm-started from the first answer's active set on the second grid: Newton on the
        // period map then starts on the right pieces, where a cold start's offset homotopy
        // fails on stiff blades (the fine blade's 2k solve fell back to minutes of dense Lemke).
        let mut session = PeriodicSolver::new(second.clone());
        session.set_warm_start(&crate::periodic::carried_active_set(&r.active_set, r.lcp.size / instants.max(1), instants, second.instants()));
        session.solve()
    })
}

/// [`estimate`] with the second solve made by `solve_second` (given the problem at k/2 or 2k):
/// a sweep passes a warm-started session of its own, so that the estimate of every point costs
/// a warm solve instead of a cold one.
pub fn estimate_with(problem: &PeriodicProblem, r: &Response, solve_second: &mut dyn FnMut(&PeriodicProblem) -> Result<Response, SolveError>) -> Accuracy {
    let none = |why: String| Accuracy { estimate: None, relative: None, method: format!("none: {why}") };
    let disc = problem.discretization();
    let k = disc.steps;
    if r.displacement.is_empty() {
        return none("no displacement output to estimate".into());
    }
    let (order, why) = expected_order(problem, r);
    let Some(p) = order else { return none(format!("{why}, so no error estimate is given")) };
    if !k.is_multiple_of(2) || k / 2 < crate::periodic::MIN_STEPS {
        return none(format!("richardson needs an even k ≥ {}, k = {k}", 2 * crate::periodic::MIN_STEPS));
    }
    // ω_max·h at k/2 against the scheme's limit: past it the k/2 solve is refused (or unstable).
    let half_h = 2.0 * std::f64::consts::PI / (problem.model().frequency * (k / 2) as f64);
    let beyond = disc.scheme.stability_limit().filter(|&l| problem.omega_max() * half_h >= l);
    let (other, note) = match beyond {
        None => (k / 2, format!("k/2 = {}", k / 2)),
        Some(l) => (
            2 * k,
            format!("2k = {} (k/2 = {} breaks {}'s stability limit: ω_max·h = {:.3} ≥ {l:.3})", 2 * k, k / 2, disc.scheme, problem.omega_max() * half_h),
        ),
    };
    let mut second = problem.clone();
    if let Err(e) = second.set_discretization(Discretization { steps: other, ..disc }) {
        return none(format!("the second solve at {note} is refused: {e}"));
    }
    let rs = match solve_second(&second) {
        Ok(rs) => rs,
        Err(e) => return none(format!("the second solve at {note} failed: {}", short(&e))),
    };
    let (mut diff, mut ptp) = (0.0f64, 0.0f64);
    for (key, x) in &r.displacement {
        let Some(xs) = rs.displacement.get(key) else { continue };
        // The instants the two grids share: every other instant of the finer one.
        let d = if other < k {
            xs.iter().enumerate().map(|(j, v)| (x[2 * j] - v).abs()).fold(0.0, f64::max)
        } else {
            x.iter().enumerate().map(|(j, v)| (xs[2 * j] - v).abs()).fold(0.0, f64::max)
        };
        diff = diff.max(d);
        ptp = ptp.max(Response::peak_to_peak(x));
    }
    let gain = 2f64.powf(p);
    let e = if other < k { diff / (gain - 1.0) } else { diff * gain / (gain - 1.0) };
    Accuracy { estimate: Some(e), relative: (ptp > 0.0).then(|| e / ptp), method: format!("richardson: {note}, order {p} ({}, {why})", disc.scheme) }
}

fn short(e: &SolveError) -> String {
    let s = e.to_string();
    s.split(':').next().unwrap_or(&s).to_string()
}

#[cfg(test)]
mod tests {
    use crate::periodic::carried_active_set;

    #[test]
    fn an_active_set_moves_to_the_doubled_and_the_halved_grid() {
        // 2 rows, 4 instants: row 1 active at instants 1 and 2, row 0 at instant 3.
        let active = [3, 5, 6];
        assert_eq!(carried_active_set(&active, 2, 4, 8), vec![5, 7, 9, 11, 12, 14]);
        // Halved: only the even instants survive (instant 2 → 1).
        assert_eq!(carried_active_set(&active, 2, 4, 2), vec![3]);
        assert!(carried_active_set(&active, 0, 4, 8).is_empty());
    }
}
