//! A laser-line sensor on the robot scanning a calibration sphere: the
//! sphere stands still in the base frame, the robot moves the sensor (a
//! camera and its plane of light, fixed on the flange) to several poses
//! where the plane cuts the sphere at different heights, turned about
//! different axes. Renders each laser image (the stripe on a dark scene, as
//! a filtered profiler camera sees it) with the robot's poses and the true
//! mounting as truth, for [`crate::laser::sphere`].
//!
//! Rendering ([`super::laser_raycast`]): each pixel near the sphere's image
//! is supersampled; a ray's first hit on the sphere is lit when it faces the
//! laser's emitter (a point of the plane, camera frame) and returns `peak
//! exp(-s^2 / (2 sigma^2))` for a point `s` metres off the plane (`sigma`
//! the sheet's half-thickness); then the ambient grey, Gaussian noise,
//! clipped to 0..255.
//!
//! The example sensor ([`example_sensor_camera`], [`example_emitter`],
//! [`example_mounting`], [`example_starts`]) and [`rendered_scans`] (the
//! stripes of the rendered images) serve the sphere tests and
//! `examples/laser_sphere_mc.rs`.

use super::laser_raycast::{render_rays, sheet, Background};
use crate::camera::{Camera, Distortion};
use crate::geometry::{pose_from_params, Pose};
use crate::laser::sphere::SphereScan;
use crate::laser::{extract_stripe, LaserPlane, StripeOptions};
use nalgebra::{Point2, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// The calibration sphere in the base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereScene {
    /// Its centre, base frame, metres.
    pub centre_base: Point3<f64>,
    /// Its radius, metres.
    pub radius_m: f64,
}

/// How the laser image is drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereRenderOptions {
    /// Grey level of the sheet's centre (default 300: the core saturates).
    pub peak: f64,
    /// The sheet's half-thickness (Gaussian sigma), metres (default 0.4 mm).
    pub sigma_m: f64,
    /// Grey level of the unlit scene (default 10).
    pub ambient: f64,
    /// Additive Gaussian noise, grey levels (default 2).
    pub noise_sigma: f64,
    /// Noise seed.
    pub seed: u64,
}

impl Default for SphereRenderOptions {
    fn default() -> Self {
        SphereRenderOptions {
            peak: 300.0,
            sigma_m: 0.0004,
            ambient: 10.0,
            noise_sigma: 2.0,
            seed: 1,
        }
    }
}

/// A sensor mounting for the examples: 120 mm out along the flange's z,
/// offset 30 mm and -50 mm, turned about 70 deg about the flange axis and
/// a little off it.
pub fn example_mounting() -> Pose {
    pose_from_params(&[0.08, -0.12, 1.2, 0.03, -0.05, 0.12])
}

/// The example sensor's camera: 640x480, f = 800 px, a mild barrel
/// (Brown k1 = -0.05, k2 = 0.02).
pub fn example_sensor_camera() -> Camera {
    Camera {
        distortion: Distortion::Brown {
            k1: -0.05,
            k2: 0.02,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
        ..Camera::pinhole(800.0, 800.0, 319.5, 239.5, 640, 480)
    }
}

/// The example emitter: the laser `plane`'s point nearest the camera
/// centre (about 10 cm from it for the example plane, the sensor's
/// baseline), camera frame.
pub fn example_emitter(plane: &LaserPlane) -> Point3<f64> {
    Point3::from(plane.normal.into_inner() * plane.distance_m)
}

/// Start values off the truth for the sphere calibration: the `plane`
/// turned 1 deg and moved 2 mm, the mounting turned 2 deg and moved 5 mm.
pub fn example_starts(plane: &LaserPlane, gripper_from_camera: &Pose) -> (LaserPlane, Pose) {
    let turn = Rotation3::from_scaled_axis(Vector3::new(0.6, 0.8, 0.0) * 1f64.to_radians());
    let start_plane = LaserPlane {
        normal: turn * plane.normal,
        distance_m: plane.distance_m + 0.002,
    };
    let start_mount =
        gripper_from_camera * pose_from_params(&[0.02, -0.025, 0.01, 0.004, -0.003, 0.0]);
    (start_plane, start_mount)
}

/// The example sphere: 60 mm across, 0.8 m in front of the robot base.
pub fn example_sphere() -> SphereScene {
    SphereScene {
        centre_base: Point3::new(0.8, 0.1, 0.2),
        radius_m: 0.03,
    }
}

/// `n` robot poses (`base_from_gripper`) that scan `scene` with the sensor
/// mounted at `gripper_from_camera` and the laser `plane`: the camera looks
/// down at the sphere from about 0.5 m, tilted up to 25 deg about a
/// direction that turns from pose to pose and turned about its optical
/// axis by up to 60 deg; the plane cuts the sphere from 0.6 of its radius
/// below the centre to 0.6 above.
pub fn sphere_scan_poses(
    n: usize,
    scene: &SphereScene,
    gripper_from_camera: &Pose,
    plane: &LaserPlane,
) -> Vec<Pose> {
    let down = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
    (0..n)
        .map(|k| {
            let f = k as f64;
            let a = f * 2.4;
            let tilt = 0.25 + 0.15 * (f * 0.9).sin();
            let yaw = 1.05 * (f * 1.7).sin();
            let turn =
                UnitQuaternion::from_scaled_axis(Vector3::new(tilt * a.cos(), tilt * a.sin(), 0.0))
                    * UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, yaw));
            let r = down * turn;
            // The centre in the camera frame: on the plane's side given
            // by the height, x and depth varied.
            let n_c = plane.normal.into_inner();
            let fraction = if n > 1 {
                -0.6 + 1.2 * f / (n - 1) as f64
            } else {
                0.0
            };
            let height = fraction * scene.radius_m;
            let x = 0.03 * (f * 1.3).cos();
            let z = 0.5 + 0.04 * (f * 2.1).sin();
            let y = (plane.distance_m + height - n_c.x * x - n_c.z * z) / n_c.y;
            let centre_camera = Vector3::new(x, y, z);
            let t = scene.centre_base.coords - r * centre_camera;
            let base_from_camera = Pose::from_parts(Translation3::from(t), r);
            base_from_camera * gripper_from_camera.inverse()
        })
        .collect()
}

