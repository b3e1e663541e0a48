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
use periodic_contact::response::Response;

#[path = "honesty/grids.rs"]
mod grids;

fn main() {
    // k/4, k/2, k, 4k, 8k.
    let mut g = grids::Grids::from_args(&[1, 2, 4, 16, 32]);
    let k = g.k;
    println!("omega k plain_est plain_true extrap_est extrap_true ref_own ratio_extrap method");
    for draw in 0..g.draws {
        let omega = g.omega(draw);
        let t = std::time::Instant::now();
        let Some((first, others)) = g.solve(omega, 2) else { continue };
        let [Some(quarter), Some(half), _, Some(four), Some(eight)] = [&others[0], &others[1], &others[2], &others[3], &others[4]] else {
            println!("{omega:.2} {k} a grid missed: {:?}", others.iter().map(|o| o.is_some()).collect::<Vec<_>>());
            continue;
        };
        let p = g.solvers[2].problem();
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
