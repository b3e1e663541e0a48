//! The packaged FMU driven by a host harness (libloading): it steps through two periods and
//! matches the CLI's JSON at the communication points; misuse gives the documented status and
//! never a crash; the binary exports exactly the 34 functions and links only the C runtime.
//!
//! Needs the FMU binary: `cargo build --release` (the tests fail with
//! that message when it is missing).
use crate::common;

use common::host::*;
use std::collections::BTreeSet;
use std::f64::consts::PI;
use std::ffi::{CString, c_char, c_void};
use std::process::Command;
use std::sync::OnceLock;

/// A damped 2-DOF structure with two harmonics of forcing, no contact (never calls the LCP solver).
const LINEAR: &str = r#"
[structure]
mass = [[2.0, 0.3], [0.3, 1.0]]
stiffness = [[5.0, -2.0], [-2.0, 3.0]]
[damping]
matrix = [[0.1, -0.02], [-0.02, 0.05]]
[excitation]
frequency = 1.7
[[force]]
dof = 1
amplitude = 0.8
phase = 0.4
[[force]]
dof = 0
amplitude = 0.3
harmonic = 2
[discretization]
scheme = "cds"
steps = 64
[output]
displacement = [0, 1]
velocity = [0]
"#;

fn linear(scheme: &str, steps: usize) -> String {
    LINEAR.replace("scheme = \"cds\"", &format!("scheme = \"{scheme}\"")).replace("steps = 64", &format!("steps = {steps}"))
}

/// The linear scene with every force amplitude scaled and another frequency.
fn linear_tuned(scale: f64, frequency: f64) -> String {
    LINEAR
        .replace("amplitude = 0.8", &format!("amplitude = {}", 0.8 * scale))
        .replace("amplitude = 0.3", &format!("amplitude = {}", 0.3 * scale))
        .replace("frequency = 1.7", &format!("frequency = {frequency}"))
}

fn cds() -> &'static Fmu {
    static F: OnceLock<Fmu> = OnceLock::new();
    F.get_or_init(|| Fmu::package("linear-cds", &linear("cds", 64)))
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Steps `n` times with h from t0 (fmpy style t = t0 + i·h), reading `names` after each step.
fn run(s: &Slave, t0: f64, h: f64, n: usize, names: &[&str]) -> Vec<Vec<f64>> {
    let vrs: Vec<u32> = names.iter().map(|n| s.vr(n)).collect();
    let mut out = Vec::new();
    for i in 0..n {
        let t = t0 + i as f64 * h;
        assert_eq!(s.step(t, h), OK, "fmi2DoStep({t}, {h}); log {:?}", s.log.all());
        let (st, v) = s.get_reals(&vrs);
        assert_eq!(st, OK);
        out.push(v);
    }
    out
}

#[test]
fn two_periods_match_the_cli_at_the_communication_points() {
    let fmu = cds();
    let reference = cli_solve(&fmu.scene);
    let k = 64;
    let (x0, x1, v0) = (series(&reference, "displacement", "0"), series(&reference, "displacement", "1"), series(&reference, "velocity", "0"));
    let scale = max_abs(&x0).max(max_abs(&x1)).max(max_abs(&v0));
    let period = 2.0 * PI / 1.7;
    assert!((reference["period"].as_f64().unwrap() - period).abs() < 1e-15);
    let s = fmu.instantiate("two-periods").expect("instantiate");
    s.init(0.0);
    assert!((s.real("displacement[0]") - x0[0]).abs() <= 1e-12 * scale);
    let h = period / k as f64;
    let got = run(&s, 0.0, h, 2 * k, &["displacement[0]", "displacement[1]", "velocity[0]"]);
    let mut worst = 0.0f64;
    for (i, row) in got.iter().enumerate() {
        let j = (i + 1) % k;
        for (a, b) in row.iter().zip([x0[j], x1[j], v0[j]]) {
            worst = worst.max((a - b).abs());
        }
    }
    assert!(worst <= 1e-11 * scale, "max deviation from the CLI {worst:e} (scale {scale})");
    // d/dt displacement is the velocity output.
    assert!((s.derivative("displacement[0]") - s.real("velocity[0]")).abs() <= 1e-12 * scale);
    assert_eq!(unsafe { (fmu.api.terminate)(s.c) }, OK);
}

#[test]
fn cds_between_instants_is_the_cubic_hermite_of_the_scheme_velocity() {
    let fmu = cds();
    let reference = cli_solve(&fmu.scene);
    let (x0, v0) = (series(&reference, "displacement", "0"), series(&reference, "velocity", "0"));
    let k = 64;
    let h = 2.0 * PI / 1.7 / k as f64;
    let s = fmu.instantiate("hermite").unwrap();
    s.init(0.0);
    // Half steps: odd ones land at s = 1/2 inside interval j.
    let got = run(&s, 0.0, h / 2.0, 2 * k, &["displacement[0]", "velocity[0]"]);
    for j in 0..k {
        let (a, b, va, vb) = (x0[j], x0[(j + 1) % k], v0[j], v0[(j + 1) % k]);
        let mid = (a + b) / 2.0 + h * (va - vb) / 8.0;
        let mid_v = 1.5 * (b - a) / h - (va + vb) / 4.0;
        let row = &got[2 * j];
        assert!((row[0] - mid).abs() < 1e-12, "j={j}: {} vs {mid}", row[0]);
        assert!((row[1] - mid_v).abs() < 1e-11, "j={j}: {} vs {mid_v}", row[1]);
    }
}

