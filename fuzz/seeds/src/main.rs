//! Writes the seed corpus of every fuzz target: `robocal-fuzz-seeds REPO OUT`
//! fills `OUT/<target>/` from the project's fixtures (`fixtures/`) and
//! from small seeded renders and synthetic scenes,
//! each input in the layout its target reads (`fuzz/src/cases.rs`).
//! Deterministic: the same files on every run.

#[path = "../../src/cases.rs"]
mod cases;

use std::fs;
use std::path::{Path, PathBuf};

use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3};
use robocal::geometry::Pose;
use robocal::handeye::Setup;
use robocal::image::GrayImage;
use robocal::io::{PoseFormat, RobotPose};
use robocal::synth::handeye::{handeye_scene, HandEyeSceneConfig};
use robocal::synth::{board_pose, render, Pinhole, RenderOptions, Scene};
use robocal::target::{Detection, Target};
use serde_json::{json, Value};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Writes numbered seeds into one target's folder.
struct Corpus {
    dir: PathBuf,
    count: usize,
}

impl Corpus {
    fn new(out: &Path, target: &str) -> Res<Corpus> {
        let dir = out.join(target);
        fs::create_dir_all(&dir)?;
        Ok(Corpus { dir, count: 0 })
    }

    fn put(&mut self, name: &str, bytes: &[u8]) -> Res<()> {
        fs::write(self.dir.join(format!("seed-{:03}-{name}", self.count)), bytes)?;
        self.count += 1;
        Ok(())
    }

    /// A selector byte, then the text.
    fn text(&mut self, name: &str, selector: u8, text: &str) -> Res<()> {
        let mut bytes = vec![selector];
        bytes.extend_from_slice(text.as_bytes());
        self.put(name, &bytes)
    }
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let [_, repo, out] = args.as_slice() else {
        return Err("usage: robocal-fuzz-seeds REPO_DIR OUT_DIR".into());
    };
    let (repo, out) = (Path::new(repo), Path::new(out));
    let renders = small_renders()?;
    image_seeds(out, &renders)?;
    detect_seeds(out, &renders)?;
    pose_seeds(out)?;
    let reports = calib_seeds(out, &renders)?;
    camera_seeds(out, repo, &reports)?;
    target_seeds(out, &renders)?;
    workflow_seeds(out, repo)?;
    Ok(())
}

/// One render per target kind: (kind byte, a, b, target, image, detection).
struct Render {
    kind: u8,
    a: u8,
    b: u8,
    target: Target,
    image: GrayImage,
    detection: Detection,
}

/// Seeded renders of every target kind at most 128 x 128 pixels, the board
/// tilted a little and filling about 60 % of the width.
fn small_renders() -> Res<Vec<Render>> {
    // (kind, a, b): see cases::detect_target_spec.
    let headers = [(0u8, 3u8, 2u8), (1, 2, 3), (1, 1 | 8, 3), (2, 2, 2), (3, 0, 0), (4, 1, 1)];
    let mut out = Vec::new();
    for (i, &(kind, a, b)) in headers.iter().enumerate() {
        for &(w, h) in &[(128u32, 96u32), (64, 64)] {
            let target = Target::parse_spec(&cases::detect_target_spec(kind, a, b))?;
            let camera = Pinhole {
                fx: w as f64,
                fy: w as f64,
                cx: (w as f64 - 1.0) / 2.0,
                cy: (h as f64 - 1.0) / 2.0,
                width: w,
                height: h,
            };
            let points = target.object_points();
            let extent_m = points
                .iter()
                .map(|p| p.1.x.max(p.1.y))
                .fold(0.03, f64::max);
            let z = camera.fx * extent_m / (0.6 * w as f64);
            let pose = board_pose(&target, (0.15, -0.1, 0.05), (0.0, 0.0, z));
            let options = RenderOptions {
                seed: i as u64 + 1,
                ..RenderOptions::default()
            };
            let rendered = render(&camera, &target, &pose, &options)?;
            let detection = Detection {
                image_size_px: [w, h],
                target: target.clone(),
                points: rendered.points,
                // Exact projections of the board points (for circle
                // targets what `perspective_pole` estimates); no model key.
                centre_model: None,
                polarity: None,
            };
            out.push(Render {
                kind,
                a,
                b,
                target,
                image: rendered.image,
                detection,
            });
        }
    }
    Ok(out)
}

