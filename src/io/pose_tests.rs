//! Unit tests of the robot pose parsers and writers: hand-computed vendor
//! poses, exact error messages, round trips, candidates, and random input.

use nalgebra::{Matrix3, Translation3, Vector3};
use wasm_bindgen_test::wasm_bindgen_test;

use super::*;
use crate::geometry::{rotation_angle_between, rotation_from_rotvec, EulerKind, EulerOrder, Pose};
use crate::rng::Rng;

fn opts(format: PoseFormat) -> PoseFileOptions {
    PoseFileOptions {
        format: Some(format),
        ..Default::default()
    }
}

fn only(text: &str, format: PoseFormat) -> Pose {
    let parsed = parse_poses(text, &opts(format)).unwrap();
    assert_eq!(parsed.poses.len(), 1);
    parsed.poses[0].base_from_gripper
}

fn assert_rotation(pose: &Pose, rows: [[f64; 3]; 3]) {
    let expected = Matrix3::from_fn(|r, c| rows[r][c]);
    let got = pose.rotation.to_rotation_matrix().into_inner();
    assert!(
        (got - expected).amax() < 1e-12,
        "got {got}, expected {expected}"
    );
}

const RZ90: [[f64; 3]; 3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
const RX90: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]];
/// Rz(90) · Rx(90), computed by hand.
const RZ90_RX90: [[f64; 3]; 3] = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
/// Rx(90) · Rz(90), computed by hand.
const RX90_RZ90: [[f64; 3]; 3] = [[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]];

#[wasm_bindgen_test(unsupported = test)]
fn vendor_presets_match_hand_computed_matrices() {
    // KUKA: A about Z first. A = 90 alone is Rz(90); (A, C) = (90, 90) is Rz·Rx.
    let p = only("100 -200 300 90 0 0", PoseFormat::Kuka);
    assert!((p.translation.vector - Vector3::new(0.1, -0.2, 0.3)).norm() < 1e-15);
    assert_rotation(&p, RZ90);
    assert_rotation(&only("0 0 0 90 0 90", PoseFormat::Kuka), RZ90_RX90);
    // FANUC: W about fixed X first; R = Rz(R) Ry(P) Rx(W).
    assert_rotation(&only("0 0 0 90 0 0", PoseFormat::Fanuc), RX90);
    assert_rotation(&only("0 0 0 90 0 90", PoseFormat::Fanuc), RZ90_RX90);
    assert_rotation(&only("0 0 0 90 0 90", PoseFormat::Yaskawa), RZ90_RX90);
    // Stäubli: intrinsic X-Y'-Z'': Rx(90) Rz(90).
    assert_rotation(&only("0 0 0 90 0 90", PoseFormat::Staubli), RX90_RZ90);
    // ABB: mm, w first.
    let h = 0.5f64.sqrt();
    let p = only(&format!("100 200 300 {h} 0 0 {h}"), PoseFormat::Abb);
    assert!((p.translation.vector - Vector3::new(0.1, 0.2, 0.3)).norm() < 1e-15);
    assert_rotation(&p, RZ90);
    assert_rotation(
        &only(&format!("0 0 0 0 0 {h} {h}"), PoseFormat::XyzQuatXyzw),
        RZ90,
    );
    assert_rotation(
        &only(&format!("0 0 0 {h} 0 0 {h}"), PoseFormat::XyzQuatWxyz),
        RZ90,
    );
    // UR: metres, rotation vector in radians.
    let p = only("0.1 0.2 0.3 0 0 1.5707963267948966", PoseFormat::Ur);
    assert!((p.translation.vector - Vector3::new(0.1, 0.2, 0.3)).norm() < 1e-15);
    assert_rotation(&p, RZ90);
    // Generic Euler, extrinsic ZYX in degrees: Rx(c) Ry(b) Rz(a) with a = 90.
    let o = PoseFileOptions {
        format: Some(PoseFormat::XyzEuler {
            order: EulerOrder::ZYX,
            kind: EulerKind::Extrinsic,
        }),
        angle_unit: Some(AngleUnit::Degree),
        ..Default::default()
    };
    let p = parse_poses("0 0 0 90 0 90", &o).unwrap().poses[0].base_from_gripper;
    assert_rotation(&p, RX90_RZ90);
    // Matrix, row-major.
    let p = only("0 -1 0 1  1 0 0 2  0 0 1 3  0 0 0 1", PoseFormat::Matrix4);
    assert_rotation(&p, RZ90);
    assert_eq!(p.translation.vector, Vector3::new(1.0, 2.0, 3.0));
}

