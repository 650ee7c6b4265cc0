//! End-to-end tests of the figures of `simulate --plot`, `sweep --plot` and the size options
//! (`--width`, `--height`, `--png-scale`) of every verb that writes figures.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

mod common;
use common::{folder_bytes as folder, png_size, svg_content};
use common::{platen, stderr};

fn scenario(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(name)
        .display()
        .to_string()
}

fn ok_json(o: &Output) -> Value {
    assert!(o.status.success(), "{}", stderr(o));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Colours of simulated data and of limits (`platen_report::figure`).
const SIMULATED: &str = "#D95F02";
const RECORDED: &str = "#1F77B4";
const LIMIT: &str = "#000000";

/// The largest |value| of a CSV column (written by `simulate --out`, not by the figures).
fn csv_peak(path: &Path, column: &str) -> f64 {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == column).unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse::<f64>().unwrap().abs())
        .fold(0.0, f64::max)
}

/// `simulate --plot`: the three figures as SVG and PNG, listed in `--json`, the same bytes on
/// a second run, peaks in the titles equal to the peaks of the CSV written alongside (to the
/// four significant digits printed), and the decomposition's four panels.
#[test]
fn simulate_plot_writes_time_histories_decomposition_and_loops() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("run.csv");
    let run = |plots: &Path| {
        ok_json(&platen(&[
            "simulate",
            &scenario("paper-forward-force.json"),
            "--out",
            csv.to_str().unwrap(),
            "--json",
            "--plot",
            plots.to_str().unwrap(),
        ]))
    };
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let summary = run(&a);
    run(&b);
    let names = ["time-history", "force-decomposition", "hysteresis"];
    let listed: Vec<&str> = summary["figures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(listed.len(), 2 * names.len(), "{listed:?}");
    for name in names {
        for ext in ["svg", "png"] {
            let path = a.join(format!("{name}.{ext}"));
            assert!(listed.contains(&path.to_str().unwrap()), "{listed:?}");
        }
    }
    let (fa, fb) = (folder(&a), folder(&b));
    assert_eq!(fa.len(), 6);
    assert!(fa == fb, "a second run gives other bytes");

    let th = svg_content(&a.join("time-history.svg"));
    for (column, symbol, unit, scale) in [
        ("u_m", "u", "m", 1.0),
        ("v_m_s", "v", "m/s", 1.0),
        ("a_m_s2", "a", "m/s²", 1.0),
        ("force_n", "F_A", "kN", 1e-3),
    ] {
        let peak = csv_peak(&csv, column) * scale;
        let title = th
            .text
            .lines()
            .find(|l| l.contains(&format!("peak |{symbol}|")))
            .unwrap_or_else(|| panic!("no {symbol} panel in {}", th.text));
        // "displacement u: peak |u| 2.729 m (EXCEEDS the limit)"
        let after = title.split(&format!("peak |{symbol}| ")).nth(1).unwrap();
        let mut words = after.split_whitespace();
        let shown: f64 = words.next().unwrap().parse().unwrap();
        assert_eq!(words.next(), Some(unit), "{title}");
        // Four significant digits printed: half a unit of the fourth.
        let tol = 0.5 * 10f64.powf(peak.log10().floor() - 3.0);
        assert!((shown - peak).abs() <= tol * 1.0001, "{title}: CSV {peak}");
    }
    // One envelope polyline per channel.
    assert_eq!(th.polylines.get(SIMULATED), Some(&4), "{:?}", th.polylines);

    let dec = svg_content(&a.join("force-decomposition.svg"));
    assert_eq!(dec.polylines.get(SIMULATED), Some(&4));
    for symbol in ["F_A", "F_I", "F_E", "F_D"] {
        assert!(dec.text.contains(&format!("{symbol} (kN)")), "{symbol}");
    }
    let loops = svg_content(&a.join("hysteresis.svg"));
    assert_eq!(loops.polylines.get(SIMULATED), Some(&3));
}

