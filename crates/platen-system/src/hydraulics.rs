//! The continuous part of the loop: spool, valve flows, chambers, supply.

use crate::params::{ServoValve, Supply, TableSystem};

/// Below this fraction of the rated drop the orifice law turns laminar (linear in the drop)
/// so that its slope stays finite at zero drop: `q = K·x·Δp/√p_t` for `|Δp| < p_t`, the
/// turbulent `K·x·sgn(Δp)·√|Δp|` above (continuous at `p_t`). 1e-4 of the rated drop is a few
/// hundred Pa: far below any working drop, so the rating is untouched.
pub const LAMINAR_FRACTION: f64 = 1e-4;

/// The hydraulic state of the loop (all actuators alike).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HydraulicState {
    /// Cap-side chamber pressure (absolute), Pa.
    pub p_a_pa: f64,
    /// Rod-side chamber pressure (absolute), Pa.
    pub p_b_pa: f64,
    /// Spool position, fraction of full opening (the flow sees it clamped to ±1).
    pub spool: f64,
    /// Spool velocity, 1/s.
    pub spool_rate_1_s: f64,
    /// Oil held in the accumulator bank, m³ (0 with a constant supply).
    pub accumulator_oil_m3: f64,
    /// The supply pressure, Pa: the bank's gas pressure, integrated alongside its oil
    /// (`Ṗ = n·P·Q/V_g`, so that no power law is evaluated per step; `P·V_g^n` stays
    /// constant to the integration's accuracy), or the constant supply pressure.
    pub supply_pressure_pa: f64,
}

/// The rates of a [`HydraulicState`] and what they come from.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HydraulicRates {
    /// `ṗ_a`, Pa/s.
    pub p_a: f64,
    /// `ṗ_b`, Pa/s.
    pub p_b: f64,
    /// Spool velocity, 1/s.
    pub spool: f64,
    /// Spool acceleration, 1/s².
    pub spool_rate: f64,
    /// Rate of the accumulator's oil, m³/s.
    pub accumulator_oil: f64,
    /// Rate of the supply pressure, Pa/s.
    pub supply_pressure: f64,
    /// Flow into chamber `a` of one actuator, m³/s.
    pub q_a_m3_s: f64,
    /// Flow out of chamber `b` of one actuator, m³/s.
    pub q_b_m3_s: f64,
    /// Flow drawn from the supply by all actuators, m³/s (negative: pushed back).
    pub supply_flow_m3_s: f64,
    /// Hydraulic power delivered into the chambers of all actuators, `n·(p_a·q_a − p_b·q_b)`, W.
    pub hydraulic_power_w: f64,
}

/// What the right-hand side needs of the parameters, computed once per run
/// ([`TableSystem::constants`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HydraulicConstants {
    /// The land coefficient of one actuator's valves, [`TableSystem::land_coefficient`].
    pub land_coefficient: f64,
    /// The drop below which the orifice is laminar, Pa ([`LAMINAR_FRACTION`] of the rated
    /// drop).
    pub laminar_drop_pa: f64,
    /// `1/√p_t`, the laminar slope's factor.
    pub laminar_slope: f64,
    /// The spool's natural frequency, rad/s.
    pub spool_rad_s: f64,
}

impl HydraulicConstants {
    /// The constants of the servo-valves `valve`.
    pub fn of_valve(valve: &ServoValve) -> Self {
        let p_t = LAMINAR_FRACTION * valve.rated_pressure_drop_pa;
        HydraulicConstants {
            land_coefficient: valve.land_coefficient(),
            laminar_drop_pa: p_t,
            laminar_slope: 1.0 / p_t.sqrt(),
            spool_rad_s: std::f64::consts::TAU * valve.natural_frequency_hz,
        }
    }
}

/// `sgn(Δp)·√|Δp|` with the laminar transition of [`LAMINAR_FRACTION`] below `p_t`.
#[inline(always)]
pub(crate) fn root(dp: f64, c: &HydraulicConstants) -> f64 {
    if dp.abs() >= c.laminar_drop_pa {
        dp.signum() * dp.abs().sqrt()
    } else {
        dp * c.laminar_slope
    }
}

/// The slope of [`root`], `d root/dΔp`, 1/√Pa: `1/(2√|Δp|)` above the laminar drop, the
/// laminar slope `1/√p_t` below it (the steepest the law gets).
#[inline(always)]
pub(crate) fn root_slope(dp: f64, c: &HydraulicConstants) -> f64 {
    let a = dp.abs();
    if a >= c.laminar_drop_pa {
        0.5 / a.sqrt()
    } else {
        c.laminar_slope
    }
}

