//! Friction through the front ends and the normal-load continuation (issue 25 items 3–4):
//! - the C API's friction accessors and `pc_problem_set_normal_force_scale` against the scene with
//!   the scaled load written into its text (another path through the parser), the slip force μN
//!   by arithmetic, and the law |f| ≤ μN, f·v ≥ 0, stuck ⇔ |f| < μN; misuse gets typed statuses;
//! - `continuation::run` in `normal_force` on the Jenkins damper against closed forms (free: the
//!   linear oscillator; stuck: the linear oscillator with k + k_t) and the event-driven exact
//!   simulation (`exact::FrictionOrbit`) in between, at k and 2k (bds1: first order).
use periodic_contact::analysis::continuation::{self, ContinuationSettings, Parameter};
use periodic_contact::capi::*;
use periodic_contact::exact::{FrictionOrbit, FrictionOscillator};
use periodic_contact::scene::Scene;
use std::ffi::{CString, c_int};

const DAMPER: &str = include_str!("../fmu/scenes/friction-damper.toml");

#[test]
fn c_api_reads_friction_contacts_and_scales_their_normal_load() {
    let path = CString::new(concat!(env!("CARGO_MANIFEST_DIR"), "/fmu/scenes/friction-damper.toml")).unwrap();
    // The reference: the scene's text with N = 2 → 1 (normal_force_scale 0.5), solved in Rust.
    let halved = DAMPER.replacen("normal_force = 2.0", "normal_force = 1.0", 1);
    assert_ne!(halved, DAMPER);
    let reference = Scene::parse(&halved, "halved.toml").unwrap().to_problem("halved.toml").unwrap().solve().unwrap();
    let want = &reference.friction[0];
    unsafe {
        let p = pc_problem_from_scene_file(path.as_ptr());
        assert!(!p.is_null());
        assert_eq!(pc_problem_friction_count(p), 1);
        for bad in [-0.5, f64::NAN, f64::INFINITY] {
            assert_eq!(pc_problem_set_normal_force_scale(p, bad), PC_ERROR_ARGUMENT, "scale {bad}");
        }
        assert_eq!(pc_problem_set_normal_force_scale(p, 0.5), PC_OK);
        let r = pc_problem_solve(p);
        assert!(!r.is_null());
        let k = pc_result_steps(r);
        assert_eq!(pc_result_friction_count(r), 1);
        let (mut force, mut slip, mut u, mut stuck) = (vec![0.0; k], vec![0.0; k], vec![0.0; k], vec![7 as c_int; k]);
        assert_eq!(pc_result_friction_force(r, 0, force.as_mut_ptr(), k), PC_OK);
        assert_eq!(pc_result_friction_slip_velocity(r, 0, slip.as_mut_ptr(), k), PC_OK);
        assert_eq!(pc_result_friction_displacement(r, 0, u.as_mut_ptr(), k), PC_OK);
        assert_eq!(pc_result_friction_stuck(r, 0, stuck.as_mut_ptr(), k), PC_OK);
        let (mut energy, mut mu_n) = (0.0, 0.0);
        assert_eq!(pc_result_friction(r, 0, &mut energy, &mut mu_n), PC_OK);
        assert_eq!(pc_result_friction(r, 0, std::ptr::null_mut(), std::ptr::null_mut()), PC_OK);
        // μ = 0.25 times N = 2 times the scale 0.5.
        assert!((mu_n - 0.25).abs() < 1e-15, "slip force {mu_n}");
        let close = |a: &[f64], b: &[f64], what: &str| {
            let scale = b.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
            let worst = a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(worst <= 1e-9 * scale, "{what}: C API differs from the scene with N halved by {worst:e}");
        };
        close(&force, &want.force, "force");
        close(&slip, &want.slip_velocity, "slip velocity");
        close(&u, &want.displacement, "displacement");
        assert!((energy - want.dissipated_energy).abs() <= 1e-9 * want.dissipated_energy);
        assert!(stuck.iter().zip(&want.stuck).all(|(a, b)| (*a == 1) == *b));
        // The law: the box, the sign of the slip, and stuck exactly inside the box.
        assert!(force.iter().all(|f| f.abs() <= mu_n * (1.0 + 1e-9)));
        assert!(force.iter().zip(&slip).all(|(f, v)| f * v >= -1e-12));
        assert!(stuck.iter().zip(&force).all(|(s, f)| (*s == 1) == (f.abs() < mu_n * (1.0 - 1e-9))));
        assert!(stuck.contains(&1) && stuck.contains(&0), "the damper sticks and slips");
        // Misuse: a friction contact that does not exist, a short or NULL buffer, NULL handles.
        assert_eq!(pc_result_friction_force(r, 1, force.as_mut_ptr(), k), PC_ERROR_ARGUMENT);
        assert_eq!(pc_result_friction_stuck(r, 0, stuck.as_mut_ptr(), k - 1), PC_ERROR_ARGUMENT);
        assert_eq!(pc_result_friction_slip_velocity(r, 0, std::ptr::null_mut(), k), PC_ERROR_ARGUMENT);
        assert_eq!(pc_result_friction(std::ptr::null(), 0, &mut energy, &mut mu_n), PC_ERROR_ARGUMENT);
        assert_eq!(pc_result_friction_count(std::ptr::null()), 0);
        assert_eq!(pc_problem_friction_count(std::ptr::null()), 0);
        assert_eq!(pc_problem_set_normal_force_scale(std::ptr::null_mut(), 1.0), PC_ERROR_ARGUMENT);
        pc_result_free(r);
        pc_problem_free(p);
    }
}

