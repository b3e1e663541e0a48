//! Siconos' lexicographic Lemke (Debian's python3-siconos, in the system Python) on the study's
//! own LCPs, so that the peer sits on the same error–time axes: the LCP of a case at k is
//! exported in Siconos' `.dat` format and solved by `validation/peers/siconos_worker.py` (embedded
//! here, run in a child process, only the `lcp_lexicolemke` call timed); when Siconos' z equals
//! ours, its orbit is ours and so is its error, and its wall time is its Lemke + our assembly and
//! recovery. No network: when Siconos is not importable the peers are left out, with the reason.
use super::Case;
use super::accuracy::{Kind, Row};
use crate::lcp::{LcpMatrix, write_dat};
use crate::periodic::{LcpMethod, PeriodFft};
use crate::time::{Pairing, Scheme};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const WORKER: &str = include_str!("../../validation/peers/siconos_worker.py");

/// Where and how large.
#[derive(Clone, Debug)]
pub struct PeerSettings {
    /// k of the LCPs given to Siconos (dense: its Lemke is O(N³)).
    pub steps: Vec<usize>,
    /// The interpreter that has `siconos.numerics`.
    pub python: String,
    /// Certification tolerance (ours and the worker's check).
    pub tolerance: f64,
    /// A child running longer is stopped and its row marked failed.
    pub timeout_s: f64,
}

impl Default for PeerSettings {
    fn default() -> Self {
        PeerSettings { steps: vec![256, 512, 1024], python: "/usr/bin/python3".into(), tolerance: 1e-10, timeout_s: 600.0 }
    }
}

/// Siconos' z may differ from ours by this much (relative, ∞-norm) and still give our orbit.
const SAME_Z: f64 = 1e-8;

/// The scheme and pairing given to Siconos: cds with the pairing that converges.
fn choice(case: Case) -> (Scheme, Pairing) {
    match case {
        Case::Rigid | Case::Impacting => (Scheme::Cds, Pairing::Forward),
        _ => (Scheme::Cds, Pairing::Same),
    }
}

/// Siconos on every contact case at every k; `Err` with the reason when Siconos cannot run at all.
pub fn run(ps: &PeerSettings, cases: &[Case], ours: &[Row], progress: &mut dyn FnMut(&Row)) -> Result<Vec<Row>, String> {
    let probe = Command::new(&ps.python).args(["-c", "import numpy, siconos.numerics"]).output();
    match probe {
        Ok(o) if o.status.success() => {}
        Ok(o) => {
            let err = String::from_utf8_lossy(&o.stderr);
            return Err(format!(
                "not run: `{} -c 'import siconos.numerics'` failed ({}); install Debian's python3-siconos (validation/peers/README.md)",
                ps.python,
                err.lines().last().unwrap_or("no message")
            ));
        }
        Err(e) => return Err(format!("not run: cannot start {}: {e}", ps.python)),
    }
    let dir = std::env::temp_dir().join(format!("pc-study-peers-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| format!("not run: {}: {e}", dir.display()))?;
    let worker = dir.join("siconos_worker.py");
    std::fs::write(&worker, WORKER).map_err(|e| format!("not run: {}: {e}", worker.display()))?;
    let mut rows = Vec::new();
    for &case in cases.iter().filter(|c| c.has_contact()) {
        let (scheme, pairing) = choice(case);
        let label = super::method_label(scheme, Some(pairing));
        for &k in &ps.steps {
            let mut row = Row::new(case, label.clone(), Kind::Siconos, k, true);
            let base = ours.iter().find(|r| r.kind == Kind::Periodic && r.case == case && r.method == label && r.steps == k && r.ok());
            match point(ps, &dir, &worker, case, scheme, pairing, k) {
                Err(why) => row.status = format!("failed: {why}"),
                Ok(p) => {
                    row.t_lcp = Some(p.time_s);
                    row.pivots = Some(p.pivots);
                    row.lcp_size = k;
                    if !p.solved {
                        row.status = format!("failed: Siconos did not solve it (info {}, residual {:.1e})", p.info, p.residual);
                    } else if p.difference > SAME_Z {
                        row.status = format!("failed: Siconos' z differs from ours by {:.1e} (another solution?)", p.difference);
                    } else {
                        row.status = "ok".into();
                        row.residual = Some(p.residual);
                        // Same z, same orbit: our error; our assembly and recovery around its Lemke.
                        row.error_x = base.and_then(|b| b.error_x);
                        row.t_assembly = base.and_then(|b| b.t_assembly);
                        row.t_recovery = base.and_then(|b| b.t_recovery);
                        row.t_total = base.and_then(|b| Some(p.time_s + b.t_assembly? + b.t_recovery?));
                        if row.error_x.is_none() {
                            row.status = format!("failed: no periodic row of ours at k = {k} to compare with");
                        }
                    }
                }
            }
            progress(&row);
            rows.push(row);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(rows)
}

struct Point {
    time_s: f64,
    info: i64,
    pivots: usize,
    solved: bool,
    residual: f64,
    difference: f64,
}

fn point(ps: &PeerSettings, dir: &Path, worker: &Path, case: Case, scheme: Scheme, pairing: Pairing, k: usize) -> Result<Point, String> {
    let problem = case.problem(scheme, Some(pairing), k, LcpMethod::Auto).map_err(|e| e.to_string())?;
    let fft = PeriodFft::new(k);
    let r = problem.solve_with(&fft, None).map_err(|e| e.to_string())?;
    let (a, q) = problem.assemble_lcp(&fft).map_err(|e| e.to_string())?;
    let stem = format!("{}-k{k}", case.name());
    let dat = dir.join(format!("{stem}.dat"));
    write_dat(&dat, &a as &dyn LcpMatrix, &q).map_err(|e| format!("{}: {e}", dat.display()))?;
    // z[j m + a] = force of contact a at sample j: the order of the exported LCP.
    let m = r.contacts.len();
    let z: Vec<f64> = (0..k * m).map(|i| r.contacts[i % m].force[i / m]).collect();
    let cand = dir.join(format!("{stem}-ours.json"));
    std::fs::write(&cand, serde_json::json!({ "ours": z }).to_string()).map_err(|e| format!("{}: {e}", cand.display()))?;
    let out = dir.join(format!("{stem}-out.json"));
    let mut child = Command::new(&ps.python)
        .arg(worker)
        .arg(&dat)
        .arg(format!("{:e}", ps.tolerance))
        .arg(&cand)
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", ps.python))?;
    let start = Instant::now();
    while child.try_wait().map_err(|e| e.to_string())?.is_none() {
        if start.elapsed() > Duration::from_secs_f64(ps.timeout_s) {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("timeout {} s", ps.timeout_s));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = child.wait_with_output().map_err(|e| e.to_string())?;
    let _ = std::fs::remove_file(&dat);
    if !o.status.success() {
        let err = String::from_utf8_lossy(&o.stderr);
        return Err(format!("the Siconos worker failed: {}", err.lines().last().unwrap_or("no message")));
    }
    let text = std::fs::read_to_string(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", out.display()))?;
    let f = |p: &str| v.pointer(p).and_then(serde_json::Value::as_f64).ok_or_else(|| format!("{}: no {p}", out.display()));
    Ok(Point {
        time_s: f("/siconos/time_s")?,
        info: f("/siconos/info")? as i64,
        pivots: f("/siconos/pivots")? as usize,
        solved: v.pointer("/siconos/solved").and_then(serde_json::Value::as_bool).unwrap_or(false),
        residual: f("/checks/siconos/residual_rel")?,
        difference: f("/differences/siconos-ours")?,
    })
}
