//! `platen simulate`: run a scenario, stream its time series to CSV, summarise it.
//!
//! The CSV is written as the samples are produced ([`CsvSink`]), to a temporary file next to
//! the target that is renamed over it when the run is complete and removed if it fails, so a
//! one-hour 1024 Hz run holds no trajectory in memory.

use std::path::Path;

use anyhow::{Context, Result};

use platen_report::simulate_report::with_outputs;
use platen_report::{run_figures, run_figures::RunRecorder, FigureSize};
use platen_scenario::{CsvSink, Run, RunSummary, Scenario};

use crate::progress::{Progress, Ticker};

/// The options of `platen simulate`.
pub struct Options<'a> {
    /// Scenario JSON file.
    pub scenario: &'a Path,
    /// CSV file for the time series.
    pub out: Option<&'a Path>,
    /// Print JSON on stdout.
    pub json: bool,
    /// Folder for the figures (SVG and PNG).
    pub plot: Option<&'a Path>,
    /// Size of the figures.
    pub size: FigureSize,
    /// The hold-down pressure to run at, MPa, instead of the scenario's.
    pub pressure_mpa: Option<f64>,
}

pub fn run(opts: &Options<'_>) -> Result<()> {
    let (path, out) = (opts.scenario, opts.out);
    let mut scenario = Scenario::load(path)?;
    if let Some(p) = opts.pressure_mpa {
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
    let mut recorder = opts.plot.map(|_| RunRecorder::new(&scenario.run));
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
            opts.plot,
            None,
            &opts.size,
            || run_figures::figures(recorder, &scenario),
            |_, _| String::new(),
        )?,
        None => Vec::new(),
    };
    let summary = RunSummary::new(path, &scenario, &output, out);
    for warning in &summary.warnings {
        eprintln!("warning: {warning}");
    }
    if opts.json {
        // Through a Value, so the keys come out in alphabetical order.
        let figures = opts.plot.map(|_| written.as_slice());
        let value = with_outputs(serde_json::to_value(&summary)?, figures, None);
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        let text =
            platen_report::simulate_report::text(&scenario, &output, &summary, out, &written);
        out!("{text}");
    }
    Ok(())
}
