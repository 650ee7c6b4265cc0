//! `table_system`: the loop around the platen (controller, servo-valves, actuators, supply).
//! With one, a motion excitation is the displacement **command** and the run is the closed
//! loop, forward ([`platen_integrate::forward_closed_loop`]).
//!
//! ```json
//! "table_system": { "preset": "lhpost-2008" }
//! "table_system": {
//!   "actuator": { "count": 1, "area_m2": 0.02, "chamber_volume_m3": 0.02,
//!                 "leakage_m3_s_per_pa": 1e-11 },
//!   "servo_valve": { "count": 1, "rated_flow_m3_s": 0.01, "rated_pressure_drop_pa": 7e6,
//!                    "natural_frequency_hz": 120, "damping_ratio": 0.7, "delay_s": 0.0005 },
//!   "oil_bulk_modulus_pa": 1.2e9, "supply_pressure_pa": 21e6, "return_pressure_pa": 3e5,
//!   "controller": { "sample_rate_hz": 4096, "displacement_gain_per_m": 20,
//!                   "velocity_feedforward_s_per_m": 0.9, "delta_p_gain_per_pa": 2e-8,
//!                   "delta_p_highpass_hz": 1 }
//! }
//! ```
//!
//! With a `preset`, every value given is laid over the preset's (`"accumulator": null`
//! replaces its bank by a constant supply); without one, every value is required but the
//! accumulator (absent: constant supply), the leakage (0), the delay (0) and the controller's
//! gains (absent gains are 0). `chamber_volume_m3` is one volume for both chambers or
//! `[cap, rod]`; `area_m2` is a double-ended actuator's area, `cap_side_area_m2` and
//! `rod_side_area_m2` a single-ended one's.
//!
//! The integrator: RK4 (default) at `step_s`, which must divide the controller's period (the
//! default is the largest such step with `h·ω_max ≤ 0.25` for the loop's fastest mode: the
//! spool, or the oil column at the stroke's ends), or Dopri5 at `rtol`/`atol`. A step that
//! cannot resolve the fastest mode (`h·ω_max > 1`) is refused.

use platen_integrate::LoopMethod;
use platen_system::{
    preset as system_preset, Accumulator, Controller, Supply, SystemError, TableSystem,
    TableSystemParts,
};

use crate::ctx::Ctx;
use crate::error::{Result, ScenarioError};
use crate::file::{Dopri5Spec, IntegratorSpec, DEFAULT_ATOL, DEFAULT_RTOL};
use crate::system_file::Overlay;
pub use crate::system_file::{
    AccumulatorSpec, ActuatorSpec, ChamberVolumes, ControllerSpec, ServoValveSpec, TableSystemSpec,
};

/// Builds the table system of `spec` (a preset with values laid over it, or explicit), with
/// every error named by its JSON path under `table_system`.
pub(crate) fn build_table_system(
    ctx: &Ctx,
    spec: &TableSystemSpec,
    stroke_m: f64,
) -> Result<TableSystem> {
    let spec = match &spec.preset {
        Some(name) => {
            let base = system_preset::by_name(name).map_err(|e| {
                ctx.invalid("table_system.preset", format!("{name:?}"), e.to_string())
            })?;
            spec.clone().overlay(TableSystemSpec::from(&base))
        }
        None => spec.clone(),
    };
    let parts = complete_system(ctx, &spec)?;
    TableSystem::new(parts, stroke_m).map_err(|e| match e {
        SystemError::Invalid {
            path,
            value,
            expected,
        } => ctx.invalid(&format!("table_system.{path}"), value, expected),
        other => ctx.invalid("table_system", "", other.to_string()),
    })
}

/// The values of the system of `spec` (its preset's values already laid under it), not yet
/// validated: every required value given, or an error naming the first missing one by its
/// JSON path; absent gains, leakage and delay are 0, an absent accumulator a constant supply.
fn complete_system(ctx: &Ctx, spec: &TableSystemSpec) -> Result<TableSystemParts> {
    let actuator = complete_actuator(ctx, spec.actuator.clone().unwrap_or_default())?;
    let servo_valve = complete_servo_valve(ctx, spec.servo_valve.clone().unwrap_or_default())?;
    let [oil_bulk_modulus_pa, supply_pressure_pa, return_pressure_pa] = need_all(
        ctx,
        [
            ("oil_bulk_modulus_pa", spec.oil_bulk_modulus_pa),
            ("supply_pressure_pa", spec.supply_pressure_pa),
            ("return_pressure_pa", spec.return_pressure_pa),
        ],
    )?;
    let controller = complete_controller(ctx, spec.controller.clone().unwrap_or_default())?;
    let supply = supply_under(
        ctx,
        "table_system",
        spec.accumulator.as_ref().and_then(Option::as_ref),
    )?;
    Ok(TableSystemParts {
        actuator,
        servo_valve,
        oil_bulk_modulus_pa,
        supply_pressure_pa,
        return_pressure_pa,
        supply,
        controller,
    })
}

