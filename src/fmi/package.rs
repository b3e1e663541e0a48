//! The `.fmu` archive: a zip (deflate, forward slashes, no leading `/` or `./`) with
//! `modelDescription.xml` at the root, written to a temporary file and renamed into place.
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

/// One archive member.
pub struct Entry {
    /// Path inside the archive, e.g. `binaries/linux64/PeriodicContact.so`.
    pub name: String,
    pub data: Vec<u8>,
    /// Unix permissions (0o644 for data, 0o755 for the binary).
    pub mode: u32,
}

/// The FMI 2.0 platform folder of the machine we run on.
pub fn platform() -> Option<&'static str> {
    match (std::env::consts::OS, std::env::consts::ARCH) {
        ("linux", "x86_64") => Some("linux64"),
        ("linux", "x86") => Some("linux32"),
        ("windows", "x86_64") => Some("win64"),
        ("windows", "x86") => Some("win32"),
        ("macos", "x86_64") => Some("darwin64"),
        _ => None,
    }
}

/// Writes `out` with `modelDescription.xml` first, then `entries`.
pub fn write_fmu(out: &Path, model_description: &str, entries: &[Entry]) -> Result<()> {
    for e in entries {
        if e.name.starts_with('/') || e.name.starts_with("./") || e.name.contains('\\') || e.name.split('/').any(|p| p == ".." || p.is_empty()) {
            return Err(Error::input(format!("archive path {:?} is not a clean relative path with forward slashes", e.name)));
        }
    }
    let tmp = out.with_extension("fmu.tmp~");
    match write_zip(&tmp, out, model_description, entries) {
        Ok(()) => std::fs::rename(&tmp, out).map_err(|e| Error::io(format!("{}: cannot write: {e}", out.display()))),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// The archive into `tmp` (`out` names it in messages).
fn write_zip(tmp: &Path, out: &Path, model_description: &str, entries: &[Entry]) -> Result<()> {
    let file = std::fs::File::create(tmp).map_err(|e| Error::io(format!("{}: cannot create: {e}", tmp.display())))?;
    let mut zip = ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
    let z = |e: zip::result::ZipError| Error::io(format!("{}: {e}", out.display()));
    let w = |e: std::io::Error| Error::io(format!("{}: {e}", out.display()));
    zip.start_file("modelDescription.xml", options.unix_permissions(0o644)).map_err(z)?;
    zip.write_all(model_description.as_bytes()).map_err(w)?;
    for e in entries {
        zip.start_file(e.name.as_str(), options.unix_permissions(e.mode)).map_err(z)?;
        zip.write_all(&e.data).map_err(w)?;
    }
    zip.finish().map_err(z)?;
    Ok(())
}
