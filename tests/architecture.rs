//! The shape of the workspace, checked against the code:
//!
//! 1. ARCHITECTURE.md's crate graph (the fenced `graph` block under "Crate graph") lists every
//!    workspace crate with exactly the workspace crates it depends on (normal dependencies, as
//!    `cargo metadata` reports them), and its "owns / must not" table has a row for every crate.
//! 2. No crate's modules import each other in a circle: the edges are the `crate::`, `super::`,
//!    `self::` and child-module paths of every `.rs` file's code (comments and the `#[cfg(test)]`
//!    module left out), a
//!    re-exported name resolved to the module that defines it; the crate root's `pub use` lines
//!    are its facade, not edges.
//! 3. The command line tool stays thin: `src/` under 2,500 lines.
//! 4. The Python wheel's build resolves its dependencies' features as the workspace does (CI reuses
//!    the tests' artifacts for it).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The standard output of `cargo ARGS` run in the repository (the test fails with cargo's
/// error when it does).
fn cargo(args: &[&str]) -> Vec<u8> {
    let out = Command::new(env!("CARGO"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// `crate name -> workspace crates it depends on` from `cargo metadata`.
fn manifest_graph() -> BTreeMap<String, BTreeSet<String>> {
    let out = cargo(&[
        "metadata",
        "--format-version",
        "1",
        "--no-deps",
        "--offline",
    ]);
    let meta: serde_json::Value = serde_json::from_slice(&out).expect("metadata JSON");
    let packages = meta["packages"].as_array().expect("packages");
    let names: BTreeSet<String> = packages
        .iter()
        .filter_map(|p| p["name"].as_str().map(String::from))
        .collect();
    packages
        .iter()
        .map(|p| {
            let deps = p["dependencies"]
                .as_array()
                .expect("dependencies")
                .iter()
                .filter(|d| d["kind"].is_null())
                .filter_map(|d| d["name"].as_str())
                .filter(|d| names.contains(*d))
                .map(String::from)
                .collect();
            (p["name"].as_str().unwrap_or_default().to_string(), deps)
        })
        .collect()
}

/// The section of ARCHITECTURE.md under the heading `title`.
fn section<'a>(doc: &'a str, title: &str) -> &'a str {
    let start = doc
        .find(&format!("## {title}"))
        .unwrap_or_else(|| panic!("ARCHITECTURE.md has no `## {title}`"));
    let rest = &doc[start + title.len() + 3..];
    &rest[..rest.find("\n## ").unwrap_or(rest.len())]
}

/// `crate -> deps` lines of the fenced `graph` block: `name -> a, b` or `name -> (none)`.
fn documented_graph(doc: &str) -> BTreeMap<String, BTreeSet<String>> {
    let graph = section(doc, "Crate graph");
    let block = graph
        .split("```graph")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("a ```graph block under Crate graph");
    block
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let (name, deps) = line
                .split_once("->")
                .unwrap_or_else(|| panic!("graph line without `->`: {line}"));
            let deps = deps
                .split(',')
                .map(|d| d.trim().to_string())
                .filter(|d| !d.is_empty() && d != "(none)")
                .collect();
            (name.trim().to_string(), deps)
        })
        .collect()
}

