//! The one JSON shape of a [`Pose`], written by every report, export and
//! the wasm API:
//!
//! ```json
//! {"matrix_row_major": [[r00, r01, r02, tx], [r10, r11, r12, ty], [r20, r21, r22, tz], [0, 0, 0, 1]],
//!  "translation_m": [tx, ty, tz],
//!  "quaternion_xyzw": [x, y, z, w]}
//! ```
//!
//! metres, the quaternion with `w >= 0` ([`PoseJson`], the only writer).
//! Inputs ([`PoseInput`]) may give the matrix alone (4 rows of 4 numbers, or
//! 16 numbers row by row), translation plus quaternion alone, or all three;
//! with all three the matrix must agree with the other two.
//!
//! On a `Pose` field: `#[serde(with = "crate::geometry::pose_serde")]` writes
//! [`PoseJson`] and reads [`PoseInput`].

use nalgebra::{Matrix4, Translation3, Vector3};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{
    matrix4_from_pose, pose_from_matrix4, quaternion_xyzw_from_rotation,
    rotation_from_quaternion_xyzw, Pose,
};
use crate::error::{Error, Result};

/// A pose as every report writes it: `p_a = a_from_b * p_b`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseJson {
    /// The 4x4 homogeneous matrix, row by row; translation in metres.
    pub matrix_row_major: [[f64; 4]; 4],
    /// Translation, metres.
    pub translation_m: [f64; 3],
    /// Rotation as a unit quaternion, order x, y, z, w, with `w >= 0`.
    pub quaternion_xyzw: [f64; 4],
}

impl From<&Pose> for PoseJson {
    fn from(pose: &Pose) -> Self {
        let m = matrix4_from_pose(pose);
        let t = pose.translation.vector;
        PoseJson {
            matrix_row_major: [0, 1, 2, 3].map(|r| [m[(r, 0)], m[(r, 1)], m[(r, 2)], m[(r, 3)]]),
            translation_m: [t.x, t.y, t.z],
            quaternion_xyzw: quaternion_xyzw_from_rotation(&pose.rotation),
        }
    }
}

impl PoseJson {
    /// The pose, read as any [`PoseInput`] (the quaternion, checked against
    /// the matrix).
    pub fn to_pose(&self) -> Result<Pose> {
        PoseInput::from(self).to_pose()
    }
}

/// Largest difference between an entry of `matrix_row_major` and the same
/// entry computed from `translation_m` and `quaternion_xyzw` (metres for
/// the translation column, unitless for the rotation block) for the two to
/// count as one pose. Far above the rounding of a written report (~1e-16),
/// far below any real disagreement.
pub const POSE_FORMS_AGREEMENT: f64 = 1e-6;

/// A `matrix_row_major` as read: 4 rows of 4 numbers or 16 numbers.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(try_from = "Vec<MatrixItem>")]
pub struct MatrixRowMajor(pub [f64; 16]);

/// One element of a `matrix_row_major` list: a number or a row.
#[derive(Deserialize)]
#[serde(untagged)]
enum MatrixItem {
    Number(f64),
    Row(Vec<f64>),
}

impl TryFrom<Vec<MatrixItem>> for MatrixRowMajor {
    type Error = String;
    fn try_from(items: Vec<MatrixItem>) -> std::result::Result<Self, String> {
        let mut numbers = Vec::with_capacity(16);
        let (mut flat, mut rows_of_4) = (0, 0);
        for item in &items {
            match item {
                MatrixItem::Number(x) => {
                    flat += 1;
                    numbers.push(*x);
                }
                MatrixItem::Row(r) => {
                    rows_of_4 += usize::from(r.len() == 4);
                    numbers.extend(r);
                }
            }
        }
        let shape_ok = (flat == 16 && items.len() == 16) || (rows_of_4 == 4 && items.len() == 4);
        let found = if flat == items.len() {
            format!("{flat} numbers")
        } else {
            let lengths: Vec<String> = items
                .iter()
                .map(|i| match i {
                    MatrixItem::Number(_) => "a number".to_string(),
                    MatrixItem::Row(r) => format!("{}", r.len()),
                })
                .collect();
            format!("rows of {}", lengths.join(", "))
        };
        match <[f64; 16]>::try_from(numbers) {
            Ok(m) if shape_ok => Ok(MatrixRowMajor(m)),
            _ => Err(format!(
                "expected matrix_row_major with 4 rows of 4 numbers (or 16 numbers), got {found}"
            )),
        }
    }
}

/// A pose as read from JSON: the keys of [`PoseJson`], each optional (see
/// the module docs for which combinations are accepted). Unknown keys are
/// ignored, so a pose inside a larger object reads as is.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
pub struct PoseInput {
    /// The 4x4 homogeneous matrix, row-major (translation in metres).
    #[serde(default)]
    pub matrix_row_major: Option<MatrixRowMajor>,
    /// Translation, metres.
    #[serde(default)]
    pub translation_m: Option<[f64; 3]>,
    /// Unit quaternion x, y, z, w (normalised when read).
    #[serde(default)]
    pub quaternion_xyzw: Option<[f64; 4]>,
}

impl From<&PoseJson> for PoseInput {
    fn from(p: &PoseJson) -> Self {
        let mut flat = [0.0; 16];
        for (i, v) in p.matrix_row_major.iter().flatten().enumerate() {
            flat[i] = *v;
        }
        PoseInput {
            matrix_row_major: Some(MatrixRowMajor(flat)),
            translation_m: Some(p.translation_m),
            quaternion_xyzw: Some(p.quaternion_xyzw),
        }
    }
}

