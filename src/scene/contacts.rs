//! Forces and contacts of a scene: their points (DOF indices or a generator's node names), their
//! values, and the obstacle motion of an out-of-round casing.
use super::{BuildError, Casing, DofSpec, NodeSpec, Scene, Source};
use crate::fe::{DofMap, NodeDofs, NodeMap};
use crate::model::{Compliance, Contact, Force, Harmonic};
use crate::time::Pairing;

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
            return Err(BuildError::field(field, format!("is {d}, the model has DOFs 0..{}", self.n_user - 1)));
        }
        match self.dofs.new_index(d) {
            Some(f) => Ok((d, f)),
            None => Err(BuildError::field(field, format!("is {d}, a fixed DOF (listed in structure.fixed), which has no motion"))),
        }
    }

    /// A node's entry in the node map, by number or by a generator's tip name. The node numbers
    /// are the FE code's (a generator's: index + 1, as in its CalculiX deck).
    pub fn node(&self, field: &str, node: &NodeSpec) -> Result<(u64, &NodeDofs), BuildError> {
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

    /// The `[[contact]]` entries in the full (clamped) numbering, and the scene's DOF of each.
    pub(super) fn contacts(&self, resolver: &Resolver) -> Result<(Vec<Contact>, Vec<usize>), BuildError> {
        let mut contacts = Vec::with_capacity(self.contact.len());
        let mut contact_dofs = Vec::with_capacity(self.contact.len());
        for (i, c) in self.contact.iter().enumerate() {
            let field = format!("contact[{i}]");
            let (u, d) = resolver.point(&field, c.dof, c.node.as_ref(), c.axis.as_deref())?;
            contact_dofs.push(u);
            contacts.push(Contact {
                dof: d,
                direction: c.direction as f64,
                gap: c.gap,
                compliance: c.stiffness.map_or(Compliance::Rigid, |stiffness| Compliance::Compliant { stiffness }),
                motion: c.motion.iter().map(|h| Harmonic { amplitude: h.amplitude, harmonic: h.harmonic, phase: h.phase }).collect(),
            });
        }
        Ok((contacts, contact_dofs))
    }

    /// Each `[[contact]]`'s own `pairing`, if any (over `discretization.pairing`).
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

    /// The `[casing]` section, if any: checks it and adds one motion term to every contact.
    pub(super) fn casing_motion(&self, contacts: &mut [Contact], source: &Source, dofs: &DofMap) -> Result<Option<Casing>, BuildError> {
        let Some(spec) = &self.casing else { return Ok(None) };
        let frequency = self.excitation.frequency;
        if !(frequency.is_finite() && frequency > 0.0) {
            return Err(BuildError::field("excitation.frequency", format!("is {frequency}, must be a finite angular frequency > 0 [rad/s]")));
        }
        let casing = Casing::from_spec(spec, frequency)?;
        if contacts.is_empty() {
            return Err(BuildError::field("casing", "there is no [[contact]] for the casing to act on"));
        }
        if let Some(arc) = &spec.arc {
            if arc.len() != contacts.len() {
                return Err(BuildError::field("casing.arc", format!("has {} values, expected one per contact ({})", arc.len(), contacts.len())));
            }
            if let Some((i, v)) = arc.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(BuildError::field(format!("casing.arc[{i}]"), format!("is {v}, must be finite")));
            }
        }
        for (i, c) in contacts.iter_mut().enumerate() {
            let s = match (&spec.arc, source) {
                (Some(arc), _) => arc[i],
                (None, Source::Blade(blade)) => {
                    // Full (clamped) DOF → scene DOF → the blade's unclamped DOF → node.
                    let node = blade.dofs.new_to_old[dofs.new_to_old[c.dof]] / 3;
                    let [x, y, z] = blade.nodes[node];
                    casing.arc(x, y, blade.params.twist_deg.to_radians() * z / blade.params.length)
                }
                (None, _) => {
                    let message = format!(
                        "is missing; contact[{i}] is not on a blade generator's node, so give the arc position [m] of every contact along the rotation"
                    );
                    return Err(BuildError::field("casing.arc", message));
                }
            };
            c.motion.push(casing.motion(s));
        }
        Ok(Some(casing))
    }
}
