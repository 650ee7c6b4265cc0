//! The per-record reports of an any-record identification: each record's fit and data, the
//! effective mass it gives alone, and the warning when the records put the mass far apart
//! (records of different tables fitted as one).

use super::data::Prepared;
use super::fitted_law;
use super::hac;
use super::result::{FloorsReport, RecordReport, RecordWarning};
use super::separable::{SeparableFit, OFFSETS};
use super::skew::ChannelDelay;
use crate::record::TestRecord;

/// [`disagreement`] of the records' masses each alone in `reports` against the joint
/// `joint_kg`.
pub(super) fn reports_disagreement(
    reports: &[RecordReport],
    joint_kg: f64,
) -> Option<RecordWarning> {
    let alone: Vec<(&str, Option<MassAlone>)> = reports
        .iter()
        .map(|r| {
            let m = r.mass_alone_kg.map(|mass_kg| MassAlone {
                mass_kg,
                std_error_kg: r.mass_alone_std_error_kg.unwrap_or(f64::INFINITY),
                inertial_share: r.mass_alone_inertial_share.unwrap_or(0.0),
            });
            (r.name.as_str(), m)
        })
        .collect();
    disagreement(&alone, joint_kg)
}

/// What a record alone says of the mass ([`RecordReport::mass_alone_kg`]).
#[derive(Debug, Clone, Copy)]
struct MassAlone {
    /// The mass, kg.
    mass_kg: f64,
    /// Its standard error, kg (infinite for fewer than two blocks).
    std_error_kg: f64,
    /// The share of the record's force (RMS about its mean, over the used samples) that its
    /// inertia `M·(a − ā)` makes.
    inertial_share: f64,
}

/// The effective mass `rec` alone gives ([`RecordReport::mass_alone_kg`]): the joint mass
/// `mass_kg` corrected by the least-squares slope of the record's residual (its force less
/// `fitted`, over the `used` samples) on its acceleration, both centred (the record's own
/// offset refitted too). Its standard error is the batch-means one of the [`hac`] module
/// (blocks of [`hac::BLOCK_SAMPLES`] samples of the record's time, unused samples scoring
/// zero): the residual is correlated. `None` without two used samples of different
/// accelerations.
fn mass_alone_kg(
    mass_kg: f64,
    rec: &TestRecord,
    used: &[bool],
    fitted: &[f64],
) -> Option<MassAlone> {
    let (a, f) = (rec.a_m_s2(), rec.force_n());
    let used_at: Vec<usize> = (0..rec.len()).filter(|&i| used[i]).collect();
    let n = used_at.len() as f64;
    let mean = |x: &dyn Fn(usize) -> f64| used_at.iter().map(|&i| x(i)).sum::<f64>() / n;
    let (am, fm, rm) = (
        mean(&|i| a[i]),
        mean(&|i| f[i]),
        mean(&|i| f[i] - fitted[i]),
    );
    let (mut saa, mut sar, mut sff) = (0.0, 0.0, 0.0);
    for &i in &used_at {
        saa += (a[i] - am).powi(2);
        sar += (a[i] - am) * (f[i] - fitted[i] - rm);
        sff += (f[i] - fm).powi(2);
    }
    if used_at.len() < 2 || saa <= 0.0 || sff <= 0.0 {
        return None;
    }
    let slope = sar / saa;
    // Batch means of the scores (a − ā)·e, e the residual after the slope.
    let blocks = rec.len() / hac::BLOCK_SAMPLES;
    let last = blocks.max(1) - 1;
    let mut sums = vec![0.0; last + 1];
    for &i in &used_at {
        let e = f[i] - fitted[i] - rm - slope * (a[i] - am);
        sums[(i / hac::BLOCK_SAMPLES).min(last)] += (a[i] - am) * e;
    }
    let k = sums.len() as f64;
    let std_error_kg = if blocks >= 2 {
        (k / (k - 1.0) * sums.iter().map(|g| g * g).sum::<f64>()).sqrt() / saa
    } else {
        f64::INFINITY
    };
    Some(MassAlone {
        mass_kg: mass_kg + slope,
        std_error_kg,
        inertial_share: mass_kg.abs() * (saa / sff).sqrt(),
    })
}

