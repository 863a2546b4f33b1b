//! Reading and writing the original material JSON (`docs/material.md`, "Material JSON").
//!
//! Numbers round-trip exactly (serde_json with `float_roundtrip` parses correctly rounded and writes the shortest
//! representation that reads back to the same bits). Unknown top-level keys (e.g. "meta", "strain shift") are kept
//! and written back; unknown keys inside "coeffs" and its terms are ignored. "strain shift", when present, must be
//! the original's [1, 0, 1, 0, 0]: this library's z already holds s = λ − 1 (see `../shared/oracles/README.md`).
//!
//! Admissible values (checked at load, so that ψ, ∇ψ, ∇²ψ stay finite over the admissible strains of
//! [`Material::eval_checked`]): density in [0, [`MAX_DENSITY`]]; strain scales in [[`MIN_STRAIN_SCALE`],
//! [`MAX_STRAIN_SCALE`]]; knots within ±[`MAX_KNOT`], spaced at least [`MIN_KNOT_SPACING`]; the constant, values
//! and slopes within ±[`MAX_COEFFICIENT`]. A leading UTF-8 byte-order mark is skipped.
//!
//! Every problem is reported as one line `FILE: FIELD: what is wrong`, never a panic. JSON has no NaN or infinity;
//! the tokens `NaN`, `Infinity`, `-Infinity` and numbers that overflow f64 (which some writers emit) are recognised
//! and reported at the field where they stand.

use super::{Hermite1D, Hermite2D, Material, StrainComponent, Term1D, Term2D};
use serde_json::{Map, Value};
use std::path::Path;

/// A material file problem: the file, the field (a JSON path such as `coeffs.1D[2].t[4]`, or a line and column
/// for syntax errors) and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {field}: {message}")]
pub struct MaterialError {
    /// the material file
    pub file: String,
    /// the field (a JSON path such as `coeffs.1D[2].t[4]`, or a line and column)
    pub field: String,
    /// what is wrong
    pub message: String,
}

/// Smallest admissible strain scale σ_k (every k; in-plane dimensionless, bending 1/m). The originals use 0.6–230;
/// a sub-normal σ (5e-324) made z/σ infinite and ψ(0) NaN.
pub const MIN_STRAIN_SCALE: f64 = 1e-6;
/// Largest admissible strain scale σ_k: 1e6 (in 1/m for bending: the curvature of a 1 µm radius).
pub const MAX_STRAIN_SCALE: f64 = 1e6;
/// Largest admissible |knot| (normalised strain z/σ): the range [`super::MAX_NORMALISED_STRAIN`] of
/// [`Material::eval_checked`] (the originals: |t| ≤ 0.95).
pub const MAX_KNOT: f64 = super::MAX_NORMALISED_STRAIN;
/// Smallest admissible knot spacing (normalised strain): the Hessian scales like 1/h², so knots scaled by 1e-300
/// overflowed it. The originals' spacings are 0.0375 and more.
pub const MIN_KNOT_SPACING: f64 = 1e-6;
/// Largest admissible |value| of the constant, the spline values and slopes (J/m², per unit normalised strain):
/// the originals reach 455. With [`MAX_KNOT`], [`MIN_KNOT_SPACING`] and the strain scale range this keeps ψ, ∇ψ
/// and ∇²ψ finite over the admissible strains (slopes of ±1e308 gave NaN at z = 0).
pub const MAX_COEFFICIENT: f64 = 1e12;
/// Largest admissible areal density ρ_A (kg/m²): the originals are 0.31–0.50; a hundred-fold heavier cloth than
/// any carpet is already 1e3 times the originals.
pub const MAX_DENSITY: f64 = 1e3;

type Res<T> = Result<T, (String, String)>;

fn err<T>(field: &str, message: impl Into<String>) -> Res<T> {
    Err((field.to_string(), message.into()))
}

/// Quote bare non-finite tokens (NaN, Infinity, -Infinity, numbers overflowing f64) so the document parses and the
/// typed reader can name the field that holds them.
fn quote_non_finite(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let mut last = 0;
    let mut in_string = false;
    while i < b.len() {
        let ch = b[i];
        if in_string {
            if ch == b'\\' {
                i += 2;
                continue;
            }
            if ch == b'"' {
                in_string = false;
            }
            i += 1;
            continue;
        }
        if ch == b'"' {
            in_string = true;
            i += 1;
            continue;
        }
        if ch == b'-' || ch.is_ascii_alphanumeric() || ch == b'.' {
            let start = i;
            while i < b.len()
                && (b[i].is_ascii_alphanumeric() || matches!(b[i], b'-' | b'+' | b'.'))
            {
                i += 1;
            }
            let tok = &text[start..i];
            let non_finite = matches!(
                tok,
                "NaN" | "-NaN" | "Infinity" | "-Infinity" | "inf" | "-inf" | "nan"
            ) || (tok.starts_with(|c: char| c == '-' || c.is_ascii_digit())
                && tok.parse::<f64>().map(|v| v.is_infinite()).unwrap_or(false));
            if non_finite {
                out.push_str(&text[last..start]);
                out.push('"');
                out.push_str(tok);
                out.push('"');
                last = i;
            }
            continue;
        }
        i += 1;
    }
    out.push_str(&text[last..]);
    out
}

