//! The variables of the FMU, built from the scene: only the effects it calls for get a
//! parameter, an input or an output. One table gives the accessors and the model description.
//!
//! Units: every Real with a dimension carries its unit in the scene's units (`[units]`, SI by
//! default), ratios (`force_scale`, `motion_scale` and their inputs) the unit "1"; `lcp.residual`
//! has none (a maximum over forces and clearances, of no single dimension). Every unit used is
//! declared in `<UnitDefinitions>` with its SI base units and factor.
use super::scheme_code;
use crate::fmi::table::{Kind, UnitDefinition, Variability, Variable, VariableTable};
use crate::model::{Compliance, Labels, Quantity};
use crate::periodic::{MIN_STEPS, PeriodicProblem, step_map};
use crate::time::Scheme;
use Variability::*;

/// What a value reference stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Role {
    Frequency,
    ForceScale,
    GapOffset,
    MotionScale,
    /// Multiplies every friction contact's normal load.
    NormalForceScale,
    Steps,
    Scheme,
    /// The event-fitted polish on (Boolean).
    Polish,
    FrequencyIn,
    ForceScaleIn,
    GapOffsetIn,
    MotionScaleIn,
    /// Index into the output slots.
    Output(usize),
}

/// What an output slot shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Output {
    Displacement(usize),
    Velocity(usize),
    Acceleration(usize),
    Force(usize),
    Gap(usize),
    Residual,
    Pivots,
    /// The error estimate of the last solve (`analysis::accuracy`) and whether there is one.
    Accuracy,
    AccuracyAvailable,
    /// The Floquet stability of the current orbit (`[output] stability`): all multipliers inside
    /// the unit circle, and the largest modulus.
    Stable,
    Multiplier,
    /// Jumps off a branch that ended at a fold, since initialisation.
    Jumps,
    /// 0 polish off, 1 polished, 2 fell back to the interpolated samples.
    PolishStatus,
    /// Friction contact i: its force f, slip velocity v, and whether it sticks (Boolean).
    FrictionForce(usize),
    FrictionSlipVelocity(usize),
    FrictionStuck(usize),
}

/// The table with the role of each value reference and the quantity of each output slot.
pub(super) struct Variables {
    pub table: VariableTable,
    pub roles: Vec<Role>,
    pub outputs: Vec<Output>,
    /// The unit definitions of the units used, in order of first use.
    pub units: Vec<UnitDefinition>,
}

impl Variables {
    fn add(&mut self, v: Variable, r: Role) {
        self.table.push(v);
        self.roles.push(r);
    }
    fn output(&mut self, v: Variable, q: Output) {
        self.add(v, Role::Output(self.outputs.len()));
        self.outputs.push(q);
    }

    /// The variables of `problem` (the scene's, before the FMU changes its outputs), labelled
    /// with the scene's units and DOF names.
    /// With `estimate`, the error estimate of each solve is an output too.
    /// `polish`: the start value of the parameter `polish` (scenes with contacts only).
    pub fn of(problem: &PeriodicProblem, labels: &Labels, estimate: bool, stability: bool, polish: bool) -> Variables {
        let mut b = Variables { table: VariableTable::new(), roles: Vec::new(), outputs: Vec::new(), units: Vec::new() };
        parameters(&mut b, problem, labels, polish);
        inputs(&mut b, problem, labels);
        outputs(&mut b, problem, labels);
        if estimate && !problem.outputs().displacement.is_empty() {
            let kind = b.real(None, Quantity::Length, labels);
            let what = "Error estimate of the last solve: max over the instants and displacement outputs, from a second solve at k/2 (Richardson); 0 when accuracy.estimated = 0";
            b.output(Variable::output("accuracy.estimate", Discrete, kind, what), Output::Accuracy);
            let kind = Kind::Integer { start: None, min: None, max: None };
            let what = "1 when accuracy.estimate holds an estimate; 0 when none can be given (a scheme that does not converge for this contact, k/2 beyond the stability limit)";
            b.output(Variable::output("accuracy.estimated", Discrete, kind, what), Output::AccuracyAvailable);
        }
        branch(&mut b, problem, labels, stability);
        b
    }

