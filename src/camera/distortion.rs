//! The lens models: one [`Distortion`] variant per model, each mapping a
//! ray in the camera frame to a distorted normalised image point `m`
//! (pixel = K m).

use super::{
    division, eucm, kannala_brandt, polynomial::col, polynomial::Poly, splined::Spline, tilt::Tilt,
};
use crate::error::{Error, Result};
use nalgebra::{Matrix2, Matrix2x3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// A distorted point with its Jacobian with respect to the undistorted one
/// and its derivative along each coefficient.
type DistortedWithJacobians = (Vector2<f64>, Matrix2<f64>, Vec<Vector2<f64>>);

/// A lens model and its coefficients. All act on normalised coordinates
/// (`X/Z`, `Y/Z`) or, for the wide-angle models, on the ray itself; the
/// coefficient order of [`Distortion::coefficients`] is the order of
/// [`Distortion::coefficient_names`].
///
/// In JSON: `{"model": "brown", "k1": -0.2, ...}`, tagged by `model` and
/// read by serde's derive (an unknown model is "unknown variant `x`,
/// expected one of `none`, `brown`, ..."; a missing coefficient "missing
/// field `k3`").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case")]
pub enum Distortion {
    /// The ideal pinhole camera.
    None,
    /// Brown-Conrady: radial k1 k2 k3 and tangential (decentering) p1 p2.
    /// OpenCV's 5-coefficient model (order `k1 k2 p1 p2 k3`). HALCON's
    /// "polynomial" model has the same terms but maps distorted to
    /// undistorted points, so its coefficients are fitted, not copied
    /// (`crate::io`'s HALCON reader and export).
    Brown {
        /// r^2 radial coefficient.
        k1: f64,
        /// r^4 radial coefficient.
        k2: f64,
        /// r^6 radial coefficient.
        k3: f64,
        /// First tangential coefficient (OpenCV p1).
        p1: f64,
        /// Second tangential coefficient (OpenCV p2).
        p2: f64,
    },
    /// OpenCV's rational model (`CALIB_RATIONAL_MODEL`) with the thin-prism
    /// terms (`CALIB_THIN_PRISM_MODEL`); s1..s4 = 0 gives the 8-coefficient
    /// model. Order `k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4` as in OpenCV.
    Rational {
        /// Numerator r^2 coefficient.
        k1: f64,
        /// Numerator r^4 coefficient.
        k2: f64,
        /// Numerator r^6 coefficient.
        k3: f64,
        /// Denominator r^2 coefficient.
        k4: f64,
        /// Denominator r^4 coefficient.
        k5: f64,
        /// Denominator r^6 coefficient.
        k6: f64,
        /// First tangential coefficient.
        p1: f64,
        /// Second tangential coefficient.
        p2: f64,
        /// Thin prism: r^2 term added to x.
        s1: f64,
        /// Thin prism: r^4 term added to x.
        s2: f64,
        /// Thin prism: r^2 term added to y.
        s3: f64,
        /// Thin prism: r^4 term added to y.
        s4: f64,
    },
    /// Division model (Fitzgibbon; Halcon "division"):
    /// `undistorted = distorted / (1 + kappa r_d^2)`, kappa in normalised
    /// units (`kappa_halcon * focal_m^2`).
    Division {
        /// The division coefficient (< 0 for barrel distortion).
        kappa: f64,
    },
    /// The radial-only Brown model of seed 000 (Chen et al. 2009, Eq. 7-8,
    /// tangential k3 k4 dropped), named as in Bouguet's toolbox `kc`:
    /// `x_d = x (1 + k1 r^2 + k2 r^4 + k5 r^6)`. Equal to
    /// [`Distortion::Brown`] with `k3 = k5` and `p1 = p2 = 0`.
    RadialK1K2K5 {
        /// r^2 coefficient.
        k1: f64,
        /// r^4 coefficient.
        k2: f64,
        /// r^6 coefficient.
        k5: f64,
    },
    /// Kannala-Brandt equidistant fisheye (OpenCV `cv::fisheye`):
    /// `theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)`.
    /// OpenCV's fisheye `alpha` (skew) is our `skew / fx`.
    KannalaBrandt {
        /// theta^3 coefficient.
        k1: f64,
        /// theta^5 coefficient.
        k2: f64,
        /// theta^7 coefficient.
        k3: f64,
        /// theta^9 coefficient.
        k4: f64,
    },
    /// Enhanced unified camera model (Khomenko et al. 2016) for wide-angle
    /// lenses; `alpha` in [0, 1), `beta > 0`.
    Eucm {
        /// Projection-sphere blend (0 = pinhole).
        alpha: f64,
        /// Ellipsoid shape (1 = sphere, the unified model).
        beta: f64,
    },
    /// A Scheimpflug camera: OpenCV's rational + thin-prism model followed
    /// by the tilted sensor of `CALIB_TILTED_MODEL` (see `tilt.rs` for the
    /// convention). Order `k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tau_x tau_y`,
    /// OpenCV's 14 coefficients; the angles in radians.
    Tilted {
        /// Numerator r^2 coefficient.
        k1: f64,
        /// Numerator r^4 coefficient.
        k2: f64,
        /// Numerator r^6 coefficient.
        k3: f64,
        /// Denominator r^2 coefficient.
        k4: f64,
        /// Denominator r^4 coefficient.
        k5: f64,
        /// Denominator r^6 coefficient.
        k6: f64,
        /// First tangential coefficient.
        p1: f64,
        /// Second tangential coefficient.
        p2: f64,
        /// Thin prism: r^2 term added to x.
        s1: f64,
        /// Thin prism: r^4 term added to x.
        s2: f64,
        /// Thin prism: r^2 term added to y.
        s3: f64,
        /// Thin prism: r^4 term added to y.
        s4: f64,
        /// Sensor tilt about the x axis, radians (OpenCV tauX).
        tau_x: f64,
        /// Sensor tilt about the y axis, radians (OpenCV tauY).
        tau_y: f64,
    },
    /// Splined stereographic ([`super::splined`]): the stereographic
    /// projection plus a B-spline correction over a grid of control points;
    /// coefficients `dx0 dy0 dx1 ...`, their count set by the layout.
    Splined(Spline),
}

/// A ray's distorted normalised point and its derivatives.
#[derive(Clone, Debug)]
pub(crate) struct RayProjection {
    /// Distorted normalised point (pixel = K m).
    pub m: Vector2<f64>,
    /// d m / d point (camera frame).
    pub d_point: Matrix2x3<f64>,
    /// d m / d coefficient, one column per coefficient in order.
    pub d_coeffs: Vec<Vector2<f64>>,
}

impl Distortion {
    /// The model's name as used in JSON and the CLI (`brown`, `rational`, ...).
    pub fn model_name(&self) -> &'static str {
        match self {
            Distortion::None => "none",
            Distortion::Brown { .. } => "brown",
            Distortion::Rational { .. } => "rational",
            Distortion::Division { .. } => "division",
            Distortion::RadialK1K2K5 { .. } => "radial_k1_k2_k5",
            Distortion::KannalaBrandt { .. } => "kannala_brandt",
            Distortion::Eucm { .. } => "eucm",
            Distortion::Tilted { .. } => "tilted",
            Distortion::Splined(_) => "splined",
        }
    }

    /// Names of the coefficients, in the order of [`Distortion::coefficients`].
    pub fn coefficient_names(&self) -> &'static [&'static str] {
        match self {
            Distortion::None => &[],
            Distortion::Brown { .. } => &["k1", "k2", "p1", "p2", "k3"],
            Distortion::Rational { .. } => &[
                "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4",
            ],
            Distortion::Division { .. } => &["kappa"],
            Distortion::RadialK1K2K5 { .. } => &["k1", "k2", "k5"],
            Distortion::KannalaBrandt { .. } => &["k1", "k2", "k3", "k4"],
            Distortion::Eucm { .. } => &["alpha", "beta"],
            Distortion::Tilted { .. } => &[
                "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4", "tau_x",
                "tau_y",
            ],
            Distortion::Splined(s) => s.names(),
        }
    }

    /// The coefficients in the order of [`Distortion::coefficient_names`]
    /// (OpenCV's order for the polynomial models).
    pub fn coefficients(&self) -> Vec<f64> {
        match *self {
            Distortion::Splined(ref s) => s.control.clone(),
            Distortion::None => vec![],
            Distortion::Brown { k1, k2, k3, p1, p2 } => vec![k1, k2, p1, p2, k3],
            Distortion::Rational {
                k1,
                k2,
                k3,
                k4,
                k5,
                k6,
                p1,
                p2,
                s1,
                s2,
                s3,
                s4,
            } => vec![k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4],
            Distortion::Division { kappa } => vec![kappa],
            Distortion::RadialK1K2K5 { k1, k2, k5 } => vec![k1, k2, k5],
            Distortion::KannalaBrandt { k1, k2, k3, k4 } => vec![k1, k2, k3, k4],
            Distortion::Eucm { alpha, beta } => vec![alpha, beta],
            Distortion::Tilted {
                k1,
                k2,
                k3,
                k4,
                k5,
                k6,
                p1,
                p2,
                s1,
                s2,
                s3,
                s4,
                tau_x,
                tau_y,
            } => vec![k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4, tau_x, tau_y],
        }
    }

    /// The same model with new coefficients (same order and count as
    /// [`Distortion::coefficients`]).
    pub fn with_coefficients(&self, c: &[f64]) -> Result<Distortion> {
        let expected = self.coefficient_names().len();
        if c.len() != expected {
            return Err(Error::invalid(
                "distortion",
                format!(
                    "the {} model has {expected} coefficients, got {}",
                    self.model_name(),
                    c.len()
                ),
            ));
        }
        if let Some(i) = c.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "distortion",
                format!(
                    "coefficient {} is not finite: {}",
                    self.coefficient_names()[i],
                    c[i]
                ),
            ));
        }
        Ok(match self {
            Distortion::None => Distortion::None,
            Distortion::Brown { .. } => Distortion::Brown {
                k1: c[0],
                k2: c[1],
                p1: c[2],
                p2: c[3],
                k3: c[4],
            },
            Distortion::Rational { .. } => Distortion::Rational {
                k1: c[0],
                k2: c[1],
                p1: c[2],
                p2: c[3],
                k3: c[4],
                k4: c[5],
                k5: c[6],
                k6: c[7],
                s1: c[8],
                s2: c[9],
                s3: c[10],
                s4: c[11],
            },
            Distortion::Division { .. } => Distortion::Division { kappa: c[0] },
            Distortion::RadialK1K2K5 { .. } => Distortion::RadialK1K2K5 {
                k1: c[0],
                k2: c[1],
                k5: c[2],
            },
            Distortion::KannalaBrandt { .. } => Distortion::KannalaBrandt {
                k1: c[0],
                k2: c[1],
                k3: c[2],
                k4: c[3],
            },
            Distortion::Eucm { .. } => Distortion::Eucm {
                alpha: c[0],
                beta: c[1],
            },
            Distortion::Tilted { .. } => Distortion::Tilted {
                k1: c[0],
                k2: c[1],
                p1: c[2],
                p2: c[3],
                k3: c[4],
                k4: c[5],
                k5: c[6],
                k6: c[7],
                s1: c[8],
                s2: c[9],
                s3: c[10],
                s4: c[11],
                tau_x: c[12],
                tau_y: c[13],
            },
            Distortion::Splined(s) => Distortion::Splined(Spline {
                control: c.to_vec(),
                ..s.clone()
            }),
        })
    }

    /// The model's math family; the polynomial models share one
    /// implementation, with their own coefficients' columns in
    /// [`Poly::distort`]'s Jacobian.
    pub(super) fn family(&self) -> Family<'_> {
        use col::*;
        match *self {
            Distortion::Splined(ref s) => Family::Splined(s),
            Distortion::None => Family::Pinhole,
            Distortion::Brown { k1, k2, k3, p1, p2 } => Family::Poly(
                Poly {
                    k: [k1, k2, k3, 0.0, 0.0, 0.0],
                    p: [p1, p2],
                    s: [0.0; 4],
                },
                &[K1, K2, P1, P2, K3],
            ),
            Distortion::Rational {
                k1,
                k2,
                k3,
                k4,
                k5,
                k6,
                p1,
                p2,
                s1,
                s2,
                s3,
                s4,
            } => Family::Poly(
                Poly {
                    k: [k1, k2, k3, k4, k5, k6],
                    p: [p1, p2],
                    s: [s1, s2, s3, s4],
                },
                &[K1, K2, P1, P2, K3, K4, K5, K6, S1, S2, S3, S4],
            ),
            Distortion::RadialK1K2K5 { k1, k2, k5 } => Family::Poly(
                Poly {
                    k: [k1, k2, k5, 0.0, 0.0, 0.0],
                    p: [0.0; 2],
                    s: [0.0; 4],
                },
                &[K1, K2, K3],
            ),
            Distortion::Division { kappa } => Family::Division(kappa),
            Distortion::KannalaBrandt { k1, k2, k3, k4 } => Family::KannalaBrandt([k1, k2, k3, k4]),
            Distortion::Eucm { alpha, beta } => Family::Eucm(alpha, beta),
            Distortion::Tilted {
                k1,
                k2,
                k3,
                k4,
                k5,
                k6,
                p1,
                p2,
                s1,
                s2,
                s3,
                s4,
                tau_x,
                tau_y,
            } => Family::Tilted(
                Poly {
                    k: [k1, k2, k3, k4, k5, k6],
                    p: [p1, p2],
                    s: [s1, s2, s3, s4],
                },
                Tilt::new(tau_x, tau_y),
            ),
        }
    }

    /// [`Distortion::project_ray`]'s point alone (the same value, the same
    /// refusals), without the Jacobians and their allocation: for every
    /// projection that needs no derivatives.
    pub(crate) fn project_point(&self, p: &Vector3<f64>) -> Result<Vector2<f64>> {
        match self.family() {
            Family::KannalaBrandt(k) => Ok(kannala_brandt::project(&k, p)?.0),
            Family::Eucm(alpha, beta) => Ok(eucm::project(alpha, beta, p)?.0),
            Family::Splined(s) => s.project_point(p),
            Family::Pinhole | Family::Poly(..) | Family::Division(_) | Family::Tilted(..) => {
                if !(p.z > 0.0) || !p.iter().all(|v| v.is_finite()) {
                    return Err(not_in_front(p));
                }
                self.distort_point(&Vector2::new(p.x / p.z, p.y / p.z))
            }
        }
    }

    /// [`Distortion::distort_with_jacobians`]'s point alone.
    pub(crate) fn distort_point(&self, n: &Vector2<f64>) -> Result<Vector2<f64>> {
        match self.family() {
            Family::Pinhole => Ok(*n),
            Family::Poly(poly, _) => {
                if !poly.in_domain(n.norm_squared()) {
                    return Err(self.beyond_fold(n));
                }
                Ok(poly.distort_value(n))
            }
            Family::Division(kappa) => Ok(division::distort(kappa, n)?.0),
            Family::Tilted(poly, tilt) => {
                if !poly.in_domain(n.norm_squared()) {
                    return Err(self.beyond_fold(n));
                }
                tilt.apply_value(&poly.distort_value(n))
            }
            Family::KannalaBrandt(_) | Family::Eucm(..) | Family::Splined(_) => {
                self.project_point(&Vector3::new(n.x, n.y, 1.0))
            }
        }
    }

    pub(super) fn beyond_fold(&self, n: &Vector2<f64>) -> Error {
        Error::invalid(
            "point",
            format!(
                "normalised point ({:.4}, {:.4}) lies beyond the fold of the {} distortion model",
                n.x,
                n.y,
                self.model_name()
            ),
        )
    }

    /// Project a camera-frame point to the distorted normalised plane.
    pub(crate) fn project_ray(&self, p: &Vector3<f64>) -> Result<RayProjection> {
        match self.family() {
            Family::KannalaBrandt(k) => {
                let (m, d_point, d_k) = kannala_brandt::project(&k, p)?;
                Ok(RayProjection {
                    m,
                    d_point,
                    d_coeffs: d_k.to_vec(),
                })
            }
            Family::Eucm(alpha, beta) => {
                let (m, d_point, d_ab) = eucm::project(alpha, beta, p)?;
                Ok(RayProjection {
                    m,
                    d_point,
                    d_coeffs: d_ab.to_vec(),
                })
            }
            Family::Splined(s) => {
                let (m, d_point, d_coeffs) = s.project(p)?;
                Ok(RayProjection {
                    m,
                    d_point,
                    d_coeffs,
                })
            }
            Family::Pinhole | Family::Poly(..) | Family::Division(_) | Family::Tilted(..) => {
                if !(p.z > 0.0) || !p.iter().all(|v| v.is_finite()) {
                    return Err(not_in_front(p));
                }
                let n = Vector2::new(p.x / p.z, p.y / p.z);
                let d_n_d_p =
                    Matrix2x3::new(1.0 / p.z, 0.0, -n.x / p.z, 0.0, 1.0 / p.z, -n.y / p.z);
                let (m, d_n, d_coeffs) = self.distort_with_jacobians(&n)?;
                Ok(RayProjection {
                    m,
                    d_point: d_n * d_n_d_p,
                    d_coeffs,
                })
            }
        }
    }

    /// Distort a normalised point `(X/Z, Y/Z)`, with the Jacobians with
    /// respect to it and to the coefficients.
    pub(crate) fn distort_with_jacobians(
        &self,
        n: &Vector2<f64>,
    ) -> Result<DistortedWithJacobians> {
        match self.family() {
            Family::Pinhole => Ok((*n, Matrix2::identity(), vec![])),
            Family::Poly(poly, cols) => {
                if !poly.in_domain(n.norm_squared()) {
                    return Err(self.beyond_fold(n));
                }
                let (m, d_n, d_all) = poly.distort(n);
                Ok((m, d_n, cols.iter().map(|&c| d_all[c]).collect()))
            }
            Family::Division(kappa) => {
                let (m, d_n, d_k) = division::distort(kappa, n)?;
                Ok((m, d_n, vec![d_k]))
            }
            Family::Tilted(poly, tilt) => {
                if !poly.in_domain(n.norm_squared()) {
                    return Err(self.beyond_fold(n));
                }
                // The 12 polynomial columns are in OpenCV's order already.
                let (d, d_n, d_poly) = poly.distort(n);
                let (m, d_d, d_tau) = tilt.apply(&d)?;
                let mut d_coeffs: Vec<Vector2<f64>> = d_poly.iter().map(|c| d_d * c).collect();
                d_coeffs.extend(d_tau);
                Ok((m, d_d * d_n, d_coeffs))
            }
            Family::KannalaBrandt(_) | Family::Eucm(..) | Family::Splined(_) => {
                let r = self.project_ray(&Vector3::new(n.x, n.y, 1.0))?;
                // d m / d(x, y) at z = 1 is the first two columns.
                Ok((
                    r.m,
                    r.d_point.fixed_columns::<2>(0).into_owned(),
                    r.d_coeffs,
                ))
            }
        }
    }

    /// The ray (unit norm) of a distorted normalised point.
    pub(crate) fn unproject_ray(&self, m: &Vector2<f64>) -> Result<Vector3<f64>> {
        let ray = match self.family() {
            Family::Pinhole => Vector3::new(m.x, m.y, 1.0),
            Family::Poly(poly, _) => {
                let n = poly.undistort(m)?;
                Vector3::new(n.x, n.y, 1.0)
            }
            Family::Division(kappa) => {
                let n = division::undistort(kappa, m)?;
                Vector3::new(n.x, n.y, 1.0)
            }
            Family::KannalaBrandt(k) => kannala_brandt::unproject(&k, m)?,
            Family::Eucm(alpha, beta) => eucm::unproject(alpha, beta, m)?,
            Family::Tilted(poly, tilt) => {
                let n = poly.undistort(&tilt.invert(m)?)?;
                Vector3::new(n.x, n.y, 1.0)
            }
            Family::Splined(s) => s.unproject(m)?,
        };
        let norm = ray.norm();
        if !(norm > 0.0) || !norm.is_finite() {
            return Err(Error::NoConvergence {
                message: format!("unprojection of ({:.6}, {:.6}) gave no ray", m.x, m.y),
            });
        }
        Ok(ray / norm)
    }
}

/// The math behind each variant.
pub(super) enum Family<'a> {
    Pinhole,
    Poly(Poly, &'static [usize]),
    Division(f64),
    KannalaBrandt([f64; 4]),
    Eucm(f64, f64),
    Tilted(Poly, Tilt),
    Splined(&'a Spline),
}

/// The refusal of a point at or behind the camera (or not finite).
pub(super) fn not_in_front(p: &Vector3<f64>) -> Error {
    Error::invalid(
        "point",
        format!(
            "point ({:.4}, {:.4}, {:.4}) is not in front of the camera (needs z > 0)",
            p.x, p.y, p.z
        ),
    )
}
