//! Restricts the FMU binary's exports to the 34 FMI 2 functions. The library is built with the
//! CLI's features (one build for the workspace, nothing recompiled when switching between the CLI
//! and the FMU), so its C API (the `pc_*` functions of include/periodic_contact.h) is linked in:
//! rustc lists those symbols as global in its own version script, and GNU ld lets an exact name
//! beat a wildcard, so this script names each of them local (`fmi2*` stays global).
//! `tests/fmu_host.rs` checks the result with `nm -D`.
use std::path::{Path, PathBuf};

fn main() {
    let header = Path::new(env!("CARGO_MANIFEST_DIR")).join("../include/periodic_contact.h");
    println!("cargo:rerun-if-changed={}", header.display());
    let text = std::fs::read_to_string(&header).expect("read include/periodic_contact.h");
    let mut names: Vec<&str> = Vec::new();
    for (i, _) in text.match_indices("pc_") {
        let name_len = text[i..].find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(text.len() - i);
        let after = text[i + name_len..].trim_start();
        let word_start = i == 0 || !text[..i].ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_');
        if word_start && after.starts_with('(') {
            names.push(&text[i..i + name_len]);
        }
    }
    names.sort_unstable();
    names.dedup();
    let locals: String = names.iter().map(|n| format!("    {n};\n")).collect();
    let map = format!("{{\n  global: fmi2*;\n  local:\n{locals}    *;\n}};\n");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR")).join("fmi2.map");
    std::fs::write(&out, map).expect("write the version script");
    println!("cargo:rustc-cdylib-link-arg=-Wl,--version-script={}", out.display());
}
