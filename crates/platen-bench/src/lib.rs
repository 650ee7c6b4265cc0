//! The workloads of `platen bench`: time the standard workloads on the `lhpost-2008` preset, next to the
//! plain-loop baseline measured in the same run.
//!
//! Workloads, all at 1024 Hz over the same number of simulated seconds (default 600, i.e.
//! 10 minutes), from rest, at 13.8 MPa. The force is a table test the LHPOST can run: a
//! 100 kN, 0.5 Hz sine (the SR9-like test of `scenarios/sr9-like-sine-force.json` without its
//! ramp) moves the platen ±0.35 m at up to 1.09 m/s and 0.38 g, inside the table's ±0.75 m,
//! 1.8 m/s and 4.2 g, and makes it reverse once a second (599 reversals located in 600 s)
//! after breaking away from rest. (Until issue 18 it was a 600 kN sine, which as a scenario
//! reaches 5.3 m, 16 m/s and 5.2 g: a synthetic stress load, not a table test.)
//!
//! * `baseline`: [`baseline::baseline_rk4`] (the one copy the criterion benches use too), the plain RK4 loop on the identified model (no stick logic,
//!   no output) under that force;
//! * `rk4`: [`Method::Rk4`] on the identified model, exact stick-slip, one step per sample,
//!   every output sample kept in memory in a [`Trajectory`] (no file I/O), same force;
//! * `rk4_full`: the same on the full Lagrangian model;
//! * `rk4_specimen`: the `rk4` workload with a 3-storey specimen on the platen
//!   ([`bench_specimen`]: 60 t, fixed-base modes 2.9, 7.6 and 11.3 Hz), through
//!   [`forward_rk4_specimen`];
//! * `dopri5`: [`Method::Dopri5`] at rtol 1e-8, atol 1e-11 on the identified model, same
//!   force, timed per accepted step;
//! * `inverse`: [`inverse`] of the paper's S9 sine motion (0.2 m, 0.6 Hz) on the identified
//!   model, timed per sample;
//! * `table_system`: the closed loop ([`forward_closed_loop`]) of the `lhpost-2008` table
//!   system (controller at 1024 Hz, valves, single-ended actuators, accumulator) on the
//!   identified model, commanded with that S9 motion, at its default step (7 RK4 steps per
//!   controller period, resolving the 246 Hz spool), timed per integration step;
//! * `six_dof`: [`forward_table`] of the six-DOF table of the shipped forward scenario
//!   ([`bench_table`]: 10 actuators, 4 struts, 6 frictionless pads) under the forces that
//!   hold it plus the standard force along x ([`bench_table_forces`]), RK4 at 1/1024 s,
//!   in runs of at most [`SIX_DOF_PIECE_S`] from rest (open loop, its path drifts over
//!   hundreds of seconds), timed per step;
//! * `ensemble` and `ensemble_scalar`: [`ENSEMBLE_LANES`] sweep-like cases (the identified
//!   model at 6.9 and 13.8 MPa under the forward force scaled by 0.9 and 1.1, more cases to
//!   fill the lanes) run by [`forward_rk4_ensemble`] in SIMD lanes, and the same cases run one
//!   after the other by the scalar [`forward_rk4`] (bit for bit the same runs), each case's
//!   peaks only; timed per step per trajectory, so their ratio is the ensemble's gain.
//!
//! The workloads are data ([`workloads`]): one timing loop ([`measure`]) runs them
//! round-robin `repeats` times and the median wall time of each is reported, so that a slow
//! phase of the machine affects all of them alike. The forward runs go through
//! [`ForwardIntegrator`] (one `match` per run, nothing per step). The output buffers are
//! allocated once, outside the timed region, and reused.
//!
//! ```
//! // 0.05 simulated seconds, each workload once (a smoke run, not a measurement).
//! let m = platen_bench::measure(0.05, 1)?;
//! let report = m.report();
//! assert!(report.rk4_ns_per_step > 0.0);
//! assert_eq!(report.workloads["rk4"].units_per_run, 51);
//! # Ok::<(), platen_bench::BenchError>(())
//! ```

pub mod baseline;
mod report;

pub use report::{BenchReport, FinalState, Measurement, WorkloadReport};

use std::collections::BTreeMap;
use std::hint::black_box;
use std::time::Instant;

use serde::Serialize;