impl PoseInput {
    /// The pose: from translation and quaternion when both are given
    /// (exactly what [`PoseJson`] wrote), else from the matrix (validated by
    /// [`pose_from_matrix4`]). With all three, errors unless the matrix
    /// agrees within [`POSE_FORMS_AGREEMENT`].
    pub fn to_pose(&self) -> Result<Pose> {
        let matrix = self.matrix_row_major.map(|m| Matrix4::from_row_slice(&m.0));
        let pose = match (self.translation_m, self.quaternion_xyzw, matrix) {
            (Some(t), Some(q), _) => Pose::from_parts(
                Translation3::from(Vector3::from(t)),
                rotation_from_quaternion_xyzw(q)?,
            ),
            (_, _, Some(m)) => return pose_from_matrix4(&m),
            (t, q, None) => {
                let only = match (t, q) {
                    (Some(_), None) => ", got translation_m alone",
                    (None, Some(_)) => ", got quaternion_xyzw alone",
                    _ => "",
                };
                return Err(Error::invalid(
                    "pose",
                    format!(
                        "expected matrix_row_major (4 rows of 4 numbers) or translation_m and quaternion_xyzw{only}"
                    ),
                ));
            }
        };
        if let Some(m) = matrix {
            let gap = (matrix4_from_pose(&pose) - m).amax();
            if !(gap <= POSE_FORMS_AGREEMENT) {
                return Err(Error::invalid(
                    "matrix_row_major",
                    format!(
                        "differs from translation_m and quaternion_xyzw by {gap:.3e} (largest entry, tolerance {POSE_FORMS_AGREEMENT:.0e}); give one form, or both for the same pose"
                    ),
                ));
            }
        }
        Ok(pose)
    }
}

/// Writes a pose as [`PoseJson`].
pub fn serialize<S: Serializer>(
    pose: &Pose,
    serializer: S,
) -> std::result::Result<S::Ok, S::Error> {
    PoseJson::from(pose).serialize(serializer)
}

/// Reads a pose as [`PoseInput`].
pub fn deserialize<'de, D: Deserializer<'de>>(
    deserializer: D,
) -> std::result::Result<Pose, D::Error> {
    PoseInput::deserialize(deserializer)?
        .to_pose()
        .map_err(serde::de::Error::custom)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::rotation_from_rotvec;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[derive(Serialize, Deserialize, Debug, PartialEq)]
    struct Holder {
        #[serde(with = "super")]
        base_from_gripper: Pose,
    }

    fn half_turn() -> Pose {
        let r = rotation_from_rotvec(&Vector3::new(0.0, 0.0, std::f64::consts::PI));
        Pose::from_parts(Translation3::new(1.0, 2.0, 0.5), r)
    }

    fn read(json: &str) -> std::result::Result<Holder, String> {
        serde_json::from_str::<Holder>(json).map_err(|e| e.to_string())
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn json_round_trip_and_names() {
        let h = Holder {
            base_from_gripper: half_turn(),
        };
        let json = serde_json::to_string(&h).unwrap();
        assert_eq!(
            json,
            concat!(
                r#"{"base_from_gripper":{"matrix_row_major":[[-1.0,-1.2246467991473532e-16,0.0,1.0],"#,
                r#"[1.2246467991473532e-16,-1.0,0.0,2.0],[0.0,0.0,1.0,0.5],[0.0,0.0,0.0,1.0]],"#,
                r#""translation_m":[1.0,2.0,0.5],"quaternion_xyzw":[0.0,0.0,1.0,6.123233995736766e-17]}}"#
            )
        );
        assert_eq!(
            read(&json).unwrap(),
            h,
            "a written pose reads back bit for bit"
        );
        let bad = r#"{"base_from_gripper":{"translation_m":[0,0,0],"quaternion_xyzw":[0,0,0,0]}}"#;
        let err = read(bad).unwrap_err();
        assert!(
            err.starts_with("quaternion_xyzw: quaternion has norm 0: not a rotation"),
            "{err}"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn every_accepted_form_reads_and_contradictions_are_refused() {
        let p = half_turn();
        let rows = r#"{"base_from_gripper":{"matrix_row_major":[[-1,0,0,1],[0,-1,0,2],[0,0,1,0.5],[0,0,0,1]]}}"#;
        let flat =
            r#"{"base_from_gripper":{"matrix_row_major":[-1,0,0,1,0,-1,0,2,0,0,1,0.5,0,0,0,1]}}"#;
        for json in [rows, flat] {
            let got = read(json).unwrap().base_from_gripper;
            assert!(
                (got.to_homogeneous() - p.to_homogeneous()).amax() < 1e-12,
                "{json}"
            );
        }
        let err = read(r#"{"base_from_gripper":{"matrix_row_major":[1,2]}}"#).unwrap_err();
        assert!(
            err.starts_with(
                "expected matrix_row_major with 4 rows of 4 numbers (or 16 numbers), got 2 numbers"
            ),
            "{err}"
        );
        let err = read(r#"{"base_from_gripper":{"translation_m":[0,0,0]}}"#).unwrap_err();
        assert!(
            err.starts_with("pose: expected matrix_row_major (4 rows of 4 numbers) or translation_m and quaternion_xyzw, got translation_m alone"),
            "{err}"
        );
        let contradiction = r#"{"base_from_gripper":{"matrix_row_major":[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]],"translation_m":[0,0,0.1],"quaternion_xyzw":[0,0,0,1]}}"#;
        let err = read(contradiction).unwrap_err();
        assert!(
            err.starts_with("matrix_row_major: differs from translation_m and quaternion_xyzw by 1.000e-1 (largest entry, tolerance 1e-6)"),
            "{err}"
        );
        let written = PoseJson::from(&p);
        assert!(written.quaternion_xyzw[3] >= 0.0);
        assert_eq!(written.to_pose().unwrap(), p);
    }
}
