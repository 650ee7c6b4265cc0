//! `platen scenarios` lists every shipped scenario once, with the name its file gives, and the
//! paper's 72 periodic tests as one folder entry; a folder that is not there is an error.

mod common;

use std::path::{Path, PathBuf};

use common::platen;
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The scenario files outside `paper-tests`, read here directly: (relative path, `name`).
fn expected(dir: &Path) -> Vec<(String, String)> {
    let mut v = Vec::new();
    let mut visit = |p: &Path, rel: String| {
        if p.extension().is_some_and(|e| e == "json") {
            let json: Value = serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
            if json.get("excitation").is_some() {
                v.push((rel, json["name"].as_str().unwrap_or("").to_owned()));
            }
        }
    };
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if name == "paper-tests" {
                continue;
            }
            for f in std::fs::read_dir(&p).unwrap() {
                let f = f.unwrap().path();
                let rel = format!("{name}/{}", f.file_name().unwrap().to_string_lossy());
                visit(&f, rel);
            }
        } else {
            visit(&p, name);
        }
    }
    v.sort();
    v
}

#[test]
fn every_shipped_scenario_is_listed_once_with_its_name() {
    let dir = root().join("scenarios");
    let o = platen(&["scenarios", dir.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let list: Value = serde_json::from_slice(&o.stdout).unwrap();
    let list = list.as_array().unwrap();
    let got: Vec<(String, String)> = list
        .iter()
        .filter(|s| s["kind"] != "group")
        .map(|s| {
            (
                s["path"].as_str().unwrap().to_owned(),
                s["name"].as_str().unwrap().to_owned(),
            )
        })
        .collect();
    assert_eq!(got, expected(&dir));
    let groups: Vec<&Value> = list.iter().filter(|s| s["kind"] == "group").collect();
    assert_eq!(groups.len(), 1);
    assert_eq!(groups[0]["path"], "paper-tests/");
    assert_eq!(groups[0]["name"], "72 scenarios");
    let kind = |path: &str| {
        list.iter()
            .find(|s| s["path"] == path)
            .map(|s| (s["kind"].clone(), s["needs_record"].clone()))
            .unwrap()
    };
    assert_eq!(kind("sr9-like-sine-force.json").0, "forward");
    assert_eq!(kind("s9-sine-motion.json").0, "inverse");
    assert_eq!(
        kind("table-system/northridge-closed-loop.json"),
        (Value::from("closed_loop"), Value::from(true))
    );
}

#[test]
fn the_text_list_names_the_kinds_and_a_missing_folder_is_an_error() {
    let o = platen(&["scenarios", root().join("scenarios").to_str().unwrap()]);
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("sr9-like-sine-force.json"), "{text}");
    assert!(text.contains("closed loop"), "{text}");
    // A record from the records folder, PEER's or not: El Centro's is a digitisation that
    // is not PEER-processed (docs/records-and-signals.md), so "PEER" would be wrong there.
    let centro = text
        .lines()
        .find(|l| l.contains("elcentro-1940-chopra.json"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(
        centro.contains("needs a record from PLATEN_RECORDS_DIR") && !centro.contains("PEER"),
        "{centro}"
    );
    let o = platen(&["scenarios", "/no/such/folder"]);
    assert!(!o.status.success());
    assert!(o.stdout.is_empty());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("/no/such/folder") && err.contains("not a folder"),
        "{err}"
    );
}
