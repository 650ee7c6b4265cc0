//! Odd (point-symmetric) extension of a record beyond its ends.
//!
//! The extension reflects the record through its end points:
//! `x(−k) = 2x(0) − x(k)` and `x(n−1+k) = 2x(n−1) − x(n−1−k)`, applied repeatedly when the
//! extension is longer than the record. It keeps the value and the slope continuous at the ends,
//! and it reproduces any straight line exactly, so a linear-phase filter whose impulse response
//! is symmetric and sums to one passes a constant or a ramp without an edge transient.

/// Value of the odd extension of `x` at index `i` (any integer). `x` must not be empty.
///
/// Reflecting through both ends makes the extension periodic with period `2(n − 1)` plus a ramp:
/// `x(i + 2(n−1)) = x(i) + 2(x(n−1) − x(0))`, which gives the value in O(1).
pub(crate) fn odd_extension_at(x: &[f64], i: isize) -> f64 {
    let n = x.len();
    debug_assert!(n > 0);
    if n == 1 {
        return x[0];
    }
    let last = (n - 1) as isize;
    if (0..=last).contains(&i) {
        return x[i as usize];
    }
    let period = 2 * last;
    let turns = i.div_euclid(period);
    let r = i.rem_euclid(period);
    let rise = 2.0 * (x[n - 1] - x[0]);
    let base = if r <= last {
        x[r as usize]
    } else {
        2.0 * x[n - 1] - x[(period - r) as usize]
    };
    base + turns as f64 * rise
}

/// Writes the record `x` with `pad` samples of odd extension on each side into `out`
/// (cleared first; `out.len() == x.len() + 2·pad` afterwards). An empty `x` gives an empty `out`.
pub(crate) fn odd_extend_into(x: &[f64], pad: usize, out: &mut Vec<f64>) {
    out.clear();
    if x.is_empty() {
        return;
    }
    out.reserve(x.len() + 2 * pad);
    let p = pad as isize;
    out.extend((-p..0).map(|i| odd_extension_at(x, i)));
    out.extend_from_slice(x);
    let n = x.len() as isize;
    out.extend((n..n + p).map(|i| odd_extension_at(x, i)));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odd_extension_of_a_line_is_the_same_line_on_both_sides_and_far_away() {
        let x: Vec<f64> = (0..5).map(|i| 2.0 + 0.5 * i as f64).collect();
        for i in -40..45 {
            let expected = 2.0 + 0.5 * i as f64;
            assert!(
                (odd_extension_at(&x, i) - expected).abs() < 1e-12,
                "i = {i}"
            );
        }
    }

    #[test]
    fn odd_extension_reflects_through_the_end_points() {
        let x = [1.0, 4.0, 2.0, 7.0];
        assert_eq!(odd_extension_at(&x, -1), 2.0 * 1.0 - 4.0);
        assert_eq!(odd_extension_at(&x, -3), 2.0 * 1.0 - 7.0);
        assert_eq!(odd_extension_at(&x, 4), 2.0 * 7.0 - 2.0);
        assert_eq!(odd_extension_at(&x, 6), 2.0 * 7.0 - 1.0);
        // Beyond one reflection: x(−4) = 2x(0) − x(4) = 2 − (14 − 2) = −10.
        assert_eq!(odd_extension_at(&x, -4), -10.0);
        let mut out = Vec::new();
        odd_extend_into(&x, 2, &mut out);
        assert_eq!(out, vec![0.0, -2.0, 1.0, 4.0, 2.0, 7.0, 12.0, 10.0]);
    }

    #[test]
    fn odd_extension_of_a_single_sample_is_constant() {
        assert_eq!(odd_extension_at(&[3.0], -7), 3.0);
        assert_eq!(odd_extension_at(&[3.0], 9), 3.0);
    }
}
