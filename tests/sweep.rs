//! Frequency sweeps of the coarse blade rubbing the casing: speed, the contact-induced shift of
//! the resonance, warm against cold starts, spectra, the CLI, and agreement with time marching.
use periodic_contact::periodic::{PeriodFft, PeriodicProblem};
use periodic_contact::scene::Scene;
use periodic_contact::sweep::{self, SweepSettings, marching};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

fn coarse() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-coarse.toml")
}

fn problem() -> PeriodicProblem {
    let (s, dir) = Scene::load(&coarse()).unwrap();
    s.build_in("blade-casing-coarse.toml", &dir).unwrap().problem
}

#[test]
fn coarse_blade_sweep_of_300_points_shows_the_stiffening_shift_of_the_resonance() {
    let t = Instant::now();
    let p = problem();
    let setup = t.elapsed().as_secs_f64();
    let freqs = sweep::linspace(2000.0, 2700.0, 300);
    let t = Instant::now();
    let points = sweep::run(&p, &freqs, &SweepSettings::default(), &|_| {}).unwrap();
    let wall = t.elapsed().as_secs_f64();
    let warm = points.iter().filter(|x| x.warm_start_used).count();
    eprintln!("coarse blade: set-up {setup:.2} s, 300-point sweep {wall:.2} s wall, {warm} warm-started");
    // Wall time is printed, not asserted: CI machines are loaded (issue 26).
    assert!(points.iter().all(|x| x.error.is_none()), "every point solves");
    assert!(warm > 250, "warm starts are used: {warm}");
    // Output 0 is the tip flap displacement (MC:y).
    let (f_lin, a_lin) = sweep::peak(&points, |x| x.linear_amplitude[0]).unwrap();
    let (f_nl, a_nl) = sweep::peak(&points, |x| x.amplitude[0]).unwrap();
    eprintln!("linear peak {a_lin:.4e} at ω = {f_lin:.2}; with contact {a_nl:.4e} at ω = {f_nl:.2} ({:+.2} %)", 100.0 * (f_nl / f_lin - 1.0));
    // The linear peak is the first bending mode (2 264.6 rad/s for the coarse blade).
    assert!((f_lin / 2264.64 - 1.0).abs() < 2e-3, "{f_lin}");
    // The stiff casing contact stiffens the blade: the peak moves up, by more than 2 %, and the
    // contact limits the amplitude.
    assert!(f_nl > 1.02 * f_lin, "peak with contact at {f_nl}, linear at {f_lin}");
    assert!(a_nl < a_lin);
    // Below resonance there is no contact and both curves coincide. (Above it the chunks now
    // follow the contact branch up as one sequential sweep does: the seams are re-checked.)
    for x in points.iter().filter(|x| x.frequency < 2150.0) {
        assert!(x.max_force.iter().all(|&f| f == 0.0), "contact at ω = {}", x.frequency);
        assert!((x.amplitude[0] - x.linear_amplitude[0]).abs() <= 1e-9 * x.linear_amplitude[0]);
    }
    // Contact on the branch leading to the shifted peak (above it the response has jumped down).
    let near = points.iter().filter(|x| x.frequency > f_nl - 40.0 && x.frequency <= f_nl).all(|x| x.contact_fraction[0] > 0.0);
    assert!(near, "the leading edge rubs near the shifted peak");
}

#[test]
fn warm_starts_save_pivots_and_agree_with_cold_solves_where_the_solution_is_unique() {
    let p = problem();
    let freqs = sweep::linspace(2150.0, 2450.0, 61);
    let one = SweepSettings { threads: 1, chunks_per_thread: 1, ..Default::default() };
    let warm = sweep::run(&p, &freqs, &one, &|_| {}).unwrap();
    let cold = sweep::run(&p, &freqs, &SweepSettings { warm_start: false, ..one.clone() }, &|_| {}).unwrap();
    let (pw, pc): (usize, usize) = (warm.iter().map(|x| x.pivots).sum(), cold.iter().map(|x| x.pivots).sum());
    eprintln!("pivots: warm {pw}, cold {pc}");
    assert!(pw < pc);
    assert!(warm.iter().skip(1).all(|x| x.warm_start_used && !x.cold_fallback));
    // Below the fold (ω < 2 320 rad/s) the periodic solution is unique: both agree.
    for (w, c) in warm.iter().zip(&cold).filter(|(w, _)| w.frequency < 2320.0) {
        for i in 0..w.amplitude.len() {
            assert!((w.amplitude[i] - c.amplitude[i]).abs() <= 1e-8 * c.amplitude[i], "ω = {}: {} vs {}", w.frequency, w.amplitude[i], c.amplitude[i]);
        }
    }
    // The sweep gives the same answers on two threads in contiguous chunks.
    let two = sweep::run(&p, &freqs, &SweepSettings { threads: 2, chunks_per_thread: 2, ..Default::default() }, &|_| {}).unwrap();
    for (a, b) in two.iter().zip(&warm).filter(|(a, _)| a.frequency < 2320.0) {
        assert_eq!(a.frequency, b.frequency);
        assert!((a.amplitude[0] - b.amplitude[0]).abs() <= 1e-8 * b.amplitude[0]);
    }
}

