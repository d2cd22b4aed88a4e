//! The documentation names only what exists. `README.md` and every
//! `docs/**/*.md` are scanned for
//! - relative link targets (`[text](path)`, images too): the file or directory exists,
//!   relative to the page;
//! - repository paths in backticks (inline code and shell code blocks): a token with a
//!   '/' that ends in '/' or in an extension (`scenes/paper-E2E1-5-interacting.toml`,
//!   `tests/it/`) exists, relative to the repository root (or to the page). Outputs and
//!   build products (`out/`, `target/`, `run/`, `runs/`), files inside an .x3p archive
//!   (`bindata/`), absolute paths, URLs and placeholders (`DIR`, `NAME`, `…`, `<…>`, `*`,
//!   `{a,b}`, `$VAR`, `~`) are skipped;
//! - `cargo test [-p P] --test X [FILTER]` and `cargo bench -p P --bench B` (and
//!   `--example E`): P is a workspace package with that target (the targets cargo would
//!   find: `[[test]]`/`[[bench]]`/`[[example]]` and the auto-discovered files); a filter
//!   `MODULE::` of the integration-test binary `it` names a module of `tests/it/`;
//! - `strata SUBCOMMAND` in inline code and shell code blocks: SUBCOMMAND is one that
//!   `strata --help` lists.
//!
//! Every problem is reported as `page:line: what`, all at once.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::support::repo;

/// README.md and every docs/**/*.md, as paths relative to the repository root.
fn pages() -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .filter_map(|e| e.ok())
            .map(|e| e.path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(root, &p, out);
            } else if p.extension().is_some_and(|e| e == "md") {
                let rel = p.strip_prefix(root).expect("below the root");
                out.push(rel.to_string_lossy().into_owned());
            }
        }
    }
    let root = repo();
    let mut out = vec!["README.md".to_string()];
    walk(&root, &root.join("docs"), &mut out);
    out
}

/// A piece of a page to check: its first line (1-based) and its text.
struct Piece {
    line: usize,
    text: String,
}

/// A page split into prose (outside fenced code blocks), inline code spans and the
/// lines of shell code blocks (`sh`, `bash`, `shell`, `console` or no language; lines
/// continued with a trailing '\' joined, `#` comments removed).
struct Split {
    prose: Vec<Piece>,
    spans: Vec<Piece>,
    shell: Vec<Piece>,
}

fn split(text: &str) -> Split {
    let mut prose = Vec::new();
    let mut shell = Vec::new();
    let mut fence: Option<String> = None;
    let mut pending: Option<Piece> = None;
    let mut para: Option<Piece> = None;
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let trimmed = line.trim_start();
        if let Some(rest) = trimmed.strip_prefix("```") {
            if fence.is_some() {
                fence = None;
            } else {
                if let Some(p) = para.take() {
                    prose.push(p);
                }
                fence = Some(rest.trim().to_lowercase());
            }
            continue;
        }
        match &fence {
            Some(lang) => {
                if !matches!(lang.as_str(), "" | "sh" | "bash" | "shell" | "console") {
                    continue;
                }
                let code = strip_comment(line);
                let (body, continued) = match code.trim_end().strip_suffix('\\') {
                    Some(b) => (b.to_string(), true),
                    None => (code.to_string(), false),
                };
                let piece = pending.get_or_insert(Piece {
                    line: n,
                    text: String::new(),
                });
                piece.text.push(' ');
                piece.text.push_str(&body);
                if !continued {
                    shell.extend(pending.take());
                }
            }
            None => {
                if line.trim().is_empty() {
                    prose.extend(para.take());
                } else {
                    let p = para.get_or_insert(Piece {
                        line: n,
                        text: String::new(),
                    });
                    p.text.push_str(line);
                    p.text.push('\n');
                }
            }
        }
    }
    prose.extend(para.take());
    shell.extend(pending.take());
    let spans = prose.iter().flat_map(code_spans).collect();
    Split {
        prose,
        spans,
        shell,
    }
}

