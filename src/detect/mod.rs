//! Target detection: a decoded grey image in, a [`Detection`] out. Nothing
//! downstream sees pixels.
//!
//! - **Chessboards** ([`chessboard`] docs state the corner order): Hessian
//!   saddle candidates on a pyramid level whose long side is at most
//!   [`DetectOptions::max_working_side_px`] (then up to two finer levels if that
//!   fails), grid growth from seeds with local perspective prediction and
//!   alternating corner polarity, and a saddle-point surface fit at full
//!   resolution for every corner.
//! - **Circle grids and dot plates**: dark (or, for light-on-dark grids,
//!   light) blobs from a locally adaptive threshold, grown into a lattice,
//!   ordered by the same rules as chessboards (right-handed, then id 0
//!   nearest the image's top-left; asymmetric grids are unambiguous).
//!   Centres are the images of the circles' centres (below), from
//!   ellipses fitted to sub-pixel edge points.
//! - **A single circle**: the largest elliptical blob; its centre comes with
//!   the covariance of the ellipse-fit centre.
//! - **Square grids** ([`squares`] docs): dark blobs as for dot plates,
//!   grown into the lattice of squares and ordered by the same rules; each
//!   square's four corners are where parabolas fitted to its sides'
//!   sub-pixel edge points (gradient centroids across each side) meet.
//!
//! - **Either print** ([`polarity`] docs): every kind is found printed dark
//!   on light or light on dark (the usual print first, the inverted one only
//!   when that finds nothing; chessboards read their print off the found
//!   board), with the ids of the usual print; [`DetectOptions::polarity`]
//!   forces one, and the detection's `polarity` says which was found.
//!
//! # Perspective-correct circle centres
//!
//! Under perspective the centre of an imaged circle (an ellipse) is not the
//! image of the circle's centre; the difference grows with the circle's
//! radius squared and the tilt (0.05-0.15 px for the 10-12.5 mm circles of
//! the tests at 30-49 degrees, f = 1000 px). Circle grids and dot plates
//! report the **image of each circle's centre** by default
//! ([`CentreModel::PerspectivePole`], method in `centres.rs`): a
//! homography fitted to the circle's grid neighbourhood (3x3 on symmetric
//! grids and dot plates, the nearest 12 or so on asymmetric ones), the circle's
//! edge points pulled back onto the board through it, the centre of the
//! ellipse fitted there mapped forward (the pole of the vanishing line
//! with respect to the imaged conic), iterated until no centre moves by
//! 1e-4 px; then the grid's radial distortion (a one-parameter division
//! model about the image centre, fitted so that one homography maps the
//! board to the undistorted centres of that pass) is taken out of the
//! centres and edge points, the iteration runs again there and the centres
//! are distorted back. No camera is needed, so the CLI, the page and the npm package
//! get the same points, and the detection's points stay the projections of
//! the board points (`centre_model` in the detection records the model).
//!
//! Chosen by numbers (tests/detect/detect_circles.rs: 1280x960, noise sigma 2,
//! tilts 30-49 degrees, 4x11 asymmetric and 7x5 symmetric grids in both
//! polarities and a 7x7 dot plate, three views each; worst per-image mean /
//! max error over all cases):
//!
//! | centre model | 'std' camera (no distortion) | strong distortion (k1 = -0.28) |
//! |---|---|---|
//! | `ellipse_centre` (uncorrected) | 0.102 / 0.154 px | 0.078 / 0.107 px |
//! | `perspective_pole`, 5x5 window | 0.0113 / 0.029 px | 0.0161 / 0.041 px |
//! | `perspective_pole`, 3x3 window | 0.0113 / 0.029 px | 0.0134 / 0.033 px |
//! | `local_quadratic`, 3x3 window | 0.0113 / 0.029 px | 0.0134 / 0.032 px |
//! | `perspective_pole`, radial step + 3x3 window | 0.0113 / 0.029 px | 0.0121 / 0.032 px |
//! | the same, edge points at the gradient's centroid (default) | 0.0099 / 0.027 px | 0.0098 / 0.026 px |
//!
//! The edge points along each ray (blobs.rs) were first the crossings of
//! the mid level between the blob and its background, which move with any
//! error of that level; they are now the centroid of the gradient around
//! the crossing. Besides the table's gain, that took away a systematic
//! floor of about 0.007 px under the centres of noise-free renders (0.003
//! px left), which had made the circle grids calibrate worse than
//! chessboards of the same views: a 9x6 circle grid and a 9x6 chessboard in
//! the same twelve poses now give intrinsics errors of 0.068 / 0.103 px
//! ('std' camera) and 0.058 / 0.097 px (strong distortion), eight noise
//! draws (tests/calib/calib_circles.rs). The centroid costs about 2-2.7 ms per
//! 1.2 MP image of 44-49 circles (it runs on the second of the two ray
//! passes only).
//!
//! On larger circles (7x5 grid at 0.25 m, ~44 px across, 46 degrees,
//! strong distortion) the 5x5 window leaves 0.035 px mean, the 3x3 one
//! 0.020 px, with the radial step 0.008 px, with the gradient-centroid
//! edges 0.006 px (ellipse centres: 0.20 px). On
//! the comparison script's steepest distorted set of large circles
//! (vignetting, gradients) one image was at 0.033 px mean, 0.11 px max
//! without the radial step, the error on the board's edge circles, whose
//! windows lie on one side of them and extrapolate the lens's bending;
//! with it 0.008 / 0.021 px (docs/benchmark-history.md, Session 10; the test
//! `large_steep_circles_with_vignetting_through_strong_distortion`). A
//! quadratic term on top of each local homography changes the centres by
//! less than 0.001 px, so the default is the plain homography. No
//! calibration-time correction (re-estimating the centres through the
//! camera model) was built: the detection-time correction meets issue
//! 20's goal (mean <= 0.03 px, max <= 0.15 px) on every render tested.
//! [`DetectOptions::circle_centres`] selects another model
//! (`EllipseCentre` for comparison). A single circle has no grid
//! neighbours and keeps its ellipse centre.
//!
//! # Time bound
//!
//! Work is bounded by the number of candidates kept (a few per expected
//! point) and seeds tried, so blank or noise images fail in about the time
//! of two smoothing passes.

