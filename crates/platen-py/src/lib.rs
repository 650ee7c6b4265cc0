//! `platen._platen`: the native module behind the `platen` Python package (PyO3, abi3 for
//! CPython ≥ 3.9, built by maturin from the repository's `pyproject.toml`).
//!
//! This crate only converts: Python arguments to the library's types, the library's results
//! to NumPy arrays and JSON text, and its errors to one exception,
//! [`error::Failure`]`(kind, message)`, whose message is the CLI's. Everything is computed
//! by the library crates ([`platen_scenario::PlatenScenario::run`], [`platen_compare`],
//! [`platen_ident`], [`platen_scenario::sweep`], [`platen_plan`]), with the GIL released and
//! panics caught.
//! The public API, its checks of Python values (dtypes, shapes, dicts) and its docstrings
//! live in `python/platen/__init__.py`.
//!
//! Scenarios come as a file path, or as JSON text made from a dict together with an
//! `origin` that names it in messages (`scenario dict`); relative paths inside resolve
//! against the origin's folder, the working directory.

pub mod error;
mod identify;
mod plan;

use std::path::{Path, PathBuf};

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use platen_compare::{Comparison, Direction, Recording, Settings, Window};
use platen_io::columns::ColumnMap;
use platen_model::{IdentifiedKey, PhysicalKey, Preset};
use platen_scenario::sweep::{csv_text, json_summary, SetAxis, Sweep};
use platen_scenario::{file, Arrays, ModelKey, PlatenScenario, Scenario};

use crate::error::{detached, Fail, Kind};

/// What a run hands to Python: the column names, one float64 array per column (moved, not
/// copied), and the summary as JSON text (keys in alphabetical order, as `--json`).
type RunParts<'py> = (Vec<String>, Vec<Bound<'py, PyArray1<f64>>>, String);

/// A scenario given as a file (`path`) or as JSON text named `origin`.
fn load(
    path: Option<&Path>,
    text: Option<&str>,
    origin: &str,
) -> Result<(PathBuf, PlatenScenario), Fail> {
    match (path, text) {
        (Some(path), _) => Ok((path.to_owned(), PlatenScenario::load(path)?)),
        (None, Some(text)) => {
            let origin = PathBuf::from(origin);
            let parsed = file::parse(&origin, text)?;
            Ok((origin.clone(), PlatenScenario::from_file(&origin, parsed)?))
        }
        (None, None) => Err(Fail::input("no scenario: give a path or a dict")),
    }
}

/// JSON text of a serialisable value, through a `Value` so that keys are sorted.
fn json_text<T: serde::Serialize>(value: &T) -> Result<String, Fail> {
    serde_json::to_value(value)
        .and_then(|v| serde_json::to_string(&v))
        .map_err(|e| {
            Fail::new(
                Kind::Internal,
                format!("internal error: summary to JSON: {e}"),
            )
        })
}

/// A run's columns by name, in the CSV's order, and its summary as JSON text.
type Columns = (Vec<(String, Vec<f64>)>, String);

/// Runs `scenario` (named `path` in its summary), keeping every output column: the
/// columns by name and the summary's JSON text.
fn run_scenario(scenario: &Scenario, path: &Path) -> Result<Columns, Fail> {
    let (columns, summary) = scenario.run_at(path)?.into_columns();
    Ok((columns, json_text(&summary)?))
}

/// A run's columns as NumPy arrays that take over its vectors, in the CSV's order.
fn to_python(py: Python<'_>, (columns, summary): Columns) -> RunParts<'_> {
    let (names, arrays) = columns
        .into_iter()
        .map(|(name, column)| (name, column.into_pyarray(py)))
        .unzip();
    (names, arrays, summary)
}

/// Runs a scenario file or a scenario dict's JSON text: `platen.simulate`.
#[pyfunction]
#[pyo3(signature = (path, text, origin))]
fn simulate<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    text: Option<String>,
    origin: String,
) -> PyResult<RunParts<'py>> {
    let (path, parsed) = match (path, text) {
        (Some(path), _) => {
            let parsed: file::ScenarioFile =
                platen_io::json::parse_json_file(&path).map_err(Fail::from)?;
            (path, parsed)
        }
        (None, Some(text)) => {
            let origin = PathBuf::from(&origin);
            let parsed = file::parse(&origin, &text).map_err(Fail::from)?;
            (origin, parsed)
        }
        (None, None) => return Err(Fail::input("no scenario: give a path or a dict").into()),
    };
    let parts = detached(py, move || {
        let scenario = Scenario::from_file(&path, parsed)?;
        run_scenario(&scenario, &path)
    })?;
    Ok(to_python(py, parts))
}

