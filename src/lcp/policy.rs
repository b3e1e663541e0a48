//! The LCP policy: which method solves a block-circulant LCP, and the fallbacks (`auto`).
//! Shared by the engine and by `periodic-contact lcp`, so it knows nothing of mechanics.
use super::{BlockCirculant, BlockPivoting, CirculantOperator, LcpOutcome, LcpSolution, LcpStep, Lemke, LemkeSettings, PivotingSettings, WarmOutcome};

/// Which LCP method to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LcpMethod {
    /// Picks by size and falls back on failure.
    Auto,
    /// Lexicographic Lemke.
    Lemke,
    /// Block principal pivoting on the active set, FFT products (the fast path for large k).
    Pivoting,
}

impl LcpMethod {
    /// Every method, in the order of the documentation.
    pub const ALL: [LcpMethod; 3] = [LcpMethod::Auto, LcpMethod::Lemke, LcpMethod::Pivoting];

    pub fn name(self) -> &'static str {
        match self {
            LcpMethod::Auto => "auto",
            LcpMethod::Lemke => "lemke",
            LcpMethod::Pivoting => "pivoting",
        }
    }
}

/// Up to this LCP size `auto` uses lexicographic Lemke directly; above, block pivoting finished
/// by Lemke from its best basis, with full lexicographic Lemke as the fallback.
pub const AUTO_LEMKE_MAX: usize = 256;

/// Solves a block-circulant LCP with `method` (the engine's logic: `auto` uses lexicographic
/// Lemke up to [`AUTO_LEMKE_MAX`], above it block pivoting with FFT products, falling back to
/// Lemke when that fails). Used by the engine and by `periodic-contact lcp` for a raw LCP whose
/// matrix is block-circulant.
pub fn solve_circulant_lcp(a: &BlockCirculant, q: &[f64], method: LcpMethod, tolerance: f64, warm_start: Option<&[usize]>) -> LcpSolution {
    if q.is_empty() {
        return LcpSolution { outcome: LcpOutcome::Solved, z: vec![], w: vec![], info: Default::default() };
    }
    let step = |method, sol: &LcpSolution| LcpStep { method, size: q.len(), pivots: sol.info.pivots, outcome: sol.outcome, time_s: sol.info.time_s };
    let lemke = || {
        let settings = LemkeSettings { certify_tol: tolerance, warm_start: warm_start.map(<[usize]>::to_vec), ..LemkeSettings::default() };
        let mut sol = Lemke::new(settings).solve(a, q);
        // Lemke accepts a guess that certifies as it is, or discards it and runs cold.
        sol.info.warm = match (warm_start, sol.info.warm_start_used) {
            (None, _) => WarmOutcome::NotOffered,
            (Some(_), true) => WarmOutcome::Accepted,
            (Some(_), false) => WarmOutcome::Rejected,
        };
        sol.info.path = vec![step(LcpMethod::Lemke, &sol)];
        sol
    };
    let pivoting = || {
        let settings = PivotingSettings { certify_tol: tolerance, warm_start: warm_start.map(<[usize]>::to_vec), ..PivotingSettings::default() };
        let mut sol = BlockPivoting::new(settings).solve(&CirculantOperator::new(a), q);
        // Block pivoting always starts from the guess: one exchange (the check) means it was right.
        sol.info.warm = match warm_start {
            None => WarmOutcome::NotOffered,
            Some(_) if sol.info.pivots <= 1 => WarmOutcome::Accepted,
            Some(_) => WarmOutcome::Repaired { pivots: sol.info.pivots },
        };
        sol.info.path = vec![step(LcpMethod::Pivoting, &sol)];
        sol
    };
    match method {
        LcpMethod::Lemke => lemke(),
        LcpMethod::Pivoting => pivoting(),
        LcpMethod::Auto if q.len() <= AUTO_LEMKE_MAX => lemke(),
        LcpMethod::Auto => {
            let fast = pivoting();
            if fast.outcome == LcpOutcome::Solved {
                fast
            } else {
                // The robust fallback: lexicographic Lemke; its pivots add to the fast path's.
                let mut sol = lemke();
                sol.info.pivots += fast.info.pivots;
                sol.info.time_s += fast.info.time_s;
                sol.info.path.splice(0..0, fast.info.path);
                sol
            }
        }
    }
}

/// Why a method name was not accepted.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LcpMethodError {
    /// Not one of [`LcpMethod::ALL`]'s names.
    #[error("unknown method \"{0}\"; expected auto, lemke or pivoting")]
    Unknown(String),
}

impl std::str::FromStr for LcpMethod {
    type Err = LcpMethodError;
    fn from_str(s: &str) -> Result<Self, LcpMethodError> {
        LcpMethod::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| LcpMethodError::Unknown(s.to_string()))
    }
}
