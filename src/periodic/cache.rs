//! The session's assembly, kept across re-solves (issue 12 item 2).
//!
//! The assembly (k/2+1 harmonic solves: Ĝ_p, X̂lin_p, Ẑ_p⁻¹Bᵀ) depends on the frequency, the grid,
//! the structure, the contacts' rows of B, the recovered DOFs and the forces. It does
//! not depend on the gaps or the obstacle motions (they enter q only, in `PeriodicProblem::lcp`),
//! and X̂lin is linear in the forces: a common scale of every force amplitude scales X̂lin and
//! B X̂lin. So a gap, motion or force-scale change (the FMU's tunables) re-solves without
//! re-assembling; anything else builds the assembly again.
use super::{Assembly, PeriodFft, PeriodicProblem, SolveError};
use crate::model::Compliance;
use std::hash::{Hash, Hasher};

/// The last assembly and what it was built for.
#[derive(Clone, Debug)]
pub(super) struct AssemblyCache {
    key: u64,
    /// The amplitude of the first nonzero force when it was built (0: no force).
    force_reference: f64,
    assembly: Assembly,
}

/// What the assembly depends on, hashed, and the force reference amplitude (forces enter the key
/// divided by it, so a common scale keeps the key).
fn key(p: &PeriodicProblem) -> (u64, f64) {
    let model = p.model();
    let disc = p.discretization();
    let mut h = std::collections::hash_map::DefaultHasher::new();
    model.frequency.to_bits().hash(&mut h);
    (disc.steps, p.period_multiple()).hash(&mut h);
    disc.scheme.name().hash(&mut h);
    p.recovery_dofs().hash(&mut h);
    let s = &model.structure;
    for m in [Some(&s.mass), Some(&s.stiffness), s.damping.as_ref()] {
        match m {
            Some(m) => m.for_each(|i, j, v| (i, j, v.to_bits()).hash(&mut h)),
            None => u8::MAX.hash(&mut h),
        }
    }
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
    let (key, reference) = key(p);
    let reuse = cache.as_ref().is_some_and(|c| c.key == key && (c.force_reference == 0.0) == (reference == 0.0));
    if !reuse {
        let assembly = p.assemble(fft)?;
        return Ok((&cache.insert(AssemblyCache { key, force_reference: reference, assembly }).assembly, true));
    }
    let c = cache.as_mut().expect("checked above");
    if c.force_reference != reference {
        let ratio = reference / c.force_reference;
        c.assembly.xlin_hat.iter_mut().chain(c.assembly.bxlin_hat.iter_mut()).for_each(|v| *v *= ratio);
        c.force_reference = reference;
    }
    Ok((&c.assembly, false))
}
