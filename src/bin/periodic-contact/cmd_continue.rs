//! `continue`: pseudo-arclength continuation of a scene's periodic orbit in one parameter, with
//! stability and located events: CSV, events JSON and PNG beside it.
use crate::cmd_sweep::sibling;
use crate::{Failure, ensure_writable, write_output};
use indicatif::{ProgressBar, ProgressStyle};
use periodic_contact::analysis::continuation::{self, ContinuationSettings, Parameter, output};
use periodic_contact::scene::Scene;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
#[command(after_help = "The scene's scheme must be a difference scheme (cds, bds1, bds2, galerkin): continuation \
    corrects on its time-stepping map, so fourier scenes are refused (trace them with `sweep`).")]
pub struct Args {
    /// The scene (TOML; see the README's "Scene format"): a difference scheme, not fourier.
    pub scene: PathBuf,
    /// The continued parameter: frequency (ω [rad/s]), speed (Ω [rad/s] of the casing; ω =
    /// lobes·Ω), force_scale (× every force of the scene), gap_offset (added to every contact's
    /// clearance, length unit) or normal_force (the normal load N of every [[friction]], force
    /// unit, from 0: the optimal-normal-load curve; friction scenes are solved point by point).
    #[arg(long, default_value = "frequency")]
    pub param: String,
    /// Where the branch starts (the parameter's value; a cold solve there).
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// Where the branch stops; it may pass folds and turn back on the way.
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Output CSV; the events JSON and the PNG go next to it (same stem).
    #[arg(short, long, default_value = "branch.csv")]
    pub output: PathBuf,
    /// Largest arclength step (in the state and the parameter over |to − from|; the exact
    /// walk's unknowns also hold the event times over the period). Default: 0.1 for the exact
    /// orbit's branch, 2e-2 for the discrete walk.
    #[arg(long)]
    pub max_step: Option<f64>,
    /// Most points of a branch (events included) before the walk stops: the real blade's exact
    /// walk makes ≈ 45 points per rad/s of speed, past the default over 150 rad/s.
    #[arg(long, default_value_t = ContinuationSettings::default().max_points)]
    pub max_points: usize,
    /// At each period doubling of the T branch, switch to the 2T branch and continue it too
    /// (same CSV with a `branch` column, same events JSON and PNG).
    #[arg(long)]
    pub switch_at_pd: bool,
    /// With `--param normal_force`: the optimal-normal-load curve instead of a branch, i.e. at
    /// each load the peak over the frequencies A to B [rad/s] of the first displacement output
    /// (`frequency:A:B`; a 24-point grid, the largest refined by golden section), and the load
    /// of the least peak. CSV: load, peak frequency, amplitudes, polished.
    #[arg(long, value_name = "frequency:A:B")]
    pub peak_over: Option<String>,
    /// With `--peak-over`: amplitudes of the stick–slip polish (exact) where it fits, else the LCP's.
    #[arg(long)]
    pub polish: bool,
    /// No PNG.
    #[arg(long)]
    pub no_plot: bool,
    /// No progress bar, and no line per point (λ, exact | discrete, max |μ|, the event found).
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: &Args) -> Result<(), Failure> {
    // The name checked before the scene is built (speed needs the casing's lobes, read after).
    if a.param != "speed" {
        Parameter::parse(&a.param).map_err(Failure::from)?;
    }
    // A normal load may start at 0 (free sliding); the other parameters are > 0.
    let least = if a.param == "normal_force" { 0.0 } else { f64::MIN_POSITIVE };
    if !(a.from.is_finite() && a.to.is_finite() && a.from >= least && a.to >= least && a.from != a.to) {
        let bound = if least == 0.0 { ">= 0" } else { "> 0" };
        return Err(Failure::input(format!("--from/--to: are {} and {}, must be finite, {bound} and different", a.from, a.to)));
    }
    if let Some(s) = a.max_step.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(Failure::input(format!("--max-step: is {s}, must be finite and > 0")));
    }
    ensure_writable(&a.output, "--output")?;
    let t_all = Instant::now();
    let (scene, dir) = Scene::load(&a.scene).map_err(|e| Failure::input(e.to_string()))?;
    let file = a.scene.display().to_string();
    let built = scene.build_in(&file, &dir).map_err(|e| Failure::input(e.to_string()))?;
    let problem = &built.problem;
    let param = match a.param.as_str() {
        "speed" => Parameter::Speed {
            lobes: built
                .casing
                .as_ref()
                .map(|c| c.lobes)
                .ok_or_else(|| Failure::input(format!("{file}: --param speed needs a [casing] section (ω = lobes·Ω)")))?,
        },
        other => Parameter::parse(other).map_err(Failure::from)?,
    };
    if a.max_points == 0 {
        return Err(Failure::input("--max-points: is 0, must be at least 1".to_string()));
    }
    let defaults = ContinuationSettings { max_points: a.max_points, ..ContinuationSettings::default() };
    let settings = match a.max_step {
        Some(s) => ContinuationSettings { max_step: s, exact_max_step: s, ..defaults },
        None => defaults,
    };
    let peak_range = match &a.peak_over {
        None if a.polish => return Err(Failure::input("--polish: only with --peak-over (the branch's points are the LCP's)".to_string())),
        None => None,
        Some(_) if param != Parameter::NormalForce => return Err(Failure::input(format!("--peak-over: only with --param normal_force (is {})", a.param))),
        Some(s) => Some(peak_range(s)?),
    };
    let bar = if a.quiet { ProgressBar::hidden() } else { ProgressBar::new(1000) };
    bar.set_style(ProgressStyle::with_template("{spinner} continue [{bar:40}] {msg}, {elapsed_precise} elapsed").unwrap().progress_chars("=> "));
    let (from, to) = (a.from, a.to);
    let on_value = |v: f64| {
        bar.set_position((((v - from) / (to - from)).clamp(0.0, 1.0) * 1000.0) as u64);
        bar.set_message(format!("{} = {v:.6}", a.param));
    };
    // The CSV's rows written as the points come, so that a walk stopped short (timeout, Ctrl-C)
    // leaves them; the whole CSV replaces them at the end. Not with --switch-at-pd (its branches'
    // rows are known at the end) nor to stdout.
    let rows = (!a.switch_at_pd && peak_range.is_none() && a.output.as_os_str() != "-")
        .then(|| streamed(&a.output, &output::csv_header(param, problem, &built.labels)))
        .transpose()?
        .map(std::cell::RefCell::new);
    // Each point on its own line (not with --quiet), also where the bar is hidden (a log file):
    // a walk of minutes per point shows where it is and what it found.
    let on_point = |p: &continuation::BranchPoint| {
        if let Some(w) = &rows
            && let Err(e) = std::io::Write::write_all(&mut *w.borrow_mut(), output::csv_row(p, 0).as_bytes())
        {
            bar.suspend(|| eprintln!("warning: {}: a row not written as it came ({e}); the whole CSV is written at the end", a.output.display()));
        }
        on_value(p.parameter);
        if !a.quiet {
            // A point without an event may carry a note too (the exact walk's start: how its events were had).
            let event = match p.event {
                Some(k) => format!(", {}: {}", k.name(), p.detail),
                None if !p.detail.is_empty() => format!(" ({})", p.detail),
                None => String::new(),
            };
            bar.suspend(|| eprintln!("  point {} = {:.7}: {}, max |μ| = {:.6}{event}", a.param, p.parameter, p.source.name(), p.max_multiplier));
        }
    };
    if let Some(range) = peak_range {
        let curve =
            continuation::optimal_load::optimal_load(problem, from, to, range, a.polish || built.polish, &settings, &on_value).map_err(Failure::from)?;
        bar.finish_and_clear();
        write_output(&a.output, &continuation::optimal_load::to_csv(&curve, problem, &built.labels))?;
        let o = &curve.optimum;
        let unit = |q| built.labels.unit(q);
        use periodic_contact::model::Quantity;
        eprintln!(
            "continue: {} loads, {} solves in {:.3} s → {}; least peak {:.9e} {} at normal_force = {:.9e} {} (ω = {:.9e} {}, {}{})",
            curve.points.len(),
            curve.solves,
            t_all.elapsed().as_secs_f64(),
            a.output.display(),
            o.amplitude[0],
            unit(Quantity::Length),
            o.normal_force,
            unit(Quantity::Force),
            o.frequency,
            unit(Quantity::Frequency),
            if curve.optimum_interior { "golden section" } else { "at an end of the load range" },
            if o.polished { ", polished" } else { ", LCP amplitudes" }
        );
        if curve.points.iter().any(|p| p.at_end) {
            eprintln!("warning: some peaks lie at an end of the frequency range (the CSV's at_range_end): widen --peak-over");
        }
        #[cfg(feature = "plots")]
        if !a.no_plot {
            let png = sibling(&a.output, "", "png");
            let stem = a.scene.file_stem().map_or(String::new(), |s| s.to_string_lossy().to_string());
            continuation::optimal_load::plot(&png, &curve, problem, &built.labels, &format!("{stem}: optimal normal load")).map_err(Failure::from)?;
            eprintln!("optimal-normal-load curve → {}", png.display());
        }
        return Ok(());
    }
    let (branches, failures) = if a.switch_at_pd {
        continuation::run_switching(problem, param, a.from, a.to, &settings, &on_point).map_err(Failure::from)?
    } else {
        (vec![continuation::run(problem, param, a.from, a.to, &settings, &on_point).map_err(Failure::from)?], Vec::new())
    };
    bar.finish_and_clear();
    let labels = &built.labels;
    write_output(&a.output, &output::to_csv(&branches, problem, labels))?;
    let json = sibling(&a.output, "-events", "json");
    write_output(&json, &output::events_json(&branches, problem))?;
    eprintln!("continue: {} branch(es) in {:.3} s → {}, {}", branches.len(), t_all.elapsed().as_secs_f64(), a.output.display(), json.display());
    for (i, b) in branches.iter().enumerate() {
        eprintln!(
            "branch {i} ({}): {} points ({} from the exact orbit, {} events), {} marches of the period map; stop: {}",
            b.label,
            b.points.len(),
            b.points.iter().filter(|p| p.source == continuation::Source::Exact).count(),
            b.events().count(),
            b.marches,
            b.stop
        );
        for e in b.events() {
            eprintln!("  {:<16} {} = {:.7}  max |μ| = {:.6}  {}", e.event.map_or("", |k| k.name()), a.param, e.parameter, e.max_multiplier, e.detail);
        }
    }
    for f in &failures {
        eprintln!("warning: {f}");
    }
    let branch = &branches[0];
    #[cfg(feature = "plots")]
    if !a.no_plot {
        let stem = a.scene.file_stem().map_or(String::new(), |s| s.to_string_lossy().to_string());
        for (i, d) in problem.outputs().displacement.iter().enumerate() {
            let png = if i == 0 { sibling(&a.output, "", "png") } else { sibling(&a.output, &format!("-dof{d}"), "png") };
            output::plot(&png, &branches, problem, i, labels, &format!("{stem}: branch")).map_err(Failure::from)?;
            eprintln!("branch of {} → {}", labels.dof(*d), png.display());
        }
    }
    if !branch.reached() {
        return Err(Failure::solver(format!("the continuation stopped before {} = {}: {}", a.param, a.to, branch.stop)));
    }
    Ok(())
}

/// `path` opened for the rows written as they come, with `header` in it; each row reaches the
/// file at its newline.
fn streamed(path: &std::path::Path, header: &str) -> Result<std::io::LineWriter<std::fs::File>, Failure> {
    let cannot = |e: std::io::Error| Failure::input(format!("{}: cannot write the output: {e}", path.display()));
    let mut w = std::io::LineWriter::new(std::fs::File::create(path).map_err(cannot)?);
    std::io::Write::write_all(&mut w, header.as_bytes()).map_err(cannot)?;
    Ok(w)
}

/// `frequency:A:B` → (A, B).
fn peak_range(s: &str) -> Result<(f64, f64), Failure> {
    let bad = || Failure::input(format!("--peak-over: is \"{s}\", must be frequency:A:B with 0 < A < B (rad/s), e.g. frequency:0.5:2.5"));
    let parts: Vec<&str> = s.split(':').collect();
    let [what, a, b] = parts.as_slice() else { return Err(bad()) };
    let (a, b): (f64, f64) = (a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?);
    if *what != "frequency" || !(a > 0.0 && b > a && b.is_finite()) {
        return Err(bad());
    }
    Ok((a, b))
}
