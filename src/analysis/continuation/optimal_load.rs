//! The optimal-normal-load curve (issue 25): for each normal load N over a range, the peak over
//! the excitation frequency of the first displacement output's amplitude, and the load whose peak
//! is least. The classic design curve of friction dampers (e.g. Griffin, J. Eng. Power 102 (1980)
//! 329–333): free sliding at N = 0 and the stuck system's resonance at large N both peak high,
//! friction damps most in between.
//!
//! Each peak: the amplitude on an even grid of `GRID` frequencies over [A, B], the largest
//! refined by golden section between its neighbours. Each amplitude: the friction LCP's certified
//! solve, and with `polish` the stick–slip orbit's exact amplitude
//! ([`crate::analysis::polish::friction`]) where it fits, else the LCP's samples (the point says
//! which). The least peak over N: golden section between the sampled least's neighbours. A peak
//! at an end of [A, B] (the range misses the resonance) is reported as such.
use super::{Parameter, amplitudes};
use crate::analysis::polish;
use crate::error::Error;
use crate::periodic::{PeriodicProblem, PeriodicSolver};

/// Frequencies sampled over [A, B] before the golden section refines the largest.
const GRID: usize = 24;
/// The frequency search stops when its bracket is this narrow, relative to B − A.
const PEAK_TOLERANCE: f64 = 1e-6;
/// The load search stops when its bracket is this narrow, relative to |to − from|.
const LOAD_TOLERANCE: f64 = 1e-4;

/// The peak over frequency at one normal load.
#[derive(Clone, Debug)]
pub struct LoadPeak {
    pub normal_force: f64,
    /// Where the peak lies [rad/s].
    pub frequency: f64,
    /// Each displacement output's amplitude at that frequency (the first's is the peak).
    pub amplitude: Vec<f64>,
    /// Every amplitude of this search came from the polished (exact) orbit.
    pub polished: bool,
    /// The peak sits at an end of [A, B].
    pub at_end: bool,
}

/// The curve at evenly spaced loads and its least peak.
#[derive(Clone, Debug)]
pub struct LoadCurve {
    pub points: Vec<LoadPeak>,
    /// The least peak, refined by golden section when interior; else the least sampled point.
    pub optimum: LoadPeak,
    pub optimum_interior: bool,
    /// LCP solves in all.
    pub solves: usize,
}

/// Golden section for the largest (`sign` = 1) or least (−1) of f on [a, b], to `tol`: the
/// abscissa and f's value and payload there.
pub(super) fn golden<T>(mut f: impl FnMut(f64) -> Result<(f64, T), Error>, mut a: f64, mut b: f64, tol: f64, sign: f64) -> Result<(f64, f64, T), Error> {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c)?, f(d)?);
    while (b - a).abs() > tol {
        if sign * fc.0 > sign * fd.0 {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = f(c)?;
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = f(d)?;
        }
    }
    Ok(if sign * fc.0 > sign * fd.0 { (c, fc.0, fc.1) } else { (d, fd.0, fd.1) })
}

struct Search<'a> {
    base: &'a PeriodicProblem,
    solver: PeriodicSolver,
    range: (f64, f64),
    polish: bool,
    solves: usize,
}

impl Search<'_> {
    /// The output amplitudes at load `n` and frequency `w`, and whether they are the polished orbit's.
    fn at(&mut self, n: f64, w: f64) -> Result<(Vec<f64>, bool), Error> {
        let mut p = self.base.clone();
        Parameter::NormalForce.apply(&mut p, n)?;
        Parameter::Frequency.apply(&mut p, w)?;
        self.solver.update_problem(p);
        let r = self.solver.solve().map_err(|e| Error::from(e).context(format!("the friction orbit at normal_force = {n}, frequency = {w}")))?;
        self.solves += 1;
        let problem = self.solver.problem();
        if self.polish
            && let Ok(orbit) = polish::friction::polish(problem, &r)
        {
            return Ok((problem.outputs().displacement.iter().map(|&d| orbit.amplitude(d)).collect(), true));
        }
        Ok((amplitudes(problem, &r), false))
    }

    /// The peak over [A, B] of the first output's amplitude at load `n`.
    fn peak(&mut self, n: f64) -> Result<LoadPeak, Error> {
        let (a, b) = self.range;
        let h = (b - a) / (GRID - 1) as f64;
        let mut grid = Vec::with_capacity(GRID);
        for i in 0..GRID {
            let w = if i + 1 == GRID { b } else { a + h * i as f64 };
            grid.push((w, self.at(n, w)?));
        }
        let mut polished = grid.iter().all(|g| g.1.1);
        let i = (0..GRID).max_by(|&x, &y| grid[x].1.0[0].total_cmp(&grid[y].1.0[0])).unwrap_or(0);
        let (w, amps) = if i == 0 || i + 1 == GRID {
            (grid[i].0, grid[i].1.0.clone())
        } else {
            let f = |w: f64| self.at(n, w).map(|(amps, pol)| (amps[0], (amps, pol)));
            let (w, _, (amps, pol)) = golden(f, grid[i - 1].0, grid[i + 1].0, PEAK_TOLERANCE * (b - a), 1.0)?;
            polished &= pol;
            (w, amps)
        };
        Ok(LoadPeak { normal_force: n, frequency: w, amplitude: amps, polished, at_end: i == 0 || i + 1 == GRID })
    }
}

