//! The solver session: one per scene and front end (CLI sweep, C API handle, FMU instance).
//!
//! In the spirit of Clarabel's `update_*` and faer's reusable factorisations: the session owns
//! the checked problem, the FFT plan of its k and the last solution's active set, and a change
//! of parameter updates them in place instead of rebuilding. A solve is warm-started from the
//! last active set when there is one; a warm start that fails is retried cold, so the warm
//! start can only save pivots, never change whether a solution is found.
use super::cache::{AssemblyCache, assembled};
use super::{PeriodFft, PeriodicProblem, SolveError};
use crate::response::{Response, WarmStartSummary};
use crate::time::Discretization;

/// How the last solve started.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WarmStart {
    /// No previous active set (first solve, new grid, or warm starts off).
    #[default]
    Cold,
    /// Started from the previous active set and solved from there.
    Used,
    /// The warm-started solve failed and the cold retry solved it.
    ColdFallback,
}

/// A problem with its caches, updated in place.
#[derive(Clone, Debug)]
pub struct PeriodicSolver {
    problem: PeriodicProblem,
    fft: PeriodFft,
    /// Active set of the last certified solution, the next warm start (`None`: start cold; an
    /// empty set is a guess too: no contact active).
    warm_start: Option<Vec<usize>>,
    /// The orbit state the next warm shooting try starts from (another grid's answer carried
    /// here, [`Self::set_warm_state`]); that try alone reads it.
    warm_state: Option<Vec<f64>>,
    warm_starts: bool,
    last_start: WarmStart,
    /// The last assembly, reused while only gaps, motions or a common force scale change.
    pub(super) cache: Option<AssemblyCache>,
    /// Assemblies built by this session (the others were reused).
    assemblies: usize,
    /// Shooting tries that failed on this problem ([`Self::solve_by_shooting_with`]), newest
    /// last; cleared when anything but ω changes.
    misses: Vec<(Try, SolveError)>,
}

/// One shooting try of a session: ω (its bits), the warm start it started from (none: cold),
/// and whether a cold try may follow the offset homotopy.
#[derive(Clone, Debug, PartialEq)]
struct Try {
    frequency: u64,
    warm: Option<Vec<usize>>,
    homotopy: bool,
}

/// Failed tries a session remembers (a guarded sweep's sub-steps across a fold repeat a few).
const MISSES_KEPT: usize = 32;

impl PeriodicSolver {
    /// Plans the FFT of the problem's k; the first solve is cold.
    pub fn new(problem: PeriodicProblem) -> Self {
        let fft = PeriodFft::new(problem.instants());
        PeriodicSolver {
            problem,
            fft,
            warm_start: None,
            warm_state: None,
            warm_starts: true,
            last_start: WarmStart::Cold,
            cache: None,
            assemblies: 0,
            misses: Vec::new(),
        }
    }

    /// Whether solves start from the previous active set (default true).
    pub fn with_warm_starts(mut self, on: bool) -> Self {
        self.warm_starts = on;
        self
    }

    pub fn problem(&self) -> &PeriodicProblem {
        &self.problem
    }
    /// The FFT plan of the current k (shared by assembly, recovery and spectra).
    pub fn fft(&self) -> &PeriodFft {
        &self.fft
    }
    /// The warm start of the next solve (indices into the LCP's z): the last solution's active
    /// set, or one given by [`PeriodicSolver::set_warm_start`]; `None` before the first solve.
    pub fn warm_start(&self) -> Option<&[usize]> {
        self.warm_start.as_deref()
    }
    /// How the last solve started.
    pub fn last_start(&self) -> WarmStart {
        self.last_start
    }

    /// Assemblies this session has built; a solve after [`Self::update_gaps`] or a common scale
    /// of [`Self::update_forces`] reuses the last one.
    pub fn assemblies(&self) -> usize {
        self.assemblies
    }

    /// Sets each contact's static clearance (model order). Gaps enter only the LCP's q: the next
    /// solve re-uses the assembly and starts from the last active set.
    pub fn update_gaps(&mut self, gaps: &[f64]) -> Result<(), SolveError> {
        let mut model = self.problem.model().clone();
        if gaps.len() != model.contacts.len() {
            return Err(SolveError::Invalid(format!("update_gaps: {} gaps for {} contacts", gaps.len(), model.contacts.len())));
        }
        model.contacts.iter_mut().zip(gaps).for_each(|(c, &g)| c.gap = g);
        self.problem = self.problem.with_model(model, self.problem.discretization())?;
        self.misses.clear();
        Ok(())
    }

