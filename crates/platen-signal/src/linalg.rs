//! Dense linear algebra small enough to write once here: the normal equations of the
//! polynomial baseline fits (`platen_signal`'s accelerogram correction and `platen_plan`'s
//! drive baseline) share this one solve.

/// Solves the `size × size` system `g·x = b` (`g` row-major; both overwritten) by Gaussian
/// elimination with partial pivoting: for the small normal equations of the baseline fits
/// (a few to a few tens of unknowns). A zero pivot (a singular system) leaves its unknown 0
/// rather than dividing by it.
pub fn solve(g: &mut [f64], b: &mut [f64], size: usize) -> Vec<f64> {
    for col in 0..size {
        let pivot = (col..size)
            .max_by(|&r1, &r2| {
                g[r1 * size + col]
                    .abs()
                    .total_cmp(&g[r2 * size + col].abs())
            })
            .unwrap_or(col);
        if pivot != col {
            for c in 0..size {
                g.swap(col * size + c, pivot * size + c);
            }
            b.swap(col, pivot);
        }
        let d = g[col * size + col];
        if d == 0.0 {
            continue;
        }
        for r in col + 1..size {
            let f = g[r * size + col] / d;
            for c in col..size {
                g[r * size + c] -= f * g[col * size + c];
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = vec![0.0; size];
    for r in (0..size).rev() {
        let tail: f64 = (r + 1..size).map(|c| g[r * size + c] * x[c]).sum();
        let d = g[r * size + r];
        x[r] = if d == 0.0 { 0.0 } else { (b[r] - tail) / d };
    }
    x
}

#[cfg(test)]
mod tests {
    use super::solve;

    /// A 3 × 3 system with a known solution, given in an order that needs pivoting.
    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let mut g = vec![0.0, 2.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 3.0];
        let x = [1.0, -2.0, 3.0];
        let mut b: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|c| g[r * 3 + c] * x[c]).sum())
            .collect();
        let got = solve(&mut g, &mut b, 3);
        for (a, e) in got.iter().zip(x) {
            assert!((a - e).abs() < 1e-14, "{got:?}");
        }
    }

    /// A singular system gives finite values, not NaN.
    #[test]
    fn a_singular_system_stays_finite() {
        let mut g = vec![1.0, 2.0, 2.0, 4.0];
        let mut b = vec![1.0, 2.0];
        assert!(solve(&mut g, &mut b, 2).iter().all(|v| v.is_finite()));
    }
}
