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