use platen_integrate::{
    forward_closed_loop, forward_rk4, forward_rk4_ensemble, forward_rk4_specimen, forward_table,
    forward_table_loop, inverse, ActuatorForces, Dopri5Settings, EnsembleCase, ForceRecord,
    ForwardIntegrator, IntegrateError, LoopMethod, LoopRun, Method, Motion, Peaks, PoseMotion, Rk4,
    State, TableLoopRun, Trajectory, ENSEMBLE_LANES,
};
use platen_model::multi_axis::{Coords, MultiAxisTable};
use platen_model::{preset, FullModel, IdentifiedModel, IdentifiedParams, Specimen, Storey};
use platen_scenario::multi_axis::TableLoopSystem;
use platen_system::TableSystem;

/// Sample rate of every workload, Hz (one RK4 step per sample: h = 1/1024 s).
pub const RATE_HZ: f64 = 1024.0;
/// Hold-down pressure of every workload, Pa.
pub const PRESSURE_PA: f64 = 13.8e6;
/// Amplitude of the sine force of the forward workloads, N (a table test within the LHPOST's
/// limits: see the module's documentation).
pub const FORCE_AMPLITUDE_N: f64 = 100e3;
/// Frequency of the sine force of the forward workloads, Hz.
pub const FORCE_FREQUENCY_HZ: f64 = 0.5;
/// Amplitude of the sine motion of the inverse and closed-loop workloads (the paper's S9), m.
pub const MOTION_AMPLITUDE_M: f64 = 0.2;
/// Frequency of the sine motion of the inverse and closed-loop workloads, Hz.
pub const MOTION_FREQUENCY_HZ: f64 = 0.6;
/// Relative tolerance of the Dopri5 workload.
const DOPRI5_RTOL: f64 = 1e-8;
/// Absolute tolerance of the Dopri5 workload.
const DOPRI5_ATOL: f64 = 1e-11;

/// Why the workloads could not be built or run.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// Too short a duration: every workload needs at least 3 samples.
    #[error("{seconds_s} s gives {samples} samples at 1024 Hz; at least 3 are needed")]
    TooShort {
        /// The simulated duration asked for, s.
        seconds_s: f64,
        /// The samples it gives at [`RATE_HZ`].
        samples: usize,
    },
    /// A model, specimen or settings value of the workloads was refused.
    #[error("bench {what}: {source}")]
    Model {
        /// Which input.
        what: &'static str,
        /// The model's error.
        source: platen_model::ModelError,
    },
    /// A record or a run of a workload failed.
    #[error("bench {what}: {source}")]
    Integrate {
        /// Which record or run.
        what: &'static str,
        /// The integrator's error.
        source: IntegrateError,
    },
    /// The motion of the inverse and closed-loop workloads was refused.
    #[error("bench motion: {0}")]
    Motion(#[from] platen_signal::SignalError),
    /// The six-DOF workload's table or forces were refused (a defect).
    #[error("bench six-DOF table: {0}")]
    Table(String),
}

/// The result of the module's functions.
pub type Result<T, E = BenchError> = std::result::Result<T, E>;

/// `what` as the context of a model error.
fn model<T>(what: &'static str, r: platen_model::Result<T>) -> Result<T> {
    r.map_err(|source| BenchError::Model { what, source })
}

/// `what` as the context of an integrator error.
fn integrate<T>(what: &'static str, r: platen_integrate::Result<T>) -> Result<T> {
    r.map_err(|source| BenchError::Integrate { what, source })
}

/// Which model a forward workload runs.
#[derive(Debug, Clone, Copy)]
enum Form {
    /// The identified model (Eq. 22/23).
    Identified,
    /// The full Lagrangian model (Eq. 1–8).
    Full,
}

/// What a workload runs.
#[derive(Debug, Clone, Copy)]
enum Job {
    /// [`baseline::baseline_rk4`] on the identified parameters; one unit per step.
    Baseline,
    /// A forward run of a model with a method; one unit per accepted step (every step for
    /// the RK4).
    Forward(Form, Method),
    /// [`forward_rk4_specimen`] on the identified model with [`bench_specimen`]; one unit per
    /// step.
    ForwardSpecimen(Rk4),
    /// [`inverse`] of the motion on the identified model; one unit per sample.
    Inverse,
    /// [`forward_closed_loop`] of the preset's table system commanded with the motion; one
    /// unit per integration step.
    TableSystem,
    /// [`forward_rk4_ensemble`] of the ensemble cases; one unit per step per trajectory.
    Ensemble(Rk4),
    /// [`forward_table`] of the six-DOF table ([`bench_table`]); one unit per step.
    SixDof(Rk4),
    /// [`forward_table_loop`] of the LHPOST6 preset commanded with the motion along x; one
    /// unit per integration step.
    SixDofClosedLoop,
    /// [`forward_rk4`] of each ensemble case in turn; one unit per step per trajectory.
    EnsembleScalar(Rk4),
}

