//! The FMI and C boundary under stress (issue 7, part 5). Reuses the libloading host harness of
//! tests/common/host.rs (the NULL-instance and ordinary misuse tests are in tests/fmu_host.rs).
//!
//! What is detected, and what cannot be:
//! - FMU: a NULL instance everywhere (fmi2Error; fmi2FreeInstance(NULL) does nothing). A non-NULL
//!   instance or FMU state is accepted only when its first use finds the 64-bit magic tag of its
//!   kind (`INSTANCE_MAGIC` / `STATE_MAGIC`, src/fmi2/instance.rs): a pointer to memory that is
//!   not an instance (random bytes, zeros, an FMU state passed as an instance, an instance passed
//!   as an FMU state) is refused with fmi2Error and nothing is written through it. The tag is
//!   cleared on free, so a freed instance or state is refused as long as the allocator has not
//!   reused the memory; that is not guaranteed (reading freed memory is undefined behaviour and
//!   not tested), and a pointer to unmapped memory or forged bytes that hold the tag cannot be
//!   told from a live handle by any check.
//! - FMU: array arguments NULL with n > 0, lengths that cannot be a real array (n·size > isize::MAX),
//!   NULL output pointers and unknown status kinds: fmi2Error with a logged reason.
//! - C API: a NULL handle everywhere (PC_ERROR_ARGUMENT with a message; NULL / 0 / NaN from the
//!   functions that return a handle, a count or a number; the free functions ignore NULL).
//!   The C API has no tag in its handles: a garbage or freed pc_problem/pc_result is NOT detected
//!   (it is undefined behaviour, as for FILE*), and is not tested.
//!
//! Then: 8 threads × instances with different frequency and force_scale, bitwise equal to the
//! sequential runs, through the FMU and through the C API; a long run of fmi2DoStep through a C
//! host (examples/fmu_host.c) with the resident size sampled; valgrind on examples/capi_demo.c
//! and on the FMU driven by the C host.
//!
//! Needs `cargo build --release` (libperiodic_contact.so and libPeriodicContact.so). Environment:
//! `PC_STRESS_STEPS` (default 10⁷) sets the long run's length.
use crate::common;

use common::host::*;
use libloading::Library;
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Barrier, OnceLock};

fn shipped(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes").join(name)).unwrap()
}

fn rigid() -> &'static Fmu {
    static F: OnceLock<Fmu> = OnceLock::new();
    F.get_or_init(|| Fmu::package("stress-rigid", &shipped("rigid-stop.toml")))
}

/// splitmix64: a seeded, dependency-free generator.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

/// Calls every one of the 34 functions that takes an instance with `c`; returns the statuses
/// (fmi2FreeInstance returns nothing and is called last).
unsafe fn every_function(a: &Api, c: Comp) -> Vec<(&'static str, c_int)> {
    let mut r = 1.5;
    let mut i = 7;
    let mut p: *const c_char = std::ptr::null();
    let mut st: *mut c_void = std::ptr::null_mut();
    let mut size = 0usize;
    let vr = 0u32;
    let order = 1;
    let bytes = [0 as c_char; 16];
    let mut out = [0 as c_char; 16];
    let cat = c"logAll".as_ptr();
    let s = unsafe {
        vec![
            ("fmi2SetDebugLogging", (a.set_debug_logging)(c, 1, 1, &cat)),
            ("fmi2SetupExperiment", (a.setup_experiment)(c, 0, 0.0, 0.0, 0, 0.0)),
            ("fmi2EnterInitializationMode", (a.enter_initialization_mode)(c)),
            ("fmi2ExitInitializationMode", (a.exit_initialization_mode)(c)),
            ("fmi2Terminate", (a.terminate)(c)),
            ("fmi2Reset", (a.reset)(c)),
            ("fmi2GetReal", (a.get_real)(c, &vr, 1, &mut r)),
            ("fmi2GetInteger", (a.get_integer)(c, &vr, 1, &mut i)),
            ("fmi2GetBoolean", (a.get_boolean)(c, &vr, 1, &mut i)),
            ("fmi2GetString", (a.get_string)(c, &vr, 1, &mut p)),
            ("fmi2SetReal", (a.set_real)(c, &vr, 1, &r)),
            ("fmi2SetInteger", (a.set_integer)(c, &vr, 1, &i)),
            ("fmi2SetBoolean", (a.set_boolean)(c, &vr, 1, &i)),
            ("fmi2SetString", (a.set_string)(c, &vr, 1, &c"x".as_ptr())),
            ("fmi2GetFMUstate", (a.get_fmu_state)(c, &mut st)),
            ("fmi2SetFMUstate", (a.set_fmu_state)(c, st)),
            ("fmi2FreeFMUstate", (a.free_fmu_state)(c, &mut st)),
            ("fmi2SerializedFMUstateSize", (a.serialized_fmu_state_size)(c, st, &mut size)),
            ("fmi2SerializeFMUstate", (a.serialize_fmu_state)(c, st, out.as_mut_ptr(), out.len())),
            ("fmi2DeSerializeFMUstate", (a.deserialize_fmu_state)(c, bytes.as_ptr(), bytes.len(), &mut st)),
            ("fmi2GetDirectionalDerivative", (a.get_directional_derivative)(c, &vr, 1, &vr, 1, &r, &mut r)),
            ("fmi2SetRealInputDerivatives", (a.set_real_input_derivatives)(c, &vr, 1, &order, &r)),
            ("fmi2GetRealOutputDerivatives", (a.get_real_output_derivatives)(c, &vr, 1, &order, &mut r)),
            ("fmi2DoStep", (a.do_step)(c, 0.0, 0.1, 1)),
            ("fmi2CancelStep", (a.cancel_step)(c)),
            ("fmi2GetStatus", (a.get_status)(c, 0, &mut i)),
            ("fmi2GetRealStatus", (a.get_real_status)(c, LAST_SUCCESSFUL_TIME, &mut r)),
            ("fmi2GetIntegerStatus", (a.get_integer_status)(c, 0, &mut i)),
            ("fmi2GetBooleanStatus", (a.get_boolean_status)(c, TERMINATED, &mut i)),
            ("fmi2GetStringStatus", (a.get_string_status)(c, 1, &mut p)),
        ]
    };
    unsafe { (a.free_instance)(c) };
    // Nothing was written to the outputs.
    assert_eq!((r, i, p, st, size), (1.5, 7, std::ptr::null(), std::ptr::null_mut(), 0), "an output was written");
    assert!(out.iter().all(|&b| b == 0));
    s
}

#[test]
fn fmu_garbage_instances_are_refused_everywhere_and_left_untouched() {
    let a = &rigid().api;
    let mut rng = Rng(0x5eed);
    // 64 KiB: far larger than an instance, so reading its tag stays inside the buffer.
    let random: Vec<u8> = (0..1 << 16).map(|_| rng.next() as u8).collect();
    let zeros = vec![0u8; 1 << 16];
    let ones = vec![0xffu8; 1 << 16];
    // The FMU-state tag everywhere: an FMU state passed as an instance.
    let state_tags: Vec<u8> = b"TS2IMFCP".iter().copied().cycle().take(1 << 16).collect();
    for (what, buffer) in [("random bytes", random), ("zeros", zeros), ("0xff", ones), ("FMU-state tags", state_tags)] {
        let mut b = buffer.clone();
        for offset in [0usize, 8, 4096] {
            let c = unsafe { b.as_mut_ptr().add(offset) } as Comp;
            let statuses = unsafe { every_function(a, c) };
            assert_eq!(statuses.len(), 30);
            for (f, s) in statuses {
                assert_eq!(s, ERROR, "{f} with a pointer to {what} (+{offset}) returned {s}");
            }
            assert!(b == buffer, "a call with a pointer to {what} wrote into it");
        }
    }
    // The one check available without an instance: these two need none.
    unsafe {
        assert_eq!(CStr::from_ptr((a.get_version)()).to_str().unwrap(), "2.0");
        assert_eq!(CStr::from_ptr((a.get_types_platform)()).to_str().unwrap(), "default");
    }
}

