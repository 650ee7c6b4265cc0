//! The loop around the platen: command → controller → servo-valves → actuator chambers →
//! actuator force. Physics only, like `platen-model`: parameters and their validation,
//! right-hand sides, the discrete controller, the linearisation and the closed forms. The
//! integrators (`platen-integrate`) couple it to the platen's equation with exact stick-slip.
//!
//! # Equations
//!
//! * **Controller** ([`Controller`]), at `f_c` with zero-order hold:
//!   `d = K_p·(u_ref − u) + K_i∫(u_ref − u) + K_vf·v_ref + K_af·a_ref − K_vb·v − K_ab·a − K_Δp·HP(Δp)`,
//!   `|d| ≤ 1`.
//! * **Servo-valve** ([`ServoValve`]): the drive, delayed by `τ`, moves the spool
//!   `ẍ_v = ω_v²(d(t − τ) − x_v) − 2ζ_vω_vẋ_v`; the flow sees the opening clamped to `±1`.
//!   Each land passes `Q = K·x_v·√Δp_land` (critically centred four-way valve), with
//!   `K = m·Q_r/√(Δp_r/2)` for `m` valves rated `Q_r` at a total drop `Δp_r`.
//! * **Chambers** ([`Actuator`]): `ṗ_a = β/V_a(u)·(Q_a − A_a·v − C_L(p_a − p_b))`,
//!   `ṗ_b = β/V_b(u)·(−Q_b + A_b·v + C_L(p_a − p_b))`, `V_a = V_a0 + A_a·u`,
//!   `V_b = V_b0 − A_b·u`; absolute pressures never below zero.
//! * **Force** on the platen: `F_A = n·(A_a·p_a − A_b·p_b)`.
//! * **Supply** ([`Supply`]): constant, or an accumulator bank whose pressure follows its gas
//!   (`P·V_g^n` constant) as the valves draw oil and the pumps refill it.
//!
//! # The multi-axis table
//!
//! [`TableHydraulics`] gives each actuator of a multi-axis table its own servo-valves and
//! chambers (double-acting with a four-way valve, or single-acting with one chamber and a
//! three-way valve) on one supply, with null pressures that hold the platen at rest.
//! [`DofController`] is the DOF control of such a table: the three-variable law per DOF
//! through the geometry at neutral ([`DofGeometry`]), and a force balance on the redundant
//! actuators. `platen-integrate`'s `forward_table_loop` runs them with the platen.
//! [`TableLinearisation`] is their small-signal model about neutral at rest: the command →
//! pose transfer matrix, each DOF's loop gain and margins, and the cross-talk.
//!
//! # Invariant
//!
//! A [`TableSystem`] is always valid: its values are private and the only way to make one,
//! [`TableSystem::new`] (or `TryFrom<TableSystemParts>`), checks them all, with the same
//! checks, in the same order and with the same messages as ever. To change a value, take its
//! parts ([`TableSystem::into_parts`]), change them and call [`TableSystem::new`] again.
//!
//! # Conventions
//!
//! SI units, unit in every name; pressures absolute, Pa; `u`, `v` positive along the force
//! that `p_a` makes; the drive and the spool opening are dimensionless fractions of full
//! scale; `Δp = p_a − p_b`. The reference velocity and acceleration are the command's own
//! `v`/`a` channels (given, or derived from the displacement by the same central differences
//! as every motion record; see `platen-scenario`), read at the controller's samples.
//!
//! ```
//! use platen_system::{preset, Mechanics};
//!
//! let sys = preset::lhpost_2008();
//! let bare = Mechanics { mass_kg: 144e3, stiffness_n_per_m: 0.0, damping_n_s_per_m: 0.0 };
//! let f = sys.oil_column_frequency_hz(bare.mass_kg, 0.0);
//! assert!((f - 10.66).abs() < 0.01);
//! ```

#![warn(missing_docs)]

mod controller;
mod dof_control;
mod error;
mod hydraulics;
mod linear;
mod params;
pub mod preset;
mod spool;
mod table;
mod table_linear;

pub use controller::{ControllerInput, ControllerState};
pub use dof_control::{
    open_loop, DofCommand, DofController, DofControllerState, DofFeedback, DofGeometry,
};
pub use error::{Result, SystemError};
pub use hydraulics::{HydraulicConstants, HydraulicRates, HydraulicState, LAMINAR_FRACTION};
pub use linear::{Capacities, Linearisation, Margins, Mechanics, Passband, SECANT_SPEED_M_S};
pub use params::{
    Accumulator, Actuator, Controller, ServoValve, Supply, TableSystem, TableSystemParts,
    PLAUSIBLE_BULK_MODULUS_PA, PLAUSIBLE_CHAMBER_M3, PLAUSIBLE_SUPPLY_PA,
};
pub use spool::{SpoolResponse, SpoolWeights};
pub use table::{
    ActuatorHydraulics, ActuatorRates, ActuatorState, StiffRate, TableHydraulics,
    TableHydraulicsParts,
};
pub use table_linear::{
    ActuatorLinearisation, CrossTalk, FlowGains, LoopStability, TableLinearisation,
    MARGINAL_RATE_1_S, PADE_ORDER,
};
