//! `study warmstart`: pivots and LCP time, cold against warm, for the rigid stop with sticking
//! (src/formulation.md §6.3, cds with forward pairing):
//! - a frequency sweep, each point warm-started from the active set of the previous one;
//! - a re-solve after a small frequency change, warm-started from the unperturbed solution.
//!
//! Warm starts go through [`PeriodicProblem::solve_with`]: lexicographic Lemke accepts the guess
//! only when its principal solve certifies as is (otherwise it runs cold); block pivoting starts
//! its exchanges from the guess.
use super::{RIGID_GAP, RIGID_OSC, sci};
use crate::Error;
use crate::exact::Oscillator;
use crate::model::Compliance;
use crate::periodic::{LcpMethod, OutputSelection, PeriodFft, PeriodicProblem, SolverSettings};
use crate::response::Response;
use crate::time::{Discretization, Pairing, Scheme};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug)]
pub struct WarmSettings {
    /// k of the LCPs.
    pub steps: Vec<usize>,
    pub methods: Vec<LcpMethod>,
    /// Sweep: ω from `sweep.0` to `sweep.1` in `sweep.2` points.
    pub sweep: (f64, f64, usize),
    /// Re-solve: relative frequency changes from ω = RIGID_OSC.omega.
    pub perturbations: Vec<f64>,
    /// Timing repeats per solve (the fastest is kept).
    pub repeats: usize,
}

impl WarmSettings {
    pub fn full() -> Self {
        WarmSettings {
            steps: vec![256, 1024, 4096],
            methods: vec![LcpMethod::Auto, LcpMethod::Lemke],
            sweep: (0.9, 1.1, 21),
            perturbations: vec![1e-4, 1e-3, 1e-2],
            repeats: 3,
        }
    }
    pub fn quick() -> Self {
        WarmSettings { steps: vec![128, 512], sweep: (0.95, 1.05, 5), perturbations: vec![1e-3], repeats: 1, ..Self::full() }
    }
}

#[derive(Clone, Debug)]
pub struct WarmRow {
    /// "sweep" or "resolve".
    pub kind: &'static str,
    pub k: usize,
    pub method: LcpMethod,
    pub omega: f64,
    /// Relative frequency change (re-solve) or step to the previous point (sweep).
    pub delta: f64,
    pub cold_pivots: usize,
    pub cold_lcp_s: f64,
    pub warm_pivots: usize,
    pub warm_lcp_s: f64,
    pub warm_start_used: bool,
    /// max |z_warm − z_cold| relative to max |z_cold| (both certified): the same solution.
    pub same_solution: f64,
    pub status: String,
}

pub struct WarmStudy {
    pub rows: Vec<WarmRow>,
    pub settings: WarmSettings,
}

fn problem(omega: f64, k: usize, method: LcpMethod) -> Result<PeriodicProblem, Error> {
    let osc = Oscillator { omega, ..RIGID_OSC };
    let model = osc.model(vec![Oscillator::stop(RIGID_GAP, Compliance::Rigid)]);
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    let solver = SolverSettings { method, parallel: false, ..SolverSettings::default() };
    PeriodicProblem::new(model, Discretization { scheme: Scheme::Cds, steps: k, pairing: Some(Pairing::Forward) }, outputs, solver).map_err(Error::from)
}

/// Fastest of `repeats` solves (the pivots are the same every time).
fn timed(p: &PeriodicProblem, fft: &PeriodFft, warm: Option<&[usize]>, repeats: usize) -> Result<Response, Error> {
    let mut best: Option<Response> = None;
    for _ in 0..repeats.max(1) {
        let r = p.solve_with(fft, warm).map_err(Error::from)?;
        if best.as_ref().is_none_or(|b| r.timing_s.lcp < b.timing_s.lcp) {
            best = Some(r);
        }
    }
    Ok(best.expect("one repeat"))
}

fn compare(kind: &'static str, k: usize, method: LcpMethod, omega: f64, delta: f64, cold: &Response, warm: &Response) -> WarmRow {
    let zc = &cold.contacts[0].force;
    let zw = &warm.contacts[0].force;
    let scale = zc.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    let diff = zc.iter().zip(zw).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale;
    WarmRow {
        kind,
        k,
        method,
        omega,
        delta,
        cold_pivots: cold.lcp.pivots,
        cold_lcp_s: cold.timing_s.lcp,
        warm_pivots: warm.lcp.pivots,
        warm_lcp_s: warm.timing_s.lcp,
        warm_start_used: warm.lcp.warm_start_used,
        same_solution: diff,
        status: "ok".into(),
    }
}

