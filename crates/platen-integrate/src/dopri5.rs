//! Adaptive forward runs with ode_solvers' Dopri5 (Dormand–Prince 5(4)), exact about
//! stick-slip.
//!
//! # Method
//!
//! ode_solvers' Dopri5 has no event location (upstream issue #25), so the run is split into
//! segments on which the right-hand side is smooth, and the events are handled here:
//!
//! * every sample interval of the force record is a segment of its own (the force is linear
//!   inside it and its derivative jumps at samples), so the step-size controller never has to
//!   reject steps at a kink; the step size carries over from one segment to the next;
//! * in **slip**, the smooth right-hand side with the friction direction fixed is integrated
//!   with `solout` stopping after the first accepted step that ends with the velocity on the
//!   other side of zero, or whose cubic Hermite interpolant (the states and accelerations at
//!   both ends) dips to zero inside it. A dip is checked by integrating to it: if the platen is
//!   across zero there, the first crossing lies before it; otherwise the run resumes after the
//!   step. The crossing is located by a bracketing root-finder (Illinois) on the length of a
//!   Dopri5 integration from the start of that step, with the same tolerances; there `v` is set
//!   to exactly zero and the net force decides stick, reverse or creep on;
//! * in **stick**, the breakaway time is solved in closed form (the force is linear within
//!   the segment), exactly as in the fixed-step RK4;
//! * in **creep**, the quasi-static creep of [`crate::creep`], with the stiff speed of a step
//!   of one sample interval.
//!
//! The modes, the root finder, the stick decision and the breakaway are those of
//! [`crate::event`], shared with the RK4.
//!
//! The state handed to Dopri5 is `(u, v, W/E₀, E_D/E₀)`: the actuator work and the dissipated
//! energy ride along, scaled by `E₀ = M(0)·(1 m/s)²` so that their error weights match the
//! motion's, which gives the energy balance of the run.

use ode_solvers::dop_shared::{IntegrationError, OutputType, System};
use ode_solvers::{Dopri5, Vector4};
use platen_model::PlatenModel;

use std::cell::Cell;

use crate::creep::{creep, creep_speed_m_s, stiff_speed_m_s, CreepEnd};
use crate::error::{IntegrateError, Result};
use crate::event::{
    arrive_at_rest, breakaway, dip_to_zero, just_past, locate_zero_velocity, Direction, EventKind,
    Mode, StepStop, MAX_EVENTS_PER_STEP,
};
use crate::output::SampleSink;
use crate::record::ForceRecord;
use crate::run::{check_run, sample_at, EnergyBalance, Kin, RunStats, State};
use crate::stop::{AdaptiveFailure, Failure, StopReason};

/// Most Dopri5 steps in one integration call before it gives up
/// ([`AdaptiveFailure::TooManySteps`]); the closed loop's Dopri5 allows as many tries per piece.
pub(crate) const MAX_STEPS: u32 = 100_000;

/// Settings of the adaptive integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dopri5Settings {
    rtol: f64,
    atol: f64,
}

impl Dopri5Settings {
    /// Relative and absolute tolerances of the step-size controller (per component of the
    /// state `(u [m], v [m/s], …)`).
    ///
    /// # Errors
    /// [`IntegrateError::InvalidTolerance`] unless both are finite and `> 0` (and `rtol < 1`).
    pub fn new(rtol: f64, atol: f64) -> Result<Self> {
        if !(rtol.is_finite() && rtol > 0.0 && rtol < 1.0) {
            return Err(IntegrateError::InvalidTolerance {
                name: "rtol",
                value: rtol,
            });
        }
        if !(atol.is_finite() && atol > 0.0) {
            return Err(IntegrateError::InvalidTolerance {
                name: "atol",
                value: atol,
            });
        }
        Ok(Self { rtol, atol })
    }

    /// Relative tolerance.
    pub fn rtol(self) -> f64 {
        self.rtol
    }

    /// Absolute tolerance.
    pub fn atol(self) -> f64 {
        self.atol
    }
}

/// Why an integration in slip stopped before the end of its span: the last accepted step
/// ended across `v = 0`, or its cubic Hermite interpolant (from the states and accelerations
/// at both ends) dips to zero at the fraction `θ` of the step ([`dip_to_zero`]): two
/// crossings may lie inside it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Trigger {
    Crossed,
    Dip(f64),
}