/// A shell line without its `#` comment (a '#' at the start or after whitespace).
fn strip_comment(line: &str) -> &str {
    let b = line.as_bytes();
    for (i, &c) in b.iter().enumerate() {
        if c == b'#' && (i == 0 || b[i - 1].is_ascii_whitespace()) {
            return &line[..i];
        }
    }
    line
}

/// The inline code spans of a paragraph (a run of n backticks up to the next run of
/// exactly n), newlines in a span read as spaces.
fn code_spans(p: &Piece) -> Vec<Piece> {
    let t = p.text.as_bytes();
    let run = |i: usize| t[i..].iter().take_while(|&&c| c == b'`').count();
    let mut out = Vec::new();
    let mut i = 0;
    while i < t.len() {
        if t[i] != b'`' {
            i += 1;
            continue;
        }
        let n = run(i);
        let start = i + n;
        let mut j = start;
        let mut end = None;
        while j < t.len() {
            if t[j] == b'`' {
                let m = run(j);
                if m == n {
                    end = Some(j);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match end {
            Some(e) => {
                let line = p.line + p.text[..start].matches('\n').count();
                out.push(Piece {
                    line,
                    text: p.text[start..e].replace('\n', " "),
                });
                i = e + n;
            }
            None => i = start,
        }
    }
    out
}

/// `[text](target)` link targets of a paragraph, with their lines.
fn links(p: &Piece) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut rest = p.text.as_str();
    let mut offset = 0;
    while let Some(k) = rest.find("](") {
        let after = &rest[k + 2..];
        if let Some(close) = after.find(')') {
            let target = &after[..close];
            if !target.contains(char::is_whitespace) {
                let line = p.line + p.text[..offset + k].matches('\n').count();
                out.push((line, target.to_string()));
            }
        }
        offset += k + 2;
        rest = &rest[k + 2..];
    }
    out
}

/// Paths named in code that are outputs, build products or inside a file, not in the
/// repository.
const NOT_IN_REPOSITORY: [&str; 5] = ["out/", "target/", "run/", "runs/", "bindata/"];

/// A token of code that names a repository path, trimmed of surrounding punctuation;
/// None for anything else (see the module docs).
fn repository_path(token: &str) -> Option<&str> {
    let t = token.trim_matches(|c: char| "\"'(),;:`".contains(c));
    if !t.contains('/') || t.contains("://") || t.starts_with('/') || t.starts_with('-') {
        return None;
    }
    if ["…", "...", "<", ">", "*", "{", "$", "~", "="]
        .iter()
        .any(|p| t.contains(p))
    {
        return None;
    }
    if NOT_IN_REPOSITORY.iter().any(|p| t.starts_with(p)) {
        return None;
    }
    let last = t.rsplit('/').next().unwrap_or("");
    let has_extension = last.rsplit_once('.').is_some_and(|(stem, ext)| {
        !stem.is_empty()
            && (1..=8).contains(&ext.len())
            && ext.chars().all(|c| c.is_ascii_alphanumeric())
    });
    if !(t.ends_with('/') || has_extension) {
        return None;
    }
    // Placeholders: a component (or its stem) in capitals, e.g. DIR/, NAME.md, KK.
    let placeholder = t.split('/').any(|c| {
        let stem = c.split('.').next().unwrap_or("");
        stem.len() >= 2 && stem.chars().all(|ch| ch.is_ascii_uppercase() || ch == '_')
    });
    (!placeholder).then_some(t)
}

/// The test, bench and example targets of one workspace package, as cargo finds them.
#[derive(Default)]
struct Targets {
    tests: BTreeSet<String>,
    benches: BTreeSet<String>,
    examples: BTreeSet<String>,
}

/// Every workspace package (name → its targets), from the manifests.
fn packages() -> BTreeMap<String, Targets> {
    let read = |p: &Path| -> toml::Table {
        let text = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        text.parse()
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
    };
    let root = repo();
    let ws = read(&root.join("Cargo.toml"));
    let members = ws["workspace"]["members"]
        .as_array()
        .expect("workspace.members");
    let mut out = BTreeMap::new();
    for m in members {
        let dir = root.join(m.as_str().expect("member path"));
        let manifest = read(&dir.join("Cargo.toml"));
        let package = manifest["package"].as_table().expect("[package]");
        let name = package["name"].as_str().expect("package.name").to_string();
        let auto = |key: &str| package.get(key).and_then(|v| v.as_bool()) != Some(false);
        let declared = |kind: &str| -> BTreeSet<String> {
            manifest
                .get(kind)
                .and_then(|v| v.as_array())
                .into_iter()
                .flatten()
                .filter_map(|t| t.get("name").and_then(|n| n.as_str()).map(String::from))
                .collect()
        };
        // Auto-discovery: dir/*.rs and dir/*/main.rs.
        let discovered = |sub: &str| -> BTreeSet<String> {
            let mut found = BTreeSet::new();
            for e in std::fs::read_dir(dir.join(sub))
                .into_iter()
                .flatten()
                .flatten()
            {
                let p = e.path();
                let name = p.file_stem().map(|s| s.to_string_lossy().into_owned());
                if p.is_dir() && p.join("main.rs").is_file() {
                    found.extend(p.file_name().map(|s| s.to_string_lossy().into_owned()));
                } else if p.extension().is_some_and(|x| x == "rs") {
                    found.extend(name);
                }
            }
            found
        };
        let mut t = Targets {
            tests: declared("test"),
            benches: declared("bench"),
            examples: declared("example"),
        };
        if auto("autotests") {
            t.tests.extend(discovered("tests"));
        }
        if auto("autobenches") {
            t.benches.extend(discovered("benches"));
        }
        if auto("autoexamples") {
            t.examples.extend(discovered("examples"));
        }
        out.insert(name, t);
    }
    out
}

/// The subcommands `strata --help` lists, and the developers' hidden ones.
fn subcommands() -> BTreeSet<String> {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
        .arg("--help")
        .output()
        .expect("run strata --help");
    assert!(o.status.success(), "strata --help failed");
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    let list: BTreeSet<String> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(String::from))
        .collect();
    assert!(
        list.contains("solve"),
        "no command list in `strata --help`:\n{help}"
    );
    // the developers' command, hidden from the user's list, is real
    for dev in DEVELOPER_COMMANDS {
        assert!(!list.contains(dev), "`strata --help` lists `{dev}`");
    }
    let mut list = list;
    for dev in DEVELOPER_COMMANDS {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
            .args([dev, "--help"])
            .output()
            .expect("run strata DEV --help");
        assert!(o.status.success(), "strata {dev} --help failed");
        list.insert(dev.to_string());
    }
    list
}

/// Subcommands for the developers (the accuracy–cost study, the K_t/K_n figures):
/// runnable, not listed by `strata --help`.
const DEVELOPER_COMMANDS: [&str; 2] = ["study", "ratio-map"];

/// Checks the cargo commands of one piece of code (the text after each `cargo test`,
/// `cargo bench`, `cargo run`, up to a shell separator).
fn check_cargo(
    code: &str,
    packages: &BTreeMap<String, Targets>,
    it_modules: &BTreeSet<String>,
    problems: &mut Vec<String>,
) {
    let tokens: Vec<&str> = code.split_whitespace().collect();
    for (i, w) in tokens.windows(2).enumerate() {
        // An install that ignores Cargo.lock re-resolves every dependency to the newest
        // semver-compatible version, not the tested ones: the docs show `--locked`.
        if w[0] == "cargo" && w[1] == "install" {
            let locked = tokens[i + 2..]
                .iter()
                .take_while(|t| !matches!(**t, "&&" | "||" | ";" | "|"))
                .any(|t| *t == "--locked");
            if !locked {
                problems.push(
                    "`cargo install` without `--locked` (ignores Cargo.lock: untested versions)"
                        .to_string(),
                );
            }
            continue;
        }
        if w[0] != "cargo" || !matches!(w[1], "test" | "bench" | "run" | "build") {
            continue;
        }
        let cmd = w[1];
        let args: Vec<&str> = tokens[i + 2..]
            .iter()
            .copied()
            .take_while(|t| !matches!(*t, "&&" | "||" | ";" | "|"))
            .collect();
        let (own, harness) = match args.iter().position(|t| *t == "--") {
            Some(k) => (&args[..k], &args[k + 1..]),
            None => (&args[..], &[][..]),
        };
        let mut selected: Vec<&str> = Vec::new();
        let mut workspace = false;
        let mut wanted: Vec<(&str, &str)> = Vec::new(); // (kind, name)
        let mut filters: Vec<&str> = Vec::new();
        let mut k = 0;
        while k < own.len() {
            let t = own[k];
            let value = own.get(k + 1).copied();
            match t {
                "-p" | "--package" => {
                    selected.extend(value);
                    k += 1;
                }
                "--workspace" | "--all" => workspace = true,
                "--test" | "--bench" | "--example" => {
                    if let Some(v) = value {
                        wanted.push((t, v));
                    }
                    k += 1;
                }
                "--features" | "--profile" | "--target-dir" | "-j" | "--jobs" => k += 1,
                _ if !t.starts_with('-') && cmd == "test" => filters.push(t),
                _ => {}
            }
            k += 1;
        }
        filters.extend(harness.iter().copied().filter(|t| !t.starts_with('-')));
        let placeholder = |s: &str| {
            s.contains('…') || s.contains('*') || s.contains("...") || s == "NAME" || s == "P"
        };
        if selected.iter().any(|p| placeholder(p)) {
            continue;
        }
        let missing: Vec<&&str> = selected
            .iter()
            .filter(|p| !packages.contains_key(**p))
            .collect();
        for p in &missing {
            problems.push(format!("`cargo {cmd} -p {p}`: no workspace package {p}"));
        }
        if !missing.is_empty() {
            continue;
        }
        let scope: Vec<&Targets> = if workspace {
            packages.values().collect()
        } else if selected.is_empty() {
            packages.get("strata").into_iter().collect()
        } else {
            selected.iter().filter_map(|p| packages.get(*p)).collect()
        };
        let in_scope = if workspace {
            "the workspace".to_string()
        } else if selected.is_empty() {
            "package strata".to_string()
        } else {
            format!("package {}", selected.join(", "))
        };
        for (kind, name) in &wanted {
            let name = name.trim_matches(|c| c == '\'' || c == '"');
            if placeholder(name) {
                continue;
            }
            let found = scope.iter().any(|t| match *kind {
                "--test" => t.tests.contains(name),
                "--bench" => t.benches.contains(name),
                _ => t.examples.contains(name),
            });
            if !found {
                problems.push(format!(
                    "`cargo {cmd} … {kind} {name}`: no such target in {in_scope}"
                ));
            }
        }
        // Filters of the integration tests' one binary: `MODULE::…` names a module.
        let on_it = wanted.iter().any(|(k, n)| *k == "--test" && *n == "it")
            && !workspace
            && (selected.is_empty() || selected == ["strata"]);
        if on_it {
            for f in filters {
                if let Some((module, _)) = f.split_once("::")
                    && !placeholder(module)
                    && !module.chars().any(|c| c.is_ascii_uppercase())
                    && !it_modules.contains(module)
                {
                    problems.push(format!(
                        "`cargo test --test it {f}`: no module {module} in tests/it/"
                    ));
                }
            }
        }
    }
}

/// Checks that a `strata SUBCOMMAND` in a piece of code names a real subcommand.
fn check_strata(code: &str, subcommands: &BTreeSet<String>, problems: &mut Vec<String>) {
    let tokens: Vec<&str> = code.split_whitespace().collect();
    for w in tokens.windows(2) {
        let word = w[0].trim_start_matches(['"', '(', '`']);
        if word != "strata" {
            continue;
        }
        let next = w[1];
        let is_word = next.chars().next().is_some_and(|c| c.is_ascii_lowercase())
            && next.chars().all(|c| c.is_ascii_lowercase() || c == '-');
        if is_word && !subcommands.contains(next) {
            problems.push(format!(
                "`strata {next}`: not a subcommand (strata --help lists {})",
                subcommands.iter().cloned().collect::<Vec<_>>().join(", ")
            ));
        }
    }
}

/// Runs every check on the pages; `page:line: problem` for each failure.
fn problems_in(pages: &[String]) -> Vec<String> {
    let root = repo();
    let packages = packages();
    let subcommands = subcommands();
    let it_modules: BTreeSet<String> = std::fs::read_dir(root.join("tests/it"))
        .expect("tests/it")
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let p = e.path();
            (p.extension().is_some_and(|x| x == "rs"))
                .then(|| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .flatten()
        })
        .collect();
    let mut out = Vec::new();
    for page in pages {
        let text =
            std::fs::read_to_string(root.join(page)).unwrap_or_else(|e| panic!("{page}: {e}"));
        let dir: PathBuf = root.join(page).parent().expect("a directory").to_path_buf();
        let s = split(&text);
        let mut problems: Vec<(usize, String)> = Vec::new();
        for p in &s.prose {
            for (line, target) in links(p) {
                let target = target.trim_start_matches('<').trim_end_matches('>');
                if target.contains("://")
                    || target.starts_with('#')
                    || target.starts_with("mailto:")
                {
                    continue;
                }
                let file = target.split('#').next().unwrap_or("");
                if !dir.join(file).exists() {
                    problems.push((line, format!("link target {target} does not exist")));
                }
            }
        }
        for piece in s.spans.iter().chain(&s.shell) {
            for token in piece.text.split_whitespace() {
                if let Some(path) = repository_path(token)
                    && !root.join(path).exists()
                    && !dir.join(path).exists()
                {
                    problems.push((piece.line, format!("`{path}` is not in the repository")));
                }
            }
            let mut found = Vec::new();
            check_cargo(&piece.text, &packages, &it_modules, &mut found);
            check_strata(&piece.text, &subcommands, &mut found);
            problems.extend(found.into_iter().map(|f| (piece.line, f)));
        }
        problems.sort();
        problems.dedup();
        out.extend(
            problems
                .into_iter()
                .map(|(l, p)| format!("{page}:{l}: {p}")),
        );
    }
    out
}

