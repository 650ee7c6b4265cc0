//! Frictionless tables (`F_μ = a = 0`, so the static threshold `F_s = 0`) carrying a specimen
//! (issue 26): every run on finite input finishes (the specimen stepper's creep, and the
//! closed loop's, pass through `v = 0` instead of stalling the event loop with "4097 events"),
//! and the linear case (`α = 1`) meets the closed-form 3-DOF frequency response, solved here
//! with plain complex arithmetic in absolute coordinates (the integrator works in relative
//! ones).

use std::f64::consts::PI;

use platen_integrate::{
    forward_closed_loop, forward_rk4_specimen, forward_specimen, Dopri5Settings, EventKind,
    ForceRecord, LoopMethod, LoopRun, Method, Motion, Rk4, RunStats, Sample, SampleSink, State,
    Step, Stepping, Trajectory,
};
use platen_model::{IdentifiedModel, Specimen, Storey};

mod common;
use common::{frictionless, sine_fit, sine_record, M_KG, RATE_HZ};

/// The two storeys of [`frame`]: mass, kg, stiffness, N/m, damping, N·s/m (bottom first).
const STOREYS: [(f64, f64, f64); 2] = [
    (30e3, 27_083_177.88, 86_208.43),
    (25e3, 19_345_127.06, 61_577.45),
];

/// The 55 t two-storey frame of `scenarios/specimen/frame-forward.json` (fixed-base modes
/// 3.0 and 7.06 Hz, stiffness-proportional damping, 3 % in the first mode).
fn frame() -> Specimen {
    Specimen::new(
        STOREYS
            .iter()
            .map(|&(mass_kg, stiffness_n_per_m, damping_n_s_per_m)| Storey {
                mass_kg,
                stiffness_n_per_m,
                damping_n_s_per_m,
            })
            .collect(),
    )
    .unwrap()
}

/// The specimen run from rest over the whole record, RK4 at `steps_per_sample`; a failure is
/// a test failure with its message.
fn run_specimen(
    model: &IdentifiedModel,
    specimen: &Specimen,
    record: &ForceRecord,
    steps_per_sample: u32,
    what: &str,
) -> (Trajectory, RunStats) {
    let mut out = Trajectory::with_capacity(record.len());
    let stats = forward_rk4_specimen(
        model,
        specimen,
        record,
        Rk4::with_steps_per_sample(steps_per_sample).unwrap(),
        State::default(),
        record.len(),
        &mut out,
    )
    .unwrap_or_else(|e| panic!("{what}: {e}"));
    (out, stats)
}

/// A grid of frictionless models (α ∈ {0.2, 0.5, 1}, K ∈ {0, 1e3, 1.266e6} N/m, C = 44.58e3)
/// with the two-storey frame on the platen, under a 1.5 Hz sine force of 1e-6 N, 1 N and
/// 1e5 N and under a force that jumps between ±amplitude and exact zeros every 3 samples,
/// RK4 at one step per sample: every run reaches the end of the record. The small forces
/// keep the net force near zero, where `α < 1` creeps through `v = 0`: these runs stalled
/// the event loop ("4097 stick-slip events inside one step", first at α = 0.5, K = 1e3,
/// 1e-6 N, t = 1.0 s). Nothing holds a frictionless platen, so rest lasts no time, and the
/// energy balance (actuator work against the platen's and the storeys' kinetic, elastic and
/// dissipated energy) closes: within 1e-5 of the largest energy flow under the sines
/// (measured: at most 8.7e-7), within 1e-3 under the jumps, whose corners cost RK4 accuracy
/// with or without creep (measured: at most 3.2e-4 at α = 0.2, 3.9e-5 at α = 1, where the
/// law is linear and nothing creeps).
#[test]
fn a_frictionless_platen_with_a_specimen_runs_to_the_end() {
    let specimen = frame();
    let mut worst_residual = std::collections::BTreeMap::new();
    for alpha in [0.2, 0.5, 1.0] {
        for k in [0.0, 1e3, 1.266e6] {
            let model = frictionless(k, 44.58e3, alpha);
            for amplitude_n in [1e-6, 1.0, 1e5] {
                let sine = sine_record(amplitude_n, 2.0 * PI * 1.5, 2.0);
                let jumps = (0..2049)
                    .map(|j| amplitude_n * [1.0, 0.0, -1.0, -0.5, 0.0, 0.25][(j / 3) % 6])
                    .collect();
                let jumps = ForceRecord::from_rate(RATE_HZ, jumps).unwrap();
                for (name, record) in [("sine", sine), ("jumps", jumps)] {
                    let what = format!("α = {alpha}, K = {k} N/m, {name} of {amplitude_n} N");
                    let (out, stats) = run_specimen(&model, &specimen, &record, 1, &what);
                    let residual = stats.energy.relative_residual();
                    eprintln!(
                        "{what}: {} reversals, {} stops, stick time {:.1e} s, energy \
                         residual {residual:.1e} (relative)",
                        stats.reversals, stats.stick_events, stats.stick_time_s
                    );
                    assert_eq!(out.t_s.len(), record.len(), "{what}: ran to the end");
                    assert!(
                        out.u_m.iter().chain(&out.v_m_s).all(|x| x.is_finite()),
                        "{what}"
                    );
                    assert!(stats.stick_time_s < 1e-12, "{what}: {stats:?}");
                    let bound = if name == "sine" { 1e-5 } else { 1e-3 };
                    assert!(residual.abs() < bound, "{what}: {stats:?}");
                    let worst = worst_residual.entry(name).or_insert(0.0f64);
                    *worst = worst.max(residual.abs());
                }
            }
        }
    }
    eprintln!("worst relative energy residuals: {worst_residual:?}");
}

