//! `robocal check` and `robocal diff` on renders: a camera calibrated from
//! 12 rendered views, then new renders of the same camera (ok), of the
//! camera with its focal length 2 % longer or its principal point moved
//! (drifted, naming the parameter), of another camera or with the wrong
//! target (broken), and the messages for bad input.

use crate::support::{robocal, temp_dir};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

const TARGET: &str = "chessboard:9x6:30mm";

/// A 640 x 480 camera file (robocal camera JSON) with mild barrel distortion.
fn camera_file(dir: &Path, name: &str, fx: f64, cx: f64, k1: f64, size: [u32; 2]) -> PathBuf {
    let h = size[1] as f64;
    let camera = json!({
        "model": "brown", "image_size_px": size,
        "camera_matrix": [[fx, 0, cx], [0, fx, (h - 1.0) / 2.0], [0, 0, 1]],
        "distortion": {"k1": k1, "k2": 0.02, "k3": 0, "p1": 0, "p2": 0}
    });
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, camera.to_string()).unwrap();
    path
}

/// `views` renders through `camera` into `dir/name`: the PNG paths.
fn render(dir: &Path, name: &str, camera: &Path, views: usize, seed: u64) -> Vec<String> {
    let out = dir.join(name);
    let (code, _, err) = robocal(&[
        "render",
        "--out",
        out.to_str().unwrap(),
        "--camera",
        camera.to_str().unwrap(),
        "--views",
        &views.to_string(),
        "--seed",
        &seed.to_string(),
    ]);
    assert_eq!(code, 0, "{err}");
    (0..views)
        .map(|v| {
            out.join(format!("view_{v:03}.png"))
                .to_str()
                .unwrap()
                .to_string()
        })
        .collect()
}

