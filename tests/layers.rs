//! The crate's layers import downwards only (`src/lib.rs`): every `crate::m` path in a top-level module's source
//! (comments and `#[cfg(test)]` modules aside) names a module listed before it in [`ORDER`]. A new import against
//! the order, and with it any cycle between modules, fails this test with the file and line at fault.

use std::path::{Path, PathBuf};

/// The crate's top-level modules from the bottom layer up (the order of `src/lib.rs`).
const ORDER: &[&str] = &[
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

#[test]
fn the_scanner_sees_imports_and_skips_comments_and_tests() {
    let text = "use crate::rod::X; // crate::shell\n//! crate::fit\nfn f() { crate::tile::g() }\n#[cfg(test)]\nuse crate::checks;";
    let got: Vec<(usize, String)> = imports(text);
    assert_eq!(got, vec![(1, "rod".to_string()), (3, "tile".to_string())]);
}