/// The supply of `accumulator` (its values' paths under `prefix`): a bank, or a constant
/// supply pressure without one.
pub(crate) fn supply_under(
    ctx: &Ctx,
    prefix: &str,
    accumulator: Option<&AccumulatorSpec>,
) -> Result<Supply> {
    let Some(acc) = accumulator else {
        return Ok(Supply::Constant);
    };
    let [precharge_pressure_pa, volume_m3, polytropic_exponent, pump_flow_m3_s] = need_all_under(
        ctx,
        prefix,
        [
            (
                "accumulator.precharge_pressure_pa",
                acc.precharge_pressure_pa,
            ),
            ("accumulator.volume_m3", acc.volume_m3),
            ("accumulator.polytropic_exponent", acc.polytropic_exponent),
            ("accumulator.pump_flow_m3_s", acc.pump_flow_m3_s),
        ],
    )?;
    Ok(Supply::Accumulator(Accumulator {
        precharge_pressure_pa,
        volume_m3,
        polytropic_exponent,
        pump_flow_m3_s,
    }))
}

/// The error of a value missing at `path` under `table_system`.
fn missing(ctx: &Ctx, path: &str, expected: &str) -> ScenarioError {
    missing_under(ctx, "table_system", path, expected)
}

/// The error of a value missing at `path` under `prefix`.
fn missing_under(ctx: &Ctx, prefix: &str, path: &str, expected: &str) -> ScenarioError {
    ctx.invalid(&format!("{prefix}.{path}"), "(missing)", expected)
}

/// The values of `fields` (their JSON paths under `table_system` and values), in order, or
/// the error naming the first missing one.
fn need_all<const N: usize>(ctx: &Ctx, fields: [(&str, Option<f64>); N]) -> Result<[f64; N]> {
    need_all_under(ctx, "table_system", fields)
}

/// [`need_all`] under `prefix`.
pub(crate) fn need_all_under<const N: usize>(
    ctx: &Ctx,
    prefix: &str,
    fields: [(&str, Option<f64>); N],
) -> Result<[f64; N]> {
    let mut values = [0.0; N];
    for (slot, (path, value)) in values.iter_mut().zip(fields) {
        *slot = value.ok_or_else(|| {
            missing_under(ctx, prefix, path, "a value (or a `preset` to take it from)")
        })?;
    }
    Ok(values)
}

/// The actuator of `a`: a count, double- or single-ended areas, chamber volumes; an absent
/// leakage is 0.
fn complete_actuator(ctx: &Ctx, a: ActuatorSpec) -> Result<platen_system::Actuator> {
    let count = a
        .count
        .ok_or_else(|| missing(ctx, "actuator.count", "a count ≥ 1"))?;
    let (cap, rod) = match (a.area_m2, a.cap_side_area_m2, a.rod_side_area_m2) {
        (Some(area), None, None) => (area, area),
        (Some(area), _, _) => {
            return Err(ctx.invalid(
                "table_system.actuator.area_m2",
                area,
                "either `area_m2` (double-ended) or `cap_side_area_m2` and `rod_side_area_m2`, not both",
            ))
        }
        (None, c, r) => {
            let [cap, rod] = need_all(
                ctx,
                [
                    ("actuator.cap_side_area_m2", c),
                    ("actuator.rod_side_area_m2", r),
                ],
            )?;
            (cap, rod)
        }
    };
    let (cap_volume, rod_volume) = match a.chamber_volume_m3 {
        Some(ChamberVolumes::Both(v)) => (v, v),
        Some(ChamberVolumes::Each([c, r])) => (c, r),
        None => {
            return Err(missing(
                ctx,
                "actuator.chamber_volume_m3",
                "a volume, or [cap, rod]",
            ))
        }
    };
    Ok(platen_system::Actuator {
        count,
        cap_area_m2: cap,
        rod_area_m2: rod,
        cap_volume_m3: cap_volume,
        rod_volume_m3: rod_volume,
        leakage_m3_s_per_pa: a.leakage_m3_s_per_pa.unwrap_or(0.0),
    })
}

