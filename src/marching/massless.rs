//! Explicit marching of a model with a massless boundary (src/formulation.md §4.1): the massive
//! DOFs a by central differences, the massless DOFs b condensed statically at every instant,
//! with the contacts (all on massless DOFs) enforced at that same instant:
//!
//! ```text
//! a_{n+1} = Ŵ_aa [ f_a(t_n) + (2M_aa/h² − K_aa) a_n − K_ab b_n − (M_aa/h² − C_aa/(2h)) a_{n−1} ]
//! K_bb b_{n+1} = f_b(t_{n+1}) − K_ba a_{n+1} − B_bᵀ λ_{n+1},   gap(t_{n+1}) − B_b b_{n+1} ≥ 0 ⟂ λ_{n+1} ≥ 0
//! ```
//!
//! The first line in the summed form (see [`super`]): Δa_{n+1} = Δa_n − Ŵ_aa(K_aa a_n + K_ab b_n)
//! − (Ŵ_aa C_aa/h) Δa_n + Ŵ_aa f_a, a_{n+1} = a_n + Δa_{n+1}, both sums compensated.
//!
//! The step LCP has G = B_b K_bb⁻¹ B_bᵀ (symmetric positive definite for independent rows), plus
//! 1/k_c on the diagonal of a compliant contact (its spring in series, the same instant): the
//! force is finite, as in the periodic LCP's step map. Stable for h < 2/ω_max with ω_max of the
//! condensed pencil with the contacts closed ([`stable_omega_max`]).
use super::small_lcp::solve_small_lcp;
use super::{MarchError, MarchResult, MarchSettings};
use crate::model::{Compliance, Model, ModelError};
use faer::Mat;
use faer::linalg::solvers::{DenseSolveCore, Solve};
use std::time::Instant;

/// ω_max for explicit marching: the model's, and with massless DOFs also that of the condensed
/// pencil with every rigid contact closed (a stiff spring, 1e6 × the largest diagonal stiffness:
/// the constrained pencil to about 1e-6), since a closed contact stiffens the condensed DOFs.
pub fn stable_omega_max(model: &Model) -> Result<f64, ModelError> {
    let open = model.omega_max()?;
    if model.massless_dofs().is_empty() || model.contacts.iter().all(|c| !c.is_rigid()) {
        return Ok(open);
    }
    let k = model.structure.stiffness.to_dense();
    let stiff = 1e6 * (0..model.n()).map(|i| k[(i, i)].abs()).fold(0.0, f64::max);
    let mut closed = model.clone();
    for c in closed.contacts.iter_mut().filter(|c| c.is_rigid()) {
        c.compliance = Compliance::Compliant { stiffness: stiff };
    }
    Ok(open.max(closed.omega_max()?))
}

fn setting(message: String) -> MarchError {
    MarchError::setting("structure", message)
}

