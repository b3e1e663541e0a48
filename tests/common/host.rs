//! A minimal FMI 2.0 co-simulation host on libloading: packages a scene with the CLI, unzips
//! the FMU, loads `binaries/linux64/PeriodicContact.so` and drives it through the 34 C
//! functions, with a real variadic C logger (tests/support/logger.c) that records every line.
#![allow(dead_code)]
use libloading::Library;
use std::collections::HashMap;
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex, OnceLock};

pub type Comp = *mut c_void;
pub const OK: c_int = 0;
pub const WARNING: c_int = 1;
pub const DISCARD: c_int = 2;
pub const ERROR: c_int = 3;
pub const CO_SIMULATION: c_int = 1;
pub const LAST_SUCCESSFUL_TIME: c_int = 2;
pub const TERMINATED: c_int = 3;

/// The 34 functions of an FMI 2.0 co-simulation binary.
pub const FMI2_CS_FUNCTIONS: [&str; 34] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];

type Vr = u32;

/// Typed pointers to the 34 functions.
pub struct Api {
    _lib: Library,
    pub get_types_platform: unsafe extern "C" fn() -> *const c_char,
    pub get_version: unsafe extern "C" fn() -> *const c_char,
    pub set_debug_logging: unsafe extern "C" fn(Comp, c_int, usize, *const *const c_char) -> c_int,
    pub instantiate: unsafe extern "C" fn(*const c_char, c_int, *const c_char, *const c_char, *const Callbacks, c_int, c_int) -> Comp,
    pub free_instance: unsafe extern "C" fn(Comp),
    pub setup_experiment: unsafe extern "C" fn(Comp, c_int, f64, f64, c_int, f64) -> c_int,
    pub enter_initialization_mode: unsafe extern "C" fn(Comp) -> c_int,
    pub exit_initialization_mode: unsafe extern "C" fn(Comp) -> c_int,
    pub terminate: unsafe extern "C" fn(Comp) -> c_int,
    pub reset: unsafe extern "C" fn(Comp) -> c_int,
    pub get_real: unsafe extern "C" fn(Comp, *const Vr, usize, *mut f64) -> c_int,
    pub get_integer: unsafe extern "C" fn(Comp, *const Vr, usize, *mut c_int) -> c_int,
    pub get_boolean: unsafe extern "C" fn(Comp, *const Vr, usize, *mut c_int) -> c_int,
    pub get_string: unsafe extern "C" fn(Comp, *const Vr, usize, *mut *const c_char) -> c_int,
    pub set_real: unsafe extern "C" fn(Comp, *const Vr, usize, *const f64) -> c_int,
    pub set_integer: unsafe extern "C" fn(Comp, *const Vr, usize, *const c_int) -> c_int,
    pub set_boolean: unsafe extern "C" fn(Comp, *const Vr, usize, *const c_int) -> c_int,
    pub set_string: unsafe extern "C" fn(Comp, *const Vr, usize, *const *const c_char) -> c_int,
    pub get_fmu_state: unsafe extern "C" fn(Comp, *mut *mut c_void) -> c_int,
    pub set_fmu_state: unsafe extern "C" fn(Comp, *mut c_void) -> c_int,
    pub free_fmu_state: unsafe extern "C" fn(Comp, *mut *mut c_void) -> c_int,
    pub serialized_fmu_state_size: unsafe extern "C" fn(Comp, *mut c_void, *mut usize) -> c_int,
    pub serialize_fmu_state: unsafe extern "C" fn(Comp, *mut c_void, *mut c_char, usize) -> c_int,
    pub deserialize_fmu_state: unsafe extern "C" fn(Comp, *const c_char, usize, *mut *mut c_void) -> c_int,
    pub get_directional_derivative: unsafe extern "C" fn(Comp, *const Vr, usize, *const Vr, usize, *const f64, *mut f64) -> c_int,
    pub set_real_input_derivatives: unsafe extern "C" fn(Comp, *const Vr, usize, *const c_int, *const f64) -> c_int,
    pub get_real_output_derivatives: unsafe extern "C" fn(Comp, *const Vr, usize, *const c_int, *mut f64) -> c_int,
    pub do_step: unsafe extern "C" fn(Comp, f64, f64, c_int) -> c_int,
    pub cancel_step: unsafe extern "C" fn(Comp) -> c_int,
    pub get_status: unsafe extern "C" fn(Comp, c_int, *mut c_int) -> c_int,
    pub get_real_status: unsafe extern "C" fn(Comp, c_int, *mut f64) -> c_int,
    pub get_integer_status: unsafe extern "C" fn(Comp, c_int, *mut c_int) -> c_int,
    pub get_boolean_status: unsafe extern "C" fn(Comp, c_int, *mut c_int) -> c_int,
    pub get_string_status: unsafe extern "C" fn(Comp, c_int, *mut *const c_char) -> c_int,
}

