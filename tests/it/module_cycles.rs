//! Files inside a crate import one way: no two `.rs` files of any workspace
//! crate import each other, directly or through a cycle, and the AVX2 choice of the
//! boundary-element solver is made in one place.
//!
//! Every `.rs` file below each crate's `src/` is read as tokens (comments, strings and
//! char literals dropped). Its module path follows from the `mod` declarations (with
//! `#[path]`), starting at `lib.rs` and `main.rs`. A file imports another when one of
//! its paths — in `use` trees and in code: `crate::…`, `super::…`, `self::…`, or a
//! child module's name — resolves to an item defined in the other file. Resolution
//! descends through modules and follows `use` re-exports (`pub use` facades and
//! imported names alike) to the file that defines the item, so a parent that only
//! declares and re-exports its children imports nothing. `mod` declarations themselves
//! are not imports. A cycle of the resulting file graph (a strongly connected
//! component of more than one file) is reported with its files.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::support::repo;

/// One token of Rust source: an identifier (raw identifiers without `r#`), `::`, or
/// one punctuation character.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Tok {
    Ident(String),
    Path,
    Punct(char),
}

/// The tokens of `src` without comments, string, byte-string, raw-string and char
/// literals, lifetimes and numbers.
fn tokens(src: &str) -> Vec<Tok> {
    let b: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    let n = b.len();
    let ident_start = |c: char| c == '_' || c.is_alphabetic();
    let ident_char = |c: char| c == '_' || c.is_alphanumeric();
    while i < n {
        let c = b[i];
        if c.is_whitespace() {
            i += 1;
        } else if c == '/' && i + 1 < n && b[i + 1] == '/' {
            while i < n && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && i + 1 < n && b[i + 1] == '*' {
            let mut depth = 0;
            while i < n {
                if b[i] == '/' && i + 1 < n && b[i + 1] == '*' {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && i + 1 < n && b[i + 1] == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if (c == 'r' || c == 'b' || c == 'c')
            && raw_string_at(&b, i).is_some_and(|end| {
                i = end;
                true
            })
        {
        } else if c == '"' || ((c == 'b' || c == 'c') && i + 1 < n && b[i + 1] == '"') {
            i += if c == '"' { 1 } else { 2 };
            while i < n && b[i] != '"' {
                if b[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
        } else if c == '\'' || (c == 'b' && i + 1 < n && b[i + 1] == '\'') {
            let q = if c == '\'' { i } else { i + 1 };
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
            if q + 1 < n && b[q + 1] == '\\' {
                let mut j = q + 2;
                while j < n && b[j] != '\'' {
                    j += 1;
                }
                i = j + 1;
            } else if q + 2 < n && b[q + 2] == '\'' {
                i = q + 3;
            } else {
                i = q + 1;
                while i < n && ident_char(b[i]) {
                    i += 1;
                }
            }
        } else if ident_start(c) {
            let mut j = i;
            if c == 'r' && i + 2 < n && b[i + 1] == '#' && ident_start(b[i + 2]) {
                j += 2;
            }
            let s = j;
            while j < n && ident_char(b[j]) {
                j += 1;
            }
            out.push(Tok::Ident(b[s..j].iter().collect()));
            i = j;
        } else if c.is_ascii_digit() {
            while i < n
                && (ident_char(b[i]) || b[i] == '.' && i + 1 < n && b[i + 1].is_ascii_digit())
            {
                i += 1;
            }
        } else if c == ':' && i + 1 < n && b[i + 1] == ':' {
            out.push(Tok::Path);
            i += 2;
        } else {
            out.push(Tok::Punct(c));
            i += 1;
        }
    }
    out
}

/// The end of a raw (byte/C) string literal starting at `i` (`r"…"`, `r#"…"#`, `br"…"`).
fn raw_string_at(b: &[char], i: usize) -> Option<usize> {
    let mut j = i;
    if b[j] == 'b' || b[j] == 'c' {
        j += 1;
    }
    if b.get(j) != Some(&'r') {
        return None;
    }
    j += 1;
    let mut hashes = 0;
    while b.get(j) == Some(&'#') {
        hashes += 1;
        j += 1;
    }
    if b.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < b.len() {
        if b[j] == '"' && (0..hashes).all(|h| b.get(j + 1 + h) == Some(&'#')) {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(b.len())
}

/// A module of one crate: the files that hold it (more than one where `#[cfg]` picks
/// between `#[path]` files), its child modules, the names it defines, the names its
/// `use` declarations bind (to absolute paths), its glob imports, and the paths its
/// code names (absolute, with the file that names them).
#[derive(Default, Debug)]
struct Module {
    files: BTreeSet<String>,
    children: BTreeSet<String>,
    defined: BTreeSet<String>,
    bound: BTreeMap<String, Vec<Vec<String>>>,
    globs: Vec<Vec<String>>,
    uses: Vec<(String, Vec<String>)>,
}

/// A crate's modules by absolute path (the root is the empty path).
type Tree = BTreeMap<Vec<String>, Module>;

/// The child file of module `m` (held in `file`) named `name`, or at `#[path]`.
fn child_file(file: &Path, is_dir_owner: bool, name: &str, attr_path: Option<&str>) -> PathBuf {
    let dir = file.parent().expect("a file has a directory");
    if let Some(p) = attr_path {
        return if is_dir_owner {
            dir.join(p)
        } else {
            dir.join(file.file_stem().expect("a stem")).join(p)
        };
    }
    let base = if is_dir_owner {
        dir.to_path_buf()
    } else {
        dir.join(file.file_stem().expect("a stem"))
    };
    let flat = base.join(format!("{name}.rs"));
    if flat.is_file() {
        flat
    } else {
        base.join(name).join("mod.rs")
    }
}

/// Makes `path` (relative to module `at`) absolute; None for paths outside the crate
/// (`std::…`, other crates, `$crate`).
fn absolute(at: &[String], path: &[String], children: &BTreeSet<String>) -> Option<Vec<String>> {
    let first = path.first()?;
    let mut out: Vec<String>;
    let rest: &[String];
    match first.as_str() {
        "crate" => {
            out = Vec::new();
            rest = &path[1..];
        }
        "self" => {
            out = at.to_vec();
            rest = &path[1..];
        }
        "super" => {
            out = at.to_vec();
            let mut k = 0;
            while path.get(k).is_some_and(|s| s == "super") {
                out.pop()?;
                k += 1;
            }
            rest = &path[k..];
        }
        name if children.contains(name) => {
            out = at.to_vec();
            rest = path;
        }
        _ => return None,
    }
    out.extend(rest.iter().cloned());
    Some(out)
}

/// Parses a `use` tree at `toks[*i]` (after `use`), with `prefix` the path so far;
/// pushes (binding name or "*", path).
fn use_tree(
    toks: &[Tok],
    i: &mut usize,
    prefix: Vec<String>,
    out: &mut Vec<(String, Vec<String>)>,
) {
    let mut path = prefix;
    if toks.get(*i) == Some(&Tok::Path) {
        *i += 1;
    }
    loop {
        match toks.get(*i) {
            Some(Tok::Ident(s)) => {
                path.push(s.clone());
                *i += 1;
                match toks.get(*i) {
                    Some(Tok::Path) => {
                        *i += 1;
                        continue;
                    }
                    Some(Tok::Ident(a)) if a == "as" => {
                        *i += 1;
                        if let Some(Tok::Ident(alias)) = toks.get(*i) {
                            *i += 1;
                            let mut p = path.clone();
                            if p.last().is_some_and(|l| l == "self") {
                                p.pop();
                            }
                            out.push((alias.clone(), p));
                        }
                        return;
                    }
                    _ => {
                        let mut p = path.clone();
                        if p.last().is_some_and(|l| l == "self") {
                            p.pop();
                        }
                        let name = p.last().cloned().unwrap_or_default();
                        out.push((name, p));
                        return;
                    }
                }
            }
            Some(Tok::Punct('*')) => {
                *i += 1;
                out.push(("*".to_string(), path));
                return;
            }
            Some(Tok::Punct('{')) => {
                *i += 1;
                loop {
                    match toks.get(*i) {
                        Some(Tok::Punct('}')) => {
                            *i += 1;
                            return;
                        }
                        Some(Tok::Punct(',')) => *i += 1,
                        None => return,
                        _ => use_tree(toks, i, path.clone(), out),
                    }
                }
            }
            _ => return,
        }
    }
}

/// Reads `file` as module `at` into `tree`, and its child files recursively.
fn read_module(tree: &mut Tree, file: &Path, at: Vec<String>, root: &Path) {
    let rel = file
        .strip_prefix(root)
        .unwrap_or(file)
        .to_string_lossy()
        .into_owned();
    let src = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let toks = tokens(&src);
    let stem = file.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let dir_owner = matches!(stem, "mod" | "lib" | "main");
    // The module of each brace level (inline `mod name { … }` blocks push a level).
    let mut stack: Vec<(Vec<String>, usize)> = vec![(at.clone(), 0)];
    let mut depth = 0usize;
    let mut pending_inline: Option<Vec<String>> = None;
    let mut attr_path: Option<String> = None;
    let path_attrs = path_attributes(&src);
    let mut path_attr_seen = 0;
    let mut files_to_read: Vec<(PathBuf, Vec<String>)> = Vec::new();
    tree.entry(at.clone())
        .or_default()
        .files
        .insert(rel.clone());
    // First pass: modules, definitions and use declarations.
    let mut code_paths: Vec<(Vec<String>, Vec<String>)> = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        let cur = stack.last().expect("the file's module").0.clone();
        match &toks[i] {
            Tok::Punct('#') => {
                // `#[path = "…"]` before a `mod` (its string read from the text).
                if let (Some(Tok::Punct('[')), Some(Tok::Ident(a))) =
                    (toks.get(i + 1), toks.get(i + 2))
                    && a == "path"
                {
                    attr_path = path_attrs.get(path_attr_seen).cloned();
                    path_attr_seen += 1;
                }
                i += 1;
            }
            Tok::Punct('{') => {
                depth += 1;
                if let Some(m) = pending_inline.take() {
                    stack.push((m, depth));
                }
                i += 1;
            }
            Tok::Punct('}') => {
                if stack.len() > 1 && stack.last().is_some_and(|s| s.1 == depth) {
                    stack.pop();
                }
                depth = depth.saturating_sub(1);
                i += 1;
            }
            Tok::Ident(k) if k == "mod" => {
                if let Some(Tok::Ident(name)) = toks.get(i + 1) {
                    let mut child = cur.clone();
                    child.push(name.clone());
                    tree.entry(cur.clone())
                        .or_default()
                        .children
                        .insert(name.clone());
                    match toks.get(i + 2) {
                        Some(Tok::Punct(';')) if cur == at => {
                            let f = child_file(file, dir_owner, name, attr_path.as_deref());
                            files_to_read.push((f, child));
                        }
                        Some(Tok::Punct('{')) => {
                            tree.entry(child.clone())
                                .or_default()
                                .files
                                .insert(rel.clone());
                            pending_inline = Some(child);
                        }
                        _ => {}
                    }
                    attr_path = None;
                    i += 2;
                } else {
                    i += 1;
                }
            }
            Tok::Ident(k) if k == "use" => {
                // `pub use`, `pub(crate) use`: a re-export (a facade), not an import of
                // the file itself.
                let reexport = match i.checked_sub(1).map(|j| &toks[j]) {
                    Some(Tok::Ident(p)) => p == "pub",
                    Some(Tok::Punct(')')) => toks[..i]
                        .iter()
                        .rposition(|t| *t == Tok::Punct('('))
                        .is_some_and(|j| j > 0 && toks[j - 1] == Tok::Ident("pub".into())),
                    _ => false,
                };
                let mut entries = Vec::new();
                let mut j = i + 1;
                use_tree(&toks, &mut j, Vec::new(), &mut entries);
                let m = tree.entry(cur.clone()).or_default();
                let children = m.children.clone();
                for (name, p) in entries {
                    // Uniform paths: a `use` path starts at the crate, an ancestor, this
                    // module, or one of its children (declared before or after).
                    let Some(abs) = absolute(&cur, &p, &children).or_else(|| {
                        // A child declared later in the file.
                        let later = declared_children(&toks);
                        absolute(&cur, &p, &later)
                    }) else {
                        continue;
                    };
                    let m = tree.entry(cur.clone()).or_default();
                    if name == "*" {
                        m.globs.push(abs.clone());
                    } else {
                        m.bound.entry(name).or_default().push(abs.clone());
                    }
                    if !reexport {
                        m.uses.push((rel.clone(), abs));
                    }
                }
                i = j;
            }
            Tok::Ident(k)
                if matches!(
                    k.as_str(),
                    "fn" | "struct" | "enum" | "trait" | "type" | "const" | "static" | "union"
                ) =>
            {
                if let Some(Tok::Ident(name)) = toks.get(i + 1) {
                    tree.entry(cur.clone())
                        .or_default()
                        .defined
                        .insert(name.clone());
                }
                i += 1;
            }
            Tok::Ident(k) if k == "macro_rules" => {
                if let (Some(Tok::Punct('!')), Some(Tok::Ident(name))) =
                    (toks.get(i + 1), toks.get(i + 2))
                {
                    tree.entry(cur.clone())
                        .or_default()
                        .defined
                        .insert(name.clone());
                }
                i += 1;
            }
            Tok::Ident(first) => {
                // A path in code: crate::…, super::…, self::…, or child::… (not after `::`,
                // `$` or `.`).
                let prev = if i > 0 { toks.get(i - 1) } else { None };
                let after_path = matches!(
                    prev,
                    Some(Tok::Path) | Some(Tok::Punct('$')) | Some(Tok::Punct('.'))
                );
                let mut j = i;
                let mut p = vec![first.clone()];
                while toks.get(j + 1) == Some(&Tok::Path) {
                    if let Some(Tok::Ident(s)) = toks.get(j + 2) {
                        p.push(s.clone());
                        j += 2;
                    } else {
                        break;
                    }
                }
                if !after_path && p.len() > 1 {
                    code_paths.push((cur.clone(), p));
                }
                i = j + 1;
            }
            _ => i += 1,
        }
    }
    for (cur, p) in code_paths {
        let children = tree
            .get(&cur)
            .map(|m| m.children.clone())
            .unwrap_or_default();
        // `pub(in crate::x)` and the like are not imports; neither is the first segment
        // of a path that only names this module (`self::`).
        if let Some(abs) = absolute(&cur, &p, &children) {
            tree.entry(cur).or_default().uses.push((rel.clone(), abs));
        }
    }
    for (f, child) in files_to_read {
        assert!(f.is_file(), "{rel}: module file {} missing", f.display());
        read_module(tree, &f, child, root);
    }
}

/// The names of every `mod name` declared in a token stream.
fn declared_children(toks: &[Tok]) -> BTreeSet<String> {
    toks.windows(2)
        .filter_map(|w| match (&w[0], &w[1]) {
            (Tok::Ident(m), Tok::Ident(name)) if m == "mod" => Some(name.clone()),
            _ => None,
        })
        .collect()
}

/// The `#[path = "…"]` values of a file, in order (read from the text: the tokens drop
/// strings).
fn path_attributes(src: &str) -> Vec<String> {
    src.lines()
        .filter_map(|l| {
            let rest = l
                .trim()
                .strip_prefix("#[path")?
                .trim_start()
                .strip_prefix('=')?;
            let rest = rest.trim().strip_prefix('"')?;
            Some(rest[..rest.find('"')?].to_string())
        })
        .collect()
}

/// The files defining what `path` (absolute) names: the module's files when it names a
/// module, else the file of the module that defines the item, following `use`
/// bindings and globs.
fn resolve(tree: &Tree, path: &[String], depth: usize) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    if depth > 16 {
        return out;
    }
    let mut module: Vec<String> = Vec::new();
    for (k, seg) in path.iter().enumerate() {
        let Some(m) = tree.get(&module) else {
            return out;
        };
        if m.children.contains(seg) {
            module.push(seg.clone());
            continue;
        }
        // An item of `module`: defined there, bound by a `use`, or through a glob.
        if m.defined.contains(seg) {
            out.extend(m.files.iter().cloned());
            return out;
        }
        if let Some(targets) = m.bound.get(seg) {
            for t in targets {
                let mut full = t.clone();
                full.extend(path[k + 1..].iter().cloned());
                if full.as_slice() != path {
                    out.extend(resolve(tree, &full, depth + 1));
                }
            }
            if !out.is_empty() {
                return out;
            }
        }
        for g in &m.globs {
            let mut full = g.clone();
            full.extend(path[k..].iter().cloned());
            if full.as_slice() != path {
                out.extend(resolve(tree, &full, depth + 1));
            }
        }
        if out.is_empty() {
            // Not found (a macro-made item, an enum variant path, …): the module itself.
            out.extend(m.files.iter().cloned());
        }
        return out;
    }
    // The whole path names a module.
    if let Some(m) = tree.get(&module) {
        out.extend(m.files.iter().cloned());
    }
    out
}

/// The file import graph of one crate root (`lib.rs` or `main.rs`): file → imported
/// files, with one path that makes each edge (`crate::…`, for the message).
type Graph = BTreeMap<String, BTreeMap<String, String>>;

fn graph(root_file: &Path, root: &Path) -> Graph {
    let mut tree = Tree::new();
    read_module(&mut tree, root_file, Vec::new(), root);
    let mut g = Graph::new();
    for m in tree.values() {
        for f in &m.files {
            g.entry(f.clone()).or_default();
        }
        for (file, path) in &m.uses {
            for target in resolve(&tree, path, 0) {
                if &target != file {
                    g.entry(file.clone())
                        .or_default()
                        .entry(target)
                        .or_insert_with(|| format!("crate::{}", path.join("::")));
                }
            }
        }
    }
    g
}

/// The cycles of a graph: its strongly connected components of more than one file
/// (Tarjan), each with one closed path through it for the message.
fn cycles(g: &Graph) -> Vec<Vec<String>> {
    struct T<'g> {
        g: &'g Graph,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        on: BTreeSet<&'g str>,
        stack: Vec<&'g str>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    impl<'g> T<'g> {
        fn visit(&mut self, v: &'g str) {
            self.index.insert(v, self.next);
            self.low.insert(v, self.next);
            self.next += 1;
            self.stack.push(v);
            self.on.insert(v);
            for w in self.g.get(v).into_iter().flat_map(|m| m.keys()) {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let l = self.low[w].min(self.low[v]);
                    self.low.insert(v, l);
                } else if self.on.contains(w) {
                    let l = self.index[w].min(self.low[v]);
                    self.low.insert(v, l);
                }
            }
            if self.low[v] == self.index[v] {
                let mut comp = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on.remove(w);
                    comp.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if comp.len() > 1 {
                    comp.sort();
                    self.out.push(comp);
                }
            }
        }
    }
    let mut t = T {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        on: BTreeSet::new(),
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v.as_str()) {
            t.visit(v);
        }
    }
    t.out
}

/// A closed path inside one strongly connected component, from its first file.
fn closed_path(g: &Graph, comp: &[String]) -> String {
    let inside: BTreeSet<&str> = comp.iter().map(|s| s.as_str()).collect();
    let start = comp[0].as_str();
    // Breadth-first from the start's successors back to the start.
    let mut prev: BTreeMap<&str, &str> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::new();
    for w in g[start].keys() {
        if inside.contains(w.as_str()) && !prev.contains_key(w.as_str()) {
            prev.insert(w.as_str(), start);
            queue.push_back(w.as_str());
        }
    }
    while let Some(v) = queue.pop_front() {
        if v == start {
            break;
        }
        for w in g[v].keys() {
            if inside.contains(w.as_str()) && !prev.contains_key(w.as_str()) {
                prev.insert(w.as_str(), v);
                queue.push_back(w.as_str());
            }
        }
    }
    let mut path = vec![start];
    let mut v = prev.get(start).copied();
    while let Some(p) = v {
        path.push(p);
        if p == start {
            break;
        }
        v = prev.get(p).copied();
    }
    path.reverse();
    let mut out = path[0].to_string();
    for w in path.windows(2) {
        out.push_str(&format!(" -({})-> {}", g[w[0]][w[1]], w[1]));
    }
    out
}

/// Every crate root of the workspace: `*/src/lib.rs` and `*/src/main.rs` of the
/// members (the package directories with a `Cargo.toml` and a `src/`).
fn crate_roots() -> Vec<PathBuf> {
    let root = repo();
    let manifest =
        std::fs::read_to_string(root.join("Cargo.toml")).expect("the workspace manifest");
    let members = manifest
        .split("members")
        .nth(1)
        .and_then(|s| s.split('[').nth(1))
        .and_then(|s| s.split(']').next())
        .expect("workspace members");
    let mut out = Vec::new();
    for m in members.split(',') {
        let m = m.trim().trim_matches('"');
        if m.is_empty() {
            continue;
        }
        for f in ["src/lib.rs", "src/main.rs"] {
            let p = root.join(m).join(f);
            if p.is_file() {
                out.push(p);
            }
        }
    }
    out
}

/// All cycles of the workspace, as messages.
fn workspace_cycles() -> Vec<String> {
    let root = repo();
    let mut problems = Vec::new();
    for r in crate_roots() {
        let g = graph(&r, &root);
        for comp in cycles(&g) {
            problems.push(format!(
                "{}: files import each other: {} (e.g. {})",
                r.strip_prefix(&root).unwrap_or(&r).display(),
                comp.join(", "),
                closed_path(&g, &comp)
            ));
        }
    }
    problems
}

/// Cycles left, for now, to the work under way on their files: the files of
/// each, and what removes it. Any other cycle fails the test, and so does an entry that
/// is no longer a cycle (delete it then): the list only shrinks.
const KNOWN: &[(&[&str], &str)] = &[];

#[test]
fn no_file_imports_another_in_a_cycle() {
    let problems = workspace_cycles();
    let known = |p: &str| {
        KNOWN.iter().any(|(files, _)| {
            p.split_once("import each other: ")
                .and_then(|(_, rest)| rest.split(" (e.g.").next())
                .is_some_and(|list| list == files.join(", "))
        })
    };
    let new: Vec<&String> = problems.iter().filter(|p| !known(p)).collect();
    let gone: Vec<&str> = KNOWN
        .iter()
        .filter(|(files, _)| {
            !problems
                .iter()
                .any(|p| p.contains(&format!("import each other: {} (e.g.", files.join(", "))))
        })
        .map(|(files, _)| files[0])
        .collect();
    assert!(
        new.is_empty(),
        "{} import cycle(s) between files:\n{}",
        new.len(),
        new.iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
    assert!(
        gone.is_empty(),
        "no longer cycles: remove them from KNOWN in tests/it/module_cycles.rs: {gone:?}"
    );
}

/// The checker itself: a crate whose files import each other is caught, through
/// `use`, code paths, `super::` and re-exports alike; a parent that only declares and
/// re-exports is not.
#[test]
fn checker_finds_cycles() {
    let dir = crate::support::temp_dir("module-cycles");
    let src = dir.join("src");
    std::fs::create_dir_all(src.join("a")).expect("mkdir");
    let write = |p: &str, s: &str| std::fs::write(src.join(p), s).expect("write");
    write(
        "lib.rs",
        "mod a;\nmod b;\nmod c;\nmod leaf;\npub use b::B;\npub use leaf::Leaf;\n// crate::c::C in a comment\n",
    );
    write(
        "a/mod.rs",
        "mod inner;\npub(crate) fn a() { inner::f(); }\n",
    );
    write(
        "a/inner.rs",
        "pub(crate) fn f() { let _ = \"crate::b::B\"; }\n",
    );
    write(
        "b.rs",
        "use crate::Leaf;\npub struct B;\nfn g() { crate::c::h(); }\n",
    );
    write("c.rs", "pub(crate) fn h() { let _ = super::B; }\n");
    write("leaf.rs", "pub struct Leaf;\n");
    let g = graph(&src.join("lib.rs"), &dir);
    let found = cycles(&g);
    assert_eq!(
        found,
        vec![vec!["src/b.rs".to_string(), "src/c.rs".to_string()]],
        "{g:?}"
    );
    assert!(g["src/b.rs"].contains_key("src/leaf.rs"), "{g:?}");
    assert!(
        g["src/lib.rs"].is_empty(),
        "a facade imports nothing it re-exports: {g:?}"
    );
    assert!(
        !g["src/a/inner.rs"].contains_key("src/b.rs"),
        "strings are not paths: {g:?}"
    );
    assert!(g["src/a/mod.rs"].contains_key("src/a/inner.rs"), "{g:?}");
}

/// The boundary-element solver checks the CPU for AVX2 in one place (its kernel choice).
#[test]
fn bem_checks_for_avx2_in_one_place() {
    let src = repo().join("bem/src");
    let mut sites = Vec::new();
    let mut stack = vec![src.clone()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("bem/src").flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = std::fs::read_to_string(&p).expect("read");
                for (n, line) in text.lines().enumerate() {
                    let code = line.split("//").next().unwrap_or("");
                    if code.contains("is_x86_feature_detected!") {
                        sites.push(format!(
                            "{}:{}",
                            p.strip_prefix(repo()).unwrap_or(&p).display(),
                            n + 1
                        ));
                    }
                }
            }
        }
    }
    assert_eq!(sites.len(), 1, "AVX2 checked at: {sites:?}");
}
