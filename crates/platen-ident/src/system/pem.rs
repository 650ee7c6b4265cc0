//! The loop fitted by its prediction error: the equation-error values of the plant refined
//! so that the identified closed loop, run on each fitted record's command, reproduces the
//! recorded table and storey accelerations.
//!
//! # The fit
//!
//! * **Model**: [`platen_integrate::forward_closed_loop`] from rest at the command's first
//!   sample, RK4 at the steps per period the judgement takes for the starting loop (held for
//!   the whole fit, so the cost is one smooth function of the parameters), exactly as
//!   [`super::Judgement`] runs it.
//! * **Residuals**: for every fitted record, the table's acceleration and each storey's,
//!   and the pressure difference `Δp` where every fitted record has it, recorded and
//!   predicted both through the judgement's zero-phase low-pass
//!   ([`super::JUDGE_LOWPASS_HZ`]), their difference divided by the channel's RMS over all
//!   fitted records (so the table and each storey weigh alike, whatever their amplitudes),
//!   less each record's channel's mean residual (its sensor's zero offset, a nuisance
//!   parameter solved in closed form: an accelerometer's, or `Δp`'s, which a table at rest
//!   holding its friction cannot zero). `Δp` is the force over the area: without it the
//!   accelerations leave the plant's force scale (masses, friction, flow, volume) in a
//!   flat valley; on the stand-ins of `tests/data/real_table` the fit without it put the
//!   platen's mass 29 % above the truth (with it 7 %) for a held-out NRMSE 1–2 points lower. The records start at rest, so no transient is
//!   discarded. The cost is the mean square of these residuals; each channel's NRMSE is the
//!   root of its own mean square.
//! * **Parameters** (each as its value relative to the start, `ln(p/p₀)`, so that a step
//!   is a relative change and a positive value stays positive): the platen's mass, Coulomb
//!   force, viscous coefficient, the Stribeck amplitude and the viscous exponent (those two
//!   only when the equation error gives them: a Stribeck amplitude `> 0`, an exponent other
//!   than 1; the exponent moves linearly in `[0, 1]`), each storey's mass, stiffness and
//!   damping, the valves' rated flow, the valve lag (delay and spool period scaled together:
//!   only their sum `τ + 2ζ/ω_n` is seen in the records' band) and the chambers' volume (both
//!   together). A viscous coefficient the equation error holds at 0 moves linearly from 0,
//!   `≥ 0`. A storey damping held at 0 stays there.
//! * **Not the controller's gains**: they stay the drive regression's (`identify_system`),
//!   linear in the recorded drive and within 0.3 % of the truth on the stand-ins of
//!   `tests/data/real_table`. The accelerations alone do not pin them: with the gains free
//!   the fit walked them along a valley with the plant's force scale (there `K_p` went from
//!   14.26 to 23.8 /m, `K_vf` from 0.440 to 0.791 s/m and `K_Δp` from 2.39e-9 to 6.33e-9 /Pa,
//!   truth 14.3, 0.44, 2.4e-9, for a held-out NRMSE within 0.5 points of the fit without
//!   them; forward differences, accelerations only); with the recorded drive compared as
//!   well, that search stopped in a local minimum of heavily damped storeys (held-out table
//!   NRMSE 55 %).
//! * **Jacobian**: central differences of step [`FD_STEP`] in those coordinates (1 % of
//!   each value), one-sided where a side's run fails. The residuals are smooth in the
//!   parameters except where a small change moves a stick or slip event across a sample
//!   instant (the platen's acceleration jumps there): a step of 1 % averages those jumps
//!   over many events rather than resolving one, and the central difference's truncation
//!   error (the step squared times the third derivative, 1e-4 relative) is far below the
//!   parameters' uncertainty. Forward differences (half the runs) were tried and stalled: on
//!   the round trip of `tests/prediction_error.rs` they stopped at twice the noise's NRMSE
//!   with the platen's mass 9 % off and no descent direction left; central ones converge
//!   there in 10 iterations to the noise (every value within 2 % but the viscous
//!   coefficient's).
//! * **Which parameters**: at the start, a parameter whose Jacobian column is below
//!   [`MIN_COLUMN_NORM`] of the largest (the records do not see it), or whose column the
//!   others reproduce to a multiple correlation above [`MAX_CORRELATION`] (one of a pair the
//!   records cannot tell apart; the larger variance inflation goes first), is held at its
//!   start and listed in [`super::SystemIdentification::not_identified`].
//! * **Levenberg–Marquardt**: Marquardt's damping `λ·diag(JᵀJ)`, `λ` divided by 10 after a
//!   step that lowers the cost, multiplied by 10 after one that does not. A run that fails
//!   (the integrator, or values no table system takes) is a rejected step. The fit converges
//!   when the full Gauss–Newton step `−(JᵀJ)⁻¹Jᵀr` would lower the sum of squares by less
//!   than [`CHI2_TOLERANCE`] times the residuals' effective variance `σ²·τ` (the score
//!   statistic `rᵀJ(JᵀJ)⁻¹Jᵀr/σ²τ`: no step can improve the fit by a meaningful fraction
//!   of one standard error); it stops unconverged after [`MAX_ITERATIONS`] iterations, or
//!   when no damping gives a lower cost.
//! * **Standard errors**: `σ²·τ·(JᵀJ)⁻¹` at the final values, `σ²` the residuals' mean
//!   square over `N − p`, `τ` their integrated autocorrelation time in samples (the band-
//!   limited residuals are strongly correlated from sample to sample: without `τ` the errors
//!   would be `√τ` too small). [`PredictionErrorFit::effective_residuals`] is `N/τ`. They are
//!   conditional on the model's structure: a residual that is model error, not noise, is
//!   treated as noise.
//!
//! The fit is deterministic: the runs are independent and collected in order (rayon over
//! the Jacobian's columns and the records), and every sum is in a fixed order.

use nalgebra::{DMatrix, DVector};
use platen_integrate::{
    forward_closed_loop, LoopMethod, LoopRun, Motion, Sample, SampleSink, State,
};
use platen_model::{IdentifiedModel, IdentifiedParams, Specimen, Storey};
use platen_signal::{ButterworthLowpass, ZeroPhaseFilter};
use platen_system::{TableSystem, TableSystemParts};
use rayon::prelude::*;

