//! Smoke test of `platen bench`: it runs briefly and reports every figure (not a timing test).

use std::process::Command;

#[test]
fn bench_json_reports_every_figure_as_a_positive_number() {
    let o = Command::new(env!("CARGO_BIN_EXE_platen"))
        .args(["bench", "--json", "--seconds", "2", "--repeats", "1"])
        .output()
        .expect("run platen");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let b: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for key in [
        "rk4_ns_per_step",
        "rk4_full_ns_per_step",
        "dopri5_ns_per_accepted_step",
        "inverse_ns_per_sample",
        "baseline_ns_per_step",
        "rk4_ratio_to_baseline",
        "rk4_full_ratio_to_baseline",
        "rk4_steps_per_s",
        "rk4_simulated_s_per_wall_s",
        "ensemble_ns_per_step_per_trajectory",
        "ensemble_scalar_ns_per_step",
        "ensemble_ratio_to_scalar",
        "six_dof_closed_loop_ns_per_step",
        "six_dof_closed_loop_ratio_to_table_system",
    ] {
        let v = b[key]
            .as_f64()
            .unwrap_or_else(|| panic!("missing {key}: {b}"));
        assert!(v.is_finite() && v > 0.0, "{key} = {v}");
    }
    for workload in ["baseline", "rk4", "rk4_full", "dopri5", "inverse"] {
        let w = &b["workloads"][workload];
        for key in ["ns_per_unit", "units_per_s", "simulated_s_per_wall_s"] {
            let v = w[key]
                .as_f64()
                .unwrap_or_else(|| panic!("{workload}.{key}"));
            assert!(v.is_finite() && v > 0.0, "{workload}.{key} = {v}");
        }
    }
    // 2 s at 1024 Hz, one step per sample.
    assert_eq!(b["workloads"]["rk4"]["units_per_run"], 2048);
}

#[test]
fn bench_rejects_a_bad_duration_as_a_usage_error() {
    let o = Command::new(env!("CARGO_BIN_EXE_platen"))
        .args(["bench", "--seconds", "0"])
        .output()
        .expect("run platen");
    assert_eq!(o.status.code(), Some(2));
}
