//! The summary of a run ([`RunSummary`]): what `platen simulate --json` prints and a Python
//! user's `run.summary` holds. A serde type, so every front end reports the same keys.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use platen_integrate::{Exceedance, ForwardIntegrator, Peaks, RunStats};
use platen_model::{PlatenModel, Specimen, TableLimits};

use crate::rig::Rig;
use crate::scenario::{Derived, PlatenScenario, Run};
use crate::RunOutput;

/// The summary of one run of a scenario. Serialise it through [`serde_json::to_value`] to
/// get the keys in alphabetical order, as `platen simulate --json` prints them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSummary {
    /// The scenario file.
    pub scenario: String,
    /// The scenario's name.
    pub name: String,
    /// `"forward"` (force → motion) or `"inverse"` (motion → force).
    pub direction: &'static str,
    /// `"identified"` or `"full"`.
    pub model_form: &'static str,
    /// The preset the model is based on.
    pub preset: &'static str,
    /// The values the scenario lays over the preset's, by name (empty when the preset's own
    /// values run): the model is the preset's only where this does not name a parameter.
    pub model_overrides: BTreeMap<&'static str, f64>,
    /// The hold-down pressure, MPa.
    pub hold_down_pressure_mpa: f64,
    /// Output samples.
    pub samples: usize,
    /// Time from the first to the last output sample, s.
    pub duration_s: f64,
    /// Signed peak displacement, m.
    pub peak_u_m: f64,
    /// When it occurred, s.
    pub peak_u_m_t_s: f64,
    /// Signed peak velocity, m/s.
    pub peak_v_m_s: f64,
    /// When it occurred, s.
    pub peak_v_m_s_t_s: f64,
    /// Signed peak acceleration, m/s².
    pub peak_a_m_s2: f64,
    /// When it occurred, s.
    pub peak_a_m_s2_t_s: f64,
    /// Signed peak actuator force, N.
    pub peak_force_n: f64,
    /// When it occurred, s.
    pub peak_force_n_t_s: f64,
    /// Stick-slip counts, solver statistics and energy balance (forward runs only).
    #[serde(flatten)]
    pub forward: Option<ForwardSummary>,
    /// Every limit the run exceeds.
    pub limit_exceedances: Vec<ExceedanceSummary>,
    /// Every limit with the run's peak against it.
    pub limits: LimitsSummary,
    /// The excitation's channels that platen derived, with how (empty when the file or
    /// generator gave every channel).
    pub derived: Derived,
    /// The CSV written, if any.
    pub out: Option<String>,
    /// The specimen's peaks (`null` without a specimen).
    pub specimen: Option<SpecimenSummary>,
    /// The oil-column frequency of the table system at mid-stroke, linearised, with the
    /// specimen's mass as a rigid payload, Hz (closed-loop runs only).
    pub oil_column_frequency_hz: Option<f64>,
    /// The closed loop's figures (closed-loop runs only).
    pub table_system: Option<SystemSummary>,
    /// What the run wants its user to know (an unstable loop, cavitation, saturated valves).
    pub warnings: Vec<String>,
}

