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
//! - Interpolation between the k instants, consistent with the scheme:
//!   - `fourier`: the trigonometric interpolant of the samples (exact for the collocation);
//!   - the other schemes: displacement by cubic Hermite through (x_j, v_j) with the scheme's own
//!     velocity v_j, velocity as its derivative (so velocity = d/dt displacement exactly, and
//!     both equal the samples at the instants); acceleration piecewise linear;
//!   - contact force and gap: piecewise linear for every scheme, which keeps force ≥ 0 and a
//!     rigid gap ≥ 0 between the instants.
//!
//!   `fmi2GetRealOutputDerivatives` (order 1) is the exact time derivative of the interpolant:
//!   for `displacement[d]` it is the velocity.
use crate::fmi2::bytes::{ByteReader, ByteWriter};
use crate::fmi2::table::{Kind, UnitDefinition, Variability, Variable, VariableTable};
use crate::fmi2::{DefaultExperiment, Fmi2Model, Logger, ModelDescription};
pub use crate::periodic::Tuning;
use crate::periodic::{MAX_STEPS, MIN_STEPS, PeriodFft, PeriodicProblem};
use crate::response::Response;
use crate::scene::Scene;
use crate::time::{Discretization, Scheme};
use num_complex::Complex64 as C;
use std::path::Path;
use std::sync::Arc;

pub const MODEL_IDENTIFIER: &str = "PeriodicContact";
/// The scene inside the FMU's `resources/`.
pub const SCENE_FILE: &str = "scene.toml";

/// What a value reference stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
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

#[derive(Clone, Copy, Debug, PartialEq)]
enum Quantity {
    Displacement(usize),
    Velocity(usize),
    Acceleration(usize),
    Force(usize),
    Gap(usize),
    Residual,
    Pivots,
}

/// Current parameter and input values.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Values {
    params: Tuning,
    inputs: Tuning,
    steps: usize,
    scheme: Scheme,
}

/// Everything a solve depends on.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Config {
    tuning: Tuning,
    steps: usize,
    scheme: Scheme,
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
        };
        Config { tuning, steps: self.steps, scheme: self.scheme }
    }
}

fn scheme_code(s: Scheme) -> i32 {
    Scheme::ALL.iter().position(|x| *x == s).expect("listed") as i32 + 1
}

/// One output over the period with its interpolant.
#[derive(Clone, Debug, PartialEq)]
enum Series {
    /// Cubic Hermite through (x_j, v_j); `level` 0 gives H, 1 gives H'.
    Hermite {
        x: Vec<f64>,
        v: Vec<f64>,
        level: u8,
    },
    Linear(Vec<f64>),
    /// Re Σ c e^{i p ω τ} over the harmonics p kept.
    Trig {
        p: Vec<usize>,
        c: Vec<C>,
    },
    Constant(f64),
}

impl Series {
    /// Value and first time derivative at sample j (next j1) and fraction s of the step h.
    #[inline]
    fn eval(&self, j: usize, j1: usize, s: f64, h: f64, omega: f64, powers: &[C]) -> (f64, f64) {
        match self {
            Series::Hermite { x, v, level } => {
                let (x0, x1, v0, v1) = (x[j], x[j1], v[j] * h, v[j1] * h);
                let (s2, s3) = (s * s, s * s * s);
                let d1 = ((6.0 * s2 - 6.0 * s) * (x0 - x1) + (3.0 * s2 - 4.0 * s + 1.0) * v0 + (3.0 * s2 - 2.0 * s) * v1) / h;
                if *level == 0 {
                    let val = (2.0 * s3 - 3.0 * s2 + 1.0) * x0 + (s3 - 2.0 * s2 + s) * v0 + (-2.0 * s3 + 3.0 * s2) * x1 + (s3 - s2) * v1;
                    (val, d1)
                } else {
                    let d2 = ((12.0 * s - 6.0) * (x0 - x1) + (6.0 * s - 4.0) * v0 + (6.0 * s - 2.0) * v1) / (h * h);
                    (d1, d2)
                }
            }
            Series::Linear(y) => ((1.0 - s) * y[j] + s * y[j1], (y[j1] - y[j]) / h),
            Series::Trig { p, c } => {
                let (mut val, mut der) = (0.0, 0.0);
                for (&p, c) in p.iter().zip(c) {
                    let z = c * powers[p];
                    val += z.re;
                    der -= p as f64 * omega * z.im;
                }
                (val, der)
            }
            Series::Constant(v) => (*v, 0.0),
        }
    }

