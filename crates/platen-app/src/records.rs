//! Reading test records for identification: recorded CSV files, an identification manifest
//! that lists them (with kinds, hold-down pressures, column maps and a specimen's floors), and
//! motion scenarios whose recorded-like data are made in memory. What `platen identify` and
//! Python's `platen.identify` read, through the same code.
//!
//! ```json
//! { "tests": [ { "file": "run-017.csv", "kind": "triangle", "pressure_mpa": 13.8 },
//!              { "scenario": "13.8MPa/S9.json", "seed": 9 } ],
//!   "columns": { "force_n": { "name": "Force", "unit": "kN" } },
//!   "floors": [ { "column": "Floor 1 Acc", "unit": "mm/s2", "mass_kg": 14000 } ] }
//! ```
//!
//! * `file` is relative to the manifest; `kind` is `sine`, `triangle` or `record` (the
//!   any-record method whatever the data); every key but `file` (or `scenario`) is optional.
//!   Files listed only in the manifest are read too; an entry naming a file already given
//!   is laid over it.
//! * `scenario` names a motion scenario instead: its recorded-like data with noise seed
//!   `seed` (default 1) are made in memory exactly as `platen generate recorded` writes
//!   them, at the scenario's hold-down pressure.
//! * `columns` maps a data system's channel names and units to platen's columns (the
//!   scenario format's `columns` object, [`ColumnMap`]): the request's map for every file,
//!   the manifest's top-level `columns` for the files it lists, an entry's own `columns`,
//!   the most specific winning. A map's `delay_s` (a known channel skew) is applied by
//!   identification as given.
//! * `floors` (top level or per entry) lists a specimen's floor accelerometers with their
//!   storey masses, whose base shear `Σ mᵢ·aᵢ` is taken off the force
//!   ([`TestRecord::with_floors`]).
//!
//! ```no_run
//! use platen_app::records::{read_records, RecordRequest};
//!
//! let request = RecordRequest {
//!     manifest: Some("scenarios/paper-tests/manifest.json".into()),
//!     ..RecordRequest::default()
//! };
//! let inputs = read_records(&request)?;
//! assert_eq!(inputs.records.len(), inputs.sources.len());
//! # Ok::<(), platen_app::InputError>(())
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use platen_ident::{TestKind, TestRecord};
use platen_io::columns::{ColumnMap, ColumnSpec};
use platen_io::json::parse_json_file;
use platen_scenario::sampling::uniform_step_s;
use platen_scenario::PlatenScenario;

use crate::error::InputError;
use crate::recorded::recorded_of;

/// What to read: files, a manifest, a column map and hold-down pressures.
#[derive(Debug, Clone, Default)]
pub struct RecordRequest {
    /// Recorded CSV files, read first and in this order.
    pub files: Vec<PathBuf>,
    /// Hold-down pressures, MPa: none, one for every file (and every manifest entry that
    /// gives none), or one per file in order (`None`: not given for that file).
    pub pressures_mpa: Vec<Option<f64>>,
    /// An identification manifest whose entries are read after `files` (an entry naming one
    /// of `files` is laid over it).
    pub manifest: Option<PathBuf>,
    /// How the files' channels map to platen's columns (the manifest's own `columns` win for
    /// the files it lists).
    pub columns: ColumnMap,
}

/// A specimen floor's accelerometer and its storey mass (a manifest's `floors`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FloorSpec {
    /// The column's header.
    pub column: String,
    /// Its unit (default m/s2).
    #[serde(default)]
    pub unit: Option<String>,
    /// The storey's mass, kg.
    pub mass_kg: f64,
}