/// A closed-loop run's figures.
///
/// `tracking`, `saturated_time_s` and `steps_per_period` carry the keys a multi-axis table's
/// summary has (`loop` there); the flat `tracking_*`, `valve_saturated_time_s` and
/// `steps_per_controller_period` are the same figures under the names this summary had first,
/// kept for the scripts that read them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SystemSummary {
    /// How the one DOF followed its command, as a multi-axis table reports each of its DOFs
    /// (`x`; the peaks there are magnitudes).
    pub tracking: std::collections::BTreeMap<&'static str, AxisTracking>,
    /// Time with the drive saturated, s (`valve_saturated_time_s`).
    pub saturated_time_s: f64,
    /// Integration steps per controller period (`steps_per_controller_period`).
    pub steps_per_period: u32,
    /// RMS of the displacement error `u − u_ref`, m.
    pub tracking_displacement_rms_m: f64,
    /// Signed peak of the displacement error, m.
    pub tracking_displacement_peak_m: f64,
    /// When, s.
    pub tracking_displacement_peak_t_s: f64,
    /// RMS of the acceleration error `a − a_ref`, m/s².
    pub tracking_acceleration_rms_m_s2: f64,
    /// Signed peak of the acceleration error, m/s².
    pub tracking_acceleration_peak_m_s2: f64,
    /// When, s.
    pub tracking_acceleration_peak_t_s: f64,
    /// The displacement error's RMS over the command's (`null` for a command that stays at 0).
    pub tracking_displacement_nrmse: Option<f64>,
    /// The acceleration error's RMS over the command's acceleration's: the relative error
    /// `platen plan` iterates down (`null` for a command without acceleration).
    pub tracking_acceleration_nrmse: Option<f64>,
    /// Time with the drive saturated, s.
    pub valve_saturated_time_s: f64,
    /// Signed peak flow of the valves into the cap-side chambers, m³/s.
    pub peak_flow_m3_s: f64,
    /// When, s.
    pub peak_flow_t_s: f64,
    /// The valves' flow at full opening with the null drop on each land, m³/s.
    pub valve_flow_capacity_m3_s: f64,
    /// Lowest supply pressure, Pa.
    pub min_supply_pressure_pa: f64,
    /// First time a chamber reached the cavitation floor, s (`null`: never).
    pub cavitation_at_s: Option<f64>,
    /// Hydraulic energy delivered into the chambers, J.
    pub hydraulic_energy_j: f64,
    /// Controller samples.
    pub controller_samples: u64,
    /// Integration steps per controller period.
    pub steps_per_controller_period: u32,
    /// The linearised loop's stability and margins.
    pub loop_margins: LoopMargins,
}

/// How one DOF of a closed loop followed its command (at the output samples): the same keys
/// on every table, under `tracking.<dof>` (the uniaxial table's one DOF is `x`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisTracking {
    /// RMS of command − achieved, m or rad.
    pub rms_error: f64,
    /// Largest |command − achieved|, m or rad.
    pub peak_error: f64,
    /// RMS of the error over the RMS of the command (`null` for a still command: the
    /// error is then absolute, `rms_error`, the cross-talk into that DOF).
    pub displacement_nrmse: Option<f64>,
    /// RMS of the acceleration error (command's − achieved), m/s² or rad/s².
    pub rms_acceleration_error: f64,
    /// Largest |acceleration error|, m/s² or rad/s².
    pub peak_acceleration_error: f64,
    /// RMS of the acceleration error over the RMS of the command's acceleration (`null`
    /// for a still command).
    pub acceleration_nrmse: Option<f64>,
}

/// A loop's margins, broken at its drive, and its closed-loop peak
/// ([`platen_system::Margins`]): the uniaxial loop's `loop_margins` (in `platen simulate`'s
/// summary and `platen model`'s description) and each DOF's of a multi-axis table's (the
/// other DOFs' loops closed).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LoopMargins {
    /// Frequency of the gain crossover of the phase margin, Hz.
    pub gain_crossover_hz: Option<f64>,
    /// Gain margin, dB (`null`: no phase crossover below the controller's Nyquist
    /// frequency).
    pub gain_margin_db: Option<f64>,
    /// The closed loop's largest gain command → displacement (or pose) up to the
    /// controller's Nyquist frequency.
    pub peak_gain: f64,
    /// Where that peak is, Hz.
    pub peak_gain_hz: f64,
    /// Frequency of the phase crossover of the gain margin, Hz.
    pub phase_crossover_hz: Option<f64>,
    /// Phase margin, degrees (`null`: no gain crossover).
    pub phase_margin_deg: Option<f64>,
    /// Whether the closed loop is stable (Nyquist).
    pub stable: bool,
}

impl From<&platen_system::Margins> for LoopMargins {
    fn from(m: &platen_system::Margins) -> Self {
        Self {
            gain_crossover_hz: m.gain_crossover_hz,
            gain_margin_db: m.gain_margin_db,
            peak_gain: m.peak_gain,
            peak_gain_hz: m.peak_gain_hz,
            phase_crossover_hz: m.phase_crossover_hz,
            phase_margin_deg: m.phase_margin_deg,
            stable: m.stable,
        }
    }
}

impl Rig {
    /// The linearised loop of a rig with a table system: its mechanics (the model's mass,
    /// the slope of its elastic force and its secant damping, with the specimen as a rigid
    /// payload) at mid-stroke, and its margins (`None` without a table system).
    pub fn loop_linearisation(
        &self,
    ) -> Option<(platen_system::Linearisation, platen_system::Margins)> {
        self.table_system
            .as_ref()
            .map(|system| linearise(self, system))
    }
}

