//! `platen identify`: the platen's parameters from periodic sine and triangle tests (the
//! paper's hysteresis-loop method, §3, with its fits and a global fit as a cross-check) and
//! from any other record (earthquake, white noise: the any-record method of
//! [`platen_ident::identify_records`]). Each file is routed by its data
//! ([`platen_ident::route`]); `--method periodic|record|both` forces the method.
//! When every file is periodic and no method is forced, the output is the periodic method's
//! alone, as before.
//!
//! A manifest entry's `kind` may also be `record` (the any-record method whatever the
//! data), and `floors` (top level, or per entry) lists a specimen's floor accelerometers
//! with their storey masses, whose base shear `Σ mᵢ·aᵢ` is taken off the force:
//! `"floors": [{"column": "Floor 1 Acc", "unit": "mm/s2", "mass_kg": 14000}, …]`.
//!
//! Input: recorded CSVs with `t_s`, `u_m`, `a_m_s2`, `force_n` and optionally `v_m_s`. Whether
//! a test is a sine or a triangle is recognised from its data, and file names play no part;
//! a manifest may say it, and the hold-down pressure, per file:
//!
//! ```json
//! { "tests": [ { "file": "run-017.csv", "kind": "triangle", "pressure_mpa": 13.8 } ] }
//! ```
//!
//! (`file` relative to the manifest; `kind` `sine` or `triangle`; every key but `file`
//! optional). Files listed only in the manifest are identified too.
//!
//! An entry may name a motion scenario instead of a file, `{ "scenario": "13.8MPa/S9.json",
//! "seed": 9 }`: its recorded-like data are made in memory exactly as `platen generate
//! recorded --seed 9` writes them (the same numbers as identifying that CSV), and its
//! hold-down pressure is the scenario's. `scenarios/paper-tests/manifest.json` lists the
//! paper's whole programme this way.
//!
//! A data system's own channel names and units are mapped to platen's columns with the
//! `columns` object of the scenario format ([`platen_scenario::columns`]): `--columns
//! MAP.json` for every file, a manifest's top-level `columns` for the files it lists, or an
//! entry's own `columns`, the most specific winning.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use platen_ident::anyrecord::summary::{record_entries, RecordInfoSummary, RecordSummary};
use platen_ident::{
    identify_any, Estimate, Flag, Identification, IdentificationSummary, Identified, IdentifiedKey,
    IdentifyOutput, MethodRequest, Parameter, RecordIdentification, RecordSettings, Settings,
    TestKind, TestRecord,
};
use platen_io::columns::{ColumnMap, ColumnSpec};
use platen_io::json::parse_json_file;
use platen_scenario::sampling::uniform_step_s;

use platen_report::{html, identify_figures, record_figures, Figure};

use crate::generate;

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

/// The manifest file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    tests: Vec<ManifestEntry>,
    /// Channel names and units of every listed file (an entry's own `columns` wins).
    #[serde(default)]
    columns: Option<BTreeMap<String, ColumnSpec>>,
    /// Floor accelerometers of every listed file (an entry's own `floors` wins).
    #[serde(default)]
    floors: Option<Vec<FloorSpec>>,
}

/// A specimen floor's accelerometer and its storey mass.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct FloorSpec {
    /// The column's header.
    column: String,
    /// Its unit (default m/s2).
    #[serde(default)]
    unit: Option<String>,
    /// The storey's mass, kg.
    mass_kg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ManifestEntry {
    /// A recorded CSV (this or `scenario`).
    #[serde(default)]
    file: Option<PathBuf>,
    /// A motion scenario whose recorded-like data are identified (this or `file`).
    #[serde(default)]
    scenario: Option<PathBuf>,
    /// The noise seed of a `scenario` entry's recorded-like data (default 1, as `generate`).
    #[serde(default)]
    seed: Option<u64>,
    #[serde(default)]
    kind: Option<KindName>,
    #[serde(default)]
    pressure_mpa: Option<f64>,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    columns: Option<BTreeMap<String, ColumnSpec>>,
    #[serde(default)]
    floors: Option<Vec<FloorSpec>>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum KindName {
    Sine,
    Triangle,
    Record,
}

/// One input file with what is known about it.
#[derive(Clone)]
struct Input {
    path: PathBuf,
    /// The test's name in messages (the path as given, or the manifest's name).
    name: String,
    /// The name in the report's tables (the file name, or the manifest's name).
    label: String,
    kind: Option<TestKind>,
    pressure_mpa: Option<f64>,
    /// How the file's channels map to platen's columns.
    columns: ColumnMap,
    /// Declared `kind: record` in the manifest.
    record: bool,
    /// The specimen's floor accelerometers.
    floors: Vec<FloorSpec>,
    /// `Some(seed)`: `path` is a motion scenario whose recorded-like data (with this seed)
    /// are identified, made in memory ([`generate::recorded_of`]).
    generated_seed: Option<u64>,
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
    let inputs = inputs(opts)?;
    let mut records = Vec::with_capacity(inputs.len());
    for input in &inputs {
        records.push(read_record(input)?);
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
    let declared: Vec<bool> = inputs.iter().map(|i| i.record).collect();
    let request = match opts.method {
        None => MethodRequest::Auto,
        Some(MethodChoice::Periodic) => MethodRequest::Periodic,
        Some(MethodChoice::Record) => MethodRequest::Record,
        Some(MethodChoice::Both) => MethodRequest::Both,
    };
    let id = identify_any(&records, &declared, request, &settings, &record_settings)
        .context("identification failed")?;
    let files: Vec<String> = inputs
        .iter()
        .map(|i| i.path.display().to_string())
        .collect();
    let entries = record_entries(&id, &records, &files);
    for (e, input) in entries.iter().zip(&inputs) {
        if let Some(reason) = e.account.as_ref().and_then(|a| a.reason.as_ref()) {
            eprintln!("warning: {} was not used: {reason}", input.name);
        }
    }
    let output = id.output(&records, &files, request);
    match id {
        Identified {
            records: Some((rid, record_idx)),
            periodic,
            ..
        } => run_records(
            opts,
            &inputs,
            (&rid, &record_idx),
            periodic,
            &entries,
            output,
        ),
        Identified {
            periodic: Some((periodic, _)),
            ..
        } => run_periodic(opts, &inputs, &periodic, &entries, output),
        Identified { .. } => unreachable!("identify_any runs at least one method"),
    }
}

/// What `--json` prints: the identification's output ([`Identified::output`]) and the files
/// written.
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
        // Through a `Value`, whose maps sort their keys at every level.
        let value = serde_json::to_value(&self)?;
        outln!("{}", serde_json::to_string_pretty(&value)?);
        Ok(())
    }
}

/// The paper's method on every file: the output as it has always been, with the records'
/// accounts.
fn run_periodic(
    opts: &Options,
    inputs: &[Input],
    id: &Identification,
    entries: &[RecordInfoSummary],
    output: IdentifyOutput,
) -> Result<()> {
    let written = platen_report::write_outputs(
        opts.plot,
        opts.report,
        &opts.size,
        || identify_figures::figures(id),
        |figures, rendered| html_report(id, inputs, entries, figures, rendered),
    )?;
    if opts.json {
        JsonOutput {
            output,
            figures: figure_list(opts, &written),
            report: opts.report.map(|path| path.display().to_string()),
        }
        .print()?;
    } else {
        out!("{}", report(id, inputs));
        out!("{}", accounts_report(entries, inputs));
        print_written(&written, opts.report)?;
    }
    Ok(())
}

/// The figure files written, for `--json` (absent without `--plot`).
fn figure_list(opts: &Options, written: &[PathBuf]) -> Option<Vec<String>> {
    opts.plot
        .map(|_| written.iter().map(|p| p.display().to_string()).collect())
}

