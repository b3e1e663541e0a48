//! Shooting on the step map (`auto`'s first step for the difference schemes) against dense
//! lexicographic Lemke, the certified reference: the same forces and displacements to 1e-9 on
//! every shipped scene and on random multi-contact models drawn from families nobody tuned for;
//! every fallback of the policy exercised; the largest sizes against the exact orbit.
use periodic_contact::exact::{Oscillator, RigidStopOrbit};
use periodic_contact::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};
use periodic_contact::periodic::{LcpMethod, OutputSelection, PeriodicProblem, PeriodicSolver, SolveError, SolverSettings, step_map};
use periodic_contact::response::Response;

use crate::common::compare;
use compare::{difference, max_abs};
use periodic_contact::scene::Scene;
use periodic_contact::time::{Discretization, Pairing, Scheme};
use std::path::Path;

const AGREE: f64 = 1e-9;

fn with(p: &PeriodicProblem, method: LcpMethod) -> PeriodicProblem {
    let mut q = p.clone();
    q.set_solver_settings(SolverSettings { method, ..q.solver_settings().clone() }).unwrap();
    q
}

/// `auto` (shooting first, Lemke after a failed shooting) and Lemke alone: both certified, the same
/// answer to 1e-9, residual ≤ 1e-10 of the gaps' scale. Returns (auto, whether shooting alone
/// solved it, lemke).
fn agree(name: &str, p: &PeriodicProblem) -> (Response, bool, Response) {
    let lemke = with(p, LcpMethod::Lemke).solve().unwrap_or_else(|e| panic!("{name}: lemke failed: {e}"));
    let auto = with(p, LcpMethod::Auto).solve().unwrap_or_else(|e| panic!("{name}: auto failed: {e}\n{:?}\n{:?}", p.model(), p.discretization()));
    let alone = auto.lcp.path.contains("shooting") && !auto.lcp.path.contains("fallback");
    let d = difference(&auto, &lemke);
    eprintln!(
        "{name} k = {}: auto {} ({} steps, {:.4} s, residual {:.1e}); lemke {} pivots, {:.4} s; difference {d:.1e}",
        p.discretization().steps,
        if alone { "by shooting" } else { "after a fallback" },
        auto.lcp.pivots,
        auto.timing_s.lcp,
        auto.lcp.residual,
        lemke.lcp.pivots,
        lemke.timing_s.lcp
    );
    assert!(d <= AGREE, "{name}: auto differs from lemke by {d:.3e}");
    let scale = auto.contacts.iter().map(|c| max_abs(&c.gap)).fold(1.0, f64::max);
    assert!(auto.lcp.residual <= 1e-10 * scale, "{name}: residual {:e}", auto.lcp.residual);
    (auto, alone, lemke)
}

fn load(path: &Path) -> PeriodicProblem {
    let (s, _) = Scene::load(path).unwrap();
    s.to_problem(&path.display().to_string()).unwrap()
}

/// Every shipped scene with contact and a step map, at its k and (1-DOF and chain scenes) 2k:
/// `auto` agrees with Lemke, and shooting alone solves every one of them cold except the rigid
/// blade at its resonance, where the offset homotopy runs out of its budget (measured) and
/// Lemke answers; started from that answer's active set, as a sweep starts each point from the
/// last, shooting alone solves it. The compliant blades are left out: dense Lemke ends on its
/// pivot limit there (61 540 pivots on blade-casing), so there is no reference answer.
#[test]
fn shooting_agrees_with_lemke_on_every_shipped_scene() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes");
    let mut paths: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "toml")).collect();
    paths.sort();
    let mut checked = 0;
    for path in paths {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let p = load(&path);
        if p.model().contacts.is_empty() || (name.starts_with("blade-") && !name.contains("rigid")) {
            continue;
        }
        assert!(step_map(&p).is_ok(), "{name}: every shipped contact scene has a step map: {:?}", step_map(&p).err());
        let k = p.discretization().steps;
        let sizes: &[usize] = if name.starts_with("blade-") { &[k] } else { &[k, 2 * k] };
        for &kk in sizes {
            let mut pk = p.clone();
            pk.set_discretization(Discretization { steps: kk, ..p.discretization() }).unwrap();
            let (_, alone, lemke) = agree(&name, &pk);
            if name.starts_with("blade-") {
                let mut session = PeriodicSolver::new(with(&pk, LcpMethod::Shooting));
                session.set_warm_start(&lemke.active_set);
                let warm = session.solve().unwrap_or_else(|e| panic!("{name}: shooting from Lemke's active set failed: {e}"));
                assert!(difference(&warm, &lemke) <= AGREE, "{name}: warm shooting differs from lemke");
            } else {
                assert!(alone, "{name} k = {kk}: shooting alone did not solve it");
            }
            checked += 1;
        }
    }
    assert!(checked >= 8, "only {checked} scene/size pairs checked");
}

