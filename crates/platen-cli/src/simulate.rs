//! `platen simulate`: run a scenario, stream its time series to CSV, summarise it.
//!
//! The CSV is written as the samples are produced ([`CsvSink`]), to a temporary file next to
//! the target that is renamed over it when the run is complete and removed if it fails, so a
//! one-hour 1024 Hz run holds no trajectory in memory.

use std::path::Path;

use anyhow::Result;
use serde_json::{json, Map, Value};

use platen_integrate::{ForwardIntegrator, Peaks, RunStats, Sample, SampleSink};
use platen_model::STANDARD_GRAVITY_M_S2;
use platen_scenario::{CsvSink, Run, RunOutput, Scenario};

pub fn run(path: &Path, out: Option<&Path>, json_out: bool) -> Result<()> {
    let scenario = Scenario::load(path)?;
    // Create the temporary output first, so that an unwritable path fails before the run.
    let mut stream = out.map(CsvSink::create).transpose()?;
    let RunOutput { peaks, stats } = match stream.as_mut() {
        Some(sink) => scenario.run(sink)?,
        None => scenario.run(&mut NoOutput)?,
    };
    if let Some(stream) = stream {
        stream.finish()?;
    }
    let summary = summary_json(path, &scenario, &peaks, stats.as_ref(), out);
    if json_out {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_summary(&scenario, &peaks, stats.as_ref(), out);
    }
    Ok(())
}

/// A sink that keeps nothing (the summary's [`Peaks`] are collected alongside).
struct NoOutput;

impl SampleSink for NoOutput {
    #[inline]
    fn accept(&mut self, _: &Sample) {}
}

fn summary_json(
    path: &Path,
    s: &Scenario,
    peaks: &Peaks,
    stats: Option<&RunStats>,
    out: Option<&Path>,
) -> Value {
    let mut m = Map::new();
    m.insert("scenario".into(), json!(path.display().to_string()));
    m.insert("name".into(), json!(s.name));
    m.insert(
        "direction".into(),
        json!(if stats.is_some() {
            "forward"
        } else {
            "inverse"
        }),
    );
    m.insert("model_form".into(), json!(s.model.form()));
    m.insert("preset".into(), json!(s.preset.name()));
    m.insert(
        "hold_down_pressure_mpa".into(),
        json!(s.hold_down_pressure_pa / 1e6),
    );
    m.insert("samples".into(), json!(peaks.samples));
    m.insert("duration_s".into(), json!(peaks.span_s.1 - peaks.span_s.0));
    for (key, peak) in [
        ("peak_u_m", peaks.u_m),
        ("peak_v_m_s", peaks.v_m_s),
        ("peak_a_m_s2", peaks.a_m_s2),
        ("peak_force_n", peaks.force_n),
    ] {
        m.insert(key.into(), json!(peak.value));
        m.insert(format!("{key}_t_s"), json!(peak.t_s));
    }
    if let Some(st) = stats {
        m.insert("stick_time_s".into(), json!(st.stick_time_s));
        m.insert("stick_events".into(), json!(st.stick_events));
        m.insert("breakaways".into(), json!(st.breakaways));
        m.insert("reversals".into(), json!(st.reversals));
        let method = match &s.run {
            Run::Forward { integrator, .. } => integrator.name(),
            Run::Inverse { .. } => "none",
        };
        m.insert(
            "solver".into(),
            json!({
                "method": method,
                "steps": st.steps,
                "accepted_steps": st.accepted_steps,
                "rejected_steps": st.rejected_steps,
                "rhs_evaluations": st.rhs_evaluations,
                "events_located": st.events(),
                "root_iterations": st.root_iterations,
            }),
        );
        let e = &st.energy;
        m.insert(
            "energy".into(),
            json!({
                "actuator_work_j": e.actuator_work_j,
                "kinetic_start_j": e.kinetic_start_j,
                "kinetic_end_j": e.kinetic_end_j,
                "elastic_start_j": e.elastic_start_j,
                "elastic_end_j": e.elastic_end_j,
                "dissipated_j": e.dissipated_j,
                "residual_j": e.residual_j(),
                "relative_residual": e.relative_residual(),
            }),
        );
    }
    let exceed: Vec<Value> = peaks
        .exceedances(&s.limits)
        .iter()
        .map(|e| json!({"quantity": e.quantity, "peak": e.peak, "limit": e.limit, "t_s": e.t_s}))
        .collect();
    m.insert("limit_exceedances".into(), Value::Array(exceed));
    // Every limit with the run's peak against it, so a report can say which ones it respects.
    let l = &s.limits;
    let check = |peak: f64, limit: f64| json!({"limit": limit, "peak": peak, "respected": peak.abs() <= limit});
    m.insert(
        "limits".into(),
        json!({
            "stroke_m": check(peaks.u_m.value, l.stroke_m),
            "velocity_m_s": check(peaks.v_m_s.value, l.velocity_m_s),
            "acceleration_m_s2": check(peaks.a_m_s2.value, l.acceleration_m_s2),
            "force_n": check(peaks.force_n.value, l.force_n),
        }),
    );
    m.insert("out".into(), json!(out.map(|p| p.display().to_string())));
    Value::Object(m)
}

fn print_summary(s: &Scenario, peaks: &Peaks, stats: Option<&RunStats>, out: Option<&Path>) {
    let dir = if stats.is_some() {
        "forward (force → motion)"
    } else {
        "inverse (motion → force)"
    };
    println!(
        "{}: {dir}, {} model, {} at {:.2} MPa",
        s.name,
        s.model.form(),
        s.preset.name(),
        s.hold_down_pressure_pa / 1e6
    );
    println!(
        "  {} samples over {:.3} s",
        peaks.samples,
        peaks.span_s.1 - peaks.span_s.0
    );
    println!(
        "  peak displacement {:>+10.4} m     at {:.3} s",
        peaks.u_m.value, peaks.u_m.t_s
    );
    println!(
        "  peak velocity     {:>+10.4} m/s   at {:.3} s",
        peaks.v_m_s.value, peaks.v_m_s.t_s
    );
    println!(
        "  peak acceleration {:>+10.4} m/s²  at {:.3} s ({:.3} g)",
        peaks.a_m_s2.value,
        peaks.a_m_s2.t_s,
        peaks.a_m_s2.value / STANDARD_GRAVITY_M_S2
    );
    println!(
        "  peak force        {:>+10.1} kN    at {:.3} s",
        peaks.force_n.value / 1e3,
        peaks.force_n.t_s
    );
    if let (Some(st), Run::Forward { integrator, .. }) = (stats, &s.run) {
        println!(
            "  stick: {:.3} s in all, {} stops, {} breakaways, {} reversals",
            st.stick_time_s, st.stick_events, st.breakaways, st.reversals
        );
        println!(
            "  solver: {}, {} steps ({} rejected), {} right-hand-side evaluations, {} events located",
            integrator.name(),
            st.steps,
            st.rejected_steps,
            st.rhs_evaluations,
            st.events()
        );
        println!(
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
        println!(
            "  within the table's limits (stroke ±{} m, {} m/s, {:.1} g, {:.1} MN)",
            l.stroke_m,
            l.velocity_m_s,
            l.acceleration_m_s2 / STANDARD_GRAVITY_M_S2,
            l.force_n / 1e6
        );
    }
    for e in ex {
        println!(
            "  EXCEEDS {} limit: peak {:+.4} vs limit {:.4} (SI units) at {:.3} s",
            e.quantity, e.peak, e.limit, e.t_s
        );
    }
    if let Some(out) = out {
        println!("  wrote {}", out.display());
    }
}
