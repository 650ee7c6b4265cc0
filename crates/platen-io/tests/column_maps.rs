//! Column maps against hand-written lab files: trimmed headers, every canonical column
//! (storeys included), errors that list what is accepted, and `delay_s`.
//!
//! The expected values are written out by hand from the files' text and the units'
//! definitions (1 mm = 1e-3 m, 1 g = 9.80665 m/s², 1 MPa = 1e6 Pa), not produced by the code
//! under test.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use platen_io::columns::{ColumnMap, ColumnSpec, MAX_DELAY_S};
use platen_io::IoError;

/// A scratch folder with `name` holding `text`.
fn file(name: &str, text: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

fn map(json: &str) -> Result<ColumnMap, (String, String, String)> {
    let spec: BTreeMap<String, ColumnSpec> = serde_json::from_str(json).unwrap();
    ColumnMap::new(&spec, "columns")
}

/// `a` and `b` equal to 1e-12 relative: the conversions multiply once, so only the last
/// bit of a product can differ from the hand-written value.
fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-12 * y.abs().max(1e-300))
}

#[test]
fn headers_match_with_spaces_trimmed_in_the_file_and_in_the_map() {
    // A DAQ export that pads its header names, as some write " Time, Table disp".
    let (_d, path) = file(
        "daq.csv",
        " Time ,  Table disp , acc\n0, 1.5, 0.1\n0.5, -2.5, 0.2\n",
    );
    let m = map(
        r#"{"t_s": {"name": "Time"}, "u_m": {"name": " Table disp ", "unit": "mm"},
                    "a_m_s2": {"name": "acc ", "unit": "g"}}"#,
    )
    .unwrap();
    assert_eq!(m.header("u_m"), "Table disp");
    let mut t = m.read_table(&path, &["t_s", "u_m"], &["a_m_s2"]).unwrap();
    assert_eq!(t.take_column("t_s").unwrap(), vec![0.0, 0.5]);
    let u = t.take_column("u_m").unwrap();
    assert!(close(&u, &[1.5e-3, -2.5e-3]), "{u:?}");
    let a = t.take_column("a_m_s2").unwrap();
    assert!(close(&a, &[0.980665, 1.96133]), "{a:?}");
    // A map's name of only spaces names no header.
    let e = map(r#"{"u_m": {"name": "  "}}"#).unwrap_err();
    assert_eq!(e.0, "columns.u_m.name", "{e:?}");
}

