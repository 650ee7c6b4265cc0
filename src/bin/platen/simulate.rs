//! `platen simulate`: run a scenario, stream its time series to CSV, summarise it.
//!
//! The CSV is written as the samples are produced ([`CsvSink`]), to a temporary file next to
//! the target that is renamed over it when the run is complete and removed if it fails, so a
//! one-hour 1024 Hz run holds no trajectory in memory.

use std::path::Path;

use anyhow::{Context, Result};

use platen_integrate::{ForwardIntegrator, Peaks, RunStats, Sample, SampleSink};
use platen_model::STANDARD_GRAVITY_M_S2;
use platen_report::{run_figures, run_figures::RunRecorder, FigureSize};
use platen_scenario::{CsvSink, Run, RunSummary, Scenario};

/// The options of `platen simulate`.
pub struct Options<'a> {
    /// Scenario JSON file.
    pub scenario: &'a Path,
    /// CSV file for the time series.
    pub out: Option<&'a Path>,
    /// Print JSON on stdout.
    pub json: bool,
    /// Folder for the figures (SVG and PNG).
    pub plot: Option<&'a Path>,
    /// Size of the figures.
    pub size: FigureSize,
    /// The hold-down pressure to run at, MPa, instead of the scenario's.
    pub pressure_mpa: Option<f64>,
}

pub fn run(opts: &Options<'_>) -> Result<()> {
    let (path, out) = (opts.scenario, opts.out);
    let mut scenario = Scenario::load(path)?;
    if let Some(p) = opts.pressure_mpa {
        scenario = scenario
            .at_pressure(p * 1e6)
            .with_context(|| format!("`{}`: the model at --pressure-mpa {p}", path.display()))?;
    }
    // Create the temporary output first, so that an unwritable path fails before the run.
    let storeys = scenario.storeys();
    let mut stream = out
        .map(|p| CsvSink::create_for(p, storeys, scenario.closed_loop.is_some()))
        .transpose()?;
    // The figures' points are collected as the run goes, in memory that does not grow with it.
    let mut recorder = opts.plot.map(|_| RunRecorder::new(&scenario.run));
    let output = match (stream.as_mut(), recorder.as_mut()) {
        (Some(sink), Some(rec)) => scenario.run(&mut (sink, rec))?,
        (Some(sink), None) => scenario.run(sink)?,
        (None, Some(rec)) => scenario.run(rec)?,
        (None, None) => scenario.run(&mut NoOutput)?,
    };
    if let Some(stream) = stream {
        stream.finish()?;
    }
    let written = match recorder {
        Some(recorder) => platen_report::write_outputs(
            opts.plot,
            None,
            &opts.size,
            || run_figures::figures(recorder, &scenario),
            |_, _| String::new(),
        )?,
        None => Vec::new(),
    };
    let summary = RunSummary::new(path, &scenario, &output, out);
    for warning in &summary.warnings {
        eprintln!("warning: {warning}");
    }
    if opts.json {
        // Through a Value, so the keys come out in alphabetical order.
        let mut value = serde_json::to_value(&summary)?;
        if let (Some(_), Some(map)) = (opts.plot, value.as_object_mut()) {
            map.insert("figures".into(), figure_list(&written).into());
        }
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        print_summary(&scenario, &output.peaks, output.stats.as_ref(), out)?;
        print_loop(&summary)?;
        if !written.is_empty() {
            outln!("  wrote {} figure files (SVG and PNG):", written.len());
            for path in &written {
                outln!("    {}", path.display());
            }
        }
    }
    Ok(())
}

/// The figure files written, as the `figures` list of `--json`.
pub fn figure_list(written: &[std::path::PathBuf]) -> Vec<String> {
    written.iter().map(|p| p.display().to_string()).collect()
}

