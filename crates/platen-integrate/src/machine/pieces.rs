//! The machine's one-step maps: an RK4 step (graded near rest, [`Grading`]; the fast slip
//! step of a grid step, [`Machine::slip_fast`]) and an adaptive Dormand–Prince 5(4) piece
//! that meets `rtol`/`atol` over it, scaled per state ([`Plant::error_scale`]).

use crate::clock::Clock;
use crate::event::{dip_to_zero, Mode};
use crate::stop::AdaptiveFailure;

use super::{Machine, PieceMethod, Plant, Rk4Stages, V, Y};

impl<P: Plant<L>, const L: usize> Machine<P, L> {
    /// One RK4 step of length `len` from position `s` (`y` with rates `k1` there): the end
    /// state and the smallest stage speed along the slip direction.
    #[inline(always)]
    pub(super) fn rk4(&mut self, s: f64, len: f64, y: &Y<L>, k1: &Y<L>) -> (Y<L>, f64) {
        let mode = self.mode;
        let dt = self.plant.clock().seconds(len);
        let (i_mid, i_end) = (self.plant.input(s + 0.5 * len), self.plant.input(s + len));
        let combine = |base: &Y<L>, k: &Y<L>, c: f64| {
            let mut out = *base;
            for i in 0..L {
                out[i] += c * k[i];
            }
            out
        };
        let (mut k2, mut k3, mut k4) = ([0.0; L], [0.0; L], [0.0; L]);
        let w = self.w_stiff;
        let y2 = combine(y, k1, 0.5 * dt);
        self.plant.rates(mode, w, i_mid, &y2, &mut k2);
        let y3 = combine(y, &k2, 0.5 * dt);
        self.plant.rates(mode, w, i_mid, &y3, &mut k3);
        let y4 = combine(y, &k3, dt);
        self.plant.rates(mode, w, i_end, &y4, &mut k4);
        self.stats.rhs_evaluations += 3;
        let h6 = dt / 6.0;
        let st = Rk4Stages {
            s,
            h6,
            i_mid,
            i_end,
            y,
            y2: &y2,
            y3: &y3,
            y4: &y4,
        };
        let mut y1 = self.combine_rk4(&st, k1, &k2, &k3, &k4);
        let stage_min = match mode {
            Mode::Slip(dir) => {
                let d = dir.sign();
                (d * y2[V]).min(d * y3[V]).min(d * y4[V])
            }
            _ => f64::INFINITY,
        };
        self.plant.settle(mode, w, i_end, &mut y1);
        (y1, stage_min)
    }

