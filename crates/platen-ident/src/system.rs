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
//! compared with theirs ([`HeldOut`]). A quantity the records cannot show is listed in
//! [`SystemIdentification::not_identified`] with the reason.

use nalgebra::{DMatrix, DVector};

use crate::error::{IdentError, Result};

mod plant;

pub use plant::{
    predict, IdentifiedHydraulics, IdentifiedMechanics, IdentifiedPlant, IdentifiedStorey, Mode,
    Prediction, CONTINUITY_LOWPASS_HZ, DRIFT_HIGHPASS_HZ, JUDGE_STEPS_PER_PERIOD, SLIP_SPEED_M_S,
};

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
    /// The plant (platen, specimen, valves, oil column) and the identified loop's
    /// predictions, with a base geometry ([`SystemSettings::base`]).
    pub plant: Option<IdentifiedPlant>,
    /// Quantities the records cannot show, with the reason.
    pub not_identified: Vec<(String, String)>,
}

/// Settings of [`identify_system`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SystemSettings {
    /// The `Δp` high-pass corner, Hz, if known (otherwise chosen from [`HIGHPASS_GRID_HZ`]).
    pub delta_p_highpass_hz: Option<f64>,
    /// The table's geometry from its drawings (actuator count and areas, valve count and
    /// rated drop, supply and return pressures, bulk modulus): with it the plant is
    /// identified; the rest of its values are replaced by the fitted ones. Without it only
    /// the gains are (the motion is invariant to scaling every area, mass, force, flow and
    /// volume together: see [`plant`](IdentifiedPlant)).
    pub base: Option<platen_system::TableSystem>,
    /// Whether to run the identified loop on every record's command and judge it
    /// ([`IdentifiedPlant::predictions`]).
    pub judge: bool,
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

/// The regressor rows `[e, v_ref, a_ref, −v, (−a), (−HP Δp)]` and drives of a record's
/// unsaturated samples (ends left out); the count of saturated samples.
fn rows(
    r: &SystemRecord,
    h: f64,
    cols: Columns,
    corner_hz: f64,
) -> (Vec<Vec<f64>>, Vec<f64>, usize) {
    let n = r.t_s.len();
    let (vref, aref) = central(&r.command_u_m, h);
    let hp = r
        .delta_p_pa
        .as_ref()
        .filter(|_| cols.delta_p)
        .map(|dp| highpass(dp, h, corner_hz));
    let mut x = Vec::with_capacity(n);
    let mut y = Vec::with_capacity(n);
    let mut saturated = 0;
    let Some(drive) = r.drive.as_ref() else {
        return (x, y, 0);
    };
    for i in 2..n - 2 {
        if drive[i].abs() >= SATURATED_DRIVE {
            saturated += 1;
            continue;
        }
        let v = (r.u_m[i] - r.u_m[i - 1]) / h;
        let mut row = vec![r.command_u_m[i] - r.u_m[i], vref[i], aref[i], -v];
        if cols.acceleration {
            row.push(-r.a_m_s2.as_ref().map_or(0.0, |a| a[i]));
        }
        if let Some(hp) = &hp {
            row.push(-hp[i]);
        }
        x.push(row);
        y.push(drive[i]);
    }
    (x, y, saturated)
}

/// Least squares with each column scaled to unit RMS; the coefficients and the residual's
/// sum of squares.
fn solve(x: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, f64)> {
    let m = x.first()?.len();
    let n = x.len();
    if n <= m {
        return None;
    }
    let scale: Vec<f64> = (0..m)
        .map(|j| {
            let s = (x.iter().map(|r| r[j] * r[j]).sum::<f64>() / n as f64).sqrt();
            if s > 0.0 {
                s
            } else {
                1.0
            }
        })
        .collect();
    let a = DMatrix::from_fn(n, m, |i, j| x[i][j] / scale[j]);
    let b = DVector::from_column_slice(y);
    let svd = a.clone().svd(true, true);
    let c = svd.solve(&b, 1e-12).ok()?;
    let res = &b - &a * &c;
    Some((
        (0..m).map(|j| c[j] / scale[j]).collect(),
        res.norm_squared(),
    ))
}

