//! Errors of the integrators.

use platen_signal::SignalError;

use crate::stop::{AdaptiveFailure, Failure, StopReason};

/// Why a run could not be set up or did not finish.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegrateError {
    /// The columns of a record do not have the same length.
    #[error("record columns differ in length: {what} has {found} values, expected {expected}")]
    LengthMismatch {
        /// Which column.
        what: &'static str,
        /// Its length.
        found: usize,
        /// The length of the time column.
        expected: usize,
    },
    /// A record has too few samples.
    #[error("record has {found} samples; at least {needed} are needed")]
    TooShort {
        /// Samples present.
        found: usize,
        /// Samples needed.
        needed: usize,
    },
    /// A value in a record is NaN or infinite.
    #[error("{what}[{index}] = {value} is not finite")]
    NonFiniteInput {
        /// Which column.
        what: &'static str,
        /// Zero-based sample index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// Time does not increase strictly.
    #[error("time is not strictly increasing at sample {index}: {previous_s} s then {value_s} s")]
    TimeNotIncreasing {
        /// Zero-based sample index.
        index: usize,
        /// The previous time, s.
        previous_s: f64,
        /// The offending time, s.
        value_s: f64,
    },
    /// A record is not uniformly sampled: one interval (a dropped sample, a jump) differs
    /// from the typical one by more than twice [`crate::UNIFORM_RELATIVE_TOLERANCE`].
    #[error(
        "record is not uniformly sampled: the interval before sample {index} is {found_s} s, \
         expected {expected_s} s (within 20 %: a gap or a jump in time)"
    )]
    NonUniform {
        /// Zero-based sample index.
        index: usize,
        /// The typical (median) interval, s.
        expected_s: f64,
        /// The offending interval, s.
        found_s: f64,
    },
    /// A time stamp is further from the record's fitted sampling grid than
    /// [`crate::UNIFORM_RELATIVE_TOLERANCE`] of the interval (jitter, or a change of rate).
    #[error(
        "record is not uniformly sampled: sample {index} is stamped {found_s} s, but the grid \
         fitted over the record puts it at {grid_s} s (interval {interval_s} s; stamps may be off \
         it by up to 10 % of the interval)"
    )]
    OffGrid {
        /// Zero-based sample index.
        index: usize,
        /// Where the fitted grid puts the sample, s.
        grid_s: f64,
        /// Its stamp, s.
        found_s: f64,
        /// The fitted interval, s.
        interval_s: f64,
    },
    /// The actuators of a multi-axis table cannot hold its free DOFs at the pose of a
    /// sample (their geometry loses rank there).
    #[error("at t = {t_s} s the actuators cannot hold the platen's free DOFs (their geometry loses rank at that pose)")]
    Unresolvable {
        /// The sample's time, s.
        t_s: f64,
    },
    /// The integration step does not divide the sample interval.
    #[error(
        "step_s = {step_s} s does not divide the sample interval {sample_interval_s} s into a \
         whole number of steps (use sample_interval / k for an integer k >= 1)"
    )]
    StepNotDivisor {
        /// The requested step, s.
        step_s: f64,
        /// The record's sample interval, s.
        sample_interval_s: f64,
    },
    /// A velocity dead band ([`crate::Motion::with_rest_velocity`]) that is not a finite
    /// positive number.
    #[error("rest_velocity_m_s = {value} is invalid: expected a finite velocity > 0 m/s")]
    InvalidRestVelocity {
        /// The value given, m/s.
        value: f64,
    },
    /// A step size that is not a finite positive number.
    #[error("step_s = {step_s} is invalid: expected a finite number > 0")]
    InvalidStep {
        /// The requested step, s.
        step_s: f64,
    },
    /// A table system that cannot run: the static forces outside what its chambers exert,
    /// or a controller geometry that does not move every free DOF.
    #[error("the table's hydraulics cannot hold it at rest: {0}")]
    InvalidSystem(platen_system::SystemError),
    /// The servo-valves of a closed-loop table do not share one delay.
    #[error("the servo-valves of a closed-loop table must share one delay_s")]
    UnequalValveDelays,
    /// More output samples were requested than the record holds.
    #[error("{requested} samples requested but the record holds only {available}")]
    RecordTooShort {
        /// Requested sample count.
        requested: usize,
        /// Samples in the record.
        available: usize,
    },
    /// The initial state is not finite.
    #[error("initial state u = {u_m} m, v = {v_m_s} m/s is not finite")]
    InvalidInitialState {
        /// Initial displacement, m.
        u_m: f64,
        /// Initial velocity, m/s.
        v_m_s: f64,
    },
    /// The state became NaN or infinite.
    #[error(
        "numerical failure at t = {t_s} s: state became non-finite (u = {u_m} m, v = {v_m_s} m/s)"
    )]
    NonFiniteState {
        /// Time of the failure, s.
        t_s: f64,
        /// Displacement, m.
        u_m: f64,
        /// Velocity, m/s.
        v_m_s: f64,
    },
    /// A tolerance of the adaptive integrator that is not usable.
    #[error("{name} = {value} is invalid: expected a finite number > 0 (and rtol < 1)")]
    InvalidTolerance {
        /// `rtol` or `atol`.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// The adaptive integrator gave up.
    #[error("numerical failure at t = {t_s} s: the adaptive integrator (Dopri5) failed: {reason}")]
    AdaptiveFailed {
        /// Time of the failure, s.
        t_s: f64,
        /// Why Dopri5 gave up.
        reason: AdaptiveFailure,
    },
    /// A closed-loop run drove the platen to the end of its actuators.
    #[error("the platen reached the end of its actuators at t = {t_s} s (u = {u_m} m): a chamber's oil volume is gone; the command asks for more stroke than the actuators have (check it against the table's stroke)")]
    EndStop {
        /// Time, s.
        t_s: f64,
        /// Displacement, m.
        u_m: f64,
    },
    /// A multi-axis table's state became NaN or infinite.
    #[error(
        "numerical failure at t = {t_s} s: the table's state became non-finite, from the pose x = {} m, y = {} m, z = {} m, roll = {} rad, pitch = {} rad, yaw = {} rad; something makes its motion unbounded or faster than the step can follow: look at the servo-valves (rated_flow_m3_s, natural_frequency_hz, rated_pressure_drop_pa), the oil columns, the hold-down struts' gas_volume_m3 (a small gas volume is a stiff spring), the controller's gains, a stiff specimen and the initial state",
        .pose[0], .pose[1], .pose[2], .pose[3], .pose[4], .pose[5]
    )]
    TableNonFiniteState {
        /// Time of the failure, s.
        t_s: f64,
        /// The pose the failing step started from: x, y, z (m), roll, pitch, yaw (rad).
        pose: [f64; 6],
    },
    /// A six-DOF table's hold-down strut used up its gas: the platen pulled it longer than
    /// its gas volume over its area allows.
    #[error("hold-down strut {strut} (table.hold_down_struts[{strut}]) ran out of gas at t = {t_s} s: its pull grew without bound as its gas volume went; the motion lengthens it by more than gas_volume_m3 / area_m2 allows (check those two values, or the command)")]
    StrutGasSpent {
        /// Time, s.
        t_s: f64,
        /// The strut's index in the table.
        strut: usize,
    },
    /// Any other error of `platen_signal` converted with `From` (a [`crate::Motion`]'s
    /// checks convert to the variants above that have the same message).
    #[error(transparent)]
    Signal(SignalError),
    /// The stick-slip event loop stopped advancing inside one step.
    #[error("numerical failure at t = {t_s} s: {events} stick-slip events inside one step; the event loop does not advance")]
    EventLoopStalled {
        /// Time of the failure, s.
        t_s: f64,
        /// Events handled inside the step.
        events: u32,
    },
}

