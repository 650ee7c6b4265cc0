//! The text form of `platen model`: a model's description
//! ([`platen_scenario::describe::ModelDescription`]) and its table system's
//! ([`platen_scenario::describe::SystemDescription`]) grouped for a person, in the units an
//! engineer reads (t, MN/m, kN, MPa, g, l/min) with four significant digits, the columns of
//! each part aligned, numbers on their decimal point.
//!
//! ```
//! use platen_model::Preset;
//! use platen_scenario::describe::ModelDescription;
//!
//! let d = ModelDescription::of_preset(Preset::Lhpost2008, 13.8e6, false)?;
//! let text = platen_report::model_text::text(&d);
//! assert!(text.starts_with("preset lhpost-2008, hold-down pressure 13.8 MPa\n"));
//! assert!(text.contains("  Mₑ        effective mass                            144.0    t\n"));
//! # Ok::<(), platen_model::ModelError>(())
//! ```

use std::fmt::Write as _;
use std::path::Path;

use platen_model::STANDARD_GRAVITY_M_S2;
use platen_scenario::describe::{ModelDescription, SystemDescription};
use platen_scenario::Rig;
use platen_system::Supply;

/// Significant digits of every printed value: the paper quotes its parameters to 3–4.
pub const SIGNIFICANT_DIGITS: i32 = 4;

/// The whole text form: the model's groups and, with a table system, the system's.
pub fn text(d: &ModelDescription) -> String {
    let mut s = model_text(d);
    if let Some(system) = &d.table_system {
        s.push_str(&system_text(system));
    }
    s
}

/// The lines `platen model --scenario` prints before the model's text: the scenario's path
/// and name, the values it lays over its preset's and its specimen.
pub fn scenario_header(path: &Path, name: &str, rig: &Rig) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "scenario {} ({})", path.display(), name);
    let overrides: Vec<String> = rig
        .overrides
        .values()
        .iter()
        .map(|(key, value)| format!("{} = {value}", key.name()))
        .collect();
    if !overrides.is_empty() {
        let _ = writeln!(
            s,
            "model values laid over the preset's: {}",
            overrides.join(", ")
        );
    }
    if let Some(sp) = &rig.specimen {
        let storeys = sp.len();
        let _ = writeln!(
            s,
            "specimen: {storeys} storey{}, {} t in all (a rigid payload in the linearised loop)",
            if storeys == 1 { "" } else { "s" },
            significant(sp.total_mass_kg() / 1e3, SIGNIFICANT_DIGITS)
        );
    }
    s
}

