//! robocal handeye: robot poses paired with the images (path suffix, numeric
//! order, one pose per file) and wrong pairings named (split from
//! cli_handeye.rs).

use super::cli_handeye::{distance, matrix, ok, read_json, robocal};
use std::path::PathBuf;

/// The demo's poses and images as a user's cell has them: unpadded numbers
/// (`img_0.png` ... `img_11.png`), listed in the shell's order (0, 1, 10,
/// 11, 2, ...), the pose file's image column holding the path as typed.
struct Cell {
    dir: PathBuf,
    /// Image paths in the shell's (lexicographic) order.
    images: Vec<String>,
    /// The demo's pose rows without the image column, in pose order.
    rows: Vec<String>,
}

fn cell(name: &str) -> Cell {
    let dir = std::env::temp_dir().join(format!("robocal-pairing-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().unwrap();
    ok(&robocal(&["render", "--out", d, "--demo"]));
    std::fs::create_dir_all(dir.join("images")).unwrap();
    for i in 0..12 {
        std::fs::rename(
            dir.join(format!("demo_{i:02}.png")),
            dir.join(format!("images/img_{i}.png")),
        )
        .unwrap();
    }
    let mut images: Vec<String> = (0..12)
        .map(|i| {
            dir.join(format!("images/img_{i}.png"))
                .to_str()
                .unwrap()
                .to_string()
        })
        .collect();
    images.sort();
    let text = std::fs::read_to_string(dir.join("poses.csv")).unwrap();
    assert!(text.starts_with("name,"), "{text}");
    let rows = text
        .lines()
        .skip(1)
        .map(|l| l.split_once(',').unwrap().1.to_string())
        .collect();
    Cell { dir, images, rows }
}

impl Cell {
    /// Run `robocal handeye` on a pose file holding `poses` (with `header`).
    fn run(&self, header: &str, poses: &[String], extra: &[&str]) -> std::process::Output {
        let file = self.dir.join("poses_user.csv");
        std::fs::write(&file, format!("{header}\n{}\n", poses.join("\n"))).unwrap();
        let mut args: Vec<String> = [
            "handeye",
            "--setup",
            "eye-in-hand",
            "--poses",
            file.to_str().unwrap(),
            "--camera",
            self.dir.join("truth.json").to_str().unwrap(),
            "--target",
            "chessboard:9x6:30mm",
            "--bootstrap",
            "0",
            "--threads",
            "2",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        args.extend(extra.iter().map(|s| s.to_string()));
        args.extend(self.images.iter().cloned());
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        robocal(&refs)
    }
}

fn solved_right(out: &std::process::Output, cell: &Cell) -> serde_json::Value {
    ok(out);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let truth = read_json(&cell.dir.join("truth.json"));
    let (t, r) = distance(
        &matrix(&report["gripper_from_camera"]),
        &matrix(&truth["gripper_from_camera"]),
    );
    assert!(t < 0.1 && r < 0.01, "{t} mm, {r} deg");
    report
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn poses_pair_by_path_suffix_and_numeric_order_and_wrong_pairings_are_named() {
    let c = cell("rules");
    let header = "x,y,z,rx,ry,rz";
    // 1. No image column: pose i with the i-th image in numeric order,
    // although the shell listed img_10.png before img_2.png.
    let report = solved_right(&c.run(header, &c.rows, &[]), &c);
    let pairs = report["pairs"].as_array().unwrap();
    for (i, p) in pairs.iter().enumerate() {
        let image = p["image"].as_str().unwrap();
        assert!(
            image.ends_with(&format!("/img_{i}.png")),
            "pose {i}: {image}"
        );
    }
    // 2. The image column as the user typed the paths (relative, with the
    // folder), absolute, or stems: matched by path suffix, path, stem.
    let dir = c.dir.to_str().unwrap();
    let namers: [fn(usize, &str) -> String; 3] = [
        |i, _| format!("images/img_{i}.png"),
        |i, d| format!("{d}/images/img_{i}.png"),
        |i, _| format!("img_{i}"),
    ];
    for name in namers {
        let named: Vec<String> = (0..12)
            .map(|i| format!("{},{}", name(i, dir), c.rows[i]))
            .collect();
        solved_right(&c.run(&format!("image,{header}"), &named, &[]), &c);
    }
    // 3. Paired in the shell's order on request: the data say numeric order.
    let out = c.run(header, &c.rows, &["--pair-by", "lexicographic"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(
        e.starts_with(
            "robocal: pairing: the poses fit the images only when paired in numeric order of \
             the file names: the rotation angles of the robot and camera motions agree to 0.0"
        ) && e
            .contains("as paired in lexicographic order of the file names: pass --pair-by numeric"),
        "{e}"
    );
    // 4. Two rows naming one image, and a row naming no image: errors naming them.
    let mut named: Vec<String> = (0..12)
        .map(|i| format!("images/img_{i}.png,{}", c.rows[i]))
        .collect();
    named[5] = format!("images/img_4.png,{}", c.rows[5]);
    let out = c.run(&format!("image,{header}"), &named, &[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("pairing: two poses name the same image: rows 6, 7 all name '"),
        "{}",
        stderr(&out)
    );
    named[5] = format!("images/img_44.png,{}", c.rows[5]);
    let out = c.run(&format!("image,{header}"), &named, &[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains(
            "pairing: 1 of 12 poses name no image that was given: row 7 'images/img_44.png': \
             give those images, or remove their rows from the pose file"
        ),
        "{}",
        stderr(&out)
    );
    // 5. --pair-by with an unknown rule.
    let out = c.run(header, &c.rows, &["--pair-by", "name"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim_end(),
        "robocal: handeye: --pair-by: unknown rule 'name' (valid: auto, numeric, \
         lexicographic, given) (see 'robocal handeye --help')"
    );
    let _ = std::fs::remove_dir_all(&c.dir);
}

/// The demo's pose rows (UR: m, rotation vector) as (translation m,
/// rotation).
fn demo_poses(c: &Cell) -> Vec<([f64; 3], robocal::geometry::Rotation)> {
    c.rows
        .iter()
        .map(|row| {
            let v: Vec<f64> = row.split(',').map(|f| f.parse().unwrap()).collect();
            let r =
                robocal::geometry::rotation_from_rotvec(&nalgebra::Vector3::new(v[3], v[4], v[5]));
            ([v[0], v[1], v[2]], r)
        })
        .collect()
}

impl Cell {
    /// `robocal handeye` with `--poses` given as `poses` (a folder or files).
    fn run_poses(
        &self,
        poses: &[String],
        images: &[String],
        extra: &[&str],
    ) -> std::process::Output {
        let mut args: Vec<String> = vec![
            "handeye".into(),
            "--setup".into(),
            "eye-in-hand".into(),
            "--poses".into(),
        ];
        args.extend(poses.iter().cloned());
        for a in [
            "--camera",
            self.dir.join("truth.json").to_str().unwrap(),
            "--target",
            "chessboard:9x6:30mm",
            "--bootstrap",
            "0",
            "--threads",
            "2",
        ] {
            args.push(a.into());
        }
        args.extend(extra.iter().map(|s| s.to_string()));
        args.extend(images.iter().cloned());
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        robocal(&refs)
    }
}

#[test]
fn one_pose_per_file_folders_and_lists_pair_by_stem() {
    let c = cell("files");
    let poses = demo_poses(&c);
    let folder = c.dir.join("poses");
    std::fs::create_dir_all(&folder).unwrap();
    // 1. A folder of ROS Pose YAML (block and flow alike) and JSON, one per
    // image, named by the image stems; a README in the folder is not read.
    for (i, (t, r)) in poses.iter().enumerate() {
        let q = robocal::geometry::quaternion_xyzw_from_rotation(r);
        let (name, text) = match i % 3 {
            0 => (format!("img_{i}.yaml"), format!(
                "header:\n  frame_id: base_link\npose:\n  position:\n    x: {}\n    y: {}\n    z: {}\n  orientation:\n    x: {}\n    y: {}\n    z: {}\n    w: {}\n",
                t[0], t[1], t[2], q[0], q[1], q[2], q[3])),
            1 => (format!("img_{i}.yml"), format!(
                "position: {{x: {}, y: {}, z: {}}}\norientation: {{x: {}, y: {}, z: {}, w: {}}}\n",
                t[0], t[1], t[2], q[0], q[1], q[2], q[3])),
            _ => (format!("img_{i}.json"), format!(
                r#"{{"position": {{"x": {}, "y": {}, "z": {}}}, "orientation": {{"x": {}, "y": {}, "z": {}, "w": {}}}}}"#,
                t[0], t[1], t[2], q[0], q[1], q[2], q[3])),
        };
        std::fs::write(folder.join(name), text).unwrap();
    }
    std::fs::write(folder.join("README.md"), "poses of the cell\n").unwrap();
    let report = solved_right(
        &c.run_poses(&[folder.to_str().unwrap().into()], &c.images, &[]),
        &c,
    );
    for p in report["pairs"].as_array().unwrap() {
        let i = p["pose_index"].as_u64().unwrap();
        let image = p["image"].as_str().unwrap();
        assert!(
            image.ends_with(&format!("/img_{i}.png")),
            "pose {i}: {image}"
        );
    }
    // 2. Several files: 4x4 matrices as text, millimetres by --pose-units.
    let mats = c.dir.join("mats");
    std::fs::create_dir_all(&mats).unwrap();
    let mut listed = Vec::new();
    for (i, (t, r)) in poses.iter().enumerate() {
        let m = r.to_rotation_matrix().into_inner();
        let text: String = (0..3)
            .map(|k| format!("{} {} {} {}\n", m[(k, 0)], m[(k, 1)], m[(k, 2)], t[k] * 1e3))
            .chain(["0 0 0 1\n".to_string()])
            .collect();
        let path = mats.join(format!("img_{i}.txt"));
        std::fs::write(&path, text).unwrap();
        listed.push(path.to_str().unwrap().to_string());
    }
    listed.reverse();
    solved_right(
        &c.run_poses(&listed, &c.images, &["--pose-units", "mm"]),
        &c,
    );
    // 3. A table with units and Euler angles in degrees in its header.
    let rows: Vec<String> = poses
        .iter()
        .map(|(t, r)| {
            let e = robocal::geometry::euler_from_rotation(
                r,
                robocal::geometry::EulerOrder::XYZ,
                robocal::geometry::EulerKind::Extrinsic,
            );
            format!(
                "{},{},{},{},{},{}",
                t[0] * 1e3,
                t[1] * 1e3,
                t[2] * 1e3,
                e[0].to_degrees(),
                e[1].to_degrees(),
                e[2].to_degrees()
            )
        })
        .collect();
    solved_right(
        &c.run("x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg", &rows, &[]),
        &c,
    );
    // Radians under a _deg header: read as the header says (tiny rotations),
    // caught by the plausibility checks, not solved silently.
    let radians: Vec<String> = poses
        .iter()
        .map(|(t, r)| {
            let e = robocal::geometry::euler_from_rotation(
                r,
                robocal::geometry::EulerOrder::XYZ,
                robocal::geometry::EulerKind::Extrinsic,
            );
            format!(
                "{},{},{},{},{},{}",
                t[0] * 1e3,
                t[1] * 1e3,
                t[2] * 1e3,
                e[0],
                e[1],
                e[2]
            )
        })
        .collect();
    let out = c.run("x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg", &radians, &[]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let e = stderr(&out);
    let file = c.dir.join("poses_user.csv");
    let first = e.lines().next().unwrap_or_default();
    assert!(
        first.starts_with(&format!(
            "warning: '{}': every pose is within ",
            file.display()
        )) && first.ends_with(
            " deg of the base orientation with the angles read as degrees: radians read as \
                 degrees? If the file holds radians, say so (a _rad header, --pose-units rad, or \
                 Angles: radians on the page)"
        ),
        "{e}"
    );
    assert!(e.contains("robocal: robot poses: the robot translations fit the camera motion only when scaled by"), "{e}");
    // Said in radians, the same numbers solve.
    solved_right(
        &c.run(
            "x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg",
            &radians,
            &["--pose-units", "rad"],
        ),
        &c,
    );
    // 4. A bad file is named with its line, before any image is read (the
    // images given do not exist).
    std::fs::write(
        folder.join("img_4.yml"),
        "position: {x: 0.1, y: 0.2, z: 0.3}\norientation:\n  {x: 0, y: 0, z: 0, w: 2}\n",
    )
    .unwrap();
    let missing = vec![c.dir.join("nothing.png").to_str().unwrap().to_string()];
    let out = c.run_poses(&[folder.to_str().unwrap().into()], &missing, &[]);
    assert_eq!(out.status.code(), Some(1));
    let bad = folder.join("img_4.yml");
    assert_eq!(
        stderr(&out).trim_end(),
        format!(
            "robocal: '{}': line 3: quaternion has norm 2: not a rotation",
            bad.display()
        )
    );
    // 5. An empty folder, and --pose-format names only pose-file formats.
    let empty = c.dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = c.run_poses(&[empty.to_str().unwrap().into()], &missing, &[]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out).trim_end(),
        format!(
            "robocal: '{}': no pose files in the folder (files ending .yaml, .yml, .json, .txt, .csv, .tsv, .dat)",
            empty.display()
        )
    );
    let _ = std::fs::remove_dir_all(&c.dir);
}
