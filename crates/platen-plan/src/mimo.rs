//! Drive iteration of several coupled axes at once, through the transfer matrix
//! ([`iterate_mimo`]), as controllers of multi-axis tables do it (MTS's OLI works in DOF space
//! with a matrix FRF).
//!
//! # The iteration
//!
//! On a multi-axis table the x drive moves z and pitch through the specimen's overturning
//! moment, so correcting each axis alone, each through its own diagonal term, stalls where
//! the coupling is strong. With `p` axes, drives `D` (displacement commands), achieved
//! accelerations `R_k`, target accelerations `T` (zero on the axes held still), per
//! frequency:
//!
//! ```text
//!   D_{k+1}(f) = D_k(f) + g · w(f) · Ĥ⁺(f) · (T(f) − R_k(f)) / (−(2πf)²)
//!   Ĥ⁺ = (Ĥᴴ·Ĥ + ε²·max‖Ĥ‖²_F · I)⁻¹ · Ĥᴴ
//! ```
//!
//! * `Ĥ(f)` (`p × p`) maps the commands' displacements to the achieved displacements (and
//!   equally accelerations to accelerations); element `(i, j)` is axis `i`'s response to
//!   axis `j`'s command.
//! * `Ĥ⁺` is the Tikhonov-regularised inverse: where `Ĥ` is well conditioned it is `Ĥ⁻¹`;
//!   along directions whose singular value falls to `ε·max‖Ĥ‖_F` it gives half the exact
//!   inverse and it never exceeds `1/(2ε·max‖Ĥ‖_F)` (`‖·‖_F` the Frobenius norm, the
//!   largest over the band). For one axis it is the single-axis iteration's inverse exactly
//!   ([`crate::iterate()`]): the single-axis iteration is this one with one axis
//!   ([`crate::iterate_axes`]).
//! * The band `w(f)`, the gain `g`, the padding, the taper at the record's ends and the stop
//!   criteria are those of [`crate::IterationSettings`], the criteria judged on the **overall**
//!   acceleration NRMSE, `√(Σ_axes Σ_t (R − T)²/Σ_axes Σ_t T²)`, so that the cross-talk on
//!   the axes held still counts as error.
//! * On a linear plant whose `Ĥ` is exact and invertible, every axis's in-band error
//!   shrinks by exactly `1 − g` per iteration, cross-coupled or not (tested).
//!
//! # Reported per iteration
//!
//! Per axis: the acceleration NRMSE (`null` on an axis held still, whose error is its
//! cross-talk, reported as `rms_acceleration_error_m_s2`), the displacement NRMSE, the
//! response-spectrum error (as the single-axis iteration's), the drive's peak and the
//! achieved peak acceleration; overall: the acceleration NRMSE and the time saturated.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::acceptance::SpectrumCheck;
use crate::baseline::{peak, rms};
use crate::correction::{checked, TransferMatrix};
use crate::error::Result;
use crate::iterate::{
    iterate_axes, nrmse, signed_peak, Iteration, IterationSettings, Response, SpectrumSettings,
};

pub use crate::settings::AxisTarget;

/// One axis's figures in one iteration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AxisRecord {
    /// `rms(R − T)/rms(T)` on the acceleration (`null` on an axis held still).
    pub acceleration_nrmse: Option<f64>,
    /// `rms(R − T)`, m/s²: on an axis held still, its cross-talk.
    pub rms_acceleration_error_m_s2: f64,
    /// The same NRMSE on the displacement (`null` on an axis held still).
    pub displacement_nrmse: Option<f64>,
    /// Largest relative error of the achieved 5 %-damped response spectrum against the
    /// target's (`null` on an axis held still).
    pub spectrum_error: Option<f64>,
    /// The period where it occurs, s.
    pub spectrum_error_period_s: Option<f64>,
    /// The drive's largest displacement, m.
    pub peak_drive_u_m: f64,
    /// The achieved signed peak acceleration, m/s².
    pub peak_a_m_s2: f64,
}

/// One iteration's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MimoRecord {
    /// 0 for the target's own command, then 1, 2, …
    pub iteration: usize,
    /// The overall acceleration NRMSE (all axes' errors over all axes' targets).
    pub acceleration_nrmse: f64,
    /// Per axis.
    pub axes: BTreeMap<&'static str, AxisRecord>,
    /// Time with any valve saturated, s.
    pub valve_saturated_time_s: f64,
}

/// The finished iteration of several axes: the best drives per axis in the targets' order.
pub type MimoIteration<R> = Iteration<R, MimoRecord, Vec<Vec<f64>>>;

