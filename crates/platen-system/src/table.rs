//! The hydraulics of a multi-axis table: a servo-valve and chambers per actuator, one supply
//! for all of them.
//!
//! Each actuator `i` has its own state (`p_a`, `p_b`, spool, spool rate) and follows the
//! equations of the uniaxial loop ([`crate`]) with its own stroke `s_i` in place of `u`:
//!
//! * **Double-acting** (`A_b > 0`): a critically centred four-way valve,
//!   `ṗ_a = β/V_a·(Q_a − A_a·ṡ − C_L(p_a − p_b))`, `ṗ_b = β/V_b·(−Q_b + A_b·ṡ + C_L(p_a − p_b))`,
//!   `V_a = V₀ + A_a·s`, `V_b = V₀ − A_b·s`; force `A_a·p_a − A_b·p_b`.
//! * **Single-acting** (`A_b = 0`, the vertical actuators under a platen's pads): one chamber
//!   and a three-way valve, which is the four-way valve with its `b` port blocked (the same
//!   land coefficient, the rating being per land): `Q_a = K·x·√(P_s − p_a)` opening,
//!   `K·x·√(p_a − P_R)` closing; `ṗ_a = β/V_a·(Q_a − A_a·ṡ − C_L(p_a − P_R))` (its leakage goes
//!   to return); force `A_a·p_a`. `p_b` is not used (held at the return pressure).
//!
//! All valves draw from one supply (constant, or an accumulator bank fed by pumps) and return
//! to one return line. The spool of each actuator follows its own drive through its valve's
//! second-order response; the delay of the drive is the controller's business.
//!
//! **Null pressures.** At rest at neutral, actuator `i` exerts the force `f0_i` that holds
//! the platen (its weight and the struts' pull, resolved over the actuators as the force
//! balance does: [`platen_model::multi_axis::MultiAxisTable::resolve_forces`]): a
//! double-acting actuator with equal drops on its two lands (`p_a0 + p_b0 = P_s + P_R`,
//! `A_a·p_a0 − A_b·p_b0 = f0`), a single-acting one with `p_a0 = f0/A_a`.

use platen_model::multi_axis::{Coords, MultiAxisTable};

use crate::error::{invalid, non_negative, positive, Result, SystemError};
use crate::hydraulics::{
    charged_oil_m3, four_way_conductances, four_way_flows, root, root_slope, supply_pressure_at,
    supply_rates, supply_stiffness_1_s, HydraulicConstants,
};
use crate::params::{validate_supply, ServoValve, Supply};
use crate::spool::SpoolResponse;

/// One actuator's hydraulics on a multi-axis table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorHydraulics {
    /// Cap-side piston area (chamber `a`), m².
    pub cap_area_m2: f64,
    /// Rod-side annulus area (chamber `b`), m² (0: single-acting, one chamber).
    pub rod_area_m2: f64,
    /// Oil volume of each chamber at neutral, lines included, m³.
    pub chamber_volume_m3: f64,
    /// Leakage, m³/s per Pa: across the piston (double-acting) or to return (single-acting).
    pub leakage_m3_s_per_pa: f64,
    /// Its servo-valves.
    pub servo_valve: ServoValve,
}

impl ActuatorHydraulics {
    /// Whether it has one chamber (and a three-way valve).
    pub fn is_single_acting(&self) -> bool {
        self.rod_area_m2 == 0.0
    }

    /// Chamber volumes `(V_a, V_b)` at stroke `s_m`, m³ (`V_b` of a single-acting actuator
    /// is its neutral volume; it holds no oil that matters).
    #[inline(always)]
    pub fn chamber_volumes_m3(&self, s_m: f64) -> (f64, f64) {
        (
            self.chamber_volume_m3 + self.cap_area_m2 * s_m,
            self.chamber_volume_m3 - self.rod_area_m2 * s_m,
        )
    }

    /// Its force on the platen, `A_a·p_a − A_b·p_b`, N.
    #[inline(always)]
    pub fn force_n(&self, p_a_pa: f64, p_b_pa: f64) -> f64 {
        self.cap_area_m2 * p_a_pa - self.rod_area_m2 * p_b_pa
    }

