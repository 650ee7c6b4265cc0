//! One periodic test's recorded channels, with what is known about the test.

use std::collections::BTreeMap;

use crate::error::{IdentError, Result};

/// The waveform of a periodic test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TestKind {
    /// A sine test (paper: S1–S12): used for the effective mass (Eq. 18/19).
    Sine,
    /// A triangle test with rounded reversals (paper: T1–T12): used for the stiffness
    /// (Eq. 16/17) over its constant-velocity portions.
    Triangle,
}

impl TestKind {
    /// `"sine"` or `"triangle"`.
    pub fn name(self) -> &'static str {
        match self {
            TestKind::Sine => "sine",
            TestKind::Triangle => "triangle",
        }
    }
}

/// The recorded channels of one periodic test, uniformly sampled.
///
/// Displacement `u_m`, acceleration `a_m_s2` and the total actuator force `force_n` are
/// required; the velocity `v_m_s` is optional (without it the crossover estimate of
/// [`platen_signal::CrossoverVelocity`] is made from `u` and `a`, as the paper's data system
/// did). The hold-down pressure and the waveform may be given; the waveform is otherwise
/// recognised from the data, and a test without a pressure is grouped with the other tests
/// without one.
#[derive(Debug, Clone, PartialEq)]
pub struct TestRecord {
    name: String,
    sample_rate_hz: f64,
    start_s: f64,
    u_m: Vec<f64>,
    v_m_s: Option<Vec<f64>>,
    a_m_s2: Vec<f64>,
    force_n: Vec<f64>,
    pressure_pa: Option<f64>,
    kind: Option<TestKind>,
    floors: Option<Floors>,
    channel_delays_s: BTreeMap<&'static str, f64>,
}

/// The channels whose delay against the displacement may be given
/// ([`TestRecord::with_channel_delay_s`]).
pub const DELAYABLE_CHANNELS: [&str; 3] = ["a_m_s2", "force_n", "v_m_s"];

/// The specimen floors of a record whose base shear was removed from its force
/// ([`TestRecord::with_floors`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Floors {
    /// The storeys' masses, kg, bottom first.
    pub masses_kg: Vec<f64>,
    /// Largest |Σ mᵢ·aᵢ| removed, N.
    pub peak_base_shear_n: f64,
}

/// Fewest samples a record may have: far below any real test (a cycle of the paper's
/// fastest test holds 358 samples at 512 Hz); this only rejects degenerate input.
pub const MIN_SAMPLES: usize = 64;

impl TestRecord {
    /// A record sampled at the times `t_s` (uniform to within
    /// [`platen_integrate::UNIFORM_RELATIVE_TOLERANCE`]).
    ///
    /// # Errors
    /// [`IdentError::InvalidRecord`] naming `name` if the channels differ in length, hold
    /// fewer than [`MIN_SAMPLES`] samples or a non-finite value, or the times are not uniform.
    pub fn new(
        name: impl Into<String>,
        t_s: &[f64],
        u_m: Vec<f64>,
        a_m_s2: Vec<f64>,
        force_n: Vec<f64>,
    ) -> Result<Self> {
        let name = name.into();
        let dt =
            platen_integrate::uniform_interval_s(t_s).map_err(|e| IdentError::InvalidRecord {
                test: name.clone(),
                message: format!("time column: {e}"),
            })?;
        let mut rec = Self::from_rate(name, 1.0 / dt, u_m, a_m_s2, force_n)?;
        rec.start_s = t_s[0];
        Ok(rec)
    }

