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
//! exceeded earliest, with when. The largest common scale that fits is found by bisection
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

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

use platen_integrate::{PoseMotion, TableLoopStats, TableRun};
use platen_io::IoError;
use platen_scenario::file::ScenarioFile;
use platen_scenario::multi_axis::{
    TableScenario, ACCELERATION_COLUMNS, POSE_COLUMNS, RATE_COLUMNS,
};
use platen_system::TableLinearisation;

use crate::baseline::{command_motion, BaselineSettings, TargetMotion};
use crate::error::{check_setting, PlanError, Result};
use crate::feasibility::{search_max_scale, MaxScale, MaxScaleSettings};
use crate::iterate::{
    spectrum_acceptance as spectrum_acceptance_of, IterationSettings, SpectrumAcceptance,
    ACCEPTANCE_BAND,
};
use crate::mimo::{iterate_mimo, AxisTarget, MimoIteration, MimoResponse, TransferMatrix};
use crate::rrs::RequiredSpectrum;
use crate::target::Target;

/// The scenario JSON `text` (from `path`, for messages) if it is a multi-axis one (it has a
/// `table`), parsed, its `excitation` optional (a plan's target takes its place, and a
/// commanded table does not read it); `None` for JSON without a `table`, which the
/// single-axis planner reads and reports on.
///
/// # Errors
/// [`PlanError::Io`] for text that is not JSON (its line and column) and for a multi-axis
/// scenario that does not parse (its path and line).
pub fn table_scenario_file(path: &Path, text: &str) -> Result<Option<ScenarioFile>> {
    let Ok(mut value) = serde_json::from_str::<serde_json::Value>(text) else {
        // Not JSON: its syntax error, at its line and column, as `simulate` reports it.
        return Ok(Some(platen_io::json::parse_json(path, text)?));
    };
    let Some(object) = value.as_object_mut().filter(|o| o.contains_key("table")) else {
        return Ok(None);
    };
    if object.contains_key("excitation") {
        return Ok(Some(platen_io::json::parse_json(path, text)?));
    }
    // No excitation: an empty one.
    object.insert("excitation".into(), serde_json::json!({}));
    let pretty = serde_json::to_string_pretty(&value).map_err(|e| IoError::Record {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    Ok(Some(platen_io::json::parse_json(path, &pretty)?))
}

/// [`table_scenario_file`] of the file at `path`; `None` also for a file that cannot be
/// read (the single-axis planner reports it).
///
/// # Errors
/// As [`table_scenario_file`].
pub fn read_table_scenario(path: &Path) -> Result<Option<ScenarioFile>> {
    match std::fs::read_to_string(path) {
        Ok(text) => table_scenario_file(path, &text),
        Err(_) => Ok(None),
    }
}

/// The drive CSV's columns: a six-DOF `motion_csv`.
pub const DRIVE_COLUMNS: [&str; 7] = [
    "t_s",
    "x_m",
    "y_m",
    "z_m",
    "roll_rad",
    "pitch_rad",
    "yaw_rad",
];

/// The translational axes a target gives, in order.
pub const AXES: [&str; 3] = ["x", "y", "z"];

/// A target of up to three axes on one time base.
#[derive(Debug, Clone)]
pub struct AxisTargets {
    origin: PathBuf,
    /// Per axis (x, y, z), its target (absent: held at zero).
    axes: [Option<Target>; 3],
}

impl AxisTargets {
    /// The targets of the axes given (`None`: held at zero), all on the same times.
    ///
    /// # Errors
    /// [`PlanError::Target`] when no axis is given or the axes' times differ.
    pub fn new(origin: &Path, axes: [Option<Target>; 3]) -> Result<Self> {
        let bad = |message: String| PlanError::Target {
            origin: origin.display().to_string(),
            message,
        };
        let mut given = axes.iter().flatten();
        let first = given
            .next()
            .ok_or_else(|| bad("no axis: expected at least one of x, y, z".into()))?;
        if given.any(|t| t.t_s() != first.t_s()) {
            return Err(bad("the axes' targets have different times".into()));
        }
        Ok(Self {
            origin: origin.to_owned(),
            axes,
        })
    }

    /// Reads a target CSV: `t_s` and, per axis, `x_m_s2` (an acceleration target) or, without
    /// it, `x_m` (a displacement); the same for y and z. Other columns are ignored.
    ///
    /// # Errors
    /// [`PlanError::Io`] naming the file and line: unreadable, no `t_s`, none of the axes'
    /// columns, a bad cell, times that do not increase strictly or are not uniform, fewer
    /// than [`MIN_TARGET_SAMPLES`](crate::MIN_TARGET_SAMPLES) rows.
    pub fn read_csv(path: &Path) -> Result<Self> {
        let optional: Vec<&'static str> = ACCELERATION_COLUMNS[..3]
            .iter()
            .chain(&POSE_COLUMNS[..3])
            .copied()
            .collect();
        let mut table = platen_io::csv::read_table(path, &["t_s"], &optional)?;
        let t_s = table.take_column("t_s").unwrap_or_default();
        // The file's own checks first, so that they name the file and line.
        crate::target::checked_times(path, &t_s)?;
        platen_io::columns::check_record_rate(path, &t_s, 1.0)?;
        let mut axes: [Option<Target>; 3] = [None, None, None];
        for (k, axis) in axes.iter_mut().enumerate() {
            *axis = match (
                table.take_column(ACCELERATION_COLUMNS[k]),
                table.take_column(POSE_COLUMNS[k]),
            ) {
                (Some(a), _) => Some(Target::acceleration(path, t_s.clone(), a)?),
                (None, Some(u)) => Some(Target::displacement(path, t_s.clone(), u)?),
                (None, None) => None,
            };
        }
        if axes.iter().all(Option::is_none) {
            return Err(IoError::Record {
                path: path.to_owned(),
                message: "a three-component target needs at least one of the columns x_m_s2, \
                          y_m_s2, z_m_s2 (or the displacements x_m, y_m, z_m); absent axes are \
                          held at zero"
                    .into(),
            }
            .into());
        }
        Self::new(path, axes)
    }

    /// Every axis put on `rate_hz` ([`Target::resampled_to`]: anti-aliased when slower).
    ///
    /// # Errors
    /// As [`Target::resampled_to`].
    pub fn resampled_to(&self, rate_hz: f64) -> Result<Self> {
        let mut axes: [Option<Target>; 3] = [None, None, None];
        for (to, from) in axes.iter_mut().zip(&self.axes) {
            *to = from.as_ref().map(|t| t.resampled_to(rate_hz)).transpose()?;
        }
        Self::new(&self.origin, axes)
    }

    /// Where the target comes from.
    pub fn origin(&self) -> &Path {
        &self.origin
    }

    /// Per axis (x, y, z), its target.
    pub fn axes(&self) -> &[Option<Target>; 3] {
        &self.axes
    }

    /// The first axis's target (every axis has its times).
    fn first(&self) -> &Target {
        self.axes
            .iter()
            .flatten()
            .next()
            .expect("AxisTargets::new holds at least one axis")
    }

    /// The times, s.
    pub fn t_s(&self) -> &[f64] {
        self.first().t_s()
    }

    /// The sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.first().sample_rate_hz()
    }
}

/// What a multi-axis plan does.
#[derive(Debug, Clone, Default)]
pub struct TablePlanSettings {
    /// The baseline treatment of each axis's target.
    pub baseline: BaselineSettings,
    /// The drive iteration (its `frf` is ignored: the table's linearised matrix is used).
    pub iteration: IterationSettings,
    /// The largest common scale (absent: not searched).
    pub max_scale: Option<MaxScaleSettings>,
    /// The largest scale of each axis too, the others as given.
    pub per_axis_max_scale: bool,
    /// Per axis (x, y, z), the required response spectrum its achieved acceleration is
    /// accepted against (`None`: its target's own spectrum).
    pub rrs: [Option<RequiredSpectrum>; 3],
    /// The level the drives are iterated at, a fraction of the target in `(0, 1]` (`None` or
    /// 1: full level), then scaled up and run once at full level, as the single-axis plan's
    /// ([`crate::PlanSettings::iterate_at`]).
    pub iterate_at: Option<f64>,
}

impl TablePlanSettings {
    /// The settings of `platen plan`'s options (and `platen.plan`'s arguments): at most
    /// `iterations` corrections at `gain`, stopping at `target_nrmse`, in `band_hz` (default
    /// band when `None`); the largest common scale searched when `max_scale` or
    /// `per_axis_scale`, each axis's too with `per_axis_scale`; the rest default.
    pub fn new(
        iterations: usize,
        gain: f64,
        target_nrmse: f64,
        band_hz: Option<(f64, f64)>,
        max_scale: bool,
        per_axis_scale: bool,
    ) -> Self {
        Self {
            iteration: IterationSettings {
                max_iterations: iterations,
                gain,
                target_nrmse,
                band_hz,
                ..Default::default()
            },
            max_scale: (max_scale || per_axis_scale).then(MaxScaleSettings::default),
            per_axis_max_scale: per_axis_scale,
            ..Default::default()
        }
    }
}

/// What the table achieved for a drive: its run, the loop's figures, and per axis (x, y, z)
/// the achieved displacement and acceleration at the target's samples.
#[derive(Debug, Clone)]
pub struct TableAchieved {
    /// The run (every column `simulate` writes).
    pub run: TableRun,
    /// The loop's own figures.
    pub stats: TableLoopStats,
}

impl MimoResponse for TableAchieved {
    fn u_m(&self, i: usize) -> &[f64] {
        self.run.column(POSE_COLUMNS[i]).unwrap_or(&[])
    }
    fn a_m_s2(&self, i: usize) -> &[f64] {
        self.run.column(ACCELERATION_COLUMNS[i]).unwrap_or(&[])
    }
    fn saturated_time_s(&self) -> f64 {
        self.stats.saturated_time_s
    }
    fn cavitation_at_s(&self) -> Option<f64> {
        self.stats.cavitation_at_s
    }
}

/// The share of a single-acting actuator's static force below which it counts as lifted off
/// (`{name}.uplift`): 1 %.
pub const UPLIFT_RESIDUAL: f64 = 0.01;

/// One limit of a multi-axis table against a run's peak.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableLimitUse {
    /// The limit: `x.stroke_m`, `z.acceleration_m_s2`, `v3.force_n`, `h1.flow_m3_s`,
    /// `overturning_moment_n_m`, …
    pub limit: String,
    /// The run's signed peak, SI units.
    pub peak: f64,
    /// The allowed value (the bound on the peak's side), SI units.
    pub allowed: f64,
    /// How much of the limit the run uses: above 1 it fails.
    pub ratio: f64,
    /// When the peak occurred, s.
    pub t_s: f64,
    /// When the limit was first exceeded, s (`null` when it was not).
    pub first_exceeded_s: Option<f64>,
}

