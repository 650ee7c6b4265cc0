//! The multi-axis linearisation ([`TableLinearisation`]) of the loop test table
//! (`tools/reference/loop_table.json`) against the independent NumPy reference
//! `tools/reference/multi_axis_loop.py` (full Newton–Euler linearised by its own central
//! differences, per-actuator Merritt hydraulics, the DOF controller with force balance, hold
//! and delay, assembled as one system of its own). Its numbers are in
//! `tests/data/reference/multi_axis_loop_frf.json`, written by
//!
//! ```text
//! python3 tools/reference/multi_axis_loop.py tools/reference/loop_table.json \
//!     --freqs 0.5,1,2,5,10,20 --json tests/data/reference/multi_axis_loop_frf.json
//! ```
//!
//! (Python 3.11.7, NumPy 2.4.6, SciPy 1.17.1; the reference sets entries below 1e-12 of the
//! matrix's largest to exactly 0, the round-off of couplings that symmetry makes zero).

#[path = "common/loop_table.rs"]
mod loop_table;

use nalgebra::Complex;
use platen_model::multi_axis::Dof;
use platen_system::TableLinearisation;
use serde_json::Value;

fn reference() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/reference/multi_axis_loop_frf.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn linearisation() -> TableLinearisation {
    let rig = loop_table::loop_table();
    TableLinearisation::new(&rig.table, &rig.hydraulics, &rig.controller, None).unwrap()
}

/// Every entry of the command → pose matrix at 0.5, 1, 2, 5, 10 and 20 Hz within 1e-6 of
/// the largest entry of its column (the command's), and the static forces within 1e-9 of
/// the largest.
#[test]
fn the_transfer_matrix_matches_the_numpy_reference() {
    let rig = loop_table::loop_table();
    let lin = TableLinearisation::new(&rig.table, &rig.hydraulics, &rig.controller, None).unwrap();
    let r = reference();
    let f0_max = lin
        .actuators()
        .iter()
        .map(|a| a.static_force_n.abs())
        .fold(0.0, f64::max);
    for (a, actuator) in lin.actuators().iter().zip(rig.table.actuators()) {
        let name = &actuator.name;
        let expected = r["static_forces_n"][name].as_f64().unwrap();
        assert!(
            (a.static_force_n - expected).abs() < 1e-9 * f0_max,
            "{name}: {} vs {expected}",
            a.static_force_n
        );
    }
    let mut worst = 0.0f64;
    for (fi, f) in r["frequencies_hz"].as_array().unwrap().iter().enumerate() {
        let f = f.as_f64().unwrap();
        let h = lin.transfer_matrix(f);
        let at = |i: usize, j: usize| {
            Complex::new(
                r["real"][fi][i][j].as_f64().unwrap(),
                r["imag"][fi][i][j].as_f64().unwrap(),
            )
        };
        let mut worst_here = 0.0f64;
        for command in Dof::ALL {
            let j = command.index();
            let scale = (0..6).map(|i| at(i, j).norm()).fold(0.0, f64::max);
            for pose in Dof::ALL {
                let i = pose.index();
                let err = (h[i][j] - at(i, j)).norm() / scale;
                assert!(
                    err < 1e-6,
                    "{f} Hz, pose {} / command {}: {} vs {} ({err:.2e} of the column)",
                    pose.name(),
                    command.name(),
                    h[i][j],
                    at(i, j)
                );
                worst_here = worst_here.max(err);
            }
        }
        // The DOF's own response from its broken loop closed again (one solve per DOF, as
        // the margins use it) is the closed system's diagonal.
        for d in Dof::ALL {
            let own = lin.response(d, f).unwrap();
            let k = d.index();
            assert!(
                (own - h[k][k]).norm() < 1e-12 * h[k][k].norm(),
                "{f} Hz {}",
                d.name()
            );
        }
        println!("{f:5} Hz: worst difference {worst_here:.2e} of its column's largest entry");
        worst = worst.max(worst_here);
    }
    println!("worst: {worst:.2e}");
}

/// The per-DOF loops broken at their DOF drives (the others closed): the phase margin (the
/// smallest distance of `L_k` from −1 over its gain crossovers), the gain margin and the
/// first gain crossover as the reference finds them, within 1e-3° and dB and 1e-4 Hz (the
/// searches differ: its grid is 3000 points from 0.01 Hz to 2 kHz, ours 20 000 points from
/// 0.001 Hz to the controller's Nyquist frequency).
#[test]
fn the_margins_match_the_numpy_reference() {
    let lin = linearisation();
    let r = reference();
    // Two of the six (a horizontal DOF with three gain crossovers, a vertical one): each
    // search takes some 20 s in a debug build.
    for dof in [Dof::X, Dof::Pitch] {
        let m = lin.margins(dof).unwrap();
        let expected = &r["margins"][dof.name()];
        let pm = expected["phase_margin_deg"].as_f64().unwrap();
        let gm = expected["gain_margin_db"].as_f64().unwrap();
        let first = expected["first_crossover_hz"].as_f64().unwrap();
        println!(
            "{}: {m:?}; reference phase margin {pm}, gain margin {gm}",
            dof.name()
        );
        assert!(
            (m.phase_margin_deg.unwrap() - pm).abs() < 1e-3,
            "{}",
            dof.name()
        );
        assert!(
            (m.gain_margin_db.unwrap() - gm).abs() < 1e-3,
            "{}",
            dof.name()
        );
        let crossings = expected["gain_crossings"].as_array().unwrap();
        let lowest = crossings
            .iter()
            .map(|c| c["f_hz"].as_f64().unwrap())
            .fold(f64::INFINITY, f64::min);
        assert!((lowest - first).abs() < 1e-12);
        // Ours reports the crossover of the worst phase margin; the reference lists all.
        let at_worst = crossings
            .iter()
            .find(|c| (c["distance_deg"].as_f64().unwrap() - pm).abs() < 1e-9)
            .unwrap()["f_hz"]
            .as_f64()
            .unwrap();
        assert!((m.gain_crossover_hz.unwrap() - at_worst).abs() < 1e-4);
        assert!(m.stable, "{}", dof.name());
    }
}
