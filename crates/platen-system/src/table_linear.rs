//! The small-signal model of a multi-axis table's closed loop about neutral at rest: the
//! command → pose transfer matrix, each DOF's loop gain and margins, and the cross-talk.
//!
//! # The linear model
//!
//! About the platen at rest at neutral, held by the static forces `f₀`
//! ([`TableHydraulics::static_forces_n`]: its weight, the struts' pull and a specimen's
//! weight resolved over the actuators as the force balance does), every actuator at its null
//! pressures with its spool at (or, making up the leakage, next to) its null. Deviations,
//! over the `n_f` free DOFs (the held ones are removed), `s = jω`:
//!
//! * **Mechanics**, linearised numerically from [`MultiAxisTable::accelerations`] by central
//!   differences about `(q, q̇, f) = (0, 0, f₀)`, with the actuators' forces along their lines
//!   at the pose, the struts and gravity (and a specimen's static push) as the applied
//!   wrench: `q̈ = A_q·q + A_v·q̇ + B·f (+ P·w)`. `A_q` holds the struts' stiffness, the
//!   geometric stiffness of the preloads (forces that turn with the platen, pads' forces on
//!   fixed lines); `A_v` is zero at rest but kept; `P` is the acceleration per wrench. The
//!   strokes `S = G·q`, `G` the strokes' derivatives at neutral, read exactly from
//!   [`MultiAxisTable::stroke_rate_m_s`] (linear in the rates), as the chambers see them
//!   (the force transmission is in `B`: the two differ for a tilted pad).
//! * **Specimen** ([`LinearSpecimen`], optional): its DOFs `z` feel the platen's acceleration,
//!   `M·(s²z + Γ_f·s²q) + (C·s + K)·z = 0`, and push on the platen with the wrench
//!   `Γᵀ·(C·s + K)·z` (`Γ_f` its influence on the free DOFs).
//! * **Chambers**, per actuator, Merritt's model with constant volumes `V₀` (compliances
//!   `c = V₀/β`):
//!   `(c·s + C_L)·P_a − C_L·P_b = K_qa·X − A_a·s·S`,
//!   `−C_L·P_a + (c·s + C_L)·P_b = −K_qb·X + A_b·s·S`, force `f = A_a·P_a − A_b·P_b`,
//!   `Δp = P_a − P_b`; a single-acting one `(c·s + C_L)·P_a = K_qa·X − A_a·s·S` (its leakage
//!   to return), `f = A_a·P_a`, `Δp = P_a`.
//! * **Flow gains** ([`FlowGains`]): the critically centred valve's land passes `K·x·√Δp`
//!   onto a different drop on either side of its null (the orifice's laminar slope below its
//!   transition drop, as the nonlinear valve; no flow-pressure coefficient at the null). By
//!   default the mean of the two sides, `K_qa = K·(√(P_s − p_a0) + √(p_a0 − P_R))/2`,
//!   `K_qb = K·(√(P_s − p_b0) + √(p_b0 − P_R))/2` (the NumPy reference's: a sine's
//!   fundamental about a spool resting on its null); or the side the spool rests on to make
//!   up the leakage ([`FlowGains::AtRest`], the nonlinear loop's tangent). They agree where
//!   the null pressures are at mid-supply. Elsewhere the nonlinear loop's fundamental
//!   depends on the amplitude: the rest side's gain while the spool's excursion stays within
//!   its rest opening, and beyond it a describing function neither is (the valve's kink at
//!   its null is not linearisable, and the flow it rectifies moves the spool's mean). On the
//!   loop test table (`tools/reference/loop_table.json`, null pressures far from mid-supply)
//!   the mean's x response at 2 Hz is 0.8 % and 1.3° off the nonlinear loop's at 0.1 mm,
//!   its x → pitch cross-talk 8.5 % and 4.8°; the rest side's is within 0.6 % and 0.3° of
//!   it for excursions within the rest openings (`platen-integrate`'s
//!   `tests/table_linear_small_signal.rs`).
//! * **Valve**: `X = ω_v²/(s² + 2ζ_v·ω_v·s + ω_v²)·e^{−sτ}·Z(s)·D`, `Z = (1 − e^{−sT})/(sT)`
//!   the controller's zero-order hold (`T = 1/f_c`), `τ` the valve's delay, `D` its drive.
//! * **Controller** ([`DofController`], its constant geometry `G_c` and `G_c⁺`):
//!   `q̂ = G_c⁺·G·q`, `Δp̂ = G_c⁺·Δp`, per free DOF `k`
//!   `d_k = (K_p + K_i/s)·(r_k − q̂_k) + (K_vf·s + K_af·s²)·r_k − K_vb·s·q̂_k − K_ab·s²·q_k
//!   − K_Δp·HP(s)·Δp̂_k` (the acceleration fed back is the platen's own), `HP = s/(s + ω_hp)`
//!   (1 without a high-pass; the digital filter is its Tustin form), and the actuator drives
//!   `D = G_c·d − K_fb·(I − G_c·G_c⁺)·f`.
//!
//! Per frequency the unknowns `[q, z, D]` (the DOF drives `d` substituted) solve one complex
//! linear system (`n_f + n_z + n` of them), with the command `r` on the right-hand side.
//!
//! **Loop gain** of DOF `k` ([`TableLinearisation::loop_gain`]): the loop broken at its DOF
//! drive `d_k` with every other loop (and the force balance) closed; a unit `d_k` injected,
//! `L_k = −(the controller's own d_k)`, so that the closed loop is `1 + L_k` as the uniaxial
//! [`TableSystem::loop_gain`](crate::TableSystem::loop_gain). With one free DOF and two
//! identical actuators along it, this is the uniaxial loop of two actuators.
//!
//! # Left out
//!
//! Friction (the pads and bearings are frictionless here: Coulomb friction is not
//! linearisable at rest), the accumulator (the supply is constant), the warping forces the
//! force balance builds at rest to hold redundant actuators' rest openings (they shift the
//! chamber pressures a little off the null ones), the valves' saturation,
//! the chambers' volume change with the stroke, sampling beyond the hold's response (aliasing;
//! within `(f/f_c)²`), and the modes of the double-acting actuators' mean pressure: with
//! `p_a0 + p_b0 = P_s + P_R` the two lands' gains are equal and the valve has no
//! flow-pressure coefficient at null, so `P_a + P_b` has a pole at exactly `s = 0` that no
//! command reaches (the response is finite at every `f > 0`). Frequencies are `> 0` (the
//! integrator and those modes make `s = 0` singular).
//!
//! # Conventions
//!
//! SI units; the pose `(x, y, z, roll, pitch, yaw)` in m and rad as
//! [`platen_model::multi_axis`], so a transfer-matrix entry is m/m, rad/rad, m/rad or rad/m;
//! rows are the pose, columns the command; the held DOFs' rows and columns are zero.

