//! A table system's closed forms and linearised loop, as `platen model --system` and
//! `--scenario` describe them (re-exported by [`crate::describe`]): its parameters in the
//! scenario format ([`TableSystemSpec`]), the oil-column frequencies, the valve-limited velocities, the flow and
//! force capacities, the linearisation about mid-stroke, the loop's margins and closed-loop
//! passband, and the default RK4 step per controller period.

use serde::Serialize;

use platen_system::{Linearisation, Margins, Mechanics, Passband, TableSystem, SECANT_SPEED_M_S};

use crate::scenario::Model;
use crate::summary::LoopMargins;
use crate::system_file::TableSystemSpec;

/// The small-signal coefficients of the loop about mid-stroke (`linearisation`; see
/// [`Linearisation`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LinearisationDescription {
    /// Hydraulic compliance of chamber `a`, `V_a/β`, m³/Pa.
    pub compliance_a_m3_per_pa: f64,
    /// Hydraulic compliance of chamber `b`, `V_b/β`, m³/Pa.
    pub compliance_b_m3_per_pa: f64,
    /// Secant damping of the mechanics, N·s/m.
    pub damping_n_s_per_m: f64,
    /// The speed of that secant, m/s ([`SECANT_SPEED_M_S`]).
    pub damping_secant_speed_m_s: f64,
    /// Flow gain of the cap-side land `K_qa`, m³/s per unit opening (one actuator).
    pub flow_gain_a_m3_s: f64,
    /// Flow gain of the rod-side land `K_qb`, m³/s per unit opening.
    pub flow_gain_b_m3_s: f64,
    /// Flow-pressure coefficient `K_c`, m³/s/Pa.
    pub flow_pressure_m3_s_per_pa: f64,
    /// Moving mass (payload included), kg.
    pub mass_kg: f64,
    /// Restoring stiffness, N/m.
    pub stiffness_n_per_m: f64,
}

impl From<&Linearisation> for LinearisationDescription {
    fn from(lin: &Linearisation) -> Self {
        Self {
            compliance_a_m3_per_pa: lin.compliance_a_m3_per_pa,
            compliance_b_m3_per_pa: lin.compliance_b_m3_per_pa,
            damping_n_s_per_m: lin.mechanics.damping_n_s_per_m,
            damping_secant_speed_m_s: SECANT_SPEED_M_S,
            flow_gain_a_m3_s: lin.flow_gain_a_m3_s,
            flow_gain_b_m3_s: lin.flow_gain_b_m3_s,
            flow_pressure_m3_s_per_pa: lin.flow_pressure_m3_s_per_pa,
            mass_kg: lin.mechanics.mass_kg,
            stiffness_n_per_m: lin.mechanics.stiffness_n_per_m,
        }
    }
}

/// [`LoopMargins`]' former name in `platen model`'s description.
pub type LoopMarginsDescription = LoopMargins;

