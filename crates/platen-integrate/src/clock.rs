//! Where a plant's time is kept, apart from its right-hand side and its events.
//!
//! The mode machine ([`crate::machine`]) passes lengths and positions inside a span in the
//! clock's own units and asks the clock where a located event lands, so that each driver's
//! arithmetic of time is its own and its runs keep their bits. Two clocks serve every plant:
//! * [`GridClock`]: positions are fractions of grid step `n` of a force record (the bare
//!   platen, the specimen, the multi-axis table under recorded forces);
//! * [`SecondsClock`]: positions are seconds from the start of the current advance (the
//!   closed loops, whose controller and valve delays cut time into segments).

use crate::grid::{Grid, GridStep};

/// The time hooks of a plant: lengths and positions in the clock's units, `tau` where the
/// current advance started and `rest` the length left to the end of the span.
pub(crate) trait Clock {
    /// The grid's step, s.
    fn step_s(&self) -> f64;
    /// A length in the clock's units, in seconds.
    fn seconds(&self, len: f64) -> f64;
    /// A length in seconds, in the clock's units.
    fn units(&self, seconds: f64) -> f64;
    /// The time at position `at`, s.
    fn time_s(&self, at: f64) -> f64;
    /// The smallest bracket the event root finder is asked for, in the clock's units (the
    /// bracket is `4ε·max(len, floor)`).
    fn tolerance_floor(&self) -> f64;
    /// A creep stop this close to the start of its advance has not moved time.
    fn min_progress(&self) -> f64;
    /// Where an event located `x` past `tau` lands (snapped onto the span's end when a
    /// hair short of it), in the units the plant's driver counts in.
    fn land(&self, tau: f64, x: f64, rest: f64) -> f64;
    /// Where a committed piece of length `len` from `tau` ends, in the driver's units.
    fn reach(&self, tau: f64, len: f64) -> f64;
    /// Where a breakaway located `x` past `tau` lands, in the driver's units; `held` when
    /// rounding kept friction holding there (still stuck: time must still move).
    fn break_at(&self, tau: f64, x: f64, rest: f64, held: bool) -> f64;
}

/// The clock hooks of a plant (or a table's source) whose clock is its field `clock` of type
/// `$ty`.
macro_rules! clock_field {
    ($ty:ty) => {
        type Clock = $ty;
        fn clock(&self) -> &$ty {
            &self.clock
        }
        fn clock_mut(&mut self) -> &mut $ty {
            &mut self.clock
        }
    };
}
pub(crate) use clock_field;

/// The integer time grid of a force record: positions are fractions of the current grid
/// step `n`, an event a hair short of the step's end lands on it.
pub(crate) struct GridClock<'a> {
    /// The record seen from the grid.
    pub(crate) grid: Grid<'a>,
    /// The grid step being taken.
    pub(crate) n: GridStep,
}

impl<'a> GridClock<'a> {
    /// The clock of `grid` at its first step.
    pub(crate) fn new(grid: Grid<'a>) -> Self {
        GridClock {
            grid,
            n: GridStep { n: 0, j: 0, i: 0.0 },
        }
    }

    /// The record's force at position `at` of the current step.
    #[inline(always)]
    pub(crate) fn force(&self, at: f64) -> f64 {
        self.grid.force(self.n, at)
    }
}

impl Clock for GridClock<'_> {
    fn step_s(&self) -> f64 {
        self.grid.h
    }
    #[inline(always)]
    fn seconds(&self, len: f64) -> f64 {
        len * self.grid.h
    }
    fn units(&self, seconds: f64) -> f64 {
        seconds / self.grid.h
    }
    fn time_s(&self, at: f64) -> f64 {
        self.grid.time_s(self.n, at)
    }
    fn tolerance_floor(&self) -> f64 {
        0.0
    }
    /// A creep stop located this close (fraction of a step) to where the advance started
    /// has not moved time.
    fn min_progress(&self) -> f64 {
        4.0 * f64::EPSILON
    }
    fn land(&self, tau: f64, x: f64, _rest: f64) -> f64 {
        let at = tau + x;
        if 1.0 - at < 1e-12 {
            1.0
        } else {
            at
        }
    }
    fn reach(&self, tau: f64, len: f64) -> f64 {
        tau + len
    }
    fn break_at(&self, tau: f64, x: f64, _rest: f64, _held: bool) -> f64 {
        (tau + x).min(1.0)
    }
}

/// Seconds from the start of the current advance at `t`, on a grid of step `h`: the clock of
/// a closed loop, whose driver moves `t` through the segments between its cuts.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SecondsClock {
    /// Time at the start of the current advance, s.
    pub(crate) t: f64,
    /// The grid's step, s.
    pub(crate) h: f64,
}

impl Clock for SecondsClock {
    fn step_s(&self) -> f64 {
        self.h
    }
    #[inline(always)]
    fn seconds(&self, len: f64) -> f64 {
        len
    }
    fn units(&self, seconds: f64) -> f64 {
        seconds
    }
    fn time_s(&self, at: f64) -> f64 {
        self.t + at
    }
    fn tolerance_floor(&self) -> f64 {
        self.h
    }
    /// A creep stop located this close (`4ε` of a step `h`) to where the advance started has
    /// not moved time: if the net force at rest still drives the creep on, it is stepped
    /// just past instead of creeping on in place.
    fn min_progress(&self) -> f64 {
        4.0 * f64::EPSILON * self.h
    }
    fn land(&self, _tau: f64, x: f64, rest: f64) -> f64 {
        if rest - x < 1e-12 * self.h {
            rest
        } else {
            x
        }
    }
    fn reach(&self, _tau: f64, len: f64) -> f64 {
        len
    }
    fn break_at(&self, _tau: f64, x: f64, rest: f64, held: bool) -> f64 {
        if held {
            x.max(f64::MIN_POSITIVE).min(rest)
        } else {
            x
        }
    }
}
