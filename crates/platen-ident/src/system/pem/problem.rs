//! The prediction-error problem: the fitted records as targets (their compared channels in
//! the band, each channel's scale), the closed loop run on each command, and the residuals,
//! their Jacobian, NRMSE and correlation time.

use nalgebra::{DMatrix, DVector};
use platen_integrate::{
    forward_closed_loop, LoopMethod, LoopRun, Motion, Sample, SampleSink, State,
};
use platen_signal::{ButterworthLowpass, ZeroPhaseFilter};
use rayon::prelude::*;

use super::values::{Built, Param, Values};
use crate::system::SystemRecord;

/// Central-difference step of the Jacobian, in the parameters' coordinates (relative for the
/// logarithmic ones: 1 %).
pub const FD_STEP: f64 = 1e-2;

/// A compared channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Channel {
    /// The table's acceleration.
    Table,
    /// Storey `k`'s acceleration (from 0, bottom first).
    Storey(usize),
    /// The pressure difference `Δp`.
    DeltaP,
}

impl Channel {
    /// Its column name.
    pub(super) fn name(self) -> String {
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
pub(super) struct Target<'a> {
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
pub(super) struct Problem<'a> {
    /// The fitted records.
    pub targets: Vec<Target<'a>>,
    /// The compared channels.
    pub channels: Vec<Channel>,
    /// Each channel's RMS over every fitted record, in the band.
    pub scale: Vec<f64>,
    /// The loop's values at the start (the equation error's).
    pub start: Values,
    /// The parameters.
    pub params: Vec<Param>,
    /// RK4 steps per controller period of every run.
    pub steps_per_period: u32,
}

impl Problem<'_> {
    /// The residuals (record by record, channel by channel) at `theta`; `None` when a run
    /// fails or the values make no loop.
    pub(super) fn residuals(&self, theta: &[f64]) -> Option<Vec<f64>> {
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
    pub(super) fn jacobian(
        &self,
        theta: &[f64],
        r0: &[f64],
        cols: &[usize],
    ) -> (Option<DMatrix<f64>>, usize) {
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
    pub(super) fn channel_nrmse(&self, r: &[f64]) -> Vec<f64> {
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
    pub(super) fn correlation_time(&self, r: &[f64]) -> f64 {
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

/// `Σ r²`.
pub(super) fn sum_squares(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// The fitted records as targets, with each channel's RMS; `None` without a table
/// acceleration in every fitted record (or a filter or command that cannot be made).
pub(super) fn targets<'a>(
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

/// The RMS of the commands' velocity over the fitted records, m/s.
pub(super) fn mean_command_speed(targets: &[Target<'_>]) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;

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
