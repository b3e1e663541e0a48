//! `study accuracy`: error against CPU time for every scheme and pairing, k = 32 … 8192, on the
//! exact references of notes §6, with the explicit time-marching reference (notes §5) on the
//! same axes. Writes `accuracy.csv`, `accuracy.md` and `accuracy.png`.
//!
//! Cost caps (so that the whole run stays within a few minutes on 2 cores): the runs go level by
//! level (all cases and methods at k = 32, then at 64, …), so that the overall budget cuts the
//! largest sizes first; a method stops growing k once its next run is predicted (from the growth
//! of its last two runs) to take longer than `solve_cap_s`, and, for the choices that do not
//! converge, k stops at `nonconverging_max_k` (their error has plateaued long before; their
//! LCPs are degenerate and the fallback there is dense Lemke, O(N³)). Skipped points are listed in
//! the CSV with their reason.
use super::{Case, Reference, fitted_order, method_label, sci};
use crate::Error;
use crate::lcp::{LcpMatrix, dat::write_dat};
use crate::marching::{MarchSettings, march};
use crate::periodic::{LcpMethod, PeriodFft};
use crate::time::{Pairing, Scheme};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
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
    /// A method stops growing k (the marcher N) once its next run is predicted to take longer
    /// than this [s] (from the growth of its last two runs).
    pub solve_cap_s: f64,
    /// k cap of the (scheme, pairing) choices that do not converge.
    pub nonconverging_max_k: usize,
    /// Total budget [s]: past it the remaining (larger) runs are skipped.
    pub budget_s: f64,
    /// Timing: repeat a run until this much time was spent (at most 5 times); keep the fastest.
    pub min_timing_s: f64,
    /// Export every LCP solved (up to `export_max` unknowns) to this folder as Siconos `.dat`.
    pub export_lcp: Option<PathBuf>,
    pub export_max: usize,
}

impl AccuracySettings {
    /// The documented full study: k = 32 … 8192, marcher N = 32 … 8192.
    pub fn full() -> Self {
        let pow2 = |lo: u32, hi: u32| (lo..=hi).map(|e| 1usize << e).collect::<Vec<_>>();
        AccuracySettings {
            steps: pow2(5, 13),
            march_steps: pow2(5, 13),
            cases: Case::ALL.to_vec(),
            methods: vec![],
            march: true,
            march_tolerance: 1e-10,
            solve_cap_s: 10.0,
            nonconverging_max_k: 1024,
            budget_s: 300.0,
            min_timing_s: 0.05,
            export_lcp: None,
            export_max: 4096,
        }
    }
    /// For tests: k = 32 … 128, a few seconds.
    pub fn quick() -> Self {
        AccuracySettings { steps: vec![32, 64, 128], march_steps: vec![32, 64, 128], budget_s: 60.0, min_timing_s: 0.0, ..Self::full() }
    }
}

