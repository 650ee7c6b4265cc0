//! The multi-axis table in closed loop: a six-DOF command drives the DOF controller
//! ([`DofController`]), whose actuator drives pass each actuator's servo-valves into its
//! chambers ([`TableHydraulics`]), whose forces move the platen (and its specimen) with the
//! bearings' exact planar stick-slip: the plant of [`crate::forward_table`] with the
//! actuator forces taken from the state instead of a record.
//!
//! # Time
//!
//! As the uniaxial loop ([`crate::forward_closed_loop`]): the controller samples at `f_c`,
//! the grid divides its period into `k` steps (`t = t₀ + n·h` from an integer counter), the
//! drives are held between samples and reach the valves `τ` later (the valves' common pure
//! delay), and a step is cut where the valves' input changes or an output sample (the
//! command's own time stamps) falls. The controller reads the state exactly at its samples:
//! strokes and their rates (exact kinematics), the platen's accelerations (the right-hand
//! limit), each actuator's `Δp` and force; the command's pose, rates and accelerations are
//! linear between its samples and held past its ends.
//!
//! # State
//!
//! After the platen's (and the specimen's) states, per actuator `p_a`, `p_b`, spool and
//! spool rate (for at most [`MAX_LOOP_ACTUATORS`] actuators), then the accumulator's oil,
//! the supply pressure, and the hydraulic and leakage energies. The spools are not stepped:
//! between drive changes each follows its valve's exact response to the held drive
//! ([`platen_system::SpoolResponse`], anchored at the last change), the integrator's stages
//! read their openings from it, and each accepted state has them written in. The step then
//! needs to resolve the oil columns and the spool's transient in the flows, not the spool's
//! own stepping. The hydraulics start at rest
//! in their null state for the forces that hold the platen (and the specimen's weight) at
//! neutral, resolved as the force balance does: a platen commanded to stay at neutral stays.

use platen_model::multi_axis::{Coords, Dof, LinearSpecimen, MultiAxisTable};
use platen_system::{
    ActuatorState, DofCommand, DofController, DofControllerState, DofFeedback, SpoolResponse,
    Supply, TableHydraulics,
};

use crate::clock::SecondsClock;
use crate::control::{Command, ControlLoop, Driver, Emit, LoopMethod, LoopStats};
use crate::error::{IntegrateError, Result};
use crate::machine::{Machine, Plant, Y};
use crate::multi_axis::{PoseMotion, TableRun};
use crate::output::TableSink;
use crate::stop::Failure;
use crate::table_forward::Rows;
pub use crate::table_plant::SPENT_GAS_FRACTION;
use crate::table_plant::{
    pose, reaim, start_machine, start_state, Forces, Source, Strokes, TablePlant, BARE,
    MAX_TABLE_ACTUATORS, QD, WITH_SPECIMEN,
};
use crate::table_plant::{spent_strut, table_step_error};
use crate::MAX_TABLE_SPECIMEN_DOFS;

/// The most actuators a closed-loop table run takes (their hydraulic states live in the
/// integrator's fixed-size state).
pub const MAX_LOOP_ACTUATORS: usize = 16;
/// The hydraulics' share of the state: four per actuator, then oil, supply pressure and the
/// two energy integrals.
const TAIL: usize = 4 * MAX_LOOP_ACTUATORS + 4;
/// The state's length of a bare table in closed loop.
const LOOP_BARE: usize = BARE + TAIL;
/// The state's length with a specimen.
const LOOP_WITH_SPECIMEN: usize = WITH_SPECIMEN + TAIL;

/// Where the hydraulics start in a state of length `L`.
const fn hy<const L: usize>() -> usize {
    L - TAIL
}
/// The accumulator's oil.
const fn oil<const L: usize>() -> usize {
    L - 4
}
/// The supply pressure.
const fn ps<const L: usize>() -> usize {
    L - 3
}
/// The hydraulic energy delivered into the chambers.
const fn eh<const L: usize>() -> usize {
    L - 2
}
/// The energy lost to leakage.
const fn el<const L: usize>() -> usize {
    L - 1
}

