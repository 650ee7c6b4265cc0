//! Recorded-like data: what the table's data system would have recorded during a motion test.
//!
//! Given the true motion and the actuator force the model says it needs (an inverse run), this
//! adds the artefacts the paper describes (§1.5) to make a record to test identification and
//! comparison against:
//!
//! * **oil-column ringing** at 10.66 Hz after every velocity reversal: a damped sinusoid
//!   (damping ratio [`ArtefactSettings::oil_column_damping_ratio`]) whose amplitude is a
//!   fraction of the force jump at the reversal (`2·F_s`), starting at the reversal;
//! * a **246 Hz servo-valve tone** of constant amplitude on the force (below the 256 Hz Nyquist
//!   frequency of the 512 Hz recorder, so it shows in the record as in the paper);
//! * **pressure resolution**: the force is quantised in steps of 689.5 Pa × the total piston
//!   area (the differential pressure of both actuators read at the transducers' resolution);
//! * **sensor noise**: Gaussian white noise on force, displacement (with the transducer's
//!   resolution) and acceleration; the acceleration channel also passes the signal
//!   conditioner's 100 Hz analog low-pass (2nd-order Butterworth, causal, as an analog filter is);
//! * the **velocity** channel is not measured: it is estimated by the crossover filter from the
//!   recorded displacement and acceleration, as the paper's data system did.
//!
//! Everything is drawn from one seeded generator, so the same seed gives the same record.

use std::f64::consts::PI;

use platen_integrate::Trajectory;

use crate::generate::SplitMix64;

/// The artefacts and their sizes. [`Default`] gives the values documented on each field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArtefactSettings {
    /// Oil-column frequency, Hz (default 10.66, the paper's).
    pub oil_column_hz: f64,
    /// Damping ratio of the oil-column ringing (default 0.05).
    pub oil_column_damping_ratio: f64,
    /// Ringing amplitude as a fraction of the force jump at a reversal (default 0.3).
    pub oil_column_fraction: f64,
    /// Servo-valve tone frequency, Hz (default 246, the paper's).
    pub valve_tone_hz: f64,
    /// Servo-valve tone amplitude, N (default 2 kN).
    pub valve_tone_n: f64,
    /// Pressure resolution of the transducers, Pa (default 689.5, the paper's).
    pub pressure_resolution_pa: f64,
    /// Total piston area of both actuators, m² (default 0.33: the 2.6 and 4.2 MN actuators
    /// at 20.7 MPa supply pressure).
    pub piston_area_m2: f64,
    /// Force noise, N RMS (default 500 N).
    pub force_noise_n: f64,
    /// Displacement noise, m RMS (default 20 µm) and resolution, m (default 2 µm).
    pub displacement_noise_m: f64,
    /// Displacement transducer resolution, m (default 2 µm).
    pub displacement_resolution_m: f64,
    /// Acceleration noise, m/s² RMS (default 0.005 g).
    pub acceleration_noise_m_s2: f64,
    /// Cut-off of the accelerometer conditioner's analog low-pass, Hz (default 100).
    pub accelerometer_cutoff_hz: f64,
    /// Crossover frequency of the velocity estimate, Hz (default 2).
    pub crossover_hz: f64,
}

impl Default for ArtefactSettings {
    fn default() -> Self {
        Self {
            oil_column_hz: 10.66,
            oil_column_damping_ratio: 0.05,
            oil_column_fraction: 0.3,
            valve_tone_hz: 246.0,
            valve_tone_n: 2e3,
            pressure_resolution_pa: 689.5,
            piston_area_m2: 0.33,
            force_noise_n: 500.0,
            displacement_noise_m: 20e-6,
            displacement_resolution_m: 2e-6,
            acceleration_noise_m_s2: 0.005 * platen_model::STANDARD_GRAVITY_M_S2,
            accelerometer_cutoff_hz: 100.0,
            crossover_hz: 2.0,
        }
    }
}

/// The recorded channels, one value per sample of the input.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Recorded {
    /// Time, s.
    pub t_s: Vec<f64>,
    /// Recorded displacement, m.
    pub u_m: Vec<f64>,
    /// Velocity estimated by the crossover filter, m/s.
    pub v_m_s: Vec<f64>,
    /// Recorded acceleration, m/s².
    pub a_m_s2: Vec<f64>,
    /// Recorded actuator force, N.
    pub force_n: Vec<f64>,
}

