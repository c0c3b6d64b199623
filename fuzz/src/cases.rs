//! The body of every fuzz target, one public function per target, each
//! taking the fuzzer's bytes. Shared by the fuzz targets
//! (`fuzz/fuzz_targets/<target>.rs`), the seed generator (`fuzz/seeds/`, for
//! the input layouts) and the regression suite (`tests/detect/fuzz_regressions.rs`,
//! which replays `fixtures/fuzz/<target>/*` through the same function), all
//! through `#[path]`, so a crash input replays exactly as it was fuzzed.
//!
//! Input layouts: [`image_decode`] takes the file bytes as they are; the
//! text targets take a selector byte (which entry point, which options)
//! followed by the UTF-8 text; [`detect`] takes five header bytes (target
//! kind and size, image size) followed by grey pixels.
//!
//! A case panics only on a bug: every entry point must return `Ok` or `Err`
//! for any input, and the few invariants asserted here are the ones the
//! library documents (specs and detections round-trip, decoded sizes match).
#![allow(dead_code)]

use robocal::image::{DecodeOptions, GrayImage};
use robocal::io::{AngleUnit, LengthUnit, PoseDirection, PoseFileOptions, PoseFormat};
use robocal::target::{Detection, Target};

/// Pixel limit of the decoding target: a 4 MP image decodes in a few
/// milliseconds, so the fuzzer spends its time on headers, not on pixels.
pub const FUZZ_MAX_PIXELS: u64 = 4_000_000;
/// Allocation limit of the decoding target, bytes.
pub const FUZZ_MAX_ALLOC_BYTES: u64 = 256 << 20;
/// Largest side of the images of the [`detect`] target, pixels.
pub const DETECT_MAX_SIDE_PX: u32 = 128;
/// Header bytes of a [`detect`] input before the pixels.
pub const DETECT_HEADER_BYTES: usize = 5;

/// The selector byte and the UTF-8 text after it (`None` for no selector
/// or text that is not UTF-8: every text entry point takes `&str`).
fn selector_and_text(data: &[u8]) -> Option<(u8, &str)> {
    let (&selector, rest) = data.split_first()?;
    Some((selector, std::str::from_utf8(rest).ok()?))
}

/// `robocal::image::decode` under the fuzzing limits, with a preview.
pub fn image_decode(data: &[u8]) {
    let options = DecodeOptions {
        max_pixels: FUZZ_MAX_PIXELS,
        max_alloc_bytes: FUZZ_MAX_ALLOC_BYTES,
        preview_max_side: Some(64),
    };
    let _ = robocal::image::sniff_format(data);
    if let Ok(decoded) = robocal::image::decode(data, &options) {
        let g = &decoded.gray;
        assert_eq!(g.pixels.len(), g.width as usize * g.height as usize);
        assert_eq!(
            (g.width, g.height),
            (decoded.info.width, decoded.info.height)
        );
        assert!(g.width as u64 * g.height as u64 <= FUZZ_MAX_PIXELS);
        if let Some(p) = &decoded.preview {
            assert_eq!(p.pixels.len(), 4 * p.width as usize * p.height as usize);
            assert!(p.width.max(p.height) <= 64);
        }
    }
}

/// The target spec a [`detect`] input's first three bytes name: byte 0 the
/// kind (chessboard, circle grid, dot plate, single circle, square grid),
/// bytes 1 and 2 the columns and rows (2 to 9), bit 3 of byte 1 an
/// asymmetric circle grid, bit 4 light-on-dark circles.
pub fn detect_target_spec(kind: u8, a: u8, b: u8) -> String {
    let cols = 2 + (a & 7);
    let rows = 2 + (b & 7);
    match kind % 5 {
        0 => format!("chessboard:{cols}x{rows}:30mm"),
        1 => {
            let layout = if a & 8 != 0 {
                "asymmetric"
            } else {
                "symmetric"
            };
            let polarity = if a & 16 != 0 {
                "light-on-dark"
            } else {
                "dark-on-light"
            };
            format!("circles:{cols}x{rows}:20mm:{layout}:{polarity}")
        }
        2 => format!("dots:{cols}x{rows}:25mm:12.5mm"),
        3 => "circle:10mm".to_string(),
        _ => format!("squares:{cols}x{rows}:12.7mm:22.5778mm"),
    }
}

