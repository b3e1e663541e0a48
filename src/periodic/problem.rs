//! The checked problem: a model with its discretisation, outputs and solver settings. Fields are
//! private: every way in (constructor, updaters) runs the checks, so a `PeriodicProblem` is
//! always ready to solve.
use super::{Assembly, OutputMap, OutputSelection, PeriodFft, SolveError, SolverSettings, assembly, lcp_failure, limits, recovery};
use crate::lcp::{
    BlockCirculant, DENSE_MAX, DENSE_MEMORY_MAX, GIB, LcpMethod, LcpOutcome, LcpSolution, dense_fallback_allowed, dense_memory, solve_periodic_lcp_with,
};
use crate::model::{Contact, Model};
use crate::response::Response;
use crate::time::{Discretization, Pairing};
use std::time::Instant;

/// A model with its discretisation, outputs and solver settings, checked and ready to solve.
#[derive(Clone, Debug)]
pub struct PeriodicProblem {
    model: Model,
    disc: Discretization,
    outputs: OutputSelection,
    solver: SolverSettings,
    /// `Some`: `outputs` are user DOFs (labels), computed through the map.
    output_map: Option<OutputMap>,
    /// ω_max of the model as solved ([`Model::omega_max`]), cached: it depends on neither ω nor k.
    omega_max: f64,
    /// `Some(note)`: k was chosen by `steps = "auto"` (the note says how).
    auto_steps: Option<String>,
    /// Per-contact pairing overrides (index = contact; empty: none), over `disc.pairing`.
    contact_pairing: Vec<Option<Pairing>>,
    /// p: the orbit's period is p·T, discretised by p·k instants (k = `disc.steps` per forcing
    /// period); the forcing keeps ω (harmonic p of the base 2π/(pT)).
    period_multiple: usize,
    /// Each contact's gap samples on the grid, computed once ([`super::gaps`]).
    pub(super) gaps: super::gaps::GapSamples,
}

/// Fewest instants per period that any scheme needs.
pub const MIN_STEPS: usize = 4;
/// Most instants per period we accept (memory of the recovery grows like k·outputs).
pub const MAX_STEPS: usize = 1 << 22;
/// Largest LCP accepted, k·m unknowns. Why: shooting needs O(k·(d² + m)) memory, but the
/// recovery stores k samples of every output and the FFT assembly k/2 blocks of m²; 2^20 keeps
/// that within a few hundred MiB. The dense methods stop at [`DENSE_MAX`] (their B⁻¹ or LU of the
/// active block can need N² numbers): a problem without a step map (fourier, a large model) is
/// refused above it when it is solved, with the reason.
pub const MAX_LCP_SIZE: usize = 1 << 20;
/// Most floating-point operations the dense assembly may cost, ≈ (k/2+1)·(8/3)·n³ (one complex LU
/// per distinct harmonic). Why: a 5000×5000 dense model at k = 256 would take hours; it must be
/// refused at once with a remedy, not attempted. 10¹² is a few minutes on one core
/// (n = 1000 at k = 256 is 3.4·10¹¹ and accepted).
pub const MAX_DENSE_FLOPS: f64 = 1e12;

impl PeriodicProblem {
    /// Contact `a`'s row of B in the user's numbering: the output map's, else the model's own.
    pub fn user_row(&self, a: usize) -> &[(usize, f64)] {
        self.output_map().and_then(|m| m.contact_row(a)).unwrap_or(&self.model().contacts[a].row)
    }

    /// Checks everything, the scheme's stability limit included ([`crate::time::Scheme::stability_limit`]).
    pub fn new(model: Model, disc: Discretization, outputs: OutputSelection, solver: SolverSettings) -> Result<Self, SolveError> {
        Self::build(model, disc, outputs, solver, None, None)
    }

    /// [`PeriodicProblem::new`] with k chosen by `steps = "auto"` ([`limits::auto_steps`]) at the
    /// model's frequency; `disc.steps` is ignored. The choice is reported in [`Self::warnings`].
    pub fn new_auto(model: Model, disc: Discretization, outputs: OutputSelection, solver: SolverSettings) -> Result<Self, SolveError> {
        model.validate()?;
        let omega_max = model.omega_max()?;
        let (steps, note) = limits::auto_steps(&model, disc.scheme, omega_max, model.frequency);
        Self::build(model, Discretization { steps, ..disc }, outputs, solver, Some(omega_max), Some(note))
    }

