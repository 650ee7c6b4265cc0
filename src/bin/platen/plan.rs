//! `platen plan`: can the scenario's table run the target, what limits it, the largest scale
//! that fits, and the drive (displacement command) that makes the simulated table reproduce
//! it. Everything is computed by `platen_plan`; this file parses, prints and writes.
//!
//! The drive CSV's temporary file is created first (an unwritable destination fails before
//! anything runs) and renamed over `--out` only when the plan is complete: a failed plan
//! leaves nothing and does not touch an existing file.

use std::path::PathBuf;

use anyhow::Result;
use clap::ValueEnum;

use platen_io::columns::ColumnMap;
use platen_io::csv::CsvWriter;
use platen_plan::{
    FrfSource, MaxScaleSettings, NoiseSettings, PlanError, PlanScenario, PlanSettings, PlanTarget,
};
use platen_report::planned;
use platen_report::simulate_report::with_outputs;

use crate::progress::Progress;

/// The arguments of `platen plan`.
#[derive(clap::Args)]
pub struct Args {
    /// Scenario JSON file with a `table_system` (its model, table system, specimen and limits
    /// are used; its excitation, if any, is ignored: the target takes its place), or with a
    /// multi-axis `table` and its `controller` (a three-component plan).
    pub scenario: PathBuf,
    /// Target CSV: `t_s` and `a_m_s2` (an acceleration record), or `t_s` and `u_m` (a
    /// displacement), uniformly sampled (a slower or faster target is put on the controller's
    /// rate, a faster one anti-aliased, with a notice). On a multi-axis table: `t_s` and any
    /// of `x_m_s2`,
    /// `y_m_s2`, `z_m_s2` (or `x_m`, `y_m`, `z_m`); absent axes are held at zero.
    #[arg(long, value_name = "TARGET.csv")]
    pub target: PathBuf,
    /// JSON file mapping the target's own column names and units to platen's `t_s`,
    /// `a_m_s2` or `u_m`, as a scenario's excitation.columns: {"t_s": {"name": "Time (s)"},
    /// "a_m_s2": {"name": "Acc [g]", "unit": "g"}} (a uniaxial target).
    #[arg(long, value_name = "MAP.json")]
    pub columns: Option<PathBuf>,
    /// Write the drive (`t_s`, `u_m`: the displacement command, at the controller's rate) to
    /// this CSV file; on a multi-axis table the six-DOF command (`t_s`, `x_m` … `yaw_rad`), a
    /// `motion_csv` that `simulate` replays.
    #[arg(long, value_name = "DRIVE.csv", value_parser = crate::usage::OutFile("drive.csv"))]
    pub out: PathBuf,
    /// Required response spectrum CSV to accept the drive's run against (AC156-style band
    /// -10/+30 %): `period_s` (or `frequency_hz`) and `psa_m_s2` (or `psa_g`); on a
    /// multi-axis table `x_psa_m_s2`, `y_psa_m_s2`, `z_psa_m_s2` (or `…_psa_g`), an axis
    /// without one judged against its target. Default: the target's own spectrum.
    #[arg(long, value_name = "RRS.csv")]
    pub rrs: Option<PathBuf>,
    /// Damping ratio of the required response spectrum (a fraction).
    #[arg(long, value_name = "ZETA", default_value_t = platen_plan::DEFAULT_RRS_DAMPING, value_parser = |s: &str| parse_checked(s, |z| (0.0..1.0).contains(&z), "a damping ratio in [0, 1) (0.05 for 5 %)"))]
    pub rrs_damping: f64,
    /// Iterate the drive at this fraction of the target (say 0.25), so that the specimen
    /// does not see full-level shaking while the drive converges; the best drive is scaled up
    /// by its inverse and run once at full level, which gives the predicted full-level error
    /// (the drive written is the scaled-up one).
    #[arg(long, value_name = "LEVEL", value_parser = |s: &str| parse_checked(s, |l| l > 0.0 && l <= 1.0, "a fraction of the target in (0, 1] (0.25 for 25 %)"))]
    pub iterate_at: Option<f64>,
    /// Most drive corrections (0: run the target's own command only).
    #[arg(long, value_name = "N", default_value_t = 10, value_parser = clap::value_parser!(u16).range(0..=200))]
    pub iterations: u16,
    /// Gain g of the iteration D ← D + g·Ĥ⁻¹(T − R), in (0, 2).
    #[arg(long, value_name = "G", default_value_t = platen_plan::iterate::DEFAULT_GAIN, value_parser = parse_gain)]
    pub gain: f64,
    /// Stop when the acceleration NRMSE is at most this (a fraction).
    #[arg(long, value_name = "E", default_value_t = 0.02, value_parser = parse_nrmse)]
    pub target_nrmse: f64,
    /// Where Ĥ comes from: the model's linearisation, or measured on the simulated table with
    /// a white-noise command at the target's RMS acceleration (sees a specimen's modes);
    /// auto: measured when the scenario has a specimen, linearised otherwise.
    #[arg(long, value_enum, default_value_t = Frf::Auto)]
    pub frf: Frf,
    /// Correction band, Hz (default 0.1 to the smaller of 50 Hz and 0.45 times the rate).
    #[arg(long, value_name = "LO,HI", value_parser = parse_band)]
    pub band_hz: Option<(f64, f64)>,
    /// Do not search the largest scale that fits (saves about ten closed-loop runs).
    #[arg(long)]
    pub no_max_scale: bool,
    /// Multi-axis scenarios: also search the largest scale of each axis, the others as given
    /// (about ten closed-loop runs per axis).
    #[arg(long)]
    pub per_axis_scale: bool,
    /// Print the plan as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write the plan's figures to this folder as SVG and PNG: target against achieved
    /// acceleration (iteration 0 and the drive's), their 5 %-damped response spectra, the
    /// errors per iteration, the limits' margins.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write a self-contained HTML report (margins, iterations, figures) to this file.
    #[arg(long, value_name = "FILE.html", value_parser = crate::usage::OutFile("report.html"))]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub size: crate::plot::SizeArgs,
}