/// A complex number, for the frequency response.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// Solves the 3×3 complex system `A·x = b` by Gaussian elimination with partial pivoting.
fn solve3(mut a: [[Complex; 3]; 3], mut b: [Complex; 3]) -> [Complex; 3] {
    for col in 0..3 {
        let pivot = (col..3)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (pivot_row, pivot_b) = (a[col], b[col]);
        for row in col + 1..3 {
            let factor = a[row][col].div(pivot_row[col]);
            for (entry, &above) in a[row].iter_mut().zip(&pivot_row).skip(col) {
                *entry = entry.sub(factor.mul(above));
            }
            b[row] = b[row].sub(factor.mul(pivot_b));
        }
    }
    let mut x = [Complex::new(0.0, 0.0); 3];
    for row in (0..3).rev() {
        let sum = (row + 1..3).fold(b[row], |sum, c| sum.sub(a[row][c].mul(x[c])));
        x[row] = sum.div(a[row][row]);
    }
    x
}

/// The steady-state complex amplitudes `X = (K − ω²M + iωC)⁻¹·F` of the platen and the two
/// floors (absolute displacements) under a force of complex amplitude `f0` on the platen:
/// the platen `M_KG` on its spring `k` and dashpot `c` to the ground, storey 1 between the
/// platen and floor 1, storey 2 between the floors.
fn frequency_response(k: f64, c: f64, omega: f64, f0: f64) -> [Complex; 3] {
    let [(m1, k1, c1), (m2, k2, c2)] = STOREYS;
    // The dynamic stiffness of a spring-dashpot pair, and of a mass.
    let link = |k: f64, c: f64| Complex::new(k, omega * c);
    let mass = |m: f64| Complex::new(-omega * omega * m, 0.0);
    let zero = Complex::new(0.0, 0.0);
    let (l0, l1, l2) = (link(k, c), link(k1, c1), link(k2, c2));
    let a = [
        [l0.add(l1).add(mass(M_KG)), zero.sub(l1), zero],
        [zero.sub(l1), l1.add(l2).add(mass(m1)), zero.sub(l2)],
        [zero, zero.sub(l2), l2.add(mass(m2))],
    ];
    solve3(a, [Complex::new(f0, 0.0), zero, zero])
}

/// `F_μ = a = 0`, α = 1 and the frame on the platen: a linear 3-DOF system. Under
/// `F₀ sin ωt` its steady state is `Im(X·e^(iωt))` with `X` from the 3×3 complex system
/// `(K − ω²M + iωC)·X = F` (here `F₀` = 100 kN at 1 Hz, K = 1.266e6 N/m, C = 0.4·√(KM), i.e.
/// ζ = 0.2 of the bare platen: |X₀| = 14.44 mm). The platen's displacement, fitted over 12
/// periods from 36 s, matches `X₀` within 1e-4 relative in amplitude and as a complex
/// amplitude (so in phase too), and the roof's displacement relative to the platen matches
/// `X₂ − X₀` likewise.
///
/// Error budget: the slowest mode of the coupled system (0.39 Hz, decay rate 0.43/s) has
/// decayed by e^(−15) = 2e-7 at 36 s; RK4 at h = 1/4096 s (4 steps a sample) errs by about
/// `(ωh)⁴` on the forced response and its stiffest mode (7 Hz) is far inside its stability
/// region; the force is linear between samples, whose fundamental is the sine's times
/// `sinc²(ωΔt/2) ≈ 1 − (ωΔt)²/12 = 1 − 3.1e-6` at Δt = 1/1024 s. So 1e-4 holds with a margin
/// of 30 over the largest of these, and fails for a storey mass or stiffness off by a few
/// parts in 1e4, a base shear with a wrong sign, or a half-cycle lost at a reversal.
#[test]
fn a_linear_frictionless_platen_with_a_specimen_has_the_3_dof_steady_state() {
    let k = 1.266e6;
    let c = 0.4 * (k * M_KG).sqrt();
    let model = frictionless(k, c, 1.0);
    let record = sine_record(1e5, 2.0 * PI, 48.0);
    let (out, stats) = run_specimen(&model, &frame(), &record, 4, "linear 3-DOF");
    check_3_dof_steady_state(&out, &stats, k, c, "RK4");
}

