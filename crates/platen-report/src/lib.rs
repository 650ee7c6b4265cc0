//! Figures (SVG and PNG) and reports (HTML and text) of platen's comparisons and
//! identifications.
//!
//! * [`figure`]: what a figure is (panels of line, point and segment series); [`Figure::to_svg`]
//!   draws it with plotters' SVG backend (no font or C library: text is SVG `<text>`).
//! * [`compare_figures`] and [`identify_figures`] build the figures of a
//!   [`Comparison`](platen_compare::Comparison) and of an
//!   [`Identification`](platen_ident::Identification).
//! * [`render`] writes them: SVG, PNG copies rendered by resvg with the embedded Noto Sans,
//!   and the HTML page, every file atomically ([`write_outputs`]).
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
//! * Colours: recorded data blue ([`figure::RECORDED`]), simulated orange
//!   ([`figure::SIMULATED`]), model laws and fits black ([`figure::MODEL`]).

mod axes;
pub mod compare_figures;
mod error;
pub mod figure;
pub mod html;
pub mod identify_figures;
pub mod record_figures;
pub mod render;
pub mod series;
mod svg;
pub mod text;

pub use error::{ReportError, Result};
pub use figure::{Figure, Panel, Series, Style};
pub use render::{render_all, svg_to_png, write_figures, write_outputs};
