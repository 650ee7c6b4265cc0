//! Columnar output: a time series as an Apache Parquet file, the CSV's columns under the
//! same names, one `float64` (`DOUBLE`, required) column each, one row per sample.
//!
//! Written with the `parquet` crate's Arrow writer: uncompressed (a run's floats barely
//! compress, and no codec keeps the build small), plain encoding (no dictionary), row groups
//! of up to 1 048 576 rows; the Arrow schema is stored in the file's metadata, so pandas
//! (`pd.read_parquet`), polars and Arrow read the columns back as `float64`. The file is
//! written atomically ([`AtomicFile`]) like every platen output: nothing is left at the
//! destination unless [`ParquetWriter::finish`] succeeds. Same rows, same bytes.
//!
//! ```
//! use platen_io::parquet::{read_parquet, write_parquet_atomic};
//!
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("run.parquet");
//! write_parquet_atomic(&path, &["t_s", "u_m"], &[&[0.0, 0.5], &[1e-3, -0.0]]).unwrap();
//! let (names, columns) = read_parquet(&path).unwrap();
//! assert_eq!(names, ["t_s", "u_m"]);
//! assert_eq!(columns[1][1].to_bits(), (-0.0f64).to_bits());
//! ```

use std::fs::File;
use std::io;
use std::path::Path;
use std::sync::Arc;

use arrow_array::{Array, ArrayRef, Float64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::arrow::ArrowWriter;
use parquet::basic::Compression;
use parquet::file::properties::WriterProperties;

use crate::atomic::{write_error, AtomicFile};
use crate::error::{IoAction, IoError, Result};

/// Rows gathered before they are handed to the Arrow writer as one record batch.
const BATCH_ROWS: usize = 1 << 16;

/// Whether `path` names a Parquet file (extension `parquet`, any case).
pub fn is_parquet_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("parquet"))
}

/// A time series written row by row to a Parquet file, atomically: the schema at creation,
/// one [`ParquetWriter::write_row`] per sample, then [`ParquetWriter::finish`]. Dropped
/// unfinished, it removes its temporary file.
pub struct ParquetWriter {
    writer: ArrowWriter<AtomicFile>,
    schema: Arc<Schema>,
    path: std::path::PathBuf,
    header: Vec<String>,
    /// The rows of the batch being gathered, by column.
    columns: Vec<Vec<f64>>,
    rows: u64,
}

impl std::fmt::Debug for ParquetWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParquetWriter")
            .field("path", &self.path)
            .field("header", &self.header)
            .field("rows", &self.rows)
            .finish_non_exhaustive()
    }
}

impl ParquetWriter {
    /// Creates the temporary file next to `path` and the writer of the columns `header`.
    ///
    /// # Errors
    /// As [`AtomicFile::create`]; [`IoError::Io`] if the writer cannot be set up.
    pub fn create<S: AsRef<str>>(path: &Path, header: &[S]) -> Result<Self> {
        let header: Vec<String> = header.iter().map(|n| n.as_ref().to_owned()).collect();
        let fields: Vec<Field> = header
            .iter()
            .map(|name| Field::new(name, DataType::Float64, false))
            .collect();
        let schema = Arc::new(Schema::new(fields));
        let props = WriterProperties::builder()
            .set_compression(Compression::UNCOMPRESSED)
            .set_dictionary_enabled(false)
            .build();
        let file = AtomicFile::create(path)?;
        let writer = ArrowWriter::try_new(file, Arc::clone(&schema), Some(props))
            .map_err(|e| parquet_error(path, e))?;
        Ok(Self {
            writer,
            schema,
            path: path.to_path_buf(),
            columns: vec![Vec::with_capacity(BATCH_ROWS); header.len()],
            header,
            rows: 0,
        })
    }