/// A small deterministic generator (64-bit LCG, Knuth's constants): the families are drawn, not
/// tuned.
struct Draw(u64);
impl Draw {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
    fn index(&mut self, n: usize) -> usize {
        ((self.unit() * n as f64) as usize).min(n - 1)
    }
}

/// A random spring–mass chain of n DOFs (masses 0.5–2, springs 0.5–2 including one to ground at
/// each end), Rayleigh damping giving 2–8 % on the first mode, a harmonic force on a random DOF,
/// and m contacts on random DOFs and sides, all rigid or all compliant (stiffness 5–50 × the
/// chain's), gaps at 40–90 % of the contact-free amplitude so that every contact is reached.
fn random_chain(draw: &mut Draw, n: usize, m: usize, rigid: bool) -> Model {
    let masses: Vec<f64> = (0..n).map(|_| draw.range(0.5, 2.0)).collect();
    let springs: Vec<f64> = (0..=n).map(|_| draw.range(0.5, 2.0)).collect();
    let mut k = vec![vec![0.0; n]; n];
    for i in 0..n {
        k[i][i] = springs[i] + springs[i + 1];
        if i + 1 < n {
            k[i][i + 1] = -springs[i + 1];
            k[i + 1][i] = -springs[i + 1];
        }
    }
    let mass: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| if i == j { masses[i] } else { 0.0 }).collect()).collect();
    let beta = draw.range(0.02, 0.08);
    let damping: Vec<Vec<f64>> = k.iter().map(|row| row.iter().map(|v| beta * v).collect()).collect();
    let omega = draw.range(0.3, 1.2);
    let forced = draw.index(n);
    let structure = Structure { mass: Matrix::from_rows(&mass), stiffness: Matrix::from_rows(&k), damping: Some(Matrix::from_rows(&damping)) };
    let mut model = Model {
        structure,
        forces: vec![Force { dof: forced, term: Harmonic { amplitude: draw.range(0.5, 2.0), harmonic: 1, phase: 0.0 } }],
        contacts: Vec::new(),
        frequency: omega,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    };
    // The contact-free amplitude of each DOF, from a linear solve (no contact).
    let outputs = OutputSelection { displacement: (0..n).collect(), velocity: vec![], acceleration: vec![], contacts: false };
    let free = PeriodicProblem::new(model.clone(), Discretization { scheme: Scheme::Cds, steps: 256, pairing: None }, outputs, SolverSettings::default())
        .unwrap()
        .solve()
        .unwrap();
    // Distinct DOFs: two stops on one DOF make the step matrix singular (no step map; auto then
    // takes the block-circulant chain, tests/fast_solver.rs covers that case).
    let mut dofs: Vec<usize> = (0..n).collect();
    for _ in 0..m {
        let dof = dofs.swap_remove(draw.index(dofs.len()));
        let direction = if draw.unit() < 0.5 { 1.0 } else { -1.0 };
        let x = &free.displacement[&dof.to_string()];
        let reach = x.iter().map(|v| direction * v).fold(f64::MIN, f64::max);
        let gap = reach * draw.range(0.4, 0.9);
        let compliance = if rigid { Compliance::Rigid } else { Compliance::Compliant { stiffness: draw.range(5.0, 50.0) } };
        model.contacts.push(Contact { row: vec![(dof, direction)], gap, compliance, motion: Vec::new() });
    }
    model
}

