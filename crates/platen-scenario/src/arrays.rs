//! Scenarios whose records are given in memory instead of named in the file: what Python's
//! `platen.forward` and `platen.inverse` run, and what a library user runs on a record that
//! is already in memory (from a data system, a DataFrame, another program).
//!
//! ```
//! use std::path::Path;
//! use platen_scenario::{file, Arrays, PlatenScenario};
//! use platen_integrate::Trajectory;
//!
//! // The scenario format without an excitation source: the arrays are the excitation.
//! let settings = file::parse(
//!     Path::new("settings"),
//!     r#"{"model": {"preset": "lhpost-2008"}, "excitation": {}}"#,
//! )?;
//! let t_s: Vec<f64> = (0..=2048).map(|j| j as f64 / 1024.0).collect();
//! let force_n: Vec<f64> = t_s.iter().map(|t| 60e3 * (std::f64::consts::PI * t).sin()).collect();
//! let origin = Path::new("my record");
//! let scenario = PlatenScenario::from_arrays(origin, settings, Arrays::Force { t_s, force_n })?;
//! let mut out = Trajectory::default();
//! let output = scenario.run(&mut out)?;
//! assert_eq!(out.len(), 2049);
//! assert!(output.stats.is_some()); // a forward run
//! # Ok::<(), platen_scenario::ScenarioError>(())
//! ```

use std::path::Path;

use platen_integrate::{ForceRecord, IntegrateError};

use crate::ctx::Ctx;
use crate::error::{Result, ScenarioError};
use crate::excitation::{
    check_direction_fields, force_run, motion_run, named_sources, rejected, with_rest_velocity,
    Derived, Run,
};
use crate::file::ScenarioFile;
use crate::scenario::PlatenScenario;

/// Records given in memory, in SI units: they take the place of the scenario file's
/// `excitation.force_csv` or `excitation.motion_csv`.
#[derive(Debug, Clone, PartialEq)]
pub enum Arrays {
    /// A recorded actuator force, uniformly sampled, linear between samples: a forward run.
    Force {
        /// Sample times, s (strictly increasing, on a uniform grid: [`platen_integrate::uniform_interval_s`]).
        t_s: Vec<f64>,
        /// Actuator force, N.
        force_n: Vec<f64>,
    },
    /// A prescribed motion: an inverse run. A missing velocity or acceleration is derived
    /// from the displacement (second-order finite differences), as for `motion_csv`.
    Motion {
        /// Sample times, s (strictly increasing).
        t_s: Vec<f64>,
        /// Displacement, m.
        u_m: Vec<f64>,
        /// Velocity, m/s.
        v_m_s: Option<Vec<f64>>,
        /// Acceleration, m/s².
        a_m_s2: Option<Vec<f64>>,
    },
}

impl PlatenScenario {
    /// Validates `file`, whose excitation names no source, with `arrays` as its excitation.
    /// Everything else of the scenario format applies as in a file: the model, the
    /// integrator and initial state (forward runs), `duration_s`, and a force's
    /// `excitation.lowpass_hz`. `origin` names the caller in messages (for example
    /// `platen.forward()`); relative paths resolve against its folder.
    ///
    /// # Errors
    /// Every error of [`PlatenScenario::from_file`] for the settings; for the arrays,
    /// [`ScenarioError::RecordRejected`] naming the array and the 0-based index of a bad
    /// value (`force_n[12] = NaN is not finite`, columns of different lengths, times that do
    /// not increase strictly or are not uniformly sampled, too few samples); an excitation
    /// that also names a source or a column map is an invalid field.
    pub fn from_arrays(origin: &Path, file: ScenarioFile, arrays: Arrays) -> Result<Self> {
        Self::validate(origin, &file, |ctx, file| arrays_run(ctx, file, arrays))
    }
}

