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
const THRESHOLD_OFFSET: i64 = 7;

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
/// and left of (x, y).
pub(super) fn integral_image(img: &GrayImage) -> Vec<u64> {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut s = vec![0u64; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut row = 0u64;
        let src = &img.pixels[y * w..(y + 1) * w];
        for (x, &v) in src.iter().enumerate() {
            row += u64::from(v);
            s[(y + 1) * (w + 1) + x + 1] = s[y * (w + 1) + x + 1] + row;
        }
    }
    s
}

/// Runs of pixels more than [`THRESHOLD_OFFSET`] below the mean of the
/// `win` x `win` window around them (cut at the image edge).
pub(super) fn threshold(img: &GrayImage, s: &[u64], win: usize) -> Runs {
    let (w, h) = (img.width as usize, img.height as usize);
    let r = win / 2;
    let mut runs = Vec::new();
    let mut row_start = Vec::with_capacity(h + 1);
    for y in 0..h {
        row_start.push(runs.len());
        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(h));
        let top = &s[y0 * (w + 1)..(y0 + 1) * (w + 1)];
        let bottom = &s[y1 * (w + 1)..(y1 + 1) * (w + 1)];
        let rows = (y1 - y0) as i64;
        let src = &img.pixels[y * w..(y + 1) * w];
        let mut start: Option<usize> = None;
        for (x, &v) in src.iter().enumerate() {
            let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(w));
            let sum = (bottom[x1] + top[x0] - top[x1] - bottom[x0]) as i64;
            let area = rows * (x1 - x0) as i64;
            let dark = (i64::from(v) + THRESHOLD_OFFSET) * area < sum;
            match (dark, start) {
                (true, None) => start = Some(x),
                (false, Some(x0)) => {
                    runs.push(Run {
                        x0: x0 as u32,
                        x1: x as u32,
                    });
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(x0) = start {
            runs.push(Run {
                x0: x0 as u32,
                x1: w as u32,
            });
        }
    }
    row_start.push(runs.len());
    Runs {
        width: w,
        height: h,
        runs,
        row_start,
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

    #[test]
    fn threshold_runs_are_the_dark_pixels_row_by_row() {
        let m = runs_of(&["........", ".##..##.", ".#######", "........"]);
        assert_eq!(m.row(0), &[]);
        assert_eq!(m.row(1), &[Run { x0: 1, x1: 3 }, Run { x0: 5, x1: 7 }]);
        assert_eq!(m.row(2), &[Run { x0: 1, x1: 8 }]);
        assert_eq!(m.row(3), &[]);
    }

    #[test]
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

    #[test]
    fn erosion_keeps_pixels_whose_four_neighbours_are_dark() {
        let m = runs_of(&[".....", ".###.", ".####", ".###.", "....."]);
        let e = erode(&m);
        assert_eq!(e.row(1), &[]);
        assert_eq!(e.row(2), &[Run { x0: 2, x1: 4 }]);
        assert_eq!(e.row(3), &[]);
        assert_eq!(e.row(4), &[]);
    }

    #[test]
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
