//! What the CLI writes, when writing fails: an output file is replaced
//! whole or not at all (the old bytes stay, no temporary file is left), a
//! reader that closes stdout early ends the command quietly (exit 141, as a
//! shell reports SIGPIPE), and a full stdout is a one-line error (exit 1).

use crate::support;
use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use support::temp_dir;

const BIN: &str = env!("CARGO_BIN_EXE_robocal");

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("list the folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Run `robocal args` in `dir` under a file-size limit of 1 KiB with
/// SIGXFSZ ignored, so a write past the limit fails with EFBIG (as a full
/// disk fails with ENOSPC) instead of killing the process; this works for
/// root too, whom a read-only folder does not stop.
fn run_with_size_limit(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = Command::new("sh")
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 2; exec \"$@\"")
        .arg("sh")
        .arg(BIN)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run robocal under sh");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_failed_write_leaves_the_old_output_file_intact() {
    let dir = temp_dir("output", "atomic");
    let old = b"<svg>the good board of yesterday</svg>\n";
    std::fs::write(dir.join("board.svg"), old).expect("write the old file");
    let (code, err) = run_with_size_limit(
        &dir,
        &["target", "chessboard:9x6:30mm", "--svg", "board.svg"],
    );
    assert_eq!(code, 1, "stderr: {err}");
    assert_eq!(
        err.lines().next().unwrap_or(""),
        "robocal: cannot write 'board.svg': File too large (os error 27)"
    );
    assert_eq!(std::fs::read(dir.join("board.svg")).expect("read"), old);
    assert_eq!(
        names(&dir),
        vec!["board.svg".to_string()],
        "no temporary file left"
    );

    // The same command without the limit replaces the file whole.
    let (code, _, err) = support::robocal_in(
        &dir,
        &["target", "chessboard:9x6:30mm", "--svg", "board.svg"],
    );
    assert_eq!(code, 0, "stderr: {err}");
    let new = std::fs::read_to_string(dir.join("board.svg")).expect("read");
    assert!(
        new.starts_with("<?xml") || new.starts_with("<svg"),
        "{new:.80}"
    );
    assert!(new.trim_end().ends_with("</svg>"), "the new board is whole");
    assert_eq!(names(&dir), vec!["board.svg".to_string()]);
    std::fs::remove_dir_all(dir).expect("clean up");
}

#[test]
fn a_failed_render_leaves_the_old_png_intact() {
    let dir = temp_dir("output", "render");
    std::fs::create_dir_all(dir.join("r")).expect("folder");
    let old = b"an old PNG's bytes";
    std::fs::write(dir.join("r/view_000.png"), old).expect("write the old file");
    let (code, err) = run_with_size_limit(&dir, &["render", "--out", "r", "--views", "1"]);
    assert_eq!(code, 1, "stderr: {err}");
    assert_eq!(
        err.lines().next().unwrap_or(""),
        "robocal: cannot write 'r/view_000.png': File too large (os error 27)"
    );
    assert_eq!(
        std::fs::read(dir.join("r/view_000.png")).expect("read"),
        old
    );
    assert_eq!(names(&dir.join("r")), vec!["view_000.png".to_string()]);
    std::fs::remove_dir_all(dir).expect("clean up");
}

#[test]
fn a_reader_that_closes_stdout_early_ends_the_command_quietly() {
    let dir = temp_dir("output", "pipe");
    std::fs::write(dir.join("empty.png"), b"").expect("write");
    // 3000 lines of about 65 bytes: more than a pipe holds, so the command
    // meets the closed pipe whenever the reader closes it.
    let files = vec!["empty.png"; 3000];
    let mut child = Command::new(BIN)
        .arg("info")
        .args(&files)
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start robocal");
    let mut stdout = child.stdout.take().expect("stdout");
    let mut first = [0u8; 16];
    stdout.read_exact(&mut first).expect("read the first bytes");
    drop(stdout); // `| head -c 16`
    let mut err = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut err)
        .expect("read stderr");
    let status = child.wait().expect("wait");
    assert_eq!(&first, b"{\"error\":\"not an");
    assert_eq!(status.code(), Some(141), "stderr: {err}");
    assert_eq!(err, "", "no message, no backtrace");
    std::fs::remove_dir_all(dir).expect("clean up");
}

#[test]
fn a_full_stdout_is_a_one_line_error() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("open /dev/full");
    let out = Command::new(BIN)
        .args(["target", "chessboard:9x6:30mm"])
        .stdout(full)
        .output()
        .expect("run robocal");
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "robocal: cannot write to stdout: No space left on device (os error 28)\n"
    );
}
