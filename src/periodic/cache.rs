//! The session's assembly, kept across re-solves (issue 12 item 2).
//!
//! The assembly (k/2+1 harmonic solves: Ĝ_p, X̂lin_p, Ẑ_p⁻¹Bᵀ) depends on the frequency, the grid,
//! the structure, the contacts' rows of B, the recovered DOFs and the forces. It does
//! not depend on the gaps or the obstacle motions (they enter q only, in `PeriodicProblem::lcp`),
//! and X̂lin is linear in the forces: a common scale of every force amplitude scales X̂lin and
//! B X̂lin. So a gap, motion or force-scale change (the FMU's tunables) re-solves without
//! re-assembling; anything else builds the assembly again, on the structure's ω-independent
//! part ([`StructureOperator`]: modes, residual flexibility) kept while M, C, K are the same.
use super::assembly::{ModalProducts, StructureOperator};
use super::{Assembly, PeriodFft, PeriodicProblem, SolveError};
use crate::model::Compliance;
use std::hash::{Hash, Hasher};
use std::sync::Arc;

/// The last assembly and what it was built for.
#[derive(Clone, Debug)]
pub(super) struct AssemblyCache {
    key: u64,
    /// The amplitude of the first nonzero force when it was built (0: no force).
    force_reference: f64,
    assembly: Assembly,
    /// The ω-independent part (modes, residual flexibility, ...) and the hash of the M, C, K it
    /// was built from: a new frequency or grid rebuilds only the per-harmonic part on it.
    /// Shared (`Arc`) by the sessions a sweep clones per chunk.
    structure: Option<(u64, Arc<StructureOperator>)>,
    /// The modal assembly's products, overwritten by the next build.
    products: ModalProducts,
}

/// The hash of the structure's M, C and K (what [`StructureOperator`] depends on).
fn structure_key(p: &PeriodicProblem) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    hash_structure(&p.model().structure, &mut h);
    h.finish()
}

fn hash_structure(s: &crate::model::Structure, h: &mut impl Hasher) {
    for m in [Some(&s.mass), Some(&s.stiffness), s.damping.as_ref()] {
        match m {
            Some(m) => m.for_each(|i, j, v| (i, j, v.to_bits()).hash(h)),
            None => u8::MAX.hash(h),
        }
    }
}

/// What the assembly depends on, hashed, and the force reference amplitude (forces enter the key
/// divided by it, so a common scale keeps the key).
fn key(p: &PeriodicProblem, structure: u64) -> (u64, f64) {
    let model = p.model();
    let disc = p.discretization();
    let mut h = std::collections::hash_map::DefaultHasher::new();
    model.frequency.to_bits().hash(&mut h);
    (disc.steps, p.period_multiple()).hash(&mut h);
    disc.scheme.name().hash(&mut h);
    p.recovery_rows().iter().for_each(|(l, terms)| (l, terms.iter().map(|&(d, c)| (d, c.to_bits())).collect::<Vec<_>>()).hash(&mut h));
    structure.hash(&mut h);
    for c in &model.contacts {
        c.row.iter().for_each(|&(d, v)| (d, v.to_bits()).hash(&mut h));
        c.row.len().hash(&mut h);
        if let Compliance::Compliant { stiffness } = c.compliance {
            stiffness.to_bits().hash(&mut h);
        }
    }
    for f in &model.frictions {
        f.row.iter().for_each(|&(d, c)| (d, c.to_bits()).hash(&mut h));
    }
    for r in &model.rubbing {
        r.row.iter().for_each(|&(d, c)| (d, c.to_bits()).hash(&mut h));
        (r.contact, r.traction().to_bits()).hash(&mut h);
    }
    let reference = model.forces.iter().map(|f| f.term.amplitude).find(|&a| a != 0.0).unwrap_or(0.0);
    for f in &model.forces {
        let shape = if reference == 0.0 { 0.0 } else { f.term.amplitude / reference };
        (f.dof, f.term.harmonic, f.term.phase.to_bits(), shape.to_bits()).hash(&mut h);
    }
    (h.finish(), reference)
}