/// The figure's text holds a title "… peak |SYMBOL| X …" with X the `peak` to the four
/// significant digits printed.
fn assert_shown_peak(text: &str, symbol: &str, peak: f64) {
    let marker = format!("peak |{symbol}| ");
    let title = text
        .lines()
        .find(|l| l.contains(&marker))
        .unwrap_or_else(|| panic!("no `{marker}` in {text}"));
    let shown: f64 = title
        .split(&marker)
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .unwrap()
        .parse()
        .unwrap();
    let tol = 0.5 * 10f64.powf(peak.log10().floor() - 3.0);
    assert!(
        (shown - peak).abs() <= tol * 1.0001,
        "{title}: expected {peak}"
    );
}

/// A short closed-loop run (the lhpost-2008 table system following a 5 cm, 1 Hz sine
/// command for 2 s), written to `dir`.
fn closed_loop_scenario(dir: &Path) -> String {
    let path = dir.join("closed-loop.json");
    fs::write(
        &path,
        r#"{"model": {"preset": "lhpost-2008"}, "table_system": {"preset": "lhpost-2008"},
            "excitation": {"sine_motion": {"amplitude_m": 0.05, "frequency_hz": 1.0,
            "sample_rate_hz": 1024}}, "duration_s": 2.0}"#,
    )
    .unwrap();
    path.display().to_string()
}

/// `simulate --plot` of a closed-loop run: the run's three figures and the loop's six
/// (command and achieved motion, tracking errors, drive and spool, pressures, flow against
/// the valves' capacity, supply pressure), each a valid SVG with its PNG, listed in
/// `--json`, the same bytes on a second run; the command solid blue and the achieved motion
/// dashed orange, the capacity as ± dashed black lines, the peaks as the summary's.
#[test]
fn simulate_plot_of_a_closed_loop_run_adds_the_loop_figures() {
    let dir = tempfile::tempdir().unwrap();
    let path = closed_loop_scenario(dir.path());
    let run = |plots: &Path| {
        ok_json(&platen(&[
            "simulate",
            &path,
            "--json",
            "--plot",
            plots.to_str().unwrap(),
        ]))
    };
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let summary = run(&a);
    run(&b);
    let names = [
        "time-history",
        "force-decomposition",
        "hysteresis",
        "tracking",
        "tracking-error",
        "valve",
        "pressure-difference",
        "flow",
        "supply-pressure",
    ];
    let listed: Vec<&str> = summary["figures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(listed.len(), 2 * names.len(), "{listed:?}");
    for name in names {
        for ext in ["svg", "png"] {
            let file = a.join(format!("{name}.{ext}"));
            assert!(listed.contains(&file.to_str().unwrap()), "{listed:?}");
        }
        let svg = a.join(format!("{name}.svg"));
        common::check_png(&svg, &svg_content(&svg));
    }
    assert!(folder(&a) == folder(&b), "a second run gives other bytes");

    // Command and achieved displacement and acceleration, whole and zoomed: four panels of a
    // solid blue command and a dashed orange achieved motion, one legend under the title.
    let tracking = svg_content(&a.join("tracking.svg"));
    assert_eq!(
        tracking.polylines.get(RECORDED),
        Some(&5),
        "{:?}",
        tracking.polylines
    );
    assert_eq!(
        tracking.polylines.get(SIMULATED),
        Some(&5),
        "{:?}",
        tracking.polylines
    );
    assert!(
        tracking.text.contains("peak |u_ref| 0.05000 m"),
        "{}",
        tracking.text
    );
    assert!(
        tracking.text.contains("achieved (simulated)"),
        "{}",
        tracking.text
    );
    let svg = fs::read_to_string(a.join("tracking.svg")).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    for (stroke, dashed) in [(RECORDED, false), (SIMULATED, true)] {
        assert!(
            doc.descendants()
                .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some(stroke))
                .all(|n| n.attribute("stroke-dasharray").is_some() == dashed),
            "{stroke}"
        );
    }
    let ts = &summary["table_system"];
    // The tracking errors' peaks are the summary's (to the four digits shown).
    let errors = svg_content(&a.join("tracking-error.svg"));
    for (symbol, key, scale) in [
        ("u − u_ref", "tracking_displacement_peak_m", 1e3),
        ("a − a_ref", "tracking_acceleration_peak_m_s2", 1.0),
    ] {
        let peak = ts[key].as_f64().unwrap().abs() * scale;
        assert_shown_peak(&errors.text, symbol, peak);
    }

    let valve = svg_content(&a.join("valve.svg"));
    assert!(valve.text.contains("drive d: peak |d|"), "{}", valve.text);
    assert!(valve.text.contains("spool opening x_v"), "{}", valve.text);
    let pressures = svg_content(&a.join("pressure-difference.svg"));
    assert!(
        pressures.text.contains("Δp = p_a − p_b (MPa)"),
        "{}",
        pressures.text
    );
    assert!(
        pressures.text.contains("p_b (rod side)"),
        "{}",
        pressures.text
    );

    // The flow against ±capacity: two dashed black lines and the legend's sample.
    let flow = svg_content(&a.join("flow.svg"));
    assert_eq!(flow.polylines.get(LIMIT), Some(&3), "{:?}", flow.polylines);
    let capacity = ts["valve_flow_capacity_m3_s"].as_f64().unwrap();
    assert!(
        flow.text
            .contains(&format!("valve capacity ±{capacity:.3} m³/s")),
        "{capacity}: {}",
        flow.text
    );
    assert_shown_peak(
        &flow.text,
        "Q",
        ts["peak_flow_m3_s"].as_f64().unwrap().abs(),
    );
    assert!(flow.text.contains("% of the capacity"), "{}", flow.text);

    let supply = svg_content(&a.join("supply-pressure.svg"));
    assert!(
        supply.text.contains("set pressure 20.7 MPa"),
        "{}",
        supply.text
    );
    assert!(supply.text.contains("lowest"), "{}", supply.text);
}

