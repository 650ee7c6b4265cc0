//! A specimen on the platen: a linear shear building fixed on it (the contract's
//! `specimen.storeys`, bottom storey first), or a general linear specimen (its mass, stiffness
//! and damping matrices and its influence along the platen's axis), of which the shear
//! building is the special case.
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
//!
//! A **general linear specimen** ([`Specimen::general`]) has DOFs `z` relative to the platen,
//! symmetric matrices `M` (positive definite), `K`, `C` (positive semi-definite) and the
//! influence `ι` (each DOF's rigid-body share of the platen's motion along its axis: the `x`
//! column of the six-DOF influence matrix; the platen moves along `x` only, so the other
//! columns do not matter here). Then
//!
//! ```text
//!     M·(z̈ + ι·a) + C·ż + K·z = 0
//!     B = ιᵀ·M·(z̈ + ι·a) = −ιᵀ·(K·z + C·ż)
//!     E = ½(v·ι + ż)ᵀ·M·(v·ι + ż) + ½zᵀ·K·z,   Ė = B·v − żᵀ·C·ż
//! ```
//!
//! and the storeys are the case `ι = 1`, `M` diagonal, `K` and `C` tridiagonal. A general
//! specimen's "drift" of DOF `i` (its column `storey{i}_…` of the output) is its displacement
//! relative to the platen: its DOFs need not be storeys stacked on one another.

use crate::error::{non_negative, positive, ModelError, Result};
use crate::hysteresis::{Hysteresis, HystereticStorey};

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

/// A validated specimen on the platen: a shear building (bottom storey first) or a general
/// linear specimen (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Specimen {
    /// The storeys, bottom first; empty for a general specimen.
    storeys: Vec<Storey>,
    /// A general specimen's matrices; `None` for a shear building.
    matrices: Option<Box<Matrices>>,
    /// Each storey's hysteresis (`None`: linear), one per storey; empty when every storey is
    /// linear.
    hysteresis: Vec<Option<Hysteresis>>,
    /// Each storey's height, m, where given (for drift ratios); empty when none is.
    heights_m: Vec<Option<f64>>,
}

/// A general linear specimen along the platen's axis: its matrices row-major (`n × n`) and
/// what the rates and the base shear take from them.
#[derive(Debug, Clone, PartialEq)]
struct Matrices {
    n: usize,
    mass: Vec<f64>,
    mass_inverse: Vec<f64>,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    /// `ι`, each DOF's share of the platen's motion.
    influence: Vec<f64>,
    /// `K·ι`: the base shear is `−(K·ι)·z − (C·ι)·ż` (`K`, `C` symmetric).
    base_stiffness: Vec<f64>,
    /// `C·ι`.
    base_damping: Vec<f64>,
    /// `ιᵀ·C·ι`: how the base shear's rate feels the platen's acceleration.
    base_damping_n_s_per_m: f64,
    /// `ιᵀ·M·ι`: the rigid-body mass the platen carries, kg.
    rigid_mass_kg: f64,
}

/// `Σⱼ a[i·n + j]·x[j]`, `j` rising.
#[inline(always)]
fn row_dot(a: &[f64], n: usize, i: usize, x: &[f64]) -> f64 {
    let row = &a[i * n..(i + 1) * n];
    let mut sum = 0.0;
    for (aij, xj) in row.iter().zip(x) {
        sum += aij * xj;
    }
    sum
}

