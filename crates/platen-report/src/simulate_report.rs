//! The text summary of a run (`platen simulate`): what ran, its peaks, a forward run's
//! solver, stick and energy figures, a specimen's base shear and storey drifts, the table's
//! limits, and a closed loop's tracking, valves, supply and margins.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use platen_integrate::{ForwardIntegrator as _, Peaks, RunStats};
use platen_model::{Specimen, STANDARD_GRAVITY_M_S2};
use platen_scenario::{PlatenScenario, Run, RunOutput, RunSummary, SpecimenSummary};

/// The text summary of `scenario`'s run `output` (summarised as `summary`), its CSV written
/// to `out` if any, and the figure files `figures` written for it (none: no figure lines).
///
/// ```no_run
/// use std::path::Path;
/// use platen_scenario::{PlatenScenario, RunSummary};
/// # struct Nothing;
/// # impl platen_integrate::SampleSink for Nothing {
/// #     fn accept(&mut self, _: &platen_integrate::Sample) {}
/// # }
///
/// let path = Path::new("scenarios/specimen/frame-forward.json");
/// let scenario = PlatenScenario::load(path)?;
/// let output = scenario.run(&mut Nothing)?;
/// let summary = RunSummary::new(path, &scenario, &output, None);
/// print!("{}", platen_report::simulate_report::text(&scenario, &output, &summary, None, &[]));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn text(
    scenario: &PlatenScenario,
    output: &RunOutput,
    summary: &RunSummary,
    out: Option<&Path>,
    figures: &[PathBuf],
) -> String {
    let mut s = String::new();
    run_lines(&mut s, scenario, output, out);
    loop_lines(&mut s, summary);
    if !figures.is_empty() {
        let _ = writeln!(s, "  wrote {} figure files (SVG and PNG):", figures.len());
        for path in figures {
            let _ = writeln!(s, "    {}", path.display());
        }
    }
    s
}

/// `", overridden: name = value, …"` when the scenario lays values over its preset's.
fn overridden(s: &PlatenScenario) -> String {
    let values = s.rig.overrides.values();
    if values.is_empty() {
        return String::new();
    }
    let listed: Vec<String> = values
        .iter()
        .map(|(key, value)| format!("{} = {value}", key.name()))
        .collect();
    format!(", overridden: {}", listed.join(", "))
}

/// `x` to 3 decimals without trailing zeros (4.2 g, 6.8 MN, 2.25 g).
fn trimmed(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// The specimen's lines: the peak base shear, kN, and each storey's peak drift, mm, with
/// their times (nothing without a specimen); for a storey with a height its drift ratio, and
/// for a storey that yields its ductility demand, residual drift, yield excursions and
/// hysteretic energy.
fn specimen_lines(s: &mut String, peaks: &Peaks, specimen: Option<&Specimen>) {
    if peaks.storeys == 0 {
        return;
    }
    let _ = writeln!(
        s,
        "  peak base shear   {:>+10.1} kN    at {:.3} s",
        peaks.base_shear_n.value / 1e3,
        peaks.base_shear_n.t_s
    );
    let summary = SpecimenSummary::new(specimen, peaks);
    for (i, st) in summary.storeys.iter().enumerate() {
        let ratio = st
            .peak_drift_ratio
            .map(|r| format!(" ({:.2} % of its height)", r * 100.0))
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "  peak storey {} drift {:>+8.3} mm    at {:.3} s{ratio}",
            i + 1,
            st.peak_drift_m * 1e3,
            st.peak_drift_m_t_s
        );
        if let (Some(mu), Some(excursions), Some(e)) =
            (st.ductility, st.yield_excursions, st.hysteretic_j)
        {
            let _ = writeln!(
                s,
                "    storey {} ductility {mu:.2}, {excursions} yield excursions, residual drift \
                 {:+.3} mm, hysteretic energy {:.1} kJ",
                i + 1,
                st.residual_drift_m * 1e3,
                e / 1e3
            );
        }
    }
}

