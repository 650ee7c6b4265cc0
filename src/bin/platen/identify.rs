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
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use platen_app::system::{read_system_inputs, SystemRequest};
use platen_app::{declared_record, files, InputError, RecordRequest, RecordSource};
use platen_ident::{
    identify_any, IdentifyOutput, MethodRequest, RecordSettings, Settings, TestRecord,
    ValidRecordSettings, ValidSettings,
};
use platen_io::columns::ColumnMap;
use platen_report::identify_report::{written_text, IdentifyReport};
use platen_report::FigureSize;

use crate::{plot, usage};

/// The arguments of `platen identify`.
#[derive(clap::Args)]
pub struct IdentifyArgs {
    /// Recorded test CSV files.
    #[arg(required_unless_present = "manifest")]
    files: Vec<PathBuf>,
    /// Hold-down pressure, MPa: one value for every file (and for manifest entries without
    /// one), or one per FILE in order (comma separated). Tests without a pressure form
    /// their own group.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, value_parser = parse_pressure_mpa)]
    pressure_mpa: Vec<f64>,
    /// JSON manifest: {"tests": [{"file": PATH, "kind": "sine"|"triangle"|"record",
    /// "pressure_mpa": P, "name": NAME, "columns": MAP, "floors": [{"column": NAME,
    /// "unit": UNIT, "mass_kg": M}]}], "columns": MAP, "floors": FLOORS}, paths relative
    /// to the manifest; floors are a specimen's accelerometers whose base shear Σ mᵢ·aᵢ is
    /// taken off the force.
    #[arg(long)]
    manifest: Option<PathBuf>,
    /// Hold the viscous exponent α at this value (Eq. 21: 0.5) instead of fitting it.
    #[arg(long, value_parser = parse_exponent)]
    viscous_exponent: Option<f64>,
    /// Do not fit the low-velocity term a·e^(−b|v|) (set it to zero).
    #[arg(long)]
    no_low_velocity_term: bool,
    /// Print the seven identified keys, their uncertainties and the per-test tables as
    /// JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write the identification figures to this folder as SVG and PNG: per-test Kₑ and
    /// Mₑ with confidence intervals (Tables I, II), elastic force against displacement,
    /// inertial force against acceleration, dissipative force against velocity with the
    /// fitted law (Fig. 7), Coulomb force against vertical load (Fig. 8).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// Write a self-contained HTML report (parameters, per-test tables, figures) to this
    /// file.
    #[arg(long, value_name = "FILE.html", value_parser = usage::OutFile("report.html"))]
    report: Option<PathBuf>,
    /// JSON file mapping the files' channel names and units to platen's columns, as a
    /// scenario's excitation.columns: {"u_m": {"name": "Table disp", "unit": "mm"}, …}
    /// (a manifest's own `columns` win).
    #[arg(long, value_name = "MAP.json")]
    columns: Option<PathBuf>,
    /// Force the method: `periodic` (the paper's wherever the data are periodic; a file
    /// that is not, or that the paper's method rejects, falls back to the any-record
    /// method with its reason), `record` (the any-record method on every file, fitted
    /// jointly) or `both` (periodic tests through both). Default: periodic tests (regular
    /// cycles of one shape) to the paper's method, any other record (earthquake, white
    /// noise) to the any-record method. Every file is listed with what was done with it.
    #[arg(long, value_enum)]
    method: Option<MethodChoice>,
    /// Skip the any-record method's output-error check (forward simulation fitted to the
    /// measured motion).
    #[arg(long)]
    no_output_error: bool,
    /// Hold the any-record method's stiffness at Kₑ ≥ 0 (a table without a restoring
    /// stiffness of its own); a warning says when the bound is active.
    #[arg(long)]
    nonnegative_stiffness: bool,
    /// Identify the table's whole loop from closed-loop records instead (t_s,
    /// command_u_m, u_m, drive and, as tables record them, delta_p_pa or
    /// cap_pressure_pa and rod_pressure_pa, a_m_s2, storey{i}_a_m_s2): the controller's
    /// gains, the platen, the specimen, the valves and the oil column. The last of two or
    /// more FILEs is held out: the identified loop runs on every record's command and is
    /// judged against a linear black box and perfect tracking (--plot draws it). With
    /// --json, a runnable scenario that is the identified table, each value's provenance.
    #[arg(long, conflicts_with_all = ["manifest", "pressure_mpa", "report", "method"])]
    system: bool,
    /// With --system: the table's geometry from its drawings (actuator count and areas,
    /// valve count and rated drop, supply and return pressures, bulk modulus), as a
    /// scenario with a table_system or a table_system object (e.g. {"preset":
    /// "lhpost-2008", "actuator": {…}}). Without it the plant is identified in ratios to
    /// the actuator area, laid on --area-m2 or a nominal area (listed as assumed).
    #[arg(long, value_name = "FILE.json", requires = "system")]
    base: Option<PathBuf>,
    /// With --system and without --base: the actuator's area, m², when it is known
    /// without the rest of the drawings (the plant's absolute scale).
    #[arg(long, value_name = "M2", requires = "system", conflicts_with = "base")]
    area_m2: Option<f64>,
    /// With --system: keep the equation-error values instead of refining them by the
    /// loop's prediction error (the closed loop run on the fitted records' commands, its
    /// table and storey accelerations fitted to theirs by Levenberg–Marquardt).
    #[arg(long, requires = "system")]
    no_prediction_error: bool,
    #[command(flatten)]
    size: plot::SizeArgs,
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

/// Runs `platen identify`: the table's loop with `--system`, the platen's parameters
/// otherwise.
pub fn run(args: &IdentifyArgs) -> Result<()> {
    let size = args.size.size();
    if args.system {
        run_system(args, &size)
    } else {
        run_records(args, &size)
    }
}

/// `platen identify FILE…`: the platen's parameters from test records.
fn run_records(args: &IdentifyArgs, size: &FigureSize) -> Result<()> {
    let sources = record_request(args)?.sources().map_err(input_error)?;
    let progress = progress_bar(sources.len());
    let records = read_sources(&sources, &progress)?;
    let (settings, record_settings) = settings(args)?;
    // Where each file goes (forced, declared `record`, or by its data), the periodic method
    // on the periodic tests it accepts, the any-record method on the rest: every file
    // accounted for.
    let method = match args.method {
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
    let (plot, html) = (args.plot.as_deref(), args.report.as_deref());
    let written = platen_report::write_outputs(
        plot,
        html,
        size,
        || report.figures(),
        |figures, rendered| report.html(figures, rendered),
    )?;
    if args.json {
        JsonOutput {
            output,
            figures: plot.map(|_| written.iter().map(|p| p.display().to_string()).collect()),
            report: html.map(|path| path.display().to_string()),
        }
        .print()
    } else {
        out!("{}{}", report.text(), written_text(&written, html));
        Ok(())
    }
}

/// The files, pressures, manifest and column map asked for; more than one pressure must
/// be one per file.
fn record_request(args: &IdentifyArgs) -> Result<RecordRequest> {
    let (n, files_given) = (args.pressure_mpa.len(), args.files.len());
    if n > 1 && n != files_given {
        bail!(
            "--pressure-mpa has {n} values for {files_given} files: give one value for all files, or one per file in order"
        );
    }
    Ok(RecordRequest {
        files: args.files.clone(),
        pressures_mpa: args.pressure_mpa.iter().map(|&p| Some(p)).collect(),
        manifest: args.manifest.clone(),
        columns: match &args.columns {
            Some(path) => ColumnMap::load(path)?,
            None => ColumnMap::default(),
        },
    })
}

/// Reads every source, one step of `progress` each (cleared when a file fails).
fn read_sources(sources: &[RecordSource], progress: &ProgressBar) -> Result<Vec<TestRecord>> {
    let mut records = Vec::with_capacity(sources.len());
    for source in sources {
        records.push(source.read().map_err(|e| {
            progress.finish_and_clear();
            input_error(e)
        })?);
        progress.inc(1);
    }
    Ok(records)
}

/// The periodic method's settings and the any-record method's, checked.
fn settings(args: &IdentifyArgs) -> Result<(ValidSettings, ValidRecordSettings)> {
    let settings = Settings {
        viscous_exponent: args.viscous_exponent,
        low_velocity_term: !args.no_low_velocity_term,
        ..Settings::default()
    }
    .build()
    .context("identification failed")?;
    let record_settings = RecordSettings {
        viscous_exponent: args.viscous_exponent,
        low_velocity_term: !args.no_low_velocity_term,
        output_error: !args.no_output_error,
        nonnegative_stiffness: args.nonnegative_stiffness,
        ..RecordSettings::default()
    }
    .build()
    .context("identification failed")?;
    Ok((settings, record_settings))
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

/// `platen identify --system FILE…`: the table's loop from closed-loop records (see
/// `platen_ident::system`). Which records are fitted and which held out is
/// [`platen_app::system`]'s (with two or more files, the last is held out); the identified
/// loop is judged on every record. Prints the identification and, with `--json`, a runnable
/// scenario that is the identified table with each value's provenance.
fn run_system(args: &IdentifyArgs, size: &FigureSize) -> Result<()> {
    use platen_ident::system::{identify_system, SystemSettings};
    use platen_report::system_identify_report::{
        identified_system_text, prediction_figures, system_json,
    };
    if args.files.is_empty() {
        return Err(input_error(InputError::NoSystemFiles));
    }
    let map = match &args.columns {
        Some(path) => ColumnMap::load(path)?,
        None => ColumnMap::default(),
    };
    let request = SystemRequest {
        files: args.files.clone(),
        columns: map,
        base: args.base.clone(),
    };
    let inputs = read_system_inputs(&request).map_err(input_error)?;
    let settings = SystemSettings {
        base: inputs.base,
        area_m2: args.area_m2,
        judge: true,
        prediction_error: !args.no_prediction_error,
        ..SystemSettings::default()
    };
    let id = identify_system(&inputs.records, &inputs.fit, &settings)?;
    let written = platen_report::render::write_outputs(
        args.plot.as_deref(),
        None,
        size,
        || prediction_figures(&id),
        |_, _| String::new(),
    )?;
    if args.json {
        let held = inputs.commanding;
        let mut value = system_json(
            &id,
            &inputs.records[held],
            &inputs.commanding_path(),
            &request.columns,
            inputs.base_stroke_m,
        );
        if args.plot.is_some() {
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
