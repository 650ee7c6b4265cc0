//! Self-contained HTML reports (`platen compare --report FILE.html`, `platen identify
//! --report FILE.html`): one page with what was run, the tables, every figure inlined as SVG
//! (no external file, script or font) and the `--json` summary at the end; and the pieces
//! (tables, paragraphs, headings) a verb builds its sections from. A page is a pure function
//! of its inputs, so the same input gives the same bytes.

use std::fmt::Write as _;

use serde_json::Value;

use platen_compare::{Comparison, Direction};

use crate::figure::Figure;
use crate::text::{display_row, recorded_limit_row, DISPLAY_HEADINGS, RECORDED_LIMIT_HEADINGS};

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

/// What a report page holds, top to bottom.
pub struct Page<'a> {
    /// Document title (browser tab).
    pub title: String,
    /// Heading at the top.
    pub heading: String,
    /// What was run: (term, value) pairs.
    pub items: Vec<(String, String)>,
    /// Sections of ready-made HTML (tables, notes), in order.
    pub sections: Vec<String>,
    /// The figures and their SVG (`rendered[i]` is the SVG of `figures[i]`).
    pub figures: &'a [Figure],
    /// `(file name, svg)` of each figure.
    pub rendered: &'a [(String, String)],
    /// The machine-readable summary shown at the end.
    pub summary: Value,
}

/// The page as one HTML document.
pub fn page(p: &Page<'_>) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
        escape(&p.title),
        escape(&p.heading)
    );
    let _ = writeln!(h, "<dl>");
    for (term, value) in &p.items {
        let _ = writeln!(h, "<dt>{}</dt><dd>{}</dd>", escape(term), escape(value));
    }
    let _ = writeln!(h, "</dl>");
    for section in &p.sections {
        h.push_str(section);
    }
    if !p.figures.is_empty() {
        let _ = writeln!(h, "<h2>Figures</h2>");
    }
    for (figure, (file, svg)) in p.figures.iter().zip(p.rendered) {
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
    let _ = writeln!(
        h,
        "<h2>Summary (JSON)</h2>\n<pre>{}</pre>\n<p>Written by platen {}.</p>\n</body>\n</html>",
        escape(&serde_json::to_string_pretty(&p.summary).unwrap_or_default()),
        env!("CARGO_PKG_VERSION")
    );
    h
}

/// An HTML table: a heading row and body rows, every cell escaped; `code_first` sets the
/// first word of the first column in `<code>` (a key, then its description).
pub fn table(headings: &[&str], rows: &[Vec<String>], code_first: bool) -> String {
    let mut h = String::from("<div class=\"scroll\">\n<table>\n<tr>");
    for heading in headings {
        let _ = write!(h, "<th>{}</th>", escape(heading));
    }
    let _ = writeln!(h, "</tr>");
    for row in rows {
        h.push_str("<tr>");
        for (i, cell) in row.iter().enumerate() {
            if i == 0 && code_first {
                let (key, rest) = cell.split_once(' ').unwrap_or((cell, ""));
                let rest = if rest.is_empty() {
                    String::new()
                } else {
                    format!(" {}", escape(rest))
                };
                let _ = write!(h, "<td><code>{}</code>{rest}</td>", escape(key));
            } else {
                let _ = write!(h, "<td>{}</td>", escape(cell));
            }
        }
        let _ = writeln!(h, "</tr>");
    }
    h.push_str("</table>\n</div>\n");
    h
}

/// A paragraph of escaped text, with an optional class.
pub fn paragraph(text: &str, class: Option<&str>) -> String {
    match class {
        Some(c) => format!("<p class=\"{}\">{}</p>\n", escape(c), escape(text)),
        None => format!("<p>{}</p>\n", escape(text)),
    }
}

/// A section heading.
pub fn heading(text: &str) -> String {
    format!("<h2>{}</h2>\n", escape(text))
}

/// Preformatted text.
pub fn preformatted(text: &str) -> String {
    format!("<pre>{}</pre>\n", escape(text))
}

