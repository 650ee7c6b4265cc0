//! Do the stated 95 % intervals of the any-record method cover the truth? 50 records: the
//! five noise-free truths `coverage-K.csv` of the independent NumPy reference (earthquake-like
//! and white-noise tests of a table that is not the paper's, 30 s at 204.8 Hz each), each
//! with ten seeded realisations of the lab's noise (white noise on displacement and
//! acceleration, white plus AR(1) noise with ρ = 0.97 on the force: correlated residuals)
//! and the lab's offsets. Each parameter's interval, and the band of the dissipative law at
//! five speeds per record, must cover the truth in at least 90 % of the records.
//!
//! Measured (release build, this commit): Mₑ 50/50, Kₑ 46, F_μ 46, Cₑ 48, α 46, a 46, b 45;
//! the band 242 of 250 checks. With 12 s records (the first version) Kₑ, α and b covered in
//! only 43–45 of 50: the batch-means blocks must be long against the platen's 0.5 Hz mode,
//! and 12 s holds too few of them.

mod lab;

use platen_ident::{identify_records, IdentifiedKey, RecordSettings};

/// Records in the study (30 s each).
const RECORDS: usize = 50;

/// The requirement: the 95 % intervals cover the truth in at least 90 % of the
/// records. (With 50 records and a true rate of 95 %, fewer than 45 covered has a
/// probability of 3.8 %: the check is loose enough not to fail by chance and tight enough
/// to catch intervals that are too narrow by 30 % or more, whose rate drops to ~83 %.)
const MIN_COVERAGE: f64 = 0.90;

#[test]
fn the_95_percent_intervals_cover_the_truth_in_at_least_90_percent_of_50_records() {
    let settings = RecordSettings {
        output_error: false,
        ..RecordSettings::default()
    }
    .build()
    .unwrap();
    // Two threads (CI has two cores); each record's result is kept in order.
    let results: Vec<_> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..2)
            .map(|part| {
                let settings = &settings;
                scope.spawn(move || {
                    (0..RECORDS)
                        .filter(|n| n % 2 == part)
                        .map(|n| {
                            let rec = lab::coverage_record(n % 5, 1000 + n as u64);
                            (n, identify_records(&[rec], settings).unwrap())
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        let mut all: Vec<_> = handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect();
        all.sort_by_key(|(n, _)| *n);
        all
    });
    let mut covered = [0usize; 7];
    let mut estimated = [0usize; 7];
    let (mut band_checked, mut band_covered) = (0, 0);
    let law = lab::true_law();
    for (_, id) in &results {
        for (k, (key, p)) in id.parameters.iter().enumerate() {
            if let Some(e) = p.estimate() {
                estimated[k] += 1;
                let truth = lab::true_value(key);
                if e.ci95_low <= truth && truth <= e.ci95_high {
                    covered[k] += 1;
                }
            }
        }
        // The band at five speeds spread over the speeds each record reaches.
        for p in id.band.iter().step_by(10) {
            band_checked += 1;
            let truth = law.smooth_magnitude_n(p.speed_m_s);
            if p.low_n <= truth && truth <= p.high_n {
                band_covered += 1;
            }
        }
    }
    for (k, key) in IdentifiedKey::ALL.into_iter().enumerate() {
        println!(
            "{:28} estimated in {:2}/{RECORDS}, covered in {:2}",
            key.name(),
            estimated[k],
            covered[k]
        );
    }
    println!("F_D band covered in {band_covered}/{band_checked} checks");
    assert!(
        band_covered as f64 >= MIN_COVERAGE * band_checked as f64,
        "the 95 % band of F_D covers the true law in {band_covered} of {band_checked} checks"
    );
    for (k, key) in IdentifiedKey::ALL.into_iter().enumerate() {
        let rate = covered[k] as f64 / RECORDS as f64;
        assert!(
            rate >= MIN_COVERAGE,
            "{}: the 95 % interval covers the truth in {} of {RECORDS} records",
            key.name(),
            covered[k]
        );
    }
}
