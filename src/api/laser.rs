//! Laser-line sensors (`robocal laser`): the laser plane from images of a
//! board with the stripe on it, and a stripe image turned into 3-D points.
//!
//! [`laser_plane`]: per image pair (the board image with the laser off and
//! the stripe image with it on; or one image showing both), the board is
//! detected, its pose found by PnP with the calibrated camera, the stripe
//! extracted (the laser-off image subtracted when given), its centres on
//! the board kept (inside the detected corners' hull) and met with the
//! board plane; the plane is fitted to those points ([`crate::laser::fit`]),
//! its covariance including the board poses' (from their corners' scatter).
//! [`laser_points`]: a stripe image and a plane to points in the camera
//! frame (and flange and base frames given the mounting and robot pose).

use crate::calib::{pnp, View};
use crate::camera::Camera;
use crate::detect::{detect, DetectOptions};
use crate::error::{Error, Result};
use crate::geometry::{Pose, PoseJson};
use crate::image::GrayImage;
use crate::laser::fit::ImageResidual;
use crate::laser::joint::{held_parameters, refine_holding, JointImage};
use crate::laser::points::{profile_points, ProfilePoint};
use crate::laser::{
    extract_stripe, fit_plane_with_boards, plane_in_camera, BoardPose, LaserPlane, PlaneFitOptions,
    PlaneResidual, ScanAxis, StripeObservation, StripeOptions,
};
use crate::target::Target;
use nalgebra::Point2;
use serde::Serialize;

/// One board pose: its image and, for pairs, the stripe image.
pub struct LaserView {
    /// The name carried into the report.
    pub name: String,
    /// The board image (laser off, or the one image with both).
    pub board: GrayImage,
    /// The stripe image (laser on) of a pair; `None`: `board` shows both.
    pub stripe: Option<GrayImage>,
}

/// Settings of [`laser_plane`].
#[derive(Debug, Clone, Default)]
pub struct LaserPlaneSettings {
    /// The fit's error model.
    pub residual: PlaneResidual,
    /// The stripe extractor.
    pub stripe: StripeOptions,
    /// The board detector.
    pub detect: DetectOptions,
}

/// The plane and its uncertainty, as the report writes it.
#[derive(Debug, Clone, Serialize)]
pub struct LaserPlaneJson {
    /// Unit normal, camera frame.
    pub normal_camera: [f64; 3],
    /// Camera centre to plane, metres.
    pub distance_m: f64,
    /// Covariance of `(nx, ny, nz, distance_m)`, row by row.
    pub covariance: [[f64; 4]; 4],
    /// The normal's angular standard deviation (RMS over its two tilt
    /// axes), degrees.
    pub normal_std_deg: f64,
    /// The distance's standard deviation, millimetres.
    pub distance_std_mm: f64,
}

/// One image of the fit.
#[derive(Debug, Clone, Serialize)]
pub struct LaserImageReport {
    /// The name given.
    pub name: String,
    /// The board's pose from its corners.
    pub camera_from_target: PoseJson,
    /// The board pose's reprojection RMS, pixels.
    pub board_rms_px: f64,
    /// Columns or rows.
    pub stripe_axis: ScanAxis,
    /// Stripe centres found / kept on the board.
    pub stripe_points: usize,
    /// Centres used by the fit (on the board).
    pub n_points: usize,
    /// Residual RMS along the scan, pixels.
    pub rms_px: f64,
    /// Point-to-plane RMS, millimetres.
    pub rms_mm: f64,
    /// Gaps in the stripe, `[first, last]` scan lines.
    pub gaps: Vec<[usize; 2]>,
}

/// The laser plane report (`kind`: `laser_plane`).
#[derive(Debug, Clone, Serialize)]
pub struct LaserPlaneReport {
    /// `laser_plane`.
    pub kind: &'static str,
    /// The robocal that wrote it.
    pub robocal_version: &'static str,
    /// The plane.
    pub laser_plane: LaserPlaneJson,
    /// The error model (`image_px` or `point_to_plane`).
    pub residual: &'static str,
    /// The stripe extractor (`cog` or `ridge`).
    pub extractor: &'static str,
    /// The residual variance `chi^2 / (m - 3)` (near 1 when the extractor's
    /// stds are right; the covariance comes from the residuals themselves).
    pub variance_factor: f64,
    /// Per image.
    pub images: Vec<LaserImageReport>,
    /// Singular values of the stripe points' scatter, metres.
    pub singular_values_m: [f64; 3],
    /// Weak geometry and dropped images.
    pub warnings: Vec<String>,
}