/// The `table_system` object of `platen model --json` (SI; fields in alphabetical order).
/// The loop described is the one the table drives: with the specimen as a rigid payload
/// when there is one, else the bare table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SystemDescription {
    /// The closed loop's −3 dB bandwidth, Hz (see [`Passband`]).
    pub closed_loop_bandwidth_hz: Option<f64>,
    /// Its lowest gain below the peak.
    pub closed_loop_min_gain: f64,
    /// Where it is, Hz.
    pub closed_loop_min_gain_hz: f64,
    /// Controller sample rate, Hz.
    pub controller_sample_rate_hz: f64,
    /// Force of all actuators at stall pulling, N.
    pub force_capacity_pull_n: f64,
    /// Force of all actuators at stall pushing, N.
    pub force_capacity_push_n: f64,
    /// The linearisation about mid-stroke.
    pub linearisation: LinearisationDescription,
    /// The loop's margins and peak.
    pub loop_margins: LoopMargins,
    /// The model's moving mass at mid-stroke (bare table), kg.
    pub model_mass_kg: f64,
    /// Null pressure of chamber `a`, Pa.
    pub null_pressure_a_pa: f64,
    /// Null pressure of chamber `b`, Pa.
    pub null_pressure_b_pa: f64,
    /// Oil-column frequency at `u = +stroke` (with the specimen, if any), Hz.
    pub oil_column_frequency_extended_hz: f64,
    /// Oil-column frequency at mid-stroke, bare table, Hz.
    pub oil_column_frequency_hz: f64,
    /// Oil-column frequency at `u = −stroke` (with the specimen, if any), Hz.
    pub oil_column_frequency_retracted_hz: f64,
    /// Oil-column frequency at mid-stroke with the specimen as a rigid payload, Hz.
    pub oil_column_frequency_with_specimen_hz: Option<f64>,
    /// The system's parameters in the scenario format, every value given
    /// ([`TableSystemSpec::from`]; printed with its keys sorted).
    #[serde(serialize_with = "sorted")]
    pub parameters: TableSystemSpec,
    /// The system described (what `parameters` writes; not printed).
    #[serde(skip)]
    pub system: TableSystem,
    /// The preset the system came from (`None`, printed `null`: a scenario's own values).
    pub preset: Option<String>,
    /// The specimen's mass, kg.
    pub specimen_mass_kg: Option<f64>,
    /// The default RK4 step of closed-loop runs, s.
    pub step_s: f64,
    /// Default RK4 steps per controller period.
    pub steps_per_controller_period: u32,
    /// The table's stroke, either way, m.
    pub stroke_m: f64,
    /// Flow of all valves at full opening with the null drop on each land, m³/s.
    pub valve_flow_capacity_m3_s: f64,
    /// No-load velocity at full opening, extending, m/s.
    pub valve_limited_velocity_extend_m_s: f64,
    /// No-load velocity at full opening, retracting, m/s.
    pub valve_limited_velocity_retract_m_s: f64,
}

/// `value` written as a JSON object with its keys in alphabetical order (the order of the
/// contract's JSON), whatever the order of its type's fields.
fn sorted<S: serde::Serializer, T: Serialize>(value: &T, s: S) -> Result<S::Ok, S::Error> {
    serde_json::to_value(value)
        .map_err(serde::ser::Error::custom)?
        .serialize(s)
}

/// A table system driving a model, linearised about mid-stroke: the bare table and, with a
/// specimen, the table with the specimen as a rigid payload; the margins, passband and
/// default step of the loop the table drives.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemAnalysis {
    /// The preset the system came from (`None`: a scenario's own values).
    pub preset: Option<String>,
    /// The system.
    pub system: TableSystem,
    /// The model's mass at mid-stroke, kg.
    pub model_mass_kg: f64,
    /// The specimen's mass, kg.
    pub specimen_mass_kg: Option<f64>,
    /// The table's stroke, either way, m.
    pub stroke_m: f64,
    /// The loop about mid-stroke driving the bare table.
    pub bare: Linearisation,
    /// The loop driving the table with the specimen as a rigid payload.
    pub loaded: Option<Linearisation>,
    /// The margins of the loop the table drives ([`SystemAnalysis::driven`]).
    pub margins: Margins,
    /// Its closed loop's bandwidth and lowest gain below it.
    pub passband: Passband,
    /// Default RK4 steps per controller period.
    pub steps_per_controller_period: u32,
}

impl SystemAnalysis {
    /// `system` (from the preset named `preset`, if any) driving `model` over the stroke
    /// `±stroke_m`, with a specimen of `specimen_mass_kg` as a rigid payload if given.
    pub fn new(
        preset: Option<String>,
        system: TableSystem,
        model: &Model,
        stroke_m: f64,
        specimen_mass_kg: Option<f64>,
    ) -> Self {
        let mechanics = |payload: f64| match model {
            Model::Identified(m) => Mechanics::of_model(m, payload),
            Model::Full(m) => Mechanics::of_model(&**m, payload),
        };
        let bare = system.linearise(mechanics(0.0), 0.0);
        let loaded = specimen_mass_kg.map(|m| system.linearise(mechanics(m), 0.0));
        let driven = loaded.as_ref().unwrap_or(&bare);
        Self {
            preset,
            model_mass_kg: bare.mechanics.mass_kg,
            specimen_mass_kg,
            stroke_m,
            margins: system.margins(driven),
            passband: system.passband(driven),
            steps_per_controller_period: system
                .default_steps_per_period(driven.mechanics.mass_kg, stroke_m),
            system,
            bare,
            loaded,
        }
    }

