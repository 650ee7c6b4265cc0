//! Why a forward run stopped: it finished, or a numerical failure stopped it at a time, for a
//! typed cause.
//!
//! A run that finishes returns its [`crate::RunStats`], whose `stop` is
//! [`StopReason::Finished`]; a run that fails returns an [`crate::IntegrateError`] whose
//! [`stop_reason`](crate::IntegrateError::stop_reason) is [`StopReason::Failed`].

use std::fmt;

/// Why a forward run stopped.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StopReason {
    /// Every sample asked for was delivered.
    Finished {
        /// Time of the last sample delivered (the record's first time if none was), s.
        t_s: f64,
    },
    /// A numerical failure stopped the run; the samples before `t_s` were delivered.
    Failed {
        /// Time of the failure, s.
        t_s: f64,
        /// What failed.
        cause: Failure,
    },
}

impl Default for StopReason {
    /// `Finished` at `t = 0 s`.
    fn default() -> Self {
        StopReason::Finished { t_s: 0.0 }
    }
}

/// The cause of a numerical failure during a run.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Failure {
    /// The state became NaN or infinite.
    NonFiniteState {
        /// Displacement, m.
        u_m: f64,
        /// Velocity, m/s.
        v_m_s: f64,
    },
    /// A multi-axis table's state became NaN or infinite.
    TableNonFiniteState {
        /// The pose the failing step started from: x, y, z (m), roll, pitch, yaw (rad).
        pose: [f64; 6],
    },
    /// The stick-slip event loop stopped advancing inside one step.
    EventLoopStalled {
        /// Events handled inside the step.
        events: u32,
    },
    /// The adaptive integrator (Dopri5) gave up.
    AdaptiveFailed(AdaptiveFailure),
    /// A closed-loop run drove the platen to the end of its actuators: a chamber's volume
    /// (lines included) is gone. Not a numerical failure: the command asks for more stroke
    /// than the actuators have.
    EndStop {
        /// Displacement, m.
        u_m: f64,
    },
}

/// Why the adaptive Dopri5 gave up.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AdaptiveFailure {
    /// More steps were needed than the integrator allows in one call.
    TooManySteps {
        /// The step budget of one call.
        steps: u32,
    },
    /// The step size fell below what the time resolution allows.
    StepSizeUnderflow,
    /// A stiffness detection fired (kept for matching; this crate's Dopri5 has none and
    /// never reports it).
    StiffnessDetected,
}

impl fmt::Display for AdaptiveFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AdaptiveFailure::TooManySteps { steps } => write!(f, "more than {steps} steps needed"),
            AdaptiveFailure::StepSizeUnderflow => f.write_str("step size underflow"),
            AdaptiveFailure::StiffnessDetected => f.write_str("stiffness detected"),
        }
    }
}
