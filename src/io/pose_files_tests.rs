//! One pose per file: each form with its exact pose, and the errors naming
//! the file and line. Noise-free: poses agree to 1e-9 (the printed digits).

use super::*;
use crate::geometry::{rotation_from_euler, EulerKind, EulerOrder, Pose};
use crate::io::{LengthUnit, PoseFormat};
use nalgebra::{UnitQuaternion, Vector3};

fn file(name: &str, text: &str) -> PoseFileText {
    PoseFileText {
        name: name.into(),
        text: text.into(),
    }
}

fn read(files: &[PoseFileText]) -> ParsedPoses {
    parse_pose_files(files, &PoseFileOptions::default()).unwrap()
}

fn err(files: &[PoseFileText]) -> String {
    parse_pose_files(files, &PoseFileOptions::default())
        .unwrap_err()
        .to_string()
}

/// Translation (m) and rotation (rad) between two poses.
fn close(a: &Pose, b: &Pose) {
    let dt = (a.translation.vector - b.translation.vector).norm();
    let dr = a.rotation.angle_to(&b.rotation);
    assert!(dt < 1e-9 && dr < 1e-9, "{dt} m, {dr} rad: {a:?} vs {b:?}");
}

fn pose(t: [f64; 3], q_xyzw: [f64; 4]) -> Pose {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2],
    ));
    Pose::from_parts(Vector3::from(t).into(), q)
}

const H: f64 = std::f64::consts::FRAC_1_SQRT_2;

#[test]
fn ros_pose_yaml_block_flow_and_rostopic_echo() {
    let block = "position:\n  x: 0.1\n  y: -0.2\n  z: 0.3\norientation:\n  x: 0.0\n  y: 0.0\n  z: 0.7071067811865476\n  w: 0.7071067811865476\n";
    let flow = "position: {x: 0.4, y: 0.5, z: 0.6}\norientation: {x: 0, y: 0, z: 0, w: 1}\n";
    let echo = "header:\n  seq: 7\n  stamp:\n    secs: 1700000000\n    nsecs: 5\n  frame_id: \"base_link\"\npose:\n  position:\n    x: 1.0\n    y: 2.0\n    z: 3.0\n  orientation:\n    x: 1.0\n    y: 0.0\n    z: 0.0\n    w: 0.0\n---\n";
    // Given out of order: read in numeric order of the names.
    let p = read(&[
        file("d/pose_10.yaml", echo),
        file("d/pose_2.yml", flow),
        file("d/pose_1.yaml", block),
    ]);
    assert_eq!(p.format, PoseFormat::XyzQuatXyzw);
    assert_eq!(p.length_unit, LengthUnit::Metre);
    let names: Vec<_> = p.poses.iter().map(|q| q.name.clone().unwrap()).collect();
    assert_eq!(names, ["pose_1", "pose_2", "pose_10"]);
    assert_eq!(
        p.poses.iter().map(|q| q.line).collect::<Vec<_>>(),
        [1, 2, 3]
    );
    close(
        &p.poses[0].base_from_gripper,
        &pose([0.1, -0.2, 0.3], [0.0, 0.0, H, H]),
    );
    close(
        &p.poses[1].base_from_gripper,
        &pose([0.4, 0.5, 0.6], [0.0, 0.0, 0.0, 1.0]),
    );
    close(
        &p.poses[2].base_from_gripper,
        &pose([1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0]),
    );
    assert_eq!(
        p.notes[0],
        "3 pose files, one pose each, in numeric order of their names; each pose named by its file's stem"
    );
}

#[test]
fn ros_transform_lists_and_units_on_the_parent() {
    let a = "translation: [0.1, 0.2, 0.3]\nrotation: [0, 0, 0, 1]\n";
    let b = "translation: [0.0, 0.0, 1.0]\nrotation: [0, 1, 0, 0]\n";
    let p = read(&[file("a.yaml", a), file("b.yaml", b)]);
    close(
        &p.poses[0].base_from_gripper,
        &pose([0.1, 0.2, 0.3], [0.0, 0.0, 0.0, 1.0]),
    );
    close(
        &p.poses[1].base_from_gripper,
        &pose([0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 0.0]),
    );
    let mm = "position_mm: {x: 100, y: 200, z: 300}\norientation: {w: 1, x: 0, y: 0, z: 0}\n";
    let p = read(&[file("one.yaml", mm)]);
    assert_eq!(p.length_unit, LengthUnit::Millimetre);
    // qw first by position in the file: the wxyz layout, same pose.
    assert_eq!(p.format, PoseFormat::XyzQuatWxyz);
    close(
        &p.poses[0].base_from_gripper,
        &pose([0.1, 0.2, 0.3], [0.0, 0.0, 0.0, 1.0]),
    );
}

