//! The closed loop's poles: the linear model of [`TableLinearisation`] as a state-space
//! matrix, its delays by Padé approximants, and the stability told by its eigenvalues.
//!
//! # The state
//!
//! `[q, q̇, z, ż]` (the free DOFs, the specimen), then per actuator its chamber pressures
//! `P_a` (and `P_b` when double-acting), its spool `x, ẋ` and the [`PADE_ORDER`] states of
//! its drive's delay, then per free DOF its controller's integrator (with `K_i ≠ 0`) and its
//! `Δp` high-pass (with `K_Δp ≠ 0` and a corner). The equations are the module's, in the time
//! domain, with the command at zero:
//!
//! * `q̈ = A_q·q + A_v·q̇ + B·f + P·Γᵀ·(C·ż + K·z)`, `f = A_a·P_a − A_b·P_b`;
//! * `z̈ = −Γ_f·q̈ − M⁻¹·(C·ż + K·z)`;
//! * `c·Ṗ_a = −C_L·(P_a − P_b) + K_qa·x − A_a·(G·q̇)`, `c·Ṗ_b = C_L·(P_a − P_b) − K_qb·x +
//!   A_b·(G·q̇)` (single-acting: `c·Ṗ_a = −C_L·P_a + K_qa·x − A_a·(G·q̇)`);
//! * `ẍ = ω_v²·(D_θ − x) − 2ζ_v·ω_v·ẋ`, `D_θ` the drive `D` delayed by `θ = τ + T/2`: the
//!   valve's delay and the zero-order hold's (`(1 − e^{−sT})/(sT)` has the phase of
//!   `e^{−sT/2}`; its magnitude, within 0.4 % below `0.05/T`, is left out), as the
//!   `[m/m]` Padé approximant `N(−sθ)/N(sθ)`;
//! * `d_k = −K_p·q̂_k + K_i·ξ_k − K_vb·q̂̇_k − K_ab·q̈_k − K_Δp·h_k`, `ξ̇_k = −q̂_k`,
//!   `h = HP(Δp̂)` (`η̇ = −ω_hp·η + Δp̂`, `h = Δp̂ − ω_hp·η`), `q̂ = G_c⁺·G·q`,
//!   `Δp̂ = G_c⁺·Δp`;
//! * `D = G_c·d − K_fb·(I − G_c·G_c⁺)·f`.
//!
//! The loop is stable when every eigenvalue of the matrix has a negative real part; an
//! eigenvalue within [`MARGINAL_RATE_1_S`] of the axis (a mode of the chambers' mean pressure
//! that no flow reaches, an integrator that nothing closes) is marginal, not unstable.

use nalgebra::DMatrix;
use num_complex::Complex64 as C64;
use platen_model::multi_axis::Dof;

use super::{ActuatorLinearisation, TableLinearisation};

/// Order of the Padé approximants of the delays: `[6/6]` is within 1e-6 in phase of
/// `e^{−sθ}` for `ωθ < 2`, well past the valves' bandwidth at the delays of servo-valves.
pub const PADE_ORDER: usize = 6;

/// The real part, 1/s, below which an eigenvalue counts as on the imaginary axis (marginal):
/// a growth with a time constant of 1 000 s, longer than any test.
pub const MARGINAL_RATE_1_S: f64 = 1e-3;

/// The closed loop's stability from its eigenvalues ([`TableLinearisation::stability`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LoopStability {
    /// No eigenvalue in the right half-plane (beyond [`MARGINAL_RATE_1_S`]).
    pub stable: bool,
    /// The eigenvalues with a real part above [`MARGINAL_RATE_1_S`] (upper half-plane ones of
    /// complex pairs), fastest-growing first, 1/s.
    pub unstable_poles: Vec<C64>,
    /// The free DOF that moves the most in the fastest-growing mode (rotations weighted by
    /// the platen's radius of gyration about that axis); `None` when stable.
    pub unstable_dof: Option<Dof>,
    /// The largest real part of the eigenvalues off the imaginary axis (beyond
    /// [`MARGINAL_RATE_1_S`] either way), 1/s: negative when stable (the slowest decay),
    /// positive when not (the fastest growth).
    pub largest_real_part_1_s: f64,
    /// How many eigenvalues lie within [`MARGINAL_RATE_1_S`] of the imaginary axis.
    pub marginal_poles: usize,
    /// How many states the matrix has.
    pub states: usize,
}

