//! Craig–Bampton reduction of the coarse blade, against the full model.
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use periodic_contact::fe::*;
use periodic_contact::model::Matrix;
use periodic_contact::reduction::*;
use std::sync::OnceLock;

struct Fixture {
    blade: Blade,
    /// First 5 eigenfrequencies of the full coarse blade [rad/s].
    full: Vec<f64>,
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let blade = Blade::generate(&BladeParams::coarse()).unwrap();
        let full = sparse_modes(&blade.stiffness, &blade.mass, 5).unwrap().omega;
        Fixture { blade, full }
    })
}

fn reduce(b: &Blade, boundary: &[usize], eta: usize) -> ReducedModel {
    craig_bampton(&b.stiffness, &b.mass, boundary, &CraigBamptonOptions { modes: eta, ..Default::default() }).unwrap()
}

#[test]
fn eigenfrequencies_converge_from_above_and_within_0_1_percent_at_the_default() {
    let f = fixture();
    let b = &f.blade;
    let bnd = b.contact_dofs();
    let mut previous: Option<Vec<f64>> = None;
    for eta in [2, 4, 6, 8, 10, 15, DEFAULT_MODES, 30] {
        let r = reduce(b, &bnd, eta);
        let w = r.modes(5).unwrap().omega;
        let rel: Vec<f64> = w.iter().zip(&f.full).map(|(a, b)| (a - b) / b).collect();
        let txt: Vec<String> = rel.iter().map(|e| format!("{e:+.2e}")).collect();
        eprintln!("η = {eta:>2}: relative differences {}", txt.join(" "));
        for (i, &e) in rel.iter().enumerate() {
            // An upper bound (Rayleigh–Ritz), to round-off.
            assert!(e > -1e-9, "η = {eta}, mode {}: below the full model by {e:e}", i + 1);
        }
        if let Some(p) = &previous {
            for i in 0..5 {
                assert!(w[i] <= p[i] * (1.0 + 1e-9), "η = {eta}, mode {}: {} rose from {}", i + 1, w[i], p[i]);
            }
        }
        if eta == DEFAULT_MODES {
            let worst = rel.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(worst < 1e-3, "default η = {eta}: worst {worst:e}");
        }
        previous = Some(w);
    }
}

#[test]
fn all_dofs_as_boundary_is_exact() {
    let mut p = BladeParams::coarse();
    p.mesh = MeshDensity { span: 6, chord: 2, thickness: 2 };
    let b = Blade::generate(&p).unwrap();
    let n = b.n_dof();
    // Every DOF, in reverse order.
    let bnd: Vec<usize> = (0..n).rev().collect();
    let r = reduce(&b, &bnd, 0);
    assert_eq!(r.n(), n);
    let k = Matrix::Sparse(b.stiffness.clone()).to_dense();
    let m = Matrix::Sparse(b.mass.clone()).to_dense();
    for i in 0..n {
        for j in 0..n {
            assert_eq!(r.stiffness[(i, j)], k[(n - 1 - i, n - 1 - j)]);
            assert_eq!(r.mass[(i, j)], m[(n - 1 - i, n - 1 - j)]);
        }
    }
    let full = dense_modes(k.as_ref(), m.as_ref(), 6).unwrap().omega;
    let red = r.modes(6).unwrap().omega;
    for i in 0..6 {
        // Same matrices up to the ordering: equal up to the dense eigensolver's round-off.
        assert!((full[i] - red[i]).abs() <= 1e-9 * full[i], "mode {i}: {} vs {}", full[i], red[i]);
    }
    // Asking for modes with nothing internal is refused.
    let e = craig_bampton(&b.stiffness, &b.mass, &bnd, &CraigBamptonOptions { modes: 1, ..Default::default() }).unwrap_err();
    assert!(matches!(e, ReductionError::TooManyModes { requested: 1, internal: 0 }), "{e}");
}

