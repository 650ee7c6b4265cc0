//! The summary of a multi-axis run (`platen simulate --json`).

use std::collections::BTreeMap;

use super::*;
pub use crate::summary::AxisTracking;
use crate::summary::LoopMargins;

/// The peaks of one DOF of a multi-axis run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisPeaks {
    /// Largest |coordinate|, m or rad.
    pub peak: f64,
    /// Largest |rate|, m/s or rad/s.
    pub peak_rate: f64,
    /// Largest |second derivative|, m/s² or rad/s².
    pub peak_acceleration: f64,
}

/// One actuator's peaks against its limits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ActuatorPeaks {
    /// Its name.
    pub name: String,
    /// Largest |stroke|, m.
    pub peak_stroke_m: f64,
    /// Its stroke limit (± from neutral), m.
    pub stroke_limit_m: f64,
    /// Largest force (push), N.
    pub max_force_n: f64,
    /// Smallest force (most pull), N.
    pub min_force_n: f64,
    /// Its push limit at the supply pressure, N.
    pub push_limit_n: f64,
    /// Its pull limit at the supply pressure (≤ 0), N.
    pub pull_limit_n: f64,
    /// Largest |flow| into chamber `a` (closed loop), m³/s.
    pub peak_flow_m3_s: Option<f64>,
    /// Its valves' flow capacity at the supply pressure, `m·Q_r·√((P_s − P_R)/Δp_r)`
    /// (closed loop), m³/s.
    pub flow_capacity_m3_s: Option<f64>,
    /// Time its drive was saturated (`|d| = 1`, counted at the output samples; closed loop),
    /// s.
    pub saturated_time_s: Option<f64>,
    /// Whether stroke and force stayed within the limits.
    pub respected: bool,
}

/// One axis's peaks against its limits (`table.limits`; `null` where none is given).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisLimitCheck {
    /// Its displacement limit (stroke or angle), m or rad.
    pub displacement_limit: Option<f64>,
    /// Its rate limit, m/s or rad/s.
    pub rate_limit: Option<f64>,
    /// Its acceleration limit, m/s² or rad/s².
    pub acceleration_limit: Option<f64>,
    /// Whether the peaks stayed within the limits given.
    pub respected: bool,
}

/// The overturning moment the platen exerted on the specimen against the table's limit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OverturningSummary {
    /// Largest `√(M_x² + M_y²)` about the reference point, N·m.
    pub peak_n_m: f64,
    /// The limit (`table.limits.overturning_moment_n_m`), N·m.
    pub limit_n_m: Option<f64>,
    /// Whether it stayed within the limit (true without one).
    pub respected: bool,
}

/// A closed loop's own figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableLoopSummary {
    /// Time with a drive saturated (at the controller's samples), s.
    pub saturated_time_s: f64,
    /// First time a chamber reached the cavitation floor (0 Pa absolute), s.
    pub cavitation_at_s: Option<f64>,
    /// Lowest supply pressure, Pa.
    pub min_supply_pressure_pa: f64,
    /// Largest warping force (the null-space part of the actuator forces), N.
    pub max_warping_force_n: f64,
    /// Hydraulic energy delivered into the chambers, J.
    pub hydraulic_energy_j: f64,
    /// Controller samples.
    pub controller_samples: u64,
    /// RK4 steps per controller period (or Dopri5 pieces).
    pub steps_per_period: u32,
    /// The loop's stability from the eigenvalues of its linearisation at neutral (`null`
    /// when it cannot be linearised: the actuators cannot hold the platen there).
    pub stability: Option<LoopStabilityDescription>,
    /// Per free DOF, its loop's margins, broken at its drive with the others closed.
    pub loop_margins: BTreeMap<&'static str, LoopMargins>,
}

/// One strut's range of pull.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StrutPeaks {
    /// Its name.
    pub name: String,
    /// Smallest pull, N.
    pub min_force_n: f64,
    /// Largest pull, N.
    pub max_force_n: f64,
}

/// What `platen simulate --json` prints for a multi-axis run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableSummary {
    /// The scenario's name.
    pub name: String,
    /// `"inverse"` or `"forward"`.
    pub kind: &'static str,
    /// Output samples.
    pub samples: usize,
    /// Simulated duration, s.
    pub duration_s: f64,
    /// The motion's channels platen derived, with how.
    pub derived: Derived,
    /// Per DOF (`x` … `yaw`), its peaks.
    pub axes: BTreeMap<&'static str, AxisPeaks>,
    /// Per actuator, its peaks against its limits.
    pub actuators: Vec<ActuatorPeaks>,
    /// Per strut, its range of pull.
    pub struts: Vec<StrutPeaks>,
    /// With a specimen: the largest |value| of each base-force and overturning-moment column.
    pub specimen: BTreeMap<&'static str, f64>,
    /// Per DOF, how it followed its command (closed loop; `null` otherwise).
    pub tracking: Option<BTreeMap<&'static str, AxisTracking>>,
    /// Per DOF, its peaks against `table.limits` (every DOF; limits `null` where not given).
    pub limits: BTreeMap<&'static str, AxisLimitCheck>,
    /// The overturning moment against its limit (with a specimen; `null` otherwise).
    pub overturning_moment: Option<OverturningSummary>,
    /// The closed loop's own figures (`null` for an open-loop run).
    #[serde(rename = "loop")]
    pub loop_figures: Option<TableLoopSummary>,
    /// What an engineer should look at: limits exceeded, cavitation, saturation.
    pub warnings: Vec<String>,
    /// Whether every actuator and axis stayed within its limits.
    pub within_limits: bool,
    /// The CSV written, if any.
    pub output: Option<String>,
}

