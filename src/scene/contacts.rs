//! Forces and contacts of a scene: their points (DOF indices or a generator's node names), their
//! rows of B (one DOF with a direction, or a unit normal over a node's DOFs: given, or radial
//! about the rotation axis), their values, and the obstacle motion of an out-of-round casing.
use super::rotor::Rotor;
use super::{BuildError, Casing, ContactSpec, DofSpec, NodeSpec, NormalSpec, Scene, Source};
use crate::fe::{DofMap, NodeMap};
use crate::model::{Compliance, Contact, Force, Harmonic};
use crate::time::Pairing;
use std::path::{Path, PathBuf};

/// Turns the scene's DOF references into (scene DOF, full clamped DOF).
pub(super) struct Resolver<'a> {
    pub source: &'a Source,
    pub dofs: &'a DofMap,
    pub n_user: usize,
    /// The node map of a generator or an FE code's output (node → DOF per direction).
    pub nodes: Option<&'a NodeMap>,
}

impl Resolver<'_> {
    fn index(&self, field: &str, d: usize) -> Result<(usize, usize), BuildError> {
        if d >= self.n_user {
            return Err(BuildError::field(field, format!("is {d}, the model has DOFs 0 to {} (use one of them)", self.n_user - 1)));
        }
        match self.dofs.new_index(d) {
            Some(f) => Ok((d, f)),
            None => Err(BuildError::field(field, format!("is {d}, a fixed DOF (listed in structure.fixed), which has no motion"))),
        }
    }

    /// A node's entry in the node map, by number or by a generator's tip name. The node numbers
    /// are the FE code's (a generator's: index + 1, as in its CalculiX deck).
    pub fn node(&self, field: &str, node: &NodeSpec) -> Result<(u64, &crate::fe::NodeDofs), BuildError> {
        let number = match node {
            NodeSpec::Name(name) => {
                let Source::Blade(blade) = self.source else {
                    let remedy = if self.nodes.is_some() { "a node number with axis" } else { "a DOF index" };
                    return Err(BuildError::field(field, format!("is \"{name}\", but node names exist only with structure.generator; give {remedy}")));
                };
                let id = blade
                    .named_node(name)
                    .ok_or_else(|| BuildError::field(field, format!("is \"{name}\", expected one of {}", crate::fe::TIP_NODES.join(", "))))?;
                id as u64 + 1
            }
            NodeSpec::Number(n) => *n,
        };
        let Some(nodes) = self.nodes else {
            return Err(BuildError::field(field, format!("is {node}, but nodes exist only with structure.generator or structure.calculix; give a DOF index")));
        };
        let dofs = nodes.get(number).ok_or_else(|| BuildError::field(field, format!("node {number} is not in {}: {}", nodes.source, nodes.missing)))?;
        Ok((number, dofs))
    }

    fn named(&self, field: &str, node: &NodeSpec, axis: Option<&str>) -> Result<(usize, usize), BuildError> {
        let (number, _) = self.node(field, node)?;
        let axis = match (axis, node) {
            (Some(a), _) => a,
            (None, NodeSpec::Name(_)) => "z",
            (None, NodeSpec::Number(n)) => return Err(BuildError::field(field, format!("node {n} needs axis = \"x\", \"y\" or \"z\""))),
        };
        let nodes = self.nodes.expect("resolved by node()");
        let d = crate::fe::axis_index(axis).and_then(|a| nodes.dof(number, a)).map_err(|e| BuildError::field(field, e.to_string()))?;
        self.index(field, d)
    }

    /// A force's or contact's point: `dof` or `node` (+ `axis`).
    fn point(&self, field: &str, dof: Option<usize>, node: Option<&NodeSpec>, axis: Option<&str>) -> Result<(usize, usize), BuildError> {
        match (dof, node) {
            (Some(_), Some(n)) => Err(BuildError::field(field, format!("give either dof or node ({n}), not both"))),
            (None, None) => Err(BuildError::field(field, "needs dof = index, or node = number (or \"LE\" | \"MC\" | \"TE\") with axis")),
            (Some(d), None) => {
                if let Some(a) = axis {
                    return Err(BuildError::field(format!("{field}.axis"), format!("is \"{a}\", but axis goes with node, not dof")));
                }
                self.index(&format!("{field}.dof"), d)
            }
            (None, Some(n)) => self.named(&format!("{field}.node"), n, axis),
        }
    }

    /// An output or boundary entry: an index, `"LE"` or `"LE:y"`.
    pub fn output_pair(&self, field: &str, d: &DofSpec) -> Result<(usize, usize), BuildError> {
        match d {
            DofSpec::Index(i) => self.index(field, *i),
            DofSpec::Name(s) => {
                let (node, axis) = match s.split_once(':') {
                    Some((n, a)) => (n, Some(a)),
                    None => (s.as_str(), None),
                };
                let node = node.parse().map_or_else(|_| NodeSpec::Name(node.to_string()), NodeSpec::Number);
                self.named(field, &node, axis)
            }
            DofSpec::Node { node, axis } => self.named(field, node, axis.as_deref()),
            DofSpec::Invalid(v) => Err(BuildError::field(
                field,
                format!("is {v}, expected a DOF index, a node name such as \"LE\" or \"MC:y\", or {{ node = 1234, axis = \"x\" }}"),
            )),
        }
    }

    /// An output entry in the scene's numbering.
    pub fn output(&self, field: &str, d: &DofSpec) -> Result<usize, BuildError> {
        self.output_pair(field, d).map(|(u, _)| u)
    }
}

