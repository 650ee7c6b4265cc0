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

use std::collections::BTreeMap;

use nalgebra::{DMatrix, SymmetricEigen};
use platen_model::{IdentifiedParams, Specimen, Storey};
use platen_signal::{ButterworthLowpass, ZeroPhaseFilter};
use platen_system::{Actuator, Controller, ServoValve, Supply, TableSystem, TableSystemParts};

use super::fit::{Design, LinearFit};
use super::skew::{self, ChannelSkew, MIN_APPLIED_SAMPLES, PRESSURE_SHIFT_GRID};
use super::{SystemRecord, SystemSettings};
use crate::error::{IdentError, Result};

/// Samples slower than this are left out of the mechanics fit (the friction there may be a
/// stick reaction, not `±F_μ`), m/s.
pub const SLIP_SPEED_M_S: f64 = 0.01;
/// Corner of the `s²/(s + ω₀)²` filter on the storey equations, Hz. The drift regressor is
/// the relative acceleration through `1/(s + ω₀)²`, whose gain is flat below `ω₀`: the
/// accelerometers' noise there, integrated twice, would be in the regressor and bias the
/// stiffness low (errors in variables). The noise's share of the regressor is least for `ω₀`
/// near the specimen's modes; 2 Hz is below the first mode of the specimens shake tables
/// carry and keeps that share small (on the small table's records, where the frame's first
/// mode is at 6.5 Hz, a 0.3 Hz corner gave its stiffness 33 % low).
pub const DRIFT_HIGHPASS_HZ: f64 = 2.0;
/// Highest corner of the low-pass on the continuity equations, Hz (a fifth of the sample
/// rate below 500 Hz).
pub const CONTINUITY_LOWPASS_HZ: f64 = 100.0;
/// Corner of the zero-phase low-pass on the force balance, as a fraction of the sample rate
/// (20.5 Hz at 204.8 Hz, 102 Hz at 1024 Hz): below the content a command does not drive,
/// above the platen's motion.
pub const MECHANICS_LOWPASS_FRACTION: f64 = 0.1;
/// Spool natural frequencies tried, Hz.
pub const SPOOL_FREQUENCY_GRID_HZ: [f64; 6] = [60.0, 100.0, 150.0, 200.0, 300.0, 500.0];
/// Spool damping ratios tried.
pub const SPOOL_DAMPING_GRID: [f64; 3] = [0.5, 0.7, 0.9];
/// Valve delays tried, in sixteenths of the controller period.
pub const DELAY_GRID_SIXTEENTHS: [u32; 5] = [0, 4, 8, 12, 16];
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

/// The platen's mechanics found by least squares.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IdentifiedMechanics {
    /// `Mₑ`, kg (the platen alone: the storeys' masses are separate).
    pub effective_mass_kg: f64,
    /// `Kₑ`, N/m.
    pub stiffness_n_per_m: f64,
    /// Viscous coefficient `C`, N·(s/m)^α.
    pub viscous_coefficient: f64,
    /// Viscous exponent `α` (1 unless the records support another: [`EXPONENT_GRID`]).
    pub viscous_exponent: f64,
    /// Stribeck amplitude `a`, N (0 unless the records support the term).
    pub low_velocity_force_n: f64,
    /// Stribeck decay `b`, s/m ([`DECAY_GRID_S_PER_M`]; 0 without the term).
    pub low_velocity_decay_s_per_m: f64,
    /// Samples slower than this were left out of the fit, m/s ([`SLIP_SPEED_M_S`], or
    /// [`LOW_SLIP_SPEED_M_S`] for a richer law).
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

/// One identified storey, with its fit.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IdentifiedStorey {
    /// Floor mass, kg (from the platen's equation).
    pub mass_kg: f64,
    /// Storey stiffness, N/m.
    pub stiffness_n_per_m: f64,
    /// Storey damping, N·s/m.
    pub damping_n_s_per_m: f64,
    /// RMS residual of the storey's equation relative to its (filtered) shear's RMS.
    pub shear_nrmse: f64,
}

/// A fixed-base mode of the identified specimen.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Mode {
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Modal damping ratio (classical: `φᵀCφ / 2ωφᵀMφ`).
    pub damping_ratio: f64,
}

/// The valves and the oil column found from the chambers' continuity.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IdentifiedHydraulics {
    /// Land coefficient of one actuator's valves together, m³/s/√Pa at full opening.
    pub land_coefficient: f64,
    /// Rated flow of one valve at the base's rated pressure drop, m³/s.
    pub rated_flow_m3_s: f64,
    /// Cross-port leakage, m³/s/Pa.
    pub leakage_m3_s_per_pa: f64,
    /// Cap-side compliance `V_a0/β`, m³/Pa.
    pub cap_compliance_m3_per_pa: f64,
    /// Rod-side compliance `V_b0/β`, m³/Pa.
    pub rod_compliance_m3_per_pa: f64,
    /// Cap-side volume at `u = 0` with the base's `β`, m³.
    pub cap_volume_m3: f64,
    /// Rod-side volume at `u = 0` with the base's `β`, m³.
    pub rod_volume_m3: f64,
    /// The base's bulk modulus, Pa (not identified: see the module docs).
    pub oil_bulk_modulus_pa: f64,
    /// Spool natural frequency, Hz (the grid's best).
    pub spool_natural_frequency_hz: f64,
    /// Spool damping ratio (the grid's best).
    pub spool_damping_ratio: f64,
    /// Valve delay, s (the grid's best).
    pub valve_delay_s: f64,
    /// `τ + 2ζ/ω_n`: the spool's low-frequency equivalent lag, s.
    pub equivalent_lag_s: f64,
    /// Whether the grid's residual is flat along the equivalent lag (the spool's own
    /// frequency and damping beyond the records' band).
    pub lag_only: bool,
    /// RMS residual of the (filtered) continuity equations relative to their flows' RMS.
    pub flow_nrmse: f64,
    /// Oil-column frequency with the identified platen's mass, Hz.
    pub oil_column_frequency_hz: f64,
    /// Oil-column frequency with the specimen as a rigid payload (what `platen simulate`
    /// reports), Hz.
    pub oil_column_frequency_with_specimen_hz: f64,
    /// The pressure channels the continuity used: `"chamber pressures"` or `"delta_p"`.
    pub from: &'static str,
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

