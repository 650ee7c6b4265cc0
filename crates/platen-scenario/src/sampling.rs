//! The sampling grid of a record read from a file.

use std::path::Path;

use platen_integrate::{IntegrateError, SamplingGrid};
use platen_io::IoError;

/// Sample interval of the uniformly sampled time column `t_s` read from `path`, s: the interval
/// of the grid fitted over the whole record ([`sampling_grid`]). Every verb reads its records'
/// time columns through this one check.
///
/// # Errors
/// As [`sampling_grid`].
pub fn uniform_step_s(path: &Path, t_s: &[f64]) -> Result<f64, IoError> {
    sampling_grid(path, t_s).map(|grid| grid.interval_s)
}

/// The sampling grid fitted to the time column `t_s` read from `path`
/// ([`platen_integrate::sampling_grid`]): stamps may be off the grid by up to
/// [`platen_integrate::UNIFORM_RELATIVE_TOLERANCE`] (10 %) of the interval (rounded stamps),
/// and the record is then used on the grid.
///
/// # Errors
/// [`NonUniform`](IoError::NonUniform) naming the line that ends an interval more than 20 %
/// off the typical one (a dropped sample, a jump); [`OffGrid`](IoError::OffGrid) naming the
/// first line whose stamp is more than 10 % of the interval off the fitted grid (jitter, a
/// change of rate); [`TimeNotIncreasing`](IoError::TimeNotIncreasing); fewer than 2 samples
/// give [`TooShort`](IoError::TooShort). `path` is used for messages only; line numbers assume
/// the header on line 1 and one sample per line (sample `i`, 0-based, on line `i + 2`).
pub fn sampling_grid(path: &Path, t_s: &[f64]) -> Result<SamplingGrid, IoError> {
    let line = |index: usize| index as u64 + 2;
    platen_integrate::sampling_grid(t_s).map_err(|e| match e {
        IntegrateError::TooShort { found, needed } => IoError::TooShort {
            path: path.to_path_buf(),
            rows: found,
            needed,
        },
        IntegrateError::TimeNotIncreasing {
            index,
            previous_s,
            value_s,
        } => IoError::TimeNotIncreasing {
            path: path.to_path_buf(),
            line: line(index),
            previous_s,
            value_s,
        },
        IntegrateError::NonFiniteInput { index, value, .. } => IoError::NonFinite {
            path: path.to_path_buf(),
            line: line(index),
            column: "t_s".to_owned(),
            value: value.to_string(),
        },
        IntegrateError::NonUniform {
            index,
            expected_s,
            found_s,
        } => IoError::NonUniform {
            path: path.to_path_buf(),
            line: line(index),
            expected_s,
            found_s,
        },
        IntegrateError::OffGrid {
            index,
            grid_s,
            found_s,
            interval_s,
        } => IoError::OffGrid {
            path: path.to_path_buf(),
            line: line(index),
            grid_s,
            found_s,
            interval_s,
        },
        other => IoError::Record {
            path: path.to_path_buf(),
            message: other.to_string(),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_of_a_uniform_time_column_is_its_mean_interval() {
        let t: Vec<f64> = (0..10_000).map(|i| i as f64 / 1024.0).collect();
        let step = uniform_step_s(Path::new("rec.csv"), &t).unwrap();
        assert_eq!(step, 1.0 / 1024.0);

        let t: Vec<f64> = (0..3_600_000).map(|i| i as f64 * 0.001).collect();
        let step = uniform_step_s(Path::new("rec.csv"), &t).unwrap();
        assert!((step - 0.001).abs() < 1e-15);
    }

    #[test]
    fn a_non_uniform_time_column_is_reported_with_the_line_of_the_odd_interval() {
        let t = [0.0, 0.01, 0.02, 0.035, 0.04];
        let error = uniform_step_s(Path::new("irregular.csv"), &t).unwrap_err();
        let message = error.to_string();
        assert!(
            matches!(error, IoError::NonUniform { line: 5, expected_s, found_s, .. }
                if expected_s == 0.01 && (found_s - 0.015).abs() < 1e-15),
            "{error:?}"
        );
        assert!(
            message.contains("irregular.csv")
                && message.contains("line 5")
                && message.contains("`t_s`"),
            "{message}"
        );
        let error = uniform_step_s(Path::new("back.csv"), &[0.0, 1.0, 1.0, 3.0]).unwrap_err();
        assert!(
            matches!(error, IoError::TimeNotIncreasing { line: 4, .. }),
            "{error:?}"
        );
    }

    /// 300 s at 204.8 Hz with the stamps printed to 1e-5 s (5 decimals), as a lab's data
    /// system writes them: every stamp is within 5e-6 s (0.1 % of the interval) of the true
    /// grid, and intervals alternate between 0.00488 s and 0.00489 s.
    fn rounded_204_8_hz(seconds: f64) -> Vec<f64> {
        let n = (seconds * 204.8) as usize + 1;
        (0..n)
            .map(|i| ((i as f64 / 204.8) * 1e5).round() / 1e5)
            .collect()
    }

    #[test]
    fn stamps_rounded_to_ten_microseconds_over_300_s_at_204_8_hz_fit_the_true_interval() {
        let t = rounded_204_8_hz(300.0);
        let grid = sampling_grid(Path::new("lab.csv"), &t).unwrap();
        // The least-squares slope of 61 441 stamps each rounded by at most 5e-6 s: the fitted
        // interval is within 1e-11 s of 1/204.8 s (the bound 2·5e-6/61 440 = 1.6e-10 s of a
        // line through two rounded stamps; NumPy's `polyfit` on the same stamps: 2.5e-15 s).
        let exact = 1.0 / 204.8;
        assert!(
            (grid.interval_s - exact).abs() < 1e-11,
            "{} against {exact}",
            grid.interval_s
        );
        assert!(grid.max_deviation_s <= 5.0e-6 + 1e-12, "{grid:?}");
        assert!(grid.start_s.abs() < 5e-6, "{grid:?}");
        // An RK4 step of Δt/2 and Δt/4 divides the fitted interval; a step that is 1e-6
        // relative off does not (over 61 440 intervals it drifts 0.3 ms off the grid).
        assert_eq!(grid.steps_per_interval(exact / 2.0).unwrap(), 2);
        assert_eq!(grid.steps_per_interval(exact / 4.0).unwrap(), 4);
        assert!(grid.steps_per_interval(exact / 2.0 * (1.0 + 1e-6)).is_err());
        assert!(grid.steps_per_interval(0.003).is_err());
    }

    #[test]
    fn exact_stamps_give_the_interval_to_the_bit_and_a_step_must_divide_it_to_1e_9() {
        let t: Vec<f64> = (0..5000).map(|i| i as f64 / 1024.0).collect();
        let grid = sampling_grid(Path::new("rec.csv"), &t).unwrap();
        assert_eq!(grid.interval_s, 1.0 / 1024.0);
        assert_eq!(grid.start_s, 0.0);
        assert_eq!(grid.max_deviation_s, 0.0);
        assert_eq!(grid.steps_per_interval(1.0 / 8192.0).unwrap(), 8);
        assert!(grid
            .steps_per_interval(1.0 / 8192.0 * (1.0 + 1e-8))
            .is_err());
    }

    #[test]
    fn a_dropped_sample_in_a_long_rounded_record_is_reported_at_its_line() {
        let mut t = rounded_204_8_hz(300.0);
        t.remove(30_000); // the interval ending at old sample 30 001 (now index 30 000) doubles
        let error = uniform_step_s(Path::new("gap.csv"), &t).unwrap_err();
        assert!(
            matches!(error, IoError::NonUniform { line: 30_002, found_s, .. }
                if (found_s - 2.0 / 204.8).abs() < 2e-5),
            "{error:?}"
        );
        assert!(error.to_string().contains("gap.csv"), "{error}");
    }

    #[test]
    fn a_stamp_off_the_grid_by_more_than_a_tenth_of_the_interval_is_jitter_at_its_line() {
        // 15 % of an interval: each interval next to it changes by 15 % (< 20 %, so the
        // interval check passes), the stamp itself is 15 % off the fitted grid.
        let mut t: Vec<f64> = (0..2000).map(|i| i as f64 * 0.01).collect();
        t[700] += 0.0015;
        let error = uniform_step_s(Path::new("jitter.csv"), &t).unwrap_err();
        assert!(
            matches!(error, IoError::OffGrid { line: 702, grid_s, .. }
                if (grid_s - 7.0).abs() < 1e-6),
            "{error:?}"
        );
        assert!(error.to_string().contains("line 702"), "{error}");
        // 9 % is rounding-sized: accepted, and the grid is the true one.
        t[700] = 7.0009;
        let grid = sampling_grid(Path::new("jitter.csv"), &t).unwrap();
        assert!((grid.interval_s - 0.01).abs() < 1e-9, "{grid:?}");
    }

    #[test]
    fn a_change_of_rate_inside_the_record_leaves_stamps_off_the_fitted_grid() {
        // 100 Hz, then 100.5 Hz: every interval is within 0.5 % of the median, but the stamps
        // drift 5 intervals apart over the second half.
        let mut t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.01).collect();
        let t_mid = t[999];
        t.extend((1..1000).map(|i| t_mid + i as f64 / 100.5));
        let error = uniform_step_s(Path::new("rates.csv"), &t).unwrap_err();
        assert!(matches!(error, IoError::OffGrid { .. }), "{error:?}");
    }

    #[test]
    fn a_time_column_with_fewer_than_two_samples_is_too_short() {
        for t in [&[][..], &[0.0][..]] {
            let error = uniform_step_s(Path::new("one.csv"), t).unwrap_err();
            assert!(
                matches!(error, IoError::TooShort { rows, needed: 2, .. } if rows == t.len()),
                "{error:?}"
            );
            assert!(error.to_string().contains("one.csv"));
        }
    }
}
