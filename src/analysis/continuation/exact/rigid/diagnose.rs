//! What goes singular where the corrector stalls (`PC_TRACE_UNMERGE` set): the augmented
//! Jacobian's smallest singular value and the unknowns and conditions it involves, the short
//! steps' fate, and each massless rigid contact's landing rate, release rate and interior
//! extrema (on a massless contact the force and clearance are continuous, so the margin's
//! minimum sits at zero at every landing and release and says nothing there).
use super::super::family::Node;
use super::super::{MAX_DRIFT, MIN_COS, Walk, signature};
use crate::analysis::polish::EventKind as Switch;
use nalgebra::DMatrix;

impl Walk<'_> {
    /// The stall's diagnosis on stderr (nothing without `PC_TRACE_UNMERGE`).
    pub(super) fn diagnose_stall(&self, here: &Node) {
        if std::env::var_os("PC_TRACE_UNMERGE").is_none() {
            return;
        }
        let (fam, d, ne) = (&self.fam, self.fam.dim(), self.fam.ne());
        let n2 = d - 1 - ne;
        let name = |i: usize| {
            if i < n2 {
                format!("state {i}")
            } else if i < n2 + ne {
                let ev = fam.sig.events[i - n2];
                format!("θ{} (contact {} {:?}, at {:.9})", i - n2, ev.contact, ev.kind, here.w[i])
            } else {
                "λ".into()
            }
        };
        if let Some(jac) = fam.jacobian(&here.w) {
            let mut a = DMatrix::zeros(d, d);
            a.view_mut((0, 0), (d - 1, d)).copy_from(&jac);
            let t = fam.metric.unit(&here.tangent);
            for c in 0..d {
                a[(d - 1, c)] = fam.metric.lower(&t)[c];
            }
            let svd = a.clone().svd(true, true);
            let (u, vt) = (svd.u.expect("asked"), svd.v_t.expect("asked"));
            let s = &svd.singular_values;
            let k = s.imin();
            let mut sorted: Vec<f64> = s.iter().copied().collect();
            sorted.sort_by(f64::total_cmp);
            eprintln!("diagnose: augmented Jacobian {d}×{d}: σ_min {:e}, next {:e} {:e}, σ_max {:e}", sorted[0], sorted[1], sorted[2], sorted[d - 1]);
            let top = |v: Vec<f64>, what: &str| {
                let mut idx: Vec<usize> = (0..v.len()).collect();
                idx.sort_by(|&x, &y| v[y].abs().total_cmp(&v[x].abs()));
                for &i in idx.iter().take(6) {
                    eprintln!("diagnose:   {what} {:+.4} {}", v[i], if what == "row" { row_name(i, n2, ne, &name) } else { name(i) });
                }
            };
            top(vt.row(k).iter().copied().collect(), "unknown");
            top(u.column(k).iter().copied().collect(), "row");
        }
        // Short steps along the tangent: which acceptance fails.
        let along = fam.metric.unit(&here.tangent);
        let normal = fam.metric.lower(&along);
        for step in [1e-6, 1e-8, 1e-10] {
            let pred: Vec<f64> = here.w.iter().zip(&along).map(|(w, t)| w + step * t).collect();
            let target: f64 = normal.iter().zip(&pred).map(|(a, b)| a * b).sum();
            let w = fam.correct(&pred, &normal, target).ok();
            let n = w.clone().and_then(|w| fam.node_with(w, &along, false));
            let verdict = n.as_ref().map(|n| {
                let drift = fam.metric.norm(&n.w.iter().zip(&pred).map(|(a, b)| a - b).collect::<Vec<_>>());
                let turn = fam.metric.dot(&fam.metric.unit(&n.tangent), &along);
                format!(
                    "drift/step {:.3e} (≤ {MAX_DRIFT}), turn {turn:.6} (≥ {MIN_COS}), reversed {}, collapsed {}",
                    drift / step,
                    signature::reversed(fam, &n.w),
                    signature::collapsed(fam, &pred, &n.w)
                )
            });
            eprintln!("diagnose: step {step:e}: corrected {}, node {}, {verdict:?}", w.is_some(), n.is_some());
        }
        self.diagnose_contacts(here);
    }

    /// Each massless rigid contact's landings (clearance rate before), releases (force rate
    /// before) and the smallest interior minima of the held forces and clearances.
    fn diagnose_contacts(&self, here: &Node) {
        let o = &here.orbit;
        let (p, model) = (o.period(), self.problem.model());
        let ne = o.events().len();
        let mut rates = Vec::new();
        let h = 1e-7 * p;
        for (e, (ev, &t)) in o.events().iter().zip(o.times()).enumerate() {
            let c = ev.contact;
            match ev.kind {
                Switch::Impact { stick: true } => rates.push((o.clearance_rate(c, t - h).abs(), e, c, "landing: |clearance rate| before", t / p)),
                Switch::Release => rates.push(((o.contact_force(c, t - 2.0 * h) - o.contact_force(c, t - h)) / h, e, c, "release: −force rate before", t / p)),
                _ => {}
            }
        }
        let (mut xs, mut fs) = (0.0f64, 0.0f64);
        let samples = 400;
        let mut values: Vec<Vec<(f64, usize, bool, f64)>> = vec![Vec::new(); ne];
        for e in 0..ne {
            let (a, b) = (o.times()[e], if e + 1 < ne { o.times()[e + 1] } else { o.times()[0] + p });
            for j in 1..samples {
                let t = a + (b - a) * j as f64 / samples as f64;
                let forces = o.contact_forces(t);
                for c in (0..model.contacts.len()).filter(|&c| model.contacts[c].is_rigid()) {
                    let g = o.clearance_at(c, t);
                    let held = g.abs() < 1e-14 || forces[c] != 0.0;
                    let v = if held { forces[c] } else { g };
                    if held {
                        fs = fs.max(v.abs())
                    } else {
                        xs = xs.max(v.abs())
                    }
                    values[e].push((t, c, held, v));
                }
            }
        }
        let wr = model.frequency;
        rates.sort_by(|a, b| {
            (a.0 / if a.3.starts_with('l') { xs * wr } else { fs * wr }).total_cmp(&(b.0 / if b.3.starts_with('l') { xs * wr } else { fs * wr }))
        });
        eprintln!("diagnose: clearance scale {xs:e}, force scale {fs:e}; the 6 slowest landings and releases (rate over scale·ω):");
        for (r, e, c, what, at) in rates.iter().take(6) {
            let scale = if what.starts_with('l') { xs * wr } else { fs * wr };
            eprintln!("diagnose:   event {e} contact {c} at {at:.9}: {what} {:e}", r / scale);
        }
        // Interior local minima per phase and contact (sampled; the ends excluded).
        let mut minima = Vec::new();
        let nc = model.contacts.len();
        for (e, vals) in values.iter().enumerate() {
            for c in 0..nc {
                let s: Vec<&(f64, usize, bool, f64)> = vals.iter().filter(|v| v.1 == c).collect();
                for i in 1..s.len().saturating_sub(1) {
                    if s[i].2 == s[i - 1].2 && s[i].2 == s[i + 1].2 && s[i].3 <= s[i - 1].3 && s[i].3 <= s[i + 1].3 {
                        let rel = s[i].3 / if s[i].2 { fs } else { xs };
                        minima.push((rel, e, c, s[i].2, s[i].0 / p));
                    }
                }
            }
        }
        minima.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (rel, e, c, held, at) in minima.iter().take(6) {
            eprintln!("diagnose:   interior minimum of contact {c}'s {} in phase {e} at {at:.9}: {rel:e}", if *held { "force" } else { "clearance" });
        }
    }
}

/// The residual row `i`'s name: the shooting's state rows, then one condition per event.
fn row_name(i: usize, n2: usize, ne: usize, name: &dyn Fn(usize) -> String) -> String {
    if i < n2 {
        format!("state row {i}")
    } else if i < n2 + ne {
        format!("condition of {}", name(i))
    } else {
        "the arclength row".into()
    }
}
