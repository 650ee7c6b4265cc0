//! The plant of the loop (platen, specimen, valves, oil column) identified from what tables
//! record: the command, the displacement, the drive, the pressure difference `Δp` *or* the
//! two chamber pressures, and the accelerations of the table and, where recorded, of the
//! storeys.
//!
//! # What the records can show, and what is taken from the drawings or assumed
//!
//! Scaling every area by `s` and the masses, forces, valve flows, chamber volumes and leakage
//! by `s` as well leaves the motion unchanged: without the actuator geometry only ratios to
//! the area are visible. The geometry a lab knows from its drawings (actuator count, cap and
//! rod areas, valve count, rated pressure drop, supply and return pressures, the oil's bulk
//! modulus) comes from a *base* table system ([`super::SystemSettings::base`]) when given.
//! Without it the plant is laid on a nominal geometry, every value of which is listed as
//! `assumed` ([`super::ValueProvenance`]): one double-ended actuator of
//! [`NOMINAL_AREA_M2`] (or the area given alone, [`super::SystemSettings::area_m2`]), one
//! valve rated at [`NOMINAL_RATED_DROP_PA`], supply [`NOMINAL_SUPPLY_PRESSURE_PA`], return
//! [`NOMINAL_RETURN_PRESSURE_PA`], bulk modulus [`NOMINAL_BULK_MODULUS_PA`]. The masses,
//! forces, flows and volumes then scale with the area; the motion, the oil column, the loop's
//! response and every prediction do not. With both chamber pressures and no base the rod
//! side's share of the area is identified (a regressor of the force balance); with `Δp`
//! alone the actuator is double-ended (`Δp` gives the force only then).
//!
//! * **Platen and specimen masses, stiffness, viscous and Coulomb friction**: linear least
//!   squares of `F_A = M·a + C·v + K·u + F_μ·sgn(v) + Σ mᵢ·aᵢ`, `F_A = n·A·Δp` or
//!   `n(A_a·p_a − A_b·p_b)`, `v` the central difference of `u`, over the samples with
//!   `|v| ≥` [`SLIP_SPEED_M_S`] (where the friction is surely `±F_μ`, not a stick reaction),
//!   every term through the same zero-phase low-pass at [`MECHANICS_LOWPASS_FRACTION`] of the
//!   sample rate (fourth-order Butterworth, forward and backward): content the command does
//!   not drive (hydraulic noise, pumps, an accelerometer's own resonances) lies above it, and
//!   in a regressor it would bias the masses low (errors in variables). `C`, `F_μ` and `K`
//!   are constrained `≥ 0`.
//! * **Storeys' stiffness and damping**: storey `j`'s equation
//!   `Σ_{i≥j} mᵢ·aᵢ = −k_j·δ_j − c_j·δ̇_j` (`δ_j` the drift, the double integral of
//!   `a_j − a_{j−1}`, `a₀` the table's) with both sides passed through the same filter
//!   `s²/(s + ω₀)²` (Tustin, `ω₀ = 2π·`[`DRIFT_HIGHPASS_HZ`]): the drift side becomes
//!   `(a_j − a_{j−1})/(s + ω₀)²`, a stable filter of the record, so no drift is integrated
//!   open loop. The records start at rest, so the causal filters start exact.
//! * **Valves and oil column**: with both pressures, each chamber's continuity
//!   `A_a·v + A_a·u·ṗ_a/β = K·x_v·√drop_a − C_L·Δp − (V_a0/β)·ṗ_a` (and the rod side's); with
//!   `Δp` alone, the load flow of the double-ended actuator
//!   `A·v = K·x_v·√((P_s − P_R − sgn(x_v)·Δp)/2) − C_L·Δp − (V₀/2β)·Δṗ` (the chambers' sum of
//!   pressures stays `P_s + P_R`). Both are linear in the land coefficient `K`, the leakage
//!   `C_L` and the compliances `V/β`, every term through the same low-pass
//!   `ω_c²/(s² + 2ζω_c s + ω_c²)` (`ω_c = 2π·min(`[`CONTINUITY_LOWPASS_HZ`]`, f_s/5)`,
//!   Tustin) so that `ṗ` and `v` come out of the filter's own state instead of differentiated
//!   noise. `x_v` is the recorded drive through the spool (pure delay, then second order),
//!   its delay, natural frequency and damping chosen from a grid by the least residual. Only
//!   `V/β` is visible (the `u·ṗ/β` term is a fraction of a percent at these strokes): `β` is
//!   the base's (or the nominal) and the volumes follow.
//!
//! Every linear fit carries standard errors from its residuals' own correlation
//! ([`super::fit`]); they are listed per scenario value in [`IdentifiedPlant::std_errors`].
//!
//! # Where each part is
//!
//! * [`mechanics`]: the platen's force balance (and the pressures' skew it finds), with
//!   [`friction`] the friction law it is fitted with;
//! * [`storeys`]: the storeys' equations and the specimen's modes;
//! * [`hydraulics`]: the chambers' continuity, the valves and oil column;
//! * [`filters`]: the filters they share.
//!
//! This file lays the plant's geometry ([`PlantInput`]), runs the three fits in that order
//! ([`identify_plant`]) and assembles the model and specimen they give.

