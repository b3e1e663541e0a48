//! accuracy.png: one panel per case, error against wall time on log–log axes. Each scheme has one
//! colour: the plain periodic LCP (solid line, filled circles), the same results polished (dashed,
//! filled triangles), and each result's own error estimate as a hollow marker at the same time
//! (hollow circle: Richardson; hollow triangle: the polish's). Time marching in grey, Siconos'
//! Lemke on our LCP in red squares; a reference's own error bound (the chain's) as a grey dashed line.
use super::{AccuracyStudy, Kind, Row};
use crate::Error;
use crate::plot::{Chart, Legend, Line, Look, Scale, Series, styled_panel_chart};
use crate::study::Case;
use crate::time::Scheme;
use std::path::Path;

/// Palette index of a scheme (Tableau 10; red and grey are kept for Siconos and marching).
fn colour(method: &str) -> usize {
    match method.split('/').next().unwrap_or(method) {
        "bds1" => 0,
        "bds2" => 1,
        "cds" => 2,
        "galerkin" => 4,
        "fourier" => 5,
        _ => 8,
    }
}

/// The choices drawn: the converging ones with the scheme's default pairing (the others,
/// first-order forward pairings on compliant contact among them, are in accuracy.md).
fn drawn(case: Case, method: &str) -> bool {
    let mut parts = method.split('/');
    let (Some(scheme), pairing) = (parts.next().and_then(|s| Scheme::ALL.into_iter().find(|x| x.to_string() == s)), parts.next()) else {
        return false;
    };
    let default = scheme.default_pairing(case != Case::Compliant && case != Case::Chain);
    pairing.is_none_or(|p| p == default.name())
}

impl AccuracyStudy {
    fn panel(&self, case: Case) -> (Vec<Series>, Vec<Look>) {
        let (mut series, mut looks) = (Vec::new(), Vec::new());
        let mut push = |label: String, points: Vec<(f64, f64)>, look: Look| {
            if !points.is_empty() || label.starts_with('(') {
                series.push(Series { label, points, markers: look.marker.is_some() });
                looks.push(look);
            }
        };
        let rows = |method: &str, kind: Kind| -> Vec<&Row> { self.ok_rows(case).filter(|r| r.method == method && r.kind == kind).collect() };
        let mut methods: Vec<String> = Vec::new();
        for r in self.ok_rows(case).filter(|r| r.kind == Kind::Periodic && r.converges && drawn(case, &r.method)) {
            if !methods.contains(&r.method) {
                methods.push(r.method.clone());
            }
        }
        for m in &methods {
            let c = colour(m);
            let plain = rows(m, Kind::Periodic);
            let polished = rows(m, Kind::Polished);
            push(
                format!("{m} LCP"),
                plain.iter().map(|r| (r.t_total.unwrap(), r.error_x.unwrap())).collect(),
                Look { colour: c, line: Line::Solid, marker: Some(0), hollow: false },
            );
            push(
                format!("{m} + polish"),
                polished.iter().map(|r| (r.t_total.unwrap(), r.error_x.unwrap())).collect(),
                Look { colour: c, line: Line::Dashed, marker: Some(1), hollow: false },
            );
            let est = |rs: &[&Row]| rs.iter().filter_map(|r| r.estimate.map(|e| (r.t_total.unwrap(), e))).collect::<Vec<_>>();
            push(String::new(), est(&plain), Look { colour: c, line: Line::None, marker: Some(0), hollow: true });
            push(String::new(), est(&polished), Look { colour: c, line: Line::None, marker: Some(1), hollow: true });
        }
        let march = rows("march cds", Kind::Marching);
        push(
            "time marching (cds)".into(),
            march.iter().map(|r| (r.t_total.unwrap(), r.error_x.unwrap())).collect(),
            Look { colour: 7, line: Line::Solid, marker: Some(0), hollow: false },
        );
        let peers: Vec<&Row> = self.ok_rows(case).filter(|r| r.kind == Kind::Siconos).collect();
        if let Some(p) = peers.first() {
            push(
                format!("Siconos Lemke, our LCP ({})", p.method),
                peers.iter().map(|r| (r.t_total.unwrap(), r.error_x.unwrap())).collect(),
                Look { colour: 3, line: Line::None, marker: Some(2), hollow: false },
            );
        }
        let u = self.uncertainty_of(case);
        if u > 0.0 {
            let (lo, hi) = self.ok_rows(case).filter_map(|r| r.t_total).fold((f64::INFINITY, 0.0f64), |(l, h), t| (l.min(t), h.max(t)));
            push(
                format!("the reference's own error bound ({u:.1e})"),
                vec![(lo, u), (hi, u)],
                Look { colour: 7, line: Line::Dashed, marker: None, hollow: false },
            );
        }
        push("(hollow: the run's error estimate)".into(), vec![], Look { colour: 7, line: Line::None, marker: Some(0), hollow: true });
        (series, looks)
    }

    /// One panel per case.
    #[cfg(feature = "plots")]
    pub fn plot(&self, path: &Path) -> Result<(), Error> {
        let titles: Vec<String> = self.settings.cases.iter().map(|c| format!("{}: error vs wall time", c.title())).collect();
        let charts: Vec<Chart> = titles
            .iter()
            .map(|t| Chart {
                title: t,
                x_label: "wall time [s], one thread",
                y_label: "max |x − x_ref| / peak-to-peak [-]",
                x_scale: Scale::Log,
                y_scale: Scale::Log,
            })
            .collect();
        let drawn: Vec<(Vec<Series>, Vec<Look>)> = self.settings.cases.iter().map(|&c| self.panel(c)).collect();
        let panels: Vec<(&Chart, &[Series], &[Look])> = charts.iter().zip(&drawn).map(|(c, (s, l))| (c, s.as_slice(), l.as_slice())).collect();
        let cols = panels.len().min(2);
        let rows = panels.len().div_ceil(cols.max(1)) as u32;
        styled_panel_chart(path, &panels, cols, 1100 * cols as u32, 900 * rows, Legend::Emptiest).map_err(Error::from)
    }
}