/// A closed-loop run of a multi-axis table.
#[derive(Debug, Clone, Copy)]
pub struct TableLoopRun<'a> {
    /// The table.
    pub table: &'a MultiAxisTable,
    /// Its actuators' hydraulics and supply.
    pub hydraulics: &'a TableHydraulics,
    /// Its DOF controller.
    pub controller: &'a DofController,
    /// The specimen on the platen, if any.
    pub specimen: Option<&'a LinearSpecimen>,
    /// The six-DOF command (pose, rates, accelerations).
    pub command: &'a PoseMotion,
    /// The integrator: RK4 or Dopri5 pieces, `steps_per_period` per controller period.
    pub method: LoopMethod,
}

/// What a closed-loop table run reports besides its columns: the one closed loop's
/// statistics ([`LoopStats`]; `run.steps` the integration grid's steps).
pub type TableLoopStats = LoopStats;

/// The actuators' hydraulics in the state: the source of the closed loop's forces.
pub(crate) struct Hydraulic<'a> {
    hyd: &'a TableHydraulics,
    /// The valves' inputs (the delayed, held drives).
    drives: [f64; MAX_LOOP_ACTUATORS],
    /// The spools' exact motion under the held drives (see [`Spools`]).
    spools: Spools,
    /// Seconds from the start of the current advance.
    clock: SecondsClock,
    cavitation_at_s: Option<f64>,
    min_supply_pressure_pa: f64,
}

impl Hydraulic<'_> {
    /// The spools' positions and rates at time `t_s` (≥ the anchor) under the held drives.
    fn spools_at(&self, t_s: f64) -> (SpoolPositions, SpoolPositions) {
        self.spools.at(t_s, &self.drives, self.count())
    }

    /// New drives arrive at `t_s`: the spools' motion is re-anchored there.
    fn drive(&mut self, t_s: f64, drives: [f64; MAX_LOOP_ACTUATORS]) {
        let (x, v) = self.spools_at(t_s);
        self.spools.anchor(t_s, x, v);
        self.drives = drives;
    }

    fn state<const L: usize>(y: &Y<L>, i: usize) -> ActuatorState {
        let k = hy::<L>() + 4 * i;
        ActuatorState {
            p_a_pa: y[k],
            p_b_pa: y[k + 1],
            spool: y[k + 2],
            spool_rate_1_s: y[k + 3],
        }
    }

    fn count(&self) -> usize {
        self.hyd.actuators().len()
    }
}

