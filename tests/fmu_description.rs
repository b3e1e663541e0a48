//! The variable table and modelDescription.xml of the contact model, without the FMU binary:
//! only the effects a scene calls for have variables; the XML follows the schema's element
//! order with Outputs and InitialUnknowns consistent; the GUID is derived from the content.
use periodic_contact::fmi::fmi2::xml;
use periodic_contact::fmi::table::Causality;
use periodic_contact::fmu_model::ContactModel;
use std::collections::BTreeSet;

const BASE: &str = r#"
[structure]
mass = [[1.0]]
stiffness = [[1.0]]
[damping]
matrix = [[0.1]]
[excitation]
frequency = 1.0
"#;

fn names(text: &str) -> BTreeSet<String> {
    let m = ContactModel::from_scene_text(text, "t").unwrap();
    m.model_description().variables.iter().map(|(_, v)| v.name.clone()).collect()
}

fn set(v: &[&str]) -> BTreeSet<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
fn variables_follow_the_effects() {
    // The error estimate of each solve is an output by default ([discretization] error_estimate).
    let common = ["frequency", "steps", "scheme", "frequency_in", "displacement[0]", "accuracy.estimate", "accuracy.estimated"];
    // No force, no contact: only the frequency and the grid (no LCP, so no LCP diagnostics).
    assert_eq!(names(BASE), set(&common));
    // A force: its scale and input.
    let forced = format!("{BASE}[[force]]\ndof = 0\namplitude = 1.0\n");
    assert_eq!(names(&forced), set(&[&common[..], &["force_scale", "force_scale_in"]].concat()));
    // A static rigid obstacle: gap offset and contact outputs, the polish switch and its outcome,
    // no motion parameters.
    let contact = format!("{forced}[[contact]]\ndof = 0\ngap = 0.5\n");
    // With a contact and a step map (cds by default) the re-solves follow a branch: `jumps`.
    let c = ["gap_offset", "gap_offset_in", "contact[0].force", "contact[0].gap", "lcp.pivots", "lcp.residual", "polish", "polish.status", "jumps"];
    assert_eq!(names(&contact), set(&[&common[..], &["force_scale", "force_scale_in"], &c].concat()));
    // A moving obstacle: motion_scale too.
    let moving = format!("{contact}motion = [{{ amplitude = 0.1, harmonic = 2 }}]\n");
    assert_eq!(names(&moving), set(&[&common[..], &["force_scale", "force_scale_in"], &c, &["motion_scale", "motion_scale_in"]].concat()));
    // [output] decides which responses are outputs.
    let out = format!("{contact}[output]\ndisplacement = []\nvelocity = [0]\nacceleration = [0]\ncontacts = false\n");
    let n = names(&out);
    assert!(n.contains("velocity[0]") && n.contains("acceleration[0]") && !n.contains("displacement[0]") && !n.contains("contact[0].force"));
    assert!(n.contains("lcp.pivots"), "with a contact the LCP diagnostics are there, even without contact outputs");
    assert!(!n.contains("accuracy.estimate"), "no displacement output, nothing to estimate");
    // [output] stability = true: the orbit's stability too; fourier has no step map, so neither.
    let stable = format!("{contact}[output]\ndisplacement = [0]\nstability = true\n");
    assert_eq!(names(&stable), set(&[&common[..], &["force_scale", "force_scale_in"], &c, &["stable", "multiplier"]].concat()));
    let fourier = stable.replace("[output]", "[discretization]\nscheme = \"fourier\"\n[output]");
    let n = names(&fourier);
    assert!(!n.contains("stable") && !n.contains("multiplier") && !n.contains("jumps"), "{n:?}");
    // error_estimate = "none": no second solve, no accuracy outputs.
    let fast = format!("{BASE}[discretization]\nerror_estimate = \"none\"\n");
    assert_eq!(names(&fast), set(&common[..5]));
}

