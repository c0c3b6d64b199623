//! Where a board sits in a camera's view: the outline of its print, its
//! size, and the pose that puts it, turned and sized as asked, inside the
//! image. Shared by the live-capture guide (`capture`: coverage and the next
//! pose to suggest) and the synthetic video's keyframes (`synth::video`).

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::Pose;
use crate::target::Target;
use nalgebra::{Point2, Point3, Translation3, UnitQuaternion, Vector3};

/// Pixels [`fitted_pose`] keeps between the board's print (its points plus
/// one point spacing around them) and the image border.
const HOLD_MARGIN_PX: f64 = 4.0;
/// Each try that does not fit shrinks the board by this factor.
const SHRINK: f64 = 0.92;
/// Shrinks tried before a keyframe is declared impossible.
const MAX_SHRINKS: usize = 40;

/// The board rotated by `rotation` with the centre of its print on the ray
/// through pixel `aim`, at the distance where its points' larger side spans
/// `span` image widths when facing the camera; shrunk (the distance grown)
/// until its print ([`print_outline`]) is at least 4 px inside the image.
pub fn fitted_pose(
    camera: &Camera,
    target: &Target,
    aim: &Point2<f64>,
    rotation: UnitQuaternion<f64>,
    span: f64,
) -> Result<Pose> {
    let (w, h) = (camera.width as f64, camera.height as f64);
    let print = print_outline(target);
    let (min, max) = (print[0], print[2]);
    let centre = Vector3::new(0.5 * (min.x + max.x), 0.5 * (min.y + max.y), 0.0);
    let ray = camera.unproject(aim)?;
    let ray = ray / ray.z;
    let side = board_side_m(target);
    let mut span = span;
    for _ in 0..MAX_SHRINKS {
        let depth = camera.fx * side / (span * w);
        let t = ray * depth - rotation * centre;
        let pose = Pose::from_parts(Translation3::from(t), rotation);
        let inside = print.iter().all(|p| {
            camera.project(&(pose * p)).is_ok_and(|q| {
                q.x >= HOLD_MARGIN_PX
                    && q.y >= HOLD_MARGIN_PX
                    && q.x <= w - 1.0 - HOLD_MARGIN_PX
                    && q.y <= h - 1.0 - HOLD_MARGIN_PX
            })
        });
        if inside {
            return Ok(pose);
        }
        span *= SHRINK;
    }
    Err(Error::degenerate(format!(
        "no board size keeps the board aimed at ({:.0}, {:.0}) px inside the {}x{} image",
        aim.x, aim.y, camera.width, camera.height
    )))
}

/// The larger side of the board's points, metres; of its print
/// ([`print_outline`]) when the points have no extent (a single circle).
pub fn board_side_m(target: &Target) -> f64 {
    let (min, max) = extent(target.object_points().into_iter().map(|p| p.1));
    let side = (max.x - min.x).max(max.y - min.y);
    if side > 0.0 {
        return side;
    }
    let print = print_outline(target);
    (print[2].x - print[0].x).max(print[2].y - print[0].y)
}

/// Corners of the board's points grown by one point spacing on every side
/// (by two diameters for a single circle: the print around the points that
/// detection needs): min, (max.x, min.y), max, (min.x, max.y), in the
/// target frame.
pub fn print_outline(target: &Target) -> [Point3<f64>; 4] {
    let (min, max) = extent(target.object_points().into_iter().map(|p| p.1));
    let m = match target {
        Target::SingleCircle { diameter_m } => 2.0 * diameter_m,
        Target::Chessboard { .. }
        | Target::CircleGrid { .. }
        | Target::DotPlate { .. }
        | Target::SquareGrid { .. }
        | Target::Charuco { .. }
        | Target::Aprilgrid { .. }
        | Target::ArucoGrid { .. }
        | Target::OriginDotGrid { .. } => target.unit_m(),
    };
    let (a, b) = (
        Point3::new(min.x - m, min.y - m, 0.0),
        Point3::new(max.x + m, max.y + m, 0.0),
    );
    [a, Point3::new(b.x, a.y, 0.0), b, Point3::new(a.x, b.y, 0.0)]
}

fn extent(points: impl Iterator<Item = Point3<f64>>) -> (Point3<f64>, Point3<f64>) {
    points.fold(
        (
            Point3::new(f64::INFINITY, f64::INFINITY, 0.0),
            Point3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, 0.0),
        ),
        |(lo, hi), p| {
            (
                Point3::new(lo.x.min(p.x), lo.y.min(p.y), 0.0),
                Point3::new(hi.x.max(p.x), hi.y.max(p.y), 0.0),
            )
        },
    )
}
