//! A specimen on the platen: a linear shear building fixed on it (the contract's
//! `specimen.storeys`, bottom storey first).
//!
//! # Equations
//!
//! Storey `i = 1…n` has mass `mᵢ`, storey stiffness `kᵢ` and storey viscous damping `cᵢ`;
//! `zᵢ` is its displacement relative to the platen, `dᵢ = zᵢ − zᵢ₋₁` its drift (`z₀ = 0`) and
//! `Vᵢ = kᵢdᵢ + cᵢḋᵢ` the shear in storey `i` (`Vₙ₊₁ = 0`). With the platen acceleration `a`:
//!
//! ```text
//!     mᵢ·(a + z̈ᵢ) = −Vᵢ + Vᵢ₊₁                      (storey i)
//!     B = Σ mᵢ·(a + z̈ᵢ) = −V₁ = −(k₁z₁ + c₁ż₁)        (base shear)
//!     M(u)·a = F_A − F_E(u) − F_D − B                 (platen)
//! ```
//!
//! `B` is the force the platen exerts on the specimen (positive along `u`): the specimen's mass
//! times its absolute acceleration. The specimen pushes back on the platen with `−B`, so the
//! actuator force is `F_A = F_I + F_E + F_D + B`. Because `B` depends on the storey state and not
//! on `a`, the platen's acceleration is explicit. At rest the platen sticks while
//! `|F_A − F_E(u) − B| ≤ F_s(u)`.
//!
//! The specimen's energy is `E = ½Σmᵢ(v + żᵢ)² + ½Σkᵢdᵢ²`, and `Ė = B·v − Σcᵢḋᵢ²`: the power
//! the platen feeds in minus what the storey dampers dissipate.

use crate::error::{non_negative, positive, ModelError, Result};

/// One storey of a shear building: its floor mass, storey stiffness and storey damping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Storey {
    /// Floor mass, kg (`> 0`).
    pub mass_kg: f64,
    /// Storey (inter-storey) stiffness, N/m (`> 0`).
    pub stiffness_n_per_m: f64,
    /// Storey (inter-storey) viscous damping, N·s/m (`≥ 0`).
    pub damping_n_s_per_m: f64,
}

/// A validated shear building on the platen, bottom storey first (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Specimen {
    storeys: Vec<Storey>,
}

impl Specimen {
    /// The most storeys a specimen may have (the integrators keep the storey state in
    /// fixed-size arrays so that a run never allocates per step).
    pub const MAX_STOREYS: usize = 12;

