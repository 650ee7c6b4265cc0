//! Offline drive iteration, as shake-table controllers do it on the real table, here on the
//! simulated one ([`iterate`], [`iterate_with`]).
//!
//! # The iteration
//!
//! The drive `D` is a displacement command. Iteration 0 runs the target's own command
//! (`D₀ = T_u`, [`crate::TargetMotion`]); then, with the achieved acceleration `R_k` and the
//! target acceleration `T`, in the frequency domain,
//!
//! ```text
//!   D_{k+1}(f) = D_k(f) + g · w(f) · Ĥ⁻¹(f) · (T(f) − R_k(f)) / (−(2πf)²)
//!   Ĥ⁻¹ = Ĥ* / (|Ĥ|² + ε²·max|Ĥ|²)
//! ```
//!
//! * `Ĥ` maps the command's displacement to the achieved displacement, and equally the
//!   command's acceleration to the achieved acceleration (`a = s²u` on both sides), so the
//!   error is taken on the acceleration (what a shake-table test is judged by) and divided by
//!   `−ω²` to correct the displacement drive. `Ĥ` is linearised or measured
//!   ([`crate::frf`]; by default measured when the scenario carries a specimen).
//! * **Regularised inverse.** `ε` (default 0.1) keeps `Ĥ⁻¹` finite where `|Ĥ|` is small: at
//!   `|Ĥ| = ε·max|Ĥ|` it gives half the exact inverse, and it never exceeds `1/(2ε·max|Ĥ|)`.
//! * **Band** `w(f)`: 1 inside `[f_lo, f_hi]` with half-cosine roll-offs over the lowest and
//!   highest `edge_fraction` of it (from `f_lo` to `f_lo·(1 + e)` and from `f_hi·(1 − e)` to
//!   `f_hi`), **0 outside**: the drive is not corrected outside the band. Default
//!   `[0.1 Hz, min(50 Hz, 0.45·f_s)]`: below 0.1 Hz the correction would be displacement the
//!   stroke cannot give (and the baseline treatment has set that content), and above 50 Hz
//!   the LHPOST's loop has rolled off (`|Ĥ| ≈ 0.5` and falling, phase past −90°) into what
//!   the servo-valves and the oil column decide, not the drive; earthquake targets carry
//!   little there.
//! * **Gain** `g` (default 0.7). On a linear plant whose `Ĥ` is exact, the in-band error
//!   shrinks by exactly `1 − g` per iteration; where `Ĥ` is off by a factor `ρ = H/Ĥ` it
//!   shrinks by `|1 − gρ|`, which stays below 1 for any phase error under 90° and magnitude
//!   errors up to `2/g`. `g = 1` converges in one step on an exact `Ĥ` and diverges as soon as
//!   `ρ` exceeds 2; `g = 0.7` keeps a factor 0.3 per iteration where `Ĥ` is right and still
//!   converges wherever the table's gain is up to 2.9 times `Ĥ`'s (`ρ < 2/g`: around a
//!   specimen's modes that a linearised `Ĥ` misses, and where friction and the orifice law
//!   make the table's gain depend on the amplitude). On the LHPOST with Northridge, `g` = 0.5,
//!   0.7, 0.9, 1 end at 2.80, 2.57, 2.55, 2.51 % after 10 iterations; with a two-storey frame
//!   and the linearised `Ĥ`, 0.9 oscillates and stalls at 7.8 % where 0.7 reaches 3.4 %. See
//!   `docs/planning.md`.
//! * **Record ends.** The error is zero-padded (by `pad_s`, default the larger of 4 s and a
//!   quarter of the record) before the FFT, so the inverse filter's response — non-causal:
//!   it anticipates the loop's lag — neither wraps around nor leaks from one end to the
//!   other; the correction is cut back to the record and tapered to zero by a half-cosine
//!   over `taper_s` (default 0.1 s) at both ends, so the drive starts from and ends at the
//!   target's rest.
//!
//! # One axis, several axes
//!
//! Written once for `p` coupled axes ([`iterate_axes`]): `Ĥ` is then the `p × p` transfer
//! matrix and `Ĥ⁻¹` its Tikhonov-regularised inverse ([`crate::mimo`],
//! [`crate::DriveCorrection`]); the single-axis iteration ([`iterate_with`]) is that
//! iteration with one axis, whose `1 × 1` inverse is the formula above to the last bit.
//!
//! # Stopping
//!
//! After each run: **converged** when the acceleration NRMSE is at most `target_nrmse`
//! (default 0.02); **stalled** when it has not improved on the best by more than
//! `min_improvement` (0.5 %, relative) for `stall_iterations` (2) iterations in a row — the
//! reason names what limits the table in the last run (saturated valves, cavitation, the
//! platen sticking under friction, or an error that lies mostly outside the band or that the
//! linear inverse does not reduce); **max_iterations** after `max_iterations` corrections
//! (default 10). The best drive (lowest acceleration NRMSE) is returned, not the last.
//!
//! # Reported per iteration
//!
//! `acceleration_nrmse` (`rms(R − T)/rms(T)`), `displacement_nrmse` (the same on the
//! displacement), `spectrum_error` (the largest relative error of the achieved 5 %-damped
//! pseudo-acceleration response spectrum against the target's over 0.05–2 s, 50 periods
//! evenly spaced in logarithm, with the period where it occurs), the drive's peak, and the
//! time the valves were saturated and the platen stuck.