    /// Writes one row, `values[j]` under `header[j]`.
    ///
    /// # Errors
    /// [`NonFinite`](IoError::NonFinite) (naming the line the value would have had in the
    /// CSV: the row number + 1) as the CSV writer does, or [`IoError::Io`] for a failed write.
    pub fn write_row(&mut self, values: &[f64]) -> Result<()> {
        if let Some(j) = values.iter().position(|v| !v.is_finite()) {
            return Err(IoError::NonFinite {
                path: self.path.clone(),
                line: self.rows + 2,
                column: self.header[j].clone(),
                value: values[j].to_string(),
            });
        }
        for (column, &value) in self.columns.iter_mut().zip(values) {
            column.push(value);
        }
        self.rows += 1;
        if self.columns.first().is_some_and(|c| c.len() >= BATCH_ROWS) {
            self.write_batch()?;
        }
        Ok(())
    }

    /// Hands the gathered rows to the Arrow writer as one record batch.
    fn write_batch(&mut self) -> Result<()> {
        let arrays: Vec<ArrayRef> = self
            .columns
            .iter_mut()
            .map(|c| {
                let values = std::mem::replace(c, Vec::with_capacity(BATCH_ROWS));
                Arc::new(Float64Array::from(values)) as ArrayRef
            })
            .collect();
        let batch = RecordBatch::try_new(Arc::clone(&self.schema), arrays)
            .map_err(|e| write_error(&self.path, io::Error::other(e)))?;
        self.writer
            .write(&batch)
            .map_err(|e| parquet_error(&self.path, e))
    }

    /// Writes the last rows and the footer, then syncs the file and renames it over the
    /// destination.
    ///
    /// # Errors
    /// [`IoError::Io`] for a failed write; as [`AtomicFile::commit`].
    pub fn finish(mut self) -> Result<()> {
        if self.columns.first().is_some_and(|c| !c.is_empty()) {
            self.write_batch()?;
        }
        let file = self
            .writer
            .into_inner()
            .map_err(|e| parquet_error(&self.path, e))?;
        file.commit()
    }
}

/// Writes columns to a Parquet file atomically: `header[j]` names `columns[j]`; names, lengths
/// and values are checked as for [`write_csv_atomic`](crate::csv::write_csv_atomic).
///
/// # Errors
/// [`HeaderMismatch`](IoError::HeaderMismatch), [`InvalidColumnName`](IoError::InvalidColumnName),
/// [`ColumnLengthMismatch`](IoError::ColumnLengthMismatch),
/// [`NonFinite`](IoError::NonFinite), or as [`ParquetWriter`]; nothing is left at `path`.
pub fn write_parquet_atomic(path: &Path, header: &[&str], columns: &[&[f64]]) -> Result<()> {
    write_parquet_atomic_inner(path, header, columns)
}

/// Writes `columns` under `header` to `path` atomically: Parquet for a `.parquet` path
/// ([`is_parquet_path`]), CSV otherwise ([`crate::csv::write_csv_atomic`]).
///
/// # Errors
/// As the writer chosen.
pub fn write_columns_atomic(path: &Path, header: &[&str], columns: &[&[f64]]) -> Result<()> {
    if is_parquet_path(path) {
        write_parquet_atomic(path, header, columns)
    } else {
        crate::csv::write_csv_atomic(path, header, columns)
    }
}

fn write_parquet_atomic_inner(path: &Path, header: &[&str], columns: &[&[f64]]) -> Result<()> {
    let rows = crate::csv::checked_rows(path, header, columns)?;
    let mut writer = ParquetWriter::create(path, header)?;
    crate::csv::for_each_row(columns, rows, |row| writer.write_row(row))?;
    writer.finish()
}

