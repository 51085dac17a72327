//! [`SceneError`]: everything that can be wrong with a scene file, each with the place it happened
//! ([`Location`]), and the "did you mean" hints ([`hint`]) its messages end with.

use std::borrow::Cow;
use std::fmt;
use std::path::{Path, PathBuf};

/// `text` with every control character (NUL, newline, ESC, …) and every bidirectional-text
/// override written as an escape (`\0`, `\n`, `\u{1b}`, `\u{202e}`), so a name or path read from a
/// file cannot break a message's line or drive the terminal that prints it.
pub fn escape_controls(text: &str) -> Cow<'_, str> {
    let bad = |c: char| c.is_control() || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    if !text.chars().any(bad) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '\0' => out.push_str("\\0"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if bad(c) => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

/// A path for a message: as `Path::display` shows it, control characters escaped
/// ([`escape_controls`]).
pub(crate) fn show_path(path: &Path) -> String {
    escape_controls(&path.display().to_string()).into_owned()
}

/// A place in a scene file: the file and the 1-based line and column (in characters) of the
/// offending key or value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The scene file.
    pub path: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, counted in characters.
    pub col: usize,
}

impl Location {
    /// The location of byte `offset` in `text` (clamped to the text; never panics).
    pub fn from_offset(path: &Path, text: &str, offset: usize) -> Self {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let col = before[line_start..].chars().count() + 1;
        Self { path: path.to_path_buf(), line, col }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", show_path(&self.path), self.line, self.col)
    }
}

/// Why a scene could not be loaded. `Display` is `path:line:col: message` (or `path: message` for
/// errors without a position); every message says what was wrong and, where one exists, the fix.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneError {
    /// The scene file could not be read (missing, unreadable, not UTF-8).
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        message: String,
    },
    /// The file is not valid TOML.
    Syntax {
        /// Where the parser stopped.
        at: Location,
        /// The parser's message.
        message: String,
    },
    /// A key that the table does not accept, with the nearest valid key when one is close.
    UnknownKey {
        /// The key.
        at: Location,
        /// The full message, including the suggestion.
        message: String,
    },
    /// A value of the wrong type or shape (a string where a number belongs, 2 components where 3
    /// belong, …).
    Type {
        /// The value.
        at: Location,
        /// What was expected and what was found.
        message: String,
    },
    /// A value of the right type outside its valid range: NaN/inf, negative, zero-length
    /// vectors, `fov` outside (0, 180), `near ≥ far`, image size 0 or over 16384, an unknown
    /// enumeration name, …
    Value {
        /// The value.
        at: Location,
        /// The rule that was broken and the value found.
        message: String,
    },
    /// A required key is absent.
    Missing {
        /// The table (its header) that lacks the key.
        at: Location,
        /// Which key and what it means.
        message: String,
    },
    /// Two objects, two waves or two tracks share a name/target.
    Duplicate {
        /// The second occurrence.
        at: Location,
        /// What is duplicated and where the first one is.
        message: String,
    },
    /// An animation track is wrong: unknown target, keys out of order, value of the wrong shape.
    Track {
        /// The offending part of the track.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// A glTF file referenced by an `[[object]]` could not be loaded.
    Gltf {
        /// The `path` key in the scene that referenced the file.
        at: Location,
        /// The glTF file.
        file: PathBuf,
        /// What is wrong with it.
        message: String,
    },
}

impl SceneError {
    /// The location in the scene file, if the error has one.
    pub fn location(&self) -> Option<&Location> {
        match self {
            SceneError::Io { .. } => None,
            SceneError::Syntax { at, .. }
            | SceneError::UnknownKey { at, .. }
            | SceneError::Type { at, .. }
            | SceneError::Value { at, .. }
            | SceneError::Missing { at, .. }
            | SceneError::Duplicate { at, .. }
            | SceneError::Track { at, .. }
            | SceneError::Gltf { at, .. } => Some(at),
        }
    }

