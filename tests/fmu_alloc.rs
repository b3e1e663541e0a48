//! `fmi2DoStep` after the solve costs O(outputs) and allocates nothing: counted with a global
//! allocator around 20 000 steps (and output reads) of the generic shell with the contact model,
//! for a Hermite (cds) and a trigonometric (fourier) interpolant. Only the calling thread's
//! allocations count: the solve in fmi2ExitInitializationMode starts rayon's workers, which on a
//! loaded machine were still allocating their thread state during the 20 000 steps (2–4 spurious
//! allocations when the binary ran alone, none under `cargo test`). A separate binary for its
//! global allocator.
use periodic_contact::fmi::fmi2::types::*;
use periodic_contact::fmi::fmi2::{ffi, xml};
use periodic_contact::fmi::table::BaseType;
use periodic_contact::fmu_model::ContactModel;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ffi::CString;
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
thread_local! {
    // Armed on the thread that calls the FMU (const-initialised: no allocation, no destructor).
    static ARMED: Cell<bool> = const { Cell::new(false) };
}
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);
static OTHER_THREADS: AtomicUsize = AtomicUsize::new(0);
static ANY_ARMED: AtomicUsize = AtomicUsize::new(0);

fn count() {
    if ARMED.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    } else if ANY_ARMED.load(Ordering::Relaxed) > 0 {
        OTHER_THREADS.fetch_add(1, Ordering::Relaxed);
    }
}

fn arm(on: bool) {
    ARMED.with(|a| a.set(on));
    if on {
        ANY_ARMED.fetch_add(1, Ordering::SeqCst)
    } else {
        ANY_ARMED.fetch_sub(1, Ordering::SeqCst)
    };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

const SCENE: &str = r#"
[structure]
mass = [[2.0, 0.3], [0.3, 1.0]]
stiffness = [[5.0, -2.0], [-2.0, 3.0]]
[damping]
rayleigh = [0.01, 0.02]
[excitation]
frequency = 1.7
[[force]]
dof = 1
amplitude = 0.8
[discretization]
scheme = "cds"
steps = 128
[output]
displacement = [0, 1]
velocity = [0, 1]
acceleration = [1]
"#;

#[test]
fn do_step_allocates_nothing() {
    for scheme in ["cds", "fourier"] {
        let text = SCENE.replace("\"cds\"", &format!("\"{scheme}\""));
        let dir = std::env::temp_dir().join(format!("periodic-contact-alloc-{}-{scheme}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("scene.toml"), &text).unwrap();
        let model = ContactModel::from_scene_text(&text, "alloc").unwrap();
        let (_, guid) = xml::render(model.model_description());
        let (name, guid, uri) = (CString::new("alloc").unwrap(), CString::new(guid).unwrap(), CString::new(format!("file://{}", dir.display())).unwrap());
        let cb =
            Fmi2CallbackFunctions { logger: None, allocate_memory: None, free_memory: None, step_finished: None, component_environment: std::ptr::null_mut() };
        unsafe {
            let c = ffi::instantiate::<ContactModel>(name.as_ptr(), FMI2_CO_SIMULATION, guid.as_ptr(), uri.as_ptr(), &cb, 0, 0);
            assert!(!c.is_null());
            assert_eq!(ffi::setup_experiment::<ContactModel>(c, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(ffi::enter_initialization_mode::<ContactModel>(c), 0);
            assert_eq!(ffi::exit_initialization_mode::<ContactModel>(c), 0);
            let vrs: Vec<u32> = (0..model.model_description().variables.len() as u32).collect();
            let mut values = vec![0.0; vrs.len()];
            let table = &model.model_description().variables;
            let outputs: Vec<u32> = table.outputs().filter(|vr| table.get(*vr).unwrap().kind.base() == BaseType::Real).collect();
            let h = 0.013;
            arm(true);
            for i in 0..20_000 {
                let s = ffi::do_step::<ContactModel>(c, i as f64 * h, h, 1);
                let g = ffi::get_real::<ContactModel>(c, outputs.as_ptr(), outputs.len(), values.as_mut_ptr());
                if s != 0 || g != 0 {
                    arm(false);
                    panic!("{scheme}: status {s}/{g} at step {i}");
                }
            }
            arm(false);
            let n = ALLOCATIONS.swap(0, Ordering::SeqCst);
            eprintln!("{scheme}: {n} allocations on the calling thread, {} on other threads meanwhile", OTHER_THREADS.swap(0, Ordering::SeqCst));
            assert_eq!(n, 0, "{scheme}: {n} allocations in 20 000 fmi2DoStep + fmi2GetReal calls");
            assert!(values.iter().all(|v| v.is_finite()));
            let _ = vrs;
            ffi::free_instance::<ContactModel>(c);
        }
    }
}
