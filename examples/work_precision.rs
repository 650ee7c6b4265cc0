//! Work-precision table: error against right-hand-side evaluations for the fixed-step RK4 at
//! several steps and Dopri5 at several tolerances, on forward runs with stick phases against
//! the independent SciPy references in `tests/data/reference/`.
//!
//! Run: `cargo run --release --example work_precision`. docs/accuracy.md quotes its output.

use std::path::{Path, PathBuf};

use platen::integrate::{
    forward_dopri5, forward_rk4, Dopri5Settings, ForceRecord, Peaks, Rk4, RunStats, State,
    Trajectory,
};
use platen::model::{IdentifiedParams, PlatenModel};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/reference")
        .join(name)
}

fn columns(name: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(data(name)).expect("reference data");
    let mut lines = text.lines();
    let n = lines.next().expect("header").split(',').count();
    let mut cols = vec![Vec::new(); n];
    for line in lines.filter(|l| !l.is_empty()) {
        for (c, cell) in line.split(',').enumerate() {
            cols[c].push(cell.parse::<f64>().expect("number"));
        }
    }
    cols
}

fn table<M: PlatenModel>(title: &str, model: &M, force: &str, reference: &str) {
    let f = columns(force);
    let record = ForceRecord::new(f[0].clone(), f[1].clone()).expect("record");
    let truth = columns(reference);
    println!("\n{title}\n");
    println!("| integrator | setting | RHS evaluations | max \\|Δu\\| (m) | energy residual (relative) |");
    println!("|---|---|---|---|---|");
    let row = |name: &str, setting: String, out: &Trajectory, st: &RunStats| {
        let du = out
            .u_m
            .iter()
            .zip(&truth[1])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "| {name} | {setting} | {} | {du:.2e} | {:.1e} |",
            st.rhs_evaluations,
            st.energy.relative_residual()
        );
    };
    for k in [1, 2, 4, 8] {
        let mut out = (Trajectory::default(), Peaks::default());
        let st = forward_rk4(
            model,
            &record,
            Rk4::with_steps_per_sample(k).unwrap(),
            State::default(),
            record.len(),
            &mut out,
        )
        .expect("rk4");
        row("rk4", format!("h = Δt/{k}"), &out.0, &st);
    }
    for rtol in [1e-4, 1e-6, 1e-8, 1e-10] {
        let mut out = (Trajectory::default(), Peaks::default());
        let settings = Dopri5Settings::new(rtol, rtol * 1e-3).unwrap();
        let st = forward_dopri5(
            model,
            &record,
            settings,
            State::default(),
            record.len(),
            &mut out,
        )
        .expect("dopri5");
        row("dopri5", format!("rtol = {rtol:.0e}"), &out.0, &st);
    }
}

fn main() {
    let paper = platen::model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap();
    table(
        "Paper's identified model, 10 s at 1024 Hz, one initial stick phase (reference trusted to ~1e-9 m):",
        &paper,
        "paper_forward_force.csv",
        "paper_forward_reference.csv",
    );
    let nonpaper = IdentifiedParams {
        effective_mass_kg: 95_000.0,
        stiffness_n_per_m: 2.1e6,
        coulomb_force_n: 18_000.0,
        viscous_coefficient: 30_000.0,
        viscous_exponent: 0.7,
        low_velocity_force_n: 8_000.0,
        low_velocity_decay_s_per_m: 50.0,
    }
    .build()
    .unwrap();
    table(
        "Non-paper parameters, 12 s at 1024 Hz, 7 stick phases (reference cross-checked to 1.6e-10 m):",
        &nonpaper,
        "identified_nonpaper_force.csv",
        "identified_nonpaper_reference.csv",
    );
}
