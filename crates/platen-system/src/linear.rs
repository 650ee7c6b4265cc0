//! The small-signal model of the loop about a state, its closed-loop response, its margins,
//! and the closed forms of the table's capacities.
//!
//! # The linear model
//!
//! About a state with the spool centred (`x_v = 0⁺`), chamber pressures `p_a0`, `p_b0` and
//! the platen at `u0` with volumes `V_a`, `V_b` (Merritt's valve coefficients for each land):
//!
//! ```text
//!   M·a = n·(A_a·p_a − A_b·p_b) − K·u − C·v
//!   (V_a/β)·ṗ_a =  K_qa·x_v − A_a·v − C_L·(p_a − p_b)      K_qa = K·√(P_s − p_a0)
//!   (V_b/β)·ṗ_b = −K_qb·x_v + A_b·v + C_L·(p_a − p_b)      K_qb = K·√(p_b0 − P_R)
//!   ẍ_v = ω_v²·(d_v − x_v) − 2ζ_v·ω_v·ẋ_v
//! ```
//!
//! A critically-centred valve has no flow-pressure coefficient at `x_v = 0` (`K_c = 0`): the
//! damping of the oil column comes from the leakage `C_L`, the platen's damping `C` and the
//! controller's `Δp` feedback. The controller is the continuous law of [`crate::Controller`]
//! followed by the zero-order hold's exact response `(1 − e^{−sT})/(sT)` and the valve's
//! delay `e^{−sτ}`; the high-pass filter is the continuous `s/(s + ω_hp)` (the digital one is
//! its Tustin form, equal within `(ωT)²`).
//!
//! The platen's friction is not linearisable at `v = 0`: [`Mechanics::of_model`] takes its
//! secant damping at a reference speed, and stick-slip is left to the simulation.

use num_complex::Complex64 as C64;
use platen_model::PlatenModel;

use crate::params::{ServoValve, TableSystem};

/// The rigid-body mechanics the loop drives, linearised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mechanics {
    /// Moving mass (payload included), kg.
    pub mass_kg: f64,
    /// Restoring stiffness, N/m.
    pub stiffness_n_per_m: f64,
    /// Viscous damping, N·s/m.
    pub damping_n_s_per_m: f64,
}

/// The speed at which [`Mechanics::of_model`] takes the platen's secant damping, m/s.
pub const SECANT_SPEED_M_S: f64 = 0.1;

impl Mechanics {
    /// The mechanics of `model` at mid-stroke with a rigid `payload_kg` on it: its mass, the
    /// slope of its elastic force, and the secant of its speed-dependent dissipation
    /// `(D(0, v*) − F_s)/v*` at `v* =` [`SECANT_SPEED_M_S`] (the Coulomb part is not linear).
    pub fn of_model<M: PlatenModel + ?Sized>(model: &M, payload_kg: f64) -> Self {
        let du = 1e-4;
        let k = (model.elastic_force_n(du) - model.elastic_force_n(-du)) / (2.0 * du);
        let c = model.dissipative_excess_n(0.0, SECANT_SPEED_M_S) / SECANT_SPEED_M_S;
        Self {
            mass_kg: model.mass_kg(0.0) + payload_kg,
            stiffness_n_per_m: k,
            damping_n_s_per_m: c,
        }
    }
}

/// The small-signal coefficients of the loop about a state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linearisation {
    /// Flow gain of the cap-side land `K_qa`, m³/s per unit opening (one actuator).
    pub flow_gain_a_m3_s: f64,
    /// Flow gain of the rod-side land `K_qb`, m³/s per unit opening.
    pub flow_gain_b_m3_s: f64,
    /// Flow-pressure coefficient `K_c` at the centred spool, m³/s/Pa (0: critically centred).
    pub flow_pressure_m3_s_per_pa: f64,
    /// Hydraulic compliance of chamber `a`, `V_a/β`, m³/Pa.
    pub compliance_a_m3_per_pa: f64,
    /// Hydraulic compliance of chamber `b`, `V_b/β`, m³/Pa.
    pub compliance_b_m3_per_pa: f64,
    /// The mechanics.
    pub mechanics: Mechanics,
}

