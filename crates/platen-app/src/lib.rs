//! The application layer of platen: what turns files and scenarios into the estimators'
//! inputs. The front ends (the `platen` binary, the Python module) share it, so that a
//! record reads the same way whichever of them is used; the estimators themselves
//! (`platen-ident`) read nothing and take records already in memory.
//!
//! * [`records`]: recorded CSV files through a column map, an identification manifest (kinds,
//!   hold-down pressures, column maps, a specimen's floors, scenario entries) and where each
//!   record goes, into [`platen_ident::TestRecord`]s for [`platen_ident::identify_any`].
//! * [`recorded`]: the recorded-like data of a motion scenario, made in memory (what
//!   `platen generate recorded` writes and a manifest's `scenario` entry identifies).
//! * [`system`]: the closed-loop records of a table-system identification, which of them are
//!   fitted and which held out, and the table's base, for
//!   [`platen_ident::system::identify_system`].
//!
//! ```
//! use platen_app::{read_records, RecordRequest};
//! use platen_io::columns::ColumnMap;
//! use std::path::Path;
//!
//! // A lab's earthquake record, exported with its own channel names and units.
//! let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/any-record");
//! let request = RecordRequest {
//!     files: vec![format!("{data}/eq-lab.csv").into()],
//!     pressures_mpa: vec![Some(13.8)],
//!     columns: ColumnMap::load(Path::new(&format!("{data}/columns.json")))?,
//!     ..RecordRequest::default()
//! };
//! let inputs = read_records(&request)?;
//! assert_eq!(inputs.records[0].pressure_pa(), Some(13.8e6));
//! assert_eq!(inputs.sources[0].label, "eq-lab.csv");
//! // What `platen_ident::identify_any` takes with the records: none declared `"record"`.
//! assert_eq!(inputs.declared_record(), [false]);
//! # Ok::<(), platen_app::InputError>(())
//! ```
//!
//! # Conventions
//!
//! * SI units inside; a request's hold-down pressures are in MPa, as the command line and
//!   manifests give them (`pressure_mpa`), and become Pa on the records.
//! * Errors name the file, the manifest's JSON path or the CSV line, and what was expected
//!   ([`InputError`]); a file's own error ([`platen_io::IoError`]) and a scenario's
//!   ([`platen_scenario::ScenarioError`]) stay themselves inside it.

#![warn(missing_docs)]

mod error;
pub mod recorded;
pub mod records;
pub mod system;

pub use error::{InputError, Result};
pub use recorded::recorded_of;
pub use records::{
    declared_record, files, read_records, FloorSpec, RecordInputs, RecordRequest, RecordSource,
};
pub use system::{
    fitted, read_base_system, read_system_inputs, read_system_records, SystemInputs, SystemRequest,
};
