//! The recorded test: its columns, time base and sample interval, read and checked before
//! anything is simulated.

use std::ops::Range;
use std::path::{Path, PathBuf};

use platen_io::columns::ColumnMap;
use platen_io::csv::Table;
use platen_scenario::sampling::uniform_step_s;

use crate::error::{CompareError, Result};
use platen_model::Specimen;

use crate::{Channel, Direction, Window};

/// A recorded test read for a comparison: uniformly sampled, with the columns its direction
/// needs (see [`Direction::record_columns`]) and the specimen's columns it has
/// (`base_shear_n`, `storey{i}_u_m`, `storey{i}_a_m_s2`), in SI units.
#[derive(Debug)]
pub struct Recording {
    /// The file it was read from.
    pub path: PathBuf,
    /// Recorded times, s.
    pub t_s: Vec<f64>,
    /// The sample interval, s.
    pub step_s: f64,
    /// Every other column read, under platen's names, in SI units.
    pub table: Table,
}

impl Recording {
    /// Reads the record at `path` through the column map `columns` (use
    /// `ColumnMap::default()` for a file with platen's own column names), with the columns a
    /// comparison in `direction` needs, and checks that it is uniformly sampled.
    ///
    /// # Errors
    /// [`CompareError::Scenario`] for an unreadable or malformed file, a missing column or a
    /// non-uniform time base.
    pub fn read(path: &Path, direction: Direction, columns: &ColumnMap) -> Result<Self> {
        let (required, optional) = direction.record_columns();
        // The specimen's columns are read where present: which are compared is decided
        // against the scenario's specimen (see `Recording::specimen_channels`).
        let optional: Vec<&str> = optional
            .iter()
            .copied()
            .chain(Channel::specimen_channels(Specimen::MAX_STOREYS).map(Channel::name))
            .collect();
        let mut table = columns.read_table(path, required, &optional)?;
        let t_s = table.take_column("t_s").unwrap_or_default();
        let step_s = uniform_step_s(path, &t_s)?;
        Ok(Self {
            path: path.to_path_buf(),
            t_s,
            step_s,
            table,
        })
    }

    /// The first and last recorded time, s.
    pub fn span_s(&self) -> (f64, f64) {
        (self.t_s[0], self.t_s[self.t_s.len() - 1])
    }

    /// The indices of the recorded samples inside `simulated_span_s` (within half a sample
    /// interval), checked to cover that span and to hold `window`, and the window clamped to
    /// the compared span: a bound within half a sample interval outside the span (a start
    /// just before the first compared stamp, an end just after the last) is taken as the
    /// span's end.
    ///
    /// # Errors
    /// [`CompareError::RecordTooShort`], [`CompareError::TooFewRecordedSamples`],
    /// [`CompareError::WindowOutside`] (a bound further out).
    pub(crate) fn compared_range(
        &self,
        scenario_path: &Path,
        simulated_span_s: (f64, f64),
        window: Option<Window>,
    ) -> Result<(Range<usize>, Option<Window>)> {
        let (rec_span, sim_span) = (self.span_s(), simulated_span_s);
        let tol = 0.5 * self.step_s;
        if rec_span.0 > sim_span.0 + tol || rec_span.1 < sim_span.1 - tol {
            return Err(CompareError::RecordTooShort {
                recorded: self.path.clone(),
                scenario: scenario_path.to_path_buf(),
                recorded_span_s: rec_span,
                simulated_span_s: sim_span,
                tolerance_s: tol,
            });
        }
        let first = self.t_s.partition_point(|&t| t < sim_span.0 - tol);
        let end = self.t_s.partition_point(|&t| t <= sim_span.1 + tol);
        if end.saturating_sub(first) < 2 {
            return Err(CompareError::TooFewRecordedSamples {
                recorded: self.path.clone(),
                samples: end.saturating_sub(first),
                simulated_span_s: sim_span,
            });
        }
        let compared_span = (self.t_s[first], self.t_s[end - 1]);
        let window = match window {
            Some(w) if w.start_s < compared_span.0 - tol || w.end_s > compared_span.1 + tol => {
                return Err(CompareError::WindowOutside {
                    window_s: [w.start_s, w.end_s],
                    compared_span_s: compared_span,
                    recorded: self.path.clone(),
                    tolerance_s: tol,
                });
            }
            // Within the tolerance: clamped (a NaN bound is left for the metrics to refuse).
            Some(w) => Some(Window {
                start_s: if w.start_s < compared_span.0 {
                    compared_span.0
                } else {
                    w.start_s
                },
                end_s: if w.end_s > compared_span.1 {
                    compared_span.1
                } else {
                    w.end_s
                },
            }),
            None => None,
        };
        Ok((first..end, window))
    }

    /// The column `key` on `range`, if the record has it.
    pub(crate) fn column(&self, key: &str, range: &Range<usize>) -> Option<Vec<f64>> {
        self.table.column(key).map(|c| c[range.clone()].to_vec())
    }

    /// The specimen's channels that this recording has and a specimen of `storeys` storeys
    /// produces, in report order ([`Channel::specimen_channels`]).
    ///
    /// # Errors
    /// [`CompareError::StoreyNotInSpecimen`] for a storey column of a storey the specimen
    /// does not have (checked only with a specimen: `storeys > 0`).
    pub(crate) fn specimen_channels(&self, storeys: usize) -> Result<Vec<Channel>> {
        if storeys == 0 {
            return Ok(Vec::new());
        }
        let present = |c: &Channel| self.table.has_column(c.name());
        if let Some(extra) = Channel::specimen_channels(Specimen::MAX_STOREYS)
            .filter(|c| match c {
                Channel::StoreyDisplacement(i) | Channel::StoreyAcceleration(i) => {
                    usize::from(*i) > storeys
                }
                _ => false,
            })
            .find(present)
        {
            return Err(CompareError::StoreyNotInSpecimen {
                recorded: self.path.clone(),
                column: extra.name(),
                storeys,
            });
        }
        Ok(Channel::specimen_channels(storeys)
            .filter(present)
            .collect())
    }

    /// The specimen's columns this recording has, in report order.
    pub(crate) fn specimen_columns(&self) -> Vec<&'static str> {
        Channel::specimen_channels(Specimen::MAX_STOREYS)
            .map(Channel::name)
            .filter(|name| self.table.has_column(name))
            .collect()
    }
}