/// Gain and phase margins of the loop broken at the drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Margins {
    /// Gain margin, dB, at the lowest phase crossover (`None`: no crossover below the
    /// controller's Nyquist frequency).
    pub gain_margin_db: Option<f64>,
    /// Frequency of that phase crossover, Hz.
    pub phase_crossover_hz: Option<f64>,
    /// Phase margin, degrees: the smallest angle between `L` and `−1` over the gain
    /// crossovers (`180° − |arg L|`; the loop's stability is [`Margins::stable`]).
    pub phase_margin_deg: Option<f64>,
    /// Frequency of that gain crossover, Hz.
    pub gain_crossover_hz: Option<f64>,
    /// Whether the closed loop is stable by the Nyquist criterion: the open loop is stable
    /// but for its poles at `s = 0` (the integrator, and the platen's displacement on a table
    /// without stiffness), whose indentations are counted, so the closed loop is stable when
    /// `1 + L` does not encircle the origin.
    pub stable: bool,
    /// The largest closed-loop gain command → displacement up to the controller's Nyquist
    /// frequency (the resonance peak), and where it is.
    pub peak_gain: f64,
    /// Frequency of that peak, Hz.
    pub peak_gain_hz: f64,
}

/// How flat the closed loop's gain command → displacement is: its −3 dB bandwidth and its
/// lowest gain below it ([`TableSystem::passband`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Passband {
    /// The frequency above which `|U/R|` stays below `1/√2` (−3 dB) up to the controller's
    /// Nyquist frequency, Hz (`None`: it ends above `1/√2`, or never reaches it).
    pub bandwidth_hz: Option<f64>,
    /// The lowest `|U/R|` from 0.001 Hz to its largest below the bandwidth (below the
    /// Nyquist frequency without one): a dip inside the band the table tracks, before the
    /// resonance peak and the roll-off.
    pub min_gain: f64,
    /// Where it is, Hz.
    pub min_gain_hz: f64,
}

/// The table's capacities by the closed forms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capacities {
    /// Force of all actuators at stall pushing (`p_a = P_s`, `p_b = P_R`), N.
    pub push_force_n: f64,
    /// Force of all actuators at stall pulling, N (positive).
    pub pull_force_n: f64,
    /// No-load velocity at full opening, extending (`+u`), m/s.
    pub extend_velocity_m_s: f64,
    /// No-load velocity at full opening, retracting, m/s (positive).
    pub retract_velocity_m_s: f64,
    /// Flow of all valves at full opening with the null drop on each land, m³/s.
    pub valve_flow_m3_s: f64,
}

impl TableSystem {
    /// The linearisation about the platen at `u_m` with the null pressures and a centred
    /// spool, driving `mechanics`.
    pub fn linearise(&self, mechanics: Mechanics, u_m: f64) -> Linearisation {
        let (p_a0, p_b0) = self.null_pressures_pa();
        let k = self.land_coefficient();
        let (v_a, v_b) = self.chamber_volumes_m3(u_m);
        Linearisation {
            flow_gain_a_m3_s: k * (self.supply_pressure_pa - p_a0).max(0.0).sqrt(),
            flow_gain_b_m3_s: k * (p_b0 - self.return_pressure_pa).max(0.0).sqrt(),
            flow_pressure_m3_s_per_pa: 0.0,
            compliance_a_m3_per_pa: v_a / self.oil_bulk_modulus_pa,
            compliance_b_m3_per_pa: v_b / self.oil_bulk_modulus_pa,
            mechanics,
        }
    }

