//! `robocal intrinsics` through the real binary: detections files written
//! like `robocal detect`'s from seeded synthetic scenes (exact answers),
//! the OpenCV sample images when present, and bad arguments.

use crate::support;
use support::{dataset, robocal, temp_dir};

use robocal::synth::Scene;
use robocal::Camera;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A `robocal detect` output for a noise-free scene, plus one failed image.
fn detections_file(dir: &Path) -> (PathBuf, Camera) {
    let truth = Camera::example_brown();
    let scene = Scene::calibration(11, &truth, (9, 6), 0.03, 6, 0.0).expect("scene");
    let mut images: Vec<Value> = scene
        .views
        .iter()
        .map(|v| {
            let points: Vec<Value> = v
                .image_px
                .iter()
                .enumerate()
                .map(|(id, p)| json!({"id": id, "x_px": p.x, "y_px": p.y}))
                .collect();
            json!({"file": format!("{}.png", v.name), "detect_ms": 1.0, "detection": {
                "image_size_px": [1280, 960],
                "target": {"kind": "chessboard", "cols": 9, "rows": 6, "square_m": 0.03},
                "points": points}})
        })
        .collect();
    images.push(
        json!({"file": "blurred.png", "error": {"kind": "not_found", "message": "no board"}}),
    );
    let doc = json!({"robocal_version": "0.1.0",
                     "target": {"kind": "chessboard", "cols": 9, "rows": 6, "square_m": 0.03},
                     "images": images});
    let path = dir.join("detections.json");
    std::fs::write(&path, doc.to_string()).expect("write");
    (path, truth)
}