/// The run of `arrays` under `file`'s settings.
fn arrays_run(ctx: &Ctx, file: &ScenarioFile, arrays: Arrays) -> Result<(Run, Derived)> {
    let ex = &file.excitation;
    let named = named_sources(ex);
    if !named.is_empty() {
        return Err(ctx.invalid(
            "excitation",
            format!("{{{}}}", named.join(", ")),
            "no source (force_csv, motion_csv, …): the arrays given are the excitation",
        ));
    }
    if ex.columns.is_some() {
        return Err(ctx.invalid(
            "excitation.columns",
            "(set)",
            "no column map: arrays are given in platen's columns and SI units",
        ));
    }
    let path = ctx.path;
    match arrays {
        Arrays::Force { t_s, force_n } => {
            check_direction_fields(ctx, file, true)?;
            let record = ForceRecord::new(t_s, force_n).map_err(|e| rejected(path, e))?;
            force_run(ctx, file, path, record, None).map(|run| (run, Derived::new()))
        }
        Arrays::Motion {
            t_s,
            u_m,
            v_m_s,
            a_m_s2,
        } => {
            check_direction_fields(ctx, file, false)?;
            // The duration is cut on the time column before the motion's own checks run.
            if t_s.is_empty() {
                return Err(too_short(path, 0));
            }
            let lengths = [
                ("u_m", Some(&u_m)),
                ("v_m_s", v_m_s.as_ref()),
                ("a_m_s2", a_m_s2.as_ref()),
            ];
            for (what, column) in lengths {
                if let Some(column) = column.filter(|c| c.len() != t_s.len()) {
                    return Err(rejected(
                        path,
                        IntegrateError::LengthMismatch {
                            what,
                            found: column.len(),
                            expected: t_s.len(),
                        },
                    ));
                }
            }
            let (run, derived) = motion_run(ctx, file, path, t_s, u_m, v_m_s, a_m_s2)?;
            Ok((with_rest_velocity(ctx, file, run)?, derived))
        }
    }
}

