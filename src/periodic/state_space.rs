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
//! Γ = (−W Eᵀ, …, −W Eᵀ), E the contacts' force rows (E = B but for rubbing contacts, whose force
//! row is n − μ·sign(V)·t, src/formulation.md §9: S is then non-symmetric). Contact c is paired with the gap at t_{j+s} (s its pairing offset):
//! - s = L (cds/galerkin forward, bds same): w = gap_c(t_{j+L}) − B_c x_{j+L} + z/k_c, read in
//!   y's first block after the step: implicit, S_cc = B_c W B_cᵀ + 1/k_c;
//! - s = L − 1 (cds/galerkin same): w = gap_c(t_j) − B_c x_j + z/k_c, x_j = y's first block minus
//!   its second, known before the step: explicit, S_cc = 1/k_c, so only a compliant contact has
//!   one answer per step;
//! - s > L (bds forward): the force is paired with a later step's gap, not a step map.
//!
//! **Massless DOFs** b (a zero row of M and C; src/formulation.md §4.1) have no dynamics of their
//! own: when K enters the scheme at one instant only (a0 = e_(i*): cds, bds1, bds2), their rows
//! read K_b· x_(j+L−i*) + B_bᵀ z_j = f_(j,b), so x_b = K_bb⁻¹(f_b − K_ba x_a − B_bᵀ z) at that
//! instant, and the march advances the massive DOFs a alone, with K̃ = K_aa − K_ab K_bb⁻¹ K_ba,
//! f̃ = f_a − K_ab K_bb⁻¹ f_b and contact rows B̃ = B_a − B_b K_bb⁻¹ K_ba. A contact on massless
//! DOFs reads that same instant (pairing offset L − i* = 0: same), with the static flexibility
//! D = B_b K_bb⁻¹ B_bᵀ added to S = HΓ + D and −B_b K_bb⁻¹ f_b to r_j. Galerkin weighs K over three
//! instants, (1, 4, 1)/6: a massless DOF then couples the whole period and has no step map.
//!
//! Fourier collocation is not a time stepper. The map is dense in d = p·n (reduced models: its
//! memory is O(d² + k·(d + m)), checked with the LCP's before solving).
use super::PeriodicProblem;
use crate::lcp::{DenseLu, GIB, StepMapData, StepMapLcp, dense_product};
use crate::model::{Compliance, Model};
use crate::time::Scheme;
use faer::Mat;
use faer::linalg::solvers::Solve;

/// The most memory the shooting solver may take for a step map ([`shooting_memory`]).
pub const SHOOTING_MEMORY_MAX: f64 = 4.0 * GIB;

/// The most work one Newton iteration of shooting may cost at the least ([`shooting_work`]):
/// about a minute on one core.
pub const SHOOTING_WORK_MAX: f64 = 1e12;

/// Bytes the shooting solver holds for a step map of state size d over k steps with m pairs: the
/// augmented Φ's powers (log₂ k + 1 of them) and a few more (d+1)² matrices (a run's powers, the
/// Jacobian, Newton's LU), and the march's k·(d + 3m) (c_j, r_j, z_j and the sets).
pub fn shooting_memory(k: usize, d: usize, m: usize) -> f64 {
    let matrices = f64::from(usize::BITS - k.leading_zeros()) + 6.0;
    8.0 * (matrices * ((d + 1) as f64).powi(2) + k as f64 * (d + 3 * m) as f64)
}

/// Floating-point operations of one Newton iteration at the least: a march (k·d²) and the
/// contact-free Jacobian's log₂ k squarings of (d+1)² matrices (each run of one contact set
/// adds up to 2·log₂ k more).
pub fn shooting_work(k: usize, d: usize, m: usize) -> f64 {
    let squarings = f64::from(usize::BITS - k.leading_zeros());
    k as f64 * ((d * d) as f64 + 2.0 * (d * m) as f64) + squarings * 2.0 * ((d + 1) as f64).powi(3)
}

/// Why a problem has no step map (the solver then uses the LCP alone).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct NoStepMap(pub String);

/// Lead L and the coefficients a2·h², a1·h, a0 of a difference scheme.
pub(super) type Coefficients = (usize, Vec<f64>, Vec<f64>, Vec<f64>);

