//! The reports of `platen identify`: the text a terminal shows and the HTML page of
//! `--report`, for the paper's hysteresis-loop method ([`Identification`]), the any-record
//! method ([`RecordIdentification`]) or both ([`Identified`]), with one line per input record
//! saying what identification did with it and why. `identify --system`'s report is
//! [`crate::system_identify_report`].
//!
//! Parameters are shown in a reader's units ([`display_unit`]: t, MN/m, kN), each estimate as
//! `value ± one standard error` with enough decimals to show the standard error's first
//! significant digit ([`plus_minus`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use platen_app::RecordSource;
use platen_ident::anyrecord::summary::{RecordInfoSummary, RecordSummary};
use platen_ident::anyrecord::ChannelDelay;
use platen_ident::{
    Correlations, Estimate, Flag, Identification, IdentificationSummary, Identified, IdentifiedKey,
    OutputErrorFit, Parameter, ParameterEstimates, RecordIdentification, TestKind, TestRecord,
};

use crate::figure::Figure;
use crate::{html, identify_figures, record_figures};

/// An identification with the records it came from, ready to be reported.
#[derive(Clone, Copy)]
pub struct IdentifyReport<'a> {
    /// What [`platen_ident::identify_any`] found.
    pub identified: &'a Identified,
    /// Where each record came from (names and labels), in input order.
    pub sources: &'a [RecordSource],
    /// The records, in input order.
    pub records: &'a [TestRecord],
}

impl IdentifyReport<'_> {
    /// The warnings about records left out: `"{name} was not used: {reason}"`, one per
    /// record not used.
    pub fn unused(&self) -> Vec<String> {
        self.identified
            .accounts
            .iter()
            .zip(self.sources)
            .filter_map(|(a, s)| {
                a.reason
                    .as_ref()
                    .map(|r| format!("{} was not used: {r}", s.name))
            })
            .collect()
    }

    /// The figures: the any-record method's, then the periodic method's.
    pub fn figures(&self) -> Vec<Figure> {
        let mut f = match &self.identified.records {
            Some((rid, _)) => record_figures::figures(rid),
            None => Vec::new(),
        };
        if let Some((p, _)) = &self.identified.periodic {
            f.extend(identify_figures::figures(p));
        }
        f
    }

    /// The text report: the any-record method's (if it ran) and the periodic method's
    /// parameters and tables, then every record's account.
    pub fn text(&self) -> String {
        let all: Vec<&RecordSource> = self.sources.iter().collect();
        let entries = self.entries();
        let mut s = match &self.identified.records {
            Some((rid, idx)) => {
                let mut s = record_report(rid, &self.subset(idx));
                if let Some((p, pidx)) = &self.identified.periodic {
                    s.push_str("\n== Periodic tests (hysteresis-loop method, §3) ==\n\n");
                    s.push_str(&periodic_report(p, &self.subset(pidx)));
                }
                s
            }
            None => match &self.identified.periodic {
                Some((p, _)) => periodic_report(p, &all),
                None => String::new(),
            },
        };
        s.push_str(&accounts_report(&entries, &all));
        s
    }

    /// The HTML page: parameter tables, the text report, the records' accounts, the figures
    /// (`rendered[i]` the SVG of `figures[i]`) and the JSON summary.
    pub fn html(&self, figures: &[Figure], rendered: &[(String, String)]) -> String {
        let all: Vec<&RecordSource> = self.sources.iter().collect();
        let entries = self.entries();
        match (&self.identified.records, &self.identified.periodic) {
            (Some((rid, idx)), periodic) => record_html(
                rid,
                &self.subset(idx),
                periodic.as_ref().map(|(p, pidx)| (p, self.subset(pidx))),
                (&entries, &all),
                figures,
                rendered,
            ),
            (None, Some((p, _))) => periodic_html(p, &all, &entries, figures, rendered),
            (None, None) => String::new(),
        }
    }

    fn entries(&self) -> Vec<RecordInfoSummary> {
        self.identified
            .record_entries(self.records, &platen_app::files(self.sources))
    }

    fn subset(&self, idx: &[usize]) -> Vec<&RecordSource> {
        idx.iter().map(|&k| &self.sources[k]).collect()
    }
}

