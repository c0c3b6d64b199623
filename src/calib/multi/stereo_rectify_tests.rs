//! Epipolar geometry and rectification of a known pair. Noise-free, so the
//! constraints hold to rounding (1e-9 on unit-scale normalised points, 1e-9
//! px on rows); the OpenCV oracle numbers are from cv2.stereoRectify
//! (opencv-python-headless 5.1.0, CALIB_ZERO_DISPARITY, alpha -1) on the
//! same cameras, agreeing to 1e-6 (OpenCV's undistortPoints stops after a
//! fixed number of iterations, ours at convergence).

use super::*;
use crate::camera::Distortion;
use crate::geometry::rotation_from_rotvec;
use nalgebra::{Point3, Translation3};

fn brown(fx: f64, cx: f64, k1: f64) -> Camera {
    Camera {
        fx,
        fy: fx * 1.01,
        cx,
        cy: 241.0,
        skew: 0.0,
        width: 640,
        height: 480,
        distortion: Distortion::Brown {
            k1,
            k2: 0.01,
            k3: 0.0,
            p1: 0.0005,
            p2: -0.0003,
        },
    }
}

fn pair() -> (Camera, Camera, Pose) {
    let right_from_left = Pose::from_parts(
        Translation3::new(-0.06, 0.002, -0.001),
        rotation_from_rotvec(&Vector3::new(0.01, -0.04, 0.015)),
    );
    (
        brown(620.0, 318.0, -0.12),
        brown(640.0, 326.0, -0.05),
        right_from_left,
    )
}

fn points() -> Vec<Point3<f64>> {
    (0..30)
        .map(|i| {
            let i = i as f64;
            Point3::new(-0.3 + 0.02 * i, 0.2 - 0.013 * i, 0.8 + 0.05 * (i % 7.0))
        })
        .collect()
}

#[test]
fn points_satisfy_the_epipolar_constraint_of_e_and_f() {
    let (left, right, right_from_left) = pair();
    let e = essential_matrix(&right_from_left);
    let f = fundamental_matrix(&left, &right, &right_from_left).unwrap();
    // E = [T]x R entry by entry.
    let t = right_from_left.translation.vector;
    let r = right_from_left.rotation.to_rotation_matrix().into_inner();
    assert!((e - cross_matrix(&t) * r).norm() < 1e-15);
    let (k1, k2) = (left.camera_matrix(), right.camera_matrix());
    for p in points() {
        let q = right_from_left * p;
        let xl = p.coords / p.z;
        let xr = q.coords / q.z;
        let c = xr.dot(&(e * xl));
        assert!(c.abs() < 1e-9, "x_r^T E x_l = {c}");
        // Undistorted pixels: F.
        let (ul, ur) = (k1 * xl, k2 * xr);
        let c = ur.dot(&(f * ul));
        assert!(c.abs() < 1e-9, "p_r^T F p_l = {c}");
    }
}

#[test]
fn rectified_rows_align_and_depth_comes_back_from_disparity() {
    let (left, right, right_from_left) = pair();
    let rect = rectify(&left, &right, &right_from_left).unwrap();
    assert!(!rect.vertical);
    // R1, R2 are rotations; the rectified right camera sits on the new x axis.
    for r in [rect.r1, rect.r2] {
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-12);
        assert!((r.determinant() - 1.0).abs() < 1e-12);
    }
    let tx = rect.p2[(0, 3)] / rect.p2[(0, 0)];
    assert!((tx.abs() - right_from_left.translation.vector.norm()).abs() < 1e-12);
    assert!(
        tx < 0.0,
        "the right camera is at +x: Tx = -baseline, got {tx}"
    );
    for p in points() {
        // The same point in each rectified camera, from each camera's frame.
        let in_left = rect.r1 * p.coords;
        let in_right = rect.r2 * (right_from_left * p).coords;
        let pl = rect.p1 * in_left.push(1.0);
        let pr = rect.p1 * in_right.push(1.0);
        let (vl, vr) = (pl.y / pl.z, pr.y / pr.z);
        assert!((vl - vr).abs() < 1e-9, "rows {vl} and {vr} px");
        // P2 projects rectified-left coordinates into the right image.
        let p2 = rect.p2 * in_left.push(1.0);
        assert!((p2.x / p2.z - pr.x / pr.z).abs() < 1e-9);
        // Q brings the depth back from the disparity.
        let d = pl.x / pl.z - pr.x / pr.z;
        let h = rect.q * nalgebra::Vector4::new(pl.x / pl.z, vl, d, 1.0);
        assert!(
            (h.z / h.w - in_left.z).abs() < 1e-9,
            "depth {} m",
            h.z / h.w
        );
    }
}