/// Where each actuator's states sit in the state vector.
#[derive(Debug, Clone, Copy)]
struct ActuatorSlots {
    p_a: usize,
    p_b: Option<usize>,
    spool: usize,
    delay: usize,
}

/// The `[m/m]` Padé approximant of `e^{−σ}` in controllable canonical form (in `σ = sθ`):
/// `(A, b, c, d)` with `A` the companion matrix of the monic denominator.
fn pade(m: usize) -> (DMatrix<f64>, Vec<f64>, f64) {
    // N(x) = Σ c_k x^k, c_k = (2m − k)!·m! / ((2m)!·k!·(m − k)!).
    let fact = |n: usize| (1..=n).map(|i| i as f64).product::<f64>();
    let c: Vec<f64> = (0..=m)
        .map(|k| fact(2 * m - k) * fact(m) / (fact(2 * m) * fact(k) * fact(m - k)))
        .collect();
    let a: Vec<f64> = c.iter().map(|x| x / c[m]).collect();
    let sign = |k: usize| if k % 2 == 0 { 1.0 } else { -1.0 };
    let d = sign(m);
    let mut companion = DMatrix::zeros(m, m);
    for r in 0..m.saturating_sub(1) {
        companion[(r, r + 1)] = 1.0;
    }
    for k in 0..m {
        companion[(m - 1, k)] = -a[k];
    }
    // The strictly proper part of N(−σ)/N(σ): numerator coefficients (−1)^k·a_k − d·a_k.
    let out: Vec<f64> = (0..m).map(|k| (sign(k) - d) * a[k]).collect();
    (companion, out, d)
}

impl TableLinearisation {
    /// The closed loop's state matrix (see the module docs), with the loop of free DOF
    /// `broken` opened at its drive (`d_k = 0`) when given.
    pub fn state_matrix(&self, broken: Option<usize>) -> DMatrix<f64> {
        self.assemble(broken)
    }

    /// Stability of the closed loop from its eigenvalues (see [`LoopStability`]).
    pub fn stability(&self) -> LoopStability {
        let a = self.assemble(None);
        let states = a.nrows();
        let eig = eigenvalues(&a);
        let marginal = |l: &C64| l.re.abs() <= MARGINAL_RATE_1_S;
        let largest = eig
            .iter()
            .filter(|l| !marginal(l))
            .map(|l| l.re)
            .fold(f64::NEG_INFINITY, f64::max);
        let marginal_poles = eig.iter().filter(|l| marginal(l)).count();
        let mut unstable: Vec<C64> = eig
            .iter()
            .copied()
            .filter(|l| l.re > MARGINAL_RATE_1_S && l.im >= 0.0)
            .collect();
        unstable.sort_by(|x, y| y.re.total_cmp(&x.re));
        let unstable_dof = unstable.first().and_then(|&l| self.dof_of_mode(&a, l));
        LoopStability {
            stable: unstable.is_empty() && eig.iter().all(|l| l.re.is_finite()),
            unstable_poles: unstable,
            unstable_dof,
            largest_real_part_1_s: largest,
            marginal_poles,
            states,
        }
    }

    /// How many eigenvalues of the loop opened at `dof`'s drive (the other loops closed) lie
    /// in the right half-plane: the open-loop unstable poles the Nyquist criterion must count
    /// for its loop gain. `None` for a held DOF.
    pub fn open_loop_unstable_poles(&self, dof: Dof) -> Option<usize> {
        let k = self.free.iter().position(|&d| d == dof)?;
        Some(self.unstable_with_open(k))
    }