/// `Σᵢ a[i]·b[i]`, `i` rising.
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut sum = 0.0;
    for (ai, bi) in a.iter().zip(b) {
        sum += ai * bi;
    }
    sum
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
        Ok(Self {
            storeys,
            matrices: None,
            hysteresis: Vec::new(),
            heights_m: Vec::new(),
        })
    }

    /// The general linear specimen `linear` on the uniaxial platen: its matrices, and the `x`
    /// column of its influence (the platen moves along `x` only; the other columns do not
    /// matter here).
    ///
    /// # Errors
    /// [`ModelError::InvalidTable`] at `specimen.influence` when the `x` column is all zero:
    /// such a specimen would not feel the platen's motion at all, which is a mistake in the
    /// file rather than a test.
    pub fn general(linear: &crate::multi_axis::LinearSpecimen) -> Result<Self> {
        let n = linear.len();
        let influence: Vec<f64> = linear.influence().column(0).iter().copied().collect();
        if influence.iter().all(|&x| x == 0.0) {
            return Err(ModelError::InvalidTable {
                path: "specimen.influence".into(),
                expected: "a non-zero share of x for some DOF (the first of each row's six \
                           numbers): on the uniaxial platen only x moves, and a specimen that \
                           does not feel it is not on the table"
                    .into(),
            });
        }
        let row_major = |m: &nalgebra::DMatrix<f64>| -> Vec<f64> {
            (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .map(|(i, j)| m[(i, j)])
                .collect()
        };
        let (mass, stiffness, damping) = (
            row_major(linear.mass()),
            row_major(linear.stiffness()),
            row_major(linear.damping()),
        );
        let inverse = linear
            .mass()
            .clone()
            .cholesky()
            .expect("a validated linear specimen has a positive definite mass")
            .inverse();
        let base_stiffness: Vec<f64> = (0..n)
            .map(|i| row_dot(&stiffness, n, i, &influence))
            .collect();
        let base_damping: Vec<f64> = (0..n)
            .map(|i| row_dot(&damping, n, i, &influence))
            .collect();
        let mass_influence: Vec<f64> = (0..n).map(|i| row_dot(&mass, n, i, &influence)).collect();
        Ok(Self {
            storeys: Vec::new(),
            matrices: Some(Box::new(Matrices {
                n,
                mass_inverse: row_major(&inverse),
                base_damping_n_s_per_m: dot(&influence, &base_damping),
                rigid_mass_kg: dot(&influence, &mass_influence),
                mass,
                stiffness,
                damping,
                influence,
                base_stiffness,
                base_damping,
            })),
            hysteresis: Vec::new(),
            heights_m: Vec::new(),
        })
    }

    /// The shear building with storey heights (one entry per storey, bottom first; `None`
    /// where not given), m: the drift ratios' denominators.
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] for a count that is not one per storey;
    /// [`ModelError::InvalidStorey`] for a height that is not finite and `> 0`.
    pub fn with_heights(mut self, heights_m: Vec<Option<f64>>) -> Result<Self> {
        if heights_m.len() != self.len() {
            return Err(ModelError::InvalidParameter {
                name: "height_m",
                value: heights_m.len() as f64,
                expected: "one entry per storey",
            });
        }
        for (i, h) in heights_m.iter().enumerate() {
            if let Some(h) = h {
                positive("height_m", *h).map_err(|e| ModelError::InvalidStorey {
                    index: i,
                    source: Box::new(e),
                })?;
            }
        }
        self.heights_m = if heights_m.iter().any(Option::is_some) {
            heights_m
        } else {
            Vec::new()
        };
        Ok(self)
    }

    /// Storey `i`'s height, m, if given.
    pub fn height_m(&self, i: usize) -> Option<f64> {
        self.heights_m.get(i).copied().flatten()
    }

    /// The shear building with `hysteresis` laid over its storeys (one entry per storey, bottom
    /// first; `None` keeps a storey linear): the storeys that yield
    /// ([`crate::hysteresis`]). The storey's stiffness is the elastic one.
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] for a general linear specimen (its DOFs are not
    /// storeys with a drift to yield on) or a count that is not one per storey.
    pub fn with_hysteresis(mut self, hysteresis: Vec<Option<Hysteresis>>) -> Result<Self> {
        if self.matrices.is_some() {
            return Err(ModelError::InvalidParameter {
                name: "hysteresis",
                value: hysteresis.len() as f64,
                expected: "storeys of a shear building: a general linear specimen's DOFs have \
                           no storey drift to yield on",
            });
        }
        if hysteresis.len() != self.storeys.len() {
            return Err(ModelError::InvalidParameter {
                name: "hysteresis",
                value: hysteresis.len() as f64,
                expected: "one entry per storey",
            });
        }
        self.hysteresis = if hysteresis.iter().any(Option::is_some) {
            hysteresis
        } else {
            Vec::new()
        };
        Ok(self)
    }

    /// Whether some storey yields (carries a [`Hysteresis`]).
    pub fn is_hysteretic(&self) -> bool {
        !self.hysteresis.is_empty()
    }

    /// Storey `i`'s hysteresis, if it has one.
    pub fn hysteresis(&self, i: usize) -> Option<&Hysteresis> {
        self.hysteresis.get(i).and_then(Option::as_ref)
    }

    /// Storey `i`'s hysteretic constants, if it yields.
    pub fn hysteretic_storey(&self, i: usize) -> Option<HystereticStorey> {
        self.hysteresis(i)
            .map(|h| HystereticStorey::new(self.storeys[i].stiffness_n_per_m, h))
    }

    /// Whether it is a shear building (its [`storeys`](Self::storeys) given), not a general
    /// linear specimen.
    pub fn is_shear_building(&self) -> bool {
        self.matrices.is_none()
    }

    /// Its influence `ιᵢ` along the platen's axis: 1 for every storey.
    #[inline(always)]
    pub fn influence(&self, i: usize) -> f64 {
        match &self.matrices {
            None => 1.0,
            Some(g) => g.influence[i],
        }
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

    /// The storeys, bottom first (empty for a general linear specimen).
    pub fn storeys(&self) -> &[Storey] {
        &self.storeys
    }

    /// Number of storeys (of DOFs, for a general linear specimen).
    pub fn len(&self) -> usize {
        match &self.matrices {
            None => self.storeys.len(),
            Some(g) => g.n,
        }
    }

    /// Always `false`: a specimen has at least one storey (for clippy's `len` convention).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Total mass `Σmᵢ`, kg: the mass the platen carries (a general specimen's rigid-body
    /// mass along the axis, `ιᵀ·M·ι`).
    pub fn total_mass_kg(&self) -> f64 {
        match &self.matrices {
            None => self.storeys.iter().map(|s| s.mass_kg).sum(),
            Some(g) => g.rigid_mass_kg,
        }
    }

    /// The mass matrix (diagonal for storeys), row-major `n×n`, kg.
    pub fn mass_matrix(&self) -> Vec<f64> {
        if let Some(g) = &self.matrices {
            return g.mass.clone();
        }
        let n = self.len();
        let mut m = vec![0.0; n * n];
        for (i, s) in self.storeys.iter().enumerate() {
            m[i * n + i] = s.mass_kg;
        }
        m
    }

    /// The fixed-base stiffness matrix (tridiagonal for storeys), row-major `n×n`, N/m.
    pub fn stiffness_matrix(&self) -> Vec<f64> {
        match &self.matrices {
            None => self.tridiagonal(|s| s.stiffness_n_per_m),
            Some(g) => g.stiffness.clone(),
        }
    }

    /// The fixed-base damping matrix (tridiagonal for storeys), row-major `n×n`, N·s/m.
    pub fn damping_matrix(&self) -> Vec<f64> {
        match &self.matrices {
            None => self.tridiagonal(|s| s.damping_n_s_per_m),
            Some(g) => g.damping.clone(),
        }
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
    /// iteration with the tridiagonal solve (the matrix is symmetric positive definite); for a
    /// general specimen, the lowest eigenvalue of `L⁻¹·K·L⁻ᵀ` (`M = L·Lᵀ`).
    pub fn first_eigenvalue(&self) -> f64 {
        if let Some(g) = &self.matrices {
            let n = g.n;
            let l = nalgebra::DMatrix::from_row_slice(n, n, &g.mass)
                .cholesky()
                .expect("a validated linear specimen has a positive definite mass")
                .l();
            let l_inv = l.try_inverse().expect("a Cholesky factor is invertible");
            let k = nalgebra::DMatrix::from_row_slice(n, n, &g.stiffness);
            let a = &l_inv * k * l_inv.transpose();
            let a = (&a + a.transpose()) * 0.5;
            return a.symmetric_eigenvalues().min();
        }
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

    /// The base shear `B = −(k₁z₁ + c₁ż₁)`, N (general: `−ιᵀ·(K·z + C·ż)`), from the relative
    /// displacements `z` and velocities `zd`: the force the platen exerts on the specimen
    /// (module docs).
    #[inline(always)]
    pub fn base_shear_n(&self, z: &[f64], zd: &[f64]) -> f64 {
        match &self.matrices {
            None => {
                let s = &self.storeys[0];
                -(s.stiffness_n_per_m * z[0] + s.damping_n_s_per_m * zd[0])
            }
            Some(g) => -(dot(&g.base_stiffness, &z[..g.n]) + dot(&g.base_damping, &zd[..g.n])),
        }
    }

    /// The base shear's rate `Ḃ = −(k₁ż₁ + c₁z̈₁)`, N/s (general: `−ιᵀ·(K·ż + C·z̈)`), from the
    /// relative velocities `zd` and accelerations `zdd`.
    #[inline(always)]
    pub fn base_shear_rate_n_s(&self, zd: &[f64], zdd: &[f64]) -> f64 {
        self.base_shear_n(zd, zdd)
    }

    /// `Ḟ − Ḃ`, N/s: the force rate `force_rate_n_s` less the base shear's rate, as
    /// `Ḟ + k₁ż₁ + c₁z̈₁` for storeys (general: `Ḟ + ιᵀ·(K·ż + C·z̈)`), from the relative
    /// velocities `zd` and accelerations `zdd`. The net force's rate at rest.
    #[inline(always)]
    pub fn less_base_shear_rate(&self, force_rate_n_s: f64, zd: &[f64], zdd: &[f64]) -> f64 {
        match &self.matrices {
            None => {
                let s = &self.storeys[0];
                force_rate_n_s + s.stiffness_n_per_m * zd[0] + s.damping_n_s_per_m * zdd[0]
            }
            Some(_) => force_rate_n_s - self.base_shear_rate_n_s(zd, zdd),
        }
    }

    /// How the base shear's rate feels the platen's acceleration `a` (`∂Ḃ/∂a`, N·s/m): the
    /// bottom storey's `c₁` (general: `ιᵀ·C·ι`), since `z̈ = z̈⁰ − ι·a`.
    #[inline(always)]
    pub fn base_damping_n_s_per_m(&self) -> f64 {
        match &self.matrices {
            None => self.storeys[0].damping_n_s_per_m,
            Some(g) => g.base_damping_n_s_per_m,
        }
    }

    /// The absolute acceleration of storey (DOF) `i`, m/s², under platen acceleration `a`
    /// from its relative acceleration `zdd_i`: `a + z̈ᵢ` (general: `ιᵢ·a + z̈ᵢ`).
    #[inline(always)]
    pub fn absolute_acceleration_m_s2(&self, i: usize, a_m_s2: f64, zdd_i: f64) -> f64 {
        match &self.matrices {
            None => a_m_s2 + zdd_i,
            Some(g) => g.influence[i] * a_m_s2 + zdd_i,
        }
    }

    /// The drift of storey `i`, m: `zᵢ − zᵢ₋₁` (`z₀ = 0`); a general specimen's DOF `i`
    /// relative to the platen, `zᵢ`.
    #[inline(always)]
    pub fn drift_m(&self, i: usize, z: &[f64]) -> f64 {
        match (&self.matrices, i) {
            (None, 0) => z[0] - 0.0,
            (None, _) => z[i] - z[i - 1],
            (Some(_), _) => z[i],
        }
    }

    /// The relative storey accelerations `z̈ᵢ` under platen acceleration `a`, written into
    /// `out[..n]`, from the relative displacements `z[..n]` and velocities `zd[..n]`; returns
    /// the power `Σcᵢḋᵢ² ≥ 0` dissipated by the storey dampers, W.
    ///
    /// A general specimen: `z̈ = −M⁻¹·(K·z + C·ż) − ι·a`, and the power `żᵀ·C·ż`.
    #[inline(always)]
    pub fn storey_accelerations(&self, a_m_s2: f64, z: &[f64], zd: &[f64], out: &mut [f64]) -> f64 {
        if let Some(g) = &self.matrices {
            return g.accelerations(a_m_s2, z, zd, out);
        }
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

    /// The specimen's energy `½Σmᵢ(v + żᵢ)² + ½Σkᵢdᵢ²`, J, at platen velocity `v` (general:
    /// `½(v·ι + ż)ᵀ·M·(v·ι + ż) + ½zᵀ·K·z`).
    pub fn energy_j(&self, v_m_s: f64, z: &[f64], zd: &[f64]) -> f64 {
        if let Some(g) = &self.matrices {
            return g.energy_j(v_m_s, z, zd);
        }
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

impl Matrices {
    /// [`Specimen::storey_accelerations`] of a general specimen: `z̈ = −M⁻¹·r − ι·a` with
    /// `r = K·z + C·ż`, and the power `żᵀ·C·ż`. No allocation (the DOFs are at most
    /// [`Specimen::MAX_STOREYS`]).
    #[inline(always)]
    fn accelerations(&self, a_m_s2: f64, z: &[f64], zd: &[f64], out: &mut [f64]) -> f64 {
        let n = self.n;
        let (z, zd) = (&z[..n], &zd[..n]);
        let mut r = [0.0; Specimen::MAX_STOREYS];
        let mut power = 0.0;
        for (i, ri) in r[..n].iter_mut().enumerate() {
            let cz = row_dot(&self.damping, n, i, zd);
            *ri = row_dot(&self.stiffness, n, i, z) + cz;
            power += zd[i] * cz;
        }
        for (i, o) in out[..n].iter_mut().enumerate() {
            *o = -row_dot(&self.mass_inverse, n, i, &r[..n]) - self.influence[i] * a_m_s2;
        }
        power
    }

    /// [`Specimen::energy_j`] of a general specimen (no allocation: it is called at every
    /// output sample of an energy-checked run).
    fn energy_j(&self, v_m_s: f64, z: &[f64], zd: &[f64]) -> f64 {
        let n = self.n;
        let mut w = [0.0; Specimen::MAX_STOREYS];
        for (i, wi) in w[..n].iter_mut().enumerate() {
            *wi = v_m_s * self.influence[i] + zd[i];
        }
        let w = &w[..n];
        let mut e = 0.0;
        for i in 0..n {
            e += 0.5 * w[i] * row_dot(&self.mass, n, i, w)
                + 0.5 * z[i] * row_dot(&self.stiffness, n, i, &z[..n]);
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
        let b = s.base_shear_n(&z, &zd);
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
