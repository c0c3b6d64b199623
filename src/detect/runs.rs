//! The dark-pixel mask of [`super::blobs`] as horizontal runs, and its
//! 4-connected components with their moments, found run by run.
//!
//! A pixel is "dark" when it lies below the local mean (box window of an
//! eighth of the image) by a quarter of the local mean's distance to the
//! image's 5th-percentile grey level (at least 8 levels). The mask is never
//! stored: each row's dark pixels become runs `[x0, x1)`, and the
//! components are unions of runs that overlap a run of the row above, so
//! the labelling and the moments cost per run, not per pixel (a circle
//! grid's mask has a few hundred runs per row at most).
//!
//! 8-bit images (the usual working level of circle grids and dot plates)
//! are thresholded in integers ([`dark_runs_u8`]); float planes (coarser
//! pyramid levels) in `f64` ([`dark_runs_plane`]). Both compute the same
//! test (on integer grey levels the `f64` one is exact), so both give the
//! same mask, and the moments are exact integer sums: the blobs are
//! bit-for-bit those of the per-pixel labelling this replaced.

use crate::image::filter::Plane;
use crate::image::GrayImage;

/// Dark runs of an image, row by row.
pub(crate) struct Runs {
    pub w: usize,
    pub h: usize,
    /// `[x0, x1)` of each run, rows in order, each row's runs left to right.
    pub spans: Vec<(u32, u32)>,
    /// Row `y`'s runs are `spans[row_start[y]..row_start[y + 1]]`.
    pub row_start: Vec<usize>,
}

impl Runs {
    fn new(w: usize, h: usize) -> Runs {
        Runs {
            w,
            h,
            spans: Vec::new(),
            row_start: Vec::with_capacity(h + 1),
        }
    }

    /// Appends one row's mask (0: not dark, 1: dark) as runs.
    fn push_row(&mut self, mask: &[u8]) {
        self.row_start.push(self.spans.len());
        let mut x = 0;
        let w = mask.len();
        while x < w {
            // Most of a row is not dark: eight pixels at a time.
            if let Some(word) = mask.get(x..x + 8) {
                if word.iter().fold(0u8, |a, &m| a | m) == 0 {
                    x += 8;
                    continue;
                }
            }
            if mask[x] == 0 {
                x += 1;
                continue;
            }
            let x0 = x;
            while x < w && mask[x] != 0 {
                x += 1;
            }
            self.spans.push((x0 as u32, x as u32));
        }
    }

    fn finish(&mut self) {
        self.row_start.push(self.spans.len());
    }
}

/// The grey level under which a fraction `q` of the `n` counted pixels lie.
fn percentile(hist: &[usize; 256], n: usize, q: f64) -> usize {
    let target = (q * n as f64) as usize;
    let mut acc = 0;
    for (v, c) in hist.iter().enumerate() {
        acc += c;
        if acc > target {
            return v;
        }
    }
    255
}

/// Half-width of the local-mean window, pixels.
fn window_radius(w: usize, h: usize) -> usize {
    (w.min(h) / 16).max(8)
}

/// Whether [`dark_runs_u8`] can take `img`: every box sum of its grey
/// levels fits in `u32` (about 16 MP).
pub(crate) fn fits_u8(img: &GrayImage) -> bool {
    (img.width as u64) * (img.height as u64) * 255 < u32::MAX as u64
}

