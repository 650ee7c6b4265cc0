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

use std::collections::VecDeque;

use platen_model::multi_axis::{Coords, Dof, LinearSpecimen, MultiAxisTable};
use platen_system::{
    ActuatorState, DofCommand, DofController, DofControllerState, DofFeedback, SpoolResponse,
    Supply, TableHydraulics,
};

use crate::closed_loop::LoopMethod;
use crate::error::{IntegrateError, Result};
use crate::machine::{Machine, PieceMethod, Y};
use crate::multi_axis::{PoseMotion, TableRun};
use crate::stop::Failure;
use crate::table_plant::{
    pose, reaim, start_machine, start_state, Forces, Output, Source, Strokes, TablePlant, BARE,
    MAX_TABLE_ACTUATORS, QD, WITH_SPECIMEN,
};
use crate::MAX_TABLE_SPECIMEN_DOFS;

/// A strut whose gas volume falls below this fraction of its volume at neutral has used up
/// its gas: its pressure is then `100^n` times the neutral one (7 600 times for `n` = 1.44),
/// beyond any strut's rating, and grows without bound as the volume goes.
pub const SPENT_GAS_FRACTION: f64 = 0.01;

/// A run whose state became non-finite while a strut had less than this fraction of its gas
/// left (at the last finite state) is reported as that strut's gas spent: a strut at a
/// quarter of its gas stiffens seven-fold within the step (n = 1.44) and its pull is what the
/// step could not follow.
const BLOWN_UP_GAS_FRACTION: f64 = 0.25;

/// The first strut of `table` at pose `q` with less than [`SPENT_GAS_FRACTION`] of its gas
/// volume left, if any.
fn spent_strut(table: &MultiAxisTable, q: &Coords) -> Option<usize> {
    spent_strut_below(table, q, SPENT_GAS_FRACTION)
}

/// The first strut of `table` at pose `q` with less than `fraction` of its gas volume left.
fn spent_strut_below(table: &MultiAxisTable, q: &Coords, fraction: f64) -> Option<usize> {
    table.struts().iter().enumerate().position(|(j, s)| {
        let p = table.strut_at(j, q).pressure_pa;
        // V = V₀·(p₀/p)^(1/n); an infinite pressure is a volume gone.
        let left = (s.pressure_pa / p).powf(1.0 / s.polytropic_exponent);
        left.is_nan() || left <= fraction
    })
}

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

/// What a closed-loop table run reports besides its columns.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TableLoopStats {
    /// Time with a drive saturated, s.
    pub saturated_time_s: f64,
    /// First time a chamber pressure reached the cavitation floor (0 Pa absolute), s.
    pub cavitation_at_s: Option<f64>,
    /// Lowest supply pressure, Pa.
    pub min_supply_pressure_pa: f64,
    /// Hydraulic energy delivered into the chambers, J.
    pub hydraulic_energy_j: f64,
    /// Energy lost to leakage, J.
    pub leakage_energy_j: f64,
    /// The largest warping force (norm of the null-space part of the actuator forces) at
    /// the controller's samples, N.
    pub max_warping_force_n: f64,
    /// Controller samples taken.
    pub controller_samples: u64,
    /// Integration grid steps.
    pub steps: u64,
}

