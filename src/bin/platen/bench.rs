//! `platen bench`: time the standard workloads on the `lhpost-2008` preset, next to the
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
//! * `baseline`: [`baseline::baseline_rk4`] (`benches/common/baseline.rs`, the one copy the
//!   criterion benches use too), the plain RK4 loop on the identified model (no stick logic,
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
//! * `ensemble` and `ensemble_scalar`: [`ENSEMBLE_LANES`] sweep-like cases (the identified
//!   model at 6.9 and 13.8 MPa under the forward force scaled by 0.9 and 1.1, more cases to
//!   fill the lanes) run by [`forward_rk4_ensemble`] in SIMD lanes, and the same cases run one
//!   after the other by the scalar [`forward_rk4`] (bit for bit the same runs), each case's
//!   peaks only; timed per step per trajectory, so their ratio is the ensemble's gain.
//!
//! The workloads are data ([`workloads`]): one timing loop ([`time_round_robin`]) runs them
//! round-robin `repeats` times and the median wall time of each is reported, so that a slow
//! phase of the machine affects all of them alike. The forward runs go through
//! [`ForwardIntegrator`] (one `match` per run, nothing per step). The output buffers are
//! allocated once, outside the timed region, and reused.

use std::hint::black_box;
use std::time::Instant;

use anyhow::{ensure, Context, Result};
use serde_json::{json, Map, Value};

use platen_integrate::{
    forward_closed_loop, forward_rk4, forward_rk4_ensemble, forward_rk4_specimen, inverse,
    Dopri5Settings, EnsembleCase, ForceRecord, ForwardIntegrator, LoopMethod, LoopRun, Method,
    Motion, Peaks, Rk4, State, Trajectory, ENSEMBLE_LANES,
};
use platen_model::{preset, FullModel, IdentifiedModel, IdentifiedParams, Specimen, Storey};
use platen_system::TableSystem;

/// The plain-loop measuring stick, compiled from the one file the criterion benches use.
#[path = "../../../benches/common/baseline.rs"]
mod baseline;

/// Sample rate of every workload, Hz (one RK4 step per sample: h = 1/1024 s).
const RATE_HZ: f64 = 1024.0;
/// Hold-down pressure of every workload, Pa.
const PRESSURE_PA: f64 = 13.8e6;
/// Sine force of the forward workloads: amplitude, N, and frequency, Hz (a table test within
/// the LHPOST's limits: see the module's documentation).
const FORCE_AMPLITUDE_N: f64 = 100e3;
const FORCE_FREQUENCY_HZ: f64 = 0.5;
/// Sine motion of the inverse workload (the paper's S9): amplitude, m, and frequency, Hz.
const MOTION_AMPLITUDE_M: f64 = 0.2;
const MOTION_FREQUENCY_HZ: f64 = 0.6;
/// Tolerances of the Dopri5 workload.
const DOPRI5_RTOL: f64 = 1e-8;
const DOPRI5_ATOL: f64 = 1e-11;

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
    /// [`forward_rk4`] of each ensemble case in turn; one unit per step per trajectory.
    EnsembleScalar(Rk4),
}

/// One timed workload.
struct Workload {
    key: &'static str,
    title: &'static str,
    /// What one unit of work is ("step", "accepted step", "sample").
    unit: &'static str,
    job: Job,
    /// Units of work per run (steps, accepted steps or samples).
    units: u64,
    /// Wall time of each run, s.
    times_s: Vec<f64>,
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

    fn median_s(&self) -> f64 {
        let mut t = self.times_s.clone();
        t.sort_by(f64::total_cmp);
        let n = t.len();
        if n % 2 == 1 {
            t[n / 2]
        } else {
            0.5 * (t[n / 2 - 1] + t[n / 2])
        }
    }

    fn ns_per_unit(&self) -> f64 {
        self.median_s() * 1e9 / self.units as f64
    }

    fn json(&self, simulated_s: f64) -> Value {
        let median = self.median_s();
        json!({
            "unit": self.unit,
            "units_per_run": self.units,
            "runs": self.times_s.len(),
            "median_wall_s": median,
            "min_wall_s": self.times_s.iter().copied().fold(f64::INFINITY, f64::min),
            "ns_per_unit": self.ns_per_unit(),
            "units_per_s": self.units as f64 / median,
            "simulated_s_per_wall_s": simulated_s / median,
        })
    }
}

