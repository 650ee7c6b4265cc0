//! The README's promises about its own commands: the quick start runs top to bottom, and every
//! command in the README and in `docs/` writes only under `out/`, which git ignores.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

mod common;

use common::docs::{commands, copy_tree, pages, root, written_paths};

#[test]
fn every_command_of_the_readme_and_docs_writes_under_out() {
    let mut checked = 0;
    for doc in pages() {
        let text = std::fs::read_to_string(&doc).unwrap();
        for command in commands(&text) {
            for path in written_paths(&command) {
                assert!(
                    path.starts_with("out/") && !path.contains(".."),
                    "{}: `{command}` writes `{path}`, outside out/",
                    doc.display()
                );
                checked += 1;
            }
        }
    }
    // The README alone names a dozen outputs; a parser that finds none checks nothing.
    assert!(checked >= 12, "only {checked} outputs found");
    // out/ exists in a clone (its .gitignore is tracked) and git ignores everything else in it.
    let ignore = std::fs::read_to_string(root().join("out/.gitignore")).unwrap();
    let rules: Vec<&str> = ignore
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .collect();
    assert_eq!(rules, ["*", "!.gitignore"]);
}

#[test]
fn the_output_check_sees_a_command_that_writes_elsewhere() {
    let cmds = commands(
        "```sh\nplaten simulate s.json --out sr9.csv\nplaten compare a.json \\\n    --plot figs\n```\n",
    );
    assert_eq!(cmds.len(), 2);
    assert_eq!(written_paths(&cmds[0]), ["sr9.csv"]);
    assert_eq!(written_paths(&cmds[1]), ["figs"]);
    assert_eq!(
        written_paths("python3 -m venv out/venv && out/venv/bin/pip install ."),
        ["out/venv"]
    );
}

/// Every file under `dir` with its modification time.
fn snapshot(dir: &Path, into: &mut BTreeMap<PathBuf, SystemTime>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            snapshot(&p, into);
        } else {
            into.insert(p.clone(), p.metadata().unwrap().modified().unwrap());
        }
    }
}

/// The quick start's `platen` commands, in order, in a copy of the clone's `scenarios/` and
/// `out/`: each succeeds, and nothing outside `out/` is created or changed. (Its Python line
/// is what `.ci/run` does in its own virtual environment.)
#[test]
fn the_readme_quick_start_runs_top_to_bottom_and_writes_only_under_out() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let start = readme
        .find("\n## Quick start\n")
        .expect("a Quick start section");
    let section = &readme[start + 1..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    let commands: Vec<String> = commands(section)
        .into_iter()
        .filter(|c| c.starts_with("platen "))
        .filter(|c| {
            // A scenario that reads a PEER record (a `ground_motion`) cannot run here, where
            // PLATEN_RECORDS_DIR is removed: tests/docs_commands.rs runs it with the records.
            let needs_record = c.split_whitespace().any(|w| {
                w.ends_with(".json")
                    && std::fs::read_to_string(root().join(w))
                        .is_ok_and(|t| t.contains("\"ground_motion\""))
            });
            if needs_record {
                eprintln!("not run here (needs a PEER record): {c}");
            }
            !needs_record
        })
        .collect();
    assert!(commands.len() >= 4, "{commands:?}");

    let dir = tempfile::tempdir().unwrap();
    copy_tree(&root().join("scenarios"), &dir.path().join("scenarios"));
    std::fs::create_dir(dir.path().join("out")).unwrap();
    std::fs::copy(
        root().join("out/.gitignore"),
        dir.path().join("out/.gitignore"),
    )
    .unwrap();
    let mut before = BTreeMap::new();
    snapshot(dir.path(), &mut before);

    for command in &commands {
        let args: Vec<&str> = command.split_whitespace().skip(1).collect();
        let o = Command::new(env!("CARGO_BIN_EXE_platen"))
            .args(&args)
            .current_dir(dir.path())
            .env_remove("PLATEN_RECORDS_DIR")
            .output()
            .expect("run platen");
        assert!(
            o.status.success(),
            "`{command}`: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        for path in written_paths(command) {
            assert!(
                dir.path().join(&path).exists(),
                "`{command}` wrote no {path}"
            );
        }
    }

    let mut after = BTreeMap::new();
    snapshot(dir.path(), &mut after);
    let out = dir.path().join("out");
    for (path, modified) in &after {
        if !path.starts_with(&out) {
            assert_eq!(
                before.get(path),
                Some(modified),
                "{} was created or changed",
                path.display()
            );
        }
    }
    assert!(after.keys().filter(|p| p.starts_with(&out)).count() > commands.len());
}