#[test]
fn spectrum_of_a_cosine_and_of_the_rubbing_blade() {
    let fft = PeriodFft::new(64);
    let x: Vec<f64> = (0..64).map(|j| 0.5 + 2.0 * (3.0 * 2.0 * std::f64::consts::PI * j as f64 / 64.0 + 0.3).cos()).collect();
    let a = sweep::spectrum::harmonic_amplitudes(&fft, &x);
    assert!((a[0] - 0.5).abs() < 1e-12 && (a[3] - 2.0).abs() < 1e-12);
    assert!(a.iter().enumerate().filter(|(p, _)| *p != 0 && *p != 3).all(|(_, v)| v.abs() < 1e-12));

    let mut p = problem();
    p.set_frequency(2300.0).unwrap();
    let r = p.solve().unwrap();
    let s = sweep::spectrum::spectrum(&p, &r, 20);
    assert_eq!(s.displacement.len(), 3);
    assert_eq!(s.force.len(), 3);
    let (_, flap) = &s.displacement[0];
    // The flap response is dominated by the forced harmonic; the rubbing force is rich in
    // higher harmonics.
    assert!(flap[1] > 10.0 * flap[2..].iter().copied().fold(0.0, f64::max));
    let le = &s.force[0].2;
    assert!(le[0] > 0.0 && le[1] > 0.0 && le[2] > 0.1 * le[1] && le[3] > 0.01 * le[1], "{le:?}");
}

#[test]
fn time_marching_agrees_with_the_lcp_at_three_sweep_points() {
    let p = problem();
    let opts = marching::MarchOptions { tolerances: vec![1e-6], reference_factor: 0, ..Default::default() };
    for f in [2220.0, 2260.0, 2300.0] {
        let c = marching::compare(&p, f, &opts).unwrap();
        let r = &c.runs[0];
        assert!(c.response.contacts[0].force.iter().any(|&x| x > 0.0), "ω = {f} is in contact");
        let txt: Vec<String> = r.error_vs_lcp.iter().map(|e| e.map_or("—".into(), |e| format!("{e:.2e}"))).collect();
        eprintln!(
            "ω = {f}: march N = {}/period, {} periods, {:.3} s; LCP (cold) {:.4} s; max |x_march − x_LCP| / amplitude (MC:y, LE, TE): {}",
            c.steps_per_period,
            r.periods,
            r.time_s,
            c.lcp_time_s,
            txt.join(", ")
        );
        assert!(r.converged);
        // Both are second-order discretisations of the same orbit (measured ≤ 1.3e-3 with
        // k = 512 and N ≈ 1 000): agreement within 5e-3 of the amplitude.
        for e in &r.error_vs_lcp {
            assert!(e.unwrap() < 5e-3, "ω = {f}: {e:?}");
        }
    }
}

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_periodic-contact"))
}

/// The header's columns as (key, unit): "amplitude_1903 [mm]" → ("amplitude_1903", "mm").
fn columns(head: &str) -> Vec<(&str, &str)> {
    head.split(',').map(|c| c.split_once(" [").map_or((c, ""), |(k, u)| (k, u.trim_end_matches(']')))).collect()
}