    /// Trigonometric interpolant of real samples: c_0 = X̂_0/k, c_p = 2X̂_p/k, c_{k/2} = X̂_{k/2}/k,
    /// times `factor(p)` (i p ω for a derivative); negligible harmonics dropped.
    fn trig(samples: &[f64], fft: &PeriodFft, factor: impl Fn(usize) -> C) -> Series {
        let k = samples.len();
        let spec = fft.forward(samples);
        let coef: Vec<C> = spec
            .iter()
            .enumerate()
            .map(|(p, x)| {
                let w = if p == 0 || (k % 2 == 0 && p == k / 2) { 1.0 } else { 2.0 };
                let mut c = x * w / k as f64;
                if p == 0 || (k % 2 == 0 && p == k / 2) {
                    c.im = 0.0;
                }
                c * factor(p)
            })
            .collect();
        let big = coef.iter().map(|c| c.norm()).fold(0.0, f64::max);
        let keep: Vec<usize> = (0..coef.len()).filter(|&p| coef[p].norm() > 1e-15 * big).collect();
        Series::Trig { c: keep.iter().map(|&p| coef[p]).collect(), p: keep }
    }
}

/// A solved configuration: one series per output slot.
#[derive(Clone, Debug, PartialEq)]
struct Solution {
    config: Config,
    period: f64,
    h: f64,
    omega: f64,
    k: usize,
    series: Vec<Series>,
    pivots: i32,
    residual: f64,
    active_set: Vec<usize>,
    warnings: Vec<String>,
}

impl Solution {
    fn max_harmonic(&self) -> usize {
        self.series.iter().filter_map(|s| if let Series::Trig { p, .. } = s { p.last().copied() } else { None }).max().unwrap_or(0)
    }
}

