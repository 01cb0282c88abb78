//! The code's large-scale shape, guarded: the modules form layers in data-flow order and
//! no file imports from a layer above its own; no files depend on each other in a cycle;
//! exactly one module imports mujoco-rs (`sim`) and one imports rerun (`viz`).
//!
//! How references are read: every `use` of `crate::`, `super::` or `self::` paths, every
//! path spelled from `crate::` or `super::` in code, and every path through a child module
//! a file declares (`mod child;` … `child::item`), tests included; comments and string
//! literals are left out. A path resolves to the file of the deepest module it names. A
//! file may use its own ancestors' items (that is Rust's containment, how a module's
//! files share its types), so edges from a file to an ancestor's file are not counted
//! toward cycles; every other edge is.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom first. A module may reference modules of lower layers only; two
/// modules of one layer may not reference each other.
const LAYERS: &[&[&str]] = &[
    // Foundations that know nothing of the robot or the world.
    &["geometry", "rng", "progress", "search"],
    &["params"],
    &["robot"],
    &["urdf_export"],
    &["support"],
    // The world: scenario file → height map → cost client.
    &["scenario"],
    &["terrain"],
    &["cost"],
    // How the robot stands on terrain, and the one feasibility model.
    &["posture"],
    &["feasibility"],
    // Planning and motion: the path's types, the planner, the manoeuvres and keyframes.
    &["path"],
    &["planner"],
    &["motion"],
    // Execution: controllers and the simulation, the monitor over it.
    &["control", "sim"],
    &["monitor"],
    // Pictures and recordings.
    &["render"],
    &["viz"],
    // The closed loop as a library, the commands, the command line.
    &["closed_loop"],
    &["jobs"],
    &["cli"],
];

/// A source file: its path under `src/` and its module path.
struct SourceFile {
    rel: String,
    module: Vec<String>,
    text: String,
}

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn collect(dir: &Path, root: &Path, out: &mut Vec<SourceFile>) {
    let mut entries: Vec<_> =
        std::fs::read_dir(dir).expect("src readable").map(|e| e.expect("entry").path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            collect(&p, root, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            let rel = p.strip_prefix(root).expect("under src").to_string_lossy().replace('\\', "/");
            let mut module: Vec<String> =
                rel.trim_end_matches(".rs").split('/').map(str::to_owned).collect();
            if matches!(module.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                module.pop();
            }
            let text = std::fs::read_to_string(&p).expect("readable");
            out.push(SourceFile { rel, module, text: strip(&text) });
        }
    }
}