#[test]
fn every_canonical_column_maps_storeys_included() {
    let (_d, path) = file(
        "specimen.csv",
        "time,Cmd,dP cap,dP rod,F1 drift,F12 acc,Shear\n\
         0,10,5,4,2,0.5,3\n1,20,6,3,-4,-0.25,-7\n",
    );
    let m = map(
        r#"{"t_s": {"name": "time"}, "command_u_m": {"name": "Cmd", "unit": "mm"},
                    "cap_pressure_pa": {"name": "dP cap", "unit": "MPa"},
                    "rod_pressure_pa": {"name": "dP rod", "unit": "bar"},
                    "storey1_u_m": {"name": "F1 drift", "unit": "cm"},
                    "storey12_a_m_s2": {"name": "F12 acc", "unit": "g"},
                    "base_shear_n": {"name": "Shear", "unit": "kN"}}"#,
    )
    .unwrap();
    let mut t = m
        .read_table(
            &path,
            &["t_s", "command_u_m"],
            &[
                "cap_pressure_pa",
                "rod_pressure_pa",
                "storey1_u_m",
                "storey12_a_m_s2",
                "base_shear_n",
            ],
        )
        .unwrap();
    let mut col = |c: &str| t.take_column(c).unwrap();
    assert!(close(&col("command_u_m"), &[0.010, 0.020]));
    assert!(close(&col("cap_pressure_pa"), &[5e6, 6e6]));
    assert!(close(&col("rod_pressure_pa"), &[4e5, 3e5]));
    assert!(close(&col("storey1_u_m"), &[0.02, -0.04]));
    assert!(close(&col("storey12_a_m_s2"), &[4.903325, -2.4516625]));
    assert!(close(&col("base_shear_n"), &[3e3, -7e3]));
    // A storey displacement takes a displacement's units only.
    let e = map(r#"{"storey2_u_m": {"unit": "g"}}"#).unwrap_err();
    assert_eq!(e.0, "columns.storey2_u_m.unit");
    assert!(e.2.contains("m, mm, cm, in"), "{e:?}");
    for bad in [
        "storey0_u_m",
        "storey_u_m",
        "storey+1_u_m",
        "storey01_a_m_s2",
    ] {
        let e = map(&format!(r#"{{"{bad}": {{}}}}"#)).unwrap_err();
        assert_eq!(e.0, format!("columns.{bad}"), "{e:?}");
    }
}

#[test]
fn an_unknown_column_or_unit_lists_what_is_accepted() {
    let e = map(r#"{"displacement": {"name": "disp"}}"#).unwrap_err();
    assert_eq!(e.0, "columns.displacement");
    for name in [
        "t_s",
        "u_m",
        "v_m_s",
        "a_m_s2",
        "force_n",
        "command_u_m",
        "drive",
        "delta_p_pa",
        "storey{i}_u_m",
        "storey{i}_a_m_s2",
    ] {
        assert!(e.2.contains(name), "{name} not listed: {e:?}");
    }
    let e = map(r#"{"u_m": {"unit": "furlong"}}"#).unwrap_err();
    assert_eq!(
        (e.0.as_str(), e.1.as_str()),
        ("columns.u_m.unit", "\"furlong\"")
    );
    assert!(e.2.contains("m, mm, cm, in"), "{e:?}");
    let e = map(r#"{"a_m_s2": {"unit": "G"}}"#).unwrap_err();
    assert!(e.2.contains("m/s2, mm/s2, cm/s2, gal, in/s2, g"), "{e:?}");
    let e = map(r#"{"delta_p_pa": {"unit": "atm"}}"#).unwrap_err();
    assert!(e.2.contains("Pa, kPa, MPa, bar, psi"), "{e:?}");
    // A drive in volts needs the scale that makes it a fraction of full opening.
    let e = map(r#"{"drive": {"unit": "V"}}"#).unwrap_err();
    assert_eq!(e.0, "columns.drive.scale", "{e:?}");
    assert!(e.2.contains("0.1 for a ±10 V"), "{e:?}");
    let e = map(r#"{"drive": {"unit": "mm"}}"#).unwrap_err();
    assert!(e.2.starts_with("no unit or V"), "{e:?}");
}

#[test]
fn a_mapped_header_absent_from_the_file_lists_the_files_headers() {
    let (_d, path) = file("lab.csv", "Time,disp\n0,1\n1,2\n");
    // Required and optional alike: a map that names a channel expects the file to have it.
    for (json, ours, at) in [
        (
            r#"{"t_s": {"name": "Time"}, "u_m": {"name": "Table disp"}}"#,
            "u_m",
            "`Table disp`",
        ),
        (
            r#"{"t_s": {"name": "Time"}, "u_m": {"name": "disp"}, "a_m_s2": {"name": "acc", "unit": "g"}}"#,
            "a_m_s2",
            "`acc`",
        ),
        (
            r#"{"t_s": {"name": "Time"}, "u_m": {"name": "disp"}, "a_m_s2": {"unit": "g"}}"#,
            "a_m_s2",
            "`a_m_s2`",
        ),
    ] {
        let e = map(json)
            .unwrap()
            .read_table(&path, &["t_s", "u_m"], &["a_m_s2"])
            .unwrap_err();
        assert!(
            matches!(&e, IoError::MappedColumnMissing { column, .. } if column == ours),
            "{e:?}"
        );
        let text = e.to_string();
        assert!(
            text.contains(at) && text.contains(&format!("columns.{ours}")),
            "{text}"
        );
        assert!(text.contains("the header has: `Time`, `disp`"), "{text}");
        assert_eq!(e.file(), path.as_path());
    }
    // Without a map entry an optional column the file lacks is simply not read.
    let m = map(r#"{"t_s": {"name": "Time"}, "u_m": {"name": "disp"}}"#).unwrap();
    let t = m.read_table(&path, &["t_s", "u_m"], &["a_m_s2"]).unwrap();
    assert!(!t.has_column("a_m_s2"));
}

#[test]
fn a_file_without_t_s_says_a_column_map_fixes_it_with_an_example() {
    let (_d, path) = file("daq.csv", "Time,disp\n0,1\n1,2\n");
    let e = ColumnMap::default()
        .read_table(&path, &["t_s", "u_m"], &[])
        .unwrap_err();
    assert!(
        matches!(&e, IoError::UnmappedColumn { column, .. } if column == "t_s"),
        "{e:?}"
    );
    let text = e.to_string();
    for part in [
        "missing required column `t_s`",
        "the header has: `Time`, `disp`",
        "--columns MAP.json",
        "excitation.columns",
        r#"e.g. {"t_s": {"name": "Time", "unit": "s"}}"#,
    ] {
        assert!(text.contains(part), "{part:?} not in {text}");
    }
    // The example is itself a map that reads the file's time.
    let example = text.rsplit("e.g. ").next().unwrap();
    let m = ColumnMap::from_json(Path::new("example"), example).unwrap();
    let e = m.read_table(&path, &["t_s", "u_m"], &[]).unwrap_err();
    assert!(
        matches!(&e, IoError::UnmappedColumn { column, .. } if column == "u_m"),
        "{e:?}"
    );
    // The hint for the displacement names the other column, never the time the map
    // already reads (issue 38: it pointed `u_m` at `Time`), and is itself a map that, with
    // the time's, reads the file.
    let text = e.to_string();
    assert!(
        text.contains(r#"{"u_m": {"name": "disp", "unit": "mm"}}"#),
        "{text}"
    );
    let both =
        map(r#"{"t_s": {"name": "Time", "unit": "s"}, "u_m": {"name": "disp", "unit": "mm"}}"#)
            .unwrap();
    let t = both.read_table(&path, &["t_s", "u_m"], &[]).unwrap();
    assert_eq!(t.column("u_m").unwrap(), &[0.001, 0.002]);
    // Under platen's own names: the time column `t_s` is not suggested for `u_m` either.
    let (_d2, own) = file("own.csv", "t_s,disp\n0,1\n1,2\n");
    let e = ColumnMap::default()
        .read_table(&own, &["t_s", "u_m"], &[])
        .unwrap_err();
    assert!(
        e.to_string()
            .contains(r#"{"u_m": {"name": "disp", "unit": "mm"}}"#),
        "{e}"
    );
    // The time is found among later headers too.
    let (_d3, late) = file("late.csv", "disp,Time (s)\n1,0\n2,1\n");
    let e = ColumnMap::default()
        .read_table(&late, &["t_s", "u_m"], &[])
        .unwrap_err();
    assert!(
        e.to_string()
            .contains(r#"{"t_s": {"name": "Time (s)", "unit": "s"}}"#),
        "{e}"
    );
    // A header that is no platen column (an identification floor's own channel) gets no
    // map example.
    let e = ColumnMap::default()
        .read_table(&path, &["Time", "Acc F1"], &[])
        .unwrap_err();
    assert!(matches!(&e, IoError::MissingColumn { .. }), "{e:?}");
}

#[test]
fn delay_s_is_parsed_and_handed_over_not_applied() {
    let (_d, path) = file("skew.csv", "t_s,u_m,acc\n0,1,2\n1,2,3\n");
    let m =
        map(r#"{"a_m_s2": {"name": "acc", "delay_s": 0.0042}, "force_n": {"delay_s": -0.001}}"#)
            .unwrap();
    assert_eq!(m.delay_s("a_m_s2"), Some(0.0042));
    assert_eq!(m.delay_s("force_n"), Some(-0.001));
    assert_eq!(m.delay_s("u_m"), None);
    assert_eq!(m.delay_s("v_m_s"), None);
    let mut t = m.read_table(&path, &["t_s", "u_m", "a_m_s2"], &[]).unwrap();
    assert_eq!(t.take_column("a_m_s2").unwrap(), vec![2.0, 3.0]);
    assert_eq!(t.take_column("t_s").unwrap(), vec![0.0, 1.0]);
}

#[test]
fn delay_s_refusals_name_their_json_path() {
    assert_eq!(MAX_DELAY_S, 1.0);
    for (json, at) in [
        (r#"{"a_m_s2": {"delay_s": 4}}"#, "columns.a_m_s2.delay_s"),
        (r#"{"a_m_s2": {"delay_s": -1.0}}"#, "columns.a_m_s2.delay_s"),
        (r#"{"t_s": {"delay_s": 0.001}}"#, "columns.t_s.delay_s"),
        (r#"{"u_m": {"delay_s": 0.001}}"#, "columns.u_m.delay_s"),
        (
            r#"{"drive": {"ignore": true, "delay_s": 0.001}}"#,
            "columns.drive.ignore",
        ),
    ] {
        let e = map(json).unwrap_err();
        assert_eq!(e.0, at, "{json}: {e:?}");
    }
    let e = map(r#"{"force_n": {"delay_s": 4}}"#).unwrap_err();
    assert!(e.2.contains("|delay_s| < 1 s"), "{e:?}");
    // Not finite: JSON cannot write it, a program can.
    let spec = BTreeMap::from([(
        "force_n".to_owned(),
        ColumnSpec {
            delay_s: Some(f64::INFINITY),
            ..ColumnSpec::default()
        },
    )]);
    let e = ColumnMap::new(&spec, "excitation.columns").unwrap_err();
    assert_eq!(e.0, "excitation.columns.force_n.delay_s");
    // From a file, the path is the JSON path inside it and the file is named.
    let (_d, path) = file("map.json", r#"{"drive": {"scale": 0.1, "delay_s": 2.5}}"#);
    let e = ColumnMap::load(&path).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("map.json") && text.contains("columns.drive.delay_s = 2.5"),
        "{text}"
    );
}