    /// A Real of quantity `q` in the scene's units (declared on first use).
    fn real(&mut self, start: Option<f64>, q: Quantity, labels: &Labels) -> Kind {
        let name = labels.units.name(q);
        if !self.units.iter().any(|u| u.name == name) {
            let (factor, exps) = labels.units.si(q);
            let base = ["kg", "m", "s", "rad"].into_iter().zip(exps).filter(|(_, e)| *e != 0).collect();
            self.units.push(UnitDefinition { name: name.clone(), base, factor });
        }
        Kind::Real { start, unit: Some(name), min: None, max: None }
    }
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

fn parameters(b: &mut Variables, problem: &PeriodicProblem, labels: &Labels, problem_polish: bool) {
    let model = problem.model();
    let (has_forces, m, has_motion) = effects(problem);
    let kind = b.real(Some(model.frequency), Quantity::Frequency, labels);
    let time = labels.units.time();
    let text = format!("Fundamental angular frequency of the excitation and of the obstacle motion; period T = 2*pi/frequency [{time}]");
    b.add(Variable::parameter("frequency", Tunable, kind, &text), Role::Frequency);
    if has_forces {
        let kind = b.real(Some(1.0), Quantity::Ratio, labels);
        b.add(Variable::parameter("force_scale", Tunable, kind, "Multiplies every force amplitude of the scene"), Role::ForceScale);
    }
    if m > 0 {
        let kind = b.real(Some(0.0), Quantity::Length, labels);
        b.add(Variable::parameter("gap_offset", Tunable, kind, "Added to every static clearance"), Role::GapOffset);
    }
    if has_motion {
        let kind = b.real(Some(1.0), Quantity::Ratio, labels);
        b.add(Variable::parameter("motion_scale", Tunable, kind, "Multiplies every obstacle-motion amplitude"), Role::MotionScale);
    }
    if !model.frictions.is_empty() {
        let kind = b.real(Some(1.0), Quantity::Ratio, labels);
        let text = "Multiplies every friction contact's normal load N, so its slip force mu*N (1 = the scene's loads; >= 0)";
        b.add(Variable::parameter("normal_force_scale", Tunable, kind, text), Role::NormalForceScale);
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
    if m > 0 {
        let text = "Refine each solve by the event-fitted polish: displacement, velocity, contact force and gap then come from the exact orbit between the events (see polish.status); default: the scene's [discretization] polish";
        b.add(Variable::parameter("polish", Tunable, Kind::Boolean { start: Some(problem_polish) }, text), Role::Polish);
    }
}

fn inputs(b: &mut Variables, problem: &PeriodicProblem, labels: &Labels) {
    let (has_forces, m, has_motion) = effects(problem);
    let input = |b: &mut Variables, name: &str, start: f64, q: Quantity, text: &str, role: Role| {
        let Kind::Real { unit, .. } = b.real(None, q, labels) else { unreachable!("a Real") };
        b.add(Variable::input(name, start, unit.as_deref(), text), role);
    };
    let text = "Drives the frequency continuously: when > 0 it replaces the parameter frequency; 0 = not driven";
    input(b, "frequency_in", 0.0, Quantity::Frequency, text, Role::FrequencyIn);
    if has_forces {
        input(b, "force_scale_in", 1.0, Quantity::Ratio, "Multiplies force_scale (1 = not driven)", Role::ForceScaleIn);
    }
    if m > 0 {
        input(b, "gap_offset_in", 0.0, Quantity::Length, "Added to gap_offset (0 = not driven)", Role::GapOffsetIn);
    }
    if has_motion {
        input(b, "motion_scale_in", 1.0, Quantity::Ratio, "Multiplies motion_scale (1 = not driven)", Role::MotionScaleIn);
    }
}

fn outputs(b: &mut Variables, problem: &PeriodicProblem, labels: &Labels) {
    let (model, shown) = (problem.model(), &problem.outputs());
    let name = |d: usize| match labels.names.get(&d) {
        Some(n) => format!("{n} (DOF {d})"),
        None => format!("DOF {d}"),
    };
    let motions = [
        ("displacement", "Displacement", Quantity::Length, &shown.displacement, Output::Displacement as fn(usize) -> Output),
        ("velocity", "Velocity", Quantity::Velocity, &shown.velocity, Output::Velocity),
        ("acceleration", "Acceleration", Quantity::Acceleration, &shown.acceleration, Output::Acceleration),
    ];
    for (var, text, q, list, slot) in motions {
        for d in unique(list) {
            let kind = b.real(None, q, labels);
            b.output(Variable::output(&format!("{var}[{d}]"), Continuous, kind, &format!("{text} of {}", name(d))), slot(d));
        }
    }
    if shown.contacts {
        let stiffness_unit = format!("{}/{}", labels.units.force(), labels.units.length());
        for (i, c) in model.contacts.iter().enumerate() {
            let at = contact_place(i, problem.user_row(i), &name);
            let (force, gap) = match c.compliance {
                Compliance::Rigid => (
                    format!("Compressive force >= 0 of the rigid {at}; > 0 only where the clearance is 0"),
                    format!("Clearance >= 0 of the rigid {at}: obstacle position gap(t) minus the displacement along the contact direction"),
                ),
                Compliance::Compliant { stiffness } => (
                    format!("Compressive force >= 0 of the compliant {at}: stiffness*penetration, stiffness {stiffness} {stiffness_unit}"),
                    format!(
                        "Clearance of the compliant {at}: gap(t) minus the displacement along the contact direction; negative = penetration (force = stiffness*penetration)"
                    ),
                ),
            };
            let kind = b.real(None, Quantity::Force, labels);
            b.output(Variable::output(&format!("contact[{i}].force"), Continuous, kind, &force), Output::Force(i));
            let kind = b.real(None, Quantity::Length, labels);
            b.output(Variable::output(&format!("contact[{i}].gap"), Continuous, kind, &gap), Output::Gap(i));
        }
    }
    friction_outputs(b, problem, labels, &name);
    // Only with contacts: without them no LCP is solved (the scene's effects, nothing more).
    if !model.contacts.is_empty() {
        b.output(Variable::output("lcp.pivots", Discrete, Kind::Integer { start: None, min: None, max: None }, "Pivots of the last LCP solve"), Output::Pivots);
        let kind = Kind::Real { start: None, unit: None, min: None, max: None };
        b.output(
            Variable::output("lcp.residual", Discrete, kind, "Residual max|min(z, Az+q)| of the last LCP solve (forces and clearances: no unit)"),
            Output::Residual,
        );
        let kind = Kind::Integer { start: None, min: None, max: None };
        let what = "Event-fitted polish of the last solve: 0 off (parameter polish = false), 1 polished (outputs exact between the instants), 2 fell back to the interpolated samples (the reason is logged as a warning)";
        b.output(Variable::output("polish.status", Discrete, kind, what), Output::PolishStatus);
    }
}

/// Force, slip velocity and stuck flag of each `[[friction]]` (none without).
fn friction_outputs(b: &mut Variables, problem: &PeriodicProblem, labels: &Labels, name: &dyn Fn(usize) -> String) {
    for (i, f) in problem.model().frictions.iter().enumerate() {
        let on = match f.row.as_slice() {
            [(d, _)] if problem.output_map().is_none() => name(*d),
            // A clamped scene numbers the model's DOFs apart from the user's.
            [(d, _)] => format!("model DOF {d}"),
            _ => "its sliding direction".to_string(),
        };
        let (force, length) = (labels.units.force(), labels.units.length());
        let element = match f.stiffness {
            Some(kt) => format!("a Jenkins element (tangential stiffness {kt} {force}/{length})"),
            None => "rigid Coulomb friction".to_string(),
        };
        let slip = format!("{} {force}", f.slip_force());
        let kind = b.real(None, Quantity::Force, labels);
        let bound = match f.contact {
            Some(c) => format!(
                "|force| <= mu*lambda_n (mu = {}, lambda_n the force of contact {c}), = mu*lambda_n*sign(slip_velocity) while slipping, 0 while the contact is open",
                f.coefficient
            ),
            None => format!("|force| <= mu*N ({slip} times normal_force_scale), = mu*N*sign(slip_velocity) while slipping"),
        };
        let what =
            format!("Friction force of friction contact {i} on {on}, {element}: acts on the structure as minus the force along the sliding direction; {bound}");
        b.output(Variable::output(&format!("friction[{i}].force"), Continuous, kind, &what), Output::FrictionForce(i));
        let kind = b.real(None, Quantity::Velocity, labels);
        let what =
            format!("Slip velocity of friction contact {i} (bds1's backward difference at the instants; a Jenkins element's slider velocity); 0 while stuck");
        b.output(Variable::output(&format!("friction[{i}].slip_velocity"), Continuous, kind, &what), Output::FrictionSlipVelocity(i));
        let what = format!("true while friction contact {i} sticks (|force| < mu*N): the flag of the nearest instant");
        b.output(Variable::output(&format!("friction[{i}].stuck"), Discrete, Kind::Boolean { start: None }, &what), Output::FrictionStuck(i));
    }
}

/// "contact 2 on MC:y (DOF 7)", or for a normal over several DOFs "contact 2 along 0.6·LE:x
/// (DOF 3) + 0.8·LE:y (DOF 4)": the gap is gap(t) minus the displacement along that normal.
fn contact_place(i: usize, row: &[(usize, f64)], name: &dyn Fn(usize) -> String) -> String {
    match row {
        [(d, _)] => format!("contact {i} on {}", name(*d)),
        _ => {
            let terms: Vec<String> = row.iter().map(|&(d, c)| format!("{c:.6}*{}", name(d))).collect();
            format!("contact {i} along the normal {}", terms.join(" + "))
        }
    }
}

/// The branch outputs (issue 13 item 6), only where the scheme has a step map and the scene has
/// contacts: `jumps` always, `stable` and `multiplier` when the scene asks (`[output] stability`).
fn branch(b: &mut Variables, problem: &PeriodicProblem, labels: &Labels, stability: bool) {
    if problem.model().contacts.is_empty() || step_map(problem).is_err() {
        return;
    }
    let what = "Jumps since initialisation: re-solves where the branch of the current orbit ended at a fold between the old and the new values, so the response jumped to the orbit that exists (each logged in logEvents with the frequency and the amplitudes)";
    b.output(Variable::output("jumps", Discrete, Kind::Integer { start: None, min: None, max: None }, what), Output::Jumps);
    if stability {
        let what = "true when every Floquet multiplier of the current orbit is inside the unit circle (the discrete monodromy of the step map on the orbit's active sets, as periodic-contact continue)";
        b.output(Variable::output("stable", Discrete, Kind::Boolean { start: None }, what), Output::Stable);
        let kind = b.real(None, Quantity::Ratio, labels);
        b.output(Variable::output("multiplier", Discrete, kind, "Largest Floquet modulus of the current orbit (> 1: unstable)"), Output::Multiplier);
    }
}