/// The orifice conductances `(g_a, g_b)` of a four-way valve at opening `x` (clamped to ±1),
/// m³/(s·Pa): `|∂q_a/∂p_a|` and `|∂q_b/∂p_b|`, the lands' flows' slopes against their own
/// chamber's pressure. The land open to the supply is the first for `x ≥ 0`, the second
/// below.
#[inline(always)]
pub(crate) fn four_way_conductances(
    c: &HydraulicConstants,
    x: f64,
    p_a: f64,
    p_b: f64,
    p_s: f64,
    p_r: f64,
) -> (f64, f64) {
    let x = x.clamp(-1.0, 1.0);
    let k = c.land_coefficient * x.abs();
    if x >= 0.0 {
        (k * root_slope(p_s - p_a, c), k * root_slope(p_b - p_r, c))
    } else {
        (k * root_slope(p_a - p_r, c), k * root_slope(p_s - p_b, c))
    }
}

/// The rate at which an accumulator bank's pressure answers its own change, 1/s: the
/// magnitude of `∂Ṗ/∂P` for `Ṗ = n·P·q/V_g`, with `q` the pump's tapered flow less
/// `drawn_m3_s` (all actuators) and `g_supply_m3_s_pa` the lands' conductance to the supply
/// (`∂drawn/∂P`). 0 for a constant supply.
pub(crate) fn supply_stiffness_1_s(
    supply: &Supply,
    set_pa: f64,
    drawn_m3_s: f64,
    g_supply_m3_s_pa: f64,
    oil_m3: f64,
    p_s: f64,
) -> f64 {
    match supply {
        Supply::Constant => 0.0,
        Supply::Accumulator(acc) => {
            let band = 0.01 * set_pa;
            let taper = ((set_pa - p_s) / band).clamp(0.0, 1.0);
            let taper_slope = if taper > 0.0 && taper < 1.0 {
                acc.pump_flow_m3_s / band
            } else {
                0.0
            };
            let q = acc.pump_flow_m3_s * taper - drawn_m3_s;
            let gas = (acc.volume_m3 - oil_m3).max(1e-9 * acc.volume_m3);
            (acc.polytropic_exponent / gas * (q - p_s * (g_supply_m3_s_pa + taper_slope))).abs()
        }
    }
}

impl TableSystem {
    /// The stiffest local rate of the loop's pressures at platen displacement `u_m` and
    /// state `s`, 1/s: the largest of `β/V·(g + C_leak)` for either chamber, with `g` the
    /// conductance of the valve's land to it (`|∂q/∂p|`, the orifice law's slope at the
    /// land's drop and the spool's opening), and the accumulator's `n·P/V_g` over the lands
    /// open to it. Near a land's laminar drop at full opening (a chamber pressed to the
    /// supply or the return by a saturated, unstable loop) this is far faster than the oil
    /// column: the integrator shortens its steps to it ([`TableSystem::default_steps_per_period`]
    /// covers the working point only).
    pub fn pressure_rate_1_s(&self, c: &HydraulicConstants, u_m: f64, s: &HydraulicState) -> f64 {
        let act = &self.actuator;
        let (p_a, p_b) = (s.p_a_pa.max(0.0), s.p_b_pa.max(0.0));
        let p_s = s.supply_pressure_pa;
        let (g_a, g_b) = four_way_conductances(c, s.spool, p_a, p_b, p_s, self.return_pressure_pa);
        let (v_a, v_b) = self.chamber_volumes_m3(u_m);
        let beta = self.oil_bulk_modulus_pa;
        let leak = act.leakage_m3_s_per_pa;
        let n = f64::from(act.count);
        let supply = match self.supply {
            Supply::Constant => 0.0,
            Supply::Accumulator(_) => {
                let (q_a, q_b) = self.valve_flows_with(c, s.spool, p_a, p_b, p_s);
                let (drawn, g) = if s.spool >= 0.0 {
                    (q_a, g_a)
                } else {
                    (-q_b, g_b)
                };
                supply_stiffness_1_s(
                    &self.supply,
                    self.supply_pressure_pa,
                    n * drawn,
                    n * g,
                    s.accumulator_oil_m3,
                    p_s,
                )
            }
        };
        (beta / v_a * (g_a + leak))
            .max(beta / v_b * (g_b + leak))
            .max(supply)
    }
}

