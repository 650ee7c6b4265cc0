//! `platen identify`: the platen's parameters from periodic sine and triangle tests (the
//! paper's hysteresis-loop method, §3, with its fits and a global fit as a cross-check) and
//! from any other record (earthquake, white noise: the any-record method of
//! [`platen_ident::identify_records`]). Each file is routed by its data
//! ([`platen_ident::route`]); `--method periodic|record|both` forces the method.
//! When every file is periodic and no method is forced, the output is the periodic method's
//! alone, as before.
//!
//! The records are read by [`platen_ident::inputs`] (files, `--columns`, a manifest with
//! kinds, pressures, column maps, a specimen's `floors` and scenario entries), identified by
//! [`platen_ident::identify_any`] and reported by [`platen_report::identify_report`]; this
//! file turns the arguments into a request and prints or writes what comes back.

use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use platen_ident::inputs::{declared_record, files, InputError, RecordRequest};
use platen_ident::{identify_any, IdentifyOutput, MethodRequest, RecordSettings, Settings};
use platen_io::columns::ColumnMap;
use platen_report::identify_report::IdentifyReport;

/// Options of `platen identify`.
pub struct Options<'a> {
    pub files: &'a [PathBuf],
    pub pressure_mpa: &'a [f64],
    pub manifest: Option<&'a Path>,
    pub viscous_exponent: Option<f64>,
    pub no_low_velocity_term: bool,
    pub json: bool,
    /// Folder for the figures (SVG and PNG).
    pub plot: Option<&'a Path>,
    /// Self-contained HTML report.
    pub report: Option<&'a Path>,
    /// Size of the figures.
    pub size: platen_report::FigureSize,
    /// JSON file mapping the files' own channel names and units to platen's columns.
    pub columns: Option<&'a Path>,
    /// The method forced on every file (`None`: each file by its data).
    pub method: Option<MethodChoice>,
    /// Skip the any-record method's output-error check.
    pub no_output_error: bool,
    /// Hold the any-record method's stiffness at `Kₑ ≥ 0`.
    pub nonnegative_stiffness: bool,
}

/// `--method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodChoice {
    /// The paper's hysteresis-loop method on every file (each must be a periodic test).
    Periodic,
    /// The any-record method on every file, fitted jointly.
    Record,
    /// Periodic tests through both methods, the rest through the any-record method (every
    /// file enters the any-record fit).
    Both,
}

/// Checks a `--pressure-mpa` value: finite, ≥ 0 and at most 100 MPa (a larger one is a
/// pressure in another unit: [`platen_scenario::units::check_pressure_mpa`]).
pub fn parse_pressure_mpa(s: &str) -> Result<f64, String> {
    let p: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    platen_scenario::units::check_pressure_mpa(p)
}

/// Checks a `--viscous-exponent` value: in [0, 1].
pub fn parse_exponent(s: &str) -> Result<f64, String> {
    let a: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if a.is_finite() && (0.0..=1.0).contains(&a) {
        Ok(a)
    } else {
        Err(format!("{a}: expected an exponent in [0, 1]"))
    }
}

