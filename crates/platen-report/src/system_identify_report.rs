//! The report of `platen identify --system`: the text a terminal shows, the `--json` object
//! with the scenario that *is* the identified table (every value identified, given or
//! assumed, with its provenance; nothing from a preset), and the figures of the identified
//! loop's predictions against the records, side by side with a linear black box and perfect
//! tracking.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use platen_ident::system::{
    IdentifiedHydraulics, IdentifiedPlant, Judgement, Prediction, PredictionErrorFit,
    SystemIdentification, SystemRecord, ValueProvenance,
};
use platen_io::columns::ColumnMap;
use platen_io::columns::ColumnSpec;
use platen_model::{IdentifiedParams, Specimen};
use platen_scenario::file::{
    ExcitationSpec, IdentifiedOverrides, LimitsSpec, ModelSpec, ScenarioFile, SpecimenSpec,
    StoreySpec,
};
use platen_scenario::TableSystemSpec;
use platen_system::TableSystem;

use crate::figure::{Figure, Panel, MODEL, RECORDED, SIMULATED};
use crate::series::{line, patterned, thinned, Points};

/// Most points drawn per series of a prediction figure.
const MAX_POINTS: usize = 4000;

/// A table-system identification as a runnable scenario.
pub struct SystemScenario {
    /// The scenario (the identified model, table system and specimen, commanded by the
    /// held-out record), or `None` when the records do not give a whole plant.
    pub scenario: Option<serde_json::Value>,
    /// Where each value of the scenario comes from.
    pub provenance: Vec<ValueProvenance>,
    /// Why there is no scenario (what could not be identified), when there is none.
    pub missing: Vec<String>,
}

/// The scenario of a table-system identification, commanded by the held-out record `held`
/// (read from `held_path` through `columns`); `base_stroke` is the base's stroke limit, if
/// it gives one. It holds no `duration_s`: it runs any record's command by changing its
/// `motion_csv`.
pub fn system_scenario(
    id: &SystemIdentification,
    held: &SystemRecord,
    held_path: &Path,
    columns: &ColumnMap,
    base_stroke: Option<f64>,
) -> SystemScenario {
    let plant = id.plant.as_ref();
    let (Some(sys), Some(m)) = (plant.and_then(|p| p.system), plant.and_then(|p| p.model)) else {
        return SystemScenario {
            scenario: None,
            provenance: Vec::new(),
            missing: missing_plant(id),
        };
    };
    let specimen = plant.and_then(|p| p.specimen.as_ref());
    let (limits, base_stroke_kept) = scenario_limits(&sys, &m, specimen, base_stroke);
    let file = ScenarioFile {
        schema: None,
        name: Some(format!("identified table, commanded by {}", held.name)),
        description: None,
        // The format needs a preset; every value of the identified form is given, and every
        // limit, so the preset contributes nothing.
        model: Some(ModelSpec {
            preset: "lhpost-2008".into(),
            hold_down_pressure_mpa: None,
            identified: Some(IdentifiedOverrides {
                effective_mass_kg: Some(m.effective_mass_kg),
                stiffness_n_per_m: Some(m.stiffness_n_per_m),
                coulomb_force_n: Some(m.coulomb_force_n),
                viscous_coefficient: Some(m.viscous_coefficient),
                viscous_exponent: Some(m.viscous_exponent),
                low_velocity_force_n: Some(m.low_velocity_force_n),
                low_velocity_decay_s_per_m: Some(m.low_velocity_decay_s_per_m),
            }),
            full: None,
        }),
        excitation: held_excitation(held_path, columns),
        integrator: None,
        initial: None,
        duration_s: None,
        limits: Some(limits),
        specimen: specimen.map(|sp| SpecimenSpec {
            storeys: (sp.storeys().iter())
                .map(|s| StoreySpec {
                    mass_kg: s.mass_kg,
                    stiffness_n_per_m: s.stiffness_n_per_m,
                    damping_n_s_per_m: s.damping_n_s_per_m,
                    hysteresis: None,
                    height_m: None,
                })
                .collect(),
            ..SpecimenSpec::default()
        }),
        table_system: Some(TableSystemSpec::from(&sys)),
        table: None,
    };
    // Every key a string and every number finite or null: the conversion cannot fail.
    let scenario = serde_json::to_value(&file).unwrap_or_default();
    SystemScenario {
        scenario: Some(scenario),
        provenance: scenario_provenance(id, base_stroke_kept),
        missing: Vec::new(),
    }
}

