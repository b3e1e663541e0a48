//! The branch as CSV, its events as JSON, and its response curves as PNG.
use super::Branch;
use crate::model::{Labels, Quantity};
use crate::periodic::PeriodicProblem;

/// One row per point: the parameter (named as given, with its unit), `amplitude_<dof> [unit]`
/// per displacement output as in `sweep`, `stable`, `multiplier` (largest |μ|),
/// `period_multiple`, `event`, `certified`.
pub fn to_csv(branch: &Branch, problem: &PeriodicProblem, labels: &Labels) -> String {
    let mm = labels.unit(Quantity::Length);
    let mut head = vec![format!("{} {}", branch.parameter.name(), labels.unit(branch.parameter.describe().1))];
    head.extend(problem.outputs().displacement.iter().map(|d| format!("amplitude_{d} {mm}")));
    head.extend(["stable", "multiplier", "period_multiple", "event", "certified"].map(String::from));
    let mut s = head.join(",") + "\n";
    for p in &branch.points {
        let mut row = vec![format!("{:e}", p.parameter)];
        row.extend(p.amplitude.iter().map(|a| format!("{a:e}")));
        row.push(p.stable.to_string());
        row.push(format!("{:e}", p.max_multiplier));
        row.push(p.period_multiple.to_string());
        row.push(p.event.map_or(String::new(), |e| e.name().to_string()));
        row.push(p.certified.to_string());
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s
}

/// The events as a JSON array: kind, parameter, amplitudes, largest |μ|, multipliers, detail.
pub fn events_json(branch: &Branch, problem: &PeriodicProblem) -> String {
    let dofs = &problem.outputs().displacement;
    let events: Vec<serde_json::Value> = branch
        .events()
        .map(|p| {
            let amplitude: serde_json::Map<String, serde_json::Value> = dofs.iter().zip(&p.amplitude).map(|(d, a)| (d.to_string(), (*a).into())).collect();
            serde_json::json!({
                "type": p.event.map(|e| e.name()),
                branch.parameter.name(): p.parameter,
                "amplitude": amplitude,
                "max_multiplier": p.max_multiplier,
                "multipliers": p.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
                "stable": p.stable,
                "detail": p.detail,
            })
        })
        .collect();
    serde_json::to_string_pretty(&serde_json::json!({ "parameter": branch.parameter.name(), "stop": branch.stop, "events": events })).unwrap_or_default()
}

/// PNG of displacement output `i` along the branch: stable runs solid, unstable runs dashed in the
/// same colour, each event kind as markers of its own without a line; axes named with units.
#[cfg(feature = "plots")]
pub fn plot(path: &std::path::Path, branch: &Branch, problem: &PeriodicProblem, i: usize, labels: &Labels, title: &str) -> Result<(), crate::Error> {
    use crate::plot::{Chart, Legend, Line, Look, Scale, Series, styled_panel_chart};
    let d = problem.outputs().displacement[i];
    let (mut series, mut looks): (Vec<Series>, Vec<Look>) = (Vec::new(), Vec::new());
    let mut labelled = [false; 2];
    let mut push_run = |run: Vec<(f64, f64)>, stable: bool, series: &mut Vec<Series>, looks: &mut Vec<Look>| {
        // One legend entry per kind of run.
        let label = if std::mem::replace(&mut labelled[stable as usize], true) {
            ""
        } else if stable {
            "stable"
        } else {
            "unstable"
        };
        series.push(Series { label: label.into(), points: run, markers: false });
        looks.push(Look { colour: 0, line: if stable { Line::Solid } else { Line::Dashed }, marker: None, hollow: false });
    };
    let mut run: Vec<(f64, f64)> = Vec::new();
    let mut stable = branch.points.first().is_some_and(|p| p.stable);
    for p in &branch.points {
        let xy = (p.parameter, p.amplitude[i]);
        if p.stable != stable {
            run.push(xy);
            push_run(std::mem::take(&mut run), stable, &mut series, &mut looks);
            stable = p.stable;
        }
        run.push(xy);
    }
    push_run(run, stable, &mut series, &mut looks);
    let kinds = [super::EventKind::Fold, super::EventKind::Grazing, super::EventKind::PeriodDoubling, super::EventKind::NeimarkSacker];
    for (j, kind) in kinds.into_iter().enumerate() {
        let pts: Vec<(f64, f64)> = branch.events().filter(|p| p.event == Some(kind)).map(|p| (p.parameter, p.amplitude[i])).collect();
        if !pts.is_empty() {
            series.push(Series { label: kind.name().into(), points: pts, markers: true });
            looks.push(Look { colour: j + 1, line: Line::None, marker: Some(j % 3), hollow: false });
        }
    }
    let (what, quantity) = branch.parameter.describe();
    let x_label = format!("{what} {}", labels.unit(quantity));
    let y_label = format!("amplitude of {} {} (peak-to-peak / 2)", labels.dof(d), labels.unit(Quantity::Length));
    let title = format!("{title} of {}", labels.dof(d));
    let chart = Chart { title: &title, x_label: &x_label, y_label: &y_label, x_scale: Scale::Linear, y_scale: Scale::Linear };
    styled_panel_chart(path, &[(&chart, &series, &looks)], 1, 1000, 650, Legend::Default).map_err(crate::Error::from)
}
