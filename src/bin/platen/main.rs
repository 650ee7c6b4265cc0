//! `platen`: simulate, inspect and (later) identify the mechanics of a shake-table platen.
//!
//! Exit codes: 0 success, 2 usage error, 3 input error (a file, scenario or parameter that
//! cannot be used), 4 numerical failure, 5 I/O error while writing output.
//!
//! Errors go to stderr as `error: MESSAGE`; with `--json`, as one JSON object instead (see
//! [`error_json`]).

#![recursion_limit = "256"]

/// `println!` for the verbs' standard output that returns an error instead of panicking when
/// the output cannot be written (a reader that closed the pipe: `platen model | head -1`).
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*).map_err(crate::stdout_error)?;
    }};
}

/// `print!` for the verbs' standard output: see [`outln!`].
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*).map_err(crate::stdout_error)?;
    }};
}

mod bench;
mod compare;
mod error_json;
mod generate;
mod identify;
mod model;
mod plan;
mod plot;
mod progress;
mod schema;
mod simulate;
mod sweep;
mod usage;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use platen_compare::CompareError;
use platen_integrate::IntegrateError;
use platen_io::IoError;
use platen_report::ReportError;
use platen_scenario::ScenarioError;

#[derive(Parser)]
#[command(
    name = "platen",
    version,
    about = "Mechanics of a large shake-table platen (NEES-UCSD LHPOST model)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario: forward (force → motion), inverse (motion → force) or closed loop.
    ///
    /// A scenario with a table_system runs the closed loop: its motion is the displacement
    /// command of the controller, whose valves and actuators make the force.
    #[command(after_help = "Examples:\n  \
        platen simulate scenarios/paper-forward-force.json --out forward.csv\n  \
        platen simulate scenarios/s9-sine-motion.json --json\n  \
        platen simulate scenarios/table-system/wn10g-closed-loop.json --plot closed-loop")]
    Simulate {
        /// Scenario JSON file.
        scenario: PathBuf,
        /// Write the time series (t_s, u_m, v_m_s, a_m_s2, force_n, inertial_force_n,
        /// elastic_force_n, dissipative_force_n; then a specimen's and a closed loop's
        /// columns) to this CSV file; a name ending in .parquet writes Parquet instead (the
        /// same columns, float64, one row per sample).
        #[arg(long, value_parser = usage::OutFile("run.csv"))]
        out: Option<PathBuf>,
        /// Print a machine-readable summary on stdout.
        #[arg(long)]
        json: bool,
        /// Write the run's figures to this folder as SVG and PNG: motion and actuator force
        /// over time (with the table's limits near a peak), the force decomposition
        /// F_A = F_I + F_E + F_D, hysteresis loops of F_A against u, v and a; for a closed
        /// loop also command against achieved motion, tracking error, drive and spool,
        /// pressure difference, flow against the valves' capacity, supply pressure.
        #[arg(long, value_name = "DIR")]
        plot: Option<PathBuf>,
        #[command(flatten)]
        size: plot::SizeArgs,
        /// Run at this hold-down pressure, MPa, instead of the scenario's (the model rebuilt
        /// from its preset at P with the scenario's overrides, as `sweep --pressure-mpa`).
        #[arg(long, value_name = "P", allow_negative_numbers = true, value_parser = sweep::parse_pressure_mpa)]
        pressure_mpa: Option<f64>,
    },
    /// Run a scenario and compare it with a recorded test, channel by channel.
    ///
    /// Forward scenarios compare the displacement u_m and velocity v_m_s, inverse scenarios
    /// the actuator force force_n, on the recorded time base. Per channel: RMS error, NRMSE
    /// (normalised by the recorded RMS), signed peaks and their ratio, correlation and lag by
    /// cross-correlation.
    #[command(after_help = "Examples:\n  \
        platen compare scenarios/sr9/sr9-forward.json --recorded scenarios/sr9/sr9-recorded.csv\n  \
        platen compare scenarios/sr9/sr9-forward.json --recorded scenarios/sr9/sr9-recorded.csv \\\n      \
        --plot figures --report sr9.html")]
    Compare {
        /// Scenario JSON file.
        scenario: PathBuf,
        /// Recorded CSV file (t_s and u_m, v_m_s for a forward run, force_n for an inverse
        /// one; a_m_s2 and the other columns are used by the figures where present). It must
        /// be uniformly sampled and cover the scenario's time span.
        #[arg(long, value_name = "REC.csv")]
        recorded: PathBuf,
        /// Print the metrics as JSON (one object per channel: u_m, v_m_s or force_n).
        #[arg(long)]
        json: bool,
        /// Write the figures to this folder as SVG and PNG (time histories with a zoom, residuals,
        /// hysteresis loops, dissipative force against velocity with the model's law).
        #[arg(long, value_name = "DIR")]
        plot: Option<PathBuf>,
        /// Compute the metrics over this time window only, s (also the zoomed interval).
        #[arg(long, value_name = "T0,T1", allow_hyphen_values = true, value_parser = compare::parse_window)]
        window: Option<compare::Window>,
        /// Write a self-contained HTML report (metrics table and figures) to this file.
        #[arg(long, value_name = "FILE.html", value_parser = usage::OutFile("report.html"))]
        report: Option<PathBuf>,
        /// JSON file mapping the record's channel names and units to platen's columns, as a
        /// scenario's excitation.columns: {"u_m": {"name": "Table disp", "unit": "mm"}, …}.
        #[arg(long, value_name = "MAP.json")]
        columns: Option<PathBuf>,
        /// Largest lag searched by cross-correlation, either way, s.
        #[arg(long, value_name = "S", default_value_t = 0.25, value_parser = compare::parse_max_lag)]
        max_lag: f64,
        #[command(flatten)]
        size: plot::SizeArgs,
    },
    /// Print a preset's parameters and derived quantities, and a table system's.
    ///
    /// The text groups the simulated model's parameters, the quantities derived from the full
    /// model (Eq. 5–8), the physical parameters and the table's limits, in engineering units;
    /// --json prints the same in SI under the contract's keys.
    ///
    /// With a table system (--system, or a --scenario with a table_system) it adds, under
    /// `table_system` in --json: the system's parameters; the oil-column frequency at
    /// mid-stroke with the model's mass (oil_column_frequency_hz), with the specimen as a
    /// rigid payload, and at both ends of the stroke; the valve-limited velocities and the
    /// valves' flow capacity; the push and pull force capacities; the linearisation about
    /// mid-stroke (flow gains, compliances, mechanics); the linearised loop's margins, peak
    /// and bandwidth; and the default RK4 steps per controller period of a closed-loop run.
    #[command(after_help = "Examples:\n  \
        platen model\n  \
        platen model --form full --pressure-mpa 6.9 --json\n  \
        platen model --system lhpost-2008 --plot bode\n  \
        platen model --scenario scenarios/table-system/northridge-closed-loop.json --json")]
    Model {
        /// Preset name.
        #[arg(long, default_value = "lhpost-2008")]
        preset: String,
        /// Hold-down nitrogen pressure, MPa (default: the preset's nominal pressure).
        #[arg(long)]
        pressure_mpa: Option<f64>,
        /// Which form to describe.
        #[arg(long, value_enum, default_value_t = Form::Identified)]
        form: Form,
        /// Describe this table system too (a table-system preset: lhpost-2008); with
        /// --scenario it replaces the scenario's table_system.
        #[arg(long, value_name = "PRESET")]
        system: Option<String>,
        /// Describe the model, table_system and specimen of this scenario (its model
        /// preset, pressure, form and values; its excitation, integrator, initial state and
        /// duration are not read).
        #[arg(
            long,
            value_name = "FILE",
            conflicts_with_all = ["preset", "pressure_mpa", "form"]
        )]
        scenario: Option<PathBuf>,
        /// Print JSON on stdout.
        #[arg(long)]
        json: bool,
        /// Write the Bode plots of the linearised loop to this folder as SVG and PNG: the
        /// closed loop command → displacement (bode-closed-loop) and the loop gain L broken
        /// at the drive (bode-loop-gain), magnitude and phase, 0.1 Hz to the controller's
        /// Nyquist frequency or 200 Hz. Needs a table system (--system or --scenario).
        #[arg(long, value_name = "DIR")]
        plot: Option<PathBuf>,
        #[command(flatten)]
        size: plot::SizeArgs,
    },
    /// Time the standard workloads against a baseline measured in the same run.
    ///
    /// The workloads are forward RK4 on both model forms, Dopri5 and the inverse, on the
    /// lhpost-2008 preset, next to a plain-loop RK4 baseline.
    #[command(after_help = "Examples:\n  \
        platen bench\n  \
        platen bench --seconds 60 --repeats 3 --json")]
    Bench {
        /// Print a machine-readable summary on stdout (keys rk4_ns_per_step, …).
        #[arg(long)]
        json: bool,
        /// Simulated seconds of every workload's 1024 Hz record.
        #[arg(long, default_value_t = 600.0, value_parser = bench::parse_seconds)]
        seconds: f64,
        /// Runs of each workload (round-robin); the median is reported.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
        repeats: u32,
    },
    /// Print the JSON Schema of the scenario format.
    ///
    /// Point an editor at it to get completion and checking while writing scenarios.
    #[command(after_help = "Example:\n  \
        platen schema --out scenario.schema.json")]
    Schema {
        /// Write the schema to this file instead of standard output.
        #[arg(long, value_parser = usage::OutFile("scenario.schema.json"))]
        out: Option<PathBuf>,
    },
    /// List the shipped scenarios: path, what each runs, its name.
    ///
    /// Reads the `scenarios` folder of the current directory (a clone of the repository), else
    /// the one platen was built from, or DIR. Scenarios that need a PEER record say so.
    #[command(after_help = "Examples:\n  \
        platen scenarios\n  \
        platen scenarios --json\n  \
        platen scenarios my-lab/scenarios")]
    Scenarios {
        /// The folder to list (default: ./scenarios, else the one platen was built from).
        dir: Option<PathBuf>,
        /// Print the list as JSON: [{path, name, kind, needs_record, specimen}, …].
        #[arg(long)]
        json: bool,
    },
    /// Print a shell completion script for platen's verbs and options.
    ///
    /// Load it in the shell's startup file, e.g. for bash
    /// `source <(platen completions bash)`, or save it where the shell looks for completions.
    #[command(after_help = "Examples:\n  \
        platen completions bash > ~/.local/share/bash-completion/completions/platen\n  \
        platen completions zsh > ~/.zfunc/_platen\n  \
        platen completions fish > ~/.config/fish/completions/platen.fish")]
    Completions {
        /// The shell: bash, zsh, fish, elvish or powershell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Write a scenario's excitation, or recorded-like data for a motion scenario.
    #[command(after_help = "Examples:\n  \
        platen generate excitation scenarios/s9-sine-motion.json --out s9-motion.csv\n  \
        platen generate recorded scenarios/s9-sine-motion.json --seed 3 --out s9-recorded.csv")]
    Generate {
        /// What to write.
        #[arg(value_enum)]
        what: generate::What,
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
        json: bool,
    },
    /// Run a grid of variants of a scenario in parallel, one summary row per case.
    ///
    /// The cases are the Cartesian product of the axes given (scale outermost, then pressure,
    /// then each --set in order, the last varying fastest); an axis not given holds the
    /// scenario's own value. Cases run in parallel on every core (RAYON_NUM_THREADS sets the
    /// number of threads; the output is the same whatever it is), with a progress bar on
    /// stderr when it is a terminal and CI is unset. Each row: case, scale,
    /// hold_down_pressure_mpa, one column per --set, peak_u_m, peak_v_m_s, peak_a_m_s2,
    /// peak_force_n (signed), stick_time_s, events, limits_exceeded, status.
    #[command(after_help = "Examples:\n  \
        platen sweep scenarios/paper-forward-force.json --scale 0.5,1,1.5 --pressure-mpa 0,6.9,13.8\n  \
        platen sweep scenarios/paper-forward-force.json --set identified.coulomb_force_n=20e3,25e3 \\\n      \
        --out cases.csv")]
    Sweep {
        /// Scenario JSON file.
        scenario: PathBuf,
        /// Factors multiplying the excitation (the force record, or the prescribed motion),
        /// comma separated: --scale 0.5,1,1.5.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = sweep::parse_scale)]
        scale: Vec<f64>,
        /// Hold-down nitrogen pressures, MPa, comma separated: --pressure-mpa 0,6.9,13.8.
        #[arg(long, value_delimiter = ',', allow_negative_numbers = true, value_parser = sweep::parse_pressure_mpa)]
        pressure_mpa: Vec<f64>,
        /// A model parameter and its values, repeatable: --set identified.coulomb_force_n=20e3,25e3
        /// or --set full.platen_mass_kg=130e3,140e3 (the scenario's form: identified or full).
        #[arg(long = "set", value_name = "FORM.NAME=V1,V2,…", value_parser = sweep::parse_set)]
        set: Vec<sweep::SetAxis>,
        /// Write one row per case to this CSV file (written atomically when all cases are done).
        #[arg(long, value_parser = usage::OutFile("cases.csv"))]
        out: Option<PathBuf>,
        /// Print a machine-readable summary of every case on stdout.
        #[arg(long)]
        json: bool,
        /// Write figures to this folder as SVG and PNG: for each axis with two or more
        /// values, the peaks of every case against it with the table's limits.
        #[arg(long, value_name = "DIR")]
        plot: Option<PathBuf>,
        #[command(flatten)]
        size: plot::SizeArgs,
    },
    /// Identify the platen's parameters from test records.
    ///
    /// Periodic sine and triangle tests go to the paper's hysteresis-loop method (§3, with a
    /// global fit of Eq. 23 as a cross-check), any other record (earthquake, white noise) to
    /// the any-record method (equation error by separable least squares, output-error check,
    /// standard errors robust to correlated residuals, the dissipative law with its 95 %
    /// band).
    ///
    /// Each FILE is a recorded CSV with t_s, u_m, a_m_s2, force_n and optionally v_m_s
    /// (otherwise the crossover estimate is made). Which method a file goes to, and sine or
    /// triangle, is recognised from the data; file names play no part.
    #[command(after_help = "Examples:\n  \
        platen identify T1.csv T2.csv S4.csv S5.csv --pressure-mpa 13.8\n  \
        platen identify --manifest tests.json --plot figures --report identify.html")]
    Identify {
        /// Recorded test CSV files.
        #[arg(required_unless_present = "manifest")]
        files: Vec<PathBuf>,
        /// Hold-down pressure, MPa: one value for every file (and for manifest entries without
        /// one), or one per FILE in order (comma separated). Tests without a pressure form
        /// their own group.
        #[arg(long, value_delimiter = ',', allow_negative_numbers = true, value_parser = identify::parse_pressure_mpa)]
        pressure_mpa: Vec<f64>,
        /// JSON manifest: {"tests": [{"file": PATH, "kind": "sine"|"triangle"|"record",
        /// "pressure_mpa": P, "name": NAME, "columns": MAP, "floors": [{"column": NAME,
        /// "unit": UNIT, "mass_kg": M}]}], "columns": MAP, "floors": FLOORS}, paths relative
        /// to the manifest; floors are a specimen's accelerometers whose base shear Σ mᵢ·aᵢ is
        /// taken off the force.
        #[arg(long)]
        manifest: Option<PathBuf>,
        /// Hold the viscous exponent α at this value (Eq. 21: 0.5) instead of fitting it.
        #[arg(long, value_parser = identify::parse_exponent)]
        viscous_exponent: Option<f64>,
        /// Do not fit the low-velocity term a·e^(−b|v|) (set it to zero).
        #[arg(long)]
        no_low_velocity_term: bool,
        /// Print the seven identified keys, their uncertainties and the per-test tables as
        /// JSON on stdout.
        #[arg(long)]
        json: bool,
        /// Write the identification figures to this folder as SVG and PNG: per-test Kₑ and
        /// Mₑ with confidence intervals (Tables I, II), elastic force against displacement,
        /// inertial force against acceleration, dissipative force against velocity with the
        /// fitted law (Fig. 7), Coulomb force against vertical load (Fig. 8).
        #[arg(long, value_name = "DIR")]
        plot: Option<PathBuf>,
        /// Write a self-contained HTML report (parameters, per-test tables, figures) to this
        /// file.
        #[arg(long, value_name = "FILE.html", value_parser = usage::OutFile("report.html"))]
        report: Option<PathBuf>,
        /// JSON file mapping the files' channel names and units to platen's columns, as a
        /// scenario's excitation.columns: {"u_m": {"name": "Table disp", "unit": "mm"}, …}
        /// (a manifest's own `columns` win).
        #[arg(long, value_name = "MAP.json")]
        columns: Option<PathBuf>,
        /// Force the method: `periodic` (the paper's wherever the data are periodic; a file
        /// that is not, or that the paper's method rejects, falls back to the any-record
        /// method with its reason), `record` (the any-record method on every file, fitted
        /// jointly) or `both` (periodic tests through both). Default: periodic tests (regular
        /// cycles of one shape) to the paper's method, any other record (earthquake, white
        /// noise) to the any-record method. Every file is listed with what was done with it.
        #[arg(long, value_enum)]
        method: Option<identify::MethodChoice>,
        /// Skip the any-record method's output-error check (forward simulation fitted to the
        /// measured motion).
        #[arg(long)]
        no_output_error: bool,
        /// Hold the any-record method's stiffness at Kₑ ≥ 0 (a table without a restoring
        /// stiffness of its own); a warning says when the bound is active.
        #[arg(long)]
        nonnegative_stiffness: bool,
        /// Identify the table's whole loop from closed-loop records instead (t_s,
        /// command_u_m, u_m, drive and, as tables record them, delta_p_pa or
        /// cap_pressure_pa and rod_pressure_pa, a_m_s2, storey{i}_a_m_s2): the controller's
        /// gains, the platen, the specimen, the valves and the oil column. The last of two or
        /// more FILEs is held out: the identified loop runs on every record's command and is
        /// judged against a linear black box and perfect tracking (--plot draws it). With
        /// --json, a runnable scenario that is the identified table, each value's provenance.
        #[arg(long, conflicts_with_all = ["manifest", "pressure_mpa", "report", "method"])]
        system: bool,
        /// With --system: the table's geometry from its drawings (actuator count and areas,
        /// valve count and rated drop, supply and return pressures, bulk modulus), as a
        /// scenario with a table_system or a table_system object (e.g. {"preset":
        /// "lhpost-2008", "actuator": {…}}). Without it the plant is identified in ratios to
        /// the actuator area, laid on --area-m2 or a nominal area (listed as assumed).
        #[arg(long, value_name = "FILE.json", requires = "system")]
        base: Option<PathBuf>,
        /// With --system and without --base: the actuator's area, m², when it is known
        /// without the rest of the drawings (the plant's absolute scale).
        #[arg(long, value_name = "M2", requires = "system", conflicts_with = "base")]
        area_m2: Option<f64>,
        #[command(flatten)]
        size: plot::SizeArgs,
    },
    /// Plan a test: feasibility, largest scale, and the drive that reproduces a target.
    ///
    /// The target's own command (an acceleration integrated with a baseline treatment that
    /// starts and ends at rest, or a displacement) runs through the scenario's closed loop
    /// (model, table_system, specimen): peaks and margins of stroke, velocity, acceleration,
    /// actuator force, valve flow and supply pressure; the limits that fail; the largest scale
    /// that fits, by bisection on the simulated loop. Then offline drive iteration
    /// D ← D + g·Ĥ⁻¹(T − R) in the frequency domain, with the acceleration NRMSE, the
    /// displacement NRMSE and the 5 %-damped response-spectrum error (0.05–2 s) per
    /// iteration. An infeasible target is an answer (exit 0). See docs/planning.md.
    #[command(after_help = "Examples:\n  \
        platen plan scenarios/table-system/northridge-closed-loop.json --target target.csv --out drive.csv\n  \
        platen plan scenario.json --target target.csv --out drive.csv --frf measured --iterations 15 --json")]
    Plan(plan::Args),
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Form {
    /// The identified model of Eq. 22/23.
    Identified,
    /// The full Lagrangian model of Eq. 1–8.
    Full,
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse().map_err(usage::spaced_list) {
        Ok(cli) => cli,
        // With --json a usage error is a JSON error object too; help and version print as
        // usual.
        Err(e) if e.use_stderr() && std::env::args_os().any(|a| a == "--json") => {
            let rendered = e.to_string();
            let message = rendered
                .lines()
                .take_while(|l| !l.starts_with("Usage:"))
                .map(str::trim)
                .filter(|l| !l.is_empty())
                .collect::<Vec<_>>()
                .join(" ");
            let message = message.strip_prefix("error: ").unwrap_or(&message);
            eprintln!("{}", error_json::usage(message));
            return ExitCode::from(2);
        }
        Err(e) => e.exit(),
    };
    let json = cli.command.wants_json();
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of standard output went away (`| head`): stop quietly, as filters do.
        Err(e) if e.chain().any(|c| c.is::<ClosedPipe>()) => ExitCode::SUCCESS,
        Err(e) => {
            let code = exit_code(&e);
            if json {
                eprintln!("{}", error_json::object(&e, code));
            } else {
                eprintln!("error: {e:#}");
            }
            ExitCode::from(code)
        }
    }
}