/// Slip dynamics on one segment: local time `x` (s) from the segment's sample, force
/// `f0 + slope·x`.
struct SlipSystem<'a, M> {
    model: &'a M,
    dir: f64,
    f0: f64,
    slope: f64,
    inv_e0: f64,
    /// Stop after an accepted step that crosses or may cross v = 0 (not while locating the
    /// crossing), and say why here.
    watch: Option<&'a Cell<Option<Trigger>>>,
    /// Time, speed `dir·v` and its rate `dir·a` at the end of the last accepted step.
    last: (f64, f64, f64),
}

impl<M: PlatenModel> System<f64, Vector4<f64>> for SlipSystem<'_, M> {
    #[inline]
    fn system(&self, x: f64, y: &Vector4<f64>, dy: &mut Vector4<f64>) {
        let f = self.f0 + self.slope * x;
        let r = self.model.slip_rates(f, y[0], y[1], self.dir);
        dy[0] = y[1];
        dy[1] = r.a_m_s2;
        dy[2] = f * y[1] * self.inv_e0;
        dy[3] = r.dissipated_power_w * self.inv_e0;
    }

    fn solout(&mut self, x: f64, y: &Vector4<f64>, dy: &Vector4<f64>) -> bool {
        let Some(watch) = self.watch else {
            return false;
        };
        let (x0, w0, r0) = self.last;
        let (w1, r1) = (self.dir * y[1], self.dir * dy[1]);
        self.last = (x, w1, r1);
        let h = x - x0;
        let trigger = if w1 <= 0.0 {
            Some(Trigger::Crossed)
        } else {
            dip_to_zero(w0, w1, r0 * h, r1 * h).map(Trigger::Dip)
        };
        watch.set(trigger);
        trigger.is_some()
    }
}

/// Runs the model forward under `record` from `initial` with Dopri5 and exact stick-slip,
/// delivering `samples` output samples (the record's first `samples` sample times) to `sink`.
///
/// # Errors
/// As [`crate::forward_rk4`], plus [`IntegrateError::AdaptiveFailed`] when Dopri5 gives up
/// (step-size underflow, too many steps), with the time.
pub fn forward_dopri5<M: PlatenModel, S: SampleSink>(
    model: &M,
    record: &ForceRecord,
    settings: Dopri5Settings,
    initial: State,
    samples: usize,
    sink: &mut S,
) -> Result<RunStats> {
    check_run(record, initial, samples)?;
    let force = record.force_n();
    let times = record.t_s();
    let dt = record.dt_s();
    let e0 = model.mass_kg(0.0);
    let mut run = AdaptiveRun {
        model,
        settings,
        e0,
        y: Kin::start(initial),
        mode: Mode::Stick,
        h: 0.0,
        w_stiff: 0.0,
        stats: RunStats::default(),
    };
    run.mode = Mode::initial(model, initial.u_m, initial.v_m_s, force[0]);
    run.stats.energy = EnergyBalance::start(model, initial.u_m, initial.v_m_s);
    if samples == 0 {
        run.stats.stop = StopReason::Finished { t_s: times[0] };
        return Ok(run.stats);
    }
    sink.accept(&sample_at(
        model,
        0,
        times[0],
        force[0],
        run.y,
        run.acceleration(force[0]),
        run.mode == Mode::Stick,
    ));
    for j in 0..samples - 1 {
        run.segment(times[j], dt, force[j], force[j + 1])?;
        let f = force[j + 1];
        sink.accept(&sample_at(
            model,
            j + 1,
            times[j + 1],
            f,
            run.y,
            run.acceleration(f),
            run.mode == Mode::Stick,
        ));
    }
    run.stats
        .energy
        .close(model, run.y.u, run.y.v, run.y.work, run.y.dissipated);
    run.stats.steps = run.stats.accepted_steps + run.stats.rejected_steps;
    run.stats.stop = StopReason::Finished {
        t_s: times[samples - 1],
    };
    Ok(run.stats)
}

struct AdaptiveRun<'a, M> {
    model: &'a M,
    settings: Dopri5Settings,
    e0: f64,
    y: Kin,
    mode: Mode,
    /// Step size carried from one segment to the next (0: let Dopri5 choose).
    h: f64,
    /// The stiff speed of the current creep phase (see [`crate::creep`]), m/s.
    w_stiff: f64,
    stats: RunStats,
}

