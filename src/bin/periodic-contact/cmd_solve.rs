//! `solve` and the default run.
use crate::{Failure, ensure_writable, write_output};
use periodic_contact::analysis::{accuracy, hysteresis, polish, scheme_auto};
use periodic_contact::linalg::PeriodFft;
use periodic_contact::model::Labels;
use periodic_contact::periodic::PeriodicProblem;
use periodic_contact::periodic::limits::AccuracyTarget;
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;
use std::path::Path;

fn solve(problem: &PeriodicProblem) -> Result<Response, Failure> {
    for w in problem.warnings() {
        eprintln!("warning: {w}");
    }
    problem.solve().map_err(|e| Failure::from(periodic_contact::Error::from(e)))
}

/// What the CLI asks of a result beyond the solve: flags can only switch on (`--polish`) or
/// off (`--no-estimate`) what the scene says.
#[derive(Clone, Copy, Debug)]
pub struct Refine {
    pub estimate: bool,
    /// CPU seconds for the estimate's neighbour solves.
    pub estimate_budget: f64,
    pub polish: bool,
}

/// What the command line overrides in the scene.
#[derive(Clone, Copy, Debug)]
pub struct Overrides {
    /// `--frequency`: ω [rad/s].
    pub frequency: Option<f64>,
    /// `--period-multiple`: orbits of p forcing periods.
    pub period_multiple: Option<i64>,
}

/// What `solve` writes: the JSON, and on request the LCP and the hysteresis loops.
#[derive(Clone, Copy, Debug)]
pub struct Files<'a> {
    pub output: &'a Path,
    pub export_lcp: Option<&'a Path>,
    pub hysteresis: Option<&'a Path>,
}

/// A scene loaded for `solve`: the checked problem, what to refine, the scene's labels and the
/// scene DOF of each `[[friction]]` (for the hysteresis plot).
struct Loaded {
    problem: PeriodicProblem,
    refine: Refine,
    labels: Labels,
    friction_dofs: Vec<usize>,
    /// `scheme = "auto"`: the tolerance and the policy's choice.
    auto: Option<(AccuracyTarget, String)>,
}

fn load(scene: &Path, overrides: Overrides, flags: Refine) -> Result<Loaded, Failure> {
    let (mut s, dir) = Scene::load(scene).map_err(|e| Failure::input(e.to_string()))?;
    if let Some(f) = overrides.frequency {
        s.set_frequency(f);
    }
    if let Some(p) = overrides.period_multiple {
        if p < 1 {
            return Err(Failure::input(format!(
                "--period-multiple: is {p}, must be a whole number of forcing periods ≥ 1 (1: T-periodic, 2: period doubled, …)"
            )));
        }
        s.discretization.period_multiple = Some(p);
    }
    let friction_dofs = s.friction.iter().map(|f| f.dof.unwrap_or(usize::MAX)).collect();
    let built = s.build_in(&scene.display().to_string(), &dir).map_err(|e| Failure::input(e.to_string()))?;
    let refine = Refine { estimate: flags.estimate && built.error_estimate, polish: flags.polish || built.polish, ..flags };
    let auto = built.accuracy_target.zip(built.scheme_choice);
    Ok(Loaded { problem: built.problem, refine, labels: built.labels, friction_dofs, auto })
}

/// The error estimate, then the polish (whose estimate replaces it), as `refine` asks.
fn refine(problem: &PeriodicProblem, r: &mut Response, refine: Refine) {
    if r.scheme_choice.is_some() {
        // `scheme = "auto"` estimated every k it solved.
    } else if refine.estimate {
        r.accuracy = accuracy::estimate_within(problem, r, refine.estimate_budget);
    } else {
        r.accuracy.method = "none: not requested (--no-estimate or error_estimate = \"none\")".to_string();
    }
    if refine.polish {
        let n = r.warnings.len();
        let _ = polish::apply(problem, r);
        for w in &r.warnings[n..] {
            eprintln!("warning: {w}");
        }
    }
}

/// The largest LCP `--export-lcp` writes: a dense .dat of N = 4096 is already 0.4 GB of text.
const EXPORT_MAX: usize = 4096;

/// Writes the scene's LCP (w = A z + q, z the contact forces) in Siconos' dense `.dat` format.
fn export_lcp(problem: &PeriodicProblem, path: &Path) -> Result<(), Failure> {
    let (k, m) = (problem.instants(), problem.model().contacts.len());
    if m == 0 {
        return Err(Failure::input("--export-lcp: the scene has no contact, so there is no LCP to export"));
    }
    if k * m > EXPORT_MAX {
        return Err(Failure::input(format!(
            "--export-lcp: the LCP has N = k·m = {k}·{m} = {} unknowns, above the dense export's limit {EXPORT_MAX}; lower discretization.steps",
            k * m
        )));
    }
    let (a, q) = problem.assemble_lcp(&PeriodFft::new(k)).map_err(|e| Failure::from(periodic_contact::Error::from(e)))?;
    periodic_contact::lcp::dat::write_dat(path, &a, &q).map_err(|e| Failure::input(format!("--export-lcp {}: cannot write: {e}", path.display())))?;
    eprintln!("LCP of size {} (k = {k}, m = {m}) → {}", q.len(), path.display());
    Ok(())
}

