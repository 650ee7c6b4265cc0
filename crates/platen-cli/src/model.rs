//! `platen model`: a preset's parameters and derived quantities.
//!
//! `--json` prints [`platen_scenario::describe_model`]'s object as it is (SI, the contract's
//! keys). The text form reads the same object and groups it for a person: the model the
//! verbs simulate, the quantities derived from the full model (Eq. 5–8), the physical
//! parameters and the table's limits, in the units an engineer reads (t, MN/m, kN, MPa, g)
//! with four significant digits.

use std::fmt::Write as _;

use anyhow::Result;
use serde_json::Value;

use platen_model::{Preset, STANDARD_GRAVITY_M_S2};

use crate::Form;

pub fn run(preset: &str, pressure_mpa: Option<f64>, form: Form, json_out: bool) -> Result<()> {
    let preset = Preset::from_name(preset)?;
    let pressure_pa = match pressure_mpa {
        Some(p) if !(p.is_finite() && p >= 0.0) => {
            anyhow::bail!("--pressure-mpa {p}: expected a pressure >= 0 MPa")
        }
        Some(p) => p * 1e6,
        None => preset.nominal_pressure_pa(),
    };
    let value = platen_scenario::describe_model(preset, pressure_pa, matches!(form, Form::Full))?;
    if json_out {
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        out!("{}", text(&value));
    }
    Ok(())
}

