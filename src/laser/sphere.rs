//! The sensor on the robot from scans of a known object: a sphere of known
//! radius standing still in the robot's base frame, scanned by the
//! laser-line sensor on the flange at several robot poses (issue 40, "the
//! laser plane and camera in the flange frame directly from laser profiles
//! of a known object").
//!
//! Each stripe centre `u` of scan `k` is a 3-D point on the laser plane
//! (camera frame) `p(u) = ray(u) d / (n . ray(u))`, in the base frame
//! `base_from_gripper_k * gripper_from_camera * p(u)`, and lies on the
//! sphere: the residual is its distance to the centre `c` minus the radius,
//! in metres. One Levenberg-Marquardt refines twelve numbers together: the
//! laser plane in the camera frame (two tilt angles of its normal and its
//! distance, around the start plane), the mounting `gripper_from_camera`
//! (a right perturbation, rotation vector then translation, around the
//! start mounting) and the sphere's centre in the base frame. The camera's
//! intrinsics are held (calibrate them first). The covariance is a
//! sandwich over the residuals with neighbouring centres' errors
//! correlated (Newey-West, [`sandwich_covariance`]).
//!
//! Why the twelve numbers are determined: with the intrinsics known, the
//! map from pixels to the plane fixes the camera's pose relative to the
//! plane up to the plane's own three in-plane motions, and those are fixed
//! by the mounting; the known radius fixes the scale (the plane's
//! distance). The robot must turn between scans (about at least two
//! different axes) and the plane must cut the sphere at different heights;
//! a rank-deficient problem is an error that says so.
//!
//! Starting values: the mounting from the design drawing or a hand-eye
//! calibration, the plane from `laser plane` or the design; they need to be
//! within a few millimetres and degrees. The centre starts where the start
//! values put the points: a least-squares sphere of the known radius.

use super::covariance::newey_west;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{pose_from_params, tangent_basis, Plane, PlaneEstimate, Pose};
use crate::optim::{self, BlockParams, BlockProblem, LmOptions, ResidualBlock};
use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Point2, Point3, Rotation3, Vector3, Vector4};

/// One scan: the robot's pose and the stripe centres on the sphere.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereScan {
    /// The flange's pose in the base frame for this scan.
    pub base_from_gripper: Pose,
    /// Stripe centres on the sphere, pixels.
    pub pixels: Vec<Point2<f64>>,
}

/// The result of [`calibrate_on_sphere`].
#[derive(Debug, Clone)]
pub struct SphereCalibration {
    /// The laser plane in the camera frame with its covariance.
    pub plane_camera: PlaneEstimate,
    /// The camera's mounting on the flange.
    pub gripper_from_camera: Pose,
    /// Covariance of the mounting's right perturbation (rotation vector
    /// rad, then translation m).
    pub gripper_from_camera_covariance: Matrix6<f64>,
    /// The laser plane in the flange frame, its covariance from the joint
    /// estimate (plane and mounting are correlated).
    pub plane_flange: PlaneEstimate,
    /// The sphere's centre in the base frame, m.
    pub centre_base: Point3<f64>,
    /// Its covariance, m^2.
    pub centre_covariance: Matrix3<f64>,
    /// RMS of the points' distance to the sphere, m, over all scans.
    pub rms_m: f64,
    /// The same per scan.
    pub scan_rms_m: Vec<f64>,
    /// Points used.
    pub n_points: usize,
    /// Levenberg-Marquardt iterations.
    pub iterations: usize,
}

/// The twelve numbers around the start values: plane `(a, b, d)`, mounting
/// perturbation `(w, v)`, centre.
const N_PARAMS: usize = 12;

struct Problem<'a> {
    rays: Vec<Vec<Vector3<f64>>>,
    scans: &'a [SphereScan],
    radius_m: f64,
    start_plane: Plane,
    start_mount: Pose,
}

