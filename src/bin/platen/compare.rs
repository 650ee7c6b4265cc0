//! `platen compare`: run a scenario and compare it with a recorded test, channel by channel,
//! with the figures and the HTML report an engineer puts in a report.
//!
//! The comparison is [`platen_compare::Comparison`]; the figures, the page and the terminal
//! summary are [`platen_report`]'s. This file parses the options and prints.

use std::path::PathBuf;

use anyhow::Result;

use platen_compare::{Comparison, Settings};
use platen_report::{compare_figures, html, text};

pub use platen_compare::Window;

use crate::{plot, usage};

/// Parses `--window T0,T1`.
pub fn parse_window(text: &str) -> Result<Window, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [a, b] = parts.as_slice() else {
        return Err(format!(
            "`{text}`: expected two times in seconds, T0,T1 (for example 4,8)"
        ));
    };
    let parse = |s: &str| {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{s}` is not a finite time in seconds"))
    };
    let (t0, t1) = (parse(a)?, parse(b)?);
    if t1 <= t0 {
        return Err(format!(
            "`{text}`: the window must end after it starts (T0 < T1)"
        ));
    }
    Ok(Window {
        start_s: t0,
        end_s: t1,
    })
}

/// Parses `--max-lag S`.
pub fn parse_max_lag(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("`{text}`: expected a duration in seconds, >= 0")),
    }
}

/// The arguments of `platen compare`.
#[derive(clap::Args)]
pub struct CompareArgs {
    /// Scenario JSON file.
    scenario: PathBuf,
    /// Recorded CSV file (t_s and u_m, v_m_s for a forward run, force_n for an inverse
    /// one; a_m_s2 and the other columns are used by the figures where present). It must
    /// be uniformly sampled and cover the scenario's time span.
    #[arg(long, value_name = "REC.csv")]
    recorded: PathBuf,
    /// Print the metrics as JSON (one object per channel: u_m, v_m_s or force_n).
    #[arg(long)]
    pub json: bool,
    /// Write the figures to this folder as SVG and PNG (time histories with a zoom, residuals,
    /// hysteresis loops, dissipative force against velocity with the model's law).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// Compute the metrics over this time window only, s (also the zoomed interval).
    #[arg(long, value_name = "T0,T1", allow_hyphen_values = true, value_parser = parse_window)]
    window: Option<Window>,
    /// Write a self-contained HTML report (metrics table and figures) to this file.
    #[arg(long, value_name = "FILE.html", value_parser = usage::OutFile("report.html"))]
    report: Option<PathBuf>,
    /// JSON file mapping the record's channel names and units to platen's columns, as a
    /// scenario's excitation.columns: {"u_m": {"name": "Table disp", "unit": "mm"}, …}.
    #[arg(long, value_name = "MAP.json")]
    columns: Option<PathBuf>,
    /// Largest lag searched by cross-correlation, either way, s.
    #[arg(long, value_name = "S", default_value_t = 0.25, value_parser = parse_max_lag)]
    max_lag: f64,
    #[command(flatten)]
    size: plot::SizeArgs,
}

/// Runs `platen compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    let size = args.size.size();
    let (plot, report) = (args.plot.as_deref(), args.report.as_deref());
    let settings = Settings {
        window: args.window,
        max_lag_s: args.max_lag,
    };
    let comparison = Comparison::from_files(
        &args.scenario,
        &args.recorded,
        args.columns.as_deref(),
        &settings,
    )?;
    let written = platen_report::write_outputs(
        plot,
        report,
        &size,
        || compare_figures::figures(&comparison),
        |figures, rendered| html::compare_page(&comparison, figures, rendered),
    )?;
    if args.json {
        // The text summary lists them; with --json they also go to stderr, as simulate's.
        for warning in comparison.warnings() {
            eprintln!("warning: {warning}");
        }
        let summary = comparison.summary(&written, report);
        let summary = serde_json::to_value(&summary)?;
        outln!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        out!("{}", text::compare_summary(&comparison, &written, report));
    }
    Ok(())
}
