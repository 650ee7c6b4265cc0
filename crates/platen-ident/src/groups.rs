//! Pressure groups: the tests of one hold-down pressure are analysed together, and the
//! final estimate belongs to the reference pressure.

use crate::error::{IdentError, Result};
use crate::record::TestRecord;
use crate::settings::ValidSettings;
use crate::warning::Warning;
use crate::work::Work;

/// Two pressures closer than 1 Pa are the same group.
const PRESSURE_TOLERANCE_PA: f64 = 1.0;

/// The pressure groups of an identification.
#[derive(Debug, Clone)]
pub(crate) struct Groups {
    /// Each group's pressure, Pa: tests without a pressure first, then by increasing pressure.
    pub(crate) keys: Vec<Option<f64>>,
    /// The group of the reference pressure.
    pub(crate) reference: usize,
}

/// Checks that the reference pressure of the settings, if any, is one of the tests'.
///
/// # Errors
/// [`IdentError::InvalidSetting`] for `reference_pressure_pa`.
pub(crate) fn check_reference(records: &[TestRecord], settings: &ValidSettings) -> Result<()> {
    if let Some(p) = settings.reference_pressure_pa {
        if !records.iter().any(|r| {
            r.pressure_pa()
                .is_some_and(|q| (q - p).abs() <= PRESSURE_TOLERANCE_PA)
        }) {
            return Err(IdentError::InvalidSetting {
                name: "reference_pressure_pa",
                value: p,
                expected: "the hold-down pressure of at least one test",
            });
        }
    }
    Ok(())
}

/// Groups the tests by pressure (setting each test's group) and finds the reference group:
/// the settings' pressure (checked by [`check_reference`]) or the highest.
pub(crate) fn group(
    work: &mut [Work],
    settings: &ValidSettings,
    warnings: &mut Vec<Warning>,
) -> Groups {
    let mut keys: Vec<Option<f64>> = Vec::new();
    for w in work.iter() {
        if !keys.iter().any(|k| same_pressure(*k, w.pressure)) {
            keys.push(w.pressure);
        }
    }
    keys.sort_by(|a, b| match (a, b) {
        (None, None) => std::cmp::Ordering::Equal,
        (None, Some(_)) => std::cmp::Ordering::Less,
        (Some(_), None) => std::cmp::Ordering::Greater,
        (Some(x), Some(y)) => x.total_cmp(y),
    });
    for w in work.iter_mut() {
        w.group = keys
            .iter()
            .position(|k| same_pressure(*k, w.pressure))
            .expect("every pressure has a group");
    }
    let reference = match settings.reference_pressure_pa {
        Some(p) => keys
            .iter()
            .position(|k| k.is_some_and(|q| (q - p).abs() <= PRESSURE_TOLERANCE_PA))
            .expect("checked by check_reference"),
        None => keys.len() - 1,
    };
    if keys.len() > 1 && keys[0].is_none() {
        warnings.push(Warning::TestsWithoutPressure {
            count: work.iter().filter(|w| w.pressure.is_none()).count(),
        });
    }
    Groups { keys, reference }
}

fn same_pressure(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(x), Some(y)) => (x - y).abs() <= PRESSURE_TOLERANCE_PA,
        _ => false,
    }
}
