//! `fmu SCENE.toml -o NAME.fmu`: packages a scene with the FMI 2.0 co-simulation binary.
use crate::{Failure, ensure_writable};
use periodic_contact::fmu_model;
use std::path::{Path, PathBuf};

/// The environment variable that names the FMU binary (like `--binary`).
pub const BINARY_ENV: &str = "PERIODIC_CONTACT_FMU_BINARY";
const BINARY_FILE: &str = "libPeriodicContact.so";

/// `--binary`, else `$PERIODIC_CONTACT_FMU_BINARY`, else `libPeriodicContact.so` next to this
/// executable (the same `target/<profile>/` folder).
fn find_binary(explicit: Option<&Path>) -> Result<PathBuf, Failure> {
    if let Some(p) = explicit {
        return if p.is_file() { Ok(p.to_path_buf()) } else { Err(Failure::input(format!("--binary {}: no such file", p.display()))) };
    }
    if let Some(p) = std::env::var_os(BINARY_ENV).filter(|v| !v.is_empty()) {
        let p = PathBuf::from(p);
        return if p.is_file() { Ok(p) } else { Err(Failure::input(format!("{BINARY_ENV}={}: no such file", p.display()))) };
    }
    let exe = std::env::current_exe().map_err(|e| Failure::input(format!("cannot locate this executable: {e}")))?;
    let beside = exe.parent().map(|d| d.join(BINARY_FILE)).unwrap_or_else(|| PathBuf::from(BINARY_FILE));
    if beside.is_file() {
        return Ok(beside);
    }
    Err(Failure::input(format!(
        "the FMU binary {BINARY_FILE} was not found at {}; build it with `cargo build --release` \
         (it lands in target/release/), or name it with --binary PATH or {BINARY_ENV}=PATH",
        beside.display()
    )))
}

pub fn run(scene: &Path, output: &Path, binary: Option<&Path>) -> Result<(), Failure> {
    ensure_writable(output, "--output")?;
    let so = find_binary(binary)?;
    let guid = fmu_model::package(scene, &so, output)?;
    eprintln!("packaged {} with {} → {} (GUID {guid})", scene.display(), so.display(), output.display());
    Ok(())
}
