//! Dark pixels as horizontal runs, and their 4-connected regions.
//!
//! The candidate search never walks a per-pixel mask: the adaptive
//! threshold writes runs of dark pixels row by row, erosion intersects
//! runs of neighbouring rows, and regions are unions of overlapping runs
//! (union-find over runs, not a flood fill over pixels). A region's outline
//! for the convex hull is its runs' end points, already in row order, so no
//! sort is needed.

use crate::image::GrayImage;

/// Grey levels below the local mean for a dark pixel (OpenCV's
/// adaptiveThreshConstant is 7).
const THRESHOLD_OFFSET: u32 = 7;

/// Dark pixels `x0..x1` (end exclusive) of one row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Run {
    pub x0: u32,
    pub x1: u32,
}

/// The dark runs of an image, row after row, each row's runs left to right.
pub(super) struct Runs {
    pub width: usize,
    pub height: usize,
    runs: Vec<Run>,
    /// Row `y`'s runs are `runs[row_start[y]..row_start[y + 1]]`.
    row_start: Vec<usize>,
}

impl Runs {
    fn row(&self, y: usize) -> &[Run] {
        &self.runs[self.row_start[y]..self.row_start[y + 1]]
    }
}

/// Summed-area table: `s[y * (w + 1) + x]` is the sum of the pixels above
/// and left of (x, y), modulo 2^32. A window's sum (four entries, wrapping
/// arithmetic) is exact while the true sum stays under 2^32: windows of up
/// to 16.8 million pixels ([`MAX_WINDOW`]). Half the memory of 64-bit sums,
/// and 32-bit lanes for the vectorised threshold.
pub(super) fn integral_image(img: &GrayImage) -> Vec<u32> {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut s = vec![0u32; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut row = 0u32;
        let src = &img.pixels[y * w..(y + 1) * w];
        let (above, below) = s[y * (w + 1)..(y + 2) * (w + 1)].split_at_mut(w + 1);
        for ((&v, a), b) in src.iter().zip(&above[1..]).zip(&mut below[1..]) {
            row = row.wrapping_add(u32::from(v));
            *b = a.wrapping_add(row);
        }
    }
    s
}

/// Largest window side [`threshold`] takes (larger ones are cut to it): its
/// sums and `(v + 7) * area` stay under 2^32. The marker search's windows
/// are at most 91 pixels.
pub(super) const MAX_WINDOW: usize = 4001;

/// Runs of pixels more than [`THRESHOLD_OFFSET`] below the mean of the
/// `win` x `win` window around them (cut at the image edge). Each row is
/// first written as a byte mask (the middle, where the window is not cut
/// at the left or right edge, in one loop without branches that compilers
/// vectorise; its two ends pixel by pixel), then read as runs, eight bytes
/// at a time where the mask does not change.
pub(super) fn threshold(img: &GrayImage, s: &[u32], win: usize) -> Runs {
    let (w, h) = (img.width as usize, img.height as usize);
    let r = win.min(MAX_WINDOW) / 2;
    let mut runs = Vec::new();
    let mut row_start = Vec::with_capacity(h + 1);
    let mut mask = vec![0u8; w];
    // x in lo..hi: the window spans x - r ..= x + r inside the image.
    let (lo, hi) = (r.min(w), w.saturating_sub(r).max(r.min(w)));
    for y in 0..h {
        row_start.push(runs.len());
        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(h));
        let top = &s[y0 * (w + 1)..(y0 + 1) * (w + 1)];
        let bottom = &s[y1 * (w + 1)..(y1 + 1) * (w + 1)];
        let rows = (y1 - y0) as u32;
        let src = &img.pixels[y * w..(y + 1) * w];
        let dark = |x: usize| {
            let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(w));
            let sum = bottom[x1]
                .wrapping_sub(bottom[x0])
                .wrapping_sub(top[x1])
                .wrapping_add(top[x0]);
            let area = rows * (x1 - x0) as u32;
            u8::from((u32::from(src[x]) + THRESHOLD_OFFSET) * area < sum)
        };
        for x in (0..lo).chain(hi..w) {
            mask[x] = dark(x);
        }
        if hi > lo {
            let area = rows * (2 * r + 1) as u32;
            let n = hi - lo;
            let (t0, t1) = (&top[..n], &top[2 * r + 1..2 * r + 1 + n]);
            let (b0, b1) = (&bottom[..n], &bottom[2 * r + 1..2 * r + 1 + n]);
            let (v, m) = (&src[lo..hi], &mut mask[lo..hi]);
            for i in 0..n {
                let sum = b1[i]
                    .wrapping_sub(b0[i])
                    .wrapping_sub(t1[i])
                    .wrapping_add(t0[i]);
                m[i] = u8::from((u32::from(v[i]) + THRESHOLD_OFFSET) * area < sum);
            }
        }
        mask_runs(&mask, &mut runs);
    }
    row_start.push(runs.len());
    Runs {
        width: w,
        height: h,
        runs,
        row_start,
    }
}

