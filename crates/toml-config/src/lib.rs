//! # toml-config — the workspace's one TOML loader
//!
//! Every configuration file of the workspace (the tracker's `configs/outdoor.toml`, the INS
//! scenario `configs/paper.toml` and its sections) is read through [`TomlDoc`], so that every
//! error a user can cause through such a file is a [`TomlError`] naming the file, the line and
//! the column (1-based; the column counts characters) of the offending key or value, once:
//!
//! ```text
//! configs/mine.toml:12:1: unknown field `threshold`, expected one of `magnitude_threshold`, … (in `gradient`)
//! configs/mine.toml:31:14: `filter.r_sigma_px` = -2: must be > 0
//! ```
//!
//! Parse and schema errors (syntax, unknown or missing key, wrong type — with
//! `#[serde(deny_unknown_fields)]` on the target types) are located by the span the `toml`
//! parser attaches to them; range errors found after deserialisation by the caller's validation
//! are located with [`TomlDoc::error_at`], which finds a dotted key (`filter.r_sigma_px`,
//! `sighting.landmarks[1].lat_deg`) in the document.
//!
//! No I/O: callers read the file (and report an unreadable file with their own I/O error) and
//! pass its text and its path.
//!
//! ## Example
//! ```
//! use serde::Deserialize;
//! use toml_config::TomlDoc;
//!
//! #[derive(Deserialize, Debug)]
//! #[serde(deny_unknown_fields)]
//! struct Filter {
//!     r_sigma_px: f64,
//! }
//!
//! let doc = TomlDoc::parse("cfg.toml", "[filter]\nr_sigma_px = 2.0\n")?;
//! let f: Filter = doc.section("filter")?;
//! assert_eq!(f.r_sigma_px, 2.0);
//!
//! let doc = TomlDoc::parse("cfg.toml", "[filter]\nr_sigma = 2.0\n")?;
//! let e = doc.section::<Filter>("filter").unwrap_err();
//! assert_eq!((e.path.as_str(), e.line, e.column), ("cfg.toml", Some(2), Some(1)));
//! assert!(e.to_string().starts_with("cfg.toml:2:1: unknown field `r_sigma`"), "{e}");
//!
//! // A range error found after parsing, located at its key.
//! let e = doc.error_at("filter.r_sigma", "must be > 0");
//! assert_eq!(e.to_string(), "cfg.toml:2:1: must be > 0");
//! # Ok::<(), toml_config::TomlError>(())
//! ```

#[cfg(feature = "proptest")]
pub mod mutate;

use serde::de::DeserializeOwned;
use toml::Spanned;
use toml::de::{DeTable, DeValue, ValueDeserializer};

/// An error in a TOML text: the file (or name) it came from, where in it, and what.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{path}{}: {message}", at(*.line, *.column))]
pub struct TomlError {
    /// The file path as given by the caller (or a name such as `preset outdoor`).
    pub path: String,
    /// Line, 1-based; `None` when the error concerns no one place (a missing section).
    pub line: Option<usize>,
    /// Column, 1-based, in characters; `None` with `line`.
    pub column: Option<usize>,
    /// What is wrong (names the key where the parser or the validation does).
    pub message: String,
}

fn at(line: Option<usize>, column: Option<usize>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!(":{l}:{c}"),
        (Some(l), None) => format!(":{l}"),
        _ => String::new(),
    }
}

/// Line and column (both 1-based, the column in characters) of byte `offset` of `text`; an
/// offset past the end (or inside a character) is clamped to the nearest character boundary
/// before it.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line = before.matches('\n').count() + 1;
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

/// A parsed TOML document that remembers where each key and value came from.
#[derive(Debug)]
pub struct TomlDoc<'a> {
    path: String,
    text: &'a str,
    root: Spanned<DeTable<'a>>,
}

impl<'a> TomlDoc<'a> {
    /// Parse `text` (the contents of `path`). A syntax error is located at the offending token.
    pub fn parse(path: impl Into<String>, text: &'a str) -> Result<Self, TomlError> {
        let path = path.into();
        match DeTable::parse(text) {
            Ok(root) => Ok(TomlDoc { path, text, root }),
            Err(e) => {
                let (line, column) = e.span().map(|s| line_col(text, s.start)).unzip();
                Err(TomlError {
                    path,
                    line,
                    column,
                    message: e.message().trim().to_owned(),
                })
            }
        }
    }

    /// The path (or name) given to [`TomlDoc::parse`].
    pub fn path(&self) -> &str {
        &self.path
    }

    /// An error at byte `offset` of the text (`None`: not located).
    pub fn error_at_offset(&self, offset: Option<usize>, message: impl Into<String>) -> TomlError {
        let (line, column) = offset.map(|o| line_col(self.text, o)).unzip();
        TomlError {
            path: self.path.clone(),
            line,
            column,
            message: message.into(),
        }
    }

