//! Cycle handling (paper §3): the period, the waveform, the steady-state cycle, its alignment
//! (u > 0 on the first half) and the two low-passed versions of every channel.

use std::f64::consts::PI;

use platen_signal::{
    differentiate, ButterworthLowpass, CrossoverVelocity, FirLowpass, SampleRate, Window,
    ZeroPhaseFilter,
};

use crate::error::{IdentError, Result};
use crate::record::{TestKind, TestRecord};
use crate::settings::ValidSettings;

/// Hysteresis of the zero-crossing detector, as a fraction of the displacement amplitude: the
/// displacement must swing past ±25 % of its amplitude between two crossings, so transducer
/// noise (20 µm on the paper's smallest 1.6 cm amplitude) can never count as a crossing.
const CROSSING_HYSTERESIS: f64 = 0.25;

/// Largest spread of the intervals between same-direction zero crossings, as a fraction of
/// the period, for a record to count as periodic. Steady periodic tests repeat to far better
/// than 1 %; 10 % still accepts a ramped start, and rejects earthquake or white-noise records.
const PERIOD_REGULARITY: f64 = 0.10;

/// Velocity tolerance of a constant-velocity ("plateau") sample, relative to the plateau
/// velocity. The rounded reversals of a triangle change the velocity linearly, so 3 % keeps
/// 1.5 % of each arc's duration (their small inertial force is subtracted anyway, see
/// `identify`), and the velocity noise of the paper's slowest test (≈ 1·10⁻⁴ m/s on 1 cm/s
/// after the 8 Hz filter) stays well inside it.
pub const PLATEAU_TOLERANCE: f64 = 0.03;

/// A test whose velocity stays within [`PLATEAU_TOLERANCE`] of its median speed for at least
/// this fraction of a cycle is a triangle test. A sine spends 4 %–20 % of its cycle within
/// 3 %–5 % of any speed level; the paper's triangles spend 70 %–90 % at their plateau
/// (T12, the fastest, 82 %). 40 % sits in the middle of that gap.
pub const TRIANGLE_PLATEAU_FRACTION: f64 = 0.40;

/// Step-response tolerance that sets the reversal window of the dissipative filter: within
/// this window of a velocity reversal the low-passed force is still more than 5 % of the way
/// through the friction jump `2·F_s` (82 ms for the paper's filter), so it says more about
/// how the jump was filtered than about the force at that velocity, and the samples are not
/// used. Outside it the jump's remaining ripple (the Hamming sinc's tail takes 0.33 s to fall
/// below 0.5 %) is removed with the fitted law (see `identify`).
const SETTLE_TOLERANCE: f64 = 0.05;

/// What was found about a test's cycles.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleInfo {
    /// Period, s (from a least-squares fit to every zero crossing of the low-passed
    /// displacement).
    pub period_s: f64,
    /// Fundamental frequency `1/T`, Hz.
    pub frequency_hz: f64,
    /// Number of full cycles in the record.
    pub full_cycles: usize,
    /// Which full cycle was analysed, 1-based (the second-to-last when there are two or more).
    pub cycle_used: usize,
    /// Start of the analysed cycle, s: the upward zero crossing of the displacement about its
    /// offset, so that `u > 0` over the cycle's first half.
    pub cycle_start_s: f64,
    /// Displacement amplitude about the offset, m: half the recorded displacement's
    /// peak-to-peak over the analysed cycle. The recorded samples, not the low-passed ones: a
    /// triangle through the 4× fundamental low-pass loses its corners (T1: 4.81 cm low-passed
    /// against 5.005 cm recorded); transducer noise adds its peak (tens of µm) at most.
    pub amplitude_m: f64,
    /// Displacement offset, m: the mid-range of the recorded displacement over the analysed
    /// cycle.
    pub offset_m: f64,
    /// Fraction of the cycle at constant velocity (within 3 % of the plateau speed).
    pub plateau_fraction: f64,
    /// Total harmonic distortion of the displacement over the cycle (harmonics 2–7 against
    /// the fundamental): 0 for a pure sine, ≈ 0.12 for a sharp triangle.
    pub harmonic_distortion: f64,
    /// The waveform recognised from the data.
    pub detected_kind: TestKind,
    /// Cut-off of the zero-phase Butterworth used for inertial and elastic forces, Hz
    /// (4× the fundamental).
    pub inertial_cutoff_hz: f64,
    /// Cut-off of the FIR used for dissipative forces, Hz (8 Hz).
    pub dissipative_cutoff_hz: f64,
    /// Half-width of the window about each velocity reversal in which the dissipative filter
    /// still smears the friction jump, s.
    pub reversal_window_s: f64,
}

