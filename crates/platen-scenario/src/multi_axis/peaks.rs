//! What the summary of a multi-axis run needs of it, gathered row by row as the run goes
//! ([`TablePeaks`]), so that a run streamed to its file is summarised without being held.

use std::collections::BTreeMap;

use super::*;

/// The figures a multi-axis run's summary is made of, gathered one row at a time (a
/// [`TableSink`]): each column's largest magnitude, smallest and largest value and the
/// samples at or beyond ±1 (a drive's saturation), the overturning moment's peak, and a closed
/// loop's tracking sums per free DOF. Its memory does not grow with the run: a one-hour run
/// streamed to its file is summarised as it goes
/// ([`TableScenario::summary_of`](super::TableScenario::summary_of)).
///
/// Every figure is the same fold, in the same order, as over the whole column (`rms` sums
/// its squares from the first sample on), so a summary of the peaks equals one of the run
/// held in memory, bit for bit.
#[derive(Debug, Clone)]
pub struct TablePeaks<'a> {
    /// The command a closed loop tracks (`None` otherwise).
    command: Option<&'a PoseMotion>,
    /// The free DOFs, whose tracking is summarised.
    free: Vec<Dof>,
    names: Vec<String>,
    columns: Vec<ColumnPeaks>,
    /// The columns of the overturning moments `M_x`, `M_y` (a run with a specimen).
    overturning: Option<(usize, usize)>,
    peak_overturning_n_m: f64,
    tracking: Vec<TrackingSums>,
    rows: usize,
    t_first_s: f64,
    t_last_s: f64,
}

/// One column's folds.
#[derive(Debug, Clone, Copy)]
struct ColumnPeaks {
    abs_max: f64,
    min: f64,
    max: f64,
    /// Samples with |x| ≥ 1.
    at_or_beyond_one: usize,
}

impl ColumnPeaks {
    const START: Self = Self {
        abs_max: 0.0,
        min: f64::INFINITY,
        max: f64::NEG_INFINITY,
        at_or_beyond_one: 0,
    };

    #[inline]
    fn push(&mut self, x: f64) {
        self.abs_max = self.abs_max.max(x.abs());
        self.min = self.min.min(x);
        self.max = self.max.max(x);
        self.at_or_beyond_one += usize::from(x.abs() >= 1.0);
    }
}

/// A closed loop's tracking of one DOF's command: sums of squares and largest magnitudes of
/// the errors, and the commands' sums of squares, over the samples both have.
#[derive(Debug, Clone)]
struct TrackingSums {
    dof: Dof,
    /// The achieved coordinate's and second derivative's columns (`None`: the run lacks it).
    achieved: [Option<usize>; 2],
    /// Σ e², Σ e_a², Σ u_ref², Σ a_ref².
    squares: [f64; 4],
    /// max |e|, max |e_a|.
    peaks: [f64; 2],
    /// Samples of the command reached (the run's rows, at most the command's length).
    samples: usize,
}

/// The neutral element of `f64`'s `Sum`, with which `rms` starts its sum of squares.
fn sum_start() -> f64 {
    std::iter::empty::<f64>().sum()
}

impl<'a> TablePeaks<'a> {
    /// Empty peaks of a run of `scenario`.
    pub fn new(scenario: &'a TableScenario) -> Self {
        let command = match &scenario.run {
            TableRunSpec::Loop { command } => Some(&**command),
            _ => None,
        };
        Self {
            command,
            free: scenario.table.free().iter().collect(),
            names: Vec::new(),
            columns: Vec::new(),
            overturning: None,
            peak_overturning_n_m: 0.0,
            tracking: Vec::new(),
            rows: 0,
            t_first_s: 0.0,
            t_last_s: 0.0,
        }
    }

    /// The peaks of `run` (a run of `scenario` held in memory).
    pub fn of_run(scenario: &'a TableScenario, run: &TableRun) -> Self {
        let mut peaks = Self::new(scenario);
        let names: Vec<String> = run.columns.iter().map(|(n, _)| n.clone()).collect();
        peaks.start(&names, run.len());
        let mut row = vec![0.0; names.len()];
        for i in 0..run.len() {
            for (x, (_, c)) in row.iter_mut().zip(&run.columns) {
                *x = c[i];
            }
            peaks.accept(&row);
        }
        peaks
    }

    fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    fn column(&self, name: &str) -> Option<&ColumnPeaks> {
        self.index(name).map(|i| &self.columns[i])
    }

    /// Rows received.
    pub fn samples(&self) -> usize {
        self.rows
    }

    /// Time from the first row to the last, s (0 for none).
    pub fn span_s(&self) -> f64 {
        if self.rows == 0 {
            0.0
        } else {
            self.t_last_s - self.t_first_s
        }
    }

