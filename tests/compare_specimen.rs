//! `platen compare` and the figures on runs with a specimen (issue 14): the base shear and
//! the storey channels are compared when the recording has them, against metrics computed
//! here in closed form; a storey the specimen lacks is refused before anything runs;
//! `simulate --plot` draws the specimen's base shear and drifts.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

use platen_compare::{Comparison, Settings};
use platen_io::csv::{read_table, write_csv_atomic};
use serde_json::Value;

mod common;
use common::{check_png, series_counts, svg_content};
use common::{platen, stderr};

fn specimen_scenario(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/specimen")
        .join(name)
        .display()
        .to_string()
}

fn ok_json(o: &Output) -> Value {
    assert!(o.status.success(), "platen failed: {}", stderr(o));
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
}

/// The header of the CSV a 2-storey specimen run writes, as the contract lists it.
const SPECIMEN_HEADER: [&str; 13] = [
    "t_s",
    "u_m",
    "v_m_s",
    "a_m_s2",
    "force_n",
    "inertial_force_n",
    "elastic_force_n",
    "dissipative_force_n",
    "base_shear_n",
    "storey1_u_m",
    "storey2_u_m",
    "storey1_a_m_s2",
    "storey2_a_m_s2",
];

/// Runs `platen simulate` on the shipped specimen scenario `name` into `dir/run.csv`.
fn simulated_csv(dir: &Path, name: &str) -> PathBuf {
    let out = dir.join(format!("{name}.csv"));
    let o = platen(&[
        "simulate",
        &specimen_scenario(name),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

/// Reads every column of a platen CSV (header order) and rewrites it into `dst` with each
/// column passed through `edit(name, values)`; `extra` columns are appended.
fn rewrite(
    src: &Path,
    dst: &Path,
    header: &[&str],
    edit: impl Fn(&str, &mut Vec<f64>),
    extra: &[(&str, Vec<f64>)],
) {
    let table = read_table(src, header, &[]).unwrap();
    let mut names: Vec<&str> = header.to_vec();
    let mut columns: Vec<Vec<f64>> = header
        .iter()
        .map(|n| {
            let mut c = table.column(n).unwrap().to_vec();
            edit(n, &mut c);
            c
        })
        .collect();
    for (n, c) in extra {
        names.push(n);
        columns.push(c.clone());
    }
    let slices: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
    write_csv_atomic(dst, &names, &slices).unwrap();
}

fn compare_json(scenario: &str, recorded: &Path) -> Value {
    ok_json(&platen(&[
        "compare",
        &specimen_scenario(scenario),
        "--recorded",
        recorded.to_str().unwrap(),
        "--json",
    ]))
}

fn channels(summary: &Value) -> Vec<String> {
    summary["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_owned())
        .collect()
}

/// A recording written by the simulation itself compares with a zero error on every channel,
/// the specimen's included, in both directions: the CSV writes the shortest decimal that
/// reads back to the same double, and the recorded times are the simulated ones, so the
/// alignment is exact and every residual is exactly 0.
#[test]
fn a_specimen_run_compared_with_its_own_output_has_zero_error_on_every_channel() {
    let dir = tempfile::tempdir().unwrap();
    for (name, platen_channels) in [
        ("frame-forward.json", &["u_m", "v_m_s"][..]),
        ("frame-inverse.json", &["force_n"][..]),
    ] {
        let csv = simulated_csv(dir.path(), name);
        let s = compare_json(name, &csv);
        let mut expected: Vec<&str> = platen_channels.to_vec();
        expected.extend(&SPECIMEN_HEADER[8..]);
        assert_eq!(channels(&s), expected, "{name}");
        for ch in &expected {
            let m = &s[*ch];
            assert_eq!(m["rms_error"], 0.0, "{name} {ch}: {m}");
            assert_eq!(m["nrmse"], 0.0, "{name} {ch}: {m}");
            assert_eq!(m["peak_ratio"], 1.0, "{name} {ch}: {m}");
            assert!(
                m["rms_recorded"].as_f64().unwrap() > 0.0,
                "{name} {ch}: {m}"
            );
        }
        assert_eq!(s["base_shear_n"]["unit"], "N");
        assert_eq!(s["storey1_a_m_s2"]["unit"], "m/s²");
        assert_eq!(s["notes"], Value::Array(Vec::new()), "{name}");
    }
}

/// A recording whose base shear is the simulated one times 1.1 (and whose top storey's
/// acceleration is times 0.9): with error = simulated − recorded = (1 − k)·s and recorded
/// RMS = k·RMS(s), NRMSE = |1 − k|/k and peak ratio = 1/k, whatever s is: 1/11 and 1/1.1 for
/// the base shear, 1/9 and 1/0.9 for the storey. The other channels stay exact. The bound
/// 1e-12 covers the rounding of the scaled values and of the sums of squares over 8193
/// samples (each ~1e-16 relative).
#[test]
fn a_scaled_base_shear_gives_the_nrmse_and_peak_ratio_of_the_scale() {
    const ROUNDING: f64 = 1e-12;
    let dir = tempfile::tempdir().unwrap();
    for name in ["frame-forward.json", "frame-inverse.json"] {
        let csv = simulated_csv(dir.path(), name);
        let scaled = dir.path().join(format!("scaled-{name}.csv"));
        rewrite(
            &csv,
            &scaled,
            &SPECIMEN_HEADER,
            |n, c| {
                let k = match n {
                    "base_shear_n" => 1.1,
                    "storey2_a_m_s2" => 0.9,
                    _ => return,
                };
                c.iter_mut().for_each(|x| *x *= k);
            },
            &[],
        );
        let s = compare_json(name, &scaled);
        for (ch, k) in [("base_shear_n", 1.1f64), ("storey2_a_m_s2", 0.9)] {
            let m = &s[ch];
            let nrmse = m["nrmse"].as_f64().unwrap();
            let ratio = m["peak_ratio"].as_f64().unwrap();
            assert!(
                (nrmse - (1.0 - k).abs() / k).abs() < ROUNDING,
                "{name} {ch}: NRMSE {nrmse}"
            );
            assert!((ratio - 1.0 / k).abs() < ROUNDING, "{name} {ch}: {ratio}");
            assert!((m["correlation"].as_f64().unwrap() - 1.0).abs() < ROUNDING);
            // The lag's sub-sample refinement of a scaled copy's correlation peak: zero up
            // to rounding (1e-12 s is a billionth of the 1/1024 s sample interval).
            let lag = m["lag_s"].as_f64().unwrap();
            assert!(lag.abs() < 1e-12, "{name} {ch}: lag {lag} s");
        }
        for ch in ["storey1_u_m", "storey2_u_m", "storey1_a_m_s2"] {
            assert_eq!(s[ch]["nrmse"], 0.0, "{name} {ch}");
        }
    }
}

/// A recording with a column for a storey the 2-storey specimen does not have is refused,
/// naming the column and the number of storeys, before anything is simulated or written.
#[test]
fn a_storey_the_specimen_lacks_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulated_csv(dir.path(), "frame-forward.json");
    let n = read_table(&csv, &["t_s"], &[]).unwrap().len();
    for extra in ["storey3_u_m", "storey12_a_m_s2"] {
        let bad = dir.path().join(format!("{extra}.csv"));
        rewrite(
            &csv,
            &bad,
            &SPECIMEN_HEADER,
            |_, _| {},
            &[(extra, vec![0.0; n])],
        );
        let plots = dir.path().join(format!("plots-{extra}"));
        let o = platen(&[
            "compare",
            &specimen_scenario("frame-forward.json"),
            "--recorded",
            bad.to_str().unwrap(),
            "--plot",
            plots.to_str().unwrap(),
        ]);
        assert!(!o.status.success());
        let err = stderr(&o);
        assert!(err.contains(&format!("`{extra}`")), "{err}");
        assert!(err.contains("specimen has 2 storey(s)"), "{err}");
        assert!(err.contains(&bad.display().to_string()), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!plots.exists(), "figures written for a refused comparison");
    }
}

/// A recording without the specimen's columns compares the platen's channels only (the
/// recorded F_D then subtracts the simulated base shear, and a note says so); a scenario
/// without a specimen ignores a recording's specimen columns, with a note.
#[test]
fn specimen_columns_are_compared_only_where_both_sides_have_them() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulated_csv(dir.path(), "frame-forward.json");
    let bare_rec = dir.path().join("bare.csv");
    rewrite(&csv, &bare_rec, &SPECIMEN_HEADER[..8], |_, _| {}, &[]);
    let s = compare_json("frame-forward.json", &bare_rec);
    assert_eq!(channels(&s), ["u_m", "v_m_s"]);
    let notes = s["notes"].to_string();
    assert!(notes.contains("no base_shear_n column"), "{notes}");

    // The bare platen (the same scenario without its specimen) against the specimen's
    // recording: the specimen's columns are not compared.
    let text = fs::read_to_string(specimen_scenario("frame-forward.json")).unwrap();
    let mut json: Value = serde_json::from_str(&text).unwrap();
    json.as_object_mut().unwrap().remove("specimen").unwrap();
    let bare = dir.path().join("bare.json");
    fs::write(&bare, json.to_string()).unwrap();
    let s = ok_json(&platen(&[
        "compare",
        bare.to_str().unwrap(),
        "--recorded",
        csv.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(channels(&s), ["u_m", "v_m_s"]);
    let notes = s["notes"].to_string();
    assert!(
        notes.contains("the scenario has no specimen") && notes.contains("storey2_a_m_s2"),
        "{notes}"
    );
}

/// With a specimen the actuator force carries the base shear: the recorded dissipative force
/// is F_A − F_I − F_E − B. On a recording written by the simulation it is the run's own
/// `dissipative_force_n` column (F_A = F_I + F_E + F_D + B at every sample), to the rounding
/// of a sum of forces of ~1e5 N (1e-9 of the peak actuator force); without the − B it would
/// be off by the base shear (70 kN).
#[test]
fn the_recorded_dissipative_force_of_a_specimen_run_excludes_the_base_shear() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulated_csv(dir.path(), "frame-forward.json");
    let c = Comparison::from_files(
        Path::new(&specimen_scenario("frame-forward.json")),
        &csv,
        None,
        &Settings::default(),
    )
    .unwrap();
    let table = read_table(&csv, &["dissipative_force_n", "force_n"], &[]).unwrap();
    let fd = table.column("dissipative_force_n").unwrap();
    let peak = table
        .column("force_n")
        .unwrap()
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    assert_eq!(c.recorded_dissipative_n.len(), fd.len());
    let worst = c
        .recorded_dissipative_n
        .iter()
        .zip(fd)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-9 * peak, "worst {worst} N of {peak} N");
}

/// `RunResult::column` finds the specimen's columns, and `columns` lists them in the order
/// of the CSV header `platen simulate` writes (a separate code path, `CsvSink`), with the
/// same values.
#[test]
fn run_result_lists_and_finds_the_specimen_columns_as_the_csv_has_them() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulated_csv(dir.path(), "frame-inverse.json");
    let run = platen_scenario::simulate(specimen_scenario("frame-inverse.json")).unwrap();
    let header = fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = header.lines().next().unwrap().split(',').collect();
    assert_eq!(run.columns(), header);
    assert_eq!(header, SPECIMEN_HEADER);
    let table = read_table(&csv, &SPECIMEN_HEADER, &[]).unwrap();
    for name in SPECIMEN_HEADER {
        assert_eq!(
            run.column(name).unwrap(),
            table.column(name).unwrap(),
            "{name}"
        );
    }
    assert_eq!(run.column("storey3_u_m"), None);
}

/// `simulate --plot` on a specimen run adds the `specimen` figure: a base-shear panel whose
/// title's peak is the CSV's (to the four significant digits printed) and a drift panel per
/// storey; a bare run has no such figure.
#[test]
fn simulate_plot_of_a_specimen_run_draws_the_base_shear_and_drifts() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("run.csv");
    let plots = dir.path().join("plots");
    let s = ok_json(&platen(&[
        "simulate",
        &specimen_scenario("frame-inverse.json"),
        "--out",
        csv.to_str().unwrap(),
        "--json",
        "--plot",
        plots.to_str().unwrap(),
    ]));
    let svg = plots.join("specimen.svg");
    let listed = s["figures"].to_string();
    assert!(listed.contains("specimen.svg"), "{listed}");
    let content = svg_content(&svg);
    check_png(&svg, &content);
    assert_eq!(series_counts(&content), [3], "one series per panel");
    let table = read_table(&csv, &["base_shear_n"], &[]).unwrap();
    let peak_kn = table
        .column("base_shear_n")
        .unwrap()
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()))
        * 1e-3;
    let title = format!(
        "peak |B| {} kN",
        platen_report::text::significant(peak_kn, 4)
    );
    assert!(
        content.text.contains(&title),
        "{title} in\n{}",
        content.text
    );
    for label in [
        "B (kN)",
        "storey 1 drift d_1",
        "storey 2 drift d_2",
        "d_2 (mm)",
    ] {
        assert!(content.text.contains(label), "{label} in\n{}", content.text);
    }

    let bare = dir.path().join("bare");
    let o = platen(&[
        "simulate",
        &PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/paper-forward-force.json")
            .display()
            .to_string(),
        "--out",
        dir.path().join("bare.csv").to_str().unwrap(),
        "--plot",
        bare.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!bare.join("specimen.svg").exists());
}

