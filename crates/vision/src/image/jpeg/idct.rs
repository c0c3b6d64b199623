//! The 8x8 inverse DCT and the colour conversions of JPEG decoding.
//!
//! The IDCT is the accurate integer one of the Independent JPEG Group's
//! libjpeg (`jidctint`, Loeffler-Ligtenberg-Moschytz with 13-bit constants,
//! two passes, 2 extra bits between them): the same pixels as libjpeg's and
//! libjpeg-turbo's default decoders, and so as OpenCV's `imread`.

use std::num::Wrapping;

const CONST_BITS: u32 = 13;
const PASS1_BITS: u32 = 2;

const FIX_0_298631336: i32 = 2446;
const FIX_0_390180644: i32 = 3196;
const FIX_0_541196100: i32 = 4433;
const FIX_0_765366865: i32 = 6270;
const FIX_0_899976223: i32 = 7373;
const FIX_1_175875602: i32 = 9633;
const FIX_1_501321110: i32 = 12299;
const FIX_1_847759065: i32 = 15137;
const FIX_1_961570560: i32 = 16069;
const FIX_2_053119869: i32 = 16819;
const FIX_2_562915447: i32 = 20995;
const FIX_3_072711026: i32 = 25172;

/// One 1-D 8-point IDCT of `x` (inputs in natural order), before the final
/// descaling: outputs 0..8 scaled by 2^CONST_BITS. Wrapping arithmetic:
/// valid data never comes near overflow, damaged data must not panic.
#[inline(always)]
fn butterfly(x: [i32; 8]) -> [i32; 8] {
    let x = x.map(Wrapping);
    let k = |c: i32| Wrapping(c);
    // Even part.
    let z1 = (x[2] + x[6]) * k(FIX_0_541196100);
    let tmp2 = z1 - x[6] * k(FIX_1_847759065);
    let tmp3 = z1 + x[2] * k(FIX_0_765366865);
    let tmp0 = (x[0] + x[4]) << CONST_BITS as usize;
    let tmp1 = (x[0] - x[4]) << CONST_BITS as usize;
    let (tmp10, tmp13) = (tmp0 + tmp3, tmp0 - tmp3);
    let (tmp11, tmp12) = (tmp1 + tmp2, tmp1 - tmp2);
    // Odd part.
    let (t0, t1, t2, t3) = (x[7], x[5], x[3], x[1]);
    let z1 = t0 + t3;
    let z2 = t1 + t2;
    let z3 = t0 + t2;
    let z4 = t1 + t3;
    let z5 = (z3 + z4) * k(FIX_1_175875602);
    let z1 = z1 * k(-FIX_0_899976223);
    let z2 = z2 * k(-FIX_2_562915447);
    let z3 = z3 * k(-FIX_1_961570560) + z5;
    let z4 = z4 * k(-FIX_0_390180644) + z5;
    let t0 = t0 * k(FIX_0_298631336) + z1 + z3;
    let t1 = t1 * k(FIX_2_053119869) + z2 + z4;
    let t2 = t2 * k(FIX_3_072711026) + z2 + z3;
    let t3 = t3 * k(FIX_1_501321110) + z1 + z4;
    [
        tmp10 + t3,
        tmp11 + t2,
        tmp12 + t1,
        tmp13 + t0,
        tmp13 - t0,
        tmp12 - t1,
        tmp11 - t2,
        tmp10 - t3,
    ]
    .map(|v| v.0)
}

#[inline(always)]
fn descale(x: i32, n: u32) -> i32 {
    x.wrapping_add(1 << (n - 1)) >> n
}

/// Inverse DCT of the dequantised coefficients `c` (natural order) into
/// the 8x8 pixels at `out[0]`, rows `stride` apart (level-shifted, clamped).
pub(super) fn idct_block(c: &[i32; 64], out: &mut [u8], stride: usize) {
    // Only a DC term (most blocks of smooth images): a flat block.
    if c[1..].iter().all(|&v| v == 0) {
        let v = clamp(descale(c[0], 3).wrapping_add(128));
        for row in out.chunks_mut(stride).take(8) {
            row[..8].fill(v);
        }
        return;
    }
    let mut ws = [0i32; 64];
    for col in 0..8 {
        let x: [i32; 8] = std::array::from_fn(|r| c[r * 8 + col]);
        if x[1..].iter().all(|&v| v == 0) {
            let dc = x[0].wrapping_shl(PASS1_BITS);
            for r in 0..8 {
                ws[r * 8 + col] = dc;
            }
            continue;
        }
        let y = butterfly(x);
        for r in 0..8 {
            ws[r * 8 + col] = descale(y[r], CONST_BITS - PASS1_BITS);
        }
    }
    for (r, row) in out.chunks_mut(stride).take(8).enumerate() {
        let x: [i32; 8] = std::array::from_fn(|i| ws[r * 8 + i]);
        let row = &mut row[..8];
        if x[1..].iter().all(|&v| v == 0) {
            row.fill(clamp(descale(x[0], PASS1_BITS + 3).wrapping_add(128)));
            continue;
        }
        let y = butterfly(x);
        for (o, v) in row.iter_mut().zip(y) {
            *o = clamp(descale(v, CONST_BITS + PASS1_BITS + 3).wrapping_add(128));
        }
    }
}

