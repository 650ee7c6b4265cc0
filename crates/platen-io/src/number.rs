//! Fast number text for CSV output: the bytes of Rust's `{}` formatting of an `f64`, or of
//! `{:e}` when the magnitude is below 1e-5 or at least 1e16, at the speed of the `ryu` crate.
//!
//! Both Rust's formatting and Ryū print the *shortest* digits that parse back to the same
//! `f64` (the closest such digits to the exact value, boundaries included for an even
//! mantissa), and Ryū writes plain decimals (`0.001`, `12.5`, `3.0`) exactly for the
//! magnitudes `1e-5 ≤ |x| < 1e16` and `d.ddde±x` (`1e-7`, `1.25e20`) outside them — the
//! thresholds platen's CSV writers use to choose between `{}` and `{:e}`. Two differences
//! remain, and [`NumberBuffer::format`] removes both:
//!
//! * Ryū ends an integral decimal with `.0` (`3.0`, `-0.0`, `1500.0`) where `{}` writes `3`,
//!   `-0`, `1500`: the suffix is dropped.
//! * When the value lies exactly halfway between the two closest shortest digit strings
//!   (`1000000000000000.25`: `…0.2` and `…0.3` both read back as it), Ryū rounds the last
//!   digit to even and Rust's formatting rounds it up. Such a tie needs the value's lowest set
//!   bit to be `2^(k−1)` for the unit `10^k` of the last digit, with `−25 ≤ k − 1 ≤ −2`, an
//!   ulp of at least `10^k` and at most 17 digits: [`tie_possible`] tests that from the bits
//!   (a few integer operations), and the rare values it lets through are formatted by `std`.
//!
//! A property test over random bit patterns (subnormals, integers, both exponent extremes,
//! `-0.0`, ties) checks the result against `format!`.
//!
//! ```
//! use platen_io::number::NumberBuffer;
//! let mut buf = NumberBuffer::new();
//! assert_eq!(buf.format(3.0), "3");
//! assert_eq!(buf.format(-0.0), "-0");
//! assert_eq!(buf.format(0.1 + 0.2), "0.30000000000000004");
//! assert_eq!(buf.format(1e-7), "1e-7");
//! assert_eq!(buf.format(f64::MAX), "1.7976931348623157e308");
//! ```

/// A reusable buffer that formats finite `f64` values without allocating (see the
/// [module documentation](self)).
#[derive(Default)]
pub struct NumberBuffer {
    ryu: ryu::Buffer,
    fallback: Inline,
}

impl std::fmt::Debug for NumberBuffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("NumberBuffer")
    }
}

impl NumberBuffer {
    /// A new buffer.
    pub fn new() -> Self {
        Self::default()
    }

    /// The text of a finite `value`: `format!("{value}")` when `value` is 0 or
    /// `1e-5 ≤ |value| < 1e16`, `format!("{value:e}")` otherwise. A non-finite value gives
    /// `NaN`, `inf` or `-inf` (CSV writers refuse those before formatting).
    #[inline]
    pub fn format(&mut self, value: f64) -> &str {
        if !value.is_finite() {
            return if value.is_nan() {
                "NaN"
            } else if value > 0.0 {
                "inf"
            } else {
                "-inf"
            };
        }
        if tie_possible(value) {
            return self.std_format(value);
        }
        let text = self.ryu.format_finite(value);
        text.strip_suffix(".0").unwrap_or(text)
    }

    /// [`reference_text`]'s text, written by `std` into the inline buffer (no allocation).
    #[cold]
    fn std_format(&mut self, value: f64) -> &str {
        use std::fmt::Write as _;
        self.fallback.len = 0;
        let magnitude = value.abs();
        // The longest text of a finite f64 is 24 bytes (`-2.2250738585072014e-308`) under
        // `{:e}`, and 18 digits plus sign and point under `{}` in the range it is used for.
        let written = if magnitude == 0.0 || (1e-5..1e16).contains(&magnitude) {
            write!(self.fallback, "{value}")
        } else {
            write!(self.fallback, "{value:e}")
        };
        debug_assert!(written.is_ok());
        std::str::from_utf8(&self.fallback.bytes[..self.fallback.len]).unwrap_or_default()
    }
}

