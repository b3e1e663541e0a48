//! The C API from C: examples/capi_demo.c is compiled with `cc` against the root cdylib
//! (libperiodic_contact.so, next to the CLI in target/<profile>/), run on a scene, and every
//! number it prints is checked against the Rust API for the same problem.
use periodic_contact::periodic::Tuning;
use periodic_contact::scene::Scene;
use periodic_contact::time::Pairing;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

const SCENE: &str = r#"
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
[discretization]
scheme = "cds"
steps = 48
[output]
displacement = [0, 1]
velocity = [0]
"#;

/// The same 2-DOF structure the demo builds from matrices.
const MATRICES: &str = r#"
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
[discretization]
scheme = "fourier"
steps = 32
[output]
displacement = [0, 1]
velocity = [0, 1]
"#;

/// The two-stop chain (rigid stops on DOF 1, direction +1, and DOF 2, direction −1), with one
/// pairing per contact set through `pc_problem_set_contact_pairing`. Under bds1 (the scene's cds
/// with a rigid same-paired stop is ill-posed: pivot limit): contact 0 keeps bds1's default
/// `same`, contact 1 is set to `forward`.
const CHAIN: &str = "fmu/scenes/chain-3dof-two-stops.toml";
const PAIRINGS: [Pairing; 2] = [Pairing::Same, Pairing::Forward];

/// The chain scene under bds1.
fn chain_bds1() -> String {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(CHAIN)).unwrap();
    assert!(text.contains("scheme = \"cds\""));
    text.replace("scheme = \"cds\"", "scheme = \"bds1\"")
}

/// target/<profile>/ of this test run, holding libperiodic_contact.so after `cargo build`
/// (`cargo test` builds the library as an rlib only, so the cdylib comes from `cargo build`).
fn cdylib_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_BIN_EXE_periodic-contact")).parent().unwrap().to_path_buf();
    let so = dir.join("libperiodic_contact.so");
    let how = "build it first with `cargo build` (same profile as the tests)";
    let built = std::fs::metadata(&so).and_then(|m| m.modified()).unwrap_or_else(|_| panic!("{} is missing; {how}", so.display()));
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for src in ["src/capi.rs", "src/capi/polish.rs", "include/periodic_contact.h"] {
        let changed = std::fs::metadata(root.join(src)).and_then(|m| m.modified()).unwrap();
        assert!(built >= changed, "{} is older than {src}; {how}", so.display());
    }
    dir
}

/// key → values by index, from "key index value" lines.
fn parse(out: &str) -> HashMap<String, Vec<String>> {
    let mut m: HashMap<String, Vec<String>> = HashMap::new();
    for line in out.lines() {
        let mut it = line.splitn(3, ' ');
        let (k, i, v) = (it.next().unwrap(), it.next().unwrap().parse::<usize>().unwrap(), it.next().unwrap_or(""));
        let e = m.entry(k.to_string()).or_default();
        assert_eq!(e.len(), i, "{line}");
        e.push(v.to_string());
    }
    m
}

fn numbers(m: &HashMap<String, Vec<String>>, key: &str) -> Vec<f64> {
    m.get(key).unwrap_or_else(|| panic!("the demo printed no {key}")).iter().map(|v| v.parse().unwrap()).collect()
}

fn assert_close(a: &[f64], b: &[f64], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    let scale = b.iter().fold(1e-300f64, |m, x| m.max(x.abs()));
    for (j, (x, y)) in a.iter().zip(b).enumerate() {
        assert!((x - y).abs() <= 1e-13 * scale, "{what}[{j}]: C {x} vs Rust {y}");
    }
}

