//! The per-test working state of an identification: one analysed cycle, its Eq. 20 points
//! and the estimates made from it.

use platen_model::DissipativeLaw;
use platen_signal::ZeroPhaseFilter;

use crate::cycle::{interp, Analysed, PLATEAU_TOLERANCE};
use crate::estimate::Estimate;
use crate::law::LawPoints;
use crate::record::{TestKind, TestRecord};
use crate::result::{PeakForce, TestResult};
use crate::settings::ValidSettings;
use crate::warning::{Flag, Warning};

/// A sine test whose displacement has more than 5 % harmonic distortion (harmonics 2–7 over
/// the fundamental) is "distorted" (paper: S12) and not used for the mass. A controller
/// tracking a sine leaves well under 1 %; the paper's rounded triangles have 9 %, a sharp
/// triangle 12 %.
pub const MAX_SINE_DISTORTION: f64 = 0.05;

/// A triangle test needs constant velocity over at least a quarter of its cycle to support a
/// stiffness estimate (the paper's triangles: 70 %–90 %).
pub const MIN_PLATEAU_FRACTION: f64 = 0.25;

/// The peak velocity of a sine test is read over ±T/40 about its peak-velocity instant, where
/// `|cos| > 0.988`: the speed is within 1.2 % of its peak and ≈ 1/20 of the cycle is averaged.
const PEAK_WINDOW: f64 = 1.0 / 40.0;

/// Per-test working state.
pub(crate) struct Work {
    pub(crate) name: String,
    pub(crate) an: Analysed,
    pub(crate) kind: TestKind,
    pub(crate) kind_given: bool,
    pub(crate) pressure: Option<f64>,
    pub(crate) group: usize,
    /// Eq. 20 on the grid, `j ∈ [0, n/4)`: velocity, force, usable, within the peak window,
    /// and the smearing correction (subtracted from the force).
    pub(crate) odd_v: Vec<f64>,
    pub(crate) odd_f: Vec<f64>,
    pub(crate) odd_usable: Vec<bool>,
    pub(crate) odd_peak: Vec<bool>,
    pub(crate) odd_corr: Vec<f64>,
    /// The smearing correction over the whole record (for the global fit).
    pub(crate) rec_corr: Vec<f64>,
    /// Triangle tests: the point for the law fit (see [`Work::dissipative`]).
    pub(crate) law_point: Option<(f64, f64)>,
    pub(crate) peak: Option<PeakForce>,
    pub(crate) peak_velocity: f64,
    pub(crate) peak_acceleration: f64,
    pub(crate) flags: Vec<Flag>,
    pub(crate) stiffness: Option<Estimate>,
    pub(crate) mass: Option<Estimate>,
    pub(crate) used_for_stiffness: bool,
    pub(crate) used_for_mass: bool,
    pub(crate) elastic_curve: Vec<[f64; 2]>,
    pub(crate) inertial_curve: Vec<[f64; 2]>,
    pub(crate) cutoff_factor: f64,
}

/// Mirror-pair averages of the 4×-fundamental channels.
#[derive(Default)]
pub(crate) struct Pairs {
    pub(crate) u: Vec<f64>,
    pub(crate) a: Vec<f64>,
    pub(crate) f: Vec<f64>,
    pub(crate) g: Vec<f64>,
}

impl Pairs {
    /// The points `(x, y − β·ḡ)`: a response `y` against `x` with the fitted reversal
    /// impulses `β·ḡ` removed.
    pub(crate) fn curve(&self, x: &[f64], y: &[f64], beta: f64) -> Vec<[f64; 2]> {
        x.iter()
            .zip(y)
            .zip(&self.g)
            .map(|((x, y), g)| [*x, y - beta * g])
            .collect()
    }
}

/// Mirror pairs of Eq. 16–19 on a grid of `n` points: `(t, T/2 − t)` for `0 < t ≤ T/4` and
/// `(t, 3T/2 − t)` for `T/2 < t ≤ 3T/4`.
pub(crate) fn mirror_pairs(n: usize) -> impl Iterator<Item = (usize, usize)> {
    let q = n / 4;
    (1..=q)
        .map(move |j| (j, 2 * q - j))
        .chain((2 * q + 1..=3 * q).map(move |j| (j, 6 * q - j)))
}

