//! Forces and contacts of a scene: their points (DOF indices or a generator's node names), their
//! values, and the obstacle motion of an out-of-round casing.
use super::{BuildError, Casing, DofSpec, Scene, Source};
use crate::fe::DofMap;
use crate::model::{Compliance, Contact, Force, Harmonic};
use crate::time::Pairing;

/// Turns the scene's DOF references into (scene DOF, full clamped DOF).
pub(super) struct Resolver<'a> {
    pub source: &'a Source,
    pub dofs: &'a DofMap,
    pub n_user: usize,
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

    fn named(&self, field: &str, node: &str, axis: Option<&str>) -> Result<(usize, usize), BuildError> {
        let Source::Blade(blade) = self.source else {
            return Err(BuildError::field(field, format!("is \"{node}\", but node names exist only with structure.generator; give a DOF index")));
        };
        let id =
            blade.named_node(node).ok_or_else(|| BuildError::field(field, format!("is \"{node}\", expected one of {}", crate::fe::TIP_NODES.join(", "))))?;
        let a = match axis {
            None | Some("z") => 2,
            Some("x") => 0,
            Some("y") => 1,
            Some(other) => return Err(BuildError::field(field, format!("axis \"{other}\", expected x, y or z"))),
        };
        let d = blade.dof(id, a).ok_or_else(|| BuildError::field(field, format!("node \"{node}\" is clamped")))?;
        self.index(field, d)
    }

    /// A force's or contact's point: `dof` or `node` (+ `axis`).
    fn point(&self, field: &str, dof: Option<usize>, node: Option<&str>, axis: Option<&str>) -> Result<(usize, usize), BuildError> {
        match (dof, node) {
            (Some(_), Some(n)) => Err(BuildError::field(field, format!("give either dof or node (\"{n}\"), not both"))),
            (None, None) => Err(BuildError::field(field, "needs dof = index or node = \"LE\" | \"MC\" | \"TE\"")),
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
                self.named(field, node, axis)
            }
            DofSpec::Invalid(v) => Err(BuildError::field(field, format!("is {v}, expected a DOF index or a node name such as \"LE\" or \"MC:y\""))),
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
            let (_, d) = resolver.point(&field, f.dof, f.node.as_deref(), f.axis.as_deref())?;
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
            let (u, d) = resolver.point(&field, c.dof, c.node.as_deref(), c.axis.as_deref())?;
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
