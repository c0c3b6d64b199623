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
    Case {
        name: "handeye-one-pose",
        files: &[("one.txt", b"1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "one.txt", "--camera-poses", "one.txt"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: requires at least 3 pose pairs, got 1",
    },
    Case {
        name: "poses-three-values",
        files: &[("three.txt", b"1 2 3\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "three.txt", "--camera-poses", "three.txt"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 1: 3 values, but pose formats have 6, 7 or 16 values a line",
    },
    Case {
        name: "poses-not-a-rotation",
        files: &[(
            "scaled.txt",
            b"1 0 0 0 0 1 0 0 0 0 2 0 0 0 0 1\n1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n",
        )],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "scaled.txt", "--camera-poses", "scaled.txt"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 1: 4x4 matrix rotation block is not orthonormal: largest |RᵀR - I| entry is 3.000e0, tolerance 1e-3",
    },
    Case {
        name: "detections-nan-as-text",
        files: &[(
            "nan.json",
            br#"{"target":{"kind":"chessboard","cols":9,"rows":6,"square_m":0.03},"images":[{"file":"a.png","detection":{"image_size_px":[640,480],"points":[{"id":0,"x_px":"NaN","y_px":1}]}}]}"#,
        )],
        args: &["intrinsics", "--detections", "nan.json"],
        code: 1,
        stream: Stream::Stderr,
        message: r#"robocal: 'nan.json' is not a 'robocal detect' output (an object with "images"): invalid type: string "NaN", expected f64 at line 1 column 161"#,
    },
    Case {
        name: "max-pixels-zero",
        files: &[],
        args: &["info", "--max-pixels", "0", "x.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "error: invalid value '0' for '--max-pixels <N>': '0' is not a pixel count: give a whole number > 0, e.g. 150000000 or 150MP",
    },
    Case {
        name: "spec-negative-size",
        files: &[],
        args: &["detect", "--target", "chessboard:9x6:-30mm", "x.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: sizes must be positive metres (see 'robocal detect --help')",
    },
    Case {
        name: "export-empty-file",
        files: &[("cam.json", b"")],
        args: &["export", "cam.json", "--format", "opencv-yaml"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 1: the report is not valid JSON: EOF while parsing a value at line 1 column 0",
    },
    Case {
        name: "export-yaml-given-as-report",
        files: &[("cam.yaml", b"%YAML:1.0\nimage_width: 640\n")],
        args: &["export", "cam.yaml", "--format", "ros-yaml"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: line 1, column 1: the report is not valid JSON: expected value at line 1 column 1",
    },
    Case {
        name: "export-report-without-camera",
        files: &[("k.json", br#"{"camera_matrix": [[1,0],[0,1]]}"#)],
        args: &["export", "k.json", "--format", "opencv-yaml"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: report: format 'opencv-yaml' needs a camera, and this report has none (no image_size_px)",
    },
    Case {
        name: "stereo-right-missing",
        files: &[],
        args: &["stereo", "--target", "chessboard:9x6:30mm", "--left", "a.png", "--right"],
        code: 2,
        stream: Stream::Stderr,
        message: "error: a value is required for '--right <IMAGES>...' but none was supplied",
    },
    Case {
        name: "render-negative-noise",
        files: &[],
        args: &["render", "--out", "o", "--views", "3", "--noise", "-1"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: render: --noise must be a sigma >= 0 in grey levels, got -1 (see 'robocal render --help')",
    },
    Case {
        name: "render-nan-blur",
        files: &[],
        args: &["render", "--out", "o", "--views", "3", "--blur", "NaN"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: render: --blur must be a sigma >= 0 in px, got NaN (see 'robocal render --help')",
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
