//! The platen's force balance: its design over the fitted records (the actuator force from
//! the pressures, the regressors through the zero-phase low-pass, the samples near rest left
//! out), the pressures' skew it finds, and the platen's values it gives.

use std::collections::BTreeMap;

use platen_system::TableSystemParts;

use super::design::{mechanics_columns, mechanics_design, mechanics_signs, ForceFrom, Law};
use super::friction::friction_law;
use super::storeys::plant_storeys;
use super::{IdentifiedPlant, PlantInput};
use crate::error::Result;
use crate::system::fit::LinearFit;
use crate::system::skew::{self, ChannelSkew, MIN_APPLIED_SAMPLES, PRESSURE_SHIFT_GRID};
use crate::system::SystemRecord;

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
    /// Samples slower than this were left out of the fit, m/s ([`SLIP_SPEED_M_S`](super::design::SLIP_SPEED_M_S), or
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
