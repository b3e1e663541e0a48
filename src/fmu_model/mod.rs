//! The physics adapter behind the FMI 2 shell: a scene becomes a quasi-steady co-simulation
//! component whose outputs are the periodic response.
//!
//! - Variables come from the scene, only for the effects it calls for (see [`ContactModel::from_scene_text`]).
//! - `fmi2ExitInitializationMode` solves the periodic problem; `fmi2DoStep` evaluates the
//!   response at the new communication time, O(outputs), without allocating and without solving.
//! - When a tunable parameter or an input has changed, the next `fmi2DoStep` re-solves first,
//!   warm-started from the previous active set, reusing the FFT plan. The phase θ of the
//!   excitation is kept continuous across a change of ω (a frequency change is a chirp, not a
//!   phase jump): outputs are the response at τ = θ/ω mod T.
//! - With the parameter `polish` (scenes with contacts), each solve is refined by the
//!   event-fitted polish (`analysis::polish`) and displacement, velocity, contact force and gap
//!   at a communication point are the polished orbit's, exact between the instants (a matrix
//!   exponential per point: `fmi2DoStep` then allocates); `polish.status` says whether it
//!   succeeded (1) or fell back to the interpolation below (2, with a logged warning).
//! - Interpolation between the k instants, consistent with the scheme (`analysis::interpolant`):
//!   - `fourier`: the trigonometric interpolant of the samples (exact for the collocation);
//!   - the other schemes: displacement by cubic Hermite through (x_j, v_j) with the scheme's own
//!     velocity v_j, velocity as its derivative (so velocity = d/dt displacement exactly, and
//!     both equal the samples at the instants); acceleration piecewise linear;
//!   - contact force and gap: piecewise linear for every scheme, which keeps force ≥ 0 and a
//!     rigid gap ≥ 0 between the instants.
//!
//!   `fmi2GetRealOutputDerivatives` (order 1) is the exact time derivative of the interpolant:
//!   for `displacement[d]` it is the velocity.
use crate::analysis::accuracy;
use crate::analysis::continuation::{self, Current, Jump};
use crate::analysis::interpolant::{fill_powers, locate};
use crate::analysis::polish::{self, PolishedOrbit};
use crate::error::{Error, Result};
use crate::fmi::state::{StateReader, StateWriter};
use crate::fmi::{CoSimModel, DefaultExperiment, EventLog, ModelDescription};
use crate::model::Units;
pub use crate::periodic::Tuning;
use crate::periodic::{MAX_STEPS, MIN_STEPS, PeriodFft, PeriodicProblem, PeriodicSolver};
use crate::response::Response;
use crate::scene::Scene;
use crate::time::{Discretization, Scheme};
use num_complex::Complex64 as C;
use std::path::Path;
use std::sync::Arc;

mod documentation;
mod package;
mod series;
mod state;
mod variables;

pub use package::package;
use series::{Series, Solution};
pub use state::ContactSnapshot;
use variables::{Output, Role, Variables, unique};

pub const MODEL_IDENTIFIER: &str = "PeriodicContact";
/// The scene inside the FMU's `resources/`.
pub const SCENE_FILE: &str = "scene.toml";

/// Current parameter and input values.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Values {
    params: Tuning,
    inputs: Tuning,
    steps: usize,
    scheme: Scheme,
    polish: bool,
}

/// Everything a solve depends on.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Config {
    tuning: Tuning,
    steps: usize,
    scheme: Scheme,
    polish: bool,
}

impl Values {
    /// frequency_in > 0 replaces frequency; the scale inputs multiply, gap_offset_in adds.
    fn config(&self) -> Config {
        let (p, i) = (&self.params, &self.inputs);
        let tuning = Tuning {
            frequency: if i.frequency > 0.0 { i.frequency } else { p.frequency },
            force_scale: p.force_scale * i.force_scale,
            gap_offset: p.gap_offset + i.gap_offset,
            motion_scale: p.motion_scale * i.motion_scale,
            normal_force_scale: p.normal_force_scale * i.normal_force_scale,
        };
        Config { tuning, steps: self.steps, scheme: self.scheme, polish: self.polish }
    }
}

fn scheme_code(s: Scheme) -> i32 {
    Scheme::ALL.iter().position(|x| *x == s).expect("listed") as i32 + 1
}