/// The coefficients of a difference scheme; `None` for fourier.
pub(super) fn coefficients(scheme: Scheme) -> Option<Coefficients> {
    Some(match scheme {
        Scheme::Cds => (1, vec![1.0, -2.0, 1.0], vec![0.5, 0.0, -0.5], vec![0.0, 1.0, 0.0]),
        Scheme::Galerkin => (1, vec![1.0, -2.0, 1.0], vec![0.5, 0.0, -0.5], vec![1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0]),
        Scheme::Bds1 => (0, vec![1.0, -2.0, 1.0], vec![1.0, -1.0, 0.0], vec![1.0, 0.0, 0.0]),
        Scheme::Bds2 => (0, vec![2.0, -5.0, 4.0, -1.0], vec![1.5, -2.0, 0.5, 0.0], vec![1.0, 0.0, 0.0, 0.0]),
        Scheme::Fourier => return None,
    })
}

/// A shooting answer's orbit state `state` (s_0, [`step_map`]'s state under `scheme`) on a grid of
/// `from` instants, carried to `to` instants over the same period: the difference ∇^b x scales as
/// h^b, so block b by (from/to)^b, and the newest instant (L − 1)·h moves with h, so x by
/// (L − 1)·(from/to − 1)·∇x (first order in h, as the carried active set is). A Newton start
/// for the same orbit on the other grid; `None` where the scheme has no step map or the state is
/// not of its shape.
pub fn carried_state(scheme: Scheme, state: &[f64], from: usize, to: usize) -> Option<Vec<f64>> {
    let (lead, a2, ..) = coefficients(scheme)?;
    let p = a2.len() - 1;
    if from == 0 || to == 0 || state.is_empty() || !state.len().is_multiple_of(p) {
        return None;
    }
    let (n, ratio) = (state.len() / p, from as f64 / to as f64);
    let mut carried: Vec<f64> = state.iter().enumerate().map(|(e, v)| v * ratio.powi((e / n) as i32)).collect();
    if p > 1 {
        let shift = (lead as f64 - 1.0) * (ratio - 1.0);
        (0..n).for_each(|r| carried[r] += shift * state[n + r]);
    }
    Some(carried)
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
        return Err(NoStepMap(
            "friction rows are stepped by their own map (src/periodic/friction_shooting.rs, friction alone), not the contacts' (src/formulation.md §9)"
                .to_string(),
        ));
    }
    let offsets: Vec<usize> = (0..m).map(|c| problem.pairing_at(c).offset()).collect();
    if let Some(c) = offsets.iter().position(|&s| s > lead) {
        return Err(NoStepMap(format!("contact[{c}] is paired forward under {}: its force waits for a later step's gap", disc.scheme)));
    }
    let p = a2.len() - 1;
    // Massless DOFs are condensed out of the state; the map is dense in the rest.
    let n = n - model.massless_dofs().len();
    let d = p * n;
    // Refuse it before building it when it cannot fit or run.
    let (bytes, work) = (shooting_memory(k, d, m), shooting_work(k, d, m));
    if bytes > SHOOTING_MEMORY_MAX || work > SHOOTING_WORK_MAX {
        return Err(NoStepMap(format!(
            "shooting on the step map of {n} DOFs with mass (state of d = {d}) over k = {k} steps needs ≈ {:.2} GiB (at most {:.0}) and ≈ {work:.1e} flops per Newton iteration (at most {SHOOTING_WORK_MAX:.0e}); reduce the model (Craig–Bampton) or steps",
            bytes / GIB,
            SHOOTING_MEMORY_MAX / GIB
        )));
    }
    let h = problem.period() / k as f64;
    let cond = Condensed::new(model, &a0, lead, &offsets)?;
    let (mass, stiffness, damping, n) = (&cond.mass, &cond.stiffness, &cond.damping, cond.massive.len());
    let d = p * n;
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
    let (forces, gap_shift) = cond.force_samples(model, k, h);
    let galerkin = disc.scheme == Scheme::Galerkin;
    let mut c = vec![0.0; k * d];
    let mut fbar = vec![0.0; n];
    // W row by row (the products below read rows), and no product at an unloaded instant (c_j
    // stays 0): the real blade's casing is its only excitation (issue 23).
    let w_rows: Vec<f64> = (0..n * n).map(|e| w[(e / n, e % n)]).collect();
    // No force: every c_j stays 0 without reading the k·n zero samples.
    for j in (0..k).filter(|_| !model.forces.is_empty()) {
        for (dof, f) in fbar.iter_mut().enumerate() {
            let at = |jj: usize| forces[jj * n + dof];
            *f = if galerkin { (at((j + 1) % k) + 4.0 * at(j) + at((j + k - 1) % k)) / 6.0 } else { at(j) };
        }
        if fbar.iter().all(|&f| f == 0.0) {
            continue;
        }
        for r in 0..n {
            let v: f64 = w_rows[r * n..(r + 1) * n].iter().zip(&fbar).map(|(w, f)| w * f).sum();
            for b in 0..p {
                c[j * d + b * n + r] = v;
            }
        }
    }
    let mut hm = vec![0.0; m * d];
    let mut gamma = vec![0.0; d * m];
    // D: the static flexibility of the massless DOFs plus each compliant contact's 1/k_c.
    let mut flexibility = cond.flexibility.clone();
    let mut r = vec![0.0; k * m];
    // The contacts' forces enter through Ẽᵀ (rubbing: Ẽ ≠ B̃, S non-symmetric), their gaps through B̃.
    let wb = dense_product(&w, &cond.force_rows.transpose().to_owned());
    let gaps = problem.gap_samples(k);
    for (ci, contact) in model.contacts.iter().enumerate() {
        // Implicit (s = L) reads x_(j+L), y's first block; explicit (s = L − 1) reads
        // x_(j+L−1) = x_(j+L) − ∇x_(j+L), known before the step (Γ's blocks are equal: HΓ = 0).
        for col in 0..n {
            hm[ci * d + col] = -cond.rows[(ci, col)];
            if offsets[ci] + 1 == lead {
                hm[ci * d + n + col] = cond.rows[(ci, col)];
            }
        }
        for row in 0..n {
            for b in 0..p {
                gamma[(b * n + row) * m + ci] = -wb[(row, ci)];
            }
        }
        if let Compliance::Compliant { stiffness } = contact.compliance {
            flexibility[ci * m + ci] += 1.0 / stiffness;
        }
        let gap = &gaps[ci];
        for j in 0..k {
            let at = (j + offsets[ci]) % k;
            r[j * m + ci] = gap[at] + gap_shift[at * m + ci];
        }
    }
    StepMapLcp::new(StepMapData { k, d, m, phi, carry, c, h: hm, gamma, flexibility, r }).map_err(|e| NoStepMap(e.to_string()))
}

