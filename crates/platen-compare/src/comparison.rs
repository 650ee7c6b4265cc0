//! A scenario run compared with a recording: the run, its alignment on the recorded time
//! base, the recorded quantities (with substitutes for missing columns), the metrics per
//! channel and the dissipative force.

use std::ops::Range;
use std::path::{Path, PathBuf};

use platen_integrate::Trajectory;
use platen_io::columns::ColumnMap;
use platen_model::{force_terms, PlatenModel};
use platen_scenario::{Model, PlatenScenario};
use platen_signal::metrics::{interpolate_linear, ChannelMetrics, Comparator};
use platen_signal::{differentiate, CrossoverVelocity, SampleRate, DEFAULT_CROSSOVER_HZ};

use crate::error::{CompareError, Result};
use crate::{Channel, Direction, RecordedLimitCheck, Recording, Settings, Window};

/// One compared channel on the recorded time base.
#[derive(Debug)]
pub struct ComparedChannel {
    /// Which channel.
    pub channel: Channel,
    /// Recorded values, SI unit of the channel.
    pub recorded: Vec<f64>,
    /// Simulated values interpolated onto the recorded times, SI unit of the channel.
    pub simulated: Vec<f64>,
    /// The metrics (error = simulated − recorded).
    pub metrics: ChannelMetrics,
}

impl ComparedChannel {
    /// The residual, simulated − recorded, at every compared time, SI unit of the channel.
    pub fn residual(&self) -> Vec<f64> {
        self.simulated
            .iter()
            .zip(&self.recorded)
            .map(|(a, b)| a - b)
            .collect()
    }
}

/// Motion and force on the recorded time base.
#[derive(Debug, Default)]
pub struct Quantities {
    /// Displacement, m.
    pub u_m: Vec<f64>,
    /// Velocity, m/s.
    pub v_m_s: Vec<f64>,
    /// Acceleration, m/s².
    pub a_m_s2: Vec<f64>,
    /// Actuator force, N.
    pub force_n: Vec<f64>,
    /// Where the recorded data come from, for captions (empty for simulated data).
    pub sources: Sources,
}

/// Where the recorded data come from (file columns or substitutes).
#[derive(Debug, Default)]
pub struct Sources {
    /// For the hysteresis loops.
    pub loops: String,
    /// For the dissipative force.
    pub dissipative: String,
    /// Every substitution made, one sentence each.
    pub notes: Vec<String>,
}

/// A scenario run compared with a recorded test.
#[derive(Debug)]
pub struct Comparison {
    /// Scenario file.
    pub scenario_path: PathBuf,
    /// Recorded file.
    pub recorded_path: PathBuf,
    /// Scenario name.
    pub name: String,
    /// Forward or inverse.
    pub direction: Direction,
    /// `"identified"` or `"full"`.
    pub model_form: &'static str,
    /// Recorded sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Recorded sample interval, s.
    pub sample_interval_s: f64,
    /// Recorded times compared (within the simulated span), s.
    pub t_s: Vec<f64>,
    /// The simulated span, s.
    pub simulated_span_s: (f64, f64),
    /// The record's span, s.
    pub recorded_span_s: (f64, f64),
    /// The metrics window, if any, clamped to the compared span (a bound given within half a
    /// sample interval outside it is the span's end).
    pub window: Option<Window>,
    /// The lag search bound, s.
    pub max_lag_s: f64,
    /// The compared channels: the platen's in [`Direction::channels`] order, then the
    /// specimen's the recording has ([`Channel::specimen_channels`] order).
    pub channels: Vec<ComparedChannel>,
    /// Recorded data (with substitutes where the file lacks a column).
    pub recorded: Quantities,
    /// Simulated data interpolated onto the recorded times.
    pub simulated: Quantities,
    /// The recorded force of a forward run (when the file has one), N.
    pub recorded_input_force_n: Option<Vec<f64>>,
    /// Storeys of the scenario's specimen (0 without one).
    pub specimen_storeys: usize,
    /// `F_A − F_I − F_E` from the recorded data (`− B` with a specimen), N.
    pub recorded_dissipative_n: Vec<f64>,
    /// The model's dissipative law `(v, F_D)`, m/s and N.
    pub law: Vec<(f64, f64)>,
    /// How the law is labelled.
    pub law_label: String,
    /// The recording itself against the table's limits (the scenario's preset's with its
    /// `limits` laid over), over the whole record: one check per limit whose column the file
    /// has, in [`TableLimit::ALL`](crate::TableLimit::ALL) order.
    pub recorded_limits: Vec<RecordedLimitCheck>,
}