/// Plans shared by every record of one sample rate.
#[derive(Debug, Clone)]
pub(crate) struct RatePlan {
    pub rate_hz: f64,
    pub fir: FirLowpass,
    pub settle_s: f64,
    pub crossover: CrossoverVelocity,
}

impl RatePlan {
    /// The index in `plans` of the plan at `rec`'s sample rate, made and added if there is
    /// none yet (one filter design per rate, however many records share it).
    pub(crate) fn for_record(
        plans: &mut Vec<RatePlan>,
        rec: &TestRecord,
        settings: &ValidSettings,
    ) -> Result<usize> {
        let rate = rec.sample_rate_hz();
        if let Some(i) = plans
            .iter()
            .position(|p| (p.rate_hz - rate).abs() <= 1e-9 * rate)
        {
            return Ok(i);
        }
        plans.push(RatePlan::new(rate, settings, rec.name())?);
        Ok(plans.len() - 1)
    }

    pub(crate) fn new(rate_hz: f64, settings: &ValidSettings, test: &str) -> Result<Self> {
        let signal = |source| IdentError::Signal {
            test: test.to_owned(),
            source,
        };
        let half = (0.5 * settings.dissipative_filter_length_s * rate_hz).round() as usize;
        let order = 2 * half.max(8);
        let fir = FirLowpass::new(
            order,
            settings.dissipative_cutoff_hz,
            rate_hz,
            Window::Hamming,
        )
        .map_err(signal)?;
        let settle_s = settle_time_samples(fir.taps(), SETTLE_TOLERANCE) as f64 / rate_hz;
        let crossover =
            CrossoverVelocity::butterworth(2, settings.crossover_hz, rate_hz).map_err(signal)?;
        Ok(Self {
            rate_hz,
            fir,
            settle_s,
            crossover,
        })
    }
}

/// Samples after (and before) a unit step beyond which the filtered step stays within
/// [`SETTLE_TOLERANCE`] of its final (initial) value.
fn settle_time_samples(taps: &[f64], tolerance: f64) -> usize {
    let m = taps.len() - 1;
    let half = m / 2;
    // Unit step at sample 0 (x = 1 for i ≥ 0). Output at offset d: Σ_{k ≥ half − d} h_k.
    let mut tail = vec![0.0; m + 2];
    for k in (0..=m).rev() {
        tail[k] = tail[k + 1] + taps[k];
    }
    let mut last_bad = 0usize;
    for d in -(half as isize)..=(half as isize) {
        let k = (half as isize - d) as usize;
        let y = tail[k];
        let target = if d >= 0 { 1.0 } else { 0.0 };
        if (y - target).abs() > tolerance {
            last_bad = last_bad.max(if d >= 0 {
                d as usize + 1
            } else {
                (-d) as usize
            });
        }
    }
    last_bad
}

/// A test analysed: the aligned steady-state cycle on a grid, and whole-record channels.
#[derive(Debug, Clone)]
pub(crate) struct Analysed {
    pub info: CycleInfo,
    /// Grid points over the cycle (a multiple of 4); grid point `j` is at
    /// `cycle_start + j·T/n`, so the mirror times of Eq. 10–20 fall on grid points.
    pub n: usize,
    /// First grid point and grid step, in samples of the record.
    pub grid_start: f64,
    pub grid_step: f64,
    /// The dissipative FIR (to filter model forces the same way as the data).
    pub fir: FirLowpass,
    /// The dissipative filter's 0.5 % settling time, s.
    pub arc_reach_s: f64,
    /// Channels low-passed at 4× the fundamental, on the grid (the acceleration: see
    /// `analyse`).
    pub u4: Vec<f64>,
    pub a4: Vec<f64>,
    /// Signed unit impulses at the velocity reversals through the same low-pass, per N·s.
    pub g4: Vec<f64>,
    pub f4: Vec<f64>,
    /// The force itself on the grid (for the plateaus of triangle tests).
    pub f: Vec<f64>,
    /// Channels low-passed by the dissipative FIR, on the grid: the velocity channel, the
    /// force, and the velocity of the filtered displacement (for the plateaus).
    pub v8: Vec<f64>,
    pub f8: Vec<f64>,
    pub vu8: Vec<f64>,
    /// Plateau speed: median of |vu8| over the cycle, m/s.
    pub plateau_speed: f64,
    /// Whole record through the dissipative FIR: displacement, velocity, force, and the
    /// acceleration as the second derivative of the filtered displacement.
    pub rec_u8: Vec<f64>,
    pub rec_v8: Vec<f64>,
    /// The velocity channel itself (given, or the crossover estimate), unfiltered.
    pub rec_v: Vec<f64>,
    pub rec_f8: Vec<f64>,
    pub rec_a8: Vec<f64>,
    /// Samples of the whole record usable for instantaneous fits (away from the edges and
    /// from velocity reversals).
    pub rec_usable: Vec<bool>,
}