/// The model of one FMU instance.
pub struct ContactModel {
    desc: ModelDescription,
    /// The scene's units (labels: the documentation page).
    units: Units,
    /// The scene's problem, recovering what the outputs need (displacement and velocity at
    /// every DOF that has either output).
    base: PeriodicProblem,
    roles: Vec<Role>,
    outputs: Vec<Output>,
    start: Values,
    values: Values,
    /// The solver session: the FFT plan and the warm start, updated at each re-solve.
    session: PeriodicSolver,
    /// Each solve also estimates its error (a second solve at k/2): the scene's
    /// `[discretization] error_estimate`, exposed as `accuracy.estimate`.
    estimate: bool,
    /// Each solve also computes the orbit's Floquet stability (`[output] stability`).
    stability: bool,
    solution: Option<Arc<Solution>>,
    /// The exact orbit on the branch the re-solves follow, with the configuration and active set
    /// of the solution it belongs to (after a state restore to another solution, the exact walk
    /// starts again from the polish of the grid orbit).
    branch: Option<(Config, Vec<usize>, PolishedOrbit)>,
    /// Why the last re-solve followed the discrete branch, not the exact one; the log says it once.
    discrete_why: Option<String>,
    said_discrete: bool,
    /// The log has said that the re-solves follow the exact branch.
    said_exact: bool,
    /// τ(t) = t + phase_offset (mod T): keeps the phase continuous across frequency changes.
    phase_offset: f64,
    initialized: bool,
    start_time: f64,
    /// Output values and their first derivatives at the current time, by slot.
    out: Vec<f64>,
    der: Vec<f64>,
    /// e^{i p ω τ}, p = 0..=max harmonic (fourier only).
    powers: Vec<C>,
}

impl ContactModel {
    /// Builds the model of a scene. `file` names the source in messages only.
    pub fn from_scene_text(text: &str, file: &str) -> Result<Self> {
        let scene = Scene::parse(text, file)?;
        let built = scene.build(file)?;
        let problem = built.problem;
        if problem.period_multiple() != 1 {
            // Its output series and phase bookkeeping are one forcing period long.
            return Err(Error::input(format!(
                "{file}: discretization.period_multiple: is {}; the FMU reports T-periodic orbits only: remove the key (use `periodic-contact solve --period-multiple` for orbits of several periods)",
                problem.period_multiple()
            )));
        }
        let shown = problem.outputs().clone();
        let model = problem.model();
        let Variables { table: t, roles, outputs, units } = Variables::of(&problem, &built.labels, built.error_estimate, built.stability, built.polish);
        let estimate = outputs.iter().any(|o| matches!(o, Output::Accuracy));
        let stability = outputs.iter().any(|o| matches!(o, Output::Stable));
        let k = problem.discretization().steps;
        let mut base = problem.clone();
        // No rayon inside an FMU: its global pool would outlive the instance and keep the
        // library mapped (notes, rust-crates §faer).
        base.set_parallel(false);
        let mut recovered = unique(&[shown.displacement.clone(), shown.velocity.clone()].concat());
        recovered.sort_unstable();
        let mut selection = base.outputs().clone();
        selection.displacement = recovered.clone();
        selection.velocity = recovered;
        base.set_outputs(selection)?;

        let period = model.period();
        let desc = ModelDescription {
            model_name: MODEL_IDENTIFIER.into(),
            model_identifier: MODEL_IDENTIFIER.into(),
            description: format!("{} (units: {})", summary(&problem), built.labels.units.summary()),
            generation_tool: format!("periodic-contact {}", env!("CARGO_PKG_VERSION")),
            variables: t,
            units,
            enumerations: vec![],
            default_experiment: Some(DefaultExperiment { start_time: 0.0, stop_time: 3.0 * period, step_size: period / k as f64 }),
            max_output_derivative_order: 1,
        };
        let scene_tuning = Tuning::of(&problem);
        let neutral = Tuning { frequency: 0.0, force_scale: 1.0, gap_offset: 0.0, motion_scale: 1.0, normal_force_scale: 1.0 };
        let polish = built.polish && !model.contacts.is_empty();
        let start = Values { params: scene_tuning, inputs: neutral, steps: k, scheme: problem.discretization().scheme, polish };
        let nout = outputs.len();
        Ok(ContactModel {
            desc,
            units: built.labels.units,
            roles,
            outputs,
            start,
            values: start,
            session: PeriodicSolver::new(base.clone()),
            estimate,
            stability,
            base,
            solution: None,
            branch: None,
            discrete_why: None,
            said_discrete: false,
            said_exact: false,
            phase_offset: 0.0,
            initialized: false,
            start_time: 0.0,
            out: vec![0.0; nout],
            der: vec![0.0; nout],
            powers: Vec::new(),
        })
    }

