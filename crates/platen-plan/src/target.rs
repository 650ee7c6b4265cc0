//! The target: what the table should do, as an acceleration or a displacement record on a
//! uniform time base ([`Target`]).

use std::path::{Path, PathBuf};

use platen_io::columns::ColumnMap;
use platen_io::IoError;

use crate::error::{PlanError, Result};

/// The fewest samples a target may have: the iteration works on its spectrum, and fewer
/// samples than this carry no usable band.
pub const MIN_TARGET_SAMPLES: usize = 16;

/// The times `t_s` of the target file at `path` checked as the file's own (so that the
/// errors name the file and line): at least [`MIN_TARGET_SAMPLES`] rows, a uniform grid.
pub(crate) fn checked_times(path: &Path, t_s: &[f64]) -> Result<platen_integrate::SamplingGrid> {
    if t_s.len() < MIN_TARGET_SAMPLES {
        return Err(IoError::TooShort {
            path: path.to_owned(),
            rows: t_s.len(),
            needed: MIN_TARGET_SAMPLES,
        }
        .into());
    }
    Ok(platen_scenario::sampling::sampling_grid(path, t_s)?)
}

/// A synthetic earthquake-like acceleration at `t_s`, m/s², for trying a plan without a
/// record: `sines` (frequency Hz, weight, phase rad) summed under a rise–hold–decay envelope
/// (still to 1 s, rising quadratically to 6 s, held to 14 s, then decaying with 6 s), scaled
/// by `peak_g`·g/2.
pub fn enveloped_sines_m_s2(t_s: f64, peak_g: f64, sines: &[(f64, f64, f64)]) -> f64 {
    let env = if t_s < 1.0 {
        0.0
    } else if t_s < 6.0 {
        ((t_s - 1.0) / 5.0).powi(2)
    } else {
        (-(t_s - 14.0).max(0.0) / 6.0).exp()
    };
    let s: f64 = sines
        .iter()
        .map(|(f, a, p)| a * (std::f64::consts::TAU * f * t_s + p).sin())
        .sum();
    peak_g * 9.806_65 * env * s / 2.0
}

/// The synthetic three-component target of the three-component plan's bench and release
/// test, m/s², at the times `t_s`: per axis (x, y, z) [`enveloped_sines_m_s2`] with five
/// sines of its own, about 0.25, 0.2 and 0.15 g at the peak (Tarzana's at 25 %).
pub fn synthetic_three_component_m_s2(t_s: &[f64]) -> [Vec<f64>; 3] {
    /// Per axis: its peak, g, and its sines (frequency Hz, weight, phase rad).
    type Axis = (f64, [(f64, f64, f64); 5]);
    const AXES: [Axis; 3] = [
        (
            0.25,
            [
                (0.7, 0.3, 0.0),
                (1.9, 1.0, 1.1),
                (3.3, 0.8, 2.3),
                (6.1, 0.6, 0.4),
                (11.0, 0.4, 5.0),
            ],
        ),
        (
            0.2,
            [
                (0.9, 0.4, 0.7),
                (2.3, 1.0, 0.2),
                (4.1, 0.7, 1.9),
                (7.3, 0.5, 3.1),
                (13.0, 0.3, 0.9),
            ],
        ),
        (
            0.15,
            [
                (1.3, 0.3, 2.2),
                (3.7, 0.8, 0.5),
                (6.7, 1.0, 1.4),
                (11.0, 0.6, 2.8),
                (17.0, 0.4, 0.1),
            ],
        ),
    ];
    AXES.map(|(peak_g, sines)| {
        t_s.iter()
            .map(|&t| enveloped_sines_m_s2(t, peak_g, &sines))
            .collect()
    })
}

/// What a target prescribes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetKind {
    /// The table's acceleration (`a_m_s2`): the displacement command is integrated from it
    /// with the baseline treatment of [`crate::baseline`].
    Acceleration,
    /// The table's displacement (`u_m`): the command as it is; the acceleration to reproduce
    /// is its second derivative (second-order finite differences, as `simulate` derives it).
    Displacement,
}

impl TargetKind {
    /// `"acceleration"` or `"displacement"`.
    pub fn name(self) -> &'static str {
        match self {
            TargetKind::Acceleration => "acceleration",
            TargetKind::Displacement => "displacement",
        }
    }
}

/// A validated target: at least [`MIN_TARGET_SAMPLES`] finite samples on a uniform,
/// strictly increasing time base.
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    origin: PathBuf,
    t_s: Vec<f64>,
    values: Vec<f64>,
    kind: TargetKind,
    interval_s: f64,
}

impl Target {
    /// A target acceleration `a_m_s2` (m/s²) at the times `t_s`; `origin` names it in
    /// messages.
    ///
    /// # Errors
    /// [`PlanError::Target`] naming the 0-based index of a non-finite value, a time that does
    /// not increase or leaves the uniform grid, columns of different lengths, or fewer than
    /// [`MIN_TARGET_SAMPLES`] samples.
    pub fn acceleration(origin: &Path, t_s: Vec<f64>, a_m_s2: Vec<f64>) -> Result<Self> {
        Self::new(origin, t_s, a_m_s2, TargetKind::Acceleration)
    }

    /// A target displacement `u_m` (m) at the times `t_s`.
    ///
    /// # Errors
    /// As [`Target::acceleration`].
    pub fn displacement(origin: &Path, t_s: Vec<f64>, u_m: Vec<f64>) -> Result<Self> {
        Self::new(origin, t_s, u_m, TargetKind::Displacement)
    }