/// Zero crossings of `x` (already centred) with hysteresis `threshold`, as fractional sample
/// indices with their direction (true = upward).
fn crossings(x: &[f64], threshold: f64) -> Vec<(f64, bool)> {
    let mut out = Vec::new();
    let mut state = 0i8;
    for i in 0..x.len() {
        let up = x[i] > threshold;
        let down = x[i] < -threshold;
        if (up && state == 1) || (down && state == -1) || !(up || down) {
            continue;
        }
        if state != 0 {
            // The last sign change before i: walk back over samples of the new sign.
            let positive = up;
            let mut k = i;
            while k > 0 && (x[k - 1] > 0.0) == positive && x[k - 1] != 0.0 {
                k -= 1;
            }
            if k > 0 {
                let (a, b) = (x[k - 1], x[k]);
                let frac = if b != a { -a / (b - a) } else { 0.0 };
                out.push(((k - 1) as f64 + frac.clamp(0.0, 1.0), positive));
            }
        }
        state = if up { 1 } else { -1 };
    }
    out
}

fn min_max(x: &[f64]) -> (f64, f64) {
    x.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// Catmull–Rom interpolation of `x` at fractional index `s` (clamped to the record); exact
/// for quadratics.
pub(crate) fn interp(x: &[f64], s: f64) -> f64 {
    let n = x.len();
    let s = s.clamp(0.0, (n - 1) as f64);
    let i = (s.floor() as usize).min(n - 2);
    let f = s - i as f64;
    let at = |k: isize| x[k.clamp(0, n as isize - 1) as usize];
    let (p0, p1, p2, p3) = (
        at(i as isize - 1),
        at(i as isize),
        at(i as isize + 1),
        at(i as isize + 2),
    );
    p1 + 0.5
        * f
        * (p2 - p0 + f * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + f * (3.0 * (p1 - p2) + p3 - p0)))
}

/// Least-squares fit of crossing times `t_k = c + k·T/2 + s_k·δ` (`s_k = ±1` for up/down):
/// returns `(c, T, δ)` in sample units. The offset-free crossings are `c + k·T/2`.
fn fit_crossings(cross: &[(f64, bool)]) -> Option<(f64, f64, f64)> {
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut atb = nalgebra::Vector3::<f64>::zeros();
    for (k, &(t, up)) in cross.iter().enumerate() {
        let row = nalgebra::Vector3::new(1.0, 0.5 * k as f64, if up { 1.0 } else { -1.0 });
        ata += row * row.transpose();
        atb += row * t;
    }
    let sol = ata.lu().solve(&atb)?;
    Some((sol[0], sol[1], sol[2]))
}

/// The errors of one record, naming it.
struct Errors<'a> {
    test: &'a str,
}

impl Errors<'_> {
    fn signal(&self, source: platen_signal::SignalError) -> IdentError {
        IdentError::Signal {
            test: self.test.to_owned(),
            source,
        }
    }

    fn not_periodic(&self, reason: String) -> IdentError {
        IdentError::NotPeriodic {
            test: self.test.to_owned(),
            reason,
        }
    }
}

/// The fundamental frequency from the zero crossings of the raw displacement about its
/// mid-range, Hz, after checking that they are regular.
fn fundamental_hz(u: &[f64], rate: f64, errors: &Errors) -> Result<f64> {
    let (lo, hi) = min_max(u);
    let amp = 0.5 * (hi - lo);
    if amp <= 0.0 {
        return Err(errors.not_periodic("the displacement is constant".into()));
    }
    let mid = 0.5 * (hi + lo);
    let centred: Vec<f64> = u.iter().map(|x| x - mid).collect();
    let rough = crossings(&centred, CROSSING_HYSTERESIS * amp);
    if rough.len() < 3 {
        return Err(errors.not_periodic(format!(
            "the displacement crosses its mid-range {} time(s); one full cycle needs at least 3",
            rough.len()
        )));
    }
    let rough_period = 2.0 * (rough[rough.len() - 1].0 - rough[0].0) / (rough.len() - 1) as f64;
    // Same-direction intervals must all be close to the period.
    for w in rough.windows(3) {
        let interval = w[2].0 - w[0].0;
        if (interval - rough_period).abs() > PERIOD_REGULARITY * rough_period {
            return Err(errors.not_periodic(format!(
                "zero crossings are irregular (an interval of {:.4} s against a mean period of {:.4} s)",
                interval / rate,
                rough_period / rate
            )));
        }
    }
    Ok(rate / rough_period)
}

