//! Where each value of the identified table's scenario comes from: identified from the
//! records (with its standard error where the fit gives one), given (the lab's drawings,
//! `--base`, or the area alone), or assumed (a nominal value, with why it cannot be known).
//! Nothing in the scenario comes silently from a preset.

use super::plant::{
    IdentifiedPlant, PlantInput, NOMINAL_AREA_M2, NOMINAL_BULK_MODULUS_PA, NOMINAL_RATED_DROP_PA,
    NOMINAL_RETURN_PRESSURE_PA, NOMINAL_SUPPLY_PRESSURE_PA,
};
use super::SystemIdentification;

/// Where a value comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Source {
    /// Fitted to the records.
    Identified,
    /// From the lab (the base's drawings or an area given).
    Given,
    /// A nominal value the records cannot show.
    Assumed,
}

/// One value of the identified scenario and where it comes from.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ValueProvenance {
    /// Its path in the scenario (`model.identified.effective_mass_kg`,
    /// `table_system.actuator.chamber_volume_m3[0]`, …).
    pub path: String,
    /// Where it comes from.
    pub source: Source,
    /// Its standard error (identified values whose fit gives one).
    pub std_error: Option<f64>,
    /// Why, where it is not plainly identified.
    pub note: Option<String>,
}

fn entry(path: &str, source: Source, note: Option<&str>) -> ValueProvenance {
    ValueProvenance {
        path: path.to_owned(),
        source,
        std_error: None,
        note: note.map(str::to_owned),
    }
}

