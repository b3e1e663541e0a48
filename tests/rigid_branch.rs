//! The exact walk on rigid stops (issue 24): plastic impacts (e = 0) and sticking arcs, against
//! the closed-form impact oscillator of src/exact/rigid.rs (its impact map and multiplier, not
//! the polish) and against long time integration (tests/common/stop_march.rs: exact flows, events
//! located inside the step; not the grid marcher, whose impacts land on its grid).
use crate::common::family::{Chain, Draw};
use crate::common::stop_march::{Labels, StopChain, check_labels, verdict};
use periodic_contact::analysis::continuation::{self, ContinuationSettings, Parameter, Source};
use periodic_contact::exact::{Oscillator, RigidRegime, RigidStopOrbit};
use periodic_contact::periodic::PeriodicProblem;

fn problem(text: &str) -> PeriodicProblem {
    periodic_contact::scene::Scene::parse(text, "rigid").unwrap().to_problem("rigid").unwrap()
}

/// The 1-DOF impact oscillator m x'' + c x' + k x = F cos Ωt, x ≤ g0 (rigid, plastic impacts).
fn impact_oscillator(osc: &Oscillator, gap: f64, steps: usize) -> String {
    format!(
        "[structure]\nmass = [[{}]]\nstiffness = [[{}]]\n[damping]\nmatrix = [[{}]]\n[excitation]\nfrequency = {}\n[[force]]\ndof = 0\namplitude = {}\n\
         [[contact]]\ndof = 0\ngap = {gap}\n[discretization]\nscheme = \"bds1\"\nsteps = {steps}\n[output]\ndisplacement = [0]\n",
        osc.mass, osc.stiffness, osc.damping, osc.omega, osc.force
    )
}

/// Two 1-DOF impact oscillators' branches against the closed form of src/exact/rigid.rs (the
/// impact instant from the free flight of exactly one period, or the departure at
/// Ω t_d = arccos(k g0 / F) and the sticking arc; bisection on its own flows, not the polish):
/// pure impacts (k g0 > F) over Ω ∈ [0.7, 1.3], where the one nonzero Floquet multiplier is the
/// impact map's derivative μ = dt_next/dt0 (a plastic impact leaves one degree of freedom, the
/// impact time); and impacts with sticking (k g0 < F) over Ω ∈ [0.55, 0.8], where the departure
/// is fixed and every multiplier is 0, through the merging of a pure impact and a sticking
/// impact into one at Ω ≈ 0.6384.
#[test]
fn impact_oscillator_branches_match_the_closed_form() {
    let (m, c, k, f) = (1.0, 0.1, 1.0, 1.0);
    for (gap, from, to, regime) in [(1.5, 0.7, 1.3, RigidRegime::Impacting), (0.5, 0.55, 0.8, RigidRegime::Sticking)] {
        let p = problem(&impact_oscillator(&Oscillator::new(m, c, k, f, from), gap, 512));
        let b = continuation::run(&p, Parameter::Frequency, from, to, &ContinuationSettings::default(), &|_| {}).unwrap();
        assert!(b.reached(), "{}", b.stop);
        assert!(b.points.iter().all(|q| q.source == Source::Exact), "{}", b.stop);
        let (mut worst_amp, mut worst_mu, mut compared) = (0.0f64, 0.0f64, 0);
        for q in b.points.iter().filter(|q| q.event.is_none()) {
            let Ok(r) = RigidStopOrbit::solve(&Oscillator::new(m, c, k, f, q.parameter), gap) else { continue };
            if r.regime() != regime {
                continue;
            }
            let amp = 0.5 * r.peak_to_peak();
            worst_amp = worst_amp.max((q.amplitude[0] - amp).abs() / amp);
            let mu = r.multiplier().unwrap_or(0.0);
            worst_mu = worst_mu.max((q.max_multiplier - mu.abs()).abs());
            assert_eq!(q.stable, mu.abs() < 1.0, "Ω = {}: stable {} but |μ| = {}", q.parameter, q.stable, mu.abs());
            compared += 1;
        }
        eprintln!(
            "impact oscillator, gap {gap}: {} points, {compared} {regime:?} points vs closed form: amplitude {worst_amp:.1e} (relative), largest |μ| {worst_mu:.1e}; events {:?}",
            b.points.len(),
            b.events().map(|e| (e.event.unwrap().name(), e.parameter, e.detail.as_str())).collect::<Vec<_>>()
        );
        assert!(compared >= 5, "only {compared} {regime:?} points");
        if regime == RigidRegime::Sticking {
            // The pure impact starts to stick on the exact orbit: the grazing where the closed
            // form's sticking arc shrinks to nothing (its regime changes).
            let onset = sticking_onset(&Oscillator::new(m, c, k, f, from), gap, from, to);
            let at = b.events().map(|e| e.parameter).min_by(|x, y| (x - onset).abs().total_cmp(&(y - onset).abs())).unwrap();
            eprintln!("sticking onset: walk {at:.10}, closed form {onset:.10}");
            assert!((at - onset).abs() < 1e-6, "the sticking onset at Ω = {at}, the closed form's at {onset}");
        }
        assert!(worst_amp < 1e-6, "amplitude off the closed form by {worst_amp:.1e}");
        assert!(worst_mu < 1e-4, "multiplier off the closed form's by {worst_mu:.1e}");
    }
}

