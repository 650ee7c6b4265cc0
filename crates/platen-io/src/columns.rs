//! Mapping a lab's own channel names and units to platen's columns.
//!
//! Data systems export their own headers (`Table disp` in mm, acceleration in g, a
//! differential pressure instead of a force). A scenario maps them with a `columns` object
//! next to the file it names:
//!
//! ```json
//! "excitation": {
//!   "motion_csv": "lab.csv",
//!   "columns": {
//!     "t_s": { "name": "Time", "unit": "ms" },
//!     "u_m": { "name": "Table disp", "unit": "mm" },
//!     "a_m_s2": { "name": "Table acc", "unit": "g" }
//!   }
//! }
//! ```
//!
//! A force can come from a pressure: `"force_n": {"name": "dP", "unit": "MPa",
//! "times_area_m2": 0.33}`. Columns not mapped are read under platen's own name in SI units.
//!
//! A channel's zero: `"offset": -0.13` subtracts a transducer's offset (in the file's unit,
//! before the conversion: `SI = (value − offset)·factor`); `"remove_mean": true` subtracts the
//! channel's mean over the file, `"zero_at_start": true` its first value (one or the other;
//! the time column takes `offset` and `zero_at_start` only).
//!
//! Every column a reader asks for can be mapped: `t_s`, `u_m`, `v_m_s`, `a_m_s2`, `force_n`,
//! `base_shear_n`, the table system's `command_u_m` (a displacement), `drive` (a fraction of
//! full opening, no unit), `delta_p_pa`, `cap_pressure_pa`, `rod_pressure_pa` (pressures), and
//! the specimen's `storey{i}_u_m` and `storey{i}_a_m_s2` (`i` ≥ 1).
//! `"scale": 0.1` multiplies a channel after its unit's factor (a drive recorded in volts of a
//! ±10 V servo amplifier).
//!
//! Header names match with surrounding spaces trimmed, in the file and in the map (`" Table
//! disp "` reads the file's `Table disp`, and a DAQ export's `" disp"` is read as `disp`). A
//! channel the map names must be in the file, even one the reading could do without; an
//! unknown column, an unknown unit or a header absent from the file is an error listing the
//! accepted columns, the units of that quantity, or the file's headers. A file that lacks a
//! required column, without a map entry for it, is reported with a one-line map that would
//! read it.
//!
//! `"delay_s": 0.004` records a channel's known delay relative to the displacement `u_m`
//! (finite, `|delay_s|` < [`MAX_DELAY_S`]; not on `t_s` or `u_m`). Reading does not apply it:
//! [`ColumnMap::delay_s`] hands it to identification, which corrects the channel's skew.
//!
//! Units: time `s`, `ms`; displacement `m`, `mm`, `cm`, `in`; velocity `m/s`, `mm/s`, `cm/s`,
//! `in/s`; acceleration `m/s2`, `mm/s2`, `cm/s2` (`gal`), `in/s2`, `g` (9.80665 m/s²); force `N`,
//! `kN`, `MN`, `lbf`, `kip`; pressure (with `times_area_m2`) `Pa`, `kPa`, `MPa`, `bar`, `psi`.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;

use crate::csv::{read_table, Table};
use crate::error::{IoError, Result};
use crate::json::{parse_json, parse_json_file};

use crate::STANDARD_GRAVITY_M_S2;

/// How one of platen's columns is found in a file.
#[derive(Debug, Clone, Default, Deserialize, serde::Serialize, PartialEq, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColumnSpec {
    /// The header in the file (default: platen's own column name).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The unit of the values in the file (default: platen's SI unit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
    /// For a force given as a pressure: the area it acts on, m².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub times_area_m2: Option<f64>,
    /// A factor applied after the unit's (default 1): `SI = (value − offset)·unit·scale`,
    /// e.g. 0.1 for a drive recorded in volts of a ±10 V servo amplifier.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// A constant subtracted from every value, in the file's unit (before the conversion to
    /// SI; default 0): a transducer's offset, e.g. `-0.13` for a pressure read in MPa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
    /// Subtract the channel's mean over the file (after the offset; default false). Not for
    /// `t_s`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub remove_mean: bool,
    /// Subtract the channel's first value, so it starts at zero (default false); not with
    /// `remove_mean`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub zero_at_start: bool,
    /// Do not read this column even where the file has one of this name (default false):
    /// platen then does without it as for a file that lacks it, e.g. a motion's `v_m_s` and
    /// `a_m_s2` derived from its `u_m`. Alone: no other field with it; not for a column the
    /// reading requires.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub ignore: bool,
    /// The channel's known delay relative to the displacement `u_m`, s (default none): a
    /// data system that samples a channel late by `delay_s` (positive) or early (negative).
    /// Finite, `|delay_s|` < 1 s; not for `t_s` or `u_m` itself. Reading a file does not apply
    /// it: identification uses it ([`ColumnMap::delay_s`]) to correct the channel's skew.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delay_s: Option<f64>,
}

/// The largest `|delay_s|` a column map accepts, s: a data system's channel skew is a few
/// samples (milliseconds); a second or more is a wrong unit (ms given as s) or a wrong
/// channel, not a skew.
pub const MAX_DELAY_S: f64 = 1.0;

