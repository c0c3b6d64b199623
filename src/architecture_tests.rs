//! The layering rules of docs/architecture.md, checked from the source: every
//! `crate::MODULE` path of every file under src/ (in `use` lines and inline
//! paths, grouped `crate::{a, b}` imports included; comments and string
//! literals left out) against what its part may name, and the host APIs
//! (files, clock, environment, threads, printing, the browser) against the
//! parts that may touch a host. A failure names the file, the line, the
//! import and the rule it breaks.
//!
//! Test code (files named `tests.rs` or `*_tests.rs`, items under
//! `#[cfg(test)]`) may use the seeded generators of `synth` and read
//! fixtures; it still never breaks an import rule marked `everywhere`.

use std::fs;
use std::path::{Path, PathBuf};

mod cycle_tests;

/// Where a rule applies.
#[derive(Clone, Copy, PartialEq)]
enum Scope {
    /// Library and test code alike.
    Everywhere,
    /// Library code only: tests may use the synthetic scenes.
    Library,
}

/// Which crate modules a part may name.
enum Allowed {
    /// Only these (its own always).
    Only(&'static [&'static str]),
    /// Anything but these.
    Never(&'static [&'static str]),
}

/// A part (the first component of a path under src/: `calib`, `rng`, ...),
/// what it may import, where, and why.
struct Rule {
    part: &'static str,
    allowed: Allowed,
    scope: Scope,
    why: &'static str,
}

const RULES: &[Rule] = &[
    Rule {
        part: "geometry",
        allowed: Allowed::Only(&["error", "rng"]),
        scope: Scope::Everywhere,
        why: "geometry is the bottom: poses and rotations need nothing else",
    },
    Rule {
        part: "optim",
        allowed: Allowed::Only(&["error", "rng"]),
        scope: Scope::Everywhere,
        why: "the one Levenberg-Marquardt knows no model",
    },
    Rule {
        part: "rng",
        allowed: Allowed::Only(&[]),
        scope: Scope::Everywhere,
        why: "the seeded generator stands alone",
    },
    Rule {
        part: "camera",
        allowed: Allowed::Only(&["error", "geometry", "rng"]),
        scope: Scope::Everywhere,
        why: "the camera is maths: it never imports image (pixels) nor anything above it",
    },
    Rule {
        part: "image",
        allowed: Allowed::Only(&["error", "camera"]),
        scope: Scope::Everywhere,
        why: "image decodes and resamples pixels; it knows cameras, not targets or detectors",
    },
    Rule {
        part: "target",
        allowed: Allowed::Only(&["error", "camera", "geometry", "rng"]),
        scope: Scope::Everywhere,
        why: "target is the plain-data seam between detection and solving",
    },
    Rule {
        part: "detect",
        allowed: Allowed::Never(&["calib", "handeye", "workflows", "io", "capture", "wasm"]),
        scope: Scope::Everywhere,
        why: "detection turns images into detections and knows no solver",
    },
    Rule {
        part: "detect",
        allowed: Allowed::Never(&["synth"]),
        scope: Scope::Library,
        why: "detection never depends on the renderer (tests may render)",
    },
    Rule {
        part: "calib",
        allowed: Allowed::Never(&["detect", "image", "capture", "wasm"]),
        scope: Scope::Everywhere,
        why: "the solvers never see pixels: corner lists in, reports out",
    },
    Rule {
        part: "handeye",
        allowed: Allowed::Never(&["detect", "image", "capture", "wasm"]),
        scope: Scope::Everywhere,
        why: "the solvers never see pixels: corner lists in, reports out",
    },
    Rule {
        part: "calib",
        allowed: Allowed::Never(&["synth"]),
        scope: Scope::Library,
        why: "the solvers never depend on the synthetic scenes (tests may)",
    },
    Rule {
        part: "handeye",
        allowed: Allowed::Never(&["synth"]),
        scope: Scope::Library,
        why: "the solvers never depend on the synthetic scenes (the bootstrap draws from rng)",
    },
    Rule {
        part: "workflows",
        allowed: Allowed::Never(&["detect", "image", "capture", "synth", "wasm"]),
        scope: Scope::Library,
        why: "the workflows are solvers too: points in, fits out",
    },
    Rule {
        part: "io",
        allowed: Allowed::Never(&["detect", "image", "capture", "synth", "wasm"]),
        scope: Scope::Library,
        why: "io is text in, text out: it knows types, not pixels or detectors",
    },
    Rule {
        part: "capture",
        allowed: Allowed::Never(&["synth", "wasm"]),
        scope: Scope::Library,
        why: "live capture uses the board placement of target, not the renderer",
    },
    Rule {
        part: "synth",
        allowed: Allowed::Never(&["capture", "wasm"]),
        scope: Scope::Everywhere,
        why: "the synthetic scenes serve tests and the demo, never a host",
    },
    Rule {
        part: "laser",
        allowed: Allowed::Never(&["calib", "handeye", "workflows", "io", "capture", "wasm"]),
        scope: Scope::Everywhere,
        why: "the laser stripe and plane are their own solver: pixels and points in, a plane out",
    },
    Rule {
        part: "laser",
        allowed: Allowed::Never(&["synth"]),
        scope: Scope::Library,
        why: "the laser solver never depends on the renderer (tests may render stripes)",
    },
    Rule {
        part: "api",
        allowed: Allowed::Never(&["wasm"]),
        scope: Scope::Everywhere,
        why: "the request/report layer is called by the hosts, never the other way",
    },
];