#[test]
fn model_description_order_outputs_and_initial_unknowns() {
    let text = format!(
        "{BASE}[[force]]\ndof = 0\namplitude = 1.0\n[[contact]]\ndof = 0\ngap = 0.5\nmotion = [{{ amplitude = 0.1 }}]\n[output]\ndisplacement = [0]\nvelocity = [0]\n"
    );
    let m = ContactModel::from_scene_text(&text, "t").unwrap();
    let d = m.model_description();
    d.variables.check().unwrap();
    let (doc, guid) = xml::render(d);
    // Schema order of the children of fmiModelDescription.
    let order = ["<CoSimulation", "<UnitDefinitions", "<LogCategories", "<DefaultExperiment", "<ModelVariables", "<ModelStructure"];
    let pos: Vec<usize> = order.iter().map(|e| doc.find(e).unwrap_or_else(|| panic!("{e} missing"))).collect();
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "{pos:?}");
    assert!(doc.find("<Outputs").unwrap() < doc.find("<InitialUnknowns").unwrap());
    // Outputs = every causality="output" (1-based indices); InitialUnknowns the same (all calculated).
    let outputs: Vec<u32> = d.variables.iter().filter(|(_, v)| v.causality == Causality::Output).map(|(vr, _)| vr + 1).collect();
    let section = |name: &str| -> Vec<u32> {
        let s = &doc[doc.find(&format!("<{name}>")).unwrap()..doc.find(&format!("</{name}>")).unwrap()];
        s.match_indices("index=\"").map(|(i, _)| s[i + 7..].split('"').next().unwrap().parse().unwrap()).collect()
    };
    assert_eq!(section("Outputs"), outputs);
    assert_eq!(section("InitialUnknowns"), outputs);
    assert!(doc.contains(&format!("guid=\"{guid}\"")));
    assert!(doc.contains("variableNamingConvention=\"structured\""));
    assert!(doc.contains("modelIdentifier=\"PeriodicContact\""));
    assert!(doc.contains("<Integer min=\"1\" max=\"5\" start=\"3\"/>"), "scheme is an Integer (libcosim ignores Enumerations)");
    assert!(doc.contains("name=\"polish\"") && doc.contains("<Boolean start=\"false\"/>"), "polish: a Boolean parameter, off unless the scene says so");
    // Outputs have no start; parameters and inputs have one.
    for (_, v) in d.variables.iter() {
        let start = match &v.kind {
            periodic_contact::fmi::table::Kind::Real { start, .. } => start.is_some(),
            periodic_contact::fmi::table::Kind::Integer { start, .. } | periodic_contact::fmi::table::Kind::Enumeration { start, .. } => start.is_some(),
            periodic_contact::fmi::table::Kind::Boolean { start } => start.is_some(),
            _ => unreachable!(),
        };
        assert_eq!(start, v.causality != Causality::Output, "{}", v.name);
    }
}

#[test]
fn the_guid_is_derived_from_the_content() {
    let a = ContactModel::from_scene_text(BASE, "a").unwrap();
    let b = ContactModel::from_scene_text(BASE, "another/file/name.toml").unwrap();
    let c = ContactModel::from_scene_text(&BASE.replace("frequency = 1.0", "frequency = 1.1"), "c").unwrap();
    let ga = xml::render(a.model_description()).1;
    assert_eq!(ga, xml::render(b.model_description()).1, "the file name is not content");
    assert_ne!(ga, xml::render(c.model_description()).1, "a different start value is");
    assert_eq!(ga.len(), 38);
}

#[test]
fn invalid_scenes_are_refused_with_the_field() {
    let e = ContactModel::from_scene_text(&BASE.replace("stiffness = [[1.0]]", "stiffness = [[-1.0, 2.0]]"), "bad.toml").err().unwrap();
    let e = e.to_string();
    assert!(e.contains("bad.toml") && e.contains("stiffness"), "{e}");
}

