//! The units a scene names (`[units]`) and the names of its DOFs: labels only. The solver is
//! unit-agnostic: every number is in the scene's units, which must be consistent. Length, force
//! and time are named; angles are radians (frequency: rad per time unit); mass is derived,
//! force·time²/length (N·s²/m = kg; with mm, N, s it is t = 1000 kg).
use std::collections::BTreeMap;

/// A named unit and its value in SI (m, N, s).
type Named = (&'static str, f64);

/// Length units: name, metres per unit.
pub const LENGTH_UNITS: [Named; 4] = [("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("in", 0.0254)];
/// Force units: name, newtons per unit.
pub const FORCE_UNITS: [Named; 4] = [("N", 1.0), ("kN", 1e3), ("mN", 1e-3), ("lbf", 4.448_221_615_260_5)];
/// Time units: name, seconds per unit.
pub const TIME_UNITS: [Named; 2] = [("s", 1.0), ("ms", 1e-3)];

/// What a number measures, for its unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    Length,
    Velocity,
    Acceleration,
    Force,
    Time,
    /// Angular frequency: rad per time unit.
    Frequency,
    /// A ratio (unit "1").
    Ratio,
}

/// The scene's length, force and time units (default SI: m, N, s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Units {
    length: Named,
    force: Named,
    time: Named,
}

impl Default for Units {
    fn default() -> Self {
        Units { length: LENGTH_UNITS[0], force: FORCE_UNITS[0], time: TIME_UNITS[0] }
    }
}

/// The entry of `table` named `name` (`um` is `µm`).
fn find(table: &[Named], name: &str) -> Option<Named> {
    let name = if name == "um" { "µm" } else { name };
    table.iter().find(|(n, _)| *n == name).copied()
}

impl Units {
    /// The units named `length`, `force`, `time`; `Err` names the first unknown one as
    /// `(field, value, allowed values)`.
    pub fn new(length: &str, force: &str, time: &str) -> Result<Units, (&'static str, String, String)> {
        let pick = |field: &'static str, table: &[Named], v: &str| {
            find(table, v).ok_or_else(|| {
                let mut allowed: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
                if field == "length" {
                    allowed.insert(3, "um");
                }
                (field, v.to_string(), allowed.join(", "))
            })
        };
        Ok(Units { length: pick("length", &LENGTH_UNITS, length)?, force: pick("force", &FORCE_UNITS, force)?, time: pick("time", &TIME_UNITS, time)? })
    }

    pub fn length(&self) -> &'static str {
        self.length.0
    }
    pub fn force(&self) -> &'static str {
        self.force.0
    }
    pub fn time(&self) -> &'static str {
        self.time.0
    }

    /// The unit of `q`: "mm", "mm/s", "mm/s2", "kN", "s", "rad/s", "1".
    pub fn name(&self, q: Quantity) -> String {
        let (l, t) = (self.length.0, self.time.0);
        match q {
            Quantity::Length => l.into(),
            Quantity::Velocity => format!("{l}/{t}"),
            Quantity::Acceleration => format!("{l}/{t}2"),
            Quantity::Force => self.force.0.into(),
            Quantity::Time => t.into(),
            Quantity::Frequency => format!("rad/{t}"),
            Quantity::Ratio => "1".into(),
        }
    }

    /// The derived mass unit, force·time²/length: "N.s2/m" (= kg).
    pub fn mass(&self) -> String {
        format!("{}.{}2/{}", self.force.0, self.time.0, self.length.0)
    }

    /// `q` in SI: (factor to SI, exponents of kg, m, s, rad). 1 mm/s = 0.001 m/s: (1e-3, [0, 1, −1, 0]).
    pub fn si(&self, q: Quantity) -> (f64, [i32; 4]) {
        let (l, f, t) = (self.length.1, self.force.1, self.time.1);
        match q {
            Quantity::Length => (l, [0, 1, 0, 0]),
            Quantity::Velocity => (l / t, [0, 1, -1, 0]),
            Quantity::Acceleration => (l / (t * t), [0, 1, -2, 0]),
            Quantity::Force => (f, [1, 1, -2, 0]),
            Quantity::Time => (t, [0, 0, 1, 0]),
            Quantity::Frequency => (1.0 / t, [0, 0, -1, 1]),
            Quantity::Ratio => (1.0, [0; 4]),
        }
    }

    /// "m, N, s" (the summary of a scene's units).
    pub fn summary(&self) -> String {
        format!("{}, {}, {}", self.length.0, self.force.0, self.time.0)
    }
}

/// What the front ends print for a scene: its units and the names of its DOFs ("MC:y" for a
/// generator's node; others by index).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Labels {
    pub units: Units,
    /// Scene DOF → name, for the DOFs that have one.
    pub names: BTreeMap<usize, String>,
}

impl Labels {
    /// "MC:y", or "DOF 3" for a DOF without a name.
    pub fn dof(&self, d: usize) -> String {
        self.names.get(&d).cloned().unwrap_or_else(|| format!("DOF {d}"))
    }
    /// `q`'s unit, bracketed for an axis or a column: "[mm]".
    pub fn unit(&self, q: Quantity) -> String {
        format!("[{}]", self.units.name(q))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_factors_and_refusals() {
        let u = Units::new("mm", "kN", "s").unwrap();
        assert_eq!((u.name(Quantity::Velocity), u.name(Quantity::Acceleration), u.name(Quantity::Frequency)), ("mm/s".into(), "mm/s2".into(), "rad/s".into()));
        assert_eq!(u.si(Quantity::Length), (1e-3, [0, 1, 0, 0]));
        assert_eq!(u.si(Quantity::Force), (1e3, [1, 1, -2, 0]));
        assert_eq!(u.mass(), "kN.s2/mm");
        assert_eq!(Units::new("um", "N", "ms").unwrap().name(Quantity::Velocity), "µm/ms");
        assert_eq!(Units::new("m", "N", "ms").unwrap().si(Quantity::Frequency), (1e3, [0, 0, -1, 1]));
        let (field, value, allowed) = Units::new("m", "kg", "s").unwrap_err();
        assert_eq!((field, value.as_str(), allowed.as_str()), ("force", "kg", "N, kN, mN, lbf"));
        assert_eq!(Units::new("cm", "N", "s").unwrap_err().2, "m, mm, µm, um, in");
        assert_eq!(Units::default().summary(), "m, N, s");
    }

    #[test]
    fn labels_name_or_number_the_dofs() {
        let l = Labels { units: Units::default(), names: [(7, "MC:y".to_string())].into() };
        assert_eq!((l.dof(7), l.dof(3), l.unit(Quantity::Force)), ("MC:y".into(), "DOF 3".into(), "[N]".into()));
    }
}