/// One record to read, with what is known about it: a file given or listed, or a
/// manifest's scenario entry.
#[derive(Debug, Clone)]
pub struct RecordSource {
    /// The recorded CSV, or the motion scenario of a `scenario` entry.
    pub path: PathBuf,
    /// The test's name in messages (the path as given, or the manifest's `name`).
    pub name: String,
    /// The name in a report's tables (the file name, or the manifest's `name`).
    pub label: String,
    /// The waveform a manifest declares (`None`: recognised from the data).
    pub kind: Option<TestKind>,
    /// The hold-down pressure, MPa.
    pub pressure_mpa: Option<f64>,
    /// How the file's channels map to platen's columns.
    pub columns: ColumnMap,
    /// Declared `"kind": "record"` in the manifest: the any-record method whatever the data.
    pub declared_record: bool,
    /// The specimen's floor accelerometers.
    pub floors: Vec<FloorSpec>,
    /// `Some(seed)`: `path` is a motion scenario whose recorded-like data, with this noise
    /// seed, are identified (made in memory).
    pub generated_seed: Option<u64>,
}

/// The records read, in input order, with where each came from.
#[derive(Debug, Clone)]
pub struct RecordInputs {
    /// Where each record came from.
    pub sources: Vec<RecordSource>,
    /// The records, one per source.
    pub records: Vec<TestRecord>,
}

impl RecordInputs {
    /// Whether each record was declared `"kind": "record"` (for
    /// [`platen_ident::identify_any`]).
    pub fn declared_record(&self) -> Vec<bool> {
        declared_record(&self.sources)
    }

    /// The file each record came from, as given (for [`platen_ident::Identified::output`]).
    pub fn files(&self) -> Vec<String> {
        files(&self.sources)
    }
}

/// Whether each source was declared `"kind": "record"` (for
/// [`platen_ident::identify_any`]).
pub fn declared_record(sources: &[RecordSource]) -> Vec<bool> {
    sources.iter().map(|s| s.declared_record).collect()
}

/// The file of each source, as given (for [`platen_ident::Identified::output`]).
pub fn files(sources: &[RecordSource]) -> Vec<String> {
    sources
        .iter()
        .map(|s| s.path.display().to_string())
        .collect()
}

/// Reads every record of `request`: [`RecordRequest::sources`], then [`RecordSource::read`]
/// on each, in order.
///
/// # Errors
/// See [`InputError`]: the first source or record that cannot be read.
pub fn read_records(request: &RecordRequest) -> Result<RecordInputs, InputError> {
    let sources = request.sources()?;
    let records = sources
        .iter()
        .map(RecordSource::read)
        .collect::<Result<Vec<_>, _>>()?;
    Ok(RecordInputs { sources, records })
}

impl RecordRequest {
    /// The records to read: the files, then the manifest's entries not already given, with
    /// kinds, pressures, column maps and floors from the manifest and the request. Nothing is
    /// read but the manifest.
    ///
    /// # Errors
    /// [`InputError::PressureCount`], [`InputError::Pressure`], [`InputError::NoFiles`], and
    /// the manifest's errors.
    pub fn sources(&self) -> Result<Vec<RecordSource>, InputError> {
        let pressures = &self.pressures_mpa;
        if pressures.len() > 1 && pressures.len() != self.files.len() {
            return Err(InputError::PressureCount {
                given: pressures.len(),
                files: self.files.len(),
            });
        }
        if let Some(e) = pressures
            .iter()
            .flatten()
            .find_map(|&p| platen_scenario::units::check_pressure_mpa(p).err())
        {
            return Err(InputError::Pressure { message: e });
        }
        let mut sources: Vec<RecordSource> = self
            .files
            .iter()
            .enumerate()
            .map(|(i, f)| RecordSource {
                path: f.clone(),
                name: f.display().to_string(),
                label: file_label(f),
                kind: None,
                pressure_mpa: match pressures.len() {
                    0 => None,
                    1 => pressures[0],
                    _ => pressures[i],
                },
                columns: self.columns.clone(),
                declared_record: false,
                floors: Vec::new(),
                generated_seed: None,
            })
            .collect();
        if let Some(path) = &self.manifest {
            let (tests, reader) = ManifestReader::read(path, &self.columns)?;
            // A single pressure is the default for every file.
            let default_mpa = match pressures.as_slice() {
                [p] => *p,
                _ => None,
            };
            for (k, entry) in tests.into_iter().enumerate() {
                reader.add(&mut sources, k, entry, default_mpa)?;
            }
        }
        if sources.is_empty() {
            return Err(InputError::NoFiles);
        }
        Ok(sources)
    }
}