use nalgebra::DMatrix;
use num_complex::Complex64 as C64;
use platen_model::multi_axis::{Coords, Dof, LinearSpecimen, MultiAxisTable, Wrench};

use crate::dof_control::{DofController, DofGeometry};
use crate::error::{invalid, Result, SystemError};
use crate::hydraulics::{root, HydraulicConstants};
use crate::linear::{hold_response, search_margins, spool_response, LawTerms, Margins};
use crate::params::Controller;
use crate::table::{ActuatorHydraulics, TableHydraulics};

mod poles;
pub use poles::{LoopStability, MARGINAL_RATE_1_S, PADE_ORDER};

/// Step of the pose's central differences, m or rad (rates, m/s or rad/s).
const POSE_STEP: f64 = 1e-5;
/// Step of the actuator forces' and of the wrench's central differences, N or N·m (the
/// accelerations are linear in them).
const FORCE_STEP_N: f64 = 1e3;

/// One actuator's small-signal values at rest at neutral.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorLinearisation {
    /// The static force that holds the platen, N.
    pub static_force_n: f64,
    /// Its null pressure in chamber `a`, Pa (absolute).
    pub null_pressure_a_pa: f64,
    /// Its null pressure in chamber `b`, Pa (the return pressure for a single-acting one).
    pub null_pressure_b_pa: f64,
    /// Flow gain of the cap-side land `K_qa` ([`FlowGains`]), m³/s per unit opening.
    pub flow_gain_a_m3_s: f64,
    /// Flow gain of the rod-side land `K_qb`, m³/s per unit opening (0: single-acting).
    pub flow_gain_b_m3_s: f64,
    /// With [`FlowGains::AtRest`], the spool's opening at rest that makes up the leakage at
    /// the null pressures (fraction of full opening; 0 with [`FlowGains::Mean`]): the model
    /// holds for spool excursions smaller than it.
    pub rest_opening: f64,
    /// Hydraulic compliance of each chamber at neutral, `V₀/β`, m³/Pa.
    pub compliance_m3_per_pa: f64,
    /// Its hydraulics.
    pub hydraulics: ActuatorHydraulics,
}

