//! The filter's start for a batch of views: Zhang's closed form.

use super::super::closed_form::intrinsics_from_homographies;
use super::super::homography::homography;
use super::super::{CalibrationOptions, View};
use crate::camera::Camera;
use crate::error::Result;
use nalgebra::Point2;

/// The options with Zhang's closed-form intrinsics (all views' homographies,
/// zero skew) as the filter's start when no initial camera is given; the
/// principal point stays at the image centre when it is held. Without a
/// closed form (one view, degenerate views) the filter's own start is kept.
pub(super) fn closed_form_start(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> CalibrationOptions {
    if options.initial_camera.is_some() {
        return options.clone();
    }
    let homographies = views
        .iter()
        .map(|v| {
            let plane: Vec<Point2<f64>> = v.object_m.iter().map(|p| p.xy()).collect();
            homography(&plane, &v.image_px)
        })
        .collect::<Result<Vec<_>>>();
    let k = homographies.and_then(|h| intrinsics_from_homographies(&h, image_size_px, true));
    let Ok(k) = k else {
        return options.clone();
    };
    let (fx, fy) = (k[(0, 0)], k[(1, 1)]);
    if !(fx > 0.0 && fy > 0.0 && fx.is_finite() && fy.is_finite()) {
        return options.clone();
    }
    let (mut cx, mut cy) = (k[(0, 2)], k[(1, 2)]);
    if options.fix_principal_point {
        cx = 0.5 * (image_size_px.0 as f64 - 1.0);
        cy = 0.5 * (image_size_px.1 as f64 - 1.0);
    }
    CalibrationOptions {
        initial_camera: Some(Camera {
            fx,
            fy,
            cx,
            cy,
            skew: 0.0,
            width: image_size_px.0,
            height: image_size_px.1,
            distortion: options.model.clone(),
        }),
        ..options.clone()
    }
}