/// How the actuator force comes from a record's pressures.
#[derive(Debug, Clone, Copy, PartialEq)]
enum ForceFrom {
    /// `n(A_a·p_a − A_b·p_b)` with the base's areas.
    Chambers,
    /// `n·A·(p_a − r·p_b)` with `r` fitted (both pressures, no base).
    ChambersRatioFree,
    /// `n·A·Δp` (a double-ended actuator).
    DeltaP,
}

/// How the fitted records give the force, or why they cannot.
fn force_from(
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

/// The zero-phase low-pass of the force balance at `h`.
fn mechanics_filter(r: &SystemRecord, h: f64) -> Result<ButterworthLowpass> {
    ButterworthLowpass::new(4, MECHANICS_LOWPASS_FRACTION / h, 1.0 / h).map_err(|source| {
        IdentError::Signal {
            test: r.name.clone(),
            source,
        }
    })
}

fn filtered(f: &ButterworthLowpass, r: &SystemRecord, x: &[f64]) -> Result<Vec<f64>> {
    f.apply(x).map_err(|source| IdentError::Signal {
        test: r.name.clone(),
        source,
    })
}

fn central_velocity(u: &[f64], h: f64) -> Vec<f64> {
    let n = u.len();
    let mut v = vec![0.0; n];
    for i in 1..n - 1 {
        v[i] = (u[i + 1] - u[i - 1]) / (2.0 * h);
    }
    v
}

/// The force balance's design over the fitted records, the pressures shifted earlier by
/// `shift_s`. Columns: `[M, C, K, F_μ, m₁ … m_s, (r), f₁ … f_R]`, the last one constant
/// force per fitted record: a pressure transducer's offset (a table at rest holds its
/// friction, so `Δp` cannot be zeroed at rest; ±1 bar on a small actuator is of the order of
/// its friction) and the accelerometers' (times the masses) differ from record to record.
#[allow(clippy::too_many_arguments)]
fn mechanics_design(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    input: &PlantInput,
    from: ForceFrom,
    storeys: usize,
    shift_s: f64,
    law: &Law,
) -> Result<Design> {
    let act = &input.base.actuator;
    let n_act = f64::from(act.count);
    let ratio = from == ForceFrom::ChambersRatioFree;
    let m = mechanics_columns(from, storeys, fitted.len(), law);
    let offsets = 4 + storeys + usize::from(ratio);
    let mut design = Design::new(m);
    for (slot, &k) in fitted.iter().enumerate() {
        let r = &records[k];
        let h = periods[k];
        let lp = mechanics_filter(r, h)?;
        let s = shift_s / h;
        let sh = |x: &Option<Vec<f64>>| -> Result<Vec<f64>> {
            skew::shift(r, x.as_deref().unwrap_or(&[]), s)
        };
        let (force, extra): (Vec<f64>, Option<Vec<f64>>) = match from {
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
                let f = |p: &[f64]| -> Vec<f64> {
                    p.iter().map(|p| n_act * act.cap_area_m2 * p).collect()
                };
                (f(&pa), Some(f(&pb)))
            }
        };
        let Some(a) = &r.a_m_s2 else { continue };
        let v = central_velocity(&r.u_m, h);
        let sgn: Vec<f64> = v.iter().map(|v| v.signum()).collect();
        let y = filtered(&lp, r, &force)?;
        // C·|v|^α·sgn(v): exactly v for α = 1 (the linear law's column, bit for bit).
        let viscous: Vec<f64> = if law.exponent == 1.0 {
            v.clone()
        } else {
            v.iter()
                .map(|v| v.signum() * v.abs().powf(law.exponent))
                .collect()
        };
        let mut cols = vec![
            filtered(&lp, r, a)?,
            filtered(&lp, r, &viscous)?,
            filtered(&lp, r, &r.u_m)?,
            filtered(&lp, r, &sgn)?,
        ];
        for st in r.storey_a_m_s2.iter().take(storeys) {
            cols.push(filtered(&lp, r, st)?);
        }
        if let Some(e) = &extra {
            // n·A·(p_a − r·p_b) = M·a + …: the rod side's term moves to the regressors,
            // n·A·p_a = M·a + … + r·(n·A·p_b).
            cols.push(filtered(&lp, r, e)?);
        }
        // The law's extra columns, after the records' constants.
        let mut tail = Vec::new();
        if let Some(b) = law.decay_s_per_m {
            let stribeck: Vec<f64> = v
                .iter()
                .map(|v| v.signum() * (-b * v.abs()).exp())
                .collect();
            tail.push(filtered(&lp, r, &stribeck)?);
        }
        if law.exponent_score {
            // ∂(|v|^α sgn v)/∂α at α = 1: its coefficient is C·(α − 1) to first order.
            let score: Vec<f64> = v
                .iter()
                .map(|&v| if v == 0.0 { 0.0 } else { v * v.abs().ln() })
                .collect();
            tail.push(filtered(&lp, r, &score)?);
        }
        // This record's constant, through the same filter (its start is cut with the edge).
        let constant = filtered(&lp, r, &vec![1.0; r.u_m.len()])?;
        let n = r.u_m.len();
        let edge = ((0.5 / h) as usize).min(n / 4);
        let mut row = vec![0.0; m];
        let first_tail = offsets + fitted.len();
        let guard = stick_guard_samples();
        // Samples within `guard` of one below the slip speed are left out too: the low-pass
        // spreads the friction there (a stick reaction, not ±F_μ) over them.
        let mut near_rest = vec![false; n];
        for i in 0..n {
            if v[i].abs() < law.slip_speed_m_s {
                for flag in &mut near_rest[i.saturating_sub(guard)..(i + guard + 1).min(n)] {
                    *flag = true;
                }
            }
        }
        for i in edge..n - edge {
            if near_rest[i] {
                continue;
            }
            for (c, col) in row.iter_mut().zip(&cols) {
                *c = col[i];
            }
            row[offsets + slot] = constant[i];
            for (j, col) in tail.iter().enumerate() {
                row[first_tail + j] = col[i];
            }
            design.push(&row, y[i], k, i);
        }
    }
    Ok(design)
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
fn mechanics_columns(from: ForceFrom, storeys: usize, records: usize, law: &Law) -> usize {
    4 + storeys
        + usize::from(from == ForceFrom::ChambersRatioFree)
        + records
        + usize::from(law.decay_s_per_m.is_some())
        + usize::from(law.exponent_score)
}

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

/// Samples slower than this are left out of the fits of a richer friction law, m/s: the
/// Stribeck term lives at a few mm/s, and above [`SLIP_SPEED_M_S`] there is little of it
/// left to see (e^(−2) at b = 200 s/m). Four times the velocity noise of a 5 µm displacement
/// sensor differenced at 204.8 Hz (0.72 mm/s), so a stuck platen's samples stay out.
pub const LOW_SLIP_SPEED_M_S: f64 = 0.003;
/// The Stribeck decays `b` tried, s/m (a decay speed 1/b of 40 to 1.25 mm/s).
pub const DECAY_GRID_S_PER_M: [f64; 6] = [25.0, 50.0, 100.0, 200.0, 400.0, 800.0];
/// The viscous exponents `α` tried.
pub const EXPONENT_GRID: [f64; 10] = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2];
/// A richer friction term is kept only when its coefficient is this many (batch-means)
/// standard errors from 0: the records support it well beyond chance (two-sided p < 0.3 %).
pub const FRICTION_TERM_T: f64 = 3.0;