#[test]
fn rectification_matches_opencv() {
    let (left, right, right_from_left) = pair();
    let rect = rectify(&left, &right, &right_from_left).unwrap();
    // cv2.stereoRectify(K1, D1, K2, D2, (640, 480), R, T, flags=CALIB_ZERO_DISPARITY, alpha=-1)
    // with D = [k1, 0.01, 0.0005, -0.0003, 0] (benches/stereo_rectify_opencv.py).
    // Rotations to 1e-9; pixels to 1e-4 px (OpenCV undistorts the corners
    // with a fixed number of iterations, we to convergence).
    let close = |what: &str, ours: Vec<f64>, theirs: &[f64], tolerance: f64| {
        for (i, (a, b)) in ours.iter().zip(theirs).enumerate() {
            assert!((a - b).abs() < tolerance, "{what}[{i}]: {a} vs OpenCV {b}");
        }
    };
    let flat = |m: &dyn Fn(usize) -> f64, n: usize| (0..n).map(m).collect::<Vec<f64>>();
    close(
        "R1",
        flat(&|i| rect.r1[(i / 3, i % 3)], 9),
        &OPENCV_R1,
        1e-9,
    );
    close(
        "R2",
        flat(&|i| rect.r2[(i / 3, i % 3)], 9),
        &OPENCV_R2,
        1e-9,
    );
    close(
        "P1",
        flat(&|i| rect.p1[(i / 4, i % 4)], 12),
        &OPENCV_P1,
        1e-4,
    );
    close(
        "P2",
        flat(&|i| rect.p2[(i / 4, i % 4)], 12),
        &OPENCV_P2,
        1e-4,
    );
    close("Q", flat(&|i| rect.q[(i / 4, i % 4)], 16), &OPENCV_Q, 1e-4);
}

const OPENCV_R1: [f64; 9] = [
    0.9985689649115307,
    -0.04832791001225464,
    -0.02290055521950448,
    0.04820361752515503,
    0.9988198133371483,
    -0.00594909595088168,
    0.023161035663431,
    0.0048366929809165946,
    0.9997200472272254,
];
const OPENCV_R2: [f64; 9] = [
    0.9993062780989564,
    -0.033310209269965564,
    0.016655104634982584,
    0.03321985740619828,
    0.9994319705981438,
    0.005672496824410728,
    -0.016834596102163254,
    -0.005115281488070617,
    0.9998452031536557,
];
const OPENCV_P1: [f64; 12] = [
    636.3,
    0.0,
    324.4859085083008,
    0.0,
    0.0,
    636.3,
    241.5830249786377,
    0.0,
    0.0,
    0.0,
    1.0,
    0.0,
];
const OPENCV_P2: [f64; 12] = [
    636.3,
    0.0,
    324.4859085083008,
    -38.20450330065815,
    0.0,
    636.3,
    241.5830249786377,
    0.0,
    0.0,
    0.0,
    1.0,
    0.0,
];
const OPENCV_Q: [f64; 16] = [
    1.0,
    0.0,
    0.0,
    -324.4859085083008,
    0.0,
    1.0,
    0.0,
    -241.5830249786377,
    0.0,
    0.0,
    0.0,
    636.3,
    0.0,
    0.0,
    16.655104634982607,
    -0.0,
];

#[test]
fn a_pair_without_a_baseline_or_with_two_sizes_is_refused() {
    let (left, mut right, right_from_left) = pair();
    let same_place = Pose::from_parts(Translation3::new(0.0, 0.0, 0.0), right_from_left.rotation);
    assert_eq!(
        rectify(&left, &right, &same_place).unwrap_err().to_string(),
        "right_from_left: the baseline is zero: the cameras are at one place, so there is nothing to rectify"
    );
    right.width = 1280;
    assert_eq!(
        rectify(&left, &right, &right_from_left).unwrap_err().to_string(),
        "image_size_px: stereo rectification needs one image size, but the left camera is 640x480 and the right 1280x480"
    );
}