/// `sweep --plot`: one figure per axis with two or more values; per panel one line and one
/// marker per case of each combination of the other axes, the table's limit as a dashed
/// black line (and its legend sample); nothing for a single case; the same bytes twice.
#[test]
fn sweep_plot_draws_peaks_against_each_axis_with_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let path = scenario("paper-forward-force.json");
    let run = |plots: &Path, extra: &[&str]| {
        let mut args = vec!["sweep", &path, "--json", "--plot", plots.to_str().unwrap()];
        args.extend_from_slice(extra);
        ok_json(&platen(&args))
    };
    let axes = ["--scale", "0.5,1", "--pressure-mpa", "0,6.9,13.8"];
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let summary = run(&a, &axes);
    run(&b, &axes);
    assert_eq!(summary["figures"].as_array().unwrap().len(), 4);
    assert!(folder(&a) == folder(&b), "a second run gives other bytes");

    let by_scale = svg_content(&a.join("peaks-against-scale.svg"));
    // 4 panels × 3 pressure lines, and one shared legend of 3 lines and the limit.
    let colours = [
        "#1B9E77", "#D95F02", "#7570B3", // the three pressures
    ];
    for c in colours {
        assert_eq!(
            by_scale.polylines.get(c),
            Some(&5),
            "{c}: {:?}",
            by_scale.polylines
        );
    }
    // 4 panels × 6 cases.
    assert_eq!(by_scale.circles.values().sum::<usize>(), 24);
    assert!(by_scale.text.contains("13.8 MPa"));
    // The limits: drawn where a peak reaches a quarter of the limit (the peak displacement,
    // 2.7 m, of a 0.75 m stroke), given in the title otherwise (the force, 485 kN of 6.8 MN).
    assert!(
        by_scale
            .text
            .contains("peak |displacement|, table limit 0.75 m"),
        "{}",
        by_scale.text
    );
    assert!(
        by_scale
            .text
            .contains("peak |actuator force| (table limit 6800 kN, off the scale"),
        "{}",
        by_scale.text
    );
    let svg = fs::read_to_string(a.join("peaks-against-scale.svg")).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let drawn_limits = doc
        .descendants()
        .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some(LIMIT))
        .filter(|n| n.attribute("stroke-dasharray").is_some())
        .filter(|n| {
            n.attribute("points")
                .unwrap_or_default()
                .split_whitespace()
                .count()
                >= 2
        })
        .count();
    let titled = by_scale.text.matches(", table limit").count();
    assert!(titled >= 1);
    assert_eq!(
        drawn_limits,
        titled + 1,
        "a dashed line per drawn limit and the legend's"
    );

    let by_pressure = svg_content(&a.join("peaks-against-hold_down_pressure_mpa.svg"));
    assert!(by_pressure.text.contains("scale 0.5"));
    assert_eq!(by_pressure.circles.values().sum::<usize>(), 24);

    // A single case varies nothing: no figure, and the text output says why.
    let single = dir.path().join("single");
    let o = platen(&[
        "sweep",
        &scenario("paper-forward-force.json"),
        "--plot",
        single.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("no figures"));
    assert!(!single.join("peaks-against-scale.svg").exists());
}

