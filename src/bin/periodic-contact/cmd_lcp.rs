//! `lcp FILE.dat`: a raw LCP in Siconos' format, solved by lexicographic Lemke.
use crate::{Failure, write_output};
use periodic_contact::lcp::{Lemke, LemkeSettings, dat};
use std::path::Path;

pub fn run(file: &Path, output: &Path) -> Result<(), Failure> {
    let (a, q) = dat::read_dat(file).map_err(|e| Failure::input(e.to_string()))?;
    let sol = Lemke::new(LemkeSettings::default()).solve(&a, &q);
    let json = serde_json::json!({
        "file": file.display().to_string(),
        "size": q.len(),
        "status": sol.outcome.name(),
        "z": sol.z,
        "w": sol.w,
        "pivots": sol.info.pivots,
        "residual": sol.info.residual,
        "relative_error": sol.info.relative_error,
        "time_s": sol.info.time_s,
    });
    write_output(output, &serde_json::to_string_pretty(&json).expect("json"))?;
    if sol.outcome == periodic_contact::lcp::LcpOutcome::Solved { Ok(()) } else { Err(Failure::solver(format!("{}: {}", file.display(), sol.outcome.name()))) }
}