/// Why there is no scenario: what of the plant could not be identified.
fn missing_plant(id: &SystemIdentification) -> Vec<String> {
    let mut missing: Vec<String> = id
        .not_identified
        .iter()
        .filter(|(what, _)| {
            what.contains("platen") || what.contains("servo-valve") || what.contains("gains")
        })
        .map(|(what, why)| format!("{what}: {why}"))
        .collect();
    if missing.is_empty() {
        missing.push("the plant could not be identified from these records".into());
    }
    missing
}

/// The excitation of the scenario: the held-out record's command, read through `columns`.
fn held_excitation(held_path: &Path, columns: &ColumnMap) -> ExcitationSpec {
    // The record's own a_m_s2 is the table's, not the command's: the command's velocity
    // and acceleration are derived from command_u_m (the record's columns ignored).
    let ignored = ColumnSpec {
        ignore: true,
        ..ColumnSpec::default()
    };
    let columns = BTreeMap::from([
        ("t_s".to_owned(), columns.reading_spec("t_s")),
        ("u_m".to_owned(), columns.reading_spec("command_u_m")),
        ("v_m_s".to_owned(), ignored.clone()),
        ("a_m_s2".to_owned(), ignored),
    ]);
    ExcitationSpec {
        motion_csv: Some(held_path.to_path_buf()),
        columns: Some(columns),
        ..ExcitationSpec::default()
    }
}

/// The identified table's limits, and whether the stroke is the base's `base_stroke`.
fn scenario_limits(
    sys: &TableSystem,
    m: &IdentifiedParams,
    specimen: Option<&Specimen>,
    base_stroke: Option<f64>,
) -> (LimitsSpec, bool) {
    // The chambers must keep oil over the stroke: the base's, else 90 % of what the
    // identified volumes allow. The other limits are this table's: its capacities by the
    // closed forms in the weaker direction, and the acceleration that force gives the moving
    // mass (platen and specimen).
    let a = sys.actuator();
    let room = (a.cap_volume_m3 / a.cap_area_m2).min(a.rod_volume_m3 / a.rod_area_m2);
    let stroke = base_stroke
        .filter(|s| *s < room)
        .unwrap_or_else(|| platen_ident::system::stroke_limit_m(sys));
    let cap = sys.capacities();
    let force = cap.push_force_n.min(cap.pull_force_n);
    let velocity = cap.extend_velocity_m_s.min(cap.retract_velocity_m_s);
    let specimen_kg: f64 = specimen.map_or(0.0, |sp| sp.storeys().iter().map(|s| s.mass_kg).sum());
    let limits = LimitsSpec {
        stroke_m: Some(stroke),
        velocity_m_s: Some(velocity),
        acceleration_m_s2: Some(force / (m.effective_mass_kg + specimen_kg)),
        force_n: Some(force),
    };
    (limits, base_stroke.is_some_and(|s| s < room))
}

/// Where each value of the scenario comes from: the identification's, and the limits'
/// (`base_stroke`: the stroke is the base's).
fn scenario_provenance(id: &SystemIdentification, base_stroke: bool) -> Vec<ValueProvenance> {
    let mut provenance = id.provenance.clone();
    let derived = |path: &str, note: &str| ValueProvenance {
        path: path.into(),
        source: platen_ident::system::Source::Identified,
        std_error: None,
        note: Some(note.into()),
    };
    provenance.push(if base_stroke {
        ValueProvenance {
            source: platen_ident::system::Source::Given,
            ..derived("limits.stroke_m", "the base's stroke")
        }
    } else {
        derived(
            "limits.stroke_m",
            "90 % of the stroke the identified chamber volumes allow",
        )
    });
    provenance.push(derived(
        "limits.velocity_m_s",
        "the valve-limited velocity of the identified valves (closed form, weaker direction)",
    ));
    provenance.push(derived(
        "limits.force_n",
        "A·(P_s − P_R) of the geometry (closed form, weaker direction)",
    ));
    provenance.push(derived(
        "limits.acceleration_m_s2",
        "the force limit over the identified platen and specimen masses",
    ));
    provenance.sort_by(|a, b| a.path.cmp(&b.path));
    provenance
}

