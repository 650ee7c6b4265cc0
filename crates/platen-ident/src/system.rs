//! The controller of a table's loop identified from its own records (`platen identify
//! --system`).
//!
//! A record holds what the controller read and what it sent, sampled at the controller's
//! rate: the command `command_u_m`, the feedback displacement `u_m` and, where recorded, the
//! drive `drive` (a fraction of full opening, `|d| ≤ 1`), the pressure difference
//! `delta_p_pa` and the acceleration `a_m_s2`. With the drive recorded, the gains of
//!
//! `d = K_p·(u_ref − u) + K_vf·v_ref + K_af·a_ref − K_vb·v − K_ab·a − K_Δp·HP(Δp)`
//!
//! are found by linear least squares over every unsaturated sample (`|d| < 0.999`). The
//! signals are derived from the records as platen's controller derives them:
//!
//! * `v_ref`, `a_ref`: central differences of the command (one-sided at the ends);
//! * `v`: the backward difference of the recorded displacement (what a digital controller can
//!   compute at the sample; 0 at the first);
//! * `a`: the recorded acceleration;
//! * `HP(Δp)`: the first-order Tustin high-pass of the recorded `Δp` (output 0 at the first
//!   sample), its corner given or chosen from [`HIGHPASS_GRID_HZ`] by the least residual.
//!
//! The first and last two samples of each record are left out. The fit uses the records
//! marked for fitting; the others are held out and the drive the fitted gains predict is
//! compared with theirs ([`HeldOut`]). Which records those are is the caller's choice: this
//! crate reads no files and chooses none (`platen identify --system` holds out the last of
//! two or more records, as the application layer's `platen_app::system::fitted` says). A
//! quantity the records cannot show is listed in [`SystemIdentification::not_identified`]
//! with the reason.
//!
//! The gains are constrained to the range a scenario accepts (every gain `≥ 0`): a gain the
//! unconstrained fit would make negative is held at 0 and said so
//! ([`SystemIdentification::not_identified`]); the others are refitted without it
//! ([`fit`](self) has the exact non-negative least squares and the standard errors).
//!
//! Before any fit the channels' skew is measured and corrected ([`skew`]): the table's
//! acceleration against the second derivative of the displacement (the storeys' accelerometers
//! are taken to share the table's data path), the pressures by the platen's force balance.
//!
//! A loop that cannot be identified is an error with the reason
//! ([`IdentError::LoopNotIdentifiable`]): a fitted record without the drive, or a command
//! that does not move the table.

use crate::error::{IdentError, Result};

mod fit;
mod judge;
mod pem;
mod plant;
mod provenance;
pub mod skew;
pub mod transmissibility;

pub use judge::{
    fir_black_box, Baseline, BlackBox, HeldOutMedians, Judgement, Prediction, PredictionSeries,
    BLACK_BOX_LENGTH_S, JUDGE_LOWPASS_HZ, MAX_BLACK_BOX_TAPS,
};
pub use pem::{
    refine_loop, ChannelFit, LoopValues, PemParameter, PredictionErrorFit, RefinedLoop,
    CHI2_TOLERANCE, FD_STEP, MAX_CORRELATION, MAX_ITERATIONS, MIN_COLUMN_NORM,
};
pub use plant::stroke_limit_m;
pub use plant::{
    Geometry, IdentifiedHydraulics, IdentifiedMechanics, IdentifiedPlant, IdentifiedStorey, Mode,
    CONTINUITY_LOWPASS_HZ, DRIFT_HIGHPASS_HZ, MECHANICS_LOWPASS_FRACTION, NOMINAL_AREA_M2,
    NOMINAL_BULK_MODULUS_PA, NOMINAL_RATED_DROP_PA, NOMINAL_RETURN_PRESSURE_PA,
    NOMINAL_SUPPLY_PRESSURE_PA, SLIP_SPEED_M_S, STROKE_FRACTION_OF_ROOM,
};
pub use plant::{DECAY_GRID_S_PER_M, EXPONENT_GRID, FRICTION_TERM_T, LOW_SLIP_SPEED_M_S};
pub use provenance::{Source, ValueProvenance};
pub use skew::{ChannelSkew, RecordSkew, PER_RECORD_MAX_SE_SAMPLES};
pub use transmissibility::{ModeCheck, Transmissibility, TransmissibilityPeak};