impl<const L: usize> Source<L> for Hydraulic<'_> {
    /// The spools' positions: exact, from [`Spools`], not stepped.
    type Input = SpoolPositions;
    const RATES_ON_COMMIT: bool = true;
    const NEEDS_STROKES: bool = true;

    #[inline(always)]
    fn input(&self, at: f64) -> SpoolPositions {
        self.spools_at(self.clock.t + at).0
    }

    fn forces(&self, _input: SpoolPositions, y: &Y<L>) -> Forces {
        let mut out = [0.0; MAX_TABLE_ACTUATORS];
        for (i, o) in out.iter_mut().enumerate().take(self.count()) {
            *o = self.hyd.force_n(i, &Self::state(y, i));
        }
        out
    }

    /// The spools' states are not stepped (their rates are 0 here): the input carries
    /// their exact positions, and [`Source::admit`] writes them into the state.
    fn rates(&self, spools: SpoolPositions, y: &Y<L>, strokes: &Strokes, dy: &mut Y<L>) {
        let p_s = y[ps::<L>()];
        let (mut drawn, mut power, mut leak) = (0.0, 0.0, 0.0);
        for (i, &spool) in spools.iter().enumerate().take(self.count()) {
            let (s, v) = (strokes.stroke_m[i], strokes.rate_m_s[i]);
            let state = ActuatorState {
                spool,
                ..Self::state(y, i)
            };
            let r = self
                .hyd
                .actuator_rates(i, s, v, self.drives[i], &state, p_s);
            let k = hy::<L>() + 4 * i;
            dy[k] = r.p_a;
            dy[k + 1] = r.p_b;
            dy[k + 2] = 0.0;
            dy[k + 3] = 0.0;
            drawn += r.drawn_m3_s;
            power += r.power_w;
            leak += r.leakage_w;
        }
        let (d_oil, d_ps) = self.hyd.supply_rates(drawn, y[oil::<L>()], p_s);
        dy[oil::<L>()] = d_oil;
        dy[ps::<L>()] = d_ps;
        dy[eh::<L>()] = power;
        dy[el::<L>()] = leak;
    }

    /// Every chamber's and the accumulator's ([`TableHydraulics::pressure_rate_1_s`],
    /// [`TableHydraulics::supply_rate_1_s`]) at the spools' openings in the state.
    fn stiff_rate(&self, y: &Y<L>, strokes: Option<&Strokes>) -> f64 {
        let p_s = y[ps::<L>()];
        let (mut rate, mut drawn, mut g_supply) = (0.0_f64, 0.0, 0.0);
        for i in 0..self.count() {
            let s_m = strokes.map(|s| s.stroke_m[i]);
            let r = self.hyd.pressure_rate_1_s(i, s_m, &Self::state(y, i), p_s);
            rate = rate.max(r.rate_1_s);
            drawn += r.drawn_m3_s;
            g_supply += r.supply_conductance_m3_s_pa;
        }
        let bank = self
            .hyd
            .supply_rate_1_s(drawn, g_supply, y[oil::<L>()], p_s);
        rate.max(bank)
    }

    /// Pressures are held at the cavitation floor (0 Pa absolute); the lowest supply
    /// pressure is kept; the spools' exact states at `t_s` are written in.
    fn admit(&mut self, y: &mut Y<L>, t_s: f64) -> bool {
        let mut floored = false;
        let (x, v) = self.spools_at(t_s);
        for i in 0..self.count() {
            let k = hy::<L>() + 4 * i;
            (y[k + 2], y[k + 3]) = (x[i], v[i]);
            for j in [k, k + 1] {
                if y[j] < 0.0 {
                    y[j] = 0.0;
                    floored = true;
                }
            }
        }
        if floored {
            self.cavitation_at_s.get_or_insert(t_s);
        }
        self.min_supply_pressure_pa = self.min_supply_pressure_pa.min(y[ps::<L>()]);
        floored
    }

    /// The supply pressure for the pressures, full opening for the spools, the bank's volume
    /// for its oil (as the uniaxial loop); the energy integrals are not controlled.
    fn error_scale(&self, i: usize, y0: f64, y1: f64, rtol: f64, atol: f64) -> Option<f64> {
        let start = hy::<L>();
        if i < start {
            return None;
        }
        let m = y0.abs().max(y1.abs());
        let p = self.hyd.supply_pressure_pa() * 1e3;
        let unit = if i >= eh::<L>() {
            return Some(f64::INFINITY);
        } else if i == oil::<L>() {
            match self.hyd.supply() {
                Supply::Accumulator(acc) => acc.volume_m3,
                Supply::Constant => 1.0,
            }
        } else if i == ps::<L>() {
            p
        } else {
            let a = (i - start) / 4;
            match (i - start) % 4 {
                0 | 1 => p,
                2 => 1e3,
                _ => {
                    let valve = self.hyd.actuators().get(a).map(|x| x.servo_valve);
                    1e3 * std::f64::consts::TAU * valve.map_or(1.0, |v| v.natural_frequency_hz)
                }
            }
        };
        Some(atol * unit + rtol * m)
    }

    crate::clock::clock_field!(SecondsClock);
}

/// One number per actuator (the first `n`), on the stack.
type PerActuator = [f64; MAX_LOOP_ACTUATORS];

/// The spools' positions (fractions of full opening), per actuator.
pub(crate) type SpoolPositions = [f64; MAX_LOOP_ACTUATORS];

/// The spools' motion in closed form: each spool's position and rate at the last change of
/// the drives (the anchor), carried to any later time by its valve's exact response to the
/// held drive ([`SpoolResponse`]). The spool is linear between drive changes, so the
/// integrator does not step it, and its rate does not limit the step.
pub(crate) struct Spools {
    /// Per actuator, its valve's response.
    responses: [SpoolResponse; MAX_LOOP_ACTUATORS],
    /// Whether actuator `i`'s valve is the same model as `i − 1`'s (their weights shared).
    same_as_previous: [bool; MAX_LOOP_ACTUATORS],
    /// The anchor's time, s.
    anchor_s: f64,
    /// The positions at the anchor.
    x0: SpoolPositions,
    /// The rates at the anchor, 1/s.
    v0: SpoolPositions,
}