/// "Records": one line per input file, what identification did with it and why.
fn accounts_report(entries: &[RecordInfoSummary], inputs: &[&RecordSource]) -> String {
    let mut s = String::from("\nRecords (every file accounted for)\n");
    let w = inputs
        .iter()
        .map(|i| i.label.chars().count())
        .max()
        .unwrap_or(0);
    for (e, input) in entries.iter().zip(inputs) {
        let Some(a) = &e.account else { continue };
        let status = match &a.reason {
            None => "used".to_owned(),
            Some(r) => format!("NOT USED: {r}"),
        };
        let delays =
            e.channel_delay_s
                .as_ref()
                .filter(|d| !d.is_empty())
                .map_or(String::new(), |d| {
                    let list: Vec<String> = d
                        .iter()
                        .map(|(c, s)| format!("{c} {:+.2} samples", s * e.sample_rate_hz))
                        .collect();
                    format!("; delay {}", list.join(", "))
                });
        let _ = writeln!(
            s,
            "  {:<w$}  {:<8}  {status}{delays}; {}",
            input.label,
            a.method.name(),
            a.routing
        );
    }
    s
}

/// The HTML table of [`accounts_report`].
fn accounts_table(entries: &[RecordInfoSummary], inputs: &[&RecordSource]) -> Vec<String> {
    let rows: Vec<Vec<String>> = entries
        .iter()
        .zip(inputs)
        .filter_map(|(e, input)| {
            let a = e.account.as_ref()?;
            Some(vec![
                input.label.clone(),
                a.method.name().to_owned(),
                if a.used { "yes" } else { "no" }.to_owned(),
                a.reason.clone().unwrap_or_default(),
                e.channel_delay_s
                    .as_ref()
                    .map(|d| {
                        d.iter()
                            .map(|(c, s)| format!("{c} {:.3} ms", 1e3 * s))
                            .collect::<Vec<_>>()
                            .join(", ")
                    })
                    .unwrap_or_default(),
                a.routing.clone(),
            ])
        })
        .collect();
    vec![
        html::heading("Records"),
        html::table(
            &[
                "file",
                "method",
                "used",
                "reason",
                "channel delay",
                "routing",
            ],
            &rows,
            false,
        ),
    ]
}

/// A record's channel delays for its report line: estimated (± one standard error) or
/// given, in ms and samples, and whether the channel was corrected.
fn delay_text(delays: &[ChannelDelay], sample_rate_hz: f64) -> String {
    let mut s = String::new();
    for d in delays {
        let _ = write!(
            s,
            ", {} delay {:.2}{} ms = {:.2} samples ({}; {})",
            d.column,
            1e3 * d.delay_s,
            d.std_error_s
                .map_or(String::new(), |se| format!(" ± {:.2}", 1e3 * se)),
            d.delay_s * sample_rate_hz,
            if d.estimated() { "estimated" } else { "given" },
            match (d.applied, d.estimated()) {
                (true, _) => "corrected",
                (false, true) => "too small to correct: used as recorded",
                (false, false) => "used as recorded",
            }
        );
    }
    s
}

