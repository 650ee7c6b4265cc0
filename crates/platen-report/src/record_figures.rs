//! The figures of an any-record identification (`platen identify --plot DIR` on records that
//! are not periodic tests): per record, the measured force against the equation error's
//! fitted force over time with the residual below; the measured displacement against the
//! output error's simulation; and the dissipative force against speed, with the law and its
//! 95 % band.
//!
//! Colours: recorded data blue ([`RECORDED`]), fitted or simulated orange ([`SIMULATED`]),
//! residuals purple ([`RESIDUAL`]), the law black ([`MODEL`]) with its band grey.

use plotters::style::RGBColor;

use platen_ident::{RecordIdentification, RecordReport};

use crate::figure::{Figure, Panel, MODEL, RECORDED, RESIDUAL, SIMULATED};
use crate::series::{envelope, line, points, thinned, MAX_SCATTER_POINTS};

/// Colour of the law's confidence band.
pub const BAND: RGBColor = RGBColor(150, 150, 150);

/// Buckets of the time-history envelopes (min and max per bucket keep the peaks).
const BUCKETS: usize = 1500;

/// Every figure: per record its force and (when the output error ran) displacement; then
/// the dissipative law.
pub fn figures(id: &RecordIdentification) -> Vec<Figure> {
    let mut out = Vec::new();
    let many = id.records.len() > 1;
    for (r, rec) in id.records.iter().enumerate() {
        let suffix = if many {
            format!("-{}", r + 1)
        } else {
            String::new()
        };
        out.push(force(rec, &suffix));
        if rec.simulated_u_m.is_some() {
            out.push(displacement(rec, &suffix));
        }
    }
    out.push(dissipative(id));
    out
}

fn times(rec: &RecordReport) -> Vec<f64> {
    (0..rec.samples)
        .map(|i| rec.start_s + i as f64 / rec.sample_rate_hz)
        .collect()
}

fn span(t: &[f64]) -> (f64, f64) {
    (t[0], t[t.len() - 1])
}

fn kn(x: &[f64]) -> Vec<f64> {
    x.iter().map(|v| v / 1e3).collect()
}

/// Measured and fitted force over time, and the residual.
fn force(rec: &RecordReport, suffix: &str) -> Figure {
    let t = times(rec);
    let range = span(&t);
    let residual: Vec<f64> = rec
        .fitted_force_n
        .iter()
        .zip(&rec.force_n)
        .map(|(m, f)| (m - f) / 1e3)
        .collect();
    Figure {
        name: format!("record-force{suffix}"),
        title: format!("Actuator force of {}: measured and fitted (equation error)", rec.name),
        caption: format!(
            "{}: the force the platen takes (recorded{}), the equation error's fit Mₑa + Kₑu + F_D(v̂) + offset, and fitted − measured (min and max per {}-sample bucket).",
            rec.name,
            if rec.floors.is_some() { ", less the specimen's base shear" } else { "" },
            rec.samples.div_ceil(BUCKETS)
        ),
        panels: vec![
            Panel::new(
                "force",
                "t (s)",
                "force (kN)",
                vec![
                    line("measured", envelope(&t, &kn(&rec.force_n), range, BUCKETS), RECORDED, 1),
                    line("fitted", envelope(&t, &kn(&rec.fitted_force_n), range, BUCKETS), SIMULATED, 1),
                ],
            ),
            Panel::new(
                "residual (fitted − measured)",
                "t (s)",
                "force (kN)",
                vec![line("residual", envelope(&t, &residual, range, BUCKETS), RESIDUAL, 1)],
            ),
        ],
        columns: 1,
        size: (1400, 900),
    }
}

/// Measured and simulated displacement (output error).
fn displacement(rec: &RecordReport, suffix: &str) -> Figure {
    let t = times(rec);
    let range = span(&t);
    let sim = rec.simulated_u_m.as_deref().unwrap_or_default();
    let mm = |x: &[f64]| x.iter().map(|v| v * 1e3).collect::<Vec<f64>>();
    let residual: Vec<f64> = sim
        .iter()
        .zip(&rec.u_m)
        .map(|(s, u)| (s - u) * 1e3)
        .collect();
    Figure {
        name: format!("record-displacement{suffix}"),
        title: format!("Displacement of {}: measured and simulated (output error)", rec.name),
        caption: format!(
            "{}: the displacement measured and simulated forward from the recorded force with the output error's parameters (exact stick-slip), and simulated − measured.",
            rec.name
        ),
        panels: vec![
            Panel::new(
                "displacement",
                "t (s)",
                "u (mm)",
                vec![
                    line("measured", envelope(&t, &mm(&rec.u_m), range, BUCKETS), RECORDED, 1),
                    line("simulated", envelope(&t, &mm(sim), range, BUCKETS), SIMULATED, 1),
                ],
            ),
            Panel::new(
                "residual (simulated − measured)",
                "t (s)",
                "u (mm)",
                vec![line("residual", envelope(&t, &residual, range, BUCKETS), RESIDUAL, 1)],
            ),
        ],
        columns: 1,
        size: (1400, 900),
    }
}

/// `|F_D|` against `|v|`: the records' points (force less the fitted inertial and elastic
/// forces and offset, on the samples fitted), the law and its band.
fn dissipative(id: &RecordIdentification) -> Figure {
    let law = id.law;
    let mut speed = Vec::new();
    let mut force = Vec::new();
    for rec in &id.records {
        for i in (0..rec.samples).filter(|&i| rec.used[i]) {
            let v = rec.velocity_m_s[i];
            // F − (Mₑa + Kₑu + offset) = F_D(v̂) + (F − fitted): the law plus the residual.
            let d = law.smooth_signed_n(v);
            speed.push(v.abs());
            force.push((d + rec.force_n[i] - rec.fitted_force_n[i]) * v.signum() / 1e3);
        }
    }
    let (pts, stride) = thinned(&speed, &force, MAX_SCATTER_POINTS);
    let band = &id.band;
    let law: Vec<(f64, f64)> = band
        .iter()
        .map(|b| (b.speed_m_s, b.force_n / 1e3))
        .collect();
    let low: Vec<(f64, f64)> = band.iter().map(|b| (b.speed_m_s, b.low_n / 1e3)).collect();
    let high: Vec<(f64, f64)> = band.iter().map(|b| (b.speed_m_s, b.high_n / 1e3)).collect();
    Figure {
        name: "record-dissipative".into(),
        title: "Dissipative force against speed, with the law's 95 % band".into(),
        caption: format!(
            "|F_D| = sign(v̂)·(F − Mₑa − Kₑu − offset) on the samples fitted ({}), the fitted law F_μ + Cₑ|v|^α + a·e^(−b|v|) and its pointwise 95 % band over the speeds reached.",
            crate::series::every(stride)
        ),
        panels: vec![Panel::new(
            "dissipative force",
            "|v| (m/s)",
            "|F_D| (kN)",
            vec![
                points("records", pts, RECORDED, 2),
                line("95 % band", low, BAND, 2),
                line("", high, BAND, 2),
                line("law", law, MODEL, 3),
            ],
        )],
        columns: 1,
        size: (1100, 800),
    }
}
