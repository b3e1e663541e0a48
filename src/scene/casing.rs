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
use super::BuildError;
use crate::model::Harmonic;

/// The checked `[casing]` section.
#[derive(Clone, Debug, PartialEq)]
pub struct Casing {
    pub lobes: u32,
    pub depth: f64,
    pub radius: f64,
    /// Stagger γ [rad].
    pub stagger: f64,
    /// φ0 [rad].
    pub phase: f64,
}

impl Casing {
    /// Checks the section against the excitation frequency ω (= EO·Ω when `speed` is given).
    pub fn from_spec(spec: &super::CasingSpec, frequency: f64) -> Result<Casing, BuildError> {
        if spec.lobes < 1 {
            return Err(BuildError::field("casing.lobes", format!("is {}, must be ≥ 1 (the engine order)", spec.lobes)));
        }
        // The negated comparisons below refuse NaN as well.
        if !(spec.depth.is_finite() && spec.depth >= 0.0) {
            return Err(BuildError::field("casing.depth", format!("is {}, must be finite and ≥ 0", spec.depth)));
        }
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
            check_speed(speed, spec.lobes, frequency)?;
        }
        Ok(Casing { lobes: spec.lobes, depth: spec.depth, radius: spec.radius, stagger: spec.stagger.to_radians(), phase: spec.phase })
    }

    /// Arc coordinate s along the direction of rotation of a point (x, y) of a blade section
    /// twisted by `twist` [rad] (see the module documentation).
    pub fn arc(&self, x: f64, y: f64, twist: f64) -> f64 {
        let (st, ct) = twist.sin_cos();
        let (sg, cg) = self.stagger.sin_cos();
        // e_θ = −sin γ·u + cos γ·n, u = (cos τ, sin τ), n = (−sin τ, cos τ).
        let e = (-sg * ct - cg * st, -sg * st + cg * ct);
        x * e.0 + y * e.1
    }

    /// φ_i = φ0 + EO·s/R.
    pub fn phase_at(&self, arc: f64) -> f64 {
        self.phase + self.lobes as f64 * arc / self.radius
    }

    /// The obstacle motion term of a contact at arc coordinate s: −δ·cos(ω t + φ_i).
    pub fn motion(&self, arc: f64) -> Harmonic {
        Harmonic { amplitude: -self.depth, harmonic: 1, phase: self.phase_at(arc) }
    }
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
