//! Long time integration of a chain with one stop, its events located on exact flows: between
//! events the motion is linear, y(t) = y_p(t) + e^{A(t − t0)} (y(t0) − y_p(t0)) (the harmonic
//! particular solution of (K − Ω²M + iΩC) X = f); an impact or a release is found by binary descent
//! on the flows over h/2^j (to h·2⁻⁵²); on a rigid stop impacts are plastic (e = 0) and the contact
//! sticks while its holding force is compressive (Leine & Nijmeijer, "Dynamics and Bifurcations of
//! Non-Smooth Mechanical Systems", §3.5); a compliant stop adds its stiffness while closed. No code of the crate is used (marcher, LCP, polish, continuation), so
//! it can check their orbits and stability labels: the period map's fixed point, its
//! finite-difference Jacobian's eigenvalues, and a long simulation started near the orbit.
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;
use periodic_contact::analysis::continuation::{BranchPoint, Source};

/// M x'' + C x' + K x = f cos Ωt − z e_c: rigid, x_c ≤ gap and z ≥ 0 (M diagonal: a plastic
/// impact stops DOF c alone); compliant, z = k_c max(x_c − gap, 0).
#[derive(Clone, Debug)]
pub struct StopChain {
    pub mass: Vec<f64>,
    pub stiffness: DMatrix<f64>,
    pub damping: DMatrix<f64>,
    pub force: Vec<f64>,
    pub omega: f64,
    pub dof: usize,
    pub gap: f64,
    /// k_c of a compliant stop; `None`: rigid.
    pub contact_stiffness: Option<f64>,
}

/// Flow steps per forcing period (events are located inside a step, so this only bounds the
/// bracket: two crossings of the stop within T/1024 are taken as none).
const STEPS: usize = 1024;

/// A linear phase: the DOFs that move (all, or all but the stuck one) and their exact flow.
struct Phase {
    dofs: Vec<usize>,
    a: DMatrix<f64>,
    harmonic: Vec<C>,
    fixed: Vec<f64>,
    /// e^{A h/2^j}, j = 0..=52.
    steps: Vec<DMatrix<f64>>,
}

impl Phase {
    /// The phase with the contact open, or closed (stuck on a rigid stop, pressed into a compliant one).
    fn new(s: &StopChain, closed: bool, h: f64) -> Phase {
        let stuck = closed && s.contact_stiffness.is_none();
        let pressed = if closed { s.contact_stiffness.unwrap_or(0.0) } else { 0.0 };
        let dofs: Vec<usize> = (0..s.mass.len()).filter(|&i| !(stuck && i == s.dof)).collect();
        let r = dofs.len();
        let kc = |i: usize, j: usize| s.stiffness[(i, j)] + if i == s.dof && j == s.dof { pressed } else { 0.0 };
        let (k, c) = (DMatrix::from_fn(r, r, |i, j| kc(dofs[i], dofs[j])), DMatrix::from_fn(r, r, |i, j| s.damping[(dofs[i], dofs[j])]));
        let mut a = DMatrix::zeros(2 * r, 2 * r);
        for i in 0..r {
            a[(i, r + i)] = 1.0;
            for j in 0..r {
                a[(r + i, j)] = -k[(i, j)] / s.mass[dofs[i]];
                a[(r + i, r + j)] = -c[(i, j)] / s.mass[dofs[i]];
            }
        }
        let w = s.omega;
        let dynamic = DMatrix::from_fn(r, r, |i, j| C::new(k[(i, j)] - if i == j { w * w * s.mass[dofs[i]] } else { 0.0 }, w * c[(i, j)]));
        let f = DVector::from_iterator(r, dofs.iter().map(|&i| C::new(s.force[i], 0.0)));
        let harmonic = if r == 0 { vec![] } else { dynamic.lu().solve(&f).expect("no resonance").iter().copied().collect() };
        // The stuck DOF held at the gap pulls on the others through K: K_r x0 = −K_rc gap; a
        // pressed compliant stop pushes by k_c (gap − x_c): (K + k_c e_c e_cᵀ) x0 = k_c gap e_c.
        let pull = DVector::from_iterator(
            r,
            dofs.iter().map(|&i| {
                if stuck {
                    -s.stiffness[(i, s.dof)] * s.gap
                } else if i == s.dof {
                    pressed * s.gap
                } else {
                    0.0
                }
            }),
        );
        let fixed = if r == 0 { vec![] } else { k.clone().lu().solve(&pull).expect("grounded").iter().copied().collect() };
        let steps = (0..=52).map(|j| if r == 0 { DMatrix::zeros(0, 0) } else { (&a * (h / 2f64.powi(j))).exp() }).collect();
        Phase { dofs, a, harmonic, fixed, steps }
    }

