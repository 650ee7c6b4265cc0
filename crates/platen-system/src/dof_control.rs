//! DOF control of a multi-axis table, as the MTS 469D and its peers do it: actuator
//! feedbacks → DOF feedbacks through the geometry, the three-variable law per DOF, DOF drives →
//! actuator drives through the geometry, and a force balance on the redundant actuators.
//!
//! # Geometry
//!
//! `G` (actuators × free DOFs) is the strokes' derivative with respect to the pose at neutral:
//! row `i` is actuator `i`'s unit wrench as a generalised force
//! ([`MultiAxisTable::generalised_force`]), so that `δs = G·δq`, and by virtual work the
//! actuator forces `f` exert the generalised force `Gᵀ·f`. The controller uses this constant
//! matrix (the geometry transform of a real controller is calibrated at neutral, not
//! recomputed from the pose):
//!
//! * DOF feedback: `q̂ = G⁺·s`, `q̂̇ = G⁺·ṡ` (least squares, `G⁺` the pseudo-inverse), and
//!   `Δp̂ = G⁺·Δp` per DOF; the acceleration feedback is the platen's own (accelerometers).
//! * DOF drive: per free DOF `k` the law of [`Controller`] with its own gains (for a rotation
//!   the same keys are per rad), saturated at `±1`.
//! * Actuator drives: `D = G·d − K_fb·(I − G·G⁺)·f`, each saturated at `±1`. `I − G·G⁺` is
//!   the projector on the null space of `Gᵀ`: the force combinations that move nothing and
//!   only warp the platen. The force balance drives them to zero at its gain `K_fb` (drive per
//!   N). The forces that hold the platen at rest are the minimum-norm resolution, which has no
//!   null-space part, so the balance leaves them alone.
//!
//! With one DOF free and two identical actuators along it, `G = [1, 1]ᵀ`: the DOF feedback is
//! the mean of the two strokes, both actuators get the DOF's drive, and the balance sees
//! their force difference: the uniaxial loop of [`crate::TableSystem`] with two actuators.

use nalgebra::DMatrix;
use platen_model::multi_axis::{Coords, Dof, MultiAxisTable};

use crate::controller::{ControllerInput, ControllerState};
use crate::error::{invalid, non_negative, Result, SystemError};
use crate::params::Controller;

/// The constant geometry transforms of a DOF controller.
#[derive(Debug, Clone, PartialEq)]
pub struct DofGeometry {
    /// The free DOFs, in order.
    free: Vec<Dof>,
    /// `G`, actuators × free DOFs.
    g: DMatrix<f64>,
    /// `G⁺`, free DOFs × actuators.
    pinv: DMatrix<f64>,
    /// `I − G·G⁺`, actuators × actuators.
    warp: DMatrix<f64>,
}

impl DofGeometry {
    /// The geometry of `table` at neutral.
    ///
    /// # Errors
    /// As [`DofGeometry::from_matrix`].
    pub fn of_table(table: &MultiAxisTable) -> Result<Self> {
        let neutral = Coords::zeros();
        let free: Vec<Dof> = table.free().iter().collect();
        let n = table.actuators().len();
        let g = DMatrix::from_fn(n, free.len(), |i, k| {
            let w = table.actuator_at(i, &neutral).unit_wrench;
            table.generalised_force(&neutral, &w)[free[k].index()]
        });
        Self::from_matrix(free, g)
    }

    /// The geometry of the matrix `g` (actuators × the DOFs `free`, strokes per unit of each
    /// DOF): for a controller calibrated on a geometry that differs from the table's.
    ///
    /// # Errors
    /// [`SystemError::Invalid`] (`actuators`) when `g` is not finite, its shape does not
    /// match `free`, or it does not have full column rank (a free DOF nothing moves).
    pub fn from_matrix(free: Vec<Dof>, g: DMatrix<f64>) -> Result<Self> {
        let rank_deficient = || {
            invalid(
                "actuators",
                g.nrows() as f64,
                "actuators whose lines move every free DOF independently at neutral",
            )
        };
        if g.ncols() != free.len() || g.nrows() < free.len() || g.iter().any(|x| !x.is_finite()) {
            return Err(rank_deficient());
        }
        let svd = g.clone().svd(true, true);
        let top = svd.singular_values.max();
        if free.is_empty() || svd.singular_values.min() <= 1e-12 * top {
            return Err(rank_deficient());
        }
        let pinv = svd.pseudo_inverse(0.0).map_err(|_| rank_deficient())?;
        let warp = DMatrix::identity(g.nrows(), g.nrows()) - &g * &pinv;
        Ok(DofGeometry {
            free,
            g,
            pinv,
            warp,
        })
    }

