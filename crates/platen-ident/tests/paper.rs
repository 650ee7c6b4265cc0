//! The paper's identification (§3) reproduced on recorded-like data of its own test program.
//!
//! The data: the S1–S12 and T1–T12 programs of `scenarios/paper-tests/` at 0, 6.9 and
//! 13.8 MPa, sampled at the paper's 512 Hz recorder rate, run through the `lhpost-2008`
//! identified model (Eq. 22: Mₑ = 144 t, Kₑ = 1.266 MN/m at 13.8 MPa, F_μ = 0.44 % of F_z,
//! Cₑ = 44.58 kN/(m/s)^0.5, a = 12.04 kN, b = 78.5 s/m) and given the artefacts of the paper's
//! records: 10.66 Hz oil-column ringing after every reversal (30 % of the friction jump), the
//! 246 Hz valve tone, pressure resolution, force, displacement and acceleration noise, the
//! accelerometer's 100 Hz conditioner and the crossover velocity. Seeds are fixed.
//!
//! Tolerances are the issue's, and what the paper's own tables show: Table I spans
//! 1.24–1.27 MN/m; Table II's reliable tests give 144 t; §3.3–3.4 give 26.0 kN,
//! 44.58 kN/(m/s)^0.5 and μₑ = 0.44 %.

mod common;

use std::sync::OnceLock;

use platen_ident::{identify, Flag, Identification, IdentifiedKey, TestKind, ValidSettings};

/// The whole program at the three pressures, identified once for every test of this file.
fn program() -> &'static Identification {
    static ID: OnceLock<Identification> = OnceLock::new();
    ID.get_or_init(|| {
        let mut records = Vec::new();
        for (k, p) in [0.0, 6.9e6, 13.8e6].into_iter().enumerate() {
            records.extend(common::paper_records(
                p,
                &Default::default(),
                1000 * k as u64 + 17,
            ));
        }
        identify(&records, &ValidSettings::default()).unwrap()
    })
}

fn at_nominal(name: &str) -> bool {
    name.ends_with("@13.8MPa")
}

#[test]
fn every_test_is_recognised_as_sine_or_triangle_from_its_data() {
    let id = program();
    assert_eq!(id.tests.len(), 72);
    for t in &id.tests {
        let want = if t.name.starts_with('S') {
            TestKind::Sine
        } else {
            TestKind::Triangle
        };
        assert_eq!(t.kind, want, "{}", t.name);
        assert!(!t.kind_given);
    }
}

/// Table I: 1.24–1.27 MN/m for every triangle test; the mean within 1 % of 1.266 MN/m.
#[test]
fn stiffness_per_triangle_test_lies_within_table_i_and_the_mean_within_1_percent() {
    let id = program();
    let mut ks = Vec::new();
    for t in id
        .tests
        .iter()
        .filter(|t| t.kind == TestKind::Triangle && at_nominal(&t.name))
    {
        let k = t
            .stiffness
            .expect("every triangle test has a stiffness")
            .value;
        assert!((1.24e6..=1.27e6).contains(&k), "{}: Kₑ = {k}", t.name);
        assert!(t.used_for_stiffness, "{}", t.name);
        ks.push(k);
    }
    assert_eq!(ks.len(), 12);
    let mean = ks.iter().sum::<f64>() / 12.0;
    assert!((mean / 1.266e6 - 1.0).abs() < 0.01, "mean Kₑ = {mean}");
    let k = id.parameters[IdentifiedKey::Stiffness].value().unwrap();
    assert!((k / 1.266e6 - 1.0).abs() < 0.01, "final Kₑ = {k}");
    assert_eq!(id.reference_pressure_pa, Some(13.8e6));
}

/// The stiffness scales with the hold-down pressure (Fig. 4: 0.65 MN/m at 6.9 MPa, zero at
/// 0 MPa).
#[test]
fn stiffness_at_lower_pressures_scales_with_the_pressure() {
    let id = program();
    let k = |p: f64| {
        id.pressures
            .iter()
            .find(|g| g.pressure_pa == Some(p))
            .and_then(|g| g.stiffness)
            .unwrap()
            .value
    };
    assert!((k(6.9e6) / 0.633e6 - 1.0).abs() < 0.01, "{}", k(6.9e6));
    assert!(k(0.0).abs() < 0.005 * 1.266e6, "{}", k(0.0));
}

/// Table II: 144 t on S4–S11 within 2 %; S1–S3 flagged (tiny accelerations) and left out.
#[test]
fn mass_per_sine_test_is_within_2_percent_of_144_t_and_s1_to_s3_are_flagged() {
    let id = program();
    for t in id.tests.iter().filter(|t| t.kind == TestKind::Sine) {
        let m = t.effective_mass.expect("every sine test has a mass").value;
        let k: usize = t.name[1..t.name.find('@').unwrap()].parse().unwrap();
        if (4..=11).contains(&k) {
            assert!((m / 144e3 - 1.0).abs() < 0.02, "{}: Mₑ = {m}", t.name);
            assert!(t.used_for_mass, "{}", t.name);
        }
        if k <= 3 {
            assert!(!t.used_for_mass, "{} should be flagged", t.name);
            assert!(
                t.flags
                    .iter()
                    .any(|f| matches!(f, Flag::SmallInertialForce { .. })),
                "{}",
                t.name
            );
        }
    }
    let m = id.parameters[IdentifiedKey::EffectiveMass]
        .estimate()
        .unwrap();
    assert!(
        (m.value / 144e3 - 1.0).abs() < 0.01,
        "final Mₑ = {}",
        m.value
    );
    assert!(m.ci95_low < m.value && m.value < m.ci95_high);
}