/// The manifest file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    tests: Vec<ManifestEntry>,
    /// Channel names and units of every listed file (an entry's own `columns` wins).
    #[serde(default)]
    columns: Option<BTreeMap<String, ColumnSpec>>,
    /// Floor accelerometers of every listed file (an entry's own `floors` wins).
    #[serde(default)]
    floors: Option<Vec<FloorSpec>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ManifestEntry {
    /// A recorded CSV (this or `scenario`).
    #[serde(default)]
    file: Option<PathBuf>,
    /// A motion scenario whose recorded-like data are identified (this or `file`).
    #[serde(default)]
    scenario: Option<PathBuf>,
    /// The noise seed of a `scenario` entry's recorded-like data (default 1, as `generate`).
    #[serde(default)]
    seed: Option<u64>,
    #[serde(default)]
    kind: Option<KindName>,
    #[serde(default)]
    pressure_mpa: Option<f64>,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    columns: Option<BTreeMap<String, ColumnSpec>>,
    #[serde(default)]
    floors: Option<Vec<FloorSpec>>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum KindName {
    Sine,
    Triangle,
    Record,
}

/// Turns a manifest's entries into sources.
struct ManifestReader<'a> {
    path: &'a Path,
    /// The folder the entries' files are relative to.
    base: &'a Path,
    /// The manifest's own `columns`, if any.
    columns: Option<ColumnMap>,
    /// The request's map, or platen's own names.
    default_columns: &'a ColumnMap,
    /// The manifest's own `floors`, if any.
    floors: Option<Vec<FloorSpec>>,
}

impl<'a> ManifestReader<'a> {
    fn read(
        path: &'a Path,
        default_columns: &'a ColumnMap,
    ) -> Result<(Vec<ManifestEntry>, Self), InputError> {
        let manifest: Manifest =
            parse_json_file(path).map_err(|source| InputError::Manifest { source })?;
        let mut reader = ManifestReader {
            path,
            base: path.parent().unwrap_or(Path::new(".")),
            columns: None,
            default_columns,
            floors: manifest.floors,
        };
        reader.columns = match &manifest.columns {
            Some(spec) => Some(reader.column_map(spec, "columns")?),
            None => None,
        };
        Ok((manifest.tests, reader))
    }

    fn column_map(
        &self,
        spec: &BTreeMap<String, ColumnSpec>,
        at: &str,
    ) -> Result<ColumnMap, InputError> {
        ColumnMap::new(spec, at).map_err(|(json_path, value, expected)| {
            InputError::ManifestColumns {
                manifest: self.path.to_owned(),
                json_path,
                value,
                expected,
            }
        })
    }