/// Random multi-contact models (2–5 DOFs, 1–3 contacts, rigid or compliant, every difference
/// scheme with its converging pairing, k = 128–512): `auto` agrees with dense Lemke to 1e-9, and
/// shooting alone solves nearly all of them.
#[test]
fn shooting_agrees_with_lemke_on_random_multi_contact_models() {
    let mut draw = Draw(20261124);
    let (mut solved, mut by_shooting) = (0, 0);
    for case in 0..24 {
        let n = 2 + draw.index(4);
        let m = (1 + draw.index(3)).min(n);
        let rigid = case % 2 == 0;
        let (scheme, pairing) = match (rigid, draw.index(4)) {
            (true, 0 | 1) => (Scheme::Cds, Pairing::Forward),
            (true, 2) => (Scheme::Galerkin, Pairing::Forward),
            (true, _) => (Scheme::Bds1, Pairing::Same),
            (false, 0) => (Scheme::Cds, Pairing::Same),
            (false, 1) => (Scheme::Galerkin, Pairing::Same),
            (false, 2) => (Scheme::Bds1, Pairing::Same),
            (false, _) => (Scheme::Bds2, Pairing::Same),
        };
        let k = [128, 256, 512][draw.index(3)];
        let model = random_chain(&mut draw, n, m, rigid);
        let outputs = OutputSelection { displacement: (0..n).collect(), velocity: vec![], acceleration: vec![], contacts: true };
        let p = match PeriodicProblem::new(model, Discretization { scheme, steps: k, pairing: Some(pairing) }, outputs, SolverSettings::default()) {
            Ok(p) => p,
            // A draw past cds's stability limit is refused before solving (tests/scheme_limits.rs).
            Err(SolveError::Limit(why)) => {
                eprintln!("case {case}: refused: {why}");
                continue;
            }
            Err(e) => panic!("case {case}: {e}"),
        };
        let name = format!("case {case}: n = {n}, m = {m}, {} {scheme}/{pairing}", if rigid { "rigid" } else { "compliant" });
        let (r, alone, _) = agree(&name, &p);
        assert!(r.contacts.iter().any(|c| c.force.iter().any(|&f| f > 0.0)), "{name}: no contact is active");
        solved += 1;
        by_shooting += usize::from(alone);
    }
    eprintln!("{by_shooting} of {solved} draws solved by shooting alone, the others after its fallback to Lemke");
    assert!(solved >= 20, "only {solved} of 24 draws were solvable");
    // Measured: 23 of 24 (the exception, two compliant stops near resonance, needs more than the
    // homotopy's budget). Fewer would mean the fast path regressed.
    assert!(by_shooting + 2 >= solved, "only {by_shooting} of {solved} solved by shooting alone");
}

/// Past the old caps of the step map (64 DOFs, 10 contacts): 70-DOF chains with 12 compliant
/// stops (stiffness 1–3, the chain's order), under cds/same (S diagonal) and bds1/same (S = B W Bᵀ + D couples all 12: checked
/// through its symmetric part), at k = 256 (N = 3072). Shooting alone solves them
/// and agrees with dense Lemke's certified answer to 1e-9. (Rigid stops under cds/forward, or stops
/// 5–50 times stiffer, on this chain: Newton does not converge and Lemke answers.)
#[test]
fn shooting_past_the_old_caps_agrees_with_lemke() {
    let mut draw = Draw(20261125);
    for (rigid, scheme, pairing, k) in [(false, Scheme::Cds, Pairing::Same, 256), (false, Scheme::Bds1, Pairing::Same, 256)] {
        let (n, m) = (70, 12);
        let mut model = random_chain(&mut draw, n, m, rigid);
        // Stops of the springs' order (1–3): at 5–50 Newton does not converge with 12 stops.
        for c in &mut model.contacts {
            c.compliance = Compliance::Compliant { stiffness: draw.range(1.0, 3.0) };
        }
        let outputs = OutputSelection { displacement: vec![0, n - 1], velocity: vec![], acceleration: vec![], contacts: true };
        let p = PeriodicProblem::new(model, Discretization { scheme, steps: k, pairing: Some(pairing) }, outputs, SolverSettings::default()).unwrap();
        assert!(step_map(&p).is_ok(), "{:?}", step_map(&p).err());
        let name = format!("n = {n}, m = {m}, {} {scheme}/{pairing}", if rigid { "rigid" } else { "compliant" });
        let (r, alone, _) = agree(&name, &p);
        assert!(alone, "{name}: shooting alone did not solve it: {}", r.lcp.path);
        let active = r.contacts.iter().filter(|c| c.force.iter().any(|&f| f > 0.0)).count();
        // Several stops touch (measured: 3 of 12 under cds), so the step LCPs couple pairs.
        assert!(active >= 2, "{name}: only {active} of {m} contacts are active");
    }
}

