//! What a run is compared on: the direction of the run and the compared channels.

use platen_integrate::{SpecimenColumns, Trajectory};
use platen_model::Specimen;
use platen_scenario::{PlatenScenario, Run};
use serde::Serialize;

/// What drives the model, and so what is compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Force → motion: the displacement and the velocity are compared.
    Forward,
    /// Motion → force: the actuator force is compared.
    Inverse,
}

impl Direction {
    /// The direction of `scenario`'s run. A closed loop is compared on its actuator force,
    /// as an inverse run is: the loop makes the force that the command's motion needs.
    pub fn of(scenario: &PlatenScenario) -> Self {
        match &scenario.run {
            Run::Forward { .. } => Direction::Forward,
            Run::Inverse { .. } | Run::ClosedLoop { .. } => Direction::Inverse,
        }
    }

    /// `"forward"` or `"inverse"`.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Forward => "forward",
            Direction::Inverse => "inverse",
        }
    }

    /// The channels compared in this direction, in report order.
    pub fn channels(self) -> &'static [Channel] {
        match self {
            Direction::Forward => &[Channel::Displacement, Channel::Velocity],
            Direction::Inverse => &[Channel::Force],
        }
    }

    /// The record's columns that a comparison in this direction needs, and those it uses
    /// where present.
    pub fn record_columns(self) -> (&'static [&'static str], &'static [&'static str]) {
        match self {
            Direction::Forward => (&["t_s", "u_m"], &["v_m_s", "a_m_s2", "force_n"]),
            Direction::Inverse => (&["t_s", "force_n"], &["u_m", "v_m_s", "a_m_s2"]),
        }
    }
}

/// A compared channel. It serialises as its column name ([`Channel::name`]).
///
/// The platen's channels are compared in every run of their direction; the specimen's
/// (`BaseShear`, `StoreyDisplacement`, `StoreyAcceleration`) when the scenario has a specimen
/// and the recording has the column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Channel {
    /// Platen displacement `u_m`, m.
    Displacement,
    /// Platen velocity `v_m_s`, m/s.
    Velocity,
    /// Actuator force `force_n`, N.
    Force,
    /// The specimen's base shear `base_shear_n`, N.
    BaseShear,
    /// Storey `i`'s displacement relative to the platen, `storey{i}_u_m`, m (the storey
    /// from 1 to [`Specimen::MAX_STOREYS`](platen_model::Specimen::MAX_STOREYS)).
    StoreyDisplacement(u8),
    /// Storey `i`'s absolute acceleration, `storey{i}_a_m_s2`, m/s² (the storey from 1 to
    /// [`Specimen::MAX_STOREYS`](platen_model::Specimen::MAX_STOREYS)).
    StoreyAcceleration(u8),
}

/// Builds `[concat!(prefix, "1", suffix), …, concat!(prefix, "12", suffix)]`.
macro_rules! per_storey {
    ($prefix:literal, $suffix:literal) => {
        [
            concat!($prefix, "1", $suffix),
            concat!($prefix, "2", $suffix),
            concat!($prefix, "3", $suffix),
            concat!($prefix, "4", $suffix),
            concat!($prefix, "5", $suffix),
            concat!($prefix, "6", $suffix),
            concat!($prefix, "7", $suffix),
            concat!($prefix, "8", $suffix),
            concat!($prefix, "9", $suffix),
            concat!($prefix, "10", $suffix),
            concat!($prefix, "11", $suffix),
            concat!($prefix, "12", $suffix),
        ]
    };
}

const STOREY_U_QUANTITY: [&str; Specimen::MAX_STOREYS] =
    per_storey!("storey ", " displacement (relative to the platen)");
const STOREY_A_QUANTITY: [&str; Specimen::MAX_STOREYS] =
    per_storey!("storey ", " acceleration (absolute)");
const STOREY_U_SYMBOL: [&str; Specimen::MAX_STOREYS] = per_storey!("z_", "");
const STOREY_A_SYMBOL: [&str; Specimen::MAX_STOREYS] = per_storey!("a_", "");

impl Channel {
    /// The specimen's channels a run of `storeys` storeys can compare, in report order:
    /// base shear, storey displacements, storey accelerations.
    pub fn specimen_channels(storeys: usize) -> impl Iterator<Item = Channel> {
        let storeys = storeys.min(Specimen::MAX_STOREYS) as u8;
        std::iter::once(Channel::BaseShear)
            .chain((1..=storeys).map(Channel::StoreyDisplacement))
            .chain((1..=storeys).map(Channel::StoreyAcceleration))
    }

