//! The laser plane from stripe observations on boards of known pose, by
//! least squares, with its covariance, per-image residuals and warnings.
//!
//! Two error models:
//! - [`PlaneResidual::ImagePx`] (the default): each stripe centre's
//!   residual is the distance, along its scan direction in pixels, between
//!   the measured centre and where the plane/board intersection line crosses
//!   that column (row), to first order `(n . X - d) / (n . dX/dv)`, divided
//!   by the centre's std: `sqrt(v(std))`, `v` a non-decreasing function
//!   of the std the extractor reports whose values the residuals of a
//!   first fit with every centre alike give ([`CentreVariance`]: the
//!   extractor's std ranks the centres, it does not give their error's
//!   scale). The noise is in the image, so a far or grazing board, whose
//!   points move by millimetres per pixel, weighs what its pixels are
//!   worth.
//! - [`PlaneResidual::PointToPlane`]: the metric distance of each 3-D point
//!   to the plane, unweighted: the classic total-least-squares plane, which
//!   over-weights far and grazing boards.
//!
//! The plane's parameters are its normal (a rotation vector `a e1 + b e2`
//! about [`tangent_basis`]'s axes) and its distance: the fit is a
//! [`PlaneEstimate`], its covariance over `(a, b, d)`
//! ([`super::covariance`]: the residuals' own scatter, correlations along
//! the stripe included, plus the board poses' uncertainty when given).

use super::covariance::{plane_covariance, BoardPose};
use super::plane::{plane_in_camera, LaserPlane, StripeObservation};
use super::weights::CentreVariance;
use crate::error::{Error, Result};
use crate::geometry::{tangent_basis, Plane, PlaneEstimate};
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

/// The residual the plane fit minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum PlaneResidual {
    /// Pixels along the scan direction, weighted by each centre's std.
    #[default]
    ImagePx,
    /// Metres from each point to the plane, unweighted.
    PointToPlane,
}

impl PlaneResidual {
    /// The name used by the CLI and JSON (`image_px`, `point_to_plane`).
    pub fn name(self) -> &'static str {
        match self {
            PlaneResidual::ImagePx => "image_px",
            PlaneResidual::PointToPlane => "point_to_plane",
        }
    }

    /// From its name; an unknown name is an error naming the choices.
    pub fn from_name(name: &str) -> Result<PlaneResidual> {
        match name {
            "image_px" | "image" => Ok(PlaneResidual::ImagePx),
            "point_to_plane" | "point" => Ok(PlaneResidual::PointToPlane),
            other => Err(Error::invalid(
                "residual",
                format!("unknown residual '{other}' (expected image_px or point_to_plane)"),
            )),
        }
    }
}

/// Settings of [`fit_plane`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlaneFitOptions {
    /// The error model (default: image-space).
    pub residual: PlaneResidual,
}

/// The residuals of one image's stripe.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImageResidual {
    /// The image's index.
    pub image: usize,
    /// Stripe centres used.
    pub n_points: usize,
    /// RMS residual along the scan, pixels (image-space model, unweighted).
    pub rms_px: f64,
    /// RMS point-to-plane distance, millimetres.
    pub rms_mm: f64,
}

/// A fitted laser plane.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneFit {
    /// The plane (camera frame, distance >= 0) and the covariance of its
    /// `(a, b, d)` ([`crate::geometry::plane`]'s convention); the 4x4 over
    /// `(nx, ny, nz, d)` is [`PlaneEstimate::normal_distance_covariance`].
    pub estimate: PlaneEstimate,
    /// The residual variance `chi^2 / (m - 3)` with the extractor's stds
    /// (1 when they are right).
    pub variance_factor: f64,
    /// The error scale every centre has, pixels along the scan: the root
    /// of the smallest variance of [`PlaneFit::centre_variance`] (0 for
    /// the point-to-plane model).
    pub centre_floor_px: f64,
    /// Each centre's variance (px^2 along the scan) as a function of the
    /// std the extractor reported ([`CentreVariance`]).
    pub centre_variance: CentreVariance,
    /// How many times the centres' correlation along the stripe widens
    /// the plane's covariance over independent errors with the variances
    /// of [`PlaneFit::centre_variance`]: the cube root of the ratio of the
    /// determinants of the two (board poses left out), at least 1 (1 for
    /// the point-to-plane model). On renders 1.1-3.1, median 1.85.
    pub centre_correlation: f64,
    /// RMS of the minimised residuals (image: in units of each centre's
    /// root variance; point: metres).
    pub rms: f64,
    /// Per image.
    pub per_image: Vec<ImageResidual>,
    /// Singular values of the centred point cloud (m, largest first).
    pub singular_values_m: [f64; 3],
    /// Weak geometry, in words.
    pub warnings: Vec<String>,
}

