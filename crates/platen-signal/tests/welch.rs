//! Welch power spectral density.

mod common;

use common::{sine, Rng};
use platen_signal::{SignalError, Welch};

/// `scipy.signal.welch(x, fs=100.0, nperseg=16)` (SciPy 1.17) for
/// `x[j] = sin(0.3j) + 0.1·(j mod 7)`, 64 samples: the same definition (periodic Hann, 50 %
/// overlap, constant detrend, one-sided density), computed independently; 1e-15 relative.
#[test]
fn matches_scipy_welch_on_a_deterministic_record() {
    let x: Vec<f64> = (0..64)
        .map(|j| (0.3 * j as f64).sin() + 0.1 * (j % 7) as f64)
        .collect();
    let psd = Welch::new(16, 100.0).unwrap().estimate(&x).unwrap();
    let scipy = [
        9.696_840_394_998_138e-3,
        3.621_848_370_317_047_6e-2,
        9.322_925_285_503_849e-3,
        1.419_423_900_220_168_8e-3,
        5.846_986_960_710_507e-4,
        6.889_879_348_489_978e-4,
        2.507_154_316_608_934e-4,
        5.425_160_385_797_928e-4,
        8.849_790_308_395_02e-5,
    ];
    assert_eq!(psd.density().len(), scipy.len());
    assert_eq!(psd.segments(), 7);
    for (k, (p, e)) in psd.density().iter().zip(scipy).enumerate() {
        assert!((p - e).abs() < 1e-13 * e, "bin {k}: {p} vs SciPy {e}");
        assert_eq!(psd.frequency_hz(k), 6.25 * k as f64);
    }
}

/// Seeded white noise, σ = 0.3, 2¹⁸ samples at 1024 Hz, segments of 1024 (511 segments):
/// * the level is flat at `σ²/(f_s/2) = 1.758e-4` per Hz: the mean over bins 1..511 within 1 %
///   (each bin averages ~511 overlapping segments, relative scatter ≈ 1/√(0.95·511) ≈ 4.6 %; the
///   mean of ~511 such bins scatters by ≈ 0.2 %), every 32-bin band within 5 % (scatter ≈ 0.8 %),
///   every single bin within 25 % (5.4 scatters);
/// * `∫PSD df` equals the record's variance within 0.5 % and σ² within 1 % (the sample
///   variance of 2¹⁸ normal draws scatters by √(2/n) = 0.28 %);
/// * `rms_in_band(0, ∞)` is the standard deviation, and `rms_in_band` over half the band is
///   `σ/√2` within 1 %.
#[test]
fn white_noise_is_flat_at_sigma_squared_over_half_the_rate_and_integrates_to_the_variance() {
    let (fs, sigma) = (1024.0, 0.3);
    let x = Rng::new(7).white(1 << 18, sigma);
    let psd = Welch::new(1024, fs).unwrap().estimate(&x).unwrap();
    let level = sigma * sigma / (fs / 2.0);
    let inner = &psd.density()[1..512];
    let mean = inner.iter().sum::<f64>() / inner.len() as f64;
    assert!(
        (mean / level - 1.0).abs() < 0.01,
        "mean level {mean} vs {level}"
    );
    for (b, band) in inner.chunks(32).enumerate() {
        let m = band.iter().sum::<f64>() / band.len() as f64;
        assert!((m / level - 1.0).abs() < 0.05, "band {b}: {m} vs {level}");
    }
    for (k, p) in inner.iter().enumerate() {
        assert!(
            (p / level - 1.0).abs() < 0.25,
            "bin {}: {p} vs {level}",
            k + 1
        );
    }
    let n = x.len() as f64;
    let mean_x = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean_x).powi(2)).sum::<f64>() / n;
    assert!(
        (psd.variance() / var - 1.0).abs() < 0.005,
        "{} vs {var}",
        psd.variance()
    );
    assert!((psd.variance() / (sigma * sigma) - 1.0).abs() < 0.01);
    let total = psd.rms_in_band(0.0, f64::INFINITY).unwrap();
    assert!((total - psd.variance().sqrt()).abs() < 1e-15);
    let half = psd.rms_in_band(0.0, 256.0).unwrap();
    assert!(
        (half / (sigma / 2f64.sqrt()) - 1.0).abs() < 0.01,
        "half band rms {half}"
    );
}

