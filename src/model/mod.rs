//! The mechanical model: M x'' + C x' + K x = f(t) − Bᵀ z on the circle of period T = 2π/ω,
//! with m unilateral contacts (src/formulation.md §1).
//!
//! Sign conventions (user-facing, the paper's λ = −force, g = −gap):
//! - contact `i` acts along a unit normal n_i over the model's DOFs, row i of B (sparse, its
//!   [`Contact::row`]): B_i x ≤ gap(t); a contact on one DOF d with direction s ∈ {+1, −1} is
//!   the one-entry row s·e_dᵀ;
//! - its clearance is gap(t) − B_i x ≥ 0 and its force z ≥ 0 is compressive: it pushes the
//!   structure by −B_iᵀ z.
//!
//! Units are the user's, as long as they are consistent (e.g. kg, N/m, m, s; or t, N/mm, mm, s);
//! a scene may name them ([`Units`]), for labels only.
mod friction;
mod matrix;
mod spectrum;
pub mod units;
mod validate;

pub use friction::{Friction, Rubbing};
pub use matrix::Matrix;
pub use units::{Labels, Quantity, Units};
pub use validate::ModelError;

use std::f64::consts::PI;

/// One cosine term `amplitude·cos(harmonic·ω·t + phase)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Harmonic {
    pub amplitude: f64,
    /// Multiple of the fundamental ω (0 is a constant term).
    pub harmonic: u32,
    /// Phase [rad].
    pub phase: f64,
}

impl Harmonic {
    pub fn value(&self, omega: f64, t: f64) -> f64 {
        self.amplitude * (self.harmonic as f64 * omega * t + self.phase).cos()
    }
    /// d/dt of [`Harmonic::value`].
    pub fn rate(&self, omega: f64, t: f64) -> f64 {
        let w = self.harmonic as f64 * omega;
        -self.amplitude * w * (w * t + self.phase).sin()
    }
}

/// An external force term on one DOF: f[dof] += amplitude·cos(harmonic·ω·t + phase).
#[derive(Clone, Debug, PartialEq)]
pub struct Force {
    pub dof: usize,
    pub term: Harmonic,
}

/// How a contact transmits force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Compliance {
    /// Signorini: clearance ≥ 0, force ≥ 0, clearance·force = 0.
    Rigid,
    /// Penalty: force = stiffness·max(0, penetration).
    Compliant { stiffness: f64 },
}

/// A unilateral contact along a unit normal against an obstacle at clearance gap(t).
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    /// Row i of B, sparse: (DOF, coefficient) pairs of a unit normal (Σ coefficient² = 1, each
    /// DOF once). The contact keeps B_i x ≤ gap(t); `[(d, 1.0)]` is x[d] ≤ gap(t) and
    /// `[(d, -1.0)]` is x[d] ≥ −gap(t).
    pub row: Vec<(usize, f64)>,
    /// Static clearance.
    pub gap: f64,
    pub compliance: Compliance,
    /// Obstacle motion: gap(t) = gap + Σ motion terms. Empty for a static obstacle.
    pub motion: Vec<Harmonic>,
}