/// How a channel is read: its header, the factor from the file's unit to SI, the offset
/// subtracted first (file unit), and how its zero is set.
#[derive(Debug, Clone, PartialEq)]
struct Mapping {
    header: String,
    factor: f64,
    offset: f64,
    zero: Zero,
    /// Not read (`ignore`).
    ignored: bool,
    /// The header was given (`name`), rather than platen's own name.
    named: bool,
    /// The channel's delay relative to the displacement, s (`delay_s`).
    delay_s: Option<f64>,
}

/// Where a channel's zero is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Zero {
    /// As recorded (less the offset).
    AsRecorded,
    /// At the channel's mean.
    Mean,
    /// At the channel's first value.
    Start,
}

impl Mapping {
    /// The channel in SI units: `(x − offset)·factor`, then its zero set.
    fn apply(&self, column: &mut [f64]) {
        if self.offset != 0.0 || self.factor != 1.0 {
            for x in column.iter_mut() {
                *x = (*x - self.offset) * self.factor;
            }
        }
        let zero = match self.zero {
            Zero::AsRecorded => return,
            Zero::Mean => column.iter().sum::<f64>() / column.len().max(1) as f64,
            Zero::Start => column.first().copied().unwrap_or(0.0),
        };
        column.iter_mut().for_each(|x| *x -= zero);
    }
}

/// platen's column names and the kind of quantity each holds (besides the storeys'
/// displacements `storey{i}_u_m` and accelerations `storey{i}_a_m_s2`, `i` ≥ 1): every
/// column a reader of records asks for.
const QUANTITIES: [(&str, Kind); 11] = [
    ("t_s", Kind::Time),
    ("u_m", Kind::Displacement),
    ("v_m_s", Kind::Velocity),
    ("a_m_s2", Kind::Acceleration),
    ("force_n", Kind::Force),
    ("base_shear_n", Kind::Force),
    ("command_u_m", Kind::Displacement),
    ("drive", Kind::Drive),
    ("delta_p_pa", Kind::Pressure),
    ("cap_pressure_pa", Kind::Pressure),
    ("rod_pressure_pa", Kind::Pressure),
];

/// The per-storey columns: `storey{i}` followed by one of these suffixes, with their kind.
const STOREY_QUANTITIES: [(&str, Kind); 2] = [
    ("_u_m", Kind::Displacement),
    ("_a_m_s2", Kind::Acceleration),
];

/// Every platen column a column map accepts, as a message lists them.
pub fn canonical_columns() -> String {
    let mut names: Vec<String> = QUANTITIES.iter().map(|(n, _)| (*n).to_owned()).collect();
    names.extend(
        STOREY_QUANTITIES
            .iter()
            .map(|(s, _)| format!("storey{{i}}{s} (i ≥ 1)")),
    );
    names.join(", ")
}

/// The kind of platen's column `name`, if it is one.
fn kind_of(name: &str) -> Option<Kind> {
    if let Some(k) = QUANTITIES.iter().find(|(n, _)| *n == name).map(|(_, k)| *k) {
        return Some(k);
    }
    let rest = name.strip_prefix("storey")?;
    STOREY_QUANTITIES.iter().find_map(|(suffix, kind)| {
        let storey = rest.strip_suffix(suffix)?;
        let i: u32 = storey.parse().ok()?;
        (i >= 1 && !storey.starts_with(['0', '+'])).then_some(*kind)
    })
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Time,
    Displacement,
    Velocity,
    Acceleration,
    Force,
    /// A valve drive, a fraction of full opening (no unit; `scale` converts volts).
    Drive,
    /// A pressure difference, Pa.
    Pressure,
}

/// An invalid field: its JSON path, the value found, and what was expected.
pub type Invalid = (String, String, String);

/// A validated mapping: for each platen column, the header to read, the factor to SI, the
/// offset and the zero.
///
/// Always valid: its entries are private and every way to make one checks them
/// ([`ColumnMap::new`] from the plain [`ColumnSpec`]s, [`ColumnMap::load`],
/// [`ColumnMap::from_json`]); the default map, empty, reads every column under platen's own
/// name in SI units.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ColumnMap {
    entries: BTreeMap<String, Mapping>,
}

impl ColumnMap {
    /// Validates a `columns` object. `json_path` prefixes error locations.
    ///
    /// # Errors
    /// `(json path, value, expected)` for an unknown platen column, an unknown unit, a unit of
    /// the wrong kind, or a pressure without (or an area with a non-pressure) unit.
    pub fn new(spec: &BTreeMap<String, ColumnSpec>, json_path: &str) -> Result<Self, Invalid> {
        let mut entries = BTreeMap::new();
        for (ours, s) in spec {
            let kind = kind_of(ours).ok_or_else(|| {
                (
                    format!("{json_path}.{ours}"),
                    format!("{ours:?}"),
                    format!("one of platen's columns: {}", canonical_columns()),
                )
            })?;
            let here = format!("{json_path}.{ours}");
            let mapping = if s.ignore {
                Self::left_out(ours, s, kind, &here)?
            } else {
                Self::mapping(ours, s, kind, &here)?
            };
            entries.insert(ours.clone(), mapping);
        }
        Ok(Self { entries })
    }