/// `--frf`.
#[derive(Clone, Copy, ValueEnum)]
pub enum Frf {
    /// Measured with a specimen, linearised without.
    Auto,
    /// The model's linearisation about mid-stroke (the specimen as a rigid payload).
    Linearised,
    /// Measured on the simulated table with band-limited white noise (64 s).
    Measured,
}

fn parse_number(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: expected a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("`{s}`: expected a finite number"))
    }
}

/// A finite number for which `ok` holds, else `"{v}: expected {what}"`.
fn parse_checked(s: &str, ok: fn(f64) -> bool, what: &str) -> std::result::Result<f64, String> {
    let v = parse_number(s)?;
    ok(v).then_some(v).ok_or(format!("{v}: expected {what}"))
}

/// `--gain`: in (0, 2).
fn parse_gain(s: &str) -> std::result::Result<f64, String> {
    parse_checked(s, |g| g > 0.0 && g < 2.0, "a gain in (0, 2)")
}

/// `--target-nrmse`: a fraction >= 0.
fn parse_nrmse(s: &str) -> std::result::Result<f64, String> {
    parse_checked(s, |e| e >= 0.0, "an NRMSE >= 0 (a fraction)")
}

/// `--band-hz LO,HI` with `0 < LO < HI`.
fn parse_band(s: &str) -> std::result::Result<(f64, f64), String> {
    let (lo, hi) = s
        .split_once(',')
        .ok_or_else(|| format!("`{s}`: expected LO,HI in Hz"))?;
    let (lo, hi) = (parse_number(lo)?, parse_number(hi)?);
    if lo > 0.0 && hi > lo {
        Ok((lo, hi))
    } else {
        Err(format!("`{s}`: expected 0 < LO < HI, Hz"))
    }
}

/// The error of the plan, unwrapped so that the exit code and the JSON error object see the
/// file and line errors it holds (as for every verb).
fn cli_error(e: PlanError) -> anyhow::Error {
    match e.into_io() {
        Ok(io) => io.into(),
        Err(PlanError::Scenario(se)) => se.into(),
        Err(PlanError::Run { what, source }) => {
            anyhow::Error::new(source).context(format!("the closed-loop run of {what} failed"))
        }
        Err(other) => other.into(),
    }
}

