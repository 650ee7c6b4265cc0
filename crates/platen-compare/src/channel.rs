//! What a run is compared on: the direction of the run and the compared channels.

use platen_scenario::{Run, Scenario};
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
    /// The direction of `scenario`'s run.
    pub fn of(scenario: &Scenario) -> Self {
        match &scenario.run {
            Run::Forward { .. } => Direction::Forward,
            Run::Inverse { .. } => Direction::Inverse,
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum Channel {
    /// Platen displacement `u_m`, m.
    #[serde(rename = "u_m")]
    Displacement,
    /// Platen velocity `v_m_s`, m/s.
    #[serde(rename = "v_m_s")]
    Velocity,
    /// Actuator force `force_n`, N.
    #[serde(rename = "force_n")]
    Force,
}

impl Channel {
    /// The CSV column and JSON key: `"u_m"`, `"v_m_s"` or `"force_n"`.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Displacement => "u_m",
            Channel::Velocity => "v_m_s",
            Channel::Force => "force_n",
        }
    }

    /// The plain name: `"displacement"`, `"velocity"` or `"actuator force"`.
    pub fn quantity(self) -> &'static str {
        match self {
            Channel::Displacement => "displacement",
            Channel::Velocity => "velocity",
            Channel::Force => "actuator force",
        }
    }

    /// The symbol: `"u"`, `"v"` or `"F_A"`.
    pub fn symbol(self) -> &'static str {
        match self {
            Channel::Displacement => "u",
            Channel::Velocity => "v",
            Channel::Force => "F_A",
        }
    }

    /// The SI unit of the column: `"m"`, `"m/s"` or `"N"`.
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Displacement => "m",
            Channel::Velocity => "m/s",
            Channel::Force => "N",
        }
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
        for c in [Channel::Displacement, Channel::Velocity, Channel::Force] {
            let json = serde_json::to_value(c).unwrap();
            assert_eq!(json, serde_json::Value::from(c.name()));
        }
    }
}