/// Room for the text `std` writes for a tie ([`NumberBuffer::format`]).
#[derive(Clone, Copy, Default)]
struct Inline {
    bytes: [u8; 32],
    len: usize,
}

impl std::fmt::Write for Inline {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.len + s.len();
        let room = self.bytes.get_mut(self.len..end).ok_or(std::fmt::Error)?;
        room.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// Whether the shortest digits of finite `value` could be a tie between two strings of the
/// same length (see the [module documentation](self)); `false` guarantees there is none.
///
/// With `v = odd·2^p` (`p` the exponent of the lowest set bit) and `ulp = 2^q`, a tie in the
/// last digit, of unit `10^k`, means `v = (d + ½)·10^k` for an integer `d` of at most 17
/// digits whose neighbours `d·10^k` and `(d + 1)·10^k` both lie within `ulp/2` of `v`. Then
/// `k < 0` (`k ≥ 0` would make `v` a multiple of `10^k/2` with an odd `5^k` factor above
/// its ulp), `p = k − 1`, `2d + 1 = odd·5^(−k) < 2·10^17` so `−k ≤ 24`, `10^k ≤ 2^q`, and
/// `|v| < 10^(k + 17)`. Each test below is that condition, loosened a little where exact
/// arithmetic would cost more.
#[inline]
pub fn tie_possible(value: f64) -> bool {
    let bits = value.to_bits();
    let exponent_bits = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1 << 52) - 1);
    let (mantissa, q) = if exponent_bits == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1 << 52), exponent_bits - 1075)
    };
    if mantissa == 0 {
        return false;
    }
    let p = q + mantissa.trailing_zeros() as i32;
    let k = p + 1;
    if !(-24..=-1).contains(&k) {
        return false;
    }
    // 10^k ≤ 2^q ⇔ q ≥ k·log2(10); 3.321929 > log2(10) = 3.3219280…, so for k < 0 the
    // bound is a hair low (more values pass).
    if i64::from(q) * 1_000_000 < i64::from(k) * 3_321_929 {
        return false;
    }
    // |v| < 10^(k + 17), checked as |v| < 2·10^(k + 17) with k + 17 in −7..=16.
    value.abs() < 2.0 * POWERS_OF_TEN[(k + 17 + 7) as usize]
}

/// `10^i` for `i = −7…16`.
const POWERS_OF_TEN: [f64; 24] = [
    1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9,
    1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
];

/// Appends the text of a finite `value` ([`NumberBuffer::format`]) to `out`.
#[inline]
pub fn format_number(buf: &mut NumberBuffer, out: &mut Vec<u8>, value: f64) {
    out.extend_from_slice(buf.format(value).as_bytes());
}