/// The same sticking oscillator walked down, 0.8 → 0.55: the merged orbit (one sticking impact)
/// un-merges where the force holding the mass at its landing reaches zero (the landing turns
/// into a pure impact and a micro-flight, issue 24's coarse rigid blade at 2217.54 rad/s). The
/// change is recorded where that force crosses zero, against the closed form's change of regime
/// (bisection on its own flows), and the walk stays on the exact orbit to the end.
#[test]
fn sticking_oscillator_unmerges_where_the_closed_form_changes() {
    let (m, c, k, f, gap) = (1.0, 0.1, 1.0, 1.0, 0.5);
    let p = problem(&impact_oscillator(&Oscillator::new(m, c, k, f, 0.8), gap, 512));
    let b = continuation::run(&p, Parameter::Frequency, 0.8, 0.55, &ContinuationSettings::default(), &|_| {}).unwrap();
    assert!(b.reached(), "{}", b.stop);
    assert!(b.points.iter().all(|q| q.source == Source::Exact), "{}", b.stop);
    let onset = sticking_onset(&Oscillator::new(m, c, k, f, 0.55), gap, 0.55, 0.8);
    let at = b.events().map(|e| e.parameter).min_by(|x, y| (x - onset).abs().total_cmp(&(y - onset).abs())).unwrap();
    eprintln!("un-merge walking down: walk {at:.10}, closed form {onset:.10}");
    assert!((at - onset).abs() < 1e-6, "the un-merge at Ω = {at}, the closed form's change at {onset}");
}