/// How a quantity is shown: its SI value is divided by `scale` and printed with `unit`.
#[derive(Clone, Copy)]
enum Unit {
    /// Tonnes (SI kg / 1000).
    Tonne,
    /// MN/m (SI N/m / 10⁶).
    MeganewtonPerMetre,
    /// kN (SI N / 1000).
    Kilonewton,
    /// MN (SI N / 10⁶).
    Meganewton,
    /// kN/(m/s)^α with the exponent held by the key named here.
    KilonewtonPerVelocityTo(&'static str),
    /// MPa (SI Pa / 10⁶).
    Megapascal,
    /// m.
    Metre,
    /// m².
    SquareMetre,
    /// m/s.
    MetrePerSecond,
    /// Standard gravities (SI m/s² / g₀).
    Gravity,
    /// s/m.
    SecondPerMetre,
    /// Percent of a dimensionless ratio (friction coefficients).
    Percent,
    /// A dimensionless number.
    None,
}

impl Unit {
    /// The shown number and unit of SI value `v`; `section` holds the exponent of a viscous
    /// coefficient.
    fn show(self, v: f64, section: &serde_json::Map<String, Value>) -> (f64, String) {
        match self {
            Unit::Tonne => (v / 1e3, "t".into()),
            Unit::MeganewtonPerMetre => (v / 1e6, "MN/m".into()),
            Unit::Kilonewton => (v / 1e3, "kN".into()),
            Unit::Meganewton => (v / 1e6, "MN".into()),
            Unit::KilonewtonPerVelocityTo(key) => {
                let unit = match section.get(key).and_then(Value::as_f64) {
                    Some(1.0) => "kN·s/m".to_string(),
                    Some(e) => format!("kN/(m/s)^{e}"),
                    None => "kN/(m/s)^α".to_string(),
                };
                (v / 1e3, unit)
            }
            Unit::Megapascal => (v / 1e6, "MPa".into()),
            Unit::Metre => (v, "m".into()),
            Unit::SquareMetre => (v, "m²".into()),
            Unit::MetrePerSecond => (v, "m/s".into()),
            Unit::Gravity => (v / STANDARD_GRAVITY_M_S2, "g".into()),
            Unit::SecondPerMetre => (v, "s/m".into()),
            Unit::Percent => (v * 100.0, "%".into()),
            Unit::None => (v, String::new()),
        }
    }
}

/// One printed line: the JSON key, the paper's symbol, a description and the unit shown.
type Row = (&'static str, &'static str, &'static str, Unit);

/// The seven identified keys of the selected form (top level of the description).
const IDENTIFIED: &[Row] = &[
    ("effective_mass_kg", "Mₑ", "effective mass", Unit::Tonne),
    (
        "stiffness_n_per_m",
        "Kₑ",
        "stiffness (hold-down struts)",
        Unit::MeganewtonPerMetre,
    ),
    (
        "coulomb_force_n",
        "F_μ",
        "Coulomb friction force",
        Unit::Kilonewton,
    ),
    (
        "viscous_coefficient",
        "Cₑ",
        "viscous coefficient",
        Unit::KilonewtonPerVelocityTo("viscous_exponent"),
    ),
    ("viscous_exponent", "α", "viscous exponent", Unit::None),
    (
        "low_velocity_force_n",
        "a",
        "low-velocity friction force",
        Unit::Kilonewton,
    ),
    (
        "low_velocity_decay_s_per_m",
        "b",
        "low-velocity friction decay",
        Unit::SecondPerMetre,
    ),
];

/// The quantities of Eq. 5–8 derived from the physical parameters (top level).
const DERIVED: &[Row] = &[
    (
        "full_effective_mass_kg",
        "Mₑ",
        "effective mass (Eq. 5a)",
        Unit::Tonne,
    ),
    (
        "strut_effective_mass_kg",
        "M̄ₑ",
        "effective mass of one strut (Eq. 5b)",
        Unit::Tonne,
    ),
    (
        "strut_rotational_mass_kg",
        "M̄′ₑ",
        "strut rotational mass (Eq. 5c)",
        Unit::Tonne,
    ),
    (
        "full_stiffness_n_per_m",
        "Kₑ",
        "stiffness (Eq. 6a)",
        Unit::MeganewtonPerMetre,
    ),
    (
        "cubic_stiffness_n_per_m",
        "K′ₑ",
        "cubic stiffness (Eq. 6b)",
        Unit::MeganewtonPerMetre,
    ),
    (
        "hold_down_force_n",
        "F_hd",
        "hold-down force 2p₀A",
        Unit::Meganewton,
    ),
    (
        "hold_down_friction_coefficient",
        "μ′ₑ",
        "hold-down friction coefficient (Eq. 7b)",
        Unit::Percent,
    ),
    (
        "hinge_friction_coefficient",
        "μ⁽ⁱᵛ⁾ₑ",
        "hinge friction coefficient (Eq. 8)",
        Unit::Percent,
    ),
    (
        "full_coulomb_force_n",
        "F_μ",
        "Coulomb friction force (Eq. 7a)",
        Unit::Kilonewton,
    ),
];

/// The physical parameters of the full model (the `physical` object).
const PHYSICAL: &[Row] = &[
    ("platen_mass_kg", "M_pl", "platen mass", Unit::Tonne),
    (
        "actuator_moving_mass_kg",
        "M_act",
        "moving mass of one actuator",
        Unit::Tonne,
    ),
    (
        "strut_piston_mass_kg",
        "M₁",
        "strut piston mass",
        Unit::Tonne,
    ),
    (
        "strut_cylinder_mass_kg",
        "M₂",
        "strut cylinder mass",
        Unit::Tonne,
    ),
    ("strut_height_m", "h", "strut height", Unit::Metre),
    (
        "strut_piston_length_m",
        "l₀",
        "strut piston length",
        Unit::Metre,
    ),
    (
        "hold_down_pressure_pa",
        "p₀",
        "nitrogen pre-charge pressure",
        Unit::Megapascal,
    ),
    (
        "strut_area_m2",
        "A",
        "strut chamber area",
        Unit::SquareMetre,
    ),
    (
        "gas_heat_capacity_ratio",
        "γ",
        "gas heat capacity ratio",
        Unit::None,
    ),
    (
        "supported_weight_n",
        "F_pl+act",
        "weight on the vertical bearings",
        Unit::Kilonewton,
    ),
    (
        "bearing_friction_coefficient",
        "μ″ₑ",
        "vertical bearing friction",
        Unit::Percent,
    ),
    (
        "lateral_friction_coefficient",
        "μ‴ₑ",
        "lateral bearing friction",
        Unit::Percent,
    ),
    (
        "lateral_normal_force_n",
        "F_l",
        "normal force on the lateral bearings",
        Unit::Kilonewton,
    ),
    (
        "hinge_swivel_friction_coefficient",
        "μ_hg",
        "strut swivel friction",
        Unit::Percent,
    ),
    ("hinge_radius_m", "a", "strut hinge radius", Unit::Metre),
    (
        "hinge_force_distribution_factor",
        "κ",
        "hinge force-distribution factor",
        Unit::None,
    ),
    (
        "viscous_coefficient",
        "Cₑ",
        "actuator viscous coefficient",
        Unit::KilonewtonPerVelocityTo("viscous_exponent"),
    ),
    (
        "viscous_exponent",
        "α",
        "actuator viscous exponent",
        Unit::None,
    ),
    (
        "strut_viscous_coefficient",
        "c_β",
        "strut viscous coefficient",
        Unit::KilonewtonPerVelocityTo("strut_viscous_exponent"),
    ),
    (
        "strut_viscous_exponent",
        "β",
        "strut viscous exponent",
        Unit::None,
    ),
    (
        "low_velocity_force_n",
        "a",
        "low-velocity friction force",
        Unit::Kilonewton,
    ),
    (
        "low_velocity_decay_s_per_m",
        "b",
        "low-velocity friction decay",
        Unit::SecondPerMetre,
    ),
];

/// The table's operational limits (the `limits` object).
const LIMITS: &[Row] = &[
    ("stroke_m", "", "stroke, either way", Unit::Metre),
    ("velocity_m_s", "", "velocity", Unit::MetrePerSecond),
    (
        "acceleration_m_s2",
        "",
        "acceleration, bare table",
        Unit::Gravity,
    ),
    ("force_n", "", "actuator force", Unit::Meganewton),
];

/// Significant digits of every printed value: the paper quotes its parameters to 3–4.
const SIGNIFICANT_DIGITS: i32 = 4;

/// `v` rounded to `digits` significant digits, in fixed notation, without trailing zeros
/// beyond the first decimal (`144.0`, `1.266`, `0.5`, `1613`). The units of the text form keep
/// every preset value between 10⁻³ and 10⁴, where fixed notation stays short.
pub(crate) fn significant(v: f64, digits: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (digits - 1 - magnitude).max(0) as usize;
    // Digits left of the point beyond `digits` are rounded away (792 156 → 792 200).
    let v = if magnitude >= digits {
        let f = 10f64.powi(magnitude + 1 - digits);
        (v / f).round() * f
    } else {
        v
    };
    let mut s = format!("{v:.decimals$}");
    if s.contains('.') {
        while s.ends_with('0') && !s.ends_with(".0") {
            s.pop();
        }
    }
    s
}

/// Characters a terminal shows as columns: combining marks (the bar of `M̄ₑ`) take none.
fn display_width(s: &str) -> usize {
    s.chars()
        .filter(|c| !('\u{0300}'..='\u{036F}').contains(c))
        .count()
}

/// `s` padded with spaces on the right to `w` display columns.
fn pad_right(s: &str, w: usize) -> String {
    format!("{s}{}", " ".repeat(w.saturating_sub(display_width(s))))
}

/// The grouped text form of a model description (the object of
/// [`platen_scenario::describe_model`]).
pub(crate) fn text(d: &Value) -> String {
    let empty = serde_json::Map::new();
    let top = d.as_object().unwrap_or(&empty);
    let physical = top
        .get("physical")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    let limits = top
        .get("limits")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    let name = |k: &str| top.get(k).and_then(Value::as_str).unwrap_or("?").to_owned();
    let form = name("form");
    let mut s = String::new();
    let pressure = top
        .get("hold_down_pressure_mpa")
        .and_then(Value::as_f64)
        .map_or_else(|| "?".into(), |p| significant(p, SIGNIFICANT_DIGITS));
    let _ = writeln!(
        s,
        "preset {}, hold-down pressure {pressure} MPa",
        name("preset")
    );
    let heading = if form == "full" {
        "Model simulated (full form, Eq. 1–8, as its identified equivalent)"
    } else {
        "Model simulated (identified form, Eq. 22/23)"
    };
    let mut simulated = rows(IDENTIFIED, top);
    // The natural frequency of the linear part, √(Kₑ/Mₑ)/2π.
    if let (Some(k), Some(m)) = (
        top.get("stiffness_n_per_m").and_then(Value::as_f64),
        top.get("effective_mass_kg").and_then(Value::as_f64),
    ) {
        simulated.push([
            "fₙ".into(),
            "natural frequency √(Kₑ/Mₑ)/2π".into(),
            significant((k / m).sqrt() / std::f64::consts::TAU, SIGNIFICANT_DIGITS),
            "Hz".into(),
        ]);
    }
    let mut groups: Vec<(&str, Vec<[String; 4]>)> = vec![
        (heading, simulated),
        (
            "Derived from the physical parameters (full model, Eq. 5–8)",
            rows(DERIVED, top),
        ),
        ("Physical parameters (full model)", rows(PHYSICAL, physical)),
        ("Table limits", rows(LIMITS, limits)),
    ];
    // Numbers are aligned on their decimal point: integer parts right-aligned, fractions
    // (with the point) left-aligned.
    let split = |v: &str| -> (String, String) {
        match v.find('.') {
            Some(i) => (v[..i].to_owned(), v[i..].to_owned()),
            None => (v.to_owned(), String::new()),
        }
    };
    let symbol_w = width(&groups, |c| display_width(&c[0]));
    let text_w = width(&groups, |c| display_width(&c[1]));
    let int_w = width(&groups, |c| split(&c[2]).0.len());
    let frac_w = width(&groups, |c| display_width(&split(&c[2]).1));
    for (title, lines) in groups.drain(..) {
        let _ = writeln!(s, "\n{title}");
        for [sym, what, value, unit] in lines {
            let (int, frac) = split(&value);
            let line = format!(
                "  {}  {}  {int:>int_w$}{} {unit}",
                pad_right(&sym, symbol_w),
                pad_right(&what, text_w),
                pad_right(&frac, frac_w),
            );
            let _ = writeln!(s, "{}", line.trim_end());
        }
    }
    s
}

/// The printed cells of `table`'s keys found in `section`.
fn rows(table: &[Row], section: &serde_json::Map<String, Value>) -> Vec<[String; 4]> {
    table
        .iter()
        .filter_map(|&(key, sym, what, unit)| {
            let v = section.get(key)?.as_f64()?;
            let (shown, unit) = unit.show(v, section);
            Some([
                sym.to_owned(),
                what.to_owned(),
                significant(shown, SIGNIFICANT_DIGITS),
                unit,
            ])
        })
        .collect()
}

/// The widest of `cell_width` over every row of every group.
fn width(groups: &[(&str, Vec<[String; 4]>)], cell_width: impl Fn(&[String; 4]) -> usize) -> usize {
    groups
        .iter()
        .flat_map(|(_, r)| r.iter().map(&cell_width))
        .max()
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits_follow_the_magnitude() {
        assert_eq!(significant(144.0, 4), "144.0");
        assert_eq!(significant(1.266, 4), "1.266");
        assert_eq!(significant(25.4452, 4), "25.45");
        assert_eq!(significant(0.045400084, 4), "0.0454");
        assert_eq!(significant(0.5, 4), "0.5");
        assert_eq!(significant(1613.0, 4), "1613");
        assert_eq!(significant(792155.844155844, 4), "792200");
        assert_eq!(significant(-2.0, 4), "-2.0");
        assert_eq!(significant(0.0, 4), "0");
    }
}
