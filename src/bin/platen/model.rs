//! `platen model`: a preset's parameters and derived quantities, and with `--system` or
//! `--scenario` the table system's closed forms and linearised loop.
//!
//! The description is [`platen_scenario::describe`]'s ([`ModelDescription`], with a table
//! system's [`SystemAnalysis`]); `--json` prints it as it is (SI, the contract's keys), the
//! text form is [`platen_report::model_text`]'s, and `--plot` draws the linearised loop's
//! Bode plots ([`platen_report::system_figures::analysis_figures`]).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::ValueEnum;

use platen_model::Preset;
use platen_report::{model_text, system_figures};
use platen_scenario::describe::{self, ModelDescription, SystemAnalysis};
use platen_scenario::multi_axis::TableScenario;
use platen_scenario::{LoadedRig, Model, ScenarioRig};
use platen_system::TableSystem;

use crate::plot;

/// The arguments of `platen model`.
#[derive(clap::Args)]
pub struct ModelArgs {
    /// Preset name.
    #[arg(long, default_value = "lhpost-2008")]
    preset: String,
    /// Hold-down nitrogen pressure, MPa (default: the preset's nominal pressure).
    #[arg(long)]
    pressure_mpa: Option<f64>,
    /// Which form to describe.
    #[arg(long, value_enum, default_value_t = Form::Identified)]
    form: Form,
    /// Describe this table system too (a table-system preset: lhpost-2008); with
    /// --scenario it replaces the scenario's table_system.
    #[arg(long, value_name = "PRESET")]
    system: Option<String>,
    /// Describe the model, table_system and specimen of this scenario (its model
    /// preset, pressure, form and values; its excitation, integrator, initial state and
    /// duration are not read).
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with_all = ["preset", "pressure_mpa", "form"]
    )]
    scenario: Option<PathBuf>,
    /// Print JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write the Bode plots of the linearised loop to this folder as SVG and PNG: the
    /// closed loop command → displacement (bode-closed-loop) and the loop gain L broken
    /// at the drive (bode-loop-gain), magnitude and phase, 0.1 Hz to the controller's
    /// Nyquist frequency or 200 Hz. Needs a table system (--system or --scenario).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    #[command(flatten)]
    size: plot::SizeArgs,
}

/// `--form`.
#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Form {
    /// The identified model of Eq. 22/23.
    Identified,
    /// The full Lagrangian model of Eq. 1–8.
    Full,
}

/// What `platen model` describes: the description, the model, its stroke and specimen, the
/// scenario's table system and what the figures' titles name.
struct Described {
    /// The scenario's header line (empty without `--scenario`).
    header: String,
    description: ModelDescription,
    model: Model,
    stroke_m: f64,
    specimen_kg: Option<f64>,
    /// The scenario's table system and the preset it names.
    given: Option<(Option<String>, TableSystem)>,
    name: String,
}

/// Runs `platen model`.
pub fn run(args: &ModelArgs) -> Result<()> {
    let size = args.size.size();
    let names = platen_system::preset::PRESET_NAMES;
    if args.system.is_none() && args.scenario.is_none() && args.plot.is_some() {
        bail!(
            "--plot draws the Bode plots of a table system's loop: give --system PRESET \
             ({names}) or a --scenario with a `table_system`"
        );
    }
    let mut described = match &args.scenario {
        Some(path) => match ScenarioRig::load(path)? {
            ScenarioRig::Platen(loaded) => of_scenario(path, loaded)?,
            ScenarioRig::Table(table) => return describe_table(args, path, &table),
        },
        None => of_preset(args)?,
    };
    let system = match &args.system {
        Some(name) => Some((Some(name.clone()), system_preset(name, described.stroke_m)?)),
        None => described.given.take(),
    };
    let analysis = system.map(|(preset, system)| {
        SystemAnalysis::new(
            preset,
            system,
            &described.model,
            described.stroke_m,
            described.specimen_kg,
        )
    });
    described.description.table_system = analysis.as_ref().map(SystemAnalysis::description);
    let written = match (&analysis, args.plot.as_deref()) {
        (None, Some(_)) => bail!(
            "--plot draws the Bode plots of a table system's loop, and {} has no \
             `table_system`: give --system PRESET ({names})",
            args.scenario
                .as_ref()
                .map_or("the scenario".into(), |p| p.display().to_string()),
        ),
        (Some(a), plot @ Some(_)) => platen_report::write_outputs(
            plot,
            None,
            &size,
            || system_figures::analysis_figures(&described.name, a),
            |_, _| String::new(),
        )?,
        _ => Vec::new(),
    };
    print(args, &described, &written)
}

