//! `excitation` → what a scenario runs ([`Run`]): the record or generated waveform, read,
//! checked against the duration, low-passed (forces) or integrated (ground motions).

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::Path;

use platen_integrate::{Dopri5Settings, ForceRecord, IntegrateError, Method, Motion, Rk4, State};

use crate::rig::LoopSettings;
use platen_io::columns::ColumnMap;
use platen_io::IoError;
use platen_model::STANDARD_GRAVITY_M_S2;

use crate::ctx::{check_finite, check_positive, Ctx};
use crate::error::{Result, ScenarioError};
use crate::file::*;
use crate::generate::{self, GenerateError};
use crate::sampling::{sampling_grid, uniform_step_s};

/// What a scenario runs: what the rig ([`crate::Rig`]) does.
#[derive(Debug, Clone, PartialEq)]
pub enum Run {
    /// Force-driven: the force record drives the model forward.
    Forward {
        /// The actuator force.
        record: ForceRecord,
        /// Integrator settings.
        integrator: Method,
        /// State at the first sample.
        initial: State,
        /// Output samples (the first `samples` of the record).
        samples: usize,
    },
    /// Motion-driven: the force the motion needs.
    Inverse {
        /// The prescribed motion (already cut to the duration).
        motion: Motion,
    },
    /// Commanded: the rig's table system drives the platen to follow a displacement
    /// command, forward (a rig with a `table_system` and a motion excitation).
    ClosedLoop {
        /// The displacement command, with its velocity and acceleration (already cut to
        /// the duration).
        command: Motion,
        /// The loop's integrator and the platen's initial state.
        settings: LoopSettings,
    },
}

impl Run {
    /// The times of the first and last output sample, s: known before the run, so that
    /// inputs that must cover them (a recorded test to compare with) are checked first.
    pub fn time_span_s(&self) -> (f64, f64) {
        let (t, n) = match self {
            Run::Forward {
                record, samples, ..
            } => (record.t_s(), *samples),
            Run::Inverse { motion } => (motion.t_s(), motion.len()),
            Run::ClosedLoop { command, .. } => (command.t_s(), command.len()),
        };
        match n.checked_sub(1).and_then(|last| t.get(last)) {
            Some(&end) => (t[0], end),
            None => (f64::NAN, f64::NAN),
        }
    }

    /// The same run with its excitation multiplied by `k`: the force record, or the
    /// prescribed (or commanded) displacement, velocity and acceleration. `k = 1` borrows this run, so a
    /// sweep's unscaled cases copy no record.
    ///
    /// # Errors
    /// The record's checks ([`ForceRecord::new`], [`Motion::new`]) when a scaled value is
    /// not finite.
    pub fn scaled(&self, k: f64) -> std::result::Result<Cow<'_, Run>, IntegrateError> {
        if k == 1.0 {
            return Ok(Cow::Borrowed(self));
        }
        let times = |c: &[f64]| c.iter().map(|x| x * k).collect();
        Ok(Cow::Owned(match self {
            Run::Forward {
                record,
                integrator,
                initial,
                samples,
            } => Run::Forward {
                record: ForceRecord::new(record.t_s().to_vec(), times(record.force_n()))?,
                integrator: *integrator,
                initial: *initial,
                samples: *samples,
            },
            Run::Inverse { motion } => Run::Inverse {
                motion: scaled_motion(motion, k)?,
            },
            Run::ClosedLoop { command, settings } => Run::ClosedLoop {
                command: scaled_motion(command, k)?,
                settings: *settings,
            },
        }))
    }

    /// Number of output samples: the force record's first `samples`, the motion's or the
    /// command's every sample.
    pub fn samples(&self) -> usize {
        match self {
            Run::Forward { samples, .. } => *samples,
            Run::Inverse { motion } => motion.len(),
            Run::ClosedLoop { command, .. } => command.len(),
        }
    }

    /// The direction of the run: `"forward"` (a force, or a command through the loop,
    /// integrated forward) or `"inverse"` (the force a motion needs).
    pub fn direction(&self) -> &'static str {
        match self {
            Run::Forward { .. } | Run::ClosedLoop { .. } => "forward",
            Run::Inverse { .. } => "inverse",
        }
    }
}

/// `motion` with its displacement, velocity and acceleration multiplied by `k`.
fn scaled_motion(motion: &Motion, k: f64) -> std::result::Result<Motion, IntegrateError> {
    let times = |c: &[f64]| c.iter().map(|x| x * k).collect();
    let scaled = Motion::new(
        motion.t_s().to_vec(),
        times(motion.u_m()),
        times(motion.v_m_s()),
        times(motion.a_m_s2()),
    )?;
    // The dead band is the velocity measurement's resolution: not scaled.
    Ok(match motion.rest_velocity_m_s() {
        Some(band) => scaled.with_rest_velocity(band)?,
        None => scaled,
    })
}

