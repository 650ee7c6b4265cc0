//! The servo-valves and the oil column from the chambers' continuity: the spool's opening
//! from the recorded drive on a grid of delays and spool dynamics, each fitted by linear least
//! squares, the best one the valves, and the table system they make.

use std::collections::BTreeMap;

use platen_system::{TableSystem, TableSystemParts};

use super::design::ForceFrom;
use super::filters::second_order;
use super::{actuator_stroke_limit_m, IdentifiedPlant};
use crate::system::fit::{Design, LinearFit};
use crate::system::SystemRecord;

/// Highest corner of the low-pass on the continuity equations, Hz (a fifth of the sample
/// rate below 500 Hz).
pub const CONTINUITY_LOWPASS_HZ: f64 = 100.0;
/// Spool natural frequencies tried, Hz.
pub const SPOOL_FREQUENCY_GRID_HZ: [f64; 6] = [60.0, 100.0, 150.0, 200.0, 300.0, 500.0];
/// Spool damping ratios tried.
pub const SPOOL_DAMPING_GRID: [f64; 3] = [0.5, 0.7, 0.9];
/// Valve delays tried, in sixteenths of the controller period.
pub const DELAY_GRID_SIXTEENTHS: [u32; 5] = [0, 4, 8, 12, 16];

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
    /// The pressure channels the continuity used: `"chamber pressures"` or `"delta_p"`.
    pub from: &'static str,
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

/// The spool-independent filtered terms of one record's continuity.
struct Continuity {
    /// `LP(Δp)`.
    lp_dp: Vec<f64>,
    /// Chambers: `LP(ṗ_a)`, `LP(ṗ_b)`; `Δp` alone: `LP(Δṗ)/2` (twice).
    lp_dpa: Vec<f64>,
    lp_dpb: Vec<f64>,
    /// Chambers: `A_a·(LP(v) + LP(u·ṗ_a)/β)` and the rod side's; `Δp` alone: `A·LP(v)`.
    rhs_a: Vec<f64>,
    rhs_b: Vec<f64>,
    /// Whether the record's chambers are used (else its `Δp`).
    chambers: bool,
}

/// The continuity's low-pass corner at period `h`, Hz.
fn continuity_corner_hz(h: f64) -> f64 {
    CONTINUITY_LOWPASS_HZ.min(0.2 / h)
}

fn lowpass(x: &[f64], h: f64) -> [Vec<f64>; 3] {
    let w = std::f64::consts::TAU * continuity_corner_hz(h);
    let [q, qd, qdd] = second_order(x, h, w, std::f64::consts::FRAC_1_SQRT_2);
    let s = |v: Vec<f64>| v.into_iter().map(|z| z * w * w).collect::<Vec<f64>>();
    [s(q), s(qd), s(qdd)]
}

fn continuity(
    r: &SystemRecord,
    h: f64,
    base: &TableSystemParts,
    chambers: bool,
) -> Option<Continuity> {
    let a = &base.actuator;
    let [_, lp_v, _] = lowpass(&r.u_m, h);
    if !chambers {
        let dp = r.delta_p_pa.as_ref()?;
        let [lp_dp, lp_ddp, _] = lowpass(dp, h);
        let half: Vec<f64> = lp_ddp.iter().map(|x| 0.5 * x).collect();
        let rhs: Vec<f64> = lp_v.iter().map(|v| a.cap_area_m2 * v).collect();
        return Some(Continuity {
            lp_dp,
            lp_dpa: half.clone(),
            lp_dpb: half,
            rhs_a: rhs.clone(),
            rhs_b: rhs,
            chambers,
        });
    }
    let (pa, pb) = (r.cap_pressure_pa.as_ref()?, r.rod_pressure_pa.as_ref()?);
    let beta = base.oil_bulk_modulus_pa;
    let dp: Vec<f64> = pa.iter().zip(pb).map(|(a, b)| a - b).collect();
    let [lp_dp, _, _] = lowpass(&dp, h);
    let [_, lp_dpa, _] = lowpass(pa, h);
    let [_, lp_dpb, _] = lowpass(pb, h);
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
        chambers,
    })
}