    /// The particular solution's [x; v] of the moving DOFs at t.
    fn particular(&self, w: f64, t: f64) -> DVector<f64> {
        let r = self.dofs.len();
        let e = C::new(0.0, w * t).exp();
        DVector::from_fn(2 * r, |i, _| if i < r { (self.harmonic[i] * e).re + self.fixed[i] } else { (C::new(0.0, w) * self.harmonic[i - r] * e).re })
    }

    /// The full state `y` at t carried to t + τ by the flow `e` (e^{Aτ}).
    fn flow(&self, w: f64, t: f64, y: &DVector<f64>, tau: f64, e: &DMatrix<f64>) -> DVector<f64> {
        let (n, r) = (y.len() / 2, self.dofs.len());
        let mut z = DVector::from_fn(2 * r, |i, _| if i < r { y[self.dofs[i]] } else { y[n + self.dofs[i - r]] });
        z -= self.particular(w, t);
        let z = e * z + self.particular(w, t + tau);
        let mut out = y.clone();
        for (i, &d) in self.dofs.iter().enumerate() {
            out[d] = z[i];
            out[n + d] = z[r + i];
        }
        out
    }
}

/// An event of the orbit: its time and whether the contact is closed after it.
#[derive(Clone, Copy, Debug)]
pub struct Event {
    pub time: f64,
    pub closed_after: bool,
}

/// What a march reports after each step and event: (t, y, the event).
pub type Seen<'a> = dyn FnMut(f64, &DVector<f64>, Option<Event>) + 'a;

/// A simulation: the flows of both phases at one Ω.
pub struct StopMarch {
    pub sys: StopChain,
    pub period: f64,
    h: f64,
    phases: [Phase; 2],
}

impl StopMarch {
    pub fn new(sys: &StopChain) -> StopMarch {
        let period = 2.0 * std::f64::consts::PI / sys.omega;
        let h = period / STEPS as f64;
        StopMarch { sys: sys.clone(), period, h, phases: [Phase::new(sys, false, h), Phase::new(sys, true, h)] }
    }

    fn n(&self) -> usize {
        self.sys.mass.len()
    }

    /// The compressive force that holds DOF c on the stop (x_c = gap, v_c = 0): its equation of
    /// motion with a_c = 0, z = f_c cos Ωt − (Kx)_c − (Cv)_c; and dz/dt.
    fn holding(&self, t: f64, y: &DVector<f64>) -> (f64, f64) {
        let (s, n) = (&self.sys, self.n());
        let (c, w) = (s.dof, s.omega);
        let accel = |i: usize| {
            if i == c {
                return 0.0;
            }
            let f = s.force[i] * (w * t).cos() - (0..n).map(|j| s.stiffness[(i, j)] * y[j] + s.damping[(i, j)] * y[n + j]).sum::<f64>();
            f / s.mass[i]
        };
        let z = s.force[c] * (w * t).cos() - (0..n).map(|j| s.stiffness[(c, j)] * y[j] + s.damping[(c, j)] * y[n + j]).sum::<f64>();
        let dz = -w * s.force[c] * (w * t).sin() - (0..n).map(|j| s.stiffness[(c, j)] * y[n + j] + s.damping[(c, j)] * accel(j)).sum::<f64>();
        (z, dz)
    }