/// Image side from a header byte: 16 to [`DETECT_MAX_SIDE_PX`] pixels.
fn detect_side(byte: u8) -> u32 {
    robocal::detect::MIN_IMAGE_SIDE_PX + byte as u32 % (DETECT_MAX_SIDE_PX - 15)
}

/// The header byte giving `side` (inverse of the side rule above).
pub fn detect_side_byte(side: u32) -> u8 {
    (side.clamp(robocal::detect::MIN_IMAGE_SIDE_PX, DETECT_MAX_SIDE_PX)
        - robocal::detect::MIN_IMAGE_SIDE_PX) as u8
}

/// The [`detect`] input for a target header and an image of at most
/// 128 x 128 pixels (the seed generator writes renders with it).
pub fn detect_input(kind: u8, a: u8, b: u8, image: &GrayImage) -> Vec<u8> {
    let mut out = vec![
        kind,
        a,
        b,
        detect_side_byte(image.width),
        detect_side_byte(image.height),
    ];
    out.extend_from_slice(&image.pixels);
    out
}

/// The target and the tiny grey image of a [`detect`] input: header bytes
/// as in [`detect_target_spec`] and [`detect_input`], then pixels row by
/// row, repeated to fill the image (mid-grey when there are none).
pub fn detect_case(data: &[u8]) -> Option<(Target, GrayImage)> {
    let header = data.get(..DETECT_HEADER_BYTES)?;
    let target = Target::parse_spec(&detect_target_spec(header[0], header[1], header[2])).ok()?;
    let (w, h) = (detect_side(header[3]), detect_side(header[4]));
    let body = &data[DETECT_HEADER_BYTES..];
    let n = w as usize * h as usize;
    let pixels: Vec<u8> = if body.is_empty() {
        vec![128; n]
    } else {
        body.iter().copied().cycle().take(n).collect()
    };
    Some((target, GrayImage::new(w, h, pixels).ok()?))
}

/// `robocal::detect::detect` of each target kind on a small grey image.
pub fn detect(data: &[u8]) {
    let Some((target, image)) = detect_case(data) else {
        return;
    };
    let options = robocal::detect::DetectOptions::default();
    if let Ok(detection) = robocal::detect::detect(&image, &target, &options) {
        assert_eq!(detection.image_size_px, [image.width, image.height]);
        for p in &detection.points {
            assert!(p.x_px.is_finite() && p.y_px.is_finite(), "point {p:?}");
            assert!(p.id < target.point_count(), "point {p:?} of {target:?}");
        }
    }
}

/// The pose-file options of a [`robot_poses`] selector pair: byte 0 the
/// format (0 = from the file, else one of [`PoseFormat::all`]), byte 1 the
/// length unit (bits 0-1), angle unit (bits 2-3) and direction (bit 4).
pub fn pose_options(format_byte: u8, unit_byte: u8) -> PoseFileOptions {
    let all = PoseFormat::all();
    PoseFileOptions {
        format: (format_byte != 0).then(|| all[(format_byte as usize - 1) % all.len()]),
        length_unit: match unit_byte & 3 {
            1 => Some(LengthUnit::Millimetre),
            2 => Some(LengthUnit::Metre),
            _ => None,
        },
        angle_unit: match (unit_byte >> 2) & 3 {
            1 => Some(AngleUnit::Degree),
            2 => Some(AngleUnit::Radian),
            _ => None,
        },
        direction: if unit_byte & 16 != 0 {
            PoseDirection::GripperFromBase
        } else {
            PoseDirection::BaseFromGripper
        },
    }
}

