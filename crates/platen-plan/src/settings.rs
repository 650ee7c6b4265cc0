//! What a drive iteration is asked to do: its settings, the response spectrum it reports on,
//! and the target of each axis. Plain data, shared by the iteration ([`crate::iterate`]), its
//! correction and its acceptance, which import it and nothing of each other's.

use crate::frf::FrfSource;

/// The default gain `g`.
pub const DEFAULT_GAIN: f64 = 0.7;

/// How the iteration runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterationSettings {
    /// Corrections at most (default 10); 0 runs only the target's own command.
    pub max_iterations: usize,
    /// The gain `g`, in `(0, 2)` (default [`DEFAULT_GAIN`]).
    pub gain: f64,
    /// Stop when the acceleration NRMSE is at most this (default 0.02).
    pub target_nrmse: f64,
    /// The correction band `[f_lo, f_hi]`, Hz (default `[0.1, min(50, 0.45·f_s)]`).
    pub band_hz: Option<(f64, f64)>,
    /// Fraction of each band edge rolled off by a half cosine, in `[0, 0.5]` (default 0.2).
    pub edge_fraction: f64,
    /// `ε` of the regularised inverse, `≥ 0` (default 0.1).
    pub regularisation: f64,
    /// Iterations without improvement that stop the iteration (default 2).
    pub stall_iterations: usize,
    /// The relative decrease of the best NRMSE that counts as an improvement (default 0.005).
    pub min_improvement: f64,
    /// Zero padding of the error before the FFT, s (default: the larger of 4 s and a quarter
    /// of the record; 0 makes the iteration circular on the record itself).
    pub pad_s: Option<f64>,
    /// Half-cosine taper of each correction at both ends of the record, s (default 0.1).
    pub taper_s: f64,
    /// Where `Ĥ` comes from (default [`FrfSource::Auto`]: measured with a specimen,
    /// linearised without).
    pub frf: FrfSource,
    /// The response spectrum the error is reported on.
    pub spectrum: SpectrumSettings,
}

impl Default for IterationSettings {
    fn default() -> Self {
        Self {
            max_iterations: 10,
            gain: DEFAULT_GAIN,
            target_nrmse: 0.02,
            band_hz: None,
            edge_fraction: 0.2,
            regularisation: 0.1,
            stall_iterations: 2,
            min_improvement: 0.005,
            pad_s: None,
            taper_s: 0.1,
            frf: FrfSource::Auto,
            spectrum: SpectrumSettings::default(),
        }
    }
}

/// The response spectrum of `spectrum_error`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectrumSettings {
    /// Damping ratio (default 0.05).
    pub damping_ratio: f64,
    /// Shortest and longest period, s (default 0.05 and 2).
    pub periods_s: (f64, f64),
    /// Periods, evenly spaced in logarithm (default 50).
    pub count: usize,
}

impl Default for SpectrumSettings {
    fn default() -> Self {
        Self {
            damping_ratio: 0.05,
            periods_s: (0.05, 2.0),
            count: 50,
        }
    }
}

/// The default band at `sample_rate_hz`, Hz.
pub fn default_band_hz(sample_rate_hz: f64) -> (f64, f64) {
    (0.1, 50.0_f64.min(0.45 * sample_rate_hz))
}

/// One axis of a multi-axis target: its name and its target motion at the common samples.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisTarget {
    /// The axis: `x`, `y` or `z`.
    pub name: &'static str,
    /// Target displacement (the drive of iteration 0), m.
    pub u_m: Vec<f64>,
    /// Target acceleration, m/s² (all zero on an axis held still).
    pub a_m_s2: Vec<f64>,
}

impl AxisTarget {
    /// An axis held still: zero displacement and acceleration over `samples`.
    pub fn still(name: &'static str, samples: usize) -> Self {
        Self {
            name,
            u_m: vec![0.0; samples],
            a_m_s2: vec![0.0; samples],
        }
    }

    /// The same axis at `level` times its size.
    pub fn scaled(&self, level: f64) -> Self {
        Self {
            name: self.name,
            u_m: self.u_m.iter().map(|u| u * level).collect(),
            a_m_s2: self.a_m_s2.iter().map(|a| a * level).collect(),
        }
    }

    /// Whether the axis is held still (its target acceleration is zero throughout).
    pub fn is_still(&self) -> bool {
        self.a_m_s2.iter().all(|&a| a == 0.0)
    }
}