#[test]
fn fourier_interpolates_trigonometrically_the_continuous_response() {
    let fmu = Fmu::package("linear-fourier", &linear("fourier", 32));
    // Continuous response: (K − (pω)²M + i pω C) X_p = F_p for p = 1 (DOF 1) and p = 2 (DOF 0).
    let (m, kk, c) = ([[2.0, 0.3], [0.3, 1.0]], [[5.0, -2.0], [-2.0, 3.0]], [[0.1, -0.02], [-0.02, 0.05]]);
    let w = 1.7;
    let amp = |p: f64, f: [(f64, f64); 2]| {
        let z = |i: usize, j: usize| (kk[i][j] - (p * w).powi(2) * m[i][j], p * w * c[i][j]);
        let mul = |a: (f64, f64), b: (f64, f64)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
        let sub = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0, a.1 - b.1);
        let div = |a: (f64, f64), b: (f64, f64)| {
            let d = b.0 * b.0 + b.1 * b.1;
            ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
        };
        let det = sub(mul(z(0, 0), z(1, 1)), mul(z(0, 1), z(1, 0)));
        let x0 = div(sub(mul(f[0], z(1, 1)), mul(z(0, 1), f[1])), det);
        let x1 = div(sub(mul(z(0, 0), f[1]), mul(z(1, 0), f[0])), det);
        [x0, x1]
    };
    let a1 = amp(1.0, [(0.0, 0.0), (0.8 * 0.4f64.cos(), 0.8 * 0.4f64.sin())]);
    let a2 = amp(2.0, [(0.3, 0.0), (0.0, 0.0)]);
    let exact = |d: usize, t: f64| {
        let re = |a: (f64, f64), p: f64| a.0 * (p * w * t).cos() - a.1 * (p * w * t).sin();
        let dre = |a: (f64, f64), p: f64| -p * w * (a.0 * (p * w * t).sin() + a.1 * (p * w * t).cos());
        (re(a1[d], 1.0) + re(a2[d], 2.0), dre(a1[d], 1.0) + dre(a2[d], 2.0))
    };
    let s = fmu.instantiate("fourier").unwrap();
    s.init(0.0);
    // Off the grid: h = T/45 with k = 32.
    let h = 2.0 * PI / w / 45.0;
    let got = run(&s, 0.0, h, 90, &["displacement[0]", "displacement[1]", "velocity[0]"]);
    for (i, row) in got.iter().enumerate() {
        let t = (i + 1) as f64 * h;
        let (e0, ev0) = exact(0, t);
        let (e1, _) = exact(1, t);
        assert!((row[0] - e0).abs() < 1e-10 && (row[1] - e1).abs() < 1e-10 && (row[2] - ev0).abs() < 1e-10, "t={t}: {row:?} vs {e0} {e1} {ev0}");
    }
}

/// The FMU's error estimate lies within a factor of 10 of the true error of its samples against
/// the exact continuous linear response (src/formulation.md §6.1, `exact::LinearResponse`).
#[test]
fn the_error_estimate_output_is_within_a_factor_of_ten_of_the_true_error() {
    let fmu = cds();
    let s = fmu.instantiate("accuracy").unwrap();
    s.init(0.0);
    assert_eq!(s.integer("accuracy.estimated"), 1);
    let estimate = s.real("accuracy.estimate");
    let problem = periodic_contact::scene::Scene::parse(&linear("cds", 64), "t").unwrap().to_problem("t").unwrap();
    let exact = periodic_contact::exact::LinearResponse::from_model(problem.model()).unwrap();
    let r = problem.solve().unwrap();
    let mut truth = 0.0f64;
    for (j, &t) in r.time.iter().enumerate() {
        let x = exact.displacement(t);
        truth = truth.max((r.displacement["0"][j] - x[0]).abs()).max((r.displacement["1"][j] - x[1]).abs());
    }
    eprintln!("FMU accuracy.estimate {estimate:.3e}, true error {truth:.3e}");
    assert!((0.1..=10.0).contains(&(estimate / truth)), "estimate {estimate:.3e} vs true error {truth:.3e}");
}