/// The runs of ones in a 0 / 1 byte mask, appended to `out`; eight bytes
/// at a time while they all equal the current state.
fn mask_runs(mask: &[u8], out: &mut Vec<Run>) {
    const ONES: u64 = 0x0101_0101_0101_0101;
    let mut start: Option<usize> = None;
    let mut x = 0;
    while x < mask.len() {
        if x + 8 <= mask.len() {
            let word = u64::from_le_bytes(mask[x..x + 8].try_into().unwrap_or([2; 8]));
            if word == if start.is_some() { ONES } else { 0 } {
                x += 8;
                continue;
            }
        }
        match (mask[x] != 0, start) {
            (true, None) => start = Some(x),
            (false, Some(x0)) => {
                out.push(Run {
                    x0: x0 as u32,
                    x1: x as u32,
                });
                start = None;
            }
            _ => {}
        }
        x += 1;
    }
    if let Some(x0) = start {
        out.push(Run {
            x0: x0 as u32,
            x1: mask.len() as u32,
        });
    }
}

/// `a` ∩ `b` for two sorted lists of disjoint runs, appended to `out`.
fn intersect(a: &[Run], b: &[Run], out: &mut Vec<Run>) {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let x0 = a[i].x0.max(b[j].x0);
        let x1 = a[i].x1.min(b[j].x1);
        if x0 < x1 {
            out.push(Run { x0, x1 });
        }
        if a[i].x1 < b[j].x1 {
            i += 1;
        } else {
            j += 1;
        }
    }
}

/// Dark pixels whose four neighbours are dark too: breaks the one- or
/// two-pixel necks where dark regions meet at a corner under blur and tilt
/// (an AprilGrid tag and its corner squares), at the price of a pixel all
/// round. Pixels on the image border are never kept.
pub(super) fn erode(m: &Runs) -> Runs {
    let mut runs = Vec::new();
    let mut row_start = vec![0; m.height + 1];
    let (mut shrunk, mut above) = (Vec::new(), Vec::new());
    let inner = m.height.saturating_sub(2);
    for (y, start) in row_start.iter_mut().enumerate().skip(1).take(inner) {
        *start = runs.len();
        shrunk.clear();
        shrunk.extend(m.row(y).iter().filter_map(|r| {
            (r.x1 >= r.x0 + 3).then_some(Run {
                x0: r.x0 + 1,
                x1: r.x1 - 1,
            })
        }));
        above.clear();
        intersect(&shrunk, m.row(y - 1), &mut above);
        intersect(&above, m.row(y + 1), &mut runs);
    }
    let last = m.height.saturating_sub(1);
    for s in row_start.iter_mut().skip(last.max(1)) {
        *s = runs.len();
    }
    Runs {
        width: m.width,
        height: m.height,
        runs,
        row_start,
    }
}

/// One 4-connected region of dark runs that does not touch the image
/// border: its runs in row order, each with its row.
pub(super) struct Region {
    pub runs: Vec<(u32, Run)>,
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let p = parent[parent[i as usize] as usize];
        parent[i as usize] = p;
        i = p;
    }
    i
}