    /// Its values, and that its chambers keep oil over `±stroke_m`.
    fn validate(&self, stroke_m: f64) -> Result<()> {
        positive("cap_side_area_m2", self.cap_area_m2)?;
        non_negative("rod_side_area_m2", self.rod_area_m2)?;
        crate::params::plausible_area("cap_side_area_m2", self.cap_area_m2)?;
        crate::params::plausible_area("rod_side_area_m2", self.rod_area_m2)?;
        positive("chamber_volume_m3", self.chamber_volume_m3)?;
        crate::params::plausible_chamber("chamber_volume_m3", self.chamber_volume_m3)?;
        non_negative("leakage_m3_s_per_pa", self.leakage_m3_s_per_pa)?;
        let largest = self.cap_area_m2.max(self.rod_area_m2);
        if stroke_m.is_finite() && self.chamber_volume_m3 - largest * stroke_m <= 0.0 {
            return Err(invalid(
                "chamber_volume_m3",
                self.chamber_volume_m3,
                format!(
                    "more than area × stroke = {} m³, so that a chamber keeps oil at the end \
                     of the stroke",
                    largest * stroke_m
                ),
            ));
        }
        self.servo_valve.validate()
    }
}

/// Everything a [`TableHydraulics`] is made of.
#[derive(Debug, Clone, PartialEq)]
pub struct TableHydraulicsParts {
    /// Per actuator, in the table's order.
    pub actuators: Vec<ActuatorHydraulics>,
    /// Oil bulk modulus `β`, Pa.
    pub oil_bulk_modulus_pa: f64,
    /// Supply pressure `P_s` (the set pressure with an accumulator), Pa, absolute.
    pub supply_pressure_pa: f64,
    /// Return pressure `P_R`, Pa, absolute.
    pub return_pressure_pa: f64,
    /// Where the valves take their oil from.
    pub supply: Supply,
}

/// The hydraulics of a multi-axis table, validated ([`TableHydraulics::new`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TableHydraulics {
    parts: TableHydraulicsParts,
    constants: Vec<HydraulicConstants>,
    /// Each actuator's smallest chamber volumes over its stroke `(V_a, V_b)`, m³.
    smallest_volumes_m3: Vec<(f64, f64)>,
}

/// One actuator's hydraulic state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ActuatorState {
    /// Chamber `a` pressure (absolute), Pa.
    pub p_a_pa: f64,
    /// Chamber `b` pressure (absolute), Pa (the return pressure for a single-acting one).
    pub p_b_pa: f64,
    /// Spool position, fraction of full opening.
    pub spool: f64,
    /// Spool velocity, 1/s.
    pub spool_rate_1_s: f64,
}

/// The rates of an [`ActuatorState`] and the flows behind them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ActuatorRates {
    /// `ṗ_a`, Pa/s.
    pub p_a: f64,
    /// `ṗ_b`, Pa/s.
    pub p_b: f64,
    /// Spool velocity, 1/s.
    pub spool: f64,
    /// Spool acceleration, 1/s².
    pub spool_rate: f64,
    /// Flow into chamber `a`, m³/s.
    pub q_a_m3_s: f64,
    /// Flow drawn from the supply, m³/s (negative: pushed back).
    pub drawn_m3_s: f64,
    /// Hydraulic power into its chambers, W.
    pub power_w: f64,
    /// Power lost to its leakage, W.
    pub leakage_w: f64,
}

/// An actuator's stiffest local pressure rate and what it draws from the supply
/// ([`TableHydraulics::pressure_rate_1_s`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StiffRate {
    /// The stiffest rate of its chambers' pressures, 1/s.
    pub rate_1_s: f64,
    /// The flow its valves draw from the supply, m³/s (negative: pushed back).
    pub drawn_m3_s: f64,
    /// Its valves' conductance to the supply, `∂drawn/∂P_s`, m³/(s·Pa).
    pub supply_conductance_m3_s_pa: f64,
}

