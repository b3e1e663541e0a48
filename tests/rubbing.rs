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
