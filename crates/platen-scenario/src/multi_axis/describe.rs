//! The description of a multi-axis scenario (`platen model --scenario --json`).

use super::*;
use crate::summary::LoopMargins;

/// One mode of `platen model --json` on a multi-axis scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeDescription {
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// The platen's part of the shape: x, y, z (m), roll, pitch, yaw (rad), mass-normalised.
    pub shape: [f64; 6],
}

/// What `platen model --json` prints on a multi-axis scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableDescription {
    /// The scenario's name.
    pub name: String,
    /// The platen's modes at neutral on its oil columns and struts, valves shut, specimen
    /// included, lowest first.
    pub modes: Vec<ModeDescription>,
    /// Per free DOF, the capacities the geometry and hydraulics give (bare table):
    /// translations `{stroke_m, acceleration_m_s2, force_n}`, rotations `{angle_rad,
    /// acceleration_rad_s2, moment_n_m}`. Velocities come with the servo-valves of the
    /// multi-axis closed loop.
    pub axes:
        std::collections::BTreeMap<&'static str, std::collections::BTreeMap<&'static str, f64>>,
    /// The platen's mass, kg.
    pub mass_kg: f64,
    /// The held DOFs.
    pub held_dofs: Vec<&'static str>,
    /// The closed loop's small-signal figures (a table with a `controller`; `null`
    /// otherwise).
    #[serde(rename = "loop")]
    pub loop_figures: Option<TableLoopDescription>,
}

/// One DOF's loop, broken at its drive with the others closed: its [`LoopMargins`] (the
/// former name).
pub type DofLoopDescription = LoopMargins;

/// The largest cross-talk of one DOF's command at a frequency.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrossTalkDescription {
    /// The frequency, Hz.
    pub frequency_hz: f64,
    /// |pose/command| of the commanded DOF itself.
    pub diagonal: f64,
    /// The DOF that responds the most to it (`null` with one free DOF).
    pub largest_dof: Option<&'static str>,
    /// |that response/command| (m/m, rad/rad, m/rad or rad/m).
    pub largest: Option<f64>,
}

/// The closed loop's stability from the eigenvalues of its linearisation
/// (`platen_system::TableLinearisation::stability`: delays by Padé approximants).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoopStabilityDescription {
    /// No closed-loop eigenvalue in the right half-plane.
    pub stable: bool,
    /// The largest real part of the closed-loop eigenvalues off the imaginary axis (beyond
    /// 1e-3 1/s either way: the chambers' mean pressures and unclosed integrators sit on
    /// it), 1/s: negative, the slowest decay of a stable loop; positive, the fastest growth
    /// of an unstable one.
    pub largest_real_part_1_s: f64,
    /// The unstable eigenvalues (upper half-plane of each pair), fastest-growing first:
    /// `[growth rate 1/s, frequency Hz]`.
    pub unstable_poles: Vec<[f64; 2]>,
    /// The DOF that moves the most in the fastest-growing mode (`null` when stable).
    pub unstable_dof: Option<&'static str>,
}

/// `platen model` on a table with a controller: the linearised loop about neutral at rest
/// (mean flow gains, see `platen_system::TableLinearisation`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableLoopDescription {
    /// The whole loop's stability, from its eigenvalues: the verdict (each DOF's margins
    /// below are measured with the other loops closed).
    pub stability: LoopStabilityDescription,
    /// Per free DOF, its loop's margins.
    pub dofs: std::collections::BTreeMap<&'static str, LoopMargins>,
    /// Per free DOF's command, its largest cross-talk at 1, 2, 5 and 10 Hz.
    pub cross_talk: std::collections::BTreeMap<&'static str, Vec<CrossTalkDescription>>,
    /// Per actuator its force at rest (the static hold), N.
    pub static_forces_n: std::collections::BTreeMap<String, f64>,
}

/// The frequencies at which `platen model` reports the cross-talk, Hz.
pub const CROSS_TALK_HZ: [f64; 4] = [1.0, 2.0, 5.0, 10.0];

impl TableScenario {
    /// Its description: modes and capacities.
    pub fn describe(&self) -> TableDescription {
        let modes = match &self.specimen {
            Some(s) => self.table.modes_with(s),
            None => self.table.modes(),
        };
        let rates = self.rate_capacities();
        let axes = self
            .table
            .capacities(self.supply_pressure_pa, self.return_pressure_pa)
            .into_iter()
            .map(|c| {
                let keys = if c.dof.is_rotation() {
                    ["angle_rad", "acceleration_rad_s2", "moment_n_m"]
                } else {
                    ["stroke_m", "acceleration_m_s2", "force_n"]
                };
                let mut values: std::collections::BTreeMap<&'static str, f64> = keys
                    .into_iter()
                    .zip([c.stroke, c.acceleration, c.force])
                    .collect();
                if let Some(r) = rates.as_ref().and_then(|r| r.get(&c.dof.index())) {
                    let key = if c.dof.is_rotation() {
                        "rate_rad_s"
                    } else {
                        "velocity_m_s"
                    };
                    values.insert(key, *r);
                }
                (c.dof.name(), values)
            })
            .collect();
        TableDescription {
            name: self.name.clone(),
            modes: modes
                .into_iter()
                .map(|m| ModeDescription {
                    frequency_hz: m.frequency_hz,
                    shape: m.shape.into(),
                })
                .collect(),
            axes,
            mass_kg: self.table.platen().mass_kg(),
            held_dofs: self.table.held().iter().map(Dof::name).collect(),
            loop_figures: self.loop_description(),
        }
    }