/// The constraints of the force balance: `C, K, F_μ ≥ 0`.
fn mechanics_signs(m: usize) -> Vec<bool> {
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

/// The friction law the corrected records support ([`Law`]): the best of the grids of
/// [`DECAY_GRID_S_PER_M`] (or none) and [`EXPONENT_GRID`] above [`LOW_SLIP_SPEED_M_S`]; the
/// Stribeck term kept when its amplitude is positive and [`FRICTION_TERM_T`] standard errors
/// from 0, an exponent other than 1 when the score of `α = 1` (the coefficient of `v·ln|v|`)
/// is. Without either, Coulomb and linear viscous friction above [`SLIP_SPEED_M_S`], as
/// before any richer law was tried. Returns the fit and its law.
fn friction_law(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    input: &PlantInput,
    from: ForceFrom,
    storeys: usize,
) -> Result<Option<(LinearFit, Law)>> {
    let fit = |law: &Law| -> Result<Option<LinearFit>> {
        let m = mechanics_columns(from, storeys, fitted.len(), law);
        let design = mechanics_design(records, periods, fitted, input, from, storeys, 0.0, law)?;
        Ok(design.fit(&mechanics_signs(m), &vec![false; m]))
    };
    let low = |exponent: f64, decay_s_per_m: Option<f64>| Law {
        exponent,
        decay_s_per_m,
        slip_speed_m_s: LOW_SLIP_SPEED_M_S,
        exponent_score: false,
    };
    // Every law of a grid, fitted once, in the grid's order (decays outer, exponents inner).
    let grid = |decays: &[Option<f64>], exponents: &[f64]| -> Result<Vec<(LinearFit, Law)>> {
        let mut out = Vec::with_capacity(decays.len() * exponents.len());
        for &b in decays {
            for &alpha in exponents {
                let law = low(alpha, b);
                if let Some(f) = fit(&law)? {
                    out.push((f, law));
                }
            }
        }
        Ok(out)
    };
    // The fit of least residual among `fits` (the first of equals).
    let best = |fits: Vec<(LinearFit, Law)>| -> Option<(LinearFit, Law)> {
        fits.into_iter()
            .reduce(|a, b| if b.0.rss < a.0.rss { b } else { a })
    };
    let t = |f: &LinearFit, j: usize| f.coef[j] / f.estimates[j].std_error;
    let last = |f: &LinearFit| f.coef.len() - 1;
    let decays: Vec<Option<f64>> = DECAY_GRID_S_PER_M.iter().map(|&b| Some(b)).collect();
    let with_stribeck = grid(&decays, &EXPONENT_GRID)?;
    // The Stribeck term: its amplitude at the best decay and exponent.
    let stribeck = match best(with_stribeck.clone()) {
        Some((f, law)) if f.coef[last(&f)] > 0.0 && t(&f, last(&f)) > FRICTION_TERM_T => {
            law.decay_s_per_m
        }
        _ => None,
    };
    // The exponent: the score of α = 1 with the Stribeck term as found.
    let score_law = Law {
        exponent_score: true,
        ..low(1.0, stribeck)
    };
    let exponent_free = fit(&score_law)?.is_some_and(|f| t(&f, last(&f)).abs() > FRICTION_TERM_T);
    if stribeck.is_none() && !exponent_free {
        return Ok(fit(&Law::LINEAR)?.map(|f| (f, Law::LINEAR)));
    }
    if stribeck.is_none() {
        return Ok(best(grid(&[None], &EXPONENT_GRID)?));
    }
    // With the Stribeck term: the grid's own fits at its decay (every exponent, or α = 1).
    Ok(best(
        with_stribeck
            .into_iter()
            .filter(|(_, law)| {
                law.decay_s_per_m == stribeck && (exponent_free || law.exponent == 1.0)
            })
            .collect(),
    ))
}

/// The second-order filter `1/(s² + 2ζω s + ω²)` of `x` by the trapezoidal rule, started at
/// rest: returns `(q, q̇, q̈)` (so `s^k/(s² + 2ζω s + ω²)` of `x` for `k = 0, 1, 2`).
fn second_order(x: &[f64], h: f64, w: f64, zeta: f64) -> [Vec<f64>; 3] {
    // State y = (q, q̇): ẏ = A y + B x, A = [[0, 1], [−ω², −2ζω]], B = (0, 1).
    // Trapezoid: (I − hA/2) y₊ = (I + hA/2) y + h/2·B (x + x₊).
    let (a10, a11) = (-w * w, -2.0 * zeta * w);
    let m = [[1.0, -0.5 * h], [-0.5 * h * a10, 1.0 - 0.5 * h * a11]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ];
    let n = x.len();
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut y0, mut y1) = (0.0, 0.0);
    qdd[0] = x[0];
    for i in 1..n {
        let r0 = y0 + 0.5 * h * y1;
        let r1 = y1 + 0.5 * h * (a10 * y0 + a11 * y1) + 0.5 * h * (x[i - 1] + x[i]);
        y0 = inv[0][0] * r0 + inv[0][1] * r1;
        y1 = inv[1][0] * r0 + inv[1][1] * r1;
        q[i] = y0;
        qd[i] = y1;
        qdd[i] = x[i] + a10 * y0 + a11 * y1;
    }
    [q, qd, qdd]
}