/// The tag is the first word of an instance and of an FMU state, so the check on entry reads
/// only the first 8 bytes behind a pointer (never past a smaller object of another kind).
#[test]
fn the_tags_are_the_first_word_of_instances_and_states() {
    let fmu = rigid();
    let s = fmu.instantiate("tags").unwrap();
    let word = |p: *mut c_void| unsafe { (p as *const u64).read() };
    assert_eq!(word(s.c), 0x5043_464d_4932_494e, "an instance does not start with \"PCFMI2IN\"");
    let mut st: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (fmu.api.get_fmu_state)(s.c, &mut st) }, OK);
    assert_eq!(word(st), 0x5043_464d_4932_5354, "an FMU state does not start with \"PCFMI2ST\"");
    assert_eq!(unsafe { (fmu.api.free_fmu_state)(s.c, &mut st) }, OK);
}

#[test]
fn fmu_instances_and_states_are_not_confused() {
    let fmu = rigid();
    let a = &fmu.api;
    let s = fmu.instantiate("confused").unwrap();
    s.init(0.0);
    assert_eq!(s.step(0.0, 0.01), OK);
    let mut st: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (a.get_fmu_state)(s.c, &mut st) }, OK);
    // A state passed as an instance: refused, the state stays usable.
    assert_eq!(unsafe { (a.do_step)(st, 0.01, 0.01, 1) }, ERROR);
    assert_eq!(unsafe { (a.reset)(st) }, ERROR);
    unsafe { (a.free_instance)(st) }; // must not free the state
    // An instance passed as a state: refused (and the instance is not freed).
    let mut me = s.c;
    let mut size = 0usize;
    for (what, status) in [
        ("fmi2SetFMUstate", unsafe { (a.set_fmu_state)(s.c, s.c) }),
        ("fmi2SerializedFMUstateSize", unsafe { (a.serialized_fmu_state_size)(s.c, s.c, &mut size) }),
        ("fmi2FreeFMUstate", unsafe { (a.free_fmu_state)(s.c, &mut me) }),
        ("fmi2GetFMUstate (overwrite)", unsafe { (a.get_fmu_state)(s.c, &mut me) }),
    ] {
        assert_eq!(status, ERROR, "{what} with the instance as a state");
        assert_eq!(me, s.c, "{what} changed the pointer");
        assert_eq!(unsafe { (a.reset)(s.c) }, OK, "the instance survives {what}");
    }
    let line = s.log.find("not a state of this FMU").expect("logged");
    assert_eq!(line.status, ERROR);
    // The state is intact: restoring it gives back stepComplete at t = 0.01.
    assert_eq!(unsafe { (a.set_fmu_state)(s.c, st) }, OK);
    assert_eq!(s.step(0.01, 0.01), OK);
    // NULL and garbage FMU-state arguments.
    let mut garbage = vec![0x5au8; 1 << 16];
    let g = garbage.as_mut_ptr() as *mut c_void;
    let mut gp = g;
    let mut bytes = vec![0 as c_char; 64];
    let cases: Vec<(&str, c_int)> = unsafe {
        vec![
            ("fmi2GetFMUstate(NULL)", (a.get_fmu_state)(s.c, std::ptr::null_mut())),
            ("fmi2GetFMUstate(&garbage)", (a.get_fmu_state)(s.c, &mut gp)),
            ("fmi2SetFMUstate(NULL)", (a.set_fmu_state)(s.c, std::ptr::null_mut())),
            ("fmi2SetFMUstate(garbage)", (a.set_fmu_state)(s.c, g)),
            ("fmi2FreeFMUstate(&garbage)", (a.free_fmu_state)(s.c, &mut gp)),
            ("fmi2SerializedFMUstateSize(garbage)", (a.serialized_fmu_state_size)(s.c, g, &mut size)),
            ("fmi2SerializedFMUstateSize(size NULL)", (a.serialized_fmu_state_size)(s.c, st, std::ptr::null_mut())),
            ("fmi2SerializeFMUstate(garbage)", (a.serialize_fmu_state)(s.c, g, bytes.as_mut_ptr(), bytes.len())),
            ("fmi2SerializeFMUstate(too small)", (a.serialize_fmu_state)(s.c, st, bytes.as_mut_ptr(), 8)),
            ("fmi2SerializeFMUstate(NULL buffer)", (a.serialize_fmu_state)(s.c, st, std::ptr::null_mut(), 1 << 20)),
            ("fmi2DeSerializeFMUstate(NULL bytes)", (a.deserialize_fmu_state)(s.c, std::ptr::null(), 64, &mut gp)),
            ("fmi2DeSerializeFMUstate(garbage bytes)", (a.deserialize_fmu_state)(s.c, garbage.as_ptr() as *const c_char, 4096, &mut gp)),
            ("fmi2DeSerializeFMUstate(size > isize::MAX)", (a.deserialize_fmu_state)(s.c, bytes.as_ptr(), usize::MAX, &mut gp)),
            ("fmi2DeSerializeFMUstate(FMUstate NULL)", (a.deserialize_fmu_state)(s.c, bytes.as_ptr(), 8, std::ptr::null_mut())),
        ]
    };
    for (what, status) in cases {
        assert_eq!(status, ERROR, "{what}");
    }
    assert_eq!(gp, g, "a refused call changed the caller's FMUstate");
    assert!(garbage.iter().all(|&b| b == 0x5a), "a garbage state was written to");
    // NULL FMUstate pointers where the standard allows them: freeing nothing is fine.
    let mut null: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (a.free_fmu_state)(s.c, &mut null) }, OK);
    assert_eq!(unsafe { (a.free_fmu_state)(s.c, std::ptr::null_mut()) }, OK);
    assert_eq!(unsafe { (a.free_fmu_state)(s.c, &mut st) }, OK);
    assert!(st.is_null());
}

