//! The filters the plant's fits share: the force balance's zero-phase low-pass (also the
//! storeys'), the velocity by central differences, the trapezoidal second-order filter (the
//! storeys' drift and the continuity's low-pass) and band-limited upsampling.

use platen_signal::{ButterworthLowpass, ZeroPhaseFilter};

use crate::error::{IdentError, Result};
use crate::system::SystemRecord;

/// Corner of the zero-phase low-pass on the force balance, as a fraction of the sample rate
/// (20.5 Hz at 204.8 Hz, 102 Hz at 1024 Hz): below the content a command does not drive,
/// above the platen's motion.
pub const MECHANICS_LOWPASS_FRACTION: f64 = 0.1;

/// The zero-phase low-pass of the force balance at `h`.
pub(super) fn mechanics_filter(r: &SystemRecord, h: f64) -> Result<ButterworthLowpass> {
    ButterworthLowpass::new(4, MECHANICS_LOWPASS_FRACTION / h, 1.0 / h).map_err(|source| {
        IdentError::Signal {
            test: r.name.clone(),
            source,
        }
    })
}

/// `x` through the force balance's low-pass `f` (an error names the record `r`).
pub(super) fn filtered(f: &ButterworthLowpass, r: &SystemRecord, x: &[f64]) -> Result<Vec<f64>> {
    f.apply(x).map_err(|source| IdentError::Signal {
        test: r.name.clone(),
        source,
    })
}

/// The velocity of `u` by central differences at period `h` (0 at both ends).
pub(super) fn central_velocity(u: &[f64], h: f64) -> Vec<f64> {
    let n = u.len();
    let mut v = vec![0.0; n];
    for i in 1..n - 1 {
        v[i] = (u[i + 1] - u[i - 1]) / (2.0 * h);
    }
    v
}

/// The second-order filter `1/(s² + 2ζω s + ω²)` of `x` by the trapezoidal rule, started at
/// rest: returns `(q, q̇, q̈)` (so `s^k/(s² + 2ζω s + ω²)` of `x` for `k = 0, 1, 2`).
pub(super) fn second_order(x: &[f64], h: f64, w: f64, zeta: f64) -> [Vec<f64>; 3] {
    // State y = (q, q̇): ẏ = A y + B x, A = [[0, 1], [−ω², −2ζω]], B = (0, 1).
    // Trapezoid: (I − hA/2) y₊ = (I + hA/2) y + h/2·B (x + x₊).
    let (a10, a11) = (-w * w, -2.0 * zeta * w);
    let m = [[1.0, -0.5 * h], [-0.5 * h * a10, 1.0 - 0.5 * h * a11]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ];
    let n = x.len();
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut y0, mut y1) = (0.0, 0.0);
    qdd[0] = x[0];
    for i in 1..n {
        let r0 = y0 + 0.5 * h * y1;
        let r1 = y1 + 0.5 * h * (a10 * y0 + a11 * y1) + 0.5 * h * (x[i - 1] + x[i]);
        y0 = inv[0][0] * r0 + inv[0][1] * r1;
        y1 = inv[1][0] * r0 + inv[1][1] * r1;
        q[i] = y0;
        qd[i] = y1;
        qdd[i] = x[i] + a10 * y0 + a11 * y1;
    }
    [q, qd, qdd]
}

/// The storey fit's filters run at this many times the records' rate: the trapezoid rule's
/// frequency warping, `(ωh)²/6` relative on a double integral (0.66 % at 6.5 Hz on 204.8 Hz
/// records, which showed as a stiffness 0.7 % high), falls with the square of the step.
pub(super) const UPSAMPLE: usize = 4;

/// `x` at `UPSAMPLE` times its rate: band-limited interpolation
/// ([`platen_signal::advance`] by each fraction of a sample, interleaved).
pub(super) fn upsampled(x: &[f64]) -> Option<Vec<f64>> {
    let shifted: Vec<Vec<f64>> = (1..UPSAMPLE)
        .map(|k| platen_signal::advance(x, k as f64 / UPSAMPLE as f64).ok())
        .collect::<Option<_>>()?;
    let mut out = Vec::with_capacity(UPSAMPLE * x.len());
    for i in 0..x.len() {
        out.push(x[i]);
        for s in &shifted {
            out.push(s[i]);
        }
    }
    Some(out)
}
