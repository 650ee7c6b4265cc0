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
use Shown::{Count, Number, Optional};
use Value::{Field, NaturalFrequency, Physical};

/// Significant digits of every printed value: the paper quotes its parameters to 3–4.
pub const SIGNIFICANT_DIGITS: i32 = 4;

/// The whole text form: the model's groups and, with a table system, the system's.
pub fn text(d: &ModelDescription) -> String {
    let mut s = model_text(d);
    if let Some(system) = &d.table_system {
        s.push_str(&table_system_text(system));
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
    /// kN/(m/s)^α with the exponent α the value given (none: unknown).
    KilonewtonPerVelocityTo(Value),
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
    /// Hz.
    Hertz,
    /// Percent of a dimensionless ratio (friction coefficients).
    Percent,
    /// A dimensionless number.
    None,
}

impl Unit {
    /// The shown number and unit of SI value `v` of description `d`.
    fn show(self, v: f64, d: &ModelDescription) -> (f64, String) {
        match self {
            Unit::Tonne => (v / 1e3, "t".into()),
            Unit::MeganewtonPerMetre => (v / 1e6, "MN/m".into()),
            Unit::Kilonewton => (v / 1e3, "kN".into()),
            Unit::Meganewton => (v / 1e6, "MN".into()),
            Unit::KilonewtonPerVelocityTo(exponent) => {
                let unit = match exponent.of(d) {
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
            Unit::Hertz => (v, "Hz".into()),
            Unit::Percent => (v * 100.0, "%".into()),
            Unit::None => (v, String::new()),
        }
    }
}

/// `v` if it is finite (a value JSON can hold: the rows show what `--json` prints).
fn finite(v: f64) -> Option<f64> {
    Some(v).filter(|v| v.is_finite())
}

/// Where a quantity's SI value is in a model description.
#[derive(Clone, Copy)]
enum Value {
    /// A field of the description (not shown unless finite).
    Field(fn(&ModelDescription) -> f64),
    /// A physical parameter, by its key (not shown unless present and finite).
    Physical(&'static str),
    /// The natural frequency of the linear part, √(Kₑ/Mₑ)/2π, in Hz (shown when Kₑ and Mₑ
    /// are finite).
    NaturalFrequency,
}

impl Value {
    /// The value in `d`, if it is shown.
    fn of(self, d: &ModelDescription) -> Option<f64> {
        match self {
            Value::Field(field) => finite(field(d)),
            Value::Physical(key) => d.physical.get(key).copied().and_then(finite),
            Value::NaturalFrequency => {
                let (k, m) = (finite(d.stiffness_n_per_m)?, finite(d.effective_mass_kg)?);
                Some((k / m).sqrt() / std::f64::consts::TAU)
            }
        }
    }
}

/// A line of the model's text: symbol, description, value and how it is shown.
type Quantity = (&'static str, &'static str, Value, Unit);

/// The unit of the simulated viscous coefficient: kN/(m/s)^α, α the simulated exponent.
const VISCOUS: Unit = Unit::KilonewtonPerVelocityTo(Field(|d| d.viscous_exponent));

/// The unit of the actuators' physical viscous coefficient, to their exponent.
const ACTUATOR_VISCOUS: Unit = Unit::KilonewtonPerVelocityTo(Physical("viscous_exponent"));

/// The unit of the struts' physical viscous coefficient, to their exponent.
const STRUT_VISCOUS: Unit = Unit::KilonewtonPerVelocityTo(Physical("strut_viscous_exponent"));

/// The model simulated: its seven identified keys and the natural frequency they give.
#[rustfmt::skip]
const SIMULATED: [Quantity; 8] = [
    ("Mₑ",  "effective mass",
        Field(|d| d.effective_mass_kg),          Unit::Tonne),
    ("Kₑ",  "stiffness (hold-down struts)",
        Field(|d| d.stiffness_n_per_m),          Unit::MeganewtonPerMetre),
    ("F_μ", "Coulomb friction force",
        Field(|d| d.coulomb_force_n),            Unit::Kilonewton),
    ("Cₑ",  "viscous coefficient",
        Field(|d| d.viscous_coefficient),        VISCOUS),
    ("α",   "viscous exponent",
        Field(|d| d.viscous_exponent),           Unit::None),
    ("a",   "low-velocity friction force",
        Field(|d| d.low_velocity_force_n),       Unit::Kilonewton),
    ("b",   "low-velocity friction decay",
        Field(|d| d.low_velocity_decay_s_per_m), Unit::SecondPerMetre),
    ("fₙ",  "natural frequency √(Kₑ/Mₑ)/2π",
        NaturalFrequency,                        Unit::Hertz),
];

/// The quantities derived from the physical parameters (full model, Eq. 5–8).
#[rustfmt::skip]
const DERIVED: [Quantity; 9] = [
    ("Mₑ",     "effective mass (Eq. 5a)",
        Field(|d| d.full_effective_mass_kg),         Unit::Tonne),
    ("M̄ₑ",    "effective mass of one strut (Eq. 5b)",
        Field(|d| d.strut_effective_mass_kg),        Unit::Tonne),
    ("M̄′ₑ",   "strut rotational mass (Eq. 5c)",
        Field(|d| d.strut_rotational_mass_kg),       Unit::Tonne),
    ("Kₑ",     "stiffness (Eq. 6a)",
        Field(|d| d.full_stiffness_n_per_m),         Unit::MeganewtonPerMetre),
    ("K′ₑ",    "cubic stiffness (Eq. 6b)",
        Field(|d| d.cubic_stiffness_n_per_m),        Unit::MeganewtonPerMetre),
    ("F_hd",   "hold-down force 2p₀A",
        Field(|d| d.hold_down_force_n),              Unit::Meganewton),
    ("μ′ₑ",    "hold-down friction coefficient (Eq. 7b)",
        Field(|d| d.hold_down_friction_coefficient), Unit::Percent),
    ("μ⁽ⁱᵛ⁾ₑ", "hinge friction coefficient (Eq. 8)",
        Field(|d| d.hinge_friction_coefficient),     Unit::Percent),
    ("F_μ",    "Coulomb friction force (Eq. 7a)",
        Field(|d| d.full_coulomb_force_n),           Unit::Kilonewton),
];

/// The physical parameters of the full model, by their keys.
#[rustfmt::skip]
const PHYSICAL: [Quantity; 22] = [
    ("M_pl",     "platen mass",
        Physical("platen_mass_kg"),                    Unit::Tonne),
    ("M_act",    "moving mass of one actuator",
        Physical("actuator_moving_mass_kg"),           Unit::Tonne),
    ("M₁",       "strut piston mass",
        Physical("strut_piston_mass_kg"),              Unit::Tonne),
    ("M₂",       "strut cylinder mass",
        Physical("strut_cylinder_mass_kg"),            Unit::Tonne),
    ("h",        "strut height",
        Physical("strut_height_m"),                    Unit::Metre),
    ("l₀",       "strut piston length",
        Physical("strut_piston_length_m"),             Unit::Metre),
    ("p₀",       "nitrogen pre-charge pressure",
        Physical("hold_down_pressure_pa"),             Unit::Megapascal),
    ("A",        "strut chamber area",
        Physical("strut_area_m2"),                     Unit::SquareMetre),
    ("γ",        "gas heat capacity ratio",
        Physical("gas_heat_capacity_ratio"),           Unit::None),
    ("F_pl+act", "weight on the vertical bearings",
        Physical("supported_weight_n"),                Unit::Kilonewton),
    ("μ″ₑ",      "vertical bearing friction",
        Physical("bearing_friction_coefficient"),      Unit::Percent),
    ("μ‴ₑ",      "lateral bearing friction",
        Physical("lateral_friction_coefficient"),      Unit::Percent),
    ("F_l",      "normal force on the lateral bearings",
        Physical("lateral_normal_force_n"),            Unit::Kilonewton),
    ("μ_hg",     "strut swivel friction",
        Physical("hinge_swivel_friction_coefficient"), Unit::Percent),
    ("a",        "strut hinge radius",
        Physical("hinge_radius_m"),                    Unit::Metre),
    ("κ",        "hinge force-distribution factor",
        Physical("hinge_force_distribution_factor"),   Unit::None),
    ("Cₑ",       "actuator viscous coefficient",
        Physical("viscous_coefficient"),               ACTUATOR_VISCOUS),
    ("α",        "actuator viscous exponent",
        Physical("viscous_exponent"),                  Unit::None),
    ("c_β",      "strut viscous coefficient",
        Physical("strut_viscous_coefficient"),         STRUT_VISCOUS),
    ("β",        "strut viscous exponent",
        Physical("strut_viscous_exponent"),            Unit::None),
    ("a",        "low-velocity friction force",
        Physical("low_velocity_force_n"),              Unit::Kilonewton),
    ("b",        "low-velocity friction decay",
        Physical("low_velocity_decay_s_per_m"),        Unit::SecondPerMetre),
];

/// The table's limits.
#[rustfmt::skip]
const LIMITS: [Quantity; 4] = [
    ("", "stroke, either way",       Field(|d| d.limits.stroke_m),          Unit::Metre),
    ("", "velocity",                 Field(|d| d.limits.velocity_m_s),      Unit::MetrePerSecond),
    ("", "acceleration, bare table", Field(|d| d.limits.acceleration_m_s2), Unit::Gravity),
    ("", "actuator force",           Field(|d| d.limits.force_n),           Unit::Meganewton),
];

/// The printed cells of `quantities` in `d`; a quantity without a shown value is left out.
fn rows(d: &ModelDescription, quantities: &[Quantity]) -> Vec<[String; 4]> {
    quantities
        .iter()
        .filter_map(|&(sym, what, value, unit)| {
            let (shown, unit) = unit.show(value.of(d)?, d);
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
    let groups: Vec<Group> = [
        (heading, &SIMULATED[..]),
        (
            "Derived from the physical parameters (full model, Eq. 5–8)",
            &DERIVED,
        ),
        ("Physical parameters (full model)", &PHYSICAL),
        ("Table limits", &LIMITS),
    ]
    .into_iter()
    .map(|(title, quantities)| (title.to_owned(), rows(d, quantities)))
    .collect();
    write_groups(&mut s, groups);
    s
}

/// A printed value of the table system's text.
#[derive(Clone, Copy)]
enum Shown {
    /// A number, to [`SIGNIFICANT_DIGITS`].
    Number(f64),
    /// A count.
    Count(u32),
    /// A number there may be none of: `none`, without a unit, when there is none.
    Optional(Option<f64>),
}

/// A line of the table system's text: symbol, description, value and unit.
type Line<'a> = (&'static str, &'a str, Shown, &'static str);

/// The group titled `title` of `lines`, printed.
fn group(title: String, lines: &[Line]) -> Group {
    let num = |x: f64| significant(x, SIGNIFICANT_DIGITS);
    let cells = lines.iter().map(|&(sym, what, value, unit)| {
        let (value, unit) = match value {
            Number(x) => (num(x), unit),
            Count(n) => (n.to_string(), unit),
            Optional(x) => (
                x.map_or("none".to_owned(), num),
                if x.is_some() { unit } else { "" },
            ),
        };
        [sym.to_owned(), what.to_owned(), value, unit.to_owned()]
    });
    (title, cells.collect())
}

/// The table system's groups: its parameters, oil column, capacities, linearisation, loop
/// and integration step, in engineering units.
pub fn table_system_text(d: &SystemDescription) -> String {
    let groups = vec![
        system_parameters(d),
        oil_column(d),
        capacities(d),
        linearisation(d),
        loop_margins(d),
        integration(d),
    ];
    let mut s = String::new();
    write_groups(&mut s, groups);
    s
}

/// The system's name: its preset's (marked when the scenario lays values over them) or the
/// scenario's.
fn system_name(d: &SystemDescription) -> String {
    d.preset
        .as_deref()
        .map_or("given by the scenario".to_owned(), |p| {
            // The preset's own values, or the scenario's laid over them.
            let own = platen_system::preset::by_name(p).map_or(true, |s| s == d.system);
            let laid = if own {
                ""
            } else {
                ", with the scenario's values"
            };
            format!("{p}{laid}")
        })
}

/// The system's parameters: actuators, oil, valves, supply and controller.
fn system_parameters(d: &SystemDescription) -> Group {
    let (p, a, v) = (&d.system, d.system.actuator(), d.system.servo_valve());
    let num = |x: f64| significant(x, SIGNIFICANT_DIGITS);
    let rated = format!(
        "rated flow of one valve (at {} MPa drop)",
        num(v.rated_pressure_drop_pa / 1e6)
    );
    let supply = match p.supply() {
        Supply::Constant => "supply pressure (constant)".to_owned(),
        Supply::Accumulator(acc) => format!(
            "supply pressure (accumulator, precharge {} MPa)",
            num(acc.precharge_pressure_pa / 1e6)
        ),
    };
    #[rustfmt::skip]
    let lines: [Line; 12] = [
        ("n",   "actuators",
            Count(a.count),                      ""),
        ("A_a", "cap-side area",
            Number(a.cap_area_m2),               "m²"),
        ("A_b", "rod-side area",
            Number(a.rod_area_m2),               "m²"),
        ("V_a", "cap-side chamber volume at mid-stroke",
            Number(a.cap_volume_m3),             "m³"),
        ("V_b", "rod-side chamber volume at mid-stroke",
            Number(a.rod_volume_m3),             "m³"),
        ("β",   "oil bulk modulus",
            Number(p.oil_bulk_modulus_pa() / 1e9), "GPa"),
        ("m",   "servo-valves per actuator",
            Count(v.count),                      ""),
        ("Q_r", &rated,
            Number(v.rated_flow_m3_s * 60e3),    "l/min"),
        ("f_v", "spool natural frequency",
            Number(v.natural_frequency_hz),      "Hz"),
        ("P_s", &supply,
            Number(p.supply_pressure_pa() / 1e6),  "MPa"),
        ("P_R", "return pressure",
            Number(p.return_pressure_pa() / 1e6),  "MPa"),
        ("f_c", "controller sample rate",
            Number(p.controller().sample_rate_hz), "Hz"),
    ];
    group(format!("Table system ({})", system_name(d)), &lines)
}

/// The oil column's frequency at mid-stroke (bare and with the specimen), retracted and
/// extended.
fn oil_column(d: &SystemDescription) -> Group {
    let num = |x: f64| significant(x, SIGNIFICANT_DIGITS);
    let with_specimen = if d.specimen_mass_kg.is_some() {
        ", with the specimen"
    } else {
        ""
    };
    let bare = format!(
        "oil column at mid-stroke, bare table (M = {} t)",
        num(d.model_mass_kg / 1e3)
    );
    let loaded = d.specimen_mass_kg.map(|kg| {
        format!(
            "oil column at mid-stroke, with the specimen (M + {} t)",
            num(kg / 1e3)
        )
    });
    let retracted = format!(
        "oil column retracted, u = −{} m{with_specimen}",
        num(d.stroke_m)
    );
    let extended = format!(
        "oil column extended, u = +{} m{with_specimen}",
        num(d.stroke_m)
    );
    let mut lines = vec![(
        "f_oc",
        bare.as_str(),
        Number(d.oil_column_frequency_hz),
        "Hz",
    )];
    if let (Some(f), Some(what)) = (d.oil_column_frequency_with_specimen_hz, &loaded) {
        lines.push(("f_oc", what, Number(f), "Hz"));
    }
    lines.push((
        "f_oc",
        &retracted,
        Number(d.oil_column_frequency_retracted_hz),
        "Hz",
    ));
    lines.push((
        "f_oc",
        &extended,
        Number(d.oil_column_frequency_extended_hz),
        "Hz",
    ));
    group("Oil column (linearised, rigid moving mass)".into(), &lines)
}

/// The table's capacities by the closed forms.
fn capacities(d: &SystemDescription) -> Group {
    #[rustfmt::skip]
    let lines: [Line; 5] = [
        ("v_ext",  "valve-limited velocity, extending (no load)",
            Number(d.valve_limited_velocity_extend_m_s),  "m/s"),
        ("v_ret",  "valve-limited velocity, retracting (no load)",
            Number(d.valve_limited_velocity_retract_m_s), "m/s"),
        ("Q_max",  "valve flow capacity (null drop on each land)",
            Number(d.valve_flow_capacity_m3_s),           "m³/s"),
        ("F_push", "force capacity, pushing (stall)",
            Number(d.force_capacity_push_n / 1e6),        "MN"),
        ("F_pull", "force capacity, pulling (stall)",
            Number(d.force_capacity_pull_n / 1e6),        "MN"),
    ];
    group("Capacities (closed forms)".into(), &lines)
}

/// The end of a loop group's title: the specimen as a rigid payload, when there is one.
fn payload(d: &SystemDescription) -> &'static str {
    if d.specimen_mass_kg.is_some() {
        "; the specimen as a rigid payload"
    } else {
        ""
    }
}

/// The linearisation at mid-stroke.
fn linearisation(d: &SystemDescription) -> Group {
    let lin = &d.linearisation;
    let damping = format!("secant damping at {} m/s", lin.damping_secant_speed_m_s);
    let title = format!(
        "Linearisation at mid-stroke (centred spool, null pressures{})",
        payload(d)
    );
    #[rustfmt::skip]
    let lines: [Line; 10] = [
        ("p_a0",  "null pressure, cap side",
            Number(d.null_pressure_a_pa / 1e6),          "MPa"),
        ("p_b0",  "null pressure, rod side",
            Number(d.null_pressure_b_pa / 1e6),          "MPa"),
        ("K_qa",  "flow gain, cap-side land (one actuator)",
            Number(lin.flow_gain_a_m3_s),                "m³/s"),
        ("K_qb",  "flow gain, rod-side land (one actuator)",
            Number(lin.flow_gain_b_m3_s),                "m³/s"),
        ("K_c",   "flow-pressure coefficient (critically centred)",
            Number(lin.flow_pressure_m3_s_per_pa * 1e9), "l/s/MPa"),
        ("V_a/β", "hydraulic compliance, chamber a",
            Number(lin.compliance_a_m3_per_pa * 1e9),    "l/MPa"),
        ("V_b/β", "hydraulic compliance, chamber b",
            Number(lin.compliance_b_m3_per_pa * 1e9),    "l/MPa"),
        ("M",     "moving mass",
            Number(lin.mass_kg / 1e3),                   "t"),
        ("K",     "restoring stiffness",
            Number(lin.stiffness_n_per_m / 1e6),         "MN/m"),
        ("C",     &damping,
            Number(lin.damping_n_s_per_m / 1e3),         "kN·s/m"),
    ];
    group(title, &lines)
}

/// The loop broken at the drive: its margins, and the closed loop's peak and bandwidth.
fn loop_margins(d: &SystemDescription) -> Group {
    let m = &d.loop_margins;
    let stability = if m.stable {
        "stable (Nyquist)"
    } else {
        "UNSTABLE (Nyquist)"
    };
    let title = format!(
        "Loop, linearised and broken at the drive{}: {stability}",
        payload(d)
    );
    #[rustfmt::skip]
    let lines: [Line; 9] = [
        ("GM",     "gain margin",
            Optional(m.gain_margin_db),           "dB"),
        ("f_pc",   "phase crossover",
            Optional(m.phase_crossover_hz),       "Hz"),
        ("PM",     "phase margin",
            Optional(m.phase_margin_deg),         "°"),
        ("f_gc",   "gain crossover",
            Optional(m.gain_crossover_hz),        "Hz"),
        ("|U/R|",  "peak closed-loop gain, command → displacement",
            Number(m.peak_gain),                  ""),
        ("f_peak", "at",
            Number(m.peak_gain_hz),               "Hz"),
        ("f_bw",   "bandwidth (|U/R| below −3 dB above it)",
            Optional(d.closed_loop_bandwidth_hz), "Hz"),
        ("|U/R|",  "lowest closed-loop gain below the peak",
            Number(d.closed_loop_min_gain),       ""),
        ("f_min",  "at",
            Number(d.closed_loop_min_gain_hz),    "Hz"),
    ];
    group(title, &lines)
}

/// The closed-loop runs' default integration step.
fn integration(d: &SystemDescription) -> Group {
    #[rustfmt::skip]
    let lines: [Line; 2] = [
        ("k", "RK4 steps per controller period", Count(d.steps_per_controller_period), ""),
        ("h", "step T/k",                        Number(d.step_s * 1e3),               "ms"),
    ];
    group("Integration (closed-loop runs' default)".into(), &lines)
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
        let s = table_system_text(&own.description());
        assert!(s.starts_with("\nTable system (lhpost-2008)\n"), "{s}");
        assert!(s.contains("  f_oc    oil column at mid-stroke, bare table (M = 144.0 t)"));
        assert!(s.contains("broken at the drive: stable (Nyquist)"));
        let mut changed = sys.into_parts();
        changed.controller.displacement_gain_per_m *= 2.0;
        let changed = platen_system::TableSystem::new(changed, 0.0).unwrap();
        let laid =
            SystemAnalysis::new(Some("lhpost-2008".into()), changed, &model, 0.75, Some(4e4));
        let s = table_system_text(&laid.description());
        assert!(
            s.contains("Table system (lhpost-2008, with the scenario's values)"),
            "{s}"
        );
        assert!(s.contains("with the specimen (M + 40.0 t)"), "{s}");
    }
}