    /// [`TableLinearisation::open_loop_unstable_poles`] of free DOF `k`.
    pub(crate) fn unstable_with_open(&self, k: usize) -> usize {
        eigenvalues(&self.state_matrix(Some(k)))
            .iter()
            .filter(|l| l.re > MARGINAL_RATE_1_S)
            .count()
    }

    /// The free DOF that moves the most in the mode of eigenvalue `lambda` (one step of
    /// inverse iteration from a fixed start), rotations weighted by the platen's radius of
    /// gyration.
    fn dof_of_mode(&self, a: &DMatrix<f64>, lambda: C64) -> Option<Dof> {
        let n = a.nrows();
        // A shift just off the eigenvalue keeps the solve regular.
        let shift = lambda + C64::new(1e-9 * (1.0 + lambda.norm()), 0.0);
        let m = DMatrix::from_fn(n, n, |r, c| {
            C64::from(a[(r, c)]) - if r == c { shift } else { C64::from(0.0) }
        });
        let lu = m.lu();
        let mut v = DMatrix::from_fn(n, 1, |r, _| C64::from(1.0 + 0.01 * r as f64));
        for _ in 0..3 {
            v = lu.solve(&v)?;
            let norm = v.norm();
            if !(norm.is_finite() && norm > 0.0) {
                return None;
            }
            v /= C64::from(norm);
        }
        let weight = |d: Dof| {
            if d.is_rotation() {
                self.radius_of_gyration_m[d.index() - 3]
            } else {
                1.0
            }
        };
        self.free
            .iter()
            .enumerate()
            .map(|(k, &d)| (d, v[(k, 0)].norm() * weight(d)))
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .map(|(d, _)| d)
    }

    /// The state matrix: the states' layout, the algebraic outputs over the state (forces,
    /// `Δp`, the accelerations, the drives), then the rates row block by row block.
    fn assemble(&self, broken: Option<usize>) -> DMatrix<f64> {
        let layout = self.layout();
        let (force, delta_p) = self.chamber_outputs(&layout);
        let mut qdd = self.platen_accelerations(&layout, &force);
        let zdd = self.specimen_accelerations(&layout, &mut qdd);
        // The DOF drives d (free × state), then the actuator drives D = G_c·d − balance·f.
        let dp_hat = &self.g_c_pinv * &delta_p;
        let d = self.dof_drives(&layout, &qdd, &dp_hat, broken);
        let drives = &self.g_c * &d - &self.balance * &force;
        // The rates.
        let mut a = DMatrix::zeros(layout.size, layout.size);
        layout.kinematic_rows(&mut a, &qdd, &zdd);
        let pade = pade(PADE_ORDER);
        for (i, (act, s)) in self.actuators.iter().zip(&layout.slots).enumerate() {
            self.chamber_rows(&mut a, &layout, i, act, s);
            self.valve_rows(&mut a, i, act, s, &drives, &pade);
        }
        self.controller_rows(&mut a, &layout, &dp_hat);
        a
    }

    /// Where every state sits: the free DOFs and the specimen, each actuator's chambers,
    /// spool and delay line, then the controllers' integrators and high-passes.
    fn layout(&self) -> StateLayout {
        let nf = self.free.len();
        let nz = self.specimen.as_ref().map_or(0, |s| s.mass.nrows());
        let n = self.actuators.len();
        let (iq, iqd, iz, izd) = (0, nf, 2 * nf, 2 * nf + nz);
        let mut next = 2 * nf + 2 * nz;
        let mut slots = Vec::with_capacity(n);
        for a in &self.actuators {
            let p_a = next;
            let single = a.hydraulics.is_single_acting();
            let p_b = (!single).then_some(p_a + 1);
            let spool = p_a + if single { 1 } else { 2 };
            let delay = spool + 2;
            next = delay + PADE_ORDER;
            slots.push(ActuatorSlots {
                p_a,
                p_b,
                spool,
                delay,
            });
        }
        let mut integrator = vec![None; nf];
        let mut highpass = vec![None; nf];
        for (k, g) in self.gains.iter().enumerate() {
            if g.integral_gain_per_m_s != 0.0 {
                integrator[k] = Some(next);
                next += 1;
            }
            if g.delta_p_gain_per_pa != 0.0 && g.delta_p_highpass_hz > 0.0 {
                highpass[k] = Some(next);
                next += 1;
            }
        }
        StateLayout {
            nf,
            nz,
            iq,
            iqd,
            iz,
            izd,
            slots,
            integrator,
            highpass,
            size: next,
        }
    }

