//! Typed access to the values of an ARCSim scene with errors and warnings that name the file, the line and the
//! key's path (docs/arcsim.md, "Ignored keys and errors": unknown keys get a one-line warning naming the key,
//! malformed ones a one-line error with the file and key).

use super::json::{Node, Value};
use crate::shell::ShellError;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The reading context: the file's name for messages, its folder for relative paths, and the warnings so far.
pub(super) struct Ctx<'a> {
    pub file: &'a str,
    /// the scene file's folder (as given; relative paths in the produced scene start here)
    pub dir: &'a Path,
    pub warnings: Vec<String>,
    /// notes (not warnings): what the converter did that a user may want to know
    pub notes: Vec<String>,
}

/// The entries of an object by key.
pub(super) type Fields<'n> = HashMap<&'n str, &'n Node>;

/// What an object's key is to the converter.
pub(super) enum Key<'r> {
    /// converted (looked up by the caller)
    Used,
    /// an ARCSim key the conversion does not use: a warning with this reason
    Ignored(&'r str),
}

impl Ctx<'_> {
    pub fn error(&self, line: usize, key: &str, message: impl Into<String>) -> ShellError {
        ShellError::Arcsim {
            file: self.file.to_string(),
            line,
            key: key.to_string(),
            message: message.into(),
        }
    }

    /// A one-line warning naming the file, line and key.
    pub fn warn(&mut self, line: usize, key: &str, message: &str) {
        self.warnings.push(format!(
            "{}:{line}: warning: key `{key}` {message}",
            self.file
        ));
    }

    /// The object at `node` with its keys checked against `keys` (`path` is the object's own path, "" for the
    /// top level): ignored keys and keys not in the list get a warning each; a key given twice is an error.
    pub fn fields<'n>(
        &mut self,
        node: &'n Node,
        path: &str,
        keys: &[(&str, Key)],
    ) -> Result<Fields<'n>, ShellError> {
        let Value::Object(entries) = &node.value else {
            return Err(self.error(
                node.line,
                if path.is_empty() { "(top level)" } else { path },
                format!("expected an object, got {}", node.value.kind()),
            ));
        };
        let mut out = HashMap::new();
        for (k, v) in entries {
            let full = join(path, k);
            if out.insert(k.as_str(), v).is_some() {
                return Err(self.error(v.line, &full, "is given twice"));
            }
            match keys.iter().find(|(name, _)| name == k) {
                Some((_, Key::Used)) => {}
                Some((_, Key::Ignored(why))) => {
                    self.warn(v.line, &full, &format!("ignored: {why}"))
                }
                None => self.warn(
                    v.line,
                    &full,
                    "ignored: not an ARCSim key this converter knows (docs/arcsim.md lists them)",
                ),
            }
        }
        Ok(out)
    }

    /// A finite number.
    pub fn number(&self, n: &Node, key: &str) -> Result<f64, ShellError> {
        match n.value {
            Value::Number(x) if x.is_finite() => Ok(x),
            Value::Number(x) => {
                Err(self.error(n.line, key, format!("must be a finite number, got {x}")))
            }
            ref v => Err(self.error(n.line, key, format!("expected a number, got {}", v.kind()))),
        }
    }

    /// A finite number ≥ 0.
    pub fn non_negative(&self, n: &Node, key: &str) -> Result<f64, ShellError> {
        let x = self.number(n, key)?;
        if x < 0.0 {
            return Err(self.error(n.line, key, format!("must not be negative, got {x}")));
        }
        Ok(x)
    }

    /// A finite number > 0.
    pub fn positive(&self, n: &Node, key: &str) -> Result<f64, ShellError> {
        let x = self.number(n, key)?;
        if x <= 0.0 {
            return Err(self.error(n.line, key, format!("must be positive, got {x}")));
        }
        Ok(x)
    }

    /// A fraction in [0, 1].
    pub fn fraction(&self, n: &Node, key: &str) -> Result<f64, ShellError> {
        let x = self.number(n, key)?;
        if !(0.0..=1.0).contains(&x) {
            return Err(self.error(
                n.line,
                key,
                format!("must be a fraction in [0, 1], got {x}"),
            ));
        }
        Ok(x)
    }

    /// A whole number in `0..end` (`what` describes the range in the message).
    pub fn index(&self, n: &Node, key: &str, end: usize, what: &str) -> Result<usize, ShellError> {
        let x = self.number(n, key)?;
        if x.fract() != 0.0 || x < 0.0 || x >= end as f64 {
            return Err(self.error(n.line, key, format!("must be {what}, got {x}")));
        }
        Ok(x as usize)
    }

    pub fn boolean(&self, n: &Node, key: &str) -> Result<bool, ShellError> {
        match n.value {
            Value::Bool(b) => Ok(b),
            ref v => Err(self.error(
                n.line,
                key,
                format!("expected true or false, got {}", v.kind()),
            )),
        }
    }

    pub fn string<'n>(&self, n: &'n Node, key: &str) -> Result<&'n str, ShellError> {
        match &n.value {
            Value::String(s) => Ok(s),
            v => Err(self.error(n.line, key, format!("expected a string, got {}", v.kind()))),
        }
    }

    pub fn array<'n>(&self, n: &'n Node, key: &str) -> Result<&'n [Node], ShellError> {
        match &n.value {
            Value::Array(a) => Ok(a),
            v => Err(self.error(n.line, key, format!("expected an array, got {}", v.kind()))),
        }
    }

    /// An array of exactly `N` finite numbers.
    pub fn numbers<const N: usize>(&self, n: &Node, key: &str) -> Result<[f64; N], ShellError> {
        let a = self.array(n, key)?;
        if a.len() != N {
            return Err(self.error(
                n.line,
                key,
                format!("expected {N} numbers, got {}", a.len()),
            ));
        }
        let mut out = [0.0; N];
        for (i, x) in a.iter().enumerate() {
            out[i] = self.number(x, &format!("{key}[{i}]"))?;
        }
        Ok(out)
    }

    /// A required key of `fields` (the object at `line`, path `path`).
    pub fn required<'n>(
        &self,
        fields: &Fields<'n>,
        line: usize,
        path: &str,
        key: &str,
    ) -> Result<&'n Node, ShellError> {
        fields
            .get(key)
            .copied()
            .ok_or_else(|| self.error(line, &join(path, key), "is missing"))
    }

    /// A file named in the scene, resolved as ARCSim-HYLC's scenes expect: relative names are tried in the scene
    /// file's folder and then in each folder above it, the first that exists wins. Returns the name relative to
    /// the scene's folder (`../../../meshes/x.obj`; absolute names stay as they are) and the path to open.
    pub fn resolve(&mut self, n: &Node, key: &str) -> Result<(String, PathBuf), ShellError> {
        let name = self.string(n, key)?;
        if name.is_empty() {
            return Err(self.error(n.line, key, "is an empty file name"));
        }
        if Path::new(name).is_absolute() {
            return if Path::new(name).is_file() {
                Ok((name.to_string(), PathBuf::from(name)))
            } else {
                Err(self.error(n.line, key, format!("{name}: no such file")))
            };
        }
        let here = if self.dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            self.dir
        };
        let start = std::fs::canonicalize(here)
            .map_err(|e| self.error(n.line, key, format!("{}: {e}", here.display())))?;
        for (up, folder) in start.ancestors().enumerate() {
            let found = folder.join(name);
            if found.is_file() {
                let rel = match follow_link_files(&found) {
                    None => format!("{}{name}", "../".repeat(up)),
                    Some(target) => {
                        let rel = relative(&start, &target);
                        self.notes.push(format!(
                            "{}:{}: note: key `{key}`: {name} is a link stored as text (a symbolic link checked \
                             out as a file); followed to {rel}",
                            self.file, n.line
                        ));
                        rel
                    }
                };
                let open = here.join(&rel);
                return Ok((rel, open));
            }
        }
        Err(self.error(
            n.line,
            key,
            format!(
                "{name}: no such file in {} or any folder above it",
                start.display()
            ),
        ))
    }
}

