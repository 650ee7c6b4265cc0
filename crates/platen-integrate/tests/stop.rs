//! Why a run stopped, as the caller sees it: a finished run's statistics, a failed run's error.

use platen_integrate::{
    forward_dopri5, forward_rk4, AdaptiveFailure, Dopri5Settings, Failure, ForceRecord,
    IntegrateError, Peaks, Rk4, State, StopReason,
};
use platen_model::{preset, IdentifiedModel};

/// The `lhpost-2008` identified model at 13.8 MPa, one RK4 step per sample and an empty sink.
fn setup() -> (IdentifiedModel, Rk4, Peaks) {
    let model = preset::lhpost_2008_identified(13.8e6).build().unwrap();
    (
        model,
        Rk4::with_steps_per_sample(1).unwrap(),
        Peaks::default(),
    )
}

#[test]
fn a_finished_run_says_so_with_the_time_of_its_last_sample() {
    let (model, rk4, mut peaks) = setup();
    let record = ForceRecord::from_rate(1024.0, vec![100e3; 1025]).unwrap();
    let stats = forward_rk4(&model, &record, rk4, State::default(), 513, &mut peaks).unwrap();
    assert_eq!(stats.stop, StopReason::Finished { t_s: 0.5 });
    let settings = Dopri5Settings::new(1e-6, 1e-9).unwrap();
    let stats = forward_dopri5(
        &model,
        &record,
        settings,
        State::default(),
        1025,
        &mut peaks,
    );
    assert_eq!(stats.unwrap().stop, StopReason::Finished { t_s: 1.0 });
}

/// A force of 1e308 N drives the displacement so far that the elastic force overflows: the
/// run fails with a non-finite state, and the error tells when.
#[test]
fn a_run_that_blows_up_reports_a_typed_non_finite_failure_with_its_time() {
    let (model, rk4, mut peaks) = setup();
    let record = ForceRecord::from_rate(1024.0, vec![1e308; 4097]).unwrap();
    let e = forward_rk4(&model, &record, rk4, State::default(), 4097, &mut peaks).unwrap_err();
    let Some(StopReason::Failed { t_s, cause }) = e.stop_reason() else {
        panic!("not a run failure: {e:?}");
    };
    assert!(matches!(cause, Failure::NonFiniteState { .. }), "{cause:?}");
    assert!(t_s > 0.0 && t_s <= 4.0, "{t_s}");
    assert!(e
        .to_string()
        .starts_with(&format!("numerical failure at t = {t_s} s: ")));
}

/// Every numerical failure maps to the error variant the CLI knows (and back), with the
/// message it has always printed.
#[test]
fn failures_and_errors_map_both_ways_with_the_same_messages() {
    let cases = [
        (
            Failure::NonFiniteState {
                u_m: f64::NAN,
                v_m_s: 1.0,
            },
            "numerical failure at t = 0.5 s: state became non-finite (u = NaN m, v = 1 m/s)",
        ),
        (
            Failure::EventLoopStalled { events: 65 },
            "numerical failure at t = 0.5 s: 65 stick-slip events inside one step; the event \
             loop does not advance",
        ),
        (
            Failure::AdaptiveFailed(AdaptiveFailure::TooManySteps { steps: 100_000 }),
            "numerical failure at t = 0.5 s: the adaptive integrator (Dopri5) failed: more than \
             100000 steps needed",
        ),
        (
            Failure::AdaptiveFailed(AdaptiveFailure::StepSizeUnderflow),
            "numerical failure at t = 0.5 s: the adaptive integrator (Dopri5) failed: step size \
             underflow",
        ),
    ];
    for (cause, message) in cases {
        let e = IntegrateError::failed(0.5, cause);
        assert_eq!(e.to_string(), message);
        match e.stop_reason() {
            Some(StopReason::Failed { t_s, cause: back }) => {
                assert_eq!(t_s, 0.5);
                // NaN != NaN: compare the debug forms.
                assert_eq!(format!("{back:?}"), format!("{cause:?}"));
            }
            other => panic!("{other:?}"),
        }
    }
    assert!(matches!(
        IntegrateError::failed(1.0, Failure::EventLoopStalled { events: 65 }),
        IntegrateError::EventLoopStalled { events: 65, .. }
    ));
    let setup = IntegrateError::InvalidStep { step_s: -1.0 };
    assert_eq!(setup.stop_reason(), None);
}