/// Which of a land's two gains the linearisation takes (see the module docs): a critically
/// centred valve's land passes `K·x·√Δp` onto a different drop on either side of its null.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FlowGains {
    /// The mean of the opening- and closing-side gains, `K·(√(P_s − p₀) + √(p₀ − P_R))/2`
    /// (the NumPy reference's): the fundamental of a sine about a spool at rest on its null.
    /// Exact where the two drops are equal (null pressures at mid-supply).
    #[default]
    Mean,
    /// The gain of the side on which the spool rests: at the null pressures the leakage
    /// (across the piston `C_L·(p_a0 − p_b0)`, or to return `C_L·(p_a0 − P_R)` single-acting)
    /// flows, and the valve makes it up by resting slightly open
    /// ([`ActuatorLinearisation::rest_opening`]); a signal whose spool excursion stays within
    /// that opening sees only that side's gain. The tangent linearisation of the nonlinear
    /// loop about its equilibrium. Without leakage to make up, the mean.
    AtRest,
}

/// A specimen's part of the linear mechanics.
#[derive(Debug, Clone, PartialEq)]
struct SpecimenPart {
    mass: DMatrix<f64>,
    stiffness: DMatrix<f64>,
    damping: DMatrix<f64>,
    /// `M·Γ_f`, specimen DOFs × free DOFs.
    mass_influence: DMatrix<f64>,
    /// `P·Γᵀ`: the platen's acceleration per unit of the specimen's restoring forces, free
    /// DOFs × specimen DOFs.
    push: DMatrix<f64>,
}

/// The linearised closed loop of a multi-axis table (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TableLinearisation {
    free: Vec<Dof>,
    /// `A_q`, free × free.
    a_q: DMatrix<f64>,
    /// `A_v`, free × free.
    a_v: DMatrix<f64>,
    /// `B`, free × actuators.
    b: DMatrix<f64>,
    /// `G` (the strokes' derivatives), actuators × free.
    g: DMatrix<f64>,
    specimen: Option<SpecimenPart>,
    actuators: Vec<ActuatorLinearisation>,
    /// Per free DOF its gains.
    gains: Vec<Controller>,
    period_s: f64,
    /// `G_c`, actuators × free.
    g_c: DMatrix<f64>,
    /// `G_c⁺`, free × actuators.
    g_c_pinv: DMatrix<f64>,
    /// `G_c⁺·G`, free × free.
    feedback_geometry: DMatrix<f64>,
    /// `K_fb·(I − G_c·G_c⁺)`, actuators × actuators.
    balance: DMatrix<f64>,
    /// The platen's radius of gyration about x, y and z through its centre of mass, m (the
    /// weight of a rotation against a translation in a mode's shape).
    radius_of_gyration_m: [f64; 3],
}

/// One actuator's response at a frequency: the spool per drive and the force and `Δp` per
/// spool opening and per stroke.
#[derive(Debug, Clone, Copy)]
struct ActuatorResponse {
    valve: C64,
    force_per_spool: C64,
    force_per_stroke: C64,
    delta_p_per_spool: C64,
    delta_p_per_stroke: C64,
}

/// The largest cross-talk of one DOF's command ([`TableLinearisation::cross_talk`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrossTalk {
    /// The commanded DOF.
    pub command: Dof,
    /// Its own response, pose over command.
    pub diagonal: C64,
    /// The other DOF whose response to it is the largest in magnitude (SI units: m/rad and
    /// rad/m compared with m/m and rad/rad as numbers), and that response; `None` with one
    /// free DOF.
    pub largest: Option<(Dof, C64)>,
}

impl TableLinearisation {
    /// The linear model of `table` under `hydraulics` and `controller`, with `specimen` on the
    /// platen, about neutral at rest (see the module docs), with the mean flow gains
    /// ([`FlowGains::Mean`]).
    ///
    /// # Errors
    /// [`SystemError::Mismatch`] when the hydraulics or the controller's geometry do not have
    /// one entry per actuator, or the controller's free DOFs are not the table's;
    /// [`SystemError::Invalid`] when the actuators cannot hold the platen at neutral (as
    /// [`TableHydraulics::static_forces_n`]), or the platen's mass matrix is singular;
    /// [`SystemError::OfActuator`] when an actuator's static force needs chamber pressures
    /// outside the return and supply pressures.
    pub fn new(
        table: &MultiAxisTable,
        hydraulics: &TableHydraulics,
        controller: &DofController,
        specimen: Option<&LinearSpecimen>,
    ) -> Result<Self> {
        Self::with_flow_gains(table, hydraulics, controller, specimen, FlowGains::Mean)
    }

