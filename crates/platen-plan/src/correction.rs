//! The drive correction of the iteration ([`DriveCorrection`]): `ΔD = IFFT(W·FFT(E))` with
//! `W = g·w·Ĥ⁺/(−ω²)` a `p × p` matrix per FFT bin, planned once per record length. One axis
//! is the case `p = 1`, where `Ĥ⁺ = Ĥ*/(|Ĥ|² + ε²·max|Ĥ|²)` (see [`crate::iterate`]).
//!
//! `Ĥ⁺ = (ĤᴴĤ + ε²·max‖Ĥ‖²_F·I)⁻¹·Ĥᴴ` comes from one Hermitian eigendecomposition of `ĤᴴĤ`
//! per bin (nalgebra's [`SymmetricEigen`]): with `ĤᴴĤ = V·Λ·Vᴴ`, the regularised matrix shares
//! `V` and `Ĥ⁺ = V·(Λ + floor)⁻¹·Vᴴ·Ĥᴴ`, and `√(λ_max/λ_min)` is `Ĥ`'s condition number. For
//! one axis the decomposition is exact (`V = 1`, `λ = |Ĥ|²`) and the weights are the scalar
//! formula's to the last bit (tested).

use std::sync::Arc;

use nalgebra::{DMatrix, SymmetricEigen};
use rustfft::num_complex::Complex64 as C64;
use rustfft::{Fft, FftPlanner};

use crate::error::{check_setting, PlanError, Result};
use crate::settings::{default_band_hz, IterationSettings};

/// The transfer matrix `Ĥ(f)` of `p` axes: `h[i][j]` is axis `i`'s response to axis `j`'s
/// command (`1 × 1` for one axis).
pub type TransferMatrix = Vec<Vec<C64>>;

const ZERO: C64 = C64::new(0.0, 0.0);

/// The correction operator of `p` coupled axes (`p = 1`: one axis), planned once per record
/// length.
pub struct DriveCorrection {
    p: usize,
    n: usize,
    m: usize,
    /// `g·w·Ĥ⁺/(−ω²)` per positive bin `0..=m/2` (row-major `p × p`; empty outside the band).
    weights: Vec<Vec<C64>>,
    /// Bins inside the band, positive frequencies.
    in_band: Vec<bool>,
    taper: Vec<f64>,
    max_condition: f64,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for DriveCorrection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DriveCorrection")
            .field("axes", &self.p)
            .field("samples", &self.n)
            .field("fft_len", &self.m)
            .finish()
    }
}

/// The axes' corrections and how much of the error the band covers.
#[derive(Debug, Clone, PartialEq)]
pub struct Correction {
    /// Per axis, the drive's correction, m.
    pub delta_u_m: Vec<Vec<f64>>,
    /// Fraction of the errors' energy on bins inside the band.
    pub in_band_fraction: f64,
}

/// The correction band `w(f)`: 1 inside `hz`, half-cosine roll-offs over its lowest and
/// highest `edge_fraction`, 0 outside.
pub(crate) struct Band {
    pub(crate) hz: (f64, f64),
    pub(crate) edge_fraction: f64,
}

impl Band {
    /// `w(f)`.
    pub(crate) fn weight(&self, f: f64) -> f64 {
        let (lo, hi) = self.hz;
        let e = self.edge_fraction;
        if f < lo || f > hi {
            return 0.0;
        }
        let (lo_end, hi_start) = (lo * (1.0 + e), hi * (1.0 - e));
        let ramp = |x: f64| 0.5 - 0.5 * (std::f64::consts::PI * x).cos();
        let mut w = 1.0;
        if f < lo_end {
            w *= ramp((f - lo) / (lo_end - lo));
        }
        if f > hi_start {
            w *= ramp((hi - f) / (hi - hi_start));
        }
        w
    }
}

/// `n` ones tapered to zero by a half-cosine over `taper_n` samples at both ends.
pub(crate) fn half_cosine_taper(n: usize, taper_n: usize) -> Vec<f64> {
    let mut taper = vec![1.0; n];
    for j in 0..taper_n {
        let w = 0.5 - 0.5 * (std::f64::consts::PI * j as f64 / taper_n as f64).cos();
        taper[j] = w;
        taper[n - 1 - j] = w;
    }
    taper
}

