//! A general linear specimen on the multi-axis platen.

use nalgebra::{DMatrix, DVector, Matrix6};

use super::modes::Mode;
use super::table::{MultiAxisTable, Wrench, MAX_GEOMETRY_M};

/// The most DOFs a general linear specimen may have: the six-DOF runs carry its state in
/// fixed-size arrays, and a larger one is a finite-element model to condense first.
pub const MAX_SPECIMEN_DOFS: usize = 12;
use crate::error::{ModelError, Result};
use crate::Specimen;

/// A linear specimen fixed on the platen: `n` DOFs `z` relative to the platen with mass,
/// stiffness and damping matrices (SI units per DOF) and an influence matrix `Γ` (`n × 6`:
/// each DOF's rigid-body share of the platen's accelerations `(ẗ, ω̇)` about the reference
/// point, table axes). It moves by `M·(z̈ + Γ·a) + C·ż + K·z = 0` and pushes on the platen
/// with the wrench `Γᵀ·(C·ż + K·z)` (the reaction to `Γᵀ·M·(z̈ + Γ·a)`, the force of the
/// platen on it).
#[derive(Debug, Clone, PartialEq)]
pub struct LinearSpecimen {
    mass: DMatrix<f64>,
    stiffness: DMatrix<f64>,
    damping: DMatrix<f64>,
    influence: DMatrix<f64>,
    /// The Cholesky factor's inverse product `M⁻¹`, kept for the rates.
    mass_inverse: DMatrix<f64>,
    /// `Γᵀ` (`6 × n`), kept for the wrench on the platen.
    influence_transpose: DMatrix<f64>,
}

/// `out = A·x` for `A` stored column by column (`out.len()` rows, `x.len()` columns), as
/// nalgebra's `A * x` computes it (its gemv, one column at a time): `outᵢ = Aᵢ₀·x₀`, then
/// `outᵢ = Aᵢⱼ·xⱼ + outᵢ` for `j` rising (a floating-point sum of two numbers does not depend
/// on their order). Each number is therefore the same, bit for bit, as the allocating
/// product's (tested against it).
#[inline(always)]
fn product_into(a: &[f64], x: &[f64], out: &mut [f64]) {
    let rows = out.len();
    let mut columns = a.chunks_exact(rows).zip(x);
    if let Some((column, &xj)) = columns.next() {
        for (o, &aij) in out.iter_mut().zip(column) {
            *o = aij * xj;
        }
    }
    for (column, &xj) in columns {
        for (o, &aij) in out.iter_mut().zip(column) {
            *o += aij * xj;
        }
    }
}

/// Row `i` of `A·x` (`A` stored column by column with `rows` rows, `x.len()` columns) in the
/// order of [`product_into`].
#[inline(always)]
fn row_product(a: &[f64], rows: usize, i: usize, x: &[f64]) -> f64 {
    let mut sum = a[i] * x[0];
    for (j, xj) in x.iter().enumerate().skip(1) {
        sum += a[j * rows + i] * xj;
    }
    sum
}

fn invalid(path: &str, expected: impl Into<String>) -> ModelError {
    ModelError::InvalidTable {
        path: path.into(),
        expected: expected.into(),
    }
}

fn square(path: &str, m: &DMatrix<f64>, n: usize) -> Result<()> {
    if m.nrows() != n || m.ncols() != n {
        return Err(invalid(
            path,
            format!("a {n}×{n} matrix (one row and column per DOF)"),
        ));
    }
    if !m.iter().all(|x| x.is_finite()) {
        return Err(invalid(path, "finite numbers"));
    }
    let scale = m.abs().max().max(f64::MIN_POSITIVE);
    if (m - m.transpose()).abs().max() > 1e-9 * scale {
        return Err(invalid(path, "a symmetric matrix"));
    }
    Ok(())
}

