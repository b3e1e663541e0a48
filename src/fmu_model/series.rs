//! A solved configuration ([`Solution`]): one interpolant per output slot
//! ([`crate::analysis::interpolant::Series`]) and, with `polish`, the polished orbit that
//! replaces the interpolants of displacement, velocity, force and gap.
use super::Config;
use super::variables::Output;
pub(crate) use crate::analysis::interpolant::Series;
use crate::analysis::polish::PolishedOrbit;
use crate::periodic::OutputMap;
use std::sync::Arc;

/// A solved configuration: one series per output slot.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Solution {
    pub(super) config: Config,
    pub(super) period: f64,
    pub(super) h: f64,
    pub(super) omega: f64,
    pub(super) k: usize,
    pub(super) series: Vec<Series>,
    pub(super) pivots: i32,
    pub(super) residual: f64,
    pub(super) active_set: Vec<usize>,
    pub(super) warnings: Vec<String>,
    /// `continuation::amplitude` of the response (a jump's "before").
    pub(super) amplitude: f64,
    /// Jumps off a branch since initialisation, this solve's included.
    pub(super) jumps: u32,
    /// The polished orbit (parameter `polish`), or `None` (not asked, or it fell back).
    pub(super) polished: Option<Arc<PolishedOrbit>>,
}

impl Solution {
    /// Overwrites the values and derivatives of displacement, velocity, force and gap at τ by the
    /// polished orbit's (exact between the instants). Derivatives: velocity, acceleration, the
    /// clearance rate; a force's by a central difference of ±1e-7·T.
    pub(super) fn eval_polished(&self, orbit: &PolishedOrbit, outputs: &[Output], map: Option<&OutputMap>, tau: f64, out: &mut [f64], der: &mut [f64]) {
        let (y, a) = (orbit.state(tau), orbit.acceleration(tau));
        let n = y.len() / 2;
        let user = |d: usize, v: &nalgebra::DVector<f64>, off: usize| crate::analysis::polish::user_value(map, d, v, off, n);
        let dt = 1e-7 * self.period;
        for (slot, q) in outputs.iter().enumerate() {
            let value = match *q {
                Output::Displacement(d) => user(d, &y, 0).zip(user(d, &y, n)),
                Output::Velocity(d) => user(d, &y, n).zip(user(d, &a, 0)),
                Output::Force(i) => Some((orbit.contact_force(i, tau), (orbit.contact_force(i, tau + dt) - orbit.contact_force(i, tau - dt)) / (2.0 * dt))),
                Output::Gap(i) => Some((orbit.clearance_at(i, tau), orbit.clearance_rate(i, tau))),
                _ => None,
            };
            if let Some((v, d)) = value {
                out[slot] = v;
                der[slot] = d;
            }
        }
    }

    pub(super) fn max_harmonic(&self) -> usize {
        self.series.iter().map(Series::max_harmonic).max().unwrap_or(0)
    }
}