#[test]
fn matrices_as_text_json_and_opencv_yaml() {
    let text4 = "0 -1 0 0.1\n1 0 0 0.2\n0 0 1 0.3\n0 0 0 1\n";
    let text3 = "0 -1 0 0.1\n1 0 0 0.2\n0 0 1 0.3\n";
    let json = r#"{"name": "p", "matrix": [[0, -1, 0, 0.1], [1, 0, 0, 0.2], [0, 0, 1, 0.3], [0, 0, 0, 1]]}"#;
    let opencv = "%YAML:1.0\n---\nT: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n   data: [ 0., -1., 0., 0.1, 1., 0., 0., 0.2,\n       0., 0., 1., 0.3, 0., 0., 0., 1. ]\n";
    let want = pose([0.1, 0.2, 0.3], [0.0, 0.0, H, H]);
    for (f, format) in [
        (file("m.txt", text4), PoseFormat::Matrix4),
        (file("m.txt", text3), PoseFormat::Matrix3x4),
        (file("m.json", json), PoseFormat::Matrix4),
        (file("m.yaml", opencv), PoseFormat::Matrix4),
    ] {
        let p = read(std::slice::from_ref(&f));
        assert_eq!(p.format, format, "{}", f.text);
        close(&p.poses[0].base_from_gripper, &want);
    }
}

#[test]
fn header_text_and_flat_names_with_units_and_euler_degrees() {
    let csv = "x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg\n100,200,300,90,0,0\n";
    let p = read(&[file("0001.csv", csv)]);
    assert_eq!(
        p.format,
        PoseFormat::XyzEuler {
            order: EulerOrder::XYZ,
            kind: EulerKind::Extrinsic
        }
    );
    let r = rotation_from_euler(
        EulerOrder::XYZ,
        EulerKind::Extrinsic,
        [90f64.to_radians(), 0.0, 0.0],
    );
    close(
        &p.poses[0].base_from_gripper,
        &Pose::from_parts(Vector3::new(0.1, 0.2, 0.3).into(), r),
    );
    assert!(
        p.notes
            .iter()
            .any(|n| n.starts_with("rx ry rz in degrees read as Euler angles")),
        "{:?}",
        p.notes
    );
    // KUKA names as YAML keys.
    let kuka = "X: 100\nY: 0\nZ: 500\nA: 90\nB: 0\nC: 0\n";
    let p = read(&[file("k.yaml", kuka)]);
    assert_eq!(p.format, PoseFormat::Kuka);
    close(
        &p.poses[0].base_from_gripper,
        &pose([0.1, 0.0, 0.5], [0.0, 0.0, H, H]),
    );
}

