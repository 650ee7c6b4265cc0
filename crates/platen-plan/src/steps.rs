//! The steps every plan takes, whatever the table (uniaxial [`crate::plan_platen`],
//! multi-axis [`crate::plan_multi_axis`], both behind [`crate::plan()`](fn@crate::plan)),
//! written once: the level the drive is iterated at, the target put on the controller's rate,
//! the drive iterated at a low level and scaled up, the response-spectrum acceptance and the
//! warnings they give, and the iteration's outcome as the summaries report it.

use std::borrow::Cow;

use serde::Serialize;

use crate::error::{check_setting, Result};
use crate::iterate::{
    spectrum_acceptance, Iteration, IterationRecord, Response, SpectrumAcceptance,
    SpectrumSettings, Stop, ACCEPTANCE_BAND,
};
use crate::rrs::RequiredSpectrum;

/// A drive iterated at a low level and scaled up ([`crate::PlanSettings::iterate_at`]). The
/// iteration's drives and `achieved` are then the scaled-up drives and their full-level run;
/// its records are the low-level runs' (their NRMSEs are relative, so they compare). `Rec` is an iteration's record: one axis's
/// ([`IterationRecord`]) or several axes' ([`crate::MimoRecord`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IteratedAt<Rec = IterationRecord> {
    /// The level, a fraction of the target.
    pub level: f64,
    /// The best iteration's record at that level.
    pub at_level: Rec,
    /// The scaled-up drive's run at full level: the predicted full-level error.
    pub full_level: Rec,
}

/// The level the drive is iterated at: `iterate_at`, checked in `(0, 1]`, or 1.
///
/// # Errors
/// [`crate::PlanError::Setting`] for a level outside `(0, 1]`.
pub(crate) fn iteration_level(iterate_at: Option<f64>) -> Result<f64> {
    match iterate_at {
        Some(level) => check_setting(
            "iterate_at",
            level,
            level > 0.0 && level <= 1.0,
            "a fraction of the target in (0, 1]",
        ),
        None => Ok(1.0),
    }
}

/// A target that can be put on another rate: one axis's ([`crate::Target`]) or several
/// axes' ([`crate::AxisTargets`]).
pub(crate) trait Resampled: Clone {
    /// Its sample rate, Hz.
    fn sample_rate_hz(&self) -> f64;
    /// It on `rate_hz` (anti-aliased when slower).
    fn resampled_to(&self, rate_hz: f64) -> Result<Self>;
}

/// `target` on the controller's rate `controller_hz` when it is faster (anti-aliased), with
/// a notice pushed on `notices`; as it is otherwise.
///
/// # Errors
/// As [`Resampled::resampled_to`].
pub(crate) fn on_controller_rate<'t, T: Resampled>(
    target: &'t T,
    controller_hz: f64,
    notices: &mut Vec<String>,
) -> Result<Cow<'t, T>> {
    if target.sample_rate_hz() > controller_hz * (1.0 + 1e-9) {
        notices.push(resample_notice(target.sample_rate_hz(), controller_hz));
        Ok(Cow::Owned(target.resampled_to(controller_hz)?))
    } else {
        Ok(Cow::Borrowed(target))
    }
}

/// The notice of a target sampled at `from_hz`, faster than the controller's `to_hz`, put
/// on the controller's rate.
fn resample_notice(from_hz: f64, to_hz: f64) -> String {
    format!(
        "the target's {from_hz:.6} Hz is faster than the controller's {to_hz} Hz: it was \
         resampled to {to_hz} Hz, low-passed at {:.1} Hz (its content below {:.1} Hz kept \
         within 0.5 %, above {:.1} Hz removed)",
        0.4 * to_hz,
        0.3 * to_hz,
        0.5 * to_hz
    )
}

/// Scales up the best drive of `iteration`, iterated at `level` (below 1), by `1/level`
/// (`scale(drive, level)`), runs it at full level (`run_full(drive)`: its run and record) and
/// puts both in the iteration; `nrmse` reads a record's acceleration NRMSE. Warns on
/// `warnings` of a full-level run that reaches the end of the actuators and of one whose
/// error does not scale ([`SCALED_UP_ERROR_WARNED`]).
///
/// # Errors
/// Any error of `run_full`.
pub(crate) fn scaled_up<R: Response, Rec: Clone, D>(
    level: f64,
    iteration: &mut Iteration<R, Rec, D>,
    scale: impl Fn(&D, f64) -> D,
    run_full: impl FnOnce(&D) -> Result<(R, Rec)>,
    nrmse: impl Fn(&Rec) -> f64,
    warnings: &mut Vec<String>,
) -> Result<IteratedAt<Rec>> {
    let at_level = iteration.best_record().clone();
    let drive = scale(&iteration.drive_u_m, level);
    let (full, full_level) = run_full(&drive)?;
    if let Some((t_s, u_m)) = full.end_stop() {
        warnings.push(format!(
            "the drive iterated at {:.0} % and scaled up drives the platen to the end of \
             its actuators at {t_s:.3} s (u = {u_m:.3} m): its full-level figures end there",
            100.0 * level,
        ));
    }
    warnings.extend(scaled_up_warning(
        level,
        nrmse(&full_level),
        nrmse(&at_level),
    ));
    iteration.drive_u_m = drive;
    iteration.achieved = full;
    Ok(IteratedAt {
        level,
        at_level,
        full_level,
    })
}

