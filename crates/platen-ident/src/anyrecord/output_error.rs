//! The output-error refinement: the identified model is run forward (RK4 with exact
//! stick-slip, [`platen_integrate::forward_rk4`]) under each record's force, less the
//! equation error's force offset, and its displacement and acceleration are fitted to the
//! measured ones by Levenberg–Marquardt with a forward-difference Jacobian.
//!
//! Residuals per record and channel have their mean removed (a constant displacement or
//! accelerometer offset is not the model's business: with the force offset held, a
//! displacement offset `d` and an accelerometer offset `e` leave `u_sim = u_rec + Mₑe/Kₑ`,
//! `a_sim = a_rec − e` up to the initial state), and are divided by their RMS at the start,
//! so each channel weighs the same whatever its unit. The initial state `(u₀, v₀)` of each
//! record is fitted too.
//!
//! **Cost.** Every evaluation is a set of forward runs, one per record (and, for the
//! Jacobian, one per record and column: each model parameter's column reruns every record,
//! each record's initial state only its own). The runs are independent: they are done in
//! parallel over the records (rayon's pool: as many threads as cores) and assembled in
//! record order, so the result is the same bits whatever the number of threads.
//!
//! Unlike the equation error this sees the platen at rest: how long it sticks and where it
//! stops depend on `F_s = F_μ + a` exactly, so the low-velocity behaviour that the equation
//! error leaves out (samples below its minimum speed) enters here.

use std::sync::atomic::{AtomicUsize, Ordering};

use platen_integrate::{forward_rk4, ForceRecord, Rk4, Sample, SampleSink, State};
use platen_model::IdentifiedParams;
use rayon::prelude::*;

use crate::lm::{Jacobian, Problem};
use crate::record::TestRecord;

use super::separable::{
    COULOMB, EXPONENT, LOW_DECAY, LOW_FORCE, MASS, OFFSETS, STIFFNESS, VISCOUS,
};

/// Collects `u` and `a` of a run into preallocated buffers.
struct MotionSink<'a> {
    u: &'a mut [f64],
    a: &'a mut [f64],
}

impl SampleSink for MotionSink<'_> {
    #[inline]
    fn accept(&mut self, s: &Sample) {
        self.u[s.index] = s.u_m;
        self.a[s.index] = s.a_m_s2;
    }
}

/// One record as the output error sees it.
struct OeRecord {
    force: ForceRecord,
    u: Vec<f64>,
    a: Vec<f64>,
    /// 1/RMS of the start's de-meaned residual, per channel.
    weight_u: f64,
    weight_a: f64,
}

/// A record at the end of the output-error fit.
pub(crate) struct RecordEnd {
    /// The simulated displacement, m (`None` if the model is invalid or the run fails).
    pub simulated_u_m: Option<Vec<f64>>,
    /// Unweighted RMS of the displacement and acceleration residuals (NaN if so).
    pub rms: (f64, f64),
}

/// The output-error problem. Parameter vector: the model parameters fitted (full-vector
/// indices `model_free`), then `(u₀, v₀)` of each record.
pub(crate) struct OutputError {
    records: Vec<OeRecord>,
    model_free: Vec<usize>,
    /// The full model vector (held parameters at their values).
    base: [f64; 7],
    rk4: Rk4,
    /// Unweighted RMS of each record's displacement and acceleration residuals at the start.
    start_rms: Vec<(f64, f64)>,
    /// Forward runs of a record so far (counted from every thread).
    runs: AtomicUsize,
}

