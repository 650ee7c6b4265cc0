//! `platen model`: a preset's parameters and derived quantities, and with `--system` or
//! `--scenario` the table system's closed forms and linearised loop.
//!
//! `--json` prints [`platen_scenario::describe_model`]'s object as it is (SI, the contract's
//! keys). The text form reads the same object and groups it for a person: the model the
//! verbs simulate, the quantities derived from the full model (Eq. 5–8), the physical
//! parameters and the table's limits, in the units an engineer reads (t, MN/m, kN, MPa, g)
//! with four significant digits.
//!
//! With a table system (`--system PRESET`, or a `--scenario` whose `table_system` is read
//! with its model and specimen) the description gains a `table_system` object: the system's
//! parameters (in the scenario format), the oil-column frequency at mid-stroke (bare, with
//! the specimen as a rigid payload) and at the stroke's ends, the valve-limited velocities,
//! the flow and force capacities, the linearisation about mid-stroke, the loop's margins and
//! closed-loop peak and bandwidth, and the default RK4 step per controller period; `--plot`
//! draws the linearised loop's Bode plots ([`platen_report::system_figures`]).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context, Result};
use serde_json::{json, Map, Value};

use platen_model::{IdentifiedKey, PhysicalKey, Preset, STANDARD_GRAVITY_M_S2};
use platen_report::system_figures::{self, LoopCurve};
use platen_report::FigureSize;
use platen_scenario::{Model, Scenario};
use platen_system::{Linearisation, Margins, Mechanics, Supply, TableSystem, SECANT_SPEED_M_S};

use crate::Form;

/// The options of `platen model`.
pub struct Options<'a> {
    /// Model preset (without a scenario).
    pub preset: &'a str,
    /// Hold-down pressure, MPa (without a scenario; default the preset's).
    pub pressure_mpa: Option<f64>,
    /// The form described (without a scenario).
    pub form: Form,
    /// A table-system preset (replaces a scenario's `table_system`).
    pub system: Option<&'a str>,
    /// A scenario whose model, table system and specimen are described.
    pub scenario: Option<&'a Path>,
    /// Print JSON on stdout.
    pub json: bool,
    /// Folder for the Bode figures (SVG and PNG).
    pub plot: Option<&'a Path>,
    /// Size of the figures.
    pub size: FigureSize,
}