impl TableHydraulics {
    /// The hydraulics of `parts` for actuators of strokes `strokes_m` (± from neutral).
    ///
    /// # Errors
    /// [`SystemError::OfActuator`] wrapping the first bad value of an actuator (by its
    /// index), or [`SystemError::Invalid`] for the oil, the pressures or the accumulator.
    pub fn new(parts: TableHydraulicsParts, strokes_m: &[f64]) -> Result<Self> {
        for (index, (a, &stroke)) in parts.actuators.iter().zip(strokes_m).enumerate() {
            a.validate(stroke).map_err(|e| SystemError::OfActuator {
                index,
                source: Box::new(e),
            })?;
        }
        validate_supply(
            parts.oil_bulk_modulus_pa,
            parts.supply_pressure_pa,
            parts.return_pressure_pa,
            &parts.supply,
        )?;
        let constants = parts
            .actuators
            .iter()
            .map(|a| HydraulicConstants::of_valve(&a.servo_valve))
            .collect();
        let smallest_volumes_m3 = parts
            .actuators
            .iter()
            .zip(strokes_m)
            .map(|(a, &stroke)| {
                let (ends, starts) = (a.chamber_volumes_m3(stroke), a.chamber_volumes_m3(-stroke));
                (ends.0.min(starts.0), ends.1.min(starts.1))
            })
            .collect();
        Ok(TableHydraulics {
            parts,
            constants,
            smallest_volumes_m3,
        })
    }

    /// Its values.
    pub fn parts(&self) -> &TableHydraulicsParts {
        &self.parts
    }

    /// The actuators' hydraulics.
    pub fn actuators(&self) -> &[ActuatorHydraulics] {
        &self.parts.actuators
    }

    /// The supply (set) pressure, Pa.
    pub fn supply_pressure_pa(&self) -> f64 {
        self.parts.supply_pressure_pa
    }

    /// The return pressure, Pa.
    pub fn return_pressure_pa(&self) -> f64 {
        self.parts.return_pressure_pa
    }

    /// The oil's bulk modulus, Pa.
    pub fn oil_bulk_modulus_pa(&self) -> f64 {
        self.parts.oil_bulk_modulus_pa
    }

    /// The supply.
    pub fn supply(&self) -> &Supply {
        &self.parts.supply
    }

    /// The supply pressure with `oil_m3` in the accumulator, Pa.
    pub fn supply_pressure_at(&self, oil_m3: f64) -> f64 {
        supply_pressure_at(&self.parts.supply, self.parts.supply_pressure_pa, oil_m3)
    }

    /// The accumulator's oil at the set pressure, m³ (0 without one).
    pub fn charged_oil_m3(&self) -> f64 {
        charged_oil_m3(&self.parts.supply, self.parts.supply_pressure_pa)
    }

    /// The rates `(accumulator oil, supply pressure)` when the valves draw `drawn_m3_s`.
    #[inline(always)]
    pub fn supply_rates(&self, drawn_m3_s: f64, oil_m3: f64, p_s: f64) -> (f64, f64) {
        supply_rates(
            &self.parts.supply,
            self.parts.supply_pressure_pa,
            drawn_m3_s,
            oil_m3,
            p_s,
        )
    }

    /// The null pressures `(p_a0, p_b0)` of actuator `i` exerting `force_n` at rest (see the
    /// module docs).
    ///
    /// # Errors
    /// [`SystemError::OfActuator`] when no pressure between return and supply exerts it.
    pub fn null_pressures_pa(&self, i: usize, force_n: f64) -> Result<(f64, f64)> {
        let a = &self.parts.actuators[i];
        let (ps, pr) = (self.parts.supply_pressure_pa, self.parts.return_pressure_pa);
        let (p_a, p_b) = if a.is_single_acting() {
            (force_n / a.cap_area_m2, pr)
        } else {
            // A_a·p_a − A_b·(S − p_a) = f with S = P_s + P_R.
            let sum = ps + pr;
            let p_a = (force_n + a.rod_area_m2 * sum) / (a.cap_area_m2 + a.rod_area_m2);
            (p_a, sum - p_a)
        };
        let inside = |p: f64| p.is_finite() && p > pr && p < ps;
        if inside(p_a) && (a.is_single_acting() || inside(p_b)) {
            Ok((p_a, p_b))
        } else {
            let expected = if a.is_single_acting() && p_a.is_finite() && p_a <= pr {
                // A single-acting actuator pushes at least the return pressure on its area:
                // it cannot hold a smaller force (a vertical with none of the platen's weight
                // on it, as when z is held) at rest.
                format!(
                    "a single-acting actuator with a static force to hold: it must hold \
                     {force_n:.6e} N at rest, less than the return pressure on its area pushes \
                     ({:.6e} N), and it cannot pull (with z held, no weight rests on the \
                     verticals: hold z on double-acting verticals, or leave z free)",
                    pr * a.cap_area_m2
                )
            } else {
                format!(
                    "an area that holds its static force {force_n:.6e} N at rest with chamber \
                     pressures between the return and supply pressures (it needs {p_a:.6e} Pa \
                     in chamber a)"
                )
            };
            Err(SystemError::OfActuator {
                index: i,
                source: Box::new(invalid("cap_side_area_m2", a.cap_area_m2, expected)),
            })
        }
    }

