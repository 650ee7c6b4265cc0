//! The full Lagrangian model of the paper (Eq. 1–8), built from physical parameters.

use crate::error::{finite, non_negative, positive, unit_exponent, ModelError, Result};
use crate::{DissipativeLaw, Exponent, IdentifiedParams, PlatenModel};

/// Physical parameters of a platen with two inclined nitrogen hold-down struts (paper §2).
///
/// Every derived quantity of Eq. 5–8 is computed from these by [`PhysicalParams::derived`];
/// none of them is typed in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicalParams {
    /// Platen mass `M_pl`, kg. `> 0`.
    pub platen_mass_kg: f64,
    /// Mass of the moving parts of ONE actuator `M_act`, kg. `≥ 0`.
    pub actuator_moving_mass_kg: f64,
    /// Mass of the piston of one hold-down strut `M₁`, kg. `≥ 0`.
    pub strut_piston_mass_kg: f64,
    /// Mass of the cylinder of one hold-down strut `M₂`, kg. `≥ 0`.
    pub strut_cylinder_mass_kg: f64,
    /// Pin-to-pin height of a hold-down strut at `u = 0`, `h`, m. `> 0`.
    pub strut_height_m: f64,
    /// Initial length of the strut piston `l₀`, m. `> 0`.
    pub strut_piston_length_m: f64,
    /// Nitrogen pre-charge pressure `p₀` of the hold-down struts, Pa. `≥ 0`.
    pub hold_down_pressure_pa: f64,
    /// Effective cross-section area of the nitrogen chamber of one strut `A`, m². `> 0`.
    pub strut_area_m2: f64,
    /// Ratio of heat capacities of the gas `γ` (adiabatic compression). `≥ 1`.
    pub gas_heat_capacity_ratio: f64,
    /// Weight of platen and actuators carried by the vertical bearings `F_pl+act`, N. `≥ 0`.
    pub supported_weight_n: f64,
    /// Coulomb friction coefficient of the vertical bearings `μ″ₑ`. `≥ 0`.
    pub bearing_friction_coefficient: f64,
    /// Coulomb friction coefficient of the lateral bearings `μ‴ₑ`. `≥ 0`.
    pub lateral_friction_coefficient: f64,
    /// Normal force on the lateral bearings `F_l`, N (taken constant). `≥ 0`.
    pub lateral_normal_force_n: f64,
    /// Coulomb friction coefficient in the strut swivels `μ_hg`. `≥ 0`.
    pub hinge_swivel_friction_coefficient: f64,
    /// Radius of the strut hinge `a`, m. `≥ 0`.
    pub hinge_radius_m: f64,
    /// Hinge force-distribution constant `κ` (4/π for a cosine pressure on a pin). `≥ 0`.
    pub hinge_force_distribution_factor: f64,
    /// Actuator viscous coefficient `Cₑ`, N/(m/s)^α. `≥ 0`.
    pub viscous_coefficient: f64,
    /// Actuator viscous exponent `α ∈ [0, 1]`.
    pub viscous_exponent: f64,
    /// Strut viscous coefficient `c_β`, N/(m/s)^β. `≥ 0`.
    pub strut_viscous_coefficient: f64,
    /// Strut viscous exponent `β ∈ [0, 1]`.
    pub strut_viscous_exponent: f64,
    /// Low-velocity friction force `a`, N (Eq. 22). `≥ 0`.
    pub low_velocity_force_n: f64,
    /// Low-velocity friction decay `b`, s/m (Eq. 22). `≥ 0`.
    pub low_velocity_decay_s_per_m: f64,
}

