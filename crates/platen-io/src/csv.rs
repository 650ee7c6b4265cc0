//! Time-series CSV reading and atomic writing.
//!
//! # Conventions
//!
//! * **Format.** Comma separated, UTF-8, one header row followed by one row per sample. Fields may
//!   be quoted as usual in CSV. Line endings `\n` or `\r\n`. A UTF-8 byte-order mark before the
//!   first header name is tolerated. Comment lines are **not** supported. Blank lines at the end of
//!   the file are ignored; a blank line anywhere else is an error (so that line numbers in error
//!   messages are always those a text editor shows).
//! * **Columns are selected by name**, never by position: extra columns are allowed and ignored,
//!   and column order does not matter. Header names are trimmed of surrounding whitespace.
//! * **SI units, unit in the name**: `t_s` (time, s), `u_m` (displacement, m), `v_m_s`
//!   (velocity, m/s), `a_m_s2` (acceleration, m/s²), `force_n` (force, N); simulated output adds
//!   `inertial_force_n`, `elastic_force_n`, `dissipative_force_n`.
//! * **Numbers.** Every selected cell must parse as a finite `f64` after trimming whitespace
//!   (`1`, `-2.5`, `1e-3`, `.5`, …). `nan`, `inf`, `Infinity` and values that overflow `f64` are
//!   rejected. Whenever `t_s` is selected it must increase strictly.
//! * **Line numbers** in errors are 1-based as a text editor shows them; the header is line 1.
//! * **Writing** prints numbers with Rust's `{}` formatting of `f64` (`0.001`, `-2.5`, `3`), or
//!   with `{:e}` (`1e-300`, `1.7976931348623157e308`) when the magnitude is below 1e-5 or at
//!   least 1e16, where `{}` would spell out hundreds of zeros. Both give the shortest text that
//!   parses back to the identical value, so a write → read round trip is bit-exact and output is
//!   deterministic. The text is produced by [`crate::number`] (Ryū's digits, the same bytes as
//!   `format!`, several times faster) and gathered a megabyte at a time. Files are replaced atomically: written to a temporary file in the same
//!   directory, synced, then renamed over the destination.

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use csv::{ReaderBuilder, StringRecord, Terminator};

use crate::atomic::{write_error, AtomicFile};
use crate::error::{IoAction, IoError, Result};
use crate::number::{format_number, NumberBuffer};

/// Name of the time column, s. Whenever it is selected it must increase strictly.
pub const TIME_COLUMN: &str = "t_s";

/// Capacity of the read and write buffers, bytes.
const BUFFER_BYTES: usize = 1 << 16;

/// Longest cell text quoted verbatim in an error message, characters.
const MAX_QUOTED_CHARS: usize = 80;

/// Numeric columns read from a CSV file, selected by name.
///
/// All columns have the same length, [`Table::len`]. Columns appear in the order they were
/// requested (required first, then the optional columns that were present).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    path: PathBuf,
    names: Vec<String>,
    columns: Vec<Vec<f64>>,
    rows: usize,
}

impl Table {
    /// The values of column `name`, or `None` if that column was not read (an optional column
    /// absent from the file, a column not requested, or one already taken with
    /// [`Table::take_column`]).
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.position(name).map(|i| self.columns[i].as_slice())
    }

    /// Removes column `name` from the table and returns its values without copying them.
    pub fn take_column(&mut self, name: &str) -> Option<Vec<f64>> {
        let i = self.position(name)?;
        self.names.remove(i);
        Some(self.columns.remove(i))
    }

    /// Whether column `name` was read.
    pub fn has_column(&self, name: &str) -> bool {
        self.position(name).is_some()
    }

    /// Names of the columns held, in the order they were requested.
    pub fn column_names(&self) -> impl Iterator<Item = &str> + '_ {
        self.names.iter().map(String::as_str)
    }

    /// Number of data rows (samples).
    pub fn len(&self) -> usize {
        self.rows
    }

    /// Whether the table has no data rows. Never true for a table returned by [`read_table`].
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// The file the table was read from, for error messages.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames column `from` to `to` and transforms its values with `f` (a unit conversion,
    /// an offset); nothing happens if there is no column `from`.
    pub(crate) fn rename_with(&mut self, from: &str, to: &str, f: impl FnOnce(&mut [f64])) {
        if let Some(i) = self.position(from) {
            to.clone_into(&mut self.names[i]);
            f(&mut self.columns[i]);
        }
    }

    fn position(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }
}