    /// Validates `storeys` (bottom first): at least one and at most
    /// [`Specimen::MAX_STOREYS`], every mass and stiffness finite and `> 0`, every damping
    /// finite and `≥ 0`.
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] for a storey count out of range;
    /// [`ModelError::InvalidStorey`] naming the storey (from 1, bottom first) and its first
    /// offending value.
    pub fn new(storeys: Vec<Storey>) -> Result<Self> {
        if storeys.is_empty() || storeys.len() > Self::MAX_STOREYS {
            return Err(ModelError::InvalidParameter {
                name: "storeys",
                value: storeys.len() as f64,
                expected: "between 1 and 12 storeys",
            });
        }
        for (i, s) in storeys.iter().enumerate() {
            let wrap = |e: ModelError| ModelError::InvalidStorey {
                index: i,
                source: Box::new(e),
            };
            positive("mass_kg", s.mass_kg).map_err(wrap)?;
            positive("stiffness_n_per_m", s.stiffness_n_per_m).map_err(wrap)?;
            non_negative("damping_n_s_per_m", s.damping_n_s_per_m).map_err(wrap)?;
        }
        Ok(Self { storeys })
    }

    /// A specimen from the modal data a user usually has: the storey masses (bottom first),
    /// the shape of the storey stiffnesses (`stiffness_profile`, any positive scale: the
    /// stiffnesses are `κ·profileᵢ`), the first natural frequency `f₁` (fixed base) and the
    /// first mode's damping ratio `ζ₁`.
    ///
    /// `κ` is set so that the first mode of the fixed-base building is at `f₁` (the lowest
    /// eigenvalue of `K·φ = ω²M·φ`, found by inverse iteration). Damping is **Rayleigh
    /// damping restricted to its stiffness-proportional part**, `C = β·K` with `β = 2ζ₁/ω₁`, so
    /// `cᵢ = β·kᵢ`: the mass-proportional part `α·M` of Rayleigh damping would be a dashpot
    /// from every floor to the ground, which a storey damper cannot represent. Mode `j` then has
    /// the damping ratio `ζⱼ = ζ₁·ωⱼ/ω₁`.
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] for masses or a profile that are not positive and
    /// finite or of different lengths, a frequency not `> 0`, or a damping ratio outside
    /// `[0, 1)`.
    pub fn from_first_mode(
        masses_kg: &[f64],
        stiffness_profile: &[f64],
        first_frequency_hz: f64,
        first_damping_ratio: f64,
    ) -> Result<Self> {
        if masses_kg.len() != stiffness_profile.len() {
            return Err(ModelError::InvalidParameter {
                name: "stiffness_profile",
                value: stiffness_profile.len() as f64,
                expected: "one value per storey mass",
            });
        }
        positive("first_frequency_hz", first_frequency_hz)?;
        if !(first_damping_ratio.is_finite() && (0.0..1.0).contains(&first_damping_ratio)) {
            return Err(ModelError::InvalidParameter {
                name: "first_damping_ratio",
                value: first_damping_ratio,
                expected: "a damping ratio in [0, 1)",
            });
        }
        let unit = Self::new(
            masses_kg
                .iter()
                .zip(stiffness_profile)
                .map(|(&m, &k)| Storey {
                    mass_kg: m,
                    stiffness_n_per_m: k,
                    damping_n_s_per_m: 0.0,
                })
                .collect(),
        )?;
        let omega_sq_unit = unit.first_eigenvalue();
        let omega = 2.0 * std::f64::consts::PI * first_frequency_hz;
        let kappa = omega * omega / omega_sq_unit;
        let beta = 2.0 * first_damping_ratio / omega;
        Self::new(
            unit.storeys
                .iter()
                .map(|s| Storey {
                    mass_kg: s.mass_kg,
                    stiffness_n_per_m: kappa * s.stiffness_n_per_m,
                    damping_n_s_per_m: beta * kappa * s.stiffness_n_per_m,
                })
                .collect(),
        )
    }

    /// The storeys, bottom first.
    pub fn storeys(&self) -> &[Storey] {
        &self.storeys
    }

    /// Number of storeys.
    pub fn len(&self) -> usize {
        self.storeys.len()
    }

    /// Always `false`: a specimen has at least one storey (for clippy's `len` convention).
    pub fn is_empty(&self) -> bool {
        self.storeys.is_empty()
    }

    /// Total mass `Σmᵢ`, kg.
    pub fn total_mass_kg(&self) -> f64 {
        self.storeys.iter().map(|s| s.mass_kg).sum()
    }

    /// The mass matrix (diagonal), row-major `n×n`, kg.
    pub fn mass_matrix(&self) -> Vec<f64> {
        let n = self.len();
        let mut m = vec![0.0; n * n];
        for (i, s) in self.storeys.iter().enumerate() {
            m[i * n + i] = s.mass_kg;
        }
        m
    }

    /// The fixed-base stiffness matrix (tridiagonal), row-major `n×n`, N/m.
    pub fn stiffness_matrix(&self) -> Vec<f64> {
        self.tridiagonal(|s| s.stiffness_n_per_m)
    }

    /// The fixed-base damping matrix (tridiagonal), row-major `n×n`, N·s/m.
    pub fn damping_matrix(&self) -> Vec<f64> {
        self.tridiagonal(|s| s.damping_n_s_per_m)
    }

    fn tridiagonal(&self, value: impl Fn(&Storey) -> f64) -> Vec<f64> {
        let n = self.len();
        let mut k = vec![0.0; n * n];
        for i in 0..n {
            let ki = value(&self.storeys[i]);
            k[i * n + i] += ki;
            if i > 0 {
                k[(i - 1) * n + (i - 1)] += ki;
                k[i * n + (i - 1)] -= ki;
                k[(i - 1) * n + i] -= ki;
            }
        }
        k
    }

    /// The lowest eigenvalue `ω₁²` of `K·φ = ω²·M·φ` (fixed base), rad²/s², by inverse
    /// iteration with the tridiagonal solve (the matrix is symmetric positive definite).
    pub fn first_eigenvalue(&self) -> f64 {
        let n = self.len();
        let k = self.stiffness_matrix();
        let mut x: Vec<f64> = (0..n).map(|i| (i + 1) as f64).collect();
        let mut lambda = 0.0;
        for _ in 0..500 {
            // Solve K·y = M·x (Thomas algorithm on the tridiagonal K).
            let rhs: Vec<f64> = (0..n).map(|i| self.storeys[i].mass_kg * x[i]).collect();
            let y = solve_tridiagonal(&k, n, &rhs);
            // Rayleigh quotient of y: (yᵀKy)/(yᵀMy).
            let ky = (0..n)
                .map(|i| y[i] * (0..n).map(|j| k[i * n + j] * y[j]).sum::<f64>())
                .sum::<f64>();
            let my = (0..n)
                .map(|i| self.storeys[i].mass_kg * y[i] * y[i])
                .sum::<f64>();
            let next = ky / my;
            let norm = my.sqrt();
            x = y.iter().map(|v| v / norm).collect();
            if (next - lambda).abs() <= 1e-15 * next {
                return next;
            }
            lambda = next;
        }
        lambda
    }

    /// The base shear `B = −(k₁z₁ + c₁ż₁)`, N, from the bottom storey's relative displacement
    /// and velocity: the force the platen exerts on the specimen (module docs).
    #[inline(always)]
    pub fn base_shear_n(&self, z1_m: f64, z1_m_s: f64) -> f64 {
        let s = &self.storeys[0];
        -(s.stiffness_n_per_m * z1_m + s.damping_n_s_per_m * z1_m_s)
    }

    /// The relative storey accelerations `z̈ᵢ` under platen acceleration `a`, written into
    /// `out[..n]`, from the relative displacements `z[..n]` and velocities `zd[..n]`; returns
    /// the power `Σcᵢḋᵢ² ≥ 0` dissipated by the storey dampers, W.
    #[inline(always)]
    pub fn storey_accelerations(&self, a_m_s2: f64, z: &[f64], zd: &[f64], out: &mut [f64]) -> f64 {
        let n = self.len();
        let (storeys, z, zd, out) = (&self.storeys[..n], &z[..n], &zd[..n], &mut out[..n]);
        let mut power = 0.0;
        // The shear Vᵢ of each storey from the bottom; floor i−1 feels −Vᵢ₋₁ + Vᵢ, the top
        // floor −Vₙ.
        let (mut z_prev, mut zd_prev, mut shear_prev) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let s = &storeys[i];
            let (d, dd) = (z[i] - z_prev, zd[i] - zd_prev);
            let shear = s.stiffness_n_per_m * d + s.damping_n_s_per_m * dd;
            power += s.damping_n_s_per_m * dd * dd;
            if i > 0 {
                out[i - 1] = (shear - shear_prev) / storeys[i - 1].mass_kg - a_m_s2;
            }
            (z_prev, zd_prev, shear_prev) = (z[i], zd[i], shear);
        }
        out[n - 1] = -shear_prev / storeys[n - 1].mass_kg - a_m_s2;
        power
    }

    /// The specimen's energy `½Σmᵢ(v + żᵢ)² + ½Σkᵢdᵢ²`, J, at platen velocity `v`.
    pub fn energy_j(&self, v_m_s: f64, z: &[f64], zd: &[f64]) -> f64 {
        let mut e = 0.0;
        let mut z_prev = 0.0;
        for (i, s) in self.storeys.iter().enumerate() {
            let w = v_m_s + zd[i];
            let d = z[i] - z_prev;
            e += 0.5 * s.mass_kg * w * w + 0.5 * s.stiffness_n_per_m * d * d;
            z_prev = z[i];
        }
        e
    }
}

