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
