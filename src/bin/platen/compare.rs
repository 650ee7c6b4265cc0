//! `platen compare`: run a scenario and compare it with a recorded test, channel by channel,
//! with the figures and the HTML report an engineer puts in a report.
//!
//! The comparison is [`platen_compare::Comparison`]; the figures, the page and the terminal
//! summary are [`platen_report`]'s. This file parses the options and prints.

use std::path::Path;

use anyhow::Result;

use platen_compare::{Comparison, Settings};
use platen_report::{compare_figures, html, text};

pub use platen_compare::Window;

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

/// The options of `platen compare`.
pub struct Options<'a> {
    /// Scenario JSON file.
    pub scenario: &'a Path,
    /// Recorded CSV file.
    pub recorded: &'a Path,
    /// Print JSON on stdout.
    pub json: bool,
    /// Folder for the SVG figures.
    pub plot: Option<&'a Path>,
    /// Metrics window.
    pub window: Option<Window>,
    /// HTML report file.
    pub report: Option<&'a Path>,
    /// Lag search bound, s.
    pub max_lag_s: f64,
    /// JSON file mapping the record's own channel names and units to platen's columns.
    pub columns: Option<&'a Path>,
    /// Size of the figures.
    pub size: platen_report::FigureSize,
}

/// Runs `platen compare`.
pub fn run(options: &Options<'_>) -> Result<()> {
    let settings = Settings {
        window: options.window,
        max_lag_s: options.max_lag_s,
    };
    let comparison = Comparison::from_files(
        options.scenario,
        options.recorded,
        options.columns,
        &settings,
    )?;
    let written = platen_report::write_outputs(
        options.plot,
        options.report,
        &options.size,
        || compare_figures::figures(&comparison),
        |figures, rendered| html::compare_page(&comparison, figures, rendered),
    )?;
    if options.json {
        // The text summary lists them; with --json they also go to stderr, as simulate's.
        for warning in comparison.warnings() {
            eprintln!("warning: {warning}");
        }
        let summary = comparison.summary(&written, options.report);
        let summary = serde_json::to_value(&summary)?;
        outln!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        out!(
            "{}",
            text::compare_summary(&comparison, &written, options.report)
        );
    }
    Ok(())
}
