//! The crate's layers import downwards only (`src/lib.rs`): every `crate::m` path in a top-level module's source
//! (comments and `#[cfg(test)]` modules aside) names a module listed before it in [`ORDER`]. A new import against
//! the order, and with it any cycle between modules, fails this test with the file and line at fault.
//!
//! Inside a layer, sibling modules (the children of one module, e.g. `sample::run` and `sample::starts`) import
//! each other without a cycle: every `crate::…`, `super::…` and `self::…` path (groups `{…}` expanded) is
//! resolved to the module it names, and the imports between the children of each module form an acyclic graph.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The crate's top-level modules from the bottom layer up (the order of `src/lib.rs`).
const ORDER: &[&str] = &[
    "provenance",
    "sparse",
    "strain",
    "real",
    "periodic",
    "diff",
    "material",
    "pattern",
    "rod",
    "contact",
    "tile",
    "micro",
    "sample",
    "fit",
    "shell",
    "generate",
    "workflow",
    "validation",
    "checks",
];

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `(line number, imported module)` of every `crate::m` outside comments and test modules.
fn imports(text: &str) -> Vec<(usize, String)> {
    let mut v = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap();
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            let tail = &rest[i + 7..];
            // `crate::{a, b}` would hide its modules from this scanner: the crate writes one path per module.
            assert!(
                !tail.starts_with('{'),
                "line {}: write `use crate::m::…` per module, not `crate::{{…}}`",
                n + 1
            );
            let name: String = tail
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            v.push((n + 1, name));
            rest = tail;
        }
    }
    v
}

#[test]
fn lib_declares_exactly_the_ordered_modules() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let mut declared: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod ").and_then(|r| r.strip_suffix(';')))
        .collect();
    declared.sort();
    let mut ordered = ORDER.to_vec();
    ordered.sort();
    assert_eq!(
        declared, ordered,
        "src/lib.rs and tests/layers.rs list different modules"
    );
}

#[test]
fn layers_import_downwards_only() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut violations = Vec::new();
    for (rank, m) in ORDER.iter().enumerate() {
        let mut files = Vec::new();
        let dir = src.join(m);
        if dir.is_dir() {
            sources(&dir, &mut files);
        }
        let file = src.join(format!("{m}.rs"));
        if file.is_file() {
            files.push(file);
        }
        assert!(!files.is_empty(), "module {m} has no source under src/");
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            for (line, dep) in imports(&text) {
                let Some(dep_rank) = ORDER.iter().position(|o| *o == dep) else {
                    continue; // an item of the crate root (e.g. `shared_dir`) or `crate::` in a string
                };
                if dep_rank >= rank && dep != *m {
                    violations.push(format!(
                        "{}:{line}: {m} imports {dep}, which is not below it",
                        f.strip_prefix(&src).unwrap().display()
                    ));
                }
            }
        }
    }
    assert!(
        violations.is_empty(),
        "imports against the layer order:\n{}",
        violations.join("\n")
    );
}

/// A module path from the crate root (`["sample", "run"]`).
type ModPath = Vec<String>;

/// The module a file under `src/` defines: `a/b.rs` and `a/b/mod.rs` are `a::b`, `lib.rs` the root.
fn module_of(rel: &Path) -> ModPath {
    let mut parts: ModPath = rel
        .with_extension("")
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// The tokens of the source before its first `#[cfg(test)]` line, comments cut, with their line numbers:
/// identifiers, `::`, and single characters; string and char literals are skipped.
fn tokens(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let code: Vec<char> = line.split("//").next().unwrap().chars().collect();
        let mut i = 0;
        while i < code.len() {
            let c = code[i];
            if c.is_alphabetic() || c == '_' {
                let start = i;
                while i < code.len() && (code[i].is_alphanumeric() || code[i] == '_') {
                    i += 1;
                }
                out.push((n + 1, code[start..i].iter().collect()));
                continue;
            }
            if c == '"' {
                i += 1;
                while i < code.len() && code[i] != '"' {
                    i += if code[i] == '\\' { 2 } else { 1 };
                }
            } else if c == '\''
                && i + 2 < code.len()
                && (code[i + 1] == '\\' || code[i + 2] == '\'')
            {
                i += 2;
                while i < code.len() && code[i] != '\'' {
                    i += 1;
                }
            } else if c == ':' && code.get(i + 1) == Some(&':') {
                out.push((n + 1, "::".to_string()));
                i += 1;
            } else if !c.is_whitespace() {
                out.push((n + 1, c.to_string()));
            }
            i += 1;
        }
    }
    out
}

