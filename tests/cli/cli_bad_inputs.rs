//! The catalogue of bad inputs (docs/bad-inputs.md) through the real binary:
//! one row per input, with the files it needs, the exit code and the exact
//! message. A row fails when the message changes: update docs/bad-inputs.md
//! with it.

use crate::support;
use support::catalogue::{check_all, strings, Row, Stream};

/// One catalogue row: a name (also the scratch folder), the files written
/// into that folder, the arguments (run in that folder), the exit code and
/// the exact first line of the message.
// Rows 73-90 and 93 (issue 37's second round: flags, outputs, exports,
// messages) are in a file of their own.
mod round2;

pub(crate) struct Case {
    pub(crate) name: &'static str,
    pub(crate) files: &'static [(&'static str, &'static [u8])],
    pub(crate) args: &'static [&'static str],
    pub(crate) code: i32,
    pub(crate) stream: Stream,
    pub(crate) message: &'static str,
}

const NOT_UTF8: &[u8] = b"\xff\xfe\x00";

/// A PNG of 100000 x 100000 pixels (header, an empty IDAT, IEND; CRCs valid).
const PNG_HUGE: &[u8] = b"\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x01\x86\xa0\x00\x01\x86\xa0\x08\x00\x00\x00\x00\x8d\x39\x54\x14\x00\x00\x00\x08\x49\x44\x41\x54\x78\x9c\x03\x00\x00\x00\x00\x01\x48\x06\x89\xd2\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82";

/// A PNG header with width 0.
const PNG_ZERO_WIDTH: &[u8] = b"\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\x00\x00\x00\x00\x01\xe0\x08\x00\x00\x00\x00\xae\xd3\x33\xf8\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82";

/// The 28-byte JPEG of issue 16 (a DHT whose code counts overrun its table).
const JPEG_28: &[u8] =
    b"\xff\xd8\xff\xc4\x00\x16\x00\x02\x01\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x00\x01\x02\xff\xd9";

/// An OpenCV YAML camera file without its camera_matrix.
const CV_YAML_NO_MATRIX: &[u8] = b"%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n\
distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\n";

/// A ROS camera_info YAML whose camera_matrix has 8 numbers.
const ROS_YAML_K8: &[u8] = b"image_width: 640\nimage_height: 480\ncamera_name: cam\ncamera_matrix:\n  rows: 3\n  cols: 3\n\
  data: [560, 0, 319.5, 0, 560, 239.5, 0, 0]\ndistortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n";

/// A camera JSON whose name would inject a key into a ROS YAML.
const CAMERA_NAME_NEWLINE: &[u8] = br#"{"name":"cam\ncamera_matrix: {rows: 3}","model":"brown","image_size_px":[640,480],"camera_matrix":[[560,0,319.5],[0,560,239.5],[0,0,1]],"distortion":{"k1":0,"k2":0,"p1":0,"p2":0,"k3":0}}"#;

/// A hand-eye report with a transform whose name would close an XML
/// attribute and open an element.
const TRANSFORM_NAME_XML: &[u8] = br#"{"gripper_from_camera":{"translation_m":[0.03,-0.02,0.1],"quaternion_xyzw":[0,0,0.7071067811865476,0.7071067811865476]},"a_from_b\"/><node name=\"x":{"translation_m":[0.03,-0.02,0.1],"quaternion_xyzw":[0,0,0.7071067811865476,0.7071067811865476]}}"#;