use super::plant::{IdentifiedPlant, STROKE_FRACTION_OF_ROOM};
use super::{SystemRecord, JUDGE_LOWPASS_HZ};
use crate::error::{IdentError, Result};

/// Most Levenberg–Marquardt iterations (Jacobians).
pub const MAX_ITERATIONS: usize = 30;
/// Central-difference step of the Jacobian, in the parameters' coordinates (relative for the
/// logarithmic ones: 1 %).
pub const FD_STEP: f64 = 1e-2;
/// The fit stops when the full Gauss–Newton step would lower the sum of squares by less
/// than this many effective residual variances `σ²·τ` (the score statistic).
pub const CHI2_TOLERANCE: f64 = 0.1;
/// A Jacobian column below this fraction of the largest column's norm: not seen.
pub const MIN_COLUMN_NORM: f64 = 1e-6;
/// Multiple correlation of a Jacobian column with the others above which the parameter is
/// held (the records cannot tell it from the others).
pub const MAX_CORRELATION: f64 = 0.9999;
/// Largest relative change of a logarithmic parameter over the whole fit (`e^±5`).
const MAX_LOG_CHANGE: f64 = 5.0;
/// Largest Marquardt damping before the fit gives up on a lower cost.
const MAX_LAMBDA: f64 = 1e10;

/// One refined parameter.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PemParameter {
    /// What it is: its path in the printed scenario where it is one value
    /// (`model.identified.effective_mass_kg`, `specimen.storeys[0].stiffness_n_per_m`,
    /// `table_system.controller.displacement_gain_per_m`, …), else what it scales
    /// (`table_system.servo_valve.equivalent_lag_s`: the delay and the spool's period
    /// together; `table_system.actuator.chamber_volume_m3`: both chambers).
    pub key: String,
    /// The equation error's value (the start), in the key's unit.
    pub start: f64,
    /// The refined value.
    pub value: f64,
    /// Its standard error (see the module docs), in the key's unit; absent when held.
    pub std_error: Option<f64>,
    /// Whether the fit moved it (else it is held at the start: see `not_identified`).
    pub refined: bool,
}

/// One channel's fit on the fitted records.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChannelFit {
    /// `a_m_s2` (the table) or `storey{i}_a_m_s2`.
    pub channel: String,
    /// NRMSE in the band over every fitted record (RMS of recorded less predicted over the
    /// recorded RMS), with the equation error's values.
    pub nrmse_before: f64,
    /// The same with the refined values.
    pub nrmse_after: f64,
}

/// The prediction-error fit of the loop (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PredictionErrorFit {
    /// Levenberg–Marquardt iterations (Jacobians that led to a step).
    pub iterations: usize,
    /// Whether it stopped on the statistical criterion (else on the iteration cap or with no
    /// lower cost found).
    pub converged: bool,
    /// Why it stopped.
    pub stop_reason: String,
    /// Steps rejected (a higher cost or a failed run).
    pub rejected_steps: usize,
    /// Runs that failed (the integrator or values no table system takes).
    pub failed_runs: usize,
    /// Mean square of the normalised residuals with the equation error's values.
    pub cost_before: f64,
    /// The same with the refined values.
    pub cost_after: f64,
    /// Residuals (samples × channels over the fitted records).
    pub residuals: usize,
    /// The residuals' integrated autocorrelation time, samples.
    pub correlation_time_samples: f64,
    /// `residuals / correlation_time_samples`: the independent residuals the standard
    /// errors count.
    pub effective_residuals: f64,
    /// RK4 steps per controller period of the fit's runs.
    pub steps_per_period: u32,
    /// Band of the compared accelerations, Hz.
    pub band_hz: f64,
    /// Each channel's NRMSE before and after.
    pub channels: Vec<ChannelFit>,
    /// Every parameter, refined or held.
    pub parameters: Vec<PemParameter>,
}

/// What a parameter is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Mass,
    Coulomb,
    Viscous,
    Stribeck,
    Exponent,
    StoreyMass(usize),
    StoreyStiffness(usize),
    StoreyDamping(usize),
    RatedFlow,
    ValveLag,
    ChamberVolume,
}

/// How a parameter's coordinate `θ` gives its value.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Coordinate {
    /// `start·e^θ`, `|θ| ≤ MAX_LOG_CHANGE`.
    Log,
    /// `unit·θ`, `θ·unit ∈ [min, max]`.
    Linear { unit: f64, min: f64, max: f64 },
}

#[derive(Debug, Clone)]
struct Param {
    kind: Kind,
    key: String,
    start: f64,
    coordinate: Coordinate,
}

impl Param {
    fn theta0(&self) -> f64 {
        match self.coordinate {
            Coordinate::Log => 0.0,
            Coordinate::Linear { unit, .. } => self.start / unit,
        }
    }

    fn value(&self, theta: f64) -> f64 {
        match self.coordinate {
            Coordinate::Log => self.start * theta.exp(),
            Coordinate::Linear { unit, .. } => unit * theta,
        }
    }

    fn project(&self, theta: f64) -> f64 {
        match self.coordinate {
            Coordinate::Log => theta.clamp(-MAX_LOG_CHANGE, MAX_LOG_CHANGE),
            Coordinate::Linear { unit, min, max } => theta.clamp(min / unit, max / unit),
        }
    }

    /// `d value / d θ` at `theta`.
    fn derivative(&self, theta: f64) -> f64 {
        match self.coordinate {
            Coordinate::Log => self.value(theta),
            Coordinate::Linear { unit, .. } => unit,
        }
    }
}

/// The loop's values: what a parameter vector sets.
#[derive(Debug, Clone)]
struct Values {
    parts: TableSystemParts,
    model: IdentifiedParams,
    storeys: Vec<Storey>,
}

/// A loop ready to run.
struct Built {
    system: TableSystem,
    model: IdentifiedModel,
    specimen: Option<Specimen>,
}

