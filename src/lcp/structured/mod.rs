//! Solvers and operators that use the structure of A instead of its entries.
//!
//! The period's LCP matrix is block-circulant (k blocks of m×m, m = number of contacts): products
//! cost O(m²·k log k) by FFT, and a banded or low-rank structure of the blocks could be used too.
//! This is the room for everything that exploits such structure:
//!
//! - operators: types implementing [`LcpMatrix`](super::LcpMatrix) with a fast `mul_into`
//!   ([`CirculantOperator`]); any solver written against the trait uses them unchanged;
//! - structured solver families: shooting on a step map (`step_map.rs`, `shooting.rs`: the LCP
//!   of a time-stepping scheme as the fixed point of its period map, O(k·(d² + d·m + |a|³)) per march; `step_lcp.rs` the step's LCP, `jacobian.rs` the
//!   period Jacobian by runs of one active set),
//!   and room for others (an active-block revised Lemke, say). A new family lives in its
//!   own file here, exposes `Settings` + `solve(&self, a, q) -> LcpSolution` like the general
//!   solvers, and is offered through a new [`LcpMethod`](super::LcpMethod) variant in
//!   `policy.rs` (and, if it should be tried automatically, a branch of the `auto` policy).
//!
//! Rules of the room: it depends on the rest of `lcp` (matrices, status) and on `crate::linalg`
//! only; hot paths own or receive their scratch buffers (nothing allocated per product or pivot).
mod circulant;
mod jacobian;
mod shooting;
mod step_lcp;
mod step_map;

pub use circulant::CirculantOperator;
pub use jacobian::product as dense_product;
pub use shooting::{ShootingOutcome, ShootingReach, ShootingSettings, ShootingSolution, solve_shooting};
pub use step_lcp::MAX_PAIRS;
pub use step_map::{DenseLu, StepMapData, StepMapError, StepMapLcp};
