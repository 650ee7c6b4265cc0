//! The figures of a comparison (`platen compare --plot DIR`), in report order: a time history
//! per compared channel (whole record and a zoom), the input force of a forward run, the
//! residuals, the hysteresis loops and the dissipative force against velocity with the
//! model's law.

use plotters::style::RGBColor;

use platen_compare::{ComparedChannel, Comparison, Direction};
use platen_signal::metrics::signed_peak;

use crate::figure::{Dash, Figure, Panel, MODEL, RECORDED, RESIDUAL, SIMULATED};
use crate::series::{
    envelope, every, line, patterned, points, scaled, thinned, MAX_LOOP_POINTS, MAX_SCATTER_POINTS,
};
use crate::text::{display_units, significant};

/// Horizontal pixels of a full-width panel, the number of envelope buckets.
const BUCKETS: usize = 1100;

/// The figures of a comparison, in report order.
pub fn figures(c: &Comparison) -> Vec<Figure> {
    let ctx = Context::new(c);
    let mut out: Vec<Figure> = c.channels.iter().map(|ch| time_history(&ctx, ch)).collect();
    if let Some(recorded_n) = &c.recorded_input_force_n {
        out.push(input_force(&ctx, recorded_n));
    }
    out.push(residuals(&ctx));
    out.push(hysteresis(c));
    out.push(dissipative_force(c));
    out
}

/// What the time-history figures share: the compared span, the zoomed interval and how it
/// was chosen, the record's name.
struct Context<'a> {
    c: &'a Comparison,
    span: (f64, f64),
    zoom: (f64, f64),
    zoom_note: &'static str,
    rec_name: String,
}

impl<'a> Context<'a> {
    fn new(c: &'a Comparison) -> Self {
        let (zoom, zoom_note) = match c.window {
            Some(w) => ((w.start_s, w.end_s), "the --window"),
            None => (auto_zoom(c), "around the largest residual"),
        };
        Self {
            c,
            span: c.compared_span_s(),
            zoom,
            zoom_note,
            rec_name: c.recorded_name(),
        }
    }

    /// Two time-history panels: the whole record with the zoomed interval shaded, and the
    /// zoom; `series` are (label, values, colour, width, pattern).
    fn whole_and_zoom(
        &self,
        y_label: String,
        series: [(&str, &[f64], RGBColor, u32, Dash); 2],
        note: &str,
    ) -> Vec<Panel> {
        let (z0, z1) = self.zoom;
        let panel = |title: String, range: (f64, f64), shade: Option<(f64, f64)>| Panel {
            title,
            x_label: "time t (s)".into(),
            y_label: y_label.clone(),
            series: series
                .iter()
                .map(|&(label, y, color, width, dash)| {
                    patterned(
                        label,
                        envelope(&self.c.t_s, y, range, BUCKETS),
                        color,
                        width,
                        dash,
                    )
                })
                .collect(),
            x_range: Some(range),
            shade_x: shade,
            y_range: None,
            x_log: false,
            y_log: false,
            x_categories: Vec::new(),
        };
        vec![
            panel(
                format!("whole record, {:.1}–{:.1} s", self.span.0, self.span.1),
                self.span,
                Some((z0, z1)),
            ),
            panel(format!("zoom {z0:.2}–{z1:.2} s{note}"), (z0, z1), None),
        ]
    }
}

/// Recorded and simulated values of one compared channel.
fn time_history(ctx: &Context<'_>, ch: &ComparedChannel) -> Figure {
    let channel = ch.channel;
    let units = display_units(channel);
    let rec = scaled(&ch.recorded, units.scale);
    let sim = scaled(&ch.simulated, units.scale);
    let zoom_note = ctx.zoom_note;
    Figure {
        name: format!("time-history-{}", channel.name()),
        title: format!(
            "Recorded and simulated {} ({})",
            channel.quantity(),
            channel.symbol()
        ),
        caption: format!(
            "{} of {} (solid blue, drawn wider) and of the simulation (dashed orange, on \
             top): whole record, and the shaded interval zoomed below ({zoom_note}).",
            capitalised(channel.quantity()),
            ctx.rec_name
        ),
        panels: ctx.whole_and_zoom(
            format!(
                "{} {} ({})",
                channel.quantity(),
                channel.symbol(),
                units.unit
            ),
            [
                ("recorded", &rec, RECORDED, 4, Dash::Solid),
                ("simulated", &sim, SIMULATED, 2, Dash::Dashed),
            ],
            &format!(" ({zoom_note})"),
        ),
        columns: 1,
        rows: Vec::new(),
        size: (1200, 900),
    }
}

