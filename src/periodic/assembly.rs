//! Frequency-domain assembly (src/formulation.md §2–3): one complex n×n factorisation per distinct harmonic
//! p = 0..=k/2 of Ẑ_p = σ2_p M + σ1_p C + w_p K, never the kn×kn system.
//! From it: the receptance between contacts Ĝ_p = B Ẑ_p⁻¹ Bᵀ, the contact-free response
//! X̂lin_p = Ẑ_p⁻¹ w_p F̂_p, and Ẑ_p⁻¹ Bᵀ at the DOFs that are output.
use super::SolveError;
use super::fft::PeriodFft;
use crate::model::{Matrix, Model};
use crate::time::{Scheme, Symbols};
use faer::Mat;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::SymbolicLu;
use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};
use num_complex::Complex64 as C;

mod modal;
pub use modal::ModalProducts;
use modal::assemble_modal;

/// Pivot ratio below which Ẑ_p counts as singular (undamped resonance, rigid-body mode).
const SINGULAR_PIVOT_RATIO: f64 = 1e-13;

/// Everything the LCP and the recovery need, per harmonic.
#[derive(Clone, Debug)]
pub struct Assembly {
    pub k: usize,
    /// Number of contacts m.
    pub m: usize,
    /// Labels of the recovered outputs, in row order of `xlin_hat` and `h_hat` (model DOFs,
    /// or the output map's labels: each row is its combination of model DOFs, [`RecoveryRow`]).
    pub dofs: Vec<usize>,
    pub symbols: Symbols,
    /// Ĝ_p, row-major m×m, for p = 0..=k/2; shared with the LCP's spectrum where that needs no
    /// change (`PeriodicProblem::lcp`: a 4.7 MB copy per solve at k = 2048, issue 23).
    pub g_hat: std::sync::Arc<Vec<C>>,
    /// X̂lin_p at `dofs`: [p][dofs.len()].
    pub xlin_hat: Vec<C>,
    /// B X̂lin_p: [p][m].
    pub bxlin_hat: Vec<C>,
    /// Ẑ_p⁻¹ Bᵀ at `dofs`: [p][dofs.len()][m].
    pub h_hat: Vec<C>,
    /// The rubbing contacts' tangential rows, folded into the contacts' columns (`rubbing.rs`).
    pub tangential: Vec<super::TangentialRow>,
}

/// Samples of the external force at the k instants of `period`, DOF by DOF, only for loaded DOFs.
fn force_spectra(model: &Model, period: f64, fft: &PeriodFft) -> Vec<(usize, Vec<C>)> {
    let k = fft.k();
    let mut dofs: Vec<usize> = model.forces.iter().map(|f| f.dof).collect();
    dofs.sort_unstable();
    dofs.dedup();
    dofs.into_iter()
        .map(|d| {
            let samples: Vec<f64> = (0..k)
                .map(|j| {
                    let t = j as f64 * period / k as f64;
                    model.forces.iter().filter(|f| f.dof == d).map(|f| f.term.value(model.frequency, t)).sum()
                })
                .collect();
            (d, fft.forward(&samples))
        })
        .collect()
}

/// Ẑ_p = σ2 M + σ1 C + w K, factorised per harmonic: dense LU, or sparse LU on the union
/// pattern of M, C, K with one symbolic analysis shared by every harmonic; or, for a dense model
/// whose damping is diagonal in its modes (none, Rayleigh, modal ratios: a reduced model),
/// Ẑ_p⁻¹ = Φ diag(1/(σ2 + σ1 c_i + w ω_i²)) Φᵀ from one eigen-decomposition: O(n²) per harmonic.
enum Operator {
    Dense {
        mass: Mat<f64>,
        stiffness: Mat<f64>,
        damping: Option<Mat<f64>>,
    },
    /// `residual`: with massless DOFs (a massless-boundary reduction), the static flexibility the
    /// massive modes miss, R = K⁻¹ − Φ Λ⁻¹ Φᵀ, and Ẑ_p⁻¹ = Φ D_p Φᵀ + R / w_p.
    Modal {
        phi: Mat<f64>,
        lambda: Vec<f64>,
        c: Vec<f64>,
        residual: Option<Mat<f64>>,
    },
    Sparse {
        symbolic: SymbolicLu<usize>,
        pattern: SymbolicSparseColMat<usize>,
        mass: Vec<f64>,
        stiffness: Vec<f64>,
        damping: Vec<f64>,
    },
}