    /// The oil-column frequency `(1/2π)·√(n·β·(A_a²/V_a + A_b²/V_b)/M)` with the platen at
    /// `u_m` and a moving mass `mass_kg`, Hz.
    pub fn oil_column_frequency_hz(&self, mass_kg: f64, u_m: f64) -> f64 {
        let a = &self.actuator;
        let (v_a, v_b) = self.chamber_volumes_m3(u_m);
        let stiffness = f64::from(a.count)
            * self.oil_bulk_modulus_pa
            * (a.cap_area_m2.powi(2) / v_a + a.rod_area_m2.powi(2) / v_b);
        (stiffness / mass_kg).sqrt() / std::f64::consts::TAU
    }

    /// The capacities by the closed forms (see [`Capacities`]).
    pub fn capacities(&self) -> Capacities {
        let a = &self.actuator;
        let n = f64::from(a.count);
        let (aa, ab) = (a.cap_area_m2, a.rod_area_m2);
        let (ps, pr) = (self.supply_pressure_pa, self.return_pressure_pa);
        let k = self.land_coefficient();
        let cube = aa.powi(3) + ab.powi(3);
        // No load: A_a·v = K√(P_s − p_a), A_b·v = K√(p_b − P_R), A_a·p_a = A_b·p_b.
        let extend = k * ((aa * ps - ab * pr).max(0.0) / cube).sqrt();
        let retract = k * ((ab * ps - aa * pr).max(0.0) / cube).sqrt();
        Capacities {
            push_force_n: n * (aa * ps - ab * pr),
            pull_force_n: n * (ab * ps - aa * pr),
            extend_velocity_m_s: extend,
            retract_velocity_m_s: retract,
            valve_flow_m3_s: n * k * (0.5 * (ps - pr)).sqrt(),
        }
    }

    /// The plant's response at `f_hz` from the valve input `d_v` to the displacement and to
    /// the pressure difference `p_a − p_b`: `(U/D_v, ΔP/D_v)`.
    pub fn plant_response(&self, lin: &Linearisation, f_hz: f64) -> (C64, C64) {
        let s = C64::new(0.0, std::f64::consts::TAU * f_hz);
        let act = &self.actuator;
        let m = &lin.mechanics;
        let n = f64::from(act.count);
        let x_v = spool_response(&self.servo_valve, s);
        // Unknowns U, P_a, P_b (V = sU) from x_v, by Cramer's rule on the 3 × 3 system:
        //   (M s² + C s + K)·U − n A_a P_a + n A_b P_b = 0
        //   A_a s U + (c_a s + C_L) P_a − C_L P_b      = K_qa X_v
        //  −A_b s U − C_L P_a + (c_b s + C_L) P_b      = −K_qb X_v
        let cl = act.leakage_m3_s_per_pa;
        let (aa, ab) = (act.cap_area_m2, act.rod_area_m2);
        let mat = [
            [
                m.mass_kg * s * s + m.damping_n_s_per_m * s + m.stiffness_n_per_m,
                C64::from(-n * aa),
                C64::from(n * ab),
            ],
            [aa * s, lin.compliance_a_m3_per_pa * s + cl, C64::from(-cl)],
            [-ab * s, C64::from(-cl), lin.compliance_b_m3_per_pa * s + cl],
        ];
        let rhs = [
            C64::from(0.0),
            lin.flow_gain_a_m3_s * x_v,
            -lin.flow_gain_b_m3_s * x_v,
        ];
        let det = det3(&mat);
        let col = |j: usize| {
            let mut m2 = mat;
            for (row, r) in m2.iter_mut().zip(rhs) {
                row[j] = r;
            }
            det3(&m2) / det
        };
        let (u, p_a, p_b) = (col(0), col(1), col(2));
        (u, p_a - p_b)
    }