    /// As [`TableLinearisation::new`], the valves' flow gains taken as `gains` says.
    ///
    /// # Errors
    /// As [`TableLinearisation::new`].
    pub fn with_flow_gains(
        table: &MultiAxisTable,
        hydraulics: &TableHydraulics,
        controller: &DofController,
        specimen: Option<&LinearSpecimen>,
        gains: FlowGains,
    ) -> Result<Self> {
        let n = table.actuators().len();
        let free: Vec<Dof> = table.free().iter().collect();
        let geometry = controller.geometry();
        check_shapes(hydraulics, geometry, n, &free)?;
        let mut gravity = Wrench::zeros();
        gravity[2] = -platen_model::STANDARD_GRAVITY_M_S2;
        // A specimen at rest pushes on the platen with its weight.
        let push = specimen.map_or_else(Wrench::zeros, |s| s.rigid_mass() * gravity);
        let f0 = TableHydraulics::static_forces_n(table, &push)?;
        let mechanics = Mechanics::of(table, &free, &f0, &push)?;
        let specimen = specimen.map(|s| SpecimenPart::of(s, &free, &mechanics));
        let actuators = (0..n)
            .map(|i| actuator_linearisation(hydraulics, i, f0[i], gains))
            .collect::<Result<Vec<_>>>()?;
        let g_c = geometry.matrix().clone();
        let g_c_pinv = geometry.pseudo_inverse().clone();
        let balance =
            (DMatrix::identity(n, n) - &g_c * &g_c_pinv) * controller.force_balance_gain_per_n();
        Ok(TableLinearisation {
            radius_of_gyration_m: radius_of_gyration_m(table),
            gains: free.iter().map(|d| *controller.gains(*d)).collect(),
            period_s: controller.period_s(),
            feedback_geometry: &g_c_pinv * &mechanics.strokes,
            a_q: mechanics.per_pose,
            a_v: mechanics.per_rate,
            b: mechanics.per_force,
            g: mechanics.strokes,
            free,
            specimen,
            actuators,
            g_c,
            g_c_pinv,
            balance,
        })
    }

    /// The free DOFs, in the order of the matrices.
    pub fn free(&self) -> &[Dof] {
        &self.free
    }

    /// Per actuator its small-signal values.
    pub fn actuators(&self) -> &[ActuatorLinearisation] {
        &self.actuators
    }

    /// `A_q`: the platen's accelerations per unit of the pose at the static forces (free ×
    /// free, 1/s² and their mixed units).
    pub fn acceleration_per_pose(&self) -> &DMatrix<f64> {
        &self.a_q
    }

    /// `B`: the platen's accelerations per newton of each actuator's force (free ×
    /// actuators).
    pub fn acceleration_per_force(&self) -> &DMatrix<f64> {
        &self.b
    }

    /// `G`: the actuators' strokes per unit of the pose (actuators × free).
    pub fn strokes_per_pose(&self) -> &DMatrix<f64> {
        &self.g
    }

    /// The command → pose transfer matrix at `f_hz > 0`: `h[i][j]` is pose `i` over command
    /// `j` (x … yaw), the held DOFs' rows and columns zero. Not finite at `f_hz = 0`.
    pub fn transfer_matrix(&self, f_hz: f64) -> [[C64; 6]; 6] {
        let at = self.at(f_hz);
        let (t, rhs) = self.system(&at, None);
        let solution = t.lu().solve(&rhs);
        let mut out = [[C64::from(0.0); 6]; 6];
        for (r, a) in self.free.iter().enumerate() {
            for (c, b) in self.free.iter().enumerate() {
                out[a.index()][b.index()] = solution.as_ref().map_or(nan(), |x| x[(r, c)]);
            }
        }
        out
    }

    /// DOF `dof`'s own closed-loop response (pose over command) at `f_hz > 0`; `None` for a
    /// held DOF.
    pub fn response(&self, dof: Dof, f_hz: f64) -> Option<C64> {
        let k = self.free.iter().position(|&d| d == dof)?;
        Some(self.broken(k, f_hz).1)
    }

    /// The loop gain of DOF `dof` at `f_hz > 0`, broken at its DOF drive with every other
    /// loop and the force balance closed (see the module docs); `None` for a held DOF.
    pub fn loop_gain(&self, dof: Dof, f_hz: f64) -> Option<C64> {
        let k = self.free.iter().position(|&d| d == dof)?;
        Some(self.broken(k, f_hz).0)
    }