impl Operator {
    fn new(model: &Model) -> Result<Self, SolveError> {
        let s = &model.structure;
        let sparse = s.mass.is_sparse() || s.stiffness.is_sparse() || s.damping.as_ref().is_some_and(Matrix::is_sparse);
        if !sparse {
            if let Some(op) = Operator::modal(s) {
                return Ok(op);
            }
            return Ok(Operator::Dense { mass: s.mass.to_dense(), stiffness: s.stiffness.to_dense(), damping: s.damping.as_ref().map(Matrix::to_dense) });
        }
        let n = model.n();
        let mut triplets = Vec::new();
        for a in [Some(&s.mass), Some(&s.stiffness), s.damping.as_ref()].into_iter().flatten() {
            a.for_each(|i, j, _| triplets.push(Triplet::new(i, j, 0.0)));
        }
        let union = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets).map_err(|e| SolveError::Invalid(format!("sparse pattern: {e:?}")))?;
        let pattern = union.symbolic().to_owned().map_err(|e| SolveError::Invalid(format!("sparse pattern: {e:?}")))?;
        // Values of one matrix laid out on the union pattern.
        let values = |a: Option<&Matrix>| {
            let mut v = vec![0.0; pattern.compute_nnz()];
            if let Some(a) = a {
                a.for_each(|i, j, x| {
                    let start = pattern.col_ptr()[j];
                    let rows = &pattern.row_idx()[start..pattern.col_ptr()[j + 1]];
                    if let Ok(pos) = rows.binary_search(&i) {
                        v[start + pos] += x;
                    }
                });
            }
            v
        };
        let (mass, stiffness, damping) = (values(Some(&s.mass)), values(Some(&s.stiffness)), values(s.damping.as_ref()));
        let symbolic = SymbolicLu::try_new(pattern.as_ref()).map_err(|e| SolveError::Invalid(format!("sparse LU analysis failed: {e:?}")))?;
        Ok(Operator::Sparse { symbolic, pattern, mass, stiffness, damping })
    }

    /// The modal form of a dense structure, if it has at least [`MODAL_MIN_DOFS`] DOFs and its
    /// damping is diagonal in the undamped modes (to 1e-9 of the largest modal damping).
    fn modal(s: &crate::model::Structure) -> Option<Operator> {
        let n = s.n();
        if n < MODAL_MIN_DOFS {
            return None;
        }
        let (mass, stiffness) = (s.mass.to_dense(), s.stiffness.to_dense());
        // Massless DOFs (zero rows of M after validation): only the r = n − #massless massive
        // modes exist; the rest of Ẑ_p⁻¹ is the static residual flexibility.
        let massless = (0..n).filter(|&d| s.mass.get(d, d) <= 0.0).count();
        let r = n - massless;
        let modes = crate::reduction::dense_modes(stiffness.as_ref(), mass.as_ref(), r).ok()?;
        if modes.omega.len() != r || modes.residual.iter().any(|e| !(*e < 1e-8)) {
            return None;
        }
        let phi = modes.shapes;
        let lambda: Vec<f64> = modes.omega.iter().map(|w| w * w).collect();
        let c = match &s.damping {
            None => vec![0.0; r],
            Some(c) => {
                let c = c.to_dense();
                let d = phi.transpose() * &c * &phi;
                let scale = (0..r).map(|i| d[(i, i)].abs()).fold(0.0, f64::max);
                let off = (0..r).flat_map(|i| (0..r).map(move |j| (i, j))).filter(|(i, j)| i != j).map(|(i, j)| d[(i, j)].abs()).fold(0.0, f64::max);
                if !(off <= 1e-9 * scale) {
                    return None;
                }
                let diag: Vec<f64> = (0..r).map(|i| d[(i, i)]).collect();
                // With massless DOFs the modes do not span the space: C must be M Φ diag(c) Φᵀ M
                // (no damping on the massless DOFs), else the modal form would drop part of it.
                if massless > 0 {
                    let mphi = &mass * &phi;
                    let rebuilt = &mphi * Mat::<f64>::from_fn(r, r, |i, j| if i == j { diag[i] } else { 0.0 }) * mphi.transpose();
                    let big = (0..n).flat_map(|j| (0..n).map(move |i| (i, j))).fold(0.0f64, |a, (i, j)| a.max(c[(i, j)].abs()));
                    let miss = (0..n).flat_map(|j| (0..n).map(move |i| (i, j))).fold(0.0f64, |a, (i, j)| a.max((c[(i, j)] - rebuilt[(i, j)]).abs()));
                    if !(miss <= 1e-9 * big) {
                        return None;
                    }
                }
                diag
            }
        };
        let residual = if massless > 0 { Some(Operator::residual_flexibility(&stiffness, &phi, &lambda)?) } else { None };
        Some(Operator::Modal { phi, lambda, c, residual })
    }

    /// R = K⁻¹ − Φ Λ⁻¹ Φᵀ (MacNeal's residual flexibility, src/formulation.md §4.1): the part of
    /// Ẑ_p⁻¹ the massive modes miss, static (1/w_p) on a massless DOF. `None` if K is singular.
    fn residual_flexibility(stiffness: &Mat<f64>, phi: &Mat<f64>, lambda: &[f64]) -> Option<Mat<f64>> {
        let n = stiffness.nrows();
        let llt = stiffness.llt(faer::Side::Lower).ok()?;
        let kinv = llt.solve(Mat::<f64>::identity(n, n));
        let scaled = Mat::<f64>::from_fn(n, phi.ncols(), |i, j| phi[(i, j)] / lambda[j]);
        let r = kinv - &scaled * phi.transpose();
        let finite = (0..n).all(|j| (0..n).all(|i| r[(i, j)].is_finite()));
        finite.then(|| Mat::from_fn(n, n, |i, j| 0.5 * (r[(i, j)] + r[(j, i)])))
    }

    /// Solves Ẑ_p Y = rhs for one harmonic.
    fn solve(&self, p: usize, s2: C, s1: C, w: f64, omega: f64, rhs: &Mat<C>) -> Result<Mat<C>, SolveError> {
        let singular = SolveError::SingularOperator { harmonic: p, frequency: p as f64 * omega };
        // Not singular but beyond floating point: say so rather than "singular".
        let overflow = || {
            SolveError::Invalid(format!(
                "the dynamic operator σ2·M + σ1·C + w·K overflows at harmonic {p} (excitation.frequency = {omega:e} rad/s): the matrices, the frequency or steps are too large for floating point; rescale the units"
            ))
        };
        let y = match self {
            Operator::Dense { mass, stiffness, damping } => {
                let n = mass.nrows();
                let z = Mat::from_fn(n, n, |i, j| {
                    let c = damping.as_ref().map_or(0.0, |c| c[(i, j)]);
                    s2 * mass[(i, j)] + s1 * c + C::from(w * stiffness[(i, j)])
                });
                if !(0..n).all(|j| (0..n).all(|i| z[(i, j)].re.is_finite() && z[(i, j)].im.is_finite())) {
                    return Err(overflow());
                }
                // The size of the terms that sum to Ẑ_p: a pivot at round-off of them is a zero
                // (a 1-DOF Ẑ_p has one pivot, so a ratio among pivots alone cannot see it).
                let big = |m: &Mat<f64>| (0..n).flat_map(|j| (0..n).map(move |i| (i, j))).fold(0.0f64, |a, (i, j)| a.max(m[(i, j)].abs()));
                let terms = s2.norm() * big(mass) + s1.norm() * damping.as_ref().map_or(0.0, big) + w.abs() * big(stiffness);
                let lu = z.partial_piv_lu();
                check_pivots(lu.U(), terms).map_err(|_| singular.clone())?;
                lu.solve(rhs)
            }
            Operator::Modal { .. } => unreachable!("a modal operator is assembled in one batch (assemble_modal)"),
            Operator::Sparse { symbolic, pattern, mass, stiffness, damping } => {
                let vals: Vec<C> = (0..mass.len()).map(|e| s2 * mass[e] + s1 * damping[e] + C::from(w * stiffness[e])).collect();
                if !vals.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
                    return Err(overflow());
                }
                let z = SparseColMat::<usize, C>::new(pattern.clone(), vals);
                let lu = faer::sparse::linalg::solvers::Lu::try_new_with_symbolic(symbolic.clone(), z.as_ref()).map_err(|_| singular.clone())?;
                lu.solve(rhs)
            }
        };
        let finite = (0..y.ncols()).all(|j| (0..y.nrows()).all(|i| y[(i, j)].re.is_finite() && y[(i, j)].im.is_finite()));
        if finite { Ok(y) } else { Err(singular) }
    }
}