/// The provenance of every value of the scenario that `id` and `plant` make.
pub(crate) fn of(
    id: &SystemIdentification,
    plant: &IdentifiedPlant,
    input: &PlantInput,
) -> Vec<ValueProvenance> {
    let mut out = Vec::new();
    model_provenance(plant, &mut out);
    if plant.system.is_some() {
        actuator_provenance(plant, input, &mut out);
        loop_provenance(plant, input, &mut out);
    }
    controller_provenance(id, &mut out);
    refined_provenance(id, &mut out);
    for p in &mut out {
        if p.std_error.is_none() {
            p.std_error = plant.std_errors.get(&p.path).copied();
        }
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    out
}

/// Where the values a lab's drawings give come from: given with `--base`, else assumed.
fn drawings(input: &PlantInput) -> Source {
    if input.base_given {
        Source::Given
    } else {
        Source::Assumed
    }
}

/// The note of a value the drawings give, when there are none: the nominal `value` of
/// `what` taken instead.
fn nominal(input: &PlantInput, what: &str, value: f64) -> Option<String> {
    (!input.base_given).then(|| {
        format!(
            "no drawings: nominal {what} {value} (the records cannot show it; pass --base to \
             give the lab's)"
        )
    })
}

/// A value with a note made for it.
fn with_note(path: &str, source: Source, note: Option<String>) -> ValueProvenance {
    ValueProvenance {
        note,
        ..entry(path, source, None)
    }
}

/// The platen's model and the specimen's storeys.
fn model_provenance(plant: &IdentifiedPlant, out: &mut Vec<ValueProvenance>) {
    use Source::{Assumed, Identified};
    if plant.model.is_some() {
        for key in [
            "effective_mass_kg",
            "stiffness_n_per_m",
            "coulomb_force_n",
            "viscous_coefficient",
        ] {
            out.push(entry(&format!("model.identified.{key}"), Identified, None));
        }
        let law = plant.mechanics.as_ref();
        if law.is_some_and(|m| m.viscous_exponent != 1.0) {
            out.push(entry(
                "model.identified.viscous_exponent",
                Identified,
                Some("the best of a grid of 0.1 (the score of α = 1 beyond 3 standard errors)"),
            ));
        } else {
            out.push(entry(
                "model.identified.viscous_exponent",
                Assumed,
                Some("1: the records do not tell α from 1 (the score of α = 1 within 3 standard errors)"),
            ));
        }
        if law.is_some_and(|m| m.low_velocity_force_n > 0.0) {
            out.push(entry(
                "model.identified.low_velocity_force_n",
                Identified,
                None,
            ));
            out.push(entry(
                "model.identified.low_velocity_decay_s_per_m",
                Identified,
                Some("the best of a grid (DECAY_GRID_S_PER_M) with the other terms fitted at each"),
            ));
        } else {
            for key in ["low_velocity_force_n", "low_velocity_decay_s_per_m"] {
                out.push(entry(
                    &format!("model.identified.{key}"),
                    Assumed,
                    Some("0: the records do not support a Stribeck term (its amplitude within 3 standard errors of 0)"),
                ));
            }
        }
    }
    for j in 0..plant.storeys.len() {
        for key in ["mass_kg", "stiffness_n_per_m", "damping_n_s_per_m"] {
            out.push(entry(
                &format!("specimen.storeys[{j}].{key}"),
                Identified,
                None,
            ));
        }
    }
}

/// The actuators of the table system.
fn actuator_provenance(
    plant: &IdentifiedPlant,
    input: &PlantInput,
    out: &mut Vec<ValueProvenance>,
) {
    use Source::{Assumed, Given, Identified};
    let drawings = drawings(input);
    let nominal = |what: &str, value: f64| nominal(input, what, value);
    let area_note = (!input.area_given).then(|| {
        format!(
            "no drawings: nominal {NOMINAL_AREA_M2} m² (the records show the plant only \
             in ratios to the area: every mass, force, flow and volume scales with it, the \
             motion does not)"
        )
    });
    let area_source = if input.area_given { Given } else { Assumed };
    out.push(with_note(
        "table_system.actuator.count",
        drawings,
        nominal("count", 1.0),
    ));
    out.push(with_note(
        "table_system.actuator.cap_side_area_m2",
        area_source,
        area_note,
    ));
    let rod = match (
        input.base_given,
        plant.mechanics.and_then(|m| m.rod_to_cap_area_ratio),
    ) {
        (true, _) => entry("table_system.actuator.rod_side_area_m2", Given, None),
        (false, Some(_)) => entry(
            "table_system.actuator.rod_side_area_m2",
            Identified,
            Some("the rod side's share of the area, from the force balance of both pressures"),
        ),
        (false, None) => entry(
            "table_system.actuator.rod_side_area_m2",
            Assumed,
            Some(
                "equal to the cap side's: Δp alone gives the force of a double-ended actuator only",
            ),
        ),
    };
    out.push(rod);
    for k in 0..2 {
        out.push(entry(
            &format!("table_system.actuator.chamber_volume_m3[{k}]"),
            Identified,
            Some("identified as V/β, at the oil_bulk_modulus_pa given or assumed"),
        ));
    }
    out.push(entry(
        "table_system.actuator.leakage_m3_s_per_pa",
        Identified,
        None,
    ));
}

/// The servo-valves, the oil, the supply and the controller's fixed settings.
fn loop_provenance(plant: &IdentifiedPlant, input: &PlantInput, out: &mut Vec<ValueProvenance>) {
    use Source::{Assumed, Identified};
    let drawings = drawings(input);
    let nominal = |what: &str, value: f64| nominal(input, what, value);
    out.push(with_note(
        "table_system.servo_valve.count",
        drawings,
        nominal("count", 1.0),
    ));
    out.push(entry(
        "table_system.servo_valve.rated_flow_m3_s",
        Identified,
        Some("the land coefficient, quoted at the rated pressure drop"),
    ));
    out.push(with_note(
        "table_system.servo_valve.rated_pressure_drop_pa",
        drawings,
        nominal("rated drop (Pa)", NOMINAL_RATED_DROP_PA),
    ));
    let lag_only = plant.hydraulics.is_some_and(|h| h.lag_only);
    for key in ["natural_frequency_hz", "damping_ratio", "delay_s"] {
        out.push(entry(
            &format!("table_system.servo_valve.{key}"),
            Identified,
            Some(if lag_only {
                "the grid's best; only the equivalent lag τ + 2ζ/ω_n is visible in the \
                 records' band"
            } else {
                "the grid's best"
            }),
        ));
    }
    out.push(with_note(
        "table_system.oil_bulk_modulus_pa",
        drawings,
        nominal("bulk modulus (Pa)", NOMINAL_BULK_MODULUS_PA),
    ));
    out.push(with_note(
        "table_system.supply_pressure_pa",
        drawings,
        nominal("supply (Pa)", NOMINAL_SUPPLY_PRESSURE_PA),
    ));
    out.push(with_note(
        "table_system.return_pressure_pa",
        drawings,
        nominal("return (Pa)", NOMINAL_RETURN_PRESSURE_PA),
    ));
    out.push(with_note(
        "table_system.accumulator",
        drawings,
        (!input.base_given).then(|| "no drawings: a constant supply".to_owned()),
    ));
    out.push(entry(
        "table_system.controller.sample_rate_hz",
        Assumed,
        Some("the records' rate, taken as the controller's"),
    ));
    out.push(entry(
        "table_system.controller.integral_gain_per_m_s",
        Assumed,
        Some("0: an integrator is not fitted"),
    ));
}

/// The controller's gains and filter.
fn controller_provenance(id: &SystemIdentification, out: &mut Vec<ValueProvenance>) {
    use Source::{Assumed, Identified};
    for g in &id.gain_estimates {
        out.push(ValueProvenance {
            path: format!("table_system.controller.{}", g.key),
            source: Identified,
            std_error: g.std_error,
            note: g.held_at_zero.then(|| {
                format!(
                    "held at 0 (a scenario takes gains ≥ 0); the unconstrained fit gives {}",
                    g.unconstrained
                        .map_or("no value".to_owned(), |u| format!("{u:.4e}"))
                )
            }),
        });
    }
    if id.gains.is_some() {
        let dp_recorded = id
            .gain_estimates
            .iter()
            .any(|e| e.key == "delta_p_gain_per_pa");
        out.push(entry(
            "table_system.controller.delta_p_highpass_hz",
            if dp_recorded { Identified } else { Assumed },
            Some(if dp_recorded {
                "the grid's best corner"
            } else {
                "0: no delta_p_pa recorded"
            }),
        ));
        for key in ["acceleration_feedback_s2_per_m", "delta_p_gain_per_pa"] {
            if !id.gain_estimates.iter().any(|e| e.key == key) {
                out.push(entry(
                    &format!("table_system.controller.{key}"),
                    Assumed,
                    Some("0: its channel is not recorded"),
                ));
            }
        }
    }
}

/// The values the prediction-error fit refined: identified, with its standard error and a
/// note of where the fit started.
fn refined_provenance(id: &SystemIdentification, out: &mut [ValueProvenance]) {
    let Some(fit) = &id.prediction_error else {
        return;
    };
    for p in fit.parameters.iter().filter(|p| p.refined) {
        let (paths, note): (Vec<String>, String) = match p.key.as_str() {
            "table_system.servo_valve.equivalent_lag_s" => (
                ["delay_s", "natural_frequency_hz"]
                    .iter()
                    .map(|k| format!("table_system.servo_valve.{k}"))
                    .collect(),
                format!(
                    "refined by the prediction-error fit with the spool's period: the \
                     equivalent lag τ + 2ζ/ω_n from {:.4e} s (equation error) to {:.4e} ± {} s",
                    p.start,
                    p.value,
                    p.std_error.map_or("–".into(), |s| format!("{s:.2e}"))
                ),
            ),
            "table_system.actuator.chamber_volume_m3" => (
                (0..2)
                    .map(|k| format!("table_system.actuator.chamber_volume_m3[{k}]"))
                    .collect(),
                format!(
                    "identified as V/β (equation error), both chambers then scaled together by \
                     the prediction-error fit: {:.4e} → {:.4e} m³ at the oil_bulk_modulus_pa \
                     given or assumed",
                    p.start, p.value
                ),
            ),
            key => (
                vec![key.to_owned()],
                format!(
                    "refined by the prediction-error fit (the loop run on the fitted records' \
                     commands, its accelerations and Δp fitted to theirs) from the equation error's \
                     {:.5e}",
                    p.start
                ),
            ),
        };
        for path in paths {
            if let Some(v) = out.iter_mut().find(|v| v.path == path) {
                v.source = Source::Identified;
                v.note = Some(note.clone());
                if p.key == path {
                    v.std_error = p.std_error;
                }
            }
        }
    }
}