/// One timed workload and its measured runs.
#[derive(Debug, Clone)]
pub struct Workload {
    /// Its key in the report (`rk4`, `dopri5`, …).
    pub key: &'static str,
    /// Its line in the text table.
    pub title: &'static str,
    /// What one unit of work is ("step", "accepted step", "sample").
    pub unit: &'static str,
    job: Job,
    /// Units of work per run (steps, accepted steps or samples).
    pub units: u64,
    /// Wall time of each run, s.
    pub times_s: Vec<f64>,
}

impl Workload {
    fn new(key: &'static str, title: &'static str, unit: &'static str, job: Job) -> Self {
        Self {
            key,
            title,
            unit,
            job,
            units: 0,
            times_s: Vec::new(),
        }
    }

    /// The median wall time of its runs, s.
    pub fn median_s(&self) -> f64 {
        let mut t = self.times_s.clone();
        t.sort_by(f64::total_cmp);
        let n = t.len();
        if n % 2 == 1 {
            t[n / 2]
        } else {
            0.5 * (t[n / 2 - 1] + t[n / 2])
        }
    }

    /// The median time per unit of work, ns.
    pub fn ns_per_unit(&self) -> f64 {
        self.median_s() * 1e9 / self.units as f64
    }

    /// Its entry in the report's `workloads`, for records of `simulated_s` seconds.
    pub fn report(&self, simulated_s: f64) -> WorkloadReport {
        let median = self.median_s();
        WorkloadReport {
            median_wall_s: median,
            min_wall_s: self.times_s.iter().copied().fold(f64::INFINITY, f64::min),
            ns_per_unit: self.ns_per_unit(),
            runs: self.times_s.len(),
            simulated_s_per_wall_s: simulated_s / median,
            unit: self.unit,
            units_per_run: self.units,
            units_per_s: self.units as f64 / median,
        }
    }
}

/// The standard workloads, in the order they run and are reported, not yet measured.
pub fn workloads() -> Result<Vec<Workload>> {
    let rk4 = integrate("RK4 settings", Rk4::with_steps_per_sample(1))?;
    let dopri5 = Method::Dopri5(integrate(
        "Dopri5 settings",
        Dopri5Settings::new(DOPRI5_RTOL, DOPRI5_ATOL),
    )?);
    Ok(vec![
        Workload::new(
            "baseline",
            "baseline: plain RK4 loop, no stick logic, no output",
            "step",
            Job::Baseline,
        ),
        Workload::new(
            "rk4",
            "rk4: identified model, exact stick-slip, output kept",
            "step",
            Job::Forward(Form::Identified, Method::Rk4(rk4)),
        ),
        Workload::new(
            "rk4_full",
            "rk4_full: full model, exact stick-slip, output kept",
            "step",
            Job::Forward(Form::Full, Method::Rk4(rk4)),
        ),
        Workload::new(
            "rk4_specimen",
            "rk4_specimen: rk4 with a 3-storey specimen",
            "step",
            Job::ForwardSpecimen(rk4),
        ),
        Workload::new(
            "dopri5",
            "dopri5: rtol 1e-8, identified model, output kept",
            "accepted step",
            Job::Forward(Form::Identified, dopri5),
        ),
        Workload::new(
            "inverse",
            "inverse: S9 sine motion, identified model, output kept",
            "sample",
            Job::Inverse,
        ),
        Workload::new(
            "table_system",
            "table_system: closed loop, S9 command, output kept",
            "step",
            Job::TableSystem,
        ),
        Workload::new(
            "six_dof",
            "six_dof: 6-DOF table, 10 actuators, 4 struts, 6 pads, output kept",
            "step",
            Job::SixDof(rk4),
        ),
        Workload::new(
            "six_dof_closed_loop",
            "six_dof_closed_loop: LHPOST6 preset, closed loop, S9 along x",
            "step",
            Job::SixDofClosedLoop,
        ),
        Workload::new(
            "ensemble_scalar",
            "ensemble_scalar: sweep-like cases one by one, peaks",
            "step",
            Job::EnsembleScalar(rk4),
        ),
        Workload::new(
            "ensemble",
            "ensemble: the same cases in SIMD lanes, peaks",
            "step",
            Job::Ensemble(rk4),
        ),
    ])
}

/// The sine force of the forward workloads scaled to `amplitude_n` ([`FORCE_FREQUENCY_HZ`]),
/// `samples` samples at [`RATE_HZ`] from `t = 0`, N.
pub fn sine_force_n(amplitude_n: f64, samples: usize) -> Vec<f64> {
    let w = 2.0 * std::f64::consts::PI * FORCE_FREQUENCY_HZ;
    (0..samples)
        .map(|j| amplitude_n * (w * j as f64 / RATE_HZ).sin())
        .collect()
}

