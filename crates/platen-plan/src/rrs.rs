//! A required response spectrum (RRS) given as its own CSV, the spectrum a qualification test
//! is judged against ([`RequiredSpectrum`]): AC156-style tests give the RRS, not a record, and
//! accept the test when the achieved (test) response spectrum lies within a band of it.
//!
//! # The file
//!
//! One row per point, in any order (sorted by period when read): the period `period_s` (s)
//! or the frequency `frequency_hz` (Hz, `T = 1/f`), and the pseudo-acceleration `psa_m_s2`
//! (m/s²) or `psa_g` (in g, 9.80665 m/s²). A multi-axis RRS gives one spectrum per axis on
//! the same periods: `x_psa_m_s2` (or `x_psa_g`), and the same for `y` and `z`; an axis
//! without a column is checked against its target's own spectrum. Other columns are ignored.
//! Every period must be distinct and every pseudo-acceleration above zero (a ratio to it is
//! what is judged).
//!
//! The damping ratio of the achieved spectrum is the RRS's, given with it (5 % unless told).

use std::path::{Path, PathBuf};

use platen_io::IoError;
use platen_signal::ResponseSpectrum;

use crate::error::{PlanError, Result};
use crate::iterate::{SpectrumAcceptance, SpectrumMiss};

/// Standard gravity, m/s², for `psa_g` columns.
const G_M_S2: f64 = 9.80665;

/// The damping ratio of an RRS when none is given: 5 %.
pub const DEFAULT_RRS_DAMPING: f64 = 0.05;

/// A required response spectrum: pseudo-accelerations at periods, for one damping ratio.
#[derive(Debug, Clone, PartialEq)]
pub struct RequiredSpectrum {
    origin: PathBuf,
    periods_s: Vec<f64>,
    psa_m_s2: Vec<f64>,
    damping_ratio: f64,
}

impl RequiredSpectrum {
    /// The RRS of `psa_m_s2` at `periods_s` (the same length, at least one point, in any
    /// order: sorted here), damping ratio `damping_ratio` in `[0, 1)`; `origin` names it in
    /// messages.
    ///
    /// # Errors
    /// [`PlanError::Target`] for lengths that differ, no point, a period that is not finite
    /// and > 0 or appears twice, a pseudo-acceleration that is not finite and > 0, or a
    /// damping ratio outside `[0, 1)`; the message gives the point's 0-based index.
    pub fn new(
        origin: &Path,
        periods_s: Vec<f64>,
        psa_m_s2: Vec<f64>,
        damping_ratio: f64,
    ) -> Result<Self> {
        let bad = |message: String| PlanError::Target {
            origin: origin.display().to_string(),
            message: format!("required response spectrum: {message}"),
        };
        if periods_s.len() != psa_m_s2.len() {
            return Err(bad(format!(
                "{} periods but {} pseudo-accelerations",
                periods_s.len(),
                psa_m_s2.len()
            )));
        }
        if periods_s.is_empty() {
            return Err(bad("no point: expected at least one period".into()));
        }
        if !(0.0..1.0).contains(&damping_ratio) {
            return Err(bad(format!(
                "damping ratio {damping_ratio}: expected a fraction in [0, 1) (0.05 for 5 %)"
            )));
        }
        for (k, (t, a)) in periods_s.iter().zip(&psa_m_s2).enumerate() {
            if !(t.is_finite() && *t > 0.0) {
                return Err(bad(format!(
                    "point {k}: period {t} s, expected finite and > 0"
                )));
            }
            if !(a.is_finite() && *a > 0.0) {
                return Err(bad(format!(
                    "point {k}: pseudo-acceleration {a} m/s², expected finite and > 0 (the \
                     achieved spectrum is judged by its ratio to it)"
                )));
            }
        }
        let mut order: Vec<usize> = (0..periods_s.len()).collect();
        order.sort_by(|&i, &j| periods_s[i].total_cmp(&periods_s[j]));
        if let Some(w) = order
            .windows(2)
            .find(|w| periods_s[w[0]] == periods_s[w[1]])
        {
            return Err(bad(format!(
                "points {} and {} have the same period {} s",
                w[0].min(w[1]),
                w[0].max(w[1]),
                periods_s[w[0]]
            )));
        }
        Ok(Self {
            origin: origin.to_owned(),
            periods_s: order.iter().map(|&i| periods_s[i]).collect(),
            psa_m_s2: order.iter().map(|&i| psa_m_s2[i]).collect(),
            damping_ratio,
        })
    }