#[test]
fn the_documented_crate_graph_matches_the_manifests() {
    let doc = std::fs::read_to_string(repo().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let manifests = manifest_graph();
    let documented = documented_graph(&doc);
    assert_eq!(
        documented, manifests,
        "ARCHITECTURE.md's graph block (left) differs from the manifests (right)"
    );
    let table = section(&doc, "Crate graph");
    for name in manifests.keys() {
        let row = format!("| `{name}`");
        assert!(
            table.contains(&row),
            "no \"owns / must not\" row for {name}"
        );
    }
}

/// Code without comments and string contents (a `//` in a string would not start a comment,
/// and paths in strings are not imports).
fn code_only(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                    i += 1;
                }
                i += 2;
            }
            b'r' if (b.get(i + 1) == Some(&b'#') || b.get(i + 1) == Some(&b'"'))
                && !i
                    .checked_sub(1)
                    .is_some_and(|k| b[k].is_ascii_alphanumeric() || b[k] == b'_') =>
            {
                // A raw string r#"..."#: skip to the quote followed by as many hashes.
                let hashes = b[i + 1..].iter().take_while(|&&c| c == b'#').count();
                if b.get(i + 1 + hashes) != Some(&b'"') {
                    // A raw identifier (r#type).
                    out.push('r');
                    i += 1;
                    continue;
                }
                let mut j = i + 1 + hashes + 1;
                let close: Vec<u8> = std::iter::once(b'"')
                    .chain(std::iter::repeat_n(b'#', hashes))
                    .collect();
                while j < b.len() && !b[j..].starts_with(&close) {
                    j += 1;
                }
                i = j + close.len();
                out.push_str("\"\"");
            }
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
                out.push_str("\"\"");
            }
            b'\'' if b.get(i + 1) == Some(&b'\\') => {
                // An escaped char literal such as '\'' or '\"'.
                i += 2;
                while i < b.len() && b[i] != b'\'' {
                    i += 1;
                }
                i += 1;
            }
            b'\'' if b.get(i + 2) == Some(&b'\'') => {
                // A char literal such as '"' or '{'.
                i += 3;
            }
            c => {
                out.push(c as char);
                i += 1;
            }
        }
    }
    out
}

/// Every path a `use` tree names, e.g. `crate::{a::X, b::{Y, Z}}` gives `crate::a::X`,
/// `crate::b::Y`, `crate::b::Z`.
fn expand_use(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    fn walk(prefix: &str, t: &str, out: &mut Vec<String>) {
        if let Some(open) = t.find('{') {
            let head = &t[..open];
            let inner = &t[open + 1..t.rfind('}').unwrap_or(t.len())];
            let mut depth = 0;
            let mut start = 0;
            for (i, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        walk(&format!("{prefix}{head}"), &inner[start..i], out);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            walk(&format!("{prefix}{head}"), &inner[start..], out);
        } else if !t.is_empty() {
            out.push(format!("{prefix}{t}"));
        }
    }
    let mut out = Vec::new();
    walk("", &tree, &mut out);
    out
}

/// A crate's modules: module path (`""` for the root, `exr::header`, ...) -> file.
fn modules(src: &Path) -> BTreeMap<String, PathBuf> {
    fn visit(dir: &Path, src: &Path, out: &mut BTreeMap<String, PathBuf>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .expect("src folder")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                visit(&p, src, out);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let rel = p.strip_prefix(src).expect("inside src");
                let mut parts: Vec<String> = rel
                    .iter()
                    .map(|s| s.to_string_lossy().trim_end_matches(".rs").to_string())
                    .collect();
                if parts.last().is_some_and(|l| l == "mod") {
                    parts.pop();
                }
                let name = parts.join("::");
                let name = if matches!(name.as_str(), "lib" | "main") {
                    String::new()
                } else {
                    name
                };
                out.insert(name, p);
            }
        }
    }
    let mut out = BTreeMap::new();
    visit(src, src, &mut out);
    out
}

/// The module a path inside module `from` refers to, if any: `crate::a::b::Item` is the longest
/// known module prefix (`a::b`); `super::`/`self::` are relative; a single `crate::Item` is looked
/// up in the root's re-exports.
fn target(
    path: &str,
    from: &str,
    known: &BTreeMap<String, PathBuf>,
    reexports: &BTreeMap<String, String>,
) -> Option<String> {
    let segments: Vec<&str> = path.split("::").collect();
    let mut base: Vec<String> = if from.is_empty() {
        Vec::new()
    } else {
        from.split("::").map(String::from).collect()
    };
    let rest: &[&str] = match segments.first() {
        Some(&"crate") => {
            base.clear();
            &segments[1..]
        }
        Some(&"super") => {
            let mut k = 0;
            while segments.get(k) == Some(&"super") {
                base.pop();
                k += 1;
            }
            &segments[k..]
        }
        Some(&"self") => &segments[1..],
        Some(first) => {
            // A child module named without `self::`.
            let mut child = base.clone();
            child.push((*first).to_string());
            if known.contains_key(&child.join("::")) {
                &segments[..]
            } else {
                return None;
            }
        }
        None => return None,
    };
    let mut best = None;
    let mut cur = base.clone();
    for s in rest {
        cur.push((*s).to_string());
        if known.contains_key(&cur.join("::")) {
            best = Some(cur.join("::"));
        }
    }
    match best {
        Some(m) => Some(m),
        None if base.is_empty() => rest
            .first()
            .map(|item| reexports.get(*item).cloned().unwrap_or_default()),
        None => Some(base.join("::")),
    }
}

