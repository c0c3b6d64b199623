//! The views of a camera request read and checked: each JSON view (board
//! points and pixels, or a detection) to a [`View`], a detection's pixels
//! inside its image, and the same view given twice refused. Shared by the
//! camera, stereo, rig and check requests.

use super::camera::JsonView;
use crate::calib::View;
use crate::error::{Error, Result};
use crate::target::Detection;
use nalgebra::{Point2, Point3};

/// The correspondences of every input view.
pub fn views_of(views: &[JsonView]) -> Result<Vec<View>> {
    let out = views
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let field = |f: &str| format!("views[{i}].{f}");
            match (&v.detection, &v.object_m, &v.image_px) {
                (Some(d), None, None) => {
                    check_detection(&format!("views[{i}] ({})", v.name), d)?;
                    Ok(View::from_detection(v.name.clone(), d))
                }
                (None, Some(object), Some(image)) => {
                    if object.len() != image.len() {
                        return Err(Error::invalid(
                            field("image_px"),
                            format!(
                                "{} object points but {} image points",
                                object.len(),
                                image.len()
                            ),
                        ));
                    }
                    Ok(View {
                        name: v.name.clone(),
                        object_m: object
                            .iter()
                            .map(|p| Point3::new(p[0], p[1], p[2]))
                            .collect(),
                        image_px: image.iter().map(|p| Point2::new(p[0], p[1])).collect(),
                        point_ids: Vec::new(),
                    })
                }
                _ => Err(Error::invalid(
                    format!("views[{i}]"),
                    "give either \"detection\" or both \"object_m\" and \"image_px\"",
                )),
            }
        })
        .collect::<Result<Vec<View>>>()?;
    refuse_duplicates(&out)?;
    Ok(out)
}

/// Slack beyond the image border a detected point may have, px.
const BORDER_SLACK_PX: f64 = 1.0;

/// A detection the solvers can use: a valid target, a positive image size,
/// every point id on the target and given once, every pixel finite and
/// inside the image.
fn check_detection(field: &str, d: &Detection) -> Result<()> {
    let target = d.target.clone().validated()?;
    let [w, h] = d.image_size_px;
    if w == 0 || h == 0 {
        return Err(Error::invalid(
            field,
            format!("image_size_px is {w}x{h}: width and height must be > 0"),
        ));
    }
    let count = target.point_count();
    let mut seen = vec![false; count];
    let inside = |v: f64, n: u32| {
        v.is_finite() && v >= -0.5 - BORDER_SLACK_PX && v <= n as f64 - 0.5 + BORDER_SLACK_PX
    };
    for p in &d.points {
        if p.id >= count {
            return Err(Error::invalid(
                field,
                format!(
                    "point id {} is not on the target (ids 0 to {}): the detection is of another target",
                    p.id,
                    count - 1
                ),
            ));
        }
        if std::mem::replace(&mut seen[p.id], true) {
            return Err(Error::invalid(
                field,
                format!(
                    "point id {} is listed twice: each target point is detected once",
                    p.id
                ),
            ));
        }
        if !(inside(p.x_px, w) && inside(p.y_px, h)) {
            return Err(Error::invalid(
                field,
                format!(
                    "point id {} at ({}, {}) px is outside the {w}x{h} image",
                    p.id, p.x_px, p.y_px
                ),
            ));
        }
    }
    Ok(())
}

/// The same image given twice counts its points twice (and shrinks the
/// reported uncertainties): refuse views with identical image points.
fn refuse_duplicates(views: &[View]) -> Result<()> {
    for (i, a) in views.iter().enumerate() {
        if let Some((j, b)) = views
            .iter()
            .enumerate()
            .skip(i + 1)
            .find(|(_, b)| !a.image_px.is_empty() && b.image_px == a.image_px)
        {
            return Err(Error::invalid(
                "views",
                format!(
                    "views {i} ({}) and {j} ({}) have identical image points: the same image \
                     was given twice; remove one of them",
                    a.name, b.name
                ),
            ));
        }
    }
    Ok(())
}
