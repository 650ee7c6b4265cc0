//! The platen's force balance as a regression design over the fitted records: the actuator
//! force from the pressures, the regressors through the zero-phase low-pass, the samples near
//! rest left out. The mechanics fit ([`super::mechanics`]) and the friction law's grids
//! ([`super::friction`]) both stand on it.

use platen_signal::ButterworthLowpass;
use platen_system::Actuator;

use super::filters::{central_velocity, filtered, mechanics_filter, MECHANICS_LOWPASS_FRACTION};
use super::PlantInput;
use crate::error::Result;
use crate::system::fit::Design;
use crate::system::skew::{self};
use crate::system::SystemRecord;

/// Samples slower than this are left out of the mechanics fit (the friction there may be a
/// stick reaction, not `±F_μ`), m/s.
pub const SLIP_SPEED_M_S: f64 = 0.01;

/// The friction law a force balance is fitted with: `sgn(v)·[F_μ + a·e^(−b|v|) + C·|v|^α]`,
/// `F_μ`, `a` and `C` fitted (linear), `b` and `α` given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Law {
    /// `α`.
    pub exponent: f64,
    /// `b`, s/m, with the Stribeck term; `None` without it.
    pub decay_s_per_m: Option<f64>,
    /// Samples slower than this are left out, m/s.
    pub slip_speed_m_s: f64,
    /// With the score column `v·ln|v|` of a test of `α = 1` (a law with `α = 1` only).
    pub exponent_score: bool,
}

impl Law {
    /// Coulomb and linear viscous friction, above [`SLIP_SPEED_M_S`].
    pub const LINEAR: Law = Law {
        exponent: 1.0,
        decay_s_per_m: None,
        slip_speed_m_s: SLIP_SPEED_M_S,
        exponent_score: false,
    };
}

/// How the actuator force comes from a record's pressures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum ForceFrom {
    /// `n(A_a·p_a − A_b·p_b)` with the base's areas.
    Chambers,
    /// `n·A·(p_a − r·p_b)` with `r` fitted (both pressures, no base).
    ChambersRatioFree,
    /// `n·A·Δp` (a double-ended actuator).
    DeltaP,
}

/// How the fitted records give the force, or why they cannot.
pub(super) fn force_from(
    records: &[SystemRecord],
    fitted: &[usize],
    input: &PlantInput,
) -> std::result::Result<ForceFrom, &'static str> {
    let a = &input.base.actuator;
    let chambers = fitted
        .iter()
        .all(|&i| records[i].cap_pressure_pa.is_some() && records[i].rod_pressure_pa.is_some());
    let dp = fitted.iter().all(|&i| records[i].delta_p_pa.is_some());
    if chambers {
        Ok(if input.base_given {
            ForceFrom::Chambers
        } else {
            ForceFrom::ChambersRatioFree
        })
    } else if dp && a.cap_area_m2 == a.rod_area_m2 {
        Ok(ForceFrom::DeltaP)
    } else if dp {
        Err(
            "the base's actuator is single-ended (cap and rod areas differ): delta_p_pa alone \
             does not give its force; record cap_pressure_pa and rod_pressure_pa",
        )
    } else {
        Err(
            "no pressure recorded in every fitted record: the actuator force needs \
             delta_p_pa (a double-ended actuator) or cap_pressure_pa and rod_pressure_pa",
        )
    }
}

/// The force balance's design over the fitted records, the pressures shifted earlier by
/// `shift_s`. Columns: `[M, C, K, F_μ, m₁ … m_s, (r), f₁ … f_R]`, the last one constant
/// force per fitted record: a pressure transducer's offset (a table at rest holds its
/// friction, so `Δp` cannot be zeroed at rest; ±1 bar on a small actuator is of the order of
/// its friction) and the accelerometers' (times the masses) differ from record to record.
/// The law's own columns (Stribeck, the exponent's score) come after the constants.
#[allow(clippy::too_many_arguments)]
pub(super) fn mechanics_design(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    input: &PlantInput,
    from: ForceFrom,
    storeys: usize,
    shift_s: f64,
    law: &Law,
) -> Result<Design> {
    let m = mechanics_columns(from, storeys, fitted.len(), law);
    let offsets = 4 + storeys + usize::from(from == ForceFrom::ChambersRatioFree);
    let mut design = Design::new(m);
    for (slot, &k) in fitted.iter().enumerate() {
        let r = &records[k];
        let h = periods[k];
        let lp = mechanics_filter(r, h)?;
        let (force, extra) = actuator_force(r, &input.base.actuator, from, shift_s / h)?;
        let Some(a) = &r.a_m_s2 else { continue };
        let v = central_velocity(&r.u_m, h);
        let columns = record_columns(
            &lp,
            r,
            (a.as_slice(), v.as_slice()),
            &force,
            extra.as_deref(),
            storeys,
            law,
        )?;
        let layout = RowLayout {
            m,
            constant: offsets + slot,
            first_tail: offsets + fitted.len(),
        };
        push_moving_samples(&mut design, &columns, &layout, (v.as_slice(), law), (k, h));
    }
    Ok(design)
}

