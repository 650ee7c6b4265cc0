//! Test data: the paper's periodic program (scenarios/paper-tests) regenerated at the paper's
//! 512 Hz recorder rate, run through an inverse run of an identified model, and turned into
//! recorded-like records (oil-column ringing, 246 Hz tone, noise) with fixed seeds.

#![allow(dead_code)]

use std::path::PathBuf;

use platen_ident::TestRecord;
use platen_integrate::{inverse, Motion, Trajectory};
use platen_model::{IdentifiedModel, IdentifiedParams, PlatenModel};
use platen_scenario::generate::{sine_motion, triangle_motion};
use platen_scenario::recorded::{recorded_like, ArtefactSettings};

/// The paper recorder's rate, Hz (§1.5).
pub const RATE_HZ: f64 = 512.0;

/// One test of the program: its name and motion parameters, read from the scenario file.
#[derive(Debug, Clone)]
pub struct ProgramTest {
    pub name: String,
    pub excitation: Excitation,
    pub duration_s: f64,
}

#[derive(Debug, Clone, Copy)]
pub enum Excitation {
    Sine {
        amplitude_m: f64,
        frequency_hz: f64,
    },
    Triangle {
        amplitude_m: f64,
        velocity_m_s: f64,
        reversal_acceleration_m_s2: f64,
    },
}

impl ProgramTest {
    pub fn motion(&self, rate_hz: f64) -> Motion {
        match self.excitation {
            Excitation::Sine {
                amplitude_m,
                frequency_hz,
            } => sine_motion(amplitude_m, frequency_hz, rate_hz, self.duration_s).unwrap(),
            Excitation::Triangle {
                amplitude_m,
                velocity_m_s,
                reversal_acceleration_m_s2,
            } => triangle_motion(
                amplitude_m,
                velocity_m_s,
                reversal_acceleration_m_s2,
                rate_hz,
                self.duration_s,
            )
            .unwrap(),
        }
    }

    pub fn is_sine(&self) -> bool {
        matches!(self.excitation, Excitation::Sine { .. })
    }
}

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The 24 tests of scenarios/paper-tests/13.8MPa (the program is the same at every pressure),
/// S1–S12 then T1–T12.
pub fn paper_program() -> Vec<ProgramTest> {
    let dir = workspace().join("scenarios/paper-tests/13.8MPa");
    let mut out = Vec::new();
    for prefix in ["S", "T"] {
        for k in 1..=12 {
            let name = format!("{prefix}{k}");
            let text = std::fs::read_to_string(dir.join(format!("{name}.json"))).unwrap();
            let v: serde_json::Value = serde_json::from_str(&text).unwrap();
            let exc = &v["excitation"];
            let excitation = if let Some(s) = exc.get("sine_motion") {
                Excitation::Sine {
                    amplitude_m: s["amplitude_m"].as_f64().unwrap(),
                    frequency_hz: s["frequency_hz"].as_f64().unwrap(),
                }
            } else {
                let t = &exc["triangle_motion"];
                Excitation::Triangle {
                    amplitude_m: t["amplitude_m"].as_f64().unwrap(),
                    velocity_m_s: t["velocity_m_s"].as_f64().unwrap(),
                    reversal_acceleration_m_s2: t["reversal_acceleration_m_s2"].as_f64().unwrap(),
                }
            };
            out.push(ProgramTest {
                name,
                excitation,
                duration_s: v["duration_s"].as_f64().unwrap(),
            });
        }
    }
    out
}

/// The artefacts switched off: exact force, displacement and acceleration (the velocity is
/// still the crossover estimate from them).
pub fn noise_free() -> ArtefactSettings {
    ArtefactSettings {
        oil_column_fraction: 0.0,
        valve_tone_n: 0.0,
        pressure_resolution_pa: 0.0,
        force_noise_n: 0.0,
        displacement_noise_m: 0.0,
        displacement_resolution_m: 0.0,
        acceleration_noise_m_s2: 0.0,
        accelerometer_cutoff_hz: 1e9,
        ..ArtefactSettings::default()
    }
}

/// A recorded-like record of `test` on `model` (pressure `pressure_pa`), named `name`.
pub fn record(
    name: &str,
    test: &ProgramTest,
    params: &IdentifiedParams,
    pressure_pa: f64,
    artefacts: &ArtefactSettings,
    seed: u64,
) -> TestRecord {
    record_of_motion(
        name,
        &test.motion(RATE_HZ),
        params,
        pressure_pa,
        artefacts,
        seed,
    )
}

/// A recorded-like record of any motion on `params`.
pub fn record_of_motion(
    name: &str,
    motion: &Motion,
    params: &IdentifiedParams,
    pressure_pa: f64,
    artefacts: &ArtefactSettings,
    seed: u64,
) -> TestRecord {
    let model: IdentifiedModel = params.build().unwrap();
    let mut truth = Trajectory::with_capacity(motion.len());
    inverse(&model, motion, &mut truth);
    let rec = recorded_like(&truth, model.static_threshold_n(0.0), artefacts, seed).unwrap();
    TestRecord::new(name, &rec.t_s, rec.u_m, rec.a_m_s2, rec.force_n)
        .unwrap()
        .with_velocity(rec.v_m_s)
        .unwrap()
        .with_pressure_pa(pressure_pa)
        .unwrap()
}

/// The tests of the program with these names (`"S4"`, `"T12"`, …), in the order given.
pub fn tests_named(names: &[&str]) -> Vec<ProgramTest> {
    let all = paper_program();
    names
        .iter()
        .map(|n| all.iter().find(|t| t.name == *n).unwrap().clone())
        .collect()
}

/// Records of the named tests at 13.8 MPa on the `lhpost-2008` preset.
pub fn nominal_records(
    names: &[&str],
    artefacts: &ArtefactSettings,
    seed0: u64,
) -> Vec<TestRecord> {
    let params = platen_model::preset::lhpost_2008_identified(13.8e6);
    tests_named(names)
        .iter()
        .enumerate()
        .map(|(k, t)| record(&t.name, t, &params, 13.8e6, artefacts, seed0 + k as u64))
        .collect()
}

/// The whole program at one pressure on the `lhpost-2008` preset, seeds `seed0 + k`.
pub fn paper_records(
    pressure_pa: f64,
    artefacts: &ArtefactSettings,
    seed0: u64,
) -> Vec<TestRecord> {
    let params = platen_model::preset::lhpost_2008_identified(pressure_pa);
    paper_program()
        .iter()
        .enumerate()
        .map(|(k, t)| {
            record(
                &format!("{}@{}MPa", t.name, pressure_pa / 1e6),
                t,
                &params,
                pressure_pa,
                artefacts,
                seed0 + k as u64,
            )
        })
        .collect()
}
