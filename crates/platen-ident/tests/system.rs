//! `identify_system` on closed-loop records made by an independent numpy reference
//! (`tools/reference/system_ident_records.py`, parameters not the preset's, sensor noise).

use std::path::{Path, PathBuf};

use platen_ident::system::{identify_system, SystemRecord, SystemSettings};
use platen_ident::IdentError;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/system_ident")
        .join(name)
}

fn load(name: &str) -> SystemRecord {
    let mut t = platen_io::csv::read_table(
        &data(name),
        &["t_s", "command_u_m", "u_m"],
        &["drive", "delta_p_pa", "a_m_s2"],
    )
    .unwrap();
    SystemRecord {
        name: name.into(),
        t_s: t.take_column("t_s").unwrap(),
        command_u_m: t.take_column("command_u_m").unwrap(),
        u_m: t.take_column("u_m").unwrap(),
        drive: t.take_column("drive"),
        delta_p_pa: t.take_column("delta_p_pa"),
        a_m_s2: t.take_column("a_m_s2"),
    }
}

fn truth() -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(data("truth.json")).unwrap()).unwrap()
}

#[test]
fn gains_recovered_within_2_percent_and_held_out_record_judged() {
    let records = vec![load("wn-a.csv"), load("chirp.csv"), load("wn-b.csv")];
    let id = identify_system(&records, &[true, true, false], &SystemSettings::default()).unwrap();
    let g = id.gains.unwrap();
    let truth = truth();
    let c = &truth["controller"];
    for (key, got) in [
        ("displacement_gain_per_m", g.displacement_gain_per_m),
        (
            "velocity_feedforward_s_per_m",
            g.velocity_feedforward_s_per_m,
        ),
        (
            "acceleration_feedforward_s2_per_m",
            g.acceleration_feedforward_s2_per_m,
        ),
        ("velocity_feedback_s_per_m", g.velocity_feedback_s_per_m),
        (
            "acceleration_feedback_s2_per_m",
            g.acceleration_feedback_s2_per_m,
        ),
        ("delta_p_gain_per_pa", g.delta_p_gain_per_pa),
        ("delta_p_highpass_hz", g.delta_p_highpass_hz),
    ] {
        let want = c[key].as_f64().unwrap();
        eprintln!(
            "{key}: {got:.6e} (truth {want:.6e}, {:+.3} %)",
            100.0 * (got / want - 1.0)
        );
        assert!((got / want - 1.0).abs() < 0.02, "{key}: {got} vs {want}");
    }
    assert!((g.sample_rate_hz - 1024.0).abs() < 1e-6);
    let held: Vec<_> = id.records.iter().filter(|r| !r.fitted).collect();
    assert_eq!(held.len(), 1);
    assert_eq!(held[0].name, "wn-b.csv");
    eprintln!("{:?}", id.records);
    assert!(held[0].samples > 6000);
    assert!(held[0].drive_nrmse < 0.02, "{:?}", held[0]);
    assert_eq!(id.fitted_records, ["wn-a.csv", "chirp.csv"]);
}

#[test]
fn without_drive_the_gains_are_not_identified_and_say_why() {
    let mut r = load("wn-a.csv");
    r.drive = None;
    r.delta_p_pa = None;
    let id = identify_system(&[r], &[true], &SystemSettings::default()).unwrap();
    assert!(id.gains.is_none());
    let names: Vec<&str> = id.not_identified.iter().map(|(w, _)| w.as_str()).collect();
    assert!(names.contains(&"controller gains"), "{names:?}");
    assert!(
        names.iter().any(|n| n.starts_with("delta_p_gain")),
        "{names:?}"
    );
}

#[test]
fn bad_records_get_clear_errors() {
    let mut r = load("chirp.csv");
    r.command_u_m.truncate(100);
    let e = identify_system(&[r], &[true], &SystemSettings::default()).unwrap_err();
    assert!(e.to_string().contains("command_u_m has 100 samples"), "{e}");
    let e =
        identify_system(&[load("chirp.csv")], &[false], &SystemSettings::default()).unwrap_err();
    assert!(
        e.to_string().contains("no record is marked for the fit"),
        "{e}"
    );
    assert_eq!(
        identify_system(&[], &[], &SystemSettings::default()).unwrap_err(),
        IdentError::NoTests
    );
    let e = platen_io::csv::read_table(
        &data("missing-command.csv"),
        &["t_s", "command_u_m", "u_m"],
        &[],
    )
    .unwrap_err();
    assert!(e.to_string().contains("command_u_m"), "{e}");
}
