//! Patterns and strains as the micro commands take them.

use anyhow::anyhow;
use hylc::micro::MacroStrain;
use hylc::pattern::Pattern;
use hylc::workflow::inputs::load_pattern;

/// A pattern by file or generated kind (`hylc::workflow::inputs::load_pattern`), with its note on stderr when
/// the file's periods were replaced by the implied ones.
pub fn load_pattern_noted(arg: &str) -> anyhow::Result<Pattern> {
    let loaded = load_pattern(arg)?;
    if let Some(note) = loaded.note(arg) {
        eprintln!("{note}");
    }
    Ok(loaded.pattern)
}

/// Parse "sx,sa,sy[,II00,II11]".
pub fn parse_strain(text: &str) -> anyhow::Result<MacroStrain> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| anyhow!("--z: cannot parse {s:?} in {text:?}"))
        })
        .collect::<Result<_, _>>()?;
    match v.len() {
        3 => Ok(MacroStrain::in_plane(v[0], v[1], v[2])),
        5 => Ok(MacroStrain::new(v[0], v[1], v[2], v[3], v[4])),
        k => Err(anyhow!(
            "--z: expected 3 (s_x,s_a,s_y) or 5 (s_x,s_a,s_y,II00,II11) numbers, got {k} in {text:?}"
        )),
    }
}
