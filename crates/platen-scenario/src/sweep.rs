//! Batch sweeps: the Cartesian product of excitation scales, hold-down pressures and model
//! parameter values over one scenario, run in parallel on every core (rayon), one row of
//! peaks and counters per case. The rows are in case order, so the output has the same bytes
//! whatever the number of threads.
//!
//! Forward RK4 sweeps run their identified-model cases in groups of up to
//! [`ENSEMBLE_LANES`] consecutive cases, each group one ensemble
//! ([`forward_rk4_ensemble`]: the cases in SIMD lanes, bit for bit the scalar runs), so the
//! results, and the output's bytes, are those of one scalar run per case.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use rayon::prelude::*;
use serde::Serialize;
use serde_json::Value;

use platen_integrate::{
    forward_rk4_ensemble, EnsembleCase, IntegrateError, Method, Peaks, Rk4, RunStats,
    ENSEMBLE_LANES,
};
use platen_io::csv::write_number;
use platen_model::ModelError;

use crate::scenario::{Model, ModelKey, PlatenScenario, Run};
use crate::summary::ExceedanceSummary;

/// One parameter axis: `FORM.KEY` and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct SetAxis {
    /// `identified.KEY` or `full.KEY`, the column name of the axis.
    pub name: String,
    /// The parameter.
    pub key: ModelKey,
    /// Its values, in order.
    pub values: Vec<f64>,
}

/// A case whose model cannot be built: nothing runs.
#[derive(Debug, thiserror::Error)]
#[error("case {case} ({description}): the model cannot be built; nothing was run")]
pub struct CaseError {
    /// The case's index.
    pub case: usize,
    /// Its scale, pressure and parameter values.
    pub description: String,
    /// Why the model is rejected.
    #[source]
    pub source: ModelError,
}

/// The grid of a sweep: every case's model, built (and so validated) before anything runs.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The cases in order: scale varies slowest, then pressure, then each axis in order.
    pub cases: Vec<Case>,
    /// The column names of the parameter axes.
    pub set_names: Vec<String>,
}

impl Sweep {
    /// The grid over `scenario`: an empty `scales` or `pressures_mpa` holds the scenario's
    /// own value.
    ///
    /// # Errors
    /// [`CaseError`] for the first case whose model cannot be built.
    pub fn new(
        scenario: &PlatenScenario,
        scales: &[f64],
        pressures_mpa: &[f64],
        sets: &[SetAxis],
    ) -> Result<Self, CaseError> {
        let scales = if scales.is_empty() {
            &[1.0][..]
        } else {
            scales
        };
        let pressures: Vec<(f64, f64)> = if pressures_mpa.is_empty() {
            vec![(
                scenario.rig.hold_down_pressure_pa / 1e6,
                scenario.rig.hold_down_pressure_pa,
            )]
        } else {
            pressures_mpa.iter().map(|&p| (p, p * 1e6)).collect()
        };
        let mut cases = Vec::new();
        for &scale in scales {
            for &(pressure_mpa, pressure_pa) in &pressures {
                for combo in product(sets) {
                    let named: Vec<(ModelKey, f64)> = sets
                        .iter()
                        .zip(&combo)
                        .map(|(axis, &v)| (axis.key, v))
                        .collect();
                    let model = scenario
                        .rig
                        .model_at(pressure_pa, &named)
                        .map_err(|source| CaseError {
                            case: cases.len(),
                            description: describe(scale, pressure_mpa, sets, &combo),
                            source,
                        })?;
                    cases.push(Case {
                        scale,
                        pressure_mpa,
                        sets: combo,
                        model,
                    });
                }
            }
        }
        Ok(Self {
            cases,
            set_names: sets.iter().map(|a| a.name.clone()).collect(),
        })
    }

    /// Runs every case in parallel under `run` (the scenario's excitation), calling
    /// `progress` after each; the outcomes are in case order.
    pub fn run(&self, run: &Run, progress: impl Fn() + Sync) -> Vec<Outcome> {
        if let Run::Forward {
            integrator: Method::Rk4(rk4),
            samples,
            ..
        } = run
        {
            // Groups as large as the lanes allow while every thread still gets one.
            let threads = rayon::current_num_threads().max(1);
            let lanes = self.cases.len().div_ceil(threads).clamp(1, ENSEMBLE_LANES);
            let groups: Vec<&[Case]> = self.cases.chunks(lanes).collect();
            return groups
                .par_iter()
                .flat_map_iter(|group| {
                    let outcomes = run_group(group, run, *rk4, *samples);
                    group.iter().for_each(|_| progress());
                    outcomes
                })
                .collect();
        }
        self.cases
            .par_iter()
            .map(|case| {
                let outcome = run_case(case, run);
                progress();
                outcome
            })
            .collect()
    }
}

