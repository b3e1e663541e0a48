//! Rubbing in gross slip (src/formulation.md §9): `[[friction]] contact = i, sliding_velocity = V`
//! adds μ·λ_n along the counter-face's motion to contact i's force. Reference: the closed form of
//! a 2-DOF structure held in permanent contact with a compliant stop, where the contact force is
//! k_c·x₀ and the system is linear: (K + k_c (e₀ − μ·sign(V)·e₁) e₀ᵀ − ω²M + iωC) X = F per
//! harmonic, a non-symmetric 2×2 solve independent of the LCP.
use num_complex::Complex64 as C;
use periodic_contact::scene::Scene;

const SCENE: &str = r#"[structure]
mass = [[1.0, 0.0], [0.0, 1.0]]
stiffness = [[2.0, -0.5], [-0.5, 1.5]]

[damping]
rayleigh = [0.02, 0.01]

[excitation]
frequency = 1.3

[[force]]
dof = 0
amplitude = 2.0
harmonic = 0

[[force]]
dof = 0
amplitude = 0.5

[[contact]]
dof = 0
gap = 0.0
stiffness = 10.0

[[friction]]
contact = 0
dof = 1
coefficient = 0.3
sliding_velocity = 5.0

[discretization]
scheme = "fourier"
steps = 64
"#;

/// x(t_j) of the closed form at `k` instants, DOF by DOF.
fn closed_form(mu_sign_v: f64, k: usize) -> [Vec<f64>; 2] {
    let (kc, omega) = (10.0, 1.3);
    let kk = [[2.0 + kc, -0.5], [-0.5 - mu_sign_v * kc, 1.5]];
    let m = [[1.0, 0.0], [0.0, 1.0]];
    let cc = |i: usize, j: usize| 0.02 * m[i][j] + 0.01 * [[2.0, -0.5], [-0.5, 1.5]][i][j];
    let solve = |w: f64, f: f64| {
        let a = |i: usize, j: usize| C::new(kk[i][j] - w * w * m[i][j], w * cc(i, j));
        let det = a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0);
        [a(1, 1) * f / det, -a(1, 0) * f / det]
    };
    let (xs, xh) = (solve(0.0, 2.0), solve(omega, 0.5));
    let t = |j: usize| j as f64 * 2.0 * std::f64::consts::PI / omega / k as f64;
    [0, 1].map(|d| (0..k).map(|j| xs[d].re + (xh[d] * C::from_polar(1.0, omega * t(j))).re).collect())
}

fn worst_error(text: &str, mu_sign_v: f64) -> f64 {
    let r = Scene::parse(text, "r.toml").unwrap().to_problem("r.toml").unwrap().solve().unwrap();
    let k = r.displacement["0"].len();
    let exact = closed_form(mu_sign_v, k);
    let scale = exact[1].iter().fold(0.0_f64, |v, x| v.max(x.abs()));
    (0..2).flat_map(|d| r.displacement[&d.to_string()].iter().zip(&exact[d]).map(|(a, b)| (a - b).abs() / scale).collect::<Vec<_>>()).fold(0.0, f64::max)
}

#[test]
fn rubbing_in_gross_slip_matches_the_closed_form_of_permanent_contact() {
    // Measured: spectral (fourier) to round-off; cds converges at order 2.
    let e = worst_error(SCENE, 0.3);
    println!("rubbing, fourier k = 64: worst error {e:.3e}");
    assert!(e < 1e-8, "{e}");
    // The friction's direction follows the counter-face: V < 0 flips it (and the mean tangential offset).
    let e = worst_error(&SCENE.replacen("sliding_velocity = 5.0", "sliding_velocity = -5.0", 1), -0.3);
    assert!(e < 1e-8, "{e}");
    let cds = |k: usize| worst_error(&SCENE.replacen("\"fourier\"", "\"cds\"", 1).replacen("steps = 64", &format!("steps = {k}"), 1), 0.3);
    let (coarse, fine) = (cds(128), cds(256));
    println!("rubbing, cds: worst error {coarse:.3e} at k = 128, {fine:.3e} at k = 256");
    assert!(fine < 1e-3 && coarse / fine > 3.5 && coarse / fine < 4.5, "{coarse} {fine}");
}