    /// The end of an RK4 step with stages `st` and rates `k1`…`k4`: the classical
    /// combination, or the plant's own quadrature of a state ([`Plant::rk4_quadrature`]).
    #[inline(always)]
    pub(super) fn combine_rk4(
        &self,
        st: &Rk4Stages<'_, L, P::Input>,
        k1: &Y<L>,
        k2: &Y<L>,
        k3: &Y<L>,
        k4: &Y<L>,
    ) -> Y<L> {
        let mut y1 = *st.y;
        for i in 0..L {
            y1[i] = match self.plant.rk4_quadrature(i, st) {
                Some(yi) => yi,
                None => y1[i] + st.h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]),
            };
        }
        y1
    }

    /// Adaptive Dormand–Prince 5(4) over a length `len` from position `s` (`y` with rates
    /// `k1` there): the end state and the smallest speed along the slip direction at its
    /// stages.
    pub(super) fn dopri5(
        &mut self,
        s: f64,
        len: f64,
        y: &Y<L>,
        k1: &Y<L>,
        tol: (f64, f64),
    ) -> (Y<L>, f64) {
        let dt = self.plant.clock().seconds(len);
        let mode = self.mode;
        let w = self.w_stiff;
        let (mut yc, mut kc) = (*y, *k1);
        let mut done = 0.0;
        let mut stage_min = f64::INFINITY;
        let mut hs = self.h_dopri.min(dt);
        let mut guard = 0u32;
        while done < dt {
            guard += 1;
            let last = dt - done <= hs * (1.0 + 1e-12);
            let step = if last { dt - done } else { hs };
            let (ks, ys) = self.dopri5_stages(s, done, step, &yc, &kc);
            let y_new = ys[5];
            let err = self.dopri5_error(step, &yc, &y_new, &ks, tol);
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
                    // with the failure (`Machine::take_failure`).
                    let reason = if underflow {
                        AdaptiveFailure::StepSizeUnderflow
                    } else {
                        AdaptiveFailure::TooManySteps { steps: MAX_STEPS }
                    };
                    let t_s = self.plant.clock().time_s(s) + done;
                    self.gave_up.get_or_insert((t_s, reason));
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
                self.stats.accepted_steps += 1;
                if !last {
                    hs = (step * factor).min(self.h);
                    self.h_dopri = hs;
                }
                if last {
                    break;
                }
            } else {
                self.stats.rejected_steps += 1;
                hs = step * factor;
            }
        }
        let input = self.plant.input(s + len);
        self.plant.settle(mode, w, input, &mut yc);
        (yc, stage_min)
    }

    /// The six stages of one Dormand–Prince step of `step` seconds from `yc` (rates `kc`), `done`
    /// seconds past position `s`: the rates at the stages (the 7th at the new state) and the
    /// stage states (the 6th is the new state).
    pub(super) fn dopri5_stages(
        &mut self,
        s: f64,
        done: f64,
        step: f64,
        yc: &Y<L>,
        kc: &Y<L>,
    ) -> ([Y<L>; 7], [Y<L>; 6]) {
        let mut ks = [[0.0; L]; 7];
        ks[0] = *kc;
        let mut ys = [*yc; 6];
        for stage in 0..6 {
            let mut yi = *yc;
            for i in 0..L {
                let mut acc = 0.0;
                for (j, kj) in ks.iter().enumerate().take(stage + 1) {
                    acc += DP_A[stage][j] * kj[i];
                }
                yi[i] += step * acc;
            }
            ys[stage] = yi;
            let at = s + self.plant.clock().units(done + DP_C[stage] * step);
            let input = self.plant.input(at);
            let mut kn = [0.0; L];
            self.plant
                .rates(self.mode, self.w_stiff, input, &yi, &mut kn);
            ks[stage + 1] = kn;
        }
        self.stats.rhs_evaluations += 6;
        (ks, ys)
    }

    /// The scaled error norm (the largest over the states) of a Dormand–Prince step of
    /// `step` seconds from `yc` to `y_new` with stage rates `ks`, at tolerances `(rtol, atol)`.
    pub(super) fn dopri5_error(
        &self,
        step: f64,
        yc: &Y<L>,
        y_new: &Y<L>,
        ks: &[Y<L>; 7],
        (rtol, atol): (f64, f64),
    ) -> f64 {
        let mut err: f64 = 0.0;
        for i in 0..L {
            let mut e = 0.0;
            for (j, kj) in ks.iter().enumerate() {
                e += DP_E[j] * kj[i];
            }
            let sc = self.plant.error_scale(i, yc[i], y_new[i], rtol, atol);
            err = err.max((step * e / sc).abs());
        }
        err
    }

    /// The current mode's state over a length `x` from position `tau`, as the method maps it
    /// (RK4 split by `grading`); with the smallest stage speed.
    pub(super) fn piece(&mut self, tau: f64, x: f64, grading: Grading) -> (Y<L>, f64) {
        let (mut y, mut k) = (self.y, self.k);
        if let PieceMethod::Dopri5 { rtol, atol } = self.method {
            return self.dopri5(tau, x, &y, &k, (rtol, atol));
        }
        let mut stage_min = f64::INFINITY;
        let mut s = tau;
        for (i, &p) in grading.pieces().iter().enumerate() {
            let len = p * x;
            if i > 0 {
                let input = self.plant.input(s);
                self.plant.rates(self.mode, self.w_stiff, input, &y, &mut k);
                self.stats.rhs_evaluations += 1;
            }
            let (y1, m) = self.rk4(s, len, &y, &k);
            y = y1;
            stage_min = stage_min.min(m);
            s += len;
        }
        (y, stage_min)
    }

    /// One RK4 step over the rest of a span of length 1, from position `tau`, in slip with
    /// direction `direction::<POSITIVE>()` (the platen moving, `v ≠ 0`), committed when it is
    /// safe: from `tau = 0` exactly the first try of [`Machine::advance`] (a single piece of
    /// length 1), the same operations in the same order, so what it commits is bit for bit
    /// what [`Machine::advance`] would. Returns whether it committed; if not, nothing has
    /// changed but the counters of a plant that counts tried steps
    /// ([`Plant::COUNTS_TRIED_STEPS`]), and the span is taken again by [`Machine::advance`].
    #[inline(always)]
    pub(crate) fn slip_fast<const POSITIVE: bool>(&mut self, tau: f64) -> bool {
        let dir = direction::<POSITIVE>();
        let h = self.plant.clock().seconds(1.0 - tau);
        let (i_mid, i_end) = (self.plant.input(0.5 * (1.0 + tau)), self.plant.input(1.0));
        let (y, k1) = (&self.y, &self.k);
        let hh = 0.5 * h;
        let (mut k2, mut k3, mut k4) = ([0.0; L], [0.0; L], [0.0; L]);
        let mut y2 = *y;
        for i in 0..L {
            y2[i] += hh * k1[i];
        }
        self.plant.slip_rates::<POSITIVE>(i_mid, &y2, &mut k2);
        let mut y3 = *y;
        for i in 0..L {
            y3[i] += hh * k2[i];
        }
        self.plant.slip_rates::<POSITIVE>(i_mid, &y3, &mut k3);
        let mut y4 = *y;
        for i in 0..L {
            y4[i] += h * k3[i];
        }
        self.plant.slip_rates::<POSITIVE>(i_end, &y4, &mut k4);
        let st = Rk4Stages {
            s: tau,
            h6: h / 6.0,
            i_mid,
            i_end,
            y,
            y2: &y2,
            y3: &y3,
            y4: &y4,
        };
        let y1 = self.combine_rk4(&st, k1, &k2, &k3, &k4);
        if P::COUNTS_TRIED_STEPS {
            self.stats.rhs_evaluations += 3;
        }
        let stage_min = (dir * y2[V]).min(dir * y3[V]).min(dir * y4[V]);
        if !(dir * y1[V] > 0.0 && stage_min > 0.0 && self.plant.is_finite(&y1)) {
            return false;
        }
        let mut k_end = [0.0; L];
        let a1 = self.plant.slip_rates::<POSITIVE>(i_end, &y1, &mut k_end);
        if P::COUNTS_TRIED_STEPS {
            self.stats.rhs_evaluations += 1;
        }
        let (d0, d1) = (dir * self.a * h, dir * a1 * h);
        if dip_to_zero(dir * self.y[V], dir * y1[V], d0, d1).is_some() || !a1.is_finite() {
            return false;
        }
        if !P::COUNTS_TRIED_STEPS {
            self.stats.rhs_evaluations += 4;
        }
        (self.y, self.k, self.a) = (y1, k_end, a1);
        true
    }
}

