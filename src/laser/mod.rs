//! Laser-line (sheet-of-light) sensors: the stripe's centre in an image,
//! the laser plane in the camera frame and profiles turned into 3-D points.
//!
//! - [`stripe`] / [`ridge`]: sub-pixel stripe centres per column (or row)
//!   by the centre of gravity over a thresholded window, or by a ridge
//!   detector (Steger: Gaussian derivatives, the second derivative's
//!   extremum along the line normal), with width, quality, gaps and ends;
//! - [`plane`]: the plane `normal_camera . X = distance_m` and the stripe
//!   observations it is fitted to (a stripe centre on a board of known pose);
//! - [`fit`]: the least-squares plane with its covariance, per-image
//!   residuals and the warnings when the poses do not constrain it;
//! - [`points`]: a stripe's centres to 3-D points (camera, flange or base).
//!
//! Pure maths on pixels and numbers: no files, no clock.

pub mod fit;
pub mod plane;
pub mod points;
pub mod ridge;
pub mod stripe;

pub use fit::{fit_plane, PlaneFit, PlaneFitOptions, PlaneResidual};
pub use plane::{LaserPlane, StripeObservation};
pub use stripe::{extract_stripe, ScanAxis, Stripe, StripeMethod, StripeOptions, StripePoint};

#[cfg(test)]
mod tests;
