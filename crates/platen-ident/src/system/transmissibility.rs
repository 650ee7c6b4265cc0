//! The specimen's modes as the records show them, with no model at all: the transmissibility
//! from the table's acceleration to the roof's (`H₁ = P_xy/P_xx`, Welch cross-spectra pooled
//! over the fitted records), its peaks and their half-power damping. Reported beside the
//! identified modes, with a warning when an identified mode lies more than
//! [`MODE_TOLERANCE`] from the peak the records show.
//!
//! # Peaks
//!
//! The transmissibility's local maxima between [`LOWEST_PEAK_HZ`] and the highest frequency
//! the records carry ([`HIGHEST_PEAK_FRACTION`] of the sample rate, at most
//! [`HIGHEST_PEAK_HZ`]), the `storeys` tallest (a frame of `n` storeys has `n` modes), lowest
//! first. Each is located to a fraction of a bin by the parabola through the logarithms of the
//! three bins around it (exact for a Gaussian; on a lightly damped resonance seen through a
//! Hann window, within a tenth of a bin). Its half-power width is where `|H|` falls to
//! `1/√2` of the peak on each side (linear between bins); the damping ratio is the width over
//! twice the frequency. The window smears every resonance over its own bandwidth (the Hann
//! window's effective noise bandwidth is 1.5 bins), so a measured width is always an upper
//! bound of the true one, and an estimate with little bias only when it is several window
//! bandwidths wide ([`RESOLVED_BINS`]); narrower, it is reported as the bound it is.

use super::SystemRecord;

/// An identified mode further than this (relative) from the transmissibility's peak is
/// warned about: the first-order change of a mode with its stiffness is half the stiffness's,
/// so 2 % is a storey stiffness 4 % off, far beyond what a fit of the records should leave.
pub const MODE_TOLERANCE: f64 = 0.02;
/// The lowest frequency searched for peaks, Hz.
pub const LOWEST_PEAK_HZ: f64 = 0.5;
/// The highest frequency searched for peaks, Hz.
pub const HIGHEST_PEAK_HZ: f64 = 40.0;
/// The highest frequency searched as a fraction of the sample rate (the anti-aliasing band).
pub const HIGHEST_PEAK_FRACTION: f64 = 0.4;
/// The finest resolution sought, Hz: segments no longer than `f_s/RESOLUTION_HZ` samples.
pub const RESOLUTION_HZ: f64 = 0.0125;
/// A half-power width of at least this many bins is taken as an estimate of the damping, a
/// narrower one only as its upper bound: four times the Hann window's effective noise
/// bandwidth of 1.5 bins, where the window's smearing of a resonance's width falls below a
/// few percent (Bendat & Piersol's `B_e ≤ B_r/4`).
pub const RESOLVED_BINS: f64 = 6.0;
/// The shortest Welch segment used, samples (below it the bins are too coarse to tell a
/// storey's mode: 0.8 Hz at 204.8 Hz).
pub const MIN_SEGMENT: usize = 256;

/// One peak of the roof's transmissibility.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TransmissibilityPeak {
    /// The peak's frequency, Hz (parabolic between bins).
    pub frequency_hz: f64,
    /// The frequency of the peak's bin, Hz.
    pub bin_frequency_hz: f64,
    /// `|H|` at the peak's bin.
    pub magnitude: f64,
    /// The half-power damping ratio (`Δf/2f`), or its upper bound when not resolved.
    pub half_power_damping_ratio: f64,
    /// Whether the half-power width is [`RESOLVED_BINS`] bins or wider: otherwise the damping
    /// is only bounded (`half_power_damping_ratio` is the bound).
    pub damping_resolved: bool,
    /// The coherence between the table and the roof at the peak's bin.
    pub coherence: f64,
}

/// An identified mode beside the peak the records show nearest it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ModeCheck {
    /// The identified mode's frequency, Hz.
    pub identified_hz: f64,
    /// The transmissibility peak's, Hz.
    pub transmissibility_hz: f64,
    /// `identified/transmissibility − 1`.
    pub relative_difference: f64,
    /// The identified mode's damping ratio.
    pub identified_damping_ratio: f64,
    /// The peak's half-power damping ratio (or its bound).
    pub half_power_damping_ratio: f64,
}

/// The records' own modal content ([module docs](self)).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Transmissibility {
    /// Bin spacing, Hz.
    pub resolution_hz: f64,
    /// Samples per Welch segment (periodic Hann, 50 % overlap).
    pub segment_samples: usize,
    /// Segments averaged over the records.
    pub segments: usize,
    /// The records pooled.
    pub records: usize,
    /// The peaks, lowest first.
    pub peaks: Vec<TransmissibilityPeak>,
    /// Each identified mode beside its nearest peak.
    pub mode_checks: Vec<ModeCheck>,
    /// Identified modes further than [`MODE_TOLERANCE`] from the records' peak.
    pub warnings: Vec<String>,
}

