//! The same images given for two cameras (issue 35, item 6): a stereo pair
//! or two rig cameras whose detections are identical in every frame they
//! share solve to a baseline of exactly 0 m, a meaningless result. Refused
//! before solving; after solving, a baseline that is zero within its
//! uncertainty is refused too (the same scene detected twice with
//! different noise).

use crate::calib::View;
use crate::error::{Error, Result};

/// A baseline is "zero within its uncertainty" below this many times the
/// norm of its translation standard deviations (the norm is already about
/// sqrt(3) sigma along any axis, so this is about 5 sigma).
pub const ZERO_BASELINE_SIGMAS: f64 = 3.0;

/// Whether two views hold the same detection: the same target points at
/// the same pixels.
fn identical(a: &View, b: &View) -> bool {
    !a.image_px.is_empty()
        && a.image_px == b.image_px
        && a.object_m == b.object_m
        && a.point_ids == b.point_ids
}

/// Refuse two cameras (`who`: "the left and right images", "cameras a and
/// b") whose views, paired by frame (`unit`: "pairs", "shared frames"),
/// are identical in every pair; `field` names the input for the error.
pub(crate) fn refuse_identical_views(
    field: &str,
    who: &str,
    unit: &str,
    pairs: &[(&View, &View)],
) -> Result<()> {
    if pairs.is_empty() || !pairs.iter().all(|(x, y)| identical(x, y)) {
        return Ok(());
    }
    Err(Error::invalid(
        field,
        format!(
            "{who} have identical detections in all {} {unit}: the same images were given \
             for both cameras, which would solve to a baseline of 0 m; give each camera its \
             own images",
            pairs.len()
        ),
    ))
}

/// Refuse a baseline (metres) between two cameras (`who`: "the left and
/// right cameras", "cameras a and b") that is zero within its uncertainty
/// (`std_translation_m`, the per-axis standard deviations of the relative
/// translation; without them, an exact 0).
pub(crate) fn refuse_zero_baseline(
    field: &str,
    who: &str,
    baseline_m: f64,
    std_translation_m: Option<[f64; 3]>,
) -> Result<()> {
    let sigma = std_translation_m.map_or(0.0, |s| (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt());
    if baseline_m > ZERO_BASELINE_SIGMAS * sigma && baseline_m > 0.0 {
        return Ok(());
    }
    Err(Error::invalid(
        field,
        format!(
            "the baseline between {who} is {baseline_m:.6} m, zero within its uncertainty \
             ({sigma:.6} m): the two cameras are at the same place, so the images are of one \
             camera (the same scene given for both?); give each camera its own images, taken \
             at the same moments"
        ),
    ))
}