impl Spools {
    /// Every spool at rest at neutral at `t0_s`.
    fn new(hyd: &TableHydraulics, t0_s: f64) -> Self {
        let mut responses = [SpoolResponse::new(1.0, 1.0); MAX_LOOP_ACTUATORS];
        let mut same_as_previous = [false; MAX_LOOP_ACTUATORS];
        for i in 0..hyd.actuators().len() {
            responses[i] = hyd.spool_response(i);
            same_as_previous[i] = i > 0 && responses[i] == responses[i - 1];
        }
        Spools {
            responses,
            same_as_previous,
            anchor_s: t0_s,
            x0: [0.0; MAX_LOOP_ACTUATORS],
            v0: [0.0; MAX_LOOP_ACTUATORS],
        }
    }

    /// The first `n` spools' positions and rates at `t_s` under `drives`.
    #[inline(always)]
    fn at(
        &self,
        t_s: f64,
        drives: &[f64; MAX_LOOP_ACTUATORS],
        n: usize,
    ) -> (SpoolPositions, SpoolPositions) {
        let dt = (t_s - self.anchor_s).max(0.0);
        let (mut x, mut v) = ([0.0; MAX_LOOP_ACTUATORS], [0.0; MAX_LOOP_ACTUATORS]);
        let mut w = self.responses[0].weights(dt);
        for i in 0..n {
            if !self.same_as_previous[i] && i > 0 {
                w = self.responses[i].weights(dt);
            }
            (x[i], v[i]) = self.responses[i].at(w, drives[i], self.x0[i], self.v0[i]);
        }
        (x, v)
    }

    /// Re-anchors at `t_s` with positions `x` and rates `v`.
    fn anchor(&mut self, t_s: f64, x: SpoolPositions, v: SpoolPositions) {
        (self.anchor_s, self.x0, self.v0) = (t_s, x, v);
    }
}

/// The loop's own output columns per actuator (after the common ones).
const ACTUATOR_COLUMNS: [&str; 4] = ["drive", "spool_opening", "delta_p_pa", "flow_m3_s"];

/// Runs the closed loop `run`: the command drives the DOF controller, whose drives move the
/// valves, chambers and platen. Returns a row at each of the command's time stamps (the
/// columns of [`forward_table_loop_into`]) with the run's statistics.
///
/// # Errors
/// As [`forward_table_loop_into`].
pub fn forward_table_loop(run: &TableLoopRun<'_>) -> Result<(TableRun, TableLoopStats)> {
    let mut out = TableRun::default();
    let stats = forward_table_loop_into(run, &mut out)?;
    Ok((out, stats))
}

/// Runs the closed loop `run`: the command drives the DOF controller, whose drives move the
/// valves, chambers and platen. Delivers a row to `sink` at each of the command's time
/// stamps: the columns of [`crate::forward_table`] (with `{name}_force_n` the chambers'
/// force), then `command_x_m` … `command_yaw_rad`, per actuator `{name}_drive`,
/// `{name}_spool_opening`, `{name}_delta_p_pa` (`p_a − p_b`; `p_a − P_R` single-acting) and
/// `{name}_flow_m3_s` (into chamber `a`), then `supply_pressure_pa`, `warping_force_n` (the
/// null-space part of the actuator forces, the force balance's error, at the last controller
/// sample) and `hydraulic_energy_j`. The columns' names reach the sink first
/// ([`TableSink::start`]), unless the command is empty.
///
/// # Errors
/// [`IntegrateError::InvalidStep`] for zero steps per period or tolerances that are not
/// positive; [`IntegrateError::LengthMismatch`] when the hydraulics or the controller do not
/// have one entry per actuator, or the table more than [`MAX_LOOP_ACTUATORS`]; the static
/// forces outside what the chambers can exert ([`IntegrateError::InvalidSystem`]);
/// [`IntegrateError::UnequalValveDelays`]; a numerical failure (non-finite state) or an
/// actuator at its end stop with its time (the rows before it delivered).
pub fn forward_table_loop_into<K: TableSink>(
    run: &TableLoopRun<'_>,
    sink: &mut K,
) -> Result<TableLoopStats> {
    let k = check_table_loop(run)?;
    if run.command.is_empty() {
        return Ok(TableLoopStats::default());
    }
    match run.specimen {
        None => run_table_loop::<LOOP_BARE, K>(run, k, sink),
        Some(s) if s.len() <= MAX_TABLE_SPECIMEN_DOFS => {
            run_table_loop::<LOOP_WITH_SPECIMEN, K>(run, k, sink)
        }
        Some(s) => Err(IntegrateError::LengthMismatch {
            what: "specimen DOFs of a closed-loop table run (at most MAX_TABLE_SPECIMEN_DOFS)",
            found: s.len(),
            expected: MAX_TABLE_SPECIMEN_DOFS,
        }),
    }
}