    fn build(
        model: Model,
        disc: Discretization,
        outputs: OutputSelection,
        solver: SolverSettings,
        omega_max: Option<f64>,
        auto_steps: Option<String>,
    ) -> Result<Self, SolveError> {
        // Size limits first: they are O(1), the validation below factorises M.
        check_sizes(&model, &disc, 1)?;
        model.validate()?;
        check_grid(&model, &disc)?;
        check_solver(&solver)?;
        check_outputs(&outputs, model.n())?;
        let omega_max = match omega_max {
            Some(w) => w,
            None => model.omega_max()?,
        };
        limits::check_stability(&model, &disc, omega_max)?;
        Ok(PeriodicProblem {
            model,
            disc,
            outputs,
            solver,
            output_map: None,
            omega_max,
            auto_steps,
            contact_pairing: Vec::new(),
            period_multiple: 1,
            gaps: Default::default(),
        })
    }

    /// The orbit's period in forcing periods, p (1: T-periodic).
    pub fn period_multiple(&self) -> usize {
        self.period_multiple
    }

    /// The discretised period p·T [s].
    pub fn period(&self) -> f64 {
        self.period_multiple as f64 * self.model.period()
    }

    /// Instants of the discretised period, p·k.
    pub fn instants(&self) -> usize {
        self.disc.steps * self.period_multiple
    }

    /// Seeks orbits of period p·T (p = 1: T-periodic), k steps per forcing period; checked
    /// (p ≥ 1, p·k within the size limits), unchanged on error.
    pub fn set_period_multiple(&mut self, p: usize) -> Result<(), SolveError> {
        if p == 0 {
            return Err(SolveError::Invalid(
                "discretization.period_multiple: is 0, must be a whole number of forcing periods ≥ 1 (1: T-periodic orbits, 2: period doubled, …)".to_string(),
            ));
        }
        check_sizes(&self.model, &self.disc, p)?;
        self.period_multiple = p;
        Ok(())
    }

    /// ω_max [rad/s] of the model as solved (compliant contacts closed), the bound of the
    /// schemes' stability limits.
    pub fn omega_max(&self) -> f64 {
        self.omega_max
    }

    /// Whether k was chosen by `steps = "auto"`.
    pub fn steps_auto(&self) -> bool {
        self.auto_steps.is_some()
    }

    /// With `steps = "auto"`, chooses k again for `frequency` and moves the problem there (a
    /// sweep passes its lowest frequency, the largest h, so that every point shares one k);
    /// unchanged otherwise or on error.
    pub fn fit_auto_steps(&mut self, frequency: f64, why: &str) -> Result<(), SolveError> {
        if self.auto_steps.is_none() {
            return Ok(());
        }
        let old = std::mem::replace(&mut self.model.frequency, frequency);
        let (steps, note) = limits::auto_steps(&self.model, self.disc.scheme, self.omega_max, frequency);
        let fitted = self.model.validate_frequency().map_err(SolveError::from).and_then(|()| self.set_discretization(Discretization { steps, ..self.disc }));
        if fitted.is_err() {
            self.model.frequency = old;
        }
        fitted?;
        self.auto_steps = Some(format!("{note}, {why}"));
        Ok(())
    }

    pub fn model(&self) -> &Model {
        &self.model
    }
    pub fn discretization(&self) -> Discretization {
        self.disc
    }
    pub fn outputs(&self) -> &OutputSelection {
        &self.outputs
    }
    pub fn solver_settings(&self) -> &SolverSettings {
        &self.solver
    }
    /// `Some` when the outputs are named in the user's numbering (clamped or reduced model).
    pub fn output_map(&self) -> Option<&OutputMap> {
        self.output_map.as_ref()
    }

    /// The same outputs, settings and output map over another model with the same DOFs and
    /// grid `disc` (a tuned copy: other frequency, loads or gaps), checked again.
    pub fn with_model(&self, model: Model, disc: Discretization) -> Result<Self, SolveError> {
        // ω_max depends on M, K and the contact stiffnesses only: reuse it when they are the same.
        let omega_max = same_spectrum(&self.model, &model).then_some(self.omega_max);
        let auto = self.auto_steps.clone().filter(|_| disc.steps == self.disc.steps);
        let mut p = PeriodicProblem::build(model, disc, OutputSelection::default(), self.solver.clone(), omega_max, auto)?;
        p.set_period_multiple(self.period_multiple)?;
        // The overrides follow the contacts by index (a contact added later has none).
        p.contact_pairing = self.contact_pairing.iter().copied().take(p.model.contacts.len()).collect();
        match &self.output_map {
            None => p.set_outputs(self.outputs.clone())?,
            Some(map) => p = p.with_output_map(self.outputs.clone(), map.clone())?,
        }
        Ok(p)
    }

