//! Named table systems. `lhpost-2008` is the NEES-UCSD LHPOST's loop, built from its
//! published figures; every value the sources do not give is chosen to meet them.
//!
//! # Where the `lhpost-2008` numbers come from
//!
//! | value | | source |
//! |---|---|---|
//! | 2 actuators, acting together | | published (paper §1.2: two actuators) |
//! | supply pressure 20.7 MPa, return 0.35 MPa | | **assumed** (3000 psi, the usual rating pressure of servo-hydraulic supplies; 50 psi return) |
//! | cap area `A_a` = 0.2051 m², rod area `A_b` = 0.1291 m² | | **derived from** the published 4.2 MN compression / 2.6 MN tension of each actuator: `A_a·P_s − A_b·P_R` = 4.2 MN, `A_b·P_s − A_a·P_R` = 2.6 MN |
//! | 2 servo-valves per actuator, 10 000 l/min each at 7 MPa drop | | published |
//! | spool natural frequency 246 Hz | | **derived from** the 246 Hz valve-stage resonance in the paper's records (§2) |
//! | spool damping ratio 0.5, delay 0.5 ms | | **assumed** |
//! | oil bulk modulus 1.0 GPa (effective) | | **assumed** (mineral oil ≈ 1.5 GPa, lowered by hoses and entrained air) |
//! | chamber volumes 0.2122 / 0.1335 m³ at mid-stroke | | **derived from** the 10.66 Hz oil column with `Mₑ` = 144 t (paper §2): equal effective column length 1.035 m each side, so 0.285 m of dead length and lines beyond the 0.75 m stroke |
//! | cross-port leakage 2·10⁻¹¹ m³/s/Pa | | **assumed** (a 1 MPa difference leaks 1.2 l/min) |
//! | accumulator: precharge 13.8 MPa, 8 m³ gas, n = 1.4, pumps 0.05 m³/s | | **assumed** (a bank that carries a 40 s earthquake at full scale) |
//! | controller at 1024 Hz | | **assumed** (the 469D's acquisition rate, paper §2) |
//! | gains | | **assumed**, tuned on the linearised loop: see [`lhpost_2008`] |
//!
//! What these give (tested): the oil column at 10.66 Hz with 144 t at mid-stroke; no-load
//! velocities of 3.5 m/s extending and 2.8 m/s retracting at full opening (at least the
//! published 1.8 m/s); stall forces 8.4 MN pushing and 5.2 MN pulling for the pair, the
//! published 4.2/2.6 MN per actuator. The published table capacity of 6.8 MN is one
//! actuator's compression plus the other's tension (4.2 + 2.6 MN), the mean of the pair's push
//! and pull; the preset's `limits.force_n` stays 6.8 MN.

use crate::error::{Result, SystemError};
use crate::params::{
    Accumulator, Actuator, Controller, ServoValve, Supply, TableSystem, TableSystemParts,
};

/// Names accepted by [`by_name`].
pub const PRESET_NAMES: &str = "lhpost-2008";

/// The preset called `name`.
///
/// # Errors
/// [`SystemError::UnknownPreset`] listing the names.
pub fn by_name(name: &str) -> Result<TableSystem> {
    match name {
        "lhpost-2008" => Ok(lhpost_2008()),
        _ => Err(SystemError::UnknownPreset {
            name: name.to_owned(),
            known: PRESET_NAMES,
        }),
    }
}

/// The LHPOST's loop (see the module docs for every value's source).
///
/// Gains (assumed; tuned on the linearised loop with the identified platen, its secant
/// damping at 0.1 m/s, for a flat command → displacement response with margins of at least
/// 8 dB and 45°): displacement gain 16 /m (a velocity constant of 60 /s through the valves'
/// 3.8 m/s per unit opening); velocity feedforward 0.2 s/m, three quarters of the inverse of
/// that velocity gain (the full inverse overshoots near the oil column); acceleration
/// feedforward 0.008 s²/m; `Δp` feedback 2·10⁻⁸ /Pa (a 1 MPa difference takes 2 % of the
/// drive) through a 0.1 Hz high-pass, which damps the oil column without fighting the static
/// load of the hold-down struts. They give a gain margin of 14.3 dB (at 140 Hz), a phase
/// margin of 74° and a closed-loop peak of 1.45 at 7.6 Hz; `platen model --system lhpost-2008` prints
/// them. On Northridge (Tarzana, 100 %) the platen follows the command within 2.0 mm RMS.
pub fn lhpost_2008() -> TableSystem {
    let parts = TableSystemParts {
        actuator: Actuator {
            count: 2,
            cap_area_m2: 0.2051,
            rod_area_m2: 0.1291,
            cap_volume_m3: 0.2122,
            rod_volume_m3: 0.1335,
            leakage_m3_s_per_pa: 2e-11,
        },
        servo_valve: ServoValve {
            count: 2,
            rated_flow_m3_s: 10_000.0 / 60_000.0,
            rated_pressure_drop_pa: 7e6,
            natural_frequency_hz: 246.0,
            damping_ratio: 0.5,
            delay_s: 0.0005,
        },
        oil_bulk_modulus_pa: 1.0e9,
        supply_pressure_pa: 20.7e6,
        return_pressure_pa: 0.35e6,
        supply: Supply::Accumulator(Accumulator {
            precharge_pressure_pa: 13.8e6,
            volume_m3: 8.0,
            polytropic_exponent: 1.4,
            pump_flow_m3_s: 0.05,
        }),
        controller: Controller {
            sample_rate_hz: 1024.0,
            displacement_gain_per_m: 16.0,
            integral_gain_per_m_s: 0.0,
            velocity_feedforward_s_per_m: 0.2,
            acceleration_feedforward_s2_per_m: 0.008,
            velocity_feedback_s_per_m: 0.0,
            acceleration_feedback_s2_per_m: 0.0,
            delta_p_gain_per_pa: 2e-8,
            delta_p_highpass_hz: 0.1,
        },
    };
    TableSystem::new(parts, 0.0).expect("the LHPOST preset is valid")
}