#[test]
fn fmu_impossible_lengths_null_outputs_and_unknown_kinds_are_errors() {
    let fmu = rigid();
    let a = &fmu.api;
    let s = fmu.instantiate("lengths").unwrap();
    s.init(0.0);
    let vr = s.vr("displacement[0]");
    let mut r = [0.0f64; 4];
    let mut i = [0 as c_int; 4];
    let cat = c"logAll".as_ptr();
    let checks: Vec<(&str, c_int)> = unsafe {
        vec![
            // A pointer with an impossible count: refused before anything is read.
            ("fmi2GetReal(n = usize::MAX)", (a.get_real)(s.c, &vr, usize::MAX, r.as_mut_ptr())),
            ("fmi2SetReal(n = usize::MAX)", (a.set_real)(s.c, &vr, usize::MAX, r.as_ptr())),
            ("fmi2GetInteger(n = 2^62)", (a.get_integer)(s.c, &vr, 1 << 62, i.as_mut_ptr())),
            ("fmi2SetDebugLogging(n = usize::MAX)", (a.set_debug_logging)(s.c, 1, usize::MAX, &cat)),
            ("fmi2GetRealOutputDerivatives(n = usize::MAX)", (a.get_real_output_derivatives)(s.c, &vr, usize::MAX, i.as_ptr(), r.as_mut_ptr())),
            // NULL outputs and inputs.
            ("fmi2GetReal(value NULL)", (a.get_real)(s.c, &vr, 1, std::ptr::null_mut())),
            ("fmi2GetReal(vr NULL)", (a.get_real)(s.c, std::ptr::null(), 1, r.as_mut_ptr())),
            ("fmi2SetString(value[0] NULL)", (a.set_string)(s.c, &vr, 1, &std::ptr::null())),
            ("fmi2SetDebugLogging(categories[0] NULL)", (a.set_debug_logging)(s.c, 1, 1, &std::ptr::null())),
            ("fmi2GetRealStatus(value NULL)", (a.get_real_status)(s.c, LAST_SUCCESSFUL_TIME, std::ptr::null_mut())),
            ("fmi2GetBooleanStatus(value NULL)", (a.get_boolean_status)(s.c, TERMINATED, std::ptr::null_mut())),
            ("fmi2GetStatus(value NULL)", (a.get_status)(s.c, 0, std::ptr::null_mut())),
            ("fmi2GetStringStatus(value NULL)", (a.get_string_status)(s.c, 0, std::ptr::null_mut())),
            // Status kinds that are not an fmi2StatusKind.
            ("fmi2GetRealStatus(kind -1)", (a.get_real_status)(s.c, -1, r.as_mut_ptr())),
            ("fmi2GetBooleanStatus(kind 4)", (a.get_boolean_status)(s.c, 4, i.as_mut_ptr())),
            ("fmi2GetIntegerStatus(kind i32::MAX)", (a.get_integer_status)(s.c, i32::MAX, i.as_mut_ptr())),
            ("fmi2GetStatus(kind i32::MIN)", (a.get_status)(s.c, i32::MIN, i.as_mut_ptr())),
            // Communication points and steps that are not numbers.
            ("fmi2DoStep(t NaN)", (a.do_step)(s.c, f64::NAN, 0.1, 1)),
            ("fmi2DoStep(h inf)", (a.do_step)(s.c, 0.0, f64::INFINITY, 1)),
            ("fmi2DoStep(h -0)", (a.do_step)(s.c, 0.0, -0.0, 1)),
            ("fmi2DoStep(h subnormal, t off)", (a.do_step)(s.c, 1e300, 5e-324, 1)),
        ]
    };
    for (what, status) in checks {
        assert_eq!(status, ERROR, "{what}; log {:?}", s.log.all().last());
        assert!(r.iter().all(|v| v.is_finite()), "{what} wrote a non-finite value");
        // Each of these moved the instance to the error state: back to a fresh run.
        assert_eq!(unsafe { (a.reset)(s.c) }, OK);
        s.init(0.0);
    }
    // Every line was logged with "%s" (messages may contain user text).
    assert!(s.log.all().iter().all(|l| l.format == "%s" && l.instance == "lengths"));
    // fmi2Instantiate with garbage arguments: NULL, never a crash.
    let name = CString::new("garbage-args").unwrap();
    let guid = CString::new(fmu.guid.clone()).unwrap();
    let log = std::sync::Arc::new(Log::default());
    let (_env, cb) = callbacks(&log);
    let bad_uri = CString::new("file:///nonexistent/%ZZ/\u{fffd}").unwrap();
    let weird = [b'x', 0xff, 0xfe, 0].map(|b| b as c_char);
    unsafe {
        for t in [-1, 2, i32::MAX] {
            assert!((a.instantiate)(name.as_ptr(), t, guid.as_ptr(), CString::new(fmu.resources_uri.clone()).unwrap().as_ptr(), &cb, 0, 0).is_null());
        }
        assert!((a.instantiate)(name.as_ptr(), CO_SIMULATION, guid.as_ptr(), bad_uri.as_ptr(), &cb, 0, 0).is_null());
        assert!((a.instantiate)(name.as_ptr(), CO_SIMULATION, weird.as_ptr(), bad_uri.as_ptr(), &cb, 0, 0).is_null());
        // A non-UTF-8 instance name is accepted (copied lossily), the instance works.
        let res = CString::new(fmu.resources_uri.clone()).unwrap();
        let c = (a.instantiate)(weird.as_ptr(), CO_SIMULATION, guid.as_ptr(), res.as_ptr(), &cb, 0, 1);
        assert!(!c.is_null());
        assert_eq!((a.do_step)(c, 0.0, 0.1, 1), ERROR);
        (a.free_instance)(c);
    }
    assert!(log.all().iter().all(|l| l.format == "%s"));
}

// --- the C API ------------------------------------------------------------------------------

type P = *mut c_void;

/// The 32 functions of libperiodic_contact.so.
struct CApi {
    _lib: Library,
    version: unsafe extern "C" fn() -> *const c_char,
    last_error: unsafe extern "C" fn() -> *const c_char,
    from_scene_file: unsafe extern "C" fn(*const c_char) -> P,
    from_scene_text: unsafe extern "C" fn(*const c_char) -> P,
    from_matrices: unsafe extern "C" fn(usize, *const f64, *const f64, *const f64, f64, *const c_char, usize) -> P,
    add_force: unsafe extern "C" fn(P, usize, f64, u32, f64) -> c_int,
    add_contact: unsafe extern "C" fn(P, usize, c_int, f64, f64, *mut usize) -> c_int,
    add_contact_motion: unsafe extern "C" fn(P, usize, f64, u32, f64) -> c_int,
    set_outputs: unsafe extern "C" fn(P, *const usize, usize, *const usize, usize, *const usize, usize, c_int) -> c_int,
    set_pairing: unsafe extern "C" fn(P, *const c_char) -> c_int,
    set_parallel: unsafe extern "C" fn(P, c_int) -> c_int,
    set_frequency: unsafe extern "C" fn(P, f64) -> c_int,
    set_force_scale: unsafe extern "C" fn(P, f64) -> c_int,
    set_gap_offset: unsafe extern "C" fn(P, f64) -> c_int,
    set_motion_scale: unsafe extern "C" fn(P, f64) -> c_int,
    frequency: unsafe extern "C" fn(P) -> f64,
    solve: unsafe extern "C" fn(P) -> P,
    problem_free: unsafe extern "C" fn(P),
    steps: unsafe extern "C" fn(P) -> usize,
    period: unsafe extern "C" fn(P) -> f64,
    time: unsafe extern "C" fn(P, *mut f64, usize) -> c_int,
    displacement: unsafe extern "C" fn(P, usize, *mut f64, usize) -> c_int,
    velocity: unsafe extern "C" fn(P, usize, *mut f64, usize) -> c_int,
    acceleration: unsafe extern "C" fn(P, usize, *mut f64, usize) -> c_int,
    contact_count: unsafe extern "C" fn(P) -> usize,
    contact_force: unsafe extern "C" fn(P, usize, *mut f64, usize) -> c_int,
    contact_gap: unsafe extern "C" fn(P, usize, *mut f64, usize) -> c_int,
    lcp: unsafe extern "C" fn(P, *mut usize, *mut usize, *mut f64, *mut c_int) -> c_int,
    warning_count: unsafe extern "C" fn(P) -> usize,
    warning: unsafe extern "C" fn(P, usize) -> *const c_char,
    json: unsafe extern "C" fn(P) -> *const c_char,
    result_free: unsafe extern "C" fn(P),
}