/// Reads the columns `required` and, where present, `optional` from the CSV file at `path`.
///
/// See the [module documentation](self) for the format. Errors:
/// [`Io`](IoError::Io) if the file cannot be read,
/// [`CsvSyntax`](IoError::CsvSyntax) for malformed CSV (invalid UTF-8, a blank line before
/// the header or inside the data), [`MissingColumn`](IoError::MissingColumn) if a required
/// column is not in the header, [`DuplicateColumn`](IoError::DuplicateColumn) if a
/// selected name appears twice in the header, [`RaggedRow`](IoError::RaggedRow) if a row's
/// field count differs from the header's, [`NonNumeric`](IoError::NonNumeric) /
/// [`NonFinite`](IoError::NonFinite) for a bad cell in a selected column,
/// [`TimeNotIncreasing`](IoError::TimeNotIncreasing) if `t_s` is selected and does not
/// increase strictly, and [`Empty`](IoError::Empty) if there is no data row.
///
/// A name listed twice (or in both lists) is read once.
pub fn read_table(path: &Path, required: &[&str], optional: &[&str]) -> Result<Table> {
    let read_error = |source| IoError::Io {
        path: path.to_path_buf(),
        action: IoAction::Reading,
        source,
    };
    let mut file = File::open(path).map_err(read_error)?;
    let unterminated_end = unterminated_end(&mut file).map_err(read_error)?;
    // Only `\n` ends a record, so that every record consumes its own line end and the csv
    // crate's line counts stay exact; the `\r` of a `\r\n` line end is trimmed with the field.
    let mut reader = ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .terminator(Terminator::Any(b'\n'))
        .buffer_capacity(BUFFER_BYTES)
        .from_reader(file);
    let mut record = StringRecord::new();

    let header = read_header(path, &mut reader, &mut record, unterminated_end)?;
    let selection = select_columns(path, &header, required, optional)?;
    let time_slot = selection.iter().position(|(_, name)| name == TIME_COLUMN);

    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); selection.len()];
    let mut rows = 0usize;
    let mut previous_t = f64::NEG_INFINITY;
    // First blank line seen; an error unless only blank lines follow.
    let mut blank_line: Option<u64> = None;

    loop {
        let more = reader
            .read_record(&mut record)
            .map_err(|e| csv_error(path, e, reader.position().line()))?;
        if !more {
            break;
        }
        let (line, skipped) = locate(&record, reader.position(), unterminated_end);
        if skipped > 0 {
            // The csv crate silently skips empty lines.
            blank_line.get_or_insert(line - skipped);
        }
        if is_blank(&record) {
            blank_line.get_or_insert(line);
            continue;
        }
        if let Some(blank) = blank_line {
            return Err(syntax(
                path,
                blank,
                "blank line inside the data (only trailing blank lines are allowed)",
            ));
        }
        push_row(path, line, &record, header.len(), &selection, &mut columns)?;
        if let Some(slot) = time_slot {
            let t = columns[slot][rows];
            if t <= previous_t {
                return Err(IoError::TimeNotIncreasing {
                    path: path.to_path_buf(),
                    line,
                    previous_s: previous_t,
                    value_s: t,
                });
            }
            previous_t = t;
        }
        rows += 1;
    }

    if rows == 0 {
        return Err(IoError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok(Table {
        path: path.to_path_buf(),
        names: selection.into_iter().map(|(_, name)| name).collect(),
        columns,
        rows,
    })
}

/// Reads the header row (line 1): names trimmed, a UTF-8 byte-order mark dropped.
fn read_header(
    path: &Path,
    reader: &mut csv::Reader<File>,
    record: &mut StringRecord,
    unterminated_end: Option<u64>,
) -> Result<Vec<String>> {
    if !reader
        .read_record(record)
        .map_err(|e| csv_error(path, e, 1))?
    {
        return Err(IoError::Empty {
            path: path.to_path_buf(),
        });
    }
    let (_, skipped) = locate(record, reader.position(), unterminated_end);
    if skipped > 0 {
        return Err(syntax(
            path,
            1,
            "expected the header row on line 1, found a blank line",
        ));
    }
    Ok(record
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let name = if i == 0 {
                name.trim_start_matches('\u{feff}')
            } else {
                name
            };
            name.trim().to_owned()
        })
        .collect())
}

/// Appends the selected cells of the data row `record` (on `line`) to `columns`.
fn push_row(
    path: &Path,
    line: u64,
    record: &StringRecord,
    fields: usize,
    selection: &[(usize, String)],
    columns: &mut [Vec<f64>],
) -> Result<()> {
    if record.len() != fields {
        return Err(IoError::RaggedRow {
            path: path.to_path_buf(),
            line,
            expected: fields,
            found: record.len(),
        });
    }
    for ((index, name), column) in selection.iter().zip(columns.iter_mut()) {
        let cell = record.get(*index).unwrap_or_default();
        column.push(parse_cell(path, line, name, cell)?);
    }
    Ok(())
}

/// Resolves the requested names to header indices: `(index in the header, name)`.
fn select_columns(
    path: &Path,
    header: &[String],
    required: &[&str],
    optional: &[&str],
) -> Result<Vec<(usize, String)>> {
    let mut selection: Vec<(usize, String)> = Vec::with_capacity(required.len() + optional.len());
    let requests = required
        .iter()
        .map(|name| (*name, true))
        .chain(optional.iter().map(|name| (*name, false)));
    for (name, is_required) in requests {
        if selection.iter().any(|(_, selected)| selected == name) {
            continue;
        }
        let mut matches = header
            .iter()
            .enumerate()
            .filter(|(_, h)| h.as_str() == name);
        match (matches.next(), matches.next()) {
            (Some((index, _)), None) => selection.push((index, name.to_owned())),
            (Some(_), Some(_)) => {
                return Err(IoError::DuplicateColumn {
                    path: path.to_path_buf(),
                    column: name.to_owned(),
                })
            }
            (None, _) if is_required => {
                return Err(IoError::MissingColumn {
                    path: path.to_path_buf(),
                    column: name.to_owned(),
                    available: header.to_vec(),
                })
            }
            (None, _) => {}
        }
    }
    Ok(selection)
}

/// Parses one cell of a selected column as a finite `f64`.
#[inline]
fn parse_cell(path: &Path, line: u64, column: &str, cell: &str) -> Result<f64> {
    let text = cell.trim();
    match text.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(value),
        Ok(_) => Err(IoError::NonFinite {
            path: path.to_path_buf(),
            line,
            column: column.to_owned(),
            value: quote_cell(text),
        }),
        Err(_) => Err(IoError::NonNumeric {
            path: path.to_path_buf(),
            line,
            column: column.to_owned(),
            value: quote_cell(text),
        }),
    }
}

