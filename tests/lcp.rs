//! Tests of the LCP module: Lemke's method, the Siconos `.dat` reader/writer, brute-force
//! enumeration, the block-circulant matrix. Every expected number comes from an independent
//! reference (enumeration, a hand computation, or a direct check of the LCP conditions on the
//! parsed data), never from an earlier run of the solver.
//!
//! The ignored test `lemke_block_circulant_timing` prints solve times for n = 1024…4096:
//! `cargo test --release --test suite lcp:: -- --ignored --nocapture`.
//! The random tests scale with the environment variable `LCP_STRESS` (a multiplier, default 1):
//! `LCP_STRESS=100 cargo test --release --test suite lcp::` is the long stress run.
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::time::Instant;

use periodic_contact::lcp::{
    BlockCirculant, DatError, DenseMatrix, LcpMatrix, LcpOutcome, LcpSolution, Lemke, LemkeSettings, parse_dat, read_dat, solve_by_enumeration, write_dat,
};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// SplitMix64: a tiny deterministic PRNG.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// Multiplier of the random test counts (environment variable `LCP_STRESS`, default 1).
fn stress() -> usize {
    std::env::var("LCP_STRESS").ok().and_then(|v| v.parse().ok()).unwrap_or(1).max(1)
}

fn solve_with(a: &dyn LcpMatrix, q: &[f64], settings: LemkeSettings) -> LcpSolution {
    let s = Lemke::new(settings).solve(a, q);
    assert_eq!(s.z.len(), q.len());
    assert_eq!(s.w.len(), q.len());
    assert!(s.z.iter().chain(&s.w).all(|v| v.is_finite()), "non-finite z or w: {s:?}");
    assert!(!s.info.residual.is_nan() && !s.info.relative_error.is_nan(), "NaN residual: {s:?}");
    assert!(s.info.time_s.is_finite() && s.info.time_s >= 0.0);
    s
}

fn solve(a: &dyn LcpMatrix, q: &[f64]) -> LcpSolution {
    solve_with(a, q, LemkeSettings::default())
}

/// Independent check of the LCP conditions: w = A z + q recomputed here entry by entry,
/// z ≥ −tol, w ≥ −tol, |min(z_i, w_i)| ≤ tol, with tol = 1e-9 · max(1, ‖q‖∞).
fn assert_lcp_solution(a: &dyn LcpMatrix, q: &[f64], z: &[f64], what: &str) {
    let n = q.len();
    let tol = 1e-9 * q.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        let wi = q[i] + (0..n).map(|j| a.entry(i, j) * z[j]).sum::<f64>();
        assert!(z[i] >= -tol, "{what}: z[{i}] = {} < 0", z[i]);
        assert!(wi >= -tol, "{what}: w[{i}] = {wi} < 0");
        assert!(z[i].min(wi).abs() <= tol, "{what}: not complementary at {i}: z = {}, w = {wi}", z[i]);
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// z is one of the enumerated solutions (to `rel` relative).
fn is_among_tol(z: &[f64], sols: &[Vec<f64>], rel: f64) -> bool {
    let tol = rel * norm_inf(z).max(1.0);
    sols.iter().any(|s| max_diff(s, z) <= tol)
}

/// A solution is ill-conditioned when ‖A‖∞‖z‖∞ > 1e5 · max(1, ‖q‖∞): the round-off of w = A z + q
/// (≈ n·eps·‖A‖‖z‖) then approaches the certification threshold 1e-9 · max(1, ‖q‖∞), so an
/// honest solver may have to say `Inaccurate`, and two solvers agree only to ≈ eps·cond.
fn ill_conditioned(a: &dyn LcpMatrix, q: &[f64], z: &[f64]) -> bool {
    let n = q.len();
    let anorm = (0..n).map(|i| (0..n).map(|j| a.entry(i, j).abs()).sum::<f64>()).fold(0.0, f64::max);
    anorm * norm_inf(z) > 1e5 * norm_inf(q).max(1.0)
}

// ---------------------------------------------------------------------------------------------
// Random small LCPs against enumeration
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq)]
enum Class {
    /// Lᵀ L + 0.1 I: symmetric positive definite.
    Spd,
    /// Strictly row diagonally dominant with a positive diagonal, nonsymmetric.
    DiagDominant,
    /// Lᵀ L + 0.1 I + (B − Bᵀ): positive definite, nonsymmetric.
    PdNonsym,
    /// Lᵀ L (L has n/2 rows) + (B − Bᵀ)/2: positive semidefinite, singular in general.
    Psd,
    /// Lᵀ L (L has n/2 rows): symmetric positive semidefinite, singular (rank n/2).
    PsdSym,
    /// Uniform entries in [−1, 1]: indefinite, not P in general.
    Indefinite,
}

fn random_matrix(rng: &mut Rng, n: usize, class: Class) -> DenseMatrix {
    let u = |rng: &mut Rng, rows: usize| -> Vec<f64> { (0..rows * n).map(|_| rng.uniform(-1.0, 1.0)).collect() };
    let gram = |l: &[f64], rows: usize, i: usize, j: usize| -> f64 { (0..rows).map(|k| l[k * n + i] * l[k * n + j]).sum() };
    match class {
        Class::Spd => {
            let l = u(rng, n);
            DenseMatrix::from_fn(n, |i, j| gram(&l, n, i, j) + if i == j { 0.1 } else { 0.0 })
        }
        Class::DiagDominant => {
            let off = u(rng, n);
            let extra: Vec<f64> = (0..n).map(|_| rng.uniform(0.1, 1.0)).collect();
            DenseMatrix::from_fn(
                n,
                |i, j| {
                    if i == j { (0..n).filter(|&k| k != i).map(|k| off[i * n + k].abs()).sum::<f64>() + extra[i] } else { off[i * n + j] }
                },
            )
        }
        Class::PdNonsym => {
            let l = u(rng, n);
            let b = u(rng, n);
            DenseMatrix::from_fn(n, |i, j| gram(&l, n, i, j) + if i == j { 0.1 } else { 0.0 } + b[i * n + j] - b[j * n + i])
        }
        Class::Psd | Class::PsdSym => {
            let rows = (n / 2).max(1);
            let l = u(rng, rows);
            let skew = if class == Class::Psd { 0.5 } else { 0.0 };
            let b = u(rng, n);
            DenseMatrix::from_fn(n, |i, j| gram(&l, rows, i, j) + skew * (b[i * n + j] - b[j * n + i]))
        }
        Class::Indefinite => {
            let e = u(rng, n);
            DenseMatrix::from_fn(n, |i, j| e[i * n + j])
        }
    }
}