impl Contact {
    /// A contact on one DOF: `direction` +1 keeps x[dof] ≤ gap, −1 keeps x[dof] ≥ −gap.
    pub fn on_dof(dof: usize, direction: f64, gap: f64, compliance: Compliance) -> Contact {
        Contact { row: vec![(dof, direction)], gap, compliance, motion: Vec::new() }
    }
    /// The normal displacement B_i x (for a one-entry row exactly ±x[d]).
    pub fn normal_displacement(&self, x: &[f64]) -> f64 {
        self.along(|d| x[d])
    }
    /// B_i v for a vector given entry by entry (a column of a matrix, a complex sample, …); a
    /// one-entry row multiplies its one entry by ±1 alone, bit-identical to the DOF's value.
    pub fn along<T>(&self, v: impl Fn(usize) -> T) -> T
    where
        T: std::ops::Mul<f64, Output = T> + std::iter::Sum<T>,
    {
        match self.row.as_slice() {
            [(d, c)] => v(*d) * *c,
            row => row.iter().map(|&(d, c)| v(d) * c).sum(),
        }
    }
    /// f −= B_iᵀ z: the compressive force z pushes the structure against its normal.
    pub fn push_back(&self, z: f64, f: &mut [f64]) {
        for &(d, c) in &self.row {
            f[d] -= c * z;
        }
    }
    /// The DOF that labels the contact in outputs: the row's largest |coefficient| (the first
    /// of equals), so a one-entry row's own DOF.
    pub fn label_dof(&self) -> usize {
        label_of(&self.row).0
    }
    /// The clearance gap(t) of the obstacle, at zero displacement.
    pub fn gap_at(&self, omega: f64, t: f64) -> f64 {
        self.gap + self.motion.iter().map(|h| h.value(omega, t)).sum::<f64>()
    }
    /// The clearance at the grid instants t_j = j·(periods·2π/ω)/instants of `periods` forcing
    /// periods (`angles` of that grid): [`Contact::gap_at`] there, for any ω. Each term's angle
    /// harmonic·ω·t_j = 2π·(harmonic·periods·j mod instants)/instants is reduced exactly and read
    /// from the table, so a sample costs a few products per term instead of a cosine (the real
    /// blade's 17 contacts × 13 casing harmonics × 1024 instants were a third of a sweep point's
    /// solve, issue 23).
    pub fn gap_samples(&self, angles: &GridAngles, periods: usize) -> Vec<f64> {
        let instants = angles.0.len();
        let mut gap = vec![self.gap; instants];
        for h in self.motion.iter().filter(|_| instants > 0) {
            let (sin_phase, cos_phase) = h.phase.sin_cos();
            // The index advance per instant, reduced modulo the grid (u128: no overflow).
            let advance = (u128::from(h.harmonic) * periods as u128 % instants as u128) as usize;
            let mut index = 0usize;
            for g in gap.iter_mut() {
                let (sin_a, cos_a) = angles.0[index];
                *g += h.amplitude * (cos_a * cos_phase - sin_a * sin_phase);
                index += advance;
                if index >= instants {
                    index -= instants;
                }
            }
        }
        gap
    }
    pub fn is_rigid(&self) -> bool {
        matches!(self.compliance, Compliance::Rigid)
    }
}

/// (sin, cos) of 2π·i/k for i in 0..k: the angles of a grid of k instants over the period, shared
/// by every contact's [`Contact::gap_samples`].
#[derive(Clone, Debug)]
pub struct GridAngles(Vec<(f64, f64)>);

impl GridAngles {
    pub fn new(instants: usize) -> GridAngles {
        let step = 2.0 * PI / instants.max(1) as f64;
        GridAngles((0..instants).map(|i| (i as f64 * step).sin_cos()).collect())
    }
}

/// The DOF of a row's largest |coefficient| (the first of equals) and that coefficient's sign
/// (+1 or −1): a one-entry row's DOF and direction; (0, +1) for an empty row.
pub fn label_of(row: &[(usize, f64)]) -> (usize, i32) {
    let mut best: Option<(usize, f64)> = None;
    for &(d, c) in row {
        if best.is_none_or(|b| c.abs() > b.1.abs()) {
            best = Some((d, c));
        }
    }
    best.map_or((0, 1), |(d, c)| (d, if c < 0.0 { -1 } else { 1 }))
}

/// M, C (optional), K: the structure's n×n matrices.
#[derive(Clone, Debug)]
pub struct Structure {
    pub mass: Matrix,
    pub stiffness: Matrix,
    /// `None`: no damping term is assembled at all.
    pub damping: Option<Matrix>,
}

impl Structure {
    pub fn n(&self) -> usize {
        self.mass.nrows()
    }
}

/// The effects a model calls for; only these are assembled and computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Effects {
    pub damping: bool,
    pub forcing: bool,
    pub contact: bool,
    pub compliance: bool,
    pub moving_obstacle: bool,
    pub friction: bool,
}

