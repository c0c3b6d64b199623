//! Step 1 of a rig calibration: each camera alone. Its views that fix a
//! homography are kept (the others left out with a warning); a camera
//! whose intrinsics are solved is calibrated by Zhang ([`calibrate`]), a
//! camera given and held gets only its board poses (homography pose, then
//! the bundle adjustment with every camera parameter held).

use crate::calib::closed_form::pose_from_homography;
use crate::calib::homography::homography;
use crate::calib::multi::rig::RigCameraViews;
use crate::calib::multi::stereo::{report_poses, used_masks};
use crate::calib::refine::{block_from_pose, CalibProblem};
use crate::calib::usable::usable_views;
use crate::calib::zhang::{held_aspect, lm_options};
use crate::calib::{calibrate, CalibrationOptions, Outlier, View};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{pose_from_params, Pose};
use crate::optim::{solve, BlockParams, LmOptions};
use nalgebra::Point2;

/// One camera after step 1.
pub(crate) struct Alone {
    /// Its intrinsics (the start of the joint refinement).
    pub camera: Camera,
    /// Whether they were given and are held.
    pub held: bool,
    /// Per camera parameter: held in the joint refinement.
    pub fixed: Vec<bool>,
    /// The held fy / fx, if any.
    pub aspect: Option<f64>,
    /// The views used, in frame order.
    pub views: Vec<View>,
    /// The frame of each used view.
    pub frames: Vec<usize>,
    /// Per view, per point: not rejected as an outlier.
    pub used: Vec<Vec<bool>>,
    /// Per view: camera_from_target.
    pub poses: Vec<Pose>,
    /// Per view: the points rejected as outliers.
    pub outliers: Vec<Vec<Outlier>>,
    /// Views left out and why.
    pub warnings: Vec<String>,
    /// The std of each intrinsic parameter from this camera's own
    /// calibration (names of [`Camera::param_names`]); empty when held.
    pub solo_std: std::collections::BTreeMap<String, f64>,
}

impl Alone {
    /// Points of view `view` in use.
    pub fn n_used(&self, view: usize) -> usize {
        self.used
            .get(view)
            .map_or(0, |u| u.iter().filter(|x| **x).count())
    }

    /// Its single-camera problem (views, masks, aspect).
    pub fn problem(&self) -> CalibProblem<'_> {
        CalibProblem {
            template: &self.camera,
            views: &self.views,
            used: &self.used,
            aspect: self.aspect,
            warp: None,
        }
    }
}

/// Step 1 for one camera.
pub(crate) fn camera_alone(input: &RigCameraViews, options: &CalibrationOptions) -> Result<Alone> {
    let name = &input.name;
    let mut sorted: Vec<&(usize, View)> = input.views.iter().collect();
    sorted.sort_by_key(|(f, _)| *f);
    let views: Vec<View> = sorted.iter().map(|(_, v)| v.clone()).collect();
    let (usable, left_out) = usable_views(&views);
    let frames: Vec<usize> = sorted
        .iter()
        .enumerate()
        .filter(|(i, _)| !left_out.iter().any(|l| l.index == *i))
        .map(|(_, (f, _))| *f)
        .collect();
    let warnings = left_out
        .iter()
        .map(|l| format!("camera {name}: {}", l.warning()))
        .collect();
    match &input.camera {
        None => {
            let report =
                calibrate(&usable, input.image_size_px, options).map_err(|e| in_camera(name, e))?;
            let camera = report.camera.clone();
            Ok(Alone {
                fixed: lm_options(&camera, options)?.fixed_global,
                aspect: held_aspect(&camera, options),
                poses: report_poses(&report)?,
                used: used_masks(&usable, &report),
                outliers: report.views.iter().map(|v| v.outliers.clone()).collect(),
                solo_std: report.std.clone(),
                camera,
                held: false,
                views: usable,
                frames,
                warnings,
            })
        }
        Some(given) => {
            let poses = held_camera_poses(given, &usable, input.image_size_px)
                .map_err(|e| in_camera(name, e))?;
            Ok(Alone {
                fixed: vec![true; given.params().len()],
                aspect: None,
                poses,
                used: usable
                    .iter()
                    .map(|v| vec![true; v.object_m.len()])
                    .collect(),
                outliers: vec![Vec::new(); usable.len()],
                solo_std: Default::default(),
                camera: given.clone(),
                held: true,
                views: usable,
                frames,
                warnings,
            })
        }
    }
}

/// The board pose of every view under a held camera: from the homography,
/// then refined with every camera parameter held.
fn held_camera_poses(camera: &Camera, views: &[View], size: (u32, u32)) -> Result<Vec<Pose>> {
    if (camera.width, camera.height) != size {
        return Err(Error::invalid(
            "camera",
            format!(
                "the given camera is for {}x{} images, but the images are {}x{}",
                camera.width, camera.height, size.0, size.1
            ),
        ));
    }
    if views.is_empty() {
        return Err(Error::too_few("views whose points fix a homography", 1, 0));
    }
    let k = camera.camera_matrix();
    let blocks = views
        .iter()
        .map(|v| {
            let plane: Vec<Point2<f64>> = v.object_m.iter().map(|p| p.xy()).collect();
            let h = homography(&plane, &v.image_px)?;
            pose_from_homography(&k, &h).map(|p| block_from_pose(&p))
        })
        .collect::<Result<Vec<_>>>()?;
    let used: Vec<Vec<bool>> = views.iter().map(|v| vec![true; v.object_m.len()]).collect();
    let problem = CalibProblem {
        template: camera,
        views,
        used: &used,
        aspect: None,
        warp: None,
    };
    let n = camera.params().len();
    let result = solve(
        &problem,
        &BlockParams {
            global: camera.params(),
            blocks,
        },
        &LmOptions {
            fixed_global: vec![true; n],
            ..LmOptions::default()
        },
    )?;
    Ok(result
        .params
        .blocks
        .iter()
        .map(|b| pose_from_params(b))
        .collect())
}

/// An error of one camera's step, naming the camera.
fn in_camera(name: &str, e: Error) -> Error {
    match e {
        Error::Invalid { field, message } => Error::Invalid {
            field: format!("camera {name}: {field}"),
            message,
        },
        Error::TooFew {
            what,
            required,
            actual,
        } => Error::TooFew {
            what: format!("{what} of camera {name}"),
            required,
            actual,
        },
        Error::Degenerate { message } => Error::degenerate(format!("camera {name}: {message}")),
        other => other,
    }
}