    /// The mapping of column `ours` (of `kind`, at JSON path `here`) that `ignore` leaves out.
    fn left_out(ours: &str, s: &ColumnSpec, kind: Kind, here: &str) -> Result<Mapping, Invalid> {
        let alone = ColumnSpec {
            ignore: true,
            ..ColumnSpec::default()
        };
        if kind == Kind::Time || *s != alone {
            return Err((
                format!("{here}.ignore"),
                "true".into(),
                if kind == Kind::Time {
                    "no ignore on the time column t_s".into()
                } else {
                    "ignore alone: no name, unit, scale, offset or zero with it".into()
                },
            ));
        }
        Ok(Mapping {
            header: ours.to_owned(),
            factor: 1.0,
            offset: 0.0,
            zero: Zero::AsRecorded,
            ignored: true,
            named: false,
            delay_s: None,
        })
    }

    /// The mapping of column `ours` (of `kind`, at JSON path `here`) from its spec.
    fn mapping(ours: &str, s: &ColumnSpec, kind: Kind, here: &str) -> Result<Mapping, Invalid> {
        let factor = Self::scale(s, kind, here, Self::unit_factor(s, kind, here)?)?;
        let header = match s.name.as_deref().map(str::trim) {
            None => ours.to_owned(),
            Some("") => {
                return Err((
                    format!("{here}.name"),
                    format!("{:?}", s.name.as_deref().unwrap_or_default()),
                    "a header name of the file (not empty)".into(),
                ))
            }
            Some(name) => name.to_owned(),
        };
        let delay_s = match s.delay_s {
            None => None,
            Some(_) if matches!(kind, Kind::Time) || ours == "u_m" => {
                return Err((
                    format!("{here}.delay_s"),
                    s.delay_s.unwrap_or_default().to_string(),
                    "no delay on t_s or u_m: a delay is a channel's skew relative to the \
                     displacement u_m"
                        .into(),
                ))
            }
            Some(d) if d.is_finite() && d.abs() < MAX_DELAY_S => Some(d),
            Some(d) => {
                return Err((
                    format!("{here}.delay_s"),
                    d.to_string(),
                    format!(
                        "a finite delay in seconds, |delay_s| < {MAX_DELAY_S} s (a channel's \
                         skew is milliseconds: 0.004, not 4)"
                    ),
                ))
            }
        };
        let offset = s.offset.unwrap_or(0.0);
        if !offset.is_finite() {
            return Err((
                format!("{here}.offset"),
                offset.to_string(),
                "a finite number in the file's unit".into(),
            ));
        }
        let zero = match (s.remove_mean, s.zero_at_start) {
            (true, true) => {
                return Err((
                    format!("{here}.remove_mean"),
                    "true".into(),
                    "either remove_mean or zero_at_start, not both".into(),
                ))
            }
            (true, false) if kind == Kind::Time => {
                return Err((
                    format!("{here}.remove_mean"),
                    "true".into(),
                    "no mean removal on the time column (zero_at_start or offset shift it)".into(),
                ))
            }
            (true, false) => Zero::Mean,
            (false, true) => Zero::Start,
            (false, false) => Zero::AsRecorded,
        };
        Ok(Mapping {
            header,
            factor,
            offset,
            zero,
            ignored: false,
            named: s.name.is_some(),
            delay_s,
        })
    }

    /// The factor of the spec's unit (times its area for a pressure read as a force).
    fn unit_factor(s: &ColumnSpec, kind: Kind, here: &str) -> Result<f64, Invalid> {
        let factor = match (&s.unit, s.times_area_m2) {
            (None, None) => 1.0,
            (None, Some(_)) => {
                return Err((
                    format!("{here}.unit"),
                    "(missing)".into(),
                    "a pressure unit for times_area_m2".into(),
                ))
            }
            (Some(u), area) => {
                let (unit_kind, f) = unit_factor(u).ok_or_else(|| {
                    (
                        format!("{here}.unit"),
                        format!("{u:?}"),
                        expected_unit(kind),
                    )
                })?;
                match (unit_kind, area) {
                    (UnitKind::Pressure, Some(a)) if kind == Kind::Force => {
                        if !(a.is_finite() && a > 0.0) {
                            return Err((
                                format!("{here}.times_area_m2"),
                                a.to_string(),
                                "an area > 0 m²".into(),
                            ));
                        }
                        f * a
                    }
                    (UnitKind::Pressure, None) if kind == Kind::Pressure => f,
                    (UnitKind::Pressure, _) => {
                        return Err((
                            format!("{here}.unit"),
                            format!("{u:?}"),
                            "a pressure unit only for force_n, with times_area_m2".into(),
                        ))
                    }
                    (UnitKind::Of(k), None) if k == kind => f,
                    (UnitKind::Of(_), Some(_)) => {
                        return Err((
                            format!("{here}.times_area_m2"),
                            "(set)".into(),
                            "times_area_m2 only with a pressure unit".into(),
                        ))
                    }
                    (UnitKind::Of(_), None) => {
                        return Err((
                            format!("{here}.unit"),
                            format!("{u:?}"),
                            expected_unit(kind),
                        ))
                    }
                }
            }
        };
        Ok(factor)
    }

    /// The unit's `factor` times the spec's `scale` (which a drive in volts needs).
    fn scale(s: &ColumnSpec, kind: Kind, here: &str, factor: f64) -> Result<f64, Invalid> {
        if kind == Kind::Drive && s.unit.as_deref().map(str::trim) == Some("V") && s.scale.is_none()
        {
            return Err((
                format!("{here}.scale"),
                "(missing)".into(),
                "a drive in volts needs scale = 1/(full-scale volts) to be a fraction of full \
                 opening, e.g. 0.1 for a ±10 V servo amplifier"
                    .into(),
            ));
        }
        match s.scale {
            None => Ok(factor),
            Some(k) if k.is_finite() && k != 0.0 => Ok(factor * k),
            Some(k) => Err((
                format!("{here}.scale"),
                k.to_string(),
                "a finite, non-zero factor".into(),
            )),
        }
    }