impl Problem<'_> {
    fn plane(&self, p: &[f64]) -> Plane {
        let (e1, e2) = tangent_basis(&self.start_plane.normal);
        let turn = Rotation3::from_scaled_axis(e1 * p[0] + e2 * p[1]);
        Plane {
            normal: turn * self.start_plane.normal,
            distance_m: p[2],
        }
    }

    fn mount(&self, p: &[f64]) -> Pose {
        self.start_mount * pose_from_params(&p[3..9])
    }

    /// Every scan's residuals at `p`; `None` when a ray misses the plane.
    fn residuals(&self, p: &[f64]) -> Option<Vec<DVector<f64>>> {
        let plane = self.plane(p);
        let mount = self.mount(p);
        let centre = Vector3::new(p[9], p[10], p[11]);
        let mut out = Vec::with_capacity(self.scans.len());
        for (scan, rays) in self.scans.iter().zip(&self.rays) {
            let base_from_camera = scan.base_from_gripper * mount;
            let mut r = DVector::zeros(rays.len());
            for (i, ray) in rays.iter().enumerate() {
                let x = plane.intersect_ray(ray)?;
                r[i] = ((base_from_camera * x).coords - centre).norm() - self.radius_m;
            }
            out.push(r);
        }
        Some(out)
    }
}

/// Central-difference steps: 1e-7 rad for angles, 1e-7 m for lengths (the
/// residuals are smooth; the Jacobian's relative error is ~1e-7).
const STEP: f64 = 1e-7;

impl BlockProblem for Problem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let p = &params.global;
        let missed = || Error::degenerate("a stripe centre's ray does not meet the laser plane");
        let r0 = self.residuals(p).ok_or_else(missed)?;
        let mut jac: Vec<DMatrix<f64>> = r0
            .iter()
            .map(|r| DMatrix::zeros(r.len(), if jacobians { N_PARAMS } else { 0 }))
            .collect();
        if jacobians {
            for j in 0..N_PARAMS {
                let mut plus = p.clone();
                let mut minus = p.clone();
                plus[j] += STEP;
                minus[j] -= STEP;
                let rp = self.residuals(&plus).ok_or_else(missed)?;
                let rm = self.residuals(&minus).ok_or_else(missed)?;
                for (k, m) in jac.iter_mut().enumerate() {
                    m.set_column(j, &((&rp[k] - &rm[k]) / (2.0 * STEP)));
                }
            }
        }
        Ok(r0
            .into_iter()
            .zip(jac)
            .map(|(residuals, jac_global)| ResidualBlock {
                block: None,
                residuals,
                jac_global,
                jac_block: DMatrix::zeros(0, 0),
            })
            .collect())
    }
}

/// The twelve numbers' covariance at the solution: the sandwich `A^-1 B
/// A^-1` (`A = J^T J`) whose middle sums each centre's `J_k r_k` with its
/// neighbours' along the scan's stripe (Newey-West, as the plane fit's
/// [`super::covariance`]), times `m / (m - 12)`. Neighbouring centres err
/// alike (the extractor's systematic error over a stretch of the stripe),
/// so `s^2 (J^T J)^-1`, which takes them as independent, was 1.5 times
/// too narrow in std over robot poses moved a little between runs
/// (BENCHMARKS.md section 18, s27). `None` when `A` is singular.
fn sandwich_covariance(problem: &Problem, params: &BlockParams) -> Result<Option<DMatrix<f64>>> {
    let blocks = problem.residuals_and_jacobian(params, true)?;
    let mut a = DMatrix::zeros(N_PARAMS, N_PARAMS);
    let mut meat = DMatrix::zeros(N_PARAMS, N_PARAMS);
    let mut m = 0usize;
    for b in &blocks {
        a += b.jac_global.transpose() * &b.jac_global;
        let g: Vec<DVector<f64>> = (0..b.residuals.len())
            .map(|k| b.jac_global.row(k).transpose() * b.residuals[k])
            .collect();
        meat += newey_west(&g, N_PARAMS);
        m += b.residuals.len();
    }
    let Some(inv) = a.try_inverse() else {
        return Ok(None);
    };
    let scale = if m > N_PARAMS {
        m as f64 / (m - N_PARAMS) as f64
    } else {
        1.0
    };
    let c = &inv * meat * &inv * scale;
    Ok(Some(0.5 * (&c + c.transpose())))
}

