//! `robocal detect` end to end: rendered images written to a temp folder,
//! the binary run on them, the JSON checked against the renderer's truth.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use robocal::synth::{render, Pinhole, RenderOptions};
use robocal::target::Target;
use std::process::Command;

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("robocal-cli-detect-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn detects_in_good_images_and_reports_bad_ones() {
    let dir = temp_dir("mixed");
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let cam = Pinhole {
        fx: 700.0,
        fy: 700.0,
        cx: 319.5,
        cy: 239.5,
        width: 640,
        height: 480,
    };
    let mut truths = Vec::new();
    for k in 0..3 {
        let r = UnitQuaternion::from_euler_angles(0.1 * k as f64, -0.2, 0.05 * k as f64);
        let t = Vector3::new(0.0, 0.0, 0.5) - r * Vector3::new(0.12, 0.075, 0.0);
        let pose = Isometry3::from_parts(Translation3::from(t), r);
        let o = RenderOptions {
            seed: k,
            ..RenderOptions::default()
        };
        let img = render(&cam, &target, &pose, &o).unwrap();
        let path = dir.join(format!("board{k}.png"));
        std::fs::write(&path, robocal::image::encode_png(&img.image).unwrap()).unwrap();
        truths.push(img.points);
    }
    std::fs::write(
        dir.join("blank.pgm"),
        b"P5\n64 64\n255\n"
            .iter()
            .copied()
            .chain(std::iter::repeat(128).take(64 * 64))
            .collect::<Vec<u8>>(),
    )
    .unwrap();
    std::fs::write(dir.join("notes.txt"), b"not an image").unwrap();
    let out = dir.join("detections.json");
    let files: Vec<String> = [
        "board0.png",
        "blank.pgm",
        "board1.png",
        "notes.txt",
        "board2.png",
    ]
    .iter()
    .map(|f| dir.join(f).to_string_lossy().into_owned())
    .collect();
    let status = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args([
            "detect",
            "--target",
            "chessboard:9x6:30mm",
            "--threads",
            "2",
            "-o",
        ])
        .arg(&out)
        .args(&files)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let stderr = String::from_utf8_lossy(&status.stderr);
    assert!(
        stderr.contains("blank.pgm: board not found: no 9x6 chessboard corners"),
        "{stderr}"
    );
    assert!(stderr.contains("target found in 3 of 5 images"), "{stderr}");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let images = doc["images"].as_array().unwrap();
    assert_eq!(images.len(), 5);
    assert_eq!(images[1]["error"]["kind"], "not_found");
    assert_eq!(images[3]["error"]["kind"], "image");
    for (slot, truth) in [0usize, 2, 4].iter().zip(&truths) {
        let det: robocal::target::Detection =
            serde_json::from_value(images[*slot]["detection"].clone()).unwrap();
        assert_eq!(det.image_size_px, [640, 480]);
        assert_eq!(det.points.len(), 54);
        for (d, t) in det.points.iter().zip(truth) {
            // Noise sigma 2 on 640x480: each corner within 0.2 px (about 5 sd).
            let e = ((d.x_px - t.x_px).powi(2) + (d.y_px - t.y_px).powi(2)).sqrt();
            assert!(e < 0.2, "image {slot} id {}: {e} px", d.id);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn usage_errors_name_the_problem() {
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["detect", "--target", "chessboard:9x6", "x.png"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("'chessboard:9x6' is not a target spec"),
        "{err}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["detect", "--help"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stdout)
        .contains("robocal detect --target chessboard:9x6:30mm"));
}

/// Two AprilGrids of one layout, printed with tags 0-35 and 36-71, in one
/// 640x480 image (the left half of a render of one beside the right half of
/// a render of the other), and the second board alone: `robocal detect`
/// with the first board's spec reports it as the detection and the second
/// under `other_boards`; the image of the second board alone fails (the
/// target's ids are not in view) and still lists it.
#[test]
fn other_boards_of_the_layout_are_listed_per_image() {
    let dir = temp_dir("boards");
    let cam = Pinhole {
        fx: 700.0,
        fy: 700.0,
        cx: 319.5,
        cy: 239.5,
        width: 640,
        height: 480,
    };
    let spec = "aprilgrid:6x6:20mm:0.3";
    let draw = |spec: &str, x: f64, seed: u64| {
        let t = Target::parse_spec(spec).unwrap();
        let pose = robocal::synth::board_pose(&t, (0.1, -0.1, 0.0), (x, 0.0, 0.5));
        let o = RenderOptions {
            seed,
            ..RenderOptions::default()
        };
        render(&cam, &t, &pose, &o).unwrap().image
    };
    let a = draw(spec, -0.11, 1);
    let b = draw(&format!("{spec}:first=36"), 0.11, 2);
    let w = a.width as usize;
    let both: Vec<u8> = (0..a.pixels.len())
        .map(|i| {
            if i % w < w / 2 {
                a.pixels[i]
            } else {
                b.pixels[i]
            }
        })
        .collect();
    let both = robocal::image::GrayImage::new(a.width, a.height, both).unwrap();
    for (name, img) in [("both.png", &both), ("second.png", &b)] {
        std::fs::write(dir.join(name), robocal::image::encode_png(img).unwrap()).unwrap();
    }
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .current_dir(&dir)
        .args(["detect", "--target", spec, "both.png", "second.png"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let images = doc["images"].as_array().unwrap();
    // Whole boards in view: all 144 corners but at most 2 (the page's test
    // and tests/detect/detect_markers.rs see 142-144 on such renders).
    let count = |d: &serde_json::Value| d["points"].as_array().unwrap().len();
    let both = &images[0];
    assert_eq!(both["detection"]["target"]["first_id"], 0);
    assert!(
        count(&both["detection"]) >= 142,
        "{}",
        count(&both["detection"])
    );
    let others = both["other_boards"].as_array().unwrap();
    assert_eq!(others.len(), 1);
    assert_eq!(others[0]["target"]["first_id"], 36);
    assert!(count(&others[0]) >= 142, "{}", count(&others[0]));
    let second = &images[1];
    assert!(second["error"].is_object(), "{second}");
    assert_eq!(second["other_boards"][0]["target"]["first_id"], 36);
    assert!(
        stderr.contains(
            "both.png: other boards in view: aprilgrid:6x6:20mm:0.3:first=36 (other_boards)"
        ),
        "{stderr}"
    );
}
