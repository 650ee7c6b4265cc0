//! `platen bench`'s text: the measurement of [`platen_bench::measure`] as a table, one line
//! per workload ([`text`]).

use std::fmt::Write as _;

use platen_bench::{Measurement, FORCE_AMPLITUDE_N, FORCE_FREQUENCY_HZ, PRESSURE_PA, RATE_HZ};

/// The text table of the measurement `m` (`platen bench`), one line per workload in the
/// order they ran.
pub fn text(m: &Measurement) -> String {
    let (simulated_s, base) = (m.simulated_s, m.base_ns());
    let mut s = String::new();
    let _ = writeln!(
        s,
        "platen bench: lhpost-2008 at {} MPa, {simulated_s} s records at {RATE_HZ} Hz from rest, \
         median of {} runs",
        PRESSURE_PA / 1e6,
        m.repeats
    );
    let _ = writeln!(
        s,
        "  forward workloads: a {} kN, {FORCE_FREQUENCY_HZ} Hz sine force, a table test within the \
         LHPOST's limits (±0.35 m, 1.09 m/s, 0.38 g), one reversal per second",
        FORCE_AMPLITUDE_N / 1e3
    );
    let _ = writeln!(
        s,
        "  {:<54} {:>14} {:>10} {:>10} {:>12} {:>6}",
        "workload", "unit", "ns/unit", "units/s", "sim s/wall s", "ratio"
    );
    for w in &m.workloads {
        let ratio = if w.unit == "step" {
            format!("{:.3}", w.ns_per_unit() / base)
        } else {
            "-".to_owned()
        };
        let _ = writeln!(
            s,
            "  {:<54} {:>14} {:>10.1} {:>10.3e} {:>12.0} {:>6}",
            w.title,
            w.unit,
            w.ns_per_unit(),
            w.units as f64 / w.median_s(),
            simulated_s / w.median_s(),
            ratio
        );
    }
    s.push_str("  ratio: ns/step over the baseline's, measured in the same run\n");
    s
}

#[cfg(test)]
mod tests {
    /// Three header lines, one per workload, one footnote.
    #[test]
    fn one_line_per_workload() {
        let m = platen_bench::measure(4.0 / platen_bench::RATE_HZ, 1).unwrap();
        let t = super::text(&m);
        assert_eq!(t.lines().count(), 3 + m.workloads.len() + 1);
        assert_eq!(m.workloads.len(), 11);
    }
}