/// The actuators' hydraulics in the state: the source of the closed loop's forces.
pub(crate) struct Hydraulic<'a> {
    hyd: &'a TableHydraulics,
    /// The valves' inputs (the delayed, held drives).
    drives: [f64; MAX_LOOP_ACTUATORS],
    /// The spools' exact motion under the held drives (see [`Spools`]).
    spools: Spools,
    /// Time at the start of the current advance, s.
    t: f64,
    /// The grid's step, s.
    h: f64,
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
        self.spools_at(self.t + at).0
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

    fn step_s(&self) -> f64 {
        self.h
    }
    #[inline(always)]
    fn seconds(&self, len: f64) -> f64 {
        len
    }
    fn units(&self, seconds: f64) -> f64 {
        seconds
    }
    fn time_s(&self, at: f64) -> f64 {
        self.t + at
    }
    fn tolerance_floor(&self) -> f64 {
        self.h
    }
    fn min_progress(&self) -> f64 {
        4.0 * f64::EPSILON * self.h
    }
    fn land(&self, _tau: f64, x: f64, rest: f64) -> f64 {
        if rest - x < 1e-12 * self.h {
            rest
        } else {
            x
        }
    }
    fn reach(&self, _tau: f64, len: f64) -> f64 {
        len
    }
    fn break_at(&self, _tau: f64, x: f64, rest: f64, held: bool) -> f64 {
        if held {
            x.max(f64::MIN_POSITIVE).min(rest)
        } else {
            x
        }
    }
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
/// valves, chambers and platen. Delivers a row at each of the command's time stamps: the
/// columns of [`crate::forward_table`] (with `{name}_force_n` the chambers' force), then
/// `command_x_m` … `command_yaw_rad`, per actuator `{name}_drive`, `{name}_spool_opening`,
/// `{name}_delta_p_pa` (`p_a − p_b`; `p_a − P_R` single-acting) and `{name}_flow_m3_s` (into
/// chamber `a`), then `supply_pressure_pa`, `warping_force_n` (the null-space part of the
/// actuator forces, the force balance's error, at the last controller sample) and
/// `hydraulic_energy_j`.
///
/// # Errors
/// [`IntegrateError::InvalidStep`] for zero steps per period or tolerances that are not
/// positive; [`IntegrateError::LengthMismatch`] when the hydraulics or the controller do not
/// have one entry per actuator, or the table more than [`MAX_LOOP_ACTUATORS`]; the static
/// forces outside what the chambers can exert ([`IntegrateError::InvalidSystem`]);
/// [`IntegrateError::UnequalValveDelays`]; a numerical failure (non-finite state) or an
/// actuator at its end stop with its time.
pub fn forward_table_loop(run: &TableLoopRun<'_>) -> Result<(TableRun, TableLoopStats)> {
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
    let k = run.method.steps_per_period();
    if k == 0 {
        return Err(IntegrateError::InvalidStep { step_s: 0.0 });
    }
    if let LoopMethod::Dopri5 { rtol, atol, .. } = run.method {
        if !(rtol > 0.0 && rtol.is_finite() && atol > 0.0 && atol.is_finite()) {
            return Err(IntegrateError::InvalidStep { step_s: f64::NAN });
        }
    }
    if run.command.is_empty() {
        return Ok((TableRun::default(), TableLoopStats::default()));
    }
    match run.specimen {
        None => TableLoop::<LOOP_BARE>::new(run, k)?.run(),
        Some(s) if s.len() <= MAX_TABLE_SPECIMEN_DOFS => {
            TableLoop::<LOOP_WITH_SPECIMEN>::new(run, k)?.run()
        }
        Some(s) => Err(IntegrateError::LengthMismatch {
            what: "specimen DOFs of a closed-loop table run (at most MAX_TABLE_SPECIMEN_DOFS)",
            found: s.len(),
            expected: MAX_TABLE_SPECIMEN_DOFS,
        }),
    }
}

/// A closed-loop table run: the mode machine between the controller's samples.
struct TableLoop<'a, const L: usize> {
    machine: Machine<TablePlant<'a, Hydraulic<'a>, L>, L>,
    run: TableLoopRun<'a>,
    state: DofControllerState,
    /// Drives on their way through the valves' delay: (time they arrive, drives).
    queue: VecDeque<(f64, [f64; MAX_LOOP_ACTUATORS])>,
    out: Output,
    /// The loop's own columns of the row being emitted (kept to reuse its allocation).
    extra: Vec<f64>,
    stats: TableLoopStats,
    h: f64,
    t0: f64,
    /// Integration steps per controller period.
    k: u64,
    /// The next grid step.
    n: u64,
    /// The next output sample.
    j: usize,
}