/// The continuity fit for one spool: coefficients `[K, C_L, V_a0/β, V_b0/β]` (`Δp` alone:
/// `[K, C_L, V₀/β]`), every one `≥ 0`.
fn fit_continuity(
    recs: &[(usize, &SystemRecord, f64, Continuity)],
    base: &TableSystemParts,
    spool_of: &dyn Fn(&[f64], f64) -> Vec<f64>,
) -> Option<LinearFit> {
    let laminar = platen_system::LAMINAR_FRACTION * base.servo_valve.rated_pressure_drop_pa;
    let (ps, pr) = (base.supply_pressure_pa, base.return_pressure_pa);
    let chambers = recs.first()?.3.chambers;
    let m = if chambers { 4 } else { 3 };
    let mut design = Design::new(m);
    for (k, r, h, c) in recs {
        let xv = spool_of(r.drive.as_ref()?, *h);
        let (mut qa, mut qb) = (vec![0.0; xv.len()], vec![0.0; xv.len()]);
        if chambers {
            let (pa, pb) = (r.cap_pressure_pa.as_ref()?, r.rod_pressure_pa.as_ref()?);
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
        } else {
            let dp = r.delta_p_pa.as_ref()?;
            for i in 0..xv.len() {
                let drop = 0.5 * (ps - pr - xv[i].signum() * dp[i]);
                qa[i] = xv[i] * root(drop, laminar);
            }
        }
        let [lqa, _, _] = lowpass(&qa, *h);
        let [lqb, _, _] = if chambers {
            lowpass(&qb, *h)
        } else {
            [Vec::new(), Vec::new(), Vec::new()]
        };
        let skip = (0.05 / *h) as usize;
        for i in skip..xv.len() {
            if chambers {
                design.push(&[lqa[i], -c.lp_dp[i], -c.lp_dpa[i], 0.0], c.rhs_a[i], *k, i);
                design.push(&[lqb[i], -c.lp_dp[i], 0.0, c.lp_dpb[i]], c.rhs_b[i], *k, i);
            } else {
                design.push(&[lqa[i], -c.lp_dp[i], -c.lp_dpa[i]], c.rhs_a[i], *k, i);
            }
        }
    }
    design.fit(&vec![true; m], &vec![false; m])
}

/// The servo-valves and the oil column of [`identify_plant`] (the continuity fit), and the
/// table system they make when a scenario takes it.
///
/// [`identify_plant`]: super::identify_plant
pub(super) fn plant_hydraulics(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    from: &std::result::Result<ForceFrom, &str>,
    base: &TableSystemParts,
    plant: &mut IdentifiedPlant,
    not_identified: &mut Vec<(String, String)>,
) {
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    let drive = fitted.iter().all(|&i| records[i].drive.is_some());
    let chambers = matches!(from, Ok(ForceFrom::Chambers | ForceFrom::ChambersRatioFree));
    let cont: Option<Vec<(usize, &SystemRecord, f64, Continuity)>> = match from {
        Ok(_) => fitted
            .iter()
            .map(|&i| {
                Some((
                    i,
                    &records[i],
                    periods[i],
                    continuity(&records[i], periods[i], base, chambers)?,
                ))
            })
            .collect(),
        Err(_) => None,
    };
    match (cont, drive) {
        (Some(recs), true) => {
            if let Some(hyd) = fit_valves(&recs, base, plant, not_identified) {
                let mut sys = *base;
                sys.actuator.cap_volume_m3 = hyd.cap_volume_m3;
                sys.actuator.rod_volume_m3 = hyd.rod_volume_m3;
                sys.actuator.leakage_m3_s_per_pa = hyd.leakage_m3_s_per_pa;
                sys.servo_valve.rated_flow_m3_s = hyd.rated_flow_m3_s;
                sys.servo_valve.natural_frequency_hz = hyd.spool_natural_frequency_hz;
                sys.servo_valve.damping_ratio = hyd.spool_damping_ratio;
                sys.servo_valve.delay_s = hyd.valve_delay_s;
                let mut hyd = hyd;
                if let Some(m) = &plant.mechanics {
                    let payload: f64 = plant.storeys.iter().map(|s| s.mass_kg).sum();
                    hyd.oil_column_frequency_hz =
                        sys.oil_column_frequency_hz(m.effective_mass_kg, 0.0);
                    hyd.oil_column_frequency_with_specimen_hz =
                        sys.oil_column_frequency_hz(m.effective_mass_kg + payload, 0.0);
                }
                // Only a system a scenario takes is printed and run.
                match TableSystem::new(sys, actuator_stroke_limit_m(&sys.actuator)) {
                    Ok(sys) => plant.system = Some(sys),
                    Err(e) => not_identified.push(why(
                        "the table system as a whole",
                        &format!(
                            "the identified values are not a table system a scenario takes \
                             ({e}); the records do not determine the valves and chambers"
                        ),
                    )),
                }
                plant.hydraulics = Some(hyd);
            }
        }
        (None, _) => {
            if from.is_ok() {
                not_identified.push(why(
                    "servo-valve flow gain and dynamics, oil column, leakage",
                    "the continuity needs the pressures in every fitted record",
                ));
            }
        }
        (Some(_), false) => not_identified.push(why(
            "servo-valve flow gain and dynamics, oil column, leakage",
            "no drive recorded in every fitted record: the spool's input is unknown",
        )),
    }
}

