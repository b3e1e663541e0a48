//! An out-of-round casing seen from the rotating blade: scene sugar that turns `[casing]` into
//! obstacle motion terms of the contacts. The engine stays generic: a contact only knows its
//! clearance gap(t) = gap + Σ amplitude·cos(harmonic·ω·t + phase).
//!
//! ## Model and sign conventions
//!
//! The casing is fixed; its clearance above the undeformed blade tip varies around the
//! circumference with `lobes` = L lobes of depth δ: at the stationary angle θ the radial
//! clearance is g0 − δ·cos(L·θ) (a lobe crest, clearance g0 − δ, at θ = 0, 2π/L, …). The rotor
//! turns at Ω in the direction of increasing θ. A blade point whose arc coordinate along the
//! direction of rotation is s (measured at the tip from the stacking axis, the z axis of the
//! blade generator, where MC sits) is at θ(t) = Ω·t + s/R, R the casing radius. Its clearance is
//!
//! ```text
//! gap_i(t) = g0_i − δ·cos(EO·Ω·t + EO·s_i/R + φ0)          EO = L
//!          = g0_i − δ·cos(ω·t + φ_i),   φ_i = φ0 + EO·s_i/R,   ω = EO·Ω
//! ```
//!
//! with g0_i the contact's own `gap`. So ω, the fundamental of the periodic problem, is the
//! lobe-passing frequency EO·Ω (the period is the lobe-passing period 2π/(EO·Ω)), and each
//! contact gets one motion term `{ amplitude = −δ, harmonic = 1, phase = φ_i }`. A node with
//! s_i > 0 leads: it meets each crest earlier, by s_i/(R·Ω) seconds (phase lead EO·s_i/R).
//!
//! Arc coordinate of a generator node at (x, y, z) in the blade's axes (x chordwise and y through
//! the thickness at the root, z radial; twist τ(z) = twist·z/L about +z): with the local chord
//! direction u = (cos τ, sin τ), the local thickness direction n = (−sin τ, cos τ) and the stagger
//! γ (angle from the engine axis to the chord), the direction of rotation is
//! e_θ = −sin γ·u + cos γ·n and s = (x, y)·e_θ. For γ > 0 the leading edge (chord position
//! −c/2) leads by (c/2)·sin γ: the compressor-rotor convention (chord LE→TE pointing downstream
//! and against the rotation). Contacts on Matrix Market DOFs give s explicitly (`arc`).
//!
//! ## Casings of any shape
//!
//! `harmonics = [{ order, amplitude, phase }, …]` gives the clearance change as a Fourier series
//! in the casing's stationary angle θ, Δg(θ) = Σ_k a_k·cos(k·θ + φ_k); `profile = "casing.csv"`
//! gives it sampled over one turn, and a real DFT turns the samples into that series
//! ([`super::profile`]). Contact i at angular position θ_i (about the rotation axis, from its
//! node's coordinates) is at θ = Ω·t + θ_i, so
//!
//! ```text
//! gap_i(t) = g0_i + Σ_k a_k·cos(k·Ω·t + k·θ_i + φ_k),   ω = L·Ω,
//! ```
//!
//! one motion term `{ amplitude = a_k, harmonic = k/L, phase = k·θ_i + φ_k }` per order: every
//! order must be a multiple of the symmetry order L = `lobes` (default 1). The engine stays
//! generic: a contact's obstacle motion is its `Vec<Harmonic>`, whatever made it.
//!
//! The angular position: for a generated blade, θ_i = atan2(r·e_θ, r·e_r) with r the node's
//! position from the rotation axis (the axis runs along e_a = cos γ·u + sin γ·n of the tip
//! section, at radius R below MC, so MC has θ = 0 and radius R); for a Matrix Market contact with
//! `position`, about `casing.axis` through `casing.center`, θ = 0 at the first positioned
//! contact. The cosine-lobe form (`depth`) keeps its small-angle arc s_i/R (results unchanged).
use super::BuildError;
use crate::model::Harmonic;