#[test]
fn rubbing_slower_than_the_structure_is_a_typed_outcome() {
    // The tangential DOF moves at up to ≈ 0.2: a counter-face at 0.01 cannot keep gross slip.
    let text = SCENE.replacen("sliding_velocity = 5.0", "sliding_velocity = 0.01", 1);
    let e = Scene::parse(&text, "r.toml").unwrap().to_problem("r.toml").unwrap().solve().unwrap_err();
    assert_eq!(e.kind(), periodic_contact::ErrorKind::Input, "{e}");
    let e = e.to_string();
    assert!(e.contains("friction[0].sliding_velocity") && e.contains("gross slip"), "{e}");
    // A contact index past the contacts is named.
    let text = SCENE.replacen("contact = 0", "contact = 3", 1);
    let e = Scene::parse(&text, "r.toml").unwrap().to_problem("r.toml").unwrap_err().to_string();
    assert!(e.contains("friction[0].contact") && e.contains('3'), "{e}");
}

#[test]
fn export_refuses_a_rubbing_scene_and_writes_nothing() {
    // B alone would misstate a rubbing contact's force row (n − μ·sign(V)·t), so export refuses.
    let dir = std::env::temp_dir().join(format!("pc-rubbing-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("rub.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = dir.join("model");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_periodic-contact")).arg("export").arg(&scene).arg("-o").arg(&out).output().unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && e.contains("rubbing") && e.contains("rub.toml"), "{e}");
    assert!(!out.join("B.mtx").exists() && !out.join("M.mtx").exists(), "export wrote files for a scene it refused");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The displacements of `text` solved by `method`, with the solver's account.
fn solved_by(text: &str, method: &str) -> (Vec<Vec<f64>>, String) {
    let text = format!("{text}\n[solver]\nmethod = \"{method}\"\ntolerance = 1e-12\n");
    let r = Scene::parse(&text, "r.toml").unwrap().to_problem("r.toml").unwrap().solve().unwrap();
    let mut dofs: Vec<_> = r.displacement.iter().collect();
    dofs.sort_by(|a, b| a.0.cmp(b.0));
    (dofs.into_iter().map(|(_, x)| x.clone()).collect(), r.lcp.path.clone())
}

/// Worst difference between shooting on the step map and dense Lemke, relative to the largest displacement.
fn shooting_against_dense(text: &str) -> f64 {
    let (dense, how) = solved_by(text, "lemke");
    assert!(!how.contains("shooting"), "{how}");
    let (shot, how) = solved_by(text, "shooting");
    assert!(how.contains("shooting"), "{how}");
    let scale = dense.iter().flatten().fold(0.0_f64, |v, x| v.max(x.abs()));
    dense.iter().flatten().zip(shot.iter().flatten()).fold(0.0_f64, |v, (a, b)| v.max((a - b).abs() / scale))
}

#[test]
fn shooting_on_the_step_map_equals_the_dense_lcp_with_rubbing() {
    // The closed-form case (permanent contact) under bds1. Measured: shooting does not converge on
    // this permanently pressed case under cds or bds2, with or without rubbing (μ = 0 and no
    // [[friction]] alike): its offset homotopy starts from the contact-free orbit.
    let bds1 = SCENE.replacen("\"fourier\"", "\"bds1\"", 1).replacen("steps = 64", "steps = 128\npairing = \"same\"", 1);
    let e = shooting_against_dense(&bds1);
    println!("rubbing, bds1 k = 128: shooting vs dense Lemke {e:.3e}");
    assert!(e < 1e-10, "{e}");
    // A 4-DOF chain, two compliant stops that open and close, each rubbed along its neighbour
    // DOF in opposite directions: S is non-symmetric and couples the two contacts.
    let e = shooting_against_dense(CHAIN);
    println!("rubbing chain, cds k = 256: shooting vs dense Lemke {e:.3e}");
    assert!(e < 1e-10, "{e}");
    let e = shooting_against_dense(&CHAIN.replacen("\"cds\"", "\"bds2\"", 1));
    println!("rubbing chain, bds2 k = 256: shooting vs dense Lemke {e:.3e}");
    assert!(e < 1e-10, "{e}");
    // DOF 3 massless (condensed out of the step map): contact 1's sliding row acts on it, so the
    // force rows E differ from B on a massless DOF (D = B_b K_bb⁻¹ E_bᵀ).
    let massless = CHAIN.replacen("[0, 0, 0, 1.0]]", "[0, 0, 0, 0.0]]", 1).replacen("[0.03, 0.01]", "[0.05, 0.0]", 1).replacen("gap = 0.3", "gap = 0.1", 1);
    let e = shooting_against_dense(&massless);
    println!("rubbing chain, sliding on a massless DOF, cds k = 256: shooting vs dense Lemke {e:.3e}");
    assert!(e < 1e-10, "{e}");
}

const CHAIN: &str = r#"[structure]
mass = [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]
stiffness = [[2.0, -1.0, 0, 0], [-1.0, 2.0, -1.0, 0], [0, -1.0, 2.0, -1.0], [0, 0, -1.0, 1.5]]

[damping]
rayleigh = [0.03, 0.01]

[excitation]
frequency = 0.9

[[force]]
dof = 3
amplitude = 1.0

[[contact]]
dof = 0
gap = 0.5
stiffness = 20.0

[[contact]]
dof = 2
gap = 0.3
stiffness = 20.0

[[friction]]
contact = 0
dof = 1
coefficient = 0.15
sliding_velocity = 50.0

[[friction]]
contact = 1
dof = 3
coefficient = 0.15
sliding_velocity = -50.0

[discretization]
scheme = "cds"
steps = 256
pairing = "same"
"#;

#[test]
fn rubbing_at_zero_friction_is_the_plain_contact_scene() {
    // μ = 0 folds zero times the tangential columns into the contacts': the same LCP, the same answer.
    let plain = CHAIN[..CHAIN.find("[[friction]]").unwrap()].to_string() + &CHAIN[CHAIN.find("[discretization]").unwrap()..];
    let zero = CHAIN.replace("coefficient = 0.15", "coefficient = 0.0");
    for method in ["lemke", "shooting"] {
        let (a, _) = solved_by(&plain, method);
        let (b, _) = solved_by(&zero, method);
        assert_eq!(a, b, "{method}: μ = 0 differs from the plain contact scene");
    }
}

/// The coarse blade (fmu/scenes/blade-casing-coarse.toml) with each tip contact rubbed along the
/// direction of rotation at μ, bds2 (A-stable: the full model has ω_max ≈ 1.1e7 rad/s), k = 128,
/// ω = 2260 rad/s (in contact), Rayleigh damping on the full model (projected exactly).
fn rubbing_blade(mu: f64, reduction: bool) -> String {
    let base = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-coarse.toml")).unwrap();
    let mut out = String::new();
    let mut skip = false;
    for line in base.lines() {
        if line.starts_with('[') {
            skip = ["[reduction]", "[damping]", "[excitation]", "[discretization]"].contains(&line);
        }
        if !skip {
            out += line;
            out.push('\n');
        }
    }
    if reduction {
        out += "[reduction]\nmethod = \"craig-bampton\"\nmodes = 20\n";
    }
    out += "[damping]\nrayleigh = [11.3, 2.2e-6]\n[excitation]\nfrequency = 2260.0\n";
    out += "[discretization]\nscheme = \"bds2\"\nsteps = 128\npairing = \"same\"\nerror_estimate = \"none\"\n";
    for (i, node) in ["LE", "MC", "TE"].iter().enumerate() {
        out += &format!("[[friction]]\ncontact = {i}\nnode = \"{node}\"\ndirection = \"tangential\"\ncoefficient = {mu}\nsliding_velocity = -188.3\n");
    }
    out
}

#[test]
fn the_reduced_rubbing_blade_matches_the_full_model() {
    let solve = |mu: f64, reduction: bool| {
        let m = Scene::parse(&rubbing_blade(mu, reduction), "b.toml").unwrap().build("b.toml").unwrap();
        if reduction {
            // Each tip node's sliding DOFs joined the boundary (3 radial + the x, y, z that e_θ touches).
            assert!(m.reduction.as_ref().unwrap().n_boundary() > 3);
        }
        // e_θ = axis × e_r is a unit vector.
        let t: f64 = m.problem.model().rubbing.iter().map(|r| r.row.iter().map(|(_, v)| v * v).sum::<f64>()).sum();
        assert!((t - 3.0).abs() < 1e-12 || reduction, "{t}");
        m.problem.solve().unwrap()
    };
    let t = std::time::Instant::now();
    let full = solve(0.15, false);
    let reduced = solve(0.15, true);
    let frictionless = solve(0.0, true);
    let worst = |a: &periodic_contact::response::Response, b: &periodic_contact::response::Response| {
        b.displacement
            .iter()
            .map(|(key, xb)| {
                let amp = periodic_contact::response::Response::peak_to_peak(xb) / 2.0;
                a.displacement[key].iter().zip(xb).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max) / amp
            })
            .fold(0.0, f64::max)
    };
    let (e, shift) = (worst(&reduced, &full), worst(&frictionless, &reduced));
    println!("rubbing blade μ = 0.15, k = 128: reduced (CB η = 20) vs full {e:.2e}; μ = 0 vs μ = 0.15 {shift:.2e}; {:.1} s", t.elapsed().as_secs_f64());
    assert!(full.contacts.iter().any(|c| c.force.iter().any(|&f| f > 0.0)), "the point is in contact");
    assert!(e < 1e-3 && shift > 10.0 * e, "reduced vs full {e:e}, friction's effect {shift:e}");
}

#[test]
fn a_sliding_direction_without_its_node_or_axis_is_refused_by_name() {
    let refused = |from: &str, to: &str| Scene::parse(&SCENE.replacen(from, to, 1), "r.toml").unwrap().to_problem("r.toml").unwrap_err().to_string();
    // direction needs the node it applies at.
    let e = refused("dof = 1\ncoefficient", "direction = [0.0, 1.0]\ncoefficient");
    assert!(e.contains("friction[0]") && e.contains("node"), "{e}");
    // "tangential" needs the rotation axis (a [casing] or casing.axis).
    let e = refused("dof = 1\ncoefficient", "dofs = [0, 1]\ndirection = \"tangential\"\ncoefficient");
    assert!(e.contains("friction[0].direction") && e.contains("rotation axis"), "{e}");
    // dof and direction together: one sliding direction, not two.
    let e = refused("dof = 1\ncoefficient", "dof = 1\ndirection = [1.0]\ncoefficient");
    assert!(e.contains("friction[0]") && e.contains("not both"), "{e}");
    // A given direction over the node's DOFs is normalised: [0, 2] is dof = 1.
    let by_dofs = Scene::parse(&SCENE.replacen("dof = 1\ncoefficient", "dofs = [0, 1]\ndirection = [0.0, 2.0]\ncoefficient", 1), "r.toml").unwrap();
    let by_dof = Scene::parse(SCENE, "r.toml").unwrap();
    let (a, b) = (by_dofs.to_problem("r.toml").unwrap().solve().unwrap(), by_dof.to_problem("r.toml").unwrap().solve().unwrap());
    assert_eq!(a.displacement, b.displacement);
}

/// The real rubbing blade's LCP (N = 17 408) ran 20 min in the dense fallback: `auto` now refuses
/// it with the projected cost (N³ flops at 1e10/s: 17 408³/1e10 s = 8.8 min; 8·N² bytes =
/// 2.26 GiB, by hand), and still allows it on the fine blade's N = 6144 (2.3 s projected).
#[test]
fn the_dense_fallback_is_a_projected_cost_decision() {
    use periodic_contact::lcp::{DENSE_FALLBACK_MAX_S, dense_fallback_allowed, dense_lemke_seconds};
    assert!((dense_lemke_seconds(17_408) - 527.5).abs() < 0.1, "{}", dense_lemke_seconds(17_408));
    let refused = dense_fallback_allowed(17_408).expect_err("N = 17 408 must be refused");
    for part in ["N = 17408", "≈ 9 min", "≈ 2.3 GiB"] {
        assert!(refused.contains(part), "{part} missing from: {refused}");
    }
    assert!(dense_fallback_allowed(6144).is_ok());
    // The limit sits between them: N³ = 1e10 · DENSE_FALLBACK_MAX_S.
    let limit = (1e10 * DENSE_FALLBACK_MAX_S).cbrt() as usize;
    assert!(dense_fallback_allowed(limit - 1).is_ok() && dense_fallback_allowed(limit + 2).is_err());
}
