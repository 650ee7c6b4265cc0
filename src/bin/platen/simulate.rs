//! `platen simulate`: run a scenario, stream its time series to CSV, summarise it.
//!
//! The CSV is written as the samples are produced ([`CsvSink`]), to a temporary file next to
//! the target that is renamed over it when the run is complete and removed if it fails, so a
//! one-hour 1024 Hz run holds no trajectory in memory.

use std::path::PathBuf;

use anyhow::Result;

use platen_report::simulate::{simulate, Outputs, SimulateError};
use platen_scenario::Scenario;

use crate::progress::{Progress, Ticker};
use crate::{plot, sweep, usage};

/// The arguments of `platen simulate`.
#[derive(clap::Args)]
pub struct SimulateArgs {
    /// Scenario JSON file.
    scenario: PathBuf,
    /// Write the time series (t_s, u_m, v_m_s, a_m_s2, force_n, inertial_force_n,
    /// elastic_force_n, dissipative_force_n; then a specimen's and a closed loop's
    /// columns) to this CSV file; a name ending in .parquet writes Parquet instead (the
    /// same columns, float64, one row per sample).
    #[arg(long, value_parser = usage::OutFile("run.csv"))]
    out: Option<PathBuf>,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write the run's figures to this folder as SVG and PNG: motion and actuator force
    /// over time (with the table's limits near a peak), the force decomposition
    /// F_A = F_I + F_E + F_D, hysteresis loops of F_A against u, v and a; for a closed
    /// loop also command against achieved motion, tracking error, drive and spool,
    /// pressure difference, flow against the valves' capacity, supply pressure.
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    #[command(flatten)]
    size: plot::SizeArgs,
    /// Run at this hold-down pressure, MPa, instead of the scenario's (the model rebuilt
    /// from its preset at P with the scenario's overrides, as `sweep --pressure-mpa`).
    #[arg(long, value_name = "P", allow_negative_numbers = true, value_parser = sweep::parse_pressure_mpa)]
    pressure_mpa: Option<f64>,
}

/// Runs `platen simulate`: the scenario, whatever its table, through
/// [`platen_report::simulate::simulate`].
pub fn run(args: &SimulateArgs) -> Result<()> {
    let path = args.scenario.as_path();
    let mut scenario = Scenario::load(path)?;
    if let Some(p) = args.pressure_mpa {
        scenario = scenario.at_pressure_mpa(path, p)?;
    }
    let outputs = Outputs {
        out: args.out.as_deref(),
        plot: args.plot.as_deref(),
        size: args.size.size(),
    };
    // A bar of the samples written (on a terminal, after a second).
    let progress = Progress::new(
        scenario.samples() as u64,
        "{bar:30} {percent:>3}% of {human_len} samples, {eta} left",
    );
    let tick = Ticker {
        progress: &progress,
        samples: 0,
    };
    let simulated = simulate(&scenario, path, &outputs, tick).map_err(|e| match e {
        SimulateError::Scenario(e) => anyhow::Error::from(e),
        SimulateError::Report(e) => e.into(),
        SimulateError::Io(e) => e.into(),
    })?;
    progress.finish();
    for warning in &simulated.warnings {
        eprintln!("warning: {warning}");
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&simulated.json()?)?);
    } else {
        out!("{}", simulated.text);
    }
    Ok(())
}