/// The `platen compare` report page; `rendered[i]` is the SVG of `figures[i]`.
pub fn compare_page(c: &Comparison, figures: &[Figure], rendered: &[(String, String)]) -> String {
    let mut summary = serde_json::to_value(c.summary(&[], None)).unwrap_or_default();
    if let Some(fields) = summary.as_object_mut() {
        // What this run wrote is not part of the comparison.
        fields.remove("figures");
        fields.remove("report");
    }
    page(&Page {
        title: format!("platen compare: {}", c.name),
        heading: c.name.clone(),
        items: compare_items(c),
        sections: vec![metrics_section(c), recorded_limits_section(c)],
        figures,
        rendered,
        summary,
    })
}

/// What was compared: files, direction, model, samples, window, lag search.
fn compare_items(c: &Comparison) -> Vec<(String, String)> {
    let direction = match c.direction {
        Direction::Forward => {
            "forward: the force drives the model; displacement and velocity compared"
        }
        Direction::Inverse => "inverse: the motion drives the model; actuator force compared",
    };
    let (first, last) = c.compared_span_s();
    vec![
        ("scenario".into(), c.scenario_path.display().to_string()),
        ("recorded".into(), c.recorded_path.display().to_string()),
        ("run".into(), direction.to_string()),
        ("model".into(), format!("{} form", c.model_form)),
        (
            "compared".into(),
            format!(
                "{} recorded samples at {} Hz, {first:.3}–{last:.3} s (simulated {:.3}–{:.3} s, record {:.3}–{:.3} s)",
                c.t_s.len(),
                crate::text::rounded(c.sample_rate_hz, 9),
                c.simulated_span_s.0,
                c.simulated_span_s.1,
                c.recorded_span_s.0,
                c.recorded_span_s.1
            ),
        ),
        (
            "metrics window".into(),
            match c.window {
                Some(w) => format!("{}–{} s", w.start_s, w.end_s),
                None => "the whole compared span".into(),
            },
        ),
        ("lag search".into(), format!("±{} s", c.max_lag_s)),
    ]
}

/// The recording itself against the table's limits, and a warning per limit it exceeds
/// (empty for a recording with none of the limited columns).
fn recorded_limits_section(c: &Comparison) -> String {
    if c.recorded_limits.is_empty() {
        return String::new();
    }
    let mut headings = vec!["recorded column"];
    headings.extend(RECORDED_LIMIT_HEADINGS);
    let rows: Vec<Vec<String>> = c
        .recorded_limits
        .iter()
        .map(|check| {
            let mut row = vec![format!("{} (against {})", check.column, check.kind.key())];
            row.extend(recorded_limit_row(check));
            row
        })
        .collect();
    let mut h = heading("The recording against the table's limits");
    h.push_str(&table(&headings, &rows, true));
    h.push_str(&paragraph(
        "Each limit (the scenario's preset's, with its `limits` laid over) against the \
         recording's own column over the whole record; a column the file lacks is not checked. \
         Time beyond = recorded samples beyond the limit × the sample interval.",
        None,
    ));
    for warning in c.warnings() {
        h.push_str(&paragraph(&format!("warning: {warning}"), Some("note")));
    }
    h
}

/// The metrics table, how to read it, and the notes on substituted columns.
fn metrics_section(c: &Comparison) -> String {
    let mut headings = vec!["channel"];
    headings.extend(DISPLAY_HEADINGS);
    let rows: Vec<Vec<String>> = c
        .channels
        .iter()
        .map(|ch| {
            let mut row = vec![format!("{} ({})", ch.channel.name(), ch.channel.quantity())];
            row.extend(display_row(ch));
            row
        })
        .collect();
    let mut metrics = heading("Metrics");
    metrics.push_str(&table(&headings, &rows, true));
    metrics.push_str(&paragraph(
        "Error = simulated − recorded on the recorded time base; NRMSE = RMS error / RMS of the \
         recorded channel; peak ratio = |peak simulated| / |peak recorded|; correlation is \
         Pearson's at zero lag; a positive lag means the simulation is late.",
        None,
    ));
    for note in &c.recorded.sources.notes {
        metrics.push_str(&paragraph(note, Some("note")));
    }
    metrics
}