/// `Ĥ` on the bins `0..=half`, `df` apart (empty outside the band and at 0 Hz), checked
/// `p × p` and finite, and its largest Frobenius norm.
fn frf_on_bins(
    p: usize,
    half: usize,
    df: f64,
    band: &Band,
    frf: &dyn Fn(f64) -> TransferMatrix,
) -> Result<(Vec<Vec<C64>>, f64)> {
    let mut h = vec![Vec::new(); half + 1];
    let mut max_norm = 0.0_f64;
    for (k, slot) in h.iter_mut().enumerate().skip(1) {
        let f = k as f64 * df;
        if band.weight(f) <= 0.0 {
            continue;
        }
        let hf = frf(f);
        if hf.len() != p || hf.iter().any(|row| row.len() != p) {
            return Err(PlanError::Setting {
                name: "frf",
                value: f,
                expected: "a square transfer matrix of the axes' count at every frequency",
            });
        }
        *slot = hf.into_iter().flatten().collect();
        if slot.iter().any(|c| !c.re.is_finite() || !c.im.is_finite()) {
            return Err(PlanError::Setting {
                name: "frf",
                value: f,
                expected: "a finite transfer matrix in the band",
            });
        }
        // ‖Ĥ‖_F by hypot, so that one axis's is |Ĥ| itself.
        max_norm = max_norm.max(slot.iter().fold(0.0, |s, c| s.hypot(c.norm())));
    }
    Ok((h, max_norm))
}

/// The weights `scale·Ĥ⁺` of the row-major `p × p` `h` with the regularisation `floor`
/// (`scale(λ)` the gain over `λ + floor`, see [`DriveCorrection::new`]), and `Ĥ`'s condition
/// number; `None` for the weights where `ĤᴴĤ + floor·I` is singular.
fn inverse_weights(
    h: &[C64],
    p: usize,
    floor: f64,
    scale: impl Fn(f64) -> f64,
) -> (Option<Vec<C64>>, f64) {
    // ĤᴴĤ = V·Λ·Vᴴ (Hermitian).
    let gram = DMatrix::from_fn(p, p, |i, j| {
        (0..p).fold(ZERO, |s, r| s + h[r * p + i].conj() * h[r * p + j])
    });
    let eig = SymmetricEigen::new(gram);
    let (lo, hi) = eig
        .eigenvalues
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &e| {
            (lo.min(e), hi.max(e))
        });
    let condition = if lo <= 0.0 {
        f64::INFINITY
    } else {
        (hi / lo).sqrt()
    };
    let v = &eig.eigenvectors;
    let mut d = Vec::with_capacity(p);
    for &lambda in eig.eigenvalues.iter() {
        let denominator = lambda + floor;
        if denominator <= 0.0 {
            return (None, condition);
        }
        d.push(scale(denominator));
    }
    // W = V·D·(Vᴴ·Ĥᴴ).
    let vh_hh =
        |k: usize, j: usize| (0..p).fold(ZERO, |s, r| s + v[(r, k)].conj() * h[j * p + r].conj());
    let mut w = vec![ZERO; p * p];
    for i in 0..p {
        for j in 0..p {
            w[i * p + j] = (0..p).fold(ZERO, |s, k| s + v[(i, k)] * (vh_hh(k, j) * d[k]));
        }
    }
    (Some(w), condition)
}