/// The least-squares sphere of known `radius_m` through `points`: the
/// algebraic fit `2 p . c - k = |p|^2` for a start, then Gauss-Newton on
/// `|p - c| - r` with the radius held.
fn sphere_centre(points: &[Vector3<f64>], radius_m: f64) -> Option<Vector3<f64>> {
    let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    let mut ata = nalgebra::Matrix4::<f64>::zeros();
    let mut atb = Vector4::zeros();
    for p in points {
        let q = p - mean;
        let row = Vector4::new(2.0 * q.x, 2.0 * q.y, 2.0 * q.z, -1.0);
        ata += row * row.transpose();
        atb += row * q.norm_squared();
    }
    // Near-coplanar points leave the algebraic fit loose: fall back to
    // the mean, pushed back by the radius along the spread's normal.
    let mut c = match ata.try_inverse() {
        Some(inv) => {
            let s = inv * atb;
            mean + Vector3::new(s[0], s[1], s[2])
        }
        None => mean,
    };
    for _ in 0..50 {
        let mut jtj = Matrix3::zeros();
        let mut jtr = Vector3::zeros();
        for p in points {
            let d = p - c;
            let n = d.norm();
            if n < 1e-12 {
                continue;
            }
            let j = -d / n;
            jtj += j * j.transpose();
            jtr += j * (n - radius_m);
        }
        let step = jtj.try_inverse()? * jtr;
        c -= step;
        if step.norm() < 1e-12 {
            break;
        }
    }
    c.iter().all(|v| v.is_finite()).then_some(c)
}

