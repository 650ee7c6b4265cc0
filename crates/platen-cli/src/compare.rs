//! `platen compare`: run a scenario and compare it with a recorded test, channel by channel,
//! with the figures and the HTML report an engineer puts in a report.
//!
//! * **Forward** scenarios (a force drives the model) compare the displacement `u_m` and the
//!   velocity `v_m_s` with the recorded file's columns; **inverse** scenarios (a motion drives
//!   the model) compare the actuator force `force_n`. The scenario runs as it is: its own
//!   excitation drives it (for a test, the recorded force or motion, `force_csv` /
//!   `motion_csv`).
//! * The two are aligned on the **recorded time base**: the simulated series is interpolated
//!   linearly onto the recorded samples that lie within the simulated span (exactly, where
//!   the time stamps coincide). The record must be uniformly sampled and cover the scenario's
//!   span, within half a recorded sample interval at each end.
//! * Metrics are those of [`platen_signal::metrics`], over the whole compared span or the
//!   `--window`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde_json::{json, Map, Value};

use platen_integrate::Trajectory;
use platen_io::columns::ColumnMap;
use platen_io::csv::Table;
use platen_model::{force_terms, PlatenModel};
use platen_scenario::sampling::uniform_step_s;
use platen_scenario::{Model, Run, Scenario};
use platen_signal::metrics::{interpolate_linear, ChannelMetrics, Comparator};
use platen_signal::{differentiate, SampleRate};

use crate::plot;
use crate::report;

/// A time window `[t0, t1]`, s, from `--window T0,T1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window(pub [f64; 2]);

