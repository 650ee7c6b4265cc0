//! The channels of each record as the fits use them: the velocity (given, or the crossover
//! estimate), the samples fast enough for the equation error, and those samples stacked,
//! one block per record (a refit that changes one record shares the others' blocks).

use std::cell::{OnceCell, RefCell};
use std::rc::Rc;

use platen_signal::CrossoverVelocity;

use crate::error::{IdentError, Result};
use crate::record::TestRecord;

use super::separable::{FixedSums, GridSums};
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

/// One record's samples used by the equation error (those of [`Prepared::used`]), in order.
#[derive(Debug, Default)]
pub(crate) struct Block {
    /// Index of the record.
    pub record: usize,
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
    /// Index of each sample in its record.
    pub time: Vec<usize>,
    /// Noise variances of the accelerometer, (m/s²)², and of the displacement, m²
    /// ([`Prepared::a_noise_var`], [`Prepared::u_noise_var`]).
    pub noise_var: [f64; 2],
    /// The equation error's sums over this block of the columns that do not depend on
    /// `(α, b)`, and at the nodes of its start grid: computed once and shared by every fit
    /// that uses the block (module `separable`).
    pub(crate) fixed: OnceCell<FixedSums>,
    pub(crate) grid: RefCell<Vec<Rc<GridSums>>>,
}

impl Block {
    /// The used samples of record `record`.
    pub(crate) fn new(record: usize, rec: &TestRecord, p: &Prepared) -> Self {
        let mut b = Block {
            record,
            noise_var: [p.a_noise_var, p.u_noise_var],
            ..Block::default()
        };
        for i in (0..rec.len()).filter(|&i| p.used[i]) {
            let v = p.v_m_s[i];
            b.a.push(rec.a_m_s2()[i]);
            b.u.push(rec.u_m()[i]);
            b.s.push(v.signum());
            b.w.push(v.abs());
            b.ln_w.push(v.abs().ln());
            b.f.push(rec.force_n()[i]);
            b.time.push(i);
        }
        b
    }

    pub(crate) fn len(&self) -> usize {
        self.f.len()
    }
}

/// The samples of the equation error, stacked over the records: one [`Block`] per record, in
/// record order (a record with no sample fast enough has an empty block). The residuals and
/// the Jacobian's rows of a fit follow the same order.
#[derive(Debug, Clone, Default)]
pub(crate) struct Stacked {
    pub blocks: Vec<Rc<Block>>,
    /// `Σ σ²_a` and `Σ σ²_u` over the samples: the part of `Σa²` and `Σu²` that is sensor
    /// noise, removed from the normal equations (corrected least squares).
    pub noise_sums: [f64; 2],
}

impl Stacked {
    pub(crate) fn new(records: &[TestRecord], prepared: &[Prepared]) -> Self {
        Self::from_blocks(
            records
                .iter()
                .zip(prepared)
                .enumerate()
                .map(|(r, (rec, p))| Rc::new(Block::new(r, rec, p)))
                .collect(),
        )
    }

    pub(crate) fn from_blocks(blocks: Vec<Rc<Block>>) -> Self {
        let mut noise_sums = [0.0; 2];
        // Sample by sample, in order, as the sums were always formed.
        for b in &blocks {
            for _ in 0..b.len() {
                noise_sums[0] += b.noise_var[0];
                noise_sums[1] += b.noise_var[1];
            }
        }
        Self { blocks, noise_sums }
    }

    /// The same samples with record `record`'s block replaced (the others are shared).
    pub(crate) fn with_block(&self, record: usize, block: Block) -> Self {
        let mut blocks = self.blocks.clone();
        blocks[record] = Rc::new(block);
        Self::from_blocks(blocks)
    }

    pub(crate) fn len(&self) -> usize {
        self.blocks.iter().map(|b| b.len()).sum()
    }

    /// `|v|` of every sample.
    pub(crate) fn speeds(&self) -> impl Iterator<Item = f64> + '_ {
        self.blocks.iter().flat_map(|b| b.w.iter().copied())
    }

    /// The record of every sample.
    pub(crate) fn groups(&self) -> Vec<usize> {
        self.blocks
            .iter()
            .flat_map(|b| std::iter::repeat_n(b.record, b.len()))
            .collect()
    }

    /// Record and sample index of every sample (the residuals' layout).
    pub(crate) fn layout(&self) -> (Vec<usize>, Vec<usize>) {
        let mut time = Vec::with_capacity(self.len());
        let mut group = Vec::with_capacity(self.len());
        for b in &self.blocks {
            time.extend_from_slice(&b.time);
            group.extend(std::iter::repeat_n(b.record, b.len()));
        }
        (time, group)
    }
}
