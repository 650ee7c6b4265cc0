//! Waveform generators: the paper's sine and triangle tests, band-limited white noise, and
//! sine forces. Each returns samples at `j / sample_rate_hz`, `j = 0, 1, …`, so times are exact
//! for power-of-two rates.

use std::f64::consts::PI;

use platen_integrate::{ForceRecord, Motion};
use rustfft::{num_complex::Complex, FftPlanner};

/// Why a generator's parameters were rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GenerateError {
    /// A parameter out of range.
    #[error("`{name}` = {value}: expected {expected}")]
    Invalid {
        /// The parameter's name (as in the scenario file).
        name: &'static str,
        /// The value.
        value: f64,
        /// What a valid value looks like.
        expected: String,
    },
}

fn check(name: &'static str, value: f64, ok: bool, expected: &str) -> Result<f64, GenerateError> {
    if value.is_finite() && ok {
        Ok(value)
    } else {
        Err(GenerateError::Invalid {
            name,
            value,
            expected: expected.to_owned(),
        })
    }
}

/// The longest generated record, in samples: 13.5 h at 1024 Hz. A run holds a few columns of
/// this length in memory, so a larger request is an input error rather than an allocation
/// failure.
pub const MAX_GENERATED_SAMPLES: usize = 50_000_000;

/// Number of samples covering `duration_s` at `rate_hz` (both ends included).
fn sample_count(rate_hz: f64, duration_s: f64) -> Result<usize, GenerateError> {
    check(
        "sample_rate_hz",
        rate_hz,
        rate_hz > 0.0,
        "a sample rate > 0",
    )?;
    check("duration_s", duration_s, duration_s > 0.0, "a duration > 0")?;
    let n = (duration_s * rate_hz + 1e-6).floor() + 1.0;
    check(
        "duration_s",
        duration_s,
        n <= MAX_GENERATED_SAMPLES as f64,
        &format!("at most {MAX_GENERATED_SAMPLES} samples at the sample rate (13.5 h at 1024 Hz)"),
    )?;
    check(
        "duration_s",
        duration_s,
        n >= 3.0,
        "at least 3 samples at the sample rate",
    )?;
    Ok(n as usize)
}

/// A frequency below the Nyquist frequency of the sample rate: a waveform above it would be
/// sampled as a lower one (aliasing).
fn below_nyquist(frequency_hz: f64, rate_hz: f64) -> Result<f64, GenerateError> {
    check(
        "frequency_hz",
        frequency_hz,
        frequency_hz < 0.5 * rate_hz,
        &format!(
            "a frequency below the Nyquist frequency of the sample rate ({} Hz)",
            0.5 * rate_hz
        ),
    )
}