/// The storey fit's filters run at this many times the records' rate: the trapezoid rule's
/// frequency warping, `(ωh)²/6` relative on a double integral (0.66 % at 6.5 Hz on 204.8 Hz
/// records, which showed as a stiffness 0.7 % high), falls with the square of the step.
const UPSAMPLE: usize = 4;

/// `x` at `UPSAMPLE` times its rate: band-limited interpolation
/// ([`platen_signal::advance`] by each fraction of a sample, interleaved).
fn upsampled(x: &[f64]) -> Option<Vec<f64>> {
    let shifted: Vec<Vec<f64>> = (1..UPSAMPLE)
        .map(|k| platen_signal::advance(x, k as f64 / UPSAMPLE as f64).ok())
        .collect::<Option<_>>()?;
    let mut out = Vec::with_capacity(UPSAMPLE * x.len());
    for i in 0..x.len() {
        out.push(x[i]);
        for s in &shifted {
            out.push(s[i]);
        }
    }
    Some(out)
}

/// The storeys' stiffness and damping (masses given), bottom first, with the standard errors
/// of stiffness and damping.
fn fit_storeys(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    masses: &[f64],
) -> Option<Vec<(IdentifiedStorey, [f64; 2])>> {
    let w0 = std::f64::consts::TAU * DRIFT_HIGHPASS_HZ;
    let ns = masses.len();
    let mut out = Vec::with_capacity(ns);
    for j in 0..ns {
        let mut design = Design::new(2);
        for &k in fitted {
            let (r, h) = (&records[k], periods[k]);
            let below = if j == 0 {
                r.a_m_s2.as_ref()?
            } else {
                &r.storey_a_m_s2[j - 1]
            };
            let rel: Vec<f64> = r.storey_a_m_s2[j]
                .iter()
                .zip(below)
                .map(|(a, b)| a - b)
                .collect();
            let shear: Vec<f64> = (0..r.u_m.len())
                .map(|i| (j..ns).map(|s| masses[s] * r.storey_a_m_s2[s][i]).sum())
                .collect();
            // Both sides through the force balance's low-pass: what the command does not
            // drive is left out, as there.
            let lp = mechanics_filter(r, h).ok()?;
            let (rel, shear) = (lp.apply(&rel).ok()?, lp.apply(&shear).ok()?);
            // Both sides through s²/(s+ω₀)² first: the drift regressor below is the relative
            // acceleration through 1/(s+ω₀)², whose DC gain 1/ω₀² would carry the
            // accelerometers' offsets (a few tenths of a mg after zeroing) into the drift as
            // a constant, which the stiffness cannot fit and is biased by (on the stand-ins of
            // real records, the first mode came out 11 % low). Then 1/(s+ω₀)²: ζ = 1, both
            // run at UPSAMPLE times the rate on the band-limited interpolation of both sides,
            // then taken at the samples.
            let (rel, shear) = (upsampled(&rel)?, upsampled(&shear)?);
            let hu = h / UPSAMPLE as f64;
            let [_, _, rel] = second_order(&rel, hu, w0, 1.0);
            let [_, _, shear] = second_order(&shear, hu, w0, 1.0);
            let [d0, d1, _] = second_order(&rel, hu, w0, 1.0);
            let [_, _, s2] = second_order(&shear, hu, w0, 1.0);
            // The filters' start (a step through the fourth-order chain, e.g. an offset,
            // decays as (ω₀t)³e^(−ω₀t): below 1e-2 of its peak after 1.5 corner periods).
            let skip = (1.5 / (DRIFT_HIGHPASS_HZ * h)) as usize;
            let n = r.u_m.len();
            // The last samples' interpolation reaches past the record: left out.
            for i in skip.min(n / 4)..n - UPSAMPLE {
                let j = UPSAMPLE * i;
                design.push(&[-d0[j], -d1[j]], s2[j], k, i);
            }
        }
        let f = design.fit(&[true, true], &[false, false])?;
        out.push((
            IdentifiedStorey {
                mass_kg: masses[j],
                stiffness_n_per_m: f.coef[0],
                damping_n_s_per_m: f.coef[1],
                shear_nrmse: f.nrmse(),
            },
            [f.estimates[0].std_error, f.estimates[1].std_error],
        ));
    }
    Some(out)
}