impl Values {
    /// These values with `params` at `theta`.
    fn with(&self, params: &[Param], theta: &[f64]) -> Values {
        let mut v = self.clone();
        for (p, &t) in params.iter().zip(theta) {
            let x = p.value(t);
            match p.kind {
                Kind::Mass => v.model.effective_mass_kg = x,
                Kind::Coulomb => v.model.coulomb_force_n = x,
                Kind::Viscous => v.model.viscous_coefficient = x,
                Kind::Stribeck => v.model.low_velocity_force_n = x,
                Kind::Exponent => v.model.viscous_exponent = x,
                Kind::StoreyMass(j) => v.storeys[j].mass_kg = x,
                Kind::StoreyStiffness(j) => v.storeys[j].stiffness_n_per_m = x,
                Kind::StoreyDamping(j) => v.storeys[j].damping_n_s_per_m = x,
                Kind::RatedFlow => v.parts.servo_valve.rated_flow_m3_s = x,
                Kind::ValveLag => {
                    let s = x / p.start;
                    v.parts.servo_valve.delay_s = self.parts.servo_valve.delay_s * s;
                    v.parts.servo_valve.natural_frequency_hz =
                        self.parts.servo_valve.natural_frequency_hz / s;
                }
                Kind::ChamberVolume => {
                    let s = x / p.start;
                    v.parts.actuator.cap_volume_m3 = self.parts.actuator.cap_volume_m3 * s;
                    v.parts.actuator.rod_volume_m3 = self.parts.actuator.rod_volume_m3 * s;
                }
            }
        }
        v
    }

    /// The stroke limit the identification gives these chambers.
    fn stroke_m(&self) -> f64 {
        let a = &self.parts.actuator;
        STROKE_FRACTION_OF_ROOM
            * (a.cap_volume_m3 / a.cap_area_m2).min(a.rod_volume_m3 / a.rod_area_m2)
    }

    /// The loop, if these values make one.
    fn build(&self) -> Option<Built> {
        let system = TableSystem::new(self.parts, self.stroke_m()).ok()?;
        let model = self.model.build().ok()?;
        let specimen = if self.storeys.is_empty() {
            None
        } else {
            Some(Specimen::new(self.storeys.clone()).ok()?)
        };
        Some(Built {
            system,
            model,
            specimen,
        })
    }
}

/// A compared channel.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Channel {
    /// The table's acceleration.
    Table,
    /// Storey `k`'s acceleration (from 0, bottom first).
    Storey(usize),
    /// The pressure difference `Δp`.
    DeltaP,
}

impl Channel {
    /// Its column name.
    fn name(self) -> String {
        match self {
            Channel::Table => "a_m_s2".into(),
            Channel::Storey(k) => format!("storey{}_a_m_s2", k + 1),
            Channel::DeltaP => "delta_p_pa".into(),
        }
    }

    /// Its recording in `r`.
    fn recorded(self, r: &SystemRecord) -> Option<&[f64]> {
        match self {
            Channel::Table => r.a_m_s2.as_deref(),
            Channel::Storey(k) => r.storey_a_m_s2.get(k).map(Vec::as_slice),
            Channel::DeltaP => r.delta_p_pa.as_deref(),
        }
    }
}

/// One fitted record, ready to be compared.
struct Target<'a> {
    record: &'a SystemRecord,
    command: Motion,
    lowpass: ButterworthLowpass,
    /// The recorded channels in the band, in the problem's order.
    channels: Vec<Vec<f64>>,
}

/// The compared channels of a run.
struct Collect<'c> {
    channels: &'c [Channel],
    out: Vec<Vec<f64>>,
}

impl SampleSink for Collect<'_> {
    fn accept(&mut self, s: &Sample) {
        for (c, out) in self.channels.iter().zip(&mut self.out) {
            out.push(match *c {
                Channel::Table => s.a_m_s2,
                Channel::Storey(k) => s
                    .specimen
                    .as_ref()
                    .and_then(|sp| sp.a_m_s2.get(k).copied())
                    .unwrap_or(f64::NAN),
                Channel::DeltaP => s.system.as_ref().map_or(f64::NAN, |x| x.delta_p_pa),
            });
        }
    }
}

/// The prediction-error problem: the fitted records, the starting values, the parameters.
struct Problem<'a> {
    targets: Vec<Target<'a>>,
    /// The compared channels.
    channels: Vec<Channel>,
    /// Each channel's RMS over every fitted record, in the band.
    scale: Vec<f64>,
    start: Values,
    params: Vec<Param>,
    steps_per_period: u32,
}