/// One term a·cos(order·θ + phase) of the clearance change in the casing's angle θ.
#[derive(Clone, Debug, PartialEq)]
pub struct CasingTerm {
    pub order: u32,
    pub amplitude: f64,
    pub phase: f64,
}

/// The casing's clearance law over its angle.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// L cosine lobes of depth δ: −δ·cos(L·θ + φ0).
    Lobes { depth: f64 },
    /// Σ a_k cos(k θ + φ_k): `harmonics`, or a sampled `profile` after its DFT.
    Series(Vec<CasingTerm>),
}

/// The checked `[casing]` section.
#[derive(Clone, Debug, PartialEq)]
pub struct Casing {
    pub lobes: u32,
    pub shape: Shape,
    pub radius: f64,
    /// Stagger γ [rad].
    pub stagger: f64,
    /// φ0 [rad].
    pub phase: f64,
}

impl Casing {
    /// Checks the section against the excitation frequency ω (= EO·Ω when `speed` is given);
    /// `profile` is the series of the sampled profile, read by the caller, if any.
    pub fn from_spec(spec: &super::CasingSpec, frequency: f64, profile: Option<Vec<CasingTerm>>) -> Result<Casing, BuildError> {
        let given = [spec.depth.is_some(), spec.harmonics.is_some(), spec.profile.is_some()];
        if given.iter().filter(|g| **g).count() != 1 {
            return Err(BuildError::field(
                "casing",
                "give exactly one shape: depth (cosine lobes), harmonics = [{ order, amplitude, phase }, …] or profile = \"file.csv\"",
            ));
        }
        let lobes = match (spec.lobes, spec.depth) {
            (Some(l), _) => l,
            (None, Some(_)) => return Err(BuildError::field("casing.lobes", "is missing; the cosine-lobe casing (depth) needs its number of lobes")),
            (None, None) => 1,
        };
        if lobes < 1 {
            return Err(BuildError::field("casing.lobes", format!("is {lobes}, must be ≥ 1 (the engine order)")));
        }
        // The negated comparisons below refuse NaN as well.
        if !(spec.radius.is_finite() && spec.radius > 0.0) {
            return Err(BuildError::field("casing.radius", format!("is {}, must be finite and > 0", spec.radius)));
        }
        if !(spec.stagger.is_finite() && spec.stagger.abs() <= 90.0) {
            return Err(BuildError::field("casing.stagger", format!("is {}, must be an angle within ±90 degrees", spec.stagger)));
        }
        if !spec.phase.is_finite() {
            return Err(BuildError::field("casing.phase", format!("is {}, must be finite", spec.phase)));
        }
        if let Some(speed) = spec.speed {
            check_speed(speed, lobes, frequency)?;
        }
        let shape = match (spec.depth, &spec.harmonics, profile) {
            (Some(depth), _, _) => {
                if !(depth.is_finite() && depth >= 0.0) {
                    return Err(BuildError::field("casing.depth", format!("is {depth}, must be finite and ≥ 0")));
                }
                Shape::Lobes { depth }
            }
            (None, Some(terms), _) => {
                let terms: Vec<CasingTerm> = terms.iter().map(|h| CasingTerm { order: h.order, amplitude: h.amplitude, phase: h.phase }).collect();
                Shape::Series(check_terms("casing.harmonics", &terms, lobes)?)
            }
            (None, None, Some(terms)) => Shape::Series(check_terms("casing.profile", &terms, lobes)?),
            (None, None, None) => return Err(BuildError::field("casing.profile", "was not read")),
        };
        if spec.phase != 0.0 && !matches!(shape, Shape::Lobes { .. }) {
            return Err(BuildError::field("casing.phase", "goes with depth (cosine lobes); a series gives each term its own phase"));
        }
        Ok(Casing { lobes, shape, radius: spec.radius, stagger: spec.stagger.to_radians(), phase: spec.phase })
    }

