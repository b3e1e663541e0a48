//! The switch search along one phase on its time grid, without flowing the full state per step:
//! the massive state's deviation from the particular solution is stepped by e^{Ah} (one product
//! of the 2n_a-sized matrix per step), and each contact's clearance is its periodic part (gap
//! minus the particular solution, harmonics turned by e^{ipωh}) minus its row on the lifted
//! deviation (B_i L z_x, L = N_a + N_b S: phase.rs). A sign change between two grid points is
//! then refined on the clearance in closed form (the phase's modes from the bracket's start), and
//! the full state is flowed once, to the switch. The grid and the signs are the per-step flows'
//! (the search before), at about a tenth of their cost on the compliant blade (17 contacts,
//! 13 gap harmonics, 69 DOFs: ~1100 steps per period).
use super::super::phase::{self, Phase};
use crate::model::Model;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;
use std::sync::Arc;

/// What a phase's grid keeps at every ω (made once per contact set and shared by its re-tunings
/// through the [`super::PhaseBank`]): the step, e^{Ah}, and the contacts' rows.
pub(super) struct Fixed {
    /// The step [s] and e^{Ah} on [x_a; v_a].
    pub h: f64,
    step: DMatrix<f64>,
    /// B_i L (rows: contacts, columns: the massive coordinates x_a), and on Â's modes (B_i L V_x).
    rows: DMatrix<f64>,
    modal_rows: Option<DMatrix<C>>,
    /// B_i N_a and B_i N_b: the contacts' rows on the massive and massless coordinates (for
    /// B_i P̂_p from the particular solution's coordinates).
    on_massive: DMatrix<f64>,
    on_massless: DMatrix<f64>,
    /// The modes a real signal needs, with their weights: one of each conjugate pair of Â's
    /// eigenvalues (weight 2: Re(m e^{λτ}) + Re(m̄ e^{λ̄τ}) = 2 Re(m e^{λτ})) and the real ones (1).
    modes: Vec<(usize, f64)>,
}

impl Fixed {
    /// The ω-independent part of `ph`'s grid with step `h`.
    pub fn new(model: &Model, ph: &Phase, h: f64) -> Fixed {
        let m = model.contacts.len();
        let lift = ph.lifted();
        let along = |basis: &DMatrix<f64>| DMatrix::from_fn(m, basis.ncols(), |i, k| model.contacts[i].along(|d| basis[(d, k)]));
        let rows = along(lift);
        let modal_rows = ph.rows_on_modes(&rows);
        let lambda = ph.modal_coordinates(&DVector::zeros(2 * lift.ncols())).map_or_else(Vec::new, |(l, _)| l.to_vec());
        let mut paired = vec![false; lambda.len()];
        let mut modes = Vec::with_capacity(lambda.len());
        for j in 0..lambda.len() {
            if paired[j] {
                continue;
            }
            let twin = (lambda[j].im != 0.0).then(|| (j + 1..lambda.len()).find(|&k| !paired[k] && lambda[k] == lambda[j].conj())).flatten();
            if let Some(k) = twin {
                paired[k] = true;
            }
            modes.push((j, if twin.is_some() { 2.0 } else { 1.0 }));
        }
        let (on_massive, on_massless) = (along(ph.massive_basis()), along(ph.massless_basis()));
        Fixed { h, step: ph.grid_step(h), rows, modal_rows, on_massive, on_massless, modes }
    }
}

/// One phase's grid at one ω: its [`Fixed`] part and the clearances' periodic parts.
pub(super) struct Grid {
    pub fixed: Arc<Fixed>,
    /// ω, the harmonics' orders p (ascending), rates pω and e^{ipωh}.
    omega: f64,
    orders: Vec<u32>,
    rates: Vec<f64>,
    turn: Vec<C>,
    /// Contact i's clearance's periodic part at each harmonic (rows: contacts): gap_i − B_i P̂_p.
    periodic: DMatrix<C>,
}

