//! The dissipative law `D(w) = F_μ + Cₑ·w^α + a·e^(−b·w)` of Eq. 21/22, written once for
//! every form of the model and for identification.

use crate::Exponent;

/// The dissipative law of Eq. 22 (Eq. 21 is the case `a = 0`, `α = 0.5`): the magnitude of
/// the dissipative force at speed `w = |v| ≥ 0` is `F_μ + Cₑ·w^α + a·e^(−b·w)`.
///
/// [`crate::IdentifiedModel`] is this law plus mass and stiffness; [`crate::FullModel`] adds
/// the strut terms of Eq. 4 to it with `F_μ` from Eq. 7a.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DissipativeLaw {
    /// Coulomb friction force `F_μ`, N.
    pub coulomb_force_n: f64,
    /// Viscous coefficient `Cₑ`, N/(m/s)^α.
    pub viscous_coefficient: f64,
    /// Viscous exponent `α`.
    pub exponent: Exponent,
    /// Low-velocity force `a`, N.
    pub low_velocity_force_n: f64,
    /// Low-velocity decay `b`, s/m.
    pub low_velocity_decay_s_per_m: f64,
}

impl DissipativeLaw {
    /// The magnitude `F_μ + Cₑ·w^α + a·e^(−b·w)` at speed `w ≥ 0`, N, with the exponents the
    /// paper uses evaluated without `powf` ([`Exponent::pow`]). This is the integrators' hot
    /// path.
    #[inline(always)]
    pub fn magnitude_n(&self, speed_m_s: f64) -> f64 {
        self.coulomb_force_n
            + self.viscous_coefficient * self.exponent.pow(speed_m_s)
            + self.low_velocity_force_n * (-self.low_velocity_decay_s_per_m * speed_m_s).exp()
    }

    /// The excess `D(w) − D(0⁺) = Cₑ·(w^α − 0^α) + a·(e^(−b·w) − 1)` at speed `w ≥ 0`, N,
    /// computed without forming the difference (`e^x − 1` by `exp_m1`), so it keeps full
    /// relative precision where it is far smaller than `F_μ + a` (a platen barely above its
    /// static threshold creeps at a speed set by this excess alone).
    #[inline]
    pub fn excess_n(&self, speed_m_s: f64) -> f64 {
        self.viscous_coefficient * (self.exponent.pow(speed_m_s) - self.exponent.pow(0.0))
            + self.low_velocity_force_n * (-self.low_velocity_decay_s_per_m * speed_m_s).exp_m1()
    }

    /// The magnitude at speed `w > 0` given `ln w`, with `w^α` evaluated as `e^(α·ln w)`
    /// whatever `α` is ([`Exponent::pow_from_ln`]): the form that is smooth in `α`, as a fit
    /// of the law needs. Agrees with [`DissipativeLaw::magnitude_n`] to rounding.
    #[inline]
    pub fn magnitude_from_ln_n(&self, speed_m_s: f64, ln_speed: f64) -> f64 {
        self.coulomb_force_n
            + self.viscous_coefficient * self.exponent.pow_from_ln(ln_speed)
            + self.low_velocity_force_n * (-self.low_velocity_decay_s_per_m * speed_m_s).exp()
    }

    /// [`DissipativeLaw::magnitude_from_ln_n`] at a speed `w ≥ 0` (at `w = 0`: `F_μ + a`, plus
    /// `Cₑ` when `α = 0`).
    #[inline]
    pub fn smooth_magnitude_n(&self, speed_m_s: f64) -> f64 {
        self.coulomb_force_n
            + self.viscous_coefficient * self.exponent.pow_smooth(speed_m_s)
            + self.low_velocity_force_n * (-self.low_velocity_decay_s_per_m * speed_m_s).exp()
    }

    /// `sign(v)·D(|v|)` with [`DissipativeLaw::smooth_magnitude_n`], N (0 at rest).
    pub fn smooth_signed_n(&self, v_m_s: f64) -> f64 {
        if v_m_s > 0.0 {
            self.smooth_magnitude_n(v_m_s)
        } else if v_m_s < 0.0 {
            -self.smooth_magnitude_n(-v_m_s)
        } else {
            0.0
        }
    }

    /// The derivatives of the magnitude at speed `w > 0` (given `ln w`) with respect to the
    /// law's parameters, in the order `(F_μ, Cₑ, α, a, b)`:
    /// `[1, w^α, Cₑ·w^α·ln w, e^(−b·w), −a·w·e^(−b·w)]`, with `w^α = e^(α·ln w)`.
    #[inline]
    pub fn gradient(&self, speed_m_s: f64, ln_speed: f64) -> [f64; 5] {
        let wa = (self.exponent.value() * ln_speed).exp();
        let e = (-self.low_velocity_decay_s_per_m * speed_m_s).exp();
        [
            1.0,
            wa,
            self.viscous_coefficient * wa * ln_speed,
            e,
            -self.low_velocity_force_n * speed_m_s * e,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> DissipativeLaw {
        DissipativeLaw {
            coulomb_force_n: 25.445e3,
            viscous_coefficient: 44.58e3,
            exponent: Exponent::Half,
            low_velocity_force_n: 12.04e3,
            low_velocity_decay_s_per_m: 78.5,
        }
    }

    /// Eq. 22 at 1 m/s: 25.445 + 44.58 + 12.04·e^(−78.5) ≈ 70.025 kN; at rest 25.445 + 12.04.
    #[test]
    fn eq_22_at_one_metre_per_second_is_70_kn() {
        assert!((paper().magnitude_n(1.0) - 70.025e3).abs() < 1.0);
        assert!((paper().magnitude_n(0.0) - 37.485e3).abs() < 1.0);
        assert!((paper().smooth_magnitude_n(0.0) - 37.485e3).abs() < 1.0);
    }

    #[test]
    fn the_smooth_evaluation_agrees_with_the_fast_one_to_rounding() {
        for w in [1e-4, 0.01, 0.3, 1.0, 1.8] {
            let (a, b) = (paper().magnitude_n(w), paper().smooth_magnitude_n(w));
            assert!((a - b).abs() <= 1e-12 * a, "{w}: {a} vs {b}");
            assert_eq!(b, paper().magnitude_from_ln_n(w, w.ln()));
        }
    }
}
