//! The warning for a joint refinement (`refine: joint_intrinsics`) that moves
//! the camera intrinsics far from their calibration.
//!
//! The joint refinement lets fx, fy, cx and cy absorb whatever does not fit:
//! with robot poses less accurate than the images, the intrinsics drift by
//! hundreds of their calibrated standard deviations and the hand-eye closure
//! gets worse while the reprojection improves. When a camera calibration's
//! standard deviations are known, a move by more than
//! [`INTRINSIC_MOVE_ALERT_STD`] of them is named, with what it suggests.

use crate::camera::Camera;
use crate::handeye::HandEyeResult;
use std::collections::BTreeMap;

/// A move of an intrinsic by more than this many of its calibrated standard
/// deviations is warned about (a consistent data set moves them by a few).
pub const INTRINSIC_MOVE_ALERT_STD: f64 = 10.0;

/// The standard deviations of a camera calibration JSON: the `std` object of
/// a calibration report (`{"report": {"std": ...}}` or `{"std": ...}`), or
/// `None` when the JSON carries none (a bare camera).
pub fn std_from_json(value: &serde_json::Value) -> Option<BTreeMap<String, f64>> {
    let report = value.get("report").unwrap_or(value);
    let std = report.get("std")?.as_object()?;
    let map: BTreeMap<String, f64> = std
        .iter()
        .filter_map(|(k, v)| v.as_f64().map(|x| (k.clone(), x)))
        .collect();
    (!map.is_empty()).then_some(map)
}

/// The warning for `refined` against the calibrated `before` with standard
/// deviations `std` (intrinsics whose std is 0, i.e. held, or absent are not
/// judged); `None` when every intrinsic moved less than
/// [`INTRINSIC_MOVE_ALERT_STD`] standard deviations.
pub fn intrinsic_move_warning(
    before: &Camera,
    refined: &Camera,
    std: &BTreeMap<String, f64>,
) -> Option<String> {
    let moved: Vec<String> = [
        ("fx", before.fx, refined.fx),
        ("fy", before.fy, refined.fy),
        ("cx", before.cx, refined.cx),
        ("cy", before.cy, refined.cy),
    ]
    .into_iter()
    .filter_map(|(name, a, b)| {
        let s = *std.get(name)?;
        let k = (b - a).abs() / s;
        (s > 0.0 && k.is_finite() && k > INTRINSIC_MOVE_ALERT_STD)
            .then(|| format!("{name} from {a:.2} to {b:.2} px ({k:.0} std)"))
    })
    .collect();
    if moved.is_empty() {
        return None;
    }
    Some(format!(
        "the joint refinement moved the camera intrinsics far beyond their calibrated \
         uncertainty: {}. The robot poses and the images disagree, and the intrinsics absorbed \
         it: the robot poses are probably less accurate than the camera (use the refinement \
         with robot pose noise estimated, or the one with robot poses exact, and keep the \
         camera calibration), or the camera changed (focus, zoom) between the calibration and \
         these images (then calibrate the camera again from these images)",
        moved.join(", ")
    ))
}