/// The laser plane from board images with the stripe.
pub fn laser_plane(
    camera: &Camera,
    target: &Target,
    views: &[LaserView],
    settings: &LaserPlaneSettings,
) -> Result<LaserPlaneReport> {
    let measured = measure(camera, target, views, settings)?;
    Ok(fit_measured(camera, measured, settings)?.0)
}

/// [`laser_plane`] with the camera refined jointly with the plane
/// ([`crate::laser::joint`]: the corners of every board and the stripe
/// centres in one least squares; at least 3 board poses). The report is
/// the plane fitted with the refined camera and board poses; the refined
/// camera is returned beside it.
pub fn laser_plane_refining_camera(
    camera: &Camera,
    target: &Target,
    views: &[LaserView],
    settings: &LaserPlaneSettings,
) -> Result<(LaserPlaneReport, Camera)> {
    let measured = measure(camera, target, views, settings)?;
    let (first, centre_variance, correlation) = fit_measured(camera, measured.clone(), settings)?;
    let start = plane_in_camera(
        nalgebra::Vector3::from(first.laser_plane.normal_camera),
        first.laser_plane.distance_m,
    )?;
    // Each centre's std from the first fit's variance function, widened
    // by its correlation factor: the stripe then carries the information
    // on the plane its correlated errors leave (the corners have unit
    // variance by their own scatter).
    let stripe_std = |s: f64| (centre_variance.variance(s) * correlation).sqrt();
    let images: Vec<JointImage> = measured
        .iter()
        .map(|m| JointImage {
            object_m: m.view.object_m.clone(),
            image_px: m.view.image_px.clone(),
            corner_std_px: m.corner_variance.sqrt().max(1e-3),
            camera_from_target: m.pose,
            stripe: m
                .centres
                .iter()
                .map(|(p, s)| (*p, stripe_std(*s)))
                .collect(),
            scan_along_y: m.along_y,
        })
        .collect();
    let (held, why) = held_parameters(camera);
    let joint = refine_holding(camera, &images, &start, &held)?;
    let mut again = Vec::with_capacity(measured.len());
    for (m, pose) in measured.into_iter().zip(&joint.camera_from_target) {
        again.push(remeasure(&joint.camera, m, pose)?);
    }
    let (mut report, ..) = fit_measured(&joint.camera, again, settings)?;
    report.warnings.push(format!(
        "the camera was refined with the plane: corner RMS {:.3} px (was {:.3} px)",
        joint.corner_rms_px.0, joint.corner_rms_px.1
    ));
    report.warnings.extend(why);
    Ok((report, joint.camera))
}

/// One board pose as measured: the board's corners and pose, the stripe
/// centres on it.
#[derive(Clone)]
struct Measured {
    view: View,
    pose: crate::geometry::Pose,
    rms: f64,
    /// The corners' variance per coordinate, px^2.
    corner_variance: f64,
    /// The pose's covariance per unit corner variance.
    unit_covariance: nalgebra::Matrix6<f64>,
    /// Centres on the board: pixel and std along the scan.
    centres: Vec<(Point2<f64>, f64)>,
    along_y: bool,
    report: LaserImageReport,
}

fn measure(
    camera: &Camera,
    target: &Target,
    views: &[LaserView],
    settings: &LaserPlaneSettings,
) -> Result<Vec<Measured>> {
    if views.len() < 2 {
        return Err(Error::too_few(
            "board poses (images or pairs)",
            2,
            views.len(),
        ));
    }
    let mut out = Vec::with_capacity(views.len());
    for v in views {
        let detection = detect(&v.board, target, &settings.detect)
            .map_err(|e| Error::invalid(&v.name, format!("board not found: {e}")))?;
        let view = View::from_detection(v.name.clone(), &detection);
        let (pose, rms, unit_covariance) = pnp::camera_from_target_with_covariance(camera, &view)?;
        // The corners' variance per coordinate: rms^2 = sum |r|^2 / n over
        // 2 n coordinates less the pose's 6 parameters.
        let n = view.image_px.len() as f64;
        let corner_variance = rms * rms * n / (2.0 * n - 6.0).max(1.0);
        let (on, off) = match &v.stripe {
            Some(s) => (s, Some(&v.board)),
            None => (&v.board, None),
        };
        let stripe = extract_stripe(on, off, &settings.stripe)
            .map_err(|e| Error::invalid(&v.name, e.to_string()))?;
        let hull = convex_hull(&view.image_px);
        let centres: Vec<(Point2<f64>, f64)> = stripe
            .points
            .iter()
            .map(|p| (Point2::new(p.x_px, p.y_px), p.std_px))
            .filter(|(px, _)| inside(&hull, px))
            .collect();
        out.push(Measured {
            report: LaserImageReport {
                name: v.name.clone(),
                camera_from_target: PoseJson::from(&pose),
                board_rms_px: rms,
                stripe_axis: stripe.axis,
                stripe_points: stripe.points.len(),
                n_points: 0,
                rms_px: 0.0,
                rms_mm: 0.0,
                gaps: stripe.gaps.clone(),
            },
            view,
            pose,
            rms,
            corner_variance,
            unit_covariance,
            centres,
            along_y: stripe.axis == ScanAxis::Columns,
        });
    }
    Ok(out)
}

