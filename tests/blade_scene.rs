//! Scenes with finite-element input: Matrix Market files, fixed DOFs, the blade generator with
//! named nodes, the Craig–Bampton reduction (eigenfrequencies and periodic responses against the
//! full model), the casing, and the error messages.
use periodic_contact::fe::{Blade, BladeParams, write_matrix_market};
use periodic_contact::model::Harmonic;
use periodic_contact::reduction::sparse_modes;
use periodic_contact::response::Response;
use periodic_contact::scene::{Scene, SceneModel};
use std::path::{Path, PathBuf};

fn build(text: &str) -> SceneModel {
    Scene::parse(text, "test.toml").unwrap().build("test.toml").unwrap()
}

fn build_err(text: &str) -> String {
    match Scene::parse(text, "bad.toml").and_then(|s| s.build("bad.toml")) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn coarse_scene() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-coarse.toml")).unwrap()
}

/// The coarse blade scene with its [reduction] section replaced (`None`: no reduction).
fn blade_scene(reduction: Option<&str>, damping: &str, steps: usize, frequency: f64) -> String {
    let base = coarse_scene();
    let mut out = String::new();
    let mut skip = false;
    for line in base.lines() {
        if line.starts_with('[') {
            skip = line == "[reduction]" || line == "[damping]" || line == "[excitation]" || line == "[discretization]";
        }
        if !skip {
            out.push_str(line);
            out.push('\n');
        }
    }
    if let Some(r) = reduction {
        out.push_str(&format!("[reduction]\nmethod = \"craig-bampton\"\n{r}\n"));
    }
    out.push_str(&format!("[damping]\n{damping}\n[excitation]\nfrequency = {frequency}\n"));
    // bds2 (A-stable): the full FE model has ω_max ≈ 1.1e7 rad/s, far past cds's ω_max·h < 2.
    out.push_str(&format!("[discretization]\nscheme = \"bds2\"\nsteps = {steps}\npairing = \"same\"\n"));
    out
}

#[test]
fn reduced_eigenfrequencies_converge_to_the_full_ones_through_the_scene() {
    let full_scene = build(&blade_scene(None, "rayleigh = [0.0, 0.0]", 64, 2300.0));
    let s = &full_scene.full;
    let (periodic_contact::model::Matrix::Sparse(k), periodic_contact::model::Matrix::Sparse(m)) = (&s.stiffness, &s.mass) else {
        panic!("the generator gives sparse matrices")
    };
    let full = sparse_modes(k, m, 5).unwrap().omega;
    let mut previous = f64::INFINITY;
    for eta in [2, 4, 6, 10, 15] {
        let b = build(&blade_scene(Some(&format!("modes = {eta}")), "modal_ratios = [0.005]", 64, 2300.0));
        let red = b.reduction.as_ref().unwrap();
        assert_eq!((red.n_boundary(), red.n_modes()), (3, eta));
        let w = red.modes(5).unwrap().omega;
        let worst = w.iter().zip(&full).map(|(r, f)| (r - f) / f).fold(0.0f64, f64::max);
        eprintln!("η = {eta:>2}: worst relative difference of the first five eigenfrequencies {worst:.3e}");
        assert!(worst >= -1e-9 && worst <= previous * (1.0 + 1e-9), "η = {eta}: {worst:e} after {previous:e}");
        previous = worst;
    }
    // The default η (no `modes` key).
    let b = build(&blade_scene(Some(""), "modal_ratios = [0.005]", 64, 2300.0));
    let red = b.reduction.as_ref().unwrap();
    assert_eq!(red.n_modes(), periodic_contact::reduction::DEFAULT_MODES);
    let w = red.modes(5).unwrap().omega;
    let worst = w.iter().zip(&full).map(|(r, f)| ((r - f) / f).abs()).fold(0.0f64, f64::max);
    eprintln!("default η = {}: worst {worst:.3e}", red.n_modes());
    assert!(worst < 1e-3, "{worst:e}");
    assert!(worst <= previous);
}

/// max_j |a_j − b_j| / amplitude(b), per output key of b.
fn rel_diff(a: &Response, b: &Response) -> Vec<(String, f64)> {
    b.displacement
        .iter()
        .map(|(key, xb)| {
            let xa = &a.displacement[key];
            let amp = Response::peak_to_peak(xb) / 2.0;
            (key.clone(), xa.iter().zip(xb).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max) / amp)
        })
        .collect()
}