/// Eq. 21 fitted as the paper did: F_μ = 26.00 kN and Cₑ = 44.58 kN/(m/s)^0.5, within 10 %.
#[test]
fn eq_21_gives_the_papers_coulomb_force_and_viscous_coefficient_within_10_percent() {
    let fit = program().paper_fit.as_ref().expect("Eq. 21 fit");
    assert!(fit.sine_only);
    let f = fit.coulomb_force.value;
    let c = fit.viscous_coefficient.value;
    assert!((f / 26.0e3 - 1.0).abs() < 0.10, "F_μ = {f}");
    assert!((c / 44.58e3 - 1.0).abs() < 0.10, "Cₑ = {c}");
}

/// Fig. 8: F_μ = μₑ·F_z with μₑ = 0.44 %, from the three pressures (within 10 %), both by
/// the final law and by the paper's route.
#[test]
fn the_friction_coefficient_from_the_three_pressures_is_within_10_percent_of_0_44_percent() {
    let id = program();
    let mu = id.friction_coefficient.unwrap().value;
    assert!((mu / 0.0044 - 1.0).abs() < 0.10, "μₑ = {mu}");
    let paper = id
        .paper_fit
        .as_ref()
        .unwrap()
        .friction_coefficient
        .unwrap()
        .value;
    assert!(
        (paper / 0.0044 - 1.0).abs() < 0.10,
        "paper route μₑ = {paper}"
    );
    assert_eq!(id.pressures.len(), 3);
    assert!(id.pressures.iter().all(|g| g.coulomb_force.is_some()));
}

/// The dissipative law as identified, with the exponent free: F_μ and Cₑ within 2 % of
/// Eq. 22, α within 0.01 of 0.5, and the low-velocity term within 5 % (measured here:
/// 0.1 %, 0.1 %, 0.001, 2 %, 2 %; the low-velocity term rests on the noisiest velocities).
#[test]
fn the_full_dissipative_law_is_close_to_eq_22() {
    let p = &program().parameters;
    // (parameter, Eq. 22's value, relative tolerance)
    for (key, want, tol) in [
        (IdentifiedKey::CoulombForce, 25.445e3, 0.02),
        (IdentifiedKey::ViscousCoefficient, 44.58e3, 0.02),
        (IdentifiedKey::LowVelocityForce, 12.04e3, 0.05),
        (IdentifiedKey::LowVelocityDecay, 78.5, 0.05),
    ] {
        let got = p[key].value().unwrap();
        assert!((got / want - 1.0).abs() < tol, "{key} = {:?}", p[key]);
    }
    let alpha = p[IdentifiedKey::ViscousExponent].value().unwrap();
    assert!((alpha - 0.5).abs() < 0.01, "α = {alpha}");
}

/// The global fit of Eq. 23 agrees with the hysteresis-loop estimate.
#[test]
fn the_global_fit_agrees_with_the_hysteresis_loop_estimate() {
    let id = program();
    let g = id.global.as_ref().expect("global fit");
    assert!(g.converged);
    let m = g.parameters[IdentifiedKey::EffectiveMass].value().unwrap();
    let k = g.parameters[IdentifiedKey::Stiffness].value().unwrap();
    assert!((m / 144e3 - 1.0).abs() < 0.01, "{m}");
    assert!((k / 1.266e6 - 1.0).abs() < 0.01, "{k}");
    let c = g.parameters[IdentifiedKey::ViscousCoefficient]
        .value()
        .unwrap();
    assert!((c / 44.58e3 - 1.0).abs() < 0.05, "{c}");
    assert_eq!(g.groups.len(), 3);
}

/// Per test, the dissipative force at peak velocity lies on Eq. 22 within 1 % (Fig. 7).
#[test]
fn dissipative_force_at_peak_velocity_follows_eq_22_for_every_test() {
    let id = program();
    for t in &id.tests {
        let p: f64 = t.name[t.name.find('@').unwrap() + 1..t.name.len() - 3]
            .parse()
            .unwrap();
        let law = platen_model::preset::lhpost_2008_identified(p * 1e6)
            .build()
            .unwrap();
        let pk = t.peak_dissipative.expect("peak point");
        let want = platen_model::PlatenModel::dissipative_magnitude_n(&law, 0.0, pk.velocity_m_s);
        assert!(
            (pk.force_n / want - 1.0).abs() < 0.01,
            "{}: F_D({:.4}) = {:.0}, Eq. 22 {:.0}",
            t.name,
            pk.velocity_m_s,
            pk.force_n,
            want
        );
    }
}