/// The generated samples as a motion, or the error of the parameter `name = value` that made
/// them unusable (a waveform too large for double precision: `A·(2πf)²` overflows).
fn generated_motion(
    t: Vec<f64>,
    u: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    (name, value): (&'static str, f64),
) -> Result<Motion, GenerateError> {
    Motion::new(t, u, v, a).map_err(|e| GenerateError::Invalid {
        name,
        value,
        expected: format!("a value for which the generated motion is finite ({e})"),
    })
}

fn times(rate_hz: f64, n: usize) -> Vec<f64> {
    (0..n).map(|j| j as f64 / rate_hz).collect()
}

/// `u = A·sin(2πft)` with exact velocity and acceleration (the paper's S tests).
///
/// # Errors
/// Non-finite amplitude, frequency ≤ 0 or at or above the Nyquist frequency `rate/2`,
/// rate ≤ 0, duration ≤ 0, or a waveform too large for double precision.
pub fn sine_motion(
    amplitude_m: f64,
    frequency_hz: f64,
    rate_hz: f64,
    duration_s: f64,
) -> Result<Motion, GenerateError> {
    check("amplitude_m", amplitude_m, true, "a finite amplitude")?;
    check(
        "frequency_hz",
        frequency_hz,
        frequency_hz > 0.0,
        "a frequency > 0",
    )?;
    let n = sample_count(rate_hz, duration_s)?;
    below_nyquist(frequency_hz, rate_hz)?;
    let w = 2.0 * PI * frequency_hz;
    let t = times(rate_hz, n);
    let u = t.iter().map(|&t| amplitude_m * (w * t).sin()).collect();
    let v = t.iter().map(|&t| amplitude_m * w * (w * t).cos()).collect();
    let a = t
        .iter()
        .map(|&t| -amplitude_m * w * w * (w * t).sin())
        .collect();
    generated_motion(t, u, v, a, ("amplitude_m", amplitude_m))
}

/// `F = r(t)·A·sin(2πft)` with `r` a linear ramp from 0 to 1 over `ramp_s` (0: none).
///
/// # Errors
/// Non-finite amplitude, frequency < 0 or at or above the Nyquist frequency `rate/2`,
/// ramp < 0, rate ≤ 0, duration ≤ 0.
pub fn sine_force(
    amplitude_n: f64,
    frequency_hz: f64,
    ramp_s: f64,
    rate_hz: f64,
    duration_s: f64,
) -> Result<ForceRecord, GenerateError> {
    check("amplitude_n", amplitude_n, true, "a finite amplitude")?;
    check(
        "frequency_hz",
        frequency_hz,
        frequency_hz >= 0.0,
        "a frequency >= 0",
    )?;
    check("ramp_s", ramp_s, ramp_s >= 0.0, "a ramp length >= 0")?;
    let n = sample_count(rate_hz, duration_s)?;
    below_nyquist(frequency_hz, rate_hz)?;
    let force = times(rate_hz, n)
        .iter()
        .map(|&t| {
            let r = if ramp_s > 0.0 {
                (t / ramp_s).min(1.0)
            } else {
                1.0
            };
            r * amplitude_n * (2.0 * PI * frequency_hz * t).sin()
        })
        .collect();
    ForceRecord::from_rate(rate_hz, force).map_err(|e| GenerateError::Invalid {
        name: "amplitude_n",
        value: amplitude_n,
        expected: format!("a value for which the generated force is finite ({e})"),
    })
}

/// A triangle displacement wave with rounded reversals (the paper's T tests): constant
/// velocity `±V` between reversals, and at each reversal a constant-acceleration arc of
/// `±A_r` that turns `+V` into `−V` in `2V/A_r` seconds. It starts at `u = 0` moving up at `V`.
///
/// The peak displacement is exactly `U`, the constant velocity exactly `V`, and the period is
/// `T = 4U/V + 2V/A_r` (a sharp triangle of the same `U`, `V` has `4U/V`). Table I of the
/// paper lists `U`, `V` and a frequency ≈ `V/(4U)`.
///
/// # Errors
/// Amplitude, velocity or acceleration ≤ 0 or non-finite, or an arc that does not fit
/// (`V²/(2A_r) > U`).
pub fn triangle_motion(
    amplitude_m: f64,
    velocity_m_s: f64,
    reversal_acceleration_m_s2: f64,
    rate_hz: f64,
    duration_s: f64,
) -> Result<Motion, GenerateError> {
    let (u_max, v_c, a_r) = (amplitude_m, velocity_m_s, reversal_acceleration_m_s2);
    check("amplitude_m", u_max, u_max > 0.0, "an amplitude > 0")?;
    check("velocity_m_s", v_c, v_c > 0.0, "a velocity > 0")?;
    check(
        "reversal_acceleration_m_s2",
        a_r,
        a_r > 0.0,
        "an acceleration > 0",
    )?;
    let arc = v_c * v_c / (2.0 * a_r);
    check(
        "reversal_acceleration_m_s2",
        a_r,
        arc <= u_max,
        &format!(
            "at least V²/(2U) = {} m/s² so the reversal arcs fit inside the stroke",
            v_c * v_c / (2.0 * u_max)
        ),
    )?;
    let n = sample_count(rate_hz, duration_s)?;
    let t1 = (u_max - arc) / v_c; // constant-velocity time from 0 to the arc
    let tau = v_c / a_r; // half the arc
    let period = 4.0 * t1 + 4.0 * tau;
    let u1 = u_max - arc;
    let at = |t: f64| -> (f64, f64, f64) {
        let p = t.rem_euclid(period);
        if p < t1 {
            (v_c * p, v_c, 0.0)
        } else if p < t1 + 2.0 * tau {
            let q = p - t1;
            (u1 + v_c * q - 0.5 * a_r * q * q, v_c - a_r * q, -a_r)
        } else if p < 3.0 * t1 + 2.0 * tau {
            let q = p - (t1 + 2.0 * tau);
            (u1 - v_c * q, -v_c, 0.0)
        } else if p < 3.0 * t1 + 4.0 * tau {
            let q = p - (3.0 * t1 + 2.0 * tau);
            (-u1 - v_c * q + 0.5 * a_r * q * q, -v_c + a_r * q, a_r)
        } else {
            let q = p - (3.0 * t1 + 4.0 * tau);
            (-u1 + v_c * q, v_c, 0.0)
        }
    };
    let t = times(rate_hz, n);
    let (mut u, mut v, mut a) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for &ti in &t {
        let (ui, vi, ai) = at(ti);
        u.push(ui);
        v.push(vi);
        a.push(ai);
    }
    generated_motion(t, u, v, a, ("amplitude_m", amplitude_m))
}

/// SplitMix64: a small, fast, well-mixed generator; seeded runs are reproducible everywhere.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator with the given seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }
}