impl Work {
    pub(crate) fn new(rec: &TestRecord, an: Analysed, settings: &ValidSettings) -> Self {
        let detected = an.info.detected_kind;
        let (kind, kind_given) = match rec.kind() {
            Some(k) => (k, true),
            None => (detected, false),
        };
        let mut flags = Vec::new();
        if kind != detected {
            flags.push(Flag::KindMismatch { detected });
        }
        if an.info.full_cycles < 2 {
            flags.push(Flag::SingleCycle);
        }
        let peak_acceleration = an.a4.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        let mut w = Work {
            name: rec.name().to_owned(),
            kind,
            kind_given,
            pressure: rec.pressure_pa(),
            group: 0,
            odd_v: Vec::new(),
            odd_f: Vec::new(),
            odd_usable: Vec::new(),
            odd_peak: Vec::new(),
            odd_corr: Vec::new(),
            rec_corr: Vec::new(),
            law_point: None,
            peak: None,
            peak_velocity: an.plateau_speed,
            peak_acceleration,
            flags,
            stiffness: None,
            mass: None,
            used_for_stiffness: false,
            used_for_mass: false,
            elastic_curve: Vec::new(),
            inertial_curve: Vec::new(),
            cutoff_factor: settings.inertial_cutoff_factor,
            an,
        };
        w.dissipative();
        w.update_peak();
        if w.kind == TestKind::Sine && w.an.info.harmonic_distortion > MAX_SINE_DISTORTION {
            w.flags.push(Flag::Distorted {
                harmonic_distortion: w.an.info.harmonic_distortion,
            });
        }
        if w.kind == TestKind::Triangle && w.an.info.plateau_fraction < MIN_PLATEAU_FRACTION {
            w.flags.push(Flag::ShortPlateau {
                fraction: w.an.info.plateau_fraction,
            });
        }
        w
    }

    /// Grid points of a triangle test (all false unless `wanted`) deep in a plateau: the run
    /// of plateau points through them extends `margin` on both sides, i.e. the run ending at
    /// `j + margin` is at least `2·margin + 1` long.
    fn deep_in_plateau(&self, margin: usize, wanted: bool) -> Vec<bool> {
        let n = self.an.n;
        if !wanted {
            return vec![false; n];
        }
        let on: Vec<bool> = (0..n).map(|j| self.on_plateau(j)).collect();
        let mut run = 0usize;
        let mut left = vec![0usize; n];
        for k in 0..2 * n {
            run = if on[k % n] { run + 1 } else { 0 };
            left[k % n] = run;
        }
        (0..n)
            .map(|j| left[(j + margin) % n] > 2 * margin)
            .collect()
    }

    pub(crate) fn on_plateau(&self, j: usize) -> bool {
        let v = self.an.plateau_speed;
        (self.an.vu8[j].abs() - v).abs() <= PLATEAU_TOLERANCE * v
    }