    fn new(origin: &Path, t_s: Vec<f64>, values: Vec<f64>, kind: TargetKind) -> Result<Self> {
        let bad = |message: String| PlanError::Target {
            origin: origin.display().to_string(),
            message,
        };
        let name = match kind {
            TargetKind::Acceleration => "a_m_s2",
            TargetKind::Displacement => "u_m",
        };
        if values.len() != t_s.len() {
            return Err(bad(format!(
                "`{name}` has {} values but `t_s` has {}",
                values.len(),
                t_s.len()
            )));
        }
        if t_s.len() < MIN_TARGET_SAMPLES {
            return Err(bad(format!(
                "{} samples: expected at least {MIN_TARGET_SAMPLES}",
                t_s.len()
            )));
        }
        for (column, data) in [("t_s", &t_s), (name, &values)] {
            if let Some(i) = data.iter().position(|v| !v.is_finite()) {
                return Err(bad(format!("{column}[{i}] = {} is not finite", data[i])));
            }
        }
        let grid = platen_integrate::sampling_grid(&t_s).map_err(|e| bad(e.to_string()))?;
        Ok(Self {
            origin: origin.to_owned(),
            t_s,
            values,
            kind,
            interval_s: grid.interval_s,
        })
    }

    /// Reads a target CSV: `t_s` and `a_m_s2` (an acceleration target) or, without
    /// `a_m_s2`, `u_m` (a displacement target); other columns are ignored.
    ///
    /// # Errors
    /// [`PlanError::Io`] naming the file and the line: unreadable, no `t_s` or neither
    /// `a_m_s2` nor `u_m`, a non-numeric or non-finite cell, times that do not increase
    /// strictly or are not uniformly sampled ([`platen_scenario::sampling::sampling_grid`]),
    /// fewer than [`MIN_TARGET_SAMPLES`] rows.
    pub fn read_csv(path: &Path) -> Result<Self> {
        Self::read_csv_mapped(path, &ColumnMap::default())
    }

    /// Reads a lab's target CSV through the column map `columns` (its own headers and units,
    /// `g` or `mm` say, as a scenario's `excitation.columns` and `--columns` of `compare` and
    /// `identify`): platen's `t_s` and `a_m_s2`, or without `a_m_s2`, `u_m`. The empty map is
    /// [`Target::read_csv`].
    ///
    /// # Errors
    /// As [`Target::read_csv`]; a missing column is named by its header in the file.
    pub fn read_csv_mapped(path: &Path, columns: &ColumnMap) -> Result<Self> {
        let read_table =
            |required: &[&str], optional: &[&str]| columns.read_table(path, required, optional);
        // The acceleration when the file has one (a displacement column beside it is not
        // read, so it cannot fail the target); else the displacement.
        let mut table = read_table(&["t_s"], &["a_m_s2"])?;
        let (kind, values) = match table.take_column("a_m_s2") {
            Some(a) => (TargetKind::Acceleration, a),
            None => {
                let either = "a_m_s2` or `u_m".to_owned();
                table = read_table(&["t_s", "u_m"], &[]).map_err(|e| match e {
                    IoError::MissingColumn {
                        path, available, ..
                    } => IoError::MissingColumn {
                        path,
                        column: either,
                        available,
                    },
                    IoError::UnmappedColumn {
                        path,
                        column,
                        available,
                        example,
                    } if column == "u_m" => IoError::UnmappedColumn {
                        path,
                        column: either,
                        available,
                        example,
                    },
                    other => other,
                })?;
                let u = table.take_column("u_m").unwrap_or_default();
                (TargetKind::Displacement, u)
            }
        };
        let t_s = table.take_column("t_s").unwrap_or_default();
        let grid = checked_times(path, &t_s)?;
        Ok(Self {
            origin: path.to_owned(),
            t_s,
            values,
            kind,
            interval_s: grid.interval_s,
        })
    }

    /// This target on the grid of `rate_hz`, slower than its own, from its first time stamp:
    /// low-passed and resampled by [`platen_signal::Resampler`] (a zero-phase windowed-sinc
    /// anti-alias filter with its −6 dB cut-off at `0.4·rate_hz`: content below
    /// `0.3·rate_hz` keeps its phase and, within 0.5 %, its amplitude; content at the new
    /// Nyquist frequency and above is down to −50 dB before it could alias).
    ///
    /// # Errors
    /// [`PlanError::Target`] if the resampled record is not a target (fewer than
    /// [`MIN_TARGET_SAMPLES`] samples at the new rate).
    pub fn resampled_to(&self, rate_hz: f64) -> Result<Self> {
        let bad = |message: String| PlanError::Target {
            origin: self.origin.display().to_string(),
            message,
        };
        let values = platen_signal::Resampler::new(
            self.sample_rate_hz(),
            rate_hz,
            platen_signal::Interpolation::Cubic,
        )
        .and_then(|r| r.apply(&self.values))
        .map_err(|e| bad(format!("resampling it to {rate_hz} Hz: {e}")))?;
        let t0 = self.t_s[0];
        let t_s = (0..values.len()).map(|k| t0 + k as f64 / rate_hz).collect();
        Self::new(&self.origin, t_s, values, self.kind)
    }

    /// Where the target comes from.
    pub fn origin(&self) -> &Path {
        &self.origin
    }

    /// Acceleration or displacement.
    pub fn kind(&self) -> TargetKind {
        self.kind
    }

    /// The time stamps, s.
    pub fn t_s(&self) -> &[f64] {
        &self.t_s
    }

    /// The prescribed values: m/s² for an acceleration target, m for a displacement target.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Always false: a target has at least [`MIN_TARGET_SAMPLES`] samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// The sample interval fitted over the whole record, s.
    pub fn interval_s(&self) -> f64 {
        self.interval_s
    }

    /// The sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        1.0 / self.interval_s
    }

    /// The time from the first to the last sample, s.
    pub fn duration_s(&self) -> f64 {
        self.t_s[self.t_s.len() - 1] - self.t_s[0]
    }
}
