//! The random 1–3-DOF oscillators the branch families draw (continuation.rs: compliant stops,
//! rigid_branch.rs: rigid stops): one generator and one chain, so both families draw alike.
use super::stop_march::StopChain;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;

/// A small deterministic generator (SplitMix64).
pub struct Draw(pub u64);
impl Draw {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// A grounded chain of 1–3 DOFs: masses 0.5–2, springs 0.5–2 (spring i joins DOF i to i − 1, DOF 0
/// to the ground), its first natural frequency ω₁.
#[derive(Clone)]
pub struct Chain {
    pub n: usize,
    pub mass: Vec<f64>,
    pub springs: Vec<f64>,
    pub stiffness: DMatrix<f64>,
    pub w1: f64,
}

impl Chain {
    pub fn draw(d: &mut Draw) -> Chain {
        let n = 1 + (d.next() * 3.0) as usize;
        let mass: Vec<f64> = (0..n).map(|_| d.range(0.5, 2.0)).collect();
        let springs: Vec<f64> = (0..n).map(|_| d.range(0.5, 2.0)).collect();
        let mut k = DMatrix::zeros(n, n);
        for (i, s) in springs.iter().enumerate() {
            k[(i, i)] += s;
            if i > 0 {
                k[(i - 1, i - 1)] += s;
                k[(i, i - 1)] -= s;
                k[(i - 1, i)] -= s;
            }
        }
        let minv = DMatrix::from_diagonal(&DVector::from_iterator(n, mass.iter().map(|x| 1.0 / x.sqrt())));
        let w1 = (&minv * &k * &minv).symmetric_eigen().eigenvalues.min().sqrt();
        Chain { n, mass, springs, stiffness: k, w1 }
    }

    /// |X_c(ω)| of the contact-free chain with C = αK under `amp` at `fdof`: (K − ω²M + iωC) X = f.
    pub fn linear_amplitude(&self, alpha: f64, fdof: usize, cdof: usize, amp: f64, w: f64) -> f64 {
        let (n, k) = (self.n, &self.stiffness);
        let a = DMatrix::from_fn(n, n, |r, c| C::new(k[(r, c)] - if r == c { w * w * self.mass[r] } else { 0.0 }, w * alpha * k[(r, c)]));
        let mut f = DVector::zeros(n);
        f[fdof] = C::new(amp, 0.0);
        a.lu().solve(&f).map_or(0.0, |x| x[cdof].norm())
    }

    /// The same oscillator for tests/common/stop_march.rs at 0.6·ω₁: C = αK, the force `amp` at
    /// `fdof`, a stop on `cdof` at `gap` (rigid without `contact_stiffness`).
    pub fn stop(&self, alpha: f64, (fdof, amp): (usize, f64), cdof: usize, gap: f64, contact_stiffness: Option<f64>) -> StopChain {
        StopChain {
            mass: self.mass.clone(),
            stiffness: self.stiffness.clone(),
            damping: &self.stiffness * alpha,
            force: (0..self.n).map(|i| if i == fdof { amp } else { 0.0 }).collect(),
            omega: 0.6 * self.w1,
            dof: cdof,
            gap,
            contact_stiffness,
        }
    }

    /// The scene: C = αK, the force `amp` at `fdof`, the `[[contact]]` body `contact`, output `cdof`, at 0.6·ω₁.
    pub fn scene(&self, alpha: f64, (fdof, amp): (usize, f64), contact: &str, scheme: &str, steps: usize, cdof: usize) -> String {
        let n = self.n;
        let row = |r: usize, a: &dyn Fn(usize, usize) -> f64| format!("[{}]", (0..n).map(|c| format!("{:e}", a(r, c))).collect::<Vec<_>>().join(", "));
        let mat = |a: &dyn Fn(usize, usize) -> f64| format!("[{}]", (0..n).map(|r| row(r, a)).collect::<Vec<_>>().join(", "));
        format!(
            "[structure]\nmass = {}\nstiffness = {}\n[damping]\nmatrix = {}\n[excitation]\nfrequency = {}\n[[force]]\ndof = {fdof}\namplitude = {amp}\n\
             [[contact]]\n{contact}[discretization]\nscheme = \"{scheme}\"\nsteps = {steps}\n[output]\ndisplacement = [{cdof}]\n",
            mat(&|r, c| if r == c { self.mass[r] } else { 0.0 }),
            mat(&|r, c| self.stiffness[(r, c)]),
            mat(&|r, c| alpha * self.stiffness[(r, c)]),
            0.6 * self.w1
        )
    }
}
