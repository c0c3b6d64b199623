//! Float image planes, separable Gaussian smoothing, 2x pyramid reduction and
//! bilinear sampling: the low-level pixel work shared by the detectors and
//! the renderer.

use super::GrayImage;

/// A single-channel f32 image, row-major.
#[derive(Debug, Clone)]
pub(crate) struct Plane {
    pub w: usize,
    pub h: usize,
    pub data: Vec<f32>,
}

impl Plane {
    pub fn from_gray(img: &GrayImage) -> Plane {
        Plane {
            w: img.width as usize,
            h: img.height as usize,
            data: img.pixels.iter().map(|&v| v as f32).collect(),
        }
    }

    /// Value at integer (x, y) with coordinates clamped into the image.
    #[inline]
    pub fn at(&self, x: isize, y: isize) -> f32 {
        let xc = x.clamp(0, self.w as isize - 1) as usize;
        let yc = y.clamp(0, self.h as isize - 1) as usize;
        self.data[yc * self.w + xc]
    }

    /// Bilinear interpolation at (x, y), clamped at the border.
    pub fn bilinear(&self, x: f64, y: f64) -> f32 {
        let x0 = x.floor();
        let y0 = y.floor();
        let fx = (x - x0) as f32;
        let fy = (y - y0) as f32;
        let (xi, yi) = (x0 as isize, y0 as isize);
        // Inside the image the four pixels are two pairs of neighbours,
        // read without the clamps (the same values; the clamped reads were
        // a call per pixel in the wasm build).
        let (a, b, c, d) =
            if xi >= 0 && yi >= 0 && xi + 1 < self.w as isize && yi + 1 < self.h as isize {
                let i = yi as usize * self.w + xi as usize;
                let (top, bottom) = (&self.data[i..i + 2], &self.data[i + self.w..i + self.w + 2]);
                (top[0], top[1], bottom[0], bottom[1])
            } else {
                (
                    self.at(xi, yi),
                    self.at(xi + 1, yi),
                    self.at(xi, yi + 1),
                    self.at(xi + 1, yi + 1),
                )
            };
        (a * (1.0 - fx) + b * fx) * (1.0 - fy) + (c * (1.0 - fx) + d * fx) * fy
    }

    /// Half-size image, each pixel the mean of a 2x2 block. Pixel x of the
    /// result covers x' = 2x + 0.5 of the input.
    pub fn downsample2(&self) -> Plane {
        let w = (self.w / 2).max(1);
        let h = (self.h / 2).max(1);
        let mut data = vec![0.0f32; w * h];
        for y in 0..h {
            let r0 = (2 * y).min(self.h - 1) * self.w;
            let r1 = (2 * y + 1).min(self.h - 1) * self.w;
            for x in 0..w {
                let x0 = (2 * x).min(self.w - 1);
                let x1 = (2 * x + 1).min(self.w - 1);
                data[y * w + x] = 0.25
                    * (self.data[r0 + x0]
                        + self.data[r0 + x1]
                        + self.data[r1 + x0]
                        + self.data[r1 + x1]);
            }
        }
        Plane { w, h, data }
    }

    /// Separable Gaussian smoothing with standard deviation `sigma` pixels
    /// (kernel radius 3 sigma, borders clamped). Row by row: the vertical
    /// pass fills one padded row buffer, the horizontal pass reads it, so
    /// no full-size intermediate is allocated. Both passes run tap by tap
    /// over whole rows (vectorisable), pairing the symmetric taps.
    pub fn gaussian(&self, sigma: f64) -> Plane {
        let k = gaussian_kernel(sigma);
        let r = k.len() / 2;
        let (w, h) = (self.w, self.h);
        let mut data = vec![0.0f32; w * h];
        let mut padded = vec![0.0f32; w + 2 * r];
        let row = |yy: isize| {
            let yy = yy.clamp(0, h as isize - 1) as usize;
            &self.data[yy * w..(yy + 1) * w]
        };
        for y in 0..h {
            let mid = &mut padded[r..r + w];
            for (o, s) in mid.iter_mut().zip(row(y as isize)) {
                *o = k[r] * s;
            }
            for d in 1..=r {
                let (up, down) = (row(y as isize - d as isize), row((y + d) as isize));
                let kv = k[r + d];
                for ((o, a), b) in mid.iter_mut().zip(up).zip(down) {
                    *o += kv * (a + b);
                }
            }
            let (first, last) = (padded[r], padded[r + w - 1]);
            padded[..r].iter_mut().for_each(|v| *v = first);
            padded[r + w..].iter_mut().for_each(|v| *v = last);
            let out = &mut data[y * w..(y + 1) * w];
            for (o, s) in out.iter_mut().zip(&padded[r..r + w]) {
                *o = k[r] * s;
            }
            for d in 1..=r {
                let kv = k[r + d];
                let (left, right) = (&padded[r - d..r - d + w], &padded[r + d..r + d + w]);
                for ((o, a), b) in out.iter_mut().zip(left).zip(right) {
                    *o += kv * (a + b);
                }
            }
        }
        Plane { w, h, data }
    }
}