    /// The actuators' forces `f` and pressure differences `Δp` as rows over the state.
    fn chamber_outputs(&self, layout: &StateLayout) -> (DMatrix<f64>, DMatrix<f64>) {
        let n = self.actuators.len();
        let mut force = DMatrix::zeros(n, layout.size);
        let mut delta_p = DMatrix::zeros(n, layout.size);
        for (i, (a, s)) in self.actuators.iter().zip(&layout.slots).enumerate() {
            force[(i, s.p_a)] = a.hydraulics.cap_area_m2;
            delta_p[(i, s.p_a)] = 1.0;
            if let Some(b) = s.p_b {
                force[(i, b)] = -a.hydraulics.rod_area_m2;
                delta_p[(i, b)] = -1.0;
            }
        }
        (force, delta_p)
    }

    /// The platen's accelerations without the specimen's push, rows over the state:
    /// `q̈ = A_q·q + A_v·q̇ + B·f`.
    fn platen_accelerations(&self, layout: &StateLayout, force: &DMatrix<f64>) -> DMatrix<f64> {
        let StateLayout { nf, iq, iqd, .. } = *layout;
        let mut qdd = &self.b * force;
        for r in 0..nf {
            for c in 0..nf {
                qdd[(r, iq + c)] += self.a_q[(r, c)];
                qdd[(r, iqd + c)] += self.a_v[(r, c)];
            }
        }
        qdd
    }

    /// Adds the specimen's push `P·Γᵀ·(C·ż + K·z)` to the platen's accelerations `qdd`, and
    /// returns the specimen's, `z̈ = −Γ_f·q̈ − M⁻¹·(C·ż + K·z)` (no rows without a specimen).
    fn specimen_accelerations(&self, layout: &StateLayout, qdd: &mut DMatrix<f64>) -> DMatrix<f64> {
        let StateLayout {
            nf, nz, iz, izd, ..
        } = *layout;
        let mut zdd = DMatrix::zeros(nz, layout.size);
        if let Some(sp) = &self.specimen {
            let on_platen_k = &sp.push * &sp.stiffness;
            let on_platen_c = &sp.push * &sp.damping;
            for r in 0..nf {
                for j in 0..nz {
                    qdd[(r, iz + j)] += on_platen_k[(r, j)];
                    qdd[(r, izd + j)] += on_platen_c[(r, j)];
                }
            }
            let m_inv = sp
                .mass
                .clone()
                .try_inverse()
                .unwrap_or_else(|| DMatrix::zeros(nz, nz));
            let influence = &m_inv * &sp.mass_influence;
            zdd = -(&influence * &*qdd);
            let (mk, mc) = (&m_inv * &sp.stiffness, &m_inv * &sp.damping);
            for r in 0..nz {
                for j in 0..nz {
                    zdd[(r, iz + j)] -= mk[(r, j)];
                    zdd[(r, izd + j)] -= mc[(r, j)];
                }
            }
        }
        zdd
    }

