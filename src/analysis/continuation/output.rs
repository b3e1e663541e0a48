//! The branch as CSV, its events as JSON, and its response curves as PNG.
use super::{Branch, BranchPoint, Parameter};
use crate::model::{Labels, Quantity};
use crate::periodic::PeriodicProblem;

/// One row per point of each branch, in order: the parameter (named as given, with its unit),
/// `amplitude_<dof> [unit]` per displacement output as in `sweep` (over the orbit's period),
/// `stable`, `multiplier` (largest |μ| of the orbit's own monodromy, over p·T), `period_multiple`,
/// `event`, `certified`, `branch` (its index: 0 the T branch, then the switched ones), `source`
/// (`exact`: the exact orbit's branch; `discrete`: the grid's).
pub fn to_csv(branches: &[Branch], problem: &PeriodicProblem, labels: &Labels) -> String {
    let Some(first) = branches.first() else { return String::new() };
    let mut s = csv_header(first.parameter, problem, labels);
    for (b, branch) in branches.iter().enumerate() {
        branch.points.iter().for_each(|p| s.push_str(&csv_row(p, b)));
    }
    s
}

/// The CSV's header line ([`to_csv`]), newline included.
pub fn csv_header(parameter: Parameter, problem: &PeriodicProblem, labels: &Labels) -> String {
    let mm = labels.unit(Quantity::Length);
    let mut head = vec![format!("{} {}", parameter.name(), labels.unit(parameter.describe().1))];
    head.extend(problem.outputs().displacement.iter().map(|d| format!("amplitude_{d} {mm}")));
    head.extend(["stable", "multiplier", "period_multiple", "event", "certified", "branch", "source"].map(String::from));
    head.join(",") + "\n"
}

/// One point's CSV row ([`to_csv`]) on the branch of index `branch`, newline included: a front
/// end writes the rows as the points come, so that a walk stopped short leaves them.
pub fn csv_row(p: &BranchPoint, branch: usize) -> String {
    let mut row = vec![format!("{:e}", p.parameter)];
    row.extend(p.amplitude.iter().map(|a| format!("{a:e}")));
    row.push(p.stable.to_string());
    // Friction orbits have no multipliers (no step map): the cell stays empty.
    row.push(if p.multipliers.is_empty() { String::new() } else { format!("{:e}", p.max_multiplier) });
    row.push(p.period_multiple.to_string());
    row.push(p.event.map_or(String::new(), |e| e.name().to_string()));
    row.push(p.certified.to_string());
    row.push(branch.to_string());
    row.push(p.source.name().to_string());
    row.join(",") + "\n"
}

/// The events as JSON: per event its branch (index and label), period_multiple, kind, parameter,
/// amplitudes, largest |μ|, multipliers, detail; and per branch its label and why it stopped.
pub fn events_json(branches: &[Branch], problem: &PeriodicProblem) -> String {
    let dofs = &problem.outputs().displacement;
    let Some(first) = branches.first() else { return String::new() };
    let name = first.parameter.name();
    let events: Vec<serde_json::Value> = branches
        .iter()
        .enumerate()
        .flat_map(|(b, branch)| branch.events().map(move |p| (b, branch, p)))
        .map(|(b, branch, p)| {
            let amplitude: serde_json::Map<String, serde_json::Value> = dofs.iter().zip(&p.amplitude).map(|(d, a)| (d.to_string(), (*a).into())).collect();
            serde_json::json!({
                "type": p.event.map(|e| e.name()),
                name: p.parameter,
                "branch": b,
                "branch_label": branch.label,
                "period_multiple": p.period_multiple,
                "amplitude": amplitude,
                "max_multiplier": p.max_multiplier,
                "multipliers": p.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
                "stable": p.stable,
                "detail": p.detail,
                "source": p.source.name(),
            })
        })
        .collect();
    let list: Vec<serde_json::Value> = branches
        .iter()
        .map(|b| serde_json::json!({ "label": b.label, "period_multiple": b.period_multiple, "points": b.points.len(), "stop": b.stop }))
        .collect();
    serde_json::to_string_pretty(&serde_json::json!({ "parameter": name, "stop": first.stop, "branches": list, "events": events })).unwrap_or_default()
}

