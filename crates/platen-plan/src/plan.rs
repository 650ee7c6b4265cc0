//! The plan of the uniaxial table (a platen and its `table_system`, [`plan_platen`]): the
//! target's motion, its feasibility and largest scale, the drive iteration, and the summary
//! `platen plan --json` prints ([`PlanSummary`]); and the settings of every plan
//! ([`PlanSettings`]). [`crate::plan()`](fn@crate::plan) is the one entry that calls it.

use std::path::{Path, PathBuf};

use serde::Serialize;

use platen_io::csv::{write_csv_atomic, CsvWriter};
use platen_scenario::{LimitsSummary, LoadedRig};

use crate::baseline::{peak, rms, BaselineSettings, TargetMotion};
use crate::error::{PlanError, Result};
use crate::feasibility::{
    failing, feasibility, limit_uses, limits_summary, Feasibility, LimitUse, MaxScale,
    MaxScaleSettings,
};
use crate::iterate::{
    iterate_observed, record_of, IterationRecord, IterationSettings, SpectrumAcceptance, Stop,
};
use crate::platen_loop::{Achieved, PlatenLoop};
use crate::rrs::RequiredSpectrum;
use crate::steps::{
    acceptance, iteration_level, on_controller_rate, scaled_up, IteratedAt, IterationOutcome,
    Resampled,
};
use crate::target::Target;
use crate::Iteration;

/// Everything a plan can be told, whatever the table.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlanSettings {
    /// How an acceleration target (each axis's, on a multi-axis table) becomes a
    /// displacement command.
    pub baseline: BaselineSettings,
    /// The drive iteration (on a multi-axis table its `frf` is ignored: the table's
    /// linearised transfer matrix is used).
    pub iteration: IterationSettings,
    /// The search of the largest (common) scale (`None`: not searched).
    pub max_scale: Option<MaxScaleSettings>,
    /// A multi-axis table: the largest scale of each axis too, the others as given (the
    /// uniaxial table has one axis: its scale is the common one).
    pub per_axis_max_scale: bool,
    /// The uniaxial table: the required response spectrum the drive's run is accepted
    /// against (`None`: the target's own spectrum, [`crate::ACCEPTANCE_BAND`] either way).
    pub rrs: Option<RequiredSpectrum>,
    /// A multi-axis table: per axis (x, y, z), the required response spectrum its achieved
    /// acceleration is accepted against (`None`: its target's own spectrum).
    pub axis_rrs: [Option<RequiredSpectrum>; 3],
    /// The level the drive is iterated at, a fraction of the target in `(0, 1]` (`None` or 1:
    /// at full level). Below 1 the drive is iterated on the target scaled by it, as labs
    /// iterate so that the specimen does not see full-level shaking while the drive
    /// converges, then scaled up by its inverse and run once at full level: that run is the
    /// drive's (its error is the predicted full-level error, [`IteratedAt`]).
    pub iterate_at: Option<f64>,
}

impl PlanSettings {
    /// The settings of `platen plan`'s options (and `platen.plan`'s arguments): at most
    /// `iterations` corrections at `gain`, stopping at `target_nrmse`, in `band_hz` (default
    /// band when `None`); the largest common scale searched when `max_scale` or
    /// `per_axis_scale`, each axis's too with `per_axis_scale`; the rest default.
    pub fn new(
        iterations: usize,
        gain: f64,
        target_nrmse: f64,
        band_hz: Option<(f64, f64)>,
        max_scale: bool,
        per_axis_scale: bool,
    ) -> Self {
        Self {
            iteration: IterationSettings {
                max_iterations: iterations,
                gain,
                target_nrmse,
                band_hz,
                ..Default::default()
            },
            max_scale: (max_scale || per_axis_scale).then(MaxScaleSettings::default),
            per_axis_max_scale: per_axis_scale,
            ..Default::default()
        }
    }

    /// The defaults with the largest scale searched.
    pub fn with_max_scale() -> Self {
        Self {
            max_scale: Some(MaxScaleSettings::default()),
            ..Self::default()
        }
    }
}

