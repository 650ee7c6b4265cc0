//! The closed loop: a displacement command drives the controller, the servo-valves and the
//! actuator chambers of a [`TableSystem`], whose force drives the platen (and a specimen) with
//! exact stick-slip.
//!
//! # Time
//!
//! The controller runs at `f_c`; the integration grid divides its period into `k` steps,
//! `t = t₀ + n·h`, `h = 1/(k·f_c)`, from an integer counter. The drive is held between
//! controller samples and reaches the valve `τ` later (the valve's pure delay), so the valve
//! input is piecewise constant: a step is cut where it changes, and where an output sample
//! (the command record's own time stamps) falls inside it. Between cuts the right-hand side is
//! smooth but for the friction events, which are located as in the force-driven runs.
//!
//! # Modes
//!
//! As [`crate::forward_rk4_specimen`], with the actuator force now a function of the state
//! (the chamber pressures) instead of a record:
//! * **slip±**: the full state; a piece is accepted when the speed stays positive at its
//!   stages, its end and on its Hermite interpolant, else halved, and `v = 0` is located by
//!   Illinois root finding on the integrator's map.
//! * **stick**: `v = 0`, the hydraulics (and the specimen) evolve: the loop fights the friction
//!   and the pressure difference ramps until `|N| = |F_A − F_E(u) − B|` reaches `F_s`, located
//!   the same way (its rate `Ṅ = n(A_a·ṗ_a − A_b·ṗ_b) + k₁ż₁ + c₁z̈₁` is exact).
//! * **creep±** (`α < 1`): the velocity slaved to the net force below the stiff speed; the
//!   platen's acceleration is taken as zero there (it is the rate of a velocity below the
//!   stiff speed, negligible next to the loop's). A creep stop that rounds onto the start of
//!   its advance with the net force at rest still a hair along the motion is stepped
//!   `just_past` it (as in [`crate::forward_rk4_specimen`]), so a frictionless table
//!   (`F_s = 0`) creeps through `v = 0` instead of stalling.
//!
//! The integrator of each piece is RK4 (one step, graded near rest as the force-driven RK4) or
//! an adaptive Dormand–Prince 5(4) that meets `rtol`/`atol` over the piece.
//!
//! # Measured by the controller
//!
//! The controller reads the state at its samples exactly: `u`, `v`, the platen's acceleration
//! (the right-hand limit), and `Δp`; the command `u_ref`, `v_ref`, `a_ref` are the command
//! record's channels, linear between samples and held past its ends.

use std::collections::VecDeque;

use platen_model::{PlatenModel, Specimen};
use platen_system::{
    ControllerInput, ControllerState, HydraulicConstants, HydraulicState, Supply, TableSystem,
};

use crate::creep::creep_speed_m_s;
use crate::error::{IntegrateError, Result};
use crate::event::{Direction, EventKind, Mode};
use crate::machine::{Machine, PieceMethod, Plant, DI, SD, U, V, W};
use crate::output::{SampleSink, SystemSample};
use crate::run::{EnergyBalance, RunStats, State};
use crate::steppable::{Samples, Steppable};
use crate::stop::{Failure, StopReason};
use crate::Motion;

const NS: usize = Specimen::MAX_STOREYS;
/// A creep stop located this close (fraction of a step `h`) to where the advance started has
/// not moved time: if the net force at rest still drives the creep on, it is stepped just
/// past (`just_past`) instead of creeping on in place.
const MIN_PROGRESS: f64 = 4.0 * f64::EPSILON;
const PA: usize = 5;
const PB: usize = 6;
const XV: usize = 7;
const XR: usize = 8;
const OIL: usize = 9;
/// Hydraulic energy delivered into the chambers, `∫n(p_a·q_a − p_b·q_b) dt`, J.
const EH: usize = 10;
/// Energy lost to cross-port leakage, `∫n·C_L(p_a − p_b)² dt`, J.
const EL: usize = 11;
/// Supply pressure, Pa.
const PS: usize = 12;
const Z: usize = 13;
/// The state of a loop with `(L − Z)/2` storeys: the stepper is compiled per length so that a
/// bare platen steps arrays of 12, not of the largest specimen's 36.
type Y<const L: usize> = [f64; L];

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
}