/// Solves the tridiagonal system `A·y = rhs` (`A` row-major `n×n`, diagonally dominant or
/// symmetric positive definite) by the Thomas algorithm.
fn solve_tridiagonal(a: &[f64], n: usize, rhs: &[f64]) -> Vec<f64> {
    let mut c = vec![0.0; n];
    let mut d = vec![0.0; n];
    for i in 0..n {
        let lower = if i > 0 { a[i * n + i - 1] } else { 0.0 };
        let upper = if i + 1 < n { a[i * n + i + 1] } else { 0.0 };
        let (c_prev, d_prev) = if i > 0 {
            (c[i - 1], d[i - 1])
        } else {
            (0.0, 0.0)
        };
        let denom = a[i * n + i] - lower * c_prev;
        c[i] = upper / denom;
        d[i] = (rhs[i] - lower * d_prev) / denom;
    }
    let mut y = vec![0.0; n];
    for i in (0..n).rev() {
        y[i] = d[i] - if i + 1 < n { c[i] * y[i + 1] } else { 0.0 };
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_storey() -> Specimen {
        Specimen::new(vec![
            Storey {
                mass_kg: 30e3,
                stiffness_n_per_m: 60e6,
                damping_n_s_per_m: 40e3,
            },
            Storey {
                mass_kg: 20e3,
                stiffness_n_per_m: 40e6,
                damping_n_s_per_m: 25e3,
            },
        ])
        .unwrap()
    }

    /// The 2-DOF eigenvalues in closed form: λ₁λ₂ = k₁k₂/(m₁m₂) and
    /// λ₁ + λ₂ = (k₁ + k₂)/m₁ + k₂/m₂, the roots of the characteristic quadratic.
    #[test]
    fn the_first_eigenvalue_is_the_root_of_the_two_storey_quadratic() {
        let (m1, m2, k1, k2): (f64, f64, f64, f64) = (30e3, 20e3, 60e6, 40e6);
        let sum = (k1 + k2) / m1 + k2 / m2;
        let prod = k1 * k2 / (m1 * m2);
        let lambda1 = 0.5 * (sum - (sum * sum - 4.0 * prod).sqrt());
        let found = two_storey().first_eigenvalue();
        assert!(
            (found / lambda1 - 1.0).abs() < 1e-12,
            "{found} vs {lambda1}"
        );
    }

    /// A single storey: f₁ = √(k/m)/2π, and c = 2ζ√(km) (the SDOF damping ratio).
    #[test]
    fn the_modal_constructor_hits_the_frequency_and_the_damping_ratio() {
        let s = Specimen::from_first_mode(&[40e3], &[1.0], 5.0, 0.02).unwrap();
        let st = s.storeys()[0];
        let omega = (st.stiffness_n_per_m / st.mass_kg).sqrt();
        assert!((omega / (2.0 * std::f64::consts::PI * 5.0) - 1.0).abs() < 1e-12);
        let zeta = st.damping_n_s_per_m / (2.0 * (st.stiffness_n_per_m * st.mass_kg).sqrt());
        assert!((zeta - 0.02).abs() < 1e-12);
        let two = Specimen::from_first_mode(&[30e3, 20e3], &[3.0, 2.0], 4.0, 0.03).unwrap();
        let f1 = two.first_eigenvalue().sqrt() / (2.0 * std::f64::consts::PI);
        assert!((f1 - 4.0).abs() < 1e-10, "{f1}");
        let s0 = two.storeys()[0];
        assert!((s0.stiffness_n_per_m / two.storeys()[1].stiffness_n_per_m - 1.5).abs() < 1e-12);
    }

    /// The storey equations against the matrices: M(z̈ + a·1) = −Kz − Cż, and the base shear
    /// is the sum of the storeys' absolute inertia forces.
    #[test]
    fn the_storey_rates_match_the_matrices_and_sum_to_the_base_shear() {
        let s = two_storey();
        let (z, zd, a) = ([0.01, 0.025], [0.3, -0.2], 1.7);
        let mut out = [0.0; 2];
        let power = s.storey_accelerations(a, &z, &zd, &mut out);
        let (m, k, c) = (s.mass_matrix(), s.stiffness_matrix(), s.damping_matrix());
        for i in 0..2 {
            let rhs: f64 = -(0..2)
                .map(|j| k[i * 2 + j] * z[j] + c[i * 2 + j] * zd[j])
                .sum::<f64>();
            let lhs = m[i * 2 + i] * (out[i] + a);
            assert!((lhs - rhs).abs() <= 1e-9 * rhs.abs(), "{i}: {lhs} vs {rhs}");
        }
        let inertia: f64 = (0..2).map(|i| m[i * 2 + i] * (out[i] + a)).sum();
        let b = s.base_shear_n(z[0], zd[0]);
        assert!((inertia - b).abs() <= 1e-9 * b.abs(), "{inertia} vs {b}");
        let expected = 40e3 * 0.3f64.powi(2) + 25e3 * 0.5f64.powi(2);
        assert!((power - expected).abs() <= 1e-9 * expected);
    }

    #[test]
    fn invalid_storeys_are_rejected_with_their_index() {
        assert!(Specimen::new(vec![]).is_err());
        let mut st = two_storey().storeys().to_vec();
        st[1].stiffness_n_per_m = 0.0;
        let e = Specimen::new(st.clone()).unwrap_err().to_string();
        assert!(
            e.contains("storey 2") && e.contains("stiffness_n_per_m"),
            "{e}"
        );
        st[1].stiffness_n_per_m = 1.0;
        st[0].damping_n_s_per_m = f64::NAN;
        assert!(Specimen::new(st).is_err());
        assert!(Specimen::from_first_mode(&[1.0], &[1.0], 5.0, 1.5).is_err());
        assert!(Specimen::from_first_mode(&[1.0, 2.0], &[1.0], 5.0, 0.0).is_err());
    }
}
