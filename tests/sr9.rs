//! The paper's SR9 check (Fig. 13) end to end: a recorded actuator force, low-passed at 0.6 Hz,
//! drives the model forward; the simulated displacement and velocity match the recorded ones.

use std::path::Path;

use platen::integrate::Method;
use platen::integrate::{inverse, Peaks, Trajectory};
use platen::io::csv::{read_table, write_csv_atomic};
use platen::model::PlatenModel;
use platen::scenario::recorded::{recorded_like, ArtefactSettings, Recorded};
use platen::scenario::{Model, PlatenScenario, Run};

fn nrmse(sim: &[f64], rec: &[f64]) -> f64 {
    let n = sim.len().min(rec.len());
    let e: f64 = (0..n).map(|i| (sim[i] - rec[i]).powi(2)).sum::<f64>() / n as f64;
    let r: f64 = rec[..n].iter().map(|x| x * x).sum::<f64>() / n as f64;
    (e / r).sqrt()
}

fn forward(s: &PlatenScenario) -> Trajectory {
    assert!(
        matches!(
            &s.run,
            Run::Forward {
                integrator: Method::Rk4(_),
                ..
            }
        ),
        "SR9 is a forward RK4 scenario"
    );
    let mut out = Trajectory::default();
    s.run(&mut out).unwrap();
    out
}

/// The bar (3 % NRMSE) is the issue's; measured 0.7 % on displacement and 1.5 % on velocity.
/// What remains is the force's harmonics above 0.6 Hz that the low-pass removes (the friction
/// jumps at reversals) and the recorded channels' noise.
#[test]
fn the_shipped_sr9_check_reproduces_the_recorded_motion_within_3_percent() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/sr9");
    let s = PlatenScenario::load(&dir.join("sr9-forward.json")).unwrap();
    let sim = forward(&s);
    let mut rec = read_table(&dir.join("sr9-recorded.csv"), &["t_s", "u_m", "v_m_s"], &[]).unwrap();
    let (u, v) = (
        rec.take_column("u_m").unwrap(),
        rec.take_column("v_m_s").unwrap(),
    );
    let (eu, ev) = (nrmse(&sim.u_m, &u), nrmse(&sim.v_m_s, &v));
    eprintln!(
        "SR9: NRMSE u = {:.2} %, v = {:.2} %",
        100.0 * eu,
        100.0 * ev
    );
    assert!(eu < 0.03 && ev < 0.03, "u {eu}, v {ev}");
}

/// The same check on an SR9-like record made with other model parameters (a heavier, stiffer,
/// rougher table), stronger artefacts and another seed; the check runs with those parameters.
#[test]
fn the_sr9_check_holds_for_other_parameters_and_artefacts() {
    let tmp = tempfile::tempdir().unwrap();
    let model = r#""model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": 160000, "stiffness_n_per_m": 1.5e6, "coulomb_force_n": 35000, "viscous_coefficient": 60000, "viscous_exponent": 0.6}}"#;
    let motion = tmp.path().join("m.json");
    std::fs::write(
        &motion,
        format!(r#"{{{model}, "excitation": {{"sine_motion": {{"amplitude_m": 0.38, "frequency_hz": 0.5, "sample_rate_hz": 512}}}}, "duration_s": 20}}"#),
    )
    .unwrap();
    let s = PlatenScenario::load(&motion).unwrap();
    let (Model::Identified(m), Run::Inverse { motion: mo }) = (&s.rig.model, &s.run) else {
        panic!()
    };
    let mut truth = (Trajectory::default(), Peaks::default());
    inverse(m, mo, &mut truth);
    let artefacts = ArtefactSettings {
        oil_column_fraction: 0.6,
        valve_tone_n: 5e3,
        force_noise_n: 1500.0,
        displacement_noise_m: 50e-6,
        ..ArtefactSettings::default()
    };
    let rec: Recorded =
        recorded_like(&truth.0, m.static_threshold_n(0.0), &artefacts, 2024).unwrap();
    let rec_path = tmp.path().join("rec.csv");
    write_csv_atomic(&rec_path, &Recorded::COLUMN_NAMES, &rec.columns()).unwrap();
    let fwd = tmp.path().join("f.json");
    std::fs::write(
        &fwd,
        format!(
            r#"{{{model}, "excitation": {{"force_csv": "rec.csv", "lowpass_hz": 0.6}}, "integrator": {{"method": "rk4", "step_s": 0.0009765625}}, "initial": {{"from_record": true}}}}"#
        ),
    )
    .unwrap();
    let sim = forward(&PlatenScenario::load(&fwd).unwrap());
    let (eu, ev) = (nrmse(&sim.u_m, &rec.u_m), nrmse(&sim.v_m_s, &rec.v_m_s));
    eprintln!(
        "SR9-like, other parameters: NRMSE u = {:.2} %, v = {:.2} %",
        100.0 * eu,
        100.0 * ev
    );
    assert!(eu < 0.03 && ev < 0.03, "u {eu}, v {ev}");
}