/// Largest median mismatch of consecutive half-cycles for a record to count as periodic:
/// `√(Σ(x₁ + x₂)² / Σ(x₁² + x₂²))` of the displacement about its mid-range over one half
/// period `x₁` and the next `x₂` (0 for a sine or a triangle, whose second half-cycle is the
/// first one inverted; about 1 for unrelated motion). A steady test with noise and rounded
/// reversals stays below 0.02; an amplitude that grows by 30 % from one half-cycle to the
/// next (a ramped start) gives 0.15, and the median over the half-cycles ignores a ramp at
/// either end. Earthquake records whose few mid-range crossings happen to be regular give
/// 0.4 and more.
pub const HALF_CYCLE_MISMATCH: f64 = 0.15;

/// Largest share of the displacement's energy (`Σ(u − mid)²`) outside the span of its regular
/// cycles (first to last mid-range crossing, widened by a quarter period at each end) for a
/// record to count as periodic. A test at rest before and after its cycles, or with a
/// taper, has almost none there; an earthquake record whose regular crossings cover only part
/// of it has most of its motion outside.
pub const OUTSIDE_CYCLES_ENERGY: f64 = 0.25;

/// Whether `rec` is a periodic test, by its data alone: its displacement crosses its
/// mid-range at least three times at regular intervals (the first check of [`analyse`]),
/// consecutive half-cycles have the same shape inverted (median mismatch below
/// [`HALF_CYCLE_MISMATCH`]), and the cycles hold the motion (at most
/// [`OUTSIDE_CYCLES_ENERGY`] of it outside them). Returns the fundamental frequency, Hz;
/// `Err` says why the record is not periodic.
pub(crate) fn periodicity(rec: &TestRecord) -> Result<f64> {
    let errors = Errors { test: rec.name() };
    let rate = rec.sample_rate_hz();
    let f0 = fundamental_hz(rec.u_m(), rate, &errors)?;
    periodic_shape(rec.u_m(), rate / f0, &errors)?;
    Ok(f0)
}

/// The shape checks of [`periodicity`] on a displacement whose crossings are regular, with
/// period `period` in samples.
fn periodic_shape(u: &[f64], period: f64, errors: &Errors) -> Result<()> {
    let (lo, hi) = min_max(u);
    let mid = 0.5 * (hi + lo);
    let c: Vec<f64> = u.iter().map(|x| x - mid).collect();
    let cross = crossings(&c, CROSSING_HYSTERESIS * 0.5 * (hi - lo));
    let (first, last) = (cross[0].0, cross[cross.len() - 1].0);
    let (from, to) = (first - 0.25 * period, last + 0.25 * period);
    let total: f64 = c.iter().map(|x| x * x).sum();
    let outside: f64 = c
        .iter()
        .enumerate()
        .filter(|&(i, _)| (i as f64) < from || (i as f64) > to)
        .map(|(_, x)| x * x)
        .sum();
    if outside > OUTSIDE_CYCLES_ENERGY * total {
        return Err(errors.not_periodic(format!(
            "{:.0} % of its motion lies outside its {} regular zero crossings (at most {:.0} % in a periodic test)",
            100.0 * outside / total,
            cross.len(),
            100.0 * OUTSIDE_CYCLES_ENERGY
        )));
    }
    // Consecutive half-cycles from each crossing but the last two.
    let half = 0.5 * period;
    let points = half.ceil().max(1.0) as usize;
    let mut mismatch: Vec<f64> = cross[..cross.len() - 2]
        .iter()
        .map(|&(s0, _)| {
            let (mut num, mut den) = (0.0, 0.0);
            for j in 0..points {
                let s = s0 + half * j as f64 / points as f64;
                let (x1, x2) = (interp(&c, s), interp(&c, s + half));
                num += (x1 + x2).powi(2);
                den += x1 * x1 + x2 * x2;
            }
            if den > 0.0 {
                (num / den).sqrt()
            } else {
                1.0
            }
        })
        .collect();
    mismatch.sort_by(f64::total_cmp);
    let median = mismatch[(mismatch.len() - 1) / 2];
    if median > HALF_CYCLE_MISMATCH {
        return Err(errors.not_periodic(format!(
            "its half-cycles do not repeat (median mismatch {:.2} between consecutive half-cycles, at most {HALF_CYCLE_MISMATCH} in a periodic test)",
            median
        )));
    }
    Ok(())
}