/// The servo-valves of `v`; an absent delay is 0.
fn complete_servo_valve(ctx: &Ctx, v: ServoValveSpec) -> Result<platen_system::ServoValve> {
    complete_servo_valve_under(ctx, "table_system", v)
}

/// [`complete_servo_valve`] with its paths under `prefix`.
pub(crate) fn complete_servo_valve_under(
    ctx: &Ctx,
    prefix: &str,
    v: ServoValveSpec,
) -> Result<platen_system::ServoValve> {
    let count = v
        .count
        .ok_or_else(|| missing_under(ctx, prefix, "servo_valve.count", "a count ≥ 1"))?;
    let [rated_flow_m3_s, rated_pressure_drop_pa, natural_frequency_hz, damping_ratio] =
        need_all_under(
            ctx,
            prefix,
            [
                ("servo_valve.rated_flow_m3_s", v.rated_flow_m3_s),
                (
                    "servo_valve.rated_pressure_drop_pa",
                    v.rated_pressure_drop_pa,
                ),
                ("servo_valve.natural_frequency_hz", v.natural_frequency_hz),
                ("servo_valve.damping_ratio", v.damping_ratio),
            ],
        )?;
    Ok(platen_system::ServoValve {
        count,
        rated_flow_m3_s,
        rated_pressure_drop_pa,
        natural_frequency_hz,
        damping_ratio,
        delay_s: v.delay_s.unwrap_or(0.0),
    })
}

/// The controller of `c`: its sample rate, and its gains (absent gains are 0).
fn complete_controller(ctx: &Ctx, c: ControllerSpec) -> Result<Controller> {
    let sample_rate_hz = c.sample_rate_hz.ok_or_else(|| {
        missing(
            ctx,
            "controller.sample_rate_hz",
            "the controller's sample rate, Hz",
        )
    })?;
    Ok(controller_gains(sample_rate_hz, &c))
}

/// The gains of `c` at `sample_rate_hz` (absent gains are 0).
pub(crate) fn controller_gains(sample_rate_hz: f64, c: &ControllerSpec) -> Controller {
    let gain = |g: Option<f64>| g.unwrap_or(0.0);
    Controller {
        sample_rate_hz,
        displacement_gain_per_m: gain(c.displacement_gain_per_m),
        integral_gain_per_m_s: gain(c.integral_gain_per_m_s),
        velocity_feedforward_s_per_m: gain(c.velocity_feedforward_s_per_m),
        acceleration_feedforward_s2_per_m: gain(c.acceleration_feedforward_s2_per_m),
        velocity_feedback_s_per_m: gain(c.velocity_feedback_s_per_m),
        acceleration_feedback_s2_per_m: gain(c.acceleration_feedback_s2_per_m),
        delta_p_gain_per_pa: gain(c.delta_p_gain_per_pa),
        delta_p_highpass_hz: gain(c.delta_p_highpass_hz),
    }
}

/// The most RK4 steps per controller period, as
/// [`TableSystem::default_steps_per_period`] clamps them.
const MAX_STEPS_PER_PERIOD: f64 = 1e6;

/// The error of a loop whose fastest mode RK4 cannot resolve within
/// [`MAX_STEPS_PER_PERIOD`] steps per controller period, named by the value that makes it
/// fast: the spool's natural frequency, or the oil column (stiff oil, small chambers).
fn unresolvable(
    ctx: &Ctx,
    system: &TableSystem,
    period: f64,
    fastest: f64,
) -> crate::error::ScenarioError {
    let tau = std::f64::consts::TAU;
    let f_max = MAX_STEPS_PER_PERIOD / (tau * period);
    let remedy = format!(
        "RK4 resolves modes up to {f_max:.3e} Hz with the controller at {} Hz \
         ({MAX_STEPS_PER_PERIOD:e} steps per controller period); use \
         {{\"method\": \"dopri5\"}} or a faster controller",
        system.controller().sample_rate_hz
    );
    let valve_hz = system.servo_valve().natural_frequency_hz;
    if tau * valve_hz >= fastest {
        ctx.invalid(
            "table_system.servo_valve.natural_frequency_hz",
            valve_hz,
            format!("a spool RK4 can resolve: {remedy}"),
        )
    } else {
        ctx.invalid(
            "table_system",
            format!(
                "(an oil column of {:.4e} Hz at the stroke's ends)",
                fastest / tau
            ),
            format!("a loop RK4 can resolve: {remedy}"),
        )
    }
}