fn get<'a>(obj: &'a Map<String, Value>, key: &str, path: &str) -> Res<&'a Value> {
    obj.get(key)
        .ok_or_else(|| (path.to_string(), format!("missing key \"{key}\"")))
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

fn number(v: &Value, path: &str) -> Res<f64> {
    match v {
        Value::Number(n) => match n.as_f64() {
            Some(x) if x.is_finite() => Ok(x),
            _ => err(path, format!("number {n} is not a finite f64")),
        },
        Value::String(s) => err(path, format!("expected a finite number, found {s}")),
        other => err(path, format!("expected a number, found {}", kind(other))),
    }
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

fn array<'a>(v: &'a Value, path: &str) -> Res<&'a Vec<Value>> {
    v.as_array().ok_or_else(|| {
        (
            path.to_string(),
            format!("expected an array, found {}", kind(v)),
        )
    })
}

fn object<'a>(v: &'a Value, path: &str) -> Res<&'a Map<String, Value>> {
    v.as_object().ok_or_else(|| {
        (
            path.to_string(),
            format!("expected an object, found {}", kind(v)),
        )
    })
}

fn numbers(obj: &Map<String, Value>, key: &str, path: &str) -> Res<Vec<f64>> {
    let p = join(path, key);
    array(get(obj, key, path)?, &p)?
        .iter()
        .enumerate()
        .map(|(i, x)| number(x, &format!("{p}[{i}]")))
        .collect()
}

/// A strain by the file's index k = 0…4 (s_x, s_a, s_y, x-bending Π₀₀, y-bending Π₁₁).
fn index(obj: &Map<String, Value>, key: &str, path: &str) -> Res<StrainComponent> {
    let p = join(path, key);
    let x = number(get(obj, key, path)?, &p)?;
    match StrainComponent::from_index(x as usize) {
        Some(c) if x.fract() == 0.0 && x >= 0.0 => Ok(c),
        _ => err(
            &p,
            format!(
                "unknown strain index {x} (expected 0..4: s_x, s_a, s_y, x-bending, y-bending)"
            ),
        ),
    }
}

fn knots(obj: &Map<String, Value>, key: &str, path: &str) -> Res<Vec<f64>> {
    let t = numbers(obj, key, path)?;
    let p = join(path, key);
    if t.len() < 2 {
        return err(&p, format!("needs at least 2 knots, has {}", t.len()));
    }
    for i in 1..t.len() {
        if t[i] <= t[i - 1] {
            return err(
                &p,
                format!(
                    "knots not strictly increasing at index {i} ({} then {})",
                    t[i - 1],
                    t[i]
                ),
            );
        }
        if t[i] - t[i - 1] < MIN_KNOT_SPACING {
            return err(
                &format!("{p}[{i}]"),
                format!(
                    "knot spacing {:e} (from {:e} to {:e}) is below the minimum {MIN_KNOT_SPACING:e}",
                    t[i] - t[i - 1],
                    t[i - 1],
                    t[i]
                ),
            );
        }
    }
    if let Some(i) = t.iter().position(|x| x.abs() > MAX_KNOT) {
        return err(
            &format!("{p}[{i}]"),
            format!("knot {:e} is outside [-{MAX_KNOT:e}, {MAX_KNOT:e}]", t[i]),
        );
    }
    Ok(t)
}

/// A coefficient checked against [`MAX_COEFFICIENT`].
fn coefficient(x: f64, path: &str) -> Res<f64> {
    if x.abs() > MAX_COEFFICIENT {
        return err(
            path,
            format!("|{x:e}| is above the largest admissible coefficient {MAX_COEFFICIENT:e}"),
        );
    }
    Ok(x)
}

fn sized(obj: &Map<String, Value>, key: &str, path: &str, n: usize, what: &str) -> Res<Vec<f64>> {
    let v = numbers(obj, key, path)?;
    let p = join(path, key);
    if v.len() != n {
        return err(
            &p,
            format!("wrong array length {} (expected {n}, {what})", v.len()),
        );
    }
    for (i, &x) in v.iter().enumerate() {
        coefficient(x, &format!("{p}[{i}]"))?;
    }
    Ok(v)
}