    /// The rest state of every actuator when they exert the static forces `forces_n`.
    ///
    /// # Errors
    /// As [`TableHydraulics::null_pressures_pa`].
    pub fn rest_states(&self, forces_n: &[f64]) -> Result<Vec<ActuatorState>> {
        forces_n
            .iter()
            .enumerate()
            .map(|(i, &f)| {
                let (p_a_pa, p_b_pa) = self.null_pressures_pa(i, f)?;
                Ok(ActuatorState {
                    p_a_pa,
                    p_b_pa,
                    spool: 0.0,
                    spool_rate_1_s: 0.0,
                })
            })
            .collect()
    }

    /// The pressure difference actuator `i`'s `Δp` feedback reads: `p_a − p_b`, or
    /// `p_a − P_R` for a single-acting actuator, Pa.
    #[inline(always)]
    pub fn delta_p_pa(&self, i: usize, s: &ActuatorState) -> f64 {
        let (p_a, p_b) = (s.p_a_pa.max(0.0), s.p_b_pa.max(0.0));
        if self.parts.actuators[i].is_single_acting() {
            p_a - self.parts.return_pressure_pa
        } else {
            p_a - p_b
        }
    }

    /// Actuator `i`'s force at its state, N (pressures read at the cavitation floor).
    #[inline(always)]
    pub fn force_n(&self, i: usize, s: &ActuatorState) -> f64 {
        self.parts.actuators[i].force_n(s.p_a_pa.max(0.0), s.p_b_pa.max(0.0))
    }

    /// Flows `(q_a, q_b)` of actuator `i`'s valves at opening `x` (clamped to ±1): into
    /// chamber `a` and out of chamber `b` (0 for a single-acting one), m³/s.
    #[inline(always)]
    pub fn valve_flows_m3_s(&self, i: usize, x: f64, p_a: f64, p_b: f64, p_s: f64) -> (f64, f64) {
        let c = &self.constants[i];
        let p_r = self.parts.return_pressure_pa;
        if self.parts.actuators[i].is_single_acting() {
            let x = x.clamp(-1.0, 1.0);
            let k = c.land_coefficient;
            let q_a = if x > 0.0 {
                k * x * root(p_s - p_a, c)
            } else if x < 0.0 {
                k * x * root(p_a - p_r, c)
            } else {
                0.0
            };
            (q_a, 0.0)
        } else {
            four_way_flows(c, x, p_a, p_b, p_s, p_r)
        }
    }

