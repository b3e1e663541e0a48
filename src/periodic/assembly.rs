//! Frequency-domain assembly (notes §2–3): one complex n×n factorisation per distinct harmonic
//! p = 0..=k/2 of Ẑ_p = σ2_p M + σ1_p C + w_p K, never the kn×kn system.
//! From it: the receptance between contacts Ĝ_p = B Ẑ_p⁻¹ Bᵀ, the contact-free response
//! X̂lin_p = Ẑ_p⁻¹ w_p F̂_p, and Ẑ_p⁻¹ Bᵀ at the DOFs that are output.
use super::fft::PeriodFft;
use super::SolveError;
use crate::model::{Matrix, Model};
use crate::time::{Discretization, Symbols};
use faer::Mat;
use faer::linalg::solvers::Solve;
use num_complex::Complex64 as C;

/// Pivot ratio below which Ẑ_p counts as singular (undamped resonance, rigid-body mode).
const SINGULAR_PIVOT_RATIO: f64 = 1e-13;

/// Everything the LCP and the recovery need, per harmonic.
#[derive(Clone, Debug)]
pub struct Assembly {
    pub k: usize,
    /// Number of contacts m.
    pub m: usize,
    /// DOFs at which responses are recovered (sorted, unique).
    pub dofs: Vec<usize>,
    pub symbols: Symbols,
    /// Ĝ_p, row-major m×m, for p = 0..=k/2.
    pub g_hat: Vec<C>,
    /// X̂lin_p at `dofs`: [p][dofs.len()].
    pub xlin_hat: Vec<C>,
    /// B X̂lin_p: [p][m].
    pub bxlin_hat: Vec<C>,
    /// Ẑ_p⁻¹ Bᵀ at `dofs`: [p][dofs.len()][m].
    pub h_hat: Vec<C>,
}

/// Samples of the external force at the k instants, DOF by DOF, only for loaded DOFs.
fn force_spectra(model: &Model, fft: &PeriodFft) -> Vec<(usize, Vec<C>)> {
    let k = fft.k();
    let period = model.period();
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

/// The dense matrices as complex-ready real copies.
struct DenseOperator {
    mass: Mat<f64>,
    stiffness: Mat<f64>,
    damping: Option<Mat<f64>>,
}

impl DenseOperator {
    fn new(model: &Model) -> Self {
        let s = &model.structure;
        DenseOperator { mass: s.mass.to_dense(), stiffness: s.stiffness.to_dense(), damping: s.damping.as_ref().map(Matrix::to_dense) }
    }
    fn z(&self, s2: C, s1: C, w: f64) -> Mat<C> {
        let n = self.mass.nrows();
        Mat::from_fn(n, n, |i, j| {
            let c = self.damping.as_ref().map_or(0.0, |c| c[(i, j)]);
            s2 * self.mass[(i, j)] + s1 * c + C::from(w * self.stiffness[(i, j)])
        })
    }
}

/// Assembles Ĝ, X̂lin and Ẑ⁻¹Bᵀ at `dofs` for every distinct harmonic.
pub fn assemble(model: &Model, disc: &Discretization, dofs: &[usize], fft: &PeriodFft) -> Result<Assembly, SolveError> {
    let k = disc.steps;
    let n = model.n();
    let m = model.contacts.len();
    let nh = k / 2 + 1;
    let symbols = disc.scheme.symbols(k, model.period());
    let forces = force_spectra(model, fft);
    let op = DenseOperator::new(model);
    let nd = dofs.len();
    let mut asm = Assembly {
        k,
        m,
        dofs: dofs.to_vec(),
        g_hat: vec![C::ZERO; nh * m * m],
        xlin_hat: vec![C::ZERO; nh * nd],
        bxlin_hat: vec![C::ZERO; nh * m],
        h_hat: vec![C::ZERO; nh * nd * m],
        symbols,
    };
    // Right-hand sides: Bᵀ (m columns, s_i e_{d_i}) then w_p F̂_p.
    let mut rhs = Mat::<C>::zeros(n, m + 1);
    for p in 0..nh {
        let (s1, s2, w) = (asm.symbols.sigma1[p], asm.symbols.sigma2[p], asm.symbols.weight[p]);
        let z = op.z(s2, s1, w);
        let lu = z.partial_piv_lu();
        check_pivots(lu.U(), p, model.frequency)?;
        rhs.fill(C::ZERO);
        for (i, c) in model.contacts.iter().enumerate() {
            rhs[(c.dof, i)] = C::from(c.direction);
        }
        for (d, spec) in &forces {
            rhs[(*d, m)] = spec[p] * w;
        }
        let y = lu.solve(&rhs);
        if !(0..m + 1).all(|j| (0..n).all(|i| y[(i, j)].re.is_finite() && y[(i, j)].im.is_finite())) {
            return Err(SolveError::SingularOperator { harmonic: p, frequency: p as f64 * model.frequency });
        }
        for (a, ca) in model.contacts.iter().enumerate() {
            for b in 0..m {
                asm.g_hat[(p * m + a) * m + b] = y[(ca.dof, b)] * ca.direction;
            }
            asm.bxlin_hat[p * m + a] = y[(ca.dof, m)] * ca.direction;
        }
        for (r, &d) in dofs.iter().enumerate() {
            asm.xlin_hat[p * nd + r] = y[(d, m)];
            for b in 0..m {
                asm.h_hat[(p * nd + r) * m + b] = y[(d, b)];
            }
        }
    }
    Ok(asm)
}

fn check_pivots(u: faer::MatRef<'_, C>, p: usize, omega: f64) -> Result<(), SolveError> {
    let n = u.nrows();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for i in 0..n {
        let v = u[(i, i)].norm();
        lo = lo.min(v);
        hi = hi.max(v);
    }
    // NaN-safe: `!(lo > …)` is true for NaN.
    if !(lo > SINGULAR_PIVOT_RATIO * hi) {
        return Err(SolveError::SingularOperator { harmonic: p, frequency: p as f64 * omega });
    }
    Ok(())
}
