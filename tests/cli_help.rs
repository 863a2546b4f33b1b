//! Every command's help is for users: no internal references (an issue number, rustdoc link syntax, "the
//! design's"), and `solve --help`, the longest of the micro-solver's, fits a screen (≤ 40 lines) in its short
//! form (`-h`).

use std::process::Command;

fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .unwrap();
    assert!(out.status.success(), "hylc {args:?}");
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn no_help_text_leaks_internal_references() {
    let top = help(&["--help"]);
    let names: Vec<&str> = top
        .lines()
        .filter(|l| l.starts_with("  ") && !l.trim_start().starts_with('-'))
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(names.len() >= 20, "{top}");
    for name in names {
        for flag in ["--help", "-h"] {
            let text = help(&[name, flag]);
            for bad in ["issue", "[`", "design's"] {
                let hit = text.lines().find(|l| l.to_lowercase().contains(bad));
                assert!(hit.is_none(), "hylc {name} {flag}: {bad:?} in {hit:?}");
            }
        }
    }
}

#[test]
fn solve_short_help_fits_a_screen() {
    let n = help(&["solve", "-h"]).lines().count();
    assert!(n <= 40, "hylc solve -h: {n} lines");
}

#[test]
fn completions_name_every_command() {
    for shell in ["bash", "zsh", "fish"] {
        let text = help(&["completions", shell]);
        for name in ["simulate", "gradient", "sample", "fit", "check-derivatives"] {
            assert!(text.contains(name), "{shell}: {name} missing");
        }
    }
}
