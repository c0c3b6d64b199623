//! The catalogue of bad inputs (docs/bad-inputs.md) through the real binary:
//! one row per input, with the files it needs, the exit code and the exact
//! message. A row fails when the message changes: update docs/bad-inputs.md
//! with it.

use std::path::Path;
use std::process::Command;

/// Which output carries the message: `info` writes one JSON line per file
/// to stdout; every other failure is one line on stderr.
#[derive(Clone, Copy)]
enum Stream {
    Stdout,
    Stderr,
}

/// One catalogue row: a name (also the scratch folder), the files written
/// into that folder, the arguments (run in that folder), the exit code and
/// the exact first line of the message.
struct Case {
    name: &'static str,
    files: &'static [(&'static str, &'static [u8])],
    args: &'static [&'static str],
    code: i32,
    stream: Stream,
    message: &'static str,
}

const NOT_UTF8: &[u8] = b"\xff\xfe\x00";

const CASES: &[Case] = &[
    Case {
        name: "image-empty",
        files: &[("empty.png", b"")],
        args: &["info", "empty.png"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"not an image: the file is empty","file":"empty.png"}"#,
    },
    Case {
        name: "image-wrong-magic",
        files: &[("text.png", b"hello")],
        args: &["info", "text.png"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP","file":"text.png"}"#,
    },
    Case {
        name: "image-png-signature-only",
        files: &[("sig.png", b"\x89PNG\r\n\x1a\n")],
        args: &["info", "sig.png"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"corrupt or truncated PNG file: unexpected end of file","file":"sig.png"}"#,
    },
    Case {
        name: "image-gif-truncated",
        files: &[("t.gif", b"GIF89a")],
        args: &["info", "t.gif"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"corrupt or truncated GIF file: Format error decoding Gif: Unexpected End of File","file":"t.gif"}"#,
    },
    Case {
        name: "info-no-files",
        files: &[],
        args: &["info"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: info: give at least one image file (see 'robocal info --help')",
    },
    Case {
        name: "detect-no-files",
        files: &[],
        args: &["detect", "--target", "chessboard:9x6:30mm"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: give at least one image file (see 'robocal detect --help')",
    },
    Case {
        name: "spec-one-column",
        files: &[],
        args: &["detect", "--target", "chessboard:1x6:30mm", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: a grid needs 2 to 100000 points with at least 2 per side, got 1x6 (see 'robocal detect --help')",
    },
    Case {
        name: "spec-huge-grid",
        files: &[],
        args: &["detect", "--target", "chessboard:100000x100000:30mm", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: a grid needs 2 to 100000 points with at least 2 per side, got 100000x100000 (see 'robocal detect --help')",
    },
    Case {
        name: "spec-zero-size",
        files: &[],
        args: &["detect", "--target", "chessboard:9x6:0mm", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: sizes must be positive metres (see 'robocal detect --help')",
    },
    Case {
        name: "spec-nan-size",
        files: &[],
        args: &["detect", "--target", "chessboard:9x6:NaNmm", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: sizes must be positive metres (see 'robocal detect --help')",
    },
    Case {
        name: "spec-unknown-kind",
        files: &[],
        args: &["detect", "--target", "foo:9x6:30mm", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: 'foo:9x6:30mm' is not a target spec; expected chessboard:COLSxROWS:SIZE, circles:COLSxROWS:SIZE[:asymmetric], dots:COLSxROWS:PITCH[:DIAMETER], squares:COLSxROWS:SIDE:PITCH or circle:DIAMETER (e.g. chessboard:9x6:30mm) (see 'robocal detect --help')",
    },
    Case {
        name: "spec-missing-size",
        files: &[],
        args: &["detect", "--target", "chessboard:9x6", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: 'chessboard:9x6' is not a target spec; expected chessboard:COLSxROWS:SIZE, circles:COLSxROWS:SIZE[:asymmetric], dots:COLSxROWS:PITCH[:DIAMETER], squares:COLSxROWS:SIDE:PITCH or circle:DIAMETER (e.g. chessboard:9x6:30mm) (see 'robocal detect --help')",
    },
    Case {
        name: "spec-unknown-option",
        files: &[],
        args: &["detect", "--target", "circles:4x11:20mm:sideways", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: unknown circle-grid option 'sideways' (expected asymmetric, symmetric, dark-on-light or light-on-dark) (see 'robocal detect --help')",
    },
    Case {
        name: "render-zero-views",
        files: &[],
        args: &["render", "--views", "0", "--out", "r0"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: render: --views must be between 1 and 1000 (see 'robocal render --help')",
    },
    Case {
        name: "detections-empty",
        files: &[("d.json", b"")],
        args: &["intrinsics", "--target", "chessboard:9x6:30mm", "--detections", "d.json"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: 'd.json' is not a 'robocal detect' output (an object with \"images\"): EOF while parsing a value at line 1 column 0",
    },
    Case {
        name: "detections-not-utf8",
        files: &[("d.json", NOT_UTF8)],
        args: &["intrinsics", "--target", "chessboard:9x6:30mm", "--detections", "d.json"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: cannot read 'd.json': stream did not contain valid UTF-8",
    },
    Case {
        name: "detections-missing-file",
        files: &[],
        args: &["intrinsics", "--target", "chessboard:9x6:30mm", "--detections", "d.json"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: cannot read 'd.json': No such file or directory (os error 2)",
    },
    Case {
        name: "detections-wrong-object",
        files: &[("d.json", b"{\"x\":1}\n")],
        args: &["intrinsics", "--target", "chessboard:9x6:30mm", "--detections", "d.json"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: 'd.json' is not a 'robocal detect' output (an object with \"images\"): missing field `images` at line 1 column 7",
    },
    Case {
        name: "poses-empty",
        files: &[("p.csv", b""), ("c.csv", b"")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "c.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: requires at least 1 poses, got 0",
    },
    Case {
        name: "poses-not-utf8",
        files: &[("p.csv", NOT_UTF8), ("c.csv", b"")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "c.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: 'p.csv' is not UTF-8 text",
    },
    Case {
        name: "poses-nan",
        files: &[("p.csv", b"x,y,z,qx,qy,qz,qw\n0,0,NaN,0,0,0,1\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "p.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 2, column 3: 'NaN' is not a number",
    },
    Case {
        name: "poses-zero-quaternion",
        files: &[("p.csv", b"x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,0\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "p.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 2, column 4: quaternion has norm 0: not a rotation",
    },
    Case {
        name: "poses-unknown-header",
        files: &[("p.csv", b"x,y,z\n1,2\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "p.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 1: the header 'x y z' names no known pose format; name the format, or use column names such as x,y,z,qx,qy,qz,qw or X,Y,Z,A,B,C",
    },
    Case {
        name: "handeye-unknown-setup",
        files: &[("p.csv", b"")],
        args: &["handeye", "--setup", "sideways", "--poses", "p.csv", "--camera-poses", "p.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: setup: unknown setup 'sideways' (valid: eye-in-hand, eye-to-hand)",
    },
    Case {
        name: "export-missing-file",
        files: &[],
        args: &["export", "r.json", "--format", "urdf"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: cannot read 'r.json': No such file or directory (os error 2)",
    },
    Case {
        name: "poses-count-mismatch",
        files: &[("p.csv", b"x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,1\n0,0,1,0,0,0,1\n0,1,0,0,0,0,1\n"), ("c.txt", b"0 0 0 0 0 0 1\n0 0 1 0 0 0 1\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "c.txt", "--camera-pose-format", "xyz-quaternion-xyzw"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: poses: 3 robot poses but 2 camera poses: they must pair up one to one",
    },
    Case {
        name: "detections-no-views",
        files: &[("d.json", b"{\"images\":[]}\n")],
        args: &["intrinsics", "--target", "chessboard:9x6:30mm", "--detections", "d.json"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: requires at least 3 views, got 0",
    },
    Case {
        name: "export-empty-report",
        files: &[("r.json", b"")],
        args: &["export", "r.json", "--format", "urdf"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 1: the report is not valid JSON: EOF while parsing a value at line 1 column 0",
    },
    Case {
        name: "poses-inf",
        files: &[("p.csv", b"x,y,z,qx,qy,qz,qw\n0,0,inf,0,0,0,1\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "p.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 2, column 3: 'inf' is not a number",
    },
];

/// Runs `robocal args` in `dir`: (exit code, stdout, stderr).
fn run_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run robocal");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn every_bad_input_gets_its_exact_message() {
    let root = std::env::temp_dir().join(format!("robocal-bad-inputs-{}", std::process::id()));
    let mut failures = Vec::new();
    for case in CASES {
        let dir = root.join(case.name);
        std::fs::create_dir_all(&dir).expect("scratch folder");
        for (name, bytes) in case.files {
            std::fs::write(dir.join(name), bytes).expect("write input");
        }
        let (code, out, err) = run_in(&dir, case.args);
        let text = match case.stream {
            Stream::Stdout => &out,
            Stream::Stderr => &err,
        };
        let first = text.lines().next().unwrap_or("");
        if code != case.code || first != case.message {
            failures.push(format!(
                "{}: exit {code} (want {}), message\n  got  {first}\n  want {}\nstdout {out}\nstderr {err}",
                case.name, case.code, case.message
            ));
        }
    }
    let _ = std::fs::remove_dir_all(&root);
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
