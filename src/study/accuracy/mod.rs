//! `study accuracy`: what accuracy costs. For every case (src/formulation.md §6's exact references, a pure-impact
//! rigid stop, a 2-DOF compliant chain against long time integration) and every scheme and
//! pairing, k = 32 … 8192: the periodic LCP's error against its wall time, its error estimate
//! (`analysis::accuracy`, Richardson from k/2) beside the true error, the same result after the
//! event-fitted polish (`analysis::polish`, time = solve + polish), the explicit time-marching
//! reference (src/formulation.md §5) and Siconos' Lemke on the same LCPs ([`super::peers`]), all on the same
//! axes; then the estimates' honesty on random members of the exact families
//! ([`super::honesty`]). Writes `accuracy.csv`, `estimate.csv`, `accuracy.md`, `accuracy.png`.
//!
//! Cost caps (so that the whole run stays within about 2 minutes on 2 cores): the runs go
//! level by level (all cases and methods at k = 32, then at 64, …), so that the overall budget
//! cuts the largest sizes first; a method stops growing k once its next run is predicted (from
//! the growth of its last two runs) to take longer than `solve_cap_s`, and, for the choices that
//! do not converge, k stops at `nonconverging_max_k` (their error has plateaued long before).
//! Skipped points are listed in the CSV with their reason.
mod figure;
mod report;

use super::honesty::{self, HonestySettings, HonestyStudy};
use super::peers::{self, PeerSettings};
use super::{Case, Reference, method_label};
use crate::Error;
use crate::analysis::{accuracy, polish};
use crate::lcp::{LcpMatrix, write_dat};
use crate::marching::{MarchSettings, march};
use crate::periodic::{LcpMethod, PeriodFft};
use crate::response::Response;
use crate::time::{Pairing, Scheme};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

/// Settings of the study; see [`AccuracySettings::full`] and [`AccuracySettings::quick`].
#[derive(Clone, Debug)]
pub struct AccuracySettings {
    /// k of the periodic LCP.
    pub steps: Vec<usize>,
    /// Steps per period of the marcher.
    pub march_steps: Vec<usize>,
    pub cases: Vec<Case>,
    /// Only these "scheme/pairing" (or "scheme") labels; all when empty.
    pub methods: Vec<String>,
    /// Run the time-marching reference.
    pub march: bool,
    /// Periodicity tolerance of the marcher (defect relative to the peak-to-peak amplitude).
    pub march_tolerance: f64,
    /// Polish every result of a converging choice (a second point, time = solve + polish).
    pub polish: bool,
    /// Siconos' Lemke on the same LCPs; `None`: no peers.
    pub peers: Option<PeerSettings>,
    /// The estimates' honesty on random family members; `None`: not measured.
    pub honesty: Option<HonestySettings>,
    /// A method stops growing k (the marcher N) once its next run is predicted to take longer
    /// than this [s] (from the growth of its last two runs).
    pub solve_cap_s: f64,
    /// k cap of the (scheme, pairing) choices that do not converge.
    pub nonconverging_max_k: usize,
    /// Budget of the sweep over k [s]: past it the remaining (larger) runs are skipped.
    pub budget_s: f64,
    /// Timing: repeat a run until this much time was spent (at most 5 times); keep the fastest.
    pub min_timing_s: f64,
    /// Export every LCP solved (up to `export_max` unknowns) to this folder as Siconos `.dat`.
    pub export_lcp: Option<PathBuf>,
    pub export_max: usize,
}