impl Api {
    pub fn load(path: &Path) -> Api {
        let lib = unsafe { Library::new(path) }.unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()));
        macro_rules! f {
            ($name:literal) => {
                *unsafe { lib.get($name) }.unwrap_or_else(|e| panic!("{}: missing {}: {e}", path.display(), $name))
            };
        }
        Api {
            get_types_platform: f!("fmi2GetTypesPlatform"),
            get_version: f!("fmi2GetVersion"),
            set_debug_logging: f!("fmi2SetDebugLogging"),
            instantiate: f!("fmi2Instantiate"),
            free_instance: f!("fmi2FreeInstance"),
            setup_experiment: f!("fmi2SetupExperiment"),
            enter_initialization_mode: f!("fmi2EnterInitializationMode"),
            exit_initialization_mode: f!("fmi2ExitInitializationMode"),
            terminate: f!("fmi2Terminate"),
            reset: f!("fmi2Reset"),
            get_real: f!("fmi2GetReal"),
            get_integer: f!("fmi2GetInteger"),
            get_boolean: f!("fmi2GetBoolean"),
            get_string: f!("fmi2GetString"),
            set_real: f!("fmi2SetReal"),
            set_integer: f!("fmi2SetInteger"),
            set_boolean: f!("fmi2SetBoolean"),
            set_string: f!("fmi2SetString"),
            get_fmu_state: f!("fmi2GetFMUstate"),
            set_fmu_state: f!("fmi2SetFMUstate"),
            free_fmu_state: f!("fmi2FreeFMUstate"),
            serialized_fmu_state_size: f!("fmi2SerializedFMUstateSize"),
            serialize_fmu_state: f!("fmi2SerializeFMUstate"),
            deserialize_fmu_state: f!("fmi2DeSerializeFMUstate"),
            get_directional_derivative: f!("fmi2GetDirectionalDerivative"),
            set_real_input_derivatives: f!("fmi2SetRealInputDerivatives"),
            get_real_output_derivatives: f!("fmi2GetRealOutputDerivatives"),
            do_step: f!("fmi2DoStep"),
            cancel_step: f!("fmi2CancelStep"),
            get_status: f!("fmi2GetStatus"),
            get_real_status: f!("fmi2GetRealStatus"),
            get_integer_status: f!("fmi2GetIntegerStatus"),
            get_boolean_status: f!("fmi2GetBooleanStatus"),
            get_string_status: f!("fmi2GetStringStatus"),
            _lib: lib,
        }
    }
}

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct Callbacks {
    pub logger: *const c_void,
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    pub step_finished: *const c_void,
    pub component_environment: *mut c_void,
}

unsafe extern "C" {
    fn calloc(n: usize, size: usize) -> *mut c_void;
    fn free(p: *mut c_void);
}

#[derive(Clone, Debug)]
pub struct LogLine {
    pub instance: String,
    pub status: c_int,
    pub category: String,
    pub format: String,
    pub message: String,
    /// The `ctx` that came back through componentEnvironment.
    pub ctx: usize,
}

#[derive(Default)]
pub struct Log {
    pub lines: Mutex<Vec<LogLine>>,
}

impl Log {
    pub fn all(&self) -> Vec<LogLine> {
        self.lines.lock().unwrap().clone()
    }
    pub fn find(&self, needle: &str) -> Option<LogLine> {
        self.all().into_iter().find(|l| l.message.contains(needle))
    }
    pub fn clear(&self) {
        self.lines.lock().unwrap().clear()
    }
}

#[repr(C)]
pub struct LogEnv {
    sink: extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char, *const c_char),
    ctx: *mut c_void,
}

fn text(p: *const c_char) -> String {
    if p.is_null() { "<NULL>".into() } else { unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned() }
}

extern "C" fn sink(ctx: *mut c_void, instance: *const c_char, status: c_int, category: *const c_char, format: *const c_char, message: *const c_char) {
    let log = unsafe { &*(ctx as *const Log) };
    log.lines.lock().unwrap().push(LogLine {
        instance: text(instance),
        status,
        category: text(category),
        format: text(format),
        message: text(message),
        ctx: ctx as usize,
    });
}

