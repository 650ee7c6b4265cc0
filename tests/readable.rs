//! What a person reads: `platen model`'s grouped text, the verbs' help.

use std::process::Output;

use platen_model::Preset;

mod common;
use common::platen;

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The line of `text` that starts (after its indent) with `symbol` and holds `what`.
fn line<'a>(text: &'a str, symbol: &str, what: &str) -> &'a str {
    text.lines()
        .find(|l| l.trim_start().starts_with(symbol) && l.contains(what))
        .unwrap_or_else(|| panic!("no line `{symbol} … {what}` in\n{text}"))
}

/// The number and unit after the description on a line of the model text.
fn value_and_unit(line: &str, what: &str) -> (f64, String) {
    let rest = &line[line.find(what).unwrap() + what.len()..];
    let mut words = rest.split_whitespace();
    let v = words.next().unwrap().parse().unwrap();
    (v, words.collect::<Vec<_>>().join(" "))
}

/// The paper's identified values (Eq. 22/23: Mₑ = 144 t, Kₑ = 1.266 MN/m, Cₑ = 44.58
/// kN/(m/s)^0.5) and the LHPOST's limits (§1.2: ±0.75 m, 1.8 m/s, 4.2 g, 6.8 MN) read in
/// engineering units; the other values are the preset's, converted here independently of the
/// CLI's table. Printed values carry four significant digits, so each is checked to half a
/// unit of its fourth digit (relative 5e-4).
#[test]
fn model_text_is_grouped_in_engineering_units() {
    let o = platen(&["model"]);
    assert!(o.status.success());
    let text = stdout(&o);
    for group in [
        "Model simulated (identified form",
        "Derived from the physical parameters",
        "Physical parameters",
        "Table limits",
    ] {
        assert!(text.contains(group), "no group {group:?} in\n{text}");
    }
    let p = Preset::Lhpost2008.identified(13.8e6).unwrap();
    let phys = Preset::Lhpost2008.physical(13.8e6).unwrap();
    let close = |got: f64, want: f64, name: &str| {
        assert!(
            (got - want).abs() <= 5e-4 * want.abs(),
            "{name}: printed {got}, expected {want}\n{text}"
        );
    };
    for (symbol, what, want, unit) in [
        ("Mₑ", "effective mass", 144.0, "t"),
        ("Kₑ", "stiffness (hold-down struts)", 1.266, "MN/m"),
        ("Cₑ", "viscous coefficient", 44.58, "kN/(m/s)^0.5"),
        (
            "F_μ",
            "Coulomb friction force",
            p.coulomb_force_n / 1e3,
            "kN",
        ),
        ("stroke", "stroke, either way", 0.75, "m"),
        ("velocity", "velocity", 1.8, "m/s"),
        ("acceleration", "acceleration, bare table", 4.2, "g"),
        ("actuator", "actuator force", 6.8, "MN"),
        ("M_pl", "platen mass", phys.platen_mass_kg / 1e3, "t"),
        (
            "F_pl+act",
            "weight on the vertical bearings",
            phys.supported_weight_n / 1e3,
            "kN",
        ),
        (
            "μ″ₑ",
            "vertical bearing friction",
            phys.bearing_friction_coefficient * 100.0,
            "%",
        ),
    ] {
        let l = line(&text, symbol, what);
        let (v, u) = value_and_unit(l, what);
        close(v, want, what);
        assert_eq!(u, unit, "{l}");
    }
    // fₙ = √(Kₑ/Mₑ)/2π of the paper's values.
    let (f, u) = value_and_unit(line(&text, "fₙ", "natural frequency"), "2π");
    close(f, (1.266e6f64 / 144e3).sqrt() / std::f64::consts::TAU, "fₙ");
    assert_eq!(u, "Hz");
    // No raw floats: no run of more than four significant digits, no quoted strings.
    let longest_digit_run = text
        .split(|c: char| !c.is_ascii_digit() && c != '.')
        .map(|w| w.chars().filter(char::is_ascii_digit).count())
        .max()
        .unwrap();
    assert!(longest_digit_run <= 5, "a long number in\n{text}");
    assert!(!text.contains('"'), "{text}");
}

/// The values of a group line up: every unit starts in the same column.
#[test]
fn model_text_values_are_aligned_on_the_decimal_point() {
    let text = stdout(&platen(&["model"]));
    let columns: Vec<usize> = ["144.0", "1.266", "25.45", "0.4719"]
        .iter()
        .map(|v| {
            let l = text.lines().find(|l| l.contains(v)).unwrap();
            let byte = l.find(v).unwrap() + v.find('.').unwrap();
            l[..byte].chars().count()
        })
        .collect();
    assert!(
        columns.windows(2).all(|w| w[0] == w[1]),
        "{columns:?}\n{text}"
    );
}

/// `--json` is still the contract's object: the seven keys and the derived quantities in SI.
#[test]
fn model_json_is_unchanged_by_the_text_form() {
    let o = platen(&["model", "--json"]);
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let want = platen_scenario::describe_model(Preset::Lhpost2008, 13.8e6, false).unwrap();
    assert_eq!(m, want);
}

/// The verbs of the contract.
const VERBS: [&str; 11] = [
    "simulate",
    "compare",
    "identify",
    "model",
    "generate",
    "bench",
    "schema",
    "sweep",
    "plan",
    "completions",
    "scenarios",
];

/// `platen --help` lists each verb on one line of at most 100 characters, and no line of the
/// list continues the one before (a continuation would start with more than two spaces).
#[test]
fn the_verb_list_has_one_short_line_per_verb() {
    let o = platen(&["--help"]);
    assert!(o.status.success());
    let help = stdout(&o);
    let list: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .collect();
    for verb in VERBS {
        let lines: Vec<&&str> = list
            .iter()
            .filter(|l| l.trim_start().starts_with(&format!("{verb} ")))
            .collect();
        assert_eq!(lines.len(), 1, "{verb}:\n{help}");
        assert!(lines[0].chars().count() <= 100, "{}", lines[0]);
    }
    for l in &list {
        let first = l.split_whitespace().next().unwrap();
        assert!(
            VERBS.contains(&first) || first == "help",
            "a line that is not a verb: {l:?}\n{help}"
        );
    }
}

/// Each verb's help, short and long, ends with examples that name the verb.
#[test]
fn each_verbs_help_ends_with_examples() {
    for verb in VERBS {
        for flag in ["-h", "--help"] {
            let o = platen(&[verb, flag]);
            assert!(o.status.success(), "{verb} {flag}");
            let help = stdout(&o);
            let at = help
                .find("\nExample")
                .unwrap_or_else(|| panic!("{verb} {flag}: no example in\n{help}"));
            let examples = &help[at..];
            assert!(
                examples.contains(&format!("platen {verb} "))
                    || examples.contains(&format!("platen {verb}\n")),
                "{verb} {flag}:\n{examples}"
            );
            // The examples are the last thing printed.
            assert!(!examples.contains("Options:"), "{verb} {flag}:\n{help}");
        }
    }
}

/// Every shipped file an example names exists (a renamed scenario breaks this test, not a
/// user's first try).
#[test]
fn the_examples_name_shipped_files() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf();
    let mut named = 0;
    for verb in VERBS {
        let help = stdout(&platen(&[verb, "--help"]));
        for word in help
            .split_whitespace()
            .filter(|w| w.starts_with("scenarios/"))
        {
            assert!(root.join(word).is_file(), "{verb} --help names {word}");
            named += 1;
        }
    }
    assert!(named >= 8, "only {named} shipped files named");
}
