//! The text summaries of a test plan (`platen plan`): the target, feasibility and the limits'
//! margins, the largest scale that fits, the drive iterations and the drive; of a uniaxial
//! plan ([`text`]) and of a multi-axis one ([`table_text`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use platen_model::STANDARD_GRAVITY_M_S2;
use platen_plan::six_dof::{TablePlanSummary, AXES};
use platen_plan::{PlanSummary, TableLimitUse};

use crate::text::{engineering_unit, rounded, significant};

/// The unit of a limit, from its name.
fn unit(limit: &str) -> &'static str {
    match limit.rsplit('_').next() {
        Some("m") => "m",
        Some("s") if limit.ends_with("_m_s") => "m/s",
        Some("s2") => "m/s²",
        Some("n") => "N",
        Some("pa") => "Pa",
        Some("s") => "m³/s",
        _ => "",
    }
}

/// The text summary of the plan `s`, then the figure files `figures` written to `plot_dir`
/// and the HTML `report` written, if any.
pub fn text(
    s: &PlanSummary,
    figures: &[PathBuf],
    plot_dir: Option<&Path>,
    report: Option<&Path>,
) -> String {
    let mut o = String::new();
    summary_lines(&mut o, s);
    if !figures.is_empty() {
        let _ = writeln!(
            o,
            "  figures: {} files (SVG and PNG) in {}",
            figures.len(),
            plot_dir.map_or(String::new(), |d| d.display().to_string())
        );
    }
    if let Some(report) = report {
        let _ = writeln!(o, "  report: {}", report.display());
    }
    o
}

/// The target, the margins, the scale and the feasibility.
fn summary_lines(o: &mut String, s: &PlanSummary) {
    let t = &s.target;
    let _ = writeln!(o, "{}: plan of `{}` on `{}`", s.name, t.file, s.scenario);
    let _ = writeln!(
        o,
        "  target: {}, {} samples at {} Hz over {:.3} s (drive at {} Hz); peak {:.4} m/s² \
         ({:.3} g), command peak {:.4} m",
        t.kind,
        t.samples,
        rounded(t.sample_rate_hz, 9),
        t.duration_s,
        rounded(t.drive_sample_rate_hz, 9),
        t.peak_a_m_s2,
        t.peak_a_m_s2 / STANDARD_GRAVITY_M_S2,
        t.peak_u_m
    );
    if let Some(d) = t.baseline_degree {
        let _ = writeln!(
            o,
            "  baseline: end-matching polynomial of degree {d}; it removed {} m/s² RMS \
             ({:.2} % of the target's), {} m/s² at most",
            significant(t.baseline_correction_rms_m_s2, 4),
            100.0 * t.baseline_correction_rms_m_s2 / t.rms_a_m_s2.max(f64::MIN_POSITIVE),
            significant(t.baseline_correction_peak_m_s2, 4)
        );
    }
    let feasible = if s.feasible {
        "yes".to_owned()
    } else {
        let names: Vec<String> = s
            .limiting
            .iter()
            .map(|l| format!("{} ({:.3}× at {:.3} s)", l.limit, l.ratio, l.t_s))
            .collect();
        format!("NO: {}", names.join(", "))
    };
    let _ = writeln!(o, "  feasible: {feasible}");
    let _ = writeln!(
        o,
        "    {:<20} {:>12} {:>12} {:<5} {:>7} {:>10}",
        "limit", "peak", "allowed", "", "use", "at"
    );
    for l in &s.margins {
        // Peak and allowed in one engineering format, the allowed value's unit (0.6593
        // against 6.800 MN, not 659293 against 6.800e6 N).
        let (factor, unit) = engineering_unit(unit(l.limit), l.allowed);
        let _ = writeln!(
            o,
            "    {:<20} {:>12} {:>12} {:<5} {:>6.1}% {:>8.3} s",
            l.limit,
            significant(factor * l.peak, 4),
            significant(factor * l.allowed, 4),
            unit,
            100.0 * l.ratio,
            l.t_s
        );
    }
    if let Some(m) = &s.max_scale_search {
        if m.at_upper_bound {
            let _ = writeln!(
                o,
                "  largest scale that fits: at least {} (the search's bound)",
                m.scale
            );
        } else {
            let _ = writeln!(
                o,
                "  largest scale that fits: {:.4} (bracket {:.4}–{:.4}; beyond it: {}; {} runs)",
                m.scale,
                m.bracket[0],
                m.bracket[1],
                m.limiting.join(", "),
                m.runs
            );
        }
    }
    iteration_lines(o, s);
}