/// [`super::march`] for a model with massless DOFs (`massless`, sorted).
pub(super) fn march_massless(model: &Model, settings: &MarchSettings, massless: &[usize], start: Instant) -> Result<MarchResult, MarchError> {
    let n = model.n();
    let (mm, kk) = (model.structure.mass.to_dense(), model.structure.stiffness.to_dense());
    let cc = model.structure.damping.as_ref().map_or_else(|| Mat::<f64>::zeros(n, n), |c| c.to_dense());
    let is_b: Vec<bool> = (0..n).map(|d| massless.binary_search(&d).is_ok()).collect();
    let (ia, ib): (Vec<usize>, Vec<usize>) = (0..n).partition(|&d| !is_b[d]);
    let (na, nb) = (ia.len(), ib.len());
    // The condensation is static only if the massless DOFs carry neither mass nor damping.
    for &b in &ib {
        if let Some(d) = (0..n).find(|&d| mm[(b, d)] != 0.0 || mm[(d, b)] != 0.0 || cc[(b, d)] != 0.0 || cc[(d, b)] != 0.0) {
            return Err(setting(format!(
                "DOF {b} is massless but couples to DOF {d} through the mass or damping; the static condensation of the massless DOFs needs none"
            )));
        }
    }
    for (i, c) in model.contacts.iter().enumerate() {
        if !model.contact_is_massless(c) {
            return Err(setting(format!(
                "contact[{i}] is not on a massless DOF; with a massless boundary the marcher takes contacts (rigid or compliant) on massless DOFs only"
            )));
        }
    }
    let ns = settings.steps_per_period;
    let period = model.period();
    let h = period / ns as f64;
    let omega_max = stable_omega_max(model)?;
    if omega_max * h >= 2.0 {
        let n_min = (period * omega_max / 2.0).floor() as usize + 1;
        return Err(MarchError::setting(
            "settings.steps_per_period",
            format!("is {ns}, h = {h:e} ≥ 2/ω_max = {:e} (ω_max = {omega_max:e}, contacts closed); use more than {n_min} steps per period", 2.0 / omega_max),
        ));
    }
    let sub = |m: &Mat<f64>, r: &[usize], c: &[usize]| Mat::<f64>::from_fn(r.len(), c.len(), |i, j| m[(r[i], c[j])]);
    let (maa, caa, kaa, kab) = (sub(&mm, &ia, &ia), sub(&cc, &ia, &ia), sub(&kk, &ia, &ia), sub(&kk, &ia, &ib));
    let w = Mat::<f64>::from_fn(na, na, |i, j| maa[(i, j)] / (h * h) + caa[(i, j)] / (2.0 * h)).partial_piv_lu().inverse();
    // The increment's matrices −Ŵ_aa K_aa, −Ŵ_aa C_aa/h, −Ŵ_aa K_ab (no 2I − h²M⁻¹K is rounded).
    let q1 = -(&w * &kaa);
    let q2 = -(&w * &caa) * faer::Scale(1.0 / h);
    let ab = -(&w * &kab);
    let s = sub(&kk, &ib, &ib).partial_piv_lu().inverse();
    let sba = -(&s * sub(&kk, &ib, &ia));
    if [&w, &s].iter().any(|m| (0..m.nrows()).any(|i| (0..m.ncols()).any(|j| !m[(i, j)].is_finite()))) {
        return Err(setting("M_aa/h² + C_aa/(2h) or K_bb (the massless block) is singular".into()));
    }
    // Contact rows on b, S B_bᵀ and G = B_b S B_bᵀ.
    let pos: Vec<usize> = {
        let mut p = vec![0; n];
        ib.iter().enumerate().for_each(|(k, &d)| p[d] = k);
        p
    };
    let m = model.contacts.len();
    let cols: Vec<Vec<f64>> = model.contacts.iter().map(|c| (0..nb).map(|r| c.row.iter().map(|&(d, v)| v * s[(r, pos[d])]).sum()).collect()).collect();
    // A compliant contact adds its spring in series: λ/k_c of penetration at force λ
    // (w = gap − B b + λ/k_c ≥ 0 ⟂ λ ≥ 0 is λ = k_c·max(0, B b − gap), §4.1's statics).
    let g: Vec<f64> = (0..m * m)
        .map(|k| {
            let series = match model.contacts[k / m].compliance {
                Compliance::Compliant { stiffness } if k / m == k % m => 1.0 / stiffness,
                _ => 0.0,
            };
            model.contacts[k / m].row.iter().map(|&(d, v)| v * cols[k % m][pos[d]]).sum::<f64>() + series
        })
        .collect();
    let omega = model.frequency;
    let mut f = vec![0.0; n];
    // The massless DOFs of x at t from its massive ones (statics and the contact LCP); λ out.
    let mut condense = |t: f64, x: &mut [f64], lam: &mut [f64]| -> Result<(), super::StepLcpError> {
        model.force_at(t, &mut f);
        for (r, &b) in ib.iter().enumerate() {
            x[b] = (0..nb).map(|k| s[(r, k)] * f[ib[k]]).sum::<f64>() + (0..na).map(|k| sba[(r, k)] * x[ia[k]]).sum::<f64>();
        }
        let q: Vec<f64> = model.contacts.iter().map(|c| c.gap_at(omega, t) - c.normal_displacement(x)).collect();
        lam.iter_mut().for_each(|v| *v = 0.0);
        if q.iter().any(|&v| v < 0.0) {
            lam.copy_from_slice(&solve_small_lcp(&g, &q, m)?);
            for (i, &l) in lam.iter().enumerate() {
                (0..nb).for_each(|r| x[ib[r]] -= l * cols[i][r]);
            }
        }
        Ok(())
    };
    let step_error = |step, period, error| MarchError::Step { step, period, error };
    // Start: x_0 (its massless part condensed), x_{−1} = x_0 − h v_0 + h²/2 a_0 on the massive DOFs.
    let mut x_cur = settings.initial_displacement.clone().unwrap_or_else(|| vec![0.0; n]);
    let v0 = settings.initial_velocity.clone().unwrap_or_else(|| vec![0.0; n]);
    let mut lam = vec![0.0; m];
    condense(0.0, &mut x_cur, &mut lam).map_err(|e| step_error(0, 0, e))?;
    let mut fa = vec![0.0; n];
    model.force_at(0.0, &mut fa);
    let r0 = Mat::<f64>::from_fn(na, 1, |i, _| fa[ia[i]] - (0..n).map(|d| cc[(ia[i], d)] * v0[d] + kk[(ia[i], d)] * x_cur[d]).sum::<f64>());
    let acc0 = maa.partial_piv_lu().solve(&r0);
    // Δ_0 = x_0 − x_{−1} = h v_0 − h²/2 a_0 on the massive DOFs (the massless ones start at rest).
    let mut d_cur = vec![0.0; n];
    for (i, &a) in ia.iter().enumerate() {
        d_cur[a] = h * v0[a] - 0.5 * h * h * acc0[(i, 0)];
    }
    let (mut x_next, mut d_next) = (x_cur.clone(), vec![0.0; n]);
    let mut sum = super::Compensated::new(n);
    let mut rec = super::Recorder::new(n, m, ns, h);
    for p in 0..settings.max_periods {
        for j in 0..ns {
            let t = j as f64 * h;
            model.force_at(t, &mut fa);
            for (i, &a) in ia.iter().enumerate() {
                let mut v: f64 = (0..na).map(|k| q1[(i, k)] * x_cur[ia[k]] + q2[(i, k)] * d_cur[ia[k]] + w[(i, k)] * fa[ia[k]]).sum();
                v += (0..nb).map(|k| ab[(i, k)] * x_cur[ib[k]]).sum::<f64>();
                d_next[a] = v;
            }
            sum.step(&x_cur, &d_cur, &mut x_next, &mut d_next, ia.iter().copied());
            rec.contacts(j, model, t, &lam, &x_cur);
            condense((j + 1) as f64 * h, &mut x_next, &mut lam).map_err(|e| step_error(j, p + 1, e))?;
            if x_next.iter().any(|v| !v.is_finite()) {
                return Err(MarchError::Diverged { step: j, period: p + 1 });
            }
            for &b in &ib {
                d_next[b] = x_next[b] - x_cur[b];
            }
            rec.state(j, &x_cur, &d_cur, &d_next);
            std::mem::swap(&mut x_cur, &mut x_next);
            std::mem::swap(&mut d_cur, &mut d_next);
        }
        if rec.end_period(p, settings) {
            break;
        }
    }
    Ok(rec.finish(omega_max, start))
}
