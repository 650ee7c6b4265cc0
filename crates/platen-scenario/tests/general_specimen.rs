//! A general linear specimen (its four matrices) on the uniaxial platen, issue 53's "every
//! specimen on every table", against independent truth:
//!
//! - **the storeys are its special case**: the shipped two-storey frame written as matrices
//!   (diagonal mass, tridiagonal stiffness and damping, influence 1 along x and arbitrary
//!   numbers in the other five columns, which the uniaxial platen ignores) runs as the storeys
//!   do, forward with stick-slip, inverse, and in the closed loop;
//! - **closed form**: one DOF with influence ½ under a prescribed cubic platen motion
//!   (`a = c·t`) from rest, `z = −ι·c·(t − sin ωt/ω)/ω²`, and its base shear `B = −ι·k·z`;
//! - **a coupled specimen** (a block swaying and rocking on springs: a full mass matrix) closes
//!   its energy balance forward, and its base shear is its mass times its centre's absolute
//!   acceleration, read from the output columns;
//! - bad matrices are refused with their JSON path before any run.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use platen_scenario::{RunResult, Scenario};

fn shipped(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn read(rel: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(shipped(rel)).unwrap()).unwrap()
}

/// Runs `doc` written into `dir` as `name`.
fn run(dir: &Path, name: &str, doc: &Value) -> RunResult {
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string_pretty(doc).unwrap()).unwrap();
    Scenario::load(&path)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .run()
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The storeys of `doc`'s specimen written as the four matrices, with `extra` in the
/// influence's five columns other than x.
fn as_matrices(doc: &Value, extra: [f64; 5]) -> Value {
    let storeys = doc["specimen"]["storeys"].as_array().unwrap();
    let n = storeys.len();
    let get = |i: usize, key: &str| storeys[i][key].as_f64().unwrap();
    let tridiagonal = |key: &str| -> Vec<Vec<f64>> {
        let mut k = vec![vec![0.0; n]; n];
        for i in 0..n {
            let ki = get(i, key);
            k[i][i] += ki;
            if i > 0 {
                k[i - 1][i - 1] += ki;
                k[i][i - 1] -= ki;
                k[i - 1][i] -= ki;
            }
        }
        k
    };
    let mass: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if i == j { get(i, "mass_kg") } else { 0.0 })
                .collect()
        })
        .collect();
    let influence: Vec<Vec<f64>> = (0..n)
        .map(|_| std::iter::once(1.0).chain(extra).collect())
        .collect();
    let mut out = doc.clone();
    out["specimen"] = json!({
        "mass_matrix": mass,
        "stiffness_matrix": tridiagonal("stiffness_n_per_m"),
        "damping_matrix": tridiagonal("damping_n_s_per_m"),
        "influence": influence,
    });
    out
}

/// The largest difference between the two runs' columns, relative to each column's peak;
/// the column names must agree.
fn worst_relative_difference(a: &RunResult, b: &RunResult) -> (String, f64) {
    assert_eq!(a.columns(), b.columns());
    let mut worst = (String::new(), 0.0f64);
    for name in a.columns() {
        let (x, y) = (a.column(name).unwrap(), b.column(name).unwrap());
        assert_eq!(x.len(), y.len(), "{name}");
        let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = x
            .iter()
            .zip(y)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        let relative = if peak > 0.0 { diff / peak } else { diff };
        if relative > worst.1 {
            worst = (name.to_owned(), relative);
        }
    }
    worst
}

/// The two forms do the same physics with sums in another order (the matrices' products
/// against the storeys' shears), so they differ by rounding, 1e-16 relative per operation.
/// Through thousands of steps and the stick-slip events (whose times are located by root
/// finding to rounding) that grows (measured: at most 2.8e-14 of a column's peak, in the
/// closed loop's dissipative force), and 1e-11 leaves room for another CPU's rounding while
/// staying many orders below any physical difference: the storeys' influence on the platen is
/// of order 1 (their base shear is a third of the force).
const SAME_PHYSICS: f64 = 1e-11;