/// The damper of fmu/scenes/friction-damper.toml (m = 1, c = 0.1, k = 1, F = 1, k_t = 2) at Ω.
fn damper(omega: f64, slip_force: f64) -> FrictionOscillator {
    FrictionOscillator {
        mass: vec![vec![1.0]],
        damping: vec![vec![0.1]],
        stiffness: vec![vec![1.0]],
        force: vec![1.0],
        omega,
        dof: 0,
        slip_force,
        tangential_stiffness: Some(2.0),
    }
}

/// |F / (k − mΩ² + icΩ)|: the linear oscillator's amplitude.
fn linear_amplitude(k: f64, omega: f64) -> f64 {
    1.0 / ((k - omega * omega).powi(2) + (0.1 * omega).powi(2)).sqrt()
}

#[test]
fn normal_load_continuation_against_the_event_driven_simulation() {
    // The shipped damper (Ω = 0.8) from free sliding (N = 0) to stuck (N = 8: μN = 2, above the
    // stuck spring force), at k = 128 and 256. Exact: the linear oscillator at N = 0 and, from
    // N = 5 on, with k + k_t (stuck for good: the simulation's amplitude is the plateau's from N = 4 on); the event-driven
    // simulation in between.
    let (omega, mu) = (0.8, 0.25);
    let settings = ContinuationSettings { max_step: 1.0 / 8.0, ..ContinuationSettings::default() };
    let branch = |k: usize| {
        let text = DAMPER.replacen("steps = 256", &format!("steps = {k}"), 1);
        let problem = Scene::parse(&text, "d.toml").unwrap().to_problem("d.toml").unwrap();
        let b = continuation::run(&problem, Parameter::NormalForce, 0.0, 8.0, &settings, &|_| {}).expect("branch");
        assert!(b.reached(), "{}", b.stop);
        b
    };
    let (coarse, fine) = (branch(128), branch(256));
    let grid = |b: &continuation::Branch| b.points.iter().filter(|p| p.detail.is_empty()).map(|p| (p.parameter, p.amplitude[0])).collect::<Vec<_>>();
    let (coarse, fine) = (grid(&coarse), grid(&fine));
    assert_eq!(coarse.len(), 9);
    let stuck = linear_amplitude(3.0, omega);
    for (&(n, a), &(n2, b)) in coarse.iter().zip(&fine) {
        assert_eq!(n, n2);
        let exact = match n {
            0.0 => linear_amplitude(1.0, omega),
            n if n >= 5.0 => stuck,
            n => FrictionOrbit::solve(&damper(omega, mu * n), 2000, 1e-11, 5000).expect("orbit").amplitude(0, 4000),
        };
        let (e1, e2) = ((a - exact).abs() / exact, (b - exact).abs() / exact);
        let extrapolated = (2.0 * b - a - exact).abs() / exact;
        println!("N = {n}: exact amplitude {exact:.6}, errors {e1:.3e} (k = 128), {e2:.3e} (k = 256), extrapolated {extrapolated:.3e}");
        assert!(e2 < 0.75 * e1 + 1e-4, "N = {n}: errors {e1:.3e} → {e2:.3e}: not converging");
        assert!(e2 < 4e-2 && extrapolated < 1e-2, "N = {n}: errors {e2:.3e}, extrapolated {extrapolated:.3e}");
    }
    // Free to stuck: the amplitude falls from the free one to the stuck plateau.
    assert!(fine[0].1 > 5.0 * stuck && (fine[8].1 - stuck).abs() < 2e-2 * stuck);
    // A scene without [[friction]] has no normal load to continue: refused by name.
    let plain = "[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n[excitation]\nfrequency = 1.0\n[[force]]\ndof = 0\namplitude = 1.0\n[discretization]\nscheme = \"bds1\"\nsteps = 64\n";
    let p = Scene::parse(plain, "p.toml").unwrap().to_problem("p.toml").unwrap();
    let e = continuation::run(&p, Parameter::NormalForce, 0.0, 1.0, &settings, &|_| {}).unwrap_err();
    assert!(e.to_string().contains("no [[friction]]"), "{e}");
}
