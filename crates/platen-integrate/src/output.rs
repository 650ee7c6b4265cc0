//! Output of a run: one [`Sample`] per input sample time, delivered to a [`SampleSink`].

use platen_model::{ForceTerms, Specimen, TableLimits};

/// The state of the platen and the decomposition of the actuator force at one output time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Zero-based index of the input sample.
    pub index: usize,
    /// Time, s (the input record's own time stamp).
    pub t_s: f64,
    /// Displacement, m.
    pub u_m: f64,
    /// Velocity, m/s.
    pub v_m_s: f64,
    /// Acceleration, m/s² (0 while stuck; the right-hand limit after an event).
    pub a_m_s2: f64,
    /// Force decomposition `F_I + F_E + F_D = F_A`, N. While stuck `F_D` is the static
    /// friction reaction `F_A − F_E(u)`.
    pub terms: ForceTerms,
    /// Whether the platen is stuck (friction holds it at rest).
    pub stuck: bool,
    /// The specimen's channels, for a run with a specimen.
    pub specimen: Option<SpecimenSample>,
    /// The table system's channels, for a closed-loop run.
    pub system: Option<SystemSample>,
}

/// The table system's channels at one output time (a closed-loop run, see
/// [`crate::forward_closed_loop`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SystemSample {
    /// The displacement command `u_ref`, m.
    pub command_u_m: f64,
    /// The drive the controller holds (`|d| ≤ 1`).
    pub drive: f64,
    /// The spool opening the valves' flow sees (clamped to `±1`).
    pub spool_opening: f64,
    /// Pressure difference `p_a − p_b`, Pa.
    pub delta_p_pa: f64,
    /// Cap-side chamber pressure (absolute), Pa.
    pub p_a_pa: f64,
    /// Rod-side chamber pressure (absolute), Pa.
    pub p_b_pa: f64,
    /// Flow of all valves into the cap-side chambers, m³/s (negative: out of them).
    pub flow_m3_s: f64,
    /// Supply pressure, Pa.
    pub supply_pressure_pa: f64,
}

/// The specimen's channels at one output time (see [`platen_model::Specimen`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpecimenSample {
    /// Base shear `B = Σmᵢ·(a + z̈ᵢ)`, N: the force the platen exerts on the specimen. The
    /// actuator force is `F_I + F_E + F_D + B`.
    pub base_shear_n: f64,
    /// Number of storeys (the first `storeys` entries of the arrays are used).
    pub storeys: usize,
    /// Storey displacements relative to the platen, m, bottom first.
    pub u_m: [f64; Specimen::MAX_STOREYS],
    /// Storey absolute accelerations `a + z̈ᵢ`, m/s², bottom first.
    pub a_m_s2: [f64; Specimen::MAX_STOREYS],
    /// Storey drifts `zᵢ − zᵢ₋₁`, m, bottom first.
    pub drift_m: [f64; Specimen::MAX_STOREYS],
    /// Whether the specimen yields (some storey carries a hysteresis): only then are
    /// `force_n`, `hysteretic_force_n` and `hysteretic_j` filled.
    pub hysteretic: bool,
    /// Storey restoring forces (the dashpot excluded), N, bottom first.
    pub force_n: [f64; Specimen::MAX_STOREYS],
    /// Storey hysteretic forces `q` (the restoring force less `a·k·δ`), N, bottom first.
    pub hysteretic_force_n: [f64; Specimen::MAX_STOREYS],
    /// Energy dissipated in hysteresis per storey since the start, J, bottom first.
    pub hysteretic_j: [f64; Specimen::MAX_STOREYS],
    /// Yield excursions per storey since the start, bottom first (bilinear: yield events;
    /// Bouc–Wen: passages of `|q|` beyond 90 % of `q_y`, once per direction of drift).
    pub yield_excursions: [usize; Specimen::MAX_STOREYS],
}