/// What a closed-loop run reports besides its samples.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoopStats {
    /// The solver's counters and the platen's energy balance.
    pub run: RunStats,
    /// Time with the drive saturated (`|d| = 1`), s.
    pub saturated_time_s: f64,
    /// First time a chamber pressure reached the cavitation floor (0 Pa absolute), s.
    pub cavitation_at_s: Option<f64>,
    /// Lowest supply pressure, Pa.
    pub min_supply_pressure_pa: f64,
    /// Hydraulic energy delivered into the chambers, J.
    pub hydraulic_energy_j: f64,
    /// Energy lost to cross-port leakage, J.
    pub leakage_energy_j: f64,
    /// Controller samples taken.
    pub controller_samples: u64,
}

/// A closed-loop run: the table system, what it carries, its command, its integrator.
#[derive(Debug, Clone, Copy)]
pub struct LoopRun<'a> {
    /// The loop around the platen.
    pub system: &'a TableSystem,
    /// The specimen on the platen, if any.
    pub specimen: Option<&'a Specimen>,
    /// The displacement command with its velocity and acceleration.
    pub command: &'a Motion,
    /// The integrator.
    pub method: LoopMethod,
    /// The platen's state at the command's first sample (the hydraulics start at their null
    /// state: centred spool, null pressures, a charged bank; the specimen at rest).
    pub initial: State,
}

/// Runs the closed loop `run` on `model`: the command drives the controller, whose valves and
/// actuators drive the platen (and the specimen). Delivers `samples` output samples at the
/// command's first `samples` time stamps to `sink`.
///
/// # Errors
/// [`IntegrateError::InvalidStep`] for zero steps per period or tolerances that are not
/// positive; a numerical failure (non-finite state) with its time.
pub fn forward_closed_loop<M: PlatenModel, S: SampleSink>(
    model: &M,
    run: &LoopRun<'_>,
    samples: usize,
    sink: &mut S,
) -> Result<LoopStats> {
    let Some((k, h, samples)) = check_loop(run, samples)? else {
        return Ok(LoopStats::default());
    };
    macro_rules! by_storeys {
        ($($n:literal => $len:literal),*) => {
            match run.specimen.map_or(0, Specimen::len) {
                $($n => {
                    let mut stepper = Loop::<M, $len>::new(model, run, k, h, samples);
                    stepper.run(sink)?;
                    Ok(stepper.finish())
                })*
                other => unreachable!("a validated specimen has 1 to {NS} storeys, not {other}"),
            }
        };
    }
    by_storeys!(0 => 13, 1 => 15, 2 => 17, 3 => 19, 4 => 21, 5 => 23, 6 => 25, 7 => 27,
                8 => 29, 9 => 31, 10 => 33, 11 => 35, 12 => 37)
}

/// The checks of a closed-loop run before it starts; its steps per period, step and samples
/// (at most the command's), or `None` when there is no sample to deliver.
pub(crate) fn check_loop(run: &LoopRun<'_>, samples: usize) -> Result<Option<(u32, f64, usize)>> {
    let (system, method) = (run.system, run.method);
    let k = method.steps_per_period();
    let period = 1.0 / system.controller().sample_rate_hz;
    if k == 0 {
        return Err(IntegrateError::InvalidStep { step_s: 0.0 });
    }
    if let LoopMethod::Dopri5 { rtol, atol, .. } = method {
        if !(rtol > 0.0 && rtol.is_finite() && atol > 0.0 && atol.is_finite()) {
            return Err(IntegrateError::InvalidStep { step_s: f64::NAN });
        }
    }
    if !(run.initial.u_m.is_finite() && run.initial.v_m_s.is_finite()) {
        return Err(IntegrateError::failed(
            run.command.t_s().first().copied().unwrap_or(0.0),
            Failure::NonFiniteState {
                u_m: run.initial.u_m,
                v_m_s: run.initial.v_m_s,
            },
        ));
    }
    let samples = samples.min(run.command.len());
    if samples == 0 {
        return Ok(None);
    }
    Ok(Some((k, period / f64::from(k), samples)))
}