/// Corners tried for the `Δp` high-pass when none is given, Hz (0: `Δp` unfiltered).
pub const HIGHPASS_GRID_HZ: [f64; 12] = [
    0.0, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 2.0, 5.0, 10.0,
];

/// Drive samples at or beyond this magnitude are saturated and left out of the fit.
pub const SATURATED_DRIVE: f64 = 0.999;

/// One record of the loop, sampled uniformly at the controller's rate.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemRecord {
    /// Its name (the file it came from).
    pub name: String,
    /// Sample times, s (uniform).
    pub t_s: Vec<f64>,
    /// The displacement command `u_ref`, m.
    pub command_u_m: Vec<f64>,
    /// The feedback displacement `u`, m.
    pub u_m: Vec<f64>,
    /// The drive sent to the valves (fraction of full opening), if recorded.
    pub drive: Option<Vec<f64>>,
    /// The pressure difference `p_a − p_b`, Pa, if recorded.
    pub delta_p_pa: Option<Vec<f64>>,
    /// The platen's acceleration, m/s², if recorded.
    pub a_m_s2: Option<Vec<f64>>,
    /// The cap-side chamber pressure (absolute), Pa, if recorded.
    pub cap_pressure_pa: Option<Vec<f64>>,
    /// The rod-side chamber pressure (absolute), Pa, if recorded.
    pub rod_pressure_pa: Option<Vec<f64>>,
    /// The storeys' absolute accelerations, m/s², bottom first (empty: none recorded).
    pub storey_a_m_s2: Vec<Vec<f64>>,
}

impl SystemRecord {
    /// The sample period, s, checked with the channels' lengths and finiteness.
    ///
    /// # Errors
    /// [`IdentError::InvalidRecord`] for fewer than 16 samples, channels of different
    /// lengths, a non-finite value, or times that are not uniform and increasing.
    pub fn period_s(&self) -> Result<f64> {
        let bad = |message: String| IdentError::InvalidRecord {
            test: self.name.clone(),
            message,
        };
        let n = self.t_s.len();
        if n < 16 {
            return Err(bad(format!("{n} samples: at least 16 are needed")));
        }
        let mut channels: Vec<(&str, &[f64])> = vec![
            ("t_s", &self.t_s),
            ("command_u_m", &self.command_u_m),
            ("u_m", &self.u_m),
        ];
        for (name, c) in [
            ("drive", &self.drive),
            ("delta_p_pa", &self.delta_p_pa),
            ("a_m_s2", &self.a_m_s2),
            ("cap_pressure_pa", &self.cap_pressure_pa),
            ("rod_pressure_pa", &self.rod_pressure_pa),
        ] {
            if let Some(c) = c {
                channels.push((name, c));
            }
        }
        let storeys: Vec<String> = (1..=self.storey_a_m_s2.len())
            .map(|i| format!("storey{i}_a_m_s2"))
            .collect();
        for (name, c) in storeys.iter().zip(&self.storey_a_m_s2) {
            channels.push((name, c));
        }
        for (name, c) in channels {
            if c.len() != n {
                return Err(bad(format!("{name} has {} samples, t_s {n}", c.len())));
            }
            if let Some(i) = c.iter().position(|x| !x.is_finite()) {
                return Err(bad(format!("{name} is not finite at row {}", i + 1)));
            }
        }
        let h = (self.t_s[n - 1] - self.t_s[0]) / (n - 1) as f64;
        if h.is_nan() || h <= 0.0 {
            return Err(bad("t_s does not increase".into()));
        }
        if let Some(i) = self
            .t_s
            .windows(2)
            .position(|w| ((w[1] - w[0]) / h - 1.0).abs() > 1e-3)
        {
            return Err(bad(format!(
                "t_s is not uniform at row {}: the controller's records are sampled at one rate",
                i + 2
            )));
        }
        Ok(h)
    }
}

