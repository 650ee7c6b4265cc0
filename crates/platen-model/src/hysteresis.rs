//! Hysteretic storeys: a storey of a shear building that yields.
//!
//! # Equations
//!
//! A storey of elastic stiffness `k`, yield force `F_y`, yield drift `δ_y = F_y/k` and
//! post-yield stiffness ratio `a` (`0 ≤ a < 1`) resists its drift `δ` with the restoring
//! force
//!
//! ```text
//!     F = a·k·δ + q,          q = (1 − a)·k·r      (the hysteretic part, |q| ≤ q_y)
//! ```
//!
//! with `q_y = (1 − a)·F_y` and `r` the elastic-plastic drift. The storey's dashpot acts on
//! `δ̇` beside it, as on a linear storey. Two laws for `q`:
//!
//! * **bilinear** (kinematic hardening; `a = 0` is elastic-perfectly plastic): `ṙ = δ̇` while
//!   `|r| < δ_y`, or while `|r| = δ_y` and the drift unloads (`δ̇·r < 0`); `ṙ = 0` while the
//!   storey yields (`|r| = δ_y`, `δ̇·r ≥ 0`). The branch is part of the state and changes at
//!   located events: **yield** where `|r|` reaches `δ_y`, **unloading** where `δ̇` crosses
//!   zero while yielding. Between events the storey is linear: on the elastic branch
//!   `F = k·δ − (1 − a)·k·δ_p` with the plastic drift `δ_p` held (`r = δ − δ_p`), on the
//!   yielding branch `F = a·k·δ + s·q_y` (`s = ±1` the direction of yield) with `δ_p`
//!   following `δ`. The state variable is the plastic drift `δ_p`, m. So an
//!   elastic-perfectly plastic storey holds exactly `±F_y` while it yields, and a storey that
//!   never yields (`δ_p = 0`) computes `k·δ` bit for bit as a linear one.
//! * **Bouc–Wen** (smooth): `q̇ = (1 − a)·k·δ̇·(1 − |q/q_y|ⁿ·(b·sgn(δ̇·q) + 1 − b))`, the
//!   exponent `n` and `b` the share of `β` in `β + γ` (`b = ½` the common symmetric choice).
//!   `q` tends to `±q_y` as the storey yields, and to the bilinear law as `n → ∞`. The state
//!   variable is `q`, N. This is OpenSees' `uniaxialMaterial BoucWen` with `alpha = a`,
//!   `ko = k`, `n`, `beta = b/δ_yⁿ`, `gamma = (1 − b)/δ_yⁿ`, `Ao = 1` and no degradation.
//!
//! The energy dissipated in hysteresis is the work of the plastic part,
//! `E_h = ∫ q·(δ̇ − q̇/((1 − a)·k)) dt ≥ 0`: for the bilinear law `s·q_y·δ̇` while yielding
//! and 0 on the elastic branch; for Bouc–Wen `q·δ̇·|q/q_y|ⁿ·(b·sgn(δ̇·q) + 1 − b)`. The
//! storey's stored (recoverable) energy is `½·a·k·δ² + q²/(2(1 − a)k)`.

use crate::error::{non_negative, positive, ModelError, Result};

/// How a storey's hysteretic force evolves (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HysteresisLaw {
    /// Bilinear with kinematic hardening: exact yield and unloading events.
    Bilinear,
    /// Bouc–Wen: the smooth law, its force part of the integrated state.
    BoucWen {
        /// The exponent `n` (`≥ 1`; larger is sharper, `→ ∞` is bilinear).
        exponent: f64,
        /// `b = β/(β + γ)` in `[0, 1]`; ½ is the symmetric common choice.
        beta_share: f64,
    },
}

/// A storey's validated hysteresis: its law, yield force and post-yield stiffness ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hysteresis {
    law: HysteresisLaw,
    yield_force_n: f64,
    post_yield_stiffness_ratio: f64,
}

/// The largest Bouc–Wen exponent accepted: beyond it `|q/q_y|ⁿ` is the bilinear corner to
/// rounding and its rate stiff enough to need steps far below any record's; the bilinear law
/// is the exact choice there.
pub const MAX_BOUC_WEN_EXPONENT: f64 = 64.0;