/// The fixed-base modes of `storeys` (classical modal damping).
pub(super) fn modes(storeys: &[IdentifiedStorey]) -> Vec<Mode> {
    let n = storeys.len();
    let tri = |f: &dyn Fn(&IdentifiedStorey) -> f64| {
        DMatrix::from_fn(n, n, |i, j| {
            let own = f(&storeys[i]) + storeys.get(i + 1).map_or(0.0, f);
            if i == j {
                own
            } else if i + 1 == j {
                -f(&storeys[j])
            } else if j + 1 == i {
                -f(&storeys[i])
            } else {
                0.0
            }
        })
    };
    let k = tri(&|s| s.stiffness_n_per_m);
    let c = tri(&|s| s.damping_n_s_per_m);
    let isq: Vec<f64> = storeys.iter().map(|s| 1.0 / s.mass_kg.sqrt()).collect();
    let ks = DMatrix::from_fn(n, n, |i, j| k[(i, j)] * isq[i] * isq[j]);
    let cs = DMatrix::from_fn(n, n, |i, j| c[(i, j)] * isq[i] * isq[j]);
    let eig = SymmetricEigen::new(ks);
    let mut out: Vec<Mode> = (0..n)
        .filter(|&m| eig.eigenvalues[m] > 0.0)
        .map(|m| {
            let w = eig.eigenvalues[m].sqrt();
            let phi = eig.eigenvectors.column(m);
            let cm = (phi.transpose() * &cs * phi)[(0, 0)];
            Mode {
                frequency_hz: w / std::f64::consts::TAU,
                damping_ratio: cm / (2.0 * w),
            }
        })
        .collect();
    out.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    out
}

/// The spool opening at the samples: the held drive, delayed by `delay_sub` sixteenths of
/// the period, through `ω²/(s² + 2ζωs + ω²)` (RK4, 16 steps per period), clamped to ±1.
fn spool(drive: &[f64], h: f64, f_hz: f64, zeta: f64, delay_sub: u32) -> Vec<f64> {
    let w = std::f64::consts::TAU * f_hz;
    let dt = h / 16.0;
    let f = |x: f64, xd: f64, d: f64| (xd, w * w * (d - x) - 2.0 * zeta * w * xd);
    let (mut x, mut xd) = (0.0_f64, 0.0_f64);
    let mut out = vec![0.0; drive.len()];
    let mut prev = 0.0;
    for i in 0..drive.len() {
        out[i] = x.clamp(-1.0, 1.0);
        for j in 0..16 {
            let d = if j < delay_sub { prev } else { drive[i] };
            let k1 = f(x, xd, d);
            let k2 = f(x + 0.5 * dt * k1.0, xd + 0.5 * dt * k1.1, d);
            let k3 = f(x + 0.5 * dt * k2.0, xd + 0.5 * dt * k2.1, d);
            let k4 = f(x + dt * k3.0, xd + dt * k3.1, d);
            x += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            xd += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        }
        prev = drive[i];
    }
    out
}

/// Signed `√|dp|`, linear below `laminar` Pa (as platen's valve).
fn root(dp: f64, laminar: f64) -> f64 {
    if dp.abs() >= laminar {
        dp.signum() * dp.abs().sqrt()
    } else {
        dp / laminar.sqrt()
    }
}

/// The spool-independent filtered terms of one record's continuity.
struct Continuity {
    /// `LP(Δp)`.
    lp_dp: Vec<f64>,
    /// Chambers: `LP(ṗ_a)`, `LP(ṗ_b)`; `Δp` alone: `LP(Δṗ)/2` (twice).
    lp_dpa: Vec<f64>,
    lp_dpb: Vec<f64>,
    /// Chambers: `A_a·(LP(v) + LP(u·ṗ_a)/β)` and the rod side's; `Δp` alone: `A·LP(v)`.
    rhs_a: Vec<f64>,
    rhs_b: Vec<f64>,
    /// Whether the record's chambers are used (else its `Δp`).
    chambers: bool,
}

/// The continuity's low-pass corner at period `h`, Hz.
fn continuity_corner_hz(h: f64) -> f64 {
    CONTINUITY_LOWPASS_HZ.min(0.2 / h)
}

