//! The plant of the loop (platen, specimen, valves, oil column) identified from records that
//! carry the chamber pressures and the accelerations, and the identified loop judged by
//! running it on a held-out record's command.
//!
//! # What the records can show, and what is taken from the drawings
//!
//! Scaling every area by `s` and the masses, forces, valve flows, chamber volumes and leakage
//! by `s` as well leaves the motion unchanged: without the actuator geometry only ratios to
//! the area are visible. The geometry a lab knows from its drawings (actuator count, cap and
//! rod areas, valve count, rated pressure drop, supply and return pressures, the oil's bulk
//! modulus) comes from a *base* table system ([`super::SystemSettings::base`]); everything
//! else is fitted:
//!
//! * **Platen and specimen masses, stiffness, viscous and Coulomb friction**: linear least
//!   squares of `F_A = M·a + C·v + K·u + F_μ·sgn(v) + Σ mᵢ·aᵢ` with
//!   `F_A = n(A_a·p_a − A_b·p_b)` from the recorded pressures, `v` the central difference of
//!   `u`, `a`, `aᵢ` the recorded accelerations, over the samples with `|v| ≥`
//!   [`SLIP_SPEED_M_S`] (where the friction is surely `±F_μ`, not a stick reaction).
//! * **Storeys' stiffness and damping**: storey `j`'s equation
//!   `Σ_{i≥j} mᵢ·aᵢ = −k_j·δ_j − c_j·δ̇_j` (`δ_j` the drift, the double integral of
//!   `a_j − a_{j−1}`, `a₀` the table's) with both sides passed through the same filter
//!   `s²/(s + ω₀)²` (Tustin, `ω₀ = 2π·`[`DRIFT_HIGHPASS_HZ`]): the drift side becomes
//!   `(a_j − a_{j−1})/(s + ω₀)²`, a stable filter of the record, so no drift is integrated
//!   open loop. The records start at rest, so the causal filters start exact.
//! * **Valves and oil column**: each chamber's continuity,
//!   `A_a·v + A_a·u·ṗ_a/β = K·x_v·√drop_a − C_L·Δp − (V_a0/β)·ṗ_a` (and the rod side's),
//!   linear in the land coefficient `K`, the leakage `C_L` and the compliances `V/β`, with
//!   every term passed through the same low-pass `ω_c²/(s² + 2ζω_c s + ω_c²)`
//!   (`ω_c = 2π·`[`CONTINUITY_LOWPASS_HZ`], Tustin) so that `ṗ` and `v` come out of the
//!   filter's own state instead of differentiated noise. `x_v` is the recorded drive through
//!   the spool (pure delay, then second order), its delay, natural frequency and damping
//!   chosen from a grid by the least residual. Only `V/β` is visible (the `u·ṗ/β` term is a
//!   fraction of a percent at these strokes): `β` is the base's and the volumes follow.
//!
//! The identified loop is judged by running it ([`platen_integrate::forward_closed_loop`]) on
//! each held-out record's command and comparing the achieved table acceleration and
//! displacement with the record's.

use nalgebra::{DMatrix, SymmetricEigen};
use platen_integrate::{
    forward_closed_loop, LoopMethod, LoopRun, Motion, Sample, SampleSink, State,
};
use platen_model::{IdentifiedParams, Specimen, Storey};
use platen_system::TableSystem;

use super::{solve, SystemRecord};

/// Samples slower than this are left out of the mechanics fit (the friction there may be a
/// stick reaction, not `±F_μ`), m/s.
pub const SLIP_SPEED_M_S: f64 = 0.01;
/// Corner of the `s²/(s + ω₀)²` filter on the storey equations, Hz.
pub const DRIFT_HIGHPASS_HZ: f64 = 0.3;
/// Corner of the low-pass on the continuity equations, Hz.
pub const CONTINUITY_LOWPASS_HZ: f64 = 100.0;
/// Integration steps per controller period in the judging runs.
pub const JUDGE_STEPS_PER_PERIOD: u32 = 16;
/// Spool natural frequencies tried, Hz.
pub const SPOOL_FREQUENCY_GRID_HZ: [f64; 6] = [60.0, 100.0, 150.0, 200.0, 300.0, 500.0];
/// Spool damping ratios tried.
pub const SPOOL_DAMPING_GRID: [f64; 3] = [0.5, 0.7, 0.9];
/// Valve delays tried, in sixteenths of the controller period.
pub const DELAY_GRID_SIXTEENTHS: [u32; 5] = [0, 4, 8, 12, 16];

