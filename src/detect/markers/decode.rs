//! Reading a candidate quad as a marker: perspective-rectified bit
//! sampling, a threshold between the dark and light cells (Otsu over the
//! cell means), the border check and the dictionary's error-correcting
//! decode.

use super::homography::Homography;
use super::quads::Quad;
use crate::image::GrayImage;
use crate::target::dictionary::Dictionary;
use nalgebra::Point2;

/// Samples per cell side (the middle of each cell, away from its edges).
const SAMPLES_PER_CELL: usize = 3;
/// Fraction of a cell's side the samples spread over, centred.
const SAMPLE_SPREAD: f64 = 0.5;
/// Least grey-level difference between the light and dark cells' means.
const MIN_CONTRAST: f64 = 20.0;
/// Border cells that may read light, as a fraction of the border (OpenCV's
/// maxErroneousBitsInBorderRate is 0.35; stricter here, the border is what
/// rejects false markers).
const MAX_BORDER_ERROR_RATE: f64 = 0.1;
/// [`MIN_CONTRAST`] for a read where the board predicts a marker: the
/// place and the id are known, so a faint marker (blur, low contrast,
/// small) is read too.
const EXPECTED_MIN_CONTRAST: f64 = 8.0;
/// [`MAX_BORDER_ERROR_RATE`] for a read where the board predicts a marker
/// (OpenCV's maxErroneousBitsInBorderRate).
const EXPECTED_MAX_BORDER_ERROR_RATE: f64 = 0.35;

/// Markers with at least this many bits a side (6 x 6: AprilGrid's 36h11,
/// `DICT_6X6_*`, `DICT_7X7_*`) are read at a predicted place with their own
/// threshold too ([`read_expected`]).
const OWN_THRESHOLD_MIN_BITS: usize = 6;

/// A decoded marker in the image.
#[derive(Debug, Clone)]
pub(crate) struct Marker {
    /// Dictionary id.
    pub id: usize,
    /// Corners in the marker's own order (top-left, top-right,
    /// bottom-right, bottom-left of its rotation 0), pixels.
    pub corners: [Point2<f64>; 4],
    /// Bits that differed from the dictionary's marker.
    pub bit_errors: u32,
}

/// Read `quad` as a marker of `dictionary` with a `border`-bit black
/// border, accepting up to `max_bit_errors` wrong bits.
pub(crate) fn read_marker(
    img: &GrayImage,
    quad: &Quad,
    dictionary: Dictionary,
    border: usize,
    max_bit_errors: u32,
) -> Option<Marker> {
    let n = dictionary.marker_bits() + 2 * border;
    let cells = sample_cells(img, &quad.corners, n)?;
    let code = classify(&cells, n, border, MIN_CONTRAST, MAX_BORDER_ERROR_RATE)?;
    // 4. Decode; the marker's own top-left is sampled corner `rotation`.
    let d = dictionary.decode(code, max_bit_errors)?;
    let corners = [0, 1, 2, 3].map(|j| quad.corners[(d.rotation + j) % 4]);
    Some(Marker {
        id: d.id,
        corners,
        bit_errors: d.bit_errors,
    })
}