    /// Index `i − 1` into the per-storey tables.
    fn storey_index(i: u8) -> usize {
        usize::from(i).clamp(1, Specimen::MAX_STOREYS) - 1
    }

    /// The CSV column and JSON key: `"u_m"`, `"v_m_s"`, `"force_n"`, `"base_shear_n"`,
    /// `"storey{i}_u_m"` or `"storey{i}_a_m_s2"`.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Displacement => "u_m",
            Channel::Velocity => "v_m_s",
            Channel::Force => "force_n",
            Channel::BaseShear => SpecimenColumns::BASE_SHEAR_NAME,
            Channel::StoreyDisplacement(i) => {
                SpecimenColumns::STOREY_U_NAMES[Self::storey_index(i)]
            }
            Channel::StoreyAcceleration(i) => {
                SpecimenColumns::STOREY_A_NAMES[Self::storey_index(i)]
            }
        }
    }

    /// The plain name: `"displacement"`, `"velocity"`, `"actuator force"`, `"base shear"`,
    /// `"storey 1 displacement (relative to the platen)"`, `"storey 1 acceleration
    /// (absolute)"`.
    pub fn quantity(self) -> &'static str {
        match self {
            Channel::Displacement => "displacement",
            Channel::Velocity => "velocity",
            Channel::Force => "actuator force",
            Channel::BaseShear => "base shear",
            Channel::StoreyDisplacement(i) => STOREY_U_QUANTITY[Self::storey_index(i)],
            Channel::StoreyAcceleration(i) => STOREY_A_QUANTITY[Self::storey_index(i)],
        }
    }

    /// The symbol: `"u"`, `"v"`, `"F_A"`, `"B"`, `"z_1"` or `"a_1"`.
    pub fn symbol(self) -> &'static str {
        match self {
            Channel::Displacement => "u",
            Channel::Velocity => "v",
            Channel::Force => "F_A",
            Channel::BaseShear => "B",
            Channel::StoreyDisplacement(i) => STOREY_U_SYMBOL[Self::storey_index(i)],
            Channel::StoreyAcceleration(i) => STOREY_A_SYMBOL[Self::storey_index(i)],
        }
    }

    /// The SI unit of the column: `"m"`, `"m/s"`, `"N"` or `"m/s²"`.
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Displacement | Channel::StoreyDisplacement(_) => "m",
            Channel::Velocity => "m/s",
            Channel::Force | Channel::BaseShear => "N",
            Channel::StoreyAcceleration(_) => "m/s²",
        }
    }

    /// The simulated column of this channel in `sim` (`None` for a specimen channel of a
    /// run without one, or a storey it does not have).
    pub(crate) fn of(self, sim: &Trajectory) -> Option<&[f64]> {
        match self {
            Channel::Displacement => Some(&sim.u_m),
            Channel::Velocity => Some(&sim.v_m_s),
            Channel::Force => Some(&sim.force_n),
            _ => sim.specimen.as_ref()?.column(self.name()),
        }
    }
}

impl Serialize for Channel {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl std::fmt::Display for Channel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_channel_serialises_as_its_column_name() {
        for c in [Channel::Displacement, Channel::Velocity, Channel::Force]
            .into_iter()
            .chain(Channel::specimen_channels(Specimen::MAX_STOREYS))
        {
            let json = serde_json::to_value(c).unwrap();
            assert_eq!(json, serde_json::Value::from(c.name()));
        }
    }

    /// The storey tables hold storey `i` at index `i − 1` (the names are written out here,
    /// not by the tables' macro).
    #[test]
    fn storey_channels_name_their_storey() {
        for i in 1..=Specimen::MAX_STOREYS as u8 {
            assert_eq!(
                Channel::StoreyDisplacement(i).name(),
                format!("storey{i}_u_m")
            );
            assert_eq!(
                Channel::StoreyAcceleration(i).name(),
                format!("storey{i}_a_m_s2")
            );
            assert_eq!(Channel::StoreyDisplacement(i).symbol(), format!("z_{i}"));
            assert!(Channel::StoreyAcceleration(i)
                .quantity()
                .starts_with(&format!("storey {i} ")));
        }
        let names: Vec<_> = Channel::specimen_channels(2).map(Channel::name).collect();
        assert_eq!(
            names,
            [
                "base_shear_n",
                "storey1_u_m",
                "storey2_u_m",
                "storey1_a_m_s2",
                "storey2_a_m_s2"
            ]
        );
    }
}
