//! Exports of a laser plane: the plane as a frame (z along the normal) in
//! the transform formats ([`crate::io::export_transform`]: URDF, ROS static
//! TF, ...), and a HALCON-style sheet-of-light parameter list.

use crate::error::Result;
use crate::io::export_camera::float;
use crate::io::export_transform::{export_transform, FrameNames, TransformFormat};
use crate::laser::LaserPlane;
use nalgebra::Matrix4;

/// The plane in a transform format, as the frame `camera_from_laser_plane`.
pub fn export_plane_frame(plane: &LaserPlane, format: TransformFormat) -> Result<String> {
    let names = FrameNames::from_transform_name("camera_from_laser_plane")?;
    Ok(export_transform(&plane.a_from_plane(), &names, format))
}

/// A HALCON-style parameter list: the light plane's pose in the camera
/// frame as a HALCON pose `[tx, ty, tz, alpha, beta, gamma, 0]` (metres,
/// degrees, type 0 = 'Rp+T', 'gba', 'point': R = Rx(alpha) Ry(beta)
/// Rz(gamma)), its z = 0 plane the light plane, plus the plane's normal,
/// distance and their standard deviations.
pub fn export_plane_halcon(plane: &LaserPlane, covariance: &Matrix4<f64>) -> String {
    let pose = plane.a_from_plane();
    let r = pose.rotation.to_rotation_matrix();
    let m = r.matrix();
    let beta = m[(0, 2)].clamp(-1.0, 1.0).asin();
    let alpha = (-m[(1, 2)]).atan2(m[(2, 2)]);
    let gamma = (-m[(0, 1)]).atan2(m[(0, 0)]);
    let t = pose.translation.vector;
    let n = plane.normal;
    let std = |i: usize| covariance[(i, i)].max(0.0).sqrt();
    format!(
        "* robocal laser plane, HALCON-style sheet-of-light parameters\n\
         * LightplanePose: pose of the light plane (its z = 0) in the camera frame,\n\
         * [tx, ty, tz (m), alpha, beta, gamma (deg), type 0 ('Rp+T', 'gba', 'point')]\n\
         LightplanePose := [{}, {}, {}, {}, {}, {}, 0]\n\
         * the plane n . X = d in the camera frame (m) and the standard deviations\n\
         LightplaneNormal := [{}, {}, {}]\n\
         LightplaneDistance := {}\n\
         LightplaneNormalStd := [{}, {}, {}]\n\
         LightplaneDistanceStd := {}\n",
        float(t.x),
        float(t.y),
        float(t.z),
        float(alpha.to_degrees()),
        float(beta.to_degrees()),
        float(gamma.to_degrees()),
        float(n[0]),
        float(n[1]),
        float(n[2]),
        float(plane.distance_m),
        float(std(0)),
        float(std(1)),
        float(std(2)),
        float(std(3)),
    )
}