impl Comparison {
    /// Loads the scenario, the column map (if any) and the record, then compares: the files
    /// are read and checked in that order before anything is simulated.
    ///
    /// # Errors
    /// Every error of [`PlatenScenario::load`], [`ColumnMap::load`], [`Recording::read`] and
    /// [`Comparison::new`].
    pub fn from_files(
        scenario_path: &Path,
        recorded_path: &Path,
        columns: Option<&Path>,
        settings: &Settings,
    ) -> Result<Self> {
        let scenario = PlatenScenario::load(scenario_path)?;
        let map = match columns {
            Some(path) => ColumnMap::load(path)?,
            None => ColumnMap::default(),
        };
        let recording = Recording::read(recorded_path, Direction::of(&scenario), &map)?;
        Self::new(&scenario, scenario_path, recording, settings)
    }

    /// Checks that `recording` covers `scenario`'s span (and holds the window), runs the
    /// scenario, aligns it on the recorded times and computes the metrics. `scenario_path`
    /// names the scenario in messages and in the summary.
    ///
    /// # Errors
    /// [`CompareError::RecordTooShort`], [`CompareError::TooFewRecordedSamples`],
    /// [`CompareError::WindowOutside`] and [`CompareError::StoreyNotInSpecimen`] before the
    /// run; [`CompareError::Scenario`] if the run
    /// fails; [`CompareError::TooFewSimulatedSamples`], [`CompareError::Align`],
    /// [`CompareError::SampleRate`], [`CompareError::Settings`] and
    /// [`CompareError::Metrics`] after it.
    pub fn new(
        scenario: &PlatenScenario,
        scenario_path: &Path,
        recording: Recording,
        settings: &Settings,
    ) -> Result<Self> {
        let direction = Direction::of(scenario);
        let sim_span = scenario.run.time_span_s();
        let settings_window_given = settings.window;
        let (range, window) = recording.compared_range(scenario_path, sim_span, settings.window)?;
        let settings = &Settings {
            window,
            ..*settings
        };
        let specimen_channels = recording.specimen_channels(scenario.storeys())?;
        let sim = simulate(scenario, scenario_path)?;
        debug_assert_eq!((sim.t_s[0], sim.t_s[sim.len() - 1]), sim_span);
        let t_s = recording.t_s[range.clone()].to_vec();
        let simulated = aligned(&sim, &t_s)?;
        let rate = SampleRate::new(1.0 / recording.step_s).map_err(CompareError::SampleRate)?;
        let mut recorded = recorded_quantities(&recording, &range, direction, &simulated, rate)?;
        if let (Some(given), Some(used)) = (settings_window_given, window) {
            if given != used {
                let note = window_note(given, used, &t_s, recording.step_s);
                recorded.sources.notes.push(note);
            }
        }
        let recorded_limits = RecordedLimitCheck::of_recording(&recording, &scenario.rig.limits);
        let on_times = OnRecordedTimes {
            recording: &recording,
            range: &range,
            sim: &sim,
            t_s: &t_s,
        };
        let series = on_times.series(direction, &recorded, &simulated, specimen_channels)?;
        if scenario.rig.specimen.is_none() {
            recorded
                .sources
                .notes
                .extend(unused_specimen_note(&recording));
        }
        let with_specimen = scenario.rig.specimen.is_some();
        let base_shear_n = on_times.base_shear(&series, with_specimen, &mut recorded.sources)?;
        let channels = compare_channels(series, rate, &t_s, settings)?;
        let b = base_shear_n.as_deref();
        let (recorded_dissipative_n, law, law_label) = match &scenario.rig.model {
            Model::Identified(m) => dissipative(m, &recorded, b, "(Eq. 22)"),
            Model::Full(m) => dissipative(&**m, &recorded, b, "at u = 0 (Eq. 4)"),
        };
        let recorded_input_force_n =
            recorded_input_force(direction, &recording, &range, &mut recorded.sources.notes);
        Ok(Comparison {
            scenario_path: scenario_path.to_path_buf(),
            recorded_span_s: recording.span_s(),
            recorded_path: recording.path,
            name: scenario.name.clone(),
            direction,
            model_form: scenario.rig.model.form(),
            sample_rate_hz: rate.hz(),
            sample_interval_s: recording.step_s,
            t_s,
            simulated_span_s: sim_span,
            window: settings.window,
            max_lag_s: settings.max_lag_s,
            channels,
            recorded,
            simulated,
            recorded_input_force_n,
            specimen_storeys: scenario.storeys(),
            recorded_dissipative_n,
            law,
            law_label,
            recorded_limits,
        })
    }