/// The renders in every format `robocal::image` decodes.
fn image_seeds(out: &Path, renders: &[Render]) -> Res<()> {
    use image::{DynamicImage, ImageFormat, Luma, Rgb};
    let mut corpus = Corpus::new(out, "image_decode")?;
    for (i, r) in renders.iter().enumerate().filter(|(i, _)| i % 2 == 1) {
        let g = &r.image;
        corpus.put(&format!("{i}.png"), &robocal::image::encode_png(g)?)?;
        corpus.put(&format!("{i}.pgm"), &robocal::image::encode_pgm(g))?;
        let grey = image::GrayImage::from_fn(g.width, g.height, |x, y| {
            Luma([g.pixels[(y * g.width + x) as usize]])
        });
        let rgb = image::RgbImage::from_fn(g.width, g.height, |x, y| {
            let v = g.pixels[(y * g.width + x) as usize];
            Rgb([v, v / 2, 255 - v])
        });
        let wide = DynamicImage::ImageLuma8(grey.clone()).to_luma16();
        let variants: [(&str, DynamicImage, ImageFormat); 9] = [
            ("rgb.png", DynamicImage::ImageRgb8(rgb.clone()), ImageFormat::Png),
            ("16.png", DynamicImage::ImageLuma16(wide), ImageFormat::Png),
            ("jpg", DynamicImage::ImageLuma8(grey.clone()), ImageFormat::Jpeg),
            ("rgb.jpg", DynamicImage::ImageRgb8(rgb.clone()), ImageFormat::Jpeg),
            ("gif", DynamicImage::ImageRgb8(rgb.clone()), ImageFormat::Gif),
            ("tif", DynamicImage::ImageLuma8(grey.clone()), ImageFormat::Tiff),
            ("bmp", DynamicImage::ImageRgb8(rgb.clone()), ImageFormat::Bmp),
            ("ppm", DynamicImage::ImageRgb8(rgb.clone()), ImageFormat::Pnm),
            ("webp", DynamicImage::ImageRgb8(rgb), ImageFormat::WebP),
        ];
        for (ext, img, format) in variants {
            let mut bytes = std::io::Cursor::new(Vec::new());
            img.write_to(&mut bytes, format)?;
            corpus.put(&format!("{i}.{ext}"), bytes.get_ref())?;
        }
    }
    Ok(())
}

fn detect_seeds(out: &Path, renders: &[Render]) -> Res<()> {
    let mut corpus = Corpus::new(out, "detect")?;
    for r in renders {
        let name = format!("{}-{}x{}", r.target.to_spec(), r.image.width, r.image.height);
        corpus.put(&name.replace(':', "_"), &cases::detect_input(r.kind, r.a, r.b, &r.image))?;
    }
    Ok(())
}

/// A pose as the hand-eye JSON takes it, in the form `i` picks.
fn pose_json(p: &Pose, i: usize) -> Value {
    if i % 2 == 0 {
        let m = p.to_homogeneous();
        json!({"matrix_row_major": (0..4).map(|r| (0..4).map(|c| m[(r, c)]).collect::<Vec<_>>()).collect::<Vec<_>>()})
    } else {
        let q = p.rotation;
        let t = p.translation.vector;
        json!({"translation_m": [t.x, t.y, t.z], "quaternion_xyzw": [q.i, q.j, q.k, q.w]})
    }
}

