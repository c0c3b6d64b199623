//! No import cycle among the files of `src/handeye` (docs/architecture.md):
//! the stages import the input and result types and each other downwards,
//! never the orchestrator that imports them. Every path a file names
//! (`crate::handeye::..`, `super::..`, `self::..`, a child module in a
//! `use`) is resolved to the file that defines the item, through the `pub
//! use` re-exports of `mod.rs` (which are not imports of their own); a
//! cycle among those edges is named file by file. Library code only: test
//! files and `#[cfg(test)]` items sit above everything and import freely.

use super::{code_only, rust_files, test_lines};
use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;

/// A module path below `crate`, e.g. `["handeye", "refine", "over_poses"]`.
type Module = Vec<String>;

/// The module a file under `src` is: `a/mod.rs` is `a`, `a/b.rs` is `a::b`.
fn module_of(rel: &Path) -> Module {
    let mut m: Module = rel
        .components()
        .map(|c| {
            c.as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string()
        })
        .collect();
    if m.last().is_some_and(|l| l == "mod") {
        m.pop();
    }
    m
}

/// `a::{b, c::{d, e as f}}` as `[a::b, a::c::d, a::c::e]` (aliases dropped).
fn expand(tree: &str) -> Vec<Vec<String>> {
    let mut compact = String::new();
    let mut alias = false;
    for w in tree.split_whitespace() {
        if alias {
            compact.push_str(w.trim_start_matches(|c: char| c.is_alphanumeric() || c == '_'));
            alias = false;
        } else if w == "as" {
            alias = true;
        } else {
            compact.push_str(w);
        }
    }
    expand_compact(&compact)
}

/// [`expand`] of a tree without white space or aliases.
fn expand_compact(tree: &str) -> Vec<Vec<String>> {
    let Some(open) = tree.find('{') else {
        return vec![tree
            .split("::")
            .filter(|s| !s.is_empty())
            .map(str::to_string)
            .collect()];
    };
    let prefix = &tree[..open];
    let inner = tree[open + 1..]
        .strip_suffix('}')
        .unwrap_or(&tree[open + 1..]);
    super::split_braced_items(inner)
        .iter()
        .filter(|i| !i.is_empty())
        .flat_map(|i| expand_compact(&format!("{prefix}{i}")))
        .collect()
}

/// The path trees named in `code`: `(tree, in a use, a pub use)`, from every
/// `use ...;` and every inline `crate::` / `super::` / `self::` path.
fn paths(code: &str) -> Vec<(String, bool, bool)> {
    let b = code.as_bytes();
    let word = |i: usize| {
        b.get(i)
            .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
    };
    let mut found = Vec::new();
    let mut used_span = Vec::new();
    let mut i = 0;
    while let Some(at) = code[i..].find("use ").map(|k| k + i) {
        i = at + 4;
        if at > 0 && (word(at - 1) || b[at - 1] == b'$') {
            continue;
        }
        let Some(end) = code[at..].find(';').map(|k| k + at) else {
            break;
        };
        let start = code[..at].rfind([';', '{', '}']).map_or(0, |k| k + 1);
        let head = code[start..at].trim();
        let head = head.rsplit(']').next().unwrap_or(head).trim();
        found.push((code[at + 4..end].to_string(), true, head.starts_with("pub")));
        used_span.push((at, end));
        i = end;
    }
    for root in ["crate::", "super::", "self::"] {
        for (at, _) in code.match_indices(root) {
            if (at > 0 && (word(at - 1) || b[at - 1] == b'$' || b[at - 1] == b':'))
                || used_span.iter().any(|&(s, e)| at > s && at < e)
            {
                continue;
            }
            let (mut end, mut depth) = (at, 0);
            for (k, ch) in code[at..].char_indices() {
                match ch {
                    '{' => depth += 1,
                    '}' if depth > 0 => depth -= 1,
                    ':' | '_' | '*' => {}
                    ',' | ' ' | '\n' if depth > 0 => {}
                    c if c.is_alphanumeric() => {}
                    _ if depth > 0 => {}
                    _ => break,
                }
                end = at + k + ch.len_utf8();
            }
            found.push((code[at..end].to_string(), false, false));
        }
    }
    found
}