    /// The recorded file's name, for captions.
    pub fn recorded_name(&self) -> String {
        self.recorded_path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| self.recorded_path.display().to_string())
    }

    /// The first and last compared time, s.
    pub fn compared_span_s(&self) -> (f64, f64) {
        (self.t_s[0], self.t_s[self.t_s.len() - 1])
    }
}

/// The note of a `--window` that reached past the compared span by less than half a sample
/// interval (`step_s`), and was clamped from `given` to `used`.
fn window_note(given: Window, used: Window, t_s: &[f64], step_s: f64) -> String {
    format!(
        "--window {},{} s reaches past the compared span {} s to {} s by less than \
         half a sample interval ({} s): the metrics window is {},{} s.",
        given.start_s,
        given.end_s,
        t_s[0],
        t_s[t_s.len() - 1],
        0.5 * step_s,
        used.start_s,
        used.end_s
    )
}

/// The note of a recording with specimen columns for a scenario without a specimen.
fn unused_specimen_note(recording: &Recording) -> Option<String> {
    let unused = recording.specimen_columns();
    (!unused.is_empty()).then(|| {
        format!(
            "`{}` has the specimen's columns {}: the scenario has no specimen, so they \
             are not compared.",
            recording.path.display(),
            unused.join(", ")
        )
    })
}

/// The recorded force of a forward run, if the file has one (a note in `notes` when not).
fn recorded_input_force(
    direction: Direction,
    recording: &Recording,
    range: &Range<usize>,
    notes: &mut Vec<String>,
) -> Option<Vec<f64>> {
    let force_n = match direction {
        Direction::Forward => recording.column("force_n", range),
        Direction::Inverse => None,
    };
    if force_n.is_none() && direction == Direction::Forward {
        notes.push(format!(
            "`{}` has no force_n column: the recorded loops and F_D use the driving force.",
            recording.path.display()
        ));
    }
    force_n
}

/// A channel with its recorded and simulated values on the compared times.
type Series = (Channel, Vec<f64>, Vec<f64>);

/// The recording's compared samples (`range`, at the times `t_s`) and the run `sim` to be
/// put on them.
struct OnRecordedTimes<'a> {
    recording: &'a Recording,
    range: &'a Range<usize>,
    sim: &'a Trajectory,
    t_s: &'a [f64],
}

