//! `package`: a scene, every file it references and the FMU binary into one `.fmu`.
//!
//! The referenced files (the scene's [`Scene::referenced_files`]) go into `resources/` at their
//! paths relative to the scene, so that `resources/scene.toml` finds them as the original scene
//! does. A path outside the scene's folder (absolute, or through `..`) is copied to
//! `resources/external/<i>/` and the packaged scene's field is rewritten to point there.
//! Every file is read before anything is written: on any error no `.fmu` is written.
use super::{ContactModel, MODEL_IDENTIFIER, SCENE_FILE};
use crate::error::{Error, Result};
use crate::fmi::package::Entry;
use crate::scene::{FileReference, Scene};
use std::path::{Component, Path};

/// Writes `out` (.fmu) for `scene_path`, with the FMU binary `binary`. Returns the GUID.
pub fn package(scene_path: &Path, binary: &Path, out: &Path) -> Result<String> {
    let file = scene_path.display().to_string();
    let text = std::fs::read_to_string(scene_path).map_err(|e| Error::io(format!("{file}: cannot read the scene: {e}")))?;
    let scene = Scene::parse(&text, &file)?;
    let dir = scene_path.parent().unwrap_or(Path::new(""));
    let (resources, scene_text) = referenced_entries(&scene, &text, dir, &file)?;
    let model = ContactModel::from_scene_text(&text, &file)?;
    model.desc.check().map_err(|e| e.context("internal error, the model description is invalid"))?;
    let (xml, guid) = crate::fmi::fmi2::xml::render(&model.desc);
    let so = std::fs::read(binary).map_err(|e| Error::io(format!("{}: cannot read the FMU binary: {e}", binary.display())))?;
    if !so.starts_with(b"\x7fELF") {
        return Err(Error::input(format!("{}: is not an ELF shared library", binary.display())));
    }
    let platform = crate::fmi::package::platform().ok_or_else(|| Error::input("this platform has no FMI 2.0 platform folder name"))?;
    let name = scene_path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut entries = vec![
        Entry { name: format!("binaries/{platform}/{MODEL_IDENTIFIER}.so"), data: so, mode: 0o755 },
        Entry { name: format!("resources/{SCENE_FILE}"), data: scene_text.into_bytes(), mode: 0o644 },
    ];
    entries.extend(resources);
    entries.push(Entry { name: "documentation/index.html".into(), data: model.documentation_html(&name).into_bytes(), mode: 0o644 });
    crate::fmi::package::write_fmu(out, &xml, &entries)?;
    Ok(guid)
}

/// The `resources/` entries of every referenced file, and the scene text to package (the original,
/// or with the fields of files outside the scene's folder rewritten).
fn referenced_entries(scene: &Scene, text: &str, dir: &Path, file: &str) -> Result<(Vec<Entry>, String)> {
    let mut entries: Vec<Entry> = Vec::new();
    let mut moved: Vec<(String, String)> = Vec::new();
    for (i, r) in scene.referenced_files().iter().enumerate() {
        let inside = r.files.iter().all(|f| is_inside(f));
        let new_value = format!("external/{i}/{}", Path::new(&r.value).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default());
        for f in &r.files {
            let data = read_referenced(r, f, dir, file)?;
            let name = if inside {
                format!("resources/{}", f.replace('\\', "/").trim_start_matches("./"))
            } else {
                // The file keeps what follows the value (a job name's extension).
                format!("resources/{new_value}{}", f.strip_prefix(r.value.as_str()).unwrap_or_default())
            };
            if !entries.iter().any(|e| e.name == name) {
                entries.push(Entry { name, data, mode: 0o644 });
            }
        }
        if !inside {
            moved.push((r.field.clone(), new_value));
        }
    }
    if moved.is_empty() {
        return Ok((entries, text.to_string()));
    }
    let mut table: toml::Table = toml::from_str(text).map_err(|e| Error::input(format!("{file}: {e}")))?;
    for (field, value) in &moved {
        set_field(&mut table, field, value).ok_or_else(|| Error::input(format!("{file}: internal error, cannot rewrite {field} for the FMU")))?;
    }
    let body = toml::to_string(&table).map_err(|e| Error::input(format!("{file}: internal error, cannot write the packaged scene: {e}")))?;
    let header = "# Packaged by periodic-contact: files outside the scene's folder were copied to external/ and their fields rewritten.\n";
    Ok((entries, format!("{header}{body}")))
}

/// The bytes of `f`, or an error naming the scene, the field, the file and the remedy.
fn read_referenced(r: &FileReference, f: &str, dir: &Path, file: &str) -> Result<Vec<u8>> {
    let path = dir.join(f);
    std::fs::read(&path).map_err(|e| {
        Error::io(format!(
            "{file}: {} = \"{}\": cannot read {}: {e}; the FMU carries every file the scene references in its resources/: \
             create the file or correct the path (relative to the scene's folder); no .fmu was written",
            r.field,
            r.value,
            path.display()
        ))
    })
}

/// A relative path below the scene's folder (no `..`, not absolute), which is not the packaged
/// scene's own name.
fn is_inside(f: &str) -> bool {
    let p = Path::new(f);
    p.components().all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
        && p.components().any(|c| matches!(c, Component::Normal(_)))
        && f != SCENE_FILE
}

/// Sets the string at the dotted `field` of `table`; `None` if the path is not there.
fn set_field(table: &mut toml::Table, field: &str, value: &str) -> Option<()> {
    let mut keys = field.split('.').peekable();
    let mut t = table;
    while let Some(k) = keys.next() {
        if keys.peek().is_none() {
            *t.get_mut(k)? = toml::Value::String(value.to_string());
            return Some(());
        }
        t = t.get_mut(k)?.as_table_mut()?;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_inside_the_scene_folder_are_kept_and_the_others_moved() {
        assert!(is_inside("M.mtx") && is_inside("data/M.mtx") && is_inside("./M.mtx"));
        assert!(!is_inside("../M.mtx") && !is_inside("/tmp/M.mtx") && !is_inside("a/../../M.mtx") && !is_inside(SCENE_FILE) && !is_inside(""));
        let mut t: toml::Table = toml::from_str("[structure]\nmass = { matrix_market = \"../M.mtx\" }\n").unwrap();
        set_field(&mut t, "structure.mass.matrix_market", "external/0/M.mtx").unwrap();
        assert_eq!(t["structure"]["mass"]["matrix_market"].as_str(), Some("external/0/M.mtx"));
        assert!(set_field(&mut t, "structure.damping.matrix_market", "x").is_none());
    }
}
