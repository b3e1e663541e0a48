//! `bench`: time, pivots and peak memory of the periodic LCP over the class of problems, per k.
//!
//! Cases (issue 12): the rigid 1-DOF stop with sticking and with pure impacts, the compliant stop,
//! the 3-DOF chain with two stops, the rigid reduced blade. Each has a nominal scene (draw 0, the shipped scene's values)
//! and a family: `--draws N` adds N scenes with parameters drawn uniformly within the family's
//! ranges (seeded), and the report gives the spread per size, worst case first.
//! Each measurement runs in a child process of its own, so that its peak resident size is its
//! own and a `--timeout` can stop it.
use crate::Failure;
use periodic_contact::scene::Scene;
use periodic_contact::study::families::{Family, SplitMix, pick};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Peak resident set size of this process [MiB] (Linux VmHWM), if known.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// One member of a family: its scene text and a one-line summary of its parameters.
struct Member {
    scene: String,
    summary: String,
}

/// A family of benchmark scenes.
struct Case {
    name: &'static str,
    about: &'static str,
    /// The scene with `steps` instants; `rng` is `None` for the nominal member.
    member: fn(usize, Option<&mut SplitMix>) -> Member,
}

/// A 1-DOF family member (`study::families`) as a scene: m x'' + c x' + k x = F cos ωt against a
/// stop at g0 (rigid, or compliant with stiffness kc).
fn oscillator(steps: usize, family: Family, rng: Option<&mut SplitMix>) -> Member {
    let m = family.member(rng);
    let (o, gap) = (m.oscillator, m.gap);
    let contact_stiffness = m.contact_stiffness.map_or(String::new(), |kc| format!("stiffness = {kc}\n"));
    let scene = format!(
        "[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n\n[damping]\nmatrix = [[{}]]\n\n[excitation]\nfrequency = {}\n\n\
         [[force]]\ndof = 0\namplitude = {}\n\n[[contact]]\ndof = 0\ndirection = 1\ngap = {gap}\n{contact_stiffness}\n\
         [discretization]\nscheme = \"cds\"\nsteps = {steps}\n\n[output]\ndisplacement = [0]\n",
        o.damping, o.omega, o.force
    );
    Member { scene, summary: m.summary() }
}

/// The paper's case: the rigid reduced blade (23 DOFs after Craig–Bampton, 3 tip contacts).
const BLADE: &str = include_str!("../../../fmu/scenes/blade-casing-rigid.toml");

/// The size case (issue 23): a 100-DOF spring–mass chain given as dense matrices (the step map
/// is dense in the state whatever the model, as a Craig–Bampton model's), 32 compliant stops on
/// DOFs 1, 4, …, 94 from alternating sides, each obstacle moving at the forcing frequency
/// so that every contact has a contact phase, cds with same pairing (compliant stops: second
/// order). Contact stiffnesses 1–4, the springs' order: at 5–50 (tests/shooting.rs's draws)
/// Newton on the period map does not converge with 12 or more stops (measured). Drawn: masses and springs 0.5–2, ω, the gaps, the obstacles' amplitudes and
/// phases, the contact stiffnesses.
fn reduced(steps: usize, mut rng: Option<&mut SplitMix>) -> Member {
    let (mut scene, omega, mean_mass) = drawn_chain(&mut rng, 100, (0.8, (0.6, 1.0)), (50, 0.5));
    for c in 0..32 {
        let gap = pick(&mut rng, 0.1, (0.05, 0.15));
        let amplitude = pick(&mut rng, 0.25, (0.2, 0.3));
        let phase = pick(&mut rng, 0.2 * c as f64, (0.0, std::f64::consts::TAU));
        let kc = pick(&mut rng, 2.0, (1.0, 4.0));
        scene += &format!(
            "[[contact]]\ndof = {}\ndirection = {}\ngap = {gap}\nstiffness = {kc}\nmotion = [{{ amplitude = {amplitude}, harmonic = 1, phase = {phase} }}]\n\n",
            1 + 3 * c,
            if c % 2 == 0 { 1 } else { -1 }
        );
    }
    scene += &format!("[discretization]\nscheme = \"cds\"\nsteps = {steps}\npairing = \"same\"\n\n[output]\ndisplacement = [0, 50, 99]\n");
    Member { scene, summary: format!("ω={omega:.3}, m̄={mean_mass:.3}") }
}

