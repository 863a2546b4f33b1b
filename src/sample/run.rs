//! Running a sampling plan on one pattern (`docs/sampling.md`, section "Sampling plan
//! (C4)", "Running a plan").
//!
//! - Chains ([`Plan::chains`]) run in parallel (rayon); each chain is sequential, so every sample's result depends
//!   only on its chain and not on scheduling, shards or interruptions.
//! - Warm start: each step starts from the equilibrium of the step it continues (the nearest converged one up the
//!   chain), extrapolated with the secant predictor [`MicroProblem::predict`] when that step's own predecessor
//!   converged too ([`RunOptions::predictor`]); `cold` starts every sample from the reference state. A record's
//!   `time` includes the predictor's.
//! - Multi-start ([`RunOptions::starts`], [`super::starts`]; docs/sampling.md): `warm+cold` also solves every
//!   sample from the reference state and writes the lowest converged Ψ̄, listing every start.
//! - The sample file is JSON lines, append-only: one [`Record`] per sample, written as one `write` call of the
//!   full line and then synced to disk, so an interrupted run loses at most the sample in flight.
//! - Resume: ids already in the file are skipped (a truncated last line is cut off first). Skipped samples that a
//!   remaining sample continues from are re-solved (not re-written) to recover their states, so a resumed run
//!   writes bitwise the same records as an uninterrupted one (unless a solve hits a wall-time limit, whose
//!   outcome depends on the machine's load).
//! - Shards: shard k of n runs the chains with index ≡ k (mod n); [`merge`] concatenates shard files and removes
//!   duplicate ids.

use super::plan::{fnv1a64, Chain, Plan, Sample, Step};
use super::record::{Record, SampleStart, SampleStatus, StartKind};
use super::sensitivities::{add_sensitivities, fill_file, lacks_sensitivities};
use super::starts::{disagree, keep, kept_index, Solve, Starts, DEFAULT_DISAGREEMENT};
use super::SampleError;
use crate::contact::ccd::{net_crossings, Crossing};
use crate::micro::envelope::strain_derivatives;
use crate::micro::{CrossingGuard, MacroStrain, MicroProblem, MicroState, Predictor, Status};
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Options of [`run_plan`].
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Start every sample from the reference state.
    pub cold: bool,
    /// Run shard k of n (k < n).
    pub shard: Option<(usize, usize)>,
    /// Stop after writing this many samples.
    pub limit: Option<usize>,
    /// The predictor of warm starts.
    pub predictor: Predictor,
    /// The starts of every sample (docs/sampling.md; [`super::starts`]); not with `cold`.
    pub starts: Starts,
    /// `Starts::All`: the relative difference of the warm and the cold Ψ̄ above which the reversed chain is tried
    /// too ([`super::starts::DEFAULT_DISAGREEMENT`] when `None`).
    pub disagreement: Option<f64>,
    /// Store ∂Ψ̄/∂θ and dσ/dθ in every record that counts as converged ([`super::sensitivities`]), and add them
    /// to the finished records of the selected chains that lack them (re-solving their chains; the file is then
    /// rewritten).
    pub sensitivities: bool,
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunSummary {
    /// Samples in the selected chains.
    pub selected: usize,
    /// Of these, already in the file at the start.
    pub already_done: usize,
    /// Records written by this run.
    pub written: usize,
    /// Of these, converged.
    pub converged: usize,
    /// Solves redone (not written) to recover warm-start states of finished samples (or, with
    /// [`RunOptions::sensitivities`], their sensitivities).
    pub replayed: usize,
    /// Records written by this run with sensitivities ([`RunOptions::sensitivities`]).
    pub sensitivities: usize,
    /// Finished records of the selected chains that lacked sensitivities, and of these the ones given them (the
    /// others were re-solved to another result, or their sensitivities could not be computed).
    pub lacking_sensitivities: usize,
    /// Of `lacking_sensitivities`, the records given them.
    pub sensitivities_added: usize,
    /// Wall time (s).
    pub time: f64,
}

