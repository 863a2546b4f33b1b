//! Inputs named the way the command line names them: a pattern by file or generated kind, the construction that
//! selects C1's tension factors, a sampling plan by name or file.

use super::WorkflowError;
use crate::generate::default_pattern;
use crate::micro::reference::{reference_state, Construction, ReferenceOptions, ReferenceReport};
use crate::micro::SolverOptions;
use crate::pattern::Pattern;
use crate::rod::YarnMaterial;
use crate::sample::Plan;
use std::path::Path;

/// A loaded pattern, with the periods its file stored when they disagreed with its rest lengths.
pub struct LoadedPattern {
    /// The pattern (with the implied periods when the file's disagreed).
    pub pattern: Pattern,
    /// The file's periods, replaced by the implied ones (`None` when they agreed or the pattern is generated).
    pub replaced_periods: Option<[f64; 2]>,
}

impl LoadedPattern {
    /// The note to show when the file's periods were replaced.
    pub fn note(&self, arg: &str) -> Option<String> {
        self.replaced_periods.map(|stored| {
            format!(
                "note: {arg}: periods {stored:?} disagree with the rest lengths; using the implied periods {:?}",
                self.pattern.periods
            )
        })
    }
}

/// A pattern from a `.pyp` file, or a generated one by kind name (`plain`, `twill`, `satin`, `basket`,
/// `stockinette`). A file whose periods disagree with its rest lengths is used at the implied periods
/// ([`LoadedPattern::note`] says so).
pub fn load_pattern(arg: &str) -> Result<LoadedPattern, WorkflowError> {
    let path = Path::new(arg);
    if path.extension().is_some_and(|e| e == "pyp") || path.exists() {
        let (pattern, replaced_periods) = Pattern::load_pyp_at_implied_periods(path)?;
        Ok(LoadedPattern {
            pattern,
            replaced_periods,
        })
    } else {
        let pattern = default_pattern(arg)
            .map_err(|e| WorkflowError::Input(format!("{arg}: not a file, and {e}")))?;
        Ok(LoadedPattern {
            pattern,
            replaced_periods: None,
        })
    }
}

/// The construction of a pattern argument (it selects C1's tension factors): the given one, else knitted for the
/// generated stockinette and woven for the other generated kinds; a file needs it given.
pub fn construction_of(
    arg: &str,
    given: Option<Construction>,
) -> Result<Construction, WorkflowError> {
    match given {
        Some(c) => Ok(c),
        None if Path::new(arg).exists() => Err(WorkflowError::Input(format!(
            "{arg}: pass --construction knitted|woven (it selects the tension factors)"
        ))),
        None if arg == "stockinette" => Ok(Construction::Knitted),
        None => Ok(Construction::Woven),
    }
}

/// The reference state (C1) of the pattern argument `arg` as `hylc reference` computes it, with the default solver
/// options: the construction given, else [`construction_of`] the argument (woven when `equilibrate_only`, which skips
/// the stress-free state and the tension). Returns the state, C1's report and the construction used.
pub fn reference_of(
    arg: &str,
    pattern: &Pattern,
    yarn: &YarnMaterial,
    given: Option<Construction>,
    equilibrate_only: bool,
) -> Result<(Pattern, ReferenceReport, Construction), WorkflowError> {
    let construction = match given {
        None if equilibrate_only => Construction::Woven,
        given => construction_of(arg, given)?,
    };
    let options = ReferenceOptions {
        stress_free_and_tension: !equilibrate_only,
        ..Default::default()
    };
    let (q, report) = reference_state(
        pattern,
        yarn,
        construction,
        &SolverOptions::default(),
        &options,
    )
    .map_err(|source| WorkflowError::Reference {
        pattern: arg.to_string(),
        source,
    })?;
    Ok((q, report, construction))
}

/// The names of the built-in sampling plans.
pub const PLAN_NAMES: [&str; 4] = ["default", "reduced", "quick", "holdout"];

/// A plan by name (`default`, `reduced`, `quick`, `holdout`) or JSON file; an argument that is neither names the
/// plans there are.
pub fn load_plan(arg: &str) -> Result<Plan, WorkflowError> {
    match arg {
        "default" => Ok(Plan::default()),
        "reduced" => Ok(Plan::reduced()),
        "quick" => Ok(Plan::quick()),
        "holdout" => Ok(Plan::holdout()),
        _ if !Path::new(arg).exists() => Err(WorkflowError::Input(format!(
            "{arg}: not a plan ({}) and no such plan file",
            PLAN_NAMES.join(", ")
        ))),
        _ => Ok(Plan::load(Path::new(arg))?),
    }
}