fn lowpass(x: &[f64], h: f64) -> [Vec<f64>; 3] {
    let w = std::f64::consts::TAU * continuity_corner_hz(h);
    let [q, qd, qdd] = second_order(x, h, w, std::f64::consts::FRAC_1_SQRT_2);
    let s = |v: Vec<f64>| v.into_iter().map(|z| z * w * w).collect::<Vec<f64>>();
    [s(q), s(qd), s(qdd)]
}

fn continuity(
    r: &SystemRecord,
    h: f64,
    base: &TableSystemParts,
    chambers: bool,
) -> Option<Continuity> {
    let a = &base.actuator;
    let [_, lp_v, _] = lowpass(&r.u_m, h);
    if !chambers {
        let dp = r.delta_p_pa.as_ref()?;
        let [lp_dp, lp_ddp, _] = lowpass(dp, h);
        let half: Vec<f64> = lp_ddp.iter().map(|x| 0.5 * x).collect();
        let rhs: Vec<f64> = lp_v.iter().map(|v| a.cap_area_m2 * v).collect();
        return Some(Continuity {
            lp_dp,
            lp_dpa: half.clone(),
            lp_dpb: half,
            rhs_a: rhs.clone(),
            rhs_b: rhs,
            chambers,
        });
    }
    let (pa, pb) = (r.cap_pressure_pa.as_ref()?, r.rod_pressure_pa.as_ref()?);
    let beta = base.oil_bulk_modulus_pa;
    let dp: Vec<f64> = pa.iter().zip(pb).map(|(a, b)| a - b).collect();
    let [lp_dp, _, _] = lowpass(&dp, h);
    let [_, lp_dpa, _] = lowpass(pa, h);
    let [_, lp_dpb, _] = lowpass(pb, h);
    // The small u·ṗ/β terms, with ṗ from the filtered pressure (unfiltered is noise).
    let upa: Vec<f64> = r.u_m.iter().zip(&lp_dpa).map(|(u, p)| u * p).collect();
    let upb: Vec<f64> = r.u_m.iter().zip(&lp_dpb).map(|(u, p)| u * p).collect();
    let [lp_upa, _, _] = lowpass(&upa, h);
    let [lp_upb, _, _] = lowpass(&upb, h);
    let rhs_a = (0..pa.len())
        .map(|i| a.cap_area_m2 * (lp_v[i] + lp_upa[i] / beta))
        .collect();
    let rhs_b = (0..pa.len())
        .map(|i| a.rod_area_m2 * (lp_v[i] + lp_upb[i] / beta))
        .collect();
    Some(Continuity {
        lp_dp,
        lp_dpa,
        lp_dpb,
        rhs_a,
        rhs_b,
        chambers,
    })
}

/// The continuity fit for one spool: coefficients `[K, C_L, V_a0/β, V_b0/β]` (`Δp` alone:
/// `[K, C_L, V₀/β]`), every one `≥ 0`.
fn fit_continuity(
    recs: &[(usize, &SystemRecord, f64, Continuity)],
    base: &TableSystemParts,
    spool_of: &dyn Fn(&[f64], f64) -> Vec<f64>,
) -> Option<LinearFit> {
    let laminar = platen_system::LAMINAR_FRACTION * base.servo_valve.rated_pressure_drop_pa;
    let (ps, pr) = (base.supply_pressure_pa, base.return_pressure_pa);
    let chambers = recs.first()?.3.chambers;
    let m = if chambers { 4 } else { 3 };
    let mut design = Design::new(m);
    for (k, r, h, c) in recs {
        let xv = spool_of(r.drive.as_ref()?, *h);
        let (mut qa, mut qb) = (vec![0.0; xv.len()], vec![0.0; xv.len()]);
        if chambers {
            let (pa, pb) = (r.cap_pressure_pa.as_ref()?, r.rod_pressure_pa.as_ref()?);
            for i in 0..xv.len() {
                let (pa, pb) = (pa[i].max(0.0), pb[i].max(0.0));
                (qa[i], qb[i]) = if xv[i] >= 0.0 {
                    (
                        xv[i] * root(ps - pa, laminar),
                        xv[i] * root(pb - pr, laminar),
                    )
                } else {
                    (
                        xv[i] * root(pa - pr, laminar),
                        xv[i] * root(ps - pb, laminar),
                    )
                };
            }
        } else {
            let dp = r.delta_p_pa.as_ref()?;
            for i in 0..xv.len() {
                let drop = 0.5 * (ps - pr - xv[i].signum() * dp[i]);
                qa[i] = xv[i] * root(drop, laminar);
            }
        }
        let [lqa, _, _] = lowpass(&qa, *h);
        let [lqb, _, _] = if chambers {
            lowpass(&qb, *h)
        } else {
            [Vec::new(), Vec::new(), Vec::new()]
        };
        let skip = (0.05 / *h) as usize;
        for i in skip..xv.len() {
            if chambers {
                design.push(&[lqa[i], -c.lp_dp[i], -c.lp_dpa[i], 0.0], c.rhs_a[i], *k, i);
                design.push(&[lqb[i], -c.lp_dp[i], 0.0, c.lp_dpb[i]], c.rhs_b[i], *k, i);
            } else {
                design.push(&[lqa[i], -c.lp_dp[i], -c.lp_dpa[i]], c.rhs_a[i], *k, i);
            }
        }
    }
    design.fit(&vec![true; m], &vec![false; m])
}

