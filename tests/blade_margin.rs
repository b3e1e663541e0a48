//! The rigid margin of an exact orbit (`PolishedOrbit::rigid_margin`, the exact walk's test
//! function for a new event): against a brute-force reference, the orbit's own clearances and held
//! forces at thousands of instants a period (each a flow from its phase's start, `PolishedOrbit::state`),
//! and its cost on the real blade.
use periodic_contact::analysis::polish::{self, PolishedOrbit};
use periodic_contact::periodic::PeriodicProblem;
use periodic_contact::scene::Scene;
use std::path::Path;

/// The thread's CPU time [s] (Linux).
fn thread_cpu() -> f64 {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap();
    s.split_whitespace().next().unwrap().parse::<f64>().unwrap() * 1e-9
}

/// The smallest margin of the rigid contacts `rigid` at `t`, as `rigid_margin` scales it: a held
/// force over the force scale where the contact is stuck (a nonzero force), its clearance over
/// the largest normal displacement after an event otherwise.
fn margins_at(o: &PolishedOrbit, xs: f64, rigid: &[usize], t: f64) -> f64 {
    let forces = o.contact_forces(t);
    rigid.iter().map(|&i| if forces[i] == 0.0 { o.clearance_at(i, t) / xs } else { forces[i] / o.force_scale() }).fold(f64::INFINITY, f64::min)
}

/// The orbit's margin against the brute-force reference: no sampled value below it (beyond
/// round-off), none far above it, and its own value where it says.
fn check(name: &str, p: &PeriodicProblem, samples: usize) {
    let orbit = polish::polish(p, &p.solve().unwrap()).unwrap_or_else(|e| panic!("{name}: {e}"));
    let m = orbit.rigid_margin().unwrap();
    let model = p.model();
    let records = orbit.event_records();
    let xs = records.iter().flat_map(|r| model.contacts.iter().map(|c| c.along(|d| orbit.state(r.time)[d]).abs())).fold(0.0, f64::max);
    let rigid: Vec<usize> = (0..model.contacts.len()).filter(|&i| model.contacts[i].is_rigid()).collect();
    let (s, period) = (orbit.section_time(), orbit.period());
    let brute = (0..samples).map(|j| margins_at(&orbit, xs, &rigid, s + period * j as f64 / samples as f64)).fold(f64::INFINITY, f64::min);
    // At the margin's time as it measures it (the time may be its phase's end, an event).
    let here =
        if m.what == polish::CLEARANCE { orbit.clearance_at(m.contact, m.time) / xs } else { orbit.contact_force(m.contact, m.time) / orbit.force_scale() };
    eprintln!(
        "{name}: {} events, margin {:.3e} ({} of contact {} at {:.6}), brute force {brute:.3e}, direct at its time {here:.3e}",
        records.len(),
        m.value,
        m.what,
        m.contact,
        m.time
    );
    assert!(m.value <= brute + 1e-12 && m.value >= brute - 1e-9, "{name}");
    assert!((here - m.value).abs() <= 1e-11, "{name}");
}

fn oscillator(gap: f64, omega: f64) -> PeriodicProblem {
    let text = format!(
        "[structure]\nmass = [[1.0]]\nstiffness = [[1.0]]\n[damping]\nmatrix = [[0.1]]\n[excitation]\nfrequency = {omega}\n[[force]]\ndof = 0\namplitude = 1.0\n\
         [[contact]]\ndof = 0\ngap = {gap}\n[discretization]\nscheme = \"bds1\"\nsteps = 512\n[output]\ndisplacement = [0]\n"
    );
    Scene::parse(&text, "o").unwrap().to_problem("o").unwrap()
}

/// Impact oscillators: pure impacts (g = 1.5), impacts with sticking (g = 0.5).
#[test]
fn the_rigid_margin_is_the_orbits_smallest_clearance_or_held_force() {
    for (gap, omega) in [(1.5, 0.8), (1.5, 1.0), (0.5, 0.7)] {
        check(&format!("impact oscillator g = {gap}, Ω = {omega}"), &oscillator(gap, omega), 20_000);
    }
}

/// The coarse blade with rigid tips on its massless boundary (tests/massless_polish.rs's case):
/// 56 events, held forces and clearances of 17 contacts.
#[test]
#[ignore = "opt-in: ≈ 10 s CPU (the LCP at k = 512, the polish, 4000 brute-force instants)"]
fn the_coarse_blades_rigid_margin_is_its_smallest_clearance_or_held_force() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu/scenes/blade-two-lobes.toml");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("method = \"craig-bampton\"", "method = \"massless-boundary\"")
        .replace("scheme = \"bds2\"", "scheme = \"cds\"");
    let text = text.replace("steps = 256", "steps = 512");
    let drop = |l: &str| {
        l.starts_with("stiffness = 1e7")
            || l == "[[force]]"
            || l.starts_with("node = \"MC\"")
            || l.starts_with("axis = \"y\"")
            || l.starts_with("amplitude = 1.0")
    };
    let text: String = text.lines().filter(|l| !drop(l)).map(|l| format!("{l}\n")).collect();
    let t = text.replace("frequency = 2300.0", "frequency = 2250.0");
    check("coarse rigid blade at 2250", &Scene::parse(&t, "blade.toml").unwrap().to_problem("blade.toml").unwrap(), 4000);
}

/// The real blade at 2300 rad/s (52 events, 17 rigid tips): the margin in ≤ 0.1 s CPU (2.3 s
/// before, flowing the 138-state orbit per sample and per golden step).
#[test]
#[ignore = "opt-in: needs examples/real-blade/job (CalculiX matrices, untracked) and ≈ 30 s CPU"]
fn the_real_blades_rigid_margin_costs_little() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/real-blade/blade.toml");
    let (scene, dir) = Scene::load(&path).unwrap();
    let p = scene.build_in("blade.toml", &dir).unwrap().problem;
    check("real blade at 2300", &p, 4000);
    let orbit = polish::polish(&p, &p.solve().unwrap()).unwrap();
    let c0 = thread_cpu();
    let m = orbit.rigid_margin().unwrap();
    let cpu = thread_cpu() - c0;
    eprintln!("real blade at 2300 rad/s: rigid margin {:.3e} in {cpu:.3} s CPU", m.value);
    assert!(cpu <= 0.1, "{cpu} s");
}
