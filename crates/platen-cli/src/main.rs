//! `platen`: simulate, inspect and (later) identify the mechanics of a shake-table platen.
//!
//! Exit codes: 0 success, 2 usage error, 3 input error (a file, scenario or parameter that
//! cannot be used), 4 numerical failure, 5 I/O error while writing output.

#![recursion_limit = "256"]

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use serde_json::{json, Map, Value};

use platen_integrate::{
    forward_dopri5, forward_rk4, inverse, IntegrateError, Peaks, RunStats, Trajectory,
};
use platen_model::{PlatenModel, Preset, STANDARD_GRAVITY_M_S2};
use platen_scenario::csv_io::write_csv_atomic;
use platen_scenario::{Integrator, Model, Run, Scenario, ScenarioError};

#[derive(Parser)]
#[command(
    name = "platen",
    version,
    about = "Mechanics of a large shake-table platen (NEES-UCSD LHPOST model)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario: forward (force → motion) or inverse (motion → force).
    Simulate {
        /// Scenario JSON file.
        scenario: PathBuf,
        /// Write the time series (t_s, u_m, v_m_s, a_m_s2, force_n, inertial_force_n,
        /// elastic_force_n, dissipative_force_n) to this CSV file.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print a machine-readable summary on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Print a preset's parameters and derived quantities.
    Model {
        /// Preset name.
        #[arg(long, default_value = "lhpost-2008")]
        preset: String,
        /// Hold-down nitrogen pressure, MPa (default: the preset's nominal pressure).
        #[arg(long)]
        pressure_mpa: Option<f64>,
        /// Which form to describe.
        #[arg(long, value_enum, default_value_t = Form::Identified)]
        form: Form,
        /// Print JSON on stdout.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Form {
    /// The identified model of Eq. 22/23.
    Identified,
    /// The full Lagrangian model of Eq. 1–8.
    Full,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Simulate {
            scenario,
            out,
            json,
        } => simulate(&scenario, out.as_deref(), json),
        Command::Model {
            preset,
            pressure_mpa,
            form,
            json,
        } => model(&preset, pressure_mpa, form, json),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(exit_code(&e))
        }
    }
}

/// Maps an error chain to the documented exit codes.
fn exit_code(e: &anyhow::Error) -> u8 {
    for cause in e.chain() {
        if let Some(ie) = cause.downcast_ref::<IntegrateError>() {
            return match ie {
                IntegrateError::NonFiniteState { .. } | IntegrateError::EventLoopStalled { .. } => {
                    4
                }
                _ => 3,
            };
        }
        if let Some(se) = cause.downcast_ref::<ScenarioError>() {
            return match se {
                ScenarioError::Io { action, .. } if *action != "reading" => 5,
                _ => 3,
            };
        }
    }
    3
}

fn simulate(path: &Path, out: Option<&Path>, json_out: bool) -> Result<()> {
    let scenario = Scenario::load(path)?;
    let (trajectory, peaks, stats) = match &scenario.model {
        Model::Identified(m) => execute(m, &scenario.run)?,
        Model::Full(m) => execute(&**m, &scenario.run)?,
    };
    if let Some(out) = out {
        let names = Trajectory::COLUMN_NAMES;
        write_csv_atomic(out, &names, &trajectory.columns())?;
    }
    let summary = summary_json(path, &scenario, &peaks, stats.as_ref(), out);
    if json_out {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_summary(&scenario, &peaks, stats.as_ref(), out);
    }
    Ok(())
}

fn execute<M: PlatenModel>(model: &M, run: &Run) -> Result<(Trajectory, Peaks, Option<RunStats>)> {
    match run {
        Run::Forward {
            record,
            integrator,
            initial,
            samples,
        } => {
            let mut sink = (Trajectory::with_capacity(*samples), Peaks::default());
            let stats = match integrator {
                Integrator::Rk4(rk4) => {
                    forward_rk4(model, record, *rk4, *initial, *samples, &mut sink)
                }
                Integrator::Dopri5(settings) => {
                    forward_dopri5(model, record, *settings, *initial, *samples, &mut sink)
                }
            }
            .context("forward run failed; no output was written")?;
            Ok((sink.0, sink.1, Some(stats)))
        }
        Run::Inverse { motion } => {
            let mut sink = (Trajectory::with_capacity(motion.len()), Peaks::default());
            inverse(model, motion, &mut sink);
            Ok((sink.0, sink.1, None))
        }
    }
}

