//! The refinement over pixels ([`crate::handeye::refine::pixel_problem`])
//! run from a closed-form [`HandEyeResult`]: the primary closed form seeds
//! the reprojection Levenberg-Marquardt, and the findings
//! ([`PixelFindings`]) go back to the orchestrator, which makes the refined
//! transforms the primary result (`method` = `refined from <closed form>`),
//! fills `errors.reprojection_rms_px` and keeps every closed form listed in
//! `methods` with its own reprojection RMS.

use crate::calib::View;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::handeye::refine::pixel_problem::refine;
pub use crate::handeye::refine::pixel_summary::{RefineMode, RefinementSummary};
use crate::handeye::{Chain, Pose};
use crate::handeye::{HandEyeInput, HandEyeResult};

/// Reprojection RMS (px) of `(x, y)`: view `i` sees the target through
/// `x^-1 * robot[i]^-1 * y`.
pub fn reprojection_rms_px(
    chain: &Chain,
    views: &[View],
    camera: &Camera,
    x: &Pose,
    y: &Pose,
) -> Result<f64> {
    reprojection_rms_per_view_px(chain, views, camera, x, y).map(|(all, _)| all)
}

/// Reprojection RMS (px) of `(x, y)` over every point and per view (0 for a
/// view without points): view `i`'s target points are projected through
/// the chain's implied `camera_from_target = x^-1 * robot[i]^-1 * y`
/// (eye-in-hand `camera_from_gripper * gripper_from_base[i] *
/// base_from_target`, eye-to-hand `camera_from_base * base_from_gripper[i] *
/// gripper_from_target`), not through the view's own PnP pose.
pub fn reprojection_rms_per_view_px(
    chain: &Chain,
    views: &[View],
    camera: &Camera,
    x: &Pose,
    y: &Pose,
) -> Result<(f64, Vec<f64>)> {
    let (mut sum, mut count) = (0.0, 0usize);
    let mut per_view = Vec::with_capacity(views.len());
    for (i, (view, robot)) in views.iter().zip(&chain.robot).enumerate() {
        let camera_from_target = x.inverse() * robot.inverse() * y;
        let (mut view_sum, mut view_count) = (0.0, 0usize);
        for (p, obs) in view.object_m.iter().zip(&view.image_px) {
            let q = camera_from_target * p;
            let projected = camera.project(&q).map_err(|e| {
                let what = if q.z <= 0.0 {
                    format!("lies behind the camera (z = {:.4} m)", q.z)
                } else {
                    format!(
                        "(z = {:.4} m) does not project through the lens model ({e}): \
                         the robot pose of that view does not fit its image; check the \
                         pairing of poses with images",
                        q.z
                    )
                };
                Error::degenerate(format!(
                    "through the solved transforms and view {} a target point {what}",
                    i + 1,
                ))
            })?;
            let e2 = (projected - obs).norm_squared();
            sum += e2;
            view_sum += e2;
            count += 1;
            view_count += 1;
        }
        per_view.push(if view_count > 0 {
            (view_sum / view_count as f64).sqrt()
        } else {
            0.0
        });
    }
    if count == 0 {
        return Err(Error::too_few("image points", 1, 0));
    }
    Ok(((sum / count as f64).sqrt(), per_view))
}

/// What the refinement over pixels found, for the orchestrator
/// ([`crate::handeye::solve::apply_refinement`]) to write into the result.
#[derive(Debug, Clone)]
pub struct PixelFindings {
    /// The reprojection RMS (px) of each closed form, in the order of the
    /// result's `methods` (`None` for a method that failed).
    pub method_rms_px: Vec<Option<f64>>,
    /// The reprojection RMS (px) of the primary closed form.
    pub closed_form_rms_px: f64,
    /// The refined transforms, when a refinement ran.
    pub refined: Option<PixelRefined>,
    /// What the user should know, in the order found.
    pub warnings: Vec<String>,
}

/// The refined solution of [`PixelFindings`].
#[derive(Debug, Clone)]
pub struct PixelRefined {
    /// The refined `gripper_from_camera` or `base_from_camera`.
    pub x: Pose,
    /// The refined `base_from_target` or `gripper_from_target`.
    pub y: Pose,
    /// The report's `refinement` object.
    pub summary: RefinementSummary,
}

