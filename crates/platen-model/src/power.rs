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
}