/// Cell text for an error message, shortened if very long.
fn quote_cell(text: &str) -> String {
    match text.char_indices().nth(MAX_QUOTED_CHARS) {
        Some((end, _)) => format!("{}…", &text[..end]),
        None => text.to_owned(),
    }
}

/// If the regular file `file` does not end with `\n`, its length: the byte offset at which its
/// last record ends without a line end. `None` for files ending with `\n`, empty files and
/// files that cannot seek (pipes). Leaves `file` positioned at its start.
fn unterminated_end(file: &mut File) -> io::Result<Option<u64>> {
    let metadata = file.metadata()?;
    if !metadata.is_file() || metadata.len() == 0 {
        return Ok(None);
    }
    file.seek(SeekFrom::End(-1))?;
    let mut last = [0u8];
    file.read_exact(&mut last)?;
    file.rewind()?;
    Ok((last[0] != b'\n').then_some(metadata.len()))
}

/// Where the text of `record` starts: `(1-based line, empty lines skipped before it)`.
///
/// The csv crate sets a record's position *before* skipping empty lines, and counts every `\n`
/// it consumes: the empty lines skipped, those inside quoted fields, and the record's own line
/// end (absent only on an unterminated last line). `end` is the reader's position after the
/// record; `unterminated_end` as returned by [`unterminated_end`].
fn locate(record: &StringRecord, end: &csv::Position, unterminated_end: Option<u64>) -> (u64, u64) {
    let start = record.position().map_or(end.line(), csv::Position::line);
    let span = end.line().saturating_sub(start);
    if span == 0 {
        return (start, 0);
    }
    let terminated = u64::from(unterminated_end != Some(end.byte()));
    let quoted = if span > terminated {
        record.iter().map(|f| f.matches('\n').count() as u64).sum()
    } else {
        0
    };
    let skipped = span.saturating_sub(quoted + terminated);
    (start + skipped, skipped)
}

/// Whether a record is a line holding nothing but whitespace.
fn is_blank(record: &StringRecord) -> bool {
    record.len() == 1 && record[0].trim().is_empty()
}

fn syntax(path: &Path, line: u64, message: &str) -> IoError {
    IoError::CsvSyntax {
        path: path.to_path_buf(),
        line,
        message: message.to_owned(),
    }
}

/// Converts an error of the `csv` crate; `line` is used when the error carries no position.
fn csv_error(path: &Path, error: csv::Error, line: u64) -> IoError {
    let position_line = error.position().map(csv::Position::line);
    match error.into_kind() {
        csv::ErrorKind::Io(source) => IoError::Io {
            path: path.to_path_buf(),
            action: IoAction::Reading,
            source,
        },
        csv::ErrorKind::Utf8 { pos, err } => IoError::CsvSyntax {
            path: path.to_path_buf(),
            line: pos.map_or(line, |p| p.line()),
            message: format!("field {} is not valid UTF-8 text", err.field() + 1),
        },
        // Other kinds (unequal lengths, seek, serde) cannot occur when reading flexible
        // `StringRecord`s; report them anyway.
        other => IoError::CsvSyntax {
            path: path.to_path_buf(),
            line: position_line.unwrap_or(line),
            message: format!("{other:?}"),
        },
    }
}

/// Writes a time-series CSV file atomically: `header[j]` names `columns[j]`.
///
/// Numbers are printed as the shortest text that parses back to the same `f64` (`{}`
/// formatting, or `{:e}` for magnitudes below 1e-5 or from 1e16 on); lines end with `\n`. All columns must have the same length
/// ([`ColumnLengthMismatch`](IoError::ColumnLengthMismatch)), there must be one name per
/// column ([`HeaderMismatch`](IoError::HeaderMismatch)), names must be non-empty and need no
/// CSV quoting ([`InvalidColumnName`](IoError::InvalidColumnName)), and every value must
/// be finite ([`NonFinite`](IoError::NonFinite), naming the line the value would have had),
/// so that every file written can be read back by [`read_table`].
///
/// The data go to a temporary file in the same directory ([`AtomicFile`]), which is flushed,
/// synced and renamed over `path`. On any error the temporary file is removed and an existing
/// file at `path` is left untouched.
pub fn write_csv_atomic(path: &Path, header: &[&str], columns: &[&[f64]]) -> Result<()> {
    let rows = checked_rows(path, header, columns)?;
    let mut writer = CsvWriter::create(path, header)?;
    for_each_row(columns, rows, |row| writer.write_row(row))?;
    writer.finish()
}

/// Checks columns about to be written to `path` (one valid name per column, all of one
/// length) and returns their length: the checks of [`write_csv_atomic`], shared by the
/// Parquet writer.
///
/// # Errors
/// [`HeaderMismatch`](IoError::HeaderMismatch), [`InvalidColumnName`](IoError::InvalidColumnName),
/// [`ColumnLengthMismatch`](IoError::ColumnLengthMismatch), in that order.
pub(crate) fn checked_rows(path: &Path, header: &[&str], columns: &[&[f64]]) -> Result<usize> {
    if header.len() != columns.len() {
        return Err(IoError::HeaderMismatch {
            path: path.to_path_buf(),
            names: header.len(),
            columns: columns.len(),
        });
    }
    if let Some(name) = header.iter().find(|n| !valid_column_name(n)) {
        return Err(IoError::InvalidColumnName {
            path: path.to_path_buf(),
            column: (*name).to_owned(),
        });
    }
    let rows = columns.first().map_or(0, |c| c.len());
    for (name, column) in header.iter().zip(columns) {
        if column.len() != rows {
            return Err(IoError::ColumnLengthMismatch {
                path: path.to_path_buf(),
                column: (*name).to_owned(),
                expected: rows,
                found: column.len(),
            });
        }
    }
    Ok(rows)
}

