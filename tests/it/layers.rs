//! The main crate's files do not import each other in a loop (the Bevy-free layers are
//! crates of their own, kept in order by Cargo's graph). Imports are every `crate::…` and
//! `super::…` path in a file (in `use` trees too), resolved to the module file they name; a
//! parent's `mod child;` and its bare `child::…` paths are the module tree, not imports.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
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

/// A file's module path below `crate` (`src/editor/ui/mod.rs` → `["editor", "ui"]`).
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    parts
}

/// The code of a file without its comments (doc comments name paths that are not imports).
fn code_of(text: &str) -> String {
    text.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// Every path a file names that starts with `crate::` or `super::`, with `use` trees
/// expanded (`crate::a::{b::C, d}` gives `crate::a::b::C` and `crate::a::d`).
fn named_paths(code: &str) -> Vec<String> {
    let bytes = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if !code.is_char_boundary(i) {
            i += 1;
            continue;
        }
        let rest = &code[i..];
        let starts = (rest.starts_with("crate::") || rest.starts_with("super::"))
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_' || bytes[i - 1] == b':'));
        if !starts {
            i += 1;
            continue;
        }
        let (tree, len) = use_tree(rest);
        out.extend(tree);
        i += len.max(1);
    }
    out
}

/// The paths of the use tree at the start of `text` and how many bytes it spans.
fn use_tree(text: &str) -> (Vec<String>, usize) {
    let bytes = text.as_bytes();
    let mut end = 0;
    while end < bytes.len() && (bytes[end].is_ascii_alphanumeric() || bytes[end] == b'_' || bytes[end] == b':') {
        end += 1;
    }
    let prefix = text[..end].trim_end_matches(':').to_string();
    if !text[..end].ends_with("::") || bytes.get(end) != Some(&b'{') {
        return (vec![prefix], end);
    }
    // A group: split at top-level commas up to the matching brace.
    let (mut depth, mut start, mut paths) = (0, end + 1, Vec::new());
    for (k, &b) in bytes.iter().enumerate().skip(end) {
        match b {
            b'{' => depth += 1,
            b'}' | b',' if depth == 1 => {
                let item = text[start..k].trim();
                if !item.is_empty() && item != "self" {
                    let (inner, _) = use_tree(&format!("{prefix}::{item}"));
                    paths.extend(inner);
                } else if item == "self" {
                    paths.push(prefix.clone());
                }
                start = k + 1;
                if b == b'}' {
                    return (paths, k + 1);
                }
            }
            b'}' => depth -= 1,
            _ => {}
        }
    }
    (paths, bytes.len())
}

/// The module file a path names: the longest prefix of it that is a module.
fn resolve(path: &str, from: &[String], modules: &BTreeMap<Vec<String>, PathBuf>) -> Option<PathBuf> {
    let mut parts: Vec<&str> = path.split("::").collect();
    // `super` is relative to the file's module (a `mod.rs` is its folder's module).
    let mut base: Vec<String> = match parts.first() {
        Some(&"crate") => {
            parts.remove(0);
            Vec::new()
        }
        _ => from.to_vec(),
    };
    while parts.first() == Some(&"super") {
        parts.remove(0);
        base.pop();
    }
    let mut full = base;
    full.extend(parts.iter().map(|p| p.to_string()));
    (0..=full.len()).rev().find_map(|n| modules.get(&full[..n]).cloned())
}

/// Each file of the main crate and the module files it imports.
fn import_graph() -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    import_graph_of(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"))
}

/// Each file of the crate whose sources are `src` and the module files it imports.
fn import_graph_of(src: &Path) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let src = src.to_path_buf();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.retain(|f| !f.ends_with("main.rs"));
    let modules: BTreeMap<Vec<String>, PathBuf> = files.iter().map(|f| (module_of(&src, f), f.clone())).collect();
    let mut graph = BTreeMap::new();
    for file in &files {
        let module = module_of(&src, file);
        // `super` in `a/b.rs` is `a`; in `a/b/mod.rs` also `a` (its own module is `a::b`).
        let from = module.clone();
        let code = code_of(&std::fs::read_to_string(file).unwrap());
        let targets =
            named_paths(&code).iter().filter_map(|p| resolve(p, &from, &modules)).filter(|t| t != file).collect();
        graph.insert(file.clone(), targets);
    }
    graph
}

