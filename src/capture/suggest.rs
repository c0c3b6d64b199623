//! The next pose to show the user, and when to stop: a coverage rule before
//! a calibration exists, then the candidate pose that most reduces the
//! predicted projection uncertainty of the current calibration.
//!
//! Candidates: the board aimed at 3 x 3 points of the image (a quarter,
//! half and three quarters of each side), tilted by -25, 0 or 25 degrees
//! about each image axis, at spans of 0.3, 0.45 and 0.65 image widths (far,
//! middle, near), each fitted inside the image (243 poses, fewer where the
//! board cannot fit).
//!
//! Coverage rule: the candidate whose signature adds the most, scored 100
//! for a tilt bin without kept frames, 50 for an empty distance bin, plus 1
//! per empty image cell it would cover; the first in the order above wins
//! ties (frontal before tilted, far before near).
//!
//! Uncertainty rule: each candidate's points are added to the normal
//! equations of the calibration (their Jacobians in the free camera
//! parameters, the candidate's own pose eliminated by its Schur complement,
//! weighted by the calibration's residual variance), and the candidate
//! whose predicted worst projection uncertainty over the image (the
//! report's 9 x 7 grid, at its reference depth) is the smallest wins.
//!
//! Good enough: a calibration of at least [`GOOD_MIN_VIEWS`] views whose
//! parameters are all determined and whose worst projection uncertainty is
//! below [`GOOD_MAX_STD_PX`].
//!
//! The same prediction judges a still, sharp frame once a calibration
//! exists and is not good enough: the frame's own points at its pose
//! (through the calibrated camera) added to the normal equations; it adds
//! information when the predicted worst projection uncertainty is at least
//! [`LOWERS_UNCERTAINTY_BY`] below the calibration's, unless it repeats a
//! kept view ([`SAME_VIEW_PX`]). So the guide keeps capturing views that
//! help after the coverage bins are full, and stops once good enough.

use super::coverage::{cell_counts, signature, Coverage, Signature};
use crate::calib::CameraCalibration;
use crate::camera::Camera;
use crate::geometry::{Pose, PoseJson};
use crate::target::placement::{board_side_m, fitted_pose, print_outline};
use crate::target::Target;
use nalgebra::{DMatrix, Matrix3, Point2, Point3, SymmetricEigen, UnitQuaternion, Vector3};
use serde::Serialize;

/// Aims of the candidates, fractions of the image width and height.
pub const CANDIDATE_AIMS: [f64; 3] = [0.25, 0.5, 0.75];
/// Tilts of the candidates about each image axis, degrees.
pub const CANDIDATE_TILTS_DEG: [f64; 3] = [0.0, -25.0, 25.0];
/// Spans of the candidates (far, middle, near), image widths.
pub const CANDIDATE_SPANS: [f64; 3] = [0.3, 0.45, 0.65];
/// Good enough: the worst projection uncertainty over the image, px.
pub const GOOD_MAX_STD_PX: f64 = 0.2;
/// Good enough: the fewest views.
pub const GOOD_MIN_VIEWS: usize = 8;
/// Under a running calibration that is not good enough, a frame adds
/// information when adding it would lower the predicted worst projection
/// uncertainty by at least this fraction (module docs).
pub const LOWERS_UNCERTAINTY_BY: f64 = 0.05;
/// A frame whose points all lie within this many pixels of the same points
/// of a kept frame is that view again: it never lowers the uncertainty
/// (its pixels are the same measurement, not a new one).
pub const SAME_VIEW_PX: f64 = 3.0;

/// A pose the guide may suggest.
#[derive(Debug, Clone)]
pub struct Candidate {
    /// The board's pose.
    pub camera_from_target: Pose,
    /// What it would cover.
    pub signature: Signature,
    /// Its print's outline in the image.
    pub outline_px: [[f64; 2]; 4],
}

/// Which rule chose a suggestion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Rule {
    /// The coverage rule (no calibration yet).
    Coverage,
    /// The predicted uncertainty of the current calibration.
    Uncertainty,
}

/// The next pose to show: the board outline the user should match.
#[derive(Debug, Clone, Serialize)]
pub struct Suggestion {
    /// The rule that chose it.
    pub rule: Rule,
    /// The corners of the board's print in the image, px, in the order of
    /// the board's corners (origin corner first, then along x).
    pub outline_px: [[f64; 2]; 4],
    /// The suggested pose.
    pub camera_from_target: PoseJson,
    /// Its tilt about the image x axis, degrees.
    pub tilt_x_deg: f64,
    /// Its tilt about the image y axis, degrees.
    pub tilt_y_deg: f64,
    /// Its span (board side over image width when facing the camera).
    pub span: f64,
    /// With the uncertainty rule: the predicted worst projection
    /// uncertainty after adding it, px.
    pub predicted_max_std_px: Option<f64>,
    /// One sentence for the user.
    pub why: String,
}