/// The platen's mechanics found by least squares.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IdentifiedMechanics {
    /// `Mₑ`, kg (the platen alone: the storeys' masses are separate).
    pub effective_mass_kg: f64,
    /// `Kₑ`, N/m.
    pub stiffness_n_per_m: f64,
    /// Viscous coefficient, N·s/m (exponent 1).
    pub viscous_coefficient: f64,
    /// Coulomb force `F_μ`, N.
    pub coulomb_force_n: f64,
    /// Samples in the fit (`|v| ≥` [`SLIP_SPEED_M_S`]).
    pub samples: usize,
    /// RMS of the force residual, N.
    pub force_rms_residual_n: f64,
    /// That RMS relative to the actuator force's RMS.
    pub force_nrmse: f64,
}

/// One identified storey, with its fit.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IdentifiedStorey {
    /// Floor mass, kg (from the platen's equation).
    pub mass_kg: f64,
    /// Storey stiffness, N/m.
    pub stiffness_n_per_m: f64,
    /// Storey damping, N·s/m.
    pub damping_n_s_per_m: f64,
    /// RMS residual of the storey's equation relative to its (filtered) shear's RMS.
    pub shear_nrmse: f64,
}

/// A fixed-base mode of the identified specimen.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Mode {
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Modal damping ratio (classical: `φᵀCφ / 2ωφᵀMφ`).
    pub damping_ratio: f64,
}

/// The valves and the oil column found from the chambers' continuity.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IdentifiedHydraulics {
    /// Land coefficient of one actuator's valves together, m³/s/√Pa at full opening.
    pub land_coefficient: f64,
    /// Rated flow of one valve at the base's rated pressure drop, m³/s.
    pub rated_flow_m3_s: f64,
    /// Cross-port leakage, m³/s/Pa.
    pub leakage_m3_s_per_pa: f64,
    /// Cap-side compliance `V_a0/β`, m³/Pa.
    pub cap_compliance_m3_per_pa: f64,
    /// Rod-side compliance `V_b0/β`, m³/Pa.
    pub rod_compliance_m3_per_pa: f64,
    /// Cap-side volume at `u = 0` with the base's `β`, m³.
    pub cap_volume_m3: f64,
    /// Rod-side volume at `u = 0` with the base's `β`, m³.
    pub rod_volume_m3: f64,
    /// The base's bulk modulus, Pa (not identified: see the module docs).
    pub oil_bulk_modulus_pa: f64,
    /// Spool natural frequency, Hz (the grid's best).
    pub spool_natural_frequency_hz: f64,
    /// Spool damping ratio (the grid's best).
    pub spool_damping_ratio: f64,
    /// Valve delay, s (the grid's best).
    pub valve_delay_s: f64,
    /// `τ + 2ζ/ω_n`: the spool's low-frequency equivalent lag, s.
    pub equivalent_lag_s: f64,
    /// Whether the grid's residual is flat along the equivalent lag (the spool's own
    /// frequency and damping beyond the records' band).
    pub lag_only: bool,
    /// RMS residual of the (filtered) continuity equations relative to their flows' RMS.
    pub flow_nrmse: f64,
    /// Oil-column frequency with the identified platen's mass, Hz.
    pub oil_column_frequency_hz: f64,
    /// Oil-column frequency with the specimen as a rigid payload (what `platen simulate`
    /// reports), Hz.
    pub oil_column_frequency_with_specimen_hz: f64,
}

/// The identified loop run on one record's command.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Prediction {
    /// The record's name.
    pub name: String,
    /// Whether the record was used in the fit.
    pub fitted: bool,
    /// RMS of the recorded table acceleration, m/s².
    pub acceleration_rms_m_s2: f64,
    /// RMS of recorded less predicted table acceleration, m/s².
    pub acceleration_rms_error_m_s2: f64,
    /// The accelerometer's noise estimated from the record (RMS of the second difference
    /// over √6: an upper bound, the signal's own curvature included), m/s².
    pub acceleration_noise_m_s2: f64,
    /// RMS of the recorded displacement, m.
    pub displacement_rms_m: f64,
    /// RMS of recorded less predicted displacement, m.
    pub displacement_rms_error_m: f64,
}

