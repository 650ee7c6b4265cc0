//! Helpers shared by the CLI's tests: run the binary, read an SVG as XML and tally its series.

#![allow(dead_code)]

pub mod docs;

use std::collections::BTreeMap;
use std::fs;
use std::path::Path;
use std::process::{Command, Output};

/// Runs the `platen` binary this test run built with `args`.
pub fn platen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_platen"))
        .args(args)
        .output()
        .expect("run platen")
}

/// A run's standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// What one SVG holds: polylines by stroke colour, circles by fill colour, all text.
pub struct SvgContent {
    pub width: u32,
    pub height: u32,
    pub polylines: BTreeMap<String, usize>,
    pub circles: BTreeMap<String, usize>,
    pub text: String,
}

/// The stroke of axes and tick marks (not a data series).
const AXIS_STROKE: &str = "#5A5A5A";

/// Parses `path` as XML (it must be a well-formed SVG document) and tallies its elements.
pub fn svg_content(path: &Path) -> SvgContent {
    let text = fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text)
        .unwrap_or_else(|e| panic!("{} is not well-formed XML: {e}", path.display()));
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "svg", "{}", path.display());
    assert_eq!(
        root.tag_name().namespace(),
        Some("http://www.w3.org/2000/svg")
    );
    assert!(root.attribute("viewBox").is_some());
    let mut content = SvgContent {
        width: root.attribute("width").unwrap().parse().unwrap(),
        height: root.attribute("height").unwrap().parse().unwrap(),
        polylines: BTreeMap::new(),
        circles: BTreeMap::new(),
        text: String::new(),
    };
    for node in root.descendants().filter(|n| n.is_element()) {
        match node.tag_name().name() {
            "polyline" => {
                let stroke = node.attribute("stroke").unwrap_or("none").to_owned();
                if stroke != AXIS_STROKE {
                    *content.polylines.entry(stroke).or_default() += 1;
                }
            }
            "circle" => {
                let fill = node.attribute("fill").unwrap_or("none").to_owned();
                *content.circles.entry(fill).or_default() += 1;
            }
            "text" => {
                content
                    .text
                    .push_str(node.text().unwrap_or_default().trim());
                content.text.push('\n');
            }
            _ => {}
        }
    }
    content
}

/// The number of polylines of each series colour, in colour order.
pub fn series_counts(c: &SvgContent) -> Vec<usize> {
    c.polylines.values().copied().collect()
}

/// The pixel size of a PNG file (which must be one).
pub fn png_size(path: &Path) -> (u32, u32) {
    let png = fs::read(path).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    let be = |b: &[u8]| u32::from_be_bytes(b.try_into().unwrap());
    (be(&png[16..20]), be(&png[20..24]))
}

/// The PNG copy next to an SVG: a PNG of the SVG's pixel size.
pub fn check_png(svg: &Path, content: &SvgContent) {
    assert_eq!(
        png_size(&svg.with_extension("png")),
        (content.width, content.height)
    );
}

/// Every file of a folder, by name, with its bytes, in name order.
pub fn folder_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    files.sort();
    files
}

/// Rewrites a platen CSV as a data system would export it: each `(platen column, header,
/// SI units per file unit)` becomes a column `header` holding the value in the file's unit.
pub fn relabel(src: &Path, dst: &Path, channels: &[(&str, &str, f64)]) {
    use platen_io::csv::{read_table, write_csv_atomic};
    let names: Vec<&str> = channels.iter().map(|c| c.0).collect();
    let table = read_table(src, &names, &[]).unwrap();
    let columns: Vec<Vec<f64>> = channels
        .iter()
        .map(|(ours, _, si_per_unit)| {
            table
                .column(ours)
                .unwrap()
                .iter()
                .map(|x| x / si_per_unit)
                .collect()
        })
        .collect();
    let headers: Vec<&str> = channels.iter().map(|c| c.1).collect();
    let slices: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
    write_csv_atomic(dst, &headers, &slices).unwrap();
}

/// The column map of [`LAB_CHANNELS`], as `--columns` takes it.
pub const LAB_COLUMNS_JSON: &str = r#"{
  "t_s": {"name": "Time", "unit": "ms"},
  "u_m": {"name": "Table disp", "unit": "mm"},
  "v_m_s": {"name": "Table vel", "unit": "cm/s"},
  "a_m_s2": {"name": "Table acc", "unit": "g"},
  "force_n": {"name": "Act force", "unit": "kN"}
}"#;

/// A lab's channel names and units for platen's five columns.
pub const LAB_CHANNELS: [(&str, &str, f64); 5] = [
    ("t_s", "Time", 1e-3),
    ("u_m", "Table disp", 1e-3),
    ("v_m_s", "Table vel", 1e-2),
    ("a_m_s2", "Table acc", 9.80665),
    ("force_n", "Act force", 1e3),
];