use rustfft::num_complex::Complex64 as C64;
use serde::Serialize;

use crate::acceptance::SpectrumCheck;
pub use crate::acceptance::{
    spectrum_acceptance, SpectrumAcceptance, SpectrumMiss, ACCEPTANCE_BAND,
};
use crate::baseline::{peak, rms, TargetMotion};
use crate::correction::checked;
pub use crate::correction::{Correction, DriveCorrection, TransferMatrix};
use crate::error::{PlanError, Result};
use crate::frf::{FrequencyResponse, FrfSource};
use crate::platen_loop::{Achieved, PlatenLoop};
pub use crate::settings::{
    default_band_hz, AxisTarget, IterationSettings, SpectrumSettings, DEFAULT_GAIN,
};

/// One iteration's figures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IterationRecord {
    /// 0 for the target's own command, then 1, 2, …
    pub iteration: usize,
    /// `rms(R − T)/rms(T)` on the acceleration.
    pub acceleration_nrmse: f64,
    /// The same on the displacement.
    pub displacement_nrmse: f64,
    /// Largest relative error of the achieved response spectrum against the target's.
    pub spectrum_error: f64,
    /// The period where it occurs, s.
    pub spectrum_error_period_s: f64,
    /// The drive's largest displacement, m.
    pub peak_drive_u_m: f64,
    /// The achieved signed peak acceleration, m/s².
    pub peak_a_m_s2: f64,
    /// Time with the valves' drive saturated, s.
    pub valve_saturated_time_s: f64,
    /// Time the platen was stuck, s.
    pub stick_time_s: f64,
}

/// Why the iteration stopped.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "stop", rename_all = "snake_case")]
pub enum Stop {
    /// The acceleration NRMSE reached the target.
    Converged,
    /// The iteration ran its corrections.
    MaxIterations,
    /// No improvement for `stall_iterations` iterations.
    Stalled {
        /// What limits the table, in words.
        reason: String,
    },
}

impl Stop {
    /// `converged`, `max_iterations` or `stalled`.
    pub fn name(&self) -> &'static str {
        match self {
            Stop::Converged => "converged",
            Stop::MaxIterations => "max_iterations",
            Stop::Stalled { .. } => "stalled",
        }
    }
}

/// What the plant returns for the drives of its axes: per axis the achieved displacement and
/// acceleration at the target's samples, and what the stall diagnosis reads. A uniaxial
/// table has one axis, `0`.
pub trait Response {
    /// Achieved displacement of axis `axis` (in the targets' order), m.
    fn u_m(&self, axis: usize) -> &[f64];
    /// Achieved acceleration of axis `axis`, m/s².
    fn a_m_s2(&self, axis: usize) -> &[f64];
    /// Time with the valves (any valve) saturated, s.
    fn saturated_time_s(&self) -> f64 {
        0.0
    }
    /// Time the platen was stuck, s.
    fn stick_time_s(&self) -> f64 {
        0.0
    }
    /// First cavitation, s.
    fn cavitation_at_s(&self) -> Option<f64> {
        None
    }
    /// Where the run reached the end of the actuators and stopped, `(t_s, u_m)` (its arrays
    /// are then shorter than the target).
    fn end_stop(&self) -> Option<(f64, f64)> {
        None
    }
}