#[test]
fn the_c_example_links_solves_and_prints_what_the_rust_api_computes() {
    let lib = cdylib_dir();
    let work = std::env::temp_dir().join(format!("periodic-contact-capi-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exe = work.join("capi_demo");
    let cc = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-O1"])
        .arg(format!("-I{}", root.join("include").display()))
        .arg(root.join("examples/capi_demo.c"))
        .arg(format!("-L{}", lib.display()))
        .arg("-lperiodic_contact")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .arg("-o")
        .arg(&exe)
        .output()
        .expect("run cc");
    assert!(cc.status.success(), "cc: {}", String::from_utf8_lossy(&cc.stderr));
    let scene = work.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let chain = work.join("chain-bds1.toml");
    std::fs::write(&chain, chain_bds1()).unwrap();
    let run = Command::new(&exe).arg(&scene).arg(&chain).args(PAIRINGS.map(|p| p.name())).output().unwrap();
    assert!(run.status.success(), "capi_demo: {}", String::from_utf8_lossy(&run.stderr));
    let out = parse(&String::from_utf8(run.stdout).unwrap());
    assert_eq!(out["version"][0], env!("CARGO_PKG_VERSION"));

    // 1. The scene as is.
    let p = Scene::parse(SCENE, "t").unwrap().to_problem("t").unwrap();
    let r = p.solve().unwrap();
    assert_eq!(out["scene.steps"][0], "48");
    assert_eq!(numbers(&out, "scene.period")[0], r.period);
    assert_eq!(out["scene.lcp_size"][0], "0");
    assert_close(&numbers(&out, "scene.x"), &r.displacement["0"], "scene.x");
    assert_close(&numbers(&out, "scene.v"), &r.velocity["0"], "scene.v");
    // The error estimate of the C API is the Rust API's (a second solve at k/2).
    let a = periodic_contact::analysis::accuracy::estimate(&p, &r);
    assert_eq!(out["scene.accuracy"][0], "1", "estimated by default: {:?}", out["scene.accuracy_method"]);
    assert_close(&numbers(&out, "scene.accuracy")[1..2], &[a.estimate.unwrap()], "scene.accuracy");
    assert!(out["scene.accuracy_method"][0].starts_with("richardson"), "{:?}", out["scene.accuracy_method"]);

    // 2. frequency × 1.05 and force scale 2.
    let tuning = Tuning { frequency: 1.05 * 1.7, force_scale: 2.0, gap_offset: 0.0, motion_scale: 1.0, normal_force_scale: 1.0 };
    let r2 = tuning.apply(&p, p.discretization()).unwrap().solve().unwrap();
    assert_eq!(numbers(&out, "tuned.period")[0], r2.period);
    assert_close(&numbers(&out, "tuned.x"), &r2.displacement["0"], "tuned.x");
    assert_close(&numbers(&out, "tuned.v"), &r2.velocity["0"], "tuned.v");

    // 3. Matrices.
    let r3 = Scene::parse(MATRICES, "m").unwrap().to_problem("m").unwrap().solve().unwrap();
    assert_close(&numbers(&out, "matrices.x"), &r3.displacement["0"], "matrices.x");
    assert_close(&numbers(&out, "matrices.v"), &r3.velocity["0"], "matrices.v");

    // 4. Errors: codes and messages.
    assert_eq!(out["bad_dof.code"][0], "2", "PC_ERROR_INPUT");
    assert!(out["bad_dof.message"][0].contains('7'), "{:?}", out["bad_dof.message"]);
    assert_eq!(out["missing.null"][0], "1");
    assert!(out["missing.message"][0].contains("/nonexistent/scene.toml"), "{:?}", out["missing.message"]);
    assert_eq!(out["null.code"][0], "1", "PC_ERROR_ARGUMENT");

    // 5. Contacts: the problem's accessors give the scene's contacts, each contact is solved
    //    with the pairing set for it alone, and force ⊥ paired_gap holds per contact.
    let mut chain_problem = Scene::parse(&chain_bds1(), "chain").unwrap().to_problem("chain").unwrap();
    for (i, p) in PAIRINGS.iter().enumerate() {
        chain_problem.set_contact_pairing(i, Some(*p)).unwrap();
    }
    let rc = chain_problem.solve().unwrap();
    assert_eq!(out["contacts.dof_count"][0], "3");
    assert_eq!(out["contacts.count"][0], "2");
    assert_eq!(out["contacts.bad_index"][0], "1", "PC_ERROR_ARGUMENT");
    assert_eq!(out["contacts.bad_name"][0], "2", "PC_ERROR_INPUT");
    let k = rc.steps;
    for (i, (c, pairing)) in rc.contacts.iter().zip(PAIRINGS).enumerate() {
        assert_eq!(out["contacts.dof"][i], c.dof.to_string());
        assert_eq!(out["contacts.direction"][i], c.direction.to_string());
        assert_eq!(c.dof, [1, 2][i], "the scene's DOF");
        assert_eq!(c.direction, [1, -1][i], "the scene's direction");
        assert_eq!(out["contacts.pairing"][i], pairing.name());
        assert_eq!(out["contacts.result_pairing"][i], pairing.name());
        assert_eq!(c.pairing, pairing.name(), "the JSON's pairing of contact {i}");
        let (f, g, pg) =
            (numbers(&out, &format!("contacts.force{i}")), numbers(&out, &format!("contacts.gap{i}")), numbers(&out, &format!("contacts.paired_gap{i}")));
        assert_close(&f, &c.force, "force");
        assert_close(&g, &c.gap, "gap");
        assert_close(&pg, &c.paired_gap, "paired_gap");
        // The paired gap is the gap `offset` instants later: 1 for forward, 0 for same.
        let s = pairing.offset();
        for j in 0..k {
            assert_eq!(pg[j], g[(j + s) % k], "contact {i} ({}) paired_gap[{j}]", pairing.name());
        }
        let scale = f.iter().fold(0f64, |m, x| m.max(x.abs())) * g.iter().fold(0f64, |m, x| m.max(x.abs()));
        assert!(f.iter().any(|&x| x > 0.0), "contact {i} never touches: the test would be vacuous");
        let worst = f.iter().zip(&pg).fold(0f64, |m, (a, b)| m.max((a * b).abs()));
        assert_eq!(numbers(&out, "contacts.complementarity")[i], worst);
        assert!(worst <= 1e-9 * scale, "contact {i}: max |force·paired_gap| = {worst:e} > 1e-9·{scale:e}");
        assert!(pg.iter().all(|&x| x >= -1e-9 * scale.sqrt().max(1.0)), "contact {i}: rigid paired gap < 0");
    }
    assert_eq!(out["contacts.cold.warm_start"][0], "cold");
    let warm = &out["contacts.warm.warm_start"][0];
    assert!(["accepted", "repaired", "rejected"].contains(&warm.as_str()), "{warm}");
    assert!(!out["contacts.cold.path"][0].is_empty() && !out["contacts.warm.path"][0].is_empty());

    polish_section(&out);
}

/// Section 6: the rigid stop with sticking (src/formulation.md §6.3) through the C API with the polish, at
/// times between the instants, against the exact orbit (`periodic_contact::exact`, closed-form
/// flows of its own) to 1e-8 of the peak-to-peak amplitude; without the polish, the cubic Hermite
/// through the Rust API's samples, computed here.
fn polish_section(out: &HashMap<String, Vec<String>>) {
    use periodic_contact::exact::{Oscillator, RigidStopOrbit};
    let osc = Oscillator::new(1.0, 0.1, 1.0, 1.0, 1.0);
    let exact = RigidStopOrbit::solve(&osc, 0.5).unwrap();
    assert!(exact.has_sticking());
    let ptp = exact.peak_to_peak();
    assert_eq!(out["polish.status"][0], "1", "PC_POLISH_POLISHED: {:?}", out["polish.reason"]);
    assert_eq!(out["polish.reason"][0], "");
    let kinds = &out["polish.event_kind"];
    assert_eq!(kinds.len(), 2, "{kinds:?}");
    assert!(kinds.contains(&"impact".to_string()) && kinds.contains(&"release".to_string()), "{kinds:?}");
    let times = numbers(out, "polish.event_time");
    let impulses = numbers(out, "polish.event_impulse");
    let impact = kinds.iter().position(|k| k == "impact").unwrap();
    let ti = exact.impact_time().unwrap().rem_euclid(exact.period());
    assert!((times[impact] - ti).abs() < 1e-8 * exact.period(), "impact at {} vs exact {ti}", times[impact]);
    assert!((impulses[impact] - exact.impact_impulse()).abs() < 1e-8 * exact.impact_impulse(), "impulse {} vs {}", impulses[impact], exact.impact_impulse());
    assert_eq!(out["polish.bad_event"][0], "1", "PC_ERROR_ARGUMENT");
    assert_eq!(out["plain.bad_dof"][0], "1", "PC_ERROR_ARGUMENT");
    let (t, x, v, f, g) =
        (numbers(out, "polish.t"), numbers(out, "polish.x"), numbers(out, "polish.v"), numbers(out, "polish.force"), numbers(out, "polish.gap"));
    let h = exact.period() / 256.0;
    let mut worst = 0f64;
    for j in 0..t.len() {
        assert!((t[j] / h - (t[j] / h).round()).abs() > 0.05, "t = {} falls between instants", t[j]);
        assert_eq!(out["polish.exact"][j], "1");
        assert_eq!(out["polish.exact_contact"][j], "1");
        let (xe, ve, fe) = exact.eval(t[j]);
        for (got, want) in [(x[j], xe), (v[j], ve), (g[j], 0.5 - xe), (f[j], fe)] {
            worst = worst.max((got - want).abs() / ptp);
        }
    }
    eprintln!("C API polish: max error at 6 times between instants {worst:.2e} of ptp");
    assert!(worst < 1e-8, "{worst:e}");
    assert!(f.iter().any(|&z| z > 0.1), "a time in the sticking arc: {f:?}");

    // A fallback is a typed outcome with its reason, also a warning; state_at then interpolates.
    assert_eq!(out["fallback.status"][0], "2", "PC_POLISH_FALLBACK");
    assert!(out["fallback.reason"][0].contains("no contact outputs"), "{:?}", out["fallback.reason"]);
    assert_eq!(out["fallback.exact"][0], "0");
    assert!(
        out["fallback.warning"].iter().any(|w| w.starts_with("polish: fell back") && w.contains(&out["fallback.reason"][0])),
        "{:?}",
        out["fallback.warning"]
    );

    // Without the polish: exact = 0 and the cubic Hermite through the LCP's (x_j, v_j).
    assert_eq!(out["plain.status"][0], "0", "PC_POLISH_OFF");
    assert_eq!(out["plain.events"][0], "0");
    let model = osc.model(vec![Oscillator::stop(0.5, periodic_contact::model::Compliance::Rigid)]);
    let outputs = periodic_contact::periodic::OutputSelection { displacement: vec![0], velocity: vec![0], acceleration: vec![], contacts: true };
    let disc = periodic_contact::time::Discretization { scheme: periodic_contact::time::Scheme::Cds, steps: 256, pairing: None };
    let r = periodic_contact::periodic::PeriodicProblem::new(model, disc, outputs, Default::default()).unwrap().solve().unwrap();
    let (xs, vs) = (&r.displacement["0"], &r.velocity["0"]);
    let (t, x, v) = (numbers(out, "plain.t"), numbers(out, "plain.x"), numbers(out, "plain.v"));
    for j in 0..t.len() {
        assert_eq!(out["plain.exact"][j], "0");
        let u = t[j].rem_euclid(exact.period()) / h;
        let (i, s) = (u.floor() as usize, u - u.floor());
        let i1 = (i + 1) % 256;
        let (h00, h10, h01, h11) = (2.0 * s.powi(3) - 3.0 * s * s + 1.0, s.powi(3) - 2.0 * s * s + s, -2.0 * s.powi(3) + 3.0 * s * s, s.powi(3) - s * s);
        let xh = h00 * xs[i] + h10 * h * vs[i] + h01 * xs[i1] + h11 * h * vs[i1];
        let vh = (6.0 * s * s - 6.0 * s) * (xs[i] - xs[i1]) / h + (3.0 * s * s - 4.0 * s + 1.0) * vs[i] + (3.0 * s * s - 2.0 * s) * vs[i1];
        assert!((x[j] - xh).abs() < 1e-12 * ptp && (v[j] - vh).abs() < 1e-12 * ptp, "t = {}: C ({}, {}) vs Hermite ({xh}, {vh})", t[j], x[j], v[j]);
    }
}

#[test]
fn a_contact_takes_its_own_pairing_from_the_scene_and_a_bad_name_is_refused() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(CHAIN)).unwrap();
    let with = |pairing: &str| text.replacen("gap = 0.3", &format!("gap = 0.3\npairing = \"{pairing}\""), 1);
    let p = Scene::parse(&with("same"), "t").unwrap().to_problem("t").unwrap();
    assert_eq!(p.contact_pairing(0), None);
    assert_eq!(p.contact_pairing(1), Some(Pairing::Same));
    assert_eq!([p.pairing_at(0), p.pairing_at(1)], [Pairing::Forward, Pairing::Same], "cds's default for rigid contact, then the override");
    // The override survives a tuned copy (Tuning goes through with_model).
    let tuned = Tuning::of(&p).apply(&p, p.discretization()).unwrap();
    assert_eq!(tuned.contact_pairing(1), Some(Pairing::Same));
    let err = Scene::parse(&with("backward"), "t").unwrap().to_problem("t").unwrap_err().to_string();
    assert!(err.contains("contact[1].pairing") && err.contains("backward"), "{err}");
    let mut p = p;
    assert!(p.set_contact_pairing(2, Some(Pairing::Same)).is_err(), "index checked");
}
