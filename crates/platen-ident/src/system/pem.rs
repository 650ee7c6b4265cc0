//! The loop fitted by its prediction error: the equation-error values of the plant refined
//! so that the identified closed loop, run on each fitted record's command, reproduces the
//! recorded table and storey accelerations.
//!
//! # The fit
//!
//! * **Model**: [`platen_integrate::forward_closed_loop`] from rest at the command's first
//!   sample, RK4 at the steps per period the judgement takes for the starting loop (held for
//!   the whole fit, so the cost is one smooth function of the parameters), exactly as
//!   [`super::Judgement`] runs it.
//! * **Residuals**: for every fitted record, the table's acceleration and each storey's,
//!   and the pressure difference `Δp` where every fitted record has it, recorded and
//!   predicted both through the judgement's zero-phase low-pass
//!   ([`super::JUDGE_LOWPASS_HZ`]), their difference divided by the channel's RMS over all
//!   fitted records (so the table and each storey weigh alike, whatever their amplitudes),
//!   less each record's channel's mean residual (its sensor's zero offset, a nuisance
//!   parameter solved in closed form: an accelerometer's, or `Δp`'s, which a table at rest
//!   holding its friction cannot zero). `Δp` is the force over the area: without it the
//!   accelerations leave the plant's force scale (masses, friction, flow, volume) in a
//!   flat valley; on the stand-ins of `tests/data/real_table` the fit without it put the
//!   platen's mass 29 % above the truth (with it 7 %) for a held-out NRMSE 1–2 points lower. The records start at rest, so no transient is
//!   discarded. The cost is the mean square of these residuals; each channel's NRMSE is the
//!   root of its own mean square.
//! * **Parameters** (each as its value relative to the start, `ln(p/p₀)`, so that a step
//!   is a relative change and a positive value stays positive): the platen's mass, Coulomb
//!   force, viscous coefficient, the Stribeck amplitude and the viscous exponent (those two
//!   only when the equation error gives them: a Stribeck amplitude `> 0`, an exponent other
//!   than 1; the exponent moves linearly in `[0, 1]`), each storey's mass, stiffness and
//!   damping, the valves' rated flow, the valve lag (delay and spool period scaled together:
//!   only their sum `τ + 2ζ/ω_n` is seen in the records' band) and the chambers' volume (both
//!   together). A viscous coefficient the equation error holds at 0 moves linearly from 0,
//!   `≥ 0`. A storey damping held at 0 stays there.
//! * **Not the controller's gains**: they stay the drive regression's (`identify_system`),
//!   linear in the recorded drive and within 0.3 % of the truth on the stand-ins of
//!   `tests/data/real_table`. The accelerations alone do not pin them: with the gains free
//!   the fit walked them along a valley with the plant's force scale (there `K_p` went from
//!   14.26 to 23.8 /m, `K_vf` from 0.440 to 0.791 s/m and `K_Δp` from 2.39e-9 to 6.33e-9 /Pa,
//!   truth 14.3, 0.44, 2.4e-9, for a held-out NRMSE within 0.5 points of the fit without
//!   them; forward differences, accelerations only); with the recorded drive compared as
//!   well, that search stopped in a local minimum of heavily damped storeys (held-out table
//!   NRMSE 55 %).
//! * **Jacobian**: central differences of step [`FD_STEP`] in those coordinates (1 % of
//!   each value), one-sided where a side's run fails. The residuals are smooth in the
//!   parameters except where a small change moves a stick or slip event across a sample
//!   instant (the platen's acceleration jumps there): a step of 1 % averages those jumps
//!   over many events rather than resolving one, and the central difference's truncation
//!   error (the step squared times the third derivative, 1e-4 relative) is far below the
//!   parameters' uncertainty. Forward differences (half the runs) were tried and stalled: on
//!   the round trip of `tests/prediction_error.rs` they stopped at twice the noise's NRMSE
//!   with the platen's mass 9 % off and no descent direction left; central ones converge
//!   there in 10 iterations to the noise (every value within 2 % but the viscous
//!   coefficient's).
//! * **Which parameters**: at the start, a parameter whose Jacobian column is below
//!   [`MIN_COLUMN_NORM`] of the largest (the records do not see it), or whose column the
//!   others reproduce to a multiple correlation above [`MAX_CORRELATION`] (one of a pair the
//!   records cannot tell apart; the larger variance inflation goes first), is held at its
//!   start and listed in [`super::SystemIdentification::not_identified`].
//! * **Levenberg–Marquardt**: Marquardt's damping `λ·diag(JᵀJ)`, `λ` divided by 10 after a
//!   step that lowers the cost, multiplied by 10 after one that does not. A run that fails
//!   (the integrator, or values no table system takes) is a rejected step. The fit converges
//!   when the full Gauss–Newton step `−(JᵀJ)⁻¹Jᵀr` would lower the sum of squares by less
//!   than [`CHI2_TOLERANCE`] times the residuals' effective variance `σ²·τ` (the score
//!   statistic `rᵀJ(JᵀJ)⁻¹Jᵀr/σ²τ`: no step can improve the fit by a meaningful fraction
//!   of one standard error); it stops unconverged after [`MAX_ITERATIONS`] iterations, or
//!   when no damping gives a lower cost.
//! * **Standard errors**: `σ²·τ·(JᵀJ)⁻¹` at the final values, `σ²` the residuals' mean
//!   square over `N − p`, `τ` their integrated autocorrelation time in samples (the band-
//!   limited residuals are strongly correlated from sample to sample: without `τ` the errors
//!   would be `√τ` too small). [`PredictionErrorFit::effective_residuals`] is `N/τ`. They are
//!   conditional on the model's structure: a residual that is model error, not noise, is
//!   treated as noise.
//!
//! The fit is deterministic: the runs are independent and collected in order (rayon over
//! the Jacobian's columns and the records), and every sum is in a fixed order.
//!
//! # Where each part is
//!
//! * [`values`]: the parameters and the loop's values they set;
//! * [`problem`]: the fitted records, the runs and their residuals;
//! * [`search`]: the Levenberg–Marquardt search.
//!
//! This file sets the problem up from a loop's values ([`refine_loop`]), reports the fit and
//! writes the refined values back into an identified plant ([`refine`]).

