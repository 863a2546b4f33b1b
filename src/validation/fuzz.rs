//! The fuzz suite (docs/robustness.md; `docs/robustness.md`, robustness): mutated inputs of the five input
//! formats — `.pyp` patterns, material JSON, sampling plans, scene JSON and sample files — through the library's
//! parsers and, where a mutant parses, its evaluators, in process.
//!
//! Seeds are generated (no external data): the five generated patterns, the embedded default material, the
//! built-in plans and scenes, and sample records. A case applies one to three mutators ([`Mutation`]):
//! truncation, a deleted or duplicated line, a number replaced by NaN/inf/±1e308/5e-324/2⁶⁴/a negative, a UTF-8
//! byte-order mark, CRLF line ends, binary garbage, a huge line. Each case runs under `catch_unwind` and is
//! classified ([`Outcome`]): accepted (parsed, and every evaluation finite), rejected with a typed error,
//! non-finite output of an accepted input, panic, or slow (longer than [`CASE_BUDGET`]). The targets are zero of
//! the last three. A hang or an abort (allocation failure) ends the process, which is a failure too.

use crate::generate::{default_pattern, DEFAULT_KINDS};
use crate::material::synthetic::default_material;
use crate::material::Material;
use crate::micro::strain::MacroStrain;
use crate::micro::{MicroProblem, SolverOptions};
use crate::pattern::Pattern;
use crate::rod::YarnMaterial;
use crate::sample::{read_samples, Plan, Record, SampleStart, SampleStatus};
use crate::shell::scene::{builtin, Scene, BUILTINS};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::time::{Duration, Instant};

/// Wall time one case may take (its own solver limit is 1 s; one more second for parsing and set-up).
pub const CASE_BUDGET: Duration = Duration::from_secs(2);

/// The longest "huge line" a mutator inserts (characters).
pub const HUGE_LINE: usize = 100_000;

/// The input formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Pattern files (`.pyp`).
    Pyp,
    /// Material JSON files.
    Material,
    /// Sampling plan JSON files.
    Plan,
    /// Scene JSON files.
    Scene,
    /// Sample files (JSON lines).
    Samples,
}

impl Format {
    /// Every format.
    pub const ALL: [Format; 5] = [
        Format::Pyp,
        Format::Material,
        Format::Plan,
        Format::Scene,
        Format::Samples,
    ];

    /// The format's name (`pyp`, `material`, `plan`, `scene`, `samples`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Pyp => "pyp",
            Format::Material => "material",
            Format::Plan => "plan",
            Format::Scene => "scene",
            Format::Samples => "samples",
        }
    }
}

/// One mutation of a text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mutation {
    /// Cut the text at a random byte.
    Truncate,
    /// Delete a random line.
    DeleteLine,
    /// Duplicate a random line.
    DuplicateLine,
    /// Replace one number by one of [`EXTREME_NUMBERS`].
    ReplaceNumber,
    /// Prepend a UTF-8 byte-order mark.
    ByteOrderMark,
    /// Turn every line end into CR LF.
    Crlf,
    /// Insert 1–63 random bytes at a random place.
    Garbage,
    /// Insert a run of up to [`HUGE_LINE`] `9`s or `x`s at a random place.
    HugeLine,
}

impl Mutation {
    /// Every mutation.
    pub const ALL: [Mutation; 8] = [
        Mutation::Truncate,
        Mutation::DeleteLine,
        Mutation::DuplicateLine,
        Mutation::ReplaceNumber,
        Mutation::ByteOrderMark,
        Mutation::Crlf,
        Mutation::Garbage,
        Mutation::HugeLine,
    ];
}

/// The numbers a [`Mutation::ReplaceNumber`] puts in place of one number of the text.
pub const EXTREME_NUMBERS: [&str; 14] = [
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "5e-324",
    "18446744073709551616",
    "18446744073709551615",
    "4294967296",
    "-1",
    "-0.5",
    "0",
    "1e9",
];