impl OnRecordedTimes<'_> {
    /// The compared channels: the platen's of `direction` (from `recorded` and
    /// `simulated`), then the specimen's.
    fn series(
        &self,
        direction: Direction,
        recorded: &Quantities,
        simulated: &Quantities,
        specimen_channels: Vec<Channel>,
    ) -> Result<Vec<Series>> {
        let mut series: Vec<Series> = direction
            .channels()
            .iter()
            .map(|&channel| {
                let (rec, sim) = match channel {
                    Channel::Displacement => (&recorded.u_m, &simulated.u_m),
                    Channel::Velocity => (&recorded.v_m_s, &simulated.v_m_s),
                    _ => (&recorded.force_n, &simulated.force_n),
                };
                (channel, rec.clone(), sim.clone())
            })
            .collect();
        for channel in specimen_channels {
            let rec = self
                .recording
                .column(channel.name(), self.range)
                .unwrap_or_default();
            let sim = interpolate_linear(
                &self.sim.t_s,
                channel.of(self.sim).unwrap_or_default(),
                self.t_s,
            )
            .map_err(CompareError::Align)?;
            series.push((channel, rec, sim));
        }
        Ok(series)
    }

    /// The base shear the recorded dissipative force subtracts, noted in `sources`: with a
    /// specimen the actuator force also carries the base shear, so the recorded dissipative
    /// force is F_A − F_I − F_E − B, with the recorded B where the file has one (in
    /// `series`) and the simulated B otherwise.
    fn base_shear(
        &self,
        series: &[Series],
        with_specimen: bool,
        sources: &mut Sources,
    ) -> Result<Option<Vec<f64>>> {
        Ok(match series.iter().find(|s| s.0 == Channel::BaseShear) {
            Some((_, rec, _)) => {
                sources
                    .dissipative
                    .push_str(", less the recorded base shear B");
                Some(rec.clone())
            }
            None if with_specimen => {
                let b = Channel::BaseShear.of(self.sim).unwrap_or_default();
                sources
                    .dissipative
                    .push_str(", less the simulated base shear B");
                sources.notes.push(format!(
                    "`{}` has no base_shear_n column: the recorded F_D subtracts the simulated \
                     base shear.",
                    self.recording.path.display()
                ));
                Some(interpolate_linear(&self.sim.t_s, b, self.t_s).map_err(CompareError::Align)?)
            }
            None => None,
        })
    }
}

/// Runs the scenario (through [`PlatenScenario::run`]) into a trajectory of at least 2 samples.
fn simulate(scenario: &PlatenScenario, scenario_path: &Path) -> Result<Trajectory> {
    let mut sim = Trajectory::default();
    scenario.run(&mut sim)?;
    if sim.len() < 2 {
        return Err(CompareError::TooFewSimulatedSamples {
            scenario: scenario_path.to_path_buf(),
            samples: sim.len(),
        });
    }
    Ok(sim)
}

/// The simulated motion and force interpolated linearly onto `t_s`.
fn aligned(sim: &Trajectory, t_s: &[f64]) -> Result<Quantities> {
    let on_record = |y: &[f64]| interpolate_linear(&sim.t_s, y, t_s).map_err(CompareError::Align);
    Ok(Quantities {
        u_m: on_record(&sim.u_m)?,
        v_m_s: on_record(&sim.v_m_s)?,
        a_m_s2: on_record(&sim.a_m_s2)?,
        force_n: on_record(&sim.force_n)?,
        sources: Sources::default(),
    })
}

/// The metrics of every compared channel, given as (channel, recorded, simulated).
fn compare_channels(
    series: Vec<(Channel, Vec<f64>, Vec<f64>)>,
    rate: SampleRate,
    t_s: &[f64],
    settings: &Settings,
) -> Result<Vec<ComparedChannel>> {
    let mut comparator =
        Comparator::new(rate.hz(), t_s[0], settings.max_lag_s).map_err(CompareError::Settings)?;
    if let Some(w) = settings.window {
        comparator = comparator
            .with_window_s(w.start_s, w.end_s)
            .map_err(CompareError::Settings)?;
    }
    let mut channels = Vec::new();
    for (channel, recorded, simulated) in series {
        let metrics = comparator
            .compare(&recorded, &simulated)
            .map_err(|source| CompareError::Metrics { channel, source })?;
        channels.push(ComparedChannel {
            channel,
            recorded,
            simulated,
            metrics,
        });
    }
    Ok(channels)
}

/// The velocity of a recording without one, over the whole recording, and how it was made:
/// the crossover estimate from `u_m` and `a_m_s2`
/// ([`platen_signal::CrossoverVelocity::standard`]), or the derivative of `u_m` when there is
/// no acceleration either.
fn recorded_velocity(recording: &Recording, rate: SampleRate) -> Result<(Vec<f64>, String)> {
    let u = recording.table.column("u_m").unwrap_or_default();
    match recording.table.column("a_m_s2") {
        Some(a) => {
            let v = CrossoverVelocity::standard(rate.hz())
                .and_then(|c| c.estimate(u, a))
                .map_err(|e| CompareError::Derived {
                    recorded: recording.path.clone(),
                    channel: Channel::Velocity,
                    source: e,
                })?;
            Ok((
                v,
                format!(
                    "the recorded velocity is the crossover estimate from its u_m \
                     (differentiated, below {} Hz) and a_m_s2 (integrated, above)",
                    DEFAULT_CROSSOVER_HZ
                ),
            ))
        }
        None => Ok((
            differentiate(u, rate),
            "nor an a_m_s2 column: the recorded velocity is the derivative of its u_m".into(),
        )),
    }
}