impl Problem<'_> {
    /// The residuals (record by record, channel by channel) at `theta`; `None` when a run
    /// fails or the values make no loop.
    fn residuals(&self, theta: &[f64]) -> Option<Vec<f64>> {
        let built = self.start.with(&self.params, theta).build()?;
        let blocks: Vec<Option<Vec<f64>>> = self
            .targets
            .par_iter()
            .map(|t| self.record_residuals(&built, t))
            .collect();
        let mut out = Vec::with_capacity(self.len());
        for b in blocks {
            out.extend(b?);
        }
        Some(out)
    }

    /// Total residuals.
    fn len(&self) -> usize {
        self.targets
            .iter()
            .map(|t| t.channels.len() * t.record.t_s.len())
            .sum()
    }

    /// The residual blocks `(channel, length)` in order (a record's channel each).
    fn blocks(&self) -> Vec<(usize, usize)> {
        self.targets
            .iter()
            .flat_map(|t| (0..t.channels.len()).map(|c| (c, t.record.t_s.len())))
            .collect()
    }

    fn record_residuals(&self, built: &Built, t: &Target<'_>) -> Option<Vec<f64>> {
        let r = t.record;
        let run = LoopRun {
            system: &built.system,
            specimen: built.specimen.as_ref(),
            command: &t.command,
            method: LoopMethod::Rk4 {
                steps_per_period: self.steps_per_period,
            },
            initial: State {
                u_m: r.command_u_m[0],
                v_m_s: 0.0,
            },
        };
        let n = r.t_s.len();
        let mut sink = Collect {
            channels: &self.channels,
            out: vec![Vec::with_capacity(n); self.channels.len()],
        };
        forward_closed_loop(&built.model, &run, n, &mut sink).ok()?;
        let mut out = Vec::with_capacity(n * t.channels.len());
        for ((rec, pred), scale) in t.channels.iter().zip(&sink.out).zip(&self.scale) {
            if pred.len() != n {
                return None;
            }
            let pred = t.lowpass.apply(pred).ok()?;
            // Less the block's mean: each record's channel has its own zero offset.
            let mean = rec.iter().zip(&pred).map(|(x, y)| x - y).sum::<f64>() / n as f64;
            out.extend(rec.iter().zip(&pred).map(|(x, y)| (x - y - mean) / scale));
        }
        out.iter().all(|x| x.is_finite()).then_some(out)
    }

    /// Central-difference Jacobian columns `cols` at `theta` (residuals `r0` there); a
    /// column with a side that fails is taken one-sided from the other. `None` when both
    /// fail.
    fn jacobian(&self, theta: &[f64], r0: &[f64], cols: &[usize]) -> (Option<DMatrix<f64>>, usize) {
        let columns: Vec<(Option<Vec<f64>>, usize)> = cols
            .par_iter()
            .map(|&j| {
                let mut failed = 0;
                // Both sides where both run (central), else the side that runs.
                let mut side = |step: f64| {
                    let mut t = theta.to_vec();
                    t[j] = self.params[j].project(t[j] + step);
                    let dt = t[j] - theta[j];
                    if dt == 0.0 {
                        return None;
                    }
                    let r = self.residuals(&t);
                    failed += usize::from(r.is_none());
                    r.map(|r| (r, dt))
                };
                let plus = side(FD_STEP);
                let minus = side(-FD_STEP);
                let col: Option<Vec<f64>> = match (plus, minus) {
                    (Some((rp, dp)), Some((rm, dm))) => Some(
                        rp.iter()
                            .zip(&rm)
                            .map(|(a, b)| (a - b) / (dp - dm))
                            .collect(),
                    ),
                    (Some((r, d)), None) | (None, Some((r, d))) => {
                        Some(r.iter().zip(r0).map(|(a, b)| (a - b) / d).collect())
                    }
                    (None, None) => None,
                };
                if col.is_some() {
                    return (col, failed);
                }
                (None, failed)
            })
            .collect();
        let failed = columns.iter().map(|c| c.1).sum();
        let mut jac = DMatrix::zeros(r0.len(), cols.len());
        for (k, (c, _)) in columns.into_iter().enumerate() {
            let Some(c) = c else {
                return (None, failed);
            };
            jac.set_column(k, &DVector::from_vec(c));
        }
        (Some(jac), failed)
    }

    /// Each channel's NRMSE from residuals `r`.
    fn channel_nrmse(&self, r: &[f64]) -> Vec<f64> {
        let channels = self.scale.len();
        let mut ss = vec![0.0; channels];
        let mut n = vec![0usize; channels];
        let mut at = 0;
        for (c, len) in self.blocks() {
            ss[c] += r[at..at + len].iter().map(|x| x * x).sum::<f64>();
            n[c] += len;
            at += len;
        }
        ss.iter()
            .zip(&n)
            .map(|(s, &n)| (s / n.max(1) as f64).sqrt())
            .collect()
    }

    /// The residuals' integrated autocorrelation time, samples ([`correlation_time`] of
    /// each block, weighted by its length).
    fn correlation_time(&self, r: &[f64]) -> f64 {
        let mut at = 0;
        let (mut sum, mut total) = (0.0, 0usize);
        for (_, len) in self.blocks() {
            sum += correlation_time(&r[at..at + len]) * len as f64;
            at += len;
            total += len;
        }
        if total == 0 {
            1.0
        } else {
            (sum / total as f64).max(1.0)
        }
    }
}

/// The integrated autocorrelation time of `x`, samples: `1 + 2Σρ_k` over the lags up to
/// the first non-positive autocorrelation (at most 1000 lags, at most a quarter of `x`).
fn correlation_time(x: &[f64]) -> f64 {
    let len = x.len();
    if len == 0 {
        return 1.0;
    }
    let mean = x.iter().sum::<f64>() / len as f64;
    let c0: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
    if c0 <= 0.0 {
        return 1.0;
    }
    let mut tau = 1.0;
    for k in 1..(len / 4).min(1000) {
        let ck: f64 = (0..len - k)
            .map(|i| (x[i] - mean) * (x[i + k] - mean))
            .sum();
        let rho = ck / c0;
        if rho <= 0.0 {
            break;
        }
        tau += 2.0 * rho;
    }
    tau
}

fn sum_squares(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// The parameters held because the records do not see them or cannot tell them apart,
/// with why, from the Jacobian `jac` of `cols`: the kept columns' positions in `cols`.
fn screen(
    jac: &DMatrix<f64>,
    cols: &[usize],
    params: &[Param],
) -> (Vec<usize>, Vec<(usize, String)>) {
    let norms: Vec<f64> = (0..jac.ncols()).map(|k| jac.column(k).norm()).collect();
    let largest = norms.iter().copied().fold(0.0, f64::max);
    let mut held = Vec::new();
    let mut kept: Vec<usize> = Vec::new();
    for (k, &n) in norms.iter().enumerate() {
        if n.is_finite() && n > MIN_COLUMN_NORM * largest && n > 0.0 {
            kept.push(k);
        } else {
            held.push((
                k,
                format!(
                    "the records do not see it: the predicted accelerations change by {:.1e} \
                     of the largest parameter's effect for the same relative change",
                    n / largest.max(f64::MIN_POSITIVE)
                ),
            ));
        }
    }
    loop {
        let m = kept.len();
        if m < 2 {
            break;
        }
        let c = DMatrix::from_fn(m, m, |a, b| {
            jac.column(kept[a]).dot(&jac.column(kept[b])) / (norms[kept[a]] * norms[kept[b]])
        });
        let inflation: Vec<f64> = match c.clone().cholesky() {
            Some(ch) => {
                let inv = ch.inverse();
                (0..m).map(|a| inv[(a, a)]).collect()
            }
            None => vec![f64::INFINITY; m],
        };
        // The largest inflation (the last of equals) goes first.
        let (worst, vif) =
            inflation
                .iter()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |best, (a, &v)| {
                    if v >= best.1 || v.is_nan() {
                        (a, v)
                    } else {
                        best
                    }
                });
        let r2 = 1.0 - 1.0 / vif;
        if vif.is_finite() && r2 <= MAX_CORRELATION * MAX_CORRELATION {
            break;
        }
        // Its strongest partner, for the message.
        let partner = (0..m)
            .filter(|&b| b != worst)
            .max_by(|&a, &b| c[(worst, a)].abs().total_cmp(&c[(worst, b)].abs()))
            .map_or(String::new(), |b| {
                format!(
                    "; most with {} (correlation {:.4})",
                    params[cols[kept[b]]].key,
                    c[(worst, b)]
                )
            });
        held.push((
            kept[worst],
            format!(
                "the other parameters reproduce its effect on the predicted accelerations \
                 (multiple correlation {:.6}{partner}): held at the equation error's value",
                r2.max(0.0).sqrt()
            ),
        ));
        kept.remove(worst);
    }
    held.sort_by_key(|h| h.0);
    (kept, held)
}