impl TableSystem {
    /// The supply pressure, Pa, with `oil_m3` in the accumulator (the constant pressure
    /// without one).
    #[inline(always)]
    pub fn supply_pressure_at(&self, oil_m3: f64) -> f64 {
        supply_pressure_at(&self.supply, self.supply_pressure_pa, oil_m3)
    }

    /// The accumulator's oil at the supply (set) pressure, m³ (0 without one).
    pub fn charged_oil_m3(&self) -> f64 {
        charged_oil_m3(&self.supply, self.supply_pressure_pa)
    }

    /// The state at rest at `u = 0`: a centred spool, the null pressures, a charged bank.
    pub fn rest_state(&self) -> HydraulicState {
        let (p_a, p_b) = self.null_pressures_pa();
        HydraulicState {
            p_a_pa: p_a,
            p_b_pa: p_b,
            spool: 0.0,
            spool_rate_1_s: 0.0,
            accumulator_oil_m3: self.charged_oil_m3(),
            supply_pressure_pa: self.supply_pressure_pa,
        }
    }

    /// Flows `(q_a, q_b)` of one actuator's valves at spool opening `x` (clamped to ±1):
    /// into chamber `a` and out of chamber `b`, m³/s, with supply pressure `p_s`.
    #[inline(always)]
    pub fn valve_flows_m3_s(&self, x: f64, p_a: f64, p_b: f64, p_s: f64) -> (f64, f64) {
        self.valve_flows_with(&self.constants(), x, p_a, p_b, p_s)
    }

    /// The constants of the right-hand side.
    pub fn constants(&self) -> HydraulicConstants {
        HydraulicConstants::of_valve(&self.servo_valve)
    }

    /// [`TableSystem::valve_flows_m3_s`] with its constants computed once.
    #[inline(always)]
    pub fn valve_flows_with(
        &self,
        c: &HydraulicConstants,
        x: f64,
        p_a: f64,
        p_b: f64,
        p_s: f64,
    ) -> (f64, f64) {
        four_way_flows(c, x, p_a, p_b, p_s, self.return_pressure_pa)
    }

    /// The rates of the hydraulic state at platen displacement `u_m` and velocity `v_m_s`,
    /// with valve input `drive` (the delayed, held controller output, `|drive| ≤ 1`).
    ///
    /// Pressures never fall below zero (absolute): a chamber at the floor does not fall
    /// further (the cavitation floor); its pressure is read as `max(p, 0)`.
    pub fn hydraulic_rates(
        &self,
        u_m: f64,
        v_m_s: f64,
        drive: f64,
        s: &HydraulicState,
    ) -> HydraulicRates {
        self.hydraulic_rates_with(&self.constants(), u_m, v_m_s, drive, s)
    }

    /// [`TableSystem::hydraulic_rates`] with its constants computed once (what an
    /// integrator calls per stage).
    #[inline(always)]
    pub fn hydraulic_rates_with(
        &self,
        c: &HydraulicConstants,
        u_m: f64,
        v_m_s: f64,
        drive: f64,
        s: &HydraulicState,
    ) -> HydraulicRates {
        let act = &self.actuator;
        let (p_a, p_b) = (s.p_a_pa.max(0.0), s.p_b_pa.max(0.0));
        let p_s = s.supply_pressure_pa;
        let (q_a, q_b) = self.valve_flows_with(c, s.spool, p_a, p_b, p_s);
        let (v_a, v_b) = self.chamber_volumes_m3(u_m);
        let beta = self.oil_bulk_modulus_pa;
        let leak = act.leakage_m3_s_per_pa * (p_a - p_b);
        let mut dp_a = beta / v_a * (q_a - act.cap_area_m2 * v_m_s - leak);
        let mut dp_b = beta / v_b * (-q_b + act.rod_area_m2 * v_m_s + leak);
        if s.p_a_pa <= 0.0 && dp_a < 0.0 {
            dp_a = 0.0;
        }
        if s.p_b_pa <= 0.0 && dp_b < 0.0 {
            dp_b = 0.0;
        }
        let wv = c.spool_rad_s;
        let zeta = self.servo_valve.damping_ratio;
        let n = f64::from(act.count);
        let drawn = n * if s.spool >= 0.0 { q_a } else { -q_b };
        let (oil, d_ps) = supply_rates(
            &self.supply,
            self.supply_pressure_pa,
            drawn,
            s.accumulator_oil_m3,
            p_s,
        );
        HydraulicRates {
            p_a: dp_a,
            p_b: dp_b,
            spool: s.spool_rate_1_s,
            spool_rate: wv * wv * (drive - s.spool) - 2.0 * zeta * wv * s.spool_rate_1_s,
            accumulator_oil: oil,
            supply_pressure: d_ps,
            q_a_m3_s: q_a,
            q_b_m3_s: q_b,
            supply_flow_m3_s: drawn,
            hydraulic_power_w: n * (p_a * q_a - p_b * q_b),
        }
    }
}

