//! The machine-readable summary of a comparison (`platen compare --json`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use platen_signal::metrics::ChannelMetrics;
use serde::Serialize;

use crate::{Channel, Comparison, RecordedLimitCheck};

/// The metrics of one channel, as the summary reports them (SI unit of the channel).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelSummary {
    /// SI unit of the channel.
    pub unit: &'static str,
    /// Samples the metrics are computed over.
    pub samples: usize,
    /// First and last time the metrics cover, s.
    pub span_s: [f64; 2],
    /// RMS of the recorded channel.
    pub rms_recorded: f64,
    /// RMS of simulated − recorded.
    pub rms_error: f64,
    /// RMS error / recorded RMS (`None` for a zero recorded RMS).
    pub nrmse: Option<f64>,
    /// Recorded signed peak.
    pub peak_recorded: f64,
    /// Time of the recorded peak, s.
    pub peak_recorded_t_s: f64,
    /// Simulated signed peak.
    pub peak_simulated: f64,
    /// Time of the simulated peak, s.
    pub peak_simulated_t_s: f64,
    /// |peak simulated| / |peak recorded|.
    pub peak_ratio: Option<f64>,
    /// Pearson correlation at zero lag.
    pub correlation: Option<f64>,
    /// Lag by cross-correlation, s (> 0: the simulation is late).
    pub lag_s: Option<f64>,
    /// Correlation at that lag.
    pub lag_peak_correlation: Option<f64>,
    /// Whether the lag is at the search bound.
    pub lag_at_search_limit: Option<bool>,
}

impl ChannelSummary {
    /// The summary of `metrics` of a channel in `unit`.
    pub fn new(unit: &'static str, m: &ChannelMetrics) -> Self {
        Self {
            unit,
            samples: m.samples,
            span_s: m.span_s,
            rms_recorded: m.rms_recorded,
            rms_error: m.rms_error,
            nrmse: m.nrmse,
            peak_recorded: m.peak_recorded.value,
            peak_recorded_t_s: m.peak_recorded.t_s,
            peak_simulated: m.peak_simulated.value,
            peak_simulated_t_s: m.peak_simulated.t_s,
            peak_ratio: m.peak_ratio,
            correlation: m.correlation,
            lag_s: m.lag.map(|l| l.lag_s),
            lag_peak_correlation: m.lag.map(|l| l.peak_correlation),
            lag_at_search_limit: m.lag.map(|l| l.at_search_limit),
        }
    }
}

/// The summary of a comparison: what was compared, the metrics of every channel under its
/// name ([`Channel::name`]), the notes, and the files written.
///
/// Serialise it through `serde_json::to_value` to get its keys in alphabetical order at every
/// level, as `platen compare --json` prints them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Scenario file.
    pub scenario: String,
    /// Scenario name.
    pub name: String,
    /// Recorded file.
    pub recorded: String,
    /// `"forward"` or `"inverse"`.
    pub direction: &'static str,
    /// `"identified"` or `"full"`.
    pub model_form: &'static str,
    /// Compared samples.
    pub samples: usize,
    /// Recorded sample rate, Hz.
    pub sample_rate_hz: f64,
    /// First and last compared time, s.
    pub span_s: [f64; 2],
    /// The metrics window, s.
    pub window_s: Option<[f64; 2]>,
    /// The lag search bound, s.
    pub max_lag_s: f64,
    /// The compared channels, in order.
    pub channels: Vec<Channel>,
    /// The metrics of each channel, keyed by its name.
    #[serde(flatten)]
    pub metrics: BTreeMap<&'static str, ChannelSummary>,
    /// Substitutions made for columns the record lacks, and how the window was taken.
    pub notes: Vec<String>,
    /// The recording itself against the table's limits, keyed by the limit's name
    /// (`stroke_m`, `velocity_m_s`, `acceleration_m_s2`, `force_n`): only the limits whose
    /// column (`u_m`, `v_m_s`, `a_m_s2`, `force_n`) the file has.
    pub recorded_limits: BTreeMap<&'static str, RecordedLimitCheck>,
    /// One sentence per table limit the recording exceeds
    /// ([`RecordedLimitCheck::warning`]).
    pub warnings: Vec<String>,
    /// Figure files written.
    pub figures: Vec<String>,
    /// Report written.
    pub report: Option<String>,
}

impl Comparison {
    /// One sentence per table limit the recording exceeds, in
    /// [`TableLimit::ALL`](crate::TableLimit::ALL) order.
    pub fn warnings(&self) -> Vec<String> {
        self.recorded_limits
            .iter()
            .filter_map(RecordedLimitCheck::warning)
            .collect()
    }

    /// The summary, listing the figure files and the report written.
    pub fn summary(&self, figures: &[PathBuf], report: Option<&Path>) -> Summary {
        let (first, last) = self.compared_span_s();
        Summary {
            scenario: self.scenario_path.display().to_string(),
            name: self.name.clone(),
            recorded: self.recorded_path.display().to_string(),
            direction: self.direction.name(),
            model_form: self.model_form,
            samples: self.t_s.len(),
            sample_rate_hz: self.sample_rate_hz,
            span_s: [first, last],
            window_s: self.window.map(|w| [w.start_s, w.end_s]),
            max_lag_s: self.max_lag_s,
            channels: self.channels.iter().map(|c| c.channel).collect(),
            metrics: self
                .channels
                .iter()
                .map(|c| {
                    let name = c.channel.name();
                    (name, ChannelSummary::new(c.channel.unit(), &c.metrics))
                })
                .collect(),
            notes: self.recorded.sources.notes.clone(),
            recorded_limits: self
                .recorded_limits
                .iter()
                .map(|c| (c.kind.key(), c.clone()))
                .collect(),
            warnings: self.warnings(),
            figures: figures.iter().map(|p| p.display().to_string()).collect(),
            report: report.map(|p| p.display().to_string()),
        }
    }
}