/// The paper's S9 sine motion ([`MOTION_AMPLITUDE_M`] at [`MOTION_FREQUENCY_HZ`]) with its
/// exact velocity and acceleration, `samples` samples at [`RATE_HZ`] from `t = 0`: the
/// inverse workload's motion and the closed-loop workload's command.
pub fn s9_motion(samples: usize) -> Result<Motion> {
    let w = 2.0 * std::f64::consts::PI * MOTION_FREQUENCY_HZ;
    let t: Vec<f64> = (0..samples).map(|j| j as f64 / RATE_HZ).collect();
    Ok(Motion::new(
        t.clone(),
        t.iter()
            .map(|&t| MOTION_AMPLITUDE_M * (w * t).sin())
            .collect(),
        t.iter()
            .map(|&t| MOTION_AMPLITUDE_M * w * (w * t).cos())
            .collect(),
        t.iter()
            .map(|&t| -MOTION_AMPLITUDE_M * w * w * (w * t).sin())
            .collect(),
    )?)
}

/// The 3-storey specimen of the `rk4_specimen` workload: 20 t floors, storey stiffnesses 40,
/// 32 and 24 MN/m, stiffness-proportional storey dampers (3 ms times each stiffness: 2.8 % of
/// critical in the first mode). Fixed-base modes near 2.9, 7.6 and 11.3 Hz.
pub fn bench_specimen() -> Result<Specimen> {
    let storey = |k: f64| Storey {
        mass_kg: 20e3,
        stiffness_n_per_m: k,
        damping_n_s_per_m: 3e-3 * k,
    };
    model(
        "specimen",
        Specimen::new(vec![storey(40e6), storey(32e6), storey(24e6)]),
    )
}

/// The inputs every workload shares, built outside the timed region.
pub struct Inputs {
    /// Samples of every record.
    samples: usize,
    force: Vec<f64>,
    record: ForceRecord,
    motion: Motion,
    identified_params: IdentifiedParams,
    identified: IdentifiedModel,
    full: FullModel,
    specimen: Specimen,
    system: TableSystem,
    /// The six-DOF table and its actuator forces.
    table: MultiAxisTable,
    table_forces: ActuatorForces,
    /// The LHPOST6 preset, its closed loop, and the motion as its command along x.
    lhpost6: (MultiAxisTable, TableLoopSystem, PoseMotion),
    /// The models and force records of the ensemble cases.
    ensemble_models: Vec<IdentifiedModel>,
    ensemble_records: Vec<ForceRecord>,
}

impl Inputs {
    /// The records of `samples` samples at [`RATE_HZ`], the models, the specimen, the table
    /// system and the ensemble cases.
    pub fn new(samples: usize) -> Result<Self> {
        let force = sine_force_n(FORCE_AMPLITUDE_N, samples);
        let record = integrate(
            "force record",
            ForceRecord::from_rate(RATE_HZ, force.clone()),
        )?;
        let identified_params = preset::lhpost_2008_identified(PRESSURE_PA);
        let (mut ensemble_models, mut ensemble_records) = (Vec::new(), Vec::new());
        for case in 0..ENSEMBLE_LANES {
            let scale = [0.9, 1.1][case / 2 % 2] + 0.05 * (case / 4) as f64;
            let pressure_pa = [6.9e6, PRESSURE_PA][case % 2];
            ensemble_models.push(model(
                "ensemble model",
                preset::lhpost_2008_identified(pressure_pa).build(),
            )?);
            let scaled = force.iter().map(|f| f * scale).collect();
            ensemble_records.push(integrate(
                "ensemble record",
                ForceRecord::from_rate(RATE_HZ, scaled),
            )?);
        }
        let table = bench_table()?;
        let table_forces = bench_table_forces(&table, samples.min(samples_for(SIX_DOF_PIECE_S)))?;
        let motion = s9_motion(samples)?;
        Ok(Self {
            samples,
            table,
            table_forces,
            lhpost6: bench_lhpost6(&motion)?,
            force,
            record,
            motion,
            identified: model("identified model", identified_params.build())?,
            identified_params,
            full: model(
                "full model",
                preset::lhpost_2008_physical(PRESSURE_PA).build(),
            )?,
            specimen: bench_specimen()?,
            system: platen_system::preset::lhpost_2008(),
            ensemble_models,
            ensemble_records,
        })
    }

    /// The ensemble cases, from rest.
    fn ensemble_cases(&self) -> Vec<EnsembleCase<'_>> {
        self.ensemble_models
            .iter()
            .zip(&self.ensemble_records)
            .map(|(model, record)| EnsembleCase {
                model,
                record,
                initial: State::default(),
            })
            .collect()
    }
}