impl Command {
    /// Whether the verb was asked for machine-readable output (`--json`).
    fn wants_json(&self) -> bool {
        match self {
            Command::Simulate { json, .. }
            | Command::Compare { json, .. }
            | Command::Model { json, .. }
            | Command::Bench { json, .. }
            | Command::Generate { json, .. }
            | Command::Sweep { json, .. }
            | Command::Identify { json, .. }
            | Command::Scenarios { json, .. } => *json,
            Command::Plan(args) => args.json,
            Command::Schema { .. } | Command::Completions { .. } => false,
        }
    }
}

/// Standard output was closed by its reader.
#[derive(Debug)]
struct ClosedPipe;

impl std::fmt::Display for ClosedPipe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("standard output was closed by its reader")
    }
}

impl std::error::Error for ClosedPipe {}

/// Standard output could not be written (a full disk behind a redirection, say).
#[derive(Debug)]
struct StdoutFailed(std::io::Error);

impl std::fmt::Display for StdoutFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "writing to standard output: {}", self.0)
    }
}

impl std::error::Error for StdoutFailed {}

/// The error of a failed write to standard output: [`ClosedPipe`] for a closed pipe (exit 0),
/// otherwise [`StdoutFailed`] (exit 5, an output that could not be written).
fn stdout_error(e: std::io::Error) -> anyhow::Error {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        anyhow::Error::new(ClosedPipe)
    } else {
        anyhow::Error::new(StdoutFailed(e))
    }
}