/// Robot pose files in every format and convention: `parse_poses`,
/// `parse_pose_candidates`, the JSON entry `read_poses_json`, the
/// camera-pose text reader, and the writer's round trip. Two option bytes
/// ([`pose_options`]; bits 5-6 of the second pick the camera-pose text
/// layout), then the text.
pub fn robot_poses(data: &[u8]) {
    let Some((&format_byte, rest)) = data.split_first() else {
        return;
    };
    let Some((unit_byte, text)) = selector_and_text(rest) else {
        return;
    };
    let options = pose_options(format_byte, unit_byte);
    let options_json = serde_json::to_string(&options).unwrap_or_default();
    let _ = robocal::api::poses::read_poses_json(text, &options_json);
    let _ = robocal::io::parse_pose_candidates(text, &options);
    if let Ok(parsed) = robocal::io::parse_poses(text, &options) {
        pose_round_trip(&parsed);
    }
    use robocal::io::pose_text::{parse_pose_text, PoseTextFormat};
    let text_format = match (unit_byte >> 5) & 3 {
        1 => Some(PoseTextFormat::Matrix),
        2 => Some(PoseTextFormat::XyzQuaternionXyzw),
        3 => Some(PoseTextFormat::XyzQuaternionWxyz),
        _ => None,
    };
    let _ = parse_pose_text(text, text_format);
}

/// `format_poses` then `parse_poses` with the same format gives the poses
/// back (the writer's documented inverse), for finite poses of moderate size.
fn pose_round_trip(parsed: &robocal::io::ParsedPoses) {
    let moderate = parsed.poses.iter().all(|p| {
        let t = p.base_from_gripper.translation.vector;
        t.iter().all(|x| x.is_finite() && x.abs() < 1e12)
    });
    if !moderate {
        return;
    }
    let text = robocal::io::format_poses(
        &parsed.poses,
        parsed.format,
        parsed.length_unit,
        parsed.angle_unit,
    );
    let again = PoseFileOptions {
        format: Some(parsed.format),
        length_unit: Some(parsed.length_unit),
        angle_unit: Some(parsed.angle_unit),
        direction: PoseDirection::BaseFromGripper,
    };
    let back = robocal::io::parse_poses(&text, &again)
        .unwrap_or_else(|e| panic!("written poses do not read back: {e}\n{text}"));
    assert_eq!(back.poses.len(), parsed.poses.len(), "{text}");
    for (a, b) in parsed.poses.iter().zip(&back.poses) {
        let (pa, pb) = (&a.base_from_gripper, &b.base_from_gripper);
        let scale = 1.0 + pa.translation.vector.norm();
        let dt = (pa.translation.vector - pb.translation.vector).norm();
        let dr = pa.rotation.angle_to(&pb.rotation);
        assert!(dt <= 1e-9 * scale, "translation differs by {dt} m\n{text}");
        assert!(dr <= 1e-6, "rotation differs by {dr} rad\n{text}");
    }
}

/// Camera files: selector % 3 = 0 `import_camera` (robocal JSON, OpenCV
/// YAML/XML, ROS camera_info) then every camera export; 1 the camera JSON
/// of the web app's undistorted preview (serde, `camera_from_json`,
/// `pinhole_preview`, `undistort_image`); 2 `io::export::export` of a
/// report in the format the selector picks.
pub fn camera_files(data: &[u8]) {
    let Some((selector, text)) = selector_and_text(data) else {
        return;
    };
    match selector % 3 {
        0 => {
            if let Ok((camera, _)) = robocal::io::import_camera::import_camera(text) {
                camera_uses(&camera);
            }
        }
        1 => {
            if let Ok(camera) = serde_json::from_str::<robocal::Camera>(text) {
                camera_uses(&camera);
            }
            if let Ok(value) = serde_json::from_str::<serde_json::Value>(text) {
                let _ = robocal::api::handeye::camera_from_json(&value);
            }
        }
        _ => {
            let names = export_format_names();
            let format = &names[(selector / 3) as usize % names.len()];
            let _ = robocal::io::export::export(text, format, None);
        }
    }
}

