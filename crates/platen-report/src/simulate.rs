//! `platen simulate` for any scenario: [`simulate`] runs a [`Scenario`] — the uniaxial
//! platen's or a multi-axis table's — into its outputs (the time series as CSV or Parquet,
//! the figures) and reports it (its [`Summary`], as JSON or text). The front ends call this
//! and do not tell the tables apart.
//!
//! Every run streams, whatever its table: its samples go to the output file as they are
//! produced (to a temporary file, created before the run, renamed over the target when the
//! run is complete, removed if it fails), and the figures' points and the summary's figures
//! are gathered as it goes, in memory that does not grow with the run (a uniaxial run's
//! [`RunRecorder`] and `Tracking`, a multi-axis run's [`TableRecorder`] and [`TablePeaks`]).

use std::path::{Path, PathBuf};

use platen_integrate::{SampleSink, TableSink};
use platen_io::IoError;
use platen_scenario::multi_axis::{TablePeaks, TableScenario};
use platen_scenario::{CsvSink, PlatenScenario, Run, RunSummary, Scenario, ScenarioError, Summary};

use crate::error::ReportError;
use crate::render::FigureSize;
use crate::run_figures::{self, RunRecorder};
use crate::simulate_report::with_outputs;
use crate::table_figures::{self, TableRecorder};

/// Where [`simulate`] writes a run.
#[derive(Debug, Clone, Copy)]
pub struct Outputs<'a> {
    /// The time series (CSV; a name ending in `.parquet` writes Parquet), if any.
    pub out: Option<&'a Path>,
    /// The folder of the figures (SVG and PNG), if any.
    pub plot: Option<&'a Path>,
    /// The figures' size.
    pub size: FigureSize,
}

/// Why [`simulate`] failed: the scenario's run, writing its time series, or its figures.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    /// The run (or creating its output file before it).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The figures.
    #[error(transparent)]
    Report(#[from] ReportError),
    /// Writing the time series.
    #[error(transparent)]
    Io(#[from] IoError),
}

/// A run as `platen simulate` reports it.
#[derive(Debug, Clone)]
pub struct Simulated {
    /// Its summary.
    pub summary: Summary,
    /// The figure files written (none without [`Outputs::plot`]).
    pub figures: Vec<PathBuf>,
    /// Whether figures were asked for (the JSON then lists them, even none).
    plotted: bool,
    /// The text summary.
    pub text: String,
    /// The warnings to print apart from the text (a uniaxial run's; a multi-axis run's text
    /// carries its own).
    pub warnings: Vec<String>,
}

impl Simulated {
    /// The summary as `platen simulate --json` prints it: its keys in alphabetical order,
    /// with `figures` when figures were asked for.
    ///
    /// # Errors
    /// A summary that cannot be serialised (a non-string map key; none of platen's).
    pub fn json(&self) -> serde_json::Result<serde_json::Value> {
        let figures = self.plotted.then_some(self.figures.as_slice());
        Ok(with_outputs(
            serde_json::to_value(&self.summary)?,
            figures,
            None,
        ))
    }
}

/// Runs `scenario` (read from `path`) into `outputs`, delivering its samples (a uniaxial
/// run's) or rows (a multi-axis run's) to `tick` too (a progress bar), and reports it.
///
/// # Errors
/// [`SimulateError`]: an output that cannot be created (before the run), the run's failure,
/// a value that cannot be written, a figure that cannot be drawn. Nothing is left half
/// written.
pub fn simulate<T: SampleSink + TableSink>(
    scenario: &Scenario,
    path: &Path,
    outputs: &Outputs<'_>,
    tick: T,
) -> Result<Simulated, SimulateError> {
    match scenario {
        Scenario::Platen(s) => simulate_platen(s, path, outputs, tick),
        Scenario::Table(s) => simulate_table(s, outputs, tick),
    }
}

/// [`simulate`] on the uniaxial platen: streamed.
fn simulate_platen<T: SampleSink>(
    scenario: &PlatenScenario,
    path: &Path,
    outputs: &Outputs<'_>,
    tick: T,
) -> Result<Simulated, SimulateError> {
    let Outputs { out, plot, size } = *outputs;
    // Create the temporary output first, so that an unwritable path fails before the run.
    let storeys = scenario.storeys();
    let mut stream = out
        .map(|p| {
            let closed_loop = matches!(scenario.run, Run::ClosedLoop { .. });
            let hysteretic = scenario
                .rig
                .specimen
                .as_ref()
                .is_some_and(|s| s.is_hysteretic());
            CsvSink::create_for_specimen(p, storeys, hysteretic, closed_loop)
        })
        .transpose()?;
    // The figures' points are collected as the run goes, in memory that does not grow with it.
    let mut recorder = plot.map(|_| RunRecorder::new(&scenario.run));
    let mut tick = tick;
    let output = match (stream.as_mut(), recorder.as_mut()) {
        (Some(sink), Some(rec)) => scenario.run(&mut ((sink, rec), &mut tick))?,
        (Some(sink), None) => scenario.run(&mut (sink, &mut tick))?,
        (None, Some(rec)) => scenario.run(&mut (rec, &mut tick))?,
        (None, None) => scenario.run(&mut tick)?,
    };
    if let Some(stream) = stream {
        stream.finish()?;
    }
    let figures = match recorder {
        Some(recorder) => crate::write_outputs(
            plot,
            None,
            &size,
            || run_figures::figures(recorder, scenario),
            |_, _| String::new(),
        )?,
        None => Vec::new(),
    };
    let summary = RunSummary::new(path, scenario, &output, out);
    let text = crate::simulate_report::text(scenario, &output, &summary, out, &figures);
    Ok(Simulated {
        warnings: summary.warnings.clone(),
        summary: Summary::Platen(Box::new(summary)),
        figures,
        plotted: plot.is_some(),
        text,
    })
}

/// [`simulate`] on a multi-axis table: streamed.
fn simulate_table<T: TableSink>(
    scenario: &TableScenario,
    outputs: &Outputs<'_>,
    tick: T,
) -> Result<Simulated, SimulateError> {
    let Outputs { out, plot, size } = *outputs;
    // Create the temporary output first, so that an unwritable path fails before the run.
    let mut stream = out
        .map(|p| CsvSink::create_named(p, &scenario.columns()))
        .transpose()?;
    let mut recorder = plot.map(|_| TableRecorder::new(scenario.output_t_s()));
    let mut peaks = TablePeaks::new(scenario);
    let mut tick = tick;
    let sinks = (&mut tick, (stream.as_mut(), recorder.as_mut()));
    let stats = scenario.run_into(&mut (&mut peaks, sinks))?;
    if let Some(stream) = stream {
        stream.finish()?;
    }
    let figures = match (plot, recorder) {
        (Some(dir), Some(recorder)) => table_figures::write_recorded_figures(
            recorder,
            &scenario.table,
            Some(&scenario.force_limits_n()),
            scenario.flow_capacities_m3_s().as_deref(),
            dir,
            size,
        )?,
        _ => Vec::new(),
    };
    let summary = scenario.summary_of(&peaks, stats.as_ref(), out);
    let text = crate::table_text::summary_text(&summary, &figures);
    Ok(Simulated {
        summary: Summary::Table(Box::new(summary)),
        figures,
        plotted: plot.is_some(),
        text,
        warnings: Vec::new(),
    })
}