#[test]
fn only_the_effects_the_scene_calls_for_have_variables() {
    let fmu = cds();
    let names: BTreeSet<&str> = fmu.vars.keys().map(String::as_str).collect();
    let expected: BTreeSet<&str> = [
        "frequency",
        "force_scale",
        "steps",
        "scheme",
        "frequency_in",
        "force_scale_in",
        "displacement[0]",
        "displacement[1]",
        "velocity[0]",
        "accuracy.estimate",
        "accuracy.estimated",
    ]
    .into();
    assert_eq!(names, expected);
    assert!(fmu.xml.contains("variableNamingConvention=\"structured\""));
    let s = fmu.instantiate("effects").unwrap();
    s.init(0.0);
    // No LCP without contact, so no LCP variables either.
    assert!(!fmu.xml.contains("lcp."), "LCP variables in a contact-free FMU");
    // The archive holds exactly the four members, compressed with deflate.
    let mut zip = zip::ZipArchive::new(std::fs::File::open(&fmu.fmu_file).unwrap()).unwrap();
    let mut members = BTreeSet::new();
    for i in 0..zip.len() {
        let f = zip.by_index(i).unwrap();
        let name = f.name().unwrap().to_string();
        assert_eq!(f.compression(), zip::CompressionMethod::Deflated, "{name}");
        members.insert(name);
    }
    let want: BTreeSet<String> = ["modelDescription.xml", "binaries/linux64/PeriodicContact.so", "resources/scene.toml", "documentation/index.html"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(members, want);
}

#[test]
fn tunable_parameters_and_inputs_re_solve_at_the_next_step() {
    let fmu = cds();
    let k = 64;
    let base = cli_solve(&fmu.scene);
    let s = fmu.instantiate("tuned").unwrap();
    s.init(0.0);
    let t1 = 2.0 * PI / 1.7;
    let h1 = t1 / k as f64;
    run(&s, 0.0, h1, k, &["displacement[0]"]);
    // force_scale = 2: the linear response doubles from the next step on.
    assert_eq!(s.set_real("force_scale", 2.0), OK);
    assert!((s.real("displacement[0]") - series(&base, "displacement", "0")[0]).abs() < 1e-12, "the change waits for the next step");
    let got = run(&s, t1, h1, k, &["displacement[0]"]);
    let x = series(&base, "displacement", "0");
    for (i, row) in got.iter().enumerate() {
        assert!((row[0] - 2.0 * x[(i + 1) % k]).abs() < 1e-11, "step {i}: {} vs {}", row[0], 2.0 * x[(i + 1) % k]);
    }
    // frequency_in drives ω = 1.8 at the end of the second period; the phase stays continuous,
    // so from there on the outputs are the new response's samples.
    assert_eq!(s.set_real("frequency_in", 1.8), OK);
    let tuned_scene = fmu.dir.join("tuned.toml");
    std::fs::write(&tuned_scene, linear_tuned(2.0, 1.8)).unwrap();
    let tuned = cli_solve(&tuned_scene);
    let h2 = 2.0 * PI / 1.8 / k as f64;
    let got = run(&s, 2.0 * t1, h2, k, &["displacement[0]", "displacement[1]"]);
    let (y0, y1) = (series(&tuned, "displacement", "0"), series(&tuned, "displacement", "1"));
    for (i, row) in got.iter().enumerate() {
        let j = (i + 1) % k;
        assert!((row[0] - y0[j]).abs() < 1e-10 && (row[1] - y1[j]).abs() < 1e-10, "step {i}: {row:?} vs {} {}", y0[j], y1[j]);
    }
    assert_eq!(s.real("frequency"), 1.7);
    assert_eq!(s.real("frequency_in"), 1.8);
}

#[test]
fn start_values_change_the_solved_response() {
    let fmu = cds();
    let s = fmu.instantiate("start-values").unwrap();
    assert_eq!(s.set_real("force_scale", 2.5), OK);
    assert_eq!(s.set_real("frequency", 1.9), OK);
    s.init(0.0);
    let scene = fmu.dir.join("start.toml");
    std::fs::write(&scene, linear_tuned(2.5, 1.9)).unwrap();
    let r = cli_solve(&scene);
    let k = 64;
    let h = 2.0 * PI / 1.9 / k as f64;
    let got = run(&s, 0.0, h, k, &["displacement[1]"]);
    let x = series(&r, "displacement", "1");
    for (i, row) in got.iter().enumerate() {
        assert!((row[0] - x[(i + 1) % k]).abs() < 1e-11);
    }
}

#[test]
fn fmu_state_get_set_and_serialize_restore_the_run() {
    let fmu = cds();
    let a = &fmu.api;
    let s = fmu.instantiate("state").unwrap();
    s.init(0.0);
    let h = 2.0 * PI / 1.7 / 64.0;
    run(&s, 0.0, h, 10, &[]);
    let mut st: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (a.get_fmu_state)(s.c, &mut st) }, OK);
    assert!(!st.is_null());
    let later = run(&s, 10.0 * h, h, 5, &["displacement[0]", "velocity[0]"]);
    assert_eq!(s.set_real("force_scale", 3.0), OK);
    run(&s, 15.0 * h, h, 3, &[]);
    // Back to step 10: the same five steps again (the force_scale change is undone too).
    assert_eq!(unsafe { (a.set_fmu_state)(s.c, st) }, OK);
    assert_eq!(s.real("force_scale"), 1.0);
    assert_eq!(run(&s, 10.0 * h, h, 5, &["displacement[0]", "velocity[0]"]), later);
    // Serialized, deserialized, restored into a second instance of the same FMU.
    let mut size = 0usize;
    assert_eq!(unsafe { (a.serialized_fmu_state_size)(s.c, st, &mut size) }, OK);
    let mut bytes = vec![0 as c_char; size];
    assert_eq!(unsafe { (a.serialize_fmu_state)(s.c, st, bytes.as_mut_ptr(), size) }, OK);
    let other = fmu.instantiate("state-2").unwrap();
    let mut st2: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (a.deserialize_fmu_state)(other.c, bytes.as_ptr(), size, &mut st2) }, OK);
    assert_eq!(unsafe { (a.set_fmu_state)(other.c, st2) }, OK);
    assert_eq!(run(&other, 10.0 * h, h, 5, &["displacement[0]", "velocity[0]"]), later);
    // Corrupt bytes are refused with fmi2Error, not a crash.
    let mut st3: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (a.deserialize_fmu_state)(other.c, bytes.as_ptr(), size / 2, &mut st3) }, ERROR);
    assert!(st3.is_null());
    // A state of another format version is refused by name (bytes 8..10: the format version).
    let mut old = bytes.clone();
    old[8] = 1;
    old[9] = 0;
    assert_eq!(unsafe { (a.deserialize_fmu_state)(other.c, old.as_ptr(), size, &mut st3) }, ERROR);
    assert!(st3.is_null());
    let lines = other.log.all();
    assert!(lines.iter().any(|l| l.message.starts_with("fmi2DeSerializeFMUstate: input error: serialized FMU state: ")), "{lines:?}");
    assert!(lines.iter().any(|l| l.status == ERROR && l.message.contains("format version 1 is not readable")), "{lines:?}");
    for (c, p) in [(s.c, &mut st), (other.c, &mut st2)] {
        assert_eq!(unsafe { (a.free_fmu_state)(c, p) }, OK);
        assert!(p.is_null());
    }
}

/// An undamped oscillator: at ω = 1 the harmonic-1 operator K − ω²M is exactly singular.
const UNDAMPED: &str = r#"
[structure]
mass = [[1.0]]
stiffness = [[1.0]]
[excitation]
frequency = 0.7
[[force]]
dof = 0
amplitude = 1.0
[discretization]
scheme = "fourier"
steps = 16
"#;

