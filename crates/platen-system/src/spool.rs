//! The spool's exact response to a held drive.
//!
//! Between two changes of its (delayed, held) drive `d`, a servo-valve's spool follows the
//! linear `ẍ = ω²(d − x) − 2ζω ẋ`, whatever the chambers do: the opening the flow sees is
//! the spool's position clamped to ±1, but the spool itself is never clamped. Its motion
//! over `t` is therefore the matrix exponential of
//! `A = [[0, 1], [−ω², −2ζω]]` applied to the error `(x − d, ẋ)`:
//! `e^{At} = e^{−ζωt}·(c(t)·I + s(t)·(A + ζω·I))` with `δ² = ω²(ζ² − 1)` and
//! `c = cos(ω_d t)`, `s = sin(ω_d t)/ω_d` for `δ² < 0` (`ω_d = ω√(1 − ζ²)`),
//! `c = cosh(δt)`, `s = sinh(δt)/δ` for `δ² > 0`, and `c = 1`, `s = t` at critical damping.
//!
//! An integrator that takes the spool from here instead of stepping it is freed from the
//! spool's rate (246 Hz on the LHPOST's valves), usually the loop's fastest mode.

/// The exact response of one valve's spool (`ω` rad/s, damping ratio `ζ > 0`) to a held
/// drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpoolResponse {
    /// `ω²`, 1/s².
    omega_sq: f64,
    /// `ζω`, 1/s.
    decay_1_s: f64,
    /// `δ² = ω²(ζ² − 1)`, 1/s².
    delta_sq: f64,
    /// `√|δ²|`, 1/s.
    delta_1_s: f64,
}

/// The propagator's two weights at one time: `e^{−ζωt}·c(t)` and `e^{−ζωt}·s(t)` (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpoolWeights {
    c: f64,
    s_s: f64,
}

impl SpoolResponse {
    /// The response of a spool of natural frequency `natural_frequency_hz` and damping ratio
    /// `damping_ratio` (both finite and > 0, as a valid [`crate::ServoValve`]'s).
    pub fn new(natural_frequency_hz: f64, damping_ratio: f64) -> Self {
        let omega = std::f64::consts::TAU * natural_frequency_hz;
        let delta_sq = omega * omega * (damping_ratio * damping_ratio - 1.0);
        SpoolResponse {
            omega_sq: omega * omega,
            decay_1_s: damping_ratio * omega,
            delta_sq,
            delta_1_s: delta_sq.abs().sqrt(),
        }
    }

    /// The weights of the response `dt_s ≥ 0` s after a start (shared by every spool of the
    /// same valve model: one exponential and one sine–cosine pair).
    #[inline]
    pub fn weights(&self, dt_s: f64) -> SpoolWeights {
        if dt_s == 0.0 {
            return SpoolWeights { c: 1.0, s_s: 0.0 };
        }
        let decay = (-self.decay_1_s * dt_s).exp();
        let x = self.delta_1_s * dt_s;
        let (c, s_s) = if self.delta_sq < 0.0 {
            let (sin, cos) = x.sin_cos();
            (cos, sin / self.delta_1_s)
        } else if self.delta_sq == 0.0 {
            (1.0, dt_s)
        } else if x <= 1.0 {
            (x.cosh(), x.sinh() / self.delta_1_s)
        } else {
            // e^{−ζωt}·cosh and ·sinh from their two exponentials (no overflow of cosh).
            let slow = ((self.delta_1_s - self.decay_1_s) * dt_s).exp();
            let fast = ((-self.delta_1_s - self.decay_1_s) * dt_s).exp();
            return SpoolWeights {
                c: 0.5 * (slow + fast),
                s_s: 0.5 * (slow - fast) / self.delta_1_s,
            };
        };
        SpoolWeights {
            c: decay * c,
            s_s: decay * s_s,
        }
    }

    /// The spool's position and rate at the weights' time after it was at `x0` moving at
    /// `v0` (1/s), under the held drive `drive`.
    #[inline]
    pub fn at(&self, w: SpoolWeights, drive: f64, x0: f64, v0: f64) -> (f64, f64) {
        let e = x0 - drive;
        let x = drive + w.c * e + w.s_s * (self.decay_1_s * e + v0);
        let v = w.c * v0 - w.s_s * (self.omega_sq * e + self.decay_1_s * v0);
        (x, v)
    }

