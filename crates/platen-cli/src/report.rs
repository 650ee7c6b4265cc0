//! `platen compare --report FILE.html`: one self-contained HTML page with what was compared,
//! the metrics table and every figure inlined as SVG (no external file, script or font), the
//! `--json` summary at the end. The page is a pure function of the comparison, so the same
//! input gives the same bytes.

use std::fmt::Write as _;

use crate::compare::{display_row, summary_json, Comparison, Direction, DISPLAY_HEADINGS};
use crate::plot::Figure;

const STYLE: &str = "\
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,Helvetica,Arial,sans-serif;\
max-width:1200px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}\
h1{font-size:1.6em;margin-bottom:.2em}h2{font-size:1.25em;margin-top:1.6em}\
table{border-collapse:collapse;margin:.8em 0;font-variant-numeric:tabular-nums}\
th,td{border:1px solid #ccc;padding:.3em .7em;text-align:right;white-space:nowrap}\
code{font-size:1em}.scroll{overflow-x:auto}\
th:first-child,td:first-child{text-align:left}th{background:#f3f3f3}\
dl{display:grid;grid-template-columns:max-content auto;gap:.2em 1em}dt{font-weight:600}\
dd{margin:0}figure{margin:1.5em 0}figure svg{width:100%;height:auto;border:1px solid #eee}\
figcaption{font-size:.95em;color:#444;margin-top:.3em}\
pre{background:#f7f7f7;padding:.8em;overflow-x:auto;font-size:.85em}\
.note{color:#8a4b00}";

/// Escapes text for HTML element content and attribute values.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// The report page; `rendered[i]` is the SVG of `figures[i]`.
pub fn html(c: &Comparison, figures: &[Figure], rendered: &[(String, String)]) -> String {
    let mut h = String::new();
    let title = format!("platen compare: {}", c.name);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
        escape(&title),
        escape(&c.name)
    );
    let direction = match c.direction {
        Direction::Forward => {
            "forward: the force drives the model; displacement and velocity compared"
        }
        Direction::Inverse => "inverse: the motion drives the model; actuator force compared",
    };
    let _ = writeln!(h, "<dl>");
    let mut item = |term: &str, value: String| {
        let _ = writeln!(h, "<dt>{}</dt><dd>{}</dd>", escape(term), escape(&value));
    };
    item("scenario", c.scenario_path.display().to_string());
    item("recorded", c.recorded_path.display().to_string());
    item("run", direction.to_string());
    item("model", format!("{} form", c.model_form));
    item(
        "compared",
        format!(
            "{} recorded samples at {} Hz, {:.3}–{:.3} s (simulated {:.3}–{:.3} s, record {:.3}–{:.3} s)",
            c.t_s.len(),
            c.sample_rate_hz,
            c.t_s[0],
            c.t_s[c.t_s.len() - 1],
            c.simulated_span_s.0,
            c.simulated_span_s.1,
            c.recorded_span_s.0,
            c.recorded_span_s.1
        ),
    );
    item(
        "metrics window",
        match c.window_s {
            Some([a, b]) => format!("{a}–{b} s"),
            None => "the whole compared span".into(),
        },
    );
    item("lag search", format!("±{} s", c.max_lag_s));
    let _ = writeln!(h, "</dl>");

    let _ = writeln!(
        h,
        "<h2>Metrics</h2>\n<div class=\"scroll\">\n<table>\n<tr><th>channel</th>"
    );
    for heading in DISPLAY_HEADINGS {
        let _ = write!(h, "<th>{}</th>", escape(heading));
    }
    let _ = writeln!(h, "</tr>");
    for ch in &c.channels {
        let _ = write!(
            h,
            "<tr><td><code>{}</code> ({})</td>",
            escape(ch.spec.key),
            escape(ch.spec.quantity)
        );
        for cell in display_row(ch) {
            let _ = write!(h, "<td>{}</td>", escape(&cell));
        }
        let _ = writeln!(h, "</tr>");
    }
    let _ = writeln!(
        h,
        "</table>\n</div>\n<p>Error = simulated − recorded on the recorded time base; NRMSE = RMS error / \
         RMS of the recorded channel; peak ratio = |peak simulated| / |peak recorded|; correlation \
         is Pearson's at zero lag; a positive lag means the simulation is late.</p>"
    );
    for note in &c.recorded.sources.notes {
        let _ = writeln!(h, "<p class=\"note\">{}</p>", escape(note));
    }

    let _ = writeln!(h, "<h2>Figures</h2>");
    for (figure, (file, svg)) in figures.iter().zip(rendered) {
        let _ = writeln!(
            h,
            "<figure id=\"{}\">\n{}\n<figcaption><b>{}</b> ({}). {}</figcaption>\n</figure>",
            escape(&figure.name),
            svg.trim(),
            escape(&figure.title),
            escape(file),
            escape(&figure.caption)
        );
    }

    let mut summary = summary_json(c, &[], None);
    if let Some(fields) = summary.as_object_mut() {
        // What this run wrote is not part of the comparison.
        fields.remove("figures");
        fields.remove("report");
    }
    let _ = writeln!(
        h,
        "<h2>Summary (JSON)</h2>\n<pre>{}</pre>\n<p>Written by platen {}.</p>\n</body>\n</html>",
        escape(&serde_json::to_string_pretty(&summary).unwrap_or_default()),
        env!("CARGO_PKG_VERSION")
    );
    h
}
