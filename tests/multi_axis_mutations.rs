//! A property test of the multi-axis table (issue 55): 1 000 mutated multi-axis scenarios
//! (fixed seed) through `platen simulate`, `model` and `plan`, each finishing within its time
//! limit, none panicking, every failure a message, no file left by a failed run, and no
//! non-finite number in any output.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{json, Value};

/// How many mutated scenarios (`PLATEN_MUTATIONS` overrides it, for a longer soak).
const CASES: usize = 1000;

/// Longer than any accepted case takes in a debug build (the slowest, a closed loop with its
/// linearised stability and margins, about 3 s), by far; a case past it is a hang.
const LIMIT: Duration = Duration::from_secs(10);

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A small deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// The base scenarios: a mid-size swivel-vertical table in closed loop (0.25 s of a sine along
/// x at its 1024 Hz controller), the LHPOST6 preset written out under the same command, and
/// the shipped bare inverse table under 0.25 s of the three-component motion.
fn bases(dir: &Path) -> Vec<Value> {
    let mut text = String::from("t_s,x_m,z_m\n");
    for j in 0..=256 {
        let t = j as f64 / 1024.0;
        let x = 0.002 * (std::f64::consts::TAU * 4.0 * t).sin();
        text.push_str(&format!("{t},{x},{}\n", 0.2 * x));
    }
    let csv = dir.join("command.csv");
    std::fs::write(&csv, text).unwrap();
    let csv = csv.display().to_string();
    let read = |p: &str| -> Value {
        serde_json::from_str(&std::fs::read_to_string(root().join(p)).unwrap()).unwrap()
    };
    let mut swivel = read("tests/data/multi_axis_poles/swivel-stable.json");
    swivel["table"]["controller"]["sample_rate_hz"] = json!(1024.0);
    swivel["excitation"] = json!({"motion_csv": csv});
    let mut lhpost6 = read("tests/data/multi_axis_poles/lhpost6.json");
    lhpost6["excitation"] = json!({"motion_csv": csv});
    let mut bare = read("scenarios/multi-axis/bare-inverse.json");
    bare["excitation"] = json!({"motion_csv": root()
        .join("scenarios/multi-axis/three-component-motion.csv")
        .display()
        .to_string()});
    bare["duration_s"] = json!(0.25);
    vec![swivel, lhpost6, bare]
}

/// The dotted paths of `v`'s numeric leaves (array elements as `[i]` segments).
fn leaves(v: &Value, here: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                here.push(json!(k));
                leaves(x, here, out);
                here.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                here.push(json!(i));
                leaves(x, here, out);
                here.pop();
            }
        }
        Value::Number(_) | Value::String(_) => out.push(here.clone()),
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(v, |node, seg| match seg {
        Value::String(k) => &mut node[k.as_str()],
        Value::Number(i) => &mut node[i.as_u64().unwrap() as usize],
        _ => unreachable!(),
    })
}

/// One mutation of `doc`: a leaf scaled, negated, zeroed, set far out of range, typed wrong,
/// or removed; or two at once.
fn mutate(doc: &mut Value, rng: &mut Rng) -> String {
    let mut paths = Vec::new();
    leaves(doc, &mut Vec::new(), &mut paths);
    let mut said = Vec::new();
    for _ in 0..(1 + rng.below(2)) {
        let path = &paths[rng.below(paths.len())];
        let node = at(doc, path);
        let old = node.as_f64();
        let what = rng.below(12);
        let new = match (what, old) {
            (0, Some(x)) => json!(x * 1e3),
            (1, Some(x)) => json!(x * 1e-3),
            (2, Some(x)) => json!(-x),
            (3, _) => json!(0.0),
            (4, _) => json!(1e300),
            (5, _) => json!(-1e300),
            (6, _) => json!(1e-300),
            (7, Some(x)) => json!(x * 10.0),
            (8, Some(x)) => json!(x + 1.0),
            (9, _) => json!("NaN"),
            (10, Some(x)) => json!(x * 0.1),
            _ => Value::Null,
        };
        said.push(format!("{} = {new}", join(path)));
        *node = new;
    }
    said.join("; ")
}

fn join(path: &[Value]) -> String {
    path.iter()
        .map(|s| match s {
            Value::String(k) => format!(".{k}"),
            other => format!("[{other}]"),
        })
        .collect()
}