/// One case of the grid.
#[derive(Debug, Clone)]
pub struct Case {
    /// The factor on the excitation.
    pub scale: f64,
    /// The hold-down pressure, MPa.
    pub pressure_mpa: f64,
    /// One value per `--set` axis.
    pub sets: Vec<f64>,
    /// The case's model.
    pub model: Model,
}

/// What a case produced.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The peaks of the run.
    pub peaks: Peaks,
    /// Solver statistics of a forward run.
    pub stats: Option<RunStats>,
    /// The numerical failure, if the case failed.
    pub error: Option<IntegrateError>,
}

/// Every combination of the `--set` axes' values, the last axis varying fastest.
fn product(sets: &[SetAxis]) -> Vec<Vec<f64>> {
    let mut combos = vec![Vec::new()];
    for axis in sets {
        combos = combos
            .into_iter()
            .flat_map(|prefix| {
                axis.values.iter().map(move |&v| {
                    let mut c = prefix.clone();
                    c.push(v);
                    c
                })
            })
            .collect();
    }
    combos
}

fn describe(scale: f64, pressure_mpa: f64, sets: &[SetAxis], values: &[f64]) -> String {
    let mut s = format!("scale {scale}, {pressure_mpa} MPa");
    for (axis, v) in sets.iter().zip(values) {
        let _ = write!(s, ", {} = {v}", axis.name);
    }
    s
}

/// Runs one case: its model under the scenario's excitation multiplied by its scale,
/// keeping only the peaks.
fn run_case(case: &Case, run: &Run) -> Outcome {
    let run = match run.scaled(case.scale) {
        Ok(run) => run,
        Err(e) => return failed(e),
    };
    let mut peaks = Peaks::default();
    match case.model.run(&run, &mut peaks) {
        Ok(output) => Outcome {
            peaks,
            stats: output.stats,
            error: None,
        },
        Err(e) => failed(e),
    }
}

