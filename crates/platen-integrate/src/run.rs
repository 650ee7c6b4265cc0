//! What every forward run shares, whatever its integrator: the [`State`] it starts from, the
//! [`RunStats`] and [`EnergyBalance`] it returns, the checks it makes before it starts, and
//! the output [`Sample`] it delivers from an integrated state.

use platen_model::{ForceTerms, PlatenModel};

use crate::error::{IntegrateError, Result};
use crate::event::EventKind;
use crate::output::Sample;
use crate::record::ForceRecord;
use crate::stop::StopReason;

/// The state of the platen.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct State {
    /// Displacement, m.
    pub u_m: f64,
    /// Velocity, m/s.
    pub v_m_s: f64,
}

/// Counters of a forward run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunStats {
    /// Integration steps attempted: grid steps of length `h` for the RK4, accepted plus
    /// rejected steps for Dopri5 (root-finding trials are counted in `root_iterations`).
    pub steps: u64,
    /// Evaluations of the right-hand side.
    pub rhs_evaluations: u64,
    /// Slip → stick transitions (the platen came to rest and friction held it).
    pub stick_events: u64,
    /// Stick → slip transitions (breakaways).
    pub breakaways: u64,
    /// Direct reversals (velocity crossed zero and the net force exceeded the threshold).
    pub reversals: u64,
    /// Iterations spent locating `v = 0` crossings.
    pub root_iterations: u64,
    /// Total time spent stuck, s.
    pub stick_time_s: f64,
    /// Accepted steps of an adaptive integrator (equal to `steps` for the fixed-step RK4).
    pub accepted_steps: u64,
    /// Rejected steps of an adaptive integrator (0 for the fixed-step RK4).
    pub rejected_steps: u64,
    /// The energy balance of the run.
    pub energy: EnergyBalance,
    /// Why the run stopped: [`StopReason::Finished`] with the time of the last sample for a
    /// run that returns its statistics (a failure returns an [`IntegrateError`] instead, whose
    /// [`IntegrateError::stop_reason`] says when and why).
    pub stop: StopReason,
}

/// Energy balance of a forward run: the work done by the actuator equals the change of
/// kinetic and elastic energy plus the energy dissipated. The work and the dissipated energy
/// are integrated by the same stages as the motion, so the residual measures the integration
/// error (it is not forced to zero by construction).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyBalance {
    /// Work done by the actuator force, `∫F_A·v dt`, J.
    pub actuator_work_j: f64,
    /// Kinetic energy at the start, J.
    pub kinetic_start_j: f64,
    /// Kinetic energy at the end, `½M(u)v²`, J.
    pub kinetic_end_j: f64,
    /// Elastic energy at the start, J.
    pub elastic_start_j: f64,
    /// Elastic energy at the end, J.
    pub elastic_end_j: f64,
    /// Energy dissipated, `∫D·|v| dt`, J.
    pub dissipated_j: f64,
    /// Energy of the specimen at the start, `½Σmᵢ(v + żᵢ)² + ½Σkᵢdᵢ²`, J (0 without one).
    pub specimen_start_j: f64,
    /// Energy of the specimen at the end, J (0 without one).
    pub specimen_end_j: f64,
    /// Energy dissipated by the specimen's storey dampers, `∫Σcᵢḋᵢ² dt`, J (0 without one).
    pub specimen_dissipated_j: f64,
}

impl EnergyBalance {
    /// The balance of a run that starts at `(u, v)`: nothing done yet.
    pub(crate) fn start<M: PlatenModel>(model: &M, u: f64, v: f64) -> Self {
        let kinetic = model.kinetic_energy_j(u, v);
        let elastic = model.elastic_energy_j(u);
        Self {
            kinetic_start_j: kinetic,
            kinetic_end_j: kinetic,
            elastic_start_j: elastic,
            elastic_end_j: elastic,
            ..Self::default()
        }
    }

