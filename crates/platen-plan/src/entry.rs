//! One plan for every table: the scenario read for planning ([`PlanScenario`]), its target
//! ([`PlanTarget`]) and required spectra ([`PlanSettings::read_rrs`]) read as the table
//! wants them, the plan ([`plan()`](fn@plan)) and what it gives ([`Planned`], its summary
//! [`PlannedSummary`], its drive written with [`Planned::write_drive_rows`]).
//!
//! Whatever the table, a plan takes the same steps, each written once (the crate's `steps`
//! module and [`crate::feasibility`]): the level the drive is iterated at is checked, the
//! target is put on the controller's rate, its motion is made (the baseline treatment of each axis), its own
//! command is run for the feasibility and the largest scale is searched on the simulated loop,
//! the drive is iterated ([`crate::iterate_axes`]: one axis on the uniaxial table, x, y and z
//! on a multi-axis one), scaled up when iterated at a low level, and its run is held against
//! the limits and the required spectra. What differs is the plant: the uniaxial platen and
//! its `table_system` ([`crate::plan_platen`]) or a multi-axis table and its DOF controller
//! ([`crate::plan_multi_axis`]), with their own limits.

use std::path::{Path, PathBuf};

use serde::Serialize;

use platen_io::columns::ColumnMap;
use platen_io::csv::CsvWriter;
use platen_scenario::file::ScenarioFile;
use platen_scenario::LoadedRig;

use crate::error::{PlanError, Result};
use crate::plan::{load_rig, plan_platen, Plan, PlanSettings, PlanSummary, UNIAXIAL_DRIVE_COLUMNS};
use crate::platen_loop::PlatenLoop;
use crate::rrs::RequiredSpectrum;
use crate::six_dof::{self, plan_multi_axis, AxisTargets, TablePlan, TablePlanSummary};
use crate::target::Target;

/// A scenario read for planning, whatever its table: its rig (model or table, specimen,
/// limits, loop), its excitation ignored (the target takes its place, so its records are not
/// read).
#[derive(Debug, Clone)]
pub enum PlanScenario {
    /// The uniaxial table: a platen and its `table_system` (a file without `table`).
    Platen {
        /// The scenario's file (or the name its text goes by), for messages and the summary.
        path: PathBuf,
        /// Its rig.
        rig: Box<LoadedRig>,
    },
    /// A multi-axis table and its `controller` (a file with `table`).
    Table {
        /// The scenario's file (or the name its text goes by), for messages and the summary.
        path: PathBuf,
        /// The file, its `excitation` optional ([`six_dof::table_scenario_file`]).
        file: Box<ScenarioFile>,
    },
}

impl PlanScenario {
    /// Reads the scenario file at `path` for planning: a multi-axis one (with a `table`,
    /// [`six_dof::read_table_scenario`]) or the uniaxial table's rig ([`load_rig`]).
    ///
    /// # Errors
    /// As [`six_dof::read_table_scenario`] and [`load_rig`] (among them
    /// [`PlanError::NoTableSystem`]).
    pub fn load(path: &Path) -> Result<Self> {
        match six_dof::read_table_scenario(path)? {
            Some(file) => Ok(Self::table(path, file)),
            None => Ok(Self::platen(path, load_rig(path)?)),
        }
    }

    /// The uniaxial table's rig `rig`, read from `path`.
    pub fn platen(path: &Path, rig: LoadedRig) -> Self {
        Self::Platen {
            path: path.to_owned(),
            rig: Box::new(rig),
        }
    }

    /// The multi-axis scenario `file`, read from `path`.
    pub fn table(path: &Path, file: ScenarioFile) -> Self {
        Self::Table {
            path: path.to_owned(),
            file: Box::new(file),
        }
    }

    /// The scenario's file.
    pub fn path(&self) -> &Path {
        match self {
            Self::Platen { path, .. } | Self::Table { path, .. } => path,
        }
    }

    /// Whether it is a multi-axis table.
    pub fn is_multi_axis(&self) -> bool {
        matches!(self, Self::Table { .. })
    }

    /// The columns of its drive CSV: `t_s`, `u_m` on the uniaxial table
    /// ([`crate::UNIAXIAL_DRIVE_COLUMNS`]), the six-DOF `motion_csv`'s on a multi-axis one
    /// ([`six_dof::DRIVE_COLUMNS`]).
    pub fn drive_columns(&self) -> &'static [&'static str] {
        match self {
            Self::Platen { .. } => &UNIAXIAL_DRIVE_COLUMNS,
            Self::Table { .. } => &six_dof::DRIVE_COLUMNS,
        }
    }
}