impl Grid {
    /// The grid of `ph` at `model`'s ω on `fixed` (made for `ph`'s contact set), `gaps` each
    /// contact's gap harmonics.
    pub fn new(model: &Model, ph: &Phase, fixed: Arc<Fixed>, gaps: &[phase::Harmonics]) -> Grid {
        let w = model.frequency;
        let along = ph.particular_on(&fixed.on_massive, &fixed.on_massless);
        let mut orders: Vec<u32> = along.iter().map(|(p, _)| *p).chain(gaps.iter().flat_map(|g| g.iter().map(|(p, _)| *p))).collect();
        orders.sort_unstable();
        orders.dedup();
        let zero = C::new(0.0, 0.0);
        let mut periodic = DMatrix::from_element(gaps.len(), orders.len(), zero);
        for (col, p) in orders.iter().enumerate() {
            let part = along.iter().find(|(q, _)| q == p).map(|(_, x)| x);
            for (i, g) in gaps.iter().enumerate() {
                let gap = g.iter().find(|(q, _)| q == p).map_or(zero, |(_, g)| g[0]);
                periodic[(i, col)] = gap - part.map_or(zero, |x| x[i]);
            }
        }
        let rates: Vec<f64> = orders.iter().map(|&p| p as f64 * w).collect();
        let turn = rates.iter().map(|r| C::from_polar(1.0, r * fixed.h)).collect();
        Grid { fixed, omega: w, orders, rates, turn, periodic }
    }

    /// Each contact's clearance at `t` from the deviation `z` (2n_a) and e^{ipωt} (`phasors`).
    fn clearances(&self, z: &DVector<f64>, phasors: &[C]) -> DVector<f64> {
        let rows = &self.fixed.rows;
        let mut c = -(rows * z.rows(0, rows.ncols()));
        for (i, v) in c.iter_mut().enumerate() {
            *v += phasors.iter().enumerate().map(|(p, u)| (self.periodic[(i, p)] * u).re).sum::<f64>();
        }
        c
    }

    /// Contact `i`'s clearance at `s` in closed form from the deviation's modes at `t0`
    /// ([`Phase::modal_coordinates`]: `lambda`, and `modal` = B_i L V_x c, its row on them, the
    /// modes of [`Fixed`]'s `modes` only, weighted). e^{ipωs} as powers of e^{iωs} (one sine and
    /// cosine per call, p·ε relative).
    fn clearance_at(&self, i: usize, s: f64, t0: f64, lambda: &[C], modal: &[C]) -> f64 {
        let base = C::from_polar(1.0, self.omega * s);
        let (mut power, mut order) = (C::new(1.0, 0.0), 0);
        let mut periodic = 0.0;
        for (col, &p) in self.orders.iter().enumerate() {
            power *= base.powu(p - order);
            order = p;
            periodic += (self.periodic[(i, col)] * power).re;
        }
        let transient: f64 = lambda.iter().zip(modal).map(|(l, m)| (m * (l * (s - t0)).exp()).re).sum();
        periodic - transient
    }
}

/// The first switch of the phase `ph` (grid `grid`) from the state `ya` at `a` before `end`, the
/// contacts `closed` closed: (contact, time, state there), the time at the bracket's negative end
/// (the contact has switched there); `None` when no signed clearance turns negative on the grid
/// (nor at `end`, checked on the flowed state).
pub(super) fn first_switch(
    model: &Model,
    ph: &Phase,
    grid: &Grid,
    closed: &[usize],
    (a, ya): (f64, &DVector<f64>),
    end: f64,
) -> Option<(usize, f64, DVector<f64>)> {
    let m = model.contacts.len();
    let sign: Vec<f64> = (0..m).map(|i| if closed.contains(&i) { -1.0 } else { 1.0 }).collect();
    let mut z = ph.homogeneous(a, ya);
    let mut phasors: Vec<C> = grid.rates.iter().map(|r| C::from_polar(1.0, r * a)).collect();
    let mut next = DVector::zeros(z.len());
    let mut j = 0usize;
    loop {
        let t0 = a + grid.fixed.h * j as f64;
        let t1 = a + grid.fixed.h * (j + 1) as f64;
        if t1 >= end {
            // The last, shorter interval on the flowed state (as the search before did).
            let y1 = ph.flow(a, ya, end);
            let c1 = DVector::from_fn(m, |i, _| sign[i] * clearance(model, i, &y1, end));
            return earliest(model, ph, grid, (a, ya), (t0, end), &z, &c1, &sign);
        }
        next.gemv(1.0, &grid.fixed.step, &z, 0.0);
        std::mem::swap(&mut z, &mut next);
        phasors.iter_mut().zip(&grid.turn).for_each(|(u, r)| *u *= r);
        let c1 = grid.clearances(&z, &phasors).component_mul(&DVector::from_column_slice(&sign));
        if c1.iter().any(|v| *v < 0.0) {
            // `next` holds the deviation at t0 (swapped out).
            return earliest(model, ph, grid, (a, ya), (t0, t1), &next, &c1, &sign);
        }
        j += 1;
    }
}