/// What `platen identify --system --json` prints: the identification, the scenario it makes
/// runnable ([`system_scenario`], `null` with `scenario_missing` when there is none) and the
/// provenance of its values.
pub fn system_json(
    id: &SystemIdentification,
    held: &SystemRecord,
    held_path: &Path,
    columns: &ColumnMap,
    base_stroke: Option<f64>,
) -> serde_json::Value {
    let s = system_scenario(id, held, held_path, columns, base_stroke);
    serde_json::json!({
        "system_identification": id,
        "scenario": s.scenario,
        "scenario_provenance": s.provenance,
        "scenario_missing": s.missing,
    })
}

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.2} %", 100.0 * x)
    } else {
        "–".into()
    }
}

fn plus_minus(value: f64, se: Option<f64>) -> String {
    match se {
        Some(s) if s.is_finite() => format!("{value:.5e} ± {s:.2e}"),
        _ => format!("{value:.5e}"),
    }
}

/// The text report of a table-system identification: the controller's gains, the fit on
/// each record, the plant, the predictions against the black box and perfect tracking, what
/// could not be identified and where the scenario's values come from.
pub fn identified_system_text(id: &SystemIdentification) -> String {
    let mut s = String::new();
    controller_lines(&mut s, id);
    if let Some(p) = &id.plant {
        plant_lines(&mut s, p);
    }
    if let Some(f) = &id.prediction_error {
        prediction_error_lines(&mut s, f);
    }
    if let Some(j) = &id.judgement {
        judgement_lines(&mut s, j);
    }
    for (what, why) in &id.not_identified {
        let _ = writeln!(s, "not identified: {what}: {why}");
    }
    let assumed: Vec<&str> = id
        .provenance
        .iter()
        .filter(|p| p.source == platen_ident::system::Source::Assumed)
        .map(|p| p.path.as_str())
        .collect();
    if !assumed.is_empty() {
        let _ = writeln!(
            s,
            "assumed in the scenario (--json lists every value's provenance): {}",
            assumed.join(", ")
        );
    }
    s
}

