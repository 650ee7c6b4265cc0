//! Errors of the `platen-io` crate: reading and writing files.
//!
//! Every variant carries what a user needs to fix the input: the file (shown with
//! [`Path::display`](std::path::Path::display)), the line (1-based as a text editor shows it; the CSV header is line 1),
//! the column name, the offending value and what was expected. The enum is `#[non_exhaustive]`
//! so that variants can be added without breaking callers.
//!
//! Underlying I/O errors are attached as [`std::error::Error::source`] and are *not* repeated
//! in the `Display` text, so that error-chain printers (`anyhow`'s `{:#}` / `{:?}`) show each
//! cause once.

use std::path::PathBuf;

/// Result type of this crate, defaulting to [`IoError`].
pub type Result<T, E = IoError> = std::result::Result<T, E>;

/// Everything that can go wrong while reading or writing platen's inputs and outputs.
#[non_exhaustive]
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// An operating-system I/O operation failed.
    #[error("{action} `{}` failed", path.display())]
    Io {
        /// File (or, for temporary files, the destination file) concerned.
        path: PathBuf,
        /// What was being done.
        action: IoAction,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },

    /// The folder an output is to be written in is not a folder (a file of that name is
    /// there; a missing folder is created).
    #[error(
        "cannot write `{}`: the output folder `{}` is a file, not a folder",
        path.display(),
        folder.display()
    )]
    OutputFolderMissing {
        /// The output file.
        path: PathBuf,
        /// Its folder.
        folder: PathBuf,
    },

    /// The CSV text itself is malformed (invalid UTF-8, misplaced blank line, …).
    #[error("`{}`, line {line}: malformed CSV: {message}", path.display())]
    CsvSyntax {
        /// CSV file.
        path: PathBuf,
        /// 1-based line number (header is line 1).
        line: u64,
        /// Description of the problem.
        message: String,
    },

    /// A required column is not in the header.
    #[error(
        "`{}`, line 1: missing required column `{column}` (the header has: {})",
        path.display(),
        format_names(available)
    )]
    MissingColumn {
        /// CSV file.
        path: PathBuf,
        /// Name of the missing column.
        column: String,
        /// Column names found in the header (trimmed), in file order.
        available: Vec<String>,
    },

    /// A required platen column is not in the header and no column map names it: the
    /// message says how a column map (`--columns MAP.json`, a scenario's
    /// `excitation.columns`) maps the file's own header to it.
    #[error(
        "`{}`, line 1: missing required column `{column}` (the header has: {}); a file that \
         names it otherwise or records it in other units needs a column map \
         (`--columns MAP.json`, or a scenario's `excitation.columns`), e.g. {example}",
        path.display(),
        format_names(available)
    )]
    UnmappedColumn {
        /// CSV file.
        path: PathBuf,
        /// platen's name of the missing column.
        column: String,
        /// Column names found in the header (trimmed), in file order.
        available: Vec<String>,
        /// A one-line column map that would read it, with the file's first header.
        example: String,
    },

    /// A column map reads a column from a header the file does not have.
    #[error(
        "`{}`, line 1: the column map reads `{column}` from {header}, which the file does not \
         have (the header has: {})",
        path.display(),
        format_names(available)
    )]
    MappedColumnMissing {
        /// CSV file.
        path: PathBuf,
        /// platen's name of the column.
        column: String,
        /// The header the map names, and where it names it.
        header: String,
        /// Column names found in the header (trimmed), in file order.
        available: Vec<String>,
    },

    /// A selected column name appears more than once in the header.
    #[error(
        "`{}`, line 1: column `{column}` appears more than once in the header \
         (expected each selected column exactly once)",
        path.display()
    )]
    DuplicateColumn {
        /// CSV file.
        path: PathBuf,
        /// The duplicated column name.
        column: String,
    },

    /// A cell of a selected column is not a number.
    #[error(
        "`{}`, line {line}, column `{column}`: expected a number, found `{}`",
        path.display(),
        value.escape_debug()
    )]
    NonNumeric {
        /// CSV file.
        path: PathBuf,
        /// 1-based line number (header is line 1).
        line: u64,
        /// Column name.
        column: String,
        /// The offending cell text (trimmed).
        value: String,
    },

    /// A cell parses as a number but is NaN or infinite (or overflows `f64`).
    #[error(
        "`{}`, line {line}, column `{column}`: expected a finite number, found `{value}`",
        path.display()
    )]
    NonFinite {
        /// CSV file.
        path: PathBuf,
        /// 1-based line number (header is line 1).
        line: u64,
        /// Column name.
        column: String,
        /// The offending cell text (trimmed) or value.
        value: String,
    },

    /// The file has no data rows (or not even a header row).
    #[error(
        "`{}`: no data rows (expected a header row followed by at least one row of numbers)",
        path.display()
    )]
    Empty {
        /// CSV file.
        path: PathBuf,
    },

    /// The time column `t_s` does not increase strictly.
    #[error(
        "`{}`, line {line}, column `t_s`: time must increase strictly, \
         but {value_s} s follows {previous_s} s",
        path.display()
    )]
    TimeNotIncreasing {
        /// CSV file.
        path: PathBuf,
        /// 1-based line number of the offending row.
        line: u64,
        /// Time on the previous data row, s.
        previous_s: f64,
        /// Time on the offending row, s.
        value_s: f64,
    },

    /// A row has a different number of fields than the header.
    #[error(
        "`{}`, line {line}: expected {expected} comma-separated fields (as in the header), found {found}",
        path.display()
    )]
    RaggedRow {
        /// CSV file.
        path: PathBuf,
        /// 1-based line number of the offending row.
        line: u64,
        /// Number of fields in the header.
        expected: usize,
        /// Number of fields in this row.
        found: usize,
    },

    /// A time column is not uniformly sampled: one interval (a dropped sample, a jump) is
    /// off the typical one by more than 20 %.
    #[error(
        "`{}`, line {line}, column `t_s`: expected a uniform time step of {expected_s} s, \
         found an interval of {found_s} s (intervals may differ by up to 20 %: a gap or a \
         jump in time)",
        path.display()
    )]
    NonUniform {
        /// File the time column came from.
        path: PathBuf,
        /// 1-based line of the later sample of the offending interval, assuming the header
        /// is line 1 and one sample per line (as written by this crate).
        line: u64,
        /// The typical (median) time step, s.
        expected_s: f64,
        /// The offending interval, s.
        found_s: f64,
    },

    /// A time stamp is off the sampling grid fitted over the whole record by more than 10 %
    /// of the interval (jitter, or a change of rate).
    #[error(
        "`{}`, line {line}, column `t_s`: the stamp {found_s} s is off the uniform grid \
         fitted over the record, which puts this sample at {grid_s} s (interval {interval_s} s; \
         stamps may be off it by up to 10 % of the interval)",
        path.display()
    )]
    OffGrid {
        /// File the time column came from.
        path: PathBuf,
        /// 1-based line of the sample (header on line 1, one sample per line).
        line: u64,
        /// Where the fitted grid puts the sample, s.
        grid_s: f64,
        /// Its stamp, s.
        found_s: f64,
        /// The fitted interval, s.
        interval_s: f64,
    },

    /// A record has fewer samples than an operation needs.
    #[error("`{}`: {rows} data row(s), expected at least {needed}", path.display())]
    TooShort {
        /// File the record came from.
        path: PathBuf,
        /// Number of data rows present.
        rows: usize,
        /// Number of data rows needed.
        needed: usize,
    },

    /// A table to be written has a different number of column names than columns.
    #[error(
        "`{}`: cannot write {columns} column(s) under a header of {names} name(s)",
        path.display()
    )]
    HeaderMismatch {
        /// Destination file.
        path: PathBuf,
        /// Number of header names given.
        names: usize,
        /// Number of columns given.
        columns: usize,
    },

    /// A column to be written is not as long as the first column.
    #[error(
        "`{}`, column `{column}`: expected {expected} values (as in the first column), found {found}",
        path.display()
    )]
    ColumnLengthMismatch {
        /// Destination file.
        path: PathBuf,
        /// Column name.
        column: String,
        /// Length of the first column.
        expected: usize,
        /// Length of this column.
        found: usize,
    },

    /// A column name to be written is empty, padded with whitespace or contains a
    /// character that would need CSV quoting (`,`, `"`, line break).
    #[error(
        "`{}`: invalid column name `{column}` (expected a non-empty name without commas, \
         quotes, line breaks or surrounding whitespace)",
        path.display()
    )]
    InvalidColumnName {
        /// Destination file.
        path: PathBuf,
        /// The offending column name.
        column: String,
    },

    /// A scenario file is not valid JSON or does not match the scenario format.
    #[error("`{}`: {json_path}: {message}", path.display())]
    Json {
        /// Scenario file.
        path: PathBuf,
        /// Where in the document (`model.identified.effective_mass_kg`, or `line L column C`).
        json_path: String,
        /// What is wrong and what was expected.
        message: String,
    },

    /// A JSON input (scenario, column map, manifest) is not valid JSON: a comma, bracket,
    /// brace or quote out of place.
    #[error("`{}`: JSON syntax error at line {line} column {column}: {message}", path.display())]
    JsonSyntax {
        /// The JSON file.
        path: PathBuf,
        /// 1-based line of the error, as a text editor shows it.
        line: u64,
        /// 1-based column of the error.
        column: u64,
        /// What is wrong (`trailing comma`, `expected value`, …).
        message: String,
    },

    /// A scenario field has a value that cannot be used.
    #[error("`{}`: {json_path} = {value}: expected {expected}", path.display())]
    InvalidField {
        /// Scenario file.
        path: PathBuf,
        /// JSON path of the field.
        json_path: String,
        /// The offending value, as written.
        value: String,
        /// What a valid value looks like.
        expected: String,
    },

    /// A record referenced by a scenario cannot serve it.
    #[error("`{}`: {message}", path.display())]
    Record {
        /// The record file (or the scenario, for generated records).
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// What an I/O operation that failed was doing; its `Display` is the verb phrase of the
/// message (`reading `path` failed`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IoAction {
    /// Reading an input file.
    Reading,
    /// Writing an output (through its temporary file).
    Writing,
    /// Creating the temporary file an output is written to.
    CreatingTemporary,
    /// Renaming the complete temporary file over the output.
    Renaming,
    /// Creating a folder for outputs.
    CreatingFolder,
}