/// The text report of the any-record method: the parameters, each record, the correlations,
/// the output-error check, the dissipative law with its band and the warnings; `inputs[i]`
/// names `id.records[i]`.
pub fn record_report(id: &RecordIdentification, inputs: &[&RecordSource]) -> String {
    let mut s = String::new();
    let ee = &id.equation_error;
    let _ = writeln!(
        s,
        "Identified parameters from {} (any-record method: equation error, {} samples faster than {} mm/s; RMS force residual {:.0} N)",
        count(id.records.len(), "record"),
        ee.points,
        1e3 * ee.min_speed_m_s,
        ee.rms_residual_n
    );
    parameter_lines(&mut s, &id.parameters);
    let u = &ee.uncertainty;
    let _ = writeln!(
        s,
        "  (± one standard error; 95 % intervals: batch-means sandwich over blocks of {} samples, t = {:.3}; residuals worth {:.0} independent samples)",
        u.bandwidth_samples, u.critical_value, u.effective_samples
    );
    let _ = writeln!(s, "\nRecords");
    for (r, (rec, input)) in id.records.iter().zip(inputs).enumerate() {
        let _ = writeln!(
            s,
            "  {}: {} samples at {} Hz, velocity {}, {} fitted over {:.1}–{:.0} mm/s, force offset {}{}{}",
            input.label,
            rec.samples,
            crate::text::rounded(rec.sample_rate_hz, 9),
            if rec.velocity_given { "given" } else { "from the crossover estimate" },
            rec.used_samples,
            1e3 * rec.speed_range_m_s[0],
            1e3 * rec.speed_range_m_s[1],
            plus_minus(ee.offsets_n.get(r), 1e3, 2) + " kN",
            rec.floors.as_ref().map_or(String::new(), |f| format!(
                ", base shear of {} storeys ({:.0} kg) removed (peak {:.0} kN)",
                f.masses_kg.len(),
                f.masses_kg.iter().sum::<f64>(),
                f.peak_base_shear_n / 1e3
            )),
            delay_text(&rec.channel_delays, rec.sample_rate_hz)
        );
    }
    correlation_lines(&mut s, "equation error", &u.correlations);
    if let Some(oe) = &id.output_error {
        output_error_lines(&mut s, oe);
    }
    let _ = writeln!(s, "\nDissipative force F_D(|v|) with its 95 % band");
    let step = (id.band.len() / 8).max(1);
    for b in id.band.iter().step_by(step) {
        let _ = writeln!(
            s,
            "  {:>9.1} mm/s  {:>8.2} kN  ({:.2} – {:.2})",
            1e3 * b.speed_m_s,
            b.force_n / 1e3,
            b.low_n / 1e3,
            b.high_n / 1e3
        );
    }
    if !id.warnings.is_empty() {
        let _ = writeln!(s, "\nWarnings");
        for w in &id.warnings {
            let _ = writeln!(s, "  - {w}");
        }
    }
    s
}

/// The output-error check: its parameters and each record's residuals before and after.
fn output_error_lines(s: &mut String, oe: &OutputErrorFit) {
    let _ = writeln!(
        s,
        "\nOutput-error check (forward simulation with exact stick-slip fitted to u and a; {} iterations, {} simulations{}):",
        oe.iterations,
        oe.simulations,
        if oe.converged { "" } else { ", NOT converged" }
    );
    parameter_lines(s, &oe.parameters);
    for (k, (u, a)) in oe.rms_u_m.iter().zip(&oe.rms_a_m_s2).enumerate() {
        let _ = writeln!(
            s,
            "  record {}: RMS residual u {:.3} → {:.3} mm, a {:.4} → {:.4} m/s²",
            k + 1,
            1e3 * u[0],
            1e3 * u[1],
            a[0],
            a[1]
        );
    }
}

/// The seven parameters, one line each.
fn parameter_lines(s: &mut String, params: &ParameterEstimates) {
    for (key, p) in params.iter() {
        let (name, (unit, scale, digits)) = (key.name(), display_unit(key));
        let text = match p {
            Parameter::Estimated(e) => format!(
                "{} {unit}   (95 % CI {:.d$} – {:.d$})",
                plus_minus(Some(e), scale, digits),
                e.ci95_low / scale,
                e.ci95_high / scale,
                d = decimals(e, scale, digits)
            ),
            Parameter::Fixed { value, reason } => {
                format!(
                    "{:.d$} {unit}   (fixed: {reason})",
                    value / scale,
                    d = digits
                )
            }
            Parameter::NotIdentifiable { reason } => format!("not identifiable: {reason}"),
        };
        let _ = writeln!(s, "  {name:<28} {text}");
    }
}

/// The correlation matrix of a fit.
fn correlation_lines(s: &mut String, fit: &str, c: &Correlations) {
    let _ = writeln!(s, "\nParameter correlations ({fit})");
    let names: Vec<&str> = c.keys.iter().map(|k| short(*k)).collect();
    let _ = writeln!(
        s,
        "  {:>4} {}",
        "",
        names.iter().map(|n| format!("{n:>7}")).collect::<String>()
    );
    for (i, row) in c.matrix.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {:>4} {}",
            names[i],
            row.iter().map(|x| format!("{x:>+7.3}")).collect::<String>()
        );
    }
}