/// Below this ratio of the second to the first singular value the points
/// lie on one line and no plane is defined.
const COLLINEAR_RATIO: f64 = 1e-6;
/// Below this ratio the plane is weakly constrained: a warning.
const WEAK_RATIO: f64 = 0.05;
/// Stripe lines whose directions all agree within this are parallel, deg.
const PARALLEL_DEG: f64 = 2.0;

/// Fit the laser plane to stripe observations from at least two images,
/// the board poses taken as exact.
pub fn fit_plane(obs: &[StripeObservation], options: &PlaneFitOptions) -> Result<PlaneFit> {
    fit_plane_with_boards(obs, &[], options)
}

/// [`fit_plane`] with the board poses' uncertainty added to the plane's
/// covariance (`boards`: the poses and covariances of the images).
pub fn fit_plane_with_boards(
    obs: &[StripeObservation],
    boards: &[BoardPose],
    options: &PlaneFitOptions,
) -> Result<PlaneFit> {
    let mut images: Vec<usize> = obs.iter().map(|o| o.image).collect();
    images.sort_unstable();
    images.dedup();
    if images.len() < 2 {
        return Err(Error::too_few(
            "images with a stripe on the board",
            2,
            images.len(),
        ));
    }
    if obs.len() < 3 {
        return Err(Error::too_few("stripe points", 3, obs.len()));
    }
    if let Some(o) = obs.iter().find(|o| {
        !(o.point_camera.coords.iter().all(|v| v.is_finite())
            && o.std_px.is_finite()
            && o.std_px > 0.0)
    }) {
        return Err(Error::invalid(
            "stripe",
            format!(
                "a stripe point of image {} is not finite or has no std",
                o.image + 1
            ),
        ));
    }
    let (start, singular) = total_least_squares(obs);
    let (s0, s1) = (singular[0], singular[1]);
    if !s1.is_finite() || s1 <= COLLINEAR_RATIO * s0 {
        return Err(Error::degenerate(format!(
            "the stripe points of all {} images lie on one line (singular values {:.3e}, {:.3e} m): \
             the plane is not constrained; move or tilt the board so the stripe falls elsewhere",
            images.len(),
            s0,
            s1
        )));
    }
    let mut warnings = geometry_warnings(obs, &images, singular);
    let (mut n, mut d) = gauss_newton(obs, &start, options.residual)?;
    // Each centre's variance from its reported std ([`CentreVariance`]):
    // a fit with every centre alike, the variance function from its
    // residuals (3 parameters fitted to them), the fit again with it.
    let mut weighted: Vec<StripeObservation> = obs.to_vec();
    let mut centre_variance = CentreVariance::default();
    if options.residual == PlaneResidual::ImagePx {
        for w in weighted.iter_mut() {
            w.std_px = 1.0;
        }
        (n, d) = gauss_newton(&weighted, &plane_in_camera(n, d)?, options.residual)?;
        let pairs: Vec<(f64, f64)> = obs
            .iter()
            .zip(scan_residuals(obs, &plane_in_camera(n, d)?))
            .filter_map(|(o, r)| r.map(|r| (o.std_px, r * r)))
            .collect();
        centre_variance = CentreVariance::fit(&pairs, 3);
        for (w, o) in weighted.iter_mut().zip(obs) {
            w.std_px = centre_variance.variance(o.std_px).sqrt();
        }
        (n, d) = gauss_newton(&weighted, &plane_in_camera(n, d)?, options.residual)?;
    }
    // The final linearisation, at the solution (the normal facing away).
    let plane = plane_in_camera(n, d)?;
    // The variance factor with the extractor's stds (1 when they are
    // right); the covariance from the residuals of the weighted fit.
    let raw = residual_rows(obs, &plane, options.residual);
    let chi2: f64 = raw.iter().map(|r| r.residual * r.residual).sum();
    let m = obs.len();
    let variance_factor = if m > 3 { chi2 / (m - 3) as f64 } else { 1.0 };
    let rows = residual_rows(&weighted, &plane, options.residual);
    let minimised: f64 = rows.iter().map(|r| r.residual * r.residual).sum();
    let covariance = plane_covariance(&weighted, &rows, boards)?;
    // The centres' errors are correlated along the stripe: how much that
    // widens the plane's covariance over independent errors of the same
    // variances (the joint refinement weighs the stripe by it).
    let centre_correlation = if options.residual == PlaneResidual::ImagePx && m > 3 {
        correlation_factor(&weighted, &rows, minimised / (m - 3) as f64)?
    } else {
        1.0
    };
    let per_image = images
        .iter()
        .map(|&i| image_residual(obs, i, &plane))
        .collect();
    let eig = SymmetricEigen::new(covariance);
    if eig
        .eigenvalues
        .iter()
        .any(|v| !(v.is_finite() && *v >= 0.0))
    {
        warnings.push("the plane's covariance is not positive: the fit is unreliable".into());
    }
    Ok(PlaneFit {
        estimate: PlaneEstimate { plane, covariance },
        variance_factor,
        centre_floor_px: centre_variance.floor().sqrt(),
        centre_variance,
        centre_correlation,
        rms: (minimised / m as f64).sqrt(),
        per_image,
        singular_values_m: singular,
        warnings,
    })
}