/// A sine of amplitude A on a bin frequency (10 whole cycles per segment) has RMS `A/√2`; the
/// Hann window spreads it over three bins, all inside the ±2-bin band, so `rms_in_band` around
/// it recovers `A/√2` within 0.1 %, and a band away from it holds nothing (< 1e-6).
#[test]
fn rms_in_band_recovers_a_sines_rms() {
    let fs = 256.0;
    let x = sine(8192, fs, 10.0, 2.0, 0.3);
    let psd = Welch::new(256, fs).unwrap().estimate(&x).unwrap();
    let rms = psd.rms_in_band(8.0, 12.0).unwrap();
    assert!((rms / 2f64.sqrt() - 1.0).abs() < 1e-3, "rms {rms}");
    assert!(psd.rms_in_band(20.0, 100.0).unwrap() < 1e-6);
}

#[test]
fn bad_plans_records_and_bands_are_rejected() {
    assert!(matches!(
        Welch::new(3, 100.0),
        Err(SignalError::InvalidCount {
            name: "segment_len",
            value: 3,
            ..
        })
    ));
    let w = Welch::new(64, 100.0).unwrap();
    assert!(matches!(
        w.estimate(&[0.0; 63]),
        Err(SignalError::RecordTooShort {
            found: 63,
            min: 64,
            ..
        })
    ));
    let psd = w.estimate(&[1.0; 64]).unwrap();
    assert!(psd.density().iter().all(|p| p.abs() < 1e-30));
    assert!(psd.rms_in_band(5.0, 1.0).is_err());
    assert!(psd.rms_in_band(-1.0, 1.0).is_err());
    assert!(psd.rms_in_band(0.0, f64::NAN).is_err());
}

/// The cross-spectrum against SciPy 1.17, computed independently:
/// `abs(scipy.signal.csd(x, y, fs=100, nperseg=16)[1]) / scipy.signal.welch(x, …)[1]` and
/// `scipy.signal.coherence(x, y, …)` for `x[j] = sin(0.3j) + 0.1·(j mod 7)`,
/// `y[j] = cos(0.2j) + 0.05·(j mod 5)`, 64 samples; 1e-12 relative (a ratio of sums of
/// products: a few roundings more than the PSD's).
#[test]
fn the_transfer_and_coherence_match_scipy() {
    let j = |k: usize| k as f64;
    let x: Vec<f64> = (0..64)
        .map(|k| (0.3 * j(k)).sin() + 0.1 * (k % 7) as f64)
        .collect();
    let y: Vec<f64> = (0..64)
        .map(|k| (0.2 * j(k)).cos() + 0.05 * (k % 5) as f64)
        .collect();
    let cs = Welch::new(16, 100.0).unwrap().cross(&x, &y).unwrap();
    let transfer = [
        0.027479804205202893,
        0.05094818076073238,
        0.04968164666878032,
        0.04273375318667862,
        0.09240019493137626,
        0.05766075212221295,
        0.2469105883245937,
        0.07692537888211487,
        0.05473777628279591,
    ];
    let coherence = [
        0.00297768934418349,
        0.005191277643079688,
        0.013114518621563995,
        0.0063557804625873305,
        0.02986047925254299,
        0.2713997121657326,
        0.12639013549830924,
        0.035033381519388875,
        0.13080610770744955,
    ];
    assert_eq!(cs.segments(), 7);
    for (k, (got, want)) in cs.transfer().iter().zip(transfer).enumerate() {
        assert!(
            (got - want).abs() < 1e-12 * want,
            "bin {k}: {got} vs SciPy {want}"
        );
    }
    for (k, (got, want)) in cs.coherence().iter().zip(coherence).enumerate() {
        assert!(
            (got - want).abs() < 1e-12 * want,
            "bin {k}: {got} vs SciPy {want}"
        );
    }
    // Pooling a record with itself changes nothing; channels of unequal length are refused.
    let pooled = platen_signal::CrossSpectra::pooled(&[cs.clone(), cs.clone()]).unwrap();
    assert_eq!(pooled.transfer(), cs.transfer());
    assert_eq!(pooled.segments(), 14);
    assert!(matches!(
        Welch::new(16, 100.0).unwrap().cross(&x, &y[..63]),
        Err(SignalError::LengthMismatch { .. })
    ));
}

/// A pure gain: `|H₁| = 2` exactly and coherence 1 at every bin
/// with power (the closed form), to rounding.
#[test]
fn a_pure_gain_is_recovered_exactly() {
    let mut rng = Rng::new(42);
    let x: Vec<f64> = (0..4096).map(|_| rng.normal()).collect();
    let y: Vec<f64> = x.iter().map(|v| 2.0 * v).collect();
    let cs = Welch::new(256, 100.0).unwrap().cross(&x, &y).unwrap();
    for (k, (h, c)) in cs.transfer().iter().zip(cs.coherence()).enumerate().skip(1) {
        assert!((h - 2.0).abs() < 1e-12, "bin {k}: {h}");
        assert!((c - 1.0).abs() < 1e-12, "bin {k}: {c}");
    }
}
