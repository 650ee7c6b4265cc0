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
//!   [`just_past`] it (as in [`crate::forward_rk4_specimen`]), so a frictionless table
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
use std::convert::Infallible;

use platen_model::{PlatenModel, Specimen};
use platen_system::{
    ControllerInput, ControllerState, HydraulicConstants, HydraulicRates, HydraulicState, Supply,
    TableSystem,
};

use crate::creep::{creep_speed_m_s, stiff_speed_m_s};
use crate::dopri5::MAX_STEPS;
use crate::error::{IntegrateError, Result};
use crate::event::{
    arrive_at_rest, dip_to_zero, just_past, locate_zero_velocity, mode_at_rest, Direction,
    EventKind, Mode, MAX_EVENTS_PER_STEP,
};
use crate::output::{SampleSink, SpecimenSample, SystemSample};
use crate::rk4::{Grading, MAX_HALVINGS};
use crate::run::{sample_at, EnergyBalance, Kin, RunStats, State};
use crate::stop::{AdaptiveFailure, Failure, StopReason};
use crate::Motion;

const NS: usize = Specimen::MAX_STOREYS;
/// A creep stop located this close (fraction of a step `h`) to where the advance started has
/// not moved time: if the net force at rest still drives the creep on, it is stepped just
/// past ([`just_past`]) instead of creeping on in place.
const MIN_PROGRESS: f64 = 4.0 * f64::EPSILON;
const U: usize = 0;
const V: usize = 1;
/// `∫F_A·v dt`, J.
const W: usize = 2;
/// Platen dissipation, J.
const DI: usize = 3;
/// Storey-damper dissipation, J.
const SD: usize = 4;
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
    let (system, method) = (run.system, run.method);
    let k = method.steps_per_period();
    let period = 1.0 / system.controller.sample_rate_hz;
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
        return Ok(LoopStats::default());
    }
    let h = period / f64::from(k);
    macro_rules! by_storeys {
        ($($n:literal => $len:literal),*) => {
            match run.specimen.map_or(0, Specimen::len) {
                $($n => {
                    let mut stepper = Loop::<M, $len>::new(model, run, h);
                    stepper.run(k, samples, sink)?;
                    Ok(stepper.finish())
                })*
                other => unreachable!("a validated specimen has 1 to {NS} storeys, not {other}"),
            }
        };
    }
    by_storeys!(0 => 13, 1 => 15, 2 => 17, 3 => 19, 4 => 21, 5 => 23, 6 => 25, 7 => 27,
                8 => 29, 9 => 31, 10 => 33, 11 => 35, 12 => 37)
}

struct Loop<'a, M, const L: usize> {
    model: &'a M,
    sys: &'a TableSystem,
    /// The right-hand side's constants.
    consts: HydraulicConstants,
    spec: Option<&'a Specimen>,
    command: &'a Motion,
    method: LoopMethod,
    /// Storeys.
    n: usize,
    h: f64,
    t0: f64,
    /// Time at the start of the current segment, s.
    t: f64,
    y: Y<L>,
    k: Y<L>,
    a: f64,
    mode: Mode,
    w_stiff: f64,
    /// The valve's input (the delayed, held drive).
    input: f64,
    controller: ControllerState,
    /// Drives on their way through the valve's delay: (time it arrives, value).
    queue: VecDeque<(f64, f64)>,
    /// Last Dopri5 step, s.
    h_dopri: f64,
    /// Where and why Dopri5 gave up inside the current advance (the step budget spent or the
    /// step shrunk to nothing): the run stops there with that failure
    /// ([`Loop::segment`]), as the bare platen's Dopri5 does.
    gave_up: Option<(f64, AdaptiveFailure)>,
    stats: LoopStats,
}