/// Runs one verb.
fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Simulate {
            scenario,
            out,
            json,
            plot,
            size,
            pressure_mpa,
        } => simulate::run(&simulate::Options {
            scenario: &scenario,
            out: out.as_deref(),
            json,
            plot: plot.as_deref(),
            size: size.size(),
            pressure_mpa,
        }),
        Command::Compare {
            scenario,
            recorded,
            json,
            plot,
            window,
            report,
            columns,
            max_lag,
            size,
        } => compare::run(&compare::Options {
            scenario: &scenario,
            recorded: &recorded,
            json,
            plot: plot.as_deref(),
            window,
            report: report.as_deref(),
            columns: columns.as_deref(),
            max_lag_s: max_lag,
            size: size.size(),
        }),
        Command::Model {
            preset,
            pressure_mpa,
            form,
            system,
            scenario,
            json,
            plot,
            size,
        } => model::run(&model::Options {
            preset: &preset,
            pressure_mpa,
            form,
            system: system.as_deref(),
            scenario: scenario.as_deref(),
            json,
            plot: plot.as_deref(),
            size: size.size(),
        }),
        Command::Schema { out } => schema::run(out.as_deref()),
        Command::Scenarios { dir, json } => scenarios(dir, json),
        Command::Completions { shell } => {
            let mut command = <Cli as clap::CommandFactory>::command();
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut command, "platen", &mut script);
            out!("{}", String::from_utf8_lossy(&script));
            Ok(())
        }
        Command::Generate {
            what,
            scenario,
            out,
            seed,
            json,
        } => generate::run(what, &scenario, &out, seed, json),
        Command::Bench {
            json,
            seconds,
            repeats,
        } => bench::run(seconds, repeats, json),
        Command::Sweep {
            scenario,
            scale,
            pressure_mpa,
            set,
            out,
            json,
            plot,
            size,
        } => sweep::run(
            &scenario,
            &scale,
            &pressure_mpa,
            &set,
            out.as_deref(),
            json,
            &sweep::Plot {
                dir: plot.as_deref(),
                size: size.size(),
            },
        ),
        Command::Identify {
            files,
            columns,
            json,
            system: true,
            base,
            area_m2,
            plot,
            size,
            ..
        } => identify::run_system(
            &files,
            &identify::SystemOptions {
                columns: columns.as_deref(),
                base: base.as_deref(),
                area_m2,
                json,
                plot: plot.as_deref(),
                size: size.size(),
            },
        ),
        Command::Identify {
            files,
            pressure_mpa,
            manifest,
            viscous_exponent,
            no_low_velocity_term,
            json,
            plot,
            report,
            columns,
            method,
            no_output_error,
            nonnegative_stiffness,
            system: _,
            base: _,
            area_m2: _,
            size,
        } => identify::run(&identify::Options {
            files: &files,
            pressure_mpa: &pressure_mpa,
            manifest: manifest.as_deref(),
            viscous_exponent,
            no_low_velocity_term,
            json,
            plot: plot.as_deref(),
            report: report.as_deref(),
            columns: columns.as_deref(),
            method,
            no_output_error,
            nonnegative_stiffness,
            size: size.size(),
        }),
        Command::Plan(args) => plan::run(&args),
    }
}

