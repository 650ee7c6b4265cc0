//! Resampling of uniformly sampled records to a new rate.

use crate::error::{Result, SignalError};
use crate::fir::FirLowpass;
use crate::{SampleRate, Window, ZeroPhaseFilter};

/// How values between input samples are interpolated.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Interpolation {
    /// Straight lines between samples: exact for ramps; a sine at `f` is off by up to
    /// `(πf/f_s)²/2` between samples (1.2 % at `f_s/20`).
    Linear,
    /// Not-a-knot cubic spline through all samples (twice continuously differentiable, exact
    /// for cubics, error `O((2πf/f_s)⁴)`). The default. Records of fewer than 4 samples are
    /// interpolated linearly.
    #[default]
    Cubic,
}

/// Resamples a uniformly sampled record from one rate to another.
///
/// Output sample `k` is at `t_s = k/to_hz`, the input's first sample is at `t_s = 0`, and the
/// output covers the input's span: `⌊(n − 1)·to_hz/from_hz⌋ + 1` samples for `n` inputs.
///
/// * **Downsampling** (`to_hz < from_hz`) is band-limited: the record is first low-passed with
///   a zero-phase Hamming windowed-sinc [`FirLowpass`] with its cut-off (−6 dB) at 80 % of the
///   new Nyquist frequency (`0.4·to_hz`) and order `16.5·from_hz/to_hz` rounded up to even,
///   which puts its transition band between 60 % and 100 % of the new Nyquist frequency: content
///   below `0.3·to_hz` keeps its phase and its amplitude within 0.5 %, content at or above the
///   new Nyquist frequency `0.5·to_hz` is attenuated to ≤ 3.2·10⁻³ (−50 dB) before it could
///   alias. Then the filtered record is interpolated at the new times (which are samples of it
///   when the ratio is an integer).
/// * **Upsampling** (`to_hz > from_hz`) only interpolates: the input is taken to be
///   band-limited already. See [`Interpolation`] for the accuracy of each method.
/// * Equal rates copy the record.
///
/// **Edges.** The anti-alias filter sees the record extended by odd reflection through its end
/// samples (constants and ramps pass exactly); the spline uses not-a-knot end conditions (no
/// extension needed).
#[derive(Debug, Clone)]
pub struct Resampler {
    from: SampleRate,
    to: SampleRate,
    interpolation: Interpolation,
    anti_alias: Option<FirLowpass>,
}

