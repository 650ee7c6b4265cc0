//! The shipped specimen examples (`scenarios/specimen/`): they run, carry the specimen's
//! output, and the forward one closes its energy balance (platen and specimen) to the issue's
//! 1e-10 of the largest energy flow. The balance is an accuracy indicator: RK4 conserves it only
//! to its truncation error, so it fails when a phase (stick, creep, slip) integrates with a
//! lower order than RK4's fourth, as the specimen's creep once did (second order: 3.3e-10 at
//! 1/4096 s, now 5e-13).

use std::path::{Path, PathBuf};

use platen_integrate::{Sample, SampleSink, Trajectory};
use platen_scenario::Scenario;

/// Every sample, specimen part included.
#[derive(Default)]
struct Samples(Vec<Sample>);

impl SampleSink for Samples {
    fn accept(&mut self, s: &Sample) {
        self.0.push(*s);
    }
}

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/specimen")
        .join(name)
}

#[test]
fn the_forward_specimen_example_closes_its_energy_balance() {
    let scenario = Scenario::load(&shipped("frame-forward.json")).unwrap();
    assert!(scenario.specimen.is_some());
    let mut trajectory = Trajectory::default();
    let output = scenario.run(&mut trajectory).unwrap();
    let stats = output.stats.expect("a forward run has solver statistics");
    let energy = stats.energy;
    eprintln!(
        "frame-forward: relative residual {:e} ({:e} J); specimen end {} J, dissipated {} J",
        energy.relative_residual(),
        energy.residual_j(),
        energy.specimen_end_j,
        energy.specimen_dissipated_j
    );
    assert!(energy.specimen_end_j > 1.0 && energy.specimen_dissipated_j > 1.0);
    assert!(stats.stick_events + stats.breakaways > 0, "{stats:?}");
    assert!(
        energy.relative_residual().abs() <= 1e-10,
        "{:e}",
        energy.relative_residual()
    );
}

#[test]
fn the_inverse_specimen_example_adds_the_base_shear() {
    let scenario = Scenario::load(&shipped("frame-inverse.json")).unwrap();
    let mut samples = Samples::default();
    scenario.run(&mut samples).unwrap();
    let peak = |xs: &[f64]| xs.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let base: Vec<f64> = samples
        .0
        .iter()
        .map(|s| s.specimen.expect("specimen output").base_shear_n)
        .collect();
    assert!(peak(&base) > 1e3, "peak base shear {}", peak(&base));
}