/// Runs `platen ARGS` in `dir`; `None` when killed at [`LIMIT`].
fn platen(args: &[&str]) -> Option<(Option<i32>, String, String, Duration)> {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_platen"))
        .args(args)
        .env_remove("PLATEN_RECORDS_DIR")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read both pipes on threads so that a large output cannot block the child.
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut out, &mut s).ok();
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut err, &mut s).ok();
        s
    });
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > LIMIT {
            child.kill().ok();
            child.wait().ok();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let (out, err) = (out.join().unwrap(), err.join().unwrap());
    status.map(|s| (s.code(), out, err, start.elapsed()))
}

#[test]
fn mutated_multi_axis_scenarios_end_cleanly_within_their_limit() {
    let cases: usize = std::env::var("PLATEN_MUTATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(CASES);
    let dir = tempfile::tempdir().unwrap();
    let bases = bases(dir.path());
    let target = dir.path().join("target.csv");
    std::fs::write(&target, "t_s,x_m\n0,0\n0.125,0.001\n0.25,0\n").unwrap();
    let failures = std::sync::Mutex::new(Vec::new());
    let counts = std::sync::Mutex::new([0usize; 3]);
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let n = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                if n >= cases {
                    break;
                }
                let mut rng = Rng(0x5EED_0000 + n as u64);
                let mut doc = bases[n % bases.len()].clone();
                let what = mutate(&mut doc, &mut rng);
                let scenario = dir.path().join(format!("case-{n}.json"));
                std::fs::write(&scenario, doc.to_string()).unwrap();
                let out = dir.path().join(format!("case-{n}.csv"));
                let (verb, args): (&str, Vec<String>) = match n % 10 {
                    // One case in ten through `model`, one through `plan`.
                    7 => ("model", vec!["--json".into()]),
                    8 if n % bases.len() != 2 => (
                        "plan",
                        vec![
                            "--target".into(),
                            target.display().to_string(),
                            "--out".into(),
                            out.display().to_string(),
                            "--iterations".into(),
                            "1".into(),
                            "--no-max-scale".into(),
                        ],
                    ),
                    _ => (
                        "simulate",
                        vec!["--json".into(), "--out".into(), out.display().to_string()],
                    ),
                };
                let mut all = vec![verb.to_owned()];
                if verb == "model" {
                    all.push("--scenario".into());
                }
                all.push(scenario.display().to_string());
                all.extend(args);
                let all: Vec<&str> = all.iter().map(String::as_str).collect();
                let case = format!("case {n} ({verb}, base {}): {what}", n % bases.len());
                let Some((code, stdout, stderr, _)) = platen(&all) else {
                    failures
                        .lock()
                        .unwrap()
                        .push(format!("{case}: still running after {LIMIT:?}"));
                    continue;
                };
                let mut bad = Vec::new();
                if code == Some(101) || stderr.contains("panicked") {
                    bad.push(format!("panic: {stderr}"));
                }
                match code {
                    Some(0) => {
                        counts.lock().unwrap()[0] += 1;
                        if verb != "plan" && serde_json::from_str::<Value>(&stdout).is_err() {
                            bad.push(format!("stdout is not JSON: {stdout}"));
                        }
                        if let Ok(csv) = std::fs::read_to_string(&out) {
                            // The data rows (the header holds the actuators' names).
                            let rows = csv.split_once('\n').map_or("", |(_, r)| r);
                            let lower = rows.to_ascii_lowercase();
                            if lower.contains("nan") || lower.contains("inf") {
                                bad.push("a non-finite number in the CSV".into());
                            }
                        }
                    }
                    Some(c) => {
                        counts.lock().unwrap()[1] += 1;
                        // `--json` reports an error as JSON on stderr, else as text.
                        let message = match serde_json::from_str::<Value>(&stderr) {
                            Ok(e) => e["error"]["message"].as_str().unwrap_or("").to_owned(),
                            Err(_) => stderr.strip_prefix("error: ").unwrap_or("").to_owned(),
                        };
                        if message.trim().len() < 20 {
                            bad.push(format!("exit {c} without a message: {stderr}"));
                        }
                        if out.exists() {
                            bad.push(format!("exit {c} left {}", out.display()));
                        }
                    }
                    None => bad.push("killed by a signal".into()),
                }
                let _ = std::fs::remove_file(&out);
                let _ = std::fs::remove_file(&scenario);
                if !bad.is_empty() {
                    failures
                        .lock()
                        .unwrap()
                        .push(format!("{case}: {}", bad.join("; ")));
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    let [ran, refused, _] = counts.into_inner().unwrap();
    eprintln!("{cases} cases: {ran} ran, {refused} refused with a message");
    assert!(
        failures.is_empty(),
        "{} of {cases} cases not clean:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // The mutations must leave enough runs that run, or the test tests only the refusals.
    assert!(ran * 10 >= cases, "only {ran} of {cases} ran");
}
