//! `platen.plan`: a target's feasibility, largest scale and drive on a scenario's closed loop
//! (`platen plan`), from arrays.

use std::path::{Path, PathBuf};

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use platen_plan::{FrfSource, MaxScaleSettings, NoiseSettings, PlanError, PlanSettings, Target};
use platen_scenario::LoadedRig;

use crate::error::{chain, detached, Fail, Kind};
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
#[pyo3(signature = (path, text, origin, t_s, a_m_s2, u_m, iterations, gain, target_nrmse, frf, band_hz, max_scale))]
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
        let (path, rig) = match (path, text) {
            (Some(path), _) => {
                let rig = platen_plan::load_rig(&path)?;
                (path, rig)
            }
            (None, Some(text)) => {
                // As `load_rig` reads a file: the excitation, if any, is ignored.
                let origin = PathBuf::from(&origin);
                let rig = LoadedRig::parse(&origin, &text).map_err(PlanError::from)?;
                (origin, rig)
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
        let settings = PlanSettings {
            iteration: platen_plan::IterationSettings {
                max_iterations: iterations,
                gain,
                target_nrmse,
                band_hz,
                frf,
                ..Default::default()
            },
            max_scale: max_scale.then(MaxScaleSettings::default),
            ..Default::default()
        };
        let p = platen_plan::plan(&rig, &path, &target, &settings).map_err(|e| match e {
            PlanError::TargetRate { .. } => Fail::input(chain(&e)),
            e => e.into(),
        })?;
        let drive = p.drive().map(|(t, u)| (t.to_vec(), u.to_vec()));
        Ok((drive, json_text(&p.summary(None))?))
    })?;
    Ok(match drive {
        Some((t, u)) => (Some(t.into_pyarray(py)), Some(u.into_pyarray(py)), summary),
        None => (None, None, summary),
    })
}