use std::collections::BTreeMap;

use platen_model::{IdentifiedParams, Specimen, Storey};
use platen_system::{Actuator, Controller, ServoValve, Supply, TableSystem, TableSystemParts};

use super::skew::ChannelSkew;
use super::{SystemRecord, SystemSettings};
use crate::error::Result;
use design::force_from;
use hydraulics::plant_hydraulics;
use mechanics::plant_mechanics;

mod design;
mod filters;
mod friction;
mod hydraulics;
mod mechanics;
mod storeys;

pub use design::SLIP_SPEED_M_S;
pub use filters::MECHANICS_LOWPASS_FRACTION;
pub use friction::{DECAY_GRID_S_PER_M, EXPONENT_GRID, FRICTION_TERM_T, LOW_SLIP_SPEED_M_S};
pub use hydraulics::{IdentifiedHydraulics, CONTINUITY_LOWPASS_HZ};
pub use mechanics::IdentifiedMechanics;
pub(super) use storeys::modes;
pub use storeys::{IdentifiedStorey, Mode, DRIFT_HIGHPASS_HZ};

/// The actuator area the plant is laid on without drawings, m² (assumed: the records show
/// only ratios to it).
pub const NOMINAL_AREA_M2: f64 = 0.01;
/// The supply pressure assumed without drawings, Pa (a usual lab supply; its effect on the
/// motion is through `√(P_s − P_R ∓ Δp)` only, small while `Δp ≪ P_s`).
pub const NOMINAL_SUPPLY_PRESSURE_PA: f64 = 21e6;
/// The return pressure assumed without drawings, Pa.
pub const NOMINAL_RETURN_PRESSURE_PA: f64 = 0.3e6;
/// The oil's bulk modulus assumed without drawings, Pa (mineral oil with some air; only
/// `V/β` is identified, the volumes follow from it).
pub const NOMINAL_BULK_MODULUS_PA: f64 = 1.5e9;
/// The valves' rated pressure drop assumed without drawings, Pa (the usual rating: the rated
/// flow is quoted at it).
pub const NOMINAL_RATED_DROP_PA: f64 = 7e6;

/// The stroke limit of an identified table without drawings: this share of the stroke its
/// identified chamber volumes allow (the chambers must keep oil at the ends).
pub const STROKE_FRACTION_OF_ROOM: f64 = 0.9;

/// The stroke limit of an identified table system: [`STROKE_FRACTION_OF_ROOM`] of the
/// stroke its chambers allow (`min(V_a0/A_a, V_b0/A_b)`), m.
pub fn stroke_limit_m(system: &TableSystem) -> f64 {
    actuator_stroke_limit_m(system.actuator())
}

/// [`stroke_limit_m`] of an actuator's values, checked or not.
fn actuator_stroke_limit_m(a: &Actuator) -> f64 {
    STROKE_FRACTION_OF_ROOM * (a.cap_volume_m3 / a.cap_area_m2).min(a.rod_volume_m3 / a.rod_area_m2)
}

/// Where the plant's absolute scale comes from.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Geometry {
    /// The cap-side area the plant is laid on, m².
    pub area_m2: f64,
    /// `"given"` (the base, or the area alone) or `"assumed"` (nominal: the masses, forces,
    /// flows and volumes scale with it; the motion does not).
    pub area_source: &'static str,
    /// Whether the rest of the geometry (counts, rated drop, supply and return pressures,
    /// bulk modulus) comes from a base (else nominal, assumed).
    pub base_given: bool,
}