#[test]
fn a_failed_re_solve_discards_the_step_and_a_failed_solve_is_an_error() {
    let fmu = Fmu::package("undamped", UNDAMPED);
    let a = &fmu.api;
    let s = fmu.instantiate("discard").unwrap();
    s.init(0.0);
    let h = 0.1;
    run(&s, 0.0, h, 3, &["displacement[0]"]);
    let before = s.real("displacement[0]");
    assert_eq!(s.set_real("frequency", 1.0), OK);
    assert_eq!(s.step(3.0 * h, h), DISCARD);
    let line = s.log.all().into_iter().find(|l| l.status == DISCARD).expect("a discard line");
    assert!(line.message.contains("singular"), "{line:?}");
    assert_eq!(line.category, "logStatusDiscard");
    let mut terminated = 0;
    assert_eq!(unsafe { (a.get_boolean_status)(s.c, TERMINATED, &mut terminated) }, OK);
    assert_eq!(terminated, 1);
    let mut last = f64::NAN;
    assert_eq!(unsafe { (a.get_real_status)(s.c, LAST_SUCCESSFUL_TIME, &mut last) }, OK);
    assert!((last - 3.0 * h).abs() < 1e-15);
    assert_eq!(s.real("displacement[0]"), before, "outputs stay at the last successful time, never NaN");
    assert_eq!(s.step(3.0 * h, h), ERROR, "no step after a discard");
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);

    let s = fmu.instantiate("error").unwrap();
    assert_eq!(s.set_real("frequency", 1.0), OK);
    assert_eq!(s.setup(0.0), OK);
    assert_eq!(s.enter(), OK);
    assert_eq!(s.exit(), ERROR);
    let line = s.log.find("fmi2ExitInitializationMode").expect("logged");
    assert_eq!(line.status, ERROR);
    assert!(line.message.contains("singular at harmonic 1"), "{line:?}");
}

#[test]
fn every_function_with_a_null_instance_is_an_error() {
    let a = &cds().api;
    let n = std::ptr::null_mut();
    let mut r = 0.0;
    let mut i = 0;
    let mut p: *const c_char = std::ptr::null();
    let mut st: *mut c_void = std::ptr::null_mut();
    let mut size = 0usize;
    let vr = 0u32;
    let order = 1;
    unsafe {
        assert_eq!(std::ffi::CStr::from_ptr((a.get_types_platform)()).to_str().unwrap(), "default");
        assert_eq!(std::ffi::CStr::from_ptr((a.get_version)()).to_str().unwrap(), "2.0");
        (a.free_instance)(n);
        let statuses = [
            (a.set_debug_logging)(n, 1, 0, std::ptr::null()),
            (a.setup_experiment)(n, 0, 0.0, 0.0, 0, 0.0),
            (a.enter_initialization_mode)(n),
            (a.exit_initialization_mode)(n),
            (a.terminate)(n),
            (a.reset)(n),
            (a.get_real)(n, &vr, 1, &mut r),
            (a.get_integer)(n, &vr, 1, &mut i),
            (a.get_boolean)(n, &vr, 1, &mut i),
            (a.get_string)(n, &vr, 1, &mut p),
            (a.set_real)(n, &vr, 1, &r),
            (a.set_integer)(n, &vr, 1, &i),
            (a.set_boolean)(n, &vr, 1, &i),
            (a.set_string)(n, &vr, 1, &p),
            (a.get_fmu_state)(n, &mut st),
            (a.set_fmu_state)(n, st),
            (a.free_fmu_state)(n, &mut st),
            (a.serialized_fmu_state_size)(n, st, &mut size),
            (a.serialize_fmu_state)(n, st, std::ptr::null_mut(), 0),
            (a.deserialize_fmu_state)(n, std::ptr::null(), 0, &mut st),
            (a.get_directional_derivative)(n, &vr, 1, &vr, 1, &r, &mut r),
            (a.set_real_input_derivatives)(n, &vr, 1, &order, &r),
            (a.get_real_output_derivatives)(n, &vr, 1, &order, &mut r),
            (a.do_step)(n, 0.0, 0.1, 1),
            (a.cancel_step)(n),
            (a.get_status)(n, 0, &mut i),
            (a.get_real_status)(n, LAST_SUCCESSFUL_TIME, &mut r),
            (a.get_integer_status)(n, 0, &mut i),
            (a.get_boolean_status)(n, TERMINATED, &mut i),
            (a.get_string_status)(n, 1, &mut p),
        ];
        assert!(statuses.iter().all(|&s| s == ERROR), "{statuses:?}");
        assert!(st.is_null());
    }
}

#[test]
fn bad_instantiation_arguments_give_null_and_a_log_line() {
    let fmu = cds();
    // The wrong GUID.
    let (s, log) = Slave::with_log(fmu, "wrong-guid", "{00000000-0000-0000-0000-000000000000}", Some(&fmu.resources_uri), Default::default());
    assert!(s.is_none());
    let line = log.find("GUID mismatch").expect("a log line about the GUID");
    assert_eq!((line.status, line.instance.as_str(), line.category.as_str()), (ERROR, "wrong-guid", "logStatusError"));
    assert!(line.message.contains(&fmu.guid));
    // No resources, an empty name, Model Exchange, NULL callbacks.
    let (s, log) = Slave::with_log(fmu, "no-resources", &fmu.guid, None, Default::default());
    assert!(s.is_none() && log.find("resources").is_some());
    let (s, log) = Slave::with_log(fmu, "", &fmu.guid, Some(&fmu.resources_uri), Default::default());
    assert!(s.is_none() && log.find("instanceName").is_some());
    let name = CString::new("x").unwrap();
    let guid = CString::new(fmu.guid.clone()).unwrap();
    let res = CString::new(fmu.resources_uri.clone()).unwrap();
    let c = unsafe { (fmu.api.instantiate)(name.as_ptr(), CO_SIMULATION, guid.as_ptr(), res.as_ptr(), std::ptr::null(), 0, 0) };
    assert!(c.is_null());
    let log = std::sync::Arc::new(Log::default());
    let (_env, cb) = callbacks(&log);
    let c = unsafe { (fmu.api.instantiate)(name.as_ptr(), 0, guid.as_ptr(), res.as_ptr(), &cb, 0, 0) };
    assert!(c.is_null() && log.find("co-simulation").is_some());
    let c = unsafe { (fmu.api.instantiate)(std::ptr::null(), CO_SIMULATION, std::ptr::null(), std::ptr::null(), &cb, 0, 0) };
    assert!(c.is_null());
    // Every resource-location form importers use works (file:/, file:///, file:////, localhost, %20).
    let dir = fmu.resources_uri.trim_start_matches("file://");
    let spaced = fmu.dir.join("with space");
    std::fs::create_dir_all(&spaced).unwrap();
    std::fs::copy(format!("{dir}/scene.toml"), spaced.join("scene.toml")).unwrap();
    let spaced_uri = format!("file://{}", spaced.display().to_string().replace(' ', "%20"));
    for uri in [format!("file:{dir}"), format!("file://{dir}"), format!("file:///{dir}"), format!("file://localhost{dir}"), spaced_uri] {
        let s = Slave::new(fmu, "uri", &fmu.guid, Some(&uri));
        assert!(s.is_some(), "{uri}");
    }
}