/// The head of a drawn chain scene (structure, Rayleigh damping 0.01/0.02, ω, one harmonic
/// force `load` = (DOF, amplitude)): ω (nominal, range) first, then n masses and n + 1 springs in
/// 0.5–2 (nominal 1). Returns the text, ω and the mean mass.
fn drawn_chain(rng: &mut Option<&mut SplitMix>, n: usize, omega: (f64, (f64, f64)), load: (usize, f64)) -> (String, f64, f64) {
    let omega = pick(rng, omega.0, omega.1);
    let masses: Vec<f64> = (0..n).map(|_| pick(rng, 1.0, (0.5, 2.0))).collect();
    let springs: Vec<f64> = (0..=n).map(|_| pick(rng, 1.0, (0.5, 2.0))).collect();
    let (mass, stiffness) = chain_matrices(&masses, &springs);
    let head = format!(
        "[structure]\nmass = {mass}\nstiffness = {stiffness}\n\n[damping]\nrayleigh = [0.01, 0.02]\n\n[excitation]\nfrequency = {omega}\n\n\
         [[force]]\ndof = {}\namplitude = {}\n\n",
        load.0, load.1
    );
    (head, omega, masses.iter().sum::<f64>() / n as f64)
}

/// M and K of a fixed–fixed spring–mass chain (n masses, n + 1 springs) as dense TOML arrays.
fn chain_matrices(masses: &[f64], springs: &[f64]) -> (String, String) {
    let n = masses.len();
    let row = |entry: &dyn Fn(usize) -> f64| format!("[{}]", (0..n).map(|j| format!("{}", entry(j))).collect::<Vec<_>>().join(", "));
    let mass: Vec<String> = (0..n).map(|i| row(&|j| if i == j { masses[i] } else { 0.0 })).collect();
    let stiffness: Vec<String> = (0..n)
        .map(|i| {
            row(&|j| match j {
                _ if j == i => springs[i] + springs[i + 1],
                _ if j == i + 1 => -springs[i + 1],
                _ if j + 1 == i => -springs[i],
                _ => 0.0,
            })
        })
        .collect();
    (format!("[{}]", mass.join(", ")), format!("[{}]", stiffness.join(", ")))
}

/// The friction size case (issue 25): a 16-DOF fixed–fixed chain with a friction contact under a
/// constant normal load on every mass (Jenkins elements on the even DOFs, rigid Coulomb on the
/// odd ones), Rayleigh damping, a harmonic force on DOF 8, bds1: N = 2·16·k. Drawn: masses and
/// springs 0.5–2, ω, each μN and k_t.
fn friction_chain(steps: usize, mut rng: Option<&mut SplitMix>) -> Member {
    let n = 16;
    let (mut scene, omega, mean_mass) = drawn_chain(&mut rng, n, (1.0, (0.6, 1.4)), (8, 1.0));
    for dof in 0..n {
        let slip = pick(&mut rng, 0.05, (0.02, 0.1));
        let kt = pick(&mut rng, 2.0, (0.5, 5.0));
        let jenkins = if dof % 2 == 0 { format!("stiffness = {kt}\n") } else { String::new() };
        scene += &format!("[[friction]]\ndof = {dof}\ncoefficient = 1.0\nnormal_force = {slip}\n{jenkins}\n");
    }
    scene += &format!("[discretization]\nscheme = \"bds1\"\nsteps = {steps}\n\n[output]\ndisplacement = [0, 8, 15]\n");
    Member { scene, summary: format!("ω={omega:.3}, m̄={mean_mass:.3}") }
}