    /// Adds entry `k`: to the source of the same file if there is one, else as a new source.
    fn add(
        &self,
        sources: &mut Vec<RecordSource>,
        k: usize,
        entry: ManifestEntry,
        default_mpa: Option<f64>,
    ) -> Result<(), InputError> {
        if let Some(p) = entry.pressure_mpa {
            if let Err(message) = platen_scenario::units::check_pressure_mpa(p) {
                return Err(InputError::ManifestPressure {
                    manifest: self.path.to_owned(),
                    entry: k,
                    message,
                });
            }
        }
        let (given, generated_seed) = self.source(k, &entry)?;
        let path = if given.is_absolute() {
            given.to_path_buf()
        } else {
            self.base.join(given)
        };
        let columns = match (&entry.columns, &self.columns) {
            (Some(spec), _) => self.column_map(spec, &format!("tests[{k}].columns"))?,
            (None, Some(map)) => map.clone(),
            (None, None) => self.default_columns.clone(),
        };
        let declared_record = matches!(entry.kind, Some(KindName::Record));
        let kind = entry.kind.and_then(|k| match k {
            KindName::Sine => Some(TestKind::Sine),
            KindName::Triangle => Some(TestKind::Triangle),
            KindName::Record => None,
        });
        let floors = entry
            .floors
            .clone()
            .or_else(|| self.floors.clone())
            .unwrap_or_default();
        for (i, f) in floors.iter().enumerate() {
            if !(f.mass_kg.is_finite() && f.mass_kg > 0.0) {
                return Err(InputError::FloorMass {
                    manifest: self.path.to_owned(),
                    floor: i,
                    entry: k,
                    mass_kg: f.mass_kg,
                });
            }
            floor_factor(f).map_err(|(value, expected)| InputError::FloorUnit {
                manifest: self.path.to_owned(),
                floor: i,
                entry: k,
                value,
                expected,
            })?;
        }
        let canon = std::fs::canonicalize(&path).ok();
        let existing = sources
            .iter_mut()
            .find(|s| canon.is_some() && std::fs::canonicalize(&s.path).ok() == canon);
        match existing {
            Some(source) => {
                source.declared_record = declared_record;
                source.floors = floors;
                source.generated_seed = generated_seed;
                self.merge(source, entry, kind, columns)?;
            }
            None => sources.push(RecordSource {
                label: entry.name.clone().unwrap_or_else(|| file_label(&path)),
                name: entry.name.unwrap_or_else(|| path.display().to_string()),
                path,
                kind,
                pressure_mpa: entry.pressure_mpa.or(default_mpa),
                columns,
                declared_record,
                floors,
                generated_seed,
            }),
        }
        Ok(())
    }

    /// Entry `k`'s source: its `file`, or its `scenario` with the seed of its recorded-like
    /// data.
    fn source<'e>(
        &self,
        k: usize,
        entry: &'e ManifestEntry,
    ) -> Result<(&'e Path, Option<u64>), InputError> {
        let at = |problem: &'static str| InputError::ManifestEntry {
            manifest: self.path.to_owned(),
            entry: k,
            problem,
        };
        match (&entry.file, &entry.scenario) {
            (Some(file), None) => {
                if entry.seed.is_some() {
                    return Err(at("`seed` applies to a `scenario` entry, not to a `file`"));
                }
                Ok((file, None))
            }
            (None, Some(scenario)) => {
                if entry.columns.is_some() || entry.floors.is_some() {
                    return Err(at(
                        "`columns` and `floors` apply to a recorded `file`; a `scenario` \
                         entry's recorded-like data are in platen's own columns",
                    ));
                }
                Ok((scenario, Some(entry.seed.unwrap_or(1))))
            }
            (Some(_), Some(_)) => Err(at("expected `file` or `scenario`, not both")),
            (None, None) => Err(at(
                "expected `file` (a recorded CSV) or `scenario` (a motion scenario whose \
                 recorded-like data are identified)",
            )),
        }
    }

    /// Lays an entry over the request's source of the same file.
    fn merge(
        &self,
        source: &mut RecordSource,
        entry: ManifestEntry,
        kind: Option<TestKind>,
        columns: ColumnMap,
    ) -> Result<(), InputError> {
        if let (Some(a), Some(b)) = (source.pressure_mpa, entry.pressure_mpa) {
            if a != b {
                return Err(InputError::PressureConflict {
                    path: source.path.clone(),
                    manifest: self.path.to_owned(),
                    given_mpa: a,
                    manifest_mpa: b,
                });
            }
        }
        source.pressure_mpa = entry.pressure_mpa.or(source.pressure_mpa);
        source.kind = kind;
        source.columns = columns;
        if let Some(n) = entry.name {
            source.label = n.clone();
            source.name = n;
        }
        Ok(())
    }
}