/// Flows `(q_a, q_b)` of a critically centred four-way valve at spool opening `x` (clamped to
/// ±1): into chamber `a` and out of chamber `b`, m³/s, between supply `p_s` and return `p_r`.
#[inline(always)]
pub(crate) fn four_way_flows(
    c: &HydraulicConstants,
    x: f64,
    p_a: f64,
    p_b: f64,
    p_s: f64,
    p_r: f64,
) -> (f64, f64) {
    let x = x.clamp(-1.0, 1.0);
    if x == 0.0 {
        return (0.0, 0.0);
    }
    let k = c.land_coefficient;
    if x >= 0.0 {
        (k * x * root(p_s - p_a, c), k * x * root(p_b - p_r, c))
    } else {
        (k * x * root(p_a - p_r, c), k * x * root(p_s - p_b, c))
    }
}

/// The supply pressure with `oil_m3` in the accumulator of `supply` (the set pressure
/// `set_pa` for a constant supply), Pa.
#[inline(always)]
pub(crate) fn supply_pressure_at(supply: &Supply, set_pa: f64, oil_m3: f64) -> f64 {
    match supply {
        Supply::Constant => set_pa,
        Supply::Accumulator(acc) => {
            let gas = (acc.volume_m3 - oil_m3).max(1e-9 * acc.volume_m3);
            acc.precharge_pressure_pa * (acc.volume_m3 / gas).powf(acc.polytropic_exponent)
        }
    }
}

/// The accumulator's oil at the set pressure `set_pa`, m³ (0 without one).
pub(crate) fn charged_oil_m3(supply: &Supply, set_pa: f64) -> f64 {
    match supply {
        Supply::Constant => 0.0,
        Supply::Accumulator(acc) => {
            let ratio = acc.precharge_pressure_pa / set_pa;
            acc.volume_m3 * (1.0 - ratio.powf(1.0 / acc.polytropic_exponent))
        }
    }
}

