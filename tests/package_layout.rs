//! The workspace's shape as a user meets it: the `platen` binary is a target of the root
//! package (so `cargo install --path .` installs it), and `cargo build` / `cargo run` build the
//! root package alone. The Python extension (crates/platen-py, PyO3) is built by `pip install
//! .` and by `cargo test --workspace`, never by `cargo run`, and no crate the binary links
//! depends on it (which would pull PyO3 into the command-line tool).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

use serde_json::Value;

/// The host's target triple (`rustc -vV`).
fn host() -> String {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let out = Command::new(rustc)
        .arg("-vV")
        .output()
        .expect("rustc -vV runs");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .expect("rustc -vV names the host")
        .to_string()
}

/// `cargo metadata` of this workspace for the host's platform (offline: the build that runs
/// this test has fetched every package the host needs, though not the other platforms'
/// dependencies, such as `android_system_properties`, that an unfiltered resolve would read).
fn metadata(no_deps: bool) -> Value {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.args(["metadata", "--format-version", "1", "--offline"])
        .args(["--filter-platform", &host()])
        .current_dir(env!("CARGO_MANIFEST_DIR"));
    if no_deps {
        cmd.arg("--no-deps");
    }
    let out = cmd.output().expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "cargo metadata failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("cargo metadata prints JSON")
}

fn root_id(m: &Value) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    m["packages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| Path::new(p["manifest_path"].as_str().unwrap()) == root)
        .expect("the root package is in the metadata")["id"]
        .as_str()
        .unwrap()
        .to_owned()
}

#[test]
fn the_binary_is_a_target_of_the_root_package_with_its_source_inside_it() {
    let m = metadata(true);
    let id = root_id(&m);
    let root = m["packages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["id"] == id.as_str())
        .unwrap();
    assert_eq!(root["name"], "platen");
    let bin = root["targets"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["kind"].as_array().unwrap().iter().any(|k| k == "bin"))
        .expect("the root package has a binary target");
    assert_eq!(bin["name"], "platen");
    let src = Path::new(bin["src_path"].as_str().unwrap());
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    assert!(
        src.starts_with(&dir),
        "the binary's source {} lies outside the root package's src/",
        src.display()
    );
    // Every member is a real package: no folder under crates/ is a bare source tree.
    let members: BTreeSet<String> = m["packages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            Path::new(p["manifest_path"].as_str().unwrap())
                .parent()
                .unwrap()
                .to_path_buf()
                .display()
                .to_string()
        })
        .collect();
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates");
    for entry in std::fs::read_dir(&crates).unwrap() {
        let dir = entry.unwrap().path();
        if dir.is_dir() {
            assert!(
                members.contains(&dir.display().to_string()),
                "{} is a folder under crates/ that is not a workspace package",
                dir.display()
            );
        }
    }
}

#[test]
fn cargo_run_builds_the_root_package_only() {
    let m = metadata(true);
    let defaults: Vec<&str> = m["workspace_default_members"]
        .as_array()
        .expect("cargo metadata lists the default members (cargo 1.71 or newer)")
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(defaults, [root_id(&m).as_str()]);
}

#[test]
fn nothing_the_binary_links_depends_on_the_python_extension() {
    let m = metadata(false);
    let root = root_id(&m);
    let nodes: BTreeMap<&str, Vec<&str>> = m["resolve"]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| {
            let deps = n["deps"]
                .as_array()
                .unwrap()
                .iter()
                // Normal (and build) dependencies: what `cargo build` compiles.
                .filter(|d| {
                    d["dep_kinds"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .any(|k| k["kind"].is_null() || k["kind"] == "build")
                })
                .map(|d| d["pkg"].as_str().unwrap())
                .collect();
            (n["id"].as_str().unwrap(), deps)
        })
        .collect();
    let mut seen = BTreeSet::new();
    let mut todo = vec![root.as_str()];
    while let Some(id) = todo.pop() {
        if seen.insert(id) {
            todo.extend(nodes[id].iter().copied());
        }
    }
    for id in &seen {
        assert!(
            !id.contains("platen-py") && !id.contains("#pyo3"),
            "the binary's build pulls in {id}"
        );
    }
    assert!(seen.len() > 10, "the walk found the dependencies");
}
