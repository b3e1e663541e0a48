//! The built-in default scene: a damped oscillator against a rigid stop (src/formulation.md §6.3).
pub const DEFAULT_SCENE: &str = include_str!("../../../fmu/scenes/rigid-stop.toml");
