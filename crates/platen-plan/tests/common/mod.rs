//! Shared helpers of the planning tests: scenarios built in memory and a synthetic,
//! earthquake-like accelerogram (no PEER record needed).

#![allow(dead_code)]

use std::f64::consts::PI;
use std::path::Path;

use platen_scenario::{file, Arrays, LoadedRig, PlatenScenario};

/// Standard gravity, m/s².
pub const G: f64 = 9.806_65;

/// A scenario built from `json` (a scenario file without excitation source) with the
/// displacement command `u_m` at `t_s` as its excitation, exactly as a `motion_csv` holding
/// `t_s` and `u_m` would give it.
pub fn scenario_with(json: &str, t_s: Vec<f64>, u_m: Vec<f64>) -> PlatenScenario {
    let settings = file::parse(Path::new("plan-test.json"), json).unwrap();
    PlatenScenario::from_arrays(
        Path::new("plan-test.json"),
        settings,
        Arrays::Motion {
            t_s,
            u_m,
            v_m_s: None,
            a_m_s2: None,
        },
    )
    .unwrap()
}

/// The rig of the scenario `json` (its excitation, if any, is not read): what the planner
/// drives.
pub fn scenario(json: &str) -> LoadedRig {
    LoadedRig::parse(Path::new("plan-test.json"), json).unwrap()
}

/// The LHPOST preset's scenario JSON: identified platen and its table system (`extra` is
/// spliced into the object, e.g. `, "specimen": {…}`).
pub fn lhpost_json(extra: &str) -> String {
    format!(
        r#"{{"model": {{"preset": "lhpost-2008"}}, "table_system": {{"preset": "lhpost-2008"}},
            "excitation": {{}}{extra}}}"#
    )
}

/// The LHPOST preset (see [`lhpost_json`]).
pub fn lhpost(extra: &str) -> LoadedRig {
    scenario(&lhpost_json(extra))
}

/// The two-storey frame of scenarios/specimen (55 t, modes 3.0 and 7.06 Hz).
pub const TWO_STOREYS: &str = r#", "specimen": {"storeys": [
    {"mass_kg": 30000.0, "stiffness_n_per_m": 27083177.88, "damping_n_s_per_m": 86208.43},
    {"mass_kg": 25000.0, "stiffness_n_per_m": 19345127.06, "damping_n_s_per_m": 61577.45}]}"#;

/// A small deterministic generator (SplitMix64).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// An earthquake-like accelerogram: `components` sines between 0.3 and 20 Hz with random
/// phases, amplitudes shaped by a Kanai–Tajimi spectrum (ground 2.5 Hz, ζ 0.6), under a
/// Saragoni–Hart-like envelope (quiet first 0.5 s, build-up, strong phase, decay), scaled to
/// `peak_g`. `duration_s` at `rate_hz`, from `t = 0`.
pub fn accelerogram(seed: u64, duration_s: f64, rate_hz: f64, peak_g: f64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Rng::new(seed);
    let n = (duration_s * rate_hz).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|j| j as f64 / rate_hz).collect();
    let components = 300;
    let (f_lo, f_hi) = (0.3_f64, 20.0_f64);
    let mut parts = Vec::with_capacity(components);
    for _ in 0..components {
        let f = f_lo * (f_hi / f_lo).powf(rng.uniform());
        let phase = 2.0 * PI * rng.uniform();
        let (fg, zg) = (2.5, 0.6);
        let r = f / fg;
        let kt = ((1.0 + 4.0 * zg * zg * r * r) / ((1.0 - r * r).powi(2) + 4.0 * zg * zg * r * r))
            .sqrt();
        // Equal energy per log-frequency band: amplitude ∝ √f × Kanai–Tajimi.
        parts.push((f, phase, kt * f.sqrt()));
    }
    let envelope = |t: f64| {
        let s = t - 0.5;
        if s <= 0.0 {
            0.0
        } else if s < 2.0 {
            (s / 2.0).powi(2)
        } else if s < 0.5 * duration_s {
            1.0
        } else {
            (-(s - 0.5 * duration_s) * 6.0 / duration_s).exp()
                * (1.0 - ((t - duration_s + 0.5) / 0.5).clamp(0.0, 1.0))
        }
    };
    let mut a: Vec<f64> = t
        .iter()
        .map(|&ti| {
            envelope(ti)
                * parts
                    .iter()
                    .map(|(f, ph, amp)| amp * (2.0 * PI * f * ti + ph).sin())
                    .sum::<f64>()
        })
        .collect();
    let peak = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for v in &mut a {
        *v *= peak_g * G / peak;
    }
    (t, a)
}