impl Scene {
    /// The `[[force]]` entries in the full (clamped) numbering.
    pub(super) fn forces(&self, resolver: &Resolver) -> Result<Vec<Force>, BuildError> {
        let k = self.discretization.steps.count().unwrap_or(0);
        let mut forces = Vec::with_capacity(self.force.len());
        for (i, f) in self.force.iter().enumerate() {
            let field = format!("force[{i}]");
            let (_, d) = resolver.point(&field, f.dof, f.node.as_ref(), f.axis.as_deref())?;
            if !f.amplitude.is_finite() {
                return Err(BuildError::field(format!("{field}.amplitude"), format!("is {}, must be finite", f.amplitude)));
            }
            if !f.phase.is_finite() {
                return Err(BuildError::field(format!("{field}.phase"), format!("is {}, must be finite", f.phase)));
            }
            if k >= 4 && 2 * f.harmonic as usize >= k {
                let message = format!("is {}, not resolved by steps = {k} (needs steps > {})", f.harmonic, 2 * f.harmonic);
                return Err(BuildError::field(format!("{field}.harmonic"), message));
            }
            forces.push(Force { dof: d, term: Harmonic { amplitude: f.amplitude, harmonic: f.harmonic, phase: f.phase } });
        }
        Ok(forces)
    }

    /// The `[[contact]]` entries, each with its row of B in the full (clamped) and the scene's
    /// numbering and its node's position when known; `nodes = "tip"` expands to one contact per
    /// tip node. `rotor` gives radial normals.
    pub(super) fn contacts(&self, resolver: &Resolver, rotor: Option<&Rotor>) -> Result<Vec<Placed>, BuildError> {
        let mut placed = Vec::with_capacity(self.contact.len());
        for (i, c) in self.contact.iter().enumerate() {
            let field = format!("contact[{i}]");
            let compliance = c.stiffness.map_or(Compliance::Rigid, |stiffness| Compliance::Compliant { stiffness });
            let motion: Vec<Harmonic> = c.motion.iter().map(|h| Harmonic { amplitude: h.amplitude, harmonic: h.harmonic, phase: h.phase }).collect();
            for (user_row, row, position) in contact_rows(resolver, &field, c, rotor)? {
                placed.push(Placed { contact: Contact { row, gap: c.gap, compliance, motion: motion.clone() }, user_row, position, spec: i });
            }
        }
        Ok(placed)
    }