    /// The event function of a phase (an event where it reaches 0 from below) and its rate: the
    /// penetration x_c − gap in flight, minus the holding force when stuck, the clearance when
    /// pressed into a compliant stop.
    fn event(&self, closed: bool, t: f64, y: &DVector<f64>) -> (f64, f64) {
        let (p, v) = (y[self.sys.dof] - self.sys.gap, y[self.n() + self.sys.dof]);
        match (closed, self.sys.contact_stiffness) {
            (false, _) => (p, v),
            (true, Some(_)) => (-p, -v),
            (true, None) => {
                let (z, dz) = self.holding(t, y);
                (-z, -dz)
            }
        }
    }

    /// The latest time in [t, t + span] (to h·2⁻⁵²) from which `keep` still holds going by flows of
    /// h/2^j from t (`keep` true at t): the root of a function that changes sign once there.
    fn descend(&self, closed: bool, t: f64, y: &DVector<f64>, span: f64, keep: impl Fn(f64, &DVector<f64>) -> bool) -> (f64, DVector<f64>) {
        let ph = &self.phases[usize::from(closed)];
        let (mut t1, mut y1) = (t, y.clone());
        for j in 1..=52 {
            let d = self.h / 2f64.powi(j);
            if t1 + d > t + span {
                continue;
            }
            let cand = ph.flow(self.sys.omega, t1, &y1, d, &ph.steps[j as usize]);
            if keep(t1 + d, &cand) {
                t1 += d;
                y1 = cand;
            }
        }
        (t1, y1)
    }

    /// The state at the stop after a plastic impact (or at a start on the stop): x_c = gap, v_c = 0,
    /// stuck when the holding force is compressive.
    fn impact(&self, t: f64, y: &mut DVector<f64>) -> bool {
        let (c, n) = (self.sys.dof, self.n());
        y[c] = self.sys.gap;
        y[n + c] = 0.0;
        self.holding(t, y).0 > 0.0
    }

    /// Whether the contact is closed at a start from `y` at t: on a rigid stop (within 1e-10 of the
    /// state's size), arriving or at rest, the start is taken as an impact; a compliant stop is
    /// closed when penetrated, or on its surface and moving in.
    pub fn starts_closed(&self, t: f64, y: &mut DVector<f64>) -> bool {
        let (c, n) = (self.sys.dof, self.n());
        let size = y.amax().max(self.sys.gap.abs());
        let on = (self.sys.gap - y[c]).abs() <= 1e-10 * size;
        match self.sys.contact_stiffness {
            None => (on || y[c] > self.sys.gap) && y[n + c] >= -1e-10 * size && self.impact(t, y),
            Some(_) => y[c] > self.sys.gap + 1e-10 * size || (on && y[n + c] > 0.0),
        }
    }

    /// Marches `y` (phase `closed`) from t to `until`, calling `seen(t, y, event)` after every step
    /// and event; returns the final state and phase.
    pub fn run(&self, mut t: f64, mut y: DVector<f64>, mut closed: bool, until: f64, seen: &mut Seen) -> (DVector<f64>, bool) {
        let w = self.sys.omega;
        // Events that make no progress in time (a release into a state that sticks again at once):
        // after a few, the step is taken as it is.
        let mut stalled = 0;
        while t < until {
            let tau = self.h.min(until - t);
            let ph = &self.phases[usize::from(closed)];
            let y1 = match (ph.dofs.is_empty(), tau == self.h) {
                (true, _) => y.clone(),
                (false, true) => ph.flow(w, t, &y, tau, &ph.steps[0]),
                (false, false) => ph.flow(w, t, &y, tau, &(&ph.a * tau).exp()),
            };
            let (_, d0) = self.event(closed, t, &y);
            let (e1, d1) = self.event(closed, t + tau, &y1);
            // The bracket of the first crossing: the step, or up to the event function's peak.
            let bracket = if e1 >= 0.0 {
                Some(tau)
            } else if d0 > 0.0 && d1 < 0.0 {
                let (tm, ym) = self.descend(closed, t, &y, tau, |s, x| self.event(closed, s, x).1 > 0.0);
                (self.event(closed, tm, &ym).0 >= 0.0).then_some(tm - t + self.h * 2f64.powi(-52))
            } else {
                None
            };
            match bracket.filter(|_| stalled < 4) {
                Some(span) => {
                    let (te, mut ye) = self.descend(closed, t, &y, span, |s, x| self.event(closed, s, x).0 < 0.0);
                    stalled = if te > t { 0 } else { stalled + 1 };
                    closed = !closed && (self.sys.contact_stiffness.is_some() || self.impact(te, &mut ye));
                    (t, y) = (te, ye);
                    seen(t, &y, Some(Event { time: t, closed_after: closed }));
                }
                None => {
                    stalled = 0;
                    t = if tau == until - t { until } else { t + tau };
                    y = y1;
                    seen(t, &y, None);
                }
            }
        }
        (y, closed)
    }

