//! Every input the fuzzers found to crash, hang or exhaust memory, replayed
//! through the same function the fuzz target calls (`fuzz/src/cases.rs`):
//! `fixtures/fuzz/<target>/<name>` is one input of fuzz target `<target>`.
//! A case passes when the entry points return (Ok or Err) without a panic,
//! and within [`TIME_LIMIT`] (the fuzzers' -timeout is 10 s on an
//! instrumented build; fixed hangs return in milliseconds).

#[path = "../../fuzz/src/cases.rs"]
mod cases;

use std::path::Path;
use std::time::{Duration, Instant};

/// Wall-clock bound of one case in the debug test build (opt-level 1).
const TIME_LIMIT: Duration = Duration::from_secs(10);

/// Replays every file of `fixtures/fuzz/<target>/`; returns how many ran.
fn replay(target: &str, case: fn(&[u8])) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/fuzz")
        .join(target);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return 0;
    };
    let mut paths: Vec<_> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for path in &paths {
        let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let start = Instant::now();
        case(&bytes);
        let took = start.elapsed();
        assert!(
            took < TIME_LIMIT,
            "{}: took {took:?} (limit {TIME_LIMIT:?})",
            path.display()
        );
    }
    paths.len()
}

#[test]
fn image_decode() {
    replay("image_decode", cases::image_decode);
}

/// image-webp 0.2.4 sums a lossless stream's Huffman code-length histogram
/// in a u16 (its src/huffman.rs line 65) and a crafted histogram overflows
/// it: a panic under overflow checks (the fuzzers' builds, session 20),
/// while the shipped builds (release, wasm) wrap and the tree check after
/// it rejects the file. Cargo.toml's dev profile turns overflow checks off
/// for that one crate, so the tests see what users get: this error.
#[test]
fn webp_huffman_histogram_overflow_is_a_corrupt_file() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/fuzz/image_decode/webp-huffman-histogram-overflow");
    let bytes = std::fs::read(&path).expect("fixture");
    let err = robocal::image::decode(&bytes, &robocal::image::DecodeOptions::default())
        .expect_err("a corrupt WebP")
        .to_string();
    assert_eq!(
        err,
        "corrupt or truncated WebP file: Format error decoding WebP: Invalid Huffman code"
    );
}

/// zune-jpeg 0.5.15's AVX2 inverse DCT unwraps a slice past the end of
/// its output on this crafted JPEG (found by the image_decode fuzzer with
/// the shipped build's settings, session 20): the panic is caught inside
/// `image::decode` and becomes this file's error, and `robocal info`
/// names the file and exits 1 without a backtrace. Without AVX2 the
/// scalar path runs, which does not panic.
#[test]
fn a_jpeg_decoder_panic_is_this_files_error() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/fuzz/image_decode/jpeg-avx2-idct-unwrap");
    let bytes = std::fs::read(&path).expect("fixture");
    let decoded = robocal::image::decode(&bytes, &robocal::image::DecodeOptions::default());
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        let err = decoded
            .as_ref()
            .map(|_| ())
            .expect_err("the AVX2 path panics")
            .to_string();
        assert!(
            err.starts_with("corrupt JPEG file: its decoder failed inside ("),
            "{err}"
        );
        assert!(
            err.ends_with("re-save it (e.g. as PNG) or take it again"),
            "{err}"
        );
    }
    let _ = decoded;
    let (code, stdout, stderr) = crate::support::robocal(&["info", &path.to_string_lossy()]);
    if code == 1 {
        assert!(
            stdout.contains("corrupt JPEG file: its decoder failed inside ("),
            "{stdout}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    } else {
        assert_eq!(code, 0, "{stdout}{stderr}");
    }
}

#[test]
fn detect() {
    replay("detect", cases::detect);
}

#[test]
fn robot_poses() {
    replay("robot_poses", cases::robot_poses);
}

#[test]
fn camera_files() {
    replay("camera_files", cases::camera_files);
}

#[test]
fn targets_detections() {
    replay("targets_detections", cases::targets_detections);
}

#[test]
fn calib_json() {
    replay("calib_json", cases::calib_json);
}

#[test]
fn handeye_json() {
    replay("handeye_json", cases::handeye_json);
}

#[test]
fn workflows() {
    replay("workflows", cases::workflows);
}
