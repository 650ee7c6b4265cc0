//! The identified model of the paper (Eq. 22/23).

use crate::error::{non_negative, positive, unit_exponent, Result};
use crate::{DissipativeLaw, Exponent, PlatenModel, SlipRates};

/// The seven parameters of the identified model (Eq. 22/23), named as in the contract.
///
/// `F_A = Mₑ·a + Kₑ·u + [F_μ + Cₑ|v|^α + a·e^(−b|v|)]·sign(v)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdentifiedParams {
    /// Effective horizontal mass `Mₑ`, kg (paper: 144 t). Must be `> 0`.
    pub effective_mass_kg: f64,
    /// Effective horizontal stiffness `Kₑ`, N/m (paper: 1.266 MN/m at 13.8 MPa). `≥ 0`
    /// (zero at 0 MPa hold-down pressure).
    pub stiffness_n_per_m: f64,
    /// Coulomb friction force `F_μ = μₑF_z`, N (paper: 0.44 % × 5783 kN = 25.445 kN). `≥ 0`.
    pub coulomb_force_n: f64,
    /// Viscous coefficient `Cₑ`, N/(m/s)^α (paper: 44.58 kN/(m/s)^0.5). `≥ 0`.
    pub viscous_coefficient: f64,
    /// Viscous exponent `α ∈ [0, 1]` (paper: 0.5).
    pub viscous_exponent: f64,
    /// Low-velocity force `a`, N (paper: 12.04 kN). `≥ 0`.
    pub low_velocity_force_n: f64,
    /// Low-velocity decay `b`, s/m (paper: 78.5 s/m). `≥ 0`.
    pub low_velocity_decay_s_per_m: f64,
}

impl IdentifiedParams {
    /// Validates the parameters and builds the model.
    ///
    /// # Errors
    /// [`crate::ModelError::InvalidParameter`] naming the first parameter that is non-finite
    /// or out of range.
    pub fn build(&self) -> Result<IdentifiedModel> {
        IdentifiedModel::new(*self)
    }

    /// The dissipative law `F_μ + Cₑ|v|^α + a·e^(−b|v|)` of these parameters (the exponent
    /// is not validated here: [`IdentifiedParams::build`] does that).
    pub fn dissipative_law(&self) -> DissipativeLaw {
        DissipativeLaw {
            coulomb_force_n: self.coulomb_force_n,
            viscous_coefficient: self.viscous_coefficient,
            exponent: Exponent::new(self.viscous_exponent),
            low_velocity_force_n: self.low_velocity_force_n,
            low_velocity_decay_s_per_m: self.low_velocity_decay_s_per_m,
        }
    }
}

/// The identified model of Eq. 22/23, validated and ready to evaluate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdentifiedModel {
    params: IdentifiedParams,
    inv_mass: f64,
    law: DissipativeLaw,
}

impl IdentifiedModel {
    /// Validates `params` (positive mass, non-negative forces and coefficients,
    /// `0 ≤ α ≤ 1`, all finite) and builds the model.
    ///
    /// # Errors
    /// [`crate::ModelError::InvalidParameter`] naming the offending parameter.
    pub fn new(params: IdentifiedParams) -> Result<Self> {
        positive("effective_mass_kg", params.effective_mass_kg)?;
        non_negative("stiffness_n_per_m", params.stiffness_n_per_m)?;
        non_negative("coulomb_force_n", params.coulomb_force_n)?;
        non_negative("viscous_coefficient", params.viscous_coefficient)?;
        unit_exponent("viscous_exponent", params.viscous_exponent)?;
        non_negative("low_velocity_force_n", params.low_velocity_force_n)?;
        non_negative(
            "low_velocity_decay_s_per_m",
            params.low_velocity_decay_s_per_m,
        )?;
        Ok(Self {
            params,
            inv_mass: 1.0 / params.effective_mass_kg,
            law: params.dissipative_law(),
        })
    }

    /// The parameters this model was built from.
    pub fn params(&self) -> &IdentifiedParams {
        &self.params
    }

    /// The model's dissipative law.
    pub fn law(&self) -> &DissipativeLaw {
        &self.law
    }
}

impl PlatenModel for IdentifiedModel {
    #[inline(always)]
    fn mass_kg(&self, _u_m: f64) -> f64 {
        self.params.effective_mass_kg
    }

    #[inline(always)]
    fn elastic_force_n(&self, u_m: f64) -> f64 {
        self.params.stiffness_n_per_m * u_m
    }

    #[inline(always)]
    fn velocity_inertial_force_n(&self, _u_m: f64, _v_m_s: f64) -> f64 {
        0.0
    }

    #[inline(always)]
    fn dissipative_magnitude_n(&self, _u_m: f64, speed_m_s: f64) -> f64 {
        self.law.magnitude_n(speed_m_s)
    }

    #[inline]
    fn dissipative_excess_n(&self, _u_m: f64, speed_m_s: f64) -> f64 {
        self.law.excess_n(speed_m_s)
    }

    #[inline(always)]
    fn elastic_energy_j(&self, u_m: f64) -> f64 {
        0.5 * self.params.stiffness_n_per_m * u_m * u_m
    }

    #[inline(always)]
    fn slip_rates(&self, force_n: f64, u_m: f64, v_m_s: f64, direction: f64) -> SlipRates {
        let speed = (direction * v_m_s).max(0.0);
        let d = self.dissipative_magnitude_n(u_m, speed);
        SlipRates {
            a_m_s2: (force_n - self.elastic_force_n(u_m) - direction * d) * self.inv_mass,
            dissipated_power_w: d * speed,
        }
    }
}
