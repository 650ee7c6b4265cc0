//! A time-series output chosen by the destination's extension: Parquet for `.parquet`
//! ([`ParquetWriter`]), CSV otherwise ([`CsvWriter`]). Both are atomic and take the same
//! header and rows.

use std::path::Path;

use crate::csv::CsvWriter;
use crate::error::Result;
use crate::parquet::{is_parquet_path, ParquetWriter};

/// A CSV or Parquet time series written row by row (see the [module documentation](self)).
#[derive(Debug)]
pub enum SeriesWriter {
    /// Comma-separated text.
    Csv(CsvWriter),
    /// Columnar, one `float64` column per name (boxed: the Arrow writer is large).
    Parquet(Box<ParquetWriter>),
}

impl SeriesWriter {
    /// Creates the writer for `path`: Parquet if its extension is `parquet` (any case),
    /// CSV otherwise.
    ///
    /// # Errors
    /// As [`CsvWriter::create`] or [`ParquetWriter::create`].
    pub fn create<S: AsRef<str>>(path: &Path, header: &[S]) -> Result<Self> {
        Ok(if is_parquet_path(path) {
            Self::Parquet(Box::new(ParquetWriter::create(path, header)?))
        } else {
            Self::Csv(CsvWriter::create(path, header)?)
        })
    }

    /// Writes one row, `values[j]` under `header[j]`.
    ///
    /// # Errors
    /// As [`CsvWriter::write_row`] or [`ParquetWriter::write_row`].
    #[inline]
    pub fn write_row(&mut self, values: &[f64]) -> Result<()> {
        match self {
            Self::Csv(w) => w.write_row(values),
            Self::Parquet(w) => w.write_row(values),
        }
    }

    /// Completes the file and renames it over the destination.
    ///
    /// # Errors
    /// As [`CsvWriter::finish`] or [`ParquetWriter::finish`].
    pub fn finish(self) -> Result<()> {
        match self {
            Self::Csv(w) => w.finish(),
            Self::Parquet(w) => (*w).finish(),
        }
    }
}