    /// The margins of DOF `dof`'s loop ([`TableLinearisation::loop_gain`]) by the uniaxial
    /// search ([`TableSystem::margins`](crate::TableSystem::margins)): from 0.001 Hz to the
    /// controller's Nyquist frequency, the peak of the DOF's own closed-loop response. Its
    /// `stable` is the Nyquist criterion with the unstable poles of the loop opened at `d_k`
    /// counted (the eigenvalues of [`TableLinearisation::state_matrix`] with that loop open:
    /// swivel-mounted verticals in compression are an inverted pendulum until the loops
    /// close), so that it agrees with [`TableLinearisation::stability`]. `None` for a held
    /// DOF.
    pub fn margins(&self, dof: Dof) -> Option<Margins> {
        let k = self.free.iter().position(|&d| d == dof)?;
        Some(search_margins(
            |f| {
                let (l, h) = self.broken(k, f);
                (l, h.norm())
            },
            0.5 / self.period_s,
            self.unstable_with_open(k),
        ))
    }

    /// Per free DOF's command at `f_hz > 0`, its own response and the largest response of
    /// another DOF to it.
    pub fn cross_talk(&self, f_hz: f64) -> Vec<CrossTalk> {
        let h = self.transfer_matrix(f_hz);
        self.free
            .iter()
            .map(|&command| {
                let j = command.index();
                let largest = self
                    .free
                    .iter()
                    .filter(|&&d| d != command)
                    .map(|&d| (d, h[d.index()][j]))
                    .fold(None, |best: Option<(Dof, C64)>, (d, x)| match best {
                        Some((_, b)) if b.norm() >= x.norm() => best,
                        _ => Some((d, x)),
                    });
                CrossTalk {
                    command,
                    diagonal: h[j][j],
                    largest,
                }
            })
            .collect()
    }

    /// Free DOF `k`'s loop broken at its drive at `f_hz`: `(L_k, H_kk)`. With a unit drive
    /// `d_k` injected (the command nowhere else), the unknowns are `x_v`, the controller's own
    /// `d_k` is `−F_k·x_v` so `L_k = F_k·x_v`, and closing the loop
    /// (`d_k = C_k·r_k − F_k·x`) scales `x_v` by `C_k·r_k/(1 + L_k)`.
    fn broken(&self, k: usize, f_hz: f64) -> (C64, C64) {
        let at = self.at(f_hz);
        let (t, rhs) = self.system(&at, Some(k));
        let Some(x) = t.lu().solve(&rhs) else {
            return (nan(), nan());
        };
        let l: C64 = (0..x.nrows())
            .map(|j| at.feedback[(k, j)] * x[(j, 0)])
            .sum();
        (l, x[(k, 0)] * at.command[k] / (1.0 + l))
    }

    /// What the system needs at `f_hz`.
    fn at(&self, f_hz: f64) -> AtFrequency {
        let s = C64::new(0.0, std::f64::consts::TAU * f_hz);
        let nf = self.free.len();
        let n = self.actuators.len();
        let nz = self.specimen.as_ref().map_or(0, |s| s.mass.nrows());
        let i_drive = nf + nz;
        let actuators: Vec<ActuatorResponse> =
            (0..n).map(|i| self.actuator_response(i, s)).collect();
        // The controller: d = C·r − F·x, x = [q, z, D], Δp = Ψ·W·D + M_S·G·q.
        let mut feedback = DMatrix::zeros(nf, nf + nz + n);
        let mut command = Vec::with_capacity(nf);
        for (k, gains) in self.gains.iter().enumerate() {
            let law = LawTerms::at(gains, s);
            command.push(law.error + law.feedforward);
            for c in 0..nf {
                let by_stroke: C64 = (0..n)
                    .map(|i| {
                        self.g_c_pinv[(k, i)] * actuators[i].delta_p_per_stroke * self.g[(i, c)]
                    })
                    .sum();
                feedback[(k, c)] = (law.error + law.velocity_feedback)
                    * self.feedback_geometry[(k, c)]
                    + law.delta_p * by_stroke;
            }
            feedback[(k, k)] += law.acceleration_feedback;
            for (i, a) in actuators.iter().enumerate() {
                feedback[(k, i_drive + i)] =
                    law.delta_p * self.g_c_pinv[(k, i)] * a.delta_p_per_spool * a.valve;
            }
        }
        AtFrequency {
            s,
            actuators,
            feedback,
            command,
        }
    }