/// The iterations, the stop and the drive.
fn iteration_lines(o: &mut String, s: &PlanSummary) {
    if let Some(f) = &s.frf {
        let _ = writeln!(
            o,
            "  iterations (gain {}, Ĥ {}, band {}–{} Hz):",
            f.gain, f.source, f.band_hz[0], f.band_hz[1]
        );
        let _ = writeln!(
            o,
            "    {:>3} {:>12} {:>12} {:>22}",
            "k", "accel NRMSE", "disp NRMSE", "spectrum error (5 %)"
        );
        for r in &s.iterations {
            let _ = writeln!(
                o,
                "    {:>3} {:>11.2}% {:>11.2}% {:>11.2}% at {:.3} s",
                r.iteration,
                100.0 * r.acceleration_nrmse,
                100.0 * r.displacement_nrmse,
                100.0 * r.spectrum_error,
                r.spectrum_error_period_s
            );
        }
    }
    let _ = writeln!(
        o,
        "  stop: {}{}",
        s.stop,
        s.stall_reason
            .as_ref()
            .map_or(String::new(), |r| format!(" ({r})"))
    );
    let _ = match &s.drive {
        Some(d) => writeln!(
            o,
            "  drive: iteration {} ({:.2} % acceleration NRMSE), {} samples, peak {:.4} m, \
             written to {}",
            d.achieved.iteration,
            100.0 * d.achieved.acceleration_nrmse,
            d.samples,
            d.peak_u_m,
            d.out.as_deref().unwrap_or("(nothing)")
        ),
        None => writeln!(o, "  drive: none (nothing written)"),
    };
    if let (Some(d), Some(level)) = (&s.drive, s.iterate_at) {
        if let Some(low) = &d.at_iteration_level {
            let _ = writeln!(
                o,
                "  iterated at {:.0} % of the target ({:.2} % acceleration NRMSE there), scaled \
                 up by {:.4}: predicted full-level error {:.2} % acceleration NRMSE, {:.2} % \
                 displacement NRMSE, {:.2} % spectrum error",
                100.0 * level,
                100.0 * low.acceleration_nrmse,
                1.0 / level,
                100.0 * d.achieved.acceleration_nrmse,
                100.0 * d.achieved.displacement_nrmse,
                100.0 * d.achieved.spectrum_error
            );
        }
    }
    if let Some(d) = &s.drive {
        let _ = writeln!(o, "  {}", d.spectrum_acceptance.line("response spectrum"));
    }
}

/// The text summary of the multi-axis plan `s` (`platen plan` without `--json` on a
/// scenario with a `table`).
pub fn table_text(s: &TablePlanSummary) -> String {
    let mut t = String::new();
    table_target_lines(&mut t, s);
    table_feasibility_lines(&mut t, s);
    table_iteration_lines(&mut t, s);
    t
}

/// The target, per axis.
fn table_target_lines(t: &mut String, s: &TablePlanSummary) {
    let _ = writeln!(
        t,
        "{}: three-component plan of `{}` ({} samples at {} Hz, drive at {} Hz, {:.3} s)",
        s.name,
        s.target.file,
        s.target.samples,
        s.target.sample_rate_hz,
        s.target.drive_sample_rate_hz,
        s.target.duration_s
    );
    for axis in AXES {
        match s.target.axes.get(axis) {
            Some(a) => {
                let _ = writeln!(
                    t,
                    "  {axis}: {} target, peak {:.4} m/s², command peak {:.4} m",
                    a.kind, a.peak_a_m_s2, a.peak_u_m
                );
            }
            None => {
                let _ = writeln!(t, "  {axis}: held at zero");
            }
        }
    }
}

