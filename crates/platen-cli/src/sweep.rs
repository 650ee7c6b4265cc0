//! `platen sweep`: run the Cartesian product of excitation scales, hold-down pressures and
//! model parameters over one scenario, in parallel on every core, one summary row per case.
//!
//! * The scenario is loaded and validated once ([`Scenario::load`]); each case's model is
//!   rebuilt from the preset at the case's pressure, with the scenario's own `identified` or
//!   `full` overrides laid over it (read from the file's JSON) and then the case's `--set`
//!   values. With no axis given the single case is the scenario itself (checked).
//! * Every model is built, and so validated, before any case runs: a bad value is reported
//!   with its case and exits with code 3, and nothing is written.
//! * A case keeps only the [`Peaks`] of its run and its [`RunStats`], so its memory is that
//!   of its input record, whatever the record's length. The rows are collected in case
//!   order, so the output has the same bytes whatever the number of threads
//!   (`RAYON_NUM_THREADS`).
//! * A case that fails numerically is reported in its row's `status`; the other cases still
//!   run, the output is written, and the command exits with code 4.

use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use anyhow::{anyhow, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde_json::{json, Map, Value};

use platen_integrate::{IntegrateError, Peaks, RunStats};
use platen_io::write_bytes_atomic;
use platen_model::{IdentifiedKey, PhysicalKey};
use platen_scenario::{Model, ModelKey, Run, Scenario};

use platen_io::csv::write_number;

/// Which form of the model a parameter belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    Identified,
    Full,
}

impl Form {
    fn name(self) -> &'static str {
        match self {
            Form::Identified => "identified",
            Form::Full => "full",
        }
    }
}

/// One `--set FORM.KEY=V1,V2,…` axis.
#[derive(Debug, Clone, PartialEq)]
pub struct SetAxis {
    pub form: Form,
    pub key: ModelKey,
    pub values: Vec<f64>,
}

impl SetAxis {
    /// `FORM.KEY`, the column name of the axis.
    fn name(&self) -> String {
        format!("{}.{}", self.form.name(), self.key.name())
    }
}

fn parse_number(s: &str) -> std::result::Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("`{s}` is not a finite number")),
    }
}

/// `--scale`: a finite factor.
pub fn parse_scale(s: &str) -> std::result::Result<f64, String> {
    parse_number(s)
}

/// `--pressure-mpa`: a finite pressure `>= 0`, MPa.
pub fn parse_pressure_mpa(s: &str) -> std::result::Result<f64, String> {
    let p = parse_number(s)?;
    if p >= 0.0 {
        Ok(p)
    } else {
        Err(format!("{p} MPa: expected a pressure >= 0"))
    }
}

/// `--set`: `identified.KEY=V1,V2,…` or `full.KEY=V1,V2,…` with a key the form has.
pub fn parse_set(s: &str) -> std::result::Result<SetAxis, String> {
    let Some((name, values)) = s.split_once('=') else {
        return Err(format!(
            "`{s}`: expected FORM.NAME=V1,V2,… (e.g. identified.coulomb_force_n=20e3,25e3)"
        ));
    };
    let name = name.trim();
    let (form, key) = match name.split_once('.') {
        Some(("identified", key)) => (Form::Identified, key),
        Some(("full", key)) => (Form::Full, key),
        _ => {
            return Err(format!(
                "`{name}`: expected identified.NAME or full.NAME (e.g. identified.coulomb_force_n)"
            ))
        }
    };
    let key = match form {
        Form::Identified => IdentifiedKey::from_name(key).map(ModelKey::Identified),
        Form::Full => PhysicalKey::from_name(key).map(ModelKey::Full),
    }
    .map_err(|e| {
        format!(
            "`{name}`: {e}{}",
            if key == "hold_down_pressure_pa" || key == "hold_down_pressure_mpa" {
                " (the pressure has its own axis: --pressure-mpa)"
            } else {
                ""
            }
        )
    })?;
    let values = values
        .split(',')
        .map(parse_number)
        .collect::<std::result::Result<Vec<f64>, String>>()
        .map_err(|e| format!("`{name}`: {e}"))?;
    Ok(SetAxis { form, key, values })
}

/// One case of the grid.
struct Case {
    scale: f64,
    pressure_mpa: f64,
    /// One value per `--set` axis.
    sets: Vec<f64>,
    model: Model,
}

/// What a case produced.
struct Outcome {
    peaks: Peaks,
    stats: Option<RunStats>,
    error: Option<IntegrateError>,
}