/// Parses `--window T0,T1`.
pub fn parse_window(text: &str) -> Result<Window, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [a, b] = parts.as_slice() else {
        return Err(format!(
            "`{text}`: expected two times in seconds, T0,T1 (for example 4,8)"
        ));
    };
    let parse = |s: &str| {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{s}` is not a finite time in seconds"))
    };
    let (t0, t1) = (parse(a)?, parse(b)?);
    if t1 <= t0 {
        return Err(format!(
            "`{text}`: the window must end after it starts (T0 < T1)"
        ));
    }
    Ok(Window([t0, t1]))
}

/// Parses `--max-lag S`.
pub fn parse_max_lag(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("`{text}`: expected a duration in seconds, >= 0")),
    }
}

/// The options of `platen compare`.
pub struct Options<'a> {
    /// Scenario JSON file.
    pub scenario: &'a Path,
    /// Recorded CSV file.
    pub recorded: &'a Path,
    /// Print JSON on stdout.
    pub json: bool,
    /// Folder for the SVG figures.
    pub plot: Option<&'a Path>,
    /// Metrics window.
    pub window: Option<Window>,
    /// HTML report file.
    pub report: Option<&'a Path>,
    /// Lag search bound, s.
    pub max_lag_s: f64,
    /// JSON file mapping the record's own channel names and units to platen's columns.
    pub columns: Option<&'a Path>,
}

/// What a run is compared on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Force → motion: compare u and v.
    Forward,
    /// Motion → force: compare the force.
    Inverse,
}

impl Direction {
    /// `"forward"` or `"inverse"`.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Forward => "forward",
            Direction::Inverse => "inverse",
        }
    }
}

/// A compared channel: its column, names and display units.
#[derive(Debug)]
pub struct ChannelSpec {
    /// CSV column and JSON key.
    pub key: &'static str,
    /// Plain name.
    pub quantity: &'static str,
    /// Symbol.
    pub symbol: &'static str,
    /// SI unit of the column.
    pub unit: &'static str,
    /// Factor from the SI unit to the display unit.
    pub display_scale: f64,
    /// Unit of figures and of the terminal table.
    pub display_unit: &'static str,
    /// Factor from the SI unit to the residual's display unit.
    pub residual_scale: f64,
    /// Unit of the residual figure.
    pub residual_unit: &'static str,
}

const DISPLACEMENT: ChannelSpec = ChannelSpec {
    key: "u_m",
    quantity: "displacement",
    symbol: "u",
    unit: "m",
    display_scale: 1.0,
    display_unit: "m",
    residual_scale: 1e3,
    residual_unit: "mm",
};
const VELOCITY: ChannelSpec = ChannelSpec {
    key: "v_m_s",
    quantity: "velocity",
    symbol: "v",
    unit: "m/s",
    display_scale: 1.0,
    display_unit: "m/s",
    residual_scale: 1e3,
    residual_unit: "mm/s",
};
const FORCE: ChannelSpec = ChannelSpec {
    key: "force_n",
    quantity: "actuator force",
    symbol: "F_A",
    unit: "N",
    display_scale: 1e-3,
    display_unit: "kN",
    residual_scale: 1e-3,
    residual_unit: "kN",
};

/// One compared channel on the recorded time base.
#[derive(Debug)]
pub struct Channel {
    /// Which channel.
    pub spec: &'static ChannelSpec,
    /// Recorded values.
    pub recorded: Vec<f64>,
    /// Simulated values interpolated onto the recorded times.
    pub simulated: Vec<f64>,
    /// The metrics.
    pub metrics: ChannelMetrics,
}

/// Motion and force on the recorded time base.
#[derive(Debug, Default)]
pub struct Quantities {
    /// Displacement, m.
    pub u_m: Vec<f64>,
    /// Velocity, m/s.
    pub v_m_s: Vec<f64>,
    /// Acceleration, m/s².
    pub a_m_s2: Vec<f64>,
    /// Actuator force, N.
    pub force_n: Vec<f64>,
    /// Where the figures' recorded data come from, for captions.
    pub sources: Sources,
}

/// Where the recorded data of the figures come from (file columns or substitutes).
#[derive(Debug, Default)]
pub struct Sources {
    /// For the hysteresis loops.
    pub loops: String,
    /// For the dissipative force.
    pub dissipative: String,
    /// Every substitution made, one sentence each.
    pub notes: Vec<String>,
}

/// The recorded force of a forward run, shown against the driving force.
#[derive(Debug)]
pub struct InputForce {
    /// Recorded force, N.
    pub recorded_n: Vec<f64>,
}

/// A scenario run compared with a record.
#[derive(Debug)]
pub struct Comparison {
    /// Scenario file.
    pub scenario_path: PathBuf,
    /// Recorded file.
    pub recorded_path: PathBuf,
    /// Scenario name.
    pub name: String,
    /// Forward or inverse.
    pub direction: Direction,
    /// `"identified"` or `"full"`.
    pub model_form: &'static str,
    /// Recorded sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Recorded times compared (within the simulated span), s.
    pub t_s: Vec<f64>,
    /// The simulated span, s.
    pub simulated_span_s: (f64, f64),
    /// The record's span, s.
    pub recorded_span_s: (f64, f64),
    /// The metrics window, if any, s.
    pub window_s: Option<[f64; 2]>,
    /// The lag search bound, s.
    pub max_lag_s: f64,
    /// The interval of the zoomed panels, s.
    pub zoom_s: (f64, f64),
    /// The compared channels.
    pub channels: Vec<Channel>,
    /// Recorded data (with substitutes where the file lacks a column).
    pub recorded: Quantities,
    /// Simulated data interpolated onto the recorded times.
    pub simulated: Quantities,
    /// The recorded force of a forward run (when the file has one).
    pub input_force: Option<InputForce>,
    /// `F_A − F_I − F_E` from the recorded data, N.
    pub recorded_dissipative_n: Vec<f64>,
    /// The model's dissipative law `(v, F_D)`, m/s and N.
    pub law: Vec<(f64, f64)>,
    /// How the law is labelled.
    pub law_label: String,
}

impl Comparison {
    /// The recorded file's name, for captions.
    pub fn recorded_name(&self) -> String {
        self.recorded_path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| self.recorded_path.display().to_string())
    }
}

/// Runs `platen compare`.
pub fn run(options: &Options<'_>) -> Result<()> {
    let comparison = compare(options)?;
    let written = plot::write_outputs(
        options.plot,
        options.report,
        || plot::figures(&comparison),
        |figures, rendered| report::html(&comparison, figures, rendered),
    )?;
    if options.json {
        let summary = summary_json(&comparison, &written, options.report);
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_summary(&comparison, &written, options.report);
    }
    Ok(())
}

/// Loads, runs, reads the record, aligns and computes the metrics.
pub fn compare(options: &Options<'_>) -> Result<Comparison> {
    let scenario = Scenario::load(options.scenario)?;
    let direction = match &scenario.run {
        Run::Forward { .. } => Direction::Forward,
        Run::Inverse { .. } => Direction::Inverse,
    };
    // Read the record before running, so that a bad record fails fast.
    let (required, optional): (&[&str], &[&str]) = match direction {
        Direction::Forward => (&["t_s", "u_m", "v_m_s"], &["a_m_s2", "force_n"]),
        Direction::Inverse => (&["t_s", "force_n"], &["u_m", "v_m_s", "a_m_s2"]),
    };
    let map = match options.columns {
        Some(path) => ColumnMap::load(path)?,
        None => ColumnMap::default(),
    };
    let mut table = map.read_table(options.recorded, required, optional)?;
    let rec_t = table.take_column("t_s").unwrap_or_default();
    let dt = uniform_step_s(options.recorded, &rec_t)?;

    // The span the run will cover, checked against the record before any work.
    let sim_span = scenario.run.time_span_s();
    let rec_span = (rec_t[0], rec_t[rec_t.len() - 1]);
    let tol = 0.5 * dt;
    if rec_span.0 > sim_span.0 + tol || rec_span.1 < sim_span.1 - tol {
        bail!(
            "`{}` does not cover the scenario's time span: the record runs from {} s to {} s, \
             scenario `{}` from {} s to {} s; expected a record that starts no later than {} s \
             and ends no earlier than {} s (within half its sample interval, {} s)",
            options.recorded.display(),
            rec_span.0,
            rec_span.1,
            options.scenario.display(),
            sim_span.0,
            sim_span.1,
            sim_span.0,
            sim_span.1,
            tol
        );
    }
    // The recorded samples inside the simulated span.
    let first = rec_t.partition_point(|&t| t < sim_span.0 - tol);
    let end = rec_t.partition_point(|&t| t <= sim_span.1 + tol);
    let range = first..end;
    if range.len() < 2 {
        bail!(
            "`{}` has {} sample(s) within the scenario's span {} s to {} s: a comparison needs \
             at least 2",
            options.recorded.display(),
            range.len(),
            sim_span.0,
            sim_span.1
        );
    }
    // The window must lie inside the compared span.
    let compared_span = (rec_t[first], rec_t[end - 1]);
    if let Some(Window([w0, w1])) = options.window {
        if w0 < compared_span.0 - tol || w1 > compared_span.1 + tol {
            bail!(
                "--window {w0},{w1} s is not inside the compared span {} s to {} s (the recorded \
                 samples of `{}` within the scenario's span)",
                compared_span.0,
                compared_span.1,
                options.recorded.display()
            );
        }
    }

    let mut sim = Trajectory::default();
    scenario.run(&mut sim)?;
    if sim.len() < 2 {
        bail!(
            "scenario `{}` produced {} sample(s): a comparison needs at least 2",
            options.scenario.display(),
            sim.len()
        );
    }
    debug_assert_eq!((sim.t_s[0], sim.t_s[sim.len() - 1]), sim_span);
    let t_s = rec_t[range.clone()].to_vec();
    let on_record = |y: &[f64]| -> Result<Vec<f64>> {
        interpolate_linear(&sim.t_s, y, &t_s).context("aligning the simulation on the record")
    };
    let simulated = Quantities {
        u_m: on_record(&sim.u_m)?,
        v_m_s: on_record(&sim.v_m_s)?,
        a_m_s2: on_record(&sim.a_m_s2)?,
        force_n: on_record(&sim.force_n)?,
        sources: Sources::default(),
    };
    let rate = SampleRate::new(1.0 / dt).context("the record's sample rate")?;
    let mut recorded = recorded_quantities(
        &mut table,
        range.clone(),
        direction,
        &simulated,
        rate,
        options.recorded,
    );

    let mut comparator = Comparator::new(rate.hz(), t_s[0], options.max_lag_s)?;
    if let Some(Window([w0, w1])) = options.window {
        comparator = comparator.with_window_s(w0, w1)?;
    }
    let specs: &[&'static ChannelSpec] = match direction {
        Direction::Forward => &[&DISPLACEMENT, &VELOCITY],
        Direction::Inverse => &[&FORCE],
    };
    let mut channels = Vec::new();
    for &spec in specs {
        let (rec, simv) = match spec.key {
            "u_m" => (&recorded.u_m, &simulated.u_m),
            "v_m_s" => (&recorded.v_m_s, &simulated.v_m_s),
            _ => (&recorded.force_n, &simulated.force_n),
        };
        let metrics = comparator
            .compare(rec, simv)
            .with_context(|| format!("comparing {}", spec.key))?;
        channels.push(Channel {
            spec,
            recorded: rec.clone(),
            simulated: simv.clone(),
            metrics,
        });
    }

    let zoom_s = match options.window {
        Some(Window([a, b])) => (a, b),
        None => auto_zoom(&t_s, &channels[0], dt),
    };

    // Dissipative force from the recorded data and the model's law.
    let (recorded_dissipative_n, law, law_label) = match &scenario.model {
        Model::Identified(m) => dissipative(m, &recorded, "(Eq. 22)"),
        Model::Full(m) => dissipative(&**m, &recorded, "at u = 0 (Eq. 4)"),
    };

    let input_force = match (direction, table.column("force_n")) {
        (Direction::Forward, Some(f)) => Some(InputForce {
            recorded_n: f[range.clone()].to_vec(),
        }),
        _ => None,
    };
    if input_force.is_none() && direction == Direction::Forward {
        recorded.sources.notes.push(format!(
            "`{}` has no force_n column: the recorded loops and F_D use the driving force.",
            options.recorded.display()
        ));
    }

    Ok(Comparison {
        scenario_path: options.scenario.to_path_buf(),
        recorded_path: options.recorded.to_path_buf(),
        name: scenario.name.clone(),
        direction,
        model_form: scenario.model.form(),
        sample_rate_hz: rate.hz(),
        t_s,
        simulated_span_s: sim_span,
        recorded_span_s: rec_span,
        window_s: options.window.map(|w| w.0),
        max_lag_s: options.max_lag_s,
        zoom_s,
        channels,
        recorded,
        simulated,
        input_force,
        recorded_dissipative_n,
        law,
        law_label,
    })
}

/// The zoomed interval when no window is given: about 12 cycles of the recorded channel's
/// mean frequency (from its zero crossings about the mean), at most a fifth of the span and
/// 10 s, at least 20 samples, centred on the largest residual, with a round start and width.
fn auto_zoom(t_s: &[f64], ch: &Channel, dt: f64) -> (f64, f64) {
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
    let residual: Vec<f64> = ch
        .simulated
        .iter()
        .zip(&ch.recorded)
        .map(|(a, b)| a - b)
        .collect();
    let (i, _) = platen_signal::metrics::signed_peak(&residual);
    // A round start: a multiple of the power of ten below a tenth of the width.
    let grid = 10f64.powf((0.1 * width).log10().floor());
    let width = ((width / grid).round() * grid).min(span);
    let start = ((t_s[i] - 0.5 * width) / grid).round() * grid;
    let start = start.clamp(first, last - width);
    (start, start + width)
}

/// The recorded quantities on `range`, with substitutes for the columns the file lacks.
fn recorded_quantities(
    table: &mut Table,
    range: std::ops::Range<usize>,
    direction: Direction,
    simulated: &Quantities,
    rate: SampleRate,
    path: &Path,
) -> Quantities {
    let name = path.display();
    let take = |key: &str| table.column(key).map(|c| c[range.clone()].to_vec());
    let mut notes = Vec::new();
    let u = take("u_m");
    let v = take("v_m_s");
    let a = take("a_m_s2");
    let f = take("force_n");
    let (u_m, v_m_s, a_m_s2, force_n, loops, dissipative);
    match direction {
        Direction::Forward => {
            // u and v are required for a forward comparison.
            u_m = u.unwrap_or_default();
            v_m_s = v.unwrap_or_default();
            a_m_s2 = a.unwrap_or_else(|| {
                notes.push(format!(
                    "`{name}` has no a_m_s2 column: the recorded acceleration is the derivative \
                     of its velocity."
                ));
                differentiate(&v_m_s, rate)
            });
            force_n = f.unwrap_or_else(|| simulated.force_n.clone());
            loops = "force, displacement, velocity and acceleration as in the file, unfiltered";
            dissipative = "recorded force, motion and acceleration, unfiltered";
        }
        Direction::Inverse => {
            force_n = f.unwrap_or_default();
            let motion_from_file = u.is_some();
            u_m = u.unwrap_or_else(|| simulated.u_m.clone());
            v_m_s = v.unwrap_or_else(|| simulated.v_m_s.clone());
            a_m_s2 = a.unwrap_or_else(|| simulated.a_m_s2.clone());
            if !motion_from_file {
                notes.push(format!(
                    "`{name}` has no u_m column: the recorded loops use the prescribed motion."
                ));
            }
            loops = "recorded force against the recorded motion, unfiltered";
            dissipative = "recorded force and motion, unfiltered";
        }
    }
    Quantities {
        u_m,
        v_m_s,
        a_m_s2,
        force_n,
        sources: Sources {
            loops: loops.into(),
            dissipative: dissipative.into(),
            notes,
        },
    }
}

/// `F_A − F_I − F_E` of the recorded data, and the model's law `sign(v)·D(0, |v|)` over the
/// recorded velocity range (with the jump at v = 0 drawn as the vertical segment ±F_s).
fn dissipative<M: PlatenModel + ?Sized>(
    model: &M,
    rec: &Quantities,
    form: &str,
) -> (Vec<f64>, Vec<(f64, f64)>, String) {
    let fd: Vec<f64> = (0..rec.u_m.len())
        .map(|i| {
            let terms = force_terms(model, rec.u_m[i], rec.v_m_s[i], rec.a_m_s2[i]);
            rec.force_n[i] - terms.inertial_n - terms.elastic_n
        })
        .collect();
    let (lo, hi) = rec
        .v_m_s
        .iter()
        .fold((0.0f64, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let steps = 400;
    let mut law = Vec::with_capacity(2 * steps + 2);
    for j in 0..=steps {
        let v = lo * (1.0 - j as f64 / steps as f64);
        law.push((v, -model.dissipative_magnitude_n(0.0, -v)));
    }
    for j in 0..=steps {
        let v = hi * j as f64 / steps as f64;
        law.push((v, model.dissipative_magnitude_n(0.0, v)));
    }
    (fd, law, format!("F_D(v) {form}"))
}

/// `x` with `digits` significant digits, in plain notation between 1e-3 and 1e6.
pub fn significant(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i64;
    if (-3..6).contains(&magnitude) {
        let decimals = (digits as i64 - 1 - magnitude).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.prec$e}", prec = digits.saturating_sub(1))
    }
}

fn channel_json(spec: &ChannelSpec, m: &ChannelMetrics) -> Value {
    json!({
        "unit": spec.unit,
        "samples": m.samples,
        "span_s": m.span_s,
        "rms_recorded": m.rms_recorded,
        "rms_error": m.rms_error,
        "nrmse": m.nrmse,
        "peak_recorded": m.peak_recorded.value,
        "peak_recorded_t_s": m.peak_recorded.t_s,
        "peak_simulated": m.peak_simulated.value,
        "peak_simulated_t_s": m.peak_simulated.t_s,
        "peak_ratio": m.peak_ratio,
        "correlation": m.correlation,
        "lag_s": m.lag.map(|l| l.lag_s),
        "lag_peak_correlation": m.lag.map(|l| l.peak_correlation),
        "lag_at_search_limit": m.lag.map(|l| l.at_search_limit),
    })
}

/// The `--json` summary (also embedded in the report).
pub fn summary_json(c: &Comparison, figures: &[PathBuf], report: Option<&Path>) -> Value {
    let mut m = Map::new();
    m.insert(
        "scenario".into(),
        json!(c.scenario_path.display().to_string()),
    );
    m.insert("name".into(), json!(c.name));
    m.insert(
        "recorded".into(),
        json!(c.recorded_path.display().to_string()),
    );
    m.insert("direction".into(), json!(c.direction.name()));
    m.insert("model_form".into(), json!(c.model_form));
    m.insert("samples".into(), json!(c.t_s.len()));
    m.insert("sample_rate_hz".into(), json!(c.sample_rate_hz));
    m.insert("span_s".into(), json!([c.t_s[0], c.t_s[c.t_s.len() - 1]]));
    m.insert("window_s".into(), json!(c.window_s));
    m.insert("max_lag_s".into(), json!(c.max_lag_s));
    m.insert(
        "channels".into(),
        json!(c.channels.iter().map(|ch| ch.spec.key).collect::<Vec<_>>()),
    );
    for ch in &c.channels {
        m.insert(ch.spec.key.into(), channel_json(ch.spec, &ch.metrics));
    }
    m.insert("notes".into(), json!(c.recorded.sources.notes));
    m.insert(
        "figures".into(),
        json!(figures
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()),
    );
    m.insert(
        "report".into(),
        json!(report.map(|p| p.display().to_string())),
    );
    Value::Object(m)
}

/// The metrics of a channel as display strings: RMS error, NRMSE, peaks, ratio, correlation,
/// lag.
pub fn display_row(ch: &Channel) -> [String; 7] {
    let m = &ch.metrics;
    let s = ch.spec;
    let unit = s.display_unit;
    let value = |x: f64| significant(x * s.display_scale, 4);
    let opt = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or_else(|| "–".into(), f);
    [
        format!("{} {unit}", value(m.rms_error)),
        opt(m.nrmse, &|x| format!("{:.3} %", 100.0 * x)),
        format!(
            "{} {unit} at {:.3} s",
            signed(value(m.peak_recorded.value)),
            m.peak_recorded.t_s
        ),
        format!(
            "{} {unit} at {:.3} s",
            signed(value(m.peak_simulated.value)),
            m.peak_simulated.t_s
        ),
        opt(m.peak_ratio, &|x| format!("{x:.4}")),
        opt(m.correlation, &|x| format!("{x:.5}")),
        m.lag.map_or_else(
            || "–".into(),
            |l| {
                format!(
                    "{:+.2} ms{}",
                    1e3 * l.lag_s,
                    if l.at_search_limit {
                        " (at the search limit)"
                    } else {
                        ""
                    }
                )
            },
        ),
    ]
}

/// `text` with an explicit sign.
fn signed(text: String) -> String {
    if text.starts_with('-') {
        text.replacen('-', "−", 1)
    } else {
        format!("+{text}")
    }
}

/// Column headings of [`display_row`].
pub const DISPLAY_HEADINGS: [&str; 7] = [
    "RMS error",
    "NRMSE",
    "peak recorded",
    "peak simulated",
    "peak ratio",
    "correlation",
    "lag",
];

fn print_summary(c: &Comparison, figures: &[PathBuf], report: Option<&Path>) {
    let dir = match c.direction {
        Direction::Forward => "forward (force → motion)",
        Direction::Inverse => "inverse (motion → force)",
    };
    println!("{}: {dir}, {} model", c.name, c.model_form);
    println!(
        "  compared with {}: {} samples at {} Hz over {:.3}–{:.3} s",
        c.recorded_path.display(),
        c.t_s.len(),
        c.sample_rate_hz,
        c.t_s[0],
        c.t_s[c.t_s.len() - 1]
    );
    if let Some([a, b]) = c.window_s {
        println!("  metrics over the window {a}–{b} s");
    }
    for ch in &c.channels {
        let row = display_row(ch);
        println!(
            "  {} ({}, {}):",
            ch.spec.key, ch.spec.quantity, ch.spec.display_unit
        );
        for (heading, value) in DISPLAY_HEADINGS.iter().zip(&row) {
            println!("    {heading:<24}{value}");
        }
    }
    println!(
        "  (error = simulated − recorded; NRMSE = RMS error / recorded RMS; lag > 0: the \
         simulation is late)"
    );
    for note in &c.recorded.sources.notes {
        println!("  note: {note}");
    }
    if !figures.is_empty() {
        println!("  wrote {} figure files (SVG and PNG):", figures.len());
        for f in figures {
            println!("    {}", f.display());
        }
    }
    if let Some(r) = report {
        println!("  wrote report {}", r.display());
    }
}