/// The model, table system and specimen of the scenario at `path`.
fn of_scenario(path: &Path, loaded: LoadedRig) -> Result<Described> {
    let rig = loaded.rig;
    let header = model_text::scenario_header(path, &loaded.name, &rig);
    let given = rig
        .table_system
        .map(|system| (loaded.table_system_preset, system));
    let specimen_kg = rig.specimen.as_ref().map(|sp| sp.total_mass_kg());
    let description = ModelDescription::of_rig(path, &rig)?;
    Ok(Described {
        header,
        description,
        model: rig.model,
        stroke_m: rig.limits.stroke_m,
        specimen_kg,
        given,
        name: loaded.name,
    })
}

/// The preset's model at `--pressure-mpa` in `--form`.
fn of_preset(args: &ModelArgs) -> Result<Described> {
    let preset = Preset::from_name(&args.preset)?;
    let pressure_pa = pressure_pa(preset, args.pressure_mpa)?;
    let full = matches!(args.form, Form::Full);
    let description = ModelDescription::of_preset(preset, pressure_pa, full)?;
    let model = describe::preset_model(preset, pressure_pa, full)?;
    let name = args.system.as_deref().unwrap_or(preset.name()).to_owned();
    Ok(Described {
        header: String::new(),
        description,
        model,
        stroke_m: preset.limits().stroke_m,
        specimen_kg: None,
        given: None,
        name,
    })
}

/// Prints the description (JSON or text) and the figures written.
fn print(args: &ModelArgs, described: &Described, written: &[PathBuf]) -> Result<()> {
    if args.json {
        let mut value = serde_json::to_value(&described.description)?;
        if args.plot.is_some() {
            let files: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
            value["figures"] = files.into();
        }
        outln!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    out!(
        "{}{}",
        described.header,
        model_text::text(&described.description)
    );
    if !written.is_empty() {
        outln!("\nwrote {} figure files (SVG and PNG):", written.len());
        for path in written {
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
        .check_stroke(stroke_m)
        .with_context(|| format!("--system {name} over the stroke ±{stroke_m} m"))?;
    Ok(system)
}

/// `platen model --scenario` on a multi-axis scenario: its modes and capacities.
fn describe_table(args: &ModelArgs, path: &Path, scenario: &TableScenario) -> Result<()> {
    if args.system.is_some() {
        bail!(
            "`{}` has a multi-axis `table`: --system describes the uniaxial table system's \
             loop (a table's loop is its `table.controller`)",
            path.display()
        );
    }
    let written = match (args.plot.as_deref(), &scenario.system) {
        (None, _) => Vec::new(),
        (Some(_), None) => bail!(
            "--plot draws the Bode plots of a table's closed loop, and `{}` has no \
             `table.controller`",
            path.display()
        ),
        (plot @ Some(_), Some(sys)) => {
            let lin = platen_system::TableLinearisation::new(
                &scenario.table,
                &sys.hydraulics,
                &sys.controller,
                scenario.specimen.as_ref(),
            )?;
            let rate = sys.controller.sample_rate_hz();
            platen_report::write_outputs(
                plot,
                None,
                &args.size.size(),
                || system_figures::table_loop_figures(&scenario.name, &lin, rate),
                |_, _| String::new(),
            )?
        }
    };
    let description = scenario.describe();
    crate::plot::print(
        args.json,
        args.plot.is_some(),
        &description,
        &written,
        || {
            let mut t = platen_report::table_text::description_text(&description);
            for f in &written {
                t += &format!("  wrote {}\n", f.display());
            }
            t
        },
    )
}