const C_API_FUNCTIONS: [&str; 61] = [
    "pc_problem_friction_count",
    "pc_problem_set_normal_force_scale",
    "pc_result_friction_count",
    "pc_result_friction_force",
    "pc_result_friction_slip_velocity",
    "pc_result_friction_displacement",
    "pc_result_friction_stuck",
    "pc_result_friction",
    "pc_version",
    "pc_problem_set_polish",
    "pc_result_polish",
    "pc_result_event_count",
    "pc_result_event",
    "pc_result_state_at",
    "pc_result_contact_at",
    "pc_problem_set_stability",
    "pc_result_stability",
    "pc_result_jump",
    "pc_problem_set_error_estimate",
    "pc_problem_set_error_estimate_budget",
    "pc_result_accuracy",
    "pc_problem_dof_count",
    "pc_problem_contact_count",
    "pc_problem_contact",
    "pc_problem_set_contact_pairing",
    "pc_problem_contact_pairing",
    "pc_result_contact_paired_gap",
    "pc_result_contact_pairing",
    "pc_result_warm_start",
    "pc_result_lcp_path",
    "pc_last_error",
    "pc_problem_from_scene_file",
    "pc_problem_from_scene_text",
    "pc_problem_from_matrices",
    "pc_problem_add_force",
    "pc_problem_add_contact",
    "pc_problem_add_contact_motion",
    "pc_problem_set_outputs",
    "pc_problem_set_pairing",
    "pc_problem_set_parallel",
    "pc_problem_set_frequency",
    "pc_problem_set_force_scale",
    "pc_problem_set_gap_offset",
    "pc_problem_set_motion_scale",
    "pc_problem_frequency",
    "pc_problem_solve",
    "pc_problem_free",
    "pc_result_steps",
    "pc_result_period",
    "pc_result_time",
    "pc_result_displacement",
    "pc_result_velocity",
    "pc_result_acceleration",
    "pc_result_contact_count",
    "pc_result_contact_force",
    "pc_result_contact_gap",
    "pc_result_lcp",
    "pc_result_warning_count",
    "pc_result_warning",
    "pc_result_json",
    "pc_result_free",
];

const PC_OK: c_int = 0;
const PC_ERROR_ARGUMENT: c_int = 1;
const PC_ERROR_INPUT: c_int = 2;

/// libperiodic_contact.so from `cargo build --release`, next to the CLI.
fn c_library() -> PathBuf {
    let so = Path::new(env!("CARGO_BIN_EXE_periodic-contact")).parent().unwrap().join("libperiodic_contact.so");
    assert!(so.is_file(), "{} is missing; build it first with `cargo build --release`", so.display());
    so
}

fn c_api() -> &'static CApi {
    static A: OnceLock<CApi> = OnceLock::new();
    A.get_or_init(|| {
        let lib = unsafe { Library::new(c_library()) }.unwrap();
        macro_rules! f {
            ($name:literal) => {
                *unsafe { lib.get(concat!("pc_", $name).as_bytes()) }.unwrap_or_else(|e| panic!("missing pc_{}: {e}", $name))
            };
        }
        CApi {
            version: f!("version"),
            last_error: f!("last_error"),
            from_scene_file: f!("problem_from_scene_file"),
            from_scene_text: f!("problem_from_scene_text"),
            from_matrices: f!("problem_from_matrices"),
            add_force: f!("problem_add_force"),
            add_contact: f!("problem_add_contact"),
            add_contact_motion: f!("problem_add_contact_motion"),
            set_outputs: f!("problem_set_outputs"),
            set_pairing: f!("problem_set_pairing"),
            set_parallel: f!("problem_set_parallel"),
            set_frequency: f!("problem_set_frequency"),
            set_force_scale: f!("problem_set_force_scale"),
            set_gap_offset: f!("problem_set_gap_offset"),
            set_motion_scale: f!("problem_set_motion_scale"),
            frequency: f!("problem_frequency"),
            solve: f!("problem_solve"),
            problem_free: f!("problem_free"),
            steps: f!("result_steps"),
            period: f!("result_period"),
            time: f!("result_time"),
            displacement: f!("result_displacement"),
            velocity: f!("result_velocity"),
            acceleration: f!("result_acceleration"),
            contact_count: f!("result_contact_count"),
            contact_force: f!("result_contact_force"),
            contact_gap: f!("result_contact_gap"),
            lcp: f!("result_lcp"),
            warning_count: f!("result_warning_count"),
            warning: f!("result_warning"),
            json: f!("result_json"),
            result_free: f!("result_free"),
            _lib: lib,
        }
    })
}

fn last_error(a: &CApi) -> String {
    unsafe { CStr::from_ptr((a.last_error)()) }.to_string_lossy().into_owned()
}

#[test]
fn c_api_exports_exactly_the_functions_of_the_header() {
    let out = Command::new("nm").args(["-D", "--defined-only"]).arg(c_library()).output().expect("run nm");
    let mut exported: Vec<String> = String::from_utf8_lossy(&out.stdout).lines().filter_map(|l| l.split_whitespace().nth(2)).map(String::from).collect();
    exported.sort();
    let mut expected: Vec<String> = C_API_FUNCTIONS.iter().map(|s| s.to_string()).collect();
    expected.sort();
    assert_eq!(exported, expected);
    let header = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("include/periodic_contact.h")).unwrap();
    for f in C_API_FUNCTIONS {
        assert!(header.contains(&format!("{f}(")), "{f} is not declared in the header");
    }
}

#[test]
fn c_api_every_function_with_a_null_handle() {
    let a = c_api();
    let n: P = std::ptr::null_mut();
    let mut buf = [1.5f64; 8];
    let mut index = 99usize;
    let (mut size, mut pivots, mut residual, mut warm) = (7usize, 7usize, 1.5f64, 7 as c_int);
    let dofs = [0usize];
    unsafe {
        assert!(!CStr::from_ptr((a.version)()).to_bytes().is_empty());
        // Constructors with NULL inputs: NULL and an argument message.
        for (what, p) in [
            ("pc_problem_from_scene_file(NULL)", (a.from_scene_file)(std::ptr::null())),
            ("pc_problem_from_scene_text(NULL)", (a.from_scene_text)(std::ptr::null())),
            ("pc_problem_from_matrices(NULL mass)", (a.from_matrices)(1, std::ptr::null(), [1.0].as_ptr(), std::ptr::null(), 1.0, c"cds".as_ptr(), 16)),
            ("pc_problem_from_matrices(NULL scheme)", (a.from_matrices)(1, [1.0].as_ptr(), [1.0].as_ptr(), std::ptr::null(), 1.0, std::ptr::null(), 16)),
        ] {
            assert!(p.is_null(), "{what}");
            assert!(last_error(a).contains("NULL"), "{what}: {}", last_error(a));
        }
        // Every function taking a problem or a result, with NULL.
        let codes: Vec<(&str, c_int)> = vec![
            ("pc_problem_add_force", (a.add_force)(n, 0, 1.0, 1, 0.0)),
            ("pc_problem_add_contact", (a.add_contact)(n, 0, 1, 0.5, 0.0, &mut index)),
            ("pc_problem_add_contact_motion", (a.add_contact_motion)(n, 0, 0.1, 2, 0.0)),
            ("pc_problem_set_outputs", (a.set_outputs)(n, dofs.as_ptr(), 1, dofs.as_ptr(), 1, std::ptr::null(), 0, 1)),
            ("pc_problem_set_pairing", (a.set_pairing)(n, c"same".as_ptr())),
            ("pc_problem_set_parallel", (a.set_parallel)(n, 0)),
            ("pc_problem_set_frequency", (a.set_frequency)(n, 1.0)),
            ("pc_problem_set_force_scale", (a.set_force_scale)(n, 1.0)),
            ("pc_problem_set_gap_offset", (a.set_gap_offset)(n, 0.0)),
            ("pc_problem_set_motion_scale", (a.set_motion_scale)(n, 1.0)),
            ("pc_result_time", (a.time)(n, buf.as_mut_ptr(), buf.len())),
            ("pc_result_displacement", (a.displacement)(n, 0, buf.as_mut_ptr(), buf.len())),
            ("pc_result_velocity", (a.velocity)(n, 0, buf.as_mut_ptr(), buf.len())),
            ("pc_result_acceleration", (a.acceleration)(n, 0, buf.as_mut_ptr(), buf.len())),
            ("pc_result_contact_force", (a.contact_force)(n, 0, buf.as_mut_ptr(), buf.len())),
            ("pc_result_contact_gap", (a.contact_gap)(n, 0, buf.as_mut_ptr(), buf.len())),
            ("pc_result_lcp", (a.lcp)(n, &mut size, &mut pivots, &mut residual, &mut warm)),
        ];
        for (what, code) in codes {
            assert_eq!(code, PC_ERROR_ARGUMENT, "{what}(NULL)");
            assert!(last_error(a).contains("NULL"), "{what}(NULL): {}", last_error(a));
        }
        assert!((a.solve)(n).is_null());
        assert!(last_error(a).contains("NULL"));
        assert!((a.frequency)(n).is_nan());
        assert_eq!((a.steps)(n), 0);
        assert!((a.period)(n).is_nan());
        assert_eq!((a.contact_count)(n), 0);
        assert_eq!((a.warning_count)(n), 0);
        assert!((a.warning)(n, 0).is_null());
        assert!((a.json)(n).is_null());
        assert!(last_error(a).contains("NULL"));
        (a.problem_free)(n);
        (a.result_free)(n);
    }
    assert_eq!(buf, [1.5; 8], "nothing written");
    assert_eq!((index, size, pivots, residual, warm), (99, 7, 7, 1.5, 7));
}

