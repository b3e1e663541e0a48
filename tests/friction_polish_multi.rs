//! The stick–slip polish with several friction contacts (src/analysis/polish/friction/multi.rs)
//! against an independent event-driven exact simulation: the numbers below were produced by
//! `validation/.venv/bin/python validation/peers/friction_multi_exact.py` (numpy/scipy: saddle-point
//! modes, expm flows, Brent events, fsolve shooting; checked against DOP853 on the regularised
//! law by `... friction_multi_exact.py check`). Not copied from our own output.
use periodic_contact::analysis::polish::{self, friction::multi::MultiOrbit};
use periodic_contact::exact::FrictionOscillator;
use periodic_contact::model::{Friction, Model};
use periodic_contact::periodic::*;
use periodic_contact::time::{Discretization, Scheme};

struct Reference {
    events: usize,
    stuck_fraction: &'static [f64],
    /// x(j·T/16), j = 0..16, every DOF.
    x: &'static [&'static [f64]],
}

/// chain, μN = 0.6 on m2 and 0.5 on m1, Ω = 0.8: 8 events.
const CHAIN_BOTH: Reference = Reference {
    events: 8,
    stuck_fraction: &[0.4526126842999105, 0.08159367728630983],
    x: &[
        &[0.5064325443257996, -0.12206151894284636],
        &[0.6176743431520587, -0.10028713977494695],
        &[0.6176428287810828, -0.02887745081753132],
        &[0.6015360318211195, 0.06182074885947189],
        &[0.5257387301788609, 0.11995008608159952],
        &[0.3523568818461398, 0.12215478378456449],
        &[0.0788409340768244, 0.12215478378456449],
        &[-0.24011702904565985, 0.12215478378456449],
        &[-0.5064325443246873, 0.1220615189477745],
        &[-0.6176743431458848, 0.1002871397791471],
        &[-0.6176428287748782, 0.028877450821635765],
        &[-0.6015360318170129, -0.061820748854609114],
        &[-0.52573873017848, -0.11995008607646451],
        &[-0.3523568818493845, -0.12215478377960405],
        &[-0.07884093408189238, -0.12215478377960405],
        &[0.2401170290413669, -0.12215478377960513],
    ],
};

/// chain3, Coulomb 0.35 on m1, Jenkins 0.3 (k_t = 2) on m3, Ω = 0.6: 8 events.
const CHAIN3_LOW: Reference = Reference {
    events: 8,
    stuck_fraction: &[0.09681024284148332, 0.1443522543459473],
    x: &[
        &[1.4973899177999346, 1.4973759705648828, 1.0377268410411493],
        &[1.5984996986269961, 1.9485679027908704, 1.5175350133357715],
        &[1.5969064787790308, 2.001957347788122, 1.736675279132828],
        &[1.5230808899869137, 1.7075337426701016, 1.50758790631243],
        &[1.199315044052722, 1.2087747409059666, 1.0499848411217239],
        &[0.5457780982001391, 0.6130050191596426, 0.5468956834647875],
        &[-0.29639665680541066, -0.05726806129002743, 0.02888540968158798],
        &[-1.0499852445295685, -0.7976654754505995, -0.49846574991128356],
        &[-1.4973899177992447, -1.497375970562857, -1.037726841039293],
        &[-1.5984996986267137, -1.9485679027900629, -1.5175350133347947],
        &[-1.5969064787787288, -2.0019573477879913, -1.7366752791324576],
        &[-1.5230808899864838, -1.7075337426704444, -1.5075879063126227],
        &[-1.199315044052195, -1.2087747409063057, -1.0499848411219026],
        &[-0.5457780981995528, -0.6130050191594626, -0.5468956834647023],
        &[0.2963966568070866, 0.05726806129169954, -0.028885409680375174],
        &[1.049985244530929, 0.7976654754527861, 0.49846574991300424],
    ],
};

/// chain3, Ω = 1.3: 8 events.
const CHAIN3_HIGH: Reference = Reference {
    events: 8,
    stuck_fraction: &[0.008039989577126351, 0.48907196693819255],
    x: &[
        &[-0.16979492394644824, -0.6827764008553208, -0.26858985196723595],
        &[-0.11564027370986693, -0.5206021339388941, -0.2218410394482454],
        &[-0.03618666155269459, -0.2810209804114593, -0.13226541173206013],
        &[0.05637685759810489, 0.00045361128223483146, -0.02030505417805703],
        &[0.14169729679821236, 0.28298499798008586, 0.08463146916073505],
        &[0.19572614137628822, 0.5243174798867749, 0.16918428602041377],
        &[0.20372213370070819, 0.6861867713239815, 0.2323482243676945],
        &[0.196681083471863, 0.7416754392627396, 0.26887768723928773],
        &[0.16979492394705203, 0.6827764008558254, 0.26858985196801416],
        &[0.11564027371042045, 0.5206021339394921, 0.22184103944890712],
        &[0.03618666155316266, 0.281020980412236, 0.13226541173262346],
        &[-0.05637685759767397, -0.00045361128131444356, 0.02030505417862785],
        &[-0.14169729679783022, -0.28298499797941196, -0.08463146916016429],
        &[-0.19572614137579844, -0.5243174798862543, -0.1691842860197548],
        &[-0.2037221337001146, -0.6861867713234406, -0.232348224366901],
        &[-0.19668108347125057, -0.7416754392622495, -0.26887768723846595],
    ],
};