/// The size path at a small size: a 50-DOF chain (state d = 100, so the march's products go to
/// faer's matrix–vector kernels, and the certification's exact recheck runs lag by lag on the
/// selected rows) with 8 compliant stops of the springs' order, cds/same, k = 256 (N = 2048):
/// shooting alone, certified, agrees with dense Lemke to 1e-10.
#[test]
fn shooting_with_the_large_state_kernels_agrees_with_lemke_to_1e_10() {
    let mut draw = Draw(20261126);
    let (n, m, k) = (50, 8, 256);
    let mut model = random_chain(&mut draw, n, m, false);
    for c in &mut model.contacts {
        c.compliance = Compliance::Compliant { stiffness: draw.range(1.0, 3.0) };
    }
    let outputs = OutputSelection { displacement: vec![0, n / 2, n - 1], velocity: vec![], acceleration: vec![], contacts: true };
    let p = PeriodicProblem::new(model, Discretization { scheme: Scheme::Cds, steps: k, pairing: Some(Pairing::Same) }, outputs, SolverSettings::default())
        .unwrap();
    assert_eq!(step_map(&p).unwrap().state_size(), 2 * n);
    let lemke = with(&p, LcpMethod::Lemke).solve().unwrap();
    let shot = with(&p, LcpMethod::Shooting).solve().unwrap();
    let d = difference(&shot, &lemke);
    let active = shot.contacts.iter().filter(|c| c.force.iter().any(|&f| f > 0.0)).count();
    eprintln!(
        "n = {n}, m = {m}, k = {k}: {} Newton iterations, residual {:.1e}, {active} stops active, difference to Lemke {d:.1e}",
        shot.lcp.pivots, shot.lcp.residual
    );
    assert!(active >= 2, "only {active} of {m} stops touch");
    assert!(d <= 1e-10, "shooting differs from Lemke by {d:.3e}");
}

/// The rigid stop with sticking at k = 65 536 (the size the dense methods refuse): shooting
/// solves it, certified, and the orbit is the exact one within cds/forward's O(h²) error.
#[test]
fn a_rigid_stop_at_k_65536_matches_the_exact_orbit() {
    let osc = Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 1.0, omega: 1.0 };
    let exact = RigidStopOrbit::solve(&osc, 0.5).unwrap();
    let k = 65536;
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Cds, steps: k, pairing: Some(Pairing::Forward) };
    let p = PeriodicProblem::new(osc.model(vec![Oscillator::stop(0.5, Compliance::Rigid)]), disc, outputs, SolverSettings::default()).unwrap();
    let r = p.solve().unwrap();
    assert!(r.lcp.path.contains("shooting") && !r.lcp.path.contains("fallback"), "{}", r.lcp.path);
    assert!(r.lcp.residual <= 1e-10, "residual {:e}", r.lcp.residual);
    let e = r.time.iter().zip(&r.displacement["0"]).map(|(&t, &x)| (x - exact.eval(t).0).abs()).fold(0.0, f64::max) / exact.peak_to_peak();
    eprintln!("k = {k}: error {e:.2e} against the exact orbit, {:.3} s", r.timing_s.total);
    // cds/forward is second order here (tests/convergence.rs): e·k² ≈ 2–5 measured at k ≤ 4096.
    assert!(e < 20.0 / (k as f64 * k as f64), "error {e:.3e}");
}