#[wasm_bindgen_test(unsupported = test)]
fn headers_select_format_units_names_and_columns() {
    let text = "# exported\nimage,qw,x,y,z,qx,qy,qz\n\nimg_01.png,0.7071068,1,2,3,0,0,0.7071068\n";
    let parsed = parse_poses(text, &PoseFileOptions::default()).unwrap();
    assert_eq!(parsed.format, PoseFormat::XyzQuatWxyz);
    assert_eq!(parsed.length_unit, LengthUnit::Metre);
    let p = &parsed.poses[0];
    assert_eq!((p.name.as_deref(), p.line), (Some("img_01.png"), 4));
    assert_rotation(&p.base_from_gripper, RZ90);
    assert_eq!(
        p.base_from_gripper.translation.vector,
        Vector3::new(1.0, 2.0, 3.0)
    );
    assert_eq!(
        parsed.notes,
        [
            "format xyz_quat_wxyz from the header",
            "lengths in m (the xyz_quat_wxyz default)"
        ]
    );
    // KUKA header with units and an ignored status column; tab-separated.
    let text = "X [m]\tY [m]\tZ [m]\tA\tB\tC\tS\n1\t2\t3\t90\t0\t0\t2\n";
    let parsed = parse_poses(text, &PoseFileOptions::default()).unwrap();
    assert_eq!(
        (parsed.format, parsed.length_unit, parsed.angle_unit),
        (PoseFormat::Kuka, LengthUnit::Metre, AngleUnit::Degree)
    );
    assert!(parsed.notes.contains(&"ignored columns: S".to_string()));
    assert_eq!(
        parsed.poses[0].base_from_gripper.translation.vector,
        Vector3::new(1.0, 2.0, 3.0)
    );
    // roll/pitch/yaw = extrinsic XYZ; x,y,z,rx,ry,rz = UR.
    let parsed = parse_poses(
        "x,y,z,roll,pitch,yaw\n0,0,0,0,0,1.5707963267948966",
        &PoseFileOptions::default(),
    )
    .unwrap();
    assert_rotation(&parsed.poses[0].base_from_gripper, RZ90);
    let parsed = parse_poses(
        "x,y,z,rx,ry,rz\n0,0,0,1.5707963267948966,0,0",
        &PoseFileOptions::default(),
    )
    .unwrap();
    assert_eq!(parsed.format, PoseFormat::Ur);
    assert_rotation(&parsed.poses[0].base_from_gripper, RX90);
    // 16 values without a header can only be a matrix; a leading name is kept.
    let parsed = parse_poses(
        "a 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n",
        &PoseFileOptions::default(),
    )
    .unwrap();
    assert_eq!(
        (parsed.format, parsed.poses[0].name.as_deref()),
        (PoseFormat::Matrix4, Some("a"))
    );
}

fn err(text: &str, options: &PoseFileOptions) -> String {
    parse_poses(text, options).unwrap_err().to_string()
}