    /// The loop's parts at `f_hz`: the zero-order hold and delay `Z`, the plant `(G_u, G_Δp)`,
    /// and the controller's error, feedforward, feedback and `Δp` paths.
    fn loop_parts(&self, lin: &Linearisation, f_hz: f64) -> LoopParts {
        let s = C64::new(0.0, std::f64::consts::TAU * f_hz);
        let c = &self.controller;
        let z = hold_response(s, c.period_s()) * (-s * self.servo_valve.delay_s).exp();
        let (g_u, g_p) = self.plant_response(lin, f_hz);
        let law = LawTerms::at(c, s);
        LoopParts {
            z,
            g_u,
            g_p,
            error: law.error,
            feedforward: law.feedforward,
            feedback: law.velocity_feedback + law.acceleration_feedback,
            dp: law.delta_p,
        }
    }

    /// The loop gain at `f_hz`, broken at the drive: `L = Z·((K_p + K_i/s + FB)·G_u + K_Δp·HP·G_Δp)`.
    pub fn loop_gain(&self, lin: &Linearisation, f_hz: f64) -> C64 {
        self.loop_parts(lin, f_hz).loop_gain()
    }

    /// The closed-loop response command → displacement at `f_hz`:
    /// `U/R = Z·G_u·(K_p + K_i/s + FF)/(1 + L)`. Command → acceleration is `−ω²` times it.
    pub fn closed_loop_response(&self, lin: &Linearisation, f_hz: f64) -> C64 {
        self.loop_parts(lin, f_hz).closed_loop()
    }

    /// The gain and phase margins of [`TableSystem::loop_gain`] (the worst over every
    /// crossover), the Nyquist stability of the closed loop and its resonance peak, searched
    /// from 0.001 Hz to the controller's Nyquist frequency on a logarithmic grid of 20 000
    /// points, each crossing refined by bisection.
    pub fn margins(&self, lin: &Linearisation) -> Margins {
        search_margins(
            |f| {
                let p = self.loop_parts(lin, f);
                (p.loop_gain(), p.closed_loop().norm())
            },
            0.5 * self.controller.sample_rate_hz,
            // The platen on its oil column, valve, filters, hold and delay: no unstable pole.
            0,
        )
    }

    /// The [`Passband`] of the closed loop of `lin`, on a logarithmic grid of 4000
    /// frequencies from 0.001 Hz to the controller's Nyquist frequency, the bandwidth refined
    /// by bisection.
    pub fn passband(&self, lin: &Linearisation) -> Passband {
        let level = std::f64::consts::FRAC_1_SQRT_2;
        let gain = |f: f64| self.closed_loop_response(lin, f).norm();
        let (f_min, f_max, n) = (0.001_f64, 0.5 * self.controller.sample_rate_hz, 4000);
        let at = |i: usize| f_min * (f_max / f_min).powf(i as f64 / n as f64);
        let g: Vec<f64> = (0..=n).map(|i| gain(at(i))).collect();
        // The last fall through the level, if the gain stays below it after.
        let last_fall = (1..=n)
            .rev()
            .take_while(|&i| g[i] < level)
            .last()
            .filter(|&i| g[i - 1] >= level);
        let bandwidth_hz = last_fall.map(|i| {
            let (mut a, mut b) = (at(i - 1), at(i));
            for _ in 0..60 {
                let m = (a * b).sqrt();
                if gain(m) < level {
                    b = m;
                } else {
                    a = m;
                }
            }
            (a * b).sqrt()
        });
        let below = last_fall.unwrap_or(n);
        let argmax = (0..=below).fold(0, |best, i| if g[i] > g[best] { i } else { best });
        let i_min = (0..=argmax).fold(0, |best, i| if g[i] < g[best] { i } else { best });
        Passband {
            bandwidth_hz,
            min_gain: g[i_min],
            min_gain_hz: at(i_min),
        }
    }

    /// The fastest rate of the loop, rad/s: the larger of the spool's natural frequency and
    /// the oil column's at either end of the stroke (the stiffest chamber) with `mass_kg`.
    pub fn fastest_rate_rad_s(&self, mass_kg: f64, stroke_m: f64) -> f64 {
        let wv = std::f64::consts::TAU * self.servo_valve.natural_frequency_hz;
        let oil = [-stroke_m, 0.0, stroke_m]
            .iter()
            .map(|&u| std::f64::consts::TAU * self.oil_column_frequency_hz(mass_kg, u))
            .fold(0.0, f64::max);
        wv.max(oil)
    }