impl TableLimitUse {
    /// Whether the limit is respected (`ratio ≤ 1`).
    pub fn respected(&self) -> bool {
        self.ratio <= 1.0
    }
}

/// The use of a two-sided limit `[lower ≤ 0, upper ≥ 0]` by `x` at the times `t`.
fn use_of(limit: String, t: &[f64], x: &[f64], lower: f64, upper: f64) -> TableLimitUse {
    let ratio_of = |v: f64| {
        if v >= 0.0 {
            if upper > 0.0 {
                v / upper
            } else if v > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        } else if lower < 0.0 {
            v / lower
        } else {
            f64::INFINITY
        }
    };
    let mut worst = (0.0_f64, 0.0, t.first().copied().unwrap_or(0.0));
    let mut first = None;
    for (&ti, &v) in t.iter().zip(x) {
        let r = ratio_of(v);
        if r > worst.0 {
            worst = (r, v, ti);
        }
        if r > 1.0 && first.is_none() {
            first = Some(ti);
        }
    }
    let (ratio, peak, t_s) = worst;
    TableLimitUse {
        limit,
        peak,
        allowed: if peak >= 0.0 { upper } else { lower },
        ratio,
        t_s,
        first_exceeded_s: first,
    }
}

/// Every limit of the scenario's table against the run `r` (see the [module
/// documentation](self)), in a fixed order: the axes' (x … yaw, where `table.limits` gives
/// them), the actuators' (in the table's order), the overturning moment.
pub fn limit_uses(scenario: &TableScenario, r: &TableRun) -> Vec<TableLimitUse> {
    let col = |name: &str| r.column(name).unwrap_or(&[]);
    let t = col("t_s");
    let mut uses = Vec::new();
    let names = ["x", "y", "z", "roll", "pitch", "yaw"];
    for (k, limits) in scenario.limits.each().iter().enumerate() {
        let kinds: [(&str, &str); 3] = if k < 3 {
            [
                ("stroke_m", POSE_COLUMNS[k]),
                ("velocity_m_s", RATE_COLUMNS[k]),
                ("acceleration_m_s2", ACCELERATION_COLUMNS[k]),
            ]
        } else {
            [
                ("angle_rad", POSE_COLUMNS[k]),
                ("rate_rad_s", RATE_COLUMNS[k]),
                ("acceleration_rad_s2", ACCELERATION_COLUMNS[k]),
            ]
        };
        for (limit, (what, column)) in limits.iter().zip(kinds) {
            if let Some(l) = limit {
                uses.push(use_of(
                    format!("{}.{what}", names[k]),
                    t,
                    col(column),
                    -l,
                    *l,
                ));
            }
        }
    }
    let capacities = scenario.flow_capacities_m3_s();
    for (i, (a, (pull, push))) in scenario
        .table
        .actuators()
        .iter()
        .zip(scenario.force_limits_n())
        .enumerate()
    {
        let name = &a.name;
        uses.push(use_of(
            format!("{name}.stroke_m"),
            t,
            col(&format!("{name}_stroke_m")),
            -a.stroke_m,
            a.stroke_m,
        ));
        uses.push(use_of(
            format!("{name}.force_n"),
            t,
            col(&format!("{name}_force_n")),
            pull,
            push,
        ));
        let force = col(&format!("{name}_force_n"));
        if a.rod_side_area_m2 == 0.0 && force.first().is_some_and(|&f0| f0 > 0.0) {
            // Single-acting: its share of the static hold is its preload; losing it all
            // (below UPLIFT_RESIDUAL of it) the chamber nears the cavitation floor and the
            // actuator no longer holds the platen down.
            let f0 = force[0];
            let mut u = use_of(
                format!("{name}.uplift"),
                t,
                &force.iter().map(|f| f0 - f).collect::<Vec<_>>(),
                f64::NEG_INFINITY,
                (1.0 - UPLIFT_RESIDUAL) * f0,
            );
            u.peak = f0 - u.peak;
            u.allowed = UPLIFT_RESIDUAL * f0;
            uses.push(u);
        }
        if let (Some(c), Some(flow)) = (&capacities, r.column(&format!("{name}_flow_m3_s"))) {
            uses.push(use_of(format!("{name}.flow_m3_s"), t, flow, -c[i], c[i]));
        }
    }
    if let (Some(limit), Some(mx), Some(my)) = (
        scenario.limits.overturning_moment_n_m,
        r.column("overturning_moment_x_n_m"),
        r.column("overturning_moment_y_n_m"),
    ) {
        let m: Vec<f64> = mx.iter().zip(my).map(|(a, b)| a.hypot(*b)).collect();
        uses.push(use_of(
            "overturning_moment_n_m".to_owned(),
            t,
            &m,
            -limit,
            limit,
        ));
    }
    uses
}