    /// Each `[[contact]]`'s own `pairing`, if any (over `discretization.pairing`), per spec entry.
    pub(super) fn contact_pairings(&self) -> Result<Vec<Option<Pairing>>, BuildError> {
        let parse = |(i, c): (usize, &super::spec::ContactSpec)| -> Result<Option<Pairing>, BuildError> {
            let Some(name) = &c.pairing else { return Ok(None) };
            let p = name
                .parse::<Pairing>()
                .map_err(|_| BuildError::field(format!("contact[{i}].pairing"), format!("is \"{name}\", expected \"same\" or \"forward\"")))?;
            Ok(Some(p))
        };
        self.contact.iter().enumerate().map(parse).collect()
    }

    /// The `[casing]` section, checked, with a profile's series read relative to `dir`.
    pub(super) fn checked_casing(&self, dir: &Path) -> Result<Option<Casing>, BuildError> {
        let Some(spec) = &self.casing else { return Ok(None) };
        let frequency = self.excitation.frequency;
        if !(frequency.is_finite() && frequency > 0.0) {
            return Err(BuildError::field("excitation.frequency", format!("is {frequency}, must be a finite angular frequency > 0 [rad/s]")));
        }
        let profile = spec.profile.as_deref().map(|f| super::profile::profile_series(f, dir)).transpose()?;
        Casing::from_spec(spec, frequency, profile).map(Some)
    }

    /// Files the scene references besides its matrices: the casing profile, if any (resolved
    /// against `dir`). The integrator joins this to the scene's list of referenced files, so that
    /// FMU packaging copies it into `resources/`.
    pub fn casing_files(&self, dir: &Path) -> Vec<PathBuf> {
        self.casing.iter().filter_map(|c| c.profile.as_ref()).map(|f| dir.join(f)).collect()
    }

    /// The rotor's frame for radial normals and angles: the blade's (with a casing) or
    /// `casing.axis`'s.
    pub(super) fn rotor(&self, casing: Option<&Casing>, source: &Source) -> Result<Option<Rotor>, BuildError> {
        match (source, casing, &self.casing) {
            (Source::Blade(blade), Some(casing), _) => Ok(Some(Rotor::of_blade(blade, casing))),
            (_, _, Some(spec)) => Rotor::of_spec(spec),
            _ => Ok(None),
        }
    }

    /// Adds the casing's obstacle motion to every contact: the cosine lobes at each contact's arc
    /// coordinate, a series at each contact's angle θ_i (see [`super::casing`]).
    pub(super) fn casing_motion(&self, placed: &mut [Placed], casing: Option<&Casing>, source: &Source, rotor: Option<Rotor>) -> Result<(), BuildError> {
        let (Some(spec), Some(casing)) = (&self.casing, casing) else { return Ok(()) };
        if placed.is_empty() {
            return Err(BuildError::field("casing", "there is no [[contact]] for the casing to act on"));
        }
        if let Some(arc) = &spec.arc {
            if arc.len() != placed.len() {
                return Err(BuildError::field("casing.arc", format!("has {} values, expected one per contact ({})", arc.len(), placed.len())));
            }
            if let Some((i, v)) = arc.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(BuildError::field(format!("casing.arc[{i}]"), format!("is {v}, must be finite")));
            }
        }
        let lobes = matches!(casing.shape, super::casing::Shape::Lobes { .. });
        let mut rotor = rotor;
        for (i, p) in placed.iter_mut().enumerate() {
            let (arc, angle) = match (&spec.arc, source, p.position) {
                (Some(arc), _, _) => (arc[i], arc[i] / casing.radius),
                (None, Source::Blade(blade), Some([x, y, z])) if lobes => {
                    (casing.arc(x, y, blade.params.twist_deg.to_radians() * z / blade.params.length), 0.0)
                }
                (None, _, Some(position)) if rotor.is_some() => {
                    let angle = rotor.as_mut().expect("checked").angle(&format!("contact[{}]", p.spec), position)?;
                    (angle * casing.radius, angle)
                }
                _ => {
                    let message = format!(
                        "is missing; contact[{}] has no node position, so give the arc position [m] of every contact along the rotation (or each contact's position with casing.axis)",
                        p.spec
                    );
                    return Err(BuildError::field("casing.arc", message));
                }
            };
            p.contact.motion.extend(casing.motion(arc, angle));
        }
        self.check_resolved(placed)
    }

    /// Every motion term resolved by the grid (as the forces are): harmonic h needs steps > 2h.
    fn check_resolved(&self, placed: &[Placed]) -> Result<(), BuildError> {
        let k = self.discretization.steps.count().unwrap_or(0);
        let highest = placed.iter().flat_map(|p| p.contact.motion.iter().map(|h| h.harmonic)).max().unwrap_or(0);
        if k >= 4 && 2 * highest as usize >= k {
            let message = format!(
                "reaches harmonic {highest} of ω, not resolved by steps = {k} (needs steps > {}); raise discretization.steps or smooth the casing (fewer harmonics)",
                2 * highest
            );
            return Err(BuildError::field("casing", message));
        }
        Ok(())
    }
}