#[test]
fn reduced_periodic_response_converges_to_the_full_sparse_one() {
    // Rayleigh damping is defined on the full model and projected exactly, so that both models
    // are the same structure; ζ ≈ 0.5 % at the first mode. ω = 2260 rad/s: in contact.
    let damping = "rayleigh = [11.3, 2.2e-6]";
    let (k, omega) = (128, 2260.0);
    let t = std::time::Instant::now();
    let full = build(&blade_scene(None, damping, k, omega));
    assert!(full.problem.model().structure.mass.is_sparse(), "the full model goes through the sparse path");
    let rf = full.problem.solve().unwrap();
    eprintln!("full coarse blade ({} DOFs, k = {k}): {:.2} s, LCP size {}", full.full.n(), t.elapsed().as_secs_f64(), rf.lcp.size);
    assert!(rf.contacts[0].force.iter().any(|&f| f > 0.0), "the point is in contact");
    let mut previous = f64::INFINITY;
    let mut last = f64::NAN;
    for eta in [1, 2, 5, 10, 20] {
        let red = build(&blade_scene(Some(&format!("modes = {eta}")), damping, k, omega));
        let rr = red.problem.solve().unwrap();
        assert_eq!(rr.displacement.keys().collect::<Vec<_>>(), rf.displacement.keys().collect::<Vec<_>>(), "same output keys (full numbering)");
        let d = rel_diff(&rr, &rf);
        let worst = d.iter().map(|x| x.1).fold(0.0, f64::max);
        let fmax = |r: &Response| r.contacts[0].force.iter().copied().fold(0.0, f64::max);
        let txt: Vec<String> = d.iter().map(|(k, e)| format!("DOF {k}: {e:.2e}")).collect();
        eprintln!("η = {eta:>2}: max |x_red − x_full| / amplitude {}; max force LE {:.4} (full {:.4})", txt.join(", "), fmax(&rr), fmax(&rf));
        assert!(worst < previous * 1.02, "η = {eta}: {worst:e} did not decrease from {previous:e}");
        previous = worst;
        last = worst;
    }
    assert!(last < 1e-3, "default η: {last:e}");
}

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pc-blade-scene-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn sparse(rows: &[Vec<f64>]) -> faer::sparse::SparseColMat<usize, f64> {
    let mut t = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        for (j, &v) in r.iter().enumerate() {
            if v != 0.0 {
                t.push(faer::sparse::Triplet::new(i, j, v));
            }
        }
    }
    faer::sparse::SparseColMat::try_new_from_triplets(rows.len(), rows.len(), &t).unwrap()
}

/// A chain of 6 masses with springs between neighbours and to the ground at DOF 0.
fn chain() -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let n = 6;
    let mut k = vec![vec![0.0; n]; n];
    let mut m = vec![vec![0.0; n]; n];
    for i in 0..n {
        m[i][i] = 1.0 + 0.1 * i as f64;
        k[i][i] += if i == 0 { 2.0 } else { 1.0 };
        if i + 1 < n {
            k[i][i] += 1.0;
            k[i][i + 1] = -1.0;
            k[i + 1][i] = -1.0;
        }
    }
    (m, k)
}

fn rows_toml(a: &[Vec<f64>]) -> String {
    let r: Vec<String> = a.iter().map(|r| format!("[{}]", r.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(", "))).collect();
    format!("[{}]", r.join(", "))
}