/// What the Levenberg–Marquardt search ends with.
struct Outcome {
    theta: Vec<f64>,
    residuals: Vec<f64>,
    /// The free parameters (indices into the problem's) and their covariance in `θ`.
    free: Vec<usize>,
    covariance: Option<DMatrix<f64>>,
    held: Vec<(usize, String)>,
    iterations: usize,
    converged: bool,
    stop_reason: String,
    rejected: usize,
    failed: usize,
    tau: f64,
}

/// The damped Gauss–Newton step of `a`, `g` at damping `lambda`.
fn damped_step(a: &DMatrix<f64>, g: &DVector<f64>, lambda: f64) -> Option<DVector<f64>> {
    let mut m = a.clone();
    for k in 0..m.nrows() {
        m[(k, k)] += lambda * a[(k, k)].max(f64::MIN_POSITIVE);
    }
    let step = m.cholesky()?.solve(&(-g));
    step.iter().all(|x| x.is_finite()).then_some(step)
}

/// Levenberg–Marquardt on `problem` from its start (module docs); `None` when the start's
/// own run fails.
fn levenberg_marquardt(problem: &Problem<'_>) -> Option<Outcome> {
    let mut theta: Vec<f64> = problem.params.iter().map(Param::theta0).collect();
    let mut r = problem.residuals(&theta)?;
    let n = r.len();
    let mut ss = sum_squares(&r);
    let mut free: Vec<usize> = (0..problem.params.len()).collect();
    let mut held = Vec::new();
    let (mut iterations, mut rejected, mut failed) = (0usize, 0usize, 0usize);
    let mut lambda = 1e-3;
    let mut converged = false;
    let stop_reason;
    let mut last_jac: Option<DMatrix<f64>> = None;
    loop {
        let (jac, f) = problem.jacobian(&theta, &r, &free);
        failed += f;
        let Some(mut jac) = jac else {
            stop_reason =
                "a run of the Jacobian failed both ways: stopped at the last values".into();
            break;
        };
        if iterations == 0 {
            let (kept, h) = screen(&jac, &free, &problem.params);
            held = h.into_iter().map(|(k, why)| (free[k], why)).collect();
            let cols: Vec<usize> = kept.iter().map(|&k| free[k]).collect();
            jac = DMatrix::from_fn(n, kept.len(), |i, k| jac[(i, kept[k])]);
            free = cols;
        }
        last_jac = Some(jac.clone());
        if free.is_empty() {
            stop_reason = "no parameter the records can tell apart".into();
            break;
        }
        if iterations >= MAX_ITERATIONS {
            stop_reason = format!("{MAX_ITERATIONS} iterations");
            break;
        }
        let a = jac.tr_mul(&jac);
        let rv = DVector::from_column_slice(&r);
        let g = jac.tr_mul(&rv);
        // The score statistic: what the full Gauss–Newton step would lower the sum of
        // squares by, in effective residual variances.
        let sigma2 = ss / (n.saturating_sub(free.len())).max(1) as f64;
        let tau = problem.correlation_time(&r);
        if let Some(gn) = damped_step(&a, &g, 0.0) {
            let score = -g.dot(&gn) / (sigma2 * tau);
            if score < CHI2_TOLERANCE {
                converged = true;
                stop_reason = format!(
                    "converged: the Gauss–Newton step would lower the sum of squares by \
                     {score:.3} effective residual variances (< {CHI2_TOLERANCE})"
                );
                break;
            }
        }
        iterations += 1;
        let mut accepted = false;
        while lambda <= MAX_LAMBDA {
            let Some(step) = damped_step(&a, &g, lambda) else {
                lambda *= 10.0;
                continue;
            };
            let mut trial = theta.clone();
            for (k, &j) in free.iter().enumerate() {
                trial[j] = problem.params[j].project(theta[j] + step[k]);
            }
            match problem.residuals(&trial) {
                Some(rt) if sum_squares(&rt) < ss => {
                    theta = trial;
                    r = rt;
                    ss = sum_squares(&r);
                    lambda = (lambda / 10.0).max(1e-12);
                    accepted = true;
                    break;
                }
                Some(_) => {
                    rejected += 1;
                    lambda *= 10.0;
                }
                None => {
                    rejected += 1;
                    failed += 1;
                    lambda *= 10.0;
                }
            }
        }
        if !accepted {
            // No step along the (finite-difference) gradient lowers the cost: a minimum as
            // far as the runs can tell, though the score says a better point may exist.
            stop_reason = "no damping gives a lower cost: stopped where the runs can no \
                           longer tell a better point (not converged by the score test)"
                .into();
            // The Jacobian at these values is the last one: no further run needed.
            break;
        }
    }
    let tau = problem.correlation_time(&r);
    let covariance = last_jac
        .filter(|j| j.ncols() == free.len() && !free.is_empty())
        .and_then(|jac| {
            let sigma2 = ss / (n.saturating_sub(free.len())).max(1) as f64;
            let a = jac.tr_mul(&jac);
            let inv = a.cholesky()?.inverse();
            Some(inv * (sigma2 * tau))
        });
    Some(Outcome {
        theta,
        residuals: r,
        free,
        covariance,
        held,
        iterations,
        converged,
        stop_reason,
        rejected,
        failed,
        tau,
    })
}