/// Cold shooting fails (the rigid blade near its resonance: the offset homotopy closes on
/// itself, measured) and `auto` solves it from the bds1 pilot's sets on the same grid
/// (`src/periodic/pilot.rs`), without the dense fallback, certified, and as dense Lemke does.
/// (The fallback to Lemke where the pilot misses too: tests/cold_miss.rs.)
#[test]
fn a_failed_cold_shooting_is_solved_from_the_pilot() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-rigid.toml");
    let mut p = load(&path);
    p.set_frequency(2301.010101010101).unwrap();
    match with(&p, LcpMethod::Shooting).solve() {
        Err(SolveError::Lcp { outcome, .. }) => eprintln!("shooting alone: {}", outcome.name()),
        other => panic!("shooting was expected to fail here: {:?}", other.map(|r| r.lcp.path)),
    }
    let r = p.solve().unwrap();
    eprintln!("{}", r.lcp.path);
    assert!(r.lcp.path.contains("bds1 pilot") && !r.lcp.path.contains("fallback"), "{}", r.lcp.path);
    assert!(r.lcp.residual <= 1e-9);
    let lemke = with(&p, LcpMethod::Lemke).solve().unwrap();
    let d = difference(&r, &lemke);
    assert!(d <= AGREE, "the piloted solve differs from lemke by {d:.3e}");
}

/// Fallback 2: no step map. A contact paired forward under bds1 waits for a later step's gap, so
/// the LCP is not a step map: `auto` takes the block-circulant chain, and `shooting` asked for by
/// name is refused with the reason.
#[test]
fn without_a_step_map_auto_takes_the_block_circulant_chain() {
    let osc = Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 1.0, omega: 1.0 };
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Bds1, steps: 128, pairing: Some(Pairing::Forward) };
    let p = PeriodicProblem::new(osc.model(vec![Oscillator::stop(0.5, Compliance::Rigid)]), disc, outputs, SolverSettings::default()).unwrap();
    let why = step_map(&p).unwrap_err();
    assert!(why.to_string().contains("paired forward under bds1"), "{why}");
    let r = p.solve().unwrap();
    assert!(r.lcp.path.starts_with("auto (N = 128 ≤ 256: dense Lemke)"), "{}", r.lcp.path);
    let e = with(&p, LcpMethod::Shooting).solve().unwrap_err().to_string();
    assert!(e.contains("solver.method") && e.contains("shooting") && e.contains("paired forward") && e.contains("\"auto\""), "{e}");
}

/// Fallbacks 3 and 4, at the policy itself: a step map on which shooting breaks down (Φ = I, so
/// the contact-free fixed point is singular) handed with a rigid-stop LCP. Up to N = 4096 dense
/// Lemke follows the failed shooting; above, block pivoting first. Both end certified.
#[test]
fn the_policy_falls_back_after_a_shooting_breakdown() {
    use periodic_contact::lcp::{StepMapData, StepMapLcp, solve_periodic_lcp};
    let osc = Oscillator { mass: 1.0, damping: 0.1, stiffness: 1.0, force: 1.0, omega: 1.0 };
    for (k, next) in [(1024, "dense lexicographic Lemke"), (8192, "block pivoting")] {
        let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
        let disc = Discretization { scheme: Scheme::Cds, steps: k, pairing: Some(Pairing::Forward) };
        let p = PeriodicProblem::new(osc.model(vec![Oscillator::stop(0.5, Compliance::Rigid)]), disc, outputs, SolverSettings::default()).unwrap();
        let (a, q) = p.assemble_lcp(&periodic_contact::periodic::PeriodFft::new(k)).unwrap();
        let drift = StepMapData {
            k,
            d: 1,
            m: 1,
            phi: vec![0.0],
            carry: vec![(0, 0)],
            c: vec![1.0; k],
            h: vec![1.0],
            gamma: vec![1.0],
            flexibility: vec![0.0],
            r: vec![1.0; k],
        };
        let sm = StepMapLcp::new(drift).unwrap();
        let (sol, _) = solve_periodic_lcp(&a, &q, Some(&sm), LcpMethod::Auto, 1e-9, None);
        let steps: Vec<String> = sol.info.path.iter().map(|s| format!("{} → {}", s.method.name(), s.outcome.name())).collect();
        eprintln!("N = {k}: {steps:?}");
        assert_eq!(sol.outcome, periodic_contact::lcp::LcpOutcome::Solved, "{steps:?}");
        assert_eq!(sol.info.path[0].method, LcpMethod::Shooting);
        assert_ne!(sol.info.path[0].outcome, periodic_contact::lcp::LcpOutcome::Solved);
        let rendered = periodic_contact::periodic::render_lcp_path(LcpMethod::Auto, &sol.info.path);
        assert!(rendered.contains(&format!("; fallback: {next}")), "{rendered}");
        assert!(sol.info.residual <= 1e-9 * q.iter().fold(1.0f64, |m, v| m.max(v.abs())));
    }
}