#[wasm_bindgen_test(unsupported = test)]
fn errors_say_where_and_what() {
    let mut lines = vec!["0 0 0 0 0 0"; 6];
    lines.push("1 2 3 4 abc 6");
    assert_eq!(
        err(&lines.join("\n"), &opts(PoseFormat::Kuka)),
        "line 7, column 5: 'abc' is not a number"
    );
    let text = "X,Y,Z,A,B,C,S\n1,2,3,4,5,6,0\n1,2,3,4,5,6\n";
    assert_eq!(
        err(text, &PoseFileOptions::default()),
        "line 3: 6 values, the KUKA format needs 6 (X Y Z A B C) but the header names 7"
    );
    assert_eq!(
        err("1 2 3 4 5", &opts(PoseFormat::Kuka)),
        "line 1: 5 values, the KUKA format needs 6 (X Y Z A B C)"
    );
    let mut lines = vec!["0 0 0 0 0 0 1"; 11];
    lines.push("0 0 0 0.2 0 0 0");
    assert_eq!(
        err(&lines.join("\n"), &opts(PoseFormat::XyzQuatXyzw)),
        "line 12, column 4: quaternion has norm 0.2: not a rotation"
    );
    assert_eq!(
        err("0.1 0.2 0.3 0 0 400", &opts(PoseFormat::Ur)),
        "line 1, column 4: rotation vector angle 400 deg looks like degrees; this format expects radians"
    );
    let o = PoseFileOptions {
        format: Some(PoseFormat::Kuka),
        angle_unit: Some(AngleUnit::Radian),
        ..Default::default()
    };
    assert_eq!(
        err("0 0 0 0 -90 0", &o),
        "line 1, column 5: Euler angle -90 looks like degrees; this format expects radians"
    );
    assert_eq!(
        err("1 2 3 4 5 6", &PoseFileOptions::default()),
        "line 1: 6 values a line and no header: ambiguous between ur, kuka, fanuc, yaskawa, staubli, xyz_rotvec, xyz_euler_intrinsic_xyz, xyz_euler_intrinsic_xzy, ...; name the format or add a header"
    );
    assert_eq!(
        err(
            "1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1",
            &PoseFileOptions::default()
        ),
        "line 1: 4x4 matrix bottom row is [0 0 1 1], expected [0 0 0 1]"
    );
    assert_eq!(err("a,b,c\n1,2,3", &PoseFileOptions::default()),
        "line 1: the header 'a b c' names no known pose format; name the format, or use column names such as x,y,z,qx,qy,qz,qw or X,Y,Z,A,B,C");
    assert_eq!(
        err("# nothing\n\n", &PoseFileOptions::default()),
        "poses: the file holds no poses (it is empty, or only a header and comments): give one \
         pose per line, e.g. x,y,z,qx,qy,qz,qw"
    );
    assert_eq!(
        err("1 2 3 nan 5 6", &opts(PoseFormat::Fanuc)),
        "line 1, column 4: 'nan' is not a number"
    );
    assert_eq!(
        err("1,2,,4,5,6", &opts(PoseFormat::Fanuc)),
        "line 1, column 3: empty field"
    );
    assert_eq!(
        err("x,y,z,e1,e2,e3,e4\n1,2,3,4,5,6,7", &opts(PoseFormat::Kuka)),
        "line 1: the header names 7 columns (x y z e1 e2 e3 e4), the KUKA format needs 6 (X Y Z A B C)"
    );
    // Same count, other names: read by position, and the note says so.
    let parsed = parse_poses("x,y,z,e1,e2,e3\n1,2,3,90,0,0", &opts(PoseFormat::Kuka)).unwrap();
    assert_rotation(&parsed.poses[0].base_from_gripper, RZ90);
    assert_eq!(
        parsed.notes[0],
        "header names 'x y z e1 e2 e3' are not the KUKA column names; columns read by position"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn json_objects_and_matrices() {
    let text = r#"[{"name": "p1", "x": 0.1, "y": 0.2, "z": 0.3, "qx": 0, "qy": 0, "qz": 0.7071067811865476, "qw": 0.7071067811865476}]"#;
    let parsed = parse_poses(text, &PoseFileOptions::default()).unwrap();
    assert_eq!(parsed.format, PoseFormat::XyzQuatXyzw);
    assert_eq!(
        (parsed.poses[0].name.as_deref(), parsed.poses[0].line),
        (Some("p1"), 1)
    );
    assert_rotation(&parsed.poses[0].base_from_gripper, RZ90);
    let nested =
        "[[[0,-1,0,1],[1,0,0,2],[0,0,1,3],[0,0,0,1]], [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]]";
    let parsed = parse_poses(nested, &PoseFileOptions::default()).unwrap();
    assert_eq!(
        (parsed.format, parsed.poses.len()),
        (PoseFormat::Matrix4, 2)
    );
    assert_rotation(&parsed.poses[0].base_from_gripper, RZ90);
    let wrapped = r#"{"poses": [[1,2,3,90,0,0]]}"#;
    assert_rotation(&only(wrapped, PoseFormat::Kuka), RZ90);
    let bad = r#"[{"x": 1, "y": 2, "z": 3, "qx": 0, "qy": 0, "qz": 0, "qw": "one"}]"#;
    assert_eq!(
        err(bad, &PoseFileOptions::default()),
        "JSON pose 1: 'one' is not a number"
    );
    let pair =
        "[[[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]]]";
    assert_eq!(err(pair, &PoseFileOptions::default()),
        "JSON pose 1: expected numbers or one 4x4 matrix, found a list of 2 lists (for [robot, camera] pairs, pass the robot matrices alone)");
    assert_eq!(
        err("[1, 2", &PoseFileOptions::default()),
        "line 1, column 5: invalid JSON: EOF while parsing a list"
    );
}

fn random_pose(rng: &mut Rng, case: usize) -> Pose {
    let axis = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
    let angle = match case % 5 {
        0 => 0.0,
        1 => std::f64::consts::PI - 1e-7,
        _ => rng.range(0.0, 3.1),
    };
    let t = Translation3::new(
        rng.range(-1.5, 1.5),
        rng.range(-1.5, 1.5),
        rng.range(0.0, 2.0),
    );
    Pose::from_parts(t, rotation_from_rotvec(&(axis * angle)))
}

#[wasm_bindgen_test(unsupported = test)]
fn every_format_round_trips_through_the_writer() {
    let mut rng = Rng::new(41);
    for (fi, format) in PoseFormat::all().into_iter().enumerate() {
        for (l, a) in [
            (LengthUnit::Metre, AngleUnit::Radian),
            (LengthUnit::Millimetre, AngleUnit::Degree),
        ] {
            let poses: Vec<RobotPose> = (0..40)
                .map(|i| RobotPose {
                    name: (i % 3 != 0).then(|| format!("im,\"{i}\"")),
                    line: i + 2,
                    base_from_gripper: random_pose(&mut rng, i + fi),
                })
                .collect();
            let text = format_poses(&poses, format, l, a);
            let back = parse_poses(&text, &opts(format)).unwrap();
            assert_eq!(
                (back.length_unit, back.format),
                (l, format),
                "{}",
                format.name()
            );
            for (p, q) in poses.iter().zip(&back.poses) {
                assert_eq!((&p.name, p.line), (&q.name, q.line));
                let (p, q) = (p.base_from_gripper, q.base_from_gripper);
                assert!(
                    (p.translation.vector - q.translation.vector).norm() < 1e-12,
                    "{}",
                    format.name()
                );
                assert!(
                    rotation_angle_between(&p.rotation, &q.rotation) < 1e-12,
                    "{}",
                    format.name()
                );
            }
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn gripper_from_base_files_are_inverted() {
    let mut rng = Rng::new(42);
    let pose = random_pose(&mut rng, 2);
    let rp = RobotPose {
        name: None,
        line: 2,
        base_from_gripper: pose.inverse(),
    };
    let text = format_poses(
        &[rp],
        PoseFormat::Matrix4,
        LengthUnit::Metre,
        AngleUnit::Radian,
    );
    let o = PoseFileOptions {
        direction: PoseDirection::GripperFromBase,
        ..Default::default()
    };
    let back = parse_poses(&text, &o).unwrap();
    assert_eq!(back.direction, PoseDirection::GripperFromBase);
    let got = back.poses[0].base_from_gripper;
    assert!((got.to_homogeneous() - pose.to_homogeneous()).amax() < 1e-12);
}

#[wasm_bindgen_test(unsupported = test)]
fn candidates_rank_unit_and_format_readings() {
    let mut rng = Rng::new(43);
    let poses: Vec<RobotPose> = (0..10)
        .map(|i| RobotPose {
            name: None,
            line: i + 1,
            base_from_gripper: random_pose(&mut rng, i + 2),
        })
        .collect();
    let body = |f, l, a| {
        format_poses(&poses, f, l, a)
            .lines()
            .skip(1)
            .collect::<Vec<_>>()
            .join("\n")
    };
    // UR data (m, rad) without header: UR first, and it is the truth.
    let c = parse_pose_candidates(
        &body(PoseFormat::Ur, LengthUnit::Metre, AngleUnit::Radian),
        &PoseFileOptions::default(),
    )
    .unwrap();
    assert_eq!(
        (c[0].format, c[0].length_unit, c[0].angle_unit, c[0].penalty),
        (PoseFormat::Ur, LengthUnit::Metre, AngleUnit::Radian, 0.0)
    );
    assert!(c[0].same_as.contains(&"xyz_rotvec (m, rad)".to_string()));
    assert!(
        rotation_angle_between(
            &c[0].poses[3].base_from_gripper.rotation,
            &poses[3].base_from_gripper.rotation
        ) < 1e-12
    );
    // A millimetre reading of metre data is ranked below for its tiny reach.
    let mm = c
        .iter()
        .position(|x| x.format == PoseFormat::Ur && x.length_unit == LengthUnit::Millimetre)
        .unwrap();
    assert!(c[mm].penalty > 1.0, "{:?}", c[mm].reasons);
    // KUKA data (mm, deg): zero-penalty KUKA and FANUC readings (Yaskawa merged).
    let c = parse_pose_candidates(
        &body(PoseFormat::Kuka, LengthUnit::Millimetre, AngleUnit::Degree),
        &PoseFileOptions::default(),
    )
    .unwrap();
    assert_eq!((c[0].format, c[0].penalty), (PoseFormat::Kuka, 0.0));
    assert!(c[0]
        .same_as
        .contains(&"xyz_euler_intrinsic_zyx (mm, deg)".to_string()));
    let fanuc = c
        .iter()
        .find(|x| x.format == PoseFormat::Fanuc && x.length_unit == LengthUnit::Millimetre)
        .unwrap();
    assert!(fanuc.same_as.contains(&"yaskawa (mm, deg)".to_string()));
    assert!(
        c.iter().all(|x| x.angle_unit == AngleUnit::Degree),
        "radian readings of degrees must drop"
    );
    // 7 numbers: xyzw and wxyz both offered; a header leaves only its format.
    let c = parse_pose_candidates(
        &body(
            PoseFormat::XyzQuatXyzw,
            LengthUnit::Metre,
            AngleUnit::Radian,
        ),
        &PoseFileOptions::default(),
    )
    .unwrap();
    assert_eq!(c[0].format, PoseFormat::XyzQuatXyzw);
    let wxyz = c
        .iter()
        .find(|x| x.format == PoseFormat::XyzQuatWxyz)
        .unwrap();
    assert!(
        wxyz.same_as.contains(&"abb (m)".to_string()),
        "{:?}",
        wxyz.same_as
    );
    let text = format_poses(
        &poses,
        PoseFormat::Kuka,
        LengthUnit::Millimetre,
        AngleUnit::Degree,
    );
    let c = parse_pose_candidates(&text, &PoseFileOptions::default()).unwrap();
    assert!(c.iter().all(|x| x.format == PoseFormat::Kuka));
    assert_eq!(c[0].length_unit, LengthUnit::Millimetre);
}

#[wasm_bindgen_test(unsupported = test)]
fn random_bytes_and_text_never_panic() {
    let mut rng = Rng::new(44);
    let vocab = [
        "0", "1", "-2.5", "1e308", "1e-320", "nan", "inf", "abc", ",", ";", "\t", " ", "\n", "#",
        "[", "]", "{", "}", "\"", ":", "x", "y", "z", "qw", "qx", "qy", "qz", "A", "B", "C", "rx",
        "name", "m00", "_mm", "[deg]", "poses", "90", "3.14159", "\u{feff}", "é",
    ];
    let formats = PoseFormat::all();
    for case in 0..3000 {
        let text = if case % 3 == 0 {
            let bytes: Vec<u8> = (0..rng.below(200)).map(|_| rng.below(256) as u8).collect();
            String::from_utf8_lossy(&bytes).into_owned()
        } else {
            (0..rng.below(120))
                .map(|_| vocab[rng.below(vocab.len())])
                .collect()
        };
        let o = PoseFileOptions {
            format: (case % 2 == 0).then(|| formats[rng.below(formats.len())]),
            ..Default::default()
        };
        let _ = parse_poses(&text, &o);
        let _ = parse_pose_candidates(&text, &o);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn matrix3x4_tables_by_header_names_in_any_order_or_twelve_numbers() {
    let d = PoseFileOptions::default();
    let t = |p: &Pose| p.translation.vector;
    // r11..tz interleaved as rows, then the rotation first and the
    // translation last, then m00..m23, then no header.
    for text in [
        "r11,r12,r13,tx,r21,r22,r23,ty,r31,r32,r33,tz\n0,-1,0,0.1,1,0,0,0.2,0,0,1,0.3\n",
        "r11,r12,r13,r21,r22,r23,r31,r32,r33,tx,ty,tz\n0,-1,0,1,0,0,0,0,1,0.1,0.2,0.3\n",
        "m00 m01 m02 m03 m10 m11 m12 m13 m20 m21 m22 m23\n0 -1 0 0.1 1 0 0 0.2 0 0 1 0.3\n",
        "0 -1 0 0.1 1 0 0 0.2 0 0 1 0.3\n",
    ] {
        let parsed = parse_poses(text, &d).unwrap();
        assert_eq!(parsed.format, PoseFormat::Matrix3x4, "{text}");
        let p = parsed.poses[0].base_from_gripper;
        assert_rotation(&p, RZ90);
        assert!(
            (t(&p) - Vector3::new(0.1, 0.2, 0.3)).norm() < 1e-12,
            "{text}"
        );
    }
    // Millimetres by the header, on the translation columns.
    let mm =
        "r11,r12,r13,r21,r22,r23,r31,r32,r33,tx_mm,ty_mm,tz_mm\n1,0,0,0,1,0,0,0,1,100,200,300\n";
    let parsed = parse_poses(mm, &d).unwrap();
    assert_eq!(parsed.length_unit, LengthUnit::Millimetre);
    assert!((t(&parsed.poses[0].base_from_gripper) - Vector3::new(0.1, 0.2, 0.3)).norm() < 1e-12);
    // Not a rotation: said for the 3x4 matrix, at the line.
    let err = parse_poses("1 0 0 0 0 1 0 0 0 0 2 0\n", &d)
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("line 1: 3x4 matrix "), "{err}");
    // The writer's table reads back.
    let text = format_poses(
        &parsed.poses,
        PoseFormat::Matrix3x4,
        LengthUnit::Metre,
        AngleUnit::Radian,
    );
    assert_eq!(
        text.lines().next().unwrap(),
        "r11,r12,r13,tx,r21,r22,r23,ty,r31,r32,r33,tz"
    );
    let back = parse_poses(&text, &d).unwrap();
    assert!((t(&back.poses[0].base_from_gripper) - Vector3::new(0.1, 0.2, 0.3)).norm() < 1e-12);
}

#[wasm_bindgen_test(unsupported = test)]
fn header_units_and_names_say_the_convention() {
    let d = PoseFileOptions::default();
    // _deg on rx ry rz: Euler about the fixed x, y, z (not a rotation vector).
    let deg = "x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg\n100,200,300,90,0,90\n";
    let parsed = parse_poses(deg, &d).unwrap();
    let rpy = PoseFormat::XyzEuler {
        order: EulerOrder::XYZ,
        kind: EulerKind::Extrinsic,
    };
    assert_eq!(parsed.format, rpy);
    assert_eq!(
        (parsed.length_unit, parsed.angle_unit),
        (LengthUnit::Millimetre, AngleUnit::Degree)
    );
    assert_rotation(&parsed.poses[0].base_from_gripper, RZ90_RX90);
    assert!(
        (parsed.poses[0].base_from_gripper.translation.vector - Vector3::new(0.1, 0.2, 0.3)).norm()
            < 1e-12
    );
    assert_eq!(
        parsed.notes[1],
        "rx ry rz in degrees read as Euler angles about the fixed x, then y, then z axes (R = Rz·Ry·Rx, format xyz_euler_extrinsic_xyz); name another convention with the format, e.g. staubli (xyz_euler_intrinsic_xyz) or xyz_euler_intrinsic_zyx"
    );
    // The format overrides the assumed convention; columns by their names.
    let staubli = parse_poses(deg, &opts(PoseFormat::Staubli)).unwrap();
    assert_rotation(&staubli.poses[0].base_from_gripper, RX90_RZ90);
    let zyx = PoseFormat::XyzEuler {
        order: EulerOrder::ZYX,
        kind: EulerKind::Intrinsic,
    };
    let p = parse_poses(deg, &opts(zyx)).unwrap();
    // rz is e1 of zyx: Rz(90)·Ry(0)·Rx(90), the same product as extrinsic xyz.
    assert_rotation(&p.poses[0].base_from_gripper, RZ90_RX90);
    // Without units: UR's rotation vector in radians, as before.
    assert_eq!(
        parse_poses("x,y,z,rx,ry,rz\n0,0,0,0,0,1\n", &d)
            .unwrap()
            .format,
        PoseFormat::Ur
    );
    // qw first or last by its place in the header.
    let wxyz = parse_poses(
        "x,y,z,qw,qx,qy,qz\n0,0,0,0.7071067811865476,0,0,0.7071067811865476\n",
        &d,
    )
    .unwrap();
    assert_eq!(wxyz.format, PoseFormat::XyzQuatWxyz);
    assert_rotation(&wxyz.poses[0].base_from_gripper, RZ90);
    let xyzw = parse_poses(
        "x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0.7071067811865476,0.7071067811865476\n",
        &d,
    )
    .unwrap();
    assert_eq!(xyzw.format, PoseFormat::XyzQuatXyzw);
    assert_rotation(&xyzw.poses[0].base_from_gripper, RZ90);
    // Radians under a _deg header read as degrees: tiny angles, left for the
    // plausibility checks (the reading itself is what the header says).
    let small = parse_poses(
        "x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg\n100,0,0,1.5707963267948966,0,0\n",
        &d,
    )
    .unwrap();
    assert!(
        (small.poses[0].base_from_gripper.rotation.angle()
            - std::f64::consts::FRAC_PI_2.to_radians())
        .abs()
            < 1e-12
    );
}
