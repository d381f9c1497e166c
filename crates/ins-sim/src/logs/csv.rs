//! The CSV reader every log reader shares: the header checked (one of several accepted), each
//! record split once, and every error located by file, line (1-based) and column (1-based start
//! of the field). The IMU stream ([`super::imu`]) and the other readers ([`super::read`],
//! [`super::reference`], the replay's sightings) use it; it uses none of them.

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use crate::SimError;

pub(super) fn io_err(path: &Path) -> impl Fn(std::io::Error) -> SimError + '_ {
    move |source| SimError::LogIo {
        path: path.to_path_buf(),
        source,
    }
}

/// One parsed CSV line: the text and the start of each field.
pub(super) struct Record {
    pub(super) text: String,
    pub(super) starts: Vec<usize>,
    pub(super) line: usize,
}

/// A CSV file read line by line with its header checked.
pub(super) struct CsvReader {
    pub(super) path: PathBuf,
    pub(super) lines: std::io::Lines<BufReader<File>>,
    pub(super) line: usize,
    pub(super) fields: usize,
}

impl CsvReader {
    /// Opens a file whose header is one of `headers`; returns the reader and the index of the
    /// header found. The error for another header lists the accepted ones.
    pub(super) fn open_any(path: &Path, headers: &[&str]) -> Result<(Self, usize), SimError> {
        let file = File::open(path).map_err(io_err(path))?;
        let mut r = Self {
            path: path.to_path_buf(),
            lines: BufReader::new(file).lines(),
            line: 0,
            fields: 0,
        };
        let accepted = headers
            .iter()
            .map(|h| format!("`{h}`"))
            .collect::<Vec<_>>()
            .join(" or ");
        let Some(first) = r.next_raw()? else {
            return Err(r.parse_err(1, 1, format!("empty file, expected the header {accepted}")));
        };
        let got: Vec<&str> = first.text.split(',').map(str::trim).collect();
        for (i, h) in headers.iter().enumerate() {
            if got.iter().copied().eq(h.split(',')) {
                r.fields = h.split(',').count();
                return Ok((r, i));
            }
        }
        // Name the first field that differs from the closest accepted header.
        let common = |h: &str| {
            got.iter()
                .zip(h.split(','))
                .take_while(|(a, b)| *a == b)
                .count()
        };
        let closest = headers
            .iter()
            .copied()
            .max_by_key(|h| common(h))
            .unwrap_or("");
        let k = common(closest);
        let column = first.starts.get(k).map_or(first.text.len(), |s| *s) + 1;
        let message = match (got.get(k), closest.split(',').nth(k)) {
            (Some(g), Some(want)) => {
                format!("header field `{g}`, expected `{want}` (header {accepted})")
            }
            (None, Some(want)) => format!("header ends before `{want}` (header {accepted})"),
            _ => format!("header has extra fields (header {accepted})"),
        };
        Err(r.parse_err(first.line, column, message))
    }

    pub(super) fn open(path: &Path, header: &str) -> Result<Self, SimError> {
        let file = File::open(path).map_err(io_err(path))?;
        let mut r = Self {
            path: path.to_path_buf(),
            lines: BufReader::new(file).lines(),
            line: 0,
            fields: header.split(',').count(),
        };
        let Some(first) = r.next_raw()? else {
            return Err(r.parse_err(1, 1, format!("empty file, expected the header `{header}`")));
        };
        for ((got, want), start) in first
            .text
            .split(',')
            .zip(header.split(','))
            .zip(&first.starts)
        {
            if got.trim() != want {
                return Err(r.parse_err(
                    first.line,
                    start + 1,
                    format!(
                        "header field `{}`, expected `{want}` (header `{header}`)",
                        got.trim()
                    ),
                ));
            }
        }
        if first.starts.len() != r.fields {
            return Err(r.parse_err(
                first.line,
                first.text.len() + 1,
                format!(
                    "header has {} fields, expected `{header}`",
                    first.starts.len()
                ),
            ));
        }
        Ok(r)
    }

    pub(super) fn parse_err(&self, line: usize, column: usize, message: String) -> SimError {
        SimError::LogParse {
            path: self.path.clone(),
            line,
            column,
            message,
        }
    }

    /// Next non-blank, non-comment line, split.
    pub(super) fn next_raw(&mut self) -> Result<Option<Record>, SimError> {
        for text in self.lines.by_ref() {
            self.line += 1;
            let text = text.map_err(|source| SimError::LogIo {
                path: self.path.clone(),
                source,
            })?;
            let t = text.trim_end_matches('\r');
            if t.trim().is_empty() || t.trim_start().starts_with('#') {
                continue;
            }
            let mut starts = vec![0];
            starts.extend(t.match_indices(',').map(|(i, _)| i + 1));
            return Ok(Some(Record {
                text: t.to_string(),
                starts,
                line: self.line,
            }));
        }
        Ok(None)
    }

    /// Next data record, with exactly the header's number of fields.
    pub(super) fn next(&mut self) -> Result<Option<Record>, SimError> {
        let Some(rec) = self.next_raw()? else {
            return Ok(None);
        };
        if rec.starts.len() != self.fields {
            return Err(self.parse_err(
                rec.line,
                rec.text.len() + 1,
                format!(
                    "expected {} fields, found {} (truncated or malformed line)",
                    self.fields,
                    rec.starts.len()
                ),
            ));
        }
        Ok(Some(rec))
    }

    pub(super) fn field<'a>(&self, rec: &'a Record, i: usize) -> &'a str {
        let end = rec.starts.get(i + 1).map_or(rec.text.len(), |e| e - 1);
        &rec.text[rec.starts[i]..end]
    }

    pub(super) fn f64(&self, rec: &Record, i: usize, name: &str) -> Result<f64, SimError> {
        let s = self.field(rec, i).trim();
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.parse_err(
                rec.line,
                rec.starts[i] + 1,
                format!("field `{name}`: `{s}` is not a finite number"),
            )),
        }
    }

    pub(super) fn opt_f64(
        &self,
        rec: &Record,
        i: usize,
        name: &str,
    ) -> Result<Option<f64>, SimError> {
        if self.field(rec, i).trim().is_empty() {
            Ok(None)
        } else {
            self.f64(rec, i, name).map(Some)
        }
    }

    pub(super) fn u32(&self, rec: &Record, i: usize, name: &str) -> Result<u32, SimError> {
        let s = self.field(rec, i).trim();
        s.parse::<u32>().map_err(|_| {
            self.parse_err(
                rec.line,
                rec.starts[i] + 1,
                format!("field `{name}`: `{s}` is not a non-negative integer"),
            )
        })
    }
}