/// The loop of `system` on `rig`, linearised at mid-stroke, and its margins.
fn linearise(
    rig: &Rig,
    system: &platen_system::TableSystem,
) -> (platen_system::Linearisation, platen_system::Margins) {
    let payload = rig.specimen.as_ref().map_or(0.0, |s| s.total_mass_kg());
    let mech = match &rig.model {
        crate::Model::Identified(m) => platen_system::Mechanics::of_model(m, payload),
        crate::Model::Full(m) => platen_system::Mechanics::of_model(&**m, payload),
    };
    let lin = system.linearise(mech, 0.0);
    let margins = system.margins(&lin);
    (lin, margins)
}

/// The peaks of a specimen run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpecimenSummary {
    /// Each storey's figures, bottom first.
    pub storeys: Vec<StoreySummary>,
    /// Signed peak base shear (force of the platen on the specimen), N.
    pub peak_base_shear_n: f64,
    /// When it occurred, s.
    pub peak_base_shear_n_t_s: f64,
    /// Signed peak drift of each storey, m, bottom first.
    pub peak_drift_m: Vec<f64>,
}

/// One storey's figures in a specimen run's summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StoreySummary {
    /// Signed peak drift, m.
    pub peak_drift_m: f64,
    /// When it occurred, s.
    pub peak_drift_m_t_s: f64,
    /// Peak drift over the storey's height (`null` without `height_m`).
    pub peak_drift_ratio: Option<f64>,
    /// The drift at the run's end, m: the residual drift of a specimen that has come to rest.
    pub residual_drift_m: f64,
    /// Ductility demand, peak |drift| over the yield drift `F_y/k` (`null` for a linear
    /// storey).
    pub ductility: Option<f64>,
    /// Yield excursions (`null` for a linear storey): a bilinear storey's yield events; a
    /// Bouc–Wen storey's passages of its hysteretic force beyond 90 % of its yield level,
    /// once per direction of drift.
    pub yield_excursions: Option<usize>,
    /// Energy dissipated in hysteresis, J (`null` for a linear storey).
    pub hysteretic_j: Option<f64>,
}

impl SpecimenSummary {
    /// The summary of a run of `specimen` with `peaks`.
    pub fn new(specimen: Option<&Specimen>, peaks: &Peaks) -> Self {
        let n = peaks.storeys;
        let storeys = (0..n)
            .map(|i| {
                let peak = peaks.drift_m[i];
                let yield_drift = specimen
                    .and_then(|s| s.hysteretic_storey(i))
                    .map(|h| h.yield_drift_m);
                let yielding = yield_drift.is_some() && peaks.hysteretic;
                StoreySummary {
                    peak_drift_m: peak.value,
                    peak_drift_m_t_s: peak.t_s,
                    peak_drift_ratio: specimen
                        .and_then(|s| s.height_m(i))
                        .map(|h| peak.value.abs() / h),
                    residual_drift_m: peaks.last_drift_m[i],
                    ductility: yield_drift.map(|d| peak.value.abs() / d),
                    yield_excursions: yielding.then_some(peaks.yield_excursions[i]),
                    hysteretic_j: yielding.then_some(peaks.hysteretic_j[i]),
                }
            })
            .collect();
        Self {
            storeys,
            peak_base_shear_n: peaks.base_shear_n.value,
            peak_base_shear_n_t_s: peaks.base_shear_n.t_s,
            peak_drift_m: peaks.drift_m[..n].iter().map(|p| p.value).collect(),
        }
    }
}

/// What only a forward run reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForwardSummary {
    /// Time spent stuck, s.
    pub stick_time_s: f64,
    /// Times the platen came to rest and stuck.
    pub stick_events: u64,
    /// Breakaways from rest.
    pub breakaways: u64,
    /// Direct reversals of the velocity.
    pub reversals: u64,
    /// The integrator's statistics.
    pub solver: SolverSummary,
    /// The energy balance.
    pub energy: EnergySummary,
}

/// The integrator's statistics.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolverSummary {
    /// `"rk4"` or `"dopri5"`.
    pub method: &'static str,
    /// Steps taken.
    pub steps: u64,
    /// Accepted steps.
    pub accepted_steps: u64,
    /// Rejected steps (adaptive integrators).
    pub rejected_steps: u64,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: u64,
    /// Stick-slip events located (stops, breakaways, reversals).
    pub events_located: u64,
    /// Root-finding iterations spent locating them.
    pub root_iterations: u64,
}

