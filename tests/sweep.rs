//! End-to-end tests of `platen sweep`: the grid, the row order, byte-identical output
//! whatever the number of threads, and the errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scenario(name: &str) -> String {
    workspace()
        .join("scenarios")
        .join(name)
        .display()
        .to_string()
}

/// Runs platen with `RAYON_NUM_THREADS` set to `threads`.
fn platen_on(threads: usize, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_platen"))
        .args(args)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("run platen")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn rows(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    (header, rows)
}

#[test]
fn a_3_by_2_grid_runs_every_case_in_order_with_the_same_bytes_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let sr9 = scenario("sr9-like-sine-force.json");
    let mut outputs = Vec::new();
    for threads in [1, 2] {
        let out = dir.path().join(format!("cases-{threads}.csv"));
        let o = platen_on(
            threads,
            &[
                "sweep",
                &sr9,
                "--scale",
                "0.5,1,1.5",
                "--pressure-mpa",
                "6.9,13.8",
                "--out",
                out.to_str().unwrap(),
                "--json",
            ],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        outputs.push((std::fs::read(&out).unwrap(), o.stdout, out));
    }
    assert!(
        outputs[0].0 == outputs[1].0,
        "CSV differs between 1 and 2 threads"
    );
    // The JSON names its output file, which differs here; everything else is identical.
    let json = |bytes: &[u8]| {
        let mut v: serde_json::Value = serde_json::from_slice(bytes).unwrap();
        v.as_object_mut().unwrap().remove("out");
        v.to_string()
    };
    assert_eq!(
        json(&outputs[0].1),
        json(&outputs[1].1),
        "JSON differs between 1 and 2 threads"
    );

    let (header, rows) = rows(&outputs[0].2);
    assert_eq!(
        header,
        [
            "case",
            "scale",
            "hold_down_pressure_mpa",
            "peak_u_m",
            "peak_v_m_s",
            "peak_a_m_s2",
            "peak_force_n",
            "stick_time_s",
            "events",
            "limits_exceeded",
            "status"
        ]
    );
    assert_eq!(rows.len(), 6);
    // Scale outermost, pressure inner.
    let expected = [
        ("0.5", "6.9"),
        ("0.5", "13.8"),
        ("1", "6.9"),
        ("1", "13.8"),
        ("1.5", "6.9"),
        ("1.5", "13.8"),
    ];
    for (i, (row, (scale, pressure))) in rows.iter().zip(expected).enumerate() {
        assert_eq!(row[0], i.to_string());
        assert_eq!((row[1].as_str(), row[2].as_str()), (scale, pressure));
        assert_eq!(row[10], "ok");
        let force: f64 = row[6].parse().unwrap();
        let scale: f64 = scale.parse().unwrap();
        assert!(
            (force.abs() - scale * 100e3).abs() < 1e-6 * 100e3,
            "{row:?}"
        );
    }

    // Case 3 (scale 1 at the scenario's own 13.8 MPa) is the scenario itself: the same peaks,
    // bit for bit, as `platen simulate`.
    let o = platen_on(2, &["simulate", &sr9, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let single: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let sweep: serde_json::Value = serde_json::from_slice(&outputs[0].1).unwrap();
    let case = &sweep["results"][3];
    for key in [
        "peak_u_m",
        "peak_v_m_s",
        "peak_a_m_s2",
        "peak_force_n",
        "stick_time_s",
    ] {
        assert_eq!(case[key], single[key], "{key}");
    }
    let events = single["stick_events"].as_u64().unwrap()
        + single["breakaways"].as_u64().unwrap()
        + single["reversals"].as_u64().unwrap();
    assert_eq!(case["events"].as_u64(), Some(events));
    assert_eq!(rows[3][3], single["peak_u_m"].as_f64().unwrap().to_string());
}

#[test]
fn set_sweeps_a_full_model_parameter_and_names_its_column() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cases.csv");
    let full = scenario("full-model-large-stroke.json");
    let o = platen_on(
        2,
        &[
            "sweep",
            &full,
            "--set",
            "full.platen_mass_kg=134.8e3,150e3",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = rows(&out);
    assert_eq!(header[3], "full.platen_mass_kg");
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0][3], "134800");
    assert_eq!(rows[1][3], "150000");
    // 134.8 t is the preset's own platen mass: case 0 is the scenario itself.
    let o = platen_on(1, &["simulate", &full, "--json"]);
    let single: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rows[0][4], single["peak_u_m"].as_f64().unwrap().to_string());
    assert_ne!(rows[0][4], rows[1][4]);
}

#[test]
fn an_inverse_scenario_scales_the_motion_and_leaves_stick_columns_empty() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cases.csv");
    let o = platen_on(
        1,
        &[
            "sweep",
            &scenario("s9-sine-motion.json"),
            "--scale",
            "1,2",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, rows) = rows(&out);
    assert_eq!(rows[0][3], "-0.2");
    assert_eq!(rows[1][3], "-0.4");
    assert_eq!((rows[0][7].as_str(), rows[0][8].as_str()), ("", ""));
}

#[test]
fn bad_sweep_arguments_fail_with_a_clear_message_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cases.csv");
    let sr9 = scenario("sr9-like-sine-force.json");
    let cases: &[(&[&str], i32, &str)] = &[
        (
            &["--set", "identified.bogus=1"],
            2,
            "unknown identified parameter",
        ),
        (
            &["--set", "identified.coulomb_force_n"],
            2,
            "FORM.NAME=V1,V2",
        ),
        (&["--scale", "1,abc"], 2, "abc"),
        (&["--pressure-mpa", "-1"], 2, "pressure >= 0"),
        (
            &["--set", "full.platen_mass_kg=1e5"],
            2,
            "runs the identified model",
        ),
        (
            &[
                "--set",
                "identified.coulomb_force_n=1",
                "--set",
                "identified.coulomb_force_n=2",
            ],
            2,
            "given twice",
        ),
        (
            &["--set", "identified.effective_mass_kg=144e3,-5"],
            3,
            "effective_mass_kg",
        ),
    ];
    for (extra, code, needle) in cases {
        let mut args = vec!["sweep", sr9.as_str(), "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = platen_on(2, &args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(*code), "{extra:?}: {err}");
        assert!(err.contains(needle), "{extra:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{extra:?}: output written despite the error");
    }
}

#[test]
fn the_text_summary_has_the_same_bytes_on_every_run_and_thread_count() {
    // Determinism: the summary on stdout holds no wall time and no thread count (those go to
    // stderr as a diagnostic), so two runs on 1 and 2 threads print the same bytes.
    let sr9 = scenario("sr9-like-sine-force.json");
    let args = [
        "sweep",
        &sr9,
        "--scale",
        "0.5,1,1.5",
        "--pressure-mpa",
        "6.9,13.8",
    ];
    let one = platen_on(1, &args);
    let two = platen_on(2, &args);
    assert!(
        one.status.success() && two.status.success(),
        "{}",
        stderr(&one)
    );
    assert_eq!(one.stdout, two.stdout);
    let text = String::from_utf8(one.stdout.clone()).unwrap();
    assert!(text.starts_with("SR9-like 100 kN, 0.5 Hz sine force (forward): 6 cases (identified model, lhpost-2008)\n"), "{text}");
    assert!(stderr(&one).contains("6 cases in ") && stderr(&one).contains(" s on 1 threads"));
    assert!(stderr(&two).contains(" s on 2 threads"));
}