impl AccuracySettings {
    /// The documented full study: k = 32 … 8192, marcher N = 32 … 8192, Siconos at k = 256,
    /// 512, 1024, the estimates on 16 random members of each family at k = 256, 512, 1024.
    pub fn full() -> Self {
        let pow2 = |lo: u32, hi: u32| (lo..=hi).map(|e| 1usize << e).collect::<Vec<_>>();
        AccuracySettings {
            steps: pow2(5, 13),
            march_steps: pow2(5, 13),
            cases: Case::ALL.to_vec(),
            methods: vec![],
            march: true,
            march_tolerance: 1e-10,
            polish: true,
            peers: Some(PeerSettings::default()),
            honesty: Some(HonestySettings::full()),
            solve_cap_s: 2.0,
            nonconverging_max_k: 256,
            budget_s: 120.0,
            min_timing_s: 0.05,
            export_lcp: None,
            export_max: 4096,
        }
    }
    /// For tests: k = 32 … 256, no peers, 2 members per family; a few seconds.
    pub fn quick() -> Self {
        AccuracySettings {
            steps: vec![32, 64, 128, 256],
            march_steps: vec![32, 64, 128, 256],
            peers: None,
            honesty: Some(HonestySettings::quick()),
            budget_s: 60.0,
            min_timing_s: 0.0,
            ..Self::full()
        }
    }
}

/// What a row measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    /// The periodic LCP at k instants.
    Periodic,
    /// The same result after the event-fitted polish.
    Polished,
    /// Explicit time marching to the steady state.
    Marching,
    /// Siconos' Lemke on the same LCP.
    Siconos,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Periodic => "periodic",
            Kind::Polished => "polished",
            Kind::Marching => "marching",
            Kind::Siconos => "siconos",
        }
    }
}

/// One measured (or skipped) point.
#[derive(Clone, Debug)]
pub struct Row {
    pub case: Case,
    /// "cds/forward", "cds" (no contact), or "march cds" for the time-marching reference.
    pub method: String,
    pub kind: Kind,
    /// k (periodic) or steps per period (marching).
    pub steps: usize,
    /// Converges to the exact orbit according to src/formulation.md §3 (marching: the plastic-impact orbit).
    pub converges: bool,
    /// "ok", "failed: …" or "skipped: …".
    pub status: String,
    /// max |x_j − x(t_j)| / peak-to-peak.
    pub error_x: Option<f64>,
    pub error_impulse: Option<f64>,
    /// The result's own error estimate, in the unit of `error_x`.
    pub estimate: Option<f64>,
    /// Wall time of the estimate (the second solve at k/2) [s].
    pub t_estimate: Option<f64>,
    pub t_assembly: Option<f64>,
    pub t_lcp: Option<f64>,
    pub t_recovery: Option<f64>,
    /// Wall time of the polish [s] (polished rows).
    pub t_polish: Option<f64>,
    /// Total wall time of one thread (periodic: assembly + LCP + recovery; polished: + polish;
    /// marching: to the steady state; Siconos: its Lemke + our assembly and recovery).
    pub t_total: Option<f64>,
    pub lcp_size: usize,
    pub pivots: Option<usize>,
    pub residual: Option<f64>,
    /// Marching: periods to the steady state.
    pub periods: Option<usize>,
    /// Time spent by a run that failed (for the cost cap).
    pub t_failed: Option<f64>,
}

impl Row {
    pub(crate) fn new(case: Case, method: String, kind: Kind, steps: usize, converges: bool) -> Self {
        Row {
            case,
            method,
            kind,
            steps,
            converges,
            status: String::new(),
            error_x: None,
            error_impulse: None,
            estimate: None,
            t_estimate: None,
            t_assembly: None,
            t_lcp: None,
            t_recovery: None,
            t_polish: None,
            t_total: None,
            lcp_size: 0,
            pivots: None,
            residual: None,
            periods: None,
            t_failed: None,
        }
    }
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }
    /// What one picks to buy an accuracy: "cds/forward + polish", "march cds", …
    pub fn choice(&self) -> String {
        match self.kind {
            Kind::Periodic | Kind::Marching => self.method.clone(),
            Kind::Polished => format!("{} + polish", self.method),
            Kind::Siconos => format!("Siconos Lemke ({})", self.method),
        }
    }
    /// estimate / true error, where both are known and the error is above round-off.
    pub fn estimate_ratio(&self, floor: f64) -> Option<f64> {
        match (self.estimate, self.error_x) {
            (Some(e), Some(t)) if t > floor => Some(e / t),
            _ => None,
        }
    }
}

