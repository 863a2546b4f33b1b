//! Multi-start samples (docs/sampling.md, "Multi-start samples"; `docs/sampling.md`, section
//! "Running a plan": "measure how far the two differ").
//!
//! - [`Starts::Warm`] (the default) solves each sample once, from its chain's warm start, and writes the records
//!   of earlier versions (no `starts`, no `kept`).
//! - [`Starts::WarmCold`] also solves every sample cold (from the reference state) and keeps the converged start
//!   with the lowest Ψ̄ ([`keep`]); the record lists every start ([`StartResult`]) and names the one kept. The
//!   chain still continues from its warm equilibria, so the warm start of every sample is the one of a `warm` run
//!   and the cold start the one of a `--cold` run: the kept Ψ̄ is ≤ both wherever they converged, and it depends
//!   only on the sample's chain (not on scheduling, shards or resume).
//! - [`Starts::All`] adds, for every sample whose warm and cold starts disagree (by more than
//!   [`RunOptions::disagreement`](super::RunOptions::disagreement) relative, or one converged and the other not),
//!   a start from the kept equilibrium of every step that continues it: the chain run in reverse, in a second pass
//!   after the forward pass, so a chain's records are written when the chain is done, and resuming a chain with
//!   an unfinished step solves the whole chain again (its finished records are not rewritten).
//! - [`compare`] checks two sample files of one plan for agreement (e.g. warm-first against cold-first): the
//!   samples converged in both whose Ψ̄ differ by more than a relative tolerance, with both energies.

use super::record::{Record, StartKind, StartResult};
use crate::micro::MicroState;
use std::collections::HashMap;

/// Which starts each sample is solved from (`hylc sample --starts`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Starts {
    /// The warm start along the chain only (today's records, bit for bit).
    #[default]
    Warm,
    /// The warm start and the cold start (reference state); the lowest converged Ψ̄ is kept.
    WarmCold,
    /// Warm and cold, and where they disagree the reversed chain (starts from the steps that continue a sample).
    All,
}

/// The default relative disagreement of the warm and the cold Ψ̄ above which `--starts all` tries the reversed
/// chain.
pub const DEFAULT_DISAGREEMENT: f64 = 1e-6;

impl std::fmt::Display for Starts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Starts::Warm => "warm",
            Starts::WarmCold => "warm+cold",
            Starts::All => "all",
        })
    }
}

/// Combine the solves of one sample from several starts (in order of preference, non-empty): the kept record is
/// the converged one with the lowest Ψ̄ (the first of equal ones), or the first when none converged; it gets the
/// list of all starts, the kind kept and the summed wall time.
pub fn keep(solves: Vec<(StartKind, Record)>) -> Record {
    let k = kept_index(solves.iter().map(|(_, r)| r));
    let starts: Vec<StartResult> = solves
        .iter()
        .map(|(kind, r)| StartResult {
            kind: *kind,
            psi: r.converged_psi(),
            status: r.status,
            steps: r.steps,
            crossings: r.crossings,
        })
        .collect();
    let time = solves.iter().map(|(_, r)| r.time).sum();
    let (kind, mut record) = solves.into_iter().nth(k).expect("at least one start");
    record.time = time;
    record.starts = starts;
    record.kept = Some(kind);
    record
}

/// The index of the record [`keep`] keeps: the converged one with the lowest Ψ̄ (the first of equal ones), else 0.
/// A start whose path crossed yarns does not count as converged ([`Record::converged_psi`]).
pub(super) fn kept_index<'a>(records: impl Iterator<Item = &'a Record>) -> usize {
    let mut best: Option<(usize, f64)> = None;
    for (i, r) in records.enumerate() {
        if let Some(p) = r.converged_psi() {
            if best.is_none_or(|(_, b)| p < b) {
                best = Some((i, p));
            }
        }
    }
    best.map_or(0, |(i, _)| i)
}

/// One start's solve: its kind, record and converged state.
pub(super) type Solve = (StartKind, Record, Option<MicroState>);

/// Whether a sample's warm and cold starts disagree: one converged and the other not, or both converged with Ψ̄
/// more than `rel` apart ([`relative_difference`]). A sample with one start does not disagree.
pub(super) fn disagree(solves: &[Solve], rel: f64) -> bool {
    let psi = |k: StartKind| {
        solves
            .iter()
            .find(|s| s.0 == k)
            .map(|s| s.1.converged_psi())
    };
    match (psi(StartKind::Warm), psi(StartKind::Cold)) {
        (Some(Some(a)), Some(Some(b))) => relative_difference(a, b) > rel,
        (Some(a), Some(b)) => a.is_some() != b.is_some(),
        _ => false,
    }
}