/// The limits that fail, worst first.
fn failing(uses: &[TableLimitUse]) -> Vec<TableLimitUse> {
    let mut f: Vec<TableLimitUse> = uses.iter().filter(|u| !u.respected()).cloned().collect();
    f.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    f
}

/// The feasibility of a target on a multi-axis table.
#[derive(Debug, Clone, Serialize)]
pub struct TableFeasibility {
    /// Whether every limit is respected.
    pub feasible: bool,
    /// The limits that fail, worst first.
    pub limiting: Vec<TableLimitUse>,
    /// The failing limit exceeded first, with when (`null` when feasible).
    pub binds_first: Option<TableLimitUse>,
    /// Every limit against the run of the target's own commands.
    pub uses: Vec<TableLimitUse>,
    /// The largest common scale that fits (`null` when not asked for).
    pub max_scale: Option<MaxScale>,
    /// The largest scale of each axis given, the others as given (empty when not asked for).
    pub per_axis_max_scale: BTreeMap<&'static str, MaxScale>,
}

/// A plant: the scenario's closed loop driven by per-axis displacement commands.
pub struct TablePlant<'a> {
    scenario: &'a TableScenario,
    t_s: &'a [f64],
}

impl<'a> TablePlant<'a> {
    /// The closed loop of `scenario` (one with a `controller`), commanded at the times `t_s`.
    pub fn new(scenario: &'a TableScenario, t_s: &'a [f64]) -> Self {
        Self { scenario, t_s }
    }

