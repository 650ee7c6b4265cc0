//! `platen bench`: time the standard workloads on the `lhpost-2008` preset, next to the
//! plain-loop baseline measured in the same run. The workloads, their inputs, the timing and
//! the report are [`platen::bench`]'s; this file parses and prints.

use anyhow::Result;

use platen::bench::{self, RATE_HZ};

/// Runs `platen bench`: `seconds` simulated seconds per record, `repeats` runs of each
/// workload, the report as JSON or as a table.
pub fn run(seconds: f64, repeats: u32, json_out: bool) -> Result<()> {
    let m = bench::measure(seconds, repeats)?;
    if json_out {
        outln!("{}", serde_json::to_string_pretty(&m.report())?);
    } else {
        out!("{}", m.text());
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
