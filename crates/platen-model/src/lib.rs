//! Physics of the NEES-UCSD LHPOST shake-table platen (Ozcelik et al. 2008): parameters,
//! derived effective quantities and force terms. No I/O and no solver live here.
//!
//! Two forms of the model are provided, both implementing [`PlatenModel`]:
//!
//! * [`IdentifiedModel`]: the identified model of the paper, Eq. 22/23, with the seven
//!   identified parameters of [`IdentifiedParams`];
//! * [`FullModel`]: the full Lagrangian model of Eq. 1–8, built from the physical parameters
//!   of [`PhysicalParams`] with every derived quantity of Eq. 5–8 computed
//!   ([`DerivedQuantities`]).
//!
//! [`preset`] holds the `lhpost-2008` preset in both forms, parameterised by the hold-down
//! nitrogen pressure, with the assumptions made where the paper gives no value.
//!
//! ```
//! use platen_model::{preset, PlatenModel};
//!
//! let model = preset::lhpost_2008_identified(13.8e6).build().unwrap();
//! // Eq. 22 at 1 m/s: 0.44 % × 5783 kN + 44.58 kN + 12.04 kN·e^(−78.5) ≈ 70.0 kN.
//! let f_d = model.dissipative_magnitude_n(0.0, 1.0);
//! assert!((f_d - 70.03e3).abs() < 10.0);
//! ```
//!
//! # Conventions
//!
//! * SI units everywhere (kg, m, s, N, Pa); the unit is part of every public name.
//! * `u` is the platen displacement and `v` its velocity along the table's long axis, positive
//!   in the same direction as the actuator force `F_A`.
//! * Equation of motion (Eq. 1): `F_I + F_E + F_D = F_A`, with the inertial force
//!   `F_I = M(u)·a + 2M̄′ₑ(v/h)²u` (Eq. 2), the elastic force `F_E(u)` (Eq. 3) and the
//!   dissipative force `F_D = D(u, |v|)·sign(v)` (Eq. 4). `D ≥ 0` is the *magnitude* of the
//!   dissipative force.
//! * At `v = 0` friction is set-valued: the platen stays at rest while
//!   `|F_A − F_E(u)| ≤ F_s(u)` with the static threshold `F_s(u) = D(u, 0⁺)`
//!   ([`PlatenModel::static_threshold_n`]). Resolving this is the integrator's job.
//! * [`force_terms`] is the inverse direction, which uses `sign(0) = 0` as Eq. 23 does.

#![warn(missing_docs)]

mod error;
mod full;
pub mod hysteresis;
mod identified;
mod keys;
mod law;
pub mod multi_axis;
mod physical_keys;
mod power;
pub mod preset;
mod specimen;

pub use error::{ModelError, Result};
pub use full::{DerivedQuantities, FullModel, PhysicalParams};
pub use hysteresis::{Branch, Hysteresis, HysteresisLaw, HystereticStorey};
pub use identified::{IdentifiedModel, IdentifiedParams};
pub use keys::{IdentifiedKey, IDENTIFIED_KEY_NAMES};
pub use law::DissipativeLaw;
pub use physical_keys::PhysicalKey;
pub use power::Exponent;
pub use preset::{
    Preset, TableLimits, LHPOST_HOLD_DOWN_FORCE_AT_NOMINAL_N, LHPOST_NOMINAL_PRESSURE_PA,
    LHPOST_SUPPORTED_WEIGHT_N,
};
pub use specimen::{Specimen, Storey};

/// Standard gravity, m/s² (used only to express accelerations in g).
pub const STANDARD_GRAVITY_M_S2: f64 = 9.806_65;

/// The mechanics of a platen: the terms of Eq. 1–4 as functions of the state.
///
/// Implementations hold validated parameters, so none of these methods can fail. The trait is
/// used generically by the integrators, so each method should be cheap and inlinable.
pub trait PlatenModel {
    /// Effective mass `M(u) = Mₑ + 2M̄′ₑ(u/h)²`, kg (Eq. 2, first two terms).
    fn mass_kg(&self, u_m: f64) -> f64;

    /// Elastic restoring force `F_E(u) = Kₑu + K′ₑ(u/h)²u`, N (Eq. 3).
    fn elastic_force_n(&self, u_m: f64) -> f64;

    /// Velocity-dependent inertial term `2M̄′ₑ(v/h)²u`, N (Eq. 2, last term).
    fn velocity_inertial_force_n(&self, u_m: f64, v_m_s: f64) -> f64;

    /// Magnitude `D(u, w) ≥ 0` of the dissipative force at speed `w = |v| ≥ 0`, N (Eq. 4
    /// without the sign). At `w = 0` it is the right-hand limit `D(u, 0⁺)`.
    fn dissipative_magnitude_n(&self, u_m: f64, speed_m_s: f64) -> f64;

