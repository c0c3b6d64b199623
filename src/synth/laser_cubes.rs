//! Seed 003's calibration scene: two small cubes, each with a bore in its
//! top face, on a table, and a laser-line sensor (camera plus plane of
//! light) on the robot's flange. Renders the laser image as the sensor's
//! filtered camera sees it (the stripe on a dark scene) and gives the
//! truth: the control points, where the stripe on a cube's top face ends
//! (at the cube's edges and the bore's rim), in the world (= robot base)
//! frame, as the paper reads them from the robot controller.
//!
//! Rendering ([`super::laser_raycast`]): every pixel is supersampled; each ray
//! meets the nearest of the table (`z = table_z_m`) and the cubes (axis-
//! aligned boxes standing on it); a ray entering a bore is lost (a deep
//! bore returns no light). A surface point `s` metres off the laser plane
//! returns `reflectance peak exp(-s^2 / (2 sigma^2))` with `sigma` the
//! sheet's half-thickness; the tops and the table reflect fully, the
//! cubes' sides dimly (`side_reflectance`: a dark or polished side seen off
//! its mirror angle), so the stripe on a top face ends at its edges as in
//! the paper's image. Laser shadows are not modelled (the table's stripe
//! beside a cube is not a control point). Then Gaussian noise, clipped to
//! 0..255.

use super::laser_raycast::{render_rays, sheet, Background};
use crate::camera::Camera;
use crate::geometry::Pose;
use crate::laser::LaserPlane;
use nalgebra::{Point2, Point3, Vector3};

/// A cube standing on the table, a bore of `bore_diameter_m` through the
/// middle of its top face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cube {
    /// Centre of its footprint, world x y, metres.
    pub centre_m: [f64; 2],
    /// Edge length, metres.
    pub side_m: f64,
    /// Diameter of the bore, metres.
    pub bore_diameter_m: f64,
}

/// The scene: a table and the cubes, in the world (robot base) frame.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeScene {
    /// Height of the table top, metres.
    pub table_z_m: f64,
    /// The cubes.
    pub cubes: Vec<Cube>,
}

impl CubeScene {
    /// Seed 003's objects as Table 1 places them: two 20 mm cubes with 6 mm
    /// bores side by side along world x near (588, 237) mm, their tops at
    /// z = 123.7 mm.
    pub fn seed003() -> CubeScene {
        CubeScene {
            table_z_m: 0.1037,
            cubes: vec![
                Cube {
                    centre_m: [0.600, 0.237],
                    side_m: 0.020,
                    bore_diameter_m: 0.006,
                },
                Cube {
                    centre_m: [0.5735, 0.237],
                    side_m: 0.020,
                    bore_diameter_m: 0.006,
                },
            ],
        }
    }
}

/// The sensor's laser (a plane in the camera frame) and its image.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeRenderOptions {
    /// Grey level of the sheet's centre on a surface (default 600: the
    /// stripe's core saturates).
    pub peak: f64,
    /// The sheet's half-thickness (Gaussian sigma), metres (default 0.2 mm).
    pub sigma_m: f64,
    /// Grey level of the unlit scene (default 10).
    pub ambient: f64,
    /// Reflectance of the cubes' sides relative to their tops (default 0.1).
    pub side_reflectance: f64,
    /// Additive Gaussian noise, grey levels (default 2).
    pub noise_sigma: f64,
    /// Noise seed.
    pub seed: u64,
}

impl Default for CubeRenderOptions {
    fn default() -> Self {
        CubeRenderOptions {
            peak: 600.0,
            sigma_m: 0.0002,
            ambient: 10.0,
            side_reflectance: 0.1,
            noise_sigma: 2.0,
            seed: 1,
        }
    }
}

/// What a ray meets first.
enum Hit {
    /// A point on a face, and whether the face is a cube's side.
    Surface(Point3<f64>, bool),
    Bore,
    Nothing,
}

/// The laser image of `scene` seen from `base_from_camera`, the laser
/// plane `plane` (camera frame).
pub fn render_cubes(
    camera: &Camera,
    base_from_camera: &Pose,
    plane: &LaserPlane,
    scene: &CubeScene,
    options: &CubeRenderOptions,
) -> crate::error::Result<crate::image::GrayImage> {
    let camera_from_base = base_from_camera.inverse();
    let origin = Point3::from(base_from_camera.translation.vector);
    let background = Background {
        ambient: options.ambient,
        noise_sigma: options.noise_sigma,
        seed: options.seed,
    };
    render_rays(
        camera,
        &background,
        |_, _| true,
        |ray| {
            let dir = base_from_camera.rotation * ray;
            match cast(scene, &origin, &dir) {
                Hit::Surface(p, side) => {
                    let s = plane.signed_distance_m(&(camera_from_base * p).coords);
                    let reflectance = if side { options.side_reflectance } else { 1.0 };
                    // (reflectance peak) exp(..), the product's order kept.
                    sheet(reflectance * options.peak, options.sigma_m, s)
                }
                Hit::Bore | Hit::Nothing => 0.0,
            }
        },
    )
}