/// The controller's gains, the channels' skew and the fit on each record.
fn controller_lines(s: &mut String, id: &SystemIdentification) {
    if let Some(g) = &id.gains {
        let _ = writeln!(
            s,
            "controller at {:.6} Hz (fitted on {}):",
            g.sample_rate_hz,
            id.fitted_records.join(", ")
        );
        for e in &id.gain_estimates {
            let _ = writeln!(
                s,
                "  {:<40} {}{}",
                e.key,
                plus_minus(e.value, e.std_error),
                if e.held_at_zero { "  (held at 0)" } else { "" }
            );
        }
        let _ = writeln!(
            s,
            "  {:<40} {}",
            "delta_p_highpass_hz", g.delta_p_highpass_hz
        );
        let _ = writeln!(s, "  saturated samples left out: {}", id.saturated_samples);
    }
    for c in &id.channel_skew {
        let _ = writeln!(
            s,
            "channel skew {}: {:+.3} samples ({:+.3e} s){}{}",
            c.column,
            c.delay_samples,
            c.delay_s,
            c.residual_ratio.map_or(String::new(), |r| format!(
                ", force-balance residual {r:.3} of the unshifted"
            )),
            if c.applied {
                ", corrected"
            } else {
                ", not corrected"
            }
        );
        if c.applied && !c.per_record.is_empty() {
            let each: Vec<String> = c
                .per_record
                .iter()
                .map(|r| format!("{} {:+.3}", r.name, r.applied_samples))
                .collect();
            let _ = writeln!(s, "  each record corrected by its own: {}", each.join(", "));
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
}

/// The plant: its geometry, the platen's mechanics, the specimen and the valves.
fn plant_lines(s: &mut String, p: &IdentifiedPlant) {
    let _ = writeln!(
        s,
        "geometry: actuator area {} m² ({}){}",
        p.geometry.area_m2,
        p.geometry.area_source,
        if p.geometry.base_given {
            ", the rest from --base"
        } else {
            "; counts, pressures, bulk modulus nominal (assumed): masses, forces, flows and \
             volumes scale with the area, the motion does not"
        }
    );
    let se = |k: &str| p.std_errors.get(k).copied();
    if let Some(m) = &p.mechanics {
        let _ = writeln!(
            s,
            "platen: mass {} kg, stiffness {} N/m, viscous {} N·(s/m)^α, Coulomb {} N (force \
             residual {:.3} % over {} samples){}",
            plus_minus(
                m.effective_mass_kg,
                se("model.identified.effective_mass_kg")
            ),
            plus_minus(
                m.stiffness_n_per_m,
                se("model.identified.stiffness_n_per_m")
            ),
            plus_minus(
                m.viscous_coefficient,
                se("model.identified.viscous_coefficient")
            ),
            plus_minus(m.coulomb_force_n, se("model.identified.coulomb_force_n")),
            100.0 * m.force_nrmse,
            m.samples,
            m.rod_to_cap_area_ratio.map_or(String::new(), |r| format!(
                "; rod side {r:.5} of the cap side's area (from both pressures)"
            ))
        );
        if m.viscous_exponent != 1.0 || m.low_velocity_force_n > 0.0 {
            let _ = writeln!(
                s,
                "platen friction: sgn(v)·[F_μ + a·e^(−b|v|) + C·|v|^α], α {}, a {} N, b {} s/m \
                 (slips above {} m/s in the fit)",
                m.viscous_exponent,
                plus_minus(
                    m.low_velocity_force_n,
                    se("model.identified.low_velocity_force_n")
                ),
                m.low_velocity_decay_s_per_m,
                m.slip_speed_m_s
            );
        }
    }
    storey_lines(s, p);
    if let Some(h) = &p.hydraulics {
        hydraulics_lines(s, h);
    }
}

/// The specimen's storeys and modes.
fn storey_lines(s: &mut String, p: &IdentifiedPlant) {
    let se = |k: &str| p.std_errors.get(k).copied();
    for (i, st) in p.storeys.iter().enumerate() {
        let k = |q: &str| se(&format!("specimen.storeys[{i}].{q}"));
        let _ = writeln!(
            s,
            "storey {}: mass {} kg, stiffness {} N/m, damping {} N·s/m",
            i + 1,
            plus_minus(st.mass_kg, k("mass_kg")),
            plus_minus(st.stiffness_n_per_m, k("stiffness_n_per_m")),
            plus_minus(st.damping_n_s_per_m, k("damping_n_s_per_m"))
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
    if let Some(t) = &p.transmissibility {
        let _ = writeln!(
            s,
            "the records' own modes (roof over table acceleration, Welch over {} records, \
             {:.4} Hz bins):",
            t.records, t.resolution_hz
        );
        for (i, pk) in t.peaks.iter().enumerate() {
            let zeta = if pk.damping_resolved {
                format!(
                    "half-power damping {:.2} %",
                    100.0 * pk.half_power_damping_ratio
                )
            } else {
                format!(
                    "half-power damping at most {:.2} % (too narrow for the bins to resolve)",
                    100.0 * pk.half_power_damping_ratio
                )
            };
            let _ = writeln!(
                s,
                "  peak {}: {:.4} Hz, {zeta}, coherence {:.3}",
                i + 1,
                pk.frequency_hz,
                pk.coherence
            );
        }
        for c in &t.mode_checks {
            let _ = writeln!(
                s,
                "  identified {:.4} Hz against the peak at {:.4} Hz: {:+.2} %",
                c.identified_hz,
                c.transmissibility_hz,
                100.0 * c.relative_difference
            );
        }
        for w in &t.warnings {
            let _ = writeln!(s, "warning: {w}");
        }
    }
}

/// The valves and the oil column.
fn hydraulics_lines(s: &mut String, h: &IdentifiedHydraulics) {
    let _ = writeln!(
        s,
        "valves (from {}): rated flow {:.5e} m³/s each, leakage {:.3e} m³/s/Pa, spool {} \
         Hz ζ {} delay {:.3e} s (equivalent lag {:.4e} s)",
        h.from,
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

/// The prediction-error fit: how it ended, each channel's NRMSE before and after, each
/// parameter from its equation-error start to its refined value.
fn prediction_error_lines(s: &mut String, f: &PredictionErrorFit) {
    let _ = writeln!(
        s,
        "prediction-error fit (the loop run on the fitted records' commands, accelerations \
         and Δp below {} Hz, each channel over its RMS less its offset): cost {:.4e} → {:.4e} in {} iterations \
         ({} steps rejected); {}; {} residuals, correlation time {:.1} samples ({:.0} \
         effective)",
        f.band_hz,
        f.cost_before,
        f.cost_after,
        f.iterations,
        f.rejected_steps,
        f.stop_reason,
        f.residuals,
        f.correlation_time_samples,
        f.effective_residuals
    );
    for c in &f.channels {
        let _ = writeln!(
            s,
            "  {:<40} NRMSE {} → {}",
            c.channel,
            pct(c.nrmse_before),
            pct(c.nrmse_after)
        );
    }
    for p in &f.parameters {
        let _ = writeln!(
            s,
            "  {:<52} {:.5e} → {}{}",
            p.key,
            p.start,
            plus_minus(p.value, p.std_error),
            if p.refined { "" } else { "  (held)" }
        );
    }
}

/// The identified loop's predictions on each record's command, against the black box and
/// perfect tracking.
fn judgement_lines(s: &mut String, j: &Judgement) {
    let _ = writeln!(
        s,
        "the identified loop on each record's command (RK4, {} steps per controller \
         period; accelerations below {} Hz; black box: FIR of {} taps from the command's \
         acceleration, fitted on the same records):",
        j.steps_per_period, j.band_hz, j.black_box_taps
    );
    let _ = writeln!(
        s,
        "  {:<9} {:<28} {:>11} {:>11} {:>11} {:>11} {:>11}",
        "", "record", "acc model", "acc FIR", "acc perfect", "disp model", "disp perfect"
    );
    for p in &j.predictions {
        prediction_lines(s, p);
    }
    for (name, why) in &j.failed {
        let _ = writeln!(s, "  {}: the run failed: {why}", short(name));
    }
    if let Some(h) = &j.held_out {
        let _ = writeln!(
            s,
            "held out (median of {}): acceleration NRMSE {} (black box {}, perfect tracking \
             {}), displacement {} (perfect tracking {}): {}",
            h.records,
            pct(h.model_acceleration_nrmse),
            h.black_box_acceleration_nrmse.map_or("–".into(), pct),
            pct(h.perfect_tracking_acceleration_nrmse),
            pct(h.model_displacement_nrmse),
            pct(h.perfect_tracking_displacement_nrmse),
            match h.model_beats_black_box {
                Some(true) => "the physical model predicts at least as well as the black box",
                Some(false) => "the black box predicts better than the physical model",
                None => "no black box to compare with",
            }
        );
    }
}

/// One record's line of the predictions' table, and its storeys'.
fn prediction_lines(s: &mut String, p: &Prediction) {
    let _ = writeln!(
        s,
        "  {:<9} {:<28} {:>11} {:>11} {:>11} {:>11} {:>11}",
        if p.fitted { "fitted" } else { "held out" },
        short(&p.name),
        pct(p.model.acceleration_nrmse),
        p.black_box
            .as_ref()
            .map_or("–".into(), |b| pct(b.acceleration_nrmse)),
        pct(p.perfect_tracking.acceleration_nrmse),
        pct(p.model.displacement_nrmse.unwrap_or(f64::NAN)),
        pct(p.perfect_tracking.displacement_nrmse.unwrap_or(f64::NAN)),
    );
    for (k, e) in p.model.storey_acceleration_nrmse.iter().enumerate() {
        let b = p
            .black_box
            .as_ref()
            .and_then(|b| b.storey_acceleration_nrmse.get(k).copied());
        let _ = writeln!(
            s,
            "  {:<9} {:<28} {:>11} {:>11}",
            "",
            format!("  storey {}", k + 1),
            pct(*e),
            b.map_or("–".into(), pct)
        );
    }
}

/// The file name of a record's path.
fn short(name: &str) -> String {
    Path::new(name)
        .file_name()
        .map_or(name.to_owned(), |f| f.to_string_lossy().into_owned())
}

/// The figures of the identified loop's predictions: for each held-out record (every record
/// when none is held out), the table acceleration (recorded, the identified loop, the black
/// box, the command), the displacement, and each storey's acceleration.
pub fn prediction_figures(id: &SystemIdentification) -> Vec<Figure> {
    let Some(j) = &id.judgement else {
        return Vec::new();
    };
    let any_held = j.predictions.iter().any(|p| !p.fitted);
    j.predictions
        .iter()
        .filter(|p| !any_held || !p.fitted)
        .map(|p| prediction_figure(p, j.band_hz))
        .collect()
}

fn prediction_figure(p: &Prediction, band_hz: f64) -> Figure {
    let name = short(&p.name);
    let stem = Path::new(&name)
        .file_stem()
        .map_or(name.clone(), |f| f.to_string_lossy().into_owned());
    let mut panels = vec![acceleration_panel(p, band_hz), displacement_panel(p)];
    panels.extend(storey_panels(p, band_hz));
    let rows = panels.len();
    Figure {
        name: format!("system-prediction-{stem}"),
        title: format!(
            "{name}{}: the identified loop on the record's command",
            if p.fitted { " (fitted)" } else { " (held out)" }
        ),
        caption: format!(
            "The identified loop run on the record's command (closed loop, from rest), against \
             the record; the accelerations below {band_hz} Hz (zero-phase), the black box an \
             FIR filter from the command's acceleration fitted on the same records as the \
             loop. NRMSE in the legends and titles."
        ),
        panels,
        columns: 1,
        rows: Vec::new(),
        size: (1200, 380 * rows as u32 + 120),
    }
}

/// The points drawn of a prediction's series `y` times `scale`, against its time.
fn drawn(p: &Prediction, y: &[f64], scale: f64) -> Points {
    let ys: Vec<f64> = y.iter().map(|v| v * scale).collect();
    thinned(&p.series.t_s, &ys, MAX_POINTS).0
}

/// The table acceleration: recorded, the identified loop and the black box.
fn acceleration_panel(p: &Prediction, band_hz: f64) -> Panel {
    let s = &p.series;
    let mut acc = vec![
        line("recorded", drawn(p, &s.recorded_a_m_s2, 1.0), RECORDED, 2),
        line(
            format!("identified loop ({})", pct(p.model.acceleration_nrmse)),
            drawn(p, &s.predicted_a_m_s2, 1.0),
            SIMULATED,
            2,
        ),
    ];
    if let Some(b) = &p.black_box {
        acc.push(patterned(
            format!("black box ({})", pct(b.acceleration_nrmse)),
            drawn(p, &s.black_box_a_m_s2, 1.0),
            MODEL,
            1,
            crate::figure::Dash::Dashed,
        ));
    }
    Panel::new(
        format!("table acceleration below {band_hz} Hz"),
        "t (s)",
        "a (m/s²)",
        acc,
    )
}

/// The displacement: recorded, the identified loop and the command.
fn displacement_panel(p: &Prediction) -> Panel {
    let s = &p.series;
    Panel::new(
        format!(
            "displacement: identified loop {}, perfect tracking {}",
            pct(p.model.displacement_nrmse.unwrap_or(f64::NAN)),
            pct(p.perfect_tracking.displacement_nrmse.unwrap_or(f64::NAN))
        ),
        "t (s)",
        "u (mm)",
        vec![
            line("recorded", drawn(p, &s.recorded_u_m, 1e3), RECORDED, 2),
            line(
                "identified loop",
                drawn(p, &s.predicted_u_m, 1e3),
                SIMULATED,
                2,
            ),
            patterned(
                "command",
                drawn(p, &s.command_u_m, 1e3),
                MODEL,
                1,
                crate::figure::Dash::Dashed,
            ),
        ],
    )
}

/// Each storey's acceleration: recorded and the identified loop.
fn storey_panels(p: &Prediction, band_hz: f64) -> Vec<Panel> {
    (p.series.storeys.iter().enumerate())
        .map(|(k, (rec, pred))| {
            Panel::new(
                format!(
                    "storey {} acceleration below {band_hz} Hz: identified loop {}",
                    k + 1,
                    pct(p
                        .model
                        .storey_acceleration_nrmse
                        .get(k)
                        .copied()
                        .unwrap_or(f64::NAN))
                ),
                "t (s)",
                "a (m/s²)",
                vec![
                    line("recorded", drawn(p, rec, 1.0), RECORDED, 2),
                    line("identified loop", drawn(p, pred, 1.0), SIMULATED, 2),
                ],
            )
        })
        .collect()
}