impl TableScenario {
    /// The summary of `run` (a run of this scenario); `output` the CSV written.
    pub fn summary(&self, run: &TableRun, output: Option<&Path>) -> TableSummary {
        self.summary_with(run, None, output)
    }

    /// [`TableScenario::summary`] with the closed loop's figures `stats`.
    pub fn summary_with(
        &self,
        run: &TableRun,
        stats: Option<&TableLoopStats>,
        output: Option<&Path>,
    ) -> TableSummary {
        self.summary_of(&TablePeaks::of_run(self, run), stats, output)
    }

    /// The summary of a run of this scenario from its `peaks`, gathered as it went (see
    /// [`TablePeaks`]), with the closed loop's figures `stats`; `output` the file written.
    pub fn summary_of(
        &self,
        peaks: &TablePeaks<'_>,
        stats: Option<&TableLoopStats>,
        output: Option<&Path>,
    ) -> TableSummary {
        let actuators = self.actuator_peaks(peaks);
        // The warnings in their order: the axes' limits, the overturning moment, the
        // actuators; then the loop's (an unstable loop's first of all).
        let mut warnings = Vec::new();
        let limits = self.limit_checks(peaks, &mut warnings);
        let overturning_moment = self.overturning(peaks, &mut warnings);
        for a in actuators.iter().filter(|a| !a.respected) {
            warnings.push(format!(
                "actuator {} beyond its stroke or force limits",
                a.name
            ));
        }
        let loop_figures = stats.map(|st| self.loop_summary(st, &mut warnings));
        let axes_respected = limits.values().all(|l| l.respected);
        let overturning_respected = overturning_moment.as_ref().is_none_or(|o| o.respected);
        TableSummary {
            tracking: peaks.tracking(),
            limits,
            overturning_moment,
            loop_figures: loop_figures.flatten(),
            warnings,
            name: self.name.clone(),
            kind: match self.run {
                TableRunSpec::Inverse { .. } => "inverse",
                TableRunSpec::Forward { .. } => "forward",
                TableRunSpec::Loop { .. } => "closed_loop",
            },
            samples: peaks.samples(),
            duration_s: peaks.span_s(),
            derived: self.derived.clone(),
            axes: axis_peaks(peaks),
            within_limits: actuators.iter().all(|a| a.respected)
                && axes_respected
                && overturning_respected,
            actuators,
            struts: self.strut_peaks(peaks),
            specimen: specimen_peaks(peaks),
            output: output.map(|p| p.display().to_string()),
        }
    }

    /// Each actuator's peaks against its limits.
    fn actuator_peaks(&self, peaks: &TablePeaks<'_>) -> Vec<ActuatorPeaks> {
        let capacities = self.flow_capacities_m3_s();
        self.table
            .actuators()
            .iter()
            .zip(self.force_limits_n())
            .enumerate()
            .map(|(i, (a, (pull, push)))| {
                let force = format!("{}_force_n", a.name);
                let stroke = peaks.abs_max(&format!("{}_stroke_m", a.name));
                let (max, min) = (peaks.max(&force), peaks.min(&force));
                let capacity = capacities.as_ref().map(|c| c[i]);
                let flow = peaks.abs_max_of(&format!("{}_flow_m3_s", a.name));
                let saturated = peaks.saturated_time_s(&format!("{}_drive", a.name));
                ActuatorPeaks {
                    name: a.name.clone(),
                    peak_stroke_m: stroke,
                    stroke_limit_m: a.stroke_m,
                    max_force_n: max,
                    min_force_n: min,
                    push_limit_n: push,
                    pull_limit_n: pull,
                    peak_flow_m3_s: flow,
                    flow_capacity_m3_s: capacity,
                    saturated_time_s: saturated,
                    respected: stroke <= a.stroke_m && max <= push && min >= pull,
                }
            })
            .collect()
    }

    /// Each hold-down strut's force range.
    fn strut_peaks(&self, peaks: &TablePeaks<'_>) -> Vec<StrutPeaks> {
        self.table
            .struts()
            .iter()
            .map(|s| {
                let f = format!("{}_force_n", s.name);
                StrutPeaks {
                    name: s.name.clone(),
                    min_force_n: peaks.min(&f),
                    max_force_n: peaks.max(&f),
                }
            })
            .collect()
    }