#[test]
fn calls_out_of_order_are_errors_and_reset_recovers() {
    let fmu = cds();
    let a = &fmu.api;
    let s = fmu.instantiate("order").unwrap();
    assert_eq!(s.step(0.0, 0.1), ERROR);
    let line = s.log.find("illegal call sequence").expect("logged");
    assert!(line.message.contains("fmi2DoStep") && line.message.contains("instantiated"), "{line:?}");
    // The instance is in the error state now: only reset/free/getters/state functions.
    assert_eq!(s.enter(), ERROR);
    assert!(s.log.find("error state").is_some());
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    assert_eq!(s.exit(), ERROR, "exit before enter");
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    assert_eq!(unsafe { (a.terminate)(s.c) }, ERROR, "terminate before initialisation");
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    let (st, _) = s.get_reals(&[s.vr("displacement[0]")]);
    assert_eq!(st, ERROR, "getters need initialisation mode");
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    assert_eq!(s.enter(), OK);
    assert_eq!(s.setup(0.0), ERROR, "setup after enter");
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    s.init(0.0);
    assert_eq!(unsafe { (a.cancel_step)(s.c) }, ERROR, "no step is in progress");
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    s.init(0.0);
    let h = 2.0 * PI / 1.7 / 64.0;
    assert_eq!(s.step(0.0, h), OK);
    assert_eq!(s.step(h, 0.0), ERROR, "step size 0");
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    s.init(0.0);
    assert_eq!(unsafe { (a.terminate)(s.c) }, OK);
    assert_eq!(s.step(0.0, h), ERROR, "step after terminate");
    // Unsupported optional functions: fmi2Error, logged, the state is kept.
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    s.init(0.0);
    let mut r = 0.0;
    let vr = 0u32;
    assert_eq!(unsafe { (a.get_directional_derivative)(s.c, &vr, 1, &vr, 1, &r, &mut r) }, ERROR);
    assert!(s.log.find("providesDirectionalDerivative").is_some());
    assert_eq!(s.step(0.0, h), OK, "still usable");
    let mut i = 0;
    assert_eq!(unsafe { (a.get_status)(s.c, 0, &mut i) }, DISCARD);
    assert_eq!(unsafe { (a.get_integer_status)(s.c, 0, &mut i) }, DISCARD);
}

#[test]
fn unknown_value_references_and_wrong_types_are_errors() {
    let fmu = cds();
    let a = &fmu.api;
    let s = fmu.instantiate("vr").unwrap();
    s.init(0.0);
    let (st, v) = s.get_reals(&[s.vr("displacement[0]"), 9999]);
    assert_eq!(st, ERROR);
    assert!(v[0].is_finite());
    let line = s.log.find("unknown value reference 9999").expect("logged");
    assert_eq!(line.status, ERROR);
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    s.init(0.0);
    let mut i = 0;
    assert_eq!(unsafe { (a.get_integer)(s.c, &s.vr("frequency"), 1, &mut i) }, ERROR);
    assert!(s.log.find("is a Real variable, not Integer").is_some());
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    s.init(0.0);
    assert_eq!(s.set_real("displacement[0]", 1.0), ERROR, "an output cannot be set");
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    s.init(0.0);
    // NULL arrays with n = 0 are fine; with n > 0 they are errors.
    assert_eq!(unsafe { (a.get_real)(s.c, std::ptr::null(), 0, std::ptr::null_mut()) }, OK);
    assert_eq!(unsafe { (a.set_real)(s.c, std::ptr::null(), 0, std::ptr::null()) }, OK);
    assert_eq!(unsafe { (a.get_real)(s.c, std::ptr::null(), 1, std::ptr::null_mut()) }, ERROR);
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    // Values out of the domain are refused at the call.
    assert_eq!(s.set_real("frequency", f64::NAN), ERROR);
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    assert_eq!(s.set_real("frequency", -1.0), ERROR);
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    assert_eq!(s.set_integer("steps", 2), ERROR);
    assert_eq!(unsafe { (a.reset)(s.c) }, OK);
    assert_eq!(s.set_integer("scheme", 9), ERROR);
}

#[test]
fn a_fixed_parameter_cannot_be_set_after_initialisation() {
    let fmu = cds();
    let s = fmu.instantiate("fixed").unwrap();
    assert_eq!(s.set_integer("steps", 32), OK, "fixed parameters can be set before initialisation");
    assert_eq!(s.set_integer("scheme", 5), OK);
    s.init(0.0);
    assert_eq!(s.integer("steps"), 32);
    assert_eq!(s.set_real("frequency", 1.6), OK, "tunable");
    assert_eq!(s.set_integer("steps", 128), ERROR);
    let line = s.log.find("steps (causality parameter, variability fixed) cannot be set after initialisation").expect("logged");
    assert_eq!(line.status, ERROR);
}