#[test]
fn static_boundary_load_gives_the_full_static_answer() {
    let f = fixture();
    let b = &f.blade;
    let n = b.n_dof();
    // Boundary: the three contact DOFs plus an extra one (the chordwise DOF of the mid-chord tip node).
    let mut bnd = b.contact_dofs();
    let extra = b.dof(b.named_node("MC").unwrap(), 1).unwrap();
    bnd.push(extra);
    let r = reduce(b, &bnd, DEFAULT_MODES);
    // Loads on boundary DOFs only: radial at LE and TE, flapwise (y) at MC [N].
    let mut fvec = vec![0.0; n];
    fvec[bnd[0]] = 120.0;
    fvec[bnd[2]] = -80.0;
    fvec[extra] = 5.0;
    // Full static solution by sparse Cholesky.
    let llt = b.stiffness.sp_cholesky(Side::Lower).unwrap();
    let mut x = Mat::from_fn(n, 1, |i, _| fvec[i]);
    llt.solve_in_place(x.as_mut());
    // Reduced: K_r q = Φᵀ f, x ≈ Φ q.
    let fr = r.project_vector(&fvec);
    let fr_m = Mat::from_fn(r.n(), 1, |i, _| fr[i]);
    let q = r.stiffness.llt(Side::Lower).unwrap().solve(&fr_m);
    let q: Vec<f64> = (0..r.n()).map(|i| q[(i, 0)]).collect();
    let xr = r.recover(&q);
    let scale = (0..n).map(|i| x[(i, 0)].abs()).fold(0.0, f64::max);
    let err = (0..n).map(|i| (xr[i] - x[(i, 0)]).abs()).fold(0.0, f64::max);
    eprintln!("static boundary load: max |x_red − x_full| / max |x_full| = {:e}", err / scale);
    assert!(err <= 1e-9 * scale, "relative error {:e}", err / scale);
    // The modal coordinates stay at zero (K_r is block-diagonal, Φ_ηᵀ f = 0).
    let q_modal = q[bnd.len()..].iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let q_bnd = q[..bnd.len()].iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(q_modal <= 1e-9 * q_bnd, "modal coordinates {q_modal:e}");
    // Selected DOFs through the basis rows.
    let sel = [bnd[1], 0, n - 1];
    let rec = r.recover_dofs(&q, &sel);
    for (k, &d) in sel.iter().enumerate() {
        assert!((rec[k] - xr[d]).abs() <= 1e-15 * scale.max(xr[d].abs()));
    }
}

#[test]
fn basis_structure_and_fixed_interface_modes() {
    let f = fixture();
    let b = &f.blade;
    let bnd = b.contact_dofs();
    let eta = DEFAULT_MODES;
    let r = reduce(b, &bnd, eta);
    let nb = bnd.len();
    assert_eq!((r.n_boundary(), r.n_modes(), r.n()), (nb, eta, nb + eta));
    assert_eq!(r.basis_bytes(), 8 * b.n_dof() * (nb + eta));
    // Boundary rows of Φ are unit rows; reduced_dof inverts boundary.
    for (i, &d) in bnd.iter().enumerate() {
        let row = r.basis_row(d);
        for (k, v) in row.iter().enumerate() {
            assert_eq!(*v, if k == i { 1.0 } else { 0.0 });
        }
        assert_eq!(r.reduced_dof(d), Some(i));
    }
    assert_eq!(r.reduced_dof(0), None);
    // Fixed-interface modes: ascending, mass-normalised (M_r's modal block ≈ I), K_r's modal block
    // ≈ diag(ω²) and decoupled from the boundary block.
    for j in 1..eta {
        assert!(r.interface_omega[j] >= r.interface_omega[j - 1]);
    }
    assert!(r.interface_residual.iter().all(|&x| x < 1e-6), "{:?}", r.interface_residual);
    let kbb = (0..nb).map(|i| r.stiffness[(i, i)].abs()).fold(0.0, f64::max);
    for i in 0..eta {
        for j in 0..eta {
            let m = r.mass[(nb + i, nb + j)];
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((m - want).abs() < 1e-10, "M_r modal block ({i}, {j}) = {m}");
            let k = r.stiffness[(nb + i, nb + j)];
            let w2 = r.interface_omega[i].powi(2);
            let want = if i == j { w2 } else { 0.0 };
            assert!((k - want).abs() < 1e-9 * r.interface_omega[eta - 1].powi(2), "K_r modal block ({i}, {j}) = {k}");
        }
        for j in 0..nb {
            assert!(r.stiffness[(nb + i, j)].abs() < 1e-9 * kbb.max(r.interface_omega[i].powi(2)));
        }
    }
}