/// What the study produced.
pub struct AccuracyStudy {
    pub rows: Vec<Row>,
    pub settings: AccuracySettings,
    /// Wall time of the whole run [s].
    pub elapsed_s: f64,
    /// Wall time of the exact references (the chain's marches) [s].
    pub reference_s: f64,
    /// The references' own uncertainty relative to peak-to-peak, per case.
    pub uncertainty: BTreeMap<&'static str, f64>,
    /// Why the peers are missing, if they are.
    pub peers_note: Option<String>,
    pub honesty: Option<HonestyStudy>,
    /// LCP files written.
    pub exported: Vec<PathBuf>,
    /// /proc/loadavg (1 min) at the start and the end.
    pub load: (String, String),
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg").ok().and_then(|s| s.split_whitespace().next().map(str::to_string)).unwrap_or_else(|| "unknown".into())
}

struct Track {
    stopped: Option<String>,
    /// Wall time of the last run that completed.
    last: Option<f64>,
}

impl Track {
    /// After a run of `t` seconds at size `n`: stop when the next size (twice as large) is
    /// predicted to exceed the cap, extrapolating the growth of the last two runs (at least 2×,
    /// at most 16× per doubling).
    fn record(&mut self, n: usize, t: Option<f64>, cap: f64) {
        let Some(t) = t else { return };
        let growth = self.last.map_or(4.0, |p| (t / p.max(1e-9)).clamp(2.0, 16.0));
        if t * growth > cap {
            self.stopped = Some(format!("size {n} took {t:.2} s, the next is predicted at {:.0} s > {cap} s", t * growth));
        }
        self.last = Some(t);
    }
}

/// Runs the study. `progress` receives one line per point.
pub fn run(settings: &AccuracySettings, progress: &mut dyn FnMut(&Row)) -> Result<AccuracyStudy, Error> {
    let start = Instant::now();
    let load0 = load_average();
    let mut refs = BTreeMap::new();
    for &case in &settings.cases {
        refs.insert(case.name(), case.reference().map_err(|e| e.context(format!("{}: exact reference", case.name())))?);
    }
    let reference_s = start.elapsed().as_secs_f64();
    if let Some(dir) = &settings.export_lcp {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(format!("{}: cannot create the LCP export folder: {e}", dir.display())))?;
    }
    let wanted = |label: &str| settings.methods.is_empty() || settings.methods.iter().any(|m| m == label);
    let mut tracks: BTreeMap<(String, String), Track> = BTreeMap::new();
    let mut rows = Vec::new();
    let mut exported = Vec::new();
    let sweep_start = Instant::now();
    let over_budget = || sweep_start.elapsed().as_secs_f64() > settings.budget_s;
    let levels = settings.steps.len().max(if settings.march { settings.march_steps.len() } else { 0 });
    for level in 0..levels {
        for &case in &settings.cases {
            let reference = &refs[case.name()];
            if let Some(&k) = settings.steps.get(level) {
                for (scheme, pairing) in case.methods() {
                    let label = method_label(scheme, pairing);
                    if !wanted(&label) {
                        continue;
                    }
                    let converges = case.converges(scheme, pairing);
                    let mut row = Row::new(case, label.clone(), Kind::Periodic, k, converges);
                    let track = tracks.entry((case.name().to_string(), label.clone())).or_insert(Track { stopped: None, last: None });
                    let mut polished = None;
                    if let Some(why) = &track.stopped {
                        row.status = format!("skipped: {why}");
                    } else if !converges && k > settings.nonconverging_max_k {
                        row.status = format!("skipped: does not converge, k capped at {}", settings.nonconverging_max_k);
                    } else if over_budget() {
                        row.status = format!("skipped: the sweep's budget of {} s is spent", settings.budget_s);
                    } else {
                        let r = periodic_point(&mut row, case, scheme, pairing, k, reference, settings, &mut exported)?;
                        track.record(k, row.t_total.or(row.t_failed), settings.solve_cap_s);
                        if let Some((problem, r)) = r.filter(|_| settings.polish && converges && case.has_contact()) {
                            polished = Some(polish_point(&row, &problem, &r, reference, settings));
                        }
                    }
                    // The table keeps its shape: a method that would be polished gets its polished
                    // row even when its periodic row was skipped or failed (a loaded machine spends
                    // the budget sooner), saying why.
                    let polished = polished.or_else(|| {
                        (settings.polish && converges && case.has_contact()).then(|| {
                            let mut p = Row::new(case, label.clone(), Kind::Polished, k, converges);
                            p.status = format!("skipped: no periodic solution to polish ({})", row.status);
                            p
                        })
                    });
                    progress(&row);
                    rows.push(row);
                    if let Some(p) = polished {
                        progress(&p);
                        rows.push(p);
                    }
                }
            }
            if settings.march
                && let Some(&n) = settings.march_steps.get(level)
            {
                let label = "march cds".to_string();
                let mut row = Row::new(case, label.clone(), Kind::Marching, n, true);
                let track = tracks.entry((case.name().to_string(), label)).or_insert(Track { stopped: None, last: None });
                if let Some(why) = &track.stopped {
                    row.status = format!("skipped: {why}");
                } else if over_budget() {
                    row.status = format!("skipped: the sweep's budget of {} s is spent", settings.budget_s);
                } else {
                    march_point(&mut row, case, n, reference, settings);
                    track.record(n, row.t_total.or(row.t_failed), settings.solve_cap_s);
                }
                progress(&row);
                rows.push(row);
            }
        }
    }
    let mut peers_note = None;
    if let Some(ps) = &settings.peers {
        match peers::run(ps, &settings.cases, &rows, progress) {
            Ok(peer_rows) => rows.extend(peer_rows),
            Err(why) => peers_note = Some(why),
        }
    } else {
        peers_note = Some("not run (`--no-peers` or `--quick`)".into());
    }
    let honesty = settings.honesty.as_ref().map(|h| honesty::run(h, &mut |line| eprintln!("{line}")));
    let uncertainty = refs.iter().map(|(k, r)| (*k, r.uncertainty())).collect();
    Ok(AccuracyStudy {
        rows,
        settings: settings.clone(),
        elapsed_s: start.elapsed().as_secs_f64(),
        reference_s,
        uncertainty,
        peers_note,
        honesty,
        exported,
        load: (load0, load_average()),
    })
}

