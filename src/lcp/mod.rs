//! Linear complementarity problems: find z ≥ 0 with w = A z + q ≥ 0 and zᵀw = 0.
//!
//! This module knows nothing of mechanics: it may use `crate::linalg` (FFT plans) and
//! `crate::error`, nothing else of the crate. Matrices come through [`LcpMatrix`], so a solver
//! can work on a dense matrix or on a structured one ([`BlockCirculant`], [`CirculantOperator`])
//! without forming it.
//!
//! Map (each file depends only on those above it):
//! - `matrix.rs`: the [`LcpMatrix`] trait, [`DenseMatrix`], [`BlockCirculant`];
//! - `status.rs`: [`LcpOutcome`], [`LcpInfo`], [`LcpSolution`], [`residuals`] and the certification
//!   helpers every solver shares;
//! - `principal.rs`: LU solves of principal blocks A_αα, their conditioning, the basis polish;
//! - `structured/`: operators and solvers that use structure ([`CirculantOperator`]; the room
//!   for structured solver families);
//! - `lemke/`: lexicographic Lemke in revised form, and Lemke from a given basis (`lemke::warm`);
//! - `pivoting.rs`: block principal pivoting, finished by `lemke::warm`;
//! - `policy.rs`: which method solves a block-circulant LCP ([`LcpMethod`], `auto`);
//! - `io/`: Siconos' `.dat` format; `reference.rs`: brute-force enumeration for tests.
mod lemke;
mod matrix;
mod pivoting;
mod policy;
mod principal;
mod reference;
mod status;
mod structured;

pub mod io;

pub use io::dat;
pub use io::dat::{DatError, parse_dat, read_dat, write_dat};
/// Lemke from a given complementary basis (a coarse grid's prolonged active set, a pivoting's guess).
pub(crate) use lemke::warm::solve_from_basis;
pub use lemke::{Lemke, LemkeSettings};
pub use matrix::{BlockCirculant, DenseMatrix, LcpMatrix};
pub use pivoting::{BlockPivoting, PivotingSettings};
pub use policy::{
    AUTO_LEMKE_MAX, DENSE_FALLBACK_MAX_S, DENSE_MAX, DENSE_MEMORY_MAX, GIB, LEMKE_AFTER_SHOOTING_MAX, LEMKE_FLOPS_PER_S, LcpMethod, LcpMethodError,
    dense_fallback_allowed, dense_lemke_seconds, dense_memory, progress, set_progress, solve_circulant_lcp, solve_periodic_lcp, solve_periodic_lcp_with,
};
pub use reference::solve_by_enumeration;
pub use status::{LcpInfo, LcpOutcome, LcpSolution, LcpStep, WarmOutcome, residuals};
pub use structured::{
    CirculantOperator, DenseLu, MAX_PAIRS, ShootingOutcome, ShootingReach, ShootingSettings, ShootingSolution, StepMapData, StepMapError, StepMapLcp,
    dense_product, solve_shooting,
};