/// The hand-over refusal on a model (session 25): the impact oscillator (gap 1.5 > F/k) walked up
/// from 0.9 has its impacting orbit past Ω = 1.2861, where the contact-free orbit's amplitude
/// F/√((k − mΩ²)² + (cΩ)²) (closed form) is below the gap, so two orbits coexist. The exact walk is
/// stopped there by the point limit; the discrete walk's cold solve at that Ω takes the
/// contact-free orbit (its LCP's zero solution), which must be refused, not followed to "reached".
#[test]
fn a_hand_over_to_the_contact_free_orbit_is_refused() {
    let (m, c, k, f, gap) = (1.0, 0.1, 1.0, 1.0, 1.5);
    let free = |w: f64| f / ((k - m * w * w).powi(2) + (c * w).powi(2)).sqrt();
    let p = problem(&impact_oscillator(&Oscillator::new(m, c, k, f, 0.9), gap, 512));
    let whole = continuation::run(&p, Parameter::Frequency, 0.9, 1.8, &ContinuationSettings::default(), &|_| {}).unwrap();
    // The first point past Ω = 1.3 (free amplitude 1.42 < 1.5), on the way up: the impacting orbit.
    let stop_at = whole.points.iter().position(|q| q.parameter > 1.3).expect("the walk passes 1.3");
    let settings = ContinuationSettings { max_points: stop_at + 1, ..ContinuationSettings::default() };
    let b = continuation::run(&p, Parameter::Frequency, 0.9, 1.8, &settings, &|_| {}).unwrap();
    let last = b.points.last().unwrap();
    let w = last.parameter;
    let impacting = 0.5 * RigidStopOrbit::with_contact(&Oscillator::new(m, c, k, f, w), gap).unwrap().peak_to_peak();
    eprintln!(
        "hand-over refused: exact walk stopped at Ω = {w}, amplitude {:.6} (closed form {impacting:.6}), contact-free {:.6}; {}",
        last.amplitude[0],
        free(w),
        b.stop
    );
    assert!(w > 1.3 && w < 1.378, "stopped at Ω = {w}, not between the grazing and the fold");
    assert!((last.amplitude[0] - impacting).abs() < 1e-6 * impacting, "the last exact orbit is the impacting one: {} vs {impacting}", last.amplitude[0]);
    assert!(free(w) < gap && (impacting - free(w)).abs() > 0.1 * impacting, "two distinct orbits at Ω = {w}");
    assert!(!b.reached(), "the discrete walk on the contact-free orbit was taken: {}", b.stop);
    assert!(b.stop.contains("contact-free") && b.stop.contains("refused"), "{}", b.stop);
    assert!(b.points.iter().all(|q| q.source == Source::Exact), "no discrete point appended: {}", b.stop);
}

