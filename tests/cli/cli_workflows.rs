//! The workflow subcommands (`robocal planar`, `robocal xytable`) run as a
//! user runs them: real files in, JSON out, exit codes and error messages.

use std::path::PathBuf;
use std::process::{Command, Output};

fn robocal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the robocal binary runs")
}

fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "robocal failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).trim().to_string()
}

/// A scratch file unique to this test process.
fn scratch(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("robocal-cli-workflows-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn planar_fit_prints_the_fit_object() {
    let out = robocal(&[
        "planar",
        "fit",
        "fixtures/seed001/table4_matrices.csv",
        "--predict",
        "20",
        "--point",
        "1833.0,3508.8",
    ]);
    let v = json(&out);
    for key in ["a11", "a12", "tx", "a21", "a22", "ty"] {
        for field in ["intercept", "slope", "r2", "pearson_r", "adj_r2", "rss"] {
            assert!(
                v["fit"][key][field].is_number(),
                "fit.{key}.{field} missing"
            );
        }
    }
    // Table 5: tx intercept -1748.81438, slope 0.35111.
    assert!((v["fit"]["tx"]["intercept"].as_f64().unwrap() + 1748.81438).abs() < 1e-5);
    // Table 7, 20 mm: measured X 691.07 mm; within the article's 0.08 %.
    let x = v["predictions"][0]["robot_mm"][0].as_f64().unwrap();
    assert!((x - 691.07).abs() / 691.07 < 8e-4, "x = {x} mm");
}

#[test]
fn planar_solve_reads_table3_directly() {
    let out = robocal(&["planar", "solve", "fixtures/seed001/table3_four_points.csv"]);
    let v = json(&out);
    let heights = v["heights"].as_array().unwrap();
    assert_eq!(heights.len(), 4);
    // 15 mm, Table 4: a12 = 0.697815001.
    let a12 = heights[0]["robot_from_image"]["a12"].as_f64().unwrap();
    assert!((a12 - 0.697815001).abs() < 1e-6, "a12 = {a12}");
    assert_eq!(heights[0]["residuals_mm"].as_array().unwrap().len(), 4);
    assert!(v["fit"]["ty"]["slope"].is_number());
    assert_eq!(v["pixel_density"].as_array().unwrap().len(), 4);
}

#[test]
fn planar_bad_input_gives_clear_errors() {
    let header = "height_mm,u_px,v_px,x_mm,y_mm\n";
    let two_points = scratch(
        "two.csv",
        &format!("{header}15,0,0,0,0\n15,10,0,7,0\n45,0,0,0,0\n45,10,0,7,0\n45,0,10,0,7\n"),
    );
    let out = robocal(&["planar", "solve", two_points.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out),
        "robocal: requires at least 3 point pairs, got 2"
    );

    let collinear = scratch(
        "line.csv",
        &format!("{header}15,0,0,0,0\n15,10,10,7,7\n15,20,20,14,14\n"),
    );
    let out = robocal(&["planar", "solve", collinear.to_str().unwrap()]);
    assert_eq!(
        stderr(&out),
        "robocal: the 3 image points are collinear (spread ratio 0.0e0): \
         a planar transform needs points that span both image directions"
    );

    let one_height = scratch(
        "one.csv",
        &format!("{header}15,0,0,0,0\n15,10,0,7,0\n15,0,10,0,7\n"),
    );
    let out = robocal(&["planar", "solve", one_height.to_str().unwrap()]);
    assert_eq!(
        stderr(&out),
        "robocal: requires at least 2 distinct calibration heights, got 1"
    );

    let ragged = scratch("ragged.csv", &format!("{header}15,0,0,0\n"));
    let out = robocal(&["planar", "solve", ragged.to_str().unwrap()]);
    assert!(
        stderr(&out).ends_with("line 2: expected 5 comma-separated fields like the header, got 4"),
        "{}",
        stderr(&out)
    );

    let out = robocal(&[
        "planar",
        "solve",
        two_points.to_str().unwrap(),
        "--transform",
        "projective",
    ]);
    assert_eq!(
        stderr(&out),
        "robocal: transform: expected rigid, similarity or affine, got 'projective'"
    );

    let out = robocal(&[
        "planar",
        "fit",
        "fixtures/seed001/table4_matrices.csv",
        "--point",
        "1,2",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out),
        "robocal: planar: --point needs --predict HEIGHT_MM (see 'robocal planar --help')"
    );
}

/// A synthetic XY-table scene: camera 600 mm above the stage, looking down.
fn xytable_csv(extra: &str) -> (String, nalgebra::Matrix3x4<f64>) {
    use nalgebra::{Matrix3, Point3, Translation3, UnitQuaternion};
    let k = Matrix3::new(1200.0, 0.0, 640.0, 0.0, 1200.0, 480.0, 0.0, 0.0, 1.0);
    let pose = robocal::geometry::Pose::from_parts(
        Translation3::new(10.0, -5.0, 600.0),
        UnitQuaternion::from_euler_angles(3.1, 0.05, 0.3),
    );
    let p =
        robocal::calib::dlt::normalize_scale(&(k * pose.to_homogeneous().fixed_view::<3, 4>(0, 0)));
    let mut csv = String::from("x_mm,y_mm,z_mm,u_px,v_px,role\n");
    let mut row = |x: f64, y: f64, z: f64, role: &str| {
        let q = robocal::calib::dlt::project(&p, &Point3::new(x, y, z));
        csv.push_str(&format!("{x},{y},{z},{},{},{role}\n", q.x, q.y));
    };
    for z in [0.0, 40.0] {
        for x in [-100.0, 0.0, 100.0] {
            for y in [-80.0, 0.0, 80.0] {
                row(x, y, z, "calibration");
            }
        }
    }
    for (x, y) in [(-60.0, -50.0), (60.0, -50.0), (60.0, 50.0), (-60.0, 50.0)] {
        row(x, y, 20.0, "verify");
    }
    csv.push_str(extra);
    (csv, p)
}

#[test]
fn xytable_gives_both_matrices_and_the_verification_point() {
    let (csv, truth) =
        xytable_csv("0,0,0,640.1,480.0,still\n0,0,0,639.9,480.1,still\n0,0,0,640.0,479.9,still\n");
    let file = scratch("xytable.csv", &csv);
    let v = json(&robocal(&["xytable", file.to_str().unwrap()]));
    for method in ["batch", "kalman"] {
        let p: Vec<f64> = v[method]["projection_matrix"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(p.len(), 12);
        let err = (nalgebra::Matrix3x4::from_row_slice(&p) - truth).norm() / truth.norm();
        // Noise-free centres (printed with 17 significant digits).
        assert!(err < 1e-9, "{method}: relative error {err:e}");
        assert!(v[method]["rms_px"].as_f64().unwrap() < 1e-6);
    }
    assert_eq!(v["noise_source"], "still_target");
    assert_eq!(v["kalman"]["history"].as_array().unwrap().len(), 18);
    let e = v["verification"]["batch_error_px"].as_f64().unwrap();
    assert!(e < 1e-6, "verification error {e} px");
}

#[test]
fn xytable_bad_input_gives_clear_errors() {
    let few = scratch(
        "few.csv",
        "x_mm,y_mm,z_mm,u_px,v_px\n0,0,0,1,1\n1,0,0,2,1\n0,1,0,1,2\n0,0,1,1,1\n1,1,1,2,2\n",
    );
    let out = robocal(&["xytable", few.to_str().unwrap()]);
    assert_eq!(
        stderr(&out),
        "robocal: requires at least 6 3-D/2-D point pairs, got 5"
    );

    let (csv, _) = xytable_csv("");
    let flat: String = csv.lines().take(10).map(|l| format!("{l}\n")).collect();
    let flat = scratch("flat.csv", &flat);
    let out = robocal(&["xytable", flat.to_str().unwrap()]);
    assert!(
        stderr(&out).starts_with("robocal: the 9 3-D points are coplanar"),
        "{}",
        stderr(&out)
    );

    let images = scratch("images.csv", "x_mm,y_mm,z_mm,image\n0,0,0,missing.png\n");
    let out = robocal(&["xytable", images.to_str().unwrap()]);
    assert!(
        stderr(&out).contains("line 2, column 4: missing.png: image: cannot read it: "),
        "{}",
        stderr(&out)
    );

    let out = robocal(&["xytable", few.to_str().unwrap(), "--kalman", "unscented"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out),
        "robocal: xytable: --kalman: expected extended or linearized, got 'unscented' (see 'robocal xytable --help')"
    );
}

#[test]
fn known_motion_frame_from_the_cli() {
    // Rotation of 90 degrees about z, start point at (100, 200, 1000) mm in
    // the camera frame: increments d map to (-dy, dx, dz).
    let mut csv = String::from("dx_mm,dy_mm,dz_mm,x_cam_mm,y_cam_mm,z_cam_mm\n");
    for d in [
        [0.0, 0.0, 0.0],
        [50.0, 0.0, 0.0],
        [0.0, 50.0, 0.0],
        [0.0, 0.0, 50.0],
        [30.0, 30.0, 30.0],
    ] {
        csv.push_str(&format!(
            "{},{},{},{},{},{}\n",
            d[0],
            d[1],
            d[2],
            100.0 - d[1],
            200.0 + d[0],
            1000.0 + d[2]
        ));
    }
    let file = scratch("motion.csv", &csv);
    let v = json(&robocal(&[
        "xytable",
        "--known-motion",
        file.to_str().unwrap(),
        "--start-mm",
        "10,0,0",
    ]));
    let q: Vec<f64> = v["camera_from_reference"]["quaternion_xyzw"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let h = 0.5f64.sqrt();
    assert!(
        (q[2].abs() - h).abs() < 1e-9 && (q[3].abs() - h).abs() < 1e-9,
        "{q:?}"
    );
    // T = c - R start = (100, 200, 1000) - (0, 10, 0) mm.
    let t: Vec<f64> = v["camera_from_reference"]["translation_m"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(
        (t[0] - 0.1).abs() < 1e-12 && (t[1] - 0.19).abs() < 1e-12 && (t[2] - 1.0).abs() < 1e-12,
        "{t:?}"
    );
    assert!(v["rms_mm"].as_f64().unwrap() < 1e-9);
}

/// Image files instead of centres: the CLI renders nothing, it detects the
/// circle in each image. Renders: a 10 mm dark circle on a plate parallel
/// to the image plane (so the ellipse centre is the projected centre, no
/// perspective bias), seen by a 1200 px pinhole 600 mm above the table, grey
/// noise sigma 2. Detection error ~0.02 px, so the DLT residual stays well
/// under 0.1 px.
#[test]
fn xytable_detects_the_circle_in_image_files() {
    use robocal::synth::{render, Pinhole, RenderOptions};
    use robocal::target::Target;
    let dir = std::env::temp_dir().join(format!("robocal-xyimages-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cam = Pinhole {
        fx: 1200.0,
        fy: 1200.0,
        cx: 639.5,
        cy: 479.5,
        width: 1280,
        height: 960,
    };
    let target = Target::SingleCircle { diameter_m: 0.01 };
    let mut csv = String::from("x_mm,y_mm,z_mm,image\n");
    let mut i = 0;
    for z in [0.0, 40.0] {
        for x in [-100.0, 0.0, 100.0] {
            for y in [-80.0, 0.0, 80.0] {
                let pose = nalgebra::Isometry3::from_parts(
                    nalgebra::Translation3::new(x / 1000.0, -y / 1000.0, (600.0 - z) / 1000.0),
                    nalgebra::UnitQuaternion::from_axis_angle(
                        &nalgebra::Vector3::x_axis(),
                        std::f64::consts::PI,
                    ),
                );
                let options = RenderOptions {
                    seed: i,
                    ..RenderOptions::default()
                };
                let r = render(&cam, &target, &pose, &options).unwrap();
                let name = format!("c{i:02}.png");
                std::fs::write(
                    dir.join(&name),
                    robocal::image::encode_png(&r.image).unwrap(),
                )
                .unwrap();
                csv.push_str(&format!("{x},{y},{z},{name}\n"));
                i += 1;
            }
        }
    }
    let file = dir.join("positions.csv");
    std::fs::write(&file, csv).unwrap();
    let out = robocal(&["xytable", file.to_str().unwrap(), "--target", "circle:10mm"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rms = v["batch"]["rms_px"].as_f64().unwrap();
    assert!(rms < 0.1, "batch RMS {rms} px");
}