pub fn run(o: &Options<'_>) -> Result<()> {
    if o.system.is_none() && o.scenario.is_none() {
        if o.plot.is_some() {
            bail!(
                "--plot draws the Bode plots of a table system's loop: give --system PRESET \
                 ({}) or a --scenario with a `table_system`",
                platen_system::preset::PRESET_NAMES
            );
        }
        return run_preset(o.preset, o.pressure_mpa, o.form, o.json);
    }
    let subject = match o.scenario {
        Some(path) => Subject::from_scenario(path, o.system)?,
        None => Subject::from_preset(o.preset, o.pressure_mpa, o.form, o.system)?,
    };
    let described = subject
        .system
        .as_ref()
        .map(|s| LoopDescription::new(s, &subject));
    let written = match (&described, o.plot) {
        (None, Some(_)) => bail!(
            "--plot draws the Bode plots of a table system's loop, and {} has no \
             `table_system`: give --system PRESET ({})",
            o.scenario
                .map_or("the scenario".into(), |p| p.display().to_string()),
            platen_system::preset::PRESET_NAMES
        ),
        (Some(d), Some(_)) => platen_report::write_outputs(
            o.plot,
            None,
            &o.size,
            || d.figures(&subject.name),
            |_, _| String::new(),
        )?,
        _ => Vec::new(),
    };
    let mut value = subject.description.clone();
    if o.json {
        if let Some(map) = value.as_object_mut() {
            if let Some(d) = &described {
                map.insert("table_system".into(), d.json());
            }
            if o.plot.is_some() {
                map.insert(
                    "figures".into(),
                    crate::simulate::figure_list(&written).into(),
                );
            }
        }
        outln!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    let mut s = String::new();
    for line in &subject.header {
        let _ = writeln!(s, "{line}");
    }
    s.push_str(&text(&value));
    if let Some(d) = &described {
        s.push_str(&d.text());
    }
    out!("{s}");
    if !written.is_empty() {
        outln!("\nwrote {} figure files (SVG and PNG):", written.len());
        for path in &written {
            outln!("  {}", path.display());
        }
    }
    Ok(())
}

/// `platen model` without a table system: the preset's description, as it always was.
fn run_preset(preset: &str, pressure_mpa: Option<f64>, form: Form, json_out: bool) -> Result<()> {
    let preset = Preset::from_name(preset)?;
    let pressure_pa = pressure_pa(preset, pressure_mpa)?;
    let value = platen_scenario::describe_model(preset, pressure_pa, matches!(form, Form::Full))?;
    if json_out {
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        out!("{}", text(&value));
    }
    Ok(())
}

/// `--pressure-mpa` in Pa (default the preset's nominal pressure).
fn pressure_pa(preset: Preset, pressure_mpa: Option<f64>) -> Result<f64> {
    Ok(match pressure_mpa {
        Some(p) if platen_scenario::units::expected_pressure_mpa(p).is_some() => {
            bail!(
                "--pressure-mpa {}",
                platen_scenario::units::check_pressure_mpa(p).unwrap_err()
            )
        }
        Some(p) => p * 1e6,
        None => preset.nominal_pressure_pa(),
    })
}

/// A table system and the preset it came from.
struct SystemChoice {
    /// The preset's name (`None`: explicit values in a scenario).
    preset: Option<String>,
    /// The system.
    system: TableSystem,
}

/// The table-system preset `name`, checked over the stroke `±stroke_m`.
fn system_preset(name: &str, stroke_m: f64) -> Result<SystemChoice> {
    let system =
        platen_system::preset::by_name(name).with_context(|| format!("--system {name}"))?;
    system
        .validate(stroke_m)
        .with_context(|| format!("--system {name} over the stroke ±{stroke_m} m"))?;
    Ok(SystemChoice {
        preset: Some(name.to_owned()),
        system,
    })
}

/// What `platen model` describes with a table system or a scenario.
struct Subject {
    /// The model's description (`describe_model`, with a scenario's values laid in).
    description: Value,
    /// The model.
    model: Model,
    /// The table's stroke, either way, m.
    stroke_m: f64,
    /// The specimen's number of storeys and mass, kg.
    specimen: Option<(usize, f64)>,
    /// The table system, if any.
    system: Option<SystemChoice>,
    /// What the figures' titles name.
    name: String,
    /// Lines printed before the model's text.
    header: Vec<String>,
}

impl Subject {
    /// The model preset at `pressure_mpa` in `form`, and the table-system preset `system`.
    fn from_preset(
        preset: &str,
        pressure_mpa: Option<f64>,
        form: Form,
        system: Option<&str>,
    ) -> Result<Self> {
        let preset = Preset::from_name(preset)?;
        let pressure_pa = pressure_pa(preset, pressure_mpa)?;
        let full = matches!(form, Form::Full);
        let description = platen_scenario::describe_model(preset, pressure_pa, full)?;
        let model = if full {
            Model::Full(Box::new(preset.physical(pressure_pa)?.build()?))
        } else {
            Model::Identified(preset.identified(pressure_pa)?.build()?)
        };
        let stroke_m = preset.limits().stroke_m;
        let system = system.map(|s| system_preset(s, stroke_m)).transpose()?;
        Ok(Self {
            description,
            model,
            stroke_m,
            specimen: None,
            name: system
                .as_ref()
                .and_then(|s| s.preset.clone())
                .unwrap_or_else(|| preset.name().to_owned()),
            system,
            header: Vec::new(),
        })
    }

    /// The model, table system and specimen of the scenario at `path` (its excitation,
    /// integrator, initial state and duration are not read), with the table system replaced
    /// by the preset `system` if given.
    fn from_scenario(path: &Path, system: Option<&str>) -> Result<Self> {
        let mut file: Value = platen_io::json::parse_json_file(path)?;
        let Some(obj) = file.as_object_mut() else {
            // The scenario reader's own message for a file that is not an object.
            Scenario::load(path)?;
            bail!("{}: expected a JSON object", path.display());
        };
        let given_preset = obj
            .get("table_system")
            .and_then(|t| t.get("preset"))
            .and_then(Value::as_str)
            .map(str::to_owned);
        for key in ["excitation", "duration_s", "integrator", "initial"] {
            obj.remove(key);
        }
        // A few samples of a small sine: a valid command that is never run.
        obj.insert(
            "excitation".into(),
            json!({"sine_motion": {"amplitude_m": 1e-3, "frequency_hz": 1.0, "sample_rate_hz": 1024.0}}),
        );
        obj.insert("duration_s".into(), json!(0.01));
        let scenario = Scenario::from_file(
            path,
            platen_scenario::file::parse(path, &serde_json::to_string(&file)?)?,
        )?;
        let stroke_m = scenario.limits.stroke_m;
        let system = match system {
            Some(name) => Some(system_preset(name, stroke_m)?),
            None => scenario.closed_loop.as_ref().map(|cl| SystemChoice {
                preset: given_preset,
                system: cl.system,
            }),
        };
        let specimen = scenario
            .specimen
            .as_ref()
            .map(|sp| (sp.len(), sp.total_mass_kg()));
        let mut header = vec![format!("scenario {} ({})", path.display(), scenario.name)];
        let overrides: Vec<String> = scenario
            .overrides
            .values()
            .iter()
            .map(|(key, value)| format!("{} = {value}", key.name()))
            .collect();
        if !overrides.is_empty() {
            header.push(format!(
                "model values laid over the preset's: {}",
                overrides.join(", ")
            ));
        }
        if let Some((storeys, mass)) = specimen {
            header.push(format!(
                "specimen: {storeys} storey{}, {} t in all (a rigid payload in the linearised loop)",
                if storeys == 1 { "" } else { "s" },
                significant(mass / 1e3, SIGNIFICANT_DIGITS)
            ));
        }
        Ok(Self {
            description: scenario_description(path, &scenario)?,
            model: scenario.model.clone(),
            stroke_m,
            specimen,
            system,
            name: scenario.name.clone(),
            header,
        })
    }
}

/// [`platen_scenario::describe_model`] of a scenario's preset, pressure and form with the
/// scenario's own model laid in: its seven identified keys (for the full form, its identified
/// equivalent), its physical parameters and derived quantities (full form), its limits, and
/// `scenario`, `model_overrides` and `specimen`.
fn scenario_description(path: &Path, s: &Scenario) -> Result<Value> {
    let mut d = platen_scenario::describe_model(
        s.preset,
        s.hold_down_pressure_pa,
        s.model.form() == "full",
    )?;
    let Some(map) = d.as_object_mut() else {
        return Ok(d);
    };
    let seven = match &s.model {
        Model::Identified(m) => *m.params(),
        Model::Full(m) => m.identified_equivalent(),
    };
    for key in IdentifiedKey::ALL {
        map.insert(key.name().into(), json!(seven.get(key)));
    }
    if let Model::Full(m) = &s.model {
        if let Some(physical) = map.get_mut("physical").and_then(Value::as_object_mut) {
            for key in PhysicalKey::all() {
                physical.insert(key.name().into(), json!(m.params().get(key)));
            }
        }
        let d = m.derived();
        for (key, value) in [
            ("cubic_stiffness_n_per_m", d.cubic_stiffness_n_per_m),
            ("strut_effective_mass_kg", d.strut_effective_mass_kg),
            ("strut_rotational_mass_kg", d.strut_rotational_mass_kg),
            ("hold_down_force_n", d.hold_down_force_n),
            ("hinge_friction_coefficient", d.hinge_friction_coefficient),
            (
                "hold_down_friction_coefficient",
                d.hold_down_friction_coefficient,
            ),
            ("full_effective_mass_kg", d.effective_mass_kg),
            ("full_stiffness_n_per_m", d.stiffness_n_per_m),
            ("full_coulomb_force_n", d.coulomb_force_n),
        ] {
            map.insert(key.into(), json!(value));
        }
    }
    let l = &s.limits;
    map.insert(
        "limits".into(),
        json!({
            "stroke_m": l.stroke_m,
            "velocity_m_s": l.velocity_m_s,
            "acceleration_m_s2": l.acceleration_m_s2,
            "force_n": l.force_n,
        }),
    );
    map.insert("scenario".into(), json!(path.display().to_string()));
    let overrides: Map<String, Value> = s
        .overrides
        .values()
        .iter()
        .map(|(key, value)| (key.name().to_owned(), json!(value)))
        .collect();
    if !overrides.is_empty() {
        map.insert("model_overrides".into(), Value::Object(overrides));
    }
    if let Some(sp) = &s.specimen {
        map.insert(
            "specimen".into(),
            json!({"storeys": sp.len(), "total_mass_kg": sp.total_mass_kg()}),
        );
    }
    Ok(d)
}

/// The table system's closed forms and linearised loop, for the text, the JSON and the
/// figures.
struct LoopDescription<'a> {
    choice: &'a SystemChoice,
    /// The model's mass at mid-stroke, kg.
    model_mass_kg: f64,
    /// The specimen's mass, kg.
    specimen_kg: Option<f64>,
    stroke_m: f64,
    /// The loop about mid-stroke driving the bare table.
    bare: Linearisation,
    /// The loop driving the table with the specimen as a rigid payload.
    loaded: Option<Linearisation>,
    /// The margins of the loop the table drives (with the specimen, if any).
    margins: Margins,
    /// Its closed loop's bandwidth and lowest gain below it.
    passband: system_figures::Passband,
    /// Default RK4 steps per controller period.
    steps: u32,
}

