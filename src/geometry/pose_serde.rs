//! Serde form of a [`Pose`]: `{"translation_m": [x, y, z], "quaternion_xyzw":
//! [x, y, z, w]}`, units and component order in the key names.
//!
//! Use on a field with `#[serde(with = "crate::geometry::pose_serde")]`.
//! Deserialising normalises the quaternion and rejects a zero or non-finite
//! one.

use nalgebra::{Translation3, Vector3};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{quaternion_xyzw_from_rotation, rotation_from_quaternion_xyzw, Pose};

#[derive(Serialize, Deserialize)]
struct PoseJson {
    translation_m: [f64; 3],
    quaternion_xyzw: [f64; 4],
}

/// Writes a pose as `{"translation_m", "quaternion_xyzw"}`.
pub fn serialize<S: Serializer>(pose: &Pose, serializer: S) -> Result<S::Ok, S::Error> {
    let t = pose.translation.vector;
    PoseJson {
        translation_m: [t.x, t.y, t.z],
        quaternion_xyzw: quaternion_xyzw_from_rotation(&pose.rotation),
    }
    .serialize(serializer)
}

/// Reads a pose written by [`serialize`].
pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Pose, D::Error> {
    let p = PoseJson::deserialize(deserializer)?;
    let rotation =
        rotation_from_quaternion_xyzw(p.quaternion_xyzw).map_err(serde::de::Error::custom)?;
    let t = Translation3::from(Vector3::from(p.translation_m));
    Ok(Pose::from_parts(t, rotation))
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

    #[wasm_bindgen_test(unsupported = test)]
    fn json_round_trip_and_names() {
        let r = rotation_from_rotvec(&Vector3::new(0.0, 0.0, std::f64::consts::PI));
        let h = Holder {
            base_from_gripper: Pose::from_parts(Translation3::new(1.0, 2.0, 0.5), r),
        };
        let json = serde_json::to_string(&h).unwrap();
        assert_eq!(
            json,
            r#"{"base_from_gripper":{"translation_m":[1.0,2.0,0.5],"quaternion_xyzw":[0.0,0.0,1.0,6.123233995736766e-17]}}"#
        );
        let back: Holder = serde_json::from_str(&json).unwrap();
        assert_eq!(back, h);
        let bad = r#"{"base_from_gripper":{"translation_m":[0,0,0],"quaternion_xyzw":[0,0,0,0]}}"#;
        let err = serde_json::from_str::<Holder>(bad).unwrap_err().to_string();
        assert!(
            err.starts_with("quaternion_xyzw: quaternion has norm 0: not a rotation"),
            "{err}"
        );
    }
}
