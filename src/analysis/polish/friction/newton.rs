//! One damped Newton for the stick–slip polish, one contact or several (argmin-style: a problem
//! gives the residual and the finite-difference scales; the solver has `init`, `step` and
//! `terminate`). The unknowns are a state and the event times; the residual is periodicity, one
//! condition per event and, for several contacts, the pins of contacts stuck all period (then
//! over-determined: least squares).
use nalgebra::{DMatrix, DVector};

/// A shooting problem: residual r(u) over the unknowns u.
pub trait Shooting {
    /// The residual at `u`.
    fn residual(&self, u: &DVector<f64>) -> DVector<f64>;

    /// The size below which unknown `c` is not resolved (1 for a state, the period for a time):
    /// the finite-difference step is 1e-7 · max(|u_c|, scale).
    fn scale(&self, c: usize) -> f64;

    /// The Jacobian at `u` (residual `r0` there) by forward differences.
    fn jacobian(&self, u: &DVector<f64>, r0: &DVector<f64>) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(r0.len(), u.len());
        for c in 0..u.len() {
            let h = 1e-7 * u[c].abs().max(self.scale(c));
            let mut up = u.clone();
            up[c] += h;
            j.set_column(c, &((self.residual(&up) - r0) / h));
        }
        j
    }
}

/// Why Newton stopped without an orbit.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NewtonFailure {
    #[error("singular Newton matrix: an event grazes")]
    Singular,
    #[error("Newton did not converge in {MAX_ITERATIONS} iterations, last correction {0:.2e}")]
    NotConverged(f64),
}

/// Iterations at most.
pub const MAX_ITERATIONS: usize = 40;
/// Halvings of a step that raises the residual, before the full step is taken anyway (event
/// times can make the residual locally rough; the undamped step is what converged before).
const HALVINGS: usize = 4;

/// The iteration: unknowns, their residual, and the last full correction.
#[derive(Clone, Debug)]
pub struct Newton {
    pub u: DVector<f64>,
    pub r: DVector<f64>,
    pub iterations: usize,
    pub correction: f64,
}

/// J du = −r: LU when square, else least squares by SVD (pinned rows make a stuck contact's
/// constant unique), singular values below 1e-13 of the largest dropped.
pub fn solve_step(j: &DMatrix<f64>, r: &DVector<f64>) -> Option<DVector<f64>> {
    if j.nrows() == j.ncols() {
        return j.clone().lu().solve(&(-r));
    }
    let svd = j.clone().svd(true, true);
    let tol = 1e-13 * svd.singular_values.max();
    svd.solve(&(-r), tol).ok()
}

impl Newton {
    pub fn init(problem: &impl Shooting, u: DVector<f64>) -> Self {
        let r = problem.residual(&u);
        Newton { u, r, iterations: 0, correction: f64::INFINITY }
    }

    /// One Newton step, halved while that lowers a residual the full step would raise.
    pub fn step(&mut self, problem: &impl Shooting) -> Result<(), NewtonFailure> {
        let j = problem.jacobian(&self.u, &self.r);
        let du = solve_step(&j, &self.r).ok_or(NewtonFailure::Singular)?;
        let norm = self.r.norm();
        let full = &self.u + &du;
        let r_full = problem.residual(&full);
        let (mut u, mut r) = (full, r_full);
        if !(r.norm() <= norm) {
            let damped =
                (1..=HALVINGS).map(|h| 0.5f64.powi(h as i32)).map(|l| &self.u + &du * l).map(|u| (problem.residual(&u), u)).find(|(r, _)| r.norm() < norm);
            if let Some((rd, ud)) = damped {
                (u, r) = (ud, rd);
            }
        }
        (self.u, self.r) = (u, r);
        self.iterations += 1;
        self.correction = du.amax();
        Ok(())
    }

    /// Converged: the last full correction is round-off relative to the unknowns.
    pub fn terminate(&self) -> bool {
        self.correction <= 1e-13 * self.u.amax().max(f64::MIN_POSITIVE)
    }

    /// Iterates from `u` until [`Newton::terminate`], at most [`MAX_ITERATIONS`] steps.
    pub fn run(problem: &impl Shooting, u: DVector<f64>) -> Result<Self, NewtonFailure> {
        let mut newton = Newton::init(problem, u);
        while newton.iterations < MAX_ITERATIONS {
            newton.step(problem)?;
            if newton.terminate() {
                return Ok(newton);
            }
        }
        Err(NewtonFailure::NotConverged(newton.correction))
    }
}