    /// Changes ω [rad/s], checked as [`PeriodicProblem::new`] would; unchanged on error.
    pub fn set_frequency(&mut self, frequency: f64) -> Result<(), SolveError> {
        let old = std::mem::replace(&mut self.model.frequency, frequency);
        let checked = self
            .model
            .validate_frequency()
            .map_err(SolveError::from)
            .and_then(|()| check_grid(&self.model, &self.disc))
            .and_then(|()| limits::check_stability(&self.model, &self.disc, self.omega_max));
        if checked.is_err() {
            self.model.frequency = old;
        }
        checked
    }

    /// Changes the scheme, k or the pairing, checked; unchanged on error.
    pub fn set_discretization(&mut self, disc: Discretization) -> Result<(), SolveError> {
        check_sizes(&self.model, &disc, self.period_multiple)?;
        check_grid(&self.model, &disc)?;
        limits::check_stability(&self.model, &disc, self.omega_max)?;
        if disc.steps != self.disc.steps {
            self.auto_steps = None;
        }
        self.disc = disc;
        Ok(())
    }

    /// The pairing of every contact (`None`: each contact's default).
    pub fn set_pairing(&mut self, pairing: Option<Pairing>) {
        self.disc.pairing = pairing;
    }

    /// Whether the harmonics are factorised in parallel (rayon). Off inside an FMU or a sweep
    /// that is itself parallel.
    pub fn set_parallel(&mut self, parallel: bool) {
        self.solver.parallel = parallel;
    }

    /// Changes the solver settings, checked; unchanged on error.
    pub fn set_solver_settings(&mut self, solver: SolverSettings) -> Result<(), SolveError> {
        check_solver(&solver)?;
        self.solver = solver;
        Ok(())
    }

    /// Changes the outputs (model DOFs, or labels of the output map when there is one).
    pub fn set_outputs(&mut self, outputs: OutputSelection) -> Result<(), SolveError> {
        match &self.output_map {
            None => check_outputs(&outputs, self.model.n())?,
            Some(map) => {
                if let Some(d) = outputs.dofs().into_iter().find(|d| !map.rows.contains_key(d)) {
                    return Err(SolveError::Invalid(format!("output: DOF {d} cannot be recovered (it is fixed or does not exist)")));
                }
            }
        }
        self.outputs = outputs;
        Ok(())
    }

    /// Names the outputs in the user's numbering: `outputs` lists labels of `map`.
    pub fn with_output_map(mut self, outputs: OutputSelection, map: OutputMap) -> Result<Self, SolveError> {
        let n = self.model.n();
        if let Some(d) = outputs.dofs().into_iter().find(|d| !map.rows.contains_key(d)) {
            return Err(SolveError::Invalid(format!("output: DOF {d} cannot be recovered (it is fixed or does not exist)")));
        }
        if let Some((l, _)) = map.rows.iter().find(|(_, r)| r.iter().any(|&(d, c)| d >= n || !c.is_finite())) {
            return Err(SolveError::Invalid(format!("output: the recovery of DOF {l} names a model DOF out of 0..{n} or a non-finite coefficient")));
        }
        if !map.contact_rows.is_empty() && map.contact_rows.len() != self.model.contacts.len() {
            return Err(SolveError::Invalid(format!("output: {} contact labels for {} contacts", map.contact_rows.len(), self.model.contacts.len())));
        }
        self.outputs = outputs;
        self.output_map = Some(map);
        Ok(self)
    }

    /// The outputs to recover, sorted by label: each with its (model DOF, coefficient) terms (a
    /// DOF alone without an output map).
    pub(super) fn recovery_rows(&self) -> Vec<assembly::RecoveryRow> {
        match &self.output_map {
            None => assembly::unit_rows(&self.outputs.dofs()),
            Some(map) => self.outputs.dofs().into_iter().map(|l| (l, map.rows[&l].clone())).collect(),
        }
    }

