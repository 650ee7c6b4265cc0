//! The text summaries of `platen sweep` (one row per case) and `platen generate` (the file
//! written), and the JSON report of `platen generate`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Serialize;

use platen_model::STANDARD_GRAVITY_M_S2;
use platen_scenario::sweep::{self, Case, Outcome};
use platen_scenario::PlatenScenario;

/// How a sweep ran: the grid's cases, its results and where its outputs went.
pub struct SweepRun<'a> {
    /// The scenario swept.
    pub scenario: &'a PlatenScenario,
    /// The names of the `--set` axes, in the cases' `sets` order.
    pub set_names: &'a [String],
    /// The cases, in grid order.
    pub cases: &'a [Case],
    /// Their outcomes, in the same order.
    pub outcomes: &'a [Outcome],
    /// The CSV written, if any.
    pub out: Option<&'a Path>,
}

/// The text summary of a sweep: a heading, one row per case (its axes' values, then its peaks,
/// stick time and events, and the limits it exceeded, or its failure), the CSV written; then,
/// with `figures` (`Some`: figures were asked for), the figure files written or why none
/// were. It holds nothing that changes from run to run (no wall time, no thread count): the
/// same sweep prints the same bytes.
pub fn sweep_text(run: &SweepRun<'_>, figures: Option<&[PathBuf]>) -> String {
    let mut s = String::new();
    let scenario = run.scenario;
    let _ = writeln!(
        s,
        "{}: {} cases ({} model, {})",
        scenario.name,
        run.cases.len(),
        scenario.rig.model.form(),
        scenario.rig.preset.name(),
    );
    let mut head = format!("  {:>5} {:>8} {:>8}", "case", "scale", "MPa");
    for n in run.set_names {
        let _ = write!(head, " {n:>14}");
    }
    let _ = write!(
        head,
        " {:>9} {:>9} {:>8} {:>10} {:>8} {:>6}  limits exceeded",
        "u (m)", "v (m/s)", "a (g)", "F (kN)", "stick s", "events"
    );
    let _ = writeln!(s, "{head}");
    for (i, (case, o)) in run.cases.iter().zip(run.outcomes).enumerate() {
        let _ = write!(s, "  {i:>5} {:>8} {:>8}", case.scale, case.pressure_mpa);
        for v in &case.sets {
            let _ = write!(s, " {v:>14}");
        }
        if let Some(e) = &o.error {
            let _ = writeln!(s, "  FAILED: {e}");
            continue;
        }
        let (stick, events) = match &o.stats {
            Some(st) => (format!("{:.3}", st.stick_time_s), st.events().to_string()),
            None => ("-".to_owned(), "-".to_owned()),
        };
        let _ = writeln!(
            s,
            " {:>+9.4} {:>+9.4} {:>+8.3} {:>+10.1} {stick:>8} {events:>6}  {}",
            o.peaks.u_m.value,
            o.peaks.v_m_s.value,
            o.peaks.a_m_s2.value / STANDARD_GRAVITY_M_S2,
            o.peaks.force_n.value / 1e3,
            sweep::exceeded(scenario, &o.peaks),
        );
    }
    if let Some(out) = run.out {
        let _ = writeln!(s, "  wrote {}", out.display());
    }
    if let Some(written) = figures {
        if written.is_empty() {
            s.push_str(
                "  no figures: every axis holds one value (give two or more to plot peaks \
                 against it)\n",
            );
        }
        for path in written {
            let _ = writeln!(s, "  wrote {}", path.display());
        }
    }
    s
}

/// What `platen generate` wrote (`--json`; keys in alphabetical order).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GenerateReport {
    /// `force` or `motion` (an excitation), or `recorded` (recorded-like data).
    pub kind: &'static str,
    /// The CSV written.
    pub out: String,
    /// Its rows.
    pub samples: usize,
    /// The noise seed of recorded-like data (`null` for an excitation).
    pub seed: Option<u64>,
}

impl GenerateReport {
    /// The text line: `wrote OUT (N samples)`.
    pub fn text(&self) -> String {
        format!("wrote {} ({} samples)\n", self.out, self.samples)
    }
}

#[cfg(test)]
mod tests {
    use super::GenerateReport;

    /// The report's JSON has the keys `platen generate --json` has always printed, sorted,
    /// and the seed only for recorded-like data.
    #[test]
    fn the_generate_report_prints_sorted_keys_and_a_null_seed_without_one() {
        let mut r = GenerateReport {
            kind: "recorded",
            out: "x.csv".into(),
            samples: 3,
            seed: Some(7),
        };
        assert_eq!(
            serde_json::to_string(&r).unwrap(),
            r#"{"kind":"recorded","out":"x.csv","samples":3,"seed":7}"#
        );
        r.seed = None;
        r.kind = "force";
        assert_eq!(
            serde_json::to_string(&r).unwrap(),
            r#"{"kind":"force","out":"x.csv","samples":3,"seed":null}"#
        );
        assert_eq!(r.text(), "wrote x.csv (3 samples)\n");
    }
}
