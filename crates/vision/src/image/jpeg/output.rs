//! Component planes to the interleaved output image.

use super::{idct, Component, Frame, JpegImage};

/// Planes to interleaved output: grey as is, three components through
/// YCbCr (or as RGB: Adobe transform 0 or component ids R, G, B), four
/// through Adobe CMYK or YCCK; chroma replicated to full size.
pub(super) fn output(frame: &Frame, adobe: Option<u8>) -> JpegImage {
    let (w, h) = (frame.width, frame.height);
    let comps = &frame.components;
    let channels = if comps.len() == 1 { 1 } else { 3 };
    let mut pixels = vec![0u8; w * h * channels];
    if comps.len() == 1 {
        let stride = comps[0].padded_w * 8;
        for (y, row) in pixels.chunks_exact_mut(w).enumerate() {
            row.copy_from_slice(&comps[0].plane[y * stride..y * stride + w]);
        }
        return JpegImage {
            width: w as u32,
            height: h as u32,
            channels: 1,
            pixels,
        };
    }
    let ids: Vec<u8> = comps.iter().map(|c| c.id).collect();
    let transform = adobe.unwrap_or(if ids == b"RGB" {
        0
    } else if comps.len() == 4 {
        2
    } else {
        1
    });
    // Per component: the plane row and column of each output pixel.
    let columns: Vec<Vec<usize>> = comps
        .iter()
        .map(|c| (0..w).map(|x| x * c.h / frame.h_max).collect())
        .collect();
    let v_max = frame.v_max;
    fn plane_row(c: &Component, y: usize, v_max: usize) -> &[u8] {
        let stride = c.padded_w * 8;
        let r = y * c.v / v_max;
        &c.plane[r * stride..(r + 1) * stride]
    }
    if comps.len() == 3 && transform != 0 {
        // The common case (YCbCr): chroma rows widened to full width, then
        // one pass over three equal slices.
        let mut cb_row = vec![0u8; w];
        let mut cr_row = vec![0u8; w];
        for (y, row) in pixels.chunks_exact_mut(w * 3).enumerate() {
            let luma = &plane_row(&comps[0], y, v_max)[..w];
            widen(plane_row(&comps[1], y, v_max), &columns[1], &mut cb_row);
            widen(plane_row(&comps[2], y, v_max), &columns[2], &mut cr_row);
            for (((px, &l), &cb), &cr) in
                row.chunks_exact_mut(3).zip(luma).zip(&cb_row).zip(&cr_row)
            {
                px.copy_from_slice(&idct::ycbcr_to_rgb(l, cb, cr));
            }
        }
        return JpegImage {
            width: w as u32,
            height: h as u32,
            channels: 3,
            pixels,
        };
    }
    let mut sample = [0u8; 4];
    for (y, row) in pixels.chunks_exact_mut(w * 3).enumerate() {
        let rows: Vec<&[u8]> = comps.iter().map(|c| plane_row(c, y, v_max)).collect();
        for (x, px) in row.chunks_exact_mut(3).enumerate() {
            for (i, r) in rows.iter().enumerate() {
                sample[i] = r[columns[i][x]];
            }
            let rgb = match (comps.len(), transform) {
                (3, 0) => [sample[0], sample[1], sample[2]],
                (3, _) => idct::ycbcr_to_rgb(sample[0], sample[1], sample[2]),
                (_, 0) => idct::cmyk_to_rgb(sample[0], sample[1], sample[2], sample[3]),
                _ => {
                    // YCCK: the colour transform of the (inverted) CMY.
                    let [r, g, b] = idct::ycbcr_to_rgb(sample[0], sample[1], sample[2]);
                    idct::cmyk_to_rgb(255 - r, 255 - g, 255 - b, sample[3])
                }
            };
            px.copy_from_slice(&rgb);
        }
    }
    JpegImage {
        width: w as u32,
        height: h as u32,
        channels: 3,
        pixels,
    }
}

/// A plane row at full width: `out[x] = row[columns[x]]`, with the usual
/// 1x and 2x replications as plain loops.
fn widen(row: &[u8], columns: &[usize], out: &mut [u8]) {
    let w = out.len();
    if columns.get(1) == Some(&1) || w == 1 {
        out.copy_from_slice(&row[..w]);
    } else if columns.get(2) == Some(&1) && columns.get(1) == Some(&0) {
        for (pair, &v) in out.chunks_exact_mut(2).zip(row) {
            pair[0] = v;
            pair[1] = v;
        }
        if w % 2 == 1 {
            out[w - 1] = row[(w - 1) / 2];
        }
    } else {
        for (o, &c) in out.iter_mut().zip(columns) {
            *o = row[c];
        }
    }
}