/// A recovered output: its label and its (model DOF, coefficient) terms. Why combinations: a
/// reduced model's physical output mixes every reduced DOF (69 on the real blade), and the
/// assembly at the 5 outputs instead of at the 69 DOFs is 14× smaller (issue 23).
pub type RecoveryRow = (usize, Vec<(usize, f64)>);

/// Each DOF as its own row (no output map).
pub fn unit_rows(dofs: &[usize]) -> Vec<RecoveryRow> {
    dofs.iter().map(|&d| (d, vec![(d, 1.0)])).collect()
}

/// Σ c·value(d) over a row's terms (a unit row gives value(d) exactly).
fn along_row<T: Copy + Default + std::ops::Add<Output = T> + std::ops::Mul<f64, Output = T>>(terms: &[(usize, f64)], value: impl Fn(usize) -> T) -> T {
    terms.iter().fold(T::default(), |acc, &(d, c)| acc + value(d) * c)
}

/// What one harmonic contributes.
struct HarmonicBlock {
    g: Vec<C>,
    bx: Vec<C>,
    xl: Vec<C>,
    h: Vec<C>,
}

/// Assembles Ĝ, X̂lin and Ẑ⁻¹Bᵀ at `dofs` for every distinct harmonic of the grid of `fft`
/// (k instants over `period`: T, or p·T for an orbit of p forcing periods).
/// `parallel`: spread the harmonics over rayon's threads (never from inside an FMU).
pub fn assemble(model: &Model, scheme: Scheme, period: f64, dofs: &[usize], fft: &PeriodFft, parallel: bool) -> Result<Assembly, SolveError> {
    assemble_with(model, &StructureOperator::new(model)?, scheme, period, &unit_rows(dofs), fft, parallel, &mut ModalProducts::default())
}