impl LinearSpecimen {
    /// A specimen of these matrices. Paths in errors are under `specimen`.
    ///
    /// # Errors
    /// [`ModelError::InvalidTable`] when a matrix is not `n × n` and symmetric (the influence
    /// `n × 6`), the mass matrix is not positive definite, or stiffness or damping has a
    /// negative eigenvalue.
    pub fn new(
        mass: DMatrix<f64>,
        stiffness: DMatrix<f64>,
        damping: DMatrix<f64>,
        influence: DMatrix<f64>,
    ) -> Result<Self> {
        let n = mass.nrows();
        if n == 0 {
            return Err(invalid("specimen.mass_matrix", "at least one DOF"));
        }
        if n > MAX_SPECIMEN_DOFS {
            return Err(invalid(
                "specimen.mass_matrix",
                format!(
                    "at most {MAX_SPECIMEN_DOFS} DOFs (got {n}): the six-DOF runs carry the \
                     specimen's state in fixed-size arrays; reduce it to its modes that matter \
                     (a modal or static condensation)"
                ),
            ));
        }
        square("specimen.mass_matrix", &mass, n)?;
        square("specimen.stiffness_matrix", &stiffness, n)?;
        square("specimen.damping_matrix", &damping, n)?;
        if influence.nrows() != n
            || influence.ncols() != 6
            || !influence
                .iter()
                .all(|x| x.is_finite() && x.abs() <= MAX_GEOMETRY_M)
        {
            return Err(invalid(
                "specimen.influence",
                format!(
                    "{n} rows of six finite numbers (x, y, z, roll, pitch, yaw), each within \
                     ±{MAX_GEOMETRY_M:e} (the rotations' levers in m)"
                ),
            ));
        }
        let Some(chol) = mass.clone().cholesky() else {
            return Err(invalid(
                "specimen.mass_matrix",
                "a positive definite matrix",
            ));
        };
        for (path, m) in [
            ("specimen.stiffness_matrix", &stiffness),
            ("specimen.damping_matrix", &damping),
        ] {
            let eig = m.clone().symmetric_eigenvalues();
            let scale = m.abs().max();
            if eig.min() < -1e-9 * scale {
                return Err(invalid(path, "a positive semi-definite matrix"));
            }
        }
        Ok(LinearSpecimen {
            mass_inverse: chol.inverse(),
            influence_transpose: influence.transpose(),
            mass,
            stiffness,
            damping,
            influence,
        })
    }

    /// The storeys of a shear frame along x as a linear specimen: floor `i` relative to the
    /// platen, influence `(1, 0, 0, 0, 0, 0)` (the storeys carry no heights, so no
    /// overturning moment).
    pub fn from_storeys(specimen: &Specimen) -> Self {
        let n = specimen.len();
        let m = |v: Vec<f64>| DMatrix::from_row_slice(n, n, &v);
        let mut influence = DMatrix::zeros(n, 6);
        influence.column_mut(0).fill(1.0);
        Self::new(
            m(specimen.mass_matrix()),
            m(specimen.stiffness_matrix()),
            m(specimen.damping_matrix()),
            influence,
        )
        .expect("a valid shear frame gives valid matrices")
    }

    /// Its number of DOFs.
    pub fn len(&self) -> usize {
        self.mass.nrows()
    }

    /// Whether it has no DOF (never: a specimen has at least one).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The mass matrix.
    pub fn mass(&self) -> &DMatrix<f64> {
        &self.mass
    }

    /// The stiffness matrix.
    pub fn stiffness(&self) -> &DMatrix<f64> {
        &self.stiffness
    }

    /// The damping matrix.
    pub fn damping(&self) -> &DMatrix<f64> {
        &self.damping
    }

    /// The influence matrix `Γ`, `n × 6`.
    pub fn influence(&self) -> &DMatrix<f64> {
        &self.influence
    }

    /// Its elastic and damping forces `C·ż + K·z`.
    pub fn restoring(&self, z: &DVector<f64>, zd: &DVector<f64>) -> DVector<f64> {
        &self.stiffness * z + &self.damping * zd
    }

    /// Its wrench on the platen `Γᵀ·(C·ż + K·z)` (about the reference point).
    pub fn wrench_on_platen(&self, z: &DVector<f64>, zd: &DVector<f64>) -> Wrench {
        let w = self.influence.transpose() * self.restoring(z, zd);
        Wrench::from_iterator(w.iter().copied())
    }

    /// Its relative accelerations `z̈ = −Γ·a − M⁻¹·(C·ż + K·z)` under the platen's
    /// acceleration `a = (ẗ, ω̇)`.
    pub fn accelerations(
        &self,
        z: &DVector<f64>,
        zd: &DVector<f64>,
        platen: &Wrench,
    ) -> DVector<f64> {
        -(&self.influence * platen) - &self.mass_inverse * self.restoring(z, zd)
    }