/// For P-matrices the LCP has exactly one solution for every q (Cottle, Pang & Stone 1992, §3.3):
/// enumeration must find exactly one, and Lemke must always solve and agree with it to 1e-9.
#[test]
fn random_p_matrices_unique_solution_matches_enumeration() {
    let mut rng = Rng(0x5EED_0001);
    let mut checked = 0;
    for class in [Class::Spd, Class::DiagDominant, Class::PdNonsym] {
        for n in 1..=8 {
            for _ in 0..25 * stress() {
                let a = random_matrix(&mut rng, n, class);
                let q: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
                let sols = solve_by_enumeration(&a, &q, 1e-10);
                assert_eq!(sols.len(), 1, "{class:?} n = {n}: P-matrix LCP with {} enumerated solutions", sols.len());
                let s = solve(&a, &q);
                assert_eq!(s.outcome, LcpOutcome::Solved, "{class:?} n = {n}: {s:?}");
                let tol = 1e-9 * norm_inf(&sols[0]).max(1.0);
                assert!(max_diff(&s.z, &sols[0]) <= tol, "{class:?} n = {n}: z = {:?}, enumeration {:?}", s.z, sols[0]);
                assert_lcp_solution(&a, &q, &s.z, "random P");
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 3 * 8 * 25 * stress());
}

/// PSD matrices are copositive-plus: lexicographic Lemke either solves or ends on a ray, and the
/// ray happens only if the LCP is infeasible (Cottle, Pang & Stone 1992, §4.4). So: solved ⇔
/// enumeration finds a solution (random data are nondegenerate, so enumeration is exhaustive).
#[test]
fn random_psd_solved_iff_solvable() {
    let mut rng = Rng(0x5EED_0002);
    let (mut solved, mut rays, mut inaccurate) = (0, 0, 0);
    for (n, class) in (1..=8).flat_map(|n| [(n, Class::Psd), (n, Class::PsdSym)]) {
        for _ in 0..40 * stress() {
            let a = random_matrix(&mut rng, n, class);
            let q: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
            let sols = solve_by_enumeration(&a, &q, 1e-10);
            let s = solve(&a, &q);
            let ill = sols.iter().any(|z| ill_conditioned(&a, &q, z));
            if sols.is_empty() {
                assert_eq!(s.outcome, LcpOutcome::RayTermination, "{class:?} n = {n}: no solution, but {s:?}");
                rays += 1;
            } else if s.outcome == LcpOutcome::Solved {
                let rel = if ill { 1e-5 } else { 1e-9 };
                assert!(is_among_tol(&s.z, &sols, rel), "{class:?} n = {n}: z = {:?} not among {sols:?}", s.z);
                solved += 1;
            } else {
                // Solvable, so Lemke reaches a complementary basis; only certification may fail,
                // and only for ill-conditioned solutions.
                assert_eq!(s.outcome, LcpOutcome::Inaccurate, "{class:?} n = {n}: {} solutions, but {s:?}", sols.len());
                assert!(sols.iter().all(|z| ill_conditioned(&a, &q, z)), "{class:?} n = {n}: {sols:?}, but {s:?}");
                inaccurate += 1;
            }
        }
    }
    // Both branches must really be exercised.
    println!("psd: solved {solved}, rays {rays}, inaccurate (ill-conditioned) {inaccurate}");
    assert!(solved > 50 && rays > 10, "solved {solved}, rays {rays}");
}

/// Indefinite matrices: no guarantee either way, but Lemke must never certify a wrong answer:
/// a solved z is one of the enumerated solutions, and with none Lemke does not say solved.
#[test]
fn random_indefinite_never_wrongly_solved() {
    let mut rng = Rng(0x5EED_0003);
    let (mut solved, mut unsolvable, mut failed_solvable) = (0, 0, 0);
    for n in 1..=8 {
        for _ in 0..60 * stress() {
            let a = random_matrix(&mut rng, n, Class::Indefinite);
            let q: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
            let sols = solve_by_enumeration(&a, &q, 1e-10);
            let s = solve(&a, &q);
            if s.outcome == LcpOutcome::Solved {
                let rel = if sols.iter().any(|z| ill_conditioned(&a, &q, z)) { 1e-5 } else { 1e-9 };
                assert!(is_among_tol(&s.z, &sols, rel), "n = {n}: z = {:?} not among {sols:?}", s.z);
                assert_lcp_solution(&a, &q, &s.z, "random indefinite");
                solved += 1;
            } else {
                assert!(matches!(s.outcome, LcpOutcome::RayTermination | LcpOutcome::PivotLimit | LcpOutcome::Inaccurate), "{s:?}");
                if sols.is_empty() { unsolvable += 1 } else { failed_solvable += 1 }
            }
            if sols.is_empty() {
                assert_ne!(s.outcome, LcpOutcome::Solved);
            }
        }
    }
    println!("indefinite: solved {solved}, unsolvable {unsolvable}, solvable but not solved by Lemke {failed_solvable}");
    assert!(solved > 100 && unsolvable > 10, "solved {solved}, unsolvable {unsolvable}");
}

/// Small integer data make ties in the ratio test common (degenerate bases), which exercises the
/// lexicographic rule and the row swaps of the revised form. Integer PSD matrices (Lᵀ L + B − Bᵀ
/// with integer L, B) are copositive-plus: whenever enumeration finds a solution the LCP is
/// feasible and Lemke must solve it. For any class, a solved z is a complementary basic solution,
/// so it must be among the enumerated ones.
#[test]
fn degenerate_integer_lcps() {
    let mut rng = Rng(0x5EED_0007);
    let int = |rng: &mut Rng, lo: i64, hi: i64| (lo + (rng.next_u64() % (hi - lo + 1) as u64) as i64) as f64;
    let (mut solved, mut ties_seen) = (0, 0);
    for round in 0..1200 * stress() {
        let n = 1 + round % 6;
        let psd = round % 2 == 0;
        let a = if psd {
            let rows = 1 + (rng.next_u64() as usize) % n;
            let l: Vec<f64> = (0..rows * n).map(|_| int(&mut rng, -1, 1)).collect();
            let b: Vec<f64> = (0..n * n).map(|_| int(&mut rng, -1, 1)).collect();
            DenseMatrix::from_fn(n, |i, j| (0..rows).map(|k| l[k * n + i] * l[k * n + j]).sum::<f64>() + b[i * n + j] - b[j * n + i])
        } else {
            let e: Vec<f64> = (0..n * n).map(|_| int(&mut rng, -2, 2)).collect();
            DenseMatrix::from_row_major(n, e)
        };
        let q: Vec<f64> = (0..n).map(|_| int(&mut rng, -2, 1)).collect();
        let qmin = q.iter().cloned().fold(f64::INFINITY, f64::min);
        if q.iter().filter(|&&v| v == qmin).count() > 1 {
            ties_seen += 1;
        }
        let sols = solve_by_enumeration(&a, &q, 1e-10);
        let s = solve(&a, &q);
        if s.outcome == LcpOutcome::Solved {
            let rel = if sols.iter().any(|z| ill_conditioned(&a, &q, z)) { 1e-5 } else { 1e-9 };
            assert!(is_among_tol(&s.z, &sols, rel), "round {round}: z = {:?} not among {sols:?}; A = {a:?}, q = {q:?}", s.z);
            assert_lcp_solution(&a, &q, &s.z, "integer");
            solved += 1;
        } else if psd {
            if s.outcome == LcpOutcome::Inaccurate {
                assert!(sols.iter().all(|z| ill_conditioned(&a, &q, z)), "round {round}: {sols:?}, but {s:?}");
            } else {
                assert!(sols.is_empty(), "round {round}: PSD, solvable ({sols:?}) but {s:?}; A = {a:?}, q = {q:?}");
                assert_eq!(s.outcome, LcpOutcome::RayTermination, "round {round}: {s:?}");
            }
        }
    }
    println!("integer: solved {solved}, with tied minimum q {ties_seen}");
    assert!(solved > 500 && ties_seen > 200);
}

// ---------------------------------------------------------------------------------------------
// Small classical examples
// ---------------------------------------------------------------------------------------------

fn dense(rows: &[&[f64]]) -> DenseMatrix {
    DenseMatrix::from_fn(rows.len(), |i, j| rows[i][j])
}

/// Murty (1988): A = [[1,2,0],[0,1,2],[2,0,1]], q = −e. Degenerate (all q_i tie in the first
/// ratio test). A is a P-matrix (principal minors 1, 1, 1, 1, 1, 1, 9), so the solution is unique:
/// z = (1/3, 1/3, 1/3) with w = 0 (each row: 1/3 + 2/3 − 1 = 0).
#[test]
fn murty_degenerate_3x3() {
    let a = dense(&[&[1.0, 2.0, 0.0], &[0.0, 1.0, 2.0], &[2.0, 0.0, 1.0]]);
    let q = [-1.0; 3];
    let s = solve(&a, &q);
    assert_eq!(s.outcome, LcpOutcome::Solved, "{s:?}");
    assert!(max_diff(&s.z, &[1.0 / 3.0; 3]) <= 1e-14, "{:?}", s.z);
    assert!(norm_inf(&s.w) <= 1e-14);
    let sols = solve_by_enumeration(&a, &q, 1e-12);
    assert_eq!(sols.len(), 1);
    assert!(max_diff(&sols[0], &[1.0 / 3.0; 3]) <= 1e-14);
}

/// Murty's exponential example (Murty 1988, ch. 6): M upper triangular, 1 on the diagonal, 2
/// above; q_i = −Σ_{j=i..n} 2^j. The unique solution is z = 2ⁿ e_n (w_i = 2^{n+1} − Σ_{j≥i} 2^j
/// = 2^i > 0 for i < n), and the complementary pivot method takes 2ⁿ pivots.
fn murty_exponential(n: usize) -> (DenseMatrix, Vec<f64>) {
    let a = DenseMatrix::from_fn(n, |i, j| {
        if i == j {
            1.0
        } else if j > i {
            2.0
        } else {
            0.0
        }
    });
    let q: Vec<f64> = (1..=n).map(|i| -(i..=n).map(|j| 2f64.powi(j as i32)).sum::<f64>()).collect();
    (a, q)
}

#[test]
fn murty_exponential_pivots_within_limit() {
    for n in [4usize, 6, 8] {
        let (a, q) = murty_exponential(n);
        let s = solve(&a, &q);
        assert_eq!(s.outcome, LcpOutcome::Solved, "n = {n}: {s:?}");
        let mut expected = vec![0.0; n];
        expected[n - 1] = 2f64.powi(n as i32);
        assert_eq!(s.z, expected);
        assert_eq!(s.info.pivots, 1 << n, "n = {n}");
        assert!(s.info.pivots <= 20 * n + 100);
    }
    // With a budget of 100 pivots (max_pivots_per_dim = 0) the 256 pivots of n = 8 do not fit.
    let (a, q) = murty_exponential(8);
    let s = solve_with(&a, &q, LemkeSettings { max_pivots_per_dim: 0, ..LemkeSettings::default() });
    assert_eq!(s.outcome, LcpOutcome::PivotLimit);
    assert_eq!(s.info.pivots, 100);
}

#[test]
fn ray_termination_when_infeasible() {
    // w = −z − 1 < 0 for every z ≥ 0.
    let s = solve(&dense(&[&[-1.0]]), &[-1.0]);
    assert_eq!(s.outcome, LcpOutcome::RayTermination, "{s:?}");
    // Skew-symmetric (PSD, copositive-plus) and infeasible: w2 = −z1 − 1 < 0.
    let a = dense(&[&[0.0, 1.0], &[-1.0, 0.0]]);
    let q = [-1.0, -1.0];
    assert!(solve_by_enumeration(&a, &q, 1e-12).is_empty());
    let s = solve(&a, &q);
    assert_eq!(s.outcome, LcpOutcome::RayTermination, "{s:?}");
    // Not copositive: w2 = −z1 − z2 − 1 < 0.
    let a = dense(&[&[-1.0, 2.0], &[-1.0, -1.0]]);
    let q = [1.0, -1.0];
    assert!(solve_by_enumeration(&a, &q, 1e-12).is_empty());
    assert_eq!(solve(&a, &q).outcome, LcpOutcome::RayTermination);
}

#[test]
fn trivial_when_q_nonnegative() {
    let a = dense(&[&[-3.0, 1.0], &[2.0, -5.0]]);
    let q = [0.0, 2.5];
    let s = solve(&a, &q);
    assert_eq!(s.outcome, LcpOutcome::Solved);
    assert_eq!(s.info.pivots, 0);
    assert_eq!(s.z, vec![0.0, 0.0]);
    assert_eq!(s.w, q.to_vec());
    // n = 0 is trivially solved too.
    let s = solve(&DenseMatrix::from_row_major(0, vec![]), &[]);
    assert_eq!(s.outcome, LcpOutcome::Solved);
}

#[test]
fn non_finite_data_is_reported_never_propagated() {
    let good = dense(&[&[2.0, 1.0], &[1.0, 2.0]]);
    let cases: Vec<(DenseMatrix, Vec<f64>)> = vec![
        (dense(&[&[2.0, f64::NAN], &[1.0, 2.0]]), vec![-1.0, -1.0]),
        (dense(&[&[2.0, 1.0], &[f64::INFINITY, 2.0]]), vec![-1.0, -1.0]),
        (good.clone(), vec![f64::NAN, -1.0]),
        (good.clone(), vec![-1.0, f64::NEG_INFINITY]),
        // Non-finite data are rejected even when q ≥ 0 would make z = 0 look fine.
        (dense(&[&[f64::NAN, 1.0], &[1.0, 2.0]]), vec![1.0, 1.0]),
    ];
    for (a, q) in cases {
        let s = solve(&a, &q);
        assert_eq!(s.outcome, LcpOutcome::NonFiniteData, "{s:?}");
        assert_eq!(s.z, vec![0.0, 0.0]);
        assert_eq!(s.w, vec![0.0, 0.0]);
    }
    let mut blocks = vec![1.0, 0.5, 0.25, 0.125];
    blocks[2] = f64::NAN;
    let bc = BlockCirculant::new(4, 1, blocks);
    let s = solve(&bc, &[-1.0; 4]);
    assert_eq!(s.outcome, LcpOutcome::NonFiniteData);
    // Huge but finite data: the result is still finite (checked by `solve`).
    let a = dense(&[&[1e300, -1e300], &[-1e300, 1e300]]);
    let _ = solve(&a, &[-1e300, 1e-300]);
}

// ---------------------------------------------------------------------------------------------
// Siconos test problems
// ---------------------------------------------------------------------------------------------

fn siconos_dir() -> PathBuf {
    // Shipped with the repository (tests/data/siconos-lcp/README.md: origin and licence).
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/siconos-lcp");
    assert!(dir.is_dir(), "the Siconos LCP data is missing at {}", dir.display());
    dir
}

/// What the right answer for each file is, and why.
enum Expect {
    /// The unique solution (verified by enumeration for n ≤ 12 and by hand where stated).
    Unique(Vec<f64>),
    /// Solved; the solution set is a continuum, checked by this property.
    Continuum(fn(&[f64]) -> bool),
    /// Solved; too large to enumerate: the LCP conditions are checked on the parsed data.
    Verified,
    /// Lemke ends on a ray.
    Ray,
}

#[test]
fn siconos_problems() {
    use Expect::*;
    // M is stored column by column in these files (see src/lcp/io/dat.rs).
    let table: Vec<(&str, Expect)> = vec![
        // M = [[1,1],[1,1]], q = −e: every z ≥ 0 with z1 + z2 = 1 (CPS 2009, Remark 4.1.14).
        ("lcp_CPS_1", Continuum(|z| (z[0] + z[1] - 1.0).abs() <= 1e-12)),
        // M = [[0,−1,2],[2,0,−2],[−1,1,0]], q = (−3,6,−1): z = (0,1,3) gives w = (2,0,0); unique
        // by enumeration.
        ("lcp_CPS_2", Unique(vec![0.0, 1.0, 3.0])),
        // Bimatrix game (CPS Example 4.4.23): Lemke with covering vector e leaves at once on a
        // secondary ray — after z0 enters at row 4, z4 enters and its column is zero in rows 3–4
        // (the own-player block), so nothing blocks. The game does have equilibria (enumeration
        // finds 3, checked below): this is the known failure of Lemke's scheme with d = e on
        // bimatrix games (Lemke–Howson is the method for them).
        ("lcp_CPS_3", Ray),
        // Convex QP KKT system [[Q, −aᵀ],[a, 0]] (Q SPD), q = (50,50,10,−6): z = (2,2,2,92),
        // w = 0 (row 1: 22 + 20 − 92 + 50 = 0; row 4: 2+2+2 − 6 = 0). Unique by enumeration.
        ("lcp_CPS_4", Unique(vec![2.0, 2.0, 2.0, 92.0])),
        // Same with q3 = 23: z = (3,3,0,83), degenerate (z3 = w3 = 0). Unique by enumeration.
        ("lcp_CPS_4bis", Unique(vec![3.0, 3.0, 0.0, 83.0])),
        // M = [[1,−1],[−1,1]], q = (1,−1): w1 = −w2, so w = 0 and z2 = z1 + 1 (CPS Ex. 4.4.16).
        ("lcp_CPS_5", Continuum(|z| (z[1] - z[0] - 1.0).abs() <= 1e-12)),
        // M = [[0,−1,−1],[1,0,0],[−1,0,0]], q = (0,−1,1): w2 = z1 − 1, w3 = 1 − z1 force z1 = 1,
        // and w1 = −z2 − z3 ≥ 0 forces z2 = z3 = 0: the isolated solution (1,0,0).
        ("lcp_Pang_isolated_sol", Unique(vec![1.0, 0.0, 0.0])),
        // Same with q1 = −1e−4: w1 = −z2 − z3 − 1e−4 < 0 for every z ≥ 0: infeasible.
        ("lcp_Pang_isolated_sol_perturbed", Ray),
        // [[2,1],[1,2]] z = (5,6): z = (4/3, 7/3), w = 0.
        ("lcp_deudeu", Unique(vec![4.0 / 3.0, 7.0 / 3.0])),
        // 9×9, unique by enumeration (the name refers to Siconos' own enumeration solver).
        ("lcp_enum_fails", Unique(vec![])),
        // Murty's upper-triangular M, q = −e: z = e6 (w_i = 2 − 1 = 1 for i < 6).
        ("lcp_exp_murty", Unique(vec![0.0, 0.0, 0.0, 0.0, 0.0, 1.0])),
        // Murty's exponential example, n = 6: z = 64 e6, reached after 2⁶ pivots (checked below).
        ("lcp_exp_murty2", Unique(vec![0.0, 0.0, 0.0, 0.0, 0.0, 64.0])),
        // M = [[0,−1,1],[1,0,0],[−1,0,0]], q = (−1e−4,−1,1): z1 = 1 and w1 = z3 − z2 − 1e−4 must
        // vanish (if w1 > 0 then z2 = z3 = 0 and w1 < 0): the ray z = (1, t, t + 1e−4), t ≥ 0.
        ("lcp_inf_sol_perturbed", Continuum(|z| (z[0] - 1.0).abs() <= 1e-12 && (z[2] - z[1] - 1e-4).abs() <= 1e-12)),
        // n = 26: checked on the data.
        ("lcp_mmc", Verified),
        // 4×4 nonsymmetric: z = (2/3, 0, 1/3, 0), unique by enumeration.
        ("lcp_ortiz", Unique(vec![2.0 / 3.0, 0.0, 1.0 / 3.0, 0.0])),
        // n = 40, polymatrix game [[P, −E],[Eᵀ, 0]], q = (0, −e): checked on the data.
        ("lcp_tobenna", Verified),
        // diag(1…9) z = e: z_i = 1/i.
        ("lcp_trivial", Unique((1..=9).map(|i| 1.0 / i as f64).collect())),
    ];
    let dir = siconos_dir();
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .expect("read the Siconos data folder")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".dat"))
        .map(|f| f.trim_end_matches(".dat").to_string())
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = table.iter().map(|(f, _)| f.to_string()).collect();
    listed.sort();
    assert_eq!(on_disk, listed, "every Siconos file must have a stated expectation");

    for (name, expect) in &table {
        let (a, q) = read_dat(&dir.join(format!("{name}.dat"))).unwrap_or_else(|e| panic!("{e}"));
        let n = a.dim();
        assert_eq!(q.len(), n);
        let s = solve(&a, &q);
        let sols = if n <= 12 { Some(solve_by_enumeration(&a, &q, 1e-10)) } else { None };
        println!("{name}: n = {n}, {:?}, {} pivots, residual {:.1e}", s.outcome, s.info.pivots, s.info.residual);
        match expect {
            Unique(z) => {
                assert_eq!(s.outcome, LcpOutcome::Solved, "{name}: {s:?}");
                let sols = sols.as_ref().unwrap();
                assert_eq!(sols.len(), 1, "{name}: enumeration finds {sols:?}");
                let tol = 1e-9 * norm_inf(&sols[0]).max(1.0);
                assert!(max_diff(&s.z, &sols[0]) <= tol, "{name}: z = {:?} vs enumeration {:?}", s.z, sols[0]);
                if !z.is_empty() {
                    assert!(max_diff(&s.z, z) <= tol, "{name}: z = {:?} vs expected {z:?}", s.z);
                }
                assert_lcp_solution(&a, &q, &s.z, name);
            }
            Continuum(property) => {
                assert_eq!(s.outcome, LcpOutcome::Solved, "{name}: {s:?}");
                assert!(property(&s.z), "{name}: z = {:?} not in the solution set", s.z);
                assert_lcp_solution(&a, &q, &s.z, name);
            }
            Verified => {
                assert_eq!(s.outcome, LcpOutcome::Solved, "{name}: {s:?}");
                assert_lcp_solution(&a, &q, &s.z, name);
            }
            Ray => {
                assert_eq!(s.outcome, LcpOutcome::RayTermination, "{name}: {s:?}");
            }
        }
    }

    // Per-file facts quoted in the table.
    let load = |name: &str| read_dat(&dir.join(format!("{name}.dat"))).unwrap();
    let (a, q) = load("lcp_CPS_3");
    assert_eq!(solve_by_enumeration(&a, &q, 1e-10).len(), 3, "the game has 3 equilibria");
    assert_eq!(solve(&a, &q).info.pivots, 1, "ray at the first entering z");
    let (a, q) = load("lcp_Pang_isolated_sol_perturbed");
    assert!(solve_by_enumeration(&a, &q, 1e-10).is_empty());
    // Infeasibility certificate: row 1 of M is ≤ 0 and q1 < 0.
    assert!((0..3).all(|j| a.entry(0, j) <= 0.0) && q[0] < 0.0);
    let (a, q) = load("lcp_exp_murty2");
    assert_eq!(solve(&a, &q).info.pivots, 64, "Murty: 2^6 pivots");
    let (a, q) = load("lcp_CPS_1");
    assert_eq!(solve_by_enumeration(&a, &q, 1e-10).len(), 2, "the two vertices of z1 + z2 = 1");
}