/// The controller's gains found from the records, in the units of the scenario's
/// `table_system.controller` keys.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IdentifiedGains {
    /// Sample rate of the records (the controller's, assumed), Hz.
    pub sample_rate_hz: f64,
    /// `K_p`, per m.
    pub displacement_gain_per_m: f64,
    /// `K_vf`, s/m.
    pub velocity_feedforward_s_per_m: f64,
    /// `K_af`, s²/m.
    pub acceleration_feedforward_s2_per_m: f64,
    /// `K_vb`, s/m.
    pub velocity_feedback_s_per_m: f64,
    /// `K_ab`, s²/m (0 and listed as not identified without an acceleration record).
    pub acceleration_feedback_s2_per_m: f64,
    /// `K_Δp`, per Pa (0 and listed as not identified without a `Δp` record).
    pub delta_p_gain_per_pa: f64,
    /// The high-pass corner on `Δp`, Hz (given, or the grid's best).
    pub delta_p_highpass_hz: f64,
}

/// One gain's estimate.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GainEstimate {
    /// Its scenario key (`displacement_gain_per_m`, …).
    pub key: &'static str,
    /// The value (0 when held there).
    pub value: f64,
    /// Its standard error (batch means over the fit's residuals); absent when held at 0 or
    /// not fitted.
    pub std_error: Option<f64>,
    /// Whether the sign constraint held it at 0 (the unconstrained fit made it negative).
    pub held_at_zero: bool,
    /// What the unconstrained fit gave, when it was held at 0.
    pub unconstrained: Option<f64>,
}

/// How well the gains reproduce one record's drive.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HeldOut {
    /// The record's name.
    pub name: String,
    /// Whether it was used in the fit.
    pub fitted: bool,
    /// Samples compared (unsaturated, ends left out).
    pub samples: usize,
    /// RMS of the recorded drive less the predicted one.
    pub drive_rms_error: f64,
    /// That RMS relative to the recorded drive's RMS.
    pub drive_nrmse: f64,
}

/// What `identify --system` found.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SystemIdentification {
    /// The gains, if the drive was recorded.
    pub gains: Option<IdentifiedGains>,
    /// The records used in the fit.
    pub fitted_records: Vec<String>,
    /// The fit on every record, fitted and held out.
    pub records: Vec<HeldOut>,
    /// Samples left out as saturated (`|d| ≥ 0.999`) in the fit.
    pub saturated_samples: usize,
    /// Each gain with its standard error and whether it was held at 0.
    pub gain_estimates: Vec<GainEstimate>,
    /// The channels' skew measured on the records and corrected before the fits.
    pub channel_skew: Vec<ChannelSkew>,
    /// The plant (platen, specimen, valves, oil column), in the base's geometry
    /// ([`SystemSettings::base`]) or, without one, in ratios to a nominal actuator area.
    pub plant: Option<IdentifiedPlant>,
    /// The loop's values refined by its prediction error on the fitted records
    /// ([`SystemSettings::prediction_error`]; the plant, the gains and the judgement then
    /// hold the refined values).
    pub prediction_error: Option<PredictionErrorFit>,
    /// The identified loop run on each record's command, against a linear black box and
    /// perfect tracking ([`SystemSettings::judge`]).
    pub judgement: Option<Judgement>,
    /// Where each value of the identified table's scenario comes from: `identified` (with
    /// its standard error where it has one), `given` (the base) or `assumed` (with why).
    pub provenance: Vec<ValueProvenance>,
    /// Quantities the records cannot show, with the reason.
    pub not_identified: Vec<(String, String)>,
}