/// Add the warning of [`intrinsic_move_warning`] to `result` when its
/// refinement refined the camera (joint-intrinsics mode).
pub fn warn_intrinsic_move(
    result: &mut HandEyeResult,
    before: &Camera,
    std: Option<&BTreeMap<String, f64>>,
) {
    let refined = result.refinement.as_ref().and_then(|r| r.camera.as_ref());
    if let (Some(refined), Some(std)) = (refined, std) {
        if let Some(w) = intrinsic_move_warning(before, refined, std) {
            result.warnings.push(w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn std() -> BTreeMap<String, f64> {
        [("fx", 0.05), ("fy", 0.05), ("cx", 0.1), ("cy", 0.0)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn a_move_of_many_std_is_named_with_what_it_suggests() {
        let before = Camera::pinhole(1056.0, 1056.0, 640.0, 480.0, 1280, 960);
        // fx by 10 px = 200 std; cx by 0.5 px = 5 std (within); cy held (std 0).
        let refined = Camera::pinhole(1046.0, 1056.2, 640.5, 470.0, 1280, 960);
        let w = intrinsic_move_warning(&before, &refined, &std()).expect("warning");
        assert!(
            w.contains("the camera intrinsics far beyond their calibrated uncertainty: fx from 1056.00 to 1046.00 px (200 std)."),
            "{w}"
        );
        assert!(!w.contains("cx") && !w.contains("cy"), "{w}");
        assert!(
            w.contains("the robot poses are probably less accurate"),
            "{w}"
        );
        // fy by 0.2 px = 4 std: no warning.
        let close = Camera::pinhole(1056.0, 1056.2, 640.0, 480.0, 1280, 960);
        assert_eq!(intrinsic_move_warning(&before, &close, &std()), None);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn the_std_comes_from_a_calibration_report_and_a_bare_camera_has_none() {
        let report = json!({"report": {"std": {"fx": 0.5, "k1": 0.001}, "rms_px": 0.2}});
        let s = std_from_json(&report).unwrap();
        assert_eq!((s["fx"], s["k1"]), (0.5, 0.001));
        assert_eq!(
            std_from_json(&json!({"std": {"fy": 2.0}})).unwrap()["fy"],
            2.0
        );
        assert_eq!(std_from_json(&json!({"fx": 800.0, "fy": 800.0})), None);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn the_json_api_warns_when_the_joint_refinement_moves_fx_and_not_when_trusted() {
        use crate::api::handeye::solve_handeye_json;
        use crate::geometry::PoseJson;
        use crate::handeye::refine::pixel_problem_tests::{camera, looking_scene};
        use crate::handeye::Setup;
        use crate::synth::handeye::project_grid;
        // Noise-free views of a camera with fx = fy = 800, solved from a
        // calibration 2 % off (816) whose std says 0.5 px: the joint
        // refinement must move fx by 16 px = 32 std.
        let scene = looking_scene(Setup::EyeInHand, 8, 4);
        let views = project_grid(&scene, &camera(), (9, 6, 0.03), 0.0, 1);
        let views: Vec<_> = views
            .iter()
            .map(|v| {
                json!({
                    "object_m": v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                    "image_px": v.image_px.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
                })
            })
            .collect();
        let robots: Vec<_> = scene
            .base_from_gripper
            .iter()
            .map(|p| serde_json::to_value(PoseJson::from(p)).unwrap())
            .collect();
        let mut off = camera();
        (off.fx, off.fy) = (816.0, 816.0);
        let solve = |refine: &str, std: serde_json::Value| {
            let input = json!({
                "setup": "eye-in-hand", "base_from_gripper": robots, "camera": off,
                "camera_std": std, "views": views, "refine": refine, "bootstrap_samples": 0,
            });
            let out: serde_json::Value =
                serde_json::from_str(&solve_handeye_json(&input.to_string()).unwrap()).unwrap();
            out["warnings"]
                .as_array()
                .unwrap()
                .iter()
                .map(|w| w.as_str().unwrap().to_string())
                .collect::<Vec<_>>()
        };
        let std = json!({"fx": 0.5, "fy": 0.5, "cx": 0.5, "cy": 0.5});
        let joint = solve("joint_intrinsics", std.clone());
        let moved: Vec<_> = joint
            .iter()
            .filter(|w| w.starts_with("the joint refinement moved"))
            .collect();
        assert_eq!(moved.len(), 1, "{joint:?}");
        assert!(
            moved[0].contains("fx from 816.00 to 800.00 px (32 std)"),
            "{}",
            moved[0]
        );
        let trusted = solve("trusted", std);
        assert!(
            !trusted
                .iter()
                .any(|w| w.starts_with("the joint refinement")),
            "{trusted:?}"
        );
        // Without a std (a bare camera), nothing is judged.
        let bare = solve("joint_intrinsics", serde_json::Value::Null);
        assert!(
            !bare.iter().any(|w| w.starts_with("the joint refinement")),
            "{bare:?}"
        );
    }
}
