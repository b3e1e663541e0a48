//! The 1-DOF families of `bench` and of the estimate study: a nominal member and members drawn
//! uniformly within each family's ranges (seeded), so that a claim is measured on a family,
//! worst case first, rather than on a favourite case. The exact orbit of every member is known
//! (src/formulation.md §6.2, §6.3).
use crate::exact::Oscillator;

/// SplitMix64 (Steele, Lea & Flood 2014): a seeded, dependency-free stream for the draws.
pub struct SplitMix(pub u64);

impl SplitMix {
    /// One stream per (seed, draw): a member does not depend on how many were drawn before it.
    pub fn for_draw(seed: u64, draw: usize) -> Self {
        SplitMix(seed ^ (draw as u64).wrapping_mul(0xD1B5_4A32_D192_ED03))
    }
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn uniform(&mut self, (lo, hi): (f64, f64)) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
}

/// The nominal value without a stream, a uniform draw in `range` with one.
pub fn pick(rng: &mut Option<&mut SplitMix>, nominal: f64, range: (f64, f64)) -> f64 {
    rng.as_deref_mut().map_or(nominal, |r| r.uniform(range))
}

/// A family of 1-DOF stops: m = k = 1, F cos Ωt, a stop x ≤ g0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Rigid stop with sticking (0 < k·g0 < F): F = 1, c ∈ [0.05, 0.2], g0 ∈ [0.3, 0.7], Ω ∈ [0.8, 1.2].
    RigidStick,
    /// Rigid stop, pure impacts (F < k·g0): g0 = 1, c ∈ [0.02, 0.1], F ∈ [0.3, 0.6], Ω ∈ [0.9, 1.1].
    RigidImpact,
    /// Compliant stop: g0 = 1, c ∈ [0.02, 0.1], F ∈ [0.7, 1.3], Ω ∈ [1.1, 1.5], k_c ∈ [5, 50].
    Compliant,
}

/// One member: the oscillator, its stop's gap and (compliant) contact stiffness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Member {
    pub oscillator: Oscillator,
    pub gap: f64,
    pub contact_stiffness: Option<f64>,
}

impl Member {
    /// "c=0.100 F=1.000 g0=0.500 ω=1.000 kc=10.000".
    pub fn summary(&self) -> String {
        let o = &self.oscillator;
        let kc = self.contact_stiffness.map_or(String::new(), |kc| format!(" kc={kc:.3}"));
        format!("c={:.3} F={:.3} g0={:.3} ω={:.3}{kc}", o.damping, o.force, self.gap, o.omega)
    }
}

impl Family {
    pub const ALL: [Family; 3] = [Family::RigidStick, Family::RigidImpact, Family::Compliant];

    pub fn name(self) -> &'static str {
        match self {
            Family::RigidStick => "rigid-stick",
            Family::RigidImpact => "rigid-impact",
            Family::Compliant => "compliant",
        }
    }

    /// The member of a stream (`None`: the nominal member). The draws are taken in a fixed order
    /// (c, then the family's other parameters), so a seed always gives the same members.
    pub fn member(self, mut rng: Option<&mut SplitMix>) -> Member {
        let osc = |c, force, omega| Oscillator::new(1.0, c, 1.0, force, omega);
        match self {
            Family::RigidStick => {
                let c = pick(&mut rng, 0.1, (0.05, 0.2));
                let gap = pick(&mut rng, 0.5, (0.3, 0.7));
                let omega = pick(&mut rng, 1.0, (0.8, 1.2));
                Member { oscillator: osc(c, 1.0, omega), gap, contact_stiffness: None }
            }
            Family::RigidImpact => {
                let c = pick(&mut rng, 0.05, (0.02, 0.1));
                let force = pick(&mut rng, 0.4, (0.3, 0.6));
                let omega = pick(&mut rng, 1.0, (0.9, 1.1));
                Member { oscillator: osc(c, force, omega), gap: 1.0, contact_stiffness: None }
            }
            Family::Compliant => {
                let c = pick(&mut rng, 0.05, (0.02, 0.1));
                let force = pick(&mut rng, 1.0, (0.7, 1.3));
                let omega = pick(&mut rng, 1.3, (1.1, 1.5));
                let kc = pick(&mut rng, 10.0, (5.0, 50.0));
                Member { oscillator: osc(c, force, omega), gap: 1.0, contact_stiffness: Some(kc) }
            }
        }
    }

    /// Member `draw`: 0 is the nominal member, i ≥ 1 the i-th draw of the seeded stream.
    pub fn draw(self, draw: usize, seed: u64) -> Member {
        if draw == 0 { self.member(None) } else { self.member(Some(&mut SplitMix::for_draw(seed, draw))) }
    }
}