/// A model whose dense step map would cost too much (a 2000-DOF sparse chain: d = 4000, ≈ 1.2e12
/// flops per Newton iteration at k = 256) gets none: the refusal names the memory and work
/// figures and the remedy, and comes before the map is built (the test ends in a blink).
#[test]
fn a_step_map_past_the_estimates_is_refused_with_its_figures() {
    use faer::sparse::{SparseColMat, Triplet};
    let n = 2000;
    let chain = |diagonal: f64, off: f64| {
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Triplet::new(i, i, diagonal));
            if i + 1 < n && off != 0.0 {
                t.push(Triplet::new(i, i + 1, off));
                t.push(Triplet::new(i + 1, i, off));
            }
        }
        Matrix::Sparse(SparseColMat::try_new_from_triplets(n, n, &t).unwrap())
    };
    let structure = Structure { mass: chain(1.0, 0.0), stiffness: chain(2.0, -1.0), damping: None };
    let contact = Contact::on_dof(0, 1.0, 0.5, Compliance::Rigid);
    let model = Model {
        structure,
        forces: vec![Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } }],
        contacts: vec![contact],
        frequency: 1.0,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    };
    let outputs = OutputSelection { displacement: vec![0], velocity: vec![], acceleration: vec![], contacts: true };
    let p =
        PeriodicProblem::new(model, Discretization { scheme: Scheme::Cds, steps: 256, pairing: Some(Pairing::Forward) }, outputs, SolverSettings::default())
            .unwrap();
    let why = step_map(&p).unwrap_err().to_string();
    for part in ["2000 DOFs", "d = 4000", "GiB", "flops per Newton iteration", "at most 1e12", "Craig–Bampton"] {
        assert!(why.contains(part), "{part:?} missing from: {why}");
    }
}

/// The bds1 pilot of a cold solve (`src/periodic/pilot.rs`): a Craig–Bampton-like pair, a body
/// (mass 1, spring 1 to ground) and a light tip (mass 0.01) on a stiff spring (100: the tip's
/// constraint mode at ≈ 100 rad/s against forcing at 0.8 rad/s), Rayleigh-damped (0.5 % on the
/// tip mode), a rigid stop on the tip at half its contact-free reach; cds/forward at k = 2048
/// (N = 2048). `auto` starts shooting from the pilot's sets, solves it without a fallback, and
/// agrees with dense lexicographic Lemke's certified answer to 1e-9.
#[test]
fn a_piloted_cold_solve_of_a_stiff_rigid_model_agrees_with_lemke() {
    let (n, k) = (2, 2048);
    let mass = Matrix::from_rows(&[vec![1.0, 0.0], vec![0.0, 0.01]]);
    let stiff = [vec![101.0, -100.0], vec![-100.0, 100.0]];
    let damping: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| 1e-4 * stiff[i][j] + if i == j { 0.02 * [1.0, 0.01][i] } else { 0.0 }).collect()).collect();
    let structure = Structure { mass, stiffness: Matrix::from_rows(&stiff), damping: Some(Matrix::from_rows(&damping)) };
    let force = Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } };
    let mut model = Model { structure, forces: vec![force], contacts: Vec::new(), frequency: 0.8, frictions: Vec::new(), rubbing: Vec::new() };
    let outputs = OutputSelection { displacement: vec![0, 1], velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Cds, steps: k, pairing: Some(Pairing::Forward) };
    let free = PeriodicProblem::new(model.clone(), disc, outputs.clone(), SolverSettings::default()).unwrap().solve().unwrap();
    let reach = max_abs(&free.displacement["1"]);
    model.contacts.push(Contact { row: vec![(1, 1.0)], gap: 0.5 * reach, compliance: Compliance::Rigid, motion: Vec::new() });
    let p = PeriodicProblem::new(model, disc, outputs, SolverSettings::default()).unwrap();
    let piloted = p.solve().unwrap();
    let lemke = with(&p, LcpMethod::Lemke).solve().unwrap();
    let d = difference(&piloted, &lemke);
    eprintln!(
        "{}; residual {:.1e}; lemke {} pivots, {:.2} s; difference {d:.1e}",
        piloted.lcp.path, piloted.lcp.residual, lemke.lcp.pivots, lemke.timing_s.lcp
    );
    assert!(piloted.lcp.path.contains("bds1 pilot") && !piloted.lcp.path.contains("fallback"), "{}", piloted.lcp.path);
    assert!(piloted.contacts[0].force.iter().any(|&f| f > 0.0), "the stop is never reached");
    assert!(d <= AGREE, "the piloted solve differs from lemke by {d:.3e}");
}