/// Times `f` once, s.
fn time<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let start = Instant::now();
    let out = f();
    (start.elapsed().as_secs_f64(), out)
}

/// A job's wall time, s, its units of work, and, for the baseline, its final state.
type Timed = (f64, u64, Option<State>);

impl Job {
    /// Runs the job once on `inputs` into `out` (emptied first) and returns its wall time, s,
    /// its units of work, and, for the baseline, its final state.
    fn run_once(self, inputs: &Inputs, out: &mut Trajectory) -> Result<Timed> {
        match self {
            Job::Baseline => Ok(time_baseline(inputs)),
            Job::Forward(form, method) => time_forward(form, method, inputs, out),
            Job::ForwardSpecimen(rk4) => time_forward_specimen(rk4, inputs, out),
            Job::TableSystem => time_table_system(inputs, out),
            Job::Ensemble(rk4) => time_ensemble(rk4, inputs),
            Job::EnsembleScalar(rk4) => time_ensemble_scalar(rk4, inputs),
            Job::Inverse => Ok(time_inverse(inputs, out)),
            Job::SixDof(rk4) => time_six_dof(rk4, inputs),
            Job::SixDofClosedLoop => time_six_dof_closed_loop(inputs),
        }
    }
}

/// [`Job::Baseline`].
fn time_baseline(inputs: &Inputs) -> Timed {
    let (s, end) = time(|| {
        baseline::baseline_rk4(
            black_box(&inputs.identified_params),
            black_box(&inputs.force),
            black_box(1.0 / RATE_HZ),
            State::default(),
        )
    });
    (s, (inputs.samples - 1) as u64, Some(black_box(end)))
}

/// [`Job::Forward`].
fn time_forward(
    form: Form,
    method: Method,
    inputs: &Inputs,
    out: &mut Trajectory,
) -> Result<Timed> {
    let samples = inputs.samples;
    clear(out);
    let record = black_box(&inputs.record);
    let initial = State::default();
    let (s, stats) = match form {
        Form::Identified => time(|| {
            let model = black_box(&inputs.identified);
            method.forward(model, record, initial, samples, out)
        }),
        Form::Full => time(|| {
            let model = black_box(&inputs.full);
            method.forward(model, record, initial, samples, out)
        }),
    };
    let what = match method {
        Method::Rk4(_) => "forward RK4 run",
        Method::Dopri5(_) => "forward Dopri5 run",
    };
    let stats = integrate(what, stats)?;
    black_box(&*out);
    Ok((s, stats.accepted_steps, None))
}

/// [`Job::ForwardSpecimen`].
fn time_forward_specimen(rk4: Rk4, inputs: &Inputs, out: &mut Trajectory) -> Result<Timed> {
    clear(out);
    let record = black_box(&inputs.record);
    let (s, stats) = time(|| {
        forward_rk4_specimen(
            black_box(&inputs.identified),
            black_box(&inputs.specimen),
            record,
            rk4,
            State::default(),
            inputs.samples,
            out,
        )
    });
    let stats = integrate("forward RK4 run with a specimen", stats)?;
    black_box(&*out);
    Ok((s, stats.accepted_steps, None))
}

/// [`Job::TableSystem`].
fn time_table_system(inputs: &Inputs, out: &mut Trajectory) -> Result<Timed> {
    clear(out);
    let system = &inputs.system;
    let run = LoopRun {
        system,
        specimen: None,
        command: black_box(&inputs.motion),
        method: LoopMethod::Rk4 {
            steps_per_period: system.default_steps_per_period(144e3, 0.75),
        },
        initial: State::default(),
    };
    let model = black_box(&inputs.identified);
    let (s, stats) = time(|| forward_closed_loop(model, &run, inputs.samples, out));
    let stats = integrate("closed-loop run", stats)?;
    black_box(&*out);
    Ok((s, stats.run.steps, None))
}

/// The six-DOF forward workload runs in pieces of at most this many simulated seconds, each
/// from rest at neutral. Open loop, under forces that hold the platen only at neutral, its
/// path drifts: a single 600 s run ends non-finite near 283 s (measured), a 60 s one does not.
/// Pieces keep the workload a measure of the step at any `--seconds`.
pub const SIX_DOF_PIECE_S: f64 = 60.0;

