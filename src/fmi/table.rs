//! The variable table: the single source of truth for the accessors (which value reference
//! exists, its type, where it may be set) and for `modelDescription.xml`.
//!
//! Value references are the positions in the table (0, 1, 2, …), so a lookup is an index.
use crate::error::{Error, Result};
use std::collections::HashSet;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
    Independent,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

impl Causality {
    pub fn name(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
            Causality::Independent => "independent",
        }
    }
}

impl Variability {
    pub fn name(self) -> &'static str {
        match self {
            Variability::Constant => "constant",
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

impl Initial {
    pub fn name(self) -> &'static str {
        match self {
            Initial::Exact => "exact",
            Initial::Approx => "approx",
            Initial::Calculated => "calculated",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Initial {
    Exact,
    Approx,
    Calculated,
}

/// The accessor family of a variable (`fmi2GetReal`, `fmi2GetInteger`, …). Enumerations are
/// accessed as Integer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BaseType {
    Real,
    Integer,
    Boolean,
    String,
}

impl BaseType {
    pub fn name(self) -> &'static str {
        match self {
            BaseType::Real => "Real",
            BaseType::Integer => "Integer",
            BaseType::Boolean => "Boolean",
            BaseType::String => "String",
        }
    }
}

/// The type element of a scalar variable with its attributes.
#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    Real { start: Option<f64>, unit: Option<String>, min: Option<f64>, max: Option<f64> },
    Integer { start: Option<i32>, min: Option<i32>, max: Option<i32> },
    Boolean { start: Option<bool> },
    String { start: Option<String> },
    Enumeration { declared_type: String, start: Option<i32> },
}

impl Kind {
    pub fn base(&self) -> BaseType {
        match self {
            Kind::Real { .. } => BaseType::Real,
            Kind::Integer { .. } | Kind::Enumeration { .. } => BaseType::Integer,
            Kind::Boolean { .. } => BaseType::Boolean,
            Kind::String { .. } => BaseType::String,
        }
    }
    fn has_start(&self) -> bool {
        match self {
            Kind::Real { start, .. } => start.is_some(),
            Kind::Integer { start, .. } | Kind::Enumeration { start, .. } => start.is_some(),
            Kind::Boolean { start } => start.is_some(),
            Kind::String { start } => start.is_some(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    pub name: String,
    pub description: String,
    pub causality: Causality,
    pub variability: Variability,
    /// `None`: the attribute is not written (the schema default applies).
    pub initial: Option<Initial>,
    pub kind: Kind,
}

impl Variable {
    /// A parameter (initial exact, start required).
    pub fn parameter(name: &str, variability: Variability, kind: Kind, description: &str) -> Variable {
        Variable { name: name.into(), description: description.into(), causality: Causality::Parameter, variability, initial: Some(Initial::Exact), kind }
    }
    /// A continuous Real input (start required, no initial attribute).
    pub fn input(name: &str, start: f64, unit: Option<&str>, description: &str) -> Variable {
        Variable {
            name: name.into(),
            description: description.into(),
            causality: Causality::Input,
            variability: Variability::Continuous,
            initial: None,
            kind: Kind::Real { start: Some(start), unit: unit.map(String::from), min: None, max: None },
        }
    }
    /// A calculated output (no start).
    pub fn output(name: &str, variability: Variability, kind: Kind, description: &str) -> Variable {
        Variable { name: name.into(), description: description.into(), causality: Causality::Output, variability, initial: Some(Initial::Calculated), kind }
    }

    /// `initial` with the schema default filled in (FMI 2.0 table of combinations).
    pub fn effective_initial(&self) -> Option<Initial> {
        if self.initial.is_some() {
            return self.initial;
        }
        use Causality::*;
        use Variability::*;
        match (self.causality, self.variability) {
            (Input, _) => Some(Initial::Exact),
            (Independent, _) => None,
            (Parameter, _) | (_, Constant) => Some(Initial::Exact),
            _ => Some(Initial::Calculated),
        }
    }
}

/// Where the instance is, as far as setting a variable is concerned (FMI 2.0 §2.2.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetPhase {
    Instantiated,
    InitializationMode,
    /// Step complete (slave initialised).
    Simulation,
}

/// An enumeration type of `<TypeDefinitions>`: items `(name, value, description)`.
#[derive(Clone, Debug, PartialEq)]
pub struct EnumerationType {
    pub name: String,
    pub items: Vec<(String, i32, String)>,
}

/// A unit of `<UnitDefinitions>`: its name, its non-zero SI base-unit exponents (`kg`, `m`, `s`,
/// `A`, `K`, `mol`, `cd`, `rad`), e.g. `("s", -1), ("rad", 1)`, and the factor to those base units
/// (1 mm = 0.001 m: factor 0.001; `<BaseUnit>` writes it when it is not 1). No exponents: the
/// unit "1" of a ratio.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitDefinition {
    pub name: String,
    pub base: Vec<(&'static str, i32)>,
    pub factor: f64,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct VariableTable {
    vars: Vec<Variable>,
}

impl VariableTable {
    pub fn new() -> Self {
        VariableTable::default()
    }
    /// Appends a variable and returns its value reference.
    pub fn push(&mut self, v: Variable) -> u32 {
        self.vars.push(v);
        (self.vars.len() - 1) as u32
    }
    pub fn get(&self, vr: u32) -> Option<&Variable> {
        self.vars.get(vr as usize)
    }
    pub fn len(&self) -> usize {
        self.vars.len()
    }
    pub fn is_empty(&self) -> bool {
        self.vars.is_empty()
    }
    pub fn iter(&self) -> impl Iterator<Item = (u32, &Variable)> {
        self.vars.iter().enumerate().map(|(i, v)| (i as u32, v))
    }
    pub fn by_name(&self, name: &str) -> Option<u32> {
        self.vars.iter().position(|v| v.name == name).map(|i| i as u32)
    }
    /// Value references of the outputs, in table order.
    pub fn outputs(&self) -> impl Iterator<Item = u32> + '_ {
        self.iter().filter(|(_, v)| v.causality == Causality::Output).map(|(vr, _)| vr)
    }
    /// Value references that belong in `<InitialUnknowns>`: outputs with initial approx or
    /// calculated, and calculated parameters.
    pub fn initial_unknowns(&self) -> impl Iterator<Item = u32> + '_ {
        self.iter()
            .filter(|(_, v)| match v.causality {
                Causality::Output => matches!(v.effective_initial(), Some(Initial::Approx | Initial::Calculated)),
                Causality::CalculatedParameter => true,
                _ => false,
            })
            .map(|(vr, _)| vr)
    }

    /// The variable `vr` of base type `ty`, or why not.
    pub fn lookup(&self, vr: u32, ty: BaseType) -> Result<&Variable> {
        let v = self.get(vr).ok_or_else(|| Error::input(format!("unknown value reference {vr} (this FMU has value references 0..{})", self.len())))?;
        if v.kind.base() != ty {
            return Err(Error::input(format!("value reference {vr} ({}) is a {} variable, not {}", v.name, v.kind.base().name(), ty.name())));
        }
        Ok(v)
    }

    /// Whether `vr` may be set in `phase` (FMI 2.0 §2.2.7, the rule fmpy follows).
    pub fn check_settable(&self, vr: u32, ty: BaseType, phase: SetPhase) -> Result<()> {
        let v = self.lookup(vr, ty)?;
        let init = v.effective_initial();
        let ok = match phase {
            SetPhase::Instantiated => v.variability != Variability::Constant && matches!(init, Some(Initial::Exact | Initial::Approx)),
            SetPhase::InitializationMode => v.causality == Causality::Input || (v.variability != Variability::Constant && init == Some(Initial::Exact)),
            SetPhase::Simulation => v.causality == Causality::Input || (v.causality == Causality::Parameter && v.variability == Variability::Tunable),
        };
        if ok {
            return Ok(());
        }
        let when = match phase {
            SetPhase::Instantiated => "before initialisation",
            SetPhase::InitializationMode => "in initialisation mode",
            SetPhase::Simulation => "after initialisation (only inputs and tunable parameters can)",
        };
        Err(Error::input(format!("{} (causality {}, variability {}) cannot be set {when}", v.name, v.causality.name(), v.variability.name())))
    }

    /// Checks the table against the FMI 2.0 rules that the XML schema and fmpy enforce: unique
    /// names, legal (causality, variability, initial) combinations, start values where required
    /// and only there.
    pub fn check(&self) -> Result<()> {
        let mut names = HashSet::new();
        for (vr, v) in self.iter() {
            if !names.insert(v.name.as_str()) {
                return Err(Error::input(format!("variable name {} is used twice", v.name)));
            }
            if !is_structured_name(&v.name) {
                return Err(Error::input(format!("variable name {} does not follow the structured naming convention", v.name)));
            }
            use Causality::*;
            use Variability::*;
            let legal = matches!(
                (v.causality, v.variability),
                (Parameter | CalculatedParameter, Fixed | Tunable) | (Input, Discrete | Continuous) | (Output | Local, _) | (Independent, Continuous)
            );
            if !legal {
                return Err(Error::input(format!(
                    "{} (vr {vr}): causality {} with variability {} is not allowed",
                    v.name,
                    v.causality.name(),
                    v.variability.name()
                )));
            }
            if v.variability == Continuous && v.kind.base() != BaseType::Real {
                return Err(Error::input(format!("{}: only Real variables can be continuous", v.name)));
            }
            let init = v.effective_initial();
            let needs_start = v.causality == Input || v.causality == Parameter || matches!(init, Some(Initial::Exact | Initial::Approx));
            let forbids_start = v.causality == Independent || init == Some(Initial::Calculated);
            if needs_start && !v.kind.has_start() {
                return Err(Error::input(format!("{}: a start value is required", v.name)));
            }
            if forbids_start && v.kind.has_start() {
                return Err(Error::input(format!("{}: a start value is not allowed (initial calculated)", v.name)));
            }
            if v.causality == Input && v.initial.is_some() {
                return Err(Error::input(format!("{}: an input takes no initial attribute", v.name)));
            }
        }
        Ok(())
    }
}

/// FMI 2.0 structured names (the subset we produce): `a`, `a[0]`, `a[0].b`, `a.b_c`.
pub fn is_structured_name(name: &str) -> bool {
    name.split('.').all(|part| {
        let (ident, rest) = match part.find('[') {
            Some(i) => (&part[..i], Some(&part[i..])),
            None => (part, None),
        };
        let mut chars = ident.chars();
        let first_ok = chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
        let ident_ok = first_ok && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
        let index_ok = match rest {
            None => true,
            Some(r) => r.len() > 2 && r.ends_with(']') && r[1..r.len() - 1].split(',').all(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit())),
        };
        ident_ok && index_ok
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> VariableTable {
        let mut t = VariableTable::new();
        t.push(Variable::parameter("p", Variability::Tunable, Kind::Real { start: Some(1.0), unit: None, min: None, max: None }, ""));
        t.push(Variable::parameter("n", Variability::Fixed, Kind::Integer { start: Some(4), min: None, max: None }, ""));
        t.push(Variable::input("u", 0.0, None, ""));
        t.push(Variable::output("y[0]", Variability::Continuous, Kind::Real { start: None, unit: None, min: None, max: None }, ""));
        t
    }

    #[test]
    fn settable_rules_follow_the_phase() {
        let t = table();
        assert!(t.check().is_ok());
        for vr in 0..3 {
            let ty = t.get(vr).unwrap().kind.base();
            assert!(t.check_settable(vr, ty, SetPhase::Instantiated).is_ok());
            assert!(t.check_settable(vr, ty, SetPhase::InitializationMode).is_ok());
        }
        assert!(t.check_settable(0, BaseType::Real, SetPhase::Simulation).is_ok());
        let e = t.check_settable(1, BaseType::Integer, SetPhase::Simulation).unwrap_err();
        assert!(e.message().contains("n (causality parameter, variability fixed) cannot be set after initialisation"), "{e}");
        assert!(t.check_settable(2, BaseType::Real, SetPhase::Simulation).is_ok());
        assert!(t.check_settable(3, BaseType::Real, SetPhase::Simulation).is_err());
        assert!(t.check_settable(3, BaseType::Real, SetPhase::Instantiated).is_err());
        assert!(t.check_settable(9, BaseType::Real, SetPhase::Instantiated).unwrap_err().message().contains("unknown value reference 9"));
        assert!(t.check_settable(0, BaseType::Integer, SetPhase::Instantiated).unwrap_err().message().contains("is a Real variable"));
    }

    #[test]
    fn check_refuses_illegal_tables() {
        let mut t = table();
        t.push(Variable::output("y[0]", Variability::Continuous, Kind::Real { start: None, unit: None, min: None, max: None }, ""));
        assert!(t.check().unwrap_err().message().contains("used twice"));
        let mut t = table();
        t.push(Variable::output("z", Variability::Continuous, Kind::Real { start: Some(0.0), unit: None, min: None, max: None }, ""));
        assert!(t.check().unwrap_err().message().contains("not allowed"));
        let mut t = table();
        t.push(Variable::parameter("q", Variability::Continuous, Kind::Real { start: Some(0.0), unit: None, min: None, max: None }, ""));
        assert!(t.check().is_err());
    }

    #[test]
    fn structured_names() {
        for ok in ["x", "displacement[0]", "contact[12].force", "lcp.pivots", "a_b.c_d[1,2]"] {
            assert!(is_structured_name(ok), "{ok}");
        }
        for bad in ["", "0x", "a[]", "a[x]", "a..b", "a-b", "a[0"] {
            assert!(!is_structured_name(bad), "{bad}");
        }
    }
}