    /// The largest |value| of column `name` (0 for a column the run lacks or without rows).
    pub fn abs_max(&self, name: &str) -> f64 {
        self.column(name).map_or(0.0, |c| c.abs_max)
    }

    /// The largest |value| of column `name`, `None` if the run lacks it.
    pub fn abs_max_of(&self, name: &str) -> Option<f64> {
        self.column(name).map(|c| c.abs_max)
    }

    /// The smallest value of column `name` (+∞ for a column the run lacks or without rows).
    pub fn min(&self, name: &str) -> f64 {
        self.column(name).map_or(f64::INFINITY, |c| c.min)
    }

    /// The largest value of column `name` (−∞ for a column the run lacks or without rows).
    pub fn max(&self, name: &str) -> f64 {
        self.column(name).map_or(f64::NEG_INFINITY, |c| c.max)
    }

    /// The time column `name` (a drive) spent at or beyond ±1, s: the run's span times the
    /// share of its sample intervals (`None` if the run lacks it).
    pub fn saturated_time_s(&self, name: &str) -> Option<f64> {
        self.column(name).map(|c| {
            if self.rows > 1 {
                self.span_s() * c.at_or_beyond_one as f64 / (self.rows - 1) as f64
            } else {
                0.0
            }
        })
    }

    /// The peak of the overturning moment's magnitude `hypot(M_x, M_y)`, N·m (`None` without
    /// a specimen's columns).
    pub fn peak_overturning_n_m(&self) -> Option<f64> {
        self.overturning.map(|_| self.peak_overturning_n_m)
    }

    /// A closed loop's tracking of its command in each free DOF (`None` for another run).
    pub fn tracking(&self) -> Option<BTreeMap<&'static str, AxisTracking>> {
        self.command?;
        Some(
            self.tracking
                .iter()
                .map(|s| (s.dof.name(), s.summary()))
                .collect(),
        )
    }
}

impl TrackingSums {
    fn summary(&self) -> AxisTracking {
        let mean_root = |sum: f64, n: usize| {
            if n == 0 {
                0.0
            } else {
                (sum / n as f64).sqrt()
            }
        };
        // The errors exist only where the achieved column does.
        let errors = |k: usize| self.achieved[k].map_or(0, |_| self.samples);
        let ratio = |num: f64, den: f64| (den > 0.0).then(|| num / den);
        let rms_e = mean_root(self.squares[0], errors(0));
        let rms_ea = mean_root(self.squares[1], errors(1));
        AxisTracking {
            rms_error: rms_e,
            peak_error: self.peaks[0],
            displacement_nrmse: ratio(rms_e, mean_root(self.squares[2], self.samples)),
            rms_acceleration_error: rms_ea,
            peak_acceleration_error: self.peaks[1],
            acceleration_nrmse: ratio(rms_ea, mean_root(self.squares[3], self.samples)),
        }
    }
}

impl TableSink for TablePeaks<'_> {
    fn start(&mut self, names: &[String], _samples: usize) {
        self.names = names.to_vec();
        self.columns = vec![ColumnPeaks::START; names.len()];
        self.overturning = self
            .index("overturning_moment_x_n_m")
            .zip(self.index("overturning_moment_y_n_m"));
        let zero = sum_start();
        self.tracking = match self.command {
            Some(_) => self
                .free
                .iter()
                .map(|&dof| {
                    let k = dof.index();
                    TrackingSums {
                        dof,
                        achieved: [
                            self.index(POSE_COLUMNS[k]),
                            self.index(ACCELERATION_COLUMNS[k]),
                        ],
                        squares: [zero; 4],
                        peaks: [0.0; 2],
                        samples: 0,
                    }
                })
                .collect(),
            None => Vec::new(),
        };
    }

    fn accept(&mut self, row: &[f64]) {
        let j = self.rows;
        if let Some(&t) = row.first() {
            if j == 0 {
                self.t_first_s = t;
            }
            self.t_last_s = t;
        }
        for (c, &x) in self.columns.iter_mut().zip(row) {
            c.push(x);
        }
        if let Some((mx, my)) = self.overturning {
            self.peak_overturning_n_m = self.peak_overturning_n_m.max(row[mx].hypot(row[my]));
        }
        if let Some(command) = self.command {
            for s in &mut self.tracking {
                let m = command.dof(s.dof);
                if j >= m.len() {
                    continue;
                }
                let refs = [m.u_m()[j], m.a_m_s2()[j]];
                for (k, (column, r)) in s.achieved.iter().zip(refs).enumerate() {
                    if let Some(i) = *column {
                        let e = r - row[i];
                        s.squares[k] += e * e;
                        s.peaks[k] = s.peaks[k].max(e.abs());
                    }
                    s.squares[2 + k] += r * r;
                }
                s.samples += 1;
            }
        }
        self.rows += 1;
    }
}