/// Parts that may call the request/report layer `api`: the hosts (and
/// `api` itself). Every other part sits below it and never reaches up
/// (library code; tests may drive a solver through its request).
const API_CALLERS: &[&str] = &["api", "wasm", "main", "cli"];

/// Parts that may touch a host (files, clock, environment, threads,
/// printing, the browser).
const HOST_PARTS: &[&str] = &["wasm", "main", "cli"];

/// What touching a host looks like in the code.
const HOST_APIS: &[&str] = &[
    "std::fs",
    "std::env",
    "std::net",
    "std::process",
    "std::thread",
    "std::time",
    "SystemTime",
    "Instant",
    "web_sys",
    "js_sys",
    "wasm_bindgen",
    "rayon",
    "println!",
    "eprintln!",
    "print!",
    "eprint!",
];

/// The Rust files under `dir`, sorted.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `text` with comments removed and string and char literals emptied, line
/// breaks kept (so line numbers and braces can be trusted).
fn code_only(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let at = |k: usize| c.get(k).copied().unwrap_or('\0');
    let keep_newlines = |s: &[char], out: &mut String| {
        out.extend(s.iter().filter(|&&ch| ch == '\n'));
    };
    while i < c.len() {
        if c[i] == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && at(i + 1) == '*' {
            let (start, mut depth) = (i, 0usize);
            while i < c.len() {
                if c[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            keep_newlines(&c[start..i.min(c.len())], &mut out);
        } else if c[i] == 'r'
            && (at(i + 1) == '"' || (at(i + 1) == '#' && (at(i + 2) == '"' || at(i + 2) == '#')))
            && !(i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_'))
        {
            // A raw string r"..." or r#"..."#.
            let start = i;
            i += 1;
            let mut hashes = 0;
            while at(i) == '#' {
                hashes += 1;
                i += 1;
            }
            i += 1; // the opening quote
            while i < c.len() {
                if c[i] == '"' && (1..=hashes).all(|k| at(i + k) == '#') {
                    i += 1 + hashes;
                    break;
                }
                i += 1;
            }
            keep_newlines(&c[start..i.min(c.len())], &mut out);
            out.push_str("\"\"");
        } else if c[i] == '"' {
            let start = i;
            i += 1;
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
            keep_newlines(&c[start..i.min(c.len())], &mut out);
            out.push_str("\"\"");
        } else if c[i] == '\'' && (at(i + 1) == '\\' || at(i + 2) == '\'') {
            // A char literal ('x', '\n', '\u{..}'); a lifetime stays.
            i += 1;
            while i < c.len() && c[i] != '\'' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("' '");
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// For each line of `code` (from [`code_only`]), whether it is test code:
/// the items under an attribute `#[cfg(...test...)]` (not `not(test)`).
fn test_lines(code: &str) -> Vec<bool> {
    let lines: Vec<&str> = code.lines().collect();
    let mut test = vec![false; lines.len()];
    let mut l = 0;
    while l < lines.len() {
        let t = lines[l].trim();
        let is_test_cfg = t.starts_with("#[cfg(")
            && t.split(|ch: char| !(ch.is_alphanumeric() || ch == '_'))
                .any(|w| w == "test")
            && !t.contains("not(test)");
        if !is_test_cfg {
            l += 1;
            continue;
        }
        // The item: through its `;` or its matching closing brace.
        let mut depth = 0i32;
        let mut opened = false;
        let mut k = l;
        'item: while k < lines.len() {
            test[k] = true;
            let body = if k == l { "" } else { lines[k] };
            for ch in body.chars() {
                match ch {
                    '{' => {
                        depth += 1;
                        opened = true;
                    }
                    '}' => depth -= 1,
                    ';' if !opened && depth == 0 => break 'item,
                    _ => {}
                }
            }
            if opened && depth <= 0 {
                break;
            }
            k += 1;
        }
        l = k + 1;
    }
    test
}

/// The crate modules `line` names: `crate::x`, and `crate::{x::.., y}`.
fn crate_modules(line: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut rest = line;
    while let Some(at) = rest.find("crate::") {
        let before = rest[..at].chars().last();
        let after = &rest[at + "crate::".len()..];
        rest = after;
        if before.is_some_and(|b| b.is_alphanumeric() || b == '_' || b == '$') {
            continue;
        }
        if let Some(group) = after.strip_prefix('{') {
            let items = split_braced_items(group);
            found.extend(items.iter().map(|s| leading_ident(s.trim())));
        } else {
            found.push(leading_ident(after));
        }
    }
    found.retain(|m| !m.is_empty());
    found
}

fn leading_ident(s: &str) -> String {
    s.chars()
        .take_while(|ch| ch.is_alphanumeric() || *ch == '_')
        .collect()
}

/// Whether `line` uses the host API `api` (as a whole word).
fn uses(line: &str, api: &str) -> bool {
    line.match_indices(api).any(|(at, _)| {
        let before = line[..at].chars().last();
        let after = line[at + api.len()..].chars().next();
        let word = |ch: Option<char>| ch.is_some_and(|c| c.is_alphanumeric() || c == '_');
        !word(before) && (api.ends_with('!') || !word(after))
    })
}

/// Every break of [`RULES`] and [`HOST_APIS`] in the files under `src`.
fn violations(src: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut found = Vec::new();
    for path in files {
        let rel = path.strip_prefix(src).unwrap_or(&path);
        let shown = format!("src/{}", rel.display()).replace('\\', "/");
        let part = rel
            .components()
            .next()
            .map(|c| {
                c.as_os_str()
                    .to_string_lossy()
                    .trim_end_matches(".rs")
                    .to_string()
            })
            .unwrap_or_default();
        let name = rel
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let test_file = name == "tests.rs" || name.ends_with("_tests.rs");
        let Ok(text) = fs::read_to_string(&path) else {
            found.push(format!("{shown}: cannot be read"));
            continue;
        };
        let code = code_only(&text);
        let tests = test_lines(&code);
        for (n, line) in code.lines().enumerate() {
            let is_test = test_file || tests.get(n).copied().unwrap_or(false);
            for module in crate_modules(line) {
                if module == part {
                    continue;
                }
                for rule in RULES.iter().filter(|r| r.part == part) {
                    if rule.scope == Scope::Library && is_test {
                        continue;
                    }
                    let broken = match rule.allowed {
                        Allowed::Only(ok) => !ok.contains(&module.as_str()),
                        Allowed::Never(no) => no.contains(&module.as_str()),
                    };
                    if broken {
                        found.push(format!(
                            "{shown}:{}: {part} imports {module} (crate::{module}): {}",
                            n + 1,
                            rule.why
                        ));
                    }
                }
                if module == "api" && !is_test && !API_CALLERS.contains(&part.as_str()) {
                    found.push(format!(
                        "{shown}:{}: {part} imports api (crate::api): only the hosts (wasm, cli) call the request/report layer",
                        n + 1
                    ));
                }
            }
            if is_test || HOST_PARTS.contains(&part.as_str()) {
                continue;
            }
            for api in HOST_APIS.iter().filter(|api| uses(line, api)) {
                found.push(format!(
                    "{shown}:{}: {part} uses {api}: only wasm.rs, wasm/, main.rs and cli/ touch a host",
                    n + 1
                ));
            }
        }
    }
    found
}

#[test]
fn the_layering_rules_hold_in_every_file() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(
        files.len() > 50,
        "found only {} files under {}",
        files.len(),
        src.display()
    );
    let found = violations(&src);
    assert!(
        found.is_empty(),
        "{} break(s) of the rules of docs/architecture.md:\n{}",
        found.len(),
        found.join("\n")
    );
}

/// The checker sees what it must: grouped imports, inline paths, test
/// regions, and nothing inside comments or strings.
#[test]
fn the_checker_reads_imports_and_skips_comments_strings_and_tests() {
    assert_eq!(
        crate_modules("use crate::{camera::Camera, image::{GrayImage}, rng::Rng};"),
        ["camera", "image", "rng"]
    );
    assert_eq!(
        crate_modules("let x = crate::detect::detect(&a);"),
        ["detect"]
    );
    assert!(crate_modules("macro_rules! m { () => { $crate::x } }").is_empty());
    let code = code_only(
        "use crate::a; // crate::b\n/* crate::c\n */ let s = \"crate::d {\";\nlet r = r#\"crate::e\"#; let c = '{';\n",
    );
    let named: Vec<String> = code.lines().flat_map(crate_modules).collect();
    assert_eq!(named, ["a"]);
    assert_eq!(code.lines().count(), 4, "line breaks kept");
    let code = "fn a() {}\n#[cfg(test)]\nmod tests {\n    use crate::x;\n}\nfn b() {}\n#[cfg(test)]\nmod more_tests;\nfn c() {}\n";
    assert_eq!(
        test_lines(code),
        [false, true, true, true, true, false, true, true, false]
    );
    assert!(uses("let t = std::time::Instant::now();", "Instant"));
    assert!(!uses(
        "use wasm_bindgen_test::wasm_bindgen_test;",
        "wasm_bindgen"
    ));
    assert!(uses("eprintln!(\"x\");", "eprintln!"));
    assert!(!uses("eprintln!(\"x\");", "print!"));
}

/// A small tree with one break of each kind: each is named with its file,
/// line and rule; what the rules allow is not.
#[test]
fn a_forbidden_import_is_named_with_its_file_line_and_rule() {
    let root = std::env::temp_dir().join(format!("robocal-architecture-{}", std::process::id()));
    let files = [
        ("camera/undistort.rs", "use crate::error::Result;\nuse crate::image::GrayImage;\n"),
        ("calib/zhang.rs", "use crate::{camera::Camera, detect::detect};\n#[cfg(test)]\nmod tests {\n    use crate::synth::Scene;\n}\n"),
        ("handeye/repeat.rs", "use crate::synth::Rng;\n"),
        ("io/read.rs", "pub fn f() { let _ = std::fs::read(\"x\"); }\n"),
        ("cli/mod.rs", "pub fn f() { let _ = std::fs::read(\"x\"); }\n"),
        ("detect/tests.rs", "use crate::synth::render;\n"),
        ("io/csv.rs", "use crate::api::planar::HeightMatrix;\n#[cfg(test)]\nmod tests {\n    use crate::api::planar;\n}\n"),
        ("wasm/x.rs", "use crate::api::planar::HeightMatrix;\n"),
    ];
    for (path, text) in files {
        let path = root.join(path);
        if let Some(dir) = path.parent() {
            fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{e}"));
        }
        fs::write(&path, text).unwrap_or_else(|e| panic!("{e}"));
    }
    let found = violations(&root);
    let _ = fs::remove_dir_all(&root);
    assert_eq!(
        found,
        [
            "src/calib/zhang.rs:1: calib imports detect (crate::detect): the solvers never see pixels: corner lists in, reports out",
            "src/camera/undistort.rs:2: camera imports image (crate::image): the camera is maths: it never imports image (pixels) nor anything above it",
            "src/handeye/repeat.rs:1: handeye imports synth (crate::synth): the solvers never depend on the synthetic scenes (the bootstrap draws from rng)",
            "src/io/csv.rs:1: io imports api (crate::api): only the hosts (wasm, cli) call the request/report layer",
            "src/io/read.rs:1: io uses std::fs: only wasm.rs, wasm/, main.rs and cli/ touch a host",
        ]
    );
}

/// The comma-separated items of a `use` group's inside (after its `{`), up
/// to its closing `}`: nested groups stay whole.
fn split_braced_items(group: &str) -> Vec<String> {
    let (mut items, mut depth, mut item) = (Vec::new(), 0, String::new());
    for ch in group.chars() {
        match ch {
            '{' => depth += 1,
            '}' if depth == 0 => break,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(std::mem::take(&mut item));
                continue;
            }
            _ => {}
        }
        item.push(ch);
    }
    items.push(item);
    items
}
