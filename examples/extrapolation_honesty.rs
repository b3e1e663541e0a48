//! The Richardson-extrapolated answer against the true error on random frequencies of one scene
//! (issue 23): for random ω in [lo, hi] (seeded), the scene solved at k/4, k/2, k (shooting, the
//! coarser grids warm-started from the k answer's active set carried there) and at 4k and 8k (the
//! reference). The extrapolated answer R_k = x_k + (x_k − x_{k/2})/3 on the k/2 shared instants
//! (order 2), its estimate max |R_k − R_{k/2}| (R_{k/2} from k/2 and k/4, on the k/4 instants)
//! against its true error max |R_k − x_{8k}| (x_{8k}'s own error, about |x_{8k} − x_{4k}|/3, printed
//! beside it), both over the largest peak-to-peak amplitude.
//!
//! `cargo run --release --example extrapolation_honesty -- SCENE LO HI DRAWS K [SEED]`
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
    let base = scene.to_problem(&a[1]).unwrap();
    let m = base.model().contacts.len().max(1);
    let grid = |steps: usize| {
        let mut p = base.clone();
        p.set_discretization(Discretization { steps, ..base.discretization() }).unwrap();
        PeriodicSolver::new(p)
    };
    let mut solvers: Vec<PeriodicSolver> = [k / 4, k / 2, k, 4 * k, 8 * k].iter().map(|&s| grid(s)).collect();
    println!("omega k plain_est plain_true extrap_est extrap_true ref_own ratio_extrap method");
    for draw in 0..draws {
        let omega = if draws == 1 { lo } else { SplitMix::for_draw(seed, draw).uniform((lo, hi)) };
        let t = std::time::Instant::now();
        let s = &mut solvers[2];
        s.update_frequency(omega).unwrap();
        let Ok(first) = s.solve_by_shooting(false) else {
            println!("{omega:.2} {k} cold shooting missed at k");
            continue;
        };
        let mut others: Vec<Option<Response>> = vec![];
        for i in [0, 1, 3, 4] {
            let s = &mut solvers[i];
            if s.update_frequency(omega).is_err() {
                others.push(None);
                continue;
            }
            s.set_warm_start(&carried_active_set(&first.active_set, m, k, s.problem().instants()));
            let r = s.solve_by_shooting(true).or_else(|_| s.solve_by_shooting(false));
            others.push(r.ok());
        }
        let [Some(quarter), Some(half), Some(four), Some(eight)] = [&others[0], &others[1], &others[2], &others[3]] else {
            println!("{omega:.2} {k} a grid missed: {:?}", others.iter().map(|o| o.is_some()).collect::<Vec<_>>());
            continue;
        };
        let p = solvers[2].problem();
        let plain = accuracy::estimate_from(p, &first, half, Some(quarter), "k/2");
        let (mut est, mut truth, mut plain_truth, mut ref_own, mut ptp) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for (key, x) in &first.displacement {
            let (xh, xq, x4, x8) = (&half.displacement[key], &quarter.displacement[key], &four.displacement[key], &eight.displacement[key]);
            let r_k: Vec<f64> = (0..k / 2).map(|j| x[2 * j] + (x[2 * j] - xh[j]) / 3.0).collect();
            let r_half: Vec<f64> = (0..k / 4).map(|i| xh[2 * i] + (xh[2 * i] - xq[i]) / 3.0).collect();
            est = est.max((0..k / 4).map(|i| (r_k[2 * i] - r_half[i]).abs()).fold(0.0, f64::max));
            truth = truth.max((0..k / 2).map(|j| (r_k[j] - x8[16 * j]).abs()).fold(0.0, f64::max));
            plain_truth = plain_truth.max((0..k).map(|j| (x[j] - x8[8 * j]).abs()).fold(0.0, f64::max));
            ref_own = ref_own.max((0..4 * k).map(|j| (x8[2 * j] - x4[j]).abs() / 3.0).fold(0.0, f64::max));
            ptp = ptp.max(Response::peak_to_peak(x));
        }
        println!(
            "{omega:.2} {k} {:.3e} {:.3e} {:.3e} {:.3e} {:.3e} {:.2} {} ({:.1} s)",
            plain.relative.unwrap_or(f64::NAN),
            plain_truth / ptp,
            est / ptp,
            truth / ptp,
            ref_own / ptp,
            est / truth,
            plain.method,
            t.elapsed().as_secs_f64()
        );
    }
}
