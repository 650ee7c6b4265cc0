//! Identification of a shake-table platen's parameters from periodic tests: the
//! hysteresis-loop method of Ozcelik, Luco, Conte, Trombetti and Restrepo (2008, §3), the
//! least-squares fits behind their Eq. 21/22 and Fig. 8, and a global fit of Eq. 23 as a
//! cross-check; and from any test record (earthquake, white noise, periodic) by
//! [`identify_records`] (see "Any record" below). [`route`] says which a record needs.
//!
//! ```
//! use platen_ident::{identify, Settings, TestRecord};
//! use platen_integrate::{inverse, Motion, Trajectory};
//! use platen_model::preset;
//! use platen_scenario::generate::{sine_motion, triangle_motion};
//!
//! // Exact data of the identified LHPOST model at 13.8 MPa, sampled at 512 Hz.
//! let model = preset::lhpost_2008_identified(13.8e6).build().unwrap();
//! let record = |name: &str, motion: Motion| {
//!     let mut out = Trajectory::with_capacity(motion.len());
//!     inverse(&model, &motion, &mut out);
//!     TestRecord::from_rate(name, 512.0, out.u_m, out.a_m_s2, out.force_n)
//!         .unwrap()
//!         .with_velocity(out.v_m_s)
//!         .unwrap()
//!         .with_pressure_pa(13.8e6)
//!         .unwrap()
//! };
//! let tests = vec![
//!     record("S5", sine_motion(0.04, 1.0, 512.0, 4.0).unwrap()),
//!     record("S9", sine_motion(0.2, 0.6, 512.0, 5.0).unwrap()),
//!     record("S11", sine_motion(0.2, 1.2, 512.0, 3.0).unwrap()),
//!     record("T7", triangle_motion(0.375, 0.25, 0.8333, 512.0, 19.8).unwrap()),
//!     record("T9", triangle_motion(0.4688, 0.75, 6.0, 512.0, 8.25).unwrap()),
//! ];
//! let id = identify(&tests, &Settings::default().build().unwrap()).unwrap();
//! let p = id.params().unwrap();
//! assert!((p.effective_mass_kg / 144e3 - 1.0).abs() < 0.005);
//! assert!((p.stiffness_n_per_m / 1.266e6 - 1.0).abs() < 0.005);
//! // Every test is recognised from its data: names play no part.
//! assert_eq!(id.tests[0].kind, platen_ident::TestKind::Sine);
//! assert_eq!(id.tests[3].kind, platen_ident::TestKind::Triangle);
//! ```
//!
//! # The method
//!
//! 1. **Cycles** ([`CycleInfo`]). The period comes from a least-squares fit to every zero
//!    crossing of the low-passed displacement (`t_k = c + k·T/2 ± δ`, which also absorbs a
//!    displacement offset). The waveform is recognised from the time spent at constant
//!    velocity (a triangle ≥ 40 % of its cycle, a sine ≈ 5 %), unless given. Of the full
//!    cycles in the record the second-to-last is analysed (paper §3), starting at the
//!    offset-free upward zero crossing so that `u > 0` on its first half, and resampled on a
//!    grid of `n` points (`n` a multiple of 4) so that the mirror times `T/2 − t`, `T − t`,
//!    `3T/2 − t` of Eq. 10–20 fall on grid points.
//! 2. **Filters.** Inertial and elastic work uses a zero-phase Butterworth at 4× the
//!    fundamental; dissipative work the windowed-sinc FIR of order 512 at 8 Hz on 512 Hz data
//!    (1 s long at any rate), which keeps the friction jump at reversals and removes the
//!    10.66 Hz oil-column ringing. Every channel of a test goes through the same filter, so
//!    the symmetry identities hold for the filtered data exactly.
//! 3. **Stiffness** (Eq. 16/17, Table I): on the constant-velocity portions of each triangle
//!    test, `½[F(t) + F(T/2 − t)] − Mₑā = Kₑū + βḡ + c`. The paper takes `ā = 0` there; the
//!    small acceleration the low-pass leaves near the rounded reversals is subtracted with the
//!    mass found from the sine tests (stiffness and mass are alternated until they agree).
//!    `βḡ` is the net impulse of the oil-column transient at each reversal (see below). The
//!    stiffness at a pressure is the mean over its triangle tests.
//! 4. **Mass** (Eq. 18/19, Table II): for each sine test,
//!    `½[F(t) + F(T/2 − t)] − Kₑū = Mₑā + βḡ + c` with the stiffness of its pressure. Tests
//!    whose inertial force is small against their dissipative force (paper: S1–S3) or whose
//!    displacement is distorted (S12) are flagged and not averaged in ([`Flag`]). The
//!    acceleration of sine tests is the displacement's second derivative below the crossover
//!    frequency and the accelerometer above it (at the paper's low frequencies the
//!    accelerometer's noise would dominate S4's 0.026 g); triangle tests use the
//!    accelerometer, which alone resolves the jumps at the ends of their reversal arcs.
//! 5. **Dissipative force** (Eq. 20): `¼[F(t) + F(T − t) − F(T/2 − t) − F(T/2 + t)]` against
//!    the same combination of velocities, which cancels inertial and elastic forces and any
//!    force offset. On sine tests the FIR-filtered points outside a window about each
//!    reversal are used, with the filter's smearing of the friction jump (its tail reaches
//!    0.3 s) removed as the fitted law predicts it, fit and correction alternating. On
//!    triangle tests, the constant-velocity portions: their unfiltered mean for the value at
//!    peak velocity, and for the law fit the filtered force where the plateau lies farther
//!    from the reversal arcs than the filter's reach. The value at peak velocity per test is
//!    the paper's Fig. 7.
//! 6. **Fits**: Eq. 21 as the paper did ([`PaperFit`]); the full law
//!    `F_μ + Cₑ|v|^α + a·e^(−b|v|)` (α free or held) by Levenberg–Marquardt on the
//!    instantaneous points of every test at the reference pressure, each test weighted
//!    equally; `F_μ` at every pressure with the rest of the law held; and `μₑ` as the slope of
//!    `F_μ` against the vertical load `F_z` ([`VerticalLoad`]). A parameter the tests cannot
//!    determine is reported as [`Parameter::NotIdentifiable`] with the reason (or, for the
//!    low-velocity term, left out as [`Parameter::Fixed`] at zero with the reason).
//! 7. **Global fit** ([`GlobalFit`]): every parameter at once from the instantaneous residual
//!    of Eq. 23 (plus the low-velocity term) over every test, started from the above; the
//!    two are compared and disagreements reported.
//!
//! **The oil-column impulse.** The recorded force rings at the oil-column frequency after
//! every reversal (§1.5). A low-pass removes the ringing but not its area, a net impulse of
//! `≈ A/ω` that lands where the acceleration and the displacement peak; on the paper's
//! records (ringing ≈ 30 % of the friction jump) it would add 1.5 % to S4's mass and 0.4 % to
//! T12's stiffness. It is fitted as a nuisance term: a signed unit impulse at every velocity
//! reversal through the same filter and mirror average (`ḡ`), with its size `β` free. The
//! dissipative combination of Eq. 20 cancels it by symmetry.
//!
//! # Any record
//!
//! [`identify_records`] fits `F = Mₑ·a + Kₑ·u + sign(v)·[F_μ + Cₑ|v|^α + a·e^(−b|v|)] + c_r`
//! to every record at once (one force offset `c_r` per record, which absorbs the offsets of
//! the force, displacement and accelerometer channels).
//!
//! 1. **Velocity**: the record's own channel, or the crossover estimate from `u` and `a`
//!    (2 Hz); samples slower than [`RecordSettings::min_speed_m_s`] (2 mm/s), where friction
//!    is set-valued and the sign of the estimate unsure, and the first and last 0.25 s are
//!    left out. A specimen's floors ([`TestRecord::with_floors`]) have had their base shear
//!    `Σ mᵢ·aᵢ` taken off the force.
//! 2. **Equation error** by separable least squares (variable projection): linear in
//!    `(Mₑ, Kₑ, F_μ, Cₑ, a, c_r)` for fixed `(α, b)`, solved exactly with `F_μ, Cₑ, a ≥ 0`,
//!    so the search is over `(α, b)` only (a grid, then Levenberg–Marquardt with Kaufman's
//!    Jacobian). The sensors' white noise, estimated per channel from the median of its
//!    sixth differences, is taken off `Σa²` and `Σu²` (corrected least squares): noise on a
//!    regressor biases least squares towards zero, 3 % on `Mₑ` for a low-amplitude white
//!    noise with a 0.003 g accelerometer.
//! 3. **Uncertainty**: a sandwich covariance whose middle is the batch-means long-run
//!    covariance of the scores (blocks of ≥ 400 samples, 6–30 blocks), intervals with
//!    Student's t for blocks − 1 degrees of freedom; correlations between the estimates;
//!    typed [`RecordWarning`]s where estimates trade off (|correlation| >
//!    [`MAX_CORRELATION`]), are imprecise, end on a bound or rest on few samples.
//!    Measured on 50 records with coloured force noise: every 95 % interval covers the
//!    truth in 90–100 % of them (`tests/any_record_coverage.rs`).
//! 4. **The law with its band**: `F_D(|v|)` with its pointwise 95 % band over the speeds
//!    the records reach ([`BandPoint`]): where `F_μ`, `Cₑ`, `α`, `a`, `b` trade off, the law
//!    is still determined.
//! 5. **Output error** as a check ([`OutputErrorFit`]): the model run forward (RK4 with
//!    exact stick-slip) under the recorded force, fitted to the measured displacement and
//!    acceleration from the equation error's estimate; both fits are reported and where they
//!    disagree a warning says so. It is not the final estimate: the force's own noise drives
//!    the simulated motion (1 kN of slow force noise moves a 0.95 MN/m table by 1 mm), so on
//!    the test records its standard errors are 1.5–6 times the equation error's.
//!
//! # Reading records
//!
//! This crate reads no files: it takes [`TestRecord`]s and [`system::SystemRecord`]s in
//! memory. Recorded CSV files through a column map, identification manifests and the
//! recorded-like data of motion scenarios are read by the application layer, the
//! `platen-app` crate (`platen_app::read_records`, `platen_app::read_system_inputs`),
//! which `platen identify` and Python's `platen.identify` share.
//!
//! # Conventions
//!
//! * SI units throughout; the unit is part of every public name (`sample_rate_hz`,
//!   `pressure_pa`, `force_n`). Forces are the total actuator force `F_A` and its parts, N;
//!   `u`, `v`, `a` are positive along `F_A`.
//! * Records are uniformly sampled; every filter is zero-phase (non-causal), applied to whole
//!   records before the cycle is cut out, so the analysed cycle is far from the record edges.
//! * **Uncertainties.** Standard errors come from the Jacobian at the optimum,
//!   `s²·(JᵀJ)⁻¹`, inflated by the number of consecutive samples that carry one independent
//!   observation (`f_s/(2f_c)` for data low-passed at `f_c`: residuals of filtered records are
//!   correlated, and counting every sample would understate the errors). Intervals are 95 %
//!   with Student's t for the independent degrees of freedom. Means over tests carry the
//!   standard error of the mean. They measure the scatter of the data about the model, not
//!   the model's own error.
//! * The final estimate ([`Identification::parameters`]) belongs to the *reference*
//!   pressure: the highest among the tests unless [`Settings::reference_pressure_pa`] says
//!   otherwise. The mass is averaged over every pressure.

