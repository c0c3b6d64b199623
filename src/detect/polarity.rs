//! Print polarity: every target is found printed dark on light or light on
//! dark without being told which ([`super::DetectOptions::polarity`] may
//! force one).
//!
//! # How the print is found
//!
//! - **Marker boards, circle grids, dot plates, square grids, single
//!   circles**: searched in the target's usual print first (dark on light;
//!   a circle grid's own `polarity`), then, only when that finds nothing,
//!   in the other one. The other print is searched on the inverted image
//!   (circle grids and dot plates threshold for light blobs instead), so a
//!   light-on-dark board's marker ids, corner ids and point order are those
//!   of the same board printed dark on light: a search costs twice only
//!   when it fails. Marker boards, whose search on large frames runs at
//!   half resolution before a full-resolution retry, search both prints at
//!   half resolution before either is retried ([`search_markers`]).
//! - **Chessboards** are found in either print by the same saddle points,
//!   but their corner 0 is defined by colour (the outer square beyond it is
//!   the print's first square: dark on a dark-on-light print, light on a
//!   light-on-dark one). When `cols + rows` is even the four outer corner
//!   squares share one colour, which says the print: a board whose corner
//!   squares are light is light on dark and is detected again on the
//!   inverted image, which numbers it from its light corner. When
//!   `cols + rows` is odd the inverted print is the usual one turned 180
//!   degrees: only the paper around the squares could tell them apart, and
//!   it does not reliably (OpenCV's own 9x6 sample images show a thin white
//!   margin cut through by the board's edge on dark backgrounds: a margin
//!   test called 6 of their 26 views light on dark). Such a board found
//!   without an option is numbered as dark on light and says
//!   `dark_on_light`; its numbering is consistent across views either way
//!   (a rigid board frame), and `:light-on-dark` numbers an inverted one
//!   from its own light corner.

use super::markers::homography::Homography;
use super::markers::Resolutions;
use crate::error::{Error, Result};
use crate::image::GrayImage;
use crate::target::{DetectedPoint, Polarity, Target};
use nalgebra::Point2;

/// Corners on each side of a sample used for its local homography.
const LOCAL_CORNERS: i64 = 2;

/// The print a target is searched in first when none is forced.
pub(crate) fn usual(target: &Target) -> Polarity {
    match target {
        Target::CircleGrid { polarity, .. } => *polarity,
        Target::Chessboard { .. }
        | Target::DotPlate { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. }
        | Target::Charuco { .. }
        | Target::Aprilgrid { .. }
        | Target::ArucoGrid { .. }
        | Target::OriginDotGrid { .. } => Polarity::DarkOnLight,
    }
}

/// The image with every grey level `v` replaced by `255 - v`.
pub(crate) fn inverted(image: &GrayImage) -> GrayImage {
    GrayImage {
        width: image.width,
        height: image.height,
        pixels: image.pixels.iter().map(|v| 255 - v).collect(),
    }
}

/// Search `first` then (unless `forced`) the other print; `attempt` runs
/// one search. A forced print that finds nothing while the other print
/// finds the target is reported with the option to change.
pub(crate) fn search<T>(
    target: &Target,
    forced: Option<Polarity>,
    mut attempt: impl FnMut(Polarity) -> Result<T>,
) -> Result<T> {
    let first = forced.unwrap_or_else(|| usual(target));
    let message = match attempt(first) {
        Err(Error::NotFound { message }) => message,
        other => return other,
    };
    match (forced, attempt(first.other())) {
        (None, Ok(found)) => Ok(found),
        (Some(print), Ok(_)) => Err(Error::NotFound {
            message: forced_miss(target, print, &message),
        }),
        (_, Err(_)) => Err(Error::NotFound { message }),
    }
}