/// A measured board pose with a refined camera and pose: the pose's
/// covariance and corner scatter recomputed, the centres kept.
fn remeasure(camera: &Camera, mut m: Measured, pose: &crate::geometry::Pose) -> Result<Measured> {
    let (_, _, unit_covariance) = pnp::camera_from_target_with_covariance(camera, &m.view)?;
    let n = m.view.image_px.len();
    let mut sum = 0.0;
    for (p, q) in m.view.object_m.iter().zip(&m.view.image_px) {
        sum += (camera.project(&(pose * p))? - q).norm_squared();
    }
    m.rms = (sum / n.max(1) as f64).sqrt();
    m.corner_variance = sum / (2.0 * n as f64 - 6.0).max(1.0);
    m.unit_covariance = unit_covariance;
    m.pose = *pose;
    m.report.camera_from_target = PoseJson::from(pose);
    m.report.board_rms_px = m.rms;
    Ok(m)
}

fn fit_measured(
    camera: &Camera,
    measured: Vec<Measured>,
    settings: &LaserPlaneSettings,
) -> Result<(LaserPlaneReport, crate::laser::CentreVariance, f64)> {
    let mut observations = Vec::new();
    let mut boards = Vec::new();
    let mut images = Vec::new();
    let mut warnings = Vec::new();
    for (index, m) in measured.into_iter().enumerate() {
        boards.push(BoardPose {
            image: index,
            camera_from_target: m.pose,
            covariance: m.unit_covariance * m.corner_variance,
        });
        let mut used = 0;
        for (px, std) in &m.centres {
            if let Ok(o) = StripeObservation::new(camera, &m.pose, px, m.along_y, *std, index) {
                observations.push(o);
                used += 1;
            }
        }
        if used < 2 {
            warnings.push(format!(
                "{}: {} stripe centres on the board, the image adds nothing",
                m.report.name, used
            ));
        }
        let mut report = m.report;
        report.n_points = used;
        images.push(report);
    }
    let fit = fit_plane_with_boards(
        &observations,
        &boards,
        &PlaneFitOptions {
            residual: settings.residual,
        },
    )?;
    for ImageResidual {
        image,
        rms_px,
        rms_mm,
        ..
    } in &fit.per_image
    {
        if let Some(r) = images.get_mut(*image) {
            r.rms_px = *rms_px;
            r.rms_mm = *rms_mm;
        }
    }
    warnings.extend(fit.warnings.iter().cloned());
    let report = LaserPlaneReport {
        kind: crate::report_kind::ReportKind::LaserPlane.name(),
        robocal_version: crate::VERSION,
        laser_plane: plane_json(&fit),
        residual: settings.residual.name(),
        extractor: settings.stripe.method.name(),
        variance_factor: fit.variance_factor,
        images,
        singular_values_m: fit.singular_values_m,
        warnings,
    };
    Ok((report, fit.centre_variance, fit.centre_correlation))
}

/// The report's plane from a fit.
pub fn plane_json(fit: &crate::laser::PlaneFit) -> LaserPlaneJson {
    estimate_json(&fit.estimate)
}

/// The report's plane from an estimate (camera frame).
pub fn estimate_json(estimate: &crate::geometry::PlaneEstimate) -> LaserPlaneJson {
    let c = estimate.normal_distance_covariance();
    let t = estimate.covariance;
    let n = estimate.plane.normal;
    LaserPlaneJson {
        normal_camera: [n.x, n.y, n.z],
        distance_m: estimate.plane.distance_m,
        covariance: std::array::from_fn(|r| std::array::from_fn(|k| c[(r, k)])),
        normal_std_deg: ((t[(0, 0)] + t[(1, 1)]).max(0.0) / 2.0).sqrt().to_degrees(),
        distance_std_mm: t[(2, 2)].max(0.0).sqrt() * 1e3,
    }
}

