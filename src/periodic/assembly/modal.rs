//! The modal assembly (src/formulation.md §2–3, §4.1 for the residual flexibility): every harmonic's Ĝ_p, X̂lin_p and Ẑ_p⁻¹Bᵀ from the
//! modes as real matrix products over all harmonics, into a session's kept products.
use super::{Assembly, RecoveryRow, SolveError, Statics, along_row};
use crate::model::Model;
use crate::time::Symbols;
use faer::Mat;
use num_complex::Complex64 as C;

/// The modal assembly's largest products (Ĝ's, Ẑ⁻¹Bᵀ's, X̂lin's and B X̂lin's real and imaginary
/// parts over the harmonics), kept between a session's assemblies and overwritten: faer's
/// `a * b` allocated and zeroed each (4.7 MB for Ĝ at k = 2048, m = 17), a third of the real
/// blade's `memset` (issue 23).
#[derive(Clone, Debug)]
pub struct ModalProducts([Mat<f64>; 8]);

impl Default for ModalProducts {
    fn default() -> Self {
        ModalProducts(std::array::from_fn(|_| Mat::new()))
    }
}

/// out = a·b as faer's `&a * &b` forms it (the same call into a matrix of the same shape), into
/// `out`'s storage when it has that shape already.
fn product_into<'a>(out: &'a mut Mat<f64>, a: &Mat<f64>, b: &Mat<f64>) -> &'a Mat<f64> {
    if (out.nrows(), out.ncols()) != (a.nrows(), b.ncols()) {
        *out = Mat::zeros(a.nrows(), b.ncols());
    }
    faer::linalg::matmul::matmul(out.as_mut(), faer::Accum::Replace, a.as_ref(), b.as_ref(), 1.0, faer::get_global_parallelism());
    out
}