use std::collections::BTreeMap;

use platen_model::{IdentifiedParams, Specimen};
use platen_system::{TableSystem, TableSystemParts};

use super::plant::{IdentifiedHydraulics, IdentifiedPlant};
use super::{SystemRecord, JUDGE_LOWPASS_HZ};
use crate::error::{IdentError, Result};
use problem::{mean_command_speed, sum_squares, targets, Channel, Problem};
use search::{levenberg_marquardt, Outcome};
use values::{equivalent_lag_s, parameters, Param, Values};

mod problem;
mod search;
mod values;

pub use problem::FD_STEP;
pub use search::{CHI2_TOLERANCE, MAX_CORRELATION, MAX_ITERATIONS, MIN_COLUMN_NORM};

/// One refined parameter.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PemParameter {
    /// What it is: its path in the printed scenario where it is one value
    /// (`model.identified.effective_mass_kg`, `specimen.storeys[0].stiffness_n_per_m`,
    /// `table_system.controller.displacement_gain_per_m`, …), else what it scales
    /// (`table_system.servo_valve.equivalent_lag_s`: the delay and the spool's period
    /// together; `table_system.actuator.chamber_volume_m3`: both chambers).
    pub key: String,
    /// The equation error's value (the start), in the key's unit.
    pub start: f64,
    /// The refined value.
    pub value: f64,
    /// Its standard error (see the module docs), in the key's unit; absent when held.
    pub std_error: Option<f64>,
    /// Whether the fit moved it (else it is held at the start: see `not_identified`).
    pub refined: bool,
}

/// One channel's fit on the fitted records.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChannelFit {
    /// `a_m_s2` (the table) or `storey{i}_a_m_s2`.
    pub channel: String,
    /// NRMSE in the band over every fitted record (RMS of recorded less predicted over the
    /// recorded RMS), with the equation error's values.
    pub nrmse_before: f64,
    /// The same with the refined values.
    pub nrmse_after: f64,
}

/// The prediction-error fit of the loop (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PredictionErrorFit {
    /// Levenberg–Marquardt iterations (Jacobians that led to a step).
    pub iterations: usize,
    /// Whether it stopped on the statistical criterion (else on the iteration cap or with no
    /// lower cost found).
    pub converged: bool,
    /// Why it stopped.
    pub stop_reason: String,
    /// Steps rejected (a higher cost or a failed run).
    pub rejected_steps: usize,
    /// Runs that failed (the integrator or values no table system takes).
    pub failed_runs: usize,
    /// Mean square of the normalised residuals with the equation error's values.
    pub cost_before: f64,
    /// The same with the refined values.
    pub cost_after: f64,
    /// Residuals (samples × channels over the fitted records).
    pub residuals: usize,
    /// The residuals' integrated autocorrelation time, samples.
    pub correlation_time_samples: f64,
    /// `residuals / correlation_time_samples`: the independent residuals the standard
    /// errors count.
    pub effective_residuals: f64,
    /// RK4 steps per controller period of the fit's runs.
    pub steps_per_period: u32,
    /// Band of the compared accelerations, Hz.
    pub band_hz: f64,
    /// Each channel's NRMSE before and after.
    pub channels: Vec<ChannelFit>,
    /// Every parameter, refined or held.
    pub parameters: Vec<PemParameter>,
}