/// The parameters of the loop's values (module docs), from the equation error's.
fn parameters(v: &Values, mean_speed_m_s: f64) -> Vec<Param> {
    let mut out = Vec::new();
    let log = |kind: Kind, key: &str, start: f64| Param {
        kind,
        key: key.to_owned(),
        start,
        coordinate: Coordinate::Log,
    };
    let push_log = |out: &mut Vec<Param>, kind: Kind, key: &str, start: f64| {
        if start.is_finite() && start > 0.0 {
            out.push(log(kind, key, start));
        }
    };
    let m = &v.model;
    push_log(
        &mut out,
        Kind::Mass,
        "model.identified.effective_mass_kg",
        m.effective_mass_kg,
    );
    push_log(
        &mut out,
        Kind::Coulomb,
        "model.identified.coulomb_force_n",
        m.coulomb_force_n,
    );
    if m.viscous_coefficient > 0.0 {
        push_log(
            &mut out,
            Kind::Viscous,
            "model.identified.viscous_coefficient",
            m.viscous_coefficient,
        );
    } else {
        // Held at 0 by the equation error: free from 0 upwards, in units of the force that
        // equals the mass times 1 m/s² at the records' mean speed.
        let unit = m.effective_mass_kg / mean_speed_m_s.max(1e-6).powf(m.viscous_exponent) * 1e-2;
        out.push(Param {
            kind: Kind::Viscous,
            key: "model.identified.viscous_coefficient".into(),
            start: 0.0,
            coordinate: Coordinate::Linear {
                unit,
                min: 0.0,
                max: f64::INFINITY,
            },
        });
    }
    push_log(
        &mut out,
        Kind::Stribeck,
        "model.identified.low_velocity_force_n",
        m.low_velocity_force_n,
    );
    if m.viscous_exponent != 1.0 && m.viscous_exponent.is_finite() {
        out.push(Param {
            kind: Kind::Exponent,
            key: "model.identified.viscous_exponent".into(),
            start: m.viscous_exponent,
            coordinate: Coordinate::Linear {
                unit: 1.0,
                min: 0.0,
                max: 1.0,
            },
        });
    }
    for (j, s) in v.storeys.iter().enumerate() {
        push_log(
            &mut out,
            Kind::StoreyMass(j),
            &format!("specimen.storeys[{j}].mass_kg"),
            s.mass_kg,
        );
        push_log(
            &mut out,
            Kind::StoreyStiffness(j),
            &format!("specimen.storeys[{j}].stiffness_n_per_m"),
            s.stiffness_n_per_m,
        );
        push_log(
            &mut out,
            Kind::StoreyDamping(j),
            &format!("specimen.storeys[{j}].damping_n_s_per_m"),
            s.damping_n_s_per_m,
        );
    }
    let sv = &v.parts.servo_valve;
    push_log(
        &mut out,
        Kind::RatedFlow,
        "table_system.servo_valve.rated_flow_m3_s",
        sv.rated_flow_m3_s,
    );
    push_log(
        &mut out,
        Kind::ValveLag,
        "table_system.servo_valve.equivalent_lag_s",
        equivalent_lag_s(sv.delay_s, sv.natural_frequency_hz, sv.damping_ratio),
    );
    push_log(
        &mut out,
        Kind::ChamberVolume,
        "table_system.actuator.chamber_volume_m3",
        v.parts.actuator.cap_volume_m3,
    );
    out
}

/// `τ + 2ζ/ω_n`, s.
fn equivalent_lag_s(delay_s: f64, natural_frequency_hz: f64, damping_ratio: f64) -> f64 {
    delay_s + 2.0 * damping_ratio / (std::f64::consts::TAU * natural_frequency_hz)
}

/// The fitted records as targets, with each channel's RMS; `None` without a table
/// acceleration in every fitted record (or a filter or command that cannot be made).
fn targets<'a>(
    records: &'a [SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    channels: &[Channel],
    band_hz: f64,
) -> Option<(Vec<Target<'a>>, Vec<f64>)> {
    let mut out = Vec::new();
    let mut ss = vec![0.0; channels.len()];
    let mut n = 0usize;
    for &i in fitted {
        let r = &records[i];
        let h = periods[i];
        let lowpass = ButterworthLowpass::new(4, band_hz.min(0.4 * 0.5 / h), 1.0 / h).ok()?;
        let command = Motion::from_displacement(r.t_s.clone(), r.command_u_m.clone()).ok()?;
        let channels = channels
            .iter()
            .map(|c| lowpass.apply(c.recorded(r)?).ok())
            .collect::<Option<Vec<Vec<f64>>>>()?;
        for (s, c) in ss.iter_mut().zip(&channels) {
            let mean = c.iter().sum::<f64>() / c.len() as f64;
            *s += c.iter().map(|x| (x - mean).powi(2)).sum::<f64>();
        }
        n += r.t_s.len();
        out.push(Target {
            record: r,
            command,
            lowpass,
            channels,
        });
    }
    let scale: Vec<f64> = ss.iter().map(|s| (s / n.max(1) as f64).sqrt()).collect();
    scale
        .iter()
        .all(|s| s.is_finite() && *s > 0.0)
        .then_some((out, scale))
}

/// A closed loop's values: what [`refine_loop`] starts from and gives.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopValues {
    /// The table system, its controller's gains included.
    pub system: TableSystem,
    /// The platen.
    pub model: IdentifiedParams,
    /// The specimen on the platen, if any.
    pub specimen: Option<Specimen>,
}

/// What [`refine_loop`] gives.
#[derive(Debug, Clone, PartialEq)]
pub struct RefinedLoop {
    /// The refined values.
    pub values: LoopValues,
    /// The fit.
    pub fit: PredictionErrorFit,
    /// The parameters held at their start, with why (the records do not see them or cannot
    /// tell them from others).
    pub held: Vec<(String, String)>,
}

