//! PEER NGA strong-motion records (`.AT2` acceleration, `.VT2` velocity, `.DT2` displacement).
//!
//! Layout: four header lines, then values in free format (five per line, Fortran `E`
//! notation such as `.7134740E-03`):
//!
//! 1. `PEER NGA STRONG MOTION DATABASE RECORD`
//! 2. event, date, station, component
//! 3. quantity and units: `ACCELERATION TIME SERIES IN UNITS OF G`, `VELOCITY … CM/S`,
//!    `DISPLACEMENT … CM`
//! 4. `NPTS=   2000, DT=   .0200 SEC`, in any of the variants seen in the NGA files:
//!    a trailing comma, spaces around `=` and `,` (`NPTS =   7500 , DT =   .020 SEC ,`), or
//!    filter information after `DT` (`…, DT=   .0100 SEC,   0 POLE @ 30.00000 HZ, …`).
//!
//! Values are converted to SI (m/s², m/s, m) with `g = 9.80665 m/s²`.
//!
//! The records themselves are not shipped with platen: scenarios name them by file name and
//! they are looked up in the folder given by the `PLATEN_RECORDS_DIR` environment variable
//! ([`find_record`]). PEER NGA-West2 records are downloaded free (with registration) from the
//! PEER Ground Motion Database, <https://ngawest2.berkeley.edu>; cite PEER NGA-West2 (Ancheta
//! et al. 2014, Earthquake Spectra 30(3)) when you publish with them.

use std::path::{Path, PathBuf};

use crate::STANDARD_GRAVITY_M_S2;

use crate::error::{IoAction, IoError, Result};

/// The environment variable naming the folder that holds ground-motion records.
pub const RECORDS_DIR_VAR: &str = "PLATEN_RECORDS_DIR";

/// Where a user without the records gets them.
pub const RECORDS_HELP: &str = "PEER NGA-West2 records are free to download (after registering) from the PEER \
Ground Motion Database, https://ngawest2.berkeley.edu (search by record sequence number, e.g. RSN1087 for \
Northridge 1994 Tarzana); put the unscaled .AT2 files in a folder and set PLATEN_RECORDS_DIR to it";

/// The physical quantity of a record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Acceleration (`.AT2`), stored in m/s².
    Acceleration,
    /// Velocity (`.VT2`), stored in m/s.
    Velocity,
    /// Displacement (`.DT2`), stored in m.
    Displacement,
}

/// A PEER record, converted to SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerRecord {
    /// The file it was read from.
    pub path: PathBuf,
    /// Header line 2: event, date, station, component.
    pub description: String,
    /// What the values are.
    pub quantity: Quantity,
    /// Sample interval, s.
    pub dt_s: f64,
    /// The values, in m/s², m/s or m.
    pub values: Vec<f64>,
}

impl PeerRecord {
    /// Sample times from 0, s.
    pub fn times_s(&self) -> Vec<f64> {
        (0..self.values.len())
            .map(|j| j as f64 * self.dt_s)
            .collect()
    }
}

fn header_error(path: &Path, line: u64, message: impl Into<String>) -> IoError {
    IoError::CsvSyntax {
        path: path.to_owned(),
        line,
        message: message.into(),
    }
}

/// Reads a PEER NGA `.AT2`, `.VT2` or `.DT2` file.
///
/// # Errors
/// [`IoError::Io`] if it cannot be read; [`IoError::CsvSyntax`] naming the line for a
/// header that is not a PEER header, an unknown quantity or unit, a missing or malformed
/// `NPTS`/`DT`, or a value count that differs from `NPTS`; [`IoError::NonNumeric`] or
/// [`IoError::NonFinite`] naming the line of a bad value.
pub fn read_peer(path: &Path) -> Result<PeerRecord> {
    let text = std::fs::read_to_string(path).map_err(|source| IoError::Io {
        path: path.to_owned(),
        action: IoAction::Reading,
        source,
    })?;
    let mut lines = text.lines();
    let mut next = |n: u64| {
        lines
            .next()
            .ok_or_else(|| header_error(path, n, "file ends inside the 4-line PEER header"))
    };
    let l1 = next(1)?;
    if !l1.to_ascii_uppercase().contains("PEER") {
        return Err(header_error(
            path,
            1,
            format!("expected a PEER NGA header line, found {:?}", l1.trim()),
        ));
    }
    let description = next(2)?.trim().to_owned();
    let (quantity, scale) = quantity_of(path, next(3)?)?;
    let l4 = next(4)?;
    let (npts, dt_s) = parse_npts_dt(l4).map_err(|m| header_error(path, 4, m))?;
    // NPTS comes from the file: never trust it for an allocation (a value needs at least two
    // bytes of text, so the text bounds the count).
    let mut values = Vec::with_capacity(npts.min(text.len() / 2));
    for (i, line) in text.lines().enumerate().skip(4) {
        parse_values(path, i as u64 + 1, line, scale, &mut values)?;
    }
    if values.len() != npts {
        return Err(header_error(
            path,
            4,
            format!(
                "header says NPTS = {npts} but the file holds {} values",
                values.len()
            ),
        ));
    }
    if npts < 2 {
        return Err(header_error(
            path,
            4,
            format!("NPTS = {npts}: a record needs at least 2 values"),
        ));
    }
    Ok(PeerRecord {
        path: path.to_owned(),
        description,
        quantity,
        dt_s,
        values,
    })
}