/// Runs consecutive cases of a forward RK4 sweep: the identified-model cases together as one
/// ensemble, the others as [`run_case`] runs them; the outcomes in case order, each that of
/// [`run_case`] on its case.
fn run_group(cases: &[Case], run: &Run, rk4: Rk4, samples: usize) -> Vec<Outcome> {
    let scaled: Vec<_> = cases.iter().map(|c| run.scaled(c.scale)).collect();
    let mut outcomes: Vec<Option<Outcome>> = vec![None; cases.len()];
    let mut lanes: Vec<(usize, EnsembleCase<'_>)> = Vec::new();
    for (i, (case, scaled)) in cases.iter().zip(&scaled).enumerate() {
        match (&case.model, scaled.as_deref()) {
            (
                Model::Identified(model),
                Ok(Run::Forward {
                    record, initial, ..
                }),
            ) => lanes.push((
                i,
                EnsembleCase {
                    model,
                    record,
                    initial: *initial,
                },
            )),
            _ => outcomes[i] = Some(run_case(case, run)),
        }
    }
    let ensemble: Vec<EnsembleCase<'_>> = lanes.iter().map(|&(_, c)| c).collect();
    let mut peaks = vec![Peaks::default(); ensemble.len()];
    let results = forward_rk4_ensemble(&ensemble, rk4, samples, &mut peaks);
    for ((i, _), (result, peaks)) in lanes.iter().zip(results.into_iter().zip(peaks)) {
        outcomes[*i] = Some(match result {
            Ok(stats) => Outcome {
                peaks,
                stats: Some(stats),
                error: None,
            },
            Err(e) => failed(e),
        });
    }
    outcomes.into_iter().flatten().collect()
}

fn failed(e: IntegrateError) -> Outcome {
    Outcome {
        peaks: Peaks::default(),
        stats: None,
        error: Some(e),
    }
}

/// The limits a case's peaks exceed: `"stroke;velocity"`, or `"none"`.
pub fn exceeded(scenario: &PlatenScenario, peaks: &Peaks) -> String {
    let names: Vec<&str> = peaks
        .exceedances(&scenario.rig.limits)
        .iter()
        .map(|e| e.quantity)
        .collect();
    if names.is_empty() {
        "none".to_owned()
    } else {
        names.join(";")
    }
}

/// `ok`, or `failed: …` with the case's error.
pub fn status(outcome: &Outcome) -> String {
    match &outcome.error {
        None => "ok".to_owned(),
        Some(e) => format!("failed: {e}"),
    }
}

/// A CSV field holding free text, quoted when it needs to be.
fn text_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// Column names of the sweep CSV.
fn header(set_names: &[String]) -> Vec<String> {
    let mut h = vec![
        "case".to_owned(),
        "scale".to_owned(),
        "hold_down_pressure_mpa".to_owned(),
    ];
    h.extend(set_names.iter().cloned());
    h.extend(
        [
            "peak_u_m",
            "peak_v_m_s",
            "peak_a_m_s2",
            "peak_force_n",
            "stick_time_s",
            "events",
            "limits_exceeded",
            "status",
        ]
        .map(str::to_owned),
    );
    h
}

/// The sweep CSV: one row per case in case order. Numbers in the shortest round-trip form of
/// the time-series CSVs; `stick_time_s` and `events` are empty for inverse runs, and every
/// result column but `status` is empty for a case that failed.
pub fn csv_text(
    scenario: &PlatenScenario,
    set_names: &[String],
    cases: &[Case],
    outs: &[Outcome],
) -> String {
    let mut text = header(set_names).join(",");
    text.push('\n');
    let mut buf = Vec::new();
    let mut number = |text: &mut String, v: f64| {
        buf.clear();
        // Writing to a Vec cannot fail.
        let _ = write_number(&mut buf, v);
        text.push_str(std::str::from_utf8(&buf).unwrap_or_default());
        text.push(',');
    };
    for (i, (case, o)) in cases.iter().zip(outs).enumerate() {
        let _ = write!(text, "{i},");
        number(&mut text, case.scale);
        number(&mut text, case.pressure_mpa);
        for &v in &case.sets {
            number(&mut text, v);
        }
        if o.error.is_some() {
            // Peaks up to a numerical failure mean nothing: leave them out.
            let _ = writeln!(text, ",,,,,,,{}", text_field(&status(o)));
            continue;
        }
        for v in [
            o.peaks.u_m.value,
            o.peaks.v_m_s.value,
            o.peaks.a_m_s2.value,
            o.peaks.force_n.value,
        ] {
            number(&mut text, v);
        }
        match &o.stats {
            Some(st) => {
                number(&mut text, st.stick_time_s);
                let _ = write!(text, "{},", st.events());
            }
            None => text.push_str(",,"),
        }
        let _ = writeln!(
            text,
            "{},{}",
            exceeded(scenario, &o.peaks),
            text_field(&status(o))
        );
    }
    text
}

/// The `--json` summary of a sweep ([`json_summary`]): the scenario, counts, and one row per
/// case. Serialised by serde; the JSON object's keys print sorted, as every `--json` of the
/// CLI does.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepSummary {
    /// The scenario file, as given.
    pub scenario: String,
    /// The scenario's `name`.
    pub name: String,
    /// `"forward"` or `"inverse"`.
    pub direction: &'static str,
    /// `"identified"` or `"full"`.
    pub model_form: &'static str,
    /// The model preset's name.
    pub preset: &'static str,
    /// How many cases ran.
    pub cases: usize,
    /// How many failed numerically.
    pub failed: usize,
    /// How many ran and exceeded at least one of the table's limits.
    pub exceeding_a_limit: usize,
    /// The CSV written, if any.
    pub out: Option<String>,
    /// One row per case, in case order.
    pub results: Vec<CaseSummary>,
}

/// One case's row of a [`SweepSummary`]: its axes, status, and (when it ran) its peaks with
/// their times, stick time, events and the limits it exceeds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaseSummary {
    /// The case's index (input order).
    pub case: usize,
    /// The excitation scale.
    pub scale: f64,
    /// The hold-down pressure, MPa.
    pub hold_down_pressure_mpa: f64,
    /// The `--set` values, by key.
    pub set: BTreeMap<String, f64>,
    /// `"ok"` or `"failed: …"`.
    pub status: String,
    /// The peaks, stick time, events and exceedances (absent for a failed case).
    #[serde(flatten)]
    pub run: Option<CaseRun>,
}