/// One record's actuator force, the pressures shifted earlier by `samples`: `n·A·Δp`,
/// `n(A_a·p_a − A_b·p_b)`, or (the area ratio free) `n·A·p_a` with `n·A·p_b` apart, the
/// regressor of the ratio.
fn actuator_force(
    r: &SystemRecord,
    act: &Actuator,
    from: ForceFrom,
    samples: f64,
) -> Result<(Vec<f64>, Option<Vec<f64>>)> {
    let n_act = f64::from(act.count);
    let sh = |x: &Option<Vec<f64>>| -> Result<Vec<f64>> {
        skew::shift(r, x.as_deref().unwrap_or(&[]), samples)
    };
    Ok(match from {
        ForceFrom::DeltaP => (
            sh(&r.delta_p_pa)?
                .iter()
                .map(|dp| n_act * act.cap_area_m2 * dp)
                .collect(),
            None,
        ),
        ForceFrom::Chambers => {
            let (pa, pb) = (sh(&r.cap_pressure_pa)?, sh(&r.rod_pressure_pa)?);
            (
                pa.iter()
                    .zip(&pb)
                    .map(|(pa, pb)| n_act * (act.cap_area_m2 * pa - act.rod_area_m2 * pb))
                    .collect(),
                None,
            )
        }
        ForceFrom::ChambersRatioFree => {
            let (pa, pb) = (sh(&r.cap_pressure_pa)?, sh(&r.rod_pressure_pa)?);
            let f =
                |p: &[f64]| -> Vec<f64> { p.iter().map(|p| n_act * act.cap_area_m2 * p).collect() };
            (f(&pa), Some(f(&pb)))
        }
    })
}

/// One record's force balance through the low-pass: the force, the regressors in the
/// design's order, the law's extra columns and the record's constant.
struct RecordColumns {
    /// The actuator force (the regressand).
    y: Vec<f64>,
    /// `[a, |v|^α·sgn v, u, sgn v, a₁ … a_s, (n·A·p_b)]`.
    regressors: Vec<Vec<f64>>,
    /// The Stribeck column and the exponent's score, as the law has them.
    tail: Vec<Vec<f64>>,
    /// The record's constant, through the same filter (its start is cut with the edge).
    constant: Vec<f64>,
}

/// [`RecordColumns`] of record `r` with its acceleration `a` and velocity `v`, the force
/// `force` and the area ratio's regressor `extra`, every one through the low-pass `lp`.
fn record_columns(
    lp: &ButterworthLowpass,
    r: &SystemRecord,
    (a, v): (&[f64], &[f64]),
    force: &[f64],
    extra: Option<&[f64]>,
    storeys: usize,
    law: &Law,
) -> Result<RecordColumns> {
    let sgn: Vec<f64> = v.iter().map(|v| v.signum()).collect();
    let y = filtered(lp, r, force)?;
    // C·|v|^α·sgn(v): exactly v for α = 1 (the linear law's column, bit for bit).
    let viscous: Vec<f64> = if law.exponent == 1.0 {
        v.to_vec()
    } else {
        v.iter()
            .map(|v| v.signum() * v.abs().powf(law.exponent))
            .collect()
    };
    let mut regressors = vec![
        filtered(lp, r, a)?,
        filtered(lp, r, &viscous)?,
        filtered(lp, r, &r.u_m)?,
        filtered(lp, r, &sgn)?,
    ];
    for st in r.storey_a_m_s2.iter().take(storeys) {
        regressors.push(filtered(lp, r, st)?);
    }
    if let Some(e) = extra {
        // n·A·(p_a − r·p_b) = M·a + …: the rod side's term moves to the regressors,
        // n·A·p_a = M·a + … + r·(n·A·p_b).
        regressors.push(filtered(lp, r, e)?);
    }
    let mut tail = Vec::new();
    if let Some(b) = law.decay_s_per_m {
        let stribeck: Vec<f64> = v
            .iter()
            .map(|v| v.signum() * (-b * v.abs()).exp())
            .collect();
        tail.push(filtered(lp, r, &stribeck)?);
    }
    if law.exponent_score {
        // ∂(|v|^α sgn v)/∂α at α = 1: its coefficient is C·(α − 1) to first order.
        let score: Vec<f64> = v
            .iter()
            .map(|&v| if v == 0.0 { 0.0 } else { v * v.abs().ln() })
            .collect();
        tail.push(filtered(lp, r, &score)?);
    }
    let constant = filtered(lp, r, &vec![1.0; r.u_m.len()])?;
    Ok(RecordColumns {
        y,
        regressors,
        tail,
        constant,
    })
}

