//! The phase's massive coordinates, for the variation carried in them (polish/massive.rs): the
//! basis N_a the phase flows and the lift L = N_a + N_b S back to every DOF.
use super::Phase;
use nalgebra::DMatrix;

impl Phase {
    /// N_a (n × n_a, orthonormal columns): the massive free coordinates x_a = N_aᵀ x.
    pub fn massive_basis(&self) -> &DMatrix<f64> {
        &self.free
    }

    /// L = N_a + N_b S (n × n_a): every DOF's displacement (velocity) from the massive
    /// coordinates' deviation from the particular solution (the stuck DOFs' rows zero, the
    /// massless DOFs' condensed, src/formulation.md §4.1); N_aᵀ L = I.
    pub fn lift(&self) -> DMatrix<f64> {
        &self.free + &self.slave * &self.slave_map
    }
}
