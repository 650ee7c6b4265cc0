//! The figures of a multi-axis platen run: the files written, their content, their
//! determinism, with and without the specimen's columns.

use std::fs;
use std::path::PathBuf;

use platen_integrate::TableRun;
use platen_model::multi_axis::{
    rotation, Actuator, Coords, DofSet, Mount, MultiAxisTable, Pad, RigidPlaten, Strut, TableParts,
};
use platen_report::table_figures::{figures, write_table_figures};
use platen_report::{FigureSize, Style};

const SWIVELS: [&str; 4] = ["east_x1", "east_x2", "south_y1", "south_y2"];
const PADS: [&str; 6] = ["pad_v1", "pad_v2", "pad_v3", "pad_v4", "pad_v5", "pad_v6"];

fn swivel(name: &str, base: [f64; 3], platen: [f64; 3]) -> Actuator {
    Actuator {
        name: name.into(),
        base_m: base.into(),
        mount: Mount::Swivel {
            platen_m: platen.into(),
        },
        cap_side_area_m2: 0.05,
        rod_side_area_m2: 0.05,
        chamber_volume_m3: 0.1,
        stroke_m: 0.75,
    }
}

fn pad(name: &str, contact: [f64; 3]) -> Actuator {
    // The table axis z as a unit vector: the axis of a rotation about it (this crate does
    // not depend on nalgebra).
    let z = rotation(&Coords::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.5))
        .axis()
        .expect("a rotation about z");
    Actuator {
        name: name.into(),
        base_m: [contact[0], contact[1], contact[2] - 1.5].into(),
        mount: Mount::Pad(Pad {
            axis: z,
            contact_m: contact.into(),
            friction_coefficient: 0.0044,
        }),
        cap_side_area_m2: 0.2,
        rod_side_area_m2: 0.0,
        chamber_volume_m3: 0.08,
        stroke_m: 0.013,
    }
}

fn strut(name: &str, at: [f64; 2]) -> Strut {
    Strut {
        name: name.into(),
        base_m: [at[0], at[1], -4.3].into(),
        platen_m: [at[0], at[1], -1.0].into(),
        area_m2: 0.15,
        pressure_pa: 13.8e6,
        gas_volume_m3: 0.15 * 2.1,
        polytropic_exponent: 1.44,
    }
}

/// An LHPOST6-like table: four horizontal swivel actuators, six vertical pads, two struts.
fn table() -> MultiAxisTable {
    let inertia = [[1.9e6, 0.0, 0.0], [0.0, 0.8e6, 0.0], [0.0, 0.0, 2.5e6]];
    let platen = RigidPlaten::new(150e3, inertia.into(), [0.0, 0.0, -0.5].into()).unwrap();
    let actuators = vec![
        swivel(SWIVELS[0], [-9.0, -2.0, -0.5], [-6.1, -2.0, -0.5]),
        swivel(SWIVELS[1], [-9.0, 2.0, -0.5], [-6.1, 2.0, -0.5]),
        swivel(SWIVELS[2], [0.0, -6.8, -0.5], [0.0, -3.8, -0.5]),
        swivel(SWIVELS[3], [0.0, 6.8, -0.5], [0.0, 3.8, -0.5]),
        pad(PADS[0], [-4.0, -2.5, -1.0]),
        pad(PADS[1], [-4.0, 2.5, -1.0]),
        pad(PADS[2], [0.0, -2.5, -1.0]),
        pad(PADS[3], [0.0, 2.5, -1.0]),
        pad(PADS[4], [4.0, -2.5, -1.0]),
        pad(PADS[5], [4.0, 2.5, -1.0]),
    ];
    MultiAxisTable::new(TableParts {
        platen,
        actuators,
        struts: vec![strut("strut_w", [-3.0, 0.0]), strut("strut_e", [3.0, 0.0])],
        bearings: vec![],
        held: DofSet::EMPTY,
        oil_bulk_modulus_pa: 1.5e9,
    })
    .unwrap()
}

