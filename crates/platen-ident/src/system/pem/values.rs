//! The fit's parameters and the loop's values they set: each parameter's coordinate (its
//! logarithm relative to the start, or linear within bounds), the values a parameter vector
//! makes and the loop they build.

use platen_model::{IdentifiedModel, IdentifiedParams, Specimen, Storey};
use platen_system::{TableSystem, TableSystemParts};

use super::LoopValues;
use crate::system::plant::STROKE_FRACTION_OF_ROOM;

/// Largest relative change of a logarithmic parameter over the whole fit (`e^±5`).
const MAX_LOG_CHANGE: f64 = 5.0;

/// What a parameter is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Kind {
    Mass,
    Coulomb,
    Viscous,
    Stribeck,
    Exponent,
    StoreyMass(usize),
    StoreyStiffness(usize),
    StoreyDamping(usize),
    RatedFlow,
    ValveLag,
    ChamberVolume,
}

/// How a parameter's coordinate `θ` gives its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Coordinate {
    /// `start·e^θ`, `|θ| ≤ MAX_LOG_CHANGE`.
    Log,
    /// `unit·θ`, `θ·unit ∈ [min, max]`.
    Linear { unit: f64, min: f64, max: f64 },
}

/// One parameter of the fit.
#[derive(Debug, Clone)]
pub(super) struct Param {
    /// What it sets.
    pub kind: Kind,
    /// Its path in the printed scenario, or what it scales ([`super::PemParameter::key`]).
    pub key: String,
    /// The equation error's value.
    pub start: f64,
    /// How its coordinate gives its value.
    pub coordinate: Coordinate,
}

impl Param {
    /// The coordinate of the start.
    pub(super) fn theta0(&self) -> f64 {
        match self.coordinate {
            Coordinate::Log => 0.0,
            Coordinate::Linear { unit, .. } => self.start / unit,
        }
    }

    /// The value at coordinate `theta`.
    pub(super) fn value(&self, theta: f64) -> f64 {
        match self.coordinate {
            Coordinate::Log => self.start * theta.exp(),
            Coordinate::Linear { unit, .. } => unit * theta,
        }
    }

    /// `theta` within the coordinate's bounds.
    pub(super) fn project(&self, theta: f64) -> f64 {
        match self.coordinate {
            Coordinate::Log => theta.clamp(-MAX_LOG_CHANGE, MAX_LOG_CHANGE),
            Coordinate::Linear { unit, min, max } => theta.clamp(min / unit, max / unit),
        }
    }

    /// `d value / d θ` at `theta`.
    pub(super) fn derivative(&self, theta: f64) -> f64 {
        match self.coordinate {
            Coordinate::Log => self.value(theta),
            Coordinate::Linear { unit, .. } => unit,
        }
    }
}

/// The loop's values: what a parameter vector sets.
#[derive(Debug, Clone)]
pub(super) struct Values {
    /// The table system's values, its controller's gains included.
    pub parts: TableSystemParts,
    /// The platen's.
    pub model: IdentifiedParams,
    /// The specimen's storeys, bottom first (empty without a specimen).
    pub storeys: Vec<Storey>,
}

/// A loop ready to run.
pub(super) struct Built {
    /// The table system.
    pub system: TableSystem,
    /// The platen.
    pub model: IdentifiedModel,
    /// The specimen, if any.
    pub specimen: Option<Specimen>,
}

impl Values {
    /// The values of a closed loop.
    pub(super) fn of(values: &LoopValues) -> Values {
        Values {
            parts: values.system.into_parts(),
            model: values.model,
            storeys: values
                .specimen
                .as_ref()
                .map_or_else(Vec::new, |s| s.storeys().to_vec()),
        }
    }

    /// These values with `params` at `theta`.
    pub(super) fn with(&self, params: &[Param], theta: &[f64]) -> Values {
        let mut v = self.clone();
        for (p, &t) in params.iter().zip(theta) {
            let x = p.value(t);
            match p.kind {
                Kind::Mass => v.model.effective_mass_kg = x,
                Kind::Coulomb => v.model.coulomb_force_n = x,
                Kind::Viscous => v.model.viscous_coefficient = x,
                Kind::Stribeck => v.model.low_velocity_force_n = x,
                Kind::Exponent => v.model.viscous_exponent = x,
                Kind::StoreyMass(j) => v.storeys[j].mass_kg = x,
                Kind::StoreyStiffness(j) => v.storeys[j].stiffness_n_per_m = x,
                Kind::StoreyDamping(j) => v.storeys[j].damping_n_s_per_m = x,
                Kind::RatedFlow => v.parts.servo_valve.rated_flow_m3_s = x,
                Kind::ValveLag => {
                    let s = x / p.start;
                    v.parts.servo_valve.delay_s = self.parts.servo_valve.delay_s * s;
                    v.parts.servo_valve.natural_frequency_hz =
                        self.parts.servo_valve.natural_frequency_hz / s;
                }
                Kind::ChamberVolume => {
                    let s = x / p.start;
                    v.parts.actuator.cap_volume_m3 = self.parts.actuator.cap_volume_m3 * s;
                    v.parts.actuator.rod_volume_m3 = self.parts.actuator.rod_volume_m3 * s;
                }
            }
        }
        v
    }