    /// Overrides the pairing of contact `i` (`None`: back to the global pairing or the
    /// scheme's default); checked index, unchanged on error.
    pub fn set_contact_pairing(&mut self, i: usize, pairing: Option<Pairing>) -> Result<(), SolveError> {
        let m = self.model.contacts.len();
        if i >= m {
            return Err(SolveError::Invalid(format!("contact pairing: contact {i} does not exist ({m} contacts)")));
        }
        self.contact_pairing.resize(m, None);
        self.contact_pairing[i] = pairing;
        Ok(())
    }

    /// The override of contact `i`, if any (`None` also for an index out of range).
    pub fn contact_pairing(&self, i: usize) -> Option<Pairing> {
        self.contact_pairing.get(i).copied().flatten()
    }

    /// The pairing of contact `i`: its override, else the global pairing, else the scheme's
    /// default that converges for it.
    pub fn pairing_at(&self, i: usize) -> Pairing {
        match (self.contact_pairing(i), self.disc.pairing, self.model.contacts.get(i)) {
            (Some(p), _, _) | (None, Some(p), _) => p,
            (None, None, c) => self.disc.scheme.default_pairing(c.is_some_and(|c| self.impacts(c))),
        }
    }

    /// The pairing of one contact of this problem's model ([`Self::pairing_at`]); a contact
    /// not borrowed from [`Self::model`] gets the global pairing or the scheme's default.
    pub fn pairing_of(&self, c: &Contact) -> Pairing {
        match self.model.contacts.iter().position(|x| std::ptr::eq(x, c)) {
            Some(i) => self.pairing_at(i),
            None => self.disc.pairing.unwrap_or_else(|| self.disc.scheme.default_pairing(self.impacts(c))),
        }
    }

    /// A rigid contact on a DOF with mass: its force is an impulse at impacts. On a massless DOF
    /// (src/formulation.md §4.1) the force is finite and statically transmitted, like a
    /// compliant one, and same-instant pairing is the consistent one.
    fn impacts(&self, c: &Contact) -> bool {
        c.is_rigid() && !self.model.contact_is_massless(c)
    }

    /// Warnings about choices that do not converge, said before solving.
    pub fn warnings(&self) -> Vec<String> {
        let mut w: Vec<String> = self.auto_steps.iter().cloned().collect();
        for (i, c) in self.model.contacts.iter().enumerate() {
            let p = self.pairing_of(c);
            if self.impacts(c) {
                if let Some(why) = self.disc.scheme.rigid_contact_warning(p) {
                    w.push(format!("contact[{i}] (rigid, {} with pairing {p}): {why}", self.disc.scheme));
                }
            } else if p == Pairing::Forward {
                let kind = if c.is_rigid() { "rigid on a massless DOF" } else { "compliant" };
                w.push(format!(
                    "contact[{i}] ({kind}): forward pairing makes its finite force lag one step, so the scheme is first order only; use pairing = \"same\""
                ));
            }
        }
        w
    }

    /// Solves with a fresh FFT plan and no warm start.
    pub fn solve(&self) -> Result<Response, SolveError> {
        self.solve_with(&PeriodFft::new(self.instants()), None)
    }

    /// Solves reusing `fft` (planned for [`Self::instants`]), warm-started from a previous active set.
    pub fn solve_with(&self, fft: &PeriodFft, warm_start: Option<&[usize]>) -> Result<Response, SolveError> {
        let t_start = Instant::now();
        let asm = self.assemble(fft)?;
        self.solve_assembled(&asm, fft, warm_start, t_start)
    }

    /// The harmonic solves of this problem (Ĝ, X̂lin and Ẑ⁻¹Bᵀ at the recovered DOFs).
    pub(super) fn assemble(&self, fft: &PeriodFft) -> Result<Assembly, SolveError> {
        self.assemble_with(fft, &assembly::StructureOperator::new(&self.model)?)
    }

    /// [`Self::assemble`] on the structure operator of this problem's M, C, K built before (a
    /// session keeps it across frequencies and grids).
    pub(super) fn assemble_with(&self, fft: &PeriodFft, op: &assembly::StructureOperator) -> Result<Assembly, SolveError> {
        self.assemble_reusing(fft, op, &mut assembly::ModalProducts::default())
    }