    /// Actuator `i`'s response at `s`.
    fn actuator_response(&self, i: usize, s: C64) -> ActuatorResponse {
        let a = &self.actuators[i];
        let h = &a.hydraulics;
        let valve = &h.servo_valve;
        let valve_response =
            spool_response(valve, s) * (-s * valve.delay_s).exp() * hold_response(s, self.period_s);
        let cs = a.compliance_m3_per_pa * s + h.leakage_m3_s_per_pa;
        let cl = h.leakage_m3_s_per_pa;
        // (P_a, P_b) for the chambers' right-hand sides (r_a, r_b).
        let pressures = |r_a: C64, r_b: C64| -> (C64, C64) {
            if h.is_single_acting() {
                (r_a / cs, C64::from(0.0))
            } else {
                let det = cs * cs - cl * cl;
                ((cs * r_a + cl * r_b) / det, (cl * r_a + cs * r_b) / det)
            }
        };
        let force = |(p_a, p_b): (C64, C64)| h.cap_area_m2 * p_a - h.rod_area_m2 * p_b;
        let delta_p = |(p_a, p_b): (C64, C64)| p_a - p_b;
        let per_spool = pressures(
            C64::from(a.flow_gain_a_m3_s),
            C64::from(-a.flow_gain_b_m3_s),
        );
        let per_stroke = pressures(-h.cap_area_m2 * s, h.rod_area_m2 * s);
        ActuatorResponse {
            valve: valve_response,
            force_per_spool: force(per_spool),
            force_per_stroke: force(per_stroke),
            delta_p_per_spool: delta_p(per_spool),
            delta_p_per_stroke: delta_p(per_stroke),
        }
    }

    /// The system `T·x = R` at `at`, unknowns `x = [q, z, D]` (the DOF drives substituted):
    /// with every loop closed `R` has a column per free DOF's command; with the loop of
    /// `broken` open, its one column is a unit DOF drive `d_k` injected.
    fn system(&self, at: &AtFrequency, broken: Option<usize>) -> (DMatrix<C64>, DMatrix<C64>) {
        let s = at.s;
        let act = &at.actuators;
        let nf = self.free.len();
        let n = self.actuators.len();
        let nz = self.specimen.as_ref().map_or(0, |s| s.mass.nrows());
        let (iz, i_drive) = (nf, nf + nz);
        let size = nf + nz + n;
        let mut t = DMatrix::<C64>::zeros(size, size);
        let mut rhs = DMatrix::<C64>::zeros(size, if broken.is_some() { 1 } else { nf });
        let real = |x: f64| C64::from(x);
        // Mechanics: (s² − s·A_v − A_q)·q − B·f − P·Γᵀ·(C·s + K)·z = 0,
        // f = Φ·W·D + K_S·G·q.
        for r in 0..nf {
            for c in 0..nf {
                let by_stroke: C64 = (0..n)
                    .map(|i| self.b[(r, i)] * act[i].force_per_stroke * self.g[(i, c)])
                    .sum();
                t[(r, c)] = -s * self.a_v[(r, c)] - self.a_q[(r, c)] - by_stroke;
            }
            t[(r, r)] += s * s;
            for (i, a) in act.iter().enumerate() {
                t[(r, i_drive + i)] = -self.b[(r, i)] * a.force_per_spool * a.valve;
            }
        }
        if let Some(sp) = &self.specimen {
            let restoring = sp.damping.map(|x| x * s) + sp.stiffness.map(real);
            let on_platen = sp.push.map(real) * &restoring;
            for r in 0..nf {
                for j in 0..nz {
                    t[(r, iz + j)] = -on_platen[(r, j)];
                }
            }
            // Specimen: M·Γ_f·s²·q + (M·s² + C·s + K)·z = 0.
            for a in 0..nz {
                for c in 0..nf {
                    t[(iz + a, c)] = sp.mass_influence[(a, c)] * s * s;
                }
                for b in 0..nz {
                    t[(iz + a, iz + b)] = sp.mass[(a, b)] * s * s + restoring[(a, b)];
                }
            }
        }
        // Drives: D + K_fb·(I − G_c·G_c⁺)·f + Σ_k G_c,k·F_k·x = Σ_k G_c,k·C_k·r_k over the
        // closed loops, + G_c,k·d_k for the broken one.
        for i in 0..n {
            let row = i_drive + i;
            for (j, a) in act.iter().enumerate() {
                t[(row, i_drive + j)] = self.balance[(i, j)] * a.force_per_spool * a.valve;
            }
            t[(row, row)] += 1.0;
            for c in 0..nf {
                t[(row, c)] = (0..n)
                    .map(|j| self.balance[(i, j)] * act[j].force_per_stroke * self.g[(j, c)])
                    .sum();
            }
            for k in (0..nf).filter(|&k| Some(k) != broken) {
                let g = self.g_c[(i, k)];
                for c in 0..size {
                    t[(row, c)] += g * at.feedback[(k, c)];
                }
                if broken.is_none() {
                    rhs[(row, k)] = g * at.command[k];
                }
            }
            if let Some(k) = broken {
                rhs[(row, 0)] = real(self.g_c[(i, k)]);
            }
        }
        (t, rhs)
    }
}