    /// The DOF drives `d_k = −K_p·q̂_k + K_i·ξ_k − K_vb·q̂̇_k − K_ab·q̈_k − K_Δp·h_k`, free ×
    /// state, with the loop `broken` left at zero.
    fn dof_drives(
        &self,
        layout: &StateLayout,
        qdd: &DMatrix<f64>,
        dp_hat: &DMatrix<f64>,
        broken: Option<usize>,
    ) -> DMatrix<f64> {
        let StateLayout {
            nf, iq, iqd, size, ..
        } = *layout;
        let mut d = DMatrix::zeros(nf, size);
        for (k, g) in self.gains.iter().enumerate() {
            if Some(k) == broken {
                continue;
            }
            for c in 0..nf {
                let fg = self.feedback_geometry[(k, c)];
                d[(k, iq + c)] -= g.displacement_gain_per_m * fg;
                d[(k, iqd + c)] -= g.velocity_feedback_s_per_m * fg;
            }
            for c in 0..size {
                d[(k, c)] -= g.acceleration_feedback_s2_per_m * qdd[(k, c)];
                d[(k, c)] -= g.delta_p_gain_per_pa * dp_hat[(k, c)];
            }
            if let Some(j) = layout.integrator[k] {
                d[(k, j)] += g.integral_gain_per_m_s;
            }
            if let Some(j) = layout.highpass[k] {
                let w = std::f64::consts::TAU * g.delta_p_highpass_hz;
                d[(k, j)] += g.delta_p_gain_per_pa * w;
            }
        }
        d
    }

    /// Actuator `i`'s chamber rows: `c·Ṗ_a = −C_L·(P_a − P_b) + K_qa·x − A_a·(G·q̇)` and its
    /// mirror for `P_b` (single-acting: `c·Ṗ_a = −C_L·P_a + K_qa·x − A_a·(G·q̇)`).
    fn chamber_rows(
        &self,
        a: &mut DMatrix<f64>,
        layout: &StateLayout,
        i: usize,
        act: &ActuatorLinearisation,
        s: &ActuatorSlots,
    ) {
        let StateLayout { nf, iqd, .. } = *layout;
        let stroke_rate = &self.g; // actuators × free: S = G·q, Ṡ = G·q̇.
        let h = &act.hydraulics;
        let comp = act.compliance_m3_per_pa;
        let leak = h.leakage_m3_s_per_pa;
        match s.p_b {
            None => {
                a[(s.p_a, s.p_a)] = -leak / comp;
                a[(s.p_a, s.spool)] = act.flow_gain_a_m3_s / comp;
                for c in 0..nf {
                    a[(s.p_a, iqd + c)] = -h.cap_area_m2 * stroke_rate[(i, c)] / comp;
                }
            }
            Some(b) => {
                a[(s.p_a, s.p_a)] = -leak / comp;
                a[(s.p_a, b)] = leak / comp;
                a[(b, s.p_a)] = leak / comp;
                a[(b, b)] = -leak / comp;
                a[(s.p_a, s.spool)] = act.flow_gain_a_m3_s / comp;
                a[(b, s.spool)] = -act.flow_gain_b_m3_s / comp;
                for c in 0..nf {
                    a[(s.p_a, iqd + c)] = -h.cap_area_m2 * stroke_rate[(i, c)] / comp;
                    a[(b, iqd + c)] = h.rod_area_m2 * stroke_rate[(i, c)] / comp;
                }
            }
        }
    }

    /// Actuator `i`'s delay line `w' = (A·w + e_m·D)/θ`, `D_θ = c·w + d·D`, and spool rows
    /// `ẍ = ω²·(D_θ − x) − 2ζω·ẋ`, from its drive's row in `drives` and the Padé approximant
    /// `(A, c, d)`.
    fn valve_rows(
        &self,
        a: &mut DMatrix<f64>,
        i: usize,
        act: &ActuatorLinearisation,
        s: &ActuatorSlots,
        drives: &DMatrix<f64>,
        (pade_a, pade_c, pade_d): &(DMatrix<f64>, Vec<f64>, f64),
    ) {
        let size = a.ncols();
        let valve = &act.hydraulics.servo_valve;
        let wv = std::f64::consts::TAU * valve.natural_frequency_hz;
        let theta = valve.delay_s + 0.5 * self.period_s;
        for r in 0..PADE_ORDER {
            for c in 0..PADE_ORDER {
                a[(s.delay + r, s.delay + c)] = pade_a[(r, c)] / theta;
            }
        }
        for c in 0..size {
            a[(s.delay + PADE_ORDER - 1, c)] += drives[(i, c)] / theta;
        }
        a[(s.spool, s.spool + 1)] = 1.0;
        let row = s.spool + 1;
        a[(row, s.spool)] -= wv * wv;
        a[(row, s.spool + 1)] -= 2.0 * valve.damping_ratio * wv;
        for k in 0..PADE_ORDER {
            a[(row, s.delay + k)] += wv * wv * pade_c[k];
        }
        for c in 0..size {
            a[(row, c)] += wv * wv * pade_d * drives[(i, c)];
        }
    }