/// The closed loop `run` as a [`Steppable`] run (its state length chosen by its storeys).
pub(crate) fn boxed_loop<'a, M: PlatenModel>(
    model: &'a M,
    run: &LoopRun<'a>,
    k: u32,
    h: f64,
    samples: usize,
) -> Box<dyn Steppable + 'a> {
    macro_rules! by_storeys {
        ($($n:literal => $len:literal),*) => {
            match run.specimen.map_or(0, Specimen::len) {
                $($n => {
                    let mut stepper = Loop::<M, $len>::new(model, run, k, h, samples);
                    stepper.machine.log_events();
                    Box::new(Some(stepper))
                })*
                other => unreachable!("a validated specimen has 1 to {NS} storeys, not {other}"),
            }
        };
    }
    by_storeys!(0 => 13, 1 => 15, 2 => 17, 3 => 19, 4 => 21, 5 => 23, 6 => 25, 7 => 27,
                8 => 29, 9 => 31, 10 => 33, 11 => 35, 12 => 37)
}

/// A closed loop advanced step by step (`None` once finished).
impl<M: PlatenModel, const L: usize> Steppable for Option<Loop<'_, M, L>> {
    fn advance(&mut self, out: &mut Samples) -> Result<bool> {
        let Some(run) = self else {
            return Ok(false);
        };
        loop {
            if run.grid_step(out)? {
                return Ok(false);
            }
            if !out.0.is_empty() {
                return Ok(true);
            }
        }
    }

    fn drain_events(&mut self, out: &mut VecDeque<(f64, EventKind)>) {
        if let Some(run) = self {
            run.machine.drain_events(out);
        }
    }

    fn finish(&mut self) -> RunStats {
        self.take().map(|run| run.finish().run).unwrap_or_default()
    }
}

/// The platen (and specimen) driven by the table system's actuators: the [`Plant`] of the mode
/// machine. Positions are seconds from the start of the current advance.
struct LoopPlant<'a, M, const L: usize> {
    model: &'a M,
    sys: &'a TableSystem,
    /// The right-hand side's constants.
    consts: HydraulicConstants,
    spec: Option<&'a Specimen>,
    /// Storeys.
    n: usize,
    /// The grid's step, s.
    h: f64,
    /// Time at the start of the current advance, s.
    t: f64,
    /// The valve's input (the delayed, held drive).
    input: f64,
    /// First time a chamber pressure reached the cavitation floor, s.
    cavitation_at_s: Option<f64>,
    /// Lowest supply pressure, Pa.
    min_supply_pressure_pa: f64,
}

impl<M: PlatenModel, const L: usize> LoopPlant<'_, M, L> {
    fn hydraulic_state(y: &Y<L>) -> HydraulicState {
        HydraulicState {
            p_a_pa: y[PA],
            p_b_pa: y[PB],
            spool: y[XV],
            spool_rate_1_s: y[XR],
            accumulator_oil_m3: y[OIL],
            supply_pressure_pa: y[PS],
        }
    }

    #[inline(always)]
    fn force(&self, y: &Y<L>) -> f64 {
        self.sys.force_n(y[PA].max(0.0), y[PB].max(0.0))
    }

    #[inline(always)]
    fn base_shear(&self, y: &Y<L>) -> f64 {
        match self.spec {
            Some(spec) => spec.base_shear_n(y[Z], y[Z + self.n]),
            None => 0.0,
        }
    }

    fn specimen_energy(&self, y: &Y<L>) -> f64 {
        match self.spec {
            Some(spec) => {
                let (n, zd) = (self.n, Z + self.n);
                spec.energy_j(y[V], &y[Z..Z + n], &y[zd..zd + n])
            }
            None => 0.0,
        }
    }
}