    /// The six-DOF command of the drives `u_m` (x, y, z; rotations still).
    ///
    /// # Errors
    /// As [`pose_command`].
    pub fn command(&self, u_m: &[Vec<f64>]) -> Result<PoseMotion> {
        pose_command(self.t_s, u_m)
    }

    /// Runs the drives `u_m` (x, y, z).
    ///
    /// # Errors
    /// [`PlanError::Scenario`] if the run fails (a non-finite state, the actuators losing
    /// rank).
    pub fn run(&self, u_m: &[Vec<f64>]) -> Result<TableAchieved> {
        let command = self.command(u_m)?;
        let (run, stats) = self.scenario.commanded(command)?.run_with_stats()?;
        Ok(TableAchieved {
            run,
            stats: stats.expect("a commanded scenario is a closed loop"),
        })
    }
}

/// The six-DOF command of the drives `u_m` (x, y, z; absent axes and the rotations still)
/// at the times `t_s`, each DOF's rate and acceleration derived as `simulate` derives them
/// from a `motion_csv`'s pose column ([`command_motion`]).
///
/// # Errors
/// [`PlanError::Run`] if the times are not a uniform grid.
pub fn pose_command(t_s: &[f64], u_m: &[Vec<f64>]) -> Result<PoseMotion> {
    let zero = vec![0.0; t_s.len()];
    let dofs: Vec<platen_integrate::Motion> = (0..6)
        .map(|k| command_motion(t_s, u_m.get(k).map_or(&zero[..], |u| &u[..])))
        .collect::<Result<_>>()?;
    let Ok(dofs) = <[platen_integrate::Motion; 6]>::try_from(dofs) else {
        unreachable!("six DOFs")
    };
    PoseMotion::new(dofs).map_err(|source| PlanError::Run {
        what: "the six-DOF command".into(),
        source,
    })
}

/// Drives iterated at a low level and scaled up ([`TablePlanSettings::iterate_at`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableIteratedAt {
    /// The level, a fraction of the target.
    pub level: f64,
    /// The best iteration's record at that level.
    pub at_level: crate::mimo::MimoRecord,
    /// The scaled-up drives' run at full level: the predicted full-level error.
    pub full_level: crate::mimo::MimoRecord,
}

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
    /// The drive iteration.
    pub iteration: MimoIteration<TableAchieved>,
    /// The acceleration the target's own commands achieved (iteration 0), per axis (x, y,
    /// z), m/s².
    pub first_a_m_s2: Vec<Vec<f64>>,
    /// The best drive's limits.
    pub drive_uses: Vec<TableLimitUse>,
    /// Per axis given, the best drive's achieved response spectrum against its required one
    /// (its RRS, or its target's own spectrum).
    pub spectrum_acceptance: BTreeMap<&'static str, SpectrumAcceptance>,
    /// Where the drives were iterated at a low level and scaled up (`None`: at full level);
    /// the iteration's drives and `achieved` are then the scaled-up ones and their run.
    pub iterated_at: Option<TableIteratedAt>,
    /// What an engineer should look at.
    pub warnings: Vec<String>,
}