impl IntegrateError {
    /// The error of a run stopped at `t_s` by a numerical failure `cause`.
    pub fn failed(t_s: f64, cause: Failure) -> Self {
        match cause {
            Failure::NonFiniteState { u_m, v_m_s } => {
                IntegrateError::NonFiniteState { t_s, u_m, v_m_s }
            }
            Failure::EventLoopStalled { events } => {
                IntegrateError::EventLoopStalled { t_s, events }
            }
            Failure::AdaptiveFailed(reason) => IntegrateError::AdaptiveFailed { t_s, reason },
            Failure::EndStop { u_m } => IntegrateError::EndStop { t_s, u_m },
            Failure::TableNonFiniteState { pose } => {
                IntegrateError::TableNonFiniteState { t_s, pose }
            }
        }
    }

    /// Why the run stopped, for an error that stopped a run under way
    /// ([`StopReason::Failed`] with the time and the typed cause of the numerical failure);
    /// `None` for an error that prevented a run from starting (a bad record or setting).
    pub fn stop_reason(&self) -> Option<StopReason> {
        let (t_s, cause) = match *self {
            IntegrateError::NonFiniteState { t_s, u_m, v_m_s } => {
                (t_s, Failure::NonFiniteState { u_m, v_m_s })
            }
            IntegrateError::EventLoopStalled { t_s, events } => {
                (t_s, Failure::EventLoopStalled { events })
            }
            IntegrateError::AdaptiveFailed { t_s, reason } => {
                (t_s, Failure::AdaptiveFailed(reason))
            }
            IntegrateError::EndStop { t_s, u_m } => (t_s, Failure::EndStop { u_m }),
            IntegrateError::TableNonFiniteState { t_s, pose } => {
                (t_s, Failure::TableNonFiniteState { pose })
            }
            _ => return None,
        };
        Some(StopReason::Failed { t_s, cause })
    }
}