/// Copies the scene file `scene` and every file it references (at the same relative paths) into
/// `dir`; returns the copy's path.
pub fn copy_scene(scene: &Path, dir: &Path) -> PathBuf {
    let (parsed, from) = periodic_contact::scene::Scene::load(scene).unwrap();
    for r in parsed.referenced_files() {
        for f in &r.files {
            let to = dir.join(f);
            std::fs::create_dir_all(to.parent().unwrap()).unwrap();
            std::fs::copy(from.join(f), &to).unwrap_or_else(|e| panic!("{}: {e}", from.join(f).display()));
        }
    }
    let copy = dir.join(scene.file_name().unwrap());
    std::fs::copy(scene, &copy).unwrap();
    copy
}

/// A scratch folder under the system temp dir, unique per process and name.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("periodic-contact-tests-{}", std::process::id())).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The C logger, compiled once per process with `cc`.
fn logger_symbol() -> *const c_void {
    static LIB: OnceLock<(Library, usize)> = OnceLock::new();
    let (_, f) = LIB.get_or_init(|| {
        let dir = scratch("logger");
        let so = dir.join("liblogsink.so");
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/support/logger.c");
        let st = Command::new("cc").args(["-shared", "-fPIC", "-O1", "-o"]).arg(&so).arg(&src).status().expect("run cc");
        assert!(st.success(), "cc failed on {}", src.display());
        let lib = unsafe { Library::new(&so) }.unwrap();
        let f = unsafe { *lib.get::<unsafe extern "C" fn()>("test_logger").unwrap() } as usize;
        (lib, f)
    });
    *f as *const c_void
}

/// The FMU binary built by `cargo build --release`.
pub fn fmu_binary() -> PathBuf {
    let mut roots = Vec::new();
    if let Some(d) = std::env::var_os("CARGO_TARGET_DIR") {
        roots.push(PathBuf::from(d));
    }
    // target/<profile>/deps/<test> → target
    if let Some(t) = std::env::current_exe().ok().and_then(|e| e.parent()?.parent()?.parent().map(Path::to_path_buf)) {
        roots.push(t);
    }
    roots.push(Path::new(env!("CARGO_MANIFEST_DIR")).join("target"));
    for r in &roots {
        for profile in ["release", "debug"] {
            let p = r.join(profile).join("libPeriodicContact.so");
            if p.is_file() {
                let built = std::fs::metadata(&p).and_then(|m| m.modified()).unwrap();
                let root = Path::new(env!("CARGO_MANIFEST_DIR"));
                if let Some(newer) = newest_source(&[root.join("src"), root.join("fmu/src")]).filter(|(t, _)| *t > built) {
                    panic!("{} is older than {} (the FMU embeds the engine): rebuild it with\n  cargo build --release", p.display(), newer.1.display());
                }
                return p;
            }
        }
    }
    panic!(
        "the FMU binary libPeriodicContact.so was not found under {:?} (release, then debug).\n\
         Build it first with:  cargo build --release",
        roots
    );
}

/// The most recently modified Rust source under `dirs` (the CLI excepted: the FMU binary does not
/// contain it).
fn newest_source(dirs: &[PathBuf]) -> Option<(std::time::SystemTime, PathBuf)> {
    let mut best: Option<(std::time::SystemTime, PathBuf)> = None;
    let mut stack: Vec<PathBuf> = dirs.to_vec();
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                if !p.ends_with("bin") {
                    stack.push(p);
                }
            } else if p.extension().is_some_and(|x| x == "rs") {
                let t = e.metadata().and_then(|m| m.modified()).unwrap();
                if best.as_ref().is_none_or(|(b, _)| t > *b) {
                    best = Some((t, p));
                }
            }
        }
    }
    best
}

pub fn cli() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_periodic-contact"))
}

/// Solves `scene` with the CLI and returns its JSON.
pub fn cli_solve(scene: &Path) -> serde_json::Value {
    let out = scene.with_extension("json");
    let o = Command::new(cli()).arg("solve").arg(scene).arg("-o").arg(&out).output().unwrap();
    assert!(o.status.success(), "periodic-contact solve {}: {}", scene.display(), String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap()
}

/// The shipped scenes, fmu/scenes/*.toml, sorted.
pub fn shipped_scenes() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|x| x == "toml")).collect();
    v.sort();
    assert!(v.len() >= 7, "the shipped scenes are in {}", dir.display());
    v
}

