//! Are the error estimates honest on a family, not just on a favourite case? For random members
//! of each exact family ([`super::families`]: rigid stop with sticking, with pure impacts,
//! compliant stop) and every scheme that converges there (default pairing), at each k: the
//! ratio of the estimate (`analysis::accuracy`, Richardson from k/2) to the true error against
//! the member's exact orbit (`exact`), reported worst first with the spread. To diagnose a ratio
//! far from 1, the true error at k/2 is measured too: the observed order between k/2 and k
//! against the order the estimate assumes.
use super::families::{Family, Member};
use crate::analysis::accuracy;
use crate::exact::{CompliantStopOrbit, Oscillator, RigidRegime, RigidStopOrbit};
use crate::model::Compliance;
use crate::periodic::{OutputSelection, PeriodicProblem, SolverSettings};
use crate::time::{Discretization, Scheme};
use std::fmt::Write as _;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct HonestySettings {
    pub families: Vec<Family>,
    /// Random members per family besides the nominal one (draw 0).
    pub draws: usize,
    pub seed: u64,
    pub steps: Vec<usize>,
}

impl HonestySettings {
    /// 16 random members + the nominal one per family, k = 256, 512, 1024, seed 1.
    pub fn full() -> Self {
        HonestySettings { families: Family::ALL.to_vec(), draws: 16, seed: 1, steps: vec![256, 512, 1024] }
    }
    /// 2 random members, k = 256, 512.
    pub fn quick() -> Self {
        HonestySettings { draws: 2, steps: vec![256, 512], ..Self::full() }
    }
}

/// One member, scheme and k.
#[derive(Clone, Debug)]
pub struct Point {
    pub family: Family,
    pub draw: usize,
    pub member: Member,
    /// "cds/forward".
    pub method: String,
    pub steps: usize,
    /// Relative to the exact peak-to-peak amplitude.
    pub estimate: Option<f64>,
    pub error: Option<f64>,
    /// True error at k/2.
    pub error_half: Option<f64>,
    /// The order the estimate assumes.
    pub order: Option<f64>,
    /// "ok", or why the point has no ratio.
    pub status: String,
}

impl Point {
    pub fn ratio(&self) -> Option<f64> {
        match (self.estimate, self.error) {
            (Some(e), Some(t)) if t > 0.0 => Some(e / t),
            _ => None,
        }
    }
    /// log2(e_{k/2} / e_k).
    pub fn observed_order(&self) -> Option<f64> {
        Some((self.error_half? / self.error?).log2())
    }
    fn badness(&self) -> f64 {
        self.ratio().map_or(f64::INFINITY, |r| r.log10().abs())
    }
}

pub struct HonestyStudy {
    pub points: Vec<Point>,
    pub settings: HonestySettings,
    pub elapsed_s: f64,
}

/// An exact orbit as x(t), and its peak-to-peak amplitude.
type Exact = (Box<dyn Fn(f64) -> f64>, f64);

/// The member's exact orbit, or why there is none (a member outside its family's regime is
/// reported, not measured).
fn exact(family: Family, m: &Member) -> Result<Exact, String> {
    match m.contact_stiffness {
        Some(kc) => {
            let o = CompliantStopOrbit::solve(&m.oscillator, kc, m.gap, None).map_err(|e| format!("no exact orbit: {e}"))?;
            let ptp = o.peak_to_peak();
            Ok((Box::new(move |t| o.eval(t).0), ptp))
        }
        None => {
            let o = RigidStopOrbit::solve(&m.oscillator, m.gap).map_err(|e| format!("no exact orbit: {e}"))?;
            let want = if family == Family::RigidStick { RigidRegime::Sticking } else { RigidRegime::Impacting };
            if o.regime() != want {
                return Err(format!("the exact orbit is {:?}, not {:?}", o.regime(), want));
            }
            let ptp = o.peak_to_peak();
            Ok((Box::new(move |t| o.eval(t).0), ptp))
        }
    }
}

fn schemes(family: Family) -> Vec<Scheme> {
    match family {
        Family::Compliant => Scheme::ALL.to_vec(),
        _ => vec![Scheme::Bds1, Scheme::Cds, Scheme::Galerkin],
    }
}