impl<'a> LoopDescription<'a> {
    fn new(choice: &'a SystemChoice, subject: &Subject) -> Self {
        let system = &choice.system;
        let mechanics = |payload: f64| match &subject.model {
            Model::Identified(m) => Mechanics::of_model(m, payload),
            Model::Full(m) => Mechanics::of_model(&**m, payload),
        };
        let bare = system.linearise(mechanics(0.0), 0.0);
        let specimen_kg = subject.specimen.map(|s| s.1);
        let loaded = specimen_kg.map(|m| system.linearise(mechanics(m), 0.0));
        let driven = loaded.as_ref().unwrap_or(&bare);
        Self {
            choice,
            model_mass_kg: bare.mechanics.mass_kg,
            specimen_kg,
            stroke_m: subject.stroke_m,
            margins: system.margins(driven),
            passband: system_figures::passband(system, driven),
            steps: system.default_steps_per_period(driven.mechanics.mass_kg, subject.stroke_m),
            bare,
            loaded,
        }
    }

    /// The linearisation of the loop the table drives (with the specimen, if any).
    fn driven(&self) -> &Linearisation {
        self.loaded.as_ref().unwrap_or(&self.bare)
    }

    /// The Bode figures (the loop with the specimen first, then the bare table).
    fn figures(&self, name: &str) -> Vec<platen_report::Figure> {
        let mut curves = Vec::new();
        if let (Some(lin), Some(kg)) = (self.loaded, self.specimen_kg) {
            curves.push(LoopCurve {
                label: format!(
                    "with the specimen (rigid, {} t)",
                    significant(kg / 1e3, SIGNIFICANT_DIGITS)
                ),
                linearisation: lin,
            });
        }
        curves.push(LoopCurve {
            label: if curves.is_empty() {
                String::new()
            } else {
                "bare table".into()
            },
            linearisation: self.bare,
        });
        system_figures::figures(name, &self.choice.system, &curves, &self.margins)
    }