/// The regions of `m` that do not touch the image border, span at least
/// `min_extent` pixels in x and y and cover at most half the image.
pub(super) fn regions(m: &Runs, min_extent: u32) -> Vec<Region> {
    let n = m.runs.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for y in 1..m.height {
        let (a0, b0) = (m.row_start[y - 1], m.row_start[y]);
        let (a1, b1) = (b0, m.row_start[y + 1]);
        let (mut i, mut j) = (a0, a1);
        while i < b0 && j < b1 {
            let (ra, rb) = (m.runs[i], m.runs[j]);
            if ra.x0 < rb.x1 && rb.x0 < ra.x1 {
                let (pa, pb) = (find(&mut parent, i as u32), find(&mut parent, j as u32));
                if pa != pb {
                    // The older run stays the root: roots come first in scan order.
                    parent[pa.max(pb) as usize] = pa.min(pb);
                }
            }
            if ra.x1 < rb.x1 {
                i += 1;
            } else {
                j += 1;
            }
        }
    }
    // Extent, size and border contact per root.
    let (w, h) = (m.width as u32, m.height as u32);
    let mut stats: Vec<Stats> = Vec::new();
    let mut slot = vec![u32::MAX; n];
    let mut root_of = vec![0u32; n];
    let mut y = 0;
    for (i, root_slot) in root_of.iter_mut().enumerate() {
        while m.row_start[y + 1] <= i {
            y += 1;
        }
        let root = find(&mut parent, i as u32) as usize;
        *root_slot = root as u32;
        if slot[root] == u32::MAX {
            slot[root] = stats.len() as u32;
            stats.push(Stats::new());
        }
        let s = &mut stats[slot[root] as usize];
        let r = m.runs[i];
        s.add(r, y as u32);
        s.border |= r.x0 == 0 || r.x1 == w || y == 0 || y as u32 + 1 == h;
    }
    let max_pixels = m.width * m.height / 2;
    let keep: Vec<bool> = stats
        .iter()
        .map(|s| {
            !s.border
                && s.pixels <= max_pixels
                && s.xmax - s.xmin >= min_extent
                && s.ymax - s.ymin >= min_extent
        })
        .collect();
    let mut index = vec![u32::MAX; stats.len()];
    let mut out: Vec<Region> = Vec::new();
    let mut y = 0;
    for i in 0..n {
        while m.row_start[y + 1] <= i {
            y += 1;
        }
        let k = slot[root_of[i] as usize] as usize;
        if !keep[k] {
            continue;
        }
        if index[k] == u32::MAX {
            index[k] = out.len() as u32;
            out.push(Region { runs: Vec::new() });
        }
        out[index[k] as usize].runs.push((y as u32, m.runs[i]));
    }
    out
}

struct Stats {
    pixels: usize,
    xmin: u32,
    xmax: u32,
    ymin: u32,
    ymax: u32,
    border: bool,
}

impl Stats {
    fn new() -> Self {
        Stats {
            pixels: 0,
            xmin: u32::MAX,
            xmax: 0,
            ymin: u32::MAX,
            ymax: 0,
            border: false,
        }
    }

    fn add(&mut self, r: Run, y: u32) {
        self.pixels += (r.x1 - r.x0) as usize;
        self.xmin = self.xmin.min(r.x0);
        self.xmax = self.xmax.max(r.x1 - 1);
        self.ymin = self.ymin.min(y);
        self.ymax = self.ymax.max(y);
    }
}

