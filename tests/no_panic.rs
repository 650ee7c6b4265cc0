//! No number in any field panics: every numeric field of the shipped scenarios (and the
//! optional fields a scenario may add: identified parameters, initial state, limits), set in
//! turn to huge, tiny, zero, negative, out-of-range and non-numeric values, ends in a clean
//! result or a clean error (exit 0, 3 or 4; never Rust's panic exit 101), and a value of the
//! wrong type is reported at its own field.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The values tried in every field, as JSON text: far beyond any table, far below, zero,
/// negative, past f64's range (serde rejects it), and infinities and NaN written as strings
/// (JSON has no literal for them).
const VALUES: [&str; 11] = [
    "1e300", "-1e300", "1e-300", "-1e-300", "0", "-1", "1e309", "-1e309", "\"inf\"", "\"-inf\"",
    "\"NaN\"",
];

/// Fields every scenario may carry, added to the forward and inverse scenarios below.
const OPTIONAL: [&str; 14] = [
    "model.hold_down_pressure_mpa",
    "model.identified.effective_mass_kg",
    "model.identified.stiffness_n_per_m",
    "model.identified.coulomb_force_n",
    "model.identified.viscous_coefficient",
    "model.identified.viscous_exponent",
    "model.identified.low_velocity_force_n",
    "model.identified.low_velocity_decay_s_per_m",
    "initial.u_m",
    "initial.v_m_s",
    "limits.stroke_m",
    "limits.velocity_m_s",
    "limits.acceleration_m_s2",
    "limits.force_n",
];

/// The dotted paths of the numeric leaves of `v` (arrays as `name[i]`).
fn numeric_leaves(v: &Value, here: &str, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = if here.is_empty() {
                    k.clone()
                } else {
                    format!("{here}.{k}")
                };
                numeric_leaves(x, &p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                numeric_leaves(x, &format!("{here}[{i}]"), out);
            }
        }
        Value::Number(_) => out.push(here.to_owned()),
        _ => {}
    }
}

/// `v` with every string naming a file relative to `dir` made absolute, so the scenario can
/// be written elsewhere.
fn absolute_paths(v: &mut Value, dir: &Path) {
    match v {
        Value::Object(m) => m.values_mut().for_each(|x| absolute_paths(x, dir)),
        Value::Array(a) => a.iter_mut().for_each(|x| absolute_paths(x, dir)),
        Value::String(s) if dir.join(&*s).is_file() => {
            *s = dir.join(&*s).display().to_string();
        }
        _ => {}
    }
}

/// `doc` with the field at dotted `path` set to the marker string `@@`, creating objects on
/// the way (for the optional fields).
fn with_marker(doc: &Value, path: &str) -> Value {
    let mut doc = doc.clone();
    let mut node = &mut doc;
    let parts: Vec<&str> = path.split('.').collect();
    for (i, part) in parts.iter().enumerate() {
        let (key, index) = match part.find('[') {
            Some(b) => (
                &part[..b],
                part[b + 1..part.len() - 1].parse::<usize>().ok(),
            ),
            None => (*part, None),
        };
        let last = i + 1 == parts.len();
        let obj = node.as_object_mut().unwrap();
        if last && index.is_none() {
            obj.insert(key.to_owned(), Value::String("@@".into()));
            return doc;
        }
        node = obj
            .entry(key.to_owned())
            .or_insert_with(|| Value::Object(Default::default()));
        if let Some(i) = index {
            if last {
                node[i] = Value::String("@@".into());
                return doc;
            }
            node = &mut node[i];
        }
    }
    doc
}

/// One run: the scenario `text` written into `dir`, simulated.
/// Returns the exit code and stderr; a run past `LIMIT` is killed and reported as a hang.
fn simulate(dir: &Path, text: &str, n: usize) -> (Option<i32>, String) {
    /// Longer than any shipped scenario takes in a debug build (0.9 s), by far.
    const LIMIT: Duration = Duration::from_secs(60);
    let sc = dir.join(format!("case-{n}.json"));
    std::fs::write(&sc, text).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_platen"))
        .args(["simulate", sc.to_str().unwrap()])
        .env_remove("PLATEN_RECORDS_DIR")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > LIMIT {
            child.kill().unwrap();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let mut err = String::new();
    use std::io::Read as _;
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    std::fs::remove_file(&sc).unwrap();
    match status {
        Some(s) => (s.code(), err),
        None => (None, format!("killed after {LIMIT:?}: {err}")),
    }
}

#[test]
fn no_value_in_any_numeric_field_panics() {
    let root = workspace().join("scenarios");
    let mut jobs: Vec<(PathBuf, String, String)> = Vec::new();
    let mut names: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    names.extend([
        root.join("sr9/sr9-forward.json"),
        root.join("sr9/sr9-motion.json"),
        root.join("paper-tests/13.8MPa/T1.json"),
    ]);
    names.sort();
    for file in &names {
        let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
        absolute_paths(&mut doc, file.parent().unwrap());
        let mut fields = Vec::new();
        numeric_leaves(&doc, "", &mut fields);
        let stem = file.file_name().unwrap().to_string_lossy();
        if stem == "paper-forward-force.json" || stem == "s9-sine-motion.json" {
            fields.extend(OPTIONAL.iter().map(|s| (*s).to_owned()));
        }
        for field in fields {
            let marked = with_marker(&doc, &field).to_string();
            for v in VALUES {
                jobs.push((file.clone(), field.clone(), marked.replace("\"@@\"", v)));
            }
        }
    }
    assert!(jobs.len() > 500, "{} runs", jobs.len());
    let dir = tempfile::tempdir().unwrap();
    let failures = std::sync::Mutex::new(Vec::new());
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let n = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some((file, field, text)) = jobs.get(n) else {
                    break;
                };
                let (code, err) = simulate(dir.path(), text, n);
                let value: String = text
                    .split(&format!("\"{}\":", field.rsplit('.').next().unwrap()))
                    .nth(1)
                    .map(|r| r.chars().take_while(|c| !matches!(c, ',' | '}')).collect())
                    .unwrap_or_default();
                let case = format!("{} {field} = {value}", file.display());
                let clean = matches!(code, Some(0 | 3 | 4))
                    && !err.contains("panicked")
                    && (code == Some(0) || err.starts_with("error: "));
                // A string where a number belongs is named at its own field.
                let leaf = field.rsplit('.').next().unwrap();
                let leaf = leaf.split('[').next().unwrap();
                let named = !value.starts_with('"') || err.contains(leaf);
                if !(clean && named) {
                    failures
                        .lock()
                        .unwrap()
                        .push(format!("{case}: exit {code:?}: {err}"));
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(
        failures.is_empty(),
        "{} of {} runs not clean:\n{}",
        failures.len(),
        jobs.len(),
        failures.join("\n")
    );
}