/// A finished plan.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The scenario's file (for the summary).
    pub scenario_path: PathBuf,
    /// The scenario's name.
    pub scenario_name: String,
    /// The target's origin.
    pub target_origin: PathBuf,
    /// The target's own samples.
    pub target_samples: usize,
    /// The target's own sample rate, Hz.
    pub target_rate_hz: f64,
    /// The motion asked of the table (after the baseline treatment).
    pub motion: TargetMotion,
    /// The target's feasibility (its own command, iteration 0) and largest scale.
    pub feasibility: Feasibility,
    /// The drive iteration and what its best drive's run uses of every limit (`None` when
    /// the target's own command drives the platen to the end of its actuators: there is no
    /// run to iterate on).
    pub drive: Option<PlannedDrive>,
    /// What the planner wants its user to know.
    pub warnings: Vec<String>,
}

/// The iterated drive of a plan.
#[derive(Debug, Clone)]
pub struct PlannedDrive {
    /// The drive iteration.
    pub iteration: Iteration<Achieved>,
    /// Every limit against the best drive's run.
    pub uses: Vec<LimitUse>,
    /// The scenario's four limits against the best drive's run.
    pub limits: LimitsSummary,
    /// Where `Ĥ` came from, its measured band and mean coherence.
    pub frf: FrfSummary,
    /// The best drive's achieved response spectrum against the target's
    /// ([`crate::iterate::ACCEPTANCE_BAND`]).
    pub spectrum_acceptance: SpectrumAcceptance,
    /// Where the drive was iterated at a low level and scaled up (`None`: at full level).
    pub iterated_at: Option<IteratedAt>,
}

impl Plan {
    /// The drive: time stamps (the target's, on the controller's rate), s, and displacement
    /// command, m (`None` when there is none: see [`Plan::drive`]).
    pub fn drive(&self) -> Option<(&[f64], &[f64])> {
        let d = self.drive.as_ref()?;
        Some((&self.motion.t_s, &d.iteration.drive_u_m))
    }

    /// The drive iteration, if it ran.
    pub fn iteration(&self) -> Option<&Iteration<Achieved>> {
        self.drive.as_ref().map(|d| &d.iteration)
    }

    /// Writes the drive's rows to `writer` (created with [`crate::UNIAXIAL_DRIVE_COLUMNS`])
    /// and finishes it; returns whether there was a drive to write (without, the writer is
    /// dropped and its temporary file with it).
    ///
    /// # Errors
    /// [`PlanError::Io`] if it cannot be written.
    pub fn write_drive_rows(&self, mut writer: CsvWriter) -> Result<bool> {
        let Some((t_s, u_m)) = self.drive() else {
            return Ok(false);
        };
        for (t, u) in t_s.iter().zip(u_m) {
            writer.write_row(&[*t, *u])?;
        }
        writer.finish()?;
        Ok(true)
    }
}

/// The uniaxial drive CSV's columns: the displacement command at the controller's rate, a
/// `motion_csv` that `simulate` replays.
pub const UNIAXIAL_DRIVE_COLUMNS: [&str; 2] = ["t_s", "u_m"];

/// Loads a scenario file's rig for planning ([`LoadedRig::load`]): its model, table system,
/// specimen and limits, and its loop's integrator and initial state. The `excitation` may be
/// absent and is ignored when present (the target takes its place, so its records are not
/// read), as is `duration_s`.
///
/// # Errors
/// Every error of [`LoadedRig::load`] and [`LoadedRig::loop_settings`];
/// [`PlanError::NoTableSystem`].
pub fn load_rig(path: &Path) -> Result<LoadedRig> {
    let loaded = LoadedRig::load(path)?;
    PlatenLoop::of_loaded(&loaded, path)?;
    Ok(loaded)
}