/// The Welch segment for records of these lengths at `rate_hz`: the largest power of two no
/// longer than two thirds of the shortest record (two overlapping segments in each) and than
/// `f_s/`[`RESOLUTION_HZ`]; `None` below [`MIN_SEGMENT`].
pub fn segment_samples(shortest: usize, rate_hz: f64) -> Option<usize> {
    let cap = ((2 * shortest) / 3).min((rate_hz / RESOLUTION_HZ) as usize);
    if cap < MIN_SEGMENT {
        return None;
    }
    Some(1usize << (usize::BITS - 1 - cap.leading_zeros()))
}

/// The roof's transmissibility over the `fitted` records that carry the table's and the
/// storeys' accelerations (`modes`, the identified ones, lowest first, are checked against
/// its peaks); `None` without such records or when they are too short.
pub(crate) fn transmissibility(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    modes: &[(f64, f64)],
) -> Option<Transmissibility> {
    let with: Vec<usize> = fitted
        .iter()
        .copied()
        .filter(|&i| records[i].a_m_s2.is_some() && !records[i].storey_a_m_s2.is_empty())
        .collect();
    let storeys = with.iter().map(|&i| records[i].storey_a_m_s2.len()).min()?;
    let h = periods[*with.first()?];
    // Records at other rates would put their bins elsewhere: only the first's rate pooled.
    let with: Vec<usize> = with
        .into_iter()
        .filter(|&i| (periods[i] / h - 1.0).abs() < 1e-9)
        .collect();
    let shortest = with.iter().map(|&i| records[i].t_s.len()).min()?;
    let rate_hz = 1.0 / h;
    let len = segment_samples(shortest, rate_hz)?;
    let welch = platen_signal::Welch::new(len, rate_hz).ok()?;
    let parts: Vec<platen_signal::CrossSpectra> = with
        .iter()
        .map(|&i| {
            let r = &records[i];
            welch
                .cross(r.a_m_s2.as_deref()?, &r.storey_a_m_s2[storeys - 1])
                .ok()
        })
        .collect::<Option<_>>()?;
    let pooled = platen_signal::CrossSpectra::pooled(&parts)?;
    let gain = pooled.transfer();
    let coherence = pooled.coherence();
    let df = pooled.resolution_hz();
    let hi_hz = HIGHEST_PEAK_HZ.min(HIGHEST_PEAK_FRACTION * rate_hz);
    let lo = ((LOWEST_PEAK_HZ / df).ceil() as usize).max(1);
    let hi = ((hi_hz / df).floor() as usize).min(gain.len() - 2);
    let maxima = distinct_peaks(&gain, lo, hi, storeys);
    let peaks: Vec<TransmissibilityPeak> = maxima
        .iter()
        .map(|&k| peak(&gain, k, df, coherence[k]))
        .collect();
    let (mode_checks, warnings) = check_modes(modes, &peaks, df);
    Some(Transmissibility {
        resolution_hz: df,
        segment_samples: len,
        segments: pooled.segments(),
        records: with.len(),
        peaks,
        mode_checks,
        warnings,
    })
}

/// The identified `modes` (frequency, damping ratio; lowest first) each against the nearest
/// of the transmissibility's `peaks` (bins of `df` Hz), and a warning for each farther than
/// [`MODE_TOLERANCE`].
fn check_modes(
    modes: &[(f64, f64)],
    peaks: &[TransmissibilityPeak],
    df: f64,
) -> (Vec<ModeCheck>, Vec<String>) {
    let mut mode_checks = Vec::new();
    let mut warnings = Vec::new();
    for &(f, zeta) in modes {
        let Some(p) = peaks.iter().min_by(|a, b| {
            (a.frequency_hz - f)
                .abs()
                .total_cmp(&(b.frequency_hz - f).abs())
        }) else {
            break;
        };
        let rel = f / p.frequency_hz - 1.0;
        mode_checks.push(ModeCheck {
            identified_hz: f,
            transmissibility_hz: p.frequency_hz,
            relative_difference: rel,
            identified_damping_ratio: zeta,
            half_power_damping_ratio: p.half_power_damping_ratio,
        });
        if rel.abs() > MODE_TOLERANCE {
            warnings.push(format!(
                "the identified specimen mode at {f:.3} Hz is {:+.1} % from the records' own \
                 transmissibility peak at {:.3} Hz (roof over table, Welch, {df:.4} Hz bins): \
                 the identified storeys do not move as the recorded frame does",
                100.0 * rel,
                p.frequency_hz
            ));
        }
    }
    (mode_checks, warnings)
}

