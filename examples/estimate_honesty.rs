//! The error estimate against the true error on a family of frequencies of one scene (issue 23):
//! for random ω in [lo, hi] (seeded), the scene solved at k/4, k/2, k and 4k (shooting, each grid
//! warm-started from the k answer's active set carried there); the estimate at k
//! (`analysis::accuracy::estimate_from`: Richardson from k/2, with k/4 for the observed order) against the
//! true error, the k answer against the 4k one at the k instants (an independent, finer solve of
//! the same LCP family; at order p it understates the true error by 4^−p). Both measures:
//! relative to the largest output's peak-to-peak amplitude, and to each output's own.
//!
//! `cargo run --release --example estimate_honesty -- SCENE LO HI DRAWS K [SEED]`
use periodic_contact::analysis::accuracy;
use periodic_contact::periodic::{PeriodicSolver, carried_active_set};
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;
use periodic_contact::study::families::SplitMix;
use periodic_contact::time::Discretization;
use std::path::Path;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (lo, hi): (f64, f64) = (a[2].parse().unwrap(), a[3].parse().unwrap());
    let (draws, k): (usize, usize) = (a[4].parse().unwrap(), a[5].parse().unwrap());
    let seed: u64 = a.get(6).map_or(23, |s| s.parse().unwrap());
    let (scene, _) = Scene::load(Path::new(&a[1])).unwrap();
    let t = std::time::Instant::now();
    let base = scene.to_problem(&a[1]).unwrap();
    eprintln!("set-up {:.1} s", t.elapsed().as_secs_f64());
    let m = base.model().contacts.len().max(1);
    let grid = |steps: usize| {
        let mut p = base.clone();
        p.set_discretization(Discretization { steps, ..base.discretization() }).unwrap();
        PeriodicSolver::new(p)
    };
    let mut solvers: Vec<PeriodicSolver> = [k / 4, k / 2, k, 4 * k].iter().map(|&s| grid(s)).collect();
    println!("omega k old_est new_est true_largest true_own est_own ratio_old ratio_new ratio_own observed_order method");
    for draw in 0..draws {
        let omega = if draws == 1 { lo } else { SplitMix::for_draw(seed, draw).uniform((lo, hi)) };
        let t = std::time::Instant::now();
        let s = &mut solvers[2];
        s.update_frequency(omega).unwrap();
        let first = s.solve_by_shooting(false);
        let Ok(first) = first else {
            println!("{omega:.2} {k} cold shooting missed at k");
            continue;
        };
        let mut others: Vec<Option<Response>> = vec![];
        for i in [0, 1, 3] {
            let s = &mut solvers[i];
            // k/4 may break the scheme's stability limit: the estimate then has two grids.
            if s.update_frequency(omega).is_err() {
                others.push(None);
                continue;
            }
            s.set_warm_start(&carried_active_set(&first.active_set, m, k, s.problem().instants()));
            let r = s.solve_by_shooting(true).or_else(|_| s.solve_by_shooting(false));
            others.push(r.ok());
        }
        let (quarter, [Some(half), Some(fine)]) = (others[0].as_ref(), [&others[1], &others[2]]) else {
            println!("{omega:.2} {k} a second grid missed");
            continue;
        };
        let p = solvers[2].problem();
        let old = accuracy::estimate_from(p, &first, half, None, "k/2");
        let new = accuracy::estimate_from(p, &first, half, quarter, "k/2");
        let (mut diff_own, mut diff, mut ptp) = (0.0f64, 0.0f64, 0.0f64);
        for (key, x) in &first.displacement {
            let y = &fine.displacement[key];
            let d = x.iter().enumerate().map(|(j, v)| (v - y[4 * j]).abs()).fold(0.0, f64::max);
            diff = diff.max(d);
            diff_own = diff_own.max(d / Response::peak_to_peak(x));
            ptp = ptp.max(Response::peak_to_peak(x));
        }
        let truth = diff / ptp;
        let (o, n) = (old.relative.unwrap_or(f64::NAN), new.relative.unwrap_or(f64::NAN));
        let own = new.relative_own.unwrap_or(f64::NAN);
        println!(
            "{omega:.2} {k} {o:.3e} {n:.3e} {truth:.3e} {diff_own:.3e} {own:.3e} {:.2} {:.2} {:.2} {} ({:.1} s)",
            o / truth,
            n / truth,
            own / diff_own,
            new.method,
            t.elapsed().as_secs_f64()
        );
    }
}
