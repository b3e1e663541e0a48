//! The period's LCP as a time-stepping map (for `lcp`'s shooting solver): the difference schemes
//! in state-space form.
//!
//! Row j of the global system Z X + (I ⊗ B)ᵀ z = F̄ (src/formulation.md §2) for a difference scheme reads
//! Σ_{i=0..p} N_i x_{j+L−i} + Bᵀ z_j = f̄_j, N_i = a2_i M + a1_i C + a0_i K, with the coefficients
//! of the symbols (z = one-step delay):
//!
//! | scheme | lead L | a2·h² | a1·h | a0 | f̄_j |
//! |---|---|---|---|---|---|
//! | cds | 1 | 1, −2, 1 | ½, 0, −½ | 0, 1, 0 | f_j |
//! | galerkin | 1 | 1, −2, 1 | ½, 0, −½ | ⅙, ⅔, ⅙ | (f_{j+1} + 4f_j + f_{j−1})/6 |
//! | bds1 | 0 | 1, −2, 1 | 1, −1, 0 | 1, 0, 0 | f_j |
//! | bds2 | 0 | 2, −5, 4, −1 | 3/2, −2, ½, 0 | 1, 0, 0, 0 | f_j |
//!
//! so x_{j+L} = W(f̄_j − Σ_{i≥1} N_i x_{j+L−i} − Bᵀ z_j), W = N_0⁻¹. The state is the backward
//! differences s_j = (x, ∇x, …, ∇^(p−1) x) at x_{j+L−1}, advanced in summed form (see
//! [`step_map`]): round-off then stays at ε relative per step instead of the k²·ε a state of raw
//! samples loses to 2x_j − x_(j−1). The predictor is y_j = Φ s_j + c_j and s_{j+1} = y_j + Γ z_j,
//! Γ = (−W Bᵀ, …, −W Bᵀ). Contact c is paired with the gap at t_{j+s} (s its pairing offset):
//! - s = L (cds/galerkin forward, bds same): w = gap_c(t_{j+L}) − B_c x_{j+L} + z/k_c, read in
//!   y's first block after the step: implicit, S_cc = B_c W B_cᵀ + 1/k_c;
//! - s = L − 1 (cds/galerkin same): w = gap_c(t_j) − B_c x_j + z/k_c, x_j = y's first block minus
//!   its second, known before the step: explicit, S_cc = 1/k_c, so only a compliant contact has
//!   one answer per step;
//! - s > L (bds forward): the force is paired with a later step's gap, not a step map.
//!
//! Fourier collocation is not a time stepper. The map is dense in d = p·n, so only models of up
//! to [`MAX_STEP_MAP_DOFS`] DOFs (reduced ones) get one.
use super::PeriodicProblem;
use crate::lcp::{DenseLu, MAX_PAIRS, StepMapData, StepMapLcp, dense_product};
use crate::model::{Compliance, Model};
use crate::time::Scheme;
use faer::Mat;

/// Most DOFs of a model solved by shooting: its march is dense in the state (d = 2n or 3n) and
/// each Newton iteration forms a d×d Jacobian.
pub const MAX_STEP_MAP_DOFS: usize = 64;

/// Why a problem has no step map (the solver then uses the LCP alone).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct NoStepMap(pub String);

/// Lead L and the coefficients a2·h², a1·h, a0 of a difference scheme.
type Coefficients = (usize, Vec<f64>, Vec<f64>, Vec<f64>);

/// The coefficients of a difference scheme; `None` for fourier.
fn coefficients(scheme: Scheme) -> Option<Coefficients> {
    Some(match scheme {
        Scheme::Cds => (1, vec![1.0, -2.0, 1.0], vec![0.5, 0.0, -0.5], vec![0.0, 1.0, 0.0]),
        Scheme::Galerkin => (1, vec![1.0, -2.0, 1.0], vec![0.5, 0.0, -0.5], vec![1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0]),
        Scheme::Bds1 => (0, vec![1.0, -2.0, 1.0], vec![1.0, -1.0, 0.0], vec![1.0, 0.0, 0.0]),
        Scheme::Bds2 => (0, vec![2.0, -5.0, 4.0, -1.0], vec![1.5, -2.0, 0.5, 0.0], vec![1.0, 0.0, 0.0, 0.0]),
        Scheme::Fourier => return None,
    })
}

