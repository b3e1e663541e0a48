//! Scene files (TOML): the user's description of a periodic contact problem.
//! Parsing checks types and keys; [`Scene::build`] checks values and builds the model: the
//! structure (dense rows, Matrix Market files or the blade generator), clamping, the
//! Craig–Bampton reduction, the casing, and the outputs in the user's numbering.
pub mod casing;
mod spec;

pub use casing::Casing;
pub use spec::*;

use crate::fe::{Blade, BladeSpec, DofMap};
use crate::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};
use crate::periodic::{OutputMap, OutputSelection, PeriodicProblem, SolverSettings};
use crate::reduction::{CraigBamptonOptions, DEFAULT_MODES, Damping, ReducedModel, ReductionError};
use crate::time::{Discretization, Pairing, Scheme};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A scene that cannot be used: names the file, the field and the value.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct SceneError {
    pub file: String,
    pub message: String,
}

impl SceneError {
    fn new(file: &str, message: impl Into<String>) -> Self {
        SceneError { file: file.to_string(), message: message.into() }
    }
}

/// A built scene: the problem to solve and what it was made from.
#[derive(Clone, Debug)]
pub struct SceneModel {
    /// Ready to solve. With a reduction its model is the reduced one; outputs and contact DOFs
    /// are reported in the scene's numbering either way.
    pub problem: PeriodicProblem,
    /// The full structure after clamping (`structure.fixed`), damping included when it is defined
    /// on the full model (`matrix` or `rayleigh`).
    pub full: Structure,
    /// Scene numbering (the matrices' or the generator's) → full (clamped) numbering.
    pub dofs: DofMap,
    /// The Craig–Bampton reduction, if `[reduction]`.
    pub reduction: Option<ReducedModel>,
    /// The checked casing, if `[casing]`.
    pub casing: Option<Casing>,
    /// The scene's DOF of each contact, in contact order.
    pub contact_dofs: Vec<usize>,
    /// Wall times of the set-up [s].
    pub timings: BuildTimings,
}

/// Wall times of [`Scene::build`] [s].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildTimings {
    /// Reading matrices or meshing and assembling the blade.
    pub structure: f64,
    /// The Craig–Bampton reduction (0 without).
    pub reduction: f64,
    pub total: f64,
}

/// Where the structure came from: named nodes exist only for a generator.
enum Source {
    Inline,
    Files,
    Blade(Box<Blade>),
}

