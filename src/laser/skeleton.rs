//! Seed 003's control points from a laser image: the image binarised at a
//! grey level, the stripe thinned to one pixel (Zhang-Suen), and the end
//! points of the thinned lines found (a skeleton pixel with exactly one of
//! its 8 neighbours set: the paper's "structure elements").
//!
//! Thinning erodes a line's end by about half its width; each end is
//! therefore also carried out along the skeleton's direction to where the
//! binarised stripe itself ends ([`EndPoint::refined_px`]): the cut of the
//! line by a cube's edge or a hole's rim.

use crate::error::{Error, Result};
use crate::image::GrayImage;
use serde::Serialize;

/// One end of a thinned stripe.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EndPoint {
    /// The skeleton's end pixel `[x, y]`.
    pub pixel: [usize; 2],
    /// The end carried along the skeleton's direction to the binarised
    /// stripe's end, pixels.
    pub refined_px: [f64; 2],
    /// Unit direction of the line towards this end (image axes).
    pub direction: [f64; 2],
    /// Pixels of the skeleton piece this end belongs to.
    pub piece_len: usize,
}

/// Pixels of the skeleton followed back from an end to find its direction.
const BACK: usize = 6;

/// The end points of the stripe in `image`: binarised at `threshold`
/// (grey level, the pixel > threshold), thinned, pieces shorter than
/// `min_len` pixels dropped (speckle). In scan order (row, then column).
pub fn end_points(image: &GrayImage, threshold: u8, min_len: usize) -> Result<Vec<EndPoint>> {
    let (w, h) = (image.width as usize, image.height as usize);
    if w < 3 || h < 3 {
        return Err(Error::invalid(
            "laser image",
            format!("needs at least 3x3 pixels, got {w}x{h}"),
        ));
    }
    let mask: Vec<bool> = image.pixels.iter().map(|&v| v > threshold).collect();
    let skeleton = thin(&mask, w, h);
    let at = |x: isize, y: isize| -> bool {
        x >= 0
            && y >= 0
            && (x as usize) < w
            && (y as usize) < h
            && skeleton[y as usize * w + x as usize]
    };
    let neighbours = |x: usize, y: usize| -> Vec<(usize, usize)> {
        let mut v = Vec::new();
        for dy in -1isize..=1 {
            for dx in -1isize..=1 {
                let (nx, ny) = (x as isize + dx, y as isize + dy);
                if (dx, dy) != (0, 0) && at(nx, ny) {
                    v.push((nx as usize, ny as usize));
                }
            }
        }
        v
    };
    let piece_sizes = piece_sizes(&skeleton, w, h);
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if !skeleton[y * w + x] || neighbours(x, y).len() != 1 {
                continue;
            }
            let len = piece_sizes[y * w + x];
            if len < min_len {
                continue;
            }
            // Walk back along the skeleton.
            let (mut prev, mut cur) = ((x, y), neighbours(x, y)[0]);
            for _ in 1..BACK {
                let next: Vec<(usize, usize)> = neighbours(cur.0, cur.1)
                    .into_iter()
                    .filter(|&p| p != prev && p != (x, y))
                    .collect();
                if next.len() != 1 {
                    break;
                }
                prev = cur;
                cur = next[0];
            }
            let (dx, dy) = (x as f64 - cur.0 as f64, y as f64 - cur.1 as f64);
            let norm = (dx * dx + dy * dy).sqrt().max(1e-9);
            let dir = [dx / norm, dy / norm];
            // Out along the direction while the binarised stripe is set.
            let inside = |px: f64, py: f64| {
                let (ix, iy) = (px.round(), py.round());
                ix >= 0.0
                    && iy >= 0.0
                    && (ix as usize) < w
                    && (iy as usize) < h
                    && mask[iy as usize * w + ix as usize]
            };
            let mut s = 0.0;
            while s < 2.0 * BACK as f64
                && inside(
                    x as f64 + dir[0] * (s + 0.25),
                    y as f64 + dir[1] * (s + 0.25),
                )
            {
                s += 0.25;
            }
            // `s` is the last sample inside the last set pixel, about a
            // quarter pixel past its centre: where, on average, a cut lies
            // whose pixel is set from a quarter's coverage on (a saturated
            // core four times the threshold).
            let reach = s;
            out.push(EndPoint {
                pixel: [x, y],
                refined_px: [x as f64 + dir[0] * reach, y as f64 + dir[1] * reach],
                direction: dir,
                piece_len: len,
            });
        }
    }
    Ok(out)
}

/// The size of each pixel's 8-connected piece of `mask` (0 off the mask).
fn piece_sizes(mask: &[bool], w: usize, h: usize) -> Vec<usize> {
    let mut label = vec![usize::MAX; w * h];
    let mut sizes = Vec::new();
    for start in 0..w * h {
        if !mask[start] || label[start] != usize::MAX {
            continue;
        }
        let id = sizes.len();
        let mut stack = vec![start];
        label[start] = id;
        let mut n = 0;
        while let Some(k) = stack.pop() {
            n += 1;
            let (x, y) = ((k % w) as isize, (k / w) as isize);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx as usize >= w || ny as usize >= h {
                        continue;
                    }
                    let j = ny as usize * w + nx as usize;
                    if mask[j] && label[j] == usize::MAX {
                        label[j] = id;
                        stack.push(j);
                    }
                }
            }
        }
        sizes.push(n);
    }
    label
        .iter()
        .map(|&l| if l == usize::MAX { 0 } else { sizes[l] })
        .collect()
}

/// Zhang-Suen thinning (Zhang and Suen, CACM 1984) of a binary image to
/// one-pixel lines; the border pixels are taken as background.
pub fn thin(mask: &[bool], w: usize, h: usize) -> Vec<bool> {
    let mut img: Vec<bool> = mask.to_vec();
    for y in 0..h {
        for x in 0..w {
            if x == 0 || y == 0 || x + 1 == w || y + 1 == h {
                img[y * w + x] = false;
            }
        }
    }
    loop {
        let mut changed = false;
        for pass in 0..2 {
            let mut remove = Vec::new();
            for y in 1..h.saturating_sub(1) {
                for x in 1..w.saturating_sub(1) {
                    if !img[y * w + x] {
                        continue;
                    }
                    // P2..P9 clockwise from north.
                    let p = |dx: isize, dy: isize| {
                        img[(y as isize + dy) as usize * w + (x as isize + dx) as usize] as u8
                    };
                    let n = [
                        p(0, -1),
                        p(1, -1),
                        p(1, 0),
                        p(1, 1),
                        p(0, 1),
                        p(-1, 1),
                        p(-1, 0),
                        p(-1, -1),
                    ];
                    let b: u8 = n.iter().sum();
                    let a = (0..8).filter(|&i| n[i] == 0 && n[(i + 1) % 8] == 1).count();
                    let (p2, p4, p6, p8) = (n[0], n[2], n[4], n[6]);
                    let cond = if pass == 0 {
                        p2 * p4 * p6 == 0 && p4 * p6 * p8 == 0
                    } else {
                        p2 * p4 * p8 == 0 && p2 * p6 * p8 == 0
                    };
                    if (2..=6).contains(&b) && a == 1 && cond {
                        remove.push(y * w + x);
                    }
                }
            }
            changed |= !remove.is_empty();
            for k in remove {
                img[k] = false;
            }
        }
        if !changed {
            return img;
        }
    }
}
