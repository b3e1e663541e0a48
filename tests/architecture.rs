//! ARCHITECTURE.md stays true: the rooms of `src/` and what each may use are read from its table,
//! and checked against the `crate::…` paths the code actually names. Also the house rules the
//! table cannot show: no cycle between rooms, no file over 600 lines, at most 10
//! `Result<_, String>` in the library.
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const MAX_LINES: usize = 600;
const MAX_STRING_RESULTS: usize = 10;

/// The table between `<!-- rooms -->` and `<!-- /rooms -->`: `| room | may use |` rows.
fn declared_rooms() -> BTreeMap<String, BTreeSet<String>> {
    let text = std::fs::read_to_string(Path::new(ROOT).join("ARCHITECTURE.md")).expect("ARCHITECTURE.md at the repository root");
    let start = text.find("<!-- rooms -->").expect("ARCHITECTURE.md has a <!-- rooms --> table");
    let end = text.find("<!-- /rooms -->").expect("ARCHITECTURE.md closes the table with <!-- /rooms -->");
    let mut rooms = BTreeMap::new();
    for line in text[start..end].lines().filter(|l| l.starts_with('|')) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (room, uses) = (cells[1].trim_matches('`'), cells[2]);
        if room == "room" || room.starts_with('-') {
            continue;
        }
        let uses = uses.split(',').map(|u| u.trim().trim_matches('`').to_string()).filter(|u| !u.is_empty() && u != "—").collect();
        rooms.insert(room.to_string(), uses);
    }
    rooms
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The top-level room of a file of `src/` (`periodic` for src/periodic/session.rs).
fn room_of(file: &Path) -> Option<String> {
    let rel = file.strip_prefix(Path::new(ROOT).join("src")).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    Some(first.trim_end_matches(".rs").to_string())
}

/// Rooms named by `crate::x` paths in the code (comments skipped), including `crate::{x, y}`;
/// `crate::Error` and `crate::ErrorKind` are the `error` room.
fn rooms_named(code: &str) -> BTreeSet<String> {
    let mut named = BTreeSet::new();
    for line in code.lines().map(str::trim_start).filter(|l| !l.starts_with("//")) {
        let mut rest = line;
        while let Some(i) = rest.find("crate::") {
            rest = &rest[i + "crate::".len()..];
            let items: Vec<&str> = if let Some(inner) = rest.strip_prefix('{') {
                let close = inner.find('}').unwrap_or(inner.len());
                inner[..close].split(',').map(|s| s.trim()).collect()
            } else {
                vec![rest]
            };
            for item in items {
                let name: String = item.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                let room = match name.as_str() {
                    "Error" | "ErrorKind" => "error".to_string(),
                    _ => name,
                };
                if !room.is_empty() {
                    named.insert(room);
                }
            }
        }
    }
    named
}

/// Room → rooms it names, over every file of `src/` except the binary.
fn actual_dependencies() -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(&Path::new(ROOT).join("src"), &mut files);
    let mut deps: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files {
        let Some(room) = room_of(&f) else { continue };
        if room == "bin" || room == "lib" {
            continue;
        }
        let code = std::fs::read_to_string(&f).unwrap();
        let entry = deps.entry(room.clone()).or_default();
        entry.extend(rooms_named(&code).into_iter().filter(|r| *r != room));
    }
    deps
}

#[test]
fn every_room_uses_only_what_architecture_md_allows() {
    let declared = declared_rooms();
    let actual = actual_dependencies();
    let mut wrong = Vec::new();
    for (room, uses) in &actual {
        let Some(allowed) = declared.get(room) else {
            wrong.push(format!("src/{room} is not in the ARCHITECTURE.md table"));
            continue;
        };
        let extra: Vec<&String> = uses.difference(allowed).collect();
        if !extra.is_empty() {
            wrong.push(format!("{room} uses {extra:?}, which ARCHITECTURE.md does not allow it"));
        }
        // The table says what is true, not only what is allowed: a listed room that is not used goes.
        let unused: Vec<&String> = allowed.difference(uses).collect();
        if !unused.is_empty() {
            wrong.push(format!("{room} does not use {unused:?}, which ARCHITECTURE.md lists for it"));
        }
    }
    for room in declared.keys().filter(|r| !actual.contains_key(*r)) {
        wrong.push(format!("ARCHITECTURE.md lists {room}, which is not a room of src/"));
    }
    assert!(wrong.is_empty(), "ARCHITECTURE.md and the code disagree:\n  {}", wrong.join("\n  "));
}

