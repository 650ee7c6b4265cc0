//! `platen generate`: write the excitation of a scenario, or the recorded-like data a table's
//! data system would have produced for a motion scenario.

use std::path::Path;

use anyhow::{bail, Context, Result};

use platen_integrate::{inverse, Peaks, Trajectory};
use platen_io::csv::write_csv_atomic;
use platen_model::PlatenModel;
use platen_report::sweep_report::GenerateReport;
use platen_scenario::recorded::{recorded_like, ArtefactSettings, Recorded};
use platen_scenario::{Model, Run, Scenario};

/// What to generate.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum What {
    /// The excitation as it drives the model: t_s, force_n (forward scenarios, after any
    /// low-pass) or t_s, u_m, v_m_s, a_m_s2 (motion scenarios).
    Excitation,
    /// Recorded-like data of a motion scenario: the model's actuator force with oil-column
    /// ringing at 10.66 Hz after reversals, a 246 Hz valve tone, 689.5 Pa pressure resolution
    /// and sensor noise; noisy displacement and acceleration; velocity from the crossover
    /// filter. Columns t_s, u_m, v_m_s, a_m_s2, force_n.
    Recorded,
}

/// Runs `platen generate`.
pub fn run(what: What, scenario_path: &Path, out: &Path, seed: u64, json_out: bool) -> Result<()> {
    let scenario = Scenario::load(scenario_path)?;
    match what {
        What::Excitation => match &scenario.run {
            Run::Forward {
                record, samples, ..
            } => {
                let n = *samples;
                write_csv_atomic(
                    out,
                    &["t_s", "force_n"],
                    &[&record.t_s()[..n], &record.force_n()[..n]],
                )?;
                report(json_out, out, n, "force", None)?;
            }
            Run::Inverse { motion } => {
                write_csv_atomic(
                    out,
                    &["t_s", "u_m", "v_m_s", "a_m_s2"],
                    &[motion.t_s(), motion.u_m(), motion.v_m_s(), motion.a_m_s2()],
                )?;
                report(json_out, out, motion.len(), "motion", None)?;
            }
        },
        What::Recorded => {
            let rec = recorded_of(&scenario, scenario_path, seed)?;
            write_csv_atomic(out, &Recorded::COLUMN_NAMES, &rec.columns())?;
            report(json_out, out, rec.t_s.len(), "recorded", Some(seed))?;
        }
    }
    Ok(())
}

/// The recorded-like data of a loaded motion scenario (`scenario_path` names it in
/// messages): what `platen generate recorded` writes, and what `platen identify` makes of a
/// manifest entry that names a scenario.
pub(crate) fn recorded_of(
    scenario: &Scenario,
    scenario_path: &Path,
    seed: u64,
) -> Result<Recorded> {
    let Run::Inverse { motion } = &scenario.run else {
        bail!(
            "`{}`: recorded-like data needs a motion scenario (motion_csv, sine_motion, triangle_motion, \
             white_noise_motion or ground_motion); this one is force-driven",
            scenario_path.display()
        );
    };
    match &scenario.model {
        Model::Identified(m) => recorded(m, motion, seed),
        Model::Full(m) => recorded(&**m, motion, seed),
    }
}

fn recorded<M: PlatenModel>(
    model: &M,
    motion: &platen_integrate::Motion,
    seed: u64,
) -> Result<Recorded> {
    let mut truth = (Trajectory::with_capacity(motion.len()), Peaks::default());
    inverse(model, motion, &mut truth);
    recorded_like(
        &truth.0,
        model.static_threshold_n(0.0),
        &ArtefactSettings::default(),
        seed,
    )
    .map_err(anyhow::Error::msg)
    .context("recorded-like data could not be made")
}

/// Prints what was written: [`GenerateReport`] as JSON or as its text line.
fn report(
    json_out: bool,
    out: &Path,
    samples: usize,
    kind: &'static str,
    seed: Option<u64>,
) -> Result<()> {
    let report = GenerateReport {
        kind,
        out: out.display().to_string(),
        samples,
        seed,
    };
    if json_out {
        outln!("{}", serde_json::to_string(&report)?);
    } else {
        out!("{}", report.text());
    }
    Ok(())
}