/// The quantities of Eq. 5–8 derived from [`PhysicalParams`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DerivedQuantities {
    /// `M̄ₑ = ⅓M₁(l₀/h)² + ⅓M₂`, effective mass of ONE strut, kg (Eq. 5b).
    pub strut_effective_mass_kg: f64,
    /// `Mₑ = M_pl + 2M_act + 2M̄ₑ`, kg (Eq. 5a).
    pub effective_mass_kg: f64,
    /// `M̄′ₑ = ½[⁵⁄₃M₂ − ⁴⁄₃M₁(l₀/h)²]`, strut rotational mass, kg (Eq. 5c).
    pub strut_rotational_mass_kg: f64,
    /// `Kₑ = 2p₀A/h`, N/m (Eq. 6a).
    pub stiffness_n_per_m: f64,
    /// `K′ₑ = ½(γh/l₀ − 1)Kₑ`, N/m (Eq. 6b).
    pub cubic_stiffness_n_per_m: f64,
    /// `F_hd = 2p₀A`, total hold-down force, N.
    pub hold_down_force_n: f64,
    /// `μ′ₑ = μ″ₑ + 2μ_hgκ(a/h)` (Eq. 7b).
    pub hold_down_friction_coefficient: f64,
    /// `μ⁽ⁱᵛ⁾ₑ = 2μ_hgκ(a/h)(γ/2)(h/l₀)`, coefficient of the hinge term of Eq. 4 (Eq. 8).
    pub hinge_friction_coefficient: f64,
    /// `F_μ = μ′ₑF_hd + μ″ₑF_pl+act + μ‴ₑF_l`, Coulomb friction force, N (Eq. 7a).
    pub coulomb_force_n: f64,
}

impl PhysicalParams {
    /// Validates the parameters.
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] naming the first parameter that is non-finite or out
    /// of range, or `strut_piston_mass_kg` when the effective mass `M(u)` would not stay
    /// positive for `|u| ≤ h`.
    pub fn validate(&self) -> Result<()> {
        positive("platen_mass_kg", self.platen_mass_kg)?;
        non_negative("actuator_moving_mass_kg", self.actuator_moving_mass_kg)?;
        non_negative("strut_piston_mass_kg", self.strut_piston_mass_kg)?;
        non_negative("strut_cylinder_mass_kg", self.strut_cylinder_mass_kg)?;
        positive("strut_height_m", self.strut_height_m)?;
        positive("strut_piston_length_m", self.strut_piston_length_m)?;
        non_negative("hold_down_pressure_pa", self.hold_down_pressure_pa)?;
        positive("strut_area_m2", self.strut_area_m2)?;
        if !(self.gas_heat_capacity_ratio.is_finite() && self.gas_heat_capacity_ratio >= 1.0) {
            return Err(ModelError::InvalidParameter {
                name: "gas_heat_capacity_ratio",
                value: self.gas_heat_capacity_ratio,
                expected: "a finite ratio >= 1",
            });
        }
        non_negative("supported_weight_n", self.supported_weight_n)?;
        non_negative(
            "bearing_friction_coefficient",
            self.bearing_friction_coefficient,
        )?;
        non_negative(
            "lateral_friction_coefficient",
            self.lateral_friction_coefficient,
        )?;
        non_negative("lateral_normal_force_n", self.lateral_normal_force_n)?;
        non_negative(
            "hinge_swivel_friction_coefficient",
            self.hinge_swivel_friction_coefficient,
        )?;
        non_negative("hinge_radius_m", self.hinge_radius_m)?;
        non_negative(
            "hinge_force_distribution_factor",
            self.hinge_force_distribution_factor,
        )?;
        non_negative("viscous_coefficient", self.viscous_coefficient)?;
        unit_exponent("viscous_exponent", self.viscous_exponent)?;
        non_negative("strut_viscous_coefficient", self.strut_viscous_coefficient)?;
        unit_exponent("strut_viscous_exponent", self.strut_viscous_exponent)?;
        non_negative("low_velocity_force_n", self.low_velocity_force_n)?;
        non_negative(
            "low_velocity_decay_s_per_m",
            self.low_velocity_decay_s_per_m,
        )?;
        let d = self.derived();
        // M(u) = Mₑ + 2M̄′ₑ(u/h)² must stay positive over the strut's geometric range |u| ≤ h.
        if d.effective_mass_kg + 2.0 * d.strut_rotational_mass_kg.min(0.0) <= 0.0 {
            return Err(ModelError::InvalidParameter {
                name: "strut_piston_mass_kg",
                value: self.strut_piston_mass_kg,
                expected: "a piston mass that keeps M(u) = Mₑ + 2M̄′ₑ(u/h)² positive for |u| ≤ h",
            });
        }
        for (name, value) in [
            ("effective_mass_kg", d.effective_mass_kg),
            ("cubic_stiffness_n_per_m", d.cubic_stiffness_n_per_m),
            ("coulomb_force_n", d.coulomb_force_n),
        ] {
            finite(name, value)?;
        }
        Ok(())
    }

    /// Computes the derived quantities of Eq. 5–8 (no validation).
    pub fn derived(&self) -> DerivedQuantities {
        let h = self.strut_height_m;
        let l0 = self.strut_piston_length_m;
        let ratio2 = (l0 / h).powi(2);
        let m1 = self.strut_piston_mass_kg;
        let m2 = self.strut_cylinder_mass_kg;
        let strut_effective_mass_kg = m1 * ratio2 / 3.0 + m2 / 3.0;
        let effective_mass_kg = self.platen_mass_kg
            + 2.0 * self.actuator_moving_mass_kg
            + 2.0 * strut_effective_mass_kg;
        let strut_rotational_mass_kg = 0.5 * (5.0 / 3.0 * m2 - 4.0 / 3.0 * m1 * ratio2);
        let hold_down_force_n = 2.0 * self.hold_down_pressure_pa * self.strut_area_m2;
        let stiffness_n_per_m = hold_down_force_n / h;
        let gamma = self.gas_heat_capacity_ratio;
        let cubic_stiffness_n_per_m = 0.5 * (gamma * h / l0 - 1.0) * stiffness_n_per_m;
        let hinge = 2.0
            * self.hinge_swivel_friction_coefficient
            * self.hinge_force_distribution_factor
            * (self.hinge_radius_m / h);
        let hold_down_friction_coefficient = self.bearing_friction_coefficient + hinge;
        let hinge_friction_coefficient = hinge * (gamma / 2.0) * (h / l0);
        let coulomb_force_n = hold_down_friction_coefficient * hold_down_force_n
            + self.bearing_friction_coefficient * self.supported_weight_n
            + self.lateral_friction_coefficient * self.lateral_normal_force_n;
        DerivedQuantities {
            strut_effective_mass_kg,
            effective_mass_kg,
            strut_rotational_mass_kg,
            stiffness_n_per_m,
            cubic_stiffness_n_per_m,
            hold_down_force_n,
            hold_down_friction_coefficient,
            hinge_friction_coefficient,
            coulomb_force_n,
        }
    }

    /// Validates the parameters and builds the model.
    ///
    /// # Errors
    /// See [`PhysicalParams::validate`].
    pub fn build(&self) -> Result<FullModel> {
        FullModel::new(*self)
    }
}