#[test]
fn detections_file_gives_the_exact_camera_and_an_exportable_report() {
    let dir = temp_dir("intrinsics", "file");
    let (detections, truth) = detections_file(&dir);
    let out = dir.join("camera.json");
    let (code, stdout, stderr) = robocal(&[
        "intrinsics",
        "--detections",
        detections.to_str().expect("path"),
        "--target",
        "chessboard:9x6:30mm",
        "-o",
        out.to_str().expect("path"),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout, "");
    assert!(
        stderr.contains("blurred.png: no detection, skipped"),
        "{stderr}"
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("read")).expect("report JSON");
    assert_eq!(report["views"].as_array().expect("views").len(), 6);
    // Noise-free: the optimum is the truth to ~1e-9 relative.
    let fx = report["camera_matrix"][0][0].as_f64().expect("fx");
    assert!((fx - truth.fx).abs() < 1e-9 * truth.fx, "fx {fx} px");
    assert!(report["rms_px"].as_f64().expect("rms") < 1e-9, "px");
    assert_eq!(
        report["views"][0]["residuals_px"]
            .as_array()
            .expect("r")
            .len(),
        54
    );
    let (code, yaml, stderr) = robocal(&[
        "export",
        out.to_str().expect("path"),
        "--format",
        "opencv-yaml",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(yaml.contains("camera_matrix: !!opencv-matrix"), "{yaml}");
    assert!(
        yaml.contains(&format!("{}", report["camera_matrix"][0][0])),
        "{yaml}"
    );
}

#[test]
fn method_all_prints_the_comparison_table() {
    let dir = temp_dir("intrinsics", "all");
    let (detections, _) = detections_file(&dir);
    let (code, stdout, stderr) = robocal(&[
        "intrinsics",
        "--detections",
        detections.to_str().expect("path"),
        "--method",
        "all",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let report: Value = serde_json::from_str(&stdout).expect("report on stdout");
    assert_eq!(report["model"], "brown");
    for line in [
        "method           fx",
        "zhang ",
        "tsai ",
        "ekf ",
        "robocal intrinsics: dlt left out: the 12-parameter DLT needs target points off one plane",
    ] {
        assert!(stderr.contains(line), "{line} in {stderr}");
    }
    assert!(
        !stderr.contains("\ndlt "),
        "a DLT row on flat boards: {stderr}"
    );
}

#[test]
fn bad_arguments_say_what_to_change() {
    let dir = temp_dir("intrinsics", "bad");
    let (detections, _) = detections_file(&dir);
    let d = detections.to_str().expect("path");
    let cases: [(&[&str], i32, &str); 6] = [
        (&["intrinsics"], 2, "robocal: intrinsics: give IMAGES or --detections FILE (see 'robocal intrinsics --help')\n"),
        (&["intrinsics", "a.png"], 2, "robocal: intrinsics: --target is required with images, e.g. --target chessboard:9x6:30mm (see 'robocal intrinsics --help')\n"),
        (&["intrinsics", "--detections", d, "a.png"], 2, "robocal: intrinsics: give either IMAGES or --detections, not both (see 'robocal intrinsics --help')\n"),
        (&["intrinsics", "--detections", d, "--method", "magic"], 1, "robocal: method: unknown method 'magic' (expected one of zhang, dlt, tsai, ekf, or all)\n"),
        (&["intrinsics", "--detections", d, "--model", "brown9"], 1, "robocal: model: unknown model 'brown9' (expected one of brown, radial_k1_k2_k5, rational, division, kannala_brandt, eucm, none, tilted, splined)\n"),
        (&["intrinsics", "--detections", d, "--target", "chessboard:7x5:30mm"], 2, "robocal: intrinsics: --target does not match the target of the detection of 'view_000.png' (see 'robocal intrinsics --help')\n"),
    ];
    for (args, want_code, want_err) in cases {
        let (code, stdout, stderr) = robocal(args);
        assert_eq!(
            (code, stdout.as_str()),
            (want_code, ""),
            "{args:?}: {stderr}"
        );
        let last = stderr.lines().last().unwrap_or("").to_string() + "\n";
        assert_eq!(last, want_err, "{args:?}");
    }
    let (code, _, stderr) = robocal(&["intrinsics", "--detections", "/nonexistent/d.json"]);
    assert_eq!(code, 1);
    assert!(
        stderr.starts_with("robocal: cannot read '/nonexistent/d.json': "),
        "{stderr}"
    );
}

#[test]
fn opencv_left_images_calibrate_near_the_published_camera() {
    let Some(dir) = dataset("opencv-left-right-9x6") else {
        eprintln!("skipped: opencv-left-right-9x6 dataset not found");
        return;
    };
    let mut args = vec![
        "intrinsics".to_string(),
        "--target".into(),
        "chessboard:9x6:25mm".into(),
    ];
    let mut images: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            name.starts_with("left") && name.ends_with(".jpg")
        })
        .collect();
    images.sort();
    args.extend(images.iter().map(|p| p.to_string_lossy().into_owned()));
    let refs: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    let (code, stdout, stderr) = robocal(&refs);
    assert_eq!(code, 0, "{stderr}");
    let report: Value = serde_json::from_str(&stdout).expect("report");
    assert_eq!(
        report["views"].as_array().expect("views").len(),
        13,
        "{stderr}"
    );
    // OpenCV's left_intrinsics.yml (fixed aspect ratio 1, its own corner
    // refinement) has fx 535.9, cx 342.3, cy 235.6; Bouguet's left
    // calibration fc 533.0, cc (341.6, 234.3). Our free-aspect result lies
    // between them; 5 px is about 5 of our standard deviations for fx.
    let k = &report["camera_matrix"];
    for (got, want) in [(&k[0][0], 534.5), (&k[0][2], 342.0), (&k[1][2], 235.0)] {
        let got = got.as_f64().expect("number");
        assert!((got - want).abs() < 5.0, "{got} vs {want} px");
    }
    assert!(report["rms_px"].as_f64().expect("rms") < 0.25, "px");
}

#[test]
fn aspect_ratio_holds_fx_equal_fy_and_repeat_times_the_solve() {
    let dir = temp_dir("intrinsics", "aspect");
    let (detections, truth) = detections_file(&dir);
    let d = detections.to_str().expect("path");
    let (code, stdout, stderr) = robocal(&[
        "intrinsics",
        "--detections",
        d,
        "--aspect-ratio",
        "1",
        "--repeat",
        "3",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("robocal intrinsics: solve time median ")
            && stderr.contains(" ms over 3 runs"),
        "{stderr}"
    );
    let report: Value = serde_json::from_str(&stdout).expect("report");
    let k = &report["camera_matrix"];
    // The truth has fy != fx, so holding fx = fy leaves residuals; the two
    // stay bit-identical.
    assert_ne!(truth.fx, truth.fy);
    assert_eq!(k[0][0], k[1][1]);
    assert_eq!(report["options"]["fix_aspect_ratio"], true);
    assert_eq!(report["options"]["aspect_ratio"], 1.0);
    for (value, message) in [
        (
            "0",
            "robocal: intrinsics: --aspect-ratio must be between 0.01 and 100 (see 'robocal intrinsics --help')\n",
        ),
        (
            "x",
            "error: invalid value 'x' for '--aspect-ratio <R>': invalid float literal\n",
        ),
    ] {
        let (code, _, stderr) =
            robocal(&["intrinsics", "--detections", d, "--aspect-ratio", value]);
        assert_ne!(code, 0);
        // The line of the error: robocal's start with "robocal: ", clap's
        // usage errors with "error: " (and end with a hint to --help).
        let line = stderr
            .lines()
            .find(|l| l.starts_with("robocal: ") || l.starts_with("error: "))
            .unwrap_or("");
        assert_eq!(line.to_string() + "\n", message);
    }
}

#[test]
fn detect_output_is_accepted_with_the_same_target_spec() {
    // `robocal detect` writes the target as JSON; `robocal intrinsics
    // --target SPEC` must find it equal to SPEC read again, also for lengths
    // that are not exact in binary (22.5778 mm was refused: 1 ulp apart).
    let dir = temp_dir("intrinsics", "roundtrip");
    let spec = "squares:8x8:12.7mm:22.5778mm";
    let renders = dir.join("renders");
    let (code, _, stderr) = robocal(&[
        "render",
        "--out",
        renders.to_str().expect("path"),
        "--target",
        spec,
        "--views",
        "6",
        "--seed",
        "3",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let mut images: Vec<String> = std::fs::read_dir(&renders)
        .expect("renders")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "png"))
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    images.sort();
    assert_eq!(images.len(), 6);
    let detections = dir.join("detections.json");
    let mut args = vec![
        "detect",
        "--target",
        spec,
        "-o",
        detections.to_str().expect("path"),
    ];
    args.extend(images.iter().map(String::as_str));
    let (code, _, stderr) = robocal(&args);
    assert_eq!(code, 0, "{stderr}");
    let out = dir.join("camera.json");
    let (code, _, stderr) = robocal(&[
        "intrinsics",
        "--target",
        spec,
        "--detections",
        detections.to_str().expect("path"),
        "-o",
        out.to_str().expect("path"),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("report")).expect("json");
    // The renderer's default camera: fx 900 px; noise sigma 2 on 6 views.
    let fx = report["camera_matrix"][0][0].as_f64().expect("fx");
    assert!((fx - 900.0).abs() < 5.0, "fx {fx} px");
}

#[test]
fn brown5_is_the_issue_spelling_of_brown() {
    // `robocal intrinsics --model brown5` (OpenCV's five coefficients, the
    // spelling of the CLI contract) solves the same model as `brown`.
    let dir = temp_dir("intrinsics", "brown5");
    let (detections, _) = detections_file(&dir);
    let solve = |model: &str| {
        let out = dir.join(format!("{model}.json"));
        let (code, _, stderr) = robocal(&[
            "intrinsics",
            "--detections",
            detections.to_str().expect("path"),
            "--model",
            model,
            "-o",
            out.to_str().expect("path"),
        ]);
        assert_eq!(code, 0, "{stderr}");
        let report: Value =
            serde_json::from_str(&std::fs::read_to_string(&out).expect("report")).expect("json");
        (
            report["model"].clone(),
            report["camera_matrix"].clone(),
            report["distortion"].clone(),
        )
    };
    let brown = solve("brown");
    assert_eq!(brown.0, "brown");
    assert_eq!(solve("brown5"), brown);
}

#[test]
fn robust_option_says_how_many_points_it_rejected() {
    let dir = temp_dir("intrinsics", "robust");
    let (detections, _) = detections_file(&dir);
    let out = dir.join("camera.json");
    let (code, _, stderr) = robocal(&[
        "intrinsics",
        "--detections",
        detections.to_str().expect("path"),
        "--target",
        "chessboard:9x6:30mm",
        "--robust",
        "-o",
        out.to_str().expect("path"),
    ]);
    assert_eq!(code, 0, "{stderr}");
    // Noise-free views (6 x 54 points): the robust sigma is 0 and nothing is cut.
    assert!(
        stderr.contains("robocal intrinsics: robust loss: no point rejected (of 324)\n"),
        "{stderr}"
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("read")).expect("report JSON");
    assert_eq!(report["rejected"]["count"], 0);
    assert_eq!(report["rejected"]["of_points"], 324);
    // Without the option the report has no "rejected".
    let (code, _, stderr) = robocal(&[
        "intrinsics",
        "--detections",
        detections.to_str().expect("path"),
        "--target",
        "chessboard:9x6:30mm",
        "-o",
        out.to_str().expect("path"),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("robust loss"), "{stderr}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("read")).expect("report JSON");
    assert!(report.get("rejected").is_none());
}

#[test]
fn circle_grid_detections_report_their_centre_model() {
    // The chessboard scene's points as a symmetric 9x6 circle grid (the
    // same board points), all with the default centre model.
    let dir = temp_dir("intrinsics", "centre_model");
    let (chess, _) = detections_file(&dir);
    let text = std::fs::read_to_string(&chess).expect("read");
    let mut doc: Value = serde_json::from_str(&text).expect("JSON");
    let grid = json!({"kind": "circle_grid", "cols": 9, "rows": 6, "spacing_m": 0.03,
                      "asymmetric": false, "polarity": "dark_on_light"});
    doc["target"] = grid.clone();
    for image in doc["images"].as_array_mut().expect("images") {
        if let Some(d) = image.get_mut("detection") {
            d["target"] = grid.clone();
            d["centre_model"] = json!("perspective_pole");
        }
    }
    let path = dir.join("circles.json");
    std::fs::write(&path, doc.to_string()).expect("write");
    let out = dir.join("camera.json");
    let (code, _, stderr) = robocal(&[
        "intrinsics",
        "--detections",
        path.to_str().expect("path"),
        "-o",
        out.to_str().expect("path"),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("robocal intrinsics: circle centres: perspective_pole\n"),
        "{stderr}"
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("read")).expect("report JSON");
    assert_eq!(report["centre_model"], "perspective_pole");
    assert!(report.get("centre_models").is_none(), "{report}");
    // The key does not disturb the readers of the report.
    let (code, yaml, stderr) = robocal(&[
        "export",
        out.to_str().expect("path"),
        "--format",
        "opencv-yaml",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(yaml.contains("camera_matrix: !!opencv-matrix"), "{yaml}");
}

/// The `--model` help of every command that solves cameras is made from the
/// lens-model table: each lists every model of `camera::LENS_MODELS`.
#[test]
fn the_model_help_lists_every_model_of_the_table() {
    for (command, subject) in [
        ("intrinsics", "the camera"),
        ("stereo", "both cameras"),
        ("rig", "the solved cameras"),
    ] {
        let (code, stdout, stderr) = robocal(&[command, "--help"]);
        assert_eq!(code, 0, "{command} --help: {stderr}");
        // clap wraps long help lines: compare with the white space collapsed.
        let help = stdout.split_whitespace().collect::<Vec<_>>().join(" ");
        let wanted = robocal::camera::model_help(subject);
        assert!(
            help.contains(&wanted),
            "{command} --help lacks '{wanted}':\n{stdout}"
        );
        for name in robocal::camera::MODEL_NAMES {
            assert!(help.contains(name), "{command} --help lacks {name}");
        }
    }
}

/// A detections file of `truth` seen in `n_views` views of a 10x8 board at
/// `noise_px` (seed 11, the scene of the library's cross-validation test).
fn scene_detections(
    dir: &std::path::Path,
    truth: &Camera,
    n_views: usize,
    noise_px: f64,
) -> PathBuf {
    let scene = Scene::calibration(11, truth, (10, 8), 0.03, n_views, noise_px).expect("scene");
    let target = json!({"kind": "chessboard", "cols": 10, "rows": 8, "square_m": 0.03});
    let images: Vec<Value> = scene
        .views
        .iter()
        .map(|v| {
            let points: Vec<Value> = v
                .object_m
                .iter()
                .zip(&v.image_px)
                .map(|(o, p)| {
                    let id = (o.y / 0.03).round() as usize * 10 + (o.x / 0.03).round() as usize;
                    json!({"id": id, "x_px": p.x, "y_px": p.y})
                })
                .collect();
            json!({"file": format!("{}.png", v.name), "detect_ms": 1.0, "detection": {
                "image_size_px": [truth.width, truth.height], "target": target, "points": points}})
        })
        .collect();
    let path = dir.join("detections.json");
    let doc = json!({"robocal_version": "0.1.0", "target": target, "images": images});
    std::fs::write(&path, doc.to_string()).expect("write");
    path
}

#[test]
fn cross_validation_tells_a_fisheye_s_brown_halves_apart_and_names_kannala_brandt() {
    let dir = temp_dir("intrinsics", "cross-validate");
    let d = scene_detections(&dir, &Camera::example_kannala_brandt(), 24, 0.1);
    let (code, stdout, stderr) = robocal(&[
        "intrinsics",
        "--detections",
        d.to_str().expect("path"),
        "--cross-validate",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let report: Value = serde_json::from_str(&stdout).expect("report");
    let cv = &report["cross_validation"];
    assert_eq!(cv["views"], json!([12, 12]));
    let rows = cv["models"].as_array().expect("models");
    let row = |m: &str| rows.iter().find(|r| r["model"] == m).expect("row");
    assert_eq!(row("brown")["chosen"], json!(true));
    assert_eq!(row("brown")["agree"], json!(false));
    assert_eq!(row("kannala_brandt")["agree"], json!(true));
    let recommended = cv["recommended"].as_str().expect("recommended");
    for key in [
        "diff_median_px",
        "diff_worst_px",
        "predicted_median_px",
        "ratio_median",
        "grid_points",
    ] {
        assert!(row("kannala_brandt")[key].is_number(), "{key}");
    }
    // A fisheye model (EUCM follows this lens too), named in the warning.
    assert!(
        ["kannala_brandt", "eucm"].contains(&recommended),
        "{recommended}"
    );
    assert!(
        stderr.contains("robocal intrinsics: warning: cross-validation: "),
        "{stderr}"
    );
    assert!(
        stderr.contains(&format!("(CLI: --model {recommended})")),
        "{stderr}"
    );
    // Without the flag, no key.
    let (_, stdout, _) = robocal(&["intrinsics", "--detections", d.to_str().expect("path")]);
    let plain: Value = serde_json::from_str(&stdout).expect("report");
    assert!(plain.get("cross_validation").is_none());
}

#[test]
fn the_remap_export_holds_a_map_per_pixel_for_cv2_remap() {
    let dir = temp_dir("intrinsics", "remap");
    let camera = dir.join("camera.json");
    std::fs::write(
        &camera,
        r#"{"image_size_px": [64, 48], "camera_matrix": [[60, 0, 31.5], [0, 60, 23.5], [0, 0, 1]],
            "model": "brown", "distortion": {"k1": -0.2, "k2": 0.05, "k3": 0, "p1": 0, "p2": 0}}"#,
    )
    .expect("write");
    let (code, stdout, stderr) = robocal(&[
        "export",
        camera.to_str().expect("path"),
        "--format",
        "remap",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.starts_with(
            "%YAML:1.0\n---\nimage_width: 64\nimage_height: 48\ncamera_matrix: !!opencv-matrix\n"
        ),
        "{}",
        &stdout[..200]
    );
    assert!(
        stdout.contains("mapx: !!opencv-matrix\n   rows: 48\n   cols: 64\n   dt: f\n   data: [ ")
    );
    assert!(
        stdout.contains("mapy: !!opencv-matrix\n   rows: 48\n   cols: 64\n   dt: f\n   data: [ ")
    );
    // One value per pixel; barrel distortion pulls the output's corner
    // pixel inwards in the source image.
    let values = |name: &str| -> Vec<f64> {
        let start = stdout
            .find(&format!("{name}: !!opencv-matrix"))
            .expect("matrix");
        let rest = &stdout[start..];
        let (open, close) = (rest.find('[').expect("["), rest.find(']').expect("]"));
        rest[open + 1..close]
            .split(',')
            .map(|v| v.trim().parse().expect("number"))
            .collect()
    };
    let (mapx, mapy) = (values("mapx"), values("mapy"));
    assert_eq!((mapx.len(), mapy.len()), (64 * 48, 64 * 48));
    assert!(mapx[0] > 0.5 && mapy[0] > 0.5, "{} {}", mapx[0], mapy[0]);
}
