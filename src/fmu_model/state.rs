//! The adapter's part of a serialized FMU state (after the shell's header, GUID and clock):
//! every count and code is checked against this model (outputs, instants, harmonics, contacts),
//! so that a state of another scene or a corrupted one is refused, never truncated.
use super::series::{Series, Solution};
use super::{Config, ContactModel, Values, scheme_code};
use crate::analysis::polish::{Event, EventKind, OrbitParts, PolishedOrbit};
use crate::error::{Error, Result};
use crate::fmi::state::{StateReader, StateWriter};
use crate::periodic::{MAX_STEPS, MIN_STEPS, Tuning};
use crate::time::{Discretization, Scheme};
use num_complex::Complex64 as C;
use std::sync::Arc;

/// Raise when [`write`] changes (older states are then refused by name).
pub const STATE_VERSION: u16 = 3;

/// What `fmi2GetFMUstate` keeps of a [`ContactModel`].
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSnapshot {
    pub(super) values: Values,
    pub(super) solution: Option<Arc<Solution>>,
    pub(super) phase_offset: f64,
    pub(super) initialized: bool,
    pub(super) start_time: f64,
    pub(super) out: Vec<f64>,
    pub(super) der: Vec<f64>,
}

fn bad(message: impl std::fmt::Display) -> Error {
    Error::input(format!("serialized FMU state: {message}"))
}

fn write_tuning(w: &mut StateWriter, t: &Tuning) {
    [t.frequency, t.force_scale, t.gap_offset, t.motion_scale, t.normal_force_scale].iter().for_each(|v| w.f64(*v));
}

fn read_tuning(r: &mut StateReader<'_>) -> Result<Tuning> {
    Ok(Tuning { frequency: r.f64()?, force_scale: r.f64()?, gap_offset: r.f64()?, motion_scale: r.f64()?, normal_force_scale: r.f64()? })
}

fn write_config(w: &mut StateWriter, steps: usize, scheme: Scheme, polish: bool) {
    w.usize(steps);
    w.i32(scheme_code(scheme));
    w.bool(polish);
}

/// `steps` within the solver's bounds, a known scheme code, the polish switch.
fn read_config(r: &mut StateReader<'_>) -> Result<(usize, Scheme, bool)> {
    let steps = r.usize()?;
    if !(MIN_STEPS..=MAX_STEPS).contains(&steps) {
        return Err(bad(format!("steps = {steps} is outside {MIN_STEPS}..={MAX_STEPS}")));
    }
    let code = r.i32()?;
    let scheme = usize::try_from(code).ok().and_then(|c| c.checked_sub(1)).and_then(|i| Scheme::ALL.get(i)).copied();
    let scheme = scheme.ok_or_else(|| bad(format!("{code} is not a scheme code")))?;
    Ok((steps, scheme, r.bool()?))
}

/// The snapshot after the shell's fields.
pub fn write(s: &ContactSnapshot, w: &mut StateWriter) {
    write_tuning(w, &s.values.params);
    write_tuning(w, &s.values.inputs);
    write_config(w, s.values.steps, s.values.scheme, s.values.polish);
    w.f64(s.phase_offset);
    w.bool(s.initialized);
    w.f64(s.start_time);
    w.f64s(&s.out);
    w.f64s(&s.der);
    w.bool(s.solution.is_some());
    if let Some(sol) = &s.solution {
        write_solution(w, sol);
    }
}

fn write_solution(w: &mut StateWriter, sol: &Solution) {
    write_tuning(w, &sol.config.tuning);
    write_config(w, sol.config.steps, sol.config.scheme, sol.config.polish);
    for v in [sol.period, sol.h, sol.omega, sol.residual, sol.amplitude] {
        w.f64(v);
    }
    w.usize(sol.jumps as usize);
    w.usize(sol.k);
    w.i32(sol.pivots);
    w.usizes(&sol.active_set);
    w.count(sol.warnings.len());
    sol.warnings.iter().for_each(|x| w.str(x));
    w.count(sol.series.len());
    sol.series.iter().for_each(|s| write_series(w, s));
    w.bool(sol.polished.is_some());
    if let Some(orbit) = &sol.polished {
        let parts = orbit.parts();
        w.count(parts.events.len());
        for e in &parts.events {
            w.usize(e.contact);
            w.u8(event_code(e.kind));
            w.f64(e.seed);
        }
        w.usizes(&parts.always);
        w.f64s(&parts.y0);
    }
}