/// Half-size image: each pixel the rounded mean of a 2 x 2 block (the last
/// odd row or column dropped). Pixel (i, j) of it is centred on (2i + 0.5,
/// 2j + 0.5) of `img`.
pub(super) fn decimate(img: &GrayImage) -> GrayImage {
    let (w, h) = (img.width as usize, img.height as usize);
    let (hw, hh) = (w / 2, h / 2);
    let mut pixels = Vec::with_capacity(hw * hh);
    for j in 0..hh {
        let r0 = &img.pixels[2 * j * w..2 * j * w + 2 * hw];
        let r1 = &img.pixels[(2 * j + 1) * w..(2 * j + 1) * w + 2 * hw];
        for (a, b) in r0.chunks_exact(2).zip(r1.chunks_exact(2)) {
            let s = u16::from(a[0]) + u16::from(a[1]) + u16::from(b[0]) + u16::from(b[1]);
            pixels.push(((s + 2) / 4) as u8);
        }
    }
    GrayImage {
        width: hw as u32,
        height: hh as u32,
        pixels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn image(rows: &[&str]) -> GrayImage {
        let h = rows.len();
        let w = rows[0].len();
        let pixels = rows
            .iter()
            .flat_map(|r| r.bytes().map(|b| if b == b'#' { 0 } else { 200 }))
            .collect();
        GrayImage {
            width: w as u32,
            height: h as u32,
            pixels,
        }
    }

    fn runs_of(rows: &[&str]) -> Runs {
        // Dark = '#', from a mask directly (window covering the image).
        let img = image(rows);
        let s = integral_image(&img);
        threshold(&img, &s, 2 * img.width.max(img.height) as usize + 1)
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn threshold_runs_are_the_dark_pixels_row_by_row() {
        let m = runs_of(&["........", ".##..##.", ".#######", "........"]);
        assert_eq!(m.row(0), &[]);
        assert_eq!(m.row(1), &[Run { x0: 1, x1: 3 }, Run { x0: 5, x1: 7 }]);
        assert_eq!(m.row(2), &[Run { x0: 1, x1: 8 }]);
        assert_eq!(m.row(3), &[]);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn threshold_equals_the_window_means_pixel_by_pixel() {
        // A seeded noisy image with dark blobs: every window size the search
        // uses (and one wider than the image) against the mean of each
        // window summed directly, so the vectorised middle, the cut ends
        // and the 32-bit sums give exactly the dark pixels.
        let (w, h) = (97usize, 61usize);
        let mut state = 12345u32;
        let pixels: Vec<u8> = (0..w * h)
            .map(|i| {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let (x, y) = (i % w, i / w);
                let blob = (x / 13 + y / 11) % 3 == 0;
                let noise = (state >> 24) as u8 / 4;
                if blob {
                    40 + noise
                } else {
                    150 + noise
                }
            })
            .collect();
        let img = GrayImage {
            width: w as u32,
            height: h as u32,
            pixels,
        };
        let s = integral_image(&img);
        for win in [1, 7, 21, 31, 91, 301] {
            let m = threshold(&img, &s, win);
            let r = win / 2;
            for y in 0..h {
                let mut expected = Vec::new();
                let mut start = None;
                for x in 0..=w {
                    let dark = x < w && {
                        let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(w));
                        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(h));
                        let sum: u64 = (y0..y1)
                            .flat_map(|yy| (x0..x1).map(move |xx| (xx, yy)))
                            .map(|(xx, yy)| u64::from(img.pixels[yy * w + xx]))
                            .sum();
                        let area = ((x1 - x0) * (y1 - y0)) as u64;
                        (u64::from(img.pixels[y * w + x]) + 7) * area < sum
                    };
                    match (dark, start) {
                        (true, None) => start = Some(x),
                        (false, Some(x0)) => {
                            expected.push(Run {
                                x0: x0 as u32,
                                x1: x as u32,
                            });
                            start = None;
                        }
                        _ => {}
                    }
                }
                assert_eq!(m.row(y), &expected[..], "window {win}, row {y}");
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn regions_are_4_connected_and_skip_the_border() {
        // Two blocks touching at a corner only, and one touching the right edge.
        let m = runs_of(&[
            "..........",
            ".##.......",
            ".##.......",
            "...##...##",
            "...##...##",
            "..........",
        ]);
        let r = regions(&m, 0);
        assert_eq!(
            r.len(),
            2,
            "corner contact does not connect; border region dropped"
        );
        assert_eq!(
            r[0].runs,
            vec![(1, Run { x0: 1, x1: 3 }), (2, Run { x0: 1, x1: 3 })]
        );
        assert_eq!(
            r[1].runs,
            vec![(3, Run { x0: 3, x1: 5 }), (4, Run { x0: 3, x1: 5 })]
        );
        // A U shape joins through its bottom row: one region.
        let u = runs_of(&["......", ".#..#.", ".#..#.", ".####.", "......"]);
        let r = regions(&u, 0);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].runs.len(), 5);
        assert_eq!(regions(&u, 3).len(), 0, "extent 3 x 2 is below 3 in y");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn erosion_keeps_pixels_whose_four_neighbours_are_dark() {
        let m = runs_of(&[".....", ".###.", ".####", ".###.", "....."]);
        let e = erode(&m);
        assert_eq!(e.row(1), &[]);
        assert_eq!(e.row(2), &[Run { x0: 2, x1: 4 }]);
        assert_eq!(e.row(3), &[]);
        assert_eq!(e.row(4), &[]);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn decimation_averages_2x2_blocks() {
        let img = GrayImage {
            width: 5,
            height: 3,
            pixels: vec![0, 4, 8, 8, 99, 2, 2, 9, 9, 99, 99, 99, 99, 99, 99],
        };
        let d = decimate(&img);
        assert_eq!((d.width, d.height), (2, 1));
        assert_eq!(d.pixels, vec![2, 9]);
    }
}
