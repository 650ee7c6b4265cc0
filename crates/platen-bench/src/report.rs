//! What a measurement gives: each workload's time against the baseline's, its ratio and its
//! final state, as JSON (`platen bench --json`); `platen_report::bench_report` writes it as
//! text.

use super::*;

/// The measured workloads ([`measure`]).
#[derive(Debug, Clone)]
pub struct Measurement {
    /// The workloads with their runs, in the order they ran.
    pub workloads: Vec<Workload>,
    /// Simulated time of every record, s.
    pub simulated_s: f64,
    /// Runs of each workload.
    pub repeats: u32,
    /// The baseline's final state.
    pub baseline_end: State,
}

/// The `u_m` and `v_m_s` of a state, as the report shows it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FinalState {
    /// Displacement, m.
    pub u_m: f64,
    /// Velocity, m/s.
    pub v_m_s: f64,
}

/// The figures of one workload (`workloads` of [`BenchReport`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorkloadReport {
    /// Median wall time of a run, s.
    pub median_wall_s: f64,
    /// Shortest wall time of a run, s.
    pub min_wall_s: f64,
    /// Median time per unit of work, ns.
    pub ns_per_unit: f64,
    /// Runs measured.
    pub runs: usize,
    /// Simulated seconds per wall-clock second (median run).
    pub simulated_s_per_wall_s: f64,
    /// What one unit of work is.
    pub unit: &'static str,
    /// Units of work per run.
    pub units_per_run: u64,
    /// Units of work per wall-clock second (median run).
    pub units_per_s: f64,
}

/// `platen bench --json`: the headline figures and every workload's (fields in alphabetical
/// order, as the command has always printed them).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchReport {
    /// The baseline's final state (the same loop in C, `benches/c/rk4_baseline.c`, ends in
    /// the same state, to the bit).
    pub baseline_final_state: FinalState,
    /// The baseline's time per step, ns.
    pub baseline_ns_per_step: f64,
    /// Dopri5's time per accepted step, ns.
    pub dopri5_ns_per_accepted_step: f64,
    /// Lanes of the ensemble.
    pub ensemble_lanes: usize,
    /// The ensemble's time per step per trajectory, ns.
    pub ensemble_ns_per_step_per_trajectory: f64,
    /// The ensemble's time over the scalar runs'.
    pub ensemble_ratio_to_scalar: f64,
    /// The scalar runs' time per step, ns.
    pub ensemble_scalar_ns_per_step: f64,
    /// Amplitude of the forward workloads' force, N.
    pub force_amplitude_n: f64,
    /// Frequency of the forward workloads' force, Hz.
    pub force_frequency_hz: f64,
    /// Hold-down pressure, MPa.
    pub hold_down_pressure_mpa: f64,
    /// The inverse run's time per sample, ns.
    pub inverse_ns_per_sample: f64,
    /// The model preset.
    pub preset: &'static str,
    /// Runs of each workload.
    pub repeats: u32,
    /// The full model's RK4 time per step, ns.
    pub rk4_full_ns_per_step: f64,
    /// Its ratio to the baseline's.
    pub rk4_full_ratio_to_baseline: f64,
    /// The identified model's RK4 time per step, ns.
    pub rk4_ns_per_step: f64,
    /// Its ratio to the baseline's.
    pub rk4_ratio_to_baseline: f64,
    /// Simulated seconds per wall-clock second of the RK4 workload.
    pub rk4_simulated_s_per_wall_s: f64,
    /// The specimen run's time per step, ns.
    pub rk4_specimen_ns_per_step: f64,
    /// Its ratio to the baseline's.
    pub rk4_specimen_ratio_to_baseline: f64,
    /// RK4 steps per second.
    pub rk4_steps_per_s: f64,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Simulated time of every record, s.
    pub simulated_s: f64,
    /// The LHPOST6 preset's closed-loop step (RK4, 10 actuators with their hydraulics, the
    /// DOF controller), ns.
    pub six_dof_closed_loop_ns_per_step: f64,
    /// [`BenchReport::six_dof_closed_loop_ns_per_step`] over the uniaxial closed loop's step
    /// ([`BenchReport::table_system_ns_per_step`]), measured in the same run.
    pub six_dof_closed_loop_ratio_to_table_system: f64,
    /// The six-DOF table's forward step (RK4, 10 actuators, 4 struts, 6 pads), ns.
    pub six_dof_ns_per_step: f64,
    /// [`BenchReport::six_dof_ns_per_step`] over the baseline's step.
    pub six_dof_ratio_to_baseline: f64,
    /// The closed loop's time per step, ns.
    pub table_system_ns_per_step: f64,
    /// Its ratio to the baseline's.
    pub table_system_ratio_to_baseline: f64,
    /// Every workload's figures, by key.
    pub workloads: BTreeMap<&'static str, WorkloadReport>,
}

impl Measurement {
    /// The workload under `key`.
    ///
    /// # Panics
    ///
    /// If `key` is not one of the standard workloads'.
    pub fn get(&self, key: &str) -> &Workload {
        self.workloads
            .iter()
            .find(|w| w.key == key)
            .expect("a standard workload")
    }

    /// The baseline's time per step, ns.
    pub fn base_ns(&self) -> f64 {
        self.get("baseline").ns_per_unit()
    }

    /// The report (`platen bench --json`).
    pub fn report(&self) -> BenchReport {
        let simulated_s = self.simulated_s;
        let base = self.base_ns();
        let ns = |key: &str| self.get(key).ns_per_unit();
        let end = self.baseline_end;
        BenchReport {
            baseline_final_state: FinalState {
                u_m: end.u_m,
                v_m_s: end.v_m_s,
            },
            baseline_ns_per_step: base,
            dopri5_ns_per_accepted_step: ns("dopri5"),
            ensemble_lanes: ENSEMBLE_LANES,
            ensemble_ns_per_step_per_trajectory: ns("ensemble"),
            ensemble_ratio_to_scalar: ns("ensemble") / ns("ensemble_scalar"),
            ensemble_scalar_ns_per_step: ns("ensemble_scalar"),
            force_amplitude_n: FORCE_AMPLITUDE_N,
            force_frequency_hz: FORCE_FREQUENCY_HZ,
            hold_down_pressure_mpa: PRESSURE_PA / 1e6,
            inverse_ns_per_sample: ns("inverse"),
            preset: "lhpost-2008",
            repeats: self.repeats,
            rk4_full_ns_per_step: ns("rk4_full"),
            rk4_full_ratio_to_baseline: ns("rk4_full") / base,
            rk4_ns_per_step: ns("rk4"),
            rk4_ratio_to_baseline: ns("rk4") / base,
            rk4_simulated_s_per_wall_s: simulated_s / self.get("rk4").median_s(),
            rk4_specimen_ns_per_step: ns("rk4_specimen"),
            rk4_specimen_ratio_to_baseline: ns("rk4_specimen") / base,
            rk4_steps_per_s: 1e9 / ns("rk4"),
            six_dof_ns_per_step: ns("six_dof"),
            six_dof_ratio_to_baseline: ns("six_dof") / base,
            six_dof_closed_loop_ns_per_step: ns("six_dof_closed_loop"),
            six_dof_closed_loop_ratio_to_table_system: ns("six_dof_closed_loop")
                / ns("table_system"),
            sample_rate_hz: RATE_HZ,
            simulated_s,
            table_system_ns_per_step: ns("table_system"),
            table_system_ratio_to_baseline: ns("table_system") / base,
            workloads: self
                .workloads
                .iter()
                .map(|w| (w.key, w.report(simulated_s)))
                .collect(),
        }
    }
}