/// The full Lagrangian model of Eq. 1–8, validated and ready to evaluate.
///
/// `M(u)·a = F_A − F_E(u) − F_D(u, v) − 2M̄′ₑ(v/h)²u` with
/// `M(u) = Mₑ + 2M̄′ₑ(u/h)²`, `F_E = Kₑu + K′ₑ(u/h)²u` and
/// `F_D = [F_μ + Cₑ|v|^α + a·e^(−b|v|) + 2c_β|u/h|^(1+β)|v|^β + μ⁽ⁱᵛ⁾ₑF_hd(u/h)²]·sign(v)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FullModel {
    params: PhysicalParams,
    derived: DerivedQuantities,
    inv_h: f64,
    two_mp: f64,
    law: DissipativeLaw,
    beta: Exponent,
    two_c_beta: f64,
    hinge_force_n: f64,
}

impl FullModel {
    /// Validates `params` and computes the derived quantities.
    ///
    /// # Errors
    /// See [`PhysicalParams::validate`].
    pub fn new(params: PhysicalParams) -> Result<Self> {
        params.validate()?;
        let derived = params.derived();
        Ok(Self {
            params,
            derived,
            inv_h: 1.0 / params.strut_height_m,
            two_mp: 2.0 * derived.strut_rotational_mass_kg,
            law: DissipativeLaw {
                coulomb_force_n: derived.coulomb_force_n,
                viscous_coefficient: params.viscous_coefficient,
                exponent: Exponent::new(params.viscous_exponent),
                low_velocity_force_n: params.low_velocity_force_n,
                low_velocity_decay_s_per_m: params.low_velocity_decay_s_per_m,
            },
            beta: Exponent::new(params.strut_viscous_exponent),
            two_c_beta: 2.0 * params.strut_viscous_coefficient,
            hinge_force_n: derived.hinge_friction_coefficient * derived.hold_down_force_n,
        })
    }

