//! Massless-boundary reduction: MacNeal's residual flexibility with free-interface modes
//! (src/formulation.md §4.1).
//!
//! η free-interface modes Φ (K φ = ω² M φ on the root-clamped structure, boundary free,
//! mass-normalised), the residual flexibility at the boundary columns
//! G = K⁻¹ E_b − Φ Λ⁻¹ Φ_bᵀ (n × n_b) and its boundary block G_bb (SPD). With Ψ = G G_bb⁻¹ the
//! basis is T = [Ψ, Φ − Ψ Φ_b] on the coordinates [u_b; q]: u_b are the boundary DOFs (unit rows
//! of T), q the modal amplitudes. K_r = Tᵀ K T in closed form:
//!
//! K_r = [[G_bb⁻¹, −G_bb⁻¹ Φ_b], [−Φ_bᵀ G_bb⁻¹, Λ + Φ_bᵀ G_bb⁻¹ Φ_b]]  (SPD)
//!
//! and M_r = diag(0, I): Tᵀ M T minus the residual mass Ψᵀ M Ψ, the one term MacNeal drops
//! (Ψᵀ M Φ = 0 exactly). Condensing u_b without boundary forces returns K_qq − K_qb K_bb⁻¹ K_bq = Λ,
//! so the contact-free reduced model has exactly the free-interface frequencies; under static
//! boundary forces u_b = (Φ_b Λ⁻¹ Φ_bᵀ + G_bb) f_b = (K⁻¹)_bb f_b exactly.
use super::craig_bampton::{Damping, Method, ReducedModel, ReductionError, Timings, boundary_mask, check_ratios, symmetric};
use super::eigen::{self, EigenError, Modes};
use crate::fe::sparse::sparse_times_dense;
use faer::linalg::solvers::Solve;
use faer::sparse::SparseColMat;
use faer::{Mat, Side};
use std::time::Instant;

/// Reduces (K, M) to a massless boundary `boundary` (full-model DOFs, any order, no repeats)
/// and `opts.modes` free-interface modes. K must be positive definite (the root clamped).
pub fn massless_boundary(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    boundary: &[usize],
    opts: &super::CraigBamptonOptions,
) -> Result<ReducedModel, ReductionError> {
    let t0 = Instant::now();
    let n = k.nrows();
    boundary_mask(k, m, boundary)?;
    let (nb, eta) = (boundary.len(), opts.modes);
    // The residual flexibility at n_b DOFs needs n_b modes left out.
    if eta + nb > n {
        return Err(ReductionError::TooManyModes { requested: eta, internal: n - nb });
    }
    let mut timings = Timings::default();
    let cpu0 = crate::fe::profile_cpu();
    let llt = eigen::cholesky(k).map_err(|e| ReductionError::Stiffness(e.to_string()))?;
    timings.factor = t0.elapsed().as_secs_f64();

    let t2 = Instant::now();
    let modes = eigen::lanczos(k, m, &llt, eta, &opts.lanczos).map_err(|e| match e {
        EigenError::Singular { .. } => ReductionError::Stiffness(e.to_string()),
        e => ReductionError::Eigen(e),
    })?;
    timings.eigen = t2.elapsed().as_secs_f64();
    let Modes { omega, shapes: phi, residual, .. } = modes;

    // G = K⁻¹ E_b − Φ Λ⁻¹ Φ_bᵀ: the static deflection under unit boundary loads minus the part
    // the kept modes carry (MacNeal 1971).
    let t1 = Instant::now();
    let mut g = Mat::<f64>::zeros(n, nb);
    for (i, &d) in boundary.iter().enumerate() {
        g[(d, i)] = 1.0;
    }
    llt.solve_in_place(g.as_mut());
    let phi_b = Mat::from_fn(nb, eta, |i, r| phi[(boundary[i], r)]);
    let scaled = Mat::from_fn(nb, eta, |i, r| phi_b[(i, r)] / (omega[r] * omega[r]));
    g -= &phi * scaled.transpose();
    let g_bb = symmetric(Mat::from_fn(nb, nb, |i, j| g[(boundary[i], j)]));
    let g_llt = g_bb.llt(Side::Lower).map_err(|e| ReductionError::ResidualFlexibility(format!("{e:?}")))?;
    // Round-off of the subtraction: a boundary block of a residual flexibility at 1e-12 of the
    // full flexibility is not resolved.
    let full_flex = (0..nb).map(|i| (g[(boundary[i], i)] + (0..eta).map(|r| scaled[(i, r)] * phi_b[(i, r)]).sum::<f64>()).abs()).fold(0.0, f64::max);
    let min_diag = (0..nb).map(|i| g_bb[(i, i)]).fold(f64::INFINITY, f64::min);
    if !(min_diag > 1e-12 * full_flex) {
        return Err(ReductionError::ResidualFlexibility(format!("smallest diagonal {min_diag:e} against a static flexibility of {full_flex:e}")));
    }
    let mut g_inv = Mat::<f64>::identity(nb, nb);
    g_llt.solve_in_place(g_inv.as_mut());
    let g_inv = symmetric(g_inv);
    // Ψ = G G_bb⁻¹: unit on the boundary (set exactly).
    let mut psi = &g * &g_inv;
    let mut t_q = &phi - &psi * &phi_b;
    for (i, &d) in boundary.iter().enumerate() {
        for j in 0..nb {
            psi[(d, j)] = if i == j { 1.0 } else { 0.0 };
        }
        for r in 0..eta {
            t_q[(d, r)] = 0.0;
        }
    }
    timings.static_modes = t1.elapsed().as_secs_f64();

    let t3 = Instant::now();
    let nr = nb + eta;
    let basis = Mat::from_fn(n, nr, |d, c| if c < nb { psi[(d, c)] } else { t_q[(d, c - nb)] });
    let coupling = -(&g_inv * &phi_b); // −G_bb⁻¹ Φ_b
    let modal = phi_b.transpose() * &g_inv * &phi_b;
    let stiffness = symmetric(Mat::from_fn(nr, nr, |i, j| match (i < nb, j < nb) {
        (true, true) => g_inv[(i, j)],
        (true, false) => coupling[(i, j - nb)],
        (false, true) => coupling[(j, i - nb)],
        (false, false) => modal[(i - nb, j - nb)] + if i == j { omega[i - nb] * omega[i - nb] } else { 0.0 },
    }));
    let mass = Mat::from_fn(nr, nr, |i, j| if i == j && i >= nb { 1.0 } else { 0.0 });
    timings.projection = t3.elapsed().as_secs_f64();
    timings.total = t0.elapsed().as_secs_f64();
    if let (Some(a), Some(b)) = (cpu0, crate::fe::profile_cpu()) {
        eprintln!("set-up profile: massless-boundary reduction {:.3} s thread CPU ({timings:?}, wall)", b - a);
    }
    Ok(ReducedModel {
        method: Method::MasslessBoundary,
        n_full: n,
        boundary: boundary.to_vec(),
        mass,
        stiffness,
        damping: None,
        interface_omega: omega,
        interface_residual: residual,
        timings,
        basis,
        modes_at_boundary: Some(phi_b),
    })
}

