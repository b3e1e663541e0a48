//! `bench`: assembly and LCP time of the rigid 1-DOF stop with cds, per k, with peak memory.
//! Each k runs in a child process of its own so that its peak resident size is its own.
use crate::Failure;
use periodic_contact::scene::Scene;
use std::process::Command;

/// Peak resident set size of this process [MiB] (Linux VmHWM), if known.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// One measurement, printed as one tab-separated line for the parent.
pub fn run_single(steps: usize, repeats: usize, method: &str) -> Result<(), Failure> {
    let text = crate::defaults::DEFAULT_SCENE
        .replace("steps = 256", &format!("steps = {steps}"))
        .replace("[output]", &format!("[solver]\nmethod = \"{method}\"\n\n[output]"));
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
        "{}\t{:.6}\t{:.6}\t{:.6}\t{}\t{:.3e}\t{:.1}",
        steps,
        r.timing_s.assembly,
        r.timing_s.lcp,
        r.timing_s.total,
        r.lcp.pivots,
        r.lcp.residual,
        peak_rss_mib().unwrap_or(f64::NAN)
    );
    Ok(())
}

pub fn run(steps: &[usize], repeats: usize, method: &str) -> Result<(), Failure> {
    let exe = std::env::current_exe().map_err(|e| Failure::solver(e.to_string()))?;
    println!("rigid 1-DOF stop (fmu/scenes/rigid-stop.toml), cds, forward pairing, solver.method = {method}, one core; best of {repeats}");
    println!("| k = LCP size | assembly [s] | LCP [s] | total [s] | pivots | residual | peak RSS [MiB] |");
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for &k in steps {
        let out = Command::new(&exe)
            .args(["bench", "--single", &k.to_string(), "--repeats", &repeats.to_string(), "--method", method])
            .env("RAYON_NUM_THREADS", "1")
            .output()
            .map_err(|e| Failure::solver(format!("cannot run the benchmark child: {e}")))?;
        if !out.status.success() {
            return Err(Failure::solver(format!("k = {k}: {}", String::from_utf8_lossy(&out.stderr).trim())));
        }
        let line = String::from_utf8_lossy(&out.stdout);
        let f: Vec<&str> = line.trim().split('\t').collect();
        println!("| {} | {} | {} | {} | {} | {} | {} |", f[0], f[1], f[2], f[3], f[4], f[5], f[6]);
    }
    Ok(())
}
