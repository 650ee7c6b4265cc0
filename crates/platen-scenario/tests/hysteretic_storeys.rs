//! Hysteretic storeys in a scenario (issue 52): the contract's keys read and checked with
//! their JSON paths before any run, the runs that do not take a yielding storey yet refused
//! at the key, and the shipped yielding frame's summary consistent with its own columns.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use platen_scenario::Scenario;

fn shipped(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn read(rel: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(shipped(rel)).unwrap()).unwrap()
}

/// The error of loading `doc` (written into a temporary folder), which must fail.
fn load_error(doc: &Value) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.json");
    std::fs::write(&path, serde_json::to_string_pretty(doc).unwrap()).unwrap();
    match Scenario::load(&path) {
        Ok(_) => panic!("accepted: {doc}"),
        Err(e) => e.to_string(),
    }
}

const YIELDING: &str = "scenarios/specimen/frame-yielding-inverse.json";

#[test]
fn bad_hysteresis_is_refused_at_its_json_path() {
    let cases = [
        (
            json!({"bilinear": {"yield_force_n": -3.0}}),
            "specimen.storeys[1].hysteresis.bilinear.yield_force_n",
        ),
        (
            json!({"bilinear": {"yield_force_n": 3e5, "post_yield_stiffness_ratio": 1.0}}),
            "specimen.storeys[1].hysteresis.bilinear.post_yield_stiffness_ratio",
        ),
        (
            json!({"bouc_wen": {"yield_force_n": 3e5, "exponent": 0.2}}),
            "specimen.storeys[1].hysteresis.bouc_wen.exponent",
        ),
        (
            json!({"bouc_wen": {"yield_force_n": 3e5, "beta_share": 2.0}}),
            "specimen.storeys[1].hysteresis.bouc_wen.beta_share",
        ),
        (
            json!({"bilinear": {"yield_force_n": 3e5, "hardening": 0.1}}),
            "hardening",
        ),
        (
            json!({"elastoplastic": {"yield_force_n": 3e5}}),
            "elastoplastic",
        ),
    ];
    for (hysteresis, expected) in cases {
        let mut doc = read(YIELDING);
        doc["specimen"]["storeys"][1]["hysteresis"] = hysteresis.clone();
        let e = load_error(&doc);
        assert!(e.contains(expected), "{hysteresis}: {e}");
    }
    let mut doc = read(YIELDING);
    doc["specimen"]["storeys"][0]["height_m"] = json!(0.0);
    let e = load_error(&doc);
    assert!(e.contains("specimen.storeys[0].height_m"), "{e}");
}

/// A yielding storey in the closed loop or on a multi-axis table is refused at its key,
/// naming the runs that take it, rather than run as a linear storey; a forward run takes it.
#[test]
fn runs_that_take_no_yielding_storey_yet_refuse_it() {
    let yielding = read(YIELDING)["specimen"].clone();
    let mut forward = read("scenarios/specimen/frame-forward.json");
    forward["specimen"] = yielding.clone();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("forward.json");
    std::fs::write(&path, serde_json::to_string(&forward).unwrap()).unwrap();
    let result = Scenario::load(&path).unwrap().run().unwrap();
    assert!(result.column("storey1_hysteretic_j").is_some());
    let mut table = read("scenarios/multi-axis/tower-inverse.json");
    table["specimen"] = yielding.clone();
    let e = load_error(&table);
    assert!(e.contains("specimen.storeys[0].hysteresis"), "{e}");
    let mut closed = read("scenarios/table-system/wn10g-closed-loop.json");
    closed["specimen"] = yielding;
    let e = load_error(&closed);
    assert!(
        e.contains("specimen.storeys[0].hysteresis") && e.contains("forward and inverse"),
        "{e}"
    );
}

/// The summary's per-storey figures are those of the run's own columns: the peak drift, the
/// residual (last) drift, the hysteretic energy at the end, and the ductility as the peak
/// drift over `F_y/k`.
#[test]
fn the_summary_reads_as_the_columns_do() {
    let scenario = Scenario::load(&shipped(YIELDING)).unwrap();
    let result = scenario.run().unwrap();
    let summary = serde_json::to_value(result.summary()).unwrap();
    let col = |name: &str| -> Vec<f64> {
        result
            .column(name)
            .unwrap_or_else(|| panic!("no column {name}"))
            .to_vec()
    };
    let doc = read(YIELDING);
    for i in 0..2 {
        let st = &summary["specimen"]["storeys"][i];
        let drift = col(&format!("storey{}_drift_m", i + 1));
        let peak = drift.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        assert_eq!(st["peak_drift_m"].as_f64().unwrap().abs(), peak);
        assert_eq!(
            st["residual_drift_m"].as_f64().unwrap(),
            *drift.last().unwrap()
        );
        let e = col(&format!("storey{}_hysteretic_j", i + 1));
        assert_eq!(st["hysteretic_j"].as_f64().unwrap(), *e.last().unwrap());
        let storey = &doc["specimen"]["storeys"][i];
        let yield_drift = storey["hysteresis"]["bilinear"]["yield_force_n"]
            .as_f64()
            .unwrap()
            / storey["stiffness_n_per_m"].as_f64().unwrap();
        let mu = st["ductility"].as_f64().unwrap();
        assert!((mu - peak / yield_drift).abs() < 1e-12 * mu, "{mu}");
        assert!(mu > 2.0, "storey {}: ductility {mu}", i + 1);
        assert!(st["yield_excursions"].as_u64().unwrap() >= 2);
        let ratio = st["peak_drift_ratio"].as_f64().unwrap();
        assert!((ratio - peak / 3.5).abs() < 1e-15, "{ratio}");
        // The restoring force never exceeds the bilinear envelope F_y + a·k·(|δ| − δ_y).
        let force = col(&format!("storey{}_force_n", i + 1));
        let k = storey["stiffness_n_per_m"].as_f64().unwrap();
        let a = storey["hysteresis"]["bilinear"]["post_yield_stiffness_ratio"]
            .as_f64()
            .unwrap();
        for (f, d) in force.iter().zip(&drift) {
            let envelope = k * yield_drift + a * k * (d.abs() - yield_drift).max(0.0);
            assert!(f.abs() <= envelope * (1.0 + 1e-9), "{f} N at {d} m");
        }
    }
}