/// Contact `i`'s clearance gap_i(t) − B_i x in the full state `y`.
fn clearance(model: &Model, i: usize, y: &DVector<f64>, t: f64) -> f64 {
    let w = model.frequency;
    let gap: f64 = phase::gap_harmonics(model, i).iter().map(|(p, g)| (g[0] * C::from_polar(1.0, *p as f64 * w * t)).re).sum();
    gap - model.contacts[i].along(|d| y[d])
}

/// The earliest crossing among the contacts negative at `t1` (`c1`, signed) in [t0, t1], the
/// deviation at t0 being `z0`.
#[allow(clippy::too_many_arguments)]
fn earliest(
    model: &Model,
    ph: &Phase,
    grid: &Grid,
    (a, ya): (f64, &DVector<f64>),
    (t0, t1): (f64, f64),
    z0: &DVector<f64>,
    c1: &DVector<f64>,
    sign: &[f64],
) -> Option<(usize, f64, DVector<f64>)> {
    let negative: Vec<usize> = (0..c1.len()).filter(|&i| c1[i] < 0.0).collect();
    if negative.is_empty() {
        return None;
    }
    // The deviation's modal coordinates at t0, and each crossing contact's row on them.
    let modes = ph.modal_coordinates(z0).zip(grid.fixed.modal_rows.as_ref());
    let mut first: Option<(usize, f64)> = None;
    for &i in &negative {
        let ts = match &modes {
            Some(((lambda, c), rows)) => {
                let kept = &grid.fixed.modes;
                let lambda: Vec<C> = kept.iter().map(|&(j, _)| lambda[j]).collect();
                let modal: Vec<C> = kept.iter().map(|&(j, weight)| rows[(i, j)] * c[j] * weight).collect();
                let g = |s: f64| sign[i] * grid.clearance_at(i, s, t0, &lambda, &modal);
                illinois(&g, t0, t1, c1[i])
            }
            // No eigendecomposition: the state flowed per trial time.
            None => illinois(&|s| sign[i] * clearance(model, i, &ph.flow(a, ya, s), s), t0, t1, c1[i]),
        };
        if first.is_none_or(|f| ts < f.1) {
            first = Some((i, ts));
        }
    }
    let (i, ts) = first?;
    Some((i, ts, ph.flow(a, ya, ts)))
}

/// Where `g` (≥ 0 at `a`, `gb` < 0 at `b`) changes sign: the Illinois method (regula falsi with
/// halving, Dowell & Jarratt, BIT 11, 1971) to round-off; the time at the bracket's negative end.
fn illinois(g: &dyn Fn(f64) -> f64, a: f64, b: f64, gb: f64) -> f64 {
    let (mut lo, mut hi) = (a, b);
    let (mut glo, mut ghi) = (g(a).max(0.0), gb);
    let mut side = 0;
    for _ in 0..100 {
        if hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(1e-300) {
            break;
        }
        let mut s = hi - ghi * (hi - lo) / (ghi - glo);
        if !(s > lo && s < hi) {
            s = 0.5 * (lo + hi);
        }
        let gs = g(s);
        if gs < 0.0 {
            (hi, ghi) = (s, gs);
            if side == -1 {
                glo *= 0.5;
            }
            side = -1;
        } else {
            (lo, glo) = (s, gs);
            if side == 1 {
                ghi *= 0.5;
            }
            side = 1;
        }
    }
    hi
}
