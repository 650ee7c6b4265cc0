//! `platen identify` end to end: recorded-like periodic tests made by `platen generate
//! recorded` from scenarios with a table that is not the paper's, identified back.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde_json::{json, Value};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A table that is not the paper's: every identified parameter changed, the exponent too.
const TABLE: [(&str, f64); 7] = [
    ("effective_mass_kg", 118e3),
    ("stiffness_n_per_m", 0.95e6),
    ("coulomb_force_n", 32e3),
    ("viscous_coefficient", 61e3),
    ("viscous_exponent", 0.68),
    ("low_velocity_force_n", 9e3),
    ("low_velocity_decay_s_per_m", 55.0),
];

fn truth(key: &str) -> f64 {
    TABLE.iter().find(|(k, _)| *k == key).unwrap().1
}

/// One generated test: its file (named neutrally), whether it is a sine.
struct Generated {
    file: PathBuf,
    sine: bool,
}

/// The paper's S1–S12 and T1–T12 motions at 512 Hz on `TABLE`, written by `platen generate
/// recorded` (oil-column ringing, 246 Hz tone, noise) into a temporary folder, once.
fn generated() -> &'static (tempfile::TempDir, Vec<Generated>) {
    static DATA: OnceLock<(tempfile::TempDir, Vec<Generated>)> = OnceLock::new();
    DATA.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let identified: serde_json::Map<String, Value> = TABLE
            .iter()
            .map(|(k, v)| ((*k).to_owned(), json!(v)))
            .collect();
        let mut out = Vec::new();
        let src = workspace().join("scenarios/paper-tests/13.8MPa");
        for (k, name) in (1..=12)
            .map(|i| format!("S{i}"))
            .chain((1..=12).map(|i| format!("T{i}")))
            .enumerate()
        {
            let text = std::fs::read_to_string(src.join(format!("{name}.json"))).unwrap();
            let mut scenario: Value = serde_json::from_str(&text).unwrap();
            scenario["model"] = json!({"preset": "lhpost-2008", "identified": identified});
            let exc = scenario["excitation"].as_object_mut().unwrap();
            let sine = exc.contains_key("sine_motion");
            for (_, body) in exc.iter_mut() {
                body["sample_rate_hz"] = json!(512);
            }
            // Neutral names, numbered in an order unrelated to the kind.
            let stem = format!("run-{:02}", (k * 7) % 24);
            let sc = dir.path().join(format!("{stem}.json"));
            std::fs::write(&sc, serde_json::to_string_pretty(&scenario).unwrap()).unwrap();
            let csv = dir.path().join(format!("{stem}.csv"));
            let o = platen(&[
                "generate",
                "recorded",
                sc.to_str().unwrap(),
                "--seed",
                &(100 + k).to_string(),
                "--out",
                csv.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
            out.push(Generated { file: csv, sine });
        }
        (dir, out)
    })
}

fn files() -> Vec<String> {
    generated()
        .1
        .iter()
        .map(|g| g.file.display().to_string())
        .collect()
}

