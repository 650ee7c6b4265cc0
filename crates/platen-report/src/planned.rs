//! The outputs of any plan ([`platen_plan::Planned`]), whatever the table: its text, its
//! figures and its HTML page, each the uniaxial table's ([`crate::plan_report::text`],
//! [`crate::plan_figures`]) or a multi-axis table's ([`crate::plan_report::table_text`],
//! [`crate::table_plan_figures`]).

use std::path::{Path, PathBuf};

use platen_plan::{Planned, PlannedSummary};

use crate::figure::Figure;
use crate::{plan_figures, plan_report, table_plan_figures};

/// The text summary of the plan `s` (`platen plan` without `--json`), then the figure files
/// `figures` written to `plot_dir` and the HTML `report` written, if any.
pub fn text(
    s: &PlannedSummary,
    figures: &[PathBuf],
    plot_dir: Option<&Path>,
    report: Option<&Path>,
) -> String {
    match s {
        PlannedSummary::Platen(s) => plan_report::text(s, figures, plot_dir, report),
        PlannedSummary::Table(s) => {
            let mut t = plan_report::table_text(s);
            for f in figures {
                t += &format!("wrote {}\n", f.display());
            }
            t
        }
    }
}

/// The figures of the plan `p`.
pub fn figures(p: &Planned) -> Vec<Figure> {
    match p {
        Planned::Platen(p) => plan_figures::figures(p),
        Planned::Table(p) => table_plan_figures::figures(p),
    }
}

/// The `platen plan --report` page of the plan `p` ([`plan_figures::page`]), with its
/// `--json` `summary`; `rendered[i]` is the SVG of `figures[i]`. A multi-axis table's plan has
/// no page yet (empty: `platen plan` refuses `--report` there).
pub fn page(
    p: &Planned,
    summary: serde_json::Value,
    figures: &[Figure],
    rendered: &[(String, String)],
) -> String {
    match p {
        Planned::Platen(p) => plan_figures::page(p, summary, figures, rendered),
        Planned::Table(_) => String::new(),
    }
}