/// A sample converged in both files whose Ψ̄ differ by more than the tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct Disagreement {
    /// The sample's id.
    pub id: String,
    /// Its index in the plan.
    pub index: usize,
    /// Its strain z = (s_x, s_a, s_y, Π₀₀, Π₁₁).
    pub z: [f64; 5],
    /// Ψ̄ in the first file (J/m²).
    pub psi_a: f64,
    /// Ψ̄ in the second file (J/m²).
    pub psi_b: f64,
    /// |Ψ̄_a − Ψ̄_b| / max(|Ψ̄_a|, |Ψ̄_b|) (0 when both are 0).
    pub relative: f64,
}

/// The agreement of two sample files of one plan ([`compare`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Comparison {
    /// Ids in both files.
    pub common: usize,
    /// Ids in only one of the files.
    pub only_a: usize,
    /// Ids in the second file only.
    pub only_b: usize,
    /// Of the common ids: converged in both, in one only, in neither.
    pub both_converged: usize,
    /// Common ids converged in one file only.
    pub one_converged: usize,
    /// Common ids converged in neither file.
    pub neither_converged: usize,
    /// Converged in both and within the tolerance.
    pub agree: usize,
    /// Converged in both and not within the tolerance, by plan index.
    pub differ: Vec<Disagreement>,
}

/// Relative difference |a − b| / max(|a|, |b|), 0 when both are 0.
pub fn relative_difference(a: f64, b: f64) -> f64 {
    let scale = a.abs().max(b.abs());
    if scale == 0.0 {
        0.0
    } else {
        (a - b).abs() / scale
    }
}