/// [`Job::SixDof`]: as many pieces of [`SIX_DOF_PIECE_S`] as the workload's length asks.
fn time_six_dof(rk4: Rk4, inputs: &Inputs) -> Result<Timed> {
    let (table, forces) = (&inputs.table, &inputs.table_forces);
    let steps_per_piece = forces.len().saturating_sub(1).max(1);
    let pieces = (inputs.samples.saturating_sub(1))
        .div_ceil(steps_per_piece)
        .max(1);
    let (s, run) = time(|| {
        let mut last = None;
        for _ in 0..pieces {
            let run = forward_table(
                black_box(table),
                None,
                black_box(forces),
                Method::Rk4(rk4),
                Coords::zeros(),
                Coords::zeros(),
            );
            let failed = run.is_err();
            last = Some(run);
            if failed {
                break;
            }
        }
        last.expect("at least one piece")
    });
    let run = integrate("six-DOF run", run)?;
    black_box(&run);
    Ok((s, (pieces * steps_per_piece) as u64, None))
}

/// [`Job::SixDofClosedLoop`].
fn time_six_dof_closed_loop(inputs: &Inputs) -> Result<Timed> {
    let (table, sys, command) = &inputs.lhpost6;
    let run = TableLoopRun {
        table: black_box(table),
        hydraulics: &sys.hydraulics,
        controller: &sys.controller,
        specimen: None,
        command: black_box(command),
        method: sys.method,
    };
    let (s, out) = time(|| forward_table_loop(&run));
    let (run, stats) = integrate("six-DOF closed loop", out)?;
    black_box(&run);
    Ok((s, stats.run.steps, None))
}

/// The `six_dof_closed_loop` workload's table and loop (the `lhpost6` preset, its default
/// integrator) and its command: `motion` along x, the other DOFs still.
///
/// # Errors
/// [`BenchError`] if the preset is refused or has no controller (a defect).
pub fn bench_lhpost6(motion: &Motion) -> Result<(MultiAxisTable, TableLoopSystem, PoseMotion)> {
    let spec = platen_scenario::multi_axis::TableSpec {
        preset: Some("lhpost6".into()),
        ..Default::default()
    };
    let (table, sys) = spec
        .build_with_loop(std::path::Path::new("lhpost6"))
        .map_err(|e| BenchError::Table(e.to_string()))?;
    let sys =
        sys.ok_or_else(|| BenchError::Table("the lhpost6 preset has no controller".into()))?;
    let t = motion.t_s().to_vec();
    let still = || {
        let z = vec![0.0; t.len()];
        Motion::new(t.clone(), z.clone(), z.clone(), z)
    };
    let still = || still().map_err(|e| BenchError::Table(e.to_string()));
    let dofs: [Motion; 6] = [
        motion.clone(),
        still()?,
        still()?,
        still()?,
        still()?,
        still()?,
    ];
    let command = integrate("six-DOF command", PoseMotion::new(dofs))?;
    Ok((table, sys, command))
}

/// The six-DOF table of the `six_dof` workload: the shipped forward scenario's
/// (`scenarios/multi-axis/forward.json`, an LHPOST6-like table with frictionless pads),
/// compiled in.
///
/// # Errors
/// [`BenchError`] if the compiled-in table is refused (a defect).
pub fn bench_table() -> Result<MultiAxisTable> {
    let origin = std::path::Path::new("scenarios/multi-axis/forward.json");
    let text = include_str!("../../../scenarios/multi-axis/forward.json");
    let file =
        platen_scenario::file::parse(origin, text).map_err(|e| BenchError::Table(e.to_string()))?;
    let spec = file
        .table
        .ok_or_else(|| BenchError::Table("no table".into()))?;
    spec.build(origin)
        .map_err(|e| BenchError::Table(e.to_string()))
}

/// The actuator forces of the `six_dof` workload: those that hold `table` still at neutral
/// (its weight and the struts' pull, resolved as a force balance does) plus the standard
/// workload's force as `A·cos(2πft)` along x (from rest, so that the platen oscillates
/// about an offset instead of drifting), `samples` samples at [`RATE_HZ`].
///
/// # Errors
/// [`BenchError`] if the actuators cannot hold the table (a defect).
pub fn bench_table_forces(table: &MultiAxisTable, samples: usize) -> Result<ActuatorForces> {
    let neutral = Coords::zeros();
    let hold = -(table.gravity_wrench(&neutral) + table.struts_wrench(&neutral));
    let still = table
        .resolve_forces(&neutral, &table.generalised_force(&neutral, &hold), None)
        .ok_or_else(|| BenchError::Table("cannot hold the platen".into()))?;
    let unit_x = table
        .resolve_forces(&neutral, &Coords::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0), None)
        .ok_or_else(|| BenchError::Table("cannot push along x".into()))?;
    let w = 2.0 * std::f64::consts::PI * FORCE_FREQUENCY_HZ;
    let t: Vec<f64> = (0..samples).map(|j| j as f64 / RATE_HZ).collect();
    let forces = still
        .iter()
        .zip(&unit_x)
        .map(|(f0, fx)| {
            t.iter()
                .map(|&t| f0 + fx * FORCE_AMPLITUDE_N * (w * t).cos())
                .collect()
        })
        .collect();
    integrate("six-DOF forces", ActuatorForces::new(t, forces))
}