/// Actuator work = change of kinetic and elastic energy + energy dissipated, J.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EnergySummary {
    /// Work done by the actuator force, J.
    pub actuator_work_j: f64,
    /// Kinetic energy at the start, J.
    pub kinetic_start_j: f64,
    /// Kinetic energy at the end, J.
    pub kinetic_end_j: f64,
    /// Elastic energy at the start, J.
    pub elastic_start_j: f64,
    /// Elastic energy at the end, J.
    pub elastic_end_j: f64,
    /// Energy dissipated, J.
    pub dissipated_j: f64,
    /// Energy of the specimen at the start, J (`null` without a specimen).
    pub specimen_start_j: Option<f64>,
    /// Energy of the specimen at the end, J (`null` without a specimen).
    pub specimen_end_j: Option<f64>,
    /// Energy dissipated by the specimen's storey dampers, J (`null` without a specimen).
    pub specimen_dissipated_j: Option<f64>,
    /// What the balance leaves, J: an accuracy indicator.
    pub residual_j: f64,
    /// The residual relative to the largest term.
    pub relative_residual: f64,
}

/// A limit the run exceeds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExceedanceSummary {
    /// `"stroke"`, `"velocity"`, `"acceleration"` or `"force"`.
    pub quantity: &'static str,
    /// The run's signed peak, SI units.
    pub peak: f64,
    /// The limit, SI units.
    pub limit: f64,
    /// When the peak occurred, s.
    pub t_s: f64,
}

/// One limit against the run's peak.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitCheck {
    /// The limit, SI units.
    pub limit: f64,
    /// The run's signed peak, SI units.
    pub peak: f64,
    /// Whether |peak| ≤ limit.
    pub respected: bool,
}

/// Every table limit (the preset's, with the scenario's `limits` laid over them) against the
/// run's peaks.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitsSummary {
    /// Stroke, m.
    pub stroke_m: LimitCheck,
    /// Velocity, m/s.
    pub velocity_m_s: LimitCheck,
    /// Acceleration, m/s².
    pub acceleration_m_s2: LimitCheck,
    /// Actuator force, N.
    pub force_n: LimitCheck,
}

impl RunSummary {
    /// The summary of `output`, a run of `scenario` (read from `path`) that wrote `out`.
    pub fn new(
        path: &Path,
        scenario: &PlatenScenario,
        output: &RunOutput,
        out: Option<&Path>,
    ) -> Self {
        let peaks = &output.peaks;
        let rig = &scenario.rig;
        Self {
            scenario: path.display().to_string(),
            name: scenario.name.clone(),
            direction: scenario.run.direction(),
            model_form: rig.model.form(),
            preset: rig.preset.name(),
            model_overrides: rig
                .overrides
                .values()
                .iter()
                .map(|(key, value)| (key.name(), *value))
                .collect(),
            hold_down_pressure_mpa: rig.hold_down_pressure_pa / 1e6,
            samples: peaks.samples,
            duration_s: peaks.span_s.1 - peaks.span_s.0,
            peak_u_m: peaks.u_m.value,
            peak_u_m_t_s: peaks.u_m.t_s,
            peak_v_m_s: peaks.v_m_s.value,
            peak_v_m_s_t_s: peaks.v_m_s.t_s,
            peak_a_m_s2: peaks.a_m_s2.value,
            peak_a_m_s2_t_s: peaks.a_m_s2.t_s,
            peak_force_n: peaks.force_n.value,
            peak_force_n_t_s: peaks.force_n.t_s,
            forward: output
                .stats
                .as_ref()
                .map(|st| ForwardSummary::new(st, &scenario.run, rig.specimen.is_some())),
            limit_exceedances: peaks
                .exceedances(&rig.limits)
                .iter()
                .map(ExceedanceSummary::from)
                .collect(),
            limits: LimitsSummary::new(peaks, &rig.limits),
            derived: scenario.derived.clone(),
            out: out.map(|p| p.display().to_string()),
            oil_column_frequency_hz: None,
            table_system: None,
            warnings: Vec::new(),
            specimen: (peaks.storeys > 0)
                .then(|| SpecimenSummary::new(rig.specimen.as_ref(), peaks)),
        }
        .with_loop(scenario, output)
        .with_stuck_platen(scenario)
    }
}

/// A force in kN, three decimals (a newton's resolution).
fn kn(force_n: f64) -> String {
    format!("{:.3} kN", force_n / 1e3)
}