/// Apply `m` to `text` (bytes: the result need not be UTF-8).
pub fn mutate(text: &[u8], m: Mutation, rng: &mut ChaCha8Rng) -> Vec<u8> {
    let lines =
        |t: &[u8]| -> Vec<Vec<u8>> { t.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect() };
    match m {
        Mutation::Truncate => text[..rng.random_range(0..=text.len())].to_vec(),
        Mutation::DeleteLine | Mutation::DuplicateLine => {
            let mut ls = lines(text);
            let i = rng.random_range(0..ls.len());
            if m == Mutation::DeleteLine {
                ls.remove(i);
            } else {
                let l = ls[i].clone();
                ls.insert(i, l);
            }
            ls.join(&b'\n')
        }
        Mutation::ReplaceNumber => replace_number(text, rng),
        Mutation::ByteOrderMark => [&[0xEF, 0xBB, 0xBF][..], text].concat(),
        Mutation::Crlf => {
            let mut out = Vec::with_capacity(text.len() + text.len() / 8);
            for &b in text {
                if b == b'\n' {
                    out.push(b'\r');
                }
                out.push(b);
            }
            out
        }
        Mutation::Garbage => {
            let at = rng.random_range(0..=text.len());
            let n = rng.random_range(1..64);
            let junk: Vec<u8> = (0..n).map(|_| rng.random()).collect();
            [&text[..at], &junk[..], &text[at..]].concat()
        }
        Mutation::HugeLine => {
            let at = rng.random_range(0..=text.len());
            let n = rng.random_range(1..=HUGE_LINE);
            let fill = if rng.random_bool(0.5) { b'9' } else { b'x' };
            [&text[..at], &vec![fill; n][..], &text[at..]].concat()
        }
    }
}

/// Replace one number of the text (a maximal run of digits, signs, points and exponents) by an extreme one.
fn replace_number(text: &[u8], rng: &mut ChaCha8Rng) -> Vec<u8> {
    let is_num = |b: u8| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E');
    let mut spans = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if text[i].is_ascii_digit() {
            let mut a = i;
            while a > 0 && is_num(text[a - 1]) && !text[a - 1].is_ascii_alphabetic() {
                a -= 1;
            }
            let mut b = i;
            while b < text.len() && is_num(text[b]) {
                b += 1;
            }
            spans.push((a, b));
            i = b;
        } else {
            i += 1;
        }
    }
    if spans.is_empty() {
        return text.to_vec();
    }
    let (a, b) = spans[rng.random_range(0..spans.len())];
    let new = EXTREME_NUMBERS[rng.random_range(0..EXTREME_NUMBERS.len())];
    [&text[..a], new.as_bytes(), &text[b..]].concat()
}

/// How one case ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Parsed, and every evaluation gave finite numbers or a typed error.
    Accepted,
    /// Rejected with a typed error.
    Rejected,
    /// Accepted, but an evaluation gave a non-finite number (the message says which).
    NonFinite(String),
    /// Panicked (the message).
    Panic(String),
}

/// The counts of a run over one format, with the first few failures.
#[derive(Clone, Debug, Default)]
pub struct FuzzReport {
    /// Cases run.
    pub cases: usize,
    /// Cases parsed with finite evaluations ([`Outcome::Accepted`]).
    pub accepted: usize,
    /// Cases rejected with a typed error.
    pub rejected: usize,
    /// Cases with a non-finite evaluation.
    pub non_finite: usize,
    /// Cases that panicked.
    pub panics: usize,
    /// Cases longer than [`CASE_BUDGET`].
    pub slow: usize,
    /// The longest wall time of a case.
    pub longest: Duration,
    /// (case, mutations, what happened) of the first failures.
    pub failures: Vec<(usize, Vec<Mutation>, String)>,
}

impl FuzzReport {
    /// The counts as one line: cases, accepted, rejected, non-finite, panics, slow, longest case.
    pub fn counts(&self) -> String {
        format!(
            "{} cases, {} accepted, {} rejected, {} non-finite, {} panics, {} slow, longest {:.2} s",
            self.cases,
            self.accepted,
            self.rejected,
            self.non_finite,
            self.panics,
            self.slow,
            self.longest.as_secs_f64()
        )
    }

    /// Panics, non-finite outputs and slow cases: the targets are zero.
    pub fn failed(&self) -> usize {
        self.non_finite + self.panics + self.slow
    }
}

/// The seed texts of a format.
pub fn seeds(format: Format) -> Vec<String> {
    match format {
        Format::Pyp => DEFAULT_KINDS
            .iter()
            .filter_map(|k| default_pattern(k).ok())
            .map(|p| p.to_pyp_string())
            .collect(),
        Format::Material => vec![default_material().to_json_string()],
        Format::Plan => [Plan::quick(), Plan::reduced(), Plan::holdout()]
            .iter()
            .map(|p| serde_json::to_string_pretty(p).unwrap_or_default())
            .collect(),
        Format::Scene => BUILTINS
            .iter()
            .filter_map(|b| builtin(b))
            .map(|s| serde_json::to_string_pretty(&s).unwrap_or_default())
            .collect(),
        Format::Samples => vec![sample_seed()],
    }
}