/// The closed loop's integrator: RK4 at a step that divides the controller period and
/// resolves the loop's fastest mode, or Dopri5.
pub(crate) fn loop_method(
    ctx: &Ctx,
    integrator: Option<&IntegratorSpec>,
    system: &TableSystem,
    mass_kg: f64,
    stroke_m: f64,
) -> Result<LoopMethod> {
    let period = system.controller().period_s();
    let fastest = system.fastest_rate_rad_s(mass_kg, stroke_m);
    let k = system.default_steps_per_period(mass_kg, stroke_m);
    loop_method_at(ctx, integrator, period, fastest, k, || {
        unresolvable(ctx, system, period, fastest)
    })
}

/// The closed loop's integrator for a controller of `period` s whose loop's fastest mode is
/// `fastest` rad/s: RK4 at `k_default` steps per period by default (`refused` when those do
/// not resolve it), at `integrator.step_s`, or Dopri5.
pub(crate) fn loop_method_at(
    ctx: &Ctx,
    integrator: Option<&IntegratorSpec>,
    period: f64,
    fastest: f64,
    k_default: u32,
    refused: impl FnOnce() -> ScenarioError,
) -> Result<LoopMethod> {
    // The default step: the least `k` with `h·ω_max ≤ 0.25`, but at most
    // `MAX_STEPS_PER_PERIOD`; a loop that this many steps cannot resolve is refused (RK4 at
    // the clamped step would blow up within a few steps).
    let default_rk4 = || -> Result<LoopMethod> {
        if period / f64::from(k_default) * fastest > 1.0 {
            return Err(refused());
        }
        Ok(LoopMethod::Rk4 {
            steps_per_period: k_default,
        })
    };
    match integrator {
        None => default_rk4(),
        Some(IntegratorSpec::Rk4(spec)) => match spec.step_s {
            None => default_rk4(),
            Some(step) => rk4_at_step(ctx, step, period, fastest, || k_default),
        },
        Some(IntegratorSpec::Dopri5(spec)) => dopri5(ctx, spec),
    }
}

/// RK4 at `step` (`integrator.step_s`): it must divide the controller's `period` into at most
/// [`MAX_STEPS_PER_PERIOD`] steps and resolve the loop's `fastest` mode, rad/s (the default
/// steps per period, `k_default`, are named when it does not).
fn rk4_at_step(
    ctx: &Ctx,
    step: f64,
    period: f64,
    fastest: f64,
    k_default: impl FnOnce() -> u32,
) -> Result<LoopMethod> {
    let here = "integrator.step_s";
    if !(step.is_finite() && step > 0.0) {
        return Err(ctx.invalid(here, step, "a finite step > 0 s"));
    }
    let k = (period / step).round();
    if k < 1.0 || (k * step - period).abs() > 1e-9 * period {
        return Err(ctx.invalid(
            here,
            step,
            format!(
                "the controller's period {period} s divided by a whole number \
                 (it updates the drive every {period} s)"
            ),
        ));
    }
    if k > MAX_STEPS_PER_PERIOD {
        return Err(ctx.invalid(
            here,
            step,
            format!(
                "at least the controller's period {period} s divided by \
                 {MAX_STEPS_PER_PERIOD:e} ({:e} s)",
                period / MAX_STEPS_PER_PERIOD
            ),
        ));
    }
    if step * fastest > 1.0 {
        let k_default = k_default();
        return Err(ctx.invalid(
            here,
            step,
            format!(
                "a step that resolves the loop's fastest mode ({:.1} Hz): at most {:.3e} s \
                 (default {:.3e} s)",
                fastest / std::f64::consts::TAU,
                1.0 / fastest,
                period / f64::from(k_default)
            ),
        ));
    }
    Ok(LoopMethod::Rk4 {
        steps_per_period: k as u32,
    })
}

/// Dopri5 at `spec`'s tolerances (default [`DEFAULT_RTOL`], [`DEFAULT_ATOL`]), checked.
fn dopri5(ctx: &Ctx, spec: &Dopri5Spec) -> Result<LoopMethod> {
    let rtol = spec.rtol.unwrap_or(DEFAULT_RTOL);
    let atol = spec.atol.unwrap_or(DEFAULT_ATOL);
    for (path, v) in [("integrator.rtol", rtol), ("integrator.atol", atol)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(ctx.invalid(path, v, "a finite tolerance > 0"));
        }
    }
    Ok(LoopMethod::Dopri5 {
        steps_per_period: 1,
        rtol,
        atol,
    })
}