/// Robot pose files in every format (header and no header, named rows),
/// JSON pose files, and camera-pose text files.
fn pose_seeds(out: &Path) -> Res<()> {
    let mut corpus = Corpus::new(out, "robot_poses")?;
    let scene = handeye_scene(&HandEyeSceneConfig::noise_free(Setup::EyeInHand, 5), 7);
    let poses: Vec<RobotPose> = scene
        .base_from_gripper
        .iter()
        .enumerate()
        .map(|(i, p)| RobotPose {
            name: (i % 2 == 0).then(|| format!("img{i:02}.png")),
            line: i + 2,
            base_from_gripper: *p,
        })
        .collect();
    for (index, format) in PoseFormat::all().into_iter().enumerate() {
        let (length, angle) = format.default_units();
        let text = robocal::io::format_poses(&poses, format, length, angle);
        corpus.put(&format.name(), &[&[0u8, 0u8][..], text.as_bytes()].concat())?;
        let byte = index as u8 + 1;
        let body: String = text.lines().skip(1).map(|l| format!("{l}\n")).collect();
        corpus.put(&format!("{}-bare", format.name()), &[&[byte, 0x15][..], body.as_bytes()].concat())?;
    }
    let matrices: Vec<Value> = scene
        .base_from_gripper
        .iter()
        .map(|p| {
            let m = p.to_homogeneous();
            Value::from((0..16).map(|k| m[(k / 4, k % 4)]).collect::<Vec<f64>>())
        })
        .collect();
    corpus.put("matrices.json", &[&[0u8, 0u8][..], Value::from(matrices).to_string().as_bytes()].concat())?;
    let named: Vec<Value> = scene
        .base_from_gripper
        .iter()
        .map(|p| {
            let (t, q) = (p.translation.vector * 1000.0, p.rotation);
            json!({"x": t.x, "y": t.y, "z": t.z, "qx": q.i, "qy": q.j, "qz": q.k, "qw": q.w})
        })
        .collect();
    corpus.put("named.json", &[&[0u8, 1u8][..], json!({"poses": named}).to_string().as_bytes()].concat())?;
    // Camera-pose text: 16 and 12 numbers, and x y z + quaternion per line.
    let mut matrix16 = String::from("# camera_from_target\n");
    let mut matrix12 = String::new();
    let mut quat = String::new();
    for p in &scene.camera_from_target {
        let m = p.to_homogeneous();
        let row = |n: usize| (0..n).map(|k| m[(k / 4, k % 4)].to_string()).collect::<Vec<_>>();
        matrix16.push_str(&(row(16).join(" ") + "\n"));
        matrix12.push_str(&(row(12).join(",") + "\n"));
        let (t, q) = (p.translation.vector, p.rotation);
        quat.push_str(&format!("{} {} {} {} {} {} {}\n", t.x, t.y, t.z, q.i, q.j, q.k, q.w));
    }
    corpus.put("camera16.txt", &[&[0u8, 1 << 5][..], matrix16.as_bytes()].concat())?;
    corpus.put("camera12.txt", &[&[0u8, 1 << 5][..], matrix12.as_bytes()].concat())?;
    corpus.put("camera-xyzw.txt", &[&[0u8, 2 << 5][..], quat.as_bytes()].concat())?;
    corpus.put("camera-wxyz.txt", &[&[0u8, 3 << 5][..], quat.as_bytes()].concat())?;
    Ok(())
}

/// The view JSON of a synthetic scene's views (explicit correspondences).
fn scene_views(scene: &Scene, prefix: &str) -> Vec<Value> {
    scene
        .views
        .iter()
        .map(|v| {
            json!({
                "name": format!("{prefix}{}", v.name),
                "object_m": v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                "image_px": v.image_px.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
            })
        })
        .collect()
}

/// Camera and stereo calibration inputs; returns report texts (a camera
/// report, a hand-eye report) for the export seeds.
fn calib_seeds(out: &Path, renders: &[Render]) -> Res<Vec<String>> {
    let mut corpus = Corpus::new(out, "calib_json")?;
    let camera = robocal::synth::demo::demo_camera();
    let scene = Scene::calibration(3, &camera, (5, 4), 0.03, 4, 0.1)?;
    let views = scene_views(&scene, "");
    let size = [camera.width, camera.height];
    let mut camera_report = String::new();
    for (model, method) in [
        ("brown", "zhang"),
        ("division", "zhang"),
        ("kannala_brandt", "zhang"),
        ("eucm", "zhang"),
        ("rational", "zhang"),
        ("radial_k1_k2_k5", "zhang"),
        ("none", "tsai"),
        ("brown", "ekf"),
        ("brown", "all"),
    ] {
        let input = json!({
            "model": model, "method": method,
            "options": {"robust": method == "all", "fixed_coefficients": if model == "brown" { vec!["k3"] } else { vec![] }},
            "views": views, "image_size_px": size,
        });
        let text = input.to_string();
        if model == "brown" && method == "zhang" {
            camera_report = robocal::api::camera::calibrate_json(&text)?;
        }
        corpus.text(&format!("{model}-{method}.json"), 0, &text)?;
    }
    // Detections of the small renders as views (same target, same size).
    let chess: Vec<Value> = renders
        .iter()
        .filter(|r| r.kind == 0)
        .map(|r| json!({"name": "render", "detection": r.detection}))
        .collect();
    corpus.text("detections.json", 0, &json!({"views": chess}).to_string())?;
    // Stereo: the right camera 10 cm to the right of the left one.
    let right_from_left = Pose::from_parts(
        Translation3::new(-0.1, 0.0, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.02, 0.0),
    );
    let mut right_views = Vec::new();
    for (v, pose) in scene.views.iter().zip(&scene.camera_from_target) {
        let image_px: Vec<[f64; 2]> = v
            .object_m
            .iter()
            .map(|p| {
                let q = camera
                    .project(&(right_from_left * pose * p))
                    .unwrap_or(nalgebra::Point2::new(0.0, 0.0));
                [q.x, q.y]
            })
            .collect();
        right_views.push(json!({
            "name": format!("right_{}", v.name),
            "object_m": v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
            "image_px": image_px,
        }));
    }
    let stereo = json!({
        "model": "brown", "left": views, "right": right_views,
        "left_image_size_px": size, "right_image_size_px": size,
    });
    corpus.text("stereo.json", 1, &stereo.to_string())?;
    let handeye_report = handeye_seeds(out, &camera)?;
    Ok(vec![camera_report, handeye_report])
}