/// Settings of [`identify_system`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SystemSettings {
    /// The `Δp` high-pass corner, Hz, if known (otherwise chosen from [`HIGHPASS_GRID_HZ`]).
    pub delta_p_highpass_hz: Option<f64>,
    /// The table's geometry from its drawings (actuator count and areas, valve count and
    /// rated drop, supply and return pressures, bulk modulus): with it the plant comes out in
    /// absolute units. Without it the plant is identified in ratios to the actuator area
    /// (the motion is invariant to scaling every area, mass, force, flow and volume
    /// together: see [`plant`](IdentifiedPlant)), laid on [`SystemSettings::area_m2`] or
    /// [`NOMINAL_AREA_M2`] and the other nominal values, each listed as `assumed`.
    pub base: Option<platen_system::TableSystem>,
    /// The actuator's area, m², when known without the rest of the drawings (used without a
    /// base: the plant's absolute scale).
    pub area_m2: Option<f64>,
    /// Whether to run the identified loop on every record's command and judge it
    /// ([`SystemIdentification::judgement`]).
    pub judge: bool,
    /// Whether to refine the loop's equation-error values by its prediction error on the
    /// fitted records (the closed loop run on their commands made to reproduce the table's
    /// and storeys' accelerations: [`PredictionErrorFit`]) before judging it. Default
    /// `false` here; `platen identify --system` sets it unless `--no-prediction-error`.
    pub prediction_error: bool,
}

/// Central differences (one-sided second order at the ends): velocity and acceleration.
fn central(u: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
    let n = u.len();
    let mut v = vec![0.0; n];
    let mut a = vec![0.0; n];
    for i in 1..n - 1 {
        v[i] = (u[i + 1] - u[i - 1]) / (2.0 * h);
        a[i] = (u[i + 1] - 2.0 * u[i] + u[i - 1]) / (h * h);
    }
    v[0] = (-3.0 * u[0] + 4.0 * u[1] - u[2]) / (2.0 * h);
    v[n - 1] = (3.0 * u[n - 1] - 4.0 * u[n - 2] + u[n - 3]) / (2.0 * h);
    a[0] = a[1];
    a[n - 1] = a[n - 2];
    (v, a)
}

/// The first-order Tustin high-pass of `x` at `corner_hz` (0: `x` itself), output 0 first.
fn highpass(x: &[f64], h: f64, corner_hz: f64) -> Vec<f64> {
    if corner_hz <= 0.0 {
        return x.to_vec();
    }
    let w = std::f64::consts::TAU * corner_hz;
    let c = 2.0 / h;
    let mut y = vec![0.0; x.len()];
    for i in 1..x.len() {
        y[i] = (c * (x[i] - x[i - 1]) + (c - w) * y[i - 1]) / (c + w);
    }
    y
}

/// Which regressors the records allow.
#[derive(Debug, Clone, Copy)]
struct Columns {
    acceleration: bool,
    delta_p: bool,
}

/// The gains' keys in the order of the regressor columns.
const GAIN_KEYS: [&str; 6] = [
    "displacement_gain_per_m",
    "velocity_feedforward_s_per_m",
    "acceleration_feedforward_s2_per_m",
    "velocity_feedback_s_per_m",
    "acceleration_feedback_s2_per_m",
    "delta_p_gain_per_pa",
];

