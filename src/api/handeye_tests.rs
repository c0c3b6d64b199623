//! Tests of the hand-eye JSON API: the contract keys and the ranking of
//! pose readings, on seeded synthetic scenes.

use super::handeye::*;
use crate::handeye::{Pose, Setup};
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
    // Six poses: named as too few, nothing else.
    let warnings = out["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0]
            .as_str()
            .unwrap()
            .starts_with("weak geometry: only 6 poses: "),
        "{warnings:?}"
    );
    let bad = solve_handeye_json(
        r#"{"setup":"eye-in-hand","base_from_gripper":[],"camera_from_target":[],"method":"tsai"}"#,
    );
    assert_eq!(
        bad.unwrap_err().to_string(),
        "method: unknown method 'tsai' (valid: tsai-lenz, park-martin, horaud, andreff, \
         daniilidis, chou-kamel, shah, li)"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn candidates_are_ranked_through_json_best_first() {
    let scene = handeye_scene(&HandEyeSceneConfig::opencv_noise(Setup::EyeInHand, 10), 8);
    let quat = |p: &Pose| {
        let t = p.translation.vector;
        let q = p.rotation;
        serde_json::json!({"translation_m": [t.x, t.y, t.z], "quaternion_xyzw": [q.i, q.j, q.k, q.w]})
    };
    // Wrong readings: rotation transposed, and the pose inverted.
    let transposed: Vec<_> = scene
        .base_from_gripper
        .iter()
        .map(|p| quat(&Pose::from_parts(p.translation, p.rotation.inverse())))
        .collect();
    let inverted: Vec<_> = scene
        .base_from_gripper
        .iter()
        .map(|p| quat(&p.inverse()))
        .collect();
    let right: Vec<_> = scene.base_from_gripper.iter().map(quat).collect();
    let input = serde_json::json!({
        "setup": "eye-in-hand",
        "candidates": [
            {"name": "transposed", "base_from_gripper": transposed},
            {"name": "xyz-euler", "base_from_gripper": right},
            {"name": "inverted", "base_from_gripper": inverted},
        ],
        "camera_from_target": scene.camera_from_target.iter().map(quat).collect::<Vec<_>>(),
    });
    let out: serde_json::Value =
        serde_json::from_str(&rank_candidates_json(&input.to_string()).unwrap()).unwrap();
    let scores = out["scores"].as_array().unwrap();
    assert_eq!(scores.len(), 3);
    assert_eq!(scores[0]["name"], "xyz-euler");
    // The right reading's residual comes from 0.002 rad camera noise.
    let best = scores[0]["consistency"]["rotation_rms_deg"]
        .as_f64()
        .unwrap();
    assert!(best < 1.0, "{best} deg");
    for s in &scores[1..] {
        let r = s["consistency"]["rotation_rms_deg"].as_f64().unwrap();
        assert!(r > 5.0 * best, "{}: {r} deg", s["name"]);
    }
    let text = out["recommendation"].as_str().unwrap();
    assert!(
        text.starts_with("pose format 'xyz-euler' fits the camera motion best"),
        "{text}"
    );
    // The same candidates with the wrong setup chosen: the inverted
    // reading fits it, and the right reading fits the other setup as
    // well: the advice names the setup as a candidate.
    let mut wrong = input.clone();
    wrong["setup"] = "eye-to-hand".into();
    let out: serde_json::Value =
        serde_json::from_str(&rank_candidates_json(&wrong.to_string()).unwrap()).unwrap();
    assert_eq!(out["scores"][0]["name"], "inverted");
    let text = out["recommendation"].as_str().unwrap();
    assert!(
        text.contains("; 'xyz-euler' fits eye-in-hand as well (rotation RMS 0."),
        "{text}"
    );
    assert!(text.ends_with("so choose the setup of the robot cell first (eye-in-hand: the camera on the gripper), then the reading that fits it"), "{text}");
    // Without the inverted reading, only the other setup fits: said first.
    let mut no_inverse = wrong.clone();
    no_inverse["candidates"].as_array_mut().unwrap().pop();
    let out: serde_json::Value =
        serde_json::from_str(&rank_candidates_json(&no_inverse.to_string()).unwrap()).unwrap();
    let text = out["recommendation"].as_str().unwrap();
    assert!(
        text.starts_with(
            "these poses fit eye-in-hand (the camera on the gripper), not the eye-to-hand chosen"
        ),
        "{text}"
    );
    let empty = r#"{"setup":"eye-in-hand","candidates":[],"camera_from_target":[]}"#;
    assert_eq!(
        rank_candidates_json(empty).unwrap_err().to_string(),
        "requires at least 1 pose candidates, got 0"
    );
}