#[test]
fn docs_name_only_what_exists() {
    let pages = pages();
    for must in [
        "README.md",
        "docs/README.md",
        "docs/guide/solve.md",
        "docs/validation.md",
    ] {
        assert!(pages.iter().any(|p| p == must), "{must} is not scanned");
    }
    let problems = problems_in(&pages);
    assert!(
        problems.is_empty(),
        "stale paths or commands in the documentation ({}):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

/// The cluster guide's scripts, `docs/cluster/*.sbatch` and `*.sh`.
fn cluster_scripts() -> Vec<PathBuf> {
    let dir = repo().join("docs/cluster");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "sbatch" || x == "sh"))
        .collect();
    out.sort();
    out
}

/// A shell script's logical lines (a trailing '\\' joins the next), with the first
/// line's number.
fn logical_lines(text: &str) -> Vec<(usize, String)> {
    let mut out: Vec<(usize, String)> = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let (body, continued) = match line.trim_end().strip_suffix('\\') {
            Some(b) => (b, true),
            None => (line, false),
        };
        let p = pending.get_or_insert((i + 1, String::new()));
        p.1.push(' ');
        p.1.push_str(body);
        if !continued {
            out.extend(pending.take());
        }
    }
    out.extend(pending);
    out
}

/// The words of one line of shell code as the shell passes them to a command: quotes
/// removed, every parameter expansion (`$x`, `${x}`, `${x:-default}`, `$1`) read as
/// "1", operators (`&&`, `||`, `;`, `|`, redirections) as words of their own.
fn shell_words(code: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut w: Option<String> = None;
    let mut quote: Option<char> = None;
    let mut chars = code.chars().peekable();
    while let Some(c) = chars.next() {
        match (quote, c) {
            (Some('\''), '\'') => quote = None,
            (Some('\''), _) => w.get_or_insert_default().push(c),
            (_, '$') => {
                match chars.peek() {
                    Some('{') => {
                        let mut depth = 0;
                        for d in chars.by_ref() {
                            depth += match d {
                                '{' => 1,
                                '}' => -1,
                                _ => 0,
                            };
                            if depth == 0 {
                                break;
                            }
                        }
                    }
                    Some('(') => {
                        let mut depth = 0;
                        for d in chars.by_ref() {
                            depth += match d {
                                '(' => 1,
                                ')' => -1,
                                _ => 0,
                            };
                            if depth == 0 {
                                break;
                            }
                        }
                    }
                    _ => {
                        while chars
                            .peek()
                            .is_some_and(|d| d.is_ascii_alphanumeric() || *d == '_')
                        {
                            chars.next();
                        }
                    }
                }
                w.get_or_insert_default().push('1');
            }
            (Some('"'), '"') => quote = None,
            (Some(_), _) => w.get_or_insert_default().push(c),
            (None, '"' | '\'') => {
                quote = Some(c);
                w.get_or_insert_default();
            }
            (None, c) if c.is_whitespace() => words.extend(w.take()),
            (None, ';' | '|' | '&' | '>' | '<') => {
                words.extend(w.take());
                words.push(c.to_string());
            }
            (None, _) => w.get_or_insert_default().push(c),
        }
    }
    words.extend(w);
    words
}

