//! `platen.plan`: a target's feasibility, largest scale and drive on a scenario's closed loop
//! (`platen plan`), from arrays.

use std::path::{Path, PathBuf};

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use platen_plan::{
    FrfSource, NoiseSettings, PlanError, PlanScenario, PlanSettings, PlanTarget, Planned, Target,
};
use platen_scenario::LoadedRig;

use crate::error::{detached, Fail, Kind};
use crate::{json_text, vector};

/// What `plan` hands to Python: the drive's time stamps and displacement (`None` without a
/// drive) and the summary as JSON text.
type PlanParts<'py> = (
    Option<Bound<'py, PyArray1<f64>>>,
    Option<Bound<'py, PyArray1<f64>>>,
    String,
);

impl From<PlanError> for Fail {
    fn from(e: PlanError) -> Self {
        match e {
            PlanError::Scenario(se) => se.into(),
            PlanError::Io(io) => io.into(),
            e @ PlanError::Run { .. } => Fail::of(Kind::Numerical, &e),
            e => Fail::of(Kind::Input, &e),
        }
    }
}

/// Plans the target (`a_m_s2` or `u_m` at `t_s`) on a scenario file or a scenario dict's
/// JSON text: `platen.plan`.
#[pyfunction]
#[pyo3(signature = (path, text, origin, t_s, a_m_s2, u_m, iterations, gain, target_nrmse, frf, band_hz, max_scale, rrs, rrs_damping, iterate_at))]
#[allow(clippy::too_many_arguments)]
pub fn plan<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    text: Option<String>,
    origin: String,
    t_s: PyReadonlyArray1<'py, f64>,
    a_m_s2: Option<PyReadonlyArray1<'py, f64>>,
    u_m: Option<PyReadonlyArray1<'py, f64>>,
    iterations: usize,
    gain: f64,
    target_nrmse: f64,
    frf: String,
    band_hz: Option<(f64, f64)>,
    max_scale: bool,
    rrs: Option<PathBuf>,
    rrs_damping: f64,
    iterate_at: Option<f64>,
) -> PyResult<PlanParts<'py>> {
    let t_s = vector(&t_s)?;
    let a_m_s2 = a_m_s2.as_ref().map(vector).transpose()?;
    let u_m = u_m.as_ref().map(vector).transpose()?;
    let (drive, summary) = detached(py, move || {
        let frf = match frf.as_str() {
            "auto" => FrfSource::Auto,
            "linearised" => FrfSource::Linearised,
            "measured" => FrfSource::Measured(NoiseSettings::default()),
            other => {
                return Err(Fail::input(format!(
                    "frf = {other:?}: expected \"auto\", \"linearised\" or \"measured\""
                )))
            }
        };
        let scenario = match (path, text) {
            (Some(path), _) => PlanScenario::platen(&path, platen_plan::load_rig(&path)?),
            (None, Some(text)) => {
                // As `load_rig` reads a file: the excitation, if any, is ignored.
                let origin = PathBuf::from(&origin);
                let rig = LoadedRig::parse(&origin, &text).map_err(PlanError::from)?;
                PlanScenario::platen(&origin, rig)
            }
            (None, None) => return Err(Fail::input("no scenario: give a path or a dict")),
        };
        let target_origin = Path::new("target");
        let target = match (a_m_s2, u_m) {
            (Some(a), None) => Target::acceleration(target_origin, t_s, a)?,
            (None, Some(u)) => Target::displacement(target_origin, t_s, u)?,
            _ => {
                return Err(Fail::input(
                    "target: give exactly one of target_a_m_s2 and target_u_m",
                ))
            }
        };
        let mut settings =
            PlanSettings::new(iterations, gain, target_nrmse, band_hz, max_scale, false);
        settings.iteration.frf = frf;
        if let Some(f) = rrs {
            settings.read_rrs(&scenario, &f, rrs_damping)?;
        }
        settings.iterate_at = iterate_at;
        let p = platen_plan::plan(
            &scenario,
            &PlanTarget::Platen(target),
            &settings,
            &mut |_| {},
        )?;
        let Planned::Platen(p) = &p else {
            unreachable!("a uniaxial scenario's plan")
        };
        let drive = p.drive().map(|(t, u)| (t.to_vec(), u.to_vec()));
        Ok((drive, json_text(&p.summary(None))?))
    })?;
    Ok(match drive {
        Some((t, u)) => (Some(t.into_pyarray(py)), Some(u.into_pyarray(py)), summary),
        None => (None, None, summary),
    })
}