fn print_written(written: &[PathBuf], report: Option<&Path>) -> Result<()> {
    if !written.is_empty() {
        outln!("\nWrote {} figure files (SVG and PNG):", written.len());
        for path in written {
            outln!("  {}", path.display());
        }
    }
    if let Some(path) = report {
        outln!("Wrote report {}", path.display());
    }
    Ok(())
}

/// The any-record method on the records routed to it, and the paper's method on the
/// periodic tests when there are any: [`identify_any`]'s result printed.
fn run_records(
    opts: &Options,
    inputs: &[Input],
    (id, record_idx): (&RecordIdentification, &[usize]),
    periodic: Option<(Identification, Vec<usize>)>,
    entries: &[RecordInfoSummary],
    output: IdentifyOutput,
) -> Result<()> {
    let (periodic, periodic_idx) = match periodic {
        Some((p, idx)) => (Some(p), idx),
        None => (None, Vec::new()),
    };
    let rec_inputs: Vec<&Input> = record_idx.iter().map(|&k| &inputs[k]).collect();
    let per_owned: Vec<Input> = periodic_idx.iter().map(|&k| inputs[k].clone()).collect();
    let written = platen_report::write_outputs(
        opts.plot,
        opts.report,
        &opts.size,
        || {
            let mut f = record_figures::figures(id);
            if let Some(p) = &periodic {
                f.extend(identify_figures::figures(p));
            }
            f
        },
        |figures, rendered| {
            record_html_report(
                id,
                &rec_inputs,
                periodic.as_ref(),
                &per_owned,
                (entries, inputs),
                figures,
                rendered,
            )
        },
    )?;
    if opts.json {
        JsonOutput {
            output,
            figures: figure_list(opts, &written),
            report: opts.report.map(|path| path.display().to_string()),
        }
        .print()?;
    } else {
        out!("{}", record_report(id, &rec_inputs));
        if let Some(p) = &periodic {
            outln!("\n== Periodic tests (hysteresis-loop method, §3) ==\n");
            out!("{}", report(p, &per_owned));
        }
        out!("{}", accounts_report(entries, inputs));
        print_written(&written, opts.report)?;
    }
    Ok(())
}

/// "Records": one line per input file, what identification did with it and why.
fn accounts_report(entries: &[RecordInfoSummary], inputs: &[Input]) -> String {
    let mut s = String::from("\nRecords (every file accounted for)\n");
    let w = inputs
        .iter()
        .map(|i| i.label.chars().count())
        .max()
        .unwrap_or(0);
    for (e, input) in entries.iter().zip(inputs) {
        let Some(a) = &e.account else { continue };
        let status = match &a.reason {
            None => "used".to_owned(),
            Some(r) => format!("NOT USED: {r}"),
        };
        let delays =
            e.channel_delay_s
                .as_ref()
                .filter(|d| !d.is_empty())
                .map_or(String::new(), |d| {
                    let list: Vec<String> = d
                        .iter()
                        .map(|(c, s)| format!("{c} {:+.2} samples", s * e.sample_rate_hz))
                        .collect();
                    format!("; delay {}", list.join(", "))
                });
        let _ = writeln!(
            s,
            "  {:<w$}  {:<8}  {status}{delays}; {}",
            input.label,
            a.method.name(),
            a.routing
        );
    }
    s
}

/// The HTML table of [`accounts_report`].
fn accounts_table(entries: &[RecordInfoSummary], inputs: &[Input]) -> Vec<String> {
    let rows: Vec<Vec<String>> = entries
        .iter()
        .zip(inputs)
        .filter_map(|(e, input)| {
            let a = e.account.as_ref()?;
            Some(vec![
                input.label.clone(),
                a.method.name().to_owned(),
                if a.used { "yes" } else { "no" }.to_owned(),
                a.reason.clone().unwrap_or_default(),
                e.channel_delay_s
                    .as_ref()
                    .map(|d| {
                        d.iter()
                            .map(|(c, s)| format!("{c} {:.3} ms", 1e3 * s))
                            .collect::<Vec<_>>()
                            .join(", ")
                    })
                    .unwrap_or_default(),
                a.routing.clone(),
            ])
        })
        .collect();
    vec![
        html::heading("Records"),
        html::table(
            &[
                "file",
                "method",
                "used",
                "reason",
                "channel delay",
                "routing",
            ],
            &rows,
            false,
        ),
    ]
}

/// The text report of the any-record method.
/// A record's channel delays for its report line: estimated (± one standard error) or
/// given, in ms and samples, and whether the channel was corrected.
fn delay_text(delays: &[platen_ident::anyrecord::ChannelDelay], sample_rate_hz: f64) -> String {
    let mut s = String::new();
    for d in delays {
        let _ = write!(
            s,
            ", {} delay {:.2}{} ms = {:.2} samples ({}; {})",
            d.column,
            1e3 * d.delay_s,
            d.std_error_s
                .map_or(String::new(), |se| format!(" ± {:.2}", 1e3 * se)),
            d.delay_s * sample_rate_hz,
            if d.estimated() { "estimated" } else { "given" },
            match (d.applied, d.estimated()) {
                (true, _) => "corrected",
                (false, true) => "too small to correct: used as recorded",
                (false, false) => "used as recorded",
            }
        );
    }
    s
}

fn record_report(id: &RecordIdentification, inputs: &[&Input]) -> String {
    let mut s = String::new();
    let ee = &id.equation_error;
    let _ = writeln!(
        s,
        "Identified parameters from {} (any-record method: equation error, {} samples faster than {} mm/s; RMS force residual {:.0} N)",
        count(id.records.len(), "record"),
        ee.points,
        1e3 * ee.min_speed_m_s,
        ee.rms_residual_n
    );
    parameter_lines(&mut s, &id.parameters);
    let u = &ee.uncertainty;
    let _ = writeln!(
        s,
        "  (± one standard error; 95 % intervals: batch-means sandwich over blocks of {} samples, t = {:.3}; residuals worth {:.0} independent samples)",
        u.bandwidth_samples, u.critical_value, u.effective_samples
    );
    let _ = writeln!(s, "\nRecords");
    for (r, (rec, input)) in id.records.iter().zip(inputs).enumerate() {
        let _ = writeln!(
            s,
            "  {}: {} samples at {} Hz, velocity {}, {} fitted over {:.1}–{:.0} mm/s, force offset {}{}{}",
            input.label,
            rec.samples,
            platen_report::text::rounded(rec.sample_rate_hz, 9),
            if rec.velocity_given { "given" } else { "from the crossover estimate" },
            rec.used_samples,
            1e3 * rec.speed_range_m_s[0],
            1e3 * rec.speed_range_m_s[1],
            pm(ee.offsets_n.get(r), 1e3, 2) + " kN",
            rec.floors.as_ref().map_or(String::new(), |f| format!(
                ", base shear of {} storeys ({:.0} kg) removed (peak {:.0} kN)",
                f.masses_kg.len(),
                f.masses_kg.iter().sum::<f64>(),
                f.peak_base_shear_n / 1e3
            )),
            delay_text(&rec.channel_delays, rec.sample_rate_hz)
        );
    }
    correlation_lines(&mut s, "equation error", &u.correlations);
    if let Some(oe) = &id.output_error {
        let _ = writeln!(
            s,
            "\nOutput-error check (forward simulation with exact stick-slip fitted to u and a; {} iterations, {} simulations{}):",
            oe.iterations,
            oe.simulations,
            if oe.converged { "" } else { ", NOT converged" }
        );
        parameter_lines(&mut s, &oe.parameters);
        for (k, (u, a)) in oe.rms_u_m.iter().zip(&oe.rms_a_m_s2).enumerate() {
            let _ = writeln!(
                s,
                "  record {}: RMS residual u {:.3} → {:.3} mm, a {:.4} → {:.4} m/s²",
                k + 1,
                1e3 * u[0],
                1e3 * u[1],
                a[0],
                a[1]
            );
        }
    }
    let _ = writeln!(s, "\nDissipative force F_D(|v|) with its 95 % band");
    let step = (id.band.len() / 8).max(1);
    for b in id.band.iter().step_by(step) {
        let _ = writeln!(
            s,
            "  {:>9.1} mm/s  {:>8.2} kN  ({:.2} – {:.2})",
            1e3 * b.speed_m_s,
            b.force_n / 1e3,
            b.low_n / 1e3,
            b.high_n / 1e3
        );
    }
    if !id.warnings.is_empty() {
        let _ = writeln!(s, "\nWarnings");
        for w in &id.warnings {
            let _ = writeln!(s, "  - {w}");
        }
    }
    s
}

