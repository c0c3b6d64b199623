//! Seeded synthetic calibration scenes: a planar grid target seen by a
//! known camera from random poses, with exact ground truth.

use super::Rng;
use crate::calib::View;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{rotation_from_rotvec, Pose};
use nalgebra::{Point2, Point3, Translation3, Vector3};

/// Largest tilt of the target away from facing the camera, radians (45 deg).
const MAX_TILT: f64 = std::f64::consts::FRAC_PI_4;
/// Fraction of the image width the target spans, drawn per view.
const SPAN_RANGE: (f64, f64) = (0.35, 0.6);
/// Margin kept between every projected point and the image border, px.
const BORDER_MARGIN_PX: f64 = 2.0;
/// Random poses tried per view before giving up.
const MAX_ATTEMPTS: usize = 1000;

/// A synthetic scene with its ground truth.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The true camera.
    pub camera: Camera,
    /// Target points in the target frame (z = 0), metres, row by row.
    pub target_points_m: Vec<Point3<f64>>,
    /// True pose of the target in each view.
    pub camera_from_target: Vec<Pose>,
    /// Observations: target points and their (noisy) pixels, per view.
    pub views: Vec<View>,
    /// Standard deviation of the Gaussian noise added to each pixel coordinate.
    pub noise_px: f64,
}

impl Scene {
    /// `n_views` views of a `cols x rows` grid target with `pitch_m` spacing,
    /// each pose random (tilt up to 45 deg, target spanning 35-60 % of the
    /// image width, anywhere in the image) with every point at least 2 px
    /// inside the image; pixel noise N(0, noise_px^2) per coordinate.
    pub fn calibration(
        seed: u64,
        camera: &Camera,
        grid: (usize, usize),
        pitch_m: f64,
        n_views: usize,
        noise_px: f64,
    ) -> Result<Scene> {
        let (cols, rows) = grid;
        if cols < 2 || rows < 2 || !(pitch_m > 0.0) || !(noise_px >= 0.0) {
            return Err(Error::invalid(
                "scene",
                format!("needs a grid of at least 2x2, pitch > 0 and noise >= 0, got {cols}x{rows}, {pitch_m} m, {noise_px} px"),
            ));
        }
        let mut rng = Rng::new(seed);
        let target_points_m: Vec<Point3<f64>> = (0..rows)
            .flat_map(|r| {
                (0..cols).map(move |c| Point3::new(c as f64 * pitch_m, r as f64 * pitch_m, 0.0))
            })
            .collect();
        let mut scene = Scene {
            camera: camera.clone(),
            target_points_m,
            camera_from_target: vec![],
            views: vec![],
            noise_px,
        };
        for v in 0..n_views {
            let (pose, pixels) = scene.random_view(&mut rng, grid, pitch_m)?;
            let image_px = pixels
                .iter()
                .map(|p| Point2::new(p.x + rng.gaussian(noise_px), p.y + rng.gaussian(noise_px)))
                .collect();
            scene.views.push(View {
                name: format!("view_{v:03}"),
                object_m: scene.target_points_m.clone(),
                image_px,
                point_ids: Vec::new(),
            });
            scene.camera_from_target.push(pose);
        }
        Ok(scene)
    }

    fn random_view(
        &self,
        rng: &mut Rng,
        grid: (usize, usize),
        pitch_m: f64,
    ) -> Result<(Pose, Vec<Point2<f64>>)> {
        let camera = &self.camera;
        let (w, h) = (camera.width as f64, camera.height as f64);
        let board_w = (grid.0 - 1) as f64 * pitch_m;
        let centre_target = Vector3::new(board_w / 2.0, (grid.1 - 1) as f64 * pitch_m / 2.0, 0.0);
        for _ in 0..MAX_ATTEMPTS {
            let span = rng.range(SPAN_RANGE.0, SPAN_RANGE.1);
            let distance = camera.fx * board_w / (span * w);
            let aim = Point2::new(rng.range(0.15 * w, 0.85 * w), rng.range(0.15 * h, 0.85 * h));
            let Ok(ray) = camera.unproject(&aim) else {
                continue;
            };
            let axis_angle = rng.range(0.0, 2.0 * std::f64::consts::PI);
            let tilt = rng.range(0.0, MAX_TILT);
            let tilt_axis = Vector3::new(axis_angle.cos(), axis_angle.sin(), 0.0) * tilt;
            let spin = Vector3::new(0.0, 0.0, rng.range(-0.5, 0.5));
            let rotation = rotation_from_rotvec(&tilt_axis) * rotation_from_rotvec(&spin);
            let centre_camera = ray * distance;
            let t = centre_camera - rotation * centre_target;
            let pose = Pose::from_parts(Translation3::from(t), rotation);
            let pixels: Option<Vec<Point2<f64>>> = self
                .target_points_m
                .iter()
                .map(|p| camera.project(&(pose * p)).ok())
                .collect();
            let inside = |p: &Point2<f64>| {
                p.x >= BORDER_MARGIN_PX
                    && p.y >= BORDER_MARGIN_PX
                    && p.x <= w - 1.0 - BORDER_MARGIN_PX
                    && p.y <= h - 1.0 - BORDER_MARGIN_PX
            };
            if let Some(pixels) = pixels {
                if pixels.iter().all(inside) {
                    return Ok((pose, pixels));
                }
            }
        }
        Err(Error::degenerate(format!(
            "no pose in {MAX_ATTEMPTS} tries keeps the {}x{} target inside the image",
            grid.0, grid.1
        )))
    }
}
