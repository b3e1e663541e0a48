//! Results that speak for themselves (issue 11, item 4): the gap each force sample is paired
//! with, what became of a warm start, and the LCP methods that ran. Every check recomputes its
//! reference from the raw arrays or the raw LCP, not from values the engine reported.
use periodic_contact::lcp::LcpMatrix;
use periodic_contact::periodic::{PeriodFft, PeriodicProblem, PeriodicSolver};
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;

const RIGID: &str = include_str!("../fmu/scenes/rigid-stop.toml");
const COMPLIANT: &str = include_str!("../fmu/scenes/compliant-stop.toml");

fn problem(text: &str, name: &str) -> PeriodicProblem {
    Scene::parse(text, name).unwrap().to_problem(name).unwrap()
}

fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |m, x| m.max(x.abs()))
}

/// force·paired_gap = 0 and paired_gap ≥ 0 on the rigid stop, and paired_gap is the LCP's w = A z + q
/// recomputed from the assembled LCP and the reported forces. Returns (response, scale).
fn check_paired(p: &PeriodicProblem, pairing: &str) -> (Response, f64) {
    let r = p.solve().unwrap();
    let c = &r.contacts[0];
    assert_eq!(c.pairing, pairing);
    let k = c.force.len();
    let scale = max_abs(c.force.iter().copied()) * max_abs(c.gap.iter().copied());
    assert!(scale > 0.0);
    let tol = 1e-9;
    let product = max_abs((0..k).map(|j| c.force[j] * c.paired_gap[j]));
    assert!(product <= tol * scale, "{pairing}: max |force·paired_gap| = {product:e}, scale {scale:e}");
    assert!(c.paired_gap.iter().all(|&g| g >= -tol * max_abs(c.gap.iter().copied())), "{pairing}: paired gap below 0");
    // The raw LCP: w = A z + q with z the forces (one contact: z_j = force_j).
    let (a, q) = p.assemble_lcp(&PeriodFft::new(k)).unwrap();
    let mut w = vec![0.0; k];
    a.mul_into(&c.force, &mut w);
    let wmax = max_abs(w.iter().zip(&q).map(|(wi, qi)| wi + qi));
    let diff = max_abs((0..k).map(|j| w[j] + q[j] - c.paired_gap[j]));
    assert!(diff <= 1e-9 * wmax.max(1.0), "{pairing}: paired_gap differs from A z + q by {diff:e}");
    (r, scale)
}

#[test]
fn forward_pairing_pairs_force_j_with_gap_j_plus_1() {
    let (r, scale) = check_paired(&problem(RIGID, "rigid-stop (cds)"), "forward");
    let c = &r.contacts[0];
    let k = c.force.len();
    for j in 0..k {
        assert_eq!(c.paired_gap[j], c.gap[(j + 1) % k]);
    }
    // The complaint: the same-instant product is not small under forward pairing.
    let naive = max_abs((0..k).map(|j| c.force[j] * c.gap[j]));
    assert!(naive > 1e-4 * scale, "force·gap at the same instant: {naive:e}, scale {scale:e}");
}

#[test]
fn same_pairing_pairs_force_j_with_gap_j() {
    let text = RIGID.replace("scheme = \"cds\"", "scheme = \"bds1\"");
    let (r, _) = check_paired(&problem(&text, "rigid-stop (bds1)"), "same");
    let c = &r.contacts[0];
    assert_eq!(c.paired_gap, c.gap);
}

/// A sweep-like pair: solve at ω, move to ω(1 + 1e-3) and solve warm. The warm start is kept
/// (accepted or repaired) with fewer pivots than a fresh cold solve at the same ω, and the same answer.
#[test]
fn a_warm_start_reports_what_became_of_it() {
    let text = RIGID.replace("steps = 256", "steps = 512");
    let p = problem(&text, "rigid-stop k=512");
    let omega = p.model().frequency;
    let mut warm = PeriodicSolver::new(p.clone());
    let first = warm.solve().unwrap();
    assert_eq!(first.lcp.warm_start.outcome, "cold");
    assert!(!first.lcp.warm_start_used);
    warm.update_frequency(omega * (1.0 + 1e-3)).unwrap();
    let w = warm.solve().unwrap();
    let mut cold = PeriodicSolver::new(p);
    cold.update_frequency(omega * (1.0 + 1e-3)).unwrap();
    let c = cold.solve().unwrap();
    assert_eq!(c.lcp.warm_start.outcome, "cold");
    assert!(["accepted", "repaired"].contains(&w.lcp.warm_start.outcome.as_str()), "{:?}", w.lcp.warm_start);
    assert!(w.lcp.warm_start_used);
    assert_eq!(w.lcp.warm_start.pivots, w.lcp.pivots);
    assert!(w.lcp.pivots < c.lcp.pivots, "warm {} pivots, cold {}", w.lcp.pivots, c.lcp.pivots);
    eprintln!("warm: {:?} vs cold {} pivots; path {}", w.lcp.warm_start, c.lcp.pivots, w.lcp.path);
    let scale = max_abs(c.contacts[0].force.iter().copied()).max(1.0);
    let diff = max_abs(w.contacts[0].force.iter().zip(&c.contacts[0].force).map(|(a, b)| a - b));
    assert!(diff <= 1e-9 * scale, "warm and cold forces differ by {diff:e}");
    let dx = max_abs(w.displacement["0"].iter().zip(&c.displacement["0"]).map(|(a, b)| a - b));
    assert!(dx <= 1e-9 * max_abs(c.displacement["0"].iter().copied()).max(1.0));
}

/// A scheme with a time-stepping map is solved by shooting first, whatever N; fourier has none,
/// so `auto` goes to dense Lemke up to N = 256 and to block pivoting above, which fails on the
/// compliant stop (tests/fast_solver.rs) and falls back to Lemke: the path shows both steps.
#[test]
fn the_solver_path_names_the_methods_and_the_fallback() {
    let text = RIGID.replace("steps = 256", "steps = 64");
    let r = problem(&text, "rigid-stop k=64").solve().unwrap();
    assert!(r.lcp.path.starts_with("auto (N = 64, a time-stepping map: shooting first): shooting"), "{}", r.lcp.path);
    assert!(!r.lcp.path.contains("fallback"));

    let fourier = |steps: &str| COMPLIANT.replace("scheme = \"cds\"", "scheme = \"fourier\"").replace("steps = 512", steps);
    let r = problem(&fourier("steps = 64"), "compliant-stop fourier k=64").solve().unwrap();
    assert!(r.lcp.path.starts_with("auto (N = 64 ≤ 256: dense Lemke): dense lexicographic Lemke"), "{}", r.lcp.path);

    let r = problem(&fourier("steps = 512"), "compliant-stop fourier k=512").solve().unwrap();
    let path = &r.lcp.path;
    eprintln!("{path}");
    assert!(path.starts_with("auto (N = 512 > 256: block pivoting first): block pivoting"), "{path}");
    let (fast, fallback) = path.split_once("; fallback: ").expect("a fallback");
    assert!(!fast.ends_with("→ solved"), "{path}");
    assert!(fallback.starts_with("dense lexicographic Lemke") && fallback.ends_with("→ solved"), "{path}");
}