/// A contact as the scene places it: the model's contact (full, clamped numbering), its row of B
/// in the scene's numbering, its node's coordinates when known, and its `[[contact]]` entry.
pub(super) struct Placed {
    pub contact: Contact,
    pub user_row: Vec<(usize, f64)>,
    pub position: Option<[f64; 3]>,
    pub spec: usize,
}

/// A node's x, y, z DOFs as (scene DOF, full DOF) and its coordinates when known.
struct PointDofs {
    dofs: Vec<(usize, usize)>,
    position: Option<[f64; 3]>,
}

impl Resolver<'_> {
    /// The one lookup from a node to its DOFs (x, y, z) and coordinates: a generator's named node
    /// (`"LE"`) or node index, or `dofs = [i, j, k]` with `position` in a Matrix Market scene.
    /// A node map of another FE code (node number → DOFs) plugs in here.
    fn node_dofs(&self, field: &str, node: NodeRef, position: Option<[f64; 3]>) -> Result<PointDofs, BuildError> {
        match node {
            NodeRef::Dofs(list) => {
                let dofs = list.iter().enumerate().map(|(j, &d)| self.index(&format!("{field}.dofs[{j}]"), d)).collect::<Result<_, _>>()?;
                Ok(PointDofs { dofs, position })
            }
            NodeRef::Named(name) => {
                let Source::Blade(blade) = self.source else {
                    return Err(BuildError::field(
                        format!("{field}.node"),
                        format!("is \"{name}\", but node names exist only with structure.generator; give dofs = [i, j, k]"),
                    ));
                };
                let id = blade
                    .named_node(name)
                    .ok_or_else(|| BuildError::field(format!("{field}.node"), format!("is \"{name}\", expected one of {}", crate::fe::TIP_NODES.join(", "))))?;
                self.blade_node(field, blade, id)
            }
            NodeRef::Number(number) => {
                let (_, nd) = self.node(&format!("{field}.node"), &NodeSpec::Number(number))?;
                let dofs = nd
                    .dofs
                    .iter()
                    .enumerate()
                    .map(|(a, d)| {
                        d.ok_or_else(|| BuildError::field(format!("{field}.node"), format!("node {number} has no DOF along axis {a} (fixed or absent)")))
                            .and_then(|d| self.index(field, d))
                    })
                    .collect::<Result<_, _>>()?;
                Ok(PointDofs { dofs, position: nd.position.or(position) })
            }
            NodeRef::Blade(id) => {
                let Source::Blade(blade) = self.source else { unreachable!("tip nodes expand only on a blade") };
                self.blade_node(field, blade, id)
            }
        }
    }

    fn blade_node(&self, field: &str, blade: &crate::fe::Blade, id: usize) -> Result<PointDofs, BuildError> {
        let dofs = (0..3)
            .map(|a| blade.dof(id, a).ok_or_else(|| BuildError::field(format!("{field}.node"), "is clamped")).and_then(|d| self.index(field, d)))
            .collect::<Result<_, _>>()?;
        Ok(PointDofs { dofs, position: Some(blade.nodes[id]) })
    }
}