/// Gauss-Newton over the plane's `(a, b, d)` from `start`.
fn gauss_newton(
    obs: &[StripeObservation],
    start: &LaserPlane,
    model: PlaneResidual,
) -> Result<(Vector3<f64>, f64)> {
    let mut n = start.normal.into_inner();
    let mut d = start.distance_m;
    for _ in 0..30 {
        let basis = tangent_basis(&nalgebra::Unit::new_normalize(n));
        let (a, g) = normal_equations(obs, &n, d, &basis, model);
        let Some(step) = a.cholesky().map(|ch| ch.solve(&(-g))) else {
            return Err(Error::degenerate(
                "the plane's normal equations are singular: the stripes do not constrain it",
            ));
        };
        // n <- exp(a e1 + b e2) n = n - a e2 + b e1 to first order.
        n = (n - basis.1 * step[0] + basis.0 * step[1]).normalize();
        d += step[2];
        if step.norm() < 1e-14 {
            break;
        }
    }
    Ok((n, d))
}

/// [`PlaneFit::centre_correlation`] from the weighted rows and their
/// residual variance `s2`.
fn correlation_factor(obs: &[StripeObservation], rows: &[ResidualRow], s2: f64) -> Result<f64> {
    let correlated = plane_covariance(obs, rows, &[])?;
    let mut a = Matrix3::zeros();
    for r in rows {
        a += r.jacobian * r.jacobian.transpose();
    }
    let Some(inverse) = a.try_inverse() else {
        return Ok(1.0);
    };
    let k = (correlated.determinant() / (inverse * s2).determinant()).cbrt();
    Ok(if k.is_finite() { k.max(1.0) } else { 1.0 })
}

/// Each centre's residual along its scan (pixels) at `plane`, None where
/// the plane runs along the scan direction.
fn scan_residuals(obs: &[StripeObservation], plane: &LaserPlane) -> Vec<Option<f64>> {
    let n = plane.normal.into_inner();
    obs.iter()
        .map(|o| {
            let nt = n.dot(&o.along_scan_m_per_px);
            (nt.abs() > 1e-15).then(|| (n.dot(&o.point_camera.coords) - plane.distance_m) / nt)
        })
        .collect()
}

/// One observation's residual, its Jacobian over the plane's `(a, b, d)`
/// and over the observation's point (camera frame, per metre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ResidualRow {
    pub residual: f64,
    pub jacobian: Vector3<f64>,
    pub d_point: Vector3<f64>,
}

/// The rows of every observation at `plane`, in order (zeros where the
/// plane runs along the scan direction).
pub(crate) fn residual_rows(
    obs: &[StripeObservation],
    plane: &LaserPlane,
    model: PlaneResidual,
) -> Vec<ResidualRow> {
    let n = plane.normal.into_inner();
    let basis = tangent_basis(&plane.normal);
    obs.iter()
        .map(|o| {
            residual_row(o, &n, plane.distance_m, &basis, model).unwrap_or(ResidualRow {
                residual: 0.0,
                jacobian: Vector3::zeros(),
                d_point: Vector3::zeros(),
            })
        })
        .collect()
}

fn residual_row(
    o: &StripeObservation,
    n: &Vector3<f64>,
    d: f64,
    basis: &(Vector3<f64>, Vector3<f64>),
    model: PlaneResidual,
) -> Option<ResidualRow> {
    let x = o.point_camera.coords;
    let (r, dn, dd, dx) = match model {
        PlaneResidual::PointToPlane => (n.dot(&x) - d, x, -1.0, *n),
        PlaneResidual::ImagePx => {
            let t = o.along_scan_m_per_px;
            let nt = n.dot(&t);
            if nt.abs() < 1e-15 {
                return None;
            }
            let e = n.dot(&x) - d;
            let w = 1.0 / o.std_px;
            (
                w * e / nt,
                w * (x * nt - t * e) / (nt * nt),
                -w / nt,
                n * (w / nt),
            )
        }
    };
    // The normal turned by a e1 + b e2 moves by -a e2 + b e1.
    Some(ResidualRow {
        residual: r,
        jacobian: Vector3::new(-dn.dot(&basis.1), dn.dot(&basis.0), dd),
        d_point: dx,
    })
}

