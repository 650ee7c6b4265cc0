//! Shared by the criterion benches: the standard workloads, and the medians that let each
//! bench report its ratio to the plain-loop baseline measured in the same run.
//!
//! Criterion reports each benchmark on its own; the ratio to the baseline is the figure these
//! benches exist for. Every timed routine therefore goes through [`timed`], which records the
//! time per iteration of each criterion sample, and [`report_ratios`] prints, after a group,
//! the median of the last `sample_size` samples (criterion's own sample set after warm-up)
//! of each benchmark next to the baseline's.

#![allow(dead_code, unused_imports)]

/// The plain-loop measuring stick, the one copy `platen bench` times too.
pub use platen_bench::baseline;

use std::collections::BTreeMap;
use std::hint::black_box;
use std::sync::Mutex;
use std::time::Instant;

use criterion::Bencher;

/// Sample rate of every workload, Hz; the RK4 steps once per sample (h = 1/1024 s); and
/// hold-down pressure of every workload, Pa: `platen bench`'s.
pub use platen_bench::{PRESSURE_PA, RATE_HZ};

/// A sine force of `amplitude_n` at 0.5 Hz, sampled at 1024 Hz for `seconds`, from `t = 0`.
///
/// * 100 kN (the workload of `platen bench`, a table test within the LHPOST's limits:
///   ±0.35 m, 1.09 m/s, 0.38 g): the platen breaks away from rest and then slips, reversing
///   directly every half period: no stick phase. (600 kN, the load before issue 18, reached
///   5.3 m, 16 m/s and 5.2 g: far past the table.)
/// * 45 kN, just above the 37.5 kN static threshold: two stick phases per period (≈ 22 % of
///   the time stuck), each with a stop and a breakaway to locate.
pub fn sine_force(amplitude_n: f64, seconds: usize) -> Vec<f64> {
    platen_bench::sine_force_n(amplitude_n, seconds * RATE_HZ as usize + 1)
}

/// Time per iteration (ns) of every call criterion made of each routine, by benchmark name.
static SAMPLES: Mutex<BTreeMap<String, Vec<f64>>> = Mutex::new(BTreeMap::new());

/// Times `routine` for criterion (`iter_custom`, `black_box` on its result) and records the
/// time per iteration of each sample under `name`.
pub fn timed<T>(b: &mut Bencher<'_>, name: &str, mut routine: impl FnMut() -> T) {
    b.iter_custom(|iters| {
        let start = Instant::now();
        for _ in 0..iters {
            black_box(routine());
        }
        let elapsed = start.elapsed();
        let per_iter_ns = elapsed.as_secs_f64() * 1e9 / iters.max(1) as f64;
        SAMPLES
            .lock()
            .expect("bench samples")
            .entry(name.to_owned())
            .or_default()
            .push(per_iter_ns);
        elapsed
    });
}

/// Median time per iteration of the last `sample_size` samples recorded under `name`, ns.
pub fn median_ns(name: &str, sample_size: usize) -> Option<f64> {
    let samples = SAMPLES.lock().expect("bench samples");
    let all = samples.get(name)?;
    let mut last: Vec<f64> = all[all.len().saturating_sub(sample_size)..].to_vec();
    last.sort_by(f64::total_cmp);
    let n = last.len();
    if n == 0 {
        return None;
    }
    Some(if n % 2 == 1 {
        last[n / 2]
    } else {
        0.5 * (last[n / 2 - 1] + last[n / 2])
    })
}

/// Prints, for each `(name, units)` of `rows`, the median time per unit (step or sample) and
/// its ratio to `baseline` (measured in the same run, `baseline_units` units per iteration).
/// Benchmarks filtered out on the command line are skipped.
pub fn report_ratios(
    title: &str,
    sample_size: usize,
    baseline: (&str, u64),
    rows: &[(&str, u64)],
    unit: &str,
) {
    let Some(base) = median_ns(baseline.0, sample_size).map(|t| t / baseline.1 as f64) else {
        return;
    };
    println!("\n{title}: median ns/{unit}, ratio to the plain-loop baseline of this run");
    println!("  {:<48} {:>10.1} {:>8}", baseline.0, base, "1");
    for &(name, units) in rows {
        if let Some(t) = median_ns(name, sample_size) {
            let per = t / units as f64;
            println!("  {:<48} {:>10.1} {:>8.3}", name, per, per / base);
        }
    }
    println!();
}