/// Hash of (pattern, yarn parameters, solver settings): FNV-1a 64 of the `.pyp` text, the yarn material and the
/// solver options in their frozen version-1 JSON form ([`crate::micro::SolverOptions::hash_text`], so that the hash
/// of sample files made before the settings' `version` key stays), as 16 hex digits.
pub fn problem_hash(problem: &MicroProblem) -> String {
    let text = format!(
        "{}\n{}\n{}",
        problem.pattern.to_pyp_string(),
        problem.material.hash_text(),
        problem.options.hash_text()
    );
    format!("{:016x}", fnv1a64(text.as_bytes()))
}

/// Parse `k/n` (0 ≤ k < n).
pub fn parse_shard(text: &str) -> Result<(usize, usize), SampleError> {
    let bad = || SampleError::Shard(text.to_string());
    let (k, n) = text.split_once('/').ok_or_else(bad)?;
    let k: usize = k.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    if n == 0 || k >= n {
        return Err(bad());
    }
    Ok((k, n))
}

/// Read a sample file: its records, in file order (a leading UTF-8 byte-order mark is skipped). A last line without its newline (an interrupted write) is
/// ignored, and with `repair` cut off the file; any other unreadable line is an error naming file and line.
pub fn read_samples(path: &Path, repair: bool) -> Result<Vec<Record>, SampleError> {
    let io = |action, source| SampleError::Io {
        path: path.to_path_buf(),
        action,
        source,
    };
    let text = match std::fs::read(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(vec![]),
        Err(e) => return Err(io("cannot read", e)),
    };
    let complete = text.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
    if complete < text.len() && repair {
        let f = OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(|e| io("cannot open to cut off the truncated last line", e))?;
        f.set_len(complete as u64)
            .and_then(|_| f.sync_data())
            .map_err(|e| io("cannot cut off the truncated last line", e))?;
    }
    // a UTF-8 byte-order mark is accepted, as in `.pyp` files
    let start = if text.starts_with(b"\xef\xbb\xbf") {
        3
    } else {
        0
    };
    let text = std::str::from_utf8(&text[start.min(complete)..complete]).map_err(|e| {
        SampleError::File {
            path: path.to_path_buf(),
            message: format!("not UTF-8 text: {e}"),
        }
    })?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let r: Record = serde_json::from_str(line).map_err(|e| SampleError::Line {
            path: path.to_path_buf(),
            line: i + 1,
            message: format!("not a sample record: {e}"),
        })?;
        out.push(r);
    }
    Ok(out)
}

/// A record as one line of JSON (with its newline).
fn record_line(record: &Record) -> String {
    record.to_line()
}

/// Run `plan` on `problem`, appending to the sample file `out` (created if missing; finished ids skipped).
///
/// # Example
///
/// A three-sample plan (the 1D range of s_x over [−0.05, 0.05], no other range or grid) on the generated plain
/// weave: every sample converges, and a second run finds the file finished and writes nothing.
///
/// ```
/// use hylc::generate::default_pattern;
/// use hylc::micro::{MicroProblem, SolverOptions};
/// use hylc::rod::YarnMaterial;
/// use hylc::sample::{read_samples, run_plan, Plan, RunOptions};
///
/// let pattern = default_pattern("plain")?;
/// let problem = MicroProblem::new(pattern, &YarnMaterial::default(), SolverOptions::default());
/// let mut plan = Plan {
///     count_1d: 0,
///     count_2d: 0,
///     pairs: vec![],
///     counts_1d: Some([3, 0, 0, 0, 0]),
///     ..Plan::default()
/// };
/// plan.ranges.s_x = [-0.05, 0.05];
/// let out = std::env::temp_dir().join(format!("hylc-doc-run-plan-{}.jsonl", std::process::id()));
/// let _ = std::fs::remove_file(&out);
///
/// let summary = run_plan(&problem, &plan, &out, &RunOptions::default())?;
/// assert_eq!((summary.written, summary.converged), (3, 3));
/// let records = read_samples(&out, false)?;
/// assert!(records.iter().all(|r| r.psi.is_some_and(|psi| psi > 0.0))); // Ψ̄ in J/m²
/// assert_eq!(run_plan(&problem, &plan, &out, &RunOptions::default())?.written, 0);
/// std::fs::remove_file(&out)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn run_plan(
    problem: &MicroProblem,
    plan: &Plan,
    out: &Path,
    opts: &RunOptions,
) -> Result<RunSummary, SampleError> {
    run_plan_with(problem, plan, out, opts, &|_, _| {})
}