impl std::fmt::Display for IoAction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            IoAction::Reading => "reading",
            IoAction::Writing => "writing",
            IoAction::CreatingTemporary => "creating a temporary file next to",
            IoAction::Renaming => "renaming the temporary file onto",
            IoAction::CreatingFolder => "creating the output folder",
        })
    }
}

impl IoError {
    /// The file the error is about (for an output, the output file).
    pub fn file(&self) -> &std::path::Path {
        match self {
            IoError::Io { path, .. }
            | IoError::OutputFolderMissing { path, .. }
            | IoError::CsvSyntax { path, .. }
            | IoError::MissingColumn { path, .. }
            | IoError::UnmappedColumn { path, .. }
            | IoError::MappedColumnMissing { path, .. }
            | IoError::DuplicateColumn { path, .. }
            | IoError::NonNumeric { path, .. }
            | IoError::NonFinite { path, .. }
            | IoError::Empty { path, .. }
            | IoError::TimeNotIncreasing { path, .. }
            | IoError::RaggedRow { path, .. }
            | IoError::NonUniform { path, .. }
            | IoError::OffGrid { path, .. }
            | IoError::TooShort { path, .. }
            | IoError::HeaderMismatch { path, .. }
            | IoError::ColumnLengthMismatch { path, .. }
            | IoError::InvalidColumnName { path, .. }
            | IoError::Json { path, .. }
            | IoError::JsonSyntax { path, .. }
            | IoError::InvalidField { path, .. }
            | IoError::Record { path, .. } => path,
        }
    }