    /// [`Self::assemble_with`] into a session's kept products ([`assembly::ModalProducts`]).
    pub(super) fn assemble_reusing(
        &self,
        fft: &PeriodFft,
        op: &assembly::StructureOperator,
        products: &mut assembly::ModalProducts,
    ) -> Result<Assembly, SolveError> {
        // Friction contacts ride as extra rows of B (src/formulation.md §9).
        let model = super::friction::with_rows(&self.model)?;
        // Rubbing contacts' tangential rows too, folded into their contacts' columns.
        let model = super::rubbing::with_rows(&model);
        let wide = assembly::assemble_with(&model, op, self.disc.scheme, self.period(), &self.recovery_rows(), fft, self.solver.parallel, products)?;
        Ok(super::rubbing::fold(&self.model, wide))
    }

    /// Solves with an assembly of this problem (a session's cached one); `t_start`: when the
    /// solve began, for the timings.
    pub(super) fn solve_assembled(&self, asm: &Assembly, fft: &PeriodFft, warm_start: Option<&[usize]>, t_start: Instant) -> Result<Response, SolveError> {
        if !self.model.frictions.is_empty() {
            return super::friction::solve(self, asm, fft, t_start);
        }
        let (a, q) = self.lcp(asm, fft);
        self.check_lcp_finite(&a, &q)?;
        let t_assembly = t_start.elapsed().as_secs_f64();

        let t_lcp = Instant::now();
        // A cold solve of a stiff model with rigid impacts starts from a coarse bds1 pilot's sets.
        let pilot = warm_start.is_none().then(|| super::pilot::warm_start(self)).flatten();
        // A cold solve whose shooting misses: a bds1 pilot's sets before the dense fallbacks.
        let after_miss = (warm_start.is_none() && pilot.is_none()).then(|| super::pilot::solve_after_cold_miss(self, &a, &q)).flatten();
        let (sol, walked) = match after_miss {
            Some(solved) => solved?,
            None => super::rubbing::solve_lcp(self, fft, &a, &q, warm_start.or(pilot.as_ref().map(|p| p.0.as_slice())))?,
        };
        let t_lcp = t_lcp.elapsed().as_secs_f64();
        super::rubbing::check_gross_slip(self, asm, fft, &sol.z)?;

        let t_rec = Instant::now();
        let mut response = recovery::recover(self, asm, fft, &sol)?;
        response.timing_s.assembly = t_assembly;
        response.timing_s.lcp = t_lcp;
        response.timing_s.recovery = t_rec.elapsed().as_secs_f64();
        if let Some((_, k)) = pilot {
            // The caller gave no warm start: say where the sets came from, not "warm start used".
            response.lcp.warm_start_used = false;
            response.lcp.path = format!("{} (started from a bds1 pilot's active sets at k = {k})", response.lcp.path);
        }
        if let Some(note) = walked {
            response.lcp.path = format!("{} ({note})", response.lcp.path);
        }
        response.timing_s.total = t_start.elapsed().as_secs_f64();
        Ok(response)
    }

