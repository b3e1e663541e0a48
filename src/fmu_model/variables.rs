//! The variables of the FMU, built from the scene: only the effects it calls for get a
//! parameter, an input or an output. One table gives the accessors and the model description.
use super::scheme_code;
use crate::fmi::table::{Kind, Variability, Variable, VariableTable};
use crate::periodic::{MIN_STEPS, PeriodicProblem};
use crate::time::Scheme;
use Variability::*;

/// What a value reference stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Role {
    Frequency,
    ForceScale,
    GapOffset,
    MotionScale,
    Steps,
    Scheme,
    FrequencyIn,
    ForceScaleIn,
    GapOffsetIn,
    MotionScaleIn,
    /// Index into the output slots.
    Output(usize),
}

/// What an output slot shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Quantity {
    Displacement(usize),
    Velocity(usize),
    Acceleration(usize),
    Force(usize),
    Gap(usize),
    Residual,
    Pivots,
}

/// The table with the role of each value reference and the quantity of each output slot.
pub(super) struct Variables {
    pub table: VariableTable,
    pub roles: Vec<Role>,
    pub outputs: Vec<Quantity>,
}

impl Variables {
    fn add(&mut self, v: Variable, r: Role) {
        self.table.push(v);
        self.roles.push(r);
    }
    fn output(&mut self, v: Variable, q: Quantity) {
        self.add(v, Role::Output(self.outputs.len()));
        self.outputs.push(q);
    }

    /// The variables of `problem` (the scene's, before the FMU changes its outputs).
    pub fn of(problem: &PeriodicProblem) -> Variables {
        let mut b = Variables { table: VariableTable::new(), roles: Vec::new(), outputs: Vec::new() };
        parameters(&mut b, problem);
        inputs(&mut b, problem);
        outputs(&mut b, problem);
        b
    }
}

fn real(start: Option<f64>, unit: Option<&str>) -> Kind {
    Kind::Real { start, unit: unit.map(String::from), min: None, max: None }
}

/// The DOFs of `l` in order, each once.
pub(super) fn unique(l: &[usize]) -> Vec<usize> {
    let mut seen = Vec::new();
    l.iter()
        .filter(|d| {
            if seen.contains(*d) {
                false
            } else {
                seen.push(**d);
                true
            }
        })
        .copied()
        .collect()
}

/// What the scene calls for: forces, the number of contacts, moving obstacles.
fn effects(problem: &PeriodicProblem) -> (bool, usize, bool) {
    let model = problem.model();
    (!model.forces.is_empty(), model.contacts.len(), model.contacts.iter().any(|c| !c.motion.is_empty()))
}

fn parameters(b: &mut Variables, problem: &PeriodicProblem) {
    let model = problem.model();
    let (has_forces, m, has_motion) = effects(problem);
    b.add(
        Variable::parameter(
            "frequency",
            Tunable,
            real(Some(model.frequency), Some("rad/s")),
            "Fundamental angular frequency of the excitation and of the obstacle motion; period T = 2*pi/frequency",
        ),
        Role::Frequency,
    );
    if has_forces {
        b.add(Variable::parameter("force_scale", Tunable, real(Some(1.0), None), "Multiplies every force amplitude of the scene"), Role::ForceScale);
    }
    if m > 0 {
        b.add(Variable::parameter("gap_offset", Tunable, real(Some(0.0), None), "Added to every static clearance (length unit of the scene)"), Role::GapOffset);
    }
    if has_motion {
        b.add(Variable::parameter("motion_scale", Tunable, real(Some(1.0), None), "Multiplies every obstacle-motion amplitude"), Role::MotionScale);
    }
    let k = problem.discretization().steps;
    b.add(
        Variable::parameter("steps", Fixed, Kind::Integer { start: Some(k as i32), min: Some(MIN_STEPS as i32), max: None }, "Number of instants k per period"),
        Role::Steps,
    );
    // An Integer rather than an Enumeration: libcosim ignores FMI 2 Enumeration variables.
    let codes: Vec<String> = Scheme::ALL.iter().map(|s| format!("{} {}", scheme_code(*s), s)).collect();
    let scheme = Kind::Integer { start: Some(scheme_code(problem.discretization().scheme)), min: Some(1), max: Some(Scheme::ALL.len() as i32) };
    b.add(Variable::parameter("scheme", Fixed, scheme, &format!("Time scheme on the period: {}", codes.join(", "))), Role::Scheme);
}

fn inputs(b: &mut Variables, problem: &PeriodicProblem) {
    let (has_forces, m, has_motion) = effects(problem);
    b.add(
        Variable::input("frequency_in", 0.0, Some("rad/s"), "Drives the frequency continuously: when > 0 it replaces the parameter frequency; 0 = not driven"),
        Role::FrequencyIn,
    );
    if has_forces {
        b.add(Variable::input("force_scale_in", 1.0, None, "Multiplies force_scale (1 = not driven)"), Role::ForceScaleIn);
    }
    if m > 0 {
        b.add(Variable::input("gap_offset_in", 0.0, None, "Added to gap_offset (0 = not driven)"), Role::GapOffsetIn);
    }
    if has_motion {
        b.add(Variable::input("motion_scale_in", 1.0, None, "Multiplies motion_scale (1 = not driven)"), Role::MotionScaleIn);
    }
}

fn outputs(b: &mut Variables, problem: &PeriodicProblem) {
    let (model, shown) = (problem.model(), &problem.outputs());
    for d in unique(&shown.displacement) {
        b.output(
            Variable::output(&format!("displacement[{d}]"), Continuous, real(None, None), &format!("Displacement of DOF {d} (length unit of the scene)")),
            Quantity::Displacement(d),
        );
    }
    for d in unique(&shown.velocity) {
        b.output(
            Variable::output(&format!("velocity[{d}]"), Continuous, real(None, None), &format!("Velocity of DOF {d} (length unit per second)")),
            Quantity::Velocity(d),
        );
    }
    for d in unique(&shown.acceleration) {
        b.output(
            Variable::output(&format!("acceleration[{d}]"), Continuous, real(None, None), &format!("Acceleration of DOF {d} (length unit per second squared)")),
            Quantity::Acceleration(d),
        );
    }
    if shown.contacts {
        for (i, c) in model.contacts.iter().enumerate() {
            b.output(
                Variable::output(
                    &format!("contact[{i}].force"),
                    Continuous,
                    real(None, None),
                    &format!("Compressive force >= 0 of contact {i} on DOF {} (force unit)", c.dof),
                ),
                Quantity::Force(i),
            );
            b.output(
                Variable::output(
                    &format!("contact[{i}].gap"),
                    Continuous,
                    real(None, None),
                    &format!("Clearance >= 0 of contact {i} on DOF {} (length unit)", c.dof),
                ),
                Quantity::Gap(i),
            );
        }
    }
    // Only with contacts: without them no LCP is solved (the scene's effects, nothing more).
    if !model.contacts.is_empty() {
        b.output(
            Variable::output("lcp.pivots", Discrete, Kind::Integer { start: None, min: None, max: None }, "Pivots of the last LCP solve"),
            Quantity::Pivots,
        );
        b.output(Variable::output("lcp.residual", Discrete, real(None, None), "Residual max|min(z, Az+q)| of the last LCP solve"), Quantity::Residual);
    }
}