    /// Reads a column map from a JSON file whose top level is a `columns` object (the same
    /// as a scenario's `excitation.columns`), for recorded files named on the command line.
    ///
    /// # Errors
    /// [`IoError::Io`] if the file cannot be read, [`IoError::JsonSyntax`] if it is not
    /// JSON, [`IoError::Json`] (with the JSON path) if it is not such an object, [`IoError::InvalidField`] for an unknown
    /// column or unit.
    pub fn load(path: &Path) -> Result<Self> {
        let spec: BTreeMap<String, ColumnSpec> = parse_json_file(path)?;
        Self::checked(path, &spec)
    }

    /// A column map given as JSON text (the object [`ColumnMap::load`] reads from a file,
    /// e.g. from Python's `columns=` dict); `origin` names it in messages.
    ///
    /// # Errors
    /// As [`ColumnMap::load`], but for reading a file.
    pub fn from_json(origin: &Path, text: &str) -> Result<Self> {
        let spec: BTreeMap<String, ColumnSpec> = parse_json(origin, text)?;
        Self::checked(origin, &spec)
    }

    fn checked(path: &Path, spec: &BTreeMap<String, ColumnSpec>) -> Result<Self> {
        Self::new(spec, "columns").map_err(|(json_path, value, expected)| IoError::InvalidField {
            path: path.to_owned(),
            json_path,
            value,
            expected,
        })
    }

    /// Reads platen's columns `required` and `optional` from the CSV file `path` through this
    /// map: the table holds them under platen's names, in SI units. A missing required
    /// column is reported under the file's header name.
    ///
    /// # Errors
    /// Every error of [`read_table`].
    pub fn read_table(&self, path: &Path, required: &[&str], optional: &[&str]) -> Result<Table> {
        if let Some(ours) = required.iter().find(|c| self.ignored(c)) {
            return Err(IoError::InvalidField {
                path: path.to_owned(),
                json_path: format!("columns.{ours}.ignore"),
                value: "true".into(),
                expected: format!("{ours} read: this reading needs it"),
            });
        }
        let optional: Vec<&str> = optional
            .iter()
            .copied()
            .filter(|c| !self.ignored(c))
            .collect();
        // A channel the map names must be in the file, even where the reading could do
        // without it: a map that names a header the file lacks is a mistake, not a choice.
        let (mapped, unmapped): (Vec<&str>, Vec<&str>) = optional
            .iter()
            .partition(|c| self.entries.contains_key(**c));
        let req: Vec<&str> = required
            .iter()
            .chain(&mapped)
            .map(|c| self.header(c))
            .collect();
        let opt: Vec<&str> = unmapped.iter().map(|c| self.header(c)).collect();
        let mut table = read_table(path, &req, &opt).map_err(|e| self.missing(e, required))?;
        for &ours in required.iter().chain(&optional) {
            match self.entries.get(ours) {
                Some(m) => table.rename_with(&m.header, ours, |c| m.apply(c)),
                None => table.rename_with(ours, ours, |_| ()),
            }
        }
        if let Some(t) = table.column("t_s") {
            check_record_rate(path, t, self.factor("t_s"))?;
        }
        Ok(table)
    }

