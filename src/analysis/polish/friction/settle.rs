//! Where the LCP's phase sequence is not the exact orbit's, the topology is found by marching:
//! - [`settle`]: an event-driven march of the exact flows from the seeded state until two
//!   successive periods have the same events (bds1's numerical damping can hide a short stick
//!   phase: the chain at Ω = 0.595 stops mid-swing twice a period, which the LCP at k = 512 misses);
//! - [`StickSlipOrbit::converge_stuck`]: the orbit stuck all period, which is the stuck system's
//!   linear orbit, unique up to the slider's constant (formulation.md §9); the constant is the
//!   LCP's, moved into the interval where |f| ≤ μN holds over the whole period if it lies outside.
use super::{Flows, PolishFailure, Slide, StickSlipOrbit};
use nalgebra::{DMatrix, DVector};

/// Steps per period of the march (events are then refined by bisection on the exact flow).
const STEPS: usize = 512;
/// Periods marched at most before the topology is declared unsettled.
const MAX_PERIODS: usize = 600;

/// A phase sequence over one period: the phase at `start`, then (time, phase after) per event.
pub(super) struct Topology {
    pub start: f64,
    pub first: Slide,
    pub events: Vec<(f64, Slide)>,
}

/// The phase after an event that ends `from` in state `y` (at the event).
fn next(fl: &Flows, from: Slide, y: &DVector<f64>) -> Slide {
    match from {
        Slide::Stick => Slide::Slip(fl.stick_force.dot(y).signum()),
        Slide::Slip(_) if fl.kt.is_some() => Slide::Stick,
        Slide::Slip(_) => {
            // Rigid Coulomb at bᵀv = 0: stick if the holding force is within μN, else slip on
            // the side the holding force points to.
            let held = fl.stick_force.dot(&fl.enter(from, Slide::Stick, y.clone()));
            if held.abs() <= fl.slip { Slide::Stick } else { Slide::Slip(held.signum()) }
        }
        // One contact alone has no stop.
        Slide::Open | Slide::Closed => from,
    }
}

/// Whether `phase` has ended by state `y`.
fn ended(fl: &Flows, phase: Slide, y: &DVector<f64>) -> bool {
    match phase {
        Slide::Slip(s) => s * fl.velocity(y) < 0.0,
        Slide::Stick => fl.stick_force.dot(y).abs() > fl.slip,
        Slide::Open | Slide::Closed => false,
    }
}

/// Marches the exact flows from `phase`, state `y` at `t0` until the events of two successive
/// periods agree to 1e-7·T (then returns the last period's), or `MAX_PERIODS` pass.
pub(super) fn settle(fl: &Flows, period: f64, t0: f64, mut phase: Slide, mut y: DVector<f64>) -> Option<Topology> {
    let dt = period / STEPS as f64;
    let steps: Vec<DMatrix<f64>> = fl.a.iter().map(|a| (a * dt).exp()).collect();
    if phase == Slide::Stick && fl.kt.is_none() {
        y = fl.enter(Slide::Slip(1.0), Slide::Stick, y);
    }
    let mut t = t0;
    let mut previous: Option<Vec<(f64, Slide)>> = None;
    // Bisections that barely advance (a grazing slip) are bounded too.
    let mut budget = 4 * STEPS * MAX_PERIODS;
    for p in 0..MAX_PERIODS {
        let (first, end) = (phase, t0 + (p + 1) as f64 * period);
        let mut events = Vec::new();
        while t < end {
            budget = budget.checked_sub(1)?;
            let h = dt.min(end - t);
            let yn = if h == dt { &steps[phase.index()] * &y } else { fl.flow(phase, &y, h) };
            if !ended(fl, phase, &yn) {
                (y, t) = (yn, t + h);
                continue;
            }
            // Bisection on the exact flow for the first instant the phase has ended.
            let (mut lo, mut hi) = (0.0, h);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if ended(fl, phase, &fl.flow(phase, &y, mid)) { hi = mid } else { lo = mid }
            }
            let ye = fl.flow(phase, &y, hi);
            let to = next(fl, phase, &ye);
            (y, t) = (fl.enter(phase, to, ye), t + hi);
            if to != phase {
                events.push((t - p as f64 * period, to));
                phase = to;
            }
        }
        if let Some(prev) = &previous {
            let same = prev.len() == events.len() && prev.iter().zip(&events).all(|(a, b)| a.1 == b.1 && (a.0 - b.0).abs() <= 1e-7 * period);
            if same {
                return Some(Topology { start: t0, first, events });
            }
        }
        previous = Some(events);
    }
    None
}

