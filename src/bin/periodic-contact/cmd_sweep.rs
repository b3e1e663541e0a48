//! `sweep`: a frequency sweep of a scene, warm-started and parallel, with its CSV, the
//! frequency-response PNG, spectra at chosen points and the comparison with time marching.
use crate::{Failure, ensure_writable, write_output};
use indicatif::{ProgressBar, ProgressStyle};
use periodic_contact::model::Quantity;
use periodic_contact::periodic::limits::AmplitudeMeasure;
use periodic_contact::scene::Scene;
use periodic_contact::sweep::{self, SweepSettings, marching::MarchOptions};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// The scene (TOML; see the README's "Scene format").
    pub scene: PathBuf,
    /// The swept parameter: frequency (ω [rad/s]) or speed (Ω [rad/s] of the casing; ω = lobes·Ω).
    #[arg(long, default_value = "frequency")]
    pub param: String,
    /// First value of the swept parameter.
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// Last value (below --from: the sweep runs downwards, warm-started in that direction).
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Number of equally spaced values, both ends included.
    #[arg(long, default_value_t = 100)]
    pub points: usize,
    /// Output CSV; the PNGs go next to it (same stem).
    #[arg(short, long, default_value = "sweep.csv")]
    pub output: PathBuf,
    /// No warm start (every point solved from scratch).
    #[arg(long)]
    pub cold: bool,
    /// Worker threads (0: every core). The default, one thread and one chunk, continues strictly
    /// in the sweep's direction, each point warm-started from the last: where several periodic
    /// solutions coexist it stays on the branch it is on. More threads split the range into
    /// contiguous chunks, each starting cold, which may land on other branches.
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Contiguous chunks per thread (each chunk starts cold).
    #[arg(long, default_value_t = 1)]
    pub chunks_per_thread: usize,
    /// Parameter values at which to draw the spectrum (comma-separated).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub spectrum_at: Vec<f64>,
    /// Highest harmonic in the spectra.
    #[arg(long, default_value_t = 20)]
    pub harmonics: usize,
    /// Parameter values at which to compare with explicit time marching (comma-separated).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub march_at: Vec<f64>,
    /// Periodicity defects at which the march stops (one march each, comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1e-6")]
    pub march_tol: Vec<f64>,
    /// The reference LCP for the errors has this many times the scene's steps (0: none).
    #[arg(long, default_value_t = 4)]
    pub reference_factor: usize,
    /// Time steps per period of the march (a multiple of the LCP's steps; default: stable).
    #[arg(long)]
    pub march_steps: Option<usize>,
    /// Estimate every point's error (warm-started solves at k/2 and, for the observed order, k/4
    /// per point; the CSV's last column, relative to the peak-to-peak amplitude; the worst is printed).
    #[arg(long)]
    pub estimate: bool,
    /// Refine each point whose error estimate exceeds this fraction of its peak-to-peak
    /// amplitude: solved again at 2k (warm-started from its answer), while it does and up to
    /// --max-steps; implies --estimate. The CSV's `steps` column gives each point's k.
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// The largest k of a refinement (--tolerance). 8192: the real blade's 200-point sweep needs it
    /// at one point before its second fold (2458 rad/s: 1.84e-3 at 4096, 4.6e-4 at 8192).
    #[arg(long, default_value_t = 8192)]
    pub max_steps: usize,
    /// What --tolerance and the estimates are relative to: "largest" (the largest output's
    /// peak-to-peak amplitude) or "own" (each output's own).
    #[arg(long, default_value = "largest")]
    pub tolerance_of: String,
    /// Log amplitude axis in the frequency-response PNGs (suggested when the contact and linear
    /// peaks differ by more than 10×).
    #[arg(long)]
    pub log_amplitude: bool,
    /// Each point's exact orbit (the polish's: exact flows between events), by Newton from the
    /// previous point's (compliant contacts: shooting with switch detection, the signature
    /// may change); the grid solve and the polish where that fails. Each point is printed as it
    /// comes (not with --quiet). The CSV's `source` column says which (exact | polished | grid), and
    /// `error_estimate_relative` is the exact orbit's last Newton correction or the grid's estimate.
    #[arg(long)]
    pub exact: bool,
    /// No PNG.
    #[arg(long)]
    pub no_plot: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// `<stem><suffix>.<ext>` beside `path` (also for `continue`).