impl<'a, const L: usize> TableLoop<'a, L> {
    fn new(run: &TableLoopRun<'a>, k: u32) -> Result<Self> {
        let (table, hyd) = (run.table, run.hydraulics);
        let h = run.controller.period_s() / f64::from(k);
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
            t: t0,
            h,
            cavitation_at_s: None,
            min_supply_pressure_pa: y[ps::<L>()],
        };
        let pieces = match run.method {
            LoopMethod::Rk4 { .. } => PieceMethod::Rk4,
            LoopMethod::Dopri5 { rtol, atol, .. } => PieceMethod::Dopri5 { rtol, atol },
        };
        let machine = start_machine(table, run.specimen, source, y, h, pieces);
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
        let out = Output::new(table, run.specimen, run.command.len(), names);
        let slots = (hyd.actuators()[0].servo_valve.delay_s * run.controller.sample_rate_hz())
            .ceil() as usize
            + 2;
        Ok(TableLoop {
            machine,
            run: *run,
            state: run.controller.start(),
            queue: VecDeque::with_capacity(slots),
            out,
            extra: Vec::new(),
            stats: TableLoopStats {
                min_supply_pressure_pa: y[ps::<L>()],
                ..TableLoopStats::default()
            },
            h,
            t0,
            k: u64::from(k),
            n: 0,
            j: 0,
        })
    }

    fn t(&self) -> f64 {
        self.machine.plant.source.t
    }

    fn set_t(&mut self, t: f64) {
        self.machine.plant.source.t = t;
    }

    /// The command at `t` (linear between samples, held past the ends).
    fn command_at(&self, t: f64) -> DofCommand {
        let c = self.run.command;
        let ts = c.t_s();
        let last = ts.len() - 1;
        let at = |i: usize| {
            let (pose, rates, accelerations) = c.at(i);
            DofCommand {
                pose,
                rates,
                accelerations,
            }
        };
        if t <= ts[0] {
            return at(0);
        }
        if t >= ts[last] {
            return at(last);
        }
        let j = ts.partition_point(|&x| x <= t).clamp(1, last);
        let w = (t - ts[j - 1]) / (ts[j] - ts[j - 1]);
        let (a, b) = (at(j - 1), at(j));
        DofCommand {
            pose: a.pose + (b.pose - a.pose) * w,
            rates: a.rates + (b.rates - a.rates) * w,
            accelerations: a.accelerations + (b.accelerations - a.accelerations) * w,
        }
    }

    /// What the controller reads now: strokes and their rates, Δp and forces per actuator
    /// (the first `n` of each, on the stack).
    fn feedback(&self) -> [PerActuator; 4] {
        let m = &self.machine;
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

    /// A controller sample now: the new drives enter the valves' delay line.
    fn tick(&mut self) {
        let command = self.command_at(self.t());
        let [strokes, rates, dp, forces] = self.feedback();
        let n = self.run.table.actuators().len();
        let m = &self.machine;
        let fb = DofFeedback {
            strokes_m: &strokes[..n],
            stroke_rates_m_s: &rates[..n],
            accelerations: Coords::from_fn(|k, _| m.k[QD + k]),
            delta_p_pa: &dp[..n],
            forces_n: &forces[..n],
        };
        self.run.controller.update(&mut self.state, &command, &fb);
        self.stats.controller_samples += 1;
        self.stats.max_warping_force_n = self.stats.max_warping_force_n.max(self.state.warping_n);
        let mut d = [0.0; MAX_LOOP_ACTUATORS];
        d[..self.state.drives.len()].copy_from_slice(&self.state.drives);
        let delay = self.run.hydraulics.actuators()[0].servo_valve.delay_s;
        self.queue.push_back((self.t() + delay, d));
    }

    /// Applies every delayed drive that has arrived by now (to `slack`).
    fn apply_arrived(&mut self, slack: f64) {
        let mut changed = false;
        while let Some(&(t, d)) = self.queue.front() {
            if t <= self.t() + slack {
                let now = self.t();
                self.machine.plant.source.drive(now, d);
                self.queue.pop_front();
                changed = true;
            } else {
                break;
            }
        }
        if changed {
            let mode = self.machine.mode;
            let spools = Source::<L>::input(&self.machine.plant.source, 0.0);
            self.machine.enter(mode, spools);
        }
    }

    /// Integrates `span` seconds with no cut inside, handling every event.
    fn segment(&mut self, span: f64) -> Result<()> {
        let (q0, _) = pose(&self.machine.y);
        let t0 = self.t();
        self.machine
            .advance_clocked(span, |p| &mut p.source.t)
            .map_err(|e| match e {
                // A state that blew up while a strut was running out of gas: the strut's
                // pull, not the solver, is what went without bound.
                IntegrateError::NonFiniteState { .. } => {
                    match spent_strut_below(self.run.table, &q0, BLOWN_UP_GAS_FRACTION) {
                        Some(strut) => IntegrateError::StrutGasSpent { t_s: t0, strut },
                        None => e,
                    }
                }
                e => e,
            })
    }

    /// The row of output sample `j`.
    fn emit(&mut self, j: usize) {
        let (table, hyd) = (self.run.table, self.run.hydraulics);
        let m = &self.machine;
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
        self.out.push(&self.machine, t_s, &forces[..n], &self.extra);
    }

    /// Emits every output sample due by now.
    fn emit_due(&mut self, slack: f64) {
        let ts = self.run.command.t_s();
        while self.j < ts.len() && ts[self.j] <= self.t() + slack {
            self.emit(self.j);
            self.j += 1;
        }
    }

    /// One grid step from `t₀ + n·h` (see [`crate::closed_loop`]): the controller's sample
    /// when one falls there, the output samples in it, the cuts inside it. Returns whether the
    /// run is over.
    fn grid_step(&mut self) -> Result<bool> {
        let ts = self.run.command.t_s();
        let t_end = ts[ts.len() - 1];
        let slack = 1e-9 * self.h;
        let n = self.n;
        self.set_t(self.t0 + n as f64 * self.h);
        if n % self.k == 0 {
            self.tick();
        }
        self.apply_arrived(slack);
        self.emit_due(slack);
        if self.j >= ts.len() || self.t() > t_end + slack {
            return Ok(true);
        }
        reaim(&mut self.machine);
        let t_next = self.t0 + (n + 1) as f64 * self.h;
        loop {
            let arrival = self.queue.front().map_or(f64::INFINITY, |&(t, _)| t);
            let sample = ts.get(self.j).copied().unwrap_or(f64::INFINITY);
            let cut = arrival.min(sample);
            if cut >= t_next - slack {
                break;
            }
            let span = cut - self.t();
            if span > 0.0 {
                self.segment(span)?;
            }
            self.set_t(cut);
            self.apply_arrived(slack);
            self.emit_due(slack);
        }
        let span = t_next - self.t();
        if span > 0.0 {
            self.segment(span)?;
        }
        self.check_end_stops(t_next)?;
        if self.state.saturated {
            self.stats.saturated_time_s += self.h;
        }
        self.n += 1;
        self.stats.steps += 1;
        Ok(false)
    }

    /// An actuator pushed past its chambers' oil (a chamber's volume gone), or a strut past
    /// its gas, ends the run.
    fn check_end_stops(&self, t_s: f64) -> Result<()> {
        let (table, hyd) = (self.run.table, self.run.hydraulics);
        let (q, _) = pose(&self.machine.y);
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
        if !self.machine.y.iter().all(|x| x.is_finite()) {
            return Err(IntegrateError::failed(
                t_s,
                Failure::NonFiniteState {
                    u_m: q[0],
                    v_m_s: self.machine.y[QD],
                },
            ));
        }
        Ok(())
    }

    fn run(mut self) -> Result<(TableRun, TableLoopStats)> {
        while !self.grid_step()? {}
        let y = &self.machine.y;
        let src = &self.machine.plant.source;
        self.stats.cavitation_at_s = src.cavitation_at_s;
        self.stats.min_supply_pressure_pa = src.min_supply_pressure_pa;
        self.stats.hydraulic_energy_j = y[eh::<L>()];
        self.stats.leakage_energy_j = y[el::<L>()];
        Ok((self.out.finish(), self.stats))
    }
}