    /// Closes the balance at the end state `(u, v)` with the integrated work and dissipated
    /// energy, J.
    pub(crate) fn close<M: PlatenModel>(
        &mut self,
        model: &M,
        u: f64,
        v: f64,
        work: f64,
        dissipated: f64,
    ) {
        self.actuator_work_j = work;
        self.dissipated_j = dissipated;
        self.kinetic_end_j = model.kinetic_energy_j(u, v);
        self.elastic_end_j = model.elastic_energy_j(u);
    }

    /// `W − ΔE_kin − ΔE_el − E_diss − ΔE_specimen − E_specimen,diss`, J: zero for an exact
    /// solution (the specimen's terms are zero without one).
    pub fn residual_j(&self) -> f64 {
        self.actuator_work_j
            - (self.kinetic_end_j - self.kinetic_start_j)
            - (self.elastic_end_j - self.elastic_start_j)
            - self.dissipated_j
            - (self.specimen_end_j - self.specimen_start_j)
            - self.specimen_dissipated_j
    }

    /// The residual relative to the largest energy flow of the run (actuator work, dissipated
    /// energy, or the energy at the start), or 0 for a run in which nothing moved.
    pub fn relative_residual(&self) -> f64 {
        let scale = self
            .actuator_work_j
            .abs()
            .max(self.dissipated_j)
            .max(self.kinetic_start_j + self.elastic_start_j + self.specimen_start_j);
        if scale > 0.0 {
            self.residual_j() / scale
        } else {
            0.0
        }
    }
}

impl RunStats {
    /// All located events: stops, breakaways and reversals.
    pub fn events(&self) -> u64 {
        self.stick_events + self.breakaways + self.reversals
    }

    /// Counts one located event of kind `kind`.
    #[inline]
    pub(crate) fn record(&mut self, kind: EventKind) {
        match kind {
            EventKind::Stop => self.stick_events += 1,
            EventKind::Reversal => self.reversals += 1,
            EventKind::Breakaway => self.breakaways += 1,
        }
    }
}

/// The integrated state of a slipping platen: displacement, velocity, and the two energy
/// integrals carried along with them (same RK4 stages, so the energy balance measures the
/// integration error).
///
/// RK4 steps it as it is; Dopri5 carries the two integrals scaled (see `dopri5.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Kin {
    /// Displacement, m.
    pub u: f64,
    /// Velocity, m/s.
    pub v: f64,
    /// Work done by the actuator force, `∫F_A·v dt`, J.
    pub work: f64,
    /// Energy dissipated, `∫D·|v| dt`, J.
    pub dissipated: f64,
}

impl Kin {
    /// The state at the start of a run: `initial`, nothing integrated yet.
    pub(crate) fn start(initial: State) -> Self {
        Self {
            u: initial.u_m,
            v: initial.v_m_s,
            work: 0.0,
            dissipated: 0.0,
        }
    }
}

/// The checks every forward run makes before it starts: the record holds the samples asked
/// for, and the initial state is finite.
pub(crate) fn check_run(record: &ForceRecord, initial: State, samples: usize) -> Result<()> {
    if samples > record.len() {
        return Err(IntegrateError::RecordTooShort {
            requested: samples,
            available: record.len(),
        });
    }
    if !(initial.u_m.is_finite() && initial.v_m_s.is_finite()) {
        return Err(IntegrateError::InvalidInitialState {
            u_m: initial.u_m,
            v_m_s: initial.v_m_s,
        });
    }
    Ok(())
}

/// An output sample from a state; F_D is the remainder of Eq. 1: the dissipative force in slip
/// (to rounding), the static friction reaction in stick.
#[inline]
pub(crate) fn sample_at<M: PlatenModel>(
    model: &M,
    index: usize,
    t_s: f64,
    f: f64,
    y: Kin,
    a: f64,
    stuck: bool,
) -> Sample {
    let inertial_n = model.mass_kg(y.u) * a + model.velocity_inertial_force_n(y.u, y.v);
    let elastic_n = model.elastic_force_n(y.u);
    Sample {
        index,
        t_s,
        u_m: y.u,
        v_m_s: y.v,
        a_m_s2: a,
        terms: ForceTerms {
            inertial_n,
            elastic_n,
            dissipative_n: f - inertial_n - elastic_n,
            actuator_n: f,
        },
        stuck,
        specimen: None,
        system: None,
    }
}