/// The text `format_number` must produce, written with `format!` (for tests and the
/// benchmark's baseline): `{}`, or `{:e}` below 1e-5 and from 1e16 on.
#[doc(hidden)]
pub fn reference_text(value: f64) -> String {
    let magnitude = value.abs();
    if magnitude == 0.0 || (1e-5..1e16).contains(&magnitude) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn check(value: f64) {
        let mut buf = NumberBuffer::new();
        assert_eq!(
            buf.format(value),
            reference_text(value),
            "bits {:#018x}",
            value.to_bits()
        );
    }

    #[test]
    fn awkward_values_match_rusts_formatting() {
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1 + 0.2,
            1.0 / 3.0,
            5e-324,
            -5e-324,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE - 5e-324,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            1e-5,
            1e16,
            9_999_999_999_999_998.0,
            1e15,
            1.5e15,
            123_456_789.0,
            0.001,
            306.795_676_296_597_6,
            9.007_199_254_740_992e15,
            2.0f64.powi(53) + 2.0,
            1e22,
            1e23,
            1e-300,
            4.35e-6,
        ];
        // Both sides of every threshold, a few ulps around each.
        for edge in [1e-5f64, 1e16, 1e-4, 1e15, 1.0] {
            for k in -3i64..=3 {
                values.push(f64::from_bits(edge.to_bits().wrapping_add_signed(k)));
            }
        }
        // Every power of ten and of two in range, and their neighbours.
        for e in -324..=308 {
            let p: f64 = format!("1e{e}").parse().unwrap();
            for k in -1i64..=1 {
                values.push(f64::from_bits(p.to_bits().wrapping_add_signed(k)));
            }
        }
        for e in -1074..=1023 {
            values.push(2.0f64.powi(e));
        }
        // Integers, small and near 2^53.
        for i in -1000i64..=1000 {
            values.push(i as f64);
            values.push((i + (1 << 53)) as f64);
        }
        for v in values.into_iter().filter(|v| v.is_finite()) {
            check(v);
            check(-v);
        }
    }

    #[test]
    fn ties_are_rounded_up_as_rust_does() {
        // 1e15 + 0.25: `…0.2` and `…0.3` are equally close; Ryū alone would print `…0.2`.
        let tie = 1e15 + 0.25;
        assert!(tie_possible(tie));
        check(tie);
        assert_eq!(NumberBuffer::new().format(tie), "1000000000000000.3");
        // Every value with a lowest set bit 2^(k-1), k = -1…-24, at magnitudes 1e7…1e16.
        for k in -24i32..=-1 {
            let unit = 2f64.powi(k - 1);
            for e in 7..=16 {
                let base = (10f64.powi(e) / unit).floor() * unit;
                for odd in [1.0, 3.0, 5.0, 7.0, 9.0, 11.0] {
                    check(base + odd * unit);
                }
            }
        }
    }

    #[test]
    fn the_tie_filter_passes_few_values_of_a_run() {
        // Times on a 1024 Hz grid and the sizes of a run's values are never candidates.
        assert!((0..1024 * 600).all(|j| !tie_possible(f64::from(j) / 1024.0)));
        let passed = (1..100_000)
            .map(|i| f64::from(i) * 1.234_567_89e3 + 0.1)
            .filter(|&v| tie_possible(v))
            .count();
        assert_eq!(passed, 0);
    }

    #[test]
    fn non_finite_values_have_rusts_names() {
        let mut buf = NumberBuffer::new();
        assert_eq!(buf.format(f64::NAN), format!("{}", f64::NAN));
        assert_eq!(buf.format(f64::INFINITY), format!("{}", f64::INFINITY));
        assert_eq!(
            buf.format(f64::NEG_INFINITY),
            format!("{}", f64::NEG_INFINITY)
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200_000))]

        /// Any bit pattern: every exponent (subnormals included) equally likely.
        #[test]
        fn random_bit_patterns_match_rusts_formatting(bits in any::<u64>()) {
            // (Not `prop_assume!`: one pattern in 2048 is NaN or infinite, too many rejects.)
            let value = f64::from_bits(bits);
            let mut buf = NumberBuffer::new();
            if value.is_finite() {
                prop_assert_eq!(buf.format(value), reference_text(value));
            }
        }

        /// Values of the magnitudes a run writes (1e-9 to 1e9), where `{}` applies.
        #[test]
        fn run_sized_values_match_rusts_formatting(m in -1.0f64..1.0, e in -9i32..9) {
            let value = m * 10f64.powi(e);
            let mut buf = NumberBuffer::new();
            prop_assert_eq!(buf.format(value), reference_text(value));
        }

        /// Integers and halves (exact in `f64`), where `{}` drops the fraction.
        #[test]
        fn integral_values_match_rusts_formatting(i in any::<i64>(), half in any::<bool>()) {
            let value = i as f64 + if half { 0.5 } else { 0.0 };
            let mut buf = NumberBuffer::new();
            prop_assert_eq!(buf.format(value), reference_text(value));
        }

        /// Values with few fraction bits at large magnitudes, where ties happen.
        #[test]
        fn short_fractions_match_rusts_formatting(i in 0u64..(1 << 53), shift in 0i32..30) {
            let value = i as f64 / 2f64.powi(shift);
            let mut buf = NumberBuffer::new();
            prop_assert_eq!(buf.format(value), reference_text(value));
        }

        /// Subnormals.
        #[test]
        fn subnormals_match_rusts_formatting(bits in 1u64..(1 << 52), negative in any::<bool>()) {
            let value = f64::from_bits(bits | (u64::from(negative) << 63));
            let mut buf = NumberBuffer::new();
            prop_assert_eq!(buf.format(value), reference_text(value));
        }
    }
}
