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

/// Den Hartog's unit oscillator (m = k = F = 1) with rigid Coulomb friction and a rigid stop
/// x ≤ gap (plastic impacts): the reference numbers were produced by
/// `cd validation/peers && python -c "import friction_rigid_exact as fr; …"` (the solve of
/// friction_rigid_exact.py, x(jT/16) and its resting fraction; that simulation meets the closed-form
/// departure from the stop, arccos((k g − μN)/F)/Ω, to 3e-13). Not copied from our own output.
struct RigidStopCase {
    c: f64,
    omega: f64,
    slip: f64,
    gap: f64,
    /// The simulation's events: impact, departure, reversal.
    events: usize,
    stuck_fraction: f64,
    x: [f64; 16],
}

const RIGID_STOP_CASES: [RigidStopCase; 3] = [
    RigidStopCase {
        c: 0.0,
        omega: 0.8,
        slip: 0.3,
        gap: 0.5,
        events: 3,
        stuck_fraction: 0.2777536994016705,
        x: [
            0.5,
            0.5,
            0.5,
            0.5,
            0.497906368034242,
            0.44731400520447356,
            0.2727282612142047,
            -0.06024470204447063,
            -0.5235008828365605,
            -1.025382667316002,
            -1.429623127991491,
            -1.590235982144265,
            -1.465975920011874,
            -1.066361933008908,
            -0.39656177159960787,
            0.46086981775332314,
        ],
    },
    RigidStopCase {
        c: 0.1,
        omega: 1.438,
        slip: 0.2,
        gap: 0.3,
        events: 3,
        stuck_fraction: 0.07565689478647711,
        x: [
            -0.644260551797547,
            -0.3164140850554971,
            0.07776607623110066,
            0.3,
            0.2999193988705117,
            0.2905341531523224,
            0.2471032417533208,
            0.15031854810449385,
            -0.006930666108818831,
            -0.21698784421651052,
            -0.45755412731432477,
            -0.6945532763640859,
            -0.8873253454805058,
            -0.9953435544946028,
            -0.9901901539873227,
            -0.8736325111628547,
        ],
    },
    RigidStopCase {
        c: 0.05,
        omega: 1.438,
        slip: 0.5,
        gap: 0.1,
        events: 3,
        stuck_fraction: 0.2066409983282121,
        x: [
            -0.2172286591426597,
            -0.047666869057049185,
            0.1,
            0.1,
            0.1,
            0.1,
            0.09634753139490998,
            0.07105154519914889,
            0.010526723101565327,
            -0.0858127691365077,
            -0.20484576927159232,
            -0.32173986471763993,
            -0.40433785059963434,
            -0.42287133002272426,
            -0.4016538635613846,
            -0.3365578273051677,
        ],
    },
];

#[test]
fn friction_with_a_rigid_stop_meets_the_event_driven_simulation() {
    for case in &RIGID_STOP_CASES {
        let mut model = crate::friction::oscillator(case.c, case.omega, case.slip, None).model();
        model.contacts.push(Contact::on_dof(0, 1.0, case.gap, Compliance::Rigid));
        let period = 2.0 * std::f64::consts::PI / case.omega;
        let name = format!("c = {}, Ω = {}, μN = {}, stop at {}", case.c, case.omega, case.slip, case.gap);
        let (_, orbit, _) = polished(model, 256);
        let orbit = orbit.unwrap_or_else(|e| panic!("{name}: {e}"));
        let scale = case.x.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let err = (0..16).map(|j| (orbit.state(j as f64 * period / 16.0)[0] - case.x[j]).abs()).fold(0.0, f64::max) / scale;
        let stuck = (orbit.stuck_fraction(0) - case.stuck_fraction).abs();
        let kinds: Vec<String> = orbit.event_records().into_iter().map(|e| e.kind).collect();
        println!(
            "{name}: displacement error {err:.2e} of the largest |x|, resting fraction to {stuck:.1e}, {} events (simulation {}) {kinds:?}, Newton {} iterations",
            orbit.times.len(),
            case.events,
            orbit.iterations
        );
        assert!(err < 1e-8 && stuck < 1e-8, "{name}: error {err:.2e}, resting fraction {stuck:.2e}");
        // One more than the simulation's: the stop opens at λ = 0 before friction lets go at −μN.
        assert_eq!(orbit.times.len(), case.events + 1, "{name}: {kinds:?}");
    }
}