impl Hysteresis {
    /// Bilinear hysteresis: yield force `F_y > 0`, N, and post-yield stiffness ratio
    /// `0 ≤ a < 1` (0: elastic-perfectly plastic).
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] naming the offending value.
    pub fn bilinear(yield_force_n: f64, post_yield_stiffness_ratio: f64) -> Result<Self> {
        Self::checked(
            HysteresisLaw::Bilinear,
            yield_force_n,
            post_yield_stiffness_ratio,
        )
    }

    /// Bouc–Wen hysteresis: yield force `F_y > 0`, N, post-yield stiffness ratio `0 ≤ a < 1`,
    /// exponent `1 ≤ n ≤` [`MAX_BOUC_WEN_EXPONENT`] and `0 ≤ b ≤ 1` (module docs).
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] naming the offending value.
    pub fn bouc_wen(
        yield_force_n: f64,
        post_yield_stiffness_ratio: f64,
        exponent: f64,
        beta_share: f64,
    ) -> Result<Self> {
        if !(exponent.is_finite() && (1.0..=MAX_BOUC_WEN_EXPONENT).contains(&exponent)) {
            return Err(ModelError::InvalidParameter {
                name: "exponent",
                value: exponent,
                expected: "a Bouc–Wen exponent between 1 and 64 (2 is common; the bilinear law \
                           is the sharp limit)",
            });
        }
        if !(beta_share.is_finite() && (0.0..=1.0).contains(&beta_share)) {
            return Err(ModelError::InvalidParameter {
                name: "beta_share",
                value: beta_share,
                expected: "β/(β + γ) between 0 and 1 (0.5 is the symmetric common choice)",
            });
        }
        Self::checked(
            HysteresisLaw::BoucWen {
                exponent,
                beta_share,
            },
            yield_force_n,
            post_yield_stiffness_ratio,
        )
    }

    fn checked(law: HysteresisLaw, yield_force_n: f64, ratio: f64) -> Result<Self> {
        positive("yield_force_n", yield_force_n)?;
        non_negative("post_yield_stiffness_ratio", ratio)?;
        if ratio >= 1.0 {
            return Err(ModelError::InvalidParameter {
                name: "post_yield_stiffness_ratio",
                value: ratio,
                expected: "a ratio below 1 (1 is a linear storey: leave the hysteresis out)",
            });
        }
        Ok(Self {
            law,
            yield_force_n,
            post_yield_stiffness_ratio: ratio,
        })
    }

    /// The law.
    pub fn law(&self) -> HysteresisLaw {
        self.law
    }

    /// Yield force `F_y`, N.
    pub fn yield_force_n(&self) -> f64 {
        self.yield_force_n
    }

    /// Post-yield stiffness ratio `a`.
    pub fn post_yield_stiffness_ratio(&self) -> f64 {
        self.post_yield_stiffness_ratio
    }
}

/// A hysteretic storey's branch: where its law is smooth, between located events (module
/// docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Branch {
    /// Bilinear, inside the elastic range (or unloading from it): the plastic drift is held.
    Elastic,
    /// Bilinear, yielding in the direction of the sign (`±1.0`): the hysteretic force is
    /// `sign·q_y`.
    Yielding(f64),
    /// Bouc–Wen, the drift moving in the direction of the sign (`±1.0`): the law's
    /// `sgn(δ̇·q)` is taken as `sign·sgn(q)`, so that the rate is smooth on the branch, and the
    /// branch changes where `δ̇` crosses zero (a kink of the law that would otherwise cost RK4
    /// its order at every reversal).
    Moving(f64),
}

/// A hysteretic storey's constants, precomputed for the integrators' inner loops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HystereticStorey {
    /// Elastic stiffness `k`, N/m.
    pub k: f64,
    /// `a·k`, N/m.
    pub ak: f64,
    /// `(1 − a)·k`, N/m.
    pub pk: f64,
    /// `q_y = (1 − a)·F_y`, N.
    pub qy: f64,
    /// Yield drift `δ_y = F_y/k`, m.
    pub yield_drift_m: f64,
    /// The law.
    pub law: HysteresisLaw,
}

impl HystereticStorey {
    /// The constants of a storey of elastic stiffness `k` (N/m) with `hysteresis`.
    pub fn new(stiffness_n_per_m: f64, hysteresis: &Hysteresis) -> Self {
        let (k, a, fy) = (
            stiffness_n_per_m,
            hysteresis.post_yield_stiffness_ratio,
            hysteresis.yield_force_n,
        );
        Self {
            k,
            ak: a * k,
            pk: (1.0 - a) * k,
            qy: (1.0 - a) * fy,
            yield_drift_m: fy / k,
            law: hysteresis.law,
        }
    }

    /// Whether the law is the bilinear one rather than Bouc–Wen.
    pub fn is_bilinear(&self) -> bool {
        matches!(self.law, HysteresisLaw::Bilinear)
    }

    /// The branch of a storey at rest and unstrained: elastic (bilinear), or moving in the
    /// positive direction (Bouc–Wen: with `q = 0` the direction does not enter the rate, and
    /// a drift that starts the other way is an event at the start).
    pub fn initial_branch(&self) -> Branch {
        match self.law {
            HysteresisLaw::Bilinear => Branch::Elastic,
            HysteresisLaw::BoucWen { .. } => Branch::Moving(1.0),
        }
    }