    /// Sets each force term's amplitude (model order). Multiplying every amplitude by one factor
    /// re-uses the assembly (the contact-free response is linear in the forces); any other
    /// change re-assembles at the next solve.
    pub fn update_forces(&mut self, amplitudes: &[f64]) -> Result<(), SolveError> {
        let mut model = self.problem.model().clone();
        if amplitudes.len() != model.forces.len() {
            return Err(SolveError::Invalid(format!("update_forces: {} amplitudes for {} forces", amplitudes.len(), model.forces.len())));
        }
        model.forces.iter_mut().zip(amplitudes).for_each(|(f, &a)| f.term.amplitude = a);
        self.problem = self.problem.with_model(model, self.problem.discretization())?;
        self.misses.clear();
        Ok(())
    }

    /// Changes ω; the active set is kept as the next warm start (a neighbouring orbit).
    pub fn update_frequency(&mut self, frequency: f64) -> Result<(), SolveError> {
        self.problem.set_frequency(frequency)
    }

    /// Changes the grid: a new k re-plans the FFT and drops the active set, which indexes
    /// the old grid.
    pub fn update_discretization(&mut self, disc: Discretization) -> Result<(), SolveError> {
        let old_k = self.problem.instants();
        self.problem.set_discretization(disc)?;
        self.replan(old_k);
        Ok(())
    }

    /// Seeks orbits of p forcing periods ([`PeriodicProblem::set_period_multiple`]); a new p
    /// re-plans the FFT and drops the active set, like a new k.
    pub fn update_period_multiple(&mut self, p: usize) -> Result<(), SolveError> {
        let old_k = self.problem.instants();
        self.problem.set_period_multiple(p)?;
        self.replan(old_k);
        Ok(())
    }

    /// After a change of the grid from `old_k` instants: a new plan, and no warm start.
    fn replan(&mut self, old_k: usize) {
        self.misses.clear();
        if self.problem.instants() != old_k {
            self.fft = PeriodFft::new(self.problem.instants());
            self.warm_start = None;
        }
    }

    /// Replaces the problem (a new model or tuning); the plan is kept when k is the same, and the
    /// active set when the LCP has the same size (same k and number of contacts).
    pub fn update_problem(&mut self, problem: PeriodicProblem) {
        let (k0, m0) = (self.problem.instants(), self.problem.model().contacts.len());
        let (k, m) = (problem.instants(), problem.model().contacts.len());
        if k != k0 {
            self.fft = PeriodFft::new(k);
        }
        if (k, m) != (k0, m0) {
            self.warm_start = None;
        }
        self.problem = problem;
        self.misses.clear();
    }

    /// Forgets the active set: the next solve is cold.
    pub fn reset_warm_start(&mut self) {
        self.warm_start = None;
    }

    /// Sets the warm start of the next solve (indices into the LCP's z, e.g. a neighbour's).
    pub fn set_warm_start(&mut self, active_set: &[usize]) {
        let w = self.warm_start.get_or_insert_with(Vec::new);
        w.clear();
        w.extend_from_slice(active_set);
    }

    /// The orbit state (s_0 of the step map, [`crate::periodic::carried_state`]) the next warm
    /// shooting try ([`Self::solve_by_shooting_with`]) starts Newton from, with the warm sets,
    /// before their frozen fixed point; read by that try alone. Why: a sweep's refinement of a
    /// point has its orbit on the coarser grid, and the fixed point costs a march and a period
    /// Jacobian (issue 23).
    pub fn set_warm_state(&mut self, state: Option<Vec<f64>>) {
        self.warm_state = state;
    }