    /// The free DOFs, in the order of `G`'s columns.
    pub fn free(&self) -> &[Dof] {
        &self.free
    }

    /// `G`, actuators × free DOFs.
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.g
    }

    /// `G⁺`, free DOFs × actuators.
    pub fn pseudo_inverse(&self) -> &DMatrix<f64> {
        &self.pinv
    }

    /// Number of actuators.
    pub fn actuators(&self) -> usize {
        self.g.nrows()
    }

    /// The DOF values `G⁺·x` of per-actuator values `x`, as six coordinates (held DOFs 0).
    pub fn to_dofs(&self, x: &[f64]) -> Coords {
        let mut out = Coords::zeros();
        for (r, d) in self.free.iter().enumerate() {
            out[d.index()] = (0..x.len()).map(|i| self.pinv[(r, i)] * x[i]).sum();
        }
        out
    }

    /// The warping part `(I − G·G⁺)·f` of the actuator forces `f`, written into `out`.
    pub fn warping(&self, f: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = (0..f.len()).map(|j| self.warp[(i, j)] * f[j]).sum();
        }
    }

    /// The norm of the warping part of `f`, N.
    pub fn warping_norm_n(&self, f: &[f64]) -> f64 {
        let mut w = vec![0.0; f.len()];
        self.warping(f, &mut w);
        w.iter().map(|x| x * x).sum::<f64>().sqrt()
    }
}

/// A multi-axis table's DOF controller.
#[derive(Debug, Clone, PartialEq)]
pub struct DofController {
    /// Sample rate, Hz (every DOF's loop runs at it).
    sample_rate_hz: f64,
    /// Per DOF (x … yaw), its gains ([`Controller`] with the common sample rate).
    loops: [Controller; 6],
    /// `K_fb`, drive per N of warping force.
    force_balance_gain_per_n: f64,
    geometry: DofGeometry,
}

/// The command of a DOF controller at a sample: per DOF (x … yaw) its value, rate and
/// second derivative (m or rad and their rates).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DofCommand {
    /// Pose.
    pub pose: Coords,
    /// Its rates.
    pub rates: Coords,
    /// Its second derivatives.
    pub accelerations: Coords,
}

/// What a DOF controller reads of the table at a sample.
#[derive(Debug, Clone, Copy)]
pub struct DofFeedback<'a> {
    /// Actuator strokes, m.
    pub strokes_m: &'a [f64],
    /// Their rates, m/s.
    pub stroke_rates_m_s: &'a [f64],
    /// The platen's accelerations (x … yaw, m/s² or rad/s²).
    pub accelerations: Coords,
    /// Per actuator the `Δp` its feedback reads, Pa.
    pub delta_p_pa: &'a [f64],
    /// Per actuator its force, N.
    pub forces_n: &'a [f64],
}

/// A DOF controller's memory between samples and its last output.
#[derive(Debug, Clone, PartialEq)]
pub struct DofControllerState {
    loops: [ControllerState; 6],
    /// The actuator drives held since the last sample (`|d| ≤ 1`).
    pub drives: Vec<f64>,
    /// The DOF drives of the last sample (held DOFs 0).
    pub dof_drives: Coords,
    /// Whether a DOF drive or an actuator drive was saturated at the last sample.
    pub saturated: bool,
    /// The norm of the warping forces at the last sample, N.
    pub warping_n: f64,
    /// Scratch: the warping forces.
    warp: Vec<f64>,
}

impl DofController {
    /// A controller at `sample_rate_hz` with the gains `loops` per DOF (x … yaw; their own
    /// sample rates are replaced by the common one), force-balance gain
    /// `force_balance_gain_per_n`, on `geometry`.
    ///
    /// # Errors
    /// [`SystemError::OfDof`] for a DOF's bad gain, [`SystemError::Invalid`]
    /// (`controller.force_balance_gain`) for a balance gain that is negative or not finite.
    pub fn new(
        sample_rate_hz: f64,
        mut loops: [Controller; 6],
        force_balance_gain_per_n: f64,
        geometry: DofGeometry,
    ) -> Result<Self> {
        for (d, c) in Dof::ALL.iter().zip(loops.iter_mut()) {
            c.sample_rate_hz = sample_rate_hz;
            c.validate().map_err(|e| SystemError::OfDof {
                dof: d.name(),
                source: Box::new(e),
            })?;
        }
        non_negative("controller.force_balance_gain", force_balance_gain_per_n)?;
        Ok(DofController {
            sample_rate_hz,
            loops,
            force_balance_gain_per_n,
            geometry,
        })
    }

