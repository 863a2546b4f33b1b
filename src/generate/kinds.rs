//! Patterns by kind name: the embedded defaults and the command line's `hylc generate KIND` settings (also the
//! Python module's `generate`).

use super::{bad, stockinette, weave, GenerateError, KnitParams, WeaveParams};
use crate::pattern::Pattern;

/// The names of the embedded default patterns accepted by [`default_pattern`].
pub const DEFAULT_KINDS: [&str; 5] = ["plain", "twill", "satin", "basket", "stockinette"];

/// The embedded default pattern of a kind: `plain` ([`WeaveParams::plain`]), `twill` (2/2 twill,
/// [`WeaveParams::twill`]`(4)`), `satin` (5-harness satin, [`WeaveParams::satin`]`(5, 2)`), `basket`
/// ([`WeaveParams::basket`]`(2)`) or `stockinette` ([`KnitParams::stockinette`]).
pub fn default_pattern(kind: &str) -> Result<Pattern, GenerateError> {
    match kind {
        "plain" => weave(&WeaveParams::plain()),
        "twill" => weave(&WeaveParams::twill(4)),
        "satin" => weave(&WeaveParams::satin(5, 2)),
        "basket" => weave(&WeaveParams::basket(2)),
        "stockinette" => stockinette(&KnitParams::stockinette()),
        _ => bad(
            "kind",
            format!(
                "unknown pattern kind {kind:?} (expected one of {})",
                DEFAULT_KINDS.join(", ")
            ),
        ),
    }
}

/// A pattern of a kind with the command line's settings (`hylc generate`, the Python module's `generate`): `n` the
/// twill repeat (default 4), satin repeat (default 5) or basket group size (default 2), `step` the satin move
/// (default 2), `vertices_per_radius` the vertices per yarn radius of arclength. `n` and `step` given for a kind
/// they do not apply to are errors.
pub fn generate_kind(
    kind: &str,
    n: Option<usize>,
    step: Option<usize>,
    vertices_per_radius: f64,
) -> Result<Pattern, GenerateError> {
    if !DEFAULT_KINDS.contains(&kind) {
        return default_pattern(kind);
    }
    if n.is_some() && !matches!(kind, "twill" | "satin" | "basket") {
        return bad("n", format!("does not apply to {kind}"));
    }
    if step.is_some() && kind != "satin" {
        return bad("step", format!("applies to satin only, not {kind}"));
    }
    let weave_params = match kind {
        "plain" => WeaveParams::plain(),
        "twill" => WeaveParams::twill(n.unwrap_or(4)),
        "satin" => WeaveParams::satin(n.unwrap_or(5), step.unwrap_or(2)),
        "basket" => WeaveParams::basket(n.unwrap_or(2)),
        _ => {
            return stockinette(&KnitParams {
                vertices_per_radius,
                ..KnitParams::stockinette()
            })
        }
    };
    weave(&WeaveParams {
        vertices_per_radius,
        ..weave_params
    })
}