/// Maps an error chain to the documented exit codes. Transparent wrappers (a comparison's
/// scenario error, a report's write error) hide the inner error from `chain()`, so they are
/// unwrapped here.
fn exit_code(e: &anyhow::Error) -> u8 {
    for cause in e.chain() {
        if cause.is::<StdoutFailed>() {
            return 5;
        }
        if let Some(ie) = cause.downcast_ref::<IntegrateError>() {
            return integrate_exit_code(ie);
        }
        let scenario = match cause.downcast_ref::<CompareError>() {
            Some(CompareError::Scenario(se)) => Some(se),
            _ => cause.downcast_ref::<ScenarioError>(),
        };
        match scenario {
            Some(ScenarioError::Run(ie)) => return integrate_exit_code(ie),
            Some(ScenarioError::Io(io)) => return io_exit_code(io),
            Some(_) => return 3,
            None => {}
        }
        let io = match (
            cause.downcast_ref::<ReportError>(),
            cause.downcast_ref::<CompareError>(),
        ) {
            (Some(ReportError::Write(io)), _) | (_, Some(CompareError::Io(io))) => Some(io),
            _ => cause.downcast_ref::<IoError>(),
        };
        if let Some(io) = io {
            return io_exit_code(io);
        }
    }
    3
}

/// 5 for an output that could not be written, 3 for an input that could not be read.
fn io_exit_code(e: &IoError) -> u8 {
    if e.is_output_failure() {
        5
    } else {
        3
    }
}

