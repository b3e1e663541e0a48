//! Newton's step for the friction shooting when its periodic orbits form a family (src/formulation.md
//! §9, "Friction by shooting"): stuck rigid and Jenkins contacts hold any static offset of the
//! chain whose static forces stay in their boxes, so I − P is singular along the offsets.
use faer::Mat;
use nalgebra::{DMatrix, DVector};

/// Relative singular value of I − P at or below which its direction is a family of periodic
/// orbits (round-off: measured 2.5e-14–2.8e-14 of the largest on the bench case `friction`, the
/// next one ≥ 1e-5).
const FAMILY_RANK_TOL: f64 = 1e-11;

/// Relative singular value below which a direction that shrank since the last iteration is taken
/// as closing (a contact's slip window closing on a stuck-all-period member of the family).
const CLOSING_MAX: f64 = 0.05;

/// Shrink per iteration of the least kept singular value that marks it as closing.
const CLOSING_RATIO: f64 = 0.75;

/// Newton's step on a closing direction is multiplied by this. Why: there the periodicity
/// residual is quadratic in the distance to the family (the slip window shrinks with it), a double
/// root, so Newton halves the distance per iteration; twice the step reaches the family's
/// boundary, and going past it lands inside, where every offset is periodic.
const CLOSING_OVERSHOOT: f64 = 2.0;

/// Newton's step δ for (I − P) δ = r, by SVD.
pub(super) struct FamilyStep {
    /// The minimum-norm least-squares step (no move along the family).
    pub plain: Vec<f64>,
    /// The step with its closing directions overshot, when one is closing.
    pub closing: Option<Vec<f64>>,
    /// The least kept singular value relative to the largest (for the next iteration).
    pub least: f64,
}

/// The step of `a` δ = `r`; `previous`: the last iteration's [`FamilyStep::least`].
pub(super) fn family_step(a: &Mat<f64>, r: &[f64], previous: Option<f64>) -> FamilyStep {
    let d = a.nrows();
    let svd = DMatrix::from_fn(d, d, |i, l| a[(i, l)]).svd(true, true);
    let (Some(u), Some(v_t)) = (&svd.u, &svd.v_t) else {
        return FamilyStep { plain: vec![f64::NAN; d], closing: None, least: 1.0 };
    };
    let sigma = &svd.singular_values;
    let top = sigma.max().max(f64::MIN_POSITIVE);
    let c = u.transpose() * DVector::from_column_slice(r);
    let kept: Vec<usize> = (0..d).filter(|&i| sigma[i] > FAMILY_RANK_TOL * top).collect();
    let least = kept.iter().map(|&i| sigma[i] / top).fold(1.0, f64::min);
    let mut plain = vec![0.0; d];
    let mut near = vec![0.0; d];
    for &i in &kept {
        let w = c[i] / sigma[i];
        let is_near = sigma[i] / top <= 2.0 * least;
        for (col, out) in plain.iter_mut().enumerate() {
            *out += v_t[(i, col)] * w;
        }
        if is_near {
            for (col, out) in near.iter_mut().enumerate() {
                *out += v_t[(i, col)] * w;
            }
        }
    }
    let closing = (least < CLOSING_MAX && previous.is_some_and(|p| least < CLOSING_RATIO * p))
        .then(|| plain.iter().zip(&near).map(|(p, n)| p + (CLOSING_OVERSHOOT - 1.0) * n).collect());
    FamilyStep { plain, closing, least }
}

/// Dimension of the family of periodic orbits through a converged state: singular values of
/// I − P (`p`: the period's tangent with the last march's modes) at round-off.
pub(super) fn family_dimension(p: &Mat<f64>) -> usize {
    let d = p.nrows();
    let sigma = DMatrix::from_fn(d, d, |i, l| if i == l { 1.0 } else { 0.0 } - p[(i, l)]).singular_values();
    let top = sigma.max().max(f64::MIN_POSITIVE);
    sigma.iter().filter(|&&s| s <= FAMILY_RANK_TOL * top).count()
}