impl Recorded {
    /// Column names, in the order of [`Recorded::columns`].
    pub const COLUMN_NAMES: [&'static str; 5] = ["t_s", "u_m", "v_m_s", "a_m_s2", "force_n"];

    /// The columns in the order of [`Recorded::COLUMN_NAMES`].
    pub fn columns(&self) -> [&[f64]; 5] {
        [
            &self.t_s,
            &self.u_m,
            &self.v_m_s,
            &self.a_m_s2,
            &self.force_n,
        ]
    }
}

/// Makes the recorded-like channels of an inverse run `truth` (uniformly sampled; the true
/// motion and the model's force), with the static friction threshold `static_threshold_n`
/// setting the size of the force jump at reversals.
///
/// # Errors
/// A message if the record is too short or not uniformly sampled, or the crossover filter
/// cannot be built at its rate.
pub fn recorded_like(
    truth: &Trajectory,
    static_threshold_n: f64,
    settings: &ArtefactSettings,
    seed: u64,
) -> Result<Recorded, String> {
    let n = truth.len();
    if n < 8 {
        return Err(format!(
            "{n} samples: a recorded-like record needs at least 8"
        ));
    }
    let dt = platen_integrate::uniform_interval_s(&truth.t_s).map_err(|e| e.to_string())?;
    let rate = 1.0 / dt;
    let mut rng = SplitMix64::new(seed);

    // Force: model force + ringing after reversals + valve tone + noise, then quantised.
    let mut force = truth.force_n.clone();
    add_oil_column_ringing(&mut force, truth, settings, static_threshold_n, dt);
    let tone_phase = 2.0 * PI * rng.uniform();
    let step = settings.pressure_resolution_pa * settings.piston_area_m2;
    for (f, &t) in force.iter_mut().zip(&truth.t_s) {
        *f += settings.valve_tone_n * (2.0 * PI * settings.valve_tone_hz * t + tone_phase).sin();
        *f += settings.force_noise_n * rng.normal();
        if step > 0.0 {
            *f = (*f / step).round() * step;
        }
    }

    // Displacement: true + noise, at the transducer's resolution.
    let res = settings.displacement_resolution_m;
    let u: Vec<f64> = truth
        .u_m
        .iter()
        .map(|&u| {
            let x = u + settings.displacement_noise_m * rng.normal();
            if res > 0.0 {
                (x / res).round() * res
            } else {
                x
            }
        })
        .collect();

    // Acceleration: true + noise through the conditioner's causal 2nd-order low-pass.
    let raw: Vec<f64> = truth
        .a_m_s2
        .iter()
        .map(|&a| a + settings.acceleration_noise_m_s2 * rng.normal())
        .collect();
    let a = if settings.accelerometer_cutoff_hz < 0.5 * rate {
        causal_butterworth2(&raw, settings.accelerometer_cutoff_hz, rate)
    } else {
        raw
    };

    // Velocity: crossover estimate from the recorded displacement and acceleration.
    let crossover = platen_signal::CrossoverVelocity::butterworth(2, settings.crossover_hz, rate)
        .map_err(|e| e.to_string())?;
    let v = crossover.estimate(&u, &a).map_err(|e| e.to_string())?;

    Ok(Recorded {
        t_s: truth.t_s.clone(),
        u_m: u,
        v_m_s: v,
        a_m_s2: a,
        force_n: force,
    })
}

/// Adds the oil column's ringing at `settings.oil_column_hz` after every velocity reversal of
/// `truth` to `force`, in the direction of the new motion, sized by the friction jump
/// (twice the static threshold `static_threshold_n`).
fn add_oil_column_ringing(
    force: &mut [f64],
    truth: &Trajectory,
    settings: &ArtefactSettings,
    static_threshold_n: f64,
    dt: f64,
) {
    let n = truth.len();
    let rate = 1.0 / dt;
    let w_oil = 2.0 * PI * settings.oil_column_hz;
    let zeta = settings.oil_column_damping_ratio;
    let wd = w_oil * (1.0 - zeta * zeta).sqrt();
    let ring_amp = settings.oil_column_fraction * 2.0 * static_threshold_n;
    let ring_len = ((8.0 / (zeta * w_oil)) * rate).ceil() as usize; // e^-8 of the start
    for i in 1..n {
        let (a, b) = (truth.v_m_s[i - 1], truth.v_m_s[i]);
        if a != 0.0 && b != 0.0 && a.signum() != b.signum()
            || (a != 0.0 && b == 0.0 && i + 1 < n && truth.v_m_s[i + 1].signum() == -a.signum())
        {
            // A reversal between samples i-1 and i: ring in the direction of the new motion.
            let t_r = truth.t_s[i - 1] + dt * a.abs() / (a.abs() + b.abs()).max(f64::MIN_POSITIVE);
            let sign = -a.signum();
            for (j, f) in force.iter_mut().enumerate().skip(i).take(ring_len) {
                let s = truth.t_s[j] - t_r;
                *f += sign * ring_amp * (-zeta * w_oil * s).exp() * (wd * s).sin();
            }
        }
    }
}

/// A causal 2nd-order Butterworth low-pass (bilinear transform, prewarped), starting from the
/// steady state of the first sample: the model of an analog signal conditioner.
fn causal_butterworth2(x: &[f64], cutoff_hz: f64, rate_hz: f64) -> Vec<f64> {
    let k = (PI * cutoff_hz / rate_hz).tan();
    let norm = 1.0 / (1.0 + std::f64::consts::SQRT_2 * k + k * k);
    let b0 = k * k * norm;
    let (b1, b2) = (2.0 * b0, b0);
    let a1 = 2.0 * (k * k - 1.0) * norm;
    let a2 = (1.0 - std::f64::consts::SQRT_2 * k + k * k) * norm;
    let mut y = Vec::with_capacity(x.len());
    let (mut x1, mut x2) = (x[0], x[0]);
    let (mut y1, mut y2) = (x[0], x[0]);
    for &xi in x {
        let yi = b0 * xi + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
        (x2, x1) = (x1, xi);
        (y2, y1) = (y1, yi);
        y.push(yi);
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_causal_conditioner_filter_has_unit_dc_gain_and_minus_3_db_at_its_cutoff() {
        let rate = 512.0;
        let dc = causal_butterworth2(&[2.0; 100], 100.0, rate);
        assert!(dc.iter().all(|&y| (y - 2.0).abs() < 1e-12));
        let f = 100.0;
        let x: Vec<f64> = (0..4096)
            .map(|j| (2.0 * PI * f * j as f64 / rate).sin())
            .collect();
        let y = causal_butterworth2(&x, f, rate);
        let amp = y[2048..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            (amp - std::f64::consts::FRAC_1_SQRT_2).abs() < 0.02,
            "{amp}"
        );
    }
}