/// What the plant fit found (see the module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct IdentifiedPlant {
    /// The platen.
    pub mechanics: Option<IdentifiedMechanics>,
    /// The storeys, bottom first (empty without storey accelerations).
    pub storeys: Vec<IdentifiedStorey>,
    /// The specimen's fixed-base modes, lowest first.
    pub specimen_modes: Vec<Mode>,
    /// The records' own modal content (roof over table, no model), with the identified modes
    /// checked against it; `None` without storey accelerations.
    pub transmissibility: Option<super::Transmissibility>,
    /// Valves and oil column.
    pub hydraulics: Option<IdentifiedHydraulics>,
    /// The absolute scale.
    pub geometry: Geometry,
    /// Standard errors of the identified values, by their path in the printed scenario
    /// (`model.identified.effective_mass_kg`, `specimen.storeys[0].stiffness_n_per_m`,
    /// `table_system.servo_valve.rated_flow_m3_s`, …).
    pub std_errors: BTreeMap<String, f64>,
    /// The identified table system (the base's or nominal geometry, the fitted rest), when
    /// the valves were identified.
    #[serde(skip)]
    pub system: Option<TableSystem>,
    /// The identified platen model.
    #[serde(skip)]
    pub model: Option<IdentifiedParams>,
    /// The identified specimen.
    #[serde(skip)]
    pub specimen: Option<Specimen>,
}

/// The geometry the plant is laid on ([`super::SystemSettings`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PlantInput {
    /// The base's values (given, or nominal), which the fit changes.
    pub base: TableSystemParts,
    /// Whether `base` is the lab's (else nominal).
    pub base_given: bool,
    /// Whether the area was given (with the base, or alone).
    pub area_given: bool,
}

impl PlantInput {
    /// The base of `settings`, else a nominal one of one double-ended actuator.
    pub fn new(settings: &SystemSettings, first: &SystemRecord) -> Self {
        if let Some(base) = settings.base {
            return Self {
                base: base.into_parts(),
                base_given: true,
                area_given: true,
            };
        }
        let area = settings.area_m2.unwrap_or(NOMINAL_AREA_M2);
        let h = first.period_s().unwrap_or(1e-3);
        let base = TableSystemParts {
            actuator: Actuator {
                count: 1,
                cap_area_m2: area,
                rod_area_m2: area,
                // Replaced by the fitted ones; placeholders for a valid system.
                cap_volume_m3: area,
                rod_volume_m3: area,
                leakage_m3_s_per_pa: 0.0,
            },
            servo_valve: ServoValve {
                count: 1,
                rated_flow_m3_s: 1e-3,
                rated_pressure_drop_pa: NOMINAL_RATED_DROP_PA,
                natural_frequency_hz: 100.0,
                damping_ratio: 0.7,
                delay_s: 0.0,
            },
            oil_bulk_modulus_pa: NOMINAL_BULK_MODULUS_PA,
            supply_pressure_pa: NOMINAL_SUPPLY_PRESSURE_PA,
            return_pressure_pa: NOMINAL_RETURN_PRESSURE_PA,
            supply: Supply::Constant,
            controller: Controller {
                sample_rate_hz: 1.0 / h,
                displacement_gain_per_m: 0.0,
                integral_gain_per_m_s: 0.0,
                velocity_feedforward_s_per_m: 0.0,
                acceleration_feedforward_s2_per_m: 0.0,
                velocity_feedback_s_per_m: 0.0,
                acceleration_feedback_s2_per_m: 0.0,
                delta_p_gain_per_pa: 0.0,
                delta_p_highpass_hz: 0.0,
            },
        };
        Self {
            base,
            base_given: false,
            area_given: settings.area_m2.is_some(),
        }
    }
}