pub(crate) fn sibling(path: &Path, suffix: &str, ext: &str) -> PathBuf {
    let stem = path.file_stem().map_or("sweep".into(), |s| s.to_string_lossy().to_string());
    path.with_file_name(format!("{stem}{suffix}.{ext}"))
}

/// A point slower than this [s] gets its own line above the progress bar.
const SLOW_POINT_S: f64 = 2.0;

pub fn run(a: &Args) -> Result<(), Failure> {
    if a.points == 0 {
        return Err(Failure::input("--points: is 0, a sweep needs at least one point"));
    }
    if !(a.from.is_finite() && a.to.is_finite() && a.from > 0.0 && a.to > 0.0) {
        return Err(Failure::input(format!("--from/--to: are {} and {}, must be finite and > 0", a.from, a.to)));
    }
    // The CSV, its PNGs and the spectra all go beside --output: check before the first solve.
    ensure_writable(&a.output, "--output")?;
    let t_all = Instant::now();
    let (scene, dir) = Scene::load(&a.scene).map_err(|e| Failure::input(e.to_string()))?;
    let file = a.scene.display().to_string();
    let built = scene.build_in(&file, &dir).map_err(|e| Failure::input(e.to_string()))?;
    let to_frequency: Box<dyn Fn(f64) -> f64> = match a.param.as_str() {
        "frequency" => Box::new(|v| v),
        "speed" => {
            let lobes = built
                .casing
                .as_ref()
                .map(|c| c.lobes)
                .ok_or_else(|| Failure::input(format!("{file}: --param speed needs a [casing] section (ω = lobes·Ω)")))?;
            Box::new(move |v| lobes as f64 * v)
        }
        other => return Err(Failure::input(format!("--param: is \"{other}\", expected frequency or speed"))),
    };
    // Checked before the first solve, so that a typo does not cost the whole sweep.
    for (flag, list) in [("--spectrum-at", &a.spectrum_at), ("--march-at", &a.march_at)] {
        if let Some(v) = list.iter().find(|&&v| !(to_frequency(v).is_finite() && to_frequency(v) > 0.0)) {
            return Err(Failure::input(format!("{flag}: {v} is not a valid {} (must give a finite ω > 0)", a.param)));
        }
    }
    if let Some(t) = a.march_tol.iter().find(|&&t| !(t.is_finite() && t > 0.0)) {
        return Err(Failure::input(format!("--march-tol: is {t}, must be finite and > 0")));
    }
    let values = sweep::linspace(a.from, a.to, a.points);
    let freqs: Vec<f64> = values.iter().map(|&v| to_frequency(v)).collect();
    let mut problem = built.problem.clone();
    // `steps = "auto"`: one k for the sweep, at its lowest frequency (sweep::run does the same).
    if let Some(lowest) = freqs.iter().copied().reduce(f64::min) {
        let why = format!("chosen at the lowest frequency of the sweep ({lowest} rad/s), shared by every point");
        problem.fit_auto_steps(lowest, &why).map_err(|e| Failure::from(periodic_contact::Error::from(e)))?;
    }
    for w in problem.warnings() {
        eprintln!("warning: {w}");
    }
    let problem = &problem;
    match &built.reduction {
        Some(r) => eprintln!(
            "{file}: {} DOFs reduced to {} ({}, {} boundary + {} modes) in {:.3} s; set-up {:.3} s",
            built.full.n(),
            r.n(),
            match r.method {
                periodic_contact::reduction::Method::CraigBampton => "Craig–Bampton",
                periodic_contact::reduction::Method::MasslessBoundary => "massless boundary",
            },
            r.n_boundary(),
            r.n_modes(),
            built.timings.reduction,
            built.timings.total
        ),
        None => eprintln!("{file}: {} DOFs, set-up {:.3} s", built.full.n(), built.timings.total),
    }
    if let Some(t) = a.tolerance.filter(|t| !(t.is_finite() && *t > 0.0 && *t < 1.0)) {
        return Err(Failure::input(format!("--tolerance: {t} is not a fraction of the amplitude in (0, 1); e.g. --tolerance 1e-3")));
    }
    let measure = AmplitudeMeasure::parse(&a.tolerance_of)
        .ok_or_else(|| Failure::input(format!("--tolerance-of: \"{}\" is neither \"largest\" nor \"own\"", a.tolerance_of)))?;
    let settings = SweepSettings {
        measure,
        warm_start: !a.cold,
        threads: a.threads,
        chunks_per_thread: a.chunks_per_thread,
        estimate: a.estimate || a.tolerance.is_some(),
        tolerance: a.tolerance,
        max_steps: a.max_steps,
    };
    let bar = if a.quiet { ProgressBar::hidden() } else { ProgressBar::new(a.points as u64) };
    bar.set_style(
        ProgressStyle::with_template("{spinner} sweep [{bar:40}] {pos}/{len} points, {elapsed_precise} elapsed, ETA {eta} {msg}")
            .unwrap()
            .progress_chars("=> "),
    );
    let t = Instant::now();
    // Each point's time and solver on the bar; a slow, sub-stepped or failed one on its own line
    // (not with --quiet), so that a sweep that stalls shows where.
    let on_point = |p: &sweep::SweepPoint| {
        let what = format!("ω = {}: {:.2} s, {}, {} iterations", p.frequency, p.time_s, sweep::solver_label(&p.lcp_path), p.pivots);
        if !a.quiet && a.exact {
            // An exact sweep's points each on a line: which orbit (exact | polished | grid), its
            // estimate and time, the progress of long work in a log file too.
            let est = p.estimate_relative.map_or_else(|| "no estimate".to_string(), |e| format!("estimate {e:.1e}"));
            bar.suspend(|| eprintln!("  point ω = {}: {}, {est}, {:.2} s", p.frequency, p.source, p.time_s));
        } else if !a.quiet && (p.time_s > SLOW_POINT_S || p.substeps > 0 || p.error.is_some()) {
            let status = p.error.as_deref().map_or_else(|| format!("{} ω sub-steps", p.substeps), |e| format!("failed: {e}"));
            // Printed even where the bar is hidden (stderr not a terminal, a log file).
            bar.suspend(|| eprintln!("  point {what}; {status}"));
        }
        bar.set_message(format!("(last {what})"));
        bar.inc(1);
    };
    let points = if a.exact { sweep::exact::run(problem, &freqs, &settings, &on_point) } else { sweep::run(problem, &freqs, &settings, &on_point) }
        .map_err(Failure::from)?;
    let wall = t.elapsed().as_secs_f64();
    bar.finish_and_clear();

    let labels = &built.labels;
    write_output(&a.output, &sweep::to_csv(&a.param, &values, problem, &points, labels))?;
    let failed: Vec<&sweep::SweepPoint> = points.iter().filter(|p| p.error.is_some()).collect();
    let pivots: usize = points.iter().map(|p| p.pivots).sum();
    let warm = points.iter().filter(|p| p.warm_start_used).count();
    let fallback = points.iter().filter(|p| p.cold_fallback).count();
    let asm: f64 = points.iter().map(|p| p.assembly_s).sum();
    let lcp: f64 = points.iter().map(|p| p.lcp_s).sum();
    let threads = if a.threads == 0 { rayon::current_num_threads() } else { a.threads };
    eprintln!(
        "sweep: {} points in {wall:.3} s wall ({threads} thread{}, {}): {} solved, {} failed; {} warm-started, {} cold fallbacks; {pivots} pivots; assembly {asm:.3} s + LCP {lcp:.3} s summed over points → {}",
        points.len(),
        if threads == 1 { "" } else { "s" },
        if a.cold { "cold" } else { "warm-started" },
        points.len() - failed.len(),
        failed.len(),
        warm,
        fallback,
        a.output.display()
    );
    if a.exact {
        let count = |s: &str| points.iter().filter(|p| p.source == s).count();
        eprintln!("  exact sweep: {} exact, {} polished, {} grid", count("exact"), count("polished"), count("grid"));
    }
    if settings.estimate || a.exact {
        let worst = points
            .iter()
            .filter(|p| p.error.is_none())
            .max_by(|x, y| x.estimate_relative.unwrap_or(f64::INFINITY).total_cmp(&y.estimate_relative.unwrap_or(f64::INFINITY)));
        if let Some(w) = worst {
            let none = points.iter().filter(|p| p.error.is_none() && p.estimate_relative.is_none()).count();
            let e = w.estimate_relative.map_or("none".to_string(), |e| format!("{e:.2e}"));
            eprintln!(
                "  error estimates: worst {e} of the peak-to-peak amplitude at ω = {} ({}); {none} points without an estimate",
                w.frequency, w.estimate_method
            );
        }
    }
    if let Some(tol) = a.tolerance {
        let met = points.iter().filter(|p| p.estimate_relative.is_some_and(|e| e <= tol)).count();
        let mut ks: Vec<usize> = points.iter().filter(|p| p.error.is_none()).map(|p| p.steps).collect();
        ks.sort_unstable();
        ks.dedup();
        let per_k: Vec<String> = ks.iter().map(|&k| format!("{} at k = {k}", points.iter().filter(|p| p.error.is_none() && p.steps == k).count())).collect();
        eprintln!("  tolerance {tol:e}: met at {met} of {} points; {} (refined up to --max-steps {})", points.len(), per_k.join(", "), a.max_steps);
    }
    for (i, d) in problem.outputs().displacement.iter().enumerate() {
        let nl = sweep::peak(&points, |p| p.amplitude[i]);
        let li = sweep::peak(&points, |p| p.linear_amplitude[i]);
        if let (Some(nl), Some(li)) = (nl, li) {
            let (unit, hz) = (labels.units.length(), labels.units.name(Quantity::Frequency));
            eprintln!(
                "  {}: peak with contact {:.6e} {unit} at ω = {:.6} {hz}, linear peak {:.6e} {unit} at ω = {:.6} {hz}",
                labels.dof(*d),
                nl.1,
                nl.0,
                li.1,
                li.0
            );
            let ratio = sweep::peak_ratio(nl.1, li.1);
            if ratio > 10.0 && !a.log_amplitude && !a.no_plot {
                eprintln!("  hint: the peaks differ by {ratio:.0}×: --log-amplitude draws both curves readably");
            }
        }
        let curve: Vec<(f64, f64)> = values.iter().zip(&points).filter(|(_, p)| p.error.is_none()).map(|(v, p)| (*v, p.amplitude[i])).collect();
        for (x, y) in sweep::jumps(&curve) {
            eprintln!("  {}: jump between {} = {} and {} (amplitude {:.6e} → {:.6e})", labels.dof(*d), a.param, x.0, y.0, x.1, y.1);
        }
    }
    // The solver path only where a fallback was taken (the progress bar stays clean).
    for p in points.iter().filter(|p| p.lcp_path.contains("fallback")) {
        eprintln!("  solver at ω = {}: {}", p.frequency, p.lcp_path);
    }
    for p in &failed {
        eprintln!("  failed at ω = {}: {}", p.frequency, p.error.as_deref().unwrap_or(""));
    }

    #[cfg(feature = "plots")]
    if !a.no_plot {
        let stem = a.scene.file_stem().map_or(String::new(), |s| s.to_string_lossy().to_string());
        for (i, d) in problem.outputs().displacement.iter().enumerate() {
            // The first output's curve is <csv stem>.png, the others <csv stem>-dof<d>.png.
            let png = if i == 0 { sibling(&a.output, "", "png") } else { sibling(&a.output, &format!("-dof{d}"), "png") };
            sweep::plot_frc(&png, (&a.param, &values, &points), problem, i, labels, &format!("{stem}: frequency response"), a.log_amplitude)
                .map_err(Failure::from)?;
            eprintln!("frequency-response curve of {} → {}", labels.dof(*d), png.display());
        }
    }

    if !a.spectrum_at.is_empty() {
        let mut spectra = Vec::new();
        for &v in &a.spectrum_at {
            let f = to_frequency(v);
            // Warm-start from the nearest solved sweep point, so as to stay on its branch.
            let near = points.iter().filter(|p| p.error.is_none()).min_by(|x, y| (x.frequency - f).abs().total_cmp(&(y.frequency - f).abs()));
            let mut p = problem.clone();
            p.set_parallel(false);
            let (r, _) = sweep::solve_point(&p, f, near.map(|n| n.active_set.as_slice()));
            let r = r.map_err(|e| Failure::from(e.context(format!("spectrum at {} = {v}", a.param))))?;
            let sp = sweep::spectrum::spectrum(&p, &r, a.harmonics);
            #[cfg(feature = "plots")]
            if !a.no_plot {
                let png = sibling(&a.output, &format!("-spectrum-{v}"), "png");
                let hz = labels.units.name(Quantity::Frequency);
                let title =
                    if a.param == "frequency" { format!("spectrum at ω = {v} {hz}") } else { format!("spectrum at {} = {v} (ω = {f:.4} {hz})", a.param) };
                sweep::spectrum::plot(&png, &sp, labels, &title).map_err(Failure::from)?;
                eprintln!("spectrum at {} = {v} → {}", a.param, png.display());
            }
            spectra.push(sp);
        }
        let csv = sibling(&a.output, "-spectrum", "csv");
        write_output(&csv, &sweep::spectrum::to_csv(&a.param, &a.spectrum_at, &spectra, labels))?;
        eprintln!("spectra → {}", csv.display());
    }

    if !a.march_at.is_empty() {
        let per_point = wall / points.len() as f64;
        let opts =
            MarchOptions { steps_per_period: a.march_steps, tolerances: a.march_tol.clone(), reference_factor: a.reference_factor, ..Default::default() };
        let k = problem.discretization().steps;
        println!(
            "time marching (explicit central differences with penalty contacts, from rest) against the periodic LCP (k = {k}); errors: max over the {k} instants of |x − x_ref| / amplitude, per displacement output ({}); reference: the LCP with k = {}",
            problem.outputs().displacement.iter().map(|d| d.to_string()).collect::<Vec<_>>().join("/"),
            k * a.reference_factor
        );
        println!("sweep: {per_point:.5} s per point (wall, {} points, {})", points.len(), if a.cold { "cold" } else { "warm-started" });
        println!(
            "{:>12} {:>8} {:>10} {:>8} {:>6} {:>11} {:>11} {:>35} {:>35} {:>12} {:>10}",
            a.param, "method", "tolerance", "periods", "conv", "N/period", "time [s]", "err vs ref", "err vs LCP", "× sweep pt", "× cold LCP"
        );
        let fmt = |e: &[Option<f64>]| -> String {
            let v: Vec<String> = e.iter().map(|e| e.map_or("—".to_string(), |e| format!("{e:.1e}"))).collect();
            if v.is_empty() { "—".to_string() } else { v.join("/") }
        };
        for &v in &a.march_at {
            let f = to_frequency(v);
            let c = sweep::marching::compare(problem, f, &opts).map_err(|e| Failure::solver(format!("march at {} = {v}: {e}", a.param)))?;
            println!(
                "{:>12} {:>8} {:>10} {:>8} {:>6} {:>11} {:>11.4} {:>35} {:>35} {:>12} {:>10}",
                v,
                "LCP",
                "—",
                "—",
                "—",
                k,
                c.lcp_time_s,
                fmt(&c.lcp_error_vs_reference),
                "—",
                "—",
                "—"
            );
            for r in &c.runs {
                println!(
                    "{:>12} {:>8} {:>10.0e} {:>8} {:>6} {:>11} {:>11.4} {:>35} {:>35} {:>12.0} {:>10.0}",
                    v,
                    "march",
                    r.tolerance,
                    r.periods,
                    r.converged,
                    c.steps_per_period,
                    r.time_s,
                    fmt(&r.error_vs_reference),
                    fmt(&r.error_vs_lcp),
                    r.time_s / per_point,
                    r.time_s / c.lcp_time_s
                );
            }
        }
    }
    eprintln!("total {:.3} s", t_all.elapsed().as_secs_f64());
    if !failed.is_empty() {
        return Err(Failure::solver(format!("{} of {} sweep points failed (see the status column of {})", failed.len(), points.len(), a.output.display())));
    }
    Ok(())
}