fn problem(m: &Member, scheme: Scheme, k: usize) -> Result<PeriodicProblem, String> {
    let compliance = m.contact_stiffness.map_or(Compliance::Rigid, |stiffness| Compliance::Compliant { stiffness });
    let model = m.oscillator.model(vec![Oscillator::stop(m.gap, compliance)]);
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    let solver = SolverSettings { parallel: false, ..SolverSettings::default() };
    PeriodicProblem::new(model, Discretization { scheme, steps: k, pairing: None }, outputs, solver).map_err(|e| e.to_string())
}

/// Runs every member, scheme and k; `log` receives one line per point.
pub fn run(s: &HonestySettings, log: &mut dyn FnMut(String)) -> HonestyStudy {
    let start = Instant::now();
    let mut points = Vec::new();
    for &family in &s.families {
        for draw in 0..=s.draws {
            let member = family.draw(draw, s.seed);
            let reference = exact(family, &member);
            for scheme in schemes(family) {
                for &k in &s.steps {
                    let mut p = Point {
                        family,
                        draw,
                        member,
                        method: scheme.to_string(),
                        steps: k,
                        estimate: None,
                        error: None,
                        error_half: None,
                        order: None,
                        status: "ok".into(),
                    };
                    match &reference {
                        Err(why) => p.status = why.clone(),
                        Ok((x, ptp)) => measure(&mut p, scheme, x, *ptp),
                    }
                    log(format!(
                        "estimate {:<12} draw {:>2} {:<16} k {:>5}  ratio {}  {}",
                        family.name(),
                        draw,
                        p.method,
                        k,
                        p.ratio().map_or("—".into(), |r| format!("{r:.3}")),
                        if p.status == "ok" { "" } else { &p.status }
                    ));
                    points.push(p);
                }
            }
        }
    }
    HonestyStudy { points, settings: s.clone(), elapsed_s: start.elapsed().as_secs_f64() }
}

fn measure(p: &mut Point, scheme: Scheme, x: &dyn Fn(f64) -> f64, ptp: f64) {
    let error = |pr: &PeriodicProblem| -> Result<(f64, crate::response::Response), String> {
        let r = pr.solve().map_err(|e| e.to_string())?;
        let e = r.time.iter().zip(&r.displacement["0"]).map(|(&t, &v)| (v - x(t)).abs()).fold(0.0, f64::max);
        Ok((e / ptp, r))
    };
    let mut run = || -> Result<(), String> {
        let pr = problem(&p.member, scheme, p.steps)?;
        p.method = format!("{scheme}/{}", pr.pairing_at(0));
        let (e, r) = error(&pr)?;
        p.error = Some(e);
        p.order = accuracy::expected_order(&pr, &r).0;
        let a = accuracy::estimate(&pr, &r);
        p.estimate = a.estimate.map(|v| v / ptp);
        if a.estimate.is_none() {
            return Err(a.method);
        }
        p.error_half = Some(error(&problem(&p.member, scheme, p.steps / 2)?)?.0);
        Ok(())
    };
    if let Err(why) = run() {
        p.status = why;
    }
}

impl HonestyStudy {
    pub fn csv(&self) -> String {
        let mut s =
            String::from("family,draw,member,method,steps,estimate_rel_ptp,error_rel_ptp,ratio,error_half_rel_ptp,observed_order,assumed_order,status\n");
        let e = |v: Option<f64>| v.map(|v| format!("{v:.6e}")).unwrap_or_default();
        for p in &self.points {
            let _ = writeln!(
                s,
                "{},{},\"{}\",{},{},{},{},{},{},{},{},\"{}\"",
                p.family.name(),
                p.draw,
                p.member.summary(),
                p.method,
                p.steps,
                e(p.estimate),
                e(p.error),
                e(p.ratio()),
                e(p.error_half),
                e(p.observed_order()),
                e(p.order),
                p.status.replace('"', "'")
            );
        }
        s
    }