/// The ω-independent part of the assembly, built once per structure (M, C, K) and reused at every
/// frequency and grid: the modes and MacNeal's residual flexibility of a modal model, the dense
/// matrices, or the sparse LU's symbolic analysis. Per ω only the diagonal D_p (or the numeric
/// factorisations of a non-modal model) is redone, as Clarabel updates data instead of rebuilding.
pub struct StructureOperator(Operator);

impl StructureOperator {
    pub fn new(model: &Model) -> Result<Self, SolveError> {
        Operator::new(model).map(StructureOperator)
    }
}

impl std::fmt::Debug for StructureOperator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let form = match &self.0 {
            Operator::Dense { .. } => "dense",
            Operator::Modal { .. } => "modal",
            Operator::Sparse { .. } => "sparse",
        };
        write!(f, "StructureOperator({form})")
    }
}

/// [`assemble`] on a structure operator built before (by [`StructureOperator::new`] on a model
/// with the same M, C and K; the contacts, forces and frequency are `model`'s), recovering `rows`,
/// the modal products into a session's `products`.
#[allow(clippy::too_many_arguments)]
pub(super) fn assemble_with(
    model: &Model,
    op: &StructureOperator,
    scheme: Scheme,
    period: f64,
    rows: &[RecoveryRow],
    fft: &PeriodFft,
    parallel: bool,
    products: &mut ModalProducts,
) -> Result<Assembly, SolveError> {
    let op = &op.0;
    let k = fft.k();
    let n = model.n();
    let m = model.contacts.len();
    let nh = k / 2 + 1;
    let symbols = scheme.symbols(k, period);
    let forces = force_spectra(model, period, fft);
    // Finite amplitudes can still sum past f64 (two forces of 1e308 on one DOF): say so, rather
    // than let the NaN surface as a "singular operator".
    if let Some((d, _)) = forces.iter().find(|(_, s)| !s.iter().all(|c| c.re.is_finite() && c.im.is_finite())) {
        return Err(SolveError::Invalid(format!(
            "force: the samples of the force on DOF {d} overflow floating point (amplitudes too large); rescale the units"
        )));
    }
    if let Operator::Modal { phi, lambda, c, residual } = op {
        let statics = residual.as_ref().map(|r| Statics::new(model, &forces, rows, r));
        let mut asm = assemble_modal(model, symbols, &forces, rows, (phi, lambda, c), statics.as_ref(), k, products)?;
        if let Some(st) = &statics {
            st.add_forced(&mut asm, &forces);
        }
        return Ok(asm);
    }
    let nd = rows.len();
    let one = |p: usize| -> Result<HarmonicBlock, SolveError> {
        let (s1, s2, w) = (symbols.sigma1[p], symbols.sigma2[p], symbols.weight[p]);
        // Right-hand sides: Bᵀ (m columns, B_iᵀ) then w_p F̂_p.
        let mut rhs = Mat::<C>::zeros(n, m + 1);
        for (i, c) in model.contacts.iter().enumerate() {
            for &(d, v) in &c.row {
                rhs[(d, i)] = C::from(v);
            }
        }
        for (d, spec) in &forces {
            rhs[(*d, m)] = spec[p] * w;
        }
        let y = op.solve(p, s2, s1, w, model.frequency, &rhs)?;
        let mut b = HarmonicBlock { g: vec![C::ZERO; m * m], bx: vec![C::ZERO; m], xl: vec![C::ZERO; nd], h: vec![C::ZERO; nd * m] };
        for (a, ca) in model.contacts.iter().enumerate() {
            for j in 0..m {
                b.g[a * m + j] = ca.along(|d| y[(d, j)]);
            }
            b.bx[a] = ca.along(|d| y[(d, m)]);
        }
        for (r, (_, terms)) in rows.iter().enumerate() {
            b.xl[r] = along_row(terms, |d| y[(d, m)]);
            for j in 0..m {
                b.h[r * m + j] = along_row(terms, |d| y[(d, j)]);
            }
        }
        Ok(b)
    };
    let blocks: Vec<HarmonicBlock> = if parallel && n >= PARALLEL_MIN_DOFS {
        use rayon::prelude::*;
        (0..nh).into_par_iter().map(one).collect::<Result<_, _>>()?
    } else {
        (0..nh).map(one).collect::<Result<_, _>>()?
    };
    let (mut g_hat, mut xlin_hat) = (Vec::with_capacity(nh * m * m), Vec::with_capacity(nh * nd));
    let (mut bxlin_hat, mut h_hat) = (Vec::with_capacity(nh * m), Vec::with_capacity(nh * nd * m));
    for b in blocks {
        g_hat.extend(b.g);
        bxlin_hat.extend(b.bx);
        xlin_hat.extend(b.xl);
        h_hat.extend(b.h);
    }
    Ok(Assembly { k, m, dofs: rows.iter().map(|r| r.0).collect(), symbols, g_hat: g_hat.into(), xlin_hat, bxlin_hat, h_hat, tangential: Vec::new() })
}