/// The pose line of row handeye-one-pose, as Windows saves UTF-16:
/// little-endian with a byte order mark, big-endian without.
const ONE_POSE_UTF16LE_BOM: &[u8] = b"\xff\xfe\x31\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x31\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x31\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x31\x00\x0a\x00";
const ONE_POSE_UTF16BE: &[u8] = b"\x00\x31\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x31\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x31\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x30\x00\x20\x00\x31\x00\x0a";

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
        message: r#"{"error":"the PNG file is truncated: it ends after 8 bytes, before the end of its image data (an interrupted copy or download?): copy it again from the camera or its source","file":"sig.png"}"#,
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
        message: "robocal: detect: target: the square size must be a positive length, got 0 mm (see 'robocal detect --help')",
    },
    Case {
        name: "spec-nan-size",
        files: &[],
        args: &["detect", "--target", "chessboard:9x6:NaNmm", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: the square size must be a positive length, got NaN (see 'robocal detect --help')",
    },
    Case {
        name: "spec-unknown-kind",
        files: &[],
        args: &["detect", "--target", "foo:9x6:30mm", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: 'foo:9x6:30mm' is not a target spec; expected chessboard:COLSxROWS:SIZE, circles:COLSxROWS:SIZE[:asymmetric], dots:COLSxROWS:PITCH[:DIAMETER], squares:COLSxROWS:SIDE:PITCH, charuco:SQUARESXxSQUARESY:SQUARE:MARKER:DICTIONARY, aprilgrid:TAGCOLSxTAGROWS:TAGSIZE:SPACINGRATIO, arucogrid:COLSxROWS:MARKER:SEPARATION:DICTIONARY, circles:COLSxROWS:PITCH:origin-dot or circle:DIAMETER (e.g. chessboard:9x6:30mm) (see 'robocal detect --help')",
    },
    Case {
        name: "spec-missing-size",
        files: &[],
        args: &["detect", "--target", "chessboard:9x6", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: 'chessboard:9x6' is not a target spec; expected chessboard:COLSxROWS:SIZE, circles:COLSxROWS:SIZE[:asymmetric], dots:COLSxROWS:PITCH[:DIAMETER], squares:COLSxROWS:SIDE:PITCH, charuco:SQUARESXxSQUARESY:SQUARE:MARKER:DICTIONARY, aprilgrid:TAGCOLSxTAGROWS:TAGSIZE:SPACINGRATIO, arucogrid:COLSxROWS:MARKER:SEPARATION:DICTIONARY, circles:COLSxROWS:PITCH:origin-dot or circle:DIAMETER (e.g. chessboard:9x6:30mm) (see 'robocal detect --help')",
    },
    Case {
        name: "spec-unknown-option",
        files: &[],
        args: &["detect", "--target", "circles:4x11:20mm:sideways", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: detect: target: unknown circle-grid option 'sideways' (expected asymmetric, symmetric, dark-on-light, light-on-dark or origin-dot) (see 'robocal detect --help')",
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
        message: "robocal: 'p.csv': poses: the file holds no poses (it is empty, or only a header and comments): give one pose per line, e.g. x,y,z,qx,qy,qz,qw",
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
        message: "robocal: 'p.csv': line 2, column 3: 'NaN' is not a number",
    },
    Case {
        name: "poses-zero-quaternion",
        files: &[("p.csv", b"x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,0\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "p.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: 'p.csv': line 2, column 4: quaternion has norm 0: not a rotation",
    },
    Case {
        name: "poses-unknown-header",
        files: &[("p.csv", b"x,y,z\n1,2\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.csv", "--camera-poses", "p.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: 'p.csv': line 1: the header 'x y z' names no known pose format; name the format, or use column names such as x,y,z,qx,qy,qz,qw or X,Y,Z,A,B,C",
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
        message: "robocal: 'd.json' lists no images: write it with 'robocal detect --target SPEC IMAGES... -o d.json'",
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
        message: "robocal: 'p.csv': line 2, column 3: 'inf' is not a number",
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
        message: "robocal: 'three.txt': line 1: 3 values, but pose formats have 6, 7, 12 or 16 values a line",
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
        message: "robocal: 'scaled.txt': line 1: 4x4 matrix rotation block is not orthonormal: largest |RᵀR - I| entry is 3.000e0, tolerance 1e-3",
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
        message: "robocal: detect: target: the square size must be a positive length, got -30 mm (see 'robocal detect --help')",
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
    Case {
        name: "image-png-huge",
        files: &[("huge.png", PNG_HUGE)],
        args: &["info", "huge.png"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"image is 100000x100000 = 10000.0 MP, more than the limit of 100.0 MP: downscale it first, or raise the limit (--max-pixels in the CLI, \"max_pixels\" in the JSON options)","file":"huge.png"}"#,
    },
    Case {
        name: "image-png-zero-width",
        files: &[("zero.png", PNG_ZERO_WIDTH)],
        args: &["info", "zero.png"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"corrupt or truncated PNG file: Format error decoding Png: Invalid image dimensions","file":"zero.png"}"#,
    },
    Case {
        name: "image-bmp-truncated",
        files: &[("t.bmp", b"BM\0\0\0\0\0\0\0\0\0\0")],
        args: &["info", "t.bmp"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"the BMP file is truncated: it ends after 12 bytes, before the end of its image data (an interrupted copy or download?): copy it again from the camera or its source","file":"t.bmp"}"#,
    },
    Case {
        name: "image-tiff-truncated",
        files: &[("t.tif", b"II*\0\x08\0\0\0\x01\0")],
        args: &["info", "t.tif"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"the TIFF file is truncated: it ends after 10 bytes, before the end of its image data (an interrupted copy or download?): copy it again from the camera or its source","file":"t.tif"}"#,
    },
    Case {
        name: "image-jpeg-28-bytes",
        files: &[("tiny.jpg", JPEG_28)],
        args: &["info", "tiny.jpg"],
        code: 1,
        stream: Stream::Stdout,
        message: r#"{"error":"corrupt or truncated JPEG file: Format error decoding Jpeg: Error decoding huffman values: Bad Huffman Table","file":"tiny.jpg"}"#,
    },
    Case {
        name: "camera-json-no-model",
        files: &[("cam.json", br#"{"image_size_px":[640,480],"camera_matrix":[[560,0,319.5],[0,560,239.5],[0,0,1]]}"#)],
        args: &["render", "--out", "o", "--views", "1", "--camera", "cam.json"],
        code: 1,
        stream: Stream::Stderr,
        message: r#"robocal: model: the camera JSON needs the lens model's name, e.g. "brown""#,
    },
    Case {
        name: "camera-json-negative-focal",
        files: &[("cam.json", br#"{"model":"brown","image_size_px":[640,480],"camera_matrix":[[-560,0,319.5],[0,560,239.5],[0,0,1]],"distortion":{"k1":0,"k2":0,"p1":0,"p2":0,"k3":0}}"#)],
        args: &["render", "--out", "o", "--views", "1", "--camera", "cam.json"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: camera_matrix: focal lengths must be positive, got fx -560 fy 560",
    },
    Case {
        name: "camera-opencv-yaml-no-matrix",
        files: &[("cv.yaml", CV_YAML_NO_MATRIX)],
        args: &["render", "--out", "o", "--views", "1", "--camera", "cv.yaml"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: camera_matrix: the file has no camera matrix (camera_matrix or K with 9 numbers): give a robocal camera JSON, an OpenCV YAML/XML calibration or a ROS camera_info YAML",
    },
    Case {
        name: "camera-ros-yaml-eight-values",
        files: &[("ros.yaml", ROS_YAML_K8)],
        args: &["render", "--out", "o", "--views", "1", "--camera", "ros.yaml"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: camera_matrix: the camera_matrix has 8 numbers, a 3x3 matrix needs 9 (fx 0 cx 0 fy cy 0 0 1): the file is truncated or not a camera file",
    },
    Case {
        name: "camera-opencv-xml-truncated",
        files: &[("cv.xml", b"<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n<camera_matrix type_id=\"opencv-matrix\"><rows>3</rows><cols>3</cols>")],
        args: &["render", "--out", "o", "--views", "1", "--camera", "cv.xml"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: camera_matrix: the file has no camera matrix (camera_matrix or K with 9 numbers): give a robocal camera JSON, an OpenCV YAML/XML calibration or a ROS camera_info YAML",
    },
    Case {
        name: "poses-unknown-format-name",
        files: &[("p.txt", b"0 0 0 0 0 0 1\n")],
        args: &["handeye", "--setup", "eye-in-hand", "--poses", "p.txt", "--pose-format", "furlong", "--camera-poses", "p.txt"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: handeye: --pose-format: unknown pose format 'furlong' (valid: ur, kuka, abb, fanuc, yaskawa, staubli, xyz_quat_xyzw, xyz_quat_wxyz, xyz_rotvec, matrix4, matrix3x4, xyz_euler_intrinsic_ORDER or xyz_euler_extrinsic_ORDER with ORDER such as zyx, or the line formats matrix, xyz-quaternion-xyzw, xyz-quaternion-wxyz) (see 'robocal handeye --help')",
    },
    Case {
        name: "xytable-empty-csv",
        files: &[("empty.csv", b"\n")],
        args: &["xytable", "empty.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: empty.csv: the file is empty: expected a CSV header line",
    },
    Case {
        name: "planar-wrong-header",
        files: &[("bad.csv", b"a,b\n1,2\n")],
        args: &["planar", "solve", "bad.csv"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: bad.csv: line 1: missing column(s) height_mm, u_px, v_px, x_mm, y_mm (expected header height_mm,u_px,v_px,x_mm,y_mm, got a,b)",
    },
    Case {
        name: "intrinsics-partial-views-unusable",
        files: &[("partial.json", br#"{"images":[{"file":"a.png","detection":{"image_size_px":[640,480],"target":{"kind":"chessboard","cols":9,"rows":6,"square_m":0.03},"points":[{"id":0,"x_px":100,"y_px":100},{"id":1,"x_px":120,"y_px":100},{"id":9,"x_px":100,"y_px":120}]}},{"file":"b.png","detection":{"image_size_px":[640,480],"target":{"kind":"chessboard","cols":9,"rows":6,"square_m":0.03},"points":[{"id":0,"x_px":103,"y_px":103},{"id":1,"x_px":123,"y_px":103},{"id":2,"x_px":143,"y_px":103},{"id":3,"x_px":163,"y_px":103}]}},{"file":"c.png","detection":{"image_size_px":[640,480],"target":{"kind":"chessboard","cols":9,"rows":6,"square_m":0.03},"points":[{"id":0,"x_px":106,"y_px":106},{"id":1,"x_px":126,"y_px":106},{"id":2,"x_px":146,"y_px":106},{"id":3,"x_px":166,"y_px":106},{"id":12,"x_px":166,"y_px":126}]}}]}"#)],
        args: &["intrinsics", "--detections", "partial.json"],
        code: 1,
        stream: Stream::Stderr,
        message: "robocal: views: 0 views whose points fix a homography, a calibration needs at least 3 (10 or more from varied angles are recommended); left out: view a.png (3 points: a homography needs at least 4), view b.png (its 4 points lie on one line: a homography needs 4 points with no 3 on one line), view c.png (4 of its 5 points lie on one line: a homography needs 4 points with no 3 on one line): add images in which more of the target is found",
    },
    Case {
        name: "detect-misspelled-flag",
        files: &[],
        args: &["detect", "--targett", "chessboard:9x6:30mm", "a.png"],
        code: 2,
        stream: Stream::Stderr,
        message: "error: unexpected argument '--targett' found",
    },
    Case {
        name: "rig-no-camera",
        files: &[],
        args: &["rig", "--target", "chessboard:9x6:30mm"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: rig: give one --camera NAME IMAGES... per camera (at least 2), or --input FILE (see 'robocal rig --help')",
    },
    Case {
        name: "rig-group-by-unknown",
        files: &[],
        args: &["rig", "--target", "chessboard:9x6:30mm", "--camera", "a", "a1.png", "--camera", "b", "b1.png", "--group-by", "sideways"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: rig: --group-by takes number or last (the last number in the name, the default), first (the first number), order (the position in each camera's list), or a pattern with one (\\d+) such as sync(\\d+); got 'sideways': not a rule name, and no (\\d+) in it (see 'robocal rig --help')",
    },
    Case {
        name: "rig-name-without-number",
        files: &[],
        args: &["rig", "--target", "chessboard:9x6:30mm", "--camera", "a", "a1.png", "a.png", "--camera", "b", "b1.png", "--group-by", "number"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: rig: frames are grouped by the last number in the file names, but camera a has names without one: a.png (group by number or last (the last number in the name, the default), first (the first number), order (the position in each camera's list), or a pattern with one (\\d+) such as sync(\\d+)) (see 'robocal rig --help')",
    },
    Case {
        name: "rig-camera-file-without-name",
        files: &[],
        args: &["rig", "--target", "chessboard:9x6:30mm", "--camera", "a", "a1.png", "--camera", "b", "b1.png", "--camera-file", "top.json"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: rig: --camera-file takes NAME=FILE, got 'top.json' (see 'robocal rig --help')",
    },
    Case {
        name: "rig-poses-without-setup",
        files: &[],
        args: &["rig", "--target", "chessboard:9x6:30mm", "--camera", "a", "a1.png", "--camera", "b", "b1.png", "--poses", "p.csv"],
        code: 2,
        stream: Stream::Stderr,
        message: "robocal: rig: --poses needs --setup eye-in-hand|eye-to-hand (see 'robocal rig --help')",
    },

];

#[test]
fn every_bad_input_gets_its_exact_message() {
    let rows: Vec<Row> = CASES
        .iter()
        .chain(round2::CASES)
        .map(|case| Row {
            name: case.name.to_string(),
            files: case
                .files
                .iter()
                .map(|(name, bytes)| (name.to_string(), bytes.to_vec()))
                .collect(),
            setup: Vec::new(),
            args: strings(case.args),
            code: case.code,
            stream: case.stream,
            message: case.message.to_string(),
            last_line: false,
        })
        .collect();
    check_all("bad-inputs", &rows);
}

/// Row 91: a file name that is not UTF-8 cannot be written in a `&str`
/// table, so it is run here.
#[cfg(unix)]
#[test]
fn a_file_name_that_is_not_utf8_is_named() {
    use std::os::unix::ffi::OsStrExt;
    let name = std::ffi::OsStr::from_bytes(b"view\xff.png");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_robocal"))
        .arg("info")
        .arg(name)
        .output()
        .expect("run robocal");
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).lines().next().unwrap_or(""),
        "robocal: argument 2 ('view\u{fffd}.png') is not UTF-8 text: robocal takes file names and values in UTF-8; rename the file (\u{fffd} marks the bytes that are not UTF-8)"
    );
}