fn is_ident(t: &str) -> bool {
    t.starts_with(|c: char| c.is_alphabetic() || c == '_')
}

/// The paths of one use tree starting at `toks[i]`, groups expanded (`a::{b, c::d}` is `a::b` and `a::c::d`;
/// `self` in a group names the group's prefix); returns them and the index after the tree.
fn use_tree(toks: &[(usize, String)], mut i: usize) -> (Vec<ModPath>, usize) {
    let mut prefix: ModPath = Vec::new();
    while i < toks.len() && is_ident(&toks[i].1) {
        prefix.push(toks[i].1.clone());
        i += 1;
        if toks.get(i).is_none_or(|t| t.1 != "::") {
            break;
        }
        i += 1;
        if toks.get(i).is_some_and(|t| t.1 == "{") {
            i += 1;
            let mut paths = Vec::new();
            while i < toks.len() && toks[i].1 != "}" {
                if toks[i].1 == "," {
                    i += 1;
                    continue;
                }
                let (sub, next) = use_tree(toks, i);
                for p in sub {
                    let mut full = prefix.clone();
                    full.extend(p.into_iter().filter(|s| s != "self"));
                    paths.push(full);
                }
                // `* ` or `X as Y`: skip to the entry's end
                i = next.max(i + 1);
                while i < toks.len() && toks[i].1 != "," && toks[i].1 != "}" {
                    i += 1;
                }
            }
            return (paths, i + 1);
        }
    }
    (vec![prefix], i)
}

/// `(line, module path from the crate root)` of every path in `text` that starts with `crate::`, `super::` or
/// `self::` (the module of the file is `here`).
fn resolved_paths(text: &str, here: &[String]) -> Vec<(usize, ModPath)> {
    let toks = tokens(text);
    let mut out = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        let t = toks[i].1.as_str();
        let starts_path = matches!(t, "crate" | "super" | "self")
            && (i == 0 || toks[i - 1].1 != "::")
            && toks.get(i + 1).is_some_and(|t| t.1 == "::");
        if !starts_path {
            i += 1;
            continue;
        }
        let (paths, next) = use_tree(&toks, i);
        for p in paths {
            let (mut base, mut k) = if p[0] == "crate" {
                (Vec::new(), 1)
            } else {
                (here.to_vec(), 0)
            };
            while k < p.len() && (p[k] == "super" || p[k] == "self") {
                if p[k] == "super" {
                    base.pop();
                }
                k += 1;
            }
            base.extend(p[k..].iter().cloned());
            out.push((toks[i].0, base));
        }
        i = next.max(i + 1);
    }
    out
}

/// The imports between sibling modules: for each parent module, `(from, to)` child pairs with the first site.
fn sibling_imports() -> BTreeMap<ModPath, BTreeMap<(String, String), String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    files.retain(|f| !f.strip_prefix(&src).unwrap().starts_with("bin"));
    let modules: BTreeSet<ModPath> = files
        .iter()
        .map(|f| module_of(f.strip_prefix(&src).unwrap()))
        .collect();
    let mut edges: BTreeMap<ModPath, BTreeMap<(String, String), String>> = BTreeMap::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap();
        let here = module_of(rel);
        let text = std::fs::read_to_string(f).unwrap();
        for (line, target) in resolved_paths(&text, &here) {
            let d = here.iter().zip(&target).take_while(|(a, b)| a == b).count();
            if d < here.len() && d < target.len() && modules.contains(&target[..=d]) {
                edges
                    .entry(here[..d].to_vec())
                    .or_default()
                    .entry((here[d].clone(), target[d].clone()))
                    .or_insert_with(|| format!("{}:{line}", rel.display()));
            }
        }
    }
    edges
}