/// `--width`/`--height` give every SVG that size (one of them keeps each figure's
/// proportions) and `--png-scale` multiplies the PNG's pixels; compare's recorded series is
/// solid and its simulated one dashed.
#[test]
fn size_options_set_every_figure_and_png_size() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("cmp");
    let o = platen(&[
        "compare",
        &scenario("sr9/sr9-forward.json"),
        "--recorded",
        &scenario("sr9/sr9-recorded.csv"),
        "--plot",
        plots.to_str().unwrap(),
        "--width",
        "900",
        "--height",
        "600",
        "--png-scale",
        "1.5",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut svgs = 0;
    for (name, _) in folder(&plots) {
        let path = plots.join(&name);
        if name.ends_with(".svg") {
            let c = svg_content(&path);
            assert_eq!((c.width, c.height), (900, 600), "{name}");
            assert_eq!(png_size(&path.with_extension("png")), (1350, 900), "{name}");
            svgs += 1;
        }
    }
    assert_eq!(svgs, 6);
    let svg = fs::read_to_string(plots.join("time-history-u_m.svg")).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    for (stroke, dashed) in [(RECORDED, false), (SIMULATED, true)] {
        let lines: Vec<bool> = doc
            .descendants()
            .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some(stroke))
            .map(|n| n.attribute("stroke-dasharray").is_some())
            .collect();
        assert_eq!(lines.len(), 3, "{stroke}: 2 panels and the shared legend");
        assert!(lines.iter().all(|&d| d == dashed), "{stroke}: {lines:?}");
    }

    // Only --width: the height keeps the figure's own proportions (hysteresis 1260×520).
    let plots = dir.path().join("sim");
    let o = platen(&[
        "simulate",
        &scenario("paper-forward-force.json"),
        "--plot",
        plots.to_str().unwrap(),
        "--width",
        "630",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let c = svg_content(&plots.join("hysteresis.svg"));
    assert_eq!((c.width, c.height), (630, 260));
    assert_eq!(png_size(&plots.join("hysteresis.png")), (630, 260));

    // Sizes out of range, and a PNG over 20 000 px a side, are usage errors before anything
    // runs.
    for (bad, says) in [
        (&["--width", "10"][..], "--width"),
        (&["--height", "big"], "--height"),
        (&["--png-scale", "0"], "--png-scale"),
        (&["--png-scale", "9"], "--png-scale"),
        (&["--width", "5000", "--png-scale", "8"], "20000 px"),
    ] {
        let out = dir.path().join("bad");
        let path = scenario("paper-forward-force.json");
        let mut args = vec!["simulate", &path, "--plot", out.to_str().unwrap()];
        args.extend_from_slice(bad);
        let o = platen(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{bad:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
}