/// [`run_plan`], calling `progress(written, to_write)` once before the first solve and after every record written
/// (from the worker threads).
pub fn run_plan_with(
    problem: &MicroProblem,
    plan: &Plan,
    out: &Path,
    opts: &RunOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<RunSummary, SampleError> {
    run_plan_until(problem, plan, out, opts, progress, &AtomicBool::new(false))
}

/// [`run_plan_with`] that stops early once `cancel` is set (e.g. from another thread on Ctrl-C): every chain ends
/// after the solve in flight, the records written so far stay in the file (a later run resumes from them), and the
/// summary counts what was written.
pub fn run_plan_until(
    problem: &MicroProblem,
    plan: &Plan,
    out: &Path,
    opts: &RunOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &AtomicBool,
) -> Result<RunSummary, SampleError> {
    let t0 = Instant::now();
    plan.validate()?;
    if opts.cold && opts.starts != Starts::Warm {
        return Err(SampleError::Starts(opts.starts.to_string()));
    }
    if let Some(d) = opts.disagreement.filter(|d| !(d.is_finite() && *d >= 0.0)) {
        return Err(SampleError::Disagreement(d));
    }
    let hash = problem_hash(problem);
    let existing = read_samples(out, true)?;
    if let Some(r) = existing.iter().find(|r| r.problem != hash) {
        return Err(SampleError::File {
            path: out.to_path_buf(),
            message: format!(
                "sample {} was solved for another problem (hash {}, this run {hash}): \
                 pattern, yarn parameters or solver settings differ (files made before the \
                 inertia-controlled steps became the default resume with --no-inertia)",
                r.id, r.problem
            ),
        });
    }
    let samples = plan.samples();
    let chains: Vec<_> = plan
        .chains()
        .into_iter()
        .enumerate()
        .filter(|(c, _)| opts.shard.is_none_or(|(k, n)| c % n == k))
        .map(|(_, c)| c)
        .collect();
    let fill = lacking_sensitivities(opts, &existing, &chains, &samples);
    let done: HashSet<String> = existing.into_iter().map(|r| r.id).collect();
    let selected: usize = chains.iter().map(|c| c.steps.len()).sum();
    let already_done = chains
        .iter()
        .flat_map(|c| &c.steps)
        .filter(|s| done.contains(&samples[s.sample].id))
        .count();
    let todo = selected - already_done;
    let todo = opts.limit.map_or(todo, |l| l.min(todo));

    let file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(out)
        .map_err(|e| SampleError::Io {
            path: out.to_path_buf(),
            action: "cannot open for appending",
            source: e,
        })?;
    let run = PlanRun {
        problem,
        samples: &samples,
        done: &done,
        fill: &fill,
        filled: Mutex::new(HashMap::new()),
        with_sensitivities: AtomicUsize::new(0),
        opts,
        hash: &hash,
        out,
        file: Mutex::new(file),
        todo,
        progress,
        written: AtomicUsize::new(0),
        slots: AtomicUsize::new(0),
        converged: AtomicUsize::new(0),
        replayed: AtomicUsize::new(0),
        stop: AtomicBool::new(false),
        cancel,
        failure: Mutex::new(None),
    };
    progress(0, todo);
    chains.par_iter().for_each(|chain| run.chain(&chain.steps));
    let PlanRun {
        file,
        failure,
        filled,
        written,
        converged,
        replayed,
        with_sensitivities,
        ..
    } = run;
    drop(file);
    if let Some(e) = failure.into_inner().ok().flatten() {
        return Err(e);
    }
    let filled = filled.into_inner().unwrap_or_default();
    let added = if filled.is_empty() {
        0
    } else {
        fill_file(out, &filled)?
    };
    Ok(RunSummary {
        selected,
        already_done,
        written: written.into_inner(),
        converged: converged.into_inner(),
        replayed: replayed.into_inner(),
        sensitivities: with_sensitivities.into_inner(),
        lacking_sensitivities: fill.len(),
        sensitivities_added: added,
        time: t0.elapsed().as_secs_f64(),
    })
}

/// `--sensitivities`: the finished records of the selected chains that lack them ([`lacks_sensitivities`]), by id;
/// none without the flag.
fn lacking_sensitivities(
    opts: &RunOptions,
    existing: &[Record],
    chains: &[Chain],
    samples: &[Sample],
) -> HashMap<String, Record> {
    if !opts.sensitivities {
        return HashMap::new();
    }
    let selected: HashSet<&str> = chains
        .iter()
        .flat_map(|c| &c.steps)
        .map(|s| samples[s.sample].id.as_str())
        .collect();
    existing
        .iter()
        .filter(|r| lacks_sensitivities(r) && selected.contains(r.id.as_str()))
        .map(|r| (r.id.clone(), r.clone()))
        .collect()
}

/// The shared state of one [`run_plan_with`]: the inputs, the sample file and the counters the chains update.
pub(super) struct PlanRun<'a> {
    problem: &'a MicroProblem,
    pub(super) samples: &'a [Sample],
    /// Ids already in the sample file.
    pub(super) done: &'a HashSet<String>,
    /// `--sensitivities`: the finished records that lack them, by id.
    fill: &'a HashMap<String, Record>,
    /// Of these, the ones re-solved to the same result, with their sensitivities.
    filled: Mutex<HashMap<String, Record>>,
    /// Records written with sensitivities.
    with_sensitivities: AtomicUsize,
    pub(super) opts: &'a RunOptions,
    hash: &'a str,
    out: &'a Path,
    file: Mutex<File>,
    /// Records this run will write (at most).
    todo: usize,
    progress: &'a (dyn Fn(usize, usize) + Sync),
    written: AtomicUsize,
    /// Records claimed against `opts.limit`.
    pub(super) slots: AtomicUsize,
    converged: AtomicUsize,
    pub(super) replayed: AtomicUsize,
    pub(super) stop: AtomicBool,
    /// Set from outside the run ([`run_plan_until`]) to stop it.
    cancel: &'a AtomicBool,
    failure: Mutex<Option<SampleError>>,
}