/// `segments` named in `module` as an absolute module path, or `None` for a
/// path outside the crate.
fn absolute(
    module: &Module,
    segments: &[String],
    files: &BTreeMap<Module, String>,
) -> Option<Module> {
    let (first, rest) = segments.split_first()?;
    let mut at = module.clone();
    match first.as_str() {
        "crate" => return Some(rest.to_vec()),
        "self" => {}
        "super" => {
            at.pop();
            let mut rest = rest;
            while rest.first().is_some_and(|s| s == "super") {
                at.pop();
                rest = &rest[1..];
            }
            at.extend(rest.iter().cloned());
            return Some(at);
        }
        child => {
            at.push(child.to_string());
            if !files.contains_key(&at) {
                return None;
            }
            at.extend(rest.iter().cloned());
            return Some(at);
        }
    }
    at.extend(rest.iter().cloned());
    Some(at)
}

/// The file module that defines `path`, following re-exports.
fn resolve(
    path: &[String],
    files: &BTreeMap<Module, String>,
    reexports: &BTreeMap<(Module, String), Module>,
    depth: usize,
) -> Option<Module> {
    let k = (1..=path.len())
        .rev()
        .find(|&k| files.contains_key(&path[..k]))?;
    let module = path[..k].to_vec();
    if let Some(item) = path.get(k) {
        if let Some(target) = reexports.get(&(module.clone(), item.clone())) {
            if depth < 16 {
                let mut next = target.clone();
                next.extend(path[k + 1..].iter().cloned());
                return resolve(&next, files, reexports, depth + 1);
            }
        }
    }
    Some(module)
}

/// The import edges among the library files of `src/<part>`, each file as
/// its path (`src/handeye/solve.rs`).
fn import_graph(src: &Path, part: &str) -> BTreeMap<String, BTreeSet<String>> {
    let mut all = Vec::new();
    rust_files(&src.join(part), &mut all);
    let mut files = BTreeMap::new();
    let mut codes = Vec::new();
    for path in all {
        let rel = path.strip_prefix(src).unwrap_or(&path).to_path_buf();
        let name = rel
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        if name == "tests.rs" || name.ends_with("_tests.rs") {
            continue;
        }
        let shown = format!("src/{}", rel.display()).replace('\\', "/");
        let text = fs::read_to_string(&path).unwrap_or_default();
        let code = code_only(&text);
        let tests = test_lines(&code);
        let library: Vec<&str> = code
            .lines()
            .zip(tests.iter().chain(std::iter::repeat(&false)))
            .map(|(line, &t)| if t { "" } else { line })
            .collect();
        let module = module_of(&rel);
        files.insert(module.clone(), shown);
        codes.push((module, library.join("\n")));
    }
    let mut reexports = BTreeMap::new();
    let mut uses = Vec::new();
    for (module, code) in &codes {
        for (tree, in_use, public) in paths(code) {
            for segments in expand(&tree) {
                let mut segments = segments;
                if segments.last().is_some_and(|s| s == "*") {
                    segments.pop();
                }
                let named = if in_use
                    || segments
                        .first()
                        .is_some_and(|s| s == "crate" || s == "super" || s == "self")
                {
                    absolute(module, &segments, &files)
                } else {
                    None
                };
                let Some(named) = named else { continue };
                if !named.first().is_some_and(|p| p == part) {
                    continue;
                }
                if public && in_use {
                    if let Some(last) = named.last() {
                        reexports.insert((module.clone(), last.clone()), named.clone());
                    }
                } else {
                    uses.push((module.clone(), named));
                }
            }
        }
    }
    let mut graph: BTreeMap<String, BTreeSet<String>> = files
        .values()
        .map(|f| (f.clone(), BTreeSet::new()))
        .collect();
    for (module, named) in uses {
        let Some(target) = resolve(&named, &files, &reexports, 0) else {
            continue;
        };
        if target != module {
            if let (Some(from), Some(to)) = (files.get(&module), files.get(&target)) {
                graph.entry(from.clone()).or_default().insert(to.clone());
            }
        }
    }
    graph
}

/// Every import cycle of `graph`, each as `a -> b -> ... -> a` (one per
/// strongly connected group of files, along a shortest way round, the
/// whole group named when it holds more files).
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    let reach = |from: &str| -> BTreeMap<String, String> {
        // Breadth first: each file reached, with the file it was reached from.
        let mut came = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([from.to_string()]);
        while let Some(f) = queue.pop_front() {
            for t in graph.get(&f).into_iter().flatten() {
                if !came.contains_key(t) {
                    came.insert(t.clone(), f.clone());
                    queue.push_back(t.clone());
                }
            }
        }
        came
    };
    let mut seen = BTreeSet::new();
    let mut found = Vec::new();
    for file in graph.keys() {
        if seen.contains(file) {
            continue;
        }
        let came = reach(file);
        if !came.contains_key(file) {
            continue;
        }
        let mut way = vec![file.clone()];
        let mut at = came[file].clone();
        while &at != file {
            way.push(at.clone());
            at = came[&at].clone();
        }
        way.push(file.clone());
        way.reverse();
        // The whole group of files on a cycle through `file`.
        let group: Vec<&String> = came
            .keys()
            .filter(|f| reach(f).contains_key(file))
            .collect();
        seen.extend(group.iter().map(|f| (*f).clone()));
        let mut named = way.join(" -> ");
        if group.len() + 1 > way.len() {
            let all: Vec<&str> = group.iter().map(|f| f.as_str()).collect();
            named += &format!(
                " (a group of {} files that import each other: {})",
                group.len(),
                all.join(", ")
            );
        }
        found.push(named);
    }
    found
}