/// Fits the plant on the `fitted` records in `input`'s geometry; corrects the pressures'
/// skew in `records` (reported in `skew_report`); `not_identified` gets what cannot be seen.
///
/// # Errors
/// [`IdentError::Signal`] when a filter cannot be made for a record's rate.
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

/// The platen's mechanics and the specimen's storeys of [`identify_plant`] (force `from`,
/// `storeys` recorded): into `plant`, with a free rod-to-cap area ratio into `base`.
#[allow(clippy::too_many_arguments)]
fn plant_mechanics(
    records: &mut [SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    input: &PlantInput,
    (from, storeys): (ForceFrom, usize),
    skew_report: &mut Vec<ChannelSkew>,
    (base, plant): (&mut TableSystemParts, &mut IdentifiedPlant),
    not_identified: &mut Vec<(String, String)>,
) -> Result<()> {
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    if let Some((f, law)) =
        fit_mechanics(records, periods, fitted, input, from, storeys, skew_report)?
    {
        let c = &f.coef;
        let se = |j: usize| f.estimates[j].std_error;
        let ratio = (from == ForceFrom::ChambersRatioFree).then(|| c[4 + storeys]);
        if let Some(r) = ratio {
            base.actuator.rod_area_m2 = r * base.actuator.cap_area_m2;
            plant.std_errors.insert(
                "table_system.actuator.rod_side_area_m2".into(),
                se(4 + storeys) * base.actuator.cap_area_m2,
            );
        }
        // The Stribeck amplitude is the last column when the law has it.
        let stribeck = law
            .decay_s_per_m
            .map(|b| (c[c.len() - 1], b, se(c.len() - 1)));
        if let Some((_, _, e)) = stribeck {
            if e.is_finite() {
                plant
                    .std_errors
                    .insert("model.identified.low_velocity_force_n".into(), e);
            }
        }
        let mech = IdentifiedMechanics {
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
        };
        for (j, key) in [
            (0, "effective_mass_kg"),
            (1, "viscous_coefficient"),
            (2, "stiffness_n_per_m"),
            (3, "coulomb_force_n"),
        ] {
            if se(j).is_finite() {
                plant
                    .std_errors
                    .insert(format!("model.identified.{key}"), se(j));
            }
        }
        for (name, j) in [
            ("viscous_coefficient", 1),
            ("stiffness_n_per_m", 2),
            ("coulomb_force_n", 3),
        ] {
            if f.clamped[j] {
                not_identified.push(why(
                    name,
                    "held at 0: the unconstrained force balance makes it negative, \
                     which no platen has",
                ));
            }
        }
        let masses: Vec<f64> = c[4..4 + storeys].to_vec();
        for (j, _) in masses.iter().enumerate() {
            plant
                .std_errors
                .insert(format!("specimen.storeys[{j}].mass_kg"), se(4 + j));
        }
        plant.mechanics = Some(mech);
        if storeys == 0 {
            not_identified.push(why(
                "specimen",
                "no storey{i}_a_m_s2 recorded: a specimen's base shear, if any, is \
                 in the platen's mass, stiffness and damping",
            ));
        } else if let Some(st) = fit_storeys(records, periods, fitted, &masses) {
            for (j, (_, e)) in st.iter().enumerate() {
                plant
                    .std_errors
                    .insert(format!("specimen.storeys[{j}].stiffness_n_per_m"), e[0]);
                plant
                    .std_errors
                    .insert(format!("specimen.storeys[{j}].damping_n_s_per_m"), e[1]);
            }
            plant.storeys = st.into_iter().map(|(s, _)| s).collect();
            plant.specimen_modes = modes(&plant.storeys);
        }
    }
    Ok(())
}

/// The servo-valves and the oil column of [`identify_plant`] (the continuity fit), and the
/// table system they make when a scenario takes it.
fn plant_hydraulics(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    from: &std::result::Result<ForceFrom, &str>,
    base: &TableSystemParts,
    plant: &mut IdentifiedPlant,
    not_identified: &mut Vec<(String, String)>,
) {
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    let drive = fitted.iter().all(|&i| records[i].drive.is_some());
    let chambers = matches!(from, Ok(ForceFrom::Chambers | ForceFrom::ChambersRatioFree));
    let cont: Option<Vec<(usize, &SystemRecord, f64, Continuity)>> = match from {
        Ok(_) => fitted
            .iter()
            .map(|&i| {
                Some((
                    i,
                    &records[i],
                    periods[i],
                    continuity(&records[i], periods[i], base, chambers)?,
                ))
            })
            .collect(),
        Err(_) => None,
    };
    match (cont, drive) {
        (Some(recs), true) => {
            if let Some(hyd) = fit_valves(&recs, base, plant, not_identified) {
                let mut sys = *base;
                sys.actuator.cap_volume_m3 = hyd.cap_volume_m3;
                sys.actuator.rod_volume_m3 = hyd.rod_volume_m3;
                sys.actuator.leakage_m3_s_per_pa = hyd.leakage_m3_s_per_pa;
                sys.servo_valve.rated_flow_m3_s = hyd.rated_flow_m3_s;
                sys.servo_valve.natural_frequency_hz = hyd.spool_natural_frequency_hz;
                sys.servo_valve.damping_ratio = hyd.spool_damping_ratio;
                sys.servo_valve.delay_s = hyd.valve_delay_s;
                let mut hyd = hyd;
                if let Some(m) = &plant.mechanics {
                    let payload: f64 = plant.storeys.iter().map(|s| s.mass_kg).sum();
                    hyd.oil_column_frequency_hz =
                        sys.oil_column_frequency_hz(m.effective_mass_kg, 0.0);
                    hyd.oil_column_frequency_with_specimen_hz =
                        sys.oil_column_frequency_hz(m.effective_mass_kg + payload, 0.0);
                }
                // Only a system a scenario takes is printed and run.
                match TableSystem::new(sys, actuator_stroke_limit_m(&sys.actuator)) {
                    Ok(sys) => plant.system = Some(sys),
                    Err(e) => not_identified.push(why(
                        "the table system as a whole",
                        &format!(
                            "the identified values are not a table system a scenario takes \
                             ({e}); the records do not determine the valves and chambers"
                        ),
                    )),
                }
                plant.hydraulics = Some(hyd);
            }
        }
        (None, _) => {
            if from.is_ok() {
                not_identified.push(why(
                    "servo-valve flow gain and dynamics, oil column, leakage",
                    "the continuity needs the pressures in every fitted record",
                ));
            }
        }
        (Some(_), false) => not_identified.push(why(
            "servo-valve flow gain and dynamics, oil column, leakage",
            "no drive recorded in every fitted record: the spool's input is unknown",
        )),
    }
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

/// The spool grid's best continuity fit, as the valves and oil column.
fn fit_valves(
    recs: &[(usize, &SystemRecord, f64, Continuity)],
    base: &TableSystemParts,
    plant: &mut IdentifiedPlant,
    not_identified: &mut Vec<(String, String)>,
) -> Option<IdentifiedHydraulics> {
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    let mut grid: Vec<(f64, f64, u32, LinearFit)> = Vec::new();
    for &f in &SPOOL_FREQUENCY_GRID_HZ {
        for &z in &SPOOL_DAMPING_GRID {
            for &d in &DELAY_GRID_SIXTEENTHS {
                let of = |dr: &[f64], h: f64| spool(dr, h, f, z, d);
                if let Some(fit) = fit_continuity(recs, base, &of) {
                    grid.push((f, z, d, fit));
                }
            }
        }
    }
    grid.sort_by(|a, b| a.3.rss.total_cmp(&b.3.rss));
    let (f, z, d, fit) = grid.first()?.clone();
    let chambers = recs[0].3.chambers;
    let h = recs[0].2;
    let lag =
        |f: f64, z: f64, d: u32| f64::from(d) * h / 16.0 + 2.0 * z / (std::f64::consts::TAU * f);
    let best_lag = lag(f, z, d);
    // Flat ridge: another grid point of about the same lag, a spool at least 1.5× faster or
    // slower, fits within 5 % of the best residual.
    let lag_only = grid.iter().any(|g| {
        (lag(g.0, g.1, g.2) / best_lag - 1.0).abs() < 0.1
            && (g.0 / f >= 1.5 || f / g.0 >= 1.5)
            && g.3.rss < 1.05 * fit.rss
    });
    let beta = base.oil_bulk_modulus_pa;
    let c = &fit.coef;
    let se = |j: usize| fit.estimates[j].std_error;
    let k = c[0];
    let valves = f64::from(base.servo_valve.count);
    let to_rated = (0.5 * base.servo_valve.rated_pressure_drop_pa).sqrt() / valves;
    let (ca, cb, se_a, se_b) = if chambers {
        (c[2], c[3], se(2), se(3))
    } else {
        (c[2], c[2], se(2), se(2))
    };
    for (key, value) in [
        ("table_system.servo_valve.rated_flow_m3_s", se(0) * to_rated),
        ("table_system.actuator.leakage_m3_s_per_pa", se(1)),
        ("table_system.actuator.chamber_volume_m3[0]", se_a * beta),
        ("table_system.actuator.chamber_volume_m3[1]", se_b * beta),
    ] {
        if value.is_finite() {
            plant.std_errors.insert(key.into(), value);
        }
    }
    if lag_only {
        not_identified.push(why(
            "servo_valve.natural_frequency_hz, damping_ratio, delay_s separately",
            "the spool is faster than the records' band: only its equivalent lag τ + 2ζ/ω_n \
             is visible (the printed values are the grid's best, one of many that fit as well)",
        ));
    }
    not_identified.push(why(
        "oil_bulk_modulus_pa separately from the chamber volumes",
        "only V/β is visible at these strokes: β is the base's (or the nominal), the volumes \
         follow from it",
    ));
    if !chambers {
        not_identified.push(why(
            "the two chamber volumes apart",
            "Δp alone shows the load flow of a double-ended actuator, whose chambers are then \
             taken alike (V_a0 = V_b0)",
        ));
    }
    Some(IdentifiedHydraulics {
        land_coefficient: k,
        rated_flow_m3_s: k * to_rated,
        leakage_m3_s_per_pa: c[1].max(0.0),
        cap_compliance_m3_per_pa: ca,
        rod_compliance_m3_per_pa: cb,
        cap_volume_m3: ca * beta,
        rod_volume_m3: cb * beta,
        oil_bulk_modulus_pa: beta,
        spool_natural_frequency_hz: f,
        spool_damping_ratio: z,
        valve_delay_s: f64::from(d) * h / 16.0,
        equivalent_lag_s: best_lag,
        lag_only,
        flow_nrmse: fit.nrmse(),
        oil_column_frequency_hz: f64::NAN,
        oil_column_frequency_with_specimen_hz: f64::NAN,
        from: if chambers {
            "chamber pressures"
        } else {
            "delta_p"
        },
    })
}