/// The import edges between a crate's modules.
fn module_edges(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let known = modules(src);
    let root_text = known
        .get("")
        .map(|p| code_only(&std::fs::read_to_string(p).expect("root")))
        .unwrap_or_default();
    // Root re-exports: `pub use module::{A, B}` -> A, B defined in `module`.
    let mut reexports = BTreeMap::new();
    for stmt in root_text.split(';') {
        let stmt = stmt.trim();
        if let Some(tree) = stmt.strip_prefix("pub use ") {
            for path in expand_use(tree) {
                let segs: Vec<&str> = path.split("::").collect();
                if let (Some(item), true) = (segs.last(), segs.len() >= 2) {
                    let module: Vec<&str> = segs[..segs.len() - 1]
                        .iter()
                        .copied()
                        .filter(|s| *s != "crate" && *s != "self")
                        .collect();
                    if known.contains_key(&module.join("::")) {
                        let item = item.split(" as ").last().unwrap_or(item);
                        reexports.insert(item.to_string(), module.join("::"));
                    }
                }
            }
        }
    }
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (name, file) in &known {
        let text = code_only(&std::fs::read_to_string(file).expect("module"));
        // A `#[cfg(test)]` module (by convention the file's end) is a child of this module: its
        // `super::` paths point here, not at the parent.
        let text = match text.find("#[cfg(test)]") {
            Some(at) => text[..at].to_string(),
            None => text,
        };
        let mut paths = Vec::new();
        for stmt in text.split(';') {
            let stmt = stmt.trim_start();
            let is_facade = name.is_empty() && stmt.starts_with("pub use ");
            let tree = stmt
                .strip_prefix("pub use ")
                .or_else(|| stmt.strip_prefix("pub(crate) use "))
                .or_else(|| stmt.strip_prefix("use "));
            match tree {
                Some(_) if is_facade => {}
                Some(tree) => paths.extend(expand_use(tree)),
                None => {}
            }
        }
        // Inline paths in code: crate::x, super::x, self::x.
        for key in ["crate::", "super::", "self::"] {
            for (at, _) in text.match_indices(key) {
                let before = text[..at].chars().last();
                if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                    continue;
                }
                let path: String = text[at..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                    .collect();
                paths.push(path.trim_end_matches(':').to_string());
            }
        }
        for path in paths {
            if let Some(t) = target(&path, name, &known, &reexports)
                && t != *name
                && !t.is_empty()
            {
                edges.entry(name.clone()).or_default().insert(t);
            }
        }
    }
    edges
}