    /// The header of `available` that a map example for a missing column of `kind` names:
    /// never one the map already reads, nor one that is a platen column itself (`t_s` for a
    /// missing displacement, `force_n`, …); a time-like header (`time`
    /// in it, or `t`) for the time, another for anything else; else the first free one.
    fn example_header<'a>(
        &self,
        available: &'a [String],
        required: &[&str],
        kind: Kind,
    ) -> &'a str {
        let taken = |h: &str| {
            self.entries.values().any(|m| !m.ignored && m.header == h)
                || required.contains(&h)
                || kind_of(h).is_some()
        };
        let time_like = |h: &str| {
            let h = h.trim().to_lowercase();
            h == "t" || h.contains("time")
        };
        let free: Vec<&str> = available
            .iter()
            .map(String::as_str)
            .filter(|h| !taken(h))
            .collect();
        free.iter()
            .find(|h| time_like(h) == (kind == Kind::Time))
            .or_else(|| free.first())
            .copied()
            .unwrap_or("…")
    }

    /// A missing column reported with what fixes it: the map's entry that names a header
    /// the file lacks, or for a platen column the map does not name, how a map would.
    fn missing(&self, e: IoError, required: &[&str]) -> IoError {
        let IoError::MissingColumn {
            path,
            column,
            available,
        } = e
        else {
            return e;
        };
        if let Some((ours, m)) = self
            .entries
            .iter()
            .find(|(_, m)| !m.ignored && m.header == column)
        {
            return IoError::MappedColumnMissing {
                path,
                column: ours.clone(),
                header: if m.named {
                    format!("the header `{}` (columns.{ours}.name)", m.header)
                } else {
                    format!("its own name `{ours}` (columns.{ours} gives no name)")
                },
                available,
            };
        }
        match kind_of(&column) {
            Some(kind) if required.contains(&column.as_str()) => {
                let name = self.example_header(&available, required, kind);
                let example = match example_unit(kind) {
                    Some(unit) => {
                        format!(r#"{{"{column}": {{"name": "{name}", "unit": "{unit}"}}}}"#)
                    }
                    None => format!(r#"{{"{column}": {{"name": "{name}"}}}}"#),
                };
                IoError::UnmappedColumn {
                    path,
                    column,
                    available,
                    example,
                }
            }
            _ => IoError::MissingColumn {
                path,
                column,
                available,
            },
        }
    }

    /// Whether platen's column `ours` is mapped with `ignore`: not read.
    pub fn ignored(&self, ours: &str) -> bool {
        self.entries.get(ours).is_some_and(|m| m.ignored)
    }

    /// The header to read for platen's column `ours`.
    pub fn header<'a>(&'a self, ours: &'a str) -> &'a str {
        self.entries.get(ours).map_or(ours, |m| m.header.as_str())
    }

    /// A column spec that reads platen's column `ours` exactly as this map reads it (its
    /// header, its whole factor to SI as `scale`, its offset and zero; not its delay; platen's
    /// own name for a channel the map leaves alone), for a scenario that must read the same
    /// file under another column's name (a command read as a motion's `u_m`).
    pub fn reading_spec(&self, ours: &str) -> ColumnSpec {
        let Some(m) = self.entries.get(ours) else {
            return ColumnSpec {
                name: Some(ours.to_owned()),
                ..ColumnSpec::default()
            };
        };
        if m.ignored {
            return ColumnSpec {
                ignore: true,
                ..ColumnSpec::default()
            };
        }
        ColumnSpec {
            name: Some(m.header.clone()),
            scale: (m.factor != 1.0).then_some(m.factor),
            offset: (m.offset != 0.0).then_some(m.offset),
            remove_mean: m.zero == Zero::Mean,
            zero_at_start: m.zero == Zero::Start,
            ..ColumnSpec::default()
        }
    }

    /// The factor from the file's unit to SI for platen's column `ours`.
    pub fn factor(&self, ours: &str) -> f64 {
        self.entries.get(ours).map_or(1.0, |m| m.factor)
    }

    /// The offset subtracted from platen's column `ours` before the conversion, in the file's
    /// unit (0 when none is given).
    pub fn offset(&self, ours: &str) -> f64 {
        self.entries.get(ours).map_or(0.0, |m| m.offset)
    }

    /// The known delay of platen's column `ours` relative to the displacement `u_m`, s
    /// (`delay_s` in the map; `None` when none is given). Validated (finite, below
    /// [`MAX_DELAY_S`] in magnitude) but not applied by [`ColumnMap::read_table`]: the
    /// channel is read as recorded, and identification corrects its skew.
    pub fn delay_s(&self, ours: &str) -> Option<f64> {
        self.entries.get(ours).and_then(|m| m.delay_s)
    }
}

/// The fastest sample rate a record is read at, Hz: ten times the 10 kHz of a fast
/// shake-table controller or data system. A time column faster than this is a unit slip
/// (seconds declared as ms give a thousand times the rate).
pub const MAX_RECORD_RATE_HZ: f64 = 100e3;

/// The slowest sample rate a record is read at, Hz: a shake-table record (a controller's or
/// a data system's, a PEER accelerogram's 50–200 Hz) is sampled far faster. A time column
/// of at least [`MIN_RATE_JUDGED_SAMPLES`] samples slower than this is a unit slip
/// (milliseconds read as seconds give a thousandth of the rate: a 1024 Hz record reads as
/// 1.024 Hz).
pub const MIN_RECORD_RATE_HZ: f64 = 5.0;

/// The fewest samples a time column needs for a low rate to be judged a slip: a short file
/// may be a profile of breakpoints (a force or a command linear between a few samples, a
/// ramp over 10 s in three rows), not a sampled record.
pub const MIN_RATE_JUDGED_SAMPLES: usize = 100;

/// Refuses a time column `t_s` (s, increasing) whose mean sample rate is above
/// [`MAX_RECORD_RATE_HZ`] or, over [`MIN_RATE_JUDGED_SAMPLES`] samples or more, below
/// [`MIN_RECORD_RATE_HZ`], naming what it reads as and the
/// likely slip: the file's time unit (`factor_to_s`, 1e-3 for `ms`) applied to values that
/// are already seconds, or seconds declared for values in milliseconds.
///
/// # Errors
/// [`IoError::Record`] naming `path`, the samples, span and rate, and the map that reads
/// the time in its unit.
pub fn check_record_rate(path: &Path, t_s: &[f64], factor_to_s: f64) -> Result<()> {
    let (Some(first), Some(last)) = (t_s.first(), t_s.last()) else {
        return Ok(());
    };
    let span = last - first;
    if t_s.len() < 2 || span.is_nan() || span <= 0.0 {
        return Ok(());
    }
    let rate = (t_s.len() - 1) as f64 / span;
    if rate < MIN_RECORD_RATE_HZ && t_s.len() >= MIN_RATE_JUDGED_SAMPLES {
        let slip = if factor_to_s == 1.0 {
            format!(
                "Are its values milliseconds? Then map its unit, \"columns\": {{\"t_s\": \
                 {{\"unit\": \"ms\"}}}} (a rate of {:.4} Hz)",
                rate * 1e3
            )
        } else {
            "Map the unit its values are in, e.g. \"columns\": {\"t_s\": {\"unit\": \
             \"ms\"}}"
                .to_owned()
        };
        return Err(IoError::Record {
            path: path.to_owned(),
            message: format!(
                "column t_s: {} samples over {} s, a sample rate of {:.4} Hz, below any \
                 shake-table record (at least {MIN_RECORD_RATE_HZ} Hz is read). {slip}",
                t_s.len(),
                span,
                rate
            ),
        });
    }
    if rate <= MAX_RECORD_RATE_HZ {
        return Ok(());
    }
    let slip = if factor_to_s < 1.0 {
        let unit = if factor_to_s == 1e-3 {
            "ms".to_owned()
        } else {
            format!("{factor_to_s} s")
        };
        format!(
            "Its unit is declared as {unit}: are its values seconds already? Then map it \
             \"columns\": {{\"t_s\": {{\"unit\": \"s\"}}}} (a rate of {:.4} Hz)",
            rate * factor_to_s
        )
    } else {
        "Is the time in another unit than seconds (samples, µs)? Map its unit, e.g. \
         \"columns\": {\"t_s\": {\"unit\": \"ms\"}}"
            .to_owned()
    };
    Err(IoError::Record {
        path: path.to_owned(),
        message: format!(
            "column t_s: {} samples over {} s, a sample rate of {:.4e} Hz, beyond any \
             shake-table record (at most {MAX_RECORD_RATE_HZ:e} Hz is read). {slip}",
            t_s.len(),
            span,
            rate
        ),
    })
}

enum UnitKind {
    Of(Kind),
    Pressure,
}

/// A unit of kind `k` for an example map (none for a drive).
fn example_unit(k: Kind) -> Option<&'static str> {
    Some(match k {
        Kind::Time => "s",
        Kind::Displacement => "mm",
        Kind::Velocity => "mm/s",
        Kind::Acceleration => "g",
        Kind::Force => "kN",
        Kind::Pressure => "MPa",
        Kind::Drive => "V",
    })
}