impl RunSummary {
    /// The summary with a warning for a forward run whose force never overcomes the static
    /// friction at the initial displacement (`|F_A − F_E(u₀)| ≤ F_s(u₀)` throughout, from
    /// rest), so the platen never moves: most likely a force in the wrong unit (kN read as N).
    /// The run's own output is checked too: a platen that never left stick is reported even
    /// where the force alone does not explain it.
    fn with_stuck_platen(mut self, scenario: &PlatenScenario) -> Self {
        let Run::Forward {
            record,
            initial,
            samples,
            ..
        } = &scenario.run
        else {
            return self;
        };
        if initial.v_m_s != 0.0 || self.forward.is_none() {
            return self;
        }
        let never_moved = self.peak_v_m_s == 0.0;
        let u0 = initial.u_m;
        let (elastic_n, static_n) = match &scenario.rig.model {
            crate::Model::Identified(m) => (m.elastic_force_n(u0), m.static_threshold_n(u0)),
            crate::Model::Full(m) => (m.elastic_force_n(u0), m.static_threshold_n(u0)),
        };
        let n = (*samples).min(record.len());
        let (t, f) = (&record.t_s()[..n], &record.force_n()[..n]);
        // The first sample of the largest magnitude.
        let Some(i) = (0..n).reduce(|a, b| if f[b].abs() > f[a].abs() { b } else { a }) else {
            return self;
        };
        let net_peak = f.iter().map(|x| (x - elastic_n).abs()).fold(0.0, f64::max);
        let breakaway = if elastic_n == 0.0 {
            format!(
                "the breakaway force {} (the static friction F_s at v = 0)",
                kn(static_n)
            )
        } else {
            format!(
                "the breakaway forces {} and {} (the elastic force F_E(u0) = {} at the initial \
                 displacement {u0} m, ∓ the static friction F_s = {} at v = 0)",
                kn(elastic_n - static_n),
                kn(elastic_n + static_n),
                kn(elastic_n),
                kn(static_n)
            )
        };
        if net_peak <= static_n {
            self.warnings.push(format!(
                "the force never reaches {breakaway}: its peak |force| is {} at {} s, so the \
                 platen never leaves stick{}. A force given in kN where N is expected? (In N, \
                 ×1000, it would peak at {}.) Map its unit with \
                 \"columns\": {{\"force_n\": {{\"unit\": \"kN\"}}}}",
                kn(f[i].abs()),
                t[i],
                if never_moved {
                    " (the run confirms it: the velocity stayed 0)"
                } else {
                    ""
                },
                kn(f[i].abs() * 1e3),
            ));
        } else if never_moved {
            self.warnings.push(format!(
                "the platen never left stick: the velocity stayed 0 over the whole run (peak \
                 |force| {} at {} s against {breakaway})",
                kn(f[i].abs()),
                t[i]
            ));
        }
        self
    }
}

