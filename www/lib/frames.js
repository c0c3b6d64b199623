// Video frames as the core reads them: RGBA pixels to grey (the weights the
// core's decoder uses for colour images, so a live frame and the same frame
// captured as PNG give the same grey) or a VideoFrame's luma plane, wrapped
// as a binary PGM (P5) that the core's decoder takes like any other image
// file.

/** Rec. 709 luma weights in ten-thousandths, as the `image` crate's RGB-to-luma. */
const LUMA = [2126, 7152, 722];

/**
 * RGBA bytes (`width`*`height`*4) to grey bytes: the weighted sum divided
 * by 10000 and truncated, as `image`'s integer conversion does (a
 * Uint8Array store truncates the quotient).
 */
export function greyFromRgba(rgba, width, height) {
  const n = width * height;
  const grey = new Uint8Array(n);
  for (let i = 0, j = 0; i < n; i++, j += 4) {
    grey[i] = (LUMA[0] * rgba[j] + LUMA[1] * rgba[j + 1] + LUMA[2] * rgba[j + 2]) / 10000;
  }
  return grey;
}

/** Grey bytes as a binary PGM file (P5, maxval 255). */
export function pgm(grey, width, height) {
  const head = new TextEncoder().encode(`P5\n${width} ${height}\n255\n`);
  const out = new Uint8Array(head.length + grey.length);
  out.set(head, 0);
  out.set(grey, head.length);
  return out;
}

/** VideoFrame formats whose first plane is luma (Y). */
const PLANAR_YUV = new Set(['I420', 'I420A', 'I422', 'I444', 'NV12']);
/** Where R, G and B sit in a pixel of the packed formats. */
const PACKED = { RGBA: [0, 1, 2], RGBX: [0, 1, 2], BGRA: [2, 1, 0], BGRX: [2, 1, 0] };

/**
 * The grey pixels of a WebCodecs VideoFrame (closed afterwards): the luma
 * plane as it is for YUV frames (video-range luma, 16-235, stretched to
 * 0-255), the luma weights for RGB ones. Null for a format not handled
 * (the caller draws the frame instead).
 */
export async function greyFromVideoFrame(frame) {
  try {
    const rect = frame.visibleRect;
    const { width, height } = rect;
    const format = frame.format;
    if (!PLANAR_YUV.has(format) && !PACKED[format]) return null;
    const buf = new Uint8Array(frame.allocationSize({ rect }));
    const layout = await frame.copyTo(buf, { rect });
    const { offset, stride } = layout[0];
    // Clamped: video-range luma below 16 or above 235 ends at 0 or 255 (rounded).
    const grey = new Uint8ClampedArray(width * height);
    if (PLANAR_YUV.has(format)) {
      const full = frame.colorSpace && frame.colorSpace.fullRange;
      for (let y = 0; y < height; y++) {
        const row = buf.subarray(offset + y * stride, offset + y * stride + width);
        if (full) grey.set(row, y * width);
        else for (let x = 0; x < width; x++) grey[y * width + x] = ((row[x] - 16) * 255) / 219;
      }
    } else {
      const [r, g, b] = PACKED[format];
      for (let y = 0; y < height; y++) {
        let j = offset + y * stride;
        for (let x = 0; x < width; x++, j += 4) {
          grey[y * width + x] = (LUMA[0] * buf[j + r] + LUMA[1] * buf[j + g] + LUMA[2] * buf[j + b]) / 10000;
        }
      }
    }
    return { grey: new Uint8Array(grey.buffer), width, height };
  } finally {
    frame.close();
  }
}