/// One measured (or skipped) point.
#[derive(Clone, Debug)]
pub struct Row {
    pub case: Case,
    /// "cds/forward", "cds" (no contact), or "march cds" for the time-marching reference.
    pub method: String,
    /// "periodic" or "marching".
    pub kind: &'static str,
    /// k (periodic) or steps per period (marching).
    pub steps: usize,
    /// Converges to the exact orbit according to notes §3 (marching: the plastic-impact orbit).
    pub converges: bool,
    /// "ok", "failed: …" or "skipped: …".
    pub status: String,
    pub error_x: Option<f64>,
    pub error_impulse: Option<f64>,
    pub t_assembly: Option<f64>,
    pub t_lcp: Option<f64>,
    pub t_recovery: Option<f64>,
    /// Total CPU time (periodic: assembly + LCP + recovery; marching: to the steady state).
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
    fn new(case: Case, method: String, kind: &'static str, steps: usize, converges: bool) -> Self {
        Row {
            case,
            method,
            kind,
            steps,
            converges,
            status: String::new(),
            error_x: None,
            error_impulse: None,
            t_assembly: None,
            t_lcp: None,
            t_recovery: None,
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
}

/// What the study produced.
pub struct AccuracyStudy {
    pub rows: Vec<Row>,
    pub settings: AccuracySettings,
    pub elapsed_s: f64,
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
    /// CPU time of the last run that completed.
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
    if let Some(dir) = &settings.export_lcp {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(format!("{}: cannot create the LCP export folder: {e}", dir.display())))?;
    }
    let wanted = |label: &str| settings.methods.is_empty() || settings.methods.iter().any(|m| m == label);
    let mut tracks: BTreeMap<(String, String), Track> = BTreeMap::new();
    let mut rows = Vec::new();
    let mut exported = Vec::new();
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
                    let mut row = Row::new(case, label.clone(), "periodic", k, converges);
                    let track = tracks.entry((case.name().to_string(), label.clone())).or_insert(Track { stopped: None, last: None });
                    if let Some(why) = &track.stopped {
                        row.status = format!("skipped: {why}");
                    } else if !converges && k > settings.nonconverging_max_k {
                        row.status = format!("skipped: does not converge, k capped at {}", settings.nonconverging_max_k);
                    } else if start.elapsed().as_secs_f64() > settings.budget_s {
                        row.status = format!("skipped: total budget of {} s spent", settings.budget_s);
                    } else {
                        periodic_point(&mut row, case, scheme, pairing, k, reference, settings, &mut exported)?;
                        track.record(k, row.t_total.or(row.t_failed), settings.solve_cap_s);
                    }
                    progress(&row);
                    rows.push(row);
                }
            }
            if settings.march
                && let Some(&n) = settings.march_steps.get(level)
            {
                let label = "march cds".to_string();
                let mut row = Row::new(case, label.clone(), "marching", n, true);
                let track = tracks.entry((case.name().to_string(), label)).or_insert(Track { stopped: None, last: None });
                if let Some(why) = &track.stopped {
                    row.status = format!("skipped: {why}");
                } else if start.elapsed().as_secs_f64() > settings.budget_s {
                    row.status = format!("skipped: total budget of {} s spent", settings.budget_s);
                } else {
                    march_point(&mut row, case, n, reference, settings);
                    track.record(n, row.t_total.or(row.t_failed), settings.solve_cap_s);
                }
                progress(&row);
                rows.push(row);
            }
        }
    }
    Ok(AccuracyStudy { rows, settings: settings.clone(), elapsed_s: start.elapsed().as_secs_f64(), exported, load: (load0, load_average()) })
}

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
) -> Result<(), Error> {
    let problem = match case.problem(scheme, pairing, k, LcpMethod::Auto) {
        Ok(p) => p,
        Err(e) => {
            row.status = format!("failed: {e}");
            return Ok(());
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
    let mut best = None;
    let mut spent = 0.0;
    for _ in 0..5 {
        let t0 = Instant::now();
        match problem.solve_with(&fft, None) {
            Ok(r) => {
                spent += r.timing_s.total;
                if best.as_ref().is_none_or(|b: &crate::response::Response| r.timing_s.total < b.timing_s.total) {
                    best = Some(r);
                }
            }
            Err(e) => {
                row.status = format!("failed: {e}");
                row.t_failed = Some(t0.elapsed().as_secs_f64());
                return Ok(());
            }
        }
        if spent >= settings.min_timing_s {
            break;
        }
    }
    let r = best.expect("one run");
    row.status = "ok".to_string();
    row.error_x = Some(reference.max_error(&r.time, &r.displacement["0"]));
    row.error_impulse = if case.has_contact() { reference.impulse_error(r.impulse_per_period(0)) } else { None };
    row.t_assembly = Some(r.timing_s.assembly);
    row.t_lcp = Some(r.timing_s.lcp);
    row.t_recovery = Some(r.timing_s.recovery);
    row.t_total = Some(r.timing_s.total);
    if case.has_contact() {
        row.pivots = Some(r.lcp.pivots);
        row.residual = Some(r.lcp.residual);
    }
    Ok(())
}

fn march_point(row: &mut Row, case: Case, n: usize, reference: &Reference, settings: &AccuracySettings) {
    let model = case.model();
    let ms = MarchSettings { steps_per_period: n, max_periods: 20_000, min_periods: 3, tolerance: settings.march_tolerance, ..MarchSettings::default() };
    let mut best: Option<crate::marching::MarchResult> = None;
    let mut spent = 0.0;
    for _ in 0..5 {
        let t0 = Instant::now();
        match march(&model, &ms) {
            Ok(r) if r.converged => {
                spent += r.cpu_time_s;
                if best.as_ref().is_none_or(|b| r.cpu_time_s < b.cpu_time_s) {
                    best = Some(r);
                }
            }
            Ok(r) => {
                row.status = format!("failed: no steady state within {} periods (defect {:.2e})", ms.max_periods, r.defect);
                row.t_failed = Some(r.cpu_time_s);
                return;
            }
            Err(e) => {
                row.status = format!("failed: {e}");
                row.t_failed = Some(t0.elapsed().as_secs_f64());
                return;
            }
        }
        if spent >= settings.min_timing_s {
            break;
        }
    }
    let r = best.expect("one run");
    let x: Vec<f64> = r.displacement.iter().map(|d| d[0]).collect();
    row.status = "ok".to_string();
    row.error_x = Some(reference.max_error(&r.time, &x));
    row.error_impulse = if case.has_contact() { reference.impulse_error(r.impulse_per_period()[0]) } else { None };
    row.t_total = Some(r.cpu_time_s);
    row.periods = Some(r.periods);
}

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map(|v| v.to_string()).unwrap_or_default()
}

fn opt_e(v: Option<f64>) -> String {
    v.map(|v| format!("{v:.6e}")).unwrap_or_default()
}

impl AccuracyStudy {
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "case,method,kind,steps,converges,status,error_x_rel_ptp,error_impulse_rel,time_assembly_s,time_lcp_s,time_recovery_s,time_total_s,lcp_size,pivots,residual,periods\n",
        );
        for r in &self.rows {
            let _ = writeln!(
                s,
                "{},{},{},{},{},\"{}\",{},{},{},{},{},{},{},{},{},{}",
                r.case.name(),
                r.method,
                r.kind,
                r.steps,
                r.converges,
                r.status.replace('"', "'"),
                opt_e(r.error_x),
                opt_e(r.error_impulse),
                opt_e(r.t_assembly),
                opt_e(r.t_lcp),
                opt_e(r.t_recovery),
                opt_e(r.t_total),
                r.lcp_size,
                opt(r.pivots),
                opt_e(r.residual),
                opt(r.periods)
            );
        }
        s
    }

    fn ok_rows(&self, case: Case) -> impl Iterator<Item = &Row> {
        self.rows.iter().filter(move |r| r.case == case && r.ok() && r.error_x.is_some() && r.t_total.is_some())
    }

    /// The cheapest run reaching `target` (max error relative to the peak-to-peak amplitude)
    /// among the rows of converging methods that pass `filter` (a choice that does not converge
    /// can be close at one k by chance; it is not a method one can pick for an accuracy).
    pub fn cheapest(&self, case: Case, target: f64, filter: impl Fn(&Row) -> bool) -> Option<&Row> {
        self.ok_rows(case).filter(|r| r.converges && filter(r) && r.error_x.unwrap() <= target).min_by(|a, b| a.t_total.unwrap().total_cmp(&b.t_total.unwrap()))
    }

    /// The accuracy targets of the summary.
    pub const TARGETS: [f64; 6] = [1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6];

    pub fn markdown(&self) -> String {
        let s_ = &self.settings;
        let mut s = String::new();
        let _ = writeln!(s, "# Accuracy against cost (generated by `periodic-contact study accuracy`)\n");
        let _ = writeln!(
            s,
            "Error: max over the samples of |x_j − x_exact(t_j)| divided by the exact peak-to-peak amplitude; impulse error relative. \
             CPU time on one thread: periodic = assembly + LCP + recovery (`timing_s`, fastest of up to 5 repeats for runs under {} s); \
             marching = explicit central differences with forward-increment multipliers (`marching::march`) from rest until the periodicity \
             defect is below {:.0e}. k = {:?}; marcher N = {:?}. Caps: a method stops growing k once its next run is predicted to take over {} s; choices that do not \
             converge stop at k = {}; total budget {} s (used {:.0} s). Times are wall-clock times of one thread; \
             load average of the machine at the start and the end of the run: {} / {} (a load above the core count inflates them).\n",
            s_.min_timing_s,
            s_.march_tolerance,
            s_.steps,
            if s_.march { s_.march_steps.clone() } else { vec![] },
            s_.solve_cap_s,
            s_.nonconverging_max_k,
            s_.budget_s,
            self.elapsed_s,
            self.load.0,
            self.load.1
        );
        for &case in &s_.cases {
            let _ = writeln!(s, "## {}\n", case.title());
            // Cheapest for a given accuracy.
            let _ = writeln!(s, "### Cheapest method for a given accuracy (among the choices that converge)\n");
            let _ =
                writeln!(s, "| error ≤ | cheapest overall | CPU [s] | cheapest periodic LCP | CPU [s] | time marching | CPU [s] | marching / best periodic |");
            let _ = writeln!(s, "|---:|---|---:|---|---:|---|---:|---:|");
            let mut winners: BTreeMap<String, usize> = BTreeMap::new();
            for target in Self::TARGETS {
                let all = self.cheapest(case, target, |_| true);
                let per = self.cheapest(case, target, |r| r.kind == "periodic");
                let mar = self.cheapest(case, target, |r| r.kind == "marching");
                if all.is_none() {
                    let _ = writeln!(s, "| {target:.0e} | not reached | | | | | | |");
                    continue;
                }
                let name = |r: Option<&Row>| r.map(|r| format!("{} (k = {})", r.method, r.steps)).unwrap_or_else(|| "not reached".into());
                let time = |r: Option<&Row>| sci(r.and_then(|r| r.t_total));
                let ratio = match (per, mar) {
                    (Some(p), Some(m)) => ratio_text(m.t_total.unwrap() / p.t_total.unwrap()),
                    _ => "—".into(),
                };
                *winners.entry(all.unwrap().method.clone()).or_default() += 1;
                let _ =
                    writeln!(s, "| {target:.0e} | {} | {} | {} | {} | {} | {} | {ratio} |", name(all), time(all), name(per), time(per), name(mar), time(mar));
            }
            let reached = winners.values().sum::<usize>();
            if reached > 0 {
                let mut w: Vec<_> = winners.into_iter().collect();
                w.sort_by_key(|e| std::cmp::Reverse(e.1));
                let list: Vec<String> = w.iter().map(|(m, c)| format!("**{m}** at {c} of {reached}")).collect();
                let _ = writeln!(s, "\nCheapest for the accuracy targets reached: {}.\n", list.join(", "));
            }
            // Per-method summary.
            let _ = writeln!(s, "### Per method\n");
            let _ = writeln!(
                s,
                "| method | converges (notes §3) | largest k run | error there | impulse error there | CPU there [s] (assembly / LCP / recovery) | fitted order (k ≥ 128) | failed or skipped |"
            );
            let _ = writeln!(s, "|---|---|---:|---:|---:|---|---:|---|");
            let mut labels: Vec<String> = Vec::new();
            for r in self.rows.iter().filter(|r| r.case == case) {
                if !labels.contains(&r.method) {
                    labels.push(r.method.clone());
                }
            }
            for label in labels {
                let rs: Vec<&Row> = self.rows.iter().filter(|r| r.case == case && r.method == label).collect();
                let ok: Vec<&&Row> = rs.iter().filter(|r| r.ok()).collect();
                let last = ok.last();
                let pts: Vec<(usize, f64)> = ok.iter().filter(|r| r.steps >= 128).map(|r| (r.steps, r.error_x.unwrap())).collect();
                let bad: Vec<String> = rs.iter().filter(|r| !r.ok()).map(|r| format!("{}: {}", r.steps, short(&r.status))).collect();
                let split = last.map(|r| match (r.t_assembly, r.t_lcp, r.t_recovery) {
                    (Some(a), Some(l), Some(c)) => format!("{} ({} / {} / {})", sci(r.t_total), sci(Some(a)), sci(Some(l)), sci(Some(c))),
                    _ => format!("{} ({} periods)", sci(r.t_total), opt(r.periods)),
                });
                let _ = writeln!(
                    s,
                    "| {label} | {} | {} | {} | {} | {} | {} | {} |",
                    if rs[0].converges { "yes" } else { "no" },
                    last.map(|r| r.steps.to_string()).unwrap_or_else(|| "—".into()),
                    sci(last.and_then(|r| r.error_x)),
                    sci(last.and_then(|r| r.error_impulse)),
                    split.unwrap_or_else(|| "—".into()),
                    fitted_order(&pts).map(|p| format!("{p:.2}")).unwrap_or_else(|| "—".into()),
                    if bad.is_empty() { String::new() } else { bad.join("; ") }
                );
            }
            let _ = writeln!(s);
        }
        if !self.exported.is_empty() {
            let _ = writeln!(s, "LCPs exported in Siconos `.dat` format: {}.\n", self.exported.len());
        }
        s
    }

    /// One panel per case: error against CPU time, log axes, one line per method; a last panel
    /// with the impulse error of the rigid stop.
    #[cfg(feature = "plots")]
    pub fn plot(&self, path: &Path) -> Result<(), Error> {
        use crate::plot::{Chart, Legend, Scale, Series, panel_chart};
        let series_of = |case: Case, value: &dyn Fn(&Row) -> Option<f64>| -> Vec<Series> {
            let mut labels: Vec<String> = Vec::new();
            for r in self.ok_rows(case) {
                if !labels.contains(&r.method) && value(r).is_some() {
                    labels.push(r.method.clone());
                }
            }
            labels
                .iter()
                .map(|l| {
                    let rows: Vec<&Row> = self.ok_rows(case).filter(|r| &r.method == l && value(r).is_some()).collect();
                    let conv = rows.first().is_some_and(|r| r.converges);
                    Series {
                        label: if conv { l.clone() } else { format!("{l} (does not converge)") },
                        points: rows.iter().map(|r| (r.t_total.unwrap(), value(r).unwrap())).collect(),
                        markers: true,
                    }
                })
                .collect()
        };
        let mut titles = Vec::new();
        let mut all_series = Vec::new();
        let mut y_labels = Vec::new();
        for &case in &self.settings.cases {
            titles.push(format!("{}: error vs CPU time", case.title()));
            y_labels.push("max error / peak-to-peak");
            all_series.push(series_of(case, &|r: &Row| r.error_x));
        }
        if self.settings.cases.contains(&Case::Rigid) {
            titles.push(format!("{}: impulse error vs CPU time", Case::Rigid.title()));
            y_labels.push("relative error of the impulse per period");
            all_series.push(series_of(Case::Rigid, &|r: &Row| r.error_impulse));
        }
        let chart_defs: Vec<Chart> = titles
            .iter()
            .zip(&y_labels)
            .map(|(t, y)| Chart { title: t, x_label: "CPU time [s] (one thread)", y_label: y, x_scale: Scale::Log, y_scale: Scale::Log })
            .collect();
        let panels: Vec<(&Chart, &[Series])> = chart_defs.iter().zip(&all_series).map(|(c, s)| (c, s.as_slice())).collect();
        let cols = panels.len().min(2);
        let rows = panels.len().div_ceil(cols.max(1)) as u32;
        panel_chart(path, &panels, cols, 1000 * cols as u32, 850 * rows, Legend::LowerLeft).map_err(Error::from)
    }

    /// Writes accuracy.csv, accuracy.md and (with the `plots` feature) accuracy.png into `dir`.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, Error> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(format!("{}: cannot create: {e}", dir.display())))?;
        let mut out = Vec::new();
        for (name, text) in [("accuracy.csv", self.csv()), ("accuracy.md", self.markdown())] {
            let p = dir.join(name);
            std::fs::write(&p, text).map_err(|e| Error::io(format!("{}: cannot write: {e}", p.display())))?;
            out.push(p);
        }
        #[cfg(feature = "plots")]
        {
            let p = dir.join("accuracy.png");
            self.plot(&p)?;
            out.push(p);
        }
        Ok(out)
    }
}

/// 2 significant digits: 2500×, 13×, 1.4×, 0.023×.
fn ratio_text(r: f64) -> String {
    if !r.is_finite() || r <= 0.0 {
        return "—".into();
    }
    let digits = (1 - r.log10().floor() as i32).max(0) as usize;
    format!("{r:.digits$}×")
}

fn short(s: &str) -> String {
    let s = s.split(" (pivots").next().unwrap_or(s);
    let s: String = s.chars().take(90).collect();
    s.replace('|', "/")
}
