//! Planning a three-component test on a multi-axis table ([`plan_multi_axis`]): the
//! feasibility of the target per axis and per actuator, the largest scale that fits, and the
//! drives iterated through the transfer matrix ([`crate::mimo`]).
//!
//! # The target
//!
//! `t_s` and per axis its acceleration `x_m_s2`, `y_m_s2`, `z_m_s2` or, without one, its
//! displacement `x_m`, `y_m`, `z_m` ([`AxisTargets`]); absent axes are held at zero as a
//! target (their cross-talk is error). Each axis's command is made as the single-axis plan
//! makes it ([`crate::TargetMotion`]: integrated with a baseline treatment that starts and
//! ends at rest, within the axis's stroke), at the target's own rate (at most the
//! controller's: the controller interpolates the command between its samples, as it does a
//! `motion_csv`'s). The rotations are commanded still and left to the
//! DOF controller (a rotation target is not taken yet).
//!
//! # Feasibility
//!
//! The table's closed loop runs the target's own commands and its peaks are held against
//! ([`TableLimitUse`]): per axis its stroke, velocity and acceleration (`table.limits`, where
//! given); per actuator its stroke, its force against the push and pull it can exert at the
//! supply pressure, and its flow against its valves' capacity at the supply pressure; for a
//! single-acting vertical actuator its **uplift**: its force falling from its static share
//! `F₀` (the first sample's) towards zero, ratio `(F₀ − F_min)/((1 − r)·F₀)` with the residual
//! `r` = [`UPLIFT_RESIDUAL`] (its chamber cannot pull: unloaded, it nears the cavitation floor
//! and no longer holds the platen down); the overturning moment on the specimen against
//! `table.limits.overturning_moment_n_m`. A limit fails when its ratio (peak over allowed)
//! exceeds 1; `limiting` lists those that fail, worst first, and `binds_first` the one
//! exceeded earliest, with when. A target whose own commands ask an actuator for more stroke
//! than it has, so that their run fails (a chamber's oil volume gone), is infeasible too: its
//! limits are those actuators' `stroke_m` against the strokes the commands ask (the commanded
//! pose through the geometry), and it is not iterated (`stop` `not_run`, no drives), as on the
//! uniaxial table.
//! The largest common scale that fits is found by bisection
//! on the simulated loop ([`crate::feasibility::search_max_scale`], as the single-axis
//! plan's), and, where asked, the largest scale of each axis with the others as given.
//!
//! # Drive iteration
//!
//! [`crate::iterate_mimo`] with the x, y, z block of the linearised command → pose
//! transfer matrix (`platen_system::TableLinearisation`, the specimen and the force balance
//! included). The drives are written as a six-DOF `motion_csv` (`t_s`, `x_m` … `yaw_rad`)
//! that `platen simulate` replays to the same run, bit for bit: the plan derives each axis's
//! command velocity and acceleration exactly as `simulate` derives them from a pose column
//! ([`crate::command_motion`]).

mod limits;
mod plant;
mod summary;
mod targets;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::Vector6;
use platen_integrate::{IntegrateError, StopReason};
use platen_scenario::file::ScenarioFile;
use platen_scenario::multi_axis::TableScenario;
use platen_scenario::ScenarioError;
use platen_system::TableLinearisation;

use crate::baseline::{BaselineSettings, TargetMotion};
use crate::error::{PlanError, Result};
use crate::feasibility::{search_max_scale, MaxScale};
use crate::iterate::{Response, SpectrumAcceptance, TransferMatrix};
use crate::mimo::{iterate_mimo, record_of_run, AxisTarget, MimoIteration, MimoRecord};
use crate::plan::PlanSettings;
use crate::steps::{acceptance, iteration_level, on_controller_rate, scaled_up, IteratedAt};

pub use limits::{limit_uses, TableFeasibility, TableLimitUse, UPLIFT_RESIDUAL};
pub use plant::{pose_command, TableAchieved, TablePlant};
pub use summary::{
    AxisTargetSummary, MatrixFrfSummary, TableDriveSummary, TablePlanSummary, TableTargetSummary,
};
pub use targets::{read_table_scenario, table_scenario_file, AxisTargets, AXES, DRIVE_COLUMNS};

use limits::{failing, use_of};

/// Drives iterated at a low level and scaled up ([`PlanSettings::iterate_at`]).
pub type TableIteratedAt = IteratedAt<MimoRecord>;