    /// The LCP's data must be finite; when they are not, name the contact and the instant.
    /// Why: values that pass validation one by one (a static gap plus obstacle motions near
    /// 1e308, say) can still sum past f64, and a solver's "non-finite data" says nothing of where.
    fn check_lcp_finite(&self, a: &BlockCirculant, q: &[f64]) -> Result<(), SolveError> {
        let m = self.model.contacts.len().max(1);
        let what = "gaps, obstacle motions, forces or compliances overflow floating point; rescale the units";
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(SolveError::Invalid(format!("contact[{}]: the gap of the LCP at instant {} is {}: {what}", i % m, i / m, q[i])));
        }
        // The spectrum's bound is finite only if every block is: the blocks are then not formed.
        if a.max_abs_bound().1 {
            return Ok(());
        }
        if let Some(i) = a.blocks().iter().position(|v| !v.is_finite()) {
            let (d, ab) = (i / (m * m), i % (m * m));
            return Err(SolveError::Invalid(format!(
                "contact[{}]: the LCP matrix (its response to contact[{}] {d} instants earlier) is {}: {what}",
                ab / m,
                ab % m,
                a.blocks()[i]
            )));
        }
        Ok(())
    }

    /// Solves the LCP by the configured method; a failure is typed with its remedies.
    /// `auto` and `shooting` use the scheme's step map when it has one ([`super::state_space`]).
    pub(super) fn solve_lcp(&self, a: &BlockCirculant, q: &[f64], warm_start: Option<&[usize]>) -> Result<LcpSolution, SolveError> {
        let method = self.solver.method;
        let step_map = match method {
            LcpMethod::Auto | LcpMethod::Shooting if !q.is_empty() => Some(super::state_space::step_map(self)),
            _ => None,
        };
        if let Some(Err(why)) = &step_map {
            if method == LcpMethod::Shooting {
                return Err(SolveError::Invalid(format!(
                    "solver.method: \"shooting\" needs a time-stepping map, and this problem has none: {why}; use \"auto\""
                )));
            }
            if dense_memory(q.len()) > DENSE_MEMORY_MAX {
                return Err(SolveError::Limit(format!(
                    "discretization.steps: an LCP of {} unknowns needs ≈ {:.1} GiB in the dense methods (N² numbers, at most {:.0} GiB: N ≤ {DENSE_MAX}), and shooting does not apply: {why}",
                    q.len(),
                    dense_memory(q.len()) / GIB,
                    DENSE_MEMORY_MAX / GIB
                )));
            }
        }
        let step_map = step_map.and_then(Result::ok);
        // auto's dense fallback after shooting only when its projected cost is affordable.
        let refused = (method == LcpMethod::Auto && step_map.is_some()).then(|| dense_fallback_allowed(q.len()).err()).flatten();
        let method = if refused.is_some() { LcpMethod::Shooting } else { method };
        let reach = crate::lcp::ShootingReach {
            warm_only: self.solver.shooting_warm_only,
            homotopy: self.solver.shooting_homotopy,
            settle: self.solver.shooting_settle,
            state: self.solver.shooting_state.as_deref(),
        };
        let (sol, _state) = solve_periodic_lcp_with(a, q, step_map.as_ref(), method, self.solver.tolerance, warm_start, reach, self.solver.dense_pivots);
        match refused {
            _ if sol.outcome == LcpOutcome::Solved => Ok(sol),
            Some(cost) => Err(SolveError::Limit(format!(
                "solver.method: shooting missed ({} after {} Newton iterations, residual {:.3e}); {cost}: set [solver] method = \"lemke\" to force it, or sweep towards this point from where it solves (warm starts)",
                sol.outcome.name(),
                sol.info.pivots,
                sol.info.residual
            ))),
            None => Err(lcp_failure(sol)),
        }
    }

    /// The LCP (A, q) of the period without solving it (for exports and studies).
    pub fn assemble_lcp(&self, fft: &PeriodFft) -> Result<(BlockCirculant, Vec<f64>), SolveError> {
        let asm = assembly::assemble(&self.model, self.disc.scheme, self.period(), &[], fft, self.solver.parallel)?;
        Ok(self.lcp(&asm, fft))
    }
}

/// Whether two models have the same ω_max: the same M, K and contact compliances.
fn same_spectrum(a: &Model, b: &Model) -> bool {
    let springs = |m: &Model| -> Vec<(Vec<(usize, f64)>, crate::model::Compliance)> { m.contacts.iter().map(|c| (c.row.clone(), c.compliance)).collect() };
    a.structure.mass == b.structure.mass && a.structure.stiffness == b.structure.stiffness && springs(a) == springs(b)
}