/// Plans `targets` on the closed loop of the multi-axis scenario `file` (at `path`; its
/// excitation is ignored): feasibility, the largest scale that fits (when asked), the drives
/// iterated (see the [module documentation](self)); `on_run(k)` is called when drive
/// iteration `k`'s run is done.
///
/// # Errors
/// The scenario's errors (with their JSON paths); a target whose acceleration is zero on
/// every axis; an RRS period shorter than two samples of the drive; bad settings (an
/// `iterate_at` outside (0, 1]); a run that fails. A target faster than the controller is
/// resampled to its rate, with a notice in the plan's warnings.
pub fn plan_multi_axis(
    path: &Path,
    file: &ScenarioFile,
    targets: &AxisTargets,
    settings: &TablePlanSettings,
    on_run: &mut dyn FnMut(usize),
) -> Result<TablePlan> {
    if let Some(level) = settings.iterate_at {
        check_setting(
            "iterate_at",
            level,
            level > 0.0 && level <= 1.0,
            "a fraction of the target in (0, 1]",
        )?;
    }
    let level = settings.iterate_at.unwrap_or(1.0);
    // The closed loop, first commanded still (its controller's rate bounds the target's).
    let scenario =
        TableScenario::commanded_from_file(path, file, pose_command(targets.t_s(), &[])?)?;
    let system = scenario
        .system
        .as_ref()
        .expect("a commanded scenario has a closed loop");
    let controller_hz = system.controller.sample_rate_hz();
    // A target faster than the controller is put on its rate (anti-aliased), with a notice,
    // as a uniaxial one.
    let given = targets;
    let resampled;
    let mut notices = Vec::new();
    let targets = if given.sample_rate_hz() > controller_hz * (1.0 + 1e-9) {
        resampled = given.resampled_to(controller_hz)?;
        notices.push(crate::plan::resample_notice(
            given.sample_rate_hz(),
            controller_hz,
        ));
        &resampled
    } else {
        given
    };
    // Each axis's command.
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
        let motion =
            TargetMotion::new(target, &settings.baseline, stroke, target.sample_rate_hz())?;
        motions.insert(AXES[k], motion);
    }
    let t_s: Vec<f64> = motions
        .values()
        .next()
        .map(|m| m.t_s.clone())
        .unwrap_or_default();
    let n = t_s.len();
    let interval_s = motions
        .values()
        .next()
        .map_or(1.0 / controller_hz, TargetMotion::interval_s);
    let axis_targets: Vec<AxisTarget> = AXES
        .iter()
        .map(|&axis| match motions.get(axis) {
            Some(m) => AxisTarget {
                name: axis,
                u_m: m.u_m.clone(),
                a_m_s2: m.a_m_s2.clone(),
            },
            None => AxisTarget::still(axis, n),
        })
        .collect();
    if axis_targets.iter().all(AxisTarget::is_still) {
        return Err(PlanError::Target {
            origin: targets.origin().display().to_string(),
            message: "the target's acceleration is zero on every axis: nothing to reproduce".into(),
        });
    }
    for rrs in settings.rrs.iter().flatten() {
        rrs.check_rate(1.0 / interval_s)?;
    }
    let plant = TablePlant::new(&scenario, &t_s);
    let drives0: Vec<Vec<f64>> = axis_targets.iter().map(|a| a.u_m.clone()).collect();
    // Feasibility of the target's own commands.
    let first = plant.run(&drives0)?;
    let cavitation_at_first = first.stats.cavitation_at_s;
    let first_a_m_s2: Vec<Vec<f64>> = (0..3).map(|i| first.a_m_s2(i).to_vec()).collect();
    let uses = limit_uses(&scenario, &first.run);
    let limiting = failing(&uses);
    let binds_first = limiting
        .iter()
        .filter_map(|u| u.first_exceeded_s.map(|t| (t, u)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, u)| u.clone());
    let scaled_failing = |axes_scale: [f64; 3]| {
        let drives: Vec<Vec<f64>> = drives0
            .iter()
            .zip(axes_scale)
            .map(|(d, s)| d.iter().map(|x| x * s).collect())
            .collect();
        match plant.run(&drives) {
            Ok(a) => failing(&limit_uses(&scenario, &a.run))
                .into_iter()
                .map(|u| u.limit)
                .collect(),
            Err(_) => vec!["run_failed".to_owned()],
        }
    };
    let worst = uses.iter().map(|u| u.ratio).fold(0.0, f64::max);
    let unscaled_failing: Vec<String> = limiting.iter().map(|u| u.limit.clone()).collect();
    let mut per_axis_max_scale = BTreeMap::new();
    let max_scale = match &settings.max_scale {
        Some(s) => {
            let mut found = search_max_scale(s, worst, unscaled_failing.clone(), &mut |k| {
                scaled_failing([k; 3])
            })?;
            found.runs += 1;
            if settings.per_axis_max_scale {
                for (k, axis) in AXES.iter().enumerate() {
                    if axis_targets[k].is_still() {
                        continue;
                    }
                    let mut one =
                        search_max_scale(s, worst, unscaled_failing.clone(), &mut |scale| {
                            let mut scales = [1.0; 3];
                            scales[k] = scale;
                            scaled_failing(scales)
                        })?;
                    one.runs += 1;
                    per_axis_max_scale.insert(*axis, one);
                }
            }
            Some(found)
        }
        None => None,
    };
    on_run(0);
    let feasibility = TableFeasibility {
        feasible: limiting.is_empty(),
        limiting,
        binds_first,
        uses,
        max_scale,
        per_axis_max_scale,
    };
    // The drive iteration, through the x, y, z block of the linearised transfer matrix.
    let lin = TableLinearisation::new(
        &scenario.table,
        &system.hydraulics,
        &system.controller,
        scenario.specimen.as_ref(),
    )
    .map_err(|e| PlanError::Target {
        origin: path.display().to_string(),
        message: format!("the table's loop cannot be linearised: {e}"),
    })?;
    let frf = |f: f64| -> TransferMatrix {
        let h = lin.transfer_matrix(f);
        (0..3).map(|i| (0..3).map(|j| h[i][j]).collect()).collect()
    };
    // At a low level, the iteration's first run is its own (the feasibility's is at full).
    let iterated: Vec<AxisTarget> = axis_targets.iter().map(|t| t.scaled(level)).collect();
    let mut first = (level == 1.0).then_some(first);
    let mut iteration = iterate_mimo(
        if level < 1.0 {
            &iterated
        } else {
            &axis_targets
        },
        interval_s,
        &frf,
        &settings.iteration,
        |drives, k| {
            let r = match (k, first.take()) {
                (0, Some(r)) => r,
                _ => plant.run(drives)?,
            };
            if k > 0 {
                on_run(k);
            }
            Ok(r)
        },
    )?;
    let mut warnings = Vec::new();
    let iterated_at = if level < 1.0 {
        let at_level = iteration.best_record().clone();
        let drives: Vec<Vec<f64>> = iteration
            .drive_u_m
            .iter()
            .map(|d| d.iter().map(|x| x / level).collect())
            .collect();
        let full = plant.run(&drives)?;
        let full_level = crate::mimo::record_of_run(
            iteration.best,
            &axis_targets,
            interval_s,
            &full,
            &drives,
            &settings.iteration.spectrum,
        )?;
        warnings.extend(crate::plan::scaled_up_warning(
            level,
            full_level.acceleration_nrmse,
            at_level.acceleration_nrmse,
        ));
        iteration.drive_u_m = drives;
        iteration.achieved = full;
        Some(TableIteratedAt {
            level,
            at_level,
            full_level,
        })
    } else {
        None
    };
    let drive_uses = limit_uses(&scenario, &iteration.achieved.run);
    if let Some(t) = cavitation_at_first {
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
    for u in failing(&drive_uses) {
        warnings.push(format!(
            "the best drive exceeds {}: {:.3} times its limit at {:.3} s",
            u.limit, u.ratio, u.t_s
        ));
    }
    if let Some(t) = iteration.achieved.stats.cavitation_at_s {
        warnings.push(format!("the best drive cavitates a chamber at {t:.3} s"));
    }
    // Each axis given, its achieved spectrum against its RRS (or its target's).
    let mut spectrum_acceptance = BTreeMap::new();
    for (k, axis) in AXES.iter().enumerate() {
        let Some(motion) = motions.get(axis) else {
            continue;
        };
        let achieved_a = iteration.achieved.a_m_s2(k);
        let acceptance = match &settings.rrs[k] {
            Some(rrs) => rrs.acceptance(1.0 / interval_s, achieved_a, ACCEPTANCE_BAND)?,
            None => spectrum_acceptance_of(
                &settings.iteration.spectrum,
                1.0 / interval_s,
                &motion.a_m_s2,
                achieved_a,
                ACCEPTANCE_BAND,
            )?,
        };
        warnings.extend(crate::plan::acceptance_warning(
            &format!("the best drive's achieved {axis} response spectrum"),
            &acceptance,
        ));
        spectrum_acceptance.insert(*axis, acceptance);
    }
    Ok(TablePlan {
        scenario_name: scenario.name.clone(),
        scenario_path: path.to_owned(),
        target_origin: given.origin().to_owned(),
        target_samples: given.t_s().len(),
        target_rate_hz: given.sample_rate_hz(),
        targets: axis_targets,
        t_s,
        motions,
        feasibility,
        iteration,
        first_a_m_s2,
        drive_uses,
        spectrum_acceptance,
        iterated_at,
        warnings,
    })
}