/// Hand-eye inputs (both setups, both pose forms, with image points) and
/// pose-convention rankings; returns one report.
fn handeye_seeds(out: &Path, camera: &robocal::Camera) -> Res<String> {
    let mut corpus = Corpus::new(out, "handeye_json")?;
    let mut report = String::new();
    for (k, setup) in [Setup::EyeInHand, Setup::EyeToHand].into_iter().enumerate() {
        let scene = handeye_scene(&HandEyeSceneConfig::opencv_noise(setup, 8), 11 + k as u64);
        let robot: Vec<Value> = scene.base_from_gripper.iter().enumerate().map(|(i, p)| pose_json(p, i + k)).collect();
        let cam: Vec<Value> = scene.camera_from_target.iter().enumerate().map(|(i, p)| pose_json(p, i)).collect();
        let input = json!({
            "setup": setup.name(), "base_from_gripper": robot, "camera_from_target": cam,
            "method": "all", "bootstrap_samples": 8, "seed": 3,
        });
        let text = input.to_string();
        if k == 0 {
            report = robocal::api::handeye::solve_handeye_json(&text)?;
        }
        corpus.text(&format!("{}.json", setup.name()), 0, &text)?;
        // Image points of a 4 x 3 grid per view instead of camera poses.
        let grid: Vec<Point3<f64>> = (0..12)
            .map(|i| Point3::new((i % 4) as f64 * 0.04, (i / 4) as f64 * 0.04, 0.0))
            .collect();
        let views: Vec<Value> = scene
            .camera_from_target
            .iter()
            .map(|p| {
                let px: Vec<[f64; 2]> = grid
                    .iter()
                    .map(|q| camera.project(&(p * q)).map(|u| [u.x, u.y]).unwrap_or([0.0, 0.0]))
                    .collect();
                json!({"object_m": grid.iter().map(|q| [q.x, q.y, q.z]).collect::<Vec<_>>(), "image_px": px})
            })
            .collect();
        let with_points = json!({
            "setup": setup.name(), "base_from_gripper": robot, "camera": camera,
            "views": views, "refine": "trusted", "method": "park-martin", "bootstrap_samples": 0,
        });
        corpus.text(&format!("{}-points.json", setup.name()), 0, &with_points.to_string())?;
        let inverted: Vec<Value> = scene.base_from_gripper.iter().enumerate().map(|(i, p)| pose_json(&p.inverse(), i)).collect();
        let rank = json!({
            "setup": setup.name(),
            "candidates": [{"name": "as read", "base_from_gripper": robot}, {"name": "inverted", "base_from_gripper": inverted}],
            "camera_from_target": cam,
        });
        corpus.text(&format!("{}-rank.json", setup.name()), 1, &rank.to_string())?;
    }
    Ok(report)
}

/// Camera files from fixtures (every export format), camera JSON, and the
/// reports in every export format.
fn camera_seeds(out: &Path, repo: &Path, reports: &[String]) -> Res<()> {
    let mut corpus = Corpus::new(out, "camera_files")?;
    for entry in fs::read_dir(repo.join("fixtures/exports"))? {
        let path = entry?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file").to_string();
        if !name.starts_with("camera.") {
            continue;
        }
        let text = fs::read_to_string(&path)?;
        corpus.text(&name, 0, &text)?;
        if name.ends_with(".json") {
            corpus.text(&name, 1, &text)?;
        }
    }
    let camera = robocal::synth::demo::demo_camera();
    corpus.text("demo-camera.json", 1, &serde_json::to_string(&camera)?)?;
    let names = cases::export_format_names();
    for (r, report) in reports.iter().enumerate() {
        corpus.text(&format!("report{r}-import"), 0, report)?;
        for (i, name) in names.iter().enumerate() {
            corpus.text(&format!("report{r}-{name}"), (2 + 3 * i) as u8, report)?;
        }
    }
    Ok(())
}

