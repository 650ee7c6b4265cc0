//! Inputs whose magnitude betrays a unit mistake.
//!
//! A number in the wrong unit still parses: 13.8e6 given where MPa is asked (Pa), a force
//! record in kN read as N, a displacement in mm read as m. Where no sensible reading exists the
//! input is refused; where one does, the run goes on with a warning (see
//! [`crate::RunSummary`]'s `warnings`).
//!
//! * A pressure in MPa above [`MAX_PRESSURE_MPA`] is refused ([`check_pressure_mpa`]): a
//!   table's hold-down or supply pressure is tens of MPa, and 100 MPa is beyond any hydraulic
//!   service pressure, while the usual slips (Pa, kPa, bar, psi) give 10⁵–10⁷ "MPa".
//! * A displacement record beyond [`MAX_STROKE_MULTIPLE`] times the table's stroke is refused
//!   ([`check_displacement_record`]): between one and ten strokes a run still answers "what
//!   would this table need" (the summary reports the exceeded limit), but a table ten strokes
//!   away from centre has no reading at all, and mm read as m multiplies by 1000.
//! * A force record whose peak stays below the breakaway force leaves the platen stuck for the
//!   whole run: it runs, with a warning that names the peak and the breakaway force.

use std::path::Path;

use platen_io::IoError;

/// The largest pressure accepted where MPa is asked, MPa.
pub const MAX_PRESSURE_MPA: f64 = 100.0;

/// A displacement record may reach this many times the table's stroke; beyond, it is refused.
pub const MAX_STROKE_MULTIPLE: f64 = 10.0;

/// A large number spelled as a mantissa and a power of ten that is a multiple of 3 (`13.8e6`),
/// as a user who typed it in another unit would recognise it.
pub fn spelled(x: f64) -> String {
    if !(x.is_finite() && x.abs() >= 1e4) {
        return format!("{x}");
    }
    let k = (x.abs().log10() / 3.0).floor() as i32 * 3;
    let m = x / 10f64.powi(k);
    // Six significant digits at most: the spelling of a typed number, not of its binary value.
    let m = (m * 1e4).round() / 1e4;
    format!("{m}e{k}")
}

/// Checks a pressure given in MPa (a `--pressure-mpa` option, a `pressure_mpa` or
/// `hold_down_pressure_mpa` key): finite, ≥ 0 and at most [`MAX_PRESSURE_MPA`].
///
/// # Errors
/// The value as typed and [`expected_pressure_mpa`]'s explanation.
pub fn check_pressure_mpa(p: f64) -> Result<f64, String> {
    match expected_pressure_mpa(p) {
        None => Ok(p),
        Some(expected) => Err(format!("{}: expected {expected}", spelled(p))),
    }
}

/// What a pressure `p` given in MPa should have been, or `None` if it is fine: for a pressure
/// above [`MAX_PRESSURE_MPA`], the unit it looks like it was given in and the value that unit
/// would mean in MPa.
pub fn expected_pressure_mpa(p: f64) -> Option<String> {
    if !(p.is_finite() && p >= 0.0) {
        return Some("a pressure >= 0 MPa".into());
    }
    if p <= MAX_PRESSURE_MPA {
        return None;
    }
    let looks_like = if p >= 1e5 {
        format!("Pa ({} MPa)", p / 1e6)
    } else if p >= 1e3 {
        format!("kPa ({} MPa) or psi ({:.2} MPa)", p / 1e3, p * 6.894_757e-3)
    } else {
        format!("bar ({} MPa)", p / 10.0)
    };
    Some(format!(
        "a pressure in MPa, at most {MAX_PRESSURE_MPA} MPa (MPa is expected; no table runs \
         above {MAX_PRESSURE_MPA} MPa): {} looks like {looks_like}",
        spelled(p)
    ))
}

/// Refuses a displacement record (a motion's `u_m`, a closed loop's command) that goes beyond
/// [`MAX_STROKE_MULTIPLE`] times `stroke_m`: `path` names the file, and the sample's line
/// assumes one header line and one sample per line, as a CSV has.
///
/// # Errors
/// [`IoError::Record`] naming the peak, its line and time, the stroke, and the likely slip.
pub fn check_displacement_record(
    path: &Path,
    t_s: &[f64],
    u_m: &[f64],
    stroke_m: f64,
) -> Result<(), IoError> {
    // The first sample of the largest magnitude.
    let Some((i, &peak)) = u_m
        .iter()
        .enumerate()
        .reduce(|a, b| if b.1.abs() > a.1.abs() { b } else { a })
    else {
        return Ok(());
    };
    let limit = MAX_STROKE_MULTIPLE * stroke_m;
    if peak.abs() <= limit || !stroke_m.is_finite() {
        return Ok(());
    }
    Err(IoError::Record {
        path: path.to_owned(),
        message: format!(
            "line {}, column u_m: the displacement reaches {peak} m at {} s, {:.0} times the \
             table's stroke of ±{stroke_m} m (more than {MAX_STROKE_MULTIPLE} times is refused: \
             no table reading exists). A record in mm read as m? Map its unit, e.g. \
             \"columns\": {{\"u_m\": {{\"unit\": \"mm\"}}}} ({} m in mm is {} m)",
            i + 2,
            t_s.get(i).copied().unwrap_or(f64::NAN),
            peak.abs() / stroke_m,
            peak,
            peak / 1e3
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_numbers_are_spelled_as_typed() {
        assert_eq!(spelled(13.8e6), "13.8e6");
        assert_eq!(spelled(13_800.0), "13.8e3");
        assert_eq!(spelled(2e5), "200e3");
        assert_eq!(spelled(13.8), "13.8");
    }

    #[test]
    fn pressures_in_other_units_are_refused_with_their_reading() {
        assert_eq!(check_pressure_mpa(13.8), Ok(13.8));
        assert_eq!(check_pressure_mpa(100.0), Ok(100.0));
        let e = check_pressure_mpa(13.8e6).unwrap_err();
        assert!(
            e.contains("MPa is expected") && e.contains("13.8e6 looks like Pa (13.8 MPa)"),
            "{e}"
        );
        let e = check_pressure_mpa(138.0).unwrap_err();
        assert!(e.contains("bar (13.8 MPa)"), "{e}");
        // 2000 psi = 13.79 MPa.
        let e = check_pressure_mpa(2000.0).unwrap_err();
        assert!(e.contains("psi (13.79 MPa)"), "{e}");
        assert!(check_pressure_mpa(-1.0).unwrap_err().contains(">= 0"));
        assert!(check_pressure_mpa(f64::NAN).is_err());
    }
}