/// Plans `target` on the uniaxial `table` (a scenario's rig, [`PlatenLoop::of_loaded`], or one
/// built by hand: any [`Rig`](platen_scenario::Rig) with a table system and its
/// [`LoopSettings`](platen_scenario::LoopSettings), [`PlatenLoop::new`]): the target's motion, its
/// feasibility and largest scale, then the drive iteration; `name` and `scenario_path` name
/// it in the summary, and `on_run(k)` is called when the closed-loop run of drive iteration
/// `k` is done (0: the target's own command; at most `settings.iteration.max_iterations`),
/// a hook for progress reports ([`iterate_observed`]). [`crate::plan()`](fn@crate::plan)
/// calls it for a scenario without `table`.
///
/// # Errors
/// Bad settings; a closed-loop run that fails. A target sampled faster than the controller
/// is resampled to its rate ([`Target::resampled_to`]), with a notice in the plan's
/// warnings.
pub fn plan_platen(
    table: &PlatenLoop,
    name: &str,
    scenario_path: &Path,
    target: &Target,
    settings: &PlanSettings,
    on_run: &mut dyn FnMut(usize),
) -> Result<Plan> {
    iteration_level(settings.iterate_at)?;
    // A target faster than the controller is put on its rate (anti-aliased), with a notice.
    let mut notices = Vec::new();
    let on_controller = on_controller_rate(target, table.controller_rate_hz(), &mut notices)?;
    let motion = target_motion(table, &on_controller, settings)?;
    if let Some(rrs) = &settings.rrs {
        rrs.check_rate(1.0 / motion.interval_s())?;
    }
    let feasibility = feasibility(table, &motion, settings.max_scale.as_ref())?;
    // The most serious first: the feasibility's answer, then what was done to the target and
    // what is doubtful in it, then the drive's.
    let mut warnings: Vec<String> = feasibility_warning(&feasibility).into_iter().collect();
    warnings.extend(notices);
    warnings.extend(target_warnings(&motion));
    let drive = match feasibility.achieved.end_stop {
        Some(_) => None,
        None => Some(planned_drive(
            table,
            &motion,
            &feasibility,
            settings,
            on_run,
            &mut warnings,
        )?),
    };
    Ok(Plan {
        scenario_path: scenario_path.to_owned(),
        scenario_name: name.to_owned(),
        target_origin: target.origin().to_owned(),
        target_samples: target.len(),
        target_rate_hz: target.sample_rate_hz(),
        motion,
        feasibility,
        drive,
        warnings,
    })
}

/// The share of an acceleration target's RMS that the baseline treatment may remove before
/// the plan warns: beyond it what is planned is mostly the treatment's, not the target's.
pub const BASELINE_SHARE_WARNED: f64 = 0.25;

/// The shortest target the plan judges without a warning, s: the longest period of the
/// response-spectrum error it reports (2 s), so that every period of it sees a whole cycle.
pub const SHORTEST_JUDGED_S: f64 = 2.0;

/// What the plan warns of in the target itself: a baseline treatment that removed more than
/// [`BASELINE_SHARE_WARNED`] of its RMS, a target shorter than [`SHORTEST_JUDGED_S`].
fn target_warnings(motion: &TargetMotion) -> Vec<String> {
    let mut warnings = Vec::new();
    let duration = motion.t_s.last().unwrap_or(&0.0) - motion.t_s.first().unwrap_or(&0.0);
    if duration < SHORTEST_JUDGED_S {
        warnings.push(format!(
            "the target lasts {duration:.3} s, less than {SHORTEST_JUDGED_S} s: too short to \
             judge (its response spectrum reaches 2 s periods, and its NRMSE is dominated by \
             the start)"
        ));
    }
    if motion.target_rms_m_s2 > 0.0 {
        let share = motion.correction_rms_m_s2 / motion.target_rms_m_s2;
        if share > BASELINE_SHARE_WARNED {
            warnings.push(format!(
                "the baseline treatment removed {:.0} % of the target's RMS acceleration \
                 (more than {:.0} %): what is planned is mostly the correction, not the \
                 target; check the target's units, its offset, and its length",
                100.0 * share,
                100.0 * BASELINE_SHARE_WARNED
            ));
        }
    }
    warnings
}