/// Export names for [`camera_files`]: every name of `format_names` (the
/// Euler template replaced by two of its instances).
pub fn export_format_names() -> Vec<String> {
    let mut names: Vec<String> = robocal::io::export::format_names()
        .into_iter()
        .filter(|n| !n.contains('<'))
        .collect();
    names.push("euler-intrinsic-zyx-deg".into());
    names.push("euler-extrinsic-xyz-rad".into());
    names
}

/// Every camera export, and the undistorted preview of a small image.
fn camera_uses(camera: &robocal::Camera) {
    use robocal::io::export_camera::{export_camera, CameraExportInfo, CameraFormat};
    for format in CameraFormat::ALL {
        let _ = export_camera(camera, &CameraExportInfo::default(), format);
    }
    if let Ok(preview) = camera.pinhole_preview(48) {
        let (w, h) = (32u32, 24u32);
        let pixels = (0..w * h).map(|i| (i * 7 % 251) as u8).collect();
        if let Ok(image) = GrayImage::new(w, h, pixels) {
            let _ = robocal::image::undistort_image(&image, camera, &preview);
        }
    }
}

/// Targets and detections: selector % 4 = 0 a CLI target spec, 1 a target
/// JSON object (both then checked to round-trip through `to_spec`, listed
/// and drawn as SVG), 2 a detections JSON (`robocal detect`'s file, or one
/// detection) read into calibration views, 3 stereo pairing by file names.
pub fn targets_detections(data: &[u8]) {
    let Some((selector, text)) = selector_and_text(data) else {
        return;
    };
    match selector % 4 {
        0 => {
            if let Ok(target) = Target::parse_spec(text) {
                target_uses(&target);
            }
        }
        1 => {
            let parsed = serde_json::from_str::<Target>(text).map(|t| t.validated());
            if let Ok(Ok(target)) = parsed {
                target_uses(&target);
            }
        }
        2 => detections(text),
        _ => pairing(text),
    }
}

/// Stereo pairing by file name (`robocal stereo` and the page's
/// `pair_images`): the text's lines split at the first empty line into left
/// and right names. A pairing names each image at most once, in range.
fn pairing(text: &str) {
    let (left, right) = text.split_once("\n\n").unwrap_or((text, ""));
    let left: Vec<&str> = left.lines().collect();
    let right: Vec<&str> = right.lines().collect();
    if let Ok(found) = robocal::io::pairing::pair_by_number(&left, &right) {
        let mut seen_left = vec![false; left.len()];
        let mut seen_right = vec![false; right.len()];
        for &(l, r) in &found.pairs {
            assert!(
                !std::mem::replace(&mut seen_left[l], true),
                "left {l} paired twice"
            );
            assert!(
                !std::mem::replace(&mut seen_right[r], true),
                "right {r} paired twice"
            );
        }
    }
}

/// Spec round trip (bit for bit, as `Target::to_spec` documents), points, SVG.
fn target_uses(target: &Target) {
    let spec = target.to_spec();
    let back = Target::parse_spec(&spec)
        .unwrap_or_else(|e| panic!("spec '{spec}' of {target:?} does not parse: {e}"));
    assert_eq!(&back, target, "spec '{spec}'");
    let points = target.object_points();
    assert_eq!(points.len(), target.point_count());
    let _ = robocal::target::svg::board_svg(target);
}

