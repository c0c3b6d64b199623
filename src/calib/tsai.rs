//! Tsai's two-stage calibration (IEEE J. Robotics and Automation 1987), the
//! coplanar case, as seed 000 compares it with Zhang's method:
//!
//! 1. Per view, the radial alignment constraint (the image vector from the
//!    principal point is parallel to the radial vector of the point in the
//!    camera frame, whatever f, Tz and the radial distortion) gives five
//!    unknowns `[r1 r2 Tx r4 r5] / Ty` linearly; Ty, its sign and the whole
//!    rotation follow.
//! 2. f and each view's Tz from one linear system over all views (f shared).
//! 3. Levenberg-Marquardt over f, k1 and every pose (Tsai's nonlinear stage).
//!
//! Tsai's camera model: principal point at the image centre, square pixels
//! (fx = fy; the coplanar case cannot estimate the scale factor sx), no
//! skew, radial distortion k1 only (reported as the Brown model with k2 p1
//! p2 k3 held at 0, so k1 compares directly with Zhang's).

use super::evaluate::refine_from;
use super::{CalibrationOptions, CameraCalibration, View};
use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};
use crate::geometry::{nearest_rotation, Pose};
use nalgebra::{DMatrix, DVector, Matrix3, Translation3, UnitQuaternion, Vector3};

/// Fewest points per view for the five unknowns of stage 1.
const MIN_POINTS: usize = 5;
/// |z| above which a target point is not on the plane, metres.
const PLANE_TOLERANCE_M: f64 = 1e-9;
/// Solver iterations of stage 3.
const MAX_ITERATIONS: usize = 200;

/// Tsai's calibration from planar views. A view with fewer than 5 points
/// (a partial view that still fixes a homography) is left out with a
/// warning while at least one view remains; otherwise the error names it.
pub fn calibrate_tsai(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    let (enough, few): (Vec<View>, Vec<View>) = views
        .iter()
        .cloned()
        .partition(|v| v.object_m.len() >= MIN_POINTS);
    if enough.is_empty() || few.is_empty() {
        return calibrate_tsai_views(views, image_size_px, options);
    }
    let mut report = calibrate_tsai_views(&enough, image_size_px, options)?;
    report.warnings.extend(few.iter().map(|v| {
        format!(
            "view {} left out: {} points: Tsai's method needs at least {MIN_POINTS}",
            v.name,
            v.object_m.len()
        )
    }));
    Ok(report)
}