#[test]
fn the_storeys_written_as_matrices_run_as_the_storeys_on_every_uniaxial_run() {
    let dir = tempfile::tempdir().unwrap();
    let frame = read("scenarios/specimen/frame-forward.json");
    let mut closed = read("scenarios/table-system/wn10g-closed-loop.json");
    closed["specimen"] = frame["specimen"].clone();
    closed["duration_s"] = json!(6.0);
    for (name, doc) in [
        ("forward", frame),
        ("inverse", read("scenarios/specimen/frame-inverse.json")),
        ("closed-loop", closed),
    ] {
        let storeys = run(dir.path(), &format!("{name}-storeys.json"), &doc);
        let general = as_matrices(&doc, [0.3, -0.2, 0.05, 0.8, -1.5]);
        let matrices = run(dir.path(), &format!("{name}-matrices.json"), &general);
        let (column, worst) = worst_relative_difference(&storeys, &matrices);
        eprintln!("{name}: worst relative difference {worst:e} in {column}");
        assert!(
            worst <= SAME_PHYSICS,
            "{name}: {column} differs by {worst:e}"
        );
        let shear = storeys.column("base_shear_n").unwrap();
        assert!(
            shear.iter().any(|b| b.abs() > 1e4),
            "{name}: the frame is loaded"
        );
        // And the summaries agree on the specimen's mass and peaks.
        let (s, m) = (
            serde_json::to_value(storeys.summary()).unwrap(),
            serde_json::to_value(matrices.summary()).unwrap(),
        );
        let (ps, pm) = (
            s["specimen"]["peak_base_shear_n"].as_f64().unwrap(),
            m["specimen"]["peak_base_shear_n"].as_f64().unwrap(),
        );
        assert!(
            (ps - pm).abs() <= SAME_PHYSICS * ps.abs(),
            "{name}: {ps} vs {pm}"
        );
    }
}

/// One DOF of mass `m`, stiffness `k`, no damping, influence `ι` (a DOF that takes half the
/// platen's motion, as a lever would): `m·z̈ + k·z = −m·ι·a` with `a = c·t` from rest gives
/// `z = −ι·c·(t − sin ωt/ω)/ω²`, and the base shear `B = −ι·k·z`. The inverse run integrates
/// the specimen by RK4 with 8 sub-steps per 1/1024 s (relative error near 1e-14), so the
/// tolerance of 1e-9 of the peak is the closed form's rounding with room.
#[test]
fn one_dof_with_half_influence_matches_the_closed_form_in_the_inverse() {
    let dir = tempfile::tempdir().unwrap();
    let (m, k, iota, c): (f64, f64, f64, f64) = (20e3, 8e6, 0.5, 0.4);
    let omega = (k / m).sqrt();
    let mut csv = String::from("t_s,u_m,v_m_s,a_m_s2\n");
    for i in 0..=2048 {
        let t = f64::from(i) / 1024.0;
        let (u, v, a) = (c * t * t * t / 6.0, c * t * t / 2.0, c * t);
        csv.push_str(&format!("{t},{u},{v},{a}\n"));
    }
    std::fs::write(dir.path().join("cubic.csv"), csv).unwrap();
    let doc = json!({
        "model": {"preset": "lhpost-2008"},
        "excitation": {"motion_csv": "cubic.csv"},
        "specimen": {
            "mass_matrix": [[m]], "stiffness_matrix": [[k]], "damping_matrix": [[0.0]],
            "influence": [[iota, 0.0, 0.0, 0.0, 0.0, 0.0]],
        },
    });
    let out = run(dir.path(), "lever.json", &doc);
    let t = out.column("t_s").unwrap();
    let z = out.column("storey1_u_m").unwrap();
    let b = out.column("base_shear_n").unwrap();
    let a_abs = out.column("storey1_a_m_s2").unwrap();
    let exact = |t: f64| -iota * c * (t - (omega * t).sin() / omega) / (omega * omega);
    let z_peak = z.iter().fold(0.0f64, |p, v| p.max(v.abs()));
    let b_peak = b.iter().fold(0.0f64, |p, v| p.max(v.abs()));
    assert!(z_peak > 5e-4 && b_peak > 1e3, "{z_peak} {b_peak}");
    for i in 0..t.len() {
        let ze = exact(t[i]);
        assert!(
            (z[i] - ze).abs() <= 1e-9 * z_peak,
            "t {}: {} vs {ze}",
            t[i],
            z[i]
        );
        assert!((b[i] + iota * k * ze).abs() <= 1e-9 * b_peak, "t {}", t[i]);
        // Its absolute acceleration is ι·a + z̈, and m·that is the base shear over ι.
        let zdd = -iota * c * (omega * t[i]).sin() / omega;
        let expected = iota * c * t[i] + zdd;
        assert!((a_abs[i] - expected).abs() <= 1e-6 * c, "t {}", t[i]);
    }
}