/// The model of one FMU instance.
pub struct ContactModel {
    desc: ModelDescription,
    /// The scene's problem, recovering what the outputs need (displacement and velocity at
    /// every DOF that has either output).
    base: PeriodicProblem,
    roles: Vec<Role>,
    outputs: Vec<Quantity>,
    start: Values,
    values: Values,
    fft: Option<PeriodFft>,
    solution: Option<Arc<Solution>>,
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

/// What `fmi2GetFMUstate` keeps of a [`ContactModel`].
#[derive(Clone)]
pub struct ContactSnapshot {
    values: Values,
    solution: Option<Arc<Solution>>,
    phase_offset: f64,
    initialized: bool,
    start_time: f64,
    out: Vec<f64>,
    der: Vec<f64>,
}

impl ContactModel {
    /// Builds the model of a scene. `file` names the source in messages only.
    pub fn from_scene_text(text: &str, file: &str) -> Result<Self, String> {
        let scene = Scene::parse(text, file).map_err(|e| e.to_string())?;
        let problem = scene.to_problem(file).map_err(|e| e.to_string())?;
        let shown = problem.outputs().clone();
        let model = problem.model();
        let (n, m) = (model.n(), model.contacts.len());
        let has_forces = !model.forces.is_empty();
        let has_motion = model.contacts.iter().any(|c| !c.motion.is_empty());

        let real = |start: Option<f64>, unit: Option<&str>| Kind::Real { start, unit: unit.map(String::from), min: None, max: None };
        let mut t = VariableTable::new();
        let mut roles = Vec::new();
        let mut add = |t: &mut VariableTable, v: Variable, r: Role| {
            t.push(v);
            roles.push(r);
        };
        use Variability::*;
        add(
            &mut t,
            Variable::parameter(
                "frequency",
                Tunable,
                real(Some(model.frequency), Some("rad/s")),
                "Fundamental angular frequency of the excitation and of the obstacle motion; period T = 2*pi/frequency",
            ),
            Role::Frequency,
        );
        if has_forces {
            add(&mut t, Variable::parameter("force_scale", Tunable, real(Some(1.0), None), "Multiplies every force amplitude of the scene"), Role::ForceScale);
        }
        if m > 0 {
            add(
                &mut t,
                Variable::parameter("gap_offset", Tunable, real(Some(0.0), None), "Added to every static clearance (length unit of the scene)"),
                Role::GapOffset,
            );
        }
        if has_motion {
            add(&mut t, Variable::parameter("motion_scale", Tunable, real(Some(1.0), None), "Multiplies every obstacle-motion amplitude"), Role::MotionScale);
        }
        let k = problem.discretization().steps;
        add(
            &mut t,
            Variable::parameter(
                "steps",
                Fixed,
                Kind::Integer { start: Some(k as i32), min: Some(MIN_STEPS as i32), max: None },
                "Number of instants k per period",
            ),
            Role::Steps,
        );
        // An Integer rather than an Enumeration: libcosim ignores FMI 2 Enumeration variables.
        let codes: Vec<String> = Scheme::ALL.iter().map(|s| format!("{} {}", scheme_code(*s), s)).collect();
        let scheme = Kind::Integer { start: Some(scheme_code(problem.discretization().scheme)), min: Some(1), max: Some(Scheme::ALL.len() as i32) };
        add(&mut t, Variable::parameter("scheme", Fixed, scheme, &format!("Time scheme on the period: {}", codes.join(", "))), Role::Scheme);
        add(
            &mut t,
            Variable::input(
                "frequency_in",
                0.0,
                Some("rad/s"),
                "Drives the frequency continuously: when > 0 it replaces the parameter frequency; 0 = not driven",
            ),
            Role::FrequencyIn,
        );
        if has_forces {
            add(&mut t, Variable::input("force_scale_in", 1.0, None, "Multiplies force_scale (1 = not driven)"), Role::ForceScaleIn);
        }
        if m > 0 {
            add(&mut t, Variable::input("gap_offset_in", 0.0, None, "Added to gap_offset (0 = not driven)"), Role::GapOffsetIn);
        }
        if has_motion {
            add(&mut t, Variable::input("motion_scale_in", 1.0, None, "Multiplies motion_scale (1 = not driven)"), Role::MotionScaleIn);
        }
        let mut outputs = Vec::new();
        let mut out = |t: &mut VariableTable, v: Variable, q: Quantity| {
            add(t, v, Role::Output(outputs.len()));
            outputs.push(q);
        };
        let unique = |l: &[usize]| {
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
                .collect::<Vec<_>>()
        };
        for d in unique(&shown.displacement) {
            out(
                &mut t,
                Variable::output(&format!("displacement[{d}]"), Continuous, real(None, None), &format!("Displacement of DOF {d} (length unit of the scene)")),
                Quantity::Displacement(d),
            );
        }
        for d in unique(&shown.velocity) {
            out(
                &mut t,
                Variable::output(&format!("velocity[{d}]"), Continuous, real(None, None), &format!("Velocity of DOF {d} (length unit per second)")),
                Quantity::Velocity(d),
            );
        }
        for d in unique(&shown.acceleration) {
            out(
                &mut t,
                Variable::output(
                    &format!("acceleration[{d}]"),
                    Continuous,
                    real(None, None),
                    &format!("Acceleration of DOF {d} (length unit per second squared)"),
                ),
                Quantity::Acceleration(d),
            );
        }
        if shown.contacts {
            for (i, c) in model.contacts.iter().enumerate() {
                out(
                    &mut t,
                    Variable::output(
                        &format!("contact[{i}].force"),
                        Continuous,
                        real(None, None),
                        &format!("Compressive force >= 0 of contact {i} on DOF {} (force unit)", c.dof),
                    ),
                    Quantity::Force(i),
                );
                out(
                    &mut t,
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
        // Always present, like the result's `lcp` (size 0, 0 pivots, residual 0 without contact).
        {
            out(
                &mut t,
                Variable::output("lcp.pivots", Discrete, Kind::Integer { start: None, min: None, max: None }, "Pivots of the last LCP solve"),
                Quantity::Pivots,
            );
            out(&mut t, Variable::output("lcp.residual", Discrete, real(None, None), "Residual max|min(z, Az+q)| of the last LCP solve"), Quantity::Residual);
        }

        let mut base = problem.clone();
        // No rayon inside an FMU: its global pool would outlive the instance and keep the
        // library mapped (notes, rust-crates §faer).
        base.set_parallel(false);
        let mut recovered = unique(&[shown.displacement.clone(), shown.velocity.clone()].concat());
        recovered.sort_unstable();
        let mut selection = base.outputs().clone();
        selection.displacement = recovered.clone();
        selection.velocity = recovered;
        base.set_outputs(selection).map_err(|e| e.to_string())?;

        let period = model.period();
        let effects = model.effects().names().join(", ");
        let desc = ModelDescription {
            model_name: MODEL_IDENTIFIER.into(),
            model_identifier: MODEL_IDENTIFIER.into(),
            description: if m == 0 {
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
            },
            generation_tool: format!("periodic-contact {}", env!("CARGO_PKG_VERSION")),
            variables: t,
            units: vec![UnitDefinition { name: "rad/s".into(), base: vec![("s", -1), ("rad", 1)] }],
            enumerations: vec![],
            default_experiment: Some(DefaultExperiment { start_time: 0.0, stop_time: 3.0 * period, step_size: period / k as f64 }),
            max_output_derivative_order: 1,
        };
        let scene_tuning = Tuning::of(&problem);
        let neutral = Tuning { frequency: 0.0, force_scale: 1.0, gap_offset: 0.0, motion_scale: 1.0 };
        let start = Values { params: scene_tuning, inputs: neutral, steps: k, scheme: problem.discretization().scheme };
        let nout = outputs.len();
        Ok(ContactModel {
            desc,
            base,
            roles,
            outputs,
            start,
            values: start,
            fft: None,
            solution: None,
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

    fn role(&self, vr: u32) -> Result<Role, String> {
        self.roles.get(vr as usize).copied().ok_or_else(|| format!("unknown value reference {vr}"))
    }

    /// Solves `cfg`, warm-started from the current solution when the grid is the same.
    fn solve(&mut self, cfg: Config) -> Result<Solution, String> {
        let disc = Discretization { scheme: cfg.scheme, steps: cfg.steps, pairing: self.base.discretization().pairing };
        let problem = cfg.tuning.apply(&self.base, disc).map_err(|e| e.to_string())?;
        if self.fft.as_ref().is_none_or(|f| f.k() != cfg.steps) {
            self.fft = Some(PeriodFft::new(cfg.steps));
        }
        let fft = self.fft.as_ref().expect("planned above");
        let warm = self.solution.as_ref().filter(|s| s.k == cfg.steps).map(|s| s.active_set.as_slice());
        let r = problem.solve_with(fft, warm).map_err(|e| e.to_string())?;
        Ok(self.solution_of(cfg, &problem, &r, fft))
    }

    fn solution_of(&self, config: Config, problem: &PeriodicProblem, r: &Response, fft: &PeriodFft) -> Solution {
        let omega = problem.model().frequency;
        let fourier = config.scheme == Scheme::Fourier;
        let key = |d: usize| d.to_string();
        let series = self
            .outputs
            .iter()
            .map(|q| match *q {
                Quantity::Displacement(d) | Quantity::Velocity(d) => {
                    let level = u8::from(matches!(q, Quantity::Velocity(_)));
                    let x = &r.displacement[&key(d)];
                    if fourier {
                        Series::trig(x, fft, |p| if level == 0 { C::ONE } else { C::new(0.0, p as f64 * omega) })
                    } else {
                        Series::Hermite { x: x.clone(), v: r.velocity[&key(d)].clone(), level }
                    }
                }
                // fourier: the samples are σ2 X̂ with σ2 = −(pω)² at every p, so their trigonometric
                // interpolant is the second derivative of the displacement's.
                Quantity::Acceleration(d) => {
                    let a = &r.acceleration[&key(d)];
                    if fourier { Series::trig(a, fft, |_| C::ONE) } else { Series::Linear(a.clone()) }
                }
                Quantity::Force(i) => Series::Linear(r.contacts[i].force.clone()),
                Quantity::Gap(i) => Series::Linear(r.contacts[i].gap.clone()),
                Quantity::Residual => Series::Constant(r.lcp.residual),
                Quantity::Pivots => Series::Constant(r.lcp.pivots as f64),
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
        let u = tau / sol.h;
        let j = (u.floor().max(0.0) as usize).min(sol.k - 1);
        let s = u - j as f64;
        let j1 = if j + 1 == sol.k { 0 } else { j + 1 };
        let maxp = self.powers.len();
        if maxp > 1 {
            // e^{ipωτ} by recurrence, restarted from sin/cos every 32 harmonics to bound round-off.
            let step = C::from_polar(1.0, sol.omega * tau);
            self.powers[0] = C::ONE;
            for p in 1..maxp {
                self.powers[p] = if p % 32 == 0 { C::from_polar(1.0, p as f64 * sol.omega * tau) } else { self.powers[p - 1] * step };
            }
        }
        for (i, series) in sol.series.iter().enumerate() {
            let (v, d) = series.eval(j, j1, s, sol.h, sol.omega, &self.powers);
            self.out[i] = v;
            self.der[i] = d;
        }
    }

    /// In initialisation mode outputs are computed on demand for the current values.
    fn ensure_outputs(&mut self) -> Result<(), String> {
        if self.initialized {
            return Ok(());
        }
        let cfg = self.values.config();
        if self.solution.as_ref().is_none_or(|s| s.config != cfg) {
            let sol = self.solve(cfg)?;
            self.phase_offset = 0.0;
            self.solution = None;
            self.install(sol, self.start_time);
        }
        self.evaluate(self.start_time);
        Ok(())
    }

    /// documentation/index.html: variables, units, conventions.
    pub fn documentation_html(&self, scene_name: &str) -> String {
        let esc = |s: &str| quick_xml::escape::escape(s).into_owned();
        let mut rows = String::new();
        for (vr, v) in self.desc.variables.iter() {
            let (ty, start, unit) = match &v.kind {
                Kind::Real { start, unit, .. } => ("Real", start.map(crate::fmi2::xml::real), unit.clone()),
                Kind::Integer { start, .. } => ("Integer", start.map(|s| s.to_string()), None),
                Kind::Enumeration { start, .. } => ("Enumeration", start.map(|s| s.to_string()), None),
                Kind::Boolean { start } => ("Boolean", start.map(|s| s.to_string()), None),
                Kind::String { start } => ("String", start.clone(), None),
            };
            rows += &format!(
                "<tr><td><code>{}</code></td><td>{vr}</td><td>{}</td><td>{}</td><td>{ty}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                esc(&v.name),
                v.causality.name(),
                v.variability.name(),
                esc(&start.unwrap_or_default()),
                esc(&unit.unwrap_or_default()),
                esc(&v.description)
            );
        }
        let schemes: String = Scheme::ALL.iter().map(|s| format!("<li>{} = <code>{}</code>: {}</li>", scheme_code(*s), s, esc(scheme_doc(*s)))).collect();
        format!(
            r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>PeriodicContact FMU ({scene})</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}td,th{{border:1px solid #ccc;padding:2px 6px}}table{{border-collapse:collapse}}</style></head>
<body>
<h1>{desc_name} FMU</h1>
<p>{desc}</p>
<p>Scene: <code>{scene}</code> (shipped as <code>resources/{scene_file}</code>). FMI 2.0 co-simulation, generated by {tool}.</p>
<h2>What it computes</h2>
<p>The structure M x'' + C x' + K x = f(t) &minus; B<sup>T</sup>&lambda; under its unilateral contacts is solved for its
<em>steady-state periodic response</em> over one period T = 2&pi;/&omega;, discretised at k instants, as one linear
complementarity problem (Meingast, Legrand &amp; Pierre 2014). The FMU is <em>quasi-steady</em>: it solves once at
<code>fmi2ExitInitializationMode</code>; each <code>fmi2DoStep</code> then reads the periodic response at the new
communication time (no time integration, no transient). When a tunable parameter or an input has a new value,
the next <code>fmi2DoStep</code> re-solves first (warm-started from the previous contact set) and the step's
end value comes from the new periodic response. The phase &theta; of the excitation stays continuous across a
change of &omega;: the outputs are the response at &tau; = &theta;/&omega; (mod T), with d&theta;/dt = &omega;.
With a constant &omega;, &tau; = t: the outputs at t = j&middot;T/k are exactly the solver's samples.</p>
<h2>Sign conventions and units</h2>
<ul>
<li>Units are the scene's, as long as they are consistent (e.g. kg, N/m, m, s); <code>frequency</code> is in rad/s.</li>
<li>Contact i with direction s = &plusmn;1 on DOF d keeps s&middot;x[d] &le; gap(t). <code>contact[i].gap</code> = gap(t) &minus; s&middot;x[d] &ge; 0 is the clearance,
<code>contact[i].force</code> &ge; 0 is the compressive force (it pushes DOF d by &minus;s&middot;force; the paper's &lambda; = &minus;force).</li>
<li>gap(t) = gap + <code>gap_offset</code> + <code>motion_scale</code>&middot;&Sigma; motion terms; forces are <code>force_scale</code>&middot;amplitude&middot;cos(harmonic&middot;&omega;t + phase).</li>
<li>Inputs repeat the tunable parameters for hosts that drive them continuously: <code>frequency_in</code> &gt; 0 replaces
<code>frequency</code> (0, its start value, means not driven); <code>force_scale_in</code> and <code>motion_scale_in</code> multiply their
parameters; <code>gap_offset_in</code> adds to <code>gap_offset</code>. Inputs and parameters set after initialisation take effect at the next step.</li>
<li>Only the effects the scene calls for have variables: no contact outputs or <code>gap_offset</code> without contacts,
no <code>force_scale</code> without forces, no <code>motion_scale</code> for static obstacles. <code>lcp.pivots</code> and
<code>lcp.residual</code> are always there, like the result's <code>lcp</code> (0 without contact).</li>
</ul>
<h2>Between the instants</h2>
<ul>
<li><code>fourier</code>: the trigonometric interpolant of the samples (displacement, velocity and acceleration are its derivatives).</li>
<li>Other schemes: displacement by cubic Hermite through the samples with the scheme's own velocities; <code>velocity</code> is its derivative
(equal to the scheme's velocity at the instants); acceleration piecewise linear.</li>
<li>Contact force and gap: piecewise linear (force &ge; 0 and rigid gap &ge; 0 hold between the instants too).</li>
<li><code>fmi2GetRealOutputDerivatives</code>, order 1: the exact time derivative of each output's interpolant (velocity for a displacement).</li>
</ul>
<h2>Time schemes (<code>scheme</code>)</h2><ul>{schemes}</ul>
<h2>Failures</h2>
<p>A solve that fails at initialisation returns <code>fmi2Error</code>; a re-solve that fails during the simulation returns <code>fmi2Discard</code>
(the step is not taken; <code>fmi2GetBooleanStatus(fmi2Terminated)</code> is true and <code>fmi2GetRealStatus(fmi2LastSuccessfulTime)</code> gives the time reached).
The reason is always logged; outputs are never NaN. Warnings about a scheme/pairing that does not converge for rigid contact are logged and
<code>fmi2ExitInitializationMode</code> returns <code>fmi2Warning</code>.</p>
<h2>Variables</h2>
<table><tr><th>name</th><th>vr</th><th>causality</th><th>variability</th><th>type</th><th>start</th><th>unit</th><th>description</th></tr>
{rows}</table>
</body></html>
"#,
            scene = esc(scene_name),
            desc_name = esc(&self.desc.model_name),
            desc = esc(&self.desc.description),
            scene_file = SCENE_FILE,
            tool = esc(&self.desc.generation_tool),
        )
    }
}

fn scheme_doc(s: Scheme) -> &'static str {
    match s {
        Scheme::Bds1 => "first-order backward differences",
        Scheme::Bds2 => "second-order backward differences",
        Scheme::Cds => "central differences",
        Scheme::Galerkin => "Bubnov-Galerkin in time with periodic linear hats",
        Scheme::Fourier => "Fourier time collocation",
    }
}

impl Fmi2Model for ContactModel {
    type Snapshot = ContactSnapshot;

    fn instantiate(resources: Option<&Path>) -> Result<Self, String> {
        let dir = resources.ok_or("no resource location was given; this FMU needs its resources/scene.toml")?;
        let path = dir.join(SCENE_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: cannot read the scene: {e}", path.display()))?;
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

    fn set_real(&mut self, vr: u32, v: f64) -> Result<(), String> {
        let role = self.role(vr)?;
        let name = &self.desc.variables.get(vr).expect("role exists").name;
        if !v.is_finite() {
            return Err(format!("{name} = {v}: must be finite"));
        }
        let (p, i) = (&mut self.values.params, &mut self.values.inputs);
        match role {
            Role::Frequency if v > 0.0 => p.frequency = v,
            Role::Frequency => return Err(format!("frequency = {v}: must be > 0 (rad/s)")),
            Role::FrequencyIn if v >= 0.0 => i.frequency = v,
            Role::FrequencyIn => return Err(format!("frequency_in = {v}: must be >= 0 (0 = not driven)")),
            Role::ForceScale => p.force_scale = v,
            Role::GapOffset => p.gap_offset = v,
            Role::MotionScale => p.motion_scale = v,
            Role::ForceScaleIn => i.force_scale = v,
            Role::GapOffsetIn => i.gap_offset = v,
            Role::MotionScaleIn => i.motion_scale = v,
            _ => return Err(format!("{name} cannot be set")),
        }
        Ok(())
    }

    fn set_integer(&mut self, vr: u32, v: i32) -> Result<(), String> {
        match self.role(vr)? {
            Role::Steps if (MIN_STEPS as i64..=MAX_STEPS as i64).contains(&(v as i64)) => self.values.steps = v as usize,
            Role::Steps => return Err(format!("steps = {v}: must be in {MIN_STEPS}..={MAX_STEPS}")),
            Role::Scheme if (1..=Scheme::ALL.len() as i32).contains(&v) => self.values.scheme = Scheme::ALL[(v - 1) as usize],
            Role::Scheme => return Err(format!("scheme = {v}: must be 1..=5 (bds1, bds2, cds, galerkin, fourier)")),
            _ => return Err(format!("value reference {vr} cannot be set as Integer")),
        }
        Ok(())
    }

    fn get_real(&mut self, vr: u32) -> Result<f64, String> {
        let (p, i) = (&self.values.params, &self.values.inputs);
        Ok(match self.role(vr)? {
            Role::Frequency => p.frequency,
            Role::ForceScale => p.force_scale,
            Role::GapOffset => p.gap_offset,
            Role::MotionScale => p.motion_scale,
            Role::FrequencyIn => i.frequency,
            Role::ForceScaleIn => i.force_scale,
            Role::GapOffsetIn => i.gap_offset,
            Role::MotionScaleIn => i.motion_scale,
            Role::Output(slot) => {
                self.ensure_outputs()?;
                self.out[slot]
            }
            Role::Steps | Role::Scheme => return Err(format!("value reference {vr} is not Real")),
        })
    }

    fn get_integer(&mut self, vr: u32) -> Result<i32, String> {
        Ok(match self.role(vr)? {
            Role::Steps => self.values.steps as i32,
            Role::Scheme => scheme_code(self.values.scheme),
            Role::Output(slot) => {
                self.ensure_outputs()?;
                self.out[slot] as i32
            }
            _ => return Err(format!("value reference {vr} is not Integer")),
        })
    }

    fn exit_initialization(&mut self, start_time: f64, log: &Logger) -> Result<Vec<String>, String> {
        self.start_time = start_time;
        self.ensure_outputs()?;
        self.initialized = true;
        let sol = self.solution.as_deref().expect("solved by ensure_outputs");
        log.event(&format!("solved: {} instants, {} pivots, residual {:.3e}", sol.k, sol.pivots, sol.residual));
        Ok(sol.warnings.clone())
    }

    fn do_step(&mut self, t: f64, h: f64, log: &Logger) -> Result<(), String> {
        let cfg = self.values.config();
        if self.solution.as_ref().is_none_or(|s| s.config != cfg) {
            let sol = self.solve(cfg)?;
            log.event(&format!("re-solved at t = {t} for {:?}: {} pivots, residual {:.3e}", cfg.tuning, sol.pivots, sol.residual));
            self.install(sol, t);
        }
        self.evaluate(t + h);
        Ok(())
    }

    fn output_derivative(&self, vr: u32, order: i32) -> Result<f64, String> {
        match (self.role(vr)?, order) {
            (Role::Output(slot), 1) => Ok(self.der[slot]),
            _ => Err(format!("no derivative of order {order} for value reference {vr}")),
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

    fn serialize(s: &ContactSnapshot, w: &mut ByteWriter) {
        let values = |w: &mut ByteWriter, t: &Tuning| [t.frequency, t.force_scale, t.gap_offset, t.motion_scale].iter().for_each(|v| w.f64(*v));
        values(w, &s.values.params);
        values(w, &s.values.inputs);
        w.u64(s.values.steps as u64);
        w.i32(scheme_code(s.values.scheme));
        w.f64(s.phase_offset);
        w.bool(s.initialized);
        w.f64(s.start_time);
        w.f64s(&s.out);
        w.f64s(&s.der);
        w.bool(s.solution.is_some());
        if let Some(sol) = &s.solution {
            values(w, &sol.config.tuning);
            w.u64(sol.config.steps as u64);
            w.i32(scheme_code(sol.config.scheme));
            for v in [sol.period, sol.h, sol.omega, sol.residual] {
                w.f64(v);
            }
            w.u64(sol.k as u64);
            w.i32(sol.pivots);
            w.usizes(&sol.active_set);
            w.u64(sol.warnings.len() as u64);
            sol.warnings.iter().for_each(|x| w.str(x));
            w.u64(sol.series.len() as u64);
            for series in &sol.series {
                match series {
                    Series::Hermite { x, v, level } => {
                        w.u64(0);
                        w.f64s(x);
                        w.f64s(v);
                        w.u64(*level as u64);
                    }
                    Series::Linear(y) => {
                        w.u64(1);
                        w.f64s(y);
                    }
                    Series::Trig { p, c } => {
                        w.u64(2);
                        w.usizes(p);
                        w.f64s(&c.iter().flat_map(|z| [z.re, z.im]).collect::<Vec<_>>());
                    }
                    Series::Constant(v) => {
                        w.u64(3);
                        w.f64(*v);
                    }
                }
            }
        }
    }

    fn deserialize(&self, r: &mut ByteReader<'_>) -> Result<ContactSnapshot, String> {
        let tuning = |r: &mut ByteReader<'_>| -> Result<Tuning, String> {
            Ok(Tuning { frequency: r.f64()?, force_scale: r.f64()?, gap_offset: r.f64()?, motion_scale: r.f64()? })
        };
        let scheme = |r: &mut ByteReader<'_>| -> Result<Scheme, String> {
            let c = r.i32()?;
            Scheme::ALL.get((c - 1) as usize).copied().ok_or(format!("bad scheme code {c}"))
        };
        let params = tuning(r)?;
        let inputs = tuning(r)?;
        let values = Values { params, inputs, steps: r.u64()? as usize, scheme: scheme(r)? };
        let phase_offset = r.f64()?;
        let initialized = r.bool()?;
        let start_time = r.f64()?;
        let out = r.f64s()?;
        let der = r.f64s()?;
        let n = self.outputs.len();
        if out.len() != n || der.len() != n {
            return Err(format!("the state has {} outputs, this model {n}", out.len()));
        }
        let solution = if r.bool()? {
            let config = Config { tuning: tuning(r)?, steps: r.u64()? as usize, scheme: scheme(r)? };
            let (period, h, omega, residual) = (r.f64()?, r.f64()?, r.f64()?, r.f64()?);
            let k = r.u64()? as usize;
            let pivots = r.i32()?;
            let active_set = r.usizes()?;
            let nw = r.u64()?;
            let warnings = (0..nw.min(1 << 16)).map(|_| r.str()).collect::<Result<Vec<_>, _>>()?;
            let ns = r.u64()? as usize;
            if ns != n || k == 0 {
                return Err(format!("the state has {ns} series over {k} instants, this model {n} outputs"));
            }
            let mut series = Vec::with_capacity(n);
            for _ in 0..ns {
                let s = match r.u64()? {
                    0 => Series::Hermite { x: r.f64s()?, v: r.f64s()?, level: r.u64()? as u8 },
                    1 => Series::Linear(r.f64s()?),
                    2 => {
                        let p = r.usizes()?;
                        let c: Vec<C> = r.f64s()?.chunks(2).map(|z| C::new(z[0], z[1])).collect();
                        if c.len() != p.len() || p.iter().any(|&p| p > k) {
                            return Err("bad trigonometric series".into());
                        }
                        Series::Trig { p, c }
                    }
                    3 => Series::Constant(r.f64()?),
                    t => return Err(format!("bad series tag {t}")),
                };
                let ok = match &s {
                    Series::Hermite { x, v, .. } => x.len() == k && v.len() == k,
                    Series::Linear(y) => y.len() == k,
                    _ => true,
                };
                if !ok {
                    return Err(format!("a series does not have {k} samples"));
                }
                series.push(s);
            }
            Some(Arc::new(Solution { config, period, h, omega, k, series, pivots, residual, active_set, warnings }))
        } else {
            None
        };
        Ok(ContactSnapshot { values, solution, phase_offset, initialized, start_time, out, der })
    }
}

/// Writes `out` (.fmu) for `scene_path`, with the FMU binary `binary`. Returns the GUID.
pub fn package(scene_path: &Path, binary: &Path, out: &Path) -> Result<String, String> {
    let text = std::fs::read_to_string(scene_path).map_err(|e| format!("{}: cannot read the scene: {e}", scene_path.display()))?;
    let model = ContactModel::from_scene_text(&text, &scene_path.display().to_string())?;
    model.desc.variables.check().map_err(|m| format!("internal error, the variable table is invalid: {m}"))?;
    let (xml, guid) = crate::fmi2::xml::render(&model.desc);
    let so = std::fs::read(binary).map_err(|e| format!("{}: cannot read the FMU binary: {e}", binary.display()))?;
    if !so.starts_with(b"\x7fELF") {
        return Err(format!("{}: is not an ELF shared library", binary.display()));
    }
    let platform = crate::fmi2::package::platform().ok_or("this platform has no FMI 2.0 platform folder name")?;
    let name = scene_path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let entries = vec![
        crate::fmi2::package::Entry { name: format!("binaries/{platform}/{MODEL_IDENTIFIER}.so"), data: so, mode: 0o755 },
        crate::fmi2::package::Entry { name: format!("resources/{SCENE_FILE}"), data: text.into_bytes(), mode: 0o644 },
        crate::fmi2::package::Entry { name: "documentation/index.html".into(), data: model.documentation_html(&name).into_bytes(), mode: 0o644 },
    ];
    crate::fmi2::package::write_fmu(out, &xml, &entries)?;
    Ok(guid)
}