/// Every candidate that fits inside the image through `camera`.
pub fn candidates(camera: &Camera, target: &Target) -> Vec<Candidate> {
    let side = board_side_m(target);
    let print = print_outline(target);
    let (w, h) = (camera.width as f64, camera.height as f64);
    let mut out = Vec::new();
    for span in CANDIDATE_SPANS {
        for tx in CANDIDATE_TILTS_DEG {
            for ty in CANDIDATE_TILTS_DEG {
                for v in CANDIDATE_AIMS {
                    for u in CANDIDATE_AIMS {
                        let rotation =
                            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), tx.to_radians())
                                * UnitQuaternion::from_axis_angle(
                                    &Vector3::y_axis(),
                                    ty.to_radians(),
                                );
                        let aim = Point2::new(u * w, v * h);
                        let Ok(pose) = fitted_pose(camera, target, &aim, rotation, span) else {
                            continue;
                        };
                        let Some(pixels) = project_all(camera, target, &pose) else {
                            continue;
                        };
                        let corners: Option<Vec<Point2<f64>>> = print
                            .iter()
                            .map(|p| camera.project(&(pose * p)).ok())
                            .collect();
                        let Some(c) = corners else { continue };
                        out.push(Candidate {
                            camera_from_target: pose,
                            signature: signature(&pixels, &pose, camera, side),
                            outline_px: [0, 1, 2, 3].map(|i| [c[i].x, c[i].y]),
                        });
                    }
                }
            }
        }
    }
    out
}

fn project_all(camera: &Camera, target: &Target, pose: &Pose) -> Option<Vec<Point2<f64>>> {
    target
        .object_points()
        .iter()
        .map(|(_, p)| camera.project(&(pose * p)).ok())
        .collect()
}

/// The coverage rule's choice (see the module docs).
pub fn by_coverage(candidates: &[Candidate], coverage: &Coverage) -> Option<Suggestion> {
    let score = |c: &Candidate| {
        let n = coverage.novelty(&c.signature);
        100 * n.new_tilt as usize + 50 * n.new_distance as usize + n.new_cells
    };
    let mut best: Option<(&Candidate, usize)> = None;
    for c in candidates {
        let s = score(c);
        if best.map_or(true, |(_, b)| s > b) {
            best = Some((c, s));
        }
    }
    best.map(|(c, _)| {
        let n = coverage.novelty(&c.signature);
        let why = if n.new_tilt {
            "a tilt not captured yet"
        } else if n.new_distance {
            "a distance not captured yet"
        } else if n.new_cells > 0 {
            "a region of the image not covered yet"
        } else {
            "every bin has a view: any varied pose helps"
        };
        suggestion(
            c,
            Rule::Coverage,
            None,
            format!("match this outline: {why}"),
        )
    })
}

fn suggestion(c: &Candidate, rule: Rule, predicted: Option<f64>, why: String) -> Suggestion {
    Suggestion {
        rule,
        outline_px: c.outline_px,
        camera_from_target: PoseJson::from(&c.camera_from_target),
        tilt_x_deg: c.signature.tilt_x_deg,
        tilt_y_deg: c.signature.tilt_y_deg,
        span: c.signature.span,
        predicted_max_std_px: predicted,
        why,
    }
}

/// Whether `calibration` of `views` views is good enough (module docs).
pub fn good_enough(calibration: &CameraCalibration, views: usize) -> bool {
    views >= GOOD_MIN_VIEWS
        && !calibration.std.is_empty()
        && calibration.projection_uncertainty.max_std_px < GOOD_MAX_STD_PX
}

/// The calibration's normal equations on its free parameters, ready to
/// predict the worst projection uncertainty after adding a view.
pub struct Predictor<'a> {
    camera: &'a Camera,
    free: Vec<usize>,
    info: DMatrix<f64>,
    variance: f64,
    depth: f64,
    params: usize,
}