    /// The physical parameters this model was built from.
    pub fn params(&self) -> &PhysicalParams {
        &self.params
    }

    /// The derived quantities of Eq. 5–8.
    pub fn derived(&self) -> &DerivedQuantities {
        &self.derived
    }

    /// The seven identified parameters this model reduces to for small strokes (the terms in
    /// `u/h` dropped): `Mₑ`, `Kₑ`, `F_μ` of Eq. 5–8 and the actuator's viscous and
    /// low-velocity terms.
    pub fn identified_equivalent(&self) -> IdentifiedParams {
        let (p, d) = (self.params(), self.derived());
        IdentifiedParams {
            effective_mass_kg: d.effective_mass_kg,
            stiffness_n_per_m: d.stiffness_n_per_m,
            coulomb_force_n: d.coulomb_force_n,
            viscous_coefficient: p.viscous_coefficient,
            viscous_exponent: p.viscous_exponent,
            low_velocity_force_n: p.low_velocity_force_n,
            low_velocity_decay_s_per_m: p.low_velocity_decay_s_per_m,
        }
    }

    /// The dissipative law `F_μ + Cₑ|v|^α + a·e^(−b|v|)` of Eq. 4 (without the strut terms),
    /// with `F_μ` from Eq. 7a.
    pub fn law(&self) -> &DissipativeLaw {
        &self.law
    }
}

impl PlatenModel for FullModel {
    #[inline(always)]
    fn mass_kg(&self, u_m: f64) -> f64 {
        let r = u_m * self.inv_h;
        self.derived.effective_mass_kg + self.two_mp * r * r
    }

    #[inline(always)]
    fn elastic_force_n(&self, u_m: f64) -> f64 {
        let r = u_m * self.inv_h;
        (self.derived.stiffness_n_per_m + self.derived.cubic_stiffness_n_per_m * r * r) * u_m
    }

    #[inline(always)]
    fn elastic_energy_j(&self, u_m: f64) -> f64 {
        // ∫(Kₑu + K′ₑu³/h²)du = ½Kₑu² + K′ₑu⁴/(4h²).
        let r = u_m * self.inv_h;
        (0.5 * self.derived.stiffness_n_per_m + 0.25 * self.derived.cubic_stiffness_n_per_m * r * r)
            * u_m
            * u_m
    }

    #[inline(always)]
    fn velocity_inertial_force_n(&self, u_m: f64, v_m_s: f64) -> f64 {
        let w = v_m_s * self.inv_h;
        self.two_mp * w * w * u_m
    }

    #[inline(always)]
    fn dissipative_magnitude_n(&self, u_m: f64, speed_m_s: f64) -> f64 {
        let r = (u_m * self.inv_h).abs();
        // |u/h|^(1+β)·|v|^β = |u/h|·(|u/h|·|v|)^β: one power instead of two.
        let strut = self.two_c_beta * r * self.beta.pow(r * speed_m_s);
        // (F_μ + Cₑw^α + a·e^(−bw)) + strut + hinge, in this order.
        self.law.magnitude_n(speed_m_s) + strut + self.hinge_force_n * r * r
    }

    #[inline]
    fn dissipative_excess_n(&self, u_m: f64, speed_m_s: f64) -> f64 {
        let r = (u_m * self.inv_h).abs();
        // The strut term's own excess over its value at rest (zero there for β > 0); the
        // hinge term does not depend on the speed.
        let strut = self.two_c_beta * r * (self.beta.pow(r * speed_m_s) - self.beta.pow(0.0));
        self.law.excess_n(speed_m_s) + strut
    }
}
