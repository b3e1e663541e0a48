//! Linear periodic response (no contact): every scheme reproduces its exact discrete response
//! x_j = Re[w (σ2 M + σ1 C + w K)⁻¹ F e^{iωt_j}] (src/formulation.md §6.1) and fourier the continuous one.
//! The symbols are written out here again, independently of `time::Scheme::symbols`.
use num_complex::Complex64 as C;
use periodic_contact::scene::Scene;
use std::f64::consts::PI;

const M: [[f64; 2]; 2] = [[2.0, 0.3], [0.3, 1.0]];
const K: [[f64; 2]; 2] = [[5.0, -2.0], [-2.0, 3.0]];
const CD: [[f64; 2]; 2] = [[0.1, -0.02], [-0.02, 0.05]];
const OMEGA: f64 = 1.7;

fn scene(scheme: &str, k: usize, harmonic: u32) -> String {
    format!(
        r#"
[structure]
mass = [[2.0, 0.3], [0.3, 1.0]]
stiffness = [[5.0, -2.0], [-2.0, 3.0]]
[damping]
matrix = [[0.1, -0.02], [-0.02, 0.05]]
[excitation]
frequency = {OMEGA}
[[force]]
dof = 1
amplitude = 0.8
harmonic = {harmonic}
phase = 0.4
[discretization]
scheme = "{scheme}"
steps = {k}
[output]
displacement = [0, 1]
velocity = [0]
"#
    )
}

/// (σ1, σ2, w) for a harmonic of angle θ = 2π·harmonic/k.
fn symbol(scheme: &str, theta: f64, h: f64, wave: f64) -> (C, C, f64) {
    let z = C::from_polar(1.0, -theta);
    match scheme {
        "bds1" => ((1.0 - z) / h, ((1.0 - z) / h).powi(2), 1.0),
        "bds2" => ((3.0 - 4.0 * z + z * z) / (2.0 * h), (2.0 - 5.0 * z + 4.0 * z * z - z * z * z) / (h * h), 1.0),
        "cds" => (C::new(0.0, theta.sin() / h), C::from(2.0 * (theta.cos() - 1.0) / (h * h)), 1.0),
        "galerkin" => (C::new(0.0, theta.sin() / h), C::from(2.0 * (theta.cos() - 1.0) / (h * h)), (2.0 + theta.cos()) / 3.0),
        "fourier" => (C::new(0.0, wave), C::from(-wave * wave), 1.0),
        _ => unreachable!(),
    }
}

/// Solves the 2×2 complex system (σ2 M + σ1 C + w K) X = w F by Cramer's rule.
fn discrete_amplitude(s1: C, s2: C, w: f64, f: [C; 2]) -> [C; 2] {
    let z = |i: usize, j: usize| s2 * M[i][j] + s1 * CD[i][j] + w * K[i][j];
    let det = z(0, 0) * z(1, 1) - z(0, 1) * z(1, 0);
    let (f0, f1) = (f[0] * w, f[1] * w);
    [(f0 * z(1, 1) - z(0, 1) * f1) / det, (z(0, 0) * f1 - z(1, 0) * f0) / det]
}

#[test]
fn every_scheme_reproduces_its_discrete_response() {
    for scheme in ["bds1", "bds2", "cds", "galerkin", "fourier"] {
        for (k, harmonic) in [(16usize, 1u32), (64, 3)] {
            let problem = Scene::parse(&scene(scheme, k, harmonic), "test").unwrap().to_problem("test").unwrap();
            let r = problem.solve().unwrap();
            assert_eq!(r.lcp.size, 0);
            assert_eq!(r.effects, vec!["damping", "forcing"]);
            let period = 2.0 * PI / OMEGA;
            let h = period / k as f64;
            let theta = 2.0 * PI * harmonic as f64 / k as f64;
            let (s1, s2, w) = symbol(scheme, theta, h, harmonic as f64 * OMEGA);
            let f = C::from_polar(0.8, 0.4);
            let x = discrete_amplitude(s1, s2, w, [C::ZERO, f]);
            let mut worst = 0.0f64;
            for j in 0..k {
                let e = C::from_polar(1.0, harmonic as f64 * OMEGA * j as f64 * h);
                for d in 0..2 {
                    worst = worst.max((r.displacement[&d.to_string()][j] - (x[d] * e).re).abs());
                }
                worst = worst.max((r.velocity["0"][j] - (s1 * x[0] * e).re).abs());
            }
            assert!(worst < 1e-10, "{scheme} k={k} harmonic={harmonic}: max error {worst:e}");
        }
    }
}

#[test]
fn fourier_reproduces_the_continuous_response() {
    let k = 32;
    let problem = Scene::parse(&scene("fourier", k, 2), "test").unwrap().to_problem("test").unwrap();
    let r = problem.solve().unwrap();
    // Continuous: (K − Ω²M + iΩC) X = F at Ω = 2ω.
    let w2 = 2.0 * OMEGA;
    let z = |i: usize, j: usize| C::new(K[i][j] - w2 * w2 * M[i][j], w2 * CD[i][j]);
    let f = C::from_polar(0.8, 0.4);
    let det = z(0, 0) * z(1, 1) - z(0, 1) * z(1, 0);
    let x = [-(z(0, 1) * f) / det, z(0, 0) * f / det];
    for (j, t) in r.time.iter().enumerate() {
        for d in 0..2 {
            let exact = (x[d] * C::from_polar(1.0, w2 * t)).re;
            assert!((r.displacement[&d.to_string()][j] - exact).abs() < 1e-10);
        }
        let v = (C::new(0.0, w2) * x[0] * C::from_polar(1.0, w2 * t)).re;
        assert!((r.velocity["0"][j] - v).abs() < 1e-10);
    }
}

#[test]
fn a_static_load_gives_the_static_solution() {
    // harmonic 0 = constant load: K x = f for every scheme.
    for scheme in ["bds1", "cds", "fourier"] {
        let text = scene(scheme, 8, 0).replace("phase = 0.4", "phase = 0.0");
        let r = Scene::parse(&text, "t").unwrap().to_problem("t").unwrap().solve().unwrap();
        let det = K[0][0] * K[1][1] - K[0][1] * K[1][0];
        let x1 = K[0][0] * 0.8 / det;
        assert!(r.displacement["1"].iter().all(|v| (v - x1).abs() < 1e-12), "{scheme}");
    }
}

#[test]
fn the_sparse_path_equals_the_dense_path() {
    use periodic_contact::model::Matrix;
    let dense = Scene::parse(&scene("cds", 32, 1), "t").unwrap().to_problem("t").unwrap();
    let to_sparse = |m: &Matrix| {
        let mut t = Vec::new();
        m.for_each(|i, j, v| t.push(faer::sparse::Triplet::new(i, j, v)));
        Matrix::Sparse(faer::sparse::SparseColMat::try_new_from_triplets(2, 2, &t).unwrap())
    };
    let mut model = dense.model().clone();
    let s = &mut model.structure;
    s.mass = to_sparse(&s.mass);
    s.stiffness = to_sparse(&s.stiffness);
    s.damping = s.damping.as_ref().map(to_sparse);
    let sparse = dense.with_model(model, dense.discretization()).unwrap();
    let (a, b) = (dense.solve().unwrap(), sparse.solve().unwrap());
    for d in ["0", "1"] {
        for (x, y) in a.displacement[d].iter().zip(&b.displacement[d]) {
            assert!((x - y).abs() < 1e-13);
        }
    }
}