impl SpecimenSample {
    /// A sample of `storeys` storeys with base shear `base_shear_n` and every storey channel
    /// zero, to be filled in.
    pub fn new(storeys: usize, base_shear_n: f64) -> Self {
        const Z: [f64; Specimen::MAX_STOREYS] = [0.0; Specimen::MAX_STOREYS];
        Self {
            base_shear_n,
            storeys,
            u_m: Z,
            a_m_s2: Z,
            drift_m: Z,
            hysteretic: false,
            force_n: Z,
            hysteretic_force_n: Z,
            hysteretic_j: Z,
            yield_excursions: [0; Specimen::MAX_STOREYS],
        }
    }
}

/// Receives the samples of a run in time order.
pub trait SampleSink {
    /// Called once per output sample, in order of `index`.
    fn accept(&mut self, sample: &Sample);
}

impl<A: SampleSink, B: SampleSink> SampleSink for (A, B) {
    #[inline]
    fn accept(&mut self, sample: &Sample) {
        self.0.accept(sample);
        self.1.accept(sample);
    }
}

impl<S: SampleSink + ?Sized> SampleSink for &mut S {
    #[inline]
    fn accept(&mut self, sample: &Sample) {
        (**self).accept(sample);
    }
}

/// Receives the rows of a multi-axis run in time order, as [`SampleSink`] the samples of a
/// uniaxial one.
pub trait TableSink {
    /// Called once, before the first row, with the columns' names (each with its unit) and
    /// the number of rows to come (a hint).
    fn start(&mut self, names: &[String], samples: usize);
    /// Called once per output sample with its values in the columns' order.
    fn accept(&mut self, row: &[f64]);
}

impl<S: TableSink + ?Sized> TableSink for &mut S {
    #[inline]
    fn start(&mut self, names: &[String], samples: usize) {
        (**self).start(names, samples);
    }

    #[inline]
    fn accept(&mut self, row: &[f64]) {
        (**self).accept(row);
    }
}

/// Both sinks receive every row, the first first.
impl<A: TableSink, B: TableSink> TableSink for (A, B) {
    #[inline]
    fn start(&mut self, names: &[String], samples: usize) {
        self.0.start(names, samples);
        self.1.start(names, samples);
    }

    #[inline]
    fn accept(&mut self, row: &[f64]) {
        self.0.accept(row);
        self.1.accept(row);
    }
}

/// An absent sink receives nothing.
impl<S: TableSink> TableSink for Option<S> {
    #[inline]
    fn start(&mut self, names: &[String], samples: usize) {
        if let Some(s) = self {
            s.start(names, samples);
        }
    }

    #[inline]
    fn accept(&mut self, row: &[f64]) {
        if let Some(s) = self {
            s.accept(row);
        }
    }
}

/// A run kept in memory as the contract's columns.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trajectory {
    /// Time, s.
    pub t_s: Vec<f64>,
    /// Displacement, m.
    pub u_m: Vec<f64>,
    /// Velocity, m/s.
    pub v_m_s: Vec<f64>,
    /// Acceleration, m/s².
    pub a_m_s2: Vec<f64>,
    /// Actuator force `F_A`, N.
    pub force_n: Vec<f64>,
    /// Inertial force `F_I`, N.
    pub inertial_force_n: Vec<f64>,
    /// Elastic force `F_E`, N.
    pub elastic_force_n: Vec<f64>,
    /// Dissipative force `F_D`, N.
    pub dissipative_force_n: Vec<f64>,
    /// The specimen's columns, for a run with a specimen (`None` otherwise).
    pub specimen: Option<SpecimenColumns>,
    /// The table system's columns, for a closed-loop run (`None` otherwise).
    pub system: Option<SystemColumns>,
}