/// The recorded force of a forward run against the force that drove the model.
fn input_force(ctx: &Context<'_>, recorded_n: &[f64]) -> Figure {
    let rec = scaled(recorded_n, 1e-3);
    let drv = scaled(&ctx.c.simulated.force_n, 1e-3);
    Figure {
        name: "input-force".into(),
        title: "Actuator force: recorded and as it drives the model".into(),
        caption: format!(
            "The force column of {} as recorded (solid blue) and the scenario's excitation \
             that drove the forward run, after any low-pass the scenario sets (dashed orange).",
            ctx.rec_name
        ),
        panels: ctx.whole_and_zoom(
            "actuator force F_A (kN)".into(),
            [
                ("recorded", &rec, RECORDED, 3, Dash::Solid),
                (
                    "driving the model (scenario excitation)",
                    &drv,
                    SIMULATED,
                    2,
                    Dash::Dashed,
                ),
            ],
            "",
        ),
        columns: 1,
        rows: Vec::new(),
        size: (1200, 900),
    }
}

/// Simulated − recorded of every compared channel, one panel each.
fn residuals(ctx: &Context<'_>) -> Figure {
    let c = ctx.c;
    let panel = |ch: &ComparedChannel| {
        let channel = ch.channel;
        let units = display_units(channel);
        let r = scaled(&ch.residual(), units.residual_scale);
        Panel {
            title: format!(
                "{} residual, RMS {} {}",
                channel.quantity(),
                significant(ch.metrics.rms_error * units.residual_scale, 3),
                units.residual_unit
            ),
            x_label: "time t (s)".into(),
            y_label: format!("{} sim − rec ({})", channel.symbol(), units.residual_unit),
            series: vec![line(
                String::new(),
                envelope(&c.t_s, &r, ctx.span, BUCKETS),
                RESIDUAL,
                2,
            )],
            x_range: Some(ctx.span),
            shade_x: c.window.map(|w| (w.start_s, w.end_s)),
            y_range: None,
            x_log: false,
            y_log: false,
            x_categories: Vec::new(),
        }
    };
    Figure {
        name: "residual".into(),
        title: "Residual: simulated − recorded".into(),
        caption: format!(
            "Simulated minus recorded, on the recorded time base of {}; RMS and NRMSE \
             in the table above.",
            ctx.rec_name
        ),
        panels: c.channels.iter().map(panel).collect(),
        columns: 1,
        rows: Vec::new(),
        // Shorter panels when a specimen adds channels, so that 12 storeys stay drawable.
        size: (
            1200,
            if c.channels.len() > 3 { 300 } else { 420 } * c.channels.len() as u32 + 60,
        ),
    }
}