impl Resampler {
    /// Plans resampling from `from_hz` to `to_hz` (both finite, > 0).
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] for a bad rate, or rates more than a factor 10⁶ apart
    /// (the anti-alias filter or the output would not fit in memory).
    pub fn new(from_hz: f64, to_hz: f64, interpolation: Interpolation) -> Result<Self> {
        let from = SampleRate::new(from_hz).map_err(|e| rename(e, "from_hz"))?;
        let to = SampleRate::new(to_hz).map_err(|e| rename(e, "to_hz"))?;
        let ratio = from.hz() / to.hz();
        if !(1e-6..=1e6).contains(&ratio) {
            return Err(SignalError::InvalidParameter {
                name: "to_hz",
                value: to.hz(),
                expected: "a rate within a factor of 1e6 of from_hz",
            });
        }
        let anti_alias = if to.hz() < from.hz() {
            let order = ((16.5 * ratio).ceil() as usize).next_multiple_of(2);
            Some(FirLowpass::new(
                order,
                0.4 * to.hz(),
                from.hz(),
                Window::Hamming,
            )?)
        } else {
            None
        };
        Ok(Resampler {
            from,
            to,
            interpolation,
            anti_alias,
        })
    }

    /// Input rate, Hz.
    pub fn from_hz(&self) -> f64 {
        self.from.hz()
    }

    /// Output rate, Hz.
    pub fn to_hz(&self) -> f64 {
        self.to.hz()
    }

    /// The anti-alias low-pass applied before interpolation when downsampling.
    pub fn anti_alias(&self) -> Option<&FirLowpass> {
        self.anti_alias.as_ref()
    }

    /// Gain of the anti-alias filter at `frequency_hz` (1 when upsampling); zero phase.
    /// Interpolation adds its own small loss between samples (see the type's docs).
    pub fn gain(&self, frequency_hz: f64) -> f64 {
        self.anti_alias
            .as_ref()
            .map_or(1.0, |f| f.gain(frequency_hz))
    }

    /// Number of output samples for `input_len` input samples.
    pub fn output_len(&self, input_len: usize) -> usize {
        if input_len == 0 {
            return 0;
        }
        let span = (input_len - 1) as f64 * self.to.hz() / self.from.hz();
        ((span + 1e-9).floor() as usize).saturating_add(1)
    }

    /// Resamples `input` into `output`.
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`] if `output.len() != self.output_len(input.len())`.
    pub fn process(&self, input: &[f64], output: &mut [f64]) -> Result<()> {
        let expected = self.output_len(input.len());
        if output.len() != expected {
            return Err(SignalError::LengthMismatch {
                what: "output",
                expected,
                found: output.len(),
                reference: "the resampled input (Resampler::output_len)",
            });
        }
        if input.is_empty() {
            return Ok(());
        }
        if self.from.hz() == self.to.hz() {
            output.copy_from_slice(input);
            return Ok(());
        }
        let filtered;
        let x = match &self.anti_alias {
            Some(f) => {
                filtered = f.apply(input)?;
                &filtered[..]
            }
            None => input,
        };
        let step = self.from.hz() / self.to.hz();
        let last = (x.len() - 1) as f64;
        let positions = (0..output.len()).map(|k| (k as f64 * step).min(last));
        match self.interpolation {
            Interpolation::Cubic if x.len() >= 4 => {
                let curvature = spline_curvature(x);
                for (y, pos) in output.iter_mut().zip(positions) {
                    *y = spline_at(x, &curvature, pos);
                }
            }
            _ => {
                for (y, pos) in output.iter_mut().zip(positions) {
                    *y = linear_at(x, pos);
                }
            }
        }
        Ok(())
    }

    /// Resamples `input` into a new vector of [`output_len`](Self::output_len) samples.
    ///
    /// # Errors
    /// None in practice (the output is sized here); the `Result` mirrors [`process`](Self::process).
    pub fn apply(&self, input: &[f64]) -> Result<Vec<f64>> {
        let mut out = vec![0.0; self.output_len(input.len())];
        self.process(input, &mut out)?;
        Ok(out)
    }
}

fn rename(e: SignalError, name: &'static str) -> SignalError {
    match e {
        SignalError::InvalidParameter {
            value, expected, ..
        } => SignalError::InvalidParameter {
            name,
            value,
            expected,
        },
        other => other,
    }
}

/// Value at fractional index `pos ∈ [0, n − 1]` of `x` by linear interpolation.
fn linear_at(x: &[f64], pos: f64) -> f64 {
    let i = (pos.floor() as usize).min(x.len() - 1);
    let t = pos - i as f64;
    if t == 0.0 || i + 1 == x.len() {
        x[i]
    } else {
        x[i] + t * (x[i + 1] - x[i])
    }
}

/// Second differences `m_i = h²·S''(i)` of the not-a-knot cubic spline through `x` (unit
/// spacing; `x.len() ≥ 4`).
///
/// Interior rows: `m_{i−1} + 4m_i + m_{i+1} = 6(x_{i+1} − 2x_i + x_{i−1})`. Not-a-knot (third
/// derivative continuous at samples 1 and n−2) is `m_0 − 2m_1 + m_2 = 0`, which on a uniform
/// grid turns the first row into `6m_1 = r_1` (and the last into `6m_{n−2} = r_{n−2}`); the
/// rows in between are solved by the Thomas algorithm, and `m_0 = 2m_1 − m_2`,
/// `m_{n−1} = 2m_{n−2} − m_{n−3}`.
fn spline_curvature(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let r = |i: usize| 6.0 * (x[i + 1] - 2.0 * x[i] + x[i - 1]);
    let mut m = vec![0.0; n];
    m[1] = r(1) / 6.0;
    m[n - 2] = r(n - 2) / 6.0;
    if n > 4 {
        // Rows i = 2..=n−3: m_{i−1} + 4m_i + m_{i+1} = r_i, with m_1 and m_{n−2} known.
        let rows = n - 4;
        let mut c = vec![0.0; rows]; // modified super-diagonal
        let mut d = vec![0.0; rows]; // modified right-hand side
        for j in 0..rows {
            let i = j + 2;
            let mut rhs = r(i);
            if j == 0 {
                rhs -= m[1];
            }
            if j == rows - 1 {
                rhs -= m[n - 2];
            }
            let (c_prev, d_prev) = if j == 0 {
                (0.0, 0.0)
            } else {
                (c[j - 1], d[j - 1])
            };
            let denom = 4.0 - c_prev;
            c[j] = 1.0 / denom;
            d[j] = (rhs - d_prev) / denom;
        }
        m[rows + 1] = d[rows - 1];
        for j in (0..rows - 1).rev() {
            m[j + 2] = d[j] - c[j] * m[j + 3];
        }
    }
    m[0] = 2.0 * m[1] - m[2];
    m[n - 1] = 2.0 * m[n - 2] - m[n - 3];
    m
}

/// Value of the spline at fractional index `pos ∈ [0, n − 1]`.
fn spline_at(x: &[f64], m: &[f64], pos: f64) -> f64 {
    let i = (pos.floor() as usize).min(x.len() - 2);
    let t = pos - i as f64;
    let s = 1.0 - t;
    s * x[i] + t * x[i + 1] + ((s * s * s - s) * m[i] + (t * t * t - t) * m[i + 1]) / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spline_reproduces_cubics_exactly_with_not_a_knot_ends() {
        for n in [4, 5, 6, 17] {
            let f = |s: f64| 0.5 - 1.5 * s + 0.25 * s * s + 0.125 * s * s * s;
            let x: Vec<f64> = (0..n).map(|i| f(i as f64)).collect();
            let m = spline_curvature(&x);
            for k in 0..(10 * (n - 1)) {
                let pos = k as f64 / 10.0;
                let err = (spline_at(&x, &m, pos) - f(pos)).abs();
                assert!(err < 1e-12, "n = {n}, pos = {pos}: error {err}");
            }
        }
    }

    #[test]
    fn linear_interpolation_reproduces_lines_and_the_last_sample() {
        let x = [1.0, 3.0, 5.0];
        assert_eq!(linear_at(&x, 0.5), 2.0);
        assert_eq!(linear_at(&x, 2.0), 5.0);
    }
}