impl DriveCorrection {
    /// Plans the correction of `p` axes' records of `samples` samples at `sample_rate_hz`,
    /// with `Ĥ` = `frf` (`p × p` at each frequency) and `settings`' gain, band,
    /// regularisation, padding and taper.
    ///
    /// # Errors
    /// [`PlanError::Setting`] for settings out of range (see [`IterationSettings`]), a band
    /// with no FFT bin, or an `frf` that is not `p × p` or not finite in the band.
    pub fn new(
        p: usize,
        samples: usize,
        sample_rate_hz: f64,
        frf: &dyn Fn(f64) -> TransferMatrix,
        settings: &IterationSettings,
    ) -> Result<Self> {
        let s = checked(settings, sample_rate_hz, samples)?;
        let n = samples;
        let pad = (s.pad_s * sample_rate_hz).round() as usize;
        let m = if pad == 0 { n } else { fft_size(n + pad) };
        let half = m / 2;
        let df = sample_rate_hz / m as f64;
        let band = Band {
            hz: s.band_hz,
            edge_fraction: settings.edge_fraction,
        };
        let (h, max_norm) = frf_on_bins(p, half, df, &band, frf)?;
        let floor = (settings.regularisation * max_norm).powi(2);
        let mut weights = vec![Vec::new(); half + 1];
        let mut in_band = vec![false; half + 1];
        let mut max_condition = 1.0_f64;
        for k in 1..=half {
            // The Nyquist bin of an even length has no conjugate partner: leave it out.
            if m % 2 == 0 && k == half {
                continue;
            }
            let f = k as f64 * df;
            let w = band.weight(f);
            if w <= 0.0 {
                continue;
            }
            let omega = std::f64::consts::TAU * f;
            let (inverse, condition) = inverse_weights(&h[k], p, floor, |denominator| {
                settings.gain * w / denominator / -(omega * omega)
            });
            max_condition = max_condition.max(condition);
            if let Some(inverse) = inverse {
                weights[k] = inverse;
                in_band[k] = true;
            }
        }
        if !in_band.iter().any(|&b| b) {
            return Err(PlanError::Setting {
                name: "band_hz",
                value: s.band_hz.0,
                expected: "a band holding at least one FFT bin of the record (a longer record or \
                           a wider band)",
            });
        }
        let taper_n = ((settings.taper_s * sample_rate_hz).round() as usize).min(n / 2);
        let mut planner = FftPlanner::<f64>::new();
        Ok(Self {
            p,
            n,
            m,
            weights,
            in_band,
            taper: half_cosine_taper(n, taper_n),
            max_condition,
            forward: planner.plan_fft_forward(m),
            inverse: planner.plan_fft_inverse(m),
        })
    }

    /// The FFT length, samples.
    pub fn fft_len(&self) -> usize {
        self.m
    }

    /// The largest condition number of `Ĥ` over the band's bins (1 for one axis).
    pub fn max_condition(&self) -> f64 {
        self.max_condition
    }

    /// The drives' corrections for the acceleration errors `errors_m_s2` (`T − R` per axis,
    /// one value per sample of the record), and the fraction of the errors' energy on bins
    /// inside the band.
    pub fn apply(&self, errors_m_s2: &[Vec<f64>]) -> Correction {
        let m = self.m;
        let spectra: Vec<Vec<C64>> = errors_m_s2
            .iter()
            .map(|e| {
                let mut buf = vec![ZERO; m];
                for (b, v) in buf.iter_mut().zip(e.iter().take(self.n)) {
                    b.re = *v;
                }
                self.forward.process(&mut buf);
                buf
            })
            .collect();
        let (mut total, mut inside) = (0.0, 0.0);
        for spectrum in &spectra {
            for (c, &inside_band) in spectrum[..=m / 2].iter().zip(&self.in_band).skip(1) {
                let e = c.norm_sqr();
                total += e;
                if inside_band {
                    inside += e;
                }
            }
        }
        let scale = 1.0 / m as f64;
        let delta_u_m = (0..self.p)
            .map(|i| {
                let mut buf = self.weighted(i, &spectra);
                self.inverse.process(&mut buf);
                (0..self.n)
                    .map(|j| buf[j].re * scale * self.taper[j])
                    .collect()
            })
            .collect();
        Correction {
            delta_u_m,
            in_band_fraction: if total > 0.0 { inside / total } else { 1.0 },
        }
    }

    /// Axis `i`'s corrected spectrum `Σ_j W_ij·E_j` on every bin, the negative frequencies
    /// through the conjugate weights.
    fn weighted(&self, i: usize, spectra: &[Vec<C64>]) -> Vec<C64> {
        let (p, m) = (self.p, self.m);
        let mut out = vec![ZERO; m];
        for k in 1..=m / 2 {
            if !self.in_band[k] {
                continue;
            }
            let w = &self.weights[k][i * p..(i + 1) * p];
            out[k] = spectra.iter().zip(w).fold(ZERO, |s, (e, w)| s + e[k] * w);
            out[m - k] = spectra
                .iter()
                .zip(w)
                .fold(ZERO, |s, (e, w)| s + e[m - k] * w.conj());
        }
        out
    }
}