/// The plane (and its covariance when present) of a laser plane report or
/// of `{"laser_plane": {...}}` / the bare `{"normal_camera", "distance_m"}`.
pub fn plane_from_json(text: &str) -> Result<(LaserPlane, nalgebra::Matrix4<f64>)> {
    let value: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| Error::parse(e.line(), e.column(), format!("laser plane: {e}")))?;
    let p = value.get("laser_plane").unwrap_or(&value);
    let normal: Option<Vec<f64>> = p
        .get("normal_camera")
        .and_then(|n| n.as_array())
        .map(|a| a.iter().filter_map(|v| v.as_f64()).collect());
    let distance = p.get("distance_m").and_then(|d| d.as_f64());
    let (Some(n), Some(d)) = (normal.filter(|n| n.len() == 3), distance) else {
        return Err(Error::invalid(
            "laser_plane",
            "expected {\"laser_plane\": {\"normal_camera\": [nx, ny, nz], \"distance_m\": d}}",
        ));
    };
    let plane = plane_in_camera(nalgebra::Vector3::new(n[0], n[1], n[2]), d)?;
    let mut cov = nalgebra::Matrix4::zeros();
    if let Some(rows) = p.get("covariance").and_then(|c| c.as_array()) {
        for (r, row) in rows.iter().take(4).enumerate() {
            for (k, v) in row.as_array().into_iter().flatten().take(4).enumerate() {
                cov[(r, k)] = v.as_f64().unwrap_or(0.0);
            }
        }
    }
    Ok((plane, cov))
}

/// The profile points report (`kind`: `laser_points`).
#[derive(Debug, Clone, Serialize)]
pub struct LaserPointsReport {
    /// `laser_points`.
    pub kind: &'static str,
    /// The robocal that wrote it.
    pub robocal_version: &'static str,
    /// The plane used (`{"normal_camera", "distance_m"}`).
    #[serde(serialize_with = "crate::laser::plane::serialize_camera_plane")]
    pub laser_plane: LaserPlane,
    /// Columns or rows.
    pub stripe_axis: ScanAxis,
    /// The extractor.
    pub extractor: &'static str,
    /// One per stripe centre.
    pub points: Vec<ProfilePoint>,
    /// Centres whose ray missed the plane.
    pub missed: usize,
    /// Gaps in the stripe.
    pub gaps: Vec<[usize; 2]>,
    /// Ends of the stripe's pieces, pixels.
    pub ends: Vec<[f64; 2]>,
}

/// A stripe image (with its laser-off image when given) to 3-D points.
pub fn laser_points(
    camera: &Camera,
    plane: &LaserPlane,
    stripe_image: &GrayImage,
    off: Option<&GrayImage>,
    options: &StripeOptions,
    gripper_from_camera: Option<&Pose>,
    base_from_gripper: Option<&Pose>,
) -> Result<LaserPointsReport> {
    if (stripe_image.width, stripe_image.height) != (camera.width, camera.height) {
        return Err(Error::invalid(
            "stripe image",
            format!(
                "is {}x{} but the camera is {}x{}",
                stripe_image.width, stripe_image.height, camera.width, camera.height
            ),
        ));
    }
    let stripe = extract_stripe(stripe_image, off, options)?;
    let (points, missed) = profile_points(
        camera,
        plane,
        &stripe,
        gripper_from_camera,
        base_from_gripper,
    )?;
    Ok(LaserPointsReport {
        kind: crate::report_kind::ReportKind::LaserPoints.name(),
        robocal_version: crate::VERSION,
        laser_plane: *plane,
        stripe_axis: stripe.axis,
        extractor: options.method.name(),
        points,
        missed,
        gaps: stripe.gaps,
        ends: stripe.ends,
    })
}

/// The convex hull of the board's pixels (counter-clockwise in image axes).
fn convex_hull(points: &[Point2<f64>]) -> Vec<Point2<f64>> {
    let mut p: Vec<Point2<f64>> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut hull: Vec<Point2<f64>> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Point2<f64>>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for q in iter {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(*q);
        }
        hull.pop();
    }
    hull
}

fn inside(hull: &[Point2<f64>], q: &Point2<f64>) -> bool {
    if hull.len() < 3 {
        return false;
    }
    (0..hull.len()).all(|i| {
        let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
        (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x) >= 0.0
    })
}

#[cfg(test)]
#[path = "laser_cubes_tests.rs"]
mod cube_tests;

#[cfg(test)]
#[path = "laser_joint_tests.rs"]
mod joint_tests;