    /// The controllers' own states' rows: `ξ̇_k = −q̂_k` and the high-pass
    /// `η̇ = −ω_hp·η + Δp̂`.
    fn controller_rows(&self, a: &mut DMatrix<f64>, layout: &StateLayout, dp_hat: &DMatrix<f64>) {
        let StateLayout { nf, iq, size, .. } = *layout;
        let q_hat = &self.feedback_geometry; // free × free
        for k in 0..nf {
            if let Some(j) = layout.integrator[k] {
                for c in 0..nf {
                    a[(j, iq + c)] = -q_hat[(k, c)];
                }
            }
            if let Some(j) = layout.highpass[k] {
                let w = std::f64::consts::TAU * self.gains[k].delta_p_highpass_hz;
                a[(j, j)] -= w;
                for c in 0..size {
                    a[(j, c)] += dp_hat[(k, c)];
                }
            }
        }
    }
}

/// Where every state sits in the state vector (see the module docs).
struct StateLayout {
    /// How many free DOFs.
    nf: usize,
    /// How many specimen DOFs.
    nz: usize,
    /// The first of `q`, `q̇`, `z` and `ż`.
    iq: usize,
    iqd: usize,
    iz: usize,
    izd: usize,
    /// Per actuator its states.
    slots: Vec<ActuatorSlots>,
    /// Per free DOF its integrator's state, if any.
    integrator: Vec<Option<usize>>,
    /// Per free DOF its `Δp` high-pass's state, if any.
    highpass: Vec<Option<usize>>,
    /// How many states.
    size: usize,
}

impl StateLayout {
    /// The rows of the mechanics: `q̇` and `ż` as rates of `q` and `z`, the accelerations
    /// `qdd` and `zdd` as rates of `q̇` and `ż`.
    fn kinematic_rows(&self, a: &mut DMatrix<f64>, qdd: &DMatrix<f64>, zdd: &DMatrix<f64>) {
        let StateLayout {
            nf,
            nz,
            iq,
            iqd,
            iz,
            izd,
            size,
            ..
        } = *self;
        for r in 0..nf {
            a[(iq + r, iqd + r)] = 1.0;
            for c in 0..size {
                a[(iqd + r, c)] = qdd[(r, c)];
            }
        }
        for r in 0..nz {
            a[(iz + r, izd + r)] = 1.0;
            for c in 0..size {
                a[(izd + r, c)] = zdd[(r, c)];
            }
        }
    }
}

/// The eigenvalues of `a` (balanced first, as LAPACK's `dgeev` does); NaN when the Schur
/// iteration does not converge.
fn eigenvalues(a: &DMatrix<f64>) -> Vec<C64> {
    if a.is_empty() {
        return Vec::new();
    }
    if !a.iter().all(|x| x.is_finite()) {
        return vec![C64::new(f64::NAN, f64::NAN)];
    }
    let mut balanced = a.clone();
    nalgebra::linalg::balancing::balance_parlett_reinsch(&mut balanced);
    match nalgebra::linalg::Schur::try_new(balanced, 1e-14, 100_000) {
        Some(schur) => schur.complex_eigenvalues().iter().copied().collect(),
        None => vec![C64::new(f64::NAN, f64::NAN)],
    }
}