const CASES: [Case; 7] = [
    Case {
        name: "rigid-stick",
        about: "rigid 1-DOF stop with sticking (0 < k·g0 < F; src/formulation.md §6.3): m = k = 1, F = 1, cds, forward pairing",
        member: |steps, rng| oscillator(steps, Family::RigidStick, rng),
    },
    Case {
        name: "rigid-impact",
        about: "rigid 1-DOF stop, pure impacts (F < k·g0: the mass cannot stick): m = k = 1, g0 = 1, cds, forward pairing",
        member: |steps, rng| oscillator(steps, Family::RigidImpact, rng),
    },
    Case {
        name: "compliant",
        about: "compliant 1-DOF stop (src/formulation.md §6.2: m = k = 1, g0 = 1), cds",
        member: |steps, rng| oscillator(steps, Family::Compliant, rng),
    },
    Case {
        name: "chain",
        about: "3-DOF chain with two rigid stops (fmu/scenes/chain-3dof-two-stops.toml), cds, forward pairing",
        member: |steps, mut rng| {
            let omega = pick(&mut rng, 0.6, (0.5, 0.7));
            let force = pick(&mut rng, 0.5, (0.4, 0.6));
            let g1 = pick(&mut rng, 0.4, (0.3, 0.5));
            let g2 = pick(&mut rng, 0.3, (0.25, 0.4));
            let scene = format!(
                "[structure]\nmass = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n\
                 stiffness = [[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]\n\n[damping]\nrayleigh = [0.05, 0.02]\n\n\
                 [excitation]\nfrequency = {omega}\n\n[[force]]\ndof = 2\namplitude = {force}\n\n\
                 [[contact]]\ndof = 1\ndirection = 1\ngap = {g1}\n\n[[contact]]\ndof = 2\ndirection = -1\ngap = {g2}\n\n\
                 [discretization]\nscheme = \"cds\"\nsteps = {steps}\n\n[output]\ndisplacement = [0, 1, 2]\n"
            );
            Member { scene, summary: format!("ω={omega:.3} F={force:.3} g1={g1:.3} g2={g2:.3}") }
        },
    },
    Case {
        name: "blade",
        about: "rigid reduced blade (fmu/scenes/blade-casing-rigid.toml: 23 DOFs, LE/MC/TE tip contacts, out-of-round casing), cds, forward pairing; k ≥ 1024 (cds's limit)",
        member: |steps, mut rng| {
            let omega = pick(&mut rng, 2300.0, (2200.0, 2400.0));
            let scene = BLADE.replace("steps = \"auto\"", &format!("steps = {steps}")).replace("frequency = 2300.0", &format!("frequency = {omega}"));
            Member { scene, summary: format!("ω={omega:.1} rad/s") }
        },
    },
    Case {
        name: "reduced",
        about: "100-DOF model (dense matrices), 32 compliant stops (stiffness 1–4) against obstacles moving at ω, cds, same pairing (issue 23's size case: N = 32·k)",
        member: reduced,
    },
    Case {
        name: "friction",
        about: "16-DOF chain (dense matrices), a friction contact on every mass (μN 0.02–0.1; Jenkins k_t 0.5–5 on the even DOFs, rigid Coulomb on the odd), bds1 (issue 25's size case: N = 2·16·k)",
        member: friction_chain,
    },
];

fn case(name: &str) -> Result<&'static Case, Failure> {
    CASES.iter().find(|c| c.name == name).ok_or_else(|| {
        Failure::input(format!("--case: \"{name}\" is not a case; expected {} or all", CASES.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")))
    })
}

/// Member `draw` of a family: 0 is the nominal scene, i ≥ 1 the i-th draw of the seeded stream.
fn member(c: &Case, steps: usize, draw: usize, seed: u64) -> Member {
    if draw == 0 {
        return (c.member)(steps, None);
    }
    (c.member)(steps, Some(&mut SplitMix::for_draw(seed, draw)))
}

/// One measurement in this process, printed as one tab-separated line for the parent.
pub fn run_single(name: &str, steps: usize, draw: usize, seed: u64, repeats: usize, method: &str) -> Result<(), Failure> {
    let m = member(case(name)?, steps, draw, seed);
    let text = m.scene.replace("[output]", &format!("[solver]\nmethod = \"{method}\"\n\n[output]"));
    let problem = Scene::parse(&text, "bench").and_then(|s| s.to_problem("bench")).map_err(|e| Failure::input(e.to_string()))?;
    let mut best: Option<periodic_contact::response::Response> = None;
    for _ in 0..repeats.max(1) {
        let r = problem.solve().map_err(|e| Failure::solver(e.to_string()))?;
        if best.as_ref().is_none_or(|b| r.timing_s.total < b.timing_s.total) {
            best = Some(r);
        }
    }
    let r = best.expect("at least one repeat");
    println!(
        "{:.6}\t{:.6}\t{:.6}\t{}\t{:.3e}\t{:.1}\t{}",
        r.timing_s.assembly,
        r.timing_s.lcp,
        r.timing_s.total,
        r.lcp.pivots,
        r.lcp.residual,
        peak_rss_mib().unwrap_or(f64::NAN),
        r.lcp.size
    );
    Ok(())
}

/// What a child reported, or why it did not.
enum Outcome {
    Measured { lcp_s: f64, total_s: f64, assembly_s: f64, pivots: usize, residual: f64, rss_mib: f64, size: usize },
    Failed(String),
}

fn measure(name: &str, steps: usize, draw: usize, seed: u64, repeats: usize, method: &str, timeout: Duration) -> Result<Outcome, Failure> {
    let exe = std::env::current_exe().map_err(|e| Failure::solver(e.to_string()))?;
    let args = ["bench", "--single", &steps.to_string(), "--case", name, "--draw", &draw.to_string(), "--seed", &seed.to_string()];
    let mut child = Command::new(&exe)
        .args(args)
        .args(["--repeats", &repeats.to_string(), "--method", method])
        .env("RAYON_NUM_THREADS", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| Failure::solver(format!("cannot run the benchmark child: {e}")))?;
    let start = Instant::now();
    while child.try_wait().map_err(|e| Failure::solver(e.to_string()))?.is_none() {
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            return Ok(Outcome::Failed(format!("timeout {} s", timeout.as_secs())));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().map_err(|e| Failure::solver(e.to_string()))?;
    if !out.status.success() {
        let why = String::from_utf8_lossy(&out.stderr).trim().trim_start_matches("error: ").to_string();
        return Ok(Outcome::Failed(why.chars().take(80).collect()));
    }
    let line = String::from_utf8_lossy(&out.stdout);
    let f: Vec<&str> = line.trim().split('\t').collect();
    let num = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).ok_or_else(|| Failure::solver(format!("unreadable child output {line:?}")));
    Ok(Outcome::Measured {
        assembly_s: num(0)?,
        lcp_s: num(1)?,
        total_s: num(2)?,
        pivots: num(3)? as usize,
        residual: num(4)?,
        rss_mib: num(5)?,
        size: num(6)? as usize,
    })
}

pub struct BenchArgs<'a> {
    pub cases: &'a [String],
    pub steps: &'a [usize],
    pub repeats: usize,
    pub method: &'a str,
    pub draws: usize,
    pub seed: u64,
    pub timeout_s: f64,
}