    /// The 1-based line of the file the error is about, where it is known (CSV rows, a JSON
    /// syntax error).
    pub fn line(&self) -> Option<u64> {
        match self {
            IoError::CsvSyntax { line, .. }
            | IoError::NonNumeric { line, .. }
            | IoError::NonFinite { line, .. }
            | IoError::TimeNotIncreasing { line, .. }
            | IoError::RaggedRow { line, .. }
            | IoError::NonUniform { line, .. }
            | IoError::OffGrid { line, .. } => Some(*line),
            IoError::JsonSyntax { line, .. } => Some(*line),
            _ => None,
        }
    }

    /// The field the error is about, where there is one: a CSV column's name, or the JSON
    /// path of a scenario field (for a JSON syntax or type error, the path followed by the
    /// line and column, or the line alone).
    pub fn field(&self) -> Option<&str> {
        match self {
            IoError::MissingColumn { column, .. }
            | IoError::UnmappedColumn { column, .. }
            | IoError::MappedColumnMissing { column, .. }
            | IoError::DuplicateColumn { column, .. }
            | IoError::NonNumeric { column, .. }
            | IoError::NonFinite { column, .. }
            | IoError::ColumnLengthMismatch { column, .. }
            | IoError::InvalidColumnName { column, .. } => Some(column),
            IoError::Json { json_path, .. } | IoError::InvalidField { json_path, .. } => {
                Some(json_path)
            }
            _ => None,
        }
    }
    /// Whether this error is a failure to write an output (as opposed to a bad or missing
    /// input): front ends give it its own exit code.
    pub fn is_output_failure(&self) -> bool {
        matches!(self, IoError::Io { action, .. } if *action != IoAction::Reading)
            || matches!(self, IoError::OutputFolderMissing { .. })
    }
}

/// Formats header names as a comma-separated list of back-quoted names.
fn format_names(names: &[String]) -> String {
    if names.is_empty() {
        return "no columns".to_owned();
    }
    let mut out = String::new();
    for (i, name) in names.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        out.push('`');
        out.push_str(name);
        out.push('`');
    }
    out
}