    /// The variable table and the rest of modelDescription.xml.
    pub fn model_description(&self) -> &ModelDescription {
        &self.desc
    }

    fn role(&self, vr: u32) -> Result<Role> {
        self.roles.get(vr as usize).copied().ok_or_else(|| Error::input(format!("unknown value reference {vr}")))
    }

    /// Solves `cfg`, continuing the current orbit along its branch when the grid is the same
    /// (`continuation::resolve`): the jump, when the branch ended at a fold on the way.
    fn solve(&mut self, cfg: Config) -> Result<(Solution, Option<Jump>)> {
        let disc = Discretization { scheme: cfg.scheme, steps: cfg.steps, pairing: self.base.discretization().pairing };
        // The current orbit is the current solution's (which an FMU-state restore may have changed).
        let current = self.solution.as_deref().filter(|s| s.k == cfg.steps && s.config.scheme == cfg.scheme);
        let orbit = |s: &Solution| self.branch.as_ref().filter(|b| b.0 == s.config && b.1 == s.active_set).map(|b| &b.2);
        let current =
            current.map(|s| Current { tuning: s.config.tuning, disc, active_set: &s.active_set, amplitude: s.amplitude, orbit: orbit(s), exact: true });
        let jumps = self.solution.as_ref().map_or(0, |s| s.jumps);
        let resolved = continuation::resolve(&mut self.session, &self.base, disc, cfg.tuning, current)?;
        self.discrete_why = resolved.exact;
        self.branch = resolved.orbit.map(|o| (cfg, resolved.response.active_set.clone(), o));
        let mut r = resolved.response;
        if self.estimate {
            r.accuracy = accuracy::estimate(self.session.problem(), &r);
        }
        // The exact orbit's multipliers where the branch was followed exactly, else the discrete ones.
        let stability = match (self.stability, resolved.stability) {
            (true, Some(exact)) => Some(exact),
            (true, None) => {
                Some(continuation::stability(self.session.problem(), &r.active_set).map_err(|why| Error::solve(format!("the stability of the orbit: {why}")))?)
            }
            (false, _) => None,
        };
        let jumps = jumps + u32::from(resolved.jump.is_some());
        let orbit = if cfg.polish { polish::apply(self.session.problem(), &mut r).map(Arc::new) } else { None };
        let mut sol = self.solution_of(cfg, self.session.problem(), &r, self.session.fft());
        sol.polished = orbit;
        for (series, q) in sol.series.iter_mut().zip(&self.outputs) {
            match (q, &stability) {
                (Output::Stable, Some(st)) => *series = Series::Constant(f64::from(u8::from(st.stable))),
                (Output::Multiplier, Some(st)) => *series = Series::Constant(st.largest),
                (Output::Jumps, _) => *series = Series::Constant(f64::from(jumps)),
                _ => {}
            }
        }
        sol.jumps = jumps;
        Ok((sol, resolved.jump))
    }