/// PNG of displacement output `i` along the branch: stable runs solid, unstable runs dashed in the
/// same colour, each event kind as hollow markers of its own shape without a line; axes named with units.
#[cfg(feature = "plots")]
pub fn plot(path: &std::path::Path, branches: &[Branch], problem: &PeriodicProblem, i: usize, labels: &Labels, title: &str) -> Result<(), crate::Error> {
    use crate::plot::{Chart, Legend, Line, Look, Scale, Series, styled_panel_chart};
    let d = problem.outputs().displacement[i];
    let (mut series, mut looks): (Vec<Series>, Vec<Look>) = (Vec::new(), Vec::new());
    for (b, branch) in branches.iter().enumerate() {
        let tag = if branch.period_multiple == 1 { String::new() } else { format!("{}T ", branch.period_multiple) };
        // One legend entry per branch and kind of run.
        let mut labelled = [false; 2];
        let mut push_run = |run: Vec<(f64, f64)>, stable: bool, series: &mut Vec<Series>, looks: &mut Vec<Look>| {
            let first = !std::mem::replace(&mut labelled[stable as usize], true);
            let label = if first { format!("{tag}{}", if stable { "stable" } else { "unstable" }) } else { String::new() };
            series.push(Series { label, points: run, markers: false });
            looks.push(Look { colour: b, line: if stable { Line::Solid } else { Line::Dashed }, marker: None, hollow: false });
        };
        let mut run: Vec<(f64, f64)> = Vec::new();
        let mut stable = branch.points.first().is_some_and(|p| p.stable);
        // A point whose certified solve changed its active sets may carry another orbit's
        // amplitude (the CSV flags it `certified = false`): not drawn.
        for p in branch.points.iter().filter(|p| p.certified || p.event.is_some()) {
            let xy = (p.parameter, p.amplitude[i]);
            if p.stable != stable {
                run.push(xy);
                push_run(std::mem::take(&mut run), stable, &mut series, &mut looks);
                stable = p.stable;
            }
            run.push(xy);
        }
        push_run(run, stable, &mut series, &mut looks);
    }
    let kinds = [super::EventKind::Fold, super::EventKind::Grazing, super::EventKind::PeriodDoubling, super::EventKind::NeimarkSacker];
    // Coincident events (a fold under a period doubling) are drawn side by side: each marker
    // moves right by 1.2 % of the axis per earlier marker within 1 % of the axes of its place.
    let extent = |f: &dyn Fn(&(f64, f64)) -> f64| {
        let v = series.iter().flat_map(|s| s.points.iter()).map(f);
        let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)));
        (hi - lo).max(f64::MIN_POSITIVE)
    };
    let (dx, dy) = (extent(&|p| p.0), extent(&|p| p.1));
    let mut placed: Vec<(f64, f64)> = Vec::new();
    for (j, kind) in kinds.into_iter().enumerate() {
        let events = branches.iter().flat_map(|b| b.events()).filter(|p| p.event == Some(kind));
        let pts: Vec<(f64, f64)> = events
            .map(|p| (p.parameter, p.amplitude[i]))
            .map(|(x, y)| {
                let near = placed.iter().filter(|q| (q.0 - x).abs() <= 0.01 * dx && (q.1 - y).abs() <= 0.01 * dy).count();
                (x + 0.012 * dx * near as f64, y)
            })
            .collect();
        placed.extend(branches.iter().flat_map(|b| b.events()).filter(|p| p.event == Some(kind)).map(|p| (p.parameter, p.amplitude[i])));
        if !pts.is_empty() {
            series.push(Series { label: kind.name().into(), points: pts, markers: true });
            // Outlines of distinct shapes: coincident events (a fold under a period doubling) stay visible.
            looks.push(Look { colour: branches.len() + j, line: Line::None, marker: Some(j % 3), hollow: true });
        }
    }
    let (what, quantity) = branches.first().map_or(("parameter", Quantity::Ratio), |b| b.parameter.describe());
    let x_label = format!("{what} {}", labels.unit(quantity));
    let y_label = format!("amplitude of {} {} (peak-to-peak / 2 over the orbit's period)", labels.dof(d), labels.unit(Quantity::Length));
    let title = format!("{title} of {}", labels.dof(d));
    let chart = Chart { title: &title, x_label: &x_label, y_label: &y_label, x_scale: Scale::Linear, y_scale: Scale::Linear };
    styled_panel_chart(path, &[(&chart, &series, &looks)], 1, 1000, 650, Legend::Default).map_err(crate::Error::from)
}