    /// The rates of actuator `i` at stroke `s_m` and stroke rate `v_m_s`, its valve's input
    /// `drive` (`|drive| ≤ 1`), supply pressure `p_s`. A chamber at the cavitation floor
    /// (0 Pa absolute) does not fall further.
    #[inline(always)]
    pub fn actuator_rates(
        &self,
        i: usize,
        s_m: f64,
        v_m_s: f64,
        drive: f64,
        s: &ActuatorState,
        p_s: f64,
    ) -> ActuatorRates {
        let a = &self.parts.actuators[i];
        let c = &self.constants[i];
        let beta = self.parts.oil_bulk_modulus_pa;
        let (p_a, p_b) = (s.p_a_pa.max(0.0), s.p_b_pa.max(0.0));
        let (q_a, q_b) = self.valve_flows_m3_s(i, s.spool, p_a, p_b, p_s);
        let (v_a, v_b) = a.chamber_volumes_m3(s_m);
        let single = a.is_single_acting();
        let across = if single {
            p_a - self.parts.return_pressure_pa
        } else {
            p_a - p_b
        };
        let leak = a.leakage_m3_s_per_pa * across;
        let mut dp_a = beta / v_a * (q_a - a.cap_area_m2 * v_m_s - leak);
        let mut dp_b = if single {
            0.0
        } else {
            beta / v_b * (-q_b + a.rod_area_m2 * v_m_s + leak)
        };
        if s.p_a_pa <= 0.0 && dp_a < 0.0 {
            dp_a = 0.0;
        }
        if s.p_b_pa <= 0.0 && dp_b < 0.0 {
            dp_b = 0.0;
        }
        let wv = c.spool_rad_s;
        let zeta = a.servo_valve.damping_ratio;
        let drawn = if s.spool >= 0.0 { q_a } else { -q_b };
        ActuatorRates {
            p_a: dp_a,
            p_b: dp_b,
            spool: s.spool_rate_1_s,
            spool_rate: wv * wv * (drive - s.spool) - 2.0 * zeta * wv * s.spool_rate_1_s,
            q_a_m3_s: q_a,
            drawn_m3_s: drawn,
            power_w: p_a * q_a - p_b * q_b,
            leakage_w: a.leakage_m3_s_per_pa * across * across,
        }
    }

    /// The stiffest local rate of actuator `i`'s chamber pressures at stroke `s_m` (`None`:
    /// its smallest chambers over the stroke, a bound over every stroke), state `s` and
    /// supply pressure `p_s`, 1/s: `β/V·(g + C_leak)` for either chamber, `g` the land's
    /// `|∂q/∂p|` at its drop and the spool's opening (see
    /// [`crate::TableSystem::pressure_rate_1_s`]). With the flow its valves draw from the
    /// supply, m³/s, and their conductance to it, m³/(s·Pa), for
    /// [`TableHydraulics::supply_rate_1_s`].
    pub fn pressure_rate_1_s(
        &self,
        i: usize,
        s_m: Option<f64>,
        s: &ActuatorState,
        p_s: f64,
    ) -> StiffRate {
        let a = &self.parts.actuators[i];
        let c = &self.constants[i];
        let p_r = self.parts.return_pressure_pa;
        let (p_a, p_b) = (s.p_a_pa.max(0.0), s.p_b_pa.max(0.0));
        let beta = self.parts.oil_bulk_modulus_pa;
        let leak = a.leakage_m3_s_per_pa;
        let (v_a, v_b) = s_m.map_or(self.smallest_volumes_m3[i], |s_m| a.chamber_volumes_m3(s_m));
        let (q_a, q_b) = self.valve_flows_m3_s(i, s.spool, p_a, p_b, p_s);
        if a.is_single_acting() {
            let x = s.spool.clamp(-1.0, 1.0);
            let drop = if x >= 0.0 { p_s - p_a } else { p_a - p_r };
            let g = c.land_coefficient * x.abs() * root_slope(drop, c);
            StiffRate {
                rate_1_s: beta / v_a * (g + leak),
                drawn_m3_s: q_a,
                supply_conductance_m3_s_pa: if x > 0.0 { g } else { 0.0 },
            }
        } else {
            let (g_a, g_b) = four_way_conductances(c, s.spool, p_a, p_b, p_s, p_r);
            let (drawn, g) = if s.spool >= 0.0 {
                (q_a, g_a)
            } else {
                (-q_b, g_b)
            };
            StiffRate {
                rate_1_s: (beta / v_a * (g_a + leak)).max(beta / v_b * (g_b + leak)),
                drawn_m3_s: drawn,
                supply_conductance_m3_s_pa: g,
            }
        }
    }

    /// The accumulator's local rate, 1/s (`|∂Ṗ/∂P|`), with the valves drawing `drawn_m3_s`
    /// from it through a conductance `g_supply_m3_s_pa` (the sums of
    /// [`TableHydraulics::pressure_rate_1_s`]'s), `oil_m3` in the bank at pressure `p_s`; 0
    /// for a constant supply.
    pub fn supply_rate_1_s(
        &self,
        drawn_m3_s: f64,
        g_supply_m3_s_pa: f64,
        oil_m3: f64,
        p_s: f64,
    ) -> f64 {
        supply_stiffness_1_s(
            &self.parts.supply,
            self.parts.supply_pressure_pa,
            drawn_m3_s,
            g_supply_m3_s_pa,
            oil_m3,
            p_s,
        )
    }