/// A small sample file: records of a few strains, as `hylc sample` writes them.
fn sample_seed() -> String {
    let m = default_material();
    let mut text = String::new();
    for (i, z) in [
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [0.1, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.2, 0.05, 0.0, 0.0],
        [0.0, 0.0, 0.0, 30.0, 0.0],
    ]
    .iter()
    .enumerate()
    {
        let e = m.eval(&[z[0], z[1], z[2], z[3], 0.0, z[4]]);
        let r = Record {
            id: format!("0123456789abcdef-{i}"),
            index: i,
            z: *z,
            psi: Some(e.value),
            stress: Some([
                Some(e.grad[0]),
                Some(e.grad[1]),
                Some(e.grad[2]),
                Some(e.grad[3]),
                Some(e.grad[5]),
            ]),
            status: SampleStatus::Converged,
            error: None,
            steps: 3,
            gradient_norm: Some(1e-10),
            time: 0.01,
            start: SampleStart::Warm,
            problem: "0123456789abcdef".into(),
            starts: vec![],
            kept: None,
            crossings: None,
            dpsi_dtheta: None,
            dstress_dtheta: None,
        };
        text += &serde_json::to_string(&r).unwrap_or_default();
        text.push('\n');
    }
    text
}

/// Parse (and evaluate) one mutated input; `scratch` is a folder for the formats read from files.
pub fn run_case(format: Format, bytes: &[u8], scratch: &Path) -> Outcome {
    let text = String::from_utf8_lossy(bytes);
    match format {
        Format::Pyp => pyp_case(&text),
        Format::Material => material_case(&text),
        Format::Plan => plan_case(&text),
        Format::Scene => scene_case(&text),
        Format::Samples => samples_case(bytes, scratch),
    }
}

fn finite_or(what: &str, v: f64) -> Result<(), Outcome> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Outcome::NonFinite(format!("{what} = {v}")))
    }
}

/// A pattern: parse, then a short solve at zero strain (1 s, 3 steps): Ψ̄ must be finite or an error.
fn pyp_case(text: &str) -> Outcome {
    let Ok((p, _warnings)) = Pattern::from_pyp_str(text, "fuzz.pyp") else {
        return Outcome::Rejected;
    };
    let options = SolverOptions {
        max_steps: 3,
        time_limit: Some(1.0),
        ..SolverOptions::default()
    };
    let problem = MicroProblem::new(p, &YarnMaterial::default(), options);
    match problem.solve(&MacroStrain::ZERO, None) {
        Ok(sol) => match sol.psi() {
            Ok(psi) => finite_or("Ψ̄", psi).err().unwrap_or(Outcome::Accepted),
            Err(_) => Outcome::Accepted,
        },
        Err(_) => Outcome::Accepted,
    }
}

/// A material: parse, then ψ, ∇ψ, ∇²ψ at z = 0 and at three small strains must be finite.
fn material_case(text: &str) -> Outcome {
    let Ok(m) = Material::from_json_str(text, "fuzz.json") else {
        return Outcome::Rejected;
    };
    let zs = [
        [0.0; 6],
        [0.1, 0.2, -0.05, 30.0, -10.0, 20.0],
        [-0.2, -0.3, 0.4, -50.0, 5.0, 0.0],
        [0.5, 0.0, 0.5, 0.0, 0.0, 100.0],
    ];
    for z in &zs {
        let r = m.eval(z);
        let all = std::iter::once(r.value)
            .chain(r.grad)
            .chain(r.hess.iter().flatten().copied());
        for v in all {
            if let Err(o) = finite_or(&format!("ψ or a derivative at z = {z:?}"), v) {
                return o;
            }
        }
    }
    Outcome::Accepted
}

/// A plan: parse (validation included), then its samples and chains.
fn plan_case(text: &str) -> Outcome {
    let Ok(p) = Plan::from_json(text, Some("fuzz.json")) else {
        return Outcome::Rejected;
    };
    let samples = p.samples();
    let chains = p.chains();
    if samples.len() != p.len() || chains.iter().map(|c| c.steps.len()).sum::<usize>() != p.len() {
        return Outcome::NonFinite(format!(
            "{} samples, {} in chains, len {}",
            samples.len(),
            chains.iter().map(|c| c.steps.len()).sum::<usize>(),
            p.len()
        ));
    }
    for s in &samples {
        for v in s.z {
            if let Err(o) = finite_or("a plan strain", v) {
                return o;
            }
        }
    }
    Outcome::Accepted
}