#[test]
fn cli_sweep_writes_the_csv_the_curves_and_the_spectra() {
    let dir = std::env::temp_dir().join(format!("pc-sweep-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The coarse blade's numbers, labelled in mm and kN (labels only: the solve is the same).
    let scene = dir.join("blade-mm.toml");
    let text = std::fs::read_to_string(coarse()).unwrap() + "\n[units]\nlength = \"mm\"\nforce = \"kN\"\n";
    std::fs::write(&scene, text).unwrap();
    let csv = dir.join("s.csv");
    let o = cli()
        .args(["sweep", scene.to_str().unwrap(), "--from", "2200", "--to", "2400", "--points", "21", "--threads", "2", "--spectrum-at", "2300", "-o"])
        .arg(&csv)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("21 solved, 0 failed"), "{err}");
    assert!(err.contains("frequency-response curve of MC:y") && err.contains("MC:y: peak with contact") && err.contains(" mm at ω = "), "{err}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let head = columns(lines.next().unwrap());
    let keys: Vec<&str> = head.iter().map(|c| c.0).collect();
    assert_eq!(head[0], ("frequency", "rad/s"));
    for col in [
        ("amplitude_1903", "mm"),
        ("linear_amplitude_1868", "mm"),
        ("max_force_c0_dof1868", "kN"),
        ("contact_fraction_c2_dof1940", ""),
        ("lcp_size", ""),
        ("pivots", ""),
        ("warm_start_used", ""),
        ("time_s", ""),
        ("status", ""),
    ] {
        assert!(head.contains(&col), "{col:?} missing from {head:?}");
    }
    assert!(keys.iter().enumerate().all(|(i, k)| !keys[..i].contains(k)), "a column twice: {keys:?}");
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 21);
    assert_eq!(rows[10][0].parse::<f64>().unwrap(), 2300.0);
    assert!(rows.iter().all(|r| r.last() == Some(&"solved") && r[keys.iter().position(|c| *c == "lcp_size").unwrap()] == "3072"));
    // 3 contacts × k = 1024: the scene's k since cds refuses k = 512 (ω_max·h = 3.35 > 2).
    if cfg!(feature = "plots") {
        for f in ["s.png", "s-dof1868.png", "s-spectrum-2300.png"] {
            assert!(std::fs::metadata(dir.join(f)).map(|m| m.len() > 1000).unwrap_or(false), "{f}");
        }
    }
    let spec = std::fs::read_to_string(dir.join("s-spectrum.csv")).unwrap();
    let spec_head = columns(spec.lines().next().unwrap());
    assert_eq!(spec_head[..4], [("frequency", "rad/s"), ("harmonic", ""), ("displacement_1903", "mm"), ("displacement_1868", "mm")], "{spec}");
    assert!(spec_head.iter().enumerate().all(|(i, c)| !spec_head[..i].iter().any(|d| d.0 == c.0)), "a column twice: {spec_head:?}");
    let force_col = spec_head.iter().position(|c| *c == ("force_c0_dof1868", "kN")).unwrap();
    let spec_rows: Vec<Vec<&str>> = spec.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(spec_rows.len(), 21, "harmonics 0..=20 at one point");

    // `solve --frequency` gives the sweep's point (a cold solve; below the fold it is unique).
    let out = dir.join("r.json");
    let o = cli().args(["solve", scene.to_str().unwrap(), "--frequency", "2300", "-o"]).arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let series = |v: &serde_json::Value| -> Vec<f64> { v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect() };
    let x = series(&v["displacement"]["1903"]);
    let amp = periodic_contact::response::Response::peak_to_peak(&x) / 2.0;
    let col = keys.iter().position(|c| *c == "amplitude_1903").unwrap();
    let swept: f64 = rows[10][col].parse().unwrap();
    assert!((amp - swept).abs() <= 1e-9 * swept, "{amp} vs {swept}");
    // Harmonic 0 of the spectrum is the mean contact force of the solve's samples.
    let force = series(&v["contacts"][0]["force"]);
    let mean = force.iter().sum::<f64>() / force.len() as f64;
    let (p0, f0): (&str, f64) = (spec_rows[0][1], spec_rows[0][force_col].parse().unwrap());
    assert_eq!(p0, "0");
    assert!(mean > 0.0 && (f0 - mean).abs() <= 1e-9 * mean, "harmonic 0 {f0} vs mean force {mean}");

    // The curve's axes name the DOF and the units.
    let built = Scene::load(&scene).map(|(s, d)| s.build_in("blade-mm.toml", &d).unwrap()).unwrap();
    let (xl, yl) = sweep::frc_axes("frequency", 1903, &built.labels);
    assert_eq!((xl.as_str(), yl.as_str()), ("excitation frequency ω [rad/s]", "amplitude of MC:y [mm] (peak-to-peak / 2)"));

    // `modes`: full against reduced.
    let o = cli().args(["modes", coarse().to_str().unwrap(), "--count", "5"]).output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && text.contains("rel. diff") && text.contains("1944 DOFs") && text.contains("23 DOFs"), "{text}");
    assert_eq!(text.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).count(), 5, "{text}");

    // Bad arguments exit 2 with a message.
    let o = cli().args(["sweep", coarse().to_str().unwrap(), "--from", "2200", "--to", "2400", "--param", "pressure"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--param"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A sequential sweep stays on the coarse blade's contact branch up to just below its resonance
/// tip (2796.03 rad/s by continuation; [2792, 2800] by time marching, tests/blade_fold.rs), above
/// the contact-free orbit that coexists there: where the active-set warm start lands on that
/// orbit (it did at 2720 rad/s with these 10 rad/s steps), the last orbit is continued to the new
/// frequency instead. Every point is in contact and the amplitude rises to the tip.
#[test]
fn a_sequential_sweep_stays_on_the_blades_contact_branch_up_to_the_tip() {
    let p = problem();
    let freqs: Vec<f64> = (0..=49).map(|i| 2300.0 + 10.0 * i as f64).collect();
    let one = SweepSettings { threads: 1, chunks_per_thread: 1, ..Default::default() };
    let points = sweep::run(&p, &freqs, &one, &|_| {}).unwrap();
    assert!(points.iter().all(|q| q.error.is_none() && q.contact_fraction.iter().any(|&c| c > 0.0)), "every point touches the casing");
    let amp: Vec<f64> = points.iter().map(|q| q.amplitude[0]).collect();
    assert!(amp.windows(2).all(|w| w[1] > w[0]), "the amplitude rises to the tip: {amp:?}");
    let mut free = p.clone();
    free.set_frequency(2790.0).unwrap();
    let cold = free.solve().unwrap();
    let cold_amp = periodic_contact::response::Response::peak_to_peak(&cold.displacement[&p.outputs().displacement[0].to_string()]) / 2.0;
    assert!(amp[49] > 10.0 * cold_amp, "at 2790 rad/s the branch ({}) lies far above the orbit a cold solve finds ({cold_amp})", amp[49]);
}

/// A chunk that starts cold on another orbit than the chunk before it ends on is repaired at the
/// seam: just below the coarse blade's tip (2796.03 rad/s), a cold solve at 2790 rad/s finds a far
/// smaller orbit than the contact branch the sequential sweep follows there from 2300 rad/s. Cut
/// into one chunk per point (each starting cold), the sweep re-checks every seam by continuing the
/// orbit of the point before and replaces the chunks that start elsewhere: every point equals
/// the sequential sweep's. Opt-in (11 s at load 12–15): `cargo test --release --test suite
/// sweep::a_chunk_starting_on_another_orbit_is_repaired_at_the_seam -- --ignored`.
#[test]
#[ignore]
fn a_chunk_starting_on_another_orbit_is_repaired_at_the_seam() {
    let p = problem();
    let freqs: Vec<f64> = (0..=49).map(|i| 2300.0 + 10.0 * i as f64).collect();
    let sequential = sweep::run(&p, &freqs, &SweepSettings { threads: 1, chunks_per_thread: 1, ..Default::default() }, &|_| {}).unwrap();
    let t = Instant::now();
    let chunked = sweep::run(&p, &freqs, &SweepSettings { threads: 1, chunks_per_thread: 50, ..Default::default() }, &|_| {}).unwrap();
    eprintln!("50 chunks with the seam checks: {:.2} s", t.elapsed().as_secs_f64());
    let mut cold = p.clone();
    cold.set_frequency(2790.0).unwrap();
    let cold = cold.solve().unwrap();
    let cold_amp = periodic_contact::response::Response::peak_to_peak(&cold.displacement[&p.outputs().displacement[0].to_string()]) / 2.0;
    eprintln!("2790 rad/s: branch {:.4e}, cold solve {cold_amp:.4e}", sequential[49].amplitude[0]);
    assert!(sequential[49].amplitude[0] > 2.0 * cold_amp, "a cold start at the seam lands on another orbit than the branch");
    for (a, b) in sequential.iter().zip(&chunked) {
        let worst = a.amplitude.iter().zip(&b.amplitude).fold(0.0f64, |w, (x, y)| w.max((x - y).abs() / x.abs()));
        eprintln!("ω = {}: chunked against sequential {worst:.1e}", a.frequency);
        assert!(b.error.is_none() && worst <= 1e-9, "ω = {}: {worst:e}", a.frequency);
    }
}

/// `sweep::jumps` finds the one jump of a swept curve, wherever the grid puts it, and nothing on
/// smooth curves: a resonance peak (steep flanks, 200 points) and the same peak cut at a fold-like
/// drop at x = 1.9 (the 3-DOF chain's 0.46 → 0.25 m), on grids of 50, 200 and 800 points.
#[test]
fn jumps_are_found_where_the_curve_drops_and_nowhere_on_a_smooth_peak() {
    let peak = |x: f64| 0.1 / ((1.0 - (x / 1.5).powi(2)).powi(2) + (0.05 * x / 1.5).powi(2)).sqrt();
    for n in [50, 200, 800] {
        let grid: Vec<f64> = (0..n).map(|i| 1.0 + 1.5 * i as f64 / (n - 1) as f64).collect();
        let smooth: Vec<(f64, f64)> = grid.iter().map(|&x| (x, peak(x))).collect();
        assert!(sweep::jumps(&smooth).is_empty(), "n = {n}: {:?}", sweep::jumps(&smooth));
        let cut: Vec<(f64, f64)> = grid.iter().map(|&x| (x, if x < 1.9 { 0.46 - 0.05 * (1.9 - x) } else { 0.25 - 0.1 * (x - 1.9) })).collect();
        let found = sweep::jumps(&cut);
        assert_eq!(found.len(), 1, "n = {n}: {found:?}");
        let (a, b) = found[0];
        assert!(a.0 < 1.9 && b.0 >= 1.9 && b.0 - a.0 < 2.0 / n as f64, "n = {n}: jump between {} and {}", a.0, b.0);
    }
    assert_eq!(sweep::peak_ratio(0.5, 9.0), 18.0);
}

/// `SweepSettings::estimate` gives every point the estimate of a standalone solve
/// (`accuracy::estimate`, a cold second solve) although its second grid is warm-started along
/// the sweep: below the fold the orbits are unique, so both agree to round-off.
#[test]
fn sweep_estimates_every_point_as_a_standalone_solve_does() {
    // bds2 at k = 256 (compliant contacts: second order, no stability limit) keeps it quick.
    let mut p = problem();
    p.set_discretization(periodic_contact::time::Discretization { scheme: periodic_contact::time::Scheme::Bds2, steps: 256, pairing: None }).unwrap();
    let freqs = sweep::linspace(2200.0, 2300.0, 4);
    let settings = SweepSettings { threads: 1, chunks_per_thread: 1, estimate: true, ..Default::default() };
    let points = sweep::run(&p, &freqs, &settings, &|_| {}).unwrap();
    for x in &points {
        let mut q = p.clone();
        q.set_parallel(false);
        let mut solver = periodic_contact::periodic::PeriodicSolver::new(q);
        solver.update_frequency(x.frequency).unwrap();
        let r = solver.solve().unwrap();
        let alone = periodic_contact::analysis::accuracy::estimate(solver.problem(), &r);
        let (e, a) = (x.estimate_relative.unwrap(), alone.relative.unwrap());
        eprintln!("ω = {}: sweep estimate {e:.3e}, standalone {a:.3e} ({})", x.frequency, x.estimate_method);
        assert!(e > 0.0 && (e - a).abs() <= 1e-6 * a, "ω = {}: {e} vs {a}", x.frequency);
        assert_eq!(x.estimate_method, alone.method);
    }
    // Without the setting no estimate is made.
    let plain = sweep::run(&p, &freqs[..1], &SweepSettings { estimate: false, ..settings }, &|_| {}).unwrap();
    assert!(plain[0].estimate_relative.is_none() && plain[0].estimate_method.is_empty());
}

/// The chain with its two rigid stops at k = 2560: N = 5120, above the dense fallback's quick
/// size (4096), so its sweeps are guarded.
fn large_chain() -> PeriodicProblem {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/chain-3dof-two-stops.toml"))
        .unwrap()
        .replace("steps = 256", "steps = 2560");
    Scene::parse(&text, "chain").unwrap().to_problem("chain").unwrap()
}

/// The guarded sweep of `large_chain` over 5 points with estimates.
fn guarded_sweep() -> (Vec<f64>, Vec<sweep::SweepPoint>) {
    let freqs = sweep::linspace(0.5, 0.7, 5);
    let settings = SweepSettings { threads: 1, chunks_per_thread: 1, estimate: true, ..Default::default() };
    let t = Instant::now();
    let points = sweep::run(&large_chain(), &freqs, &settings, &|_| {}).unwrap();
    eprintln!("guarded sweep, 5 points at N = 5120 with estimates: {:.2} s", t.elapsed().as_secs_f64());
    (freqs, points)
}

/// A sweep over an LCP above the dense fallback's quick size is guarded: shooting (ω sub-steps
/// where it misses), never the dense fallback, and its error estimates start from the point's
/// own active set carried to k/2. Every point is solved and estimated, by shooting alone.
#[test]
fn a_guarded_sweep_solves_and_estimates_every_point_by_shooting() {
    let (_, points) = guarded_sweep();
    for x in &points {
        eprintln!("ω = {}: {} ({} sub-steps), estimate {:?}, {:?}", x.frequency, sweep::solver_label(&x.lcp_path), x.substeps, x.estimate_relative, x.error);
        assert!(x.error.is_none() && x.estimate_relative.is_some(), "ω = {}: {:?} {}", x.frequency, x.error, x.estimate_method);
        assert_eq!(sweep::solver_label(&x.lcp_path), "shooting", "no dense fallback in a guarded sweep");
    }
    assert!(points.iter().any(|x| x.max_force.iter().any(|&f| f > 0.0)), "the stops are hit");
}

/// The guarded sweep's middle point equals dense lexicographic Lemke on the same LCP (the
/// independent reference). Opt-in (dense Lemke at N = 5120: about 100 s at load 10):
/// `cargo test --release --test suite sweep::a_guarded_sweep_equals_dense_lemke -- --ignored`.
#[test]
#[ignore]
fn a_guarded_sweep_equals_dense_lemke() {
    use periodic_contact::periodic::{LcpMethod, PeriodicSolver, SolverSettings};
    let (freqs, points) = guarded_sweep();
    let mut lemke = large_chain();
    lemke.set_frequency(freqs[2]).unwrap();
    lemke.set_solver_settings(SolverSettings { method: LcpMethod::Lemke, ..lemke.solver_settings().clone() }).unwrap();
    let t = Instant::now();
    let r = PeriodicSolver::new(lemke).solve().unwrap();
    eprintln!("dense Lemke at N = 5120: {:.2} s, {} pivots", t.elapsed().as_secs_f64(), r.lcp.pivots);
    for (i, d) in ["0", "1", "2"].iter().enumerate() {
        let a = periodic_contact::response::Response::peak_to_peak(&r.displacement[*d]) / 2.0;
        let ours = points[2].amplitude[i];
        assert!((a - ours).abs() <= 1e-9 * a, "DOF {d}: sweep {ours:e}, Lemke {a:e}");
    }
}

/// A guarded sweep's failed points are retried from their nearest solved neighbour
/// (`sweep::refill`, what recovers the real blade's points past the fold, issue 23): the three
/// middle points of `guarded_sweep`, struck out, come back from the point after them by warm
/// shooting. Each equals a cold standalone solve at its ω to 1e-9 of the amplitude where cold
/// shooting converges (0.55 and 0.6; it misses at 0.65, which the refill solves); at the first
/// (ω = 0.55) that solve agrees with explicit time marching from rest at 4k steps per period
/// (the independent reference, another discretisation of the same orbit; measured 5.5e-4) to
/// 2e-3 of the amplitude. (At ω = 0.6 the march has not settled after 20 000 periods: not used.)
#[test]
fn failed_points_of_a_guarded_sweep_are_refilled_from_their_neighbours() {
    let (_, mut points) = guarded_sweep();
    for x in &mut points[1..4] {
        *x = sweep::SweepPoint { frequency: x.frequency, error: Some("struck out".to_string()), ..Default::default() };
    }
    let settings = SweepSettings { threads: 1, chunks_per_thread: 1, ..Default::default() };
    let t = Instant::now();
    sweep::refill(&large_chain(), &mut points, &settings);
    eprintln!("refill of 3 points: {:.2} s", t.elapsed().as_secs_f64());
    let opts = marching::MarchOptions { tolerances: vec![1e-8], reference_factor: 0, steps_per_period: Some(4 * 2560), ..Default::default() };
    let mut compared = 0;
    for (i, x) in points[1..4].iter().enumerate() {
        assert!(x.error.is_none() && x.warm_start_used, "ω = {}: {:?}", x.frequency, x.error);
        // The cold solve: shooting from the contact-free orbit, nothing carried from the sweep.
        let mut cold = periodic_contact::periodic::PeriodicSolver::new(large_chain());
        cold.update_frequency(x.frequency).unwrap();
        let Ok(alone) = cold.solve_by_shooting(false) else {
            // Cold shooting misses here (as on the real blade past its fold): the refill is what solves it.
            eprintln!("ω = {}: cold shooting misses; refilled with amplitudes {:?}", x.frequency, x.amplitude);
            continue;
        };
        compared += 1;
        let amplitude = |d: usize| periodic_contact::response::Response::peak_to_peak(&alone.displacement[&d.to_string()]) / 2.0;
        let scale = x.amplitude.iter().fold(0.0f64, |a, v| a.max(*v));
        let worst = large_chain().outputs().displacement.iter().zip(&x.amplitude).fold(0.0f64, |a, (d, v)| a.max((amplitude(*d) - v).abs()));
        eprintln!("ω = {}: refilled against a cold solve {:.1e} of the amplitude", x.frequency, worst / scale);
        assert!(x.max_force.iter().any(|&f| f > 0.0), "ω = {}: the stops are hit", x.frequency);
        assert!(worst <= 1e-9 * scale, "ω = {}: {worst:e} against {scale:e}", x.frequency);
        if i == 0 {
            let c = marching::compare(&large_chain(), x.frequency, &opts).unwrap();
            let run = &c.runs[0];
            eprintln!("  march ({} periods) against the cold solve: {:?}", run.periods, run.error_vs_lcp);
            assert!(run.converged && run.error_vs_lcp.iter().all(|e| e.unwrap() < 2e-3), "ω = {}: {:?}", x.frequency, run.error_vs_lcp);
        }
    }
    assert!(compared >= 2, "{compared} refilled points compared with a cold solve");
}

/// `SweepSettings::tolerance` refines each point whose estimate exceeds it, k → 2k up to
/// `max_steps`. On the two-stop chain from k = 256 (estimates 5.7e-4 and 1.7e-4 at ω = 0.5 and
/// 0.7, both above the tolerance): every point ends within the tolerance or at the cap; a
/// refined point's amplitudes equal dense lexicographic Lemke's on its own grid (the
/// independent solver), and its true error, against cold shooting at 4× its k (nothing carried
/// from the sweep), is below the k = 256 answer's (Lemke): 5.7e-4 → 1.3e-4 at ω = 0.5, only
/// 3.3e-4 → 2.3e-4 at ω = 0.7 (not yet asymptotic there). The estimate against that true error
/// is printed, not asserted: at ω = 0.7 it reads 4.8× low (4.9e-5 against 2.3e-4).
#[test]
fn a_tolerance_refines_the_points_whose_estimate_exceeds_it() {
    use periodic_contact::periodic::{LcpMethod, PeriodicSolver, SolverSettings};
    use periodic_contact::response::Response;
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/chain-3dof-two-stops.toml")).unwrap();
    let p = Scene::parse(&text, "chain").unwrap().to_problem("chain").unwrap();
    let (tolerance, max_steps) = (1.5e-4, 512);
    let settings = SweepSettings { threads: 1, chunks_per_thread: 1, estimate: true, tolerance: Some(tolerance), max_steps, ..Default::default() };
    let t = Instant::now();
    let points = sweep::run(&p, &[0.5, 0.7], &settings, &|_| {}).unwrap();
    eprintln!("2 points refined to {tolerance:e}: {:.2} s", t.elapsed().as_secs_f64());
    let at = |f: f64, steps: usize, method: LcpMethod| {
        let mut q = p.clone();
        q.set_discretization(periodic_contact::time::Discretization { steps, ..p.discretization() }).unwrap();
        q.set_frequency(f).unwrap();
        q.set_solver_settings(SolverSettings { method, ..q.solver_settings().clone() }).unwrap();
        let mut solver = PeriodicSolver::new(q);
        if method == LcpMethod::Shooting { solver.solve_by_shooting(false) } else { solver.solve() }
    };
    let mut compared = 0;
    for x in &points {
        let e = x.estimate_relative.unwrap();
        eprintln!("ω = {}: k = {}, estimate {e:.2e} ({})", x.frequency, x.steps, x.estimate_method);
        assert!(x.error.is_none() && (e <= tolerance || x.steps == max_steps), "ω = {}: {e} at k = {}", x.frequency, x.steps);
        assert!(x.steps > 256, "ω = {}: not refined", x.frequency);
        let own = at(x.frequency, x.steps, LcpMethod::Lemke).unwrap();
        let Ok(fine) = at(x.frequency, 4 * x.steps, LcpMethod::Shooting) else {
            eprintln!("  cold shooting at k = {} misses: no true error here", 4 * x.steps);
            continue;
        };
        for (i, d) in p.outputs().displacement.iter().enumerate() {
            let amp = Response::peak_to_peak(&own.displacement[&d.to_string()]) / 2.0;
            assert!((amp - x.amplitude[i]).abs() <= 1e-9 * amp, "ω = {}, DOF {d}: sweep {:e}, Lemke {amp:e}", x.frequency, x.amplitude[i]);
        }
        // The largest deviation at the shared instants, relative to the peak-to-peak amplitude.
        let error = |r: &Response| {
            let (mut diff, mut ptp) = (0.0f64, 0.0f64);
            for d in p.outputs().displacement.iter().map(ToString::to_string) {
                let (a, b) = (&r.displacement[&d], &fine.displacement[&d]);
                let stride = b.len() / a.len();
                diff = a.iter().enumerate().fold(diff, |m, (j, v)| m.max((v - b[stride * j]).abs()));
                ptp = ptp.max(Response::peak_to_peak(a));
            }
            diff / ptp
        };
        let (truth, before) = (error(&own), error(&at(x.frequency, 256, LcpMethod::Lemke).unwrap()));
        eprintln!("  true error against cold shooting at k = {}: {truth:.2e} (estimate {e:.2e}); at k = 256 {before:.2e}", 4 * x.steps);
        assert!(truth < before, "ω = {}: refined {truth:e}, k = 256 {before:e}", x.frequency);
        compared += 1;
    }
    assert!(compared >= 1, "no refined point compared with its true error");
}

/// The k/4 solve a sweep with a tolerance skips (`accuracy::least_estimate`, Richardson at the
/// scheme's order from k/2) is a floor of the estimate it would have given: on the two-stop chain
/// at k = 256 (dense Lemke on each grid), at ω where the observed order differs from the scheme's
/// (0.61 and 0.64: an impact beside a sticking arc; 0.85: k/4 not asymptotic), the estimate with
/// k/4 and without it are both at least the floor, so a point above the tolerance by the floor is
/// refined whatever k/4 says.
#[test]
fn the_skipped_quarter_grid_could_not_have_kept_a_point_within_the_tolerance() {
    use periodic_contact::analysis::accuracy;
    use periodic_contact::periodic::{LcpMethod, PeriodicSolver, SolverSettings};
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/chain-3dof-two-stops.toml")).unwrap();
    let p = Scene::parse(&text, "chain").unwrap().to_problem("chain").unwrap();
    let at = |f: f64, steps: usize| {
        let mut q = p.clone();
        q.set_discretization(periodic_contact::time::Discretization { steps, ..p.discretization() }).unwrap();
        q.set_frequency(f).unwrap();
        q.set_solver_settings(SolverSettings { method: LcpMethod::Lemke, ..q.solver_settings().clone() }).unwrap();
        let r = PeriodicSolver::new(q.clone()).solve().unwrap();
        (q, r)
    };
    for f in [0.5, 0.61, 0.64, 0.7, 0.85] {
        let ((q, r), (_, half), (_, quarter)) = (at(f, 256), at(f, 128), at(f, 64));
        let floor = accuracy::least_estimate(&q, &r, &half, "k/2").relative.unwrap();
        let with = accuracy::estimate_from(&q, &r, &half, Some(&quarter), "k/2").relative.unwrap();
        let without = accuracy::estimate_from(&q, &r, &half, None, "k/2").relative.unwrap();
        eprintln!("ω = {f}: floor {floor:.3e}, with k/4 {with:.3e}, without {without:.3e}");
        assert!(floor > 0.0 && floor <= with * (1.0 + 1e-12) && floor <= without * (1.0 + 1e-12), "ω = {f}: floor {floor:e}, {with:e}, {without:e}");
    }
}

/// A point after one that needed 4k or more skips its own k/2 and k/4 solves and is refined at
/// once (`refine::estimate`'s prediction; issue 23). The reference is the same point swept alone
/// (no previous point: the full climb from k = 256): the swept point ends at the same k with the
/// same estimate and amplitudes (to the LCP's tolerance), or, where the climb stops at k, at 2k
/// within the tolerance.
#[test]
fn a_point_after_a_finely_refined_one_skips_the_first_grid_estimate_and_ends_where_the_climb_does() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/chain-3dof-two-stops.toml")).unwrap();
    let p = Scene::parse(&text, "chain").unwrap().to_problem("chain").unwrap();
    let k0 = p.discretization().steps;
    let settings = SweepSettings { threads: 1, chunks_per_thread: 1, estimate: true, tolerance: Some(1e-3), max_steps: 8192, ..Default::default() };
    let freqs = sweep::linspace(0.5, 0.9, 21);
    let swept = sweep::run(&p, &freqs, &settings, &|_| {}).unwrap();
    let mut skipped = 0;
    for i in 1..freqs.len() {
        if swept[i - 1].steps < 4 * k0 {
            continue;
        }
        skipped += 1;
        let alone = &sweep::run(&p, &freqs[i..=i], &settings, &|_| {}).unwrap()[0];
        let (s, a) = (&swept[i], alone);
        let (es, ea) = (s.estimate_relative.unwrap(), a.estimate_relative.unwrap());
        eprintln!("ω = {:.2}: swept k = {} ({es:.3e}), alone k = {} ({ea:.3e})", freqs[i], s.steps, a.steps);
        if a.steps == k0 && s.steps == 2 * k0 {
            assert!(es <= 1e-3, "ω = {}: {es:e} ({})", freqs[i], s.estimate_method);
            continue;
        }
        assert_eq!(s.steps, a.steps, "ω = {}: {} against {}", freqs[i], s.estimate_method, a.estimate_method);
        assert!((es - ea).abs() <= 1e-6 * ea, "ω = {}: {es:e} against {ea:e}", freqs[i]);
        let big = a.amplitude.iter().copied().fold(0.0, f64::max);
        for (x, y) in s.amplitude.iter().zip(&a.amplitude) {
            assert!((x - y).abs() <= 1e-8 * big, "ω = {}: amplitude {x:e} against {y:e}", freqs[i]);
        }
    }
    assert!(skipped >= 5, "{skipped} points followed one at 4k or more");
}