impl Response for Achieved {
    fn u_m(&self, _axis: usize) -> &[f64] {
        &self.u_m
    }
    fn a_m_s2(&self, _axis: usize) -> &[f64] {
        &self.a_m_s2
    }
    fn saturated_time_s(&self) -> f64 {
        Achieved::saturated_time_s(self)
    }
    fn stick_time_s(&self) -> f64 {
        Achieved::stick_time_s(self)
    }
    fn cavitation_at_s(&self) -> Option<f64> {
        Achieved::cavitation_at_s(self)
    }
    fn end_stop(&self) -> Option<(f64, f64)> {
        self.end_stop.map(|p| (p.t_s, p.value))
    }
}

/// The finished iteration: of one axis (`Rec` an [`IterationRecord`], `D` one drive) or of
/// several ([`crate::MimoIteration`]: `Rec` a [`crate::MimoRecord`], `D` a drive per axis).
#[derive(Debug, Clone)]
pub struct Iteration<R, Rec = IterationRecord, D = Vec<f64>> {
    /// The best drive (lowest acceleration NRMSE), m, at the target's samples (per axis in
    /// the targets' order on several axes).
    pub drive_u_m: D,
    /// Its iteration.
    pub best: usize,
    /// What it achieved.
    pub achieved: R,
    /// Every iteration's figures, from 0.
    pub records: Vec<Rec>,
    /// Why it stopped.
    pub stop: Stop,
    /// The correction band used, Hz.
    pub band_hz: (f64, f64),
    /// The FFT length (record plus padding), samples.
    pub fft_len: usize,
    /// A measured `Ĥ`'s band, Hz, and mean coherence (`None`: linearised).
    pub measured: Option<((f64, f64), f64)>,
    /// The largest condition number of `Ĥ` in the band (ratio of its largest to its smallest
    /// singular value; 1 for one axis): how ill-conditioned the inverse the regularisation
    /// guards was.
    pub max_condition: f64,
}

impl<R, Rec, D> Iteration<R, Rec, D> {
    /// The best iteration's figures.
    pub fn best_record(&self) -> &Rec {
        &self.records[self.best]
    }

    /// The same iteration with its drive mapped by `f`.
    fn map_drive<E>(self, f: impl FnOnce(D) -> E) -> Iteration<R, Rec, E> {
        Iteration {
            drive_u_m: f(self.drive_u_m),
            best: self.best,
            achieved: self.achieved,
            records: self.records,
            stop: self.stop,
            band_hz: self.band_hz,
            fft_len: self.fft_len,
            measured: self.measured,
            max_condition: self.max_condition,
        }
    }
}

/// Iterates the drive for `motion` on `table` (see the [module documentation](self)).
///
/// # Errors
/// Bad settings; [`PlanError::Run`] if a closed-loop run fails.
pub fn iterate(
    table: &PlatenLoop<'_>,
    motion: &TargetMotion,
    settings: &IterationSettings,
) -> Result<Iteration<Achieved>> {
    iterate_observed(table, motion, settings, &mut |_| {})
}

/// [`iterate`], calling `on_run(k)` when the closed-loop run of iteration `k` is done (0: the
/// target's own command; at most `settings.max_iterations`): a hook for progress reports.
///
/// # Errors
/// As [`iterate`].
pub fn iterate_observed(
    table: &PlatenLoop<'_>,
    motion: &TargetMotion,
    settings: &IterationSettings,
    on_run: &mut dyn FnMut(usize),
) -> Result<Iteration<Achieved>> {
    let fs = 1.0 / motion.interval_s();
    let with_specimen = table.rig().specimen.is_some();
    let frf = match &settings.frf.resolve(with_specimen) {
        FrfSource::Linearised | FrfSource::Auto => FrequencyResponse::linearised(table),
        FrfSource::Measured(noise) => {
            let band = settings.band_hz.unwrap_or(default_band_hz(fs));
            FrequencyResponse::measured(table, fs, noise, band, rms(&motion.a_m_s2))?
        }
    };
    let mut it = iterate_with(motion, &|f| frf.at(f), settings, |drive, k| {
        let r = table.run_or_end_stop(&motion.t_s, drive, &format!("iteration {k}"));
        on_run(k);
        r
    })?;
    it.measured = frf.measured_band();
    Ok(it)
}