/// The regressor row `[e, v_ref, a_ref, −v, −a, −HP Δp]` (absent channels 0) of every
/// unsaturated sample of a record (ends left out), pushed into `design`; the count of
/// saturated samples.
fn push_rows(
    design: &mut fit::Design,
    index: usize,
    r: &SystemRecord,
    h: f64,
    cols: Columns,
    corner_hz: f64,
) -> usize {
    let n = r.t_s.len();
    let Some(drive) = r.drive.as_ref() else {
        return 0;
    };
    let (vref, aref) = central(&r.command_u_m, h);
    let hp = r
        .delta_p_pa
        .as_ref()
        .filter(|_| cols.delta_p)
        .map(|dp| highpass(dp, h, corner_hz));
    let mut saturated = 0;
    for i in 2..n - 2 {
        if drive[i].abs() >= SATURATED_DRIVE {
            saturated += 1;
            continue;
        }
        let v = (r.u_m[i] - r.u_m[i - 1]) / h;
        let a = match (&r.a_m_s2, cols.acceleration) {
            (Some(a), true) => a[i],
            _ => 0.0,
        };
        let row = [
            r.command_u_m[i] - r.u_m[i],
            vref[i],
            aref[i],
            -v,
            -a,
            hp.as_ref().map_or(0.0, |hp| -hp[i]),
        ];
        design.push(&row, drive[i], index, i);
    }
    saturated
}

/// The command's motion in a record, against the displacement sensor's noise: a loop whose
/// command does not move the table shows nothing of it. The RMS of the command's deviation
/// from its mean must exceed this many times the RMS of the displacement's second
/// difference over √6 (the sensor's noise, an upper bound).
pub const MIN_COMMAND_TO_NOISE: f64 = 10.0;

/// Why `records` (the fitted ones) cannot show the loop, if they cannot.
fn not_identifiable(records: &[SystemRecord], fitted: &[usize]) -> Option<IdentError> {
    for &i in fitted {
        let r = &records[i];
        let fail = |reason: String| {
            Some(IdentError::LoopNotIdentifiable {
                record: r.name.clone(),
                reason,
            })
        };
        if r.drive.is_none() {
            return fail(
                "no drive recorded: the controller's gains act on the table only through the \
                 drive, which the valves, the oil column and the platen filter; without it \
                 neither the gains nor the valves can be separated (map the drive channel, \
                 e.g. {\"drive\": {\"name\": \"Voltage command\", \"unit\": \"V\", \"scale\": \
                 0.1}} for a ±10 V drive)"
                    .into(),
            );
        }
        let n = r.command_u_m.len() as f64;
        let mean = r.command_u_m.iter().sum::<f64>() / n;
        let motion = (r
            .command_u_m
            .iter()
            .map(|c| (c - mean).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        let noise = (r
            .u_m
            .windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).powi(2))
            .sum::<f64>()
            / (n - 2.0).max(1.0))
        .sqrt()
            / 6f64.sqrt();
        if motion <= MIN_COMMAND_TO_NOISE * noise {
            return fail(format!(
                "the command does not move the table (RMS {motion:.3e} m about its mean, \
                 against the displacement's noise {noise:.3e} m): a record at rest shows \
                 nothing of the loop; give records with a moving command (white noise, \
                 sweeps, earthquakes)"
            ));
        }
    }
    None
}