/// How a quantity is shown: its SI value is divided by a scale and printed with a unit.
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
    /// kN/(m/s)^α with the exponent α given (`None`: unknown).
    KilonewtonPerVelocityTo(Option<f64>),
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
    /// The shown number and unit of SI value `v`.
    fn show(self, v: f64) -> (f64, String) {
        match self {
            Unit::Tonne => (v / 1e3, "t".into()),
            Unit::MeganewtonPerMetre => (v / 1e6, "MN/m".into()),
            Unit::Kilonewton => (v / 1e3, "kN".into()),
            Unit::Meganewton => (v / 1e6, "MN".into()),
            Unit::KilonewtonPerVelocityTo(exponent) => {
                let unit = match exponent {
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

/// `v` if it is finite (a value JSON can hold: the rows show what `--json` prints).
fn finite(v: f64) -> Option<f64> {
    Some(v).filter(|v| v.is_finite())
}

/// The printed cells of the quantities given (symbol, description, SI value, unit); a
/// value that is absent or not finite is left out.
fn rows(quantities: &[(&str, &str, Option<f64>, Unit)]) -> Vec<[String; 4]> {
    quantities
        .iter()
        .filter_map(|&(sym, what, v, unit)| {
            let (shown, unit) = unit.show(finite(v?)?);
            Some([
                sym.to_owned(),
                what.to_owned(),
                significant(shown, SIGNIFICANT_DIGITS),
                unit,
            ])
        })
        .collect()
}

/// The model's groups: the model simulated, the quantities derived from the physical
/// parameters (Eq. 5–8), the physical parameters and the table's limits.
pub fn model_text(d: &ModelDescription) -> String {
    let mut s = String::new();
    let pressure = finite(d.hold_down_pressure_mpa)
        .map_or_else(|| "?".into(), |p| significant(p, SIGNIFICANT_DIGITS));
    let _ = writeln!(s, "preset {}, hold-down pressure {pressure} MPa", d.preset);
    let heading = if d.form == "full" {
        "Model simulated (full form, Eq. 1–8, as its identified equivalent)"
    } else {
        "Model simulated (identified form, Eq. 22/23)"
    };
    let alpha = finite(d.viscous_exponent);
    let mut simulated = rows(&[
        (
            "Mₑ",
            "effective mass",
            Some(d.effective_mass_kg),
            Unit::Tonne,
        ),
        (
            "Kₑ",
            "stiffness (hold-down struts)",
            Some(d.stiffness_n_per_m),
            Unit::MeganewtonPerMetre,
        ),
        (
            "F_μ",
            "Coulomb friction force",
            Some(d.coulomb_force_n),
            Unit::Kilonewton,
        ),
        (
            "Cₑ",
            "viscous coefficient",
            Some(d.viscous_coefficient),
            Unit::KilonewtonPerVelocityTo(alpha),
        ),
        (
            "α",
            "viscous exponent",
            Some(d.viscous_exponent),
            Unit::None,
        ),
        (
            "a",
            "low-velocity friction force",
            Some(d.low_velocity_force_n),
            Unit::Kilonewton,
        ),
        (
            "b",
            "low-velocity friction decay",
            Some(d.low_velocity_decay_s_per_m),
            Unit::SecondPerMetre,
        ),
    ]);
    // The natural frequency of the linear part, √(Kₑ/Mₑ)/2π.
    if let (Some(k), Some(m)) = (finite(d.stiffness_n_per_m), finite(d.effective_mass_kg)) {
        simulated.push([
            "fₙ".into(),
            "natural frequency √(Kₑ/Mₑ)/2π".into(),
            significant((k / m).sqrt() / std::f64::consts::TAU, SIGNIFICANT_DIGITS),
            "Hz".into(),
        ]);
    }
    let derived = rows(&[
        (
            "Mₑ",
            "effective mass (Eq. 5a)",
            Some(d.full_effective_mass_kg),
            Unit::Tonne,
        ),
        (
            "M̄ₑ",
            "effective mass of one strut (Eq. 5b)",
            Some(d.strut_effective_mass_kg),
            Unit::Tonne,
        ),
        (
            "M̄′ₑ",
            "strut rotational mass (Eq. 5c)",
            Some(d.strut_rotational_mass_kg),
            Unit::Tonne,
        ),
        (
            "Kₑ",
            "stiffness (Eq. 6a)",
            Some(d.full_stiffness_n_per_m),
            Unit::MeganewtonPerMetre,
        ),
        (
            "K′ₑ",
            "cubic stiffness (Eq. 6b)",
            Some(d.cubic_stiffness_n_per_m),
            Unit::MeganewtonPerMetre,
        ),
        (
            "F_hd",
            "hold-down force 2p₀A",
            Some(d.hold_down_force_n),
            Unit::Meganewton,
        ),
        (
            "μ′ₑ",
            "hold-down friction coefficient (Eq. 7b)",
            Some(d.hold_down_friction_coefficient),
            Unit::Percent,
        ),
        (
            "μ⁽ⁱᵛ⁾ₑ",
            "hinge friction coefficient (Eq. 8)",
            Some(d.hinge_friction_coefficient),
            Unit::Percent,
        ),
        (
            "F_μ",
            "Coulomb friction force (Eq. 7a)",
            Some(d.full_coulomb_force_n),
            Unit::Kilonewton,
        ),
    ]);
    let p = |key: &str| d.physical.get(key).copied();
    let exponent = |key: &str| p(key).and_then(finite);
    let physical = rows(&[
        ("M_pl", "platen mass", p("platen_mass_kg"), Unit::Tonne),
        (
            "M_act",
            "moving mass of one actuator",
            p("actuator_moving_mass_kg"),
            Unit::Tonne,
        ),
        (
            "M₁",
            "strut piston mass",
            p("strut_piston_mass_kg"),
            Unit::Tonne,
        ),
        (
            "M₂",
            "strut cylinder mass",
            p("strut_cylinder_mass_kg"),
            Unit::Tonne,
        ),
        ("h", "strut height", p("strut_height_m"), Unit::Metre),
        (
            "l₀",
            "strut piston length",
            p("strut_piston_length_m"),
            Unit::Metre,
        ),
        (
            "p₀",
            "nitrogen pre-charge pressure",
            p("hold_down_pressure_pa"),
            Unit::Megapascal,
        ),
        (
            "A",
            "strut chamber area",
            p("strut_area_m2"),
            Unit::SquareMetre,
        ),
        (
            "γ",
            "gas heat capacity ratio",
            p("gas_heat_capacity_ratio"),
            Unit::None,
        ),
        (
            "F_pl+act",
            "weight on the vertical bearings",
            p("supported_weight_n"),
            Unit::Kilonewton,
        ),
        (
            "μ″ₑ",
            "vertical bearing friction",
            p("bearing_friction_coefficient"),
            Unit::Percent,
        ),
        (
            "μ‴ₑ",
            "lateral bearing friction",
            p("lateral_friction_coefficient"),
            Unit::Percent,
        ),
        (
            "F_l",
            "normal force on the lateral bearings",
            p("lateral_normal_force_n"),
            Unit::Kilonewton,
        ),
        (
            "μ_hg",
            "strut swivel friction",
            p("hinge_swivel_friction_coefficient"),
            Unit::Percent,
        ),
        ("a", "strut hinge radius", p("hinge_radius_m"), Unit::Metre),
        (
            "κ",
            "hinge force-distribution factor",
            p("hinge_force_distribution_factor"),
            Unit::None,
        ),
        (
            "Cₑ",
            "actuator viscous coefficient",
            p("viscous_coefficient"),
            Unit::KilonewtonPerVelocityTo(exponent("viscous_exponent")),
        ),
        (
            "α",
            "actuator viscous exponent",
            p("viscous_exponent"),
            Unit::None,
        ),
        (
            "c_β",
            "strut viscous coefficient",
            p("strut_viscous_coefficient"),
            Unit::KilonewtonPerVelocityTo(exponent("strut_viscous_exponent")),
        ),
        (
            "β",
            "strut viscous exponent",
            p("strut_viscous_exponent"),
            Unit::None,
        ),
        (
            "a",
            "low-velocity friction force",
            p("low_velocity_force_n"),
            Unit::Kilonewton,
        ),
        (
            "b",
            "low-velocity friction decay",
            p("low_velocity_decay_s_per_m"),
            Unit::SecondPerMetre,
        ),
    ]);
    let l = &d.limits;
    let limits = rows(&[
        ("", "stroke, either way", Some(l.stroke_m), Unit::Metre),
        ("", "velocity", Some(l.velocity_m_s), Unit::MetrePerSecond),
        (
            "",
            "acceleration, bare table",
            Some(l.acceleration_m_s2),
            Unit::Gravity,
        ),
        ("", "actuator force", Some(l.force_n), Unit::Meganewton),
    ]);
    let groups: Vec<Group> = vec![
        (heading.to_owned(), simulated),
        (
            "Derived from the physical parameters (full model, Eq. 5–8)".to_owned(),
            derived,
        ),
        ("Physical parameters (full model)".to_owned(), physical),
        ("Table limits".to_owned(), limits),
    ];
    write_groups(&mut s, groups);
    s
}

/// The table system's groups: its parameters, oil column, capacities, linearisation, loop
/// and integration step, in engineering units.
pub fn system_text(d: &SystemDescription) -> String {
    let params = &d.system;
    let a = &params.actuator;
    let v = &params.servo_valve;
    let lin = &d.linearisation;
    let m = &d.loop_margins;
    let num = |x: f64| significant(x, SIGNIFICANT_DIGITS);
    let opt = |x: Option<f64>| x.map_or("none".to_owned(), num);
    let row = |sym: &str, what: String, value: String, unit: &str| {
        [sym.to_owned(), what, value, unit.to_owned()]
    };
    // The unit of an optional value: none when there is no value.
    let unit_of = |x: Option<f64>, unit: &'static str| if x.is_some() { unit } else { "" };
    let supply = match &params.supply {
        Supply::Constant => "supply pressure (constant)".to_owned(),
        Supply::Accumulator(acc) => format!(
            "supply pressure (accumulator, precharge {} MPa)",
            num(acc.precharge_pressure_pa / 1e6)
        ),
    };
    let parameters = vec![
        row("n", "actuators".into(), a.count.to_string(), ""),
        row("A_a", "cap-side area".into(), num(a.cap_area_m2), "m²"),
        row("A_b", "rod-side area".into(), num(a.rod_area_m2), "m²"),
        row(
            "V_a",
            "cap-side chamber volume at mid-stroke".into(),
            num(a.cap_volume_m3),
            "m³",
        ),
        row(
            "V_b",
            "rod-side chamber volume at mid-stroke".into(),
            num(a.rod_volume_m3),
            "m³",
        ),
        row(
            "β",
            "oil bulk modulus".into(),
            num(params.oil_bulk_modulus_pa / 1e9),
            "GPa",
        ),
        row(
            "m",
            "servo-valves per actuator".into(),
            v.count.to_string(),
            "",
        ),
        row(
            "Q_r",
            format!(
                "rated flow of one valve (at {} MPa drop)",
                num(v.rated_pressure_drop_pa / 1e6)
            ),
            num(v.rated_flow_m3_s * 60e3),
            "l/min",
        ),
        row(
            "f_v",
            "spool natural frequency".into(),
            num(v.natural_frequency_hz),
            "Hz",
        ),
        row("P_s", supply, num(params.supply_pressure_pa / 1e6), "MPa"),
        row(
            "P_R",
            "return pressure".into(),
            num(params.return_pressure_pa / 1e6),
            "MPa",
        ),
        row(
            "f_c",
            "controller sample rate".into(),
            num(params.controller.sample_rate_hz),
            "Hz",
        ),
    ];
    let with_specimen = if d.specimen_mass_kg.is_some() {
        ", with the specimen"
    } else {
        ""
    };
    let mut oil = vec![row(
        "f_oc",
        format!(
            "oil column at mid-stroke, bare table (M = {} t)",
            num(d.model_mass_kg / 1e3)
        ),
        num(d.oil_column_frequency_hz),
        "Hz",
    )];
    if let (Some(f), Some(kg)) = (d.oil_column_frequency_with_specimen_hz, d.specimen_mass_kg) {
        oil.push(row(
            "f_oc",
            format!(
                "oil column at mid-stroke, with the specimen (M + {} t)",
                num(kg / 1e3)
            ),
            num(f),
            "Hz",
        ));
    }
    oil.push(row(
        "f_oc",
        format!(
            "oil column retracted, u = −{} m{with_specimen}",
            num(d.stroke_m)
        ),
        num(d.oil_column_frequency_retracted_hz),
        "Hz",
    ));
    oil.push(row(
        "f_oc",
        format!(
            "oil column extended, u = +{} m{with_specimen}",
            num(d.stroke_m)
        ),
        num(d.oil_column_frequency_extended_hz),
        "Hz",
    ));
    let capacities = vec![
        row(
            "v_ext",
            "valve-limited velocity, extending (no load)".into(),
            num(d.valve_limited_velocity_extend_m_s),
            "m/s",
        ),
        row(
            "v_ret",
            "valve-limited velocity, retracting (no load)".into(),
            num(d.valve_limited_velocity_retract_m_s),
            "m/s",
        ),
        row(
            "Q_max",
            "valve flow capacity (null drop on each land)".into(),
            num(d.valve_flow_capacity_m3_s),
            "m³/s",
        ),
        row(
            "F_push",
            "force capacity, pushing (stall)".into(),
            num(d.force_capacity_push_n / 1e6),
            "MN",
        ),
        row(
            "F_pull",
            "force capacity, pulling (stall)".into(),
            num(d.force_capacity_pull_n / 1e6),
            "MN",
        ),
    ];
    let linearisation = vec![
        row(
            "p_a0",
            "null pressure, cap side".into(),
            num(d.null_pressure_a_pa / 1e6),
            "MPa",
        ),
        row(
            "p_b0",
            "null pressure, rod side".into(),
            num(d.null_pressure_b_pa / 1e6),
            "MPa",
        ),
        row(
            "K_qa",
            "flow gain, cap-side land (one actuator)".into(),
            num(lin.flow_gain_a_m3_s),
            "m³/s",
        ),
        row(
            "K_qb",
            "flow gain, rod-side land (one actuator)".into(),
            num(lin.flow_gain_b_m3_s),
            "m³/s",
        ),
        row(
            "K_c",
            "flow-pressure coefficient (critically centred)".into(),
            num(lin.flow_pressure_m3_s_per_pa * 1e9),
            "l/s/MPa",
        ),
        row(
            "V_a/β",
            "hydraulic compliance, chamber a".into(),
            num(lin.compliance_a_m3_per_pa * 1e9),
            "l/MPa",
        ),
        row(
            "V_b/β",
            "hydraulic compliance, chamber b".into(),
            num(lin.compliance_b_m3_per_pa * 1e9),
            "l/MPa",
        ),
        row("M", "moving mass".into(), num(lin.mass_kg / 1e3), "t"),
        row(
            "K",
            "restoring stiffness".into(),
            num(lin.stiffness_n_per_m / 1e6),
            "MN/m",
        ),
        row(
            "C",
            format!("secant damping at {} m/s", lin.damping_secant_speed_m_s),
            num(lin.damping_n_s_per_m / 1e3),
            "kN·s/m",
        ),
    ];
    let margins = vec![
        row(
            "GM",
            "gain margin".into(),
            opt(m.gain_margin_db),
            unit_of(m.gain_margin_db, "dB"),
        ),
        row(
            "f_pc",
            "phase crossover".into(),
            opt(m.phase_crossover_hz),
            unit_of(m.phase_crossover_hz, "Hz"),
        ),
        row(
            "PM",
            "phase margin".into(),
            opt(m.phase_margin_deg),
            unit_of(m.phase_margin_deg, "°"),
        ),
        row(
            "f_gc",
            "gain crossover".into(),
            opt(m.gain_crossover_hz),
            unit_of(m.gain_crossover_hz, "Hz"),
        ),
        row(
            "|U/R|",
            "peak closed-loop gain, command → displacement".into(),
            num(m.peak_gain),
            "",
        ),
        row("f_peak", "at".into(), num(m.peak_gain_hz), "Hz"),
        row(
            "f_bw",
            "bandwidth (|U/R| below −3 dB above it)".into(),
            opt(d.closed_loop_bandwidth_hz),
            unit_of(d.closed_loop_bandwidth_hz, "Hz"),
        ),
        row(
            "|U/R|",
            "lowest closed-loop gain below the peak".into(),
            num(d.closed_loop_min_gain),
            "",
        ),
        row("f_min", "at".into(), num(d.closed_loop_min_gain_hz), "Hz"),
    ];
    let integration = vec![
        row(
            "k",
            "RK4 steps per controller period".into(),
            d.steps_per_controller_period.to_string(),
            "",
        ),
        row("h", "step T/k".into(), num(d.step_s * 1e3), "ms"),
    ];
    let name = d
        .preset
        .as_deref()
        .map_or("given by the scenario".to_owned(), |p| {
            // The preset's own values, or the scenario's laid over them.
            let own = platen_system::preset::by_name(p).map_or(true, |s| s == *params);
            let laid = if own {
                ""
            } else {
                ", with the scenario's values"
            };
            format!("{p}{laid}")
        });
    let payload = if d.specimen_mass_kg.is_some() {
        "; the specimen as a rigid payload"
    } else {
        ""
    };
    let groups: Vec<Group> = vec![
        (format!("Table system ({name})"), parameters),
        ("Oil column (linearised, rigid moving mass)".into(), oil),
        ("Capacities (closed forms)".into(), capacities),
        (
            format!("Linearisation at mid-stroke (centred spool, null pressures{payload})"),
            linearisation,
        ),
        (
            format!(
                "Loop, linearised and broken at the drive{payload}: {}",
                if m.stable {
                    "stable (Nyquist)"
                } else {
                    "UNSTABLE (Nyquist)"
                }
            ),
            margins,
        ),
        (
            "Integration (closed-loop runs' default)".into(),
            integration,
        ),
    ];
    let mut s = String::new();
    write_groups(&mut s, groups);
    s
}

/// `v` rounded to `digits` significant digits, in fixed notation, without trailing zeros
/// beyond the first decimal (`144.0`, `1.266`, `0.5`, `1613`). The units of the text form keep
/// every preset value between 10⁻³ and 10⁴, where fixed notation stays short.
pub fn significant(v: f64, digits: i32) -> String {
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

/// A titled group of printed lines: `[symbol, description, value, unit]` each.
type Group = (String, Vec<[String; 4]>);

/// Writes `groups` to `s`, each under its title after a blank line, their columns aligned
/// across all of them: numbers on their decimal point (integer parts right-aligned,
/// fractions with the point left-aligned).
fn write_groups(s: &mut String, mut groups: Vec<Group>) {
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
}

/// The widest of `cell_width` over every row of every group.
fn width(groups: &[Group], cell_width: impl Fn(&[String; 4]) -> usize) -> usize {
    groups
        .iter()
        .flat_map(|(_, r)| r.iter().map(&cell_width))
        .max()
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use platen_model::Preset;
    use platen_scenario::describe::SystemAnalysis;
    use platen_scenario::Model;

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

    /// Numbers align on their decimal point, and a full description has every group.
    #[test]
    fn the_model_text_groups_and_aligns_the_values() {
        let d = ModelDescription::of_preset(Preset::Lhpost2008, 13.8e6, true).unwrap();
        let s = model_text(&d);
        assert!(
            s.contains("(full form, Eq. 1–8, as its identified equivalent)"),
            "{s}"
        );
        assert!(s.contains("\n  F_pl+act  weight on the vertical bearings          1613      kN\n"));
        assert!(
            s.contains("\n  c_β       strut viscous coefficient                 290.0    kN·s/m\n")
        );
        assert!(s.contains("\n            acceleration, bare table                    4.2    g\n"));
        assert_eq!(s, text(&d));
    }

    /// The system's groups name the preset, and mark a system that differs from it.
    #[test]
    fn the_system_text_names_the_preset_and_the_scenarios_values() {
        let model = Model::Identified(
            Preset::Lhpost2008
                .identified(13.8e6)
                .unwrap()
                .build()
                .unwrap(),
        );
        let sys = platen_system::preset::lhpost_2008();
        let own = SystemAnalysis::new(Some("lhpost-2008".into()), sys, &model, 0.75, None);
        let s = system_text(&own.description());
        assert!(s.starts_with("\nTable system (lhpost-2008)\n"), "{s}");
        assert!(s.contains("  f_oc    oil column at mid-stroke, bare table (M = 144.0 t)"));
        assert!(s.contains("broken at the drive: stable (Nyquist)"));
        let mut changed = sys;
        changed.controller.displacement_gain_per_m *= 2.0;
        let laid =
            SystemAnalysis::new(Some("lhpost-2008".into()), changed, &model, 0.75, Some(4e4));
        let s = system_text(&laid.description());
        assert!(
            s.contains("Table system (lhpost-2008, with the scenario's values)"),
            "{s}"
        );
        assert!(s.contains("with the specimen (M + 40.0 t)"), "{s}");
    }
}