/// Every channel of a record through the two low-passes.
struct Filtered {
    sr: SampleRate,
    butter: ButterworthLowpass,
    inertial_cutoff_hz: f64,
    /// The velocity channel (given, or the crossover estimate).
    v_raw: Vec<f64>,
    /// The acceleration of sine tests' inertial force (see [`filter`]).
    a_c: Vec<f64>,
    u4: Vec<f64>,
    f4: Vec<f64>,
    fir: FirLowpass,
    settle_s: f64,
    u8: Vec<f64>,
    v8: Vec<f64>,
    f8: Vec<f64>,
    vu8: Vec<f64>,
}

/// Low-passes the channels of `rec`: at `factor × f0` (Butterworth, zero phase) for inertial
/// and elastic work, and through the dissipative FIR.
fn filter(
    rec: &TestRecord,
    plan: &RatePlan,
    settings: &ValidSettings,
    f0: f64,
    errors: &Errors,
) -> Result<Filtered> {
    let (rate, u) = (rec.sample_rate_hz(), rec.u_m());
    let signal = |e| errors.signal(e);
    // The inertial/elastic low-pass: 4× the fundamental (paper §3), zero phase.
    let inertial_cutoff = settings.inertial_cutoff_factor * f0;
    let butter = ButterworthLowpass::new(settings.butterworth_order, inertial_cutoff, rate)
        .map_err(signal)?;
    let v_raw: Vec<f64> = match rec.v_m_s() {
        Some(v) => v.to_vec(),
        None => plan.crossover.estimate(u, rec.a_m_s2()).map_err(signal)?,
    };
    // Acceleration for inertial work: the displacement's second derivative below the
    // crossover frequency, the accelerometer above it (`a + L(ü − a)`), as the crossover
    // velocity does one derivative lower. At the low frequencies of most tests the
    // accelerometer's noise (0.005 g on the paper's records) would otherwise dominate small
    // inertial forces: 1.5 % of S4's 0.026 g peak per sample after the 4f₀ low-pass, against
    // < 0.1 % from 20 µm of displacement noise.
    let sr = SampleRate::new(rate).map_err(signal)?;
    let a_rec = rec.a_m_s2();
    let udd = differentiate(&differentiate(u, sr), sr);
    let gap: Vec<f64> = udd.iter().zip(a_rec).map(|(x, a)| x - a).collect();
    let low = plan.crossover.low_pass().apply(&gap).map_err(signal)?;
    let a_c: Vec<f64> = a_rec.iter().zip(&low).map(|(a, l)| a + l).collect();
    let u4 = butter.apply(u).map_err(signal)?;
    let f4 = butter.apply(rec.force_n()).map_err(signal)?;
    // The dissipative FIR (order 512 at 8 Hz on 512 Hz data; never below 4× the fundamental).
    let (fir, settle_s) = if plan.fir.cutoff_hz() >= inertial_cutoff {
        (plan.fir.clone(), plan.settle_s)
    } else {
        let order = plan.fir.order();
        let fir = FirLowpass::new(order, inertial_cutoff, rate, Window::Hamming).map_err(signal)?;
        let settle_s = settle_time_samples(fir.taps(), SETTLE_TOLERANCE) as f64 / rate;
        (fir, settle_s)
    };
    let u8 = fir.apply(u).map_err(signal)?;
    let v8 = fir.apply(&v_raw).map_err(signal)?;
    let f8 = fir.apply(rec.force_n()).map_err(signal)?;
    let vu8 = differentiate(&u8, sr);
    Ok(Filtered {
        sr,
        butter,
        inertial_cutoff_hz: inertial_cutoff,
        v_raw,
        a_c,
        u4,
        f4,
        fir,
        settle_s,
        u8,
        v8,
        f8,
        vu8,
    })
}

/// The cycle analysed and its grid, in samples of the record.
struct CycleChoice {
    period: f64,
    full_cycles: usize,
    cycle_used: usize,
    /// Start of the cycle (first grid point).
    tau: f64,
    /// Grid points over the cycle, and their spacing.
    n: usize,
    step: f64,
}