    /// An error located at the dotted key `key` (`filter.r_sigma_px`, `sighting.landmarks[1]
    /// .lat_deg`): at the key itself if the document has it, else at the nearest enclosing
    /// table or array element that it has, else not located.
    pub fn error_at(&self, key: &str, message: impl Into<String>) -> TomlError {
        self.error_at_offset(self.locate(key), message)
    }

    /// Byte offset of the dotted key `key` (see [`TomlDoc::error_at`]).
    pub fn locate(&self, key: &str) -> Option<usize> {
        let mut table = self.root.get_ref();
        let mut found = None;
        let mut parts = key_parts(key).peekable();
        while let Some((name, indices)) = parts.next() {
            let Some((k, v)) = table.get_key_value(name) else {
                return found;
            };
            found = Some(k.span().start);
            let mut value = v;
            for i in indices {
                match value.get_ref() {
                    DeValue::Array(items) => match items.get(i) {
                        Some(item) => {
                            found = Some(item.span().start);
                            value = item;
                        }
                        None => return found,
                    },
                    _ => return found,
                }
            }
            match value.get_ref() {
                DeValue::Table(t) => table = t,
                _ if parts.peek().is_some() => return found,
                _ => {}
            }
        }
        found
    }

    /// Names of the top-level tables and keys, in document order where the parser keeps it.
    pub fn keys(&self) -> impl Iterator<Item = &str> {
        self.root
            .get_ref()
            .iter()
            .map(|(k, _)| k.get_ref().as_ref())
    }

    /// Refuse any top-level key or table not in `allowed`, located at its first occurrence.
    pub fn allow_only(&self, allowed: &[&str]) -> Result<(), TomlError> {
        for (k, _) in self.root.get_ref().iter() {
            let name: &str = k.get_ref().as_ref();
            if !allowed.contains(&name) {
                return Err(self.error_at_offset(
                    Some(k.span().start),
                    format!("unknown section `{name}`, expected one of {allowed:?}"),
                ));
            }
        }
        Ok(())
    }

    /// Deserialise the whole document into `T`.
    pub fn deserialize<T: DeserializeOwned>(&self) -> Result<T, TomlError> {
        let value = Spanned::new(
            self.root.span(),
            DeValue::Table(self.root.get_ref().clone()),
        );
        T::deserialize(ValueDeserializer::from(value)).map_err(|e| self.de_error(None, &e))
    }

    /// Deserialise the table `[name]` into `T`. A missing section is an error (not located).
    pub fn section<T: DeserializeOwned>(&self, name: &str) -> Result<T, TomlError> {
        let value = self
            .root
            .get_ref()
            .get(name)
            .ok_or_else(|| self.error_at_offset(None, format!("section [{name}] missing")))?;
        T::deserialize(ValueDeserializer::from(value.clone()))
            .map_err(|e| self.de_error(Some(name), &e))
    }

    /// A deserialisation error: located by its span, the key path it carries appended.
    fn de_error(&self, section: Option<&str>, e: &toml::de::Error) -> TomlError {
        // Without the input attached, the error's Display is its message and, when it knows
        // them, the keys leading to the offending value as a last line "in `a.b`".
        let shown = e.to_string();
        let keys = shown
            .lines()
            .filter_map(|l| l.strip_prefix("in `").and_then(|r| r.strip_suffix('`')))
            .next_back();
        let path = match (section, keys) {
            (Some(s), Some(k)) => Some(format!("{s}.{k}")),
            (Some(s), None) => Some(s.to_owned()),
            (None, Some(k)) => Some(k.to_owned()),
            (None, None) => None,
        };
        let message = e.message().trim();
        let message = match path {
            Some(p) if !message.contains(&format!("`{p}`")) => format!("{message} (in `{p}`)"),
            _ => message.to_owned(),
        };
        self.error_at_offset(e.span().map(|s| s.start), message)
    }
}

/// `a.b[1][2].c` → `("a", []), ("b", [1, 2]), ("c", [])`; an unparsable index is dropped.
fn key_parts(key: &str) -> impl Iterator<Item = (&str, Vec<usize>)> {
    key.split('.').map(|part| {
        let (name, rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        let indices = rest
            .split(['[', ']'])
            .filter(|s| !s.is_empty())
            .filter_map(|s| s.parse().ok())
            .collect();
        (name, indices)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_lines_and_characters_from_one() {
        let t = "ab\nçd = 1\n";
        assert_eq!(line_col(t, 0), (1, 1));
        assert_eq!(line_col(t, 2), (1, 3));
        assert_eq!(line_col(t, 3), (2, 1));
        assert_eq!(line_col(t, 5), (2, 2), "ç is one character of two bytes");
        assert_eq!(line_col(t, 4), (2, 1), "inside ç: clamped back");
        assert_eq!(line_col(t, 999), (3, 1));
    }

    #[test]
    fn key_parts_split_names_and_indices() {
        let v: Vec<_> = key_parts("sighting.landmarks[1].lat_deg").collect();
        assert_eq!(
            v,
            vec![
                ("sighting", vec![]),
                ("landmarks", vec![1]),
                ("lat_deg", vec![])
            ]
        );
    }
}
