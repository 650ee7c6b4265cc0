//! `platen completions SHELL` prints a completion script that completes platen's verbs and
//! options in a real shell (bash, when the machine has it), and refuses an unknown shell.

mod common;

use common::platen;

/// Runs `script` in bash with the completion script of the built binary loaded; `None` when
/// the machine has no bash.
fn bash_completes(words: &[&str]) -> Option<Vec<String>> {
    let o = platen(&["completions", "bash"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("platen.bash");
    std::fs::write(&script, &o.stdout).unwrap();
    let cword = words.len() - 1;
    let quoted: Vec<String> = words.iter().map(|w| format!("'{w}'")).collect();
    let prev = if cword > 0 { words[cword - 1] } else { "" };
    let program = format!(
        "source '{}'; COMP_WORDS=({}); COMP_CWORD={cword}; _platen platen '{}' '{}'; printf '%s\\n' \"${{COMPREPLY[@]}}\"",
        script.display(),
        quoted.join(" "),
        words[cword],
        prev
    );
    let out = std::process::Command::new("bash")
        .arg("-c")
        .arg(program)
        .output()
        .ok()?;
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(str::to_owned)
            .collect(),
    )
}

#[test]
fn bash_completes_the_verbs_and_their_options() {
    let Some(verbs) = bash_completes(&["platen", "s"]) else {
        eprintln!("skipped: no bash on this machine");
        return;
    };
    assert_eq!(verbs, ["simulate", "schema", "scenarios", "sweep"]);
    let options = bash_completes(&["platen", "identify", "--no"]).unwrap();
    assert_eq!(
        options,
        [
            "--no-low-velocity-term",
            "--no-output-error",
            "--nonnegative-stiffness",
            "--no-prediction-error"
        ]
    );
}

#[test]
fn every_shell_gets_a_script_that_names_the_verbs() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let o = platen(&["completions", shell]);
        assert!(o.status.success(), "{shell}");
        let text = String::from_utf8(o.stdout).unwrap();
        for verb in ["simulate", "compare", "identify", "plan", "completions"] {
            assert!(text.contains(verb), "{shell}: no `{verb}`");
        }
    }
}

#[test]
fn an_unknown_shell_is_refused_with_the_choices() {
    let o = platen(&["completions", "tcsh"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bash, elvish, fish, powershell, zsh"), "{err}");
    assert!(o.stdout.is_empty());
}
