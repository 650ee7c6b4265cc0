//! Ensembles: several forward RK4 runs of the identified model advanced together, one per
//! SIMD lane, bit for bit the runs of [`forward_rk4`](crate::forward_rk4).
//!
//! # Method
//!
//! A sweep runs many cases of one scenario: the same time grid and model form, with other
//! parameters (hold-down pressure, `--set` values) and another force (the excitation's
//! scale). [`forward_rk4_ensemble`] runs up to `N` of them in lock step on the grid. Every
//! lane is a whole scalar RK4 run ([`crate::rk4`]'s stepper, with its own mode, statistics
//! and events); at each grid step the lanes whose step is the scalar path's *fast path*
//! (slip at `v ≠ 0`, one RK4 step to the end of the grid step that stays clear of `v = 0`)
//! are stepped together in arrays `[f64; N]`, and every other lane (stick, creep, leaving
//! rest, a step that could cross or touch `v = 0`, a non-finite state) runs the scalar step
//! for that step.
//!
//! The lane arithmetic is the scalar fast path's, operation for operation and in the same
//! order (the model's `slip_rates`, the RK4 stages and sums, the speed checks and the cheap
//! bound of the Hermite dip test; `e^x` is the same `f64::exp`, called per lane), so a lane's
//! state after a lane step has the same bits as after the scalar step; the friction
//! direction is a run-time `±1.0` per lane, whose products are exact, as the monomorphised
//! scalar path's folded signs are. A lane step that the fast path would not accept is
//! discarded and the scalar step run from the unchanged state, so every decision is the
//! scalar path's own. The output samples, statistics and errors of every case are those of
//! [`forward_rk4`](crate::forward_rk4) on it (tests/ensemble.rs compares every sample's bits).
//!
//! Why it is faster: one RK4 step is a chain of dependent stages (square root, exponential,
//! division-free but long), so a single run is bound by latency; `N` independent runs fill
//! the vector units and the out-of-order core with independent work.

use platen_model::{Exponent, IdentifiedModel, SlipRates};

use crate::bare::Stepper;
use crate::error::{IntegrateError, Result};
use crate::event::Mode;
use crate::grid::{Grid, GridStep, GridStepper};
use crate::machine::{DI, V};
use crate::output::SampleSink;
use crate::record::ForceRecord;
use crate::rk4::{forward_rk4, Rk4};
use crate::run::{check_run, Kin, RunStats, State};

/// The number of lanes [`forward_rk4_ensemble`] advances together (measured best of 4 and 8
/// on the bench machine: see docs/performance.md).
pub const ENSEMBLE_LANES: usize = 4;

/// One trajectory of an ensemble: its model, its force record and its state at the first
/// sample.
#[derive(Debug, Clone, Copy)]
pub struct EnsembleCase<'a> {
    /// The case's model.
    pub model: &'a IdentifiedModel,
    /// The case's actuator force.
    pub record: &'a ForceRecord,
    /// The state at the record's first sample.
    pub initial: State,
}

