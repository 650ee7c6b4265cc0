//! The stepping API ([`Stepping`]) runs the same machine as the whole-record functions: its
//! samples are theirs bit for bit, its events are the ones their counters count, in time
//! order, each between the samples that bracket it. (Against independent truth it is checked
//! in `frictionless_specimen.rs`: the closed-form 3-DOF steady state.)

use platen_integrate::{
    forward_closed_loop, forward_specimen, Dopri5Settings, EventKind, ForceRecord, LoopMethod,
    LoopRun, Method, Motion, Rk4, RunStats, Sample, SampleSink, State, Step, Stepping,
};
use platen_model::{Specimen, Storey};

#[derive(Default)]
struct Keep(Vec<Sample>);

impl SampleSink for Keep {
    fn accept(&mut self, s: &Sample) {
        self.0.push(*s);
    }
}

/// The samples, the events and the statistics of a stepped run.
fn step_through(mut run: Stepping<'_>) -> (Vec<Sample>, Vec<(f64, EventKind)>, RunStats) {
    let (mut samples, mut events) = (Vec::new(), Vec::new());
    loop {
        match run.step().unwrap() {
            Step::Sample(s) => {
                assert_eq!(run.last_sample(), Some(&s));
                samples.push(s);
            }
            Step::Event { t_s, kind } => {
                // After the sample before it, at or before the one after it.
                if let Some(last) = samples.last() {
                    assert!(t_s >= last.t_s, "{kind:?} at {t_s} s before {}", last.t_s);
                }
                events.push((t_s, kind));
            }
            Step::Finished(stats) => {
                // Finished stays finished.
                assert_eq!(run.step().unwrap(), Step::Finished(stats));
                return (samples, events, stats);
            }
            other => panic!("{other:?}"),
        }
    }
}

fn counts(events: &[(f64, EventKind)]) -> [u64; 3] {
    let n = |k| events.iter().filter(|e| e.1 == k).count() as u64;
    [
        n(EventKind::Stop),
        n(EventKind::Breakaway),
        n(EventKind::Reversal),
    ]
}

fn frame() -> Specimen {
    Specimen::new(vec![
        Storey {
            mass_kg: 30e3,
            stiffness_n_per_m: 27_083_177.88,
            damping_n_s_per_m: 86_208.43,
        },
        Storey {
            mass_kg: 25e3,
            stiffness_n_per_m: 19_345_127.06,
            damping_n_s_per_m: 61_577.45,
        },
    ])
    .unwrap()
}

/// The identified LHPOST at 13.8 MPa (F_s = 37.5 kN): a 150 kN sine sticks it at reversals.
fn lhpost() -> platen_model::IdentifiedModel {
    platen_model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap()
}

#[test]
fn stepping_a_specimen_run_gives_the_whole_run_bit_for_bit() {
    let model = lhpost();
    let spec = frame();
    let force: Vec<f64> = (0..4 * 1024)
        .map(|j| {
            let t = j as f64 / 1024.0;
            1.5e5 * (2.0 * std::f64::consts::PI * 1.5 * t).sin() * t.min(1.0)
        })
        .collect();
    let record = ForceRecord::from_rate(1024.0, force).unwrap();
    for method in [
        Method::Rk4(Rk4::with_steps_per_sample(4).unwrap()),
        Method::Dopri5(Dopri5Settings::new(1e-9, 1e-12).unwrap()),
    ] {
        let mut whole = Keep::default();
        let stats = forward_specimen(
            &model,
            &spec,
            &record,
            method,
            State::default(),
            record.len(),
            &mut whole,
        )
        .unwrap();
        let stepping =
            Stepping::specimen(&model, &spec, &record, method, State::default()).unwrap();
        let (samples, events, stepped) = step_through(stepping);
        eprintln!("{method:?}: {} events, {stats:?}", events.len());
        assert_eq!(samples, whole.0, "{method:?}");
        assert_eq!(stepped, stats, "{method:?}");
        assert_eq!(
            counts(&events),
            [stats.stick_events, stats.breakaways, stats.reversals]
        );
        assert!(stats.stick_events > 0 && stats.breakaways > 1, "{stats:?}");
        assert!(events.windows(2).all(|w| w[0].0 <= w[1].0), "{events:?}");
    }
}

#[test]
fn stepping_a_closed_loop_gives_the_whole_run_bit_for_bit() {
    let model = lhpost();
    let sys = platen_system::preset::lhpost_2008();
    let spec = frame();
    let w = std::f64::consts::PI;
    let n = 3 * 1024 + 1;
    let t: Vec<f64> = (0..n).map(|j| j as f64 / 1024.0).collect();
    let u: Vec<f64> = t.iter().map(|t| 0.05 * (w * t).sin()).collect();
    let v: Vec<f64> = t.iter().map(|t| 0.05 * w * (w * t).cos()).collect();
    let a: Vec<f64> = t.iter().map(|t| -0.05 * w * w * (w * t).sin()).collect();
    let command = Motion::new(t, u, v, a).unwrap();
    for specimen in [None, Some(&spec)] {
        let run = LoopRun {
            system: &sys,
            specimen,
            command: &command,
            method: LoopMethod::Rk4 {
                steps_per_period: 7,
            },
            initial: State::default(),
        };
        let mut whole = Keep::default();
        let stats = forward_closed_loop(&model, &run, command.len(), &mut whole).unwrap();
        let (samples, events, stepped) = step_through(Stepping::closed_loop(&model, &run).unwrap());
        eprintln!(
            "closed loop, {} storeys: {events:?}",
            specimen.map_or(0, |s| s.len())
        );
        assert_eq!(samples, whole.0);
        assert_eq!(stepped, stats.run);
        assert_eq!(
            counts(&events),
            [
                stats.run.stick_events,
                stats.run.breakaways,
                stats.run.reversals
            ]
        );
        assert!(stats.run.stick_events > 0, "{stats:?}");
        assert!(events.windows(2).all(|w| w[0].0 <= w[1].0), "{events:?}");
    }
}
