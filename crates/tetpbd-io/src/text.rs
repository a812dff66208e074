//! Line and field scanning shared by the text readers.

use crate::error::{FileKind, ReadError};

/// Longest piece of offending text copied into an error, characters.
const MAX_TEXT: usize = 32;

/// Non-blank lines of a text file, split into whitespace-separated fields, with their
/// 1-based line numbers.
pub(crate) struct Rows<'a> {
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    kind: FileKind,
    /// When true, everything from a `#` to the end of the line is a comment.
    hash_comments: bool,
    last_line: usize,
    peeked: Option<(usize, Vec<&'a str>)>,
}

impl<'a> Rows<'a> {
    /// Rows of `text`; `hash_comments` strips `#` comments (TetGen).
    pub(crate) fn new(text: &'a str, kind: FileKind, hash_comments: bool) -> Self {
        Rows {
            lines: text.lines().enumerate(),
            kind,
            hash_comments,
            last_line: 0,
            peeked: None,
        }
    }

    /// The file kind the rows come from.
    pub(crate) fn kind(&self) -> FileKind {
        self.kind
    }

    /// Number of the last line read (0 before the first).
    pub(crate) fn last_line(&self) -> usize {
        self.last_line
    }

    /// The next row with at least one field, and its line number.
    pub(crate) fn next_row(&mut self) -> Option<(usize, Vec<&'a str>)> {
        if let Some(row) = self.peeked.take() {
            return Some(row);
        }
        for (i, line) in self.lines.by_ref() {
            self.last_line = i + 1;
            let content = if self.hash_comments {
                line.split('#').next().unwrap_or("")
            } else {
                line
            };
            let fields: Vec<&str> = content.split_whitespace().collect();
            if !fields.is_empty() {
                return Some((i + 1, fields));
            }
        }
        None
    }

    /// The next row without consuming it.
    pub(crate) fn peek_row(&mut self) -> Option<&(usize, Vec<&'a str>)> {
        if self.peeked.is_none() {
            self.peeked = self.next_row();
        }
        self.peeked.as_ref()
    }

    /// A non-negative integer field.
    pub(crate) fn uint(
        &self,
        line: usize,
        field: &'static str,
        text: &str,
    ) -> Result<u64, ReadError> {
        text.parse::<u64>()
            .map_err(|_| self.bad_number(line, field, text))
    }

    /// A signed integer field.
    pub(crate) fn int(
        &self,
        line: usize,
        field: &'static str,
        text: &str,
    ) -> Result<i64, ReadError> {
        text.parse::<i64>()
            .map_err(|_| self.bad_number(line, field, text))
    }

    /// A finite floating-point field, read as `f64` and narrowed to `f32`.
    pub(crate) fn coord(
        &self,
        line: usize,
        field: &'static str,
        text: &str,
    ) -> Result<f32, ReadError> {
        match text.parse::<f64>() {
            Ok(v) if (v as f32).is_finite() => Ok(v as f32),
            _ => Err(self.bad_number(line, field, text)),
        }
    }

    /// A [`ReadError::BadNumber`] at `line`.
    pub(crate) fn bad_number(&self, line: usize, field: &'static str, text: &str) -> ReadError {
        ReadError::BadNumber {
            kind: self.kind,
            line,
            field,
            text: text.chars().take(MAX_TEXT).collect(),
        }
    }

    /// A [`ReadError::FieldCount`] at `line`.
    pub(crate) fn field_count(
        &self,
        line: usize,
        what: &'static str,
        expected: usize,
        found: usize,
    ) -> ReadError {
        ReadError::FieldCount {
            kind: self.kind,
            line,
            what,
            expected,
            found,
        }
    }

    /// A [`ReadError::MissingRows`] at the last line read.
    pub(crate) fn missing_rows(&self, what: &'static str, expected: u64, found: u64) -> ReadError {
        ReadError::MissingRows {
            kind: self.kind,
            line: self.last_line,
            what,
            expected,
            found,
        }
    }
}

/// A capacity hint that cannot exceed what `text` could possibly hold when each item takes
/// at least `min_bytes` bytes, so a header announcing absurd counts allocates nothing big.
pub(crate) fn capacity_hint(announced: u64, text: &str, min_bytes: usize) -> usize {
    usize::try_from(announced)
        .unwrap_or(usize::MAX)
        .min(text.len() / min_bytes.max(1))
}
