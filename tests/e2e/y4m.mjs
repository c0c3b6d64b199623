// A Y4M video of rendered board views for Chromium's fake camera
// (`--use-file-for-fake-video-capture`), made without the renderer's own
// video mode: `robocal render --camera CAM --target SPEC --views N` draws the
// views through a camera of the wanted size, a Chromium page decodes each
// PNG, and its grey becomes video-range luma (16-235; chroma neutral) held
// for `hold` frames at 30 fps. Chromium plays the file in a loop.
import { execFileSync } from 'node:child_process';
import { closeSync, openSync, readFileSync, readdirSync, writeFileSync, writeSync } from 'node:fs';
import { join } from 'node:path';
import { root } from './harness.mjs';

const CLI = join(root, 'target/release/robocal');

/** A robocal camera file: focal 0.9 * width, centred, mild barrel distortion (or the `camera` given). */
export function cameraJson(w, h, camera = {}) {
  const f = 0.9 * w;
  return {
    schema: 'robocal.camera.v1', model: 'brown', image_size_px: [w, h],
    camera_matrix: [[f, 0, (w - 1) / 2], [0, f, (h - 1) / 2], [0, 0, 1]],
    distortion: { k1: -0.08, k2: 0.01, k3: 0, p1: 0, p2: 0 },
    ...camera,
  };
}

/**
 * Render `views` views of `spec` in `dir` through `camera` (a camera JSON)
 * and write `dir/board.y4m`, each view held `hold` frames (the right
 * `hideRight` of each frame painted over); `page` is any
 * Chromium page (it decodes the PNGs). Returns the video's path and the
 * render's truth.json.
 */
export async function boardVideo(page, dir, { spec, camera, views, hold, seed = 3, noise = 2, hideRight = 0 }) {
  const [w, h] = camera.image_size_px;
  writeFileSync(join(dir, 'camera.json'), JSON.stringify(camera));
  execFileSync(CLI, ['render', '--out', dir, '--target', spec, '--views', String(views), '--seed', String(seed), '--noise', String(noise), '--camera', join(dir, 'camera.json')], { stdio: 'ignore' });
  const path = join(dir, 'board.y4m');
  const fd = openSync(path, 'w');
  writeSync(fd, `YUV4MPEG2 W${w} H${h} F30:1 Ip A1:1 C420jpeg\n`);
  await writeHolds(page, fd, dir, w, h, hold, hideRight);
  closeSync(fd);
  return { path, truth: JSON.parse(readFileSync(join(dir, 'truth.json'), 'utf8')) };
}

/** Each PNG of `dir` (sorted) as `hold` Y4M frames on `fd` (the right `hideRight` painted over). */
async function writeHolds(page, fd, dir, w, h, hold, hideRight = 0) {
  const pngs = readdirSync(dir).filter((f) => f.endsWith('.png')).sort();
  const chroma = Buffer.alloc((w / 2) * (h / 2) * 2, 128);
  for (const name of pngs) {
    const luma = Buffer.from(await page.evaluate(async (b64) => {
      const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      const bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
      const c = new OffscreenCanvas(bitmap.width, bitmap.height);
      const ctx = c.getContext('2d');
      ctx.drawImage(bitmap, 0, 0);
      const d = ctx.getImageData(0, 0, c.width, c.height).data;
      let s = '';
      for (let i = 0; i < d.length; i += 4) s += String.fromCharCode(16 + Math.round((219 * d[i]) / 255));
      return btoa(s);
    }, readFileSync(join(dir, name)).toString('base64')), 'base64');
    // `hideRight`: that fraction of each frame's right side painted mid-grey (a hand over the board).
    const from = Math.round(w * (1 - hideRight));
    if (hideRight > 0) for (let y = 0; y < h; y++) luma.fill(126, y * w + from, (y + 1) * w);
    for (let k = 0; k < hold; k++) {
      writeSync(fd, 'FRAME\n');
      writeSync(fd, luma);
      writeSync(fd, chroma);
    }
  }
}

/**
 * Append `views` views rendered by `robocal render --views` (random poses,
 * seeded) through the video's own camera (`truth.camera` of `robocal render
 * --video`) to the video at `path`, each held `hold` frames: more held poses
 * for the capture guide after the video's own. Returns the views' truth.json.
 */
export async function appendViews(page, path, dir, truth, { views, hold, seed }) {
  const c = truth.camera;
  const [w, h] = truth.size_px;
  const camera = cameraJson(w, h, {
    camera_matrix: [[c.fx, 0, c.cx], [0, c.fy, c.cy], [0, 0, 1]],
    distortion: { k1: c.distortion.k1, k2: c.distortion.k2, k3: c.distortion.k3, p1: c.distortion.p1, p2: c.distortion.p2 },
  });
  writeFileSync(join(dir, 'camera.json'), JSON.stringify(camera));
  execFileSync(CLI, ['render', '--out', dir, '--views', String(views), '--seed', String(seed), '--camera', join(dir, 'camera.json')], { stdio: 'ignore' });
  const fd = openSync(path, 'a');
  await writeHolds(page, fd, dir, w, h, hold);
  closeSync(fd);
  return JSON.parse(readFileSync(join(dir, 'truth.json'), 'utf8'));
}