    /// The exact response of actuator `i`'s spool to a held drive (see [`SpoolResponse`]).
    pub fn spool_response(&self, i: usize) -> SpoolResponse {
        let v = &self.parts.actuators[i].servo_valve;
        SpoolResponse::new(v.natural_frequency_hz, v.damping_ratio)
    }

    /// The oil-column stiffness of actuator `i` at stroke `s_m` with its valve shut,
    /// `β·(A_a²/V_a + A_b²/V_b)`, N/m.
    pub fn oil_column_stiffness_n_per_m(&self, i: usize, s_m: f64) -> f64 {
        let a = &self.parts.actuators[i];
        let (v_a, v_b) = a.chamber_volumes_m3(s_m);
        let rod = if a.is_single_acting() {
            0.0
        } else {
            a.rod_area_m2.powi(2) / v_b
        };
        self.parts.oil_bulk_modulus_pa * (a.cap_area_m2.powi(2) / v_a + rod)
    }

    /// The largest rate of any actuator's loop, rad/s: its spool's natural frequency, or its
    /// oil column's `√(k_oil/m)` against the mass `mass_kg` at the ends of `strokes_m`.
    pub fn fastest_rate_rad_s(&self, mass_kg: f64, strokes_m: &[f64]) -> f64 {
        (0..self.parts.actuators.len())
            .map(|i| {
                let wv = self.constants[i].spool_rad_s;
                let s = strokes_m.get(i).copied().unwrap_or(0.0);
                let oil = [-s, 0.0, s]
                    .iter()
                    .map(|&u| (self.oil_column_stiffness_n_per_m(i, u) / mass_kg).sqrt())
                    .fold(0.0, f64::max);
                wv.max(oil)
            })
            .fold(0.0, f64::max)
    }

    /// Actuator `i`'s no-load velocities `(extend, retract)` at full opening, m/s: a
    /// double-acting one with `A_a·v = K√(P_s − p_a)`, `A_b·v = K√(p_b − P_R)`,
    /// `A_a·p_a = A_b·p_b` (and mirrored); a single-acting one at its static pressure `p0`,
    /// `K√(P_s − p0)/A_a` and `K√(p0 − P_R)/A_a`.
    pub fn velocities_m_s(&self, i: usize, static_pressure_pa: f64) -> (f64, f64) {
        let a = &self.parts.actuators[i];
        let k = self.constants[i].land_coefficient;
        let (ps, pr) = (self.parts.supply_pressure_pa, self.parts.return_pressure_pa);
        if a.is_single_acting() {
            let p0 = static_pressure_pa.clamp(pr, ps);
            (
                k * (ps - p0).sqrt() / a.cap_area_m2,
                k * (p0 - pr).sqrt() / a.cap_area_m2,
            )
        } else {
            let (aa, ab) = (a.cap_area_m2, a.rod_area_m2);
            let cube = aa.powi(3) + ab.powi(3);
            (
                k * ((aa * ps - ab * pr).max(0.0) / cube).sqrt(),
                k * ((ab * ps - aa * pr).max(0.0) / cube).sqrt(),
            )
        }
    }

    /// The forces that hold `table` at rest at neutral, N per actuator: its weight and its
    /// struts' pull (and `extra_wrench`, e.g. a specimen's weight, about the reference point)
    /// resolved over the actuators as the force balance does.
    ///
    /// # Errors
    /// [`SystemError::Invalid`] (`actuators`) when the free DOFs lose rank at neutral.
    pub fn static_forces_n(
        table: &MultiAxisTable,
        extra_wrench: &platen_model::multi_axis::Wrench,
    ) -> Result<Vec<f64>> {
        let neutral = Coords::zeros();
        let hold = -(table.gravity_wrench(&neutral) + table.struts_wrench(&neutral) + extra_wrench);
        table
            .resolve_forces(&neutral, &table.generalised_force(&neutral, &hold), None)
            .ok_or_else(|| {
                invalid(
                    "actuators",
                    table.actuators().len() as f64,
                    "actuators whose lines move every free DOF at neutral",
                )
            })
    }
}