/// The quantity of header line 3 and the factor from the file's unit to SI.
fn quantity_of(path: &Path, line: &str) -> Result<(Quantity, f64)> {
    let l3 = line.to_ascii_uppercase();
    if l3.contains("ACCELERATION") && l3.contains("UNITS OF G") {
        Ok((Quantity::Acceleration, STANDARD_GRAVITY_M_S2))
    } else if l3.contains("VELOCITY") && l3.contains("CM/S") {
        Ok((Quantity::Velocity, 0.01))
    } else if l3.contains("DISPLACEMENT") && l3.contains("CM") {
        Ok((Quantity::Displacement, 0.01))
    } else {
        Err(header_error(
            path,
            3,
            format!(
                "expected `ACCELERATION … IN UNITS OF G`, `VELOCITY … CM/S` or `DISPLACEMENT … CM`, found {:?}",
                l3.trim()
            ),
        ))
    }
}

/// Parses the values of data line `line_no`, in SI units, onto `values`.
fn parse_values(
    path: &Path,
    line_no: u64,
    line: &str,
    scale: f64,
    values: &mut Vec<f64>,
) -> Result<()> {
    for token in line.split_whitespace() {
        let v: f64 = parse_fortran(token).ok_or_else(|| IoError::NonNumeric {
            path: path.to_owned(),
            line: line_no,
            column: "value".to_owned(),
            value: token.to_owned(),
        })?;
        if !v.is_finite() {
            return Err(IoError::NonFinite {
                path: path.to_owned(),
                line: line_no,
                column: "value".to_owned(),
                value: token.to_owned(),
            });
        }
        values.push(v * scale);
    }
    Ok(())
}

/// Parses `NPTS=   2000, DT=   .0200 SEC` and its variants.
fn parse_npts_dt(line: &str) -> std::result::Result<(usize, f64), String> {
    let upper = line.to_ascii_uppercase();
    let field = |key: &str| -> Option<&str> {
        let at = upper.find(key)? + key.len();
        let rest = upper[at..].trim_start();
        let rest = rest.strip_prefix('=')?.trim_start();
        let end = rest
            .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'E')))
            .unwrap_or(rest.len());
        Some(&rest[..end])
    };
    let npts = field("NPTS")
        .and_then(|s| s.parse::<usize>().ok())
        .ok_or_else(|| format!("expected `NPTS= <count>` in {:?}", line.trim()))?;
    let dt = field("DT")
        .and_then(parse_fortran)
        .filter(|dt| dt.is_finite() && *dt > 0.0)
        .ok_or_else(|| {
            format!(
                "expected `DT= <seconds>` with a positive interval in {:?}",
                line.trim()
            )
        })?;
    Ok((npts, dt))
}

/// Parses a Fortran-style real (`.7134740E-03`, `-.5E+01`, `1.0D-3`).
fn parse_fortran(token: &str) -> Option<f64> {
    if token.contains(['D', 'd']) {
        token.replace(['D', 'd'], "E").parse().ok()
    } else {
        token.parse().ok()
    }
}

/// Resolves a record named by a scenario: `name` relative to the scenario's folder if it
/// exists there, else in the folder named by [`RECORDS_DIR_VAR`].
///
/// # Errors
/// [`IoError::Record`] saying where it looked and how to get the records.
pub fn find_record(scenario_dir: Option<&Path>, name: &Path) -> Result<PathBuf> {
    if name.is_absolute() && name.is_file() {
        return Ok(name.to_owned());
    }
    let mut looked = Vec::new();
    if let Some(dir) = scenario_dir {
        let p = dir.join(name);
        if p.is_file() {
            return Ok(p);
        }
        looked.push(p.display().to_string());
    }
    match std::env::var_os(RECORDS_DIR_VAR) {
        Some(dir) => {
            let p = Path::new(&dir).join(name);
            if p.is_file() {
                return Ok(p);
            }
            looked.push(p.display().to_string());
        }
        None => looked.push(format!("${RECORDS_DIR_VAR} (not set)")),
    }
    Err(IoError::Record {
        path: name.to_owned(),
        message: format!(
            "ground-motion record not found (looked in: {}). {RECORDS_HELP}",
            looked.join(", ")
        ),
    })
}