    fn solution_of(&self, config: Config, problem: &PeriodicProblem, r: &Response, fft: &PeriodFft) -> Solution {
        let omega = problem.model().frequency;
        let fourier = (config.scheme == Scheme::Fourier).then_some(fft);
        let key = |d: usize| d.to_string();
        let series = self
            .outputs
            .iter()
            .map(|q| match *q {
                Output::Displacement(d) | Output::Velocity(d) => {
                    let level = u8::from(matches!(q, Output::Velocity(_)));
                    Series::motion(&r.displacement[&key(d)], &r.velocity[&key(d)], level, fourier, omega)
                }
                // fourier: the samples are σ2 X̂ with σ2 = −(pω)² at every p, so their trigonometric
                // interpolant is the second derivative of the displacement's.
                Output::Acceleration(d) => {
                    let a = &r.acceleration[&key(d)];
                    if let Some(fft) = fourier { Series::trig(a, fft, |_| C::ONE) } else { Series::Linear(a.clone()) }
                }
                Output::Force(i) => Series::Linear(r.contacts[i].force.clone()),
                Output::Gap(i) => Series::Linear(r.contacts[i].gap.clone()),
                Output::Residual => Series::Constant(r.lcp.residual),
                Output::Pivots => Series::Constant(r.lcp.pivots as f64),
                Output::Accuracy => Series::Constant(r.accuracy.estimate.unwrap_or(0.0)),
                Output::AccuracyAvailable => Series::Constant(f64::from(u8::from(r.accuracy.estimate.is_some()))),
                // Set by `solve`, which knows the stability and the jumps.
                Output::Stable | Output::Multiplier | Output::Jumps => Series::Constant(0.0),
                Output::FrictionForce(i) => Series::Linear(r.friction[i].force.clone()),
                Output::FrictionSlipVelocity(i) => Series::Linear(r.friction[i].slip_velocity.clone()),
                // 0/1 samples; `evaluate` rounds to the nearest instant's flag.
                Output::FrictionStuck(i) => Series::Linear(r.friction[i].stuck.iter().map(|s| f64::from(u8::from(*s))).collect()),
                Output::PolishStatus => Series::Constant(match r.polish.as_ref().map(|p| p.status.as_str()) {
                    None => 0.0,
                    Some("polished") => 1.0,
                    Some(_) => 2.0,
                }),
            })
            .collect();
        Solution {
            config,
            period: r.period,
            h: r.period / r.steps as f64,
            omega,
            k: r.steps,
            series,
            pivots: r.lcp.pivots.min(i32::MAX as usize) as i32,
            residual: r.lcp.residual,
            active_set: r.active_set.clone(),
            warnings: r.warnings.clone(),
            amplitude: continuation::amplitude(r),
            jumps: 0,
            polished: None,
        }
    }

    /// Makes `sol` current; the phase θ at time `t` is kept.
    fn install(&mut self, sol: Solution, t: f64) {
        if let Some(old) = &self.solution {
            let fraction = ((t + self.phase_offset) / old.period).rem_euclid(1.0);
            self.phase_offset = fraction * sol.period - t;
        }
        let need = sol.max_harmonic() + 1;
        if self.powers.len() < need {
            self.powers = vec![C::ZERO; need];
        }
        self.solution = Some(Arc::new(sol));
    }

    /// Output values and derivatives at time `t`: O(outputs) (plus the kept harmonics for
    /// fourier), no allocation.
    fn evaluate(&mut self, t: f64) {
        let Some(sol) = self.solution.as_deref() else { return };
        let tau = (t + self.phase_offset).rem_euclid(sol.period);
        let (j, j1, s) = locate(tau, sol.h, sol.k);
        if self.powers.len() > 1 {
            fill_powers(&mut self.powers, sol.omega, tau);
        }
        for (i, series) in sol.series.iter().enumerate() {
            let (v, d) = series.eval(j, j1, s, sol.h, sol.omega, &self.powers);
            (self.out[i], self.der[i]) = match self.outputs[i] {
                // A flag: the nearest instant's (a tie goes to slip).
                Output::FrictionStuck(_) => (f64::from(u8::from(v > 0.5)), 0.0),
                _ => (v, d),
            };
        }
        if let Some(orbit) = &sol.polished {
            sol.eval_polished(orbit, &self.outputs, self.base.output_map(), tau, &mut self.out, &mut self.der);
        }
    }

    /// In initialisation mode outputs are computed on demand for the current values.
    fn ensure_outputs(&mut self) -> Result<()> {
        if self.initialized {
            return Ok(());
        }
        let cfg = self.values.config();
        if self.solution.as_ref().is_none_or(|s| s.config != cfg) {
            let (sol, _) = self.solve(cfg)?;
            self.phase_offset = 0.0;
            self.solution = None;
            self.install(sol, self.start_time);
        }
        self.evaluate(self.start_time);
        Ok(())
    }

    /// documentation/index.html: variables, units, conventions.
    pub fn documentation_html(&self, scene_name: &str) -> String {
        let u = &self.units;
        let units = format!("length {}, force {}, time {} (mass {})", u.length(), u.force(), u.time(), u.mass());
        documentation::render(&self.desc, scene_name, &units)
    }
}

impl CoSimModel for ContactModel {
    type Snapshot = ContactSnapshot;
    const STATE_VERSION: u16 = state::STATE_VERSION;

    fn instantiate(resources: Option<&Path>) -> Result<Self> {
        let dir = resources.ok_or_else(|| Error::input("no resource location was given; this FMU needs its resources/scene.toml"))?;
        let path = dir.join(SCENE_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(format!("{}: cannot read the scene: {e}", path.display())))?;
        ContactModel::from_scene_text(&text, &path.display().to_string())
    }

    fn description(&self) -> &ModelDescription {
        &self.desc
    }