/// Identifies the controller and the plant from `records`; those with `fit[i]` true are
/// fitted, the others held out and judged.
///
/// # Errors
/// [`IdentError::NoTests`] without records, [`IdentError::InvalidRecord`] for a record whose
/// channels do not fit together, or when no record is marked for the fit, or the fit is
/// singular (a command too poor to separate the gains);
/// [`IdentError::LoopNotIdentifiable`] for a fitted record without the drive or whose
/// command does not move the table.
pub fn identify_system(
    records: &[SystemRecord],
    fit: &[bool],
    settings: &SystemSettings,
) -> Result<SystemIdentification> {
    let (periods, fitted) = check_system_inputs(records, fit, settings)?;
    // Skew: the acceleration channels first (against the displacement), then the pressures
    // (by the force balance, inside the plant's fit).
    let mut channel_skew = Vec::new();
    let mut corrected = skew::correct_accelerations(records, &periods, &fitted, &mut channel_skew)?;
    let mut not_identified = Vec::new();
    let cols = recorded_columns(records, &fitted, &mut not_identified);
    let plant_input = plant::PlantInput::new(settings, &corrected[0]);
    let mut plant = plant::identify_plant(
        &mut corrected,
        &periods,
        &fitted,
        &plant_input,
        &mut channel_skew,
        &mut not_identified,
    )?;
    let records_c = corrected.as_slice();
    let h = periods[fitted[0]];
    let (corner, gfit, sat, unconstrained) =
        fit_gains(records_c, &periods, &fitted, cols, settings)?;
    let c = &gfit.coef;
    let gains = IdentifiedGains {
        sample_rate_hz: nominal_rate_hz(h),
        displacement_gain_per_m: c[0],
        velocity_feedforward_s_per_m: c[1],
        acceleration_feedforward_s2_per_m: c[2],
        velocity_feedback_s_per_m: c[3],
        acceleration_feedback_s2_per_m: c[4],
        delta_p_gain_per_pa: c[5],
        delta_p_highpass_hz: corner,
    };
    let gain_estimates = estimates_of(&gfit, unconstrained.as_ref(), cols, &mut not_identified);
    let mut result = SystemIdentification {
        gains: Some(gains),
        fitted_records: fitted.iter().map(|&i| records[i].name.clone()).collect(),
        records: held_out(records_c, &periods, &fitted, cols, corner, c),
        saturated_samples: sat,
        gain_estimates,
        channel_skew,
        plant: None,
        prediction_error: None,
        judgement: None,
        provenance: Vec::new(),
        not_identified,
    };
    plant.system = with_gains(plant.system, &gains, &mut result.not_identified);
    if settings.prediction_error {
        result.prediction_error =
            pem::refine(records_c, &fitted, &mut plant, &mut result.not_identified);
    }
    let modes: Vec<(f64, f64)> = plant
        .specimen_modes
        .iter()
        .map(|m| (m.frequency_hz, m.damping_ratio))
        .collect();
    plant.transmissibility =
        transmissibility::transmissibility(records_c, &periods, &fitted, &modes);
    if settings.judge {
        result.judgement = judge::judge(records_c, &periods, &fitted, &plant);
    }
    result.provenance = provenance::of(&result, &plant, &plant_input);
    result.plant = Some(plant);
    Ok(result)
}

/// The controller's columns every fitted record has (the acceleration, `Δp`); the gains a
/// missing one leaves at 0 into `not_identified`.
fn recorded_columns(
    records: &[SystemRecord],
    fitted: &[usize],
    not_identified: &mut Vec<(String, String)>,
) -> Columns {
    let all = |f: fn(&SystemRecord) -> bool| fitted.iter().all(|&i| f(&records[i]));
    let cols = Columns {
        acceleration: all(|r| r.a_m_s2.is_some()),
        delta_p: all(|r| r.delta_p_pa.is_some()),
    };
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    if !cols.acceleration {
        not_identified.push(why(
            "acceleration_feedback_s2_per_m",
            "no a_m_s2 recorded: taken as 0",
        ));
    }
    if !cols.delta_p {
        not_identified.push(why(
            "delta_p_gain_per_pa, delta_p_highpass_hz",
            "no delta_p_pa recorded: taken as 0",
        ));
    }
    cols
}

/// The identified `system` with the identified `gains`: still a table system only if they
/// are gains a controller takes (checked again at the same stroke). If they are not, said in
/// `not_identified`: the result then carries no table system (and no scenario).
fn with_gains(
    system: Option<platen_system::TableSystem>,
    gains: &IdentifiedGains,
    not_identified: &mut Vec<(String, String)>,
) -> Option<platen_system::TableSystem> {
    let sys = system?;
    let stroke_m = stroke_limit_m(&sys);
    let mut parts = sys.into_parts();
    set_controller(&mut parts.controller, gains);
    match platen_system::TableSystem::new(parts, stroke_m) {
        Ok(system) => Some(system),
        Err(e) => {
            not_identified.push((
                "table_system".to_owned(),
                format!(
                    "the identified gains are not gains a controller takes ({e}): no \
                     identified table system or scenario is given"
                ),
            ));
            None
        }
    }
}