impl Effects {
    /// Names as they appear in the result's `effects` list.
    pub fn names(&self) -> Vec<&'static str> {
        let all = [
            (self.damping, "damping"),
            (self.forcing, "forcing"),
            (self.contact, "contact"),
            (self.compliance, "compliance"),
            (self.moving_obstacle, "moving_obstacle"),
            (self.friction, "friction"),
        ];
        all.iter().filter(|(on, _)| *on).map(|(_, n)| *n).collect()
    }
}

/// A complete periodic contact model.
#[derive(Clone, Debug)]
pub struct Model {
    pub structure: Structure,
    pub forces: Vec<Force>,
    pub contacts: Vec<Contact>,
    /// Coulomb friction contacts (src/formulation.md §9); empty: none is assembled.
    pub frictions: Vec<Friction>,
    /// Rubbing in gross slip on contacts (src/formulation.md §9): friction along each contact's
    /// counter-face motion, proportional to its normal force; empty: none.
    pub rubbing: Vec<Rubbing>,
    /// Fundamental angular frequency ω [rad/s]; the period is T = 2π/ω.
    pub frequency: f64,
}

impl Model {
    pub fn n(&self) -> usize {
        self.structure.n()
    }
    pub fn period(&self) -> f64 {
        2.0 * PI / self.frequency
    }
    /// External force vector f(t).
    pub fn force_at(&self, t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
        for f in &self.forces {
            out[f.dof] += f.term.value(self.frequency, t);
        }
    }
    pub fn effects(&self) -> Effects {
        Effects {
            damping: self.structure.damping.is_some(),
            forcing: self.forces.iter().any(|f| f.term.amplitude != 0.0),
            contact: !self.contacts.is_empty(),
            compliance: self.contacts.iter().any(|c| !c.is_rigid()),
            moving_obstacle: self.contacts.iter().any(|c| !c.motion.is_empty()),
            friction: !self.frictions.is_empty(),
        }
    }
    /// The massless DOFs (sorted): a zero diagonal of M. After [`Model::validate`] their rows
    /// and columns of M are zero and K holds them (src/formulation.md §4.1).
    pub fn massless_dofs(&self) -> Vec<usize> {
        (0..self.n()).filter(|&d| self.structure.mass.get(d, d) <= 0.0).collect()
    }
    /// Whether contact `c` acts on a massless DOF: its force is then finite and statically
    /// transmitted, like a compliant one (same-instant pairing).
    pub fn contact_is_massless(&self, c: &Contact) -> bool {
        c.row.iter().all(|&(dof, _)| dof < self.n() && self.structure.mass.get(dof, dof) <= 0.0)
    }
    /// The highest harmonic of ω in the forcing or in any obstacle motion.
    pub fn highest_harmonic(&self) -> u32 {
        let f = self.forces.iter().map(|f| f.term.harmonic);
        let g = self.contacts.iter().flat_map(|c| c.motion.iter().map(|h| h.harmonic));
        f.chain(g).max().unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::{Compliance, Contact, GridAngles, Harmonic};

    /// The grid samples equal the cosine series evaluated term by term at t_j = j·p·T/k
    /// ([`Contact::gap_samples`] against [`Contact::gap_at`]), for one and two forcing periods,
    /// harmonics past k/2 included (their angles wrap around the table).
    #[test]
    fn gap_samples_equal_the_series_at_the_grid_instants() {
        let mut c = Contact::on_dof(0, 1.0, 1.2e-5, Compliance::Rigid);
        c.motion = (0..13).map(|o| Harmonic { amplitude: -1e-6 / (1.0 + o as f64), harmonic: 2 * o, phase: 0.3 * o as f64 }).collect();
        let omega = 2300.0;
        for (k, periods) in [(64, 1), (96, 2), (1024, 1)] {
            let samples = c.gap_samples(&GridAngles::new(k), periods);
            let period = periods as f64 * 2.0 * std::f64::consts::PI / omega;
            let worst = (0..k).map(|j| (samples[j] - c.gap_at(omega, j as f64 * period / k as f64)).abs()).fold(0.0, f64::max);
            eprintln!("k = {k}, {periods} period(s): worst difference {worst:.2e} m");
            assert!(worst <= 1e-18, "k = {k}: {worst:e}");
        }
    }
}
