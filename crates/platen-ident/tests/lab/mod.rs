//! The independent test records of `tests/data/any-record` (made by
//! `tools/record_reference/make_records.py` with NumPy/SciPy, not by platen): reading them
//! as a lab's files, their truth, and seeded noise for the coverage study.

#![allow(dead_code)]

use std::path::PathBuf;

use platen_ident::TestRecord;
use platen_io::csv::read_table;
use platen_model::{DissipativeLaw, Exponent, IdentifiedKey};

/// The folder of the records.
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/any-record")
}

/// `truth.json`.
pub fn truth() -> serde_json::Value {
    let text = std::fs::read_to_string(data_dir().join("truth.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The true value of `key`.
pub fn true_value(key: IdentifiedKey) -> f64 {
    truth()["identified"][key.name()].as_f64().unwrap()
}

/// The true dissipative law.
pub fn true_law() -> DissipativeLaw {
    let v = |k| true_value(k);
    DissipativeLaw {
        coulomb_force_n: v(IdentifiedKey::CoulombForce),
        viscous_coefficient: v(IdentifiedKey::ViscousCoefficient),
        exponent: Exponent::new(v(IdentifiedKey::ViscousExponent)),
        low_velocity_force_n: v(IdentifiedKey::LowVelocityForce),
        low_velocity_decay_s_per_m: v(IdentifiedKey::LowVelocityDecay),
    }
}

/// The sample rate of a time column with rounded stamps: the least-squares slope of `t`
/// against the sample number, which is what a fitted-grid check accepts.
pub fn fitted_rate_hz(t: &[f64]) -> f64 {
    let n = t.len() as f64;
    let mean_k = (n - 1.0) / 2.0;
    let mean_t = t.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (k, &tk) in t.iter().enumerate() {
        let dk = k as f64 - mean_k;
        sxy += dk * (tk - mean_t);
        sxx += dk * dk;
    }
    sxx / sxy
}

/// A lab file (`Time` s, `Table Disp` mm, `Table Acc` mm/s², `dP` MPa × 0.15 m²), with the
/// floor accelerometers `Floor i Acc` (mm/s²) of `storeys` storeys, as a record in SI units.
pub fn lab_record(file: &str, storeys: usize) -> TestRecord {
    let path = data_dir().join(file);
    let floors: Vec<String> = (1..=storeys).map(|i| format!("Floor {i} Acc")).collect();
    let mut cols = vec!["Time", "Table Disp", "Table Acc", "dP"];
    cols.extend(floors.iter().map(String::as_str));
    let table = read_table(&path, &cols, &[]).unwrap();
    let col =
        |c: &str, f: f64| -> Vec<f64> { table.column(c).unwrap().iter().map(|x| x * f).collect() };
    let t = col("Time", 1.0);
    let area = truth()["area_m2"].as_f64().unwrap();
    let rec = TestRecord::from_rate(
        file,
        fitted_rate_hz(&t),
        col("Table Disp", 1e-3),
        col("Table Acc", 1e-3),
        col("dP", 1e6 * area),
    )
    .unwrap();
    if storeys == 0 {
        return rec;
    }
    let masses: Vec<f64> = truth()["storeys"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["mass_kg"].as_f64().unwrap())
        .collect();
    let floors: Vec<(f64, Vec<f64>)> = floors
        .iter()
        .zip(masses)
        .map(|(c, m)| (m, col(c, 1e-3)))
        .collect();
    rec.with_floors(&floors).unwrap()
}

/// A deterministic generator: splitmix64 uniforms, Box–Muller normals.
pub struct Rng(pub u64);

impl Rng {
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Noise-free truth `coverage-K.csv` with the lab's noise model of `truth.json` added
/// (white noise on u and a, white plus AR(1) noise on the force, the offsets), seeded.
pub fn coverage_record(k: usize, seed: u64) -> TestRecord {
    let path = data_dir().join(format!("coverage-{k}.csv"));
    let table = read_table(&path, &["u_m", "a_m_s2", "force_n"], &[]).unwrap();
    let t = truth();
    let noise = &t["noise_si"];
    let off = &t["offsets_si"];
    let g = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    let mut rng = Rng(seed);
    let u: Vec<f64> = table
        .column("u_m")
        .unwrap()
        .iter()
        .map(|x| x + g(off, "u_m") + g(noise, "u_m") * rng.normal())
        .collect();
    let a: Vec<f64> = table
        .column("a_m_s2")
        .unwrap()
        .iter()
        .map(|x| x + g(off, "a_m_s2") + g(noise, "a_m_s2") * rng.normal())
        .collect();
    let (sigma, rho) = (g(noise, "force_ar_n"), g(noise, "force_ar_rho"));
    let mut ar = sigma * rng.normal();
    let f: Vec<f64> = table
        .column("force_n")
        .unwrap()
        .iter()
        .map(|x| {
            ar = rho * ar + sigma * (1.0 - rho * rho).sqrt() * rng.normal();
            x + g(off, "force_n") + g(noise, "force_white_n") * rng.normal() + ar
        })
        .collect();
    TestRecord::from_rate(
        format!("coverage-{k} seed {seed}"),
        t["sample_rate_hz"].as_f64().unwrap(),
        u,
        a,
        f,
    )
    .unwrap()
}