/// A scene: parse and build (mesh, material, handles); the build must reject what it cannot simulate.
fn scene_case(text: &str) -> Outcome {
    let Ok(s) = Scene::from_json_str(text, "fuzz.json") else {
        return Outcome::Rejected;
    };
    match s.build("fuzz.json", Path::new(".")) {
        Ok((sim, _)) => {
            for x in sim.positions().iter().flatten() {
                if let Err(o) = finite_or("an initial position", *x) {
                    return o;
                }
            }
            Outcome::Accepted
        }
        Err(_) => Outcome::Rejected,
    }
}

/// A sample file: read it as `hylc fit` does.
fn samples_case(bytes: &[u8], scratch: &Path) -> Outcome {
    let path = scratch.join("fuzz.jsonl");
    if std::fs::write(&path, bytes).is_err() {
        return Outcome::Rejected;
    }
    match read_samples(&path, false) {
        Ok(_) => Outcome::Accepted,
        Err(_) => Outcome::Rejected,
    }
}

/// Run `cases` mutated inputs of `format` (seeded: the same `seed` gives the same cases), with `scratch` a
/// writable folder. `progress` is called every 1 000 cases with the cases done.
pub fn run(
    format: Format,
    cases: usize,
    seed: u64,
    scratch: &Path,
    progress: &mut dyn FnMut(usize),
) -> FuzzReport {
    let seeds = seeds(format);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (format as u64).wrapping_mul(0x9E37_79B9));
    let mut report = FuzzReport::default();
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    for case in 0..cases {
        let base = seeds[rng.random_range(0..seeds.len())].as_bytes().to_vec();
        // half the cases change only numbers (the text stays well-formed and reaches the evaluators), half mix
        // every mutator
        let n = rng.random_range(1..=3);
        let numbers_only = rng.random_bool(0.5);
        let muts: Vec<Mutation> = (0..n)
            .map(|_| {
                if numbers_only {
                    Mutation::ReplaceNumber
                } else {
                    Mutation::ALL[rng.random_range(0..Mutation::ALL.len())]
                }
            })
            .collect();
        let mut bytes = base;
        for &m in &muts {
            bytes = mutate(&bytes, m, &mut rng);
        }
        let t = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| run_case(format, &bytes, scratch)))
            .unwrap_or_else(|e| {
                let msg = e
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| e.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "panic".into());
                Outcome::Panic(msg)
            });
        let dt = t.elapsed();
        report.cases += 1;
        report.longest = report.longest.max(dt);
        let fail = |what: String, report: &mut FuzzReport| {
            if report.failures.len() < 10 {
                report.failures.push((case, muts.clone(), what));
            }
        };
        if dt > CASE_BUDGET {
            report.slow += 1;
            fail(format!("slow: {:.1} s", dt.as_secs_f64()), &mut report);
        }
        match outcome {
            Outcome::Accepted => report.accepted += 1,
            Outcome::Rejected => report.rejected += 1,
            Outcome::NonFinite(m) => {
                report.non_finite += 1;
                fail(format!("non-finite: {m}"), &mut report);
            }
            Outcome::Panic(m) => {
                report.panics += 1;
                fail(format!("panic: {m}"), &mut report);
            }
        }
        if (case + 1) % 1000 == 0 {
            progress(case + 1);
        }
    }
    std::panic::set_hook(hook);
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutators_change_the_text_as_named() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let t = b"a 1.5\nb 2\nc -3e4\n";
        assert!(mutate(t, Mutation::ByteOrderMark, &mut rng).starts_with(&[0xEF, 0xBB, 0xBF]));
        assert_eq!(
            mutate(t, Mutation::Crlf, &mut rng),
            b"a 1.5\r\nb 2\r\nc -3e4\r\n"
        );
        let r = mutate(t, Mutation::ReplaceNumber, &mut rng);
        let s = String::from_utf8(r).unwrap();
        assert!(EXTREME_NUMBERS.iter().any(|n| s.contains(n)), "{s}");
        assert!(mutate(t, Mutation::Truncate, &mut rng).len() <= t.len());
        let d = mutate(t, Mutation::DeleteLine, &mut rng);
        assert_eq!(d.iter().filter(|&&b| b == b'\n').count(), 2);
        let h = mutate(t, Mutation::HugeLine, &mut rng);
        assert!(h.len() > t.len());
        for f in Format::ALL {
            assert!(!seeds(f).is_empty(), "{}", f.name());
        }
    }

    #[test]
    fn unmutated_seeds_are_accepted() {
        let dir = std::env::temp_dir().join(format!("hylc-fuzz-seeds-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for f in Format::ALL {
            for s in seeds(f) {
                assert_eq!(
                    run_case(f, s.as_bytes(), &dir),
                    Outcome::Accepted,
                    "{}",
                    f.name()
                );
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}