    /// One period from (t, y): the state a period later and the events on the way.
    pub fn period_map(&self, t: f64, y: &DVector<f64>) -> (DVector<f64>, Vec<Event>) {
        let mut y = y.clone();
        let closed = self.starts_closed(t, &mut y);
        let mut events = Vec::new();
        let (end, _) = self.run(t, y, closed, t + self.period, &mut |_, _, e| events.extend(e));
        (end, events)
    }
}

/// The independent verdict on an orbit of the chain: its fixed point's Floquet multiplier, the
/// output's amplitude, and where a long simulation started near it goes.
#[derive(Clone, Copy, Debug)]
pub struct Verdict {
    /// The largest |eigenvalue| of the period map's finite-difference Jacobian at the fixed point.
    pub multiplier: f64,
    /// Peak-to-peak/2 of DOF `out` over the orbit.
    pub amplitude: f64,
    /// The start's distance from the orbit (the nudge, relative to the orbit's state size).
    pub kick: f64,
    /// The simulation's distance from the orbit after `periods` periods and after half of them,
    /// and between its last two periods and its last period and the one two before (what it
    /// converges to: an orbit of period T or 2T), all relative to the orbit's state size.
    pub distance: f64,
    pub halfway: f64,
    pub defect: f64,
    pub defect2: f64,
    /// Events per period of the orbit.
    pub events: usize,
}

/// A distance at the march's floor (relative to the state size): the orbit itself. The march's
/// own fixed point lies off the Newton one by its round-off, the same from every nudge (2.7e-14 on
/// compliant seed 733 since every period runs from ts; before, with the absolute time growing, up
/// to 8.2e-11 on the rigid family 100–139 and 1.1e-9 on seed 733, growing with the periods).
const ROUND_OFF: f64 = 1e-9;

impl Verdict {
    /// Stable by the long simulation: it returns to the orbit, relative to the nudge (within a
    /// tenth of it, and the distance still falling: at most half the halfway one, or at the
    /// round-off). Not a fixed threshold: a weakly unstable orbit's march can end on a nearby
    /// attracting set as close as the nudge (compliant seeds 731/732, |μ| 1.07/1.13: 1e-6 to
    /// 3e-6 from a 1e-6 nudge, under the old 1e-5 threshold), which is not the orbit.
    pub fn settled(&self) -> bool {
        self.distance < ROUND_OFF || (self.distance < 0.1 * self.kick && self.distance <= 0.5 * self.halfway)
    }
}

