//! The progress bars of the long verbs (`simulate`, `plan`, `sweep`): on stderr, only when it
//! is a terminal and `CI` is not set, and only once the work has lasted over a second; pipes
//! and files get the same bytes as without them.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use platen_integrate::{Sample, SampleSink, TableSink};

/// How long the work runs before its bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// A bar of `len` steps, drawn with `template` (indicatif's) once the work has lasted
/// [`SHOW_AFTER`]; never drawn when stderr is not a terminal.
pub struct Progress {
    bar: ProgressBar,
    enabled: bool,
}

impl Progress {
    /// A bar of `len` steps, hidden until it has lasted a second.
    pub fn new(len: u64, template: &str) -> Self {
        let enabled = std::io::stderr().is_terminal() && std::env::var_os("CI").is_none();
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style);
        }
        Self { bar, enabled }
    }

    /// Moves the bar to `pos` steps (and shows it once it has lasted a second).
    pub fn set_position(&self, pos: u64) {
        if !self.enabled {
            return;
        }
        self.bar.set_position(pos);
        self.show_if_slow();
    }

    /// Advances the bar by one step.
    pub fn inc(&self) {
        if !self.enabled {
            return;
        }
        self.bar.inc(1);
        self.show_if_slow();
    }

    fn show_if_slow(&self) {
        if self.bar.is_hidden() && self.bar.elapsed() >= SHOW_AFTER {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// A sink that moves a [`Progress`] by the samples a run has written (every 4096 samples, so
/// that it costs nothing per sample).
pub struct Ticker<'a> {
    /// The bar, of the run's expected samples.
    pub progress: &'a Progress,
    /// Samples seen.
    pub samples: u64,
}

impl Ticker<'_> {
    #[inline]
    fn tick(&mut self) {
        self.samples += 1;
        if self.samples % 4096 == 0 {
            self.progress.set_position(self.samples);
        }
    }
}

impl SampleSink for Ticker<'_> {
    #[inline]
    fn accept(&mut self, _: &Sample) {
        self.tick();
    }
}

/// A multi-axis run's rows tick the bar as a uniaxial run's samples do.
impl TableSink for Ticker<'_> {
    fn start(&mut self, _: &[String], _: usize) {}

    #[inline]
    fn accept(&mut self, _: &[f64]) {
        self.tick();
    }
}
