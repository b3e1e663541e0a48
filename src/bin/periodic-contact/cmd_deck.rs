//! `deck SCENE.toml -o JOB.inp`: the scene's generated blade as a CalculiX deck.
use crate::{Failure, ensure_writable, write_output};
use periodic_contact::scene::Scene;
use std::path::Path;

pub fn run(scene: &Path, output: &Path) -> Result<(), Failure> {
    ensure_writable(output, "--output")?;
    let (s, _) = Scene::load(scene).map_err(|e| Failure::input(e.to_string()))?;
    let file = scene.display().to_string();
    let blade = s.generator_blade(&file).map_err(|e| Failure::input(e.to_string()))?.ok_or_else(|| {
        Failure::input(format!(
            "{file}: structure.generator: is missing; `deck` writes the mesh of a blade generator (structure.generator = {{ kind = \"blade\", … }})"
        ))
    })?;
    write_output(output, &blade.calculix_deck())?;
    let job = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    eprintln!(
        "wrote {} ({} nodes, {} elements); `ccx {job}` in its folder writes {job}.sti, {job}.mas, {job}.dof",
        output.display(),
        blade.nodes.len(),
        blade.elements.len()
    );
    Ok(())
}