impl<'a> Predictor<'a> {
    /// `None` when the calibration's parameters are not all reported
    /// (no covariance to start from).
    pub fn new(calibration: &'a CameraCalibration) -> Option<Predictor<'a>> {
        let camera = &calibration.camera;
        let names = camera.param_names();
        let std: Vec<f64> = names
            .iter()
            .map(|n| calibration.std.get(*n).copied().unwrap_or(0.0))
            .collect();
        let corr = &calibration.correlation.matrix;
        if corr.len() != names.len() {
            return None;
        }
        let free: Vec<usize> = (0..names.len()).filter(|i| std[*i] > 0.0).collect();
        let m = free.len();
        let cov = DMatrix::from_fn(m, m, |a, b| {
            corr[free[a]][free[b]] * std[free[a]] * std[free[b]]
        });
        Some(Predictor {
            camera,
            info: pseudo_inverse(&cov),
            free,
            variance: calibration.rms_px.powi(2).max(1e-12),
            depth: calibration.projection_uncertainty.reference_depth_m,
            params: names.len(),
        })
    }

    /// The worst projection uncertainty over the image (px) after adding a
    /// view of the board points `object_m` (target frame) at `pose`;
    /// `None` when they fix no pose.
    pub fn with_view(&self, object_m: &[Point3<f64>], pose: &Pose) -> Option<f64> {
        let added = schur_information(self.camera, object_m, pose, &self.free)?;
        let cov_free = pseudo_inverse(&(&self.info + added / self.variance));
        let mut full = DMatrix::zeros(self.params, self.params);
        for (a, i) in self.free.iter().enumerate() {
            for (b, j) in self.free.iter().enumerate() {
                full[(*i, *j)] = cov_free[(a, b)];
            }
        }
        Some(crate::calib::projection_uncertainty(self.camera, &full, self.depth).max_std_px)
    }
}

/// The uncertainty rule's choice (module docs); `None` when the
/// calibration's parameters are not all determined.
pub fn by_uncertainty(
    candidates: &[Candidate],
    calibration: &CameraCalibration,
    target: &Target,
) -> Option<Suggestion> {
    let predictor = Predictor::new(calibration)?;
    let object_m: Vec<Point3<f64>> = target.object_points().into_iter().map(|p| p.1).collect();
    let mut best: Option<(&Candidate, f64)> = None;
    for c in candidates {
        let Some(worst) = predictor.with_view(&object_m, &c.camera_from_target) else {
            continue;
        };
        if best.map_or(true, |(_, b)| worst < b) {
            best = Some((c, worst));
        }
    }
    best.map(|(c, worst)| {
        let now = calibration.projection_uncertainty.max_std_px;
        let why = format!(
            "match this outline: the worst projection uncertainty would go from {now:.3} px to {worst:.3} px"
        );
        suggestion(c, Rule::Uncertainty, Some(worst), why)
    })
}

/// The information a view of the board points `object_m` at `pose` adds
/// on the free camera parameters (columns `free` of the camera's parameter
/// Jacobian), its own pose eliminated: `Hcc - Hcp Hpp^-1 Hpc`, unit pixel
/// weights.
fn schur_information(
    camera: &Camera,
    object_m: &[Point3<f64>],
    pose: &Pose,
    free: &[usize],
) -> Option<DMatrix<f64>> {
    let m = free.len();
    let mut hcc = DMatrix::<f64>::zeros(m, m);
    let mut hcp = DMatrix::<f64>::zeros(m, 6);
    let mut hpp = DMatrix::<f64>::zeros(6, 6);
    for p in object_m {
        let pc = pose * p;
        let (_, d_point, d_params) = camera.project_with_jacobians(&pc).ok()?;
        // d pc / d (rotation perturbation, translation): [-[pc]x | I].
        let skew = Matrix3::new(0.0, -pc.z, pc.y, pc.z, 0.0, -pc.x, -pc.y, pc.x, 0.0);
        let mut jp = DMatrix::<f64>::zeros(2, 6);
        let jr = d_point * (-skew);
        for r in 0..2 {
            for k in 0..3 {
                jp[(r, k)] = jr[(r, k)];
                jp[(r, 3 + k)] = d_point[(r, k)];
            }
        }
        let jc = DMatrix::from_fn(2, m, |r, k| d_params[(r, free[k])]);
        hcc += jc.transpose() * &jc;
        hcp += jc.transpose() * &jp;
        hpp += jp.transpose() * &jp;
    }
    let hpp_inv = hpp.try_inverse()?;
    Some(&hcc - &hcp * hpp_inv * hcp.transpose())
}

/// Moore-Penrose inverse of a symmetric positive semi-definite matrix
/// (eigenvalues below 1e-12 of the largest are dropped).
fn pseudo_inverse(a: &DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    if n == 0 {
        return a.clone();
    }
    let eig = SymmetricEigen::new(a.clone());
    let top = eig.eigenvalues.amax();
    let mut out = DMatrix::zeros(n, n);
    for (k, l) in eig.eigenvalues.iter().enumerate() {
        if *l > top * 1e-12 && *l > 0.0 {
            let v = eig.eigenvectors.column(k);
            out += (v * v.transpose()) / *l;
        }
    }
    out
}

/// Points per cell a candidate would add (for tests and display).
pub fn candidate_cells(camera: &Camera, target: &Target, c: &Candidate) -> Vec<usize> {
    project_all(camera, target, &c.camera_from_target)
        .map(|p| cell_counts(&p, camera.width, camera.height))
        .unwrap_or_default()
}