/// Runs every case of the grid over the scenario at `path` and reports one row per case.
pub fn run(
    path: &Path,
    scales: &[f64],
    pressures_mpa: &[f64],
    sets: &[SetAxis],
    out: Option<&Path>,
    json_out: bool,
) -> Result<()> {
    let scenario = Scenario::load(path)?;
    let form = match scenario.model {
        Model::Identified(_) => Form::Identified,
        Model::Full(_) => Form::Full,
    };
    for (i, axis) in sets.iter().enumerate() {
        if axis.form != form {
            usage_error(format!(
                "--set {}: the scenario `{}` runs the {} model; set {}.NAME parameters instead \
                 (a `full` object in the scenario's model selects the full model)",
                axis.name(),
                path.display(),
                form.name(),
                form.name(),
            ));
        }
        if sets[..i].iter().any(|other| other.key == axis.key) {
            usage_error(format!("--set {} is given twice", axis.name()));
        }
    }

    // The base case must reproduce the scenario's own model exactly.
    let base_pressure_mpa = scenario.hold_down_pressure_pa / 1e6;
    let base = scenario.model_at(scenario.hold_down_pressure_pa, &[])?;
    if base != scenario.model {
        return Err(anyhow!(
            "internal error: the sweep's model differs from the scenario's ({})",
            path.display()
        ));
    }

    let scales = if scales.is_empty() {
        &[1.0][..]
    } else {
        scales
    };
    let pressures: Vec<(f64, f64)> = if pressures_mpa.is_empty() {
        vec![(base_pressure_mpa, scenario.hold_down_pressure_pa)]
    } else {
        pressures_mpa.iter().map(|&p| (p, p * 1e6)).collect()
    };
    let mut cases = Vec::new();
    for &scale in scales {
        for &(pressure_mpa, pressure_pa) in &pressures {
            for combo in product(sets) {
                let named: Vec<(ModelKey, f64)> = sets
                    .iter()
                    .zip(&combo)
                    .map(|(axis, &v)| (axis.key, v))
                    .collect();
                let model = scenario.model_at(pressure_pa, &named).with_context(|| {
                    format!(
                        "case {} ({}): the model cannot be built; nothing was run",
                        cases.len(),
                        describe(scale, pressure_mpa, sets, &combo)
                    )
                })?;
                cases.push(Case {
                    scale,
                    pressure_mpa,
                    sets: combo,
                    model,
                });
            }
        }
    }

    let progress = progress_bar(cases.len());
    let start = Instant::now();
    let outcomes: Vec<Outcome> = cases
        .par_iter()
        .map(|case| {
            let outcome = run_case(case, &scenario.run);
            progress.inc(1);
            outcome
        })
        .collect();
    progress.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();

    let set_names: Vec<String> = sets.iter().map(SetAxis::name).collect();
    if let Some(out) = out {
        let csv = csv_text(&scenario, &set_names, &cases, &outcomes);
        write_bytes_atomic(out, csv.as_bytes())?;
    }
    if json_out {
        let summary = json_summary(path, &scenario, &set_names, &cases, &outcomes, out);
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_summary(&scenario, &set_names, &cases, &outcomes, out, wall_s);
    }

    let failed: Vec<(usize, &IntegrateError)> = outcomes
        .iter()
        .enumerate()
        .filter_map(|(i, o)| o.error.as_ref().map(|e| (i, e)))
        .collect();
    if let Some(&(first, error)) = failed.first() {
        return Err(anyhow::Error::new(error.clone()).context(format!(
            "{} of {} cases failed (first: case {first}); see their status{}",
            failed.len(),
            cases.len(),
            if out.is_some() { " in the output" } else { "" }
        )));
    }
    Ok(())
}

/// Reports a bad command line the way clap does (exit code 2) and exits.
fn usage_error(message: String) -> ! {
    clap::Error::raw(clap::error::ErrorKind::ArgumentConflict, message + "\n").exit()
}

/// Every combination of the `--set` axes' values, the last axis varying fastest.
fn product(sets: &[SetAxis]) -> Vec<Vec<f64>> {
    let mut combos = vec![Vec::new()];
    for axis in sets {
        combos = combos
            .into_iter()
            .flat_map(|prefix| {
                axis.values.iter().map(move |&v| {
                    let mut c = prefix.clone();
                    c.push(v);
                    c
                })
            })
            .collect();
    }
    combos
}

