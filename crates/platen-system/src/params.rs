//! The parameters of the table system, validated when made ([`TableSystem::new`]).

use crate::error::{invalid, non_negative, positive, Result};

/// The actuators: `count` identical actuators acting together along `u` (a positive chamber
/// pressure difference `A_a·p_a − A_b·p_b` pushes the platen towards `+u`).
///
/// Chamber `a` (cap side) grows with `u`: `V_a(u) = V_a0 + A_a·u`; chamber `b` (rod side)
/// shrinks: `V_b(u) = V_b0 − A_b·u`. A double-ended actuator has `A_a = A_b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Actuator {
    /// Number of actuators acting together.
    pub count: u32,
    /// Piston area on the cap side (chamber `a`), m².
    pub cap_area_m2: f64,
    /// Annulus area on the rod side (chamber `b`), m².
    pub rod_area_m2: f64,
    /// Volume of chamber `a` at mid-stroke (`u = 0`), lines to the valve included, m³.
    pub cap_volume_m3: f64,
    /// Volume of chamber `b` at mid-stroke, lines included, m³.
    pub rod_volume_m3: f64,
    /// Cross-port leakage coefficient `C_L`: flow from `a` to `b` per Pa of `p_a − p_b`.
    pub leakage_m3_s_per_pa: f64,
}

/// The servo-valves of one actuator: `count` identical valves in parallel.
///
/// Rated as manufacturers rate them: `rated_flow_m3_s` through a fully open valve at a
/// total pressure drop of `rated_pressure_drop_pa` across both lands (half on each), so each
/// land passes `Q = K·x_v·√Δp_land` with `K = Q_r/√(Δp_r/2)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoValve {
    /// Valves per actuator.
    pub count: u32,
    /// Rated flow of one valve, m³/s.
    pub rated_flow_m3_s: f64,
    /// Total pressure drop at which the flow is rated, Pa.
    pub rated_pressure_drop_pa: f64,
    /// Natural frequency of the spool's second-order response, Hz.
    pub natural_frequency_hz: f64,
    /// Damping ratio of the spool's response.
    pub damping_ratio: f64,
    /// Pure delay between the drive and the spool's response, s.
    pub delay_s: f64,
}

/// An accumulator bank fed by pumps: the supply pressure droops when the valves draw more
/// than the pumps give.
///
/// The gas follows `P·V_g^n = P₀·V₀^n` (precharge `P₀` at the bank's gas volume `V₀`, when
/// empty of oil). The pumps deliver their full flow below the set pressure (the table's
/// `supply_pressure_pa`) and taper linearly to nothing over the 1 % of it just below.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accumulator {
    /// Gas precharge pressure, Pa (absolute), below the supply pressure.
    pub precharge_pressure_pa: f64,
    /// Total gas volume of the bank at precharge, m³.
    pub volume_m3: f64,
    /// Polytropic exponent of the gas (1 isothermal, 1.4 adiabatic nitrogen).
    pub polytropic_exponent: f64,
    /// Largest flow the pumps deliver, m³/s.
    pub pump_flow_m3_s: f64,
}

/// The digital controller (three-variable style), run at `sample_rate_hz` with a
/// zero-order hold on its drive:
///
/// `d = K_p·e + K_i·∫e + K_vf·v_ref + K_af·a_ref − K_vb·v − K_ab·a − K_Δp·HP(Δp)`,
/// `e = u_ref − u`, saturated at `|d| ≤ 1`. `HP` is a first-order high-pass filter at
/// `delta_p_highpass_hz` (Tustin; 0 Hz passes `Δp` unfiltered). The integrator stops while
/// the drive is saturated in the direction it would push (no wind-up). Absent gains are 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controller {
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// `K_p`, drive per m of error.
    pub displacement_gain_per_m: f64,
    /// `K_i`, drive per m·s of integrated error.
    pub integral_gain_per_m_s: f64,
    /// `K_vf`, drive per m/s of command velocity.
    pub velocity_feedforward_s_per_m: f64,
    /// `K_af`, drive per m/s² of command acceleration.
    pub acceleration_feedforward_s2_per_m: f64,
    /// `K_vb`, drive per m/s of platen velocity.
    pub velocity_feedback_s_per_m: f64,
    /// `K_ab`, drive per m/s² of platen acceleration.
    pub acceleration_feedback_s2_per_m: f64,
    /// `K_Δp`, drive per Pa of (high-passed) pressure difference `p_a − p_b`.
    pub delta_p_gain_per_pa: f64,
    /// Corner of the high-pass filter on `Δp`, Hz (0: no filter).
    pub delta_p_highpass_hz: f64,
}

