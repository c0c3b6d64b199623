//! The runner of the bad-input catalogue (docs/bad-inputs.md): each row
//! writes its files into a scratch folder, runs its set-up commands (e.g.
//! `robocal render`), then the command under test, and compares the exit
//! code and the exact first line of the message.

use super::robocal_in as run_in;

/// Which output carries the message: `info` writes one JSON line per file
/// to stdout; every other failure is one line on stderr.
#[derive(Clone, Copy)]
pub enum Stream {
    Stdout,
    Stderr,
}

/// One catalogue row.
pub struct Row {
    /// The row's name in docs/bad-inputs.md (also its scratch folder).
    pub name: String,
    /// Files written into the scratch folder before anything runs.
    pub files: Vec<(String, Vec<u8>)>,
    /// `robocal` commands run first (each must succeed), e.g. renders.
    pub setup: Vec<Vec<String>>,
    /// The command under test, run in the scratch folder.
    pub args: Vec<String>,
    /// Its expected exit code (2: usage mistake, 1: failure).
    pub code: i32,
    /// Where the message goes.
    pub stream: Stream,
    /// The exact first line of the message (the last line when `last_line`:
    /// after per-image notes such as "skipped").
    pub message: String,
    /// Compare the last line of the stream instead of the first.
    pub last_line: bool,
}

/// Runs every row; panics with every mismatch (got / want) at once.
pub fn check_all(suite: &str, rows: &[Row]) {
    let root = std::env::temp_dir().join(format!("robocal-{suite}-{}", std::process::id()));
    let mut failures = Vec::new();
    for row in rows {
        let dir = root.join(&row.name);
        std::fs::create_dir_all(&dir).expect("scratch folder");
        for (name, bytes) in &row.files {
            std::fs::write(dir.join(name), bytes).expect("write input");
        }
        for command in &row.setup {
            let (code, _, err) = run_in(&dir, command);
            assert_eq!(code, 0, "{}: set-up {command:?} failed: {err}", row.name);
        }
        let (code, out, err) = run_in(&dir, &row.args);
        let text = match row.stream {
            Stream::Stdout => &out,
            Stream::Stderr => &err,
        };
        let first = if row.last_line {
            text.lines().last()
        } else {
            text.lines().next()
        }
        .unwrap_or("");
        if code != row.code || first != row.message {
            failures.push(format!(
                "{}: exit {code} (want {}), message\n  got  {first}\n  want {}\nstdout {out}\nstderr {err}",
                row.name, row.code, row.message
            ));
        }
    }
    let _ = std::fs::remove_dir_all(&root);
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// `["a", "b"]` as owned strings.
pub fn strings(words: &[&str]) -> Vec<String> {
    words.iter().map(|w| w.to_string()).collect()
}
