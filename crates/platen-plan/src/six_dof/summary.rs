//! The summary `platen plan --json` prints for a multi-axis scenario
//! ([`TablePlanSummary`]); `platen_report` renders it in words.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use crate::baseline::peak;
use crate::feasibility::MaxScale;
use crate::iterate::SpectrumAcceptance;
use crate::mimo::MimoRecord;

use super::limits::{failing, TableLimitUse};
use super::{TablePlan, TablePlannedDrive, AXES};
use crate::plan::PlanSettings;
use crate::steps::IterationOutcome;

/// One axis of the target, as the summary reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisTargetSummary {
    /// `acceleration` or `displacement`.
    pub kind: &'static str,
    /// Largest acceleration to reproduce (after the baseline treatment), m/s².
    pub peak_a_m_s2: f64,
    /// Largest displacement of its command, m.
    pub peak_u_m: f64,
    /// RMS of its acceleration, m/s².
    pub rms_a_m_s2: f64,
    /// The end-correction degree (acceleration targets).
    pub baseline_degree: Option<usize>,
    /// RMS of the acceleration the baseline treatment removed, m/s².
    pub baseline_correction_rms_m_s2: f64,
}

/// The target, as the summary reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableTargetSummary {
    /// Its file (or origin).
    pub file: String,
    /// Samples of the target.
    pub samples: usize,
    /// Its sample rate, Hz.
    pub sample_rate_hz: f64,
    /// The drive's rate (the controller's), Hz.
    pub drive_sample_rate_hz: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Per axis given; the others are held at zero.
    pub axes: BTreeMap<&'static str, AxisTargetSummary>,
}

/// The matrix `Ĥ` and the iteration's settings, as the summary reports them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MatrixFrfSummary {
    /// `linearised` (the x, y, z block of the table's linearised command → pose matrix).
    pub source: &'static str,
    /// The correction band, Hz.
    pub band_hz: [f64; 2],
    /// The gain `g`.
    pub gain: f64,
    /// `ε` of the regularised inverse.
    pub regularisation: f64,
    /// FFT length (record and padding), samples.
    pub fft_len: usize,
    /// The largest condition number of `Ĥ` in the band.
    pub max_condition: f64,
}

/// The drives, as the summary reports them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableDriveSummary {
    /// The CSV written, if any.
    pub out: Option<String>,
    /// Samples.
    pub samples: usize,
    /// Per axis, the drive's largest displacement, m.
    pub peak_u_m: BTreeMap<&'static str, f64>,
    /// What the drives achieve at full level (the best iteration's run; with `iterate_at`,
    /// the scaled-up drives' run: the predicted full-level error).
    pub achieved: MimoRecord,
    /// With `iterate_at`, what the best iteration achieved at that level (`null` otherwise).
    pub at_iteration_level: Option<MimoRecord>,
    /// The limits the drives' run exceeds, worst first.
    pub limiting: Vec<TableLimitUse>,
    /// Per axis given, its achieved response spectrum against its required one.
    pub spectrum_acceptance: BTreeMap<&'static str, SpectrumAcceptance>,
}

/// What `platen plan --json` prints for a multi-axis scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TablePlanSummary {
    /// The scenario file.
    pub scenario: String,
    /// The scenario's name.
    pub name: String,
    /// The target.
    pub target: TableTargetSummary,
    /// Whether the target's own commands respect every limit.
    pub feasible: bool,
    /// The limits that fail, worst first.
    pub limiting: Vec<TableLimitUse>,
    /// The failing limit exceeded first, with when (`null` when feasible).
    pub binds_first: Option<TableLimitUse>,
    /// Every limit with its peak, allowed value, ratio and times.
    pub margins: Vec<TableLimitUse>,
    /// The largest common scale that fits (`null` when not searched).
    pub max_scale: Option<f64>,
    /// How it was found (`null` when not searched).
    pub max_scale_search: Option<MaxScale>,
    /// Per axis, the largest scale of that axis with the others as given (empty unless
    /// asked for).
    pub per_axis_max_scale: BTreeMap<&'static str, f64>,
    /// The level the drives were iterated at, a fraction of the target (`null`: full level).
    pub iterate_at: Option<f64>,
    /// Every iteration's figures, from 0 (the target's own commands); empty when not
    /// iterated.
    pub iterations: Vec<MimoRecord>,
    /// The iteration whose drives are written (`null` when not iterated).
    pub best_iteration: Option<usize>,
    /// `converged`, `max_iterations`, `stalled`, or `not_run` (the target's own commands
    /// drive an actuator to the end of its stroke).
    pub stop: &'static str,
    /// Why the iteration stalled (`null` otherwise).
    pub stall_reason: Option<String>,
    /// `Ĥ` and the iteration's settings (`null` when not iterated).
    pub frf: Option<MatrixFrfSummary>,
    /// The drives (`null` when not iterated).
    pub drive: Option<TableDriveSummary>,
    /// What the planner wants its user to know.
    pub warnings: Vec<String>,
}