/// What a case that ran reports ([`CaseSummary::run`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaseRun {
    /// Peak |u|, m (signed), and its time.
    pub peak_u_m: f64,
    /// When `peak_u_m` occurred, s.
    pub peak_u_m_t_s: f64,
    /// Peak velocity, m/s (signed).
    pub peak_v_m_s: f64,
    /// When `peak_v_m_s` occurred, s.
    pub peak_v_m_s_t_s: f64,
    /// Peak acceleration, m/s² (signed).
    pub peak_a_m_s2: f64,
    /// When `peak_a_m_s2` occurred, s.
    pub peak_a_m_s2_t_s: f64,
    /// Peak actuator force, N (signed).
    pub peak_force_n: f64,
    /// When `peak_force_n` occurred, s.
    pub peak_force_n_t_s: f64,
    /// Time spent in stick, s (absent from runs without statistics: `null`).
    pub stick_time_s: Option<f64>,
    /// Events located (`null` as `stick_time_s`).
    pub events: Option<u64>,
    /// The table's limits the case exceeds.
    pub limit_exceedances: Vec<ExceedanceSummary>,
}

impl SweepSummary {
    /// The summary of `outs`, the outcomes of `cases` over `scenario` (read from `path`),
    /// `set_names` naming the `--set` axes and `out` the CSV written.
    pub fn new(
        path: &Path,
        scenario: &PlatenScenario,
        set_names: &[String],
        cases: &[Case],
        outs: &[Outcome],
        out: Option<&Path>,
    ) -> Self {
        let results = cases
            .iter()
            .zip(outs)
            .enumerate()
            .map(|(i, (case, o))| CaseSummary {
                case: i,
                scale: case.scale,
                hold_down_pressure_mpa: case.pressure_mpa,
                set: set_names
                    .iter()
                    .cloned()
                    .zip(case.sets.iter().copied())
                    .collect(),
                status: status(o),
                run: o.error.is_none().then(|| CaseRun {
                    peak_u_m: o.peaks.u_m.value,
                    peak_u_m_t_s: o.peaks.u_m.t_s,
                    peak_v_m_s: o.peaks.v_m_s.value,
                    peak_v_m_s_t_s: o.peaks.v_m_s.t_s,
                    peak_a_m_s2: o.peaks.a_m_s2.value,
                    peak_a_m_s2_t_s: o.peaks.a_m_s2.t_s,
                    peak_force_n: o.peaks.force_n.value,
                    peak_force_n_t_s: o.peaks.force_n.t_s,
                    stick_time_s: o.stats.map(|s| s.stick_time_s),
                    events: o.stats.map(|s| s.events()),
                    limit_exceedances: o
                        .peaks
                        .exceedances(&scenario.rig.limits)
                        .iter()
                        .map(ExceedanceSummary::from)
                        .collect(),
                }),
            })
            .collect();
        SweepSummary {
            scenario: path.display().to_string(),
            name: scenario.name.clone(),
            // A sweep runs the model alone ([`Model::run`]): a closed loop's command runs as
            // the motion it asks for.
            direction: match scenario.run {
                Run::Forward { .. } => "forward",
                Run::Inverse { .. } | Run::ClosedLoop { .. } => "inverse",
            },
            model_form: scenario.rig.model.form(),
            preset: scenario.rig.preset.name(),
            cases: cases.len(),
            failed: outs.iter().filter(|o| o.error.is_some()).count(),
            exceeding_a_limit: outs
                .iter()
                .filter(|o| {
                    o.error.is_none() && !o.peaks.exceedances(&scenario.rig.limits).is_empty()
                })
                .count(),
            out: out.map(|p| p.display().to_string()),
            results,
        }
    }
}

/// The `--json` summary of a sweep as a JSON value ([`SweepSummary`]).
pub fn json_summary(
    path: &Path,
    scenario: &PlatenScenario,
    set_names: &[String],
    cases: &[Case],
    outs: &[Outcome],
    out: Option<&Path>,
) -> Value {
    serde_json::to_value(SweepSummary::new(
        path, scenario, set_names, cases, outs, out,
    ))
    .expect("a sweep summary is plain data (strings, finite or null numbers)")
}
