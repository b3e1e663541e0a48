//! The FMU's `documentation/index.html`: the page is the template `documentation.html`, whose
//! `{placeholders}` are filled here (escaped) from the model description.
use super::scheme_code;
use crate::fmi::ModelDescription;
use crate::fmi::table::Kind;
use crate::time::Scheme;

const TEMPLATE: &str = include_str!("documentation.html");

/// The page for the model described by `desc`, built from the scene `scene_name` whose units
/// are `units` (e.g. "length mm, force kN, time s").
pub fn render(desc: &ModelDescription, scene_name: &str, units: &str) -> String {
    let esc = |s: &str| quick_xml::escape::escape(s).into_owned();
    let mut rows = String::new();
    for (vr, v) in desc.variables.iter() {
        let (ty, start, unit) = match &v.kind {
            Kind::Real { start, unit, .. } => ("Real", start.map(crate::fmi::fmi2::xml::real), unit.clone()),
            Kind::Integer { start, .. } => ("Integer", start.map(|s| s.to_string()), None),
            Kind::Enumeration { start, .. } => ("Enumeration", start.map(|s| s.to_string()), None),
            Kind::Boolean { start } => ("Boolean", start.map(|s| s.to_string()), None),
            Kind::String { start } => ("String", start.clone(), None),
        };
        rows += &format!(
            "<tr><td><code>{}</code></td><td>{vr}</td><td>{}</td><td>{}</td><td>{ty}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            esc(&v.name),
            v.causality.name(),
            v.variability.name(),
            esc(&start.unwrap_or_default()),
            esc(&unit.unwrap_or_default()),
            esc(&v.description)
        );
    }
    let schemes: String = Scheme::ALL.iter().map(|s| format!("<li>{} = <code>{}</code>: {}</li>", scheme_code(*s), s, esc(scheme_doc(*s)))).collect();
    let fields = [
        ("{scene}", esc(scene_name)),
        ("{desc_name}", esc(&desc.model_name)),
        ("{desc}", esc(&desc.description)),
        ("{scene_file}", super::SCENE_FILE.to_string()),
        ("{tool}", esc(&desc.generation_tool)),
        ("{schemes}", schemes),
        ("{rows}", rows),
        ("{units}", esc(units)),
    ];
    // One pass over the template, so that a value containing "{…}" is never substituted again.
    let mut out = String::with_capacity(TEMPLATE.len() + 4096);
    let mut rest = TEMPLATE;
    while let Some(i) = rest.find('{') {
        out.push_str(&rest[..i]);
        rest = &rest[i..];
        match fields.iter().find(|(key, _)| rest.starts_with(key)) {
            Some((key, value)) => {
                out.push_str(value);
                rest = &rest[key.len()..];
            }
            None => {
                out.push('{');
                rest = &rest[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

fn scheme_doc(s: Scheme) -> &'static str {
    match s {
        Scheme::Bds1 => "first-order backward differences",
        Scheme::Bds2 => "second-order backward differences",
        Scheme::Cds => "central differences",
        Scheme::Galerkin => "Bubnov-Galerkin in time with periodic linear hats",
        Scheme::Fourier => "Fourier time collocation",
    }
}