/// The iteration of [`iterate`] on any plant: `plant(drive, k)` runs the drive of iteration
/// `k` and returns what it achieved at the target's samples (axis 0); `frf` is `Ĥ`. It is
/// [`iterate_axes`] with one axis. A run that reaches the end of the actuators
/// ([`Response::end_stop`]) stops the iteration as stalled, keeping the best drive before it.
///
/// # Errors
/// Bad settings; any error of `plant`; [`PlanError::Run`] if the first run (the target's own
/// command) reaches the end of the actuators.
pub fn iterate_with<R: Response>(
    motion: &TargetMotion,
    frf: &dyn Fn(f64) -> C64,
    settings: &IterationSettings,
    mut plant: impl FnMut(&[f64], usize) -> Result<R>,
) -> Result<Iteration<R>> {
    let fs = 1.0 / motion.interval_s();
    checked(settings, fs, motion.len())?;
    let spectrum = SpectrumCheck::new(&settings.spectrum, fs, &motion.a_m_s2)?;
    let targets = [AxisTarget {
        name: "x",
        u_m: motion.u_m.clone(),
        a_m_s2: motion.a_m_s2.clone(),
    }];
    let it = iterate_axes(
        &targets,
        motion.interval_s(),
        &|f| vec![vec![frf(f)]],
        settings,
        |drives, k| plant(&drives[0], k),
        |k, r, drives| {
            let record = iteration_record(k, r, &drives[0], motion, &spectrum);
            (record, record.acceleration_nrmse)
        },
    )?;
    Ok(it.map_drive(|mut d| d.swap_remove(0)))
}

/// The drive iteration of the axes `targets` (all at the same samples, `interval_s` apart),
/// one or several (see the [module documentation](self)): `plant(drives, k)` runs the drives
/// of iteration `k` (per axis, in the targets' order) and returns what they achieved; `frf`
/// is `Ĥ` (`p × p`); `record(k, r, drives)` gives iteration `k`'s figures and the
/// acceleration NRMSE the stop criteria judge.
///
/// # Errors
/// Bad settings; targets of different lengths or none; any error of `plant`;
/// [`PlanError::Run`] if the first run reaches the end of the actuators.
pub fn iterate_axes<R: Response, Rec>(
    targets: &[AxisTarget],
    interval_s: f64,
    frf: &dyn Fn(f64) -> TransferMatrix,
    settings: &IterationSettings,
    mut plant: impl FnMut(&[Vec<f64>], usize) -> Result<R>,
    record: impl Fn(usize, &R, &[Vec<f64>]) -> (Rec, f64),
) -> Result<Iteration<R, Rec, Vec<Vec<f64>>>> {
    let n = common_length(targets)?;
    let fs = 1.0 / interval_s;
    let correction = DriveCorrection::new(targets.len(), n, fs, frf, settings)?;
    let band_hz = checked(settings, fs, n)?.band_hz;
    let mut drives: Vec<Vec<f64>> = targets.iter().map(|t| t.u_m.clone()).collect();
    let mut records = Vec::new();
    let mut progress = Progress::<R, Vec<Vec<f64>>> {
        best: None,
        without_improvement: 0,
    };
    let mut k = 0;
    let stop = loop {
        let r = plant(&drives, k)?;
        if let Some(stop) = end_stopped(&r, k, progress.best.is_none())? {
            break stop;
        }
        let (rec, acceleration_nrmse) = record(k, &r, &drives);
        records.push(rec);
        let errors = acceleration_errors(targets, &r);
        let is_best = progress.judge(acceleration_nrmse, settings.min_improvement);
        let converged = acceleration_nrmse <= settings.target_nrmse;
        let at_max = k >= settings.max_iterations;
        let stalled = progress.without_improvement >= settings.stall_iterations;
        let c = (!converged).then(|| correction.apply(&errors));
        let reason = match (&c, stalled) {
            (Some(c), true) => Some(stall_reason(&r, c.in_band_fraction, band_hz)),
            _ => None,
        };
        if is_best {
            progress.best = Some(BestRun {
                k,
                drive: drives.clone(),
                achieved: r,
                nrmse: acceleration_nrmse,
            });
        }
        if converged {
            break Stop::Converged;
        }
        if let Some(reason) = reason {
            break Stop::Stalled { reason };
        }
        if at_max {
            break Stop::MaxIterations;
        }
        let Some(c) = c else {
            unreachable!("a correction is made unless the iteration stops")
        };
        for (d, dd) in drives.iter_mut().zip(&c.delta_u_m) {
            for (x, dx) in d.iter_mut().zip(dd) {
                *x += dx;
            }
        }
        k += 1;
    };
    let Some(best) = progress.best else {
        unreachable!("iteration 0 always runs")
    };
    Ok(Iteration {
        drive_u_m: best.drive,
        best: best.k,
        achieved: best.achieved,
        records,
        stop,
        band_hz,
        fft_len: correction.fft_len(),
        measured: None,
        max_condition: correction.max_condition(),
    })
}