/// The plan of a three-component test.
#[derive(Debug, Clone)]
pub struct TablePlan {
    /// The scenario's name.
    pub scenario_name: String,
    /// Its file.
    pub scenario_path: PathBuf,
    /// The target's origin.
    pub target_origin: PathBuf,
    /// The target's samples.
    pub target_samples: usize,
    /// The target's sample rate, Hz.
    pub target_rate_hz: f64,
    /// Per axis (x, y, z), the target motion asked (absent axes held still).
    pub targets: Vec<AxisTarget>,
    /// The target's times, s.
    pub t_s: Vec<f64>,
    /// Per axis given, its target's command (baseline-treated).
    pub motions: BTreeMap<&'static str, TargetMotion>,
    /// The feasibility of the target's own commands.
    pub feasibility: TableFeasibility,
    /// The acceleration the target's own commands achieved (iteration 0), per axis (x, y,
    /// z), m/s² (empty when they drive an actuator to the end of its stroke).
    pub first_a_m_s2: Vec<Vec<f64>>,
    /// The drive iteration and what its best drives use of every limit (`None` when the
    /// target's own commands drive an actuator to the end of its stroke: there is no run to
    /// iterate on).
    pub drive: Option<TablePlannedDrive>,
    /// What an engineer should look at.
    pub warnings: Vec<String>,
}

/// The iterated drives of a multi-axis plan.
#[derive(Debug, Clone)]
pub struct TablePlannedDrive {
    /// The drive iteration.
    pub iteration: MimoIteration<TableAchieved>,
    /// The best drives' limits.
    pub uses: Vec<TableLimitUse>,
    /// Per axis given, the best drives' achieved response spectrum against its required one
    /// (its RRS, or its target's own spectrum).
    pub spectrum_acceptance: BTreeMap<&'static str, SpectrumAcceptance>,
    /// Where the drives were iterated at a low level and scaled up (`None`: at full level);
    /// the iteration's drives and `achieved` are then the scaled-up ones and their run.
    pub iterated_at: Option<TableIteratedAt>,
}

/// Plans `targets` on the closed loop of the multi-axis scenario `file` (at `path`; its
/// excitation is ignored; [`crate::plan()`](fn@crate::plan) calls it for a scenario with a
/// `table`): feasibility, the largest scale that fits (when asked), the drives
/// iterated (see the [module documentation](self)); `on_run(k)` is called when drive
/// iteration `k`'s run is done. A target whose own commands drive an actuator to the end of
/// its stroke is an answer (infeasible, not iterated), not an error.
///
/// # Errors
/// The scenario's errors (with their JSON paths); a target whose acceleration is zero on
/// every axis; an RRS period shorter than two samples of the drive; bad settings (an
/// `iterate_at` outside (0, 1]); a run that fails numerically. A target faster than the
/// controller is resampled to its rate, with a notice in the plan's warnings.
pub fn plan_multi_axis(
    path: &Path,
    file: &ScenarioFile,
    targets: &AxisTargets,
    settings: &PlanSettings,
    on_run: &mut dyn FnMut(usize),
) -> Result<TablePlan> {
    let level = iteration_level(settings.iterate_at)?;
    // The closed loop, first commanded still (its controller's rate bounds the target's).
    let scenario =
        TableScenario::commanded_from_file(path, file, pose_command(targets.t_s(), &[])?)?;
    let mut notices = Vec::new();
    let given = targets;
    let targets = on_controller_rate(given, controller_rate_hz(&scenario), &mut notices)?;
    let motions = axis_motions(&scenario, &targets, &settings.baseline)?;
    let t_s: Vec<f64> = motions
        .values()
        .next()
        .map(|m| m.t_s.clone())
        .unwrap_or_default();
    let planning = Planning {
        path,
        scenario: &scenario,
        t_s: &t_s,
        plant: TablePlant::new(&scenario, &t_s),
        targets: axis_targets(&motions, t_s.len()),
        interval_s: motions.values().next().map_or(
            1.0 / controller_rate_hz(&scenario),
            TargetMotion::interval_s,
        ),
        settings,
    };
    planning.check(targets.origin())?;
    let (feasibility, first) = planning.feasibility()?;
    on_run(0);
    let mut warnings = Vec::new();
    let (first_a_m_s2, drive) = match first {
        FirstRun::Ran(first) => {
            let first_a_m_s2 = (0..3).map(|i| first.a_m_s2(i).to_vec()).collect();
            let before = feasibility_warnings(&first, &feasibility, notices);
            let drive = planning.drives(*first, level, before, &motions, on_run, &mut warnings)?;
            (first_a_m_s2, Some(drive))
        }
        FirstRun::BeyondReach { t_s } => {
            warnings.extend(beyond_reach_warning(&feasibility, t_s));
            warnings.extend(notices);
            (Vec::new(), None)
        }
    };
    Ok(TablePlan {
        scenario_name: scenario.name.clone(),
        scenario_path: path.to_owned(),
        target_origin: given.origin().to_owned(),
        target_samples: given.t_s().len(),
        target_rate_hz: given.sample_rate_hz(),
        targets: planning.targets,
        t_s,
        motions,
        feasibility,
        first_a_m_s2,
        drive,
        warnings,
    })
}

