//! What a multi-axis closed loop costs before it runs: the steps its fastest mode asks of the
//! integrator, and the valves' orifice relaxation, each refused past a stated budget with the
//! value that makes it so. A unit slip (a valve's flow in l/min, a stiffness in N/mm, a spool
//! frequency in rad/s written as Hz) makes a mode far faster than any table's; without these
//! checks the run is accepted and then seems to hang.

use nalgebra::DMatrix;
use platen_integrate::PoseMotion;
use platen_model::multi_axis::{LinearSpecimen, MultiAxisTable};
use platen_system::{ActuatorState, TableHydraulics};

use crate::ctx::value_at;
use crate::ctx::Ctx;
use crate::error::Result;
use crate::table_file::TableSpec;

/// The most integration steps (RK4 steps, or Dopri5 pieces) a closed-loop run of a multi-axis
/// table may take: about two to four minutes at the six-DOF loop's 13–25 µs a step in a release
/// build. A 600 s run of the LHPOST6 at its 2048 Hz controller takes 1.2e6.
pub const MAX_LOOP_STEPS: f64 = 1e7;

/// The most a chamber's pressure may relax within one controller period at full opening
/// (`h·β/V·K/√p_t`, the orifice's laminar slope at a land whose drop is zero): the loop cuts its
/// step into that many pieces wherever the spool is wide open there. The LHPOST6's valves reach
/// about 200; a valve a hundred times too large for its chamber (a flow in l/min) reaches 10⁵ and
/// would crawl through every wide opening.
pub const MAX_ORIFICE_PIECES: f64 = 4096.0;

/// What a closed loop's integration costs per controller period.
pub(crate) struct LoopCost<'a> {
    /// Its actuators' hydraulics.
    pub hydraulics: &'a TableHydraulics,
    /// The controller's period, s.
    pub period_s: f64,
    /// Integration steps (or Dopri5 pieces) per period.
    pub steps_per_period: u32,
}

/// The source of the fastest mode the integrator follows: the steps per controller period it
/// asks, the key to look at, its value and what it is.
struct Source {
    steps_per_period: f64,
    key: String,
    value: String,
    what: String,
}

/// Refuses a closed loop whose integration would take more than [`MAX_LOOP_STEPS`] over
/// `command`, naming the value behind its fastest mode.
pub(crate) fn check_steps(
    ctx: &Ctx,
    spec: &TableSpec,
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    system: &LoopCost<'_>,
    command: &PoseMotion,
) -> Result<()> {
    let period_s = system.period_s;
    let t = command.t_s();
    let span = match (t.first(), t.last()) {
        (Some(a), Some(b)) => b - a,
        _ => 0.0,
    };
    let periods = (span / period_s).ceil().max(1.0);
    let k = f64::from(system.steps_per_period);
    let steps = k * periods;
    if steps <= MAX_LOOP_STEPS {
        return Ok(());
    }
    let json = serde_json::to_value(spec).unwrap_or_default();
    let source = fastest_source(&json, table, specimen, system.hydraulics, period_s);
    Err(ctx.invalid(
        &source.key,
        source.value,
        format!(
            "a value that keeps the run within {MAX_LOOP_STEPS:e} integration steps: the \
             integrator must follow {}, {k} steps a controller period over {periods} periods \
             ({steps:.3e} steps; a unit slip?)",
            source.what
        ),
    ))
}

/// Refuses a valve whose orifice would make its chamber's pressure relax faster than
/// [`MAX_ORIFICE_PIECES`] pieces of a controller period can follow at full opening.
pub(crate) fn check_orifices(
    ctx: &Ctx,
    spec: &TableSpec,
    hydraulics: &TableHydraulics,
    period_s: f64,
) -> Result<()> {
    for (i, a) in hydraulics.actuators().iter().enumerate() {
        let wide_open = ActuatorState {
            p_a_pa: hydraulics.supply_pressure_pa(),
            p_b_pa: hydraulics.return_pressure_pa(),
            spool: 1.0,
            spool_rate_1_s: 0.0,
        };
        let rate = hydraulics
            .pressure_rate_1_s(i, None, &wide_open, hydraulics.supply_pressure_pa())
            .rate_1_s;
        // A rate that is not finite (a rated drop of 1e-300 Pa) is refused too.
        if period_s * rate <= MAX_ORIFICE_PIECES {
            continue;
        }
        let valve = a.servo_valve;
        // A rated drop below 1 bar is the slip (a drop in bar or MPa written as Pa); else the flow.
        let (key, hint) = if valve.rated_pressure_drop_pa < 1e5 {
            (
                "rated_pressure_drop_pa",
                "a rated drop in Pa (70 bar is 7e6 Pa)",
            )
        } else {
            (
                "rated_flow_m3_s",
                "a rated flow in m³/s (630 l/min is 0.0105 m³/s)",
            )
        };
        let key = format!("table.actuators[{i}].servo_valve.{key}");
        // The spec as JSON only for the message: not on every load.
        let json = serde_json::to_value(spec).unwrap_or_default();
        let value = value_at(&json, &key["table.".len()..]);
        return Err(ctx.invalid(
            &key,
            value,
            format!(
                "{hint}: at full opening this valve would make its chamber's pressure relax at \
                 {rate:.3e} 1/s, {:.0} times within a controller period (at most \
                 {MAX_ORIFICE_PIECES} can be followed): a valve far larger than its actuator",
                period_s * rate
            ),
        ));
    }
    Ok(())
}