/// A target, as the scenario's table takes it.
#[derive(Debug, Clone)]
pub enum PlanTarget {
    /// The uniaxial table's: one acceleration or displacement.
    Platen(Target),
    /// A multi-axis table's: up to three axes on one time base.
    Table(AxisTargets),
}

impl PlanTarget {
    /// Reads the target CSV at `path` as `scenario`'s table takes it: on the uniaxial table
    /// `t_s` and `a_m_s2` or `u_m`, under `columns`' names and units
    /// ([`Target::read_csv_mapped`]); on a multi-axis table `t_s` and any of `x_m_s2`,
    /// `y_m_s2`, `z_m_s2` (or `x_m`, `y_m`, `z_m`) under platen's own names, `columns` not
    /// read ([`AxisTargets::read_csv`]).
    ///
    /// # Errors
    /// As [`Target::read_csv_mapped`] and [`AxisTargets::read_csv`].
    pub fn read_csv(scenario: &PlanScenario, path: &Path, columns: &ColumnMap) -> Result<Self> {
        match scenario {
            PlanScenario::Platen { .. } => {
                Target::read_csv_mapped(path, columns).map(PlanTarget::Platen)
            }
            PlanScenario::Table { .. } => AxisTargets::read_csv(path).map(PlanTarget::Table),
        }
    }

    /// Where the target comes from.
    pub fn origin(&self) -> &Path {
        match self {
            PlanTarget::Platen(t) => t.origin(),
            PlanTarget::Table(t) => t.origin(),
        }
    }
}

impl PlanSettings {
    /// Reads the required response spectrum CSV at `path` (of damping ratio `damping_ratio`)
    /// as `scenario`'s table takes it: one spectrum on the uniaxial table
    /// ([`RequiredSpectrum::read_csv`], into [`PlanSettings::rrs`]), one per axis on a
    /// multi-axis one ([`RequiredSpectrum::read_csv_axes`], into
    /// [`PlanSettings::axis_rrs`]).
    ///
    /// # Errors
    /// As [`RequiredSpectrum::read_csv`] and [`RequiredSpectrum::read_csv_axes`].
    pub fn read_rrs(
        &mut self,
        scenario: &PlanScenario,
        path: &Path,
        damping_ratio: f64,
    ) -> Result<()> {
        match scenario {
            PlanScenario::Platen { .. } => {
                self.rrs = Some(RequiredSpectrum::read_csv(path, damping_ratio)?);
            }
            PlanScenario::Table { .. } => {
                self.axis_rrs = RequiredSpectrum::read_csv_axes(path, damping_ratio)?;
            }
        }
        Ok(())
    }
}

/// A finished plan, whatever the table.
#[derive(Debug, Clone)]
pub enum Planned {
    /// The uniaxial table's.
    Platen(Box<Plan>),
    /// A multi-axis table's.
    Table(Box<TablePlan>),
}

/// The summary `platen plan --json` prints, whatever the table. Serialised as the inner
/// summary itself (the keys of [`PlanSummary`] or of [`TablePlanSummary`]); serialise it
/// through [`serde_json::to_value`] for the keys in alphabetical order.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum PlannedSummary {
    /// The uniaxial table's.
    Platen(Box<PlanSummary>),
    /// A multi-axis table's.
    Table(Box<TablePlanSummary>),
}

impl PlannedSummary {
    /// What the planner wants its user to know.
    pub fn warnings(&self) -> &[String] {
        match self {
            PlannedSummary::Platen(s) => &s.warnings,
            PlannedSummary::Table(s) => &s.warnings,
        }
    }
}