impl Scene {
    /// Reads and parses a scene file. Relative paths inside it resolve against its folder.
    pub fn load(path: &Path) -> Result<(Scene, PathBuf), SceneError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::new(&file, format!("cannot read the scene file: {e}")))?;
        let scene = Scene::parse(&text, &file)?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok((scene, dir))
    }

    /// Parses scene text; `file` names the source in messages.
    pub fn parse(text: &str, file: &str) -> Result<Scene, SceneError> {
        toml::from_str::<Scene>(text).map_err(|e| SceneError::new(file, spec::explain_toml_error(&e)))
    }

    /// Sets the excitation frequency ω (with a casing, the rotation speed becomes ω / lobes).
    pub fn set_frequency(&mut self, omega: f64) {
        self.excitation.frequency = omega;
        if let Some(c) = &mut self.casing {
            c.speed = None;
        }
    }

    /// Builds the model and the problem, checking every value. `file` names the source in
    /// messages; relative Matrix Market paths resolve against its folder.
    pub fn to_problem(&self, file: &str) -> Result<PeriodicProblem, SceneError> {
        Ok(self.build(file)?.problem)
    }

    /// [`Scene::to_problem`] keeping what the problem was built from.
    pub fn build(&self, file: &str) -> Result<SceneModel, SceneError> {
        let dir = Path::new(file).parent().map(Path::to_path_buf).unwrap_or_default();
        self.build_in(file, &dir)
    }

    /// [`Scene::build`] with relative paths resolved against `dir`.
    pub fn build_in(&self, file: &str, dir: &Path) -> Result<SceneModel, SceneError> {
        let t0 = Instant::now();
        let err = |m: String| SceneError::new(file, m);

        // The structure in the scene's numbering.
        let (source, structure) = self.structure_source(dir).map_err(err)?;
        let t_structure = t0.elapsed().as_secs_f64();
        let n_user = structure.mass.nrows();
        let dense_inline = matches!(source, Source::Inline);

        // Damping defined on the full model (before clamping, same numbering).
        let damping_spec = self.damping.as_ref();
        let mut full = structure;
        let mut modal_ratios = None;
        let mut rayleigh = None;
        if let Some(d) = damping_spec {
            let given = [d.matrix.is_some(), d.rayleigh.is_some(), d.modal_ratios.is_some()].iter().filter(|b| **b).count();
            if given > 1 {
                return Err(err("damping: give one of matrix, rayleigh or modal_ratios, not several".into()));
            }
            if given == 0 {
                return Err(err(
                    "damping: the section needs matrix = [[…]] (or { matrix_market = … }), rayleigh = [alpha, beta] or modal_ratios = [ζ, …]".into()
                ));
            }
            if let Some(m) = &d.matrix {
                full.damping = Some(load_matrix("damping.matrix", m, dir).map_err(err)?);
            }
            if let Some([alpha, beta]) = d.rayleigh {
                if !(alpha.is_finite() && beta.is_finite()) {
                    return Err(err(format!("damping.rayleigh: [{alpha}, {beta}] must be finite")));
                }
                full.damping = Some(full.mass.lincomb(alpha, &full.stiffness, beta));
                rayleigh = Some((alpha, beta));
            }
            if let Some(z) = &d.modal_ratios {
                if self.reduction.is_none() {
                    return Err(err("damping.modal_ratios: needs a [reduction] section (the ratios apply to the reduced model's modes); use rayleigh or matrix on an unreduced model".into()));
                }
                if z.is_empty() {
                    return Err(err("damping.modal_ratios: is empty, give at least one ratio".into()));
                }
                if let Some((i, v)) = z.iter().enumerate().find(|(_, v)| !(v.is_finite() && **v >= 0.0)) {
                    return Err(err(format!("damping.modal_ratios[{i}]: is {v}, must be finite and ≥ 0")));
                }
                modal_ratios = Some(z.clone());
            }
        }
        if let Some(c) = &full.damping {
            if c.nrows() != n_user || c.ncols() != n_user {
                return Err(err(format!("damping.matrix: is {}×{}, expected {n_user}×{n_user} (the size of structure.mass)", c.nrows(), c.ncols())));
            }
        }
        if full.stiffness.nrows() != n_user || full.stiffness.ncols() != n_user {
            return Err(err(format!(
                "structure.stiffness: is {}×{}, expected {n_user}×{n_user} (the size of structure.mass)",
                full.stiffness.nrows(),
                full.stiffness.ncols()
            )));
        }

        // Clamping.
        let dofs = if self.structure.fixed.is_empty() {
            DofMap::identity(n_user)
        } else {
            let (s, map) = crate::fe::clamp_structure(&full, &self.structure.fixed).map_err(|e| err(format!("structure.fixed: {e}")))?;
            full = s;
            map
        };
        let clamped = !self.structure.fixed.is_empty();
        let resolver = Resolver { source: &source, dofs: &dofs, n_user };

        // Forces and contacts in the full numbering (user DOF kept for the labels).
        let k = self.discretization.steps;
        let mut forces = Vec::with_capacity(self.force.len());
        for (i, f) in self.force.iter().enumerate() {
            let field = format!("force[{i}]");
            let (_, d) = resolver.point(&field, f.dof, f.node.as_deref(), f.axis.as_deref()).map_err(err)?;
            if !f.amplitude.is_finite() {
                return Err(err(format!("{field}.amplitude: is {}, must be finite", f.amplitude)));
            }
            if !f.phase.is_finite() {
                return Err(err(format!("{field}.phase: is {}, must be finite", f.phase)));
            }
            if k >= 4 && 2 * f.harmonic as usize >= k {
                return Err(err(format!("{field}.harmonic: is {}, not resolved by steps = {k} (needs steps > {})", f.harmonic, 2 * f.harmonic)));
            }
            forces.push(Force { dof: d, term: Harmonic { amplitude: f.amplitude, harmonic: f.harmonic, phase: f.phase } });
        }
        let mut contacts = Vec::with_capacity(self.contact.len());
        let mut contact_dofs = Vec::with_capacity(self.contact.len());
        for (i, c) in self.contact.iter().enumerate() {
            let field = format!("contact[{i}]");
            let (u, d) = resolver.point(&field, c.dof, c.node.as_deref(), c.axis.as_deref()).map_err(err)?;
            contact_dofs.push(u);
            contacts.push(Contact {
                dof: d,
                direction: c.direction as f64,
                gap: c.gap,
                compliance: c.stiffness.map_or(Compliance::Rigid, |stiffness| Compliance::Compliant { stiffness }),
                motion: c.motion.iter().map(|h| Harmonic { amplitude: h.amplitude, harmonic: h.harmonic, phase: h.phase }).collect(),
            });
        }

        // The casing: one motion term per contact.
        let frequency = self.excitation.frequency;
        let casing = match &self.casing {
            None => None,
            Some(spec) => {
                if !(frequency.is_finite() && frequency > 0.0) {
                    return Err(err(format!("excitation.frequency: is {frequency}, must be a finite angular frequency > 0 [rad/s]")));
                }
                let casing = Casing::from_spec(spec, frequency).map_err(err)?;
                if contacts.is_empty() {
                    return Err(err("casing: there is no [[contact]] for the casing to act on".into()));
                }
                if let Some(arc) = &spec.arc {
                    if arc.len() != contacts.len() {
                        return Err(err(format!("casing.arc: has {} values, expected one per contact ({})", arc.len(), contacts.len())));
                    }
                    if let Some((i, v)) = arc.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                        return Err(err(format!("casing.arc[{i}]: is {v}, must be finite")));
                    }
                }
                for (i, c) in contacts.iter_mut().enumerate() {
                    let s = match (&spec.arc, &source) {
                        (Some(arc), _) => arc[i],
                        (None, Source::Blade(blade)) => {
                            // Full (clamped) DOF → scene DOF → the blade's unclamped DOF → node.
                            let node = blade.dofs.new_to_old[dofs.new_to_old[c.dof]] / 3;
                            let [x, y, z] = blade.nodes[node];
                            casing.arc(x, y, blade.params.twist_deg.to_radians() * z / blade.params.length)
                        }
                        (None, _) => {
                            return Err(err(format!(
                                "casing.arc: is missing; contact[{i}] is not on a blade generator's node, so give the arc position [m] of every contact along the rotation"
                            )));
                        }
                    };
                    c.motion.push(casing.motion(s));
                }
                Some(casing)
            }
        };

        // Outputs in the user's numbering.
        let outputs = match &self.output {
            Some(o) => {
                let list = |name: &str, l: &[DofSpec]| -> Result<Vec<usize>, String> {
                    l.iter().enumerate().map(|(i, d)| resolver.output(&format!("output.{name}[{i}]"), d)).collect()
                };
                OutputSelection {
                    displacement: list("displacement", &o.displacement).map_err(err)?,
                    velocity: list("velocity", &o.velocity).map_err(err)?,
                    acceleration: list("acceleration", &o.acceleration).map_err(err)?,
                    contacts: o.contacts,
                }
            }
            None if dense_inline => OutputSelection { displacement: dofs.new_to_old.clone(), velocity: vec![], acceleration: vec![], contacts: true },
            None => {
                // Large models: the contact and loaded DOFs, not every DOF.
                let mut d: Vec<usize> = contact_dofs.clone();
                d.extend(forces.iter().map(|f| dofs.new_to_old[f.dof]));
                d.sort_unstable();
                d.dedup();
                OutputSelection { displacement: d, velocity: vec![], acceleration: vec![], contacts: true }
            }
        };

        // The reduction, or the full model.
        let t_red = Instant::now();
        let (model, map, reduction) = match &self.reduction {
            None => {
                let model = Model { structure: full.clone(), forces, contacts, frequency };
                let map = clamped.then(|| {
                    let rows = outputs.dofs().into_iter().map(|u| (u, vec![(dofs.new_index(u).expect("checked"), 1.0)])).collect();
                    OutputMap { rows, contact_dofs: contact_dofs.clone(), effects: vec![] }
                });
                (model, map, None)
            }
            Some(r) => {
                if r.method != "craig-bampton" {
                    return Err(err(format!("reduction.method: is \"{}\", expected \"craig-bampton\"", r.method)));
                }
                let eta = r.modes.unwrap_or(DEFAULT_MODES);
                let mut boundary: Vec<usize> = Vec::new();
                for c in &contacts {
                    if !boundary.contains(&c.dof) {
                        boundary.push(c.dof);
                    }
                }
                for (i, e) in r.extra_boundary.iter().enumerate() {
                    let (_, d) = resolver.output_pair(&format!("reduction.extra_boundary[{i}]"), e).map_err(err)?;
                    if !boundary.contains(&d) {
                        boundary.push(d);
                    }
                }
                let damping = match (&modal_ratios, rayleigh, &full.damping) {
                    (Some(z), _, _) => Damping::ModalRatios(z.clone()),
                    (None, Some((alpha, beta)), _) => Damping::Rayleigh { alpha, beta },
                    (None, None, Some(c)) => Damping::Matrix(crate::reduction::to_sparse(c)),
                    (None, None, None) => Damping::None,
                };
                let undamped = Structure { mass: full.mass.clone(), stiffness: full.stiffness.clone(), damping: None };
                let opts = CraigBamptonOptions { modes: eta, ..Default::default() };
                let red = crate::reduction::reduce_structure(&undamped, &boundary, &opts, Some(&damping)).map_err(|e| {
                    err(match e {
                        ReductionError::TooManyModes { requested, internal } => {
                            format!("reduction.modes: is {requested}, but only {internal} internal DOFs remain besides the {} boundary DOFs", boundary.len())
                        }
                        ReductionError::Damping(m) => format!("damping: {m}"),
                        other => format!("reduction: {other}"),
                    })
                })?;
                let row = |d: usize| -> Vec<(usize, f64)> {
                    match red.reduced_dof(d) {
                        Some(b) => vec![(b, 1.0)],
                        None => red.basis_row(d).into_iter().enumerate().filter(|(_, c)| *c != 0.0).collect(),
                    }
                };
                let mut rforces = Vec::new();
                for f in &forces {
                    for (q, c) in row(f.dof) {
                        rforces.push(Force { dof: q, term: Harmonic { amplitude: f.term.amplitude * c, ..f.term.clone() } });
                    }
                }
                let rcontacts = contacts.iter().map(|c| Contact { dof: red.reduced_dof(c.dof).expect("contacts are boundary DOFs"), ..c.clone() }).collect();
                let model = Model { structure: red.structure(), forces: rforces, contacts: rcontacts, frequency };
                let rows = outputs.dofs().into_iter().map(|u| (u, row(dofs.new_index(u).expect("checked")))).collect();
                let map = OutputMap { rows, contact_dofs: contact_dofs.clone(), effects: vec!["reduction".into()] };
                (model, Some(map), Some(red))
            }
        };
        let t_reduction = if reduction.is_some() { t_red.elapsed().as_secs_f64() } else { 0.0 };
        model.validate().map_err(|e| err(e.to_string()))?;

        let d = &self.discretization;
        let scheme: Scheme = d.scheme.parse().map_err(|m: String| err(format!("discretization.scheme: {m}")))?;
        let pairing = match &d.pairing {
            Some(p) => Some(p.parse::<Pairing>().map_err(|m| err(format!("discretization.pairing: {m}")))?),
            None => None,
        };
        let disc = Discretization { scheme, steps: d.steps, pairing };
        let solver = SolverSettings::from_spec(self.solver.as_ref()).map_err(err)?;
        let problem = match map {
            None => {
                let n = model.n();
                for (name, list) in [("displacement", &outputs.displacement), ("velocity", &outputs.velocity), ("acceleration", &outputs.acceleration)] {
                    if let Some((i, d)) = list.iter().enumerate().find(|(_, d)| **d >= n) {
                        return Err(err(format!("output.{name}[{i}]: DOF {d} does not exist, the model has DOFs 0..{}", n - 1)));
                    }
                }
                PeriodicProblem::new(model, disc, outputs, solver).map_err(|e| err(e.to_string()))?
            }
            Some(map) => PeriodicProblem::new(model, disc, OutputSelection::default(), solver)
                .and_then(|p| p.with_output_map(outputs, map))
                .map_err(|e| err(e.to_string()))?,
        };
        Ok(SceneModel {
            problem,
            full,
            dofs,
            reduction,
            casing,
            contact_dofs,
            timings: BuildTimings { structure: t_structure, reduction: t_reduction, total: t0.elapsed().as_secs_f64() },
        })
    }

    /// Loads or generates the structure (M, K; no damping yet) in the scene's numbering.
    fn structure_source(&self, dir: &Path) -> Result<(Source, Structure), String> {
        let s = &self.structure;
        match (&s.generator, &s.mass, &s.stiffness) {
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => Err("structure: give either generator = { … } or mass and stiffness, not both".into()),
            (Some(table), None, None) => {
                let mut table = table.clone();
                let kind = table.remove("kind");
                match kind.as_ref().map(|k| k.as_str()) {
                    Some(Some("blade")) => {}
                    Some(Some(other)) => return Err(format!("structure.generator.kind: is \"{other}\", expected \"blade\"")),
                    Some(None) => return Err(format!("structure.generator.kind: is {}, expected \"blade\"", kind.expect("some"))),
                    None => return Err("structure.generator: needs kind = \"blade\"".into()),
                }
                let spec: BladeSpec = serde::Deserialize::deserialize(toml::Value::Table(table))
                    .map_err(|e: toml::de::Error| format!("structure.generator: {}", e.to_string().trim()))?;
                let params = spec.params().map_err(|e| format!("structure.generator: {}", e.to_string().trim_start_matches("blade generator: ")))?;
                let blade = Blade::generate(&params).map_err(|e| format!("structure.generator: {e}"))?;
                let structure = blade.structure();
                Ok((Source::Blade(Box::new(blade)), structure))
            }
            (None, Some(m), Some(k)) => {
                let inline = matches!(m, MatrixSpec::Dense(_)) && matches!(k, MatrixSpec::Dense(_));
                let mass = load_matrix("structure.mass", m, dir)?;
                let stiffness = load_matrix("structure.stiffness", k, dir)?;
                Ok((if inline { Source::Inline } else { Source::Files }, Structure { mass, stiffness, damping: None }))
            }
            (None, None, _) => Err("structure.mass: is missing (give mass and stiffness, or generator = { kind = \"blade\", … })".into()),
            (None, Some(_), None) => Err("structure.stiffness: is missing".into()),
        }
    }
}