#![warn(missing_docs)]

mod account;
pub mod anyrecord;
mod cycle;
mod dissipative;
mod elastic;
mod error;
mod estimate;
mod global;
mod groups;
mod identify;
mod inertial;
mod law;
mod lm;
mod paper_fit;
mod record;
mod regression;
mod result;
mod route;
mod settings;
pub mod summary;
pub mod system;
mod warning;
mod work;

pub use account::{identify_any, Identified, IdentifyOutput, MethodRequest, RecordAccount};
pub use anyrecord::result::{
    BandPoint, Correlations, EquationErrorFit, FitKind, FitUncertainty, FloorsReport,
    OutputErrorFit, RecordIdentification, RecordReport, RecordWarning,
};
pub use anyrecord::settings::{RecordSettings, ValidRecordSettings};
pub use anyrecord::{
    fit_agreement, identify_records, MAX_CORRELATION, MAX_RELATIVE_STD_ERROR,
    MIN_LOW_SPEED_FRACTION,
};
pub use cycle::{
    CycleInfo, HALF_CYCLE_MISMATCH, OUTSIDE_CYCLES_ENERGY, PLATEAU_TOLERANCE,
    TRIANGLE_PLATEAU_FRACTION,
};
pub use dissipative::{LOW_SPEED_M_S, MIN_SPEED_SPREAD};
pub use error::{IdentError, Result};
pub use estimate::{student_t_975, Estimate, Parameter};
pub use identify::identify;
pub use inertial::{MAX_MASS_RELATIVE_STD_ERROR, MIN_INERTIAL_TO_DISSIPATIVE};
pub use platen_model::{DissipativeLaw, IdentifiedKey};
pub use record::{Floors, TestKind, TestRecord, MIN_SAMPLES};
pub use result::{
    GlobalFit, Identification, LawReport, PaperFit, ParameterEstimates, PeakForce, PressureGroup,
    TestResult,
};
pub use route::{route, Method, Route};
pub use settings::{Settings, ValidSettings, VerticalLoad};
pub use summary::IdentificationSummary;
pub use warning::{Flag, LowVelocityOmission, StiffnessSource, ViscousLawProblem, Warning};
pub use work::{MAX_SINE_DISTORTION, MIN_PLATEAU_FRACTION};