/// Every Real carries its unit in the scene's units, each declared once with its SI factor;
/// contact descriptions say what the gap of each kind of contact is.
#[test]
fn units_of_every_real_and_contact_descriptions() {
    use periodic_contact::fmi::table::Kind;
    let text = format!(
        "{BASE}[units]\nlength = \"mm\"\nforce = \"kN\"\n[[force]]\ndof = 0\namplitude = 1.0\n[[contact]]\ndof = 0\ngap = 0.5\nmotion = [{{ amplitude = 0.1 }}]\n[[contact]]\ndof = 0\ndirection = -1\ngap = 0.5\nstiffness = 100.0\n[output]\ndisplacement = [0]\nvelocity = [0]\nacceleration = [0]\n"
    );
    let m = ContactModel::from_scene_text(&text, "t").unwrap();
    let d = m.model_description();
    d.check().unwrap();
    let unit = |name: &str| -> Option<String> {
        let vr = d.variables.by_name(name).unwrap_or_else(|| panic!("{name}"));
        match &d.variables.get(vr).unwrap().kind {
            Kind::Real { unit, .. } => unit.clone(),
            k => panic!("{name} is {k:?}"),
        }
    };
    let expected = [
        ("frequency", Some("rad/s")),
        ("frequency_in", Some("rad/s")),
        ("force_scale", Some("1")),
        ("force_scale_in", Some("1")),
        ("gap_offset", Some("mm")),
        ("gap_offset_in", Some("mm")),
        ("motion_scale", Some("1")),
        ("displacement[0]", Some("mm")),
        ("velocity[0]", Some("mm/s")),
        ("acceleration[0]", Some("mm/s2")),
        ("contact[0].force", Some("kN")),
        ("contact[1].gap", Some("mm")),
        ("lcp.residual", None),
    ];
    for (name, u) in expected {
        assert_eq!(unit(name).as_deref(), u, "{name}");
    }
    // Every Real but the residual has a unit.
    for (_, v) in d.variables.iter() {
        if let Kind::Real { unit, .. } = &v.kind {
            assert_eq!(unit.is_none(), v.name == "lcp.residual", "{}", v.name);
        }
    }
    let units: Vec<&str> = d.units.iter().map(|u| u.name.as_str()).collect();
    assert_eq!(units, ["rad/s", "1", "mm", "mm/s", "mm/s2", "kN"]);
    let (doc, _) = xml::render(d);
    assert!(doc.contains("<Unit name=\"mm/s2\">\n      <BaseUnit m=\"1\" s=\"-2\" factor=\"0.001\"/>"), "{doc}");
    assert!(doc.contains("<Unit name=\"kN\">\n      <BaseUnit kg=\"1\" m=\"1\" s=\"-2\" factor=\"1000.0\"/>"), "{doc}");
    assert!(doc.contains("<Unit name=\"1\">\n      <BaseUnit/>"), "{doc}");
    assert!(doc.contains("<Real unit=\"mm\"/>"), "{doc}");
    // What the gap is, per kind of contact.
    let text_of = |name: &str| d.variables.get(d.variables.by_name(name).unwrap()).unwrap().description.clone();
    assert!(text_of("contact[0].gap").starts_with("Clearance >= 0 of the rigid contact 0 on DOF 0"), "{}", text_of("contact[0].gap"));
    let compliant = text_of("contact[1].gap");
    assert!(compliant.contains("compliant") && compliant.contains("negative = penetration") && !compliant.contains(">= 0"), "{compliant}");
    assert!(text_of("contact[1].force").contains("stiffness 100 kN/mm"), "{}", text_of("contact[1].force"));
    assert!(d.description.ends_with("(units: mm, kN, s)"), "{}", d.description);
    let html = m.documentation_html("t.toml");
    assert!(html.contains("Units: length mm, force kN, time s (mass kN.s2/mm)") && html.contains("<td>mm/s2</td>"), "{html}");
}
