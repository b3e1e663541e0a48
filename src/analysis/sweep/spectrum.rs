//! Harmonic content of a periodic response: amplitudes of the harmonics of ω of a displacement
//! and of the contact forces, by FFT of the samples of the orbit's period. An orbit of p forcing
//! periods (`period_multiple`) has harmonics of ω/p: index j is the harmonic j/p of ω.
use crate::model::{Labels, Quantity};
use crate::periodic::{PeriodFft, PeriodicProblem};
use crate::response::Response;

/// a_0 = |X̂_0|/k (the mean), a_p = 2|X̂_p|/k for 0 < p < k/2, a_{k/2} = |X̂_{k/2}|/k: the
/// amplitude of the cos(p·ω·t + φ_p) term of the series.
pub fn harmonic_amplitudes(fft: &PeriodFft, series: &[f64]) -> Vec<f64> {
    let k = series.len();
    let spec = fft.forward(series);
    spec.iter()
        .enumerate()
        .map(|(p, v)| {
            let twice = p != 0 && !(k.is_multiple_of(2) && p == k / 2);
            v.norm() * if twice { 2.0 } else { 1.0 } / k as f64
        })
        .collect()
}

/// The spectra of one solved point.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    /// ω [rad/s].
    pub frequency: f64,
    /// p: index j of the amplitudes is the harmonic j/p of ω (1: integer harmonics).
    pub period_multiple: usize,
    /// (output DOF, amplitudes of harmonics 0..=max_harmonic) per displacement output.
    pub displacement: Vec<(usize, Vec<f64>)>,
    /// (contact index, user DOF, amplitudes) per contact.
    pub force: Vec<(usize, usize, Vec<f64>)>,
}

/// Harmonics 0..=`max_harmonic` of ω (capped at the Nyquist index), in steps of ω/p for an orbit
/// of p forcing periods, of every displacement output and contact force.
pub fn spectrum(problem: &PeriodicProblem, response: &Response, max_harmonic: usize) -> Spectrum {
    let fft = PeriodFft::new(response.steps);
    let p = response.period_multiple.max(1);
    let h = max_harmonic.saturating_mul(p).min(response.steps / 2);
    let cut = |mut v: Vec<f64>| {
        v.truncate(h + 1);
        v
    };
    let displacement = problem
        .outputs()
        .displacement
        .iter()
        .filter_map(|d| response.displacement.get(&d.to_string()).map(|s| (*d, cut(harmonic_amplitudes(&fft, s)))))
        .collect();
    let force = response.contacts.iter().enumerate().map(|(i, c)| (i, c.dof, cut(harmonic_amplitudes(&fft, &c.force)))).collect();
    Spectrum { frequency: response_frequency(response), period_multiple: p, displacement, force }
}

/// ω: the period is p·2π/ω.
fn response_frequency(r: &Response) -> f64 {
    2.0 * std::f64::consts::PI * r.period_multiple.max(1) as f64 / r.period
}

/// Harmonic index `j` of `sp` in units of ω ("3", or "1.5" for j = 3 of a 2T orbit).
fn harmonic_of(sp: &Spectrum, j: usize) -> String {
    (j as f64 / sp.period_multiple.max(1) as f64).to_string()
}

