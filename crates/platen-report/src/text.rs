//! Numbers and channels as text: significant digits, each channel's display units, the metric
//! rows shared by the terminal summary and the HTML report, and the terminal summary of a
//! comparison.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use platen_compare::{
    Channel, ComparedChannel, Comparison, Direction, RecordedLimitCheck, TableLimit,
};

/// How a channel is shown: its unit in figures and tables, and that of its residual.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayUnits {
    /// Factor from the SI unit to the display unit.
    pub scale: f64,
    /// Unit of figures and of the terminal table.
    pub unit: &'static str,
    /// Factor from the SI unit to the residual's display unit.
    pub residual_scale: f64,
    /// Unit of the residual figure.
    pub residual_unit: &'static str,
}

/// The display units of `channel`: m and mm (platen and storey displacements), m/s and mm/s,
/// kN and kN (actuator force, base shear), m/s² and m/s² (storey accelerations).
pub fn display_units(channel: Channel) -> DisplayUnits {
    match channel {
        Channel::Displacement => DisplayUnits {
            scale: 1.0,
            unit: "m",
            residual_scale: 1e3,
            residual_unit: "mm",
        },
        Channel::Velocity => DisplayUnits {
            scale: 1.0,
            unit: "m/s",
            residual_scale: 1e3,
            residual_unit: "mm/s",
        },
        Channel::Force | Channel::BaseShear => DisplayUnits {
            scale: 1e-3,
            unit: "kN",
            residual_scale: 1e-3,
            residual_unit: "kN",
        },
        Channel::StoreyDisplacement(_) => DisplayUnits {
            scale: 1.0,
            unit: "m",
            residual_scale: 1e3,
            residual_unit: "mm",
        },
        Channel::StoreyAcceleration(_) => DisplayUnits {
            scale: 1.0,
            unit: "m/s²",
            residual_scale: 1.0,
            residual_unit: "m/s²",
        },
    }
}

/// `x` with `digits` significant digits, in plain notation between 1e-3 and 1e6.
pub fn significant(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i64;
    if (-3..6).contains(&magnitude) {
        let decimals = (digits as i64 - 1 - magnitude).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.prec$e}", prec = digits.saturating_sub(1))
    }
}

/// One engineering format for a table's values: forces, moments and pressures (`N`, `N·m`,
/// `Pa`) in the SI prefix that puts `reference` between 1 and 1000 (kN, MN, MPa, as labs read
/// them), other units as they are. Returns the factor to multiply values by and the unit.
pub fn engineering_unit(unit: &str, reference: f64) -> (f64, String) {
    if !matches!(unit, "N" | "N·m" | "Pa") || reference == 0.0 || !reference.is_finite() {
        return (1.0, unit.to_owned());
    }
    let thousands = ((reference.abs().log10() / 3.0).floor() as i32).clamp(0, 3);
    let prefix = ["", "k", "M", "G"][thousands as usize];
    (10f64.powi(-3 * thousands), format!("{prefix}{unit}"))
}