/// The overall acceleration NRMSE of `r` against `targets`.
fn overall_nrmse<R: Response>(targets: &[AxisTarget], r: &R) -> f64 {
    let (mut err, mut reference) = (0.0, 0.0);
    for (i, t) in targets.iter().enumerate() {
        for (x, y) in r.a_m_s2(i).iter().zip(&t.a_m_s2) {
            err += (x - y).powi(2);
            reference += y * y;
        }
    }
    if reference > 0.0 {
        (err / reference).sqrt()
    } else if err == 0.0 {
        0.0
    } else {
        f64::INFINITY
    }
}

/// Iterates the drives of the axes `targets` (all at the same samples, `interval_s` apart)
/// on any plant: `plant(drives, k)` runs the drives of iteration `k` (per axis, in the
/// targets' order) and returns what they achieved; `frf` is `Ĥ` (see the [module
/// documentation](self)). It is [`iterate_axes`] judged on the overall acceleration NRMSE.
///
/// # Errors
/// Bad settings; targets of different lengths or none; any error of `plant`.
pub fn iterate_mimo<R: Response>(
    targets: &[AxisTarget],
    interval_s: f64,
    frf: &dyn Fn(f64) -> TransferMatrix,
    settings: &IterationSettings,
    plant: impl FnMut(&[Vec<f64>], usize) -> Result<R>,
) -> Result<MimoIteration<R>> {
    let fs = 1.0 / interval_s;
    if let Some(t) = targets.first() {
        checked(settings, fs, t.a_m_s2.len())?;
    }
    let spectra = spectrum_checks(targets, fs, &settings.spectrum)?;
    iterate_axes(targets, interval_s, frf, settings, plant, |k, r, drives| {
        let record = mimo_record(k, targets, r, drives, &spectra);
        let overall = record.acceleration_nrmse;
        (record, overall)
    })
}

/// The response-spectrum checks of `targets` at `sample_rate_hz` (`None` for an axis held
/// still).
fn spectrum_checks(
    targets: &[AxisTarget],
    sample_rate_hz: f64,
    spectrum: &SpectrumSettings,
) -> Result<Vec<Option<SpectrumCheck>>> {
    targets
        .iter()
        .map(|t| {
            (!t.is_still())
                .then(|| SpectrumCheck::new(spectrum, sample_rate_hz, &t.a_m_s2))
                .transpose()
        })
        .collect()
}

/// The record of a run `r` of `drives` against `targets` (as iteration `k`'s).
fn mimo_record<R: Response>(
    k: usize,
    targets: &[AxisTarget],
    r: &R,
    drives: &[Vec<f64>],
    spectra: &[Option<SpectrumCheck>],
) -> MimoRecord {
    MimoRecord {
        iteration: k,
        acceleration_nrmse: overall_nrmse(targets, r),
        axes: targets
            .iter()
            .enumerate()
            .map(|(i, t)| (t.name, axis_record(t, r, i, &drives[i], &spectra[i])))
            .collect(),
        valve_saturated_time_s: r.saturated_time_s(),
    }
}

/// The record of a run `r` of `drives` against `targets` at `interval_s` (as iteration
/// `k`'s), made outside the iteration (drives scaled up).
///
/// # Errors
/// Bad spectrum settings.
pub(crate) fn record_of_run<R: Response>(
    k: usize,
    targets: &[AxisTarget],
    interval_s: f64,
    r: &R,
    drives: &[Vec<f64>],
    spectrum: &SpectrumSettings,
) -> Result<MimoRecord> {
    let spectra = spectrum_checks(targets, 1.0 / interval_s, spectrum)?;
    Ok(mimo_record(k, targets, r, drives, &spectra))
}

/// Axis `i`'s figures: target `t`, achieved `r`, drive `drive`.
fn axis_record<R: Response>(
    t: &AxisTarget,
    r: &R,
    i: usize,
    drive: &[f64],
    spectrum: &Option<SpectrumCheck>,
) -> AxisRecord {
    let still = t.is_still();
    let error: Vec<f64> = r
        .a_m_s2(i)
        .iter()
        .zip(&t.a_m_s2)
        .map(|(a, t)| a - t)
        .collect();
    let spectrum_error = spectrum.as_ref().map(|s| s.error(r.a_m_s2(i)));
    AxisRecord {
        acceleration_nrmse: (!still).then(|| nrmse(r.a_m_s2(i), &t.a_m_s2)),
        rms_acceleration_error_m_s2: rms(&error),
        displacement_nrmse: (!still && t.u_m.iter().any(|&u| u != 0.0))
            .then(|| nrmse(r.u_m(i), &t.u_m)),
        spectrum_error: spectrum_error.map(|e| e.0),
        spectrum_error_period_s: spectrum_error.map(|e| e.1),
        peak_drive_u_m: peak(drive),
        peak_a_m_s2: signed_peak(r.a_m_s2(i)),
    }
}
