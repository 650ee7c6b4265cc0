//! The figures of an identification (`platen identify --plot DIR`): the per-test estimates
//! of the paper's Tables I and II, and the three force decompositions of the hysteresis-loop
//! method (§3) with what was fitted to them: the elastic force against displacement (Eq.
//! 16/17), the inertial force against acceleration (Eq. 18/19), the dissipative force against
//! velocity with the fitted law (Eq. 20–22, Fig. 7), and the Coulomb force against the
//! vertical load (Fig. 8).
//!
//! Series colours: one per hold-down pressure group ([`GROUP_COLORS`], by increasing
//! pressure), grey for tests not used in an average, black for the final fit.
//!
//! The identified parameters are read from [`Identification`] in two places only,
//! `effective_mass_kg` and `final_law`.

use plotters::style::RGBColor;

use platen_ident::{DissipativeLaw, Estimate, Identification, PressureGroup, TestKind, TestResult};

use crate::figure::{Dash, Figure, Panel, Series, MODEL};
use crate::series::{line, patterned, points, segments, thinned, Points, MAX_SCATTER_POINTS};

/// Colours of the pressure groups, by increasing pressure (repeated beyond four groups).
pub const GROUP_COLORS: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(217, 95, 2),
    RGBColor(27, 158, 119),
    RGBColor(117, 112, 179),
];
/// Colour of tests left out of an average.
pub const UNUSED: RGBColor = RGBColor(150, 150, 150);
/// Colour of the paper's Eq. 21 fit.
pub const PAPER_FIT: RGBColor = RGBColor(178, 24, 43);

fn group_color(i: usize) -> RGBColor {
    GROUP_COLORS[i % GROUP_COLORS.len()]
}

/// "13.8 MPa", or "no pressure given".
fn group_name(p: Option<f64>) -> String {
    p.map_or_else(
        || "no pressure given".to_owned(),
        |p| format!("{} MPa", p / 1e6),
    )
}

/// The tests of group `g` (same pressure, bit for bit: they were grouped that way).
fn in_group<'a>(
    id: &'a Identification,
    g: &'a PressureGroup,
) -> impl Iterator<Item = &'a TestResult> {
    id.tests
        .iter()
        .filter(move |t| t.pressure_pa == g.pressure_pa)
}

/// The final dissipative law (`F_μ`, `Cₑ`, `α`, `a`, `b` of the identification), if every one
/// of its parameters has a value.
fn final_law(id: &Identification) -> Option<DissipativeLaw> {
    id.parameters.law()
}

/// The final effective mass `Mₑ`, kg, if it has a value.
fn effective_mass_kg(id: &Identification) -> Option<f64> {
    id.parameters.effective_mass_kg.value()
}

/// Speeds from 0 to `max`, dense near 0 where the low-velocity term and `|v|^α` bend.
fn speed_grid(max: f64) -> Vec<f64> {
    const N: usize = 400;
    (0..=N)
        .map(|i| {
            let s = i as f64 / N as f64;
            max * s * s
        })
        .collect()
}