fn too_short(path: &Path, found: usize) -> ScenarioError {
    rejected(path, IntegrateError::TooShort { found, needed: 2 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::file::parse;
    use platen_integrate::Trajectory;

    fn settings(text: &str) -> ScenarioFile {
        parse(Path::new("settings"), text).unwrap()
    }

    fn bare() -> ScenarioFile {
        settings(r#"{"model": {"preset": "lhpost-2008"}, "excitation": {}}"#)
    }

    fn sine(n: usize) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|j| j as f64 / 1024.0).collect();
        let f = t
            .iter()
            .map(|t| 80e3 * (std::f64::consts::PI * t).sin())
            .collect();
        (t, f)
    }

    fn origin() -> &'static Path {
        Path::new("platen.forward()")
    }

    /// The same record as a file and as arrays gives the same samples, bit for bit.
    #[test]
    fn a_force_given_as_arrays_runs_as_the_same_force_in_a_file() {
        let (t, f) = sine(4097);
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("force.csv");
        platen_io::csv::write_csv_atomic(&csv, &["t_s", "force_n"], &[&t, &f]).unwrap();
        let text = format!(
            r#"{{"model": {{"preset": "lhpost-2008", "identified": {{"coulomb_force_n": 20000}}}},
                "excitation": {{"force_csv": {:?}, "lowpass_hz": 3}},
                "integrator": {{"method": "rk4", "step_s": 0.00048828125}},
                "initial": {{"u_m": 0.01}}, "duration_s": 3}}"#,
            csv.display().to_string()
        );
        let from_file =
            PlatenScenario::from_file(&dir.path().join("s.json"), settings(&text)).unwrap();
        let mut in_memory = settings(&text);
        in_memory.excitation.force_csv = None;
        let from_arrays =
            PlatenScenario::from_arrays(origin(), in_memory, Arrays::Force { t_s: t, force_n: f })
                .unwrap();
        let (mut a, mut b) = (Trajectory::default(), Trajectory::default());
        let out_a = from_file.run(&mut a).unwrap();
        let out_b = from_arrays.run(&mut b).unwrap();
        assert_eq!(a, b);
        assert_eq!(out_a, out_b);
        assert_eq!(b.len(), 3073);
        assert_eq!(b.u_m[0], 0.01);
    }

    /// A motion given as arrays derives its missing velocity and acceleration as a
    /// `motion_csv` does.
    #[test]
    fn a_motion_given_as_arrays_runs_as_the_same_motion_in_a_file() {
        let t: Vec<f64> = (0..2049).map(|j| j as f64 / 1024.0).collect();
        let u: Vec<f64> = t.iter().map(|t| 0.1 * (2.0 * t).sin()).collect();
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("motion.csv");
        platen_io::csv::write_csv_atomic(&csv, &["t_s", "u_m"], &[&t, &u]).unwrap();
        let text = format!(
            r#"{{"model": {{"preset": "lhpost-2008"}}, "excitation": {{"motion_csv": {:?}}},
                "duration_s": 1.5}}"#,
            csv.display().to_string()
        );
        let from_file =
            PlatenScenario::from_file(&dir.path().join("s.json"), settings(&text)).unwrap();
        let arrays = Arrays::Motion {
            t_s: t,
            u_m: u,
            v_m_s: None,
            a_m_s2: None,
        };
        let mut in_memory = settings(&text);
        in_memory.excitation.motion_csv = None;
        let from_arrays = PlatenScenario::from_arrays(origin(), in_memory, arrays).unwrap();
        let (mut a, mut b) = (Trajectory::default(), Trajectory::default());
        from_file.run(&mut a).unwrap();
        from_arrays.run(&mut b).unwrap();
        assert_eq!(a, b);
        assert_eq!(b.len(), 1537);
    }

    #[test]
    fn bad_arrays_are_reported_with_the_array_and_the_index() {
        let cases: Vec<(Arrays, &str)> = vec![
            (
                Arrays::Force {
                    t_s: vec![0.0, 0.1, 0.2],
                    force_n: vec![0.0, f64::NAN, 1.0],
                },
                "`platen.forward()`: force_n[1] = NaN is not finite",
            ),
            (
                Arrays::Force {
                    t_s: vec![0.0, 0.1, 0.1, 0.3],
                    force_n: vec![0.0; 4],
                },
                "`platen.forward()`: time is not strictly increasing at sample 2: 0.1 s then 0.1 s",
            ),
            (
                Arrays::Force {
                    t_s: vec![0.0, 0.1, 0.2],
                    force_n: vec![0.0; 2],
                },
                "`platen.forward()`: record columns differ in length: force_n has 2 values, expected 3",
            ),
            (
                Arrays::Force {
                    t_s: vec![0.0, 0.1, 0.2, 0.35, 0.4],
                    force_n: vec![0.0; 5],
                },
                "`platen.forward()`: record is not uniformly sampled",
            ),
            (
                Arrays::Motion {
                    t_s: vec![],
                    u_m: vec![],
                    v_m_s: None,
                    a_m_s2: None,
                },
                "`platen.forward()`: record has 0 samples; at least 2 are needed",
            ),
            (
                Arrays::Motion {
                    t_s: vec![0.0, 0.1, 0.2],
                    u_m: vec![0.0; 3],
                    v_m_s: None,
                    a_m_s2: Some(vec![0.0; 4]),
                },
                "`platen.forward()`: record columns differ in length: a_m_s2 has 4 values, expected 3",
            ),
        ];
        for (arrays, expected) in cases {
            let e = PlatenScenario::from_arrays(origin(), bare(), arrays).unwrap_err();
            assert!(matches!(e, ScenarioError::RecordRejected { .. }), "{e:?}");
            assert!(
                e.to_string().starts_with(expected),
                "{e}\nexpected: {expected}"
            );
        }
    }

    #[test]
    fn settings_that_do_not_fit_arrays_are_invalid_fields() {
        let (t, f) = sine(100);
        let force = || Arrays::Force {
            t_s: t.clone(),
            force_n: f.clone(),
        };
        let motion = || Arrays::Motion {
            t_s: t.clone(),
            u_m: f.clone(),
            v_m_s: None,
            a_m_s2: None,
        };
        let cases = [
            (
                r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv"}}"#,
                force(),
                "`platen.forward()`: excitation = {force_csv}: expected no source",
            ),
            (
                r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"columns": {}}}"#,
                force(),
                "`platen.forward()`: excitation.columns = (set): expected no column map",
            ),
            (
                r#"{"model": {"preset": "lhpost-2008"}, "excitation": {}, "integrator": {"method": "rk4"}}"#,
                motion(),
                "`platen.forward()`: integrator = {…}: expected no integrator",
            ),
            (
                r#"{"model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": -1}}, "excitation": {}}"#,
                force(),
                "`platen.forward()`: model.identified.effective_mass_kg = -1",
            ),
            (
                r#"{"model": {"preset": "lhpost-2008"}, "excitation": {}, "duration_s": 10}"#,
                force(),
                "`platen.forward()`: record spans",
            ),
        ];
        for (text, arrays, expected) in cases {
            let e = PlatenScenario::from_arrays(origin(), settings(text), arrays).unwrap_err();
            assert!(
                e.to_string().starts_with(expected),
                "{e}\nexpected: {expected}"
            );
        }
    }
}