    /// The spool's position and rate `dt_s` s after it was at `x0` moving at `v0` under the
    /// held drive `drive`.
    pub fn after(&self, dt_s: f64, drive: f64, x0: f64, v0: f64) -> (f64, f64) {
        self.at(self.weights(dt_s), drive, x0, v0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spool's equation stepped by classical RK4 at `n` steps over `t`: an independent
    /// solution (RK4's error at `h·ω ≈ 2e-3` is about `(hω)⁴ ≈ 1e-11` of the motion).
    fn stepped(f_hz: f64, zeta: f64, t: f64, d: f64, x0: f64, v0: f64, n: usize) -> (f64, f64) {
        let w = std::f64::consts::TAU * f_hz;
        let rate = |x: f64, v: f64| (v, w * w * (d - x) - 2.0 * zeta * w * v);
        let h = t / n as f64;
        let (mut x, mut v) = (x0, v0);
        for _ in 0..n {
            let k1 = rate(x, v);
            let k2 = rate(x + 0.5 * h * k1.0, v + 0.5 * h * k1.1);
            let k3 = rate(x + 0.5 * h * k2.0, v + 0.5 * h * k2.1);
            let k4 = rate(x + h * k3.0, v + h * k3.1);
            x += h / 6.0 * (k1.0 + 2.0 * (k2.0 + k3.0) + k4.0);
            v += h / 6.0 * (k1.1 + 2.0 * (k2.1 + k3.1) + k4.1);
        }
        (x, v)
    }

    #[test]
    fn the_closed_form_matches_a_fine_rk4_at_every_damping() {
        // Under-, critically and over-damped; short and long spans (the long ones cross the
        // cosh branch's switch at δt = 1). Position in units of full opening: a 1e-9
        // tolerance is far above RK4's 1e-11 and far below any effect on a flow.
        for &zeta in &[0.05, 0.5, 0.7, 1.0, 1.3, 4.0] {
            for &t in &[1e-5, 4.9e-4, 3e-3, 2e-2] {
                let r = SpoolResponse::new(246.0, zeta);
                let (x, v) = r.after(t, 0.6, -0.3, 250.0);
                let n = ((t * std::f64::consts::TAU * 246.0 * 500.0).ceil() as usize).max(10);
                let (xs, vs) = stepped(246.0, zeta, t, 0.6, -0.3, 250.0, n);
                let w = std::f64::consts::TAU * 246.0;
                assert!((x - xs).abs() < 1e-9, "ζ {zeta} t {t}: x {x} vs {xs}");
                assert!((v - vs).abs() < 1e-9 * w, "ζ {zeta} t {t}: v {v} vs {vs}");
            }
        }
    }

    #[test]
    fn two_spans_compose_into_one_and_the_spool_settles_on_the_drive() {
        for &zeta in &[0.5, 1.0, 2.5] {
            let r = SpoolResponse::new(120.0, zeta);
            let (x1, v1) = r.after(3e-4, -0.4, 0.2, -30.0);
            let (x2, v2) = r.after(7e-4, -0.4, x1, v1);
            let (x, v) = r.after(1e-3, -0.4, 0.2, -30.0);
            assert!((x2 - x).abs() < 1e-14 && (v2 - v).abs() < 1e-11, "ζ {zeta}");
            // Long after, at rest on the drive (no overflow on the overdamped branch).
            let (x, v) = r.after(10.0, -0.4, 0.2, -30.0);
            assert!(
                (x + 0.4).abs() < 1e-12 && v.abs() < 1e-9,
                "ζ {zeta}: {x} {v}"
            );
        }
    }

    #[test]
    fn near_critical_damping_is_continuous() {
        // Either side of ζ = 1 the response must not jump (the branches meet at s = t).
        let t = 2e-3;
        let at = |zeta: f64| SpoolResponse::new(246.0, zeta).after(t, 1.0, 0.0, 0.0);
        let (x, _) = at(1.0);
        for zeta in [1.0 - 1e-9, 1.0 + 1e-9] {
            assert!((at(zeta).0 - x).abs() < 1e-8, "ζ {zeta}");
        }
    }
}
