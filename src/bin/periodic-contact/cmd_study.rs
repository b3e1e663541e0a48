//! `study accuracy` and `study warmstart` (issue 6): what accuracy costs, and warm starts.
use crate::Failure;
use clap::Subcommand;
use periodic_contact::study::{Case, accuracy, warmstart};
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum StudyCommand {
    /// What accuracy costs: error against wall time per scheme and pairing, k = 32 … 8192, with
    /// the error estimates, the polish, time marching and Siconos on the same axes, on the exact
    /// references (rigid stop with sticking and with pure impacts, compliant stop, linear) and a
    /// 2-DOF compliant chain; then the estimates' honesty on random family members. Writes
    /// DIR/accuracy.csv, estimate.csv, accuracy.md and accuracy.png (about 2 minutes on 2 cores:
    /// the k sweep stops at --budget, 120 s by default).
    Accuracy {
        /// The folder of the outputs (created).
        #[arg(short, long, default_value = "study")]
        output: PathBuf,
        /// k = 32 … 256, no peers, 2 members per family: for tests.
        #[arg(long)]
        quick: bool,
        /// k values (default 32 … 8192, powers of two).
        #[arg(long, value_delimiter = ',')]
        steps: Option<Vec<usize>>,
        /// Marcher steps per period (default as k).
        #[arg(long, value_delimiter = ',')]
        march_steps: Option<Vec<usize>>,
        /// Cases: compliant, rigid, impacting, chain, linear (default all).
        #[arg(long, value_delimiter = ',')]
        cases: Option<Vec<String>>,
        /// Only these methods, e.g. cds/forward,bds1/same (default all).
        #[arg(long, value_delimiter = ',')]
        methods: Option<Vec<String>>,
        /// Skip the time-marching reference.
        #[arg(long)]
        no_march: bool,
        /// Total budget in seconds (larger k are skipped past it).
        #[arg(long)]
        budget: Option<f64>,
        /// Export every LCP solved (up to --export-max unknowns) as Siconos .dat files here.
        #[arg(long)]
        export_lcp: Option<PathBuf>,
        #[arg(long, default_value_t = 4096)]
        export_max: usize,
        /// Leave Siconos out (it runs in /usr/bin/python3 with python3-siconos).
        #[arg(long)]
        no_peers: bool,
        /// Random members per family in the estimate-honesty table (0: the nominal members only).
        #[arg(long)]
        draws: Option<usize>,
        /// Seed of the family draws.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Pivots and LCP time, cold against warm: a frequency sweep of the rigid stop and re-solves
    /// after a small frequency change. Writes DIR/warmstart.csv, warmstart.md and warmstart.png.
    Warmstart {
        /// The folder of the outputs (created).
        #[arg(short, long, default_value = "study")]
        output: PathBuf,
        /// k = 128 and 512, a 5-point sweep, one repeat: for tests.
        #[arg(long)]
        quick: bool,
        /// k values (default 256, 1024, 4096).
        #[arg(long, value_delimiter = ',')]
        steps: Option<Vec<usize>>,
    },
}

pub fn run(cmd: StudyCommand) -> Result<(), Failure> {
    match cmd {
        StudyCommand::Accuracy { output, quick, steps, march_steps, cases, methods, no_march, budget, export_lcp, export_max, no_peers, draws, seed } => {
            crate::ensure_output_folder(&output, "--output")?;
            if let Some(dir) = &export_lcp {
                crate::ensure_output_folder(dir, "--export-lcp")?;
            }
            let mut s = if quick { accuracy::AccuracySettings::quick() } else { accuracy::AccuracySettings::full() };
            if let Some(k) = steps {
                if let Some(bad) = k.iter().find(|&&k| !(4..=1 << 22).contains(&k)) {
                    return Err(Failure::input(format!("--steps: {bad} is out of 4..=4194304")));
                }
                s.steps = k;
            }
            if let Some(n) = march_steps {
                s.march_steps = n;
            }
            if let Some(c) = cases {
                s.cases = c.iter().map(|c| Case::parse(c)).collect::<Result<_, _>>().map_err(|e| Failure::input(format!("--cases: {e}")))?;
            }
            if let Some(m) = methods {
                s.methods = m;
            }
            if no_march {
                s.march = false;
            }
            if let Some(b) = budget {
                s.budget_s = b;
            }
            s.export_lcp = export_lcp;
            s.export_max = export_max;
            if no_peers {
                s.peers = None;
            }
            if let Some(h) = s.honesty.as_mut() {
                h.draws = draws.unwrap_or(h.draws);
                h.seed = seed;
            }
            let study = accuracy::run(&s, &mut |r| {
                eprintln!(
                    "{:<9} {:<16} {:<8} {:>5}  {:<60} err {:>9}  est {:>9}  t {:>9}",
                    r.case.name(),
                    r.method,
                    r.kind.name(),
                    r.steps,
                    r.status.chars().take(60).collect::<String>(),
                    r.error_x.map(|v| format!("{v:.2e}")).unwrap_or_default(),
                    r.estimate.map(|v| format!("{v:.2e}")).unwrap_or_default(),
                    r.t_total.map(|v| format!("{v:.2e}")).unwrap_or_default()
                )
            })
            .map_err(Failure::from)?;
            let files = study.write(&output).map_err(Failure::from)?;
            for f in files {
                eprintln!("wrote {}", f.display());
            }
            if !study.exported.is_empty() {
                eprintln!("exported {} LCPs to {}", study.exported.len(), s.export_lcp.as_ref().unwrap().display());
            }
            Ok(())
        }
        StudyCommand::Warmstart { output, quick, steps } => {
            crate::ensure_output_folder(&output, "--output")?;
            let mut s = if quick { warmstart::WarmSettings::quick() } else { warmstart::WarmSettings::full() };
            if let Some(k) = steps {
                s.steps = k;
            }
            let study = warmstart::run(&s, &mut |r| {
                eprintln!(
                    "{:<7} k {:>5} {:<6} ω {:.4}  pivots cold {:>6} warm {:>6}  lcp cold {:.2e} s warm {:.2e} s  used {} diff {:.1e} {}",
                    r.kind,
                    r.k,
                    r.method.name(),
                    r.omega,
                    r.cold_pivots,
                    r.warm_pivots,
                    r.cold_lcp_s,
                    r.warm_lcp_s,
                    r.warm_start_used,
                    r.same_solution,
                    if r.status == "ok" { "" } else { &r.status }
                )
            })
            .map_err(Failure::from)?;
            let files = study.write(&output).map_err(Failure::from)?;
            for f in files {
                eprintln!("wrote {}", f.display());
            }
            Ok(())
        }
    }
}