/// Compare the records of two sample files by id: the samples converged in both whose Ψ̄ differ by more than
/// `rel` relative ([`relative_difference`]), and the counts. With a repeated id the last record counts.
pub fn compare(a: &[Record], b: &[Record], rel: f64) -> Comparison {
    let bs: HashMap<&str, &Record> = b.iter().map(|r| (r.id.as_str(), r)).collect();
    let as_: HashMap<&str, &Record> = a.iter().map(|r| (r.id.as_str(), r)).collect();
    let mut c = Comparison::default();
    let mut ids: Vec<&&Record> = as_.values().collect();
    ids.sort_by(|x, y| x.index.cmp(&y.index).then_with(|| x.id.cmp(&y.id)));
    for ra in ids {
        let Some(rb) = bs.get(ra.id.as_str()) else {
            c.only_a += 1;
            continue;
        };
        c.common += 1;
        match (ra.converged_psi(), rb.converged_psi()) {
            (Some(pa), Some(pb)) => {
                c.both_converged += 1;
                let d = relative_difference(pa, pb);
                if d > rel {
                    c.differ.push(Disagreement {
                        id: ra.id.clone(),
                        index: ra.index,
                        z: ra.z,
                        psi_a: pa,
                        psi_b: pb,
                        relative: d,
                    });
                } else {
                    c.agree += 1;
                }
            }
            (None, None) => c.neither_converged += 1,
            _ => c.one_converged += 1,
        }
    }
    c.only_b = bs.keys().filter(|id| !as_.contains_key(*id)).count();
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::record::{SampleStart, SampleStatus};

    fn record(psi: Option<f64>, status: SampleStatus, steps: usize) -> Record {
        Record {
            id: "x-0".into(),
            index: 0,
            z: [0.1, 0.0, 0.0, 0.0, 0.0],
            psi,
            stress: None,
            status,
            error: None,
            steps,
            gradient_norm: Some(1e-12),
            time: 0.5,
            start: SampleStart::Warm,
            problem: "0".into(),
            starts: vec![],
            kept: None,
            crossings: None,
            dpsi_dtheta: None,
            dstress_dtheta: None,
        }
    }

    #[test]
    fn keep_prefers_starts_without_yarn_crossings() {
        let mut warm = record(Some(2.0), SampleStatus::Converged, 3);
        warm.crossings = Some(0);
        let mut cold = record(Some(0.1), SampleStatus::Converged, 40);
        cold.start = SampleStart::Cold;
        cold.crossings = Some(3);
        // the lower Ψ̄ of a start that pulled yarns through each other is another fabric's
        let k = keep(vec![
            (StartKind::Warm, warm.clone()),
            (StartKind::Cold, cold.clone()),
        ]);
        assert_eq!((k.kept, k.psi), (Some(StartKind::Warm), Some(2.0)));
        assert_eq!(
            k.starts.iter().map(|s| s.crossings).collect::<Vec<_>>(),
            vec![Some(0), Some(3)]
        );
        assert_eq!(k.starts[1].psi, None);
        assert_eq!(k.starts[1].status, SampleStatus::Converged);
        // when every converged start crossed, none is a sample: the first record is kept, with its crossings
        let mut warm_crossed = warm.clone();
        warm_crossed.crossings = Some(1);
        let k = keep(vec![
            (StartKind::Warm, warm_crossed),
            (StartKind::Cold, cold.clone()),
        ]);
        assert_eq!((k.kept, k.crossings), (Some(StartKind::Warm), Some(1)));
        assert_eq!(k.converged_psi(), None);
        // not checked counts as clean, and a clean start that did not converge is not preferred
        warm.crossings = None;
        let mut stalled = record(Some(0.05), SampleStatus::Stalled, 2000);
        stalled.crossings = Some(0);
        let k = keep(vec![
            (StartKind::Cold, cold),
            (StartKind::Warm, warm),
            (StartKind::Reverse, stalled),
        ]);
        assert_eq!((k.kept, k.psi), (Some(StartKind::Warm), Some(2.0)));
    }

    #[test]
    fn keep_takes_the_lowest_converged_start() {
        let warm = record(Some(2.0), SampleStatus::Converged, 3);
        let mut cold = record(Some(1.0), SampleStatus::Converged, 9);
        cold.start = SampleStart::Cold;
        let k = keep(vec![
            (StartKind::Warm, warm.clone()),
            (StartKind::Cold, cold.clone()),
        ]);
        assert_eq!(k.kept, Some(StartKind::Cold));
        assert_eq!((k.psi, k.steps, k.start), (Some(1.0), 9, SampleStart::Cold));
        assert_eq!(k.time, 1.0);
        assert_eq!(
            k.starts.iter().map(|s| s.psi).collect::<Vec<_>>(),
            vec![Some(2.0), Some(1.0)]
        );
        // a lower Ψ̄ of a start that did not converge is no equilibrium
        let stalled = record(Some(0.5), SampleStatus::Stalled, 2000);
        let k = keep(vec![
            (StartKind::Warm, warm.clone()),
            (StartKind::Cold, stalled),
        ]);
        assert_eq!((k.kept, k.psi), (Some(StartKind::Warm), Some(2.0)));
        assert_eq!(k.starts[1].psi, None);
        assert_eq!(k.starts[1].status, SampleStatus::Stalled);
        // equal energies keep the first start; none converged keeps the first record
        let k = keep(vec![
            (StartKind::Warm, warm.clone()),
            (StartKind::Cold, warm),
        ]);
        assert_eq!(k.kept, Some(StartKind::Warm));
        let bad = record(None, SampleStatus::MaxSteps, 2000);
        let k = keep(vec![(StartKind::Warm, bad.clone()), (StartKind::Cold, bad)]);
        assert_eq!(
            (k.kept, k.status),
            (Some(StartKind::Warm), SampleStatus::MaxSteps)
        );
    }

    #[test]
    fn compare_lists_converged_samples_that_differ() {
        let mk = |i: usize, psi: Option<f64>| {
            let mut r = record(psi, SampleStatus::Converged, 1);
            r.id = format!("x-{i}");
            r.index = i;
            if psi.is_none() {
                r.status = SampleStatus::MaxSteps;
            }
            r
        };
        let a = vec![
            mk(0, Some(1.0)),
            mk(1, Some(2.0)),
            mk(2, None),
            mk(3, None),
            mk(4, Some(1.0)),
        ];
        let b = vec![
            mk(0, Some(1.0 + 1e-9)),
            mk(1, Some(3.0)),
            mk(2, Some(1.0)),
            mk(3, None),
            mk(5, Some(1.0)),
        ];
        let c = compare(&a, &b, 1e-6);
        assert_eq!((c.common, c.only_a, c.only_b), (4, 1, 1));
        assert_eq!(
            (c.both_converged, c.one_converged, c.neither_converged),
            (2, 1, 1)
        );
        assert_eq!(c.agree, 1);
        assert_eq!(c.differ.len(), 1);
        assert_eq!(
            (c.differ[0].index, c.differ[0].psi_a, c.differ[0].psi_b),
            (1, 2.0, 3.0)
        );
        assert!((c.differ[0].relative - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(relative_difference(0.0, 0.0), 0.0);
    }
}