#[inline(always)]
fn clamp(v: i32) -> u8 {
    v.clamp(0, 255) as u8
}

/// JFIF YCbCr to RGB (ITU-R BT.601 full range), 16-bit fixed point.
#[inline(always)]
pub(super) fn ycbcr_to_rgb(y: u8, cb: u8, cr: u8) -> [u8; 3] {
    let y = (y as i32) << 16;
    let cb = cb as i32 - 128;
    let cr = cr as i32 - 128;
    const HALF: i32 = 1 << 15;
    [
        clamp((y + 91881 * cr + HALF) >> 16),
        clamp((y - 22554 * cb - 46802 * cr + HALF) >> 16),
        clamp((y + 116130 * cb + HALF) >> 16),
    ]
}

/// Adobe's inverted CMYK (255 = no ink, as Photoshop writes it) to RGB.
#[inline(always)]
pub(super) fn cmyk_to_rgb(c: u8, m: u8, y: u8, k: u8) -> [u8; 3] {
    let k = k as u32;
    let f = |v: u8| ((v as u32 * k + 127) / 255) as u8;
    [f(c), f(m), f(y)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook IDCT in floating point.
    fn reference(c: &[i32; 64]) -> [f64; 64] {
        let mut out = [0.0; 64];
        for y in 0..8 {
            for x in 0..8 {
                let mut s = 0.0;
                for v in 0..8 {
                    for u in 0..8 {
                        let cu = if u == 0 { 0.5f64.sqrt() } else { 1.0 };
                        let cv = if v == 0 { 0.5f64.sqrt() } else { 1.0 };
                        let a = ((2 * x + 1) as f64 * u as f64 * std::f64::consts::PI / 16.0).cos();
                        let b = ((2 * y + 1) as f64 * v as f64 * std::f64::consts::PI / 16.0).cos();
                        s += cu * cv * c[v * 8 + u] as f64 * a * b;
                    }
                }
                out[y * 8 + x] = s / 4.0 + 128.0;
            }
        }
        out
    }

    #[test]
    fn idct_is_within_one_level_of_the_exact_transform() {
        let mut state = 7u32;
        let mut next = || {
            state = state.wrapping_mul(1664525).wrapping_add(1013904223);
            state >> 8
        };
        for trial in 0..300 {
            let mut c = [0i32; 64];
            // Few non-zero coefficients (like real blocks), then dense ones.
            let n = if trial < 200 {
                1 + next() as usize % 6
            } else {
                64
            };
            for _ in 0..n {
                let k = next() as usize % 64;
                c[k] = (next() % 301) as i32 - 150;
            }
            let mut out = [0u8; 64];
            idct_block(&c, &mut out, 8);
            let exact = reference(&c);
            for (i, (&o, e)) in out.iter().zip(exact).enumerate() {
                let e = e.round().clamp(0.0, 255.0);
                assert!(
                    (o as f64 - e).abs() <= 1.0,
                    "trial {trial}, pixel {i}: {o} vs {e}"
                );
            }
        }
    }

    #[test]
    fn colour_conversions_match_the_formulas() {
        for (y, cb, cr) in [
            (0u8, 128u8, 128u8),
            (255, 128, 128),
            (76, 85, 255),
            (150, 44, 21),
            (29, 255, 107),
        ] {
            let (yf, cbf, crf) = (y as f64, cb as f64 - 128.0, cr as f64 - 128.0);
            let want = [
                yf + 1.402 * crf,
                yf - 0.344136 * cbf - 0.714136 * crf,
                yf + 1.772 * cbf,
            ];
            let got = ycbcr_to_rgb(y, cb, cr);
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (*g as f64 - w.round().clamp(0.0, 255.0)).abs() <= 1.0,
                    "{y} {cb} {cr}: {got:?} vs {want:?}"
                );
            }
        }
        assert_eq!(cmyk_to_rgb(255, 255, 255, 255), [255, 255, 255]);
        assert_eq!(cmyk_to_rgb(0, 128, 255, 255), [0, 128, 255]);
        assert_eq!(cmyk_to_rgb(255, 255, 255, 0), [0, 0, 0]);
    }
}