/// The checks of a [`crate::Motion`] (a `platen_signal` type) as the same checks of this
/// crate's records raise them: the same variant and message, so a motion and a
/// [`crate::ForceRecord`] report a bad record alike.
impl From<SignalError> for IntegrateError {
    fn from(e: SignalError) -> Self {
        match e {
            SignalError::ColumnLengthMismatch {
                what,
                found,
                expected,
            } => IntegrateError::LengthMismatch {
                what,
                found,
                expected,
            },
            SignalError::TooFewSamples { found, needed } => {
                IntegrateError::TooShort { found, needed }
            }
            SignalError::NonFiniteInput { what, index, value } => {
                IntegrateError::NonFiniteInput { what, index, value }
            }
            SignalError::TimeNotIncreasing {
                index,
                previous_s,
                value_s,
            } => IntegrateError::TimeNotIncreasing {
                index,
                previous_s,
                value_s,
            },
            SignalError::InvalidRestVelocity { value } => {
                IntegrateError::InvalidRestVelocity { value }
            }
            other => IntegrateError::Signal(other),
        }
    }
}

/// Result alias of this crate.
pub type Result<T, E = IntegrateError> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Motion;

    /// A bad motion reports through `?` exactly as a bad force record does: the variant of
    /// this crate with the same message.
    #[test]
    fn a_motions_errors_convert_to_the_same_variant_and_message() {
        let t = || vec![0.0, 1.0, 2.0];
        let cases = [
            Motion::from_displacement(vec![0.0, 1.0], vec![0.0; 2]).unwrap_err(),
            Motion::new(t(), vec![0.0; 2], vec![0.0; 3], vec![0.0; 3]).unwrap_err(),
            Motion::new(
                t(),
                vec![0.0; 3],
                vec![0.0, f64::INFINITY, 0.0],
                vec![0.0; 3],
            )
            .unwrap_err(),
            Motion::from_displacement(vec![0.0, 2.0, 1.0], vec![0.0; 3]).unwrap_err(),
            Motion::from_displacement(t(), vec![0.0; 3])
                .unwrap()
                .with_rest_velocity(-1.0)
                .unwrap_err(),
        ];
        let converted: Vec<IntegrateError> = cases.iter().cloned().map(Into::into).collect();
        assert!(matches!(
            converted[..],
            [
                IntegrateError::TooShort {
                    found: 2,
                    needed: 3
                },
                IntegrateError::LengthMismatch { what: "u_m", .. },
                IntegrateError::NonFiniteInput {
                    what: "v_m_s",
                    index: 1,
                    ..
                },
                IntegrateError::TimeNotIncreasing { index: 2, .. },
                IntegrateError::InvalidRestVelocity { .. },
            ]
        ));
        for (signal, integrate) in cases.iter().zip(&converted) {
            assert_eq!(signal.to_string(), integrate.to_string());
        }
        let other = platen_signal::SampleRate::new(0.0).unwrap_err();
        assert_eq!(
            IntegrateError::from(other.clone()),
            IntegrateError::Signal(other)
        );
    }
}
