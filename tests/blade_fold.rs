//! The coarse blade's resonance tip, bracketed by time marching (issue 13). The continuation
//! (`periodic-contact continue fmu/scenes/blade-casing-coarse.toml --from 2150 --to 2900`, validation/RECORD.md
//! "Branches") folds at 2796.03 rad/s, 0.986 mm; beyond it only the contact-free orbit exists.
//! Independent check: explicit time marching of the reduced model (`periodic_contact::marching`),
//! started on the stable contact orbit at 2792 rad/s (followed from 2300, where it is the only
//! orbit, as the FMU re-solves, and polished to its exact state), stays on that orbit at 2792 and
//! falls to the contact-free orbit at 2800: the tip lies between (measured: marched 1.8543e-4
//! against the orbit's 1.8546e-4 largest peak-to-peak at 2792; 3.9992e-6 against the contact-free
//! orbit's 3.9992e-6 at 2800, after 837 periods).
use periodic_contact::analysis::continuation;
use periodic_contact::analysis::polish;
use periodic_contact::marching::{MarchResult, MarchSettings, march};
use periodic_contact::periodic::{PeriodicProblem, PeriodicSolver, Tuning};
use std::path::Path;

fn blade() -> PeriodicProblem {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-coarse.toml");
    let (scene, dir) = periodic_contact::scene::Scene::load(&path).unwrap();
    scene.build_in("blade", &dir).unwrap().problem
}

fn at(p: &PeriodicProblem, omega: f64) -> PeriodicProblem {
    let mut q = p.clone();
    q.set_frequency(omega).unwrap();
    q
}

/// 512 displacement samples of a polished orbit over its period.
fn sampled(orbit: &polish::PolishedOrbit, n: usize) -> Vec<Vec<f64>> {
    (0..512).map(|j| orbit.state(j as f64 * orbit.period() / 512.0).rows(0, n).iter().copied().collect()).collect()
}

/// Largest peak-to-peak over the model's DOFs of a sampled orbit.
fn ptp(samples: &[Vec<f64>]) -> f64 {
    let n = samples[0].len();
    (0..n).map(|d| samples.iter().map(|x| x[d]).fold(f64::MIN, f64::max) - samples.iter().map(|x| x[d]).fold(f64::MAX, f64::min)).fold(0.0, f64::max)
}

fn march_from(p: &PeriodicProblem, x0: &[f64], v0: &[f64]) -> MarchResult {
    let settings = MarchSettings {
        steps_per_period: 2048,
        max_periods: 4000,
        tolerance: 1e-7,
        initial_displacement: Some(x0.to_vec()),
        initial_velocity: Some(v0.to_vec()),
        ..MarchSettings::default()
    };
    march(p.model(), &settings).unwrap()
}

/// Either side of the continuation's tip (2796.03 rad/s; its zigzag [2795.83, 2796.10]).
const BELOW: f64 = 2792.0;
const ABOVE: f64 = 2800.0;

#[test]
fn time_marching_brackets_the_coarse_blades_resonance_tip() {
    let p = blade();
    let n = p.model().n();
    // The contact branch, followed up from 2300 rad/s (where it is the only orbit) in steps of
    // 20 rad/s, then to BELOW, as the FMU and the C API re-solve: continued along the branch from the current orbit
    // (`continuation::resolve`). A sweep's active-set warm start alone loses it near the tip (at
    // 2720 rad/s with 10 rad/s steps, at 2790 with 2).
    let disc = p.discretization();
    let mut tuning = Tuning::of(&p);
    tuning.frequency = 2300.0;
    let mut session = PeriodicSolver::new(at(&p, 2300.0));
    let mut r = session.solve().unwrap();
    for omega in (1..=24).map(|i| 2300.0 + 20.0 * i as f64).chain([BELOW]) {
        let next = Tuning { frequency: omega, ..tuning };
        let current = continuation::Current { tuning, disc, active_set: &r.active_set, amplitude: continuation::amplitude(&r), orbit: None, exact: true };
        let resolved = continuation::resolve(&mut session, &p, disc, next, Some(current)).unwrap();
        assert!(resolved.jump.is_none(), "no fold below the tip: {:?} at {}", resolved.jump, next.frequency);
        r = resolved.response;
        tuning = next;
    }
    let upper_problem = at(&p, BELOW);
    let orbit = polish::polish(&upper_problem, &r).unwrap();
    let upper = ptp(&sampled(&orbit, n));
    let y0 = orbit.state(0.0);
    let (x0, v0): (Vec<f64>, Vec<f64>) = (y0.rows(0, n).iter().copied().collect(), y0.rows(n, n).iter().copied().collect());
    // The contact-free orbit above the tip (the cold solve's: the only orbit there).
    let free = {
        let q = at(&p, ABOVE);
        let r = q.solve().unwrap();
        assert!(r.active_set.is_empty(), "the orbit at {ABOVE} rad/s touches the casing");
        ptp(&sampled(&polish::polish(&q, &r).unwrap(), n))
    };
    assert!(upper > 10.0 * free, "the contact orbit at {BELOW} ({upper:.3e}) is far above the contact-free one ({free:.3e})");

    let below = march_from(&upper_problem, &x0, &v0);
    let above = march_from(&at(&p, ABOVE), &x0, &v0);
    let (b, a) = (ptp(&below.displacement), ptp(&above.displacement));
    eprintln!(
        "coarse blade: contact orbit at {BELOW} rad/s ptp {upper:.4e}, marched {b:.4e} ({} periods, converged {}); at {ABOVE} marched {a:.4e} ({} periods, converged {}), contact-free orbit {free:.4e}",
        below.periods, below.converged, above.periods, above.converged
    );
    assert!(below.converged && (b - upper).abs() <= 1e-3 * upper, "below the tip the march stays on the contact orbit: {b:.4e} vs {upper:.4e}");
    assert!(above.converged && (a - free).abs() <= 1e-2 * free, "past the tip it falls to the contact-free orbit: {a:.4e} vs {free:.4e}");
}
