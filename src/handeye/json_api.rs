//! The JSON-in, JSON-out entry point used by the wasm boundary
//! (`solve_handeye`) and by anything else that speaks JSON.
//!
//! Input: `{"setup": "eye-in-hand" | "eye-to-hand", "base_from_gripper":
//! [pose...], "camera_from_target": [pose...], "method": "all" | NAME,
//! "bootstrap_samples": 100, "seed": 1, "strict_checks": true}` where a pose
//! is `{"matrix_row_major": [[4 numbers] x 4]}` or `{"translation_m": [x, y,
//! z], "quaternion_xyzw": [x, y, z, w]}` (metres). Output: the
//! [`super::output::HandEyeReport`] JSON.

use super::output::HandEyeReport;
use super::solve::{calibrate, HandEyeInput, HandEyeOptions, DEFAULT_BOOTSTRAP_SAMPLES};
use super::{HandEyeMethod, Pose, Setup};
use crate::error::{Error, Result};
use crate::geometry::{pose_from_matrix4, rotation_from_quaternion_xyzw};
use nalgebra::{Matrix4, Translation3, Vector3};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(untagged)]
enum PoseIn {
    Matrix {
        matrix_row_major: [[f64; 4]; 4],
    },
    Quaternion {
        translation_m: [f64; 3],
        quaternion_xyzw: [f64; 4],
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InputJson {
    setup: Setup,
    base_from_gripper: Vec<PoseIn>,
    camera_from_target: Vec<PoseIn>,
    #[serde(default)]
    method: Option<String>,
    #[serde(default)]
    bootstrap_samples: Option<usize>,
    #[serde(default)]
    seed: Option<u64>,
    #[serde(default)]
    strict_checks: Option<bool>,
}

fn to_pose(p: &PoseIn, field: &str, index: usize) -> Result<Pose> {
    let located = |e: Error| Error::invalid(format!("{field}[{index}]"), e.to_string());
    match p {
        PoseIn::Matrix {
            matrix_row_major: m,
        } => {
            let flat: Vec<f64> = m.iter().flatten().copied().collect();
            pose_from_matrix4(&Matrix4::from_row_slice(&flat)).map_err(located)
        }
        PoseIn::Quaternion {
            translation_m: t,
            quaternion_xyzw: q,
        } => {
            let r = rotation_from_quaternion_xyzw(*q).map_err(located)?;
            Ok(Pose::from_parts(Translation3::from(Vector3::from(*t)), r))
        }
    }
}

/// Solve from input JSON; returns the report JSON.
pub fn solve_handeye_json(input_json: &str) -> Result<String> {
    let input: InputJson = serde_json::from_str(input_json)
        .map_err(|e| Error::parse(e.line(), e.column(), e.to_string()))?;
    let poses = |list: &[PoseIn], field: &str| -> Result<Vec<Pose>> {
        list.iter()
            .enumerate()
            .map(|(i, p)| to_pose(p, field, i))
            .collect()
    };
    let mut options = HandEyeOptions {
        bootstrap_samples: input.bootstrap_samples.unwrap_or(DEFAULT_BOOTSTRAP_SAMPLES),
        seed: input.seed.unwrap_or(1),
        strict_checks: input.strict_checks.unwrap_or(true),
        ..Default::default()
    };
    match input.method.as_deref() {
        None | Some("all") => {}
        Some(name) => options.methods = vec![name.parse::<HandEyeMethod>()?],
    }
    let request = HandEyeInput {
        setup: input.setup,
        base_from_gripper: poses(&input.base_from_gripper, "base_from_gripper")?,
        camera_from_target: poses(&input.camera_from_target, "camera_from_target")?,
    };
    let result = calibrate(&request, &options)?;
    serde_json::to_string(&HandEyeReport::new(&result))
        .map_err(|e| Error::invalid("report", e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::handeye::{handeye_scene, HandEyeSceneConfig};
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn json_round_trip_gives_the_contract_keys() {
        let scene = handeye_scene(&HandEyeSceneConfig::noise_free(Setup::EyeToHand, 6), 9);
        let quat = |p: &Pose| {
            let t = p.translation.vector;
            let q = p.rotation;
            serde_json::json!({"translation_m": [t.x, t.y, t.z], "quaternion_xyzw": [q.i, q.j, q.k, q.w]})
        };
        let mat = |p: &Pose| {
            let m = p.to_homogeneous();
            let rows: Vec<Vec<f64>> = (0..4)
                .map(|r| (0..4).map(|c| m[(r, c)]).collect())
                .collect();
            serde_json::json!({ "matrix_row_major": rows })
        };
        let input = serde_json::json!({
            "setup": "eye-to-hand",
            "base_from_gripper": scene.base_from_gripper.iter().map(mat).collect::<Vec<_>>(),
            "camera_from_target": scene.camera_from_target.iter().map(quat).collect::<Vec<_>>(),
            "bootstrap_samples": 5,
        });
        let out: serde_json::Value =
            serde_json::from_str(&solve_handeye_json(&input.to_string()).unwrap()).unwrap();
        let t = &out["base_from_camera"]["translation_m"];
        let truth = scene.x_true.translation.vector;
        for k in 0..3 {
            let v = t[k].as_f64().unwrap();
            assert!(
                (v - truth[k]).abs() < 1e-9,
                "translation {k}: {v} vs {}",
                truth[k]
            );
        }
        assert!(out["gripper_from_target"]["quaternion_xyzw"].is_array());
        assert!(out["gripper_from_camera"].is_null());
        assert_eq!(out["methods"].as_array().unwrap().len(), 8);
        for key in [
            "translation_rms_mm",
            "translation_max_mm",
            "rotation_rms_deg",
            "rotation_max_deg",
        ] {
            assert!(out["errors"][key].as_f64().unwrap() < 1e-6, "{key}");
        }
        assert!(out["errors"]["reprojection_rms_px"].is_null());
        assert!(out["warnings"].as_array().unwrap().is_empty());
        let bad = solve_handeye_json(
            r#"{"setup":"eye-in-hand","base_from_gripper":[],"camera_from_target":[],"method":"tsai"}"#,
        );
        assert_eq!(
            bad.unwrap_err().to_string(),
            "method: unknown method 'tsai' (valid: tsai-lenz, park-martin, horaud, andreff, \
             daniilidis, chou-kamel, shah, li)"
        );
    }
}