impl<M: PlatenModel, const L: usize> Plant<L> for LoopPlant<'_, M, L> {
    type Model = M;
    /// Nothing: the actuator force is the chambers' and the valve's input is held.
    type Input = ();

    #[inline(always)]
    fn model(&self) -> &M {
        self.model
    }

    #[inline(always)]
    fn input(&self, _at: f64) {}

    #[inline(always)]
    fn rates(&self, mode: Mode, w_stiff: f64, _input: (), y: &Y<L>, dy: &mut Y<L>) -> f64 {
        let f = self.force(y);
        let f_eff = f - self.base_shear(y);
        let (a, v_eff) = match mode {
            Mode::Slip(dir) => {
                let r = self.model.slip_rates(f_eff, y[U], y[V], dir.sign());
                dy[U] = y[V];
                dy[V] = r.a_m_s2;
                dy[DI] = r.dissipated_power_w;
                (r.a_m_s2, y[V])
            }
            Mode::Stick => {
                dy[U] = 0.0;
                dy[V] = 0.0;
                dy[DI] = 0.0;
                (0.0, 0.0)
            }
            Mode::Creep(dir) => {
                let s = dir.sign();
                let w = creep_speed_m_s(self.model, dir, y[U], f_eff, w_stiff).unwrap_or(w_stiff);
                dy[U] = s * w;
                dy[V] = 0.0;
                dy[DI] = self.model.dissipative_magnitude_n(y[U], w) * w;
                (0.0, s * w)
            }
        };
        dy[W] = f * v_eff;
        let hs = Self::hydraulic_state(y);
        let hr = self
            .sys
            .hydraulic_rates_with(&self.consts, y[U], v_eff, self.input, &hs);
        dy[PA] = hr.p_a;
        dy[PB] = hr.p_b;
        dy[XV] = hr.spool;
        dy[XR] = hr.spool_rate;
        dy[OIL] = hr.accumulator_oil;
        dy[PS] = hr.supply_pressure;
        dy[EH] = hr.hydraulic_power_w;
        let act = self.sys.actuator();
        let dp = y[PA].max(0.0) - y[PB].max(0.0);
        dy[EL] = f64::from(act.count) * act.leakage_m3_s_per_pa * dp * dp;
        if let Some(spec) = self.spec {
            let (n, zd) = (self.n, Z + self.n);
            dy[Z..Z + n].copy_from_slice(&y[zd..zd + n]);
            let (zs, rest) = (&y[Z..Z + n], &y[zd..zd + n]);
            dy[SD] = spec.storey_accelerations(a, zs, rest, &mut dy[zd..zd + n]);
        }
        a
    }

    #[inline(always)]
    fn slip_rates<const POSITIVE: bool>(&self, input: (), y: &Y<L>, dy: &mut Y<L>) -> f64 {
        let dir = if POSITIVE {
            Direction::Positive
        } else {
            Direction::Negative
        };
        self.rates(Mode::Slip(dir), 0.0, input, y, dy)
    }

    #[inline(always)]
    fn effective_force(&self, _input: (), y: &Y<L>) -> f64 {
        self.force(y) - self.base_shear(y)
    }

    /// `N = F_A − F_E(u) − B`, with the same arithmetic as `mode_at_rest(…, f_eff)` (the
    /// actuator force less the base shear, then less the elastic force): a net force that
    /// rounds differently in the two would let the breakaway test and the mode at rest
    /// disagree by an ulp at the threshold, and the event loop toggle between them without
    /// time moving.
    #[inline(always)]
    fn net(&self, input: (), y: &Y<L>) -> f64 {
        self.effective_force(input, y) - self.model.elastic_force_n(y[U])
    }

    /// `Ṅ = n(A_a·ṗ_a − A_b·ṗ_b) + k₁ż₁ + c₁z̈₁` (`u` fixed).
    fn net_rate(&self, k: &Y<L>) -> f64 {
        let act = self.sys.actuator();
        let df = f64::from(act.count) * (act.cap_area_m2 * k[PA] - act.rod_area_m2 * k[PB]);
        match self.spec {
            Some(spec) => {
                let st = spec.storeys()[0];
                df + st.stiffness_n_per_m * k[Z] + st.damping_n_s_per_m * k[Z + self.n]
            }
            None => df,
        }
    }

    /// An actuator pushed to its end stop (a chamber's volume gone) ends the run there.
    fn check(&self, y: &Y<L>, t_s: f64) -> Result<()> {
        let (v_a, v_b) = self.sys.chamber_volumes_m3(y[U]);
        if v_a <= 0.0 || v_b <= 0.0 {
            return Err(IntegrateError::failed(t_s, Failure::EndStop { u_m: y[U] }));
        }
        Ok(())
    }

    const RATES_ON_COMMIT: bool = true;

    /// Pressures are held at the cavitation floor (0 Pa absolute); the lowest supply pressure
    /// is kept.
    fn admit(&mut self, y: &mut Y<L>, t_s: f64) -> bool {
        let floored = y[PA] < 0.0 || y[PB] < 0.0;
        if floored {
            for i in [PA, PB] {
                y[i] = y[i].max(0.0);
            }
            self.cavitation_at_s.get_or_insert(t_s);
        }
        self.min_supply_pressure_pa = self.min_supply_pressure_pa.min(y[PS]);
        floored
    }

    /// Metres for the motion and the storeys, the supply pressure for the pressures, full
    /// opening for the spool, the bank's volume for its oil; the energy integrals are
    /// quadratures and not controlled.
    /// The pressures' stiffest local rate (the orifices' conductance at their drops and
    /// the spool's opening, [`TableSystem::pressure_rate_1_s`]): fast only near a land's
    /// laminar drop at a wide opening, where the default step does not resolve it.
    #[inline(always)]
    fn stiff_rate(&self, y: &Y<L>) -> f64 {
        self.sys
            .pressure_rate_1_s(&self.consts, y[U], &Self::hydraulic_state(y))
    }

    fn error_scale(&self, i: usize, y0: f64, y1: f64, rtol: f64, atol: f64) -> f64 {
        let m = y0.abs().max(y1.abs());
        let unit = match i {
            PA | PB => self.sys.supply_pressure_pa() * 1e3,
            XV => 1e3,
            XR => 1e3 * std::f64::consts::TAU * self.sys.servo_valve().natural_frequency_hz,
            OIL => match self.sys.supply() {
                Supply::Accumulator(acc) => acc.volume_m3,
                Supply::Constant => 1.0,
            },
            PS => self.sys.supply_pressure_pa() * 1e3,
            V => 1.0,
            W | DI | SD | EH | EL => return f64::INFINITY,
            _ => 1.0,
        };
        atol * unit + rtol * m
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
        MIN_PROGRESS * self.h
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

/// A closed-loop run: the mode machine between the controller's samples.
struct Loop<'a, M, const L: usize> {
    machine: Machine<LoopPlant<'a, M, L>, L>,
    command: &'a Motion,
    h: f64,
    t0: f64,
    controller: ControllerState,
    /// Drives on their way through the valve's delay: (time it arrives, value).
    queue: VecDeque<(f64, f64)>,
    /// Time with the drive saturated, s.
    saturated_time_s: f64,
    /// Controller samples taken.
    controller_samples: u64,
    /// Integration steps per controller period.
    k: u64,
    /// Output samples to deliver.
    samples: usize,
    /// The next grid step.
    n: u64,
    /// The next output sample.
    j: usize,
}

