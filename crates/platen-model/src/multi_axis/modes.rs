//! The platen's modes at neutral on its oil columns and hold-down struts, valves shut.

use nalgebra::{DMatrix, DVector, Matrix6, SymmetricEigen};

use super::dof::{Coords, Dof};
use super::table::{MultiAxisTable, Wrench};

/// One mode of the platen at neutral.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// Its natural frequency, Hz.
    pub frequency_hz: f64,
    /// Its shape over x … yaw (m and rad), mass-normalised (`φᵀ·M·φ = 1`) with its
    /// largest-magnitude component positive; 0 in the held DOFs.
    pub shape: Coords,
}

impl MultiAxisTable {
    /// The stiffness at neutral with the valves shut, about the reference point: every
    /// actuator's oil column ([`Actuator::oil_column_stiffness_n_per_m`](super::Actuator))
    /// and every strut's gas ([`Strut::axial_stiffness_n_per_m`](super::Strut)) as an axial
    /// spring along its line at its point, `K = Σ kᵢ·wᵢ·wᵢᵀ` with `wᵢ` its unit wrench. The
    /// geometric stiffness of the preloads (strut pull and weight over lengths of metres,
    /// about 1e-3 of the oil columns') is left out.
    pub fn axial_stiffness_matrix(&self) -> Matrix6<f64> {
        let neutral = Coords::zeros();
        let beta = self.parts().oil_bulk_modulus_pa;
        let actuators = self.actuators().iter().enumerate().map(|(i, a)| {
            let w = self.actuator_at(i, &neutral).unit_wrench;
            w * w.transpose() * a.oil_column_stiffness_n_per_m(beta)
        });
        let struts = self.struts().iter().map(|s| {
            // At neutral the platen frame is table axes: the line from base to platen point.
            let line = (s.platen_m - s.base_m).normalize();
            let m = s.platen_m.cross(&line);
            let w = Wrench::new(line[0], line[1], line[2], m[0], m[1], m[2]);
            w * w.transpose() * s.axial_stiffness_n_per_m()
        });
        actuators.chain(struts).sum()
    }

    /// The modes at neutral (valves shut, linearised): the generalised eigenproblem
    /// `K·φ = ω²·M·φ` of [`axial_stiffness_matrix`](Self::axial_stiffness_matrix) and the
    /// rigid-body mass matrix, over the free DOFs, lowest first.
    pub fn modes(&self) -> Vec<Mode> {
        let neutral = Coords::zeros();
        self.modes_of(
            &self.spatial_mass_matrix(&neutral),
            &self.axial_stiffness_matrix(),
        )
    }

    /// The modes of the mass and stiffness matrices `m`, `k` (about the reference point, at
    /// neutral) over the free DOFs.
    fn modes_of(&self, m: &Matrix6<f64>, k: &Matrix6<f64>) -> Vec<Mode> {
        let free: Vec<usize> = self.free().iter().map(Dof::index).collect();
        let n = free.len();
        let pick = |a: &Matrix6<f64>| DMatrix::from_fn(n, n, |r, c| a[(free[r], free[c])]);
        generalised_modes(&pick(m), &pick(k))
            .into_iter()
            .map(|(frequency_hz, phi)| {
                let mut shape = Coords::zeros();
                for (r, &d) in free.iter().enumerate() {
                    shape[d] = phi[r];
                }
                Mode {
                    frequency_hz,
                    shape,
                }
            })
            .collect()
    }
}

/// The solutions of `K·φ = ω²·M·φ` (`M` positive definite, `K` symmetric), lowest first: the
/// frequency in Hz (0 for a negative `ω²` of rounding) and `φ` with `φᵀ·M·φ = 1` and its
/// largest-magnitude component positive. Empty if `M` is not positive definite.
pub(crate) fn generalised_modes(m: &DMatrix<f64>, k: &DMatrix<f64>) -> Vec<(f64, DVector<f64>)> {
    let Some(chol) = m.clone().cholesky() else {
        return Vec::new();
    };
    let l = chol.l();
    let Some(l_inv) = l.try_inverse() else {
        return Vec::new();
    };
    let c = &l_inv * k * l_inv.transpose();
    let c = (&c + c.transpose()) * 0.5;
    let eig = SymmetricEigen::new(c);
    let mut modes: Vec<(f64, DVector<f64>)> = (0..m.nrows())
        .map(|i| {
            let mut phi = l_inv.transpose() * eig.eigenvectors.column(i);
            let big = phi
                .iter()
                .copied()
                .fold(0.0, |b: f64, x| if x.abs() > b.abs() { x } else { b });
            if big < 0.0 {
                phi = -phi;
            }
            (
                eig.eigenvalues[i].max(0.0).sqrt() / std::f64::consts::TAU,
                phi,
            )
        })
        .collect();
    modes.sort_by(|a, b| a.0.total_cmp(&b.0));
    modes
}