/// The checks of [`identify_system`] before any fit: the records' periods and which are
/// fitted.
fn check_system_inputs(
    records: &[SystemRecord],
    fit: &[bool],
    settings: &SystemSettings,
) -> Result<(Vec<f64>, Vec<usize>)> {
    if records.is_empty() {
        return Err(IdentError::NoTests);
    }
    let periods = records
        .iter()
        .map(SystemRecord::period_s)
        .collect::<Result<Vec<f64>>>()?;
    let fitted: Vec<usize> = (0..records.len())
        .filter(|&i| fit.get(i).copied().unwrap_or(false))
        .collect();
    if fitted.is_empty() {
        return Err(IdentError::InvalidRecord {
            test: records[0].name.clone(),
            message: "no record is marked for the fit".into(),
        });
    }
    if let Some(e) = not_identifiable(records, &fitted) {
        return Err(e);
    }
    if let Some(a) = settings.area_m2 {
        if !(a.is_finite() && a > 0.0) {
            return Err(IdentError::InvalidSetting {
                name: "area_m2",
                value: a,
                expected: "a finite actuator area > 0, m²",
            });
        }
    }
    Ok((periods, fitted))
}

/// The controller's gains fitted on the `fitted` records, at the given high-pass corner or
/// the grid's best: the corner, the fit (gains ≥ 0, absent channels at 0), the saturated
/// samples left out, and what the unconstrained fit gives (reported, not used).
fn fit_gains(
    records_c: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    cols: Columns,
    settings: &SystemSettings,
) -> Result<(f64, fit::LinearFit, usize, Option<fit::LinearFit>)> {
    let absent = absent_gains(cols);
    let corners: Vec<f64> = match (cols.delta_p, settings.delta_p_highpass_hz) {
        (false, _) => vec![0.0],
        (true, Some(c)) => vec![c],
        (true, None) => HIGHPASS_GRID_HZ.to_vec(),
    };
    // Every gain ≥ 0 (a scenario refuses a negative one); the columns the records lack are
    // held at 0.
    let nonneg = [true; 6];
    let mut best: Option<(f64, fit::LinearFit, usize)> = None;
    for &corner in &corners {
        let mut design = fit::Design::new(6);
        let mut sat = 0;
        for &i in fitted {
            sat += push_rows(&mut design, i, &records_c[i], periods[i], cols, corner);
        }
        let Some(f) = design.fit(&nonneg, &absent) else {
            continue;
        };
        if best.as_ref().is_none_or(|b| f.rss < b.1.rss) {
            best = Some((corner, f, sat));
        }
    }
    let Some((corner, gfit, sat)) = best else {
        return Err(IdentError::InvalidRecord {
            test: fitted
                .iter()
                .map(|&i| records_c[i].name.clone())
                .collect::<Vec<_>>()
                .join(", "),
            message: "the drive cannot be fitted: too few unsaturated samples or a command \
                      too poor to separate the gains"
                .into(),
        });
    };
    // What the unconstrained fit gives for a gain held at 0 (reported, not used).
    let unconstrained = {
        let mut design = fit::Design::new(6);
        for &i in fitted {
            push_rows(&mut design, i, &records_c[i], periods[i], cols, corner);
        }
        design.fit(&[false; 6], &absent)
    };
    Ok((corner, gfit, sat, unconstrained))
}

/// The gains a fit holds at 0 because the records lack their channel.
fn absent_gains(cols: Columns) -> [bool; 6] {
    [
        false,
        false,
        false,
        false,
        !cols.acceleration,
        !cols.delta_p,
    ]
}