/// The controller's sample rate of a commanded scenario, Hz.
fn controller_rate_hz(scenario: &TableScenario) -> f64 {
    scenario
        .system
        .as_ref()
        .expect("a commanded scenario has a closed loop")
        .controller
        .sample_rate_hz()
}

/// Each given axis's command, baseline-treated within the axis's stroke.
fn axis_motions(
    scenario: &TableScenario,
    targets: &AxisTargets,
    baseline: &BaselineSettings,
) -> Result<BTreeMap<&'static str, TargetMotion>> {
    let mut motions = BTreeMap::new();
    let strokes = scenario.limits.each();
    for (k, target) in targets.axes().iter().enumerate() {
        let Some(target) = target else { continue };
        let stroke = strokes[k][0]
            .or_else(|| {
                // Without a limit, the longest actuator stroke bounds the axis's.
                scenario
                    .table
                    .actuators()
                    .iter()
                    .map(|a| a.stroke_m)
                    .reduce(f64::max)
            })
            .unwrap_or(f64::INFINITY);
        // At the target's own rate: the controller interpolates the command between its
        // samples (as it does a `motion_csv`'s), and the correction band ends below the
        // target's Nyquist frequency.
        let motion = TargetMotion::new(target, baseline, stroke, target.sample_rate_hz())?;
        motions.insert(AXES[k], motion);
    }
    Ok(motions)
}

/// Per axis (x, y, z), its target motion (an axis not given held still over `samples`).
fn axis_targets(motions: &BTreeMap<&'static str, TargetMotion>, samples: usize) -> Vec<AxisTarget> {
    AXES.iter()
        .map(|&axis| match motions.get(axis) {
            Some(m) => AxisTarget {
                name: axis,
                u_m: m.u_m.clone(),
                a_m_s2: m.a_m_s2.clone(),
            },
            None => AxisTarget::still(axis, samples),
        })
        .collect()
}

/// The warning of a target whose own commands ask an actuator for more stroke than it has,
/// so that their run failed at `failed_at_s`: not iterated.
fn beyond_reach_warning(feasibility: &TableFeasibility, failed_at_s: f64) -> Option<String> {
    let largest = feasibility.max_scale.as_ref().map_or(String::new(), |m| {
        format!(" (largest common scale that fits: {:.4})", m.scale)
    });
    feasibility.binds_first.as_ref().map(|u| {
        format!(
            "the target's commands ask more stroke than the actuators have: {} reaches {:.3} \
             times its limit from {:.3} s, and their run ends at {failed_at_s:.3} s, at the end \
             of its actuators: not iterated, no drives{largest}",
            u.limit,
            u.ratio,
            u.first_exceeded_s.unwrap_or(u.t_s)
        )
    })
}

/// The warnings of the target's own commands' run `first`: a chamber cavitating, the
/// feasibility's worst limit, then the `notices` of what was done to the target.
fn feasibility_warnings(
    first: &TableAchieved,
    feasibility: &TableFeasibility,
    notices: Vec<String>,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some(t) = first.stats.cavitation_at_s {
        warnings.push(format!(
            "the target's own commands cavitate a chamber at {t:.3} s: an actuator unloads \
             completely there (see the `.uplift` limits)"
        ));
    }
    if let Some(w) = feasibility.limiting.first() {
        warnings.push(format!(
            "the target is not feasible: {} reaches {:.3} times its limit at {:.3} s",
            w.limit, w.ratio, w.t_s
        ));
    }
    warnings.extend(notices);
    warnings
}