#[test]
fn damping_options() {
    let f = fixture();
    let b = &f.blade;
    let mut r = reduce(b, &b.contact_dofs(), 8);
    let n = r.n();
    // Rayleigh.
    r.set_damping(&Damping::Rayleigh { alpha: 3.0, beta: 2e-6 }).unwrap();
    let c = r.damping.clone().unwrap();
    for i in 0..n {
        for j in 0..n {
            assert_eq!(c[(i, j)], 3.0 * r.mass[(i, j)] + 2e-6 * r.stiffness[(i, j)]);
        }
    }
    // Projecting the full Rayleigh matrix gives the same (to round-off).
    let full_c = Matrix::Sparse(b.mass.clone()).lincomb(3.0, &Matrix::Sparse(b.stiffness.clone()), 2e-6);
    let Matrix::Sparse(full_c) = full_c else { unreachable!() };
    r.set_damping(&Damping::Matrix(full_c)).unwrap();
    let cp = r.damping.clone().unwrap();
    let cmax = (0..n).map(|i| c[(i, i)].abs()).fold(0.0, f64::max);
    for i in 0..n {
        for j in 0..n {
            assert!((cp[(i, j)] - c[(i, j)]).abs() < 1e-9 * cmax, "({i}, {j}): {} vs {}", cp[(i, j)], c[(i, j)]);
        }
    }
    // Modal ratios: the reduced modes see 2ζω on the diagonal and nothing off it.
    let zeta = vec![0.01, 0.02];
    r.set_damping(&Damping::ModalRatios(zeta.clone())).unwrap();
    let modes = r.modes(n).unwrap();
    let c = r.damping.clone().unwrap();
    let pcp = modes.shapes.transpose() * &c * &modes.shapes;
    for i in 0..n {
        for j in 0..n {
            let want = if i == j { 2.0 * zeta[i.min(1)] * modes.omega[i] } else { 0.0 };
            assert!((pcp[(i, j)] - want).abs() < 1e-6 * (2.0 * 0.02 * modes.omega[n - 1]), "({i}, {j}): {} vs {want}", pcp[(i, j)]);
        }
    }
    assert!(r.set_damping(&Damping::ModalRatios(vec![-0.1])).is_err());
    // The engine structure carries the damping.
    assert!(r.structure().damping.is_some());
}

#[test]
fn mode_table_compares_full_and_reduced() {
    let f = fixture();
    let b = &f.blade;
    let r = reduce(b, &b.contact_dofs(), DEFAULT_MODES);
    let t = ModeTable::compare(&Matrix::Sparse(b.stiffness.clone()), &Matrix::Sparse(b.mass.clone()), &r, 5).unwrap();
    assert_eq!(t.rows.len(), 5);
    assert_eq!((t.n_full, t.n_reduced), (b.n_dof(), r.n()));
    for (row, &w) in t.rows.iter().zip(&f.full) {
        assert!((row.full_rad_s - w).abs() < 1e-9 * w);
        assert!((row.full_hz * 2.0 * std::f64::consts::PI - row.full_rad_s).abs() < 1e-9 * w);
        assert!(row.rel_diff >= -1e-9 && row.rel_diff < 1e-3);
    }
    let text = t.to_string();
    eprintln!("{text}");
    assert_eq!(text.lines().count(), 6);
    // Dense input goes through the dense solver and agrees.
    let m = modes(&Matrix::Dense(r.stiffness.clone()), &Matrix::Dense(r.mass.clone()), 3).unwrap();
    let m2 = r.modes(3).unwrap();
    assert_eq!(m.omega, m2.omega);
}

#[test]
fn bad_boundaries_are_refused() {
    let f = fixture();
    let b = &f.blade;
    let n = b.n_dof();
    let e = craig_bampton(&b.stiffness, &b.mass, &[n], &CraigBamptonOptions::default()).unwrap_err();
    assert_eq!(e, ReductionError::BoundaryOutOfRange { dof: n, n });
    let e = craig_bampton(&b.stiffness, &b.mass, &[3, 5, 3], &CraigBamptonOptions::default()).unwrap_err();
    assert_eq!(e, ReductionError::BoundaryRepeated { dof: 3 });
    // An unclamped structure: K_ii is singular.
    let free = Blade::generate_free(&BladeParams { mesh: MeshDensity { span: 3, chord: 2, thickness: 2 }, ..BladeParams::coarse() }).unwrap();
    for eta in [0, 5] {
        let e = craig_bampton(&free.stiffness, &free.mass, &[0], &CraigBamptonOptions { modes: eta, ..Default::default() }).unwrap_err();
        assert!(matches!(e, ReductionError::InternalStiffness(_)), "{e}");
        assert!(e.to_string().contains("singular"), "{e}");
    }
    // The full modes of a free structure are refused too.
    let e = sparse_modes(&free.stiffness, &free.mass, 3).unwrap_err();
    assert!(matches!(e, EigenError::Singular { .. } | EigenError::StiffnessNotDefinite(_)), "{e}");
}