/// The modal operator for every harmonic at once: with D_p = diag(1/(σ2 + σ1 c_i + w λ_i)),
/// Ĝ_p = (BΦ) D_p (BΦ)ᵀ, X̂lin_p = Φ_out D_p Φᵀ w_p F̂_p and Ẑ_p⁻¹Bᵀ at the outputs
/// Φ_out D_p (BΦ)ᵀ, as real matrix products over all harmonics (real and imaginary parts apart).
#[allow(clippy::too_many_arguments)]
pub(super) fn assemble_modal(
    model: &Model,
    symbols: Symbols,
    forces: &[(usize, Vec<C>)],
    rows: &[RecoveryRow],
    (phi, lambda, c): (&Mat<f64>, &[f64], &[f64]),
    statics: Option<&Statics>,
    k: usize,
    products: &mut ModalProducts,
) -> Result<Assembly, SolveError> {
    // Modes (columns of Φ): n without massless DOFs, fewer with them.
    let n = phi.ncols();
    let m = model.contacts.len();
    let nd = rows.len();
    let nh = k / 2 + 1;
    // D_p[i], stored [i][p] as real and imaginary parts.
    let mut dre = Mat::<f64>::zeros(n, nh);
    let mut dim = Mat::<f64>::zeros(n, nh);
    for p in 0..nh {
        let (s1, s2, w) = (symbols.sigma1[p], symbols.sigma2[p], symbols.weight[p]);
        for i in 0..n {
            let d = s2 + s1 * c[i] + C::from(w * lambda[i]);
            // |d| against the size of its terms (squared norms: no hypot in this loop).
            let scale = s2.norm_sqr() + s1.norm_sqr() * c[i] * c[i] + (w * lambda[i]).powi(2);
            if !(d.norm_sqr() > 1e-26 * scale) {
                return Err(SolveError::SingularOperator { harmonic: p, frequency: p as f64 * model.frequency });
            }
            let inv = d.inv();
            dre[(i, p)] = inv.re;
            dim[(i, p)] = inv.im;
        }
    }
    // Modal force f̃_p = Φᵀ w_p F̂_p (n × nh), and u = D ∘ f̃.
    let nl = forces.len();
    let phil = Mat::<f64>::from_fn(n, nl, |i, l| phi[(forces[l].0, i)]);
    let fre = &phil * Mat::<f64>::from_fn(nl, nh, |l, p| (forces[l].1[p] * symbols.weight[p]).re);
    let fim = &phil * Mat::<f64>::from_fn(nl, nh, |l, p| (forces[l].1[p] * symbols.weight[p]).im);
    let ure = Mat::<f64>::from_fn(n, nh, |i, p| dre[(i, p)] * fre[(i, p)] - dim[(i, p)] * fim[(i, p)]);
    let uim = Mat::<f64>::from_fn(n, nh, |i, p| dre[(i, p)] * fim[(i, p)] + dim[(i, p)] * fre[(i, p)]);
    let bphi = Mat::<f64>::from_fn(m, n, |a, i| model.contacts[a].along(|d| phi[(d, i)]));
    let phio = Mat::<f64>::from_fn(nd, n, |r, i| along_row(&rows[r].1, |d| phi[(d, i)]));
    let [xre, xim, bre, bim, gre, gim, hre, him] = &mut products.0;
    let (xre, xim) = (product_into(xre, &phio, &ure), product_into(xim, &phio, &uim));
    let (bre, bim) = (product_into(bre, &bphi, &ure), product_into(bim, &bphi, &uim));
    // Ĝ_p[a][b] = Σ_i (BΦ)[a,i] (BΦ)[b,i] D_p[i] and Ẑ_p⁻¹Bᵀ[r][b] = Σ_i Φ_out[r,i] (BΦ)[b,i] D_p[i]:
    // one product each, rows the pairs' mode products, so that column p is harmonic p's block in
    // storage order (one sequential write; 2m products and m strided passes before, issue 23).
    let pairs = Mat::<f64>::from_fn(m * m, n, |ab, i| bphi[(ab / m, i)] * bphi[(ab % m, i)]);
    let (gre, gim) = (product_into(gre, &pairs, &dre), product_into(gim, &pairs, &dim));
    let outs = Mat::<f64>::from_fn(nd * m, n, |rb, i| phio[(rb / m, i)] * bphi[(rb % m, i)]);
    let (hre, him) = (product_into(hre, &outs, &dre), product_into(him, &outs, &dim));
    // The residual flexibility's static part / w_p, added as each harmonic is stored (a pass over
    // Ĝ and Ẑ⁻¹Bᵀ of its own, and one for the finite check, were 2 % of a real-blade sweep, issue 23).
    let inv_w: Vec<f64> = match statics {
        Some(_) => (0..nh).map(|p| residual_scale(symbols.weight[p], p, model.frequency)).collect::<Result<_, _>>()?,
        None => Vec::new(),
    };
    // Each harmonic's column, and whether its modal part is finite (B X̂lin's is not checked).
    let by_harmonic = |re: &Mat<f64>, im: &Mat<f64>, fixed: Option<&[f64]>| -> (Vec<C>, bool) {
        let mut v = Vec::with_capacity(re.nrows() * nh);
        let mut finite = true;
        for p in 0..nh {
            let (re, im) = (re.col_as_slice(p), im.col_as_slice(p));
            finite &= re.iter().chain(im).all(|x| x.is_finite());
            match fixed {
                // As `C + C::from(s / w_p)`: the imaginary part gains + 0.0.
                Some(fixed) => v.extend(re.iter().zip(im).zip(fixed).map(|((&a, &b), &s)| C::new(a + s * inv_w[p], b + 0.0))),
                None => v.extend(re.iter().zip(im).map(|(&a, &b)| C::new(a, b))),
            }
        }
        (v, finite)
    };
    let (g_hat, g_finite) = by_harmonic(gre, gim, statics.map(|st| st.brbt.as_slice()));
    let (h_hat, h_finite) = by_harmonic(hre, him, statics.map(|st| st.rbt_out.as_slice()));
    let (xlin_hat, x_finite) = by_harmonic(xre, xim, None);
    let (bxlin_hat, _) = by_harmonic(bre, bim, None);
    if !(g_finite && h_finite && x_finite) {
        return Err(SolveError::SingularOperator { harmonic: 0, frequency: 0.0 });
    }
    Ok(Assembly { k, m, dofs: rows.iter().map(|r| r.0).collect(), symbols, g_hat: g_hat.into(), xlin_hat, bxlin_hat, h_hat, tangential: Vec::new() })
}

/// 1 / w_p, the residual flexibility's factor at harmonic p (R / w_p of Ẑ_p⁻¹), or why there is none.
fn residual_scale(w: f64, p: usize, frequency: f64) -> Result<f64, SolveError> {
    let inv_w = 1.0 / w;
    (w != 0.0 && inv_w.is_finite()).then_some(inv_w).ok_or(SolveError::SingularOperator { harmonic: p, frequency: p as f64 * frequency })
}