fn event_code(kind: EventKind) -> u8 {
    match kind {
        EventKind::Impact { stick: false } => 0,
        EventKind::Impact { stick: true } => 1,
        EventKind::Release => 2,
        EventKind::On => 3,
        EventKind::Off => 4,
    }
}

/// The polished orbit of a solution of `config`, rebuilt on its model.
fn read_orbit(model: &ContactModel, config: &Config, r: &mut StateReader<'_>) -> Result<PolishedOrbit> {
    let ne = r.count(17)?;
    let mut events = Vec::with_capacity(ne);
    for _ in 0..ne {
        let contact = r.usize()?;
        let kind = match r.u8()? {
            0 => EventKind::Impact { stick: false },
            1 => EventKind::Impact { stick: true },
            2 => EventKind::Release,
            3 => EventKind::On,
            4 => EventKind::Off,
            t => return Err(bad(format!("{t} is not an event kind"))),
        };
        events.push(Event { contact, kind, seed: r.f64()? });
    }
    let parts = OrbitParts { events, always: r.usizes()?, y0: r.f64s()? };
    let disc = Discretization { scheme: config.scheme, steps: config.steps, pairing: model.base.discretization().pairing };
    let problem = config.tuning.apply(&model.base, disc)?;
    PolishedOrbit::rebuild(problem.model(), &parts).map_err(|e| bad(e.0))
}

fn write_series(w: &mut StateWriter, series: &Series) {
    match series {
        Series::Hermite { x, v, level } => {
            w.u8(0);
            w.f64s(x);
            w.f64s(v);
            w.u8(*level);
        }
        Series::Linear(y) => {
            w.u8(1);
            w.f64s(y);
        }
        Series::Trig { p, c } => {
            w.u8(2);
            w.usizes(p);
            w.count(c.len());
            c.iter().for_each(|z| [z.re, z.im].iter().for_each(|v| w.f64(*v)));
        }
        Series::Constant(v) => {
            w.u8(3);
            w.f64(*v);
        }
    }
}

impl ContactModel {
    /// Reads what [`write`] wrote, checked against this model.
    pub(super) fn read_snapshot(&self, r: &mut StateReader<'_>) -> Result<ContactSnapshot> {
        let (params, inputs) = (read_tuning(r)?, read_tuning(r)?);
        let (steps, scheme, polish) = read_config(r)?;
        let values = Values { params, inputs, steps, scheme, polish };
        let (phase_offset, initialized, start_time) = (r.f64()?, r.bool()?, r.f64()?);
        let (out, der) = (r.f64s()?, r.f64s()?);
        let n = self.outputs.len();
        if out.len() != n || der.len() != n {
            return Err(bad(format!("the state has {} outputs, this model {n}", out.len())));
        }
        let solution = if r.bool()? { Some(Arc::new(self.read_solution(r)?)) } else { None };
        Ok(ContactSnapshot { values, solution, phase_offset, initialized, start_time, out, der })
    }

    fn read_solution(&self, r: &mut StateReader<'_>) -> Result<Solution> {
        let tuning = read_tuning(r)?;
        let (steps, scheme, polish) = read_config(r)?;
        let config = Config { tuning, steps, scheme, polish };
        let (period, h, omega, residual, amplitude) = (r.f64()?, r.f64()?, r.f64()?, r.f64()?, r.f64()?);
        let jumps = u32::try_from(r.usize()?).map_err(|_| bad("the jump count is past u32"))?;
        if !(period.is_finite() && period > 0.0 && h.is_finite() && h > 0.0 && omega.is_finite()) {
            return Err(bad(format!("period {period}, step {h} and frequency {omega} must be finite and > 0")));
        }
        let k = r.usize()?;
        if k != steps {
            return Err(bad(format!("the solution has {k} instants, its configuration {steps}")));
        }
        let pivots = r.i32()?;
        let active_set = r.usizes()?;
        let lcp_size = self.base.model().contacts.len().saturating_mul(k);
        if let Some(bad_index) = active_set.iter().find(|&&i| i >= lcp_size) {
            return Err(bad(format!("active-set index {bad_index} is outside the LCP of size {lcp_size}")));
        }
        let nw = r.count(8)?;
        let warnings = (0..nw).map(|_| r.str()).collect::<Result<Vec<_>>>()?;
        let ns = r.count(1)?;
        if ns != self.outputs.len() {
            return Err(bad(format!("the state has {ns} series, this model {} outputs", self.outputs.len())));
        }
        let series = (0..ns).map(|_| read_series(r, k)).collect::<Result<Vec<_>>>()?;
        let polished = if r.bool()? { Some(Arc::new(read_orbit(self, &config, r)?)) } else { None };
        Ok(Solution { config, period, h, omega, k, series, pivots, residual, active_set, warnings, amplitude, jumps, polished })
    }
}