/// Fits the period to the crossings of the low-passed displacement `u4` and chooses the
/// cycle: the second-to-last full one, from its offset-free upward zero crossing.
fn choose_cycle(u4: &[f64], rate: f64, errors: &Errors) -> Result<CycleChoice> {
    let (lo4, hi4) = min_max(u4);
    let amp4 = 0.5 * (hi4 - lo4);
    let mid4 = 0.5 * (hi4 + lo4);
    let c4: Vec<f64> = u4.iter().map(|x| x - mid4).collect();
    let fine = crossings(&c4, CROSSING_HYSTERESIS * amp4);
    if fine.len() < 3 {
        return Err(errors
            .not_periodic("the low-passed displacement has fewer than 3 zero crossings".into()));
    }
    let (c, period, _delta) = fit_crossings(&fine)
        .ok_or_else(|| errors.not_periodic("the zero crossings do not fit a period".into()))?;
    if !(period.is_finite() && period > 4.0) {
        return Err(errors.not_periodic(format!(
            "period of {period:.2} samples is too short for the sample rate"
        )));
    }
    // Offset-free upward crossings: c + k·T/2 for the k of upward crossings.
    let up_parity = fine
        .iter()
        .position(|&(_, up)| up)
        .map(|k| k % 2)
        .unwrap_or(0);
    let first_up = c + up_parity as f64 * 0.5 * period;
    // A cycle is full when every point of its grid (n points, spacing T/n ≤ 1 sample, the
    // last one a step short of the next cycle) lies within the record, to half a sample.
    let n = 4 * ((period / 4.0).ceil() as usize).max(4);
    let step = period / n as f64;
    let tol = 0.5;
    let last = (u4.len() - 1) as f64;
    // Cycle starts τ_m = first_up + m·T with τ_m ≥ −tol and τ_m + T − step ≤ last + tol.
    let m_lo = ((-tol - first_up) / period).ceil() as i64;
    let m_hi = ((last + tol - (period - step) - first_up) / period).floor() as i64;
    if m_hi < m_lo {
        return Err(IdentError::NoFullCycle {
            test: errors.test.to_owned(),
            period_s: period / rate,
            span_s: last / rate,
        });
    }
    let full_cycles = (m_hi - m_lo + 1) as usize;
    let (m_used, cycle_used) = if full_cycles >= 2 {
        (m_hi - 1, full_cycles - 1)
    } else {
        (m_hi, 1)
    };
    Ok(CycleChoice {
        period,
        full_cycles,
        cycle_used,
        tau: first_up + m_used as f64 * period,
        n,
        step,
    })
}

impl CycleChoice {
    /// Half the peak-to-peak and the mid-range of `u` over the recorded samples of the
    /// cycle, `τ ≤ i ≤ τ + T`.
    fn recorded_amplitude(&self, u: &[f64]) -> (f64, f64) {
        let first = self.tau.ceil().max(0.0) as usize;
        let last = ((self.tau + self.period).floor() as usize).min(u.len() - 1);
        let (lo, hi) = min_max(&u[first.min(last)..=last]);
        (0.5 * (hi - lo), 0.5 * (hi + lo))
    }

    /// `x` interpolated on the cycle's grid.
    fn on_grid(&self, x: &[f64]) -> Vec<f64> {
        (0..self.n)
            .map(|j| interp(x, self.tau + j as f64 * self.step))
            .collect()
    }
}

/// The plateau speed (median of `|v|` over the cycle), the fraction of the cycle within
/// [`PLATEAU_TOLERANCE`] of it, and the waveform that fraction says.
fn waveform(g_vu8: &[f64]) -> (f64, f64, TestKind) {
    let n = g_vu8.len();
    let mut speeds: Vec<f64> = g_vu8.iter().map(|v| v.abs()).collect();
    speeds.sort_by(f64::total_cmp);
    let plateau_speed = speeds[n / 2];
    let plateau_fraction = g_vu8
        .iter()
        .filter(|v| (v.abs() - plateau_speed).abs() <= PLATEAU_TOLERANCE * plateau_speed)
        .count() as f64
        / n as f64;
    let detected_kind = if plateau_fraction >= TRIANGLE_PLATEAU_FRACTION {
        TestKind::Triangle
    } else {
        TestKind::Sine
    };
    (plateau_speed, plateau_fraction, detected_kind)
}

/// Unit impulses at the velocity reversals of `vu4`, signed as the new motion, each of area
/// 1 N·s split between the two neighbouring samples.
fn reversal_impulses(vu4: &[f64], rate: f64) -> Vec<f64> {
    let n_rec = vu4.len();
    let mut impulses = vec![0.0; n_rec];
    for i in 1..n_rec {
        let (a, b) = (vu4[i - 1], vu4[i]);
        if (a > 0.0) != (b > 0.0) && a != b {
            let frac = (a / (a - b)).clamp(0.0, 1.0);
            let sign = if b > 0.0 { 1.0 } else { -1.0 };
            impulses[i - 1] += sign * (1.0 - frac) * rate;
            impulses[i] += sign * frac * rate;
        }
    }
    impulses
}