/// The same linear 3-DOF system and steady state through the adaptive Dormand–Prince 5(4)
/// with a specimen (the specimen, the closed loop and both integrators share one mode
/// machine; before it, a specimen ran with RK4 only). Its tolerances (1e-10 relative, 1e-12
/// m absolute) put its error far below the 1e-4 budget of the RK4 case, which is then set by
/// the force's linear interpolation between samples (3.1e-6) and the decayed transient (2e-7).
#[test]
fn dopri5_with_a_specimen_has_the_3_dof_steady_state() {
    let k = 1.266e6;
    let c = 0.4 * (k * M_KG).sqrt();
    let model = frictionless(k, c, 1.0);
    let record = sine_record(1e5, 2.0 * PI, 48.0);
    let mut out = Trajectory::with_capacity(record.len());
    let method = Method::Dopri5(Dopri5Settings::new(1e-10, 1e-12).unwrap());
    let stats = forward_specimen(
        &model,
        &frame(),
        &record,
        method,
        State::default(),
        record.len(),
        &mut out,
    )
    .unwrap();
    assert!(
        stats.accepted_steps > 0 && stats.rhs_evaluations > 0,
        "{stats:?}"
    );
    check_3_dof_steady_state(&out, &stats, k, c, "Dopri5");
}

/// The same through the stepping API ([`Stepping`]): the run advanced event by event and
/// sample by sample, its samples collected by the caller, meets the closed-form steady state;
/// it reports every reversal the counters count (two a period) at times that rise, and no
/// stop (nothing holds a frictionless platen).
#[test]
fn stepping_with_a_specimen_has_the_3_dof_steady_state() {
    let k = 1.266e6;
    let c = 0.4 * (k * M_KG).sqrt();
    let model = frictionless(k, c, 1.0);
    let record = sine_record(1e5, 2.0 * PI, 48.0);
    let frame = frame();
    let method = Method::Dopri5(Dopri5Settings::new(1e-10, 1e-12).unwrap());
    let mut run = Stepping::specimen(&model, &frame, &record, method, State::default()).unwrap();
    let mut out = Trajectory::with_capacity(record.len());
    let mut reversals = Vec::new();
    let stats = loop {
        match run.step().unwrap() {
            Step::Sample(s) => out.accept(&s),
            Step::Event { t_s, kind } => {
                assert_ne!(kind, EventKind::Stop, "at {t_s} s");
                if kind == EventKind::Reversal {
                    reversals.push(t_s);
                }
            }
            Step::Finished(stats) => break stats,
            other => panic!("{other:?}"),
        }
    };
    assert_eq!(reversals.len() as u64, stats.reversals);
    assert!(reversals.windows(2).all(|w| w[0] < w[1]), "{reversals:?}");
    check_3_dof_steady_state(&out, &stats, k, c, "Stepping (Dopri5)");
}

