//! `platen simulate` on frictionless tables (issue 26): a scenario whose model overrides the
//! identified friction to zero (`coulomb_force_n = low_velocity_force_n = 0`, so `F_s = 0`)
//! and the stiffness to zero runs to the end and writes its CSV with either integrator; a
//! negative stiffness is still refused.

use std::path::Path;

mod common;
use common::{platen, stderr};

/// A scenario on the LHPOST preset with the friction and stiffness overridden, driven by a
/// 1 N, 1.5 Hz sine force for 2 s at 1024 Hz: a force that hovers around zero, so the platen
/// creeps through `v = 0` at every sign change (the records that made "4097 stick-slip
/// events inside one step").
fn scenario(dir: &Path, name: &str, stiffness: f64, alpha: f64, integrator: &str) -> String {
    let text = format!(
        r#"{{
  "name": "frictionless {name}",
  "model": {{
    "preset": "lhpost-2008",
    "identified": {{
      "coulomb_force_n": 0,
      "low_velocity_force_n": 0,
      "stiffness_n_per_m": {stiffness},
      "viscous_exponent": {alpha}
    }}
  }},
  "excitation": {{
    "sine_force": {{ "amplitude_n": 1.0, "frequency_hz": 1.5, "sample_rate_hz": 1024 }}
  }},
  "integrator": {integrator},
  "duration_s": 2.0
}}"#
    );
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn simulate_runs_a_frictionless_stiffness_free_table_with_both_integrators() {
    let dir = tempfile::tempdir().unwrap();
    for (name, alpha, integrator) in [
        (
            "rk4-half",
            0.5,
            r#"{ "method": "rk4", "step_s": 0.0009765625 }"#,
        ),
        ("dopri5-half", 0.5, r#"{ "method": "dopri5" }"#),
        (
            "rk4-linear",
            1.0,
            r#"{ "method": "rk4", "step_s": 0.0009765625 }"#,
        ),
    ] {
        let path = scenario(dir.path(), name, 0.0, alpha, integrator);
        let csv = dir.path().join(format!("{name}.csv"));
        let out = platen(&["simulate", &path, "--out", csv.to_str().unwrap()]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(&header[..4], ["t_s", "u_m", "v_m_s", "a_m_s2"], "{name}");
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
            .collect();
        // 2 s at 1024 Hz: 2049 samples, the last at 2 s, every value finite.
        assert_eq!(rows.len(), 2049, "{name}");
        assert_eq!(rows[2048][0], 2.0, "{name}");
        assert!(rows.iter().flatten().all(|x| x.is_finite()), "{name}");
    }
}

#[test]
fn simulate_still_refuses_a_negative_stiffness() {
    let dir = tempfile::tempdir().unwrap();
    let path = scenario(
        dir.path(),
        "negative",
        -1.0,
        0.5,
        r#"{ "method": "rk4", "step_s": 0.0009765625 }"#,
    );
    let csv = dir.path().join("negative.csv");
    let out = platen(&["simulate", &path, "--out", csv.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("stiffness_n_per_m"),
        "{}",
        stderr(&out)
    );
    assert!(!csv.exists(), "no half-written output");
}