/// Calls `write` with each of the first `rows` rows of `columns`, in order, in one buffer.
pub(crate) fn for_each_row(
    columns: &[&[f64]],
    rows: usize,
    mut write: impl FnMut(&[f64]) -> Result<()>,
) -> Result<()> {
    let mut row = vec![0.0; columns.len()];
    for i in 0..rows {
        for (value, column) in row.iter_mut().zip(columns) {
            *value = column[i];
        }
        write(&row)?;
    }
    Ok(())
}

/// A time-series CSV written row by row as a run produces it, atomically (see
/// [`AtomicFile`]): the header at creation, one [`CsvWriter::write_row`] per sample, then
/// [`CsvWriter::finish`]. Numbers are formatted by [`write_number`]'s formatter, so the bytes
/// are those [`write_csv_atomic`] writes for the same columns. Dropped unfinished, it removes
/// its temporary file.
///
/// The rows' text is made on threads of their own: [`CsvWriter::write_row`] checks the
/// values and copies them into a block of [`BLOCK_ROWS`] rows; full blocks are formatted by
/// two threads side by side and written in order by a third. A run that produces its samples
/// on one core so pays for its output only what the other core cannot hide (see
/// `benches/writer.rs` and `docs/performance.md`).
#[derive(Debug)]
pub struct CsvWriter {
    /// The destination, for the messages.
    path: PathBuf,
    /// The column names, kept for the messages of [`CsvWriter::write_row`].
    header: Vec<String>,
    rows: u64,
    /// Values of the rows not yet handed to the formatter, row after row.
    block: Vec<f64>,
    /// The thread that formats and writes (`None` once finished or failed).
    worker: Option<Worker>,
}

/// Rows [`CsvWriter`] gathers before handing them to its formatting thread.
pub const BLOCK_ROWS: usize = 4096;

/// Blocks that may wait for a formatting thread (a run faster than its formatting waits
/// there, with this much memory held).
const BLOCKS_IN_FLIGHT: usize = 4;

/// Blocks written between two [`AtomicFile::sync_ahead`] calls (about 10 MB of text): the
/// disk syncs while the run goes on, and the commit's sync waits only for the last ones.
const SYNC_AHEAD_BLOCKS: u64 = 16;

/// Threads that format blocks side by side (their texts are written in the rows' order): two,
/// so that on a 2-core machine the formatting uses the core the run leaves idle while it waits.
const FORMATTERS: usize = 2;

/// [`CsvWriter`]'s threads: [`FORMATTERS`] that turn numbered blocks of values into text, and
/// one that writes the texts to the file in the blocks' order and ends with the file (to
/// commit) or the first write error. Emptied blocks come back for reuse.
#[derive(Debug)]
struct Worker {
    blocks: std::sync::mpsc::SyncSender<(u64, Vec<f64>)>,
    emptied: std::sync::mpsc::Receiver<Vec<f64>>,
    formatters: Vec<std::thread::JoinHandle<()>>,
    writer: std::thread::JoinHandle<Result<AtomicFile>>,
    /// The next block's number.
    next: u64,
}

impl Worker {
    /// Starts the threads on `file` for rows of `width` values.
    fn start(mut file: AtomicFile, width: usize) -> Self {
        use std::sync::mpsc::{channel, sync_channel};
        use std::sync::{Arc, Mutex};
        let (blocks, incoming) = sync_channel::<(u64, Vec<f64>)>(BLOCKS_IN_FLIGHT);
        let incoming = Arc::new(Mutex::new(incoming));
        let (give_back, emptied) = channel::<Vec<f64>>();
        let (texts, formatted) = channel::<(u64, Vec<u8>)>();
        // Written texts come back to be filled again (fresh buffers would cost page faults).
        let (written, reusable) = channel::<Vec<u8>>();
        let reusable = Arc::new(Mutex::new(reusable));
        let formatters = (0..FORMATTERS)
            .map(|_| {
                let (incoming, give_back, texts, reusable) = (
                    Arc::clone(&incoming),
                    give_back.clone(),
                    texts.clone(),
                    Arc::clone(&reusable),
                );
                std::thread::spawn(move || {
                    let mut number = NumberBuffer::new();
                    loop {
                        // The lock is held only to take the next block.
                        let next = incoming.lock().map(|queue| queue.recv());
                        let Ok(Ok((seq, mut block))) = next else {
                            return;
                        };
                        let mut text = reusable
                            .lock()
                            .ok()
                            .and_then(|r| r.try_recv().ok())
                            .unwrap_or_else(|| Vec::with_capacity(block.len() * 24));
                        for row in block.chunks_exact(width.max(1)) {
                            for (j, &value) in row.iter().enumerate() {
                                if j > 0 {
                                    text.push(b',');
                                }
                                format_number(&mut number, &mut text, value);
                            }
                            text.push(b'\n');
                        }
                        block.clear();
                        // The writer may be gone (dropped unfinished): nothing to give back to.
                        let _ = give_back.send(block);
                        if texts.send((seq, text)).is_err() {
                            return;
                        }
                    }
                })
            })
            .collect();
        drop(texts);
        let writer = std::thread::spawn(move || {
            let mut waiting = std::collections::BTreeMap::new();
            let mut due = 0u64;
            for (seq, text) in formatted {
                waiting.insert(seq, text);
                while let Some(mut text) = waiting.remove(&due) {
                    write_text(&mut file, &mut text)?;
                    let _ = written.send(text);
                    due += 1;
                    if due % SYNC_AHEAD_BLOCKS == 0 {
                        file.sync_ahead();
                    }
                }
            }
            Ok(file)
        });
        Self {
            blocks,
            emptied,
            formatters,
            writer,
            next: 0,
        }
    }