/// Band-limited white-noise table motion (the paper's WN tests): the acceleration has a flat
/// spectrum between `band_hz.0` and `band_hz.1` (every FFT bin of the record in the band, equal
/// amplitude, random phase from `seed`) and RMS `rms_acceleration_m_s2`; velocity and
/// displacement are its exact integrals bin by bin. The record is periodic over its length, so
/// nothing drifts, and it starts and ends at the same state.
///
/// # Errors
/// RMS ≤ 0, a band that is empty, inverted, negative or above the Nyquist frequency, or no FFT
/// bin inside the band for this duration.
pub fn white_noise_motion(
    rms_acceleration_m_s2: f64,
    band_hz: (f64, f64),
    seed: u64,
    rate_hz: f64,
    duration_s: f64,
) -> Result<Motion, GenerateError> {
    check(
        "rms_acceleration_m_s2",
        rms_acceleration_m_s2,
        rms_acceleration_m_s2 > 0.0,
        "an RMS > 0",
    )?;
    let n = sample_count(rate_hz, duration_s)?;
    let (lo, hi) = band_hz;
    check(
        "band_hz[0]",
        lo,
        lo > 0.0,
        "a lower band edge > 0 Hz (a DC component would drift)",
    )?;
    check(
        "band_hz[1]",
        hi,
        hi > lo && hi < 0.5 * rate_hz,
        "an upper band edge above the lower one and below the Nyquist frequency",
    )?;
    // The record is periodic with period n/rate; bin k has frequency k·rate/n.
    let df = rate_hz / n as f64;
    let k_lo = (lo / df).ceil().max(1.0) as usize;
    let k_hi = ((hi / df).floor() as usize).min((n - 1) / 2);
    check(
        "band_hz[1]",
        hi,
        k_hi >= k_lo,
        "a band holding at least one frequency bin of the record (lengthen duration_s)",
    )?;
    let bins = k_hi - k_lo + 1;
    // K unit cosines have RMS √(K/2).
    let c = rms_acceleration_m_s2 * (2.0 / bins as f64).sqrt();
    let mut rng = SplitMix64::new(seed);
    let phases: Vec<f64> = (0..bins).map(|_| 2.0 * PI * rng.uniform()).collect();
    // Three spectra (a, v, u) synthesised by inverse FFT: x_j = Σ_k Re(X_k e^{2πi kj/n}).
    let mut planner = FftPlanner::<f64>::new();
    let fft = planner.plan_fft_inverse(n);
    let synth = |coef: &dyn Fn(f64, f64) -> Complex<f64>| -> Vec<f64> {
        let mut spec = vec![Complex::new(0.0, 0.0); n];
        for (i, k) in (k_lo..=k_hi).enumerate() {
            let w = 2.0 * PI * k as f64 * df;
            // A real cosine amplitude C with phase φ is C/2·e^{iφ} at +k and its conjugate at −k.
            let z = coef(w, phases[i]) * 0.5;
            spec[k] = z;
            spec[n - k] = z.conj();
        }
        fft.process(&mut spec);
        spec.iter().map(|z| z.re).collect()
    };
    // a = C cos(wt + φ); v = C/w sin(wt + φ); u = −C/w² cos(wt + φ).
    let a = synth(&|_, ph| Complex::from_polar(c, ph));
    let v = synth(&|w, ph| Complex::from_polar(c / w, ph) * Complex::new(0.0, -1.0));
    let u = synth(&|w, ph| Complex::from_polar(-c / (w * w), ph));
    let t = times(rate_hz, n);
    generated_motion(t, u, v, a, ("rms_acceleration_m_s2", rms_acceleration_m_s2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frequencies at or above the Nyquist frequency, and waveforms too large for double
    /// precision, are parameter errors naming the parameter, never a panic.
    #[test]
    fn extreme_parameters_are_errors_not_panics() {
        let name = |r: Result<Motion, GenerateError>| match r {
            Err(GenerateError::Invalid { name, .. }) => name,
            Ok(_) => "accepted",
        };
        assert_eq!(name(sine_motion(0.1, 1e300, 1024.0, 1.0)), "frequency_hz");
        assert_eq!(name(sine_motion(0.1, 512.0, 1024.0, 1.0)), "frequency_hz");
        assert_eq!(name(sine_motion(1e305, 400.0, 1024.0, 1.0)), "amplitude_m");
        assert_eq!(name(sine_motion(0.1, 511.0, 1024.0, 1.0)), "accepted");
        let force = sine_force(1e5, 600.0, 0.0, 1024.0, 1.0);
        assert!(matches!(
            force,
            Err(GenerateError::Invalid {
                name: "frequency_hz",
                ..
            })
        ));
        assert!(sine_force(f64::MAX, 100.0, 0.0, 1024.0, 1.0).is_ok());
    }

    use platen_signal::metrics::rms;

    fn peak(x: &[f64]) -> f64 {
        x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// Table I: T5 (25 cm, 10 cm/s), T8 (75 cm, 50 cm/s), T12 (67.5 cm, 180 cm/s).
    #[test]
    fn triangles_hit_the_amplitude_and_velocity_of_table_1() {
        for (u, v) in [(0.25, 0.10), (0.75, 0.50), (0.675, 1.80)] {
            let a_r = 5.0 * v * v / u; // arcs take 20 % of a quarter period
            let period = 4.0 * u / v + 2.0 * v / a_r;
            let m = triangle_motion(u, v, a_r, 1024.0, 2.0 * period).unwrap();
            assert!(
                (peak(m.u_m()) - u).abs() < 1e-6 * u + 0.5 * a_r / 1024f64.powi(2),
                "U for {u}"
            );
            assert!((peak(m.v_m_s()) - v).abs() < 1e-12, "V for {v}");
            assert!((peak(m.a_m_s2()) - a_r).abs() < 1e-12);
            // v is the derivative of u and a of v (checked by differences).
            let d = platen_integrate::derivative(m.t_s(), m.u_m());
            let err = d
                .iter()
                .zip(m.v_m_s())
                .skip(1)
                .take(d.len() - 2)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(err < a_r / 1024.0, "{err}");
        }
        assert!(
            triangle_motion(0.05, 1.0, 1.0, 1024.0, 10.0).is_err(),
            "arc larger than the stroke"
        );
    }

    /// Table II: S9 (20 cm, 0.6 Hz → 75.4 cm/s, 0.29 g) and S12 (20 cm, 1.43 Hz → 1.796 m/s, 1.644 g).
    #[test]
    fn sines_hit_the_velocity_and_acceleration_of_table_2() {
        for (u, f, v, a_g) in [(0.20, 0.6, 0.7536, 0.29), (0.20, 1.43, 1.7961, 1.644)] {
            let m = sine_motion(u, f, 1024.0, 10.0).unwrap();
            assert!((peak(m.v_m_s()) - v).abs() < 1e-3 * v, "{f}");
            assert!((peak(m.a_m_s2()) / 9.80665 - a_g).abs() < 0.01 * a_g, "{f}");
        }
    }

    /// WN10%g: RMS acceleration 0.1 g exactly (the bins are orthogonal over the record), the
    /// velocity and displacement are the integrals of the acceleration, and the seed decides.
    #[test]
    fn white_noise_has_the_target_rms_and_consistent_integrals() {
        let m = white_noise_motion(0.980665, (0.5, 20.0), 7, 256.0, 30.0).unwrap();
        let r = rms(m.a_m_s2());
        // The record spans n samples but its period is n/rate: the RMS over n samples is exact.
        assert!((r - 0.980665).abs() < 1e-9, "{r}");
        let dv = platen_integrate::derivative(m.t_s(), m.v_m_s());
        let err = rms(&dv
            .iter()
            .zip(m.a_m_s2())
            .skip(1)
            .take(dv.len() - 2)
            .map(|(x, y)| x - y)
            .collect::<Vec<_>>());
        assert!(err < 0.02 * r, "dv/dt vs a: {err}");
        let again = white_noise_motion(0.980665, (0.5, 20.0), 7, 256.0, 30.0).unwrap();
        assert_eq!(m, again);
        let other = white_noise_motion(0.980665, (0.5, 20.0), 8, 256.0, 30.0).unwrap();
        assert_ne!(m.u_m(), other.u_m());
    }
}
