//! The channels of each record as the fits use them: the velocity (given, or the crossover
//! estimate), the samples fast enough for the equation error, and those samples stacked.

use platen_signal::CrossoverVelocity;

use crate::error::{IdentError, Result};
use crate::record::TestRecord;

use super::settings::ValidRecordSettings;

/// One record, ready for the fits.
#[derive(Debug, Clone)]
pub(crate) struct Prepared {
    /// Velocity, m/s: the record's own channel, or the crossover estimate.
    pub v_m_s: Vec<f64>,
    /// Whether the velocity was given.
    pub velocity_given: bool,
    /// Samples used by the equation error.
    pub used: Vec<bool>,
    /// Variance of the accelerometer's noise, (m/s²)² ([`noise_variance`]).
    pub a_noise_var: f64,
    /// Variance of the displacement transducer's noise, m².
    pub u_noise_var: f64,
}

/// Variance of the white noise on a channel, from the median absolute value of its sixth
/// differences (`Σ C(6,j)² = 924` times the noise variance; the median ignores the sparse
/// jumps of the acceleration at stick-slip events, which would dominate a mean square):
/// `σ̂ = 1.4826·median|Δ⁶x| / √924`. Motion leaks in with the gain `(2 sin(πf/f_s))⁶/√924`
/// relative to the noise: 0.002 at 20 Hz on 204.8 Hz data, 10⁻⁸ at 1 Hz, so a test record's
/// content (0–20 Hz) adds nothing measurable when the rate is ten times its top frequency.
pub(crate) fn noise_variance(x: &[f64]) -> f64 {
    const C: [f64; 7] = [1.0, -6.0, 15.0, -20.0, 15.0, -6.0, 1.0];
    if x.len() < 64 {
        return 0.0;
    }
    let mut d: Vec<f64> = x
        .windows(7)
        .map(|w| w.iter().zip(C).map(|(x, c)| x * c).sum::<f64>().abs())
        .collect();
    let mid = d.len() / 2;
    let median = *d.select_nth_unstable_by(mid, f64::total_cmp).1;
    let sigma = 1.4826 * median / 924f64.sqrt();
    sigma * sigma
}

/// Velocity and selection of every record.
pub(crate) fn prepare(
    records: &[TestRecord],
    settings: &ValidRecordSettings,
) -> Result<Vec<Prepared>> {
    records
        .iter()
        .map(|rec| {
            let (v, given) = match rec.v_m_s() {
                Some(v) => (v.to_vec(), true),
                None => {
                    let signal = |source| IdentError::Signal {
                        test: rec.name().to_owned(),
                        source,
                    };
                    let cross = CrossoverVelocity::butterworth(
                        2,
                        settings.crossover_hz,
                        rec.sample_rate_hz(),
                    )
                    .map_err(signal)?;
                    (
                        cross.estimate(rec.u_m(), rec.a_m_s2()).map_err(signal)?,
                        false,
                    )
                }
            };
            let n = v.len();
            let edge = (settings.edge_s * rec.sample_rate_hz()).round() as usize;
            let used = (0..n)
                .map(|i| i >= edge && i + edge < n && v[i].abs() >= settings.min_speed_m_s)
                .collect();
            let (a_noise_var, u_noise_var) = if settings.noise_correction {
                (noise_variance(rec.a_m_s2()), noise_variance(rec.u_m()))
            } else {
                (0.0, 0.0)
            };
            Ok(Prepared {
                v_m_s: v,
                velocity_given: given,
                used,
                a_noise_var,
                u_noise_var,
            })
        })
        .collect()
}

/// The samples of the equation error, stacked over the records.
#[derive(Debug, Clone, Default)]
pub(crate) struct Stacked {
    pub a: Vec<f64>,
    pub u: Vec<f64>,
    /// `sign(v)`.
    pub s: Vec<f64>,
    /// `|v|`.
    pub w: Vec<f64>,
    /// `ln |v|`.
    pub ln_w: Vec<f64>,
    /// Force, N.
    pub f: Vec<f64>,
    /// Record of each sample.
    pub record: Vec<usize>,
    /// Index of each sample in its record.
    pub time: Vec<usize>,
    /// `Σ σ²_a` and `Σ σ²_u` over the samples: the part of `Σa²` and `Σu²` that is sensor
    /// noise, removed from the normal equations (corrected least squares).
    pub noise_sums: [f64; 2],
}

impl Stacked {
    pub(crate) fn new(records: &[TestRecord], prepared: &[Prepared]) -> Self {
        let mut s = Stacked::default();
        for (r, (rec, p)) in records.iter().zip(prepared).enumerate() {
            for i in (0..rec.len()).filter(|&i| p.used[i]) {
                let v = p.v_m_s[i];
                s.a.push(rec.a_m_s2()[i]);
                s.u.push(rec.u_m()[i]);
                s.s.push(v.signum());
                s.w.push(v.abs());
                s.ln_w.push(v.abs().ln());
                s.f.push(rec.force_n()[i]);
                s.record.push(r);
                s.time.push(i);
                s.noise_sums[0] += p.a_noise_var;
                s.noise_sums[1] += p.u_noise_var;
            }
        }
        s
    }

    pub(crate) fn len(&self) -> usize {
        self.f.len()
    }
}