/// What the plant fit found (see the module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct IdentifiedPlant {
    /// The platen.
    pub mechanics: Option<IdentifiedMechanics>,
    /// The storeys, bottom first (empty without storey accelerations).
    pub storeys: Vec<IdentifiedStorey>,
    /// The specimen's fixed-base modes, lowest first.
    pub specimen_modes: Vec<Mode>,
    /// Valves and oil column.
    pub hydraulics: Option<IdentifiedHydraulics>,
    /// The identified loop on each record's command.
    pub predictions: Vec<Prediction>,
    /// The identified table system (the base's geometry, the fitted rest).
    #[serde(skip)]
    pub system: Option<TableSystem>,
    /// The identified platen model.
    #[serde(skip)]
    pub model: Option<IdentifiedParams>,
    /// The identified specimen.
    #[serde(skip)]
    pub specimen: Option<Specimen>,
}

/// The recorded actuator force `n(A_a·p_a − A_b·p_b)` (or `n·A·Δp` for a double-ended
/// actuator with only `Δp`), N.
fn actuator_force(r: &SystemRecord, base: &TableSystem) -> Option<Vec<f64>> {
    let a = &base.actuator;
    let n = f64::from(a.count);
    match (&r.cap_pressure_pa, &r.rod_pressure_pa, &r.delta_p_pa) {
        (Some(pa), Some(pb), _) => Some(
            pa.iter()
                .zip(pb)
                .map(|(pa, pb)| n * (a.cap_area_m2 * pa - a.rod_area_m2 * pb))
                .collect(),
        ),
        (_, _, Some(dp)) if a.cap_area_m2 == a.rod_area_m2 => {
            Some(dp.iter().map(|dp| n * a.cap_area_m2 * dp).collect())
        }
        _ => None,
    }
}

fn central_velocity(u: &[f64], h: f64) -> Vec<f64> {
    let n = u.len();
    let mut v = vec![0.0; n];
    for i in 1..n - 1 {
        v[i] = (u[i + 1] - u[i - 1]) / (2.0 * h);
    }
    v
}

/// The mechanics fit over `recs`; returns the mechanics and the storeys' masses.
fn fit_mechanics(
    recs: &[(&SystemRecord, f64, Vec<f64>)],
    storeys: usize,
) -> Option<(IdentifiedMechanics, Vec<f64>)> {
    let mut x = Vec::new();
    let mut y = Vec::new();
    for (r, h, force) in recs {
        let a = r.a_m_s2.as_ref()?;
        let v = central_velocity(&r.u_m, *h);
        for i in 2..r.u_m.len() - 2 {
            if v[i].abs() < SLIP_SPEED_M_S {
                continue;
            }
            let mut row = vec![a[i], v[i], r.u_m[i], v[i].signum()];
            for s in r.storey_a_m_s2.iter().take(storeys) {
                row.push(s[i]);
            }
            x.push(row);
            y.push(force[i]);
        }
    }
    let (c, ss) = solve(&x, &y)?;
    let n = y.len() as f64;
    let rms_f = (y.iter().map(|f| f * f).sum::<f64>() / n).sqrt();
    let rms_e = (ss / n).sqrt();
    Some((
        IdentifiedMechanics {
            effective_mass_kg: c[0],
            viscous_coefficient: c[1],
            stiffness_n_per_m: c[2],
            coulomb_force_n: c[3],
            samples: y.len(),
            force_rms_residual_n: rms_e,
            force_nrmse: rms_e / rms_f,
        },
        c[4..].to_vec(),
    ))
}

/// The second-order filter `1/(s² + 2ζω s + ω²)` of `x` by the trapezoidal rule, started at
/// rest: returns `(q, q̇, q̈)` (so `s^k/(s² + 2ζω s + ω²)` of `x` for `k = 0, 1, 2`).
fn second_order(x: &[f64], h: f64, w: f64, zeta: f64) -> [Vec<f64>; 3] {
    // State y = (q, q̇): ẏ = A y + B x, A = [[0, 1], [−ω², −2ζω]], B = (0, 1).
    // Trapezoid: (I − hA/2) y₊ = (I + hA/2) y + h/2·B (x + x₊).
    let (a10, a11) = (-w * w, -2.0 * zeta * w);
    let m = [[1.0, -0.5 * h], [-0.5 * h * a10, 1.0 - 0.5 * h * a11]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ];
    let n = x.len();
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut y0, mut y1) = (0.0, 0.0);
    qdd[0] = x[0];
    for i in 1..n {
        let r0 = y0 + 0.5 * h * y1;
        let r1 = y1 + 0.5 * h * (a10 * y0 + a11 * y1) + 0.5 * h * (x[i - 1] + x[i]);
        y0 = inv[0][0] * r0 + inv[0][1] * r1;
        y1 = inv[1][0] * r0 + inv[1][1] * r1;
        q[i] = y0;
        qd[i] = y1;
        qdd[i] = x[i] + a10 * y0 + a11 * y1;
    }
    [q, qd, qdd]
}