/// `platen plan`: the scenario read for planning, whatever its table, its target and
/// required spectra as that table takes them, the one plan ([`platen_plan::plan`]), its drive
/// written, its figures, report, warnings and summary.
pub fn run(args: &Args) -> Result<()> {
    let mut settings = settings(args);
    let columns = match &args.columns {
        Some(map) => ColumnMap::load(map)?,
        None => ColumnMap::default(),
    };
    let scenario = PlanScenario::load(&args.scenario).map_err(cli_error)?;
    if scenario.is_multi_axis() {
        refuse_for_multi_axis(args)?;
    }
    // The drive's temporary file first: an unwritable destination fails before any run.
    let writer = CsvWriter::create(&args.out, scenario.drive_columns())?;
    let target = PlanTarget::read_csv(&scenario, &args.target, &columns).map_err(cli_error)?;
    if let Some(rrs) = &args.rrs {
        settings
            .read_rrs(&scenario, rrs, args.rrs_damping)
            .map_err(cli_error)?;
    }
    let progress = iteration_progress(args);
    let on_run = &mut |k: usize| progress.set_position(k as u64 + 1);
    let p = platen_plan::plan(&scenario, &target, &settings, on_run);
    progress.finish();
    let p = p.map_err(cli_error)?;
    // No drive (the target's own command reaches the end of the actuators): nothing is
    // written; the temporary file goes with the writer.
    let written = p.write_drive_rows(writer).map_err(cli_error)?;
    let summary = p.summary(&settings, written.then_some(args.out.as_path()));
    let value = serde_json::to_value(&summary)?;
    let figures = platen_report::write_outputs(
        args.plot.as_deref(),
        args.report.as_deref(),
        &args.size.size(),
        || planned::figures(&p),
        |figures, rendered| planned::page(&p, value.clone(), figures, rendered),
    )?;
    for warning in summary.warnings() {
        eprintln!("warning: {warning}");
    }
    if args.json {
        let figures = args.plot.as_ref().map(|_| figures.as_slice());
        let value = with_outputs(value, figures, args.report.as_deref());
        outln!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    out!(
        "{}",
        planned::text(
            &summary,
            &figures,
            args.plot.as_deref(),
            args.report.as_deref()
        )
    );
    Ok(())
}

/// The plan's settings of the options (its required spectra read apart).
fn settings(args: &Args) -> PlanSettings {
    PlanSettings {
        iteration: platen_plan::IterationSettings {
            max_iterations: usize::from(args.iterations),
            gain: args.gain,
            target_nrmse: args.target_nrmse,
            band_hz: args.band_hz,
            frf: match args.frf {
                Frf::Auto => FrfSource::Auto,
                Frf::Linearised => FrfSource::Linearised,
                Frf::Measured => FrfSource::Measured(NoiseSettings::default()),
            },
            ..Default::default()
        },
        max_scale: (!args.no_max_scale).then(MaxScaleSettings::default),
        per_axis_max_scale: args.per_axis_scale,
        iterate_at: args.iterate_at,
        ..Default::default()
    }
}

/// The options a multi-axis table's plan does not take (yet).
fn refuse_for_multi_axis(args: &Args) -> Result<()> {
    if let Some(map) = &args.columns {
        anyhow::bail!(
            "--columns {}: a three-component target is read under platen's own names \
             (t_s, x_m_s2, y_m_s2, z_m_s2 or x_m, y_m, z_m, SI units); --columns maps a \
             uniaxial target's",
            map.display()
        );
    }
    if matches!(args.frf, Frf::Measured) {
        anyhow::bail!(
            "--frf measured: a multi-axis table's drives are iterated through its linearised \
             transfer matrix (a measured matrix FRF is not available yet): leave --frf out or \
             give --frf linearised"
        );
    }
    if args.report.is_some() {
        anyhow::bail!(
            "--report: a three-component plan has no HTML report yet; --plot DIR writes its \
             figures and --json every figure the text reports, per axis and per iteration"
        );
    }
    if args.per_axis_scale && args.no_max_scale {
        anyhow::bail!("--per-axis-scale searches scales: it cannot go with --no-max-scale");
    }
    Ok(())
}

/// A bar of the drive iterations (on a terminal, after a second).
fn iteration_progress(args: &Args) -> Progress {
    Progress::new(
        u64::from(args.iterations) + 1,
        "{bar:30} {pos}/{len} runs of the drive iteration, {elapsed_precise} elapsed",
    )
}
