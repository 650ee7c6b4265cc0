//! The response spectra of the drive iteration: the error it reports per iteration
//! ([`SpectrumCheck`]) and the acceptance check of an achieved acceleration against a
//! required spectrum ([`spectrum_acceptance`], [`SpectrumAcceptance`]).

use serde::Serialize;

use platen_signal::ResponseSpectrum;

use crate::error::Result;
use crate::settings::SpectrumSettings;

/// The response spectrum of the error report and the target's own spectrum.
pub(crate) struct SpectrumCheck {
    spectrum: ResponseSpectrum,
    target: Vec<f64>,
}

impl SpectrumCheck {
    pub(crate) fn new(
        settings: &SpectrumSettings,
        sample_rate_hz: f64,
        target_a: &[f64],
    ) -> Result<Self> {
        let (lo, hi) = settings.periods_s;
        let periods = ResponseSpectrum::log_periods_s(lo, hi, settings.count)?;
        let spectrum = ResponseSpectrum::new(&periods, settings.damping_ratio, sample_rate_hz)?;
        let target = spectrum.pseudo_acceleration_m_s2(target_a);
        Ok(Self { spectrum, target })
    }

    /// The periods where the achieved spectrum's ratio to the target's is outside
    /// `1 + band.0 … 1 + band.1` (a period whose target spectrum is 0 is left out).
    pub(crate) fn outside(&self, achieved_a: &[f64], band: (f64, f64)) -> Vec<SpectrumMiss> {
        let psa = self.spectrum.pseudo_acceleration_m_s2(achieved_a);
        psa.iter()
            .zip(&self.target)
            .zip(self.spectrum.oscillators())
            .filter(|((_, t), _)| **t > 0.0)
            .map(|((p, t), o)| SpectrumMiss {
                period_s: o.period_s(),
                ratio: p / t,
            })
            .filter(|m| !(1.0 + band.0..=1.0 + band.1).contains(&m.ratio))
            .collect()
    }

    /// The largest relative error and its period.
    pub(crate) fn error(&self, achieved_a: &[f64]) -> (f64, f64) {
        let psa = self.spectrum.pseudo_acceleration_m_s2(achieved_a);
        let mut worst = (0.0, self.spectrum.oscillators()[0].period_s());
        for ((p, t), o) in psa
            .iter()
            .zip(&self.target)
            .zip(self.spectrum.oscillators())
        {
            let e = if *t > 0.0 { (p / t - 1.0).abs() } else { 0.0 };
            if e > worst.0 {
                worst = (e, o.period_s());
            }
        }
        worst
    }
}

/// The band of a response-spectrum acceptance check, as fractions of the required
/// spectrum: −10 % / +30 %, the tolerance AC156-style qualification tests put on the test
/// response spectrum against the required one.
pub const ACCEPTANCE_BAND: (f64, f64) = (-0.10, 0.30);

/// A response-spectrum acceptance check of an achieved acceleration against a required
/// response spectrum (RRS): the target's own spectrum, or one given as its own CSV
/// ([`crate::RequiredSpectrum`]); the periods where the achieved spectrum falls outside the
/// band.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpectrumAcceptance {
    /// Damping ratio of the spectra.
    pub damping_ratio: f64,
    /// Shortest and longest period checked, s.
    pub periods_s: (f64, f64),
    /// Periods checked (evenly spaced in logarithm).
    pub count: usize,
    /// The band, fractions of the required spectrum (`(-0.1, 0.3)`: 90 % to 130 %).
    pub band: (f64, f64),
    /// Whether the achieved spectrum is inside the band at every period.
    pub within: bool,
    /// The periods outside the band, shortest first.
    pub outside: Vec<SpectrumMiss>,
    /// The required spectrum's file (`null`: the target's own spectrum is the required one).
    pub rrs: Option<String>,
}

impl SpectrumAcceptance {
    /// What the achieved spectrum was held against, in words: "the target's" or "the
    /// required spectrum `file`".
    pub fn required_name(&self) -> String {
        match &self.rrs {
            Some(file) => format!("the required spectrum `{file}`"),
            None => "the target's".to_owned(),
        }
    }