/// `J^T J` and `J^T r` over `(a, b, d)`.
fn normal_equations(
    obs: &[StripeObservation],
    n: &Vector3<f64>,
    d: f64,
    basis: &(Vector3<f64>, Vector3<f64>),
    model: PlaneResidual,
) -> (Matrix3<f64>, Vector3<f64>) {
    let mut a = Matrix3::zeros();
    let mut g = Vector3::zeros();
    for row in obs
        .iter()
        .filter_map(|o| residual_row(o, n, d, basis, model))
    {
        a += row.jacobian * row.jacobian.transpose();
        g += row.jacobian * row.residual;
    }
    (a, g)
}

/// The point-to-plane total-least-squares plane and the singular values
/// of the centred points.
fn total_least_squares(obs: &[StripeObservation]) -> (LaserPlane, [f64; 3]) {
    let m = obs.len() as f64;
    let centre = obs
        .iter()
        .map(|o| o.point_camera.coords)
        .sum::<Vector3<f64>>()
        / m;
    let mut scatter = Matrix3::zeros();
    for o in obs {
        let v = o.point_camera.coords - centre;
        scatter += v * v.transpose();
    }
    let eig = SymmetricEigen::new(scatter);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let sv = order.map(|i| eig.eigenvalues[i].max(0.0).sqrt());
    let normal: Vector3<f64> = eig.eigenvectors.column(order[2]).into();
    let plane = plane_in_camera(normal, normal.dot(&centre)).unwrap_or(Plane {
        normal: Vector3::z_axis(),
        distance_m: 0.0,
    });
    (plane, sv)
}

/// Warnings on the geometry: points near one line, stripe lines parallel.
fn geometry_warnings(obs: &[StripeObservation], images: &[usize], sv: [f64; 3]) -> Vec<String> {
    let mut warnings = Vec::new();
    if sv[1] < WEAK_RATIO * sv[0] {
        warnings.push(format!(
            "the stripe points lie close to one line (singular values {:.2} and {:.2} mm): the \
             plane's rotation about it is weakly constrained; place the board at other distances or tilts",
            sv[0] * 1e3,
            sv[1] * 1e3
        ));
    }
    let directions: Vec<Vector3<f64>> = images
        .iter()
        .filter_map(|&i| {
            let pts: Vec<Vector3<f64>> = obs
                .iter()
                .filter(|o| o.image == i)
                .map(|o| o.point_camera.coords)
                .collect();
            line_direction(&pts)
        })
        .collect();
    if directions.len() == 2 {
        warnings.push(
            "only 2 board poses: with two stripe lines each line is fitted by itself alone, so \
             a bias of one line (a stripe running along the board's square edges, a board pose \
             off) shows in no residual and the reported std can be too small; add board poses \
             (4 or more, tilted about different axes) for a std that holds"
                .into(),
        );
    }
    if directions.len() >= 2 {
        let worst = directions
            .iter()
            .flat_map(|a| {
                directions
                    .iter()
                    .map(move |b| a.dot(b).abs().min(1.0).acos())
            })
            .fold(0.0, f64::max)
            .to_degrees();
        if worst < PARALLEL_DEG {
            warnings.push(format!(
                "all {} stripe lines are parallel (within {:.2} deg): the plane's tilt about their \
                 common direction rests on their separation alone; tilt the board about another axis \
                 between poses",
                directions.len(),
                worst
            ));
        }
    }
    warnings
}

/// The principal direction of a set of points (None for fewer than 2).
fn line_direction(pts: &[Vector3<f64>]) -> Option<Vector3<f64>> {
    if pts.len() < 2 {
        return None;
    }
    let c = pts.iter().sum::<Vector3<f64>>() / pts.len() as f64;
    let mut s = Matrix3::zeros();
    for p in pts {
        let v = p - c;
        s += v * v.transpose();
    }
    let eig = SymmetricEigen::new(s);
    let imax = eig.eigenvalues.imax();
    Some(eig.eigenvectors.column(imax).into())
}

fn image_residual(obs: &[StripeObservation], image: usize, plane: &LaserPlane) -> ImageResidual {
    let n = plane.normal;
    let (mut sp, mut sm, mut k) = (0.0, 0.0, 0usize);
    for o in obs.iter().filter(|o| o.image == image) {
        let e = plane.signed_distance_m(&o.point_camera.coords);
        let nt = n.dot(&o.along_scan_m_per_px);
        if nt.abs() > 1e-15 {
            sp += (e / nt).powi(2);
        }
        sm += e * e;
        k += 1;
    }
    let k1 = k.max(1) as f64;
    ImageResidual {
        image,
        n_points: k,
        rms_px: (sp / k1).sqrt(),
        rms_mm: (sm / k1).sqrt() * 1e3,
    }
}