/// Runs `platen identify`.
pub fn run(opts: &Options) -> Result<()> {
    let (n, files_given) = (opts.pressure_mpa.len(), opts.files.len());
    if n > 1 && n != files_given {
        bail!(
            "--pressure-mpa has {n} values for {files_given} files: give one value for all files, or one per file in order"
        );
    }
    let request = RecordRequest {
        files: opts.files.to_vec(),
        pressures_mpa: opts.pressure_mpa.iter().map(|&p| Some(p)).collect(),
        manifest: opts.manifest.map(Path::to_path_buf),
        columns: match opts.columns {
            Some(path) => ColumnMap::load(path)?,
            None => ColumnMap::default(),
        },
    };
    let sources = request.sources().map_err(input_error)?;
    let progress = progress_bar(sources.len());
    let mut records = Vec::with_capacity(sources.len());
    for source in &sources {
        records.push(source.read().map_err(input_error)?);
        progress.inc(1);
    }
    let settings = Settings {
        viscous_exponent: opts.viscous_exponent,
        low_velocity_term: !opts.no_low_velocity_term,
        ..Settings::default()
    }
    .build()
    .context("identification failed")?;
    let record_settings = RecordSettings {
        viscous_exponent: opts.viscous_exponent,
        low_velocity_term: !opts.no_low_velocity_term,
        output_error: !opts.no_output_error,
        nonnegative_stiffness: opts.nonnegative_stiffness,
        ..RecordSettings::default()
    }
    .build()
    .context("identification failed")?;
    // Where each file goes (forced, declared `record`, or by its data), the periodic method
    // on the periodic tests it accepts, the any-record method on the rest: every file
    // accounted for.
    let method = match opts.method {
        None => MethodRequest::Auto,
        Some(MethodChoice::Periodic) => MethodRequest::Periodic,
        Some(MethodChoice::Record) => MethodRequest::Record,
        Some(MethodChoice::Both) => MethodRequest::Both,
    };
    progress.set_message("identifying");
    let declared = declared_record(&sources);
    let id = identify_any(&records, &declared, method, &settings, &record_settings);
    progress.finish_and_clear();
    let id = id.context("identification failed")?;
    let report = IdentifyReport {
        identified: &id,
        sources: &sources,
        records: &records,
    };
    for warning in report.unused() {
        eprintln!("warning: {warning}");
    }
    let output = id.output(&records, &files(&sources), method);
    let written = platen_report::write_outputs(
        opts.plot,
        opts.report,
        &opts.size,
        || report.figures(),
        |figures, rendered| report.html(figures, rendered),
    )?;
    if opts.json {
        JsonOutput {
            output,
            figures: opts
                .plot
                .map(|_| written.iter().map(|p| p.display().to_string()).collect()),
            report: opts.report.map(|path| path.display().to_string()),
        }
        .print()
    } else {
        out!("{}", report.text());
        if !written.is_empty() {
            outln!("\nWrote {} figure files (SVG and PNG):", written.len());
            for path in &written {
                outln!("  {}", path.display());
            }
        }
        if let Some(path) = opts.report {
            outln!("Wrote report {}", path.display());
        }
        Ok(())
    }
}

/// A reading error as the CLI reports it: a file's or a scenario's own error stays itself
/// (its exit code and `--json` error object name the file, field and line).
fn input_error(e: InputError) -> anyhow::Error {
    match e {
        InputError::Io(io) => io.into(),
        InputError::Scenario(se) => se.into(),
        other => other.into(),
    }
}

/// A progress bar on stderr while records are read and identified: only when stderr is a
/// terminal (and `CI` is not set), and only once the run has lasted a second.
fn progress_bar(records: usize) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(records as u64), ProgressDrawTarget::hidden());
    if !std::io::stderr().is_terminal() || std::env::var_os("CI").is_some() {
        return bar;
    }
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} {bar:40} {pos}/{len} records {msg}  {elapsed}")
    {
        bar.set_style(style);
    }
    bar.set_message("read");
    let shown = bar.clone();
    std::thread::spawn(move || {
        std::thread::sleep(Duration::from_secs(1));
        if !shown.is_finished() {
            shown.set_draw_target(ProgressDrawTarget::stderr());
            shown.enable_steady_tick(Duration::from_millis(120));
        }
    });
    bar
}

/// What `--json` prints: the identification's output ([`platen_ident::Identified::output`])
/// and the files written.
#[derive(Serialize)]
struct JsonOutput {
    #[serde(flatten)]
    output: IdentifyOutput,
    #[serde(skip_serializing_if = "Option::is_none")]
    figures: Option<Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    report: Option<String>,
}

impl JsonOutput {
    fn print(self) -> Result<()> {
        // Through a `Value`, whose maps sort their keys at every level (the contract's order).
        let value = serde_json::to_value(&self)?;
        outln!("{}", serde_json::to_string_pretty(&value)?);
        Ok(())
    }
}