#[test]
fn c_api_garbage_arguments_with_live_handles_are_errors_not_crashes() {
    let a = c_api();
    let scene = CString::new(shipped("rigid-stop.toml")).unwrap();
    unsafe {
        let p = (a.from_scene_text)(scene.as_ptr());
        assert!(!p.is_null(), "{}", last_error(a));
        let mut buf = vec![0.0f64; 1024];
        let mut index = 99usize;
        // Each call: the code, and a message after a failure. PC_ERROR_INTERNAL (a caught panic)
        // would be a bug, even though it does not crash.
        let codes: Vec<(&str, c_int, c_int)> = vec![
            ("add_force(dof 7)", (a.add_force)(p, 7, 1.0, 1, 0.0), PC_ERROR_INPUT),
            ("add_force(amplitude NaN)", (a.add_force)(p, 0, f64::NAN, 1, 0.0), PC_ERROR_INPUT),
            ("add_force(phase inf)", (a.add_force)(p, 0, 1.0, 1, f64::INFINITY), PC_ERROR_INPUT),
            ("add_contact(direction 0)", (a.add_contact)(p, 0, 0, 0.5, 0.0, &mut index), PC_ERROR_ARGUMENT),
            ("add_contact(stiffness NaN)", (a.add_contact)(p, 0, 1, 0.5, f64::NAN, &mut index), PC_ERROR_ARGUMENT),
            ("add_contact(stiffness -1)", (a.add_contact)(p, 0, 1, 0.5, -1.0, &mut index), PC_ERROR_ARGUMENT),
            ("add_contact(dof usize::MAX)", (a.add_contact)(p, usize::MAX, 1, 0.5, 0.0, &mut index), PC_ERROR_INPUT),
            ("add_contact(gap NaN)", (a.add_contact)(p, 0, 1, f64::NAN, 0.0, &mut index), PC_ERROR_INPUT),
            ("add_contact_motion(contact 5)", (a.add_contact_motion)(p, 5, 0.1, 2, 0.0), PC_ERROR_ARGUMENT),
            ("add_contact_motion(amplitude inf)", (a.add_contact_motion)(p, 0, f64::INFINITY, 2, 0.0), PC_ERROR_INPUT),
            ("set_outputs(dof 9)", (a.set_outputs)(p, [9usize].as_ptr(), 1, std::ptr::null(), 0, std::ptr::null(), 0, 1), PC_ERROR_INPUT),
            ("set_outputs(NULL, n 3)", (a.set_outputs)(p, std::ptr::null(), 3, std::ptr::null(), 0, std::ptr::null(), 0, 1), PC_ERROR_ARGUMENT),
            ("set_outputs(n usize::MAX)", (a.set_outputs)(p, [0usize].as_ptr(), usize::MAX, std::ptr::null(), 0, std::ptr::null(), 0, 1), PC_ERROR_ARGUMENT),
            ("set_pairing(\"sideways\")", (a.set_pairing)(p, c"sideways".as_ptr()), PC_ERROR_INPUT),
            ("set_pairing(non-UTF-8)", (a.set_pairing)(p, [0xffu8 as c_char, 0].as_ptr()), PC_ERROR_ARGUMENT),
            ("set_frequency(0)", (a.set_frequency)(p, 0.0), PC_ERROR_ARGUMENT),
            ("set_frequency(NaN)", (a.set_frequency)(p, f64::NAN), PC_ERROR_ARGUMENT),
            ("set_frequency(-inf)", (a.set_frequency)(p, f64::NEG_INFINITY), PC_ERROR_ARGUMENT),
            ("set_force_scale(inf)", (a.set_force_scale)(p, f64::INFINITY), PC_ERROR_ARGUMENT),
            ("set_gap_offset(NaN)", (a.set_gap_offset)(p, f64::NAN), PC_ERROR_ARGUMENT),
            ("set_motion_scale(NaN)", (a.set_motion_scale)(p, f64::NAN), PC_ERROR_ARGUMENT),
        ];
        for (what, code, expected) in codes {
            assert_eq!(code, expected, "{what}: {}", last_error(a));
            assert!(!last_error(a).is_empty(), "{what}: no message");
        }
        assert_eq!(index, 99, "a refused contact wrote its index");
        // The handle still solves the original scene after all the refusals.
        let r = (a.solve)(p);
        assert!(!r.is_null(), "{}", last_error(a));
        assert_eq!(last_error(a), "", "a success clears the message");
        let k = (a.steps)(r);
        assert_eq!(k, 256);
        let res: Vec<(&str, c_int, c_int)> = vec![
            ("time(NULL)", (a.time)(r, std::ptr::null_mut(), 1024), PC_ERROR_ARGUMENT),
            ("time(len k-1)", (a.time)(r, buf.as_mut_ptr(), k - 1), PC_ERROR_ARGUMENT),
            ("displacement(dof 1)", (a.displacement)(r, 1, buf.as_mut_ptr(), k), PC_ERROR_ARGUMENT),
            ("displacement(dof usize::MAX)", (a.displacement)(r, usize::MAX, buf.as_mut_ptr(), k), PC_ERROR_ARGUMENT),
            ("acceleration(not an output)", (a.acceleration)(r, 0, buf.as_mut_ptr(), k), PC_ERROR_ARGUMENT),
            ("contact_force(contact 1)", (a.contact_force)(r, 1, buf.as_mut_ptr(), k), PC_ERROR_ARGUMENT),
            ("contact_gap(len 0)", (a.contact_gap)(r, 0, buf.as_mut_ptr(), 0), PC_ERROR_ARGUMENT),
            ("lcp(all NULL)", (a.lcp)(r, std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut()), PC_OK),
            ("time(len 1024)", (a.time)(r, buf.as_mut_ptr(), 1024), PC_OK),
        ];
        for (what, code, expected) in res {
            assert_eq!(code, expected, "{what}: {}", last_error(a));
        }
        assert!((a.warning)(r, usize::MAX).is_null());
        assert!(buf.iter().all(|v| v.is_finite()));
        (a.result_free)(r);
        // Hostile tunings reach the solver: typed errors or a finite answer, never a panic.
        for (what, set) in [("frequency 1e300", (a.set_frequency)(p, 1e300)), ("frequency 1e-300", (a.set_frequency)(p, 1e-300))] {
            assert_eq!(set, PC_OK, "{what}");
            let r = (a.solve)(p);
            if r.is_null() {
                let m = last_error(a);
                assert!(!m.contains("internal error") && !m.is_empty(), "{what}: {m}");
            } else {
                let k = (a.steps)(r);
                assert_eq!((a.displacement)(r, 0, buf.as_mut_ptr(), k), PC_OK);
                assert!(buf[..k].iter().all(|v| v.is_finite()), "{what}: a non-finite response marked as solved");
                (a.result_free)(r);
            }
        }
        (a.problem_free)(p);
        // Constructors with hostile sizes and values.
        let one = [1.0f64];
        let bad: Vec<(&str, P)> = vec![
            ("from_matrices(n 0)", (a.from_matrices)(0, one.as_ptr(), one.as_ptr(), std::ptr::null(), 1.0, c"cds".as_ptr(), 16)),
            ("from_matrices(n·n overflows)", (a.from_matrices)(usize::MAX, one.as_ptr(), one.as_ptr(), std::ptr::null(), 1.0, c"cds".as_ptr(), 16)),
            ("from_matrices(n 2^31)", (a.from_matrices)(1 << 31, one.as_ptr(), one.as_ptr(), std::ptr::null(), 1.0, c"cds".as_ptr(), 16)),
            ("from_matrices(mass NaN)", (a.from_matrices)(1, [f64::NAN].as_ptr(), one.as_ptr(), std::ptr::null(), 1.0, c"cds".as_ptr(), 16)),
            ("from_matrices(mass -1)", (a.from_matrices)(1, [-1.0].as_ptr(), one.as_ptr(), std::ptr::null(), 1.0, c"cds".as_ptr(), 16)),
            ("from_matrices(frequency NaN)", (a.from_matrices)(1, one.as_ptr(), one.as_ptr(), std::ptr::null(), f64::NAN, c"cds".as_ptr(), 16)),
            ("from_matrices(frequency -1)", (a.from_matrices)(1, one.as_ptr(), one.as_ptr(), std::ptr::null(), -1.0, c"cds".as_ptr(), 16)),
            ("from_matrices(scheme \"rk4\")", (a.from_matrices)(1, one.as_ptr(), one.as_ptr(), std::ptr::null(), 1.0, c"rk4".as_ptr(), 16)),
            ("from_matrices(steps 0)", (a.from_matrices)(1, one.as_ptr(), one.as_ptr(), std::ptr::null(), 1.0, c"cds".as_ptr(), 0)),
            ("from_matrices(steps usize::MAX)", (a.from_matrices)(1, one.as_ptr(), one.as_ptr(), std::ptr::null(), 1.0, c"cds".as_ptr(), usize::MAX)),
            ("from_scene_text(\"\")", (a.from_scene_text)(c"".as_ptr())),
            ("from_scene_text(non-UTF-8)", (a.from_scene_text)([0xc3u8 as c_char, 0x28, 0].as_ptr())),
            ("from_scene_text(binary)", (a.from_scene_text)(c"\x01\x02[[[\x7f=".as_ptr())),
            ("from_scene_file(directory)", (a.from_scene_file)(c"/".as_ptr())),
            ("from_scene_file(/dev/null)", (a.from_scene_file)(c"/dev/null".as_ptr())),
        ];
        for (what, p) in bad {
            assert!(p.is_null(), "{what} gave a handle");
            let m = last_error(a);
            assert!(!m.is_empty() && !m.contains("internal error"), "{what}: {m}");
        }
    }
}

