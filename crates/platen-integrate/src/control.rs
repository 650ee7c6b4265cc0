//! The one closed-loop driver: a command drives a controller sampled at `f_c`, whose drives
//! reach the valves `τ` later, around a plant of the mode machine ([`crate::machine`]); both
//! tables (the uniaxial platen of [`crate::forward_closed_loop`] and the multi-axis table of
//! [`crate::forward_table_loop`]) are loops of this driver ([`ControlLoop`]).
//!
//! # Time
//!
//! The controller runs at `f_c`; the integration grid divides its period into `k` steps,
//! `t = t₀ + n·h`, `h = 1/(k·f_c)`, from an integer counter. The drives are held between
//! controller samples and reach the valves `τ` later (the valves' pure delay), so the valves'
//! input is piecewise constant: a step is cut where it changes, and where an output sample
//! (the command's own time stamps) falls inside it. Between cuts the right-hand side is
//! smooth but for the friction events, which the machine locates. The plant keeps its time
//! in seconds ([`SecondsClock`]), which the driver moves from cut to cut.
//!
//! # Measured by the controller
//!
//! The controller reads the state at its samples exactly (the plant's accelerations are the
//! right-hand limit); the command is linear between its samples and held past its ends
//! ([`Command`]).

use std::collections::VecDeque;

use crate::clock::SecondsClock;
use crate::error::{IntegrateError, Result};
use crate::machine::{Machine, PieceMethod, Plant};
use crate::run::RunStats;
use crate::stop::StopReason;

/// The integrator of a closed-loop run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LoopMethod {
    /// Fixed-step RK4 with `steps_per_period` steps per controller period.
    Rk4 {
        /// Steps per controller period (`≥ 1`).
        steps_per_period: u32,
    },
    /// Adaptive Dormand–Prince 5(4) inside each piece (pieces as RK4's with
    /// `steps_per_period` per controller period).
    Dopri5 {
        /// Pieces per controller period (`≥ 1`).
        steps_per_period: u32,
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance, m (scaled to each state's own unit: see the module docs).
        atol: f64,
    },
}

impl LoopMethod {
    /// The integration steps per controller period.
    pub fn steps_per_period(&self) -> u32 {
        match *self {
            LoopMethod::Rk4 { steps_per_period }
            | LoopMethod::Dopri5 {
                steps_per_period, ..
            } => steps_per_period,
        }
    }

    /// The steps per controller period, checked: at least one, and Dopri5's tolerances
    /// positive and finite.
    ///
    /// # Errors
    /// [`IntegrateError::InvalidStep`] (its step 0 for no steps, NaN for the tolerances).
    pub(crate) fn checked_steps(&self) -> Result<u32> {
        let k = self.steps_per_period();
        if k == 0 {
            return Err(IntegrateError::InvalidStep { step_s: 0.0 });
        }
        if let LoopMethod::Dopri5 { rtol, atol, .. } = *self {
            if !(rtol > 0.0 && rtol.is_finite() && atol > 0.0 && atol.is_finite()) {
                return Err(IntegrateError::InvalidStep { step_s: f64::NAN });
            }
        }
        Ok(k)
    }

    /// The machine's pieces.
    pub(crate) fn pieces(&self) -> PieceMethod {
        match *self {
            LoopMethod::Rk4 { .. } => PieceMethod::Rk4,
            LoopMethod::Dopri5 { rtol, atol, .. } => PieceMethod::Dopri5 { rtol, atol },
        }
    }
}

/// What a closed-loop run reports besides its samples, for either table.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoopStats {
    /// The solver's counters (`run.steps`: the integration grid's steps) and, for the
    /// uniaxial platen, its energy balance (zero for the multi-axis table, whose energies are
    /// columns of its run).
    pub run: RunStats,
    /// Time with a drive saturated (`|d| = 1`), s.
    pub saturated_time_s: f64,
    /// First time a chamber pressure reached the cavitation floor (0 Pa absolute), s.
    pub cavitation_at_s: Option<f64>,
    /// Lowest supply pressure, Pa.
    pub min_supply_pressure_pa: f64,
    /// Hydraulic energy delivered into the chambers, J.
    pub hydraulic_energy_j: f64,
    /// Energy lost to leakage, J.
    pub leakage_energy_j: f64,
    /// Controller samples taken.
    pub controller_samples: u64,
    /// The largest warping force (norm of the null-space part of the actuator forces) at
    /// the controller's samples, N (a multi-axis table with redundant actuators; 0 for the
    /// uniaxial platen).
    pub max_warping_force_n: f64,
}

