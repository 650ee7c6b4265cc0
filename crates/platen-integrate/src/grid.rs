//! The integer time grid of a force record: grid step `n` is sub-step `i` of the sample
//! interval that starts at sample `j`, the force linear inside it; the driver that runs a
//! fixed-grid stepper over it and delivers its samples. A plant on the grid keeps its time
//! with a [`crate::clock::GridClock`].

use crate::error::Result;
use crate::output::{Sample, SampleSink};
use crate::record::ForceRecord;
use crate::run::RunStats;

/// Grid step `n` (from `t₀`), which is sub-step `i` of the sample interval that starts at
/// sample `j` (`n = j·k + i`). Carried together so that the hot loop never divides.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GridStep {
    pub(crate) n: u64,
    pub(crate) j: usize,
    /// `i` as a number (exact: `i < k ≤ 1e9`).
    pub(crate) i: f64,
}

/// The force record seen from the integer time grid.
pub(crate) struct Grid<'a> {
    pub(crate) force: &'a [f64],
    pub(crate) inv_k: f64,
    pub(crate) h: f64,
    pub(crate) t0: f64,
}

impl<'a> Grid<'a> {
    /// The grid of `k` steps per sample interval of `record`.
    pub(crate) fn new(record: &'a ForceRecord, k: u64) -> Self {
        Grid {
            force: record.force_n(),
            inv_k: 1.0 / k as f64,
            h: record.dt_s() / k as f64,
            t0: record.t_s()[0],
        }
    }

    /// Force at fraction `tau ∈ [0, 1]` of grid step `n`: linear between the two samples
    /// that bracket the step, exact at both samples.
    #[inline(always)]
    pub(crate) fn force(&self, n: GridStep, tau: f64) -> f64 {
        let j = n.j;
        let w = (n.i + tau) * self.inv_k;
        if w == 0.0 {
            self.force[j]
        } else {
            self.force[j] * (1.0 - w) + self.force[j + 1] * w
        }
    }

    #[inline]
    pub(crate) fn time_s(&self, n: GridStep, tau: f64) -> f64 {
        self.t0 + (n.n as f64 + tau) * self.h
    }
}

/// A fixed-step integrator on the integer time grid: what [`drive`] runs.
pub(crate) trait GridStepper {
    /// Advances from grid point `n` to `n + 1`, handling every event inside the step.
    fn step(&mut self, n: GridStep) -> Result<()>;
    /// The output sample at sample `j` of the record (grid point `j·k`), at time `t_s`.
    fn sample(&self, j: usize, t_s: f64) -> Sample;
    /// Closes the run's statistics, the run having finished at `t_s`.
    fn finish(&mut self, t_s: f64) -> RunStats;
}

/// Runs `stepper` over the first `samples` sample `times` (`k` steps per interval), delivering
/// every sample to `sink`.
#[inline(always)]
pub(crate) fn drive<T: GridStepper, S: SampleSink>(
    stepper: &mut T,
    times: &[f64],
    k: u64,
    samples: usize,
    sink: &mut S,
) -> Result<RunStats> {
    if samples == 0 {
        return Ok(stepper.finish(times[0]));
    }
    sink.accept(&stepper.sample(0, times[0]));
    let mut n = 0u64;
    for j in 0..samples - 1 {
        for i in 0..k {
            stepper.step(GridStep { n, j, i: i as f64 })?;
            n += 1;
        }
        sink.accept(&stepper.sample(j + 1, times[j + 1]));
    }
    Ok(stepper.finish(times[samples - 1]))
}