/// Repeats `f` until `min_s` was spent (at most 5 times) and keeps the fastest, as timed by
/// `time`; the first failure ends it.
pub(crate) fn fastest<T, E>(min_s: f64, mut f: impl FnMut() -> Result<T, E>, time: impl Fn(&T) -> f64) -> Result<T, E> {
    let mut best: Option<T> = None;
    let mut spent = 0.0;
    for _ in 0..5 {
        let r = f()?;
        spent += time(&r);
        if best.as_ref().is_none_or(|b| time(&r) < time(b)) {
            best = Some(r);
        }
        if spent >= min_s {
            break;
        }
    }
    Ok(best.expect("one run"))
}

/// Solves, measures and estimates one point; returns the problem and the fastest response for
/// the polish.
#[allow(clippy::too_many_arguments)] // one row of the study: its case, method, grid and the shared sinks
fn periodic_point(
    row: &mut Row,
    case: Case,
    scheme: Scheme,
    pairing: Option<Pairing>,
    k: usize,
    reference: &Reference,
    settings: &AccuracySettings,
    exported: &mut Vec<PathBuf>,
) -> Result<Option<(crate::periodic::PeriodicProblem, Response)>, Error> {
    let problem = match case.problem(scheme, pairing, k, LcpMethod::Auto) {
        Ok(p) => p,
        Err(e) => {
            row.status = format!("failed: {e}");
            return Ok(None);
        }
    };
    let fft = PeriodFft::new(k);
    row.lcp_size = if case.has_contact() { k * problem.model().contacts.len() } else { 0 };
    if let Some(dir) = &settings.export_lcp
        && case.has_contact()
        && row.lcp_size <= settings.export_max
    {
        let (a, q) = problem.assemble_lcp(&fft).map_err(Error::from)?;
        let p = dir.join(format!("{}-{}-k{k}.dat", case.name(), row.method.replace('/', "-")));
        write_dat(&p, &a as &dyn LcpMatrix, &q).map_err(|e| Error::io(format!("{}: {e}", p.display())))?;
        exported.push(p);
    }
    let t0 = Instant::now();
    let r = match fastest(settings.min_timing_s, || problem.solve_with(&fft, None), |r| r.timing_s.total) {
        Ok(r) => r,
        Err(e) => {
            row.status = format!("failed: {e}");
            row.t_failed = Some(t0.elapsed().as_secs_f64());
            return Ok(None);
        }
    };
    row.status = "ok".to_string();
    row.error_x = Some(reference.response_error(&r));
    row.error_impulse = if case.has_contact() { reference.impulse_error(r.impulse_per_period(0)) } else { None };
    row.t_assembly = Some(r.timing_s.assembly);
    row.t_lcp = Some(r.timing_s.lcp);
    row.t_recovery = Some(r.timing_s.recovery);
    row.t_total = Some(r.timing_s.total);
    if case.has_contact() {
        row.pivots = Some(r.lcp.pivots);
        row.residual = Some(r.lcp.residual);
    }
    let t0 = Instant::now();
    let a = accuracy::estimate(&problem, &r);
    row.t_estimate = Some(t0.elapsed().as_secs_f64());
    row.estimate = a.estimate.map(|e| e / reference.peak_to_peak());
    Ok(Some((problem, r)))
}