/// The orbit through `y0` at `t0` (a branch point's state and its instant): the period map's fixed point by Newton with a central-difference
/// Jacobian at a section in the longest free flight, its multipliers, and a march of `periods`
/// periods from the fixed point perturbed by `kick` of its size. `None` where Newton fails.
pub fn verdict(sys: &StopChain, t0: f64, y0: &[f64], out: usize, periods: usize, kick: f64) -> Option<Verdict> {
    let m = StopMarch::new(sys);
    let (n2, tp) = (y0.len(), m.period);
    let y0 = DVector::from_column_slice(y0);
    let size = y0.amax().max(1e-12);
    // The section: the middle of the longest flight between events (any instant without events).
    let (_, events) = m.period_map(t0, &y0);
    let mut ts = t0 + 0.5 * tp;
    if !events.is_empty() {
        let mut longest = 0.0;
        for (i, e) in events.iter().enumerate() {
            let next = events.get(i + 1).map_or(events[0].time + tp, |x| x.time);
            if !e.closed_after && next - e.time > longest {
                (longest, ts) = (next - e.time, 0.5 * (e.time + next));
            }
        }
    }
    let mut y = {
        let mut y = y0.clone();
        let closed = m.starts_closed(t0, &mut y);
        m.run(t0, y, closed, ts, &mut |_, _, _| {}).0
    };
    // Newton on P(y) − y, the Jacobian of P by central differences at δ and δ/2 extrapolated
    // (Richardson: (4 D(δ/2) − D(δ))/3, O(δ⁴)); the events keep their order. Near a grazing the
    // impact map's scale is small (μ ∝ 1/v_in): plain differences at 1e-7 were off by 1 % at |μ| = 68.
    let jacobian = |y: &DVector<f64>| {
        let central = |j: usize, d: f64| {
            let (mut p, mut q) = (y.clone(), y.clone());
            p[j] += d;
            q[j] -= d;
            (m.period_map(ts, &p).0 - m.period_map(ts, &q).0) / (2.0 * d)
        };
        let d = 2e-8 * size;
        DMatrix::from_columns(&(0..n2).map(|j| (central(j, 0.5 * d) * 4.0 - central(j, d)) / 3.0).collect::<Vec<_>>())
    };
    for _ in 0..20 {
        let r = m.period_map(ts, &y).0 - &y;
        if r.amax() < 1e-13 * size {
            break;
        }
        y -= (jacobian(&y) - DMatrix::identity(n2, n2)).lu().solve(&r)?;
    }
    if (m.period_map(ts, &y).0 - &y).amax() > 1e-10 * size {
        return None;
    }
    let multiplier = jacobian(&y).complex_eigenvalues().iter().map(|z| z.norm()).fold(0.0, f64::max);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut count = 0;
    m.run(ts, y.clone(), false, ts + tp, &mut |_, x, e| {
        (lo, hi) = (lo.min(x[out]), hi.max(x[out]));
        count += usize::from(e.is_some());
    });
    // The start, off the orbit by `kick` of its size, kept off a rigid stop.
    let mut start = DVector::from_fn(n2, |i, _| y[i] + kick * size * if i % 2 == 0 { 1.0 } else { -1.0 });
    if sys.contact_stiffness.is_none() && start[sys.dof] >= sys.gap {
        start[sys.dof] = y[sys.dof] - kick * size;
    }
    let mut closed = m.starts_closed(ts, &mut start);
    let (mut before, mut prev, mut end) = (start.clone(), start.clone(), start);
    let mut halfway = f64::NAN;
    for k in 0..periods {
        // Every period from ts (the forcing is T-periodic): an absolute time growing with k let the
        // event times' round-off grow with it (seed 733: a drift of 2.7e-12 of the state per period).
        let (e, s) = m.run(ts, end.clone(), closed, ts + tp, &mut |_, _, _| {});
        (before, prev, end, closed) = (prev, end, e, s);
        if k + 1 == periods / 2 {
            halfway = (&end - &y).amax() / size;
        }
    }
    Some(Verdict {
        multiplier,
        amplitude: 0.5 * (hi - lo),
        kick,
        distance: (&end - &y).amax() / size,
        halfway,
        defect: (&end - &prev).amax() / size,
        defect2: (&end - &before).amax() / size,
        events: count,
    })
}

/// A branch's stability labels against [`verdict`]: how many points were compared, how many
/// disagree (the label against the long simulation or the reference's |μ| < 1), how many had no
/// reference orbit (amplitude not within 1e-4 of the point's), the largest |μ| difference (relative
/// above 1), and one line per point.
#[derive(Default)]
pub struct Labels {
    pub compared: usize,
    pub wrong: usize,
    pub unresolved: usize,
    pub worst_mu: f64,
    pub lines: Vec<String>,
}