/// The seven parameters, one line each.
fn parameter_lines(s: &mut String, params: &platen_ident::ParameterEstimates) {
    for (key, p) in params.iter() {
        let (name, (unit, scale, digits)) = (key.name(), display_unit(key));
        let text = match p {
            Parameter::Estimated(e) => format!(
                "{} {unit}   (95 % CI {:.d$} – {:.d$})",
                pm(Some(e), scale, digits),
                e.ci95_low / scale,
                e.ci95_high / scale,
                d = decimals(e, scale, digits)
            ),
            Parameter::Fixed { value, reason } => {
                format!(
                    "{:.d$} {unit}   (fixed: {reason})",
                    value / scale,
                    d = digits
                )
            }
            Parameter::NotIdentifiable { reason } => format!("not identifiable: {reason}"),
        };
        let _ = writeln!(s, "  {name:<28} {text}");
    }
}

/// The correlation matrix of a fit.
fn correlation_lines(s: &mut String, fit: &str, c: &platen_ident::Correlations) {
    let _ = writeln!(s, "\nParameter correlations ({fit})");
    let names: Vec<&str> = c.keys.iter().map(|k| short(*k)).collect();
    let _ = writeln!(
        s,
        "  {:>4} {}",
        "",
        names.iter().map(|n| format!("{n:>7}")).collect::<String>()
    );
    for (i, row) in c.matrix.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {:>4} {}",
            names[i],
            row.iter().map(|x| format!("{x:>+7.3}")).collect::<String>()
        );
    }
}

fn short(key: IdentifiedKey) -> &'static str {
    match key {
        IdentifiedKey::EffectiveMass => "Me",
        IdentifiedKey::Stiffness => "Ke",
        IdentifiedKey::CoulombForce => "Fmu",
        IdentifiedKey::ViscousCoefficient => "Ce",
        IdentifiedKey::ViscousExponent => "alpha",
        IdentifiedKey::LowVelocityForce => "a",
        IdentifiedKey::LowVelocityDecay => "b",
    }
}