#[test]
fn bad_files_are_named_with_their_line() {
    let good = "position: {x: 0, y: 0, z: 0}\norientation: {x: 0, y: 0, z: 0, w: 1}\n";
    let abc = "position:\n  x: 0\n  y: abc\n  z: 0\norientation: {x: 0, y: 0, z: 0, w: 1}\n";
    assert_eq!(
        err(&[file("p/a.yaml", good), file("p/b.yaml", abc)]),
        "'p/b.yaml': line 3: 'abc' is not a number"
    );
    let norm = "position: {x: 0, y: 0, z: 0}\norientation:\n  x: 0\n  y: 0\n  z: 0\n  w: 2\n";
    assert_eq!(
        err(&[file("n.yaml", norm)]),
        "'n.yaml': line 3: quaternion has norm 2: not a rotation"
    );
    let other = "X: 100\nY: 0\nZ: 500\nA: 90\nB: 0\nC: 0\n";
    assert_eq!(
        err(&[file("a.yaml", good), file("b.yaml", other)]),
        "'b.yaml': poses: its values (X Y Z A B C) are not those of 'a.yaml' (x y z qx qy qz qw): every pose file must have the same layout"
    );
    assert_eq!(
        err(&[file("t.txt", "1 2 3\n")]),
        "'t.txt': line 1: 3 values, but pose formats have 6, 7, 12 or 16 values a line"
    );
    assert_eq!(
        err(&[file("two.csv", "x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,1\n0,0,0,0,0,0,1\n")]),
        "'two.csv': line 3: a second pose (2 rows under the header): a file in a folder of poses holds one pose; a table of poses is given alone"
    );
    assert_eq!(
        err(&[file("y.yaml", "position:\n  x: 1\n   y: 2\n")]),
        "'y.yaml': line 3: unexpected indentation"
    );
    assert_eq!(
        err(&[file("e.json", "{\"x\": 1,}")]),
        "'e.json': line 1, column 9: invalid JSON: trailing comma"
    );
    assert_eq!(
        err(&[file(
            "m.yaml",
            "a: [[1,0,0,0],[0,1,0,0],[0,0,1,0]]\nb: [[1,0,0,0],[0,1,0,0],[0,0,1,0]]\n"
        )]),
        "'m.yaml': poses: two matrices ('a' and 'b'): a pose file holds one pose"
    );
    assert_eq!(
        err(&[file(
            "d.yaml",
            "position: {x: 0, y: 0, z: 0}\nx: 1\norientation: {x: 0, y: 0, z: 0, w: 1}\n"
        )]),
        "'d.yaml': poses: 'position.x' and 'x' both give x"
    );
    assert_eq!(err(&[]), "poses: no pose files were given");
    let bad_matrix = "1 0 0 0\n0 1 0 0\n0 0 2 0\n";
    assert!(
        err(&[file("s.txt", bad_matrix)]).starts_with("'s.txt': line 1: 3x4 matrix "),
        "{}",
        err(&[file("s.txt", bad_matrix)])
    );
}

#[test]
fn six_numbers_a_file_give_ranked_candidates() {
    let files = [
        file("1.txt", "100 0 500 90 0 0\n"),
        file("2.txt", "200 0 500 0 90 0\n"),
    ];
    assert!(parse_pose_files(&files, &PoseFileOptions::default()).is_err());
    let c = parse_pose_file_candidates(&files, &PoseFileOptions::default()).unwrap();
    assert!(c.len() > 1);
    assert_eq!(c[0].poses[1].name.as_deref(), Some("2"));
    let kuka = PoseFileOptions {
        format: Some(PoseFormat::Kuka),
        ..Default::default()
    };
    let p = parse_pose_files(&files, &kuka).unwrap();
    close(
        &p.poses[0].base_from_gripper,
        &pose([0.1, 0.0, 0.5], [0.0, 0.0, H, H]),
    );
}

#[test]
fn a_header_and_a_row_of_another_length_is_an_error_in_any_file() {
    let good = "x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,1\n";
    let short = "x,y,z,qx,qy,qz,qw\n0,0,0,0,0,1\n";
    assert_eq!(
        err(&[file("a.csv", good), file("b.csv", short)]),
        "'b.csv': line 2: 6 values but the header names 7"
    );
    assert_eq!(
        err(&[file("b.csv", short)]),
        "'b.csv': line 2: 6 values but the header names 7"
    );
}

#[test]
fn random_text_never_panics() {
    // Pieces of every form, shuffled: each must read or be refused.
    let pieces = [
        "position:",
        "  x: 1",
        "orientation: {x: 0, w: 1}",
        "- 1",
        "- [1, 2]",
        "[[1,0,0,0],[0,1,0,0]",
        "{",
        "}",
        "]",
        "x,y,z,qx,qy,qz,qw",
        "0 0 0 0 0 0 1",
        "\"a\": 1",
        "'q': [1,2,3,4]",
        "  - x: 1",
        "#",
        "---",
        ":",
        "a: b: c",
        "translation: [1, 2, 3]",
        "rotation: [0, 0, 0, 1]",
        "\u{feff}",
        "\t",
        "é: ü",
        "data: [ 1.,",
        "  2. ]",
        "r11,tx",
    ];
    let mut rng = crate::rng::Rng::new(44);
    for _ in 0..3000 {
        let n = 1 + rng.below(6);
        let text: Vec<&str> = (0..n).map(|_| pieces[rng.below(pieces.len())]).collect();
        let a = text.join("\n");
        let b: String = text.concat();
        let files = [file("a.yaml", &a), file("b.txt", &b)];
        let _ = parse_pose_files(&files, &PoseFileOptions::default());
        let _ = parse_pose_file_candidates(&files, &PoseFileOptions::default());
        let _ = parse_pose_files(&files[..1], &PoseFileOptions::default());
    }
}