/// The damping of a massless-boundary model: on the modal coordinates only, C_r = diag(0, C_q)
/// (the boundary is quasi-static and carries none):
/// - Rayleigh αM + βK: C_q = α I + β Λ (ζ_r = α/(2ω_r) + β ω_r/2);
/// - modal ratios: C_q = diag(2 ζ_r ω_r);
/// - a matrix C: C_q = Φᵀ C Φ on the free-interface modes.
pub(super) fn damping(red: &ReducedModel, damping: &Damping) -> Result<Option<Mat<f64>>, ReductionError> {
    let (nb, eta) = (red.n_boundary(), red.n_modes());
    let w = &red.interface_omega;
    let c_q = match damping {
        Damping::None => return Ok(None),
        Damping::Rayleigh { alpha, beta } => Mat::from_fn(eta, eta, |i, j| if i == j { alpha + beta * w[i] * w[i] } else { 0.0 }),
        Damping::ModalRatios(z) => {
            check_ratios(z)?;
            Mat::from_fn(eta, eta, |i, j| if i == j { 2.0 * z[i.min(z.len() - 1)] * w[i] } else { 0.0 })
        }
        Damping::Matrix(c) => {
            if c.nrows() != red.n_full || c.ncols() != red.n_full {
                return Err(ReductionError::Damping(format!("the damping matrix is {}×{}, the model has {} DOFs", c.nrows(), c.ncols(), red.n_full)));
            }
            let phi_b = red.modes_at_boundary.as_ref().expect("a massless-boundary model keeps Φ_b");
            let psi = red.basis.subcols(0, nb);
            let phi = red.basis.subcols(nb, eta).to_owned() + psi * phi_b;
            symmetric(phi.transpose() * sparse_times_dense(c, phi.as_ref()))
        }
    };
    Ok(Some(Mat::from_fn(nb + eta, nb + eta, |i, j| if i >= nb && j >= nb { c_q[(i - nb, j - nb)] } else { 0.0 })))
}