/// Smallest and largest of the values.
fn range_of(x: impl Iterator<Item = f64>) -> (f64, f64) {
    x.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

/// A decomposed force curve `(x, F)` (F in N) as points in kN, and with a fitted slope
/// `F ≈ slope·x` the residual `F − slope·x` in kN; both thinned to [`MAX_SCATTER_POINTS`].
fn scatter_and_residual(curve: &[[f64; 2]], slope: Option<f64>) -> (Points, Option<Points>) {
    let x: Vec<f64> = curve.iter().map(|p| p[0]).collect();
    let f: Vec<f64> = curve.iter().map(|p| p[1] / 1e3).collect();
    let residual = slope.map(|k| {
        let r: Vec<f64> = curve.iter().map(|p| (p[1] - k * p[0]) / 1e3).collect();
        thinned(&x, &r, MAX_SCATTER_POINTS).0
    });
    (thinned(&x, &f, MAX_SCATTER_POINTS).0, residual)
}

/// Per-test points and their 95 % confidence intervals as vertical bars.
struct Estimates {
    points: Vec<(f64, f64)>,
    bars: Vec<(f64, f64)>,
}

impl Estimates {
    fn new() -> Self {
        Self {
            points: Vec::new(),
            bars: Vec::new(),
        }
    }

    fn push(&mut self, x: f64, e: &Estimate, scale: f64) {
        self.points.push((x, e.value / scale));
        if e.ci95_low.is_finite() && e.ci95_high.is_finite() {
            self.bars.push((x, e.ci95_low / scale));
            self.bars.push((x, e.ci95_high / scale));
        }
    }

    /// Cuts the bars to `[lo, hi]` (a bar cut at an edge runs on beyond the axes).
    fn clip_bars(&mut self, lo: f64, hi: f64) {
        for p in &mut self.bars {
            p.1 = p.1.clamp(lo, hi);
        }
    }

    fn into_series(self, label: impl Into<String>, color: RGBColor) -> Vec<Series> {
        if self.points.is_empty() {
            return Vec::new();
        }
        vec![
            segments(self.bars, color),
            points(label, self.points, color, 5),
        ]
    }
}

/// `used` if `is_used`, else `unused`.
fn pick<'a>(
    is_used: bool,
    used: &'a mut Estimates,
    unused: &'a mut Estimates,
) -> &'a mut Estimates {
    if is_used {
        used
    } else {
        unused
    }
}

