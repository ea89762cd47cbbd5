//! One error type for everything a user can get wrong: it always names the file or field.

use std::fmt;
use std::path::Path;

/// A user-facing error: a message that names the file, field or value at fault.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    msg: String,
}

/// Result alias used across texsim.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// A free-form message.
    pub fn msg(msg: impl Into<String>) -> Self {
        Self { msg: msg.into() }
    }
    /// A problem with a file: `path: what`.
    pub fn file(path: &Path, what: impl fmt::Display) -> Self {
        Self {
            msg: format!("{}: {what}", path.display()),
        }
    }
    /// A problem with a named field or option: `field 'name': what`.
    pub fn field(name: &str, what: impl fmt::Display) -> Self {
        Self {
            msg: format!("field '{name}': {what}"),
        }
    }
    /// Prefixes context (e.g. the file that held a bad field).
    pub fn context(self, ctx: impl fmt::Display) -> Self {
        Self {
            msg: format!("{ctx}: {}", self.msg),
        }
    }
    /// The message text.
    pub fn message(&self) -> &str {
        &self.msg
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.msg)
    }
}

impl std::error::Error for Error {}

/// `line L, column C (`source line`)` of byte `offset` in `text` (1-based, columns in chars).
#[must_use]
pub fn text_position(text: &str, offset: usize) -> String {
    let mut start = offset.min(text.len());
    while !text.is_char_boundary(start) {
        start -= 1;
    }
    let before = &text[..start];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let col = before[line_start..].chars().count() + 1;
    let src = text[line_start..].lines().next().unwrap_or("").trim();
    format!("line {line}, column {col} (`{}`)", clip_line(src))
}

/// Most characters of a source line an error quotes; a longer line is cut with `...`.
const QUOTED_LINE_CHARS: usize = 80;

/// `src` cut to [`QUOTED_LINE_CHARS`] characters (a line of megabytes stays one line).
fn clip_line(src: &str) -> std::borrow::Cow<'_, str> {
    match src.char_indices().nth(QUOTED_LINE_CHARS) {
        Some((cut, _)) => format!("{}...", &src[..cut]).into(),
        None => src.into(),
    }
}

/// One-line form of a toml error: `line L, column C (`source line`): message` (the message
/// alone when toml gives no position).
#[must_use]
pub fn toml_message(text: &str, e: &toml::de::Error) -> String {
    let msg = nearest_field(e.message().trim_end().replace('\n', " "));
    // toml says nothing when the text ends inside a key-value pair or a table header.
    let msg = if msg.is_empty() {
        "incomplete TOML: a value or a closing bracket is missing".to_string()
    } else {
        msg
    };
    match e.span() {
        Some(span) => format!("{}: {msg}", text_position(text, span.start)),
        None => msg,
    }
}

/// serde's `unknown field `x`, expected one of `a`, `b`, ...` answered with the nearest valid
/// name instead of the whole list (`unknown field `x`; did you mean 'a'?`); the list stays when
/// no name is near.
fn nearest_field(msg: String) -> String {
    let Some(rest) = msg.strip_prefix("unknown field `") else {
        return msg;
    };
    let Some((name, expected)) = rest.split_once('`') else {
        return msg;
    };
    let candidates = expected.split('`').skip(1).step_by(2);
    let hint = crate::hwconfig::did_you_mean(name, candidates);
    if hint.is_empty() {
        msg
    } else {
        format!("unknown field `{name}`{hint}")
    }
}

impl From<hw_model::ConfigError> for Error {
    fn from(e: hw_model::ConfigError) -> Self {
        Self { msg: e.to_string() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file cut after `key =` gets a message, not an empty one.
    #[test]
    fn a_cut_file_gets_a_message() {
        let text = "[raster]\ndepth_bits =";
        let e = toml::from_str::<toml::Table>(text).unwrap_err();
        let m = toml_message(text, &e);
        assert!(
            m.ends_with("a value or a closing bracket is missing"),
            "{m}"
        );
        assert!(m.starts_with("line 2"), "{m}");
    }

    /// The quoted source line is cut at 80 characters.
    #[test]
    fn a_long_line_is_quoted_cut() {
        let text = format!("a = [{}]", "1, ".repeat(100_000));
        let m = text_position(&text, 3);
        assert!(m.len() < 120 && m.ends_with("...`)"), "{m}");
        assert_eq!(text_position("x = 1", 4), "line 1, column 5 (`x = 1`)");
    }
}