/// Newton on a piece where the active sets do not change is exact (P is affine there), so a warm
/// start from the answer's own sets ends after one Newton step, at any k: the k-step march's
/// round-off (about k·ε·‖s‖, here 6e-13 of ‖s‖, above the 1e-13 tolerance) is no reason to go
/// on (issue 23: on the Craig–Bampton blade at k = 8192 a defect stuck below it cost 22 marches
/// instead of 12; measured here before the fix: a line search to t = 1/64, 9 marches). A 1e-14
/// change of the frequency is the same. Reference: the cold solve, to 1e-10 of ‖s‖.
#[test]
fn a_warm_start_on_the_answers_sets_stops_at_the_marchs_round_off() {
    use periodic_contact::lcp::{ShootingOutcome, ShootingSettings, solve_shooting};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-coarse.toml");
    let mut p = load(&path);
    let settings = ShootingSettings::default();
    let cold = solve_shooting(&step_map(&p).unwrap(), None, &settings);
    assert_eq!(cold.outcome, ShootingOutcome::Converged);
    let size = cold.state.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let omega = p.model().frequency;
    for (scale, most_iterations, most_marches) in [(1.0, 1, 3), (1.0 + 1e-14, 1, 3)] {
        p.set_frequency(omega * scale).unwrap();
        let warm = solve_shooting(&step_map(&p).unwrap(), Some(&cold.masks), &settings);
        let apart = warm.state.iter().zip(&cold.state).fold(0.0f64, |a, (x, y)| a.max((x - y).abs())) / size;
        eprintln!(
            "ω·{scale}: warm {:?}, {} iterations, {} marches, defect {:.1e} of ‖s‖, {apart:.1e} from the cold answer",
            warm.outcome,
            warm.iterations,
            warm.marches,
            warm.defect / size
        );
        assert_eq!(warm.outcome, ShootingOutcome::Converged);
        assert!(warm.iterations <= most_iterations && warm.marches <= most_marches, "{} iterations, {} marches", warm.iterations, warm.marches);
        assert!(warm.masks == cold.masks && apart <= 1e-10, "{apart:.1e} from the cold answer");
    }
}

