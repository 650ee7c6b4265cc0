//! `platen simulate`'s text summary of a specimen run reports the peak base shear and each
//! storey's peak drift, checked against an independent truth computed here from the run's
//! CSV: the base shear as Σ mᵢ·aᵢ of the storeys' absolute accelerations (the masses read
//! from the scenario file), and the drifts as differences of the storeys' displacement
//! columns (relative to the platen, so storey 1's drift is its own column).

use std::path::Path;
use std::process::Command;

/// The column `name` of a CSV text, parsed.
fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let j = head.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(j).unwrap().parse().unwrap())
        .collect()
}

/// The signed value of largest magnitude and its index (the first of equals).
fn peak(x: &[f64]) -> (f64, usize) {
    let mut best = (0.0f64, 0usize);
    for (i, &v) in x.iter().enumerate() {
        if v.abs() > best.0.abs() {
            best = (v, i);
        }
    }
    best
}

/// The number after `label` on the summary line that starts with it, and the time after
/// `at`.
fn reported(text: &str, label: &str) -> (f64, f64) {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(label))
        .unwrap_or_else(|| panic!("no `{label}` line in\n{text}"));
    let rest = &line.trim_start()[label.len()..];
    let mut words = rest.split_whitespace();
    let value: f64 = words.next().unwrap().parse().unwrap();
    let t: f64 = rest
        .split(" at ")
        .nth(1)
        .unwrap()
        .trim_end_matches(" s")
        .parse()
        .unwrap();
    (value, t)
}

fn check(scenario: &str) {
    let dir = tempfile::tempdir().unwrap();
    let csv_path = dir.path().join("run.csv");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenario = root.join("scenarios/specimen").join(scenario);
    let o = Command::new(env!("CARGO_BIN_EXE_platen"))
        .arg("simulate")
        .arg(&scenario)
        .arg("--out")
        .arg(&csv_path)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let csv = std::fs::read_to_string(&csv_path).unwrap();
    let t = column(&csv, "t_s");
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&scenario).unwrap()).unwrap();
    let masses: Vec<f64> = file["specimen"]["storeys"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["mass_kg"].as_f64().unwrap())
        .collect();

    // Base shear: Σ mᵢ·aᵢ at every sample, from the storeys' absolute accelerations.
    let mut shear = vec![0.0; t.len()];
    for (i, m) in masses.iter().enumerate() {
        for (b, a) in shear
            .iter_mut()
            .zip(column(&csv, &format!("storey{}_a_m_s2", i + 1)))
        {
            *b += m * a;
        }
    }
    let (b, j) = peak(&shear);
    let (kn, at) = reported(&text, "peak base shear");
    assert!(
        (kn - b / 1e3).abs() <= 0.05 + 1e-9 * b.abs(),
        "{kn} kN vs {b} N\n{text}"
    );
    assert!((at - t[j]).abs() <= 0.0005 + 1e-12, "{at} s vs {}", t[j]);

    // Drifts: differences of the storeys' displacements relative to the platen.
    let mut below = vec![0.0; t.len()];
    for i in 0..masses.len() {
        let u = column(&csv, &format!("storey{}_u_m", i + 1));
        let drift: Vec<f64> = u.iter().zip(&below).map(|(a, b)| a - b).collect();
        let (d, j) = peak(&drift);
        let (mm, at) = reported(&text, &format!("peak storey {} drift", i + 1));
        assert!(
            (mm - d * 1e3).abs() <= 0.0005 + 1e-9,
            "storey {}: {mm} mm vs {d} m",
            i + 1
        );
        assert!((at - t[j]).abs() <= 0.0005 + 1e-12, "{at} s vs {}", t[j]);
        below = u;
    }
    assert!(!text.contains(&format!("peak storey {} drift", masses.len() + 1)));
}

#[test]
fn a_forward_specimen_run_reports_the_base_shear_and_drifts_of_its_csv() {
    check("frame-forward.json");
}

#[test]
fn an_inverse_specimen_run_reports_the_base_shear_and_drifts_of_its_csv() {
    check("frame-inverse.json");
}

/// A run without a specimen has no specimen lines.
#[test]
fn a_run_without_a_specimen_has_no_specimen_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let o = Command::new(env!("CARGO_BIN_EXE_platen"))
        .arg("simulate")
        .arg(root.join("scenarios/sr9/sr9-forward.json"))
        .output()
        .unwrap();
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(
        !text.contains("base shear") && !text.contains("drift"),
        "{text}"
    );
}
