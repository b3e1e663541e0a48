//! The orbits whose phases the exact walk's orbit builds share ([`Modes`]), at most [`KEPT`].
use crate::analysis::polish::{Event, EventKind, PolishedOrbit};
use crate::model::Model;
use std::rc::Rc;

/// A signature's events (contact, kind) and its contacts closed all period long.
pub(super) type SignatureKey = (Vec<(usize, EventKind)>, Vec<usize>);

/// The most orbits kept (one per signature met; the real blade's tips' events pass each other
/// every few points, each new order a signature): unbounded, they were the walk's growing memory
/// (heap +1.3 MB a point, 3.9 GiB at 2153 points; validation/RECORD.md). A phase dropped with its
/// orbit is made again where its contact set comes back, bit for bit (the same CSV with 2 kept).
const KEPT: usize = 32;

/// The last orbits built, each with its events (seeds included), closed contacts and λ's bits:
/// a corrector at λ fixed (a landing force's zero, a restart, a touch point) built the same orbit
/// at λ and at λ ± h for its Jacobian's λ column at every iteration, a third of the rigid coarse
/// walk's time. A build is a function of these alone, so the copy is the build bit for bit.
const RECENT: usize = 4;

type Recent = (Vec<Event>, Vec<usize>, u64, Rc<PolishedOrbit>);

/// The first orbit built of each signature met, whose phases' eigendecompositions every later
/// orbit shares (the phase matrices do not depend on the parameter: one decomposition per contact
/// set). With the first orbit's only, every orbit past the coarse blade's first grazing decomposed
/// its new phases again: a quarter of the walk's time. Each with its last use: the least recently
/// used goes first.
#[derive(Default)]
pub(super) struct Modes {
    orbits: Vec<(SignatureKey, PolishedOrbit, u64)>,
    /// The builds made (the clock of the uses).
    clock: u64,
    /// The last [`RECENT`] orbits built, the newest last.
    recent: Vec<Recent>,
}

impl Modes {
    /// The orbit built last for `events`, `always` at λ = `lambda` (bit for bit), when one of the
    /// last [`RECENT`] builds; its signature's use is counted as a build's would be.
    pub fn again(&mut self, key: &SignatureKey, events: &[Event], always: &[usize], lambda: f64) -> Option<Rc<PolishedOrbit>> {
        let same = |e: &[Event]| {
            e.len() == events.len() && e.iter().zip(events).all(|(a, b)| a.contact == b.contact && a.kind == b.kind && a.seed.to_bits() == b.seed.to_bits())
        };
        let orbit = self.recent.iter().rev().find(|r| r.2 == lambda.to_bits() && r.1 == always && same(&r.0)).map(|r| Rc::clone(&r.3))?;
        self.clock += 1;
        let clock = self.clock;
        self.orbits.iter_mut().filter(|(k, _, _)| k == key).for_each(|m| m.2 = clock);
        Some(orbit)
    }

    /// Keeps `orbit`, built for `events`, `always` at λ = `lambda`, for [`Self::again`].
    pub fn remember(&mut self, events: Vec<Event>, always: &[usize], lambda: f64, orbit: &Rc<PolishedOrbit>) {
        if self.recent.len() >= RECENT {
            self.recent.remove(0);
        }
        // Shared, not copied: a copy of the orbit (its model, phases) per build and per ask was 2 % of the rigid walk.
        self.recent.push((events, always.to_vec(), lambda.to_bits(), Rc::clone(orbit)));
    }

    /// The orbit of the signature `key` (`events`, `always`) for `model`, its phases re-tuned from
    /// the kept orbits': the signature's own first, then any other's.
    pub fn build(&mut self, key: SignatureKey, model: &Model, events: Vec<Event>, always: &[usize]) -> Option<PolishedOrbit> {
        self.clock += 1;
        let mut bank: Vec<&PolishedOrbit> = self.orbits.iter().filter(|(k, _, _)| *k == key).map(|(_, o, _)| o).collect();
        let known = !bank.is_empty();
        bank.extend(self.orbits.iter().filter(|(k, _, _)| *k != key).map(|(_, o, _)| o));
        let orbit = PolishedOrbit::unsolved_retuning(model, events, always, &bank).ok()?;
        if known {
            let clock = self.clock;
            self.orbits.iter_mut().filter(|(k, _, _)| *k == key).for_each(|m| m.2 = clock);
        } else {
            if self.orbits.len() >= KEPT
                && let Some(oldest) = self.orbits.iter().enumerate().min_by_key(|(_, m)| m.2).map(|(i, _)| i)
            {
                self.orbits.swap_remove(oldest);
            }
            self.orbits.push((key, orbit.clone(), self.clock));
        }
        Some(orbit)
    }
}

#[cfg(test)]
mod tests {
    use crate::analysis::continuation::Parameter;
    use crate::analysis::continuation::exact::family::tests::forced_with_rigid_stop;
    use crate::analysis::continuation::exact::family::{Family, Signature, lambda_axis};
    use crate::analysis::polish;
    use crate::model::{Matrix, Structure};
    use crate::periodic::PeriodicSolver;

    /// An orbit asked for again at the same λ (a corrector at λ fixed) is the one a family that
    /// never built it makes: the residuals and Jacobians of the sticking oscillator (a rigid stop,
    /// plastic impacts) equal bit for bit, at λ and, after builds elsewhere, at λ again.
    #[test]
    fn an_orbit_asked_again_is_the_one_built_anew() {
        let structure =
            Structure { mass: Matrix::from_rows(&[vec![1.0]]), stiffness: Matrix::from_rows(&[vec![1.0]]), damping: Some(Matrix::from_rows(&[vec![0.1]])) };
        let p = forced_with_rigid_stop(structure, 0, 0.5, 512, 0.7);
        let r = PeriodicSolver::new(p.clone()).solve().expect("the grid solve at Ω = 0.7");
        let orbit = polish::polish(&p, &r).expect("the polish at Ω = 0.7");
        assert!(!orbit.events().is_empty(), "the stop is hit");
        let family = || {
            let sig = Signature { events: orbit.events().to_vec(), always: orbit.always_closed().to_vec() };
            let mut fam = Family::new(p.model(), Parameter::Frequency, 1.0, 1.0, sig);
            fam.ys = fam.scale_of(orbit.initial_state());
            fam
        };
        let walked = family();
        let w = walked.correct(&walked.pack(&orbit, 0.7), &lambda_axis(walked.dim()), 0.7).expect("closed at Ω = 0.7");
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        let mut elsewhere = w.clone();
        *elsewhere.last_mut().expect("λ") = 0.71;
        for _ in 0..2 {
            // The walked family has built at λ (and λ ± h) before; a new one has not.
            let (again, anew) = (walked.residual(&w).expect("residual"), family().residual(&w).expect("residual"));
            assert_eq!(bits(again.as_slice()), bits(anew.as_slice()), "the residual at λ again");
            let (again, anew) = (walked.jacobian(&w).expect("Jacobian"), family().jacobian(&w).expect("Jacobian"));
            assert_eq!(bits(again.as_slice()), bits(anew.as_slice()), "the Jacobian at λ again");
            walked.residual(&elsewhere).expect("a build elsewhere");
        }
    }
}