/// The estimates of the gains the records show, each gain held at 0 listed in
/// `not_identified` with what the unconstrained fit gives.
fn estimates_of(
    gfit: &fit::LinearFit,
    unconstrained: Option<&fit::LinearFit>,
    cols: Columns,
    not_identified: &mut Vec<(String, String)>,
) -> Vec<GainEstimate> {
    let (c, absent) = (&gfit.coef, absent_gains(cols));
    let gain_estimates: Vec<GainEstimate> = (0..6)
        .filter(|&j| !absent[j])
        .map(|j| GainEstimate {
            key: GAIN_KEYS[j],
            value: c[j],
            std_error: Some(gfit.estimates[j].std_error).filter(|s| s.is_finite()),
            held_at_zero: gfit.clamped[j],
            unconstrained: gfit.clamped[j]
                .then(|| unconstrained.map(|u| u.coef[j]))
                .flatten(),
        })
        .collect();
    for g in gain_estimates.iter().filter(|g| g.held_at_zero) {
        not_identified.push((
            g.key.to_owned(),
            format!(
                "held at 0: the unconstrained fit gives {} (a scenario takes only gains ≥ 0; a \
                 negative value is the fit absorbing noise, skew or what the law does not \
                 hold, not the controller)",
                g.unconstrained
                    .map_or("no value".to_owned(), |u| format!("{u:.4e}"))
            ),
        ));
    }
    gain_estimates
}

/// How well the gains predict each record's drive (the fitted ones and those held out).
fn held_out(
    records_c: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    cols: Columns,
    corner: f64,
    c: &[f64],
) -> Vec<HeldOut> {
    let mut out = Vec::new();
    for (i, r) in records_c.iter().enumerate() {
        let usable = Columns {
            acceleration: cols.acceleration && r.a_m_s2.is_some(),
            delta_p: cols.delta_p && r.delta_p_pa.is_some(),
        };
        let mut design = fit::Design::new(6);
        push_rows(&mut design, i, r, periods[i], usable, corner);
        let n = design.len().max(1) as f64;
        let (err2, dd) = design.residual_and_rhs(c);
        let rms_d = (dd / n).sqrt();
        let rms_e = (err2 / n).sqrt();
        out.push(HeldOut {
            name: r.name.clone(),
            fitted: fitted.contains(&i),
            samples: design.len(),
            drive_rms_error: rms_e,
            drive_nrmse: if rms_d > 0.0 { rms_e / rms_d } else { f64::NAN },
        });
    }
    out
}

/// The identified `gains` into a table system's controller (no integrator).
fn set_controller(ctl: &mut platen_system::Controller, gains: &IdentifiedGains) {
    ctl.sample_rate_hz = gains.sample_rate_hz;
    ctl.displacement_gain_per_m = gains.displacement_gain_per_m;
    ctl.integral_gain_per_m_s = 0.0;
    ctl.velocity_feedforward_s_per_m = gains.velocity_feedforward_s_per_m;
    ctl.acceleration_feedforward_s2_per_m = gains.acceleration_feedforward_s2_per_m;
    ctl.velocity_feedback_s_per_m = gains.velocity_feedback_s_per_m;
    ctl.acceleration_feedback_s2_per_m = gains.acceleration_feedback_s2_per_m;
    ctl.delta_p_gain_per_pa = gains.delta_p_gain_per_pa;
    ctl.delta_p_highpass_hz = gains.delta_p_highpass_hz;
}

/// The controller's rate from the records' mean period `h`: a whole number of hertz when the
/// stamps agree with one within their rounding (1e-6 relative: stamps written with 9
/// significant digits give 1023.9999996 Hz for 1024 Hz), else `1/h`.
fn nominal_rate_hz(h: f64) -> f64 {
    let rate = 1.0 / h;
    let whole = rate.round();
    if whole >= 1.0 && (rate - whole).abs() <= 1e-6 * whole {
        whole
    } else {
        rate
    }
}
