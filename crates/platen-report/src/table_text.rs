//! The text `platen simulate` and `platen model` print for a multi-axis table: its run's
//! summary ([`summary_text`]) and its description ([`description_text`]).

use std::fmt::Write;
use std::path::PathBuf;

use platen_model::multi_axis::Dof;
use platen_scenario::multi_axis::{TableDescription, TableLoopDescription, TableSummary};

/// `x` in percent with two decimals, `—` for none (a still command's relative error).
fn percent(x: Option<f64>) -> String {
    x.map_or("—".to_owned(), |x| format!("{:.2} %", 100.0 * x))
}

/// The text `platen simulate` prints for a multi-axis run (`figures` the files written).
pub fn summary_text(s: &TableSummary, figures: &[PathBuf]) -> String {
    let mut t = String::new();
    axes_lines(&mut t, s);
    tracking_lines(&mut t, s);
    limit_lines(&mut t, s);
    actuator_lines(&mut t, s);
    loop_lines(&mut t, s);
    for w in &s.warnings {
        let _ = writeln!(t, "  warning: {w}");
    }
    if let Some(o) = &s.output {
        let _ = writeln!(t, "  wrote {o}");
    }
    for f in figures {
        let _ = writeln!(t, "  wrote {}", f.display());
    }
    t
}

/// What ran and each axis's peaks.
fn axes_lines(t: &mut String, s: &TableSummary) {
    let what = match s.kind {
        "forward" => "forward from the actuator forces",
        "closed_loop" => "closed loop: the DOF controller follows a six-DOF command",
        _ => "inverse of a six-DOF motion",
    };
    let _ = writeln!(
        t,
        "{}: {what}, {} samples over {:.3} s",
        s.name, s.samples, s.duration_s
    );
    let _ = writeln!(t, "  axis    peak          rate          acceleration");
    for d in Dof::ALL {
        let a = &s.axes[d.name()];
        let u = d.unit();
        let _ = writeln!(
            t,
            "  {:<6}  {:>10.4} {u:<3} {:>10.4} {u}/s {:>10.4} {u}/s²",
            d.name(),
            a.peak,
            a.peak_rate,
            a.peak_acceleration
        );
    }
}

/// A closed loop's tracking per DOF.
fn tracking_lines(t: &mut String, s: &TableSummary) {
    if let Some(tr) = &s.tracking {
        let _ = writeln!(
            t,
            "  tracking  rms error     peak error    nrmse     rms acc. error  peak acc. error  acc. nrmse"
        );
        for d in Dof::ALL {
            let Some(a) = tr.get(d.name()) else { continue };
            let u = d.unit();
            let _ = writeln!(
                t,
                "  {:<8}  {:>9.3e} {u:<3} {:>9.3e} {u:<3} {:>8}  {:>9.3e} {u}/s²  {:>9.3e} {u}/s²  {:>8}",
                d.name(),
                a.rms_error,
                a.peak_error,
                percent(a.displacement_nrmse),
                a.rms_acceleration_error,
                a.peak_acceleration_error,
                percent(a.acceleration_nrmse)
            );
        }
    }
}

/// The axes' limits, where given.
fn limit_lines(t: &mut String, s: &TableSummary) {
    for d in Dof::ALL {
        let Some(l) = s.limits.get(d.name()) else {
            continue;
        };
        if l.displacement_limit.is_none()
            && l.rate_limit.is_none()
            && l.acceleration_limit.is_none()
        {
            continue;
        }
        let show = |x: Option<f64>| x.map_or("-".to_owned(), |v| format!("{v:.4}"));
        let _ = writeln!(
            t,
            "  limits {}: {} {}, {} {}/s, {} {}/s²{}",
            d.name(),
            show(l.displacement_limit),
            d.unit(),
            show(l.rate_limit),
            d.unit(),
            show(l.acceleration_limit),
            d.unit(),
            if l.respected { "" } else { "  EXCEEDED" }
        );
    }
}

/// The actuators' strokes, forces and flows, the struts' forces, the specimen's peaks.
fn actuator_lines(t: &mut String, s: &TableSummary) {
    let _ = writeln!(
        t,
        "  actuator  stroke (limit) m      force min … max (limits) kN"
    );
    for a in &s.actuators {
        let _ = writeln!(
            t,
            "  {:<8}  {:.4} ({:.4})      {:.1} … {:.1} ({:.1} … {:.1}){}",
            a.name,
            a.peak_stroke_m,
            a.stroke_limit_m,
            a.min_force_n / 1e3,
            a.max_force_n / 1e3,
            a.pull_limit_n / 1e3,
            a.push_limit_n / 1e3,
            if a.respected { "" } else { "  OUT OF LIMITS" }
        );
        if let (Some(q), Some(cap)) = (a.peak_flow_m3_s, a.flow_capacity_m3_s) {
            let _ = writeln!(
                t,
                "            flow {:.4} of {:.4} m³/s ({:.0} %), saturated {:.3} s",
                q,
                cap,
                100.0 * q / cap,
                a.saturated_time_s.unwrap_or(0.0)
            );
        }
    }
    for st in &s.struts {
        let _ = writeln!(
            t,
            "  strut {}: pull {:.1} … {:.1} kN",
            st.name,
            st.min_force_n / 1e3,
            st.max_force_n / 1e3
        );
    }
    for (k, v) in &s.specimen {
        let _ = writeln!(t, "  specimen {k}: peak {v:.1}");
    }
    if let Some(o) = &s.overturning_moment {
        let limit = o
            .limit_n_m
            .map_or(String::new(), |l| format!(" of {:.1} MN·m", l / 1e6));
        let _ = writeln!(
            t,
            "  overturning moment: peak {:.3} MN·m{limit}",
            o.peak_n_m / 1e6
        );
    }
}