/// A run of `n` samples at `rate_hz` built by hand: sines of different frequencies and
/// amplitudes in every column (the specimen's columns when `specimen`).
fn run(table: &MultiAxisTable, n: usize, rate_hz: f64, specimen: bool) -> TableRun {
    let t: Vec<f64> = (0..n).map(|i| i as f64 / rate_hz).collect();
    let mut k = 0.0;
    let mut sine = |amplitude: f64| -> Vec<f64> {
        k += 1.0;
        let f = 0.7 + 0.31 * k;
        t.iter()
            .map(|t| amplitude * (std::f64::consts::TAU * f * t + 0.4 * k).sin())
            .collect()
    };
    let mut columns = vec![("t_s".to_string(), t.clone())];
    for (name, amplitude) in [
        ("x_m", 0.5),
        ("y_m", 0.3),
        ("z_m", 0.005),
        ("roll_rad", 0.002),
        ("pitch_rad", 0.003),
        ("yaw_rad", 0.01),
    ] {
        columns.push((name.to_string(), sine(amplitude)));
    }
    for a in table.actuators() {
        columns.push((format!("{}_stroke_m", a.name), sine(0.8 * a.stroke_m)));
        columns.push((format!("{}_force_n", a.name), sine(1.5e6)));
    }
    for s in table.struts() {
        columns.push((format!("{}_force_n", s.name), sine(2.0e6)));
    }
    if specimen {
        for name in [
            "base_force_x_n",
            "base_force_y_n",
            "base_force_z_n",
            "overturning_moment_x_n_m",
            "overturning_moment_y_n_m",
        ] {
            columns.push((name.to_string(), sine(3.0e5)));
        }
    }
    TableRun { columns }
}

/// A fresh folder for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "platen-report-table-figures-{name}-{}",
        std::process::id()
    ));
    let _ = fs::remove_dir_all(&dir);
    dir
}

fn file_names(paths: &[PathBuf]) -> Vec<String> {
    paths
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect()
}

/// Every figure is written as SVG and PNG, sorted, non-empty, naming the actuators, with
/// the force limits; a second writing gives the same bytes.
fn written_figures(specimen: bool) {
    let table = table();
    let run = run(&table, 400, 100.0, specimen);
    let limits: Vec<(f64, f64)> = table.actuators().iter().map(|_| (-2.0e6, 2.0e6)).collect();
    let dir = temp_dir(if specimen { "specimen" } else { "bare" });
    let written = write_table_figures(
        &run,
        &table,
        Some(&limits),
        None,
        &dir,
        FigureSize::default(),
    )
    .unwrap();
    let mut expected = vec![
        "actuator_forces.png",
        "actuator_forces.svg",
        "actuator_strokes.png",
        "actuator_strokes.svg",
    ];
    if specimen {
        expected.extend(["overturning_moments.png", "overturning_moments.svg"]);
    }
    expected.extend(["pose.png", "pose.svg"]);
    assert_eq!(file_names(&written), expected);
    let mut sorted = written.clone();
    sorted.sort();
    assert_eq!(sorted, written);
    for path in &written {
        assert!(path.starts_with(&dir));
        let bytes = fs::read(path).unwrap();
        assert!(!bytes.is_empty(), "{}", path.display());
        if path.extension().unwrap() == "png" {
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        }
    }
    assert!(!dir.join("overturning_moments.svg").exists() || specimen);

    for figure in ["actuator_strokes", "actuator_forces"] {
        let svg = fs::read_to_string(dir.join(format!("{figure}.svg"))).unwrap();
        roxmltree::Document::parse(&svg).unwrap();
        for name in SWIVELS {
            assert!(
                svg.contains(&format!("{name} (swivel)")),
                "{figure}: {name}"
            );
        }
        for name in PADS {
            assert!(svg.contains(&format!("{name} (pad)")), "{figure}: {name}");
        }
        assert!(!svg.contains("EXCEEDS"), "{figure}");
    }
    let strokes = fs::read_to_string(dir.join("actuator_strokes.svg")).unwrap();
    assert!(strokes.contains("stroke ±750 mm") && strokes.contains("stroke ±13 mm"));
    let forces = fs::read_to_string(dir.join("actuator_forces.svg")).unwrap();
    assert!(forces.contains("limits −2000 / +2000 kN"), "force limits");
    let pose = fs::read_to_string(dir.join("pose.svg")).unwrap();
    for axis in [
        "x (mm)",
        "y (mm)",
        "z (mm)",
        "roll (mrad)",
        "pitch (mrad)",
        "yaw (mrad)",
    ] {
        assert!(pose.contains(axis), "{axis}");
    }
    if specimen {
        let m = fs::read_to_string(dir.join("overturning_moments.svg")).unwrap();
        for label in [
            "M_x (kN·m)",
            "M_y (kN·m)",
            "F_x (kN)",
            "F_y (kN)",
            "F_z (kN)",
        ] {
            assert!(m.contains(label), "{label}");
        }
    }

    // The same bytes again, in the same folder and in another.
    let before: Vec<Vec<u8>> = written.iter().map(|p| fs::read(p).unwrap()).collect();
    let again = write_table_figures(
        &run,
        &table,
        Some(&limits),
        None,
        &dir,
        FigureSize::default(),
    )
    .unwrap();
    assert_eq!(again, written);
    let other = temp_dir(if specimen { "specimen-2" } else { "bare-2" });
    let elsewhere = write_table_figures(
        &run,
        &table,
        Some(&limits),
        None,
        &other,
        FigureSize::default(),
    )
    .unwrap();
    for ((a, b), bytes) in written.iter().zip(&elsewhere).zip(&before) {
        assert_eq!(&fs::read(a).unwrap(), bytes, "{}", a.display());
        assert_eq!(&fs::read(b).unwrap(), bytes, "{}", b.display());
    }
    fs::remove_dir_all(&dir).unwrap();
    fs::remove_dir_all(&other).unwrap();
}