    /// The forces that hold the platen (and the specimen's weight) at rest at neutral, N per
    /// actuator (`None` when the actuators cannot).
    pub(super) fn static_forces_n(&self) -> Option<Vec<f64>> {
        let extra = self.specimen.as_ref().map_or_else(
            platen_model::multi_axis::Wrench::zeros,
            LinearSpecimen::weight_wrench,
        );
        TableHydraulics::static_forces_n(&self.table, &extra).ok()
    }

    /// Per free DOF (by index) the largest rate the valves give at full opening with no load,
    /// either way: each actuator's stroke rate `G_ik·v` within its extend or retract velocity
    /// (a single-acting one's at its static pressure). `None` without a closed loop.
    pub(super) fn rate_capacities(&self) -> Option<std::collections::BTreeMap<usize, f64>> {
        let sys = self.system.as_ref()?;
        let hyd = &sys.hydraulics;
        let geo = sys.controller.geometry();
        let forces = self.static_forces_n()?;
        let rest = hyd.rest_states(&forces).ok()?;
        let limits: Vec<(f64, f64)> = rest
            .iter()
            .enumerate()
            .map(|(i, s)| hyd.velocities_m_s(i, s.p_a_pa))
            .collect();
        Some(
            geo.free()
                .iter()
                .enumerate()
                .map(|(k, d)| {
                    let reach = |sign: f64| {
                        limits
                            .iter()
                            .enumerate()
                            .map(|(i, &(extend, retract))| {
                                let per = sign * geo.matrix()[(i, k)];
                                if per > 0.0 {
                                    extend / per
                                } else if per < 0.0 {
                                    retract / -per
                                } else {
                                    f64::INFINITY
                                }
                            })
                            .fold(f64::INFINITY, f64::min)
                    };
                    (d.index(), reach(1.0).min(reach(-1.0)))
                })
                .collect(),
        )
    }

    /// The closed loop's linearisation (`None` without one, or when it cannot be linearised).
    pub(super) fn linearisation(&self) -> Option<platen_system::TableLinearisation> {
        let sys = self.system.as_ref()?;
        platen_system::TableLinearisation::new(
            &self.table,
            &sys.hydraulics,
            &sys.controller,
            self.specimen.as_ref(),
        )
        .ok()
    }

    /// The closed loop's linearisation: margins per DOF and cross-talk (`None` without one,
    /// or when it cannot be linearised).
    pub(super) fn loop_description(&self) -> Option<TableLoopDescription> {
        let lin = self.linearisation()?;
        let (stability, dofs) = loop_verdict(&lin);
        let mut cross_talk: std::collections::BTreeMap<&'static str, Vec<CrossTalkDescription>> =
            std::collections::BTreeMap::new();
        for f in CROSS_TALK_HZ {
            for c in lin.cross_talk(f) {
                cross_talk
                    .entry(c.command.name())
                    .or_default()
                    .push(CrossTalkDescription {
                        frequency_hz: f,
                        diagonal: c.diagonal.norm(),
                        largest_dof: c.largest.map(|(d, _)| d.name()),
                        largest: c.largest.map(|(_, x)| x.norm()),
                    });
            }
        }
        let static_forces_n = self
            .table
            .actuators()
            .iter()
            .zip(lin.actuators())
            .map(|(a, l)| (a.name.clone(), l.static_force_n))
            .collect();
        Some(TableLoopDescription {
            stability,
            dofs,
            cross_talk,
            static_forces_n,
        })
    }
}

/// The linearised loop's stability (its eigenvalues) alone.
pub(super) fn loop_verdict_stability(
    lin: &platen_system::TableLinearisation,
) -> LoopStabilityDescription {
    let st = lin.stability();
    LoopStabilityDescription {
        stable: st.stable,
        largest_real_part_1_s: st.largest_real_part_1_s,
        unstable_poles: st
            .unstable_poles
            .iter()
            .map(|p| [p.re, p.im / std::f64::consts::TAU])
            .collect(),
        unstable_dof: st.unstable_dof.map(Dof::name),
    }
}

/// The linearised loop's stability (its eigenvalues) and each free DOF's margins.
pub(super) fn loop_verdict(
    lin: &platen_system::TableLinearisation,
) -> (
    LoopStabilityDescription,
    std::collections::BTreeMap<&'static str, LoopMargins>,
) {
    let stability = loop_verdict_stability(lin);
    let dofs = lin
        .free()
        .iter()
        .filter_map(|&d| {
            let m = lin.margins(d)?;
            Some((d.name(), LoopMargins::from(&m)))
        })
        .collect();
    (stability, dofs)
}

impl LoopStabilityDescription {
    /// The unstable verdict in words (`None` when stable): its fastest-growing pole and the
    /// DOF that moves most in it.
    pub fn unstable_words(&self) -> Option<String> {
        if self.stable {
            return None;
        }
        let pole = self.unstable_poles.first().map_or(
            "its eigenvalues could not be computed (values far out of range)".to_owned(),
            |[re, f]| format!("a pole grows at {re:.3} 1/s at {f:.2} Hz"),
        );
        let dof = self
            .unstable_dof
            .map_or(String::new(), |d| format!(", mostly in {d}"));
        Some(format!("{pole}{dof}"))
    }
}