/// The figures of an identification, in the order they are written.
pub fn figures(id: &Identification) -> Vec<Figure> {
    let triangles = id.tests.iter().any(|t| t.stiffness.is_some());
    let sines = id.tests.iter().any(|t| t.effective_mass.is_some());
    [
        estimates(id, triangles, sines),
        triangles.then(|| elastic_force(id)),
        sines.then(|| inertial_force(id)),
        dissipative_force(id),
        friction(id),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// Per-test estimates: Table I (stiffness) and Table II (mass), side by side.
fn estimates(id: &Identification, triangles: bool, sines: bool) -> Option<Figure> {
    let mut panels = Vec::new();
    if triangles {
        panels.push(stiffness_panel(id));
    }
    if sines {
        panels.push(mass_panel(id));
    }
    if panels.is_empty() {
        return None;
    }
    let columns = panels.len();
    Some(Figure {
        name: "estimates".into(),
        title: "Per-test estimates with 95 % confidence intervals".into(),
        caption: "Kₑ of each triangle test against its plateau velocity, by hold-down \
                  pressure (Table I), and Mₑ of each sine test against its peak \
                  acceleration (Table II); bars are 95 % confidence intervals (often \
                  smaller than the marker; a bar that reaches the frame runs on beyond \
                  it), grey tests are flagged and left out of the averages."
            .into(),
        panels,
        columns,
        rows: Vec::new(),
        size: (700 * columns as u32, 620),
    })
}

/// Kₑ of each triangle test against its plateau velocity, by pressure.
fn stiffness_panel(id: &Identification) -> Panel {
    let mut series = Vec::new();
    let mut unused = Estimates::new();
    for (i, g) in id.pressures.iter().enumerate() {
        let mut used = Estimates::new();
        for t in in_group(id, g) {
            if let Some(k) = &t.stiffness {
                pick(t.used_for_stiffness, &mut used, &mut unused).push(
                    t.peak_velocity_m_s,
                    k,
                    1e6,
                );
            }
        }
        let label = match &g.stiffness {
            Some(k) => format!(
                "{}: mean {:.4} MN/m",
                group_name(g.pressure_pa),
                k.value / 1e6
            ),
            None => group_name(g.pressure_pa),
        };
        series.extend(used.into_series(label, group_color(i)));
    }
    series.extend(unused.into_series("not used (flagged)", UNUSED));
    Panel::new(
        "Kₑ per triangle test (Eq. 16/17, Table I)",
        "plateau velocity v (m/s)",
        "stiffness Kₑ (MN/m)",
        series,
    )
}

/// Mₑ of each sine test against its peak acceleration, with the mean of the used tests.
fn mass_panel(id: &Identification) -> Panel {
    let mut used = Estimates::new();
    let mut unused = Estimates::new();
    for t in &id.tests {
        if let Some(m) = &t.effective_mass {
            pick(t.used_for_mass, &mut used, &mut unused).push(t.peak_acceleration_m_s2, m, 1e3);
        }
    }
    // The band of every estimate and the used tests' intervals; the flagged tests'
    // intervals (S1–S3-like tests can span ±30 %) are cut at its edges.
    let band = range_of(
        used.points
            .iter()
            .chain(&unused.points)
            .chain(&used.bars)
            .map(|p| p.1),
    );
    let pad = 0.25 * (band.1 - band.0).max(1e-3 * band.1.abs());
    unused.clip_bars(band.0 - pad, band.1 + pad);
    let mut series = used.into_series("used", GROUP_COLORS[0]);
    series.extend(unused.into_series("not used (flagged)", UNUSED));
    if let Some(m) = effective_mass_kg(id) {
        let x_max = id
            .tests
            .iter()
            .filter(|t| t.effective_mass.is_some())
            .map(|t| t.peak_acceleration_m_s2)
            .fold(0.0, f64::max);
        series.push(patterned(
            format!("Mₑ = {:.2} t (mean of the used)", m / 1e3),
            vec![(0.0, m / 1e3), (x_max, m / 1e3)],
            MODEL,
            2,
            Dash::Dashed,
        ));
    }
    Panel::new(
        "Mₑ per sine test (Eq. 18/19, Table II)",
        "peak acceleration a (m/s²)",
        "effective mass Mₑ (t)",
        series,
    )
}

/// Elastic force against displacement, per pressure, with Kₑ·u (top), and what Kₑ·u leaves,
/// one panel per pressure on a shared scale (below: the pressures' residuals have the same
/// shape and would hide one another in one panel).
fn elastic_force(id: &Identification) -> Figure {
    let (mut lines, mut data, mut residuals) = (Vec::new(), Vec::new(), Vec::new());
    for (i, g) in id.pressures.iter().enumerate() {
        let curve: Vec<[f64; 2]> = in_group(id, g)
            .filter(|t| t.kind == TestKind::Triangle)
            .flat_map(|t| t.elastic_curve.iter().copied())
            .collect();
        if curve.is_empty() {
            continue;
        }
        let color = group_color(i);
        let stiffness = g.stiffness.as_ref().map(|k| k.value);
        let (pts, residual) = scatter_and_residual(&curve, stiffness);
        data.push(points(
            format!("{} (data)", group_name(g.pressure_pa)),
            pts,
            color,
            2,
        ));
        if let (Some(k), Some(residual)) = (stiffness, residual) {
            let (lo, hi) = range_of(curve.iter().map(|p| p[0]));
            lines.push(patterned(
                format!("Kₑ·u, Kₑ = {:.4} MN/m", k / 1e6),
                vec![(lo, k * lo / 1e3), (hi, k * hi / 1e3)],
                color,
                2,
                Dash::Dashed,
            ));
            residuals.push((
                g.pressure_pa,
                points(group_name(g.pressure_pa), residual, color, 2),
            ));
        }
    }
    // The data first, the dashed lines over them (the data are dense enough to hide a line).
    data.extend(lines);
    let (x_label, residual_label) = ("displacement u (m)", "F_E − Kₑ·u (kN)");
    let shared = padded(range_of(
        residuals
            .iter()
            .flat_map(|(_, s)| s.points.iter().map(|p| p.1)),
    ));
    let mut panels = vec![Panel::new("", x_label, "elastic force F_E (kN)", data)];
    let row = residuals.len();
    panels.extend(residuals.into_iter().map(|(p, series)| Panel {
        y_range: shared,
        ..Panel::new(
            format!("residual at {}", group_name(p)),
            x_label,
            residual_label,
            vec![Series {
                label: String::new(),
                ..series
            }],
        )
    }));
    Figure {
        name: "elastic-force".into(),
        title: "Elastic force against displacement (Eq. 16/17)".into(),
        caption: "Top: the elastic part of the actuator force over the constant-velocity \
                  portions of the triangle tests (the dissipative part removed with the \
                  opposite-velocity half cycle), by hold-down pressure (points), with each \
                  pressure's stiffness line (dashed). Below, one panel per pressure on one \
                  scale: what the line leaves; a curvature there is the hold-down struts' \
                  cubic term K′ₑ(u/h)²u, which the identified model does not have."
            .into(),
        columns: 1,
        rows: if row > 0 { vec![1, row] } else { Vec::new() },
        panels,
        size: (1200, 1200),
    }
}

/// The range widened by 4 % each way (`None` for no values).
fn padded((lo, hi): (f64, f64)) -> Option<(f64, f64)> {
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let pad = 0.04 * (hi - lo).max(1e-9 * lo.abs().max(hi.abs()).max(1.0));
    Some((lo - pad, hi + pad))
}

/// What the mass line leaves of the sine tests' inertial force: in kN against the
/// acceleration (top), and per test relative to its own peak inertial force against its own
/// normalised acceleration (below), where the flagged tests (tiny accelerations, near a = 0
/// above) show how far from the line they are.
fn inertial_force(id: &Identification) -> Figure {
    let mass = effective_mass_kg(id);
    let (mut absolute, mut relative) = (Vec::new(), Vec::new());
    for (used, label, color) in [
        (true, "used tests", GROUP_COLORS[0]),
        (false, "flagged tests (not used)", UNUSED),
    ] {
        let tests: Vec<&TestResult> = id
            .tests
            .iter()
            .filter(|t| {
                t.kind == TestKind::Sine && t.effective_mass.is_some() && t.used_for_mass == used
            })
            .collect();
        let curve: Vec<[f64; 2]> = tests
            .iter()
            .flat_map(|t| t.inertial_curve.iter().copied())
            .collect();
        let Some(m) = mass.filter(|_| !curve.is_empty()) else {
            continue;
        };
        if let (_, Some(residual)) = scatter_and_residual(&curve, Some(m)) {
            absolute.push(points(label, residual, color, 2));
        }
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for t in &tests {
            let a_peak = t
                .inertial_curve
                .iter()
                .map(|p| p[0].abs())
                .fold(0.0, f64::max);
            if a_peak > 0.0 {
                for p in &t.inertial_curve {
                    x.push(p[0] / a_peak);
                    y.push(100.0 * (p[1] - m * p[0]) / (m * a_peak));
                }
            }
        }
        relative.push(points(
            label,
            thinned(&x, &y, MAX_SCATTER_POINTS).0,
            color,
            2,
        ));
    }
    let title = match mass {
        Some(m) => format!("Residual of the mass line Mₑ·a, Mₑ = {:.2} t", m / 1e3),
        None => "No effective mass identified".to_owned(),
    };
    Figure {
        name: "inertial-force".into(),
        title: "Inertial force against acceleration: what the mass line leaves (Eq. 18/19)".into(),
        caption: "The inertial part of the actuator force of the sine tests (the elastic and \
                  dissipative parts removed by the half-period symmetry of the cycle) less \
                  the final Mₑ·a. Top: in kN against the acceleration. Below: per test, \
                  relative to the test's peak inertial force Mₑ·a_peak, against its \
                  acceleration over its peak, so every test spans −1 to 1. Flagged tests \
                  (too small an inertial force, distorted or imprecise) in grey."
            .into(),
        panels: vec![
            Panel::new(title, "acceleration a (m/s²)", "F_I − Mₑ·a (kN)", absolute),
            Panel::new(
                "Relative to each test's peak inertial force",
                "acceleration over the test's peak a/a_peak",
                "(F_I − Mₑ·a)/(Mₑ·a_peak) (%)",
                relative,
            ),
        ],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 1100),
    }
}

/// Dissipative force against velocity, with the fitted law per pressure and Eq. 21.
fn dissipative_force(id: &Identification) -> Option<Figure> {
    let v_max = id
        .tests
        .iter()
        .flat_map(|t| t.dissipative_curve.iter().map(|p| p[0].abs()))
        .fold(0.0, f64::max);
    let mut series = dissipative_series(id, v_max);
    if let Some(p) = &id.paper_fit {
        let (fmu, ce) = (p.coulomb_force.value, p.viscous_coefficient.value);
        series.push(patterned(
            "Eq. 21 fit: F_μ + Cₑ·|v|^0.5",
            speed_grid(v_max)
                .into_iter()
                .map(|w| (w, (fmu + ce * w.sqrt()) / 1e3))
                .collect(),
            PAPER_FIT,
            2,
            Dash::Dashed,
        ));
    }
    let peaks: Vec<(f64, f64)> = id
        .tests
        .iter()
        .filter_map(|t| t.peak_dissipative)
        .map(|p| (p.velocity_m_s.abs(), p.force_n / 1e3))
        .collect();
    if !peaks.is_empty() {
        series.push(points("F_D at peak velocity (Eq. 20)", peaks, MODEL, 5));
    }
    if series.is_empty() {
        return None;
    }
    Some(Figure {
        name: "dissipative-force".into(),
        title: "Dissipative force against velocity (Eq. 20–22, Fig. 7)".into(),
        caption: "The dissipative part of the actuator force against speed, from every test \
                  by hold-down pressure, with the fitted law F_μ + Cₑ|v|^α + a·e^(−b|v|) \
                  at each pressure's F_μ, the paper's Eq. 21 fit to the peak points, and \
                  the force at each test's peak velocity."
            .into(),
        panels: vec![Panel::new(
            "",
            "velocity |v| (m/s)",
            "dissipative force F_D (kN)",
            series,
        )],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 800),
    })
}