/// The feasibility: what binds first, what fails, the closest limits, the largest scales.
fn table_feasibility_lines(t: &mut String, s: &TablePlanSummary) {
    let _ = writeln!(t, "feasible: {}", if s.feasible { "yes" } else { "no" });
    if let Some(b) = &s.binds_first {
        let _ = writeln!(
            t,
            "  binds first: {} at {:.3} s (peak {:.4e} against {:.4e}, {:.3} times at {:.3} s)",
            b.limit,
            b.first_exceeded_s.unwrap_or(b.t_s),
            b.peak,
            b.allowed,
            b.ratio,
            b.t_s
        );
    }
    for u in &s.limiting {
        let _ = writeln!(
            t,
            "  exceeded: {:<28} {:.3} times its limit ({:.4e} against {:.4e}) at {:.3} s",
            u.limit, u.ratio, u.peak, u.allowed, u.t_s
        );
    }
    let mut closest: Vec<&TableLimitUse> = s.margins.iter().collect();
    closest.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    let _ = writeln!(t, "  closest limits:");
    for u in closest.iter().take(5) {
        let _ = writeln!(
            t,
            "    {:<28} {:>6.1} % ({:.4e} against {:.4e}) at {:.3} s",
            u.limit,
            100.0 * u.ratio,
            u.peak,
            u.allowed,
            u.t_s
        );
    }
    if let Some(m) = s.max_scale {
        let _ = writeln!(t, "largest common scale that fits: {m:.4}");
    }
    for (axis, m) in &s.per_axis_max_scale {
        let _ = writeln!(t, "  largest scale of {axis} alone: {m:.4}");
    }
}

/// The drive iteration, per iteration and axis, its stop, and the drives (or why there are
/// none).
fn table_iteration_lines(t: &mut String, s: &TablePlanSummary) {
    let (Some(frf), Some(drive), Some(best)) = (&s.frf, &s.drive, s.best_iteration) else {
        let _ = writeln!(
            t,
            "drive iteration: not run (the target's own commands reach the end of an \
             actuator's stroke); no drives written"
        );
        return;
    };
    let _ = writeln!(
        t,
        "drive iteration (matrix Ĥ, linearised; band {}–{} Hz, gain {}, largest condition number {:.1}):",
        frf.band_hz[0], frf.band_hz[1], frf.gain, frf.max_condition
    );
    let _ = writeln!(
        t,
        "  iter  overall   x nrmse   y nrmse   z nrmse   (held axes: rms error, m/s²)"
    );
    for r in &s.iterations {
        let cell = |axis: &str| {
            let a = &r.axes[axis];
            a.acceleration_nrmse.map_or_else(
                || format!("({:.3})", a.rms_acceleration_error_m_s2),
                |e| format!("{:.2} %", 100.0 * e),
            )
        };
        let _ = writeln!(
            t,
            "  {:>4}  {:>6.2} %  {:>8}  {:>8}  {:>8}",
            r.iteration,
            100.0 * r.acceleration_nrmse,
            cell("x"),
            cell("y"),
            cell("z")
        );
    }
    let _ = writeln!(
        t,
        "  stop: {}{}; best iteration {}",
        s.stop,
        s.stall_reason
            .as_ref()
            .map_or(String::new(), |r| format!(" ({r})")),
        best
    );
    if let (Some(level), Some(low)) = (s.iterate_at, &drive.at_iteration_level) {
        let _ = writeln!(
            t,
            "  iterated at {:.0} % of the target ({:.2} % overall acceleration NRMSE there), \
             scaled up by {:.4}: predicted full-level error {:.2} % overall acceleration NRMSE",
            100.0 * level,
            100.0 * low.acceleration_nrmse,
            1.0 / level,
            100.0 * drive.achieved.acceleration_nrmse
        );
    }
    for (axis, a) in &drive.spectrum_acceptance {
        let _ = writeln!(t, "  {}", a.line(&format!("{axis} response spectrum")));
    }
    if let Some(out) = &drive.out {
        let _ = writeln!(
            t,
            "wrote {out} (t_s, x_m … yaw_rad: replay it with a motion_csv)"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::unit;

    /// Every limit's unit follows from the end of its name.
    #[test]
    fn a_limit_s_unit_follows_from_its_name() {
        assert_eq!(unit("stroke_m"), "m");
        assert_eq!(unit("velocity_m_s"), "m/s");
        assert_eq!(unit("acceleration_m_s2"), "m/s²");
        assert_eq!(unit("force_n"), "N");
        assert_eq!(unit("supply_pressure_pa"), "Pa");
        assert_eq!(unit("flow_m3_s"), "m³/s");
    }
}
