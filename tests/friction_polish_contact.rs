//! Friction contacts together with a compliant unilateral stop in the stick–slip polish
//! (src/analysis/polish/friction/multi/stops.rs, issue 25) against an independent event-driven
//! exact simulation: the numbers below were produced by
//! `cd validation/peers && ../.venv/bin/python friction_contact_exact.py` (numpy/scipy: a mode per
//! friction phase and stop state, saddle-point reactions, expm flows, Brent events, fsolve
//! shooting; checked against DOP853 on the regularised law by `... friction_contact_exact.py check`).
//! Not copied from our own output.
use crate::friction_polish_multi::polished;
use periodic_contact::analysis::polish;
use periodic_contact::model::{Compliance, Contact, Model};

struct Reference {
    events: usize,
    stuck_fraction: f64,
    /// x(j·T/16), j = 0..16, both DOFs.
    x: &'static [[f64; 2]],
}

/// chain_stop Ω = 0.8 (rigid Coulomb μN = 0.25 on m2, stop x1 ≤ 0.4, k_c = 5): 6 events.
const CHAIN_STOP_LOW: Reference = Reference {
    events: 6,
    stuck_fraction: 0.02357363667379484,
    x: &[
        [0.7763168024072729, 1.2429698387401154],
        [0.9034992681826215, 2.0495449686494176],
        [0.737829911834549, 2.2000925729793708],
        [0.5089140508920084, 1.7315375976644145],
        [0.3841355362491649, 0.8274865936877573],
        [0.2534589556472257, -0.1496403286434635],
        [-0.1116712398346413, -0.8225666617630751],
        [-0.7578788377896201, -1.0634827725704261],
        [-1.486469597986215, -1.075152877638987],
        [-1.988293559039001, -1.175247650100868],
        [-2.0518008842633377, -1.5194914596371463],
        [-1.6895120634813714, -1.9662584599528232],
        [-1.0996152105271666, -2.146700445870217],
        [-0.5052981148848399, -1.8614722756809146],
        [-0.02042795114031848, -1.0688333633493257],
        [0.3921801398148841, 0.0799003976303867],
    ],
};

/// chain_stop Ω = 1.3 with a Jenkins element (k_t = 3) on m2: 6 events.
const CHAIN_STOP_JENKINS: Reference = Reference {
    events: 6,
    stuck_fraction: 0.16902113864251855,
    x: &[
        [-0.2498880440506357, -1.0780933312195105],
        [-0.10212609320241019, -0.9320645264234624],
        [0.06154278547766356, -0.6620232854987912],
        [0.2169995648350741, -0.3087966107684097],
        [0.3397482017850181, 0.0906592456058861],
        [0.41015018112709234, 0.48553701670876337],
        [0.41318811491471735, 0.8169715532393523],
        [0.3489570247555264, 1.0262137129251907],
        [0.2332619637148714, 1.0654375035875607],
        [0.0833200954328779, 0.9205707297995289],
        [-0.08017620992313, 0.6499228928598223],
        [-0.23323798348475658, 0.2949777369947695],
        [-0.35198757856884666, -0.10654468152891072],
        [-0.41774165439857924, -0.5027493179561586],
        [-0.42072500280674924, -0.8338084955088201],
        [-0.36149257956308023, -1.0411390831753324],
    ],
};

/// The 2-DOF chain of tests/friction.rs (friction μN = 0.25 on m2, rigid or Jenkins) with a
/// compliant stop keeping x1 ≤ 0.4 (k_c = 5), as `chain_stop` of the Python reference.
fn chain_stop(omega: f64, kt: Option<f64>) -> Model {
    let mut o = crate::friction::chain_oscillator(omega);
    o.tangential_stiffness = kt;
    let mut model = o.model();
    model.contacts.push(Contact::on_dof(0, 1.0, 0.4, Compliance::Compliant { stiffness: 5.0 }));
    model
}

#[test]
fn friction_with_a_compliant_stop_meets_the_event_driven_simulation() {
    let cases =
        [("rigid Coulomb + stop, Ω = 0.8", chain_stop(0.8, None), CHAIN_STOP_LOW), ("Jenkins + stop, Ω = 1.3", chain_stop(1.3, Some(3.0)), CHAIN_STOP_JENKINS)];
    for (name, model, reference) in cases {
        let period = 2.0 * std::f64::consts::PI / model.frequency;
        let (mut r, orbit, problem) = polished(model, 256);
        let orbit = orbit.unwrap_or_else(|e| panic!("{name}: {e}"));
        let scale = reference.x.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
        let err = (0..16)
            .flat_map(|j| {
                let x = orbit.state(j as f64 * period / 16.0);
                (0..2).map(move |d| (x[d] - reference.x[j][d]).abs())
            })
            .fold(0.0, f64::max)
            / scale;
        let stuck = (orbit.stuck_fraction(0) - reference.stuck_fraction).abs();
        let rho = orbit.multipliers().iter().map(|z| z.norm()).fold(0.0, f64::max);
        polish::apply(&problem, &mut r);
        let p = r.polish.as_ref().expect("polish summary");
        let kinds: Vec<&str> = p.events.iter().map(|e| e.kind.as_str()).collect();
        println!(
            "{name}: displacement error {err:.2e} of the largest |x|, stuck fraction to {stuck:.1e}, {} events (exact {}) {kinds:?}, Newton {} iterations, spectral radius {rho:.4}, {}",
            orbit.times.len(),
            reference.events,
            orbit.iterations,
            p.status
        );
        assert!(err < 1e-8 && stuck < 1e-8, "{name}: error {err:.2e}, stuck fraction {stuck:.2e}");
        assert_eq!(orbit.times.len(), reference.events);
        assert_eq!(p.status, "polished", "{name}: {}", p.reason);
        assert_eq!(kinds.iter().filter(|k| k.starts_with("contact_")).count(), 2, "{name}: the stop closes and opens once");
        assert!(rho < 1.0, "damped: the simulation converged onto it");
    }
}
