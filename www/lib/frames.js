// Video frames as the core reads them: RGBA pixels to grey (the weights the
// core's decoder uses for colour images, so a live frame and the same frame
// captured as PNG give the same grey), wrapped as a binary PGM (P5) that the
// core's decoder takes like any other image file.

/** Rec. 709 luma weights in ten-thousandths, as the `image` crate's RGB-to-luma. */
const LUMA = [2126, 7152, 722];

/** RGBA bytes (`width`*`height`*4) to grey bytes. */
export function greyFromRgba(rgba, width, height) {
  const n = width * height;
  const grey = new Uint8Array(n);
  for (let i = 0, j = 0; i < n; i++, j += 4) {
    grey[i] = (LUMA[0] * rgba[j] + LUMA[1] * rgba[j + 1] + LUMA[2] * rgba[j + 2] + 5000) / 10000;
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