impl Resolver<'_> {
    /// A rubbing contact's sliding direction t over a node's DOFs (full numbering): `direction =
    /// [tx, ty, tz]` (normalised) or `"tangential"`, the direction of rotation e_θ = axis × e_r at
    /// the node (src/formulation.md §9), at `node` or `dofs` (with `position`).
    pub(super) fn sliding_row(
        &self,
        field: &str,
        at: (Option<&NodeSpec>, Option<&[usize]>, Option<[f64; 3]>),
        direction: &NormalSpec,
        rotor: Option<&Rotor>,
    ) -> Result<Vec<(usize, f64)>, BuildError> {
        let node = match at {
            (Some(NodeSpec::Name(n)), None, _) => NodeRef::Named(n),
            (Some(NodeSpec::Number(n)), None, _) => NodeRef::Number(*n),
            (None, Some(d), _) => NodeRef::Dofs(d),
            _ => return Err(BuildError::field(field, "with direction, give one of node = … or dofs = [i, j, k] (the node the counter-face slides along)")),
        };
        let nd = self.node_dofs(field, node, at.2)?;
        let key = format!("{field}.direction");
        let t = match direction {
            NormalSpec::Name(name) if name == "tangential" => {
                let Some(rotor) = rotor else {
                    return Err(BuildError::field(key, "is \"tangential\", which needs the rotation axis: a [casing] (with a blade generator) or casing.axis"));
                };
                let (Some(p), 3) = (nd.position, nd.dofs.len()) else {
                    return Err(BuildError::field(key, "is \"tangential\", which needs the node's 3 DOFs x, y, z and its coordinates (position = [x, y, z])"));
                };
                rotor.tangential(&key, p)?.to_vec()
            }
            NormalSpec::Vector(_) => unit_normal(&key, direction, nd.dofs.len(), nd.position, rotor)?,
            other => return Err(BuildError::field(key, format!("is {other:?}, expected [tx, ty, tz] or \"tangential\""))),
        };
        Ok(nd.dofs.iter().zip(t).filter(|(_, v)| *v != 0.0).map(|(&(_, f), v)| (f, v)).collect())
    }
}