    /// The linearisation of the loop the table drives (with the specimen, if any).
    pub fn driven(&self) -> &Linearisation {
        self.loaded.as_ref().unwrap_or(&self.bare)
    }

    /// The description (`table_system` of `platen model --json`).
    pub fn description(&self) -> SystemDescription {
        let sys = &self.system;
        let caps = sys.capacities();
        let driven_kg = self.driven().mechanics.mass_kg;
        let (p_a0, p_b0) = sys.null_pressures_pa();
        let period = sys.controller().period_s();
        SystemDescription {
            closed_loop_bandwidth_hz: self.passband.bandwidth_hz,
            closed_loop_min_gain: self.passband.min_gain,
            closed_loop_min_gain_hz: self.passband.min_gain_hz,
            controller_sample_rate_hz: sys.controller().sample_rate_hz,
            force_capacity_pull_n: caps.pull_force_n,
            force_capacity_push_n: caps.push_force_n,
            linearisation: LinearisationDescription::from(self.driven()),
            loop_margins: LoopMargins::from(&self.margins),
            model_mass_kg: self.model_mass_kg,
            null_pressure_a_pa: p_a0,
            null_pressure_b_pa: p_b0,
            oil_column_frequency_extended_hz: sys.oil_column_frequency_hz(driven_kg, self.stroke_m),
            oil_column_frequency_hz: sys.oil_column_frequency_hz(self.model_mass_kg, 0.0),
            oil_column_frequency_retracted_hz: sys
                .oil_column_frequency_hz(driven_kg, -self.stroke_m),
            oil_column_frequency_with_specimen_hz: self
                .loaded
                .map(|l| sys.oil_column_frequency_hz(l.mechanics.mass_kg, 0.0)),
            parameters: TableSystemSpec::from(sys),
            system: *sys,
            preset: self.preset.clone(),
            specimen_mass_kg: self.specimen_mass_kg,
            step_s: period / f64::from(self.steps_per_controller_period),
            steps_per_controller_period: self.steps_per_controller_period,
            stroke_m: self.stroke_m,
            valve_flow_capacity_m3_s: caps.valve_flow_m3_s,
            valve_limited_velocity_extend_m_s: caps.extend_velocity_m_s,
            valve_limited_velocity_retract_m_s: caps.retract_velocity_m_s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use platen_model::Preset;

    fn model() -> Model {
        Model::Identified(
            Preset::Lhpost2008
                .identified(13.8e6)
                .unwrap()
                .build()
                .unwrap(),
        )
    }

    /// The LHPOST's published oil column (10.66 Hz bare), and a specimen lowering it.
    #[test]
    fn the_description_holds_the_closed_forms_and_the_loop() {
        let sys = platen_system::preset::lhpost_2008();
        let bare = SystemAnalysis::new(Some("lhpost-2008".into()), sys, &model(), 0.75, None);
        let d = bare.description();
        assert!((d.oil_column_frequency_hz - 10.66).abs() < 0.01, "{d:?}");
        assert_eq!(d.oil_column_frequency_with_specimen_hz, None);
        assert!(d.loop_margins.stable);
        assert_eq!(d.parameters, TableSystemSpec::from(&sys));
        let loaded = SystemAnalysis::new(None, sys, &model(), 0.75, Some(40e3)).description();
        let with = loaded.oil_column_frequency_with_specimen_hz.unwrap();
        assert!(with < d.oil_column_frequency_hz, "{with}");
        assert_eq!(loaded.linearisation.mass_kg, 184e3);
        assert_eq!(loaded.model_mass_kg, 144e3);
    }

    /// Fields in alphabetical order: printed as they are, they give the sorted JSON object.
    #[test]
    fn the_struct_prints_its_keys_in_the_json_objects_order() {
        let sys = platen_system::preset::lhpost_2008();
        let d = SystemAnalysis::new(None, sys, &model(), 0.75, Some(40e3)).description();
        let direct = serde_json::to_string_pretty(&d).unwrap();
        let sorted = serde_json::to_string_pretty(&serde_json::to_value(&d).unwrap()).unwrap();
        assert_eq!(direct, sorted);
        assert!(direct.contains("\"preset\": null"), "{direct}");
    }
}