impl PlanRun<'_> {
    /// Whether the run must stop: a write failed, the limit is reached or the caller cancelled it.
    pub(super) fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed) || self.cancel.load(Ordering::Relaxed)
    }

    /// One chain, in order: its unfinished steps and (warm) every step they continue from, each started from the
    /// nearest converged step up the chain.
    fn chain(&self, steps: &[Step]) {
        if self.opts.starts == Starts::All {
            return self.chain_all(steps);
        }
        let mut need: Vec<bool> = steps
            .iter()
            .map(|s| {
                let id = &self.samples[s.sample].id;
                !self.done.contains(id) || self.fill.contains_key(id)
            })
            .collect();
        if !self.opts.cold {
            for i in (0..steps.len()).rev() {
                if need[i] {
                    if let Some(f) = steps[i].from {
                        need[f] = true;
                    }
                }
            }
        }
        let mut states: Vec<Option<MicroState>> = vec![None; steps.len()];
        for (i, step) in steps.iter().enumerate() {
            if !need[i] || self.stopped() {
                continue;
            }
            let sample = &self.samples[step.sample];
            let write = !self.done.contains(&sample.id);
            if write
                && self
                    .opts
                    .limit
                    .is_some_and(|l| self.slots.fetch_add(1, Ordering::SeqCst) >= l)
            {
                self.stop.store(true, Ordering::Relaxed);
                break;
            }
            let (record, state) = self.solve(steps, step, &states, sample, self.opts.cold);
            states[i] = state;
            // warm+cold: the cold start too, unless the chain's start was cold already (no converged step up
            // the chain); only the record changes, the chain continues from its warm equilibria
            let mut cold_state = None;
            let record = match self.opts.starts {
                Starts::Warm | Starts::All => record,
                Starts::WarmCold if record.start == SampleStart::Cold => {
                    keep(vec![(StartKind::Cold, record)])
                }
                Starts::WarmCold => {
                    let (cold, cs) = self.solve(steps, step, &states, sample, true);
                    cold_state = cs;
                    keep(vec![(StartKind::Warm, record), (StartKind::Cold, cold)])
                }
            };
            let kept = match (record.kept, cold_state.as_ref()) {
                (Some(StartKind::Cold), Some(cs)) => Some(cs),
                _ => states[i].as_ref(),
            };
            if !self.finish(record, kept, write) {
                break;
            }
        }
    }

    /// A sample's final record with its kept state: written when `write` (with sensitivities when asked), else
    /// counted as replayed and, when it is a finished record that lacks sensitivities, given them for the rewrite
    /// if it was re-solved to the same result ([`Record::same_result`]). False when the run must stop.
    pub(super) fn finish(
        &self,
        mut record: Record,
        kept: Option<&MicroState>,
        write: bool,
    ) -> bool {
        let stored = self.fill.get(&record.id).filter(|_| !write);
        let wanted = self.opts.sensitivities
            && record.converged_psi().is_some()
            && (write || stored.is_some_and(|s| s.same_result(&record)));
        if let Some(state) = kept.filter(|_| wanted) {
            // a failure leaves the record without sensitivities (a resume with the flag tries again)
            let _ = add_sensitivities(self.problem, &mut record, state);
        }
        if write {
            if record.dpsi_dtheta.is_some() {
                self.with_sensitivities.fetch_add(1, Ordering::Relaxed);
            }
            return self.write(&record);
        }
        self.replayed.fetch_add(1, Ordering::Relaxed);
        if record.dpsi_dtheta.is_some() {
            if let Ok(mut f) = self.filled.lock() {
                f.insert(record.id.clone(), record);
            }
        }
        true
    }

    /// Solve one step from its start (secant prediction, warm or cold); the record, and the state when converged.
    pub(super) fn solve(
        &self,
        steps: &[Step],
        step: &Step,
        states: &[Option<MicroState>],
        sample: &Sample,
        cold: bool,
    ) -> (Record, Option<MicroState>) {
        let problem = self.problem;
        let strain = MacroStrain(sample.z);
        // the nearest converged step up the chain, and its own converged predecessor
        let mut a = if cold { None } else { step.from };
        while let Some(k) = a {
            if states[k].is_some() {
                break;
            }
            a = steps[k].from;
        }
        let b = a
            .and_then(|k| steps[k].from)
            .filter(|&k| states[k].is_some());
        let mut how = SampleStart::Cold;
        let tp = Instant::now();
        let previous = a.and_then(|k| states[k].as_ref());
        let predicted = match self.opts.predictor {
            Predictor::Secant => match (b.and_then(|k| states[k].as_ref()), previous) {
                (Some(sb), Some(sa)) => problem.predict(sb, sa, &strain).ok().flatten(),
                _ => None,
            },
            Predictor::None => None,
        };
        // the candidates: the predicted start, then the previous equilibrium itself; with the crossing guard each
        // start's path from the previous equilibrium is checked (`MicroProblem::start_crossings`): `reject` takes
        // the first that crosses no yarns (else the cold start), `count` the first, its crossings counted
        let mut candidates: Vec<(&MicroState, SampleStart)> = Vec::new();
        if let Some(p) = predicted.as_ref() {
            candidates.push((p, SampleStart::Predicted));
        }
        candidates.extend(previous.map(|s| (s, SampleStart::Warm)));
        let mut start = None;
        let mut start_crossings = Vec::new();
        if let Some(origin) = previous {
            for (candidate, kind) in candidates {
                let crossed = self.start_crossings(origin, candidate, &strain);
                if self.rejects(&crossed) {
                    continue;
                }
                (start, how, start_crossings) = (Some(candidate), kind, crossed);
                break;
            }
        }
        // the record's time includes the prediction and the start checks
        let predict_time = tp.elapsed().as_secs_f64();
        self.solve_from(sample, start, how, predict_time, start_crossings)
    }

    /// Whether a start whose path crossed `crossed` is refused (`--crossings reject` and any crossing).
    pub(super) fn rejects(&self, crossed: &[Crossing]) -> bool {
        self.problem.options.crossings == CrossingGuard::Reject && !crossed.is_empty()
    }

    /// The yarn crossings on the way from the equilibrium `origin` to `start` and on to `strain`
    /// ([`crate::micro::MicroProblem::start_crossings`]); none when the guard is off. A failed check counts as a
    /// crossing: the start is not trusted.
    pub(super) fn start_crossings(
        &self,
        origin: &MicroState,
        start: &MicroState,
        strain: &MacroStrain,
    ) -> Vec<Crossing> {
        if self.problem.options.crossings == CrossingGuard::Off {
            return Vec::new();
        }
        self.problem
            .start_crossings(origin, start, strain)
            .unwrap_or_else(|_| vec![Crossing::untrusted()])
    }

    /// Solve one sample from `start` (the reference state when `None`), `how` naming the start; the record, and
    /// the state when converged. `predict_time` (s, the predictor's and the start checks') is added to the record's
    /// time; `start_crossings` are the
    /// crossings of the start's own path ([`PlanRun::start_crossings`]), counted with the Newton path's.
    pub(super) fn solve_from(
        &self,
        sample: &Sample,
        start: Option<&MicroState>,
        how: SampleStart,
        predict_time: f64,
        start_crossings: Vec<Crossing>,
    ) -> (Record, Option<MicroState>) {
        let problem = self.problem;
        let strain = MacroStrain(sample.z);
        let t = Instant::now();
        let mut record = Record {
            id: sample.id.clone(),
            index: sample.index,
            z: sample.z,
            psi: None,
            stress: None,
            status: SampleStatus::Error,
            error: None,
            steps: 0,
            gradient_norm: None,
            time: 0.0,
            start: how,
            problem: self.hash.to_string(),
            starts: vec![],
            kept: None,
            crossings: None,
            dpsi_dtheta: None,
            dstress_dtheta: None,
        };
        match problem.solve(&strain, start) {
            Ok(sol) => {
                let ok = sol.status == Status::Converged;
                if ok {
                    record.stress = strain_derivatives(problem, &sol.state).ok();
                }
                record.psi = sol.psi().ok();
                record.status = sol.status.into();
                record.steps = sol.steps;
                record.gradient_norm = Some(sol.gradient_norm).filter(|g| g.is_finite());
                record.time = sol.time + predict_time;
                let mut path = start_crossings;
                path.extend_from_slice(&sol.crossings);
                let net = net_crossings(&path).len();
                record.crossings = (problem.options.crossings != CrossingGuard::Off).then_some(net);
                // a chain does not continue from another fabric's equilibrium
                (record, (ok && net == 0).then_some(sol.state))
            }
            Err(e) => {
                record.error = Some(e.to_string());
                record.time = t.elapsed().as_secs_f64() + predict_time;
                (record, None)
            }
        }
    }

    /// Append a record as a single write of the full line, then sync it to disk; count it and report progress.
    /// False (and the run stops) when the file cannot be written.
    pub(super) fn write(&self, record: &Record) -> bool {
        let line = record_line(record);
        let result = match self.file.lock() {
            Ok(mut f) => f
                .write_all(line.as_bytes())
                .and_then(|_| f.sync_data())
                .map_err(|e| SampleError::Io {
                    path: self.out.to_path_buf(),
                    action: "cannot append to the sample file",
                    source: e,
                }),
            Err(_) => Err(SampleError::File {
                path: self.out.to_path_buf(),
                message: "sample file lock poisoned".into(),
            }),
        };
        if let Err(e) = result {
            if let Ok(mut f) = self.failure.lock() {
                f.get_or_insert(e);
            }
            self.stop.store(true, Ordering::Relaxed);
            return false;
        }
        let n = self.written.fetch_add(1, Ordering::Relaxed) + 1;
        if record.converged_psi().is_some() {
            self.converged.fetch_add(1, Ordering::Relaxed);
        }
        (self.progress)(n, self.todo);
        true
    }
}