pub fn run(settings: &WarmSettings, progress: &mut dyn FnMut(&WarmRow)) -> Result<WarmStudy, Error> {
    let mut rows = Vec::new();
    let (lo, hi, n) = settings.sweep;
    let omegas: Vec<f64> = (0..n).map(|i| if n > 1 { lo + (hi - lo) * i as f64 / (n - 1) as f64 } else { lo }).collect();
    for &k in &settings.steps {
        let fft = PeriodFft::new(k);
        for &method in &settings.methods {
            // Sweep: the first point has no predecessor (cold only, warm = cold).
            let mut prev_active: Option<Vec<usize>> = None;
            for (i, &omega) in omegas.iter().enumerate() {
                let p = problem(omega, k, method)?;
                let cold = match timed(&p, &fft, None, settings.repeats) {
                    Ok(r) => r,
                    Err(e) => {
                        let row = WarmRow {
                            kind: "sweep",
                            k,
                            method,
                            omega,
                            delta: 0.0,
                            cold_pivots: 0,
                            cold_lcp_s: f64::NAN,
                            warm_pivots: 0,
                            warm_lcp_s: f64::NAN,
                            warm_start_used: false,
                            same_solution: f64::NAN,
                            status: format!("failed: {e}"),
                        };
                        progress(&row);
                        rows.push(row);
                        prev_active = None;
                        continue;
                    }
                };
                let warm = match &prev_active {
                    Some(a) => timed(&p, &fft, Some(a), settings.repeats)?,
                    None => cold.clone(),
                };
                if prev_active.is_some() {
                    let row = compare("sweep", k, method, omega, omega - omegas[i - 1], &cold, &warm);
                    progress(&row);
                    rows.push(row);
                }
                prev_active = Some(warm.active_set.clone());
            }
            // Re-solve after a small frequency change.
            let base = problem(RIGID_OSC.omega, k, method)?;
            let base_r = timed(&base, &fft, None, 1)?;
            for &d in &settings.perturbations {
                let omega = RIGID_OSC.omega * (1.0 + d);
                let p = problem(omega, k, method)?;
                let cold = timed(&p, &fft, None, settings.repeats)?;
                let warm = timed(&p, &fft, Some(&base_r.active_set), settings.repeats)?;
                let row = compare("resolve", k, method, omega, d, &cold, &warm);
                progress(&row);
                rows.push(row);
            }
        }
    }
    Ok(WarmStudy { rows, settings: settings.clone() })
}

impl WarmStudy {
    pub fn csv(&self) -> String {
        let mut s = String::from("kind,k,method,omega,delta,cold_pivots,cold_lcp_s,warm_pivots,warm_lcp_s,warm_start_used,solution_difference,status\n");
        for r in &self.rows {
            let _ = writeln!(
                s,
                "{},{},{},{:.6},{:.3e},{},{:.6e},{},{:.6e},{},{:.3e},\"{}\"",
                r.kind,
                r.k,
                r.method.name(),
                r.omega,
                r.delta,
                r.cold_pivots,
                r.cold_lcp_s,
                r.warm_pivots,
                r.warm_lcp_s,
                r.warm_start_used,
                r.same_solution,
                r.status.replace('"', "'")
            );
        }
        s
    }