/// One CSV for several spectra: the parameter (and the frequency when the parameter is not the
/// frequency), harmonic, then one column per output and per contact force, with units as in
/// [`super::to_csv`]. Harmonic 0 is the mean.
pub fn to_csv(param: &str, values: &[f64], spectra: &[Spectrum], labels: &Labels) -> String {
    let Some(first) = spectra.first() else { return String::new() };
    let hz = labels.unit(Quantity::Frequency);
    let mut head = vec![format!("{param} {hz}")];
    if param != "frequency" {
        head.push(format!("frequency {hz}"));
    }
    head.push("harmonic".into());
    let (mm, kn) = (labels.unit(Quantity::Length), labels.unit(Quantity::Force));
    head.extend(first.displacement.iter().map(|(d, _)| format!("displacement_{d} {mm}")));
    head.extend(first.force.iter().map(|(i, d, _)| format!("force_c{i}_dof{d} {kn}")));
    let mut s = head.join(",") + "\n";
    for (v, sp) in values.iter().zip(spectra) {
        let nh = sp.displacement.first().map(|x| x.1.len()).or(sp.force.first().map(|x| x.2.len())).unwrap_or(0);
        for p in 0..nh {
            let mut row = vec![v.to_string()];
            if param != "frequency" {
                row.push(sp.frequency.to_string());
            }
            row.push(harmonic_of(sp, p));
            row.extend(sp.displacement.iter().map(|(_, a)| format!("{:e}", a[p])));
            row.extend(sp.force.iter().map(|(_, _, a)| format!("{:e}", a[p])));
            s.push_str(&row.join(","));
            s.push('\n');
        }
    }
    s
}

/// PNG of one spectrum, absolute levels in the scene's units as stems on a log axis, harmonic 0
/// (the mean) included: the displacement outputs in one panel, the contact forces in the other.
/// Levels below 1e-9 of a panel's largest are round-off and left out; several curves in a panel
/// stand side by side around each harmonic, so that equal levels do not hide each other.
#[cfg(feature = "plots")]
pub fn plot(path: &std::path::Path, sp: &Spectrum, labels: &Labels, title: &str) -> Result<(), crate::Error> {
    use crate::plot::{Chart, Legend, Line, Look, Scale, Series, styled_panel_chart};
    let series = |curves: Vec<(String, &Vec<f64>)>| -> (Vec<Series>, Vec<Look>) {
        let floor = 1e-9 * curves.iter().flat_map(|(_, a)| a.iter().copied()).fold(0.0, f64::max);
        let n = curves.len();
        let width = 0.5 / sp.period_multiple.max(1) as f64;
        curves
            .into_iter()
            .enumerate()
            .map(|(c, (label, a))| {
                let shift = if n > 1 { width * (c as f64 / (n - 1) as f64 - 0.5) } else { 0.0 };
                let points: Vec<(f64, f64)> =
                    a.iter().enumerate().filter(|(_, v)| **v > floor).map(|(j, v)| (j as f64 / sp.period_multiple.max(1) as f64 + shift, *v)).collect();
                let label = if points.is_empty() { format!("{label} (zero)") } else { label };
                (Series { label, points, markers: true }, Look { colour: c, line: Line::Stems, marker: Some(0), hollow: false })
            })
            .unzip()
    };
    let shown = series(sp.displacement.iter().map(|(d, a)| (labels.dof(*d), a)).collect());
    let forces = series(sp.force.iter().map(|(i, d, a)| (format!("contact {i} at {}", labels.dof(*d)), a)).collect());
    let (y1, y2) = (format!("displacement amplitude {}", labels.unit(Quantity::Length)), format!("contact force amplitude {}", labels.unit(Quantity::Force)));
    let (t1, t2) = (format!("{title}: displacement"), format!("{title}: contact force"));
    let p = sp.period_multiple.max(1);
    let x_label = if p == 1 { "harmonic of ω (0: mean)".to_string() } else { format!("harmonic of ω (0: mean; steps of ω/{p}, an orbit of {p} periods)") };
    let c1 = Chart { title: &t1, x_label: &x_label, y_label: &y1, x_scale: Scale::Linear, y_scale: Scale::Log };
    let c2 = Chart { title: &t2, x_label: &x_label, y_label: &y2, x_scale: Scale::Linear, y_scale: Scale::Log };
    let panels = [(&c1, shown.0.as_slice(), shown.1.as_slice()), (&c2, forces.0.as_slice(), forces.1.as_slice())];
    styled_panel_chart(path, &panels, 1, 1000, 1100, Legend::UpperRight).map_err(crate::Error::from)
}