impl<'a, M: PlatenModel, const L: usize> Loop<'a, M, L> {
    /// The loop of `run`, `k` steps of `h` per controller period, to deliver `samples`.
    fn new(model: &'a M, run: &LoopRun<'a>, k: u32, h: f64, samples: usize) -> Self {
        let (sys, spec, command, method) = (run.system, run.specimen, run.command, run.method);
        let n = spec.map_or(0, Specimen::len);
        let mut y = [0.0; L];
        let rest = sys.rest_state();
        y[U] = run.initial.u_m;
        y[V] = run.initial.v_m_s;
        y[PA] = rest.p_a_pa;
        y[PB] = rest.p_b_pa;
        y[OIL] = rest.accumulator_oil_m3;
        y[PS] = rest.supply_pressure_pa;
        let t0 = command.t_s()[0];
        let delay = sys.servo_valve().delay_s;
        let slots = (delay * sys.controller().sample_rate_hz).ceil() as usize + 2;
        let plant = LoopPlant {
            model,
            sys,
            consts: sys.constants(),
            spec,
            n,
            h,
            t: t0,
            input: 0.0,
            cavitation_at_s: None,
            min_supply_pressure_pa: sys.supply_pressure_at(rest.accumulator_oil_m3),
        };
        let mode = Mode::initial(
            model,
            y[U],
            y[V],
            plant.net((), &y) + model.elastic_force_n(y[U]),
        );
        let specimen_start_j = plant.specimen_energy(&y);
        let pieces = match method {
            LoopMethod::Rk4 { .. } => PieceMethod::Rk4,
            LoopMethod::Dopri5 { rtol, atol, .. } => PieceMethod::Dopri5 { rtol, atol },
        };
        let mut machine = Machine::new(plant, y, h, pieces);
        machine.enter(mode, ());
        let energy = &mut machine.stats.energy;
        *energy = EnergyBalance::start(model, y[U], y[V]);
        energy.specimen_start_j = specimen_start_j;
        energy.specimen_end_j = specimen_start_j;
        Loop {
            machine,
            command,
            h,
            t0,
            controller: ControllerState::default(),
            queue: VecDeque::with_capacity(slots),
            saturated_time_s: 0.0,
            controller_samples: 0,
            k: u64::from(k),
            samples,
            n: 0,
            j: 0,
        }
    }