    /// [`restoring`](Self::restoring) into `out` without allocating: `z`, `zd` and `out` are
    /// `n` long (one per DOF), and every number has the bits [`restoring`](Self::restoring)
    /// gives (the same products and sums in the same order as nalgebra's gemv). For the
    /// right-hand side of an integrator, which takes it at every stage.
    ///
    /// # Panics
    /// If a slice is shorter than `n`.
    #[inline]
    pub fn restoring_into(&self, z: &[f64], zd: &[f64], out: &mut [f64]) {
        let n = self.len();
        let (z, zd, out) = (&z[..n], &zd[..n], &mut out[..n]);
        product_into(self.stiffness.as_slice(), z, out);
        for (i, o) in out.iter_mut().enumerate() {
            // `K·z + C·ż` adds `(K·z)ᵢ + (C·ż)ᵢ`, element by element.
            *o += row_product(self.damping.as_slice(), n, i, zd);
        }
    }

    /// [`wrench_on_platen`](Self::wrench_on_platen) from its restoring forces `restoring`
    /// (`n` long, [`restoring_into`](Self::restoring_into)) without allocating, to the bit.
    ///
    /// # Panics
    /// If `restoring` is shorter than `n`.
    #[inline]
    pub fn wrench_from_restoring(&self, restoring: &[f64]) -> Wrench {
        let n = self.len();
        let restoring = &restoring[..n];
        let mut w = Wrench::zeros();
        product_into(
            self.influence_transpose.as_slice(),
            restoring,
            w.as_mut_slice(),
        );
        w
    }

    /// [`accelerations`](Self::accelerations) from its restoring forces `restoring` (`n`
    /// long, [`restoring_into`](Self::restoring_into)) into `out` (`n` long) without
    /// allocating, to the bit.
    ///
    /// # Panics
    /// If a slice is shorter than `n`.
    #[inline]
    pub fn accelerations_into(&self, restoring: &[f64], platen: &Wrench, out: &mut [f64]) {
        let n = self.len();
        let (restoring, out) = (&restoring[..n], &mut out[..n]);
        product_into(self.influence.as_slice(), platen.as_slice(), out);
        for (i, o) in out.iter_mut().enumerate() {
            // `−(Γ·a) − M⁻¹·(C·ż + K·z)`, element by element.
            *o = -*o - row_product(self.mass_inverse.as_slice(), n, i, restoring);
        }
    }

    /// Its damping forces `C·ż` into `out` without allocating (`zd` and `out` `n` long), to
    /// the bit of `damping() * ż`.
    ///
    /// # Panics
    /// If a slice is shorter than `n`.
    #[inline]
    pub fn damping_forces_into(&self, zd: &[f64], out: &mut [f64]) {
        let n = self.len();
        product_into(self.damping.as_slice(), &zd[..n], &mut out[..n]);
    }

    /// Its static deflection under a steady platen acceleration `a` (gravity as the
    /// acceleration `−g`): `K·z = −M·Γ·a`. `None` if the stiffness is singular.
    pub fn equilibrium_under(&self, a: &Wrench) -> Option<DVector<f64>> {
        let load = -(&self.mass * (&self.influence * a));
        self.stiffness.clone().cholesky().map(|c| c.solve(&load))
    }

    /// Its weight as a wrench on the platen at rest about the reference point,
    /// `Γᵀ·M·Γ·g` with `g = (0, 0, −9.80665, 0, 0, 0)`.
    pub fn weight_wrench(&self) -> Wrench {
        self.rigid_mass() * Wrench::new(0.0, 0.0, -crate::STANDARD_GRAVITY_M_S2, 0.0, 0.0, 0.0)
    }

    /// Its rigid-body mass about the reference point, `Γᵀ·M·Γ` (6 × 6).
    pub fn rigid_mass(&self) -> Matrix6<f64> {
        let m = self.influence.transpose() * &self.mass * &self.influence;
        Matrix6::from_iterator(m.iter().copied())
    }
}