    /// The points with a ratio outside [0.1, 10] or none, worst first.
    pub fn outliers(&self) -> Vec<&Point> {
        let mut v: Vec<&Point> = self.points.iter().filter(|p| p.ratio().is_none_or(|r| !(0.1..=10.0).contains(&r))).collect();
        v.sort_by(|a, b| b.badness().total_cmp(&a.badness()));
        v
    }

    pub fn markdown(&self) -> String {
        let st = &self.settings;
        let mut s = String::new();
        let _ = writeln!(s, "## Estimate honesty on families (estimate / true error, worst first)\n");
        let _ = writeln!(
            s,
            "Families of `bench` (`study::families`): {}; the nominal member and {} random members each (seed {}), k = {:?}, every scheme \
             that converges there with its default pairing. Ratio = Richardson estimate from k/2 / true error against the member's exact orbit; \
             the observed order is log2(e(k/2) / e(k)) of the true errors. {} points in {:.1} s.\n",
            st.families.iter().map(|f| f.name()).collect::<Vec<_>>().join(", "),
            st.draws,
            st.seed,
            st.steps,
            self.points.len(),
            self.elapsed_s
        );
        let _ = writeln!(
            s,
            "| family | method | k | members | worst ratio (draw) | min | median | max | outside [0.1, 10] | observed order: min … max (assumed) |\n|---|---|---:|---:|---|---:|---:|---:|---:|---|"
        );
        let mut groups: Vec<(Family, String, usize, Vec<&Point>)> = Vec::new();
        for p in &self.points {
            match groups.iter_mut().find(|g| g.0 == p.family && g.1 == p.method && g.2 == p.steps) {
                Some(g) => g.3.push(p),
                None => groups.push((p.family, p.method.clone(), p.steps, vec![p])),
            }
        }
        let worst = |g: &[&Point]| g.iter().map(|p| p.badness()).fold(0.0, f64::max);
        groups.sort_by(|a, b| worst(&b.3).total_cmp(&worst(&a.3)));
        for (family, method, k, g) in &groups {
            let mut r: Vec<f64> = g.iter().filter_map(|p| p.ratio()).collect();
            r.sort_by(f64::total_cmp);
            let w = g.iter().max_by(|a, b| a.badness().total_cmp(&b.badness())).unwrap();
            let out = g.len() - r.iter().filter(|r| (0.1..=10.0).contains(*r)).count();
            let obs: Vec<f64> = g.iter().filter_map(|p| p.observed_order()).collect();
            let (lo, hi) = obs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
            let f = |v: Option<&f64>| v.map_or("—".into(), |v| format!("{v:.3}"));
            let _ = writeln!(
                s,
                "| {} | {method} | {k} | {} | {} ({}) | {} | {} | {} | {out} | {} ({}) |",
                family.name(),
                g.len(),
                w.ratio().map_or_else(|| "none".into(), |v| format!("{v:.3}")),
                w.draw,
                f(r.first()),
                f(r.get(r.len() / 2)),
                f(r.last()),
                if obs.is_empty() { "—".into() } else { format!("{lo:.2} … {hi:.2}") },
                w.order.map_or("—".into(), |o| format!("{o}"))
            );
        }
        let out = self.outliers();
        let _ = writeln!(s, "\n{} of {} points outside [0.1, 10] or without a ratio.", out.len(), self.points.len());
        if !out.is_empty() {
            let _ = writeln!(
                s,
                "\n| family | draw (member) | method | k | ratio | error | error at k/2 | observed order (assumed) | status |\n|---|---|---|---:|---:|---:|---:|---|---|"
            );
            let e = |v: Option<f64>| v.map_or("—".into(), |v| format!("{v:.2e}"));
            for p in out.iter().take(20) {
                let _ = writeln!(
                    s,
                    "| {} | {} ({}) | {} | {} | {} | {} | {} | {} ({}) | {} |",
                    p.family.name(),
                    p.draw,
                    p.member.summary(),
                    p.method,
                    p.steps,
                    p.ratio().map_or("—".into(), |r| format!("{r:.3}")),
                    e(p.error),
                    e(p.error_half),
                    p.observed_order().map_or("—".into(), |o| format!("{o:.2}")),
                    p.order.map_or("—".into(), |o| format!("{o}")),
                    p.status.replace('|', "/")
                );
            }
        }
        s
    }
}