pub fn run(scene: &Path, files: Files, overrides: Overrides, flags: Refine) -> Result<(), Failure> {
    // One solve may take minutes (shooting's homotopies, a dense fallback): say where it is.
    periodic_contact::lcp::set_progress(true);
    let Files { output, export_lcp: export, hysteresis } = files;
    ensure_writable(output, "--output")?;
    if let Some(p) = export {
        ensure_writable(p, "--export-lcp")?;
    }
    if let Some(p) = hysteresis {
        ensure_writable(p, "--hysteresis")?;
    }
    let Loaded { mut problem, refine: flags, labels, friction_dofs, auto } = load(scene, overrides, flags)?;
    if hysteresis.is_some() && problem.model().frictions.is_empty() {
        return Err(Failure::input(format!(
            "--hysteresis: {} has no [[friction]] contact, so there is no force–displacement loop to draw; add a [[friction]] entry or leave --hysteresis out",
            scene.display()
        )));
    }
    if let Some(p) = export {
        export_lcp(&problem, p)?;
    }
    // Errors found while solving name the scene too (those of loading already do).
    let named = |f: Failure| Failure { message: format!("{}: {}", scene.display(), f.message), ..f };
    let mut r = match &auto {
        Some((target, choice)) => {
            eprintln!("{choice}");
            scheme_auto::solve_to_tolerance_within(&mut problem, target, choice, flags.estimate_budget)
                .map_err(|e| named(Failure::from(periodic_contact::Error::from(e))))?
        }
        None => solve(&problem).map_err(named)?,
    };
    refine(&problem, &mut r, flags);
    let json = serde_json::to_string_pretty(&r).map_err(|e| Failure::solver(e.to_string()))?;
    write_output(output, &json)?;
    if let Some(p) = hysteresis {
        hysteresis::plot_hysteresis(p, &r.friction, &hysteresis::LoopLabels { dofs: &friction_dofs, labels: &labels })
            .map_err(|e| Failure::solver(e.to_string()))?;
        for (i, f) in r.friction.iter().enumerate() {
            eprintln!(
                "friction[{i}]: {:.6} {}·{} dissipated per cycle (∮ f du, the loop's area)",
                f.dissipated_energy,
                labels.units.force(),
                labels.units.length()
            );
        }
        eprintln!("hysteresis loop(s) → {}", p.display());
    }
    eprintln!("solver: {}", r.lcp.path);
    if let Some(c) = &r.scheme_choice {
        let tried: Vec<String> = c
            .tried
            .iter()
            .map(|t| format!("k = {}: {} in {:.2} s", t.steps, t.estimate.map_or("no estimate".into(), |e| format!("{e:.2e}")), t.seconds))
            .collect();
        eprintln!(
            "scheme auto: {} {} k = {} ({}), {}",
            c.scheme,
            c.pairing,
            c.steps,
            tried.join("; "),
            if c.met { "tolerance met" } else { "tolerance NOT met" }
        );
    }
    match (r.accuracy.estimate, r.accuracy.relative) {
        (Some(e), Some(rel)) => eprintln!("error estimate: {e:.3e} ({rel:.2e} of the peak-to-peak amplitude), {}", r.accuracy.method),
        (Some(e), None) => eprintln!("error estimate: {e:.3e}, {}", r.accuracy.method),
        _ => eprintln!("error estimate: {}", r.accuracy.method),
    }
    if output.as_os_str() != "-" {
        eprintln!(
            "solved {}: LCP size {}, {} pivots, residual {:.2e}, {:.3} s → {}",
            scene.display(),
            r.lcp.size,
            r.lcp.pivots,
            r.lcp.residual,
            r.timing_s.total,
            output.display()
        );
    }
    match &r.scheme_choice {
        // The result is written; the exit status says it misses the tolerance (a Limit).
        Some(c) if !c.met => Err(Failure::input(format!("{}: {}", scene.display(), r.warnings.last().map_or("", String::as_str)))),
        _ => Ok(()),
    }
}

/// `cargo run --release` without arguments: the built-in scene and a short table.
pub fn run_default() -> Result<(), Failure> {
    let scene = Scene::parse(crate::defaults::DEFAULT_SCENE, "built-in rigid-stop scene").map_err(|e| Failure::input(e.to_string()))?;
    let problem = scene.to_problem("built-in rigid-stop scene").map_err(|e| Failure::input(e.to_string()))?;
    let r = solve(&problem)?;
    let x = &r.displacement["0"];
    println!("periodic-contact: built-in scene (fmu/scenes/rigid-stop.toml)");
    println!("  damped oscillator m=1, c=0.1, k=1, F=cos(t), rigid stop at x=0.5; {} k={} pairing={}", r.scheme, r.steps, r.pairing);
    println!("  {:<34} {:>14}", "quantity", "value");
    let rows = [
        ("amplitude (peak-to-peak/2) [m]", format!("{:.6}", Response::peak_to_peak(x) / 2.0)),
        ("min displacement [m]", format!("{:.6}", x.iter().cloned().fold(f64::INFINITY, f64::min))),
        ("max contact force [N]", format!("{:.6}", r.contacts[0].force.iter().cloned().fold(0.0, f64::max))),
        ("impulse per period [N·s]", format!("{:.6}", r.impulse_per_period(0))),
        ("fraction of period in contact", format!("{:.4}", r.contact_fraction(0))),
        ("LCP size", r.lcp.size.to_string()),
        ("pivots", r.lcp.pivots.to_string()),
        ("residual ‖min(z,w)‖∞", format!("{:.2e}", r.lcp.residual)),
        ("time [s]", format!("{:.4}", r.timing_s.total)),
    ];
    for (k, v) in rows {
        println!("  {k:<34} {v:>14}");
    }
    println!("  exact (src/formulation.md §6.3): min displacement −1.869854, impulse per period 2.80804");
    Ok(())
}