/// Where the valves take their oil from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Supply {
    /// A constant supply pressure.
    Constant,
    /// An accumulator bank fed by pumps (see [`Accumulator`]).
    Accumulator(Accumulator),
}

impl Actuator {
    /// Its values, and that its chambers keep oil over the stroke `±stroke_m`.
    fn validate(&self, stroke_m: f64) -> Result<()> {
        let a = self;
        if a.count == 0 {
            return Err(invalid("actuator.count", 0.0, "at least 1 actuator"));
        }
        positive("actuator.cap_side_area_m2", a.cap_area_m2)?;
        positive("actuator.rod_side_area_m2", a.rod_area_m2)?;
        plausible_area("actuator.cap_side_area_m2", a.cap_area_m2)?;
        plausible_area("actuator.rod_side_area_m2", a.rod_area_m2)?;
        positive("actuator.chamber_volume_m3", a.cap_volume_m3)?;
        positive("actuator.chamber_volume_m3", a.rod_volume_m3)?;
        plausible_chamber("actuator.chamber_volume_m3", a.cap_volume_m3)?;
        plausible_chamber("actuator.chamber_volume_m3", a.rod_volume_m3)?;
        non_negative("actuator.leakage_m3_s_per_pa", a.leakage_m3_s_per_pa)?;
        if stroke_m.is_finite() && stroke_m > 0.0 {
            let left_a = a.cap_volume_m3 - a.cap_area_m2 * stroke_m;
            if left_a <= 0.0 {
                return Err(invalid(
                    "actuator.chamber_volume_m3",
                    a.cap_volume_m3,
                    format!(
                        "more than A_a·stroke = {:.6} m³: the cap-side chamber would empty \
                         at u = −{stroke_m} m",
                        a.cap_area_m2 * stroke_m
                    ),
                ));
            }
            let left_b = a.rod_volume_m3 - a.rod_area_m2 * stroke_m;
            if left_b <= 0.0 {
                return Err(invalid(
                    "actuator.chamber_volume_m3",
                    a.rod_volume_m3,
                    format!(
                        "more than A_b·stroke = {:.6} m³: the rod-side chamber would empty \
                         at u = +{stroke_m} m",
                        a.rod_area_m2 * stroke_m
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The fastest spool a servo-valve may have, Hz ([`ServoValve::natural_frequency_hz`]).
pub const MAX_SPOOL_HZ: f64 = 5000.0;

/// The largest damping ratio of a spool ([`ServoValve::damping_ratio`]).
pub const MAX_SPOOL_DAMPING: f64 = 10.0;

impl ServoValve {
    /// `K = m·Q_r/√(Δp_r/2)` of all `m` valves together: the land coefficient, m³/s per √Pa
    /// at full opening.
    pub fn land_coefficient(&self) -> f64 {
        f64::from(self.count) * self.rated_flow_m3_s / (0.5 * self.rated_pressure_drop_pa).sqrt()
    }

    /// Its values.
    pub(crate) fn validate(&self) -> Result<()> {
        let v = self;
        if v.count == 0 {
            return Err(invalid("servo_valve.count", 0.0, "at least 1 valve"));
        }
        positive("servo_valve.rated_flow_m3_s", v.rated_flow_m3_s)?;
        positive(
            "servo_valve.rated_pressure_drop_pa",
            v.rated_pressure_drop_pa,
        )?;
        positive("servo_valve.natural_frequency_hz", v.natural_frequency_hz)?;
        positive("servo_valve.damping_ratio", v.damping_ratio)?;
        // A servo-valve's spool answers at tens to hundreds of hertz, damped below critical
        // or a little above: beyond these bounds a value is a unit slip (rad/s written as Hz,
        // a percentage as a ratio), and a spool ten kilohertz fast takes the loop a thousand
        // steps a controller period.
        if v.natural_frequency_hz > MAX_SPOOL_HZ {
            return Err(invalid(
                "servo_valve.natural_frequency_hz",
                v.natural_frequency_hz,
                format!(
                    "at most {MAX_SPOOL_HZ} Hz (servo-valves answer at tens to hundreds of hertz)"
                ),
            ));
        }
        if v.damping_ratio > MAX_SPOOL_DAMPING {
            return Err(invalid(
                "servo_valve.damping_ratio",
                v.damping_ratio,
                format!(
                    "at most {MAX_SPOOL_DAMPING} (a ratio to critical damping, not a percentage)"
                ),
            ));
        }
        non_negative("servo_valve.delay_s", v.delay_s)?;
        if v.delay_s > 1.0 {
            return Err(invalid("servo_valve.delay_s", v.delay_s, "at most 1 s"));
        }
        Ok(())
    }
}

impl Controller {
    /// Its rate, gains and filter.
    pub(crate) fn validate(&self) -> Result<()> {
        let c = self;
        positive("controller.sample_rate_hz", c.sample_rate_hz)?;
        // Each gain at most what opens the valve fully for an error of a micrometre (a
        // micrometre per second, per second squared; a pascal): beyond any loop, the unit
        // slip or typing error that makes the run chatter at full opening forever.
        for (path, value, max) in [
            (
                "controller.displacement_gain_per_m",
                c.displacement_gain_per_m,
                1e6,
            ),
            (
                "controller.integral_gain_per_m_s",
                c.integral_gain_per_m_s,
                1e9,
            ),
            (
                "controller.velocity_feedforward_s_per_m",
                c.velocity_feedforward_s_per_m,
                1e6,
            ),
            (
                "controller.acceleration_feedforward_s2_per_m",
                c.acceleration_feedforward_s2_per_m,
                1e6,
            ),
            (
                "controller.velocity_feedback_s_per_m",
                c.velocity_feedback_s_per_m,
                1e6,
            ),
            (
                "controller.acceleration_feedback_s2_per_m",
                c.acceleration_feedback_s2_per_m,
                1e6,
            ),
            ("controller.delta_p_gain_per_pa", c.delta_p_gain_per_pa, 1.0),
            (
                "controller.delta_p_highpass_hz",
                c.delta_p_highpass_hz,
                f64::INFINITY,
            ),
        ] {
            non_negative(path, value)?;
            if value > max {
                return Err(invalid(
                    path,
                    value,
                    format!(
                        "at most {max:e}: a gain that opens the valve fully for an error of \
                         {:e} of its unit is beyond any loop",
                        1.0 / max
                    ),
                ));
            }
        }
        if c.delta_p_highpass_hz >= 0.5 * c.sample_rate_hz {
            return Err(invalid(
                "controller.delta_p_highpass_hz",
                c.delta_p_highpass_hz,
                format!(
                    "below the controller's Nyquist frequency {} Hz",
                    0.5 * c.sample_rate_hz
                ),
            ));
        }
        Ok(())
    }
}

/// The values of a [`TableSystem`], unchecked: what [`TableSystem::new`] validates, and what
/// [`TableSystem::into_parts`] gives back to change a value and validate again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableSystemParts {
    /// The actuators.
    pub actuator: Actuator,
    /// The servo-valves of each actuator.
    pub servo_valve: ServoValve,
    /// Effective bulk modulus of the oil (lines, hoses and entrained air included), Pa.
    pub oil_bulk_modulus_pa: f64,
    /// Supply pressure (absolute), Pa: the constant pressure, or the pumps' set pressure and
    /// the accumulator's initial pressure.
    pub supply_pressure_pa: f64,
    /// Return (tank) pressure (absolute), Pa.
    pub return_pressure_pa: f64,
    /// Constant supply or accumulator bank.
    pub supply: Supply,
    /// The controller.
    pub controller: Controller,
}

/// The complete loop around the platen: command → controller → servo-valves → actuator
/// chambers → actuator force.
///
/// Always valid: the only way to make one is [`TableSystem::new`], which checks every value
/// (and the chambers over a stroke); to change a value, take its
/// [`parts`](TableSystem::into_parts), change them and call [`TableSystem::new`] again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableSystem {
    pub(crate) actuator: Actuator,
    pub(crate) servo_valve: ServoValve,
    pub(crate) oil_bulk_modulus_pa: f64,
    pub(crate) supply_pressure_pa: f64,
    pub(crate) return_pressure_pa: f64,
    pub(crate) supply: Supply,
    pub(crate) controller: Controller,
}

impl TableSystemParts {
    /// The oil-column frequency of these values, checked or not (e.g. fitted ones, before
    /// [`TableSystem::new`] decides whether they make a table system): the same formula as
    /// [`TableSystem::oil_column_frequency_hz`], Hz.
    pub fn oil_column_frequency_hz(&self, mass_kg: f64, u_m: f64) -> f64 {
        TableSystem::unchecked(*self).oil_column_frequency_hz(mass_kg, u_m)
    }
}

impl TryFrom<TableSystemParts> for TableSystem {
    type Error = crate::SystemError;

    /// [`TableSystem::new`] with no stroke to check the chambers over.
    fn try_from(parts: TableSystemParts) -> Result<Self> {
        TableSystem::new(parts, 0.0)
    }
}

impl From<TableSystem> for TableSystemParts {
    fn from(sys: TableSystem) -> Self {
        sys.into_parts()
    }
}

impl TableSystem {
    /// A table system from its values, checked: every value, and that the chambers keep oil
    /// over the stroke `±stroke_m` (`V_a0 − A_a·stroke > 0` and `V_b0 − A_b·stroke > 0`; a
    /// stroke that is not finite and positive, e.g. 0, skips that check).
    ///
    /// # Errors
    /// [`crate::SystemError::Invalid`] naming the first offending value by its path.
    pub fn new(parts: TableSystemParts, stroke_m: f64) -> Result<Self> {
        let sys = TableSystem::unchecked(parts);
        sys.check(stroke_m)?;
        Ok(sys)
    }

    /// The values as they are, not checked: only for computing with values that may not make
    /// a table system, never handed out.
    fn unchecked(parts: TableSystemParts) -> Self {
        let TableSystemParts {
            actuator,
            servo_valve,
            oil_bulk_modulus_pa,
            supply_pressure_pa,
            return_pressure_pa,
            supply,
            controller,
        } = parts;
        TableSystem {
            actuator,
            servo_valve,
            oil_bulk_modulus_pa,
            supply_pressure_pa,
            return_pressure_pa,
            supply,
            controller,
        }
    }

    /// Its values, to change some and make a new one with [`TableSystem::new`].
    pub fn into_parts(self) -> TableSystemParts {
        TableSystemParts {
            actuator: self.actuator,
            servo_valve: self.servo_valve,
            oil_bulk_modulus_pa: self.oil_bulk_modulus_pa,
            supply_pressure_pa: self.supply_pressure_pa,
            return_pressure_pa: self.return_pressure_pa,
            supply: self.supply,
            controller: self.controller,
        }
    }

    /// The actuators.
    pub fn actuator(&self) -> &Actuator {
        &self.actuator
    }

    /// The servo-valves of each actuator.
    pub fn servo_valve(&self) -> &ServoValve {
        &self.servo_valve
    }

    /// Effective bulk modulus of the oil (lines, hoses and entrained air included), Pa.
    pub fn oil_bulk_modulus_pa(&self) -> f64 {
        self.oil_bulk_modulus_pa
    }

    /// Supply pressure (absolute), Pa: the constant pressure, or the pumps' set pressure and
    /// the accumulator's initial pressure.
    pub fn supply_pressure_pa(&self) -> f64 {
        self.supply_pressure_pa
    }

    /// Return (tank) pressure (absolute), Pa.
    pub fn return_pressure_pa(&self) -> f64 {
        self.return_pressure_pa
    }

    /// Constant supply or accumulator bank.
    pub fn supply(&self) -> &Supply {
        &self.supply
    }

    /// The controller.
    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// Checks that the chambers keep oil over the stroke `±stroke_m`, for a system made for
    /// another stroke (or none): `V_a0 − A_a·stroke > 0` and `V_b0 − A_b·stroke > 0`. Its
    /// values were checked when it was made; they are checked again, in the same order as
    /// [`TableSystem::new`] does, so the error is the one `new` would give at this stroke.
    ///
    /// # Errors
    /// [`crate::SystemError::Invalid`] naming the first offending value by its path.
    pub fn check_stroke(&self, stroke_m: f64) -> Result<()> {
        self.check(stroke_m)
    }

    /// Every value, and the chambers over the stroke `±stroke_m`.
    fn check(&self, stroke_m: f64) -> Result<()> {
        self.actuator.validate(stroke_m)?;
        self.servo_valve.validate()?;
        self.validate_supply()?;
        self.controller.validate()
    }

    /// The oil, the supply and return pressures, and the accumulator bank.
    fn validate_supply(&self) -> Result<()> {
        validate_supply(
            self.oil_bulk_modulus_pa,
            self.supply_pressure_pa,
            self.return_pressure_pa,
            &self.supply,
        )
    }

    /// `K = Q_r/√(Δp_r/2)` of all the valves of one actuator together: the land
    /// coefficient, m³/s per √Pa at full opening.
    pub fn land_coefficient(&self) -> f64 {
        self.servo_valve.land_coefficient()
    }

    /// The null pressures `(p_a0, p_b0)` of a centred valve with no load: equal drops on
    /// both lands (`p_a0 + p_b0 = P_s + P_R`) and no net force (`A_a·p_a0 = A_b·p_b0`).
    pub fn null_pressures_pa(&self) -> (f64, f64) {
        let (aa, ab) = (self.actuator.cap_area_m2, self.actuator.rod_area_m2);
        let sum = self.supply_pressure_pa + self.return_pressure_pa;
        (sum * ab / (aa + ab), sum * aa / (aa + ab))
    }

    /// Chamber volumes `(V_a, V_b)` at displacement `u_m`, m³.
    #[inline(always)]
    pub fn chamber_volumes_m3(&self, u_m: f64) -> (f64, f64) {
        let a = &self.actuator;
        (
            a.cap_volume_m3 + a.cap_area_m2 * u_m,
            a.rod_volume_m3 - a.rod_area_m2 * u_m,
        )
    }

    /// The actuator force `n·(A_a·p_a − A_b·p_b)` of all actuators, N.
    #[inline(always)]
    pub fn force_n(&self, p_a_pa: f64, p_b_pa: f64) -> f64 {
        let a = &self.actuator;
        f64::from(a.count) * (a.cap_area_m2 * p_a_pa - a.rod_area_m2 * p_b_pa)
    }
}

/// The supply pressures a servo-hydraulic table runs at, Pa: a few MPa to a few tens (21 MPa
/// is the norm, 35 MPa the highest lab systems); a value outside is a unit slip (an MPa value
/// written in Pa, or one multiplied twice), refused before it is blamed on another value or
/// runs at 20 g.
pub const PLAUSIBLE_SUPPLY_PA: (f64, f64) = (0.5e6, 70e6);

/// Refuses a supply pressure outside [`PLAUSIBLE_SUPPLY_PA`], naming what it looks like.
fn plausible_supply(p: f64) -> Result<()> {
    let (lo, hi) = PLAUSIBLE_SUPPLY_PA;
    if (lo..=hi).contains(&p) {
        return Ok(());
    }
    let hint = if (lo * 1e-6..=hi * 1e-6).contains(&p) {
        format!(": {p} looks like MPa, which is {p}e6 Pa")
    } else if (lo * 1e-3..=hi * 1e-3).contains(&p) {
        format!(": {p} looks like kPa, which is {p}e3 Pa")
    } else if p > hi {
        format!(": {} MPa is beyond any servo-hydraulic supply", p * 1e-6)
    } else {
        String::new()
    };
    Err(invalid(
        "supply_pressure_pa",
        p,
        format!(
            "an absolute supply pressure in Pa between {} and {} MPa{hint}",
            lo * 1e-6,
            hi * 1e-6
        ),
    ))
}

/// The effective bulk moduli of a table's oil, Pa: 10 MPa (oil full of air) to 20 GPa (beyond
/// any oil; mineral oil is 1.4–2 GPa, less with hoses and air). A value outside is a unit
/// slip (a GPa or MPa value written in Pa), refused with what it looks like.
pub const PLAUSIBLE_BULK_MODULUS_PA: (f64, f64) = (1e7, 2e10);

/// The largest oil volume of one chamber, lines included, m³: an actuator of a large table
/// holds some 0.2 m³ a side (the LHPOST's 0.21 and 0.13 m³); a volume above this is one in
/// litres (or cm³) written as m³.
pub const PLAUSIBLE_CHAMBER_M3: f64 = 10.0;

/// Refuses a bulk modulus outside [`PLAUSIBLE_BULK_MODULUS_PA`], naming what it looks like.
fn plausible_bulk_modulus(path: &'static str, beta: f64) -> Result<()> {
    let (lo, hi) = PLAUSIBLE_BULK_MODULUS_PA;
    if (lo..=hi).contains(&beta) {
        return Ok(());
    }
    let hint = if beta <= 20.0 {
        format!(": {beta} looks like GPa, which is {beta}e9 Pa")
    } else if beta <= 20e3 {
        format!(": {beta} looks like MPa, which is {beta}e6 Pa")
    } else if beta < lo {
        format!(": {beta} looks like kPa, which is {beta}e3 Pa")
    } else {
        format!(": {} GPa is stiffer than any oil", beta * 1e-9)
    };
    Err(invalid(
        path,
        beta,
        format!(
            "an oil bulk modulus in Pa between {} MPa and {} GPa{hint}",
            lo * 1e-6,
            hi * 1e-9
        ),
    ))
}

/// The largest piston area of one actuator, m²: a 1.6 m bore, eight times the LHPOST's
/// 0.205 m² cap side; an area above this is one in cm² written as m² (the LHPOST's would read
/// 2051).
pub const PLAUSIBLE_AREA_M2: f64 = 2.0;

/// Refuses a piston area above [`PLAUSIBLE_AREA_M2`] (cm² written as m²).
pub(crate) fn plausible_area(path: &'static str, a: f64) -> Result<()> {
    if a <= PLAUSIBLE_AREA_M2 {
        return Ok(());
    }
    Err(invalid(
        path,
        a,
        format!(
            "one actuator's piston area in m², at most {PLAUSIBLE_AREA_M2} m² (a 1.6 m bore; \
             the LHPOST's cap side is 0.2051 m²): {a} looks like cm², which is {} m²",
            a * 1e-4
        ),
    ))
}

/// Refuses a chamber volume above [`PLAUSIBLE_CHAMBER_M3`] (litres written as m³).
pub(crate) fn plausible_chamber(path: &'static str, v: f64) -> Result<()> {
    if v <= PLAUSIBLE_CHAMBER_M3 {
        return Ok(());
    }
    Err(invalid(
        path,
        v,
        format!(
            "one chamber's oil in m³, at most {PLAUSIBLE_CHAMBER_M3} m³ (a large table's \
             actuator holds some 0.2 m³ a side): {v} looks like litres, which is {} m³",
            v * 1e-3
        ),
    ))
}

/// The oil's bulk modulus, the supply and return pressures and the accumulator bank: the
/// checks shared by the uniaxial and the multi-axis table systems.
pub(crate) fn validate_supply(
    oil_bulk_modulus_pa: f64,
    supply_pressure_pa: f64,
    return_pressure_pa: f64,
    supply: &Supply,
) -> Result<()> {
    positive("oil_bulk_modulus_pa", oil_bulk_modulus_pa)?;
    plausible_bulk_modulus("oil_bulk_modulus_pa", oil_bulk_modulus_pa)?;
    positive("supply_pressure_pa", supply_pressure_pa)?;
    plausible_supply(supply_pressure_pa)?;
    non_negative("return_pressure_pa", return_pressure_pa)?;
    if return_pressure_pa >= supply_pressure_pa {
        return Err(invalid(
            "return_pressure_pa",
            return_pressure_pa,
            format!("below the supply pressure {} Pa", supply_pressure_pa),
        ));
    }
    if let Supply::Accumulator(acc) = supply {
        positive(
            "accumulator.precharge_pressure_pa",
            acc.precharge_pressure_pa,
        )?;
        if acc.precharge_pressure_pa >= supply_pressure_pa {
            return Err(invalid(
                "accumulator.precharge_pressure_pa",
                acc.precharge_pressure_pa,
                format!("below the supply pressure {} Pa", supply_pressure_pa),
            ));
        }
        positive("accumulator.volume_m3", acc.volume_m3)?;
        if !(acc.polytropic_exponent.is_finite() && (1.0..=1.7).contains(&acc.polytropic_exponent))
        {
            return Err(invalid(
                "accumulator.polytropic_exponent",
                acc.polytropic_exponent,
                "between 1 (isothermal) and 1.7",
            ));
        }
        non_negative("accumulator.pump_flow_m3_s", acc.pump_flow_m3_s)?;
    }
    Ok(())
}
