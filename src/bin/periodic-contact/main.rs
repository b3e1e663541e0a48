//! periodic-contact: the command-line tool.
//! Exit status: 0 success, 1 the solver failed (typed outcome printed), 2 bad input.
mod cmd_bench;
mod cmd_continue;
mod cmd_deck;
mod cmd_export;
mod cmd_fmu;
mod cmd_lcp;
mod cmd_modes;
mod cmd_solve;
mod cmd_study;
mod cmd_sweep;
mod defaults;
mod malloc;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "periodic-contact", version, about = "Steady-state periodic responses under unilateral contact, as one LCP over the period")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene and write the periodic response as JSON.
    Solve {
        /// The scene (TOML; see the README's "Scene format").
        scene: PathBuf,
        /// Output JSON file ("-" for stdout).
        #[arg(short, long, default_value = "result.json")]
        output: PathBuf,
        /// Override excitation.frequency ω [rad/s] (with a casing: ω = lobes·Ω).
        #[arg(long)]
        frequency: Option<f64>,
        /// Also write the scene's LCP (dense, Siconos .dat format) to this file, for peers.
        #[arg(long)]
        export_lcp: Option<PathBuf>,
        /// Skip the error estimate (a second solve at k/2; on by default, or as
        /// `[discretization] error_estimate` says).
        #[arg(long)]
        no_estimate: bool,
        /// CPU seconds the error estimate's neighbour solves may take together; past it the
        /// result has no estimate and says why (`accuracy.missing`), its own answer unchanged.
        /// With `scheme = "auto"` it bounds the estimate of every k the refinement solves.
        #[arg(long, value_name = "SECONDS", default_value_t = periodic_contact::analysis::accuracy::neighbour::ESTIMATE_BUDGET_CPU_S)]
        estimate_budget: f64,
        /// Refine the orbit by the event-fitted polish (also `[discretization] polish = true`).
        #[arg(long)]
        polish: bool,
        /// Seek an orbit of P forcing periods (period P·T; overrides `[discretization]
        /// period_multiple`): the LCP over P periods, `steps` instants per forcing period.
        #[arg(long)]
        period_multiple: Option<i64>,
        /// Also draw each friction contact's hysteresis loop (friction force against the
        /// contact's relative displacement, the energy per cycle in the title) to this PNG;
        /// refused on a scene without `[[friction]]`.
        #[arg(long, value_name = "PNG")]
        hysteresis: Option<PathBuf>,
    },
    /// Package a scene as an FMI 2.0 co-simulation FMU (needs `cargo build --release`).
    Fmu {
        /// The scene (TOML) packaged into the FMU's resources.
        scene: PathBuf,
        /// Output .fmu file.
        #[arg(short, long)]
        output: PathBuf,
        /// The FMU binary libPeriodicContact.so (default: $PERIODIC_CONTACT_FMU_BINARY, else next to this executable).
        #[arg(long)]
        binary: Option<PathBuf>,
    },
    /// Write the mesh of a scene's blade generator as a CalculiX deck (C3D8 or C3D8I, root
    /// clamped, *FREQUENCY SOLVER=MATRIXSTORAGE): `ccx JOB` then writes JOB.sti, JOB.mas, JOB.dof.
    Deck {
        scene: PathBuf,
        /// Output .inp file.
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Write the model the scene solves (reduced, damped) for an independent reference: M, C, K
    /// and the contact rows B as Matrix Market, gaps, compliances, forces, ω and outputs in
    /// DIR/model.json (validation/exact_flow.py reads it).
    Export {
        scene: PathBuf,
        /// Output folder (created).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// First eigenfrequencies of the full model and, with [reduction], of the reduced one.
    Modes {
        /// The scene (TOML; see the README's "Scene format").
        scene: PathBuf,
        /// How many modes.
        #[arg(long, default_value_t = 10)]
        count: usize,
    },
    /// Frequency sweep: CSV, frequency-response PNG, spectra, comparison with time marching.
    Sweep(cmd_sweep::Args),
    /// Continuation of a periodic orbit in one parameter through folds: stability (Floquet
    /// multipliers) and located events; CSV, events JSON and PNG.
    Continue(cmd_continue::Args),
    /// Benchmark over the class: time, pivots and peak memory per case and k, with random
    /// families (worst case first).
    Bench {
        /// Cases (comma-separated): rigid-stick, rigid-impact, compliant, chain, blade, reduced, or all.
        #[arg(long, value_delimiter = ',', default_value = "rigid-stick")]
        case: Vec<String>,
        /// LCP sizes k to measure.
        #[arg(long, value_delimiter = ',', default_value = "256,512,1024,2048,4096")]
        steps: Vec<usize>,
        /// Repeats per size (the best time is kept).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// LCP method: auto, lemke, pivoting or shooting.
        #[arg(long, default_value = "auto")]
        method: String,
        /// Random members of each case's family besides the nominal one.
        #[arg(long, default_value_t = 0)]
        draws: usize,
        /// Seed of the draws.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Seconds after which one measurement is stopped and reported as a timeout.
        #[arg(long, default_value_t = 600.0)]
        timeout: f64,
        /// Internal: measure one size in this process.
        #[arg(long, hide = true)]
        single: Option<usize>,
        /// Internal: the member of the family measured by --single (0: nominal).
        #[arg(long, hide = true, default_value_t = 0)]
        draw: usize,
    },
    /// Solve a raw LCP in Siconos' dense .dat format (block-circulant matrices are detected and
    /// solved by the fast path).
    Lcp {
        /// The LCP: Siconos' dense .dat format (n, M row by row, q).
        file: PathBuf,
        /// Output JSON file (z, w, status, pivots; "-" for stdout).
        #[arg(short, long, default_value = "-")]
        output: PathBuf,
        /// auto (block-circulant detection, fast path above N = 256), lemke (dense lexicographic
        /// Lemke) or pivoting.
        #[arg(long, default_value = "auto")]
        method: String,
        /// Certification: ‖min(z, Az+q)‖∞ ≤ tolerance·max(1, ‖q‖∞).
        #[arg(long, default_value = "1e-9")]
        tolerance: f64,
    },
    /// Studies: accuracy against cost, warm starts.
    Study {
        #[command(subcommand)]
        study: cmd_study::StudyCommand,
    },
}

/// A failure with its exit status.
pub struct Failure {
    pub status: u8,
    pub message: String,
}

impl From<periodic_contact::Error> for Failure {
    fn from(e: periodic_contact::Error) -> Self {
        Failure { status: e.kind().exit_status(), message: e.to_string() }
    }
}

impl Failure {
    pub fn input(message: impl Into<String>) -> Self {
        Failure { status: 2, message: message.into() }
    }
    pub fn solver(message: impl Into<String>) -> Self {
        Failure { status: 1, message: message.into() }
    }
}

fn main() -> ExitCode {
    malloc::keep_freed_memory();
    let cli = Cli::parse();
    let result = match cli.command {
        None => cmd_solve::run_default(),
        Some(Command::Solve { scene, output, frequency, export_lcp, no_estimate, estimate_budget, polish, period_multiple, hysteresis }) => {
            let overrides = cmd_solve::Overrides { frequency, period_multiple };
            let files = cmd_solve::Files { output: &output, export_lcp: export_lcp.as_deref(), hysteresis: hysteresis.as_deref() };
            cmd_solve::run(&scene, files, overrides, cmd_solve::Refine { estimate: !no_estimate, estimate_budget, polish })
        }
        Some(Command::Modes { scene, count }) => cmd_modes::run(&scene, count),
        Some(Command::Deck { scene, output }) => cmd_deck::run(&scene, &output),
        Some(Command::Export { scene, output }) => cmd_export::run(&scene, &output),
        Some(Command::Sweep(args)) => cmd_sweep::run(&args),
        Some(Command::Continue(args)) => cmd_continue::run(&args),
        Some(Command::Lcp { file, output, method, tolerance }) => cmd_lcp::run(&file, &output, &method, tolerance),
        Some(Command::Study { study }) => cmd_study::run(study),
        Some(Command::Fmu { scene, output, binary }) => cmd_fmu::run(&scene, &output, binary.as_deref()),
        Some(Command::Bench { case, steps, repeats, method, draws, seed, timeout, single, draw }) => match single {
            Some(k) => cmd_bench::run_single(case.first().map_or("rigid-stick", String::as_str), k, draw, seed, repeats, &method),
            None => cmd_bench::run(&cmd_bench::BenchArgs { cases: &case, steps: &steps, repeats, method: &method, draws, seed, timeout_s: timeout }),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("error: {}", f.message);
            ExitCode::from(f.status)
        }
    }
}

/// Fails fast, before any solving, when `path` ("-": stdout) cannot be written: its folder is
/// missing or read-only, or it names a folder. A probe file is created and removed beside it.
pub fn ensure_writable(path: &std::path::Path, flag: &str) -> Result<(), Failure> {
    if path.as_os_str() == "-" {
        return Ok(());
    }
    if path.is_dir() {
        return Err(Failure::input(format!("{flag} {}: is a folder; name a file inside it, e.g. {}", path.display(), path.join("out").display())));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    if !dir.is_dir() {
        return Err(Failure::input(format!(
            "{flag} {}: the folder {} does not exist; create it first (mkdir -p {}) or choose another {flag}",
            path.display(),
            dir.display(),
            dir.display()
        )));
    }
    ensure_folder_writable(dir, flag, path)
}

/// A folder of outputs (created, as the studies write several files into it), checked before
/// any work starts.
pub fn ensure_output_folder(dir: &std::path::Path, flag: &str) -> Result<(), Failure> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure::input(format!("{flag} {}: cannot create the folder ({e}); choose a writable location", dir.display())))?;
    ensure_folder_writable(dir, flag, dir)
}

/// A probe file created and removed in `dir` proves that outputs can be written there.
pub fn ensure_folder_writable(dir: &std::path::Path, flag: &str, shown: &std::path::Path) -> Result<(), Failure> {
    let probe = dir.join(format!(".periodic-contact-probe-{}~", std::process::id()));
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .and_then(|_| std::fs::remove_file(&probe))
        .map_err(|e| Failure::input(format!("{flag} {}: cannot write into the folder {} ({e}); choose a writable location", shown.display(), dir.display())))
}

/// Writes `text` to `path`, or stdout for "-", without leaving a half-written file behind.
pub fn write_output(path: &std::path::Path, text: &str) -> Result<(), Failure> {
    if path.as_os_str() == "-" {
        println!("{text}");
        return Ok(());
    }
    let tmp = path.with_extension("tmp~");
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| Failure::input(format!("{}: cannot write the output: {e}", path.display())))
}
