//! The command-line tool: every shipped scene solves; bad input exits with status 2 and a message
//! naming the file and the field.
use crate::common::host::{shipped_scenes, shipped_solution};
use std::path::Path;
use std::process::Command;

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_periodic-contact"))
}

#[test]
fn every_shipped_scene_solves_from_the_cli() {
    let list = shipped_scenes();
    assert!(list.len() >= 4, "expected the example scenes in fmu/scenes");
    // Solved once per process, on a copy (tests/frontends.rs compares the same JSON with the C API and the FMU).
    for scene in list {
        let (_, v) = shipped_solution(&scene);
        assert_eq!(v["lcp"]["status"], "solved", "{}", scene.display());
        let k = v["steps"].as_u64().unwrap() as usize;
        assert_eq!(v["time"].as_array().unwrap().len(), k);
        for series in v["displacement"].as_object().unwrap().values() {
            let s = series.as_array().unwrap();
            assert_eq!(s.len(), k);
            assert!(s.iter().all(|x| x.as_f64().is_some_and(f64::is_finite)));
        }
        for c in v["contacts"].as_array().unwrap() {
            // Force ≥ 0 (compressive) and clearance ≥ 0 at the certified tolerance.
            assert!(c["force"].as_array().unwrap().iter().all(|x| x.as_f64().unwrap() >= 0.0));
            if c["stiffness"].is_null() {
                // Rigid: the clearance never goes below 0 (a compliant one does while it penetrates).
                assert!(c["gap"].as_array().unwrap().iter().all(|x| x.as_f64().unwrap() >= -1e-8));
            }
        }
    }
}

#[test]
fn the_default_run_prints_the_table() {
    let o = cli().output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    for key in ["amplitude", "max contact force", "fraction of period in contact", "LCP size", "pivots", "residual", "time"] {
        assert!(text.contains(key), "missing {key} in\n{text}");
    }
}

fn bad(scene: &str) -> String {
    let dir = std::env::temp_dir().join(format!("pc-bad-{}-{}", std::process::id(), scene.len()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(&path, scene).unwrap();
    let o = cli().arg("solve").arg(&path).arg("-o").arg(dir.join("r.json")).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "stderr: {}", String::from_utf8_lossy(&o.stderr));
    assert!(!dir.join("r.json").exists(), "no output is written on bad input");
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(err.contains("bad.toml"), "the message names the file: {err}");
    err
}

const GOOD: &str = "[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n[excitation]\nfrequency = 1.0\n[[force]]\ndof = 0\namplitude = 1.0\n";

#[test]
fn bad_input_exits_2_naming_the_field_and_value() {
    assert!(bad("[structure\nmass = 1").contains("line"));
    assert!(bad(&GOOD.replace("frequency = 1.0", "frequncy = 1.0")).contains("did you mean `frequency`"));
    assert!(bad(&GOOD.replace("mass = [[1.0]]", "mass = [[-1.0]]")).contains("structure.mass"));
    let e = bad(&GOOD.replace("dof = 0", "dof = 7"));
    assert!(e.contains("force[0].dof") && e.contains('7'), "{e}");
    let e = bad(&format!("{GOOD}[discretization]\nscheme = \"rk4\"\n"));
    assert!(e.contains("discretization.scheme") && e.contains("rk4"), "{e}");
    let e = bad(&format!("{GOOD}[[contact]]\ndof = 0\ngap = -0.5\n"));
    assert!(e.contains("contact[0].gap") && e.contains("-0.5"), "{e}");
    let e = bad(&GOOD.replace("stiffness = [[1.0]]", "stiffness = [[1.0, 2.0], [3.0, 1.0]]"));
    assert!(e.contains("structure.stiffness"), "{e}");
    let e = bad(&GOOD.replace("amplitude = 1.0", "amplitude = nan"));
    assert!(e.contains("force[0].amplitude") && e.contains("NaN"), "{e}");
    let e = bad(&format!("{GOOD}[discretization]\nsteps = 2\n"));
    assert!(e.contains("discretization.steps") && e.contains('2'), "{e}");
    let e = bad(&GOOD.replace("amplitude = 1.0", "amplitude = 1.0\nharmonic = 300"));
    assert!(e.contains("force[0].harmonic") && e.contains("300"), "{e}");
}

/// `bench` over the class: every case and a drawn member certify at a small k, the family's spread
/// line is printed, and a measurement that overruns `--timeout` is reported as such, not awaited.
#[test]
fn bench_covers_the_class_and_stops_at_its_timeout() {
    let o = cli()
        .args(["bench", "--case", "rigid-stick,rigid-impact,compliant,chain", "--steps", "64", "--repeats", "1", "--draws", "1", "--timeout", "60"])
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", String::from_utf8_lossy(&o.stderr));
    for case in ["rigid-stick", "rigid-impact", "compliant", "chain"] {
        assert!(out.contains(&format!("\n{case}: ")), "{case} missing:\n{out}");
    }
    // Two members (nominal + 1 draw) per case, each certified to the default tolerance.
    let rows: Vec<&str> = out.lines().filter(|l| l.starts_with("| 64 |") && !l.contains("spread")).collect();
    assert_eq!(rows.len(), 8, "{out}");
    for r in &rows {
        let residual: f64 = r.split('|').nth(8).unwrap().trim().parse().unwrap_or(f64::NAN);
        assert!(residual <= 1e-9, "not certified: {r}");
    }
    assert_eq!(out.matches("spread of 2 members").count(), 4, "{out}");
    // The rigid reduced blade, within cds's limit (k ≥ 813 for this model).
    let o = cli().args(["bench", "--case", "blade", "--steps", "1024", "--repeats", "1", "--draws", "1", "--timeout", "120"]).output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}");
    let rows: Vec<&str> = out.lines().filter(|l| l.starts_with("| 1024 | 3072 |")).collect();
    assert_eq!(rows.len(), 2, "{out}");
    for r in &rows {
        let residual: f64 = r.split('|').nth(8).unwrap().trim().parse().unwrap_or(f64::NAN);
        assert!(residual <= 1e-9, "not certified: {r}");
    }
    let t = std::time::Instant::now();
    let o = cli().args(["bench", "--case", "chain", "--steps", "4096", "--repeats", "1", "--method", "lemke", "--timeout", "0.5"]).output().unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("timeout"), "{}", String::from_utf8_lossy(&o.stdout));
    assert!(t.elapsed().as_secs_f64() < 10.0, "the child was not stopped");
}