fn identify_json(extra: &[&str]) -> Value {
    let files = files();
    let mut args = vec!["identify", "--json"];
    args.extend(files.iter().map(String::as_str));
    args.extend_from_slice(extra);
    let o = platen(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The issue's "done when": mass and stiffness within 2 %, Coulomb force and viscous
/// coefficient within 10 %, exponent within 0.05, from recorded-like data of a table with
/// none of the paper's values.
#[test]
fn identify_recovers_a_non_paper_table_from_recorded_like_tests() {
    let v = identify_json(&[]);
    let get = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k}: {}", v[k]));
    let rel = |k: &str| (get(k) / truth(k) - 1.0).abs();
    assert!(
        rel("effective_mass_kg") < 0.02,
        "{}",
        get("effective_mass_kg")
    );
    assert!(
        rel("stiffness_n_per_m") < 0.02,
        "{}",
        get("stiffness_n_per_m")
    );
    assert!(rel("coulomb_force_n") < 0.10, "{}", get("coulomb_force_n"));
    assert!(
        rel("viscous_coefficient") < 0.10,
        "{}",
        get("viscous_coefficient")
    );
    assert!(
        (get("viscous_exponent") - truth("viscous_exponent")).abs() < 0.05,
        "{}",
        get("viscous_exponent")
    );
    // All seven contract keys at top level, each with its uncertainty.
    for (k, _) in TABLE {
        assert!(v[k].is_number(), "{k}: {}", v[k]);
        let u = &v["uncertainty"][k];
        assert!(u["status"].is_string(), "{k}: {u}");
    }
    let m = &v["uncertainty"]["effective_mass_kg"];
    assert_eq!(m["status"], "estimated");
    let ci = m["ci95"].as_array().unwrap();
    assert!(ci[0].as_f64().unwrap() < get("effective_mass_kg"));
    assert!(ci[1].as_f64().unwrap() > get("effective_mass_kg"));
}

/// The per-test tables: one row per triangle (Kₑ) and per sine (Mₑ), each with the
/// dissipative force at peak velocity; the kinds recognised from the data, not the names.
#[test]
fn identify_json_has_the_per_test_tables_with_kinds_from_the_data() {
    let v = identify_json(&[]);
    let tri = v["triangle_tests"].as_array().unwrap();
    let sin = v["sine_tests"].as_array().unwrap();
    assert_eq!((tri.len(), sin.len()), (12, 12));
    for g in &generated().1 {
        let name = g.file.display().to_string();
        let table = if g.sine { sin } else { tri };
        let row = table
            .iter()
            .find(|r| r["file"] == name)
            .unwrap_or_else(|| panic!("{name} in the wrong table"));
        assert_eq!(row["kind_source"], "data");
        assert!(row["dissipative_force_at_peak_n"].is_number(), "{row}");
        if g.sine {
            assert!(row["effective_mass_kg"].is_number());
        } else {
            let k = row["stiffness_n_per_m"].as_f64().unwrap();
            assert!((k / 0.95e6 - 1.0).abs() < 0.02, "{name}: {k}");
        }
    }
    // The three slowest sines are flagged for the mass, with a warning each.
    let flagged = sin
        .iter()
        .filter(|r| {
            r["flags"]
                .as_array()
                .unwrap()
                .iter()
                .any(|f| f["code"] == "small_inertial_force")
        })
        .count();
    assert_eq!(flagged, 3);
    assert!(v["warnings"].as_array().unwrap().len() >= 3);
    assert!(v["global_fit"]["effective_mass_kg"].is_number());
    assert!(v["paper_eq21"]["coulomb_force_n"]["value"].is_number());
}

/// A manifest gives kinds and pressures; file names and manifest names play no part in the
/// result, and `--pressure-mpa` fills in the rest.
#[test]
fn a_manifest_gives_kinds_and_pressures_and_file_names_do_not_matter() {
    let (dir, gen) = generated();
    let tests: Vec<Value> = gen
        .iter()
        .map(|g| {
            json!({
                "file": g.file.file_name().unwrap().to_str().unwrap(),
                "kind": if g.sine { "sine" } else { "triangle" },
                // Deliberately misleading names.
                "name": format!("{}-{}", if g.sine { "T" } else { "S" }, g.file.file_name().unwrap().to_str().unwrap()),
            })
        })
        .collect();
    let manifest = dir.path().join("manifest.json");
    std::fs::write(&manifest, json!({"tests": tests}).to_string()).unwrap();
    let o = platen(&[
        "identify",
        "--json",
        "--manifest",
        manifest.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["reference_pressure_mpa"].is_null());
    // A single --pressure-mpa applies to the manifest's files too.
    let o = platen(&[
        "identify",
        "--json",
        "--manifest",
        manifest.to_str().unwrap(),
        "--pressure-mpa",
        "13.8",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let with_p: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(with_p["reference_pressure_mpa"], 13.8);
    assert_eq!(v["sine_tests"][0]["kind_source"], "manifest");
    let plain = identify_json(&["--pressure-mpa", "10"]);
    assert_eq!(plain["reference_pressure_mpa"], 10.0);
    for k in ["effective_mass_kg", "stiffness_n_per_m", "viscous_exponent"] {
        let (a, b) = (v[k].as_f64().unwrap(), plain[k].as_f64().unwrap());
        assert!((a / b - 1.0).abs() < 1e-9, "{k}: {a} vs {b}");
    }
    // With one known pressure, μₑ is F_μ/F_z there.
    assert!(plain["friction_coefficient"]["value"].is_number());
}

#[test]
fn identify_prints_a_readable_report_without_json() {
    let files = files();
    let mut args = vec!["identify"];
    args.extend(files.iter().map(String::as_str));
    let o = platen(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    for needle in [
        "Identified parameters",
        "effective_mass_kg",
        "Stiffness from triangle tests",
        "Effective mass from sine tests",
        "Dissipative force at peak velocity",
        "Eq. 21",
        "Global fit",
        "small_inertial_force",
    ] {
        assert!(text.contains(needle), "missing `{needle}` in\n{text}");
    }
}

fn fails_with(args: &[&str], needles: &[&str]) {
    let o = platen(args);
    assert_eq!(o.status.code(), Some(3), "{args:?}: {}", stderr(&o));
    let e = stderr(&o);
    for n in needles {
        assert!(e.contains(n), "`{n}` missing from: {e}");
    }
}

#[test]
fn bad_input_is_an_input_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    // A missing column.
    std::fs::write(p("nocol.csv"), "t_s,u_m,force_n\n0,0,0\n0.1,0,0\n").unwrap();
    fails_with(
        &["identify", p("nocol.csv").to_str().unwrap()],
        &["nocol.csv", "a_m_s2"],
    );
    // Not periodic, with the paper's method forced: it is not lost, it falls back to the
    // any-record method, and its account says why.
    let mut text = String::from("t_s,u_m,a_m_s2,force_n\n");
    for i in 0..2000 {
        text.push_str(&format!("{},{},0,0\n", i as f64 / 512.0, i as f64 * 1e-4));
    }
    std::fs::write(p("ramp.csv"), text).unwrap();
    let o = platen(&[
        "identify",
        p("ramp.csv").to_str().unwrap(),
        "--method",
        "periodic",
        "--no-output-error",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let r = &v["records"][0];
    assert_eq!(r["method"], "record", "{r}");
    assert_eq!(r["used"], true, "{r}");
    assert!(
        r["routing"]
            .as_str()
            .unwrap()
            .starts_with("not a periodic test: the displacement crosses its mid-range 1 time(s)"),
        "{r}"
    );
    // A file that does not exist.
    fails_with(
        &["identify", p("nowhere.csv").to_str().unwrap()],
        &["nowhere.csv"],
    );
    // Pressures that do not match the files.
    let f = files();
    fails_with(
        &["identify", &f[0], &f[1], &f[2], "--pressure-mpa", "1,2"],
        &["--pressure-mpa has 2 values for 3 files"],
    );
    // A manifest with an unknown key.
    std::fs::write(
        p("m.json"),
        r#"{"tests": [{"file": "x.csv", "pressure": 3}]}"#,
    )
    .unwrap();
    fails_with(
        &["identify", "--manifest", p("m.json").to_str().unwrap()],
        &["m.json", "pressure"],
    );
}

#[test]
fn a_negative_pressure_is_a_usage_error() {
    let o = platen(&["identify", "x.csv", "--pressure-mpa", "-1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("pressure"));
    let _ = Path::new("x");
}

mod common;
use common::{check_png, svg_content};
use common::{platen, stderr};

/// Series colours of the identification figures (`platen_report::identify_figures`): the
/// first pressure group, flagged tests, the final fit, the paper's Eq. 21 fit.
const GROUP: &str = "#1F77B4";
const FLAGGED: &str = "#969696";
const FIT: &str = "#000000";
const EQ21: &str = "#B2182B";

fn count(map: &std::collections::BTreeMap<String, usize>, colour: &str) -> usize {
    map.get(colour).copied().unwrap_or(0)
}

/// `identify --plot` at one hold-down pressure: the five figures as valid SVG (and PNG) with
/// the series the per-test tables of the JSON say they must have, the HTML report with every
/// figure inlined, the same bytes on a second run.
#[test]
fn identify_plot_writes_every_figure_with_its_series_and_a_self_contained_report() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("figures");
    let html = dir.path().join("identification.html");
    let files = files();
    let run = |plots: &Path, html: &Path| {
        let mut args = vec![
            "identify",
            "--json",
            "--pressure-mpa",
            "13.8",
            "--plot",
            plots.to_str().unwrap(),
            "--report",
            html.to_str().unwrap(),
        ];
        args.extend(files.iter().map(String::as_str));
        let o = platen(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice::<Value>(&o.stdout).unwrap()
    };
    let id = run(&plots, &html);
    let names = [
        "estimates",
        "elastic-force",
        "inertial-force",
        "dissipative-force",
        "friction",
    ];
    let written: Vec<String> = id["figures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap().to_owned())
        .collect();
    assert_eq!(written.len(), 2 * names.len(), "{written:?}");

    let tests = |kind: &str, used: bool| {
        id[kind]
            .as_array()
            .unwrap()
            .iter()
            .filter(|t| t["used"] == used)
            .count()
    };
    let (tri_used, tri_flagged) = (
        tests("triangle_tests", true),
        tests("triangle_tests", false),
    );
    let (sine_used, sine_flagged) = (tests("sine_tests", true), tests("sine_tests", false));
    assert_eq!((tri_used, tri_flagged), (12, 0));
    assert!(
        sine_used >= 8 && sine_flagged >= 3,
        "{sine_used} {sine_flagged}"
    );

    // Estimates: a confidence bar per test, a marker per test plus one per legend entry,
    // the mass line and its legend entry.
    let est = svg_content(&plots.join("estimates.svg"));
    assert_eq!(
        count(&est.polylines, GROUP),
        tri_used + sine_used,
        "{:?}",
        est.polylines
    );
    assert_eq!(count(&est.polylines, FLAGGED), sine_flagged);
    assert_eq!(count(&est.polylines, FIT), 2);
    assert_eq!(count(&est.circles, GROUP), tri_used + 1 + sine_used + 1);
    assert_eq!(count(&est.circles, FLAGGED), sine_flagged + 1);
    for label in ["stiffness Kₑ (MN/m)", "effective mass Mₑ (t)", "13.8 MPa"] {
        assert!(est.text.contains(label), "{label}");
    }

    // Elastic force: the stiffness line and its legend entry, data and residual points.
    let el = svg_content(&plots.join("elastic-force.svg"));
    assert_eq!(count(&el.polylines, GROUP), 2, "{:?}", el.polylines);
    assert_eq!(el.circles.len(), 1, "{:?}", el.circles);
    assert!(count(&el.circles, GROUP) > 1000);
    assert!(el.text.contains("F_E − Kₑ·u (kN)"));
    assert!(el.text.contains("residual at 13.8 MPa"), "{}", el.text);

    // Inertial force: what the mass line leaves, in kN and per test relative to its peak
    // inertial force; used and flagged points (and their legend entries) in both panels, no
    // line (the F_I-against-a line it replaced showed nothing but the line).
    let inertial = svg_content(&plots.join("inertial-force.svg"));
    assert!(inertial.polylines.is_empty(), "{:?}", inertial.polylines);
    assert!(count(&inertial.circles, GROUP) > 2000);
    assert!(count(&inertial.circles, FLAGGED) > 200);
    assert!(inertial.text.contains("F_I − Mₑ·a (kN)"));
    assert!(inertial.text.contains("(F_I − Mₑ·a)/(Mₑ·a_peak) (%)"));

    // Dissipative force: data, the law and Eq. 21 with legend entries, one peak point per
    // test plus its legend entry.
    let fd = svg_content(&plots.join("dissipative-force.svg"));
    assert_eq!(count(&fd.polylines, GROUP), 2, "{:?}", fd.polylines);
    assert_eq!(count(&fd.polylines, EQ21), 2);
    assert_eq!(count(&fd.circles, FIT), 24 + 1, "{:?}", fd.circles);
    assert!(count(&fd.circles, GROUP) > 1000);
    assert!(fd.text.contains("Eq. 21 fit"));

    // Friction: one pressure (one bar, one point), the μₑ line.
    let mu = svg_content(&plots.join("friction.svg"));
    assert_eq!(count(&mu.polylines, GROUP), 1, "{:?}", mu.polylines);
    assert_eq!(count(&mu.polylines, FIT), 2);
    assert_eq!(count(&mu.circles, GROUP), 2);
    assert!(mu.text.contains("vertical load F_z (MN)"));

    for name in names {
        let path = plots.join(format!("{name}.svg"));
        check_png(&path, &svg_content(&path));
    }

    // The report: every figure inlined, the parameters, nothing fetched from elsewhere.
    let page = std::fs::read_to_string(&html).unwrap();
    assert_eq!(page.matches("<svg").count(), names.len());
    for key in [
        "effective_mass_kg",
        "stiffness_n_per_m",
        "friction_coefficient",
    ] {
        assert!(page.contains(key), "{key}");
    }
    for external in ["src=", "href=", "<script", "<link", "@import", "url("] {
        assert!(!page.contains(external), "{external}");
    }

    // Determinism: a second run writes the same bytes.
    let plots2 = dir.path().join("again");
    let html2 = dir.path().join("again.html");
    run(&plots2, &html2);
    for name in names {
        for ext in ["svg", "png"] {
            let file = format!("{name}.{ext}");
            assert!(
                std::fs::read(plots.join(&file)).unwrap()
                    == std::fs::read(plots2.join(&file)).unwrap(),
                "{file} differs between runs"
            );
        }
    }
    assert!(std::fs::read(&html).unwrap() == std::fs::read(&html2).unwrap());
}

/// A figure folder that cannot be made is an output error (exit 5) and writes no report.
#[test]
fn identify_plot_into_a_file_is_an_output_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("a-file");
    std::fs::write(&blocker, "not a folder").unwrap();
    let html = dir.path().join("report.html");
    let f = files();
    let o = platen(&[
        "identify",
        &f[0],
        &f[1],
        "--plot",
        blocker.join("figures").to_str().unwrap(),
        "--report",
        html.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    assert!(stderr(&o).contains("output folder"), "{}", stderr(&o));
    assert!(!html.exists());
}

/// Files exported with a lab's channel names and units identify to the same parameters as
/// the same data in platen's columns: through `--columns`, and through a manifest's
/// `columns`: the files differ only by the rounding of a unit conversion (about 1e-16), which
/// the fits carry through to well below 1e-9 relative (measured: below 1e-10).
#[test]
fn columns_map_a_labs_channel_names_and_units() {
    let dir = tempfile::tempdir().unwrap();
    let mut lab_files = Vec::new();
    for (i, g) in generated().1.iter().enumerate() {
        let dst = dir.path().join(format!("lab-{i:02}.csv"));
        common::relabel(&g.file, &dst, &common::LAB_CHANNELS);
        lab_files.push(dst.display().to_string());
    }
    let map = dir.path().join("columns.json");
    std::fs::write(&map, common::LAB_COLUMNS_JSON).unwrap();
    let mut args = vec!["identify", "--json", "--columns", map.to_str().unwrap()];
    args.extend(lab_files.iter().map(String::as_str));
    let o = platen(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let mapped: Value = serde_json::from_slice(&o.stdout).unwrap();

    let tests: Vec<Value> = lab_files.iter().map(|f| json!({ "file": f })).collect();
    let columns: Value = serde_json::from_str(common::LAB_COLUMNS_JSON).unwrap();
    let manifest = dir.path().join("manifest.json");
    std::fs::write(
        &manifest,
        serde_json::to_string(&json!({ "tests": tests, "columns": columns })).unwrap(),
    )
    .unwrap();
    let o = platen(&[
        "identify",
        "--json",
        "--manifest",
        manifest.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let manifested: Value = serde_json::from_slice(&o.stdout).unwrap();

    let plain = identify_json(&[]);
    for (key, _) in TABLE {
        let a = plain[key].as_f64().unwrap();
        for other in [&mapped, &manifested] {
            let b = other[key].as_f64().unwrap();
            assert!((a - b).abs() <= 1e-9 * a.abs(), "{key}: {a} vs {b}");
        }
    }

    // An entry's own map with a unit of the wrong kind names the manifest and the entry.
    std::fs::write(
        &manifest,
        serde_json::to_string(&json!({ "tests": [{
            "file": &lab_files[0],
            "columns": { "u_m": { "name": "Table disp", "unit": "kN" } }
        }] }))
        .unwrap(),
    )
    .unwrap();
    fails_with(
        &["identify", "--manifest", manifest.to_str().unwrap()],
        &["manifest.json", "tests[0].columns.u_m.unit", "kN"],
    );
}