/// A cycle in `edges`, if there is one (depth-first search).
fn find_cycle(edges: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn dfs(
        n: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in edges.get(n).into_iter().flatten() {
            match state.get(m.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = stack.iter().position(|s| s == m).unwrap_or(0);
                    let mut cycle = stack[start..].to_vec();
                    cycle.push(m.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = dfs(m, edges, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in edges.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = dfs(n, edges, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

/// Every crate's source folder: `src/` and `crates/*/src`.
fn source_folders() -> Vec<PathBuf> {
    let mut dirs = vec![repo().join("src")];
    let mut crates: Vec<PathBuf> = std::fs::read_dir(repo().join("crates"))
        .expect("crates/")
        .filter_map(|e| e.ok().map(|e| e.path().join("src")))
        .filter(|p| p.is_dir())
        .collect();
    crates.sort();
    dirs.extend(crates);
    dirs
}

#[test]
fn no_crate_has_an_import_cycle_between_its_modules() {
    let mut checked = 0;
    for src in source_folders() {
        let edges = module_edges(&src);
        if let Some(cycle) = find_cycle(&edges) {
            panic!(
                "{}: modules import each other in a circle: {}",
                src.display(),
                cycle.join(" -> ")
            );
        }
        checked += 1;
    }
    assert!(checked >= 12, "only {checked} crates checked");
}

#[test]
fn the_cycle_finder_finds_what_it_should() {
    // The parser and the search on hand-made modules: `a` uses `b` twice over (a group and an
    // inline path), `b` reaches `a` through a re-exported name.
    let dir = tempfile::tempdir().expect("tempdir");
    let src = dir.path();
    std::fs::write(src.join("lib.rs"), "mod a;\nmod b;\npub use a::Thing;\n").expect("write");
    std::fs::write(
        src.join("a.rs"),
        "use crate::{b::{self, Other}};\n// use crate::nothing;\nfn f() { crate::b::g(); }\npub struct Thing;\n",
    )
    .expect("write");
    std::fs::write(
        src.join("b.rs"),
        "use crate::Thing;\npub struct Other;\npub fn g() {}\n",
    )
    .expect("write");
    let edges = module_edges(src);
    assert_eq!(edges["a"], BTreeSet::from(["b".to_string()]));
    assert_eq!(edges["b"], BTreeSet::from(["a".to_string()]));
    assert!(find_cycle(&edges).is_some());
    std::fs::write(src.join("b.rs"), "pub struct Other;\npub fn g() {}\n").expect("write");
    assert!(find_cycle(&module_edges(src)).is_none());
}

#[test]
fn the_command_line_tool_stays_thin() {
    fn lines(dir: &Path) -> usize {
        std::fs::read_dir(dir)
            .expect("dir")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .map(|p| {
                if p.is_dir() {
                    lines(&p)
                } else {
                    std::fs::read_to_string(&p).map_or(0, |t| t.lines().count())
                }
            })
            .sum()
    }
    let n = lines(&repo().join("src"));
    assert!(n < 2500, "src/ has {n} lines; move jobs into ibl-pipeline");
}

/// `package version -> the feature sets cargo resolves for it`, from `cargo tree` with `args`
/// (the host platform's dependencies).
fn resolved_features(args: &[&str]) -> BTreeMap<String, BTreeSet<String>> {
    let tree = [
        "tree", "--locked", "--prefix", "none", "--format", "{p}|{f}",
    ];
    let out = cargo(&[&tree[..], args].concat());
    let mut resolved: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for line in String::from_utf8_lossy(&out).lines() {
        let Some((package, features)) = line.trim_end_matches(" (*)").split_once('|') else {
            continue;
        };
        // "name vX.Y.Z (path)" -> "name vX.Y.Z".
        let package = package.split(' ').take(2).collect::<Vec<_>>().join(" ");
        resolved
            .entry(package)
            .or_default()
            .insert(features.to_string());
    }
    resolved
}

/// 4. CI builds the Python wheel (`maturin`, which builds `ibl-py` alone) after the Rust tests
///    and reuses their artifacts only where cargo resolves each shared crate with the features
///    the workspace's build gave it (crates/ibl-py/Cargo.toml, "The feature union";
///    BENCHMARKS.md, "CI"): a new dependency that breaks that costs CI minutes, not a failure,
///    so it is caught here.
#[test]
fn the_wheel_resolves_the_workspaces_features() {
    let wheel = resolved_features(&["-p", "ibl-py", "-e", "normal,build"]);
    let workspace = resolved_features(&["--workspace", "-e", "normal,build,dev"]);
    let missing: Vec<String> = wheel
        .iter()
        .filter_map(|(package, sets)| {
            let built = workspace.get(package)?;
            let unmatched: Vec<&String> = sets.difference(built).collect();
            (!unmatched.is_empty())
                .then(|| format!("{package}: {unmatched:?}, the workspace builds {built:?}"))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "ask crates/ibl-py/Cargo.toml for the workspace's features of:\n{}",
        missing.join("\n")
    );
}