/// The model the march advances: the massive DOFs, with the massless ones condensed statically
/// (see the module documentation). Without massless DOFs: the model itself, B̃ = B, D = 0.
struct Condensed {
    /// The massive DOFs a (model numbering).
    massive: Vec<usize>,
    mass: Mat<f64>,
    stiffness: Mat<f64>,
    damping: Option<Mat<f64>>,
    /// B̃, m × n_a (the model's sign: w = gap − B x).
    rows: Mat<f64>,
    /// Ẽ, m × n_a: the rows through which the contacts' forces act, −Ẽᵀz. Ẽ = B̃ but for
    /// rubbing contacts, whose force row is n − μ·sign(V)·t (src/formulation.md §9).
    force_rows: Mat<f64>,
    /// D = B_b K_bb⁻¹ E_bᵀ, m×m row-major.
    flexibility: Vec<f64>,
    /// The massless DOFs b and −K_bb⁻¹ K_ba (n_b × n_a), K_bb⁻¹ (n_b × n_b).
    massless: Vec<usize>,
    k_bb_inv: Mat<f64>,
}

impl Condensed {
    fn new(model: &Model, a0: &[f64], lead: usize, offsets: &[usize]) -> Result<Condensed, NoStepMap> {
        let (n, m) = (model.n(), model.contacts.len());
        let s = &model.structure;
        let massless = model.massless_dofs();
        let massive: Vec<usize> = (0..n).filter(|d| massless.binary_search(d).is_err()).collect();
        let mut full_rows = Mat::zeros(m, n);
        for (c, contact) in model.contacts.iter().enumerate() {
            for &(dof, v) in &contact.row {
                full_rows[(c, dof)] = v;
            }
        }
        let full_force_rows = force_rows(model, &full_rows);
        let dense = |a: &crate::model::Matrix, r: &[usize], c: &[usize]| a.block(r, c).to_dense();
        let damping = s.damping.as_ref().map(|c| dense(c, &massive, &massive));
        if massless.is_empty() {
            let (mass, stiffness) = (s.mass.to_dense(), s.stiffness.to_dense());
            let (rows, force_rows) = (full_rows, full_force_rows);
            return Ok(Condensed { massive, mass, stiffness, damping, rows, force_rows, flexibility: vec![0.0; m * m], massless, k_bb_inv: Mat::zeros(0, 0) });
        }
        let nonzero: Vec<usize> = (0..a0.len()).filter(|&i| a0[i] != 0.0).collect();
        let &[star] = nonzero.as_slice() else {
            return Err(NoStepMap(format!(
                "DOFs {massless:?} are massless and the scheme weighs K over {} instants: a massless DOF then couples the whole period (no step map; the periodic LCP solves it)",
                nonzero.len()
            )));
        };
        if let Some(&b) = s.damping.as_ref().and_then(|c| massless.iter().find(|&&b| (0..n).any(|j| c.get(b, j) != 0.0))) {
            return Err(NoStepMap(format!("massless DOF {b} carries damping: it is not quasi-static (no step map)")));
        }
        if let Some(c) = (0..m).find(|&c| model.contact_is_massless(&model.contacts[c]) && offsets[c] + star != lead) {
            return Err(NoStepMap(format!(
                "contact[{c}] acts on a massless DOF and is paired forward: its gap at the next instant depends on the next force (use pairing = \"same\")"
            )));
        }
        let k_bb = dense(&s.stiffness, &massless, &massless);
        let llt = k_bb.llt(faer::Side::Lower).map_err(|_| NoStepMap(format!("K is not positive definite on the massless DOFs {massless:?}")))?;
        let mut k_bb_inv = Mat::<f64>::identity(massless.len(), massless.len());
        llt.solve_in_place(k_bb_inv.as_mut());
        let k_ba = dense(&s.stiffness, &massless, &massive);
        let x_b = -(&k_bb_inv * &k_ba); // x_b = −K_bb⁻¹ K_ba x_a (+ force and contact terms)
        let stiffness = dense(&s.stiffness, &massive, &massive) + k_ba.transpose() * &x_b;
        let split = |full: &Mat<f64>, dofs: &[usize]| Mat::from_fn(m, dofs.len(), |c, j| full[(c, dofs[j])]);
        let (b_a, b_b) = (split(&full_rows, &massive), split(&full_rows, &massless));
        let (e_a, e_b) = (split(&full_force_rows, &massive), split(&full_force_rows, &massless));
        let rows = &b_a + &b_b * &x_b;
        // The force −E_bᵀz on the massless DOFs moves them by −K_bb⁻¹E_bᵀz: on the massive ones −(E_a − E_b K_bb⁻¹ K_ba)ᵀz (K symmetric).
        let force_rows = &e_a + &e_b * &x_b;
        let dmat = &b_b * &k_bb_inv * e_b.transpose();
        let flexibility = (0..m * m).map(|e| dmat[(e / m, e % m)]).collect();
        let mass = dense(&s.mass, &massive, &massive);
        Ok(Condensed { massive, mass, stiffness, damping, rows, force_rows, flexibility, massless, k_bb_inv })
    }