    /// Reads a one-axis RRS CSV (see the [module documentation](self)): `period_s` or
    /// `frequency_hz`, and `psa_m_s2` or `psa_g`.
    ///
    /// # Errors
    /// [`PlanError::Io`] naming the file (and line): unreadable, a bad cell, a missing or
    /// doubled column, a period or pseudo-acceleration that is not > 0, periods that repeat.
    pub fn read_csv(path: &Path, damping_ratio: f64) -> Result<Self> {
        let mut file = RrsFile::read(path, &[""])?;
        let psa = file.psa.remove(0).ok_or_else(|| {
            record(
                path,
                "a required response spectrum needs the column `psa_m_s2` (m/s²) or `psa_g` (g) \
                 beside `period_s` or `frequency_hz`"
                    .into(),
            )
        })?;
        file.spectrum(psa, damping_ratio)
    }

    /// Reads a three-axis RRS CSV (see the [module documentation](self)): `period_s` or
    /// `frequency_hz`, and per axis `x_psa_m_s2` or `x_psa_g` (the same for `y`, `z`); the
    /// axes without a column are `None`.
    ///
    /// # Errors
    /// As [`RequiredSpectrum::read_csv`]; no axis's column.
    pub fn read_csv_axes(path: &Path, damping_ratio: f64) -> Result<[Option<Self>; 3]> {
        let file = RrsFile::read(path, &["x_", "y_", "z_"])?;
        if file.psa.iter().all(Option::is_none) {
            return Err(record(
                path,
                "a three-component required response spectrum needs at least one of the \
                 columns x_psa_m_s2, y_psa_m_s2, z_psa_m_s2 (or x_psa_g, …) beside `period_s` \
                 or `frequency_hz`; an axis without one is checked against its target"
                    .into(),
            ));
        }
        let mut out = [None, None, None];
        for (slot, psa) in out.iter_mut().zip(file.psa.clone()) {
            if let Some(psa) = psa {
                *slot = Some(file.spectrum(psa, damping_ratio)?);
            }
        }
        Ok(out)
    }

    /// Where it comes from.
    pub fn origin(&self) -> &Path {
        &self.origin
    }

    /// The periods, s, shortest first.
    pub fn periods_s(&self) -> &[f64] {
        &self.periods_s
    }

    /// The required pseudo-accelerations at [`RequiredSpectrum::periods_s`], m/s².
    pub fn psa_m_s2(&self) -> &[f64] {
        &self.psa_m_s2
    }

    /// The damping ratio.
    pub fn damping_ratio(&self) -> f64 {
        self.damping_ratio
    }

    /// Whether a drive at `sample_rate_hz` can be judged against it: its shortest period is
    /// at least two samples (the drive carries nothing above its Nyquist frequency). A plan
    /// checks this before any run.
    ///
    /// # Errors
    /// [`PlanError::Target`] naming the shortest period and the rate.
    pub fn check_rate(&self, sample_rate_hz: f64) -> Result<()> {
        let shortest = 2.0 / sample_rate_hz;
        if self.periods_s[0] < shortest * (1.0 - 1e-12) {
            return Err(PlanError::Target {
                origin: self.origin.display().to_string(),
                message: format!(
                    "required response spectrum: its shortest period {} s is shorter than two \
                     samples of the drive at {sample_rate_hz} Hz ({shortest} s): the drive \
                     carries nothing above {} Hz to judge (leave out the periods below \
                     {shortest} s)",
                    self.periods_s[0],
                    0.5 * sample_rate_hz
                ),
            });
        }
        Ok(())
    }

    /// The acceptance check of `achieved_a` (m/s², at `sample_rate_hz`) against this RRS with
    /// the band `band` (fractions: `(-0.1, 0.3)` is 90 % to 130 %): the achieved spectrum at
    /// the RRS's own periods and damping.
    ///
    /// # Errors
    /// As [`RequiredSpectrum::check_rate`].
    pub fn acceptance(
        &self,
        sample_rate_hz: f64,
        achieved_a: &[f64],
        band: (f64, f64),
    ) -> Result<SpectrumAcceptance> {
        self.check_rate(sample_rate_hz)?;
        let spectrum = ResponseSpectrum::new(&self.periods_s, self.damping_ratio, sample_rate_hz)?;
        let psa = spectrum.pseudo_acceleration_m_s2(achieved_a);
        let outside: Vec<SpectrumMiss> = psa
            .iter()
            .zip(&self.psa_m_s2)
            .zip(&self.periods_s)
            .map(|((p, r), t)| SpectrumMiss {
                period_s: *t,
                ratio: p / r,
            })
            .filter(|m| !(1.0 + band.0..=1.0 + band.1).contains(&m.ratio))
            .collect();
        Ok(SpectrumAcceptance {
            damping_ratio: self.damping_ratio,
            periods_s: (self.periods_s[0], self.periods_s[self.periods_s.len() - 1]),
            count: self.periods_s.len(),
            band,
            within: outside.is_empty(),
            outside,
            rrs: Some(self.origin.display().to_string()),
        })
    }
}

/// A bad RRS file.
fn record(path: &Path, message: String) -> PlanError {
    IoError::Record {
        path: path.to_owned(),
        message,
    }
    .into()
}