/// The text without comments and without the contents of string and char literals.
fn strip(s: &str) -> String {
    let b: Vec<char> = s.chars().collect();
    let mut out = String::with_capacity(s.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if c == 'r'
            && (next == Some('"') || next == Some('#'))
            && !is_ident(b.get(i.wrapping_sub(1)))
        {
            // Raw string: r"…" or r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= b.len() {
                    break;
                }
                if b[j] == '"' && (0..hashes).all(|h| b.get(j + 1 + h) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = j;
        } else if c == '"' {
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == '\'' && next.is_some() && b.get(i + 2) == Some(&'\'') {
            out.push_str("' '");
            i += 3;
        } else if c == '\'' && next == Some('\\') {
            // An escaped char literal.
            i += 2;
            while i < b.len() && b[i] != '\'' {
                i += 1;
            }
            i += 1;
            out.push_str("' '");
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

fn is_ident(c: Option<&char>) -> bool {
    c.is_some_and(|c| c.is_alphanumeric() || *c == '_')
}

/// The paths of a `use` tree (`a::{b, c::{d, e as f}}`).
fn expand_tree(prefix: &[String], tree: &str, out: &mut Vec<Vec<String>>) {
    let mut parts = Vec::new();
    let (mut depth, mut cur) = (0, String::new());
    for ch in tree.chars() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        if ch == ',' && depth == 0 {
            parts.push(std::mem::take(&mut cur));
        } else {
            cur.push(ch);
        }
    }
    parts.push(cur);
    for p in parts {
        let p = p.trim();
        if p.is_empty() {
            continue;
        }
        if let Some(open) = p.find("::{") {
            let head = &p[..open];
            let inner = &p[open + 3..p.len() - 1];
            let mut next = prefix.to_vec();
            next.extend(head.split("::").filter(|s| !s.is_empty()).map(str::to_owned));
            expand_tree(&next, inner, out);
        } else if p.starts_with('{') {
            expand_tree(prefix, &p[1..p.len() - 1], out);
        } else {
            let p = p.split(" as ").next().unwrap_or(p).trim();
            let mut path = prefix.to_vec();
            path.extend(p.split("::").filter(|s| !s.is_empty()).map(str::to_owned));
            out.push(path);
        }
    }
}

/// Identifier characters from `start`.
fn ident_at(text: &str, start: usize) -> &str {
    let end = text[start..]
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .map_or(text.len(), |k| start + k);
    &text[start..end]
}

/// Every `a::b::c` path starting at byte `start` (identifiers joined by `::`).
fn path_at(text: &str, start: usize) -> Vec<String> {
    let mut out = Vec::new();
    let mut k = start;
    loop {
        let id = ident_at(text, k);
        if id.is_empty() {
            break;
        }
        out.push(id.to_owned());
        k += id.len();
        if text[k..].starts_with("::") {
            k += 2;
        } else {
            break;
        }
    }
    out
}

/// The paths file `f` references (see the module docs), as written.
fn references(f: &SourceFile) -> Vec<Vec<String>> {
    let t = &f.text;
    let mut out = Vec::new();
    // `use` statements, then blanked out for the paths in code below.
    let mut code = t.clone();
    let mut k = 0;
    while let Some(pos) = t[k..].find("use ") {
        let at = k + pos;
        k = at + 4;
        if at > 0 && is_ident(t[..at].chars().last().as_ref()) {
            continue;
        }
        let Some(end) = t[k..].find(';') else { break };
        let tree: String = t[k..k + end].split_whitespace().collect::<Vec<_>>().join(" ");
        let tree = tree.replace(":: ", "::").replace(" ::", "::");
        expand_tree(&[], &tree, &mut out);
        code.replace_range(at..k + end, &" ".repeat(k + end - at));
    }
    let t = &code;
    // Paths in code from `crate::` and `super::`, and through declared child modules.
    let children: BTreeSet<String> = t
        .lines()
        .filter_map(|l| {
            let l = l.trim();
            let l = l.strip_prefix("pub ").or_else(|| l.strip_prefix("pub(crate) ")).unwrap_or(l);
            let name = l.strip_prefix("mod ")?.strip_suffix(';')?;
            Some(name.trim().to_owned())
        })
        .collect();
    let bytes = t.as_bytes();
    for (i, _) in t.char_indices() {
        if i > 0 && (is_ident(t[..i].chars().last().as_ref()) || bytes[i - 1] == b':') {
            continue;
        }
        let id = ident_at(t, i);
        if id.is_empty() {
            continue;
        }
        if (id == "crate" || id == "super" || children.contains(id))
            && t[i + id.len()..].starts_with("::")
        {
            let mut p = path_at(t, i);
            if children.contains(id) {
                p.insert(0, "self".to_owned());
            }
            out.push(p);
        }
    }
    out
}

/// The file a path names from module `cur`: that of the deepest existing module on it.
fn resolve(
    cur: &[String],
    path: &[String],
    modules: &BTreeMap<Vec<String>, String>,
) -> Option<String> {
    let (mut base, mut rest): (Vec<String>, &[String]) = match path.first().map(String::as_str) {
        Some("crate") => (Vec::new(), &path[1..]),
        Some("self") => (cur.to_vec(), &path[1..]),
        Some("super") => (cur.to_vec(), path),
        _ => return None,
    };
    while rest.first().is_some_and(|s| s == "super") {
        base.pop();
        rest = &rest[1..];
    }
    base.extend(rest.iter().cloned());
    (1..=base.len()).rev().find_map(|n| modules.get(&base[..n]).cloned())
}

struct Graph {
    files: Vec<SourceFile>,
    /// File → files it references (resolved), with the path as written.
    edges: BTreeMap<String, BTreeMap<String, String>>,
}

fn graph() -> Graph {
    let root = src_dir();
    let mut files = Vec::new();
    collect(&root, &root, &mut files);
    graph_of(files)
}

fn graph_of(files: Vec<SourceFile>) -> Graph {
    let modules: BTreeMap<Vec<String>, String> =
        files.iter().map(|f| (f.module.clone(), f.rel.clone())).collect();
    let mut edges: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for f in &files {
        let e = edges.entry(f.rel.clone()).or_default();
        for p in references(f) {
            if let Some(target) = resolve(&f.module, &p, &modules)
                && target != f.rel
            {
                e.entry(target).or_insert_with(|| p.join("::"));
            }
        }
    }
    Graph { files, edges }
}

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn top(rel: &str) -> &str {
    rel.split('/').next().unwrap_or(rel).trim_end_matches(".rs")
}

#[test]
fn every_module_has_a_layer() {
    let g = graph();
    let missing: BTreeSet<&str> = g
        .files
        .iter()
        .map(|f| top(&f.rel))
        .filter(|m| !matches!(*m, "lib" | "main") && layer_of(m).is_none())
        .collect();
    assert!(missing.is_empty(), "modules missing from LAYERS: {missing:?}");
}

#[test]
fn no_module_imports_from_its_own_layer_or_above() {
    let bad = layer_violations(&graph());
    assert!(bad.is_empty(), "imports against the layer order:\n{}", bad.join("\n"));
}

/// Every import from a module to one of its own layer or a higher one.
fn layer_violations(g: &Graph) -> Vec<String> {
    let mut bad = Vec::new();
    for (from, targets) in &g.edges {
        let a = top(from);
        let Some(la) = layer_of(a) else { continue };
        for (to, written) in targets {
            let t = top(to);
            if t == a || matches!(t, "lib" | "main") {
                continue;
            }
            match layer_of(t) {
                Some(lt) if lt < la => {}
                _ => bad.push(format!("{from} → {to} (`{written}`): {a} may not use {t}")),
            }
        }
    }
    bad
}

#[test]
fn no_files_depend_on_each_other_in_a_cycle() {
    let cycles = import_cycles(&graph());
    assert!(cycles.is_empty(), "files in import cycles:\n{}", cycles.join("\n"));
}

/// The strongly connected components of more than one file in the import graph.
fn import_cycles(g: &Graph) -> Vec<String> {
    let module_of: BTreeMap<&str, &Vec<String>> =
        g.files.iter().map(|f| (f.rel.as_str(), &f.module)).collect();
    let is_ancestor = |a: &str, b: &str| {
        let (a, b) = (module_of[a], module_of[b]);
        a.len() < b.len() && b[..a.len()] == a[..]
    };
    let nodes: Vec<&str> = g.files.iter().map(|f| f.rel.as_str()).collect();
    let adj: BTreeMap<&str, Vec<&str>> = nodes
        .iter()
        .map(|&n| {
            let out = g.edges[n].keys().map(String::as_str).filter(|&t| !is_ancestor(t, n));
            (n, out.collect())
        })
        .collect();
    // Tarjan's strongly connected components, iterative over an explicit stack.
    let mut index: BTreeMap<&str, usize> = BTreeMap::new();
    let mut low: BTreeMap<&str, usize> = BTreeMap::new();
    let (mut stack, mut on) = (Vec::new(), BTreeSet::new());
    let mut cycles = Vec::new();
    let mut counter = 0;
    for &start in &nodes {
        if index.contains_key(start) {
            continue;
        }
        let mut work: Vec<(&str, usize)> = vec![(start, 0)];
        while let Some(&mut (v, ref mut k)) = work.last_mut() {
            if *k == 0 {
                index.insert(v, counter);
                low.insert(v, counter);
                counter += 1;
                stack.push(v);
                on.insert(v);
            }
            if let Some(&w) = adj[v].get(*k) {
                *k += 1;
                if !index.contains_key(w) {
                    work.push((w, 0));
                } else if on.contains(w) {
                    let lw = index[w];
                    let lv = low[v].min(lw);
                    low.insert(v, lv);
                }
                continue;
            }
            work.pop();
            if let Some(&(parent, _)) = work.last() {
                let lp = low[parent].min(low[v]);
                low.insert(parent, lp);
            }
            if low[v] == index[v] {
                let mut comp = Vec::new();
                while let Some(w) = stack.pop() {
                    on.remove(w);
                    comp.push(w);
                    if w == v {
                        break;
                    }
                }
                if comp.len() > 1 {
                    comp.sort_unstable();
                    cycles.push(comp.join(" ↔ "));
                }
            }
        }
    }
    cycles
}

#[test]
fn one_module_imports_mujoco_and_one_imports_rerun() {
    let g = graph();
    for (name, module) in [("mujoco_rs", "sim"), ("rerun", "viz")] {
        let users: BTreeSet<&str> = g
            .files
            .iter()
            .filter(|f| f.text.contains(&format!("{name}::")))
            .map(|f| top(&f.rel))
            .collect();
        assert_eq!(users, BTreeSet::from([module]), "{name} is used by {users:?}");
    }
}

/// The reader itself: a hand-written file's references, as the checks see them.
#[test]
fn references_are_read_from_uses_paths_and_child_modules() {
    let f = SourceFile {
        rel: "planner/graph.rs".into(),
        module: vec!["planner".into(), "graph".into()],
        text: strip(
            "//! crate::jobs in a comment\nmod inner;\nuse super::core::{GraphCore, Stance as S};\n\
             use crate::path::{EdgeLabel, ManoeuvreKind};\nfn f() { let s = \"crate::cli\"; \
             crate::search::Cost::ZERO; inner::g(); }\n",
        ),
    };
    let refs: BTreeSet<String> = references(&f).iter().map(|p| p.join("::")).collect();
    let want = [
        "super::core::GraphCore",
        "super::core::Stance",
        "crate::path::EdgeLabel",
        "crate::path::ManoeuvreKind",
        "crate::search::Cost::ZERO",
        "self::inner::g",
    ];
    assert_eq!(refs, want.iter().map(|s| (*s).to_owned()).collect());
}

/// The checks catch what they are for: an upward import planted in a small synthetic
/// source tree is reported as a layer violation and, with its downward partner, as a cycle;
/// two files of one module that use each other are a cycle but no layer violation.
#[test]
fn planted_violations_are_caught() {
    let file = |rel: &str, text: &str| SourceFile {
        rel: rel.into(),
        module: rel
            .trim_end_matches(".rs")
            .trim_end_matches("/mod")
            .split('/')
            .map(Into::into)
            .collect(),
        text: strip(text),
    };
    let upward = graph_of(vec![
        file("path.rs", "use crate::planner::Plan;\n"),
        file("planner/mod.rs", "use crate::path::ManoeuvreKind;\npub struct Plan;\n"),
    ]);
    assert_eq!(layer_violations(&upward).len(), 1, "{:?}", layer_violations(&upward));
    assert!(layer_violations(&upward)[0].starts_with("path.rs → planner/mod.rs"));
    assert_eq!(import_cycles(&upward), vec!["path.rs ↔ planner/mod.rs".to_owned()]);

    let sideways = graph_of(vec![
        file("planner/mod.rs", "mod a;\nmod b;\n"),
        file("planner/a.rs", "use super::b::B;\npub struct A;\n"),
        file("planner/b.rs", "use super::a::A;\npub struct B;\n"),
    ]);
    assert!(layer_violations(&sideways).is_empty());
    assert_eq!(import_cycles(&sideways), vec!["planner/a.rs ↔ planner/b.rs".to_owned()]);

    let clean = graph();
    assert!(clean.files.len() > 50, "the real tree is read: {} files", clean.files.len());
}
