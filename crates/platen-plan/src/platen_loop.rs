//! The simulated table: a rig's closed loop (model, `table_system`, specimen) driven by any
//! displacement command ([`PlatenLoop::run`]).

use std::path::{Path, PathBuf};

use platen_integrate::{IntegrateError, Peak, Peaks, Sample, SampleSink};
use platen_scenario::{LoadedRig, LoopSettings, Rig, RunOutput};
use platen_system::TableSystem;

use crate::baseline::command_motion;
use crate::error::{PlanError, Result};

/// A rig's closed loop, ready to run any command: what the planner simulates.
#[derive(Debug, Clone, Copy)]
pub struct PlatenLoop<'a> {
    rig: &'a Rig,
    system: &'a TableSystem,
    settings: LoopSettings,
}

/// What a run of the table gives: the achieved motion at the command's samples, and the
/// run's peaks and loop statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct Achieved {
    /// Where the run stopped at the end of the actuators, if it did
    /// ([`PlatenLoop::run_or_end_stop`]): the samples and peaks then hold the run up to there, and
    /// `output` has no statistics.
    pub end_stop: Option<Peak>,
    /// Achieved displacement, m.
    pub u_m: Vec<f64>,
    /// Achieved velocity, m/s.
    pub v_m_s: Vec<f64>,
    /// Achieved acceleration, m/s² (0 while the platen sticks).
    pub a_m_s2: Vec<f64>,
    /// The run's peaks, statistics and tracking ([`Rig::run`]'s output).
    pub output: RunOutput,
    /// The lowest supply pressure and when, Pa.
    pub min_supply_pressure: Peak,
    /// The signed peak flow of the valves into the cap-side chambers and when, m³/s.
    pub flow_peak: Peak,
    /// Samples at which the platen was stuck.
    pub stuck_samples: usize,
}

impl Achieved {
    /// Time with the valves' drive saturated, s.
    pub fn saturated_time_s(&self) -> f64 {
        self.output.system.map_or(0.0, |s| s.stats.saturated_time_s)
    }

    /// First time a chamber reached the cavitation floor, s.
    pub fn cavitation_at_s(&self) -> Option<f64> {
        self.output.system.and_then(|s| s.stats.cavitation_at_s)
    }

    /// Time the platen spent stuck (friction), s.
    pub fn stick_time_s(&self) -> f64 {
        self.output.stats.as_ref().map_or(0.0, |s| s.stick_time_s)
    }
}

/// Collects the achieved motion, its peaks, the valves' peak flow and the lowest supply
/// pressure (kept when a run stops early).
struct Recorder {
    u: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    peaks: Peaks,
    min_supply: Peak,
    flow: Peak,
    stuck: usize,
}

impl SampleSink for Recorder {
    #[inline]
    fn accept(&mut self, s: &Sample) {
        self.u.push(s.u_m);
        self.v.push(s.v_m_s);
        self.a.push(s.a_m_s2);
        if s.stuck {
            self.stuck += 1;
        }
        self.peaks.accept(s);
        if let Some(sy) = &s.system {
            if sy.flow_m3_s.abs() > self.flow.value.abs() {
                self.flow = Peak {
                    value: sy.flow_m3_s,
                    t_s: s.t_s,
                };
            }
            if self.u.len() == 1 || sy.supply_pressure_pa < self.min_supply.value {
                self.min_supply = Peak {
                    value: sy.supply_pressure_pa,
                    t_s: s.t_s,
                };
            }
        }
    }
}

impl<'a> PlatenLoop<'a> {
    /// The table of `rig`, which must have a `table_system`, its loop integrated as
    /// `settings` say; `path` names the rig's scenario file in the error.
    ///
    /// # Errors
    /// [`PlanError::NoTableSystem`].
    pub fn new(rig: &'a Rig, settings: LoopSettings, path: &Path) -> Result<Self> {
        match &rig.table_system {
            Some(system) => Ok(Self {
                rig,
                system,
                settings,
            }),
            None => Err(PlanError::NoTableSystem {
                scenario: PathBuf::from(path),
            }),
        }
    }

