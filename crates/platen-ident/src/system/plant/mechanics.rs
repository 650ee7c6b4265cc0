//! The platen's force balance: its design over the fitted records (the actuator force from
//! the pressures, the regressors through the zero-phase low-pass, the samples near rest left
//! out), the pressures' skew it finds, and the platen's values it gives.

use std::collections::BTreeMap;

use platen_signal::ButterworthLowpass;
use platen_system::{Actuator, TableSystemParts};

use super::filters::{central_velocity, filtered, mechanics_filter, MECHANICS_LOWPASS_FRACTION};
use super::friction::{friction_law, Law};
use super::storeys::plant_storeys;
use super::{IdentifiedPlant, PlantInput};
use crate::error::Result;
use crate::system::fit::{Design, LinearFit};
use crate::system::skew::{self, ChannelSkew, MIN_APPLIED_SAMPLES, PRESSURE_SHIFT_GRID};
use crate::system::SystemRecord;

/// Samples slower than this are left out of the mechanics fit (the friction there may be a
/// stick reaction, not `±F_μ`), m/s.
pub const SLIP_SPEED_M_S: f64 = 0.01;

/// The platen's mechanics found by least squares.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IdentifiedMechanics {
    /// `Mₑ`, kg (the platen alone: the storeys' masses are separate).
    pub effective_mass_kg: f64,
    /// `Kₑ`, N/m.
    pub stiffness_n_per_m: f64,
    /// Viscous coefficient `C`, N·(s/m)^α.
    pub viscous_coefficient: f64,
    /// Viscous exponent `α` (1 unless the records support another:
    /// [`EXPONENT_GRID`](crate::system::EXPONENT_GRID)).
    pub viscous_exponent: f64,
    /// Stribeck amplitude `a`, N (0 unless the records support the term).
    pub low_velocity_force_n: f64,
    /// Stribeck decay `b`, s/m ([`DECAY_GRID_S_PER_M`](crate::system::DECAY_GRID_S_PER_M);
    /// 0 without the term).
    pub low_velocity_decay_s_per_m: f64,
    /// Samples slower than this were left out of the fit, m/s ([`SLIP_SPEED_M_S`], or
    /// [`LOW_SLIP_SPEED_M_S`](crate::system::LOW_SLIP_SPEED_M_S) for a richer law).
    pub slip_speed_m_s: f64,
    /// Coulomb force `F_μ`, N.
    pub coulomb_force_n: f64,
    /// Samples in the fit (`|v| ≥` `slip_speed_m_s`).
    pub samples: usize,
    /// RMS of the force residual, N.
    pub force_rms_residual_n: f64,
    /// That RMS relative to the actuator force's RMS.
    pub force_nrmse: f64,
    /// The rod side's area over the cap side's, when identified (both pressures, no base).
    pub rod_to_cap_area_ratio: Option<f64>,
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