/// Reads every column of a Parquet file of `float64` columns (as [`ParquetWriter`] writes):
/// `(names, columns)` in the file's order.
///
/// # Errors
/// [`IoError::Io`] ([`IoAction::Reading`]) if the file cannot be opened or is not such a
/// Parquet file (the message says why).
pub fn read_parquet(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>)> {
    let read_error = |source| IoError::Io {
        path: path.to_path_buf(),
        action: IoAction::Reading,
        source,
    };
    let invalid = |message: String| read_error(io::Error::new(io::ErrorKind::InvalidData, message));
    let file = File::open(path).map_err(read_error)?;
    let builder =
        ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| invalid(e.to_string()))?;
    let names: Vec<String> = builder
        .schema()
        .fields()
        .iter()
        .map(|f| f.name().clone())
        .collect();
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    let reader = builder.build().map_err(|e| invalid(e.to_string()))?;
    for batch in reader {
        let batch = batch.map_err(|e| invalid(e.to_string()))?;
        for ((column, array), name) in columns.iter_mut().zip(batch.columns()).zip(&names) {
            let values = array
                .as_any()
                .downcast_ref::<Float64Array>()
                .ok_or_else(|| invalid(format!("column `{name}` is not float64")))?;
            if values.null_count() > 0 {
                return Err(invalid(format!("column `{name}` has missing values")));
            }
            column.extend_from_slice(values.values());
        }
    }
    Ok((names, columns))
}

/// A failure of the Parquet writer, as an I/O error of writing `path`.
fn parquet_error(path: &Path, error: parquet::errors::ParquetError) -> IoError {
    match error {
        parquet::errors::ParquetError::External(e) => match e.downcast::<io::Error>() {
            Ok(e) => write_error(path, *e),
            Err(e) => write_error(path, io::Error::other(e)),
        },
        other => write_error(path, io::Error::other(other)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atomic::temp_files_in;
    use std::fs;

    #[test]
    fn columns_round_trip_bit_for_bit_across_batches() {
        let n = BATCH_ROWS * 2 + 17;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / 1024.0).collect();
        let awkward = [
            0.0,
            -0.0,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            0.1 + 0.2,
            -1.0 / 3.0,
        ];
        let u: Vec<f64> = (0..n).map(|i| awkward[i % awkward.len()]).collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.parquet");
        write_parquet_atomic(&path, &["t_s", "u_m"], &[&t, &u]).unwrap();
        let (names, columns) = read_parquet(&path).unwrap();
        assert_eq!(names, ["t_s", "u_m"]);
        for (back, orig) in columns.iter().zip([&t, &u]) {
            assert_eq!(back.len(), orig.len());
            assert!(back
                .iter()
                .zip(orig)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        // Same rows, same bytes.
        let first = fs::read(&path).unwrap();
        write_parquet_atomic(&path, &["t_s", "u_m"], &[&t, &u]).unwrap();
        assert_eq!(fs::read(&path).unwrap(), first);
        assert!(temp_files_in(dir.path()).is_empty());
    }

    #[test]
    fn a_non_finite_value_leaves_no_file_and_the_previous_one_intact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.parquet");
        fs::write(&path, "old").unwrap();
        let error = write_parquet_atomic(&path, &["t_s", "u_m"], &[&[0.0, 1.0], &[0.0, f64::NAN]])
            .unwrap_err();
        assert!(
            matches!(error, IoError::NonFinite { line: 3, ref column, .. } if column == "u_m"),
            "{error:?}"
        );
        assert!(error.to_string().contains("run.parquet"));
        assert_eq!(fs::read_to_string(&path).unwrap(), "old");
        assert!(temp_files_in(dir.path()).is_empty());

        let blocked = path.join("run.parquet");
        let error = write_parquet_atomic(&blocked, &["t_s"], &[&[0.0]]).unwrap_err();
        assert!(
            matches!(error, IoError::OutputFolderMissing { .. }),
            "{error:?}"
        );
        let missing = dir.path().join("no_such_dir").join("run.parquet");
        write_parquet_atomic(&missing, &["t_s"], &[&[0.0]]).unwrap();
        assert!(missing.is_file());
    }

    #[test]
    fn reading_a_file_that_is_not_parquet_names_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fake.parquet");
        fs::write(&path, "t_s\n0\n").unwrap();
        let message = read_parquet(&path).unwrap_err().to_string();
        assert!(message.contains("fake.parquet"), "{message}");
        assert!(is_parquet_path(&path));
        assert!(is_parquet_path(Path::new("X.PARQUET")));
        assert!(!is_parquet_path(Path::new("x.csv")));
    }
}