/// A closed loop's values: what [`refine_loop`] starts from and gives.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopValues {
    /// The table system, its controller's gains included.
    pub system: TableSystem,
    /// The platen.
    pub model: IdentifiedParams,
    /// The specimen on the platen, if any.
    pub specimen: Option<Specimen>,
}

/// What [`refine_loop`] gives.
#[derive(Debug, Clone, PartialEq)]
pub struct RefinedLoop {
    /// The refined values.
    pub values: LoopValues,
    /// The fit.
    pub fit: PredictionErrorFit,
    /// The parameters held at their start, with why (the records do not see them or cannot
    /// tell them from others).
    pub held: Vec<(String, String)>,
}

/// Refines `start` by its prediction error on the records `fitted` of `records` (module
/// docs): the closed loop run on each one's command from rest, its table and storey
/// accelerations (and drive and `Δp` where every fitted record has them) made to reproduce
/// the recorded ones. The storeys compared are those every fitted record holds, at most
/// the specimen's.
///
/// # Errors
/// [`IdentError::InvalidRecord`] for a record whose channels do not fit together or that
/// cannot be filtered, no record to fit, or an index in `fitted` past the records; [`IdentError::LoopNotIdentifiable`] for a
/// fitted record without a table acceleration, or when `start` does not run on a fitted
/// record's command.
pub fn refine_loop(
    records: &[SystemRecord],
    fitted: &[usize],
    start: &LoopValues,
) -> Result<RefinedLoop> {
    let periods = records
        .iter()
        .map(SystemRecord::period_s)
        .collect::<Result<Vec<f64>>>()?;
    let first = check_fitted(records, fitted)?;
    let values = Values::of(start);
    let h = periods[first];
    let band_hz = JUDGE_LOWPASS_HZ.min(0.4 * 0.5 / h);
    let channels = compared_channels(records, fitted, values.storeys.len());
    let names = || {
        fitted
            .iter()
            .map(|&i| records[i].name.clone())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let Some((targets, scale)) = targets(records, &periods, fitted, &channels, band_hz) else {
        return Err(IdentError::InvalidRecord {
            test: names(),
            message: "the channels cannot be filtered at the records' rate, or one is \
                      constant, or the command cannot be read as a motion"
                .into(),
        });
    };
    // The specimen's storeys beyond those recorded in every fitted record still run (they
    // feed the base shear back), compared only where recorded.
    let payload: f64 = values.storeys.iter().map(|s| s.mass_kg).sum();
    let steps_per_period = start
        .system
        .default_steps_per_period(values.model.effective_mass_kg + payload, values.stroke_m());
    let mean_speed = mean_command_speed(&targets);
    let params = parameters(&values, mean_speed);
    let problem = Problem {
        targets,
        channels,
        scale,
        start: values.clone(),
        params,
        steps_per_period,
    };
    let Some(out) = levenberg_marquardt(&problem) else {
        return Err(IdentError::LoopNotIdentifiable {
            record: names(),
            reason: "the starting loop fails to run on a fitted record's command (the \
                     integrator, or values no table system takes)"
                .into(),
        });
    };
    let held = out
        .held
        .iter()
        .map(|(j, reason)| {
            (
                problem.params[*j].key.clone(),
                format!("prediction-error fit: {reason}"),
            )
        })
        .collect();
    let refined = values.with(&problem.params, &out.theta);
    // The start's values when the refined ones make no loop (they always do: every
    // accepted step ran).
    let values = match refined.build() {
        Some(b) => LoopValues {
            system: b.system,
            model: refined.model,
            specimen: b.specimen,
        },
        None => start.clone(),
    };
    Ok(RefinedLoop {
        values,
        fit: fit_report(&problem, out, band_hz),
        held,
    })
}

/// The index of the first fitted record, once every one of `fitted` is a record of
/// `records` with a table acceleration ([`refine_loop`]'s errors otherwise).
fn check_fitted(records: &[SystemRecord], fitted: &[usize]) -> Result<usize> {
    if let Some(&i) = fitted.iter().find(|&&i| i >= records.len()) {
        return Err(IdentError::InvalidRecord {
            test: format!("record {i}"),
            message: format!(
                "marked for the fit, but there are {} records",
                records.len()
            ),
        });
    }
    let Some(&first) = fitted.first() else {
        return Err(IdentError::InvalidRecord {
            test: records.first().map_or(String::new(), |r| r.name.clone()),
            message: "no record is marked for the fit".into(),
        });
    };
    if let Some(&i) = fitted.iter().find(|&&i| records[i].a_m_s2.is_none()) {
        return Err(IdentError::LoopNotIdentifiable {
            record: records[i].name.clone(),
            reason: "no a_m_s2: the prediction-error fit has nothing to compare the loop with"
                .into(),
        });
    }
    Ok(first)
}

/// The channels compared: the table's acceleration, the storeys' that every fitted record
/// holds (at most the specimen's `storeys`), and `Δp` where every fitted record has it.
fn compared_channels(records: &[SystemRecord], fitted: &[usize], storeys: usize) -> Vec<Channel> {
    let recorded_storeys = fitted
        .iter()
        .map(|&i| records[i].storey_a_m_s2.len())
        .min()
        .unwrap_or(0)
        .min(storeys);
    let mut channels: Vec<Channel> = std::iter::once(Channel::Table)
        .chain((0..recorded_storeys).map(Channel::Storey))
        .collect();
    if fitted.iter().all(|&i| records[i].delta_p_pa.is_some()) {
        channels.push(Channel::DeltaP);
    }
    channels
}

/// The report of the search's outcome `out` on `problem` (compared in `band_hz`): costs and
/// channels' NRMSE before (the start) and after, and every parameter.
fn fit_report(problem: &Problem<'_>, out: Outcome, band_hz: f64) -> PredictionErrorFit {
    let theta0: Vec<f64> = problem.params.iter().map(Param::theta0).collect();
    let r0 = problem.residuals(&theta0).unwrap_or_default();
    let (before, after) = (
        problem.channel_nrmse(&r0),
        problem.channel_nrmse(&out.residuals),
    );
    let n = out.residuals.len();
    let channels = (0..problem.scale.len())
        .map(|c| ChannelFit {
            channel: problem.channels[c].name(),
            nrmse_before: before.get(c).copied().unwrap_or(f64::NAN),
            nrmse_after: after.get(c).copied().unwrap_or(f64::NAN),
        })
        .collect();
    PredictionErrorFit {
        iterations: out.iterations,
        converged: out.converged,
        rejected_steps: out.rejected,
        failed_runs: out.failed,
        cost_before: sum_squares(&r0) / r0.len().max(1) as f64,
        cost_after: sum_squares(&out.residuals) / n.max(1) as f64,
        residuals: n,
        correlation_time_samples: out.tau,
        effective_residuals: n as f64 / out.tau,
        steps_per_period: problem.steps_per_period,
        band_hz,
        channels,
        parameters: parameter_reports(problem, &out),
        stop_reason: out.stop_reason,
    }
}

/// Every parameter of `problem` as the search `out` left it: start, value, standard error
/// (the covariance's, in the parameter's unit) and whether it was refined.
fn parameter_reports(problem: &Problem<'_>, out: &Outcome) -> Vec<PemParameter> {
    problem
        .params
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let k = out.free.iter().position(|&f| f == j);
            let std_error = k.and_then(|k| {
                let c = out.covariance.as_ref()?;
                let s = c[(k, k)].sqrt() * p.derivative(out.theta[j]).abs();
                s.is_finite().then_some(s)
            });
            PemParameter {
                key: p.key.clone(),
                start: p.start,
                value: p.value(out.theta[j]),
                std_error,
                refined: k.is_some(),
            }
        })
        .collect()
}