/// The checks of a closed-loop table run before it starts: one hydraulics and one controller
/// row per actuator, at most [`MAX_LOOP_ACTUATORS`], one valve delay; its steps per period.
fn check_table_loop(run: &TableLoopRun<'_>) -> Result<u32> {
    let n = run.table.actuators().len();
    for (what, found) in [
        ("actuator hydraulics", run.hydraulics.actuators().len()),
        (
            "controller geometry rows",
            run.controller.geometry().actuators(),
        ),
    ] {
        if found != n {
            return Err(IntegrateError::LengthMismatch {
                what,
                found,
                expected: n,
            });
        }
    }
    if n > MAX_LOOP_ACTUATORS {
        return Err(IntegrateError::LengthMismatch {
            what: "actuators of a closed-loop table run (at most MAX_LOOP_ACTUATORS)",
            found: n,
            expected: MAX_LOOP_ACTUATORS,
        });
    }
    let delays: Vec<f64> = run
        .hydraulics
        .actuators()
        .iter()
        .map(|a| a.servo_valve.delay_s)
        .collect();
    if delays.iter().any(|&d| d != delays[0]) {
        return Err(IntegrateError::UnequalValveDelays);
    }
    run.method.checked_steps()
}

/// [`forward_table_loop_into`] with a state of `L` numbers.
fn run_table_loop<const L: usize, K: TableSink>(
    run: &TableLoopRun<'_>,
    k: u32,
    sink: &mut K,
) -> Result<TableLoopStats> {
    let h = run.controller.period_s() / f64::from(k);
    let machine = table_machine::<L>(run, h)?;
    let control = TableLoop::new(run);
    control.rows.start(sink, run.command.len());
    let f_c = run.controller.sample_rate_hz();
    let mut driver = Driver::new(machine, control, (k, h, f_c), run.command.len());
    driver.run(sink)?;
    Ok(driver.finish())
}

/// The machine of the closed loop `run` at rest at neutral, the hydraulics in their null
/// state for the forces that hold the platen (and the specimen's weight) there, on a grid of
/// step `h`.
fn table_machine<'a, const L: usize>(
    run: &TableLoopRun<'a>,
    h: f64,
) -> Result<Machine<TablePlant<'a, Hydraulic<'a>, L>, L>> {
    let (table, hyd) = (run.table, run.hydraulics);
    // The weight of the specimen on the platen, carried at rest with the platen's.
    let extra = run.specimen.map_or_else(
        platen_model::multi_axis::Wrench::zeros,
        LinearSpecimen::weight_wrench,
    );
    let rest = TableHydraulics::static_forces_n(table, &extra)
        .and_then(|f| hyd.rest_states(&f))
        .map_err(IntegrateError::InvalidSystem)?;
    let mut y = start_state::<L>(table, run.specimen, Coords::zeros(), Coords::zeros());
    for (i, s) in rest.iter().enumerate() {
        let at = hy::<L>() + 4 * i;
        y[at] = s.p_a_pa;
        y[at + 1] = s.p_b_pa;
    }
    y[oil::<L>()] = hyd.charged_oil_m3();
    y[ps::<L>()] = hyd.supply_pressure_at(y[oil::<L>()]);
    let t0 = run.command.t_s()[0];
    let source = Hydraulic {
        hyd,
        drives: [0.0; MAX_LOOP_ACTUATORS],
        spools: Spools::new(hyd, t0),
        clock: SecondsClock { t: t0, h },
        cavitation_at_s: None,
        min_supply_pressure_pa: y[ps::<L>()],
    };
    Ok(start_machine(
        table,
        run.specimen,
        source,
        y,
        h,
        run.method.pieces(),
    ))
}

impl Command for PoseMotion {
    type Value = DofCommand;

    fn t_s(&self) -> &[f64] {
        PoseMotion::t_s(self)
    }

    fn value(&self, i: usize) -> DofCommand {
        let (pose, rates, accelerations) = self.at(i);
        DofCommand {
            pose,
            rates,
            accelerations,
        }
    }