/// When a closed-loop run that failed stopped, s (`None` for an error that is not a run's
/// failure: a scenario or command refused).
fn failed_at_s(e: &PlanError) -> Option<f64> {
    let PlanError::Scenario(
        ScenarioError::TableRun(source) | ScenarioError::TableLoopUnstable { source, .. },
    ) = e
    else {
        return None;
    };
    match *source {
        IntegrateError::StrutGasSpent { t_s, .. } => Some(t_s),
        _ => match source.stop_reason() {
            Some(StopReason::Failed { t_s, .. }) => Some(t_s),
            _ => None,
        },
    }
}

/// How the run of the target's own commands went.
enum FirstRun {
    /// It ran to the end (boxed: a whole run beside a time).
    Ran(Box<TableAchieved>),
    /// It failed at `t_s` after the commands asked an actuator for more stroke than it has.
    BeyondReach {
        /// When it failed, s.
        t_s: f64,
    },
}

/// A multi-axis plan under way: the scenario's closed loop as a plant, the axes' targets
/// at their common samples, `interval_s` apart, and the plan's settings.
struct Planning<'a> {
    path: &'a Path,
    scenario: &'a TableScenario,
    t_s: &'a [f64],
    plant: TablePlant<'a>,
    targets: Vec<AxisTarget>,
    interval_s: f64,
    settings: &'a PlanSettings,
}

