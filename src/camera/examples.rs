//! Example parameter sets, one per lens model: realistic values used by
//! tests, docs, synthetic scenes and the web demo. Each is invertible over
//! its whole image (every pixel unprojects and projects back).

use super::{Camera, Distortion};

impl Camera {
    /// A 1280x960 pinhole camera, 1000 px focal length, no distortion.
    pub fn example_pinhole() -> Camera {
        Camera {
            fx: 1000.0,
            fy: 1002.0,
            cx: 641.5,
            cy: 478.25,
            skew: 0.0,
            width: 1280,
            height: 960,
            distortion: Distortion::None,
        }
    }

    /// An industrial 1280x960 camera with moderate barrel distortion.
    pub fn example_brown() -> Camera {
        Camera {
            distortion: Distortion::Brown {
                k1: -0.28,
                k2: 0.09,
                k3: -0.012,
                p1: 0.0012,
                p2: -0.0007,
            },
            ..Camera::example_pinhole()
        }
    }

    /// OpenCV's rational model with thin-prism terms.
    pub fn example_rational() -> Camera {
        Camera {
            skew: 0.0,
            distortion: Distortion::Rational {
                k1: 0.25,
                k2: -0.04,
                k3: 0.01,
                k4: 0.55,
                k5: 0.03,
                k6: 0.002,
                p1: 0.0009,
                p2: -0.0004,
                s1: 0.0011,
                s2: -0.0002,
                s3: 0.0006,
                s4: 0.0001,
            },
            ..Camera::example_pinhole()
        }
    }

    /// Division model with barrel distortion, and a little skew.
    pub fn example_division() -> Camera {
        Camera {
            skew: 0.4,
            distortion: Distortion::Division { kappa: -0.22 },
            ..Camera::example_pinhole()
        }
    }

    /// The seed-000 radial model (k1 k2 k5).
    pub fn example_radial_k1_k2_k5() -> Camera {
        Camera {
            distortion: Distortion::RadialK1K2K5 {
                k1: -0.25,
                k2: 0.11,
                k5: -0.015,
            },
            ..Camera::example_pinhole()
        }
    }

    /// A 1280x960 fisheye (about 190 degrees across the diagonal).
    pub fn example_kannala_brandt() -> Camera {
        Camera {
            fx: 420.0,
            fy: 419.5,
            cx: 639.0,
            cy: 481.0,
            skew: 0.3,
            width: 1280,
            height: 960,
            distortion: Distortion::KannalaBrandt {
                k1: 0.045,
                k2: -0.012,
                k3: 0.0021,
                k4: -0.0004,
            },
        }
    }

    /// A wide-angle camera with the enhanced unified model.
    pub fn example_eucm() -> Camera {
        Camera {
            fx: 460.0,
            fy: 461.0,
            cx: 642.0,
            cy: 477.0,
            skew: 0.0,
            width: 1280,
            height: 960,
            distortion: Distortion::Eucm {
                alpha: 0.62,
                beta: 1.08,
            },
        }
    }

    /// A laser-profiler camera with a Scheimpflug sensor (tilted by about
    /// 3 and -2 degrees) behind a lens with barrel distortion.
    pub fn example_tilted() -> Camera {
        Camera {
            distortion: Distortion::Tilted {
                k1: -0.21,
                k2: 0.07,
                k3: -0.008,
                k4: 0.0,
                k5: 0.0,
                k6: 0.0,
                p1: 0.0008,
                p2: -0.0005,
                s1: 0.0,
                s2: 0.0,
                s3: 0.0,
                s4: 0.0,
                tau_x: 0.052,
                tau_y: -0.035,
            },
            ..Camera::example_pinhole()
        }
    }

    /// A wide-angle 1280x960 lens no parametric model fits: stereographic
    /// with a smooth bump field of a few pixels (12x8 cubic spline).
    pub fn example_splined() -> Camera {
        let mut spline = super::Spline::new(3, 12, 8);
        spline.u_max = [1.55, 1.2];
        for row in 0..8 {
            for col in 0..12 {
                let k = 2 * (row * 12 + col);
                let (c, r) = (col as f64, row as f64);
                spline.control[k] = 0.006 * (0.9 * c).sin() * (0.7 * r).cos();
                spline.control[k + 1] = 0.005 * (0.5 * c).cos() * (0.8 * r).sin();
            }
        }
        Camera {
            distortion: Distortion::Splined(spline),
            ..Camera::example_eucm()
        }
    }

    /// One example per lens model, in the order of the [`Distortion`]
    /// variants.
    pub fn examples() -> Vec<Camera> {
        vec![
            Camera::example_pinhole(),
            Camera::example_brown(),
            Camera::example_rational(),
            Camera::example_division(),
            Camera::example_radial_k1_k2_k5(),
            Camera::example_kannala_brandt(),
            Camera::example_eucm(),
            Camera::example_tilted(),
            Camera::example_splined(),
        ]
    }
}