mod blobs;
mod centres;
pub(crate) mod chessboard;
mod circles;
mod ellipse;
mod lattice;
pub mod markers;
pub mod polarity;
mod refine;
mod runs;
mod saddle;
mod squares;

use crate::error::{Error, Result};
use crate::image::filter::Plane;
use crate::image::GrayImage;
pub use crate::target::CentreModel;
use crate::target::{DetectedPoint, Detection, Polarity, Target};

/// Smallest image side the detectors accept, pixels.
pub const MIN_IMAGE_SIDE_PX: u32 = 16;

/// Tunables of [`detect`].
#[derive(Debug, Clone, PartialEq)]
pub struct DetectOptions {
    /// Long side of the pyramid level where chessboards are first searched,
    /// pixels (default 256, then up to two finer levels; circle grids use
    /// at least 2048). Corners are
    /// always refined at full resolution.
    pub max_working_side_px: u32,
    /// Which point of each imaged circle circle grids and dot plates report
    /// (default [`CentreModel::PerspectivePole`]; `EllipseCentre` turns
    /// the perspective correction off, for comparison). Recorded in the
    /// detection as `centre_model`.
    pub circle_centres: CentreModel,
    /// The print to search (`Some`: only that one; the spec options
    /// `:dark-on-light` / `:light-on-dark`, [`Target::parse_spec_print`]),
    /// or `None` (default) to find either ([`polarity`] docs).
    pub polarity: Option<Polarity>,
}

impl Default for DetectOptions {
    fn default() -> Self {
        DetectOptions {
            max_working_side_px: 256,
            circle_centres: CentreModel::default(),
            polarity: None,
        }
    }
}

/// Find `target` in `image`, printed dark on light or light on dark
/// (`polarity` docs; [`DetectOptions::polarity`] may force one). The
/// detection's `polarity` says which print was found.
///
/// Errors: [`Error::Image`] for images smaller than 16x16 pixels,
/// [`Error::NotFound`] when the target is absent or incomplete (the message
/// gives counts and likely causes, and names the print option when a forced
/// print missed a board the other print finds), [`Error::Invalid`] for a
/// bad target.
pub fn detect(image: &GrayImage, target: &Target, options: &DetectOptions) -> Result<Detection> {
    check_image(image)?;
    let target = target.clone().validated()?;
    match (&target, options.polarity) {
        // Found in either print by the same corners; the print is read off
        // the found board (`polarity` docs), so a miss is not searched again.
        (Target::Chessboard { cols, rows, .. }, None) => {
            let points = chessboard::detect_chessboard(image, *cols, *rows, options)?;
            match polarity::chessboard_print(image, &points, *cols, *rows) {
                Polarity::DarkOnLight => Ok(detection(
                    image,
                    &target,
                    points,
                    Polarity::DarkOnLight,
                    options,
                )),
                Polarity::LightOnDark => {
                    detect_printed(image, &target, Polarity::LightOnDark, options).or_else(|_| {
                        Ok(detection(
                            image,
                            &target,
                            points,
                            Polarity::DarkOnLight,
                            options,
                        ))
                    })
                }
            }
        }
        // The other print would find the same corners or none: no retry.
        (Target::Chessboard { .. }, Some(print)) => detect_printed(image, &target, print, options),
        (Target::Charuco { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. }, forced) => {
            let mut own = marker_boards(image, &target, forced, true)?;
            own.pop().ok_or_else(|| Error::NotFound {
                message: format!("board not found: {}", target.to_spec()),
            })
        }
        (_, forced) => polarity::search(&target, forced, |print| {
            detect_printed(image, &target, print, options)
        }),
    }
}