/// Copies a contiguous float64 array (the package makes it one).
fn vector(a: &PyReadonlyArray1<'_, f64>) -> PyResult<Vec<f64>> {
    Ok(a.as_slice()?.to_vec())
}

/// Runs the settings `text` (the scenario format, excitation without a source) on `arrays`.
fn run_arrays<'py>(
    py: Python<'py>,
    text: String,
    origin: String,
    arrays: Arrays,
) -> PyResult<RunParts<'py>> {
    let parts = detached(py, move || {
        let origin = PathBuf::from(origin);
        let settings = file::parse(&origin, &text)?;
        let scenario = PlatenScenario::from_arrays(&origin, settings, arrays)?;
        run_scenario(&Scenario::Platen(scenario), &origin)
    })?;
    Ok(to_python(py, parts))
}

/// A forward run of the force `force_n` sampled at `t_s`: `platen.forward`.
#[pyfunction]
fn forward<'py>(
    py: Python<'py>,
    text: String,
    origin: String,
    t_s: PyReadonlyArray1<'py, f64>,
    force_n: PyReadonlyArray1<'py, f64>,
) -> PyResult<RunParts<'py>> {
    let arrays = Arrays::Force {
        t_s: vector(&t_s)?,
        force_n: vector(&force_n)?,
    };
    run_arrays(py, text, origin, arrays)
}

/// An inverse run of the motion `u_m` (and `v_m_s`, `a_m_s2`) at `t_s`: `platen.inverse`.
#[pyfunction]
#[pyo3(signature = (text, origin, t_s, u_m, v_m_s, a_m_s2))]
fn inverse<'py>(
    py: Python<'py>,
    text: String,
    origin: String,
    t_s: PyReadonlyArray1<'py, f64>,
    u_m: PyReadonlyArray1<'py, f64>,
    v_m_s: Option<PyReadonlyArray1<'py, f64>>,
    a_m_s2: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<RunParts<'py>> {
    let arrays = Arrays::Motion {
        t_s: vector(&t_s)?,
        u_m: vector(&u_m)?,
        v_m_s: v_m_s.as_ref().map(vector).transpose()?,
        a_m_s2: a_m_s2.as_ref().map(vector).transpose()?,
    };
    run_arrays(py, text, origin, arrays)
}

/// A preset's description as JSON text: `platen.model`, the object of `platen model --json`.
#[pyfunction]
#[pyo3(signature = (preset, pressure_mpa, full))]
fn model(preset: &str, pressure_mpa: Option<f64>, full: bool) -> PyResult<String> {
    let preset = Preset::from_name(preset).map_err(Fail::from)?;
    let pressure_pa = match pressure_mpa {
        Some(p) if platen_scenario::units::expected_pressure_mpa(p).is_some() => {
            return Err(Fail::input(format!(
                "pressure_mpa = {}",
                platen_scenario::units::check_pressure_mpa(p).unwrap_err()
            ))
            .into())
        }
        Some(p) => p * 1e6,
        None => preset.nominal_pressure_pa(),
    };
    let description =
        platen_scenario::describe_model(preset, pressure_pa, full).map_err(Fail::from)?;
    Ok(json_text(&description)?)
}

/// A column map from a JSON file or from a dict's JSON text (named `columns=`).
fn column_map(path: Option<&Path>, text: Option<&str>) -> Result<ColumnMap, Fail> {
    Ok(match (path, text) {
        (Some(path), _) => ColumnMap::load(path)?,
        (None, Some(text)) => ColumnMap::from_json(Path::new("columns="), text)?,
        (None, None) => ColumnMap::default(),
    })
}