    /// The restoring force `F`, N, at drift `δ` (m) with the state variable `h` (bilinear: the
    /// plastic drift `δ_p`, m; Bouc–Wen: `q`, N) on `branch` (ignored by Bouc–Wen).
    #[inline(always)]
    pub fn force_n(&self, drift_m: f64, h: f64, branch: Branch) -> f64 {
        match (self.law, branch) {
            (HysteresisLaw::Bilinear, Branch::Yielding(s)) => self.ak * drift_m + s * self.qy,
            (HysteresisLaw::Bilinear, _) => self.k * drift_m - self.pk * h,
            (HysteresisLaw::BoucWen { .. }, _) => self.ak * drift_m + h,
        }
    }

    /// The hysteretic force `q`, N (`F − a·k·δ`).
    #[inline(always)]
    pub fn hysteretic_force_n(&self, drift_m: f64, h: f64, branch: Branch) -> f64 {
        match (self.law, branch) {
            (HysteresisLaw::Bilinear, Branch::Yielding(s)) => s * self.qy,
            (HysteresisLaw::Bilinear, _) => self.pk * (drift_m - h),
            (HysteresisLaw::BoucWen { .. }, _) => h,
        }
    }

    /// The law's own rate at drift rate `δ̇` and state `h`, 1/s: Bouc–Wen's
    /// `|∂q̇/∂q| ≤ n·|δ̇|/δ_y·|q/q_y|ⁿ⁻¹` (a fast drift over a small yield drift makes it stiff:
    /// a fixed step must resolve it); 0 for the bilinear law, linear on each branch.
    #[inline]
    pub fn own_rate_1_s(&self, drift_rate_m_s: f64, h: f64) -> f64 {
        match self.law {
            HysteresisLaw::Bilinear => 0.0,
            HysteresisLaw::BoucWen { exponent, .. } => {
                let ratio = (h / self.qy).abs();
                exponent * drift_rate_m_s.abs() / self.yield_drift_m * ratio.powf(exponent - 1.0)
            }
        }
    }

    /// The restoring force's rate, N/s, at drift rate `δ̇` with the state variable's rate `ḣ`
    /// on `branch`.
    #[inline(always)]
    pub fn force_rate_n_s(&self, drift_rate_m_s: f64, h_rate: f64, branch: Branch) -> f64 {
        match (self.law, branch) {
            (HysteresisLaw::Bilinear, Branch::Yielding(_)) => self.ak * drift_rate_m_s,
            (HysteresisLaw::Bilinear, _) => self.k * drift_rate_m_s - self.pk * h_rate,
            (HysteresisLaw::BoucWen { .. }, _) => self.ak * drift_rate_m_s + h_rate,
        }
    }

    /// The rates `(ḣ, Ė_h)` of the state variable and of the hysteretic energy (W) at drift
    /// rate `δ̇` (m/s), state `h` on `branch` (Bouc–Wen on [`Branch::Moving`] takes
    /// `sgn(δ̇·q)` as the branch's direction times `sgn(q)`; on any other branch from `δ̇`).
    #[inline(always)]
    pub fn rates(&self, drift_rate_m_s: f64, h: f64, branch: Branch) -> (f64, f64) {
        match (self.law, branch) {
            (HysteresisLaw::Bilinear, Branch::Yielding(s)) => {
                (drift_rate_m_s, s * self.qy * drift_rate_m_s)
            }
            (HysteresisLaw::Bilinear, _) => (0.0, 0.0),
            (
                HysteresisLaw::BoucWen {
                    exponent,
                    beta_share,
                },
                _,
            ) => {
                let ratio = (h / self.qy).abs();
                let pow = if exponent == 2.0 {
                    ratio * ratio
                } else {
                    ratio.powf(exponent)
                };
                let direction = match branch {
                    Branch::Moving(d) => d,
                    _ => drift_rate_m_s,
                };
                let sign = if direction * h > 0.0 {
                    1.0
                } else if direction * h < 0.0 {
                    -1.0
                } else {
                    0.0
                };
                let plastic = pow * (beta_share * sign + 1.0 - beta_share);
                (
                    self.pk * drift_rate_m_s * (1.0 - plastic),
                    h * drift_rate_m_s * plastic,
                )
            }
        }
    }

    /// The event function on `branch`: positive while the branch holds, crossing zero at its
    /// event (bilinear elastic: `δ_y − |δ − δ_p|`, reaching the yield drift; yielding in
    /// direction `s`, or Bouc–Wen moving in direction `s`: `s·δ̇`, the drift rate turning
    /// back).
    #[inline(always)]
    pub fn event_margin(&self, drift_m: f64, drift_rate_m_s: f64, h: f64, branch: Branch) -> f64 {
        match branch {
            Branch::Elastic => self.yield_drift_m - (drift_m - h).abs(),
            Branch::Yielding(s) | Branch::Moving(s) => s * drift_rate_m_s,
        }
    }

