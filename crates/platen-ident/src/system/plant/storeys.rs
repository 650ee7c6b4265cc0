//! The specimen's storeys: their stiffness and damping from each storey's equation (the
//! masses come from the platen's force balance), and the fixed-base modes they make.

use nalgebra::{DMatrix, SymmetricEigen};
use platen_signal::ZeroPhaseFilter;

use super::filters::{mechanics_filter, second_order, upsampled, UPSAMPLE};
use super::IdentifiedPlant;
use crate::system::fit::Design;
use crate::system::SystemRecord;

/// Corner of the `s²/(s + ω₀)²` filter on the storey equations, Hz. The drift regressor is
/// the relative acceleration through `1/(s + ω₀)²`, whose gain is flat below `ω₀`: the
/// accelerometers' noise there, integrated twice, would be in the regressor and bias the
/// stiffness low (errors in variables). The noise's share of the regressor is least for `ω₀`
/// near the specimen's modes; 2 Hz is below the first mode of the specimens shake tables
/// carry and keeps that share small (on the small table's records, where the frame's first
/// mode is at 6.5 Hz, a 0.3 Hz corner gave its stiffness 33 % low).
pub const DRIFT_HIGHPASS_HZ: f64 = 2.0;

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

/// The storeys of the force balance's `masses` (none recorded: said in `not_identified`):
/// their stiffness and damping with standard errors, and the specimen's modes, into `plant`.
pub(super) fn plant_storeys(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    masses: &[f64],
    plant: &mut IdentifiedPlant,
    not_identified: &mut Vec<(String, String)>,
) {
    if masses.is_empty() {
        not_identified.push((
            "specimen".to_owned(),
            "no storey{i}_a_m_s2 recorded: a specimen's base shear, if any, is \
             in the platen's mass, stiffness and damping"
                .to_owned(),
        ));
    } else if let Some(st) = fit_storeys(records, periods, fitted, masses) {
        for (j, (_, e)) in st.iter().enumerate() {
            plant
                .std_errors
                .insert(format!("specimen.storeys[{j}].stiffness_n_per_m"), e[0]);
            plant
                .std_errors
                .insert(format!("specimen.storeys[{j}].damping_n_s_per_m"), e[1]);
        }
        plant.storeys = st.into_iter().map(|(s, _)| s).collect();
        plant.specimen_modes = modes(&plant.storeys);
    }
}

/// The storeys' stiffness and damping (masses given), bottom first, with the standard errors
/// of stiffness and damping.
fn fit_storeys(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    masses: &[f64],
) -> Option<Vec<(IdentifiedStorey, [f64; 2])>> {
    let w0 = std::f64::consts::TAU * DRIFT_HIGHPASS_HZ;
    let ns = masses.len();
    let mut out = Vec::with_capacity(ns);
    for j in 0..ns {
        let mut design = Design::new(2);
        for &k in fitted {
            let (r, h) = (&records[k], periods[k]);
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
                .map(|i| (j..ns).map(|s| masses[s] * r.storey_a_m_s2[s][i]).sum())
                .collect();
            // Both sides through the force balance's low-pass: what the command does not
            // drive is left out, as there.
            let lp = mechanics_filter(r, h).ok()?;
            let (rel, shear) = (lp.apply(&rel).ok()?, lp.apply(&shear).ok()?);
            // Both sides through s²/(s+ω₀)² first: the drift regressor below is the relative
            // acceleration through 1/(s+ω₀)², whose DC gain 1/ω₀² would carry the
            // accelerometers' offsets (a few tenths of a mg after zeroing) into the drift as
            // a constant, which the stiffness cannot fit and is biased by (on the stand-ins of
            // real records, the first mode came out 11 % low). Then 1/(s+ω₀)²: ζ = 1, both
            // run at UPSAMPLE times the rate on the band-limited interpolation of both sides,
            // then taken at the samples.
            let (rel, shear) = (upsampled(&rel)?, upsampled(&shear)?);
            let hu = h / UPSAMPLE as f64;
            let [_, _, rel] = second_order(&rel, hu, w0, 1.0);
            let [_, _, shear] = second_order(&shear, hu, w0, 1.0);
            let [d0, d1, _] = second_order(&rel, hu, w0, 1.0);
            let [_, _, s2] = second_order(&shear, hu, w0, 1.0);
            // The filters' start (a step through the fourth-order chain, e.g. an offset,
            // decays as (ω₀t)³e^(−ω₀t): below 1e-2 of its peak after 1.5 corner periods).
            let skip = (1.5 / (DRIFT_HIGHPASS_HZ * h)) as usize;
            let n = r.u_m.len();
            // The last samples' interpolation reaches past the record: left out.
            for i in skip.min(n / 4)..n - UPSAMPLE {
                let j = UPSAMPLE * i;
                design.push(&[-d0[j], -d1[j]], s2[j], k, i);
            }
        }
        let f = design.fit(&[true, true], &[false, false])?;
        out.push((
            IdentifiedStorey {
                mass_kg: masses[j],
                stiffness_n_per_m: f.coef[0],
                damping_n_s_per_m: f.coef[1],
                shear_nrmse: f.nrmse(),
            },
            [f.estimates[0].std_error, f.estimates[1].std_error],
        ));
    }
    Some(out)
}

/// The fixed-base modes of `storeys` (classical modal damping).
pub(crate) fn modes(storeys: &[IdentifiedStorey]) -> Vec<Mode> {
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