    /// The oil-column frequencies: mid-stroke bare, with the specimen, at `−stroke` and
    /// `+stroke` (with the specimen), Hz.
    fn oil_columns_hz(&self) -> (f64, Option<f64>, f64, f64) {
        let sys = &self.choice.system;
        let driven = self.driven().mechanics.mass_kg;
        (
            sys.oil_column_frequency_hz(self.model_mass_kg, 0.0),
            self.loaded
                .map(|l| sys.oil_column_frequency_hz(l.mechanics.mass_kg, 0.0)),
            sys.oil_column_frequency_hz(driven, -self.stroke_m),
            sys.oil_column_frequency_hz(driven, self.stroke_m),
        )
    }

    /// The `table_system` object of `--json` (SI).
    fn json(&self) -> Value {
        let sys = &self.choice.system;
        let caps = sys.capacities();
        let (mid, with, retracted, extended) = self.oil_columns_hz();
        let (p_a0, p_b0) = sys.null_pressures_pa();
        let lin = self.driven();
        let m = &self.margins;
        let period = sys.controller.period_s();
        let mut map = Map::new();
        let mut put = |key: &str, value: Value| {
            map.insert(key.to_owned(), value);
        };
        put("preset", json!(self.choice.preset));
        put("parameters", parameters(sys));
        put("model_mass_kg", json!(self.model_mass_kg));
        if let Some(kg) = self.specimen_kg {
            put("specimen_mass_kg", json!(kg));
        }
        put("stroke_m", json!(self.stroke_m));
        put("oil_column_frequency_hz", json!(mid));
        if let Some(f) = with {
            put("oil_column_frequency_with_specimen_hz", json!(f));
        }
        put("oil_column_frequency_retracted_hz", json!(retracted));
        put("oil_column_frequency_extended_hz", json!(extended));
        put(
            "valve_limited_velocity_extend_m_s",
            json!(caps.extend_velocity_m_s),
        );
        put(
            "valve_limited_velocity_retract_m_s",
            json!(caps.retract_velocity_m_s),
        );
        put("valve_flow_capacity_m3_s", json!(caps.valve_flow_m3_s));
        put("force_capacity_push_n", json!(caps.push_force_n));
        put("force_capacity_pull_n", json!(caps.pull_force_n));
        put("null_pressure_a_pa", json!(p_a0));
        put("null_pressure_b_pa", json!(p_b0));
        put(
            "linearisation",
            json!({
                "flow_gain_a_m3_s": lin.flow_gain_a_m3_s,
                "flow_gain_b_m3_s": lin.flow_gain_b_m3_s,
                "flow_pressure_m3_s_per_pa": lin.flow_pressure_m3_s_per_pa,
                "compliance_a_m3_per_pa": lin.compliance_a_m3_per_pa,
                "compliance_b_m3_per_pa": lin.compliance_b_m3_per_pa,
                "mass_kg": lin.mechanics.mass_kg,
                "stiffness_n_per_m": lin.mechanics.stiffness_n_per_m,
                "damping_n_s_per_m": lin.mechanics.damping_n_s_per_m,
                "damping_secant_speed_m_s": SECANT_SPEED_M_S,
            }),
        );
        put(
            "loop_margins",
            json!({
                "stable": m.stable,
                "gain_margin_db": m.gain_margin_db,
                "phase_crossover_hz": m.phase_crossover_hz,
                "phase_margin_deg": m.phase_margin_deg,
                "gain_crossover_hz": m.gain_crossover_hz,
                "peak_gain": m.peak_gain,
                "peak_gain_hz": m.peak_gain_hz,
            }),
        );
        put(
            "closed_loop_bandwidth_hz",
            json!(self.passband.bandwidth_hz),
        );
        put("closed_loop_min_gain", json!(self.passband.min_gain));
        put("closed_loop_min_gain_hz", json!(self.passband.min_gain_hz));
        put(
            "controller_sample_rate_hz",
            json!(sys.controller.sample_rate_hz),
        );
        put("steps_per_controller_period", json!(self.steps));
        put("step_s", json!(period / f64::from(self.steps)));
        Value::Object(map)
    }

