//! `platen`: simulate, inspect and (later) identify the mechanics of a shake-table platen.
//!
//! Exit codes: 0 success, 2 usage error, 3 input error (a file, scenario or parameter that
//! cannot be used), 4 numerical failure, 5 I/O error while writing output.

#![recursion_limit = "256"]

mod model;
mod simulate;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use platen_integrate::IntegrateError;
use platen_scenario::ScenarioError;

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
pub(crate) enum Form {
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
        } => simulate::run(&scenario, out.as_deref(), json),
        Command::Model {
            preset,
            pressure_mpa,
            form,
            json,
        } => model::run(&preset, pressure_mpa, form, json),
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