/// A cycle through `start` in `adj`, as the list of its modules, if there is one.
fn cycle_through(adj: &BTreeMap<&str, Vec<&str>>, start: &str) -> Option<Vec<String>> {
    fn walk<'a>(
        adj: &BTreeMap<&'a str, Vec<&'a str>>,
        start: &str,
        at: &'a str,
        path: &mut Vec<&'a str>,
        seen: &mut BTreeSet<&'a str>,
    ) -> bool {
        for &next in adj.get(at).into_iter().flatten() {
            if next == start {
                return true;
            }
            if seen.insert(next) {
                path.push(next);
                if walk(adj, start, next, path, seen) {
                    return true;
                }
                path.pop();
            }
        }
        false
    }
    let mut path = vec![];
    let mut seen = BTreeSet::new();
    let start_ref = adj.keys().find(|k| **k == start)?;
    path.push(*start_ref);
    walk(adj, start, start_ref, &mut path, &mut seen)
        .then(|| path.iter().map(|s| s.to_string()).collect())
}

#[test]
fn sibling_modules_import_without_cycles() {
    let mut cycles = Vec::new();
    for (parent, pairs) in sibling_imports() {
        let mut adj: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
        for (a, b) in pairs.keys() {
            adj.entry(a.as_str()).or_default().push(b.as_str());
        }
        let mut reported = BTreeSet::new();
        for start in adj.keys() {
            let Some(cycle) = cycle_through(&adj, start) else {
                continue;
            };
            let mut key = cycle.clone();
            key.sort();
            if !reported.insert(key) {
                continue;
            }
            let parent = if parent.is_empty() {
                "crate".to_string()
            } else {
                parent.join("::")
            };
            let mut ring = cycle.clone();
            ring.push(cycle[0].clone());
            let sites: Vec<String> = ring
                .windows(2)
                .map(|w| {
                    format!(
                        "  {} → {}: {}",
                        w[0],
                        w[1],
                        pairs[&(w[0].clone(), w[1].clone())]
                    )
                })
                .collect();
            cycles.push(format!(
                "in {parent}: {}\n{}",
                ring.join(" → "),
                sites.join("\n")
            ));
        }
    }
    assert!(
        cycles.is_empty(),
        "sibling modules import each other in a cycle (move the shared items into a third module or into \
         the lower one):\n{}",
        cycles.join("\n")
    );
}

#[test]
fn the_path_resolver_expands_groups_and_climbs_super() {
    let here: Vec<String> = vec!["shell".into(), "solver".into(), "terms".into()];
    let text = "use super::{dissipation, obstacle::{self, X}, Simulation};\nuse crate::shell::motion::Motion; // super::no\nfn f() { super::super::mesh::g(\"super::str\") }\n#[cfg(test)]\nuse super::tests;";
    let got: Vec<(usize, String)> = resolved_paths(text, &here)
        .into_iter()
        .map(|(l, p)| (l, p.join("::")))
        .collect();
    let want = [
        (1, "shell::solver::dissipation"),
        (1, "shell::solver::obstacle"),
        (1, "shell::solver::obstacle::X"),
        (1, "shell::solver::Simulation"),
        (2, "shell::motion::Motion"),
        (3, "shell::mesh::g"),
    ];
    let want: Vec<(usize, String)> = want.iter().map(|(l, p)| (*l, p.to_string())).collect();
    assert_eq!(got, want);
}

#[test]
fn the_scanner_sees_imports_and_skips_comments_and_tests() {
    let text = "use crate::rod::X; // crate::shell\n//! crate::fit\nfn f() { crate::tile::g() }\n#[cfg(test)]\nuse crate::checks;";
    let got: Vec<(usize, String)> = imports(text);
    assert_eq!(got, vec![(1, "rod".to_string()), (3, "tile".to_string())]);
}
