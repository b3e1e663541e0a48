//! Every shipped scene through every front end: the CLI's JSON, the C API (called through its
//! `extern "C"` functions, as a C program does) and the FMU driven by a Rust FMI host give the same
//! displacements at the k instants, to 1e-9 of each output's peak-to-peak amplitude. The reduced
//! blades are the case that once failed in the C API and the FMU (outputs named in the full
//! model's numbering). fmpy runs the same matrix in validation/test_frontends.py.
use crate::common;

use common::host::*;
use periodic_contact::capi::*;
use std::ffi::{CStr, CString};

const TOL: f64 = 1e-9;

fn assert_same(scene: &str, front_end: &str, key: &str, got: &[f64], cli: &[f64]) {
    let (lo, hi) = cli.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| (l.min(x), h.max(x)));
    let scale = (hi - lo).max(f64::MIN_POSITIVE);
    let worst = got.iter().zip(cli).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert_eq!(got.len(), cli.len(), "{scene}: {front_end} displacement[{key}] has {} samples, the CLI {}", got.len(), cli.len());
    assert!(worst <= TOL * scale, "{scene}: {front_end} displacement[{key}] differs from the CLI by {worst:e} (peak-to-peak {scale:e})");
}

/// The C API's displacements for the CLI's keys (the scene file: its referenced files resolve
/// relative to it).
fn c_api(scene: &std::path::Path, keys: &[String], k: usize) -> Vec<Vec<f64>> {
    let path = CString::new(scene.to_str().unwrap()).unwrap();
    let last_error = || unsafe { CStr::from_ptr(pc_last_error()) }.to_string_lossy().into_owned();
    let p = unsafe { pc_problem_from_scene_file(path.as_ptr()) };
    assert!(!p.is_null(), "pc_problem_from_scene_file: {}", last_error());
    let r = unsafe { pc_problem_solve(p) };
    assert!(!r.is_null(), "pc_problem_solve: {}", last_error());
    assert_eq!(unsafe { pc_result_steps(r) }, k);
    let out = keys
        .iter()
        .map(|key| {
            let mut x = vec![f64::NAN; k];
            let status = unsafe { pc_result_displacement(r, key.parse().unwrap(), x.as_mut_ptr(), k) };
            assert_eq!(status, 0, "pc_result_displacement({key}): {}", last_error());
            x
        })
        .collect();
    unsafe {
        pc_result_free(r);
        pc_problem_free(p);
    }
    out
}

/// The FMU's displacements after each of k steps of T/k from t = 0: sample j + 1 of the period.
fn fmu(name: &str, scene: &std::path::Path, keys: &[String], k: usize, period: f64) -> Vec<Vec<f64>> {
    let fmu = Fmu::package_scene(name, scene);
    let s = fmu.instantiate(name).expect("instantiated");
    s.init(0.0);
    let names: Vec<String> = keys.iter().map(|d| format!("displacement[{d}]")).collect();
    let vrs: Vec<u32> = names.iter().map(|n| s.vr(n)).collect();
    let h = period / k as f64;
    let mut out = vec![vec![0.0; k]; keys.len()];
    for i in 0..k {
        assert_eq!(s.step(i as f64 * h, h), 0, "{name}: fmi2DoStep at step {i}; log {:?}", s.log.all());
        let (status, v) = s.get_reals(&vrs);
        assert_eq!(status, 0);
        for (series, value) in out.iter_mut().zip(v) {
            series[(i + 1) % k] = value;
        }
    }
    out
}

#[test]
fn every_shipped_scene_gives_the_same_displacements_in_the_cli_the_c_api_and_the_fmu() {
    for scene in shipped_scenes() {
        let name = scene.file_stem().unwrap().to_string_lossy().replace('-', "_");
        // A copy of the scene (with the files it references) in a scratch folder, and its CLI JSON.
        let (copy, json) = shipped_solution(&scene);
        let k = json["steps"].as_u64().unwrap() as usize;
        let period = json["period"].as_f64().unwrap();
        let keys: Vec<String> = json["displacement"].as_object().unwrap().keys().cloned().collect();
        assert!(!keys.is_empty(), "{name}: no displacement output");
        let cli: Vec<Vec<f64>> = keys.iter().map(|key| series(json, "displacement", key)).collect();
        // The C API and the FMU solve at the same time (independent: the FMU binary has its own engine).
        let (c, f) = std::thread::scope(|s| {
            let c = s.spawn(|| c_api(copy, &keys, k));
            let f = s.spawn(|| fmu(&name, copy, &keys, k, period));
            let join = |h: std::thread::ScopedJoinHandle<Vec<Vec<f64>>>| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            (join(c), join(f))
        });
        for (front_end, got) in [("C API", c), ("FMU", f)] {
            for ((key, g), c) in keys.iter().zip(&got).zip(&cli) {
                assert_same(&name, front_end, key, g, c);
            }
        }
        eprintln!("{name}: CLI, C API and FMU agree to {TOL:e} on {} displacement output(s) at k = {k}", keys.len());
    }
}
