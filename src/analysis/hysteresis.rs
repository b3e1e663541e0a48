//! Hysteresis loops of friction contacts: the friction force against the contact's relative
//! displacement over one period, and the area they enclose (src/formulation.md §9).
//!
//! Sign convention (as `model::Friction`): f acts on the structure as −bᵀf and has the sign of
//! the slip: the loop runs clockwise in (u, f) (f = +μN while u grows) and ∮ f du > 0 is the
//! energy the contact takes out of the structure per cycle. For a Jenkins element u = s + f/k_t
//! (slider s plus the spring), and ∮ f du = ∮ f ds because ∮ f df = 0: the loop's area is the
//! slider's work, the `dissipated_energy` of the result.
use crate::response::FrictionResponse;

/// The loop of one friction contact: (u_j, f_j) at the instants, closed by repeating the first.
pub fn friction_loop(f: &FrictionResponse) -> Vec<(f64, f64)> {
    let mut points: Vec<(f64, f64)> = f.displacement.iter().copied().zip(f.force.iter().copied()).collect();
    if let Some(&first) = points.first() {
        points.push(first);
    }
    points
}

/// ∮ f du over a closed polygon (u_j, f_j) by the trapezoidal rule (the shoelace formula):
/// positive when the loop runs clockwise (f high while u grows), i.e. when the contact dissipates.
pub fn loop_area(points: &[(f64, f64)]) -> f64 {
    points.windows(2).map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0)).sum()
}

/// An energy as a person writes it: `2.014` or `3.2e-7`, never `2.014e0`.
pub fn energy_text(e: f64) -> String {
    if e == 0.0 || (1e-3..1e4).contains(&e.abs()) {
        // Four significant digits.
        let decimals = (3 - e.abs().log10().floor() as i32).max(0) as usize;
        format!("{e:.decimals$}")
    } else {
        format!("{e:.3e}")
    }
}

/// What the plot labels a friction contact with: its scene DOF and the scene's labels.
#[cfg(feature = "plots")]
pub struct LoopLabels<'a> {
    /// The scene DOF each friction contact slides along, in scene order.
    pub dofs: &'a [usize],
    pub labels: &'a crate::model::Labels,
}

/// PNG of every friction contact's loop, one panel each: the closed loop, its stuck instants as
/// hollow markers, the slip force ±μN as dashed lines, and the energy per cycle in the title.
#[cfg(feature = "plots")]
pub fn plot_hysteresis(path: &std::path::Path, frictions: &[FrictionResponse], names: &LoopLabels) -> Result<(), crate::Error> {
    use crate::model::Quantity;
    use crate::plot::{Chart, Legend, Line, Look, Scale, Series, styled_panel_chart};
    let units = &names.labels.units;
    let (len, force) = (units.name(Quantity::Length), units.name(Quantity::Force));
    let mut titles = Vec::new();
    let mut axes = Vec::new();
    let mut curves = Vec::new();
    for (i, f) in frictions.iter().enumerate() {
        let dof = names.labels.dof(names.dofs.get(i).copied().unwrap_or(usize::MAX));
        let element = match f.stiffness {
            Some(kt) => format!("Jenkins, k_t = {kt}"),
            None => "rigid Coulomb".to_string(),
        };
        let mu_n = f.coefficient * f.normal_force;
        // A coupled contact's bound μλ_n varies over the period: no constant ±μN lines.
        let bound = f.contact.map_or(format!("μN = {mu_n}"), |c| format!("slip force μ·λ_n of contact[{c}], μ = {}", f.coefficient));
        titles.push(format!("friction[{i}] on {dof} ({element}, {bound}): {} {force}·{len} dissipated per cycle", energy_text(f.dissipated_energy)));
        axes.push((format!("relative displacement u of {dof} [{len}]"), format!("friction force f [{force}] (on the structure: −f)")));
        let points = friction_loop(f);
        let (lo, hi) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p.0), h.max(p.0)));
        let limit = |v: f64| if f.contact.is_some() { Vec::new() } else { vec![(lo, v), (hi, v)] };
        let stuck: Vec<(f64, f64)> = f.stuck.iter().zip(&points).filter(|(s, _)| **s).map(|(_, p)| *p).collect();
        let stuck_label = if stuck.is_empty() { String::new() } else { format!("stuck ({} of {} instants)", stuck.len(), f.stuck.len()) };
        curves.push((
            vec![
                Series { label: "f against u over one period".into(), points, markers: false },
                Series { label: stuck_label, points: stuck, markers: true },
                Series { label: if f.contact.is_some() { String::new() } else { "slip force ±μN".into() }, points: limit(mu_n), markers: false },
                Series { label: String::new(), points: limit(-mu_n), markers: false },
            ],
            vec![
                Look { colour: 0, line: Line::Solid, marker: None, hollow: false },
                Look { colour: 3, line: Line::None, marker: Some(0), hollow: true },
                Look { colour: 7, line: Line::Dashed, marker: None, hollow: false },
                Look { colour: 7, line: Line::Dashed, marker: None, hollow: false },
            ],
        ));
    }
    let charts: Vec<Chart> =
        titles.iter().zip(&axes).map(|(t, (x, y))| Chart { title: t, x_label: x, y_label: y, x_scale: Scale::Linear, y_scale: Scale::Linear }).collect();
    let panels: Vec<_> = charts.iter().zip(&curves).map(|(c, (s, l))| (c, s.as_slice(), l.as_slice())).collect();
    let rows = panels.len().max(1) as u32;
    styled_panel_chart(path, &panels, 1, 1000, 650 * rows, Legend::Middle).map_err(crate::Error::from)
}