impl Planning<'_> {
    /// A target with something to reproduce, and RRSs the drive's rate can check.
    fn check(&self, origin: &Path) -> Result<()> {
        if self.targets.iter().all(AxisTarget::is_still) {
            return Err(PlanError::Target {
                origin: origin.display().to_string(),
                message: "the target's acceleration is zero on every axis: nothing to reproduce"
                    .into(),
            });
        }
        for rrs in self.settings.axis_rrs.iter().flatten() {
            rrs.check_rate(1.0 / self.interval_s)?;
        }
        Ok(())
    }

    /// The target's own commands, each axis scaled by `scales`.
    fn scaled_commands(&self, scales: [f64; 3]) -> Vec<Vec<f64>> {
        self.targets
            .iter()
            .zip(scales)
            .map(|(t, s)| t.u_m.iter().map(|x| x * s).collect())
            .collect()
    }

    /// The feasibility of the target's own commands (see the [module documentation](self))
    /// and how their run went.
    ///
    /// # Errors
    /// A run that fails before the commands ask an actuator for more stroke than it has.
    fn feasibility(&self) -> Result<(TableFeasibility, FirstRun)> {
        let (uses, first) = match self.plant.run(&self.scaled_commands([1.0; 3])) {
            Ok(first) => (
                limit_uses(self.scenario, &first.run),
                FirstRun::Ran(Box::new(first)),
            ),
            Err(e) => {
                let Some(t_s) = failed_at_s(&e) else {
                    return Err(e);
                };
                let beyond = self.commanded_beyond_reach(t_s);
                if beyond.is_empty() {
                    return Err(e);
                }
                (beyond, FirstRun::BeyondReach { t_s })
            }
        };
        let limiting = failing(&uses);
        let binds_first = limiting
            .iter()
            .filter_map(|u| u.first_exceeded_s.map(|t| (t, u)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, u)| u.clone());
        let (max_scale, per_axis_max_scale) = self.max_scales(&uses, &limiting)?;
        Ok((
            TableFeasibility {
                feasible: limiting.is_empty(),
                limiting,
                binds_first,
                uses,
                max_scale,
                per_axis_max_scale,
            },
            first,
        ))
    }

    /// The actuators whose stroke the target's own commands ask beyond their `stroke_m`
    /// before `failed_at_s` (the pose the commands ask, rotations still, through the table's
    /// geometry), each with the command's peak stroke and when it first exceeds its limit.
    fn commanded_beyond_reach(&self, failed_at_s: f64) -> Vec<TableLimitUse> {
        let table = &self.scenario.table;
        let (t, c) = (self.t_s, &self.targets);
        let mut uses = Vec::new();
        for (i, a) in table.actuators().iter().enumerate() {
            let strokes: Vec<f64> = (0..t.len())
                .map(|j| {
                    let q = Vector6::new(c[0].u_m[j], c[1].u_m[j], c[2].u_m[j], 0.0, 0.0, 0.0);
                    table.actuator_at(i, &q).stroke_m
                })
                .collect();
            let u = use_of(
                format!("{}.stroke_m", a.name),
                t,
                &strokes,
                -a.stroke_m,
                a.stroke_m,
            );
            if u.first_exceeded_s.is_some_and(|first| first <= failed_at_s) {
                uses.push(u);
            }
        }
        uses
    }

    /// The largest common scale that fits and, where asked, each axis's (the others as
    /// given), from the unscaled run's `uses` and the limits that fail there.
    fn max_scales(
        &self,
        uses: &[TableLimitUse],
        limiting: &[TableLimitUse],
    ) -> Result<(Option<MaxScale>, BTreeMap<&'static str, MaxScale>)> {
        let mut per_axis = BTreeMap::new();
        let Some(s) = &self.settings.max_scale else {
            return Ok((None, per_axis));
        };
        let worst = uses.iter().map(|u| u.ratio).fold(0.0, f64::max);
        let unscaled_failing: Vec<String> = limiting.iter().map(|u| u.limit.clone()).collect();
        let failing_at = |scales: [f64; 3]| match self.plant.run(&self.scaled_commands(scales)) {
            Ok(a) => failing(&limit_uses(self.scenario, &a.run))
                .into_iter()
                .map(|u| u.limit)
                .collect(),
            Err(_) => vec!["run_failed".to_owned()],
        };
        let mut found = search_max_scale(s, worst, unscaled_failing.clone(), &mut |k| {
            failing_at([k; 3])
        })?;
        found.runs += 1;
        if self.settings.per_axis_max_scale {
            for (k, axis) in AXES.iter().enumerate() {
                if self.targets[k].is_still() {
                    continue;
                }
                let mut one = search_max_scale(s, worst, unscaled_failing.clone(), &mut |scale| {
                    let mut scales = [1.0; 3];
                    scales[k] = scale;
                    failing_at(scales)
                })?;
                one.runs += 1;
                per_axis.insert(*axis, one);
            }
        }
        Ok((Some(found), per_axis))
    }

    /// The x, y, z block of the table's linearised command → pose transfer matrix.
    fn linearisation(&self) -> Result<TableLinearisation> {
        let system = self
            .scenario
            .system
            .as_ref()
            .expect("a commanded scenario has a closed loop");
        TableLinearisation::new(
            &self.scenario.table,
            &system.hydraulics,
            &system.controller,
            self.scenario.specimen.as_ref(),
        )
        .map_err(|e| PlanError::Target {
            origin: self.path.display().to_string(),
            message: format!("the table's loop cannot be linearised: {e}"),
        })
    }

    /// The drives iterated at `level` (the target's own commands' run `first` is iteration
    /// 0's at full level), scaled up when below 1, with their limits and spectra; the plan's
    /// warnings pushed on `warnings`, those of the target's own commands (`before`) after the
    /// scaled-up drives' and before the best drives'.
    fn drives(
        &self,
        first: TableAchieved,
        level: f64,
        before: Vec<String>,
        motions: &BTreeMap<&'static str, TargetMotion>,
        on_run: &mut dyn FnMut(usize),
        warnings: &mut Vec<String>,
    ) -> Result<TablePlannedDrive> {
        let lin = self.linearisation()?;
        let frf = |f: f64| -> TransferMatrix {
            let h = lin.transfer_matrix(f);
            (0..3).map(|i| (0..3).map(|j| h[i][j]).collect()).collect()
        };
        let settings = &self.settings.iteration;
        // At a low level, the iteration's first run is its own (the feasibility's is at full).
        let iterated: Vec<AxisTarget> = self.targets.iter().map(|t| t.scaled(level)).collect();
        let mut first = (level == 1.0).then_some(first);
        let mut iteration = iterate_mimo(
            if level < 1.0 {
                &iterated
            } else {
                &self.targets
            },
            self.interval_s,
            &frf,
            settings,
            |drives, k| {
                let r = match (k, first.take()) {
                    (0, Some(r)) => r,
                    _ => self.plant.run(drives)?,
                };
                if k > 0 {
                    on_run(k);
                }
                Ok(r)
            },
        )?;
        let iterated_at = (level < 1.0)
            .then(|| self.scaled_up(level, &mut iteration, warnings))
            .transpose()?;
        let uses = limit_uses(self.scenario, &iteration.achieved.run);
        warnings.extend(before);
        for u in failing(&uses) {
            warnings.push(format!(
                "the best drive exceeds {}: {:.3} times its limit at {:.3} s",
                u.limit, u.ratio, u.t_s
            ));
        }
        if let Some(t) = iteration.achieved.stats.cavitation_at_s {
            warnings.push(format!("the best drive cavitates a chamber at {t:.3} s"));
        }
        let spectrum_acceptance = self.acceptances(&iteration, motions, warnings)?;
        Ok(TablePlannedDrive {
            iteration,
            uses,
            spectrum_acceptance,
            iterated_at,
        })
    }

    /// The best drives of `iteration`, iterated at `level`, scaled up and run at full level
    /// ([`scaled_up`]).
    fn scaled_up(
        &self,
        level: f64,
        iteration: &mut MimoIteration<TableAchieved>,
        warnings: &mut Vec<String>,
    ) -> Result<TableIteratedAt> {
        let best = iteration.best;
        scaled_up(
            level,
            iteration,
            |drives, level| {
                drives
                    .iter()
                    .map(|d| d.iter().map(|x| x / level).collect())
                    .collect()
            },
            |drives| {
                let full = self.plant.run(drives)?;
                let record = record_of_run(
                    best,
                    &self.targets,
                    self.interval_s,
                    &full,
                    drives,
                    &self.settings.iteration.spectrum,
                )?;
                Ok((full, record))
            },
            |r| r.acceleration_nrmse,
            warnings,
        )
    }

    /// Each axis given, its achieved spectrum against its RRS (or its target's).
    fn acceptances(
        &self,
        iteration: &MimoIteration<TableAchieved>,
        motions: &BTreeMap<&'static str, TargetMotion>,
        warnings: &mut Vec<String>,
    ) -> Result<BTreeMap<&'static str, SpectrumAcceptance>> {
        let mut out = BTreeMap::new();
        for (k, axis) in AXES.iter().enumerate() {
            let Some(motion) = motions.get(axis) else {
                continue;
            };
            let a = acceptance(
                self.settings.axis_rrs[k].as_ref(),
                &self.settings.iteration.spectrum,
                1.0 / self.interval_s,
                (&motion.a_m_s2, iteration.achieved.a_m_s2(k)),
                &format!("the best drive's achieved {axis} response spectrum"),
                warnings,
            )?;
            out.insert(*axis, a);
        }
        Ok(out)
    }
}

