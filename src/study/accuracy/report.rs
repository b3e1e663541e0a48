//! The study's CSV and markdown: the cheapest choice per tolerance (with the runner-up), the
//! estimates against the true errors, the peers, and one summary line per method.
use super::{AccuracyStudy, Kind, Row};
use crate::Error;
use crate::study::{Case, fitted_order, sci};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// True errors below this (relative to peak-to-peak) are round-off: no estimate is judged there.
pub const ROUND_OFF: f64 = 1e-12;

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map(|v| v.to_string()).unwrap_or_default()
}

fn opt_e(v: Option<f64>) -> String {
    v.map(|v| format!("{v:.6e}")).unwrap_or_default()
}

impl AccuracyStudy {
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "case,method,kind,steps,converges,status,error_x_rel_ptp,estimate_rel_ptp,error_impulse_rel,time_assembly_s,time_lcp_s,time_recovery_s,time_polish_s,time_total_s,time_estimate_s,lcp_size,pivots,residual,periods\n",
        );
        for r in &self.rows {
            let _ = writeln!(
                s,
                "{},{},{},{},{},\"{}\",{},{},{},{},{},{},{},{},{},{},{},{},{}",
                r.case.name(),
                r.method,
                r.kind.name(),
                r.steps,
                r.converges,
                r.status.replace('"', "'"),
                opt_e(r.error_x),
                opt_e(r.estimate),
                opt_e(r.error_impulse),
                opt_e(r.t_assembly),
                opt_e(r.t_lcp),
                opt_e(r.t_recovery),
                opt_e(r.t_polish),
                opt_e(r.t_total),
                opt_e(r.t_estimate),
                r.lcp_size,
                opt(r.pivots),
                opt_e(r.residual),
                opt(r.periods)
            );
        }
        s
    }

    pub(super) fn ok_rows(&self, case: Case) -> impl Iterator<Item = &Row> {
        self.rows.iter().filter(move |r| r.case == case && r.ok() && r.error_x.is_some() && r.t_total.is_some())
    }

    /// The reference's own error bound for `case` (relative to peak-to-peak; 0 for the exact orbits).
    pub fn uncertainty_of(&self, case: Case) -> f64 {
        self.uncertainty.get(case.name()).copied().unwrap_or(0.0)
    }

    /// The cheapest run reaching `target` (max error relative to the peak-to-peak amplitude,
    /// plus the reference's own error bound) among the rows of converging choices that pass
    /// `filter` (a choice that does not converge can be close at one k by chance; it is not a
    /// method one can pick for an accuracy).
    pub fn cheapest(&self, case: Case, target: f64, filter: impl Fn(&Row) -> bool) -> Option<&Row> {
        let u = self.uncertainty_of(case);
        self.ok_rows(case)
            .filter(|r| r.converges && filter(r) && r.error_x.unwrap() + u <= target)
            .min_by(|a, b| a.t_total.unwrap().total_cmp(&b.t_total.unwrap()))
    }

    /// Below this true error (relative to peak-to-peak) an estimate is not judged: round-off, or
    /// the reference's own error.
    pub fn judged_above(&self, case: Case) -> f64 {
        ROUND_OFF.max(10.0 * self.uncertainty_of(case))
    }

    /// The tolerances of the summary.
    pub const TARGETS: [f64; 9] = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10];

    /// The one table: per case and tolerance, the cheapest choice that reaches it and the
    /// cheapest other choice (the runner-up).
    pub fn cost_table(&self) -> String {
        let mut s = String::from("| case | error ≤ | cheapest | wall time [s] | runner-up | wall time [s] |\n|---|---:|---|---:|---|---:|\n");
        for &case in &self.settings.cases {
            let u = self.uncertainty_of(case);
            for target in Self::TARGETS {
                if target <= u {
                    let _ = writeln!(s, "| {} | {target:.0e} | not checkable: the reference's own error bound is {u:.1e} | | | |", case.name());
                    continue;
                }
                let name = |r: &Row| format!("{} (k = {})", r.choice(), r.steps);
                match self.cheapest(case, target, |_| true) {
                    None => {
                        let _ = writeln!(s, "| {} | {target:.0e} | not reached | | | |", case.name());
                    }
                    Some(best) => {
                        let second = self.cheapest(case, target, |r| r.choice() != best.choice());
                        let _ = writeln!(
                            s,
                            "| {} | {target:.0e} | {} | {} | {} | {} |",
                            case.name(),
                            name(best),
                            sci(best.t_total),
                            second.map_or("not reached".into(), name),
                            sci(second.and_then(|r| r.t_total))
                        );
                    }
                }
            }
        }
        s
    }

    /// Per case and kind: how far the estimates are from the true errors (ratio estimate / true).
    fn estimate_table(&self) -> String {
        let mut s = String::from(
            "| case | kind | points judged | worst ratio (method, k) | min ratio | median | max ratio | outside [0.1, 10] |\n|---|---|---:|---|---:|---:|---:|---:|\n",
        );
        for &case in &self.settings.cases {
            for kind in [Kind::Periodic, Kind::Polished] {
                let mut pts: Vec<(f64, &Row)> = self
                    .ok_rows(case)
                    .filter(|r| r.kind == kind && r.converges)
                    .filter_map(|r| r.estimate_ratio(self.judged_above(case)).map(|q| (q, r)))
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                let worst = pts.iter().max_by(|a, b| a.0.log10().abs().total_cmp(&b.0.log10().abs())).unwrap();
                let out = pts.iter().filter(|p| !(0.1..=10.0).contains(&p.0)).count();
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {:.3} ({}, k = {}) | {:.3} | {:.3} | {:.3} | {out} |",
                    case.name(),
                    kind.name(),
                    pts.len(),
                    worst.0,
                    worst.1.method,
                    worst.1.steps,
                    pts[0].0,
                    pts[pts.len() / 2].0,
                    pts[pts.len() - 1].0
                );
            }
        }
        s
    }

    pub fn markdown(&self) -> String {
        let s_ = &self.settings;
        let mut s = String::new();
        let _ = writeln!(s, "# What accuracy costs (generated by `periodic-contact study accuracy -o validation/study`)\n");
        let _ = writeln!(
            s,
            "Error: max over the samples (and DOFs) of |x_j − x_ref(t_j)| divided by the reference's peak-to-peak amplitude. References: the exact \
             orbits of `src/exact/` (src/formulation.md §6) and, for the 2-DOF chain (no closed form), explicit time marching at {n} and {n2} steps per period, \
             Richardson-extrapolated; its own error bound, the Richardson correction, is {unc}, and a chain run reaches a tolerance only when its \
             error plus that bound is below it. Wall time of one thread: periodic = assembly + LCP + recovery (`timing_s`); polished = that + the \
             event-fitted polish; marching = explicit central differences with forward-increment multipliers (`marching::march`) from rest until \
             the periodicity defect is below {mt:.0e}; Siconos = its `lcp_lexicolemke` call on the same LCP + our assembly and recovery. Fastest of up \
             to 5 repeats for runs under {rep} s. The times exclude the error estimate (its k/2 solve: `time_estimate_s` in the CSV). k = {k:?}; marcher \
             N = {mn:?}. Caps: a method stops growing k once its next run is predicted to take over {cap} s; choices that do not converge stop at \
             k = {nc}; sweep budget {b} s. Whole run {el:.0} s wall (references {rs:.1} s); load average at the start and the end: {l0} / {l1} (2 cores; \
             a load above 2 inflates the times).\n",
            n = crate::study::chain::MARCH_STEPS,
            n2 = 2 * crate::study::chain::MARCH_STEPS,
            unc = self.uncertainty.get("chain").map_or("not run".into(), |u| format!("{u:.1e} of peak-to-peak")),
            mt = s_.march_tolerance,
            rep = s_.min_timing_s,
            k = s_.steps,
            mn = if s_.march { s_.march_steps.clone() } else { vec![] },
            cap = s_.solve_cap_s,
            nc = s_.nonconverging_max_k,
            b = s_.budget_s,
            el = self.elapsed_s,
            rs = self.reference_s,
            l0 = self.load.0,
            l1 = self.load.1,
        );
        let _ = writeln!(s, "## The cheapest choice for a given accuracy\n");
        let _ = writeln!(
            s,
            "Among the choices that converge (src/formulation.md §3); a choice is a scheme/pairing with or without the polish, the marcher, or Siconos on \
             our LCP; the runner-up is the cheapest other choice.\n"
        );
        s.push_str(&self.cost_table());
        let _ = writeln!(s, "\n## Error estimates against the true error (this sweep)\n");
        let _ = writeln!(
            s,
            "Ratio estimate / true error of every converging point whose true error is above {ROUND_OFF:.0e} of peak-to-peak (below, both are \
             round-off) and, for the chain, above 10× its reference's error bound. Periodic: Richardson from a second solve at k/2 (`analysis::accuracy`); polished: the last Newton correction. \
             Worst = farthest from 1 in log.\n"
        );
        s.push_str(&self.estimate_table());
        if let Some(h) = &self.honesty {
            s.push('\n');
            s.push_str(&h.markdown());
        }
        let _ = writeln!(s, "\n## Peers\n");
        match &self.peers_note {
            Some(why) => {
                let _ = writeln!(s, "Siconos: {why}\n");
            }
            None => {
                let _ =
                    writeln!(s, "| case | method | k | Siconos Lemke [s] | ours: LCP [s] | Siconos / ours (LCP) | status |\n|---|---|---:|---:|---:|---:|---|");
                for r in self.rows.iter().filter(|r| r.kind == Kind::Siconos) {
                    let ours = self.rows.iter().find(|o| o.kind == Kind::Periodic && o.case == r.case && o.method == r.method && o.steps == r.steps);
                    let ratio = match (r.t_lcp, ours.and_then(|o| o.t_lcp)) {
                        (Some(a), Some(b)) if b > 0.0 => format!("{:.0}×", a / b),
                        _ => "—".into(),
                    };
                    let _ = writeln!(
                        s,
                        "| {} | {} | {} | {} | {} | {ratio} | {} |",
                        r.case.name(),
                        r.method,
                        r.steps,
                        sci(r.t_lcp),
                        sci(ours.and_then(|o| o.t_lcp)),
                        short(&r.status)
                    );
                }
                s.push('\n');
            }
        }
        let _ = writeln!(s, "## Per case and method\n");
        for &case in &s_.cases {
            let _ = writeln!(s, "### {}\n", case.title());
            let _ = writeln!(
                s,
                "| method | converges (src/formulation.md §3) | largest k run | error there | estimate there | polished error there | wall [s] there (LCP / + polish) | fitted order (k ≥ 128) | failed or skipped |"
            );
            let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---|---:|---|");
            let mut labels: Vec<String> = Vec::new();
            for r in self.rows.iter().filter(|r| r.case == case && matches!(r.kind, Kind::Periodic | Kind::Marching)) {
                if !labels.contains(&r.method) {
                    labels.push(r.method.clone());
                }
            }
            for label in labels {
                let rs: Vec<&Row> = self.rows.iter().filter(|r| r.case == case && r.method == label && r.kind != Kind::Siconos).collect();
                let base: Vec<&&Row> = rs.iter().filter(|r| r.ok() && r.kind != Kind::Polished).collect();
                let last = base.last();
                let pol = last.and_then(|l| rs.iter().find(|r| r.kind == Kind::Polished && r.steps == l.steps));
                let pts: Vec<(usize, f64)> = base.iter().filter(|r| r.steps >= 128).map(|r| (r.steps, r.error_x.unwrap())).collect();
                let bad: Vec<String> = rs.iter().filter(|r| !r.ok()).map(|r| format!("{} {}: {}", r.kind.name(), r.steps, short(&r.status))).collect();
                let wall = last.map(|r| match pol.and_then(|p| p.t_total) {
                    Some(tp) => format!("{} / {}", sci(r.t_total), sci(Some(tp))),
                    None => match r.periods {
                        Some(p) => format!("{} ({p} periods)", sci(r.t_total)),
                        None => sci(r.t_total),
                    },
                });
                let _ = writeln!(
                    s,
                    "| {label} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    if rs[0].converges { "yes" } else { "no" },
                    last.map(|r| r.steps.to_string()).unwrap_or_else(|| "—".into()),
                    sci(last.and_then(|r| r.error_x)),
                    sci(last.and_then(|r| r.estimate)),
                    sci(pol.and_then(|p| p.error_x)),
                    wall.unwrap_or_else(|| "—".into()),
                    fitted_order(&pts).map(|p| format!("{p:.2}")).unwrap_or_else(|| "—".into()),
                    bad.join("; ")
                );
            }
            let _ = writeln!(s);
        }
        if !self.exported.is_empty() {
            let _ = writeln!(s, "LCPs exported in Siconos `.dat` format: {}.\n", self.exported.len());
        }
        s
    }

    /// Writes accuracy.csv, estimate.csv, accuracy.md and (with the `plots` feature)
    /// accuracy.png into `dir`.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, Error> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(format!("{}: cannot create: {e}", dir.display())))?;
        let mut out = Vec::new();
        let mut files = vec![("accuracy.csv", self.csv()), ("accuracy.md", self.markdown())];
        if let Some(h) = &self.honesty {
            files.push(("estimate.csv", h.csv()));
        }
        for (name, text) in files {
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

pub(super) fn short(s: &str) -> String {
    let s = s.split(" (pivots").next().unwrap_or(s);
    let s: String = s.chars().take(90).collect();
    s.replace('|', "/")
}