/// The table system's columns of a closed-loop run kept in memory (see [`SystemSample`]),
/// in the order of the CSV: [`SystemColumns::NAMES`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SystemColumns {
    /// Displacement command, m.
    pub command_u_m: Vec<f64>,
    /// Drive (`|d| ≤ 1`).
    pub drive: Vec<f64>,
    /// Spool opening (`±1`).
    pub spool_opening: Vec<f64>,
    /// `p_a − p_b`, Pa.
    pub delta_p_pa: Vec<f64>,
    /// Flow into the cap-side chambers, m³/s.
    pub flow_m3_s: Vec<f64>,
    /// Supply pressure, Pa.
    pub supply_pressure_pa: Vec<f64>,
    /// Cap-side pressure, Pa.
    pub cap_pressure_pa: Vec<f64>,
    /// Rod-side pressure, Pa.
    pub rod_pressure_pa: Vec<f64>,
}

impl SystemColumns {
    /// The columns, moved out in the order of [`SystemColumns::NAMES`].
    pub fn into_columns(self) -> [Vec<f64>; 8] {
        [
            self.command_u_m,
            self.drive,
            self.spool_opening,
            self.delta_p_pa,
            self.flow_m3_s,
            self.supply_pressure_pa,
            self.cap_pressure_pa,
            self.rod_pressure_pa,
        ]
    }

    /// The column names, in CSV order.
    pub const NAMES: [&'static str; 8] = [
        "command_u_m",
        "drive",
        "spool_opening",
        "delta_p_pa",
        "flow_m3_s",
        "supply_pressure_pa",
        "cap_pressure_pa",
        "rod_pressure_pa",
    ];

    /// The values of one sample in the order of [`SystemColumns::NAMES`].
    pub fn row(s: &SystemSample) -> [f64; 8] {
        [
            s.command_u_m,
            s.drive,
            s.spool_opening,
            s.delta_p_pa,
            s.flow_m3_s,
            s.supply_pressure_pa,
            s.p_a_pa,
            s.p_b_pa,
        ]
    }

    /// The column names and columns, in CSV order.
    pub fn columns(&self) -> Vec<(&'static str, &[f64])> {
        let cols: [&[f64]; 8] = [
            &self.command_u_m,
            &self.drive,
            &self.spool_opening,
            &self.delta_p_pa,
            &self.flow_m3_s,
            &self.supply_pressure_pa,
            &self.cap_pressure_pa,
            &self.rod_pressure_pa,
        ];
        Self::NAMES.iter().copied().zip(cols).collect()
    }

    /// The column `name`, if it is one of these.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns()
            .into_iter()
            .find_map(|(n, c)| (n == name).then_some(c))
    }

    fn accept(&mut self, s: &SystemSample) {
        let row = Self::row(s);
        for (col, v) in [
            &mut self.command_u_m,
            &mut self.drive,
            &mut self.spool_opening,
            &mut self.delta_p_pa,
            &mut self.flow_m3_s,
            &mut self.supply_pressure_pa,
            &mut self.cap_pressure_pa,
            &mut self.rod_pressure_pa,
        ]
        .into_iter()
        .zip(row)
        {
            col.push(v);
        }
    }
}

/// Builds `[concat!("storey1", suffix), …, concat!("storey12", suffix)]`.
macro_rules! storey_names {
    ($suffix:literal) => {
        [
            concat!("storey1", $suffix),
            concat!("storey2", $suffix),
            concat!("storey3", $suffix),
            concat!("storey4", $suffix),
            concat!("storey5", $suffix),
            concat!("storey6", $suffix),
            concat!("storey7", $suffix),
            concat!("storey8", $suffix),
            concat!("storey9", $suffix),
            concat!("storey10", $suffix),
            concat!("storey11", $suffix),
            concat!("storey12", $suffix),
        ]
    };
}