/// The standard workloads, in the order they run and are reported.
fn workloads() -> Result<Vec<Workload>> {
    let rk4 = Method::Rk4(Rk4::with_steps_per_sample(1)?);
    let dopri5 = Method::Dopri5(Dopri5Settings::new(DOPRI5_RTOL, DOPRI5_ATOL)?);
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
            Job::Forward(Form::Identified, rk4),
        ),
        Workload::new(
            "rk4_full",
            "rk4_full: full model, exact stick-slip, output kept",
            "step",
            Job::Forward(Form::Full, rk4),
        ),
        Workload::new(
            "rk4_specimen",
            "rk4_specimen: rk4 with a 3-storey specimen",
            "step",
            Job::ForwardSpecimen(Rk4::with_steps_per_sample(1)?),
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
            "ensemble_scalar",
            "ensemble_scalar: sweep-like cases one by one, peaks",
            "step",
            Job::EnsembleScalar(Rk4::with_steps_per_sample(1)?),
        ),
        Workload::new(
            "ensemble",
            "ensemble: the same cases in SIMD lanes, peaks",
            "step",
            Job::Ensemble(Rk4::with_steps_per_sample(1)?),
        ),
    ])
}

/// The inputs every workload shares, built outside the timed region.
struct Inputs {
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
    /// The models and force records of the ensemble cases.
    ensemble_models: Vec<IdentifiedModel>,
    ensemble_records: Vec<ForceRecord>,
}

/// The 3-storey specimen of the `rk4_specimen` workload: 20 t floors, storey stiffnesses 40,
/// 32 and 24 MN/m, stiffness-proportional storey dampers (3 ms times each stiffness: 2.8 % of
/// critical in the first mode). Fixed-base modes near 2.9, 7.6 and 11.3 Hz.
fn bench_specimen() -> Result<Specimen> {
    let storey = |k: f64| Storey {
        mass_kg: 20e3,
        stiffness_n_per_m: k,
        damping_n_s_per_m: 3e-3 * k,
    };
    Ok(Specimen::new(vec![
        storey(40e6),
        storey(32e6),
        storey(24e6),
    ])?)
}

impl Inputs {
    /// The records of `samples` samples at [`RATE_HZ`] and the two models.
    fn new(samples: usize) -> Result<Self> {
        let w_force = 2.0 * std::f64::consts::PI * FORCE_FREQUENCY_HZ;
        let force: Vec<f64> = (0..samples)
            .map(|j| FORCE_AMPLITUDE_N * (w_force * j as f64 / RATE_HZ).sin())
            .collect();
        let record =
            ForceRecord::from_rate(RATE_HZ, force.clone()).context("bench force record")?;
        let w = 2.0 * std::f64::consts::PI * MOTION_FREQUENCY_HZ;
        let t: Vec<f64> = (0..samples).map(|j| j as f64 / RATE_HZ).collect();
        let motion = Motion::new(
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
        )
        .context("bench motion")?;
        let identified_params = preset::lhpost_2008_identified(PRESSURE_PA);
        let (mut ensemble_models, mut ensemble_records) = (Vec::new(), Vec::new());
        for case in 0..ENSEMBLE_LANES {
            let scale = [0.9, 1.1][case / 2 % 2] + 0.05 * (case / 4) as f64;
            let pressure_pa = [6.9e6, PRESSURE_PA][case % 2];
            ensemble_models.push(preset::lhpost_2008_identified(pressure_pa).build()?);
            let scaled = force.iter().map(|f| f * scale).collect();
            ensemble_records
                .push(ForceRecord::from_rate(RATE_HZ, scaled).context("bench ensemble record")?);
        }
        Ok(Self {
            samples,
            force,
            record,
            motion,
            identified: identified_params.build()?,
            identified_params,
            full: preset::lhpost_2008_physical(PRESSURE_PA).build()?,
            specimen: bench_specimen()?,
            system: platen_system::preset::lhpost_2008(),
            ensemble_models,
            ensemble_records,
        })
    }
}