/// The `strata …` command of a line of shell code, as its argument vector (up to the
/// first operator), if the line runs strata.
fn strata_command(code: &str) -> Option<Vec<String>> {
    let words = shell_words(code);
    let start = words.iter().position(|w| w == "strata")?;
    Some(
        words[start..]
            .iter()
            .take_while(|w| !matches!(w.as_str(), ";" | "|" | "&" | ">" | "<"))
            .cloned()
            .collect(),
    )
}

/// Every repository path a cluster script names (comments included) exists, and every
/// `strata` command line in them parses with strata's own command-line parser (shell
/// parameters read as "1"): the scripts the cluster guide ships stay runnable as the
/// commands change. tests/it/cluster.rs runs them.
#[test]
fn cluster_scripts_name_only_what_exists() {
    use clap::Parser;
    let root = repo();
    let scripts = cluster_scripts();
    let names: Vec<String> = scripts
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for must in [
        "solve.sbatch",
        "sweep.sbatch",
        "merge.sbatch",
        "submit-sweep.sh",
    ] {
        assert!(
            names.iter().any(|n| n == must),
            "docs/cluster/{must} missing"
        );
    }
    let mut problems = Vec::new();
    let mut commands = 0;
    for (script, name) in scripts.iter().zip(&names) {
        let text = std::fs::read_to_string(script).unwrap();
        for (n, line) in logical_lines(&text) {
            let spaced = line.replace(":-", " ");
            for token in spaced.split(|c: char| c.is_whitespace() || "\"'{}()=".contains(c)) {
                if let Some(path) = repository_path(token)
                    && !root.join(path).exists()
                {
                    problems.push(format!(
                        "docs/cluster/{name}:{n}: `{path}` is not in the repository"
                    ));
                }
            }
            let Some(argv) = strata_command(strip_comment(&line)) else {
                continue;
            };
            commands += 1;
            if let Err(e) = strata::cli::Cli::try_parse_from(&argv) {
                problems.push(format!(
                    "docs/cluster/{name}:{n}: `{}` does not parse: {}",
                    argv.join(" "),
                    e.to_string().lines().next().unwrap_or("")
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    // solve, sweep (one task), merge
    assert!(commands >= 3, "{commands} strata command lines found");
}

/// The script checker reads the shell as the shell does, and catches a stale option.
#[test]
fn cluster_script_checker_finds_stale_commands() {
    use clap::Parser;
    assert_eq!(
        shell_words(r#"srun strata solve "$scene" --out "${2:-runs/x}" >log && echo '$x'"#),
        [
            "srun", "strata", "solve", "1", "--out", "1", ">", "log", "&", "&", "echo", "$x"
        ]
    );
    let lines = logical_lines("a \\\n  b\nc\n");
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[0].0, 1);
    assert_eq!(lines[1].0, 3);
    let parse = |code: &str| strata::cli::Cli::try_parse_from(strata_command(code).unwrap());
    assert!(parse(r#"strata sweep "$s" --out "$r" --shard "${I}/${N}" --threads 4"#).is_ok());
    assert!(parse(r#"strata sweep merge "$r" --out "$r/sweep.csv""#).is_ok());
    assert!(parse(r#"srun strata solve "$scene" --out "$out" --no-plots"#).is_ok());
    // a misspelt option, a missing required argument, an unknown subcommand
    assert!(parse(r#"strata sweep "$s" --out "$r" --shards 1/2"#).is_err());
    assert!(parse(r#"strata solve --out "$out""#).is_err());
    assert!(parse("strata merge runs").is_err());
    assert_eq!(strata_command("echo done"), None);
}

/// The checker finds each kind of stale reference the README had (so that a clean run
/// means something), and lets the current spellings through.
#[test]
fn stale_references_are_found() {
    let packages = packages();
    let subcommands = subcommands();
    let it_modules: BTreeSet<String> = ["hard_cases".to_string()].into();
    let mut p = Vec::new();
    check_cargo(
        "cargo test --test hard_cases -- --nocapture",
        &packages,
        &it_modules,
        &mut p,
    );
    check_cargo(
        "cargo test -p strata-runtime --test table_fuzz",
        &packages,
        &it_modules,
        &mut p,
    );
    check_cargo(
        "cargo bench -p strata-runtime --bench rough",
        &packages,
        &it_modules,
        &mut p,
    );
    check_cargo(
        "cargo bench -p strata-bench --bench rough",
        &packages,
        &it_modules,
        &mut p,
    );
    check_cargo(
        "cargo test --test it nomodule::",
        &packages,
        &it_modules,
        &mut p,
    );
    check_strata("strata solv scene.toml", &subcommands, &mut p);
    check_cargo("cargo install --path .", &packages, &it_modules, &mut p);
    assert_eq!(p.len(), 7, "{p:#?}");
    // And these are fine.
    let mut ok = Vec::new();
    check_cargo(
        "cargo test --test it hard_cases:: -- --nocapture && cargo bench -p strata-benches --bench rough -- scaling",
        &packages,
        &it_modules,
        &mut ok,
    );
    check_cargo(
        "cargo test -p strata-capi --test c_example",
        &packages,
        &it_modules,
        &mut ok,
    );
    check_strata("strata solve s.toml --out out/x", &subcommands, &mut ok);
    check_cargo(
        "cargo install --locked --path .",
        &packages,
        &it_modules,
        &mut ok,
    );
    assert!(ok.is_empty(), "{ok:#?}");
    for (token, checked) in [
        (
            "`runtime/tests/stack_fuzz.rs`",
            Some("runtime/tests/stack_fuzz.rs"),
        ),
        ("tests/it/", Some("tests/it/")),
        ("DIR/curve.csv", None),
        ("out/paper/curve.csv", None),
        ("https://example.org/a.html", None),
        ("a/h", None),
        ("target/release/libstrata_capi.{so,a}", None),
    ] {
        assert_eq!(repository_path(token), checked, "{token}");
    }
    assert!(!repo().join("runtime/tests/stack_fuzz.rs").exists());
}