/// pc_last_error is per thread: errors on other threads do not overwrite it.
#[test]
fn c_api_last_error_is_per_thread() {
    let a = c_api();
    let scene = CString::new(shipped("rigid-stop.toml")).unwrap();
    let barrier = Barrier::new(8);
    std::thread::scope(|s| {
        for t in 0..8usize {
            let (barrier, scene) = (&barrier, &scene);
            s.spawn(move || unsafe {
                let p = (a.from_scene_text)(scene.as_ptr());
                assert!(!p.is_null());
                barrier.wait();
                for _ in 0..200 {
                    assert_eq!((a.add_force)(p, 1000 + t, 1.0, 1, 0.0), PC_ERROR_INPUT);
                    std::thread::yield_now();
                    let m = last_error(a);
                    assert!(m.contains(&format!("{}", 1000 + t)), "thread {t} reads another thread's error: {m}");
                }
                (a.problem_free)(p);
            });
        }
    });
}

// --- threads: bitwise equal to the sequential runs -------------------------------------------

/// (frequency, force_scale) per thread: below, at and above the first resonance, with and
/// without a harder push onto the stop.
const CONFIGS: [(f64, f64); 8] = [(0.6, 1.0), (0.8, 0.5), (1.0, 1.0), (1.0, 2.0), (1.2, 1.5), (1.5, 1.0), (2.0, 3.0), (0.9, 0.25)];

/// One FMU run, every output as bits: initialise with the start values, step 1.5 periods on a
/// grid off the solution's (h = T/100 with k = 256), re-solve after frequency_in = 1.01·ω
/// (warm-started), step another period.
fn fmu_run(fmu: &Fmu, s: &Slave, (w, scale): (f64, f64)) -> Vec<u64> {
    assert_eq!(s.set_real("frequency", w), OK);
    assert_eq!(s.set_real("force_scale", scale), OK);
    s.init(0.0);
    let names = ["displacement[0]", "velocity[0]", "contact[0].force", "contact[0].gap", "lcp.residual"];
    let vrs: Vec<u32> = names.iter().map(|n| s.vr(n)).collect();
    let pivots = s.vr("lcp.pivots");
    let h = 2.0 * std::f64::consts::PI / w / 100.0;
    let mut bits = Vec::new();
    for i in 0..250 {
        if i == 150 {
            assert_eq!(s.set_real("frequency_in", 1.01 * w), OK);
        }
        assert_eq!(s.step(i as f64 * h, h), OK, "{:?}", s.log.all().last());
        let (st, v) = s.get_reals(&vrs);
        assert_eq!(st, OK);
        bits.extend(v.iter().map(|x| x.to_bits()));
        let mut d = f64::NAN;
        assert_eq!(unsafe { (fmu.api.get_real_output_derivatives)(s.c, &vrs[0], 1, &1, &mut d) }, OK);
        bits.push(d.to_bits());
        let mut p = 0;
        assert_eq!(unsafe { (fmu.api.get_integer)(s.c, &pivots, 1, &mut p) }, OK);
        bits.push(p as u64);
    }
    bits
}