impl TablePlan {
    /// The best drives as the six-DOF `motion_csv` columns `simulate` replays: `t_s`, then
    /// `x_m` … `yaw_rad` (the rotations zero).
    pub fn drive_columns(&self) -> (Vec<&'static str>, Vec<Vec<f64>>) {
        let n = self.t_s.len();
        let mut columns = vec![self.t_s.clone()];
        for k in 0..6 {
            columns.push(
                self.iteration
                    .drive_u_m
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| vec![0.0; n]),
            );
        }
        (DRIVE_COLUMNS.to_vec(), columns)
    }

    /// Writes the best drives' rows to `writer` (created with [`DRIVE_COLUMNS`]) and
    /// finishes it.
    ///
    /// # Errors
    /// [`PlanError::Io`] if it cannot be written.
    pub fn write_drive_rows(&self, mut writer: platen_io::csv::CsvWriter) -> Result<()> {
        let (_, columns) = self.drive_columns();
        let mut row = vec![0.0; columns.len()];
        for j in 0..self.t_s.len() {
            for (r, c) in row.iter_mut().zip(&columns) {
                *r = c[j];
            }
            writer.write_row(&row)?;
        }
        writer.finish()?;
        Ok(())
    }

    /// Writes the best drives to `path` as a six-DOF `motion_csv` (see
    /// [`TablePlan::drive_columns`]), atomically.
    ///
    /// # Errors
    /// [`PlanError::Io`] if it cannot be written.
    pub fn write_drive(&self, path: &Path) -> Result<()> {
        let (names, columns) = self.drive_columns();
        let refs: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
        platen_io::csv::write_csv_atomic(path, &names, &refs)?;
        Ok(())
    }
}

/// One axis of the target, as the summary reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisTargetSummary {
    /// `acceleration` or `displacement`.
    pub kind: &'static str,
    /// Largest acceleration to reproduce (after the baseline treatment), m/s².
    pub peak_a_m_s2: f64,
    /// Largest displacement of its command, m.
    pub peak_u_m: f64,
    /// RMS of its acceleration, m/s².
    pub rms_a_m_s2: f64,
    /// The end-correction degree (acceleration targets).
    pub baseline_degree: Option<usize>,
    /// RMS of the acceleration the baseline treatment removed, m/s².
    pub baseline_correction_rms_m_s2: f64,
}

/// The target, as the summary reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableTargetSummary {
    /// Its file (or origin).
    pub file: String,
    /// Samples of the target.
    pub samples: usize,
    /// Its sample rate, Hz.
    pub sample_rate_hz: f64,
    /// The drive's rate (the controller's), Hz.
    pub drive_sample_rate_hz: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Per axis given; the others are held at zero.
    pub axes: BTreeMap<&'static str, AxisTargetSummary>,
}