// ---------------------------------------------------------------------------------------------
// The .dat reader and writer
// ---------------------------------------------------------------------------------------------

/// The orientation of M in the files, checked on entries whose meaning is known: lcp_CPS_4 is the
/// KKT system [[Q, −aᵀ],[a, 0]] with a = (1,1,1); its 4th text line is (−1 −1 −1 0), which is
/// column 4 of M (−aᵀ, 0), not row 4 (a, 0).
#[test]
fn dat_reads_columns_of_m() {
    let (a, q) = read_dat(&siconos_dir().join("lcp_CPS_4.dat")).unwrap();
    assert_eq!(a.row(3), &[1.0, 1.0, 1.0, 0.0]);
    assert_eq!((0..4).map(|i| a.entry(i, 3)).collect::<Vec<_>>(), vec![-1.0, -1.0, -1.0, 0.0]);
    assert_eq!(q, vec![50.0, 50.0, 10.0, -6.0]);
    // The 40×40 file with a "40 40" header (space, not tab) and the 2×2 file without a final
    // newline both parse.
    let (a, q) = read_dat(&siconos_dir().join("lcp_tobenna.dat")).unwrap();
    assert_eq!((a.dim(), q.len()), (40, 40));
    assert_eq!(q[31..].to_vec(), vec![0.0, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0]);
    let (a, q) = read_dat(&siconos_dir().join("lcp_deudeu.dat")).unwrap();
    assert_eq!(a.as_slice(), &[2.0, 1.0, 1.0, 2.0]);
    assert_eq!(q, vec![-5.0, -6.0]);
}