    /// The branch after the event of `branch` at drift `δ`, drift rate `δ̇` and state `h`, and
    /// the state to go on with: yield in the direction of `δ − δ_p` (the plastic drift kept),
    /// or unloading onto the elastic branch with `δ_p = δ − s·δ_y`, so that the hysteretic
    /// force continues from `s·q_y`; a yield reached while the drift already turns back (a
    /// graze) stays elastic. Bouc–Wen turns its direction (`q` kept).
    pub fn after_event(
        &self,
        drift_m: f64,
        drift_rate_m_s: f64,
        h: f64,
        branch: Branch,
    ) -> (Branch, f64) {
        match branch {
            Branch::Elastic => {
                let s = if drift_m - h >= 0.0 { 1.0 } else { -1.0 };
                if s * drift_rate_m_s > 0.0 {
                    (Branch::Yielding(s), h)
                } else {
                    (Branch::Elastic, h)
                }
            }
            Branch::Yielding(s) => (Branch::Elastic, drift_m - s * self.yield_drift_m),
            Branch::Moving(s) => (Branch::Moving(-s), h),
        }
    }

    /// The storey's recoverable energy `½·a·k·δ² + q²/(2(1 − a)k)`, J, at drift `δ` with
    /// hysteretic force `q`.
    #[inline(always)]
    pub fn stored_energy_j(&self, drift_m: f64, q_n: f64) -> f64 {
        0.5 * self.ak * drift_m * drift_m + 0.5 * q_n * q_n / self.pk
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_are_checked() {
        assert!(Hysteresis::bilinear(1e5, 0.0).is_ok());
        assert!(Hysteresis::bilinear(0.0, 0.0).is_err());
        assert!(Hysteresis::bilinear(1e5, 1.0).is_err());
        assert!(Hysteresis::bilinear(1e5, -0.1).is_err());
        assert!(Hysteresis::bilinear(f64::NAN, 0.1).is_err());
        assert!(Hysteresis::bouc_wen(1e5, 0.05, 2.0, 0.5).is_ok());
        assert!(Hysteresis::bouc_wen(1e5, 0.05, 0.5, 0.5).is_err());
        assert!(Hysteresis::bouc_wen(1e5, 0.05, 2.0, 1.5).is_err());
        let e = Hysteresis::bouc_wen(1e5, 0.05, 100.0, 0.5).unwrap_err();
        assert!(e.to_string().contains("exponent"), "{e}");
    }

    /// The elastic-perfectly plastic storey's force while yielding is the yield force itself,
    /// not a rounding of `k·(F_y/k)`; never yielded, the bilinear force is `k·δ` bit for bit.
    #[test]
    fn the_bilinear_forces_are_exact_where_they_should_be() {
        let h = HystereticStorey::new(27.3e6, &Hysteresis::bilinear(123_456.7, 0.0).unwrap());
        for d in [0.001, 0.37, 1e-7] {
            assert_eq!(h.force_n(d, 0.0, Branch::Yielding(1.0)), 123_456.7);
            assert_eq!(h.force_n(-d, 0.0, Branch::Yielding(-1.0)), -123_456.7);
            let small = d * 1e-3;
            assert_eq!(
                h.force_n(small, 0.0, Branch::Elastic).to_bits(),
                (27.3e6 * small).to_bits()
            );
        }
    }

    /// Bouc–Wen's rate vanishes at `q = ±q_y` on loading, and the hysteretic power is the
    /// drift rate times `q` less the recoverable part: `q·(δ̇ − q̇/((1 − a)k))`.
    #[test]
    fn bouc_wen_saturates_at_the_yield_force_and_its_power_is_the_plastic_work() {
        let h = HystereticStorey::new(1e7, &Hysteresis::bouc_wen(2e5, 0.1, 3.0, 0.5).unwrap());
        let (qd, p) = h.rates(0.2, h.qy, Branch::Elastic);
        assert!(qd.abs() < 1e-9 * h.pk, "{qd}");
        assert!((p - h.qy * 0.2).abs() < 1e-9 * h.qy, "{p}");
        for (rate, q) in [(0.3, 0.4 * h.qy), (-0.3, 0.4 * h.qy), (0.1, -0.9 * h.qy)] {
            let (qd, p) = h.rates(rate, q, Branch::Elastic);
            let expected = q * (rate - qd / h.pk);
            assert!(
                (p - expected).abs() <= 1e-12 * (q * rate).abs(),
                "{p} vs {expected}"
            );
        }
    }
}