/// The samples every target has.
///
/// # Errors
/// [`PlanError::Target`] for no target or targets of different lengths.
fn common_length(targets: &[AxisTarget]) -> Result<usize> {
    let n = targets.first().map_or(0, |t| t.a_m_s2.len());
    if targets.is_empty()
        || targets
            .iter()
            .any(|t| t.a_m_s2.len() != n || t.u_m.len() != n)
    {
        return Err(PlanError::Target {
            origin: "the axes' targets".into(),
            message: "every axis needs a target of the same length, and at least one axis".into(),
        });
    }
    Ok(n)
}

/// Per axis the acceleration error `T − R`, m/s², over the samples both have.
fn acceleration_errors<R: Response>(targets: &[AxisTarget], r: &R) -> Vec<Vec<f64>> {
    targets
        .iter()
        .enumerate()
        .map(|(i, t)| {
            t.a_m_s2
                .iter()
                .zip(r.a_m_s2(i))
                .map(|(t, a)| t - a)
                .collect()
        })
        .collect()
}

/// The best run of [`iterate_axes`] so far.
struct BestRun<R, D> {
    /// Its iteration.
    k: usize,
    /// Its drive, m.
    drive: D,
    /// What it achieved.
    achieved: R,
    /// Its acceleration NRMSE.
    nrmse: f64,
}

/// How [`iterate_axes`] is doing: its best run so far and the iterations since the last
/// improvement.
struct Progress<R, D> {
    best: Option<BestRun<R, D>>,
    without_improvement: usize,
}

impl<R, D> Progress<R, D> {
    /// Counts a run of acceleration NRMSE `nrmse` as an improvement (on the best by more than
    /// `min_improvement`, relative) or not, and says whether it is the new best.
    fn judge(&mut self, nrmse: f64, min_improvement: f64) -> bool {
        let best = self.best.as_ref();
        let improved = best.is_none_or(|b| nrmse < b.nrmse * (1.0 - min_improvement));
        let is_best = best.is_none_or(|b| nrmse < b.nrmse);
        if improved {
            self.without_improvement = 0;
        } else {
            self.without_improvement += 1;
        }
        is_best
    }
}

/// How the run `r` of iteration `k` ends the iteration when it reached the end of the
/// actuators: an error when there is no best drive yet (`no_best`), else a stall that keeps
/// the best drive before it. `None` when it did not.
fn end_stopped<R: Response>(r: &R, k: usize, no_best: bool) -> Result<Option<Stop>> {
    let Some((t_s, u_m)) = r.end_stop() else {
        return Ok(None);
    };
    if no_best {
        return Err(PlanError::Run {
            what: format!("iteration {k}"),
            source: platen_integrate::IntegrateError::EndStop { t_s, u_m },
        });
    }
    Ok(Some(Stop::Stalled {
        reason: format!(
            "the drive of iteration {k} drives the platen to the end of its actuators \
             at {t_s:.3} s (u = {u_m:.3} m): the iteration keeps the best drive before it"
        ),
    }))
}

