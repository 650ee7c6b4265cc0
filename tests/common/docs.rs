//! The shell commands of the README and of `docs/*.md`, as the docs tests read them: the
//! pages, their steps (commands and files to save), what a command writes, and a tree copy.
//! Used by tests/readme.rs (commands write only under `out/`, the quick start runs) and
//! tests/docs_commands.rs (every command runs as written).

use std::path::{Path, PathBuf};

/// The repository's root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The Markdown pages the check covers: the README and every page under `docs/`.
pub fn pages() -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    docs.insert(0, root().join("README.md"));
    docs
}

/// One step of a page: a command line, or a file the page asks to save.
#[derive(Debug, PartialEq)]
pub enum Step {
    /// A command line (continuations joined).
    Run(String),
    /// A JSON block the page asks to save at `path` (under `out/`).
    Save {
        /// Where, relative to the repository.
        path: String,
        /// The block.
        text: String,
    },
}

/// The steps of a Markdown page in order: the lines of its shell blocks (continuations
/// joined, comments and blank lines left out, only the `$ ` lines of a console block) and the
/// JSON blocks introduced by “Save as `out/…`”.
pub fn steps(markdown: &str) -> Vec<Step> {
    let mut steps = Vec::new();
    let mut block: Option<(String, Option<String>)> = None;
    let mut body = String::new();
    let mut pending = String::new();
    // The text paragraph before a block (blank lines between them allowed).
    let mut paragraph = String::new();
    let mut after_blank = false;
    for line in markdown.lines() {
        if let Some(fence) = line.trim_start().strip_prefix("```") {
            match block.take() {
                Some((lang, save)) => {
                    if lang == "json" {
                        if let Some(path) = save {
                            steps.push(Step::Save {
                                path,
                                text: std::mem::take(&mut body),
                            });
                        }
                    }
                    body.clear();
                }
                None => {
                    let lang = fence.trim().to_owned();
                    let save = paragraph
                        .rsplit_once("Save as `")
                        .and_then(|(_, rest)| rest.split_once('`'))
                        .map(|(path, _)| path.to_owned())
                        .filter(|p| p.starts_with("out/"));
                    block = Some((lang, save));
                    paragraph.clear();
                }
            }
            continue;
        }
        let Some((lang, _)) = &block else {
            if line.trim().is_empty() {
                after_blank = true;
            } else {
                if after_blank {
                    paragraph.clear();
                    after_blank = false;
                }
                paragraph.push_str(line);
                paragraph.push(' ');
            }
            continue;
        };
        if lang == "json" {
            body.push_str(line);
            body.push('\n');
            continue;
        }
        if !matches!(lang.as_str(), "sh" | "bash" | "console" | "shell") {
            continue;
        }
        let line = if lang == "console" {
            match line.trim_start().strip_prefix("$ ") {
                Some(command) => command,
                None if !pending.is_empty() => line,
                None => continue,
            }
        } else {
            line
        };
        let line = match line.find(" # ") {
            Some(i) if !in_quotes(&line[..i]) => &line[..i],
            _ => line,
        };
        let line = line.trim();
        if pending.is_empty() && (line.is_empty() || line.starts_with('#')) {
            continue;
        }
        match line.strip_suffix('\\') {
            Some(head) => {
                pending.push_str(head.trim_end());
                pending.push(' ');
            }
            None => {
                pending.push_str(line);
                steps.push(Step::Run(std::mem::take(&mut pending)));
            }
        }
    }
    steps
}

/// The command lines of a page's shell blocks, in order ([`steps`] without the saved files).
pub fn commands(markdown: &str) -> Vec<String> {
    steps(markdown)
        .into_iter()
        .filter_map(|s| match s {
            Step::Run(c) => Some(c),
            Step::Save { .. } => None,
        })
        .collect()
}

/// Whether `text` leaves a quote open (so a `#` after it is inside a string).
fn in_quotes(text: &str) -> bool {
    text.chars().filter(|&c| c == '"').count() % 2 == 1
        || text.chars().filter(|&c| c == '\'').count() % 2 == 1
}

/// The arguments that name something a command writes: the values of `--out`, `--plot`,
/// `--report` and `-o`, a virtual environment's folder and a redirection's target.
pub fn written_paths(command: &str) -> Vec<String> {
    let words: Vec<&str> = command.split_whitespace().collect();
    let mut paths = Vec::new();
    for (i, w) in words.iter().enumerate() {
        let names_output = matches!(*w, "--out" | "--plot" | "--report" | "-o" | ">" | ">>")
            || (*w == "venv" && i > 0 && words[i - 1] == "-m");
        if names_output {
            let value = words.get(i + 1).copied().unwrap_or("");
            paths.push(value.to_owned());
        }
    }
    paths
}

/// Copies the tree `from` to `to` (created).
pub fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let target = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_tree(&p, &target);
        } else {
            std::fs::copy(&p, &target).unwrap();
        }
    }
}
