//! The inverse run's velocity dead band (`Motion::with_rest_velocity`): a table standing
//! still with a noisy measured velocity gets the static friction reaction, not `sign(v)·F_s`.

use platen_integrate::{inverse, IntegrateError, Motion, Peaks, Trajectory};
use platen_model::preset::lhpost_2008_identified;
use platen_model::PlatenModel;

/// SplitMix64 and Box–Muller: seeded noise, the same numbers every run.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (((z ^ (z >> 31)) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// 10 s at 1024 Hz of a table standing at `u_m`: displacement exact, velocity with 1 mm/s
/// and acceleration with 0.02 m/s² of measurement noise (an estimated velocity and an
/// accelerometer at rest).
fn standing_still(u_m: f64) -> Motion {
    let mut rng = Rng(5);
    let n = 10_241;
    let t = (0..n).map(|i| i as f64 / 1024.0).collect();
    let v = (0..n).map(|_| 1e-3 * rng.normal()).collect();
    let a = (0..n).map(|_| 0.02 * rng.normal()).collect();
    Motion::new(t, vec![u_m; n], v, a).unwrap()
}

fn sign_changes(x: &[f64]) -> usize {
    x.windows(2).filter(|w| w[0] * w[1] < 0.0).count()
}

/// At u = 0.05 m the struts push with `Kₑu` = 63.3 kN, more than the static threshold
/// `F_s = F_μ + a` = 25.445 + 12.04 = 37.485 kN: friction holds `F_s` of it and the actuator
/// the rest, `F_A = Kₑu + Mₑa − F_s` (the noise of `a` is in it, as given). Without the dead
/// band `F_D = sign(v)·D(|v|)` flips by about `2F_s` = 75 kN thousands of times.
#[test]
fn a_noisy_table_at_rest_gets_the_static_reaction_and_no_sign_flipping() {
    let model = lhpost_2008_identified(13.8e6).build().unwrap();
    let f_s = model.static_threshold_n(0.05);
    assert!((f_s - (0.0044 * 5.783e6 + 12.04e3)).abs() < 1.0, "{f_s}");

    let noisy = standing_still(0.05);
    let mut plain = Trajectory::default();
    inverse(&model, &noisy, &mut plain);
    let flips = sign_changes(&plain.dissipative_force_n);
    assert!(flips > 1000, "without a dead band: {flips} sign changes");

    let banded = noisy.clone().with_rest_velocity(0.005).unwrap();
    let mut held = (Trajectory::default(), Peaks::default());
    inverse(&model, &banded, &mut held);
    let (out, peaks) = held;
    assert_eq!(sign_changes(&out.dissipative_force_n), 0);
    assert_eq!(peaks.stuck_samples, out.t_s.len());
    for i in 0..out.t_s.len() {
        let s = 1.266e6 * 0.05 + 144e3 * noisy.a_m_s2()[i];
        assert_eq!(out.dissipative_force_n[i], -f_s, "sample {i}");
        assert!((out.force_n[i] - (s - f_s)).abs() < 1e-6, "sample {i}");
    }
}

/// Nearer the centre friction holds everything: at u = 0.01 m, `Kₑu` = 12.7 kN < `F_s`, so the
/// actuator force is zero and `F_D = −(F_E + F_I)` exactly.
#[test]
fn within_the_friction_cone_the_actuator_force_is_zero() {
    let model = lhpost_2008_identified(13.8e6).build().unwrap();
    let motion = standing_still(0.01).with_rest_velocity(0.005).unwrap();
    let mut out = Trajectory::default();
    inverse(&model, &motion, &mut out);
    for i in 0..out.t_s.len() {
        assert_eq!(out.force_n[i], 0.0);
        assert_eq!(
            out.dissipative_force_n[i],
            -(out.inertial_force_n[i] + out.elastic_force_n[i])
        );
    }
}

/// Outside the band nothing changes: a sine at 0.75 m/s peak, band 1 mm/s, differs from the
/// run without one only at the samples where |v| ≤ 1 mm/s.
#[test]
fn the_dead_band_changes_only_the_samples_inside_it() {
    let model = lhpost_2008_identified(13.8e6).build().unwrap();
    let w = 2.0 * std::f64::consts::PI * 0.6;
    let n = 5 * 1024;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / 1024.0).collect();
    let u = t.iter().map(|t| 0.2 * (w * t).sin()).collect();
    let v: Vec<f64> = t.iter().map(|t| 0.2 * w * (w * t).cos()).collect();
    let a = t.iter().map(|t| -0.2 * w * w * (w * t).sin()).collect();
    let motion = Motion::new(t, u, v.clone(), a).unwrap();
    let mut plain = Trajectory::default();
    inverse(&model, &motion, &mut plain);
    let mut banded = Trajectory::default();
    inverse(
        &model,
        &motion.clone().with_rest_velocity(1e-3).unwrap(),
        &mut banded,
    );
    let mut inside = 0;
    for (i, vi) in v.iter().enumerate() {
        if vi.abs() <= 1e-3 {
            inside += 1;
        } else {
            assert_eq!(plain.force_n[i], banded.force_n[i], "sample {i}");
        }
    }
    assert!(inside > 0, "the sine never enters the band");
}

#[test]
fn a_dead_band_that_is_not_a_positive_velocity_is_rejected() {
    for bad in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        let e = IntegrateError::from(standing_still(0.0).with_rest_velocity(bad).unwrap_err());
        assert!(
            matches!(e, IntegrateError::InvalidRestVelocity { .. }),
            "{bad}: {e:?}"
        );
    }
}
