//! Events between two points of a branch, located to their parameter value by bisection along
//! the secant: each trial point is the orbit on the hyperplane through the secant's midpoint
//! normal to it, so that a fold between the two points is bracketed too.
use super::corrector::{Family, Solved};
use super::floquet;
use num_complex::Complex64;

/// What happens at an event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    /// The parameter turns back along the branch (saddle-node, smooth or at a kink).
    Fold,
    /// A contact's active steps go from or to none.
    Grazing,
    /// A real multiplier crosses −1.
    PeriodDoubling,
    /// A complex pair of multipliers crosses the unit circle.
    NeimarkSacker,
}

impl EventKind {
    /// The name in the CSV and JSON.
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Fold => "fold",
            EventKind::Grazing => "grazing",
            EventKind::PeriodDoubling => "period_doubling",
            EventKind::NeimarkSacker => "neimark_sacker",
        }
    }
}

/// A solved point with its tangent (oriented along the branch) and multipliers.
#[derive(Clone, Debug)]
pub(super) struct Node {
    pub solved: Solved,
    pub tangent: Vec<f64>,
    pub mu: Vec<Complex64>,
}

impl Node {
    pub fn new(fam: &mut Family, solved: Solved, tangent: Vec<f64>) -> Node {
        let smoothed = if fam.smoothing > 0.0 { fam.smoothed_monodromy(&solved, fam.blocks, fam.smoothing) } else { None };
        let mu = floquet::multipliers(smoothed.as_ref().unwrap_or(&solved.monodromy));
        Node { solved, tangent, mu }
    }
    fn side(&self, kind: EventKind, contact: usize) -> i64 {
        match kind {
            EventKind::Fold => i64::from(self.tangent[self.tangent.len() - 1] > 0.0),
            EventKind::Grazing => i64::from(self.solved.masks.iter().any(|m| m >> contact & 1 == 1)),
            EventKind::PeriodDoubling => i64::from(floquet::doubling_sign(&self.mu)),
            EventKind::NeimarkSacker => floquet::complex_outside(&self.mu) as i64,
        }
    }
}

/// The events between `a` and `b` (in order along the branch), each as the located node and a
/// detail for the JSON. `contacts`: the number of contacts (a grazing test each).
pub(super) fn between(fam: &mut Family, a: &Node, b: &Node, contacts: usize) -> Vec<(EventKind, Node, String)> {
    let mut tests = vec![(EventKind::Fold, 0), (EventKind::PeriodDoubling, 0), (EventKind::NeimarkSacker, 0)];
    tests.extend((0..contacts).map(|c| (EventKind::Grazing, c)));
    let mut found = Vec::new();
    for (kind, c) in tests {
        if a.side(kind, c) == b.side(kind, c) {
            continue;
        }
        // A located node with unknown multipliers (unconverged Schur form) gives way to b, whose are known.
        let node = locate(fam, a, b, kind, c).filter(|n| !floquet::largest(&n.mu).is_nan()).unwrap_or_else(|| b.clone());
        let detail = match kind {
            EventKind::Grazing => format!("contact {c}: active steps {} -> {}", active_steps(a, c), active_steps(b, c)),
            EventKind::NeimarkSacker | EventKind::PeriodDoubling => floquet::event_detail(kind, &node.mu),
            EventKind::Fold => String::new(),
        };
        found.push((kind, node, detail));
    }
    // Along the branch: by the secant coordinate.
    let sec: Vec<f64> = b.solved.v.iter().zip(&a.solved.v).map(|(x, y)| x - y).collect();
    let coord = |n: &Node| n.solved.v.iter().zip(&a.solved.v).zip(&sec).map(|((x, y), s)| (x - y) * s).sum::<f64>();
    found.sort_by(|x, y| coord(&x.1).total_cmp(&coord(&y.1)));
    found
}

/// Steps at which contact `c` is active.
fn active_steps(n: &Node, c: usize) -> usize {
    n.solved.masks.iter().filter(|m| *m >> c & 1 == 1).count()
}

/// Bisection between `a` and `b` on the side of `kind`: the node just past the change.
fn locate(fam: &mut Family, a: &Node, b: &Node, kind: EventKind, c: usize) -> Option<Node> {
    let (mut lo, mut hi) = (a.clone(), b.clone());
    let side_lo = lo.side(kind, c);
    for _ in 0..48 {
        let sec: Vec<f64> = hi.solved.v.iter().zip(&lo.solved.v).map(|(x, y)| x - y).collect();
        let len = sec.iter().map(|x| x * x).sum::<f64>().sqrt();
        if len <= 1e-10 {
            break;
        }
        let normal: Vec<f64> = sec.iter().map(|x| x / len).collect();
        let pred: Vec<f64> = lo.solved.v.iter().zip(&sec).map(|(x, s)| x + 0.5 * s).collect();
        let (mid, _) = fam.correct(&pred, &normal, &lo.solved.masks)?;
        let tangent = mid.tangent(&a.tangent)?;
        let node = Node::new(fam, mid, tangent);
        if node.side(kind, c) == side_lo {
            lo = node;
        } else {
            hi = node;
        }
    }
    Some(hi)
}