    fn reset(&mut self) {
        self.values = self.start;
        self.solution = None;
        self.phase_offset = 0.0;
        self.initialized = false;
        self.start_time = 0.0;
        self.out.iter_mut().for_each(|v| *v = 0.0);
        self.der.iter_mut().for_each(|v| *v = 0.0);
    }

    fn enter_initialization(&mut self, start_time: f64) {
        self.start_time = start_time;
    }

    fn set_real(&mut self, vr: u32, v: f64) -> Result<()> {
        let role = self.role(vr)?;
        let name = &self.desc.variables.get(vr).expect("role exists").name;
        if !v.is_finite() {
            return Err(Error::input(format!("{name} = {v}: must be finite")));
        }
        let (p, i) = (&mut self.values.params, &mut self.values.inputs);
        match role {
            Role::Frequency if v > 0.0 => p.frequency = v,
            Role::Frequency => return Err(Error::input(format!("frequency = {v}: must be > 0 (rad/s)"))),
            Role::FrequencyIn if v >= 0.0 => i.frequency = v,
            Role::FrequencyIn => return Err(Error::input(format!("frequency_in = {v}: must be >= 0 (0 = not driven)"))),
            Role::ForceScale => p.force_scale = v,
            Role::GapOffset => p.gap_offset = v,
            Role::MotionScale => p.motion_scale = v,
            Role::NormalForceScale if v >= 0.0 => p.normal_force_scale = v,
            Role::NormalForceScale => return Err(Error::input(format!("normal_force_scale = {v}: must be >= 0 (a tensile normal load cannot hold friction)"))),
            Role::ForceScaleIn => i.force_scale = v,
            Role::GapOffsetIn => i.gap_offset = v,
            Role::MotionScaleIn => i.motion_scale = v,
            _ => return Err(Error::input(format!("{name} cannot be set"))),
        }
        Ok(())
    }

    fn set_integer(&mut self, vr: u32, v: i32) -> Result<()> {
        match self.role(vr)? {
            Role::Steps if (MIN_STEPS as i64..=MAX_STEPS as i64).contains(&(v as i64)) => self.values.steps = v as usize,
            Role::Steps => return Err(Error::input(format!("steps = {v}: must be in {MIN_STEPS}..={MAX_STEPS}"))),
            Role::Scheme if (1..=Scheme::ALL.len() as i32).contains(&v) => self.values.scheme = Scheme::ALL[(v - 1) as usize],
            Role::Scheme => return Err(Error::input(format!("scheme = {v}: must be 1..=5 (bds1, bds2, cds, galerkin, fourier)"))),
            _ => return Err(Error::input(format!("value reference {vr} cannot be set as Integer"))),
        }
        Ok(())
    }

    fn get_real(&mut self, vr: u32) -> Result<f64> {
        let (p, i) = (&self.values.params, &self.values.inputs);
        Ok(match self.role(vr)? {
            Role::Frequency => p.frequency,
            Role::ForceScale => p.force_scale,
            Role::GapOffset => p.gap_offset,
            Role::MotionScale => p.motion_scale,
            Role::NormalForceScale => p.normal_force_scale,
            Role::FrequencyIn => i.frequency,
            Role::ForceScaleIn => i.force_scale,
            Role::GapOffsetIn => i.gap_offset,
            Role::MotionScaleIn => i.motion_scale,
            Role::Output(slot) => {
                self.ensure_outputs()?;
                self.out[slot]
            }
            Role::Steps | Role::Scheme | Role::Polish => return Err(Error::input(format!("value reference {vr} is not Real"))),
        })
    }

    fn set_boolean(&mut self, vr: u32, v: bool) -> Result<()> {
        match self.role(vr)? {
            Role::Polish => self.values.polish = v,
            _ => return Err(Error::input(format!("value reference {vr} cannot be set as Boolean"))),
        }
        Ok(())
    }

    fn get_integer(&mut self, vr: u32) -> Result<i32> {
        Ok(match self.role(vr)? {
            Role::Steps => self.values.steps as i32,
            Role::Scheme => scheme_code(self.values.scheme),
            Role::Output(slot) => {
                self.ensure_outputs()?;
                self.out[slot] as i32
            }
            _ => return Err(Error::input(format!("value reference {vr} is not Integer"))),
        })
    }