#[test]
fn no_import_cycle_among_the_files_of_handeye() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = import_graph(&src, "handeye");
    assert!(
        graph.len() > 20,
        "found only {} files under src/handeye",
        graph.len()
    );
    assert!(
        graph["src/handeye/solve.rs"].contains("src/handeye/refine/over_poses.rs"),
        "the orchestrator's imports are seen"
    );
    let found = cycles(&graph);
    assert!(
        found.is_empty(),
        "{} import cycle(s) among the files of src/handeye (docs/architecture.md: the \
         stages never import the orchestrator; shared types go to input.rs / result.rs):\n{}",
        found.len(),
        found.join("\n")
    );
}

/// A small tree whose refiner imports the result type through the root's
/// re-export of the orchestrator: the cycle is named; with the type in a
/// file of its own it is gone.
#[test]
fn an_import_cycle_through_a_reexport_is_named() {
    let root = std::env::temp_dir().join(format!("robocal-cycles-{}", std::process::id()));
    let write = |files: &[(&str, &str)]| {
        let _ = fs::remove_dir_all(&root);
        for (path, text) in files {
            let path = root.join(path);
            if let Some(dir) = path.parent() {
                fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{e}"));
            }
            fs::write(&path, text).unwrap_or_else(|e| panic!("{e}"));
        }
    };
    write(&[
        ("handeye/mod.rs", "pub mod refine;\npub mod solve;\npub use solve::{calibrate, Found};\n"),
        ("handeye/solve.rs", "use crate::handeye::refine::{self, over_poses::refine};\npub struct Found;\npub fn calibrate() { refine(); }\n"),
        ("handeye/refine/mod.rs", "pub mod over_poses;\n"),
        ("handeye/refine/over_poses.rs", "use super::super::Found; // crate::handeye::solve\npub fn refine() -> crate::handeye::Found { Found }\n#[cfg(test)]\nmod tests {\n    use crate::handeye::calibrate;\n}\n"),
    ]);
    let found = cycles(&import_graph(&root, "handeye"));
    assert_eq!(
        found,
        ["src/handeye/refine/over_poses.rs -> src/handeye/solve.rs -> src/handeye/refine/over_poses.rs"]
    );
    write(&[
        ("handeye/mod.rs", "pub mod refine;\npub mod result;\npub mod solve;\npub use result::Found;\npub use solve::calibrate;\n"),
        ("handeye/result.rs", "pub struct Found;\n"),
        ("handeye/solve.rs", "use crate::handeye::refine::over_poses::refine;\npub fn calibrate() { refine(); }\n"),
        ("handeye/refine/mod.rs", "pub mod over_poses;\n"),
        ("handeye/refine/over_poses.rs", "use crate::handeye::Found;\npub fn refine() -> Found { Found }\n"),
    ]);
    let graph = import_graph(&root, "handeye");
    let _ = fs::remove_dir_all(&root);
    assert!(graph["src/handeye/refine/over_poses.rs"].contains("src/handeye/result.rs"));
    assert!(cycles(&graph).is_empty());
}

/// The path reader: grouped and nested imports, aliases and globs.
#[test]
fn paths_and_groups_are_read() {
    assert_eq!(
        expand("crate::handeye::{a::B, c::{d, e as f}, *}"),
        [
            ["crate", "handeye", "a", "B"].map(String::from).to_vec(),
            ["crate", "handeye", "c", "d"].map(String::from).to_vec(),
            ["crate", "handeye", "c", "e"].map(String::from).to_vec(),
            ["crate", "handeye", "*"].map(String::from).to_vec(),
        ]
    );
    let found = paths("pub(crate) use x::Y;\nfn f() -> crate::a::B { super::c(); }\n");
    assert_eq!(
        found,
        [
            ("x::Y".to_string(), true, true),
            ("crate::a::B".to_string(), false, false),
            ("super::c".to_string(), false, false),
        ]
    );
}
