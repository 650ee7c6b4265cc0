//! `platen identify`: the platen's parameters from periodic sine and triangle tests (the
//! paper's hysteresis-loop method, §3, with its fits and a global fit as a cross-check) and
//! from any other record (earthquake, white noise: the any-record method of
//! [`platen_ident::identify_records`]). Each file is routed by its data
//! ([`platen_ident::route`]); `--method periodic|record|both` forces the method.
//! When every file is periodic and no method is forced, the output is the periodic method's
//! alone, as before.
//!
//! The records are read by [`platen_app`] (files, `--columns`, a manifest with kinds,
//! pressures, column maps, a specimen's `floors` and scenario entries; for `--system`, the
//! closed-loop records, the base and which record is held out), identified by
//! [`platen_ident::identify_any`] (or [`platen_ident::system::identify_system`]) and reported
//! by [`platen_report::identify_report`]; this file turns the arguments into a request and
//! prints or writes what comes back.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use platen_app::system::{read_system_inputs, SystemRequest};
use platen_app::{declared_record, files, InputError, RecordRequest};
use platen_ident::{identify_any, IdentifyOutput, MethodRequest, RecordSettings, Settings};
use platen_io::columns::ColumnMap;
use platen_report::identify_report::{written_text, IdentifyReport};

/// Options of `platen identify`.
pub struct Options<'a> {
    pub files: &'a [PathBuf],
    pub pressure_mpa: &'a [f64],
    pub manifest: Option<&'a Path>,
    pub viscous_exponent: Option<f64>,
    pub no_low_velocity_term: bool,
    pub json: bool,
    /// Folder for the figures (SVG and PNG).
    pub plot: Option<&'a Path>,
    /// Self-contained HTML report.
    pub report: Option<&'a Path>,
    /// Size of the figures.
    pub size: platen_report::FigureSize,
    /// JSON file mapping the files' own channel names and units to platen's columns.
    pub columns: Option<&'a Path>,
    /// The method forced on every file (`None`: each file by its data).
    pub method: Option<MethodChoice>,
    /// Skip the any-record method's output-error check.
    pub no_output_error: bool,
    /// Hold the any-record method's stiffness at `Kₑ ≥ 0`.
    pub nonnegative_stiffness: bool,
}

/// `--method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodChoice {
    /// The paper's hysteresis-loop method on every file (each must be a periodic test).
    Periodic,
    /// The any-record method on every file, fitted jointly.
    Record,
    /// Periodic tests through both methods, the rest through the any-record method (every
    /// file enters the any-record fit).
    Both,
}

/// Checks a `--pressure-mpa` value: finite, ≥ 0 and at most 100 MPa (a larger one is a
/// pressure in another unit: [`platen_scenario::units::check_pressure_mpa`]).
pub fn parse_pressure_mpa(s: &str) -> Result<f64, String> {
    let p: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    platen_scenario::units::check_pressure_mpa(p)
}

/// Checks a `--viscous-exponent` value: in [0, 1].
pub fn parse_exponent(s: &str) -> Result<f64, String> {
    let a: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if a.is_finite() && (0.0..=1.0).contains(&a) {
        Ok(a)
    } else {
        Err(format!("{a}: expected an exponent in [0, 1]"))
    }
}

/// Runs `platen identify`.
pub fn run(opts: &Options) -> Result<()> {
    let (n, files_given) = (opts.pressure_mpa.len(), opts.files.len());
    if n > 1 && n != files_given {
        bail!(
            "--pressure-mpa has {n} values for {files_given} files: give one value for all files, or one per file in order"
        );
    }
    let request = RecordRequest {
        files: opts.files.to_vec(),
        pressures_mpa: opts.pressure_mpa.iter().map(|&p| Some(p)).collect(),
        manifest: opts.manifest.map(Path::to_path_buf),
        columns: match opts.columns {
            Some(path) => ColumnMap::load(path)?,
            None => ColumnMap::default(),
        },
    };
    let sources = request.sources().map_err(input_error)?;
    let progress = progress_bar(sources.len());
    let mut records = Vec::with_capacity(sources.len());
    for source in &sources {
        records.push(source.read().map_err(|e| {
            progress.finish_and_clear();
            input_error(e)
        })?);
        progress.inc(1);
    }
    let settings = Settings {
        viscous_exponent: opts.viscous_exponent,
        low_velocity_term: !opts.no_low_velocity_term,
        ..Settings::default()
    }
    .build()
    .context("identification failed")?;
    let record_settings = RecordSettings {
        viscous_exponent: opts.viscous_exponent,
        low_velocity_term: !opts.no_low_velocity_term,
        output_error: !opts.no_output_error,
        nonnegative_stiffness: opts.nonnegative_stiffness,
        ..RecordSettings::default()
    }
    .build()
    .context("identification failed")?;
    // Where each file goes (forced, declared `record`, or by its data), the periodic method
    // on the periodic tests it accepts, the any-record method on the rest: every file
    // accounted for.
    let method = match opts.method {
        None => MethodRequest::Auto,
        Some(MethodChoice::Periodic) => MethodRequest::Periodic,
        Some(MethodChoice::Record) => MethodRequest::Record,
        Some(MethodChoice::Both) => MethodRequest::Both,
    };
    progress.set_message("identifying");
    let declared = declared_record(&sources);
    let id = identify_any(&records, &declared, method, &settings, &record_settings);
    progress.finish_and_clear();
    let id = id.context("identification failed")?;
    let report = IdentifyReport {
        identified: &id,
        sources: &sources,
        records: &records,
    };
    for warning in report.unused() {
        eprintln!("warning: {warning}");
    }
    let output = id.output(&records, &files(&sources), method);
    let written = platen_report::write_outputs(
        opts.plot,
        opts.report,
        &opts.size,
        || report.figures(),
        |figures, rendered| report.html(figures, rendered),
    )?;
    if opts.json {
        JsonOutput {
            output,
            figures: opts
                .plot
                .map(|_| written.iter().map(|p| p.display().to_string()).collect()),
            report: opts.report.map(|path| path.display().to_string()),
        }
        .print()
    } else {
        out!("{}{}", report.text(), written_text(&written, opts.report));
        Ok(())
    }
}