    /// The table of a rig read from the scenario file `path` ([`LoadedRig::load`]), with the
    /// file's loop settings ([`LoadedRig::loop_settings`]).
    ///
    /// # Errors
    /// [`PlanError::Scenario`] for the file's errors (its integrator's too);
    /// [`PlanError::NoTableSystem`].
    pub fn of_loaded(loaded: &'a LoadedRig, path: &Path) -> Result<Self> {
        match loaded.loop_settings()? {
            Some(settings) => Self::new(&loaded.rig, settings, path),
            None => Err(PlanError::NoTableSystem {
                scenario: PathBuf::from(path),
            }),
        }
    }

    /// The rig.
    pub fn rig(&self) -> &'a Rig {
        self.rig
    }

    /// The rig's table system.
    pub fn system(&self) -> &'a TableSystem {
        self.system
    }

    /// How the loop is integrated and where the platen starts.
    pub fn settings(&self) -> &LoopSettings {
        &self.settings
    }

    /// The controller's sample rate, Hz.
    pub fn controller_rate_hz(&self) -> f64 {
        self.system.controller().sample_rate_hz
    }

    /// Runs the closed loop with the displacement command `u_m` at the stamps `t_s` (its
    /// velocity and acceleration derived as `simulate` derives them from a `motion_csv` with
    /// `u_m` only: [`command_motion`]). `what` names the run in an error.
    ///
    /// # Errors
    /// [`PlanError::Run`] when the command is refused or the run fails numerically or at the
    /// end of the actuators.
    pub fn run(&self, t_s: &[f64], u_m: &[f64], what: &str) -> Result<Achieved> {
        let achieved = self.run_or_end_stop(t_s, u_m, what)?;
        match achieved.end_stop {
            Some(stop) => Err(PlanError::Run {
                what: what.to_owned(),
                source: IntegrateError::EndStop {
                    t_s: stop.t_s,
                    u_m: stop.value,
                },
            }),
            None => Ok(achieved),
        }
    }

    /// [`PlatenLoop::run`], but a run that reaches the end of the actuators (a chamber's oil
    /// volume gone) is an answer, not an error: [`Achieved::end_stop`] says where, and the
    /// rest holds the run up to there.
    ///
    /// # Errors
    /// [`PlanError::Run`] when the command is refused or the run fails numerically.
    pub fn run_or_end_stop(&self, t_s: &[f64], u_m: &[f64], what: &str) -> Result<Achieved> {
        let command = command_motion(t_s, u_m)?;
        let n = command.len();
        let mut rec = Recorder {
            u: Vec::with_capacity(n),
            v: Vec::with_capacity(n),
            a: Vec::with_capacity(n),
            peaks: Peaks::default(),
            min_supply: Peak::default(),
            flow: Peak::default(),
            stuck: 0,
        };
        let result = self.rig.model.run_closed_loop(
            self.system,
            &self.settings,
            &command,
            self.rig.specimen.as_ref(),
            &mut rec,
        );
        let (output, end_stop) = match result {
            Ok(output) => (output, None),
            Err(IntegrateError::EndStop { t_s, u_m }) => {
                let stop = Peak { value: u_m, t_s };
                let mut peaks = rec.peaks;
                if u_m.abs() > peaks.u_m.value.abs() {
                    peaks.u_m = stop;
                }
                let output = RunOutput {
                    peaks,
                    stats: None,
                    system: None,
                };
                (output, Some(stop))
            }
            Err(source) => {
                return Err(PlanError::Run {
                    what: what.to_owned(),
                    source,
                })
            }
        };
        Ok(Achieved {
            end_stop,
            u_m: rec.u,
            v_m_s: rec.v,
            a_m_s2: rec.a,
            output,
            min_supply_pressure: rec.min_supply,
            flow_peak: rec.flow,
            stuck_samples: rec.stuck,
        })
    }
}