/// `solve --export-lcp`: the exported LCP, solved independently by dense lexicographic Lemke
/// (`lcp --method lemke`, no structure used), gives the contact forces of the solve, for a single
/// rigid contact and for the two-stop chain (m = 2: z interleaves the contacts per instant).
#[test]
fn the_exported_lcp_solved_by_dense_lemke_gives_the_solve_forces() {
    let dir = std::env::temp_dir().join(format!("pc-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for scene in ["rigid-stop.toml", "chain-3dof-two-stops.toml"] {
        let scene_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes").join(scene);
        let (dat, json, out) = (dir.join("a.dat"), dir.join("r.json"), dir.join("z.json"));
        let o = cli().args(["solve", scene_path.to_str().unwrap(), "-o", json.to_str().unwrap(), "--export-lcp", dat.to_str().unwrap()]).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let o = cli().args(["lcp", dat.to_str().unwrap(), "--method", "lemke", "-o", out.to_str().unwrap()]).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let z: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        assert_eq!(z["structure"], "dense");
        let z: Vec<f64> = z["z"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let contacts = r["contacts"].as_array().unwrap();
        let m = contacts.len();
        assert_eq!(z.len(), m * r["steps"].as_u64().unwrap() as usize);
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for (c, contact) in contacts.iter().enumerate() {
            for (j, f) in contact["force"].as_array().unwrap().iter().enumerate() {
                let f = f.as_f64().unwrap();
                worst = worst.max((f - z[j * m + c]).abs());
                scale = scale.max(f.abs());
            }
        }
        assert!(scale > 0.0 && worst <= 1e-9 * scale, "{scene}: forces differ by {worst:e} (scale {scale:e})");
    }
}

/// `export`: the model of fmu/scenes/compliant-stop.toml, as its file states it (m = 1, c = 0.05,
/// k = 1, k_c = 10, g0 = 1, F = cos 1.3 t), read back through the Matrix Market reader.
#[test]
fn export_writes_the_model_the_scene_states() {
    let dir = std::env::temp_dir().join(format!("pc-model-export-{}", std::process::id()));
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/compliant-stop.toml");
    let o = cli().arg("export").arg(&scene).arg("-o").arg(&dir).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let entry = |name: &str| {
        let a = periodic_contact::fe::read_matrix_market(&dir.join(name)).unwrap();
        (a.nrows(), a.ncols(), a.val().to_vec())
    };
    assert_eq!(entry("M.mtx"), (1, 1, vec![1.0]));
    assert_eq!(entry("K.mtx"), (1, 1, vec![1.0]));
    assert_eq!(entry("C.mtx"), (1, 1, vec![0.05]));
    assert_eq!(entry("B.mtx"), (1, 1, vec![1.0]));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("model.json")).unwrap()).unwrap();
    assert_eq!((v["n"].as_u64(), v["m"].as_u64(), v["omega"].as_f64()), (Some(1), Some(1), Some(1.3)));
    let c = &v["contacts"][0];
    assert_eq!((c["gap_mean"].as_f64(), c["stiffness"].as_f64()), (Some(1.0), Some(10.0)));
    let f = &v["forces"][0];
    assert_eq!((f["dof"].as_u64(), f["term"]["harmonic"].as_u64(), f["term"]["cos"].as_f64()), (Some(0), Some(1), Some(1.0)));
    assert_eq!(v["outputs"][0]["row"], serde_json::json!([[0, 1.0]]));
    // A scene that cannot be built writes nothing.
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[structure]\nmass = [[1.0]]\n").unwrap();
    let o = cli().arg("export").arg(&bad).arg("-o").arg(dir.join("bad")).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(!dir.join("bad").join("model.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn solve_draws_the_friction_dampers_hysteresis_loop_and_refuses_a_scene_without_friction() {
    let tmp = std::env::temp_dir().join(format!("pc-hysteresis-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes");
    let (json, png) = (tmp.join("f.json"), tmp.join("loop.png"));
    let o =
        cli().arg("solve").arg(scenes.join("friction-damper.toml")).args(["--no-estimate", "-o"]).arg(&json).arg("--hysteresis").arg(&png).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000, "a PNG");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let e = v["friction"][0]["dissipated_energy"].as_f64().unwrap();
    // Masing's bound for the shipped damper (μN = 0.5, k_t = 2): 4·μN·(X − μN/k_t) with X its amplitude.
    let x = v["friction"][0]["displacement"].as_array().unwrap().iter().map(|u| u.as_f64().unwrap().abs()).fold(0.0, f64::max);
    assert!((e - 4.0 * 0.5 * (x - 0.25)).abs() < 0.02 * e, "energy {e} against Masing's {}", 4.0 * 0.5 * (x - 0.25));
    assert!(err.contains("dissipated per cycle"), "{err}");
    let o =
        cli().arg("solve").arg(scenes.join("rigid-stop.toml")).arg("-o").arg(tmp.join("r.json")).arg("--hysteresis").arg(tmp.join("no.png")).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--hysteresis") && err.contains("[[friction]]"), "{err}");
    assert!(!tmp.join("no.png").exists());
}

/// `continue` writes each point's CSV row as the point comes, so that a walk stopped short (a
/// timeout's signal, Ctrl-C) leaves its points: killed after its third point line, the CSV holds
/// the header and at least those three rows, each a frequency between --from and --to.
#[test]
fn a_continuation_killed_mid_walk_leaves_the_rows_of_its_points() {
    use std::io::BufRead;
    let dir = crate::common::host::scratch("killed-walk");
    let csv = dir.join("branch.csv");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/compliant-stop.toml");
    // Steps of 1e-4 over 0.5: thousands of points, far more than reach the kill.
    let mut child = cli()
        .args(["continue", scene.to_str().unwrap(), "--param", "frequency", "--from", "1.3", "--to", "0.8", "--max-step", "1e-4", "--no-plot", "-o"])
        .arg(&csv)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let lines = std::io::BufReader::new(child.stderr.take().unwrap()).lines();
    let printed = lines.map_while(Result::ok).filter(|l| l.trim_start().starts_with("point frequency")).take(3).count();
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert_eq!(printed, 3, "the walk printed fewer than 3 points");
    assert!(status.code().is_none(), "the walk ended before it was killed ({status}): the test did not stop it mid-walk");
    let text = std::fs::read_to_string(&csv).expect("the killed walk left no CSV");
    let mut rows = text.lines();
    let header = rows.next().unwrap_or_default();
    assert!(header.starts_with("frequency ") && header.contains(",amplitude_0 "), "header: {text}");
    let rows: Vec<&str> = rows.collect();
    assert!(rows.len() >= 3, "{} rows after 3 points printed: {text}", rows.len());
    for r in rows {
        let f: f64 = r.split(',').next().unwrap().parse().unwrap_or(f64::NAN);
        assert!((0.8..=1.3).contains(&f), "a row's frequency {f} is off the walk's range: {r}");
        assert_eq!(r.split(',').count(), header.split(',').count(), "a row not whole: {r}");
    }
}