    /// Eq. 20 (both branches, Eq. 14 and 15 combined):
    /// `F_D(v̂) = ¼[F(t) + F(T−t) − F(T/2−t) − F(T/2+t)]`, `0 ≤ t < T/4`, which cancels the
    /// inertial and elastic forces (odd about `t = 0`, even about `T/4`) and any force offset.
    ///
    /// Sine tests use the force through the dissipative FIR, and the points outside the
    /// reversal window. Triangle tests use only their constant-velocity portions (§3). Their
    /// value at peak velocity is the plateau mean of the unfiltered force: averaged over the
    /// plateau, the oil-column ringing, the valve tone and the noise cancel, while the 8 Hz
    /// filter's one-second reach would carry the reversal arcs' inertial transients
    /// (`Mₑ·A_r`, 3.5 MN on T12) into the plateau. For the law fit a triangle test gives one
    /// point from the filtered force, averaged over the part of the plateau farther from the
    /// arcs than the filter's 0.5 % settling time (0.33 s), if any: there neither the arcs'
    /// transients nor the ringing's net impulse (which the plateau mean does not cancel, and
    /// which would tilt the law by 1–2 % through the fastest triangles) reach.
    fn dissipative(&mut self) {
        let an = &self.an;
        let n = an.n;
        let q = n / 4;
        let step_s = an.info.period_s / n as f64;
        let settle = an.info.reversal_window_s;
        let peak_j = ((n as f64 * PEAK_WINDOW).ceil() as usize).max(1);
        let force = match self.kind {
            TestKind::Sine => &an.f8,
            TestKind::Triangle => &an.f,
        };
        // Triangles: grid points whose neighbours within the filter's main lobe, 1/(2·f_c),
        // are all on the plateau; the velocity that marks the plateau comes through the
        // 8 Hz filter, which starts bending that far ahead of the true reversal arc.
        let margin = (0.5 / an.info.dissipative_cutoff_hz / step_s).ceil() as usize;
        let triangle = self.kind == TestKind::Triangle;
        let deep = self.deep_in_plateau(margin, triangle);
        let far_margin = (an.arc_reach_s / step_s).ceil() as usize;
        let far = self.deep_in_plateau(far_margin, triangle && 2 * far_margin < n);
        let (mut lv, mut lf, mut ln) = (0.0, 0.0, 0usize);
        let mut odd_v = Vec::with_capacity(q);
        let mut odd_f = Vec::with_capacity(q);
        let mut usable = Vec::with_capacity(q);
        let mut peak = Vec::with_capacity(q);
        for j in 0..q {
            let idx = [j, (n - j) % n, 2 * q - j, 2 * q + j];
            odd_v.push(0.25 * (an.v8[idx[0]] + an.v8[idx[1]] - an.v8[idx[2]] - an.v8[idx[3]]));
            odd_f.push(0.25 * (force[idx[0]] + force[idx[1]] - force[idx[2]] - force[idx[3]]));
            let ok = match self.kind {
                TestKind::Sine => (q - j) as f64 * step_s >= settle,
                TestKind::Triangle => idx.iter().all(|&i| deep[i]),
            };
            usable.push(ok);
            peak.push(
                ok && match self.kind {
                    TestKind::Sine => j <= peak_j,
                    TestKind::Triangle => true,
                },
            );
            if self.kind == TestKind::Triangle && idx.iter().all(|&i| far[i]) {
                lv += odd_v[j];
                lf += 0.25 * (an.f8[idx[0]] + an.f8[idx[1]] - an.f8[idx[2]] - an.f8[idx[3]]);
                ln += 1;
            }
        }
        self.law_point = (ln > 0).then(|| (lv / ln as f64, lf / ln as f64));
        self.odd_corr = vec![0.0; q];
        self.odd_v = odd_v;
        self.odd_f = odd_f;
        self.odd_usable = usable;
        self.odd_peak = peak;
    }

    /// The dissipative force at peak velocity: the mean of the (corrected) Eq. 20 points in
    /// the peak window (sine) or on the plateau (triangle).
    pub(crate) fn update_peak(&mut self) {
        let (mut pv, mut pf, mut pn) = (0.0, 0.0, 0usize);
        for j in 0..self.odd_v.len() {
            if self.odd_peak[j] {
                pv += self.odd_v[j];
                pf += self.odd_f[j] - self.odd_corr[j];
                pn += 1;
            }
        }
        self.peak = (pn > 0).then(|| PeakForce {
            velocity_m_s: pv / pn as f64,
            force_n: pf / pn as f64,
        });
        if let Some(p) = self.peak {
            self.peak_velocity = p.velocity_m_s;
        }
    }

    /// The (corrected) Eq. 20 points with weights that give every test the same total weight.
    /// A triangle test is one point: the mean over its plateau.
    pub(crate) fn weighted_points(&self) -> LawPoints {
        let mut p = LawPoints::default();
        if self.kind == TestKind::Triangle {
            if let Some((v, f)) = self.law_point {
                p.push(v, f, 1.0);
            }
            return p;
        }
        let count = self.odd_usable.iter().filter(|u| **u).count();
        let w = 1.0 / count.max(1) as f64;
        for j in 0..self.odd_v.len() {
            if self.odd_usable[j] {
                p.push(self.odd_v[j], self.odd_f[j] - self.odd_corr[j], w);
            }
        }
        p
    }

