//! `export SCENE -o DIR`: the model a scene solves, exactly as the solver holds it (reduced,
//! damped, contacts on the reduced DOFs), as Matrix Market files and a JSON manifest, so that an
//! independent reference (validation/exact_flow.py) can solve the very same equations.
use crate::{Failure, ensure_output_folder};
use periodic_contact::fe::mtx::write_matrix_market;
use periodic_contact::model::{Compliance, Harmonic, Matrix, Model};
use periodic_contact::periodic::PeriodicProblem;
use periodic_contact::reduction::to_sparse;
use periodic_contact::scene::Scene;
use serde_json::{Value, json};
use std::path::Path;

/// One cosine term as the manifest writes it: its amplitude, harmonic and phase, and the same
/// term as cos/sin coefficients (a·cos(hωt + φ) = a cos φ·cos hωt − a sin φ·sin hωt).
fn harmonic_json(h: &Harmonic) -> Value {
    json!({
        "harmonic": h.harmonic,
        "amplitude": h.amplitude,
        "phase": h.phase,
        "cos": h.amplitude * h.phase.cos(),
        "sin": -h.amplitude * h.phase.sin(),
    })
}

fn write_matrix(dir: &Path, name: &str, a: &Matrix) -> Result<String, Failure> {
    let file = format!("{name}.mtx");
    let path = dir.join(&file);
    write_matrix_market(&path, &to_sparse(a), false).map_err(|e| Failure::input(format!("{}: cannot write: {e}", path.display())))?;
    Ok(file)
}

/// B (m×n, one row per contact, general Matrix Market).
fn write_contact_rows(dir: &Path, model: &Model) -> Result<String, Failure> {
    let (m, n) = (model.contacts.len(), model.n());
    let mut b = faer::Mat::<f64>::zeros(m, n);
    for (i, c) in model.contacts.iter().enumerate() {
        for &(d, v) in &c.row {
            b[(i, d)] = v;
        }
    }
    write_matrix(dir, "B", &Matrix::Dense(b))
}

/// The manifest: every number of the model besides the matrices, with the files' names.
fn manifest(problem: &PeriodicProblem, built: &periodic_contact::scene::SceneModel, files: Value) -> Value {
    let model = problem.model();
    let units = &built.labels.units;
    let contacts: Vec<Value> = model
        .contacts
        .iter()
        .enumerate()
        .map(|(i, c)| {
            json!({
                "row": c.row,
                "scene_row": problem.user_row(i),
                "label_dof": built.contact_dofs.get(i),
                "gap_mean": c.gap + c.motion.iter().filter(|h| h.harmonic == 0).map(|h| h.value(0.0, 0.0)).sum::<f64>(),
                "gap_static": c.gap,
                "gap_harmonics": c.motion.iter().map(harmonic_json).collect::<Vec<_>>(),
                "stiffness": match c.compliance { Compliance::Compliant { stiffness } => Some(stiffness), Compliance::Rigid => None },
                "pairing": problem.pairing_at(i).to_string(),
            })
        })
        .collect();
    let forces: Vec<Value> = model.forces.iter().map(|f| json!({ "dof": f.dof, "term": harmonic_json(&f.term) })).collect();
    // Each output as (model DOF, coefficient) terms, keyed as the result's JSON keys them.
    let outputs: Vec<Value> = problem
        .outputs()
        .dofs()
        .into_iter()
        .map(|d| {
            let row = problem.output_map().map_or_else(|| vec![(d, 1.0)], |m| m.rows[&d].clone());
            json!({ "key": d.to_string(), "name": built.labels.dof(d), "row": row })
        })
        .collect();
    json!({
        "format": "periodic-contact model export 1",
        "equation": "M x'' + C x' + K x = f(t) - B^T z, z_i = k_i max(0, B_i x - g_i(t)) (compliant) or Signorini (rigid: stiffness null); g_i(t) = gap_static + sum of gap_harmonics a cos(h w t + phase) = gap_mean + sum (cos cos(h w t) + sin sin(h w t)) over h >= 1; f_dof(t) += a cos(h w t + phase)",
        "n": model.n(),
        "m": model.contacts.len(),
        "omega": model.frequency,
        "period": model.period(),
        "period_multiple": problem.period_multiple(),
        "massless_dofs": model.massless_dofs(),
        "units": { "length": units.length(), "force": units.force(), "time": units.time(), "mass": units.mass(), "omega": format!("rad/{}", units.time()) },
        "files": files,
        "contacts": contacts,
        "forces": forces,
        "outputs": outputs,
        "discretization": { "scheme": problem.discretization().scheme.to_string(), "steps": problem.discretization().steps },
        "reduction": built.reduction.as_ref().map(|r| json!({ "n_boundary": r.n_boundary(), "n_modes": r.n_modes() })),
    })
}

pub fn run(scene: &Path, dir: &Path) -> Result<(), Failure> {
    ensure_output_folder(dir, "--output")?;
    let (s, folder) = Scene::load(scene).map_err(|e| Failure::input(e.to_string()))?;
    let built = s.build_in(&scene.display().to_string(), &folder).map_err(|e| Failure::input(e.to_string()))?;
    let problem = &built.problem;
    let model = problem.model();
    if !model.frictions.is_empty() || !model.rubbing.is_empty() {
        // A rubbing contact's force row differs from its gap row (n − μ·sign(V)·t): B alone would misstate it.
        return Err(Failure::input(format!(
            "{}: export writes contacts along normals only; the scene's friction or rubbing contacts ([[friction]]) are not exported: remove them to export the rest",
            scene.display()
        )));
    }
    let st = &model.structure;
    let files = json!({
        "mass": write_matrix(dir, "M", &st.mass)?,
        "stiffness": write_matrix(dir, "K", &st.stiffness)?,
        "damping": st.damping.as_ref().map(|c| write_matrix(dir, "C", c)).transpose()?,
        "contact_rows": if model.contacts.is_empty() { None } else { Some(write_contact_rows(dir, model)?) },
    });
    let text = serde_json::to_string_pretty(&manifest(problem, &built, files)).map_err(|e| Failure::solver(e.to_string()))?;
    let path = dir.join("model.json");
    std::fs::write(&path, text).map_err(|e| Failure::input(format!("{}: cannot write: {e}", path.display())))?;
    eprintln!("exported {}: n = {}, m = {} contacts, ω = {} → {}", scene.display(), model.n(), model.contacts.len(), model.frequency, path.display());
    Ok(())
}