impl Inputs {
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

impl Job {
    /// Runs the job once on `inputs` into `out` (emptied first) and returns its wall time, s,
    /// its units of work, and, for the baseline, its final state.
    fn run_once(self, inputs: &Inputs, out: &mut Trajectory) -> Result<(f64, u64, Option<State>)> {
        let samples = inputs.samples;
        match self {
            Job::Baseline => {
                let (s, end) = time(|| {
                    baseline::baseline_rk4(
                        black_box(&inputs.identified_params),
                        black_box(&inputs.force),
                        black_box(1.0 / RATE_HZ),
                        State::default(),
                    )
                });
                Ok((s, (samples - 1) as u64, Some(black_box(end))))
            }
            Job::Forward(form, method) => {
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
                let stats = stats.with_context(|| match method {
                    Method::Rk4(_) => "bench forward RK4 run",
                    Method::Dopri5(_) => "bench forward Dopri5 run",
                })?;
                black_box(&*out);
                Ok((s, stats.accepted_steps, None))
            }
            Job::ForwardSpecimen(rk4) => {
                clear(out);
                let record = black_box(&inputs.record);
                let (s, stats) = time(|| {
                    forward_rk4_specimen(
                        black_box(&inputs.identified),
                        black_box(&inputs.specimen),
                        record,
                        rk4,
                        State::default(),
                        samples,
                        out,
                    )
                });
                let stats = stats.context("bench forward RK4 run with a specimen")?;
                black_box(&*out);
                Ok((s, stats.accepted_steps, None))
            }
            Job::TableSystem => {
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
                let (s, stats) = time(|| forward_closed_loop(model, &run, samples, out));
                let stats = stats.context("bench closed-loop run")?;
                black_box(&*out);
                Ok((s, stats.run.steps, None))
            }
            Job::Ensemble(rk4) => {
                let cases = inputs.ensemble_cases();
                let mut peaks = vec![Peaks::default(); cases.len()];
                let (s, results) =
                    time(|| forward_rk4_ensemble(black_box(&cases), rk4, samples, &mut peaks));
                for r in results {
                    r.context("bench ensemble run")?;
                }
                black_box(&peaks);
                Ok((s, ((samples - 1) * cases.len()) as u64, None))
            }
            Job::EnsembleScalar(rk4) => {
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
                    r.context("bench ensemble case, scalar")?;
                }
                black_box(&peaks);
                Ok((s, ((samples - 1) * cases.len()) as u64, None))
            }
            Job::Inverse => {
                clear(out);
                let model = black_box(&inputs.identified);
                let (s, ()) = time(|| inverse(model, black_box(&inputs.motion), out));
                black_box(&*out);
                Ok((s, inputs.motion.len() as u64, None))
            }
        }
    }
}

/// The one timing loop: every workload in turn, `repeats` times. Returns the baseline's
/// final state (the same loop in C ends in the same state, to the bit).
fn time_round_robin(workloads: &mut [Workload], inputs: &Inputs, repeats: u32) -> Result<State> {
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

pub fn run(seconds: f64, repeats: u32, json_out: bool) -> Result<()> {
    let samples = (seconds * RATE_HZ).round() as usize + 1;
    ensure!(
        samples >= 3,
        "--seconds {seconds} gives {samples} samples at 1024 Hz; at least 3 are needed"
    );
    let simulated_s = (samples - 1) as f64 / RATE_HZ;
    let inputs = Inputs::new(samples)?;
    let mut workloads = workloads()?;
    let repeats = repeats.max(1);
    let baseline_end = time_round_robin(&mut workloads, &inputs, repeats)?;
    let report = Report {
        workloads: &workloads,
        simulated_s,
        repeats,
        baseline_end,
    };
    if json_out {
        outln!("{}", serde_json::to_string_pretty(&report.json())?);
    } else {
        report.print_text()?;
    }
    Ok(())
}

/// The measured workloads, ready to print.
struct Report<'a> {
    workloads: &'a [Workload],
    simulated_s: f64,
    repeats: u32,
    baseline_end: State,
}

