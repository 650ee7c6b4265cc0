//! `platen model`: a preset's parameters and derived quantities, and with `--system` or
//! `--scenario` the table system's closed forms and linearised loop.
//!
//! The description is [`platen_scenario::describe`]'s ([`ModelDescription`], with a table
//! system's [`SystemAnalysis`]); `--json` prints it as it is (SI, the contract's keys), the
//! text form is [`platen_report::model_text`]'s, and `--plot` draws the linearised loop's
//! Bode plots ([`platen_report::system_figures::analysis_figures`]).

use std::path::Path;

use anyhow::{bail, Context, Result};

use platen_model::Preset;
use platen_report::{model_text, system_figures, FigureSize};
use platen_scenario::describe::{self, ModelDescription, SystemAnalysis};
use platen_scenario::LoadedRig;
use platen_system::TableSystem;

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
    let names = platen_system::preset::PRESET_NAMES;
    if o.system.is_none() && o.scenario.is_none() && o.plot.is_some() {
        bail!(
            "--plot draws the Bode plots of a table system's loop: give --system PRESET \
             ({names}) or a --scenario with a `table_system`"
        );
    }
    // The description, the model, its stroke and specimen, the scenario's table system and
    // what the figures' titles name.
    let mut header = String::new();
    let (mut description, model, stroke_m, specimen_kg, given, name) = match o.scenario {
        Some(path) => {
            let loaded = LoadedRig::load(path)?;
            let rig = loaded.rig;
            header = model_text::scenario_header(path, &loaded.name, &rig);
            let given = rig
                .table_system
                .map(|system| (loaded.table_system_preset, system));
            let specimen_kg = rig.specimen.as_ref().map(|sp| sp.total_mass_kg());
            let d = ModelDescription::of_rig(path, &rig)?;
            (
                d,
                rig.model,
                rig.limits.stroke_m,
                specimen_kg,
                given,
                loaded.name,
            )
        }
        None => {
            let preset = Preset::from_name(o.preset)?;
            let pressure_pa = pressure_pa(preset, o.pressure_mpa)?;
            let full = matches!(o.form, Form::Full);
            let d = ModelDescription::of_preset(preset, pressure_pa, full)?;
            let model = describe::preset_model(preset, pressure_pa, full)?;
            let name = o.system.unwrap_or(preset.name()).to_owned();
            (d, model, preset.limits().stroke_m, None, None, name)
        }
    };
    let system = match o.system {
        Some(name) => Some((Some(name.to_owned()), system_preset(name, stroke_m)?)),
        None => given,
    };
    let analysis = system
        .map(|(preset, system)| SystemAnalysis::new(preset, system, &model, stroke_m, specimen_kg));
    description.table_system = analysis.as_ref().map(SystemAnalysis::description);
    let written = match (&analysis, o.plot) {
        (None, Some(_)) => bail!(
            "--plot draws the Bode plots of a table system's loop, and {} has no \
             `table_system`: give --system PRESET ({names})",
            o.scenario
                .map_or("the scenario".into(), |p| p.display().to_string()),
        ),
        (Some(a), Some(_)) => platen_report::write_outputs(
            o.plot,
            None,
            &o.size,
            || system_figures::analysis_figures(&name, a),
            |_, _| String::new(),
        )?,
        _ => Vec::new(),
    };
    if o.json {
        let mut value = serde_json::to_value(&description)?;
        if o.plot.is_some() {
            let files: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
            value["figures"] = files.into();
        }
        outln!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    out!("{header}{}", model_text::text(&description));
    if !written.is_empty() {
        outln!("\nwrote {} figure files (SVG and PNG):", written.len());
        for path in &written {
            outln!("  {}", path.display());
        }
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

/// The table-system preset `name`, checked over the stroke `±stroke_m`.
fn system_preset(name: &str, stroke_m: f64) -> Result<TableSystem> {
    let system =
        platen_system::preset::by_name(name).with_context(|| format!("--system {name}"))?;
    system
        .validate(stroke_m)
        .with_context(|| format!("--system {name} over the stroke ±{stroke_m} m"))?;
    Ok(system)
}