fn short(key: IdentifiedKey) -> &'static str {
    match key {
        IdentifiedKey::EffectiveMass => "Me",
        IdentifiedKey::Stiffness => "Ke",
        IdentifiedKey::CoulombForce => "Fmu",
        IdentifiedKey::ViscousCoefficient => "Ce",
        IdentifiedKey::ViscousExponent => "alpha",
        IdentifiedKey::LowVelocityForce => "a",
        IdentifiedKey::LowVelocityDecay => "b",
    }
}

/// The HTML report of the any-record method (and of the periodic tests, if any).
fn record_html(
    id: &RecordIdentification,
    inputs: &[&RecordSource],
    periodic: Option<(&Identification, Vec<&RecordSource>)>,
    (entries, all_inputs): (&[RecordInfoSummary], &[&RecordSource]),
    figures: &[Figure],
    rendered: &[(String, String)],
) -> String {
    let mut sections = vec![html::heading("Identified parameters (any-record method)")];
    sections.push(html::table(
        &["key", "value", "unit", "std. error", "95 % CI", "status"],
        &rows(&id.parameters),
        true,
    ));
    for w in &id.warnings {
        sections.push(html::paragraph(&w.to_string(), Some("note")));
    }
    sections.push(html::heading("Report"));
    sections.push(html::preformatted(&record_report(id, inputs)));
    if let Some((p, periodic_inputs)) = periodic {
        sections.push(html::heading("Periodic tests (hysteresis-loop method)"));
        sections.push(html::preformatted(&periodic_report(p, &periodic_inputs)));
    }
    sections.extend(accounts_table(entries, all_inputs));
    let files: Vec<String> = inputs
        .iter()
        .map(|i| i.path.display().to_string())
        .collect();
    html::page(&html::Page {
        title: "platen identify".into(),
        heading: "Identification from test records (equation error, output error)".into(),
        items: vec![
            ("records".to_owned(), id.records.len().to_string()),
            (
                "files".to_owned(),
                inputs
                    .iter()
                    .map(|i| i.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
        ],
        sections,
        figures,
        rendered,
        summary: serde_json::to_value(RecordSummary::new(id, &files))
            .expect("a summary of numbers, strings and string-keyed maps serialises"),
    })
}

/// The summary of `id`, whose tests come from `inputs`.
fn summary(id: &Identification, inputs: &[&RecordSource]) -> IdentificationSummary {
    let files: Vec<String> = inputs
        .iter()
        .map(|i| i.path.display().to_string())
        .collect();
    IdentificationSummary::new(id, &files)
}

/// The HTML report: the parameter table, the text report's per-test tables, the figures
/// and the JSON summary.
fn periodic_html(
    id: &Identification,
    inputs: &[&RecordSource],
    entries: &[RecordInfoSummary],
    figures: &[Figure],
    rendered: &[(String, String)],
) -> String {
    let mut sections = vec![html::heading("Identified parameters")];
    sections.push(html::table(
        &["key", "value", "unit", "std. error", "95 % CI", "status"],
        &parameter_rows(id),
        true,
    ));
    for w in &id.warnings {
        sections.push(html::paragraph(&w.to_string(), Some("note")));
    }
    sections.push(html::heading("Report"));
    sections.push(html::preformatted(&periodic_report(id, inputs)));
    sections.extend(accounts_table(entries, inputs));
    html::page(&html::Page {
        title: "platen identify".into(),
        heading: "Identification from periodic tests (hysteresis-loop method)".into(),
        items: html_items(id, inputs),
        sections,
        figures,
        rendered,
        summary: serde_json::to_value(summary(id, inputs))
            .expect("a summary of numbers, strings and string-keyed maps serialises"),
    })
}

/// The report's header items: the tests, the files, the reference pressure.
fn html_items(id: &Identification, inputs: &[&RecordSource]) -> Vec<(String, String)> {
    let count = |kind: TestKind| id.tests.iter().filter(|t| t.kind == kind).count();
    vec![
        (
            "tests".to_owned(),
            format!(
                "{} ({} sine, {} triangle)",
                id.tests.len(),
                count(TestKind::Sine),
                count(TestKind::Triangle)
            ),
        ),
        (
            "files".to_owned(),
            inputs
                .iter()
                .map(|i| i.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        ),
        (
            "reference pressure".to_owned(),
            id.reference_pressure_pa
                .map_or("not given".to_owned(), |p| format!("{} MPa", p / 1e6)),
        ),
    ]
}

/// The HTML table's rows: key, value, unit, standard error, interval, status.
fn parameter_rows(id: &Identification) -> Vec<Vec<String>> {
    rows(&id.parameters)
}

/// The HTML table's rows of a set of parameters.
fn rows(params: &ParameterEstimates) -> Vec<Vec<String>> {
    params
        .iter()
        .map(|(key, p)| {
            let (unit, scale, d) = display_unit(key);
            let (value, se, ci, status) = match p {
                Parameter::Estimated(e) => {
                    // The decimals of the text's `value ± se`: the value, its standard error
                    // and interval alike.
                    let d = decimals(e, scale, d);
                    (
                        format!("{:.d$}", e.value / scale),
                        format!("{:.d$}", e.std_error / scale),
                        format!("{:.d$} – {:.d$}", e.ci95_low / scale, e.ci95_high / scale),
                        "estimated".to_owned(),
                    )
                }
                Parameter::Fixed { value, reason } => (
                    format!("{:.d$}", value / scale),
                    "—".into(),
                    "—".into(),
                    format!("fixed: {reason}"),
                ),
                Parameter::NotIdentifiable { reason } => (
                    "—".into(),
                    "—".into(),
                    "—".into(),
                    format!("not identifiable: {reason}"),
                ),
            };
            vec![
                key.name().to_owned(),
                value,
                unit.to_owned(),
                se,
                ci,
                status,
            ]
        })
        .collect()
}

/// `value ± se` in a unit, `se` one standard error (the same quantity wherever a `±` is
/// printed), with at least `digits` decimals and more when needed to show the standard
/// error's first two significant digits (see `decimals`).
pub fn plus_minus(e: Option<&Estimate>, scale: f64, digits: usize) -> String {
    match e {
        Some(e) if e.std_error.is_finite() => format!(
            "{:.d$} ± {:.d$}",
            e.value / scale,
            e.std_error / scale,
            d = decimals(e, scale, digits)
        ),
        Some(e) => format!("{:.d$}", e.value / scale, d = digits),
        None => "—".to_owned(),
    }
}

/// Decimals to print `e` with in a unit of `scale`: `digits`, or enough to show the first
/// significant digit of a standard error smaller than that (never `± 0.00`), at most six
/// more.
fn decimals(e: &Estimate, scale: f64, digits: usize) -> usize {
    let se = (e.std_error / scale).abs();
    if se > 0.0 && se.is_finite() {
        let needed = -(se.log10().floor() as i64);
        (needed.max(digits as i64) as usize).min(digits + 6)
    } else {
        digits
    }
}

/// `n` and `noun`, plural unless `n` is 1 ("1 test", "24 tests").
fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

fn pressure_text(p: Option<f64>) -> String {
    p.map_or_else(|| "—".to_owned(), |p| format!("{:.1}", p / 1e6))
}

fn flag_codes(flags: &[Flag]) -> String {
    flags.iter().map(Flag::code).collect::<Vec<_>>().join(",")
}

/// How a parameter is shown to a reader: unit, SI units per shown unit, decimals.
pub fn display_unit(key: IdentifiedKey) -> (&'static str, f64, usize) {
    match key {
        IdentifiedKey::EffectiveMass => ("t", 1e3, 2),
        IdentifiedKey::Stiffness => ("MN/m", 1e6, 4),
        IdentifiedKey::CoulombForce | IdentifiedKey::LowVelocityForce => ("kN", 1e3, 2),
        IdentifiedKey::ViscousCoefficient => ("kN/(m/s)^α", 1e3, 2),
        IdentifiedKey::ViscousExponent => ("", 1.0, 3),
        IdentifiedKey::LowVelocityDecay => ("s/m", 1.0, 1),
    }
}

/// The text report of the paper's method: the parameters, the per-test tables (Tables I and
/// II, Fig. 7), the per-pressure table, the fits and the warnings; `inputs[i]` names
/// `id.tests[i]`.
pub fn periodic_report(id: &Identification, inputs: &[&RecordSource]) -> String {
    let mut s = String::new();
    let w = inputs
        .iter()
        .map(|i| i.label.chars().count())
        .max()
        .unwrap_or(4)
        .max(4);
    report_parameters(&mut s, id);
    report_triangle_tests(&mut s, id, inputs, w);
    report_sine_tests(&mut s, id, inputs, w);
    report_peaks(&mut s, id, inputs, w);
    report_pressures(&mut s, id);
    report_fits(&mut s, id);
    report_global(&mut s, id);
    report_warnings(&mut s, id);
    s
}

/// The seven parameters and μₑ.
fn report_parameters(s: &mut String, id: &Identification) {
    let _ = writeln!(
        s,
        "Identified parameters ({}; {}; ± one standard error)",
        count(id.tests.len(), "test"),
        match id.reference_pressure_pa {
            Some(p) => format!("reference hold-down pressure {} MPa", p / 1e6),
            None => "hold-down pressure not given".to_owned(),
        }
    );
    parameter_lines(s, &id.parameters);
    if let Some(mu) = &id.friction_coefficient {
        let _ = writeln!(
            s,
            "  {:<28} {} %   (F_μ = μₑ·F_z over the pressures)",
            "friction_coefficient",
            plus_minus(Some(mu), 0.01, 4)
        );
    }
}

/// The stiffness table (Table I).
fn report_triangle_tests(s: &mut String, id: &Identification, inputs: &[&RecordSource], w: usize) {
    let _ = writeln!(s, "\nStiffness from triangle tests (Eq. 16/17, Table I)");
    let _ = writeln!(
        s,
        "  {:<w$} {:>5} {:>7} {:>8} {:>8}  {:>20} {:>5}  flags",
        "test", "MPa", "f Hz", "u cm", "v cm/s", "Kₑ MN/m", "used"
    );
    for (t, input) in id.tests.iter().zip(inputs) {
        if t.kind != TestKind::Triangle {
            continue;
        }
        let _ = writeln!(
            s,
            "  {:<w$} {:>5} {:>7.3} {:>8.2} {:>8.2}  {:>20} {:>5}  {}",
            input.label,
            pressure_text(t.pressure_pa),
            t.cycle.frequency_hz,
            100.0 * t.cycle.amplitude_m,
            100.0 * t.peak_velocity_m_s,
            plus_minus(t.stiffness.as_ref(), 1e6, 4),
            if t.used_for_stiffness { "yes" } else { "no" },
            flag_codes(&t.flags)
        );
    }
}

/// The mass table (Table II).
fn report_sine_tests(s: &mut String, id: &Identification, inputs: &[&RecordSource], w: usize) {
    let _ = writeln!(s, "\nEffective mass from sine tests (Eq. 18/19, Table II)");
    let _ = writeln!(
        s,
        "  {:<w$} {:>5} {:>7} {:>8} {:>8} {:>7}  {:>16} {:>5}  flags",
        "test", "MPa", "f Hz", "u cm", "v cm/s", "a g", "Mₑ t", "used"
    );
    for (t, input) in id.tests.iter().zip(inputs) {
        if t.kind != TestKind::Sine {
            continue;
        }
        let _ = writeln!(
            s,
            "  {:<w$} {:>5} {:>7.3} {:>8.2} {:>8.2} {:>7.3}  {:>16} {:>5}  {}",
            input.label,
            pressure_text(t.pressure_pa),
            t.cycle.frequency_hz,
            100.0 * t.cycle.amplitude_m,
            100.0 * t.peak_velocity_m_s,
            t.peak_acceleration_m_s2 / platen_model::STANDARD_GRAVITY_M_S2,
            plus_minus(t.effective_mass.as_ref(), 1e3, 2),
            if t.used_for_mass { "yes" } else { "no" },
            flag_codes(&t.flags)
        );
    }
}

/// The dissipative force at peak velocity per test (Fig. 7).
fn report_peaks(s: &mut String, id: &Identification, inputs: &[&RecordSource], w: usize) {
    let _ = writeln!(s, "\nDissipative force at peak velocity (Eq. 20, Fig. 7)");
    let _ = writeln!(
        s,
        "  {:<w$} {:>8} {:>5} {:>10} {:>10}",
        "test", "kind", "MPa", "v m/s", "F_D kN"
    );
    for (t, input) in id.tests.iter().zip(inputs) {
        if let Some(p) = t.peak_dissipative {
            let _ = writeln!(
                s,
                "  {:<w$} {:>8} {:>5} {:>10.4} {:>10.2}",
                input.label,
                t.kind.name(),
                pressure_text(t.pressure_pa),
                p.velocity_m_s,
                p.force_n / 1e3
            );
        }
    }
}

/// The per-pressure table.
fn report_pressures(s: &mut String, id: &Identification) {
    let _ = writeln!(s, "\nPer hold-down pressure");
    let _ = writeln!(
        s,
        "  {:>5} {:>10} {:>22} {:>18} {:>18} {:>18}",
        "MPa", "F_z MN", "Kₑ MN/m", "F_μ kN", "F_μ S kN (Eq.21)", "F_μ T kN (Eq.21)"
    );
    for g in &id.pressures {
        let _ = writeln!(
            s,
            "  {:>5} {:>10} {:>22} {:>18} {:>18} {:>18}",
            pressure_text(g.pressure_pa),
            g.vertical_force_n
                .map_or("—".to_owned(), |f| format!("{:.3}", f / 1e6)),
            plus_minus(g.stiffness.as_ref(), 1e6, 4),
            plus_minus(g.coulomb_force.as_ref(), 1e3, 2),
            plus_minus(g.paper_coulomb_force_sine.as_ref(), 1e3, 2),
            plus_minus(g.paper_coulomb_force_triangle.as_ref(), 1e3, 2),
        );
    }
}

/// Eq. 21 as the paper fitted it, and the law fit.
fn report_fits(s: &mut String, id: &Identification) {
    if let Some(p) = &id.paper_fit {
        let _ = writeln!(
            s,
            "\nEq. 21 as the paper fitted it ({} peak points{}): F_μ = {} kN, Cₑ = {} kN/(m/s)^0.5{}",
            p.points,
            if p.sine_only { ", sine tests" } else { ", all tests" },
            plus_minus(Some(&p.coulomb_force), 1e3, 2),
            plus_minus(Some(&p.viscous_coefficient), 1e3, 2),
            p.friction_coefficient
                .as_ref()
                .map_or(String::new(), |mu| format!(
                    ", μₑ = {} %",
                    plus_minus(Some(mu), 0.01, 4)
                ))
        );
    }
    if let Some(l) = &id.law {
        let _ = writeln!(
            s,
            "Dissipative law fitted to {} points over {:.3}–{:.3} m/s: RMS residual {:.0} N",
            l.points, l.speed_range_m_s[0], l.speed_range_m_s[1], l.rms_n
        );
    }
}

/// The global fit against the hysteresis-loop estimate.
fn report_global(s: &mut String, id: &Identification) {
    if let Some(g) = &id.global {
        let _ = writeln!(
            s,
            "\nGlobal fit of Eq. 23 over every test ({} samples, RMS residual {:.0} N{}):",
            g.points,
            g.rms_residual_n,
            if g.converged { "" } else { ", NOT converged" }
        );
        for (key, p) in g.parameters.iter() {
            let (name, (unit, scale, digits)) = (key.name(), display_unit(key));
            let own = id.parameters.get(key);
            let diff = match (p.value(), own.value()) {
                (Some(a), Some(b)) if b != 0.0 => {
                    format!("  ({:+.2} %)", 100.0 * (a - b) / b.abs())
                }
                _ => String::new(),
            };
            let text = match p {
                Parameter::Estimated(e) => plus_minus(Some(e), scale, digits),
                Parameter::Fixed { value, .. } => {
                    format!("{:.d$} (held)", value / scale, d = digits)
                }
                Parameter::NotIdentifiable { .. } => "not identifiable".to_owned(),
            };
            let _ = writeln!(s, "  {name:<28} {text} {unit}{diff}");
        }
    }
}

/// The warnings.
fn report_warnings(s: &mut String, id: &Identification) {
    if !id.warnings.is_empty() {
        let _ = writeln!(s, "\nWarnings");
        for w in &id.warnings {
            let _ = writeln!(s, "  - {w}");
        }
    }
}

/// The lines naming the files written: the figures (absent when none) and the HTML report.
pub fn written_text(figures: &[PathBuf], report: Option<&Path>) -> String {
    let mut s = String::new();
    if !figures.is_empty() {
        let _ = writeln!(s, "\nWrote {} figure files (SVG and PNG):", figures.len());
        for path in figures {
            let _ = writeln!(s, "  {}", path.display());
        }
    }
    if let Some(path) = report {
        let _ = writeln!(s, "Wrote report {}", path.display());
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use platen_app::{read_records, RecordRequest};
    use platen_ident::{identify_any, MethodRequest, RecordSettings, Settings};

    /// Two of the paper's tests at 13.8 MPa, made in memory from their scenarios through a
    /// manifest that names them.
    fn paper_pair() -> (Vec<RecordSource>, Vec<TestRecord>, Identified) {
        let root =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/paper-tests/13.8MPa");
        let dir =
            std::env::temp_dir().join(format!("platen-report-identify-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let manifest = dir.join("m.json");
        let entry = |name: &str, seed: u64| serde_json::json!({"scenario": root.join(format!("{name}.json")), "seed": seed, "name": name});
        let tests = serde_json::json!({"tests": [entry("S9", 9), entry("T4", 16)]});
        std::fs::write(&manifest, tests.to_string()).unwrap();
        let inputs = read_records(&RecordRequest {
            manifest: Some(manifest),
            ..RecordRequest::default()
        })
        .unwrap();
        let id = identify_any(
            &inputs.records,
            &inputs.declared_record(),
            MethodRequest::Auto,
            &Settings::default().build().unwrap(),
            &RecordSettings::default().build().unwrap(),
        )
        .unwrap();
        (inputs.sources, inputs.records, id)
    }

    #[test]
    fn the_text_and_page_name_every_record_by_its_label() {
        let (sources, records, id) = paper_pair();
        let report = IdentifyReport {
            identified: &id,
            sources: &sources,
            records: &records,
        };
        assert!(report.unused().is_empty());
        let text = report.text();
        assert!(text.starts_with(
            "Identified parameters (2 tests; reference hold-down pressure 13.8 MPa; ± one standard error)\n"
        ));
        let accounts = &text[text.find("\nRecords (every file accounted for)\n").unwrap()..];
        assert_eq!(accounts.lines().count(), 4, "{accounts}");
        assert!(accounts.contains("\n  S9  periodic  used; "));
        assert!(accounts.contains("\n  T4  periodic  used; "));
        // The sine's mass row and the triangle's stiffness row, each under its own label.
        assert!(text.contains("\n  S9    13.8 "));
        assert!(text.contains("\n  T4    13.8 "));
        let page = report.html(&[], &[]);
        assert!(page.contains("<h2>Records</h2>"));
        assert!(page.contains("S9, T4"), "the files item lists the names");
    }

    #[test]
    fn written_files_are_listed_after_the_report() {
        assert_eq!(written_text(&[], None), "");
        let figures = [PathBuf::from("f/a.svg"), PathBuf::from("f/a.png")];
        assert_eq!(
            written_text(&figures, Some(Path::new("r.html"))),
            "\nWrote 2 figure files (SVG and PNG):\n  f/a.svg\n  f/a.png\nWrote report r.html\n"
        );
    }
}
