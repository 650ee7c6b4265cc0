//! `platen sweep`: run the Cartesian product of excitation scales, hold-down pressures and
//! model parameters over one scenario, in parallel on every core, one summary row per case.
//!
//! * The scenario is loaded and validated once ([`PlatenScenario::load`]); each case's model is
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

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, Result};

use platen_integrate::IntegrateError;
use platen_io::write_bytes_atomic;
use platen_model::{IdentifiedKey, PhysicalKey};
use platen_report::simulate_report::with_outputs;
use platen_scenario::sweep::{self, Outcome, Sweep};
use platen_scenario::{ModelKey, PlatenScenario, Run};

pub use platen_scenario::sweep::SetAxis;

use crate::{plot, usage};

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

/// `--pressure-mpa`: a finite pressure `>= 0`, MPa, at most 100 MPa (a larger one is a
/// pressure in another unit: [`platen_scenario::units::check_pressure_mpa`]).
pub fn parse_pressure_mpa(s: &str) -> std::result::Result<f64, String> {
    platen_scenario::units::check_pressure_mpa(parse_number(s)?)
}

/// `--set`: `identified.KEY=V1,V2,…` or `full.KEY=V1,V2,…` with a key the form has.
pub fn parse_set(s: &str) -> std::result::Result<SetAxis, String> {
    let Some((name, values)) = s.split_once('=') else {
        return Err(format!(
            "`{s}`: expected FORM.NAME=V1,V2,… (e.g. identified.coulomb_force_n=20e3,25e3)"
        ));
    };
    let name = name.trim();
    let (full, key) = match name.split_once('.') {
        Some(("identified", key)) => (false, key),
        Some(("full", key)) => (true, key),
        _ => {
            return Err(format!(
                "`{name}`: expected identified.NAME or full.NAME (e.g. identified.coulomb_force_n)"
            ))
        }
    };
    let key = if full {
        PhysicalKey::from_name(key).map(ModelKey::Full)
    } else {
        IdentifiedKey::from_name(key).map(ModelKey::Identified)
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
    Ok(SetAxis {
        name: name.to_owned(),
        key,
        values,
    })
}

/// The arguments of `platen sweep`.
#[derive(clap::Args)]
pub struct SweepArgs {
    /// Scenario JSON file.
    scenario: PathBuf,
    /// Factors multiplying the excitation (the force record, or the prescribed motion),
    /// comma separated: --scale 0.5,1,1.5.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = parse_scale)]
    scale: Vec<f64>,
    /// Hold-down nitrogen pressures, MPa, comma separated: --pressure-mpa 0,6.9,13.8.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, value_parser = parse_pressure_mpa)]
    pressure_mpa: Vec<f64>,
    /// A model parameter and its values, repeatable: --set identified.coulomb_force_n=20e3,25e3
    /// or --set full.platen_mass_kg=130e3,140e3 (the scenario's form: identified or full).
    #[arg(long = "set", value_name = "FORM.NAME=V1,V2,…", value_parser = parse_set)]
    set: Vec<SetAxis>,
    /// Write one row per case to this CSV file (written atomically when all cases are done).
    #[arg(long, value_parser = usage::OutFile("cases.csv"))]
    out: Option<PathBuf>,
    /// Print a machine-readable summary of every case on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write figures to this folder as SVG and PNG: for each axis with two or more
    /// values, the peaks of every case against it with the table's limits.
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    #[command(flatten)]
    size: plot::SizeArgs,
}

/// Runs every case of the grid over the scenario and reports one row per case.
pub fn run(args: &SweepArgs) -> Result<()> {
    let size = args.size.size();
    let (path, out) = (args.scenario.as_path(), args.out.as_deref());
    let scenario = load(path, &args.set)?;
    let grid = Sweep::new(&scenario, &args.scale, &args.pressure_mpa, &args.set)?;
    let progress = crate::progress::Progress::new(
        grid.cases.len() as u64,
        "{bar:40} {pos}/{len} cases  {elapsed_precise} elapsed, {eta} left",
    );
    let start = Instant::now();
    let outcomes = grid.run(&scenario.run, || progress.inc());
    progress.finish();
    let wall_s = start.elapsed().as_secs_f64();

    let (cases, set_names) = (&grid.cases, &grid.set_names);
    if let Some(out) = out {
        let csv = sweep::csv_text(&scenario, set_names, cases, &outcomes);
        write_bytes_atomic(out, csv.as_bytes())?;
    }
    let written = platen_report::write_outputs(
        args.plot.as_deref(),
        None,
        &size,
        || platen_report::sweep_figures::figures(&scenario, set_names, cases, &outcomes),
        |_, _| String::new(),
    )?;
    let figures = args.plot.as_ref().map(|_| written.as_slice());
    if args.json {
        let summary = sweep::json_summary(path, &scenario, set_names, cases, &outcomes, out);
        let summary = with_outputs(summary, figures, None);
        outln!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        let run = platen_report::sweep_report::SweepRun {
            scenario: &scenario,
            set_names,
            cases,
            outcomes: &outcomes,
            out,
        };
        out!("{}", platen_report::sweep_report::sweep_text(&run, figures));
        // How long it took is a diagnostic (stderr), so the summary's bytes are the same on
        // every run and every machine.
        eprintln!(
            "{} cases in {wall_s:.2} s on {} threads",
            cases.len(),
            rayon::current_num_threads()
        );
    }
    failures(&outcomes, out.is_some())
}

/// Loads the scenario at `path` and checks that it can be swept with the `--set` axes:
/// no specimen, no closed loop, axes of its form, and a base case that is its own model.
fn load(path: &Path, sets: &[SetAxis]) -> Result<PlatenScenario> {
    let scenario = PlatenScenario::load(path)?;
    if scenario.rig.specimen.is_some() {
        anyhow::bail!(
            "{}: sweeps of a scenario with a specimen are not supported yet (simulate runs it)",
            path.display()
        );
    }
    if let Run::ClosedLoop { .. } = scenario.run {
        anyhow::bail!(
            "{}: sweeps of a closed-loop scenario (a table_system) are not supported yet \
             (simulate runs it)",
            path.display()
        );
    }
    check_axes(path, &scenario, sets);
    // The base case must reproduce the scenario's own model exactly.
    let base = scenario
        .rig
        .model_at(scenario.rig.hold_down_pressure_pa, &[])?;
    if base != scenario.rig.model {
        return Err(anyhow!(
            "internal error: the sweep's model differs from the scenario's ({})",
            path.display()
        ));
    }
    Ok(scenario)
}

/// A form mismatch or an axis given twice is a usage error (exit code 2).
fn check_axes(path: &Path, scenario: &PlatenScenario, sets: &[SetAxis]) {
    let form = scenario.rig.overrides.form();
    for (i, axis) in sets.iter().enumerate() {
        if axis.key.form() != form {
            usage_error(format!(
                "--set {}: the scenario `{}` runs the {} model; set {}.NAME parameters instead \
                 (a `full` object in the scenario's model selects the full model)",
                axis.name,
                path.display(),
                form,
                form,
            ));
        }
        if sets[..i].iter().any(|other| other.key == axis.key) {
            usage_error(format!("--set {} is given twice", axis.name));
        }
    }
}

/// Exit code 4 when any case failed numerically, naming how many and the first.
fn failures(outcomes: &[Outcome], wrote: bool) -> Result<()> {
    let failed: Vec<(usize, &IntegrateError)> = outcomes
        .iter()
        .enumerate()
        .filter_map(|(i, o)| o.error.as_ref().map(|e| (i, e)))
        .collect();
    if let Some(&(first, error)) = failed.first() {
        return Err(anyhow::Error::new(error.clone()).context(format!(
            "{} of {} cases failed (first: case {first}); see their status{}",
            failed.len(),
            outcomes.len(),
            if wrote { " in the output" } else { "" }
        )));
    }
    Ok(())
}

/// Reports a bad command line the way clap does (exit code 2) and exits.
fn usage_error(message: String) -> ! {
    clap::Error::raw(clap::error::ErrorKind::ArgumentConflict, message + "\n").exit()
}