/// The frequency in [a, b] where the closed form's orbit changes between a sticking arc and pure
/// impacts (the sticking arc Ω t ∈ [Ω t_h, 2π + Ω t_d] shrinking to nothing), by bisection on its regime.
fn sticking_onset(osc: &Oscillator, gap: f64, a: f64, b: f64) -> f64 {
    let sticks = |w: f64| {
        let o = Oscillator::new(osc.mass, osc.damping, osc.stiffness, osc.force, w);
        RigidStopOrbit::solve(&o, gap).is_ok_and(|r| r.regime() == RigidRegime::Sticking)
    };
    let (mut lo, mut hi) = (a, b);
    let s = sticks(lo);
    assert!(s != sticks(hi), "no change of regime over [{a}, {b}]");
    while hi - lo > 1e-12 {
        let mid = 0.5 * (lo + hi);
        if sticks(mid) == s { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// A random oscillator of 1–3 DOFs (a grounded chain: masses 0.5–2, springs 0.5–2, Rayleigh
/// damping of 2–6 % at the first mode) with a RIGID stop on a random DOF, forced on a random DOF;
/// the gap is 0.3–0.8 of that DOF's linear peak near the first mode, so the branch over
/// [0.6, 1.4]·ω₁ impacts and, where the gap is small, sticks. (scene, ω₁, the same chain for the
/// event-located reference)
fn random_rigid(d: &mut Draw, steps: usize) -> (String, f64, StopChain) {
    let chain = Chain::draw(d);
    let (n, w1) = (chain.n, chain.w1);
    let alpha = 2.0 * d.range(0.02, 0.06) / w1;
    let (fdof, cdof) = ((d.next() * n as f64) as usize, (d.next() * n as f64) as usize);
    let amp = 0.1;
    let peak = (0..400).map(|j| chain.linear_amplitude(alpha, fdof, cdof, amp, w1 * (0.6 + 0.8 * j as f64 / 400.0))).fold(0.0, f64::max);
    let gap = d.range(0.3, 0.8) * peak;
    let sys = chain.stop(alpha, (fdof, amp), cdof, gap, None);
    (chain.scene(alpha, (fdof, amp), &format!("dof = {cdof}\ngap = {gap:e}\n"), "bds1", steps, cdof), w1, sys)
}

/// What the family gave: members that reached the end on the exact orbit all along, and that
/// reached it; the largest event difference between k and 2k (kind by kind); stability labels
/// against the event-located reference.
struct Family {
    exact: usize,
    reached: usize,
    worst: f64,
    labels: Labels,
}

/// The random rigid family's members `seeds`, each over [0.6, 1.4]·ω₁ at k and 2k. Prints each member.
fn rigid_family(seeds: std::ops::Range<u64>, steps: usize, checks_per_member: usize) -> Family {
    let (mut exact, mut reached, mut worst, mut labels) = (0, 0, 0.0f64, Labels::default());
    for seed in seeds {
        let sys = random_rigid(&mut Draw(seed), steps).2;
        let runs: Vec<continuation::Branch> = [steps, 2 * steps]
            .iter()
            .map(|&k| {
                let (text, w1, _) = random_rigid(&mut Draw(seed), k);
                let p = problem(&text);
                continuation::run(&p, Parameter::Frequency, 0.6 * w1, 1.4 * w1, &ContinuationSettings::default(), &|_| {}).unwrap()
            })
            .collect();
        let all_exact = runs.iter().all(|b| b.reached() && b.points.iter().all(|q| q.source == Source::Exact));
        exact += usize::from(all_exact);
        reached += usize::from(runs.iter().all(|b| b.reached()));
        let ev: Vec<Vec<(&str, f64)>> = runs.iter().map(|b| b.events().map(|e| (e.event.unwrap().name(), e.parameter)).collect()).collect();
        let same_kinds = ev[0].iter().map(|e| e.0).eq(ev[1].iter().map(|e| e.0));
        let gap = if same_kinds { ev[0].iter().zip(&ev[1]).map(|(a, b)| (a.1 - b.1).abs()).fold(0.0, f64::max) } else { f64::INFINITY };
        worst = worst.max(gap);
        // Stability at points drawn at random on the k branch, against long time integration.
        let l = check_labels(&sys, &runs[0].points, seed, checks_per_member);
        labels.absorb(&l);
        eprintln!(
            "seed {seed}: exact {all_exact}, {} events at k, {} at 2k, largest difference {gap:.1e}; {}; stop: {}",
            ev[0].len(),
            ev[1].len(),
            l.lines.join(", "),
            runs[0].stop
        );
        if std::env::var("PC_RIGID_EVENTS").is_ok() {
            for b in &runs {
                for e in b.events() {
                    eprintln!("  {} {:.9} {}", e.event.unwrap().name(), e.parameter, e.detail);
                }
                eprintln!("  --");
            }
        }
    }
    Family { exact, reached, worst, labels }
}

/// Two members of the random rigid family (issue 24) whose unstable impacting orbit from the fold
/// ends where its impulse fades on the side where the contact-free orbit is admissible (the
/// branch turns back there in λ): each reaches the end on the exact orbit, the events at k = 256
/// and 512 agree within 1e-5 kind by kind, and the stability labels at random points agree with
/// long time integration.
#[test]
fn random_rigid_oscillators_give_the_same_exact_branch_at_k_and_2k() {
    let seeds = 2..4;
    let f = rigid_family(seeds.clone(), 256, 1);
    eprintln!(
        "{} of {} exact to the end, {} reached; k vs 2k: {:.1e}; stability vs the event-located reference: {}",
        f.exact,
        seeds.end - seeds.start,
        f.reached,
        f.worst,
        f.labels.summary()
    );
    assert_eq!(f.exact, (seeds.end - seeds.start) as usize);
    assert!(f.worst <= 1e-5, "events at k and 2k differ by {:.1e}", f.worst);
    let l = &f.labels;
    assert!(l.compared >= 4 && l.wrong == 0 && l.unresolved == 0, "stability vs long time integration: {}", l.summary());
    assert!(l.worst_mu < 1e-5, "|μ| off the reference's finite-difference Jacobian: {}", l.summary());
}

/// The whole random rigid family (opt-in: `PC_RIGID_FAMILY=40 cargo test --release --test suite
/// rigid_branch:: -- --ignored`; `PC_RIGID_FAMILY_FROM` the first seed, 100 by default;
/// `PC_RIGID_EVENTS` prints every event): at least 95 % reach the end on the exact orbit; prints
/// the worst k vs 2k event disagreement and the stability labels at random points (one stable,
/// one unstable per member) against long time integration.
#[test]
#[ignore]
fn random_rigid_family() {
    let count: u64 = std::env::var("PC_RIGID_FAMILY").ok().and_then(|s| s.parse().ok()).unwrap_or(40);
    let first: u64 = std::env::var("PC_RIGID_FAMILY_FROM").ok().and_then(|s| s.parse().ok()).unwrap_or(100);
    let f = rigid_family(first..first + count, 256, 1);
    eprintln!(
        "random rigid family of {count}: {} exact to the end ({:.1} %), {} reached; worst k vs 2k event difference {:.1e}; stability vs the event-located reference: {}",
        f.exact,
        100.0 * f.exact as f64 / count as f64,
        f.reached,
        f.worst,
        f.labels.summary()
    );
    assert!(100 * f.exact as u64 >= 95 * count, "{} of {count} exact to the end (target 95 %)", f.exact);
}

/// The event-located reference (tests/common/stop_march.rs) on a 1-DOF member of the rigid family
/// against the closed-form impact map of src/exact/rigid.rs: at every pure-impact orbit over
/// [0.6, 1.4]·ω₁ (unstable ones too) its finite-difference multiplier is the closed form's
/// |μ| = |dt_next/dt0|, and its long simulation settles exactly when |μ| < 1 (seed 122 at
/// Ω ≈ 1.28, μ ≈ −1.76, among them: the grid marcher held that orbit, the reference leaves it).
#[test]
fn the_event_located_reference_agrees_with_the_closed_form_impact_map() {
    let (mut stable, mut unstable, mut worst_mu) = (0, 0, 0.0f64);
    let seed = 122;
    let (_, w1, sys) = random_rigid(&mut Draw(seed), 256);
    assert_eq!(sys.mass.len(), 1, "seed {seed} is a 1-DOF member");
    for j in 0..=40 {
        let omega = w1 * (0.6 + 0.02 * j as f64);
        let osc = Oscillator::new(sys.mass[0], sys.damping[(0, 0)], sys.stiffness[(0, 0)], sys.force[0], omega);
        for (t0, mu) in RigidStopOrbit::pure_impacts(&osc, sys.gap).unwrap() {
            if (mu.abs() - 1.0).abs() < 0.02 {
                continue;
            }
            let v = verdict(&StopChain { omega, ..sys.clone() }, t0, &[sys.gap, 0.0], 0, 400, 1e-6).expect("the reference finds the orbit");
            eprintln!(
                "seed {seed} Ω {omega:.4}: closed form μ {mu:.6}, reference |μ| {:.6}, settled {} (distance {:.1e})",
                v.multiplier,
                v.settled(),
                v.distance
            );
            worst_mu = worst_mu.max((v.multiplier - mu.abs()).abs() / mu.abs().max(1.0));
            assert_eq!(v.settled(), mu.abs() < 1.0, "Ω {omega}: μ = {mu}, settled {}", v.settled());
            if mu.abs() < 1.0 { stable += 1 } else { unstable += 1 }
        }
    }
    eprintln!("{stable} stable and {unstable} unstable pure-impact orbits; |μ| within {worst_mu:.1e} (relative above 1)");
    assert!(stable >= 1 && unstable >= 1, "{stable} stable, {unstable} unstable orbits compared");
    assert!(worst_mu < 1e-5, "reference |μ| off the closed form by {worst_mu:.1e}");
}