/// What `plan_table` hands to Python: the drive's time stamps, its six columns (`x_m` …
/// `yaw_rad`) and the summary as JSON text.
type TablePlanParts<'py> = (
    Bound<'py, PyArray1<f64>>,
    Vec<Bound<'py, PyArray1<f64>>>,
    String,
);

/// Plans a three-component target (per axis `(name, kind, values)` at `t_s`, `kind`
/// `acceleration` or `displacement`) on a multi-axis scenario file or dict's JSON text:
/// `platen.plan` with per-axis targets.
#[pyfunction]
#[pyo3(signature = (path, text, origin, t_s, axes, iterations, gain, target_nrmse, band_hz, max_scale, per_axis_scale, rrs, rrs_damping, iterate_at))]
#[allow(clippy::too_many_arguments)]
pub fn plan_table<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    text: Option<String>,
    origin: String,
    t_s: PyReadonlyArray1<'py, f64>,
    axes: Vec<(String, String, PyReadonlyArray1<'py, f64>)>,
    iterations: usize,
    gain: f64,
    target_nrmse: f64,
    band_hz: Option<(f64, f64)>,
    max_scale: bool,
    per_axis_scale: bool,
    rrs: Option<PathBuf>,
    rrs_damping: f64,
    iterate_at: Option<f64>,
) -> PyResult<TablePlanParts<'py>> {
    let t_s = vector(&t_s)?;
    let axes: Vec<(String, String, Vec<f64>)> = axes
        .iter()
        .map(|(n, k, v)| Ok((n.clone(), k.clone(), vector(v)?)))
        .collect::<PyResult<_>>()?;
    let (t, columns, summary) = detached(py, move || {
        let scenario = table_scenario(path, text, &origin)?;
        let targets = axis_targets(&t_s, axes)?;
        let mut settings = PlanSettings::new(
            iterations,
            gain,
            target_nrmse,
            band_hz,
            max_scale,
            per_axis_scale,
        );
        if let Some(f) = rrs {
            settings.read_rrs(&scenario, &f, rrs_damping)?;
        }
        settings.iterate_at = iterate_at;
        let p = platen_plan::plan(
            &scenario,
            &PlanTarget::Table(targets),
            &settings,
            &mut |_| {},
        )?;
        let Planned::Table(p) = &p else {
            unreachable!("a multi-axis scenario's plan")
        };
        let (_, mut columns) = p.drive_columns().unwrap_or_default();
        let t = if columns.is_empty() {
            Vec::new()
        } else {
            columns.remove(0)
        };
        Ok((t, columns, json_text(&p.summary(&settings, None))?))
    })?;
    Ok((
        t.into_pyarray(py),
        columns.into_iter().map(|c| c.into_pyarray(py)).collect(),
        summary,
    ))
}

/// The multi-axis scenario of the file at `path`, or of the JSON `text` named `origin`.
fn table_scenario(
    path: Option<PathBuf>,
    text: Option<String>,
    origin: &str,
) -> Result<PlanScenario, Fail> {
    let (path, text) = match (path, text) {
        (Some(path), _) => {
            let text = std::fs::read_to_string(&path)
                .map_err(|e| Fail::input(format!("`{}`: cannot be read: {e}", path.display())))?;
            (path, text)
        }
        (None, Some(text)) => (PathBuf::from(origin), text),
        (None, None) => return Err(Fail::input("no scenario: give a path or a dict")),
    };
    let file = platen_plan::six_dof::table_scenario_file(&path, &text)?
        .ok_or_else(|| Fail::input("per-axis targets need a scenario with a `table`"))?;
    Ok(PlanScenario::table(&path, file))
}

/// The three-component target of `axes` (per axis `(name, kind, values)`, `kind`
/// `acceleration` or `displacement`) at `t_s`.
fn axis_targets(
    t_s: &[f64],
    axes: Vec<(String, String, Vec<f64>)>,
) -> Result<platen_plan::AxisTargets, Fail> {
    let origin = Path::new("target");
    let mut given: [Option<Target>; 3] = [None, None, None];
    for (name, kind, values) in axes {
        let k = platen_plan::six_dof::AXES
            .iter()
            .position(|a| *a == name)
            .ok_or_else(|| Fail::input(format!("target axis `{name}`: expected one of x, y, z")))?;
        given[k] = Some(match kind.as_str() {
            "acceleration" => Target::acceleration(origin, t_s.to_vec(), values)?,
            _ => Target::displacement(origin, t_s.to_vec(), values)?,
        });
    }
    Ok(platen_plan::AxisTargets::new(origin, given)?)
}
