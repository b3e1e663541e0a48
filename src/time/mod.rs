//! Discretisation of the period: k instants t_j = j·T/k on the circle, time derivatives as
//! circulant operators described by their DFT symbols (src/formulation.md §2).
mod scheme;
pub use scheme::{Pairing, Scheme, SchemeParseError, Symbols};

/// k and the scheme: everything that fixes the time grid and its operators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Discretization {
    pub scheme: Scheme,
    /// Number of instants k per period.
    pub steps: usize,
    /// `None`: the per-contact default that converges (forward for rigid under cds and galerkin,
    /// same otherwise).
    pub pairing: Option<Pairing>,
}