/// Dark runs of an 8-bit image (of light runs with `invert`), in integer
/// arithmetic; `img` must pass [`fits_u8`]. The window sums come from
/// column sums over the window's rows, updated row by row, and their
/// prefix along the row: no image-sized buffer.
pub(crate) fn dark_runs_u8(img: &GrayImage, invert: bool) -> Runs {
    let (w, h) = (img.width as usize, img.height as usize);
    let flip = if invert { 255u8 } else { 0 };
    let row_of = |y: usize| &img.pixels[y * w..(y + 1) * w];
    let mut hist = [0usize; 256];
    for &p in &img.pixels {
        hist[(p ^ flip) as usize] += 1;
    }
    let p5 = percentile(&hist, w * h, 0.05) as i32;
    let r = window_radius(w, h);
    // Each column's window [x0, x1) and its width.
    let x0s: Vec<usize> = (0..w).map(|x| x.saturating_sub(r)).collect();
    let x1s: Vec<usize> = (0..w).map(|x| (x + r + 1).min(w)).collect();
    let widths: Vec<i32> = x0s.iter().zip(&x1s).map(|(a, b)| (b - a) as i32).collect();
    // Column sums over the window's rows (the window of row 0 first). Every
    // sum here is at most the image's total, below 2^32 (`fits_u8`).
    let mut col_sum = vec![0u32; w];
    for y in 0..(r + 1).min(h) {
        for (c, &p) in col_sum.iter_mut().zip(row_of(y)) {
            *c += (p ^ flip) as u32;
        }
    }
    let mut prefix = vec![0u32; w + 1];
    let mut sums = vec![0i32; w];
    let mut runs = Runs::new(w, h);
    let mut mask = vec![0u8; w];
    for y in 0..h {
        if y > 0 {
            if y + r < h {
                for (c, &p) in col_sum.iter_mut().zip(row_of(y + r)) {
                    *c += (p ^ flip) as u32;
                }
            }
            if y > r {
                for (c, &p) in col_sum.iter_mut().zip(row_of(y - r - 1)) {
                    *c -= (p ^ flip) as u32;
                }
            }
        }
        for x in 0..w {
            prefix[x + 1] = prefix[x] + col_sum[x];
        }
        for (s, (&x0, &x1)) in sums.iter_mut().zip(x0s.iter().zip(&x1s)) {
            *s = (prefix[x1] - prefix[x0]) as i32;
        }
        let rows = ((y + r + 1).min(h) - y.saturating_sub(r)) as i32;
        // v < mean - max((mean - p5) / 4, 8), times 4 and the window's
        // area: the test of `dark_runs_plane` in integers. In i32: a window
        // is at most 513x513 pixels (`fits_u8`: the short side is at most
        // 4096, r at most 256), so 4 * 255 * area < 2^31.
        for (((m, &p), &s), &width) in mask.iter_mut().zip(row_of(y)).zip(&sums).zip(&widths) {
            let area = rows * width;
            let v = (p ^ flip) as i32;
            let drop4 = (s - p5 * area).max(32 * area);
            *m = (4 * v * area < 4 * s - drop4) as u8;
        }
        runs.push_row(&mask);
    }
    runs.finish();
    runs
}

/// Dark runs of a float plane (of light runs with `invert`, values taken
/// as `255 - v`).
pub(crate) fn dark_runs_plane(plane: &Plane, invert: bool) -> Runs {
    let (w, h) = (plane.w, plane.h);
    let val = |v: f32| if invert { 255.0 - v } else { v };
    let mut integral = vec![0.0f64; (w + 1) * (h + 1)];
    let mut hist = [0usize; 256];
    for y in 0..h {
        let mut row = 0.0;
        let (above, here) = integral.split_at_mut((y + 1) * (w + 1));
        let above = &above[y * (w + 1)..];
        for (x, &v) in plane.data[y * w..(y + 1) * w].iter().enumerate() {
            let v = val(v);
            hist[v.clamp(0.0, 255.0) as usize] += 1;
            row += v as f64;
            here[x + 1] = above[x + 1] + row;
        }
    }
    let p5 = percentile(&hist, w * h, 0.05) as f64;
    let r = window_radius(w, h);
    let cols: Vec<(usize, usize, f64)> = (0..w)
        .map(|x| {
            let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(w));
            (x0, x1, (x1 - x0) as f64)
        })
        .collect();
    let mut runs = Runs::new(w, h);
    let mut mask = vec![0u8; w];
    for y in 0..h {
        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(h));
        let top = &integral[y0 * (w + 1)..(y0 + 1) * (w + 1)];
        let bottom = &integral[y1 * (w + 1)..(y1 + 1) * (w + 1)];
        let rows = (y1 - y0) as f64;
        let row_vals = &plane.data[y * w..(y + 1) * w];
        for ((m, &v), &(x0, x1, width)) in mask.iter_mut().zip(row_vals).zip(&cols) {
            let s = bottom[x1] - top[x1] - bottom[x0] + top[x0];
            // v < mean - max((mean - p5) / 4, 8), times the window's area
            // (no division per pixel).
            let area = rows * width;
            let drop = (0.25 * (s - p5 * area)).max(8.0 * area);
            *m = ((val(v) as f64) * area < s - drop) as u8;
        }
        runs.push_row(&mask);
    }
    runs.finish();
    runs
}

