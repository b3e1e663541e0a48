//! The `[units]` section (labels only: the solver uses the numbers as given) and the names of a
//! generator's tip DOFs, for the front ends' labels.
use super::{BuildError, Scene, Source};
use crate::model::{Labels, Units};

impl Scene {
    /// The scene's units (SI by default) and its DOF names ("MC:y" for a generator's tip nodes).
    pub(super) fn labels(&self, source: &Source) -> Result<Labels, BuildError> {
        let units = match &self.units {
            None => Units::default(),
            Some(u) => Units::new(u.length.as_deref().unwrap_or("m"), u.force.as_deref().unwrap_or("N"), u.time.as_deref().unwrap_or("s"))
                .map_err(|(field, value, allowed)| BuildError::field(format!("units.{field}"), format!("is \"{value}\", expected one of {allowed}")))?,
        };
        let mut names = std::collections::BTreeMap::new();
        if let Source::Blade(blade) = source {
            for node in crate::fe::TIP_NODES {
                let Some(id) = blade.named_node(node) else { continue };
                for (a, axis) in ["x", "y", "z"].iter().enumerate() {
                    if let Some(d) = blade.dof(id, a) {
                        names.insert(d, format!("{node}:{axis}"));
                    }
                }
            }
        }
        Ok(Labels { units, names })
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::Scene;

    const BASE: &str = "[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n[excitation]\nfrequency = 1.0\n";

    #[test]
    fn units_default_to_si_and_are_checked() {
        let built = Scene::parse(BASE, "s.toml").unwrap().build("s.toml").unwrap();
        assert_eq!(built.labels.units.summary(), "m, N, s");
        let built = Scene::parse(&format!("{BASE}[units]\nlength = \"mm\"\nforce = \"kN\"\n"), "s.toml").unwrap().build("s.toml").unwrap();
        assert_eq!(built.labels.units.summary(), "mm, kN, s");
        let e = Scene::parse(&format!("{BASE}[units]\ntime = \"h\"\n"), "s.toml").unwrap().build("s.toml").unwrap_err().to_string();
        assert_eq!(e, "s.toml: units.time: is \"h\", expected one of s, ms");
        let e = Scene::parse(&format!("{BASE}[units]\nmass = \"kg\"\n"), "s.toml").unwrap_err().to_string();
        assert!(e.contains("unknown field `mass`"), "{e}");
    }
}