/// Number of samples of a record of `len` samples at interval `dt` that `duration_s` covers.
fn samples_for(
    ctx: &Ctx,
    record_path: &Path,
    duration_s: Option<f64>,
    dt: f64,
    len: usize,
) -> Result<usize> {
    let Some(d) = duration_s else { return Ok(len) };
    check_positive(ctx, "duration_s", d)?;
    // Tolerate rounding of the duration to about a millionth of a sample.
    // In f64 first: a duration far past the record (1e300 s) saturates `as usize`.
    let intervals = (d / dt + 1e-6).floor();
    if intervals >= len as f64 {
        return Err(ScenarioError::RecordTooShort {
            path: record_path.to_owned(),
            span_s: len.saturating_sub(1) as f64 * dt,
            samples: Some(len),
            duration_s: d,
        });
    }
    let n = intervals as usize + 1;
    if n > len {
        return Err(ScenarioError::RecordTooShort {
            path: record_path.to_owned(),
            span_s: (len - 1) as f64 * dt,
            samples: Some(len),
            duration_s: d,
        });
    }
    Ok(n)
}

/// The one source of an `excitation`, validated: exactly one is present by construction.
#[derive(Clone, Copy)]
enum Source<'a> {
    ForceCsv(&'a Path),
    MotionCsv(&'a Path),
    SineForce(&'a SineForce),
    SineMotion(&'a PerAxisOr<SineMotion>),
    TriangleMotion(&'a PerAxisOr<TriangleMotion>),
    WhiteNoiseMotion(&'a PerAxisOr<WhiteNoiseMotion>),
    GroundMotion(&'a GroundMotionSpec),
}

impl<'a> Source<'a> {
    /// The one source of `ex`, or an error listing those given.
    fn of(ctx: &Ctx, ex: &'a ExcitationSpec) -> Result<Self> {
        let given = Source::given(ex);
        match given.as_slice() {
            [source] => Ok(*source),
            _ => {
                let names: Vec<&str> = given.iter().map(|source| source.name()).collect();
                Err(ctx.invalid(
                    "excitation",
                    format!("{{{}}}", names.join(", ")),
                    "exactly one of force_csv, motion_csv, sine_force, sine_motion, triangle_motion, white_noise_motion, ground_motion",
                ))
            }
        }
    }

    /// Every source `ex` names.
    fn given(ex: &'a ExcitationSpec) -> Vec<Source<'a>> {
        [
            ex.force_csv.as_deref().map(Source::ForceCsv),
            ex.motion_csv.as_deref().map(Source::MotionCsv),
            ex.sine_force.as_ref().map(Source::SineForce),
            ex.sine_motion.as_ref().map(Source::SineMotion),
            ex.triangle_motion.as_ref().map(Source::TriangleMotion),
            ex.white_noise_motion.as_ref().map(Source::WhiteNoiseMotion),
            ex.ground_motion.as_ref().map(Source::GroundMotion),
        ]
        .into_iter()
        .flatten()
        .collect()
    }

    /// The key of this source in `excitation`.
    fn name(self) -> &'static str {
        match self {
            Source::ForceCsv(_) => "force_csv",
            Source::MotionCsv(_) => "motion_csv",
            Source::SineForce(_) => "sine_force",
            Source::SineMotion(_) => "sine_motion",
            Source::TriangleMotion(_) => "triangle_motion",
            Source::WhiteNoiseMotion(_) => "white_noise_motion",
            Source::GroundMotion(_) => "ground_motion",
        }
    }

    /// Whether the source is a force (a forward run) rather than a motion (an inverse run).
    fn is_force(self) -> bool {
        matches!(self, Source::ForceCsv(_) | Source::SineForce(_))
    }
}

/// The keys of the sources `ex` names (none for a scenario whose records are given in
/// memory: [`crate::PlatenScenario::from_arrays`]).
pub(crate) fn named_sources(ex: &ExcitationSpec) -> Vec<&'static str> {
    Source::given(ex).into_iter().map(Source::name).collect()
}

/// What the scenario file's excitation, integrator, initial state and duration run, and
/// which channels of the excitation were derived (not given by the file or generator).
pub(crate) fn build_run(ctx: &Ctx, file: &ScenarioFile) -> Result<(Run, Derived)> {
    let source = Source::of(ctx, &file.excitation)?;
    check_direction_fields(ctx, file, source.is_force())?;
    let (run, derived) = build_source(ctx, file, source)?;
    Ok((with_rest_velocity(ctx, file, run)?, derived))
}

/// An inverse run with the excitation's velocity dead band (`rest_velocity_m_s`), if any.
pub(crate) fn with_rest_velocity(ctx: &Ctx, file: &ScenarioFile, run: Run) -> Result<Run> {
    let here = "excitation.rest_velocity_m_s";
    let band = (file.excitation.rest_velocity_m_s)
        .map(|b| check_positive(ctx, here, b))
        .transpose()?;
    Ok(match (run, band) {
        (Run::Inverse { motion }, Some(band)) => Run::Inverse {
            motion: motion
                .with_rest_velocity(band)
                .map_err(|e| ctx.invalid(here, band, e.to_string()))?,
        },
        (run, _) => run,
    })
}

/// The run of the excitation's one source.
fn build_source(ctx: &Ctx, file: &ScenarioFile, source: Source) -> Result<(Run, Derived)> {
    let ex = &file.excitation;
    let nothing = |run: Run| (run, Derived::new());
    let generated = |g: MotionGenerator| {
        let here = format!("excitation.{}", source.name());
        generate_motion(ctx, file, &here, g).map(|motion| nothing(Run::Inverse { motion }))
    };
    match source {
        Source::ForceCsv(rel) => force_csv_run(ctx, file, &ctx.resolve(rel)).map(nothing),
        Source::SineForce(g) => {
            let gen = Generated {
                ctx,
                file,
                here: "excitation.sine_force".to_owned(),
            };
            let record = generate::sine_force(
                g.amplitude_n,
                g.frequency_hz,
                g.ramp_s,
                g.sample_rate_hz,
                gen.duration()?,
            )
            .map_err(|e| gen.error(e))?;
            let samples = record.len();
            let record = lowpass(ctx, ex, record, samples)?;
            forward_run(ctx, file, record, samples, None).map(nothing)
        }
        Source::MotionCsv(rel) => motion_csv(ctx, file, &ctx.resolve(rel)),
        Source::SineMotion(g) => generated(MotionGenerator::Sine(single(ctx, source, g)?)),
        Source::TriangleMotion(g) => generated(MotionGenerator::Triangle(single(ctx, source, g)?)),
        Source::WhiteNoiseMotion(g) => {
            generated(MotionGenerator::WhiteNoise(single(ctx, source, g)?))
        }
        Source::GroundMotion(g) => {
            let here = "excitation.ground_motion";
            let g = single(ctx, source, g)?;
            let motion = ground_motion(ctx, here, g, file.duration_s)?;
            let integral = "exact integral of a_m_s2 (straight lines between the record's samples)";
            let derived = Derived::from([
                ("v_m_s", integral.to_owned()),
                ("u_m", format!("{integral}, twice")),
            ]);
            Ok((Run::Inverse { motion }, derived))
        }
    }
}

/// The one generator or record of a uniaxial excitation; one per axis is refused.
fn single<'a, T>(ctx: &Ctx, source: Source, given: &'a PerAxisOr<T>) -> Result<&'a T> {
    given.single().ok_or_else(|| {
        ctx.invalid(
            &format!("excitation.{}", source.name()),
            "(per axis)",
            "one source: sources per axis (x, y, z) need a multi-axis `table`",
        )
    })
}

/// A generated motion of the excitation (one axis's, on a multi-axis table).
#[derive(Clone, Copy)]
pub(crate) enum MotionGenerator<'a> {
    /// `sine_motion`.
    Sine(&'a SineMotion),
    /// `triangle_motion`.
    Triangle(&'a TriangleMotion),
    /// `white_noise_motion`.
    WhiteNoise(&'a WhiteNoiseMotion),
}

impl<'a> MotionGenerator<'a> {
    /// The generators of `ex` per axis (x, y, z), with their key, if `ex` has one given
    /// per axis.
    pub(crate) fn per_axis(ex: &'a ExcitationSpec) -> Option<(&'static str, [Option<Self>; 3])> {
        fn each<'a, T>(
            g: &'a PerAxisOr<T>,
            wrap: fn(&'a T) -> MotionGenerator<'a>,
        ) -> Option<[Option<MotionGenerator<'a>>; 3]> {
            g.per_axis().map(|a| a.each().map(|(_, g)| g.map(wrap)))
        }
        if let Some(g) = &ex.sine_motion {
            return each(g, MotionGenerator::Sine).map(|a| ("sine_motion", a));
        }
        if let Some(g) = &ex.triangle_motion {
            return each(g, MotionGenerator::Triangle).map(|a| ("triangle_motion", a));
        }
        if let Some(g) = &ex.white_noise_motion {
            return each(g, MotionGenerator::WhiteNoise).map(|a| ("white_noise_motion", a));
        }
        None
    }

    /// The generator's sample rate, Hz.
    pub(crate) fn sample_rate_hz(self) -> f64 {
        match self {
            MotionGenerator::Sine(g) => g.sample_rate_hz,
            MotionGenerator::Triangle(g) => g.sample_rate_hz,
            MotionGenerator::WhiteNoise(g) => g.sample_rate_hz,
        }
    }
}

/// The motion of generator `g`, over the scenario's `duration_s`; its errors are reported
/// under `here` (`excitation.sine_motion`, or `excitation.sine_motion.x` per axis).
pub(crate) fn generate_motion(
    ctx: &Ctx,
    file: &ScenarioFile,
    here: &str,
    g: MotionGenerator,
) -> Result<Motion> {
    let gen = Generated {
        ctx,
        file,
        here: here.to_owned(),
    };
    match g {
        MotionGenerator::Sine(g) => generate::sine_motion(
            g.amplitude_m,
            g.frequency_hz,
            g.sample_rate_hz,
            gen.duration()?,
        )
        .map_err(|e| gen.error(e)),
        MotionGenerator::Triangle(g) => generate::triangle_motion(
            g.amplitude_m,
            g.velocity_m_s,
            g.reversal_acceleration_m_s2,
            g.sample_rate_hz,
            gen.duration()?,
        )
        .map_err(|e| gen.error(e)),
        MotionGenerator::WhiteNoise(g) => white_noise(&gen, g),
    }
}

/// Fields that only one direction takes: a low-pass (forces), an integrator and an initial
/// state (forward runs).
pub(crate) fn check_direction_fields(ctx: &Ctx, file: &ScenarioFile, is_force: bool) -> Result<()> {
    let ex = &file.excitation;
    if is_force {
        if let Some(band) = ex.rest_velocity_m_s {
            return Err(ctx.invalid(
                "excitation.rest_velocity_m_s",
                band,
                "no velocity dead band on a force: it applies to motion excitations (inverse runs)",
            ));
        }
        return Ok(());
    }
    if ex.lowpass_hz.is_some() || ex.lowpass_filter.is_some() {
        return Err(ctx.invalid(
            "excitation.lowpass_hz",
            ex.lowpass_hz
                .map_or("(filter only)".to_owned(), |f| f.to_string()),
            "no low-pass on a motion: it applies to force excitations (force_csv, sine_force)",
        ));
    }
    if file.table_system.is_some() {
        // A closed loop: the motion is the command, integrated forward.
        return Ok(());
    }
    if file.integrator.is_some() {
        return Err(ctx.invalid(
            "integrator",
            "{…}",
            "no integrator: a motion-driven (inverse) run integrates nothing",
        ));
    }
    if file.initial.is_some() {
        return Err(ctx.invalid(
            "initial",
            "{…}",
            "no initial state: a motion-driven (inverse) run starts from its motion",
        ));
    }
    Ok(())
}

/// A generated excitation: it has no length of its own, and its generator's errors are
/// reported under its own key.
struct Generated<'a> {
    ctx: &'a Ctx<'a>,
    file: &'a ScenarioFile,
    /// The generator's JSON path (`excitation.sine_motion`, `excitation.sine_motion.x`).
    here: String,
}

impl Generated<'_> {
    /// The scenario's `duration_s`, which a generated excitation requires.
    fn duration(&self) -> Result<f64> {
        self.file.duration_s.ok_or_else(|| {
            self.ctx.invalid(
                "duration_s",
                "(missing)",
                format!("a duration in s: {} has no length of its own", self.here),
            )
        })
    }

    /// A generator's error, under the JSON path of the field it names.
    fn error(&self, e: GenerateError) -> ScenarioError {
        match e {
            GenerateError::Invalid {
                name: "duration_s",
                value,
                expected,
            } => self.ctx.invalid("duration_s", value, expected),
            GenerateError::Invalid {
                name,
                value,
                expected,
            } => self
                .ctx
                .invalid(&format!("{}.{name}", self.here), value, expected),
        }
    }
}

/// `excitation.force_csv`: a recorded force, cut to the duration and low-passed.
fn force_csv_run(ctx: &Ctx, file: &ScenarioFile, path: &Path) -> Result<Run> {
    let ex = &file.excitation;
    let mut cols = read_mapped(ctx, path, ex, &["t_s", "force_n"], &["u_m", "v_m_s"])?;
    let t = cols.remove("t_s").unwrap_or_default();
    let f = cols.remove("force_n").unwrap_or_default();
    let recorded_state = match (cols.get("u_m"), cols.get("v_m_s")) {
        (Some(u), Some(v)) => Some((u[0], v[0])),
        _ => None,
    };
    // Checked here first, so that a bad time column is reported with its line.
    uniform_step_s(path, &t)?;
    let record = ForceRecord::new(t, f).map_err(|cause| rejected(path, cause))?;
    force_run(ctx, file, path, record, recorded_state)
}

/// A forward run of `record` read from `path` (a file, or the caller that gave the arrays),
/// cut to the duration and low-passed.
pub(crate) fn force_run(
    ctx: &Ctx,
    file: &ScenarioFile,
    path: &Path,
    record: ForceRecord,
    recorded_state: Option<(f64, f64)>,
) -> Result<Run> {
    let ex = &file.excitation;
    let samples = samples_for(ctx, path, file.duration_s, record.dt_s(), record.len())?;
    let record = lowpass(ctx, ex, record, samples)?;
    forward_run(ctx, file, record, samples, recorded_state)
}

/// `excitation.motion_csv`: a prescribed motion, cut to the duration. Every channel given is
/// kept; a missing velocity is the crossover estimate from `u_m` and `a_m_s2` when the
/// acceleration is given, else the derivative of `u_m`; a missing acceleration is the
/// derivative of `v_m_s` (or the second derivative of `u_m`).
fn motion_csv(ctx: &Ctx, file: &ScenarioFile, path: &Path) -> Result<(Run, Derived)> {
    let ex = &file.excitation;
    let mut cols = read_mapped(ctx, path, ex, &["t_s", "u_m"], &["v_m_s", "a_m_s2"])?;
    let t = cols.remove("t_s").unwrap_or_default();
    let u = cols.remove("u_m").unwrap_or_default();
    let v = cols.remove("v_m_s");
    let a = cols.remove("a_m_s2");
    motion_run(ctx, file, path, t, u, v, a)
}

/// An inverse run of the motion `t`, `u` (and `v`, `a` where given) read from `path` (a
/// file, or the caller that gave the arrays), cut to the duration; missing velocity and
/// acceleration are derived from the displacement.
pub(crate) fn motion_run(
    ctx: &Ctx,
    file: &ScenarioFile,
    path: &Path,
    t: Vec<f64>,
    u: Vec<f64>,
    v: Option<Vec<f64>>,
    a: Option<Vec<f64>>,
) -> Result<(Run, Derived)> {
    let samples = match file.duration_s {
        None => t.len(),
        Some(d) => {
            check_positive(ctx, "duration_s", d)?;
            let end = t[0] + d;
            if t[t.len() - 1] < end - 1e-9 * d.abs() {
                return Err(ScenarioError::RecordTooShort {
                    path: path.to_owned(),
                    span_s: t[t.len() - 1] - t[0],
                    samples: None,
                    duration_s: d,
                });
            }
            let samples = t.partition_point(|&x| x <= end + 1e-9 * d.abs());
            if samples < 2 && t.len() >= 2 {
                return Err(ctx.invalid(
                    "duration_s",
                    d,
                    format!(
                        "at least one interval of the record `{}` ({} s): a run needs two \
                         samples",
                        path.display(),
                        t[1] - t[0]
                    ),
                ));
            }
            samples
        }
    };
    let cut = |c: Vec<f64>| c[..samples].to_vec();
    // Derived channels are computed on the grid fitted to the stamps (rounded stamps would put
    // their rounding into every finite difference); the output keeps the stamps.
    let grid = sampling_grid(path, &t[..samples])?;
    let on_grid: Vec<f64> = (0..samples)
        .map(|i| grid.start_s + i as f64 * grid.interval_s)
        .collect();
    let stamps = cut(t);
    let mut derived = Derived::new();
    let motion = match (v, a) {
        (Some(v), Some(a)) => Motion::new(stamps, cut(u), cut(v), cut(a)),
        (Some(v), None) => {
            derived.insert("a_m_s2", DERIVATIVE_OF_V.to_owned());
            Motion::from_displacement_velocity(on_grid, cut(u), cut(v))
                .and_then(|m| restamp(stamps, &m))
        }
        (None, Some(a)) => {
            // Keep the recorded acceleration; the velocity is the crossover estimate, as a
            // table's data system makes it (differentiated displacement below the crossover,
            // integrated acceleration above).
            let (u, a) = (cut(u), cut(a));
            let v = platen_signal::CrossoverVelocity::standard(1.0 / grid.interval_s)
                .and_then(|c| c.estimate(&u, &a))
                .map_err(|e| {
                    ScenarioError::Io(IoError::Record {
                        path: path.to_owned(),
                        message: format!("velocity from u_m and a_m_s2: {e}"),
                    })
                })?;
            derived.insert("v_m_s", crossover_note());
            Motion::new(stamps, u, v, a)
        }
        (None, None) => {
            derived.insert("v_m_s", DERIVATIVE_OF_U.to_owned());
            derived.insert("a_m_s2", SECOND_DERIVATIVE_OF_U.to_owned());
            Motion::from_displacement(on_grid, cut(u)).and_then(|m| restamp(stamps, &m))
        }
    }
    .map_err(|cause| rejected(path, cause))?;
    Ok((Run::Inverse { motion }, derived))
}

/// The channels of an excitation that platen derived, by name, with how (what a summary
/// reports under `derived`).
pub type Derived = BTreeMap<&'static str, String>;

const DERIVATIVE_OF_V: &str = "derivative of v_m_s (second-order finite differences)";
const DERIVATIVE_OF_U: &str = "derivative of u_m (second-order finite differences)";
const SECOND_DERIVATIVE_OF_U: &str = "second derivative of u_m (second-order finite differences)";

/// How the crossover velocity is made ([`platen_signal::CrossoverVelocity::standard`]).
fn crossover_note() -> String {
    format!(
        "crossover of u_m (differentiated, below {} Hz) and a_m_s2 (integrated, above)",
        platen_signal::DEFAULT_CROSSOVER_HZ
    )
}

/// `m` at the time stamps `t_s` (same length) instead of its own times.
fn restamp(t_s: Vec<f64>, m: &Motion) -> std::result::Result<Motion, platen_signal::SignalError> {
    Motion::new(
        t_s,
        m.u_m().to_vec(),
        m.v_m_s().to_vec(),
        m.a_m_s2().to_vec(),
    )
}

/// `excitation.white_noise_motion`: band-limited white noise of the given RMS acceleration.
fn white_noise(gen: &Generated, g: &WhiteNoiseMotion) -> Result<Motion> {
    let rms = check_positive(
        gen.ctx,
        &format!("{}.rms_acceleration_g", gen.here),
        g.rms_acceleration_g,
    )?;
    generate::white_noise_motion(
        rms * STANDARD_GRAVITY_M_S2,
        (g.band_hz[0], g.band_hz[1]),
        g.seed,
        g.sample_rate_hz,
        gen.duration()?,
    )
    .map_err(|e| gen.error(e))
}

/// A record the integrator's checks reject.
pub(crate) fn rejected(path: &Path, cause: impl Into<IntegrateError>) -> ScenarioError {
    ScenarioError::RecordRejected {
        path: path.to_owned(),
        cause: cause.into(),
    }
}

/// Reads platen's columns `required` and `optional` from `path` through the excitation's
/// `columns` mapping (file headers and units), in SI units. The time column must increase
/// strictly; a violation names its line.
pub(crate) fn read_mapped(
    ctx: &Ctx,
    path: &Path,
    ex: &ExcitationSpec,
    required: &[&'static str],
    optional: &[&'static str],
) -> Result<BTreeMap<&'static str, Vec<f64>>> {
    let map = match &ex.columns {
        Some(spec) => ColumnMap::new(spec, "excitation.columns")
            .map_err(|(json_path, value, expected)| ctx.invalid(&json_path, value, expected))?,
        None => ColumnMap::default(),
    };
    let mut table = map.read_table(path, required, optional)?;
    let mut out = BTreeMap::new();
    for &ours in required.iter().chain(optional) {
        if let Some(col) = table.take_column(ours) {
            out.insert(ours, col);
        }
    }
    if let Some(t) = out.get("t_s") {
        if let Some(i) = (1..t.len()).find(|&i| t[i] <= t[i - 1]) {
            return Err(IoError::TimeNotIncreasing {
                path: path.to_owned(),
                line: i as u64 + 2,
                previous_s: t[i - 1],
                value_s: t[i],
            }
            .into());
        }
    }
    Ok(out)
}

/// Applies `excitation.lowpass_hz` to the first `samples` samples of a force record (the part
/// that runs), with the chosen zero-phase filter.
fn lowpass(
    ctx: &Ctx,
    ex: &ExcitationSpec,
    record: ForceRecord,
    samples: usize,
) -> Result<ForceRecord> {
    let Some(cutoff) = ex.lowpass_hz else {
        if ex.lowpass_filter.is_some() {
            return Err(ctx.invalid(
                "excitation.lowpass_filter",
                "(set)",
                "a lowpass_hz for the filter to use",
            ));
        }
        return Ok(record);
    };
    let rate = 1.0 / record.dt_s();
    if !(cutoff.is_finite() && cutoff > 0.0 && cutoff < 0.5 * rate) {
        return Err(ctx.invalid(
            "excitation.lowpass_hz",
            cutoff,
            format!(
                "a cut-off between 0 and the record's Nyquist frequency {} Hz",
                0.5 * rate
            ),
        ));
    }
    let input = &record.force_n()[..samples];
    let signal =
        |e: platen_signal::SignalError| ctx.invalid("excitation.lowpass_hz", cutoff, e.to_string());
    use platen_signal::ZeroPhaseFilter;
    let filtered = match ex.lowpass_filter.unwrap_or(LowpassFilter::Brickwall) {
        LowpassFilter::Brickwall => platen_signal::SpectralLowpass::new(samples, cutoff, rate)
            .map_err(signal)?
            .apply(input)
            .map_err(signal)?,
        LowpassFilter::Fir => {
            platen_signal::FirLowpass::new(1024, cutoff, rate, platen_signal::Window::Hamming)
                .map_err(signal)?
                .apply(input)
                .map_err(signal)?
        }
        LowpassFilter::Butterworth => platen_signal::ButterworthLowpass::new(4, cutoff, rate)
            .map_err(signal)?
            .apply(input)
            .map_err(signal)?,
    };
    ForceRecord::new(record.t_s()[..samples].to_vec(), filtered)
        .map_err(|e| ctx.invalid("excitation.lowpass_hz", cutoff, e.to_string()))
}

/// The table motion of an `excitation.ground_motion`: the record scaled, cut to the
/// duration, baseline-corrected and integrated as PEER integrates it
/// ([`platen_signal::AccelerogramMotion`]: straight lines between samples, exact integrals).
pub(crate) fn ground_motion(
    ctx: &Ctx,
    here: &str,
    g: &GroundMotion,
    duration_s: Option<f64>,
) -> Result<Motion> {
    let scale = check_finite(ctx, &format!("{here}.scale"), g.scale)?;
    let rate = check_positive(ctx, &format!("{here}.sample_rate_hz"), g.sample_rate_hz)?;
    let path = platen_io::peer::find_record(ctx.path.parent(), &g.record)?;
    let (acc, dt_s) = read_ground_acceleration(ctx, here, g, &path)?;
    let signal = |name: &str, e: platen_signal::SignalError| {
        ctx.invalid(&format!("{here}.{name}"), "", e.to_string())
    };
    let baseline = match g.baseline {
        BaselineKind::None => platen_signal::Baseline::None,
        BaselineKind::Acceleration => platen_signal::Baseline::Acceleration {
            order: g.baseline_order,
        },
        BaselineKind::Velocity => platen_signal::Baseline::Velocity {
            order: g.baseline_order,
        },
    };
    let plan =
        platen_signal::AccelerogramMotion::new(1.0 / dt_s, rate, baseline).map_err(
            |e| match e {
                platen_signal::SignalError::InvalidCount { .. } => signal("baseline_order", e),
                other => signal("sample_rate_hz", other),
            },
        )?;
    let available = plan.output_len(acc.len());
    if available > generate::MAX_GENERATED_SAMPLES {
        return Err(ctx.invalid(
            &format!("{here}.sample_rate_hz"),
            rate,
            format!(
                "a rate giving at most {} samples for this record",
                generate::MAX_GENERATED_SAMPLES
            ),
        ));
    }
    // The table samples that run, and the record samples that cover them (the baseline is
    // fitted over what runs).
    let (samples, record_samples) = match duration_s {
        None => (available, acc.len()),
        Some(d) => {
            check_positive(ctx, "duration_s", d)?;
            let n = (d * rate + 1e-6).floor() as usize + 1;
            if n > available {
                return Err(ScenarioError::RecordTooShort {
                    path,
                    span_s: (available - 1) as f64 / rate,
                    samples: None,
                    duration_s: d,
                });
            }
            let last = ((n - 1) as f64 / rate / dt_s - 1e-9).ceil() as usize;
            (n, (last + 1).clamp(2, acc.len()))
        }
    };
    let a: Vec<f64> = acc[..record_samples].iter().map(|x| x * scale).collect();
    // The record's own faults (too short, a filter's) are the record's; a motion that cannot
    // be (non-finite) is rejected as a motion file's would be.
    let m = plan.process(&a).map_err(|e| match e {
        platen_signal::SignalError::NonFiniteInput { .. } => rejected(&path, e),
        other => signal("record", other),
    })?;
    m.truncated(samples).map_err(|cause| rejected(&path, cause))
}

/// The ground acceleration of a `ground_motion` record (m/s²) and its sample interval (s):
/// a PEER `.AT2` file, or a CSV read through the record's `columns`.
fn read_ground_acceleration(
    ctx: &Ctx,
    here: &str,
    g: &GroundMotion,
    path: &Path,
) -> Result<(Vec<f64>, f64)> {
    let is_csv = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    Ok(if is_csv {
        let ex = ExcitationSpec {
            columns: g.columns.clone(),
            ..ExcitationSpec::default()
        };
        let mut cols = read_mapped(ctx, path, &ex, &["t_s", "a_m_s2"], &[])?;
        let t = cols.remove("t_s").unwrap_or_default();
        let dt = uniform_step_s(path, &t)?;
        (cols.remove("a_m_s2").unwrap_or_default(), dt)
    } else {
        if g.columns.is_some() {
            return Err(ctx.invalid(
                &format!("{here}.columns"),
                "(set)",
                "columns only for a record given as .csv",
            ));
        }
        let rec = platen_io::peer::read_peer(path)?;
        if rec.quantity != platen_io::peer::Quantity::Acceleration {
            return Err(ScenarioError::NotAcceleration {
                path: path.to_path_buf(),
            });
        }
        (rec.values, rec.dt_s)
    })
}

/// The integrator of a forward run on `record` (`integrator`, default RK4 at the sample
/// interval): the RK4 step must divide the interval fitted over the record.
pub(crate) fn forward_method(
    ctx: &Ctx,
    file: &ScenarioFile,
    record: &ForceRecord,
) -> Result<Method> {
    Ok(match &file.integrator {
        None => Method::Rk4(Rk4::with_steps_per_sample(1).expect("k = 1 is valid")),
        Some(IntegratorSpec::Rk4(Rk4Spec { step_s })) => {
            let step = step_s.unwrap_or(record.dt_s());
            // The step must divide the interval fitted over the record (not one measured
            // between two rounded stamps); the integrator then steps at that interval / k.
            let k = platen_integrate::sampling_grid(record.t_s())
                .and_then(|grid| grid.steps_per_interval(step))
                .map_err(|e| ctx.invalid("integrator.step_s", step, step_expected(&e)))?;
            Method::Rk4(
                Rk4::with_steps_per_sample(k)
                    .map_err(|e| ctx.invalid("integrator.step_s", step, step_expected(&e)))?,
            )
        }
        Some(IntegratorSpec::Dopri5(spec)) => {
            let rtol = spec.rtol.unwrap_or(DEFAULT_RTOL);
            let atol = spec.atol.unwrap_or(DEFAULT_ATOL);
            let settings = Dopri5Settings::new(rtol, atol).map_err(|e| match e {
                platen_integrate::IntegrateError::InvalidTolerance { name, value } => ctx.invalid(
                    &format!("integrator.{name}"),
                    value,
                    "a finite number > 0 (rtol < 1)",
                ),
                other => ctx.invalid("integrator", "", other.to_string()),
            })?;
            Method::Dopri5(settings)
        }
    })
}

fn forward_run(
    ctx: &Ctx,
    file: &ScenarioFile,
    record: ForceRecord,
    samples: usize,
    recorded_state: Option<(f64, f64)>,
) -> Result<Run> {
    let integrator = forward_method(ctx, file, &record)?;
    let initial = file.initial.clone().unwrap_or_default();
    if let Some((key, _)) = initial.table_values().iter().find(|(_, v)| v.is_some()) {
        return Err(ctx.invalid(
            &format!("initial.{key}"),
            "(given)",
            "u_m, v_m_s or from_record: the pose names are a multi-axis table's (`table`)",
        ));
    }
    let (u0, v0) = if initial.from_record {
        if initial.u_m.is_some() || initial.v_m_s.is_some() {
            return Err(ctx.invalid(
                "initial",
                "{from_record, u_m/v_m_s}",
                "either from_record or u_m/v_m_s, not both",
            ));
        }
        match recorded_state {
            Some(state) => state,
            None => {
                return Err(ctx.invalid(
                    "initial.from_record",
                    "true",
                    "a force_csv with u_m and v_m_s columns to take the initial state from",
                ))
            }
        }
    } else {
        (initial.u_m.unwrap_or(0.0), initial.v_m_s.unwrap_or(0.0))
    };
    let u_m = check_finite(ctx, "initial.u_m", u0)?;
    let v_m_s = check_finite(ctx, "initial.v_m_s", v0)?;
    Ok(Run::Forward {
        record,
        integrator,
        initial: State { u_m, v_m_s },
        samples,
    })
}

/// What an RK4 `step_s` must be, for the integrator's rejection `e` of it.
fn step_expected(e: &platen_integrate::IntegrateError) -> String {
    match e {
        platen_integrate::IntegrateError::StepNotDivisor {
            sample_interval_s, ..
        } => format!(
            "a step that divides the sample interval {sample_interval_s} s into a whole number \
             of steps (the interval / k for an integer k >= 1)"
        ),
        platen_integrate::IntegrateError::InvalidStep { .. } => "a finite step > 0 s".into(),
        other => other.to_string(),
    }
}
