//! The closed loop's stability from its eigenvalues (`TableLinearisation::stability`) against
//! an independent NumPy reference (`tools/reference/multi_axis_poles.py`, from the equations,
//! with its own mechanics linearisation; `tests/data/multi_axis_poles/README.md`): a
//! swivel-vertical table stable with margin, the same table unstable in roll and pitch, and
//! the LHPOST6 preset.

use std::path::PathBuf;

use platen_model::multi_axis::Dof;
use platen_scenario::multi_axis::TableScenario;
use platen_system::TableLinearisation;
use serde_json::Value;

/// Relative agreement of the eigenvalues: the two sides linearise the mechanics by their own
/// central differences (truncation and round-off about 1e-9 of the entries) and take the
/// eigenvalues by different algorithms (balanced QR on both sides).
const POLE_TOLERANCE: f64 = 1e-6;

fn data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/multi_axis_poles")
}

#[test]
fn the_stability_verdict_agrees_with_the_independent_eigenvalues() {
    let reference: Value =
        serde_json::from_str(&std::fs::read_to_string(data().join("reference.json")).unwrap())
            .unwrap();
    for name in ["swivel-stable", "swivel-roll-pitch-unstable", "lhpost6"] {
        let path = data().join(format!("{name}.json"));
        let file =
            platen_scenario::scenario::parse(&path, &std::fs::read_to_string(&path).unwrap())
                .unwrap();
        let scenario = TableScenario::for_description(&path, &file).unwrap();
        let sys = scenario.system.as_ref().unwrap();
        let lin = TableLinearisation::new(
            &scenario.table,
            &sys.hydraulics,
            &sys.controller,
            scenario.specimen.as_ref(),
        )
        .unwrap();
        let st = lin.stability();
        let r = &reference[name];
        assert_eq!(st.stable, r["stable"].as_bool().unwrap(), "{name}");
        assert_eq!(st.states, r["states"].as_u64().unwrap() as usize, "{name}");
        assert_eq!(
            st.marginal_poles,
            r["marginal_poles"].as_u64().unwrap() as usize,
            "{name}"
        );
        let close = |a: f64, b: f64| (a - b).abs() <= POLE_TOLERANCE * b.abs().max(1.0);
        let largest = r["largest_real_part_beyond_marginal_1_s"].as_f64().unwrap();
        assert!(
            close(st.largest_real_part_1_s, largest),
            "{name}: {} against {largest}",
            st.largest_real_part_1_s
        );
        let poles = r["unstable_poles"].as_array().unwrap();
        assert_eq!(st.unstable_poles.len(), poles.len(), "{name}");
        for (p, q) in st.unstable_poles.iter().zip(poles) {
            let (re, hz) = (q[0].as_f64().unwrap(), q[1].as_f64().unwrap());
            assert!(close(p.re, re), "{name}: {p} against {re}");
            assert!(
                close(p.im / std::f64::consts::TAU, hz),
                "{name}: {p} against {hz} Hz"
            );
        }
        for d in Dof::ALL {
            let expected = r["open_loop_unstable_poles"][d.name()].as_u64().unwrap() as usize;
            assert_eq!(
                lin.open_loop_unstable_poles(d),
                Some(expected),
                "{name}: {}",
                d.name()
            );
            // Each DOF's Nyquist verdict, with those poles counted, is the loop's.
            assert_eq!(
                lin.margins(d).unwrap().stable,
                st.stable,
                "{name}: {}",
                d.name()
            );
        }
        if !st.stable {
            // The reference's mode puts 0.49 of its motion in roll and in pitch each.
            let dof = st.unstable_dof.unwrap();
            assert!(matches!(dof, Dof::Roll | Dof::Pitch), "{name}: {dof:?}");
        }
    }
}