/// The records folder from [`RECORDS_DIR_VAR`], if it is set and is a folder.
pub fn records_dir() -> Option<PathBuf> {
    std::env::var_os(RECORDS_DIR_VAR)
        .map(PathBuf::from)
        .filter(|p| p.is_dir())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_npts_dt_header_variant_of_the_nga_files_parses() {
        for (line, npts, dt) in [
            ("NPTS=   2000, DT=   .0200 SEC", 2000, 0.02),
            ("NPTS=   5372, DT=   .0100 SEC,", 5372, 0.01),
            ("NPTS =   7500 , DT =   .020 SEC ,", 7500, 0.02),
            (
                "NPTS=   1991, DT=   .0100 SEC,   0 POLE @    30.00000 HZ,  -5 POLE @      .05000",
                1991,
                0.01,
            ),
        ] {
            assert_eq!(parse_npts_dt(line).unwrap(), (npts, dt), "{line}");
        }
        assert!(parse_npts_dt("NPTS= , DT= .02").is_err());
        assert!(parse_npts_dt("NPTS= 10, DT= 0").is_err());
    }

    /// Found by the `peer_reader` fuzz target: `NPTS=99999999999999` made the reader reserve
    /// that many values up front and abort on capacity overflow.
    #[test]
    fn a_huge_npts_header_is_an_error_not_an_allocation_failure() {
        let dir = tempfile::tempdir().unwrap();
        let head =
            "PEER NGA STRONG MOTION DATABASE RECORD\nx\nACCELERATION TIME SERIES IN UNITS OF G\n";
        let p = write(
            dir.path(),
            "huge.AT2",
            &format!("{head}NPTS= 18446744073709551615, DT= .01 SEC\n .1E+00\n"),
        );
        let e = read_peer(&p).unwrap_err().to_string();
        assert!(e.contains("huge.AT2") && e.contains("line 4"), "{e}");
    }

    #[test]
    fn fortran_reals_parse() {
        assert_eq!(parse_fortran(".7134740E-03"), Some(0.000713474));
        assert_eq!(parse_fortran("-.5E+01"), Some(-5.0));
        assert_eq!(parse_fortran("1.0D-3"), Some(0.001));
        assert_eq!(parse_fortran("abc"), None);
    }

    fn write(dir: &Path, name: &str, body: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        p
    }

    #[test]
    fn a_small_record_reads_in_si_units_and_bad_ones_name_their_line() {
        let dir = tempfile::tempdir().unwrap();
        let head = "PEER NGA STRONG MOTION DATABASE RECORD\nTest, 1/1/2000, Station, 90\nACCELERATION TIME SERIES IN UNITS OF G\n";
        let p = write(
            dir.path(),
            "ok.AT2",
            &format!("{head}NPTS=   3, DT=   .0100 SEC\n  .1E+00 -.2E+00\n  .5E-01\n"),
        );
        let r = read_peer(&p).unwrap();
        assert_eq!(r.quantity, Quantity::Acceleration);
        assert_eq!(
            r.values,
            vec![0.1 * 9.80665, -0.2 * 9.80665, 0.05 * 9.80665]
        );
        assert_eq!(r.dt_s, 0.01);
        let p = write(
            dir.path(),
            "count.AT2",
            &format!("{head}NPTS=   4, DT=   .0100 SEC\n  .1E+00 -.2E+00\n"),
        );
        let e = read_peer(&p).unwrap_err().to_string();
        assert!(
            e.contains("count.AT2") && e.contains("line 4") && e.contains("NPTS = 4"),
            "{e}"
        );
        let p = write(
            dir.path(),
            "bad.AT2",
            &format!("{head}NPTS=   2, DT=   .0100 SEC\n  .1E+00\n  x.2E+00\n"),
        );
        let e = read_peer(&p).unwrap_err().to_string();
        assert!(
            e.contains("bad.AT2") && e.contains("line 6") && e.contains("x.2E+00"),
            "{e}"
        );
        let p = write(
            dir.path(),
            "nan.AT2",
            &format!("{head}NPTS=   2, DT=   .0100 SEC\n  .1E+00 NaN\n"),
        );
        assert!(read_peer(&p).unwrap_err().to_string().contains("line 5"));
        let p = write(dir.path(), "unit.AT2", "PEER NGA STRONG MOTION DATABASE RECORD\nx\nACCELERATION IN FURLONGS\nNPTS= 1, DT= .01\n");
        assert!(read_peer(&p).unwrap_err().to_string().contains("line 3"));
        let p = write(
            dir.path(),
            "short.AT2",
            "PEER NGA STRONG MOTION DATABASE RECORD\n",
        );
        assert!(read_peer(&p).unwrap_err().to_string().contains("line 2"));
    }
}