    fn lerp(a: &DofCommand, b: &DofCommand, w: f64) -> DofCommand {
        DofCommand {
            pose: a.pose + (b.pose - a.pose) * w,
            rates: a.rates + (b.rates - a.rates) * w,
            accelerations: a.accelerations + (b.accelerations - a.accelerations) * w,
        }
    }
}

/// The columns of a closed-loop run ([`forward_table_loop_into`]) of `table` carrying
/// `specimen`, in their order: what [`TableSink::start`] receives, known before the run so
/// that its output can be created first.
pub fn table_loop_columns(
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
) -> Vec<String> {
    let mut names = crate::table_columns(table, specimen);
    names.extend(loop_columns(table));
    names
}

/// The closed loop's own columns, after those of [`crate::table_columns`].
fn loop_columns(table: &MultiAxisTable) -> Vec<String> {
    let mut names: Vec<String> = Dof::ALL
        .iter()
        .map(|d| format!("command_{}_{}", d.name(), d.unit()))
        .collect();
    for a in table.actuators() {
        names.extend(ACTUATOR_COLUMNS.iter().map(|c| format!("{}_{c}", a.name)));
    }
    names.extend(
        [
            "supply_pressure_pa",
            "warping_force_n",
            "hydraulic_energy_j",
        ]
        .map(String::from),
    );
    names
}

/// The multi-axis table's DOF controller and output around its [`TablePlant`] driven by the
/// actuators' hydraulics.
struct TableLoop<'a> {
    run: TableLoopRun<'a>,
    state: DofControllerState,
    /// The columns' names and the row being delivered.
    rows: Rows,
    /// The loop's own columns of the row being emitted (kept to reuse its allocation).
    extra: Vec<f64>,
    /// The largest warping force at the controller's samples, N.
    max_warping_force_n: f64,
}

impl<'a> TableLoop<'a> {
    /// The controller and the columns of `run`.
    fn new(run: &TableLoopRun<'a>) -> Self {
        TableLoop {
            run: *run,
            state: run.controller.start(),
            rows: Rows::new(run.table, run.specimen, loop_columns(run.table)),
            extra: Vec::new(),
            max_warping_force_n: 0.0,
        }
    }

    /// What the controller reads now: strokes and their rates, Δp and forces per actuator
    /// (the first `n` of each, on the stack).
    fn feedback<const L: usize>(
        &self,
        m: &Machine<TablePlant<'a, Hydraulic<'a>, L>, L>,
    ) -> [PerActuator; 4] {
        let (table, hyd) = (self.run.table, self.run.hydraulics);
        let (q, qd) = pose(&m.y);
        let [mut strokes, mut rates, mut dp, mut forces] = [[0.0; MAX_LOOP_ACTUATORS]; 4];
        for i in 0..table.actuators().len() {
            let s = Hydraulic::state(&m.y, i);
            strokes[i] = table.actuator_at(i, &q).stroke_m;
            rates[i] = table.stroke_rate_m_s(i, &q, &qd);
            dp[i] = hyd.delta_p_pa(i, &s);
            forces[i] = hyd.force_n(i, &s);
        }
        [strokes, rates, dp, forces]
    }
}

impl<'a, const L: usize> ControlLoop<L> for TableLoop<'a> {
    type Plant = TablePlant<'a, Hydraulic<'a>, L>;
    type Command = PoseMotion;
    /// One drive per actuator.
    type Drive = [f64; MAX_LOOP_ACTUATORS];

    fn command(&self) -> &PoseMotion {
        self.run.command
    }

    fn delay_s(&self) -> f64 {
        self.run.hydraulics.actuators()[0].servo_valve.delay_s
    }

    /// The DOF controller on the strokes, their rates, the platen's accelerations, each
    /// actuator's `Δp` and force.
    fn control(
        &mut self,
        m: &Machine<Self::Plant, L>,
        command: &DofCommand,
    ) -> [f64; MAX_LOOP_ACTUATORS] {
        let [strokes, rates, dp, forces] = self.feedback(m);
        let n = self.run.table.actuators().len();
        let fb = DofFeedback {
            strokes_m: &strokes[..n],
            stroke_rates_m_s: &rates[..n],
            accelerations: Coords::from_fn(|k, _| m.k[QD + k]),
            delta_p_pa: &dp[..n],
            forces_n: &forces[..n],
        };
        self.run.controller.update(&mut self.state, command, &fb);
        self.max_warping_force_n = self.max_warping_force_n.max(self.state.warping_n);
        let mut d = [0.0; MAX_LOOP_ACTUATORS];
        d[..self.state.drives.len()].copy_from_slice(&self.state.drives);
        d
    }