/// The figures and the HTML report show the specimen's channels: a time history per channel
/// (recorded and simulated, two panels and a shared legend), one residual panel per compared
/// channel, the channels in the report's metrics table, and F_D less B in the dissipative
/// figure.
#[test]
fn the_figures_and_the_report_show_the_specimen_channels() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulated_csv(dir.path(), "frame-forward.json");
    let (plots, html) = (dir.path().join("plots"), dir.path().join("report.html"));
    let s = ok_json(&platen(&[
        "compare",
        &specimen_scenario("frame-forward.json"),
        "--recorded",
        csv.to_str().unwrap(),
        "--plot",
        plots.to_str().unwrap(),
        "--report",
        html.to_str().unwrap(),
        "--json",
    ]));
    let compared = channels(&s);
    assert_eq!(compared.len(), 7, "{compared:?}");
    for (name, label) in [
        ("base_shear_n", "base shear B (kN)"),
        ("storey2_u_m", "z_2 (m)"),
        ("storey1_a_m_s2", "a_1 (m/s²)"),
    ] {
        let path = plots.join(format!("time-history-{name}.svg"));
        let c = svg_content(&path);
        assert_eq!(series_counts(&c), [3, 3], "{name}: {:?}", c.polylines);
        assert!(c.text.contains(label), "{label} in\n{}", c.text);
        check_png(&path, &c);
    }
    let residual = svg_content(&plots.join("residual.svg"));
    assert_eq!(series_counts(&residual), [7], "{:?}", residual.polylines);
    assert!(
        residual.text.contains("B sim − rec (kN)"),
        "{}",
        residual.text
    );
    assert!(
        residual.text.contains("z_2 sim − rec (mm)"),
        "{}",
        residual.text
    );
    let fd = svg_content(&plots.join("dissipative-force.svg"));
    assert!(fd.text.contains("F_A − M·a − F_E − B"), "{}", fd.text);
    let page = fs::read_to_string(&html).unwrap();
    for name in &compared {
        assert!(page.contains(&format!("<td><code>{name}</code>")), "{name}");
        assert!(
            page.contains(&format!("id=\"time-history-{name}\"")),
            "{name}"
        );
    }
}