impl RunSummary {
    /// The summary with a closed-loop run's figures and warnings laid in.
    fn with_loop(mut self, scenario: &PlatenScenario, output: &RunOutput) -> Self {
        let (Run::ClosedLoop { settings, .. }, Some(system), Some(lo)) =
            (&scenario.run, &scenario.rig.table_system, &output.system)
        else {
            return self;
        };
        let (lin, margins) = linearise(&scenario.rig, system);
        self.oil_column_frequency_hz =
            Some(system.oil_column_frequency_hz(lin.mechanics.mass_kg, 0.0));
        let (st, tr) = (&lo.stats, &lo.tracking);
        let capacity = system.capacities().valve_flow_m3_s;
        if !margins.stable {
            self.warnings.push(format!(
                "the linearised loop is unstable (gain margin {}, phase margin {}): the run \
                 shows what the table would do, but check the controller's gains",
                margins
                    .gain_margin_db
                    .map_or("none".into(), |g| format!("{g:.1} dB")),
                margins
                    .phase_margin_deg
                    .map_or("none".into(), |p| format!("{p:.1}°")),
            ));
        }
        if let Some(t) = st.cavitation_at_s {
            self.warnings.push(format!(
                "a chamber pressure reached the cavitation floor (0 Pa absolute) at {t:.4} s"
            ));
        }
        if st.saturated_time_s > 0.0 {
            self.warnings.push(format!(
                "the drive was saturated for {:.3} s: the valves were fully open",
                st.saturated_time_s
            ));
        }
        let x = AxisTracking {
            rms_error: tr.displacement_rms_m(),
            peak_error: tr.displacement_peak.value.abs(),
            displacement_nrmse: tr.displacement_nrmse(),
            rms_acceleration_error: tr.acceleration_rms_m_s2(),
            peak_acceleration_error: tr.acceleration_peak.value.abs(),
            acceleration_nrmse: tr.acceleration_nrmse(),
        };
        self.table_system = Some(SystemSummary {
            tracking: std::iter::once(("x", x)).collect(),
            saturated_time_s: st.saturated_time_s,
            steps_per_period: settings.method.steps_per_period(),
            tracking_displacement_rms_m: tr.displacement_rms_m(),
            tracking_displacement_peak_m: tr.displacement_peak.value,
            tracking_displacement_peak_t_s: tr.displacement_peak.t_s,
            tracking_acceleration_rms_m_s2: tr.acceleration_rms_m_s2(),
            tracking_acceleration_peak_m_s2: tr.acceleration_peak.value,
            tracking_acceleration_peak_t_s: tr.acceleration_peak.t_s,
            tracking_displacement_nrmse: tr.displacement_nrmse(),
            tracking_acceleration_nrmse: tr.acceleration_nrmse(),
            valve_saturated_time_s: st.saturated_time_s,
            peak_flow_m3_s: tr.flow_peak.value,
            peak_flow_t_s: tr.flow_peak.t_s,
            valve_flow_capacity_m3_s: capacity,
            min_supply_pressure_pa: st.min_supply_pressure_pa,
            cavitation_at_s: st.cavitation_at_s,
            hydraulic_energy_j: st.hydraulic_energy_j,
            controller_samples: st.controller_samples,
            steps_per_controller_period: settings.method.steps_per_period(),
            loop_margins: LoopMargins::from(&margins),
        });
        self
    }
}

impl ForwardSummary {
    fn new(st: &RunStats, run: &Run, with_specimen: bool) -> Self {
        let specimen = |x: f64| with_specimen.then_some(x);
        let method = match run {
            Run::Forward { integrator, .. } => integrator.name(),
            Run::ClosedLoop { settings, .. } => match settings.method {
                platen_integrate::LoopMethod::Rk4 { .. } => "rk4",
                platen_integrate::LoopMethod::Dopri5 { .. } => "dopri5",
            },
            Run::Inverse { .. } => "none",
        };
        let e = &st.energy;
        Self {
            stick_time_s: st.stick_time_s,
            stick_events: st.stick_events,
            breakaways: st.breakaways,
            reversals: st.reversals,
            solver: SolverSummary {
                method,
                steps: st.steps,
                accepted_steps: st.accepted_steps,
                rejected_steps: st.rejected_steps,
                rhs_evaluations: st.rhs_evaluations,
                events_located: st.events(),
                root_iterations: st.root_iterations,
            },
            energy: EnergySummary {
                actuator_work_j: e.actuator_work_j,
                kinetic_start_j: e.kinetic_start_j,
                kinetic_end_j: e.kinetic_end_j,
                elastic_start_j: e.elastic_start_j,
                elastic_end_j: e.elastic_end_j,
                dissipated_j: e.dissipated_j,
                specimen_start_j: specimen(e.specimen_start_j),
                specimen_end_j: specimen(e.specimen_end_j),
                specimen_dissipated_j: specimen(e.specimen_dissipated_j),
                residual_j: e.residual_j(),
                relative_residual: e.relative_residual(),
            },
        }
    }
}

impl From<&Exceedance> for ExceedanceSummary {
    fn from(e: &Exceedance) -> Self {
        Self {
            quantity: e.quantity,
            peak: e.peak,
            limit: e.limit,
            t_s: e.t_s,
        }
    }
}

impl LimitsSummary {
    fn new(peaks: &Peaks, l: &TableLimits) -> Self {
        let check = |peak: f64, limit: f64| LimitCheck {
            limit,
            peak,
            respected: peak.abs() <= limit,
        };
        Self {
            stroke_m: check(peaks.u_m.value, l.stroke_m),
            velocity_m_s: check(peaks.v_m_s.value, l.velocity_m_s),
            acceleration_m_s2: check(peaks.a_m_s2.value, l.acceleration_m_s2),
            force_n: check(peaks.force_n.value, l.force_n),
        }
    }
}