/// Total harmonic distortion (harmonics 2–7 over the fundamental) of one cycle on a grid.
fn harmonic_distortion(g_u4: &[f64]) -> f64 {
    let n = g_u4.len();
    let mean_u = g_u4.iter().sum::<f64>() / n as f64;
    let harmonic = |k: usize| -> f64 {
        let (mut re, mut im) = (0.0, 0.0);
        for (j, x) in g_u4.iter().enumerate() {
            let ph = 2.0 * PI * (k * j) as f64 / n as f64;
            re += (x - mean_u) * ph.cos();
            im -= (x - mean_u) * ph.sin();
        }
        2.0 * (re * re + im * im).sqrt() / n as f64
    };
    let h1 = harmonic(1);
    ((2..=7).map(|k| harmonic(k).powi(2)).sum::<f64>()).sqrt() / h1.max(f64::MIN_POSITIVE)
}

/// Samples of the whole record usable for instantaneous fits: away from the filter's edges
/// and from the velocity reversals by the reversal window.
fn usable_samples(filtered: &Filtered, rate: f64) -> Vec<bool> {
    let (v8, n_rec) = (&filtered.v8, filtered.v8.len());
    let settle = (filtered.settle_s * rate).ceil() as usize;
    let edge = filtered.fir.order() / 2;
    let mut rec_usable = vec![true; n_rec];
    for flag in rec_usable.iter_mut().take(edge.min(n_rec)) {
        *flag = false;
    }
    for flag in rec_usable.iter_mut().skip(n_rec.saturating_sub(edge)) {
        *flag = false;
    }
    for i in 1..n_rec {
        if (v8[i - 1] > 0.0) != (v8[i] > 0.0) {
            let lo = i.saturating_sub(settle);
            let hi = (i + settle).min(n_rec);
            for flag in &mut rec_usable[lo..hi] {
                *flag = false;
            }
        }
    }
    rec_usable
}

/// Marks unusable the samples of a triangle test off its plateaus or within `reach`
/// samples of them: how far the arcs' inertial transients (M·A_r, up to MN) leak into a
/// plateau through the filter's tail.
fn keep_plateaus_only(rec_usable: &mut [bool], vu8: &[f64], plateau_speed: f64, reach: usize) {
    let n_rec = vu8.len();
    let off: Vec<bool> = vu8
        .iter()
        .map(|v| (v.abs() - plateau_speed).abs() > PLATEAU_TOLERANCE * plateau_speed)
        .collect();
    let mut last_off: Option<usize> = None;
    for i in 0..n_rec {
        if off[i] {
            last_off = Some(i);
        }
        if last_off.is_some_and(|k| i - k <= reach) {
            rec_usable[i] = false;
        }
    }
    let mut next_off: Option<usize> = None;
    for i in (0..n_rec).rev() {
        if off[i] {
            next_off = Some(i);
        }
        if next_off.is_some_and(|k| k - i <= reach) {
            rec_usable[i] = false;
        }
    }
}

/// The acceleration of the inertial force and the reversal impulses, through the 4×
/// fundamental low-pass.
fn inertial_channels(
    rec: &TestRecord,
    filtered: &Filtered,
    kind: TestKind,
    errors: &Errors,
) -> Result<(Vec<f64>, Vec<f64>)> {
    // The acceleration of the inertial force: on sines the crossover above; on triangles the
    // accelerometer itself. A triangle's acceleration jumps at the ends of its reversal arcs
    // (0 to ±A_r), and sampled displacement cannot place a jump within a sample interval: the
    // displacement-derived acceleration then carries a spurious impulse of up to A_r·Δt/2 per
    // jump (on T12, 144 t × 24 m/s² × 1 ms ≈ 3.4 kN·s), which the low-pass turns into kilonewtons
    // of force. The accelerometer's noise matters less there: the reversal arcs are large.
    let errs = |e| errors.signal(e);
    let a4 = match kind {
        TestKind::Sine => filtered.butter.apply(&filtered.a_c),
        TestKind::Triangle => filtered.butter.apply(rec.a_m_s2()),
    }
    .map_err(errs)?;
    // Unit impulses at the velocity reversals, signed as the new motion, through the same
    // low-pass: the shape of a force impulse at each reversal (see `identify`).
    let vu4 = differentiate(&filtered.u4, filtered.sr);
    let g4 = filtered
        .butter
        .apply(&reversal_impulses(&vu4, rec.sample_rate_hz()))
        .map_err(errs)?;
    Ok((a4, g4))
}