/// The motion asked of `table` for `target` (already at most the controller's rate: a faster
/// one is resampled by [`plan_platen`] first), not zero.
fn target_motion(
    table: &PlatenLoop,
    target: &Target,
    settings: &PlanSettings,
) -> Result<TargetMotion> {
    let controller_hz = table.controller_rate_hz();
    if target.kind() == crate::target::TargetKind::Displacement {
        // Beyond ten strokes no table reading exists (mm read as m): refused with the hint
        // `simulate` gives for the same record.
        platen_scenario::units::check_displacement_record(
            target.origin(),
            target.t_s(),
            target.values(),
            table.rig().limits.stroke_m,
        )?;
    }
    let motion = TargetMotion::new(
        target,
        &settings.baseline,
        table.rig().limits.stroke_m,
        controller_hz,
    )?;
    if rms(&motion.a_m_s2) == 0.0 {
        return Err(PlanError::Target {
            origin: target.origin().display().to_string(),
            message: "the target's acceleration is zero everywhere: nothing to reproduce".into(),
        });
    }
    Ok(motion)
}

/// The warning of a target whose own command reaches the end of the actuators, or that is
/// not feasible.
fn feasibility_warning(feasibility: &Feasibility) -> Option<String> {
    let largest = feasibility.max_scale.as_ref().map_or(String::new(), |m| {
        format!(" (largest scale that fits: {:.4})", m.scale)
    });
    if let Some(stop) = feasibility.achieved.end_stop {
        Some(format!(
            "the target's command drives the platen to the end of its actuators at {:.3} s \
             (u = {:.3} m): not iterated, no drive{largest}",
            stop.t_s, stop.value
        ))
    } else {
        feasibility.limiting.first().map(|worst| {
            format!(
                "the target is not feasible: {} reaches {:.3} times its limit at {:.3} s{largest}; \
                 the drive reproduces it on the model, the table cannot run it",
                worst.limit, worst.ratio, worst.t_s
            )
        })
    }
}

/// The drive iteration on `table` and its best drive's limits, with what it warns of pushed
/// on `warnings`.
fn planned_drive(
    table: &PlatenLoop,
    motion: &TargetMotion,
    feasibility: &Feasibility,
    plan_settings: &PlanSettings,
    on_run: &mut dyn FnMut(usize),
    warnings: &mut Vec<String>,
) -> Result<PlannedDrive> {
    let settings = &plan_settings.iteration;
    // Checked by `plan_platen` before any run.
    let level = plan_settings.iterate_at.unwrap_or(1.0);
    let mut iteration;
    let iterated_at = if level < 1.0 {
        iteration = iterate_observed(table, &motion.scaled(level), settings, on_run)?;
        let best = iteration.best;
        Some(scaled_up(
            level,
            &mut iteration,
            |d, level| d.iter().map(|d| d / level).collect(),
            |drive| {
                let full = table.run_or_end_stop(&motion.t_s, drive, "the full-level drive")?;
                let record = record_of(best, &full, drive, motion, &settings.spectrum)?;
                Ok((full, record))
            },
            |r| r.acceleration_nrmse,
            warnings,
        )?)
    } else {
        iteration = iterate_observed(table, motion, settings, on_run)?;
        None
    };
    let uses = limit_uses(table, &iteration.achieved);
    if feasibility.feasible {
        if let Some(worst) = failing(&uses).first() {
            warnings.push(format!(
                "the target's own command fits, but the iterated drive's run exceeds \
                 {} ({:.3} times its limit at {:.3} s)",
                worst.limit, worst.ratio, worst.t_s
            ));
        }
    }
    if let Stop::Stalled { reason } = &iteration.stop {
        warnings.push(format!("the drive iteration stalled: {reason}"));
    }
    if let Some(t) = iteration.achieved.cavitation_at_s() {
        warnings.push(format!(
            "a chamber pressure reached the cavitation floor at {t:.4} s in the drive's \
             run"
        ));
    }
    let spectrum_acceptance = acceptance(
        plan_settings.rrs.as_ref(),
        &settings.spectrum,
        1.0 / motion.interval_s(),
        (&motion.a_m_s2, &iteration.achieved.a_m_s2),
        "the drive's achieved response spectrum",
        warnings,
    )?;
    Ok(PlannedDrive {
        limits: limits_summary(table, &iteration.achieved),
        frf: FrfSummary::new(settings, &iteration),
        spectrum_acceptance,
        uses,
        iteration,
        iterated_at,
    })
}