/// The figures of iteration `k`, whose `drive` achieved `r`.
fn iteration_record<R: Response>(
    k: usize,
    r: &R,
    drive: &[f64],
    motion: &TargetMotion,
    spectrum: &SpectrumCheck,
) -> IterationRecord {
    let acceleration_nrmse = nrmse(r.a_m_s2(0), &motion.a_m_s2);
    let (spectrum_error, period) = spectrum.error(r.a_m_s2(0));
    IterationRecord {
        iteration: k,
        acceleration_nrmse,
        displacement_nrmse: nrmse(r.u_m(0), &motion.u_m),
        spectrum_error,
        spectrum_error_period_s: period,
        peak_drive_u_m: peak(drive),
        peak_a_m_s2: signed_peak(r.a_m_s2(0)),
        valve_saturated_time_s: r.saturated_time_s(),
        stick_time_s: r.stick_time_s(),
    }
}

/// The record of a run `r` of `drive` against `motion` (as iteration `k`'s), its spectrum
/// error on `spectrum`: for a run made outside the iteration (a drive scaled up).
///
/// # Errors
/// Bad spectrum settings.
pub(crate) fn record_of<R: Response>(
    k: usize,
    r: &R,
    drive: &[f64],
    motion: &TargetMotion,
    spectrum: &SpectrumSettings,
) -> Result<IterationRecord> {
    let check = SpectrumCheck::new(spectrum, 1.0 / motion.interval_s(), &motion.a_m_s2)?;
    Ok(iteration_record(k, r, drive, motion, &check))
}

pub(crate) fn signed_peak(x: &[f64]) -> f64 {
    x.iter()
        .copied()
        .fold(0.0, |m: f64, v| if v.abs() > m.abs() { v } else { m })
}

/// `rms(x − y)/rms(y)` (0 when `y` is all zero and `x = y`, infinite when only `y` is).
pub fn nrmse(x: &[f64], reference: &[f64]) -> f64 {
    let n = x.len().min(reference.len());
    if n == 0 {
        return 0.0;
    }
    let err: f64 = (0..n).map(|i| (x[i] - reference[i]).powi(2)).sum::<f64>() / n as f64;
    let r = rms(&reference[..n]);
    if r > 0.0 {
        err.sqrt() / r
    } else if err == 0.0 {
        0.0
    } else {
        f64::INFINITY
    }
}

/// Why the iteration no longer improves, from the last run (of one axis or several).
fn stall_reason<R: Response>(r: &R, in_band_fraction: f64, band_hz: (f64, f64)) -> String {
    let mut reasons = Vec::new();
    if r.saturated_time_s() > 0.0 {
        reasons.push(format!(
            "the valves were saturated (drive at ±1) for {:.3} s: the table cannot deliver \
             more flow there",
            r.saturated_time_s()
        ));
    }
    if let Some(t) = r.cavitation_at_s() {
        reasons.push(format!("a chamber cavitated at {t:.3} s"));
    }
    if r.stick_time_s() > 0.0 {
        reasons.push(format!(
            "the platen stuck for {:.3} s in all (friction at the reversals): stick-slip is not \
             linear and Ĥ⁻¹ cannot correct it",
            r.stick_time_s()
        ));
    }
    if in_band_fraction < 0.5 {
        reasons.push(format!(
            "{:.0} % of the remaining error lies outside the correction band [{}, {}] Hz",
            100.0 * (1.0 - in_band_fraction),
            band_hz.0,
            band_hz.1
        ));
    }
    if reasons.is_empty() {
        reasons.push(
            "the linear inverse no longer reduces the remaining error (nonlinearity of the \
             loop, or Ĥ off from the table in the band: try a smaller gain or a measured Ĥ)"
                .to_owned(),
        );
    }
    format!(
        "no improvement for the last iterations: {}",
        reasons.join("; ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nrmse_is_the_relative_rms_error() {
        assert_eq!(nrmse(&[2.0, -2.0], &[1.0, -1.0]), 1.0);
        assert_eq!(nrmse(&[0.0], &[0.0]), 0.0);
        assert!(nrmse(&[1.0], &[0.0]).is_infinite());
    }
}
