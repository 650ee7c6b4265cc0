//! The mistakes a new user makes first, each answered with a message that names the fix and
//! lists the valid choices (issue 27): a folder given where an output file is expected, a
//! comma list written with spaces, a JSON syntax error, an unknown unit in a column map, a
//! record without `t_s`.

mod common;

use std::path::{Path, PathBuf};

use common::{platen, stderr};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scenario(name: &str) -> String {
    root().join("scenarios").join(name).display().to_string()
}

/// The files and folders under `dir`.
fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

/// `--out dir/`, `--out dir` (an existing folder), `--report dir/`: a usage error (exit 2)
/// before anything runs, saying the option takes a file name with an example inside that
/// folder; nothing is written.
#[test]
fn a_folder_given_for_an_output_file_says_the_option_takes_a_file_name() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("results");
    std::fs::create_dir(&dir).unwrap();
    let d = dir.display().to_string();
    let slash = format!("{d}/");
    let missing = format!("{}/", tmp.path().join("new").display());
    let forward = scenario("paper-forward-force.json");
    let sine = scenario("s9-sine-motion.json");
    let closed = scenario("table-system/wn10g-closed-loop.json");
    let target = tmp.path().join("target.csv").display().to_string();
    let recorded = root().join("scenarios/sr9/sr9-recorded.csv");
    let recorded = recorded.display().to_string();
    let sr9 = scenario("sr9/sr9-forward.json");
    let cases: Vec<(Vec<&str>, &str, String)> = vec![
        (
            vec!["simulate", &forward, "--out", &slash],
            "--out",
            format!("{d}/run.csv"),
        ),
        (
            vec!["simulate", &forward, "--out", &d],
            "--out",
            format!("{d}/run.csv"),
        ),
        (
            vec!["simulate", &forward, "--out", &missing],
            "--out",
            format!("{}run.csv", missing),
        ),
        (
            vec!["sweep", &forward, "--scale", "0.5,1", "--out", &slash],
            "--out",
            format!("{d}/cases.csv"),
        ),
        (
            vec!["generate", "excitation", &sine, "--out", &d],
            "--out",
            format!("{d}/excitation.csv"),
        ),
        (
            vec!["plan", &closed, "--target", &target, "--out", &slash],
            "--out",
            format!("{d}/drive.csv"),
        ),
        (
            vec!["compare", &sr9, "--recorded", &recorded, "--report", &d],
            "--report",
            format!("{d}/report.html"),
        ),
        (
            vec!["schema", "--out", &slash],
            "--out",
            format!("{d}/scenario.schema.json"),
        ),
    ];
    for (args, option, example) in cases {
        let o = platen(&args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(
            e.contains(&format!(
                "{option} takes a file name: e.g. `{option} {example}`"
            )),
            "{args:?}: {e}"
        );
        assert!(!e.contains("renaming"), "{args:?}: {e}");
        assert!(
            listing(&dir).is_empty(),
            "{args:?} wrote {:?}",
            listing(&dir)
        );
        assert!(!tmp.path().join("new").exists(), "{args:?}");
    }
    // With --json the same message is a usage error object.
    let o = platen(&["simulate", &forward, "--out", &slash, "--json"]);
    assert_eq!(o.status.code(), Some(2));
    let v: serde_json::Value = serde_json::from_slice(&o.stderr).unwrap();
    assert_eq!(v["error"]["kind"], "usage");
    let message = v["error"]["message"].as_str().unwrap();
    assert!(message.contains("--out takes a file name"), "{message}");
}