/// The laser plane and the camera on the flange from scans of a sphere of
/// `radius_m` (see the module doc). `start_plane` (camera frame) and
/// `start_mount` (`gripper_from_camera`) are the starting values.
pub fn calibrate_on_sphere(
    camera: &Camera,
    scans: &[SphereScan],
    radius_m: f64,
    start_plane: &Plane,
    start_mount: &Pose,
) -> Result<SphereCalibration> {
    if !(radius_m.is_finite() && radius_m > 0.0) {
        return Err(Error::invalid(
            "radius_m",
            format!("the sphere's radius must be > 0 m, got {radius_m}"),
        ));
    }
    let used: Vec<&SphereScan> = scans.iter().filter(|s| s.pixels.len() >= 3).collect();
    if used.len() < 3 {
        return Err(Error::invalid(
            "scans",
            format!(
                "{} scans with 3 or more stripe points on the sphere: at least 3 are needed, \
                 from robot poses turned about different axes",
                used.len()
            ),
        ));
    }
    let scans: Vec<SphereScan> = used.into_iter().cloned().collect();
    let rays = scans
        .iter()
        .map(|s| {
            s.pixels
                .iter()
                .map(|u| camera.unproject(u))
                .collect::<Result<Vec<_>>>()
        })
        .collect::<Result<Vec<_>>>()?;
    let problem = Problem {
        rays,
        scans: &scans,
        radius_m,
        start_plane: *start_plane,
        start_mount: *start_mount,
    };
    let mut start = vec![0.0; N_PARAMS];
    start[2] = start_plane.distance_m;
    let mut base_points = Vec::new();
    for (scan, rays) in scans.iter().zip(&problem.rays) {
        let base_from_camera = scan.base_from_gripper * start_mount;
        for ray in rays {
            let x = start_plane.intersect_ray(ray).ok_or_else(|| {
                Error::degenerate("a stripe centre's ray does not meet the start laser plane")
            })?;
            base_points.push((base_from_camera * x).coords);
        }
    }
    let centre = sphere_centre(&base_points, radius_m)
        .ok_or_else(|| Error::degenerate("no sphere fits the start points"))?;
    start[9..12].copy_from_slice(centre.as_slice());
    let initial = BlockParams {
        global: start,
        blocks: vec![],
    };
    let options = LmOptions {
        cost_tolerance: 1e-14,
        ..LmOptions::default()
    };
    let result = optim::solve(&problem, &initial, &options)?;
    let undetermined = || {
        Error::degenerate(
            "the scans do not determine the plane and the mounting: turn the robot about \
             different axes between scans and cut the sphere at different heights",
        )
    };
    if result.covariance_global.is_none() {
        return Err(undetermined());
    }
    let covariance = sandwich_covariance(&problem, &result.params)?.ok_or_else(undetermined)?;
    let p = &result.params.global;
    let plane = problem.plane(p);
    let mount = problem.mount(p);
    // The plane's (a, b, d) around the solution: the start basis turned.
    let plane_cov = covariance.fixed_view::<3, 3>(0, 0).into_owned();
    let (e1s, e2s) = tangent_basis(&start_plane.normal);
    let (e1, e2) = tangent_basis(&plane.normal);
    // A small change of (a, b) turns the normal by about that rotation
    // vector in the start basis (the turn so far is a few degrees);
    // expressed in the solution's basis, its part along the normal moves
    // nothing.
    let mut basis = Matrix3::identity();
    for (col, e) in [e1s, e2s].iter().enumerate() {
        basis[(0, col)] = e1.dot(e);
        basis[(1, col)] = e2.dot(e);
    }
    let plane_camera = PlaneEstimate {
        plane,
        covariance: basis * plane_cov * basis.transpose(),
    };
    // The plane in the flange frame from both estimates, the correlation
    // kept: finite differences of its (a, b, d) over the twelve numbers.
    let flange = |q: &[f64]| problem.plane(q).in_frame(&problem.mount(q));
    let at = flange(p);
    let (f1, f2) = tangent_basis(&at.normal);
    let mut jf = DMatrix::zeros(3, N_PARAMS);
    for j in 0..9 {
        let mut plus = p.clone();
        let mut minus = p.clone();
        plus[j] += STEP;
        minus[j] -= STEP;
        let (a, b) = (flange(&plus), flange(&minus));
        let turn = b.normal.cross(&a.normal);
        jf[(0, j)] = f1.dot(&turn) / (2.0 * STEP);
        jf[(1, j)] = f2.dot(&turn) / (2.0 * STEP);
        jf[(2, j)] = (a.distance_m - b.distance_m) / (2.0 * STEP);
    }
    let flange_cov = &jf * &covariance * jf.transpose();
    let residuals = problem
        .residuals(p)
        .ok_or_else(|| Error::degenerate("a stripe centre's ray does not meet the laser plane"))?;
    let rms = |r: &DVector<f64>| (r.norm_squared() / r.len().max(1) as f64).sqrt();
    let n_points: usize = residuals.iter().map(|r| r.len()).sum();
    let total: f64 = residuals.iter().map(|r| r.norm_squared()).sum();
    Ok(SphereCalibration {
        plane_camera,
        gripper_from_camera: mount,
        gripper_from_camera_covariance: covariance.fixed_view::<6, 6>(3, 3).into_owned(),
        plane_flange: PlaneEstimate {
            plane: at,
            covariance: Matrix3::from_fn(|r, c| 0.5 * (flange_cov[(r, c)] + flange_cov[(c, r)])),
        },
        centre_base: Point3::new(p[9], p[10], p[11]),
        centre_covariance: covariance.fixed_view::<3, 3>(9, 9).into_owned(),
        rms_m: (total / n_points.max(1) as f64).sqrt(),
        scan_rms_m: residuals.iter().map(rms).collect(),
        n_points,
        iterations: result.iterations,
    })
}
