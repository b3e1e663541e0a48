//! The point where an orbit of a fixed signature stops being admissible, by bisection in λ.
use super::super::BRACKET;
use super::super::family::{Family, Node, lambda_axis};
use super::{TOL, landing, margin, trace};

/// The point between λ = `la` and `lb` where the orbit of the family's signature (corrected at λ
/// fixed from `guess`'s unknowns) stops being admissible: bisection in λ on the sign of its
/// rigid margin, to [`BRACKET`] of the range; the node on the admissible side, its tangent
/// pointing away from the inadmissible one. Where the margin there is a landing's lift-off (its
/// micro-flight just visible), the point is where that landing's force crosses zero
/// ([`landing::landing_zero`]). `None` without a sign change or where the corrector fails, and,
/// with `own`, where the margin that breaks is another contact's: a merge of `own`'s phase
/// searched ahead whose merged orbit is admissible at `la` already (the merge is there, to
/// resolution) meets the next change instead, and the branch oriented away from it walks back
/// over the old one (the coarse rigid blade at 2398.27 rad/s: contact 0's flight merged at
/// contact 2's landing 0.005 rad/s on, the walk turned back down to 2150; validation/RECORD.md).
/// The same holds where it is `own`'s margin that breaks further on: `own` touching again is its
/// next change, and a merge is only sought where the merged orbit turns admissible (the real blade
/// at 1247.0821284 rad/s: contact 1's held arc merged at its own re-touch 0.06 rad/s on, and the
/// walk turned back up to 1300).
pub(super) fn touch_point(fam: &mut Family, guess: &[f64], (la, lb): (f64, f64), own: Option<usize>) -> Option<Node> {
    let (rho, d) = (fam.rho, fam.dim());
    let e_l = lambda_axis(d);
    // The orbit at λ from the unknowns `from`: (node, admissible).
    let at = |fam: &mut Family, from: &[f64], lambda: f64| -> Option<(Node, bool)> {
        let mut g = from.to_vec();
        g[d - 1] = lambda / rho;
        let w = correct_far(fam, &g, &e_l, lambda / rho)?;
        let n = fam.node_with(w, &e_l, false)?;
        let ok = margin(&n) >= -TOL;
        Some((n, ok))
    };
    let a = at(fam, guess, la)?;
    let b = at(fam, &a.0.w, lb)?;
    let (mut ok, mut bad, mut lok, mut lbad) = match (a.1, b.1) {
        (true, false) if own.is_some() => {
            trace(format_args!("touch point: the merged orbit is admissible at {la:.10} already (the merge is there), not at {lb:.10}: refused"));
            return None;
        }
        (true, false) => (a.0, b.0, la, lb),
        (false, true) => (b.0, a.0, lb, la),
        _ => return None,
    };
    while (lok - lbad).abs() > BRACKET * rho {
        let mid = 0.5 * (lok + lbad);
        match at(fam, &ok.w, mid)? {
            (n, true) => (ok, lok) = (n, mid),
            (n, false) => (bad, lbad) = (n, mid),
        }
    }
    if let Some(m) = bad.rigid_margin().filter(|m| own.is_some_and(|c| m.contact != c)) {
        trace(format_args!("touch point: {lbad:.10} breaks contact {}'s {}, not the merging contact's: refused", m.contact, m.what));
        return None;
    }
    let away = (lok - lbad).signum();
    trace(format_args!(
        "touch point: {lok:.10} admissible, {lbad:.10} not: {:?}, lifted {:?}; landing forces {:?} / {:?}",
        bad.rigid_margin().map(|m| (m.what, m.value, m.contact, m.time / bad.orbit.period(), m.event)),
        landing::lifted(&bad),
        (0..ok.orbit.events().len()).filter_map(|e| ok.orbit.landing_force(e).map(|h| (e, ok.orbit.times()[e] / ok.orbit.period(), h))).collect::<Vec<_>>(),
        (0..bad.orbit.events().len()).filter_map(|e| bad.orbit.landing_force(e).map(|h| (e, h))).collect::<Vec<_>>()
    ));
    if let Some(e) = landing::lifted(&bad) {
        // The zero lies on the admissible side of the visible lift-off: bracketed a short way on.
        let on = lok + away * 1e-4 * rho;
        // Without a zero there, the held orbit is admissible by the lift-off tolerance alone
        // (its landing force far from zero): not the change sought.
        return landing::landing_zero(fam, &bad.w, e, (lbad, on), away).map(|z| z.0);
    }
    let prev: Vec<f64> = e_l.iter().map(|x| x * away).collect();
    fam.node(ok.w, &prev)
}

/// [`Family::correct`] from a guess whose state may lie further than the state scale from the
/// solution (the orbit without an impact, guessed from the impacting one far from the grazing):
/// where Newton's first steps exceed the scale, corrected on a 10× and 100× coarser state scale
/// first, then on the family's own.
fn correct_far(fam: &mut Family, guess: &[f64], normal: &[f64], target: f64) -> Option<Vec<f64>> {
    if let Ok(w) = fam.correct(guess, normal, target) {
        return Some(w);
    }
    let (ys, states) = (fam.ys, fam.dim() - 1 - fam.ne());
    for f in [10.0, 100.0] {
        fam.ys = ys * f;
        let g: Vec<f64> = guess.iter().enumerate().map(|(i, w)| if i < states { w / f } else { *w }).collect();
        let coarse = fam.correct(&g, normal, target).ok();
        fam.ys = ys;
        let fine = coarse.map(|w| w.iter().enumerate().map(|(i, w)| if i < states { w * f } else { *w }).collect::<Vec<f64>>());
        if let Some(w) = fine.and_then(|w| fam.correct(&w, normal, target).ok()) {
            return Some(w);
        }
    }
    None
}