/// The step map of `problem`'s LCP, or why there is none.
pub fn step_map(problem: &PeriodicProblem) -> Result<StepMapLcp, NoStepMap> {
    let model = problem.model();
    let disc = problem.discretization();
    let Some((lead, a2, a1, a0)) = coefficients(disc.scheme) else {
        return Err(NoStepMap("fourier collocation is not a time-stepping scheme".to_string()));
    };
    // p·k steps over p·T for an orbit of p forcing periods (h = T/k either way).
    let (n, m, k) = (model.n(), model.contacts.len(), problem.instants());
    if !model.frictions.is_empty() {
        return Err(NoStepMap("friction contacts have no step map yet (src/formulation.md §9)".to_string()));
    }
    if n > MAX_STEP_MAP_DOFS {
        return Err(NoStepMap(format!("the model has {n} DOFs; shooting takes at most {MAX_STEP_MAP_DOFS} (reduce it: Craig–Bampton)")));
    }
    if m > MAX_PAIRS {
        return Err(NoStepMap(format!("{m} contacts; shooting takes at most {MAX_PAIRS}")));
    }
    let offsets: Vec<usize> = (0..m).map(|c| problem.pairing_at(c).offset()).collect();
    if let Some(c) = offsets.iter().position(|&s| s > lead) {
        return Err(NoStepMap(format!("contact[{c}] is paired forward under {}: its force waits for a later step's gap", disc.scheme)));
    }
    let p = a2.len() - 1;
    let d = p * n;
    let h = problem.period() / k as f64;
    let s = &model.structure;
    let (mass, stiffness) = (s.mass.to_dense(), s.stiffness.to_dense());
    let damping = s.damping.as_ref().map(|c| c.to_dense());
    let combine = |(c2, c1, c0): (f64, f64, f64)| {
        Mat::from_fn(n, n, |r, c| c2 / (h * h) * mass[(r, c)] + c1 / h * damping.as_ref().map_or(0.0, |d| d[(r, c)]) + c0 * stiffness[(r, c)])
    };
    // W = N_0⁻¹ by LU.
    let lu = DenseLu::new(&combine((a2[0], a1[0], a0[0])));
    let columns: Vec<Vec<f64>> = (0..n).map(|c| lu.solve(&(0..n).map(|r| if r == c { 1.0 } else { 0.0 }).collect::<Vec<_>>())).collect();
    let w = Mat::from_fn(n, n, |r, c| columns[c][r]);
    // The state is (x, ∇x, …, ∇^(p−1) x) at the newest instant x_(j+L−1). The step computes
    // δ = ∇^p x_(j+L) = W (f̄_j − Bᵀz_j − Σ_i Q_i ∇^i x), Q_i = Σ_(l≤i) Ñ_l,
    // Ñ_l = Σ_i (−1)^l C(i, l) N_i (x_(j+L−i) = Σ_l (−1)^l C(i, l) ∇^l x_(j+L), Σ_l Ñ_l = N_0),
    // then ∇^b x_(j+L) = Σ_(i≥b) ∇^i x_(j+L−1) + δ exactly (the carry). The Q_i's coefficients are
    // exact small rationals, and consistency (Σ a2 = Σ a1 = 0, Σ i·a2 = 0) leaves no O(1/h²) term
    // to cancel: the march keeps ε-relative precision in every difference.
    let binomial = |i: usize, l: usize| (0..l).fold(1.0, |acc, t| acc * (i - t) as f64 / (t + 1) as f64);
    let mut q = (0.0, 0.0, 0.0);
    let mut phi = vec![0.0; d * d];
    for i in 0..p {
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        let tilde = (0..=p).filter(|&t| t >= i).fold((0.0, 0.0, 0.0), |acc, t| {
            let b = sign * binomial(t, i);
            (acc.0 + b * a2[t], acc.1 + b * a1[t], acc.2 + b * a0[t])
        });
        q = (q.0 + tilde.0, q.1 + tilde.1, q.2 + tilde.2);
        let wq = dense_product(&w, &combine(q));
        for b in 0..p {
            for r in 0..n {
                for c in 0..n {
                    phi[(b * n + r) * d + i * n + c] = -wq[(r, c)];
                }
            }
        }
    }
    let carry: Vec<(usize, usize)> = (0..p).flat_map(|b| (b..p).flat_map(move |i| (0..n).map(move |r| (b * n + r, i * n + r)))).collect();
    // f̄_j at the k instants, then c_j = (W f̄_j, …, W f̄_j).
    let forces = force_samples(model, k, h);
    let galerkin = disc.scheme == Scheme::Galerkin;
    let mut c = vec![0.0; k * d];
    let mut fbar = vec![0.0; n];
    for j in 0..k {
        for (dof, f) in fbar.iter_mut().enumerate() {
            let at = |jj: usize| forces[jj * n + dof];
            *f = if galerkin { (at((j + 1) % k) + 4.0 * at(j) + at((j + k - 1) % k)) / 6.0 } else { at(j) };
        }
        for r in 0..n {
            let v: f64 = (0..n).map(|l| w[(r, l)] * fbar[l]).sum();
            for b in 0..p {
                c[j * d + b * n + r] = v;
            }
        }
    }
    let mut hm = vec![0.0; m * d];
    let mut gamma = vec![0.0; d * m];
    let mut compliance = vec![0.0; m];
    let mut r = vec![0.0; k * m];
    for (ci, contact) in model.contacts.iter().enumerate() {
        // Implicit (s = L) reads x_(j+L), y's first block; explicit (s = L − 1) reads
        // x_(j+L−1) = x_(j+L) − ∇x_(j+L), known before the step (Γ's blocks are equal: HΓ = 0).
        hm[ci * d + contact.dof] = -contact.direction;
        if offsets[ci] + 1 == lead {
            hm[ci * d + n + contact.dof] = contact.direction;
        }
        for row in 0..n {
            for b in 0..p {
                gamma[(b * n + row) * m + ci] = -w[(row, contact.dof)] * contact.direction;
            }
        }
        if let Compliance::Compliant { stiffness } = contact.compliance {
            compliance[ci] = 1.0 / stiffness;
        }
        for j in 0..k {
            r[j * m + ci] = contact.gap_at(model.frequency, ((j + offsets[ci]) % k) as f64 * h);
        }
    }
    StepMapLcp::new(StepMapData { k, d, m, phi, carry, c, h: hm, gamma, compliance, r }).map_err(|e| NoStepMap(e.to_string()))
}

/// f(t_j) DOF by DOF (k×n), sampled as the assembly samples them.
fn force_samples(model: &Model, k: usize, h: f64) -> Vec<f64> {
    let n = model.n();
    let mut f = vec![0.0; k * n];
    for j in 0..k {
        let t = j as f64 * h;
        for term in &model.forces {
            f[j * n + term.dof] += term.term.value(model.frequency, t);
        }
    }
    f
}