/// Whether the cells inside `corners` (the marker's own corner order,
/// rotation 0) read as `dictionary`'s marker `id` with at most
/// `max_bit_errors` wrong bits, under the looser contrast and border
/// limits of a read at a place the board predicts (`recover.rs`): the
/// bit errors, or `None`. A read that is another marker of the dictionary
/// exactly is refused.
///
/// The cells are split by Otsu's threshold over every cell (the search's)
/// and, for markers of [`OWN_THRESHOLD_MIN_BITS`] bits a side or more, also
/// by the expected marker's own threshold, midway between the means of the
/// inner cells it has light and those it has dark ([`classify_expected`]);
/// the read with fewer wrong bits counts. Otsu's
/// sits low when the dark border is most of the cells, and blur greys the
/// isolated light bits: on AprilGrid tags of 18-24 px (cells of 2.2 px)
/// under 1.2 px blur, read at their true place, 42 of 210 read within 4
/// wrong bits with Otsu, 77 with the expected marker's threshold (137
/// within 6); 30 other 36h11 ids read at each of those places never came
/// within 8. On the 4 x 4 ChArUco markers of
/// tests/detect/detect_marker_recall.rs (16-21 px) the second read cost
/// corners instead (one view 50 -> 31, the set 412 -> 398 of 972; why was
/// not found): small dictionaries keep the one read.
pub(crate) fn read_expected(
    img: &GrayImage,
    corners: &[Point2<f64>; 4],
    dictionary: Dictionary,
    border: usize,
    id: usize,
    max_bit_errors: u32,
) -> Option<u32> {
    let n = dictionary.marker_bits() + 2 * border;
    let cells = sample_cells(img, corners, n)?;
    let expected = dictionary.code(id)?;
    let otsu = classify(
        &cells,
        n,
        border,
        EXPECTED_MIN_CONTRAST,
        EXPECTED_MAX_BORDER_ERROR_RATE,
    );
    let own = if dictionary.marker_bits() >= OWN_THRESHOLD_MIN_BITS {
        classify_expected(&cells, n, border, expected)
    } else {
        None
    };
    [otsu, own]
        .into_iter()
        .flatten()
        .filter(|&code| match dictionary.decode(code, 0) {
            Some(d) => d.id == id && d.rotation == 0,
            None => true,
        })
        .map(|code| (code ^ expected).count_ones())
        .filter(|&errors| errors <= max_bit_errors)
        .min()
}

/// Mean grey level of each of the `n` x `n` cells of the quad `corners`
/// (row-major, rectified by the quad's homography), `None` when a sample
/// falls outside the image.
fn sample_cells(img: &GrayImage, corners: &[Point2<f64>; 4], n: usize) -> Option<Vec<f64>> {
    let unit = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let pairs: Vec<_> = unit
        .iter()
        .zip(corners)
        .map(|(&(u, v), c)| (Point2::new(u, v), *c))
        .collect();
    let h = Homography::fit(&pairs)?;
    let off = |s: usize| 0.5 + SAMPLE_SPREAD * ((s as f64 + 0.5) / SAMPLES_PER_CELL as f64 - 0.5);
    let mut cells = vec![0.0; n * n];
    for row in 0..n {
        for col in 0..n {
            let mut sum = 0.0;
            for sy in 0..SAMPLES_PER_CELL {
                for sx in 0..SAMPLES_PER_CELL {
                    let u = (col as f64 + off(sx)) / n as f64;
                    let v = (row as f64 + off(sy)) / n as f64;
                    let p = h.map(&Point2::new(u, v))?;
                    sum += bilinear(img, p.x, p.y)?;
                }
            }
            cells[row * n + col] = sum / (SAMPLES_PER_CELL * SAMPLES_PER_CELL) as f64;
        }
    }
    Some(cells)
}