/// The 2-DOF chain of tests/friction.rs with rigid Coulomb friction μN_2 on m2 and μN_1 on m1.
pub(crate) fn chain_both(omega: f64, slip2: f64, slip1: f64) -> Model {
    let mut o = crate::friction::chain_oscillator(omega);
    o.slip_force = slip2;
    let mut model = o.model();
    model.frictions.push(Friction::on_dof(0, 1.0, slip1, None));
    model
}

/// A 3-DOF chain: rigid Coulomb μN_1 on m1, a Jenkins element (μN_3, k_t) on m3.
pub(crate) fn chain3(omega: f64, slip1: f64, slip3: f64, kt: f64) -> Model {
    let o = FrictionOscillator {
        mass: vec![vec![1.0, 0.0, 0.0], vec![0.0, 0.8, 0.0], vec![0.0, 0.0, 0.6]],
        damping: vec![vec![0.05, -0.02, 0.0], vec![-0.02, 0.04, -0.02], vec![0.0, -0.02, 0.03]],
        stiffness: vec![vec![2.0, -1.0, 0.0], vec![-1.0, 2.0, -1.0], vec![0.0, -1.0, 1.5]],
        force: vec![1.0, 0.0, 0.3],
        omega,
        dof: 0,
        slip_force: slip1,
        tangential_stiffness: None,
    };
    let mut model = o.model();
    model.frictions.push(Friction::on_dof(2, 1.0, slip3, Some(kt)));
    model
}

/// The LCP at k = `steps` (bds1), all DOFs out, and the multi-contact polish of it.
pub(crate) fn polished(model: Model, steps: usize) -> (periodic_contact::response::Response, Result<MultiOrbit, polish::PolishFailure>, PeriodicProblem) {
    let n = model.n();
    let outputs = OutputSelection { displacement: (0..n).collect(), velocity: vec![], acceleration: vec![], contacts: true };
    let disc = Discretization { scheme: Scheme::Bds1, steps, pairing: None };
    let problem = PeriodicProblem::new(model, disc, outputs, SolverSettings::default()).expect("problem");
    let r = problem.solve().expect("solve");
    let orbit = polish::friction::multi::polish(&problem, &r);
    (r, orbit, problem)
}

#[test]
fn polish_with_several_contacts_meets_the_event_driven_simulation() {
    let cases = [
        ("chain, rigid on both masses, Ω = 0.8", chain_both(0.8, 0.6, 0.5), CHAIN_BOTH),
        ("3-DOF chain, Coulomb + Jenkins, Ω = 0.6", chain3(0.6, 0.35, 0.3, 2.0), CHAIN3_LOW),
        ("3-DOF chain, Coulomb + Jenkins, Ω = 1.3", chain3(1.3, 0.35, 0.3, 2.0), CHAIN3_HIGH),
    ];
    let mut rows = Vec::new();
    for (name, model, reference) in cases {
        let period = 2.0 * std::f64::consts::PI / model.frequency;
        let (mut r, orbit, problem) = polished(model, 256);
        let orbit = orbit.unwrap_or_else(|e| panic!("{name}: {e}"));
        let scale = reference.x.iter().flat_map(|row| row.iter()).fold(0.0f64, |a, x| a.max(x.abs()));
        let err = reference
            .x
            .iter()
            .enumerate()
            .flat_map(|(j, row)| {
                let x = orbit.state(j as f64 * period / 16.0);
                row.iter().enumerate().map(move |(d, v)| (x[d] - v).abs()).collect::<Vec<_>>()
            })
            .fold(0.0, f64::max)
            / scale;
        let stuck = (0..reference.stuck_fraction.len()).map(|i| (orbit.stuck_fraction(i) - reference.stuck_fraction[i]).abs()).fold(0.0, f64::max);
        let rho = orbit.multipliers().iter().map(|z| z.norm()).fold(0.0, f64::max);
        polish::apply(&problem, &mut r);
        let status = r.polish.as_ref().map(|p| p.status.clone());
        rows.push((err, name, stuck, orbit.times.len(), reference.events, rho, orbit.iterations, status));
    }
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (err, name, stuck, events, exact, rho, it, status) in &rows {
        println!(
            "{name}: displacement error {err:.2e} of the largest |x|, stuck fractions to {stuck:.1e}, {events} events (exact {exact}), Newton {it} iterations, spectral radius {rho:.4}, {status:?}"
        );
        assert!(*err < 1e-8 && *stuck < 1e-8, "{name}: error {err:.2e}, stuck fraction {stuck:.2e}");
        assert_eq!(events, exact);
        assert_eq!(status.as_deref(), Some("polished"));
        assert!(*rho < 1.0, "damped: the simulation converged onto it");
    }
}
