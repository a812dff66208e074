//! Error types of the readers and writers.

use std::fmt;
use std::path::PathBuf;

/// Which kind of file an error was found in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// A TetGen `.node` file (vertices).
    Node,
    /// A TetGen `.ele` file (tetrahedra).
    Ele,
    /// A Gmsh `.msh` file.
    Msh,
}

impl fmt::Display for FileKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FileKind::Node => ".node",
            FileKind::Ele => ".ele",
            FileKind::Msh => ".msh",
        })
    }
}

/// Why a mesh file could not be read.
///
/// Every variant except [`ReadError::Io`] and [`ReadError::Binary`] (a byte offset) names
/// the file kind and a 1-based line number
/// (for errors at the end of the input, the number of the last line, or 0 for empty input).
#[derive(Debug)]
pub enum ReadError {
    /// The file could not be opened or read.
    Io {
        /// Which file kind was being read.
        kind: FileKind,
        /// The path given.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A field is not a valid number (or not a finite one).
    BadNumber {
        /// File kind.
        kind: FileKind,
        /// 1-based line number.
        line: usize,
        /// What the field means (e.g. "x coordinate").
        field: &'static str,
        /// The offending text (truncated to 32 characters).
        text: String,
    },
    /// A line has the wrong number of fields.
    FieldCount {
        /// File kind.
        kind: FileKind,
        /// 1-based line number.
        line: usize,
        /// What the line is (e.g. "node row").
        what: &'static str,
        /// Number of fields expected.
        expected: usize,
        /// Number of fields found.
        found: usize,
    },
    /// A header value is not supported (dimension other than 3, nodes per tetrahedron
    /// other than 4 or 10, binary or non-4.1 `.msh`, …).
    Unsupported {
        /// File kind.
        kind: FileKind,
        /// 1-based line number.
        line: usize,
        /// What is not supported, and what is.
        what: String,
    },
    /// A row's own index is not the next one in sequence (TetGen numbers rows
    /// consecutively from 0 or 1).
    BadRowNumber {
        /// File kind.
        kind: FileKind,
        /// 1-based line number.
        line: usize,
        /// The number expected.
        expected: u64,
        /// The number found.
        found: u64,
    },
    /// A vertex index or node tag refers to no vertex.
    IndexOutOfRange {
        /// File kind.
        kind: FileKind,
        /// 1-based line number.
        line: usize,
        /// The offending index or tag, as written in the file.
        index: u64,
        /// Number of vertices read.
        vertex_count: usize,
    },
    /// A Gmsh node tag is defined twice.
    DuplicateTag {
        /// File kind.
        kind: FileKind,
        /// 1-based line number.
        line: usize,
        /// The repeated tag.
        tag: u64,
    },
    /// The input ended before all the rows the header announced.
    MissingRows {
        /// File kind.
        kind: FileKind,
        /// Last line number of the input (0 if it is empty).
        line: usize,
        /// What was being read (e.g. "node rows").
        what: &'static str,
        /// Rows announced.
        expected: u64,
        /// Rows found.
        found: u64,
    },
    /// There are more data rows than the header announced.
    ExtraRows {
        /// File kind.
        kind: FileKind,
        /// 1-based line number of the first extra row.
        line: usize,
    },
    /// Counts in a Gmsh section disagree (header total against the sum of its blocks).
    CountMismatch {
        /// File kind.
        kind: FileKind,
        /// 1-based line number of the header row holding the total.
        line: usize,
        /// What was counted.
        what: &'static str,
        /// The header's total.
        expected: u64,
        /// The sum of the blocks.
        found: u64,
    },
    /// Something is wrong inside a binary `.msh` file (which has no useful line numbers).
    Binary {
        /// File kind.
        kind: FileKind,
        /// Byte offset of the problem from the start of the file.
        offset: usize,
        /// What is wrong.
        what: String,
    },
    /// A required header or section is missing, or a section is not closed.
    MissingSection {
        /// File kind.
        kind: FileKind,
        /// Last line number examined.
        line: usize,
        /// The header or section name.
        section: &'static str,
    },
}

impl ReadError {
    /// The kind of file the error was found in.
    pub fn kind(&self) -> FileKind {
        match self {
            ReadError::Io { kind, .. }
            | ReadError::BadNumber { kind, .. }
            | ReadError::FieldCount { kind, .. }
            | ReadError::Unsupported { kind, .. }
            | ReadError::BadRowNumber { kind, .. }
            | ReadError::IndexOutOfRange { kind, .. }
            | ReadError::DuplicateTag { kind, .. }
            | ReadError::MissingRows { kind, .. }
            | ReadError::ExtraRows { kind, .. }
            | ReadError::CountMismatch { kind, .. }
            | ReadError::Binary { kind, .. }
            | ReadError::MissingSection { kind, .. } => *kind,
        }
    }

