//! The layering of `src/` (docs/design/architecture.md): each top-level module imports
//! only modules of lower layers, and the files inside a module import each other
//! without circles. Reads every `crate::…` and `super::…` path in the code
//! (comments excluded), so a future back-import fails here.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top to bottom. A module may import modules of the layers below its own, never
/// its own layer's other modules or anything above.
const LAYERS: &[&[&str]] = &[
    &["main", "cli"],
    &["fidelity"],
    &["sweep", "viewer"],
    &["render"],
    &["post", "light"],
    &["skin"],
    &["frame_inputs", "testscene"],
    &["scene", "graph"],
    &["timing"],
    &["gpu"],
    &["atomic", "cache"],
    &["error", "assets", "text"],
];

fn layer_of(module: &str) -> usize {
    LAYERS
        .iter()
        .position(|l| l.contains(&module))
        .unwrap_or_else(|| panic!("module {module:?} is in no layer of tests/it/layers.rs"))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The source without `//` comments (doc links are not imports) or string literals.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let mut in_str = false;
        let mut prev = ' ';
        for (i, c) in line.char_indices() {
            if !in_str && c == '/' && line[i..].starts_with("//") {
                break;
            }
            if c == '"' && prev != '\\' {
                in_str = !in_str;
            }
            if !in_str {
                out.push(c);
            }
            prev = c;
        }
        out.push('\n');
    }
    out
}

/// Identifiers following `prefix` (e.g. the `x` of `crate::x` or `super::x`),
/// including inside `prefix{a, b::c}` groups.
fn paths_after(code: &str, prefix: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    for (i, _) in code.match_indices(prefix) {
        let before = code[..i].chars().last().unwrap_or(' ');
        if before.is_alphanumeric() || before == '_' || before == ':' {
            continue;
        }
        let rest = &code[i + prefix.len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // The first identifier of each item at the group's top level.
            let (mut depth, mut start) = (0, true);
            for (j, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && !c.is_whitespace() => {
                        start = false;
                        let name = ident(&group[j..]);
                        if !name.is_empty() {
                            found.insert(name);
                        }
                    }
                    _ => {}
                }
            }
        } else {
            let name = ident(rest);
            if !name.is_empty() {
                found.insert(name);
            }
        }
    }
    found
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// `src/skin/blur.rs` → ("skin", Some("blur")); `src/error.rs` → ("error", None).
fn module_and_file(path: &Path) -> (String, Option<String>) {
    let rel = path.strip_prefix(src()).unwrap();
    let parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    let file = (parts.len() > 1).then(|| parts[1].clone());
    (parts[0].clone(), file.filter(|f| f != "mod"))
}

#[test]
fn imports_only_run_downward() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    assert!(
        files.len() > 40,
        "found only {} files under src/",
        files.len()
    );
    let mut wrong = Vec::new();
    let mut arrows = 0;
    for path in &files {
        let (module, _) = module_and_file(path);
        if module == "lib" {
            continue;
        }
        let mine = layer_of(&module);
        // The binary's modules import the library as `dermis::`.
        let used = if module == "main" || module == "cli" {
            paths_after(&code(path), "dermis::")
        } else {
            paths_after(&code(path), "crate::")
        };
        for target in used {
            if target == module || target == "Error" || target == "Result" {
                continue;
            }
            arrows += 1;
            if layer_of(&target) <= mine {
                wrong.push(format!(
                    "{} imports {target} (layer {}), from layer {mine}",
                    path.display(),
                    layer_of(&target)
                ));
            }
        }
    }
    assert!(
        arrows > 50,
        "only {arrows} import arrows found: is the scan broken?"
    );
    assert!(
        wrong.is_empty(),
        "imports against the layers:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn files_of_a_module_import_each_other_without_circles() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    // module → file → sibling files it imports (mod.rs, the module's root, is left
    // out: it declares and re-exports its files).
    let mut graphs: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for path in &files {
        let (module, Some(file)) = module_and_file(path) else {
            continue;
        };
        let dir = path.parent().unwrap();
        let siblings: BTreeSet<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                p.file_stem().unwrap().to_string_lossy().to_string()
            })
            .filter(|n| n != "mod" && n != &file)
            .collect();
        let c = code(path);
        let mut used = paths_after(&c, "super::");
        used.extend(paths_after(&c, &format!("crate::{module}::")));
        let deps = used.intersection(&siblings).cloned().collect();
        graphs.entry(module).or_default().insert(file, deps);
    }
    let mut circles = Vec::new();
    for (module, graph) in &graphs {
        // Depth-first search for a back edge.
        fn visit(
            n: &str,
            g: &BTreeMap<String, BTreeSet<String>>,
            stack: &mut Vec<String>,
            done: &mut BTreeSet<String>,
            out: &mut Vec<String>,
        ) {
            if let Some(i) = stack.iter().position(|s| s == n) {
                out.push(stack[i..].join(" → ") + " → " + n);
                return;
            }
            if !done.insert(n.to_string()) {
                return;
            }
            stack.push(n.to_string());
            for m in g.get(n).into_iter().flatten() {
                visit(m, g, stack, done, out);
            }
            stack.pop();
        }
        let mut done = BTreeSet::new();
        for n in graph.keys() {
            let mut found = Vec::new();
            visit(n, graph, &mut Vec::new(), &mut done, &mut found);
            circles.extend(found.into_iter().map(|c| format!("{module}: {c}")));
        }
    }
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

#[test]
fn the_scan_sees_a_planted_back_import() {
    // The checker itself: paths in code and in nested groups are found; those in
    // comments are not.
    let path = std::env::temp_dir().join(format!("dermis-layers-{}.rs", std::process::id()));
    std::fs::write(
        &path,
        "use crate::render::View;\nuse crate::{skin::{a, b}, light::c};\n// crate::post\n",
    )
    .unwrap();
    let found = paths_after(&code(&path), "crate::");
    std::fs::remove_file(&path).unwrap();
    let expected: BTreeSet<String> = ["light", "render", "skin"].map(String::from).into();
    assert_eq!(found, expected);
    assert!(layer_of("render") < layer_of("skin"));
}
