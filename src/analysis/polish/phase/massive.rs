//! The phase's massive coordinates, for the variation carried in them (polish/massive.rs): the
//! basis N_a the phase flows and the lift L = N_a + N_b S back to every DOF.
use super::Phase;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;

impl Phase {
    /// N_a (n × n_a, orthonormal columns): the massive free coordinates x_a = N_aᵀ x.
    pub fn massive_basis(&self) -> &DMatrix<f64> {
        &self.free
    }

    /// N_b (n × n_b, orthonormal columns): the massless free coordinates, condensed.
    pub fn massless_basis(&self) -> &DMatrix<f64> {
        &self.slave
    }

    /// L = N_a + N_b S (n × n_a): every DOF's displacement (velocity) from the massive
    /// coordinates' deviation from the particular solution (the stuck DOFs' rows zero, the
    /// massless DOFs' condensed, src/formulation.md §4.1); N_aᵀ L = I.
    pub fn lift(&self) -> DMatrix<f64> {
        self.lifted().clone()
    }

    /// [`Self::lift`], made once per phase (shared by its clones and re-tunings).
    pub fn lifted(&self) -> &DMatrix<f64> {
        self.lift.get_or_init(|| &*self.free + &*self.slave * &*self.slave_map)
    }

    /// e^{Ah} for the switch search's grid step `h` (detect/grid.rs), made once per phase for
    /// the first h asked (the same at every ω of a sweep while the phase's fastest rate exceeds ω).
    pub fn grid_step(&self, h: f64) -> DMatrix<f64> {
        let (h0, e) = self.grid_step.get_or_init(|| (h, self.exp(h)));
        if *h0 == h { e.clone() } else { self.exp(h) }
    }

    /// The rows `r` (m × n_a, on the massive displacements' deviation) on Â's modes: r V_x (the
    /// displacement rows are not balanced), so that r z(a + τ) = Re Σ_j (r V_x)_j c_j e^{λ_j τ}
    /// with c = [`Self::modal_coordinates`] of z(a). `None` without an eigendecomposition.
    pub fn rows_on_modes(&self, r: &DMatrix<f64>) -> Option<DMatrix<C>> {
        Some(self.eigen()?.rows_on_modes(r))
    }

    /// Â's eigenvalues and the modal coordinates c = V⁻¹ D⁻¹ z of the deviation z (see [`Self::exp`]).
    pub fn modal_coordinates(&self, z: &DVector<f64>) -> Option<(&[C], Vec<C>)> {
        let nf = self.free.ncols();
        let f = self.eigen()?;
        let mut u = z.clone();
        u.rows_mut(nf, nf).scale_mut(1.0 / self.speed);
        Some((f.eigenvalues(), f.coordinates(&u)))
    }
}