/// The platen's and the roof's steady state of a run under 100 kN at 1 Hz against the
/// closed-form `X` (see [`a_linear_frictionless_platen_with_a_specimen_has_the_3_dof_steady_state`]).
fn check_3_dof_steady_state(out: &Trajectory, stats: &RunStats, k: f64, c: f64, what: &str) {
    let (omega, f0) = (2.0 * PI, 1e5);
    let x = frequency_response(k, c, omega, f0);
    let (from, n) = (36 * 1024, 12 * 1024);
    let roof = &out.specimen.as_ref().unwrap().u_m[1];
    for (name, signal, exact) in [
        ("platen", &out.u_m, x[0]),
        ("roof drift", roof, x[2].sub(x[0])),
    ] {
        // Im(X·e^(iωt)) = Re X·sin ωt + Im X·cos ωt.
        let (a, b) = sine_fit(&out.t_s, signal, omega, from, n);
        let fitted = Complex::new(a, b);
        let amplitude = (fitted.abs() / exact.abs() - 1.0).abs();
        let complex = fitted.sub(exact).abs() / exact.abs();
        eprintln!(
            "{what}, {name}: |X| = {:.9e} m vs {:.9e} m: {amplitude:.2e} relative in amplitude, \
             {complex:.2e} as a complex amplitude",
            fitted.abs(),
            exact.abs()
        );
        assert!(amplitude < 1e-4, "{what}, {name}: {fitted:?} vs {exact:?}");
        assert!(complex < 1e-4, "{what}, {name}: {fitted:?} vs {exact:?}");
    }
    eprintln!("{what}: {stats:?}");
    // No friction: every v = 0 is a crossing (two a period), never a stop.
    assert_eq!(stats.stick_events, 0, "{what}: {stats:?}");
    assert!(stats.reversals >= 90, "{what}: {stats:?}");
    assert!(stats.stick_time_s < 1e-9, "{what}: {stats:?}");
}

struct Keep(Vec<Sample>);

impl SampleSink for Keep {
    fn accept(&mut self, s: &Sample) {
        self.0.push(*s);
    }
}

/// A displacement command `amplitude·sin ωt` (with its derivatives) at 1024 Hz.
fn sine_command(amplitude_m: f64, omega: f64, duration_s: f64) -> Motion {
    let n = (duration_s * RATE_HZ).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / RATE_HZ).collect();
    let (s, c): (Vec<f64>, Vec<f64>) = t
        .iter()
        .map(|&t| ((omega * t).sin(), (omega * t).cos()))
        .unzip();
    Motion::new(
        t,
        s.iter().map(|s| amplitude_m * s).collect(),
        c.iter().map(|c| amplitude_m * omega * c).collect(),
        s.iter().map(|s| -amplitude_m * omega * omega * s).collect(),
    )
    .unwrap()
}

/// The closed loop (the LHPOST's hydraulics and controller) with the frame on a frictionless
/// platen, K = 1e3 N/m, C = 44.58e3, α = 0.5 and K = 1.266e6 N/m, C = 1e6, α = 0.2, holding
/// still (a zero command: the loop's residual forces hover around zero) and following a
/// 50 mm, 1.5 Hz sine, with RK4 (4 steps a controller period) and Dopri5: every run reaches
/// the end. Before the loop's creep stepped a stop that rounded onto its start just past it,
/// the zero command stalled RK4 and Dopri5 ("4097 events", K = 1e3: first at 0.17 s to 0.94 s)
/// and so did Dopri5 on the sine (α = 0.2, at 0.19 s).
#[test]
fn a_frictionless_closed_loop_with_a_specimen_runs_to_the_end() {
    let system = platen_system::preset::lhpost_2008();
    let specimen = frame();
    let methods = [
        (
            "rk4",
            LoopMethod::Rk4 {
                steps_per_period: 4,
            },
        ),
        (
            "dopri5",
            LoopMethod::Dopri5 {
                steps_per_period: 1,
                rtol: 1e-8,
                atol: 1e-10,
            },
        ),
    ];
    for (k, c, alpha) in [(1e3, 44.58e3, 0.5), (1.266e6, 1e6, 0.2)] {
        let model = frictionless(k, c, alpha);
        for amplitude_m in [0.0, 0.05] {
            let command = sine_command(amplitude_m, 2.0 * PI * 1.5, 3.0);
            for (name, method) in methods {
                let what = format!("α = {alpha}, K = {k} N/m, {amplitude_m} m command, {name}");
                let run = LoopRun {
                    system: &system,
                    specimen: Some(&specimen),
                    command: &command,
                    method,
                    initial: State::default(),
                };
                let mut keep = Keep(Vec::new());
                let stats = forward_closed_loop(&model, &run, command.len(), &mut keep)
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                eprintln!(
                    "{what}: {} reversals, {} stops, stick time {:.1e} s",
                    stats.run.reversals, stats.run.stick_events, stats.run.stick_time_s
                );
                assert_eq!(keep.0.len(), command.len(), "{what}: ran to the end");
                assert!(
                    keep.0
                        .iter()
                        .all(|s| s.u_m.is_finite() && s.v_m_s.is_finite()),
                    "{what}"
                );
            }
        }
    }
}
