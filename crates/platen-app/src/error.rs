//! The one error of reading: [`InputError`], and the [`Result`] alias.

use std::path::{Path, PathBuf};

use platen_ident::IdentError;
use platen_io::IoError;
use platen_scenario::ScenarioError;

/// The result of reading inputs.
pub type Result<T, E = InputError> = std::result::Result<T, E>;

/// Why records could not be read. The messages name the file, the manifest's JSON path or
/// the CSV line, and what was expected.
#[non_exhaustive]
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// A pressure count that fits neither one for all files nor one per file.
    #[error(
        "pressure_mpa has {given} values for {files} files: give one value for all files, or one \
         per file in order"
    )]
    PressureCount {
        /// Pressures given.
        given: usize,
        /// Files given.
        files: usize,
    },
    /// A request's hold-down pressure out of range.
    #[error("pressure_mpa = {message}")]
    Pressure {
        /// The value and what was expected.
        message: String,
    },
    /// Nothing to read.
    #[error("no test files: give recorded CSV files, or a manifest that lists them")]
    NoFiles,
    /// No closed-loop record to identify a table system from.
    #[error("identify --system needs at least one recorded CSV file")]
    NoSystemFiles,
    /// The manifest cannot be read or is not a manifest.
    #[error(
        "reading the identification manifest (expected {{\"tests\": [{{\"file\": PATH, \"kind\": \
         \"sine\"|\"triangle\"|\"record\", \"pressure_mpa\": P, \"name\": NAME, \"columns\": MAP, \
         \"floors\": [{{\"column\": NAME, \"unit\": UNIT, \"mass_kg\": M}}]}}], \"columns\": MAP, \
         \"floors\": FLOORS}}, with only `file` required)"
    )]
    Manifest {
        /// The file's error (with its path and JSON path).
        #[source]
        source: IoError,
    },
    /// A manifest's `columns` object that is not a column map.
    #[error("`{}`: {json_path} = {value}: expected {expected}", manifest.display())]
    ManifestColumns {
        /// The manifest.
        manifest: PathBuf,
        /// Where in it.
        json_path: String,
        /// The rejected value.
        value: String,
        /// What was expected.
        expected: String,
    },
    /// A manifest entry's hold-down pressure out of range.
    #[error("`{}`, at `tests[{entry}].pressure_mpa`: {message}", manifest.display())]
    ManifestPressure {
        /// The manifest.
        manifest: PathBuf,
        /// The entry's index.
        entry: usize,
        /// The value and what was expected.
        message: String,
    },
    /// A manifest entry whose keys do not go together.
    #[error("`{}`, at `tests[{entry}]`: {problem}", manifest.display())]
    ManifestEntry {
        /// The manifest.
        manifest: PathBuf,
        /// The entry's index.
        entry: usize,
        /// What is wrong.
        problem: &'static str,
    },
    /// A floor's mass that is not a mass.
    #[error(
        "`{}`, at `floors[{floor}].mass_kg` (tests[{entry}]): {mass_kg}: expected a mass > 0 kg",
        manifest.display()
    )]
    FloorMass {
        /// The manifest.
        manifest: PathBuf,
        /// The floor's index.
        floor: usize,
        /// The entry's index.
        entry: usize,
        /// The rejected mass.
        mass_kg: f64,
    },
    /// A floor's unit that is not an acceleration's.
    #[error(
        "`{}`, at `floors[{floor}].unit` (tests[{entry}]): {value}: expected {expected}",
        manifest.display()
    )]
    FloorUnit {
        /// The manifest.
        manifest: PathBuf,
        /// The floor's index.
        floor: usize,
        /// The entry's index.
        entry: usize,
        /// The rejected value.
        value: String,
        /// What was expected.
        expected: String,
    },
    /// A file's pressure given twice, differently.
    #[error(
        "`{}`: hold-down pressure {given_mpa} MPa from --pressure-mpa but {manifest_mpa} MPa in \
         the manifest `{}`",
        path.display(),
        manifest.display()
    )]
    PressureConflict {
        /// The file.
        path: PathBuf,
        /// The manifest.
        manifest: PathBuf,
        /// The request's pressure, MPa.
        given_mpa: f64,
        /// The manifest's, MPa.
        manifest_mpa: f64,
    },
    /// A file that cannot be read (its path, line and column in the error).
    #[error(transparent)]
    Io(#[from] IoError),
    /// A record's channels that do not make a test record.
    #[error("`{}`", path.display())]
    Record {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        #[source]
        source: IdentError,
    },
    /// A scenario entry that cannot be loaded.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// `floors` on a scenario entry.
    #[error(
        "`{}`: a manifest's `floors` apply to recorded files; recorded-like data made from a \
         scenario have no floor accelerometers",
        path.display()
    )]
    ScenarioFloors {
        /// The scenario.
        path: PathBuf,
    },
    /// A scenario entry given a pressure other than its own.
    #[error(
        "`{}`: hold-down pressure {given_mpa} MPa given for it, but the scenario runs at \
         {scenario_mpa} MPa",
        path.display()
    )]
    ScenarioPressure {
        /// The scenario.
        path: PathBuf,
        /// The pressure given, MPa.
        given_mpa: f64,
        /// The scenario's, MPa.
        scenario_mpa: f64,
    },
    /// A force-driven scenario named for recorded-like data.
    #[error(
        "`{}`: recorded-like data needs a motion scenario (motion_csv, sine_motion, \
         triangle_motion, white_noise_motion or ground_motion); this one is force-driven",
        path.display()
    )]
    NotMotion {
        /// The scenario.
        path: PathBuf,
    },
    /// Recorded-like data that could not be made.
    #[error("recorded-like data could not be made: {message}")]
    RecordedLike {
        /// Why.
        message: String,
    },
    /// A closed-loop record that cannot be read or lacks a required column.
    #[error(
        "{}: identify --system needs the columns t_s, command_u_m and u_m (drive, delta_p_pa, \
         cap_pressure_pa, rod_pressure_pa, a_m_s2, storey{{i}}_a_m_s2 where recorded)",
        source.file().display()
    )]
    SystemColumns {
        /// The file's error (with its path).
        #[source]
        source: IoError,
    },
    /// A table system's base (`--base`) that cannot be read.
    #[error("--base {}: cannot read it", path.display())]
    BaseUnreadable {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A table system's base that is not JSON.
    #[error("--base {}: not JSON", path.display())]
    BaseNotJson {
        /// The file.
        path: PathBuf,
        /// Where and why.
        #[source]
        source: serde_json::Error,
    },
    /// A table system's base that is not a valid table system.
    #[error("--base {}: not a table system", path.display())]
    BaseNotSystem {
        /// The file (boxed: the scenario error is large).
        path: Box<Path>,
        /// The scenario format's error.
        #[source]
        source: ScenarioError,
    },
    /// A base without a table system.
    #[error("--base {}: no table_system in it", path.display())]
    NoTableSystem {
        /// The file.
        path: PathBuf,
    },
    /// The recorded-like data of a scenario entry do not make a test record.
    #[error("`{}` (recorded-like, seed {seed})", path.display())]
    GeneratedRecord {
        /// The scenario.
        path: PathBuf,
        /// The noise seed.
        seed: u64,
        /// What is wrong.
        #[source]
        source: IdentError,
    },
}