/// Refines the loop's values in `plant` and `gains` by the prediction error on the `fitted`
/// records ([`refine_loop`]), writes the refined values back (the system, model, specimen,
/// storeys and their modes, hydraulics, mechanics' values, standard errors and the gains'
/// estimates) and reports the fit; `None` (with why in `not_identified`) when the loop
/// cannot be run or compared.
pub(crate) fn refine(
    records: &[SystemRecord],
    fitted: &[usize],
    plant: &mut IdentifiedPlant,
    not_identified: &mut Vec<(String, String)>,
) -> Option<PredictionErrorFit> {
    let (Some(system), Some(model)) = (plant.system, plant.model) else {
        return None;
    };
    let start = LoopValues {
        system,
        model,
        specimen: plant.specimen.clone(),
    };
    match refine_loop(records, fitted, &start) {
        Ok(r) => {
            not_identified.extend(r.held);
            write_back(plant, &r.values, &r.fit.parameters);
            Some(r.fit)
        }
        Err(e) => {
            not_identified.push((
                "the prediction-error fit".to_owned(),
                format!("not done, the equation error's values kept: {e}"),
            ));
            None
        }
    }
}

/// The refined `values` into the identification's plant: the system, model, mechanics'
/// values, storeys and their modes, hydraulics and the refined `parameters`' standard errors.
fn write_back(plant: &mut IdentifiedPlant, values: &LoopValues, parameters: &[PemParameter]) {
    let v = Values::of(values);
    if values.model.build().is_err() {
        return;
    }
    plant.system = Some(values.system);
    plant.model = Some(v.model);
    if let Some(m) = plant.mechanics.as_mut() {
        m.effective_mass_kg = v.model.effective_mass_kg;
        m.coulomb_force_n = v.model.coulomb_force_n;
        m.viscous_coefficient = v.model.viscous_coefficient;
    }
    if let Some(sp) = values.specimen.clone() {
        for (s, t) in plant.storeys.iter_mut().zip(sp.storeys()) {
            s.mass_kg = t.mass_kg;
            s.stiffness_n_per_m = t.stiffness_n_per_m;
            s.damping_n_s_per_m = t.damping_n_s_per_m;
        }
        plant.specimen_modes = super::plant::modes(&plant.storeys);
        plant.specimen = Some(sp);
    }
    if let Some(hyd) = plant.hydraulics.as_mut() {
        write_back_hydraulics(hyd, &v, &values.system);
    }
    for p in parameters.iter().filter(|p| p.refined) {
        write_back_std_error(&mut plant.std_errors, p, &v.parts);
    }
}