/// The first thing the ray `origin + t dir` (t > 0) meets.
fn cast(scene: &CubeScene, origin: &Point3<f64>, dir: &Vector3<f64>) -> Hit {
    let mut best = f64::INFINITY;
    let mut hit = Hit::Nothing;
    if dir.z.abs() > 1e-12 {
        let t = (scene.table_z_m - origin.z) / dir.z;
        if t > 0.0 {
            best = t;
            hit = Hit::Surface(origin + dir * t, false);
        }
    }
    for cube in &scene.cubes {
        let half = cube.side_m / 2.0;
        let lo = [
            cube.centre_m[0] - half,
            cube.centre_m[1] - half,
            scene.table_z_m,
        ];
        let hi = [
            cube.centre_m[0] + half,
            cube.centre_m[1] + half,
            scene.table_z_m + cube.side_m,
        ];
        // Slabs: the entry parameter and the face it enters by.
        let (mut t0, mut t1, mut face) = (f64::NEG_INFINITY, f64::INFINITY, 0usize);
        let mut missed = false;
        for k in 0..3 {
            let (o, d) = (origin[k], dir[k]);
            if d.abs() < 1e-15 {
                if o < lo[k] || o > hi[k] {
                    missed = true;
                }
                continue;
            }
            let (a, b) = ((lo[k] - o) / d, (hi[k] - o) / d);
            let (near, far) = if a < b { (a, b) } else { (b, a) };
            if near > t0 {
                t0 = near;
                face = k;
            }
            t1 = t1.min(far);
        }
        if missed || t0 > t1 || t0 <= 0.0 || t0 >= best {
            continue;
        }
        best = t0;
        let p = origin + dir * t0;
        let r = cube.bore_diameter_m / 2.0;
        let in_bore = face == 2
            && (p.x - cube.centre_m[0]).powi(2) + (p.y - cube.centre_m[1]).powi(2) < r * r;
        hit = if in_bore {
            Hit::Bore
        } else {
            Hit::Surface(p, face != 2)
        };
    }
    hit
}

/// The control points of one view: where the laser plane's line on each
/// cube's top face ends (the top face's edges and the bore's rim), world
/// frame, in the order of their image x. Lines that miss a cube or its
/// bore give fewer points.
pub fn control_points(
    base_from_camera: &Pose,
    plane: &LaserPlane,
    scene: &CubeScene,
    camera: &Camera,
) -> Vec<(Point2<f64>, Point3<f64>)> {
    // The laser plane in the world.
    let world = plane.in_frame(base_from_camera);
    let n = world.normal.into_inner();
    let mut out = Vec::new();
    for cube in &scene.cubes {
        let z = scene.table_z_m + cube.side_m;
        // The line {n . p = d, p.z = z}: direction u = n x e_z.
        let u = n.cross(&Vector3::z());
        if u.norm() < 1e-9 {
            continue;
        }
        let u = u.normalize();
        // A point of it: on the top plane, closest to the cube's centre.
        let c = Vector3::new(cube.centre_m[0], cube.centre_m[1], z);
        let m = Vector3::new(n.x, n.y, 0.0);
        let along = (world.distance_m - n.dot(&c)) / m.norm_squared();
        let p0 = c + m * along;
        // Its parameter interval inside the top square.
        let half = cube.side_m / 2.0;
        let (mut s0, mut s1) = (f64::NEG_INFINITY, f64::INFINITY);
        for k in 0..2 {
            let (o, d) = (p0[k] - c[k], u[k]);
            if d.abs() < 1e-15 {
                if o.abs() > half {
                    s0 = f64::INFINITY;
                }
                continue;
            }
            let (a, b) = ((-half - o) / d, (half - o) / d);
            s0 = s0.max(a.min(b));
            s1 = s1.min(a.max(b));
        }
        if s0 >= s1 {
            continue;
        }
        let mut params = vec![s0, s1];
        // The bore: |p0 + s u - c| = r in x y (u is horizontal).
        let r = cube.bore_diameter_m / 2.0;
        let off = p0 - c;
        let b = off.dot(&u);
        let disc = b * b - (off.norm_squared() - r * r);
        if disc > 0.0 {
            let q = disc.sqrt();
            params.push(-b - q);
            params.push(-b + q);
        }
        for s in params {
            let p = Point3::from(p0 + u * s);
            if let Ok(px) = camera.project(&(base_from_camera.inverse() * p)) {
                out.push((px, p));
            }
        }
    }
    out.sort_by(|a, b| a.0.x.total_cmp(&b.0.x));
    out
}