/// `robocal check` of `images` against `calibration`: the report.
fn check(calibration: &Path, images: &[String], extra: &[&str]) -> Value {
    let mut args = vec![
        "check",
        "--camera",
        calibration.to_str().unwrap(),
        "--target",
        TARGET,
    ];
    args.extend_from_slice(extra);
    args.extend(images.iter().map(String::as_str));
    let (code, out, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    serde_json::from_str(&out).unwrap()
}

fn moved(report: &Value) -> Vec<String> {
    report["moved"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m.as_str().unwrap().to_string())
        .collect()
}

#[test]
fn check_reads_ok_drifted_and_broken_on_renders_and_diff_measures_the_change() {
    let dir = temp_dir("cli", "check");
    let truth = camera_file(&dir, "truth", 600.0, 319.5, -0.1, [640, 480]);
    let images = render(&dir, "calibration", &truth, 12, 1);
    let calibration = dir.join("calibration.json");
    let mut args = vec![
        "intrinsics",
        "--target",
        TARGET,
        "-o",
        calibration.to_str().unwrap(),
    ];
    args.extend(images.iter().map(String::as_str));
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");

    // The same camera, other poses: ok.
    let same = check(&calibration, &render(&dir, "same", &truth, 5, 2), &[]);
    assert_eq!(same["kind"], "check");
    assert_eq!(same["verdict"], "ok", "{}", same["reasons"]);
    let shift = &same["projection_shift_px"];
    assert!(shift["worst"].as_f64().unwrap() < same["thresholds"]["shift_px"].as_f64().unwrap());
    assert!(shift["median"].as_f64().is_some() && shift["map"].as_array().unwrap().len() == 40);
    assert_eq!(same["parameters"].as_array().unwrap().len(), 4);
    eprintln!(
        "same camera: worst shift {} px, threshold {} px",
        shift["worst"], same["thresholds"]["shift_px"]
    );

    // Focal length 2 % longer: drifted, fx and fy moved.
    let longer = camera_file(&dir, "longer", 612.0, 319.5, -0.1, [640, 480]);
    let drifted = check(&calibration, &render(&dir, "longer", &longer, 5, 3), &[]);
    assert_eq!(drifted["verdict"], "drifted", "{}", drifted["reasons"]);
    let names = moved(&drifted);
    assert!(
        names.contains(&"fx".to_string()) && names.contains(&"fy".to_string()),
        "{names:?}"
    );
    let fx = &drifted["parameters"][0];
    assert_eq!(fx["name"], "fx");
    assert!(fx["shift_std"].as_f64().unwrap() > 3.0, "{fx}");
    let worst = drifted["projection_shift_px"]["worst"].as_f64().unwrap();
    eprintln!(
        "focal +2 %: fx shift {} px ({} std), projection shift worst {worst} px",
        fx["shift_px"], fx["shift_std"]
    );
    assert!(worst > 3.0, "{worst}");

    // Principal point 6 px to the right: drifted, cx moved.
    let moved_pp = camera_file(&dir, "moved", 600.0, 325.5, -0.1, [640, 480]);
    let drifted = check(&calibration, &render(&dir, "moved", &moved_pp, 5, 4), &[]);
    assert_eq!(drifted["verdict"], "drifted", "{}", drifted["reasons"]);
    assert!(
        moved(&drifted).contains(&"cx".to_string()),
        "{:?}",
        moved(&drifted)
    );

    // Another camera entirely: broken. The wrong target: broken.
    let other = camera_file(&dir, "other", 420.0, 300.0, 0.25, [640, 480]);
    let broken = check(&calibration, &render(&dir, "other", &other, 5, 5), &[]);
    assert_eq!(broken["verdict"], "broken", "{}", broken["reasons"]);
    let same_images = render(&dir, "same", &truth, 5, 2);
    let mut args = vec![
        "check",
        "--camera",
        calibration.to_str().unwrap(),
        "--target",
        "chessboard:7x5:30mm",
    ];
    args.extend(same_images.iter().map(String::as_str));
    let (code, out, _) = robocal(&args);
    assert_eq!(code, 0);
    let wrong: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(wrong["verdict"], "broken");
    assert_eq!(
        wrong["reasons"][0],
        "the target was not found in any image: check the target and that it is in view"
    );
    // Overridden thresholds are the ones reported and used.
    let strict = check(
        &calibration,
        &same_images,
        &["--shift-px", "0.0001", "--param-sigma", "7"],
    );
    assert_eq!(strict["thresholds"]["shift_px"], 0.0001);
    assert_eq!(strict["thresholds"]["param_sigma"], 7.0);
    assert_eq!(strict["verdict"], "drifted");

    // diff: the saved calibration against the truth and a 2 % longer focal.
    let out_file = dir.join("diff.json");
    let (code, _, err) = robocal(&[
        "diff",
        calibration.to_str().unwrap(),
        truth.to_str().unwrap(),
        "-o",
        out_file.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let diff: Value = serde_json::from_str(&std::fs::read_to_string(&out_file).unwrap()).unwrap();
    assert_eq!(diff["kind"], "diff");
    assert!(
        diff["projection_shift_px"]["worst"].as_f64().unwrap() < 1.0,
        "{}",
        diff["projection_shift_px"]["worst"]
    );
    let (code, out, _) = robocal(&[
        "diff",
        truth.to_str().unwrap(),
        longer.to_str().unwrap(),
        "--grid",
        "30x20",
    ]);
    assert_eq!(code, 0);
    let diff: Value = serde_json::from_str(&out).unwrap();
    let d = &diff["projection_shift_px"];
    // Pinhole part: 2 % of the corner's distance from the centre (400 px),
    // the distortion scaling with it.
    assert!(
        (d["worst"].as_f64().unwrap() - 8.0).abs() < 1.5,
        "{}",
        d["worst"]
    );
    assert_eq!(d["map"].as_array().unwrap().len(), 20);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_gets_a_message_that_names_it() {
    let dir = temp_dir("cli", "check-bad");
    let truth = camera_file(&dir, "truth", 600.0, 319.5, -0.1, [640, 480]);
    let small = camera_file(&dir, "small", 300.0, 159.5, -0.1, [320, 240]);
    let images = render(&dir, "small", &small, 1, 1);
    let (code, _, err) = robocal(&[
        "check",
        "--camera",
        "missing.json",
        "--target",
        TARGET,
        &images[0],
    ]);
    assert_eq!(code, 1);
    assert_eq!(
        err,
        "robocal: cannot read 'missing.json': No such file or directory (os error 2)\n"
    );
    let t = truth.to_str().unwrap();
    let (code, _, err) = robocal(&["check", "--camera", t, "--target", TARGET, "missing.png"]);
    assert_eq!(code, 1);
    assert_eq!(
        err,
        "robocal: cannot read 'missing.png': No such file or directory (os error 2)\n"
    );
    let (code, _, err) = robocal(&["check", "--camera", t, "--target", TARGET, &images[0]]);
    assert_eq!(code, 1);
    assert_eq!(
        err,
        format!(
            "robocal: views[0] ({}): the image is 320x240 but the saved calibration is of 640x480 \
             images: check with images of the calibrated camera at its resolution\n",
            images[0]
        )
    );
    let (code, _, err) = robocal(&["diff", t, small.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert_eq!(
        err,
        "robocal: b: image size 320x240 differs from a's 640x480: a projection difference \
         compares two calibrations of one camera at one resolution\n"
    );
    let (code, _, err) = robocal(&["diff", t, t, "--grid", "60"]);
    assert_eq!(code, 2);
    assert_eq!(
        err,
        "robocal: diff: --grid '60': give columns x rows, e.g. 60x40 (see 'robocal diff --help')\n"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `diff` (and so `check --camera`) reads every camera format robocal
/// exports, HALCON's own `.dat` too: each against the JSON it came from
/// shifts nothing; a damaged file names its line.
#[test]
fn diff_reads_halcon_matlab_and_text_files() {
    use robocal::camera::{Camera, Distortion};
    use robocal::io::export_camera::{export_camera, CameraExportInfo, CameraFormat};
    let dir = temp_dir("cli", "check-formats");
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let info = CameraExportInfo::default();
    let diff_worst = |a: &str, b: &str| {
        let (code, out, err) = robocal(&["diff", a, b, "--grid", "30x20"]);
        assert_eq!(code, 0, "{a} {b}: {err}");
        let diff: Value = serde_json::from_str(&out).unwrap();
        diff["projection_shift_px"]["worst"].as_f64().unwrap()
    };
    let brown = Camera::example_brown();
    let json = write(
        "brown.json",
        &export_camera(&brown, &info, CameraFormat::Json).unwrap(),
    );
    let other = write(
        "brown.m",
        &export_camera(&brown, &info, CameraFormat::Matlab).unwrap(),
    );
    let worst = diff_worst(&json, &other);
    assert!(worst < 1e-6, "brown.m: {worst} px");
    // HALCON's polynomial undistorts: the export fits it (within 0.5 px),
    // the reader fits Brown back (within 0.05 px); a milder lens, as the
    // lens-model table says.
    let mild = Camera {
        distortion: brown
            .distortion
            .with_coefficients(
                &brown
                    .distortion
                    .coefficients()
                    .iter()
                    .map(|c| c * 0.1)
                    .collect::<Vec<_>>(),
            )
            .unwrap(),
        ..brown.clone()
    };
    let mild_json = write(
        "mild.json",
        &export_camera(&mild, &info, CameraFormat::Json).unwrap(),
    );
    let other = write(
        "mild.hdev.txt",
        &export_camera(&mild, &info, CameraFormat::Halcon).unwrap(),
    );
    let worst = diff_worst(&mild_json, &other);
    assert!(worst < 0.55, "mild.hdev.txt: {worst} px");
    let err = export_camera(&brown, &info, CameraFormat::Halcon)
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("format: HALCON's area_scan_polynomial maps distorted to undistorted points; the nearest one to this brown model is off by "),
        "{err}"
    );
    let pinhole = Camera::example_pinhole();
    let json = write(
        "pinhole.json",
        &export_camera(&pinhole, &info, CameraFormat::Json).unwrap(),
    );
    let text = write(
        "K.txt",
        &export_camera(&pinhole, &info, CameraFormat::Text).unwrap(),
    );
    assert!(diff_worst(&json, &text) < 1e-6);
    // HALCON's write_cam_par: Focus 8 mm, Kappa -2500 1/m^2, 8.3 um pixels.
    let dat = "ParGroup: Camera: Parameter;\n\t\"Internal camera parameters\";\n\n\
        Focus:foc:\t0.008;\n\tDOUBLE:0.0:;\n\tKappa:kappa:\t-2500;\n\
        Sx:sx:\t8.3e-06;\nSy:sy:\t8.3e-06;\nCx:cx:\t371.5;\nCy:cy:\t243.25;\n\
        ImageWidth:imgw:\t752;\nImageHeight:imgh:\t480;\n";
    let f = 0.008 / 8.3e-6;
    let same = Camera {
        fx: f,
        fy: f,
        cx: 371.5,
        cy: 243.25,
        skew: 0.0,
        width: 752,
        height: 480,
        distortion: Distortion::Division {
            kappa: -2500.0 * 0.008 * 0.008,
        },
    };
    let dat_path = write("camera.dat", dat);
    let same = write(
        "same.json",
        &export_camera(&same, &info, CameraFormat::Json).unwrap(),
    );
    assert!(diff_worst(&same, &dat_path) < 1e-6);
    let broken = write("broken.dat", &dat.replace("Cy:cy:\t243.25;\n", ""));
    let (code, _, err) = robocal(&["diff", &same, &broken]);
    assert_eq!(code, 1);
    assert_eq!(
        err,
        format!(
            "robocal: '{broken}': the HALCON camera file (area_scan_division) has no Cy entry \
             ('Cy:cy: <value>;'): the file is truncated or not from write_cam_par\n"
        )
    );
    let _ = std::fs::remove_dir_all(&dir);
}