/// What ran, its peaks, a forward run's figures and the table's limits.
fn run_lines(s: &mut String, sc: &PlatenScenario, output: &RunOutput, out: Option<&Path>) {
    let (peaks, stats) = (&output.peaks, output.stats.as_ref());
    let dir = match sc.run {
        Run::ClosedLoop { .. } => "closed loop (command → controller → valves → platen)",
        Run::Forward { .. } => "forward (force → motion)",
        Run::Inverse { .. } => "inverse (motion → force)",
    };
    let _ = writeln!(
        s,
        "{}: {dir}, {} model, {} at {:.2} MPa{}",
        sc.name,
        sc.rig.model.form(),
        sc.rig.preset.name(),
        sc.rig.hold_down_pressure_pa / 1e6,
        overridden(sc)
    );
    let _ = writeln!(
        s,
        "  {} samples over {:.3} s",
        peaks.samples,
        peaks.span_s.1 - peaks.span_s.0
    );
    for (channel, how) in &sc.derived {
        let _ = writeln!(s, "  derived {channel}: {how}");
    }
    peak_lines(s, peaks);
    specimen_lines(s, peaks, sc.rig.specimen.as_ref());
    if let (Some(st), Run::Forward { integrator, .. }) = (stats, &sc.run) {
        forward_lines(s, st, integrator.name());
    }
    limit_lines(s, sc, peaks);
    if let Some(out) = out {
        let _ = writeln!(s, "  wrote {}", out.display());
    }
}

/// The peaks of the table's motion and the actuator force.
fn peak_lines(s: &mut String, peaks: &Peaks) {
    let _ = writeln!(
        s,
        "  peak displacement {:>+10.4} m     at {:.3} s",
        peaks.u_m.value, peaks.u_m.t_s
    );
    let _ = writeln!(
        s,
        "  peak velocity     {:>+10.4} m/s   at {:.3} s",
        peaks.v_m_s.value, peaks.v_m_s.t_s
    );
    let _ = writeln!(
        s,
        "  peak acceleration {:>+10.4} m/s²  at {:.3} s ({:.3} g)",
        peaks.a_m_s2.value,
        peaks.a_m_s2.t_s,
        peaks.a_m_s2.value / STANDARD_GRAVITY_M_S2
    );
    let _ = writeln!(
        s,
        "  peak force        {:>+10.1} kN    at {:.3} s",
        peaks.force_n.value / 1e3,
        peaks.force_n.t_s
    );
}

/// A forward run's stick, solver and energy figures; `integrator` names its method.
fn forward_lines(s: &mut String, st: &RunStats, integrator: &str) {
    let _ = writeln!(
        s,
        "  stick: {:.3} s in all, {} stops, {} breakaways, {} reversals",
        st.stick_time_s, st.stick_events, st.breakaways, st.reversals
    );
    let _ = writeln!(
        s,
        "  solver: {}, {} steps ({} rejected), {} right-hand-side evaluations, {} events located",
        integrator,
        st.steps,
        st.rejected_steps,
        st.rhs_evaluations,
        st.events()
    );
    let _ = writeln!(
        s,
        "  energy: actuator work {:.4e} J = ΔE_kin + ΔE_el + dissipated {:.4e} J; residual {:.2e} J ({:.1e} relative)",
        st.energy.actuator_work_j,
        st.energy.dissipated_j,
        st.energy.residual_j(),
        st.energy.relative_residual()
    );
}

/// The table's limits: within them, or each one exceeded.
fn limit_lines(s: &mut String, sc: &PlatenScenario, peaks: &Peaks) {
    let ex = peaks.exceedances(&sc.rig.limits);
    if ex.is_empty() {
        let l = &sc.rig.limits;
        let _ = writeln!(
            s,
            "  within the table's limits (stroke ±{} m, {} m/s, {} g, {} MN)",
            l.stroke_m,
            l.velocity_m_s,
            trimmed(l.acceleration_m_s2 / STANDARD_GRAVITY_M_S2),
            trimmed(l.force_n / 1e6)
        );
    }
    for e in ex {
        let _ = writeln!(
            s,
            "  EXCEEDS {} limit: peak {:+.4} vs limit {:.4} (SI units) at {:.3} s",
            e.quantity, e.peak, e.limit, e.t_s
        );
    }
}