/// The residual flexibility's part R / w_p of Ẑ_p⁻¹ in a modal assembly, ω-independent but for
/// 1 / w_p: B R Bᵀ (added to Ĝ_p) and R_out Bᵀ (to Ẑ_p⁻¹Bᵀ) as [`assemble_modal`] stores each
/// harmonic, and R F̂_p (the right-hand side is w_p F̂_p) to X̂lin_p and B X̂lin_p ([`Statics::add_forced`]).
struct Statics {
    /// B R Bᵀ, m × m row-major (Ĝ_p's storage order).
    brbt: Vec<f64>,
    /// R_out Bᵀ, nd × m row-major (Ẑ_p⁻¹Bᵀ's).
    rbt_out: Vec<f64>,
    /// B R at each loaded DOF's column: the static response of the contacts to that force.
    brf: Vec<Vec<f64>>,
    /// The rows' R_out at each loaded DOF, nd × forces row-major.
    rf_out: Vec<f64>,
}

impl Statics {
    fn new(model: &Model, forces: &[(usize, Vec<C>)], rows: &[RecoveryRow], r: &Mat<f64>) -> Statics {
        let (m, nd, n) = (model.contacts.len(), rows.len(), r.nrows());
        let rbt = Mat::<f64>::from_fn(n, m, |d, b| model.contacts[b].along(|e| r[(d, e)]));
        let brbt = (0..m * m).map(|ab| model.contacts[ab / m].along(|d| rbt[(d, ab % m)])).collect();
        let brf = forces.iter().map(|(l, _)| (0..m).map(|a| model.contacts[a].along(|d| r[(d, *l)])).collect()).collect();
        let rrow = |row: usize, col: &dyn Fn(usize) -> f64| along_row(&rows[row].1, col);
        let rbt_out = (0..nd).flat_map(|row| (0..m).map(move |b| (row, b))).map(|(row, b)| rrow(row, &|d| rbt[(d, b)])).collect();
        let rf_out = (0..nd).flat_map(|row| forces.iter().map(move |(l, _)| (row, *l))).map(|(row, l)| rrow(row, &|d| r[(d, l)])).collect();
        Statics { brbt, rbt_out, brf, rf_out }
    }