#[test]
fn figures_of_a_run_with_a_specimen() {
    written_figures(true);
}

#[test]
fn figures_of_a_run_without_a_specimen() {
    written_figures(false);
}

/// Without force limits no limit lines are drawn; limits the forces pass are flagged; the
/// size asked is the size drawn.
#[test]
fn force_limits_are_optional_and_flag_excess() {
    let table = table();
    let run = run(&table, 300, 100.0, false);
    let forces = |limits: Option<&[(f64, f64)]>| {
        figures(&run, &table, limits, None)
            .into_iter()
            .find(|f| f.name == "actuator_forces")
            .unwrap()
    };
    let bare = forces(None);
    assert_eq!(bare.panels.len(), table.actuators().len());
    assert!(bare.panels.iter().all(|p| p.series.len() == 1));
    let tight = vec![(-1.0e6, 1.0e6); table.actuators().len()];
    let flagged = forces(Some(&tight));
    assert!(flagged.panels.iter().all(|p| p.series.len() == 3));
    assert!(flagged.panels.iter().all(|p| p.title.contains("EXCEEDS")));
    // Limits for the first actuator only.
    let partial = forces(Some(&tight[..1]));
    assert_eq!(partial.panels[0].series.len(), 3);
    assert!(partial.panels[1..].iter().all(|p| p.series.len() == 1));

    let dir = temp_dir("sized");
    let size = FigureSize {
        width_px: Some(800),
        height_px: Some(600),
        png_scale: 1.0,
    };
    let written = write_table_figures(&run, &table, None, None, &dir, size).unwrap();
    assert_eq!(written.len(), 6);
    let svg = fs::read_to_string(dir.join("pose.svg")).unwrap();
    assert!(svg.contains("width=\"800\" height=\"600\""));
    fs::remove_dir_all(&dir).unwrap();
}

/// A 40 s run at 1024 Hz is drawn as an envelope of at most about 2·1100 points per line,
/// its peaks kept; a run without samples has no figures.
#[test]
fn long_runs_are_thinned_and_empty_runs_have_no_figures() {
    let table = table();
    let run = run(&table, 40 * 1024, 1024.0, true);
    let figures_ = figures(&run, &table, None, None);
    assert_eq!(figures_.len(), 4);
    for f in &figures_ {
        for p in &f.panels {
            let s = &p.series[0];
            assert!(matches!(s.style, Style::Line { .. }));
            assert!(
                s.points.len() <= 2 * 1100 + 2,
                "{}: {}",
                f.name,
                s.points.len()
            );
            assert!(s.points.len() > 1000, "{}: {}", f.name, s.points.len());
        }
    }
    // The x peak (0.5 m = 500 mm) survives the thinning to 4 significant digits.
    let pose = &figures_.iter().find(|f| f.name == "pose").unwrap();
    assert!(
        pose.panels[0].title.contains("peak |x| 500.0 mm"),
        "{}",
        pose.panels[0].title
    );

    assert!(figures(&TableRun::default(), &table, None, None).is_empty());
    let dir = temp_dir("empty");
    let written = write_table_figures(
        &TableRun::default(),
        &table,
        None,
        None,
        &dir,
        FigureSize::default(),
    )
    .unwrap();
    assert!(written.is_empty());
    let _ = fs::remove_dir_all(&dir);
}