/// The specimen's columns of a run kept in memory (see [`SpecimenSample`]), in the order of
/// the CSV a specimen run writes: `base_shear_n`, `storey{i}_u_m` for every storey, then
/// `storey{i}_a_m_s2`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpecimenColumns {
    /// Base shear `B`, N (the force the platen exerts on the specimen).
    pub base_shear_n: Vec<f64>,
    /// Per storey, bottom first: displacement relative to the platen, m.
    pub u_m: Vec<Vec<f64>>,
    /// Per storey, bottom first: absolute acceleration, m/s².
    pub a_m_s2: Vec<Vec<f64>>,
    /// A specimen that yields, per storey (empty otherwise): the drift, m, the restoring force,
    /// N, the hysteretic force, N, and the hysteretic energy, J, in the order of
    /// [`SpecimenColumns::HYSTERETIC_NAMES`].
    pub hysteretic: [Vec<Vec<f64>>; 4],
}

impl SpecimenColumns {
    /// The name of the base-shear column.
    pub const BASE_SHEAR_NAME: &'static str = "base_shear_n";
    /// `storey{i}_u_m` for `i = 1…`[`Specimen::MAX_STOREYS`] (index `i − 1`).
    pub const STOREY_U_NAMES: [&'static str; Specimen::MAX_STOREYS] = storey_names!("_u_m");
    /// `storey{i}_a_m_s2` for `i = 1…`[`Specimen::MAX_STOREYS`] (index `i − 1`).
    pub const STOREY_A_NAMES: [&'static str; Specimen::MAX_STOREYS] = storey_names!("_a_m_s2");
    /// A yielding specimen's columns, after the accelerations: `storey{i}_drift_m`,
    /// `storey{i}_force_n`, `storey{i}_hysteretic_force_n` and `storey{i}_hysteretic_j` for
    /// every storey, each kind in turn.
    pub const HYSTERETIC_NAMES: [[&'static str; Specimen::MAX_STOREYS]; 4] = [
        storey_names!("_drift_m"),
        storey_names!("_force_n"),
        storey_names!("_hysteretic_force_n"),
        storey_names!("_hysteretic_j"),
    ];

    /// Empty columns for a specimen of `storeys` storeys.
    pub fn new(storeys: usize) -> Self {
        Self {
            base_shear_n: Vec::new(),
            u_m: vec![Vec::new(); storeys],
            a_m_s2: vec![Vec::new(); storeys],
            hysteretic: Default::default(),
        }
    }

    /// Number of storeys.
    pub fn storeys(&self) -> usize {
        self.u_m.len()
    }

    /// The column names and columns, in the CSV's order: `base_shear_n`, `storey1_u_m`…,
    /// `storey1_a_m_s2`….
    ///
    /// ```
    /// use platen_integrate::SpecimenColumns;
    /// let c = SpecimenColumns::new(2);
    /// let names: Vec<&str> = c.columns().iter().map(|(name, _)| *name).collect();
    /// assert_eq!(
    ///     names,
    ///     ["base_shear_n", "storey1_u_m", "storey2_u_m", "storey1_a_m_s2", "storey2_a_m_s2"]
    /// );
    /// ```
    pub fn columns(&self) -> Vec<(&'static str, &[f64])> {
        let mut out = vec![(Self::BASE_SHEAR_NAME, self.base_shear_n.as_slice())];
        out.extend(
            Self::STOREY_U_NAMES
                .iter()
                .copied()
                .zip(self.u_m.iter().map(Vec::as_slice)),
        );
        out.extend(
            Self::STOREY_A_NAMES
                .iter()
                .copied()
                .zip(self.a_m_s2.iter().map(Vec::as_slice)),
        );
        for (names, cols) in Self::HYSTERETIC_NAMES.iter().zip(&self.hysteretic) {
            out.extend(names.iter().copied().zip(cols.iter().map(Vec::as_slice)));
        }
        out
    }

    /// The column `name`, if it is one of these.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns()
            .into_iter()
            .find_map(|(n, c)| (n == name).then_some(c))
    }

    fn accept(&mut self, s: &SpecimenSample) {
        self.base_shear_n.push(s.base_shear_n);
        for (col, &z) in self.u_m.iter_mut().zip(&s.u_m[..s.storeys]) {
            col.push(z);
        }
        for (col, &a) in self.a_m_s2.iter_mut().zip(&s.a_m_s2[..s.storeys]) {
            col.push(a);
        }
        if s.hysteretic {
            let n = s.storeys;
            let values = [
                &s.drift_m,
                &s.force_n,
                &s.hysteretic_force_n,
                &s.hysteretic_j,
            ];
            for (cols, v) in self.hysteretic.iter_mut().zip(values) {
                cols.resize_with(n, Vec::new);
                for (col, &x) in cols.iter_mut().zip(&v[..n]) {
                    col.push(x);
                }
            }
        }
    }
}

impl Trajectory {
    /// An empty trajectory with room for `n` samples.
    pub fn with_capacity(n: usize) -> Self {
        let v = || Vec::with_capacity(n);
        Self {
            t_s: v(),
            u_m: v(),
            v_m_s: v(),
            a_m_s2: v(),
            force_n: v(),
            inertial_force_n: v(),
            elastic_force_n: v(),
            dissipative_force_n: v(),
            specimen: None,
            system: None,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Whether no sample has been stored.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Column names of the contract, in the order of [`Trajectory::columns`].
    pub const COLUMN_NAMES: [&'static str; 8] = [
        "t_s",
        "u_m",
        "v_m_s",
        "a_m_s2",
        "force_n",
        "inertial_force_n",
        "elastic_force_n",
        "dissipative_force_n",
    ];

    /// The columns in the order of [`Trajectory::COLUMN_NAMES`].
    pub fn columns(&self) -> [&[f64]; 8] {
        [
            &self.t_s,
            &self.u_m,
            &self.v_m_s,
            &self.a_m_s2,
            &self.force_n,
            &self.inertial_force_n,
            &self.elastic_force_n,
            &self.dissipative_force_n,
        ]
    }
}

impl Trajectory {
    /// The columns in the order of [`Trajectory::COLUMN_NAMES`], moved out (no copy): for a
    /// front end that hands them on, as Python's NumPy arrays. The specimen's columns
    /// ([`Trajectory::specimen`]) are not among them.
    ///
    /// ```
    /// use platen_integrate::Trajectory;
    /// let t = Trajectory { t_s: vec![0.0, 0.5], u_m: vec![1.0, 2.0], ..Trajectory::default() };
    /// let moved = t.clone().into_columns();
    /// assert_eq!(moved.iter().map(Vec::as_slice).collect::<Vec<_>>(), t.columns());
    /// ```
    pub fn into_columns(self) -> [Vec<f64>; 8] {
        [
            self.t_s,
            self.u_m,
            self.v_m_s,
            self.a_m_s2,
            self.force_n,
            self.inertial_force_n,
            self.elastic_force_n,
            self.dissipative_force_n,
        ]
    }
}

impl SampleSink for Trajectory {
    #[inline]
    fn accept(&mut self, s: &Sample) {
        self.t_s.push(s.t_s);
        self.u_m.push(s.u_m);
        self.v_m_s.push(s.v_m_s);
        self.a_m_s2.push(s.a_m_s2);
        self.force_n.push(s.terms.actuator_n);
        self.inertial_force_n.push(s.terms.inertial_n);
        self.elastic_force_n.push(s.terms.elastic_n);
        self.dissipative_force_n.push(s.terms.dissipative_n);
        if let Some(sp) = &s.specimen {
            self.specimen
                .get_or_insert_with(|| SpecimenColumns::new(sp.storeys))
                .accept(sp);
        }
        if let Some(sy) = &s.system {
            self.system
                .get_or_insert_with(SystemColumns::default)
                .accept(sy);
        }
    }
}

/// The largest absolute value of a quantity and when it occurred.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Peak {
    /// The signed value with the largest magnitude.
    pub value: f64,
    /// Its time, s.
    pub t_s: f64,
}

impl Peak {
    #[inline]
    fn update(&mut self, value: f64, t_s: f64) {
        if value.abs() > self.value.abs() {
            self.value = value;
            self.t_s = t_s;
        }
    }
}

/// Peaks of a run accumulated as samples stream past (memory does not grow with length).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Peaks {
    /// Samples seen.
    pub samples: usize,
    /// First and last time seen, s.
    pub span_s: (f64, f64),
    /// Peak displacement, m.
    pub u_m: Peak,
    /// Peak velocity, m/s.
    pub v_m_s: Peak,
    /// Peak acceleration, m/s².
    pub a_m_s2: Peak,
    /// Peak actuator force, N.
    pub force_n: Peak,
    /// Samples at which the platen was stuck.
    pub stuck_samples: usize,
    /// Peak base shear, N (runs with a specimen).
    pub base_shear_n: Peak,
    /// Peak storey drifts `zᵢ − zᵢ₋₁`, m, bottom first (the first `storeys` are used).
    pub drift_m: [Peak; Specimen::MAX_STOREYS],
    /// Storeys of the specimen (0 without one).
    pub storeys: usize,
    /// Each storey's drift at the last sample, m (the residual drift of a run that has come to
    /// rest).
    pub last_drift_m: [f64; Specimen::MAX_STOREYS],
    /// Whether the specimen yields: only then are `hysteretic_j` and `yield_excursions` set.
    pub hysteretic: bool,
    /// Each storey's hysteretic energy at the last sample, J.
    pub hysteretic_j: [f64; Specimen::MAX_STOREYS],
    /// Each storey's yield excursions by the last sample.
    pub yield_excursions: [usize; Specimen::MAX_STOREYS],
}

impl SampleSink for Peaks {
    #[inline]
    fn accept(&mut self, s: &Sample) {
        if self.samples == 0 {
            self.span_s.0 = s.t_s;
        }
        self.samples += 1;
        self.span_s.1 = s.t_s;
        self.u_m.update(s.u_m, s.t_s);
        self.v_m_s.update(s.v_m_s, s.t_s);
        self.a_m_s2.update(s.a_m_s2, s.t_s);
        self.force_n.update(s.terms.actuator_n, s.t_s);
        self.stuck_samples += usize::from(s.stuck);
        if let Some(sp) = &s.specimen {
            self.storeys = sp.storeys;
            self.base_shear_n.update(sp.base_shear_n, s.t_s);
            for (peak, &d) in self.drift_m.iter_mut().zip(&sp.drift_m[..sp.storeys]) {
                peak.update(d, s.t_s);
            }
            self.last_drift_m = sp.drift_m;
            if sp.hysteretic {
                self.hysteretic = true;
                self.hysteretic_j = sp.hysteretic_j;
                self.yield_excursions = sp.yield_excursions;
            }
        }
    }
}

/// A table limit that a run exceeds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exceedance {
    /// Which limit: `"stroke"`, `"velocity"`, `"acceleration"` or `"force"`.
    pub quantity: &'static str,
    /// The run's peak (signed), in SI units.
    pub peak: f64,
    /// The limit, in SI units.
    pub limit: f64,
    /// When the peak occurred, s.
    pub t_s: f64,
}

impl Peaks {
    /// The limits of `limits` that these peaks exceed.
    pub fn exceedances(&self, limits: &TableLimits) -> Vec<Exceedance> {
        [
            ("stroke", self.u_m, limits.stroke_m),
            ("velocity", self.v_m_s, limits.velocity_m_s),
            ("acceleration", self.a_m_s2, limits.acceleration_m_s2),
            ("force", self.force_n, limits.force_n),
        ]
        .into_iter()
        .filter(|(_, peak, limit)| peak.value.abs() > *limit)
        .map(|(quantity, peak, limit)| Exceedance {
            quantity,
            peak: peak.value,
            limit,
            t_s: peak.t_s,
        })
        .collect()
    }
}