/// `target` (validated) searched in one print.
fn detect_printed(
    image: &GrayImage,
    target: &Target,
    print: Polarity,
    options: &DetectOptions,
) -> Result<Detection> {
    // Circle grids and dot plates threshold for either print; the other
    // detectors see dark marks, so a light-on-dark print is inverted.
    let inverted_image;
    let seen = match (target, print) {
        (Target::CircleGrid { .. } | Target::DotPlate { .. }, _) | (_, Polarity::DarkOnLight) => {
            image
        }
        (_, Polarity::LightOnDark) => {
            inverted_image = polarity::inverted(image);
            &inverted_image
        }
    };
    let points = match target {
        Target::Chessboard { cols, rows, .. } => {
            chessboard::detect_chessboard(seen, *cols, *rows, options)?
        }
        Target::CircleGrid { asymmetric, .. } => {
            circles::detect_grid(seen, target, print, *asymmetric, None, options)?
        }
        Target::DotPlate {
            pitch_m,
            dot_diameter_m,
            ..
        } => circles::detect_grid(
            seen,
            target,
            print,
            false,
            Some(dot_diameter_m / pitch_m),
            options,
        )?,
        Target::OriginDotGrid { .. } => circles::detect_origin_dot_grid(seen, target, options)?,
        Target::SingleCircle { .. } => vec![circles::detect_single(seen, options)?],
        Target::SquareGrid {
            cols,
            rows,
            side_m,
            pitch_m,
        } => squares::detect_square_grid(seen, *cols, *rows, side_m / pitch_m, options)?,
        Target::Charuco { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. } => {
            let mut found = markers::detect_one(seen, target, options)?;
            found.polarity = Some(print);
            return Ok(found);
        }
    };
    Ok(detection(image, target, points, print, options))
}

/// The detection of `points` of `target` found printed `print`.
fn detection(
    image: &GrayImage,
    target: &Target,
    points: Vec<DetectedPoint>,
    print: Polarity,
    options: &DetectOptions,
) -> Detection {
    let centre_model = match target {
        Target::CircleGrid { .. } | Target::DotPlate { .. } | Target::OriginDotGrid { .. } => {
            Some(options.circle_centres)
        }
        Target::Chessboard { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. }
        | Target::Charuco { .. }
        | Target::Aprilgrid { .. }
        | Target::ArucoGrid { .. } => None,
    };
    Detection {
        image_size_px: [image.width, image.height],
        target: target.clone(),
        points,
        centre_model,
        polarity: Some(print),
    }
}

/// Every board of `target` in `image`: for ChArUco boards, AprilGrids and
/// ArUco grids,
/// one detection per board of the same layout (the target's own ids
/// first, then boards printed with other blocks of consecutive ids, e.g.
/// Kalibr's `two_boards` frame with tags 0-35 and 36-71; each detection's
/// target carries its first id); for other targets the one detection of
/// [`detect`]. Errors as [`detect`] when there is none.
pub fn detect_all(
    image: &GrayImage,
    target: &Target,
    options: &DetectOptions,
) -> Result<Vec<Detection>> {
    check_image(image)?;
    match target {
        Target::Charuco { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. } => {
            marker_boards(image, target, options.polarity, false)
        }
        Target::Chessboard { .. }
        | Target::CircleGrid { .. }
        | Target::DotPlate { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. }
        | Target::OriginDotGrid { .. } => Ok(vec![detect(image, target, options)?]),
    }
}

/// Every board of a marker-board target's layout (`own`: the target's own
/// board alone, an error when only others are seen), in either print
/// (`polarity::search_markers`), each detection with the print found.
fn marker_boards(
    image: &GrayImage,
    target: &Target,
    forced: Option<Polarity>,
    own: bool,
) -> Result<Vec<Detection>> {
    let mut inverted_image: Option<GrayImage> = None;
    let large = markers::decimates(image);
    polarity::search_markers(target, forced, large, |print, resolutions| {
        let seen = match print {
            Polarity::DarkOnLight => image,
            Polarity::LightOnDark => {
                inverted_image.get_or_insert_with(|| polarity::inverted(image))
            }
        };
        let (boards, read) = markers::boards_at(seen, target, resolutions);
        let boards = match own {
            true => markers::own_board(target, boards).map(|d| vec![d]),
            false => boards,
        };
        let boards = boards.map(|mut b| {
            b.iter_mut().for_each(|d| d.polarity = Some(print));
            b
        });
        (boards, read)
    })
}

