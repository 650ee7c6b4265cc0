//! The channels of each record as the fits use them: the velocity (given, or the crossover
//! estimate), the samples fast enough for the equation error, and those samples stacked,
//! one block per record (a refit that changes one record shares the others' blocks).

use std::cell::{OnceCell, RefCell};
use std::rc::Rc;

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
    /// that uses the block (the equation error of module `separable`).
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

/// Sums over one block of the columns that do not depend on `(α, b)`: `x = (a, u, s)`, the
/// offset (`1`) and the force `y`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FixedSums {
    /// `Σ xⱼ·xₖ`.
    pub(crate) xx: [[f64; 3]; 3],
    /// `Σ xⱼ`.
    pub(crate) x: [f64; 3],
    /// The number of samples.
    pub(crate) n: f64,
    /// `Σ xⱼ·y`.
    pub(crate) xy: [f64; 3],
    /// `Σ y`.
    pub(crate) y: f64,
    /// `Σ y²`.
    pub(crate) yy: f64,
}

impl FixedSums {
    fn of(b: &Block) -> Self {
        let mut s = Self::default();
        for i in 0..b.len() {
            let x = [b.a[i], b.u[i], b.s[i]];
            let y = b.f[i];
            for j in 0..3 {
                for k in 0..3 {
                    s.xx[j][k] += x[j] * x[k];
                }
                s.x[j] += x[j];
                s.xy[j] += x[j] * y;
            }
            s.n += 1.0;
            s.y += y;
            s.yy += y * y;
        }
        s
    }

    /// The block's, computed on first use.
    pub(crate) fn cached(b: &Block) -> Self {
        *b.fixed.get_or_init(|| Self::of(b))
    }
}

/// Sums over one block of a column `z` that depends on `(α, b)` (`c = s·|v|^α` or
/// `e = s·e^(−b|v|)`) against the others.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ColumnSums {
    /// `Σ z·a`, `Σ z·u`, `Σ z·s`.
    pub(crate) zx: [f64; 3],
    /// `Σ z` (against the block's offset).
    pub(crate) z: f64,
    /// `Σ z²`.
    pub(crate) zz: f64,
    /// `Σ z·y`.
    pub(crate) zy: f64,
}

impl ColumnSums {
    #[inline(always)]
    pub(crate) fn add(&mut self, z: f64, b: &Block, i: usize) {
        self.zx[0] += z * b.a[i];
        self.zx[1] += z * b.u[i];
        self.zx[2] += z * b.s[i];
        self.z += z;
        self.zz += z * z;
        self.zy += z * b.f[i];
    }
}

/// A block's sums at one `(α, b)`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct NodeSums {
    pub(crate) c: ColumnSums,
    pub(crate) e: ColumnSums,
    /// `Σ c·e`.
    pub(crate) ce: f64,
}

/// A block's sums at every node of a start grid (`alphas × decays`).
#[derive(Debug)]
pub(crate) struct GridSums {
    alphas: Vec<f64>,
    decays: Vec<f64>,
    /// Per `α`.
    c: Vec<ColumnSums>,
    /// Per `b` (zero without the low-velocity term).
    e: Vec<ColumnSums>,
    /// Per `(α, b)`, `α` major.
    ce: Vec<f64>,
}

impl GridSums {
    /// Samples handled together: each node's column is computed once per sample (one
    /// exponential per `α` and per `b`, not per pair) and kept for the cross sums.
    const CHUNK: usize = 256;

    fn of(block: &Block, alphas: &[f64], decays: &[f64], low: bool) -> Self {
        let (na, nb) = (alphas.len(), decays.len());
        let mut g = GridSums {
            alphas: alphas.to_vec(),
            decays: decays.to_vec(),
            c: vec![ColumnSums::default(); na],
            e: vec![ColumnSums::default(); nb],
            ce: vec![0.0; na * nb],
        };
        let chunk = Self::CHUNK;
        let mut cbuf = vec![0.0; na * chunk];
        let mut ebuf = vec![0.0; nb * chunk];
        let n = block.len();
        let mut start = 0;
        while start < n {
            let len = chunk.min(n - start);
            for (k, &alpha) in alphas.iter().enumerate() {
                let sums = &mut g.c[k];
                for (j, slot) in cbuf[k * chunk..k * chunk + len].iter_mut().enumerate() {
                    let i = start + j;
                    let c = block.s[i] * (alpha * block.ln_w[i]).exp();
                    *slot = c;
                    sums.add(c, block, i);
                }
            }
            if low {
                for (k, &b) in decays.iter().enumerate() {
                    let sums = &mut g.e[k];
                    for (j, slot) in ebuf[k * chunk..k * chunk + len].iter_mut().enumerate() {
                        let i = start + j;
                        let e = block.s[i] * (-b * block.w[i]).exp();
                        *slot = e;
                        sums.add(e, block, i);
                    }
                }
                for ka in 0..na {
                    let c = &cbuf[ka * chunk..ka * chunk + len];
                    for kb in 0..nb {
                        let e = &ebuf[kb * chunk..kb * chunk + len];
                        let acc = &mut g.ce[ka * nb + kb];
                        for (x, y) in c.iter().zip(e) {
                            *acc += x * y;
                        }
                    }
                }
            }
            start += len;
        }
        g
    }

    /// The block's sums at this grid, computed on first use and kept with the block.
    pub(crate) fn cached(block: &Block, alphas: &[f64], decays: &[f64], low: bool) -> Rc<Self> {
        let mut cache = block.grid.borrow_mut();
        if let Some(g) = cache
            .iter()
            .find(|g| g.alphas == alphas && g.decays == decays)
        {
            return Rc::clone(g);
        }
        let g = Rc::new(Self::of(block, alphas, decays, low));
        cache.push(Rc::clone(&g));
        g
    }

    pub(crate) fn node(&self, ka: usize, kb: usize) -> NodeSums {
        NodeSums {
            c: self.c[ka],
            e: self.e[kb],
            ce: self.ce[ka * self.decays.len() + kb],
        }
    }
}
