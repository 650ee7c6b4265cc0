//! A forward RK4 sweep runs its cases as ensembles (SIMD lanes); every case's peaks,
//! statistics and error are still those of its own scalar run (`Model::run` on the scaled
//! excitation), to the bit, with 1, 2 or 3 threads (other groupings of the lanes).

use std::path::Path;

use platen_integrate::Peaks;
use platen_model::IdentifiedKey;
use platen_scenario::sweep::{Outcome, SetAxis, Sweep};
use platen_scenario::{ModelKey, PlatenScenario};

fn scenario() -> PlatenScenario {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/sr9-like-sine-force.json");
    PlatenScenario::load(&path).unwrap()
}

/// Everything an outcome holds, as text (`{:?}` of an f64 round-trips: equal text is equal
/// bits).
fn text(o: &Outcome) -> String {
    format!("{:?} {:?} {:?}", o.peaks, o.stats, o.error)
}

#[test]
fn forward_sweep_cases_are_their_scalar_runs_bit_for_bit_on_any_number_of_threads() {
    let scenario = scenario();
    // Scales from never leaving rest to past the stroke, three pressures, and two exponents
    // (0.5 takes the square-root lanes, 0.4 powf per lane).
    let exponent = SetAxis {
        name: "identified.viscous_exponent".to_owned(),
        key: ModelKey::Identified(IdentifiedKey::ViscousExponent),
        values: vec![0.5, 0.4],
    };
    let sweep = Sweep::new(
        &scenario,
        &[0.3, 0.5, 1.0, 1.5],
        &[0.0, 6.9, 13.8],
        &[exponent],
    )
    .unwrap();
    let scalar: Vec<String> = sweep
        .cases
        .iter()
        .map(|case| {
            let run = scenario.run.scaled(case.scale).unwrap();
            let mut peaks = Peaks::default();
            let output = case.model.run(&run, &mut peaks).unwrap();
            text(&Outcome {
                peaks,
                stats: output.stats,
                error: None,
            })
        })
        .collect();
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let outcomes = pool.install(|| sweep.run(&scenario.run, || {}));
        assert_eq!(outcomes.len(), scalar.len());
        for (i, (o, s)) in outcomes.iter().zip(&scalar).enumerate() {
            assert_eq!(&text(o), s, "case {i}, {threads} threads");
        }
    }
}