/// `path.key` (or `key` at the top level).
pub(super) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The longest link chain [`follow_link_files`] follows.
const MAX_LINKS: usize = 8;

/// A file that holds only a relative path to an existing file (how git checks out a symbolic link where the file
/// system or the copy does not keep links: the scenes' five materials are such links to
/// `../../hylc2020/materials/`): the canonical path of the file it leads to, following chains of such files;
/// `None` for an ordinary file.
fn follow_link_files(path: &Path) -> Option<PathBuf> {
    let mut at = path.to_path_buf();
    let mut followed = false;
    for _ in 0..MAX_LINKS {
        let meta = std::fs::metadata(&at).ok()?;
        if meta.len() > 4096 {
            break;
        }
        let Ok(text) = std::fs::read_to_string(&at) else {
            break;
        };
        let target = text.trim();
        if target.is_empty()
            || target.contains('\n')
            || target.starts_with(['{', '[', '#'])
            || Path::new(target).is_absolute()
        {
            break;
        }
        let next = at.parent()?.join(target);
        if !next.is_file() {
            break;
        }
        at = next;
        followed = true;
    }
    if followed {
        std::fs::canonicalize(at).ok()
    } else {
        None
    }
}

/// The path of `target` relative to the folder `base` (both canonical), with `../` where needed.
fn relative(base: &Path, target: &Path) -> String {
    let b: Vec<_> = base.components().collect();
    let t: Vec<_> = target.components().collect();
    let common = b.iter().zip(&t).take_while(|(x, y)| x == y).count();
    let mut out = "../".repeat(b.len() - common);
    let rest: Vec<String> = t[common..]
        .iter()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    out.push_str(&rest.join("/"));
    out
}