/// Actuator force against displacement, velocity and acceleration, recorded and simulated.
fn hysteresis(c: &Comparison) -> Figure {
    let f_rec = scaled(&c.recorded.force_n, 1e-3);
    let f_sim = scaled(&c.simulated.force_n, 1e-3);
    let mut loops = Vec::new();
    let mut stride = 1;
    // A forward run's "simulated" force is the one that drove the model (after any
    // low-pass), not an output of it: the caption says so, the legend stays short enough for
    // a third of the figure's width.
    let sim_label = "simulated";
    for (quantity, symbol, unit, rec_x, sim_x) in [
        ("displacement", "u", "m", &c.recorded.u_m, &c.simulated.u_m),
        (
            "velocity",
            "v",
            "m/s",
            &c.recorded.v_m_s,
            &c.simulated.v_m_s,
        ),
        (
            "acceleration",
            "a",
            "m/s²",
            &c.recorded.a_m_s2,
            &c.simulated.a_m_s2,
        ),
    ] {
        let (rec_points, k) = thinned(rec_x, &f_rec, MAX_LOOP_POINTS);
        let (sim_points, _) = thinned(sim_x, &f_sim, MAX_LOOP_POINTS);
        stride = k;
        loops.push(Panel::new(
            format!("Actuator force against {quantity}"),
            format!("{quantity} {symbol} ({unit})"),
            "actuator force F_A (kN)",
            vec![
                line("recorded", rec_points, RECORDED, 3),
                patterned(sim_label, sim_points, SIMULATED, 1, Dash::Dashed),
            ],
        ));
    }
    let thinning = if stride > 1 {
        format!(" ({} drawn)", every(stride))
    } else {
        String::new()
    };
    Figure {
        name: "hysteresis".into(),
        title: "Hysteresis loops: actuator force against the motion".into(),
        caption: format!(
            "Actuator force against displacement, velocity and acceleration (as the paper's Figs \
             4–6 and 11): recorded ({}; solid blue, drawn wider) and simulated ({}; dashed \
             orange, on top){thinning}.",
            c.recorded.sources.loops,
            match c.direction {
                Direction::Forward =>
                    "the force that drove the model against the motion it produced",
                Direction::Inverse => "the model's force against the prescribed motion",
            }
        ),
        panels: loops,
        columns: 3,
        rows: Vec::new(),
        size: (1260, 520),
    }
}

/// The recorded dissipative force against velocity, with the model's law.
fn dissipative_force(c: &Comparison) -> Figure {
    let (recorded, k) = thinned(
        &c.recorded.v_m_s,
        &scaled(&c.recorded_dissipative_n, 1e-3),
        MAX_SCATTER_POINTS,
    );
    let law: Vec<(f64, f64)> = c.law.iter().map(|&(v, f)| (v, f * 1e-3)).collect();
    let recorded_fd = if c.specimen_storeys > 0 {
        "F_A − M·a − F_E − B"
    } else {
        "F_A − M·a − F_E"
    };
    Figure {
        name: "dissipative-force".into(),
        title: "Dissipative force against velocity".into(),
        caption: format!(
            "F_D = {recorded_fd} from the recorded data ({}{}), with the model's law {} \
             (as the paper's Figs 7 and 10).",
            c.recorded.sources.dissipative,
            if k > 1 {
                format!("; {} drawn", every(k))
            } else {
                String::new()
            },
            c.law_label
        ),
        panels: vec![Panel::new(
            "",
            "velocity v (m/s)",
            "dissipative force F_D (kN)",
            vec![
                points(format!("recorded: {recorded_fd}"), recorded, RECORDED, 2),
                line(format!("model law {}", c.law_label), law, MODEL, 3),
            ],
        )],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 800),
    }
}

/// The zoomed interval when no window is given: about 12 cycles of the first channel's
/// recorded mean frequency (from its zero crossings about the mean), at most a fifth of the
/// span and 10 s, at least 20 samples, centred on the largest residual, with a round start
/// and width.
fn auto_zoom(c: &Comparison) -> (f64, f64) {
    let (t_s, ch, dt) = (&c.t_s, &c.channels[0], c.sample_interval_s);
    let (first, last) = (t_s[0], t_s[t_s.len() - 1]);
    let span = last - first;
    let mean = ch.recorded.iter().sum::<f64>() / ch.recorded.len() as f64;
    let crossings = ch
        .recorded
        .windows(2)
        .filter(|w| (w[0] - mean).signum() != (w[1] - mean).signum())
        .count();
    let cycles_width = if crossings >= 2 {
        12.0 * 2.0 * span / crossings as f64
    } else {
        span
    };
    let width = cycles_width
        .min(span / 5.0)
        .min(10.0)
        .max((20.0 * dt).min(span));
    let (i, _) = signed_peak(&ch.residual());
    // A round start: a multiple of the power of ten below a tenth of the width.
    let grid = 10f64.powf((0.1 * width).log10().floor());
    let width = ((width / grid).round() * grid).min(span);
    let start = ((t_s[i] - 0.5 * width) / grid).round() * grid;
    let start = start.clamp(first, last - width);
    (start, start + width)
}

fn capitalised(s: &str) -> String {
    let mut chars = s.chars();
    match chars.next() {
        Some(first) => first.to_uppercase().chain(chars).collect(),
        None => String::new(),
    }
}