fn parse_value(root: &Value) -> Res<Material> {
    let top = object(root, "(top level)")?;
    let density = read_density(top)?;
    let scale = read_strain_scale(top)?;
    check_strain_shift(top)?;
    let coeffs = object(get(top, "coeffs", "(top level)")?, "coeffs")?;
    let constant = coefficient(
        number(get(coeffs, "const", "coeffs")?, "coeffs.const")?,
        "coeffs.const",
    )?;
    let terms1d = read_terms1d(coeffs)?;
    let terms2d = read_terms2d(coeffs)?;
    let extra = top
        .iter()
        .filter(|(k, _)| !matches!(k.as_str(), "density" | "strain scale" | "coeffs"))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    Ok(Material {
        density,
        strain_scale: scale,
        constant,
        terms1d,
        terms2d,
        extra,
    })
}

/// `density` (kg/m²): ≥ 0 and at most [`MAX_DENSITY`].
fn read_density(top: &Map<String, Value>) -> Res<f64> {
    let density = number(get(top, "density", "(top level)")?, "density")?;
    if density < 0.0 {
        return err("density", format!("must be ≥ 0, is {density}"));
    }
    if density > MAX_DENSITY {
        return err(
            "density",
            format!("{density:e} kg/m² is above the largest admissible {MAX_DENSITY:e} kg/m²"),
        );
    }
    Ok(density)
}

/// `strain scale`: five positive numbers within [`MIN_STRAIN_SCALE`, `MAX_STRAIN_SCALE`].
fn read_strain_scale(top: &Map<String, Value>) -> Res<[f64; 5]> {
    let scale = numbers(top, "strain scale", "")?;
    if scale.len() != 5 {
        return err(
            "strain scale",
            format!("wrong array length {} (expected 5)", scale.len()),
        );
    }
    for (i, s) in scale.iter().enumerate() {
        if *s <= 0.0 {
            return err(
                &format!("strain scale[{i}]"),
                format!("must be > 0, is {s}"),
            );
        }
        if !(MIN_STRAIN_SCALE..=MAX_STRAIN_SCALE).contains(s) {
            return err(
                &format!("strain scale[{i}]"),
                format!("{s:e} is outside [{MIN_STRAIN_SCALE:e}, {MAX_STRAIN_SCALE:e}]"),
            );
        }
    }
    Ok([scale[0], scale[1], scale[2], scale[3], scale[4]])
}

/// `strain shift`, if given: only [1, 0, 1, 0, 0] (z holds s = λ − 1).
fn check_strain_shift(top: &Map<String, Value>) -> Res<()> {
    if let Some(shift) = top.get("strain shift") {
        let v: Vec<f64> = array(shift, "strain shift")?
            .iter()
            .enumerate()
            .map(|(i, x)| number(x, &format!("strain shift[{i}]")))
            .collect::<Res<_>>()?;
        if v != [1.0, 0.0, 1.0, 0.0, 0.0] {
            return err(
                "strain shift",
                format!(
                    "{v:?} is not supported: z holds s = λ − 1, only [1, 0, 1, 0, 0] is accepted"
                ),
            );
        }
    }
    Ok(())
}

/// `coeffs.1D`: one term per strain component, a knot vector with values and slopes per knot.
fn read_terms1d(coeffs: &Map<String, Value>) -> Res<Vec<Term1D>> {
    let mut terms1d: Vec<Term1D> = Vec::new();
    for (i, e) in array(get(coeffs, "1D", "coeffs")?, "coeffs.1D")?
        .iter()
        .enumerate()
    {
        let path = format!("coeffs.1D[{i}]");
        let o = object(e, &path)?;
        let strain = index(o, "k", &path)?;
        let t = knots(o, "t", &path)?;
        let n = t.len();
        let p = sized(o, "p", &path, n, "one per knot")?;
        let m = sized(o, "m", &path, n, "one per knot")?;
        if terms1d.iter().any(|x| x.strain == strain) {
            return err(
                &format!("{path}.k"),
                format!("duplicate 1D term for strain index {}", strain.index()),
            );
        }
        terms1d.push(Term1D {
            strain,
            spline: Hermite1D::new(t, p, m),
        });
    }
    Ok(terms1d)
}