/// A node as a `[[contact]]` names it.
enum NodeRef<'a> {
    Named(&'a str),
    /// An FE node number, through the scene's node map (CalculiX `.dof`, the generator).
    Number(u64),
    Blade(usize),
    Dofs(&'a [usize]),
}

/// The rows of one `[[contact]]` entry: (scene row, full row, position) per contact it makes.
type Rows = Vec<(Vec<(usize, f64)>, Vec<(usize, f64)>, Option<[f64; 3]>)>;

fn contact_rows(resolver: &Resolver, field: &str, c: &ContactSpec, rotor: Option<&Rotor>) -> Result<Rows, BuildError> {
    let along = c.normal.is_some() || c.nodes.is_some() || c.dofs.is_some();
    if !along {
        // One DOF: `dof`, or `node` + `axis`, with `direction`; a blade DOF's node gives the position.
        let (u, d) = resolver.point(field, c.dof, c.node.as_ref(), c.axis.as_deref())?;
        let s = c.direction.unwrap_or(1) as f64;
        let position = match resolver.source {
            Source::Blade(blade) => Some(blade.nodes[blade.dofs.new_to_old[u] / 3]),
            _ => c.position,
        };
        return Ok(vec![(vec![(u, s)], vec![(d, s)], position)]);
    }
    for (key, given) in [("dof", c.dof.is_some()), ("axis", c.axis.is_some()), ("direction", c.direction.is_some())] {
        if given {
            return Err(BuildError::field(
                format!("{field}.{key}"),
                "goes with a contact on one DOF; a contact along a normal takes node (or dofs) and normal",
            ));
        }
    }
    let nodes: Vec<NodeRef> = match (&c.nodes, &c.node, &c.dofs) {
        (Some(which), None, None) => match (which.as_str(), resolver.source) {
            ("tip", Source::Blade(blade)) => blade.tip_nodes().into_iter().map(NodeRef::Blade).collect(),
            ("tip", _) => return Err(BuildError::field(format!("{field}.nodes"), "is \"tip\", but tip nodes exist only with structure.generator")),
            (other, _) => {
                return Err(BuildError::field(format!("{field}.nodes"), format!("is \"{other}\", expected \"tip\" (every mid-thickness tip node, LE to TE)")));
            }
        },
        (None, Some(NodeSpec::Name(n)), None) => vec![NodeRef::Named(n)],
        (None, Some(NodeSpec::Number(n)), None) => vec![NodeRef::Number(*n)],
        (None, None, Some(d)) => vec![NodeRef::Dofs(d)],
        _ => return Err(BuildError::field(field, "give one of node, nodes or dofs with a normal")),
    };
    let default_normal = NormalSpec::Name("radial".into());
    let normal = match (&c.normal, &c.nodes) {
        (Some(n), _) => n,
        (None, Some(_)) => &default_normal,
        (None, None) => return Err(BuildError::field(format!("{field}.normal"), "is missing; give normal = [nx, ny, nz] or normal = \"radial\"")),
    };
    let mut rows = Vec::with_capacity(nodes.len());
    for node in nodes {
        let nd = resolver.node_dofs(field, node, c.position)?;
        let n = unit_normal(&format!("{field}.normal"), normal, nd.dofs.len(), nd.position, rotor)?;
        let kept: Vec<((usize, usize), f64)> = nd.dofs.iter().copied().zip(n).filter(|(_, v)| *v != 0.0).collect();
        rows.push((kept.iter().map(|&((u, _), v)| (u, v)).collect(), kept.iter().map(|&((_, f), v)| (f, v)).collect(), nd.position));
    }
    Ok(rows)
}

/// The unit normal over `len` DOFs: the given components normalised, or the radial direction at
/// `position` about the rotor's axis.
fn unit_normal(field: &str, normal: &NormalSpec, len: usize, position: Option<[f64; 3]>, rotor: Option<&Rotor>) -> Result<Vec<f64>, BuildError> {
    match normal {
        NormalSpec::Vector(v) => {
            if v.len() != len {
                return Err(BuildError::field(field, format!("has {} components for the node's {len} DOFs; give one per DOF", v.len())));
            }
            let length = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !(length.is_finite() && length > 0.0) {
                let message =
                    format!("is {v:?}, of length {length}: a normal needs a finite nonzero length; give its direction, e.g. [0, 0, 1] (it is normalised)");
                return Err(BuildError::field(field, message));
            }
            Ok(v.iter().map(|x| x / length).collect())
        }
        NormalSpec::Name(name) if name == "radial" => {
            let Some(rotor) = rotor else {
                return Err(BuildError::field(field, "is \"radial\", which needs the rotation axis: a [casing] (with a blade generator) or casing.axis"));
            };
            let Some(p) = position else {
                return Err(BuildError::field(field, "is \"radial\", which needs the node's coordinates: give position = [x, y, z]"));
            };
            if len != 3 {
                return Err(BuildError::field(field, format!("is \"radial\", which needs the node's 3 DOFs x, y, z; dofs has {len}")));
            }
            Ok(rotor.radial(field, p)?.to_vec())
        }
        other => Err(BuildError::field(field, format!("is {other:?}, expected [nx, ny, nz] or \"radial\""))),
    }
}
