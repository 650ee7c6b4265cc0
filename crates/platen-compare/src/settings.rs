//! How a comparison is made: the metrics window and the lag search.

/// A time window `[start_s, end_s]`, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Start, s.
    pub start_s: f64,
    /// End, s (after the start).
    pub end_s: f64,
}

/// How a comparison is made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Compute the metrics over this window only (default: the whole compared span).
    pub window: Option<Window>,
    /// Largest lag searched by cross-correlation, either way, s (default: `0.25`).
    pub max_lag_s: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            window: None,
            max_lag_s: 0.25,
        }
    }
}