impl<'a, M: PlatenModel, const L: usize> Loop<'a, M, L> {
    fn new(model: &'a M, run: &LoopRun<'a>, h: f64) -> Self {
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
        let delay = sys.servo_valve.delay_s;
        let slots = (delay * sys.controller.sample_rate_hz).ceil() as usize + 2;
        let mut s = Self {
            model,
            sys,
            consts: sys.constants(),
            spec,
            command,
            method,
            n,
            h,
            t0,
            t: t0,
            y,
            k: [0.0; L],
            a: 0.0,
            mode: Mode::Stick,
            w_stiff: 0.0,
            input: 0.0,
            controller: ControllerState::default(),
            queue: VecDeque::with_capacity(slots),
            h_dopri: h,
            gave_up: None,
            stats: LoopStats {
                min_supply_pressure_pa: sys.supply_pressure_at(rest.accumulator_oil_m3),
                ..LoopStats::default()
            },
        };
        let y = s.y;
        let mode = Mode::initial(model, y[U], y[V], s.net(&y) + model.elastic_force_n(y[U]));
        s.enter(mode);
        s.stats.run.energy = EnergyBalance::start(model, y[U], y[V]);
        s.stats.run.energy.specimen_start_j = s.specimen_energy(&y);
        s.stats.run.energy.specimen_end_j = s.stats.run.energy.specimen_start_j;
        s
    }

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

    /// The net force on the platen less its elastic force: `N = F_A − F_E(u) − B`.
    #[inline(always)]
    fn net(&self, y: &Y<L>) -> f64 {
        // The same arithmetic as `mode_at_rest(…, f_eff)` (the actuator force less the base
        // shear, then less the elastic force): a net force that rounds differently in the
        // two would let the breakaway test and the mode at rest disagree by an ulp at the
        // threshold, and the event loop toggle between them without time moving.
        let f_eff = self.force(y) - self.base_shear(y);
        f_eff - self.model.elastic_force_n(y[U])
    }

    /// The rates of the state in `mode`, into `dy`; returns the platen acceleration and the
    /// hydraulic rates.
    #[inline(always)]
    fn rates(&self, mode: Mode, y: &Y<L>, dy: &mut Y<L>) -> (f64, HydraulicRates) {
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
                let w = creep_speed_m_s(self.model, dir, y[U], f_eff, self.w_stiff)
                    .unwrap_or(self.w_stiff);
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
        let act = &self.sys.actuator;
        let dp = y[PA].max(0.0) - y[PB].max(0.0);
        dy[EL] = f64::from(act.count) * act.leakage_m3_s_per_pa * dp * dp;
        if let Some(spec) = self.spec {
            let (n, zd) = (self.n, Z + self.n);
            dy[Z..Z + n].copy_from_slice(&y[zd..zd + n]);
            let (zs, rest) = (&y[Z..Z + n], &y[zd..zd + n]);
            dy[SD] = spec.storey_accelerations(a, zs, rest, &mut dy[zd..zd + n]);
        }
        (a, hr)
    }

    /// The rate of the net force `Ṅ` from the rates `k` (stick: `u` fixed).
    fn net_rate(&self, k: &Y<L>) -> f64 {
        let act = &self.sys.actuator;
        let df = f64::from(act.count) * (act.cap_area_m2 * k[PA] - act.rod_area_m2 * k[PB]);
        match self.spec {
            Some(spec) => {
                let st = spec.storeys()[0];
                df + st.stiffness_n_per_m * k[Z] + st.damping_n_s_per_m * k[Z + self.n]
            }
            None => df,
        }
    }

    /// The current mode's event function: positive until the mode ends.
    fn event_g(&self, y: &Y<L>) -> f64 {
        match self.mode {
            Mode::Slip(dir) => dir.sign() * y[V],
            Mode::Stick => self.model.static_threshold_n(y[U]) - self.net(y).abs(),
            Mode::Creep(dir) => {
                let sn = dir.sign() * self.net(y);
                (sn - self.model.static_threshold_n(y[U])).min(self.exit_level(dir, y[U]) - sn)
            }
        }
    }

    fn exit_level(&self, dir: Direction, u: f64) -> f64 {
        let s = dir.sign();
        self.model.static_threshold_n(u)
            + self.model.dissipative_excess_n(u, self.w_stiff)
            + s * self.model.velocity_inertial_force_n(u, s * self.w_stiff)
    }

