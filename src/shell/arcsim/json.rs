//! The JSON dialect of ARCSim scene files (docs/arcsim.md): standard JSON plus `//` line and
//! `/* */` block comments, trailing commas before `]`/`}`, and the bare words `NaN`, `Infinity`, `-Infinity`
//! (read as numbers so that the converter can name the key that holds them instead of failing on syntax).
//! Every value keeps the line it starts on, so that errors and warnings can point at it.

use std::fmt;

/// A parsed value with the (1-based) line it starts on.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// the line it starts on (1-based)
    pub line: usize,
    /// the value
    pub value: Value,
}

/// A JSON value; objects keep their keys in file order (a repeated key appears twice).
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// `null`.
    Null,
    /// `true` or `false`.
    Bool(bool),
    /// A number (`NaN`, `Infinity` and `-Infinity` included).
    Number(f64),
    /// A string.
    String(String),
    /// An array.
    Array(Vec<Node>),
    /// An object: its keys and values in file order.
    Object(Vec<(String, Node)>),
}

impl Value {
    /// The JSON type's name, for "expected a number, got a string" messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Null => "null",
            Value::Bool(_) => "a boolean",
            Value::Number(_) => "a number",
            Value::String(_) => "a string",
            Value::Array(_) => "an array",
            Value::Object(_) => "an object",
        }
    }
}

/// A syntax error at a line and column (1-based; the column counts characters).
#[derive(Clone, Debug, PartialEq)]
pub struct SyntaxError {
    /// line (1-based)
    pub line: usize,
    /// column (1-based, in characters)
    pub column: usize,
    /// what is wrong
    pub message: String,
}

impl fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.line, self.column, self.message)
    }
}

/// The deepest nesting of arrays and objects accepted (a scene nests four levels; this bounds the recursion).
pub const MAX_DEPTH: usize = 64;

/// Parse a whole document (one value, then only whitespace and comments). A leading byte-order mark is skipped.
pub fn parse(text: &str) -> Result<Node, SyntaxError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut p = Parser {
        chars: text.chars().collect(),
        pos: 0,
        line: 1,
        column: 1,
    };
    p.skip()?;
    let v = p.value(0)?;
    p.skip()?;
    if p.pos < p.chars.len() {
        return Err(p.error("unexpected text after the scene's closing brace"));
    }
    Ok(v)
}

struct Parser {
    chars: Vec<char>,
    pos: usize,
    line: usize,
    column: usize,
}

impl Parser {
    fn error(&self, message: impl Into<String>) -> SyntaxError {
        SyntaxError {
            line: self.line,
            column: self.column,
            message: message.into(),
        }
    }

    fn peek(&self) -> Option<char> {
        self.chars.get(self.pos).copied()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek()?;
        self.pos += 1;
        if c == '\n' {
            self.line += 1;
            self.column = 1;
        } else {
            self.column += 1;
        }
        Some(c)
    }

    fn starts_with(&self, s: &str) -> bool {
        s.chars()
            .enumerate()
            .all(|(i, c)| self.chars.get(self.pos + i) == Some(&c))
    }