/// Exact moments of a set of pixels: count, sums of x, y, x^2, xy, y^2,
/// and whether it touches the image border.
#[derive(Clone, Copy, Default)]
pub(crate) struct Moments {
    pub n: u64,
    pub sx: u64,
    pub sy: u64,
    pub sxx: u64,
    pub sxy: u64,
    pub syy: u64,
    pub border: bool,
}

impl Moments {
    fn add(&mut self, o: &Moments) {
        self.n += o.n;
        self.sx += o.sx;
        self.sy += o.sy;
        self.sxx += o.sxx;
        self.sxy += o.sxy;
        self.syy += o.syy;
        self.border |= o.border;
    }

    /// The run `[x0, x1)` of row `y` (closed-form sums over its pixels).
    fn of_run(x0: u64, x1: u64, y: u64, border: bool) -> Moments {
        let n = x1 - x0;
        // Sum of x and of x^2 over x0..x1.
        let sx = (x0 + x1 - 1) * n / 2;
        let sq = |m: u64| m * (m + 1) * (2 * m + 1) / 6;
        let sxx = sq(x1 - 1) - if x0 > 0 { sq(x0 - 1) } else { 0 };
        Moments {
            n,
            sx,
            sy: y * n,
            sxx,
            sxy: y * sx,
            syy: y * y * n,
            border,
        }
    }
}