/// [`Job::Ensemble`].
fn time_ensemble(rk4: Rk4, inputs: &Inputs) -> Result<Timed> {
    let samples = inputs.samples;
    let cases = inputs.ensemble_cases();
    let mut peaks = vec![Peaks::default(); cases.len()];
    let (s, results) = time(|| forward_rk4_ensemble(black_box(&cases), rk4, samples, &mut peaks));
    for r in results {
        integrate("ensemble run", r)?;
    }
    black_box(&peaks);
    Ok((s, ((samples - 1) * cases.len()) as u64, None))
}

/// [`Job::EnsembleScalar`].
fn time_ensemble_scalar(rk4: Rk4, inputs: &Inputs) -> Result<Timed> {
    let samples = inputs.samples;
    let cases = inputs.ensemble_cases();
    let mut peaks = vec![Peaks::default(); cases.len()];
    let (s, results) = time(|| {
        black_box(&cases)
            .iter()
            .zip(peaks.iter_mut())
            .map(|(c, p)| forward_rk4(c.model, c.record, rk4, c.initial, samples, p))
            .collect::<Vec<_>>()
    });
    for r in results {
        integrate("ensemble case, scalar", r)?;
    }
    black_box(&peaks);
    Ok((s, ((samples - 1) * cases.len()) as u64, None))
}

/// [`Job::Inverse`].
fn time_inverse(inputs: &Inputs, out: &mut Trajectory) -> Timed {
    clear(out);
    let model = black_box(&inputs.identified);
    let (s, ()) = time(|| inverse(model, black_box(&inputs.motion), out));
    black_box(&*out);
    (s, inputs.motion.len() as u64, None)
}

/// The one timing loop: every workload in turn, `repeats` times. Returns the baseline's
/// final state (the same loop in C ends in the same state, to the bit).
pub fn time_round_robin(
    workloads: &mut [Workload],
    inputs: &Inputs,
    repeats: u32,
) -> Result<State> {
    let mut out = Trajectory::with_capacity(inputs.samples);
    let mut baseline_end = State::default();
    for _ in 0..repeats {
        for w in workloads.iter_mut() {
            let (s, units, end) = w.job.run_once(inputs, &mut out)?;
            w.times_s.push(s);
            w.units = units;
            if let Some(end) = end {
                baseline_end = end;
            }
        }
    }
    Ok(baseline_end)
}

/// The samples of records of `seconds_s` simulated seconds at [`RATE_HZ`] (both ends).
pub fn samples_for(seconds_s: f64) -> usize {
    (seconds_s * RATE_HZ).round() as usize + 1
}

/// Builds the inputs of records of `seconds_s` simulated seconds and times every standard
/// workload on them round-robin, `repeats` times (at least once).
pub fn measure(seconds_s: f64, repeats: u32) -> Result<Measurement> {
    let samples = samples_for(seconds_s);
    if samples < 3 {
        return Err(BenchError::TooShort { seconds_s, samples });
    }
    let simulated_s = (samples - 1) as f64 / RATE_HZ;
    let inputs = Inputs::new(samples)?;
    let mut workloads = workloads()?;
    let repeats = repeats.max(1);
    let baseline_end = time_round_robin(&mut workloads, &inputs, repeats)?;
    Ok(Measurement {
        workloads,
        simulated_s,
        repeats,
        baseline_end,
    })
}