impl TablePlan {
    /// The summary, with `out` the drive CSV written (if any) and `settings` the plan's.
    pub fn summary(&self, settings: &PlanSettings, out: Option<&Path>) -> TablePlanSummary {
        let f = &self.feasibility;
        let it = self.iteration();
        let iterated_at = self.drive.as_ref().and_then(|d| d.iterated_at.as_ref());
        let IterationOutcome {
            iterate_at,
            iterations,
            best_iteration,
            stop,
            stall_reason,
        } = IterationOutcome::of(it, iterated_at);
        TablePlanSummary {
            scenario: self.scenario_path.display().to_string(),
            name: self.scenario_name.clone(),
            target: self.target_summary(),
            feasible: f.feasible,
            limiting: f.limiting.clone(),
            binds_first: f.binds_first.clone(),
            margins: f.uses.clone(),
            max_scale: f.max_scale.as_ref().map(|m| m.scale),
            max_scale_search: f.max_scale.clone(),
            per_axis_max_scale: f
                .per_axis_max_scale
                .iter()
                .map(|(k, m)| (*k, m.scale))
                .collect(),
            iterate_at,
            iterations,
            best_iteration,
            stop,
            stall_reason,
            frf: it.map(|it| MatrixFrfSummary {
                source: "linearised",
                band_hz: [it.band_hz.0, it.band_hz.1],
                gain: settings.iteration.gain,
                regularisation: settings.iteration.regularisation,
                fft_len: it.fft_len,
                max_condition: it.max_condition,
            }),
            drive: self.drive.as_ref().map(|d| d.summary(self.t_s.len(), out)),
            warnings: self.warnings.clone(),
        }
    }

    /// The target, as the summary reports it.
    fn target_summary(&self) -> TableTargetSummary {
        let first = self.motions.values().next();
        let target_t = first.map_or(&[][..], |m| &m.t_s[..]);
        TableTargetSummary {
            file: self.target_origin.display().to_string(),
            samples: self.target_samples,
            sample_rate_hz: self.target_rate_hz,
            drive_sample_rate_hz: first.map_or(0.0, |m| 1.0 / m.interval_s()),
            duration_s: target_t
                .last()
                .zip(target_t.first())
                .map_or(0.0, |(b, a)| b - a),
            axes: self
                .motions
                .iter()
                .map(|(axis, m)| {
                    (
                        *axis,
                        AxisTargetSummary {
                            kind: m.kind.name(),
                            peak_a_m_s2: peak(&m.a_m_s2),
                            peak_u_m: m.peak_u_m(),
                            rms_a_m_s2: m.target_rms_m_s2,
                            baseline_degree: m.end_degree,
                            baseline_correction_rms_m_s2: m.correction_rms_m_s2,
                        },
                    )
                })
                .collect(),
        }
    }
}

impl TablePlannedDrive {
    /// The drives, as the summary reports them: `samples` of them, written to `out`.
    fn summary(&self, samples: usize, out: Option<&Path>) -> TableDriveSummary {
        let it = &self.iteration;
        TableDriveSummary {
            out: out.map(|p| p.display().to_string()),
            samples,
            peak_u_m: AXES
                .iter()
                .zip(&it.drive_u_m)
                .map(|(a, d)| (*a, peak(d)))
                .collect(),
            achieved: self
                .iterated_at
                .as_ref()
                .map_or_else(|| it.best_record().clone(), |i| i.full_level.clone()),
            at_iteration_level: self.iterated_at.as_ref().map(|i| i.at_level.clone()),
            limiting: failing(&self.uses),
            spectrum_acceptance: self.spectrum_acceptance.clone(),
        }
    }
}