/// A scenario against a recorded test: `platen.compare`, the object of `platen compare
/// --json`.
#[pyfunction]
#[pyo3(signature = (path, text, origin, recorded, columns_path, columns_text, window, max_lag_s))]
#[allow(clippy::too_many_arguments)]
fn compare(
    py: Python<'_>,
    path: Option<PathBuf>,
    text: Option<String>,
    origin: String,
    recorded: PathBuf,
    columns_path: Option<PathBuf>,
    columns_text: Option<String>,
    window: Option<(f64, f64)>,
    max_lag_s: f64,
) -> PyResult<String> {
    Ok(detached(py, move || {
        let (path, scenario) = load(path.as_deref(), text.as_deref(), &origin)?;
        let map = column_map(columns_path.as_deref(), columns_text.as_deref())?;
        let recording = Recording::read(&recorded, Direction::of(&scenario), &map)?;
        let settings = Settings {
            window: window.map(|(start_s, end_s)| Window { start_s, end_s }),
            max_lag_s,
        };
        let comparison = Comparison::new(&scenario, &path, recording, &settings)?;
        json_text(&comparison.summary(&[], None))
    })?)
}

/// `identified.KEY` or `full.KEY` as a sweep axis over `values`.
fn set_axis(name: String, values: Vec<f64>, form: &str) -> Result<SetAxis, Fail> {
    let key = match name.split_once('.') {
        Some(("identified", key)) => IdentifiedKey::from_name(key).map(ModelKey::Identified),
        Some(("full", key)) => PhysicalKey::from_name(key).map(ModelKey::Full),
        _ => {
            return Err(Fail::input(format!(
                "set: `{name}`: expected identified.NAME or full.NAME (e.g. identified.coulomb_force_n)"
            )))
        }
    }
    .map_err(|e| Fail::input(format!("set: `{name}`: {e}")))?;
    if key.form() != form {
        return Err(Fail::input(format!(
            "set: `{name}`: the scenario runs the {form} model; set {form}.NAME parameters instead \
             (a `full` object in the scenario's model selects the full model)"
        )));
    }
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(Fail::input(format!(
            "set: `{name}`: {v} is not a finite number"
        )));
    }
    Ok(SetAxis { name, key, values })
}

/// A grid of variants of a scenario, run in parallel on every core: `platen.sweep`. Returns
/// the CSV `platen sweep --out` writes and the JSON `--json` prints.
#[pyfunction]
#[pyo3(signature = (path, text, origin, scales, pressures_mpa, sets))]
fn sweep(
    py: Python<'_>,
    path: Option<PathBuf>,
    text: Option<String>,
    origin: String,
    scales: Vec<f64>,
    pressures_mpa: Vec<f64>,
    sets: Vec<(String, Vec<f64>)>,
) -> PyResult<(String, String)> {
    Ok(detached(py, move || {
        let (path, scenario) = load(path.as_deref(), text.as_deref(), &origin)?;
        let form = scenario.rig.overrides.form();
        let mut axes: Vec<SetAxis> = Vec::with_capacity(sets.len());
        for (name, values) in sets {
            let axis = set_axis(name, values, form)?;
            if axes.iter().any(|a| a.key == axis.key) {
                return Err(Fail::input(format!("set: `{}` is given twice", axis.name)));
            }
            axes.push(axis);
        }
        let grid = Sweep::new(&scenario, &scales, &pressures_mpa, &axes)
            .map_err(|e| Fail::of(Kind::Input, &e))?;
        let outcomes = grid.run(&scenario.run, || {});
        let csv = csv_text(&scenario, &grid.set_names, &grid.cases, &outcomes);
        let json = json_summary(
            &path,
            &scenario,
            &grid.set_names,
            &grid.cases,
            &outcomes,
            None,
        );
        Ok((csv, json_text(&json)?))
    })?)
}

/// The JSON Schema of the scenario format, as JSON text: `platen.schema`.
#[pyfunction]
fn schema() -> PyResult<String> {
    Ok(json_text(&file::json_schema())?)
}

/// The native module.
#[pymodule]
fn _platen(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Failure", m.py().get_type::<error::Failure>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(forward, m)?)?;
    m.add_function(wrap_pyfunction!(inverse, m)?)?;
    m.add_function(wrap_pyfunction!(model, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(identify::identify, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan_table, m)?)?;
    m.add_function(wrap_pyfunction!(schema, m)?)?;
    Ok(())
}