/// The recorded quantities on `range`, with substitutes for the columns the file lacks.
fn recorded_quantities(
    recording: &Recording,
    range: &Range<usize>,
    direction: Direction,
    simulated: &Quantities,
    rate: SampleRate,
) -> Result<Quantities> {
    let name = recording.path.display();
    let take = |key: &str| recording.column(key, range);
    let mut notes = Vec::new();
    let (u, v, a, f) = (take("u_m"), take("v_m_s"), take("a_m_s2"), take("force_n"));
    let (u_m, v_m_s, a_m_s2, force_n, loops, dissipative);
    match direction {
        Direction::Forward => {
            // u is required for a forward comparison; a missing velocity is estimated as a
            // table's data system does, over the whole recording (then cut to the range).
            u_m = u.unwrap_or_default();
            v_m_s = match v {
                Some(v) => v,
                None => {
                    let (velocity, how) = recorded_velocity(recording, rate)?;
                    notes.push(format!("`{name}` has no v_m_s column: {how}."));
                    velocity[range.clone()].to_vec()
                }
            };
            a_m_s2 = a.unwrap_or_else(|| {
                notes.push(format!(
                    "`{name}` has no a_m_s2 column: the recorded acceleration is the derivative \
                     of its velocity."
                ));
                differentiate(&v_m_s, rate)
            });
            force_n = f.unwrap_or_else(|| simulated.force_n.clone());
            loops = "force, displacement, velocity and acceleration as in the file, unfiltered";
            dissipative = "recorded force, motion and acceleration, unfiltered";
        }
        Direction::Inverse => {
            force_n = f.unwrap_or_default();
            if u.is_none() {
                notes.push(format!(
                    "`{name}` has no u_m column: the recorded loops use the prescribed motion."
                ));
            }
            u_m = u.unwrap_or_else(|| simulated.u_m.clone());
            v_m_s = v.unwrap_or_else(|| simulated.v_m_s.clone());
            a_m_s2 = a.unwrap_or_else(|| simulated.a_m_s2.clone());
            loops = "recorded force against the recorded motion, unfiltered";
            dissipative = "recorded force and motion, unfiltered";
        }
    }
    Ok(Quantities {
        u_m,
        v_m_s,
        a_m_s2,
        force_n,
        sources: Sources {
            loops: loops.into(),
            dissipative: dissipative.into(),
            notes,
        },
    })
}

/// `F_A − F_I − F_E` of the recorded data (less the base shear `B` of a specimen run), and
/// the model's law `sign(v)·D(0, |v|)` over the recorded velocity range (with the jump at
/// v = 0 drawn as the vertical segment ±F_s).
fn dissipative<M: PlatenModel + ?Sized>(
    model: &M,
    rec: &Quantities,
    base_shear_n: Option<&[f64]>,
    form: &str,
) -> (Vec<f64>, Vec<(f64, f64)>, String) {
    let fd: Vec<f64> = (0..rec.u_m.len())
        .map(|i| {
            let terms = force_terms(model, rec.u_m[i], rec.v_m_s[i], rec.a_m_s2[i]);
            let b = base_shear_n.map_or(0.0, |b| b[i]);
            rec.force_n[i] - terms.inertial_n - terms.elastic_n - b
        })
        .collect();
    let (lo, hi) = rec
        .v_m_s
        .iter()
        .fold((0.0f64, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let steps = 400;
    let mut law = Vec::with_capacity(2 * steps + 2);
    for j in 0..=steps {
        let v = lo * (1.0 - j as f64 / steps as f64);
        law.push((v, -model.dissipative_magnitude_n(0.0, -v)));
    }
    for j in 0..=steps {
        let v = hi * j as f64 / steps as f64;
        law.push((v, model.dissipative_magnitude_n(0.0, v)));
    }
    (fd, law, format!("F_D(v) {form}"))
}
