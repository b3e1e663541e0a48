//! `modelDescription.xml` from a [`ModelDescription`], written with quick-xml in the schema's
//! element order: CoSimulation, UnitDefinitions, TypeDefinitions, LogCategories,
//! DefaultExperiment, ModelVariables, ModelStructure (Outputs, InitialUnknowns).
//! The GUID is the content hash of the document rendered with an empty guid.
use super::logger::CATEGORIES;
use crate::fmi::ModelDescription;
use crate::fmi::table::Kind;
use quick_xml::Writer;
use quick_xml::events::{BytesDecl, Event};
use std::io;

/// The document and its GUID.
pub fn render(md: &ModelDescription) -> (String, String) {
    let guid = crate::fmi::guid::from_content(write(md, "").as_bytes());
    (write(md, &guid), guid)
}

/// xs:double text that reads back to the same f64 ("1.0", "0.1", "1e-7").
pub fn real(v: f64) -> String {
    if v.is_nan() {
        "NaN".into()
    } else if v.is_infinite() {
        if v > 0.0 { "INF".into() } else { "-INF".into() }
    } else {
        format!("{v:?}")
    }
}

fn bool_attr(b: bool) -> &'static str {
    if b { "true" } else { "false" }
}

fn write(md: &ModelDescription, guid: &str) -> String {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    document(&mut w, md, guid).expect("writing to a Vec cannot fail");
    let mut s = String::from_utf8(w.into_inner()).expect("quick-xml writes UTF-8");
    s.push('\n');
    s
}

fn document(w: &mut Writer<Vec<u8>>, md: &ModelDescription, guid: &str) -> io::Result<()> {
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    w.create_element("fmiModelDescription")
        .with_attribute(("fmiVersion", "2.0"))
        .with_attribute(("modelName", md.model_name.as_str()))
        .with_attribute(("guid", guid))
        .with_attribute(("description", md.description.as_str()))
        .with_attribute(("generationTool", md.generation_tool.as_str()))
        .with_attribute(("variableNamingConvention", "structured"))
        .with_attribute(("numberOfEventIndicators", "0"))
        .write_inner_content(|w| {
            let order = md.max_output_derivative_order.to_string();
            w.create_element("CoSimulation")
                .with_attribute(("modelIdentifier", md.model_identifier.as_str()))
                .with_attribute(("needsExecutionTool", "false"))
                .with_attribute(("canHandleVariableCommunicationStepSize", "true"))
                .with_attribute(("canInterpolateInputs", "false"))
                .with_attribute(("maxOutputDerivativeOrder", order.as_str()))
                .with_attribute(("canRunAsynchronuously", "false"))
                .with_attribute(("canBeInstantiatedOnlyOncePerProcess", "false"))
                .with_attribute(("canNotUseMemoryManagementFunctions", "true"))
                .with_attribute(("canGetAndSetFMUstate", "true"))
                .with_attribute(("canSerializeFMUstate", "true"))
                .with_attribute(("providesDirectionalDerivative", "false"))
                .write_empty()?;
            if !md.units.is_empty() {
                w.create_element("UnitDefinitions").write_inner_content(|w| {
                    for u in &md.units {
                        w.create_element("Unit").with_attribute(("name", u.name.as_str())).write_inner_content(|w| {
                            let mut exps: Vec<(&str, String)> = u.base.iter().map(|(k, e)| (*k, e.to_string())).collect();
                            if u.factor != 1.0 {
                                exps.push(("factor", real(u.factor)));
                            }
                            w.create_element("BaseUnit").with_attributes(exps.iter().map(|(k, v)| (*k, v.as_str()))).write_empty()?;
                            Ok(())
                        })?;
                    }
                    Ok(())
                })?;
            }
            if !md.enumerations.is_empty() {
                w.create_element("TypeDefinitions").write_inner_content(|w| {
                    for e in &md.enumerations {
                        w.create_element("SimpleType").with_attribute(("name", e.name.as_str())).write_inner_content(|w| {
                            w.create_element("Enumeration").write_inner_content(|w| {
                                for (name, value, desc) in &e.items {
                                    w.create_element("Item")
                                        .with_attribute(("name", name.as_str()))
                                        .with_attribute(("value", value.to_string().as_str()))
                                        .with_attribute(("description", desc.as_str()))
                                        .write_empty()?;
                                }
                                Ok(())
                            })?;
                            Ok(())
                        })?;
                    }
                    Ok(())
                })?;
            }
            w.create_element("LogCategories").write_inner_content(|w| {
                for (name, desc) in CATEGORIES {
                    w.create_element("Category").with_attribute(("name", name)).with_attribute(("description", desc)).write_empty()?;
                }
                Ok(())
            })?;
            if let Some(x) = &md.default_experiment {
                w.create_element("DefaultExperiment")
                    .with_attribute(("startTime", real(x.start_time).as_str()))
                    .with_attribute(("stopTime", real(x.stop_time).as_str()))
                    .with_attribute(("stepSize", real(x.step_size).as_str()))
                    .write_empty()?;
            }
            w.create_element("ModelVariables").write_inner_content(|w| {
                for (vr, v) in md.variables.iter() {
                    let mut el = w
                        .create_element("ScalarVariable")
                        .with_attribute(("name", v.name.as_str()))
                        .with_attribute(("valueReference", vr.to_string().as_str()));
                    if !v.description.is_empty() {
                        el = el.with_attribute(("description", v.description.as_str()));
                    }
                    el = el.with_attribute(("causality", v.causality.name())).with_attribute(("variability", v.variability.name()));
                    if let Some(i) = v.initial {
                        el = el.with_attribute(("initial", i.name()));
                    }
                    el.write_inner_content(|w| type_element(w, &v.kind))?;
                }
                Ok(())
            })?;
            w.create_element("ModelStructure").write_inner_content(|w| {
                let outputs: Vec<u32> = md.variables.outputs().collect();
                if !outputs.is_empty() {
                    w.create_element("Outputs").write_inner_content(|w| unknowns(w, &outputs))?;
                }
                let initial: Vec<u32> = md.variables.initial_unknowns().collect();
                if !initial.is_empty() {
                    w.create_element("InitialUnknowns").write_inner_content(|w| unknowns(w, &initial))?;
                }
                Ok(())
            })?;
            Ok(())
        })?;
    Ok(())
}