/// The settings checked, with the band and padding resolved.
pub(crate) struct Checked {
    pub(crate) band_hz: (f64, f64),
    pub(crate) pad_s: f64,
}

/// `s` checked for records of `samples` samples at `sample_rate_hz`.
pub(crate) fn checked(
    s: &IterationSettings,
    sample_rate_hz: f64,
    samples: usize,
) -> Result<Checked> {
    check_setting(
        "gain",
        s.gain,
        s.gain > 0.0 && s.gain < 2.0,
        "a gain in (0, 2)",
    )?;
    check_setting(
        "target_nrmse",
        s.target_nrmse,
        s.target_nrmse >= 0.0,
        "an NRMSE >= 0",
    )?;
    check_setting(
        "edge_fraction",
        s.edge_fraction,
        (0.0..=0.5).contains(&s.edge_fraction),
        "a fraction in [0, 0.5]",
    )?;
    check_setting(
        "regularisation",
        s.regularisation,
        s.regularisation >= 0.0,
        "an ε >= 0",
    )?;
    check_setting(
        "min_improvement",
        s.min_improvement,
        (0.0..1.0).contains(&s.min_improvement),
        "a relative decrease in [0, 1)",
    )?;
    check_setting("taper_s", s.taper_s, s.taper_s >= 0.0, "a duration >= 0 s")?;
    if s.stall_iterations == 0 {
        return Err(PlanError::Setting {
            name: "stall_iterations",
            value: 0.0,
            expected: "at least 1 iteration",
        });
    }
    let band_hz = s.band_hz.unwrap_or(default_band_hz(sample_rate_hz));
    let nyquist = 0.5 * sample_rate_hz;
    check_setting(
        "band_hz[0]",
        band_hz.0,
        band_hz.0 > 0.0,
        "a lower band edge > 0 Hz",
    )?;
    check_setting(
        "band_hz[1]",
        band_hz.1,
        band_hz.1 > band_hz.0 && band_hz.1 < nyquist,
        "an upper band edge above the lower one and below the target's Nyquist frequency",
    )?;
    let duration = samples as f64 / sample_rate_hz;
    let pad_s = s.pad_s.unwrap_or((0.25 * duration).max(4.0));
    check_setting("pad_s", pad_s, pad_s >= 0.0, "a padding >= 0 s")?;
    Ok(Checked { band_hz, pad_s })
}