/// The rates `(accumulator oil, supply pressure)` of `supply` (set pressure `set_pa`) when
/// the valves draw `drawn_m3_s`, the bank holding `oil_m3` at pressure `p_s`: the pumps give
/// their full flow below the set pressure and taper to nothing over the 1 % below it.
#[inline(always)]
pub(crate) fn supply_rates(
    supply: &Supply,
    set_pa: f64,
    drawn_m3_s: f64,
    oil_m3: f64,
    p_s: f64,
) -> (f64, f64) {
    match supply {
        Supply::Constant => (0.0, 0.0),
        Supply::Accumulator(acc) => {
            let band = 0.01 * set_pa;
            let taper = ((set_pa - p_s) / band).clamp(0.0, 1.0);
            let q = acc.pump_flow_m3_s * taper - drawn_m3_s;
            let gas = (acc.volume_m3 - oil_m3).max(1e-9 * acc.volume_m3);
            (q, acc.polytropic_exponent * p_s * q / gas)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::preset;

    /// `|∂ṗ/∂p|` of chamber `a`, chamber `b` and the supply by central differences of
    /// [`TableSystem::hydraulic_rates_with`] (steps of `δ` Pa, inside one branch of the law).
    fn jacobian_diagonal(sys: &TableSystem, u: f64, s: &HydraulicState, d: f64) -> [f64; 3] {
        let c = sys.constants();
        let rates = |s: HydraulicState| sys.hydraulic_rates_with(&c, u, 0.1, 0.0, &s);
        // The central difference of one rate against one pressure of the state.
        let central = |set: fn(&mut HydraulicState, f64), rate: fn(&HydraulicRates) -> f64| {
            let at = |sign: f64| {
                let mut t = *s;
                set(&mut t, sign * d);
                rate(&rates(t))
            };
            (at(1.0) - at(-1.0)) / (2.0 * d)
        };
        let da = central(|t, d| t.p_a_pa += d, |r| r.p_a);
        let db = central(|t, d| t.p_b_pa += d, |r| r.p_b);
        let ds = central(|t, d| t.supply_pressure_pa += d, |r| r.supply_pressure);
        [da.abs(), db.abs(), ds.abs()]
    }

    /// The stiffest pressure rate is the largest diagonal entry of the pressures' Jacobian,
    /// checked against central differences of the right-hand side itself: at the working
    /// point (a drop of MPa: some hundred 1/s), near the supply at full opening (a few kPa of
    /// drop) and inside the laminar drop (the steepest the law gets, `β/V·K/√p_t`, with
    /// `p_t` 700 Pa on the LHPOST: tens of thousands 1/s, far beyond its 7 steps of 0.14 ms),
    /// for either sign of the opening, with a constant supply and with the accumulator.
    /// Bound 1e-6 relative: the differences' truncation and rounding at these steps.
    #[test]
    fn the_stiffest_pressure_rate_is_the_jacobians_largest_diagonal_entry() {
        let bank = preset::lhpost_2008();
        let mut constant = bank;
        constant.supply = Supply::Constant;
        // Inside the pump's taper (its corner at the set pressure has no derivative).
        let set = bank.supply_pressure_pa;
        let p_s = set - 0.5e-2 * set;
        let p_t = LAMINAR_FRACTION * bank.servo_valve.rated_pressure_drop_pa;
        let oil = bank.charged_oil_m3();
        for sys in [&bank, &constant] {
            let cases = [
                // (u, p_a, p_b, spool, finite-difference step)
                (0.0, 12e6, 9e6, 0.3, 10.0),
                (0.2, p_s - 4e3, 1e6, 1.0, 1.0),
                (-0.5, p_s - 0.3 * p_t, 2e6, 0.9, 0.01),
                (0.4, 5e6, p_s - 0.5 * p_t, -1.0, 0.01),
                (0.1, 2e6, 8e6, -0.02, 10.0),
            ];
            for (u, p_a, p_b, spool, d) in cases {
                let s = HydraulicState {
                    p_a_pa: p_a,
                    p_b_pa: p_b,
                    spool,
                    spool_rate_1_s: 0.0,
                    accumulator_oil_m3: if sys.supply == Supply::Constant {
                        0.0
                    } else {
                        oil
                    },
                    supply_pressure_pa: p_s,
                };
                let rate = sys.pressure_rate_1_s(&sys.constants(), u, &s);
                let fd = jacobian_diagonal(sys, u, &s, d);
                let expected = fd.iter().copied().fold(0.0, f64::max);
                if let Supply::Accumulator(_) = sys.supply {
                    // The bank's own rate, which the chambers' hide, against its difference.
                    let c = sys.constants();
                    let r = sys.return_pressure_pa;
                    let (g_a, g_b) = four_way_conductances(&c, spool, p_a, p_b, p_s, r);
                    let (q_a, q_b) = sys.valve_flows_with(&c, spool, p_a, p_b, p_s);
                    let n = f64::from(sys.actuator.count);
                    let (drawn, g) = if spool >= 0.0 {
                        (q_a, g_a)
                    } else {
                        (-q_b, g_b)
                    };
                    let bank = supply_stiffness_1_s(&sys.supply, set, n * drawn, n * g, oil, p_s);
                    println!("  bank {bank:.6e} 1/s, difference {:.6e}", fd[2]);
                    assert!((bank / fd[2] - 1.0).abs() < 1e-6, "{bank} vs {}", fd[2]);
                }
                println!("u {u}, spool {spool}: {rate:.6e} 1/s, differences {fd:?}");
                assert!((rate / expected - 1.0).abs() < 1e-6, "{rate} vs {expected}");
            }
        }
        // Inside the laminar drop at full opening: the closed form.
        let c = constant.constants();
        let (v_a, _) = constant.chamber_volumes_m3(0.0);
        let s = HydraulicState {
            p_a_pa: p_s - 0.5 * p_t,
            p_b_pa: 1e6,
            spool: 1.0,
            spool_rate_1_s: 0.0,
            accumulator_oil_m3: 0.0,
            supply_pressure_pa: p_s,
        };
        let laminar = constant.oil_bulk_modulus_pa / v_a
            * (c.land_coefficient / p_t.sqrt() + constant.actuator.leakage_m3_s_per_pa);
        let rate = constant.pressure_rate_1_s(&c, 0.0, &s);
        assert!((rate / laminar - 1.0).abs() < 1e-12, "{rate} vs {laminar}");
        assert!(rate * constant.controller.period_s() / 7.0 > 2.8, "{rate}");
    }
}