    /// Queues `block` for formatting; `false` when the threads have stopped (a write error).
    fn send(&mut self, block: Vec<f64>) -> bool {
        let seq = self.next;
        self.next += 1;
        self.blocks.send((seq, block)).is_ok()
    }

    /// Waits for the threads to end (the queue closed) and returns what the writing thread
    /// ended with.
    fn join(self, path: &Path) -> Result<AtomicFile> {
        drop(self.blocks);
        let panicked = || {
            Err(write_error(
                path,
                io::Error::other("a CSV formatting thread panicked"),
            ))
        };
        for formatter in self.formatters {
            if formatter.join().is_err() {
                return panicked();
            }
        }
        self.writer.join().unwrap_or_else(|_| panicked())
    }
}

/// Hands the gathered `text` to `file` (a write this large bypasses its buffer).
fn write_text(file: &mut AtomicFile, text: &mut Vec<u8>) -> Result<()> {
    let written = file.writer().write_all(text);
    text.clear();
    written.map_err(|source| write_error(file.path(), source))
}

impl CsvWriter {
    /// Creates the temporary file next to `path`, writes the header and starts the
    /// formatting thread.
    ///
    /// # Errors
    /// [`InvalidColumnName`](IoError::InvalidColumnName) for a name that is empty or needs
    /// CSV quoting; [`IoError::Io`] if the temporary file cannot be created or written.
    pub fn create<S: AsRef<str>>(path: &Path, header: &[S]) -> Result<Self> {
        let header: Vec<String> = header.iter().map(|n| n.as_ref().to_owned()).collect();
        if let Some(name) = header.iter().find(|n| !valid_column_name(n)) {
            return Err(IoError::InvalidColumnName {
                path: path.to_path_buf(),
                column: (*name).to_owned(),
            });
        }
        let mut file = AtomicFile::create(path)?;
        let out = file.writer();
        out.write_all(header.join(",").as_bytes())
            .and_then(|()| out.write_all(b"\n"))
            .map_err(|source| write_error(path, source))?;
        let width = header.len();
        Ok(Self {
            path: path.to_path_buf(),
            header,
            rows: 0,
            block: Vec::with_capacity(BLOCK_ROWS * width),
            worker: Some(Worker::start(file, width)),
        })
    }

    /// Writes one row, `values[j]` under `header[j]`. Rows are gathered in blocks and
    /// formatted and written by the writer's own thread.
    ///
    /// # Errors
    /// [`NonFinite`](IoError::NonFinite) naming the line the value would have had, or
    /// [`IoError::Io`] for a failed write (of rows gathered before this one); after an error
    /// the writer takes no more rows.
    pub fn write_row(&mut self, values: &[f64]) -> Result<()> {
        if let Some(j) = values.iter().position(|v| !v.is_finite()) {
            return Err(IoError::NonFinite {
                path: self.path.clone(),
                line: self.rows + 2,
                column: self.header[j].to_owned(),
                value: values[j].to_string(),
            });
        }
        debug_assert_eq!(values.len(), self.header.len());
        self.block.extend_from_slice(values);
        self.rows += 1;
        if self.block.len() >= BLOCK_ROWS * self.header.len() {
            self.hand_over()?;
        }
        Ok(())
    }

    /// Hands the gathered block to the formatting thread and takes an emptied one back (or a
    /// new one while the first blocks are in flight).
    fn hand_over(&mut self) -> Result<()> {
        let Some(worker) = self.worker.as_ref() else {
            return Err(write_error(
                &self.path,
                io::Error::other("the output was not written: an earlier write failed"),
            ));
        };
        let next = worker
            .emptied
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(self.block.capacity()));
        let full = std::mem::replace(&mut self.block, next);
        if !self.worker.as_mut().expect("checked above").send(full) {
            // The thread stopped at a write error: report it.
            let worker = self.worker.take().expect("checked above");
            return match worker.join(&self.path) {
                Err(error) => Err(error),
                Ok(_) => Err(write_error(
                    &self.path,
                    io::Error::other("the CSV formatting thread stopped"),
                )),
            };
        }
        Ok(())
    }

    /// Formats and writes the last rows, flushes and syncs the file and renames it over the
    /// destination.
    ///
    /// # Errors
    /// A write error met on the way, or as [`AtomicFile::commit`].
    pub fn finish(mut self) -> Result<()> {
        if !self.block.is_empty() {
            self.hand_over()?;
        }
        let worker = self.worker.take().ok_or_else(|| {
            write_error(
                &self.path,
                io::Error::other("the output was not written: an earlier write failed"),
            )
        })?;
        worker.join(&self.path)?.commit()
    }
}

impl Drop for CsvWriter {
    /// Unfinished: stops the thread, whose file is then dropped and its temporary removed.
    fn drop(&mut self) {
        if let Some(worker) = self.worker.take() {
            let _ = worker.join(&self.path);
        }
    }
}

/// Whether `name` can be written as a header without CSV quoting and read back as itself.
fn valid_column_name(name: &str) -> bool {
    let needs_quoting = name.contains([',', '"', '\n', '\r']);
    !(name.is_empty() || needs_quoting || name.trim() != name)
}

