//! The pose plan as JSON ([`crate::handeye::plan`]): the report `robocal
//! plan` writes and the request of the wasm `plan_handeye_poses`.
//!
//! Request: `{"setup", "base_from_gripper": pose, "camera_from_target":
//! pose, "camera": camera JSON, "board_m": [[x, y, z]...], "guess": pose
//! (optional), "poses": 15, "max_tilt_deg": 40, "max_roll_deg": 60,
//! "distance_m": [min, max], "flange_box_m": [[x0, y0, z0], [x1, y1, z1]]
//! (two opposite corners, base frame), "margin_px": 20, "pixel_sigma_px":
//! 0.3, "view_px": [[u, v]...]}` (poses as [`PoseInput`]). `view_px`, the
//! current view's detected pixels of the `board_m` points in the same order,
//! lets the plan measure the corner noise on it
//! ([`crate::handeye::plan::pixel_sigma_from_view`]) when `pixel_sigma_px`
//! is not given; without either it assumes 0.3 px.

use crate::api::handeye::camera_from_json;
use crate::calib::View;
use crate::error::{Error, Result};
use crate::geometry::{PoseInput, PoseJson};
use crate::handeye::plan::{
    pixel_sigma_from_view, plan, PixelNoiseSource, Plan, PlanInput, PlanLimits, PlanNoise,
};
use crate::handeye::{Pose, Setup};
use nalgebra::{Point2, Point3};
use serde::Deserialize;
use serde_json::{json, Value};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlanRequest {
    setup: Setup,
    base_from_gripper: PoseInput,
    camera_from_target: PoseInput,
    camera: Value,
    board_m: Vec<[f64; 3]>,
    #[serde(default)]
    guess: Option<PoseInput>,
    #[serde(default)]
    poses: Option<usize>,
    #[serde(default)]
    max_tilt_deg: Option<f64>,
    #[serde(default)]
    max_roll_deg: Option<f64>,
    #[serde(default)]
    distance_m: Option<[f64; 2]>,
    #[serde(default)]
    flange_box_m: Option<[[f64; 3]; 2]>,
    #[serde(default)]
    margin_px: Option<f64>,
    #[serde(default)]
    pixel_sigma_px: Option<f64>,
    #[serde(default)]
    view_px: Option<Vec<[f64; 2]>>,
}

fn pose(p: &PoseInput, field: &str) -> Result<Pose> {
    p.to_pose()
        .map_err(|e| Error::invalid(field, e.to_string()))
}

/// The plan's JSON (the `robocal plan` output).
pub fn plan_json_value(plan: &Plan) -> Value {
    let poses: Vec<Value> = plan
        .poses
        .iter()
        .map(|p| {
            json!({
                "base_from_gripper": PoseJson::from(&p.base_from_gripper),
                "camera_from_target": PoseJson::from(&p.camera_from_target),
                "tilt_deg": p.tilt_deg,
                "distance_m": p.distance_m,
                "roll_deg": p.roll_deg,
            })
        })
        .collect();
    json!({
        "kind": "handeye-plan",
        "poses": poses,
        "predicted": plan.predicted,
        "motion": plan.motion,
        "travel_m": plan.travel_m,
        "candidates": plan.candidates,
        "notes": plan.notes,
        "noise": {
            "pixel_sigma_px": plan.noise.pixel_sigma_px,
            "pixel_sigma_from": plan.noise.pixel_sigma_from,
            "robot_rotation_deg": plan.noise.robot_rotation_deg,
            "robot_translation_mm": plan.noise.robot_translation_mm,
        },
        "robocal_version": crate::VERSION,
    })
}

/// Plan from a request JSON (module docs); returns the plan JSON.
pub fn plan_json(request_json: &str) -> Result<String> {
    let r: PlanRequest = serde_json::from_str(request_json)
        .map_err(|e| Error::parse(e.line(), e.column(), e.to_string()))?;
    let input = PlanInput {
        setup: r.setup,
        base_from_gripper: pose(&r.base_from_gripper, "base_from_gripper")?,
        camera_from_target: pose(&r.camera_from_target, "camera_from_target")?,
        camera: camera_from_json(&r.camera)?,
        board_m: r.board_m.iter().map(|p| Point3::from(*p)).collect(),
        guess: match &r.guess {
            Some(g) => pose(g, "guess")?,
            None => Pose::identity(),
        },
    };
    let d = PlanLimits::default();
    let limits = PlanLimits {
        poses: r.poses.unwrap_or(d.poses),
        max_tilt_deg: r.max_tilt_deg.unwrap_or(d.max_tilt_deg),
        max_roll_deg: r.max_roll_deg.unwrap_or(d.max_roll_deg),
        distance_m: r.distance_m.map(|v| (v[0], v[1])),
        // Two opposite corners, in any order (as `robocal plan --flange-box`).
        flange_box_m: r.flange_box_m.map(|[a, b]| {
            (
                [a[0].min(b[0]), a[1].min(b[1]), a[2].min(b[2])],
                [a[0].max(b[0]), a[1].max(b[1]), a[2].max(b[2])],
            )
        }),
        margin_px: r.margin_px.unwrap_or(d.margin_px),
    };
    let noise = match (r.pixel_sigma_px, &r.view_px) {
        (Some(sigma), _) if !(sigma > 0.0 && sigma.is_finite()) => {
            return Err(Error::invalid(
                "pixel_sigma_px",
                format!("{sigma}: a positive number of pixels"),
            ))
        }
        (Some(sigma), _) => PlanNoise {
            pixel_sigma_px: sigma,
            pixel_sigma_from: PixelNoiseSource::Given,
            ..PlanNoise::default()
        },
        (None, Some(pixels)) => {
            if pixels.len() != input.board_m.len() {
                return Err(Error::invalid(
                    "view_px",
                    format!(
                        "{} pixels for {} board points (one per point of board_m, same order)",
                        pixels.len(),
                        input.board_m.len()
                    ),
                ));
            }
            let view = View::new(
                "",
                input.board_m.clone(),
                pixels.iter().map(|p| Point2::new(p[0], p[1])).collect(),
            );
            let (_, sigma) = pixel_sigma_from_view(&input.camera, &view)
                .map_err(|e| Error::invalid("view_px", e.to_string()))?;
            PlanNoise {
                pixel_sigma_px: sigma,
                pixel_sigma_from: PixelNoiseSource::MeasuredOnView,
                ..PlanNoise::default()
            }
        }
        (None, None) => PlanNoise::default(),
    };
    let planned = plan(&input, &limits, &noise)?;
    crate::finite::check_finite("plan", &plan_json_value(&planned))?;
    Ok(plan_json_value(&planned).to_string())
}
