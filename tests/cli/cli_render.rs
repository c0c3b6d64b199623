//! `robocal render`: deterministic images with exact truth, which the
//! detector finds within its stated accuracy (renders with grey noise
//! sigma 2, barrel distortion and vignetting: every corner within 0.2 px of
//! the truth, 0.05 px on average, as the detection benchmark measured).

use std::process::Command;

fn robocal(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn renders_are_seeded_and_their_truth_is_what_the_detector_finds() {
    let base = std::env::temp_dir().join(format!("robocal-render-{}", std::process::id()));
    let (a, b) = (base.join("a"), base.join("b"));
    for dir in [&a, &b] {
        let out = robocal(&[
            "render",
            "--out",
            dir.to_str().unwrap(),
            "--views",
            "2",
            "--seed",
            "5",
        ]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let img = std::fs::read(a.join("view_001.png")).unwrap();
    assert_eq!(
        img,
        std::fs::read(b.join("view_001.png")).unwrap(),
        "same seed, same bytes"
    );
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("truth.json")).unwrap()).unwrap();
    let gray = robocal::image::decode_gray(&img).unwrap();
    let target = robocal::target::Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let found = robocal::detect::detect(&gray, &target, &Default::default()).unwrap();
    let exact = truth["views"][1]["points"].as_array().unwrap();
    assert_eq!(found.points.len(), exact.len());
    let mut sum = 0.0;
    for (p, q) in found.points.iter().zip(exact) {
        assert_eq!(p.id as u64, q["id"].as_u64().unwrap());
        let e = ((p.x_px - q["x_px"].as_f64().unwrap()).powi(2)
            + (p.y_px - q["y_px"].as_f64().unwrap()).powi(2))
        .sqrt();
        assert!(e < 0.2, "corner {} off by {e} px", p.id);
        sum += e;
    }
    assert!(
        sum / exact.len() as f64 <= 0.05,
        "mean corner error {} px",
        sum / exact.len() as f64
    );
}

#[test]
fn render_arguments_are_checked() {
    let out = robocal(&["render", "--views", "3"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "robocal: render: --out DIR is required (see 'robocal render --help')\n"
    );
    let out = robocal(&["render", "--out", "/tmp/x", "--target", "hexagon:3x3:1mm"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).starts_with("robocal: "),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dir = std::env::temp_dir().join(format!("robocal-render-rig-{}", std::process::id()));
    let dir_arg = dir.to_string_lossy().into_owned();
    let out = robocal(&["render", "--out", &dir_arg, "--rig", "--views", "0"]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "robocal: render: with --rig, --views (frames facing each pair) must be 1 to 100 and \
         --side-frames 0 to 100 (see 'robocal render --help')\n"
    );
    let out = robocal(&["render", "--out", &dir_arg, "--side-frames", "2"]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--rig"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = robocal(&["render", "--help"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("robocal render --out demo --demo"));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("robocal render --out rig --rig --views 5")
    );
}