/// The laser image of the sphere seen from `base_from_camera`; the laser
/// `plane` and its `emitter` (a point of the plane) in the camera frame.
pub fn render_sphere(
    camera: &Camera,
    base_from_camera: &Pose,
    plane: &LaserPlane,
    emitter: &Point3<f64>,
    scene: &SphereScene,
    options: &SphereRenderOptions,
) -> crate::error::Result<crate::image::GrayImage> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let c = base_from_camera.inverse() * scene.centre_base;
    let r = scene.radius_m;
    // The sphere's image: its centre's projection and a generous radius.
    let centre_px = camera.project(&c)?;
    let reach = 1.6 * camera.fx.max(camera.fy) * r / (c.z - r).max(1e-3) + 4.0;
    let x_range = (centre_px.x - reach).max(0.0) as usize
        ..((centre_px.x + reach).max(0.0) as usize + 1).min(w);
    let y_range = (centre_px.y - reach).max(0.0) as usize
        ..((centre_px.y + reach).max(0.0) as usize + 1).min(h);
    let background = Background {
        ambient: options.ambient,
        noise_sigma: options.noise_sigma,
        seed: options.seed,
    };
    render_rays(
        camera,
        &background,
        |x, y| x_range.contains(&x) && y_range.contains(&y),
        |ray| {
            let Some(p) = first_hit(&ray.normalize(), &c.coords, r) else {
                return 0.0;
            };
            if (emitter.coords - p).dot(&(p - c.coords)) <= 0.0 {
                return 0.0;
            }
            sheet(options.peak, options.sigma_m, plane.signed_distance_m(&p))
        },
    )
}

/// The scans of `scene` from the robot poses `base_from_gripper`: each
/// pose's laser image rendered ([`render_sphere`], default options, the
/// emitter [`example_emitter`], noise seed `first_seed + k` for pose `k`)
/// and its stripe extracted (default [`StripeOptions`]).
pub fn rendered_scans(
    camera: &Camera,
    base_from_gripper: &[Pose],
    gripper_from_camera: &Pose,
    plane: &LaserPlane,
    scene: &SphereScene,
    first_seed: u64,
) -> crate::error::Result<Vec<SphereScan>> {
    let emitter = example_emitter(plane);
    let mut scans = Vec::with_capacity(base_from_gripper.len());
    for (k, b) in base_from_gripper.iter().enumerate() {
        let options = SphereRenderOptions {
            seed: first_seed + k as u64,
            ..SphereRenderOptions::default()
        };
        let base_from_camera = b * gripper_from_camera;
        let image = render_sphere(camera, &base_from_camera, plane, &emitter, scene, &options)?;
        let stripe = extract_stripe(&image, None, &StripeOptions::default())?;
        scans.push(SphereScan {
            base_from_gripper: *b,
            pixels: stripe
                .points
                .iter()
                .map(|p| Point2::new(p.x_px, p.y_px))
                .collect(),
        });
    }
    Ok(scans)
}

/// Where the ray `t dir` (unit `dir`, t > 0) first meets the sphere.
fn first_hit(dir: &Vector3<f64>, centre: &Vector3<f64>, radius: f64) -> Option<Vector3<f64>> {
    let b = dir.dot(centre);
    let disc = b * b - (centre.norm_squared() - radius * radius);
    if disc < 0.0 {
        return None;
    }
    let t = b - disc.sqrt();
    (t > 0.0).then(|| dir * t)
}