/// The `count` tallest distinct resonances of `gain` between bins `lo` and `hi`, lowest first:
/// local maxima, tallest first, each kept only if `gain` falls below half the lower of it
/// and every peak already kept somewhere between the two (noise splits one resonance into
/// neighbouring maxima; two resonances are told apart by the valley between them).
fn distinct_peaks(gain: &[f64], lo: usize, hi: usize, count: usize) -> Vec<usize> {
    let mut maxima: Vec<usize> = (lo..=hi)
        .filter(|&k| gain[k] > gain[k - 1] && gain[k] >= gain[k + 1])
        .collect();
    maxima.sort_by(|&a, &b| gain[b].total_cmp(&gain[a]).then(a.cmp(&b)));
    let mut kept: Vec<usize> = Vec::new();
    for k in maxima {
        if kept.len() == count {
            break;
        }
        let apart = kept.iter().all(|&p| {
            let (a, b) = (p.min(k), p.max(k));
            let valley = gain[a..=b].iter().copied().fold(f64::INFINITY, f64::min);
            valley < 0.5 * gain[p].min(gain[k])
        });
        if apart {
            kept.push(k);
        }
    }
    kept.sort_unstable();
    kept
}

/// The peak of `gain` at bin `k` (spacing `df`), located and measured ([module docs](self)).
fn peak(gain: &[f64], k: usize, df: f64, coherence: f64) -> TransmissibilityPeak {
    let ln = |j: usize| gain[j].max(f64::MIN_POSITIVE).ln();
    let (ym, y0, yp) = (ln(k - 1), ln(k), ln(k + 1));
    let curv = ym - 2.0 * y0 + yp;
    let offset = if curv < 0.0 {
        (0.5 * (ym - yp) / curv).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let f = (k as f64 + offset) * df;
    let half = gain[k] / std::f64::consts::SQRT_2;
    // Where |H| crosses `half` going down from the peak on each side, in bins (linear).
    let below = |j: usize, towards: usize| {
        let (a, b) = (gain[j], gain[towards]);
        j as f64 + (towards as f64 - j as f64) * ((a - half) / (a - b)).clamp(0.0, 1.0)
    };
    let mut left = None;
    let mut j = k;
    while j > 0 {
        if gain[j - 1] <= half {
            left = Some(below(j, j - 1));
            break;
        }
        j -= 1;
    }
    let mut right = None;
    let mut j = k;
    while j + 1 < gain.len() {
        if gain[j + 1] <= half {
            right = Some(below(j, j + 1));
            break;
        }
        j += 1;
    }
    let width_bins = match (left, right) {
        (Some(l), Some(r)) => r - l,
        _ => f64::INFINITY,
    };
    TransmissibilityPeak {
        frequency_hz: f,
        bin_frequency_hz: k as f64 * df,
        magnitude: gain[k],
        half_power_damping_ratio: width_bins * df / (2.0 * f),
        damping_resolved: width_bins >= RESOLVED_BINS && width_bins.is_finite(),
        coherence,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_are_powers_of_two_within_the_records() {
        // 3300 samples at 204.8 Hz: two thirds is 2200, so 2048 (0.1 Hz bins).
        assert_eq!(segment_samples(3300, 204.8), Some(2048));
        // Long records stop at the finest resolution sought: 204.8/0.0125 = 16384.
        assert_eq!(segment_samples(100_000, 204.8), Some(16384));
        assert_eq!(segment_samples(300, 204.8), None);
    }

    #[test]
    fn a_resonance_split_by_noise_is_one_peak() {
        // Two maxima a bin apart (one resonance, noisy) and a second resonance beyond a
        // valley: the tallest of the first pair and the second.
        let g = [0.1, 0.2, 5.0, 4.0, 5.5, 1.0, 0.3, 0.2, 2.0, 0.4, 0.1];
        assert_eq!(distinct_peaks(&g, 1, 9, 2), vec![4, 8]);
        assert_eq!(distinct_peaks(&g, 1, 9, 1), vec![4]);
    }

    #[test]
    fn a_gaussian_peak_is_located_between_bins() {
        // ln|H| a parabola: the vertex exactly.
        let g: Vec<f64> = (0..40)
            .map(|k| (-(k as f64 - 17.3).powi(2) / 8.0).exp())
            .collect();
        let p = peak(&g, 17, 0.1, 1.0);
        assert!((p.frequency_hz - 1.73).abs() < 1e-12, "{}", p.frequency_hz);
        assert_eq!(p.bin_frequency_hz, 1.7000000000000002);
        // Half power at ln 2 / 2 below the peak's log: |k − 17.3| = √(4 ln 2) = 1.665,
        // width 3.33 bins (linear interpolation between bins overstates it a little): fewer
        // than RESOLVED_BINS, so a bound.
        assert!(!p.damping_resolved);
        let width = 2.0 * p.frequency_hz * p.half_power_damping_ratio / 0.1;
        assert!((width - 3.33).abs() < 0.15, "{width}");
    }
}