/// Writes a finite `value` as the shortest text that parses back to it (see the module docs):
/// `{}` formatting, or `{:e}` when the magnitude is below 1e-5 or at least 1e16. Every platen
/// CSV writer formats numbers with it, so streamed and in-memory outputs have the same bytes.
/// The text is [`NumberBuffer::format`]'s (Ryū's digits in this format).
#[inline]
pub fn write_number<W: Write>(out: &mut W, value: f64) -> io::Result<()> {
    out.write_all(NumberBuffer::new().format(value).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atomic::temp_files_in;
    use crate::atomic::write_bytes_atomic;
    use std::fs;
    use tempfile::TempDir;

    /// Writes `contents` to `name` in a fresh temporary directory.
    fn file_with(name: &str, contents: &[u8]) -> (TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        fs::write(&path, contents).unwrap();
        (dir, path)
    }

    /// Reads `contents` (as file `name`) expecting an error; returns it with its message.
    fn error_for(
        name: &str,
        contents: &str,
        required: &[&str],
        optional: &[&str],
    ) -> (IoError, String) {
        let (_dir, path) = file_with(name, contents.as_bytes());
        let error = read_table(&path, required, optional).unwrap_err();
        let message = error.to_string();
        assert!(message.contains(name), "no file name in: {message}");
        (error, message)
    }

    #[test]
    fn selected_columns_are_read_by_name_whatever_their_order_and_extras_are_ignored() {
        let (_dir, path) = file_with(
            "motion.csv",
            b"note,u_m,t_s,v_m_s\nx,0.5,0,1\ny,0.25,0.001,-2e-3\n",
        );
        let table = read_table(&path, &["t_s", "u_m"], &["v_m_s", "a_m_s2"]).unwrap();
        assert_eq!(table.len(), 2);
        assert!(!table.is_empty());
        assert_eq!(table.path(), path);
        assert_eq!(table.column("t_s").unwrap(), &[0.0, 0.001]);
        assert_eq!(table.column("u_m").unwrap(), &[0.5, 0.25]);
        assert_eq!(table.column("v_m_s").unwrap(), &[1.0, -2e-3]);
        assert_eq!(table.column("a_m_s2"), None);
        assert_eq!(table.column("note"), None);
        assert_eq!(
            table.column_names().collect::<Vec<_>>(),
            ["t_s", "u_m", "v_m_s"]
        );
    }

    #[test]
    fn a_taken_column_is_moved_out_of_the_table() {
        let (_dir, path) = file_with("take.csv", b"t_s,force_n\n0,1\n1,2\n");
        let mut table = read_table(&path, &["t_s", "force_n"], &[]).unwrap();
        assert_eq!(table.take_column("force_n").unwrap(), vec![1.0, 2.0]);
        assert!(!table.has_column("force_n"));
        assert!(table.has_column("t_s"));
        assert_eq!(table.len(), 2);
    }

    #[test]
    fn bom_whitespace_crlf_quotes_and_trailing_blank_lines_are_tolerated() {
        let (_dir, path) = file_with(
            "tolerant.csv",
            "\u{feff} t_s , force_n \r\n 0 ,\" 1.5 \"\r\n1,\"-2\"\r\n\r\n   \n\n".as_bytes(),
        );
        let table = read_table(&path, &["t_s", "force_n"], &[]).unwrap();
        assert_eq!(table.column("t_s").unwrap(), &[0.0, 1.0]);
        assert_eq!(table.column("force_n").unwrap(), &[1.5, -2.0]);
    }

    #[test]
    fn line_numbers_are_exact_with_crlf_line_ends_and_quoted_line_breaks() {
        let (error, message) = error_for(
            "crlf.csv",
            "t_s,u_m\r\n0,\"0\"\r\n1,x\r\n",
            &["t_s", "u_m"],
            &[],
        );
        assert!(
            matches!(error, IoError::NonNumeric { line: 3, .. }),
            "{error:?}"
        );
        assert!(message.contains("line 3"), "{message}");

        let (error, _) = error_for(
            "quoted.csv",
            "t_s,note,u_m\n0,\"two\nlines\",0\n1,,x",
            &["t_s", "u_m"],
            &[],
        );
        assert!(
            matches!(error, IoError::NonNumeric { line: 4, .. }),
            "{error:?}"
        );
    }

    #[test]
    fn a_missing_file_is_an_io_error_that_says_reading_and_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("absent.csv");
        let error = read_table(&path, &["t_s"], &[]).unwrap_err();
        let message = error.to_string();
        assert!(
            matches!(error, IoError::Io { action: IoAction::Reading, ref source, .. }
                if source.kind() == io::ErrorKind::NotFound),
            "{error:?}"
        );
        assert!(
            message.contains("absent.csv") && message.contains("reading"),
            "{message}"
        );
    }

    #[test]
    fn invalid_utf8_is_a_syntax_error_with_its_line() {
        let (_dir, path) = file_with("bytes.csv", b"t_s,u_m\n0,0\n1,\xff\xfe\n");
        let error = read_table(&path, &["t_s", "u_m"], &[]).unwrap_err();
        let message = error.to_string();
        assert!(
            matches!(error, IoError::CsvSyntax { line: 3, .. }),
            "{error:?}"
        );
        assert!(
            message.contains("bytes.csv") && message.contains("line 3"),
            "{message}"
        );
    }

    #[test]
    fn a_blank_line_inside_the_data_is_a_syntax_error_with_its_line() {
        let (error, message) = error_for("gap.csv", "t_s,u_m\n0,0\n\n1,0\n", &["t_s"], &[]);
        assert!(
            matches!(error, IoError::CsvSyntax { line: 3, .. }),
            "{error:?}"
        );
        assert!(message.contains("line 3"), "{message}");

        let (error, _) = error_for("gap2.csv", "t_s,u_m\n0,0\n  \n1,0\n", &["t_s"], &[]);
        assert!(
            matches!(error, IoError::CsvSyntax { line: 3, .. }),
            "{error:?}"
        );

        let (error, _) = error_for("gap_last.csv", "t_s,u_m\n0,0\n\n1,0", &["t_s"], &[]);
        assert!(
            matches!(error, IoError::CsvSyntax { line: 3, .. }),
            "{error:?}"
        );

        let (error, _) = error_for("gap_crlf.csv", "t_s\r\n0\r\n\r\n1\r\n", &["t_s"], &[]);
        assert!(
            matches!(error, IoError::CsvSyntax { line: 3, .. }),
            "{error:?}"
        );

        let (error, _) = error_for("gap3.csv", "\nt_s,u_m\n0,0\n", &["t_s"], &[]);
        assert!(
            matches!(error, IoError::CsvSyntax { line: 1, .. }),
            "{error:?}"
        );
    }

    #[test]
    fn a_missing_required_column_is_reported_with_the_available_names() {
        let (error, message) =
            error_for("force.csv", "time, force\n0,1\n", &["t_s", "force_n"], &[]);
        match &error {
            IoError::MissingColumn {
                column, available, ..
            } => {
                assert_eq!(column, "t_s");
                assert_eq!(available, &["time", "force"]);
            }
            other => panic!("unexpected {other:?}"),
        }
        assert!(
            message.contains("`t_s`") && message.contains("`time`") && message.contains("`force`"),
            "{message}"
        );
    }

    #[test]
    fn a_missing_optional_column_is_no_error() {
        let (_dir, path) = file_with("opt.csv", b"t_s\n0\n");
        let table = read_table(&path, &["t_s"], &["v_m_s"]).unwrap();
        assert_eq!(table.column("v_m_s"), None);
    }

    #[test]
    fn a_selected_column_appearing_twice_is_a_duplicate_column_error() {
        let (error, message) = error_for("dup.csv", "t_s,u_m,u_m\n0,1,2\n", &["t_s"], &["u_m"]);
        assert!(
            matches!(error, IoError::DuplicateColumn { ref column, .. } if column == "u_m"),
            "{error:?}"
        );
        assert!(
            message.contains("`u_m`") && message.contains("line 1"),
            "{message}"
        );
    }

    #[test]
    fn an_unselected_column_appearing_twice_is_ignored() {
        let (_dir, path) = file_with("dup_ok.csv", b"x,t_s,x\na,0,b\n");
        assert_eq!(read_table(&path, &["t_s"], &[]).unwrap().len(), 1);
    }

    #[test]
    fn a_non_numeric_cell_is_reported_with_line_column_and_value() {
        let (error, message) = error_for(
            "motion.csv",
            "t_s,u_m,comment\n0,0,a\n0.1,1.2.3,b\n",
            &["t_s", "u_m"],
            &[],
        );
        assert!(
            matches!(error, IoError::NonNumeric { line: 3, ref column, ref value, .. }
                if column == "u_m" && value == "1.2.3"),
            "{error:?}"
        );
        assert!(
            message.contains("line 3") && message.contains("`u_m`") && message.contains("1.2.3"),
            "{message}"
        );

        let (error, _) = error_for("empty_cell.csv", "t_s,u_m\n0, \n", &["t_s", "u_m"], &[]);
        assert!(
            matches!(error, IoError::NonNumeric { line: 2, .. }),
            "{error:?}"
        );
    }

    #[test]
    fn nan_and_infinite_cells_are_non_finite_errors() {
        for text in [
            "nan",
            "NaN",
            "inf",
            "-inf",
            "+inf",
            "Infinity",
            "-infinity",
            "1e400",
        ] {
            let contents = format!("t_s,force_n\n0,1\n1,{text}\n");
            let (error, message) = error_for("force.csv", &contents, &["t_s", "force_n"], &[]);
            assert!(
                matches!(error, IoError::NonFinite { line: 3, ref column, ref value, .. }
                    if column == "force_n" && value == text),
                "{text}: {error:?}"
            );
            assert!(
                message.contains("line 3")
                    && message.contains("`force_n`")
                    && message.contains(text),
                "{message}"
            );
        }
    }

    #[test]
    fn a_file_without_data_rows_is_empty() {
        for contents in ["", "t_s,u_m\n", "t_s,u_m\n\n \n"] {
            let (error, message) = error_for("nothing.csv", contents, &["t_s"], &[]);
            assert!(matches!(error, IoError::Empty { .. }), "{error:?}");
            assert!(message.contains("no data rows"), "{message}");
        }
    }

    #[test]
    fn time_that_does_not_increase_strictly_is_reported_with_both_values() {
        let (error, message) = error_for(
            "time.csv",
            "t_s,u_m\n0,0\n0.5,0\n0.25,0\n",
            &["u_m"],
            &["t_s"],
        );
        assert!(
            matches!(error, IoError::TimeNotIncreasing { line: 4, previous_s, value_s, .. }
                if previous_s == 0.5 && value_s == 0.25),
            "{error:?}"
        );
        assert!(
            message.contains("line 4")
                && message.contains("`t_s`")
                && message.contains("0.5")
                && message.contains("0.25"),
            "{message}"
        );

        let (error, _) = error_for("repeat.csv", "t_s\n0\n1\n1\n", &["t_s"], &[]);
        assert!(
            matches!(error, IoError::TimeNotIncreasing { line: 4, .. }),
            "{error:?}"
        );
    }

    #[test]
    fn rows_with_too_many_or_too_few_fields_are_ragged() {
        let (error, message) =
            error_for("ragged.csv", "t_s,u_m\n0,0\n1,0,9\n", &["t_s", "u_m"], &[]);
        assert!(
            matches!(
                error,
                IoError::RaggedRow {
                    line: 3,
                    expected: 2,
                    found: 3,
                    ..
                }
            ),
            "{error:?}"
        );
        assert!(message.contains("line 3"), "{message}");

        let (error, _) = error_for("short.csv", "t_s,u_m,x\n0,0\n", &["t_s"], &[]);
        assert!(
            matches!(
                error,
                IoError::RaggedRow {
                    line: 2,
                    expected: 3,
                    found: 2,
                    ..
                }
            ),
            "{error:?}"
        );
    }

    #[test]
    fn write_then_read_is_bit_exact_for_awkward_values() {
        let awkward = [
            1e-300,
            -0.0,
            0.1 + 0.2,
            // More digits than an f64 holds (a literal would trip clippy).
            "123456789.123456789".parse().unwrap(),
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            -1.0 / 3.0,
            0.0,
        ];
        let t: Vec<f64> = (0..awkward.len()).map(|i| i as f64 / 1024.0).collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("round_trip.csv");
        write_csv_atomic(&path, &["t_s", "force_n"], &[&t, &awkward]).unwrap();
        let table = read_table(&path, &["force_n", "t_s"], &[]).unwrap();
        let back = table.column("force_n").unwrap();
        assert_eq!(back.len(), awkward.len());
        for (a, b) in awkward.iter().zip(back) {
            assert_eq!(a.to_bits(), b.to_bits(), "{a:e} came back as {b:e}");
        }
        assert_eq!(table.column("t_s").unwrap(), t.as_slice());
        let text = fs::read_to_string(&path).unwrap();
        assert!(
            text.starts_with(
                "t_s,force_n\n0,1e-300\n0.0009765625,-0\n0.001953125,0.30000000000000004\n"
            ),
            "{text}"
        );
        assert!(text.contains(",1.7976931348623157e308\n"), "{text}");
        assert!(temp_files_in(dir.path()).is_empty());
    }

    #[test]
    fn writing_replaces_an_existing_file_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.json");
        fs::write(&path, "old").unwrap();
        write_bytes_atomic(&path, b"{\"new\": true}\n").unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "{\"new\": true}\n");
        write_csv_atomic(&dir.path().join("out.csv"), &["t_s"], &[&[0.0]]).unwrap();
        assert!(temp_files_in(dir.path()).is_empty());
    }

    #[test]
    fn a_write_into_a_missing_folder_creates_it_and_a_file_in_the_way_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let existing = dir.path().join("keep.csv");
        fs::write(&existing, "t_s\n0\n").unwrap();
        // A missing folder (and its parents) is created, as --plot creates its folder.
        let target = dir
            .path()
            .join("no_such_dir")
            .join("deeper")
            .join("out.csv");
        write_csv_atomic(&target, &["t_s"], &[&[1.0]]).unwrap();
        assert_eq!(fs::read_to_string(&target).unwrap(), "t_s\n1\n");
        // A file where the folder should be: refused, naming both, nothing written.
        let target = existing.join("out.csv");
        let error = write_csv_atomic(&target, &["t_s"], &[&[1.0]]).unwrap_err();
        let message = error.to_string();
        assert!(
            matches!(error, IoError::OutputFolderMissing { .. }),
            "{error:?}"
        );
        assert!(error.is_output_failure());
        assert!(
            message.contains("out.csv")
                && message.contains("the output folder")
                && message.contains("keep.csv")
                && message.contains("not a folder"),
            "{message}"
        );
        assert!(!target.exists());
        assert_eq!(fs::read_to_string(&existing).unwrap(), "t_s\n0\n");
        assert!(write_bytes_atomic(&target, b"x").is_err());
        assert!(temp_files_in(dir.path()).is_empty());
    }

    #[test]
    fn a_write_that_fails_midway_leaves_the_previous_file_intact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("result.csv");
        fs::write(&path, "t_s,u_m\n0,1\n").unwrap();
        let error = write_csv_atomic(
            &path,
            &["t_s", "u_m"],
            &[&[0.0, 1.0, 2.0], &[0.0, 1.0, f64::NAN]],
        )
        .unwrap_err();
        let message = error.to_string();
        assert!(
            matches!(error, IoError::NonFinite { line: 4, ref column, .. } if column == "u_m"),
            "{error:?}"
        );
        assert!(
            message.contains("result.csv")
                && message.contains("line 4")
                && message.contains("`u_m`"),
            "{message}"
        );
        assert_eq!(fs::read_to_string(&path).unwrap(), "t_s,u_m\n0,1\n");
        assert!(temp_files_in(dir.path()).is_empty());
    }

    #[test]
    fn writing_inconsistent_columns_is_refused_before_touching_the_disk() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.csv");

        let error = write_csv_atomic(&path, &["t_s", "u_m"], &[&[0.0]]).unwrap_err();
        assert!(
            matches!(
                error,
                IoError::HeaderMismatch {
                    names: 2,
                    columns: 1,
                    ..
                }
            ),
            "{error:?}"
        );
        assert!(error.to_string().contains("bad.csv"));

        let error = write_csv_atomic(&path, &["t_s", "u_m"], &[&[0.0, 1.0], &[0.0]]).unwrap_err();
        assert!(
            matches!(error, IoError::ColumnLengthMismatch { ref column, expected: 2, found: 1, .. }
                if column == "u_m"),
            "{error:?}"
        );
        assert!(error.to_string().contains("`u_m`"));

        for name in ["", "a,b", "q\"", " t_s", "x\ny"] {
            let error = write_csv_atomic(&path, &[name], &[&[0.0]]).unwrap_err();
            assert!(
                matches!(error, IoError::InvalidColumnName { .. }),
                "{name:?}: {error:?}"
            );
        }
        assert!(fs::read_dir(dir.path()).unwrap().next().is_none());
    }
}