/// The file name of `path` (the whole path if it has none).
fn file_label(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// The factor from a floor channel's unit to m/s² (checked like a column map's
/// acceleration), or the rejected value and what was expected.
fn floor_factor(f: &FloorSpec) -> Result<f64, (String, String)> {
    let mut spec = BTreeMap::new();
    spec.insert(
        "a_m_s2".to_owned(),
        ColumnSpec {
            name: Some(f.column.clone()),
            unit: f.unit.clone(),
            ..ColumnSpec::default()
        },
    );
    let map = ColumnMap::new(&spec, "floors").map_err(|(_, value, expected)| (value, expected))?;
    Ok(map.factor("a_m_s2"))
}

impl RecordSource {
    /// Reads the record: the CSV's `t_s`, `u_m`, `a_m_s2`, `force_n` (and `v_m_s` and the
    /// floors' channels where present) through the column map, uniformly sampled, with the
    /// pressure, kind, floors and the map's channel delays; or a scenario entry's
    /// recorded-like data.
    ///
    /// # Errors
    /// [`InputError::Io`] for a file that cannot be read, [`InputError::Record`] for channels
    /// that do not make a record, and the scenario entries' errors.
    pub fn read(&self) -> Result<TestRecord, InputError> {
        if let Some(seed) = self.generated_seed {
            return self.generated(seed);
        }
        let path = &self.path;
        let mut required = vec!["t_s", "u_m", "a_m_s2", "force_n"];
        required.extend(self.floors.iter().map(|f| f.column.as_str()));
        let mut table = self.columns.read_table(path, &required, &["v_m_s"])?;
        let mut take = |c: &str| table.take_column(c).unwrap_or_default();
        let (t, u, a, f) = (take("t_s"), take("u_m"), take("a_m_s2"), take("force_n"));
        let dt = uniform_step_s(path, &t)?;
        let v = table.take_column("v_m_s");
        let located = |source| InputError::Record {
            path: path.clone(),
            source,
        };
        let has_v = v.is_some();
        let mut rec =
            TestRecord::from_rate(self.name.clone(), 1.0 / dt, u, a, f).map_err(located)?;
        if let Some(v) = v {
            rec = rec.with_velocity(v).map_err(located)?;
        }
        if let Some(p) = self.pressure_mpa {
            rec = rec.with_pressure_pa(p * 1e6).map_err(located)?;
        }
        if let Some(k) = self.kind {
            rec = rec.with_kind(k);
        }
        if !self.floors.is_empty() {
            let mut floors = Vec::with_capacity(self.floors.len());
            for (i, f) in self.floors.iter().enumerate() {
                // Checked when the manifest was read; a source built by hand is checked here.
                let factor =
                    floor_factor(f).map_err(|(value, expected)| InputError::FloorUnit {
                        manifest: path.clone(),
                        floor: i,
                        entry: 0,
                        value,
                        expected,
                    })?;
                let acc = table
                    .take_column(&f.column)
                    .unwrap_or_default()
                    .into_iter()
                    .map(|a| a * factor)
                    .collect();
                floors.push((f.mass_kg, acc));
            }
            rec = rec.with_floors(&floors).map_err(located)?;
        }
        // A column map's known channel skew (`delay_s`), applied by identification as given.
        for column in platen_ident::anyrecord::DELAYABLE_CHANNELS {
            let delay = self.columns.delay_s(column);
            if let Some(d) = delay.filter(|_| column != "v_m_s" || has_v) {
                rec = rec.with_channel_delay_s(column, d).map_err(located)?;
            }
        }
        Ok(rec)
    }

    /// The recorded-like data of a manifest's `scenario` entry as a test record: the numbers
    /// `platen generate recorded` writes, so identifying them gives what identifying that
    /// CSV gives. The hold-down pressure is the scenario's (a different one given is an
    /// error: the data were made at the scenario's).
    fn generated(&self, seed: u64) -> Result<TestRecord, InputError> {
        let path = &self.path;
        if !self.floors.is_empty() {
            return Err(InputError::ScenarioFloors { path: path.clone() });
        }
        let scenario = PlatenScenario::load(path)?;
        let pressure_pa = scenario.rig.hold_down_pressure_pa;
        if let Some(p) = self.pressure_mpa {
            // The same number written twice (13.8 in both files) may differ in its last bit.
            if (p * 1e6 - pressure_pa).abs() > 1e-9 * pressure_pa.abs().max(1.0) {
                return Err(InputError::ScenarioPressure {
                    path: path.clone(),
                    given_mpa: p,
                    scenario_mpa: pressure_pa / 1e6,
                });
            }
        }
        let rec = recorded_of(&scenario, path, seed)?;
        let dt = uniform_step_s(path, &rec.t_s)?;
        let mut test = TestRecord::from_rate(
            self.name.clone(),
            1.0 / dt,
            rec.u_m,
            rec.a_m_s2,
            rec.force_n,
        )
        .and_then(|t| t.with_velocity(rec.v_m_s))
        .and_then(|t| t.with_pressure_pa(pressure_pa))
        .map_err(|source| InputError::GeneratedRecord {
            path: path.clone(),
            seed,
            source,
        })?;
        if let Some(k) = self.kind {
            test = test.with_kind(k);
        }
        Ok(test)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The repository's any-record test data.
    fn data() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/any-record")
    }

    /// A fresh folder for this test's files.
    fn folder(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("platen-app-records-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn lab_columns() -> ColumnMap {
        ColumnMap::load(&data().join("columns.json")).unwrap()
    }

    #[test]
    fn a_manifest_with_floors_removes_their_base_shear() {
        let request = RecordRequest {
            manifest: Some(data().join("two-storey-manifest.json")),
            ..RecordRequest::default()
        };
        let inputs = read_records(&request).unwrap();
        assert_eq!(inputs.sources.len(), 1);
        let floors = inputs.records[0].floors().expect("floors removed");
        assert_eq!(floors.masses_kg, [14000.0, 11000.0]);
        // Independently: the largest |Σ mᵢ·aᵢ| of the file's floor columns, mm/s² to m/s².
        let text = std::fs::read_to_string(data().join("eq-two-storey-lab.csv")).unwrap();
        let peak = text
            .lines()
            .skip(1)
            .map(|l| {
                let c: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                (14000.0 * c[4] + 11000.0 * c[5]) * 1e-3
            })
            .fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!((floors.peak_base_shear_n / peak - 1.0).abs() < 1e-12);
        assert_eq!(
            inputs.files(),
            [data().join("eq-two-storey-lab.csv").display().to_string()]
        );
    }

    #[test]
    fn a_column_maps_delay_is_given_to_the_record() {
        let dir = folder("delay");
        let map = r#"{"t_s": {"name": "Time", "unit": "s"}, "u_m": {"name": "Table Disp", "unit": "mm"},
            "a_m_s2": {"name": "Table Acc", "unit": "mm/s2", "delay_s": 0.004},
            "force_n": {"name": "dP", "unit": "MPa", "times_area_m2": 0.15}}"#;
        let request = RecordRequest {
            files: vec![data().join("eq-lab.csv")],
            pressures_mpa: vec![Some(13.8)],
            columns: ColumnMap::from_json(&dir.join("map.json"), map).unwrap(),
            ..RecordRequest::default()
        };
        let inputs = read_records(&request).unwrap();
        let rec = &inputs.records[0];
        assert_eq!(rec.channel_delay_s("a_m_s2"), Some(0.004));
        assert_eq!(rec.pressure_pa(), Some(13.8e6));
        assert_eq!(rec.name(), data().join("eq-lab.csv").display().to_string());
        assert_eq!(inputs.sources[0].label, "eq-lab.csv");
        assert_eq!(inputs.declared_record(), [false]);
    }

    #[test]
    fn manifest_entries_lay_over_the_files_and_scenarios_are_made_in_memory() {
        let dir = folder("overlay");
        let scenario = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenarios/paper-tests/13.8MPa/S9.json")
            .canonicalize()
            .unwrap();
        let manifest = dir.join("m.json");
        let eq = data().join("eq-lab.csv");
        std::fs::write(
            &manifest,
            serde_json::json!({
                "tests": [
                    { "file": eq, "kind": "record", "name": "eq" },
                    { "scenario": scenario, "seed": 9, "kind": "sine" },
                ]
            })
            .to_string(),
        )
        .unwrap();
        let request = RecordRequest {
            files: vec![eq.clone()],
            manifest: Some(manifest),
            columns: lab_columns(),
            ..RecordRequest::default()
        };
        let sources = request.sources().unwrap();
        assert_eq!(sources.len(), 2, "the file given and listed is one record");
        assert_eq!(
            (sources[0].name.as_str(), sources[0].label.as_str()),
            ("eq", "eq")
        );
        assert!(sources[0].declared_record && sources[0].kind.is_none());
        assert_eq!(sources[1].generated_seed, Some(9));
        assert_eq!(sources[1].kind, Some(TestKind::Sine));
        let rec = sources[1].read().unwrap();
        assert_eq!(rec.pressure_pa(), Some(13.8e6));
        assert_eq!(rec.kind(), Some(TestKind::Sine));
        // The numbers `platen generate recorded --seed 9` writes.
        let made = recorded_of(&PlatenScenario::load(&scenario).unwrap(), &scenario, 9).unwrap();
        assert_eq!(rec.u_m(), made.u_m.as_slice());
        assert_eq!(rec.force_n(), made.force_n.as_slice());
        assert_eq!(rec.v_m_s(), Some(made.v_m_s.as_slice()));
    }

    #[test]
    fn mistakes_are_named_with_the_file_and_json_path() {
        let dir = folder("mistakes");
        let manifest = dir.join("m.json");
        let message = |json: serde_json::Value, request: RecordRequest| {
            std::fs::write(&manifest, json.to_string()).unwrap();
            let request = RecordRequest {
                manifest: Some(manifest.clone()),
                ..request
            };
            request.sources().unwrap_err().to_string()
        };
        let m = manifest.display();
        assert_eq!(
            message(
                serde_json::json!({"tests": [{"file": "a.csv", "scenario": "b.json"}]}),
                RecordRequest::default()
            ),
            format!("`{m}`, at `tests[0]`: expected `file` or `scenario`, not both")
        );
        assert_eq!(
            message(
                serde_json::json!({"floors": [{"column": "F1", "mass_kg": 0}], "tests": [{"file": "a.csv"}]}),
                RecordRequest::default()
            ),
            format!("`{m}`, at `floors[0].mass_kg` (tests[0]): 0: expected a mass > 0 kg")
        );
        // A file given with one pressure and listed with another.
        let a = dir.join("a.csv");
        std::fs::write(&a, "t_s\n").unwrap();
        assert_eq!(
            message(
                serde_json::json!({"tests": [{"file": "a.csv", "pressure_mpa": 6.9}]}),
                RecordRequest {
                    files: vec![a.clone()],
                    pressures_mpa: vec![Some(13.8)],
                    ..RecordRequest::default()
                }
            ),
            format!(
                "`{}`: hold-down pressure 13.8 MPa from --pressure-mpa but 6.9 MPa in the manifest `{m}`",
                a.display()
            )
        );
        let err = RecordRequest {
            files: vec!["a.csv".into()],
            pressures_mpa: vec![Some(13.8), Some(6.9)],
            ..RecordRequest::default()
        }
        .sources()
        .unwrap_err();
        assert!(matches!(
            err,
            InputError::PressureCount { given: 2, files: 1 }
        ));
        let err = RecordRequest::default().sources().unwrap_err();
        assert!(matches!(err, InputError::NoFiles));
        let err = message(
            serde_json::json!({"tests": [{"file": 3}]}),
            RecordRequest::default(),
        );
        assert!(err.starts_with("reading the identification manifest (expected {\"tests\": "));
    }
}