/// Lower and upper bounds of the model parameters, in full-vector order (`Mₑ > 0`, the
/// others as [`IdentifiedParams::build`] requires).
const LOWER: [f64; 7] = [1e-6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
const UPPER: [f64; 7] = [
    f64::INFINITY,
    f64::INFINITY,
    f64::INFINITY,
    f64::INFINITY,
    1.0,
    f64::INFINITY,
    1e4,
];

/// Forward-difference step, relative to the parameter (or to `FLOOR` for a parameter near
/// zero). 10⁻⁴ is far above the simulation's rounding (~10⁻¹² of the motion) and small
/// against the parameters' standard errors (≥ 10⁻³ of their values on the test records), so
/// the difference quotient is the derivative of the fitted quantity to < 1 %.
const RELATIVE_STEP: f64 = 1e-4;
const FLOOR: [f64; 7] = [1e3, 1e4, 1e2, 1e2, 0.1, 1e2, 1.0];
/// Absolute steps of the initial state, m and m/s.
const STATE_STEP: [f64; 2] = [1e-6, 1e-6];

impl OutputError {
    /// The problem for `records` with force offsets `offsets_n` (from the equation error),
    /// starting at `full` (`[Mₑ, Kₑ, F_μ, Cₑ, α, a, b, …]`), fitting the parameters in
    /// `model_free`.
    pub(crate) fn new(
        records: &[TestRecord],
        velocities: &[Vec<f64>],
        full: &[f64],
        model_free: Vec<usize>,
        steps_per_sample: u32,
    ) -> Option<(Self, Vec<f64>)> {
        let mut base = [0.0; 7];
        for (k, b) in base.iter_mut().enumerate() {
            *b = full[k].clamp(LOWER[k], UPPER[k]);
        }
        let mut oe = Vec::with_capacity(records.len());
        let mut start: Vec<f64> = model_free.iter().map(|&i| base[i]).collect();
        for (r, rec) in records.iter().enumerate() {
            let offset = full[OFFSETS + r];
            let force = ForceRecord::from_rate(
                rec.sample_rate_hz(),
                rec.force_n().iter().map(|f| f - offset).collect(),
            )
            .ok()?;
            oe.push(OeRecord {
                force,
                u: rec.u_m().to_vec(),
                a: rec.a_m_s2().to_vec(),
                weight_u: 1.0,
                weight_a: 1.0,
            });
            start.push(rec.u_m()[0]);
            start.push(velocities[r][0]);
        }
        let mut problem = Self {
            records: oe,
            model_free,
            base,
            rk4: Rk4::with_steps_per_sample(steps_per_sample).ok()?,
            start_rms: Vec::with_capacity(records.len()),
            runs: AtomicUsize::new(0),
        };
        // Channel weights from the start's residuals.
        let q = problem.full(&start);
        let start_runs: Vec<_> = (0..problem.records.len())
            .into_par_iter()
            .map(|r| problem.raw_residuals(&q, &start, r))
            .collect();
        for (r, run) in start_runs.into_iter().enumerate() {
            let (ru, ra) = run?;
            let (su, sa) = (rms(&ru), rms(&ra));
            problem.start_rms.push((su, sa));
            let rec = &mut problem.records[r];
            rec.weight_u = if su > 0.0 { 1.0 / su } else { 1.0 };
            rec.weight_a = if sa > 0.0 { 1.0 / sa } else { 1.0 };
        }
        Some((problem, start))
    }

    /// Forward runs of a record so far (a run of every record counts one per record).
    pub(crate) fn runs(&self) -> usize {
        self.runs.load(Ordering::Relaxed)
    }

    /// Unweighted RMS of each record's displacement and acceleration residuals at the start.
    pub(crate) fn start_rms(&self) -> &[(f64, f64)] {
        &self.start_rms
    }

    /// The model vector at `p`.
    fn full(&self, p: &[f64]) -> [f64; 7] {
        let mut q = self.base;
        for (k, &i) in self.model_free.iter().enumerate() {
            q[i] = p[k];
        }
        q
    }

    fn params(q: &[f64; 7]) -> IdentifiedParams {
        IdentifiedParams {
            effective_mass_kg: q[MASS],
            stiffness_n_per_m: q[STIFFNESS],
            coulomb_force_n: q[COULOMB],
            viscous_coefficient: q[VISCOUS],
            viscous_exponent: q[EXPONENT],
            low_velocity_force_n: q[LOW_FORCE],
            low_velocity_decay_s_per_m: q[LOW_DECAY],
        }
    }

    /// Simulated − measured displacement and acceleration of record `r`, each with its
    /// mean removed; `None` if the model is invalid or the run fails.
    fn raw_residuals(&self, q: &[f64; 7], p: &[f64], r: usize) -> Option<(Vec<f64>, Vec<f64>)> {
        self.runs.fetch_add(1, Ordering::Relaxed);
        let model = Self::params(q).build().ok()?;
        let rec = &self.records[r];
        let n = rec.u.len();
        let k = self.model_free.len() + 2 * r;
        let initial = State {
            u_m: p[k],
            v_m_s: p[k + 1],
        };
        let mut u = vec![0.0; n];
        let mut a = vec![0.0; n];
        let mut sink = MotionSink {
            u: &mut u,
            a: &mut a,
        };
        forward_rk4(&model, &rec.force, self.rk4, initial, n, &mut sink).ok()?;
        for (x, m) in u.iter_mut().zip(&rec.u) {
            *x -= m;
        }
        for (x, m) in a.iter_mut().zip(&rec.a) {
            *x -= m;
        }
        for x in [&mut u, &mut a] {
            let mean = x.iter().sum::<f64>() / n as f64;
            x.iter_mut().for_each(|v| *v -= mean);
        }
        Some((u, a))
    }

    /// Lower and upper bounds of the parameter vector.
    pub(crate) fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let mut lo: Vec<f64> = self.model_free.iter().map(|&i| LOWER[i]).collect();
        let mut hi: Vec<f64> = self.model_free.iter().map(|&i| UPPER[i]).collect();
        for _ in &self.records {
            lo.extend([f64::NEG_INFINITY; 2]);
            hi.extend([f64::INFINITY; 2]);
        }
        (lo, hi)
    }

    /// For each residual: (record, sample index).
    pub(crate) fn residual_layout(&self) -> (Vec<usize>, Vec<usize>) {
        let mut group = Vec::new();
        let mut time = Vec::new();
        for (r, rec) in self.records.iter().enumerate() {
            let n = rec.u.len();
            for _channel in 0..2 {
                group.extend(std::iter::repeat_n(r, n));
                time.extend(0..n);
            }
        }
        (time, group)
    }

    /// Each record at `p`, from one run.
    pub(crate) fn finish(&self, p: &[f64]) -> Vec<RecordEnd> {
        let q = self.full(p);
        (0..self.records.len())
            .into_par_iter()
            .map(|r| match self.raw_residuals(&q, p, r) {
                Some((ru, ra)) => RecordEnd {
                    // Back from the de-meaned residual to the simulation: add the measured
                    // channel and the mean offset (a constant, shown as fitted).
                    simulated_u_m: Some(
                        ru.iter()
                            .zip(&self.records[r].u)
                            .map(|(x, m)| x + m)
                            .collect(),
                    ),
                    rms: (rms(&ru), rms(&ra)),
                },
                None => RecordEnd {
                    simulated_u_m: None,
                    rms: (f64::NAN, f64::NAN),
                },
            })
            .collect()
    }

    /// Weighted residuals of record `r` at `p` (model vector `q`) into `out` (its `2n`
    /// rows: displacement, then acceleration), `+∞` if the run fails.
    fn record_residuals(&self, q: &[f64; 7], p: &[f64], r: usize, out: &mut [f64]) {
        let rec = &self.records[r];
        let n = rec.u.len();
        match self.raw_residuals(q, p, r) {
            Some((u, a)) => {
                for i in 0..n {
                    out[i] = rec.weight_u * u[i];
                    out[n + i] = rec.weight_a * a[i];
                }
            }
            None => out.fill(f64::INFINITY),
        }
    }

    /// The first row of each record's residuals, and the end.
    fn row_starts(&self) -> Vec<usize> {
        let mut at = vec![0];
        for rec in &self.records {
            at.push(at[at.len() - 1] + 2 * rec.u.len());
        }
        at
    }

    /// The model parameters at `p`, full vector.
    pub(crate) fn model_vector(&self, p: &[f64]) -> [f64; 7] {
        self.full(p)
    }

    fn step(&self, p: &[f64], k: usize) -> f64 {
        let nm = self.model_free.len();
        if k < nm {
            let i = self.model_free[k];
            let h = RELATIVE_STEP * p[k].abs().max(FLOOR[i]);
            // Step inwards at an upper bound (α = 1).
            if p[k] + h > UPPER[i] {
                -h
            } else {
                h
            }
        } else {
            STATE_STEP[(k - nm) % 2]
        }
    }
}