/// `coeffs.2D`: one term per pair (k0 in-plane, k1 > k0), a knot grid with values and derivatives per node.
fn read_terms2d(coeffs: &Map<String, Value>) -> Res<Vec<Term2D>> {
    let mut terms2d: Vec<Term2D> = Vec::new();
    for (i, e) in array(get(coeffs, "2D", "coeffs")?, "coeffs.2D")?
        .iter()
        .enumerate()
    {
        let path = format!("coeffs.2D[{i}]");
        let o = object(e, &path)?;
        let strains = [index(o, "k0", &path)?, index(o, "k1", &path)?];
        let [k0, k1] = strains.map(StrainComponent::index);
        if k0 > 2 || k1 <= k0 {
            return err(
                &format!("{path}.k1"),
                format!("unsupported pair ({k0}, {k1}): k0 must be in-plane (0..2) and k1 > k0"),
            );
        }
        if terms2d.iter().any(|x| x.strains == strains) {
            return err(
                &format!("{path}.k1"),
                format!("duplicate 2D term ({k0}, {k1})"),
            );
        }
        let tu = knots(o, "tu", &path)?;
        let tv = knots(o, "tv", &path)?;
        let n = tu.len() * tv.len();
        let what = format!("|tu|·|tv| = {}·{}", tu.len(), tv.len());
        let p = sized(o, "p", &path, n, &what)?;
        let mu = sized(o, "mu", &path, n, &what)?;
        let mv = sized(o, "mv", &path, n, &what)?;
        let muv = sized(o, "muv", &path, n, &what)?;
        terms2d.push(Term2D {
            strains,
            spline: Hermite2D::new(tu, tv, p, mu, mv, muv),
        });
    }
    Ok(terms2d)
}

impl Material {
    /// Parse a material from JSON text; `name` is used in error messages.
    pub fn from_json_str(text: &str, name: &str) -> Result<Material, MaterialError> {
        let fail = |field: String, message: String| MaterialError {
            file: name.to_string(),
            field,
            message,
        };
        // a leading UTF-8 byte-order mark (some editors write one) is not part of the JSON text
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let quoted = quote_non_finite(text);
        let root: Value = serde_json::from_str(&quoted).map_err(|e| {
            fail(
                format!("line {} column {}", e.line(), e.column()),
                format!("invalid JSON ({e})")
                    .replace(&format!(" at line {} column {}", e.line(), e.column()), ""),
            )
        })?;
        parse_value(&root).map_err(|(f, m)| fail(f, m))
    }

    /// Read a material file.
    pub fn load(path: &Path) -> Result<Material, MaterialError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| MaterialError {
            file: name.clone(),
            field: "(file)".into(),
            message: format!("cannot read: {e}"),
        })?;
        Material::from_json_str(&text, &name)
    }

    /// The material as a JSON value in the original layout (density, strain scale, extra keys, coeffs).
    pub fn to_json_value(&self) -> Value {
        let arr = |v: &[f64]| Value::Array(v.iter().map(|&x| Value::from(x)).collect());
        let mut top = Map::new();
        top.insert("density".into(), Value::from(self.density));
        top.insert("strain scale".into(), arr(&self.strain_scale));
        for (k, v) in &self.extra {
            top.insert(k.clone(), v.clone());
        }
        let mut coeffs = Map::new();
        coeffs.insert("const".into(), Value::from(self.constant));
        let ones: Vec<Value> = self
            .terms1d
            .iter()
            .map(|t| {
                let mut o = Map::new();
                o.insert("k".into(), Value::from(t.strain.index()));
                o.insert("t".into(), arr(&t.spline.t));
                o.insert("p".into(), arr(&t.spline.p));
                o.insert("m".into(), arr(&t.spline.m));
                Value::Object(o)
            })
            .collect();
        coeffs.insert("1D".into(), Value::Array(ones));
        let twos: Vec<Value> = self
            .terms2d
            .iter()
            .map(|t| {
                let s = &t.spline;
                let mut o = Map::new();
                o.insert("k0".into(), Value::from(t.strains[0].index()));
                o.insert("k1".into(), Value::from(t.strains[1].index()));
                o.insert("tu".into(), arr(&s.tu));
                o.insert("tv".into(), arr(&s.tv));
                o.insert("p".into(), arr(&s.p));
                o.insert("mu".into(), arr(&s.mu));
                o.insert("mv".into(), arr(&s.mv));
                o.insert("muv".into(), arr(&s.muv));
                Value::Object(o)
            })
            .collect();
        coeffs.insert("2D".into(), Value::Array(twos));
        top.insert("coeffs".into(), Value::Object(coeffs));
        Value::Object(top)
    }

    /// The material as pretty-printed JSON text.
    pub fn to_json_string(&self) -> String {
        serde_json::to_string_pretty(&self.to_json_value()).expect("JSON values always serialise")
    }

    /// Write the material file (atomically: a temporary file renamed into place).
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        let tmp = path.with_extension("json.tmp");
        std::fs::write(&tmp, self.to_json_string() + "\n")?;
        std::fs::rename(&tmp, path)
    }
}

#[cfg(test)]
mod tests {
    use super::quote_non_finite;

    #[test]
    fn quotes_only_bare_non_finite_tokens() {
        let s = r#"{"a": NaN, "b": [1e999, -Infinity, 2.5], "c": "NaN inside", "d": -1e-3}"#;
        let q = quote_non_finite(s);
        assert_eq!(
            q,
            r#"{"a": "NaN", "b": ["1e999", "-Infinity", 2.5], "c": "NaN inside", "d": -1e-3}"#
        );
    }
}
