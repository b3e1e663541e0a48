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

/// M positive definite, or positive semi-definite with its null space on whole DOFs (a massless
/// boundary, src/formulation.md §4.1): those DOFs have a zero row and column of M, the rest of M
/// is positive definite, and K is positive definite on them (they are held statically, so that
/// σ2 M + σ1 C + K stays invertible).
fn check_mass(model: &Model) -> Result<(), ModelError> {
    let s = &model.structure;
    if s.mass.is_positive_definite() {
        return Ok(());
    }
    let n = s.n();
    let massless = model.massless_dofs();
    if let Some(&d) = massless.iter().find(|&&d| s.mass.get(d, d) < 0.0) {
        return Err(ModelError::new(
            format!("structure.mass[{d}][{d}]"),
            format!("is {}: the mass is not positive definite (a mass must be ≥ 0)", s.mass.get(d, d)),
        ));
    }
    let scale = (0..n).map(|d| s.mass.get(d, d).abs()).fold(0.0f64, f64::max);
    let mut off = None;
    s.mass.for_each(|i, j, v| {
        if off.is_none() && v.abs() > 1e-14 * scale && (massless.binary_search(&i).is_ok() || massless.binary_search(&j).is_ok()) {
            off = Some((i.min(j), i.max(j), v));
        }
    });
    if let Some((i, j, v)) = off {
        return Err(ModelError::new(
            format!("structure.mass[{i}][{j}]"),
            format!(
                "is {v}, but DOF {} has no mass on its diagonal: a positive semi-definite mass has a zero row and column there",
                if massless.binary_search(&i).is_ok() { i } else { j }
            ),
        ));
    }
    let massive: Vec<usize> = (0..n).filter(|d| massless.binary_search(d).is_err()).collect();
    if massive.is_empty() {
        return Err(ModelError::new(
            "structure.mass",
            "is not positive definite: it is zero, no DOF carries mass, so there is no dynamics to solve (a static problem)",
        ));
    }
    if massless.is_empty() || !s.mass.block(&massive, &massive).is_positive_definite() {
        return Err(ModelError::new(
            "structure.mass",
            format!(
                "is not positive definite{}, and not only on whole massless DOFs: every DOF must carry mass, or be massless with a zero row and column of M \
                 (a massless boundary, src/formulation.md §4.1); correct the mass matrix, or reduce the model ([reduction])",
                null_direction(model)
            ),
        ));
    }
    if let Some(&d) = massless.iter().find(|&&d| s.stiffness.get(d, d) == 0.0) {
        return Err(ModelError::new(
            format!("structure.mass[{d}][{d}]"),
            format!(
                "is 0 and structure.stiffness[{d}][{d}] is 0: DOF {d}{} carries neither mass nor stiffness, so nothing determines it; give it mass or stiffness, or remove it",
                contacts_on(model, &[d]).map(|c| format!(" ({c})")).unwrap_or_default()
            ),
        ));
    }
    if !s.stiffness.block(&massless, &massless).is_positive_definite() {
        return Err(ModelError::new(
            "structure.stiffness",
            format!(
                "is not positive definite on the massless DOFs {massless:?}: they are held by stiffness alone (σ2 M + σ1 C + K must stay invertible); clamp or stiffen them, or give them mass"
            ),
        ));
    }
    Ok(())
}

/// Largest model size whose singular mass is diagnosed (a dense eigendecomposition).
const DIAGNOSED_DOFS: usize = 600;

/// Where a singular M has no mass, for its message: " (eigenvalue λ along DOFs […]; contact[i]
/// acts on DOF d)" from the eigenvector of M's smallest eigenvalue, or "" past
/// [`DIAGNOSED_DOFS`].
fn null_direction(model: &Model) -> String {
    let n = model.n();
    if n > DIAGNOSED_DOFS {
        return String::new();
    }
    let Ok(eig) = model.structure.mass.to_dense().self_adjoint_eigen(faer::Side::Lower) else { return String::new() };
    let (values, vectors) = (eig.S().column_vector(), eig.U());
    // Eigenvalues come in ascending order: column 0 is the direction without mass.
    let largest = (0..n).map(|i| vectors[(i, 0)].abs()).fold(0.0, f64::max);
    let dofs: Vec<usize> = (0..n).filter(|&i| vectors[(i, 0)].abs() >= 0.1 * largest).collect();
    let contacts = contacts_on(model, &dofs).map(|c| format!("; {c}")).unwrap_or_default();
    format!(" (eigenvalue {:e} along DOFs {dofs:?}{contacts})", values[0])
}

/// "contact[i] acts on DOF d, …" for every contact whose row touches one of `dofs`.
fn contacts_on(model: &Model, dofs: &[usize]) -> Option<String> {
    let named: Vec<String> = model
        .contacts
        .iter()
        .enumerate()
        .flat_map(|(i, c)| c.row.iter().filter(|(d, _)| dofs.contains(d)).map(move |(d, _)| format!("contact[{i}] acts on DOF {d}")))
        .collect();
    (!named.is_empty()).then(|| named.join(", "))
}

/// Largest |‖n‖ − 1| accepted for a contact normal (the scene normalises; others must too).
const UNIT_TOL: f64 = 1e-9;

/// Row i of B: DOFs in range, each once, finite coefficients, unit length.
fn check_row(i: usize, row: &[(usize, f64)], n: usize) -> Result<(), ModelError> {
    if row.is_empty() {
        return Err(ModelError::new(format!("contact[{i}].normal"), "is empty; give the contact a DOF (dof = …) or a normal over a node's DOFs"));
    }
    for (e, &(d, c)) in row.iter().enumerate() {
        if d >= n {
            return Err(ModelError::new(format!("contact[{i}].dof"), format!("is {d}, the model has DOFs 0 to {} (use one of them)", n - 1)));
        }
        if row[..e].iter().any(|&(o, _)| o == d) {
            return Err(ModelError::new(format!("contact[{i}].normal"), format!("names DOF {d} twice; give each DOF of the normal once")));
        }
        check_finite(format!("contact[{i}].normal[{e}]"), c)?;
    }
    let norm = row.iter().map(|&(_, c)| c * c).sum::<f64>().sqrt();
    if !((norm - 1.0).abs() <= UNIT_TOL) {
        let message = if row.len() == 1 {
            format!("is {}, must be +1 or -1", row[0].1)
        } else {
            format!("has length {norm}, must be a unit normal (divide each coefficient by the length)")
        };
        let field = if row.len() == 1 { "direction" } else { "normal" };
        return Err(ModelError::new(format!("contact[{i}].{field}"), message));
    }
    Ok(())
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
        check_mass(self)?;
        self.validate_frequency()?;
        for (i, f) in self.forces.iter().enumerate() {
            if f.dof >= n {
                return Err(ModelError::new(format!("force[{i}].dof"), format!("is {}, the model has DOFs 0 to {} (use one of them)", f.dof, n - 1)));
            }
            check_finite(format!("force[{i}].amplitude"), f.term.amplitude)?;
            check_finite(format!("force[{i}].phase"), f.term.phase)?;
        }
        for (i, c) in self.contacts.iter().enumerate() {
            check_row(i, &c.row, n)?;
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
            f.check(i, n, self.contacts.len())?;
        }
        for (i, r) in self.rubbing.iter().enumerate() {
            r.check(i, n, self.contacts.len())?;
        }
        Ok(())
    }
}

impl From<ModelError> for crate::Error {
    fn from(e: ModelError) -> Self {
        crate::Error::input(e.to_string())
    }
}