fn describe(scale: f64, pressure_mpa: f64, sets: &[SetAxis], values: &[f64]) -> String {
    let mut s = format!("scale {scale}, {pressure_mpa} MPa");
    for (axis, v) in sets.iter().zip(values) {
        let _ = write!(s, ", {} = {v}", axis.name());
    }
    s
}

/// A progress bar on stderr when it is a terminal and `CI` is not set; hidden otherwise.
fn progress_bar(cases: usize) -> ProgressBar {
    if !std::io::stderr().is_terminal() || std::env::var_os("CI").is_some() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(cases as u64);
    if let Ok(style) = ProgressStyle::with_template(
        "{bar:40} {pos}/{len} cases  {elapsed_precise} elapsed, {eta} left",
    ) {
        bar.set_style(style);
    }
    bar
}

/// Runs one case: its model under the scenario's excitation multiplied by its scale,
/// keeping only the peaks.
fn run_case(case: &Case, run: &Run) -> Outcome {
    let run = match run.scaled(case.scale) {
        Ok(run) => run,
        Err(e) => return failed(e),
    };
    let mut peaks = Peaks::default();
    match case.model.run(&run, &mut peaks) {
        Ok(output) => Outcome {
            peaks,
            stats: output.stats,
            error: None,
        },
        Err(e) => failed(e),
    }
}

fn failed(e: IntegrateError) -> Outcome {
    Outcome {
        peaks: Peaks::default(),
        stats: None,
        error: Some(e),
    }
}

/// `"stroke;velocity"`, or `"none"`.
fn exceeded(scenario: &Scenario, peaks: &Peaks) -> String {
    let names: Vec<&str> = peaks
        .exceedances(&scenario.limits)
        .iter()
        .map(|e| e.quantity)
        .collect();
    if names.is_empty() {
        "none".to_owned()
    } else {
        names.join(";")
    }
}

fn status(outcome: &Outcome) -> String {
    match &outcome.error {
        None => "ok".to_owned(),
        Some(e) => format!("failed: {e}"),
    }
}

/// A CSV field holding free text, quoted when it needs to be.
fn text_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// Column names of the sweep CSV.
fn header(set_names: &[String]) -> Vec<String> {
    let mut h = vec![
        "case".to_owned(),
        "scale".to_owned(),
        "hold_down_pressure_mpa".to_owned(),
    ];
    h.extend(set_names.iter().cloned());
    h.extend(
        [
            "peak_u_m",
            "peak_v_m_s",
            "peak_a_m_s2",
            "peak_force_n",
            "stick_time_s",
            "events",
            "limits_exceeded",
            "status",
        ]
        .map(str::to_owned),
    );
    h
}

/// The sweep CSV: one row per case in case order. Numbers in the shortest round-trip form of
/// the time-series CSVs; `stick_time_s` and `events` are empty for inverse runs, and every
/// result column but `status` is empty for a case that failed.
fn csv_text(scenario: &Scenario, set_names: &[String], cases: &[Case], outs: &[Outcome]) -> String {
    let mut text = header(set_names).join(",");
    text.push('\n');
    let mut buf = Vec::new();
    let mut number = |text: &mut String, v: f64| {
        buf.clear();
        // Writing to a Vec cannot fail.
        let _ = write_number(&mut buf, v);
        text.push_str(std::str::from_utf8(&buf).unwrap_or_default());
        text.push(',');
    };
    for (i, (case, o)) in cases.iter().zip(outs).enumerate() {
        let _ = write!(text, "{i},");
        number(&mut text, case.scale);
        number(&mut text, case.pressure_mpa);
        for &v in &case.sets {
            number(&mut text, v);
        }
        if o.error.is_some() {
            // Peaks up to a numerical failure mean nothing: leave them out.
            let _ = writeln!(text, ",,,,,,,{}", text_field(&status(o)));
            continue;
        }
        for v in [
            o.peaks.u_m.value,
            o.peaks.v_m_s.value,
            o.peaks.a_m_s2.value,
            o.peaks.force_n.value,
        ] {
            number(&mut text, v);
        }
        match &o.stats {
            Some(st) => {
                number(&mut text, st.stick_time_s);
                let _ = write!(text, "{},", st.events());
            }
            None => text.push_str(",,"),
        }
        let _ = writeln!(
            text,
            "{},{}",
            exceeded(scenario, &o.peaks),
            text_field(&status(o))
        );
    }
    text
}