/// The CLI's solution of the shipped scene `scene`, solved once per process (tests/cli.rs and
/// tests/frontends.rs share it; the fine blade alone takes minutes): a copy of the scene with the
/// files it references in a scratch folder (the CLI writes its JSON beside it), and the JSON.
pub fn shipped_solution(scene: &Path) -> &'static (PathBuf, serde_json::Value) {
    type Once = OnceLock<(PathBuf, serde_json::Value)>;
    static SOLVED: OnceLock<Mutex<HashMap<PathBuf, &'static Once>>> = OnceLock::new();
    // One lock per scene, taken outside the map's lock: different scenes solve concurrently.
    let once: &'static Once = SOLVED.get_or_init(Default::default).lock().unwrap().entry(scene.to_path_buf()).or_insert_with(|| Box::leak(Box::default()));
    once.get_or_init(|| {
        let name = scene.file_stem().unwrap().to_string_lossy().replace('-', "_");
        let copy = copy_scene(scene, &scratch(&format!("shipped_{name}")));
        let json = cli_solve(&copy);
        (copy, json)
    })
}

pub fn series(json: &serde_json::Value, field: &str, key: &str) -> Vec<f64> {
    json[field][key].as_array().unwrap_or_else(|| panic!("{field}[{key}] missing")).iter().map(|v| v.as_f64().unwrap()).collect()
}

/// A packaged, unzipped and loaded FMU.
pub struct Fmu {
    pub dir: PathBuf,
    pub fmu_file: PathBuf,
    pub scene: PathBuf,
    pub xml: String,
    pub guid: String,
    pub resources_uri: String,
    pub vars: HashMap<String, u32>,
    pub api: Api,
}

impl Fmu {
    /// Writes `scene_text` to a scratch folder, packages it with the CLI and loads the binary.
    pub fn package(name: &str, scene_text: &str) -> Fmu {
        let dir = scratch(name);
        let scene = dir.join(format!("{name}.toml"));
        std::fs::write(&scene, scene_text).unwrap();
        Fmu::package_scene(name, &scene)
    }

    /// Packages the scene file `scene` (with the files it references) into its folder and loads it.
    pub fn package_scene(name: &str, scene: &Path) -> Fmu {
        let (dir, scene) = (scene.parent().unwrap().to_path_buf(), scene.to_path_buf());
        let fmu_file = dir.join(format!("{name}.fmu"));
        let o = Command::new(cli()).arg("fmu").arg(&scene).arg("-o").arg(&fmu_file).arg("--binary").arg(fmu_binary()).output().unwrap();
        assert!(o.status.success(), "periodic-contact fmu: {}", String::from_utf8_lossy(&o.stderr));
        let unz = dir.join("unzipped");
        zip::ZipArchive::new(std::fs::File::open(&fmu_file).unwrap()).unwrap().extract(&unz).unwrap();
        let xml = std::fs::read_to_string(unz.join("modelDescription.xml")).unwrap();
        let guid = attr(&xml, "fmiModelDescription", "guid");
        let vars = variables(&xml);
        let api = Api::load(&unz.join("binaries/linux64/PeriodicContact.so"));
        let resources_uri = format!("file://{}", unz.join("resources").display());
        Fmu { dir, fmu_file, scene, xml, guid, resources_uri, vars, api }
    }

    pub fn vr(&self, name: &str) -> u32 {
        *self.vars.get(name).unwrap_or_else(|| panic!("no variable {name}; have {:?}", self.vars.keys()))
    }

    pub fn instantiate(&self, name: &str) -> Option<Slave<'_>> {
        Slave::new(self, name, &self.guid, Some(&self.resources_uri))
    }
}

/// The value of attribute `a` of the first element `el`.
pub fn attr(xml: &str, el: &str, a: &str) -> String {
    let start = xml.find(&format!("<{el}")).unwrap_or_else(|| panic!("no <{el}>"));
    let tag = &xml[start..start + xml[start..].find('>').unwrap()];
    let key = format!(" {a}=\"");
    let i = tag.find(&key).unwrap_or_else(|| panic!("no {a} in <{el}>")) + key.len();
    tag[i..i + tag[i..].find('"').unwrap()].to_string()
}

/// name → valueReference of every ScalarVariable.
pub fn variables(xml: &str) -> HashMap<String, u32> {
    xml.match_indices("<ScalarVariable")
        .map(|(i, _)| {
            let rest = &xml[i..];
            (attr(rest, "ScalarVariable", "name"), attr(rest, "ScalarVariable", "valueReference").parse().unwrap())
        })
        .collect()
}

/// One instance with its logger.
pub struct Slave<'a> {
    pub fmu: &'a Fmu,
    pub c: Comp,
    pub log: Arc<Log>,
    _env: Box<LogEnv>,
}

// FMI 2 allows driving an instance from another thread than the one that created it.
unsafe impl Send for Slave<'_> {}