    /// Solves, warm-started from the last active set when there is one, cold if that fails.
    /// The active set of the answer becomes the next warm start.
    pub fn solve(&mut self) -> Result<Response, SolveError> {
        self.warm_state = None;
        let guess = self.warm_start.as_deref().filter(|_| self.warm_starts);
        let warm = guess.is_some();
        let result = if let Some(guess) = guess {
            let guess = guess.to_vec();
            match self.solve_cached(Some(&guess)) {
                Ok(r) => Ok((r, WarmStart::Used)),
                Err(_) => self.solve_cached(None).map(|r| (r, WarmStart::ColdFallback)),
            }
        } else {
            self.solve_cached(None).map(|r| (r, WarmStart::Cold))
        };
        match result {
            Ok((mut r, start)) => {
                if start == WarmStart::ColdFallback {
                    // The warm-started solve failed; the answer is the cold retry's.
                    r.lcp.warm_start = WarmStartSummary { outcome: "rejected".to_string(), pivots: r.lcp.pivots };
                    r.lcp.warm_start_used = false;
                }
                self.last_start = start;
                self.set_warm_start(&r.active_set);
                Ok(r)
            }
            Err(e) => {
                self.last_start = if warm { WarmStart::ColdFallback } else { WarmStart::Cold };
                Err(e)
            }
        }
    }

    /// Solves by shooting alone (`solver.method = "shooting"` for this solve): from the warm
    /// start when `warm` and there is one, else cold; no cold retry and no dense fallback. A
    /// failure costs one shooting budget (seconds), where the dense fallback of a large LCP costs
    /// minutes: a sweep's quick try before it sub-steps ω. A warm try is Newton from the warm
    /// start alone (no contact-free start nor offset homotopy: those are the cold try's). The
    /// answer's active set becomes the next warm start, as in [`Self::solve`].
    pub fn solve_by_shooting(&mut self, warm: bool) -> Result<Response, SolveError> {
        self.solve_by_shooting_with(warm, true)
    }

    /// [`Self::solve_by_shooting`]; `homotopy` off: a cold try ends where Newton from the
    /// contact-free orbit misses (no offset homotopy, which can cost seconds). A try this session
    /// already missed (the same ω, warm start and homotopy on the same problem) returns its error
    /// at once: shooting is deterministic, and a guarded sweep's sub-steps past a fold repeat
    /// failed tries (issue 23: a third of the real blade's fold tries).
    pub fn solve_by_shooting_with(&mut self, warm: bool, homotopy: bool) -> Result<Response, SolveError> {
        let settings = self.problem.solver_settings().clone();
        let guess = self.warm_start.clone().filter(|_| warm && self.warm_starts);
        let state = self.warm_state.take().filter(|_| guess.is_some());
        let attempt = Try { frequency: self.problem.model().frequency.to_bits(), warm: guess.clone(), homotopy };
        if let Some((_, e)) = self.misses.iter().find(|(t, _)| *t == attempt) {
            return Err(e.clone());
        }
        let quick = super::SolverSettings {
            method: crate::lcp::LcpMethod::Shooting,
            shooting_warm_only: guess.is_some(),
            shooting_homotopy: homotopy,
            shooting_state: state,
            ..settings.clone()
        };
        self.problem.set_solver_settings(quick)?;
        let result = self.solve_cached(guess.as_deref());
        self.problem.set_solver_settings(settings)?;
        if let Err(e) = &result {
            if self.misses.len() == MISSES_KEPT {
                self.misses.remove(0);
            }
            self.misses.push((attempt, e.clone()));
        }
        let r = result?;
        self.last_start = if guess.is_some() { WarmStart::Used } else { WarmStart::Cold };
        self.set_warm_start(&r.active_set);
        Ok(r)
    }

    /// One solve on the session's assembly (built or re-used).
    fn solve_cached(&mut self, warm_start: Option<&[usize]>) -> Result<Response, SolveError> {
        let t_start = std::time::Instant::now();
        let (asm, built) = assembled(&mut self.cache, &self.problem, &self.fft)?;
        self.assemblies += usize::from(built);
        self.problem.solve_assembled(asm, &self.fft, warm_start, t_start)
    }

    /// Solves cold, whatever the active set (the reference of a warm-start comparison).
    pub fn solve_cold(&mut self) -> Result<Response, SolveError> {
        let r = self.solve_cached(None)?;
        self.last_start = WarmStart::Cold;
        self.set_warm_start(&r.active_set);
        Ok(r)
    }
}
