//! Mutations of TOML text for property tests (feature `proptest`): the edits the workspace's
//! configuration parsers are fuzzed with — a value replaced by a hostile one (NaN, ±∞, overflow, a
//! wrong type), a line deleted or inserted, a bit flipped — and the checks that an error located
//! by [`crate::TomlError`] points into the text. One copy for every TOML file of the workspace
//! (tracker presets, camera files, the INS scenario).

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngSeed, TestCaseError};

/// A deterministic proptest configuration: `cases` cases, a fixed seed, no persistence files.
pub fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x746f_6d6c),
        failure_persistence: None,
        ..Config::default()
    }
}

/// Lines of `text` of the form `key = value [# comment]`: (line index, key).
pub fn key_lines(text: &str) -> Vec<(usize, String)> {
    text.lines()
        .enumerate()
        .filter_map(|(i, l)| {
            let (k, _) = l.split_once('=')?;
            let k = k.trim();
            (!k.is_empty()
                && !l.trim_start().starts_with('#')
                && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
            .then(|| (i, k.to_owned()))
        })
        .collect()
}

/// `text` with the value on line `line` replaced by `value` (its comment kept); a line without
/// `=` is left as it is.
pub fn with_value_on_line(text: &str, line: usize, value: &str) -> String {
    let mut out = String::new();
    for (i, l) in text.lines().enumerate() {
        match l.split_once('=') {
            Some((k, rest)) if i == line => {
                let comment = rest.find('#').map_or("", |c| &rest[c..]);
                out.push_str(&format!("{k}= {value} {comment}"));
            }
            _ => out.push_str(l),
        }
        out.push('\n');
    }
    out
}

/// An edit of a configuration text.
#[derive(Debug, Clone)]
pub enum Edit {
    /// Replace the value of one `key = value` line.
    Value(Index, &'static str),
    /// Delete one line.
    DeleteLine(Index),
    /// Insert a line before another.
    InsertLine(Index, String),
    /// Flip one bit of one byte (the text is then read lossily as UTF-8).
    FlipBit(Index, u8),
}

/// The hostile values [`Edit::Value`] puts in.
pub const VALUES: &[&str] = &[
    "nan",
    "+nan",
    "-nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e999",
    "0",
    "-1",
    "0.0",
    "99999999999999999999",
    "-99999999999999999999",
    "1.7976931348623157e308",
    "5e-324",
    "\"ten\"",
    "true",
    "[1.0, 2.0]",
    "[]",
    "{ a = 1 }",
    "",
    "1979-05-27",
    "'",
    "[1.0, nan, 3.0]",
];

/// Random edits: mostly value replacements, some deleted and inserted lines, some flipped bits.
pub fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        3 => (any::<Index>(), prop::sample::select(VALUES)).prop_map(|(i, v)| Edit::Value(i, v)),
        1 => any::<Index>().prop_map(Edit::DeleteLine),
        1 => (
            any::<Index>(),
            prop_oneof![
                Just("junk = 1".to_owned()),
                Just("[extra]".to_owned()),
                Just("[filter]".to_owned()),
                Just("[[trajectory.segments]]".to_owned()),
                "[ -~]{0,20}",
            ]
        )
            .prop_map(|(i, l)| Edit::InsertLine(i, l)),
        1 => (any::<Index>(), 0u8..8).prop_map(|(i, b)| Edit::FlipBit(i, b)),
    ]
}

/// `text` after the edit `e`.
pub fn apply(text: &str, e: &Edit) -> String {
    match e {
        Edit::Value(i, v) => {
            let keys = key_lines(text);
            if keys.is_empty() {
                return text.to_owned();
            }
            with_value_on_line(text, keys[i.index(keys.len())].0, v)
        }
        Edit::DeleteLine(i) => {
            let lines: Vec<&str> = text.lines().collect();
            let drop = i.index(lines.len().max(1));
            lines
                .iter()
                .enumerate()
                .filter(|(k, _)| *k != drop)
                .map(|(_, l)| format!("{l}\n"))
                .collect()
        }
        Edit::InsertLine(i, new) => {
            let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
            let at = i.index(lines.len() + 1);
            lines.insert(at, new.clone());
            lines.iter().map(|l| format!("{l}\n")).collect()
        }
        Edit::FlipBit(i, bit) => {
            let mut bytes = text.as_bytes().to_vec();
            if !bytes.is_empty() {
                let k = i.index(bytes.len());
                bytes[k] ^= 1 << bit;
            }
            String::from_utf8_lossy(&bytes).into_owned()
        }
    }
}

/// A located error must point into the text: a line that exists, a column within it (+1 for
/// an error at the end of a line).
///
/// # Errors
/// A failed test case naming the line or column that is out of the text.
pub fn check_location(
    text: &str,
    line: Option<usize>,
    column: Option<usize>,
) -> Result<(), TestCaseError> {
    if let (Some(l), Some(c)) = (line, column) {
        let n_lines = text.lines().count().max(1);
        prop_assert!(l >= 1 && l <= n_lines + 1, "line {} of {}", l, n_lines);
        let len = text.lines().nth(l - 1).map_or(0, |s| s.chars().count());
        prop_assert!(
            c >= 1 && c <= len + 1,
            "column {} of a {}-character line",
            c,
            len
        );
    }
    Ok(())
}

/// The 0-based line of the first occurrence of `needle`, `None` if it does not occur.
pub fn line_of(text: &str, needle: &str) -> Option<usize> {
    text.find(needle).map(|at| text[..at].matches('\n').count())
}