#[test]
fn no_cycle_between_rooms() {
    let deps = actual_dependencies();
    // Depth-first search with colours; a grey node reached again closes a cycle.
    fn visit(r: &str, deps: &BTreeMap<String, BTreeSet<String>>, state: &mut BTreeMap<String, u8>, path: &mut Vec<String>) -> Option<Vec<String>> {
        match state.get(r) {
            Some(2) => return None,
            Some(1) => {
                let i = path.iter().position(|p| p == r).unwrap();
                let mut cycle = path[i..].to_vec();
                cycle.push(r.to_string());
                return Some(cycle);
            }
            _ => {}
        }
        state.insert(r.to_string(), 1);
        path.push(r.to_string());
        for d in deps.get(r).into_iter().flatten() {
            if let Some(c) = visit(d, deps, state, path) {
                return Some(c);
            }
        }
        path.pop();
        state.insert(r.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for r in deps.keys() {
        if let Some(c) = visit(r, &deps, &mut state, &mut Vec::new()) {
            panic!("import cycle between rooms: {}", c.join(" → "));
        }
    }
}

#[test]
fn the_numerical_core_knows_nothing_of_mechanics_files_or_fmi() {
    let deps = actual_dependencies();
    let mechanics = ["model", "time", "periodic", "scene", "fe", "reduction", "response", "analysis", "exact", "marching"];
    let edges = ["fmi", "fmi2", "fmu", "fmu_model", "capi", "scene"];
    for (room, forbidden) in [("lcp", &mechanics[..]), ("linalg", &mechanics[..]), ("fmi", &mechanics[..]), ("periodic", &edges[..]), ("model", &edges[..])] {
        let uses = deps.get(room).cloned().unwrap_or_default();
        let bad: Vec<&&str> = forbidden.iter().filter(|f| uses.contains(**f)).collect();
        assert!(bad.is_empty(), "{room} must not use {bad:?}");
    }
}

#[test]
fn no_file_over_600_lines_and_few_string_errors() {
    let mut files = Vec::new();
    rust_files(&Path::new(ROOT).join("src"), &mut files);
    rust_files(&Path::new(ROOT).join("fmu/src"), &mut files);
    let mut long = Vec::new();
    let mut string_results = Vec::new();
    for f in &files {
        let code = std::fs::read_to_string(f).unwrap();
        let n = code.lines().count();
        if n > MAX_LINES {
            long.push(format!("{} ({n} lines)", f.display()));
        }
        for (i, line) in code.lines().enumerate() {
            if line.contains("Result<") && line.contains(", String>") {
                string_results.push(format!("{}:{}", f.display(), i + 1));
            }
        }
    }
    assert!(long.is_empty(), "files over {MAX_LINES} lines: {long:?}");
    assert!(
        string_results.len() <= MAX_STRING_RESULTS,
        "{} Result<_, String> (at most {MAX_STRING_RESULTS}):\n  {}",
        string_results.len(),
        string_results.join("\n  ")
    );
}

/// Features of `periodic-contact` that cargo enables when it builds `package`.
fn library_features_in(package: &str) -> String {
    let out = std::process::Command::new(env!("CARGO"))
        .args(["tree", "-p", package, "-e", "features", "-i", "periodic-contact", "--offline", "--manifest-path"])
        .arg(Path::new(ROOT).join("Cargo.toml"))
        .output()
        .expect("cargo tree runs");
    assert!(out.status.success(), "cargo tree: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The features of `periodic-contact` enabled in a `cargo tree` listing.
fn enabled(tree: &str) -> std::collections::BTreeSet<String> {
    tree.lines().filter_map(|l| Some(l[l.find("periodic-contact feature \"")? + 26..].split('"').next()?.to_string())).collect()
}

#[test]
fn the_fmu_binary_builds_the_library_with_the_clis_features() {
    // One library artifact for the CLI, the C API and the FMU: building one after the other
    // recompiles nothing (fmu/build.rs hides the C API's symbols; tests/fmu_host.rs checks the 34).
    let cli = enabled(&library_features_in("periodic-contact"));
    assert!(cli.contains("reference") && cli.contains("studies"), "the method sees features: {cli:?}");
    let fmu = enabled(&library_features_in("periodic-contact-fmu"));
    assert_eq!(fmu, cli, "the FMU build enables other features of the library than the CLI's");
}

#[test]
fn no_test_or_source_reads_outside_the_repository() {
    let root = Path::new(ROOT);
    let mut files = Vec::new();
    for dir in ["src", "tests", "validation", "fmu", "examples"] {
        collect_text_files(&root.join(dir), &mut files);
    }
    let this = root.join("tests/architecture.rs");
    let outside = ["../shared", "/work/", "/root/", "/home/"];
    let mut hits = Vec::new();
    for f in files.iter().filter(|f| **f != this) {
        let Ok(text) = std::fs::read_to_string(f) else { continue };
        for (i, line) in text.lines().enumerate() {
            if let Some(p) = outside.iter().find(|p| line.contains(**p)) {
                hits.push(format!("{}:{}: {p}", f.display(), i + 1));
            }
        }
    }
    assert!(hits.is_empty(), "paths outside the repository:\n  {}", hits.join("\n  "));
}

/// Source, script and text files below `dir`, without virtual environments and build output.
fn collect_text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if !name.starts_with('.') && name != "target" && name != "__pycache__" && name != "figures" && name != "study" {
                collect_text_files(&p, out);
            }
        } else if ["rs", "py", "sh", "toml", "c", "h", "md"].iter().any(|x| name.ends_with(&format!(".{x}"))) {
            out.push(p);
        }
    }
}

/// The keys a scene may hold: the fields of every `Deserialize` struct of `src/scene/` (serde's
/// `rename` honoured), with the struct that holds each.
fn scene_keys() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/scene");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "rs")).collect();
    files.sort();
    let mut keys = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let mut i = 0;
        while i < lines.len() {
            let derives = lines[i].trim_start().starts_with("#[derive(") && lines[i].contains("Deserialize");
            i += 1;
            if !derives {
                continue;
            }
            while i < lines.len() && lines[i].trim_start().starts_with("#[") {
                i += 1;
            }
            let Some(name) = lines.get(i).and_then(|l| l.trim_start().strip_prefix("pub struct ").or_else(|| l.trim_start().strip_prefix("struct "))) else {
                continue;
            };
            let name = name.split([' ', '{', '<']).next().unwrap().to_string();
            let mut rename = None;
            i += 1;
            while i < lines.len() && lines[i].trim() != "}" {
                let l = lines[i].trim();
                if let Some(r) = l.strip_prefix("#[serde(rename = \"") {
                    rename = r.split('"').next().map(str::to_string);
                } else if !l.starts_with("//") && !l.starts_with("#[") && l.contains(':') {
                    let field = l.trim_start_matches("pub ").trim_start_matches("pub(crate) ").split(':').next().unwrap().trim().to_string();
                    if field.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_') {
                        keys.push((name.clone(), rename.take().unwrap_or(field)));
                    }
                }
                i += 1;
            }
        }
    }
    keys
}