fn json_summary(
    path: &Path,
    scenario: &Scenario,
    set_names: &[String],
    cases: &[Case],
    outs: &[Outcome],
    out: Option<&Path>,
) -> Value {
    let rows: Vec<Value> = cases
        .iter()
        .zip(outs)
        .enumerate()
        .map(|(i, (case, o))| {
            let mut m = Map::new();
            m.insert("case".into(), json!(i));
            m.insert("scale".into(), json!(case.scale));
            m.insert("hold_down_pressure_mpa".into(), json!(case.pressure_mpa));
            let set: Map<String, Value> = set_names
                .iter()
                .zip(&case.sets)
                .map(|(n, v)| (n.clone(), json!(v)))
                .collect();
            m.insert("set".into(), Value::Object(set));
            m.insert("status".into(), json!(status(o)));
            if o.error.is_some() {
                return Value::Object(m);
            }
            for (key, peak) in [
                ("peak_u_m", o.peaks.u_m),
                ("peak_v_m_s", o.peaks.v_m_s),
                ("peak_a_m_s2", o.peaks.a_m_s2),
                ("peak_force_n", o.peaks.force_n),
            ] {
                m.insert(key.into(), json!(peak.value));
                m.insert(format!("{key}_t_s"), json!(peak.t_s));
            }
            m.insert(
                "stick_time_s".into(),
                json!(o.stats.map(|s| s.stick_time_s)),
            );
            m.insert("events".into(), json!(o.stats.map(|s| s.events())));
            let exceed: Vec<Value> = o
                .peaks
                .exceedances(&scenario.limits)
                .iter()
                .map(|e| json!({"quantity": e.quantity, "peak": e.peak, "limit": e.limit, "t_s": e.t_s}))
                .collect();
            m.insert("limit_exceedances".into(), Value::Array(exceed));
            Value::Object(m)
        })
        .collect();
    json!({
        "scenario": path.display().to_string(),
        "name": scenario.name,
        "direction": match scenario.run { Run::Forward { .. } => "forward", Run::Inverse { .. } => "inverse" },
        "model_form": scenario.model.form(),
        "preset": scenario.preset.name(),
        "cases": cases.len(),
        "failed": outs.iter().filter(|o| o.error.is_some()).count(),
        "exceeding_a_limit": outs
            .iter()
            .filter(|o| o.error.is_none() && !o.peaks.exceedances(&scenario.limits).is_empty())
            .count(),
        "out": out.map(|p| p.display().to_string()),
        "results": rows,
    })
}

fn print_summary(
    scenario: &Scenario,
    set_names: &[String],
    cases: &[Case],
    outs: &[Outcome],
    out: Option<&Path>,
    wall_s: f64,
) {
    println!(
        "{}: {} cases ({} model, {}) in {wall_s:.2} s on {} threads",
        scenario.name,
        cases.len(),
        scenario.model.form(),
        scenario.preset.name(),
        rayon::current_num_threads()
    );
    let mut head = format!("  {:>5} {:>8} {:>8}", "case", "scale", "MPa");
    for n in set_names {
        let _ = write!(head, " {n:>14}");
    }
    let _ = write!(
        head,
        " {:>9} {:>9} {:>8} {:>10} {:>8} {:>6}  limits exceeded",
        "u (m)", "v (m/s)", "a (g)", "F (kN)", "stick s", "events"
    );
    println!("{head}");
    for (i, (case, o)) in cases.iter().zip(outs).enumerate() {
        let mut line = format!("  {i:>5} {:>8} {:>8}", case.scale, case.pressure_mpa);
        for v in &case.sets {
            let _ = write!(line, " {v:>14}");
        }
        if let Some(e) = &o.error {
            let _ = write!(line, "  FAILED: {e}");
            println!("{line}");
            continue;
        }
        let (stick, events) = match &o.stats {
            Some(s) => (format!("{:.3}", s.stick_time_s), s.events().to_string()),
            None => ("-".to_owned(), "-".to_owned()),
        };
        let _ = write!(
            line,
            " {:>+9.4} {:>+9.4} {:>+8.3} {:>+10.1} {stick:>8} {events:>6}  {}",
            o.peaks.u_m.value,
            o.peaks.v_m_s.value,
            o.peaks.a_m_s2.value / platen_model::STANDARD_GRAVITY_M_S2,
            o.peaks.force_n.value / 1e3,
            exceeded(scenario, &o.peaks),
        );
        println!("{line}");
    }
    if let Some(out) = out {
        println!("  wrote {}", out.display());
    }
}