/// The matrix `Ĥ` and the iteration's settings, as the summary reports them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MatrixFrfSummary {
    /// `linearised` (the x, y, z block of the table's linearised command → pose matrix).
    pub source: &'static str,
    /// The correction band, Hz.
    pub band_hz: [f64; 2],
    /// The gain `g`.
    pub gain: f64,
    /// `ε` of the regularised inverse.
    pub regularisation: f64,
    /// FFT length (record and padding), samples.
    pub fft_len: usize,
    /// The largest condition number of `Ĥ` in the band.
    pub max_condition: f64,
}

/// The drives, as the summary reports them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableDriveSummary {
    /// The CSV written, if any.
    pub out: Option<String>,
    /// Samples.
    pub samples: usize,
    /// Per axis, the drive's largest displacement, m.
    pub peak_u_m: BTreeMap<&'static str, f64>,
    /// What the drives achieve at full level (the best iteration's run; with `iterate_at`,
    /// the scaled-up drives' run: the predicted full-level error).
    pub achieved: crate::mimo::MimoRecord,
    /// With `iterate_at`, what the best iteration achieved at that level (`null` otherwise).
    pub at_iteration_level: Option<crate::mimo::MimoRecord>,
    /// The limits the drives' run exceeds, worst first.
    pub limiting: Vec<TableLimitUse>,
    /// Per axis given, its achieved response spectrum against its required one.
    pub spectrum_acceptance: BTreeMap<&'static str, SpectrumAcceptance>,
}

/// What `platen plan --json` prints for a multi-axis scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TablePlanSummary {
    /// The scenario file.
    pub scenario: String,
    /// The scenario's name.
    pub name: String,
    /// The target.
    pub target: TableTargetSummary,
    /// Whether the target's own commands respect every limit.
    pub feasible: bool,
    /// The limits that fail, worst first.
    pub limiting: Vec<TableLimitUse>,
    /// The failing limit exceeded first, with when (`null` when feasible).
    pub binds_first: Option<TableLimitUse>,
    /// Every limit with its peak, allowed value, ratio and times.
    pub margins: Vec<TableLimitUse>,
    /// The largest common scale that fits (`null` when not searched).
    pub max_scale: Option<f64>,
    /// How it was found (`null` when not searched).
    pub max_scale_search: Option<MaxScale>,
    /// Per axis, the largest scale of that axis with the others as given (empty unless
    /// asked for).
    pub per_axis_max_scale: BTreeMap<&'static str, f64>,
    /// The level the drives were iterated at, a fraction of the target (`null`: full level).
    pub iterate_at: Option<f64>,
    /// Every iteration's figures, from 0 (the target's own commands).
    pub iterations: Vec<crate::mimo::MimoRecord>,
    /// The iteration whose drives are written.
    pub best_iteration: usize,
    /// `converged`, `max_iterations` or `stalled`.
    pub stop: &'static str,
    /// Why the iteration stalled (`null` otherwise).
    pub stall_reason: Option<String>,
    /// `Ĥ` and the iteration's settings.
    pub frf: MatrixFrfSummary,
    /// The drives.
    pub drive: TableDriveSummary,
    /// What the planner wants its user to know.
    pub warnings: Vec<String>,
}

impl TablePlan {
    /// The summary, with `out` the drive CSV written (if any) and `settings` the plan's.
    pub fn summary(&self, settings: &TablePlanSettings, out: Option<&Path>) -> TablePlanSummary {
        let f = &self.feasibility;
        let it = &self.iteration;
        let first = self.motions.values().next();
        let target_t = first.map_or(&[][..], |m| &m.t_s[..]);
        TablePlanSummary {
            scenario: self.scenario_path.display().to_string(),
            name: self.scenario_name.clone(),
            target: TableTargetSummary {
                file: self.target_origin.display().to_string(),
                samples: self.target_samples,
                sample_rate_hz: self.target_rate_hz,
                drive_sample_rate_hz: first.map_or(0.0, |m| 1.0 / m.interval_s()),
                duration_s: target_t
                    .last()
                    .zip(target_t.first())
                    .map_or(0.0, |(b, a)| b - a),
                axes: self
                    .motions
                    .iter()
                    .map(|(axis, m)| {
                        (
                            *axis,
                            AxisTargetSummary {
                                kind: m.kind.name(),
                                peak_a_m_s2: crate::baseline::peak(&m.a_m_s2),
                                peak_u_m: m.peak_u_m(),
                                rms_a_m_s2: m.target_rms_m_s2,
                                baseline_degree: m.end_degree,
                                baseline_correction_rms_m_s2: m.correction_rms_m_s2,
                            },
                        )
                    })
                    .collect(),
            },
            feasible: f.feasible,
            limiting: f.limiting.clone(),
            binds_first: f.binds_first.clone(),
            margins: f.uses.clone(),
            max_scale: f.max_scale.as_ref().map(|m| m.scale),
            max_scale_search: f.max_scale.clone(),
            per_axis_max_scale: f
                .per_axis_max_scale
                .iter()
                .map(|(k, m)| (*k, m.scale))
                .collect(),
            iterate_at: self.iterated_at.as_ref().map(|i| i.level),
            iterations: it.records.clone(),
            best_iteration: it.best,
            stop: it.stop.name(),
            stall_reason: match &it.stop {
                crate::iterate::Stop::Stalled { reason } => Some(reason.clone()),
                _ => None,
            },
            frf: MatrixFrfSummary {
                source: "linearised",
                band_hz: [it.band_hz.0, it.band_hz.1],
                gain: settings.iteration.gain,
                regularisation: settings.iteration.regularisation,
                fft_len: it.fft_len,
                max_condition: it.max_condition,
            },
            drive: TableDriveSummary {
                out: out.map(|p| p.display().to_string()),
                samples: self.t_s.len(),
                peak_u_m: AXES
                    .iter()
                    .zip(&it.drive_u_m)
                    .map(|(a, d)| (*a, crate::baseline::peak(d)))
                    .collect(),
                achieved: self
                    .iterated_at
                    .as_ref()
                    .map_or_else(|| it.best_record().clone(), |i| i.full_level.clone()),
                at_iteration_level: self.iterated_at.as_ref().map(|i| i.at_level.clone()),
                limiting: failing(&self.drive_uses),
                spectrum_acceptance: self.spectrum_acceptance.clone(),
            },
            warnings: self.warnings.clone(),
        }
    }
}