/// `platen identify --system FILE…`: the controller's gains from closed-loop records (see
/// `platen_ident::system`). With two or more files, the last is held out and judged; the
/// others are fitted. Prints the gains, the fit on each record, what cannot be identified and
/// a runnable scenario (the `lhpost-2008` preset with the identified controller, commanded by
/// the held-out record).
pub fn run_system(
    files: &[PathBuf],
    columns: Option<&Path>,
    base: Option<&Path>,
    json: bool,
) -> Result<()> {
    use platen_ident::system::{identify_system, SystemRecord, SystemSettings};
    if files.is_empty() {
        bail!("identify --system needs at least one recorded CSV file");
    }
    let map = match columns {
        Some(path) => ColumnMap::load(path)?,
        None => ColumnMap::default(),
    };
    let storey_names: Vec<String> = (1..=platen_model::Specimen::MAX_STOREYS)
        .map(|i| format!("storey{i}_a_m_s2"))
        .collect();
    let mut optional = vec![
        "drive",
        "delta_p_pa",
        "a_m_s2",
        "cap_pressure_pa",
        "rod_pressure_pa",
    ];
    optional.extend(storey_names.iter().map(String::as_str));
    let mut records = Vec::with_capacity(files.len());
    for path in files {
        let mut t = map
            .read_table(path, &["t_s", "command_u_m", "u_m"], &optional)
            .with_context(|| {
                format!(
                    "{}: identify --system needs the columns t_s, command_u_m and u_m \
                     (drive, delta_p_pa, cap_pressure_pa, rod_pressure_pa, a_m_s2, \
                     storey{{i}}_a_m_s2 where recorded)",
                    path.display()
                )
            })?;
        let storeys = storey_names
            .iter()
            .map_while(|c| t.take_column(c))
            .collect();
        let mut take = |c: &str| t.take_column(c);
        records.push(SystemRecord {
            name: path.display().to_string(),
            t_s: take("t_s").unwrap_or_default(),
            command_u_m: take("command_u_m").unwrap_or_default(),
            u_m: take("u_m").unwrap_or_default(),
            drive: take("drive"),
            delta_p_pa: take("delta_p_pa"),
            a_m_s2: take("a_m_s2"),
            cap_pressure_pa: take("cap_pressure_pa"),
            rod_pressure_pa: take("rod_pressure_pa"),
            storey_a_m_s2: storeys,
        });
    }
    let (base_system, base_stroke) = match base {
        Some(path) => {
            let (s, stroke) = load_base(path, &files[0], &map)?;
            (Some(s), stroke)
        }
        None => (None, None),
    };
    let n = records.len();
    let fit: Vec<bool> = (0..n).map(|i| n == 1 || i + 1 < n).collect();
    let settings = SystemSettings {
        base: base_system,
        judge: true,
        ..SystemSettings::default()
    };
    let id = identify_system(&records, &fit, &settings)?;
    let held = &records[n - 1];
    let held_path = std::fs::canonicalize(&files[n - 1]).unwrap_or_else(|_| files[n - 1].clone());
    let plant = id.plant.as_ref();
    let identified_system = plant.and_then(|p| p.system);
    let mut table_system = match &identified_system {
        Some(sys) => crate::model::parameters(sys),
        None => serde_json::json!({ "preset": "lhpost-2008" }),
    };
    if let (Some(g), None) = (&id.gains, &identified_system) {
        table_system["controller"] = serde_json::json!({
            "sample_rate_hz": g.sample_rate_hz,
            "displacement_gain_per_m": g.displacement_gain_per_m,
            "velocity_feedforward_s_per_m": g.velocity_feedforward_s_per_m,
            "acceleration_feedforward_s2_per_m": g.acceleration_feedforward_s2_per_m,
            "velocity_feedback_s_per_m": g.velocity_feedback_s_per_m,
            "acceleration_feedback_s2_per_m": g.acceleration_feedback_s2_per_m,
            "delta_p_gain_per_pa": g.delta_p_gain_per_pa,
            "delta_p_highpass_hz": g.delta_p_highpass_hz,
            "integral_gain_per_m_s": 0.0,
        });
    }
    let model = match plant.and_then(|p| p.model) {
        Some(m) => serde_json::json!({
            "preset": "lhpost-2008",
            "identified": {
                "effective_mass_kg": m.effective_mass_kg,
                "stiffness_n_per_m": m.stiffness_n_per_m,
                "coulomb_force_n": m.coulomb_force_n,
                "viscous_coefficient": m.viscous_coefficient,
                "viscous_exponent": m.viscous_exponent,
                "low_velocity_force_n": m.low_velocity_force_n,
                "low_velocity_decay_s_per_m": m.low_velocity_decay_s_per_m,
            }
        }),
        None => serde_json::json!({ "preset": "lhpost-2008" }),
    };
    let span = held.t_s.last().copied().unwrap_or(0.0) - held.t_s.first().copied().unwrap_or(0.0);
    let mut scenario = serde_json::json!({
        "name": format!("identified table system, commanded by {}", held.name),
        "model": model,
        "table_system": table_system,
        // The record's own a_m_s2 is the table's, not the command's: the command's velocity
        // and acceleration are derived from command_u_m (the record's columns ignored).
        "excitation": {
            "motion_csv": held_path.display().to_string(),
            "columns": {
                "u_m": { "name": map.header("command_u_m") },
                "v_m_s": { "ignore": true },
                "a_m_s2": { "ignore": true },
            }
        },
        "duration_s": span,
    });
    if let Some(sp) = plant.and_then(|p| p.specimen.as_ref()) {
        scenario["specimen"] = serde_json::json!({
            "storeys": sp.storeys().iter().map(|s| serde_json::json!({
                "mass_kg": s.mass_kg,
                "stiffness_n_per_m": s.stiffness_n_per_m,
                "damping_n_s_per_m": s.damping_n_s_per_m,
            })).collect::<Vec<_>>()
        });
    }
    if let Some(sys) = &identified_system {
        // The chambers must keep oil over the stroke: the base's, else 90 % of what the
        // identified volumes allow.
        let a = &sys.actuator;
        let room = (a.cap_volume_m3 / a.cap_area_m2).min(a.rod_volume_m3 / a.rod_area_m2);
        let stroke = base_stroke.filter(|s| *s < room).unwrap_or(0.9 * room);
        // The other limits are this table's, not the preset's: its capacities by the closed
        // forms in the weaker direction, and the acceleration that force gives the moving
        // mass (platen and specimen).
        let cap = sys.capacities();
        let force = cap.push_force_n.min(cap.pull_force_n);
        let velocity = cap.extend_velocity_m_s.min(cap.retract_velocity_m_s);
        let mut limits = serde_json::json!({
            "stroke_m": stroke,
            "velocity_m_s": velocity,
            "force_n": force,
        });
        if let Some(m) = plant.and_then(|p| p.model) {
            let specimen_kg: f64 = plant
                .and_then(|p| p.specimen.as_ref())
                .map_or(0.0, |sp| sp.storeys().iter().map(|s| s.mass_kg).sum());
            limits["acceleration_m_s2"] = (force / (m.effective_mass_kg + specimen_kg)).into();
        }
        scenario["limits"] = limits;
    }
    let mut from_preset: Vec<&str> = Vec::new();
    if plant.and_then(|p| p.model).is_none() {
        from_preset.push("model (the platen: mass, friction, stiffness)");
    }
    if identified_system.is_none() {
        from_preset.push("table_system: actuators, servo-valves, oil, supply, accumulator");
    } else {
        from_preset.push(
            "table_system: actuator count and areas, valve count and rated drop, supply and \
             return pressures, bulk modulus, accumulator (from --base)",
        );
    }
    from_preset
        .push("table_system.controller.integral_gain_per_m_s (0: an integrator is not fitted)");
    if json {
        let value = serde_json::json!({
            "system_identification": id,
            "scenario": scenario,
            "scenario_from_preset": from_preset,
        });
        outln!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    let mut s = String::new();
    match &id.gains {
        Some(g) => {
            let _ = writeln!(
                s,
                "controller at {:.6} Hz (fitted on {}):",
                g.sample_rate_hz,
                id.fitted_records.join(", ")
            );
            for (k, v) in [
                ("K_p  displacement_gain_per_m", g.displacement_gain_per_m),
                (
                    "K_vf velocity_feedforward_s_per_m",
                    g.velocity_feedforward_s_per_m,
                ),
                (
                    "K_af acceleration_feedforward_s2_per_m",
                    g.acceleration_feedforward_s2_per_m,
                ),
                (
                    "K_vb velocity_feedback_s_per_m",
                    g.velocity_feedback_s_per_m,
                ),
                (
                    "K_ab acceleration_feedback_s2_per_m",
                    g.acceleration_feedback_s2_per_m,
                ),
                ("K_dp delta_p_gain_per_pa", g.delta_p_gain_per_pa),
                ("     delta_p_highpass_hz", g.delta_p_highpass_hz),
            ] {
                let _ = writeln!(s, "  {k:<40} {v:.6e}");
            }
            let _ = writeln!(s, "  saturated samples left out: {}", id.saturated_samples);
        }
        None => {
            let _ = writeln!(s, "controller gains: not identified");
        }
    }
    for r in &id.records {
        let _ = writeln!(
            s,
            "{} {}: drive RMS error {:.3e} ({:.3} % of its RMS) over {} samples",
            if r.fitted { "fitted  " } else { "held out" },
            r.name,
            r.drive_rms_error,
            100.0 * r.drive_nrmse,
            r.samples
        );
    }
    if let Some(p) = plant {
        if let Some(m) = &p.mechanics {
            let _ = writeln!(
                s,
                "platen: mass {:.1} kg, stiffness {:.1} N/m, viscous {:.1} N·s/m, Coulomb \
                 {:.1} N (force residual {:.3} % over {} samples)",
                m.effective_mass_kg,
                m.stiffness_n_per_m,
                m.viscous_coefficient,
                m.coulomb_force_n,
                100.0 * m.force_nrmse,
                m.samples
            );
        }
        for (i, st) in p.storeys.iter().enumerate() {
            let _ = writeln!(
                s,
                "storey {}: mass {:.1} kg, stiffness {:.4e} N/m, damping {:.1} N·s/m",
                i + 1,
                st.mass_kg,
                st.stiffness_n_per_m,
                st.damping_n_s_per_m
            );
        }
        for (i, m) in p.specimen_modes.iter().enumerate() {
            let _ = writeln!(
                s,
                "specimen mode {}: {:.4} Hz, damping {:.2} %",
                i + 1,
                m.frequency_hz,
                100.0 * m.damping_ratio
            );
        }
        if let Some(h) = &p.hydraulics {
            let _ = writeln!(
                s,
                "valves: rated flow {:.5e} m³/s each, leakage {:.3e} m³/s/Pa, spool {} Hz ζ {} \
                 delay {:.3e} s (equivalent lag {:.4e} s)",
                h.rated_flow_m3_s,
                h.leakage_m3_s_per_pa,
                h.spool_natural_frequency_hz,
                h.spool_damping_ratio,
                h.valve_delay_s,
                h.equivalent_lag_s
            );
            let _ = writeln!(
                s,
                "oil column: chambers {:.5e} / {:.5e} m³ at β {:.4e} Pa; {:.4} Hz bare, {:.4} \
                 Hz with the specimen",
                h.cap_volume_m3,
                h.rod_volume_m3,
                h.oil_bulk_modulus_pa,
                h.oil_column_frequency_hz,
                h.oil_column_frequency_with_specimen_hz
            );
        }
        for pr in &p.predictions {
            let _ = writeln!(
                s,
                "{} {}: the identified loop on its command: table acceleration RMS error \
                 {:.4} m/s² of {:.4} (noise ≈ {:.4}), displacement {:.3e} m of {:.3e}",
                if pr.fitted { "fitted  " } else { "held out" },
                pr.name,
                pr.acceleration_rms_error_m_s2,
                pr.acceleration_rms_m_s2,
                pr.acceleration_noise_m_s2,
                pr.displacement_rms_error_m,
                pr.displacement_rms_m
            );
        }
    }
    for (what, why) in &id.not_identified {
        let _ = writeln!(s, "not identified: {what}: {why}");
    }
    let _ = writeln!(
        s,
        "scenario (with --json): {}",
        if identified_system.is_some() {
            "the identified model, table system and specimen"
        } else {
            "the lhpost-2008 preset with the identified controller"
        }
    );
    outln!("{}", s.trim_end());
    Ok(())
}

/// `--base`: a scenario with a `table_system`, or a `table_system` object, validated as a
/// scenario would validate it (commanded by `record`'s command); its stroke limit if given.
fn load_base(
    path: &Path,
    record: &Path,
    map: &ColumnMap,
) -> Result<(platen_system::TableSystem, Option<f64>)> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("--base {}: cannot read it", path.display()))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("--base {}: not JSON", path.display()))?;
    let (spec, stroke) = match value.get("table_system") {
        Some(ts) => (
            ts.clone(),
            value.pointer("/limits/stroke_m").and_then(|v| v.as_f64()),
        ),
        None => (value.clone(), None),
    };
    let record = std::fs::canonicalize(record).unwrap_or_else(|_| record.to_path_buf());
    // Validated with a tiny stroke: the base's volumes are replaced by the fitted ones.
    let scenario = serde_json::json!({
        "model": { "preset": "lhpost-2008" },
        "table_system": spec,
        "limits": { "stroke_m": stroke.unwrap_or(1e-3) },
        "excitation": {
            "motion_csv": record.display().to_string(),
            "columns": { "u_m": { "name": map.header("command_u_m") } }
        },
    });
    let file = platen_scenario::file::parse(path, &scenario.to_string())
        .with_context(|| format!("--base {}: not a table system", path.display()))?;
    let s = platen_scenario::Scenario::from_file(path, file)
        .with_context(|| format!("--base {}: not a table system", path.display()))?;
    let Some(cl) = s.closed_loop else {
        bail!("--base {}: no table_system in it", path.display());
    };
    Ok((cl.system, stroke))
}