/// Measure the reprojection RMS of every closed form and, unless `mode` is
/// [`RefineMode::None`], refine the primary solution of `result` over the
/// pixels. `views` pair one to one with the input poses.
pub fn refine_over_pixels(
    result: &HandEyeResult,
    input: &HandEyeInput,
    views: &[View],
    camera: &Camera,
    mode: RefineMode,
    pixel_sigma_px: f64,
) -> Result<PixelFindings> {
    if views.len() != input.base_from_gripper.len() {
        return Err(Error::invalid(
            "views",
            format!(
                "{} views of image points but {} robot poses: they must pair up one to one",
                views.len(),
                input.base_from_gripper.len()
            ),
        ));
    }
    let chain = input.chain()?;
    let mut method_rms_px = Vec::with_capacity(result.methods.len());
    for m in &result.methods {
        method_rms_px.push(match &m.outcome {
            Ok((x, y, _)) => Some(reprojection_rms_px(&chain, views, camera, x, y)?),
            Err(_) => None,
        });
    }
    let start_rms = reprojection_rms_px(&chain, views, camera, &result.x, &result.y)?;
    let mut found = PixelFindings {
        method_rms_px,
        closed_form_rms_px: start_rms,
        refined: None,
        warnings: Vec::new(),
    };
    let Some(options) = mode.options(pixel_sigma_px) else {
        return Ok(found);
    };
    if result.method == "scara" {
        found.warnings.push(
            "refinement skipped: with parallel rotation axes part of the translation is \
             unobservable, so the closed-form observable solution is kept"
                .to_string(),
        );
        return Ok(found);
    }
    let refined = refine(
        input.setup,
        &input.base_from_gripper,
        views,
        camera,
        &result.x,
        &result.y,
        &options,
    )?;
    found.refined = Some(PixelRefined {
        x: refined.x,
        y: refined.y,
        summary: RefinementSummary {
            mode,
            started_from: result.method.clone(),
            closed_form_reprojection_rms_px: start_rms,
            reprojection_rms_px: refined.reprojection_rms_px,
            per_view_reprojection_rms_px: refined.per_view_rms_px,
            robot_rotation_noise_deg: refined.robot_noise_estimate.map(|n| n.0.to_degrees()),
            robot_translation_noise_mm: refined.robot_noise_estimate.map(|n| n.1 * 1e3),
            camera: options.intrinsics.then_some(refined.camera),
        },
    });
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::handeye::solve_handeye_json;
    use crate::geometry::PoseJson;
    use crate::handeye::quality::residuals::pose_difference;
    use crate::handeye::refine::pixel_problem_tests::{camera, looking_scene};
    use crate::handeye::Setup;
    use crate::synth::handeye::project_grid;
    use serde::Deserialize;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn pose_json(p: &Pose) -> serde_json::Value {
        serde_json::to_value(PoseJson::from(p)).unwrap()
    }

    fn pose_of(v: &serde_json::Value) -> Pose {
        PoseJson::deserialize(v).unwrap().to_pose().unwrap()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn refinement_beats_every_closed_form_from_noisy_pixels_via_json() {
        // 10 views of a 9x6 grid with 0.5 px pixel noise, camera poses from
        // PnP on the noisy pixels (no camera_from_target given). The
        // refinement uses every pixel through the exact robot poses, so it
        // must beat the best closed form (which sees only the PnP poses), and
        // its reprojection RMS (of the 2-D point distance) must sit near
        // sqrt(2) * 0.5 = 0.707 px (540 points, 12 unknowns: the RMS estimate
        // has a std of about 0.707 / sqrt(2 * 1080) = 0.015 px; 3 std: 0.65-0.75).
        for (setup, key) in [
            (Setup::EyeInHand, "gripper_from_camera"),
            (Setup::EyeToHand, "base_from_camera"),
        ] {
            let scene = looking_scene(setup, 10, 11);
            let views = project_grid(&scene, &camera(), (9, 6, 0.03), 0.5, 5);
            let input = serde_json::json!({
                "setup": setup.name(),
                "base_from_gripper": scene.base_from_gripper.iter().map(pose_json).collect::<Vec<_>>(),
                "camera": camera(),
                "views": views.iter().map(|v| serde_json::json!({
                    "object_m": v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                    "image_px": v.image_px.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
                })).collect::<Vec<_>>(),
                "refine": "trusted",
                "bootstrap_samples": 0,
            });
            let out: serde_json::Value =
                serde_json::from_str(&solve_handeye_json(&input.to_string()).unwrap()).unwrap();
            let method = out["method"].as_str().unwrap();
            assert!(method.starts_with("refined from "), "{method}");
            let rms = out["errors"]["reprojection_rms_px"].as_f64().unwrap();
            assert!((0.65..0.75).contains(&rms), "reprojection {rms} px");
            let refined = pose_difference(&pose_of(&out[key]), &scene.x_true);
            let methods = out["methods"].as_array().unwrap();
            assert_eq!(methods.len(), 8);
            let best = methods
                .iter()
                .map(|m| {
                    assert!(m["errors"]["reprojection_rms_px"].as_f64().unwrap() > rms);
                    let e = pose_difference(&pose_of(&m[key]), &scene.x_true);
                    e.0.hypot(e.1 * 10.0)
                })
                .fold(f64::INFINITY, f64::min);
            // Combined error: mm + 10 mm per degree.
            let refined_score = refined.0.hypot(refined.1 * 10.0);
            assert!(
                refined_score < best,
                "{}: refined {refined:?} vs best closed form {best}",
                setup.name()
            );
            let r = &out["refinement"];
            assert_eq!(r["mode"], "trusted");
            assert_eq!(
                r["per_view_reprojection_rms_px"].as_array().unwrap().len(),
                10
            );
        }
    }

    /// The `views` input of the JSON API.
    fn views_json(views: &[View]) -> Vec<serde_json::Value> {
        views
            .iter()
            .map(|v| {
                serde_json::json!({
                    "object_m": v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                    "image_px": v.image_px.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
                })
            })
            .collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn detections_give_the_same_refinement_as_views() {
        // The web app sends its detections as they are; the board points come
        // from each detection's target. Same points, so the same report to
        // the last bit; both inputs at once are refused.
        let scene = looking_scene(Setup::EyeInHand, 8, 3);
        let (cols, square) = (9, 0.03);
        let views = project_grid(&scene, &camera(), (cols, 6, square), 0.3, 2);
        let view_json = views_json(&views);
        let detection_json: Vec<serde_json::Value> = views
            .iter()
            .map(|v| {
                let points: Vec<serde_json::Value> = v
                    .object_m
                    .iter()
                    .zip(&v.image_px)
                    .map(|(o, px)| {
                        let id = (o.x / square).round() as usize
                            + (o.y / square).round() as usize * cols;
                        serde_json::json!({"id": id, "x_px": px.x, "y_px": px.y})
                    })
                    .collect();
                serde_json::json!({
                    "image_size_px": [1280, 960],
                    "target": {"kind": "chessboard", "cols": cols, "rows": 6, "square_m": square},
                    "points": points,
                })
            })
            .collect();
        let base = serde_json::json!({
            "setup": "eye-in-hand",
            "base_from_gripper": scene.base_from_gripper.iter().map(pose_json).collect::<Vec<_>>(),
            "camera": camera(),
            "refine": "trusted",
            "bootstrap_samples": 0,
        });
        let with = |key: &str, value: &[serde_json::Value]| {
            let mut input = base.clone();
            input[key] = serde_json::Value::Array(value.to_vec());
            input
        };
        let from_views = solve_handeye_json(&with("views", &view_json).to_string()).unwrap();
        let from_detections =
            solve_handeye_json(&with("detections", &detection_json).to_string()).unwrap();
        assert_eq!(from_views, from_detections);
        let out: serde_json::Value = serde_json::from_str(&from_detections).unwrap();
        assert!(out["method"].as_str().unwrap().starts_with("refined from "));
        let mut both = with("views", &view_json);
        both["detections"] = serde_json::Value::Array(detection_json);
        assert_eq!(
            solve_handeye_json(&both.to_string())
                .unwrap_err()
                .to_string(),
            "detections: give either 'views' or 'detections', not both"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn joint_intrinsics_reports_the_camera_and_missing_inputs_are_named() {
        let scene = looking_scene(Setup::EyeInHand, 8, 4);
        let views = project_grid(&scene, &camera(), (9, 6, 0.03), 0.0, 1);
        let view_json = views_json(&views);
        let robots: Vec<_> = scene.base_from_gripper.iter().map(pose_json).collect();
        // The camera given as a calibration-report-like JSON string (the
        // format robocal exports), 2 % off in focal length.
        let camera_text = serde_json::json!({
            "image_size_px": [640, 480],
            "camera_matrix": [[816.0, 0.0, 320.0], [0.0, 816.0, 240.0], [0.0, 0.0, 1.0]],
            "model": "none",
            "distortion": {},
        })
        .to_string();
        let input = serde_json::json!({
            "setup": "eye-in-hand",
            "base_from_gripper": robots,
            "camera": camera_text,
            "views": view_json,
            "refine": "joint_intrinsics",
            "bootstrap_samples": 0,
        });
        let out: serde_json::Value =
            serde_json::from_str(&solve_handeye_json(&input.to_string()).unwrap()).unwrap();
        // Noise-free pixels: the joint LM recovers fx = 800 exactly.
        let fx = out["refinement"]["camera"]["fx"].as_f64().unwrap();
        assert!((fx - 800.0).abs() < 1e-6, "fx {fx}");
        let x = pose_of(&out["gripper_from_camera"]);
        let (t, r) = pose_difference(&x, &scene.x_true);
        assert!(t < 1e-6 && r < 1e-6, "{t} mm {r} deg");
        let no_camera = serde_json::json!({
            "setup": "eye-in-hand",
            "base_from_gripper": robots,
            "views": view_json,
        });
        assert_eq!(
            solve_handeye_json(&no_camera.to_string())
                .unwrap_err()
                .to_string(),
            "camera: 'camera' is required because camera_from_target is absent"
        );
        let bad_mode = serde_json::json!({
            "setup": "eye-in-hand",
            "base_from_gripper": robots,
            "views": view_json,
            "camera": camera(),
            "refine": "full",
        });
        assert_eq!(
            solve_handeye_json(&bad_mode.to_string())
                .unwrap_err()
                .to_string(),
            "refine: unknown refinement 'full' (valid: none, trusted, stochastic, joint_intrinsics)"
        );
    }
}
