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
use periodic_contact::response::Response;

#[path = "honesty/grids.rs"]
mod grids;

fn main() {
    // k/4, k/2, k, 4k.
    let mut g = grids::Grids::from_args(&[1, 2, 4, 16]);
    let k = g.k;
    println!("omega k old_est new_est true_largest true_own est_own ratio_old ratio_new ratio_own observed_order method");
    for draw in 0..g.draws {
        let omega = g.omega(draw);
        let t = std::time::Instant::now();
        let Some((first, others)) = g.solve(omega, 2) else { continue };
        let (quarter, [Some(half), Some(fine)]) = (others[0].as_ref(), [&others[1], &others[3]]) else {
            println!("{omega:.2} {k} a second grid missed");
            continue;
        };
        let p = g.solvers[2].problem();
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