/// [`search`] for marker boards, whose search runs at half resolution on
/// large frames before a full-resolution retry (`markers::Resolutions`):
/// without a forced print, both prints are searched at half resolution
/// before either is retried at full resolution, so an inverted board is
/// not found only after the usual print's retry. `attempt` runs one print
/// over some resolutions and says whether it read any marker (a print that
/// read markers at half resolution is not retried, as in one print's
/// search, unless they were small: then its own half-resolution attempt
/// searched the full resolution too, `markers::quads`). The error is the
/// usual print's, as [`search`]'s.
pub(crate) fn search_markers<T>(
    target: &Target,
    forced: Option<Polarity>,
    large: bool,
    mut attempt: impl FnMut(Polarity, Resolutions) -> (Result<T>, bool),
) -> Result<T> {
    if forced.is_some() || !large {
        return search(target, forced, |print| {
            attempt(print, Resolutions::HalfThenFull).0
        });
    }
    let first = usual(target);
    let (found, first_read) = attempt(first, Resolutions::HalfOnly);
    let mut message = match found {
        Err(Error::NotFound { message }) => message,
        other => return other,
    };
    let (found, other_read) = attempt(first.other(), Resolutions::HalfOnly);
    if let Ok(found) = found {
        return Ok(found);
    }
    if !first_read {
        match attempt(first, Resolutions::FullOnly).0 {
            Err(Error::NotFound { message: m }) => message = m,
            other => return other,
        }
    }
    if !other_read {
        if let Ok(found) = attempt(first.other(), Resolutions::FullOnly).0 {
            return Ok(found);
        }
    }
    Err(Error::NotFound { message })
}

/// The message of a forced print that missed a board the other print sees.
fn forced_miss(target: &Target, forced: Polarity, message: &str) -> String {
    let other = forced.other().spec_option();
    format!(
        "{message}; printed {other} the board is in view: the target spec forces ':{}', write ':{other}' or leave the option out to find either print ({})",
        forced.spec_option(),
        target.to_spec()
    )
}

/// The print of a chessboard found on the image as given (module docs):
/// `points` are numbered with the outer square beyond corner 0 dark when
/// any ordering allows it, so a light one means a light-on-dark print.
pub(crate) fn chessboard_print(
    image: &GrayImage,
    points: &[DetectedPoint],
    cols: usize,
    rows: usize,
) -> Polarity {
    let at = |i: i64, j: i64| {
        points
            .get(i as usize + j as usize * cols)
            .map(|p| Point2::new(p.x_px, p.y_px))
    };
    let sample = |x: f64, y: f64| grey_at_board(image, &at, cols as i64, rows as i64, x, y);
    // Square (a, b) spans corners (a, b)..(a + 1, b + 1); (-1, -1) is the
    // outer square beyond corner 0, dark in this numbering unless no
    // ordering of the board had a dark one.
    let (mut even, mut odd) = (Vec::new(), Vec::new());
    for b in -1..rows as i64 {
        for a in -1..cols as i64 {
            if let Some(v) = sample(a as f64 + 0.5, b as f64 + 0.5) {
                if (a + b).rem_euclid(2) == 0 {
                    even.push(v);
                } else {
                    odd.push(v);
                }
            }
        }
    }
    let (Some(dark), Some(light)) = (median(&mut even), median(&mut odd)) else {
        return Polarity::DarkOnLight;
    };
    if dark > light {
        Polarity::LightOnDark
    } else {
        Polarity::DarkOnLight
    }
}

/// Mean grey level of the 3x3 pixels around the image of board point
/// `(x, y)` (corner units), mapped by a homography of the corners within
/// [`LOCAL_CORNERS`] of it; `None` outside the image.
fn grey_at_board(
    image: &GrayImage,
    corner: &impl Fn(i64, i64) -> Option<Point2<f64>>,
    cols: i64,
    rows: i64,
    x: f64,
    y: f64,
) -> Option<f64> {
    let ci = (x.round() as i64).clamp(0, cols - 1);
    let cj = (y.round() as i64).clamp(0, rows - 1);
    let mut pairs = Vec::new();
    for j in (cj - LOCAL_CORNERS).max(0)..=(cj + LOCAL_CORNERS).min(rows - 1) {
        for i in (ci - LOCAL_CORNERS).max(0)..=(ci + LOCAL_CORNERS).min(cols - 1) {
            if let Some(p) = corner(i, j) {
                pairs.push((Point2::new(i as f64, j as f64), p));
            }
        }
    }
    let p = Homography::fit(&pairs)?.map(&Point2::new(x, y))?;
    let (px, py) = (p.x.round(), p.y.round());
    if px < 1.0 || py < 1.0 || px > image.width as f64 - 2.0 || py > image.height as f64 - 2.0 {
        return None;
    }
    let (px, py) = (px as u32, py as u32);
    let mut sum = 0.0;
    for dy in 0..3 {
        for dx in 0..3 {
            sum += image.get(px + dx - 1, py + dy - 1)? as f64;
        }
    }
    Some(sum / 9.0)
}

fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}