/// The step map's state carried to another grid ([`carried_state`]) against the exact samples of
/// a smooth orbit x(t) = A sin(ωt + φ): block 0 is x at the newest instant (L − 1)·h and block 1
/// its backward difference (src/periodic/state_space.rs). For cds (L = 1) and bds1 (L = 0), k →
/// 2k and k → k/2, every entry is within 3·h²·ω²·A of the other grid's exact state (h the finer
/// step; by Taylor the midpoint rule, the linear extrapolation and a difference centred 1.5·h
/// away err by at most 3·h²·max|x''|); a lost h-scaling or a wrong sign of bds1's shift errs by
/// ≈ h·ω·A, 1/(3hω) ≈ 27 times the bound.
#[test]
fn the_carried_orbit_state_is_the_other_grids_to_second_order() {
    use periodic_contact::periodic::carried_state;
    let (omega, period) = (3.0, 2.0 * std::f64::consts::PI / 3.0);
    let amplitude = [1.0, 0.4];
    let x = |t: f64| -> Vec<f64> { amplitude.iter().zip([0.3, 1.9]).map(|(a, phase)| a * (omega * t + phase).sin()).collect() };
    // The state at the newest instant (L − 1)·h of a grid of k steps: (x, ∇x).
    let state = |lead: f64, k: usize| -> Vec<f64> {
        let h = period / k as f64;
        let (now, before) = (x((lead - 1.0) * h), x((lead - 2.0) * h));
        now.iter().cloned().chain(now.iter().zip(&before).map(|(a, b)| a - b)).collect()
    };
    for (scheme, lead) in [(Scheme::Cds, 1.0), (Scheme::Bds1, 0.0)] {
        for (from, to) in [(256, 512), (512, 256)] {
            let carried = carried_state(scheme, &state(lead, from), from, to).expect("a step-map scheme");
            let exact = state(lead, to);
            let h = period / from.max(to) as f64;
            let bound = 3.0 * h * h * omega * omega * amplitude[0];
            let error = carried.iter().zip(&exact).fold(0.0f64, |a, (c, e)| a.max((c - e).abs()));
            eprintln!("{scheme:?} k = {from} → {to}: carried within {error:.2e} of the exact state (bound 3h²ω²A = {bound:.2e}, hωA = {:.2e})", h * omega);
            assert!(error <= bound, "{scheme:?} k = {from} → {to}: {error:.3e} > {bound:.3e}");
        }
    }
    assert!(carried_state(Scheme::Fourier, &[1.0, 2.0], 8, 16).is_none(), "collocation has no step map");
}

/// Shooting warm-started on the doubled grid from the coarse answer's carried sets and its
/// carried orbit state (a sweep's refinement, issue 23) ends on the cold answer of the fine grid
/// (the reference: the same sets, the state to 1e-10 of ‖s‖) and skips the frozen sets' fixed
/// point: a march fewer than from the carried sets alone, and no more period Jacobians (here the
/// carried sets are the answer's, so the frozen start's Jacobian is Newton's too: 3 marches and
/// 1 Jacobian against 2 and 1, measured).
#[test]
fn a_refinement_from_the_carried_orbit_state_ends_on_the_cold_answer_with_less_work() {
    use periodic_contact::lcp::{ShootingOutcome, ShootingSettings, solve_shooting};
    use periodic_contact::periodic::carried_state;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-casing-coarse.toml");
    let mut p = load(&path);
    let settings = ShootingSettings::default();
    let k = p.discretization().steps;
    let coarse = solve_shooting(&step_map(&p).unwrap(), None, &settings);
    assert_eq!(coarse.outcome, ShootingOutcome::Converged);
    p.set_discretization(Discretization { steps: 2 * k, ..p.discretization() }).unwrap();
    let fine = step_map(&p).unwrap();
    let cold = solve_shooting(&fine, None, &settings);
    assert_eq!(cold.outcome, ShootingOutcome::Converged);
    let sets: Vec<u64> = (0..2 * k).map(|j| coarse.masks[j / 2]).collect();
    let frozen = solve_shooting(&fine, Some(&sets), &settings);
    let state = carried_state(p.discretization().scheme, &coarse.state, k, 2 * k);
    let carried = solve_shooting(&fine, Some(&sets), &ShootingSettings { warm_state: state, ..settings.clone() });
    let size = cold.state.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for (name, warm) in [("frozen sets' fixed point", &frozen), ("carried state", &carried)] {
        let apart = warm.state.iter().zip(&cold.state).fold(0.0f64, |a, (x, y)| a.max((x - y).abs())) / size;
        eprintln!(
            "k = {} from the {name}: {:?}, {} marches, {} Jacobians, {} iterations; {apart:.1e} of ‖s‖ from the cold answer",
            2 * k,
            warm.outcome,
            warm.marches,
            warm.jacobians,
            warm.iterations
        );
        assert_eq!(warm.outcome, ShootingOutcome::Converged, "{name}");
        assert!(warm.masks == cold.masks && apart <= 1e-10, "{name}: {apart:.1e} from the cold answer");
    }
    assert!(carried.marches < frozen.marches && carried.jacobians <= frozen.jacobians, "no work saved");
}
