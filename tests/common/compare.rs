//! Comparing two responses, for the tests that hold one solver to another
//! (`use crate::common::compare;`).
use periodic_contact::response::Response;

pub fn max_abs<'a>(v: impl IntoIterator<Item = &'a f64>) -> f64 {
    v.into_iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Largest difference of the contact forces (relative to max(1, max force)) and of the recovered
/// displacements (relative to max(1, max |x|)) between two responses.
pub fn difference(a: &Response, b: &Response) -> f64 {
    let mut d = 0.0f64;
    for (ca, cb) in a.contacts.iter().zip(&b.contacts) {
        let scale = max_abs(&cb.force).max(1.0);
        d = d.max(ca.force.iter().zip(&cb.force).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale);
    }
    for (key, xb) in &b.displacement {
        let scale = max_abs(xb).max(1.0);
        d = d.max(a.displacement[key].iter().zip(xb).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale);
    }
    d
}