/// The plan's summary in words, for `platen plan` without `--json`.
pub fn summary_text(s: &TablePlanSummary) -> String {
    use std::fmt::Write as _;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{}: three-component plan of `{}` ({} samples at {} Hz, drive at {} Hz, {:.3} s)",
        s.name,
        s.target.file,
        s.target.samples,
        s.target.sample_rate_hz,
        s.target.drive_sample_rate_hz,
        s.target.duration_s
    );
    for axis in AXES {
        match s.target.axes.get(axis) {
            Some(a) => {
                let _ = writeln!(
                    t,
                    "  {axis}: {} target, peak {:.4} m/s², command peak {:.4} m",
                    a.kind, a.peak_a_m_s2, a.peak_u_m
                );
            }
            None => {
                let _ = writeln!(t, "  {axis}: held at zero");
            }
        }
    }
    let _ = writeln!(t, "feasible: {}", if s.feasible { "yes" } else { "no" });
    if let Some(b) = &s.binds_first {
        let _ = writeln!(
            t,
            "  binds first: {} at {:.3} s (peak {:.4e} against {:.4e}, {:.3} times at {:.3} s)",
            b.limit,
            b.first_exceeded_s.unwrap_or(b.t_s),
            b.peak,
            b.allowed,
            b.ratio,
            b.t_s
        );
    }
    for u in &s.limiting {
        let _ = writeln!(
            t,
            "  exceeded: {:<28} {:.3} times its limit ({:.4e} against {:.4e}) at {:.3} s",
            u.limit, u.ratio, u.peak, u.allowed, u.t_s
        );
    }
    let mut closest: Vec<&TableLimitUse> = s.margins.iter().collect();
    closest.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    let _ = writeln!(t, "  closest limits:");
    for u in closest.iter().take(5) {
        let _ = writeln!(
            t,
            "    {:<28} {:>6.1} % ({:.4e} against {:.4e}) at {:.3} s",
            u.limit,
            100.0 * u.ratio,
            u.peak,
            u.allowed,
            u.t_s
        );
    }
    if let Some(m) = s.max_scale {
        let _ = writeln!(t, "largest common scale that fits: {m:.4}");
    }
    for (axis, m) in &s.per_axis_max_scale {
        let _ = writeln!(t, "  largest scale of {axis} alone: {m:.4}");
    }
    let _ = writeln!(
        t,
        "drive iteration (matrix Ĥ, linearised; band {}–{} Hz, gain {}, largest condition number {:.1}):",
        s.frf.band_hz[0], s.frf.band_hz[1], s.frf.gain, s.frf.max_condition
    );
    let _ = writeln!(
        t,
        "  iter  overall   x nrmse   y nrmse   z nrmse   (held axes: rms error, m/s²)"
    );
    for r in &s.iterations {
        let cell = |axis: &str| {
            let a = &r.axes[axis];
            a.acceleration_nrmse.map_or_else(
                || format!("({:.3})", a.rms_acceleration_error_m_s2),
                |e| format!("{:.2} %", 100.0 * e),
            )
        };
        let _ = writeln!(
            t,
            "  {:>4}  {:>6.2} %  {:>8}  {:>8}  {:>8}",
            r.iteration,
            100.0 * r.acceleration_nrmse,
            cell("x"),
            cell("y"),
            cell("z")
        );
    }
    let _ = writeln!(
        t,
        "  stop: {}{}; best iteration {}",
        s.stop,
        s.stall_reason
            .as_ref()
            .map_or(String::new(), |r| format!(" ({r})")),
        s.best_iteration
    );
    if let (Some(level), Some(low)) = (s.iterate_at, &s.drive.at_iteration_level) {
        let _ = writeln!(
            t,
            "  iterated at {:.0} % of the target ({:.2} % overall acceleration NRMSE there), \
             scaled up by {:.4}: predicted full-level error {:.2} % overall acceleration NRMSE",
            100.0 * level,
            100.0 * low.acceleration_nrmse,
            1.0 / level,
            100.0 * s.drive.achieved.acceleration_nrmse
        );
    }
    for (axis, a) in &s.drive.spectrum_acceptance {
        let _ = writeln!(t, "  {}", a.line(&format!("{axis} response spectrum")));
    }
    if let Some(out) = &s.drive.out {
        let _ = writeln!(
            t,
            "wrote {out} (t_s, x_m … yaw_rad: replay it with a motion_csv)"
        );
    }
    t
}