/// The smallest length `≥ n` whose only prime factors are 2, 3 and 5 (fast for the FFT).
pub(crate) fn fft_size(n: usize) -> usize {
    let mut m = n.max(1);
    loop {
        let mut r = m;
        for p in [2, 3, 5] {
            while r % p == 0 {
                r /= p;
            }
        }
        if r == 1 {
            return m;
        }
        m += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> C64 {
        C64::new(re, im)
    }

    #[test]
    fn fft_sizes_are_smooth_and_not_shorter() {
        assert_eq!(fft_size(1), 1);
        assert_eq!(fft_size(7), 8);
        assert_eq!(fft_size(1001), 1024);
        assert_eq!(fft_size(46_080), 46_080);
        assert_eq!(fft_size(46_081), 46_656);
    }

    #[test]
    fn the_unregularised_inverse_is_the_inverse() {
        let h = [c(1.0, 0.5), c(0.3, -0.2), c(-0.1, 0.4), c(2.0, 0.1)];
        let (x, _) = inverse_weights(&h, 2, 0.0, |d| 1.0 / d);
        let x = x.unwrap();
        for i in 0..2 {
            for j in 0..2 {
                let s = (0..2).fold(ZERO, |s, r| s + x[i * 2 + r] * h[r * 2 + j]);
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((s - c(want, 0.0)).norm() < 1e-14, "{i}{j}: {s}");
            }
        }
    }

    /// The weights of one axis are the scalar formula `Ĥ*·(g·w/(|Ĥ|² + floor)/−ω²)` of the
    /// single-axis iteration bit for bit, on seeded random `Ĥ`, gains and floors.
    #[test]
    fn one_axis_is_the_scalar_formula_to_the_last_bit() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..10_000 {
            let h = c(next(), next());
            let (gain, w, floor, omega) = (next().abs(), next().abs(), next().abs(), 1.0 + next());
            let scalar = |d: f64| gain * w / d / -(omega * omega);
            let (x, condition) = inverse_weights(&[h], 1, floor, scalar);
            let want = h.conj() * scalar(h.norm_sqr() + floor);
            let x = x.unwrap()[0];
            assert_eq!(x.re.to_bits(), want.re.to_bits(), "{h} {floor}");
            assert_eq!(x.im.to_bits(), want.im.to_bits(), "{h} {floor}");
            assert_eq!(condition, 1.0);
        }
    }

    /// The eigendecomposition's regularised inverse against a direct solve of
    /// `(ĤᴴĤ + floor·I)·X = Ĥᴴ` by Gauss–Jordan elimination with partial pivoting (the method
    /// this crate used before nalgebra), on seeded random complex 3 × 3 `Ĥ`: equal to
    /// rounding, `16·ε·(1 + κ²)` of the inverse's size (`κ` `Ĥ`'s condition number, squared
    /// by the normal equations both solve).
    #[test]
    fn the_regularised_inverse_is_the_direct_solve_to_rounding() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let p = 3;
        for _ in 0..1000 {
            let h: Vec<C64> = (0..p * p).map(|_| c(next(), next())).collect();
            let floor = 0.01 * next().abs();
            let (x, _) = inverse_weights(&h, p, floor, |d| 1.0 / d);
            let x = x.unwrap();
            // a = ĤᴴĤ + floor·I, b = Ĥᴴ; a·x = b by Gauss–Jordan.
            let mut a = vec![ZERO; p * p];
            let mut b = vec![ZERO; p * p];
            for i in 0..p {
                for j in 0..p {
                    a[i * p + j] = (0..p).fold(ZERO, |s, r| s + h[r * p + i].conj() * h[r * p + j]);
                    b[i * p + j] = h[j * p + i].conj();
                }
                a[i * p + i] += floor;
            }
            for col in 0..p {
                let pivot = (col..p)
                    .max_by(|&r, &s| a[r * p + col].norm().total_cmp(&a[s * p + col].norm()))
                    .unwrap();
                for k in 0..p {
                    a.swap(pivot * p + k, col * p + k);
                    b.swap(pivot * p + k, col * p + k);
                }
                let d = a[col * p + col];
                for r in (0..p).filter(|&r| r != col) {
                    let f = a[r * p + col] / d;
                    for k in 0..p {
                        let (ak, bk) = (a[col * p + k], b[col * p + k]);
                        a[r * p + k] -= f * ak;
                        b[r * p + k] -= f * bk;
                    }
                }
            }
            let size = x.iter().map(|v| v.norm()).fold(0.0, f64::max);
            // Both solve the normal equations, whose condition is Ĥ's squared.
            let condition = inverse_weights(&h, p, floor, |d| d).1;
            let bound = 16.0 * f64::EPSILON * (1.0 + condition * condition);
            for r in 0..p {
                for k in 0..p {
                    let want = b[r * p + k] / a[r * p + r];
                    let e = (x[r * p + k] - want).norm() / size;
                    assert!(e < bound, "{e:e} against {bound:e}");
                }
            }
        }
    }

    #[test]
    fn the_condition_number_is_the_singular_values_ratio() {
        // diag(3, 0.5i) (unitary columns scaled): σ = 3 and 0.5.
        let h = [c(3.0, 0.0), c(0.0, 0.0), c(0.0, 0.0), c(0.0, 0.5)];
        assert!((inverse_weights(&h, 2, 0.0, |d| d).1 - 6.0).abs() < 1e-12);
        let singular = [c(1.0, 0.0), c(2.0, 0.0), c(0.5, 0.0), c(1.0, 0.0)];
        assert!(inverse_weights(&singular, 2, 0.0, |d| d).1 > 1e7);
    }
}