/// A detections file or a single detection, read as `robocal intrinsics`
/// and the web app read it, then turned into calibration views.
fn detections(text: &str) {
    let Ok(value) = serde_json::from_str::<serde_json::Value>(text) else {
        return;
    };
    let mut found: Vec<Detection> = Vec::new();
    if let Some(images) = value.get("images").and_then(|v| v.as_array()) {
        for image in images {
            if let Some(d) = image.get("detection") {
                if let Ok(d) = serde_json::from_value::<Detection>(d.clone()) {
                    found.push(d);
                }
            }
        }
    } else if let Ok(d) = serde_json::from_value::<Detection>(value) {
        found.push(d);
    }
    let mut views = Vec::new();
    for (i, d) in found.into_iter().enumerate() {
        let written = serde_json::to_string(&d).expect("a detection serialises");
        let back: Detection = serde_json::from_str(&written)
            .unwrap_or_else(|e| panic!("written detection does not read back: {e}\n{written}"));
        assert_eq!(back, d, "{written}");
        let _ = d.correspondences();
        views.push(robocal::api::camera::JsonView {
            name: format!("view{i}"),
            detection: Some(d),
            object_m: None,
            image_px: None,
        });
    }
    let _ = robocal::api::camera::views_of(&views);
}

/// The camera calibration JSON entries: selector % 2 = 0 `calibrate_json`,
/// 1 `calibrate_stereo_json`.
pub fn calib_json(data: &[u8]) {
    let Some((selector, text)) = selector_and_text(data) else {
        return;
    };
    let _ = match selector % 2 {
        0 => robocal::api::camera::calibrate_json(text),
        _ => robocal::api::stereo::calibrate_stereo_json(text),
    };
}

/// The hand-eye JSON entries: selector % 2 = 0 `solve_handeye_json`, 1
/// `rank_candidates_json` (the web app's pose-convention ranking).
pub fn handeye_json(data: &[u8]) {
    let Some((selector, text)) = selector_and_text(data) else {
        return;
    };
    let _ = match selector % 2 {
        0 => robocal::api::handeye::solve_handeye_json(text),
        _ => robocal::api::handeye::rank_candidates_json(text),
    };
}

/// The seed workflows: selector % 8 = 0..3 the CSV files (planar matrices,
/// planar points, XY-table positions, known motions) parsed and solved as
/// `robocal planar` / `xytable` do; 4..7 the JSON requests of the wasm
/// functions `planar_fit`, `planar_solve`, `xytable_solve`,
/// `known_motion_solve`.
pub fn workflows(data: &[u8]) {
    use robocal::io::workflow_csv as csv;
    use robocal::workflows::{known_motion, xytable};
    let Some((selector, text)) = selector_and_text(data) else {
        return;
    };
    match selector % 8 {
        0 => {
            if let Ok(matrices) = csv::parse_planar_matrices(text) {
                let _ = robocal::api::planar::planar_fit(&robocal::api::planar::PlanarFitRequest {
                    matrices,
                    reject_threshold: None,
                    predict: vec![],
                });
            }
        }
        1 => {
            if let Ok(points) = csv::parse_planar_points(text) {
                let _ =
                    robocal::api::planar::planar_solve(&robocal::api::planar::PlanarSolveRequest {
                        points,
                        options: Default::default(),
                        predict: vec![],
                    });
            }
        }
        2 => {
            if let Ok(request) = csv::parse_xytable(text) {
                let _ = xytable::solve_xytable(&request);
            }
        }
        3 => {
            if let Ok(request) = csv::parse_known_motion(text) {
                let _ = known_motion::solve_known_motion(&request);
            }
        }
        4 => json_call(text, robocal::api::planar::planar_fit),
        5 => json_call(text, robocal::api::planar::planar_solve),
        6 => json_call(text, xytable::solve_xytable),
        _ => json_call(text, known_motion::solve_known_motion),
    }
}

/// What the wasm boundary's `json_call` does: read the request, solve,
/// write the report.
fn json_call<Req: serde::de::DeserializeOwned, Rep: serde::Serialize>(
    text: &str,
    solve: impl Fn(&Req) -> robocal::Result<Rep>,
) {
    if let Ok(request) = serde_json::from_str::<Req>(text) {
        if let Ok(report) = solve(&request) {
            let _ = serde_json::to_string(&report);
        }
    }
}
