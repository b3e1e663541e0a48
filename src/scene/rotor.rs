//! The rotor's frame: the rotation axis, for a contact's radial normal (`normal = "radial"`) and
//! its angular position θ_i, whose casing clearance it meets.
//!
//! A generated blade turns about the engine axis e_a of its tip section (`[casing] stagger`, see
//! [`super::casing`]) through the point at radius R = `casing.radius` below the mid-chord tip
//! node: MC is at θ = 0 and radius R, and θ grows along the direction of rotation e_θ. A Matrix
//! Market scene gives the axis (`casing.axis`, rotation by the right-hand rule, and
//! `casing.center`, a point of it); θ = 0 is then the first positioned contact's radial direction.
use super::casing::Casing;
use super::{BuildError, CasingSpec};
use crate::fe::Blade;

type V3 = [f64; 3];

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// The rotation axis (a point, a unit direction) and the direction of θ = 0, if fixed.
#[derive(Clone, Debug)]
pub(super) struct Rotor {
    center: V3,
    axis: V3,
    zero: Option<V3>,
}

impl Rotor {
    /// The blade's rotor: axis −e_a (so that axis × e_z = e_θ) through (0, 0, L − R).
    pub fn of_blade(blade: &Blade, casing: &Casing) -> Rotor {
        let (a, _) = casing.rotation_frame(blade.params.twist_deg.to_radians());
        Rotor { center: [0.0, 0.0, blade.params.length - casing.radius], axis: [-a[0], -a[1], 0.0], zero: Some([0.0, 0.0, 1.0]) }
    }

    /// A Matrix Market scene's rotor from `casing.axis` and `casing.center`, if given.
    pub fn of_spec(spec: &CasingSpec) -> Result<Option<Rotor>, BuildError> {
        let Some(axis) = spec.axis else { return Ok(None) };
        let length = norm(axis);
        if !(length.is_finite() && length > 0.0) {
            return Err(BuildError::field("casing.axis", format!("is {axis:?}, a direction needs a finite nonzero length; give e.g. [0, 0, 1]")));
        }
        let center = spec.center.unwrap_or([0.0; 3]);
        if center.iter().any(|v| !v.is_finite()) {
            return Err(BuildError::field("casing.center", format!("is {center:?}, must be finite")));
        }
        Ok(Some(Rotor { center, axis: axis.map(|v| v / length), zero: None }))
    }

    /// The component of `p − center` normal to the axis.
    fn radial_vector(&self, p: V3) -> V3 {
        let r = [p[0] - self.center[0], p[1] - self.center[1], p[2] - self.center[2]];
        let along = dot(r, self.axis);
        [r[0] - along * self.axis[0], r[1] - along * self.axis[1], r[2] - along * self.axis[2]]
    }

    /// The unit radial direction at `p`; refused for a point on the axis (`field` names it).
    pub fn radial(&self, field: &str, p: V3) -> Result<V3, BuildError> {
        let r = self.radial_vector(p);
        let (length, scale) = (norm(r), norm([p[0] - self.center[0], p[1] - self.center[1], p[2] - self.center[2]]));
        if !(length > 1e-9 * scale.max(f64::MIN_POSITIVE)) {
            let message = format!(
                "the node at {p:?} lies on the rotation axis (through {:?} along {:?}), where no radial direction exists; give normal = [nx, ny, nz]",
                self.center, self.axis
            );
            return Err(BuildError::field(field, message));
        }
        Ok(r.map(|v| v / length))
    }

    /// The unit direction of rotation e_θ = axis × e_r at `p` (right-hand rule about the axis).
    pub fn tangential(&self, field: &str, p: V3) -> Result<V3, BuildError> {
        Ok(cross(self.axis, self.radial(field, p)?))
    }

    /// θ of `p` about the axis, from the direction of θ = 0 (set by the first point asked for
    /// when the scene does not fix it).
    pub fn angle(&mut self, field: &str, p: V3) -> Result<f64, BuildError> {
        let r = self.radial(field, p)?;
        let zero = *self.zero.get_or_insert(r);
        let ahead = cross(self.axis, zero);
        Ok(dot(r, ahead).atan2(dot(r, zero)))
    }
}