/// `<Unknown index=…/>` with 1-based positions in ModelVariables (= vr + 1 here).
fn unknowns(w: &mut Writer<Vec<u8>>, vrs: &[u32]) -> io::Result<()> {
    for vr in vrs {
        w.create_element("Unknown").with_attribute(("index", (vr + 1).to_string().as_str())).write_empty()?;
    }
    Ok(())
}

fn type_element(w: &mut Writer<Vec<u8>>, kind: &Kind) -> io::Result<()> {
    let mut attrs: Vec<(&str, String)> = Vec::new();
    let name = match kind {
        Kind::Real { start, unit, min, max } => {
            if let Some(u) = unit {
                attrs.push(("unit", u.clone()));
            }
            if let Some(m) = min {
                attrs.push(("min", real(*m)));
            }
            if let Some(m) = max {
                attrs.push(("max", real(*m)));
            }
            if let Some(s) = start {
                attrs.push(("start", real(*s)));
            }
            "Real"
        }
        Kind::Integer { start, min, max } => {
            if let Some(m) = min {
                attrs.push(("min", m.to_string()));
            }
            if let Some(m) = max {
                attrs.push(("max", m.to_string()));
            }
            if let Some(s) = start {
                attrs.push(("start", s.to_string()));
            }
            "Integer"
        }
        Kind::Boolean { start } => {
            if let Some(s) = start {
                attrs.push(("start", bool_attr(*s).into()));
            }
            "Boolean"
        }
        Kind::String { start } => {
            if let Some(s) = start {
                attrs.push(("start", s.clone()));
            }
            "String"
        }
        Kind::Enumeration { declared_type, start } => {
            attrs.push(("declaredType", declared_type.clone()));
            if let Some(s) = start {
                attrs.push(("start", s.to_string()));
            }
            "Enumeration"
        }
    };
    w.create_element(name).with_attributes(attrs.iter().map(|(k, v)| (*k, v.as_str()))).write_empty()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi::DefaultExperiment;
    use crate::fmi::table::*;

    fn description() -> ModelDescription {
        let mut t = VariableTable::new();
        t.push(Variable::parameter("mode", Variability::Fixed, Kind::Enumeration { declared_type: "Mode".into(), start: Some(2) }, "a <mode> & \"more\""));
        t.push(Variable::input("u", 0.5, Some("rad/s"), ""));
        t.push(Variable::output("y[0]", Variability::Continuous, Kind::Real { start: None, unit: None, min: None, max: None }, ""));
        t.push(Variable::output("n", Variability::Discrete, Kind::Integer { start: None, min: None, max: None }, ""));
        ModelDescription {
            model_name: "M".into(),
            model_identifier: "M".into(),
            description: "d".into(),
            generation_tool: "t".into(),
            variables: t,
            units: vec![
                UnitDefinition { name: "rad/s".into(), base: vec![("s", -1), ("rad", 1)], factor: 1.0 },
                UnitDefinition { name: "mm".into(), base: vec![("m", 1)], factor: 1e-3 },
            ],
            enumerations: vec![EnumerationType { name: "Mode".into(), items: vec![("a".into(), 1, "".into()), ("b".into(), 2, "".into())] }],
            default_experiment: Some(DefaultExperiment { start_time: 0.0, stop_time: 1.0, step_size: 0.1 }),
            max_output_derivative_order: 1,
        }
    }

    #[test]
    fn schema_order_escaping_and_structure() {
        let (doc, guid) = render(&description());
        let order = [
            "<CoSimulation",
            "<UnitDefinitions",
            "<TypeDefinitions",
            "<LogCategories",
            "<DefaultExperiment",
            "<ModelVariables",
            "<ModelStructure",
            "<Outputs",
            "<InitialUnknowns",
        ];
        let pos: Vec<usize> = order.iter().map(|e| doc.find(e).unwrap_or_else(|| panic!("{e}"))).collect();
        assert!(pos.windows(2).all(|w| w[0] < w[1]), "{doc}");
        assert!(doc.contains("description=\"a &lt;mode&gt; &amp; &quot;more&quot;\""), "{doc}");
        assert!(doc.contains("<Enumeration declaredType=\"Mode\" start=\"2\"/>"));
        assert!(doc.contains("<Real unit=\"rad/s\" start=\"0.5\"/>"));
        assert!(doc.contains("<BaseUnit s=\"-1\" rad=\"1\"/>"));
        assert!(doc.contains("<Unit name=\"mm\">") && doc.contains("<BaseUnit m=\"1\" factor=\"0.001\"/>"), "{doc}");
        // Outputs and InitialUnknowns: the two outputs, 1-based.
        for section in ["Outputs", "InitialUnknowns"] {
            let a = doc.find(&format!("<{section}>")).unwrap();
            let b = doc.find(&format!("</{section}>")).unwrap();
            assert_eq!(doc[a..b].matches("<Unknown").count(), 2);
            assert!(doc[a..b].contains("index=\"3\"") && doc[a..b].contains("index=\"4\""));
        }
        assert!(doc.contains(&format!("guid=\"{guid}\"")));
        // Deterministic, and the guid is the hash of the document with an empty guid.
        assert_eq!(render(&description()), (doc.clone(), guid.clone()));
        assert_eq!(guid, crate::fmi::guid::from_content(doc.replace(&guid, "").as_bytes()));
    }

    #[test]
    fn reals_read_back_exactly() {
        for v in [0.0, 1.0, -2.5, 0.1, 1e-7, 6.02214076e23, std::f64::consts::PI] {
            assert_eq!(real(v).parse::<f64>().unwrap(), v);
        }
        assert_eq!(real(f64::INFINITY), "INF");
    }
}
