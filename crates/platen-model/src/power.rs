//! Fractional powers `w^α` of a non-negative speed, with the common exponents special-cased.

/// A validated exponent `α ∈ [0, 1]` of a power law `w^α`, `w ≥ 0`.
///
/// The exponents the paper uses are evaluated without `powf`: `α = 0.5` is a square root
/// (Eq. 21/22), `α = 1` is linear, `α = 0` is a constant 1 (so the law degenerates to Coulomb
/// friction, including the right-hand limit at `w = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exponent {
    /// `w^0 = 1` for every `w ≥ 0`.
    Zero,
    /// `w^0.5 = √w`.
    Half,
    /// `w^1 = w`.
    One,
    /// Any other exponent in `(0, 1)`.
    General(f64),
}

impl Exponent {
    /// Classifies an exponent that has already been checked to lie in `[0, 1]`.
    pub fn new(alpha: f64) -> Self {
        if alpha == 0.0 {
            Exponent::Zero
        } else if alpha == 0.5 {
            Exponent::Half
        } else if alpha == 1.0 {
            Exponent::One
        } else {
            Exponent::General(alpha)
        }
    }

    /// The exponent as a number.
    pub fn value(self) -> f64 {
        match self {
            Exponent::Zero => 0.0,
            Exponent::Half => 0.5,
            Exponent::One => 1.0,
            Exponent::General(a) => a,
        }
    }

    /// `w^α` for `w ≥ 0`.
    #[inline(always)]
    pub fn pow(self, w: f64) -> f64 {
        match self {
            Exponent::Zero => 1.0,
            Exponent::Half => w.sqrt(),
            Exponent::One => w,
            Exponent::General(a) => w.powf(a),
        }
    }

    /// `w^α` for `w ≥ 0` evaluated as `e^(α·ln w)` whatever `α` is (`w^0 = 1`, `0^α = 0`
    /// for `α > 0`): smooth in `α`, for fitting the exponent. Agrees with
    /// [`Exponent::pow`] to rounding.
    #[inline]
    pub fn pow_smooth(self, w: f64) -> f64 {
        let alpha = self.value();
        if alpha == 0.0 {
            1.0
        } else if w <= 0.0 {
            0.0
        } else {
            (alpha * w.ln()).exp()
        }
    }

    /// `w^α` for `w > 0` given `ln w`, as `e^(α·ln w)` (`w^0 = 1`): see
    /// [`Exponent::pow_smooth`].
    #[inline]
    pub fn pow_from_ln(self, ln_w: f64) -> f64 {
        let alpha = self.value();
        if alpha == 0.0 {
            1.0
        } else {
            (alpha * ln_w).exp()
        }
    }
}