/// The spool grid's best continuity fit, as the valves and oil column.
fn fit_valves(
    recs: &[(usize, &SystemRecord, f64, Continuity)],
    base: &TableSystemParts,
    plant: &mut IdentifiedPlant,
    not_identified: &mut Vec<(String, String)>,
) -> Option<IdentifiedHydraulics> {
    let grid = spool_grid(recs, base);
    let (f, z, d, fit) = grid.first()?.clone();
    let chambers = recs[0].3.chambers;
    let h = recs[0].2;
    let lag =
        |f: f64, z: f64, d: u32| f64::from(d) * h / 16.0 + 2.0 * z / (std::f64::consts::TAU * f);
    let best_lag = lag(f, z, d);
    // Flat ridge: another grid point of about the same lag, a spool at least 1.5× faster or
    // slower, fits within 5 % of the best residual.
    let lag_only = grid.iter().any(|g| {
        (lag(g.0, g.1, g.2) / best_lag - 1.0).abs() < 0.1
            && (g.0 / f >= 1.5 || f / g.0 >= 1.5)
            && g.3.rss < 1.05 * fit.rss
    });
    let beta = base.oil_bulk_modulus_pa;
    let c = &fit.coef;
    let k = c[0];
    let valves = f64::from(base.servo_valve.count);
    let to_rated = (0.5 * base.servo_valve.rated_pressure_drop_pa).sqrt() / valves;
    let (ca, cb) = if chambers { (c[2], c[3]) } else { (c[2], c[2]) };
    valve_std_errors(&fit, chambers, to_rated, beta, &mut plant.std_errors);
    valve_notes(lag_only, chambers, not_identified);
    Some(IdentifiedHydraulics {
        land_coefficient: k,
        rated_flow_m3_s: k * to_rated,
        leakage_m3_s_per_pa: c[1].max(0.0),
        cap_compliance_m3_per_pa: ca,
        rod_compliance_m3_per_pa: cb,
        cap_volume_m3: ca * beta,
        rod_volume_m3: cb * beta,
        oil_bulk_modulus_pa: beta,
        spool_natural_frequency_hz: f,
        spool_damping_ratio: z,
        valve_delay_s: f64::from(d) * h / 16.0,
        equivalent_lag_s: best_lag,
        lag_only,
        flow_nrmse: fit.nrmse(),
        oil_column_frequency_hz: f64::NAN,
        oil_column_frequency_with_specimen_hz: f64::NAN,
        from: if chambers {
            "chamber pressures"
        } else {
            "delta_p"
        },
    })
}

/// The continuity fit at every spool of the grid (frequency, damping, delay in sixteenths),
/// least residual first.
fn spool_grid(
    recs: &[(usize, &SystemRecord, f64, Continuity)],
    base: &TableSystemParts,
) -> Vec<(f64, f64, u32, LinearFit)> {
    let mut grid: Vec<(f64, f64, u32, LinearFit)> = Vec::new();
    for &f in &SPOOL_FREQUENCY_GRID_HZ {
        for &z in &SPOOL_DAMPING_GRID {
            for &d in &DELAY_GRID_SIXTEENTHS {
                let of = |dr: &[f64], h: f64| spool(dr, h, f, z, d);
                if let Some(fit) = fit_continuity(recs, base, &of) {
                    grid.push((f, z, d, fit));
                }
            }
        }
    }
    grid.sort_by(|a, b| a.3.rss.total_cmp(&b.3.rss));
    grid
}

/// The finite standard errors of the valves' values (continuity fit `fit`, `to_rated` the land
/// coefficient's factor to a valve's rated flow, `beta` the bulk modulus) into `std_errors`.
fn valve_std_errors(
    fit: &LinearFit,
    chambers: bool,
    to_rated: f64,
    beta: f64,
    std_errors: &mut BTreeMap<String, f64>,
) {
    let se = |j: usize| fit.estimates[j].std_error;
    let (se_a, se_b) = if chambers {
        (se(2), se(3))
    } else {
        (se(2), se(2))
    };
    for (key, value) in [
        ("table_system.servo_valve.rated_flow_m3_s", se(0) * to_rated),
        ("table_system.actuator.leakage_m3_s_per_pa", se(1)),
        ("table_system.actuator.chamber_volume_m3[0]", se_a * beta),
        ("table_system.actuator.chamber_volume_m3[1]", se_b * beta),
    ] {
        if value.is_finite() {
            std_errors.insert(key.into(), value);
        }
    }
}

/// What the continuity fit cannot show, into `not_identified`: the spool's own dynamics when
/// only its lag is seen, `β` apart from the volumes, and (`Δp` alone) the chambers apart.
fn valve_notes(lag_only: bool, chambers: bool, not_identified: &mut Vec<(String, String)>) {
    let why = |what: &str, reason: &str| (what.to_owned(), reason.to_owned());
    if lag_only {
        not_identified.push(why(
            "servo_valve.natural_frequency_hz, damping_ratio, delay_s separately",
            "the spool is faster than the records' band: only its equivalent lag τ + 2ζ/ω_n \
             is visible (the printed values are the grid's best, one of many that fit as well)",
        ));
    }
    not_identified.push(why(
        "oil_bulk_modulus_pa separately from the chamber volumes",
        "only V/β is visible at these strokes: β is the base's (or the nominal), the volumes \
         follow from it",
    ));
    if !chambers {
        not_identified.push(why(
            "the two chamber volumes apart",
            "Δp alone shows the load flow of a double-ended actuator, whose chambers are then \
             taken alike (V_a0 = V_b0)",
        ));
    }
}
