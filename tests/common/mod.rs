pub mod compare;
pub mod family;
pub mod host;
pub mod stop_march;

/// A 2-DOF chain (m = 1, springs 2/−1, c = 0.1) forced on the first mass at Ω = 1.2, with a
/// compliant stop (gap 0.3, stiffness 20) on the second; cds, k = 256.
pub fn compliant_chain() -> periodic_contact::periodic::PeriodicProblem {
    let scene = r#"
[structure]
mass = [[1.0, 0.0], [0.0, 1.0]]
stiffness = [[2.0, -1.0], [-1.0, 2.0]]
[damping]
matrix = [[0.1, 0.0], [0.0, 0.1]]
[excitation]
frequency = 1.2
[[force]]
dof = 0
amplitude = 1.0
[[contact]]
dof = 1
gap = 0.3
stiffness = 20.0
[discretization]
scheme = "cds"
steps = 256
"#;
    periodic_contact::scene::Scene::parse(scene, "chain").unwrap().to_problem("chain").unwrap()
}
