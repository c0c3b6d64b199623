//! Laser-line sensors (`robocal laser`): the laser plane from images of a
//! board with the stripe on it, and a stripe image turned into 3-D points.
//!
//! [`laser_plane`]: per image pair (the board image with the laser off and
//! the stripe image with it on; or one image showing both), the board is
//! detected, its pose found by PnP with the calibrated camera, the stripe
//! extracted (the laser-off image subtracted when given), its centres on
//! the board kept (inside the detected corners' hull) and met with the
//! board plane; the plane is fitted to those points ([`crate::laser::fit`]).
//! [`laser_points`]: a stripe image and a plane to points in the camera
//! frame (and flange and base frames given the mounting and robot pose).

use crate::calib::{pnp, View};
use crate::camera::Camera;
use crate::detect::{detect, DetectOptions};
use crate::error::{Error, Result};
use crate::geometry::{Pose, PoseJson};
use crate::image::GrayImage;
use crate::laser::fit::ImageResidual;
use crate::laser::points::{profile_points, ProfilePoint};
use crate::laser::{
    extract_stripe, fit_plane, LaserPlane, PlaneFitOptions, PlaneResidual, ScanAxis,
    StripeObservation, StripeOptions,
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
    /// The residual variance that scaled the covariance.
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
    if views.len() < 2 {
        return Err(Error::too_few(
            "board poses (images or pairs)",
            2,
            views.len(),
        ));
    }
    let mut observations = Vec::new();
    let mut images = Vec::new();
    let mut warnings = Vec::new();
    for (index, v) in views.iter().enumerate() {
        let detection = detect(&v.board, target, &settings.detect)
            .map_err(|e| Error::invalid(&v.name, format!("board not found: {e}")))?;
        let view = View::from_detection(v.name.clone(), &detection);
        let (pose, rms) = pnp::camera_from_target(camera, &view)?;
        let (on, off) = match &v.stripe {
            Some(s) => (s, Some(&v.board)),
            None => (&v.board, None),
        };
        let stripe = extract_stripe(on, off, &settings.stripe)
            .map_err(|e| Error::invalid(&v.name, e.to_string()))?;
        let hull = convex_hull(&view.image_px);
        let along_y = stripe.axis == ScanAxis::Columns;
        let mut used = 0;
        for p in &stripe.points {
            let px = Point2::new(p.x_px, p.y_px);
            if !inside(&hull, &px) {
                continue;
            }
            if let Ok(o) = StripeObservation::new(camera, &pose, &px, along_y, p.std_px, index) {
                observations.push(o);
                used += 1;
            }
        }
        if used < 2 {
            warnings.push(format!(
                "{}: {} stripe centres on the board, the image adds nothing",
                v.name, used
            ));
        }
        images.push(LaserImageReport {
            name: v.name.clone(),
            camera_from_target: PoseJson::from(&pose),
            board_rms_px: rms,
            stripe_axis: stripe.axis,
            stripe_points: stripe.points.len(),
            n_points: used,
            rms_px: 0.0,
            rms_mm: 0.0,
            gaps: stripe.gaps.clone(),
        });
    }
    let fit = fit_plane(
        &observations,
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
    Ok(LaserPlaneReport {
        kind: crate::report_kind::ReportKind::LaserPlane.name(),
        robocal_version: crate::VERSION,
        laser_plane: plane_json(&fit),
        residual: settings.residual.name(),
        extractor: settings.stripe.method.name(),
        variance_factor: fit.variance_factor,
        images,
        singular_values_m: fit.singular_values_m,
        warnings,
    })
}

/// The report's plane from a fit.
pub fn plane_json(fit: &crate::laser::PlaneFit) -> LaserPlaneJson {
    let c = fit.covariance;
    let t = fit.tangent_covariance;
    LaserPlaneJson {
        normal_camera: fit.plane.normal_camera,
        distance_m: fit.plane.distance_m,
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
    let plane = LaserPlane::new(nalgebra::Vector3::new(n[0], n[1], n[2]), d)?;
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
    /// The plane used.
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