/// The HTML report of the any-record method (and of the periodic tests, if any).
fn record_html_report(
    id: &RecordIdentification,
    inputs: &[&Input],
    periodic: Option<&Identification>,
    periodic_inputs: &[Input],
    (entries, all_inputs): (&[RecordInfoSummary], &[Input]),
    figures: &[Figure],
    rendered: &[(String, String)],
) -> String {
    let mut sections = vec![html::heading("Identified parameters (any-record method)")];
    sections.push(html::table(
        &["key", "value", "unit", "std. error", "95 % CI", "status"],
        &rows(&id.parameters),
        true,
    ));
    for w in &id.warnings {
        sections.push(html::paragraph(&w.to_string(), Some("note")));
    }
    sections.push(html::heading("Report"));
    sections.push(html::preformatted(&record_report(id, inputs)));
    if let Some(p) = periodic {
        sections.push(html::heading("Periodic tests (hysteresis-loop method)"));
        sections.push(html::preformatted(&report(p, periodic_inputs)));
    }
    sections.extend(accounts_table(entries, all_inputs));
    let files: Vec<String> = inputs
        .iter()
        .map(|i| i.path.display().to_string())
        .collect();
    html::page(&html::Page {
        title: "platen identify".into(),
        heading: "Identification from test records (equation error, output error)".into(),
        items: vec![
            ("records".to_owned(), id.records.len().to_string()),
            (
                "files".to_owned(),
                inputs
                    .iter()
                    .map(|i| i.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
        ],
        sections,
        figures,
        rendered,
        summary: serde_json::to_value(RecordSummary::new(id, &files))
            .expect("a summary of numbers, strings and string-keyed maps serialises"),
    })
}

/// The summary of `id`, whose tests come from `inputs`.
fn summary(id: &Identification, inputs: &[Input]) -> IdentificationSummary {
    let files: Vec<String> = inputs
        .iter()
        .map(|i| i.path.display().to_string())
        .collect();
    IdentificationSummary::new(id, &files)
}

/// The HTML report: the parameter table, the text report's per-test tables, the figures
/// and the JSON summary.
fn html_report(
    id: &Identification,
    inputs: &[Input],
    entries: &[RecordInfoSummary],
    figures: &[Figure],
    rendered: &[(String, String)],
) -> String {
    let mut sections = vec![html::heading("Identified parameters")];
    sections.push(html::table(
        &["key", "value", "unit", "std. error", "95 % CI", "status"],
        &parameter_rows(id),
        true,
    ));
    for w in &id.warnings {
        sections.push(html::paragraph(&w.to_string(), Some("note")));
    }
    sections.push(html::heading("Report"));
    sections.push(html::preformatted(&report(id, inputs)));
    sections.extend(accounts_table(entries, inputs));
    html::page(&html::Page {
        title: "platen identify".into(),
        heading: "Identification from periodic tests (hysteresis-loop method)".into(),
        items: html_items(id, inputs),
        sections,
        figures,
        rendered,
        summary: serde_json::to_value(summary(id, inputs))
            .expect("a summary of numbers, strings and string-keyed maps serialises"),
    })
}

/// The report's header items: the tests, the files, the reference pressure.
fn html_items(id: &Identification, inputs: &[Input]) -> Vec<(String, String)> {
    let count = |kind: TestKind| id.tests.iter().filter(|t| t.kind == kind).count();
    vec![
        (
            "tests".to_owned(),
            format!(
                "{} ({} sine, {} triangle)",
                id.tests.len(),
                count(TestKind::Sine),
                count(TestKind::Triangle)
            ),
        ),
        (
            "files".to_owned(),
            inputs
                .iter()
                .map(|i| i.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        ),
        (
            "reference pressure".to_owned(),
            id.reference_pressure_pa
                .map_or("not given".to_owned(), |p| format!("{} MPa", p / 1e6)),
        ),
    ]
}

/// The HTML table's rows: key, value, unit, standard error, interval, status.
fn parameter_rows(id: &Identification) -> Vec<Vec<String>> {
    rows(&id.parameters)
}

/// The HTML table's rows of a set of parameters.
fn rows(params: &platen_ident::ParameterEstimates) -> Vec<Vec<String>> {
    params
        .iter()
        .map(|(key, p)| {
            let (unit, scale, d) = display_unit(key);
            let (value, se, ci, status) = match p {
                Parameter::Estimated(e) => {
                    // The decimals of the text's `value ± se`: the value, its standard error
                    // and interval alike.
                    let d = decimals(e, scale, d);
                    (
                        format!("{:.d$}", e.value / scale),
                        format!("{:.d$}", e.std_error / scale),
                        format!("{:.d$} – {:.d$}", e.ci95_low / scale, e.ci95_high / scale),
                        "estimated".to_owned(),
                    )
                }
                Parameter::Fixed { value, reason } => (
                    format!("{:.d$}", value / scale),
                    "—".into(),
                    "—".into(),
                    format!("fixed: {reason}"),
                ),
                Parameter::NotIdentifiable { reason } => (
                    "—".into(),
                    "—".into(),
                    "—".into(),
                    format!("not identifiable: {reason}"),
                ),
            };
            vec![
                key.name().to_owned(),
                value,
                unit.to_owned(),
                se,
                ci,
                status,
            ]
        })
        .collect()
}

/// The files to read: the command line's, then the manifest's not already given, with
/// kinds and pressures from the manifest and `--pressure-mpa`.
fn inputs(opts: &Options) -> Result<Vec<Input>> {
    if !opts.pressure_mpa.is_empty()
        && opts.pressure_mpa.len() != 1
        && opts.pressure_mpa.len() != opts.files.len()
    {
        bail!(
            "--pressure-mpa has {} values for {} files: give one value for all files, or one per file in order",
            opts.pressure_mpa.len(),
            opts.files.len()
        );
    }
    let default_columns = match opts.columns {
        Some(path) => ColumnMap::load(path)?,
        None => ColumnMap::default(),
    };
    let mut inputs: Vec<Input> = opts
        .files
        .iter()
        .enumerate()
        .map(|(i, f)| Input {
            path: f.clone(),
            name: f.display().to_string(),
            label: file_label(f),
            kind: None,
            pressure_mpa: match opts.pressure_mpa.len() {
                0 => None,
                1 => Some(opts.pressure_mpa[0]),
                _ => Some(opts.pressure_mpa[i]),
            },
            columns: default_columns.clone(),
            record: false,
            floors: Vec::new(),
            generated_seed: None,
        })
        .collect();
    if let Some(mpath) = opts.manifest {
        let manifest = ManifestReader::read(mpath, default_columns)?;
        for (k, entry) in manifest.tests.into_iter().enumerate() {
            manifest
                .reader
                .add(&mut inputs, k, entry, opts.pressure_mpa)?;
        }
    }
    if inputs.is_empty() {
        bail!("no test files: give recorded CSV files, or a manifest that lists them");
    }
    Ok(inputs)
}

/// A manifest read, with what its entries need.
struct ManifestTests<'a> {
    tests: Vec<ManifestEntry>,
    reader: ManifestReader<'a>,
}

/// Turns a manifest's entries into inputs.
struct ManifestReader<'a> {
    path: &'a Path,
    /// The folder the entries' files are relative to.
    base: &'a Path,
    /// The manifest's own `columns`, if any.
    columns: Option<ColumnMap>,
    /// `--columns`, or platen's own names.
    default_columns: ColumnMap,
    /// The manifest's own `floors`, if any.
    floors: Option<Vec<FloorSpec>>,
}

impl<'a> ManifestReader<'a> {
    fn read(path: &'a Path, default_columns: ColumnMap) -> Result<ManifestTests<'a>> {
        let manifest: Manifest = parse_json_file(path).context(
            "reading the identification manifest (expected {\"tests\": [{\"file\": PATH, \"kind\": \"sine\"|\"triangle\"|\"record\", \"pressure_mpa\": P, \"name\": NAME, \"columns\": MAP, \"floors\": [{\"column\": NAME, \"unit\": UNIT, \"mass_kg\": M}]}], \"columns\": MAP, \"floors\": FLOORS}, with only `file` required)",
        )?;
        let mut reader = ManifestReader {
            path,
            base: path.parent().unwrap_or(Path::new(".")),
            columns: None,
            default_columns,
            floors: manifest.floors.clone(),
        };
        reader.columns = match &manifest.columns {
            Some(spec) => Some(reader.column_map(spec, "columns")?),
            None => None,
        };
        Ok(ManifestTests {
            tests: manifest.tests,
            reader,
        })
    }

    fn column_map(&self, spec: &BTreeMap<String, ColumnSpec>, at: &str) -> Result<ColumnMap> {
        ColumnMap::new(spec, at).map_err(|(json_path, value, expected)| {
            anyhow::anyhow!(
                "`{}`: {json_path} = {value}: expected {expected}",
                self.path.display()
            )
        })
    }

    /// Adds entry `k`: to the input of the same file if there is one, else as a new input.
    fn add(
        &self,
        inputs: &mut Vec<Input>,
        k: usize,
        entry: ManifestEntry,
        pressure_mpa: &[f64],
    ) -> Result<()> {
        if let Some(p) = entry.pressure_mpa {
            if let Err(e) = platen_scenario::units::check_pressure_mpa(p) {
                bail!(
                    "`{}`, at `tests[{k}].pressure_mpa`: {e}",
                    self.path.display()
                );
            }
        }
        let (given, generated_seed) = self.source(k, &entry)?;
        let path = if given.is_absolute() {
            given.to_path_buf()
        } else {
            self.base.join(given)
        };
        let columns = match (&entry.columns, &self.columns) {
            (Some(spec), _) => self.column_map(spec, &format!("tests[{k}].columns"))?,
            (None, Some(map)) => map.clone(),
            (None, None) => self.default_columns.clone(),
        };
        let record = matches!(entry.kind, Some(KindName::Record));
        let kind = entry.kind.and_then(|k| match k {
            KindName::Sine => Some(TestKind::Sine),
            KindName::Triangle => Some(TestKind::Triangle),
            KindName::Record => None,
        });
        let floors = entry
            .floors
            .clone()
            .or_else(|| self.floors.clone())
            .unwrap_or_default();
        for (i, f) in floors.iter().enumerate() {
            if !(f.mass_kg.is_finite() && f.mass_kg > 0.0) {
                bail!(
                    "`{}`, at `floors[{i}].mass_kg` (tests[{k}]): {}: expected a mass > 0 kg",
                    self.path.display(),
                    f.mass_kg
                );
            }
            floor_factor(f).with_context(|| {
                format!(
                    "`{}`, at `floors[{i}].unit` (tests[{k}])",
                    self.path.display()
                )
            })?;
        }
        let canon = std::fs::canonicalize(&path).ok();
        let existing = inputs
            .iter_mut()
            .find(|i| canon.is_some() && std::fs::canonicalize(&i.path).ok() == canon);
        match existing {
            Some(input) => {
                input.record = record;
                input.floors = floors;
                input.generated_seed = generated_seed;
                self.merge(input, entry, kind, columns)?
            }
            None => inputs.push(Input {
                label: entry.name.clone().unwrap_or_else(|| file_label(&path)),
                name: entry.name.unwrap_or_else(|| path.display().to_string()),
                path,
                kind,
                // A single --pressure-mpa is the default for every file.
                pressure_mpa: entry.pressure_mpa.or(match pressure_mpa {
                    [p] => Some(*p),
                    _ => None,
                }),
                columns,
                record,
                floors,
                generated_seed,
            }),
        }
        Ok(())
    }

    /// Entry `k`'s source: its `file`, or its `scenario` with the seed of its recorded-like
    /// data.
    fn source<'e>(&self, k: usize, entry: &'e ManifestEntry) -> Result<(&'e Path, Option<u64>)> {
        let at = |what: &str| format!("`{}`, at `tests[{k}]`: {what}", self.path.display());
        match (&entry.file, &entry.scenario) {
            (Some(file), None) => {
                if entry.seed.is_some() {
                    bail!(
                        "{}",
                        at("`seed` applies to a `scenario` entry, not to a `file`")
                    );
                }
                Ok((file, None))
            }
            (None, Some(scenario)) => {
                if entry.columns.is_some() || entry.floors.is_some() {
                    bail!(
                        "{}",
                        at(
                            "`columns` and `floors` apply to a recorded `file`; a `scenario` \
                            entry's recorded-like data are in platen's own columns"
                        )
                    );
                }
                Ok((scenario, Some(entry.seed.unwrap_or(1))))
            }
            (Some(_), Some(_)) => bail!("{}", at("expected `file` or `scenario`, not both")),
            (None, None) => bail!(
                "{}",
                at(
                    "expected `file` (a recorded CSV) or `scenario` (a motion scenario whose \
                    recorded-like data are identified)"
                )
            ),
        }
    }

    /// Lays an entry over the command line's input of the same file.
    fn merge(
        &self,
        input: &mut Input,
        entry: ManifestEntry,
        kind: Option<TestKind>,
        columns: ColumnMap,
    ) -> Result<()> {
        if let (Some(a), Some(b)) = (input.pressure_mpa, entry.pressure_mpa) {
            if a != b {
                bail!(
                    "`{}`: hold-down pressure {a} MPa from --pressure-mpa but {b} MPa in the manifest `{}`",
                    input.path.display(),
                    self.path.display()
                );
            }
        }
        input.pressure_mpa = entry.pressure_mpa.or(input.pressure_mpa);
        input.kind = kind;
        input.columns = columns;
        if let Some(n) = entry.name {
            input.label = n.clone();
            input.name = n;
        }
        Ok(())
    }
}

fn file_label(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// The factor from a floor channel's unit to m/s² (checked like a column map's acceleration).
fn floor_factor(f: &FloorSpec) -> Result<f64> {
    let mut spec = BTreeMap::new();
    spec.insert(
        "a_m_s2".to_owned(),
        ColumnSpec {
            name: Some(f.column.clone()),
            unit: f.unit.clone(),
            ..ColumnSpec::default()
        },
    );
    let map = ColumnMap::new(&spec, "floors")
        .map_err(|(_, value, expected)| anyhow::anyhow!("{value}: expected {expected}"))?;
    Ok(map.factor("a_m_s2"))
}

fn read_record(input: &Input) -> Result<TestRecord> {
    if let Some(seed) = input.generated_seed {
        return generated_record(input, seed);
    }
    let path = &input.path;
    let mut required = vec!["t_s", "u_m", "a_m_s2", "force_n"];
    required.extend(input.floors.iter().map(|f| f.column.as_str()));
    let mut table = input.columns.read_table(path, &required, &["v_m_s"])?;
    let t = table.take_column("t_s").expect("required column");
    let dt = uniform_step_s(path, &t)?;
    let take =
        |table: &mut platen_io::csv::Table, c: &str| table.take_column(c).expect("required column");
    let u = take(&mut table, "u_m");
    let a = take(&mut table, "a_m_s2");
    let f = take(&mut table, "force_n");
    let v = table.take_column("v_m_s");
    let context = || format!("`{}`", path.display());
    let has_v = v.is_some();
    let mut rec =
        TestRecord::from_rate(input.name.clone(), 1.0 / dt, u, a, f).with_context(context)?;
    if let Some(v) = v {
        rec = rec.with_velocity(v).with_context(context)?;
    }
    if let Some(p) = input.pressure_mpa {
        rec = rec.with_pressure_pa(p * 1e6).with_context(context)?;
    }
    if let Some(k) = input.kind {
        rec = rec.with_kind(k);
    }
    if !input.floors.is_empty() {
        let mut floors = Vec::with_capacity(input.floors.len());
        for f in &input.floors {
            let factor = floor_factor(f)?;
            let acc = table
                .take_column(&f.column)
                .expect("required column")
                .into_iter()
                .map(|a| a * factor)
                .collect();
            floors.push((f.mass_kg, acc));
        }
        rec = rec.with_floors(&floors).with_context(context)?;
    }
    // A column map's known channel skew (`delay_s`), applied by identification as given.
    for column in platen_ident::anyrecord::DELAYABLE_CHANNELS {
        let delay = input.columns.delay_s(column);
        if let Some(d) = delay.filter(|_| column != "v_m_s" || has_v) {
            rec = rec.with_channel_delay_s(column, d).with_context(context)?;
        }
    }
    Ok(rec)
}

/// The recorded-like data of a manifest's `scenario` entry as a test record: the numbers
/// `platen generate recorded` writes, so identifying them gives what identifying that CSV
/// gives. The hold-down pressure is the scenario's (a different one in the manifest is an
/// error: the data were made at the scenario's).
fn generated_record(input: &Input, seed: u64) -> Result<TestRecord> {
    let path = &input.path;
    if !input.floors.is_empty() {
        bail!(
            "`{}`: a manifest's `floors` apply to recorded files; recorded-like data made from a \
             scenario have no floor accelerometers",
            path.display()
        );
    }
    let scenario = platen_scenario::Scenario::load(path)?;
    let pressure_pa = scenario.hold_down_pressure_pa;
    if let Some(p) = input.pressure_mpa {
        // The same number written twice (13.8 in both files) may differ in its last bit.
        if (p * 1e6 - pressure_pa).abs() > 1e-9 * pressure_pa.abs().max(1.0) {
            bail!(
                "`{}`: hold-down pressure {p} MPa given for it, but the scenario runs at {} MPa",
                path.display(),
                pressure_pa / 1e6
            );
        }
    }
    let rec = generate::recorded_of(&scenario, path, seed)?;
    let dt = uniform_step_s(path, &rec.t_s)?;
    let context = || format!("`{}` (recorded-like, seed {seed})", path.display());
    let mut test = TestRecord::from_rate(
        input.name.clone(),
        1.0 / dt,
        rec.u_m,
        rec.a_m_s2,
        rec.force_n,
    )
    .and_then(|t| t.with_velocity(rec.v_m_s))
    .and_then(|t| t.with_pressure_pa(pressure_pa))
    .with_context(context)?;
    if let Some(k) = input.kind {
        test = test.with_kind(k);
    }
    Ok(test)
}

/// `value ± se` in a unit, `se` one standard error (the same quantity wherever a `±` is
/// printed), with at least `digits` decimals and more when needed to show the standard
/// error's first two significant digits (see [`decimals`]).
fn pm(e: Option<&Estimate>, scale: f64, digits: usize) -> String {
    match e {
        Some(e) if e.std_error.is_finite() => format!(
            "{:.d$} ± {:.d$}",
            e.value / scale,
            e.std_error / scale,
            d = decimals(e, scale, digits)
        ),
        Some(e) => format!("{:.d$}", e.value / scale, d = digits),
        None => "—".to_owned(),
    }
}

/// Decimals to print `e` with in a unit of `scale`: `digits`, or enough to show the first
/// significant digit of a standard error smaller than that (never `± 0.00`), at most six
/// more.
fn decimals(e: &Estimate, scale: f64, digits: usize) -> usize {
    let se = (e.std_error / scale).abs();
    if se > 0.0 && se.is_finite() {
        let needed = -(se.log10().floor() as i64);
        (needed.max(digits as i64) as usize).min(digits + 6)
    } else {
        digits
    }
}

/// `n` and `noun`, plural unless `n` is 1 ("1 test", "24 tests").
fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

fn pressure_text(p: Option<f64>) -> String {
    p.map_or_else(|| "—".to_owned(), |p| format!("{:.1}", p / 1e6))
}

fn flag_codes(flags: &[Flag]) -> String {
    flags.iter().map(Flag::code).collect::<Vec<_>>().join(",")
}

/// How a parameter is shown to a reader: unit, SI units per shown unit, decimals.
fn display_unit(key: IdentifiedKey) -> (&'static str, f64, usize) {
    match key {
        IdentifiedKey::EffectiveMass => ("t", 1e3, 2),
        IdentifiedKey::Stiffness => ("MN/m", 1e6, 4),
        IdentifiedKey::CoulombForce | IdentifiedKey::LowVelocityForce => ("kN", 1e3, 2),
        IdentifiedKey::ViscousCoefficient => ("kN/(m/s)^α", 1e3, 2),
        IdentifiedKey::ViscousExponent => ("", 1.0, 3),
        IdentifiedKey::LowVelocityDecay => ("s/m", 1.0, 1),
    }
}

/// The human-readable report.
fn report(id: &Identification, inputs: &[Input]) -> String {
    let mut s = String::new();
    let w = inputs
        .iter()
        .map(|i| i.label.chars().count())
        .max()
        .unwrap_or(4)
        .max(4);
    report_parameters(&mut s, id);
    report_triangle_tests(&mut s, id, inputs, w);
    report_sine_tests(&mut s, id, inputs, w);
    report_peaks(&mut s, id, inputs, w);
    report_pressures(&mut s, id);
    report_fits(&mut s, id);
    report_global(&mut s, id);
    report_warnings(&mut s, id);
    s
}

/// The seven parameters and μₑ.
fn report_parameters(s: &mut String, id: &Identification) {
    let _ = writeln!(
        s,
        "Identified parameters ({}; {}; ± one standard error)",
        count(id.tests.len(), "test"),
        match id.reference_pressure_pa {
            Some(p) => format!("reference hold-down pressure {} MPa", p / 1e6),
            None => "hold-down pressure not given".to_owned(),
        }
    );
    parameter_lines(s, &id.parameters);
    if let Some(mu) = &id.friction_coefficient {
        let _ = writeln!(
            s,
            "  {:<28} {} %   (F_μ = μₑ·F_z over the pressures)",
            "friction_coefficient",
            pm(Some(mu), 0.01, 4)
        );
    }
}

/// The stiffness table (Table I).
fn report_triangle_tests(s: &mut String, id: &Identification, inputs: &[Input], w: usize) {
    let _ = writeln!(s, "\nStiffness from triangle tests (Eq. 16/17, Table I)");
    let _ = writeln!(
        s,
        "  {:<w$} {:>5} {:>7} {:>8} {:>8}  {:>20} {:>5}  flags",
        "test", "MPa", "f Hz", "u cm", "v cm/s", "Kₑ MN/m", "used"
    );
    for (t, input) in id.tests.iter().zip(inputs) {
        if t.kind != TestKind::Triangle {
            continue;
        }
        let _ = writeln!(
            s,
            "  {:<w$} {:>5} {:>7.3} {:>8.2} {:>8.2}  {:>20} {:>5}  {}",
            input.label,
            pressure_text(t.pressure_pa),
            t.cycle.frequency_hz,
            100.0 * t.cycle.amplitude_m,
            100.0 * t.peak_velocity_m_s,
            pm(t.stiffness.as_ref(), 1e6, 4),
            if t.used_for_stiffness { "yes" } else { "no" },
            flag_codes(&t.flags)
        );
    }
}

/// The mass table (Table II).
fn report_sine_tests(s: &mut String, id: &Identification, inputs: &[Input], w: usize) {
    let _ = writeln!(s, "\nEffective mass from sine tests (Eq. 18/19, Table II)");
    let _ = writeln!(
        s,
        "  {:<w$} {:>5} {:>7} {:>8} {:>8} {:>7}  {:>16} {:>5}  flags",
        "test", "MPa", "f Hz", "u cm", "v cm/s", "a g", "Mₑ t", "used"
    );
    for (t, input) in id.tests.iter().zip(inputs) {
        if t.kind != TestKind::Sine {
            continue;
        }
        let _ = writeln!(
            s,
            "  {:<w$} {:>5} {:>7.3} {:>8.2} {:>8.2} {:>7.3}  {:>16} {:>5}  {}",
            input.label,
            pressure_text(t.pressure_pa),
            t.cycle.frequency_hz,
            100.0 * t.cycle.amplitude_m,
            100.0 * t.peak_velocity_m_s,
            t.peak_acceleration_m_s2 / platen_model::STANDARD_GRAVITY_M_S2,
            pm(t.effective_mass.as_ref(), 1e3, 2),
            if t.used_for_mass { "yes" } else { "no" },
            flag_codes(&t.flags)
        );
    }
}

/// The dissipative force at peak velocity per test (Fig. 7).
fn report_peaks(s: &mut String, id: &Identification, inputs: &[Input], w: usize) {
    let _ = writeln!(s, "\nDissipative force at peak velocity (Eq. 20, Fig. 7)");
    let _ = writeln!(
        s,
        "  {:<w$} {:>8} {:>5} {:>10} {:>10}",
        "test", "kind", "MPa", "v m/s", "F_D kN"
    );
    for (t, input) in id.tests.iter().zip(inputs) {
        if let Some(p) = t.peak_dissipative {
            let _ = writeln!(
                s,
                "  {:<w$} {:>8} {:>5} {:>10.4} {:>10.2}",
                input.label,
                t.kind.name(),
                pressure_text(t.pressure_pa),
                p.velocity_m_s,
                p.force_n / 1e3
            );
        }
    }
}

/// The per-pressure table.
fn report_pressures(s: &mut String, id: &Identification) {
    let _ = writeln!(s, "\nPer hold-down pressure");
    let _ = writeln!(
        s,
        "  {:>5} {:>10} {:>22} {:>18} {:>18} {:>18}",
        "MPa", "F_z MN", "Kₑ MN/m", "F_μ kN", "F_μ S kN (Eq.21)", "F_μ T kN (Eq.21)"
    );
    for g in &id.pressures {
        let _ = writeln!(
            s,
            "  {:>5} {:>10} {:>22} {:>18} {:>18} {:>18}",
            pressure_text(g.pressure_pa),
            g.vertical_force_n
                .map_or("—".to_owned(), |f| format!("{:.3}", f / 1e6)),
            pm(g.stiffness.as_ref(), 1e6, 4),
            pm(g.coulomb_force.as_ref(), 1e3, 2),
            pm(g.paper_coulomb_force_sine.as_ref(), 1e3, 2),
            pm(g.paper_coulomb_force_triangle.as_ref(), 1e3, 2),
        );
    }
}

/// Eq. 21 as the paper fitted it, and the law fit.
fn report_fits(s: &mut String, id: &Identification) {
    if let Some(p) = &id.paper_fit {
        let _ = writeln!(
            s,
            "\nEq. 21 as the paper fitted it ({} peak points{}): F_μ = {} kN, Cₑ = {} kN/(m/s)^0.5{}",
            p.points,
            if p.sine_only { ", sine tests" } else { ", all tests" },
            pm(Some(&p.coulomb_force), 1e3, 2),
            pm(Some(&p.viscous_coefficient), 1e3, 2),
            p.friction_coefficient
                .as_ref()
                .map_or(String::new(), |mu| format!(
                    ", μₑ = {} %",
                    pm(Some(mu), 0.01, 4)
                ))
        );
    }
    if let Some(l) = &id.law {
        let _ = writeln!(
            s,
            "Dissipative law fitted to {} points over {:.3}–{:.3} m/s: RMS residual {:.0} N",
            l.points, l.speed_range_m_s[0], l.speed_range_m_s[1], l.rms_n
        );
    }
}

/// The global fit against the hysteresis-loop estimate.
fn report_global(s: &mut String, id: &Identification) {
    if let Some(g) = &id.global {
        let _ = writeln!(
            s,
            "\nGlobal fit of Eq. 23 over every test ({} samples, RMS residual {:.0} N{}):",
            g.points,
            g.rms_residual_n,
            if g.converged { "" } else { ", NOT converged" }
        );
        for (key, p) in g.parameters.iter() {
            let (name, (unit, scale, digits)) = (key.name(), display_unit(key));
            let own = id.parameters.get(key);
            let diff = match (p.value(), own.value()) {
                (Some(a), Some(b)) if b != 0.0 => {
                    format!("  ({:+.2} %)", 100.0 * (a - b) / b.abs())
                }
                _ => String::new(),
            };
            let text = match p {
                Parameter::Estimated(e) => pm(Some(e), scale, digits),
                Parameter::Fixed { value, .. } => {
                    format!("{:.d$} (held)", value / scale, d = digits)
                }
                Parameter::NotIdentifiable { .. } => "not identifiable".to_owned(),
            };
            let _ = writeln!(s, "  {name:<28} {text} {unit}{diff}");
        }
    }
}

/// The warnings.
fn report_warnings(s: &mut String, id: &Identification) {
    if !id.warnings.is_empty() {
        let _ = writeln!(s, "\nWarnings");
        for w in &id.warnings {
            let _ = writeln!(s, "  - {w}");
        }
    }
}

/// `platen identify --system FILE…`: the controller's gains from closed-loop records (see
/// `platen_ident::system`). With two or more files, the last is held out and judged; the
/// others are fitted. Prints the gains, the fit on each record, what cannot be identified and
/// a runnable scenario (the `lhpost-2008` preset with the identified controller, commanded by
/// the held-out record).
pub fn run_system(
    files: &[PathBuf],
    columns: Option<&Path>,
    base: Option<&Path>,
    json: bool,
) -> Result<()> {
    use platen_ident::system::{identify_system, SystemRecord, SystemSettings};
    if files.is_empty() {
        bail!("identify --system needs at least one recorded CSV file");
    }
    let map = match columns {
        Some(path) => ColumnMap::load(path)?,
        None => ColumnMap::default(),
    };
    let storey_names: Vec<String> = (1..=platen_model::Specimen::MAX_STOREYS)
        .map(|i| format!("storey{i}_a_m_s2"))
        .collect();
    let mut optional = vec![
        "drive",
        "delta_p_pa",
        "a_m_s2",
        "cap_pressure_pa",
        "rod_pressure_pa",
    ];
    optional.extend(storey_names.iter().map(String::as_str));
    let mut records = Vec::with_capacity(files.len());
    for path in files {
        let mut t = map
            .read_table(path, &["t_s", "command_u_m", "u_m"], &optional)
            .with_context(|| {
                format!(
                    "{}: identify --system needs the columns t_s, command_u_m and u_m \
                     (drive, delta_p_pa, cap_pressure_pa, rod_pressure_pa, a_m_s2, \
                     storey{{i}}_a_m_s2 where recorded)",
                    path.display()
                )
            })?;
        let storeys = storey_names
            .iter()
            .map_while(|c| t.take_column(c))
            .collect();
        let mut take = |c: &str| t.take_column(c);
        records.push(SystemRecord {
            name: path.display().to_string(),
            t_s: take("t_s").unwrap_or_default(),
            command_u_m: take("command_u_m").unwrap_or_default(),
            u_m: take("u_m").unwrap_or_default(),
            drive: take("drive"),
            delta_p_pa: take("delta_p_pa"),
            a_m_s2: take("a_m_s2"),
            cap_pressure_pa: take("cap_pressure_pa"),
            rod_pressure_pa: take("rod_pressure_pa"),
            storey_a_m_s2: storeys,
        });
    }
    let (base_system, base_stroke) = match base {
        Some(path) => {
            let (s, stroke) = load_base(path, &files[0], &map)?;
            (Some(s), stroke)
        }
        None => (None, None),
    };
    let n = records.len();
    let fit: Vec<bool> = (0..n).map(|i| n == 1 || i + 1 < n).collect();
    let settings = SystemSettings {
        base: base_system,
        judge: true,
        ..SystemSettings::default()
    };
    let id = identify_system(&records, &fit, &settings)?;
    let held = &records[n - 1];
    let held_path = std::fs::canonicalize(&files[n - 1]).unwrap_or_else(|_| files[n - 1].clone());
    let plant = id.plant.as_ref();
    let identified_system = plant.and_then(|p| p.system);
    let mut table_system = match &identified_system {
        Some(sys) => crate::model::parameters(sys),
        None => serde_json::json!({ "preset": "lhpost-2008" }),
    };
    if let (Some(g), None) = (&id.gains, &identified_system) {
        table_system["controller"] = serde_json::json!({
            "sample_rate_hz": g.sample_rate_hz,
            "displacement_gain_per_m": g.displacement_gain_per_m,
            "velocity_feedforward_s_per_m": g.velocity_feedforward_s_per_m,
            "acceleration_feedforward_s2_per_m": g.acceleration_feedforward_s2_per_m,
            "velocity_feedback_s_per_m": g.velocity_feedback_s_per_m,
            "acceleration_feedback_s2_per_m": g.acceleration_feedback_s2_per_m,
            "delta_p_gain_per_pa": g.delta_p_gain_per_pa,
            "delta_p_highpass_hz": g.delta_p_highpass_hz,
            "integral_gain_per_m_s": 0.0,
        });
    }
    let model = match plant.and_then(|p| p.model) {
        Some(m) => serde_json::json!({
            "preset": "lhpost-2008",
            "identified": {
                "effective_mass_kg": m.effective_mass_kg,
                "stiffness_n_per_m": m.stiffness_n_per_m,
                "coulomb_force_n": m.coulomb_force_n,
                "viscous_coefficient": m.viscous_coefficient,
                "viscous_exponent": m.viscous_exponent,
                "low_velocity_force_n": m.low_velocity_force_n,
                "low_velocity_decay_s_per_m": m.low_velocity_decay_s_per_m,
            }
        }),
        None => serde_json::json!({ "preset": "lhpost-2008" }),
    };
    let span = held.t_s.last().copied().unwrap_or(0.0) - held.t_s.first().copied().unwrap_or(0.0);
    let mut scenario = serde_json::json!({
        "name": format!("identified table system, commanded by {}", held.name),
        "model": model,
        "table_system": table_system,
        // The record's own a_m_s2 is the table's, not the command's: the command's velocity
        // and acceleration are derived from command_u_m (the record's columns ignored).
        "excitation": {
            "motion_csv": held_path.display().to_string(),
            "columns": {
                "u_m": { "name": map.header("command_u_m") },
                "v_m_s": { "ignore": true },
                "a_m_s2": { "ignore": true },
            }
        },
        "duration_s": span,
    });
    if let Some(sp) = plant.and_then(|p| p.specimen.as_ref()) {
        scenario["specimen"] = serde_json::json!({
            "storeys": sp.storeys().iter().map(|s| serde_json::json!({
                "mass_kg": s.mass_kg,
                "stiffness_n_per_m": s.stiffness_n_per_m,
                "damping_n_s_per_m": s.damping_n_s_per_m,
            })).collect::<Vec<_>>()
        });
    }
    if let Some(sys) = &identified_system {
        // The chambers must keep oil over the stroke: the base's, else 90 % of what the
        // identified volumes allow.
        let a = &sys.actuator;
        let room = (a.cap_volume_m3 / a.cap_area_m2).min(a.rod_volume_m3 / a.rod_area_m2);
        let stroke = base_stroke.filter(|s| *s < room).unwrap_or(0.9 * room);
        // The other limits are this table's, not the preset's: its capacities by the closed
        // forms in the weaker direction, and the acceleration that force gives the moving
        // mass (platen and specimen).
        let cap = sys.capacities();
        let force = cap.push_force_n.min(cap.pull_force_n);
        let velocity = cap.extend_velocity_m_s.min(cap.retract_velocity_m_s);
        let mut limits = serde_json::json!({
            "stroke_m": stroke,
            "velocity_m_s": velocity,
            "force_n": force,
        });
        if let Some(m) = plant.and_then(|p| p.model) {
            let specimen_kg: f64 = plant
                .and_then(|p| p.specimen.as_ref())
                .map_or(0.0, |sp| sp.storeys().iter().map(|s| s.mass_kg).sum());
            limits["acceleration_m_s2"] = (force / (m.effective_mass_kg + specimen_kg)).into();
        }
        scenario["limits"] = limits;
    }
    let mut from_preset: Vec<&str> = Vec::new();
    if plant.and_then(|p| p.model).is_none() {
        from_preset.push("model (the platen: mass, friction, stiffness)");
    }
    if identified_system.is_none() {
        from_preset.push("table_system: actuators, servo-valves, oil, supply, accumulator");
    } else {
        from_preset.push(
            "table_system: actuator count and areas, valve count and rated drop, supply and \
             return pressures, bulk modulus, accumulator (from --base)",
        );
    }
    from_preset
        .push("table_system.controller.integral_gain_per_m_s (0: an integrator is not fitted)");
    if json {
        let value = serde_json::json!({
            "system_identification": id,
            "scenario": scenario,
            "scenario_from_preset": from_preset,
        });
        outln!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    let mut s = String::new();
    match &id.gains {
        Some(g) => {
            let _ = writeln!(
                s,
                "controller at {:.6} Hz (fitted on {}):",
                g.sample_rate_hz,
                id.fitted_records.join(", ")
            );
            for (k, v) in [
                ("K_p  displacement_gain_per_m", g.displacement_gain_per_m),
                (
                    "K_vf velocity_feedforward_s_per_m",
                    g.velocity_feedforward_s_per_m,
                ),
                (
                    "K_af acceleration_feedforward_s2_per_m",
                    g.acceleration_feedforward_s2_per_m,
                ),
                (
                    "K_vb velocity_feedback_s_per_m",
                    g.velocity_feedback_s_per_m,
                ),
                (
                    "K_ab acceleration_feedback_s2_per_m",
                    g.acceleration_feedback_s2_per_m,
                ),
                ("K_dp delta_p_gain_per_pa", g.delta_p_gain_per_pa),
                ("     delta_p_highpass_hz", g.delta_p_highpass_hz),
            ] {
                let _ = writeln!(s, "  {k:<40} {v:.6e}");
            }
            let _ = writeln!(s, "  saturated samples left out: {}", id.saturated_samples);
        }
        None => {
            let _ = writeln!(s, "controller gains: not identified");
        }
    }
    for r in &id.records {
        let _ = writeln!(
            s,
            "{} {}: drive RMS error {:.3e} ({:.3} % of its RMS) over {} samples",
            if r.fitted { "fitted  " } else { "held out" },
            r.name,
            r.drive_rms_error,
            100.0 * r.drive_nrmse,
            r.samples
        );
    }
    if let Some(p) = plant {
        if let Some(m) = &p.mechanics {
            let _ = writeln!(
                s,
                "platen: mass {:.1} kg, stiffness {:.1} N/m, viscous {:.1} N·s/m, Coulomb \
                 {:.1} N (force residual {:.3} % over {} samples)",
                m.effective_mass_kg,
                m.stiffness_n_per_m,
                m.viscous_coefficient,
                m.coulomb_force_n,
                100.0 * m.force_nrmse,
                m.samples
            );
        }
        for (i, st) in p.storeys.iter().enumerate() {
            let _ = writeln!(
                s,
                "storey {}: mass {:.1} kg, stiffness {:.4e} N/m, damping {:.1} N·s/m",
                i + 1,
                st.mass_kg,
                st.stiffness_n_per_m,
                st.damping_n_s_per_m
            );
        }
        for (i, m) in p.specimen_modes.iter().enumerate() {
            let _ = writeln!(
                s,
                "specimen mode {}: {:.4} Hz, damping {:.2} %",
                i + 1,
                m.frequency_hz,
                100.0 * m.damping_ratio
            );
        }
        if let Some(h) = &p.hydraulics {
            let _ = writeln!(
                s,
                "valves: rated flow {:.5e} m³/s each, leakage {:.3e} m³/s/Pa, spool {} Hz ζ {} \
                 delay {:.3e} s (equivalent lag {:.4e} s)",
                h.rated_flow_m3_s,
                h.leakage_m3_s_per_pa,
                h.spool_natural_frequency_hz,
                h.spool_damping_ratio,
                h.valve_delay_s,
                h.equivalent_lag_s
            );
            let _ = writeln!(
                s,
                "oil column: chambers {:.5e} / {:.5e} m³ at β {:.4e} Pa; {:.4} Hz bare, {:.4} \
                 Hz with the specimen",
                h.cap_volume_m3,
                h.rod_volume_m3,
                h.oil_bulk_modulus_pa,
                h.oil_column_frequency_hz,
                h.oil_column_frequency_with_specimen_hz
            );
        }
        for pr in &p.predictions {
            let _ = writeln!(
                s,
                "{} {}: the identified loop on its command: table acceleration RMS error \
                 {:.4} m/s² of {:.4} (noise ≈ {:.4}), displacement {:.3e} m of {:.3e}",
                if pr.fitted { "fitted  " } else { "held out" },
                pr.name,
                pr.acceleration_rms_error_m_s2,
                pr.acceleration_rms_m_s2,
                pr.acceleration_noise_m_s2,
                pr.displacement_rms_error_m,
                pr.displacement_rms_m
            );
        }
    }
    for (what, why) in &id.not_identified {
        let _ = writeln!(s, "not identified: {what}: {why}");
    }
    let _ = writeln!(
        s,
        "scenario (with --json): {}",
        if identified_system.is_some() {
            "the identified model, table system and specimen"
        } else {
            "the lhpost-2008 preset with the identified controller"
        }
    );
    outln!("{}", s.trim_end());
    Ok(())
}

/// `--base`: a scenario with a `table_system`, or a `table_system` object, validated as a
/// scenario would validate it (commanded by `record`'s command); its stroke limit if given.
fn load_base(
    path: &Path,
    record: &Path,
    map: &ColumnMap,
) -> Result<(platen_system::TableSystem, Option<f64>)> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("--base {}: cannot read it", path.display()))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("--base {}: not JSON", path.display()))?;
    let (spec, stroke) = match value.get("table_system") {
        Some(ts) => (
            ts.clone(),
            value.pointer("/limits/stroke_m").and_then(|v| v.as_f64()),
        ),
        None => (value.clone(), None),
    };
    let record = std::fs::canonicalize(record).unwrap_or_else(|_| record.to_path_buf());
    // Validated with a tiny stroke: the base's volumes are replaced by the fitted ones.
    let scenario = serde_json::json!({
        "model": { "preset": "lhpost-2008" },
        "table_system": spec,
        "limits": { "stroke_m": stroke.unwrap_or(1e-3) },
        "excitation": {
            "motion_csv": record.display().to_string(),
            "columns": { "u_m": { "name": map.header("command_u_m") } }
        },
    });
    let file = platen_scenario::file::parse(path, &scenario.to_string())
        .with_context(|| format!("--base {}: not a table system", path.display()))?;
    let s = platen_scenario::Scenario::from_file(path, file)
        .with_context(|| format!("--base {}: not a table system", path.display()))?;
    let Some(cl) = s.closed_loop else {
        bail!("--base {}: no table_system in it", path.display());
    };
    Ok((cl.system, stroke))
}