    /// The current time, s.
    fn t(&self) -> f64 {
        self.machine.plant.t
    }

    /// Integrates the current segment of `span` seconds (no cut inside it), handling every
    /// event.
    fn segment(&mut self, span: f64) -> Result<()> {
        self.machine.advance_clocked(span, |p| &mut p.t)
    }

    /// The command's displacement, velocity and acceleration at `t` (linear between samples,
    /// held past the ends).
    fn command_at(&self, t: f64) -> (f64, f64, f64) {
        let ts = self.command.t_s();
        let (u, v, a) = (
            self.command.u_m(),
            self.command.v_m_s(),
            self.command.a_m_s2(),
        );
        let last = ts.len() - 1;
        if t <= ts[0] {
            return (u[0], v[0], a[0]);
        }
        if t >= ts[last] {
            return (u[last], v[last], a[last]);
        }
        let j = ts.partition_point(|&x| x <= t).clamp(1, last);
        let (t0, t1) = (ts[j - 1], ts[j]);
        let w = (t - t0) / (t1 - t0);
        let lerp = |c: &[f64]| c[j - 1] + w * (c[j] - c[j - 1]);
        (lerp(u), lerp(v), lerp(a))
    }

    /// A controller sample at the current time: the new drive enters the valve's delay line.
    fn tick(&mut self) {
        let (r, rv, ra) = self.command_at(self.t());
        let m = &self.machine;
        let input = ControllerInput {
            command_u_m: r,
            command_v_m_s: rv,
            command_a_m_s2: ra,
            u_m: m.y[U],
            v_m_s: m.y[V],
            a_m_s2: m.a,
            delta_p_pa: m.y[PA].max(0.0) - m.y[PB].max(0.0),
        };
        let sys = m.plant.sys;
        let d = sys.controller().update(&mut self.controller, &input);
        self.controller_samples += 1;
        self.queue
            .push_back((self.t() + sys.servo_valve().delay_s, d));
    }

    /// Applies every delayed drive that has arrived by the current time (to `slack`).
    fn apply_arrived(&mut self, slack: f64) -> bool {
        let mut changed = false;
        while let Some(&(t, d)) = self.queue.front() {
            if t <= self.t() + slack {
                self.machine.plant.input = d;
                self.queue.pop_front();
                changed = true;
            } else {
                break;
            }
        }
        if changed {
            let mode = self.machine.mode;
            self.machine.enter(mode, ());
        }
        changed
    }