#[test]
fn reduce_structure_projects_the_structure_damping() {
    let f = fixture();
    let b = &f.blade;
    let mut s = b.structure();
    s.damping = Some(Matrix::Sparse(b.stiffness.clone()).lincomb(1e-6, &Matrix::Sparse(b.mass.clone()), 0.0));
    let r = reduce_structure(&s, Method::CraigBampton, &b.contact_dofs(), &CraigBamptonOptions { modes: 5, ..Default::default() }, None).unwrap();
    let c = r.damping.as_ref().unwrap();
    let cmax = (0..r.n()).map(|i| c[(i, i)].abs()).fold(0.0, f64::max);
    for i in 0..r.n() {
        for j in 0..r.n() {
            assert!((c[(i, j)] - 1e-6 * r.stiffness[(i, j)]).abs() < 1e-9 * cmax);
        }
    }
    // A force on an internal DOF projects through its basis row.
    let d = 10;
    let mut fv = vec![0.0; b.n_dof()];
    fv[d] = 1.0;
    assert_eq!(r.project_vector(&fv), r.basis_row(d));
}

/// Timings of the reduction on both presets (run with
/// `cargo test --release --test suite reduction::timings -- --ignored --nocapture`).
#[test]
#[ignore]
fn timings() {
    for (name, p) in [("coarse", BladeParams::coarse()), ("fine", BladeParams::fine())] {
        let t = std::time::Instant::now();
        let b = Blade::generate(&p).unwrap();
        let t_gen = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let full = sparse_modes(&b.stiffness, &b.mass, 5).unwrap();
        let t_full = t.elapsed().as_secs_f64();
        let r = reduce(&b, &b.contact_dofs(), DEFAULT_MODES);
        let red = r.modes(5).unwrap();
        let worst = full.omega.iter().zip(&red.omega).map(|(a, b)| ((b - a) / a).abs()).fold(0.0, f64::max);
        let tm = r.timings;
        eprintln!(
            "{name}: {} DOFs, mesh {:.3} s; full model 5 modes (factor + Lanczos) {:.3} s; Craig–Bampton η = {}: \
             total {:.3} s = K_ii factor {:.3} + static modes {:.3} + eigen {:.3} + projection {:.3}; \
             basis {:.1} MB; worst of first 5 frequencies {:.2e}",
            b.n_dof(),
            t_gen,
            t_full,
            DEFAULT_MODES,
            tm.total,
            tm.factor,
            tm.static_modes,
            tm.eigen,
            tm.projection,
            r.basis_bytes() as f64 / 1e6,
            worst
        );
    }
}

fn massless(b: &Blade, boundary: &[usize], eta: usize) -> ReducedModel {
    massless_boundary(&b.stiffness, &b.mass, boundary, &CraigBamptonOptions { modes: eta, ..Default::default() }).unwrap()
}

/// The boundary block of the receptance (K − ω²M)⁻¹ of the full model (sparse LU).
fn full_receptance(b: &Blade, boundary: &[usize], omega: f64) -> Mat<f64> {
    let Matrix::Sparse(a) = Matrix::Sparse(b.stiffness.clone()).lincomb(1.0, &Matrix::Sparse(b.mass.clone()), -omega * omega) else { unreachable!() };
    let lu = a.sp_lu().unwrap();
    let n = b.n_dof();
    let mut x = Mat::from_fn(n, boundary.len(), |i, j| if i == boundary[j] { 1.0 } else { 0.0 });
    lu.solve_in_place(x.as_mut());
    Mat::from_fn(boundary.len(), boundary.len(), |i, j| x[(boundary[i], j)])
}