/// A command record: time stamps and a value (displacement or pose, with rates and
/// accelerations) at each.
pub(crate) trait Command {
    /// The command at an instant.
    type Value;
    /// The time stamps, s.
    fn t_s(&self) -> &[f64];
    /// The value at sample `i`.
    fn value(&self, i: usize) -> Self::Value;
    /// `a + w·(b − a)`, channel by channel.
    fn lerp(a: &Self::Value, b: &Self::Value, w: f64) -> Self::Value;

    /// The command at `t` (linear between samples, held past the ends).
    fn at(&self, t: f64) -> Self::Value {
        let ts = self.t_s();
        let last = ts.len() - 1;
        if t <= ts[0] {
            return self.value(0);
        }
        if t >= ts[last] {
            return self.value(last);
        }
        let j = ts.partition_point(|&x| x <= t).clamp(1, last);
        let w = (t - ts[j - 1]) / (ts[j] - ts[j - 1]);
        Self::lerp(&self.value(j - 1), &self.value(j), w)
    }
}

/// A table in closed loop: the controller and the valves' delay line around a plant of the
/// mode machine whose time is kept in seconds. What differs between the tables; the driver
/// ([`Driver`]) is the rest.
pub(crate) trait ControlLoop<const L: usize> {
    /// The plant: platen (and specimen) with the actuators' hydraulics.
    type Plant: Plant<L, Clock = SecondsClock>;
    /// The command record.
    type Command: Command;
    /// The controller's output, held until it reaches the valves.
    type Drive: Copy;

    /// The command.
    fn command(&self) -> &Self::Command;
    /// The valves' pure delay, s.
    fn delay_s(&self) -> f64;
    /// A controller sample at the machine's current state under `command`: the new drive.
    fn control(
        &mut self,
        m: &Machine<Self::Plant, L>,
        command: &<Self::Command as Command>::Value,
    ) -> Self::Drive;
    /// Whether the controller's drive is saturated.
    fn saturated(&self) -> bool;
    /// A delayed drive reaches the valves at `t_s`.
    fn arrive(plant: &mut Self::Plant, t_s: f64, drive: Self::Drive);
    /// At the start of a grid step, before its cuts (the multi-axis table's slide gauge
    /// aimed along its motion). Nothing by default.
    fn start_step(&self, _m: &mut Machine<Self::Plant, L>) {}
    /// Integrates a segment of `span` seconds with no cut inside, handling every event.
    fn segment(&self, m: &mut Machine<Self::Plant, L>, span: f64) -> Result<()> {
        m.advance_clocked(span)
    }
    /// At the end of a grid step at `t_s`: a state the table cannot take ends the run there.
    fn end_step(&self, _m: &Machine<Self::Plant, L>, _t_s: f64) -> Result<()> {
        Ok(())
    }
    /// Closes the statistics of the plant's own (energy, hydraulics) at the end of the run.
    fn finish(&self, m: &Machine<Self::Plant, L>, stats: &mut LoopStats);
}

/// A closed loop that delivers its output samples to a sink of type `S`.
pub(crate) trait Emit<S, const L: usize>: ControlLoop<L> {
    /// Delivers output sample `j` (the command's time stamp `j`) at the current state.
    fn emit(&mut self, m: &Machine<Self::Plant, L>, j: usize, sink: &mut S);
}

/// A closed-loop run: the mode machine between the controller's samples.
pub(crate) struct Driver<C: ControlLoop<L>, const L: usize> {
    /// The plant in its friction mode.
    pub(crate) machine: Machine<C::Plant, L>,
    /// The controller and the output.
    pub(crate) control: C,
    /// Drives on their way through the valves' delay: (time they arrive, drive).
    queue: VecDeque<(f64, C::Drive)>,
    /// Time with the drive saturated, s.
    saturated_time_s: f64,
    /// Controller samples taken.
    controller_samples: u64,
    /// The grid's step, s.
    h: f64,
    /// The command's first time, s.
    t0: f64,
    /// Integration steps per controller period.
    k: u64,
    /// Output samples to deliver.
    samples: usize,
    /// The next grid step.
    n: u64,
    /// The next output sample.
    j: usize,
}

impl<C: ControlLoop<L>, const L: usize> Driver<C, L> {
    /// The loop `control` around `machine` (its clock at the command's first time), `k` steps
    /// of `h` per controller period of `f_c` Hz, to deliver `samples`.
    pub(crate) fn new(
        machine: Machine<C::Plant, L>,
        control: C,
        (k, h, f_c): (u32, f64, f64),
        samples: usize,
    ) -> Self {
        let slots = (control.delay_s() * f_c).ceil() as usize + 2;
        let t0 = control.command().t_s()[0];
        Driver {
            machine,
            control,
            queue: VecDeque::with_capacity(slots),
            saturated_time_s: 0.0,
            controller_samples: 0,
            h,
            t0,
            k: u64::from(k),
            samples,
            n: 0,
            j: 0,
        }
    }