pub fn run(a: &BenchArgs) -> Result<(), Failure> {
    if !(a.timeout_s.is_finite() && a.timeout_s > 0.0) {
        return Err(Failure::input(format!("--timeout: is {}, must be finite and > 0 seconds", a.timeout_s)));
    }
    let cases: Vec<&Case> =
        if a.cases.iter().any(|c| c == "all") { CASES.iter().collect() } else { a.cases.iter().map(|c| case(c)).collect::<Result<_, _>>()? };
    let timeout = Duration::from_secs_f64(a.timeout_s);
    println!("solver.method = {}, one core per child, best of {} repeats, timeout {} s per child", a.method, a.repeats, a.timeout_s);
    for c in cases {
        println!("\n{}: {}", c.name, c.about);
        if a.draws > 0 {
            println!("family: the nominal scene and {} draws (seed {}), parameters uniform in the case's ranges", a.draws, a.seed);
        }
        println!("| k | N | member | assembly [s] | LCP [s] | total [s] | pivots | residual | peak RSS [MiB] |");
        println!("|---:|---:|---|---:|---:|---:|---:|---:|---:|");
        for &k in a.steps {
            let mut rows = Vec::new();
            for draw in 0..=a.draws {
                let summary = member(c, k, draw, a.seed).summary;
                rows.push((summary, measure(c.name, k, draw, a.seed, a.repeats, a.method, timeout)?));
            }
            // Worst first: failures, then by total time.
            rows.sort_by(|x, y| match (&x.1, &y.1) {
                (Outcome::Failed(_), Outcome::Measured { .. }) => std::cmp::Ordering::Less,
                (Outcome::Measured { .. }, Outcome::Failed(_)) => std::cmp::Ordering::Greater,
                (Outcome::Measured { total_s: tx, .. }, Outcome::Measured { total_s: ty, .. }) => ty.total_cmp(tx),
                _ => std::cmp::Ordering::Equal,
            });
            for (summary, o) in &rows {
                match o {
                    Outcome::Measured { assembly_s, lcp_s, total_s, pivots, residual, rss_mib, size } => {
                        println!("| {k} | {size} | {summary} | {assembly_s:.4} | {lcp_s:.4} | {total_s:.4} | {pivots} | {residual:.1e} | {rss_mib:.1} |")
                    }
                    Outcome::Failed(why) => println!("| {k} | — | {summary} | — | — | — | — | {why} | — |"),
                }
            }
            if rows.len() > 1 {
                let mut t: Vec<f64> = rows.iter().filter_map(|(_, o)| if let Outcome::Measured { total_s, .. } = o { Some(*total_s) } else { None }).collect();
                t.sort_by(f64::total_cmp);
                let failed = rows.len() - t.len();
                if let (Some(lo), Some(hi)) = (t.first(), t.last()) {
                    println!(
                        "| {k} | | spread of {} members: worst {hi:.4} s, median {:.4} s, best {lo:.4} s; {failed} failed | | | | | | |",
                        rows.len(),
                        t[t.len() / 2]
                    );
                }
            }
        }
    }
    Ok(())
}