/// Identifies the controller from `records`; those with `fit[i]` true are fitted, the others
/// held out and judged.
///
/// # Errors
/// [`IdentError::NoTests`] without records, [`IdentError::InvalidRecord`] for a record whose
/// channels do not fit together, or when no record is marked for the fit, or the fit is
/// singular (a command too poor to separate the gains).
pub fn identify_system(
    records: &[SystemRecord],
    fit: &[bool],
    settings: &SystemSettings,
) -> Result<SystemIdentification> {
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
    let all = |f: fn(&SystemRecord) -> bool| fitted.iter().all(|&i| f(&records[i]));
    let mut not_identified = Vec::new();
    let has_drive = all(|r| r.drive.is_some());
    let cols = Columns {
        acceleration: all(|r| r.a_m_s2.is_some()),
        delta_p: all(|r| r.delta_p_pa.is_some()),
    };
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    if !has_drive {
        not_identified.push(why(
            "controller gains",
            "no drive recorded in every fitted record: the gains act only through the drive, \
             which the valves, oil column and platen filter; without it they cannot be \
             separated from the plant",
        ));
    }
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
    let plant = match &settings.base {
        Some(base) => Some(plant::identify_plant(
            records,
            &periods,
            &fitted,
            base,
            &mut not_identified,
        )),
        None => {
            not_identified.push(why(
                "servo-valves, oil column, platen, specimen",
                "no base geometry (actuator count and areas, supply pressure): scaling every \
                 area, mass, force, flow and volume together leaves the motion unchanged, \
                 so the records alone show only ratios to the area",
            ));
            None
        }
    };
    let mut result = SystemIdentification {
        gains: None,
        fitted_records: fitted.iter().map(|&i| records[i].name.clone()).collect(),
        records: Vec::new(),
        saturated_samples: 0,
        plant,
        not_identified,
    };
    if !has_drive {
        return Ok(result);
    }
    let h = periods[fitted[0]];
    let corners: Vec<f64> = match (cols.delta_p, settings.delta_p_highpass_hz) {
        (false, _) => vec![0.0],
        (true, Some(c)) => vec![c],
        (true, None) => HIGHPASS_GRID_HZ.to_vec(),
    };
    let mut best: Option<(f64, Vec<f64>, f64, usize)> = None;
    for &corner in &corners {
        let mut x = Vec::new();
        let mut y = Vec::new();
        let mut sat = 0;
        for &i in &fitted {
            let (xi, yi, si) = rows(&records[i], periods[i], cols, corner);
            x.extend(xi);
            y.extend(yi);
            sat += si;
        }
        let Some((c, ss)) = solve(&x, &y) else {
            continue;
        };
        if best.as_ref().is_none_or(|b| ss < b.2) {
            best = Some((corner, c, ss, sat));
        }
    }
    let Some((corner, c, _, sat)) = best else {
        return Err(IdentError::InvalidRecord {
            test: result.fitted_records.join(", "),
            message: "the drive cannot be fitted: too few unsaturated samples or a command \
                      too poor to separate the gains"
                .into(),
        });
    };
    let mut k = c.iter().copied();
    let mut next = || k.next().unwrap_or(0.0);
    let gains = IdentifiedGains {
        sample_rate_hz: nominal_rate_hz(h),
        displacement_gain_per_m: next(),
        velocity_feedforward_s_per_m: next(),
        acceleration_feedforward_s2_per_m: next(),
        velocity_feedback_s_per_m: next(),
        acceleration_feedback_s2_per_m: if cols.acceleration { next() } else { 0.0 },
        delta_p_gain_per_pa: if cols.delta_p { next() } else { 0.0 },
        delta_p_highpass_hz: corner,
    };
    result.saturated_samples = sat;
    for (i, r) in records.iter().enumerate() {
        if r.drive.is_none() {
            continue;
        }
        let usable = Columns {
            acceleration: cols.acceleration && r.a_m_s2.is_some(),
            delta_p: cols.delta_p && r.delta_p_pa.is_some(),
        };
        let (x, y, _) = rows(r, periods[i], usable, corner);
        let mut coef = vec![
            gains.displacement_gain_per_m,
            gains.velocity_feedforward_s_per_m,
            gains.acceleration_feedforward_s2_per_m,
            gains.velocity_feedback_s_per_m,
        ];
        if usable.acceleration {
            coef.push(gains.acceleration_feedback_s2_per_m);
        }
        if usable.delta_p {
            coef.push(gains.delta_p_gain_per_pa);
        }
        let n = y.len().max(1) as f64;
        let err2: f64 = x
            .iter()
            .zip(&y)
            .map(|(row, d)| {
                let p: f64 = row.iter().zip(&coef).map(|(a, b)| a * b).sum();
                (d - p) * (d - p)
            })
            .sum();
        let rms_d = (y.iter().map(|d| d * d).sum::<f64>() / n).sqrt();
        let rms_e = (err2 / n).sqrt();
        result.records.push(HeldOut {
            name: r.name.clone(),
            fitted: fitted.contains(&i),
            samples: y.len(),
            drive_rms_error: rms_e,
            drive_nrmse: if rms_d > 0.0 { rms_e / rms_d } else { f64::NAN },
        });
    }
    result.gains = Some(gains);
    if let Some(plant) = result.plant.as_mut() {
        if let Some(sys) = plant.system.as_mut() {
            let c = &mut sys.controller;
            c.sample_rate_hz = gains.sample_rate_hz;
            c.displacement_gain_per_m = gains.displacement_gain_per_m;
            c.integral_gain_per_m_s = 0.0;
            c.velocity_feedforward_s_per_m = gains.velocity_feedforward_s_per_m;
            c.acceleration_feedforward_s2_per_m = gains.acceleration_feedforward_s2_per_m;
            c.velocity_feedback_s_per_m = gains.velocity_feedback_s_per_m;
            c.acceleration_feedback_s2_per_m = gains.acceleration_feedback_s2_per_m;
            c.delta_p_gain_per_pa = gains.delta_p_gain_per_pa;
            c.delta_p_highpass_hz = gains.delta_p_highpass_hz;
        }
        if settings.judge {
            if let (Some(sys), Some(model)) = (plant.system, plant.model) {
                for (i, r) in records.iter().enumerate() {
                    if let Some(p) = predict(
                        r,
                        fitted.contains(&i),
                        &sys,
                        &model,
                        plant.specimen.as_ref(),
                    ) {
                        plant.predictions.push(p);
                    }
                }
            }
        }
    }
    Ok(result)
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
