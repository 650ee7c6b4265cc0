//! The sampling grid of a record read from a file.

use std::path::Path;

use platen_integrate::IntegrateError;
use platen_io::IoError;

/// Sample interval of the uniformly sampled time column `t_s` read from `path`, s.
///
/// The interval is the mean one, `(t_last − t_first) / (n − 1)`. Every interval must match the
/// median interval within [`platen_integrate::UNIFORM_RELATIVE_TOLERANCE`] (0.1 %), else
/// [`NonUniform`](IoError::NonUniform) names the line that ends the odd interval; intervals
/// that are not positive give [`TimeNotIncreasing`](IoError::TimeNotIncreasing). Fewer
/// than 2 samples give [`TooShort`](IoError::TooShort). `path` is used for messages only;
/// line numbers assume the header on line 1 and one sample per line (sample `i`, 0-based, on
/// line `i + 2`).
pub fn uniform_step_s(path: &Path, t_s: &[f64]) -> Result<f64, IoError> {
    platen_integrate::uniform_interval_s(t_s).map_err(|e| match e {
        IntegrateError::TooShort { found, needed } => IoError::TooShort {
            path: path.to_path_buf(),
            rows: found,
            needed,
        },
        IntegrateError::NonUniform { index, found_s, .. } if found_s <= 0.0 => {
            IoError::TimeNotIncreasing {
                path: path.to_path_buf(),
                line: index as u64 + 2,
                previous_s: t_s[index - 1],
                value_s: t_s[index],
            }
        }
        IntegrateError::NonUniform {
            index,
            expected_s,
            found_s,
        } => IoError::NonUniform {
            path: path.to_path_buf(),
            line: index as u64 + 2,
            expected_s,
            found_s,
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