impl Labels {
    /// Adds a member's counts (not its lines).
    pub fn absorb(&mut self, o: &Labels) {
        (self.compared, self.wrong, self.unresolved) = (self.compared + o.compared, self.wrong + o.wrong, self.unresolved + o.unresolved);
        self.worst_mu = self.worst_mu.max(o.worst_mu);
    }

    /// "w of c disagree, u without a reference orbit, |μ| within x".
    pub fn summary(&self) -> String {
        format!(
            "{} of {} disagree, {} without a reference orbit, |μ| within {:.1e} (relative above 1)",
            self.wrong, self.compared, self.unresolved, self.worst_mu
        )
    }
}

/// `per_label` points drawn at random (`Draw(seed ^ 0x5eed)`) from the branch's stable exact points
/// and as many from its unstable ones (most of a branch is stable), not at or within 1e-6 of an event nor within
/// 0.02 of |μ| = 1, each checked by [`verdict`] with 400 periods from kicks of 1e-6 and 1e-8 (`sys` at the point's Ω; the point's output 0 is DOF `sys.dof`).
pub fn check_labels(sys: &StopChain, points: &[BranchPoint], seed: u64, per_label: usize) -> Labels {
    let mut d = crate::common::family::Draw(seed ^ 0x5eed);
    let mut l = Labels::default();
    let events: Vec<f64> = points.iter().filter(|q| q.event.is_some()).map(|q| q.parameter).collect();
    for label in [true, false] {
        // Not within 1e-6 (relative) of an event: there the reference's finite differences (2e-8 of
        // the state) straddle a grazing's square-root singularity (seed 317, 6e-10 from a grazing:
        // 0.822551–0.822579 against the one-sided exact 0.822614586, which δ = 2e-6…2e-9 confirm off it).
        let near_event = |q: &&BranchPoint| events.iter().any(|&e| (q.parameter - e).abs() <= 1e-6 * e.abs().max(1.0));
        let plain: Vec<&BranchPoint> =
            points.iter().filter(|q| q.event.is_none() && q.source == Source::Exact && q.stable == label && !near_event(q)).collect();
        for _ in 0..per_label.min(plain.len()) {
            let q = plain[(d.next() * plain.len() as f64) as usize];
            if (q.max_multiplier - 1.0).abs() < 0.02 {
                continue;
            }
            let at = StopChain { omega: q.parameter, ..sys.clone() };
            // Two nudges (of the orbit's state size): the verdict must not hang on one being "small
            // enough to settle but big enough to leave".
            let found =
                |kick: f64| verdict(&at, q.time, &q.state, sys.dof, 400, kick).filter(|v| (v.amplitude - q.amplitude[0]).abs() <= 1e-4 * q.amplitude[0]);
            let (Some(v), Some(w)) = (found(1e-6), found(1e-8)) else {
                l.unresolved += 1;
                l.lines.push(format!("Ω {:.4}: stable {} / no reference orbit (|μ| {:.3})", q.parameter, q.stable, q.max_multiplier));
                continue;
            };
            l.compared += 1;
            let agree = v.settled() == q.stable && w.settled() == q.stable && (v.multiplier < 1.0) == q.stable;
            l.wrong += usize::from(!agree);
            l.worst_mu = l.worst_mu.max((v.multiplier - q.max_multiplier).abs() / q.max_multiplier.max(1.0));
            let march = |v: &Verdict| {
                format!(
                    "from {:.0e}: {} (distance/nudge {:.1e}, halfway {:.1e}; last periods differ by {:.1e} (T), {:.1e} (2T))",
                    v.kick,
                    v.settled(),
                    v.distance / v.kick,
                    v.halfway / v.kick,
                    v.defect,
                    v.defect2
                )
            };
            l.lines.push(format!(
                "Ω {:.4}: stable {} (|μ| {:.7}, reference {:.7}; {} events); march {}; {}{}",
                q.parameter,
                q.stable,
                q.max_multiplier,
                v.multiplier,
                v.events,
                march(&v),
                march(&w),
                if agree { "" } else { " DISAGREE" }
            ));
        }
    }
    l
}