/// Analyses one record: period, waveform, steady-state cycle, filtered channels.
pub(crate) fn analyse(
    rec: &TestRecord,
    plan: &RatePlan,
    settings: &ValidSettings,
) -> Result<Analysed> {
    let rate = rec.sample_rate_hz();
    let errors = Errors { test: rec.name() };
    let f0 = fundamental_hz(rec.u_m(), rate, &errors)?;
    let filtered = filter(rec, plan, settings, f0, &errors)?;
    let cycle = choose_cycle(&filtered.u4, rate, &errors)?;
    let g_vu8 = cycle.on_grid(&filtered.vu8);
    let (plateau_speed, plateau_fraction, detected_kind) = waveform(&g_vu8);
    let kind = rec.kind().unwrap_or(detected_kind);
    let (a4, g4) = inertial_channels(rec, &filtered, kind, &errors)?;
    let g_u4 = cycle.on_grid(&filtered.u4);
    let (amplitude_m, offset_m) = cycle.recorded_amplitude(rec.u_m());
    let thd = harmonic_distortion(&g_u4);
    let mut rec_usable = usable_samples(&filtered, rate);
    // The filter's 0.5 % settling time: how far the arcs' inertial transients reach.
    let reach = settle_time_samples(filtered.fir.taps(), 0.005);
    if kind == TestKind::Triangle {
        // Only the plateaus, away from the reversal arcs by that time.
        keep_plateaus_only(&mut rec_usable, &filtered.vu8, plateau_speed, reach);
    }
    let info = CycleInfo {
        period_s: cycle.period / rate,
        frequency_hz: rate / cycle.period,
        full_cycles: cycle.full_cycles,
        cycle_used: cycle.cycle_used,
        cycle_start_s: rec.start_s() + cycle.tau / rate,
        amplitude_m,
        offset_m,
        plateau_fraction,
        harmonic_distortion: thd,
        detected_kind,
        inertial_cutoff_hz: filtered.inertial_cutoff_hz,
        dissipative_cutoff_hz: filtered.fir.cutoff_hz(),
        reversal_window_s: filtered.settle_s,
    };
    // For the instantaneous (global) fit, the second derivative of the low-passed
    // displacement: zero phase, unlike the accelerometer's conditioner (see `global`).
    let rec_a8 = differentiate(&filtered.vu8, filtered.sr);
    Ok(Analysed {
        info,
        n: cycle.n,
        grid_start: cycle.tau,
        grid_step: cycle.step,
        arc_reach_s: reach as f64 / rate,
        u4: g_u4,
        a4: cycle.on_grid(&a4),
        g4: cycle.on_grid(&g4),
        f4: cycle.on_grid(&filtered.f4),
        f: cycle.on_grid(rec.force_n()),
        v8: cycle.on_grid(&filtered.v8),
        f8: cycle.on_grid(&filtered.f8),
        vu8: g_vu8,
        plateau_speed,
        rec_u8: filtered.u8,
        rec_v8: filtered.v8,
        rec_v: filtered.v_raw,
        rec_f8: filtered.f8,
        rec_a8,
        rec_usable,
        fir: filtered.fir,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catmull_rom_is_exact_for_quadratics() {
        let x: Vec<f64> = (0..10)
            .map(|i| 0.5 * (i * i) as f64 - 3.0 * i as f64 + 1.0)
            .collect();
        for s in [1.25, 3.5, 6.9] {
            let want = 0.5 * s * s - 3.0 * s + 1.0;
            assert!((interp(&x, s) - want).abs() < 1e-12, "{s}");
        }
    }

    #[test]
    fn crossings_of_a_sine_are_found_with_direction_and_sub_sample_accuracy() {
        let period = 100.0;
        let x: Vec<f64> = (0..1000)
            .map(|i| (2.0 * PI * (i as f64 - 10.3) / period).sin())
            .collect();
        let c = crossings(&x, 0.25);
        // Upward crossings at 10.3 + 100k, downward at 60.3 + 100k, up to 960.3.
        assert_eq!(c.len(), 20);
        assert!(c[0].1 && !c[1].1);
        assert!((c[0].0 - 10.3).abs() < 2e-3, "{:?}", c[0]);
        assert!((c[1].0 - 60.3).abs() < 2e-3, "{:?}", c[1]);
        let (c0, t, delta) = fit_crossings(&c).unwrap();
        assert!((t - period).abs() < 1e-4, "{t}");
        assert!((c0 - 10.3).abs() < 2e-3, "{c0}");
        assert!(delta.abs() < 1e-3, "{delta}");
    }

    #[test]
    fn the_order_512_fir_at_8_hz_settles_to_5_percent_in_82_ms_and_to_half_a_percent_in_a_third_of_a_second(
    ) {
        let fir = FirLowpass::new(512, 8.0, 512.0, Window::Hamming).unwrap();
        // 5 %: 82 ms; 0.5 %: 0.33 s (the Hamming sinc's slow tail).
        let s = settle_time_samples(fir.taps(), 0.05);
        assert_eq!(s, 42);
        assert_eq!(settle_time_samples(fir.taps(), 0.005), 170);
    }
}