impl TablePlan {
    /// The drive iteration, if it ran.
    pub fn iteration(&self) -> Option<&MimoIteration<TableAchieved>> {
        self.drive.as_ref().map(|d| &d.iteration)
    }

    /// The best drives as the six-DOF `motion_csv` columns `simulate` replays: `t_s`, then
    /// `x_m` … `yaw_rad` (the rotations zero; `None` when not iterated).
    pub fn drive_columns(&self) -> Option<(Vec<&'static str>, Vec<Vec<f64>>)> {
        let it = self.iteration()?;
        let n = self.t_s.len();
        let mut columns = vec![self.t_s.clone()];
        for k in 0..6 {
            columns.push(it.drive_u_m.get(k).cloned().unwrap_or_else(|| vec![0.0; n]));
        }
        Some((DRIVE_COLUMNS.to_vec(), columns))
    }

    /// Writes the best drives' rows to `writer` (created with [`DRIVE_COLUMNS`]) and
    /// finishes it; returns whether there were drives to write (without, the writer is
    /// dropped and its temporary file with it).
    ///
    /// # Errors
    /// [`PlanError::Io`] if it cannot be written.
    pub fn write_drive_rows(&self, mut writer: platen_io::csv::CsvWriter) -> Result<bool> {
        let Some((_, columns)) = self.drive_columns() else {
            return Ok(false);
        };
        let mut row = vec![0.0; columns.len()];
        for j in 0..self.t_s.len() {
            for (r, c) in row.iter_mut().zip(&columns) {
                *r = c[j];
            }
            writer.write_row(&row)?;
        }
        writer.finish()?;
        Ok(true)
    }

    /// Writes the best drives to `path` as a six-DOF `motion_csv` (see
    /// [`TablePlan::drive_columns`]), atomically; nothing when not iterated.
    ///
    /// # Errors
    /// [`PlanError::Io`] if it cannot be written.
    pub fn write_drive(&self, path: &Path) -> Result<()> {
        if let Some((names, columns)) = self.drive_columns() {
            let refs: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
            platen_io::csv::write_csv_atomic(path, &names, &refs)?;
        }
        Ok(())
    }
}