    fn emit<S: SampleSink>(&mut self, j: usize, sink: &mut S) {
        let t_s = self.command.t_s()[j];
        let (m, p) = (&self.machine, &self.machine.plant);
        let mut sample = m.sample(j, t_s, p.force(&m.y), p.base_shear(&m.y), p.n, Z);
        let ps = m.y[PS];
        let (p_a, p_b) = (m.y[PA].max(0.0), m.y[PB].max(0.0));
        let (q_a, _) = p.sys.valve_flows_with(&p.consts, m.y[XV], p_a, p_b, ps);
        sample.system = Some(SystemSample {
            command_u_m: self.command.u_m()[j],
            drive: self.controller.drive,
            spool_opening: m.y[XV].clamp(-1.0, 1.0),
            delta_p_pa: p_a - p_b,
            p_a_pa: p_a,
            p_b_pa: p_b,
            flow_m3_s: f64::from(p.sys.actuator().count) * q_a,
            supply_pressure_pa: ps,
        });
        sink.accept(&sample);
    }

    /// Runs the grid: controller samples every `k` steps, each step cut where the valve's
    /// input changes or an output sample falls.
    fn run<S: SampleSink>(&mut self, sink: &mut S) -> Result<()> {
        while !self.grid_step(sink)? {}
        Ok(())
    }

    /// One grid step from `t₀ + n·h`: the controller's sample when one falls there, the
    /// output samples that fall in it, the cuts inside it. Returns whether the run is over
    /// (every output sample delivered), having delivered the last ones.
    fn grid_step<S: SampleSink>(&mut self, sink: &mut S) -> Result<bool> {
        let ts = self.command.t_s();
        let samples = self.samples;
        let t_end = ts[samples - 1];
        let slack = 1e-9 * self.h;
        let n = self.n;
        // At the grid point t₀ + n·h.
        self.machine.plant.t = self.t0 + n as f64 * self.h;
        if n % self.k == 0 {
            self.tick();
        }
        self.apply_arrived(slack);
        while self.j < samples && ts[self.j] <= self.t() + slack {
            self.emit(self.j, sink);
            self.j += 1;
        }
        if self.j >= samples || self.t() > t_end + slack {
            self.machine.stats.stop = StopReason::Finished { t_s: t_end };
            return Ok(true);
        }
        let t_next = self.t0 + (n + 1) as f64 * self.h;
        // Cuts inside (t, t_next): arrivals of delayed drives and output samples.
        loop {
            let arrival = self.queue.front().map_or(f64::INFINITY, |&(t, _)| t);
            let sample = if self.j < samples {
                ts[self.j]
            } else {
                f64::INFINITY
            };
            let cut = arrival.min(sample);
            if cut >= t_next - slack {
                break;
            }
            let span = cut - self.t();
            if span > 0.0 {
                self.segment(span)?;
            }
            self.machine.plant.t = cut;
            self.apply_arrived(slack);
            while self.j < samples && ts[self.j] <= self.t() + slack {
                self.emit(self.j, sink);
                self.j += 1;
            }
        }
        let span = t_next - self.t();
        if span > 0.0 {
            self.segment(span)?;
        }
        if self.controller.saturated {
            self.saturated_time_s += self.h;
        }
        self.n += 1;
        self.machine.stats.steps += 1;
        Ok(false)
    }

    fn finish(self) -> LoopStats {
        let m = self.machine;
        let y = m.y;
        let mut run = m.stats;
        run.energy.close(m.plant.model, y[U], y[V], y[W], y[DI]);
        run.energy.specimen_end_j = m.plant.specimen_energy(&y);
        run.energy.specimen_dissipated_j = y[SD];
        if m.is_rk4() {
            run.accepted_steps = run.steps;
        }
        LoopStats {
            run,
            saturated_time_s: self.saturated_time_s,
            cavitation_at_s: m.plant.cavitation_at_s,
            min_supply_pressure_pa: m.plant.min_supply_pressure_pa,
            hydraulic_energy_j: y[EH],
            leakage_energy_j: y[EL],
            controller_samples: self.controller_samples,
        }
    }
}