impl MultiAxisTable {
    /// The modes at neutral with `specimen` on the platen: the generalised eigenproblem of
    /// the platen and specimen together, mass `[[M_p + ΓᵀMΓ, ΓᵀM], [MΓ, M]]` and stiffness
    /// `diag(K_p, K)` (the platen's axial springs, see
    /// [`axial_stiffness_matrix`](Self::axial_stiffness_matrix)), lowest first; each shape is
    /// its platen part (x … yaw), the whole mode mass-normalised.
    pub fn modes_with(&self, specimen: &LinearSpecimen) -> Vec<Mode> {
        let free: Vec<usize> = self.free().iter().map(|d| d.index()).collect();
        let (nf, n) = (free.len(), specimen.len());
        let mp = self.spatial_mass_matrix(&super::Coords::zeros());
        let kp = self.axial_stiffness_matrix();
        let g = specimen.influence();
        let ms = specimen.mass();
        let gtmg = g.transpose() * ms * g;
        let mg = ms * g;
        let size = nf + n;
        let mut m = DMatrix::zeros(size, size);
        let mut k = DMatrix::zeros(size, size);
        for (r, &a) in free.iter().enumerate() {
            for (c, &b) in free.iter().enumerate() {
                m[(r, c)] = mp[(a, b)] + gtmg[(a, b)];
                k[(r, c)] = kp[(a, b)];
            }
            for j in 0..n {
                m[(r, nf + j)] = mg[(j, a)];
                m[(nf + j, r)] = mg[(j, a)];
            }
        }
        m.view_mut((nf, nf), (n, n)).copy_from(ms);
        k.view_mut((nf, nf), (n, n)).copy_from(specimen.stiffness());
        super::modes::generalised_modes(&m, &k)
            .into_iter()
            .map(|(f, phi)| {
                let mut shape = super::Coords::zeros();
                for (r, &d) in free.iter().enumerate() {
                    shape[d] = phi[r];
                }
                Mode {
                    frequency_hz: f,
                    shape,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A seeded generator of numbers in [−1, 1) (a 64-bit LCG's top bits).
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }

        fn matrix(&mut self, rows: usize, cols: usize, scale: f64) -> DMatrix<f64> {
            DMatrix::from_fn(rows, cols, |_, _| scale * self.next())
        }

        /// A symmetric positive definite `n × n` matrix of the order of `scale`.
        fn spd(&mut self, n: usize, scale: f64) -> DMatrix<f64> {
            let a = self.matrix(n, n, 1.0);
            (&a * a.transpose() + DMatrix::identity(n, n) * n as f64) * scale
        }
    }

    fn bits(x: &[f64]) -> Vec<u64> {
        x.iter().map(|v| v.to_bits()).collect()
    }

    /// The right-hand side's allocation-free forms against the allocating ones on seeded
    /// random specimens of 1 to 12 DOFs (past 8, where nalgebra's dot unrolls): every number
    /// has the same bits.
    #[test]
    fn the_allocation_free_forms_give_the_allocating_ones_to_the_bit() {
        let mut rng = Lcg(0x5eed);
        for n in 1..=12 {
            let s = LinearSpecimen::new(
                rng.spd(n, 6e4),
                rng.spd(n, 5e7),
                rng.spd(n, 3e5),
                rng.matrix(n, 6, 12.0),
            )
            .unwrap();
            for _ in 0..20 {
                let z = DVector::from_fn(n, |_, _| 0.01 * rng.next());
                let zd = DVector::from_fn(n, |_, _| 0.3 * rng.next());
                let a = Wrench::from_fn(|_, _| 9.0 * rng.next());
                let mut r = [0.0; 12];
                s.restoring_into(z.as_slice(), zd.as_slice(), &mut r);
                assert_eq!(bits(&r[..n]), bits(s.restoring(&z, &zd).as_slice()), "{n}");
                let w = s.wrench_from_restoring(&r);
                assert_eq!(
                    bits(w.as_slice()),
                    bits(s.wrench_on_platen(&z, &zd).as_slice())
                );
                let mut zdd = [0.0; 12];
                s.accelerations_into(&r, &a, &mut zdd);
                assert_eq!(
                    bits(&zdd[..n]),
                    bits(s.accelerations(&z, &zd, &a).as_slice())
                );
                let mut czd = [0.0; 12];
                s.damping_forces_into(zd.as_slice(), &mut czd);
                assert_eq!(bits(&czd[..n]), bits((s.damping() * &zd).as_slice()));
            }
        }
    }
}