    /// A record sampled at `sample_rate_hz` from time 0.
    ///
    /// # Errors
    /// As [`TestRecord::new`], and for a rate that is not finite and positive.
    pub fn from_rate(
        name: impl Into<String>,
        sample_rate_hz: f64,
        u_m: Vec<f64>,
        a_m_s2: Vec<f64>,
        force_n: Vec<f64>,
    ) -> Result<Self> {
        let name = name.into();
        let invalid = |message: String| IdentError::InvalidRecord {
            test: name.clone(),
            message,
        };
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(invalid(format!(
                "sample rate {sample_rate_hz} Hz: expected a finite rate > 0"
            )));
        }
        let n = u_m.len();
        if n < MIN_SAMPLES {
            return Err(invalid(format!(
                "{n} samples: expected at least {MIN_SAMPLES}"
            )));
        }
        for (what, col) in [("a_m_s2", &a_m_s2), ("force_n", &force_n)] {
            if col.len() != n {
                return Err(invalid(format!(
                    "`{what}` has {} samples, `u_m` has {n}",
                    col.len()
                )));
            }
        }
        for (what, col) in [("u_m", &u_m), ("a_m_s2", &a_m_s2), ("force_n", &force_n)] {
            if let Some(i) = col.iter().position(|x| !x.is_finite()) {
                return Err(invalid(format!(
                    "`{what}` sample {i} is {}: expected a finite number",
                    col[i]
                )));
            }
        }
        Ok(Self {
            name,
            sample_rate_hz,
            start_s: 0.0,
            u_m,
            v_m_s: None,
            a_m_s2,
            force_n,
            pressure_pa: None,
            kind: None,
            floors: None,
            channel_delays_s: BTreeMap::new(),
        })
    }

    /// Adds the recorded (or estimated) velocity channel.
    ///
    /// # Errors
    /// [`IdentError::InvalidRecord`] if its length differs from the other channels' or a
    /// value is not finite.
    pub fn with_velocity(mut self, v_m_s: Vec<f64>) -> Result<Self> {
        if v_m_s.len() != self.u_m.len() {
            return Err(IdentError::InvalidRecord {
                test: self.name.clone(),
                message: format!(
                    "`v_m_s` has {} samples, `u_m` has {}",
                    v_m_s.len(),
                    self.u_m.len()
                ),
            });
        }
        if let Some(i) = v_m_s.iter().position(|x| !x.is_finite()) {
            return Err(IdentError::InvalidRecord {
                test: self.name.clone(),
                message: format!(
                    "`v_m_s` sample {i} is {}: expected a finite number",
                    v_m_s[i]
                ),
            });
        }
        self.v_m_s = Some(v_m_s);
        Ok(self)
    }

    /// Sets the hold-down nitrogen pressure of the test, Pa.
    ///
    /// # Errors
    /// [`IdentError::InvalidRecord`] for a negative or non-finite pressure.
    pub fn with_pressure_pa(mut self, pressure_pa: f64) -> Result<Self> {
        if !(pressure_pa.is_finite() && pressure_pa >= 0.0) {
            return Err(IdentError::InvalidRecord {
                test: self.name.clone(),
                message: format!("hold-down pressure {pressure_pa} Pa: expected a pressure >= 0"),
            });
        }
        self.pressure_pa = Some(pressure_pa);
        Ok(self)
    }

    /// Removes the base shear of a specimen from the force: a shear building fixed on the
    /// platen is pushed by it with `Σ mᵢ·aᵢ` (storey masses `mᵢ`, their absolute
    /// accelerations `aᵢ`), which the recorded actuator force includes and the platen's model
    /// does not. `floors` holds `(mᵢ, aᵢ)` per storey, m/s².
    ///
    /// # Errors
    /// [`IdentError::InvalidRecord`] for a mass that is not finite and positive, or a floor
    /// channel of another length or with a non-finite value.
    pub fn with_floors(mut self, floors: &[(f64, Vec<f64>)]) -> Result<Self> {
        let n = self.u_m.len();
        let mut shear = vec![0.0; n];
        for (k, (mass, acc)) in floors.iter().enumerate() {
            let invalid = |message: String| IdentError::InvalidRecord {
                test: self.name.clone(),
                message,
            };
            if !(mass.is_finite() && *mass > 0.0) {
                return Err(invalid(format!(
                    "storey {} mass {mass} kg: expected a finite mass > 0",
                    k + 1
                )));
            }
            if acc.len() != n {
                return Err(invalid(format!(
                    "storey {} acceleration has {} samples, `u_m` has {n}",
                    k + 1,
                    acc.len()
                )));
            }
            if let Some(i) = acc.iter().position(|x| !x.is_finite()) {
                return Err(invalid(format!(
                    "storey {} acceleration sample {i} is {}: expected a finite number",
                    k + 1,
                    acc[i]
                )));
            }
            for (s, a) in shear.iter_mut().zip(acc) {
                *s += mass * a;
            }
        }
        for (f, s) in self.force_n.iter_mut().zip(&shear) {
            *f -= s;
        }
        self.floors = Some(Floors {
            masses_kg: floors.iter().map(|(m, _)| *m).collect(),
            peak_base_shear_n: shear.iter().fold(0.0, |m, s| f64::max(m, s.abs())),
        });
        Ok(self)
    }

    /// Declares a known delay of channel `column` (one of [`DELAYABLE_CHANNELS`]) against the
    /// displacement `u_m`, s: positive when the data system sampled it late (its sample at
    /// `t` holds the value at `t − delay_s`). The any-record method advances the channel by
    /// it before fitting instead of estimating the delay (a delay of 0 declares the channel
    /// on time and turns the estimate off); see [`crate::anyrecord::ChannelDelay`]. The
    /// periodic method does not use it.
    ///
    /// # Errors
    /// [`IdentError::InvalidRecord`] for another column, or a delay that is not finite or
    /// reaches a quarter of the record.
    pub fn with_channel_delay_s(mut self, column: &str, delay_s: f64) -> Result<Self> {
        let invalid = |message: String| IdentError::InvalidRecord {
            test: self.name.clone(),
            message,
        };
        let Some(&col) = DELAYABLE_CHANNELS.iter().find(|&&c| c == column) else {
            return Err(invalid(format!(
                "a delay for `{column}`: expected one of {} (delays are against `u_m`)",
                DELAYABLE_CHANNELS.join(", ")
            )));
        };
        let quarter_s = self.u_m.len() as f64 / (4.0 * self.sample_rate_hz);
        if !(delay_s.is_finite() && delay_s.abs() < quarter_s) {
            return Err(invalid(format!(
                "`{column}` delay {delay_s} s: expected a finite delay shorter than a quarter \
                 of the record ({quarter_s} s)"
            )));
        }
        self.channel_delays_s.insert(col, delay_s);
        Ok(self)
    }

    /// The delay given for `column` ([`TestRecord::with_channel_delay_s`]), s.
    pub fn channel_delay_s(&self, column: &str) -> Option<f64> {
        self.channel_delays_s.get(column).copied()
    }

    /// The record with channel `column` (one of [`DELAYABLE_CHANNELS`]) advanced by
    /// `shift_samples` ([`platen_signal::advance`]); a missing velocity channel stays missing.
    pub(crate) fn with_channel_advanced(
        &self,
        column: &str,
        shift_samples: f64,
    ) -> std::result::Result<Self, platen_signal::SignalError> {
        let mut rec = self.clone();
        match column {
            "a_m_s2" => rec.a_m_s2 = platen_signal::advance(&self.a_m_s2, shift_samples)?,
            "force_n" => rec.force_n = platen_signal::advance(&self.force_n, shift_samples)?,
            _ => {
                if let Some(v) = &self.v_m_s {
                    rec.v_m_s = Some(platen_signal::advance(v, shift_samples)?);
                }
            }
        }
        Ok(rec)
    }

    /// The floors whose base shear was removed, if any.
    pub fn floors(&self) -> Option<&Floors> {
        self.floors.as_ref()
    }

    /// Declares the waveform (otherwise recognised from the data).
    pub fn with_kind(mut self, kind: TestKind) -> Self {
        self.kind = Some(kind);
        self
    }

    /// The test's name (used in messages and tables).
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }
    /// Time of the first sample, s.
    pub fn start_s(&self) -> f64 {
        self.start_s
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.u_m.len()
    }
    /// Always false: a record has at least [`MIN_SAMPLES`] samples.
    pub fn is_empty(&self) -> bool {
        self.u_m.is_empty()
    }
    /// Displacement, m.
    pub fn u_m(&self) -> &[f64] {
        &self.u_m
    }
    /// Velocity, m/s, if given.
    pub fn v_m_s(&self) -> Option<&[f64]> {
        self.v_m_s.as_deref()
    }
    /// Acceleration, m/s².
    pub fn a_m_s2(&self) -> &[f64] {
        &self.a_m_s2
    }
    /// Total actuator force, N (less the specimen's base shear after
    /// [`TestRecord::with_floors`]).
    pub fn force_n(&self) -> &[f64] {
        &self.force_n
    }
    /// Hold-down pressure, Pa, if given.
    pub fn pressure_pa(&self) -> Option<f64> {
        self.pressure_pa
    }
    /// Declared waveform, if given.
    pub fn kind(&self) -> Option<TestKind> {
        self.kind
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Σ mᵢ·aᵢ leaves the force: 2 storeys of 10 t and 5 t at 1 and 2 m/s² take 20 kN.
    #[test]
    fn floors_take_their_base_shear_off_the_force() {
        let n = 100;
        let rec = TestRecord::from_rate("r", 100.0, vec![0.0; n], vec![0.0; n], vec![50e3; n])
            .unwrap()
            .with_floors(&[(10e3, vec![1.0; n]), (5e3, vec![2.0; n])])
            .unwrap();
        assert!(rec.force_n().iter().all(|&f| f == 30e3));
        assert_eq!(rec.floors().unwrap().peak_base_shear_n, 20e3);
    }

    #[test]
    fn a_bad_floor_is_rejected_naming_the_storey() {
        let n = 100;
        let rec =
            TestRecord::from_rate("r", 100.0, vec![0.0; n], vec![0.0; n], vec![0.0; n]).unwrap();
        let e = rec
            .clone()
            .with_floors(&[(-1.0, vec![0.0; n])])
            .unwrap_err();
        assert!(e.to_string().contains("storey 1 mass"), "{e}");
        let e = rec.with_floors(&[(1.0, vec![0.0; 3])]).unwrap_err();
        assert!(e.to_string().contains("storey 1 acceleration has 3"), "{e}");
    }

    #[test]
    fn a_channel_delay_is_checked_and_kept() {
        let n = 400;
        let rec =
            TestRecord::from_rate("r", 200.0, vec![0.0; n], vec![0.0; n], vec![0.0; n]).unwrap();
        let e = rec.clone().with_channel_delay_s("u_m", 0.01).unwrap_err();
        assert!(e.to_string().contains("a delay for `u_m`"), "{e}");
        let e = rec.clone().with_channel_delay_s("a_m_s2", 0.5).unwrap_err();
        assert!(
            e.to_string().contains("quarter of the record (0.5 s)"),
            "{e}"
        );
        assert!(rec
            .clone()
            .with_channel_delay_s("force_n", f64::NAN)
            .is_err());
        let rec = rec.with_channel_delay_s("a_m_s2", 0.0098).unwrap();
        assert_eq!(rec.channel_delay_s("a_m_s2"), Some(0.0098));
        assert_eq!(rec.channel_delay_s("force_n"), None);
    }
}