#[test]
fn matrix_market_scene_with_fixed_dofs_matches_the_inline_clamped_model() {
    let dir = tmpdir("mtx");
    let (m, k) = chain();
    let c: Vec<Vec<f64>> = k.iter().map(|r| r.iter().map(|v| 0.02 * v).collect()).collect();
    write_matrix_market(&dir.join("M.mtx"), &sparse(&m), true).unwrap();
    write_matrix_market(&dir.join("K.mtx"), &sparse(&k), true).unwrap();
    write_matrix_market(&dir.join("C.mtx"), &sparse(&c), true).unwrap();
    let tail = |shift: usize| {
        format!(
            "[excitation]\nfrequency = 0.7\n[[force]]\ndof = {}\namplitude = 0.4\n[[contact]]\ndof = {}\ngap = 0.3\n[discretization]\nsteps = 128\n[output]\ndisplacement = [{}, {}]\nvelocity = [{}]\n",
            3 - shift,
            5 - shift,
            5 - shift,
            3 - shift,
            5 - shift
        )
    };
    // The file scene clamps DOF 0; everything keeps the file's numbering.
    let file_scene = format!(
        "[structure]\nmass = {{ matrix_market = \"M.mtx\" }}\nstiffness = {{ matrix_market = \"K.mtx\" }}\nfixed = [0]\n[damping]\nmatrix = {{ matrix_market = \"C.mtx\" }}\n{}",
        tail(0)
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, &file_scene).unwrap();
    let (scene, d) = Scene::load(&path).unwrap();
    let built = scene.build_in(&path.display().to_string(), &d).unwrap();
    assert!(built.problem.model().structure.mass.is_sparse());
    let r = built.problem.solve().unwrap();
    // The inline model of DOFs 1..5 (DOF 0 removed), numbered from 0.
    let keep = |a: &Vec<Vec<f64>>| -> Vec<Vec<f64>> { a[1..].iter().map(|r| r[1..].to_vec()).collect() };
    let inline = format!(
        "[structure]\nmass = {}\nstiffness = {}\n[damping]\nmatrix = {}\n{}",
        rows_toml(&keep(&m)),
        rows_toml(&keep(&k)),
        rows_toml(&keep(&c)),
        tail(1)
    );
    let ri = build(&inline).problem.solve().unwrap();
    assert!(ri.contacts[0].force.iter().any(|&f| f > 0.0), "the contact closes");
    for (file_key, inline_key) in [("5", "4"), ("3", "2")] {
        let (a, b) = (&r.displacement[file_key], &ri.displacement[inline_key]);
        let e = a.iter().zip(b).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        assert!(e < 1e-12, "DOF {file_key}: {e:e}");
    }
    assert!(r.velocity.contains_key("5"));
    assert_eq!(r.contacts[0].dof, 5, "the contact reports the file's DOF");
    assert_eq!(ri.contacts[0].dof, 4);

    // The same file model reduced with every internal mode kept is the full model.
    let reduced = file_scene.replace("[excitation]", "[reduction]\nmethod = \"craig-bampton\"\nmodes = 3\nextra_boundary = [3]\n[excitation]");
    std::fs::write(&path, &reduced).unwrap();
    let (scene, d) = Scene::load(&path).unwrap();
    let rr = scene.build_in(&path.display().to_string(), &d).unwrap().problem.solve().unwrap();
    assert!(rr.effects.contains(&"reduction".to_string()));
    for key in ["5", "3"] {
        let e = rr.displacement[key].iter().zip(&r.displacement[key]).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        assert!(e < 1e-9, "DOF {key}: {e:e}");
    }

    // Naming a fixed DOF is refused, naming the field.
    std::fs::write(&path, file_scene.replace("dof = 5\ngap", "dof = 0\ngap")).unwrap();
    let (scene, d) = Scene::load(&path).unwrap();
    let e = scene.build_in(&path.display().to_string(), &d).unwrap_err().to_string();
    assert!(e.contains("scene.toml") && e.contains("contact[0].dof") && e.contains("fixed"), "{e}");
    std::fs::write(&path, file_scene.replace("displacement = [5, 3]", "displacement = [5, 0]")).unwrap();
    let (scene, d) = Scene::load(&path).unwrap();
    let e = scene.build_in(&path.display().to_string(), &d).unwrap_err().to_string();
    assert!(e.contains("output.displacement[1]") && e.contains("fixed"), "{e}");
    // A missing file names the field and the file.
    std::fs::write(&path, file_scene.replace("K.mtx", "missing.mtx")).unwrap();
    let (scene, d) = Scene::load(&path).unwrap();
    let e = scene.build_in(&path.display().to_string(), &d).unwrap_err().to_string();
    assert!(e.contains("structure.stiffness.matrix_market") && e.contains("missing.mtx"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn blade_scene_outputs_keep_the_full_numbering_and_the_casing_follows_its_formula() {
    let b = build(&coarse_scene());
    let blade = Blade::generate(&BladeParams::coarse()).unwrap();
    let (le, mc, te) = (blade.node_dof("LE").unwrap(), blade.node_dof("MC").unwrap(), blade.node_dof("TE").unwrap());
    let mcy = blade.dof(blade.named_node("MC").unwrap(), 1).unwrap();
    assert_eq!(b.contact_dofs, vec![le, mc, te]);
    assert_eq!(b.problem.outputs().displacement, vec![mcy, le, te]);
    let r = b.problem.solve().unwrap();
    let keys: Vec<String> = [mcy, le, te].iter().map(|d| d.to_string()).collect();
    assert!(keys.iter().all(|k| r.displacement.contains_key(k)), "{:?}", r.displacement.keys());
    assert_eq!(r.contacts.iter().map(|c| c.dof).collect::<Vec<_>>(), vec![le, mc, te]);
    assert!(r.effects.contains(&"reduction".to_string()) && r.effects.contains(&"moving_obstacle".to_string()));
    // A boundary DOF is recovered exactly: the LE output is the reduced coordinate.
    let red = b.reduction.as_ref().unwrap();
    assert_eq!(red.boundary, vec![le, mc, te]);

    // gap_i(t) = g0 − δ cos(ω t + EO·s_i/R), s_LE = +(c_tip/2) sin γ (the leading edge leads),
    // s_MC = 0, s_TE = −(c_tip/2) sin γ; c_tip = chord·taper.
    let (lobes, depth, radius, stagger) = (3.0, 1e-5, 0.25, 40f64.to_radians());
    let c_tip = 0.05 * 0.8;
    let s = [0.5 * c_tip * stagger.sin(), 0.0, -0.5 * c_tip * stagger.sin()];
    for (i, c) in b.problem.model().contacts.iter().enumerate() {
        assert_eq!(c.motion.len(), 1);
        let h: &Harmonic = &c.motion[0];
        assert_eq!((h.amplitude, h.harmonic), (-depth, 1));
        let phase = lobes * s[i] / radius;
        assert!((h.phase - phase).abs() < 1e-12, "contact {i}: phase {} expected {phase}", h.phase);
        let w = b.problem.model().frequency;
        for t in [0.0, 1e-4, 7e-4] {
            let expected = 3e-5 - depth * (w * t + phase).cos();
            assert!((c.gap_at(w, t) - expected).abs() < 1e-18);
        }
    }
    // The leading edge meets each lobe crest first: its phase leads the trailing edge's.
    assert!(b.problem.model().contacts[0].motion[0].phase > b.problem.model().contacts[2].motion[0].phase);
}

#[test]
fn bad_scenes_name_the_file_the_field_and_the_value() {
    let blade = coarse_scene();
    let cases: Vec<(String, Vec<&str>)> = vec![
        (blade.replace("kind = \"blade\"", "kind = \"disk\""), vec!["structure.generator.kind", "disk"]),
        (blade.replace("preset = \"coarse\"", "preset = \"coarse\", lenght = 0.1"), vec!["structure.generator", "lenght", "length"]),
        (blade.replace("preset = \"coarse\"", "preset = \"coarse\", taper = -1.0"), vec!["structure.generator", "taper", "-1"]),
        (blade.replace("node = \"TE\"", "node = \"XX\""), vec!["contact[2].node", "XX", "LE, MC, TE"]),
        (blade.replace("axis = \"y\"", "axis = \"w\""), vec!["force[0].node", "\"w\""]),
        (blade.replace("method = \"craig-bampton\"", "method = \"guyan\""), vec!["reduction.method", "guyan"]),
        (blade.replace("modes = 20", "modes = 5000"), vec!["reduction.modes", "5000"]),
        (blade.replace("modal_ratios = [0.005]", "modal_ratios = [-0.1]"), vec!["damping.modal_ratios[0]", "-0.1"]),
        (blade.replace("lobes = 3", "lobes = 0"), vec!["casing.lobes", "0"]),
        (blade.replace("depth = 1e-5", "depth = -1e-5"), vec!["casing.depth", "-0.00001"]),
        (blade.replace("radius = 0.25", "radius = 0.25\nspeed = 100.0"), vec!["casing.speed", "100", "excitation.frequency"]),
        (blade.replace("[\"MC:y\", \"LE\", \"TE\"]", "[\"MC:q\"]"), vec!["output.displacement[0]", "\"q\""]),
        (blade.replace("[\"MC:y\", \"LE\", \"TE\"]", "[99999]"), vec!["output.displacement[0]", "99999"]),
        (blade.replace("node = \"LE\"", "node = \"LE\"\ndof = 3"), vec!["contact[0]", "either dof or node"]),
        (blade.replace("generator = {", "mass = [[1.0]]\ngenerator = {"), vec!["structure", "not several"]),
    ];
    for (text, needles) in cases {
        let e = build_err(&text);
        assert!(e.starts_with("bad.toml: "), "names the file: {e}");
        for n in needles {
            assert!(e.contains(n), "`{n}` missing from: {e}");
        }
    }
    let inline = "[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n[excitation]\nfrequency = 1.0\n";
    let cases: Vec<(String, Vec<&str>)> = vec![
        (format!("{inline}[[contact]]\nnode = \"LE\"\ngap = 0.1\n"), vec!["contact[0].node", "structure.generator"]),
        (format!("{inline}[damping]\nmodal_ratios = [0.01]\n"), vec!["damping.modal_ratios", "[reduction]"]),
        (format!("{inline}[[contact]]\ndof = 0\ngap = 0.1\n[casing]\nlobes = 2\ndepth = 0.01\nradius = 1.0\n"), vec!["casing.arc"]),
        (inline.replace("mass = [[1.0]]", "mass = { matrix_market = 3 }"), vec!["structure.mass", "matrix_market"]),
        (inline.replace("[structure]\n", "[structure]\nfixed = [4]\n"), vec!["structure.fixed", "4"]),
    ];
    for (text, needles) in cases {
        let e = build_err(&text);
        assert!(e.starts_with("bad.toml: "), "names the file: {e}");
        for n in needles {
            assert!(e.contains(n), "`{n}` missing from: {e}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Contacts along radial normals and casings of any shape (issue 23 items 2 and 3).

/// A scratch folder for a scene and its casing profile.
fn casing_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pc-casing-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The coarse blade (twist 30°) with 16 chord elements, `nodes = "tip"` (17 radial contacts),
/// stagger 40°, and `casing` as the [casing] body; no reduction (the gaps need none).
fn tip_scene(casing: &str) -> String {
    format!(
        "[structure]\ngenerator = {{ kind = \"blade\", preset = \"coarse\", chord_elements = 16 }}\n[excitation]\nfrequency = 2300.0\n\
         [casing]\nradius = 0.25\nstagger = 40.0\n{casing}\n[[force]]\nnode = \"MC\"\naxis = \"y\"\namplitude = 1.0\n\
         [[contact]]\nnodes = \"tip\"\ngap = 3e-5\nstiffness = 1e7\n[discretization]\nscheme = \"bds2\"\nsteps = 1024\n"
    )
}

fn write_scene(dir: &Path, text: &str, csv: Option<(&str, String)>) -> SceneModel {
    if let Some((name, body)) = csv {
        std::fs::write(dir.join(name), body).unwrap();
    }
    let file = dir.join("scene.toml");
    std::fs::write(&file, text).unwrap();
    let f = file.to_str().unwrap();
    Scene::parse(text, f).unwrap().build(f).unwrap()
}

/// Each tip node's radial normal and angle θ_i, computed here from the blade's geometry: tip node
/// at chord fraction f has p = x0·u (z = L), x0 = (f − ½)·c_tip, u = (cos τ, sin τ, 0); the axis
/// runs along e_a = cos γ·u + sin γ·n through (0, 0, L − R); e_θ = −sin γ·u + cos γ·n.
fn tip_geometry(count: usize) -> Vec<([f64; 3], f64)> {
    let (tau, gamma, radius, c_tip) = (30f64.to_radians(), 40f64.to_radians(), 0.25, 0.05 * 0.8);
    let u = [tau.cos(), tau.sin(), 0.0];
    let nv = [-tau.sin(), tau.cos(), 0.0];
    let e_a: Vec<f64> = (0..3).map(|i| gamma.cos() * u[i] + gamma.sin() * nv[i]).collect();
    let e_t: Vec<f64> = (0..3).map(|i| -gamma.sin() * u[i] + gamma.cos() * nv[i]).collect();
    (0..count)
        .map(|i| {
            let x0 = (i as f64 / (count - 1) as f64 - 0.5) * c_tip;
            let r = [x0 * u[0], x0 * u[1], radius];
            let along: f64 = (0..3).map(|a| r[a] * e_a[a]).sum();
            let rp: Vec<f64> = (0..3).map(|a| r[a] - along * e_a[a]).collect();
            let len = rp.iter().map(|v| v * v).sum::<f64>().sqrt();
            let theta = (0..3).map(|a| rp[a] * e_t[a]).sum::<f64>().atan2(rp[2]);
            ([rp[0] / len, rp[1] / len, rp[2] / len], theta)
        })
        .collect()
}

/// Two Gaussian lobes: Δg(θ) = −d·Σ_{c ∈ {0, π}} exp(−wrap(θ − c)²/(2w²)).
fn two_lobes(theta: f64, depth: f64, width: f64) -> f64 {
    let wrap = |a: f64| (a + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI;
    -depth * [0.0, std::f64::consts::PI].iter().map(|c| (-wrap(theta - c).powi(2) / (2.0 * width * width)).exp()).sum::<f64>()
}

/// `nodes = "tip"` makes one contact per mid-thickness tip node along its radial normal, which
/// twist and stagger turn off every axis; a sampled two-lobe Gaussian casing gives each contact
/// gap_i(t) = g0 + Δg(Ω t + θ_i), Δg the Gaussian formula, to round-off: the profile's N = 360
/// samples resolve the lobes (w = 0.25 rad: the aliasing bound 2Σ_{|k|≥180}|ĝ_k| ~ d·e^{−(180w)²/2}
/// is far below round-off), and the orders dropped are below 1e-13 of the largest.
#[test]
fn tip_contacts_along_radial_normals_rub_two_gaussian_lobes() {
    let dir = casing_dir("gauss");
    let (depth, width) = (2e-5, 0.25);
    let mut csv = String::from("angle_deg,clearance\n");
    for j in 0..360 {
        csv.push_str(&format!("{j},{:e}\n", two_lobes((j as f64).to_radians(), depth, width)));
    }
    let b = write_scene(&dir, &tip_scene("lobes = 2\nprofile = \"lobes.csv\""), Some(("lobes.csv", csv)));
    let model = b.problem.model();
    let geometry = tip_geometry(17);
    assert_eq!(model.contacts.len(), 17, "every tip node LE..TE");
    let omega = model.frequency;
    let speed = omega / 2.0;
    let mut worst = (0.0f64, 0.0f64);
    for (i, (c, (normal, theta))) in model.contacts.iter().zip(&geometry).enumerate() {
        // The generator's DOF of axis a of a node is 3·node + a less the clamped root's 3·count.
        let row = &b.contact_rows[i];
        let mut n = [0.0; 3];
        row.iter().for_each(|&(d, v)| n[d % 3] = v);
        for a in 0..3 {
            worst.0 = worst.0.max((n[a] - normal[a]).abs());
        }
        if i != 8 {
            assert_eq!(row.len(), 3, "contact {i} mixes x, y and z: {row:?}");
            assert!(n[0].abs() > 1e-3 && n[1].abs() > 1e-3, "off-centre normals are off the axes: {row:?}");
        } else {
            assert_eq!(row.len(), 1, "MC, on the stacking line, is radial along z: {row:?}");
        }
        for j in 0..200 {
            let t = j as f64 * 2.0 * std::f64::consts::PI / omega / 200.0 * 1.37;
            let expected = 3e-5 + two_lobes(speed * t + theta, depth, width);
            worst.1 = worst.1.max((c.gap_at(omega, t) - expected).abs() / depth);
        }
    }
    let terms = c_terms(&b);
    eprintln!("17 radial tip contacts: |normal − geometry| ≤ {:.1e}, |gap_at − Gaussian| ≤ {:.1e} of the depth, {terms} casing terms", worst.0, worst.1);
    assert!(worst.0 < 1e-12, "normals: {:.1e}", worst.0);
    assert!(worst.1 < 1e-10, "gaps: {:.1e}", worst.1);
    // The referenced files: the profile, for packaging.
    let scene = Scene::parse(&std::fs::read_to_string(dir.join("scene.toml")).unwrap(), "s").unwrap();
    assert_eq!(scene.casing_files(&dir), vec![dir.join("lobes.csv")]);
    let _ = std::fs::remove_dir_all(&dir);
}

fn c_terms(b: &SceneModel) -> usize {
    match &b.casing.as_ref().unwrap().shape {
        periodic_contact::scene::casing::Shape::Series(t) => t.len(),
        other => panic!("{other:?}"),
    }
}

/// A profile sampled (in radians, closing at 2π) from a known Fourier series reproduces its orders,
/// amplitudes and phases, and equals the same series given as `harmonics`.
#[test]
fn a_sampled_profile_reproduces_its_harmonics() {
    use periodic_contact::scene::casing::Shape;
    let dir = casing_dir("series");
    let known = [(0u32, 1e-6, 0.0), (2, 4e-6, 0.3), (4, -1.5e-6, 1.2), (10, 7e-7, -2.0)];
    let g = |th: f64| known.iter().map(|&(k, a, p)| a * (k as f64 * th + p).cos()).sum::<f64>();
    for n in [32usize, 64, 256] {
        let mut csv = String::from("# a known series\nangle_rad,clearance\n");
        for j in 0..=n {
            let th = j as f64 * 2.0 * std::f64::consts::PI / n as f64;
            csv.push_str(&format!("{th:.17e},{:.17e}\n", g(if j == n { 0.0 } else { th })));
        }
        let b = write_scene(&dir, &tip_scene("lobes = 2\nprofile = \"p.csv\""), Some(("p.csv", csv)));
        let Shape::Series(terms) = &b.casing.as_ref().unwrap().shape else { panic!() };
        assert_eq!(terms.iter().map(|t| t.order).collect::<Vec<_>>(), vec![0, 2, 4, 10], "N = {n}: {terms:?}");
        for (t, &(_, a, p)) in terms.iter().zip(&known) {
            // a·cos(kθ + p) = |a|·cos(kθ + p + π) for a < 0.
            let (ea, ep) = if a < 0.0 { (-a, p + std::f64::consts::PI) } else { (a, p) };
            let dp = (t.phase - ep + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI;
            assert!((t.amplitude - ea).abs() < 1e-12 * 4e-6 * n as f64 && (t.order == 0 || dp.abs() < 1e-9), "N = {n}: {t:?} vs {a}, {p}");
        }
        // The same series as harmonics gives the same obstacle motion.
        let h = "lobes = 2\nharmonics = [{ order = 0, amplitude = 1e-6 }, { order = 2, amplitude = 4e-6, phase = 0.3 }, { order = 4, amplitude = -1.5e-6, phase = 1.2 }, { order = 10, amplitude = 7e-7, phase = -2.0 }]";
        let b2 = build(&tip_scene(h));
        let omega = b.problem.model().frequency;
        for (c, c2) in b.problem.model().contacts.iter().zip(&b2.problem.model().contacts) {
            for j in 0..50 {
                let t = j as f64 * 1e-4;
                assert!((c.gap_at(omega, t) - c2.gap_at(omega, t)).abs() < 1e-16, "profile and harmonics agree");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A radially rubbing blade solves: the 17 radial contacts with the Gaussian casing under
/// Craig–Bampton, every contact's reported normal displacement is B_i x of its scene row.
#[test]
fn radial_tip_contacts_solve_through_the_reduction() {
    let dir = casing_dir("solve");
    let mut csv = String::from("angle_deg,clearance\n");
    for j in 0..=180 {
        let deg = 2.0 * j as f64;
        csv.push_str(&format!("{deg},{:e}\n", two_lobes(deg.to_radians(), 4e-5, 0.25)));
    }
    let text = tip_scene("lobes = 2\nprofile = \"lobes.csv\"")
        .replace("[excitation]", "[reduction]\nmethod = \"craig-bampton\"\nmodes = 6\n[damping]\nmodal_ratios = [0.005]\n[excitation]")
        + "[output]\ndisplacement = [\"LE:x\", \"LE:y\", \"LE:z\", \"MC\"]\n";
    let text = text.replace("steps = 1024", "steps = 256");
    let b = write_scene(&dir, &text, Some(("lobes.csv", csv)));
    let r = b.problem.solve().unwrap();
    assert!(r.contacts.iter().any(|c| c.force.iter().any(|&f| f > 0.0)), "the lobes touch the tip");
    let le = &r.contacts[0];
    let keys: Vec<String> = le.normal.iter().map(|(d, _)| d.to_string()).collect();
    let e = (0..r.steps)
        .map(|j| (le.normal_displacement[j] - le.normal.iter().zip(&keys).map(|((_, v), k)| v * r.displacement[k][j]).sum::<f64>()).abs())
        .fold(0.0, f64::max);
    let scale = le.normal_displacement.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(e < 1e-9 * scale, "normal displacement {e:e} vs {scale:e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Matrix Market-style contacts by DOF index: `dofs` + `position` + `normal = "radial"` about
/// `casing.axis` through `casing.center`, and `dofs` + a given normal (normalised); θ = 0 at the
/// first positioned contact, growing by the right-hand rule about the axis.
#[test]
fn contacts_by_dofs_take_radial_and_given_normals() {
    let eye: Vec<String> = (0..6).map(|i| format!("[{}]", (0..6).map(|j| if i == j { "1.0" } else { "0.0" }).collect::<Vec<_>>().join(", "))).collect();
    let text = format!(
        "[structure]\nmass = [{m}]\nstiffness = [{m}]\n[excitation]\nfrequency = 3.0\n\
         [casing]\naxis = [0.0, 0.0, 2.0]\ncenter = [1.0, 1.0, 7.0]\nradius = 1.0\nharmonics = [{{ order = 1, amplitude = 0.1, phase = 0.2 }}]\n\
         [[contact]]\ndofs = [0, 1, 2]\nnormal = \"radial\"\nposition = [3.0, 1.0, 0.0]\ngap = 0.5\n\
         [[contact]]\ndofs = [3, 4, 5]\nnormal = \"radial\"\nposition = [1.0, 4.0, -2.0]\ngap = 0.5\n\
         [[contact]]\ndofs = [3, 4, 5]\nnormal = [3.0, 0.0, -4.0]\nposition = [-1.0, 1.0, 0.0]\ngap = 0.5\n",
        m = eye.join(", ")
    );
    let b = build(&text);
    assert_eq!(b.contact_rows, vec![vec![(0, 1.0)], vec![(4, 1.0)], vec![(3, 0.6), (5, -0.8)]]);
    // θ = 0, π/2 and π: gap_i(t) = 0.5 + 0.1·cos(Ω t + θ_i + 0.2), Ω = ω (lobes = 1).
    let model = b.problem.model();
    for (c, theta) in model.contacts.iter().zip([0.0, std::f64::consts::FRAC_PI_2, std::f64::consts::PI]) {
        for t in [0.0, 0.3, 1.7] {
            let expected = 0.5 + 0.1 * (3.0 * t + theta + 0.2).cos();
            assert!((c.gap_at(3.0, t) - expected).abs() < 1e-14, "θ = {theta}: {} vs {expected}", c.gap_at(3.0, t));
        }
    }
    // The cosine lobes at the same angles: −δ·cos(ω t + L·θ_i), ω = L·Ω.
    let lobes = text.replace("harmonics = [{ order = 1, amplitude = 0.1, phase = 0.2 }]", "lobes = 3\ndepth = 0.1");
    let b = build(&lobes);
    for (c, theta) in b.problem.model().contacts.iter().zip([0.0, std::f64::consts::FRAC_PI_2, std::f64::consts::PI]) {
        let expected = 0.5 - 0.1 * (3.0 * 0.3 + 3.0 * theta).cos();
        assert!((c.gap_at(3.0, 0.3) - expected).abs() < 1e-14, "lobes at θ = {theta}: {} vs {expected}", c.gap_at(3.0, 0.3));
    }
}

/// The shipped rigid blade scene (coarse, 3 rigid tip contacts) with `method`, `scheme` and
/// `steps`, the pairing left to its default.
fn rigid_blade(method: &str, scheme: &str, steps: usize) -> String {
    let base = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-rigid.toml")).unwrap();
    base.lines()
        .filter(|l| !l.starts_with("pairing ="))
        .map(|l| match l {
            l if l.starts_with("method =") => format!("method = \"{method}\""),
            l if l.starts_with("scheme =") => format!("scheme = \"{scheme}\""),
            l if l.starts_with("steps =") => format!("steps = {steps}"),
            l => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn massless_boundary_blade_has_the_kept_modes_limit_and_second_order_at_modest_k() {
    let cb = build(&rigid_blade("craig-bampton", "cds", 1024));
    let mb = build(&rigid_blade("massless-boundary", "cds", 512));
    // ω_max: Craig–Bampton's constraint modes against the massless model's highest kept mode,
    // which is the full model's 20th eigenfrequency (free-interface modes; rigid contacts open).
    let s = &cb.full;
    let (periodic_contact::model::Matrix::Sparse(k), periodic_contact::model::Matrix::Sparse(m)) = (&s.stiffness, &s.mass) else { panic!("sparse") };
    let w20 = sparse_modes(k, m, 20).unwrap().omega[19];
    let (w_cb, w_mb) = (cb.problem.omega_max(), mb.problem.omega_max());
    eprintln!("ω_max: Craig–Bampton {w_cb:.4e} rad/s, massless boundary {w_mb:.4e} rad/s (full model's ω_20 = {w20:.4e})");
    assert!(((w_mb - w20) / w20).abs() < 1e-6, "massless ω_max {w_mb} vs ω_20 {w20}");
    assert!(w_cb > 3.0 * w_mb);
    // cds at k = 256 breaks the massless model's limit (ω_max·h ≥ 2), 512 does not; Craig–Bampton needs 1024.
    let refused =
        Scene::parse(&rigid_blade("massless-boundary", "cds", 256), "t.toml").unwrap().build("t.toml").err().map(|e| e.to_string()).unwrap_or_default();
    assert!(refused.contains("stable only"), "{refused}");
    // Second order on the massless model: cds at k = 512, 1024 against k = 4096 (galerkin, measured
    // in the README, stalled between 512 and 1024 on this case).
    let reference = build(&rigid_blade("massless-boundary", "cds", 4096)).problem.solve().unwrap();
    {
        let scheme = "cds";
        let e: Vec<f64> = [512usize, 1024]
            .iter()
            .map(|&k| {
                let r = build(&rigid_blade("massless-boundary", scheme, k)).problem.solve().unwrap();
                assert!(r.warnings.iter().all(|w| !w.contains("converge")), "{scheme}: {:?}", r.warnings);
                let step = 4096 / k;
                r.displacement
                    .iter()
                    .map(|(key, x)| {
                        let xr: Vec<f64> = reference.displacement[key].iter().step_by(step).copied().collect();
                        x.iter().zip(&xr).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / Response::peak_to_peak(&reference.displacement[key])
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        let order = (e[0] / e[1]).log2();
        eprintln!("massless blade, {scheme}: errors {e:?} at k = 512, 1024 against cds k = 4096; observed order {order:.2}");
        assert!(order > 1.6, "{scheme}: order {order}");
        assert!(e[1] < 1e-2, "{scheme}: {e:?}");
    }
}
