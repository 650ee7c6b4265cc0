//! The closed loop: a displacement command drives the controller, the servo-valves and the
//! actuator chambers of a [`TableSystem`], whose force drives the platen (and a specimen) with
//! exact stick-slip.
//!
//! The loop around the platen is the one closed-loop driver's ([`crate::control`]): the
//! controller at `f_c`, the valve's delay, the grid and its cuts. This file is the uniaxial
//! plant and its controller.
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

use crate::clock::SecondsClock;
use crate::control::{Command, ControlLoop, Driver, Emit, LoopMethod, LoopStats};
use crate::creep::creep_speed_m_s;
use crate::error::{IntegrateError, Result};
use crate::event::{Direction, EventKind, Mode};
use crate::machine::{Machine, Plant, DI, SD, U, V, W};
use crate::output::{SampleSink, SystemSample};
use crate::run::{EnergyBalance, RunStats, State};
use crate::steppable::{Samples, Steppable};
use crate::stop::Failure;
use crate::Motion;

const NS: usize = Specimen::MAX_STOREYS;
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
                    let mut driver = uniaxial_loop::<M, $len>(model, run, k, h, samples);
                    driver.run(sink)?;
                    Ok(driver.finish())
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
    let period = 1.0 / run.system.controller().sample_rate_hz;
    let k = run.method.checked_steps()?;
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
                    let mut driver = uniaxial_loop::<M, $len>(model, run, k, h, samples);
                    driver.machine.log_events();
                    Box::new(Some(driver))
                })*
                other => unreachable!("a validated specimen has 1 to {NS} storeys, not {other}"),
            }
        };
    }
    by_storeys!(0 => 13, 1 => 15, 2 => 17, 3 => 19, 4 => 21, 5 => 23, 6 => 25, 7 => 27,
                8 => 29, 9 => 31, 10 => 33, 11 => 35, 12 => 37)
}

/// A closed loop advanced step by step (`None` once finished).
impl<'a, M: PlatenModel + 'a, const L: usize> Steppable for Option<Driver<Uniaxial<'a, M, L>, L>> {
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
pub(crate) struct LoopPlant<'a, M, const L: usize> {
    model: &'a M,
    sys: &'a TableSystem,
    /// The right-hand side's constants.
    consts: HydraulicConstants,
    spec: Option<&'a Specimen>,
    /// Storeys.
    n: usize,
    /// Seconds from the start of the current advance.
    clock: SecondsClock,
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
            Some(spec) => spec.base_shear_n(&y[Z..Z + self.n], &y[Z + self.n..Z + 2 * self.n]),
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
                let n = self.n;
                spec.less_base_shear_rate(df, &k[Z..Z + n], &k[Z + n..Z + 2 * n])
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

    crate::clock::clock_field!(SecondsClock);
}

/// The uniaxial platen's controller and output around its [`LoopPlant`].
pub(crate) struct Uniaxial<'a, M, const L: usize> {
    sys: &'a TableSystem,
    command: &'a Motion,
    controller: ControllerState,
    /// The platen model's marker.
    _model: std::marker::PhantomData<&'a M>,
}

/// The closed loop `run` on `model` as the one driver runs it: the platen's state and the
/// hydraulics' null state, the platen's first mode and energy balance; `k` steps of `h` per
/// controller period, to deliver `samples`.
fn uniaxial_loop<'a, M: PlatenModel, const L: usize>(
    model: &'a M,
    run: &LoopRun<'a>,
    k: u32,
    h: f64,
    samples: usize,
) -> Driver<Uniaxial<'a, M, L>, L> {
    let (sys, spec, command) = (run.system, run.specimen, run.command);
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
    let plant = LoopPlant {
        model,
        sys,
        consts: sys.constants(),
        spec,
        n,
        clock: SecondsClock { t: t0, h },
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
    let mut machine = Machine::new(plant, y, h, run.method.pieces());
    machine.enter(mode, ());
    let energy = &mut machine.stats.energy;
    *energy = EnergyBalance::start(model, y[U], y[V]);
    energy.specimen_start_j = specimen_start_j;
    energy.specimen_end_j = specimen_start_j;
    let control = Uniaxial {
        sys,
        command,
        controller: ControllerState::default(),
        _model: std::marker::PhantomData,
    };
    let f_c = sys.controller().sample_rate_hz;
    Driver::new(machine, control, (k, h, f_c), samples)
}

impl Command for Motion {
    /// The displacement, velocity and acceleration.
    type Value = (f64, f64, f64);

    fn t_s(&self) -> &[f64] {
        Motion::t_s(self)
    }

    fn value(&self, i: usize) -> (f64, f64, f64) {
        (self.u_m()[i], self.v_m_s()[i], self.a_m_s2()[i])
    }

    fn lerp(a: &(f64, f64, f64), b: &(f64, f64, f64), w: f64) -> (f64, f64, f64) {
        (
            a.0 + w * (b.0 - a.0),
            a.1 + w * (b.1 - a.1),
            a.2 + w * (b.2 - a.2),
        )
    }
}

impl<'a, M: PlatenModel + 'a, const L: usize> ControlLoop<L> for Uniaxial<'a, M, L> {
    type Plant = LoopPlant<'a, M, L>;
    type Command = Motion;
    /// The valve's input.
    type Drive = f64;

    fn command(&self) -> &Motion {
        self.command
    }

    fn delay_s(&self) -> f64 {
        self.sys.servo_valve().delay_s
    }

    /// The three-variable controller on `u`, `v`, the platen's acceleration and `Δp`.
    fn control(&mut self, m: &Machine<Self::Plant, L>, command: &(f64, f64, f64)) -> f64 {
        let (r, rv, ra) = *command;
        let input = ControllerInput {
            command_u_m: r,
            command_v_m_s: rv,
            command_a_m_s2: ra,
            u_m: m.y[U],
            v_m_s: m.y[V],
            a_m_s2: m.a,
            delta_p_pa: m.y[PA].max(0.0) - m.y[PB].max(0.0),
        };
        self.sys.controller().update(&mut self.controller, &input)
    }

    fn saturated(&self) -> bool {
        self.controller.saturated
    }

    fn arrive(plant: &mut Self::Plant, _t_s: f64, drive: f64) {
        plant.input = drive;
    }

    /// The platen's energy balance (and the specimen's), the hydraulics' figures.
    fn finish(&self, m: &Machine<Self::Plant, L>, stats: &mut LoopStats) {
        let y = m.y;
        let run = &mut stats.run;
        run.energy.close(m.plant.model, y[U], y[V], y[W], y[DI]);
        run.energy.specimen_end_j = m.plant.specimen_energy(&y);
        run.energy.specimen_dissipated_j = y[SD];
        stats.cavitation_at_s = m.plant.cavitation_at_s;
        stats.min_supply_pressure_pa = m.plant.min_supply_pressure_pa;
        stats.hydraulic_energy_j = y[EH];
        stats.leakage_energy_j = y[EL];
    }
}

impl<'a, M: PlatenModel + 'a, S: SampleSink, const L: usize> Emit<S, L> for Uniaxial<'a, M, L> {
    fn emit(&mut self, m: &Machine<Self::Plant, L>, j: usize, sink: &mut S) {
        let t_s = self.command.t_s()[j];
        let p = &m.plant;
        let spec = p.spec.map(|s| (s, !s.is_shear_building()));
        let mut sample = m.sample(j, t_s, p.force(&m.y), p.base_shear(&m.y), spec, Z);
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
}