/// Fits the plant on the `fitted` records in `input`'s geometry; corrects the pressures'
/// skew in `records` (reported in `skew_report`); `not_identified` gets what cannot be seen.
///
/// # Errors
/// [`IdentError::Signal`](crate::IdentError::Signal) when a filter cannot be made for a
/// record's rate.
pub(crate) fn identify_plant(
    records: &mut [SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    input: &PlantInput,
    skew_report: &mut Vec<ChannelSkew>,
    not_identified: &mut Vec<(String, String)>,
) -> Result<IdentifiedPlant> {
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    let mut base = input.base;
    let mut plant = IdentifiedPlant {
        mechanics: None,
        storeys: Vec::new(),
        specimen_modes: Vec::new(),
        transmissibility: None,
        hydraulics: None,
        geometry: Geometry {
            area_m2: base.actuator.cap_area_m2,
            area_source: if input.area_given { "given" } else { "assumed" },
            base_given: input.base_given,
        },
        std_errors: BTreeMap::new(),
        system: None,
        model: None,
        specimen: None,
    };
    if !input.base_given {
        not_identified.push(why(
            "the plant's absolute scale (actuator area; with it every mass, force, flow and volume)",
            "scaling every area, mass, force, flow and volume together leaves the motion \
             unchanged, so the records show only ratios to the area: the plant is laid on the \
             area given or a nominal one (listed as assumed); the motion, the oil column and \
             every prediction do not depend on it",
        ));
    }
    let storeys = fitted
        .iter()
        .map(|&i| records[i].storey_a_m_s2.len())
        .min()
        .unwrap_or(0);
    let has_a = fitted.iter().all(|&i| records[i].a_m_s2.is_some());
    let from = force_from(records, fitted, input);
    match (&from, has_a) {
        (Err(reason), _) => not_identified.push(why(
            "platen mass, stiffness, friction; specimen; servo-valves and oil column",
            reason,
        )),
        (Ok(_), false) => not_identified.push(why(
            "platen mass, stiffness, friction; specimen",
            "no a_m_s2 in every fitted record: the inertia cannot be separated",
        )),
        (Ok(from), true) => plant_mechanics(
            records,
            periods,
            fitted,
            input,
            (*from, storeys),
            skew_report,
            (&mut base, &mut plant),
            not_identified,
        )?,
    }
    plant.std_errors.retain(|_, v| v.is_finite());
    plant_hydraulics(
        records,
        periods,
        fitted,
        &from,
        &base,
        &mut plant,
        not_identified,
    );
    finish_plant(&mut plant, not_identified);
    Ok(plant)
}

/// The identified model and specimen of [`identify_plant`], from its mechanics and storeys.
fn finish_plant(plant: &mut IdentifiedPlant, not_identified: &mut Vec<(String, String)>) {
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    if let Some(m) = &plant.mechanics {
        plant.model = Some(IdentifiedParams {
            effective_mass_kg: m.effective_mass_kg,
            stiffness_n_per_m: m.stiffness_n_per_m.max(0.0),
            coulomb_force_n: m.coulomb_force_n.max(0.0),
            viscous_coefficient: m.viscous_coefficient.max(0.0),
            viscous_exponent: m.viscous_exponent,
            low_velocity_force_n: m.low_velocity_force_n,
            low_velocity_decay_s_per_m: m.low_velocity_decay_s_per_m,
        });
        if m.low_velocity_force_n == 0.0 {
            not_identified.push(why(
                "low_velocity_force_n, low_velocity_decay_s_per_m",
                "the records do not support a Stribeck term: its amplitude at the best decay \
                 is not 3 standard errors above 0 (taken as 0)",
            ));
        }
        if m.viscous_exponent == 1.0 {
            not_identified.push(why(
                "a viscous exponent other than 1",
                "the records do not tell α from 1: the score of α = 1 is within 3 standard \
                 errors of 0 (taken as 1)",
            ));
        } else {
            not_identified.push(why(
                "the viscous exponent's standard error",
                "α is the best of a grid of 0.1 (EXPONENT_GRID), with F_μ, a and C fitted at \
                 each; the others' standard errors are at that α",
            ));
        }
    }
    if !plant.storeys.is_empty() {
        plant.specimen = Specimen::new(
            plant
                .storeys
                .iter()
                .map(|s| Storey {
                    mass_kg: s.mass_kg,
                    stiffness_n_per_m: s.stiffness_n_per_m,
                    damping_n_s_per_m: s.damping_n_s_per_m.max(0.0),
                })
                .collect(),
        )
        .ok();
    }
}