#[test]
fn every_scene_key_is_documented_in_the_readmes_scene_format() {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    // The scene format: from the units section to the end of the scene-format section.
    let start = readme.find("\n## Units and sign conventions").expect("README: ## Units and sign conventions");
    let end = start + readme[start..].find("\n## Blade rubbing").expect("README: the section after ## Scene format");
    let section = &readme[start..end];
    let keys = scene_keys();
    assert!(keys.len() > 40, "parsed {} scene keys from src/scene: the parser of this test is broken", keys.len());
    let documented = |k: &str| {
        section.match_indices(k).any(|(i, _)| {
            let before = section[..i].chars().next_back().unwrap_or(' ');
            let after = section[i + k.len()..].chars().next().unwrap_or(' ');
            let word = |c: char| c.is_alphanumeric() || c == '_';
            let table = before == '[' && after == ']';
            !word(before) && !word(after) && (table || section[i + k.len()..].starts_with(" =") || before == '`' || before == '.' || after == '`')
        })
    };
    let missing: Vec<String> = keys.iter().filter(|(_, k)| !documented(k)).map(|(s, k)| format!("{s}.{k}")).collect();
    assert!(missing.is_empty(), "scene keys missing from README.md's scene format (write `key = …` or `key` there): {missing:?}");
}
