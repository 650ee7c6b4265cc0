//! The README's and docs' commands run as written (issue 27): every shell block (```sh,
//! ```bash, ```console) of README.md and docs/*.md, page by page, top to bottom, each command
//! through `bash` with the `platen` this test run built first on PATH (`cargo run --release --`
//! is that binary too, as is `target/release/platen`), in a temporary copy of what the commands
//! read (`scenarios/`, `tests/data/`, `benches/`, an empty `out/`), and each must exit 0.
//!
//! A ```json block that a page asks to save (“Save as `out/NAME.json`”) is written there first.
//! Shell helpers run as written (`cmp`, `cc`, `/usr/bin/time`, a `python3 -c` that reshapes
//! JSON with the standard library only). Each page runs on its own (its later commands see only
//! its own outputs), so a page that needs a file another page makes fails here.
//! What is not run is printed with the reason, never left out silently:
//! - building and installing (`cargo install`, `cargo build`, `cargo test`): this test runs on
//!   what they build;
//! - Python environments (`venv`, `pip`, `import platen`): python/tests/test_docs.py runs
//!   docs/python.md's code;
//! - `export PLATEN_RECORDS_DIR=…`: the test passes on its own environment's;
//! - a command that needs a PEER record when PLATEN_RECORDS_DIR is unset (it says so, naming
//!   the variable), and the later commands that read what it would have written;
//! - a command that already ran, unchanged, on an earlier page or higher up (the paper
//!   programme's identification is in the README and in docs/identification.md: 60–80 s each in
//!   a debug build), when nothing later on its page reads what it writes;
//! - a program given by its absolute path that this machine lacks (`/usr/bin/time`);
//! - `platen bench` in a debug build: it times 600 s records five times over (104 s in a debug
//!   build here), and its numbers are a release build's (`cargo test --release --test docs_commands` runs it);
//! - the LHPOST6 closed loop over Northridge (`lhpost6-northridge.json`) in a debug build:
//!   minutes there, seconds in release (`cargo test --release --test docs_commands` runs it).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

mod common;

use common::docs::{copy_tree, pages, root, steps, written_paths, Step};

/// Why a command is not run here, or None to run it.
fn not_run(command: &str) -> Option<String> {
    let words: Vec<&str> = command.split_whitespace().collect();
    if words.first() == Some(&"cargo") && words.get(1) != Some(&"run") {
        return Some(format!(
            "`cargo {}` builds what this test already runs",
            words.get(1).unwrap_or(&"")
        ));
    }
    if command.contains("venv") || command.contains("pip ") || command.contains("import platen") {
        return Some(
            "a Python environment: python/tests/test_docs.py runs docs/python.md's code".into(),
        );
    }
    if command.starts_with("export PLATEN_RECORDS_DIR=") {
        return Some(
            "the records folder comes from this test's own PLATEN_RECORDS_DIR (set or not)".into(),
        );
    }
    if cfg!(debug_assertions) && words.windows(2).any(|w| w == ["platen", "bench"]) {
        return Some(
            "`platen bench` times release builds (600 s records, five repeats): run \
             `cargo test --release --test docs_commands` to include it"
                .into(),
        );
    }
    if cfg!(debug_assertions) && command.contains("lhpost6-northridge") {
        return Some(
            "the LHPOST6 closed loop over 40 s of Northridge takes minutes in a debug build \
             (about 2 s in a release build): run `cargo test --release --test docs_commands` \
             to include it"
                .into(),
        );
    }
    if let Some(program) = words.first().filter(|w| w.starts_with('/')) {
        if !Path::new(program).exists() {
            return Some(format!("no `{program}` on this machine"));
        }
    }
    if words.first() == Some(&"cc") && !on_path("cc") {
        return Some("no C compiler (`cc`) on this machine".into());
    }
    if words.first() == Some(&"python3") && !on_path("python3") {
        return Some("no python3 on this machine".into());
    }
    None
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

/// A temporary clone of what the commands read, with `platen` on a PATH of its own.
struct Workspace {
    dir: tempfile::TempDir,
    path: std::ffi::OsString,
}

fn workspace() -> Workspace {
    let dir = tempfile::tempdir().unwrap();
    for sub in ["scenarios", "tests/data", "benches"] {
        copy_tree(&root().join(sub), &dir.path().join(sub));
    }
    std::fs::create_dir(dir.path().join("out")).unwrap();
    let binary = PathBuf::from(env!("CARGO_BIN_EXE_platen"));
    let bin = dir.path().join(".bin");
    std::fs::create_dir(&bin).unwrap();
    let release = dir.path().join("target/release");
    std::fs::create_dir_all(&release).unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&binary, bin.join("platen")).unwrap();
        std::os::unix::fs::symlink(&binary, release.join("platen")).unwrap();
    }
    let mut paths = vec![bin];
    if let Some(p) = std::env::var_os("PATH") {
        paths.extend(std::env::split_paths(&p));
    }
    Workspace {
        dir,
        path: std::env::join_paths(paths).unwrap(),
    }
}

