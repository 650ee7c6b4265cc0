//! Input mutation in the normal test suite (the cargo-fuzz targets under `fuzz/` do the same
//! at length): valid scenario JSON, CSV records and PEER files, mutated at random (seeded), are
//! either accepted or rejected with an error; the readers never panic, and an error always
//! names the file.

use std::path::Path;

use platen_io::csv::read_table;
use platen_io::peer::read_peer;
use platen_scenario::scenario::parse;
use platen_scenario::PlatenScenario;
use proptest::prelude::*;

const SCENARIO: &str = r#"{
  "name": "m",
  "model": { "preset": "lhpost-2008", "hold_down_pressure_mpa": 13.8, "identified": { "coulomb_force_n": 25000 } },
  "excitation": { "force_csv": "f.csv", "lowpass_hz": 8.0 },
  "integrator": { "method": "rk4", "step_s": 0.0009765625 },
  "initial": { "u_m": 0.0, "v_m_s": 0.0 },
  "duration_s": 0.004
}"#;

const CSV: &str = "t_s,force_n,u_m\n0,0,0\n0.0009765625,1000,0\n0.001953125,2000.5,1e-9\n0.0029296875,-3.5e3,2\n0.00390625,4,5\n";

const PEER: &str = "PEER NGA STRONG MOTION DATABASE RECORD\nTest, 1/1/2000, Station, 90\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS=   6, DT=   .0100 SEC,\n  .1E+00 -.2E+00  .3E-01 -.4E-02\n  .5E-03 -.6E-04\n";

/// A mutation: replace, insert or delete bytes at seeded positions, or truncate.
fn mutate(base: &'static str) -> impl Strategy<Value = Vec<u8>> {
    let len = base.len();
    prop::collection::vec((0usize..4, 0usize..len.max(1), any::<u8>()), 1..6).prop_map(move |ops| {
        let mut b = base.as_bytes().to_vec();
        for (op, at, byte) in ops {
            let at = at.min(b.len());
            match op {
                0 if at < b.len() => b[at] = byte,
                1 => b.insert(at, byte),
                2 if at < b.len() => {
                    b.remove(at);
                }
                _ => b.truncate(at),
            }
        }
        b
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, rng_seed: proptest::test_runner::RngSeed::Fixed(8), ..ProptestConfig::default() })]

    #[test]
    fn mutated_scenarios_are_accepted_or_rejected_without_panic(json in mutate(SCENARIO), csv in mutate(CSV)) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("f.csv"), &csv).unwrap();
        let path = dir.path().join("s.json");
        std::fs::write(&path, &json).unwrap();
        if let Err(e) = PlatenScenario::load(&path) {
            // The message names the scenario, or the (possibly mutated) record path it resolved.
            let msg = e.to_string();
            let dir_name = dir.path().display().to_string();
            prop_assert!(msg.contains("s.json") || msg.contains(&dir_name), "{}", msg);
        }
        // The parser alone, on text that may not even be UTF-8.
        let text = String::from_utf8_lossy(&json);
        let _ = parse(Path::new("s.json"), &text);
    }

    #[test]
    fn mutated_csv_records_are_accepted_or_rejected_without_panic(csv in mutate(CSV)) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.csv");
        std::fs::write(&path, &csv).unwrap();
        match read_table(&path, &["t_s", "force_n"], &["u_m"]) {
            Ok(t) => {
                let time = t.column("t_s").unwrap();
                prop_assert!(time.windows(2).all(|w| w[1] > w[0]));
                prop_assert!(t.column("force_n").unwrap().iter().all(|x| x.is_finite()));
            }
            Err(e) => prop_assert!(e.to_string().contains("r.csv"), "{}", e),
        }
    }

    #[test]
    fn mutated_peer_files_are_accepted_or_rejected_without_panic(at2 in mutate(PEER)) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.AT2");
        std::fs::write(&path, &at2).unwrap();
        match read_peer(&path) {
            Ok(r) => {
                prop_assert!(r.values.iter().all(|x| x.is_finite()));
                prop_assert!(r.dt_s > 0.0 && r.values.len() >= 2);
            }
            Err(e) => prop_assert!(e.to_string().contains("r.AT2"), "{}", e),
        }
    }
}