#[test]
fn dat_round_trip_is_exact() {
    let mut rng = Rng(0x5EED_0004);
    let n = 7;
    let values: Vec<f64> = (0..n * n).map(|_| rng.uniform(-1e3, 1e3) * 10f64.powi((rng.next_u64() % 20) as i32 - 10)).collect();
    let a = DenseMatrix::from_row_major(n, values);
    let q: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0) / 3.0).collect();
    let path = std::env::temp_dir().join(format!("lcp_round_trip_{}.dat", std::process::id()));
    write_dat(&path, &a, &q).unwrap();
    let (b, p) = read_dat(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert_eq!(a, b);
    assert_eq!(q, p);
    // A block-circulant matrix is written through its columns.
    let bc = BlockCirculant::new(3, 2, (0..12).map(|v| v as f64 - 5.5).collect());
    let path = std::env::temp_dir().join(format!("lcp_round_trip_bc_{}.dat", std::process::id()));
    write_dat(&path, &bc, &[1.0; 6]).unwrap();
    let (b, _) = read_dat(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert_eq!(b, DenseMatrix::from_matrix(&bc));
    // Non-finite data or a size mismatch are refused.
    let path = std::env::temp_dir().join(format!("lcp_refused_{}.dat", std::process::id()));
    assert!(write_dat(&path, &a, &q[1..]).is_err());
    assert!(write_dat(&path, &dense(&[&[f64::NAN]]), &[1.0]).is_err());
    assert!(!path.exists());
}

fn parse_err(text: &str) -> String {
    match parse_dat(text, "lcp_x.dat") {
        Ok(_) => panic!("parsed: {text:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn dat_errors_name_file_line_expected_and_found() {
    let good = "2\n0\n2\n2\n2\t2\n1 2\n3 4\n-1 -1\ncomment\n";
    let (a, q) = parse_dat(good, "g").unwrap();
    assert_eq!(a.as_slice(), &[1.0, 3.0, 2.0, 4.0]); // lines are columns
    assert_eq!(q, vec![-1.0, -1.0]);

    let e = parse_err("4\n0\n4\n4\n4\t4\n1 2 3 4\n1 2 3\n");
    assert_eq!(e, "lcp_x.dat line 7: expected 4 values of column 2 of M, found 3");
    let e = parse_err("2\n0\n2\n2\n2\t2\n1 2\n3 4\n");
    assert_eq!(e, "lcp_x.dat line 8: expected 2 values of q, found end of file (truncated)");
    let e = parse_err("2\n0\n2\n2\n2\t2\n1 x\n3 4\n-1 -1\n");
    assert_eq!(e, "lcp_x.dat line 6: expected a number (value 2 of column 1 of M), found \"x\"");
    let e = parse_err("2\n0\n2\n2\n2\t2\n1 2\n3 4\n-1 NaN\n");
    assert_eq!(e, "lcp_x.dat line 8: expected a finite number (value 2 of q), found \"NaN\"");
    let e = parse_err("2\n0\n2\n2\n2\t2\n1 inf\n3 4\n-1 -1\n");
    assert!(e.contains("line 6") && e.contains("finite number"), "{e}");
    let e = parse_err("2\n1\n2\n2\n");
    assert_eq!(e, "lcp_x.dat line 2: storage type 1: only dense storage (0) is supported");
    let e = parse_err("2\n0\n2\n3\n");
    assert_eq!(e, "lcp_x.dat line 4: expected the number of columns of M (2), found \"3\"");
    let e = parse_err("2\n0\n2\n2\n2 3\n");
    assert_eq!(e, "lcp_x.dat line 5: expected the dimensions of M (\"2 2\"), found \"2 3\"");
    let e = parse_err("");
    assert_eq!(e, "lcp_x.dat line 1: expected the size n (a positive integer), found end of file (truncated)");
    let e = parse_err("-3\n");
    assert_eq!(e, "lcp_x.dat line 1: expected the size n (a positive integer), found \"-3\"");
    let e = parse_err("0\n");
    assert!(e.starts_with("lcp_x.dat line 1: expected the size n"), "{e}");
    let e = parse_err("99999999999\n0\n");
    assert!(e.contains("line 1"), "{e}");
    let e = parse_err("3000000000\n0\n");
    assert!(e.contains("line 1") && e.contains("fits in memory"), "{e}");
    let e = parse_err("1000000000\n0\n1000000000\n1000000000\n1000000000 1000000000\n1 2\n");
    assert!(e.contains("line 6") && e.contains("found 2"), "{e}");
    // Blank lines and CRLF line ends are accepted.
    let (_, q) = parse_dat("\n2\r\n0\r\n\r\n2\r\n2\r\n2 2\r\n1 0\r\n0 1\r\n5 6", "crlf").unwrap();
    assert_eq!(q, vec![5.0, 6.0]);
    // A missing file is an I/O error naming it.
    let e = read_dat(Path::new("/nonexistent/lcp_missing.dat")).unwrap_err();
    assert!(matches!(e, DatError::Io { .. }) && e.to_string().starts_with("lcp_missing.dat: cannot read"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    /// Arbitrary text never panics the parser.
    #[test]
    fn dat_parser_never_panics_on_arbitrary_text(text in "\\PC*") {
        let _ = parse_dat(&text, "fuzz");
    }

    /// Text made of the format's own tokens (digits, signs, exponents, NaN, whitespace) never
    /// panics either, and whatever parses is finite and square.
    #[test]
    fn dat_parser_never_panics_on_near_valid_text(
        tokens in proptest::collection::vec(
            prop_oneof![
                Just("2".to_string()), Just("0".to_string()), Just("1".to_string()), Just("3".to_string()),
                Just("-1.5e3".to_string()), Just("nan".to_string()), Just("inf".to_string()), Just("1e400".to_string()),
                Just("\n".to_string()), Just("\t".to_string()), Just(" ".to_string()), Just("x".to_string()),
                Just("18446744073709551616".to_string()), Just("4294967296".to_string()),
            ],
            0..40,
        )
    ) {
        let text = tokens.join(" ");
        if let Ok((a, q)) = parse_dat(&text, "fuzz") {
            prop_assert_eq!(a.dim(), q.len());
            prop_assert!(a.max_abs().1 && q.iter().all(|v| v.is_finite()));
        }
    }

    /// Every truncation of a valid file either parses to the same data (only the comment was cut)
    /// or gives an error; never a panic.
    #[test]
    fn dat_truncations_error_or_parse(cut in 0usize..80) {
        let good = "3\n0\n3\n3\n3\t3\n1 2 3\n4 5 6\n7 8 9\n-1 -2 -3\n# comment\n";
        let cut = cut.min(good.len());
        match parse_dat(&good[..cut], "cut") {
            Ok((a, q)) => {
                prop_assert_eq!(q, vec![-1.0, -2.0, -3.0]);
                prop_assert_eq!(a.entry(0, 1), 4.0);
            }
            Err(e) => prop_assert!(e.to_string().starts_with("cut line ")),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Enumeration
// ---------------------------------------------------------------------------------------------

#[test]
fn enumeration_reference_cases() {
    // Diagonal: z_i = 1/d_i.
    let a = dense(&[&[2.0, 0.0], &[0.0, 4.0]]);
    assert_eq!(solve_by_enumeration(&a, &[-1.0, -1.0], 1e-12), vec![vec![0.5, 0.25]]);
    // Two isolated solutions: A = [[−1, 0],[0, 1]]... w1 = 1 − z1: z1 ∈ {0 (w1 = 1), 1 (w1 = 0)}.
    let a = dense(&[&[-1.0, 0.0], &[0.0, 1.0]]);
    let mut sols = solve_by_enumeration(&a, &[1.0, 0.5], 1e-12);
    sols.sort_by(|x, y| x[0].total_cmp(&y[0]));
    assert_eq!(sols, vec![vec![0.0, 0.0], vec![1.0, 0.0]]);
    // The documented blind spot: A = [[0,0],[1,−1]], q = (0,−1) is solved by z = (t, 0), t ≥ 1,
    // but no complementary basis is nonsingular and feasible.
    let a = dense(&[&[0.0, 0.0], &[1.0, -1.0]]);
    assert!(solve_by_enumeration(&a, &[0.0, -1.0], 1e-12).is_empty());
    assert_lcp_solution(&a, &[0.0, -1.0], &[1.0, 0.0], "blind spot");
    // Non-finite data: nothing.
    assert!(solve_by_enumeration(&dense(&[&[f64::NAN]]), &[-1.0], 1e-12).is_empty());
}

// ---------------------------------------------------------------------------------------------
// Block-circulant matrices
// ---------------------------------------------------------------------------------------------

/// Entry ((j,a),(l,b)) = blocks[((j − l) mod k)·m² + a·m + b], written out here from the
/// definition, independently of the implementation.
fn circulant_reference(k: usize, m: usize, blocks: &[f64]) -> Vec<Vec<f64>> {
    let n = k * m;
    let mut out = vec![vec![0.0; n]; n];
    for j in 0..k {
        for l in 0..k {
            let d = (j + k - l) % k;
            for a in 0..m {
                for b in 0..m {
                    out[j * m + a][l * m + b] = blocks[d * m * m + a * m + b];
                }
            }
        }
    }
    out
}

#[test]
fn block_circulant_agrees_with_its_definition() {
    let mut rng = Rng(0x5EED_0005);
    for &(k, m) in &[(1usize, 1usize), (1, 3), (5, 1), (4, 2), (3, 3), (7, 2)] {
        let blocks: Vec<f64> = (0..k * m * m).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let bc = BlockCirculant::new(k, m, blocks.clone());
        let reference = circulant_reference(k, m, &blocks);
        let n = k * m;
        assert_eq!(bc.dim(), n);
        let dense = DenseMatrix::from_matrix(&bc);
        let mut col = vec![0.0; n];
        for j in 0..n {
            bc.column_into(j, &mut col);
            for i in 0..n {
                assert_eq!(bc.entry(i, j), reference[i][j]);
                assert_eq!(dense.entry(i, j), reference[i][j]);
                assert_eq!(col[i], reference[i][j]);
            }
        }
        let z: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let mut out = vec![0.0; n];
        bc.mul_into(&z, &mut out);
        let expected: Vec<f64> = (0..n).map(|i| (0..n).map(|j| reference[i][j] * z[j]).sum()).collect();
        assert!(max_diff(&out, &expected) <= 1e-14 * n as f64);
        let (amax, finite) = bc.max_abs();
        assert!(finite);
        assert_eq!(amax, blocks.iter().fold(0.0f64, |s, v| s.max(v.abs())));
        // add_block_diagonal adds to the diagonal of every diagonal block.
        let mut shifted = bc.clone();
        let diag: Vec<f64> = (0..m).map(|a| 1.0 + a as f64).collect();
        shifted.add_block_diagonal(&diag);
        for i in 0..n {
            for j in 0..n {
                let extra = if i == j { diag[i % m] } else { 0.0 };
                assert_eq!(shifted.entry(i, j), reference[i][j] + extra);
            }
        }
    }
}

/// m ẍ + c ẋ + k x = F cos ωt (m = 1, c = 0.1, k = 1, ω = 1.3, F = 2) against a rigid stop at
/// x = gap, discretised with k time steps and the cds symbols, the force sample j paired with the
/// gap at t_{j+1} ("forward pairing"). A is the discrete receptance (block-circulant, m = 1):
/// c_d = (1/k) Σ_p Re(Ĝ_p e^{2πi p d/k}), Ĝ_p = 1/(σ2 + 0.1 σ1 + 1), blocks[d] = c_{d+1};
/// q_j = gap − x_lin(t_{j+1}), x_lin(t) = Re(F e^{iωt} / (1 − ω² + 0.1 iω)).
fn oscillator_lcp(k: usize, gap: f64) -> (BlockCirculant, Vec<f64>) {
    oscillator_lcp_with(k, gap, 1.3, true)
}

/// As [`oscillator_lcp`] with forcing frequency ω, and the pairing: forward (force j ↔ gap at
/// t_{j+1}) or same-instant (force j ↔ gap at t_j).
fn oscillator_lcp_with(k: usize, gap: f64, omega: f64, forward: bool) -> (BlockCirculant, Vec<f64>) {
    let h = 2.0 * PI / omega / k as f64;
    let (cosv, sinv): (Vec<f64>, Vec<f64>) = (0..k).map(|m| (2.0 * PI * m as f64 / k as f64).sin_cos()).map(|(s, c)| (c, s)).unzip();
    // Ĝ_p = 1 / (a + i b), a = σ2 + 1, b = 0.1 sin θ / h.
    let g: Vec<(f64, f64)> = (0..k)
        .map(|p| {
            let a = (2.0 * cosv[p] - 2.0) / (h * h) + 1.0;
            let b = 0.1 * sinv[p] / h;
            let den = a * a + b * b;
            (a / den, -b / den)
        })
        .collect();
    let c: Vec<f64> =
        (0..k).map(|d| g.iter().enumerate().map(|(p, &(gr, gi))| gr * cosv[(p * d) % k] - gi * sinv[(p * d) % k]).sum::<f64>() / k as f64).collect();
    let shift = usize::from(forward);
    let blocks: Vec<f64> = (0..k).map(|d| c[(d + shift) % k]).collect();
    let (dr, di) = (1.0 - omega * omega, 0.1 * omega);
    let den = dr * dr + di * di;
    let q = (0..k)
        .map(|j| {
            let t = (j + shift) as f64 * h;
            gap - 2.0 * (dr * (omega * t).cos() + di * (omega * t).sin()) / den
        })
        .collect();
    (BlockCirculant::new(k, 1, blocks), q)
}

/// The LCPs this module exists for, over a sweep of forcing frequencies (below and above the
/// resonance, where A is not a P-matrix) and stop positions. With forward pairing every one must
/// be solved (docs: formulation.md §3); with same-instant pairing rays and pivot explosions are
/// expected, but whatever is reported solved must satisfy the LCP conditions.
#[test]
fn oscillator_frequency_sweep() {
    let (mut same_solved, mut same_other) = (0, 0);
    for &k in &[32usize, 64, 128] {
        for iw in 0..14 {
            let omega = 0.2 + 0.3 * iw as f64;
            for &gap in &[1.0, 0.5, 0.0, -0.5] {
                let (a, q) = oscillator_lcp_with(k, gap, omega, true);
                let s = solve(&a, &q);
                assert_eq!(s.outcome, LcpOutcome::Solved, "k = {k}, ω = {omega}, gap = {gap}: {:?}", s.info);
                assert_lcp_solution(&a, &q, &s.z, "forward pairing");
                let (a, q) = oscillator_lcp_with(k, gap, omega, false);
                let s = solve(&a, &q);
                if s.outcome == LcpOutcome::Solved {
                    assert_lcp_solution(&a, &q, &s.z, "same-instant pairing");
                    same_solved += 1;
                } else {
                    same_other += 1;
                }
            }
        }
    }
    println!("same-instant pairing: {same_solved} solved, {same_other} not");
}

#[test]
fn lemke_on_block_circulant_equals_dense_copy() {
    for &(k, gap) in &[(64usize, 1.0), (96, 0.0)] {
        let (bc, q) = oscillator_lcp(k, gap);
        let dense = DenseMatrix::from_matrix(&bc);
        let s1 = solve(&bc, &q);
        let s2 = solve(&dense, &q);
        assert_eq!(s1.outcome, LcpOutcome::Solved, "{s1:?}");
        assert_eq!(s2.outcome, LcpOutcome::Solved);
        assert_eq!(s1.info.pivots, s2.info.pivots);
        assert!(max_diff(&s1.z, &s2.z) <= 1e-12 * norm_inf(&s1.z).max(1.0));
        assert!(s1.z.iter().any(|&v| v > 0.0), "contact must happen");
        assert_lcp_solution(&bc, &q, &s1.z, "oscillator");
    }
    // A block-circulant with m = 2 (two contacts): random SPD-like blocks, compared likewise.
    let mut rng = Rng(0x5EED_0006);
    let (k, m) = (6, 2);
    let mut blocks: Vec<f64> = (0..k * m * m).map(|_| rng.uniform(-0.2, 0.2)).collect();
    blocks[0] += 3.0;
    blocks[3] += 3.0;
    let bc = BlockCirculant::new(k, m, blocks);
    let q: Vec<f64> = (0..k * m).map(|_| rng.uniform(-1.0, 1.0)).collect();
    let s1 = solve(&bc, &q);
    let s2 = solve(&DenseMatrix::from_matrix(&bc), &q);
    assert_eq!((s1.outcome, s1.info.pivots), (s2.outcome, s2.info.pivots));
    assert_eq!(s1.outcome, LcpOutcome::Solved);
    assert!(max_diff(&s1.z, &s2.z) <= 1e-12 * norm_inf(&s1.z).max(1.0));
    let sols = solve_by_enumeration(&bc, &q, 1e-10);
    assert_eq!(sols.len(), 1);
    assert!(max_diff(&s1.z, &sols[0]) <= 1e-9 * norm_inf(&sols[0]).max(1.0));
}

// ---------------------------------------------------------------------------------------------
// Warm start
// ---------------------------------------------------------------------------------------------

#[test]
fn warm_start_exact_guess_is_accepted_and_wrong_guess_falls_back() {
    let (bc, q) = oscillator_lcp(128, 0.5);
    let cold = solve(&bc, &q);
    assert_eq!(cold.outcome, LcpOutcome::Solved);
    assert!(cold.info.pivots > 0 && !cold.info.warm_start_used);
    let active: Vec<usize> = (0..q.len()).filter(|&i| cold.z[i] > 0.0).collect();
    assert!(active.len() > 2);
    let with = |guess: Vec<usize>| LemkeSettings { warm_start: Some(guess), ..LemkeSettings::default() };

    let warm = solve_with(&bc, &q, with(active.clone()));
    assert_eq!(warm.outcome, LcpOutcome::Solved);
    assert!(warm.info.warm_start_used);
    assert_eq!(warm.info.pivots, 0);
    assert!(max_diff(&warm.z, &cold.z) <= 1e-12 * norm_inf(&cold.z).max(1.0));

    // Wrong guesses: a missing index, an extra index, an index out of range: cold run, same z.
    let mut missing = active.clone();
    missing.remove(active.len() / 2);
    let extra: Vec<usize> = (0..q.len()).filter(|i| !active.contains(i)).take(1).chain(active.iter().copied()).collect();
    for guess in [missing, extra, vec![q.len()], (0..q.len()).collect()] {
        let s = solve_with(&bc, &q, with(guess.clone()));
        assert_eq!(s.outcome, LcpOutcome::Solved, "guess {guess:?}");
        assert!(!s.info.warm_start_used, "guess {guess:?}");
        assert_eq!(s.info.pivots, cold.info.pivots);
        assert!(max_diff(&s.z, &cold.z) <= 1e-12 * norm_inf(&cold.z).max(1.0));
    }
}

// ---------------------------------------------------------------------------------------------
// Performance smoke check (not timed; prints)
// ---------------------------------------------------------------------------------------------

#[test]
#[ignore]
fn lemke_block_circulant_timing() {
    // gap 1.0 is the reference case; lower stops mean longer contact and larger bases.
    for &(n, gap) in &[(1024usize, 1.0), (2048, 1.0), (4096, 1.0), (2048, 0.0), (2048, -1.0), (2048, -2.0)] {
        let (a, q) = oscillator_lcp(n, gap);
        let t = Instant::now();
        let s = solve(&a, &q);
        let wall = t.elapsed().as_secs_f64();
        let active = s.z.iter().filter(|&&v| v > 0.0).count();
        println!(
            "n = {n:5}, stop at {gap:4}: {:?}, {} pivots, {active} active, residual {:.1e}, solve {:.3} s (wall {:.3} s)",
            s.outcome, s.info.pivots, s.info.residual, s.info.time_s, wall
        );
        assert_eq!(s.outcome, LcpOutcome::Solved);
    }
}