/// `x` to `digits` significant digits without trailing zeros: a sample rate measured from
/// rounded stamps, 204.79999998958843 Hz, reads 204.8 (at 9 digits), and 1024 reads 1024.
pub fn rounded(x: f64, digits: usize) -> String {
    let text = significant(x, digits);
    if text.contains('e') || !text.contains('.') {
        return text;
    }
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// `text` with an explicit sign.
fn signed(text: String) -> String {
    if text.starts_with('-') {
        text.replacen('-', "−", 1)
    } else {
        format!("+{text}")
    }
}

/// Column headings of [`display_row`].
pub const DISPLAY_HEADINGS: [&str; 7] = [
    "RMS error",
    "NRMSE",
    "peak recorded",
    "peak simulated",
    "peak ratio",
    "correlation",
    "lag",
];

/// The metrics of a channel as display strings: RMS error, NRMSE, peaks, ratio, correlation,
/// lag.
pub fn display_row(ch: &ComparedChannel) -> [String; 7] {
    let m = &ch.metrics;
    let units = display_units(ch.channel);
    let unit = units.unit;
    let value = |x: f64| significant(x * units.scale, 4);
    let opt = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or_else(|| "–".into(), f);
    [
        format!("{} {unit}", value(m.rms_error)),
        opt(m.nrmse, &|x| format!("{:.3} %", 100.0 * x)),
        format!(
            "{} {unit} at {:.3} s",
            signed(value(m.peak_recorded.value)),
            m.peak_recorded.t_s
        ),
        format!(
            "{} {unit} at {:.3} s",
            signed(value(m.peak_simulated.value)),
            m.peak_simulated.t_s
        ),
        opt(m.peak_ratio, &|x| format!("{x:.4}")),
        opt(m.correlation, &|x| format!("{x:.5}")),
        m.lag.map_or_else(
            || "–".into(),
            |l| {
                format!(
                    "{:+.2} ms{}",
                    1e3 * l.lag_s,
                    if l.at_search_limit {
                        " (at the search limit)"
                    } else {
                        ""
                    }
                )
            },
        ),
    ]
}

/// Column headings of [`recorded_limit_row`].
pub const RECORDED_LIMIT_HEADINGS: [&str; 6] = [
    "limit",
    "recorded peak",
    "of the limit",
    "respected",
    "first beyond",
    "time beyond",
];

/// A value of `kind`'s unit as display text (4 significant digits, or as given for a
/// limit): kN for the force, SI otherwise.
fn limit_value(kind: TableLimit, x: f64, as_given: bool) -> String {
    let (x, unit) = match kind {
        TableLimit::Force => (x / 1e3, "kN"),
        _ => (x, kind.unit()),
    };
    if as_given {
        // The limit as the table's record gives it, in the same format as every other
        // number here (4.2 g is 41.19 m/s², not 41.18793).
        format!("{} {unit}", rounded(x, 4))
    } else {
        format!("{} {unit}", significant(x, 4))
    }
}

/// A recorded limit check as display strings: the limit, the recorded peak and its time, the
/// peak as a percentage of the limit, whether it is respected, the first time beyond it and
/// the time spent beyond it.
pub fn recorded_limit_row(c: &RecordedLimitCheck) -> [String; 6] {
    let peak = limit_value(c.kind, c.peak, false);
    let peak = if c.peak < 0.0 {
        peak.replacen('-', "−", 1)
    } else {
        format!("+{peak}")
    };
    [
        limit_value(c.kind, c.limit, true),
        format!("{peak} at {:.3} s", c.peak_t_s),
        format!("{:.1} %", 100.0 * c.peak.abs() / c.limit),
        if c.respected { "yes" } else { "no" }.into(),
        c.first_exceeded_s
            .map_or_else(|| "–".into(), |t| format!("{t:.3} s")),
        if c.respected {
            "–".into()
        } else {
            format!("{} s", significant(c.time_exceeded_s, 4))
        },
    ]
}

/// The terminal summary of a comparison (what `platen compare` prints without `--json`),
/// listing the figure files and the report written; every line ends with a newline.
pub fn compare_summary(c: &Comparison, figures: &[PathBuf], report: Option<&Path>) -> String {
    let mut s = String::new();
    let dir = match c.direction {
        Direction::Forward => "forward (force → motion)",
        Direction::Inverse => "inverse (motion → force)",
    };
    let (first, last) = c.compared_span_s();
    let _ = writeln!(s, "{}: {dir}, {} model", c.name, c.model_form);
    let _ = writeln!(
        s,
        "  compared with {}: {} samples at {} Hz over {first:.3}–{last:.3} s",
        c.recorded_path.display(),
        c.t_s.len(),
        rounded(c.sample_rate_hz, 9),
    );
    if let Some(w) = c.window {
        let _ = writeln!(s, "  metrics over the window {}–{} s", w.start_s, w.end_s);
    }
    for ch in &c.channels {
        let row = display_row(ch);
        let _ = writeln!(
            s,
            "  {} ({}, {}):",
            ch.channel.name(),
            ch.channel.quantity(),
            display_units(ch.channel).unit
        );
        for (heading, value) in DISPLAY_HEADINGS.iter().zip(&row) {
            let _ = writeln!(s, "    {heading:<24}{value}");
        }
    }
    let _ = writeln!(
        s,
        "  (error = simulated − recorded; NRMSE = RMS error / recorded RMS; lag > 0: the \
         simulation is late)"
    );
    for note in &c.recorded.sources.notes {
        let _ = writeln!(s, "  note: {note}");
    }
    if !c.recorded_limits.is_empty() {
        let _ = writeln!(
            s,
            "  the recording against the table's limits (its own columns, whole record):"
        );
        for check in &c.recorded_limits {
            let [limit, peak, share, _, first, beyond] = recorded_limit_row(check);
            let verdict = if check.respected {
                "respected".to_string()
            } else {
                format!("BEYOND from {first}, {beyond} in all")
            };
            let _ = writeln!(
                s,
                "    {:<28}peak {peak}, {share} of {limit}: {verdict}",
                format!("{} ({})", check.kind.key(), check.column),
            );
        }
    }
    for warning in c.warnings() {
        let _ = writeln!(s, "  warning: {warning}");
    }
    if !figures.is_empty() {
        let _ = writeln!(s, "  wrote {} figure files (SVG and PNG):", figures.len());
        for f in figures {
            let _ = writeln!(s, "    {}", f.display());
        }
    }
    if let Some(r) = report {
        let _ = writeln!(s, "  wrote report {}", r.display());
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounded_reads_as_a_person_writes_it() {
        assert_eq!(rounded(204.79999998958843, 9), "204.8");
        assert_eq!(rounded(1024.0, 9), "1024");
        assert_eq!(rounded(1023.9999996, 9), "1024");
        assert_eq!(rounded(0.5, 9), "0.5");
        assert_eq!(rounded(2.5e7, 3), "2.50e7");
    }
}

#[cfg(test)]
mod engineering_tests {
    use super::*;

    #[test]
    fn forces_and_pressures_take_the_prefix_of_their_reference_and_others_keep_their_unit() {
        // issue 38: a plan table read `-589683` against `6.800e6 N` and `2.060e7 Pa`.
        let (f, u) = engineering_unit("N", 6.8e6);
        assert_eq!(
            (significant(f * 659_293.0, 4), u.as_str()),
            ("0.6593".into(), "MN")
        );
        assert_eq!(significant(f * 6.8e6, 4), "6.800");
        let (f, u) = engineering_unit("Pa", 13.8e6);
        assert_eq!(
            (significant(f * 2.0607e7, 4), u.as_str()),
            ("20.61".into(), "MPa")
        );
        let (f, u) = engineering_unit("N", 37_500.0);
        assert_eq!(
            (significant(f * 37_500.0, 4), u.as_str()),
            ("37.50".into(), "kN")
        );
        // Below 1 in its base unit, and every non-force unit, as they are.
        assert_eq!(engineering_unit("N", 12.0), (1.0, "N".into()));
        assert_eq!(engineering_unit("m/s²", 41.18793), (1.0, "m/s²".into()));
        assert_eq!(engineering_unit("m", 0.75), (1.0, "m".into()));
    }
}