    /// The message without the location prefix.
    pub fn message(&self) -> &str {
        match self {
            SceneError::Io { message, .. }
            | SceneError::Syntax { message, .. }
            | SceneError::UnknownKey { message, .. }
            | SceneError::Type { message, .. }
            | SceneError::Value { message, .. }
            | SceneError::Missing { message, .. }
            | SceneError::Duplicate { message, .. }
            | SceneError::Track { message, .. }
            | SceneError::Gltf { message, .. } => message,
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneError::Io { path, message } => {
                write!(f, "{}: {}", show_path(path), escape_controls(message))
            }
            SceneError::Gltf { at, file, message } => {
                write!(f, "{at}: glTF file {}: {}", show_path(file), escape_controls(message))
            }
            other => {
                // every remaining variant has a location
                let at = other.location().expect("positioned variant");
                write!(f, "{at}: {}", escape_controls(other.message()))
            }
        }
    }
}

impl std::error::Error for SceneError {}

/// Levenshtein distance between two strings (by characters, ASCII case ignored).
pub(crate) fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().map(|c| c.to_ascii_lowercase()).collect();
    let b: Vec<char> = b.chars().map(|c| c.to_ascii_lowercase()).collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.iter().enumerate() {
        cur[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// Longest word a "did you mean" looks for (a typo of a longer name is not worth the work).
const SUGGEST_MAX_WORD: usize = 64;
/// Most candidates a "did you mean" compares, in order (a scene may name 65 536 objects).
const SUGGEST_MAX_CANDIDATES: usize = 4096;
/// Most candidates a hint lists when none is close.
const HINT_MAX_LISTED: usize = 40;

/// The candidate nearest to `word` if it is close enough to be a plausible typo. The work is
/// bounded whatever the file holds: words over [`SUGGEST_MAX_WORD`] characters get no
/// suggestion, candidates whose length alone rules them out are skipped, and at most
/// [`SUGGEST_MAX_CANDIDATES`] are compared.
pub(crate) fn suggest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let n = word.chars().count();
    if n > SUGGEST_MAX_WORD {
        return None;
    }
    let limit = (n / 3).max(2);
    candidates
        .into_iter()
        .take(SUGGEST_MAX_CANDIDATES)
        .filter(|c| c.len() <= 4 * (n + limit) && c.chars().count().abs_diff(n) <= limit)
        .map(|c| (edit_distance(word, c), c))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

/// `"; did you mean `x`?"` or, without a close match, `"; valid keys: a, b, c"` (at most
/// [`HINT_MAX_LISTED`] of them, then how many there are).
pub(crate) fn hint(word: &str, candidates: &[&str], noun: &str) -> String {
    match suggest(word, candidates.iter().copied()) {
        Some(s) => format!("; did you mean `{s}`?"),
        None if candidates.is_empty() => String::new(),
        None => {
            let list: Vec<String> =
                candidates.iter().take(HINT_MAX_LISTED).map(|c| format!("`{c}`")).collect();
            let more = if candidates.len() > HINT_MAX_LISTED {
                format!(", … ({} in all)", candidates.len())
            } else {
                String::new()
            };
            format!("; valid {noun}: {}{more}", list.join(", "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_and_suggestion() {
        assert_eq!(edit_distance("alpah_s", "alpha_s"), 2);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(suggest("alpah_s", ["alpha_s", "alpha_c", "M"]), Some("alpha_s"));
        assert_eq!(suggest("zzzzzz", ["alpha_s", "M"]), None);
    }

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(escape_controls("plain/ü.png"), "plain/ü.png");
        assert_eq!(escape_controls("a\0b\nc\u{1b}[31m"), "a\\0b\\nc\\u{1b}[31m");
        assert_eq!(escape_controls("x\u{202e}y"), "x\\u{202e}y");
        assert_eq!(show_path(Path::new("d/\tf")), "d/\\tf");
    }

    #[test]
    fn location_counts_lines_and_characters() {
        let text = "a = 1\nλλ = 2\n";
        let at = Location::from_offset(Path::new("x.toml"), text, text.find("= 2").unwrap());
        assert_eq!((at.line, at.col), (2, 4));
        let end = Location::from_offset(Path::new("x.toml"), text, 10_000);
        assert_eq!((end.line, end.col), (3, 1));
    }
}