/// One series over `k` instants.
fn read_series(r: &mut StateReader<'_>, k: usize) -> Result<Series> {
    let samples = |r: &mut StateReader<'_>| -> Result<Vec<f64>> {
        let y = r.f64s()?;
        if y.len() == k { Ok(y) } else { Err(bad(format!("a series has {} samples, not {k}", y.len()))) }
    };
    match r.u8()? {
        0 => {
            let (x, v) = (samples(r)?, samples(r)?);
            let level = r.u8()?;
            if level > 1 {
                return Err(bad(format!("Hermite level {level} is not 0 or 1")));
            }
            Ok(Series::Hermite { x, v, level })
        }
        1 => Ok(Series::Linear(samples(r)?)),
        2 => {
            let p = r.usizes()?;
            let nc = r.count(16)?;
            if nc != p.len() || p.iter().any(|&p| p > k) {
                return Err(bad(format!("a trigonometric series has {} harmonics and {nc} coefficients (at most harmonic {k})", p.len())));
            }
            let c = (0..nc).map(|_| Ok(C::new(r.f64()?, r.f64()?))).collect::<Result<Vec<_>>>()?;
            Ok(Series::Trig { p, c })
        }
        3 => Ok(Series::Constant(r.f64()?)),
        t => Err(bad(format!("{t} is not a series tag"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi::{CoSimModel, EventLog};

    struct Quiet;
    impl EventLog for Quiet {
        fn events_enabled(&self) -> bool {
            false
        }
        fn event(&self, _: &str) {}
    }

    fn solved(scheme: &str) -> ContactModel {
        let scene = format!(
            "[structure]\nmass = [[2.0, 0.3], [0.3, 1.0]]\nstiffness = [[5.0, -2.0], [-2.0, 3.0]]\n[damping]\nrayleigh = [0.01, 0.02]\n\
             [excitation]\nfrequency = 1.7\n[[force]]\ndof = 1\namplitude = 0.8\n[discretization]\nscheme = \"{scheme}\"\nsteps = 16\n\
             [output]\ndisplacement = [0, 1]\nvelocity = [0]\nacceleration = [1]\n"
        );
        let mut m = ContactModel::from_scene_text(&scene, "test.toml").unwrap();
        m.exit_initialization(0.0, &Quiet).unwrap();
        m.do_step(0.0, 0.1, &Quiet).unwrap();
        m
    }

    fn bytes(m: &ContactModel) -> (ContactSnapshot, Vec<u8>) {
        let s = m.snapshot();
        let mut w = StateWriter::new(STATE_VERSION);
        write(&s, &mut w);
        (s, w.into_bytes())
    }

    fn read(m: &ContactModel, b: &[u8]) -> Result<ContactSnapshot> {
        let mut r = StateReader::new(b, STATE_VERSION)?;
        let s = m.read_snapshot(&mut r)?;
        r.finish()?;
        Ok(s)
    }

    #[test]
    fn a_round_trip_is_exact_for_hermite_and_trigonometric_series() {
        for scheme in ["cds", "fourier"] {
            let m = solved(scheme);
            let (s, b) = bytes(&m);
            assert_eq!(read(&m, &b).unwrap(), s, "{scheme}");
        }
    }

    #[test]
    fn truncated_corrupted_and_foreign_states_are_refused() {
        let m = solved("fourier");
        let (_, b) = bytes(&m);
        for cut in 0..b.len() {
            assert!(read(&m, &b[..cut]).is_err(), "a state cut at {cut} of {} bytes was accepted", b.len());
        }
        // The scheme code (after the magic, the versions, two tunings of 5 numbers and steps) set to 9.
        let mut bad = b.clone();
        let at = crate::fmi::state::HEADER_LEN + 2 * 5 * 8 + 8;
        bad[at..at + 4].copy_from_slice(&9i32.to_le_bytes());
        assert!(read(&m, &bad).unwrap_err().message().contains("9 is not a scheme code"));
        // A state of another model version.
        assert!(StateReader::new(&b, STATE_VERSION + 1).err().unwrap().message().contains("model part has version"));
        // A state of a scene with other outputs.
        let other = ContactModel::from_scene_text("[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n[excitation]\nfrequency = 0.5\n", "o.toml").unwrap();
        assert!(read(&other, &b).unwrap_err().message().contains("outputs"));
    }
}