/// `--scale 0.5 1` (and the other comma lists): a usage error that shows the one
/// comma-separated list the values make, whatever the order of the arguments.
#[test]
fn a_comma_list_written_with_spaces_shows_the_list_with_commas() {
    let forward = scenario("paper-forward-force.json");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["sweep", &forward, "--scale", "0.5", "1"],
            "`--scale 0.5,1`",
        ),
        (
            vec!["sweep", &forward, "--scale", "0.5", "1", "1.5", "--json"],
            "`--scale 0.5,1,1.5`",
        ),
        (
            vec!["sweep", "--pressure-mpa", "0", "6.9", "13.8", &forward],
            "`--pressure-mpa 0,6.9,13.8`",
        ),
        (
            vec![
                "sweep",
                &forward,
                "--set",
                "identified.coulomb_force_n=20e3",
                "25e3",
            ],
            "`--set identified.coulomb_force_n=20e3,25e3`",
        ),
        (
            vec!["sweep", &forward, "--scale=0.5", "1"],
            "`--scale 0.5,1`",
        ),
    ];
    for (args, fix) in cases {
        let o = platen(&args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(
            e.contains("takes one comma-separated list"),
            "{args:?}: {e}"
        );
        assert!(e.contains(fix), "{args:?}: {e}");
        if args.contains(&"--json") {
            let v: serde_json::Value = serde_json::from_str(e.trim()).unwrap();
            assert_eq!(v["error"]["kind"], "usage", "{e}");
        }
    }
    // Where the option takes one value (simulate's --pressure-mpa), clap's own message.
    let o = platen(&["simulate", &forward, "--pressure-mpa", "6.9", "13.8"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!stderr(&o).contains("comma-separated"), "{}", stderr(&o));
    // Another unexpected argument keeps clap's own message.
    let o = platen(&["sweep", &forward, "--scale", "0.5", "fast"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("unexpected argument 'fast'"),
        "{}",
        stderr(&o)
    );
}

/// A JSON syntax error in a scenario, a manifest or a column map names the file, the line and
/// the column, with no `?` for the path serde could not tell.
#[test]
fn a_json_syntax_error_names_the_file_line_and_column() {
    let tmp = tempfile::tempdir().unwrap();
    // Broken before any key is read, so every reader meets the syntax error first.
    let bad = "\n\n\n{,}";
    let path = tmp.path().join("broken.json");
    std::fs::write(&path, bad).unwrap();
    let p = path.display().to_string();
    let csv = root().join("scenarios/sr9/sr9-recorded.csv");
    let csv = csv.display().to_string();
    let sr9 = scenario("sr9/sr9-forward.json");
    let runs: Vec<Vec<&str>> = vec![
        vec!["simulate", &p],
        vec!["identify", "--manifest", &p],
        vec!["compare", &sr9, "--recorded", &csv, "--columns", &p],
        vec!["identify", &csv, "--columns", &p],
    ];
    for args in runs {
        let o = platen(&args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(3), "{args:?}: {e}");
        assert!(
            e.contains(&format!(
                "`{p}`: JSON syntax error at line 4 column 2: key must be a string"
            )),
            "{args:?}: {e}"
        );
        assert!(!e.contains('?'), "{args:?}: {e}");
        let mut json = args.clone();
        json.push("--json");
        let o = platen(&json);
        assert_eq!(o.status.code(), Some(3));
        let v: serde_json::Value = serde_json::from_slice(&o.stderr).unwrap();
        let err = &v["error"];
        assert_eq!(err["kind"], "input", "{v}");
        assert_eq!(err["file"], p.as_str(), "{v}");
        assert_eq!(err["line"], 4, "{v}");
        assert!(err["field"].is_null(), "{v}");
        assert!(
            err["message"]
                .as_str()
                .unwrap()
                .contains("JSON syntax error at line 4 column 2"),
            "{v}"
        );
    }
}

/// An unknown unit in a column map lists the units of that quantity; a record without `t_s`
/// says that a column map fixes it, with an example.
#[test]
fn a_unit_or_column_mistake_lists_the_choices_and_the_fix() {
    let tmp = tempfile::tempdir().unwrap();
    let record = tmp.path().join("lab.csv");
    let mut text = String::from("time,disp\n");
    for j in 0..=2048 {
        let t = j as f64 / 1024.0;
        text.push_str(&format!("{t},{}\n", 10.0 * (t * 6.0).sin()));
    }
    std::fs::write(&record, text).unwrap();
    let r = record.display().to_string();
    let sr9 = scenario("sr9/sr9-forward.json");

    let o = platen(&["compare", &sr9, "--recorded", &r]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{e}");
    assert!(e.contains("missing required column `t_s`"), "{e}");
    assert!(e.contains("the header has: `time`, `disp`"), "{e}");
    assert!(
        e.contains("needs a column map (`--columns MAP.json`"),
        "{e}"
    );
    assert!(
        e.contains(r#"{"t_s": {"name": "time", "unit": "s"}}"#),
        "{e}"
    );

    let map = tmp.path().join("map.json");
    std::fs::write(
        &map,
        r#"{"t_s": {"name": "time", "unit": "s"}, "u_m": {"name": "disp", "unit": "inches"}}"#,
    )
    .unwrap();
    let m = map.display().to_string();
    let o = platen(&["compare", &sr9, "--recorded", &r, "--columns", &m]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{e}");
    assert!(e.contains("columns.u_m.unit = \"inches\""), "{e}");
    assert!(
        e.contains("expected a unit of displacement (m, mm, cm, in)"),
        "{e}"
    );
}