/// The closed loop's figures and stability.
fn loop_lines(t: &mut String, s: &TableSummary) {
    if let Some(l) = &s.loop_figures {
        let _ = writeln!(
            t,
            "  loop: {} controller samples, {} RK4 steps each; lowest supply {:.2} MPa; \
             largest warping force {:.1} kN; saturated {:.3} s",
            l.controller_samples,
            l.steps_per_period,
            l.min_supply_pressure_pa / 1e6,
            l.max_warping_force_n / 1e3,
            l.saturated_time_s
        );
        let verdict = match &l.stability {
            Some(st) if st.stable => "stable".to_owned(),
            Some(st) => format!("UNSTABLE, {}", st.unstable_words().unwrap_or_default()),
            None => "not linearised".to_owned(),
        };
        let margins: Vec<String> = Dof::ALL
            .iter()
            .filter_map(|d| {
                let m = l.loop_margins.get(d.name())?;
                let gm = m
                    .gain_margin_db
                    .map_or("-".to_owned(), |g| format!("{g:.1} dB"));
                let pm = m
                    .phase_margin_deg
                    .map_or("-".to_owned(), |p| format!("{p:.0}°"));
                Some(format!("{} {gm}, {pm}", d.name()))
            })
            .collect();
        let _ = writeln!(
            t,
            "  loop stability (linearised at neutral): {verdict}; margins {}",
            margins.join("; ")
        );
    }
}

/// The text `platen model` prints for a multi-axis scenario.
pub fn description_text(d: &TableDescription) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{}: multi-axis table, platen {:.1} t",
        d.name,
        d.mass_kg / 1e3
    );
    if !d.held_dofs.is_empty() {
        let _ = writeln!(t, "  held: {}", d.held_dofs.join(", "));
    }
    let _ = writeln!(t, "  modes (valves shut, at neutral):");
    for (i, m) in d.modes.iter().enumerate() {
        let s = m.shape;
        let _ = writeln!(
            t,
            "    {:>2}  {:>8.3} Hz  shape x {:+.3e} y {:+.3e} z {:+.3e} roll {:+.3e} pitch {:+.3e} yaw {:+.3e}",
            i + 1,
            m.frequency_hz,
            s[0],
            s[1],
            s[2],
            s[3],
            s[4],
            s[5]
        );
    }
    let _ = writeln!(t, "  capacities (bare table, about the static hold):");
    for (axis, values) in &d.axes {
        let list: Vec<String> = values.iter().map(|(k, v)| format!("{k} {v:.4e}")).collect();
        let _ = writeln!(t, "    {axis:<6} {}", list.join(", "));
    }
    if let Some(l) = &d.loop_figures {
        loop_description_lines(&mut t, l);
    }
    t
}

/// A closed loop's stability, margins per DOF and cross-talk, linearised at neutral.
fn loop_description_lines(t: &mut String, l: &TableLoopDescription) {
    let st = &l.stability;
    if st.stable {
        let _ = writeln!(
            t,
            "  closed loop (linearised at neutral): stable, no pole in the right half-plane"
        );
    } else {
        let poles: Vec<String> = st
            .unstable_poles
            .iter()
            .map(|[re, f]| format!("{re:.3} 1/s at {f:.2} Hz"))
            .collect();
        let _ = writeln!(
            t,
            "  closed loop (linearised at neutral): UNSTABLE, growing {}{}",
            poles.join(", "),
            st.unstable_dof
                .map_or(String::new(), |d| format!(" (mostly {d})"))
        );
    }
    let _ = writeln!(
        t,
        "  each DOF's loop broken at its drive (the others closed):"
    );
    let show = |x: Option<f64>, unit: &str| x.map_or("-".to_owned(), |v| format!("{v:.2} {unit}"));
    for d in Dof::ALL {
        let Some(m) = l.dofs.get(d.name()) else {
            continue;
        };
        let _ = writeln!(
            t,
            "    {:<6} gain margin {} at {}, phase margin {} at {}, peak {:.2} at {:.2} Hz{}",
            d.name(),
            show(m.gain_margin_db, "dB"),
            show(m.phase_crossover_hz, "Hz"),
            show(m.phase_margin_deg, "°"),
            show(m.gain_crossover_hz, "Hz"),
            m.peak_gain,
            m.peak_gain_hz,
            if m.stable { "" } else { "  UNSTABLE" }
        );
    }
    let _ = writeln!(
        t,
        "  cross-talk (largest other DOF per command, |response/command|):"
    );
    for d in Dof::ALL {
        let Some(list) = l.cross_talk.get(d.name()) else {
            continue;
        };
        let cells: Vec<String> = list
            .iter()
            .map(|c| match (c.largest_dof, c.largest) {
                (Some(o), Some(x)) => format!(
                    "{:.0} Hz: {:.3} ({o} {:.2e})",
                    c.frequency_hz, c.diagonal, x
                ),
                _ => format!("{:.0} Hz: {:.3}", c.frequency_hz, c.diagonal),
            })
            .collect();
        let _ = writeln!(t, "    {:<6} {}", d.name(), cells.join("; "));
    }
}