/// Refines `start` by its prediction error on the records `fitted` of `records` (module
/// docs): the closed loop run on each one's command from rest, its table and storey
/// accelerations (and drive and `Δp` where every fitted record has them) made to reproduce
/// the recorded ones. The storeys compared are those every fitted record holds, at most
/// the specimen's.
///
/// # Errors
/// [`IdentError::InvalidRecord`] for a record whose channels do not fit together or that
/// cannot be filtered, no record to fit, or an index in `fitted` past the records; [`IdentError::LoopNotIdentifiable`] for a
/// fitted record without a table acceleration, or when `start` does not run on a fitted
/// record's command.
pub fn refine_loop(
    records: &[SystemRecord],
    fitted: &[usize],
    start: &LoopValues,
) -> Result<RefinedLoop> {
    let periods = records
        .iter()
        .map(SystemRecord::period_s)
        .collect::<Result<Vec<f64>>>()?;
    if let Some(&i) = fitted.iter().find(|&&i| i >= records.len()) {
        return Err(IdentError::InvalidRecord {
            test: format!("record {i}"),
            message: format!(
                "marked for the fit, but there are {} records",
                records.len()
            ),
        });
    }
    let Some(&first) = fitted.first() else {
        return Err(IdentError::InvalidRecord {
            test: records.first().map_or(String::new(), |r| r.name.clone()),
            message: "no record is marked for the fit".into(),
        });
    };
    if let Some(&i) = fitted.iter().find(|&&i| records[i].a_m_s2.is_none()) {
        return Err(IdentError::LoopNotIdentifiable {
            record: records[i].name.clone(),
            reason: "no a_m_s2: the prediction-error fit has nothing to compare the loop with"
                .into(),
        });
    }
    let values = Values {
        parts: start.system.into_parts(),
        model: start.model,
        storeys: start
            .specimen
            .as_ref()
            .map_or_else(Vec::new, |s| s.storeys().to_vec()),
    };
    let recorded_storeys = fitted
        .iter()
        .map(|&i| records[i].storey_a_m_s2.len())
        .min()
        .unwrap_or(0)
        .min(values.storeys.len());
    let h = periods[first];
    let band_hz = JUDGE_LOWPASS_HZ.min(0.4 * 0.5 / h);
    let mut channels: Vec<Channel> = std::iter::once(Channel::Table)
        .chain((0..recorded_storeys).map(Channel::Storey))
        .collect();
    if fitted.iter().all(|&i| records[i].delta_p_pa.is_some()) {
        channels.push(Channel::DeltaP);
    }
    let names = || {
        fitted
            .iter()
            .map(|&i| records[i].name.clone())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let Some((targets, scale)) = targets(records, &periods, fitted, &channels, band_hz) else {
        return Err(IdentError::InvalidRecord {
            test: names(),
            message: "the channels cannot be filtered at the records' rate, or one is \
                      constant, or the command cannot be read as a motion"
                .into(),
        });
    };
    // The specimen's storeys beyond those recorded in every fitted record still run (they
    // feed the base shear back), compared only where recorded.
    let payload: f64 = values.storeys.iter().map(|s| s.mass_kg).sum();
    let steps_per_period = start
        .system
        .default_steps_per_period(values.model.effective_mass_kg + payload, values.stroke_m());
    let mean_speed = mean_command_speed(&targets);
    let params = parameters(&values, mean_speed);
    let problem = Problem {
        targets,
        channels,
        scale,
        start: values.clone(),
        params,
        steps_per_period,
    };
    let Some(out) = levenberg_marquardt(&problem) else {
        return Err(IdentError::LoopNotIdentifiable {
            record: names(),
            reason: "the starting loop fails to run on a fitted record's command (the \
                     integrator, or values no table system takes)"
                .into(),
        });
    };
    let theta0: Vec<f64> = problem.params.iter().map(Param::theta0).collect();
    let r0 = problem.residuals(&theta0).unwrap_or_default();
    let (before, after) = (
        problem.channel_nrmse(&r0),
        problem.channel_nrmse(&out.residuals),
    );
    let n = out.residuals.len();
    let channels = (0..problem.scale.len())
        .map(|c| ChannelFit {
            channel: problem.channels[c].name(),
            nrmse_before: before.get(c).copied().unwrap_or(f64::NAN),
            nrmse_after: after.get(c).copied().unwrap_or(f64::NAN),
        })
        .collect();
    let parameters: Vec<PemParameter> = problem
        .params
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let k = out.free.iter().position(|&f| f == j);
            let std_error = k.and_then(|k| {
                let c = out.covariance.as_ref()?;
                let s = c[(k, k)].sqrt() * p.derivative(out.theta[j]).abs();
                s.is_finite().then_some(s)
            });
            PemParameter {
                key: p.key.clone(),
                start: p.start,
                value: p.value(out.theta[j]),
                std_error,
                refined: k.is_some(),
            }
        })
        .collect();
    let held = out
        .held
        .iter()
        .map(|(j, reason)| {
            (
                problem.params[*j].key.clone(),
                format!("prediction-error fit: {reason}"),
            )
        })
        .collect();
    let refined = values.with(&problem.params, &out.theta);
    // The start's values when the refined ones make no loop (they always do: every
    // accepted step ran).
    let built = refined.build();
    let values = match built {
        Some(b) => LoopValues {
            system: b.system,
            model: refined.model,
            specimen: b.specimen,
        },
        None => start.clone(),
    };
    Ok(RefinedLoop {
        values,
        fit: PredictionErrorFit {
            iterations: out.iterations,
            converged: out.converged,
            stop_reason: out.stop_reason,
            rejected_steps: out.rejected,
            failed_runs: out.failed,
            cost_before: sum_squares(&r0) / r0.len().max(1) as f64,
            cost_after: sum_squares(&out.residuals) / n.max(1) as f64,
            residuals: n,
            correlation_time_samples: out.tau,
            effective_residuals: n as f64 / out.tau,
            steps_per_period,
            band_hz,
            channels,
            parameters,
        },
        held,
    })
}

/// Refines the loop's values in `plant` and `gains` by the prediction error on the `fitted`
/// records ([`refine_loop`]), writes the refined values back (the system, model, specimen,
/// storeys and their modes, hydraulics, mechanics' values, standard errors and the gains'
/// estimates) and reports the fit; `None` (with why in `not_identified`) when the loop
/// cannot be run or compared.
pub(crate) fn refine(
    records: &[SystemRecord],
    fitted: &[usize],
    plant: &mut IdentifiedPlant,
    not_identified: &mut Vec<(String, String)>,
) -> Option<PredictionErrorFit> {
    let (Some(system), Some(model)) = (plant.system, plant.model) else {
        return None;
    };
    let start = LoopValues {
        system,
        model,
        specimen: plant.specimen.clone(),
    };
    match refine_loop(records, fitted, &start) {
        Ok(r) => {
            not_identified.extend(r.held);
            write_back(plant, &r.values, &r.fit.parameters);
            Some(r.fit)
        }
        Err(e) => {
            not_identified.push((
                "the prediction-error fit".to_owned(),
                format!("not done, the equation error's values kept: {e}"),
            ));
            None
        }
    }
}

