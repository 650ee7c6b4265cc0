//! A multi-axis plan's inputs: the scenario file read without its excitation, and the target
//! of up to three axes on one time base ([`AxisTargets`]).

use std::path::{Path, PathBuf};

use platen_io::IoError;
use platen_scenario::file::ScenarioFile;
use platen_scenario::multi_axis::{ACCELERATION_COLUMNS, POSE_COLUMNS};

use crate::error::{PlanError, Result};
use crate::steps::Resampled;
use crate::target::Target;

/// The scenario JSON `text` (from `path`, for messages) if it is a multi-axis one (it has a
/// `table`), parsed, its `excitation` optional (a plan's target takes its place, and a
/// commanded table does not read it); `None` for JSON without a `table`, which the
/// single-axis planner reads and reports on.
///
/// # Errors
/// [`PlanError::Io`] for text that is not JSON (its line and column) and for a multi-axis
/// scenario that does not parse (its path and line).
pub fn table_scenario_file(path: &Path, text: &str) -> Result<Option<ScenarioFile>> {
    let Ok(mut value) = serde_json::from_str::<serde_json::Value>(text) else {
        // Not JSON: its syntax error, at its line and column, as `simulate` reports it.
        return Ok(Some(platen_io::json::parse_json(path, text)?));
    };
    let Some(object) = value.as_object_mut().filter(|o| o.contains_key("table")) else {
        return Ok(None);
    };
    if object.contains_key("excitation") {
        return Ok(Some(platen_io::json::parse_json(path, text)?));
    }
    // No excitation: an empty one.
    object.insert("excitation".into(), serde_json::json!({}));
    let pretty = serde_json::to_string_pretty(&value).map_err(|e| IoError::Record {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    Ok(Some(platen_io::json::parse_json(path, &pretty)?))
}

/// [`table_scenario_file`] of the file at `path`; `None` also for a file that cannot be
/// read (the single-axis planner reports it).
///
/// # Errors
/// As [`table_scenario_file`].
pub fn read_table_scenario(path: &Path) -> Result<Option<ScenarioFile>> {
    match std::fs::read_to_string(path) {
        Ok(text) => table_scenario_file(path, &text),
        Err(_) => Ok(None),
    }
}

/// The drive CSV's columns: a six-DOF `motion_csv`.
pub const DRIVE_COLUMNS: [&str; 7] = [
    "t_s",
    "x_m",
    "y_m",
    "z_m",
    "roll_rad",
    "pitch_rad",
    "yaw_rad",
];

/// The translational axes a target gives, in order.
pub const AXES: [&str; 3] = ["x", "y", "z"];

/// A target of up to three axes on one time base.
#[derive(Debug, Clone)]
pub struct AxisTargets {
    origin: PathBuf,
    /// Per axis (x, y, z), its target (absent: held at zero).
    axes: [Option<Target>; 3],
}

impl AxisTargets {
    /// The targets of the axes given (`None`: held at zero), all on the same times.
    ///
    /// # Errors
    /// [`PlanError::Target`] when no axis is given or the axes' times differ.
    pub fn new(origin: &Path, axes: [Option<Target>; 3]) -> Result<Self> {
        let bad = |message: String| PlanError::Target {
            origin: origin.display().to_string(),
            message,
        };
        let mut given = axes.iter().flatten();
        let first = given
            .next()
            .ok_or_else(|| bad("no axis: expected at least one of x, y, z".into()))?;
        if given.any(|t| t.t_s() != first.t_s()) {
            return Err(bad("the axes' targets have different times".into()));
        }
        Ok(Self {
            origin: origin.to_owned(),
            axes,
        })
    }

    /// Reads a target CSV: `t_s` and, per axis, `x_m_s2` (an acceleration target) or, without
    /// it, `x_m` (a displacement); the same for y and z. Other columns are ignored.
    ///
    /// # Errors
    /// [`PlanError::Io`] naming the file and line: unreadable, no `t_s`, none of the axes'
    /// columns, a bad cell, times that do not increase strictly or are not uniform, fewer
    /// than [`MIN_TARGET_SAMPLES`](crate::MIN_TARGET_SAMPLES) rows.
    pub fn read_csv(path: &Path) -> Result<Self> {
        let optional: Vec<&'static str> = ACCELERATION_COLUMNS[..3]
            .iter()
            .chain(&POSE_COLUMNS[..3])
            .copied()
            .collect();
        let mut table = platen_io::csv::read_table(path, &["t_s"], &optional)?;
        let t_s = table.take_column("t_s").unwrap_or_default();
        // The file's own checks first, so that they name the file and line.
        crate::target::checked_times(path, &t_s)?;
        platen_io::columns::check_record_rate(path, &t_s, 1.0)?;
        let mut axes: [Option<Target>; 3] = [None, None, None];
        for (k, axis) in axes.iter_mut().enumerate() {
            *axis = match (
                table.take_column(ACCELERATION_COLUMNS[k]),
                table.take_column(POSE_COLUMNS[k]),
            ) {
                (Some(a), _) => Some(Target::acceleration(path, t_s.clone(), a)?),
                (None, Some(u)) => Some(Target::displacement(path, t_s.clone(), u)?),
                (None, None) => None,
            };
        }
        if axes.iter().all(Option::is_none) {
            return Err(IoError::Record {
                path: path.to_owned(),
                message: "a three-component target needs at least one of the columns x_m_s2, \
                          y_m_s2, z_m_s2 (or the displacements x_m, y_m, z_m); absent axes are \
                          held at zero"
                    .into(),
            }
            .into());
        }
        Self::new(path, axes)
    }

    /// Every axis put on `rate_hz` ([`Target::resampled_to`]: anti-aliased when slower).
    ///
    /// # Errors
    /// As [`Target::resampled_to`].
    pub fn resampled_to(&self, rate_hz: f64) -> Result<Self> {
        let mut axes: [Option<Target>; 3] = [None, None, None];
        for (to, from) in axes.iter_mut().zip(&self.axes) {
            *to = from.as_ref().map(|t| t.resampled_to(rate_hz)).transpose()?;
        }
        Self::new(&self.origin, axes)
    }

    /// Where the target comes from.
    pub fn origin(&self) -> &Path {
        &self.origin
    }

    /// Per axis (x, y, z), its target.
    pub fn axes(&self) -> &[Option<Target>; 3] {
        &self.axes
    }

    /// The first axis's target (every axis has its times).
    fn first(&self) -> &Target {
        self.axes
            .iter()
            .flatten()
            .next()
            .expect("AxisTargets::new holds at least one axis")
    }

    /// The times, s.
    pub fn t_s(&self) -> &[f64] {
        self.first().t_s()
    }

    /// The sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.first().sample_rate_hz()
    }
}

impl Resampled for AxisTargets {
    fn sample_rate_hz(&self) -> f64 {
        AxisTargets::sample_rate_hz(self)
    }
    fn resampled_to(&self, rate_hz: f64) -> Result<Self> {
        AxisTargets::resampled_to(self, rate_hz)
    }
}