/// The frequency-dependent parts of the system at one frequency.
struct AtFrequency {
    s: C64,
    actuators: Vec<ActuatorResponse>,
    /// `F`: the controller's feedback on the unknowns `[q, z, D]`, free × unknowns.
    feedback: DMatrix<C64>,
    /// `C_k = K_p + K_i/s + K_vf·s + K_af·s²` per free DOF: its drive per command.
    command: Vec<C64>,
}

/// Checks that the hydraulics and the controller's geometry have one entry per actuator of
/// the table (`n`), and the geometry the table's `free` DOFs.
fn check_shapes(
    hydraulics: &TableHydraulics,
    geometry: &DofGeometry,
    n: usize,
    free: &[Dof],
) -> Result<()> {
    for (what, found) in [
        (
            "actuators of the hydraulics and the table",
            hydraulics.actuators().len(),
        ),
        (
            "actuators of the controller's geometry and the table",
            geometry.actuators(),
        ),
    ] {
        if found != n {
            return Err(SystemError::Mismatch {
                what,
                found: found.to_string(),
                expected: n.to_string(),
            });
        }
    }
    if geometry.free() != free {
        let names = |d: &[Dof]| d.iter().map(|d| d.name()).collect::<Vec<_>>().join(" ");
        return Err(SystemError::Mismatch {
            what: "free DOFs of the controller and the table",
            found: names(geometry.free()),
            expected: names(free),
        });
    }
    Ok(())
}

/// The platen's radius of gyration about x, y and z through its centre of mass, m (at least
/// 1 mm).
fn radius_of_gyration_m(table: &MultiAxisTable) -> [f64; 3] {
    let platen = table.platen();
    [0, 1, 2].map(|k| {
        (platen.inertia_kg_m2()[(k, k)] / platen.mass_kg())
            .sqrt()
            .max(1e-3)
    })
}

impl SpecimenPart {
    /// Specimen `s`'s matrices, its influence taken over the `free` DOFs and its push on the
    /// platen through `mechanics`.
    fn of(s: &LinearSpecimen, free: &[Dof], mechanics: &Mechanics) -> Self {
        let influence = DMatrix::from_fn(s.len(), free.len(), |a, c| {
            s.influence()[(a, free[c].index())]
        });
        SpecimenPart {
            mass: s.mass().clone(),
            stiffness: s.stiffness().clone(),
            damping: s.damping().clone(),
            mass_influence: s.mass() * influence,
            push: &mechanics.per_wrench * s.influence().transpose(),
        }
    }
}

/// The mechanics linearised at neutral (see the module docs).
struct Mechanics {
    per_pose: DMatrix<f64>,
    per_rate: DMatrix<f64>,
    per_force: DMatrix<f64>,
    /// The accelerations per unit wrench about the reference point, free × 6.
    per_wrench: DMatrix<f64>,
    strokes: DMatrix<f64>,
}