#[test]
fn percent_signs_in_messages_are_never_formats_and_the_name_is_copied() {
    let fmu = cds();
    let name = "inst %s%n%x%p";
    let mut buffer: Vec<u8> = name.bytes().chain([0]).collect();
    let log = std::sync::Arc::new(Log::default());
    let (_env, cb) = callbacks(&log);
    let guid = CString::new(fmu.guid.clone()).unwrap();
    let res = CString::new(fmu.resources_uri.clone()).unwrap();
    let c = unsafe { (fmu.api.instantiate)(buffer.as_ptr() as *const c_char, CO_SIMULATION, guid.as_ptr(), res.as_ptr(), &cb, 0, 1) };
    assert!(!c.is_null());
    // Overwrite the caller's string: the FMU must have copied it.
    buffer.iter_mut().take(name.len()).for_each(|b| *b = b'X');
    assert_eq!(unsafe { (fmu.api.do_step)(c, 0.0, 0.1, 1) }, ERROR);
    let cat = CString::new("log%s%n%s%n").unwrap();
    let cats = [cat.as_ptr()];
    assert_eq!(unsafe { (fmu.api.set_debug_logging)(c, 1, 1, cats.as_ptr()) }, ERROR);
    let lines = log.all();
    assert!(lines.len() >= 2, "{lines:?}");
    for l in &lines {
        assert_eq!(l.format, "%s");
        assert_eq!(l.instance, name);
        assert_eq!(l.ctx, std::sync::Arc::as_ptr(&log) as usize, "componentEnvironment passed back");
    }
    assert!(lines.iter().any(|l| l.message.contains("unknown log category \"log%s%n%s%n\"")), "{lines:?}");
    unsafe { (fmu.api.free_instance)(c) };
}

#[test]
fn a_thousand_instantiate_free_cycles() {
    let fmu = cds();
    for i in 0..1000 {
        let s = fmu.instantiate(&format!("cycle-{i}")).expect("instantiate");
        if i % 100 == 0 {
            s.init(0.0);
            assert_eq!(s.step(0.0, 0.01), OK);
        }
    }
}