/// The value behind the fastest mode the loop's integrator follows: a spool, an oil column,
/// the specimen's own stiffness, or its levers coupling it to the platen's rotations.
fn fastest_source(
    json: &serde_json::Value,
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    hydraulics: &TableHydraulics,
    period_s: f64,
) -> Source {
    let mut sources = Vec::new();
    push_spool_sources(&mut sources, json, table, hydraulics, period_s);
    let oil = push_oil_column_sources(&mut sources, json, table, hydraulics, period_s);
    if let Some(s) = specimen {
        push_specimen_sources(&mut sources, table, s, oil, period_s);
    }
    // The first of the fastest (the lowest-numbered actuator of equal ones).
    sources
        .into_iter()
        .reduce(|best, s| {
            if s.steps_per_period > best.steps_per_period {
                s
            } else {
                best
            }
        })
        .unwrap_or(Source {
            steps_per_period: 0.0,
            key: "table.controller.sample_rate_hz".into(),
            value: String::new(),
            what: "the loop".into(),
        })
}

/// Hz of an angular frequency `w`, rad/s.
fn hz(w: f64) -> f64 {
    w / std::f64::consts::TAU
}

/// Each actuator's spool, at its valve's natural frequency.
fn push_spool_sources(
    sources: &mut Vec<Source>,
    json: &serde_json::Value,
    table: &MultiAxisTable,
    hydraulics: &TableHydraulics,
    period_s: f64,
) {
    use std::f64::consts::TAU;
    for (i, a) in hydraulics.actuators().iter().enumerate() {
        let f = a.servo_valve.natural_frequency_hz;
        let key = format!("table.actuators[{i}].servo_valve.natural_frequency_hz");
        sources.push(Source {
            steps_per_period: period_s * TAU * f,
            value: value_at(json, &key["table.".len()..]),
            key,
            what: format!(
                "actuator `{}`'s spool at {f:.4e} Hz",
                table.actuators()[i].name
            ),
        });
    }
}

/// The oil columns: each actuator's shut-valve stiffness on the platen's mass (each one
/// faster than those before it); the fastest's angular frequency, rad/s (0 without one).
fn push_oil_column_sources(
    sources: &mut Vec<Source>,
    json: &serde_json::Value,
    table: &MultiAxisTable,
    hydraulics: &TableHydraulics,
    period_s: f64,
) -> f64 {
    let mass = table.platen().mass_kg();
    let mut oil = 0.0_f64;
    for i in 0..hydraulics.actuators().len() {
        let w = (hydraulics.oil_column_stiffness_n_per_m(i, 0.0) / mass).sqrt();
        if w > oil {
            oil = w;
            let key = format!("table.actuators[{i}].chamber_volume_m3");
            sources.push(Source {
                steps_per_period: period_s * w / 0.25,
                value: value_at(json, &key["table.".len()..]),
                key,
                what: format!(
                    "actuator `{}`'s oil column at about {:.4e} Hz on the platen's mass",
                    table.actuators()[i].name,
                    hz(w)
                ),
            });
        }
    }
    oil
}

/// The specimen's stiffest mode on its own base, and its fastest mode on the platen when
/// that is far above both its own and the fastest oil column's (`oil`, rad/s): its levers
/// then couple it to the platen's rotations.
fn push_specimen_sources(
    sources: &mut Vec<Source>,
    table: &MultiAxisTable,
    s: &LinearSpecimen,
    oil: f64,
    period_s: f64,
) {
    use std::f64::consts::TAU;
    let own = stiffest_mode_rad_s(s);
    sources.push(Source {
        steps_per_period: period_s * own / 0.25,
        key: "specimen.stiffness_matrix".into(),
        value: "(as given)".into(),
        what: format!(
            "the specimen's stiffest mode on its own base, {:.4e} Hz",
            hz(own)
        ),
    });
    let coupled = table
        .modes_with(s)
        .iter()
        .map(|m| TAU * m.frequency_hz)
        .fold(0.0, f64::max);
    if coupled > 1.1 * own.max(oil) {
        sources.push(Source {
            steps_per_period: period_s * coupled / 0.25,
            key: "specimen.influence".into(),
            value: "(as given)".into(),
            what: format!(
                "a mode of the specimen on the platen at {:.4e} Hz, far above its own and \
                 the oil columns': its levers couple it to the platen's rotations",
                hz(coupled)
            ),
        });
    }
}

/// The specimen's fastest natural frequency on a fixed base, rad/s: `√λ_max` of `M⁻¹K` (by
/// the symmetric `L⁻¹·K·L⁻ᵀ`, `M = L·Lᵀ`).
fn stiffest_mode_rad_s(s: &LinearSpecimen) -> f64 {
    let Some(chol) = s.mass().clone().cholesky() else {
        return 0.0;
    };
    let l = chol.l();
    let Some(l_inv) = l.clone().try_inverse() else {
        return 0.0;
    };
    let k: DMatrix<f64> = &l_inv * s.stiffness() * l_inv.transpose();
    let k = (&k + k.transpose()) * 0.5;
    k.symmetric_eigenvalues().max().max(0.0).sqrt()
}