/// Empties a trajectory, keeping its buffers (their pages are already mapped).
fn clear(t: &mut Trajectory) {
    for column in [
        &mut t.t_s,
        &mut t.u_m,
        &mut t.v_m_s,
        &mut t.a_m_s2,
        &mut t.force_n,
        &mut t.inertial_force_n,
        &mut t.elastic_force_n,
        &mut t.dissipative_force_n,
    ] {
        column.clear();
    }
    // A specimen run's columns too (kept, with their buffers, for the next specimen run).
    if let Some(sp) = &mut t.specimen {
        sp.base_shear_n.clear();
        sp.u_m.iter_mut().chain(&mut sp.a_m_s2).for_each(Vec::clear);
    }
    if let Some(sy) = &mut t.system {
        for column in [
            &mut sy.command_u_m,
            &mut sy.drive,
            &mut sy.spool_opening,
            &mut sy.delta_p_pa,
            &mut sy.flow_m3_s,
            &mut sy.supply_pressure_pa,
            &mut sy.cap_pressure_pa,
            &mut sy.rod_pressure_pa,
        ] {
            column.clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The forward workload is a table test: run as a scenario for 60 s it stays within the
    /// preset's limits (the LHPOST's ±0.75 m, 1.8 m/s, 4.2 g, 6.8 MN), at the peaks the
    /// module's documentation states (to the 0.01 printed), and reverses once a second after
    /// breaking away, with no stick phase but the one at rest.
    #[test]
    fn the_forward_workload_is_a_table_test_within_the_lhpost_limits_that_reverses_every_second() {
        let inputs = Inputs::new(60 * 1024 + 1).unwrap();
        let mut out = Trajectory::with_capacity(inputs.samples);
        let rk4 = Method::Rk4(Rk4::with_steps_per_sample(1).unwrap());
        let stats = rk4
            .forward(
                &inputs.identified,
                &inputs.record,
                State::default(),
                inputs.samples,
                &mut out,
            )
            .unwrap();
        let peak = |x: &[f64]| x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let limits = preset::Preset::Lhpost2008.limits();
        let (u, v, a) = (peak(&out.u_m), peak(&out.v_m_s), peak(&out.a_m_s2));
        assert!(
            u < limits.stroke_m && v < limits.velocity_m_s,
            "{u} m, {v} m/s"
        );
        assert!(a < limits.acceleration_m_s2, "{a} m/s²");
        assert!(peak(&out.force_n) < limits.force_n);
        assert!((u - 0.35).abs() < 0.005, "{u} m");
        assert!((v - 1.09).abs() < 0.005, "{v} m/s");
        assert!((a / 9.80665 - 0.38).abs() < 0.005, "{a} m/s²");
        assert_eq!(stats.breakaways, 1);
        assert_eq!(stats.reversals, 59);
        assert_eq!(stats.stick_events, 0);
    }

    /// The baseline ([`baseline`]) computes the model it claims to: under a
    /// force well above the friction threshold the platen slips in one direction
    /// from the first step, so the plain loop (no stick logic) and the exact integrator take
    /// the same path.
    #[test]
    fn the_baseline_matches_the_exact_integrator_while_the_platen_slips_one_way() {
        let params = preset::lhpost_2008_identified(13.8e6);
        let force: Vec<f64> = vec![200e3; 257];
        let end = baseline::baseline_rk4(&params, &force, 1.0 / 1024.0, State::default());
        let model = params.build().unwrap();
        let record = platen_integrate::ForceRecord::from_rate(1024.0, force).unwrap();
        let mut out = platen_integrate::Trajectory::with_capacity(record.len());
        let rk4 = platen_integrate::Rk4::with_steps_per_sample(1).unwrap();
        platen_integrate::forward_rk4(
            &model,
            &record,
            rk4,
            State::default(),
            record.len(),
            &mut out,
        )
        .unwrap();
        let (u, v) = (out.u_m[256], out.v_m_s[256]);
        assert!(end.v_m_s > 0.2, "{end:?}");
        // Only the first step differs: the exact run grades it towards the √|v| singularity
        // at rest, the plain loop does not (an O(h^1.5) error of ~2e-7 m/s, measured).
        assert!((end.u_m - u).abs() < 1e-6, "{} vs {u}", end.u_m);
        assert!((end.v_m_s - v).abs() < 1e-6, "{} vs {v}", end.v_m_s);
    }

    /// The report's fields are declared in alphabetical order, so its JSON has the keys in the
    /// order `platen bench --json` has always printed them (a `serde_json::Value`'s, sorted);
    /// and a short run counts its units.
    #[test]
    fn the_report_prints_its_keys_sorted_and_counts_the_units_of_a_short_run() {
        let m = measure(4.0 / RATE_HZ, 1).unwrap();
        let report = m.report();
        let text = serde_json::to_string_pretty(&report).unwrap();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        // The keys, line by line, without the numbers (which a parse may round).
        let keys = |t: &str| -> Vec<String> {
            t.lines()
                .map(|l| l.split(':').next().unwrap().to_owned())
                .collect()
        };
        let sorted = serde_json::to_string_pretty(&value).unwrap();
        assert_eq!(keys(&sorted), keys(&text));
        assert_eq!(report.workloads.len(), 11);
        assert_eq!(report.workloads["rk4"].units_per_run, 4);
        assert_eq!(report.workloads["inverse"].units_per_run, 5);
        assert_eq!(
            report.workloads["ensemble"].units_per_run,
            4 * ENSEMBLE_LANES as u64
        );
        assert!(matches!(
            measure(1.0 / RATE_HZ, 1),
            Err(BenchError::TooShort { samples: 2, .. })
        ));
    }
}
