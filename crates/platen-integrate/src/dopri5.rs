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
//!   other side of zero. The crossing is then located by a bracketing root-finder (Illinois)
//!   on the length of a Dopri5 integration from the start of that step, with the same
//!   tolerances; there `v` is set to exactly zero and the net force decides stick or reverse;
//! * in **stick**, the breakaway time is solved in closed form (the force is linear within
//!   the segment), exactly as in the fixed-step RK4.
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

use crate::error::{IntegrateError, Result};
use crate::event::{
    arrive_at_rest, breakaway, locate_zero_velocity, EventKind, Mode, StepStop, MAX_EVENTS_PER_STEP,
};
use crate::output::SampleSink;
use crate::record::ForceRecord;
use crate::run::{check_run, sample_at, EnergyBalance, Kin, RunStats, State};
use crate::stop::{AdaptiveFailure, Failure, StopReason};

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

/// Slip dynamics on one segment: local time `x` (s) from the segment's sample, force
/// `f0 + slope·x`.
struct SlipSystem<'a, M> {
    model: &'a M,
    dir: f64,
    f0: f64,
    slope: f64,
    inv_e0: f64,
    /// Stop after an accepted step that crosses v = 0 (not while locating the crossing).
    stop_on_crossing: bool,
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

    fn solout(&mut self, _x: f64, y: &Vector4<f64>, _dy: &Vector4<f64>) -> bool {
        self.stop_on_crossing && self.dir * y[1] <= 0.0
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
    stats: RunStats,
}

impl<M: PlatenModel> AdaptiveRun<'_, M> {
    fn acceleration(&mut self, f: f64) -> f64 {
        match self.mode {
            Mode::Stick => 0.0,
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
                Mode::Slip(direction) => self.slip(direction.sign(), x, dt, f0, slope, t0)?,
            };
            match stop {
                StepStop::Step => return Ok(()),
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

    /// The stick part of [`AdaptiveRun::segment`] from local time `x`: friction holds to the
    /// end of the segment, or the platen breaks away ([`breakaway`]) and slips.
    fn stick(&mut self, x: f64, dt: f64, f0: f64, f1: f64, slope: f64) -> StepStop {
        let Some(b) = breakaway(self.model, self.y.u, f0 + slope * x, f1) else {
            self.stats.stick_time_s += dt - x;
            return StepStop::Step;
        };
        let xb = x + b.fraction * (dt - x);
        self.stats.stick_time_s += xb - x;
        self.stats.record(EventKind::Breakaway);
        self.mode = Mode::Slip(b.direction);
        StepStop::Event {
            at: xb,
            kind: EventKind::Breakaway,
        }
    }

    /// The slip part of [`AdaptiveRun::segment`] from local time `x`: Dopri5 to the end of the
    /// segment, or to the located `v = 0` crossing, where the reset is applied.
    /// `dir` is the direction of slip, `±1.0`.
    fn slip(
        &mut self,
        dir: f64,
        x: f64,
        dt: f64,
        f0: f64,
        slope: f64,
        t0: f64,
    ) -> Result<StepStop> {
        let sys = SlipSystem {
            model: self.model,
            dir,
            f0,
            slope,
            inv_e0: 1.0 / self.e0,
            stop_on_crossing: true,
        };
        let (xs, ys, crossed) = self.integrate(sys, x, dt, self.h, t0)?;
        let n = xs.len();
        if !crossed {
            self.y = self.unpack(ys[n - 1]);
            self.check_finite(t0 + dt)?;
            return Ok(StepStop::Step);
        }
        // The last accepted step [xs[n-2], xs[n-1]] crosses v = 0.
        let (xa, ya) = (xs[n - 2], ys[n - 2]);
        let (xb, yb) = (xs[n - 1], ys[n - 1]);
        let (xe, ye) = self.locate(dir, f0, slope, xa, ya, xb, yb, t0)?;
        self.y = Kin {
            v: 0.0,
            ..self.unpack(ye)
        };
        self.check_finite(t0 + xe)?;
        let kind;
        (self.mode, kind) = arrive_at_rest(self.model, self.y.u, f0 + slope * xe);
        self.stats.record(kind);
        Ok(StepStop::Event { at: xe, kind })
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
    ) -> Result<(Vec<f64>, Vec<Vector4<f64>>, bool)> {
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
    ) -> Result<(Vec<f64>, Vec<Vector4<f64>>, bool)> {
        let span = x1 - x0;
        let dir = sys.dir;
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
            100_000,
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
        let crossed = n >= 2 && dir * ys[n - 1][1] <= 0.0 && xs[n - 1] <= x1;
        Ok((xs, ys, crossed))
    }

    /// Locates the zero of `dir·v` inside the accepted step `[xa, xb]` by
    /// [`locate_zero_velocity`] on the length of a Dopri5 integration from `(xa, ya)`, with the
    /// run's tolerances. Returns `(xa, ya)` if the platen started at rest and cannot move in
    /// `dir` at all: it stays where it is.
    #[allow(clippy::too_many_arguments)]
    fn locate(
        &mut self,
        dir: f64,
        f0: f64,
        slope: f64,
        xa: f64,
        ya: Vector4<f64>,
        xb: f64,
        yb: Vector4<f64>,
        t0: f64,
    ) -> Result<(f64, Vector4<f64>)> {
        let inv_e0 = 1.0 / self.e0;
        let span = xb - xa;
        let tolerance = 4.0 * f64::EPSILON * span.max(xb.abs());
        let found = locate_zero_velocity(span, dir * ya[1], (yb, dir * yb[1]), tolerance, |len| {
            self.stats.root_iterations += 1;
            let sys = SlipSystem {
                model: self.model,
                dir,
                f0,
                slope,
                inv_e0,
                stop_on_crossing: false,
            };
            let (_, ys, _) = self.integrate_from(sys, xa, ya, xa + len, len, t0)?;
            let y = ys[ys.len() - 1];
            Ok((y, dir * y[1]))
        })?;
        Ok(found.map_or((xa, ya), |(len, y)| (xa + len, y)))
    }
}