    fn creep_velocity(&self, dir: Direction, y: &Y<L>) -> f64 {
        let f_eff = self.force(y) - self.base_shear(y);
        let w = creep_speed_m_s(self.model, dir, y[U], f_eff, self.w_stiff).unwrap_or(self.w_stiff);
        dir.sign() * w
    }

    fn enter(&mut self, mode: Mode) {
        self.mode = mode;
        if let Mode::Creep(dir) = mode {
            self.w_stiff = stiff_speed_m_s(self.model, self.y[U], self.h);
            let y = self.y;
            self.y[V] = self.creep_velocity(dir, &y);
        }
        let (y, mut k) = (self.y, [0.0; L]);
        self.a = self.rates(mode, &y, &mut k).0;
        self.k = k;
        self.stats.run.rhs_evaluations += 1;
    }

    // ---- one-step maps -------------------------------------------------------------------

    /// One RK4 step of `dt` seconds from `y` with rates `k1`: the end state and the smallest
    /// stage speed along the slip direction.
    fn rk4(&mut self, dt: f64, y: &Y<L>, k1: &Y<L>) -> (Y<L>, f64) {
        let mode = self.mode;
        let combine = |base: &Y<L>, k: &Y<L>, c: f64| {
            let mut out = *base;
            for i in 0..L {
                out[i] += c * k[i];
            }
            out
        };
        let (mut k2, mut k3, mut k4) = ([0.0; L], [0.0; L], [0.0; L]);
        let y2 = combine(y, k1, 0.5 * dt);
        self.rates(mode, &y2, &mut k2);
        let y3 = combine(y, &k2, 0.5 * dt);
        self.rates(mode, &y3, &mut k3);
        let y4 = combine(y, &k3, dt);
        self.rates(mode, &y4, &mut k4);
        self.stats.run.rhs_evaluations += 3;
        let h6 = dt / 6.0;
        let mut y1 = *y;
        for i in 0..L {
            y1[i] += h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        let stage_min = match mode {
            Mode::Slip(dir) => {
                let d = dir.sign();
                (d * y2[V]).min(d * y3[V]).min(d * y4[V])
            }
            _ => f64::INFINITY,
        };
        (y1, stage_min)
    }

    /// Error scale of each state for the adaptive step: metres for the motion and the
    /// storeys, the supply pressure for the pressures, full opening for the spool, the bank's
    /// volume for its oil; the energy integrals are quadratures and not controlled.
    fn scale(&self, i: usize, y0: f64, y1: f64, rtol: f64, atol: f64) -> f64 {
        let m = y0.abs().max(y1.abs());
        let unit = match i {
            PA | PB => self.sys.supply_pressure_pa * 1e3,
            XV => 1e3,
            XR => 1e3 * std::f64::consts::TAU * self.sys.servo_valve.natural_frequency_hz,
            OIL => match &self.sys.supply {
                Supply::Accumulator(acc) => acc.volume_m3,
                Supply::Constant => 1.0,
            },
            PS => self.sys.supply_pressure_pa * 1e3,
            V => 1.0,
            W | DI | SD | EH | EL => return f64::INFINITY,
            _ => 1.0,
        };
        atol * unit + rtol * m
    }

    /// Adaptive Dormand–Prince 5(4) over `dt` from `y` with rates `k1`: the end state and
    /// the smallest speed along the slip direction at its stages.
    fn dopri5(&mut self, dt: f64, y: &Y<L>, k1: &Y<L>, rtol: f64, atol: f64) -> (Y<L>, f64) {
        const C: [f64; 6] = [0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
        const A: [[f64; 6]; 6] = [
            [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
            [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
            [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
            [
                19372.0 / 6561.0,
                -25360.0 / 2187.0,
                64448.0 / 6561.0,
                -212.0 / 729.0,
                0.0,
                0.0,
            ],
            [
                9017.0 / 3168.0,
                -355.0 / 33.0,
                46732.0 / 5247.0,
                49.0 / 176.0,
                -5103.0 / 18656.0,
                0.0,
            ],
            [
                35.0 / 384.0,
                0.0,
                500.0 / 1113.0,
                125.0 / 192.0,
                -2187.0 / 6784.0,
                11.0 / 84.0,
            ],
        ];
        const E: [f64; 7] = [
            71.0 / 57600.0,
            0.0,
            -71.0 / 16695.0,
            71.0 / 1920.0,
            -17253.0 / 339200.0,
            22.0 / 525.0,
            -1.0 / 40.0,
        ];
        let _ = C;
        let mode = self.mode;
        let (mut yc, mut kc) = (*y, *k1);
        let mut done = 0.0;
        let mut stage_min = f64::INFINITY;
        let mut hs = self.h_dopri.min(dt);
        let mut guard = 0u32;
        while done < dt {
            guard += 1;
            let last = dt - done <= hs * (1.0 + 1e-12);
            let step = if last { dt - done } else { hs };
            let mut ks = [[0.0; L]; 7];
            ks[0] = kc;
            let mut ys = [yc; 6];
            for s in 0..6 {
                let mut yi = yc;
                for i in 0..L {
                    let mut acc = 0.0;
                    for (j, kj) in ks.iter().enumerate().take(s + 1) {
                        acc += A[s][j] * kj[i];
                    }
                    yi[i] += step * acc;
                }
                ys[s] = yi;
                let mut kn = [0.0; L];
                self.rates(mode, &yi, &mut kn);
                ks[s + 1] = kn;
            }
            self.stats.run.rhs_evaluations += 6;
            let y_new = ys[5];
            let mut err: f64 = 0.0;
            for i in 0..L {
                let mut e = 0.0;
                for (j, kj) in ks.iter().enumerate() {
                    e += E[j] * kj[i];
                }
                let sc = self.scale(i, yc[i], y_new[i], rtol, atol);
                err = err.max((step * e / sc).abs());
            }
            let factor = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
            };
            // NaN counts as not accurate.
            let accurate = err <= 1.0;
            if !accurate {
                let underflow = step <= 1e-14 * dt.max(1e-9);
                if underflow || guard > MAX_STEPS {
                    // Dopri5 gives up: the piece ends where it got to and the run stops there
                    // with the failure (`Loop::segment`).
                    let reason = if underflow {
                        AdaptiveFailure::StepSizeUnderflow
                    } else {
                        AdaptiveFailure::TooManySteps { steps: MAX_STEPS }
                    };
                    self.gave_up.get_or_insert((self.t + done, reason));
                    return (yc, stage_min);
                }
            }
            if accurate {
                if let Mode::Slip(dir) = mode {
                    let d = dir.sign();
                    for yi in &ys {
                        stage_min = stage_min.min(d * yi[V]);
                    }
                }
                done += step;
                yc = y_new;
                kc = ks[6];
                self.stats.run.accepted_steps += 1;
                if !last {
                    hs = (step * factor).min(self.h);
                    self.h_dopri = hs;
                }
                if last {
                    break;
                }
            } else {
                self.stats.run.rejected_steps += 1;
                hs = step * factor;
            }
        }
        (yc, stage_min)
    }

    /// The current mode's state over `x` seconds from the current state, as the method maps
    /// it (RK4 graded by `grading`); with the smallest stage speed.
    fn piece(&mut self, x: f64, grading: Grading) -> (Y<L>, f64) {
        let (y, k) = (self.y, self.k);
        match self.method {
            LoopMethod::Dopri5 { rtol, atol, .. } => self.dopri5(x, &y, &k, rtol, atol),
            LoopMethod::Rk4 { .. } => {
                let (mut y, mut k) = (y, k);
                let mut stage_min = f64::INFINITY;
                for (i, &p) in grading.pieces().iter().enumerate() {
                    if i > 0 {
                        self.rates(self.mode, &y, &mut k);
                        self.stats.run.rhs_evaluations += 1;
                    }
                    let (y1, m) = self.rk4(p * x, &y, &k);
                    y = y1;
                    stage_min = stage_min.min(m);
                }
                (y, stage_min)
            }
        }
    }

    // ---- event logic ---------------------------------------------------------------------

    /// Whether the event function may dip to zero inside a piece of `x` seconds to `y1`
    /// (rates `k1`, platen acceleration `a1`).
    fn dips(&self, x: f64, y1: &Y<L>, k1: &Y<L>, a1: f64) -> bool {
        match self.mode {
            Mode::Slip(dir) => {
                let d = dir.sign();
                dip_to_zero(d * self.y[V], d * y1[V], d * self.a * x, d * a1 * x).is_some()
            }
            Mode::Stick => {
                let fs = self.model.static_threshold_n(self.y[U]);
                let (n0, n1) = (self.net(&self.y), self.net(y1));
                let (d0, d1) = (self.net_rate(&self.k) * x, self.net_rate(k1) * x);
                dip_to_zero(fs - n0, fs - n1, -d0, -d1).is_some()
                    || dip_to_zero(fs + n0, fs + n1, d0, d1).is_some()
            }
            Mode::Creep(_) => false,
        }
    }

    /// Integrates the current segment of `span` seconds (no cut inside it), handling every
    /// event.
    fn segment(&mut self, span: f64) -> Result<()> {
        let mut tau = 0.0;
        let mut events = 0u32;
        while tau < span {
            let at = self.advance(span - tau)?;
            if let Some((t_s, reason)) = self.gave_up.take() {
                return Err(IntegrateError::failed(t_s, Failure::AdaptiveFailed(reason)));
            }
            tau += at;
            self.t += at;
            events += 1;
            if events > MAX_EVENTS_PER_STEP {
                let stalled = Failure::EventLoopStalled { events };
                return Err(IntegrateError::failed(self.t, stalled));
            }
        }
        Ok(())
    }

    /// Advances in the current mode over at most `rest` seconds, to the end or to the mode's
    /// next event; returns the time advanced.
    fn advance(&mut self, rest: f64) -> Result<f64> {
        let slip = matches!(self.mode, Mode::Slip(_));
        let from_rest = slip && self.y[V] == 0.0;
        if let (Mode::Slip(dir), true) = (self.mode, from_rest) {
            let w_stiff = stiff_speed_m_s(self.model, self.y[U], self.h);
            let f_eff = self.force(&self.y) - self.base_shear(&self.y);
            if creep_speed_m_s(self.model, dir, self.y[U], f_eff, w_stiff).is_some() {
                self.enter(Mode::Creep(dir));
                return Ok(0.0);
            }
        }
        let (try_grading, event_grading) = match (slip, from_rest) {
            (true, true) => (Grading::Start, Grading::Both),
            (true, false) => (Grading::Single, Grading::End),
            _ => (Grading::Single, Grading::Single),
        };
        let mut len = rest;
        for _ in 0..=MAX_HALVINGS {
            let (y1, stage_min) = self.piece(len, try_grading);
            if !y1.iter().all(|x| x.is_finite()) {
                return Err(self.non_finite());
            }
            let (v_a, v_b) = self.sys.chamber_volumes_m3(y1[U]);
            if v_a <= 0.0 || v_b <= 0.0 {
                let cause = Failure::EndStop { u_m: y1[U] };
                return Err(IntegrateError::failed(self.t + len, cause));
            }
            let g1 = self.event_g(&y1);
            if g1 > 0.0 && stage_min > 0.0 {
                let mut k1 = [0.0; L];
                let (a1, _) = self.rates(self.mode, &y1, &mut k1);
                self.stats.run.rhs_evaluations += 1;
                if !self.dips(len, &y1, &k1, a1) {
                    if self.mode == Mode::Stick {
                        self.stats.run.stick_time_s += len;
                    }
                    self.commit_with(y1, k1, a1, self.t + len);
                    return Ok(len);
                }
            } else if g1 <= 0.0 {
                let (y2, g2) = if event_grading == try_grading {
                    (y1, g1)
                } else {
                    let (y2, _) = self.piece(len, event_grading);
                    (y2, self.event_g(&y2))
                };
                if g2 <= 0.0 {
                    let g0 = self.event_g(&self.y);
                    let tolerance = 4.0 * f64::EPSILON * len.max(self.h);
                    let Ok(found) = locate_zero_velocity(len, g0, (y2, g2), tolerance, |x| {
                        self.stats.run.root_iterations += 1;
                        let (y, _) = self.piece(x, event_grading);
                        let g = self.event_g(&y);
                        Ok::<_, Infallible>((y, g))
                    });
                    let (x, y_event) = found.unwrap_or((0.0, self.y));
                    return Ok(self.event(x, rest, y_event));
                }
            }
            len *= 0.5;
        }
        let y = self.y;
        Ok(self.event(0.0, rest, y))
    }

    /// Accepts `y` as the state at time `t` (pressures held at the cavitation floor).
    fn commit(&mut self, y: Y<L>, t: f64) {
        let mut k = [0.0; L];
        let (a, _) = self.rates(self.mode, &y, &mut k);
        self.stats.run.rhs_evaluations += 1;
        self.commit_with(y, k, a, t);
    }

    /// [`Loop::commit`] with the rates `k` and acceleration `a` at `y` already known (they
    /// are recomputed only if a pressure is held at the floor).
    fn commit_with(&mut self, mut y: Y<L>, mut k: Y<L>, mut a: f64, t: f64) {
        if y[PA] < 0.0 || y[PB] < 0.0 {
            for i in [PA, PB] {
                y[i] = y[i].max(0.0);
            }
            self.stats.cavitation_at_s.get_or_insert(t);
            a = self.rates(self.mode, &y, &mut k).0;
            self.stats.run.rhs_evaluations += 1;
        }
        (self.y, self.k, self.a) = (y, k, a);
        self.stats.min_supply_pressure_pa = self.stats.min_supply_pressure_pa.min(y[PS]);
    }

    /// The reset at the current mode's event, located `x` seconds on (at most `rest`).
    fn event(&mut self, x: f64, rest: f64, y_event: Y<L>) -> f64 {
        let mut at = x;
        if rest - at < 1e-12 * self.h {
            at = rest;
        }
        match self.mode {
            Mode::Slip(from) => {
                let mut y = y_event;
                y[V] = 0.0;
                self.commit(y, self.t + at);
                let f_eff = self.force(&self.y) - self.base_shear(&self.y);
                let (mode, kind) = arrive_at_rest(self.model, self.y[U], f_eff, from);
                self.enter(mode);
                if let Some(kind) = kind {
                    self.stats.run.record(kind);
                }
                at
            }
            Mode::Stick => {
                let u = self.y[U];
                let fs = self.model.static_threshold_n(u);
                let x_b = just_past(x, rest, |x| {
                    let (y, _) = self.piece(x, Grading::Single);
                    self.net(&y).abs() > fs
                });
                let y = if x_b == x {
                    y_event
                } else {
                    self.piece(x_b, Grading::Single).0
                };
                self.stats.run.stick_time_s += x_b;
                self.commit(y, self.t + x_b);
                let net = self.net(&self.y);
                if net.abs() <= fs {
                    self.enter(Mode::Stick);
                    return x_b.max(f64::MIN_POSITIVE).min(rest);
                }
                self.stats.run.record(EventKind::Breakaway);
                self.enter(Mode::Slip(Direction::of_sign(net)));
                x_b
            }
            Mode::Creep(dir) => {
                let start = (self.y, self.k);
                self.commit(y_event, self.t + at);
                let sn = dir.sign() * self.net(&self.y);
                let fs = self.model.static_threshold_n(self.y[U]);
                if sn - fs <= self.exit_level(dir, self.y[U]) - sn {
                    self.y[V] = 0.0;
                    let f_eff = self.force(&self.y) - self.base_shear(&self.y);
                    let mut mode = mode_at_rest(self.model, self.y[U], f_eff);
                    if mode == Mode::Slip(dir) && x <= MIN_PROGRESS * self.h {
                        // The stop rounded onto the start of the advance, where the net force
                        // at rest is a hair along the motion: creeping on from here would
                        // locate the same stop again without moving time. Step just past it,
                        // to where the net force at rest no longer drives the creep on (see
                        // `crate::creep`, whose passes do the same).
                        at = self.creep_just_past(x, rest, start, dir);
                        let f_eff = self.force(&self.y) - self.base_shear(&self.y);
                        mode = mode_at_rest(self.model, self.y[U], f_eff);
                    }
                    match mode {
                        Mode::Slip(d) if d == dir => self.enter(Mode::Creep(dir)),
                        Mode::Stick => {
                            self.stats.run.record(EventKind::Stop);
                            self.enter(Mode::Stick);
                        }
                        other => {
                            self.stats.run.record(EventKind::Reversal);
                            self.enter(other);
                        }
                    }
                } else {
                    let y = self.y;
                    let v = self.creep_velocity(dir, &y);
                    self.y[V] = if v == 0.0 {
                        dir.sign() * f64::MIN_POSITIVE
                    } else {
                        v
                    };
                    self.enter(Mode::Slip(dir));
                }
                at
            }
        }
    }

    /// A creep stop located `x ≤` [`MIN_PROGRESS`]`·h` seconds into the advance (from the
    /// state and rates `start`) where the net force at rest still drives the creep on in
    /// `dir`: creeps from `start` to the first of `x + 4ε, x + 8ε, …` s ([`just_past`]) where
    /// it does not, or to `rest`, and commits that state at rest (`v = 0`). Returns where
    /// (seconds into the advance).
    fn creep_just_past(&mut self, x: f64, rest: f64, start: (Y<L>, Y<L>), dir: Direction) -> f64 {
        let stopped = (self.y, self.k, self.a);
        (self.y, self.k) = start;
        let x_b = just_past(x, rest, |x| {
            let (y, _) = self.piece(x, Grading::Single);
            let f_eff = self.force(&y) - self.base_shear(&y);
            mode_at_rest(self.model, y[U], f_eff) != Mode::Slip(dir)
        });
        if x_b > x {
            let (y, _) = self.piece(x_b, Grading::Single);
            self.commit(y, self.t + x_b);
        } else {
            (self.y, self.k, self.a) = stopped;
        }
        self.y[V] = 0.0;
        if rest - x_b < 1e-12 * self.h {
            rest
        } else {
            x_b
        }
    }

    fn non_finite(&self) -> IntegrateError {
        let cause = Failure::NonFiniteState {
            u_m: self.y[U],
            v_m_s: self.y[V],
        };
        IntegrateError::failed(self.t, cause)
    }

    // ---- the loop around the steps -------------------------------------------------------

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
        let (r, rv, ra) = self.command_at(self.t);
        let input = ControllerInput {
            command_u_m: r,
            command_v_m_s: rv,
            command_a_m_s2: ra,
            u_m: self.y[U],
            v_m_s: self.y[V],
            a_m_s2: self.a,
            delta_p_pa: self.y[PA].max(0.0) - self.y[PB].max(0.0),
        };
        let d = self.sys.controller.update(&mut self.controller, &input);
        self.stats.controller_samples += 1;
        self.queue
            .push_back((self.t + self.sys.servo_valve.delay_s, d));
    }

    /// Applies every delayed drive that has arrived by the current time (to `slack`).
    fn apply_arrived(&mut self, slack: f64) -> bool {
        let mut changed = false;
        while let Some(&(t, d)) = self.queue.front() {
            if t <= self.t + slack {
                self.input = d;
                self.queue.pop_front();
                changed = true;
            } else {
                break;
            }
        }
        if changed {
            let mode = self.mode;
            self.enter(mode);
        }
        changed
    }

    fn emit<S: SampleSink>(&mut self, j: usize, sink: &mut S) {
        let t_s = self.command.t_s()[j];
        let f = self.force(&self.y);
        let bs = self.base_shear(&self.y);
        let kin = Kin {
            u: self.y[U],
            v: self.y[V],
            work: self.y[W],
            dissipated: self.y[DI],
        };
        let mut sample = sample_at(
            self.model,
            j,
            t_s,
            f - bs,
            kin,
            self.a,
            self.mode == Mode::Stick,
        );
        sample.terms.actuator_n = f;
        if let Some(_spec) = self.spec {
            let mut sp = SpecimenSample {
                base_shear_n: bs,
                storeys: self.n,
                u_m: [0.0; NS],
                a_m_s2: [0.0; NS],
                drift_m: [0.0; NS],
            };
            let mut below = 0.0;
            for i in 0..self.n {
                sp.u_m[i] = self.y[Z + i];
                sp.a_m_s2[i] = self.a + self.k[Z + self.n + i];
                sp.drift_m[i] = self.y[Z + i] - below;
                below = self.y[Z + i];
            }
            sample.specimen = Some(sp);
        }
        let ps = self.y[PS];
        let (p_a, p_b) = (self.y[PA].max(0.0), self.y[PB].max(0.0));
        let (q_a, _) = self
            .sys
            .valve_flows_with(&self.consts, self.y[XV], p_a, p_b, ps);
        sample.system = Some(SystemSample {
            command_u_m: self.command.u_m()[j],
            drive: self.controller.drive,
            spool_opening: self.y[XV].clamp(-1.0, 1.0),
            delta_p_pa: p_a - p_b,
            p_a_pa: p_a,
            p_b_pa: p_b,
            flow_m3_s: f64::from(self.sys.actuator.count) * q_a,
            supply_pressure_pa: ps,
        });
        sink.accept(&sample);
    }

    /// Runs the grid: controller samples every `k` steps, each step cut where the valve's
    /// input changes or an output sample falls.
    fn run<S: SampleSink>(&mut self, k: u32, samples: usize, sink: &mut S) -> Result<()> {
        let ts = self.command.t_s();
        let t_end = ts[samples - 1];
        let slack = 1e-9 * self.h;
        let mut j = 0usize;
        let mut n: u64 = 0;
        let k = u64::from(k);
        loop {
            // At the grid point t₀ + n·h.
            self.t = self.t0 + n as f64 * self.h;
            if n % k == 0 {
                self.tick();
            }
            self.apply_arrived(slack);
            while j < samples && ts[j] <= self.t + slack {
                self.emit(j, sink);
                j += 1;
            }
            if j >= samples || self.t > t_end + slack {
                break;
            }
            let t_next = self.t0 + (n + 1) as f64 * self.h;
            // Cuts inside (t, t_next): arrivals of delayed drives and output samples.
            loop {
                let arrival = self.queue.front().map_or(f64::INFINITY, |&(t, _)| t);
                let sample = if j < samples { ts[j] } else { f64::INFINITY };
                let cut = arrival.min(sample);
                if cut >= t_next - slack {
                    break;
                }
                let span = cut - self.t;
                if span > 0.0 {
                    self.segment(span)?;
                }
                self.t = cut;
                self.apply_arrived(slack);
                while j < samples && ts[j] <= self.t + slack {
                    self.emit(j, sink);
                    j += 1;
                }
            }
            let span = t_next - self.t;
            if span > 0.0 {
                self.segment(span)?;
            }
            if self.controller.saturated {
                self.stats.saturated_time_s += self.h;
            }
            n += 1;
            self.stats.run.steps += 1;
        }
        self.stats.run.stop = StopReason::Finished { t_s: t_end };
        Ok(())
    }

    fn finish(mut self) -> LoopStats {
        let y = self.y;
        self.stats
            .run
            .energy
            .close(self.model, y[U], y[V], y[W], y[DI]);
        self.stats.run.energy.specimen_end_j = self.specimen_energy(&y);
        self.stats.run.energy.specimen_dissipated_j = y[SD];
        if matches!(self.method, LoopMethod::Rk4 { .. }) {
            self.stats.run.accepted_steps = self.stats.run.steps;
        }
        self.stats.hydraulic_energy_j = y[EH];
        self.stats.leakage_energy_j = y[EL];
        self.stats
    }
}