    pub fn markdown(&self) -> String {
        let st = &self.settings;
        let mut s = String::new();
        let _ = writeln!(s, "# Warm starts (generated by `periodic-contact study warmstart`)\n");
        let _ = writeln!(
            s,
            "Rigid stop with sticking (src/formulation.md §6.3: m = 1, c = 0.1, k = 1, F = 1, g0 = 0.5), cds with forward pairing, one thread. \
             LCP time = `timing_s.lcp`, fastest of {} repeats. `auto` is lexicographic Lemke up to N = 256 and block pivoting above; \
             `lemke` is lexicographic Lemke at every size (its warm start is accepted only when the guessed active set is exactly right). \
             Pivots of block pivoting count its block exchanges plus the pivots of its finishing Lemke run; \
             a Lemke warm start that is accepted shows 0 pivots. Solution difference: max |z_warm − z_cold| / max |z_cold| \
             (both certified). The CSV also has the engine's `warm_start_used` flag.\n",
            st.repeats
        );
        let _ = writeln!(s, "## Frequency sweep ω = {} … {} ({} points), each point warm-started from the previous one\n", st.sweep.0, st.sweep.1, st.sweep.2);
        let _ = writeln!(
            s,
            "| k | method | points | pivots cold (total) | pivots warm (total) | LCP time cold [s] | LCP time warm [s] | time ratio cold/warm | max solution difference |"
        );
        let _ = writeln!(s, "|---:|---|---:|---:|---:|---:|---:|---:|---:|");
        for &k in &st.steps {
            for &m in &st.methods {
                let rs: Vec<&WarmRow> = self.rows.iter().filter(|r| r.kind == "sweep" && r.k == k && r.method == m && r.status == "ok").collect();
                if rs.is_empty() {
                    continue;
                }
                let (pc, pw) = (rs.iter().map(|r| r.cold_pivots).sum::<usize>(), rs.iter().map(|r| r.warm_pivots).sum::<usize>());
                let (tc, tw) = (rs.iter().map(|r| r.cold_lcp_s).sum::<f64>(), rs.iter().map(|r| r.warm_lcp_s).sum::<f64>());
                let diff = rs.iter().map(|r| r.same_solution).fold(0.0f64, f64::max);
                let _ = writeln!(s, "| {k} | {} | {} | {pc} | {pw} | {tc:.4} | {tw:.4} | {:.2} | {} |", m.name(), rs.len(), tc / tw, sci(Some(diff)));
            }
        }
        let failed: Vec<&WarmRow> = self.rows.iter().filter(|r| r.status != "ok").collect();
        for r in failed {
            let _ = writeln!(s, "\nFailed: k = {}, {}, ω = {:.4}: {}", r.k, r.method.name(), r.omega, r.status);
        }
        let _ = writeln!(s, "\n## Re-solve after a small frequency change from ω = {}\n", RIGID_OSC.omega);
        let _ =
            writeln!(s, "| k | method | Δω/ω | pivots cold | pivots warm | LCP time cold [s] | LCP time warm [s] | ratio cold/warm | solution difference |");
        let _ = writeln!(s, "|---:|---|---:|---:|---:|---:|---:|---:|---:|");
        for r in self.rows.iter().filter(|r| r.kind == "resolve") {
            let _ = writeln!(
                s,
                "| {} | {} | {:.0e} | {} | {} | {:.2e} | {:.2e} | {:.2} | {} |",
                r.k,
                r.method.name(),
                r.delta,
                r.cold_pivots,
                r.warm_pivots,
                r.cold_lcp_s,
                r.warm_lcp_s,
                r.cold_lcp_s / r.warm_lcp_s,
                sci(Some(r.same_solution))
            );
        }
        s
    }

    /// Pivots along the sweep, cold and warm, per k and method.
    #[cfg(feature = "plots")]
    pub fn plot(&self, path: &Path) -> Result<(), Error> {
        use crate::plot::{Chart, Scale, Series, line_chart};
        let mut series = Vec::new();
        for &k in &self.settings.steps {
            for &m in &self.settings.methods {
                let rs: Vec<&WarmRow> = self.rows.iter().filter(|r| r.kind == "sweep" && r.k == k && r.method == m && r.status == "ok").collect();
                if rs.is_empty() {
                    continue;
                }
                series.push(Series {
                    label: format!("k = {k}, {}, cold", m.name()),
                    points: rs.iter().map(|r| (r.omega, r.cold_lcp_s)).collect(),
                    markers: false,
                });
                series.push(Series {
                    label: format!("k = {k}, {}, warm", m.name()),
                    points: rs.iter().map(|r| (r.omega, r.warm_lcp_s)).collect(),
                    markers: true,
                });
            }
        }
        let chart = Chart {
            title: "Rigid stop sweep: LCP time per point, cold vs warm",
            x_label: "ω [rad/s]",
            y_label: "LCP time [s]",
            x_scale: Scale::Linear,
            y_scale: Scale::Log,
        };
        line_chart(path, &chart, &series, 1100, 750).map_err(Error::from)
    }

    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, Error> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(format!("{}: cannot create: {e}", dir.display())))?;
        let mut out = Vec::new();
        for (name, text) in [("warmstart.csv", self.csv()), ("warmstart.md", self.markdown())] {
            let p = dir.join(name);
            std::fs::write(&p, text).map_err(|e| Error::io(format!("{}: cannot write: {e}", p.display())))?;
            out.push(p);
        }
        #[cfg(feature = "plots")]
        {
            let p = dir.join("warmstart.png");
            self.plot(&p)?;
            out.push(p);
        }
        Ok(out)
    }
}
