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
mod completions;
mod error_json;
mod generate;
mod identify;
mod model;
mod plan;
mod plot;
mod progress;
mod scenarios;
mod schema;
mod simulate;
mod sweep;
mod usage;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
    Simulate(simulate::SimulateArgs),
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
    Compare(compare::CompareArgs),
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
    Model(model::ModelArgs),
    /// Time the standard workloads against a baseline measured in the same run.
    ///
    /// The workloads are forward RK4 on both model forms, Dopri5 and the inverse, on the
    /// lhpost-2008 preset, next to a plain-loop RK4 baseline.
    #[command(after_help = "Examples:\n  \
        platen bench\n  \
        platen bench --seconds 60 --repeats 3 --json")]
    Bench(bench::BenchArgs),
    /// Print the JSON Schema of the scenario format.
    ///
    /// Point an editor at it to get completion and checking while writing scenarios.
    #[command(after_help = "Example:\n  \
        platen schema --out scenario.schema.json")]
    Schema(schema::SchemaArgs),
    /// List the shipped scenarios: path, what each runs, its name.
    ///
    /// Reads the `scenarios` folder of the current directory (a clone of the repository), else
    /// the one platen was built from, or DIR. Scenarios that need a PEER record say so.
    #[command(after_help = "Examples:\n  \
        platen scenarios\n  \
        platen scenarios --json\n  \
        platen scenarios my-lab/scenarios")]
    Scenarios(scenarios::ScenariosArgs),
    /// Print a shell completion script for platen's verbs and options.
    ///
    /// Load it in the shell's startup file, e.g. for bash
    /// `source <(platen completions bash)`, or save it where the shell looks for completions.
    #[command(after_help = "Examples:\n  \
        platen completions bash > ~/.local/share/bash-completion/completions/platen\n  \
        platen completions zsh > ~/.zfunc/_platen\n  \
        platen completions fish > ~/.config/fish/completions/platen.fish")]
    Completions(completions::CompletionsArgs),
    /// Write a scenario's excitation, or recorded-like data for a motion scenario.
    #[command(after_help = "Examples:\n  \
        platen generate excitation scenarios/s9-sine-motion.json --out s9-motion.csv\n  \
        platen generate recorded scenarios/s9-sine-motion.json --seed 3 --out s9-recorded.csv")]
    Generate(generate::GenerateArgs),
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
    Sweep(sweep::SweepArgs),
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
    Identify(identify::IdentifyArgs),
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
            Command::Simulate(args) => args.json,
            Command::Compare(args) => args.json,
            Command::Model(args) => args.json,
            Command::Bench(args) => args.json,
            Command::Generate(args) => args.json,
            Command::Sweep(args) => args.json,
            Command::Identify(args) => args.json,
            Command::Scenarios(args) => args.json,
            Command::Plan(args) => args.json,
            Command::Schema(_) | Command::Completions(_) => false,
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
        Command::Simulate(args) => simulate::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Model(args) => model::run(&args),
        Command::Schema(args) => schema::run(&args),
        Command::Scenarios(args) => scenarios::run(&args),
        Command::Completions(args) => completions::run(&args),
        Command::Generate(args) => generate::run(&args),
        Command::Bench(args) => bench::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Identify(args) => identify::run(&args),
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
            Some(
                ScenarioError::Run(ie)
                | ScenarioError::TableRun(ie)
                | ScenarioError::TableLoopUnstable { source: ie, .. },
            ) => return integrate_exit_code(ie),
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
        IntegrateError::NonFiniteState { .. }
        | IntegrateError::TableNonFiniteState { .. }
        | IntegrateError::EventLoopStalled { .. } => 4,
        _ => 3,
    }
}