/// How many times the low-level error a drive iterated at a low level and scaled up may
/// reach at full level before the plan warns: beyond it the table does not scale between the
/// levels, and the low-level iteration did not converge on the full-level drive.
pub const SCALED_UP_ERROR_WARNED: f64 = 1.5;

/// The warning of a drive iterated at `level` whose full-level run's acceleration NRMSE
/// `full` exceeds [`SCALED_UP_ERROR_WARNED`] times its low-level one `low` (`None` below).
fn scaled_up_warning(level: f64, full: f64, low: f64) -> Option<String> {
    (full > SCALED_UP_ERROR_WARNED * low).then(|| {
        format!(
            "the drive iterated at {:.0} % predicts {:.2} % acceleration NRMSE at full level, \
         against {:.2} % at its level: the table does not scale between the two (friction \
         weighs more at a low level, the valves' orifice law is not linear); iterate at a \
         higher level",
            100.0 * level,
            100.0 * full,
            100.0 * low
        )
    })
}

/// The drive iteration as a plan's summary reports it, whatever the table: the level it was
/// iterated at, every iteration's record, the best one, how it stopped and why it stalled.
pub(crate) struct IterationOutcome<Rec> {
    /// The level the drive was iterated at, a fraction of the target (`None`: full level).
    pub iterate_at: Option<f64>,
    /// Every iteration's record, from 0 (the target's own command); empty when not iterated.
    pub iterations: Vec<Rec>,
    /// The iteration whose drive is written (`None` when not iterated).
    pub best_iteration: Option<usize>,
    /// `converged`, `max_iterations`, `stalled`, or `not_run` (not iterated: the target's own
    /// command reaches the end of the actuators).
    pub stop: &'static str,
    /// Why the iteration stalled (`None` otherwise).
    pub stall_reason: Option<String>,
}

impl<Rec: Clone> IterationOutcome<Rec> {
    /// The outcome of the drive iteration `it` (`None`: not iterated), scaled up from the
    /// level of `iterated_at` where it was iterated at a low level.
    pub(crate) fn of<R, D>(
        it: Option<&Iteration<R, Rec, D>>,
        iterated_at: Option<&IteratedAt<Rec>>,
    ) -> Self {
        Self {
            iterate_at: iterated_at.map(|i| i.level),
            iterations: it.map_or_else(Vec::new, |it| it.records.clone()),
            best_iteration: it.map(|it| it.best),
            stop: it.map_or("not_run", |it| it.stop.name()),
            stall_reason: match it.map(|it| &it.stop) {
                Some(Stop::Stalled { reason }) => Some(reason.clone()),
                _ => None,
            },
        }
    }
}

/// The acceptance of the achieved acceleration `achieved_a` (at `sample_rate_hz`) against
/// `rrs`, or without one against the target's own spectrum (`target_a`, on `spectrum`), in
/// [`ACCEPTANCE_BAND`]; a failing check's warning, naming the spectrum `what`, pushed on
/// `warnings`.
///
/// # Errors
/// Bad spectrum settings.
pub(crate) fn acceptance(
    rrs: Option<&RequiredSpectrum>,
    spectrum: &SpectrumSettings,
    sample_rate_hz: f64,
    (target_a, achieved_a): (&[f64], &[f64]),
    what: &str,
    warnings: &mut Vec<String>,
) -> Result<SpectrumAcceptance> {
    let acceptance = match rrs {
        Some(rrs) => rrs.acceptance(sample_rate_hz, achieved_a, ACCEPTANCE_BAND)?,
        None => spectrum_acceptance(
            spectrum,
            sample_rate_hz,
            target_a,
            achieved_a,
            ACCEPTANCE_BAND,
        )?,
    };
    warnings.extend(acceptance_warning(what, &acceptance));
    Ok(acceptance)
}

/// The warning of a spectrum acceptance check that fails (`None` when within), `what` naming
/// the spectrum ("the drive's achieved response spectrum", with its axis on a multi-axis
/// table).
fn acceptance_warning(what: &str, acceptance: &SpectrumAcceptance) -> Option<String> {
    let miss = &acceptance.outside;
    let (first, last) = (miss.first()?, miss.last()?);
    Some(format!(
        "{what} ({:.0} % damped) is outside {:+.0}/{:+.0} % of {} at {} of {} periods, from \
         {:.3} to {:.3} s",
        100.0 * acceptance.damping_ratio,
        100.0 * acceptance.band.0,
        100.0 * acceptance.band.1,
        acceptance.required_name(),
        miss.len(),
        acceptance.count,
        first.period_s,
        last.period_s
    ))
}