/// The closed loop's lines (nothing for the other runs).
fn loop_lines(s: &mut String, summary: &RunSummary) {
    let (Some(ts), Some(f)) = (&summary.table_system, summary.oil_column_frequency_hz) else {
        return;
    };
    let _ = writeln!(
        s,
        "  closed loop: oil column {f:.2} Hz at mid-stroke; {} controller samples, {} steps each",
        ts.controller_samples, ts.steps_per_controller_period
    );
    // The relative error (NRMSE) first: it is what an engineer compares across runs.
    let nrmse = |x: Option<f64>| x.map_or("—".to_string(), |x| format!("{:.1} %", 100.0 * x));
    let _ = writeln!(
        s,
        "  tracking: displacement error {} NRMSE, {:.3} mm RMS, {:+.3} mm peak at {:.3} s",
        nrmse(ts.tracking_displacement_nrmse),
        ts.tracking_displacement_rms_m * 1e3,
        ts.tracking_displacement_peak_m * 1e3,
        ts.tracking_displacement_peak_t_s
    );
    let _ = writeln!(
        s,
        "            acceleration error {} NRMSE, {:.4} m/s² RMS, {:+.4} m/s² peak at {:.3} s",
        nrmse(ts.tracking_acceleration_nrmse),
        ts.tracking_acceleration_rms_m_s2,
        ts.tracking_acceleration_peak_m_s2,
        ts.tracking_acceleration_peak_t_s
    );
    let _ = writeln!(
        s,
        "  valves: peak flow {:+.4} m³/s of {:.4} m³/s capacity ({:.0} %), saturated {:.3} s",
        ts.peak_flow_m3_s,
        ts.valve_flow_capacity_m3_s,
        100.0 * ts.peak_flow_m3_s.abs() / ts.valve_flow_capacity_m3_s,
        ts.valve_saturated_time_s
    );
    let _ = writeln!(
        s,
        "  supply: lowest {:.2} MPa{}",
        ts.min_supply_pressure_pa / 1e6,
        ts.cavitation_at_s
            .map_or(String::new(), |t| format!("; CAVITATION at {t:.4} s"))
    );
    let m = &ts.loop_margins;
    let _ = writeln!(
        s,
        "  loop (linearised): {}, gain margin {}, phase margin {}",
        if m.stable { "stable" } else { "UNSTABLE" },
        m.gain_margin_db.map_or("none".into(), |g| format!(
            "{g:.1} dB at {:.1} Hz",
            m.phase_crossover_hz.unwrap_or(0.0)
        )),
        m.phase_margin_deg.map_or("none".into(), |p| format!(
            "{p:.1}° at {:.2} Hz",
            m.gain_crossover_hz.unwrap_or(0.0)
        ))
    );
}

/// A verb's `--json` object with the outputs written beside it: `figures`, the files written
/// (when figures were asked for: `Some`, even if empty), and `report`, the HTML page (if any).
/// The keys stay in alphabetical order (a `serde_json` map); a value that is not an object is
/// returned as it is.
pub fn with_outputs(
    mut value: serde_json::Value,
    figures: Option<&[PathBuf]>,
    report: Option<&Path>,
) -> serde_json::Value {
    if let serde_json::Value::Object(map) = &mut value {
        if let Some(figures) = figures {
            let list: Vec<String> = figures.iter().map(|p| p.display().to_string()).collect();
            map.insert("figures".into(), list.into());
        }
        if let Some(report) = report {
            map.insert("report".into(), report.display().to_string().into());
        }
    }
    value
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use super::with_outputs;

    /// The outputs go in as sorted keys; without them the value is unchanged.
    #[test]
    fn with_outputs_adds_the_figures_and_report_written() {
        let v = serde_json::json!({"name": "x", "samples": 3});
        assert_eq!(with_outputs(v.clone(), None, None), v);
        let figures = [PathBuf::from("d/a.svg"), PathBuf::from("d/a.png")];
        let w = with_outputs(v, Some(&figures), Some(Path::new("r.html")));
        assert_eq!(
            serde_json::to_string(&w).unwrap(),
            r#"{"figures":["d/a.svg","d/a.png"],"name":"x","report":"r.html","samples":3}"#
        );
    }
}
