//! A casing profile sampled over one turn (`[casing] profile = "casing.csv"`), turned into the
//! Fourier series the engine takes.
//!
//! The file: a header naming the angle's unit, `angle_deg,clearance` or `angle_rad,clearance`,
//! then one `angle,clearance change` line per sample (length unit of the scene; `#` comments and
//! blank lines skipped). The N samples must be uniformly spaced from angle 0 over one turn,
//! θ_j = j·2π/N, and either stop short of 2π (the turn closes on itself) or end with a sample at
//! exactly 2π whose value equals the first one's (it is then dropped); anything else is not a
//! periodic profile and is refused, naming the file, the line and the remedy.
//!
//! The real DFT of the samples, c_k = (2/N) Σ_j g_j e^{−ikθ_j} (k = 0 and N/2 with 1/N), gives
//! Δg(θ) = Σ_k |c_k|·cos(kθ + arg c_k), the trigonometric interpolant of the samples: exact at
//! every sample, and for a smooth profile off the samples within the aliasing error
//! 2·Σ_{|k| ≥ N/2} |ĝ_k| of its true coefficients ĝ_k (Trefethen, "Spectral Methods in MATLAB",
//! ch. 2). Every order the grid resolves (0..=N/2) is kept except those below
//! [`DROP_RELATIVE`] of the largest amplitude: they are round-off of the transform, and each kept
//! order is one motion term per contact.
use super::BuildError;
use super::casing::CasingTerm;
use crate::periodic::PeriodFft;
use std::f64::consts::PI;
use std::path::Path;

/// Orders whose amplitude is below this fraction of the largest one are dropped (round-off).
pub const DROP_RELATIVE: f64 = 1e-13;

/// Relative tolerance on the uniform spacing and on the closing sample's angle.
const ANGLE_TOL: f64 = 1e-9;

/// The samples of `path` (angles in rad, values), checked.
pub fn read_profile(path: &Path) -> Result<(Vec<f64>, Vec<f64>), BuildError> {
    let name = path.display().to_string();
    let field = |line: usize| format!("casing.profile ({name}, line {line})");
    let text = std::fs::read_to_string(path)
        .map_err(|e| BuildError::field("casing.profile", format!("{name}: cannot read the file ({e}); give a CSV path relative to the scene file")))?;
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (hl, header) = lines.next().ok_or_else(|| BuildError::field(field(1), "the file is empty; expected a header angle_deg,clearance then the samples"))?;
    let scale = match header.split(',').next().map(str::trim) {
        Some("angle_deg") => PI / 180.0,
        Some("angle_rad") => 1.0,
        _ => {
            return Err(BuildError::field(
                field(hl),
                format!("header is \"{header}\"; expected angle_deg,clearance or angle_rad,clearance (the unit of the angles)"),
            ));
        }
    };
    let (mut angles, mut values, mut at) = (Vec::new(), Vec::new(), Vec::new());
    for (ln, l) in lines {
        let cols: Vec<&str> = l.split(',').map(str::trim).collect();
        let parsed = match cols.as_slice() {
            [a, v] => a.parse::<f64>().ok().zip(v.parse::<f64>().ok()),
            _ => None,
        };
        let Some((a, v)) = parsed.filter(|(a, v)| a.is_finite() && v.is_finite()) else {
            return Err(BuildError::field(field(ln), format!("is \"{l}\"; expected two finite numbers: angle,clearance change")));
        };
        angles.push(a * scale);
        values.push(v);
        at.push(ln);
    }
    if values.len() < 3 {
        return Err(BuildError::field(field(hl), format!("has {} samples; give at least 3 over one turn", values.len())));
    }
    // A closing sample at 2π must repeat the first: then it is dropped.
    let last = angles.len() - 1;
    if (angles[last] - 2.0 * PI).abs() <= ANGLE_TOL * 2.0 * PI {
        let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
        if (values[last] - values[0]).abs() > 1e-9 * scale {
            let message = format!(
                "closes the turn at 2π with clearance {} but starts at {} (line {}): the profile is not periodic; make the last value equal the first, or stop the samples short of 2π",
                values[last], values[0], at[0]
            );
            return Err(BuildError::field(field(at[last]), message));
        }
        angles.pop();
        values.pop();
    }
    let n = values.len();
    for (j, &a) in angles.iter().enumerate() {
        let expected = j as f64 * 2.0 * PI / n as f64;
        if (a - expected).abs() > ANGLE_TOL * 2.0 * PI {
            let message = format!(
                "has angle {:.9} rad where the uniform grid of {n} samples over one turn has {expected:.9} rad: the samples must start at 0 and be uniformly spaced, ending short of 2π or with the first value repeated at 2π; resample the profile",
                a
            );
            return Err(BuildError::field(field(at[j]), message));
        }
    }
    Ok((angles, values))
}

/// The series Σ_k a_k cos(kθ + φ_k) of uniformly spaced samples over one turn (see the module
/// documentation for which orders are kept).
pub fn series(values: &[f64]) -> Vec<CasingTerm> {
    let n = values.len();
    let spectrum = PeriodFft::new(n).forward(values);
    let mut terms: Vec<CasingTerm> = spectrum
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let weight = if k == 0 || 2 * k == n { 1.0 } else { 2.0 } / n as f64;
            let c = c * weight;
            CasingTerm { order: k as u32, amplitude: c.norm(), phase: c.arg() }
        })
        .collect();
    let largest = terms.iter().fold(0.0f64, |m, t| m.max(t.amplitude));
    terms.retain(|t| t.amplitude > DROP_RELATIVE * largest);
    terms
}

/// The profile's series, read from `spec.profile` relative to `dir`.
pub fn profile_series(file: &str, dir: &Path) -> Result<Vec<CasingTerm>, BuildError> {
    let (_, values) = read_profile(&dir.join(file))?;
    Ok(series(&values))
}