/// A reading error as the CLI reports it: a file's or a scenario's own error stays itself
/// (its exit code and `--json` error object name the file, field and line).
fn input_error(e: InputError) -> anyhow::Error {
    match e {
        InputError::Io(io) => io.into(),
        InputError::Scenario(se) => se.into(),
        other => other.into(),
    }
}

/// A progress bar on stderr while records are read and identified: only when stderr is a
/// terminal (and `CI` is not set), and only once the run has lasted a second.
fn progress_bar(records: usize) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(records as u64), ProgressDrawTarget::hidden());
    if !std::io::stderr().is_terminal() || std::env::var_os("CI").is_some() {
        return bar;
    }
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} {bar:40} {pos}/{len} records {msg}  {elapsed}")
    {
        bar.set_style(style);
    }
    bar.set_message("read");
    let shown = bar.clone();
    std::thread::spawn(move || {
        std::thread::sleep(Duration::from_secs(1));
        if !shown.is_finished() {
            shown.set_draw_target(ProgressDrawTarget::stderr());
            shown.enable_steady_tick(Duration::from_millis(120));
        }
    });
    bar
}

/// What `--json` prints: the identification's output ([`platen_ident::Identified::output`])
/// and the files written.
#[derive(Serialize)]
struct JsonOutput {
    #[serde(flatten)]
    output: IdentifyOutput,
    #[serde(skip_serializing_if = "Option::is_none")]
    figures: Option<Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    report: Option<String>,
}

impl JsonOutput {
    fn print(self) -> Result<()> {
        // Through a `Value`, whose maps sort their keys at every level (the contract's order).
        let value = serde_json::to_value(&self)?;
        outln!("{}", serde_json::to_string_pretty(&value)?);
        Ok(())
    }
}

/// The options of `platen identify --system`.
pub struct SystemOptions<'a> {
    /// The column map.
    pub columns: Option<&'a Path>,
    /// The base geometry (`--base`).
    pub base: Option<&'a Path>,
    /// The actuator area alone (`--area-m2`).
    pub area_m2: Option<f64>,
    /// `--json`.
    pub json: bool,
    /// `--plot DIR`.
    pub plot: Option<&'a Path>,
    /// The figures' size.
    pub size: platen_report::render::FigureSize,
}

/// `platen identify --system FILE…`: the table's loop from closed-loop records (see
/// `platen_ident::system`). Which records are fitted and which held out is
/// [`platen_app::system`]'s (with two or more files, the last is held out); the identified
/// loop is judged on every record. Prints the identification and, with `--json`, a runnable
/// scenario that is the identified table with each value's provenance.
pub fn run_system(files: &[PathBuf], o: &SystemOptions<'_>) -> Result<()> {
    use platen_ident::system::{identify_system, SystemSettings};
    use platen_report::system_identify_report::{
        identified_system_text, prediction_figures, system_json,
    };
    if files.is_empty() {
        return Err(input_error(InputError::NoSystemFiles));
    }
    let map = match o.columns {
        Some(path) => ColumnMap::load(path)?,
        None => ColumnMap::default(),
    };
    let request = SystemRequest {
        files: files.to_vec(),
        columns: map,
        base: o.base.map(Path::to_path_buf),
    };
    let inputs = read_system_inputs(&request).map_err(input_error)?;
    let settings = SystemSettings {
        base: inputs.base,
        area_m2: o.area_m2,
        judge: true,
        ..SystemSettings::default()
    };
    let id = identify_system(&inputs.records, &inputs.fit, &settings)?;
    let written = platen_report::render::write_outputs(
        o.plot,
        None,
        &o.size,
        || prediction_figures(&id),
        |_, _| String::new(),
    )?;
    if o.json {
        let held = inputs.commanding;
        let mut value = system_json(
            &id,
            &inputs.records[held],
            &inputs.commanding_path(),
            &request.columns,
            inputs.base_stroke_m,
        );
        if o.plot.is_some() {
            value["figures"] = written
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .into();
        }
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        outln!("{}", identified_system_text(&id).trim_end());
        let w = written_text(&written, None);
        if !w.is_empty() {
            outln!("{}", w.trim_end());
        }
    }
    Ok(())
}
