//! Ordinary least squares with an intercept, for the symmetry identities of Eq. 16–19.

/// Ordinary least squares `y = Σ bᵢ·xᵢ + c` (an intercept is added).
pub(crate) struct Regression {
    pub(crate) coef: Vec<f64>,
    /// `(XᵀX)⁻¹` with the intercept last.
    inv: nalgebra::DMatrix<f64>,
    /// Rows of the design, for projecting other responses.
    design: nalgebra::DMatrix<f64>,
    ssr: f64,
    n: usize,
}

impl Regression {
    pub(crate) fn fit(columns: &[&[f64]], y: &[f64]) -> Option<Self> {
        let n = y.len();
        let p = columns.len() + 1;
        if n < p + 2 {
            return None;
        }
        let design = nalgebra::DMatrix::from_fn(n, p, |i, c| {
            if c < columns.len() {
                columns[c][i]
            } else {
                1.0
            }
        });
        let xtx = design.tr_mul(&design);
        // Scale to unit diagonal before inverting: the columns differ by orders of magnitude.
        let d: Vec<f64> = (0..p)
            .map(|i| xtx[(i, i)].sqrt().max(f64::MIN_POSITIVE))
            .collect();
        let scaled = nalgebra::DMatrix::from_fn(p, p, |a, b| xtx[(a, b)] / (d[a] * d[b]));
        let sinv = scaled.try_inverse()?;
        let inv = nalgebra::DMatrix::from_fn(p, p, |a, b| sinv[(a, b)] / (d[a] * d[b]));
        let yv = nalgebra::DVector::from_column_slice(y);
        let coef = &inv * design.tr_mul(&yv);
        let ssr = (&yv - &design * &coef).norm_squared();
        Some(Self {
            coef: coef.iter().copied().collect(),
            inv,
            design,
            ssr,
            n,
        })
    }

    /// The coefficients another response `z` would get on the same design.
    pub(crate) fn project(&self, z: &[f64]) -> Vec<f64> {
        let zv = nalgebra::DVector::from_column_slice(z);
        (&self.inv * self.design.tr_mul(&zv))
            .iter()
            .copied()
            .collect()
    }

    /// `(value, variance)` of coefficient `i`, with the residual variance inflated by the
    /// correlation length `l` (see [`crate::lm::covariance`]).
    pub(crate) fn coefficient(&self, i: usize, l: f64) -> (f64, f64) {
        let p = self.coef.len();
        let s2 = self.ssr / (self.n as f64 - p as f64);
        (self.coef[i], l * s2 * self.inv[(i, i)])
    }

    pub(crate) fn dof(&self, l: f64) -> f64 {
        (self.n as f64 / l - self.coef.len() as f64).max(1.0)
    }
}