/// The assembly of `p`: the cached one when only gaps, motions or a common force scale changed
/// (scaled in place), else built anew. Returns it and whether it was built.
pub(super) fn assembled<'a>(cache: &'a mut Option<AssemblyCache>, p: &PeriodicProblem, fft: &PeriodFft) -> Result<(&'a Assembly, bool), SolveError> {
    // M, C and K hashed once a solve (twice before: 1.3 % of the real blade's sweep, issue 23).
    let skey = structure_key(p);
    let (key, reference) = key(p, skey);
    let reuse = cache.as_ref().is_some_and(|c| c.key == key && (c.force_reference == 0.0) == (reference == 0.0));
    if !reuse {
        let operator = match cache.as_mut().and_then(|c| c.structure.take()) {
            Some((k, op)) if k == skey => op,
            _ => Arc::new(StructureOperator::new(p.model())?),
        };
        let mut products = cache.as_mut().map(|c| std::mem::take(&mut c.products)).unwrap_or_default();
        let assembly = p.assemble_reusing(fft, &operator, &mut products)?;
        let fresh = AssemblyCache { key, force_reference: reference, assembly, structure: Some((skey, operator)), products };
        return Ok((&cache.insert(fresh).assembly, true));
    }
    let c = cache.as_mut().expect("checked above");
    if c.force_reference != reference {
        let ratio = reference / c.force_reference;
        c.assembly.xlin_hat.iter_mut().chain(c.assembly.bxlin_hat.iter_mut()).for_each(|v| *v *= ratio);
        c.force_reference = reference;
    }
    Ok((&c.assembly, false))
}

#[cfg(test)]
mod tests {
    use super::super::assembly::tests::chain_with_massless_boundary;
    use super::super::{OutputSelection, PeriodicProblem, PeriodicSolver, SolverSettings};
    use crate::time::{Discretization, Pairing, Scheme};
    use std::sync::Arc;

    /// A session changing ω keeps the structure operator (modes, residual flexibility) and
    /// rebuilds only the per-harmonic part; each answer equals a fresh problem's solve at that ω,
    /// which builds everything anew, to 1e-12 of the amplitude.
    #[test]
    fn a_new_frequency_reuses_the_structure_operator_and_equals_a_fresh_solve() {
        let mut model = chain_with_massless_boundary();
        // The rigid contacts on massless DOFs (a finite force: cds with the same pairing, as the
        // real blade), gaps below the contact-free amplitude.
        model.contacts.truncate(2);
        model.contacts.iter_mut().for_each(|c| c.gap = 2e-5);
        let disc = Discretization { scheme: Scheme::Cds, steps: 128, pairing: Some(Pairing::Same) };
        let outputs = OutputSelection { displacement: vec![1, 3, 12], contacts: true, ..Default::default() };
        let problem = PeriodicProblem::new(model, disc, outputs, SolverSettings::default()).unwrap();
        let mut session = PeriodicSolver::new(problem.clone());
        let mut first: Option<Arc<super::StructureOperator>> = None;
        for omega in [30.0, 37.0, 44.0] {
            session.update_frequency(omega).unwrap();
            let swept = session.solve().unwrap();
            let op = session.cache.as_ref().and_then(|c| c.structure.as_ref()).map(|(_, op)| op.clone()).unwrap();
            assert!(Arc::ptr_eq(first.get_or_insert_with(|| op.clone()), &op), "ω = {omega}: the operator was rebuilt");
            let mut fresh = problem.clone();
            fresh.set_frequency(omega).unwrap();
            let alone = fresh.solve().unwrap();
            let mut worst = 0.0f64;
            let mut amplitude = 0.0f64;
            for (key, x) in &alone.displacement {
                let (lo, hi) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
                amplitude = amplitude.max(hi - lo);
                worst = x.iter().zip(&swept.displacement[key]).fold(worst, |a, (u, v)| a.max((u - v).abs()));
            }
            let touching = alone.contacts.iter().any(|c| c.force.iter().any(|&f| f > 0.0));
            eprintln!("ω = {omega}: session against a fresh solve {:.2e} of the amplitude {amplitude:.3e} (contact: {touching})", worst / amplitude);
            assert!(touching, "ω = {omega}: the contacts are not hit");
            assert!(amplitude > 0.0 && worst <= 1e-12 * amplitude, "ω = {omega}: {worst:e} against {amplitude:e}");
        }
        assert_eq!(session.assemblies(), 3, "one assembly per frequency, on one structure operator");
    }
}
