//! Files in and out of platen: time-series CSV by column name, a lab's column maps and units,
//! PEER NGA ground-motion records, JSON inputs with the JSON path of every error, and atomic
//! output. No physics.
//!
//! ```
//! use platen_io::csv::{read_table, write_csv_atomic};
//!
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("force.csv");
//! write_csv_atomic(&path, &["t_s", "force_n"], &[&[0.0, 0.5], &[0.0, 1e3]]).unwrap();
//! let table = read_table(&path, &["t_s", "force_n"], &[]).unwrap();
//! assert_eq!(table.column("force_n"), Some(&[0.0, 1e3][..]));
//! ```
//!
//! # Invariant
//!
//! A column map ([`columns::ColumnMap`]) is always valid: it has no public fields, and its
//! constructors check every column, unit and delay before it exists.
//!
//! # Conventions
//!
//! SI units inside; the unit is in every column name (`t_s`, `u_m`, `v_m_s`, `a_m_s2`,
//! `force_n`). Errors ([`IoError`]) name the file and the line (CSV, PEER, 1-based as an editor
//! shows them, the header on line 1) or the JSON path, the value, and what was expected. Every
//! output is written to a temporary file next to its destination and renamed over it when
//! complete ([`atomic`]), so a failed write never leaves a partial file nor touches a previous
//! one; numbers are written as the shortest text that reads back to the same `f64`.

pub mod atomic;
pub mod columns;
pub mod csv;
pub mod error;
pub mod json;
pub mod number;
pub mod parquet;
pub mod peer;
pub mod series;

pub use atomic::{write_bytes_atomic, AtomicFile};
pub use error::{IoAction, IoError, Result};

/// Standard gravity, m/s² (exact by definition): the unit `g` of a column map and of PEER
/// acceleration records.
pub const STANDARD_GRAVITY_M_S2: f64 = 9.806_65;