    /// The filter's smearing of the friction jump, as `law` predicts it. With the law's
    /// dissipative force `m(t) = sign(v)·D(|v|)` of the (unfiltered) velocity channel,
    /// `δ = L(m) − m(v̄)` is what the low-pass `L` adds to a force that follows the law, beyond
    /// the law at the filtered velocity `v̄` the points are plotted against. Removing it from
    /// the data lets the filtered points stand for `D(|v̄|)` up to the reversal window rather
    /// than to the filter's 0.3 s tail. Sine tests only: triangle tests use only the parts of
    /// their plateaus that the smearing does not reach.
    pub(crate) fn correct_smearing(&mut self, law: &DissipativeLaw) {
        if self.kind == TestKind::Triangle {
            return;
        }
        let an = &self.an;
        let signed = |v: f64| law.smooth_signed_n(v);
        let m: Vec<f64> = an.rec_v.iter().map(|&v| signed(v)).collect();
        let Ok(lm) = an.fir.apply(&m) else { return };
        let delta: Vec<f64> = lm
            .iter()
            .zip(&an.rec_v8)
            .map(|(l, &v)| l - signed(v))
            .collect();
        let n = an.n;
        let q = n / 4;
        let at = |j: usize| interp(&delta, an.grid_start + j as f64 * an.grid_step);
        for j in 0..q {
            let idx = [j, (n - j) % n, 2 * q - j, 2 * q + j];
            self.odd_corr[j] = 0.25 * (at(idx[0]) + at(idx[1]) - at(idx[2]) - at(idx[3]));
        }
        self.rec_corr = delta;
    }

    /// Averages `(ū, ā, F̄, ḡ)` over the mirror pairs selected by `keep` (`ḡ`: the reversal
    /// impulses through the low-pass).
    pub(crate) fn pairs(&self, keep: impl Fn(usize, usize) -> bool) -> Pairs {
        let an = &self.an;
        let mut p = Pairs::default();
        for (j, m) in mirror_pairs(an.n) {
            if keep(j, m) {
                p.u.push(0.5 * (an.u4[j] + an.u4[m]));
                p.a.push(0.5 * (an.a4[j] + an.a4[m]));
                p.f.push(0.5 * (an.f4[j] + an.f4[m]));
                p.g.push(0.5 * (an.g4[j] + an.g4[m]));
            }
        }
        p
    }

    /// Grid points per independent sample of the 4×-fundamental low-passed data:
    /// `(n/T)/(2·f_c) = n/(2·factor)`.
    pub(crate) fn correlation(&self) -> f64 {
        self.an.n as f64 / (2.0 * self.cutoff_factor)
    }

    /// A warning for each of the test's flags.
    pub(crate) fn flag_warnings(&self) -> impl Iterator<Item = Warning> + '_ {
        self.flags.iter().map(|f| Warning::FlaggedTest {
            test: self.name.clone(),
            flag: f.clone(),
        })
    }

    pub(crate) fn into_result(self) -> TestResult {
        TestResult {
            name: self.name,
            kind: self.kind,
            kind_given: self.kind_given,
            pressure_pa: self.pressure,
            cycle: self.an.info,
            peak_velocity_m_s: self.peak_velocity,
            peak_acceleration_m_s2: self.peak_acceleration,
            stiffness: self.stiffness,
            effective_mass: self.mass,
            peak_dissipative: self.peak,
            used_for_stiffness: self.used_for_stiffness,
            used_for_mass: self.used_for_mass,
            flags: self.flags,
            elastic_curve: self.elastic_curve,
            inertial_curve: self.inertial_curve,
            dissipative_curve: (0..self.odd_v.len())
                .filter(|&j| self.odd_usable[j])
                .map(|j| [self.odd_v[j], self.odd_f[j] - self.odd_corr[j]])
                .collect(),
        }
    }
}