/// The import cycles: strongly connected groups of more than one file (Tarjan).
fn cycles(graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<BTreeSet<PathBuf>> {
    struct State<'g> {
        graph: &'g BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'g PathBuf, usize>,
        low: BTreeMap<&'g PathBuf, usize>,
        stack: Vec<&'g PathBuf>,
        on_stack: BTreeSet<&'g PathBuf>,
        found: Vec<BTreeSet<PathBuf>>,
    }
    fn visit<'g>(s: &mut State<'g>, v: &'g PathBuf) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in &s.graph[v] {
            if !s.index.contains_key(w) {
                visit(s, w);
                let low = s.low[v].min(s.low[w]);
                s.low.insert(v, low);
            } else if s.on_stack.contains(w) {
                let low = s.low[v].min(s.index[w]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = BTreeSet::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                group.insert(w.clone());
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                s.found.push(group);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.found
}

#[test]
fn no_file_imports_another_that_imports_it_back() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = import_graph();
    assert!(graph.len() > 50, "only {} files read", graph.len());
    let named = |cycle: &BTreeSet<PathBuf>| -> Vec<String> {
        cycle.iter().map(|f| f.strip_prefix(&src).unwrap().display().to_string()).collect()
    };
    let found: Vec<Vec<String>> = cycles(&graph).iter().map(named).collect();
    assert!(found.is_empty(), "import cycles: {found:?}");
}

/// The layer crates' files do not import each other in a loop either.
#[test]
fn no_file_of_a_layer_crate_imports_another_that_imports_it_back() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for layer in ["marionette-rig", "marionette-formats", "marionette-document"] {
        let src = root.join("crates").join(layer).join("src");
        let graph = import_graph_of(&src);
        assert!(graph.len() > 10, "{layer}: only {} files read", graph.len());
        let named = |cycle: &BTreeSet<PathBuf>| -> Vec<String> {
            cycle.iter().map(|f| f.strip_prefix(&src).unwrap().display().to_string()).collect()
        };
        let found: Vec<Vec<String>> = cycles(&graph).iter().map(named).collect();
        assert!(found.is_empty(), "{layer}: import cycles: {found:?}");
    }
}

#[test]
fn the_import_reader_sees_use_trees_and_super() {
    let paths = named_paths("use crate::formats::{scene::{A, B}, gltf, self};\nlet x = super::super::y::z();");
    assert_eq!(
        paths,
        [
            "crate::formats::scene::A",
            "crate::formats::scene::B",
            "crate::formats::gltf",
            "crate::formats",
            "super::super::y::z"
        ]
    );
    let mut modules = BTreeMap::new();
    modules.insert(vec!["formats".to_string(), "scene".to_string()], PathBuf::from("scene.rs"));
    modules.insert(vec!["a".to_string()], PathBuf::from("a/mod.rs"));
    let from = vec!["a".to_string(), "b".to_string()];
    assert_eq!(resolve("crate::formats::scene::A", &from, &modules), Some(PathBuf::from("scene.rs")));
    assert_eq!(resolve("super::X", &from, &modules), Some(PathBuf::from("a/mod.rs")));
}

/// The Bevy-free layers build, and run their unit tests, without any Bevy crate.
#[test]
fn the_layer_crates_depend_on_no_bevy_crate() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for layer in ["marionette-rig", "marionette-formats", "marionette-document"] {
        let out = std::process::Command::new(env!("CARGO"))
            .current_dir(root)
            .args(["tree", "--offline", "--locked", "-e", "normal,dev,build", "--prefix", "none", "-p", layer])
            .output()
            .unwrap();
        assert!(out.status.success(), "cargo tree -p {layer}: {}", String::from_utf8_lossy(&out.stderr));
        let tree = String::from_utf8_lossy(&out.stdout);
        assert!(tree.lines().count() > 3, "{layer}: {tree}");
        let bevy: Vec<&str> = tree.lines().filter(|l| l.starts_with("bevy") || l.starts_with("wgpu")).collect();
        assert!(bevy.is_empty(), "{layer} depends on {bevy:?}");
    }
}

/// The editor's rooms, lowest first: a room imports only rooms before it (`state`, the
/// shared state, imports none; `order` and `cores` are the editor's own ground).
const EDITOR_ROOMS: [&[&str]; 7] =
    [&["state", "order", "cores"], &["scene_doc"], &["edits"], &["present"], &["interact"], &["ui"], &["bench"]];

/// The rank of the room a file of `src/editor` is in; `editor/mod.rs`, which holds the
/// rooms together, is above them all; `None` outside the editor.
fn editor_room(src: &Path, file: &Path) -> Option<usize> {
    let rel = file.strip_prefix(src.join("editor")).ok()?;
    if rel == Path::new("mod.rs") {
        return Some(EDITOR_ROOMS.len());
    }
    let first = rel.iter().next()?.to_string_lossy().trim_end_matches(".rs").to_string();
    EDITOR_ROOMS.iter().position(|rooms| rooms.contains(&first.as_str()))
}

#[test]
fn no_editor_room_imports_a_room_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = import_graph();
    let mut upward = Vec::new();
    for (file, targets) in &graph {
        let Some(room) = editor_room(&src, file) else { continue };
        for target in targets {
            if editor_room(&src, target).is_some_and(|to| to > room) {
                upward.push(format!("{} -> {}", file.display(), target.display()));
            }
        }
    }
    assert!(upward.is_empty(), "{} upward imports: {upward:#?}", upward.len());
}
