//! Reading and writing LCPs in exchange formats (no solver, no mechanics).
pub mod dat;