    /// Each axis's peaks against `table.limits`, a warning for each exceeded.
    fn limit_checks(
        &self,
        peaks: &TablePeaks<'_>,
        warnings: &mut Vec<String>,
    ) -> BTreeMap<&'static str, AxisLimitCheck> {
        Dof::ALL
            .iter()
            .zip(self.limits.each())
            .map(|(d, [u, v, a])| {
                let k = d.index();
                let peaks = [
                    peaks.abs_max(POSE_COLUMNS[k]),
                    peaks.abs_max(RATE_COLUMNS[k]),
                    peaks.abs_max(ACCELERATION_COLUMNS[k]),
                ];
                let mut respected = true;
                let checks = [u, v, a].into_iter().zip(peaks);
                for ((limit, peak), what) in checks.zip(["displacement", "rate", "acceleration"]) {
                    if let Some(l) = limit.filter(|l| peak > *l) {
                        respected = false;
                        warnings.push(format!(
                            "{} {what} {peak:.4e} beyond its limit {l:.4e} (table.limits)",
                            d.name()
                        ));
                    }
                }
                let check = AxisLimitCheck {
                    displacement_limit: u,
                    rate_limit: v,
                    acceleration_limit: a,
                    respected,
                };
                (d.name(), check)
            })
            .collect()
    }

    /// The specimen's peak overturning moment against the table's limit (`None` without a
    /// specimen), a warning when exceeded.
    fn overturning(
        &self,
        peaks: &TablePeaks<'_>,
        warnings: &mut Vec<String>,
    ) -> Option<OverturningSummary> {
        let peak = peaks.peak_overturning_n_m()?;
        let limit = self.limits.overturning_moment_n_m;
        let respected = limit.is_none_or(|l| peak <= l);
        if !respected {
            warnings.push(format!(
                "overturning moment {peak:.4e} N·m beyond the table's {:.4e} N·m",
                limit.unwrap_or_default()
            ));
        }
        Some(OverturningSummary {
            peak_n_m: peak,
            limit_n_m: limit,
            respected,
        })
    }

    /// The closed loop's figures (`None` without one): its statistics `st`, its linearised
    /// stability and margins, and their warnings (an unstable loop's first).
    fn loop_summary(
        &self,
        st: &TableLoopStats,
        warnings: &mut Vec<String>,
    ) -> Option<TableLoopSummary> {
        let sys = self.system.as_ref()?;
        let (stability, loop_margins) = match self.linearisation() {
            Some(lin) => {
                let (s, m) = loop_verdict(&lin);
                (Some(s), m)
            }
            None => (None, BTreeMap::new()),
        };
        if let Some(words) = stability.as_ref().and_then(|s| s.unstable_words()) {
            // The most serious first.
            warnings.insert(
                0,
                format!(
                    "the closed loop is unstable (linearised at neutral, {words}): the run shows \
                     what the table would do, but check the controller's gains (`platen model \
                     --scenario` shows each DOF's margins)"
                ),
            );
        }
        if let Some(at) = st.cavitation_at_s {
            warnings.push(format!(
                "cavitation: a chamber reached 0 Pa (absolute) at t = {at:.4} s"
            ));
        }
        if st.saturated_time_s > 0.0 {
            warnings.push(format!(
                "drives saturated for {:.3} s: the table could not follow its command",
                st.saturated_time_s
            ));
        }
        Some(TableLoopSummary {
            saturated_time_s: st.saturated_time_s,
            cavitation_at_s: st.cavitation_at_s,
            min_supply_pressure_pa: st.min_supply_pressure_pa,
            max_warping_force_n: st.max_warping_force_n,
            hydraulic_energy_j: st.hydraulic_energy_j,
            controller_samples: st.controller_samples,
            steps_per_period: sys.method.steps_per_period(),
            stability,
            loop_margins,
        })
    }
}

/// Each DOF's peaks.
fn axis_peaks(peaks: &TablePeaks<'_>) -> BTreeMap<&'static str, AxisPeaks> {
    Dof::ALL
        .iter()
        .map(|d| {
            let k = d.index();
            let peaks = AxisPeaks {
                peak: peaks.abs_max(POSE_COLUMNS[k]),
                peak_rate: peaks.abs_max(RATE_COLUMNS[k]),
                peak_acceleration: peaks.abs_max(ACCELERATION_COLUMNS[k]),
            };
            (d.name(), peaks)
        })
        .collect()
}

/// The specimen's peak base forces and overturning moments, by column (empty without one).
fn specimen_peaks(peaks: &TablePeaks<'_>) -> BTreeMap<&'static str, f64> {
    [
        "base_force_x_n",
        "base_force_y_n",
        "base_force_z_n",
        "overturning_moment_x_n_m",
        "overturning_moment_y_n_m",
    ]
    .into_iter()
    .filter_map(|c| peaks.abs_max_of(c).map(|v| (c, v)))
    .collect()
}