/// A matrix from dense rows or a Matrix Market file.
fn load_matrix(field: &str, spec: &MatrixSpec, dir: &Path) -> Result<Matrix, String> {
    match spec {
        MatrixSpec::Dense(rows) => dense(field, rows),
        MatrixSpec::File(f) => {
            let path = dir.join(&f.matrix_market);
            crate::fe::read_matrix_market(&path).map(Matrix::Sparse).map_err(|e| format!("{field}.matrix_market: \"{}\": {e}", f.matrix_market))
        }
        MatrixSpec::Invalid(v) => Err(format!("{field}: is {v}, expected n rows of n numbers [[…], …] or {{ matrix_market = \"file.mtx\" }}")),
    }
}

fn dense(field: &str, rows: &[Vec<f64>]) -> Result<Matrix, String> {
    let n = rows.len();
    if n == 0 {
        return Err(format!("{field}: is empty, expected n rows of n numbers"));
    }
    if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != n) {
        return Err(format!("{field}[{i}]: has {} values, expected {n} (a square matrix of {n} rows)", r.len()));
    }
    Ok(Matrix::from_rows(rows))
}

/// Turns the scene's DOF references into (scene DOF, full clamped DOF).
struct Resolver<'a> {
    source: &'a Source,
    dofs: &'a DofMap,
    n_user: usize,
}

