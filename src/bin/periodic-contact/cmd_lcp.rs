//! `lcp FILE.dat`: a raw LCP in Siconos' format.
//!
//! A raw LCP carries no structure, so it is looked for: when the dense matrix is exactly
//! block-circulant (blocks of size m = 1..=8, tolerance 0) it is solved like the engine's own
//! LCPs (`auto`: Lemke up to N = 256, above it block pivoting with FFT products, Lemke as the
//! fallback). Otherwise (or with `--method lemke`) dense lexicographic Lemke.
use crate::{Failure, ensure_writable, write_output};
use periodic_contact::lcp::{BlockCirculant, BlockPivoting, LcpOutcome, Lemke, LemkeSettings, PivotingSettings, dat};
use periodic_contact::lcp::{LcpMethod, solve_circulant_lcp};
use std::path::Path;
use std::time::Instant;

/// Largest block size tried by the structure detection.
const MAX_BLOCK: usize = 8;

pub fn run(file: &Path, output: &Path, method: &str, tolerance: f64) -> Result<(), Failure> {
    let method: LcpMethod = method.parse().map_err(|e| Failure::input(format!("--method: {e}")))?;
    if method == LcpMethod::Shooting {
        return Err(Failure::input(
            "--method: \"shooting\" needs the time-stepping map of a scene, which a raw LCP does not carry; use `periodic-contact solve SCENE` (its `auto` shoots first), or --method auto here".to_string(),
        ));
    }
    if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
        return Err(Failure::input(format!("--tolerance: is {tolerance}, must be in (0, 1)")));
    }
    ensure_writable(output, "--output")?;
    let (a, q) = dat::read_dat(file).map_err(|e| Failure::input(e.to_string()))?;
    let start = Instant::now();
    let circulant = if method == LcpMethod::Lemke { None } else { BlockCirculant::detect(&a, MAX_BLOCK) };
    let detect_s = start.elapsed().as_secs_f64();
    let (structure, sol) = match &circulant {
        Some(c) => {
            drop(a);
            (format!("block-circulant (k = {}, m = {})", c.k(), c.m()), solve_circulant_lcp(c, &q, method, tolerance, None))
        }
        None => {
            let sol = match method {
                LcpMethod::Pivoting => BlockPivoting::new(PivotingSettings { certify_tol: tolerance, ..PivotingSettings::default() }).solve(&a, &q),
                _ => Lemke::new(LemkeSettings { certify_tol: tolerance, ..LemkeSettings::default() }).solve(&a, &q),
            };
            ("dense".to_string(), sol)
        }
    };
    let total_s = start.elapsed().as_secs_f64();
    let json = serde_json::json!({
        "file": file.display().to_string(),
        "size": q.len(),
        "structure": structure,
        "method": method.name(),
        "tolerance": tolerance,
        "status": sol.outcome.name(),
        "z": sol.z,
        "w": sol.w,
        "pivots": sol.info.pivots,
        "residual": sol.info.residual,
        "relative_error": sol.info.relative_error,
        // Structure detection plus solve (reading the file is not included).
        "time_s": total_s,
        "detect_time_s": detect_s,
        "solve_time_s": sol.info.time_s,
    });
    write_output(output, &serde_json::to_string_pretty(&json).expect("json"))?;
    if sol.outcome == LcpOutcome::Solved {
        return Ok(());
    }
    let tried = if circulant.is_some() { format!("{structure}, --method {}", method.name()) } else { format!("dense, --method {}", method.name()) };
    Err(Failure::solver(format!(
        "{}: {} after {} pivots ({tried}; residual {:.2e}, tolerance {tolerance:e}); {}",
        file.display(),
        sol.outcome.name(),
        sol.info.pivots,
        sol.info.residual,
        remedy(sol.outcome, method)
    )))
}

/// What to try next for a raw LCP that ended without a certified solution.
fn remedy(outcome: LcpOutcome, method: LcpMethod) -> &'static str {
    match (outcome, method) {
        (LcpOutcome::NonFiniteData, _) => "the matrix or q holds NaN or ±∞: fix the file",
        (LcpOutcome::Inaccurate, _) => {
            "a basis was found but its residual misses the tolerance (an ill-conditioned matrix): loosen --tolerance, or rescale the rows of M and q"
        }
        (_, LcpMethod::Pivoting) => {
            "block pivoting has no convergence guarantee outside P-matrices: retry with --method lemke (lexicographic, the certified reference)"
        }
        (LcpOutcome::RayTermination, _) => {
            "Lemke ended on a secondary ray: if the matrix is copositive-plus the LCP has no solution; check the sign convention w = Mz + q (Siconos' .dat), or try --method pivoting"
        }
        _ => "the pivot budget ran out on a degenerate or ill-posed LCP: check that M is not near-singular, or try --method pivoting",
    }
}
