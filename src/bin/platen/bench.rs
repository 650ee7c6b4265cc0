//! `platen bench`: time the standard workloads on the `lhpost-2008` preset, next to the
//! plain-loop baseline measured in the same run. The workloads, their inputs, the timing and
//! the report are [`platen_bench`]'s, its text [`platen_report::bench_report`]'s; this file
//! parses and prints.

use anyhow::Result;

use platen_bench::{self as bench, RATE_HZ};

/// The arguments of `platen bench`.
#[derive(clap::Args)]
pub struct BenchArgs {
    /// Print a machine-readable summary on stdout (keys rk4_ns_per_step, …).
    #[arg(long)]
    pub json: bool,
    /// Simulated seconds of every workload's 1024 Hz record.
    #[arg(long, default_value_t = 600.0, value_parser = parse_seconds)]
    seconds: f64,
    /// Runs of each workload (round-robin); the median is reported.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    repeats: u32,
}

/// Runs `platen bench`: `--seconds` simulated seconds per record, `--repeats` runs of each
/// workload, the report as JSON or as a table.
pub fn run(args: &BenchArgs) -> Result<()> {
    let m = bench::measure(args.seconds, args.repeats)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&m.report())?);
    } else {
        out!("{}", platen_report::bench_report::text(&m));
    }
    Ok(())
}

/// `--seconds`: a finite number of simulated seconds, at least 2/1024 and at most 1e6.
pub fn parse_seconds(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of seconds"))?;
    if v.is_finite() && (2.0 / RATE_HZ..=1e6).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{v} s: expected a duration from {} s to 1e6 s",
            2.0 / RATE_HZ
        ))
    }
}