/// 4 for a numerical failure, 3 for an input the integrator cannot use.
fn integrate_exit_code(e: &IntegrateError) -> u8 {
    match e {
        IntegrateError::NonFiniteState { .. } | IntegrateError::EventLoopStalled { .. } => 4,
        _ => 3,
    }
}

/// `platen scenarios`: the shipped scenarios ([`platen_scenario::catalog`]).
fn scenarios(dir: Option<PathBuf>, json: bool) -> anyhow::Result<()> {
    use platen_scenario::catalog::{shipped, RunKind};
    let dir = match dir {
        Some(d) => d,
        None => {
            let here = PathBuf::from("scenarios");
            let built = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios");
            if here.is_dir() {
                here
            } else if built.is_dir() {
                built
            } else {
                anyhow::bail!(
                    "no scenarios folder here (./scenarios) nor where platen was built ({}): give one, `platen scenarios DIR`, or run from a clone of the repository",
                    built.display()
                )
            }
        }
    };
    if !dir.is_dir() {
        anyhow::bail!(
            "`{}` is not a folder: expected a folder of scenario files",
            dir.display()
        );
    }
    let list = shipped(&dir)?;
    if json {
        outln!("{}", serde_json::to_string_pretty(&list)?);
        return Ok(());
    }
    outln!("Scenarios in {}:", dir.display());
    let w = list
        .iter()
        .map(|s| s.path.chars().count())
        .max()
        .unwrap_or(0);
    for s in &list {
        let kind = match s.kind {
            RunKind::Forward => "forward",
            RunKind::Inverse => "inverse",
            RunKind::ClosedLoop => "closed loop",
            RunKind::Group => "folder",
        };
        let mut notes = Vec::new();
        if s.specimen {
            notes.push("specimen");
        }
        if s.needs_record {
            notes.push("needs a PEER record");
        }
        let notes = if notes.is_empty() {
            String::new()
        } else {
            format!(" ({})", notes.join(", "))
        };
        outln!("  {:<w$}  {:<11}  {}{notes}", s.path, kind, s.name);
    }
    outln!(
        "Run one: platen simulate {}/<path> --out out/run.csv",
        dir.display()
    );
    Ok(())
}