impl Problem for OutputError {
    fn residual_count(&self) -> usize {
        self.records.iter().map(|r| 2 * r.u.len()).sum()
    }
    fn parameter_count(&self) -> usize {
        self.model_free.len() + 2 * self.records.len()
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) {
        let q = self.full(p);
        let rows = self.row_starts();
        let mut spans = Vec::with_capacity(self.records.len());
        let mut rest = out;
        for r in 0..self.records.len() {
            let (span, tail) = rest.split_at_mut(rows[r + 1] - rows[r]);
            spans.push(span);
            rest = tail;
        }
        spans
            .into_par_iter()
            .enumerate()
            .for_each(|(r, span)| self.record_residuals(&q, p, r, span));
    }
    /// Forward differences: every record rerun for a model parameter, only its own record
    /// for a record's initial state; `base` is the residuals at `p`. Each record's rows of
    /// the Jacobian come from that record's runs alone, so the records are done in parallel,
    /// each writing its own rows.
    fn jacobian(&self, p: &[f64], base: &[f64], j: &mut Jacobian) {
        let nm = self.model_free.len();
        let q = self.full(p);
        let rows = self.row_starts();
        let mut shared = by_record(j.shared.as_mut_slice(), &rows);
        let mut local = by_record(j.local.as_mut_slice(), &rows);
        let tasks: Vec<_> = shared
            .iter_mut()
            .zip(local.iter_mut())
            .enumerate()
            .collect();
        tasks.into_par_iter().for_each(|(rec, (shared, local))| {
            let base = &base[rows[rec]..rows[rec + 1]];
            let mut trial = p.to_vec();
            let mut r = vec![0.0; base.len()];
            let own = (nm + 2 * rec)..(nm + 2 * rec + 2);
            for k in (0..nm).chain(own) {
                let h = self.step(p, k);
                trial[k] = p[k] + h;
                let qk = if k < nm { self.full(&trial) } else { q };
                self.record_residuals(&qk, &trial, rec, &mut r);
                trial[k] = p[k];
                let column: &mut [f64] = if k < nm {
                    shared[k]
                } else {
                    local[k - nm - 2 * rec]
                };
                for ((d, &x), &b) in column.iter_mut().zip(&r).zip(base) {
                    let quotient = (x - b) / h;
                    *d = if quotient.is_finite() { quotient } else { 0.0 };
                }
            }
        });
    }
    fn new_jacobian(&self) -> Jacobian {
        let (_, group) = self.residual_layout();
        Jacobian::blocked(
            self.residual_count(),
            self.model_free.len(),
            2,
            group,
            self.records.len(),
        )
    }
}

/// A column-major matrix's columns (each `rows[last]` long) cut at `rows`: for each record,
/// its rows of every column, in column order.
fn by_record<'a>(data: &'a mut [f64], rows: &[usize]) -> Vec<Vec<&'a mut [f64]>> {
    let records = rows.len() - 1;
    let mut out: Vec<Vec<&mut [f64]>> = (0..records).map(|_| Vec::new()).collect();
    let height = rows[records];
    if height == 0 {
        return out;
    }
    for column in data.chunks_mut(height) {
        let mut rest = column;
        for (r, spans) in out.iter_mut().enumerate() {
            let (span, tail) = rest.split_at_mut(rows[r + 1] - rows[r]);
            spans.push(span);
            rest = tail;
        }
    }
    out
}

use platen_signal::metrics::rms;