impl PlanRun<'_> {
    /// `--starts all` on one chain: the forward pass (warm and cold starts, the chain continuing from its warm
    /// equilibria), then the reversed pass (a sample whose starts [`disagree`] is also started from the kept
    /// equilibrium of every step continuing it, latest first, so a lower branch found late propagates back up),
    /// then the chain's unfinished records in order.
    pub(super) fn chain_all(&self, steps: &[Step]) {
        let id = |i: usize| &self.samples[steps[i].sample].id;
        if (0..steps.len()).all(|i| self.done.contains(id(i)) && !self.fill.contains_key(id(i))) {
            return;
        }
        let rel = self.opts.disagreement.unwrap_or(DEFAULT_DISAGREEMENT);
        let mut states: Vec<Option<MicroState>> = vec![None; steps.len()];
        let mut solves: Vec<Vec<Solve>> = Vec::with_capacity(steps.len());
        for (i, step) in steps.iter().enumerate() {
            if self.stopped() {
                return;
            }
            let sample = &self.samples[step.sample];
            let (warm, ws) = self.solve(steps, step, &states, sample, false);
            states[i] = ws.clone();
            solves.push(if warm.start == SampleStart::Cold {
                vec![(StartKind::Cold, warm, ws)]
            } else {
                let (cold, cs) = self.solve(steps, step, &states, sample, true);
                vec![(StartKind::Warm, warm, ws), (StartKind::Cold, cold, cs)]
            });
        }
        let mut kept: Vec<Option<MicroState>> = vec![None; steps.len()];
        for i in (0..steps.len()).rev() {
            if disagree(&solves[i], rel) {
                let sample = &self.samples[steps[i].sample];
                for j in (i + 1..steps.len()).filter(|&j| steps[j].from == Some(i)) {
                    if let Some(s) = kept[j].as_ref() {
                        let strain = MacroStrain(sample.z);
                        let crossed = self.start_crossings(s, s, &strain);
                        if self.rejects(&crossed) {
                            continue;
                        }
                        let (r, st) =
                            self.solve_from(sample, Some(s), SampleStart::Reverse, 0.0, crossed);
                        solves[i].push((StartKind::Reverse, r, st));
                    }
                }
            }
            let k = kept_index(solves[i].iter().map(|s| &s.1));
            kept[i] = solves[i][k].2.clone();
        }
        for (i, v) in solves.into_iter().enumerate() {
            let write = !self.done.contains(id(i));
            if write
                && self
                    .opts
                    .limit
                    .is_some_and(|l| self.slots.fetch_add(1, Ordering::SeqCst) >= l)
            {
                self.stop.store(true, Ordering::Relaxed);
                return;
            }
            let record = keep(v.into_iter().map(|(k, r, _)| (k, r)).collect());
            if !self.finish(record, kept[i].as_ref(), write) {
                return;
            }
        }
    }
}