    /// RK4 steps per controller period that resolve the fastest rate: the least `k` with
    /// `h·ω_max ≤ 0.25` for `h = T/k` (RK4's error per step is then about `(hω)⁵/120 ≈ 1e-5`
    /// of the mode; its stability bound is `hω < 2.8`).
    pub fn default_steps_per_period(&self, mass_kg: f64, stroke_m: f64) -> u32 {
        let t = self.controller.period_s();
        let k = (t * self.fastest_rate_rad_s(mass_kg, stroke_m) / 0.25).ceil();
        k.clamp(1.0, 1e6) as u32
    }
}

/// The margins search of [`TableSystem::margins`] on any loop: `loop_at(f)` is the loop
/// gain broken at one point and the closed loop's gain whose peak is reported, from
/// 0.001 Hz to `f_max` Hz on a logarithmic grid of 20 000 points, each crossing refined by
/// bisection.
pub(crate) fn search_margins(
    loop_at: impl Fn(f64) -> (C64, f64),
    f_max: f64,
    open_loop_unstable: usize,
) -> Margins {
    let loop_gain = |f: f64| loop_at(f).0;
    let (f_min, n) = (0.001_f64, 20_000);
    let at = |i: usize| f_min * (f_max / f_min).powf(i as f64 / n as f64);
    let mag = |f: f64| loop_gain(f).norm() - 1.0;
    let im = |f: f64| loop_gain(f).im;
    let mut out = Margins {
        gain_margin_db: None,
        phase_crossover_hz: None,
        phase_margin_deg: None,
        gain_crossover_hz: None,
        stable: true,
        peak_gain: 0.0,
        peak_gain_hz: 0.0,
    };
    let l0 = loop_gain(at(0));
    let (mut f0, mut m0, mut i0) = (at(0), l0.norm() - 1.0, l0.im);
    // The winding of 1 + L over 0 < ω < ∞ (the half contour; the other half mirrors it).
    let mut arg0 = (1.0 + l0).arg();
    let first_arg = arg0;
    let mut unwrapped = arg0;
    for i in 1..=n {
        let f1 = at(i);
        let (l1, h) = loop_at(f1);
        let (m1, i1) = (l1.norm() - 1.0, l1.im);
        let arg1 = (1.0 + l1).arg();
        let mut d = arg1 - arg0;
        while d > std::f64::consts::PI {
            d -= std::f64::consts::TAU;
        }
        while d < -std::f64::consts::PI {
            d += std::f64::consts::TAU;
        }
        unwrapped += d;
        arg0 = arg1;
        if h > out.peak_gain {
            out.peak_gain = h;
            out.peak_gain_hz = f1;
        }
        if m0.signum() != m1.signum() {
            let f = bisect(&mag, f0, f1);
            let l = loop_gain(f);
            // The angle between L and −1 at the crossover.
            let pm = 180.0 - l.arg().to_degrees().abs();
            if out.phase_margin_deg.is_none_or(|p| pm < p) {
                out.phase_margin_deg = Some(pm);
                out.gain_crossover_hz = Some(f);
            }
        }
        if i0.signum() != i1.signum() {
            let f = bisect(&im, f0, f1);
            let l = loop_gain(f);
            let gm = -20.0 * l.norm().log10();
            if l.re < 0.0 && out.gain_margin_db.is_none_or(|g| gm < g) {
                out.gain_margin_db = Some(gm);
                out.phase_crossover_hz = Some(f);
            }
        }
        (f0, m0, i0) = (f1, m1, i1);
    }
    // The full contour is this half, its mirror image and, for each pole of L at s = 0,
    // the indentation around it, which turns 1 + L by −π.
    let total = unwrapped - first_arg;
    // Poles of L at s = 0 (the controller's integrator; the platen's displacement when
    // nothing restores it): the slope of |L| a decade below the grid.
    let slope = (loop_gain(f_min * 0.01).norm() / loop_gain(f_min * 0.1).norm()).log10();
    let integrators = slope.round().max(0.0);
    let windings = (2.0 * total - std::f64::consts::PI * integrators) / std::f64::consts::TAU;
    // Nyquist: the closed loop's unstable poles are the open loop's less the counterclockwise
    // windings of 1 + L about 0 along the imaginary axis upwards.
    out.stable = windings.round() == open_loop_unstable as f64;
    out
}