pub fn callbacks(log: &Arc<Log>) -> (Box<LogEnv>, Callbacks) {
    let env = Box::new(LogEnv { sink, ctx: Arc::as_ptr(log) as *mut c_void });
    let cb = Callbacks {
        logger: logger_symbol(),
        allocate_memory: Some(calloc),
        free_memory: Some(free),
        step_finished: std::ptr::null(),
        component_environment: &*env as *const LogEnv as *mut c_void,
    };
    (env, cb)
}

impl<'a> Slave<'a> {
    pub fn new(fmu: &'a Fmu, name: &str, guid: &str, resources: Option<&str>) -> Option<Slave<'a>> {
        let log = Arc::new(Log::default());
        Slave::with_log(fmu, name, guid, resources, log).0
    }

    /// Also returns the log when instantiation fails.
    pub fn with_log(fmu: &'a Fmu, name: &str, guid: &str, resources: Option<&str>, log: Arc<Log>) -> (Option<Slave<'a>>, Arc<Log>) {
        let (env, cb) = callbacks(&log);
        let name = CString::new(name).unwrap();
        let guid = CString::new(guid).unwrap();
        let res = resources.map(|r| CString::new(r).unwrap());
        let c = unsafe { (fmu.api.instantiate)(name.as_ptr(), CO_SIMULATION, guid.as_ptr(), res.as_ref().map_or(std::ptr::null(), |r| r.as_ptr()), &cb, 0, 0) };
        if c.is_null() {
            return (None, log);
        }
        (Some(Slave { fmu, c, log: log.clone(), _env: env }), log)
    }

    pub fn vr(&self, name: &str) -> u32 {
        self.fmu.vr(name)
    }
    pub fn setup(&self, start: f64) -> c_int {
        unsafe { (self.fmu.api.setup_experiment)(self.c, 0, 0.0, start, 0, 0.0) }
    }
    pub fn enter(&self) -> c_int {
        unsafe { (self.fmu.api.enter_initialization_mode)(self.c) }
    }
    pub fn exit(&self) -> c_int {
        unsafe { (self.fmu.api.exit_initialization_mode)(self.c) }
    }
    /// Setup at `start`, enter and exit initialisation; asserts OK (or Warning).
    pub fn init(&self, start: f64) {
        assert_eq!(self.setup(start), OK);
        assert_eq!(self.enter(), OK);
        let s = self.exit();
        assert!(s == OK || s == WARNING, "fmi2ExitInitializationMode: {s}; log {:?}", self.log.all());
    }
    pub fn step(&self, t: f64, h: f64) -> c_int {
        unsafe { (self.fmu.api.do_step)(self.c, t, h, 1) }
    }
    pub fn get_reals(&self, vrs: &[u32]) -> (c_int, Vec<f64>) {
        let mut v = vec![f64::NAN; vrs.len()];
        let s = unsafe { (self.fmu.api.get_real)(self.c, vrs.as_ptr(), vrs.len(), v.as_mut_ptr()) };
        (s, v)
    }
    pub fn real(&self, name: &str) -> f64 {
        let (s, v) = self.get_reals(&[self.vr(name)]);
        assert_eq!(s, OK, "fmi2GetReal({name}); log {:?}", self.log.all());
        v[0]
    }
    pub fn integer(&self, name: &str) -> i32 {
        let mut v = 0;
        let s = unsafe { (self.fmu.api.get_integer)(self.c, &self.vr(name), 1, &mut v) };
        assert_eq!(s, OK, "fmi2GetInteger({name})");
        v
    }
    pub fn set_real(&self, name: &str, v: f64) -> c_int {
        unsafe { (self.fmu.api.set_real)(self.c, &self.vr(name), 1, &v) }
    }
    pub fn set_boolean(&self, name: &str, v: bool) -> c_int {
        unsafe { (self.fmu.api.set_boolean)(self.c, &self.vr(name), 1, &c_int::from(v)) }
    }
    pub fn set_integer(&self, name: &str, v: i32) -> c_int {
        unsafe { (self.fmu.api.set_integer)(self.c, &self.vr(name), 1, &v) }
    }
    pub fn derivative(&self, name: &str) -> f64 {
        let mut v = f64::NAN;
        let s = unsafe { (self.fmu.api.get_real_output_derivatives)(self.c, &self.vr(name), 1, &1, &mut v) };
        assert_eq!(s, OK, "fmi2GetRealOutputDerivatives({name})");
        v
    }
}

impl Drop for Slave<'_> {
    fn drop(&mut self) {
        unsafe { (self.fmu.api.free_instance)(self.c) };
    }
}
