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

use std::path::Path;
use std::time::Instant;

use anyhow::{anyhow, Result};

use platen_integrate::IntegrateError;
use platen_io::write_bytes_atomic;
use platen_model::{IdentifiedKey, PhysicalKey};
use platen_report::simulate_report::with_outputs;
use platen_scenario::sweep::{self, Outcome, Sweep};
use platen_scenario::{ModelKey, Run, Scenario};

pub use platen_scenario::sweep::SetAxis;

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

/// Where `platen sweep` writes its figures, and their size.
pub struct Plot<'a> {
    /// Folder for the figures (SVG and PNG).
    pub dir: Option<&'a Path>,
    /// Size of the figures.
    pub size: platen_report::FigureSize,
}

/// Runs every case of the grid over the scenario at `path` and reports one row per case.
pub fn run(
    path: &Path,
    scales: &[f64],
    pressures_mpa: &[f64],
    sets: &[SetAxis],
    out: Option<&Path>,
    json_out: bool,
    plot: &Plot<'_>,
) -> Result<()> {
    let scenario = Scenario::load(path)?;
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
    let grid = Sweep::new(&scenario, scales, pressures_mpa, sets)?;
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
        plot.dir,
        None,
        &plot.size,
        || platen_report::sweep_figures::figures(&scenario, set_names, cases, &outcomes),
        |_, _| String::new(),
    )?;
    if json_out {
        let summary = sweep::json_summary(path, &scenario, set_names, cases, &outcomes, out);
        let figures = plot.dir.map(|_| written.as_slice());
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
        let figures = plot.dir.map(|_| written.as_slice());
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

/// A form mismatch or an axis given twice is a usage error (exit code 2).
fn check_axes(path: &Path, scenario: &Scenario, sets: &[SetAxis]) {
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