impl Report<'_> {
    /// The workload under `key`.
    fn get(&self, key: &str) -> &Workload {
        self.workloads
            .iter()
            .find(|w| w.key == key)
            .expect("a standard workload")
    }

    /// The baseline's time per step, ns.
    fn base_ns(&self) -> f64 {
        self.get("baseline").ns_per_unit()
    }

    /// The `--json` summary.
    fn json(&self) -> Value {
        let simulated_s = self.simulated_s;
        let (base, rk4, rk4_full) = (self.base_ns(), self.get("rk4"), self.get("rk4_full"));
        let mut m = Map::new();
        m.insert("preset".into(), json!("lhpost-2008"));
        m.insert("hold_down_pressure_mpa".into(), json!(PRESSURE_PA / 1e6));
        m.insert("simulated_s".into(), json!(simulated_s));
        m.insert("sample_rate_hz".into(), json!(RATE_HZ));
        m.insert("repeats".into(), json!(self.repeats));
        m.insert("force_amplitude_n".into(), json!(FORCE_AMPLITUDE_N));
        m.insert("force_frequency_hz".into(), json!(FORCE_FREQUENCY_HZ));
        m.insert("rk4_ns_per_step".into(), json!(rk4.ns_per_unit()));
        m.insert("rk4_full_ns_per_step".into(), json!(rk4_full.ns_per_unit()));
        let specimen = self.get("rk4_specimen");
        m.insert(
            "rk4_specimen_ns_per_step".into(),
            json!(specimen.ns_per_unit()),
        );
        m.insert(
            "rk4_specimen_ratio_to_baseline".into(),
            json!(specimen.ns_per_unit() / base),
        );
        m.insert(
            "dopri5_ns_per_accepted_step".into(),
            json!(self.get("dopri5").ns_per_unit()),
        );
        m.insert(
            "inverse_ns_per_sample".into(),
            json!(self.get("inverse").ns_per_unit()),
        );
        m.insert("baseline_ns_per_step".into(), json!(base));
        let system = self.get("table_system");
        m.insert(
            "table_system_ns_per_step".into(),
            json!(system.ns_per_unit()),
        );
        m.insert(
            "table_system_ratio_to_baseline".into(),
            json!(system.ns_per_unit() / base),
        );
        m.insert(
            "rk4_ratio_to_baseline".into(),
            json!(rk4.ns_per_unit() / base),
        );
        m.insert(
            "rk4_full_ratio_to_baseline".into(),
            json!(rk4_full.ns_per_unit() / base),
        );
        m.insert("rk4_steps_per_s".into(), json!(1e9 / rk4.ns_per_unit()));
        let (ensemble, ensemble_scalar) = (self.get("ensemble"), self.get("ensemble_scalar"));
        m.insert("ensemble_lanes".into(), json!(ENSEMBLE_LANES));
        m.insert(
            "ensemble_ns_per_step_per_trajectory".into(),
            json!(ensemble.ns_per_unit()),
        );
        m.insert(
            "ensemble_scalar_ns_per_step".into(),
            json!(ensemble_scalar.ns_per_unit()),
        );
        m.insert(
            "ensemble_ratio_to_scalar".into(),
            json!(ensemble.ns_per_unit() / ensemble_scalar.ns_per_unit()),
        );
        m.insert(
            "rk4_simulated_s_per_wall_s".into(),
            json!(simulated_s / rk4.median_s()),
        );
        // The same loop in C (benches/c/rk4_baseline.c) ends in the same state, to the bit.
        let end = self.baseline_end;
        m.insert(
            "baseline_final_state".into(),
            json!({"u_m": end.u_m, "v_m_s": end.v_m_s}),
        );
        let detail = self
            .workloads
            .iter()
            .map(|w| (w.key.to_owned(), w.json(simulated_s)))
            .collect();
        m.insert("workloads".into(), Value::Object(detail));
        Value::Object(m)
    }

    /// The text table.
    fn print_text(&self) -> anyhow::Result<()> {
        let (simulated_s, base) = (self.simulated_s, self.base_ns());
        outln!(
            "platen bench: lhpost-2008 at {} MPa, {simulated_s} s records at {RATE_HZ} Hz from rest, \
             median of {} runs",
            PRESSURE_PA / 1e6,
            self.repeats
        );
        outln!(
            "  forward workloads: a {} kN, {FORCE_FREQUENCY_HZ} Hz sine force, a table test within the \
             LHPOST's limits (±0.35 m, 1.09 m/s, 0.38 g), one reversal per second",
            FORCE_AMPLITUDE_N / 1e3
        );
        outln!(
            "  {:<54} {:>14} {:>10} {:>10} {:>12} {:>6}",
            "workload",
            "unit",
            "ns/unit",
            "units/s",
            "sim s/wall s",
            "ratio"
        );
        for w in self.workloads {
            let ratio = if w.unit == "step" {
                format!("{:.3}", w.ns_per_unit() / base)
            } else {
                "-".to_owned()
            };
            outln!(
                "  {:<54} {:>14} {:>10.1} {:>10.3e} {:>12.0} {:>6}",
                w.title,
                w.unit,
                w.ns_per_unit(),
                w.units as f64 / w.median_s(),
                simulated_s / w.median_s(),
                ratio
            );
        }
        outln!("  ratio: ns/step over the baseline's, measured in the same run");
        Ok(())
    }
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

/// `--seconds`: a finite number of simulated seconds, at least 2/1024 and at most 1e6.
pub fn parse_seconds(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of seconds"))?;
    if v.is_finite() && (2.0 / RATE_HZ..=1e6).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{v} s: expected a duration from {} s to 1e6 s",
            2.0 / RATE_HZ
        ))
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

    /// The baseline (`benches/common/baseline.rs`) computes the model it claims to: under a
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
}