    fn get_boolean(&mut self, vr: u32) -> Result<bool> {
        match self.role(vr)? {
            Role::Polish => Ok(self.values.polish),
            Role::Output(slot) => {
                self.ensure_outputs()?;
                Ok(self.out[slot] != 0.0)
            }
            _ => Err(Error::input(format!("value reference {vr} is not Boolean"))),
        }
    }

    fn exit_initialization(&mut self, start_time: f64, log: &dyn EventLog) -> Result<Vec<String>> {
        self.start_time = start_time;
        self.ensure_outputs()?;
        self.initialized = true;
        let sol = self.solution.as_deref().expect("solved by ensure_outputs");
        log.event(&format!("solved: {} instants, {} pivots, residual {:.3e}", sol.k, sol.pivots, sol.residual));
        Ok(sol.warnings.clone())
    }

    fn do_step(&mut self, t: f64, h: f64, log: &dyn EventLog) -> Result<()> {
        let cfg = self.values.config();
        if self.solution.as_ref().is_none_or(|s| s.config != cfg) {
            let old = self.solution.as_ref().map(|s| s.config.tuning.frequency);
            let (sol, jump) = self.solve(cfg)?;
            if let (Some(j), Some(old)) = (jump, old) {
                log.event(&format!(
                    "jump at t = {t}: the branch ended at a fold (frequency {:.9} rad/s) between frequency {old:.9} and {:.9}; amplitude {:.6e} -> {:.6e} (jump {})",
                    j.fold.frequency, cfg.tuning.frequency, j.from_amplitude, j.to_amplitude, sol.jumps
                ));
            }
            if old.is_some() && self.branch.is_some() && self.discrete_why.is_none() && !self.said_exact {
                self.said_exact = true;
                log.event("the re-solves follow the exact branch: each is a step of the exact walk from the current exact orbit, its jumps at the exact folds");
            }
            if let (Some(why), false) = (self.discrete_why.take(), self.said_discrete) {
                self.said_discrete = true;
                log.event(&format!("the re-solves follow the discrete branch of the grid, not the exact orbit's: {why}"));
            }
            log.event(&format!("re-solved at t = {t} for {:?}: {} pivots, residual {:.3e}", cfg.tuning, sol.pivots, sol.residual));
            self.install(sol, t);
        }
        self.evaluate(t + h);
        Ok(())
    }

    fn output_derivative(&self, vr: u32, order: i32) -> Result<f64> {
        match (self.role(vr)?, order) {
            (Role::Output(slot), 1) => Ok(self.der[slot]),
            _ => Err(Error::input(format!("no derivative of order {order} for value reference {vr}"))),
        }
    }

    fn snapshot(&self) -> ContactSnapshot {
        ContactSnapshot {
            values: self.values,
            solution: self.solution.clone(),
            phase_offset: self.phase_offset,
            initialized: self.initialized,
            start_time: self.start_time,
            out: self.out.clone(),
            der: self.der.clone(),
        }
    }

    fn restore(&mut self, s: &ContactSnapshot) {
        self.values = s.values;
        self.phase_offset = s.phase_offset;
        self.initialized = s.initialized;
        self.start_time = s.start_time;
        self.out.clone_from(&s.out);
        self.der.clone_from(&s.der);
        let need = s.solution.as_ref().map_or(0, |x| x.max_harmonic() + 1);
        if self.powers.len() < need {
            self.powers = vec![C::ZERO; need];
        }
        self.solution = s.solution.clone();
    }

    fn serialize(s: &ContactSnapshot, w: &mut StateWriter) {
        state::write(s, w)
    }

    fn deserialize(&self, r: &mut StateReader<'_>) -> Result<ContactSnapshot> {
        self.read_snapshot(r)
    }
}

/// The model description's one-line summary of the scene.
fn summary(problem: &PeriodicProblem) -> String {
    let model = problem.model();
    let (n, m, k) = (model.n(), model.contacts.len(), problem.discretization().steps);
    let effects = model.effects().names().join(", ");
    if m == 0 {
        format!(
            "Steady-state periodic response of a {n}-DOF linear structure without contact (effects: {}), solved over one period ({}, {k} instants); a quasi-steady co-simulation component",
            if effects.is_empty() { "none" } else { &effects },
            problem.discretization().scheme
        )
    } else {
        format!(
            "Steady-state periodic response of a {n}-DOF structure with {m} unilateral contact(s) (effects: {}), solved over one period as one LCP ({}, {k} instants); a quasi-steady co-simulation component",
            if effects.is_empty() { "none" } else { &effects },
            problem.discretization().scheme
        )
    }
}