    /// f̃(t_j) on the massive DOFs (k × n_a) and the gap shift −B_b K_bb⁻¹ f_b(t_j) (k × m).
    fn force_samples(&self, model: &Model, k: usize, h: f64) -> (Vec<f64>, Vec<f64>) {
        let (n, m, na, nb) = (model.n(), model.contacts.len(), self.massive.len(), self.massless.len());
        let mut f = vec![0.0; k * na];
        let mut shift = vec![0.0; k * m];
        // No force, no samples to read (the real blade's casing is its only excitation, issue 23).
        if model.forces.is_empty() {
            return (f, shift);
        }
        let full = force_samples(model, k, h);
        for j in 0..k {
            let row = &full[j * n..(j + 1) * n];
            for (i, &a) in self.massive.iter().enumerate() {
                f[j * na + i] = row[a];
            }
            if nb == 0 || self.massless.iter().all(|&b| row[b] == 0.0) {
                continue;
            }
            // x_b⁰ = K_bb⁻¹ f_b: the massless DOFs' static share of the load.
            let xb: Vec<f64> = (0..nb).map(|i| (0..nb).map(|l| self.k_bb_inv[(i, l)] * row[self.massless[l]]).sum()).collect();
            for (i, &a) in self.massive.iter().enumerate() {
                f[j * na + i] -= (0..nb).map(|l| model.structure.stiffness.get(a, self.massless[l]) * xb[l]).sum::<f64>();
            }
            for (c, contact) in model.contacts.iter().enumerate() {
                // The massless DOFs' static displacement moves the clearance: −B_b x_b⁰.
                shift[j * m + c] = -contact.along(|dof| self.massless.binary_search(&dof).map_or(0.0, |l| xb[l]));
            }
        }
        (f, shift)
    }
}

/// E (m×n): the contacts' force rows, B plus −μ·sign(V)·t on each rubbing contact's row
/// (src/formulation.md §9; `rubbing.rs` folds the same term into the LCP's columns).
fn force_rows(model: &Model, rows: &Mat<f64>) -> Mat<f64> {
    let mut e = rows.clone();
    for r in &model.rubbing {
        for &(dof, v) in &r.row {
            e[(r.contact, dof)] += r.traction() * v;
        }
    }
    e
}

/// f(t_j) DOF by DOF (k×n), sampled as the assembly samples them.
pub(super) fn force_samples(model: &Model, k: usize, h: f64) -> Vec<f64> {
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