/// Per pressure: the dissipative force data, and the final law at that pressure's `F_μ`
/// up to `v_max`.
fn dissipative_series(id: &Identification, v_max: f64) -> Vec<Series> {
    let mut series = Vec::new();
    let law = final_law(id);
    for (i, g) in id.pressures.iter().enumerate() {
        let (mut v, mut f) = (Vec::new(), Vec::new());
        for t in in_group(id, g) {
            for p in &t.dissipative_curve {
                v.push(p[0]);
                f.push(p[1] / 1e3);
            }
        }
        if v.is_empty() {
            continue;
        }
        let color = group_color(i);
        series.push(points(
            format!("{} (data)", group_name(g.pressure_pa)),
            thinned(&v, &f, MAX_SCATTER_POINTS).0,
            color,
            2,
        ));
        if let (Some(law), Some(fmu)) = (law, g.coulomb_force.as_ref()) {
            let law = DissipativeLaw {
                coulomb_force_n: fmu.value,
                ..law
            };
            series.push(line(
                format!("law, F_μ = {:.2} kN", fmu.value / 1e3),
                speed_grid(v_max)
                    .into_iter()
                    .map(|w| (w, law.smooth_magnitude_n(w) / 1e3))
                    .collect(),
                color,
                3,
            ));
        }
    }
    series
}

