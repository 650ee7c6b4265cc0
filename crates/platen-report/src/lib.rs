//! Figures (SVG and PNG) and reports (HTML and text) of platen's comparisons and
//! identifications.
//!
//! * [`figure`]: what a figure is (panels of line, point and segment series); [`Figure::to_svg`]
//!   draws it with plotters' SVG backend (no font or C library: text is SVG `<text>`).
//! * [`compare_figures`] and [`identify_figures`] build the figures of a
//!   [`Comparison`](platen_compare::Comparison) and of an
//!   [`Identification`](platen_ident::Identification).
//! * [`run_figures`] builds the figures of a run without a recording (`simulate --plot`),
//!   collected while it runs ([`run_figures::RunRecorder`]), and [`sweep_figures`] the peaks
//!   of a sweep against each of its axes, with the table's limits; a closed-loop run adds
//!   the loop's figures (tracking, valve, pressures, flow, supply).
//! * [`system_figures`] draws the Bode plots of a table system's linearised loop
//!   (`platen model --system … --plot`), on a logarithmic frequency axis
//!   ([`Panel::x_log`]).
//! * [`table_figures`] draws a run of the multi-axis (six-DOF) platen: its pose, the
//!   actuators' strokes and forces against their limits, and the specimen's overturning
//!   moments and base forces.
//! * [`plan_figures`] draws a test plan (`platen plan --plot`, `--report`): target against
//!   achieved acceleration, response spectra, convergence and the limits' margins;
//!   [`table_plan_figures`] a multi-axis table's, per axis; [`planned`] any plan's text,
//!   figures and page, whatever the table.
//! * [`render`] writes them: SVG, PNG copies rendered by resvg with the embedded Noto Sans,
//!   and the HTML page, every file atomically ([`write_outputs`]).
//! * [`identify_report`] writes `platen identify`'s text report and HTML page.
//! * [`simulate_report`], [`plan_report`] and [`sweep_report`] write the text summaries of
//!   `platen simulate`, `plan`, `sweep` and `generate` (and `generate`'s JSON report);
//!   [`bench_report`] `platen bench`'s table.
//! * [`html`] builds self-contained pages; [`text`] the numbers, metric rows and terminal
//!   summary.
//!
//! Output is a pure function of the data: the same input gives the same bytes.
//!
//! # Example
//!
//! ```
//! use std::path::Path;
//! use platen_compare::{Comparison, Settings};
//! use platen_report::{compare_figures, html, render_all};
//!
//! let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/sr9");
//! let c = Comparison::from_files(
//!     &root.join("sr9-forward.json"),
//!     &root.join("sr9-recorded.csv"),
//!     None,
//!     &Settings::default(),
//! )?;
//! let figures = compare_figures::figures(&c);
//! assert_eq!(figures[0].name, "time-history-u_m");
//! let rendered = render_all(&figures)?;
//! let page = html::compare_page(&c, &figures, &rendered);
//! assert!(page.contains("<svg"));
//! print!("{}", platen_report::text::compare_summary(&c, &[], None));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Conventions
//!
//! * **Units**: SI in the data; figures and tables show displacement in m, velocity in m/s
//!   and forces in kN ([`text::display_units`]), residuals of motion in mm and mm/s.
//! * **Residual** = **simulated − recorded**, on the recorded time base.
//! * **Lag** > 0 means the simulation is late.
//! * Colours and strokes: recorded data solid blue ([`figure::RECORDED`]), simulated dashed
//!   orange ([`figure::SIMULATED`]), model laws and fits black ([`figure::MODEL`]), so that
//!   recorded and simulated differ without colour too ([`figure::Dash`]).
//! * Legends sit in a strip above each panel's axes: they never hide data or stretch an axis.

mod axes;
pub mod bench_report;
pub mod compare_figures;
mod error;
pub mod figure;
pub mod html;
pub mod identify_figures;
pub mod identify_report;
pub mod model_text;
pub mod plan_figures;
pub mod plan_report;
pub mod planned;
pub mod record_figures;
pub mod render;
pub mod run_figures;
pub mod series;
pub mod simulate;
pub mod simulate_report;
mod svg;
pub mod sweep_figures;
pub mod sweep_report;
pub mod system_figures;
pub mod system_identify_report;
pub mod table_figures;
pub mod table_plan_figures;
pub mod table_text;
pub mod text;

pub use error::{ReportError, Result};
pub use figure::{Figure, Panel, Series, Style};
pub use render::{render_all, svg_to_png, write_figures, write_outputs, FigureSize};