/// The refined valves and chambers of `v` (run as `system`) into the identified hydraulics.
fn write_back_hydraulics(hyd: &mut IdentifiedHydraulics, v: &Values, system: &TableSystem) {
    let sv = &v.parts.servo_valve;
    let a = &v.parts.actuator;
    if hyd.rated_flow_m3_s > 0.0 {
        hyd.land_coefficient *= sv.rated_flow_m3_s / hyd.rated_flow_m3_s;
    }
    hyd.rated_flow_m3_s = sv.rated_flow_m3_s;
    hyd.cap_volume_m3 = a.cap_volume_m3;
    hyd.rod_volume_m3 = a.rod_volume_m3;
    hyd.cap_compliance_m3_per_pa = a.cap_volume_m3 / v.parts.oil_bulk_modulus_pa;
    hyd.rod_compliance_m3_per_pa = a.rod_volume_m3 / v.parts.oil_bulk_modulus_pa;
    hyd.valve_delay_s = sv.delay_s;
    hyd.spool_natural_frequency_hz = sv.natural_frequency_hz;
    hyd.equivalent_lag_s = equivalent_lag_s(sv.delay_s, sv.natural_frequency_hz, sv.damping_ratio);
    let payload: f64 = v.storeys.iter().map(|s| s.mass_kg).sum();
    hyd.oil_column_frequency_hz = system.oil_column_frequency_hz(v.model.effective_mass_kg, 0.0);
    hyd.oil_column_frequency_with_specimen_hz =
        system.oil_column_frequency_hz(v.model.effective_mass_kg + payload, 0.0);
}

/// A refined parameter's standard error into `std_errors` under the scenario paths it
/// stands for (none for the valve lag, both chambers' volumes for their common factor,
/// scaled by each one's volume in `parts`), or removed there when it has none.
fn write_back_std_error(
    std_errors: &mut BTreeMap<String, f64>,
    p: &PemParameter,
    parts: &TableSystemParts,
) {
    let paths: Vec<String> = match p.key.as_str() {
        "table_system.servo_valve.equivalent_lag_s" => vec![],
        "table_system.actuator.chamber_volume_m3" => (0..2)
            .map(|k| format!("table_system.actuator.chamber_volume_m3[{k}]"))
            .collect(),
        key => vec![key.to_owned()],
    };
    for path in paths {
        match p.std_error {
            Some(s) => {
                // A chamber's volume scales with the common factor.
                let s = if p.key == "table_system.actuator.chamber_volume_m3" {
                    let k = if path.ends_with("[0]") {
                        parts.actuator.cap_volume_m3
                    } else {
                        parts.actuator.rod_volume_m3
                    };
                    s / p.value * k
                } else {
                    s
                };
                std_errors.insert(path, s);
            }
            None => {
                std_errors.remove(&path);
            }
        }
    }
}