/// Size checks shared by the entry points.
fn check_image(image: &GrayImage) -> Result<()> {
    let (w, h) = (image.width, image.height);
    if w < MIN_IMAGE_SIDE_PX || h < MIN_IMAGE_SIDE_PX {
        return Err(Error::Image {
            message: format!(
                "image is {w}x{h} pixels; detection needs at least {MIN_IMAGE_SIDE_PX}x{MIN_IMAGE_SIDE_PX}"
            ),
        });
    }
    if image.pixels.len() != w as usize * h as usize {
        return Err(Error::Image {
            message: format!(
                "a {w}x{h} image needs {} bytes, got {}",
                w as usize * h as usize,
                image.pixels.len()
            ),
        });
    }
    Ok(())
}

/// The coarsest pyramid level whose long side is at most `max_side`
/// (at least 64 px, at most level 8).
pub(crate) fn working_level(img: &GrayImage, max_side: u32) -> u32 {
    let long = img.width.max(img.height).max(1);
    let max_side = max_side.max(64);
    let mut level = 0u32;
    while (long >> level) > max_side && level < 8 {
        level += 1;
    }
    level
}

/// Pyramid levels to search, coarsest first: the first level whose long
/// side is at most `max_side`, then the next finer one (if any).
pub(crate) fn pyramid_levels(img: &GrayImage, max_side: u32) -> Vec<(u32, Plane)> {
    let coarse = working_level(img, max_side);
    let finest = coarse.saturating_sub(1);
    let mut plane = if finest == 0 {
        Plane::from_gray(img)
    } else {
        downsample_gray(img)
    };
    let mut level = if finest == 0 { 0 } else { 1 };
    while level < finest {
        plane = plane.downsample2();
        level += 1;
    }
    let mut out = Vec::new();
    if coarse > finest {
        out.push((coarse, plane.downsample2()));
    }
    out.push((finest, plane));
    out
}

/// Level 1 of the pyramid straight from 8-bit pixels (no full-size f32 copy).
fn downsample_gray(img: &GrayImage) -> Plane {
    let (iw, ih) = (img.width as usize, img.height as usize);
    let w = (iw / 2).max(1);
    let h = (ih / 2).max(1);
    let mut data = vec![0.0f32; w * h];
    for y in 0..h {
        let r0 = (2 * y).min(ih - 1) * iw;
        let r1 = (2 * y + 1).min(ih - 1) * iw;
        for x in 0..w {
            let x0 = (2 * x).min(iw - 1);
            let x1 = (2 * x + 1).min(iw - 1);
            let s = img.pixels[r0 + x0] as u32
                + img.pixels[r0 + x1] as u32
                + img.pixels[r1 + x0] as u32
                + img.pixels[r1 + x1] as u32;
            data[y * w + x] = s as f32 * 0.25;
        }
    }
    Plane { w, h, data }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn tiny_images_are_refused_with_their_size() {
        let img = GrayImage::new(1, 1, vec![0]).unwrap();
        let t = Target::parse_spec("chessboard:9x6:30mm").unwrap();
        let e = detect(&img, &t, &DetectOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "image is 1x1 pixels; detection needs at least 16x16"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn random_images_never_panic_and_find_nothing() {
        // Property: for seeded random images of random sizes and contents
        // (uniform noise, constant, stripes), every target kind returns an
        // error or a detection, never a panic.
        let mut rng = Rng::new(2024);
        let targets = [
            "chessboard:9x6:30mm",
            "circles:4x11:20mm:asymmetric",
            "circles:4x4:20mm:light-on-dark",
            "dots:7x7:25mm",
            "circle:10mm",
            "squares:8x8:12.7mm:22.5778mm",
            "charuco:5x7:30mm:22mm:DICT_4X4_50",
            "charuco:4x4:30mm:22mm:DICT_APRILTAG_16h5:legacy",
            "aprilgrid:3x3:40mm:0.3",
        ];
        for case in 0..24 {
            let w = 16 + rng.below(120) as u32;
            let h = 16 + rng.below(120) as u32;
            let kind = case % 3;
            let px: Vec<u8> = (0..w * h)
                .map(|i| match kind {
                    0 => rng.below(256) as u8,
                    1 => 77,
                    _ => {
                        if (i % w) % 7 < 3 {
                            20
                        } else {
                            230
                        }
                    }
                })
                .collect();
            let img = GrayImage::new(w, h, px).unwrap();
            for spec in targets {
                let t = Target::parse_spec(spec).unwrap();
                let r = detect(&img, &t, &DetectOptions::default());
                if let Err(e) = &r {
                    assert!(
                        matches!(e, Error::NotFound { .. }),
                        "{spec} on {w}x{h}: {e}"
                    );
                }
                if spec.starts_with("chessboard") {
                    assert!(r.is_err(), "a chessboard in noise case {case}");
                }
            }
        }
    }
}
