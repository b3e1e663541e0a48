//! Time marching from a continued orbit (issue 24): is a point of an exact branch a periodic
//! orbit, and is it stable? Continues `scene` in the frequency from `from` towards `to`, takes
//! the exact point nearest `at` (its state just after event 0, at instant t0 of the period),
//! and marches the model (central differences, plastic impacts: src/marching/) from that state
//! with the forcing and the obstacles' motion shifted by t0. Prints, period by period, the
//! distance of the marched state from the orbit's (over the orbit's peak-to-peak): a wrong
//! "orbit" is far already after one period; an unstable one starts near (the scheme's error)
//! and drifts away at the rate of its largest multiplier.
//!
//! `cargo run --release --example orbit_march -- SCENE FROM TO AT [STEPS_PER_PERIOD] [PERIODS]`
use periodic_contact::analysis::continuation::{self, BranchPoint, ContinuationSettings, Parameter, Source};
use periodic_contact::marching::{MarchSettings, march};
use std::cell::RefCell;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: orbit_march SCENE FROM TO AT [STEPS_PER_PERIOD] [PERIODS]";
    let num = |i: usize, d: f64| args.get(i).map_or(d, |s| s.parse().expect(usage));
    let scene = args.get(1).expect(usage);
    let (from, to, at) = (num(2, f64::NAN), num(3, f64::NAN), num(4, f64::NAN));
    let (steps, periods) = (num(5, 4096.0) as usize, num(6, 200.0) as usize);
    let (s, dir) = periodic_contact::scene::Scene::load(Path::new(scene)).expect("the scene");
    let problem = s.build_in(scene, &dir).expect("the scene builds").problem;
    // The walk is stopped (a panic caught) once past `at`: the rest of the range is not needed.
    let seen: RefCell<Vec<BranchPoint>> = RefCell::new(Vec::new());
    let on_point = |p: &BranchPoint| {
        seen.borrow_mut().push(p.clone());
        if (p.parameter - at) * (to - from).signum() > 1.0 {
            std::panic::panic_any("past");
        }
    };
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let walked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        continuation::run(&problem, Parameter::Frequency, from, to, &ContinuationSettings::default(), &on_point).map(|b| b.stop)
    }));
    std::panic::set_hook(hook);
    eprintln!("walk: {:?}", walked.as_ref().map(|r| r.as_ref().map_err(|e| e.to_string())).map_err(|_| "stopped past AT"));
    let points = seen.into_inner();
    let p = points
        .iter()
        .filter(|p| p.source == Source::Exact && p.event.is_none())
        .min_by(|a, b| (a.parameter - at).abs().total_cmp(&(b.parameter - at).abs()))
        .expect("an exact point");
    let n = problem.model().n();
    let omega = p.parameter;
    println!(
        "point: λ = {omega:.7} rad/s, max|μ| {:.4}, amplitude {:?}, t0 = {:.6e} s, |μ| {:?}",
        p.max_multiplier,
        p.amplitude,
        p.time,
        p.multipliers.iter().take(4).map(|m| format!("{:.4}{:+.4}i", m.re, m.im)).collect::<Vec<_>>()
    );
    // The model seen from t0: each term's phase advanced by harmonic·ω·t0.
    let mut model = problem.model().clone();
    model.frequency = omega;
    let shift = |h: &mut periodic_contact::model::Harmonic| h.phase += f64::from(h.harmonic) * omega * p.time;
    model.forces.iter_mut().for_each(|f| shift(&mut f.term));
    model.contacts.iter_mut().flat_map(|c| c.motion.iter_mut()).for_each(shift);
    let (x0, v0) = (p.state[..n].to_vec(), p.state[n..2 * n].to_vec());
    let tips: Vec<usize> = model.contacts.iter().map(|c| c.label_dof()).collect();
    // One period at three step counts: the march's own error falls with h, an orbit's defect does not.
    for n_steps in [steps / 4, steps, 4 * steps] {
        let settings = MarchSettings {
            steps_per_period: n_steps,
            max_periods: 2,
            min_periods: 2,
            tolerance: 1e-300,
            initial_displacement: Some(x0.clone()),
            initial_velocity: Some(v0.clone()),
        };
        let r = march(&model, &settings).expect("the march");
        let scale = x0.iter().map(|v| v.abs()).fold(0.0f64, f64::max).max(1e-300);
        let dist = r.displacement[0].iter().zip(&x0).map(|(a, b)| (a - b).abs()).fold(0.0f64, f64::max) / scale;
        println!("one period at {n_steps} steps: displacement off the orbit's by {dist:.3e} of its largest component");
    }
    // Period by period: march k periods, compare the state at the period's start with the orbit's.
    let mut last = None;
    for k in [1usize, 2, 5, 10, 20, 40, 60, 80, 100, 150, 200, 300, 400].into_iter().filter(|&k| k <= periods) {
        let settings = MarchSettings {
            steps_per_period: steps,
            max_periods: k + 1,
            min_periods: k + 1,
            tolerance: 1e-300,
            initial_displacement: Some(x0.clone()),
            initial_velocity: Some(v0.clone()),
        };
        let r = march(&model, &settings).expect("the march");
        // The last simulated period's first sample is the state k periods on.
        let x = &r.displacement[0];
        let ptp = |d: usize| {
            let (lo, hi) = r.displacement.iter().fold((f64::MAX, f64::MIN), |(lo, hi), s| (lo.min(s[d]), hi.max(s[d])));
            hi - lo
        };
        let scale = x0.iter().map(|v| v.abs()).fold(0.0f64, f64::max).max(1e-300);
        let dist = x.iter().zip(&x0).map(|(a, b)| (a - b).abs()).fold(0.0f64, f64::max) / scale;
        let half: Vec<String> = tips.iter().map(|&d| format!("{:.4e}", 0.5 * ptp(d))).collect();
        println!(
            "after {k:4} periods: displacement off the orbit's by {dist:.3e} of its largest component; marched half peak-to-peak (tips) {half:?}; cpu {:.2} s",
            r.cpu_time_s
        );
        last = Some(r);
    }
    if let Some(r) = last {
        println!("defect history (every 10th period): {:?}", r.defect_history.iter().step_by(10).map(|d| format!("{d:.2e}")).collect::<Vec<_>>());
    }
}
