//! Laser-line (sheet-of-light) sensors: the stripe's centre in an image,
//! the laser plane in the camera frame and profiles turned into 3-D points.
//!
//! - [`stripe`] / [`ridge`]: sub-pixel stripe centres per column (or row)
//!   by the centre of gravity over a thresholded window, or by a ridge
//!   detector (Steger: Gaussian derivatives, the second derivative's
//!   extremum along the line normal), with width, quality, gaps and ends;
//! - [`plane`]: the laser plane (a [`crate::geometry::Plane`] in the camera
//!   frame, `normal . X = distance_m`) and the stripe observations it is
//!   fitted to (a stripe centre on a board of known pose);
//! - [`fit`]: the least-squares plane (a [`crate::geometry::PlaneEstimate`])
//!   with per-image residuals and the warnings when the poses do not
//!   constrain it; [`weights`]: the centres' variances it weighs them by;
//!   [`covariance`]: its covariance from the residuals'
//!   correlated scatter and the board poses' uncertainty;
//! - [`points`]: a stripe's centres to 3-D points (camera, flange or base);
//! - [`skeleton`]: seed 003's control points: the laser image binarised,
//!   thinned, and the end points of its lines;
//! - [`sphere`]: the sensor on the robot (plane and camera in the flange
//!   frame) from scans of a sphere of known radius.
//!
//! Pure maths on pixels and numbers: no files, no clock.

pub mod covariance;
pub mod fit;
pub mod joint;
pub mod plane;
pub mod points;
mod ratio;
pub mod ridge;
pub mod skeleton;
pub mod sphere;
pub mod stripe;
pub mod weights;

pub use covariance::BoardPose;
pub use fit::{fit_plane, fit_plane_with_boards, PlaneFit, PlaneFitOptions, PlaneResidual};
pub use plane::{plane_in_camera, LaserPlane, StripeObservation};
pub use stripe::{extract_stripe, ScanAxis, Stripe, StripeMethod, StripeOptions, StripePoint};
pub use weights::CentreVariance;

#[cfg(test)]
mod sphere_tests;
#[cfg(test)]
mod tests;