/// Sizes we refuse before any work: k, the p·k instants of p forcing periods, the LCP size and
/// the dense assembly's cost.
fn check_sizes(model: &Model, disc: &Discretization, p: usize) -> Result<(), SolveError> {
    let k = disc.steps;
    if !(MIN_STEPS..=MAX_STEPS).contains(&k) {
        return Err(SolveError::Invalid(format!("discretization.steps: is {k}, must be in {MIN_STEPS}..={MAX_STEPS}")));
    }
    let instants = k.saturating_mul(p);
    if instants > MAX_STEPS {
        return Err(SolveError::Limit(format!(
            "discretization.period_multiple: is {p} with steps = {k}, {instants} instants over the period (period_multiple × steps); at most {MAX_STEPS} are accepted: reduce period_multiple or steps"
        )));
    }
    let m = model.contacts.len();
    let unknowns = instants.saturating_mul(m);
    // Fourier collocation has no step map: only the dense methods solve it.
    if disc.scheme == crate::time::Scheme::Fourier && dense_memory(unknowns) > DENSE_MEMORY_MAX {
        return Err(SolveError::Limit(format!(
            "discretization.steps: is {k}{} with {m} contact(s), an LCP of {unknowns} unknowns; fourier collocation has no time-stepping map and its dense methods would need ≈ {:.1} GiB (N² numbers; at most {DENSE_MAX} unknowns, {:.0} GiB, under fourier): use scheme cds, galerkin, bds1 or bds2, which shoot in O(k·(d + m)) memory, or reduce steps",
            if p > 1 { format!(" × period_multiple {p}") } else { String::new() },
            dense_memory(unknowns) / GIB,
            DENSE_MEMORY_MAX / GIB
        )));
    }
    if unknowns > MAX_LCP_SIZE {
        let times = if p > 1 { format!(" × period_multiple {p}") } else { String::new() };
        return Err(SolveError::Limit(format!(
            "discretization.steps: is {k}{times} with {m} contact(s), an LCP of {unknowns} unknowns (steps{} × contacts); at most {MAX_LCP_SIZE} are accepted: reduce steps{}",
            if p > 1 { " × period_multiple" } else { "" },
            if p > 1 { " or period_multiple" } else { "" }
        )));
    }
    let s = &model.structure;
    let dense = !(s.mass.is_sparse() || s.stiffness.is_sparse() || s.damping.as_ref().is_some_and(crate::model::Matrix::is_sparse));
    let n = model.n();
    let flops = (instants / 2 + 1) as f64 * (8.0 / 3.0) * (n as f64).powi(3);
    if dense && flops > MAX_DENSE_FLOPS {
        return Err(SolveError::Limit(format!(
            "structure.mass: a dense {n}×{n} model with steps = {k}{} needs {} complex {n}×{n} factorisations (≈ {flops:.1e} flops, at most {MAX_DENSE_FLOPS:.0e} accepted): give the matrices in sparse form, reduce the model (Craig–Bampton), or reduce steps",
            if p > 1 { format!(" × period_multiple {p}") } else { String::new() },
            instants / 2 + 1
        )));
    }
    Ok(())
}

/// The time grid must be representable and resolve every harmonic of the loads and obstacles.
fn check_grid(model: &Model, disc: &Discretization) -> Result<(), SolveError> {
    let k = disc.steps;
    // The difference operators divide by h²: a time step whose 1/h² overflows (ω = 1e308)
    // gives σ2 = 0/0 = NaN at harmonic 0 (found by tests/props.rs).
    let h = model.period() / k as f64;
    if !(1.0 / (h * h)).is_finite() {
        return Err(SolveError::Invalid(format!(
            "excitation.frequency: is {:e} with steps = {k}: the time step T/k = {h:e} is too small for floating point (1/h² overflows); rescale the time unit",
            model.frequency
        )));
    }
    // A harmonic h is resolved by k samples only if h < k/2 (Nyquist).
    for (i, f) in model.forces.iter().enumerate() {
        if 2 * f.term.harmonic as usize >= k {
            return Err(SolveError::Invalid(format!(
                "force[{i}].harmonic: is {}, not resolved by steps = {k} (needs steps > {})",
                f.term.harmonic,
                2 * f.term.harmonic
            )));
        }
    }
    for (i, c) in model.contacts.iter().enumerate() {
        for (j, h) in c.motion.iter().enumerate() {
            if 2 * h.harmonic as usize >= k {
                return Err(SolveError::Invalid(format!(
                    "contact[{i}].motion[{j}].harmonic: is {}, not resolved by steps = {k} (needs steps > {})",
                    h.harmonic,
                    2 * h.harmonic
                )));
            }
        }
    }
    Ok(())
}

fn check_solver(s: &SolverSettings) -> Result<(), SolveError> {
    let t = s.tolerance;
    if !(t.is_finite() && t > 0.0 && t < 1.0) {
        return Err(SolveError::Invalid(format!("solver.tolerance: is {t}, must be in (0, 1)")));
    }
    Ok(())
}

fn check_outputs(outputs: &OutputSelection, n: usize) -> Result<(), SolveError> {
    if let Some(d) = outputs.dofs().into_iter().find(|&d| d >= n) {
        return Err(SolveError::Invalid(format!("output: DOF {d} does not exist, the model has DOFs 0 to {}", n - 1)));
    }
    Ok(())
}