/// Where a record's columns go in a row of the design.
struct RowLayout {
    /// The row's length.
    m: usize,
    /// The column of the record's constant.
    constant: usize,
    /// The column of the law's first extra one.
    first_tail: usize,
}

/// Pushes the samples of record `k` (period `h`) that are away from the edges and from rest
/// (velocity `v` at least the `law`'s slip speed, [`stick_guard_samples`] either side).
fn push_moving_samples(
    design: &mut Design,
    c: &RecordColumns,
    layout: &RowLayout,
    (v, law): (&[f64], &Law),
    (k, h): (usize, f64),
) {
    let n = v.len();
    let edge = ((0.5 / h) as usize).min(n / 4);
    let near_rest = near_rest(v, law.slip_speed_m_s);
    let mut row = vec![0.0; layout.m];
    for i in edge..n - edge {
        if near_rest[i] {
            continue;
        }
        for (x, col) in row.iter_mut().zip(&c.regressors) {
            *x = col[i];
        }
        row[layout.constant] = c.constant[i];
        for (j, col) in c.tail.iter().enumerate() {
            row[layout.first_tail + j] = col[i];
        }
        design.push(&row, c.y[i], k, i);
    }
}

/// The samples slower than `slip_speed_m_s` and those within [`stick_guard_samples`] of one:
/// the low-pass spreads the friction there (a stick reaction, not ±F_μ) over them.
fn near_rest(v: &[f64], slip_speed_m_s: f64) -> Vec<bool> {
    let n = v.len();
    let guard = stick_guard_samples();
    let mut near = vec![false; n];
    for i in 0..n {
        if v[i].abs() < slip_speed_m_s {
            for flag in &mut near[i.saturating_sub(guard)..(i + guard + 1).min(n)] {
                *flag = true;
            }
        }
    }
    near
}

/// Samples on each side of one slower than the slip speed that are left out of the force
/// balance with it: half the period of the low-pass's corner (5 samples at a tenth of the rate),
/// the reach of its main lobe. On the stand-ins of real records (a platen stuck a quarter of
/// the time, 138 stick-slip events in 17.6 s) the force residual fell from 4.4 % to 1.4 % of
/// the force and the Stribeck amplitude's standard error by half (3 and 8 samples give a
/// mass within 0.2 % of 5's, residuals of 1.7 and 1.1 %).
fn stick_guard_samples() -> usize {
    (0.5 / MECHANICS_LOWPASS_FRACTION).round() as usize
}

/// The force balance's column count: platen, storeys, the free area ratio, one constant per
/// fitted record (see [`mechanics_design`]).
pub(super) fn mechanics_columns(
    from: ForceFrom,
    storeys: usize,
    records: usize,
    law: &Law,
) -> usize {
    4 + storeys
        + usize::from(from == ForceFrom::ChambersRatioFree)
        + records
        + usize::from(law.decay_s_per_m.is_some())
        + usize::from(law.exponent_score)
}

/// The constraints of the force balance: `C, K, F_μ ≥ 0`.
pub(super) fn mechanics_signs(m: usize) -> Vec<bool> {
    (0..m).map(|j| (1..=3).contains(&j)).collect()
}