/// The warning of records that put the mass far apart: among the records that determine it
/// (their inertia at least [`INERTIAL_SHARE_JUDGED`] of their force, and a standard error
/// below [`MASS_DETERMINED`] of the joint mass), the lightest and the heaviest differ by more
/// than [`MASS_SPREAD_WARNED`] of it (at least 5.6 standard errors of the difference).
fn disagreement(reports: &[(&str, Option<MassAlone>)], joint_kg: f64) -> Option<RecordWarning> {
    let masses: Vec<(&str, f64)> = reports
        .iter()
        .filter_map(|(name, m)| {
            let m = (*m)?;
            (m.inertial_share >= INERTIAL_SHARE_JUDGED
                && m.std_error_kg < MASS_DETERMINED * joint_kg.abs())
            .then_some((*name, m.mass_kg))
        })
        .collect();
    let lightest = masses.iter().min_by(|a, b| a.1.total_cmp(&b.1))?;
    let heaviest = masses.iter().max_by(|a, b| a.1.total_cmp(&b.1))?;
    (heaviest.1 - lightest.1 > MASS_SPREAD_WARNED * joint_kg.abs()).then(|| {
        RecordWarning::RecordsDisagree {
            lightest: (lightest.0.to_owned(), lightest.1),
            heaviest: (heaviest.0.to_owned(), heaviest.1),
            joint_kg,
        }
    })
}

/// The share of a record's force its inertia must make for its mass alone to be judged: a
/// record dominated by friction or stiffness (a slow sine, a triangle's ramps) puts any misfit
/// of those into the mass it gives alone.
pub const INERTIAL_SHARE_JUDGED: f64 = 0.5;

/// How far apart, as a fraction of the joint mass, the records' masses each alone may lie
/// before the identification warns that they are not of one table.
pub const MASS_SPREAD_WARNED: f64 = 0.1;

/// The standard error, as a fraction of the joint mass, below which a record's mass alone
/// counts in [`MASS_SPREAD_WARNED`]'s comparison: a record that barely accelerates (a slow
/// sine, a triangle's ramps) does not determine the mass by itself.
pub const MASS_DETERMINED: f64 = 0.025;

/// The per-record reports of the joint `fit` (the records' `simulated` motion from the
/// output error, where made), with each record's corrected channel `delays`.
pub(super) fn record_reports(
    records: &[TestRecord],
    prepared: &[Prepared],
    fit: &SeparableFit,
    simulated: Vec<Option<Vec<f64>>>,
    delays: Vec<Vec<ChannelDelay>>,
) -> Vec<RecordReport> {
    let q = &fit.full;
    let law = fitted_law(q);
    records
        .iter()
        .zip(prepared)
        .zip(simulated)
        .zip(delays)
        .enumerate()
        .map(|(r, (((rec, p), sim), channel_delays))| {
            let fitted_force: Vec<f64> = (0..rec.len())
                .map(|i| {
                    q[0] * rec.a_m_s2()[i]
                        + q[1] * rec.u_m()[i]
                        + law.smooth_signed_n(p.v_m_s[i])
                        + q[OFFSETS + r]
                })
                .collect();
            let alone = mass_alone_kg(q[0], rec, &p.used, &fitted_force);
            let speeds = (0..rec.len())
                .filter(|&i| p.used[i])
                .map(|i| p.v_m_s[i].abs())
                .fold([f64::INFINITY, 0.0], |[lo, hi], w| [lo.min(w), hi.max(w)]);
            RecordReport {
                name: rec.name().to_owned(),
                sample_rate_hz: rec.sample_rate_hz(),
                start_s: rec.start_s(),
                samples: rec.len(),
                velocity_given: p.velocity_given,
                used_samples: p.used.iter().filter(|&&u| u).count(),
                speed_range_m_s: speeds,
                floors: rec.floors().map(|f| FloorsReport {
                    masses_kg: f.masses_kg.clone(),
                    peak_base_shear_n: f.peak_base_shear_n,
                }),
                force_n: rec.force_n().to_vec(),
                fitted_force_n: fitted_force.clone(),
                used: p.used.clone(),
                velocity_m_s: p.v_m_s.clone(),
                u_m: rec.u_m().to_vec(),
                simulated_u_m: sim,
                channel_delays,
                mass_alone_kg: alone.map(|m| m.mass_kg),
                mass_alone_std_error_kg: alone.map(|m| m.std_error_kg),
                mass_alone_inertial_share: alone.map(|m| m.inertial_share),
            }
        })
        .collect()
}
