//! Where the rubbing real blade's branches end near 2278 rad/s (validation/RECORD.md "Friction", issue 25):
//! walks the lower branch up warm, jumps to the upper one as the sweep does (warm Newton from
//! the last lower orbit at the next 5 rad/s point), then walks the upper branch DOWN in halved
//! steps to its end. Prints ω, the flap amplitude (`6843:y`, half its peak-to-peak) per orbit.
//!
//! `cargo run --release --example rubbing_fold -- examples/rubbing/real-blade-mu0.15.toml`
use periodic_contact::periodic::PeriodicSolver;
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;
use std::path::Path;

fn flap(r: &Response) -> f64 {
    // `6843:y` is the model DOF 20272 (the sweep CSV's amplitude_20272).
    r.displacement.get("20272").map_or(f64::NAN, |s| Response::peak_to_peak(s) / 2.0)
}

/// Walks `session` from `from` by `step` while warm shooting solves, halving a missed step down
/// to `smallest` (or to 2300 rad/s going up); returns the last frequency solved.
fn walk(session: &mut PeriodicSolver, from: f64, mut step: f64, smallest: f64, label: &str) -> f64 {
    let mut here = from;
    while step.abs() >= smallest {
        let next = here + step;
        if next > 2300.0 + 1e-9 {
            break;
        }
        session.update_frequency(next).unwrap();
        match session.solve_by_shooting(true) {
            Ok(r) => {
                println!("{label} {next:.4} {:.9e}", flap(&r));
                here = next;
            }
            Err(_) => {
                eprintln!("{label}: {next:.4} missed (step {step})");
                step /= 2.0;
            }
        }
    }
    here
}

fn main() {
    let scene = std::env::args().nth(1).expect("SCENE");
    let (s, dir) = Scene::load(Path::new(&scene)).unwrap();
    let built = s.build_in(&scene, &dir).unwrap();
    let mut problem = built.problem;
    // As in a sweep (one thread per point): the jump below is sensitive to the last bits.
    problem.set_parallel(std::env::var("PARALLEL").is_ok());
    let mut session = PeriodicSolver::new(problem);
    session.update_frequency(2270.0).unwrap();
    let r = session.solve_by_shooting(false).unwrap();
    println!("lower 2270.0000 {:.9e}", flap(&r));
    let fold = walk(&mut session, 2270.0, 1.0, 0.01, "lower");
    println!("# the lower branch ends at {fold:.4} rad/s (a step of 0.01 misses)");
    // The sweep's jump: warm Newton from the last orbit below the fold at a point past it.
    let near_fold = session.warm_start().unwrap().to_vec();
    let jump = [2280.0, 2285.0, 2290.0].into_iter().find(|&w| {
        session.set_warm_start(&near_fold);
        session.update_frequency(w).unwrap();
        let r = session.solve_by_shooting(true);
        r.as_ref().map(|r| println!("jump {w:.4} {:.9e}", flap(r))).is_ok()
    });
    let jump = jump.expect("no jump");
    let upper = session.warm_start().unwrap().to_vec();
    let low = walk(&mut session, jump, -0.5, 0.01, "upper");
    println!("# the upper branch ends going down at {low:.4} rad/s (a step of 0.01 misses)");
    session.set_warm_start(&upper);
    let top = walk(&mut session, jump, 5.0, 0.3, "upper");
    println!("# the upper branch walked up to {top:.4} rad/s");
}