/// The Dormand–Prince 5(4) tableau: nodes.
const DP_C: [f64; 6] = [0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
/// The Dormand–Prince 5(4) tableau: stage coefficients (the last row is the 5th-order
/// solution, so the 7th stage is the rate at the new state: first same as last).
const DP_A: [[f64; 6]; 6] = [
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
/// The Dormand–Prince 5(4) tableau: the error estimate's weights (5th − 4th order).
const DP_E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Most Dopri5 steps in one piece before it gives up ([`AdaptiveFailure::TooManySteps`]).
pub(crate) const MAX_STEPS: u32 = 100_000;

/// The friction direction of slip as a number: `+1.0` for `POSITIVE`, `−1.0` otherwise.
///
/// The slip path is monomorphised over the direction so that, once the model's
/// `slip_rates` is inlined, `direction·v` and `direction·D` fold to `v`/`−v` and `D`/`−D`
/// (exact for ±1, so the results are bit for bit those of a run-time direction) and two
/// multiplications leave the dependency chain of every stage.
#[inline(always)]
pub(crate) const fn direction<const POSITIVE: bool>() -> f64 {
    if POSITIVE {
        1.0
    } else {
        -1.0
    }
}

/// How a slip interval is split into RK4 sub-steps.
///
/// Near `v = 0` the `|v|^α` law (α < 1) makes the right-hand side singular like `√(t − t*)`,
/// which cuts a single RK4 step's accuracy to `O(h^1.5)` (about 1e-7 m/s per event at
/// h = 1/1024 s on the paper's model). Geometric sub-steps that halve towards the singular
/// end make the step that holds it `2⁵` times shorter, which removes that error to the
/// 1e-10 m level, at the cost of a few extra stages per event only.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Grading {
    /// One plain RK4 step.
    Single,
    /// Singular at the start (leaving rest).
    Start,
    /// Singular at the end (arriving at rest).
    End,
    /// Singular at both ends.
    Both,
}

const GRADED_START: [f64; 6] = [
    1.0 / 32.0,
    1.0 / 32.0,
    1.0 / 16.0,
    1.0 / 8.0,
    1.0 / 4.0,
    1.0 / 2.0,
];
const GRADED_END: [f64; 6] = [
    1.0 / 2.0,
    1.0 / 4.0,
    1.0 / 8.0,
    1.0 / 16.0,
    1.0 / 32.0,
    1.0 / 32.0,
];
const GRADED_BOTH: [f64; 12] = [
    1.0 / 64.0,
    1.0 / 64.0,
    1.0 / 32.0,
    1.0 / 16.0,
    1.0 / 8.0,
    1.0 / 4.0,
    1.0 / 4.0,
    1.0 / 8.0,
    1.0 / 16.0,
    1.0 / 32.0,
    1.0 / 64.0,
    1.0 / 64.0,
];

impl Grading {
    pub(crate) fn pieces(self) -> &'static [f64] {
        match self {
            Grading::Single => &[1.0],
            Grading::Start => &GRADED_START,
            Grading::End => &GRADED_END,
            Grading::Both => &GRADED_BOTH,
        }
    }
}