/// The mechanics fit, the pressures' skew found by the force balance and corrected in
/// `records` (and reported).
#[allow(clippy::too_many_arguments)]
fn fit_mechanics(
    records: &mut [SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    input: &PlantInput,
    from: ForceFrom,
    storeys: usize,
    skew_report: &mut Vec<ChannelSkew>,
) -> Result<Option<(LinearFit, Law)>> {
    let m = mechanics_columns(from, storeys, fitted.len(), &Law::LINEAR);
    let (signs, none) = (mechanics_signs(m), vec![false; m]);
    let h0 = periods[fitted[0]];
    // The linear law's residual with the pressures shifted earlier by `samples`.
    let rss_at = |samples: f64| -> Result<Option<f64>> {
        let d = mechanics_design(
            records,
            periods,
            fitted,
            input,
            from,
            storeys,
            samples * h0,
            &Law::LINEAR,
        )?;
        Ok(d.fit(&signs, &none).map(|f| f.rss))
    };
    let grid = PRESSURE_SHIFT_GRID
        .iter()
        .map(|&s| rss_at(s))
        .collect::<Result<Vec<_>>>()?;
    let best = grid
        .iter()
        .enumerate()
        .filter_map(|(i, r)| r.map(|r| (i, r)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    let Some((ib, rb)) = best else {
        return Ok(None);
    };
    let step = PRESSURE_SHIFT_GRID[1] - PRESSURE_SHIFT_GRID[0];
    let samples = match (
        ib.checked_sub(1).and_then(|i| grid[i]),
        grid.get(ib + 1).copied().flatten(),
    ) {
        (Some(ym), Some(yp)) => skew::parabola_vertex(PRESSURE_SHIFT_GRID[ib], step, ym, rb, yp),
        _ => PRESSURE_SHIFT_GRID[ib],
    };
    let zero = PRESSURE_SHIFT_GRID
        .iter()
        .position(|&x| x == 0.0)
        .and_then(|i| grid[i]);
    let final_rss = rss_at(samples)?;
    let residual_ratio = match (final_rss, zero) {
        (Some(a), Some(b)) if b > 0.0 => Some(a / b),
        _ => None,
    };
    let applied = samples.abs() > MIN_APPLIED_SAMPLES
        && residual_ratio.is_some_and(|r| r <= skew::PRESSURE_SKEW_MAX_RESIDUAL_RATIO);
    let column = match from {
        ForceFrom::DeltaP => "delta_p_pa",
        _ => "cap_pressure_pa, rod_pressure_pa",
    };
    skew_report.push(ChannelSkew {
        column: column.into(),
        delay_s: samples * h0,
        std_error_s: None,
        delay_samples: samples,
        applied,
        residual_ratio,
        method: "the shift that fits the platen's force balance best (a grid of half samples, \
                 then a parabola through the best three)",
        per_record: Vec::new(),
    });
    if applied {
        skew::correct_pressures(records, periods, samples * h0)?;
    }
    friction_law(records, periods, fitted, input, from, storeys)
}

/// The platen's mechanics and the specimen's storeys of [`identify_plant`] (force `from`,
/// `storeys` recorded): into `plant`, with a free rod-to-cap area ratio into `base`.
///
/// [`identify_plant`]: super::identify_plant
#[allow(clippy::too_many_arguments)]
pub(super) fn plant_mechanics(
    records: &mut [SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    input: &PlantInput,
    (from, storeys): (ForceFrom, usize),
    skew_report: &mut Vec<ChannelSkew>,
    (base, plant): (&mut TableSystemParts, &mut IdentifiedPlant),
    not_identified: &mut Vec<(String, String)>,
) -> Result<()> {
    let Some((f, law)) =
        fit_mechanics(records, periods, fitted, input, from, storeys, skew_report)?
    else {
        return Ok(());
    };
    let se = |j: usize| f.estimates[j].std_error;
    let ratio = (from == ForceFrom::ChambersRatioFree).then(|| f.coef[4 + storeys]);
    if let Some(r) = ratio {
        base.actuator.rod_area_m2 = r * base.actuator.cap_area_m2;
        plant.std_errors.insert(
            "table_system.actuator.rod_side_area_m2".into(),
            se(4 + storeys) * base.actuator.cap_area_m2,
        );
    }
    let mech = mechanics_values(&f, &law, ratio, &mut plant.std_errors);
    for (name, j) in [
        ("viscous_coefficient", 1),
        ("stiffness_n_per_m", 2),
        ("coulomb_force_n", 3),
    ] {
        if f.clamped[j] {
            not_identified.push((
                name.to_owned(),
                "held at 0: the unconstrained force balance makes it negative, \
                 which no platen has"
                    .to_owned(),
            ));
        }
    }
    let masses: Vec<f64> = f.coef[4..4 + storeys].to_vec();
    for (j, _) in masses.iter().enumerate() {
        plant
            .std_errors
            .insert(format!("specimen.storeys[{j}].mass_kg"), se(4 + j));
    }
    plant.mechanics = Some(mech);
    plant_storeys(records, periods, fitted, &masses, plant, not_identified);
    Ok(())
}

/// The platen's values of the force balance's fit `f` with its `law` (and the area `ratio`
/// when free), their finite standard errors into `std_errors`.
fn mechanics_values(
    f: &LinearFit,
    law: &Law,
    ratio: Option<f64>,
    std_errors: &mut BTreeMap<String, f64>,
) -> IdentifiedMechanics {
    let c = &f.coef;
    let se = |j: usize| f.estimates[j].std_error;
    // The Stribeck amplitude is the last column when the law has it.
    let stribeck = law
        .decay_s_per_m
        .map(|b| (c[c.len() - 1], b, se(c.len() - 1)));
    if let Some((_, _, e)) = stribeck {
        if e.is_finite() {
            std_errors.insert("model.identified.low_velocity_force_n".into(), e);
        }
    }
    for (j, key) in [
        (0, "effective_mass_kg"),
        (1, "viscous_coefficient"),
        (2, "stiffness_n_per_m"),
        (3, "coulomb_force_n"),
    ] {
        if se(j).is_finite() {
            std_errors.insert(format!("model.identified.{key}"), se(j));
        }
    }
    IdentifiedMechanics {
        effective_mass_kg: c[0],
        viscous_coefficient: c[1],
        viscous_exponent: law.exponent,
        low_velocity_force_n: stribeck.map_or(0.0, |s| s.0),
        low_velocity_decay_s_per_m: stribeck.map_or(0.0, |s| s.1),
        slip_speed_m_s: law.slip_speed_m_s,
        stiffness_n_per_m: c[2],
        coulomb_force_n: c[3],
        samples: f.rows,
        force_rms_residual_n: f.rms_residual(),
        force_nrmse: f.nrmse(),
        rod_to_cap_area_ratio: ratio,
    }
}
