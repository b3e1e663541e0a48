//! Harmonic content of a periodic response: amplitudes of the harmonics of ω of a displacement
//! and of the contact forces, by FFT of the k samples of one period.
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
    /// (output DOF, amplitudes of harmonics 0..=max_harmonic) per displacement output.
    pub displacement: Vec<(usize, Vec<f64>)>,
    /// (contact index, user DOF, amplitudes) per contact.
    pub force: Vec<(usize, usize, Vec<f64>)>,
}

/// Harmonics 0..=`max_harmonic` (capped at k/2) of every displacement output and contact force.
pub fn spectrum(problem: &PeriodicProblem, response: &Response, max_harmonic: usize) -> Spectrum {
    let fft = PeriodFft::new(response.steps);
    let h = max_harmonic.min(response.steps / 2);
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
    Spectrum { frequency: response_frequency(response), displacement, force }
}

fn response_frequency(r: &Response) -> f64 {
    2.0 * std::f64::consts::PI / r.period
}

/// One CSV for several spectra: parameter, frequency, harmonic, then one column per output and
/// per contact force.
pub fn to_csv(param: &str, values: &[f64], spectra: &[Spectrum]) -> String {
    let Some(first) = spectra.first() else { return String::new() };
    let mut head = vec![param.to_string(), "frequency".into(), "harmonic".into()];
    head.extend(first.displacement.iter().map(|(d, _)| format!("displacement_{d}")));
    head.extend(first.force.iter().map(|(i, d, _)| format!("force_c{i}_dof{d}")));
    let mut s = head.join(",") + "\n";
    for (v, sp) in values.iter().zip(spectra) {
        let nh = sp.displacement.first().map(|x| x.1.len()).or(sp.force.first().map(|x| x.2.len())).unwrap_or(0);
        for p in 0..nh {
            let mut row = vec![v.to_string(), sp.frequency.to_string(), p.to_string()];
            row.extend(sp.displacement.iter().map(|(_, a)| format!("{:e}", a[p])));
            row.extend(sp.force.iter().map(|(_, _, a)| format!("{:e}", a[p])));
            s.push_str(&row.join(","));
            s.push('\n');
        }
    }
    s
}

/// PNG of one spectrum: each series relative to its largest harmonic (log scale), the first
/// displacement output and every contact force.
#[cfg(feature = "plots")]
pub fn plot(path: &std::path::Path, sp: &Spectrum, title: &str) -> Result<(), crate::Error> {
    use crate::plot::{Chart, Scale, Series, line_chart};
    let rel = |a: &[f64]| -> (f64, Vec<(f64, f64)>) {
        let max = a.iter().copied().fold(0.0, f64::max);
        let pts = a.iter().enumerate().skip(1).map(|(p, v)| (p as f64, if max > 0.0 { v / max } else { 0.0 })).collect();
        (max, pts)
    };
    let mut series = Vec::new();
    if let Some((d, a)) = sp.displacement.first() {
        let (max, points) = rel(a);
        series.push(Series { label: format!("displacement of DOF {d} (largest {max:.3e})"), points, markers: true });
    }
    for (i, d, a) in &sp.force {
        let (max, points) = rel(a);
        series.push(Series { label: format!("force of contact {i} on DOF {d} (largest {max:.3e})"), points, markers: true });
    }
    let chart = Chart { title, x_label: "harmonic p of ω", y_label: "amplitude / largest harmonic", x_scale: Scale::Linear, y_scale: Scale::Log };
    line_chart(path, &chart, &series, 1000, 650).map_err(crate::Error::from)
}
