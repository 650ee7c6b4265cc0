//! `platen generate`: write the excitation of a scenario, or the recorded-like data a table's
//! data system would have produced for a motion scenario.

use std::path::{Path, PathBuf};

use anyhow::Result;

use platen_app::recorded_of;
use platen_io::csv::write_csv_atomic;
use platen_report::sweep_report::GenerateReport;
use platen_scenario::recorded::Recorded;
use platen_scenario::{PlatenScenario, Scenario};

use crate::usage;

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

/// The arguments of `platen generate`.
#[derive(clap::Args)]
pub struct GenerateArgs {
    /// What to write.
    #[arg(value_enum)]
    what: What,
    /// Scenario JSON file.
    scenario: PathBuf,
    /// Output CSV file.
    #[arg(long, value_parser = usage::OutFile("excitation.csv"))]
    out: PathBuf,
    /// Seed of the noise of recorded-like data.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `platen generate`.
pub fn run(args: &GenerateArgs) -> Result<()> {
    let (scenario_path, out, seed, json_out) = (&args.scenario, &args.out, args.seed, args.json);
    match args.what {
        What::Excitation => {
            let scenario = Scenario::load(scenario_path)?;
            let excitation = scenario.excitation();
            let names: Vec<&str> = excitation.names.iter().map(String::as_str).collect();
            write_csv_atomic(out, &names, &excitation.columns)?;
            report(json_out, out, excitation.len(), excitation.kind, None)?;
        }
        What::Recorded => {
            // Recorded-like data is the uniaxial platen's (its LVDT, accelerometer and
            // load-cell channels).
            let scenario = PlatenScenario::load(scenario_path)?;
            let rec = recorded_of(&scenario, scenario_path, seed)?;
            write_csv_atomic(out, &Recorded::COLUMN_NAMES, &rec.columns())?;
            report(json_out, out, rec.t_s.len(), "recorded", Some(seed))?;
        }
    }
    Ok(())
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