/// Writes the drive CSV (`t_s`, `u_m`) atomically: nothing is left at `path` if it fails.
///
/// # Errors
/// [`PlanError::Io`].
pub fn write_drive(path: &Path, t_s: &[f64], u_m: &[f64]) -> Result<()> {
    Ok(write_csv_atomic(
        path,
        &UNIAXIAL_DRIVE_COLUMNS,
        &[t_s, u_m],
    )?)
}

/// Where `Ĥ` came from, as the summary reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfSummary {
    /// `linearised` or `measured`.
    pub source: &'static str,
    /// The correction band, Hz.
    pub band_hz: [f64; 2],
    /// The measured band, Hz (measured only; `null` for a linearised one).
    pub measured_band_hz: Option<[f64; 2]>,
    /// Mean coherence of the measurement over its band (measured only; `null` for a linearised one).
    pub coherence: Option<f64>,
    /// The gain `g`.
    pub gain: f64,
    /// `ε` of the regularised inverse.
    pub regularisation: f64,
    /// FFT length (record and padding), samples.
    pub fft_len: usize,
}

impl FrfSummary {
    fn new(settings: &IterationSettings, it: &Iteration<Achieved>) -> Self {
        Self {
            source: if it.measured.is_some() {
                "measured"
            } else {
                "linearised"
            },
            band_hz: [it.band_hz.0, it.band_hz.1],
            measured_band_hz: it.measured.map(|m| [m.0 .0, m.0 .1]),
            coherence: it.measured.map(|m| m.1),
            gain: settings.gain,
            regularisation: settings.regularisation,
            fft_len: it.fft_len,
        }
    }
}

/// The summary `platen plan --json` prints. Serialise it through [`serde_json::to_value`]
/// for the keys in alphabetical order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanSummary {
    /// The scenario file.
    pub scenario: String,
    /// The scenario's name.
    pub name: String,
    /// The target.
    pub target: TargetSummary,
    /// Whether the target's own command respects every limit.
    pub feasible: bool,
    /// The scenario's four limits against the target command's run, as `simulate`'s.
    pub limits: LimitsSummary,
    /// The limits that fail, worst first.
    pub limiting: Vec<LimitUse>,
    /// Every limit with its peak, allowed value, ratio and time.
    pub margins: Vec<LimitUse>,
    /// The largest scale of the target that fits (`null` when not searched).
    pub max_scale: Option<f64>,
    /// The level the drive was iterated at, a fraction of the target (`null`: full level).
    pub iterate_at: Option<f64>,
    /// How it was found.
    pub max_scale_search: Option<MaxScale>,
    /// Every iteration's figures, from 0 (the target's own command); empty when not iterated.
    pub iterations: Vec<IterationRecord>,
    /// The iteration whose drive is written (`null` when not iterated).
    pub best_iteration: Option<usize>,
    /// `converged`, `max_iterations`, `stalled`, or `not_run` (the target's own command
    /// reaches the end of the actuators).
    pub stop: &'static str,
    /// Why the iteration stalled (`null` otherwise).
    pub stall_reason: Option<String>,
    /// `Ĥ` and the iteration's settings (`null` when not iterated).
    pub frf: Option<FrfSummary>,
    /// The drive (`null` when not iterated).
    pub drive: Option<DriveSummary>,
    /// What the planner wants its user to know.
    pub warnings: Vec<String>,
}

/// The target, as the summary reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetSummary {
    /// Its file (or origin).
    pub file: String,
    /// `acceleration` or `displacement`.
    pub kind: &'static str,
    /// Samples.
    pub samples: usize,
    /// Its sample rate, Hz.
    pub sample_rate_hz: f64,
    /// The rate of the drive (the controller's), Hz: a slower target is put on it.
    pub drive_sample_rate_hz: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Largest acceleration to reproduce (after the baseline treatment), m/s².
    pub peak_a_m_s2: f64,
    /// Largest displacement of its command, m.
    pub peak_u_m: f64,
    /// The end-correction degree (acceleration targets).
    pub baseline_degree: Option<usize>,
    /// RMS of the acceleration the baseline treatment removed, m/s².
    pub baseline_correction_rms_m_s2: f64,
    /// Its largest magnitude, m/s².
    pub baseline_correction_peak_m_s2: f64,
    /// RMS of the target's own acceleration, m/s².
    pub rms_a_m_s2: f64,
}