    /// The stroke limit the identification gives these chambers.
    pub(super) fn stroke_m(&self) -> f64 {
        let a = &self.parts.actuator;
        STROKE_FRACTION_OF_ROOM
            * (a.cap_volume_m3 / a.cap_area_m2).min(a.rod_volume_m3 / a.rod_area_m2)
    }

    /// The loop, if these values make one.
    pub(super) fn build(&self) -> Option<Built> {
        let system = TableSystem::new(self.parts, self.stroke_m()).ok()?;
        let model = self.model.build().ok()?;
        let specimen = if self.storeys.is_empty() {
            None
        } else {
            Some(Specimen::new(self.storeys.clone()).ok()?)
        };
        Some(Built {
            system,
            model,
            specimen,
        })
    }
}

/// The parameters of the loop's values (module docs), from the equation error's: the
/// platen's, each storey's (mass, stiffness, damping), then the valves' and chambers'.
/// A value that is not positive and finite is not a parameter (held), but for a viscous
/// coefficient held at 0, which moves linearly from 0.
pub(super) fn parameters(v: &Values, mean_speed_m_s: f64) -> Vec<Param> {
    let mut out = platen_parameters(&v.model, mean_speed_m_s);
    for (j, s) in v.storeys.iter().enumerate() {
        push_log(
            &mut out,
            Kind::StoreyMass(j),
            &format!("specimen.storeys[{j}].mass_kg"),
            s.mass_kg,
        );
        push_log(
            &mut out,
            Kind::StoreyStiffness(j),
            &format!("specimen.storeys[{j}].stiffness_n_per_m"),
            s.stiffness_n_per_m,
        );
        push_log(
            &mut out,
            Kind::StoreyDamping(j),
            &format!("specimen.storeys[{j}].damping_n_s_per_m"),
            s.damping_n_s_per_m,
        );
    }
    let sv = &v.parts.servo_valve;
    push_log(
        &mut out,
        Kind::RatedFlow,
        "table_system.servo_valve.rated_flow_m3_s",
        sv.rated_flow_m3_s,
    );
    push_log(
        &mut out,
        Kind::ValveLag,
        "table_system.servo_valve.equivalent_lag_s",
        equivalent_lag_s(sv.delay_s, sv.natural_frequency_hz, sv.damping_ratio),
    );
    push_log(
        &mut out,
        Kind::ChamberVolume,
        "table_system.actuator.chamber_volume_m3",
        v.parts.actuator.cap_volume_m3,
    );
    out
}

/// A logarithmic parameter of `start` into `out`, when `start` is positive and finite.
fn push_log(out: &mut Vec<Param>, kind: Kind, key: &str, start: f64) {
    if start.is_finite() && start > 0.0 {
        out.push(Param {
            kind,
            key: key.to_owned(),
            start,
            coordinate: Coordinate::Log,
        });
    }
}

/// The platen's parameters of [`parameters`]: mass, Coulomb force, viscous coefficient,
/// Stribeck amplitude and (other than 1) the viscous exponent.
fn platen_parameters(m: &IdentifiedParams, mean_speed_m_s: f64) -> Vec<Param> {
    let mut out = Vec::new();
    push_log(
        &mut out,
        Kind::Mass,
        "model.identified.effective_mass_kg",
        m.effective_mass_kg,
    );
    push_log(
        &mut out,
        Kind::Coulomb,
        "model.identified.coulomb_force_n",
        m.coulomb_force_n,
    );
    if m.viscous_coefficient > 0.0 {
        push_log(
            &mut out,
            Kind::Viscous,
            "model.identified.viscous_coefficient",
            m.viscous_coefficient,
        );
    } else {
        // Held at 0 by the equation error: free from 0 upwards, in units of the force that
        // equals the mass times 1 m/s² at the records' mean speed.
        let unit = m.effective_mass_kg / mean_speed_m_s.max(1e-6).powf(m.viscous_exponent) * 1e-2;
        out.push(Param {
            kind: Kind::Viscous,
            key: "model.identified.viscous_coefficient".into(),
            start: 0.0,
            coordinate: Coordinate::Linear {
                unit,
                min: 0.0,
                max: f64::INFINITY,
            },
        });
    }
    push_log(
        &mut out,
        Kind::Stribeck,
        "model.identified.low_velocity_force_n",
        m.low_velocity_force_n,
    );
    if m.viscous_exponent != 1.0 && m.viscous_exponent.is_finite() {
        out.push(Param {
            kind: Kind::Exponent,
            key: "model.identified.viscous_exponent".into(),
            start: m.viscous_exponent,
            coordinate: Coordinate::Linear {
                unit: 1.0,
                min: 0.0,
                max: 1.0,
            },
        });
    }
    out
}

/// `τ + 2ζ/ω_n`, s.
pub(super) fn equivalent_lag_s(delay_s: f64, natural_frequency_hz: f64, damping_ratio: f64) -> f64 {
    delay_s + 2.0 * damping_ratio / (std::f64::consts::TAU * natural_frequency_hz)
}