#[test]
fn two_instances_with_different_parameters_on_two_threads() {
    let fmu = cds();
    let k = 64;
    let cases = [(1.0, 1.7), (2.5, 1.9)];
    let references: Vec<Vec<f64>> = cases
        .iter()
        .enumerate()
        .map(|(i, &(scale, w))| {
            let p = fmu.dir.join(format!("thread-{i}.toml"));
            std::fs::write(&p, linear_tuned(scale, w)).unwrap();
            series(&cli_solve(&p), "displacement", "0")
        })
        .collect();
    // Instantiated here, driven from worker threads (as libcosim does), interleaved.
    let slaves: Vec<Slave> = cases
        .iter()
        .enumerate()
        .map(|(i, &(scale, w))| {
            let s = fmu.instantiate(&format!("thread-{i}")).unwrap();
            assert_eq!(s.set_real("force_scale", scale), OK);
            assert_eq!(s.set_real("frequency", w), OK);
            s
        })
        .collect();
    let results: Vec<Vec<Vec<f64>>> = std::thread::scope(|scope| {
        let handles: Vec<_> = slaves
            .into_iter()
            .zip(cases)
            .map(|(s, (_, w))| {
                scope.spawn(move || {
                    s.init(0.0);
                    let h = 2.0 * PI / w / k as f64;
                    let mut all = Vec::new();
                    for _ in 0..20 {
                        let t0 = all.len() as f64 * h;
                        all.extend(run(&s, t0, h, 2 * k / 20 + 1, &["displacement[0]"]));
                        std::thread::yield_now();
                    }
                    all
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (got, reference) in results.iter().zip(&references) {
        for (i, row) in got.iter().enumerate() {
            assert!((row[0] - reference[(i + 1) % k]).abs() < 1e-10, "step {i}: {} vs {}", row[0], reference[(i + 1) % k]);
        }
    }
}

#[test]
fn communication_points_are_compared_with_a_tolerance() {
    let fmu = cds();
    let s = fmu.instantiate("tolerance").unwrap();
    s.init(0.0);
    // ecos accumulates t += h.
    let h = 0.01;
    let mut t = 0.0;
    for _ in 0..1000 {
        assert_eq!(s.step(t, h), OK, "t = {t:.17}");
        t += h;
    }
    assert_eq!(s.step(t + 1e-3, h), ERROR);
    assert!(s.log.find("does not match the FMU's time").is_some());
}

#[test]
fn the_binary_exports_exactly_the_34_functions_and_links_only_the_c_runtime() {
    let so = fmu_binary();
    let nm = Command::new("nm").args(["-D", "--defined-only"]).arg(&so).output().expect("run nm");
    assert!(nm.status.success());
    let exported: BTreeSet<String> = String::from_utf8_lossy(&nm.stdout).lines().filter_map(|l| l.split_whitespace().nth(2)).map(String::from).collect();
    let expected: BTreeSet<String> = FMI2_CS_FUNCTIONS.iter().map(|s| s.to_string()).collect();
    assert_eq!(exported, expected, "nm -D --defined-only {}", so.display());
    let re = Command::new("readelf").arg("-d").arg(&so).output().expect("run readelf");
    let needed: Vec<String> = String::from_utf8_lossy(&re.stdout)
        .lines()
        .filter(|l| l.contains("(NEEDED)"))
        .filter_map(|l| Some(l[l.find('[')? + 1..l.find(']')?].to_string()))
        .collect();
    assert!(!needed.is_empty());
    for n in &needed {
        let ok = ["libc.so", "libm.so", "libgcc_s.so", "ld-linux"].iter().any(|p| n.starts_with(p));
        assert!(ok, "{} needs {n}; all NEEDED: {needed:?}", so.display());
    }
}

// --- scenes with contact (the shipped examples) ----------------------------------------------

fn shipped(name: &str) -> String {
    std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes").join(name)).unwrap()
}

fn rigid() -> &'static Fmu {
    static F: OnceLock<Fmu> = OnceLock::new();
    F.get_or_init(|| Fmu::package("rigid-stop", &shipped("rigid-stop.toml")))
}

fn contact_series(json: &serde_json::Value, i: usize, field: &str) -> Vec<f64> {
    json["contacts"][i][field].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect()
}

/// Steps two periods on the grid and compares every output with the CLI's JSON.
fn compare_two_periods(fmu: &Fmu, s: &Slave, reference: &serde_json::Value, t0: f64) {
    compare_periods(fmu, s, reference, t0, false);
}

/// As [`compare_two_periods`]; `warm`: the FMU re-solved warm-started from its last orbit while
/// the CLI solved cold, so it may take fewer LCP steps (never more).
fn compare_periods(fmu: &Fmu, s: &Slave, reference: &serde_json::Value, t0: f64, warm: bool) {
    let k = reference["steps"].as_u64().unwrap() as usize;
    let h = reference["period"].as_f64().unwrap() / k as f64;
    let x = series(reference, "displacement", "0");
    let v = series(reference, "velocity", "0");
    let (f, g) = (contact_series(reference, 0, "force"), contact_series(reference, 0, "gap"));
    let got = run(s, t0, h, 2 * k, &["displacement[0]", "velocity[0]", "contact[0].force", "contact[0].gap"]);
    let scale = max_abs(&x).max(max_abs(&v)).max(max_abs(&f)).max(1.0);
    for (i, row) in got.iter().enumerate() {
        let j = (i + 1) % k;
        for (name, a, b) in [("x", row[0], x[j]), ("v", row[1], v[j]), ("force", row[2], f[j]), ("gap", row[3], g[j])] {
            assert!((a - b).abs() <= 1e-9 * scale, "{}: step {i}, {name}: FMU {a} vs CLI {b}", fmu.scene.display());
        }
    }
    let (pivots, cold) = (s.integer("lcp.pivots") as u64, reference["lcp"]["pivots"].as_u64().unwrap());
    if warm {
        assert!(pivots <= cold, "warm re-solve: {pivots} LCP steps, cold CLI solve {cold}");
    } else {
        assert_eq!(pivots, cold);
    }
    // serde_json's default float parser may be off by one ulp; a warm re-solve ends on another
    // iterate of the same orbit, so only both certified.
    let residual = reference["lcp"]["residual"].as_f64().unwrap();
    if warm {
        assert!(s.real("lcp.residual") <= 1e-9 && residual <= 1e-9, "{} vs {residual}", s.real("lcp.residual"));
    } else {
        assert!((s.real("lcp.residual") - residual).abs() <= 1e-12 * residual.abs(), "{} vs {residual}", s.real("lcp.residual"));
    }
}

#[test]
fn rigid_stop_two_periods_match_the_cli_with_contact_outputs() {
    let fmu = rigid();
    for present in ["gap_offset", "gap_offset_in", "contact[0].force", "contact[0].gap", "lcp.pivots", "lcp.residual"] {
        assert!(fmu.vars.contains_key(present), "{present}");
    }
    assert!(!fmu.vars.contains_key("motion_scale"), "a static obstacle has no motion parameters");
    let reference = cli_solve(&fmu.scene);
    let s = fmu.instantiate("rigid").unwrap();
    s.init(0.0);
    compare_two_periods(fmu, &s, &reference, 0.0);
    // Between the instants force and gap are interpolated linearly: never negative.
    let k = reference["steps"].as_u64().unwrap() as usize;
    let h = reference["period"].as_f64().unwrap() / k as f64;
    let t0 = 2.0 * reference["period"].as_f64().unwrap();
    for row in run(&s, t0, h / 3.0, 3 * k, &["contact[0].force", "contact[0].gap"]) {
        assert!(row[0] >= 0.0 && row[1] >= -1e-12, "{row:?}");
    }
}

#[test]
fn contact_start_values_and_a_warm_started_re_solve_match_the_cli() {
    let fmu = rigid();
    let s = fmu.instantiate("rigid-tuned").unwrap();
    assert_eq!(s.set_real("gap_offset", 0.1), OK);
    let on = [c"logEvents".as_ptr()];
    assert_eq!(unsafe { (fmu.api.set_debug_logging)(s.c, 1, 1, on.as_ptr()) }, OK);
    s.init(0.0);
    let scene = fmu.dir.join("gap06.toml");
    std::fs::write(&scene, shipped("rigid-stop.toml").replace("gap = 0.5", "gap = 0.6")).unwrap();
    let reference = cli_solve(&scene);
    compare_two_periods(fmu, &s, &reference, 0.0);
    // A small change of frequency at t = 2T: re-solved at the next step, warm-started.
    assert_eq!(s.set_real("frequency", 1.02), OK);
    let scene = fmu.dir.join("gap06-w102.toml");
    std::fs::write(&scene, shipped("rigid-stop.toml").replace("gap = 0.5", "gap = 0.6").replace("frequency = 1.0", "frequency = 1.02")).unwrap();
    let tuned = cli_solve(&scene);
    compare_periods(fmu, &s, &tuned, 2.0 * reference["period"].as_f64().unwrap(), true);
    let line = s.log.find("re-solved").expect("a logEvents line about the re-solve");
    assert_eq!(line.status, OK);
}

#[test]
fn moving_obstacle_and_compliant_stop_match_the_cli() {
    let moving = Fmu::package("moving-obstacle", &shipped("moving-obstacle.toml"));
    assert!(moving.vars.contains_key("motion_scale") && moving.vars.contains_key("motion_scale_in"));
    let s = moving.instantiate("moving").unwrap();
    assert_eq!(s.set_real("motion_scale", 2.0), OK);
    s.init(0.0);
    let scene = moving.dir.join("motion2.toml");
    std::fs::write(&scene, shipped("moving-obstacle.toml").replace("amplitude = 0.05", "amplitude = 0.1")).unwrap();
    compare_two_periods(&moving, &s, &cli_solve(&scene), 0.0);

    let compliant = Fmu::package("compliant-stop", &shipped("compliant-stop.toml"));
    let s = compliant.instantiate("compliant").unwrap();
    s.init(0.0);
    compare_two_periods(&compliant, &s, &cli_solve(&compliant.scene), 0.0);
}

/// With `polish` on, the outputs at communication points between the instants are the exact
/// orbit's (`periodic_contact::exact`, the rigid stop with sticking of src/formulation.md §6.3) to 1e-8 of the
/// peak-to-peak amplitude, `polish.status` = 1, and a serialized FMU state restores the polished
/// orbit; without contact outputs the polish falls back (`polish.status` = 2, a logged warning).
#[test]
fn polish_gives_the_exact_orbit_between_the_instants() {
    use periodic_contact::exact::{Oscillator, RigidStopOrbit};
    let exact = RigidStopOrbit::solve(&Oscillator::new(1.0, 0.1, 1.0, 1.0, 1.0), 0.5).unwrap();
    let ptp = exact.peak_to_peak();
    let fmu = rigid();
    let s = fmu.instantiate("polish").unwrap();
    assert_eq!(s.set_boolean("polish", true), OK);
    s.init(0.0);
    assert_eq!(s.integer("polish.status"), 1, "{:?}", s.log.all());
    let names = ["displacement[0]", "velocity[0]", "contact[0].force", "contact[0].gap"];
    // 1.37 steps of the grid: communication points fall between the instants.
    let h = 1.37 * exact.period() / 256.0;
    let rows = run(&s, 0.0, h, 400, &names);
    let mut worst = 0f64;
    for (i, row) in rows.iter().enumerate() {
        let t = (i + 1) as f64 * h;
        let (x, v, f) = exact.eval(t);
        for (got, want) in row.iter().zip([x, v, f, 0.5 - x]) {
            worst = worst.max((got - want).abs() / ptp);
        }
    }
    eprintln!("FMU polish: max error over 400 communication points {worst:.2e} of ptp");
    assert!(worst < 1e-8, "{worst:e}");
    assert!((s.derivative("displacement[0]") - s.real("velocity[0]")).abs() < 1e-12);
    // A serialized state restores the polished orbit in another instance.
    let a = &fmu.api;
    let mut st: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (a.get_fmu_state)(s.c, &mut st) }, OK);
    let later = run(&s, 400.0 * h, h, 5, &names);
    let mut size = 0usize;
    assert_eq!(unsafe { (a.serialized_fmu_state_size)(s.c, st, &mut size) }, OK);
    let mut bytes = vec![0 as c_char; size];
    assert_eq!(unsafe { (a.serialize_fmu_state)(s.c, st, bytes.as_mut_ptr(), size) }, OK);
    let other = fmu.instantiate("polish-2").unwrap();
    let mut st2: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (a.deserialize_fmu_state)(other.c, bytes.as_ptr(), size, &mut st2) }, OK, "{:?}", other.log.all());
    assert_eq!(unsafe { (a.set_fmu_state)(other.c, st2) }, OK);
    assert_eq!(run(&other, 400.0 * h, h, 5, &names), later);
    for (c, p) in [(s.c, &mut st), (other.c, &mut st2)] {
        assert_eq!(unsafe { (a.free_fmu_state)(c, p) }, OK);
    }
    // Off again (tunable): the next step re-solves and interpolates the samples.
    assert_eq!(s.set_boolean("polish", false), OK);
    run(&s, 405.0 * h, h, 1, &[]);
    assert_eq!(s.integer("polish.status"), 0);

    // No contact outputs: the events cannot be read, the polish falls back and says why.
    let text = shipped("rigid-stop.toml").replace("velocity = [0]", "velocity = [0]\ncontacts = false").replace("steps = 256", "steps = 256\npolish = true");
    let fallback = Fmu::package("rigid-stop-fallback", &text);
    let s = fallback.instantiate("fallback").unwrap();
    s.init(0.0);
    assert_eq!(s.integer("polish.status"), 2);
    assert!(
        s.log.all().iter().any(|l| l.status == WARNING && l.message.contains("polish: fell back") && l.message.contains("no contact outputs")),
        "{:?}",
        s.log.all()
    );
}

/// Matrix Market files outside the scene's folder (`../M.mtx`) are packaged under
/// `resources/external/` with the packaged scene rewritten to point there, and the FMU under the
/// Rust host gives the CLI's displacements to 1e-9 (the files beside the scene are covered by the
/// front-end matrix, tests/frontends.rs).
#[test]
fn matrix_market_files_outside_the_scene_folder_are_packaged_and_read_from_resources() {
    let dir = scratch("outside_mtx");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("M.mtx"), "%%MatrixMarket matrix coordinate real symmetric\n2 2 3\n1 1 2.0\n2 1 0.3\n2 2 1.0\n").unwrap();
    std::fs::write(dir.join("K.mtx"), "%%MatrixMarket matrix coordinate real general\n2 2 4\n1 1 5.0\n2 1 -2.0\n1 2 -2.0\n2 2 3.0\n").unwrap();
    let scene = dir.join("sub/outside.toml");
    let text = "[structure]\nmass = { matrix_market = \"../M.mtx\" }\nstiffness = { matrix_market = \"../K.mtx\" }\n[damping]\nrayleigh = [0.02, 0.01]\n\
                [excitation]\nfrequency = 1.3\n[[force]]\ndof = 1\namplitude = 1.0\n[[contact]]\ndof = 0\ngap = 0.2\n\
                [discretization]\nscheme = \"cds\"\nsteps = 128\n[output]\ndisplacement = [0, 1]\n";
    std::fs::write(&scene, text).unwrap();
    let json = cli_solve(&scene);
    let fmu = Fmu::package_scene("outside", &scene);
    let resources = fmu.dir.join("unzipped/resources");
    assert!(resources.join("external/0/M.mtx").is_file() && resources.join("external/1/K.mtx").is_file());
    let packaged = std::fs::read_to_string(resources.join("scene.toml")).unwrap();
    assert!(packaged.contains("external/0/M.mtx") && !packaged.contains("../M.mtx"), "{packaged}");
    let s = fmu.instantiate("outside").expect("instantiated");
    s.init(0.0);
    let k = json["steps"].as_u64().unwrap() as usize;
    let h = json["period"].as_f64().unwrap() / k as f64;
    let got = run(&s, 0.0, h, k, &["displacement[0]", "displacement[1]"]);
    for (c, key) in ["0", "1"].iter().enumerate() {
        let cli = series(&json, "displacement", key);
        let scale = max_abs(&cli);
        for (i, row) in got.iter().enumerate() {
            assert!((row[c] - cli[(i + 1) % k]).abs() <= 1e-9 * scale, "displacement[{key}] at step {i}: FMU {} CLI {}", row[c], cli[(i + 1) % k]);
        }
    }
}
