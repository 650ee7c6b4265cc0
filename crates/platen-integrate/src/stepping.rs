//! Advancing a run a step at a time: [`Stepping`], in the manner of an ODE solver's stepping
//! interface. Each [`Stepping::step`] says what happened: a stick-slip event with its time and
//! kind, an output sample reached, or the run finished; between steps the caller reads the
//! last sample and the counters, and goes on (or stops: nothing is left running).
//!
//! The plants of the mode machine step so: the platen with a specimen under a force record
//! (either integrator) and the closed loop (with or without a specimen). The result is bit for
//! bit that of the whole-record functions ([`crate::forward_specimen`],
//! [`crate::forward_closed_loop`]): they run the same machine.
//!
//! ```
//! use platen_integrate::{EventKind, ForceRecord, Method, Rk4, State, Step, Stepping};
//! use platen_model::{preset, Specimen, Storey};
//!
//! let model = preset::lhpost_2008_identified(13.8e6).build().unwrap();
//! let storey = Storey { mass_kg: 30e3, stiffness_n_per_m: 27e6, damping_n_s_per_m: 86e3 };
//! let frame = Specimen::new(vec![storey]).unwrap();
//! let force = (0..2048).map(|j| 1.5e5 * (3.0 * j as f64 / 1024.0).sin()).collect();
//! let record = ForceRecord::from_rate(1024.0, force).unwrap();
//! let rk4 = Method::Rk4(Rk4::with_steps_per_sample(4).unwrap());
//! let mut run = Stepping::specimen(&model, &frame, &record, rk4, State::default()).unwrap();
//! let mut stops = 0;
//! let stats = loop {
//!     match run.step().unwrap() {
//!         Step::Event { kind: EventKind::Stop, .. } => stops += 1,
//!         Step::Finished(stats) => break stats,
//!         _ => {} // other events, and samples (`run.last_sample()`)
//!     }
//! };
//! assert_eq!(stats.stick_events, stops);
//! ```

use std::collections::VecDeque;

use platen_model::{PlatenModel, Specimen};

use crate::closed_loop::{boxed_loop, check_loop, LoopRun};
use crate::error::Result;
use crate::event::EventKind;
use crate::method::Method;
use crate::output::Sample;
use crate::record::ForceRecord;
use crate::run::{RunStats, State};
use crate::specimen::boxed_specimen;
use crate::steppable::{Samples, Steppable};

/// What one [`Stepping::step`] did.
// A step is returned one at a time, never stored in bulk: copying the sample is nothing next
// to the integration behind it, and boxing it would allocate per sample.
#[allow(clippy::large_enum_variant)]
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A stick-slip event happened at `t_s` (events come before the sample that follows
    /// them, in time order).
    Event {
        /// When, s.
        t_s: f64,
        /// What.
        kind: EventKind,
    },
    /// The run reached its next output sample.
    Sample(Sample),
    /// Every sample has been delivered: the run's statistics, energy balance closed.
    Finished(RunStats),
}

/// A run advanced step by step ([`Stepping::step`]).
pub struct Stepping<'a> {
    run: Box<dyn Steppable + 'a>,
    events: VecDeque<(f64, EventKind)>,
    samples: Samples,
    last: Option<Sample>,
    more: bool,
    finished: Option<RunStats>,
}

impl<'a> Stepping<'a> {
    fn new(run: Box<dyn Steppable + 'a>) -> Self {
        Stepping {
            run,
            events: VecDeque::new(),
            samples: Samples::default(),
            last: None,
            more: true,
            finished: None,
        }
    }

    /// The platen with `specimen` on it under `record` from `initial`, with `method` (as
    /// [`crate::forward_specimen`], over the whole record).
    ///
    /// # Errors
    /// A non-finite initial state.
    pub fn specimen<M: PlatenModel>(
        model: &'a M,
        specimen: &'a Specimen,
        record: &'a ForceRecord,
        method: Method,
        initial: State,
    ) -> Result<Self> {
        Ok(Self::new(boxed_specimen(
            model, specimen, record, method, initial,
        )?))
    }

    /// The closed loop `run` on `model` (as [`crate::forward_closed_loop`], over the whole
    /// command).
    ///
    /// # Errors
    /// As [`crate::forward_closed_loop`] before it starts: no steps per period, tolerances
    /// that are not positive, a non-finite initial state.
    pub fn closed_loop<M: PlatenModel>(model: &'a M, run: &LoopRun<'a>) -> Result<Self> {
        let mut stepping = match check_loop(run, run.command.len())? {
            Some((k, h, samples)) => Self::new(boxed_loop(model, run, k, h, samples)),
            None => Self::new(Box::new(Empty)),
        };
        stepping.more = !run.command.is_empty();
        Ok(stepping)
    }

    /// Advances to what happens next: an event, the next output sample, or the end.
    ///
    /// # Errors
    /// A numerical failure with its time (as the whole-record functions): the samples and
    /// events before it have been returned.
    pub fn step(&mut self) -> Result<Step> {
        loop {
            // In time order: an event at a sample's time comes first (the sample is the
            // state after it).
            let sample_t = self.samples.0.front().map_or(f64::INFINITY, |s| s.t_s);
            match self.events.front() {
                Some(&(t_s, kind)) if t_s <= sample_t || self.samples.0.is_empty() => {
                    self.events.pop_front();
                    return Ok(Step::Event { t_s, kind });
                }
                _ => {}
            }
            if let Some(sample) = self.samples.0.pop_front() {
                self.last = Some(sample);
                return Ok(Step::Sample(sample));
            }
            if let Some(stats) = self.finished {
                return Ok(Step::Finished(stats));
            }
            if self.more {
                self.more = self.run.advance(&mut self.samples)?;
                self.run.drain_events(&mut self.events);
            } else {
                self.finished = Some(self.run.finish());
            }
        }
    }

    /// The last output sample returned, if any.
    pub fn last_sample(&self) -> Option<&Sample> {
        self.last.as_ref()
    }
}

/// A closed loop with no sample to deliver.
struct Empty;

impl Steppable for Empty {
    fn advance(&mut self, _out: &mut Samples) -> Result<bool> {
        Ok(false)
    }
    fn drain_events(&mut self, _out: &mut VecDeque<(f64, EventKind)>) {}
    fn finish(&mut self) -> RunStats {
        RunStats::default()
    }
}