    /// Arc coordinate s along the direction of rotation of a point (x, y) of a blade section
    /// twisted by `twist` [rad] (see the module documentation).
    pub fn arc(&self, x: f64, y: f64, twist: f64) -> f64 {
        let (_, e) = self.rotation_frame(twist);
        x * e[0] + y * e[1]
    }

    /// The engine axis e_a and the direction of rotation e_θ in the (x, y) plane of a blade
    /// section twisted by `twist`: e_θ = −sin γ·u + cos γ·n, e_a = cos γ·u + sin γ·n.
    pub fn rotation_frame(&self, twist: f64) -> ([f64; 2], [f64; 2]) {
        let (st, ct) = twist.sin_cos();
        let (sg, cg) = self.stagger.sin_cos();
        // u = (cos τ, sin τ), n = (−sin τ, cos τ).
        ([cg * ct - sg * st, cg * st + sg * ct], [-sg * ct - cg * st, -sg * st + cg * ct])
    }

    /// φ_i = φ0 + EO·s/R.
    pub fn phase_at(&self, arc: f64) -> f64 {
        self.phase + self.lobes as f64 * arc / self.radius
    }

    /// The obstacle motion of a contact at arc coordinate s (cosine lobes: −δ·cos(ω t + φ_i))
    /// or at angle θ_i (a series: one term per order, harmonic k/L of ω = L·Ω).
    pub fn motion(&self, arc: f64, angle: f64) -> Vec<Harmonic> {
        match &self.shape {
            Shape::Lobes { depth } => vec![Harmonic { amplitude: -depth, harmonic: 1, phase: self.phase_at(arc) }],
            Shape::Series(terms) => {
                terms.iter().map(|t| Harmonic { amplitude: t.amplitude, harmonic: t.order / self.lobes, phase: t.order as f64 * angle + t.phase }).collect()
            }
        }
    }

    /// The clearance change Δg(θ) at the casing's angle θ.
    pub fn clearance_change(&self, theta: f64) -> f64 {
        match &self.shape {
            Shape::Lobes { depth } => -depth * (self.lobes as f64 * theta + self.phase).cos(),
            Shape::Series(terms) => terms.iter().map(|t| t.amplitude * (t.order as f64 * theta + t.phase).cos()).sum(),
        }
    }
}

/// Finite terms whose orders are multiples of L (ω = L·Ω must be their fundamental).
fn check_terms(field: &str, terms: &[CasingTerm], lobes: u32) -> Result<Vec<CasingTerm>, BuildError> {
    for (i, t) in terms.iter().enumerate() {
        if !t.amplitude.is_finite() || !t.phase.is_finite() {
            return Err(BuildError::field(format!("{field}[{i}]"), format!("has amplitude {} and phase {}, both must be finite", t.amplitude, t.phase)));
        }
        if t.order % lobes != 0 {
            let message = format!(
                "has order {} (amplitude {:e}), not a multiple of casing.lobes = {lobes}: ω = lobes·Ω would not be its fundamental; set lobes = 1 (or a divisor of every order)",
                t.order, t.amplitude
            );
            return Err(BuildError::field(format!("{field}[{i}]"), message));
        }
    }
    Ok(terms.to_vec())
}

/// `casing.speed`, when given, must be excitation.frequency / lobes.
fn check_speed(speed: f64, lobes: u32, frequency: f64) -> Result<(), BuildError> {
    if !(speed.is_finite() && speed > 0.0) {
        return Err(BuildError::field("casing.speed", format!("is {speed}, must be a finite angular speed > 0 [rad/s]")));
    }
    let expected = lobes as f64 * speed;
    if (expected - frequency).abs() > 1e-9 * expected {
        let message = format!(
            "is {speed} rad/s, so the lobe-passing frequency lobes·speed = {expected} rad/s, but excitation.frequency is {frequency}; set excitation.frequency = {expected} or drop casing.speed"
        );
        return Err(BuildError::field("casing.speed", message));
    }
    Ok(())
}