/// Pyramid level `level` (each pixel the mean of a `2^level` square block,
/// borders clamped) straight from 8-bit pixels: rows are summed in integers,
/// so the result equals repeated [`Plane::downsample2`] up to rounding.
pub(crate) fn box_level(img: &GrayImage, level: u32) -> Plane {
    let (iw, ih) = (img.width as usize, img.height as usize);
    if level == 0 {
        return Plane::from_gray(img);
    }
    let level = level.min(8);
    let f = 1usize << level;
    let w = (iw >> level).max(1);
    let h = (ih >> level).max(1);
    let scale = 1.0 / (f * f) as f32;
    let mut data = vec![0.0f32; w * h];
    // Row sums of at most 256 rows of 8-bit pixels fit in u16; block sums
    // (up to 256 x 256 pixels) need u32.
    let mut sums = vec![0u16; iw];
    let whole = (iw / f).min(w);
    let (mut a, mut b) = (vec![0u32; whole * f], vec![0u32; whole * f]);
    for y in 0..h {
        sums.iter_mut().for_each(|v| *v = 0);
        for k in 0..f {
            let yy = (y * f + k).min(ih - 1);
            for (s, &p) in sums.iter_mut().zip(&img.pixels[yy * iw..(yy + 1) * iw]) {
                *s += p as u16;
            }
        }
        let out = &mut data[y * w..(y + 1) * w];
        // Whole blocks by pairwise halving (vectorisable), then a clamped
        // last block (odd widths).
        for (d, &s) in a.iter_mut().zip(&sums) {
            *d = s as u32;
        }
        let mut n = whole * f;
        for _ in 0..level {
            n /= 2;
            for (d, pair) in b[..n].iter_mut().zip(a.chunks_exact(2)) {
                *d = pair[0] + pair[1];
            }
            std::mem::swap(&mut a, &mut b);
        }
        // Block sums are below 2^24 (256 x 256 x 255): `as i32` is exact,
        // and the signed conversion is one instruction in wasm SIMD (the
        // unsigned one is emulated).
        for (o, &v) in out.iter_mut().zip(&a[..whole]) {
            *o = v as i32 as f32 * scale;
        }
        for (x, o) in out.iter_mut().enumerate().skip(whole) {
            let mut acc = 0u32;
            for k in 0..f {
                acc += sums[(x * f + k).min(iw - 1)] as u32;
            }
            *o = acc as f32 * scale;
        }
    }
    Plane { w, h, data }
}

/// The larger of two numbers that are never NaN (pixel values, responses,
/// coordinates): one compare and select. `f32::max` is the same for such
/// operands, but it must return the other operand for a NaN, which wasm's
/// `f32.max` does not do, so in the wasm build it is a call to `fmaxf` in
/// every iteration and the loop around it cannot vectorise (issue 38: a
/// tenth of the wasm chessboard detection). Natively both are `maxss`.
#[inline(always)]
pub(crate) fn max_f32(a: f32, b: f32) -> f32 {
    if b > a {
        b
    } else {
        a
    }
}

/// The smaller of two numbers that are never NaN (see [`max_f32`]).
#[inline(always)]
pub(crate) fn min_f32(a: f32, b: f32) -> f32 {
    if b < a {
        b
    } else {
        a
    }
}

/// [`min_f32`] for f64 (`f64::min` is a call to `fmin` in wasm).
#[inline(always)]
pub(crate) fn min_f64(a: f64, b: f64) -> f64 {
    if b < a {
        b
    } else {
        a
    }
}

/// The half-width of [`gaussian_kernel`]'s taps for `sigma`.
pub(crate) fn gaussian_radius(sigma: f64) -> usize {
    (3.0 * sigma.max(0.3)).ceil().max(1.0) as usize
}

/// Normalised Gaussian taps, radius ceil(3 sigma) (at least 1).
pub(crate) fn gaussian_kernel(sigma: f64) -> Vec<f32> {
    let sigma = sigma.max(0.3);
    let r = gaussian_radius(sigma) as isize;
    let mut k: Vec<f32> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp() as f32)
        .collect();
    let s: f32 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= s);
    k
}

/// Map a coordinate at pyramid level `level` to level 0 (full resolution).
#[inline]
pub(crate) fn to_full(v: f64, level: u32) -> f64 {
    let s = (1u64 << level) as f64;
    s * (v + 0.5) - 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn the_select_helpers_agree_with_the_library_max_and_min() {
        let values = [
            -3.5f32,
            -1.0,
            -f32::MIN_POSITIVE,
            0.0,
            1e-30,
            0.25,
            1.0,
            255.0,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for &a in &values {
            for &b in &values {
                assert_eq!(max_f32(a, b).to_bits(), a.max(b).to_bits(), "{a} {b}");
                assert_eq!(min_f32(a, b).to_bits(), a.min(b).to_bits(), "{a} {b}");
                let (a, b) = (a as f64, b as f64);
                assert_eq!(min_f64(a, b).to_bits(), a.min(b).to_bits(), "{a} {b}");
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn smoothing_keeps_constants_and_pyramid_maps_centres() {
        let p = Plane {
            w: 7,
            h: 5,
            data: vec![3.0; 35],
        };
        let g = p.gaussian(1.5);
        assert!(g.data.iter().all(|v| (v - 3.0).abs() < 1e-5));
        // A ramp v = x: the 2x2 mean of columns 2 and 3 is 2.5 = to_full(1, 1).
        let ramp = Plane {
            w: 8,
            h: 4,
            data: (0..32).map(|i| (i % 8) as f32).collect(),
        };
        let d = ramp.downsample2();
        assert_eq!((d.w, d.h), (4, 2));
        assert!((d.data[1] as f64 - to_full(1.0, 1)).abs() < 1e-6);
    }
}