/// Plans `target` on `scenario`'s table: can the table run the target, what limits it, the
/// largest scale that fits (when asked), and the drive that makes the simulated table
/// reproduce it (see the [module documentation](self)); `on_run(k)` is called when the
/// closed-loop run of drive iteration `k` is done (0: the target's own command; at most
/// `settings.iteration.max_iterations`), a hook for progress reports. A target whose own
/// command drives the table to the end of its actuators is an answer (infeasible, not
/// iterated), not an error.
///
/// ```
/// use std::path::Path;
/// use platen_plan::{plan, PlanScenario, PlanSettings, PlanTarget, Target};
///
/// let json = r#"{"model": {"preset": "lhpost-2008"}, "table_system": {"preset": "lhpost-2008"}}"#;
/// let path = Path::new("lhpost.json");
/// let scenario = PlanScenario::platen(path, platen_scenario::LoadedRig::parse(path, json)?);
/// let t: Vec<f64> = (0..4097).map(|j| j as f64 / 1024.0).collect(); // 4 s at 1024 Hz
/// let a = t.iter().map(|t| 2.0 * (std::f64::consts::TAU * 2.0 * t).sin()).collect();
/// let target = PlanTarget::Platen(Target::acceleration(Path::new("sine"), t, a)?);
/// let p = plan(&scenario, &target, &PlanSettings::default(), &mut |_| {})?;
/// let platen = p.platen().expect("a uniaxial scenario's plan");
/// let best = platen.iteration().unwrap().best_record();
/// assert!(platen.feasibility.feasible && best.acceleration_nrmse < 0.1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// [`PlanError::NoTableSystem`]; a target of the other table's kind
/// ([`PlanError::Target`]); a target with nothing to reproduce; an RRS period shorter than
/// two samples of the drive; bad settings (an `iterate_at` outside (0, 1]); a closed-loop run
/// that fails. A target faster than the controller is resampled to its rate, with a notice in
/// the plan's warnings.
pub fn plan(
    scenario: &PlanScenario,
    target: &PlanTarget,
    settings: &PlanSettings,
    on_run: &mut dyn FnMut(usize),
) -> Result<Planned> {
    match (scenario, target) {
        (PlanScenario::Platen { path, rig }, PlanTarget::Platen(target)) => {
            let table = PlatenLoop::of_loaded(rig, path)?;
            let p = plan_platen(&table, &rig.name, path, target, settings, on_run)?;
            Ok(Planned::Platen(Box::new(p)))
        }
        (PlanScenario::Table { path, file }, PlanTarget::Table(targets)) => {
            let p = plan_multi_axis(path, file, targets, settings, on_run)?;
            Ok(Planned::Table(Box::new(p)))
        }
        (PlanScenario::Platen { .. }, PlanTarget::Table(_)) => Err(mismatch(
            target,
            "a three-component target needs a multi-axis scenario (one with a `table`)",
        )),
        (PlanScenario::Table { .. }, PlanTarget::Platen(_)) => Err(mismatch(
            target,
            "a multi-axis scenario takes a target per axis (x, y, z)",
        )),
    }
}

/// The error of a target of the other table's kind.
fn mismatch(target: &PlanTarget, message: &str) -> PlanError {
    PlanError::Target {
        origin: target.origin().display().to_string(),
        message: message.into(),
    }
}

impl Planned {
    /// The uniaxial table's plan, if it is one.
    pub fn platen(&self) -> Option<&Plan> {
        match self {
            Planned::Platen(p) => Some(p),
            Planned::Table(_) => None,
        }
    }

    /// The multi-axis table's plan, if it is one.
    pub fn table(&self) -> Option<&TablePlan> {
        match self {
            Planned::Platen(_) => None,
            Planned::Table(p) => Some(p),
        }
    }

    /// The uniaxial table's plan, if it is one, by value.
    pub fn into_platen(self) -> Option<Plan> {
        match self {
            Planned::Platen(p) => Some(*p),
            Planned::Table(_) => None,
        }
    }

    /// The multi-axis table's plan, if it is one, by value.
    pub fn into_table(self) -> Option<TablePlan> {
        match self {
            Planned::Platen(_) => None,
            Planned::Table(p) => Some(*p),
        }
    }

    /// What the planner wants its user to know.
    pub fn warnings(&self) -> &[String] {
        match self {
            Planned::Platen(p) => &p.warnings,
            Planned::Table(p) => &p.warnings,
        }
    }

    /// The summary, with `settings` the plan's and `out` the drive CSV written (if any).
    pub fn summary(&self, settings: &PlanSettings, out: Option<&Path>) -> PlannedSummary {
        match self {
            Planned::Platen(p) => PlannedSummary::Platen(Box::new(p.summary(out))),
            Planned::Table(p) => PlannedSummary::Table(Box::new(p.summary(settings, out))),
        }
    }

    /// Writes the drive's rows to `writer` (created with the scenario's
    /// [`PlanScenario::drive_columns`]) and finishes it; returns whether there was a drive to
    /// write (without, the writer is dropped and its temporary file with it).
    ///
    /// # Errors
    /// [`PlanError::Io`] if it cannot be written.
    pub fn write_drive_rows(&self, writer: CsvWriter) -> Result<bool> {
        match self {
            Planned::Platen(p) => p.write_drive_rows(writer),
            Planned::Table(p) => p.write_drive_rows(writer),
        }
    }
}