/// The storeys' stiffness and damping (masses given), bottom first.
fn fit_storeys(
    recs: &[(&SystemRecord, f64, Vec<f64>)],
    masses: &[f64],
) -> Option<Vec<IdentifiedStorey>> {
    let w0 = std::f64::consts::TAU * DRIFT_HIGHPASS_HZ;
    let ns = masses.len();
    let mut out = Vec::with_capacity(ns);
    for j in 0..ns {
        let mut x = Vec::new();
        let mut y = Vec::new();
        for (r, h, _) in recs {
            let below = if j == 0 {
                r.a_m_s2.as_ref()?
            } else {
                &r.storey_a_m_s2[j - 1]
            };
            let rel: Vec<f64> = r.storey_a_m_s2[j]
                .iter()
                .zip(below)
                .map(|(a, b)| a - b)
                .collect();
            let shear: Vec<f64> = (0..r.u_m.len())
                .map(|i| (j..ns).map(|k| masses[k] * r.storey_a_m_s2[k][i]).sum())
                .collect();
            // 1/(s+ω₀)²: ζ = 1.
            let [d0, d1, _] = second_order(&rel, *h, w0, 1.0);
            let [_, _, s2] = second_order(&shear, *h, w0, 1.0);
            let skip = (2.0 / (DRIFT_HIGHPASS_HZ * *h)) as usize / 10;
            for i in skip.min(r.u_m.len() / 4)..r.u_m.len() {
                x.push(vec![-d0[i], -d1[i]]);
                y.push(s2[i]);
            }
        }
        let (c, ss) = solve(&x, &y)?;
        let n = y.len() as f64;
        let rms = (y.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
        out.push(IdentifiedStorey {
            mass_kg: masses[j],
            stiffness_n_per_m: c[0],
            damping_n_s_per_m: c[1],
            shear_nrmse: (ss / n).sqrt() / rms,
        });
    }
    Some(out)
}

/// The fixed-base modes of `storeys` (classical modal damping).
fn modes(storeys: &[IdentifiedStorey]) -> Vec<Mode> {
    let n = storeys.len();
    let tri = |f: &dyn Fn(&IdentifiedStorey) -> f64| {
        DMatrix::from_fn(n, n, |i, j| {
            let own = f(&storeys[i]) + storeys.get(i + 1).map_or(0.0, f);
            if i == j {
                own
            } else if i + 1 == j {
                -f(&storeys[j])
            } else if j + 1 == i {
                -f(&storeys[i])
            } else {
                0.0
            }
        })
    };
    let k = tri(&|s| s.stiffness_n_per_m);
    let c = tri(&|s| s.damping_n_s_per_m);
    let isq: Vec<f64> = storeys.iter().map(|s| 1.0 / s.mass_kg.sqrt()).collect();
    let ks = DMatrix::from_fn(n, n, |i, j| k[(i, j)] * isq[i] * isq[j]);
    let cs = DMatrix::from_fn(n, n, |i, j| c[(i, j)] * isq[i] * isq[j]);
    let eig = SymmetricEigen::new(ks);
    let mut out: Vec<Mode> = (0..n)
        .filter(|&m| eig.eigenvalues[m] > 0.0)
        .map(|m| {
            let w = eig.eigenvalues[m].sqrt();
            let phi = eig.eigenvectors.column(m);
            let cm = (phi.transpose() * &cs * phi)[(0, 0)];
            Mode {
                frequency_hz: w / std::f64::consts::TAU,
                damping_ratio: cm / (2.0 * w),
            }
        })
        .collect();
    out.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    out
}

/// The spool opening at the samples: the held drive, delayed by `delay_sub` sixteenths of
/// the period, through `ω²/(s² + 2ζωs + ω²)` (RK4, 16 steps per period), clamped to ±1.
fn spool(drive: &[f64], h: f64, f_hz: f64, zeta: f64, delay_sub: u32) -> Vec<f64> {
    let w = std::f64::consts::TAU * f_hz;
    let dt = h / 16.0;
    let f = |x: f64, xd: f64, d: f64| (xd, w * w * (d - x) - 2.0 * zeta * w * xd);
    let (mut x, mut xd) = (0.0_f64, 0.0_f64);
    let mut out = vec![0.0; drive.len()];
    let mut prev = 0.0;
    for i in 0..drive.len() {
        out[i] = x.clamp(-1.0, 1.0);
        for j in 0..16 {
            let d = if j < delay_sub { prev } else { drive[i] };
            let k1 = f(x, xd, d);
            let k2 = f(x + 0.5 * dt * k1.0, xd + 0.5 * dt * k1.1, d);
            let k3 = f(x + 0.5 * dt * k2.0, xd + 0.5 * dt * k2.1, d);
            let k4 = f(x + dt * k3.0, xd + dt * k3.1, d);
            x += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            xd += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        }
        prev = drive[i];
    }
    out
}

/// Signed `√|dp|`, linear below `laminar` Pa (as platen's valve).
fn root(dp: f64, laminar: f64) -> f64 {
    if dp.abs() >= laminar {
        dp.signum() * dp.abs().sqrt()
    } else {
        dp / laminar.sqrt()
    }
}

/// The filtered continuity rows of one record for one spool: `(rows, rhs)`.
struct Continuity {
    /// Filtered `x_v·√drop` regressors need the spool; the rest is fixed per record.
    lp_dp: Vec<f64>,
    lp_dpa: Vec<f64>,
    lp_dpb: Vec<f64>,
    rhs_a: Vec<f64>,
    rhs_b: Vec<f64>,
}

fn lowpass(x: &[f64], h: f64) -> [Vec<f64>; 3] {
    let w = std::f64::consts::TAU * CONTINUITY_LOWPASS_HZ;
    let [q, qd, qdd] = second_order(x, h, w, std::f64::consts::FRAC_1_SQRT_2);
    let s = |v: Vec<f64>| v.into_iter().map(|z| z * w * w).collect::<Vec<f64>>();
    [s(q), s(qd), s(qdd)]
}

fn continuity(r: &SystemRecord, h: f64, base: &TableSystem) -> Option<Continuity> {
    let (pa, pb) = (r.cap_pressure_pa.as_ref()?, r.rod_pressure_pa.as_ref()?);
    let a = &base.actuator;
    let beta = base.oil_bulk_modulus_pa;
    let dp: Vec<f64> = pa.iter().zip(pb).map(|(a, b)| a - b).collect();
    let [lp_dp, _, _] = lowpass(&dp, h);
    let [_, lp_dpa, _] = lowpass(pa, h);
    let [_, lp_dpb, _] = lowpass(pb, h);
    let [_, lp_v, _] = lowpass(&r.u_m, h);
    // The small u·ṗ/β terms, with ṗ from the filtered pressure (unfiltered is noise).
    let upa: Vec<f64> = r.u_m.iter().zip(&lp_dpa).map(|(u, p)| u * p).collect();
    let upb: Vec<f64> = r.u_m.iter().zip(&lp_dpb).map(|(u, p)| u * p).collect();
    let [lp_upa, _, _] = lowpass(&upa, h);
    let [lp_upb, _, _] = lowpass(&upb, h);
    let rhs_a = (0..pa.len())
        .map(|i| a.cap_area_m2 * (lp_v[i] + lp_upa[i] / beta))
        .collect();
    let rhs_b = (0..pa.len())
        .map(|i| a.rod_area_m2 * (lp_v[i] + lp_upb[i] / beta))
        .collect();
    Some(Continuity {
        lp_dp,
        lp_dpa,
        lp_dpb,
        rhs_a,
        rhs_b,
    })
}

/// `(coefficients [K, C_L, V_a0/β, V_b0/β], residual², rhs², samples)` for one spool.
fn fit_continuity(
    recs: &[(&SystemRecord, f64, Continuity)],
    base: &TableSystem,
    spool_of: &dyn Fn(&[f64], f64) -> Vec<f64>,
) -> Option<(Vec<f64>, f64, f64)> {
    let laminar = platen_system::LAMINAR_FRACTION * base.servo_valve.rated_pressure_drop_pa;
    let (ps, pr) = (base.supply_pressure_pa, base.return_pressure_pa);
    let mut x = Vec::new();
    let mut y = Vec::new();
    for (r, h, c) in recs {
        let (pa, pb) = (r.cap_pressure_pa.as_ref()?, r.rod_pressure_pa.as_ref()?);
        let xv = spool_of(r.drive.as_ref()?, *h);
        let (mut qa, mut qb) = (vec![0.0; xv.len()], vec![0.0; xv.len()]);
        for i in 0..xv.len() {
            let (pa, pb) = (pa[i].max(0.0), pb[i].max(0.0));
            (qa[i], qb[i]) = if xv[i] >= 0.0 {
                (
                    xv[i] * root(ps - pa, laminar),
                    xv[i] * root(pb - pr, laminar),
                )
            } else {
                (
                    xv[i] * root(pa - pr, laminar),
                    xv[i] * root(ps - pb, laminar),
                )
            };
        }
        let [lqa, _, _] = lowpass(&qa, *h);
        let [lqb, _, _] = lowpass(&qb, *h);
        let skip = (0.05 / *h) as usize;
        for i in skip..xv.len() {
            x.push(vec![lqa[i], -c.lp_dp[i], -c.lp_dpa[i], 0.0]);
            y.push(c.rhs_a[i]);
            x.push(vec![lqb[i], -c.lp_dp[i], 0.0, c.lp_dpb[i]]);
            y.push(c.rhs_b[i]);
        }
    }
    let (c, ss) = normal_equations(&x, &y)?;
    let yy = y.iter().map(|v| v * v).sum::<f64>();
    Some((c, ss, yy))
}

/// Least squares by the column-scaled normal equations (small, well-conditioned problems
/// solved many times: the grid search); the coefficients and the residual's sum of squares.
fn normal_equations(x: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, f64)> {
    let m = x.first()?.len();
    let mut scale = vec![0.0; m];
    for row in x {
        for (s, v) in scale.iter_mut().zip(row) {
            *s += v * v;
        }
    }
    let scale: Vec<f64> = scale
        .iter()
        .map(|s| if *s > 0.0 { s.sqrt() } else { 1.0 })
        .collect();
    let mut ata = DMatrix::<f64>::zeros(m, m);
    let mut atb = nalgebra::DVector::<f64>::zeros(m);
    for (row, yi) in x.iter().zip(y) {
        for i in 0..m {
            let xi = row[i] / scale[i];
            atb[i] += xi * yi;
            for j in 0..m {
                ata[(i, j)] += xi * row[j] / scale[j];
            }
        }
    }
    let c = ata.cholesky()?.solve(&atb);
    let coef: Vec<f64> = (0..m).map(|j| c[j] / scale[j]).collect();
    let ss = x
        .iter()
        .zip(y)
        .map(|(row, yi)| {
            let p: f64 = row.iter().zip(&coef).map(|(a, b)| a * b).sum();
            (yi - p) * (yi - p)
        })
        .sum();
    Some((coef, ss))
}

/// Collects the table's displacement and acceleration of a run.
#[derive(Default)]
struct Collect {
    u: Vec<f64>,
    a: Vec<f64>,
}

impl SampleSink for Collect {
    fn accept(&mut self, s: &Sample) {
        self.u.push(s.u_m);
        self.a.push(s.a_m_s2);
    }
}

fn rms(x: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for v in x {
        s += v * v;
        n += 1;
    }
    (s / n.max(1) as f64).sqrt()
}

/// Runs the identified loop on `r`'s command and compares it with the record.
pub fn predict(
    r: &SystemRecord,
    fitted: bool,
    system: &TableSystem,
    model: &IdentifiedParams,
    specimen: Option<&Specimen>,
) -> Option<Prediction> {
    let a_rec = r.a_m_s2.as_ref()?;
    let model = model.build().ok()?;
    let command = Motion::from_displacement(r.t_s.clone(), r.command_u_m.clone()).ok()?;
    let run = LoopRun {
        system,
        specimen,
        command: &command,
        method: LoopMethod::Rk4 {
            steps_per_period: JUDGE_STEPS_PER_PERIOD,
        },
        initial: State {
            u_m: r.command_u_m[0],
            v_m_s: 0.0,
        },
    };
    let mut sink = Collect::default();
    forward_closed_loop(&model, &run, r.t_s.len(), &mut sink).ok()?;
    if sink.a.len() != a_rec.len() {
        return None;
    }
    let n = a_rec.len();
    let noise = rms((1..n - 1).map(|i| a_rec[i + 1] - 2.0 * a_rec[i] + a_rec[i - 1])) / 6f64.sqrt();
    Some(Prediction {
        name: r.name.clone(),
        fitted,
        acceleration_rms_m_s2: rms(a_rec.iter().copied()),
        acceleration_rms_error_m_s2: rms(a_rec.iter().zip(&sink.a).map(|(x, y)| x - y)),
        acceleration_noise_m_s2: noise,
        displacement_rms_m: rms(r.u_m.iter().copied()),
        displacement_rms_error_m: rms(r.u_m.iter().zip(&sink.u).map(|(x, y)| x - y)),
    })
}

/// Fits the plant on `fitted` records with the `base` geometry; `not_identified` gets what
/// cannot be seen.
pub(super) fn identify_plant(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    base: &TableSystem,
    not_identified: &mut Vec<(String, String)>,
) -> IdentifiedPlant {
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    let mut plant = IdentifiedPlant {
        mechanics: None,
        storeys: Vec::new(),
        specimen_modes: Vec::new(),
        hydraulics: None,
        predictions: Vec::new(),
        system: None,
        model: None,
        specimen: None,
    };
    let forces: Option<Vec<(&SystemRecord, f64, Vec<f64>)>> = fitted
        .iter()
        .map(|&i| Some((&records[i], periods[i], actuator_force(&records[i], base)?)))
        .collect();
    let storeys = fitted
        .iter()
        .map(|&i| records[i].storey_a_m_s2.len())
        .min()
        .unwrap_or(0);
    let has_a = fitted.iter().all(|&i| records[i].a_m_s2.is_some());
    match (&forces, has_a) {
        (None, _) => not_identified.push(why(
            "platen mass, stiffness, friction; specimen",
            "the actuator force needs cap_pressure_pa and rod_pressure_pa in every fitted \
             record (delta_p_pa alone gives it only for a double-ended actuator)",
        )),
        (Some(_), false) => not_identified.push(why(
            "platen mass, stiffness, friction; specimen",
            "no a_m_s2 in every fitted record: the inertia cannot be separated",
        )),
        (Some(recs), true) => {
            if let Some((mech, masses)) = fit_mechanics(recs, storeys) {
                plant.mechanics = Some(mech);
                if storeys == 0 {
                    not_identified.push(why(
                        "specimen",
                        "no storey{i}_a_m_s2 recorded: a specimen's base shear, if any, is \
                         in the platen's mass, stiffness and damping",
                    ));
                } else if let Some(st) = fit_storeys(recs, &masses) {
                    plant.specimen_modes = modes(&st);
                    plant.storeys = st;
                }
            }
        }
    }
    let drive = fitted.iter().all(|&i| records[i].drive.is_some());
    let cont: Option<Vec<(&SystemRecord, f64, Continuity)>> = fitted
        .iter()
        .map(|&i| {
            Some((
                &records[i],
                periods[i],
                continuity(&records[i], periods[i], base)?,
            ))
        })
        .collect();
    match (cont, drive) {
        (Some(recs), true) => {
            let mut grid: Vec<(f64, f64, u32, Vec<f64>, f64, f64)> = Vec::new();
            for &f in &SPOOL_FREQUENCY_GRID_HZ {
                for &z in &SPOOL_DAMPING_GRID {
                    for &d in &DELAY_GRID_SIXTEENTHS {
                        let of = |dr: &[f64], h: f64| spool(dr, h, f, z, d);
                        if let Some((c, ss, yy)) = fit_continuity(&recs, base, &of) {
                            grid.push((f, z, d, c, ss, yy));
                        }
                    }
                }
            }
            grid.sort_by(|a, b| a.4.total_cmp(&b.4));
            if let Some((f, z, d, c, ss, yy)) = grid.first().cloned() {
                let h = recs[0].1;
                let lag = |f: f64, z: f64, d: u32| {
                    f64::from(d) * h / 16.0 + 2.0 * z / (std::f64::consts::TAU * f)
                };
                let best_lag = lag(f, z, d);
                // Flat ridge: another grid point of about the same lag, a spool at least
                // 1.5× faster or slower, fits within 5 % of the best residual.
                let lag_only = grid.iter().any(|g| {
                    (lag(g.0, g.1, g.2) / best_lag - 1.0).abs() < 0.1
                        && (g.0 / f >= 1.5 || f / g.0 >= 1.5)
                        && g.4 < 1.05 * ss
                });
                let beta = base.oil_bulk_modulus_pa;
                let k = c[0];
                let valves = f64::from(base.servo_valve.count);
                let rated = k * (0.5 * base.servo_valve.rated_pressure_drop_pa).sqrt() / valves;
                let mut hyd = IdentifiedHydraulics {
                    land_coefficient: k,
                    rated_flow_m3_s: rated,
                    leakage_m3_s_per_pa: c[1],
                    cap_compliance_m3_per_pa: c[2],
                    rod_compliance_m3_per_pa: c[3],
                    cap_volume_m3: c[2] * beta,
                    rod_volume_m3: c[3] * beta,
                    oil_bulk_modulus_pa: beta,
                    spool_natural_frequency_hz: f,
                    spool_damping_ratio: z,
                    valve_delay_s: f64::from(d) * h / 16.0,
                    equivalent_lag_s: best_lag,
                    lag_only,
                    flow_nrmse: (ss / yy).sqrt(),
                    oil_column_frequency_hz: f64::NAN,
                    oil_column_frequency_with_specimen_hz: f64::NAN,
                };
                if lag_only {
                    not_identified.push(why(
                        "servo_valve.natural_frequency_hz, damping_ratio, delay_s separately",
                        "the spool is faster than the records' band: only its equivalent lag \
                         τ + 2ζ/ω_n is visible (the printed values are the grid's best, one \
                         of many that fit as well)",
                    ));
                }
                not_identified.push(why(
                    "oil_bulk_modulus_pa separately from the chamber volumes",
                    "only V/β is visible at these strokes: β is the base's, the volumes \
                     follow from it",
                ));
                if hyd.leakage_m3_s_per_pa < 0.0 {
                    hyd.leakage_m3_s_per_pa = 0.0;
                }
                let mut sys = *base;
                sys.actuator.cap_volume_m3 = hyd.cap_volume_m3;
                sys.actuator.rod_volume_m3 = hyd.rod_volume_m3;
                sys.actuator.leakage_m3_s_per_pa = hyd.leakage_m3_s_per_pa;
                sys.servo_valve.rated_flow_m3_s = rated;
                sys.servo_valve.natural_frequency_hz = f;
                sys.servo_valve.damping_ratio = z;
                sys.servo_valve.delay_s = hyd.valve_delay_s;
                if let Some(m) = &plant.mechanics {
                    let payload: f64 = plant.storeys.iter().map(|s| s.mass_kg).sum();
                    hyd.oil_column_frequency_hz =
                        sys.oil_column_frequency_hz(m.effective_mass_kg, 0.0);
                    hyd.oil_column_frequency_with_specimen_hz =
                        sys.oil_column_frequency_hz(m.effective_mass_kg + payload, 0.0);
                }
                plant.system = Some(sys);
                plant.hydraulics = Some(hyd);
            }
        }
        (None, _) => not_identified.push(why(
            "servo-valve flow gain and dynamics, oil column, leakage",
            "the chambers' continuity needs cap_pressure_pa and rod_pressure_pa in every \
             fitted record",
        )),
        (Some(_), false) => not_identified.push(why(
            "servo-valve flow gain and dynamics, oil column, leakage",
            "no drive recorded in every fitted record: the spool's input is unknown",
        )),
    }
    if let Some(m) = &plant.mechanics {
        plant.model = Some(IdentifiedParams {
            effective_mass_kg: m.effective_mass_kg,
            stiffness_n_per_m: m.stiffness_n_per_m.max(0.0),
            coulomb_force_n: m.coulomb_force_n.max(0.0),
            viscous_coefficient: m.viscous_coefficient.max(0.0),
            viscous_exponent: 1.0,
            low_velocity_force_n: 0.0,
            low_velocity_decay_s_per_m: 0.0,
        });
        not_identified.push(why(
            "low_velocity_force_n, low_velocity_decay_s_per_m, a viscous exponent other than 1",
            "the mechanics fit is linear: F_μ·sgn(v) + C·v only (the Stribeck term 0, α = 1)",
        ));
    }
    if !plant.storeys.is_empty() {
        plant.specimen = Specimen::new(
            plant
                .storeys
                .iter()
                .map(|s| Storey {
                    mass_kg: s.mass_kg,
                    stiffness_n_per_m: s.stiffness_n_per_m,
                    damping_n_s_per_m: s.damping_n_s_per_m.max(0.0),
                })
                .collect(),
        )
        .ok();
    }
    plant
}