    /// Skip whitespace and comments.
    fn skip(&mut self) -> Result<(), SyntaxError> {
        loop {
            match self.peek() {
                Some(c) if c.is_whitespace() => {
                    self.bump();
                }
                Some('/') if self.starts_with("//") => {
                    while self.peek().is_some_and(|c| c != '\n') {
                        self.bump();
                    }
                }
                Some('/') if self.starts_with("/*") => {
                    let start = self.error("a /* comment is never closed");
                    self.bump();
                    self.bump();
                    loop {
                        if self.starts_with("*/") {
                            self.bump();
                            self.bump();
                            break;
                        }
                        if self.bump().is_none() {
                            return Err(start);
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    fn value(&mut self, depth: usize) -> Result<Node, SyntaxError> {
        let line = self.line;
        let value = match self.peek() {
            None => return Err(self.error("unexpected end of the file (a value was expected)")),
            Some('{') | Some('[') if depth >= MAX_DEPTH => {
                return Err(self.error(format!("nested deeper than {MAX_DEPTH} levels")))
            }
            Some('{') => self.object(depth)?,
            Some('[') => self.array(depth)?,
            Some('"') => Value::String(self.string()?),
            Some(c) if c == '-' || c.is_ascii_digit() || c.is_ascii_alphabetic() => self.word()?,
            Some(c) => return Err(self.error(format!("unexpected character {c:?}"))),
        };
        Ok(Node { line, value })
    }

    fn object(&mut self, depth: usize) -> Result<Value, SyntaxError> {
        self.bump();
        let mut entries = Vec::new();
        loop {
            self.skip()?;
            match self.peek() {
                Some('}') => {
                    self.bump();
                    return Ok(Value::Object(entries));
                }
                Some('"') => {}
                _ => return Err(self.error("expected a quoted key or '}'")),
            }
            let key = self.string()?;
            self.skip()?;
            if self.bump() != Some(':') {
                return Err(self.error(format!("expected ':' after the key \"{key}\"")));
            }
            self.skip()?;
            let v = self.value(depth + 1)?;
            entries.push((key, v));
            self.skip()?;
            match self.bump() {
                Some(',') => {}
                Some('}') => return Ok(Value::Object(entries)),
                _ => return Err(self.error("expected ',' or '}' after an object entry")),
            }
        }
    }

    fn array(&mut self, depth: usize) -> Result<Value, SyntaxError> {
        self.bump();
        let mut items = Vec::new();
        loop {
            self.skip()?;
            if self.peek() == Some(']') {
                self.bump();
                return Ok(Value::Array(items));
            }
            items.push(self.value(depth + 1)?);
            self.skip()?;
            match self.bump() {
                Some(',') => {}
                Some(']') => return Ok(Value::Array(items)),
                _ => return Err(self.error("expected ',' or ']' after an array element")),
            }
        }
    }

    fn string(&mut self) -> Result<String, SyntaxError> {
        let start = self.error("a string is never closed");
        self.bump();
        let mut s = String::new();
        loop {
            match self.bump() {
                None | Some('\n') => return Err(start),
                Some('"') => return Ok(s),
                Some('\\') => {
                    let c = match self.bump() {
                        Some('"') => '"',
                        Some('\\') => '\\',
                        Some('/') => '/',
                        Some('b') => '\u{8}',
                        Some('f') => '\u{c}',
                        Some('n') => '\n',
                        Some('r') => '\r',
                        Some('t') => '\t',
                        Some('u') => {
                            let hex: String = (0..4).filter_map(|_| self.bump()).collect();
                            u32::from_str_radix(&hex, 16)
                                .ok()
                                .and_then(char::from_u32)
                                .ok_or_else(|| self.error(format!("bad escape \\u{hex}")))?
                        }
                        other => {
                            return Err(self.error(format!("bad escape \\{}", other.unwrap_or(' '))))
                        }
                    };
                    s.push(c);
                }
                Some(c) => s.push(c),
            }
        }
    }

    /// A number, `true`, `false`, `null`, `NaN`, `Infinity` or `-Infinity`.
    fn word(&mut self) -> Result<Value, SyntaxError> {
        let start = self.error("");
        let mut w = String::new();
        while let Some(c) = self.peek() {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '+' | '.') {
                w.push(c);
                self.bump();
            } else {
                break;
            }
        }
        let bad = |m: String| SyntaxError {
            message: m,
            ..start.clone()
        };
        Ok(match w.as_str() {
            "true" => Value::Bool(true),
            "false" => Value::Bool(false),
            "null" => Value::Null,
            "NaN" | "nan" => Value::Number(f64::NAN),
            "Infinity" | "inf" => Value::Number(f64::INFINITY),
            "-Infinity" | "-inf" => Value::Number(f64::NEG_INFINITY),
            _ if is_json_number(&w) => Value::Number(
                w.parse::<f64>()
                    .map_err(|_| bad(format!("bad number {w:?}")))?,
            ),
            _ => return Err(bad(format!("unexpected word {w:?} (not a JSON value)"))),
        })
    }
}

/// Whether `w` follows JSON's number grammar: `-? (0 | [1-9][0-9]*) (. [0-9]+)? ([eE] [+-]? [0-9]+)?`.
fn is_json_number(w: &str) -> bool {
    let b = w.as_bytes();
    let mut i = 0;
    let digits = |i: &mut usize| {
        let s = *i;
        while *i < b.len() && b[*i].is_ascii_digit() {
            *i += 1;
        }
        *i > s
    };
    if b.first() == Some(&b'-') {
        i += 1;
    }
    if b.get(i) == Some(&b'0') {
        i += 1;
    } else if !digits(&mut i) {
        return false;
    }
    if b.get(i) == Some(&b'.') {
        i += 1;
        if !digits(&mut i) {
            return false;
        }
    }
    if matches!(b.get(i), Some(b'e') | Some(b'E')) {
        i += 1;
        if matches!(b.get(i), Some(b'+') | Some(b'-')) {
            i += 1;
        }
        if !digits(&mut i) {
            return false;
        }
    }
    i == b.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_lines_and_special_numbers() {
        let text = "{\n  // a comment\n  \"a\": 1e-3, /* block\n */ \"b\": [1, NaN, -Infinity,],\n  \"c\": \"x//y\"\n}";
        let n = parse(text).unwrap();
        let Value::Object(e) = n.value else {
            panic!("an object")
        };
        assert_eq!(e[0].0, "a");
        assert_eq!(e[0].1.line, 3);
        assert_eq!(e[0].1.value, Value::Number(1e-3));
        assert_eq!(e[1].1.line, 4);
        let Value::Array(a) = &e[1].1.value else {
            panic!("an array")
        };
        assert_eq!(a.len(), 3);
        assert!(matches!(a[1].value, Value::Number(x) if x.is_nan()));
        assert_eq!(a[2].value, Value::Number(f64::NEG_INFINITY));
        assert_eq!(e[2].1.value, Value::String("x//y".into()));
    }

    #[test]
    fn syntax_errors_have_positions() {
        let e = parse("{\n \"a\": 01\n}").unwrap_err();
        assert_eq!((e.line, e.column), (2, 7));
        let e = parse("{\"a\": 1 /* open").unwrap_err();
        assert_eq!(e.line, 1);
        assert!(e.message.contains("never closed"), "{}", e.message);
        assert!(parse("[1] 2").is_err());
        assert!(parse(&"[".repeat(100)).is_err());
    }
}
