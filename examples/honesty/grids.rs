//! What the honesty examples share: a scene's arguments, its solvers at several k, and one
//! frequency solved at k (cold) and at the other grids warm-started from k's active set.
use periodic_contact::periodic::{PeriodicSolver, carried_active_set};
use periodic_contact::response::Response;
use periodic_contact::scene::Scene;
use periodic_contact::study::families::SplitMix;
use periodic_contact::time::Discretization;
use std::path::Path;

/// `SCENE LO HI DRAWS K [SEED]`, the solvers at `factors`·k (in k/4 units: 1 = k/4, 4 = k, 32 = 8k)
/// and the contacts' count m.
pub struct Grids {
    pub lo: f64,
    pub hi: f64,
    pub draws: usize,
    pub k: usize,
    pub seed: u64,
    pub m: usize,
    pub solvers: Vec<PeriodicSolver>,
}

impl Grids {
    pub fn from_args(quarters: &[usize]) -> Grids {
        let a: Vec<String> = std::env::args().collect();
        let (lo, hi): (f64, f64) = (a[2].parse().unwrap(), a[3].parse().unwrap());
        let (draws, k): (usize, usize) = (a[4].parse().unwrap(), a[5].parse().unwrap());
        let seed: u64 = a.get(6).map_or(23, |s| s.parse().unwrap());
        let (scene, _) = Scene::load(Path::new(&a[1])).unwrap();
        let t = std::time::Instant::now();
        let base = scene.to_problem(&a[1]).unwrap();
        eprintln!("set-up {:.1} s", t.elapsed().as_secs_f64());
        let m = base.model().contacts.len().max(1);
        let solvers = quarters
            .iter()
            .map(|q| {
                let mut p = base.clone();
                p.set_discretization(Discretization { steps: q * k / 4, ..base.discretization() }).unwrap();
                PeriodicSolver::new(p)
            })
            .collect();
        Grids { lo, hi, draws, k, seed, m, solvers }
    }

    /// The draw's frequency (lo itself for one draw).
    pub fn omega(&self, draw: usize) -> f64 {
        if self.draws == 1 { self.lo } else { SplitMix::for_draw(self.seed, draw).uniform((self.lo, self.hi)) }
    }

    /// Solver `main` (at k) cold at ω, then every other solver warm-started from its active set;
    /// `None` (printed) where k itself missed. A grid that breaks the scheme's limit or misses is `None`.
    pub fn solve(&mut self, omega: f64, main: usize) -> Option<(Response, Vec<Option<Response>>)> {
        let s = &mut self.solvers[main];
        s.update_frequency(omega).unwrap();
        let Ok(first) = s.solve_by_shooting(false) else {
            println!("{omega:.2} {} cold shooting missed at k", self.k);
            return None;
        };
        let (m, k) = (self.m, self.k);
        let others = (0..self.solvers.len())
            .map(|i| {
                let s = &mut self.solvers[i];
                // k/4 may break the scheme's stability limit.
                if i == main || s.update_frequency(omega).is_err() {
                    return None;
                }
                s.set_warm_start(&carried_active_set(&first.active_set, m, k, s.problem().instants()));
                s.solve_by_shooting(true).or_else(|_| s.solve_by_shooting(false)).ok()
            })
            .collect();
        Some((first, others))
    }
}