    /// The current time, s.
    fn t(&self) -> f64 {
        self.machine.plant.clock().t
    }

    /// Moves the clock to `t`, s.
    fn set_t(&mut self, t: f64) {
        self.machine.plant.clock_mut().t = t;
    }

    /// A controller sample at the current time: the new drive enters the valves' delay line.
    fn tick(&mut self) {
        let command = self.control.command().at(self.t());
        let d = self.control.control(&self.machine, &command);
        self.controller_samples += 1;
        let delay = self.control.delay_s();
        self.queue.push_back((self.t() + delay, d));
    }

    /// Applies every delayed drive that has arrived by the current time (to `slack`).
    fn apply_arrived(&mut self, slack: f64) {
        let mut changed = false;
        while let Some(&(t, d)) = self.queue.front() {
            if t <= self.t() + slack {
                let now = self.t();
                C::arrive(&mut self.machine.plant, now, d);
                self.queue.pop_front();
                changed = true;
            } else {
                break;
            }
        }
        if changed {
            let mode = self.machine.mode;
            let input = self.machine.plant.input(0.0);
            self.machine.enter(mode, input);
        }
    }

    /// Integrates `span` seconds with no cut inside, if any.
    fn segment(&mut self, span: f64) -> Result<()> {
        if span > 0.0 {
            self.control.segment(&mut self.machine, span)?;
        }
        Ok(())
    }

    /// Runs the grid: controller samples every `k` steps, each step cut where the valves'
    /// input changes or an output sample falls.
    pub(crate) fn run<S>(&mut self, sink: &mut S) -> Result<()>
    where
        C: Emit<S, L>,
    {
        while !self.grid_step(sink)? {}
        Ok(())
    }

    /// Delivers every output sample due by the current time (to `slack`).
    fn emit_due<S>(&mut self, slack: f64, sink: &mut S)
    where
        C: Emit<S, L>,
    {
        while self.j < self.samples && self.control.command().t_s()[self.j] <= self.t() + slack {
            self.control.emit(&self.machine, self.j, sink);
            self.j += 1;
        }
    }

    /// One grid step from `t₀ + n·h`: the controller's sample when one falls there, the
    /// output samples that fall in it, the cuts inside it. Returns whether the run is over
    /// (every output sample delivered), having delivered the last ones.
    pub(crate) fn grid_step<S>(&mut self, sink: &mut S) -> Result<bool>
    where
        C: Emit<S, L>,
    {
        let samples = self.samples;
        let t_end = self.control.command().t_s()[samples - 1];
        let slack = 1e-9 * self.h;
        let n = self.n;
        // At the grid point t₀ + n·h.
        self.set_t(self.t0 + n as f64 * self.h);
        if n % self.k == 0 {
            self.tick();
        }
        self.apply_arrived(slack);
        self.emit_due(slack, sink);
        if self.j >= samples || self.t() > t_end + slack {
            self.machine.stats.stop = StopReason::Finished { t_s: t_end };
            return Ok(true);
        }
        self.control.start_step(&mut self.machine);
        let t_next = self.t0 + (n + 1) as f64 * self.h;
        // Cuts inside (t, t_next): arrivals of delayed drives and output samples.
        loop {
            let arrival = self.queue.front().map_or(f64::INFINITY, |&(t, _)| t);
            let sample = if self.j < samples {
                self.control.command().t_s()[self.j]
            } else {
                f64::INFINITY
            };
            let cut = arrival.min(sample);
            if cut >= t_next - slack {
                break;
            }
            self.segment(cut - self.t())?;
            self.set_t(cut);
            self.apply_arrived(slack);
            self.emit_due(slack, sink);
        }
        self.segment(t_next - self.t())?;
        self.control.end_step(&self.machine, t_next)?;
        if self.control.saturated() {
            self.saturated_time_s += self.h;
        }
        self.n += 1;
        self.machine.stats.steps += 1;
        Ok(false)
    }

    /// The run's statistics.
    pub(crate) fn finish(&self) -> LoopStats {
        let m = &self.machine;
        let mut run = m.stats;
        if m.is_rk4() {
            run.accepted_steps = run.steps;
        }
        let mut stats = LoopStats {
            run,
            saturated_time_s: self.saturated_time_s,
            controller_samples: self.controller_samples,
            ..LoopStats::default()
        };
        self.control.finish(m, &mut stats);
        stats
    }
}