impl<M: PlatenModel> AdaptiveRun<'_, M> {
    fn acceleration(&mut self, f: f64) -> f64 {
        match self.mode {
            Mode::Stick | Mode::Creep(_) => 0.0,
            Mode::Slip(dir) => {
                self.stats.rhs_evaluations += 1;
                self.model
                    .slip_acceleration_m_s2(f, self.y.u, self.y.v, dir.sign())
            }
        }
    }

    /// Advances across one sample interval `[t0, t0 + dt]` with the force going linearly from
    /// `f0` to `f1`.
    fn segment(&mut self, t0: f64, dt: f64, f0: f64, f1: f64) -> Result<()> {
        let slope = (f1 - f0) / dt;
        let mut x = 0.0;
        let mut events = 0u32;
        while x < dt {
            events += 1;
            if events > MAX_EVENTS_PER_STEP {
                let stalled = Failure::EventLoopStalled { events };
                return Err(IntegrateError::failed(t0 + x, stalled));
            }
            let stop = match self.mode {
                Mode::Stick => self.stick(x, dt, f0, f1, slope),
                Mode::Slip(direction) => self.slip(direction, x, dt, f0, slope, t0)?,
                Mode::Creep(direction) => self.creep(direction, x, dt, f0, f1, slope, t0)?,
            };
            match stop {
                StepStop::Step => return Ok(()),
                StepStop::Moved { at } => x = at,
                StepStop::Event { at, kind } => {
                    x = at;
                    // A stop or reversal within rounding of the end ends the segment.
                    if kind != EventKind::Breakaway && dt - x < 1e-12 * dt {
                        return Ok(());
                    }
                }
            }
        }
        Ok(())
    }

    /// Switches to `mode` at the current state: a creep phase gets its stiff speed for steps
    /// of one sample interval `dt`.
    fn enter(&mut self, mode: Mode, dt: f64) {
        self.mode = mode;
        if let Mode::Creep(_) = mode {
            self.w_stiff = stiff_speed_m_s(self.model, self.y.u, dt);
        }
    }

    /// The stick part of [`AdaptiveRun::segment`] from local time `x`: friction holds to the
    /// end of the segment, or the platen breaks away ([`breakaway`]) and slips, from a point
    /// where `|N|` is above the threshold.
    fn stick(&mut self, x: f64, dt: f64, f0: f64, f1: f64, slope: f64) -> StepStop {
        let Some(b) = breakaway(self.model, self.y.u, f0 + slope * x, f1) else {
            self.stats.stick_time_s += dt - x;
            return StepStop::Step;
        };
        let elastic = self.model.elastic_force_n(self.y.u);
        let threshold = self.model.static_threshold_n(self.y.u);
        let sign = b.direction.sign();
        let xb = just_past(x + b.fraction * (dt - x), dt, |t| {
            sign * (f0 + slope * t - elastic) > threshold
        });
        self.stats.stick_time_s += xb - x;
        self.stats.record(EventKind::Breakaway);
        self.mode = Mode::Slip(b.direction);
        StepStop::Event {
            at: xb,
            kind: EventKind::Breakaway,
        }
    }

    /// The creep part of [`AdaptiveRun::segment`] from local time `x` ([`crate::creep`]).
    #[allow(clippy::too_many_arguments)]
    fn creep(
        &mut self,
        dir: Direction,
        x: f64,
        dt: f64,
        f0: f64,
        f1: f64,
        slope: f64,
        t0: f64,
    ) -> Result<StepStop> {
        let span_s = dt - x;
        let run = creep(
            self.model,
            dir,
            self.y,
            f0 + slope * x,
            f1,
            span_s,
            self.w_stiff,
        );
        self.stats.rhs_evaluations += run.evaluations;
        self.y = run.y;
        let at = if run.at_s >= span_s {
            dt
        } else {
            (x + run.at_s).min(dt)
        };
        self.check_finite(t0 + at)?;
        Ok(match run.end {
            CreepEnd::Continues if at >= dt => StepStop::Step,
            CreepEnd::Continues => StepStop::Moved { at },
            CreepEnd::Stops => {
                self.stats.record(EventKind::Stop);
                self.mode = Mode::Stick;
                StepStop::Event {
                    at,
                    kind: EventKind::Stop,
                }
            }
            CreepEnd::Slips => {
                self.mode = Mode::Slip(dir);
                StepStop::Moved { at }
            }
            CreepEnd::Reverses => {
                // Leave rest the other way from where the net force, as this segment
                // evaluates it, is beyond the threshold that way (creep's own time rounds).
                let (u, sign) = (self.y.u, dir.opposite().sign());
                let (elastic, threshold) = (
                    self.model.elastic_force_n(u),
                    self.model.static_threshold_n(u),
                );
                let at = just_past(at, dt, |t| sign * (f0 + slope * t - elastic) > threshold);
                let (mode, kind) = arrive_at_rest(self.model, u, f0 + slope * at, dir);
                self.enter(mode, dt);
                match kind {
                    Some(kind) => {
                        self.stats.record(kind);
                        StepStop::Event { at, kind }
                    }
                    None => StepStop::Moved { at },
                }
            }
        })
    }

    /// The slip part of [`AdaptiveRun::segment`] from local time `x`: Dopri5 to the end of the
    /// segment, or to the located `v = 0` crossing, where the reset is applied. A step whose
    /// Hermite interpolant dips to zero is checked at the dip: if the platen is across zero
    /// there, the first crossing is located inside it; otherwise the run resumes after it.
    fn slip(
        &mut self,
        direction: Direction,
        x: f64,
        dt: f64,
        f0: f64,
        slope: f64,
        t0: f64,
    ) -> Result<StepStop> {
        let dir = direction.sign();
        if self.y.v == 0.0 {
            // Leaving rest: if the creep speed stays below the stiff speed to the end of the
            // segment (the force is linear: its ends bound it), the explicit steps would only
            // overshoot; creep instead.
            let w_stiff = stiff_speed_m_s(self.model, self.y.u, dt);
            let creeps = [f0 + slope * x, f0 + slope * dt]
                .iter()
                .all(|&f| creep_speed_m_s(self.model, direction, self.y.u, f, w_stiff).is_some());
            if creeps {
                self.enter(Mode::Creep(direction), dt);
                return Ok(StepStop::Moved { at: x });
            }
        }
        let watch = Cell::new(None);
        let a0 = self.acceleration(f0 + slope * x);
        let sys = SlipSystem {
            model: self.model,
            dir,
            f0,
            slope,
            inv_e0: 1.0 / self.e0,
            watch: Some(&watch),
            last: (x, dir * self.y.v, dir * a0),
        };
        let (xs, ys) = self.integrate(sys, x, dt, self.h, t0)?;
        let n = xs.len();
        let (xa, ya) = (xs[n - 2], ys[n - 2]);
        let (xb, yb) = (xs[n - 1], ys[n - 1]);
        let end = match watch.get() {
            None => {
                self.y = self.unpack(yb);
                self.check_finite(t0 + dt)?;
                return Ok(StepStop::Step);
            }
            Some(Trigger::Crossed) => (xb, yb),
            Some(Trigger::Dip(theta)) => {
                let xm = xa + theta * (xb - xa);
                let ym = self.integrate_plain(dir, f0, slope, xa, ya, xm, t0)?;
                if dir * ym[1] > 0.0 {
                    // No crossing at the dip: resume after the step.
                    self.y = self.unpack(yb);
                    self.check_finite(t0 + xb)?;
                    return Ok(if xb >= dt {
                        StepStop::Step
                    } else {
                        StepStop::Moved { at: xb }
                    });
                }
                (xm, ym)
            }
        };
        let (xe, ye) = self.locate(dir, f0, slope, (xa, ya), end, t0)?;
        self.y = Kin {
            v: 0.0,
            ..self.unpack(ye)
        };
        self.check_finite(t0 + xe)?;
        let (mode, kind) = arrive_at_rest(self.model, self.y.u, f0 + slope * xe, direction);
        self.enter(mode, dt);
        Ok(match kind {
            Some(kind) => {
                self.stats.record(kind);
                StepStop::Event { at: xe, kind }
            }
            None => StepStop::Moved { at: xe },
        })
    }

    fn unpack(&self, y: Vector4<f64>) -> Kin {
        Kin {
            u: y[0],
            v: y[1],
            work: y[2] * self.e0,
            dissipated: y[3] * self.e0,
        }
    }

    fn pack(&self, y: Kin) -> Vector4<f64> {
        Vector4::new(y.u, y.v, y.work / self.e0, y.dissipated / self.e0)
    }

    fn check_finite(&self, t_s: f64) -> Result<()> {
        if self.y.u.is_finite() && self.y.v.is_finite() {
            Ok(())
        } else {
            let cause = Failure::NonFiniteState {
                u_m: self.y.u,
                v_m_s: self.y.v,
            };
            Err(IntegrateError::failed(t_s, cause))
        }
    }

    /// Integrates `sys` from local time `x0` (state: the current one) to `x1`. Returns the
    /// accepted steps' times and states and whether `solout` stopped at a crossing.
    fn integrate(
        &mut self,
        sys: SlipSystem<'_, M>,
        x0: f64,
        x1: f64,
        h0: f64,
        t0: f64,
    ) -> Result<(Vec<f64>, Vec<Vector4<f64>>)> {
        let y0 = self.pack(self.y);
        self.integrate_from(sys, x0, y0, x1, h0, t0)
    }

    #[allow(clippy::too_many_arguments)]
    fn integrate_from(
        &mut self,
        sys: SlipSystem<'_, M>,
        x0: f64,
        y0: Vector4<f64>,
        x1: f64,
        h0: f64,
        t0: f64,
    ) -> Result<(Vec<f64>, Vec<Vector4<f64>>)> {
        let span = x1 - x0;
        let h = if h0 > 0.0 { h0.min(span) } else { 0.0 };
        debug_assert!(h.is_finite());
        let mut solver = Dopri5::from_param(
            sys,
            x0,
            x1,
            span,
            y0,
            self.settings.rtol,
            self.settings.atol,
            0.9,
            0.04,
            0.2,
            10.0,
            span,
            h,
            MAX_STEPS,
            // Stiffness detection off: the only large eigenvalue-like behaviour is the
            // √|v| singularity at v = 0, which the events handle.
            u32::MAX,
            OutputType::Sparse,
        );
        let stats = solver.integrate().map_err(|e| {
            let (x, reason) = match e {
                IntegrationError::MaxNumStepReached { x, n_step } => {
                    (x, AdaptiveFailure::TooManySteps { steps: n_step })
                }
                IntegrationError::StepSizeUnderflow { x } => {
                    (x, AdaptiveFailure::StepSizeUnderflow)
                }
                IntegrationError::StiffnessDetected { x } => {
                    (x, AdaptiveFailure::StiffnessDetected)
                }
            };
            IntegrateError::failed(t0 + x, Failure::AdaptiveFailed(reason))
        })?;
        self.stats.rhs_evaluations += u64::from(stats.num_eval);
        self.stats.accepted_steps += u64::from(stats.accepted_steps);
        self.stats.rejected_steps += u64::from(stats.rejected_steps);
        let xs = solver.x_out().clone();
        let ys = solver.y_out().clone();
        let n = xs.len();
        // Carry a step size to the next segment: the second-to-last step (the last one is cut
        // to land on x1), or, when one step covered the whole segment without a rejection,
        // the whole next segment (the controller would have grown the step anyway).
        if n >= 3 {
            self.h = xs[n - 2] - xs[n - 3];
        } else if n == 2 {
            self.h = if stats.rejected_steps == 0 {
                f64::INFINITY
            } else {
                xs[1] - xs[0]
            };
        }
        Ok((xs, ys))
    }

    /// The state after a Dopri5 integration in slip `dir` from `(xa, ya)` to `xb`, with the
    /// run's tolerances and no stop on crossings.
    #[allow(clippy::too_many_arguments)]
    fn integrate_plain(
        &mut self,
        dir: f64,
        f0: f64,
        slope: f64,
        xa: f64,
        ya: Vector4<f64>,
        xb: f64,
        t0: f64,
    ) -> Result<Vector4<f64>> {
        let sys = SlipSystem {
            model: self.model,
            dir,
            f0,
            slope,
            inv_e0: 1.0 / self.e0,
            watch: None,
            last: (xa, 0.0, 0.0),
        };
        let (_, ys) = self.integrate_from(sys, xa, ya, xb, xb - xa, t0)?;
        Ok(ys[ys.len() - 1])
    }

    /// Locates the zero of `dir·v` between `a = (xa, ya)`, where the platen slips in `dir`,
    /// and `b = (xb, yb)`, where it is across zero, by [`locate_zero_velocity`] on the length
    /// of a Dopri5 integration from `a`, with the run's tolerances. Returns `a` if the platen
    /// started at rest and cannot move in `dir` at all: it stays where it is.
    fn locate(
        &mut self,
        dir: f64,
        f0: f64,
        slope: f64,
        (xa, ya): (f64, Vector4<f64>),
        (xb, yb): (f64, Vector4<f64>),
        t0: f64,
    ) -> Result<(f64, Vector4<f64>)> {
        let span = xb - xa;
        let tolerance = 4.0 * f64::EPSILON * span.max(xb.abs());
        let found = locate_zero_velocity(span, dir * ya[1], (yb, dir * yb[1]), tolerance, |len| {
            self.stats.root_iterations += 1;
            let y = self.integrate_plain(dir, f0, slope, xa, ya, xa + len, t0)?;
            Ok::<_, IntegrateError>((y, dir * y[1]))
        })?;
        Ok(found.map_or((xa, ya), |(len, y)| (xa + len, y)))
    }
}