/// The 4-connected components of `runs` with their moments, ordered by
/// their first pixel in raster order.
pub(crate) fn components(runs: &Runs) -> Vec<Moments> {
    let (w, h) = (runs.w, runs.h);
    // Each run's label; labels are made in raster order and a union keeps
    // the smaller root, so a component's root is its first run's label.
    let mut parent: Vec<u32> = Vec::new();
    let mut label = vec![0u32; runs.spans.len()];
    fn find(parent: &mut [u32], mut a: u32) -> u32 {
        while parent[a as usize] != a {
            parent[a as usize] = parent[parent[a as usize] as usize];
            a = parent[a as usize];
        }
        a
    }
    for y in 0..h {
        let here = runs.row_start[y]..runs.row_start[y + 1];
        let above = if y > 0 {
            runs.row_start[y - 1]..runs.row_start[y]
        } else {
            0..0
        };
        // Runs above that may overlap the current one (both rows sorted).
        let mut first_above = above.start;
        for i in here {
            let (b0, b1) = runs.spans[i];
            while first_above < above.end && runs.spans[first_above].1 <= b0 {
                first_above += 1;
            }
            let mut mine: Option<u32> = None;
            let mut j = first_above;
            while j < above.end && runs.spans[j].0 < b1 {
                let other = find(&mut parent, label[j]);
                mine = Some(match mine {
                    None => other,
                    Some(m) => {
                        let m = find(&mut parent, m);
                        let (lo, hi) = (m.min(other), m.max(other));
                        parent[hi as usize] = lo;
                        lo
                    }
                });
                j += 1;
            }
            label[i] = mine.unwrap_or_else(|| {
                let l = parent.len() as u32;
                parent.push(l);
                l
            });
        }
    }
    // Every label straight to its root: a parent is always a smaller
    // label, so in increasing order each parent is already resolved.
    for l in 0..parent.len() {
        parent[l] = parent[parent[l] as usize];
    }
    let mut moments = vec![Moments::default(); parent.len()];
    for y in 0..h {
        let border_row = y == 0 || y + 1 == h;
        for i in runs.row_start[y]..runs.row_start[y + 1] {
            let (x0, x1) = runs.spans[i];
            let border = border_row || x0 == 0 || x1 as usize == w;
            let m = Moments::of_run(x0 as u64, x1 as u64, y as u64, border);
            moments[parent[label[i] as usize] as usize].add(&m);
        }
    }
    // Roots only (a root is its own parent), in label order.
    moments
        .into_iter()
        .enumerate()
        .filter(|&(l, _)| parent[l] as usize == l)
        .map(|(_, m)| m)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// Per-pixel 4-connected labelling with flood fill, components in
    /// raster order of their first pixel: the reference for [`components`].
    fn reference(mask: &[bool], w: usize, h: usize) -> Vec<Moments> {
        let mut seen = vec![false; w * h];
        let mut out = Vec::new();
        for start in 0..w * h {
            if !mask[start] || seen[start] {
                continue;
            }
            let mut m = Moments::default();
            let mut stack = vec![start];
            seen[start] = true;
            while let Some(i) = stack.pop() {
                let (x, y) = ((i % w) as u64, (i / w) as u64);
                m.add(&Moments::of_run(
                    x,
                    x + 1,
                    y,
                    x == 0 || y == 0 || x as usize == w - 1 || y as usize == h - 1,
                ));
                let (xu, yu) = (x as usize, y as usize);
                let mut next = |j: usize| {
                    if mask[j] && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                };
                if xu > 0 {
                    next(i - 1);
                }
                if xu + 1 < w {
                    next(i + 1);
                }
                if yu > 0 {
                    next(i - w);
                }
                if yu + 1 < h {
                    next(i + w);
                }
            }
            out.push(m);
        }
        out
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn run_components_equal_per_pixel_labelling() {
        // A seeded random mask (dense enough for U shapes, merges from
        // several runs above and diagonal-only contacts, which 4-connectivity
        // keeps apart).
        let (w, h) = (53usize, 37usize);
        let mut rng = crate::rng::Rng::new(7);
        for density in [0.3, 0.5, 0.62] {
            let mask: Vec<bool> = (0..w * h).map(|_| rng.uniform() < density).collect();
            let bytes: Vec<u8> = mask.iter().map(|&m| m as u8).collect();
            let mut runs = Runs::new(w, h);
            for y in 0..h {
                runs.push_row(&bytes[y * w..(y + 1) * w]);
            }
            runs.finish();
            let got = components(&runs);
            let want = reference(&mask, w, h);
            assert_eq!(got.len(), want.len(), "density {density}");
            for (g, r) in got.iter().zip(&want) {
                assert_eq!(
                    (g.n, g.sx, g.sy, g.sxx, g.sxy, g.syy, g.border),
                    (r.n, r.sx, r.sy, r.sxx, r.sxy, r.syy, r.border),
                    "density {density}"
                );
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn integer_and_float_thresholds_agree() {
        // A vignetted image of discs, both prints: the 8-bit path and the
        // float path on the same grey levels give the same runs.
        let (w, h) = (160usize, 120usize);
        let px: Vec<u8> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                let (u, v) = ((x % 20.0) - 10.0, (y % 20.0) - 10.0);
                let shade = 200.0 - 0.004 * ((x - 80.0).powi(2) + (y - 60.0).powi(2));
                let disc = if u * u + v * v < 30.0 { 120.0 } else { 0.0 };
                (shade - disc + ((i * 37) % 11) as f64).clamp(0.0, 255.0) as u8
            })
            .collect();
        let img = GrayImage::new(w as u32, h as u32, px).unwrap();
        assert!(fits_u8(&img));
        let plane = Plane::from_gray(&img);
        for invert in [false, true] {
            let a = dark_runs_u8(&img, invert);
            let b = dark_runs_plane(&plane, invert);
            assert!(a.spans.len() > 20, "{} runs", a.spans.len());
            assert_eq!(a.spans, b.spans, "invert {invert}");
            assert_eq!(a.row_start, b.row_start);
        }
    }
}