/// Target specs of every kind and option, their JSON, detection files.
fn target_seeds(out: &Path, renders: &[Render]) -> Res<()> {
    let mut corpus = Corpus::new(out, "targets_detections")?;
    let specs = [
        "chessboard:9x6:30mm",
        "chessboard:7x5:0.025m",
        "circles:4x11:20mm:asymmetric",
        "circles:7x6:1.5cm:symmetric:light-on-dark",
        "dots:7x7:25mm",
        "dots:5x4:25mm:12.5mm",
        "circle:10mm",
        "squares:8x8:12.7mm:22.5778mm",
    ];
    for spec in specs {
        corpus.text(&spec.replace(':', "_"), 0, spec)?;
        let target = Target::parse_spec(spec)?;
        corpus.text(&format!("{}.json", spec.replace(':', "_")), 1, &serde_json::to_string(&target)?)?;
    }
    let images: Vec<Value> = renders
        .iter()
        .enumerate()
        .map(|(i, r)| json!({"file": format!("render{i}.png"), "detection": r.detection}))
        .chain([json!({"file": "blank.png", "detection": null})])
        .collect();
    corpus.text("detections.json", 2, &json!({"images": images}).to_string())?;
    corpus.text("detection.json", 2, &serde_json::to_string(&renders[0].detection)?)?;
    Ok(())
}

/// The workflow CSVs from fixtures/seed001 and generated XY-table and
/// known-motion files, then each as the JSON request of its solver.
fn workflow_seeds(out: &Path, repo: &Path) -> Res<()> {
    use robocal::io::workflow_csv as csv;
    let mut corpus = Corpus::new(out, "workflows")?;
    let seed001 = repo.join("fixtures/seed001");
    let matrices = fs::read_to_string(seed001.join("table4_matrices.csv"))?;
    let points = fs::read_to_string(seed001.join("table3_four_points.csv"))?;
    let xytable = xytable_csv();
    let known = known_motion_csv();
    corpus.text("matrices.csv", 0, &matrices)?;
    corpus.text("points.csv", 1, &points)?;
    corpus.text("xytable.csv", 2, &xytable)?;
    corpus.text("known-motion.csv", 3, &known)?;
    let fit = json!({"matrices": csv::parse_planar_matrices(&matrices)?, "reject_threshold": 2.5,
        "predict": [{"height_mm": 40.0, "image_px": [1000.0, 1000.0]}]});
    corpus.text("planar-fit.json", 4, &fit.to_string())?;
    let solve = json!({"points": csv::parse_planar_points(&points)?,
        "predict": [{"height_mm": 40.0, "image_px": [1000.0, 1000.0]}]});
    corpus.text("planar-solve.json", 5, &solve.to_string())?;
    corpus.text("xytable.json", 6, &serde_json::to_string(&csv::parse_xytable(&xytable)?)?)?;
    corpus.text("known-motion.json", 7, &serde_json::to_string(&csv::parse_known_motion(&known)?)?)?;
    Ok(())
}

/// Pixels of a pinhole camera 1 m above the table: u = 800 x / (1000 - z) + 640.
fn project_mm(x: f64, y: f64, z: f64) -> (f64, f64) {
    let depth = 1000.0 - z;
    (800.0 * x / depth + 640.0, 800.0 * y / depth + 480.0)
}

fn xytable_csv() -> String {
    let mut text = String::from("x_mm,y_mm,z_mm,u_px,v_px,role\n");
    for z in [0.0, 40.0] {
        for x in [-100.0, 0.0, 100.0] {
            for y in [-80.0, 0.0, 80.0] {
                let (u, v) = project_mm(x, y, z);
                text.push_str(&format!("{x},{y},{z},{u},{v},calibration\n"));
            }
        }
    }
    for (x, y) in [(-50.0, -50.0), (50.0, -50.0), (50.0, 50.0), (-50.0, 50.0)] {
        let (u, v) = project_mm(x, y, 20.0);
        text.push_str(&format!("{x},{y},20,{u},{v},verify\n"));
    }
    for k in 0..3 {
        text.push_str(&format!("0,0,0,{},{},still\n", 640.0 + 0.01 * k as f64, 480.0));
    }
    text
}

fn known_motion_csv() -> String {
    let rotation = UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3);
    let start = Vector3::new(10.0, -20.0, 500.0);
    let mut position = Vector3::zeros();
    let mut text = String::from("dx_mm,dy_mm,dz_mm,x_cam_mm,y_cam_mm,z_cam_mm\n");
    for d in [[0.0, 0.0, 0.0], [50.0, 0.0, 0.0], [0.0, 50.0, 0.0], [0.0, 0.0, 50.0], [-50.0, -50.0, 0.0]] {
        position += Vector3::from(d);
        let p = rotation * position + start;
        text.push_str(&format!("{},{},{},{},{},{}\n", d[0], d[1], d[2], p.x, p.y, p.z));
    }
    text
}