impl Mechanics {
    /// Central differences of the accelerations about `(0, 0, f0)` with the specimen's push
    /// `push`, and of the strokes about neutral.
    fn of(table: &MultiAxisTable, free: &[Dof], f0: &[f64], push: &Wrench) -> Result<Self> {
        let (nf, n) = (free.len(), f0.len());
        let singular = || {
            invalid(
                "platen.inertia_kg_m2",
                table.platen().mass_kg(),
                "a platen whose mass matrix is positive definite at neutral",
            )
        };
        let acc = |q: &Coords, qd: &Coords, f: &[f64], w: &Wrench| -> Result<Coords> {
            let mut applied = table.struts_wrench(q) + w;
            for (i, fi) in f.iter().enumerate() {
                applied += table.actuator_at(i, q).unit_wrench * *fi;
            }
            table.accelerations(q, qd, &applied).ok_or_else(singular)
        };
        let zero = Coords::zeros();
        let along = |k: usize, h: f64| {
            let mut x = Coords::zeros();
            x[free[k].index()] = h;
            x
        };
        let mut per_pose = DMatrix::zeros(nf, nf);
        let mut per_rate = DMatrix::zeros(nf, nf);
        let mut strokes = DMatrix::zeros(n, nf);
        for k in 0..nf {
            let (up, down) = (along(k, POSE_STEP), along(k, -POSE_STEP));
            let dq =
                (acc(&up, &zero, f0, push)? - acc(&down, &zero, f0, push)?) / (2.0 * POSE_STEP);
            let dv =
                (acc(&zero, &up, f0, push)? - acc(&zero, &down, f0, push)?) / (2.0 * POSE_STEP);
            for (r, d) in free.iter().enumerate() {
                per_pose[(r, k)] = dq[d.index()];
                per_rate[(r, k)] = dv[d.index()];
            }
            // The stroke rates are linear in the pose's rates: exact, no difference needed.
            let unit = along(k, 1.0);
            for i in 0..n {
                strokes[(i, k)] = table.stroke_rate_m_s(i, &zero, &unit);
            }
        }
        let mut per_force = DMatrix::zeros(nf, n);
        let mut f = f0.to_vec();
        for i in 0..n {
            f[i] = f0[i] + FORCE_STEP_N;
            let up = acc(&zero, &zero, &f, push)?;
            f[i] = f0[i] - FORCE_STEP_N;
            let down = acc(&zero, &zero, &f, push)?;
            f[i] = f0[i];
            for (r, d) in free.iter().enumerate() {
                per_force[(r, i)] = (up[d.index()] - down[d.index()]) / (2.0 * FORCE_STEP_N);
            }
        }
        let mut per_wrench = DMatrix::zeros(nf, 6);
        for j in 0..6 {
            let mut w = Wrench::zeros();
            w[j] = FORCE_STEP_N;
            let up = acc(&zero, &zero, f0, &(push + w))?;
            let down = acc(&zero, &zero, f0, &(push - w))?;
            for (r, d) in free.iter().enumerate() {
                per_wrench[(r, j)] = (up[d.index()] - down[d.index()]) / (2.0 * FORCE_STEP_N);
            }
        }
        Ok(Mechanics {
            per_pose,
            per_rate,
            per_force,
            per_wrench,
            strokes,
        })
    }
}

/// Actuator `i`'s small-signal values when it exerts `force_n` at rest, its flow gains
/// taken as `gains` says.
fn actuator_linearisation(
    hydraulics: &TableHydraulics,
    i: usize,
    force_n: f64,
    gains: FlowGains,
) -> Result<ActuatorLinearisation> {
    let h = hydraulics.actuators()[i];
    let (p_a0, p_b0) = hydraulics.null_pressures_pa(i, force_n)?;
    let (ps, pr) = (
        hydraulics.supply_pressure_pa(),
        hydraulics.return_pressure_pa(),
    );
    let c = HydraulicConstants::of_valve(&h.servo_valve);
    let k = c.land_coefficient;
    // Each land's gain opening (x > 0) and closing (x < 0): chamber a fills from supply or
    // drains to return; chamber b the other way round.
    let (open_a, close_a) = (k * root(ps - p_a0, &c), k * root(p_a0 - pr, &c));
    let (open_b, close_b) = (k * root(p_b0 - pr, &c), k * root(ps - p_b0, &c));
    let single = h.is_single_acting();
    // The leakage out of chamber a at the null pressures, which the valve makes up at rest.
    let leak = h.leakage_m3_s_per_pa * if single { p_a0 - pr } else { p_a0 - p_b0 };
    let mean = (0.5 * (open_a + close_a), 0.5 * (open_b + close_b));
    let ((gain_a, gain_b), rest) = match gains {
        FlowGains::AtRest if leak > 0.0 => ((open_a, open_b), leak / open_a),
        FlowGains::AtRest if leak < 0.0 => ((close_a, close_b), leak / close_a),
        _ => (mean, 0.0),
    };
    Ok(ActuatorLinearisation {
        static_force_n: force_n,
        null_pressure_a_pa: p_a0,
        null_pressure_b_pa: p_b0,
        flow_gain_a_m3_s: gain_a,
        flow_gain_b_m3_s: if single { 0.0 } else { gain_b },
        rest_opening: rest,
        compliance_m3_per_pa: h.chamber_volume_m3 / hydraulics.oil_bulk_modulus_pa(),
        hydraulics: h,
    })
}

fn nan() -> C64 {
    C64::new(f64::NAN, f64::NAN)
}
