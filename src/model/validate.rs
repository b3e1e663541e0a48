//! Input checks of a [`Model`]: every error names the field and the value.
use super::{Compliance, Matrix, Model};

/// A model that cannot be solved as given. `field` uses the scene's key paths
/// (`structure.mass`, `contact[1].dof`, …) so that the message points at the input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct ModelError {
    pub field: String,
    pub message: String,
}

impl ModelError {
    pub fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        ModelError { field: field.into(), message: message.into() }
    }
}

/// Relative asymmetry accepted in M, C and K (round-off of FE exports).
const SYMMETRY_TOL: f64 = 1e-10;

fn check_square(name: &str, a: &Matrix, n: usize) -> Result<(), ModelError> {
    if a.nrows() != n || a.ncols() != n {
        return Err(ModelError::new(name, format!("is {}×{}, expected {n}×{n} (the size of structure.mass)", a.nrows(), a.ncols())));
    }
    let mut bad = None;
    let mut scale = 0.0f64;
    a.for_each(|i, j, v| {
        if !v.is_finite() && bad.is_none() {
            bad = Some((i, j, v));
        }
        scale = scale.max(v.abs());
    });
    if let Some((i, j, v)) = bad {
        return Err(ModelError::new(format!("{name}[{i}][{j}]"), format!("is {v}, every entry must be finite")));
    }
    let mut asym = None;
    a.for_each(|i, j, v| {
        if asym.is_none() && i < j {
            let t = a.get(j, i);
            if (v - t).abs() > SYMMETRY_TOL * scale.max(f64::MIN_POSITIVE) {
                asym = Some((i, j, v, t));
            }
        }
    });
    if let Some((i, j, v, t)) = asym {
        return Err(ModelError::new(name, format!("is not symmetric: [{i}][{j}] = {v} but [{j}][{i}] = {t}")));
    }
    Ok(())
}

fn check_finite(field: String, v: f64) -> Result<(), ModelError> {
    if v.is_finite() { Ok(()) } else { Err(ModelError::new(field, format!("is {v}, must be finite"))) }
}

/// M positive definite: a Cholesky factorisation that succeeds (dense), or a sparse one.
fn check_positive_definite(name: &str, a: &Matrix) -> Result<(), ModelError> {
    let ok = match a {
        Matrix::Dense(m) => m.llt(faer::Side::Lower).is_ok(),
        Matrix::Sparse(s) => s.sp_cholesky(faer::Side::Lower).is_ok(),
    };
    if ok { Ok(()) } else { Err(ModelError::new(name, "is not positive definite (every DOF must carry mass)")) }
}

impl Model {
    /// ω alone: finite, > 0, and with a finite period (checked again when only ω changes).
    pub fn validate_frequency(&self) -> Result<(), ModelError> {
        if !(self.frequency.is_finite() && self.frequency > 0.0) {
            return Err(ModelError::new("excitation.frequency", format!("is {}, must be a finite angular frequency > 0 [rad/s]", self.frequency)));
        }
        // A subnormal ω (e.g. 1e-320) passes the test above but its period 2π/ω overflows, and
        // the instants t_j = j·T/k would start with 0·∞ = NaN (found by tests/props.rs).
        if !self.period().is_finite() {
            return Err(ModelError::new(
                "excitation.frequency",
                format!("is {:e}, too small: the period 2π/ω is not finite; rescale the time unit", self.frequency),
            ));
        }
        Ok(())
    }

    /// Checks dimensions, symmetry, definiteness, finiteness and index ranges.
    pub fn validate(&self) -> Result<(), ModelError> {
        let s = &self.structure;
        let n = s.n();
        if n == 0 {
            return Err(ModelError::new("structure.mass", "is empty: the model needs at least one DOF"));
        }
        check_square("structure.mass", &s.mass, n)?;
        check_square("structure.stiffness", &s.stiffness, n)?;
        if let Some(c) = &s.damping {
            check_square("damping", c, n)?;
        }
        check_positive_definite("structure.mass", &s.mass)?;
        self.validate_frequency()?;
        for (i, f) in self.forces.iter().enumerate() {
            if f.dof >= n {
                return Err(ModelError::new(format!("force[{i}].dof"), format!("is {}, the model has DOFs 0..{}", f.dof, n - 1)));
            }
            check_finite(format!("force[{i}].amplitude"), f.term.amplitude)?;
            check_finite(format!("force[{i}].phase"), f.term.phase)?;
        }
        for (i, c) in self.contacts.iter().enumerate() {
            if c.dof >= n {
                return Err(ModelError::new(format!("contact[{i}].dof"), format!("is {}, the model has DOFs 0..{}", c.dof, n - 1)));
            }
            if c.direction != 1.0 && c.direction != -1.0 {
                return Err(ModelError::new(format!("contact[{i}].direction"), format!("is {}, must be +1 or -1", c.direction)));
            }
            check_finite(format!("contact[{i}].gap"), c.gap)?;
            if c.gap < 0.0 {
                return Err(ModelError::new(format!("contact[{i}].gap"), format!("is {}, a static clearance must be ≥ 0 (move the reference instead)", c.gap)));
            }
            if let Compliance::Compliant { stiffness } = c.compliance {
                if !(stiffness.is_finite() && stiffness > 0.0) {
                    return Err(ModelError::new(format!("contact[{i}].stiffness"), format!("is {stiffness}, a contact stiffness must be finite and > 0")));
                }
                // The LCP holds the compliance 1/k: a subnormal k (1e-320) makes it infinite.
                if !(1.0 / stiffness).is_finite() {
                    return Err(ModelError::new(
                        format!("contact[{i}].stiffness"),
                        format!("is {stiffness:e}, too small: its compliance 1/k is not finite; rescale the units or remove the contact"),
                    ));
                }
            }
            for (h, m) in c.motion.iter().enumerate() {
                check_finite(format!("contact[{i}].motion[{h}].amplitude"), m.amplitude)?;
                check_finite(format!("contact[{i}].motion[{h}].phase"), m.phase)?;
            }
        }
        for (i, f) in self.frictions.iter().enumerate() {
            f.check(i, n)?;
        }
        Ok(())
    }
}

impl From<ModelError> for crate::Error {
    fn from(e: ModelError) -> Self {
        crate::Error::input(e.to_string())
    }
}