/// Runs every case forward with fixed-step RK4 and exact stick-slip, [`ENSEMBLE_LANES`]
/// cases at a time in SIMD lanes, delivering the first `samples` output samples of case `i`
/// to `sinks[i]`. The results, and every sample delivered, are bit for bit those of
/// [`forward_rk4`](crate::forward_rk4) on each case alone.
///
/// Consecutive cases whose records share the time grid (the same sample times, to the bit)
/// run together; a case on another grid runs alone.
///
/// # Errors
/// Per case, the error [`forward_rk4`](crate::forward_rk4) returns on it (the other cases
/// go on).
///
/// # Panics
/// If `sinks` and `cases` differ in length.
pub fn forward_rk4_ensemble<S: SampleSink>(
    cases: &[EnsembleCase<'_>],
    rk4: Rk4,
    samples: usize,
    sinks: &mut [S],
) -> Vec<Result<RunStats>> {
    forward_rk4_lanes::<ENSEMBLE_LANES, S>(cases, rk4, samples, sinks)
}

/// [`forward_rk4_ensemble`] with `N` lanes (`N ≥ 1`).
///
/// # Errors
/// As [`forward_rk4_ensemble`].
///
/// # Panics
/// If `sinks` and `cases` differ in length.
pub fn forward_rk4_lanes<const N: usize, S: SampleSink>(
    cases: &[EnsembleCase<'_>],
    rk4: Rk4,
    samples: usize,
    sinks: &mut [S],
) -> Vec<Result<RunStats>> {
    assert_eq!(cases.len(), sinks.len(), "one sink per ensemble case");
    let mut results = Vec::with_capacity(cases.len());
    let mut start = 0;
    while start < cases.len() {
        // The next group: up to N runnable cases on the first one's grid.
        let mut end = start + 1;
        let first = cases[start].record;
        let runnable =
            |c: &EnsembleCase<'_>| samples >= 2 && check_run(c.record, c.initial, samples).is_ok();
        if runnable(&cases[start]) {
            while end < cases.len()
                && end - start < N
                && runnable(&cases[end])
                && same_grid(first, cases[end].record)
            {
                end += 1;
            }
        }
        let group = &cases[start..end];
        let group_sinks = &mut sinks[start..end];
        if end - start == 1 {
            let c = &group[0];
            results.push(forward_rk4(
                c.model,
                c.record,
                rk4,
                c.initial,
                samples,
                &mut group_sinks[0],
            ));
        } else {
            let all = |e: fn(Exponent) -> bool| group.iter().all(|c| e(c.model.law().exponent));
            let k = u64::from(rk4.steps_per_sample());
            if all(|e| e == Exponent::Half) {
                results.extend(run_group::<N, Half, S>(group, k, samples, group_sinks));
            } else {
                results.extend(run_group::<N, AnyPow, S>(group, k, samples, group_sinks));
            }
        }
        start = end;
    }
    results
}

/// Whether two records have the same sample times and interval, to the bit.
fn same_grid(a: &ForceRecord, b: &ForceRecord) -> bool {
    a.dt_s().to_bits() == b.dt_s().to_bits()
        && a.len() == b.len()
        && a.t_s()
            .iter()
            .zip(b.t_s())
            .all(|(x, y)| x.to_bits() == y.to_bits())
}

/// `w^α` in the lanes: the same operation as [`Exponent::pow`].
trait LanePow {
    fn pow(e: Exponent, w: f64) -> f64;
}

/// Every lane's exponent is ½: `√w` (vectorises).
struct Half;

impl LanePow for Half {
    #[inline(always)]
    fn pow(_: Exponent, w: f64) -> f64 {
        w.sqrt()
    }
}

/// Lanes with other or mixed exponents: [`Exponent::pow`] per lane.
struct AnyPow;

impl LanePow for AnyPow {
    #[inline(always)]
    fn pow(e: Exponent, w: f64) -> f64 {
        e.pow(w)
    }
}

/// The identified model's parameters, one lane each (padding lanes repeat lane 0).
struct LaneParams<const N: usize> {
    stiffness: [f64; N],
    coulomb: [f64; N],
    viscous: [f64; N],
    exponent: [Exponent; N],
    low_force: [f64; N],
    low_decay: [f64; N],
    inv_mass: [f64; N],
}

impl<const N: usize> LaneParams<N> {
    fn new(models: &[&IdentifiedModel]) -> Self {
        let at = |l: usize| models[l.min(models.len() - 1)];
        Self {
            stiffness: std::array::from_fn(|l| at(l).params().stiffness_n_per_m),
            coulomb: std::array::from_fn(|l| at(l).law().coulomb_force_n),
            viscous: std::array::from_fn(|l| at(l).law().viscous_coefficient),
            exponent: std::array::from_fn(|l| at(l).law().exponent),
            low_force: std::array::from_fn(|l| at(l).law().low_velocity_force_n),
            low_decay: std::array::from_fn(|l| at(l).law().low_velocity_decay_s_per_m),
            // As IdentifiedModel::new computes it.
            inv_mass: std::array::from_fn(|l| 1.0 / at(l).params().effective_mass_kg),
        }
    }

    /// [`IdentifiedModel`]'s `slip_rates` in every lane: acceleration and dissipated power.
    #[inline(always)]
    fn rates<P: LanePow>(
        &self,
        f: &[f64; N],
        u: &[f64; N],
        v: &[f64; N],
        dir: &[f64; N],
    ) -> ([f64; N], [f64; N]) {
        let mut speed = [0.0; N];
        let mut x = [0.0; N];
        for l in 0..N {
            speed[l] = (dir[l] * v[l]).max(0.0);
            x[l] = -self.low_decay[l] * speed[l];
        }
        let mut e = [0.0; N];
        for l in 0..N {
            e[l] = x[l].exp();
        }
        let mut a = [0.0; N];
        let mut p = [0.0; N];
        for l in 0..N {
            let d = self.coulomb[l]
                + self.viscous[l] * P::pow(self.exponent[l], speed[l])
                + self.low_force[l] * e[l];
            a[l] = (f[l] - self.stiffness[l] * u[l] - dir[l] * d) * self.inv_mass[l];
            p[l] = d * speed[l];
        }
        (a, p)
    }
}

/// The inputs of one lane step: the state, its rates, the direction and the forces at the
/// start, middle and end of the grid step.
struct LaneIn<const N: usize> {
    u: [f64; N],
    v: [f64; N],
    work: [f64; N],
    dissipated: [f64; N],
    a0: [f64; N],
    p0: [f64; N],
    dir: [f64; N],
    f_start: [f64; N],
    f_mid: [f64; N],
    f_end: [f64; N],
}

impl<const N: usize> LaneIn<N> {
    /// Harmless inputs for lanes that do not step in lanes (slip at 1 m/s, no force).
    fn idle() -> Self {
        Self {
            u: [0.0; N],
            v: [1.0; N],
            work: [0.0; N],
            dissipated: [0.0; N],
            a0: [0.0; N],
            p0: [0.0; N],
            dir: [1.0; N],
            f_start: [0.0; N],
            f_mid: [0.0; N],
            f_end: [0.0; N],
        }
    }
}

/// The outputs of one lane step: the state and rates at the end and whether the scalar fast
/// path accepts the step.
struct LaneOut<const N: usize> {
    y: [Kin; N],
    rates: [SlipRates; N],
    accept: [bool; N],
}

/// The scalar fast path of `Stepper::slip` (one RK4 step of length `h` from the start of a
/// grid step, then the checks that accept it) in every lane.
#[inline(always)]
fn lane_step<const N: usize, P: LanePow>(p: &LaneParams<N>, h: f64, i: &LaneIn<N>) -> LaneOut<N> {
    let (u, v, dir) = (&i.u, &i.v, &i.dir);
    let hh = 0.5 * h;
    let mut v2 = [0.0; N];
    let mut x = [0.0; N];
    for l in 0..N {
        v2[l] = v[l] + hh * i.a0[l];
        x[l] = u[l] + hh * v[l];
    }
    let (a2, p2) = p.rates::<P>(&i.f_mid, &x, &v2, dir);
    let mut v3 = [0.0; N];
    for l in 0..N {
        v3[l] = v[l] + hh * a2[l];
        x[l] = u[l] + hh * v2[l];
    }
    let (a3, p3) = p.rates::<P>(&i.f_mid, &x, &v3, dir);
    let mut v4 = [0.0; N];
    for l in 0..N {
        v4[l] = v[l] + h * a3[l];
        x[l] = u[l] + h * v3[l];
    }
    let (a4, p4) = p.rates::<P>(&i.f_end, &x, &v4, dir);
    let h6 = h / 6.0;
    let mut stage_min = [0.0; N];
    let mut u1 = [0.0; N];
    let mut v1 = [0.0; N];
    let mut work1 = [0.0; N];
    let mut diss1 = [0.0; N];
    for l in 0..N {
        stage_min[l] = (dir[l] * v2[l]).min(dir[l] * v3[l]).min(dir[l] * v4[l]);
        u1[l] = u[l] + h6 * (v[l] + 2.0 * (v2[l] + v3[l]) + v4[l]);
        v1[l] = v[l] + h6 * (i.a0[l] + 2.0 * (a2[l] + a3[l]) + a4[l]);
        work1[l] = i.work[l]
            + h6 * (i.f_start[l] * v[l] + 2.0 * i.f_mid[l] * (v2[l] + v3[l]) + i.f_end[l] * v4[l]);
        diss1[l] = i.dissipated[l] + h6 * (i.p0[l] + 2.0 * (p2[l] + p3[l]) + p4[l]);
    }
    let (a1, p1) = p.rates::<P>(&i.f_end, &u1, &v1, dir);
    let mut accept = [false; N];
    for l in 0..N {
        // The checks of Stepper::slip, with dip_to_zero's cheap bound: a step the bound does
        // not clear goes to the scalar path, which decides it exactly.
        let (w0, w1) = (dir[l] * v[l], dir[l] * v1[l]);
        let (d0, d1) = (dir[l] * i.a0[l] * h, dir[l] * a1[l] * h);
        let delta = w1 - w0;
        let bound = 0.25 * (d0 - delta).abs().max((d1 - delta).abs());
        accept[l] = w1 > 0.0
            && stage_min[l] > 0.0
            && w0.min(w1) > bound
            && u1[l].is_finite()
            && a1[l].is_finite();
    }
    LaneOut {
        y: std::array::from_fn(|l| Kin {
            u: u1[l],
            v: v1[l],
            work: work1[l],
            dissipated: diss1[l],
        }),
        rates: std::array::from_fn(|l| SlipRates {
            a_m_s2: a1[l],
            dissipated_power_w: p1[l],
        }),
        accept,
    }
}

/// Runs a group of at most `N` cases on one grid (checked runnable, `samples ≥ 2`), as
/// `rk4::drive` runs one.
fn run_group<const N: usize, P: LanePow, S: SampleSink>(
    cases: &[EnsembleCase<'_>],
    k: u64,
    samples: usize,
    sinks: &mut [S],
) -> Vec<Result<RunStats>> {
    let m = cases.len();
    debug_assert!((2..=N).contains(&m));
    let models: Vec<&IdentifiedModel> = cases.iter().map(|c| c.model).collect();
    let params = LaneParams::<N>::new(&models);
    let mut lanes: Vec<Stepper<'_, IdentifiedModel>> = cases
        .iter()
        .map(|c| Stepper::new(c.model, Grid::new(c.record, k), c.initial))
        .collect();
    let h = lanes[0].machine.plant.clock.grid.h;
    let times = cases[0].record.t_s();
    let mut errors: Vec<Option<IntegrateError>> = vec![None; m];
    for (lane, sink) in lanes.iter().zip(sinks.iter_mut()) {
        sink.accept(&lane.sample(0, times[0]));
    }
    let mut input = LaneIn::<N>::idle();
    let mut n = 0u64;
    for j in 0..samples - 1 {
        for i in 0..k {
            let g = GridStep { n, j, i: i as f64 };
            let fast = gather_slipping(&lanes, &errors, g, &mut input);
            let out = if fast.iter().any(|&f| f) {
                Some(lane_step::<N, P>(&params, h, &input))
            } else {
                None
            };
            advance_lanes(&mut lanes, &mut errors, g, out.as_ref(), &fast, &input);
            n += 1;
        }
        for (l, (lane, sink)) in lanes.iter().zip(sinks.iter_mut()).enumerate() {
            if errors[l].is_none() {
                sink.accept(&lane.sample(j + 1, times[j + 1]));
            }
        }
    }
    lanes
        .iter_mut()
        .zip(errors)
        .map(|(lane, e)| match e {
            Some(e) => Err(e),
            None => Ok(lane.finish(times[samples - 1])),
        })
        .collect()
}

/// The lanes that slide (in a slip with a non-zero velocity, and not failed) at grid step
/// `g`: their states and forces written into `input`, and a flag per lane (`true` for those
/// the fast path steps).
#[inline(always)]
fn gather_slipping<const N: usize>(
    lanes: &[Stepper<'_, IdentifiedModel>],
    errors: &[Option<IntegrateError>],
    g: GridStep,
    input: &mut LaneIn<N>,
) -> [bool; N] {
    let mut fast = [false; N];
    for (l, lane) in lanes.iter().enumerate() {
        if errors[l].is_some() {
            continue;
        }
        let m = &lane.machine;
        if let Mode::Slip(d) = m.mode {
            if m.y[V] != 0.0 {
                let y = lane.kin();
                fast[l] = true;
                input.u[l] = y.u;
                input.v[l] = y.v;
                input.work[l] = y.work;
                input.dissipated[l] = y.dissipated;
                input.a0[l] = m.a;
                input.p0[l] = m.k[DI];
                input.dir[l] = d.sign();
                let grid = &m.plant.clock.grid;
                input.f_start[l] = grid.force(g, 0.0);
                input.f_mid[l] = grid.force(g, 0.5 * (1.0 + 0.0));
                input.f_end[l] = grid.force(g, 1.0);
            }
        }
    }
    fast
}

/// Every lane not failed through grid step `g`: the fast path's step `out` committed where
/// it ran (`fast`) and accepts it, the lane's own step otherwise (a failure kept in
/// `errors`).
#[inline(always)]
fn advance_lanes<const N: usize>(
    lanes: &mut [Stepper<'_, IdentifiedModel>],
    errors: &mut [Option<IntegrateError>],
    g: GridStep,
    out: Option<&LaneOut<N>>,
    fast: &[bool; N],
    input: &LaneIn<N>,
) {
    for (l, lane) in lanes.iter_mut().enumerate() {
        if errors[l].is_some() {
            continue;
        }
        match out {
            Some(out) if fast[l] && out.accept[l] => {
                let stats = &mut lane.machine.stats;
                stats.steps += 1;
                stats.rhs_evaluations += 4;
                let r = out.rates[l];
                lane.commit_slip(out.y[l], r.a_m_s2, r.dissipated_power_w, input.f_end[l]);
            }
            _ => {
                if let Err(e) = lane.step(g) {
                    errors[l] = Some(e);
                }
            }
        }
    }
}