    /// The 1-based line number of the error; `None` for [`ReadError::Io`] and
    /// [`ReadError::Binary`].
    pub fn line(&self) -> Option<usize> {
        match self {
            ReadError::Io { .. } | ReadError::Binary { .. } => None,
            ReadError::BadNumber { line, .. }
            | ReadError::FieldCount { line, .. }
            | ReadError::Unsupported { line, .. }
            | ReadError::BadRowNumber { line, .. }
            | ReadError::IndexOutOfRange { line, .. }
            | ReadError::DuplicateTag { line, .. }
            | ReadError::MissingRows { line, .. }
            | ReadError::ExtraRows { line, .. }
            | ReadError::CountMismatch { line, .. }
            | ReadError::MissingSection { line, .. } => Some(*line),
        }
    }
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReadError::Io { kind, path, source } => {
                write!(f, "{kind} file {}: {source}", path.display())
            }
            ReadError::BadNumber {
                kind,
                line,
                field,
                text,
            } => write!(
                f,
                "{kind} line {line}: {field} is not a valid number: `{text}`"
            ),
            ReadError::FieldCount {
                kind,
                line,
                what,
                expected,
                found,
            } => write!(
                f,
                "{kind} line {line}: {what} has {found} fields, expected {expected}"
            ),
            ReadError::Unsupported { kind, line, what } => {
                write!(f, "{kind} line {line}: unsupported: {what}")
            }
            ReadError::BadRowNumber {
                kind,
                line,
                expected,
                found,
            } => write!(
                f,
                "{kind} line {line}: row number {found}, expected {expected}"
            ),
            ReadError::IndexOutOfRange {
                kind,
                line,
                index,
                vertex_count,
            } => write!(
                f,
                "{kind} line {line}: vertex {index} does not exist ({vertex_count} vertices)"
            ),
            ReadError::DuplicateTag { kind, line, tag } => {
                write!(f, "{kind} line {line}: node tag {tag} defined twice")
            }
            ReadError::MissingRows {
                kind,
                line,
                what,
                expected,
                found,
            } => write!(
                f,
                "{kind} line {line}: input ends after {found} of {expected} {what}"
            ),
            ReadError::ExtraRows { kind, line } => {
                write!(f, "{kind} line {line}: more rows than the header announced")
            }
            ReadError::CountMismatch {
                kind,
                line,
                what,
                expected,
                found,
            } => write!(
                f,
                "{kind} line {line}: header announces {expected} {what}, the blocks hold {found}"
            ),
            ReadError::Binary { kind, offset, what } => {
                write!(f, "{kind} (binary) byte {offset}: {what}")
            }
            ReadError::MissingSection {
                kind,
                line,
                section,
            } => write!(f, "{kind} line {line}: missing {section}"),
        }
    }
}

impl std::error::Error for ReadError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ReadError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Why a frame could not be written.
#[derive(Debug)]
pub enum WriteError {
    /// A triangle or tetrahedron refers to a position that does not exist.
    IndexOutOfRange {
        /// The offending index.
        index: u32,
        /// Number of positions given.
        len: usize,
    },
    /// The file could not be written.
    Io(std::io::Error),
}

impl fmt::Display for WriteError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WriteError::IndexOutOfRange { index, len } => {
                write!(f, "index {index} out of range ({len} positions)")
            }
            WriteError::Io(e) => write!(f, "write failed: {e}"),
        }
    }
}

impl std::error::Error for WriteError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            WriteError::Io(e) => Some(e),
            WriteError::IndexOutOfRange { .. } => None,
        }
    }
}

impl From<std::io::Error> for WriteError {
    fn from(e: std::io::Error) -> Self {
        WriteError::Io(e)
    }
}