/// A block of mass `m` and inertia `J` about its centre, at height `h` on a sway spring
/// `k_s` and a rocking spring `k_θ` (each with a damper): DOFs `(x_s, θ)` relative to the
/// platen, its centre at `u + x_s + h·θ`. Then `M = [[m, m·h], [m·h, m·h² + J]]`, influence
/// `(1, 0)` along x. Forward under the frame's sine force with stick-slip, the run's energy
/// balance (platen and specimen, a separate account of the work and the dissipation) closes
/// to 1e-10 of the largest flow, as the storeys' does; and the base shear equals the block's
/// mass times its centre's absolute acceleration, `m·(a_x + h·θ̈)` from the output's
/// absolute accelerations (`storey1_a_m_s2 = a + ẍ_s`, `storey2_a_m_s2 = θ̈`).
#[test]
fn a_swaying_rocking_block_closes_its_energy_and_its_shear_is_its_inertia() {
    let dir = tempfile::tempdir().unwrap();
    let (m, j, h) = (40e3, 60e3, 1.5);
    let (ks, kt, cs, ct) = (30e6, 120e6, 60e3, 150e3);
    let mut doc = read("scenarios/specimen/frame-forward.json");
    doc["specimen"] = json!({
        "mass_matrix": [[m, m * h], [m * h, m * h * h + j]],
        "stiffness_matrix": [[ks, 0.0], [0.0, kt]],
        "damping_matrix": [[cs, 0.0], [0.0, ct]],
        "influence": [[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]],
    });
    let path = dir.path().join("block.json");
    std::fs::write(&path, doc.to_string()).unwrap();
    let Scenario::Platen(scenario) = Scenario::load(&path).unwrap() else {
        panic!("a uniaxial scenario");
    };
    let mut trajectory = platen_integrate::Trajectory::default();
    let output = scenario.run(&mut trajectory).unwrap();
    let stats = output.stats.expect("a forward run has solver statistics");
    let energy = stats.energy;
    eprintln!(
        "block: relative residual {:e}, specimen end {} J, dissipated {} J, stick events {}",
        energy.relative_residual(),
        energy.specimen_end_j,
        energy.specimen_dissipated_j,
        stats.stick_events
    );
    assert!(energy.specimen_dissipated_j > 1.0);
    assert!(stats.stick_events + stats.breakaways > 0, "{stats:?}");
    assert!(energy.relative_residual().abs() <= 1e-10);
    let out = run(dir.path(), "block-again.json", &doc);
    let (b, a1, a2) = (
        out.column("base_shear_n").unwrap(),
        out.column("storey1_a_m_s2").unwrap(),
        out.column("storey2_a_m_s2").unwrap(),
    );
    let peak = b.iter().fold(0.0f64, |p, v| p.max(v.abs()));
    assert!(peak > 1e4, "{peak}");
    for i in 0..b.len() {
        let inertia = m * (a1[i] + h * a2[i]);
        assert!(
            (b[i] - inertia).abs() <= 1e-9 * peak,
            "sample {i}: {} vs {inertia}",
            b[i]
        );
    }
}

#[test]
fn bad_matrices_are_refused_with_their_path() {
    let dir = tempfile::tempdir().unwrap();
    let base = read("scenarios/specimen/frame-inverse.json");
    let cases = [
        (
            json!({"mass_matrix": [[1e3]], "stiffness_matrix": [[1e6]], "damping_matrix": [[0.0]],
                   "influence": [[0.0, 1.0, 0.0, 0.0, 0.0, 0.0]]}),
            "specimen.influence",
        ),
        (
            json!({"mass_matrix": [[-1e3]], "stiffness_matrix": [[1e6]], "damping_matrix": [[0.0]],
                   "influence": [[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]]}),
            "specimen.mass_matrix",
        ),
        (
            json!({"mass_matrix": [[1e3]], "stiffness_matrix": [[1e6]],
                   "influence": [[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]]}),
            "specimen.damping_matrix",
        ),
        (
            json!({"mass_matrix": [[1e3]], "stiffness_matrix": [[1e6]], "damping_matrix": [[0.0]],
                   "influence": [[1.0, 0.0, 0.0]]}),
            "specimen.influence[0]",
        ),
        (
            json!({"storeys": [{"mass_kg": 1e3, "stiffness_n_per_m": 1e6, "damping_n_s_per_m": 0.0}],
                   "mass_matrix": [[1e3]], "stiffness_matrix": [[1e6]], "damping_matrix": [[0.0]],
                   "influence": [[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]]}),
            "specimen.storeys",
        ),
    ];
    for (i, (specimen, path)) in cases.into_iter().enumerate() {
        let mut doc = base.clone();
        doc["specimen"] = specimen;
        let file = dir.path().join(format!("bad{i}.json"));
        std::fs::write(&file, doc.to_string()).unwrap();
        let Err(err) = Scenario::load(&file) else {
            panic!("case {i}: accepted");
        };
        let err = err.to_string();
        assert!(err.contains(path), "case {i}: {err}");
    }
}