fn summary_json(
    path: &Path,
    s: &Scenario,
    peaks: &Peaks,
    stats: Option<&RunStats>,
    out: Option<&Path>,
) -> Value {
    let mut m = Map::new();
    m.insert("scenario".into(), json!(path.display().to_string()));
    m.insert("name".into(), json!(s.name));
    m.insert(
        "direction".into(),
        json!(if stats.is_some() {
            "forward"
        } else {
            "inverse"
        }),
    );
    m.insert("model_form".into(), json!(s.model.form()));
    m.insert("preset".into(), json!(s.preset.name()));
    m.insert(
        "hold_down_pressure_mpa".into(),
        json!(s.hold_down_pressure_pa / 1e6),
    );
    m.insert("samples".into(), json!(peaks.samples));
    m.insert("duration_s".into(), json!(peaks.span_s.1 - peaks.span_s.0));
    for (key, peak) in [
        ("peak_u_m", peaks.u_m),
        ("peak_v_m_s", peaks.v_m_s),
        ("peak_a_m_s2", peaks.a_m_s2),
        ("peak_force_n", peaks.force_n),
    ] {
        m.insert(key.into(), json!(peak.value));
        m.insert(format!("{key}_t_s"), json!(peak.t_s));
    }
    if let Some(st) = stats {
        m.insert("stick_time_s".into(), json!(st.stick_time_s));
        m.insert("stick_events".into(), json!(st.stick_events));
        m.insert("breakaways".into(), json!(st.breakaways));
        m.insert("reversals".into(), json!(st.reversals));
        let method = match &s.run {
            Run::Forward { integrator, .. } => integrator.name(),
            Run::Inverse { .. } => "none",
        };
        m.insert(
            "solver".into(),
            json!({
                "method": method,
                "steps": st.steps,
                "accepted_steps": st.accepted_steps,
                "rejected_steps": st.rejected_steps,
                "rhs_evaluations": st.rhs_evaluations,
                "events_located": st.events(),
                "root_iterations": st.root_iterations,
            }),
        );
        let e = &st.energy;
        m.insert(
            "energy".into(),
            json!({
                "actuator_work_j": e.actuator_work_j,
                "kinetic_start_j": e.kinetic_start_j,
                "kinetic_end_j": e.kinetic_end_j,
                "elastic_start_j": e.elastic_start_j,
                "elastic_end_j": e.elastic_end_j,
                "dissipated_j": e.dissipated_j,
                "residual_j": e.residual_j(),
                "relative_residual": e.relative_residual(),
            }),
        );
    }
    let exceed: Vec<Value> = peaks
        .exceedances(&s.limits)
        .iter()
        .map(|e| json!({"quantity": e.quantity, "peak": e.peak, "limit": e.limit, "t_s": e.t_s}))
        .collect();
    m.insert("limit_exceedances".into(), Value::Array(exceed));
    m.insert("out".into(), json!(out.map(|p| p.display().to_string())));
    Value::Object(m)
}

fn print_summary(s: &Scenario, peaks: &Peaks, stats: Option<&RunStats>, out: Option<&Path>) {
    let dir = if stats.is_some() {
        "forward (force → motion)"
    } else {
        "inverse (motion → force)"
    };
    println!(
        "{}: {dir}, {} model, {} at {:.2} MPa",
        s.name,
        s.model.form(),
        s.preset.name(),
        s.hold_down_pressure_pa / 1e6
    );
    println!(
        "  {} samples over {:.3} s",
        peaks.samples,
        peaks.span_s.1 - peaks.span_s.0
    );
    println!(
        "  peak displacement {:>+10.4} m     at {:.3} s",
        peaks.u_m.value, peaks.u_m.t_s
    );
    println!(
        "  peak velocity     {:>+10.4} m/s   at {:.3} s",
        peaks.v_m_s.value, peaks.v_m_s.t_s
    );
    println!(
        "  peak acceleration {:>+10.4} m/s²  at {:.3} s ({:.3} g)",
        peaks.a_m_s2.value,
        peaks.a_m_s2.t_s,
        peaks.a_m_s2.value / STANDARD_GRAVITY_M_S2
    );
    println!(
        "  peak force        {:>+10.1} kN    at {:.3} s",
        peaks.force_n.value / 1e3,
        peaks.force_n.t_s
    );
    if let (Some(st), Run::Forward { integrator, .. }) = (stats, &s.run) {
        println!(
            "  stick: {:.3} s in all, {} stops, {} breakaways, {} reversals",
            st.stick_time_s, st.stick_events, st.breakaways, st.reversals
        );
        println!(
            "  solver: {}, {} steps ({} rejected), {} right-hand-side evaluations, {} events located",
            integrator.name(),
            st.steps,
            st.rejected_steps,
            st.rhs_evaluations,
            st.events()
        );
        println!(
            "  energy: actuator work {:.4e} J = ΔE_kin + ΔE_el + dissipated {:.4e} J; residual {:.2e} J ({:.1e} relative)",
            st.energy.actuator_work_j,
            st.energy.dissipated_j,
            st.energy.residual_j(),
            st.energy.relative_residual()
        );
    }
    let ex = peaks.exceedances(&s.limits);
    if ex.is_empty() {
        println!("  within the table's limits");
    }
    for e in ex {
        println!(
            "  EXCEEDS {} limit: peak {:+.4} vs limit {:.4} (SI units) at {:.3} s",
            e.quantity, e.peak, e.limit, e.t_s
        );
    }
    if let Some(out) = out {
        println!("  wrote {}", out.display());
    }
}