fn calibrate_tsai_views(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    let cx = 0.5 * (image_size_px.0 as f64 - 1.0);
    let cy = 0.5 * (image_size_px.1 as f64 - 1.0);
    // 1. Rotation, Tx and Ty per view.
    let partial: Vec<PartialPose> = views
        .iter()
        .map(|v| radial_alignment(v, cx, cy))
        .collect::<Result<_>>()?;
    // 2. f and the Tz's, with the rotation signs fixed so that f > 0.
    let (f, poses) = focal_and_depths(views, &partial, cx, cy)?;
    // 3. Nonlinear refinement of f, k1 and the poses.
    let camera = Camera {
        fx: f,
        fy: f,
        cx,
        cy,
        skew: 0.0,
        width: image_size_px.0,
        height: image_size_px.1,
        distortion: Distortion::Brown {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
    };
    // Free: fx (fy follows), k1.
    let fixed = (0..camera.params().len())
        .map(|i| !(i == 0 || i == 5))
        .collect();
    let mut report = refine_from(
        views,
        &camera,
        &poses,
        fixed,
        Some(1.0),
        MAX_ITERATIONS,
        options,
    )?;
    report.options.fix_principal_point = true;
    report.options.fix_aspect_ratio = true;
    report.options.zero_skew = true;
    report.options.fixed_coefficients = ["k2", "p1", "p2", "k3"].map(String::from).to_vec();
    Ok(report)
}

/// Stage-1 result of one view: rotation rows 1-2 (up to the sign of the
/// third column), Tx, Ty, and the board origin used (Tsai needs the origin
/// away from the camera's y = 0 plane, so the point imaged farthest from
/// the principal point's row is taken).
struct PartialPose {
    r: Matrix3<f64>,
    tx: f64,
    ty: f64,
    origin: Vector3<f64>,
}

fn radial_alignment(view: &View, cx: f64, cy: f64) -> Result<PartialPose> {
    if view.object_m.len() < MIN_POINTS {
        return Err(Error::too_few(
            format!("points in view {} for Tsai's method", view.name),
            MIN_POINTS,
            view.object_m.len(),
        ));
    }
    if view.object_m.iter().any(|p| p.z.abs() > PLANE_TOLERANCE_M) {
        return Err(Error::invalid(
            format!("views[{}].object_m", view.name),
            "Tsai's method here is the coplanar case: target points must have z = 0",
        ));
    }
    let d: Vec<(f64, f64)> = view.image_px.iter().map(|p| (p.x - cx, p.y - cy)).collect();
    let far_row = (0..d.len())
        .max_by(|&a, &b| d[a].1.abs().total_cmp(&d[b].1.abs()))
        .unwrap_or(0);
    let origin = view.object_m[far_row].coords;
    let w: Vec<(f64, f64)> = view
        .object_m
        .iter()
        .map(|p| (p.x - origin.x, p.y - origin.y))
        .collect();
    // Least squares for a = [r1 r2 Tx r4 r5] / Ty.
    let mut m = DMatrix::zeros(d.len(), 5);
    let mut rhs = DVector::zeros(d.len());
    for (i, (&(xd, yd), &(xw, yw))) in d.iter().zip(&w).enumerate() {
        m.row_mut(i)
            .copy_from_slice(&[yd * xw, yd * yw, yd, -xd * xw, -xd * yw]);
        rhs[i] = xd;
    }
    let a = m
        .svd(true, true)
        .solve(&rhs, 1e-12)
        .map_err(|e| Error::degenerate(format!("Tsai stage 1 in view {}: {e}", view.name)))?;
    let (a1, a2, a3, a4, a5) = (a[0], a[1], a[2], a[3], a[4]);
    // Ty^2 from the 2x2 block C = [[a1 a2] [a4 a5]] (Tsai's Eq. for a full-rank C).
    let sr = a1 * a1 + a2 * a2 + a4 * a4 + a5 * a5;
    let det = a1 * a5 - a4 * a2;
    let ty2 = if det.abs() > 1e-12 * sr {
        (sr - (sr * sr - 4.0 * det * det).max(0.0).sqrt()) / (2.0 * det * det)
    } else {
        // Rank-1 C: one row or column of R's 2x2 block has unit norm.
        let best = [
            a1 * a1 + a2 * a2,
            a4 * a4 + a5 * a5,
            a1 * a1 + a4 * a4,
            a2 * a2 + a5 * a5,
        ]
        .into_iter()
        .fold(0.0, f64::max);
        if best <= 0.0 {
            return Err(Error::degenerate(format!(
                "Tsai stage 1 in view {}: the radial alignment system has no solution",
                view.name
            )));
        }
        1.0 / best
    };
    // The sign of Ty: the farthest point from the centre must project on
    // the same side as it is observed.
    let far = (0..d.len())
        .max_by(|&a, &b| (d[a].0.hypot(d[a].1)).total_cmp(&d[b].0.hypot(d[b].1)))
        .unwrap_or(0);
    let mut ty = ty2.sqrt();
    let (xw, yw) = w[far];
    let x = (a1 * xw + a2 * yw + a3) * ty;
    let y = (a4 * xw + a5 * yw + 1.0) * ty;
    if x * d[far].0 < 0.0 || y * d[far].1 < 0.0 {
        ty = -ty;
    }
    let (r1, r2, r4, r5) = (a1 * ty, a2 * ty, a4 * ty, a5 * ty);
    let r3 = (1.0 - r1 * r1 - r2 * r2).max(0.0).sqrt();
    let r6 = -(r1 * r4 + r2 * r5).signum() * (1.0 - r4 * r4 - r5 * r5).max(0.0).sqrt();
    let row1 = Vector3::new(r1, r2, r3);
    let row2 = Vector3::new(r4, r5, r6);
    let row3 = row1.cross(&row2);
    Ok(PartialPose {
        r: Matrix3::from_rows(&[row1.transpose(), row2.transpose(), row3.transpose()]),
        tx: a3 * ty,
        ty,
        origin,
    })
}

/// The linear system `y f - yd Tz_k = w yd` (and the same in x) over all
/// views, with f shared: [f, Tz_1, ..., Tz_n].
fn solve_stage2(views: &[View], partial: &[PartialPose], cx: f64, cy: f64) -> Result<DVector<f64>> {
    let n_rows: usize = views.iter().map(|v| 2 * v.object_m.len()).sum();
    let mut m = DMatrix::zeros(n_rows, 1 + views.len());
    let mut rhs = DVector::zeros(n_rows);
    let mut row = 0;
    for (k, (view, p)) in views.iter().zip(partial).enumerate() {
        for (object, pixel) in view.object_m.iter().zip(&view.image_px) {
            let q = object.coords - p.origin;
            let xc = p.r[(0, 0)] * q.x + p.r[(0, 1)] * q.y + p.tx;
            let yc = p.r[(1, 0)] * q.x + p.r[(1, 1)] * q.y + p.ty;
            let w = p.r[(2, 0)] * q.x + p.r[(2, 1)] * q.y;
            for (c, d) in [(xc, pixel.x - cx), (yc, pixel.y - cy)] {
                m[(row, 0)] = c;
                m[(row, 1 + k)] = -d;
                rhs[row] = w * d;
                row += 1;
            }
        }
    }
    m.svd(true, true)
        .solve(&rhs, 1e-12)
        .map_err(|e| Error::degenerate(format!("Tsai stage 2: {e}")))
}

fn focal_and_depths(
    views: &[View],
    partial: &[PartialPose],
    cx: f64,
    cy: f64,
) -> Result<(f64, Vec<Pose>)> {
    // A view whose f comes out negative has the wrong sign of r3: flip
    // r3, r6, r7, r8 (Tsai's rule), decided per view from its own system.
    let mut fixed_signs = Vec::with_capacity(views.len());
    for (view, p) in views.iter().zip(partial) {
        let one = solve_stage2(std::slice::from_ref(view), std::slice::from_ref(p), cx, cy)?;
        let mut r = p.r;
        if one[0] < 0.0 {
            r[(0, 2)] = -r[(0, 2)];
            r[(1, 2)] = -r[(1, 2)];
            r[(2, 0)] = -r[(2, 0)];
            r[(2, 1)] = -r[(2, 1)];
        }
        fixed_signs.push(PartialPose { r, ..*p });
    }
    let x = solve_stage2(views, &fixed_signs, cx, cy)?;
    let f = x[0];
    if !(f > 0.0) {
        return Err(Error::degenerate(format!(
            "Tsai stage 2 gave a focal length of {f} px: the views do not determine it (tilt the target)"
        )));
    }
    let poses = fixed_signs
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let rotation = nearest_rotation(&p.r)?;
            // Camera = R (X - origin) + T'  =>  T = T' - R origin.
            let t = Vector3::new(p.tx, p.ty, x[1 + k]) - rotation * p.origin;
            Ok(Pose::from_parts(
                Translation3::from(t),
                UnitQuaternion::from_rotation_matrix(&rotation),
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((f, poses))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::Scene;
    use nalgebra::Point3;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// Tsai's own model (centred principal point, square pixels, k1 only).
    fn tsai_camera() -> Camera {
        Camera {
            fx: 900.0,
            fy: 900.0,
            cx: 319.5,
            cy: 239.5,
            skew: 0.0,
            width: 640,
            height: 480,
            distortion: Distortion::Brown {
                k1: -0.2,
                k2: 0.0,
                k3: 0.0,
                p1: 0.0,
                p2: 0.0,
            },
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn noise_free_views_of_tsais_model_are_recovered_exactly() {
        let truth = tsai_camera();
        let scene = Scene::calibration(5, &truth, (9, 6), 0.03, 6, 0.0).expect("scene");
        let report =
            calibrate_tsai(&scene.views, (640, 480), &CalibrationOptions::default()).expect("tsai");
        assert!(report.rms_px < 1e-9, "rms {} px", report.rms_px);
        assert!(
            (report.camera.fx - 900.0).abs() < 1e-7,
            "fx {} px",
            report.camera.fx
        );
        assert_eq!(report.camera.fy, report.camera.fx);
        assert!((report.distortion["k1"] + 0.2).abs() < 1e-10);
        for (pose, view) in scene.camera_from_target.iter().zip(&report.views) {
            let t = pose.translation.vector;
            let got = Vector3::from(view.camera_from_target.translation_m);
            assert!((t - got).norm() < 1e-9, "pose m");
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn linear_stages_alone_are_exact_without_distortion() {
        let truth = Camera {
            distortion: Distortion::None,
            ..tsai_camera()
        };
        let scene = Scene::calibration(6, &truth, (9, 6), 0.03, 4, 0.0).expect("scene");
        let partial: Vec<PartialPose> = scene
            .views
            .iter()
            .map(|v| radial_alignment(v, 319.5, 239.5))
            .collect::<Result<_>>()
            .expect("stage 1");
        let (f, poses) = focal_and_depths(&scene.views, &partial, 319.5, 239.5).expect("stage 2");
        assert!((f - 900.0).abs() < 1e-7, "f {f} px");
        for (want, got) in scene.camera_from_target.iter().zip(&poses) {
            let p = Point3::new(0.1, 0.05, 0.0);
            assert!(((want * p) - (got * p)).norm() < 1e-9, "m");
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn non_planar_points_are_refused() {
        let truth = tsai_camera();
        let mut scene = Scene::calibration(5, &truth, (9, 6), 0.03, 3, 0.0).expect("scene");
        scene.views[1].object_m[3].z = 0.01;
        let e = calibrate_tsai(&scene.views, (640, 480), &CalibrationOptions::default())
            .expect_err("non-planar");
        assert_eq!(
            e.to_string(),
            "views[view_001].object_m: Tsai's method here is the coplanar case: target points must have z = 0"
        );
    }
}