    fn saturated(&self) -> bool {
        self.state.saturated
    }

    fn arrive(plant: &mut Self::Plant, t_s: f64, drives: [f64; MAX_LOOP_ACTUATORS]) {
        plant.source.drive(t_s, drives);
    }

    /// A slide with friction has its gauge aimed along its motion.
    fn start_step(&self, m: &mut Machine<Self::Plant, L>) {
        reaim(m);
    }

    /// A state that blew up while a strut was running out of gas is the strut's gas spent.
    fn segment(&self, m: &mut Machine<Self::Plant, L>, span: f64) -> Result<()> {
        let (q0, _) = pose(&m.y);
        let t0 = m.plant.clock().t;
        m.advance_clocked(span).map_err(|e| match e {
            // Reported at the segment's start, where the state was last finite.
            IntegrateError::NonFiniteState { u_m, v_m_s, .. } => table_step_error(
                IntegrateError::NonFiniteState {
                    t_s: t0,
                    u_m,
                    v_m_s,
                },
                self.run.table,
                &q0,
            ),
            e => e,
        })
    }

    /// An actuator pushed past its chambers' oil (a chamber's volume gone), or a strut past
    /// its gas, ends the run.
    fn end_step(&self, m: &Machine<Self::Plant, L>, t_s: f64) -> Result<()> {
        let (table, hyd) = (self.run.table, self.run.hydraulics);
        let (q, _) = pose(&m.y);
        if let Some(strut) = spent_strut(table, &q) {
            return Err(IntegrateError::StrutGasSpent { t_s, strut });
        }
        for (i, a) in hyd.actuators().iter().enumerate() {
            let s = table.actuator_at(i, &q).stroke_m;
            let (v_a, v_b) = a.chamber_volumes_m3(s);
            if v_a <= 0.0 || (!a.is_single_acting() && v_b <= 0.0) {
                return Err(IntegrateError::failed(t_s, Failure::EndStop { u_m: s }));
            }
        }
        if !m.y.iter().all(|x| x.is_finite()) {
            return Err(IntegrateError::failed(
                t_s,
                Failure::TableNonFiniteState {
                    pose: std::array::from_fn(|k| q[k]),
                },
            ));
        }
        Ok(())
    }

    /// The hydraulics' figures and the largest warping force.
    fn finish(&self, m: &Machine<Self::Plant, L>, stats: &mut LoopStats) {
        let (y, src) = (&m.y, &m.plant.source);
        stats.cavitation_at_s = src.cavitation_at_s;
        stats.min_supply_pressure_pa = src.min_supply_pressure_pa;
        stats.hydraulic_energy_j = y[eh::<L>()];
        stats.leakage_energy_j = y[el::<L>()];
        stats.max_warping_force_n = self.max_warping_force_n;
    }
}

impl<'a, K: TableSink, const L: usize> Emit<K, L> for TableLoop<'a> {
    /// The row of output sample `j`: the table's columns, then the loop's own.
    fn emit(&mut self, m: &Machine<Self::Plant, L>, j: usize, sink: &mut K) {
        let (table, hyd) = (self.run.table, self.run.hydraulics);
        let y = &m.y;
        let t_s = self.run.command.t_s()[j];
        let n = table.actuators().len();
        let (pose_j, _, _) = self.run.command.at(j);
        let extra = &mut self.extra;
        extra.clear();
        extra.extend(pose_j.iter().copied());
        let mut forces = [0.0; MAX_LOOP_ACTUATORS];
        let p_s = y[ps::<L>()];
        for (i, f) in forces.iter_mut().enumerate().take(n) {
            let s = Hydraulic::state(y, i);
            *f = hyd.force_n(i, &s);
            let (q_a, _) =
                hyd.valve_flows_m3_s(i, s.spool, s.p_a_pa.max(0.0), s.p_b_pa.max(0.0), p_s);
            extra.extend([
                self.state.drives[i],
                s.spool.clamp(-1.0, 1.0),
                hyd.delta_p_pa(i, &s),
                q_a,
            ]);
        }
        extra.extend([p_s, self.state.warping_n, y[eh::<L>()]]);
        self.rows.push(m, t_s, &forces[..n], &self.extra, sink);
    }
}