    /// The text form: the system's parameters, oil column, capacities, linearisation, loop
    /// and integration step, in engineering units.
    fn text(&self) -> String {
        let sys = &self.choice.system;
        let a = &sys.actuator;
        let v = &sys.servo_valve;
        let c = &sys.controller;
        let caps = sys.capacities();
        let (mid, with, retracted, extended) = self.oil_columns_hz();
        let (p_a0, p_b0) = sys.null_pressures_pa();
        let lin = self.driven();
        let m = &self.margins;
        let num = |x: f64| significant(x, SIGNIFICANT_DIGITS);
        let opt = |x: Option<f64>| x.map_or("none".to_owned(), num);
        let row = |sym: &str, what: String, value: String, unit: &str| {
            [sym.to_owned(), what, value, unit.to_owned()]
        };
        let supply = match &sys.supply {
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
                num(sys.oil_bulk_modulus_pa / 1e9),
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
            row("P_s", supply, num(sys.supply_pressure_pa / 1e6), "MPa"),
            row(
                "P_R",
                "return pressure".into(),
                num(sys.return_pressure_pa / 1e6),
                "MPa",
            ),
            row(
                "f_c",
                "controller sample rate".into(),
                num(c.sample_rate_hz),
                "Hz",
            ),
        ];
        let with_specimen = if self.specimen_kg.is_some() {
            ", with the specimen"
        } else {
            ""
        };
        let mut oil = vec![row(
            "f_oc",
            format!(
                "oil column at mid-stroke, bare table (M = {} t)",
                num(self.model_mass_kg / 1e3)
            ),
            num(mid),
            "Hz",
        )];
        if let (Some(f), Some(kg)) = (with, self.specimen_kg) {
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
                num(self.stroke_m)
            ),
            num(retracted),
            "Hz",
        ));
        oil.push(row(
            "f_oc",
            format!(
                "oil column extended, u = +{} m{with_specimen}",
                num(self.stroke_m)
            ),
            num(extended),
            "Hz",
        ));
        let capacities = vec![
            row(
                "v_ext",
                "valve-limited velocity, extending (no load)".into(),
                num(caps.extend_velocity_m_s),
                "m/s",
            ),
            row(
                "v_ret",
                "valve-limited velocity, retracting (no load)".into(),
                num(caps.retract_velocity_m_s),
                "m/s",
            ),
            row(
                "Q_max",
                "valve flow capacity (null drop on each land)".into(),
                num(caps.valve_flow_m3_s),
                "m³/s",
            ),
            row(
                "F_push",
                "force capacity, pushing (stall)".into(),
                num(caps.push_force_n / 1e6),
                "MN",
            ),
            row(
                "F_pull",
                "force capacity, pulling (stall)".into(),
                num(caps.pull_force_n / 1e6),
                "MN",
            ),
        ];
        let linearisation = vec![
            row(
                "p_a0",
                "null pressure, cap side".into(),
                num(p_a0 / 1e6),
                "MPa",
            ),
            row(
                "p_b0",
                "null pressure, rod side".into(),
                num(p_b0 / 1e6),
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
            row(
                "M",
                "moving mass".into(),
                num(lin.mechanics.mass_kg / 1e3),
                "t",
            ),
            row(
                "K",
                "restoring stiffness".into(),
                num(lin.mechanics.stiffness_n_per_m / 1e6),
                "MN/m",
            ),
            row(
                "C",
                format!("secant damping at {SECANT_SPEED_M_S} m/s"),
                num(lin.mechanics.damping_n_s_per_m / 1e3),
                "kN·s/m",
            ),
        ];
        let band = &self.passband;
        let margins = vec![
            row(
                "GM",
                "gain margin".into(),
                opt(m.gain_margin_db),
                if m.gain_margin_db.is_some() { "dB" } else { "" },
            ),
            row(
                "f_pc",
                "phase crossover".into(),
                opt(m.phase_crossover_hz),
                if m.phase_crossover_hz.is_some() {
                    "Hz"
                } else {
                    ""
                },
            ),
            row(
                "PM",
                "phase margin".into(),
                opt(m.phase_margin_deg),
                if m.phase_margin_deg.is_some() {
                    "°"
                } else {
                    ""
                },
            ),
            row(
                "f_gc",
                "gain crossover".into(),
                opt(m.gain_crossover_hz),
                if m.gain_crossover_hz.is_some() {
                    "Hz"
                } else {
                    ""
                },
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
                opt(band.bandwidth_hz),
                if band.bandwidth_hz.is_some() {
                    "Hz"
                } else {
                    ""
                },
            ),
            row(
                "|U/R|",
                "lowest closed-loop gain below the peak".into(),
                num(band.min_gain),
                "",
            ),
            row("f_min", "at".into(), num(band.min_gain_hz), "Hz"),
        ];
        let period = c.period_s();
        let integration = vec![
            row(
                "k",
                "RK4 steps per controller period".into(),
                self.steps.to_string(),
                "",
            ),
            row(
                "h",
                "step T/k".into(),
                num(period / f64::from(self.steps) * 1e3),
                "ms",
            ),
        ];
        let name = self
            .choice
            .preset
            .as_deref()
            .map_or("given by the scenario".to_owned(), |p| {
                let laid =
                    if self.choice.system == platen_system::preset::by_name(p).unwrap_or(*sys) {
                        ""
                    } else {
                        ", with the scenario's values"
                    };
                format!("{p}{laid}")
            });
        let payload = if self.specimen_kg.is_some() {
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
}

/// The system's parameters as the scenario format's `table_system` object, every key explicit
/// (`platen model --json` and the scenario `identify --system` prints).
pub(crate) fn parameters(sys: &TableSystem) -> Value {
    let a = &sys.actuator;
    let v = &sys.servo_valve;
    let c = &sys.controller;
    json!({
        "actuator": {
            "count": a.count,
            "cap_side_area_m2": a.cap_area_m2,
            "rod_side_area_m2": a.rod_area_m2,
            "chamber_volume_m3": [a.cap_volume_m3, a.rod_volume_m3],
            "leakage_m3_s_per_pa": a.leakage_m3_s_per_pa,
        },
        "servo_valve": {
            "count": v.count,
            "rated_flow_m3_s": v.rated_flow_m3_s,
            "rated_pressure_drop_pa": v.rated_pressure_drop_pa,
            "natural_frequency_hz": v.natural_frequency_hz,
            "damping_ratio": v.damping_ratio,
            "delay_s": v.delay_s,
        },
        "oil_bulk_modulus_pa": sys.oil_bulk_modulus_pa,
        "supply_pressure_pa": sys.supply_pressure_pa,
        "return_pressure_pa": sys.return_pressure_pa,
        "accumulator": match &sys.supply {
            Supply::Constant => Value::Null,
            Supply::Accumulator(acc) => json!({
                "precharge_pressure_pa": acc.precharge_pressure_pa,
                "volume_m3": acc.volume_m3,
                "polytropic_exponent": acc.polytropic_exponent,
                "pump_flow_m3_s": acc.pump_flow_m3_s,
            }),
        },
        "controller": {
            "sample_rate_hz": c.sample_rate_hz,
            "displacement_gain_per_m": c.displacement_gain_per_m,
            "integral_gain_per_m_s": c.integral_gain_per_m_s,
            "velocity_feedforward_s_per_m": c.velocity_feedforward_s_per_m,
            "acceleration_feedforward_s2_per_m": c.acceleration_feedforward_s2_per_m,
            "velocity_feedback_s_per_m": c.velocity_feedback_s_per_m,
            "acceleration_feedback_s2_per_m": c.acceleration_feedback_s2_per_m,
            "delta_p_gain_per_pa": c.delta_p_gain_per_pa,
            "delta_p_highpass_hz": c.delta_p_highpass_hz,
        },
    })
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
    let groups: Vec<Group> = vec![
        (heading.to_owned(), simulated),
        (
            "Derived from the physical parameters (full model, Eq. 5–8)".to_owned(),
            rows(DERIVED, top),
        ),
        (
            "Physical parameters (full model)".to_owned(),
            rows(PHYSICAL, physical),
        ),
        ("Table limits".to_owned(), rows(LIMITS, limits)),
    ];
    write_groups(&mut s, groups);
    s
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