impl Resolver<'_> {
    fn index(&self, field: &str, d: usize) -> Result<(usize, usize), String> {
        if d >= self.n_user {
            return Err(format!("{field}: is {d}, the model has DOFs 0..{}", self.n_user - 1));
        }
        match self.dofs.new_index(d) {
            Some(f) => Ok((d, f)),
            None => Err(format!("{field}: is {d}, a fixed DOF (listed in structure.fixed), which has no motion")),
        }
    }

    fn named(&self, field: &str, node: &str, axis: Option<&str>) -> Result<(usize, usize), String> {
        let Source::Blade(blade) = self.source else {
            return Err(format!("{field}: is \"{node}\", but node names exist only with structure.generator; give a DOF index"));
        };
        let id = blade.named_node(node).ok_or_else(|| format!("{field}: is \"{node}\", expected one of {}", crate::fe::TIP_NODES.join(", ")))?;
        let a = match axis {
            None | Some("z") => 2,
            Some("x") => 0,
            Some("y") => 1,
            Some(other) => return Err(format!("{field}: axis \"{other}\", expected x, y or z")),
        };
        let d = blade.dof(id, a).ok_or_else(|| format!("{field}: node \"{node}\" is clamped"))?;
        self.index(field, d)
    }

    /// A force's or contact's point: `dof` or `node` (+ `axis`).
    fn point(&self, field: &str, dof: Option<usize>, node: Option<&str>, axis: Option<&str>) -> Result<(usize, usize), String> {
        match (dof, node) {
            (Some(_), Some(n)) => Err(format!("{field}: give either dof or node (\"{n}\"), not both")),
            (None, None) => Err(format!("{field}: needs dof = index or node = \"LE\" | \"MC\" | \"TE\"")),
            (Some(d), None) => {
                if let Some(a) = axis {
                    return Err(format!("{field}.axis: is \"{a}\", but axis goes with node, not dof"));
                }
                self.index(&format!("{field}.dof"), d)
            }
            (None, Some(n)) => self.named(&format!("{field}.node"), n, axis),
        }
    }

    /// An output or boundary entry: an index, `"LE"` or `"LE:y"`.
    fn output_pair(&self, field: &str, d: &DofSpec) -> Result<(usize, usize), String> {
        match d {
            DofSpec::Index(i) => self.index(field, *i),
            DofSpec::Name(s) => {
                let (node, axis) = match s.split_once(':') {
                    Some((n, a)) => (n, Some(a)),
                    None => (s.as_str(), None),
                };
                self.named(field, node, axis)
            }
            DofSpec::Invalid(v) => Err(format!("{field}: is {v}, expected a DOF index or a node name such as \"LE\" or \"MC:y\"")),
        }
    }

    fn output(&self, field: &str, d: &DofSpec) -> Result<usize, String> {
        self.output_pair(field, d).map(|(u, _)| u)
    }
}