    /// Adds R F̂_p to X̂lin_p and B R F̂_p to B X̂lin_p.
    fn add_forced(&self, asm: &mut Assembly, forces: &[(usize, Vec<C>)]) {
        let (m, nd, nh) = (asm.m, asm.dofs.len(), asm.k / 2 + 1);
        for p in 0..nh {
            for row in 0..nd {
                for (l, (_, spec)) in forces.iter().enumerate() {
                    asm.xlin_hat[p * nd + row] += spec[p] * self.rf_out[row * forces.len() + l];
                }
            }
            for (l, (_, spec)) in forces.iter().enumerate() {
                for a in 0..m {
                    asm.bxlin_hat[p * m + a] += spec[p] * self.brf[l][a];
                }
            }
        }
    }
}

/// From this many DOFs a dense model with modal damping is solved in its modes.
const MODAL_MIN_DOFS: usize = 16;

/// Below this many DOFs one factorisation is too cheap to be worth a thread.
const PARALLEL_MIN_DOFS: usize = 64;

fn check_pivots(u: faer::MatRef<'_, C>, terms: f64) -> Result<(), ()> {
    let n = u.nrows();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for i in 0..n {
        let v = u[(i, i)].norm();
        lo = lo.min(v);
        hi = hi.max(v);
    }
    // NaN-safe: `!(lo > …)` is true for NaN.
    if !(lo > SINGULAR_PIVOT_RATIO * hi.max(terms)) {
        return Err(());
    }
    Ok(())
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::model::{Compliance, Contact, Force, Harmonic, Structure};

    /// A 20-DOF spring chain whose first 4 DOFs are massless (a massless-boundary model), mass-
    /// proportional damping, contacts on massless and massive DOFs, forces on both.
    pub(crate) fn chain_with_massless_boundary() -> Model {
        let n = 20;
        let massless = 4;
        let stiffness = |i: usize| 1.0e4 * (1.0 + 0.3 * i as f64);
        let mut k = vec![vec![0.0; n]; n];
        for i in 0..n {
            // Spring i joins DOF i to DOF i − 1 (DOF 0 to the ground); a light spring to the ground too.
            k[i][i] += stiffness(i) + 50.0;
            if i > 0 {
                k[i - 1][i - 1] += stiffness(i);
                k[i][i - 1] -= stiffness(i);
                k[i - 1][i] -= stiffness(i);
            }
        }
        let mass: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| if i == j && i >= massless { 1.0 + 0.1 * i as f64 } else { 0.0 }).collect()).collect();
        let damping: Vec<Vec<f64>> = mass.iter().map(|row| row.iter().map(|v| 0.8 * v).collect()).collect();
        let harmonic = |amplitude, harmonic| Harmonic { amplitude, harmonic, phase: 0.3 };
        Model {
            structure: Structure { mass: Matrix::from_rows(&mass), stiffness: Matrix::from_rows(&k), damping: Some(Matrix::from_rows(&damping)) },
            forces: vec![Force { dof: 12, term: harmonic(3.0, 1) }, Force { dof: 2, term: harmonic(0.5, 2) }],
            contacts: vec![
                Contact::on_dof(0, 1.0, 1e-3, Compliance::Rigid),
                Contact::on_dof(3, -1.0, 1e-3, Compliance::Rigid),
                Contact::on_dof(7, 1.0, 1e-3, Compliance::Rigid),
            ],
            frequency: 37.0,
            frictions: Vec::new(),
            rubbing: Vec::new(),
        }
    }

    #[test]
    fn modal_assembly_with_massless_dofs_equals_the_dense_factorisation() {
        let model = chain_with_massless_boundary();
        let op = Operator::new(&model).unwrap();
        assert!(matches!(op, Operator::Modal { residual: Some(_), .. }), "a massless-boundary model is solved in its modes plus the residual flexibility");
        let (k, period) = (32, 2.0 * std::f64::consts::PI / model.frequency);
        let fft = PeriodFft::new(k);
        let dofs = [1, 3, 9, 12];
        let asm = assemble(&model, Scheme::Cds, period, &dofs, &fft, false).unwrap();
        // Reference: Ẑ_p factorised by dense LU at every harmonic, the right-hand sides Bᵀ and w_p F̂_p.
        let s = &model.structure;
        let dense = Operator::Dense { mass: s.mass.to_dense(), stiffness: s.stiffness.to_dense(), damping: s.damping.as_ref().map(Matrix::to_dense) };
        let forces = force_spectra(&model, period, &fft);
        let (n, m, nd) = (model.n(), model.contacts.len(), dofs.len());
        let mut worst = 0.0f64;
        for p in 0..=k / 2 {
            let (s1, s2, w) = (asm.symbols.sigma1[p], asm.symbols.sigma2[p], asm.symbols.weight[p]);
            let rhs = Mat::<C>::from_fn(n, m + 1, |d, j| match j {
                j if j < m => C::from(model.contacts[j].along(|e| if e == d { 1.0 } else { 0.0 })),
                _ => forces.iter().filter(|(l, _)| *l == d).map(|(_, f)| f[p] * w).sum(),
            });
            let y = dense.solve(p, s2, s1, w, model.frequency, &rhs).unwrap();
            let scale = (0..n).flat_map(|i| (0..=m).map(move |j| (i, j))).fold(0.0f64, |a, (i, j)| a.max(y[(i, j)].norm()));
            for a in 0..m {
                for b in 0..m {
                    worst = worst.max((asm.g_hat[(p * m + a) * m + b] - model.contacts[a].along(|d| y[(d, b)])).norm() / scale);
                }
                worst = worst.max((asm.bxlin_hat[p * m + a] - model.contacts[a].along(|d| y[(d, m)])).norm() / scale);
            }
            for (r, &d) in dofs.iter().enumerate() {
                worst = worst.max((asm.xlin_hat[p * nd + r] - y[(d, m)]).norm() / scale);
                for b in 0..m {
                    worst = worst.max((asm.h_hat[(p * nd + r) * m + b] - y[(d, b)]).norm() / scale);
                }
            }
        }
        println!("modal + residual flexibility against dense LU: worst relative difference {worst:.2e}");
        assert!(worst < 1e-9, "worst relative difference {worst:e}");
    }
}