/// The terms of a DOF's three-variable law ([`crate::Controller`]) at `s`, each per unit of
/// what it acts on.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LawTerms {
    /// On the error `r − u`: `K_p + K_i/s`.
    pub error: C64,
    /// On the command: `K_vf·s + K_af·s²`.
    pub feedforward: C64,
    /// On the displacement fed back: `K_vb·s` (the velocity feedback).
    pub velocity_feedback: C64,
    /// On the displacement fed back: `K_ab·s²` (the acceleration feedback).
    pub acceleration_feedback: C64,
    /// On the `Δp` fed back: `K_Δp·s/(s + ω_hp)` (`K_Δp` without a high-pass).
    pub delta_p: C64,
}

impl LawTerms {
    /// The terms of `c` at `s`.
    pub(crate) fn at(c: &crate::Controller, s: C64) -> Self {
        let highpass = if c.delta_p_highpass_hz > 0.0 {
            s / (s + std::f64::consts::TAU * c.delta_p_highpass_hz)
        } else {
            C64::from(1.0)
        };
        LawTerms {
            error: c.displacement_gain_per_m + c.integral_gain_per_m_s / s,
            feedforward: c.velocity_feedforward_s_per_m * s
                + c.acceleration_feedforward_s2_per_m * s * s,
            velocity_feedback: c.velocity_feedback_s_per_m * s,
            acceleration_feedback: c.acceleration_feedback_s2_per_m * s * s,
            delta_p: c.delta_p_gain_per_pa * highpass,
        }
    }
}

/// The zero-order hold's response `(1 − e^{−sT})/(sT)` at `s = jω` for the period `T`.
pub(crate) fn hold_response(s: C64, period_s: f64) -> C64 {
    if s.im * period_s < 1e-12 {
        C64::from(1.0)
    } else {
        (1.0 - (-s * period_s).exp()) / (s * period_s)
    }
}

/// The spool's response to its input, `ω_v²/(s² + 2ζ_v·ω_v·s + ω_v²)`.
pub(crate) fn spool_response(valve: &ServoValve, s: C64) -> C64 {
    let wv = std::f64::consts::TAU * valve.natural_frequency_hz;
    let zeta = valve.damping_ratio;
    wv * wv / (s * s + 2.0 * zeta * wv * s + wv * wv)
}

struct LoopParts {
    z: C64,
    g_u: C64,
    g_p: C64,
    error: C64,
    feedforward: C64,
    feedback: C64,
    dp: C64,
}

impl LoopParts {
    /// `L = Z·((K_p + K_i/s + FB)·G_u + K_Δp·HP·G_Δp)`.
    fn loop_gain(&self) -> C64 {
        self.z * ((self.error + self.feedback) * self.g_u + self.dp * self.g_p)
    }

    /// `U/R = Z·G_u·(K_p + K_i/s + FF)/(1 + L)`.
    fn closed_loop(&self) -> C64 {
        self.z * self.g_u * (self.error + self.feedforward) / (1.0 + self.loop_gain())
    }
}

fn det3(m: &[[C64; 3]; 3]) -> C64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn bisect(g: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let ga = g(a);
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if g(m).signum() == ga.signum() {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}