/// An RRS file read: its periods (in file order) and, per prefix, its pseudo-accelerations,
/// m/s².
struct RrsFile {
    path: PathBuf,
    periods_s: Vec<f64>,
    psa: Vec<Option<Vec<f64>>>,
}

impl RrsFile {
    fn read(path: &Path, prefixes: &[&str]) -> Result<Self> {
        let psa_names: Vec<[String; 2]> = prefixes
            .iter()
            .map(|p| [format!("{p}psa_m_s2"), format!("{p}psa_g")])
            .collect();
        let mut optional: Vec<&str> = vec!["period_s", "frequency_hz"];
        optional.extend(psa_names.iter().flatten().map(String::as_str));
        let mut table = platen_io::csv::read_table(path, &[], &optional)?;
        let one_of = |table: &mut platen_io::csv::Table, a: &str, b: &str| match (
            table.take_column(a),
            table.take_column(b),
        ) {
            (Some(_), Some(_)) => Err(record(
                path,
                format!("both `{a}` and `{b}`: expected one of them"),
            )),
            (Some(x), None) => Ok(Some((x, true))),
            (None, Some(x)) => Ok(Some((x, false))),
            (None, None) => Ok(None),
        };
        let periods_s = match one_of(&mut table, "period_s", "frequency_hz")? {
            Some((t, true)) => t,
            Some((f, false)) => {
                if let Some(k) = f.iter().position(|f| *f <= 0.0) {
                    return Err(record(
                        path,
                        format!(
                            "line {}, column `frequency_hz`: {} Hz, expected > 0",
                            k + 2,
                            f[k]
                        ),
                    ));
                }
                f.iter().map(|f| 1.0 / f).collect()
            }
            None => {
                return Err(record(
                    path,
                    "a required response spectrum needs the column `period_s` (s) or \
                     `frequency_hz` (Hz)"
                        .into(),
                ))
            }
        };
        if let Some(k) = periods_s.iter().position(|t| *t <= 0.0) {
            return Err(record(
                path,
                format!(
                    "line {}, column `period_s`: {} s, expected > 0",
                    k + 2,
                    periods_s[k]
                ),
            ));
        }
        let mut psa = Vec::new();
        for [si, g] in &psa_names {
            psa.push(match one_of(&mut table, si, g)? {
                Some((a, true)) => Some(a),
                Some((a, false)) => Some(a.iter().map(|a| a * G_M_S2).collect()),
                None => None,
            });
        }
        Ok(Self {
            path: path.to_owned(),
            periods_s,
            psa,
        })
    }

    /// The spectrum of one column, its errors as the file's (with the line).
    fn spectrum(&self, psa_m_s2: Vec<f64>, damping_ratio: f64) -> Result<RequiredSpectrum> {
        if let Some(k) = psa_m_s2.iter().position(|a| *a <= 0.0) {
            return Err(record(
                &self.path,
                format!(
                    "line {}: pseudo-acceleration {} m/s², expected > 0 (the achieved spectrum \
                     is judged by its ratio to it)",
                    k + 2,
                    psa_m_s2[k]
                ),
            ));
        }
        let mut sorted: Vec<(usize, f64)> = self.periods_s.iter().copied().enumerate().collect();
        sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
        if let Some(w) = sorted.windows(2).find(|w| w[0].1 == w[1].1) {
            return Err(record(
                &self.path,
                format!(
                    "lines {} and {} have the same period {} s",
                    w[0].0.min(w[1].0) + 2,
                    w[0].0.max(w[1].0) + 2,
                    w[0].1
                ),
            ));
        }
        RequiredSpectrum::new(&self.path, self.periods_s.clone(), psa_m_s2, damping_ratio)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_sorted_by_period_and_bad_points_are_named() {
        let o = Path::new("rrs");
        let r = RequiredSpectrum::new(o, vec![1.0, 0.1, 0.5], vec![3.0, 1.0, 2.0], 0.05).unwrap();
        assert_eq!(r.periods_s(), &[0.1, 0.5, 1.0]);
        assert_eq!(r.psa_m_s2(), &[1.0, 2.0, 3.0]);
        let e = RequiredSpectrum::new(o, vec![0.1, 0.2], vec![1.0, 0.0], 0.05).unwrap_err();
        assert!(e.to_string().contains("point 1"), "{e}");
        let e = RequiredSpectrum::new(o, vec![0.2, 0.1, 0.2], vec![1.0; 3], 0.05).unwrap_err();
        assert!(e.to_string().contains("points 0 and 2"), "{e}");
        assert!(RequiredSpectrum::new(o, vec![0.1], vec![1.0], 5.0).is_err());
        assert!(RequiredSpectrum::new(o, vec![], vec![], 0.05).is_err());
    }
}