/// Coulomb force against vertical load, with μₑ.
fn friction(id: &Identification) -> Option<Figure> {
    let mu = id.friction_coefficient.as_ref()?;
    let mut est = Estimates::new();
    let mut f_z_max: f64 = 0.0;
    for g in &id.pressures {
        if let (Some(fz), Some(fmu)) = (g.vertical_force_n, g.coulomb_force.as_ref()) {
            est.push(fz / 1e6, fmu, 1e3);
            f_z_max = f_z_max.max(fz / 1e6);
        }
    }
    let mut series = est.into_series("F_μ per pressure", GROUP_COLORS[0]);
    series.push(patterned(
        format!("μₑ·F_z, μₑ = {:.4} %", 100.0 * mu.value),
        vec![(0.0, 0.0), (f_z_max, mu.value * f_z_max * 1e3)],
        MODEL,
        2,
        Dash::Dashed,
    ));
    Some(Figure {
        name: "friction".into(),
        title: "Coulomb force against vertical load (Fig. 8)".into(),
        caption: "F_μ identified at each hold-down pressure against the vertical bearing \
                  load F_z at that pressure, with 95 % confidence intervals and the line \
                  through the origin whose slope is the friction coefficient μₑ."
            .into(),
        panels: vec![Panel::new(
            "",
            "vertical load F_z (MN)",
            "Coulomb force F_μ (kN)",
            series,
        )],
        columns: 1,
        rows: Vec::new(),
        size: (1000, 700),
    })
}