/// What a map's `unit` for a column of kind `k` should be, listing the accepted units.
fn expected_unit(k: Kind) -> String {
    match k {
        Kind::Drive => format!("no unit or V: {}", kind_name(k)),
        _ => format!("a unit of {}", kind_name(k)),
    }
}

fn kind_name(k: Kind) -> &'static str {
    match k {
        Kind::Time => "time (s, ms)",
        Kind::Displacement => "displacement (m, mm, cm, in)",
        Kind::Velocity => "velocity (m/s, mm/s, cm/s, in/s)",
        Kind::Acceleration => "acceleration (m/s2, mm/s2, cm/s2, gal, in/s2, g)",
        Kind::Force => {
            "force (N, kN, MN, lbf, kip) or a pressure (Pa, kPa, MPa, bar, psi) with times_area_m2"
        }
        Kind::Drive => {
            "a drive is a fraction of full opening; in volts, unit V with scale 1/(full-scale \
             volts), e.g. 0.1 for ±10 V"
        }
        Kind::Pressure => "pressure (Pa, kPa, MPa, bar, psi)",
    }
}

fn unit_factor(unit: &str) -> Option<(UnitKind, f64)> {
    use Kind::*;
    let inch = 0.0254;
    Some(match unit.trim() {
        "s" => (UnitKind::Of(Time), 1.0),
        "ms" => (UnitKind::Of(Time), 1e-3),
        "m" => (UnitKind::Of(Displacement), 1.0),
        "mm" => (UnitKind::Of(Displacement), 1e-3),
        "cm" => (UnitKind::Of(Displacement), 1e-2),
        "in" => (UnitKind::Of(Displacement), inch),
        "m/s" => (UnitKind::Of(Velocity), 1.0),
        "mm/s" => (UnitKind::Of(Velocity), 1e-3),
        "cm/s" => (UnitKind::Of(Velocity), 1e-2),
        "in/s" => (UnitKind::Of(Velocity), inch),
        "m/s2" | "m/s^2" | "m/s²" => (UnitKind::Of(Acceleration), 1.0),
        "mm/s2" | "mm/s^2" | "mm/s²" => (UnitKind::Of(Acceleration), 1e-3),
        "cm/s2" | "cm/s^2" | "cm/s²" | "gal" => (UnitKind::Of(Acceleration), 1e-2),
        "in/s2" | "in/s^2" | "in/s²" => (UnitKind::Of(Acceleration), inch),
        "g" => (UnitKind::Of(Acceleration), STANDARD_GRAVITY_M_S2),
        "N" => (UnitKind::Of(Force), 1.0),
        "kN" => (UnitKind::Of(Force), 1e3),
        "MN" => (UnitKind::Of(Force), 1e6),
        "lbf" => (UnitKind::Of(Force), 4.448_221_615_260_5),
        "kip" => (UnitKind::Of(Force), 4_448.221_615_260_5),
        "Pa" => (UnitKind::Pressure, 1.0),
        "kPa" => (UnitKind::Pressure, 1e3),
        "MPa" => (UnitKind::Pressure, 1e6),
        "bar" => (UnitKind::Pressure, 1e5),
        "psi" => (UnitKind::Pressure, 6_894.757_293_168),
        // A drive recorded in volts: its `scale` (1 over the full-scale voltage) makes it the
        // fraction of full opening.
        "V" => (UnitKind::Of(Drive), 1.0),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(json: &str) -> Result<ColumnMap, (String, String, String)> {
        let spec: BTreeMap<String, ColumnSpec> = serde_json::from_str(json).unwrap();
        ColumnMap::new(&spec, "excitation.columns")
    }

    #[test]
    fn a_map_given_as_json_text_is_checked_and_named_by_its_origin() {
        let m = ColumnMap::from_json(
            Path::new("columns="),
            r#"{"u_m": {"name": "disp", "unit": "mm"}}"#,
        )
        .unwrap();
        assert_eq!((m.header("u_m"), m.factor("u_m")), ("disp", 1e-3));
        let e = ColumnMap::from_json(Path::new("columns="), r#"{"u_m": {"unit": "furlong"}}"#)
            .unwrap_err();
        assert!(
            matches!(&e, IoError::InvalidField { json_path, .. } if json_path == "columns.u_m.unit"),
            "{e:?}"
        );
        assert!(
            e.to_string().starts_with("`columns=`: columns.u_m.unit"),
            "{e}"
        );
    }

    /// A drive recorded in volts maps with its scale; without one it is refused at
    /// `….drive.scale`, with the fix (issue 33).
    #[test]
    fn a_drive_in_volts_needs_its_scale() {
        let m =
            map(r#"{"drive": {"name": "Voltage command", "unit": "V", "scale": 0.1}}"#).unwrap();
        assert_eq!(
            (m.header("drive"), m.factor("drive")),
            ("Voltage command", 0.1)
        );
        let (path, _, expected) =
            map(r#"{"drive": {"name": "Voltage command", "unit": "V"}}"#).unwrap_err();
        assert_eq!(path, "excitation.columns.drive.scale");
        assert!(expected.contains("0.1 for a ±10 V"), "{expected}");
        // Volts are a drive's unit only.
        let (path, _, _) = map(r#"{"u_m": {"unit": "V"}}"#).unwrap_err();
        assert_eq!(path, "excitation.columns.u_m.unit");
    }

    /// A reading spec reads a channel as the map does: the header, the whole factor as
    /// `scale`, the offset and the zero.
    #[test]
    fn a_reading_spec_reads_as_the_map_does() {
        let m = map(
            r#"{"command_u_m": {"name": "Cmd", "unit": "mm", "offset": 0.5, "zero_at_start": true},
                        "a_m_s2": {"ignore": true}}"#,
        )
        .unwrap();
        let spec = m.reading_spec("command_u_m");
        assert_eq!(spec.name.as_deref(), Some("Cmd"));
        assert_eq!(spec.scale, Some(1e-3));
        assert_eq!(spec.offset, Some(0.5));
        assert!(spec.zero_at_start && !spec.remove_mean && spec.unit.is_none());
        let again = map(&format!(
            r#"{{"u_m": {}}}"#,
            serde_json::to_string(&spec).unwrap()
        ))
        .unwrap();
        assert_eq!(again.factor("u_m"), m.factor("command_u_m"));
        assert_eq!(again.offset("u_m"), m.offset("command_u_m"));
        assert!(m.reading_spec("a_m_s2").ignore);
        // A channel the map leaves alone is read by platen's own name.
        assert_eq!(m.reading_spec("t_s").name.as_deref(), Some("t_s"));
    }

    #[test]
    fn lab_channels_map_to_si_columns() {
        let m = map(r#"{"u_m": {"name": "Table disp", "unit": "mm"}, "a_m_s2": {"name": "acc (g)", "unit": "g"},
                        "force_n": {"name": "dP", "unit": "MPa", "times_area_m2": 0.33}}"#)
        .unwrap();
        assert_eq!(m.header("u_m"), "Table disp");
        assert_eq!(m.factor("u_m"), 1e-3);
        assert_eq!(m.factor("a_m_s2"), 9.80665);
        assert!((m.factor("force_n") - 0.33e6).abs() < 1e-6);
        assert_eq!(m.header("t_s"), "t_s");
        assert_eq!(m.factor("t_s"), 1.0);
    }

    #[test]
    fn table_system_channels_map_with_units_and_a_scale() {
        let m = map(r#"{"command_u_m": {"name": "Cmd", "unit": "mm"}, "drive": {"name": "Drive V", "scale": 0.1},
                        "delta_p_pa": {"name": "dP", "unit": "MPa"}, "storey2_a_m_s2": {"unit": "g", "scale": 2}}"#)
        .unwrap();
        assert_eq!(
            (m.header("command_u_m"), m.factor("command_u_m")),
            ("Cmd", 1e-3)
        );
        assert_eq!((m.header("drive"), m.factor("drive")), ("Drive V", 0.1));
        assert_eq!(m.factor("delta_p_pa"), 1e6);
        assert_eq!(m.factor("storey2_a_m_s2"), 2.0 * 9.80665);
        for (json, path) in [
            (r#"{"drive": {"unit": "mm"}}"#, "c.drive.unit"),
            (r#"{"delta_p_pa": {"unit": "kN"}}"#, "c.delta_p_pa.unit"),
            (r#"{"u_m": {"scale": 0}}"#, "c.u_m.scale"),
            (r#"{"storey0_a_m_s2": {}}"#, "c.storey0_a_m_s2"),
            (r#"{"storey_a_m_s2": {}}"#, "c.storey_a_m_s2"),
        ] {
            let spec: BTreeMap<String, ColumnSpec> = serde_json::from_str(json).unwrap();
            let e = ColumnMap::new(&spec, "c").unwrap_err();
            assert_eq!(e.0, path, "{json}: {e:?}");
        }
    }

    #[test]
    fn wrong_units_name_their_json_path() {
        for (json, path) in [
            (r#"{"u_m": {"unit": "g"}}"#, "excitation.columns.u_m.unit"),
            (
                r#"{"u_m": {"unit": "furlong"}}"#,
                "excitation.columns.u_m.unit",
            ),
            (r#"{"disp": {"unit": "mm"}}"#, "excitation.columns.disp"),
            (
                r#"{"force_n": {"unit": "MPa"}}"#,
                "excitation.columns.force_n.unit",
            ),
            (
                r#"{"force_n": {"unit": "kN", "times_area_m2": 0.3}}"#,
                "excitation.columns.force_n.times_area_m2",
            ),
            (
                r#"{"force_n": {"unit": "MPa", "times_area_m2": -1}}"#,
                "excitation.columns.force_n.times_area_m2",
            ),
        ] {
            let e = map(json).unwrap_err();
            assert_eq!(e.0, path, "{json}: {e:?}");
        }
    }

    /// A pressure transducer reading −0.13 MPa at zero load: the offset is subtracted in the
    /// file's unit before the area multiplies it, so 0.87 MPa on 0.33 m² is 1.0 MPa·0.33 m².
    #[test]
    fn an_offset_is_subtracted_in_the_files_unit_and_the_zero_can_be_set() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lab.csv");
        std::fs::write(&path, "time,dP,disp\n1,-0.13,5\n2,0.87,7\n3,0.37,12\n").unwrap();
        let m = map(r#"{"t_s": {"name": "time", "zero_at_start": true},
                        "force_n": {"name": "dP", "unit": "MPa", "times_area_m2": 0.33, "offset": -0.13},
                        "u_m": {"name": "disp", "unit": "mm", "remove_mean": true}}"#)
        .unwrap();
        assert_eq!(m.offset("force_n"), -0.13);
        let mut t = m
            .read_table(&path, &["t_s", "force_n", "u_m"], &[])
            .unwrap();
        assert_eq!(t.take_column("t_s").unwrap(), vec![0.0, 1.0, 2.0]);
        let f = t.take_column("force_n").unwrap();
        for (got, want) in f.iter().zip([0.0, 0.33e6, 0.165e6]) {
            assert!((got - want).abs() < 1e-6, "{f:?}");
        }
        // (5, 7, 12) mm less their mean 8 mm.
        let u = t.take_column("u_m").unwrap();
        for (got, want) in u.iter().zip([-3e-3, -1e-3, 4e-3]) {
            assert!((got - want).abs() < 1e-15, "{u:?}");
        }
        let m = map(r#"{"u_m": {"name": "disp", "zero_at_start": true, "offset": 1}}"#).unwrap();
        let mut t = m.read_table(&path, &["u_m"], &[]).unwrap();
        assert_eq!(t.take_column("u_m").unwrap(), vec![0.0, 2.0, 7.0]);
    }

    #[test]
    fn an_ignored_column_is_not_read_and_must_be_alone_and_optional() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rec.csv");
        std::fs::write(&path, "t_s,command_u_m,a_m_s2\n0,1,9\n1,2,9\n").unwrap();
        let m = map(r#"{"u_m": {"name": "command_u_m"}, "a_m_s2": {"ignore": true}}"#).unwrap();
        assert!(m.ignored("a_m_s2") && !m.ignored("u_m"));
        let mut t = m
            .read_table(&path, &["t_s", "u_m"], &["v_m_s", "a_m_s2"])
            .unwrap();
        assert_eq!(t.take_column("u_m").unwrap(), vec![1.0, 2.0]);
        assert_eq!(t.take_column("a_m_s2"), None);
        let e = m.read_table(&path, &["t_s", "a_m_s2"], &[]).unwrap_err();
        assert!(e.to_string().contains("columns.a_m_s2.ignore"), "{e}");
        for (json, at) in [
            (
                r#"{"a_m_s2": {"ignore": true, "unit": "g"}}"#,
                "a_m_s2.ignore",
            ),
            (r#"{"t_s": {"ignore": true}}"#, "t_s.ignore"),
        ] {
            let e = map(json).unwrap_err();
            assert_eq!(e.0, format!("excitation.columns.{at}"), "{json}: {e:?}");
        }
    }

    #[test]
    fn zero_options_that_contradict_or_make_no_sense_name_their_json_path() {
        for (json, path) in [
            (
                r#"{"u_m": {"remove_mean": true, "zero_at_start": true}}"#,
                "excitation.columns.u_m.remove_mean",
            ),
            (
                r#"{"t_s": {"remove_mean": true}}"#,
                "excitation.columns.t_s.remove_mean",
            ),
        ] {
            let e = map(json).unwrap_err();
            assert_eq!(e.0, path, "{json}: {e:?}");
        }
        // A non-finite offset cannot be written in JSON; one given programmatically is refused.
        let spec = BTreeMap::from([(
            "u_m".to_owned(),
            ColumnSpec {
                offset: Some(f64::NAN),
                ..ColumnSpec::default()
            },
        )]);
        let e = ColumnMap::new(&spec, "columns").unwrap_err();
        assert_eq!(e.0, "columns.u_m.offset");
    }
}