/// The drive, as the summary reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriveSummary {
    /// The CSV written, if any.
    pub out: Option<String>,
    /// Samples.
    pub samples: usize,
    /// Largest displacement of the drive, m.
    pub peak_u_m: f64,
    /// What the drive achieves at full level (the best iteration's run; with `iterate_at`,
    /// the scaled-up drive's run: the predicted full-level error).
    pub achieved: IterationRecord,
    /// With `iterate_at`, what the best iteration achieved at that level (`null` otherwise).
    pub at_iteration_level: Option<IterationRecord>,
    /// The run's signed peak displacement, m.
    pub run_peak_u_m: f64,
    /// The run's signed peak velocity, m/s.
    pub run_peak_v_m_s: f64,
    /// The run's signed peak actuator force, N.
    pub run_peak_force_n: f64,
    /// The scenario's four limits against the drive's run.
    pub limits: LimitsSummary,
    /// The limits the drive's run exceeds, worst first.
    pub limiting: Vec<LimitUse>,
    /// Its achieved response spectrum against the target's as the required one.
    pub spectrum_acceptance: SpectrumAcceptance,
}

impl Plan {
    /// The summary, with `out` the drive CSV written (if any).
    pub fn summary(&self, out: Option<&Path>) -> PlanSummary {
        let f = &self.feasibility;
        let m = &self.motion;
        let iterated_at = self.drive.as_ref().and_then(|d| d.iterated_at.as_ref());
        let IterationOutcome {
            iterate_at,
            iterations,
            best_iteration,
            stop,
            stall_reason,
        } = IterationOutcome::of(self.iteration(), iterated_at);
        PlanSummary {
            scenario: self.scenario_path.display().to_string(),
            name: self.scenario_name.clone(),
            target: TargetSummary {
                file: self.target_origin.display().to_string(),
                kind: m.kind.name(),
                samples: self.target_samples,
                sample_rate_hz: self.target_rate_hz,
                drive_sample_rate_hz: 1.0 / m.interval_s(),
                duration_s: m.t_s[m.len() - 1] - m.t_s[0],
                peak_a_m_s2: peak(&m.a_m_s2),
                peak_u_m: m.peak_u_m(),
                baseline_degree: m.end_degree,
                baseline_correction_rms_m_s2: m.correction_rms_m_s2,
                baseline_correction_peak_m_s2: m.correction_peak_m_s2,
                rms_a_m_s2: m.target_rms_m_s2,
            },
            feasible: f.feasible,
            limits: f.limits.clone(),
            limiting: f.limiting.clone(),
            margins: f.uses.clone(),
            max_scale: f.max_scale.as_ref().map(|s| s.scale),
            iterate_at,
            max_scale_search: f.max_scale.clone(),
            iterations,
            best_iteration,
            stop,
            stall_reason,
            frf: self.drive.as_ref().map(|d| d.frf.clone()),
            drive: self.drive.as_ref().map(|d| {
                let it = &d.iteration;
                let p = &it.achieved.output.peaks;
                DriveSummary {
                    out: out.map(|p| p.display().to_string()),
                    samples: it.drive_u_m.len(),
                    peak_u_m: peak(&it.drive_u_m),
                    achieved: d.iterated_at.map_or(*it.best_record(), |i| i.full_level),
                    at_iteration_level: d.iterated_at.map(|i| i.at_level),
                    run_peak_u_m: p.u_m.value,
                    run_peak_v_m_s: p.v_m_s.value,
                    run_peak_force_n: p.force_n.value,
                    limits: d.limits.clone(),
                    limiting: failing(&d.uses),
                    spectrum_acceptance: d.spectrum_acceptance.clone(),
                }
            }),
            warnings: self.warnings.clone(),
        }
    }
}

impl Resampled for Target {
    fn sample_rate_hz(&self) -> f64 {
        Target::sample_rate_hz(self)
    }
    fn resampled_to(&self, rate_hz: f64) -> Result<Self> {
        Target::resampled_to(self, rate_hz)
    }
}