/// The inner cells' bits (light = 1, row-major) of sampled `cells`, split
/// by Otsu's threshold, when the light and dark means differ by at least
/// `min_contrast` and at most `max_border_rate` of the border cells read
/// light.
fn classify(
    cells: &[f64],
    n: usize,
    border: usize,
    min_contrast: f64,
    max_border_rate: f64,
) -> Option<u64> {
    let t = otsu(cells)?;
    let (dark, light): (Vec<f64>, Vec<f64>) = cells.iter().copied().partition(|&v| v < t);
    if dark.is_empty() || light.is_empty() {
        return None;
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    if mean(&light) - mean(&dark) < min_contrast {
        return None;
    }
    let is_border =
        |r: usize, c: usize| r < border || c < border || r >= n - border || c >= n - border;
    let mut border_cells = 0;
    let mut border_light = 0;
    let mut code = 0u64;
    for r in 0..n {
        for c in 0..n {
            let light = cells[r * n + c] >= t;
            if is_border(r, c) {
                border_cells += 1;
                border_light += usize::from(light);
            } else {
                code = (code << 1) | u64::from(light);
            }
        }
    }
    if border_light as f64 > max_border_rate * border_cells as f64 {
        return None;
    }
    Some(code)
}

/// The inner cells' bits (light = 1, row-major) of sampled `cells` read
/// against the `expected` code: the threshold lies midway between the
/// means of the inner cells `expected` has light and dark; `None` when
/// `expected` has only one kind, when those means differ by less than
/// [`EXPECTED_MIN_CONTRAST`] or when more than
/// [`EXPECTED_MAX_BORDER_ERROR_RATE`] of the border cells read light.
fn classify_expected(cells: &[f64], n: usize, border: usize, expected: u64) -> Option<u64> {
    let inner = n - 2 * border;
    let nbits = inner * inner;
    let is_border =
        |r: usize, c: usize| r < border || c < border || r >= n - border || c >= n - border;
    let (mut light, mut dark) = ((0.0, 0usize), (0.0, 0usize));
    let mut k = 0;
    for r in 0..n {
        for c in 0..n {
            if is_border(r, c) {
                continue;
            }
            let v = cells[r * n + c];
            if (expected >> (nbits - 1 - k)) & 1 == 1 {
                light = (light.0 + v, light.1 + 1);
            } else {
                dark = (dark.0 + v, dark.1 + 1);
            }
            k += 1;
        }
    }
    if light.1 == 0 || dark.1 == 0 {
        return None;
    }
    let (light, dark) = (light.0 / light.1 as f64, dark.0 / dark.1 as f64);
    if light - dark < EXPECTED_MIN_CONTRAST {
        return None;
    }
    let t = 0.5 * (light + dark);
    let (mut border_cells, mut border_light, mut code) = (0, 0, 0u64);
    for r in 0..n {
        for c in 0..n {
            let is_light = cells[r * n + c] >= t;
            if is_border(r, c) {
                border_cells += 1;
                border_light += usize::from(is_light);
            } else {
                code = (code << 1) | u64::from(is_light);
            }
        }
    }
    if border_light as f64 > EXPECTED_MAX_BORDER_ERROR_RATE * border_cells as f64 {
        return None;
    }
    Some(code)
}

fn bilinear(img: &GrayImage, x: f64, y: f64) -> Option<f64> {
    let (w, h) = (img.width as usize, img.height as usize);
    if !(x >= 0.0 && y >= 0.0 && x <= (w - 1) as f64 && y <= (h - 1) as f64) {
        return None;
    }
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let p = |xx: usize, yy: usize| f64::from(img.pixels[yy * w + xx]);
    Some(
        (p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx) * (1.0 - fy)
            + (p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx) * fy,
    )
}

/// Otsu's threshold of a few values: the split between sorted values that
/// maximises the between-class variance (returned as the midpoint).
fn otsu(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let total: f64 = v.iter().sum();
    let mut best = None;
    let mut best_score = -1.0;
    let mut left = 0.0;
    for k in 1..n {
        left += v[k - 1];
        let (n0, n1) = (k as f64, (n - k) as f64);
        let (m0, m1) = (left / n0, (total - left) / n1);
        let score = n0 * n1 * (m1 - m0) * (m1 - m0);
        if score > best_score && v[k] > v[k - 1] {
            best_score = score;
            best = Some(0.5 * (v[k] + v[k - 1]));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::markers::recover::recover_bit_errors;
    use crate::rng::Rng;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// Marker `id` of `dictionary` with `border` dark cells around it,
    /// drawn axis-aligned at (8, 8) with cells of `cell` px (dark 90, light
    /// 140: low contrast), blurred by a Gaussian of `blur` px and given
    /// noise of std 2 grey levels; with the marker's outer corners.
    fn drawn(
        dictionary: Dictionary,
        id: usize,
        border: usize,
        cell: f64,
        blur: f64,
    ) -> (GrayImage, [Point2<f64>; 4]) {
        let bits = dictionary.marker_bits();
        let n = bits + 2 * border;
        let code = dictionary.code(id).unwrap();
        let side = cell * n as f64;
        let size = (side + 16.0).ceil() as usize;
        let value = |x: f64, y: f64| -> f64 {
            let (c, r) = (((x - 8.0) / cell).floor(), ((y - 8.0) / cell).floor());
            if c < 0.0 || r < 0.0 || c >= n as f64 || r >= n as f64 {
                return 200.0; // the white paper around the marker
            }
            let (r, c) = (r as usize, c as usize);
            if r < border || c < border || r >= n - border || c >= n - border {
                return 90.0;
            }
            let k = (r - border) * bits + (c - border);
            if (code >> (bits * bits - 1 - k)) & 1 == 1 {
                140.0
            } else {
                90.0
            }
        };
        // 4 x 4 samples a pixel, then a separable Gaussian.
        let mut sharp = vec![0.0; size * size];
        for y in 0..size {
            for x in 0..size {
                let mut sum = 0.0;
                for s in 0..16 {
                    let (dx, dy) = ((s % 4) as f64 + 0.5, (s / 4) as f64 + 0.5);
                    sum += value(x as f64 + dx / 4.0, y as f64 + dy / 4.0);
                }
                sharp[y * size + x] = sum / 16.0;
            }
        }
        let radius = (3.0 * blur).ceil() as isize;
        let kernel: Vec<f64> = (-radius..=radius)
            .map(|d| (-(d * d) as f64 / (2.0 * blur * blur)).exp())
            .collect();
        let total: f64 = kernel.iter().sum();
        let pass = |src: &[f64], across: bool| -> Vec<f64> {
            let mut out = vec![0.0; size * size];
            for y in 0..size {
                for x in 0..size {
                    let mut sum = 0.0;
                    for (i, w) in kernel.iter().enumerate() {
                        let d = i as isize - radius;
                        let (xx, yy) = if across {
                            ((x as isize + d).clamp(0, size as isize - 1) as usize, y)
                        } else {
                            (x, (y as isize + d).clamp(0, size as isize - 1) as usize)
                        };
                        sum += w * src[yy * size + xx];
                    }
                    out[y * size + x] = sum / total;
                }
            }
            out
        };
        let blurred = pass(&pass(&sharp, true), false);
        let mut rng = Rng::new(id as u64 + 1);
        let pixels = blurred
            .iter()
            .map(|v| (v + rng.gaussian(2.0)).round().clamp(0.0, 255.0) as u8)
            .collect();
        // Pixel centres at integer coordinates: the cell edges sit 0.5 px
        // before the drawn positions.
        let (a, b) = (8.0 - 0.5, 8.0 - 0.5 + side);
        let corners = [
            Point2::new(a, a),
            Point2::new(b, a),
            Point2::new(b, b),
            Point2::new(a, b),
        ];
        let image = GrayImage {
            width: size as u32,
            height: size as u32,
            pixels,
        };
        (image, corners)
    }

    /// At a place the board predicts, the marker that is there reads as
    /// itself, and no other marker of the dictionary reads as the predicted
    /// id within the recovery's bit-error limit: 6x6 AprilTags (own
    /// threshold, 6 wrong bits allowed) of 2.5 px cells under 1 px blur,
    /// and ArUco 4x4 (Otsu only, 2 allowed); every other id of the
    /// dictionary's first 200 tried at each place.
    #[wasm_bindgen_test(unsupported = test)]
    fn a_wrong_marker_at_a_predicted_place_is_not_read_as_the_predicted_one() {
        for (dictionary, border, cell, blur) in [
            (Dictionary::DICT_APRILTAG_36h11, 2, 2.5, 1.0),
            (Dictionary::DICT_APRILTAG_36h11, 1, 3.0, 0.8),
            (Dictionary::DICT_4X4_50, 1, 4.0, 1.0),
        ] {
            let limit = recover_bit_errors(dictionary.marker_bits());
            let ids = dictionary.len().min(200);
            for there in [0, 7, 23, 41] {
                let (image, corners) = drawn(dictionary, there, border, cell, blur);
                let own = read_expected(&image, &corners, dictionary, border, there, limit);
                assert!(
                    own.is_some_and(|e| e <= 1),
                    "{dictionary:?} id {there}: read itself with {own:?} wrong bits"
                );
                for predicted in (0..ids).filter(|&p| p != there) {
                    let read =
                        read_expected(&image, &corners, dictionary, border, predicted, limit);
                    assert!(
                        read.is_none(),
                        "{dictionary:?}: marker {there} read as {predicted} with {read:?} wrong bits"
                    );
                }
            }
        }
    }
}