#[test]
fn fmu_eight_threads_with_different_parameters_are_bitwise_equal_to_sequential_runs() {
    let fmu = rigid();
    let sequential: Vec<Vec<u64>> = CONFIGS.iter().enumerate().map(|(i, &cfg)| fmu_run(fmu, &fmu.instantiate(&format!("seq-{i}")).unwrap(), cfg)).collect();
    // The configurations differ from each other (the comparison below is not vacuous).
    for i in 1..8 {
        assert_ne!(sequential[i], sequential[0]);
    }
    for round in 0..2 {
        let barrier = Barrier::new(8);
        // Half of the instances are created here and driven from a worker thread (libcosim does
        // this), half are created on their own thread.
        let premade: Vec<Option<Slave>> = (0..8).map(|i| (i % 2 == 0).then(|| fmu.instantiate(&format!("main-{round}-{i}")).unwrap())).collect();
        let parallel: Vec<Vec<u64>> = std::thread::scope(|scope| {
            let handles: Vec<_> = premade
                .into_iter()
                .enumerate()
                .map(|(i, pre)| {
                    let barrier = &barrier;
                    scope.spawn(move || {
                        let s = pre.unwrap_or_else(|| fmu.instantiate(&format!("thread-{round}-{i}")).unwrap());
                        barrier.wait();
                        fmu_run(fmu, &s, CONFIGS[i])
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (i, (p, q)) in parallel.iter().zip(&sequential).enumerate() {
            assert!(p == q, "round {round}, thread {i} {:?}: differs from the sequential run", CONFIGS[i]);
        }
    }
}

/// One C API run: solve, re-solve after frequency × 1.01 (warm-started); every series as bits.
/// `chain`: a 64-DOF chain from matrices with a stop on its last DOF, on rayon's global pool
/// (64 DOFs is where the assembly goes parallel), shared by all threads. ω = 0.3–1 rad/s, which
/// bds2 at k = 64 resolves (ω_max·h ≤ 0.65): at 0.03–0.1 rad/s the chain's top modes ring 60 times
/// a period between instants, the re-solve's follow cannot start the exact orbit there and walks
/// the discrete branch (93 s for one 1 % step: this test was the suite's longest by far).
unsafe fn c_run(a: &CApi, chain: bool, (w, scale): (f64, f64)) -> Vec<u64> {
    let p = if chain {
        let n = 64;
        let mut m = vec![0.0; n * n];
        let mut k = vec![0.0; n * n];
        let mut c = vec![0.0; n * n];
        for i in 0..n {
            m[i * n + i] = 1.0;
            k[i * n + i] = if i + 1 < n { 2.0 } else { 1.0 };
            c[i * n + i] = 0.02;
            if i + 1 < n {
                k[i * n + i + 1] = -1.0;
                k[(i + 1) * n + i] = -1.0;
            }
        }
        let p = unsafe { (a.from_matrices)(n, m.as_ptr(), k.as_ptr(), c.as_ptr(), w * 0.5, c"bds2".as_ptr(), 64) };
        assert!(!p.is_null(), "{}", last_error(a));
        unsafe {
            assert_eq!((a.set_parallel)(p, 1), PC_OK);
            assert_eq!((a.add_force)(p, n - 1, 0.1, 1, 0.0), PC_OK);
            assert_eq!((a.add_contact)(p, n - 1, 1, 1.0, 50.0, std::ptr::null_mut()), PC_OK);
            assert_eq!((a.set_outputs)(p, [0, n / 2, n - 1].as_ptr(), 3, [n - 1].as_ptr(), 1, std::ptr::null(), 0, 1), PC_OK);
        }
        p
    } else {
        let scene = CString::new(shipped("rigid-stop.toml")).unwrap();
        let p = unsafe { (a.from_scene_text)(scene.as_ptr()) };
        assert!(!p.is_null(), "{}", last_error(a));
        unsafe { assert_eq!((a.set_frequency)(p, w), PC_OK) };
        p
    };
    let mut bits = Vec::new();
    unsafe {
        assert_eq!((a.set_force_scale)(p, scale), PC_OK);
        for pass in 0..2 {
            if pass == 1 {
                assert_eq!((a.set_frequency)(p, (a.frequency)(p) * 1.01), PC_OK);
            }
            let r = (a.solve)(p);
            assert!(!r.is_null(), "{:?}: {}", (w, scale), last_error(a));
            let k = (a.steps)(r);
            let mut buf = vec![0.0; k];
            let dofs: &[usize] = if chain { &[0, 32, 63] } else { &[0] };
            for &d in dofs {
                assert_eq!((a.displacement)(r, d, buf.as_mut_ptr(), k), PC_OK);
                bits.extend(buf.iter().map(|x| x.to_bits()));
            }
            assert_eq!((a.velocity)(r, dofs[dofs.len() - 1], buf.as_mut_ptr(), k), PC_OK);
            bits.extend(buf.iter().map(|x| x.to_bits()));
            for i in 0..(a.contact_count)(r) {
                assert_eq!((a.contact_force)(r, i, buf.as_mut_ptr(), k), PC_OK);
                bits.extend(buf.iter().map(|x| x.to_bits()));
                assert_eq!((a.contact_gap)(r, i, buf.as_mut_ptr(), k), PC_OK);
                bits.extend(buf.iter().map(|x| x.to_bits()));
            }
            let (mut size, mut pivots, mut residual, mut warm) = (0, 0, 0.0, 0);
            assert_eq!((a.lcp)(r, &mut size, &mut pivots, &mut residual, &mut warm), PC_OK);
            bits.extend([size as u64, pivots as u64, residual.to_bits(), warm as u64]);
            bits.push((a.period)(r).to_bits());
            (a.result_free)(r);
        }
        (a.problem_free)(p);
    }
    bits
}

#[test]
fn c_api_eight_threads_with_different_parameters_are_bitwise_equal_to_sequential_runs() {
    let a = c_api();
    for chain in [false, true] {
        let sequential: Vec<Vec<u64>> = CONFIGS.iter().map(|&cfg| unsafe { c_run(a, chain, cfg) }).collect();
        for i in 1..8 {
            assert_ne!(sequential[i], sequential[0]);
        }
        let barrier = Barrier::new(8);
        let parallel: Vec<Vec<u64>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..8)
                .map(|i| {
                    let barrier = &barrier;
                    scope.spawn(move || {
                        barrier.wait();
                        unsafe { c_run(a, chain, CONFIGS[i]) }
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (i, (p, q)) in parallel.iter().zip(&sequential).enumerate() {
            assert!(p == q, "{} thread {i} {:?}: differs from the sequential run", if chain { "64-DOF chain" } else { "rigid stop" }, CONFIGS[i]);
        }
    }
}

// --- the C host: a long run and valgrind -----------------------------------------------------

fn compile(name: &str, source: &str, extra: &[String]) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exe = scratch(&format!("cc-{name}")).join(name);
    let out = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-O1", "-g"])
        .arg(format!("-I{}", root.join("include").display()))
        .arg(root.join(source))
        .args(extra)
        .arg("-o")
        .arg(&exe)
        .output()
        .expect("run cc");
    assert!(out.status.success(), "cc {source}: {}", String::from_utf8_lossy(&out.stderr));
    exe
}

fn fmu_host() -> &'static Path {
    static H: OnceLock<PathBuf> = OnceLock::new();
    H.get_or_init(|| compile("fmu_host", "examples/fmu_host.c", &["-ldl".into()]))
}

fn chain_fmu() -> &'static Fmu {
    static F: OnceLock<Fmu> = OnceLock::new();
    F.get_or_init(|| Fmu::package("stress-chain", &shipped("chain-3dof-two-stops.toml")))
}

/// "key a b" lines of the C host.
fn host_lines(out: &str, key: &str) -> Vec<Vec<String>> {
    out.lines().filter(|l| l.split_whitespace().next() == Some(key)).map(|l| l.split_whitespace().skip(1).map(String::from).collect()).collect()
}

fn run_host(dir: &Path, args: &[&str]) -> String {
    let o = Command::new(fmu_host()).arg(dir).args(args).output().unwrap();
    assert!(o.status.success(), "fmu_host {args:?}: {}\n{}", String::from_utf8_lossy(&o.stderr), String::from_utf8_lossy(&o.stdout));
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn the_c_host_reads_what_the_rust_host_reads() {
    let fmu = rigid();
    let out = run_host(&fmu.dir.join("unzipped"), &[]);
    let k: usize = host_lines(&out, "steps")[0][0].parse().unwrap();
    let period: f64 = host_lines(&out, "period")[0][0].parse().unwrap();
    let values: Vec<(String, f64)> = host_lines(&out, "output").into_iter().map(|v| (v[0].clone(), v[1].parse().unwrap())).collect();
    // displacement, velocity, contact force and gap, lcp.residual, accuracy.estimate.
    const REALS: usize = 6;
    assert_eq!(values.len(), 2 * REALS, "two periods × {REALS} Real outputs");
    // The same calls through libloading give the same numbers (printed with %.17g: exact).
    let s = fmu.instantiate("c-host-twin").unwrap();
    s.init(0.0);
    let h = period / k as f64;
    for i in 0..2 * k {
        assert_eq!(s.step(i as f64 * h, h), OK);
        if (i + 1) % k == 0 {
            let period_values = &values[((i + 1) / k - 1) * REALS..(i + 1) / k * REALS];
            for (name, v) in period_values {
                assert_eq!(s.real(name), *v, "{name} after period {}", (i + 1) / k);
            }
        }
    }
}

/// fmi2DoStep over a long run through the C host, with fmi2GetReal of every output after each
/// step: the resident size must not grow. Two runs: plain stepping (no allocation at all, so the
/// samples must be flat to the page), and stepping with a warm-started re-solve every 5000 steps
/// (frequency_in toggled), where the allocator may move the resident size up and down but must
/// not drift.
#[test]
fn a_long_run_keeps_its_resident_size() {
    let steps: u64 = std::env::var("PC_STRESS_STEPS").ok().and_then(|s| s.parse().ok()).unwrap_or(10_000_000);
    let dir = chain_fmu().dir.join("unzipped");
    let every = (steps / 20).max(1);
    let out = run_host(&dir, &["--steps", &steps.to_string(), "--rss-every", &every.to_string()]);
    let rss: Vec<(u64, u64)> = host_lines(&out, "rss").iter().map(|v| (v[0].parse().unwrap(), v[1].parse().unwrap())).collect();
    let rate: f64 = host_lines(&out, "steps_per_s")[0][0].parse().unwrap();
    assert_eq!(host_lines(&out, "nonfinite")[0][0], "0");
    println!("plain run: {steps} steps of chain-3dof-two-stops (10 Real outputs read per step): {rate:.0} steps/s; RSS [KiB] at step: {rss:?}");
    assert_eq!(rss.len(), 21);
    // After the first sample period (first touches of stack and buffers): at most 4 pages more.
    let settled = rss[1].1;
    let hi = rss[1..].iter().map(|r| r.1).max().unwrap();
    assert!(hi <= settled + 16, "RSS grew by {} KiB during plain stepping: {rss:?}", hi - settled);

    let steps = steps.min(1_000_000);
    let every = steps / 20;
    let out = run_host(&dir, &["--steps", &steps.to_string(), "--rss-every", &every.to_string(), "--resolve-every", "5000"]);
    let rss: Vec<(u64, u64)> = host_lines(&out, "rss").iter().map(|v| (v[0].parse().unwrap(), v[1].parse().unwrap())).collect();
    let rate: f64 = host_lines(&out, "steps_per_s")[0][0].parse().unwrap();
    assert_eq!(host_lines(&out, "nonfinite")[0][0], "0");
    println!("with a re-solve every 5000 steps ({} re-solves): {rate:.0} steps/s; RSS [KiB] at step: {rss:?}", steps / 5000);
    let first = rss[1..=10].iter().map(|r| r.1).max().unwrap();
    let second = rss[11..].iter().map(|r| r.1).max().unwrap();
    assert!(second <= first + 1024, "RSS drifted from {first} to {second} KiB over {} re-solves: {rss:?}", steps / 5000);
}

/// valgrind on PATH; else installed with apt-get when running as root; else None (skipped).
fn valgrind() -> Option<&'static str> {
    let present = || Command::new("valgrind").arg("--version").output().is_ok_and(|o| o.status.success());
    if present() {
        return Some("valgrind");
    }
    let root = std::fs::read_to_string("/proc/self/status").is_ok_and(|s| s.lines().any(|l| l.starts_with("Uid:") && l.split_whitespace().nth(1) == Some("0")));
    if root {
        eprintln!("valgrind is missing: apt-get install -y valgrind");
        let apt = |args: &[&str]| Command::new("apt-get").args(args).env("DEBIAN_FRONTEND", "noninteractive").status().is_ok_and(|s| s.success());
        if !apt(&["install", "-y", "-q", "valgrind"]) {
            apt(&["update", "-q"]);
            apt(&["install", "-y", "-q", "valgrind"]);
        }
        if present() {
            return Some("valgrind");
        }
    }
    None
}

/// Runs `cmd` under valgrind; asserts exit 0, no errors (invalid reads/writes, uninitialised
/// values) and no definitely lost blocks. Returns valgrind's summary lines.
fn under_valgrind(vg: &str, what: &str, cmd: &[&std::ffi::OsStr]) -> Vec<String> {
    let o = Command::new(vg).args(["--leak-check=full", "--errors-for-leak-kinds=definite", "--error-exitcode=99"]).args(cmd).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    let summary: Vec<String> = err
        .lines()
        .filter(|l| {
            [
                "ERROR SUMMARY",
                "in use at exit",
                "total heap usage",
                "definitely lost",
                "indirectly lost",
                "possibly lost",
                "still reachable",
                "suppressed:",
                "All heap blocks",
            ]
            .iter()
            .any(|k| l.contains(k))
        })
        .map(|l| l.split_once("== ").map_or(l, |x| x.1).trim().to_string())
        .collect();
    assert!(o.status.success(), "valgrind {what}: exit {:?}\n{err}", o.status.code());
    assert!(err.contains("ERROR SUMMARY: 0 errors"), "valgrind {what}:\n{err}");
    assert!(!err.contains("Invalid read") && !err.contains("Invalid write") && !err.contains("uninitialised"), "valgrind {what}:\n{err}");
    let definite_ok = err.contains("All heap blocks were freed") || err.contains("definitely lost: 0 bytes in 0 blocks") || !err.contains("definitely lost:");
    assert!(definite_ok, "valgrind {what}: definite leaks\n{err}");
    println!("valgrind {what}:\n  {}", summary.join("\n  "));
    summary
}

#[test]
fn valgrind_on_the_c_example_and_on_the_fmu_driven_by_the_c_host() {
    let Some(vg) = valgrind() else {
        println!("SKIPPED: valgrind is not installed and could not be installed (apt-get install -y valgrind needs root); no memory check was run");
        return;
    };
    // The C API example, on a scene with a contact (LCP, warm-started re-solve).
    let lib_dir = c_library().parent().unwrap().to_path_buf();
    let demo = compile(
        "capi_demo",
        "examples/capi_demo.c",
        &[format!("-L{}", lib_dir.display()), "-lperiodic_contact".into(), format!("-Wl,-rpath,{}", lib_dir.display())],
    );
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/rigid-stop.toml");
    under_valgrind(vg, "capi_demo rigid-stop.toml", &[demo.as_os_str(), scene.as_os_str()]);
    // The FMU through the C host: dlopen, instantiate, initialise, two periods, outputs, free.
    let dir = rigid().dir.join("unzipped");
    under_valgrind(vg, "fmu_host rigid-stop (two periods)", &[fmu_host().as_os_str(), dir.as_os_str()]);
    // … and with re-solves (warm-started) on the two-contact chain.
    let dir = chain_fmu().dir.join("unzipped");
    under_valgrind(
        vg,
        "fmu_host chain-3dof-two-stops (1500 steps, a re-solve every 300)",
        &[fmu_host().as_os_str(), dir.as_os_str(), "--steps".as_ref(), "1500".as_ref(), "--resolve-every".as_ref(), "300".as_ref()],
    );
}
