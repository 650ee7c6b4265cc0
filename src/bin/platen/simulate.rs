//! `platen simulate`: run a scenario, stream its time series to CSV, summarise it.
//!
//! The CSV is written as the samples are produced ([`CsvSink`]), to a temporary file next to
//! the target that is renamed over it when the run is complete and removed if it fails, so a
//! one-hour 1024 Hz run holds no trajectory in memory.

use std::path::PathBuf;

use anyhow::{Context, Result};

use platen_report::simulate_report::with_outputs;
use platen_report::{run_figures, run_figures::RunRecorder};
use platen_scenario::file::ScenarioFile;
use platen_scenario::multi_axis::TableScenario;
use platen_scenario::{CsvSink, Run, RunSummary, Scenario};

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

/// Runs `platen simulate`.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let size = args.size.size();
    let (path, out) = (args.scenario.as_path(), args.out.as_deref());
    let plot = args.plot.as_deref();
    let file: ScenarioFile = platen_io::json::parse_json_file(path)?;
    if file.table.is_some() {
        return run_table(args, path, &file);
    }
    let mut scenario = Scenario::from_file(path, file)?;
    if let Some(p) = args.pressure_mpa {
        scenario = scenario
            .at_pressure(p * 1e6)
            .with_context(|| format!("`{}`: the model at --pressure-mpa {p}", path.display()))?;
    }
    // Create the temporary output first, so that an unwritable path fails before the run.
    let storeys = scenario.storeys();
    let mut stream = out
        .map(|p| {
            let closed_loop = matches!(scenario.run, Run::ClosedLoop { .. });
            CsvSink::create_for(p, storeys, closed_loop)
        })
        .transpose()?;
    // The figures' points are collected as the run goes, in memory that does not grow with it.
    let mut recorder = plot.map(|_| RunRecorder::new(&scenario.run));
    // A bar of the samples written (on a terminal, after a second).
    let expected = scenario.run.samples();
    let progress = Progress::new(
        expected as u64,
        "{bar:30} {percent:>3}% of {human_len} samples, {eta} left",
    );
    let tick = Ticker {
        progress: &progress,
        samples: 0,
    };
    let output = match (stream.as_mut(), recorder.as_mut()) {
        (Some(sink), Some(rec)) => scenario.run(&mut ((sink, rec), tick))?,
        (Some(sink), None) => scenario.run(&mut (sink, tick))?,
        (None, Some(rec)) => scenario.run(&mut (rec, tick))?,
        (None, None) => scenario.run(&mut { tick })?,
    };
    progress.finish();
    if let Some(stream) = stream {
        stream.finish()?;
    }
    let written = match recorder {
        Some(recorder) => platen_report::write_outputs(
            plot,
            None,
            &size,
            || run_figures::figures(recorder, &scenario),
            |_, _| String::new(),
        )?,
        None => Vec::new(),
    };
    let summary = RunSummary::new(path, &scenario, &output, out);
    for warning in &summary.warnings {
        eprintln!("warning: {warning}");
    }
    if args.json {
        // Through a Value, so the keys come out in alphabetical order.
        let figures = plot.map(|_| written.as_slice());
        let value = with_outputs(serde_json::to_value(&summary)?, figures, None);
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        let text =
            platen_report::simulate_report::text(&scenario, &output, &summary, out, &written);
        out!("{text}");
    }
    Ok(())
}

/// `platen simulate` on a scenario of a multi-axis table: the run's columns to `--out`, its
/// summary, and (with `--plot`) its figures.
fn run_table(args: &SimulateArgs, path: &std::path::Path, file: &ScenarioFile) -> Result<()> {
    if args.pressure_mpa.is_some() {
        anyhow::bail!(
            "`{}`: --pressure-mpa sets the uniaxial platen's hold-down pressure; a multi-axis \
             table's struts carry theirs in `table.hold_down_struts[].pressure_pa`",
            path.display()
        );
    }
    let scenario = TableScenario::from_file(path, file)?;
    let (run, stats) = scenario.run_with_stats()?;
    let out = args.out.as_deref();
    if let Some(out) = out {
        let header: Vec<&str> = run.columns.iter().map(|(n, _)| n.as_str()).collect();
        let columns: Vec<&[f64]> = run.columns.iter().map(|(_, c)| c.as_slice()).collect();
        platen_io::parquet::write_columns_atomic(out, &header, &columns)?;
    }
    let written = match args.plot.as_deref() {
        Some(dir) => platen_report::table_figures::write_table_figures(
            &run,
            &scenario.table,
            Some(&scenario.force_limits_n()),
            scenario.flow_capacities_m3_s().as_deref(),
            dir,
            args.size.size(),
        )?,
        None => Vec::new(),
    };
    let summary = scenario.summary_with(&run, stats.as_ref(), out);
    crate::plot::print(args.json, args.plot.is_some(), &summary, &written, || {
        platen_scenario::multi_axis::summary_text(&summary, &written)
    })
}