/// The peak over the frequencies `range` of the first displacement output's amplitude at the
/// normal load `n` (one point of the curve).
pub fn peak_at(problem: &PeriodicProblem, n: f64, range: (f64, f64), polish: bool) -> Result<LoadPeak, Error> {
    Search { base: problem, solver: PeriodicSolver::new(problem.clone()), range, polish, solves: 0 }.peak(n)
}

/// The optimal-normal-load curve of `problem` for N from `from` to `to` (1/`max_step`
/// intervals, at most `max_points` points), peaks over frequencies in `range`.
pub fn optimal_load(
    problem: &PeriodicProblem,
    from: f64,
    to: f64,
    range: (f64, f64),
    polish: bool,
    settings: &super::ContinuationSettings,
    on_point: &dyn Fn(f64),
) -> Result<LoadCurve, Error> {
    if problem.model().frictions.is_empty() || !problem.model().contacts.is_empty() {
        return Err(Error::input(
            "--peak-over: the optimal-normal-load curve needs [[friction]] contacts under a normal load and no [[contact]]; add one or remove the contacts",
        ));
    }
    if !(range.0 > 0.0 && range.1 > range.0 && range.1.is_finite()) {
        return Err(Error::input(format!("--peak-over frequency:A:B: is {}:{}, needs 0 < A < B (rad/s)", range.0, range.1)));
    }
    let mut search = Search { base: problem, solver: PeriodicSolver::new(problem.clone()), range, polish, solves: 0 };
    let intervals = ((1.0 / settings.max_step).ceil() as usize).clamp(1, settings.max_points.max(2) - 1);
    let mut points = Vec::with_capacity(intervals + 1);
    for i in 0..=intervals {
        let n = if i == intervals { to } else { from + (to - from) * i as f64 / intervals as f64 };
        points.push(search.peak(n)?);
        on_point(n);
    }
    let least = (0..points.len()).min_by(|&x, &y| points[x].amplitude[0].total_cmp(&points[y].amplitude[0])).unwrap_or(0);
    let interior = least > 0 && least + 1 < points.len();
    let optimum = if interior {
        let (a, b) = (points[least - 1].normal_force, points[least + 1].normal_force);
        let f = |n: f64| search.peak(n).map(|p| (p.amplitude[0], p));
        golden(f, a, b, LOAD_TOLERANCE * (to - from).abs(), -1.0)?.2
    } else {
        points[least].clone()
    };
    Ok(LoadCurve { points, optimum, optimum_interior: interior, solves: search.solves })
}

/// The curve as CSV: load, peak frequency, each output's amplitude there, polished, at_end.
pub fn to_csv(curve: &LoadCurve, problem: &PeriodicProblem, labels: &crate::model::Labels) -> String {
    use crate::model::Quantity;
    let mut s = format!("normal_force {},peak_frequency {}", labels.unit(Quantity::Force), labels.unit(Quantity::Frequency));
    for d in &problem.outputs().displacement {
        s += &format!(",amplitude_{d} {}", labels.unit(Quantity::Length));
    }
    s += ",polished,at_range_end\n";
    for p in &curve.points {
        s += &format!("{:e},{:e}", p.normal_force, p.frequency);
        p.amplitude.iter().for_each(|a| s += &format!(",{a:e}"));
        s += &format!(",{},{}\n", p.polished, p.at_end);
    }
    s
}

/// Peak amplitude against the normal load, the optimum marked.
pub fn plot(path: &std::path::Path, curve: &LoadCurve, problem: &PeriodicProblem, labels: &crate::model::Labels, title: &str) -> Result<(), Error> {
    use crate::model::Quantity;
    use crate::plot::{Chart, Scale, Series, line_chart};
    let d = problem.outputs().displacement.first().copied().unwrap_or(0);
    let x_label = format!("normal load N of every friction contact {}", labels.unit(Quantity::Force));
    let y_label = format!("peak over frequency of the amplitude of {} {}", labels.dof(d), labels.unit(Quantity::Length));
    let chart = Chart { title, x_label: &x_label, y_label: &y_label, x_scale: Scale::Linear, y_scale: Scale::Linear };
    let o = &curve.optimum;
    let series = [
        Series { label: "peak amplitude".into(), points: curve.points.iter().map(|p| (p.normal_force, p.amplitude[0])).collect(), markers: true },
        Series {
            label: format!("least peak {:.6e} at N = {:.6e}", o.amplitude[0], o.normal_force),
            points: vec![(o.normal_force, o.amplitude[0])],
            markers: true,
        },
    ];
    line_chart(path, &chart, &series, 1000, 650).map_err(Error::from)
}