/// Runs the steps of one page; returns the commands run and the lines skipped (with reasons).
/// `done` holds the commands already run on earlier pages: one that comes again, and whose
/// outputs nothing later on this page reads, is not run twice.
fn run_page(page: &Path, done: &mut BTreeSet<String>) -> (usize, Vec<String>) {
    let text = std::fs::read_to_string(page).unwrap();
    let name = page
        .strip_prefix(root())
        .unwrap_or(page)
        .display()
        .to_string();
    let steps = steps(&text);
    let ws = workspace();
    let records = std::env::var_os("PLATEN_RECORDS_DIR").filter(|v| !v.is_empty());
    let mut assignments = String::new();
    let mut missing: BTreeSet<String> = BTreeSet::new();
    let mut skipped = Vec::new();
    let mut ran = 0;
    let later_text: Vec<String> = (0..steps.len())
        .map(|i| {
            steps[i + 1..]
                .iter()
                .filter_map(|s| match s {
                    Step::Run(c) => Some(c.as_str()),
                    Step::Save { .. } => None,
                })
                .collect::<Vec<_>>()
                .join("\n")
        })
        .collect();
    for (i, step) in steps.into_iter().enumerate() {
        let command = match step {
            Step::Save { path, text } => {
                let target = ws.dir.path().join(&path);
                std::fs::create_dir_all(target.parent().unwrap()).unwrap();
                std::fs::write(target, text).unwrap();
                continue;
            }
            Step::Run(command) => command.replace("cargo run --release -- ", "platen "),
        };
        let skip = |reason: String, skipped: &mut Vec<String>| {
            let line = format!("{name}: not run: `{command}`: {reason}");
            println!("{line}");
            skipped.push(line);
        };
        if let Some(reason) = not_run(&command) {
            missing.extend(written_paths(&command));
            skip(reason, &mut skipped);
            continue;
        }
        let read_later = written_paths(&command)
            .iter()
            .any(|p| later_text[i].contains(p.as_str()));
        if done.contains(&command) && !read_later {
            skip(
                "the same command ran earlier (and nothing later on this page reads its output)"
                    .into(),
                &mut skipped,
            );
            continue;
        }
        if let Some(input) = missing.iter().find(|m| command.contains(m.as_str())) {
            let reason = format!("it reads `{input}`, which a command not run would have written");
            missing.extend(written_paths(&command));
            skip(reason, &mut skipped);
            continue;
        }
        // A shell variable set on its own line (`S="--scale …"`) holds for the page's later
        // lines.
        let assignment = command.split_once('=').is_some_and(|(var, value)| {
            !var.is_empty()
                && var.chars().all(|c| c == '_' || c.is_ascii_alphanumeric())
                && (!value.contains(char::is_whitespace)
                    || (value.starts_with('"')
                        && value.ends_with('"')
                        && value.matches('"').count() == 2))
        });
        if assignment {
            assignments.push_str(&command);
            assignments.push('\n');
            continue;
        }
        let script = format!("set -e\n{assignments}{command}\n");
        // bash, the shell the pages are written for (`time VAR=1 platen …` is its keyword).
        let mut sh = Command::new(if on_path("bash") { "bash" } else { "sh" });
        sh.arg("-c")
            .arg(&script)
            .current_dir(ws.dir.path())
            .env("PATH", &ws.path)
            .env("CI", "1");
        match &records {
            Some(r) => sh.env("PLATEN_RECORDS_DIR", r),
            None => sh.env_remove("PLATEN_RECORDS_DIR"),
        };
        let start = Instant::now();
        let o = sh.output().expect("run sh");
        let took = start.elapsed().as_secs_f64();
        let stderr = String::from_utf8_lossy(&o.stderr);
        if !o.status.success() && records.is_none() && stderr.contains("PLATEN_RECORDS_DIR") {
            missing.extend(written_paths(&command));
            skip(
                "it needs a PEER record and PLATEN_RECORDS_DIR is unset".into(),
                &mut skipped,
            );
            continue;
        }
        assert!(
            o.status.success(),
            "{name}: `{command}` failed ({}):\n{stderr}",
            o.status
        );
        println!("{name}: ran `{command}` in {took:.1} s");
        done.insert(command);
        ran += 1;
    }
    (ran, skipped)
}

#[test]
fn every_command_of_the_readme_and_docs_runs_as_written() {
    let mut ran = 0;
    let mut skipped = Vec::new();
    let mut done = BTreeSet::new();
    for page in pages() {
        let (r, s) = run_page(&page, &mut done);
        ran += r;
        skipped.extend(s);
    }
    println!("{ran} commands ran, {} not run:", skipped.len());
    for s in &skipped {
        println!("  {s}");
    }
    // The README alone has a dozen platen commands; a parser that finds few checks nothing.
    assert!(ran >= 25, "only {ran} commands ran");
}

#[test]
fn the_parser_joins_continuations_and_finds_saved_files() {
    let page = "Text.\n\n```sh\n# a comment\nplaten compare a.json \\\n    --plot out/f   # figures\ncargo run --release -- model\n```\n\nSave as `out/x.json`:\n\n```json\n{\"a\": 1}\n```\n\n```console\n$ platen model --json\n{\"effective_mass_kg\": 1}\n```\n";
    assert_eq!(
        steps(page),
        [
            Step::Run("platen compare a.json --plot out/f".into()),
            Step::Run("cargo run --release -- model".into()),
            Step::Save {
                path: "out/x.json".into(),
                text: "{\"a\": 1}\n".into()
            },
            Step::Run("platen model --json".into()),
        ]
    );
    assert!(not_run("cargo install --path .").is_some());
    assert!(not_run("python3 -m venv out/venv && out/venv/bin/pip install .").is_some());
    assert!(not_run("platen simulate s.json").is_none());
    assert_eq!(
        written_paths("platen identify --system a.csv --json > out/id.json"),
        ["out/id.json"]
    );
}