    /// Static friction threshold `F_s(u) = D(u, 0⁺)`, N: the largest net force
    /// `|F_A − F_E(u)|` the platen resists at rest.
    #[inline]
    fn static_threshold_n(&self, u_m: f64) -> f64 {
        self.dissipative_magnitude_n(u_m, 0.0)
    }

    /// The excess `D(u, w) − F_s(u)` of the dissipative force over the static threshold at
    /// speed `w ≥ 0`, N. The default forms the difference; implementations compute it without
    /// cancellation, since the creep of a platen barely above its threshold (an excess of
    /// 1e-9 N on 30 kN) depends on it to full relative precision.
    #[inline]
    fn dissipative_excess_n(&self, u_m: f64, speed_m_s: f64) -> f64 {
        self.dissipative_magnitude_n(u_m, speed_m_s) - self.static_threshold_n(u_m)
    }

    /// Elastic (potential) energy stored at displacement `u`, J: the integral of
    /// [`PlatenModel::elastic_force_n`] from 0 to `u`.
    fn elastic_energy_j(&self, u_m: f64) -> f64;

    /// Kinetic energy `½·M(u)·v²`, J. With the displacement-dependent mass of Eq. 2 its rate is
    /// `v·(M(u)·a + 2M̄′ₑ(v/h)²u)`, the power of the inertial force.
    #[inline]
    fn kinetic_energy_j(&self, u_m: f64, v_m_s: f64) -> f64 {
        0.5 * self.mass_kg(u_m) * v_m_s * v_m_s
    }

    /// Acceleration and dissipated power in slip with the friction direction fixed to
    /// `direction` (`+1.0` or `−1.0`):
    /// `a = (F_A − F_E − direction·D(u, w) − 2M̄′ₑ(v/h)²u) / M(u)` and `P_D = D(u, w)·w`, with
    /// the speed `w = max(direction·v, 0)`.
    ///
    /// The speed is clamped at zero so that the right-hand side stays continuous when an
    /// integrator stage overshoots `v = 0`; locating that crossing is the integrator's job.
    #[inline]
    fn slip_rates(&self, force_n: f64, u_m: f64, v_m_s: f64, direction: f64) -> SlipRates {
        let speed = (direction * v_m_s).max(0.0);
        let d = self.dissipative_magnitude_n(u_m, speed);
        let a_m_s2 = (force_n
            - self.elastic_force_n(u_m)
            - direction * d
            - self.velocity_inertial_force_n(u_m, v_m_s))
            / self.mass_kg(u_m);
        SlipRates {
            a_m_s2,
            dissipated_power_w: d * speed,
        }
    }

    /// Acceleration in slip with the friction direction fixed to `direction`, m/s²: the
    /// acceleration of [`PlatenModel::slip_rates`].
    #[inline]
    fn slip_acceleration_m_s2(&self, force_n: f64, u_m: f64, v_m_s: f64, direction: f64) -> f64 {
        self.slip_rates(force_n, u_m, v_m_s, direction).a_m_s2
    }
}

/// Rates of a slipping platen: see [`PlatenModel::slip_rates`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipRates {
    /// Acceleration, m/s².
    pub a_m_s2: f64,
    /// Power dissipated by the dissipative force, `D·|v| ≥ 0`, W.
    pub dissipated_power_w: f64,
}

/// The decomposition of the actuator force of Eq. 1 at one instant, N.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ForceTerms {
    /// Inertial force `F_I = M(u)·a + 2M̄′ₑ(v/h)²u`, N.
    pub inertial_n: f64,
    /// Elastic force `F_E(u)`, N.
    pub elastic_n: f64,
    /// Dissipative force `F_D`, N (signed: opposes the motion).
    pub dissipative_n: f64,
    /// Total actuator force `F_A = F_I + F_E + F_D`, N.
    pub actuator_n: f64,
}

/// The actuator force a prescribed state `(u, v, a)` needs, with its decomposition (Eq. 1–4;
/// for an [`IdentifiedModel`] this is exactly Eq. 23 plus the low-velocity term of Eq. 22).
///
/// At `v = 0` the dissipative force is taken as zero (`sign(0) = 0`, as in Eq. 23): any value
/// within `±F_s(u)` would hold the platen, and this is the one that treats both directions alike.
#[inline]
pub fn force_terms<M: PlatenModel + ?Sized>(
    model: &M,
    u_m: f64,
    v_m_s: f64,
    a_m_s2: f64,
) -> ForceTerms {
    let inertial_n = model.mass_kg(u_m) * a_m_s2 + model.velocity_inertial_force_n(u_m, v_m_s);
    let elastic_n = model.elastic_force_n(u_m);
    let dissipative_n = if v_m_s > 0.0 {
        model.dissipative_magnitude_n(u_m, v_m_s)
    } else if v_m_s < 0.0 {
        -model.dissipative_magnitude_n(u_m, -v_m_s)
    } else {
        0.0
    };
    ForceTerms {
        inertial_n,
        elastic_n,
        dissipative_n,
        actuator_n: inertial_n + elastic_n + dissipative_n,
    }
}