/// The polished point of a periodic row: time = the row's solve + the polish (fastest of the
/// repeats), error against the same reference, the polish's own estimate.
fn polish_point(base: &Row, problem: &crate::periodic::PeriodicProblem, r: &Response, reference: &Reference, settings: &AccuracySettings) -> Row {
    let mut row = Row::new(base.case, base.method.clone(), Kind::Polished, base.steps, base.converges);
    row.lcp_size = base.lcp_size;
    let run = || {
        let mut p = r.clone();
        let t0 = Instant::now();
        polish::apply(problem, &mut p);
        Ok::<_, ()>((p, t0.elapsed().as_secs_f64()))
    };
    let (p, t) = fastest(settings.min_timing_s, run, |(_, t)| *t).expect("the polish does not fail: it falls back");
    let s = p.polish.as_ref().expect("the polish ran");
    if s.status != "polished" {
        row.status = format!("failed: the polish fell back: {}", s.reason);
        return row;
    }
    row.status = "ok".into();
    row.error_x = Some(reference.response_error(&p));
    row.error_impulse = reference.impulse_error(p.impulse_per_period(0));
    row.estimate = p.accuracy.estimate.map(|e| e / reference.peak_to_peak());
    row.t_polish = Some(t);
    row.t_total = base.t_total.map(|b| b + t);
    row
}

fn march_point(row: &mut Row, case: Case, n: usize, reference: &Reference, settings: &AccuracySettings) {
    let model = case.model();
    let ms = MarchSettings { steps_per_period: n, max_periods: 20_000, min_periods: 3, tolerance: settings.march_tolerance, ..MarchSettings::default() };
    let t0 = Instant::now();
    let run = || match march(&model, &ms) {
        Ok(r) if r.converged => Ok(r),
        Ok(r) => Err((format!("no steady state within {} periods (defect {:.2e})", ms.max_periods, r.defect), r.cpu_time_s)),
        Err(e) => Err((e.to_string(), t0.elapsed().as_secs_f64())),
    };
    let r = match fastest(settings.min_timing_s, run, |r| r.cpu_time_s) {
        Ok(r) => r,
        Err((why, t)) => {
            row.status = format!("failed: {why}");
            row.t_failed = Some(t);
            return;
        }
    };
    let dofs = case.dofs();
    let x: Vec<Vec<f64>> = dofs.iter().map(|&d| r.displacement.iter().map(|s| s[d]).collect()).collect();
    let xs: Vec<&[f64]> = x.iter().map(Vec::as_slice).collect();
    row.status = "ok".to_string();
    row.error_x = Some(reference.max_error(&r.time, &xs));
    row.error_impulse = if case.has_contact() { reference.impulse_error(r.impulse_per_period()[0]) } else { None };
    row.t_total = Some(r.cpu_time_s);
    row.periods = Some(r.periods);
}