/// The RMS of the commands' velocity over the fitted records, m/s.
fn mean_command_speed(targets: &[Target<'_>]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for t in targets {
        let u = &t.record.command_u_m;
        let h = (t.record.t_s[u.len() - 1] - t.record.t_s[0]) / (u.len() - 1) as f64;
        for w in u.windows(2) {
            s += ((w[1] - w[0]) / h).powi(2);
            n += 1;
        }
    }
    (s / n.max(1) as f64).sqrt()
}

/// The refined `v` into the identification's plant and gains.
fn write_back(plant: &mut IdentifiedPlant, values: &LoopValues, parameters: &[PemParameter]) {
    let v = Values {
        parts: values.system.into_parts(),
        model: values.model,
        storeys: values
            .specimen
            .as_ref()
            .map_or_else(Vec::new, |s| s.storeys().to_vec()),
    };
    let built = Built {
        system: values.system,
        model: match values.model.build() {
            Ok(m) => m,
            Err(_) => return,
        },
        specimen: values.specimen.clone(),
    };
    plant.system = Some(built.system);
    plant.model = Some(v.model);
    if let Some(m) = plant.mechanics.as_mut() {
        m.effective_mass_kg = v.model.effective_mass_kg;
        m.coulomb_force_n = v.model.coulomb_force_n;
        m.viscous_coefficient = v.model.viscous_coefficient;
    }
    if let Some(sp) = built.specimen {
        for (s, t) in plant.storeys.iter_mut().zip(sp.storeys()) {
            s.mass_kg = t.mass_kg;
            s.stiffness_n_per_m = t.stiffness_n_per_m;
            s.damping_n_s_per_m = t.damping_n_s_per_m;
        }
        plant.specimen_modes = super::plant::modes(&plant.storeys);
        plant.specimen = Some(sp);
    }
    if let Some(hyd) = plant.hydraulics.as_mut() {
        let sv = &v.parts.servo_valve;
        let a = &v.parts.actuator;
        if hyd.rated_flow_m3_s > 0.0 {
            hyd.land_coefficient *= sv.rated_flow_m3_s / hyd.rated_flow_m3_s;
        }
        hyd.rated_flow_m3_s = sv.rated_flow_m3_s;
        hyd.cap_volume_m3 = a.cap_volume_m3;
        hyd.rod_volume_m3 = a.rod_volume_m3;
        hyd.cap_compliance_m3_per_pa = a.cap_volume_m3 / v.parts.oil_bulk_modulus_pa;
        hyd.rod_compliance_m3_per_pa = a.rod_volume_m3 / v.parts.oil_bulk_modulus_pa;
        hyd.valve_delay_s = sv.delay_s;
        hyd.spool_natural_frequency_hz = sv.natural_frequency_hz;
        hyd.equivalent_lag_s =
            equivalent_lag_s(sv.delay_s, sv.natural_frequency_hz, sv.damping_ratio);
        let payload: f64 = v.storeys.iter().map(|s| s.mass_kg).sum();
        hyd.oil_column_frequency_hz = built
            .system
            .oil_column_frequency_hz(v.model.effective_mass_kg, 0.0);
        hyd.oil_column_frequency_with_specimen_hz = built
            .system
            .oil_column_frequency_hz(v.model.effective_mass_kg + payload, 0.0);
    }
    for p in parameters.iter().filter(|p| p.refined) {
        let paths: Vec<String> = match p.key.as_str() {
            "table_system.servo_valve.equivalent_lag_s" => vec![],
            "table_system.actuator.chamber_volume_m3" => (0..2)
                .map(|k| format!("table_system.actuator.chamber_volume_m3[{k}]"))
                .collect(),
            key => vec![key.to_owned()],
        };
        for path in paths {
            match p.std_error {
                Some(s) => {
                    // A chamber's volume scales with the common factor.
                    let s = if p.key == "table_system.actuator.chamber_volume_m3" {
                        let k = if path.ends_with("[0]") {
                            v.parts.actuator.cap_volume_m3
                        } else {
                            v.parts.actuator.rod_volume_m3
                        };
                        s / p.value * k
                    } else {
                        s
                    };
                    plant.std_errors.insert(path, s);
                }
                None => {
                    plant.std_errors.remove(&path);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(n: usize) -> Vec<Param> {
        (0..n)
            .map(|j| Param {
                kind: Kind::Mass,
                key: format!("p{j}"),
                start: 1.0,
                coordinate: Coordinate::Log,
            })
            .collect()
    }

    /// Two identical columns: one is held, the other kept; a zero column is held.
    #[test]
    fn a_column_the_others_reproduce_or_a_zero_column_is_held() {
        let n = 50;
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).cos()).collect();
        let jac = DMatrix::from_fn(n, 4, |i, k| match k {
            0 => x[i],
            1 => y[i],
            2 => 2.0 * x[i],
            _ => 0.0,
        });
        let (kept, held) = screen(&jac, &[0, 1, 2, 3], &params(4));
        assert_eq!(held.len(), 2, "{held:?}");
        assert!(held.iter().any(|h| h.0 == 3));
        assert!(kept.contains(&1));
        assert_eq!(kept.len(), 2);
    }

    /// The integrated autocorrelation time of white residuals is about 1 sample; of a
    /// moving average of 5 white samples (correlation 1 − k/5 at lag k < 5) it is
    /// `1 + 2·(4 + 3 + 2 + 1)/5 = 5`.
    #[test]
    fn correlation_time_of_white_and_moving_average_residuals() {
        let mut state = 11u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let w: Vec<f64> = (0..20_000).map(|_| rnd()).collect();
        let ma: Vec<f64> = (0..w.len() - 5).map(|i| w[i..i + 5].iter().sum()).collect();
        let tau = correlation_time;
        assert!((tau(&w) - 1.0).abs() < 0.1, "{}", tau(&w));
        assert!((tau(&ma) - 5.0).abs() < 0.5, "{}", tau(&ma));
    }
}