/// The boundary block of (K_r − ω²M_r)⁻¹ (the boundary coordinates come first in both methods).
fn reduced_receptance(r: &ReducedModel, omega: f64) -> Mat<f64> {
    let nb = r.n_boundary();
    let a = Mat::from_fn(r.n(), r.n(), |i, j| r.stiffness[(i, j)] - omega * omega * r.mass[(i, j)]);
    let x = a.partial_piv_lu().solve(Mat::<f64>::from_fn(r.n(), nb, |i, j| if i == j { 1.0 } else { 0.0 }));
    Mat::from_fn(nb, nb, |i, j| x[(i, j)])
}

fn relative_difference(a: &Mat<f64>, reference: &Mat<f64>) -> f64 {
    let scale = (0..a.nrows()).flat_map(|i| (0..a.ncols()).map(move |j| (i, j))).map(|(i, j)| reference[(i, j)].abs()).fold(0.0, f64::max);
    (0..a.nrows()).flat_map(|i| (0..a.ncols()).map(move |j| (i, j))).map(|(i, j)| (a[(i, j)] - reference[(i, j)]).abs()).fold(0.0, f64::max) / scale
}

#[test]
fn massless_boundary_against_the_full_blade() {
    let f = fixture();
    let b = &f.blade;
    let bnd = b.contact_dofs();
    let nb = bnd.len();
    for eta in [2, 5, 10] {
        let r = massless(b, &bnd, eta);
        assert_eq!(r.method, Method::MasslessBoundary);
        // M_r = diag(0, I): the boundary carries no mass.
        for i in 0..r.n() {
            for j in 0..r.n() {
                assert_eq!(r.mass[(i, j)], if i == j && i >= nb { 1.0 } else { 0.0 });
            }
        }
        // K_r is the exact projection Tᵀ K T of the full stiffness on the basis.
        let proj = r.project_matrix(&b.stiffness);
        let kmax = (0..r.n()).map(|i| r.stiffness[(i, i)].abs()).fold(0.0, f64::max);
        let dk = (0..r.n()).flat_map(|i| (0..r.n()).map(move |j| (i, j))).map(|(i, j)| (proj[(i, j)] - r.stiffness[(i, j)]).abs()).fold(0.0, f64::max);
        assert!(dk < 1e-8 * kmax, "η = {eta}: ‖TᵀKT − K_r‖ = {dk:e} against {kmax:e}");
        // Static: the receptance at ω = 0 is the full flexibility at the boundary, exactly.
        let e0 = relative_difference(&reduced_receptance(&r, 0.0), &full_receptance(b, &bnd, 0.0));
        eprintln!("η = {eta}: static boundary flexibility, relative difference {e0:.2e}");
        assert!(e0 < 1e-9, "η = {eta}: static flexibility off by {e0:e}");
        // The finite eigenfrequencies are the full model's lowest η (free-interface modes).
        let w = r.modes(eta.min(5)).unwrap().omega;
        for (i, (a, e)) in w.iter().zip(&f.full).enumerate() {
            assert!(((a - e) / e).abs() < 1e-8, "η = {eta}, mode {}: {a} vs full {e}", i + 1);
        }
        assert!(r.modes(eta + 1).is_err(), "the boundary coordinates have no finite frequency");
    }
    // Receptance at the boundary below, between and above the first resonances, against the full
    // model; Craig–Bampton with as many modes beside it. Measured: the massless boundary converges
    // (its error is the neglected residual mass, O(ω²)), but Craig–Bampton, which keeps the static
    // modes' mass, is 10–300× closer with as many modes.
    let w1 = f.full[0];
    let mut previous = [f64::INFINITY; 3];
    for eta in [2, 5, 10] {
        let (mb, cb) = (massless(b, &bnd, eta), reduce(b, &bnd, eta));
        for (i, frac) in [0.3, 0.7, 1.4].into_iter().enumerate() {
            let omega = frac * w1;
            let full = full_receptance(b, &bnd, omega);
            let (e_mb, e_cb) = (relative_difference(&reduced_receptance(&mb, omega), &full), relative_difference(&reduced_receptance(&cb, omega), &full));
            eprintln!("η = {eta:>2}, ω = {frac}·ω1: receptance error massless {e_mb:.2e}, Craig–Bampton {e_cb:.2e}");
            assert!(e_mb < 0.5 * previous[i], "η = {eta}, ω = {frac}·ω1: {e_mb:e} does not converge (was {:e})", previous[i]);
            assert!(e_mb < 3e-3 * frac * frac, "η = {eta}, ω = {frac}·ω1: {e_mb:e}");
            previous[i] = e_mb;
        }
    }
}