    /// The check in one line, `label` naming the spectrum: its damping, periods, required
    /// spectrum and band, then "within at every period" or the periods outside with their
    /// ratios.
    pub fn line(&self, label: &str) -> String {
        // Periods to four decimals: 0.05 and 2 as given, an RRS's 1/33 Hz as 0.0303.
        let round = |p: f64| (p * 1e4).round() / 1e4;
        let head = format!(
            "{label} ({:.0} %, {} periods {}–{} s) against {}, band {:+.0}/{:+.0} %:",
            100.0 * self.damping_ratio,
            self.count,
            round(self.periods_s.0),
            round(self.periods_s.1),
            self.required_name(),
            100.0 * self.band.0,
            100.0 * self.band.1
        );
        if self.within {
            format!("{head} within at every period")
        } else {
            let list: Vec<String> = self
                .outside
                .iter()
                .map(|m| format!("{:.3} s ({:.0} %)", m.period_s, 100.0 * m.ratio))
                .collect();
            format!(
                "{head} OUTSIDE at {} of {}: {}",
                self.outside.len(),
                self.count,
                list.join(", ")
            )
        }
    }
}

/// One period where an achieved spectrum is outside its acceptance band.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpectrumMiss {
    /// The period, s.
    pub period_s: f64,
    /// Achieved over required pseudo-acceleration.
    pub ratio: f64,
}

/// The acceptance check of `achieved_a` against `target_a` (both at `sample_rate_hz`) on the
/// spectrum of `settings`, with the band `band`.
///
/// # Errors
/// Bad spectrum settings.
pub fn spectrum_acceptance(
    settings: &SpectrumSettings,
    sample_rate_hz: f64,
    target_a: &[f64],
    achieved_a: &[f64],
    band: (f64, f64),
) -> Result<SpectrumAcceptance> {
    let check = SpectrumCheck::new(settings, sample_rate_hz, target_a)?;
    let outside = check.outside(achieved_a, band);
    Ok(SpectrumAcceptance {
        damping_ratio: settings.damping_ratio,
        periods_s: settings.periods_s,
        count: settings.count,
        band,
        within: outside.is_empty(),
        outside,
        rrs: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The acceptance check against an independent truth: response spectra are linear in
    /// the record, so an achieved acceleration `c` times the target's has the ratio `c` at
    /// every period (to rounding, 1e-12). 0.91, 1.2 and 1.29 are inside −10/+30 %, 0.85 and 1.35
    /// outside at all 50 periods; a record whose short-period content alone is doubled is
    /// outside only at the short periods.
    #[test]
    fn the_spectrum_acceptance_check_finds_the_periods_outside_its_band() {
        let fs = 200.0;
        let n = 4000;
        let wave = |t: f64, hf: f64| {
            (std::f64::consts::TAU * 1.3 * t).sin() + hf * (std::f64::consts::TAU * 15.0 * t).sin()
        };
        let target: Vec<f64> = (0..n).map(|i| wave(i as f64 / fs, 0.3)).collect();
        let settings = SpectrumSettings::default();
        for (c, within) in [
            (1.2, true),
            (0.91, true),
            (1.29, true),
            (0.85, false),
            (1.35, false),
        ] {
            let achieved: Vec<f64> = target.iter().map(|a| c * a).collect();
            let r =
                spectrum_acceptance(&settings, fs, &target, &achieved, ACCEPTANCE_BAND).unwrap();
            assert_eq!(r.within, within, "{c}");
            assert_eq!(r.outside.len(), if within { 0 } else { 50 }, "{c}");
            for m in &r.outside {
                assert!((m.ratio - c).abs() < 1e-12, "{c}: {m:?}");
            }
        }
        let achieved: Vec<f64> = (0..n).map(|i| wave(i as f64 / fs, 0.9)).collect();
        let r = spectrum_acceptance(&settings, fs, &target, &achieved, ACCEPTANCE_BAND).unwrap();
        assert!(!r.within && !r.outside.is_empty() && r.outside.len() < 50);
        println!("short periods outside: {:?}", r.outside);
        assert!(r.outside.iter().all(|m| m.period_s < 0.3 && m.ratio > 1.3));
        assert!(r.outside.windows(2).all(|w| w[0].period_s < w[1].period_s));
    }
}