fn model(preset: &str, pressure_mpa: Option<f64>, form: Form, json_out: bool) -> Result<()> {
    let preset = Preset::from_name(preset)?;
    let pressure_pa = match pressure_mpa {
        Some(p) if !(p.is_finite() && p >= 0.0) => {
            anyhow::bail!("--pressure-mpa {p}: expected a pressure >= 0 MPa")
        }
        Some(p) => p * 1e6,
        None => preset.nominal_pressure_pa(),
    };
    let identified = preset.identified(pressure_pa)?.build()?;
    let full = preset.physical(pressure_pa)?.build()?;
    let (p, d) = (full.params(), full.derived());
    // The seven contract keys describe the selected form; the derived quantities of Eq. 5-8
    // and the physical parameters are always shown.
    let (form_name, seven) = match form {
        Form::Identified => {
            let q = identified.params();
            (
                "identified",
                [
                    q.effective_mass_kg,
                    q.stiffness_n_per_m,
                    q.coulomb_force_n,
                    q.viscous_coefficient,
                    q.viscous_exponent,
                    q.low_velocity_force_n,
                    q.low_velocity_decay_s_per_m,
                ],
            )
        }
        Form::Full => (
            "full",
            [
                d.effective_mass_kg,
                d.stiffness_n_per_m,
                d.coulomb_force_n,
                p.viscous_coefficient,
                p.viscous_exponent,
                p.low_velocity_force_n,
                p.low_velocity_decay_s_per_m,
            ],
        ),
    };
    let value = json!({
        "preset": preset.name(),
        "form": form_name,
        "hold_down_pressure_mpa": pressure_pa / 1e6,
        "effective_mass_kg": seven[0],
        "stiffness_n_per_m": seven[1],
        "coulomb_force_n": seven[2],
        "viscous_coefficient": seven[3],
        "viscous_exponent": seven[4],
        "low_velocity_force_n": seven[5],
        "low_velocity_decay_s_per_m": seven[6],
        "cubic_stiffness_n_per_m": d.cubic_stiffness_n_per_m,
        "strut_effective_mass_kg": d.strut_effective_mass_kg,
        "strut_rotational_mass_kg": d.strut_rotational_mass_kg,
        "hold_down_force_n": d.hold_down_force_n,
        "hinge_friction_coefficient": d.hinge_friction_coefficient,
        "hold_down_friction_coefficient": d.hold_down_friction_coefficient,
        "full_effective_mass_kg": d.effective_mass_kg,
        "full_stiffness_n_per_m": d.stiffness_n_per_m,
        "full_coulomb_force_n": d.coulomb_force_n,
        "limits": {
            "stroke_m": preset.limits().stroke_m,
            "velocity_m_s": preset.limits().velocity_m_s,
            "acceleration_m_s2": preset.limits().acceleration_m_s2,
            "force_n": preset.limits().force_n,
        },
        "physical": {
            "platen_mass_kg": p.platen_mass_kg,
            "actuator_moving_mass_kg": p.actuator_moving_mass_kg,
            "strut_piston_mass_kg": p.strut_piston_mass_kg,
            "strut_cylinder_mass_kg": p.strut_cylinder_mass_kg,
            "strut_height_m": p.strut_height_m,
            "strut_piston_length_m": p.strut_piston_length_m,
            "hold_down_pressure_pa": p.hold_down_pressure_pa,
            "strut_area_m2": p.strut_area_m2,
            "gas_heat_capacity_ratio": p.gas_heat_capacity_ratio,
            "supported_weight_n": p.supported_weight_n,
            "bearing_friction_coefficient": p.bearing_friction_coefficient,
            "lateral_friction_coefficient": p.lateral_friction_coefficient,
            "lateral_normal_force_n": p.lateral_normal_force_n,
            "hinge_swivel_friction_coefficient": p.hinge_swivel_friction_coefficient,
            "hinge_radius_m": p.hinge_radius_m,
            "hinge_force_distribution_factor": p.hinge_force_distribution_factor,
            "viscous_coefficient": p.viscous_coefficient,
            "viscous_exponent": p.viscous_exponent,
            "strut_viscous_coefficient": p.strut_viscous_coefficient,
            "strut_viscous_exponent": p.strut_viscous_exponent,
            "low_velocity_force_n": p.low_velocity_force_n,
            "low_velocity_decay_s_per_m": p.low_velocity_decay_s_per_m,
        }
    });
    if json_out {
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else if let Value::Object(m) = &value {
        for (k, v) in m {
            if !v.is_object() {
                println!("{k:>34}  {v}");
            }
        }
        for section in ["limits", "physical"] {
            if let Some(Value::Object(sub)) = m.get(section) {
                println!("  {section}:");
                for (k, v) in sub {
                    println!("{k:>34}  {v}");
                }
            }
        }
    }
    Ok(())
}
