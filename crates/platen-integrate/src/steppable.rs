//! What the stepping API ([`crate::Stepping`]) needs of a run: a plant's driver advanced a
//! sample at a time, its events drained, its statistics closed. Kept apart from the API so
//! that the drivers (specimen, closed loop) and the API do not import each other.

use std::collections::VecDeque;

use crate::error::Result;
use crate::event::EventKind;
use crate::output::{Sample, SampleSink};
use crate::run::RunStats;

/// A run of a plant of the mode machine that one advances step by step.
pub(crate) trait Steppable {
    /// Advances to the next output sample(s), pushing them to `out`; `false` once the run
    /// has delivered its last sample.
    fn advance(&mut self, out: &mut Samples) -> Result<bool>;
    /// Moves the events logged since the last call into `out`.
    fn drain_events(&mut self, out: &mut VecDeque<(f64, EventKind)>);
    /// Closes the run's statistics.
    fn finish(&mut self) -> RunStats;
}

/// The samples a step delivered, in order.
#[derive(Debug, Default)]
pub(crate) struct Samples(pub(crate) VecDeque<Sample>);

impl SampleSink for Samples {
    fn accept(&mut self, sample: &Sample) {
        self.0.push_back(*sample);
    }
}