/// `", overridden: name = value, …"` when the scenario lays values over its preset's.
fn overridden(s: &Scenario) -> String {
    let values = s.overrides.values();
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

/// A sink that keeps nothing (the summary's [`Peaks`] are collected alongside).
struct NoOutput;

impl SampleSink for NoOutput {
    #[inline]
    fn accept(&mut self, _: &Sample) {}
}

/// The closed loop's lines of the text summary.
fn print_loop(summary: &RunSummary) -> anyhow::Result<()> {
    let (Some(ts), Some(f)) = (&summary.table_system, summary.oil_column_frequency_hz) else {
        return Ok(());
    };
    outln!(
        "  closed loop: oil column {f:.2} Hz at mid-stroke; {} controller samples, {} steps each",
        ts.controller_samples,
        ts.steps_per_controller_period
    );
    outln!(
        "  tracking: displacement error {:.3} mm RMS, {:+.3} mm peak at {:.3} s",
        ts.tracking_displacement_rms_m * 1e3,
        ts.tracking_displacement_peak_m * 1e3,
        ts.tracking_displacement_peak_t_s
    );
    outln!(
        "            acceleration error {:.4} m/s² RMS, {:+.4} m/s² peak at {:.3} s",
        ts.tracking_acceleration_rms_m_s2,
        ts.tracking_acceleration_peak_m_s2,
        ts.tracking_acceleration_peak_t_s
    );
    outln!(
        "  valves: peak flow {:+.4} m³/s of {:.4} m³/s capacity ({:.0} %), saturated {:.3} s",
        ts.peak_flow_m3_s,
        ts.valve_flow_capacity_m3_s,
        100.0 * ts.peak_flow_m3_s.abs() / ts.valve_flow_capacity_m3_s,
        ts.valve_saturated_time_s
    );
    outln!(
        "  supply: lowest {:.2} MPa{}",
        ts.min_supply_pressure_pa / 1e6,
        ts.cavitation_at_s
            .map_or(String::new(), |t| format!("; CAVITATION at {t:.4} s"))
    );
    let m = &ts.loop_margins;
    outln!(
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
    Ok(())
}

fn print_summary(
    s: &Scenario,
    peaks: &Peaks,
    stats: Option<&RunStats>,
    out: Option<&Path>,
) -> anyhow::Result<()> {
    let dir = if s.closed_loop.is_some() {
        "closed loop (command → controller → valves → platen)"
    } else if stats.is_some() {
        "forward (force → motion)"
    } else {
        "inverse (motion → force)"
    };
    outln!(
        "{}: {dir}, {} model, {} at {:.2} MPa{}",
        s.name,
        s.model.form(),
        s.preset.name(),
        s.hold_down_pressure_pa / 1e6,
        overridden(s)
    );
    outln!(
        "  {} samples over {:.3} s",
        peaks.samples,
        peaks.span_s.1 - peaks.span_s.0
    );
    for (channel, how) in &s.derived {
        outln!("  derived {channel}: {how}");
    }
    outln!(
        "  peak displacement {:>+10.4} m     at {:.3} s",
        peaks.u_m.value,
        peaks.u_m.t_s
    );
    outln!(
        "  peak velocity     {:>+10.4} m/s   at {:.3} s",
        peaks.v_m_s.value,
        peaks.v_m_s.t_s
    );
    outln!(
        "  peak acceleration {:>+10.4} m/s²  at {:.3} s ({:.3} g)",
        peaks.a_m_s2.value,
        peaks.a_m_s2.t_s,
        peaks.a_m_s2.value / STANDARD_GRAVITY_M_S2
    );
    outln!(
        "  peak force        {:>+10.1} kN    at {:.3} s",
        peaks.force_n.value / 1e3,
        peaks.force_n.t_s
    );
    if let (Some(st), Run::Forward { integrator, .. }) = (stats, &s.run) {
        outln!(
            "  stick: {:.3} s in all, {} stops, {} breakaways, {} reversals",
            st.stick_time_s,
            st.stick_events,
            st.breakaways,
            st.reversals
        );
        outln!(
            "  solver: {}, {} steps ({} rejected), {} right-hand-side evaluations, {} events located",
            integrator.name(),
            st.steps,
            st.rejected_steps,
            st.rhs_evaluations,
            st.events()
        );
        outln!(
            "  energy: actuator work {:.4e} J = ΔE_kin + ΔE_el + dissipated {:.4e} J; residual {:.2e} J ({:.1e} relative)",
            st.energy.actuator_work_j,
            st.energy.dissipated_j,
            st.energy.residual_j(),
            st.energy.relative_residual()
        );
    }
    let ex = peaks.exceedances(&s.limits);
    if ex.is_empty() {
        let l = &s.limits;
        outln!(
            "  within the table's limits (stroke ±{} m, {} m/s, {} g, {} MN)",
            l.stroke_m,
            l.velocity_m_s,
            trimmed(l.acceleration_m_s2 / STANDARD_GRAVITY_M_S2),
            trimmed(l.force_n / 1e6)
        );
    }
    for e in ex {
        outln!(
            "  EXCEEDS {} limit: peak {:+.4} vs limit {:.4} (SI units) at {:.3} s",
            e.quantity,
            e.peak,
            e.limit,
            e.t_s
        );
    }
    if let Some(out) = out {
        outln!("  wrote {}", out.display());
    }
    Ok(())
}
