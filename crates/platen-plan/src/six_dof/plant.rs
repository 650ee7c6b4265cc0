//! The multi-axis table as a plant of the drive iteration: its closed loop driven by per-axis
//! displacement commands ([`TablePlant`]) and what it achieves ([`TableAchieved`]).

use platen_integrate::{PoseMotion, TableLoopStats, TableRun};
use platen_scenario::multi_axis::{TableScenario, ACCELERATION_COLUMNS, POSE_COLUMNS};

use crate::baseline::command_motion;
use crate::error::{PlanError, Result};
use crate::iterate::Response;

/// What the table achieved for a drive: its run, the loop's figures, and per axis (x, y, z)
/// the achieved displacement and acceleration at the target's samples.
#[derive(Debug, Clone)]
pub struct TableAchieved {
    /// The run (every column `simulate` writes).
    pub run: TableRun,
    /// The loop's own figures.
    pub stats: TableLoopStats,
}

impl Response for TableAchieved {
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