/// Merge sample files (e.g. shards) into `out`: all records, ordered by plan index then id; a repeated id with the
/// same result ([`Record::same_result`]) is dropped (the copy with sensitivities kept where only one has them),
/// with another result it is an error naming the file and id.
/// Returns (records written, duplicates dropped). `out` is written to a temporary file and renamed.
pub fn merge(out: &Path, inputs: &[&Path]) -> Result<(usize, usize), SampleError> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut records: Vec<Record> = Vec::new();
    let mut duplicates = 0;
    for path in inputs {
        for r in read_samples(path, false)? {
            match seen.get(&r.id) {
                None => {
                    seen.insert(r.id.clone(), records.len());
                    records.push(r);
                }
                Some(&k) if records[k].same_result(&r) => {
                    // the copy with sensitivities, if only one has them
                    if records[k].dpsi_dtheta.is_none() && r.dpsi_dtheta.is_some() {
                        records[k] = r;
                    }
                    duplicates += 1
                }
                Some(&k) => {
                    return Err(SampleError::File {
                        path: path.to_path_buf(),
                        message: format!(
                            "sample {} has another result than in an earlier input (Ψ̄ {:?} and {:?}, status {:?} and {:?})",
                            r.id, records[k].psi, r.psi, records[k].status, r.status
                        ),
                    })
                }
            }
        }
    }
    records.sort_by(|a, b| a.index.cmp(&b.index).then_with(|| a.id.cmp(&b.id)));
    let text: String = records.iter().map(record_line).collect();
    let tmp = out.with_extension("merge-tmp");
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, out))
        .map_err(|e| SampleError::Io {
            path: out.to_path_buf(),
            action: "cannot write",
            source: e,
        })?;
    Ok((records.len(), duplicates))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_parsing() {
        assert_eq!(parse_shard("0/2").unwrap(), (0, 2));
        assert_eq!(parse_shard(" 3 / 4 ").unwrap(), (3, 4));
        for bad in ["2/2", "1", "a/b", "0/0", "-1/2"] {
            let e = parse_shard(bad).unwrap_err().to_string();
            assert_eq!(
                e,
                format!("--shard: expected k/n with 0 ≤ k < n, got {bad:?}")
            );
        }
    }

    #[test]
    fn records_keep_their_text_form_and_old_lines_load() {
        // a line as earlier versions wrote it (status and start as plain strings)
        let old = r#"{"id":"884175aca732b4af-18","index":18,"z":[0.1,0.0,0.0,0.0,0.0],"psi":null,"stress":null,"status":"MaxSteps","error":null,"steps":2000,"gradient_norm":0.001,"time":0.5,"start":"predicted","problem":"bb8024c6f202cb08"}"#;
        let r: Record = serde_json::from_str(old).unwrap();
        assert_eq!(r.status, SampleStatus::MaxSteps);
        assert_eq!(r.start, SampleStart::Predicted);
        assert_eq!(serde_json::to_string(&r).unwrap(), old);
        let bad = old.replace("\"MaxSteps\"", "\"Maybe\"");
        assert!(serde_json::from_str::<Record>(&bad).is_err());
        for s in [
            Status::Converged,
            Status::Stalled,
            Status::MaxSteps,
            Status::TimeLimit,
        ] {
            let text = serde_json::to_string(&SampleStatus::from(s)).unwrap();
            assert_eq!(text, format!("\"{s}\""));
        }
    }

    #[test]
    fn truncated_last_line_is_cut_off() {
        let dir = std::env::temp_dir().join(format!("hylc-sample-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.jsonl");
        let r = Record {
            id: "x-0".into(),
            index: 0,
            z: [0.1, 0.0, 0.0, 0.0, 0.0],
            psi: Some(1.0 / 3.0),
            stress: Some([Some(0.5), None, Some(0.0), Some(-1e-300), None]),
            status: SampleStatus::Converged,
            error: None,
            steps: 3,
            gradient_norm: Some(1e-12),
            time: 0.01,
            start: SampleStart::Cold,
            problem: "0".into(),
            starts: vec![],
            kept: None,
            crossings: None,
            dpsi_dtheta: None,
            dstress_dtheta: None,
        };
        let line = serde_json::to_string(&r).unwrap();
        std::fs::write(&path, format!("{line}\n{}", &line[..20])).unwrap();
        assert_eq!(read_samples(&path, false).unwrap(), vec![r.clone()]);
        assert_eq!(read_samples(&path, true).unwrap(), vec![r.clone()]);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), format!("{line}\n"));
        std::fs::write(&path, format!("{}\n{line}\n", &line[..20])).unwrap();
        let e = read_samples(&path, false).unwrap_err().to_string();
        assert!(e.contains("s.jsonl:1: not a sample record"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_byte_order_mark_is_skipped_and_only_converged_records_count() {
        let dir = std::env::temp_dir().join(format!("hylc-sample-bom-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.jsonl");
        let mut r = Record {
            id: "x-0".into(),
            index: 0,
            z: [0.1, 0.0, 0.0, 0.0, 0.0],
            psi: Some(0.25),
            stress: None,
            status: SampleStatus::Converged,
            error: None,
            steps: 3,
            gradient_norm: Some(1e-12),
            time: 0.01,
            start: SampleStart::Cold,
            problem: "0".into(),
            starts: vec![],
            kept: None,
            crossings: None,
            dpsi_dtheta: None,
            dstress_dtheta: None,
        };
        std::fs::write(&path, format!("\u{feff}{}", record_line(&r))).unwrap();
        assert_eq!(read_samples(&path, true).unwrap(), vec![r.clone()]);
        // a BOM alone (no complete line) is an empty file
        std::fs::write(&path, "\u{feff}").unwrap();
        assert_eq!(read_samples(&path, false).unwrap(), vec![]);
        assert_eq!(r.converged_psi(), Some(0.25));
        r.status = SampleStatus::MaxSteps;
        assert_eq!(r.converged_psi(), None);
        std::fs::remove_dir_all(&dir).ok();
    }
}