    /// The sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    /// The sample period, s.
    pub fn period_s(&self) -> f64 {
        1.0 / self.sample_rate_hz
    }

    /// The gains of DOF `dof`.
    pub fn gains(&self, dof: Dof) -> &Controller {
        &self.loops[dof.index()]
    }

    /// The force-balance gain, drive per N.
    pub fn force_balance_gain_per_n(&self) -> f64 {
        self.force_balance_gain_per_n
    }

    /// The geometry transforms.
    pub fn geometry(&self) -> &DofGeometry {
        &self.geometry
    }

    /// The state before the first sample: every drive 0.
    pub fn start(&self) -> DofControllerState {
        let n = self.geometry.actuators();
        DofControllerState {
            loops: [ControllerState::default(); 6],
            drives: vec![0.0; n],
            dof_drives: Coords::zeros(),
            saturated: false,
            warping_n: 0.0,
            warp: vec![0.0; n],
        }
    }

    /// One sample: the new actuator drives into `state.drives` from the command and the
    /// feedback (see the module docs).
    pub fn update(&self, state: &mut DofControllerState, command: &DofCommand, fb: &DofFeedback) {
        let geo = &self.geometry;
        let q = geo.to_dofs(fb.strokes_m);
        let qd = geo.to_dofs(fb.stroke_rates_m_s);
        let dp = geo.to_dofs(fb.delta_p_pa);
        let mut d = Coords::zeros();
        let mut saturated = false;
        for dof in &geo.free {
            let k = dof.index();
            let input = ControllerInput {
                command_u_m: command.pose[k],
                command_v_m_s: command.rates[k],
                command_a_m_s2: command.accelerations[k],
                u_m: q[k],
                v_m_s: qd[k],
                a_m_s2: fb.accelerations[k],
                delta_p_pa: dp[k],
            };
            d[k] = self.loops[k].update(&mut state.loops[k], &input);
            saturated |= state.loops[k].saturated;
        }
        geo.warping(fb.forces_n, &mut state.warp);
        state.warping_n = state.warp.iter().map(|x| x * x).sum::<f64>().sqrt();
        for (i, drive) in state.drives.iter_mut().enumerate() {
            let along: f64 = geo
                .free
                .iter()
                .enumerate()
                .map(|(r, dof)| geo.g[(i, r)] * d[dof.index()])
                .sum();
            let raw = along - self.force_balance_gain_per_n * state.warp[i];
            saturated |= raw.abs() > 1.0;
            *drive = raw.clamp(-1.0, 1.0);
        }
        state.dof_drives = d;
        state.saturated = saturated;
    }
}

/// Every DOF's gains at zero at `sample_rate_hz` (a DOF left open).
pub fn open_loop(sample_rate_hz: f64) -> Controller {
    Controller {
        sample_rate_hz,
        displacement_gain_per_m: 0.0,
        integral_gain_per_m_s: 0.0,
        velocity_feedforward_s_per_m: 0.0,
        acceleration_feedforward_s2_per_m: 0.0,
        velocity_feedback_s_per_m: 0.0,
        acceleration_feedback_s2_per_m: 0.0,
        delta_p_gain_per_pa: 0.0,
        delta_p_highpass_hz: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_actuators_along_x_read_their_mean_and_balance_their_difference() {
        let geo = DofGeometry::from_matrix(vec![Dof::X], DMatrix::from_element(2, 1, 1.0))
            .expect("full rank");
        let q = geo.to_dofs(&[0.1, 0.3]);
        assert!((q[0] - 0.2).abs() < 1e-15);
        assert!((geo.warping_norm_n(&[5.0, 3.0]) - 2f64.sqrt()).abs() < 1e-12);
        assert!(geo.warping_norm_n(&[4.0, 4.0]) < 1e-12);
    }

    #[test]
    fn a_free_dof_nothing_moves_is_refused() {
        let g = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 1.0, 0.0]);
        assert!(DofGeometry::from_matrix(vec![Dof::X, Dof::Y], g).is_err());
    }
}