impl StickSlipOrbit {
    /// The orbit stuck all period with the slider constant `c` (rigid: bᵀx = c, bᵀv = 0; Jenkins:
    /// s₀ = c): the periodic fixed point of the stuck flow, whose one-period map has multiplier 1
    /// along the constant (and, rigid, bᵀv), made unique by those rows (least squares, consistent).
    fn fit_stuck(&mut self, c: f64) -> Result<(), PolishFailure> {
        let fl = &self.flows;
        let (n, nr) = (fl.n, self.nr);
        let mut rows: Vec<(DVector<f64>, f64)> = Vec::new();
        let unit = |i: usize| DVector::from_fn(nr, |j, _| if j == i { 1.0 } else { 0.0 });
        match fl.kt {
            Some(_) => rows.push((unit(2 * n), c)),
            None => {
                let mut bx = DVector::zeros(nr);
                bx.rows_mut(0, n).copy_from(&fl.b);
                let mut bv = DVector::zeros(nr);
                bv.rows_mut(n, n).copy_from(&fl.b);
                rows.push((bx, c));
                rows.push((bv, 0.0));
            }
        }
        let zero = DVector::zeros(nr);
        let c0 = self.shoot(&zero).0;
        let mut a = DMatrix::zeros(nr + rows.len(), nr);
        let mut rhs = DVector::zeros(nr + rows.len());
        for i in 0..nr {
            a.view_mut((0, i), (nr, 1)).copy_from(&(self.shoot(&unit(i)).0 - &c0));
        }
        rhs.rows_mut(0, nr).copy_from(&(-&c0));
        for (k, (row, value)) in rows.iter().enumerate() {
            a.set_row(nr + k, &row.transpose());
            rhs[nr + k] = *value;
        }
        let u = a
            .clone()
            .svd(true, true)
            .solve(&rhs, 1e-13)
            .map_err(|e| PolishFailure(format!("stick–slip polish: the stuck orbit's least squares failed ({e}); the LCP's orbit is kept")))?;
        let (r, states) = self.shoot(&u);
        self.residual = r.amax();
        self.correction = self.residual;
        self.iterations = 1;
        self.states = states;
        self.monodromy = a.view((0, 0), (nr, nr)) + DMatrix::identity(nr, nr);
        Ok(())
    }

    /// The permanently stuck orbit: fitted at the LCP's slider constant `c`, then moved (if
    /// needed) by the constant force shift per unit constant into |f| ≤ μN over the period.
    pub(super) fn converge_stuck(&mut self, c: f64) -> Result<(), PolishFailure> {
        let samples = 4096;
        let force_range = |o: &Self| {
            let f: Vec<f64> = (0..samples).map(|i| o.contact(o.start + i as f64 * o.period / samples as f64).0).collect();
            (f.iter().copied().fold(f64::INFINITY, f64::min), f.iter().copied().fold(f64::NEG_INFINITY, f64::max))
        };
        self.fit_stuck(c + 1.0)?;
        let (lo1, _) = force_range(self);
        self.fit_stuck(c)?;
        let (lo, hi) = force_range(self);
        let (slip, per_unit) = (self.flows.slip, lo1 - lo);
        if hi - lo >= 2.0 * slip {
            return Err(PolishFailure(format!(
                "stick–slip polish: the LCP says stuck all period, but the stuck orbit's holding force spans {:.6e} > 2μN = {:.6e}; the LCP's orbit is kept",
                hi - lo,
                2.0 * slip
            )));
        }
        // Shift so that lo ≥ −μN and hi ≤ μN with the least move of the constant.
        let shift = if hi > slip {
            slip - hi
        } else if lo < -slip {
            -slip - lo
        } else {
            0.0
        };
        if shift != 0.0 && per_unit.abs() > 0.0 {
            self.fit_stuck(c + shift / per_unit)?;
        }
        Ok(())
    }
}

/// Converges and verifies `orbit` (stuck all period: at the slider constant `c`).
pub(super) fn fit(mut orbit: StickSlipOrbit, c: f64) -> Result<StickSlipOrbit, PolishFailure> {
    if orbit.times.is_empty() && orbit.first == Slide::Stick {
        orbit.converge_stuck(c)?
    } else {
        orbit.converge()?
    }
    orbit.verify()?;
    Ok(orbit)
}

/// The orbit of the topology the exact flows settle on from `seed` (time, phase, augmented
/// state; at rest stuck at t = 0 without one); None when the march does not settle.
pub(super) fn marched(fl: &Flows, period: f64, seed: Option<(f64, Slide, DVector<f64>)>, c: f64) -> Option<Result<StickSlipOrbit, PolishFailure>> {
    let (t0, phase, y) = seed.unwrap_or_else(|| (0.0, Slide::Stick, fl.augment(0.0, &[])));
    let topo = settle(fl, period, t0, phase, y)?;
    let m = topo.events.len();
    if m == 0 {
        return Some(fit(StickSlipOrbit::new(fl.clone(), period, topo.start, topo.first, vec![], vec![]), c));
    }
    // Run i: the phase after event i, until event i + 1; the origin in the middle of the longest.
    let end = |i: usize| if i + 1 < m { topo.events[i + 1].0 } else { topo.events[0].0 + period };
    let longest = (0..m).max_by(|&a, &b| (end(a) - topo.events[a].0).total_cmp(&(end(b) - topo.events[b].0))).unwrap_or(0);
    let start = 0.5 * (topo.events[longest].0 + end(longest));
    let order: Vec<usize> = (1..=m).map(|i| (longest + i) % m).collect();
    let times = order.iter().map(|&i| start + (topo.events[i].0 - start).rem_euclid(period)).collect();
    let slides = order.iter().map(|&i| topo.events[i].1).collect();
    Some(fit(StickSlipOrbit::new(fl.clone(), period, start, topo.events[longest].1, slides, times), c))
}
