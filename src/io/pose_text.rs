//! A plain text file of poses, one per line: 16 numbers (a row-major 4x4
//! matrix), 12 numbers (its top 3x4), or 7 numbers (translation + quaternion,
//! order named by [`PoseTextFormat`]). Separators: spaces, tabs, commas,
//! semicolons; `#` starts a comment. Units: metres.
//!
//! This is the `--camera-poses` format (camera_from_target per view); the
//! robot pose parsers beside it in `crate::io` cover controller-specific formats.

use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::{Matrix3, Quaternion, Rotation3, Translation3, UnitQuaternion};

/// How to read a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoseTextFormat {
    /// 16 or 12 numbers: a row-major homogeneous matrix.
    Matrix,
    /// `x y z qx qy qz qw`.
    XyzQuaternionXyzw,
    /// `x y z qw qx qy qz`.
    XyzQuaternionWxyz,
}

impl std::str::FromStr for PoseTextFormat {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "matrix" => Ok(PoseTextFormat::Matrix),
            "xyz-quaternion-xyzw" => Ok(PoseTextFormat::XyzQuaternionXyzw),
            "xyz-quaternion-wxyz" => Ok(PoseTextFormat::XyzQuaternionWxyz),
            _ => Err(Error::invalid(
                "pose format",
                format!(
                    "unknown pose format '{s}' (valid: matrix, xyz-quaternion-xyzw, \
                     xyz-quaternion-wxyz)"
                ),
            )),
        }
    }
}

/// Tolerance on `R^T R = I` for matrix rows (rounded files pass, typos fail).
const ORTHONORMAL_TOLERANCE: f64 = 1e-3;

/// Parse one pose per non-empty line. `format` `None` accepts matrices only
/// and asks for the quaternion order when a line has 7 numbers.
pub fn parse_pose_text(text: &str, format: Option<PoseTextFormat>) -> Result<Vec<Pose>> {
    let mut poses = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line_no = index + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut values = Vec::new();
        for (col, field) in line
            .split(|c: char| c.is_whitespace() || c == ',' || c == ';')
            .filter(|f| !f.is_empty())
            .enumerate()
        {
            let v = field.parse::<f64>().ok().ok_or_else(|| {
                Error::parse(line_no, col + 1, format!("'{field}' is not a number"))
            })?;
            values.push(v);
        }
        poses.push(pose_from_values(&values, format, line_no)?);
    }
    if poses.is_empty() {
        return Err(Error::parse(
            0,
            0,
            "the pose file has no poses: expected one pose per line",
        ));
    }
    Ok(poses)
}

fn pose_from_values(v: &[f64], format: Option<PoseTextFormat>, line: usize) -> Result<Pose> {
    match (v.len(), format) {
        (16 | 12, None | Some(PoseTextFormat::Matrix)) => {
            let bottom_off = v[12..]
                .iter()
                .zip([0.0, 0.0, 0.0, 1.0])
                .any(|(a, b)| !((a - b).abs() <= ORTHONORMAL_TOLERANCE));
            if v.len() == 16 && bottom_off {
                return Err(Error::parse(
                    line,
                    0,
                    format!(
                        "the bottom row of the 4x4 matrix is [{} {} {} {}], expected [0 0 0 1]: \
                         write the matrix row by row",
                        v[12], v[13], v[14], v[15]
                    ),
                ));
            }
            let r = Matrix3::new(v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]);
            let err = (r.transpose() * r - Matrix3::identity()).abs().max();
            if err > ORTHONORMAL_TOLERANCE || r.determinant() < 0.0 {
                return Err(Error::parse(
                    line,
                    0,
                    format!(
                        "the 3x3 block is not a rotation (|R^T R - I| = {err:.2e}, det = {:.4})",
                        r.determinant()
                    ),
                ));
            }
            let rot = Rotation3::from_matrix_eps(&r, 1e-12, 100, Rotation3::identity());
            Ok(Pose::from_parts(
                Translation3::new(v[3], v[7], v[11]),
                UnitQuaternion::from_rotation_matrix(&rot),
            ))
        }
        (7, Some(f @ (PoseTextFormat::XyzQuaternionXyzw | PoseTextFormat::XyzQuaternionWxyz))) => {
            let q = match f {
                PoseTextFormat::XyzQuaternionXyzw => Quaternion::new(v[6], v[3], v[4], v[5]),
                _ => Quaternion::new(v[3], v[4], v[5], v[6]),
            };
            let n = q.norm();
            if (n - 1.0).abs() > ORTHONORMAL_TOLERANCE {
                return Err(Error::parse(
                    line,
                    0,
                    format!("quaternion norm is {n:.6}, expected 1"),
                ));
            }
            Ok(Pose::from_parts(
                Translation3::new(v[0], v[1], v[2]),
                UnitQuaternion::new_normalize(q),
            ))
        }
        (7, _) => Err(Error::parse(
            line,
            0,
            "7 numbers (translation + quaternion): say the quaternion order with the format \
             xyz-quaternion-xyzw or xyz-quaternion-wxyz",
        )),
        (n, _) => Err(Error::parse(
            line,
            0,
            format!(
                "expected 16 or 12 numbers (row-major matrix) or 7 (xyz + quaternion), got {n}"
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn matrices_and_quaternions_parse_and_mistakes_are_located() {
        let text = "# comment\n1 0 0 0.5\t0 -1 0 0 0 0 -1 2 0 0 0 1\n\n0,0,0,1,0,0,0\n";
        let e = parse_pose_text(text, None).unwrap_err().to_string();
        assert_eq!(
            e,
            "line 4: 7 numbers (translation + quaternion): say the quaternion order with the \
             format xyz-quaternion-xyzw or xyz-quaternion-wxyz"
        );
        let poses = parse_pose_text("1 0 0 0.5 0 -1 0 0 0 0 -1 2 0 0 0 1\n", None).unwrap();
        assert_eq!(poses[0].translation.vector.z, 2.0);
        assert!((poses[0].rotation.angle() - std::f64::consts::PI).abs() < 1e-12);
        let q = parse_pose_text(
            "1 2 3 0 0 0.7071067811865476 0.7071067811865476",
            Some(PoseTextFormat::XyzQuaternionXyzw),
        )
        .unwrap();
        assert!((q[0].rotation.angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(
            parse_pose_text("1 0 0 x", None).unwrap_err().to_string(),
            "line 1, column 4: 'x' is not a number"
        );
    }
}
