// Live detection frames per second on the page's camera source, in headless
// Chromium with its fake camera playing a Y4M video of a board.
//
// For each board and resolution: `robocal render --camera CAM --target SPEC`
// draws 4 views of the board through a camera of that image size; a first
// Chromium page turns them into a Y4M video (grey as video-range luma,
// neutral chroma, each view held for 5 frames at 30 fps, played in a loop);
// a second Chromium opens the app with
// `--use-fake-device-for-media-stream --use-file-for-fake-video-capture=VIDEO`,
// sets the target, starts the camera at that resolution, and after a warm-up
// reads the page's own counters for `--seconds` (the status line's
// data-fps / data-detect-fps: sliding 2 s windows) and the worker's
// milliseconds a frame, sampled every 500 ms. Printed: the median of each,
// and the share of frames the board was found in.
//
// Usage (crate root, after `make web cli` and `tools/setup.sh e2e`):
//   node bench/live_fps.mjs [--seconds N] [--sizes 640x480,1280x720,1920x1080] [--boards chessboard,charuco,aprilgrid]
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync, openSync, writeSync, closeSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { startServer, launch } from '../tests/e2e/harness.mjs';

const BOARDS = {
  chessboard: { spec: 'chessboard:9x6:30mm', form: { kind: 'chessboard', cols: '9', rows: '6', square_mm: '30' } },
  charuco: { spec: 'charuco:8x6:30mm:22mm:DICT_5X5_100', form: { kind: 'charuco', squares_x: '8', squares_y: '6', charuco_square_mm: '30', marker_mm: '22', dictionary: 'DICT_5X5_100' } },
  aprilgrid: { spec: 'aprilgrid:6x6:30mm:0.3', form: { kind: 'aprilgrid', tag_cols: '6', tag_rows: '6', tag_mm: '30', spacing_ratio: '0.3' } },
};
const VIEWS = 4;
const HOLD = 5; // frames per view
const CLI = resolve('target/release/robocal');

const args = process.argv.slice(2);
const opt = (name, dflt) => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : dflt; };
const seconds = Number(opt('--seconds', '10'));
const sizes = opt('--sizes', '640x480,1280x720,1920x1080').split(',').map((s) => s.split('x').map(Number));
const boards = opt('--boards', 'chessboard,charuco,aprilgrid').split(',');

/** A pinhole camera of the given size (mild barrel distortion), as a robocal camera file. */
function cameraFile(dir, w, h) {
  const f = 0.9 * w;
  const cam = {
    schema: 'robocal.camera.v1', model: 'brown', image_size_px: [w, h],
    camera_matrix: [[f, 0, (w - 1) / 2], [0, f, (h - 1) / 2], [0, 0, 1]],
    distortion: { k1: -0.08, k2: 0.01, k3: 0, p1: 0, p2: 0 },
  };
  const path = join(dir, 'camera.json');
  writeFileSync(path, JSON.stringify(cam));
  return path;
}

/** The rendered PNGs turned into a Y4M video (4:2:0) in a Chromium page; returns its path. */
async function y4m(page, dir, w, h) {
  const pngs = readdirSync(dir).filter((f) => f.endsWith('.png')).sort();
  const path = join(dir, 'board.y4m');
  const fd = openSync(path, 'w');
  writeSync(fd, `YUV4MPEG2 W${w} H${h} F30:1 Ip A1:1 C420jpeg\n`);
  const chroma = Buffer.alloc((w / 2) * (h / 2) * 2, 128);
  for (const name of pngs) {
    const luma = Buffer.from(await page.evaluate(async (b64) => {
      const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      const bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
      const c = new OffscreenCanvas(bitmap.width, bitmap.height);
      const ctx = c.getContext('2d');
      ctx.drawImage(bitmap, 0, 0);
      const d = ctx.getImageData(0, 0, c.width, c.height).data;
      // Video-range luma (16-235): the player maps it back to the grey drawn.
      let s = '';
      for (let i = 0; i < d.length; i += 4) s += String.fromCharCode(16 + Math.round((219 * d[i]) / 255));
      return btoa(s);
    }, readFileSync(join(dir, name)).toString('base64')), 'base64');
    for (let k = 0; k < HOLD; k++) {
      writeSync(fd, 'FRAME\n');
      writeSync(fd, luma);
      writeSync(fd, chroma);
    }
  }
  closeSync(fd);
  return path;
}

/** One board at one size: the page's counters over `seconds`. */
async function measure(url, video, board, w, h) {
  const browser = await launch(['--use-fake-device-for-media-stream', `--use-file-for-fake-video-capture=${video}`]);
  try {
    const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
    await context.grantPermissions(['camera'], { origin: url });
    const page = await context.newPage();
    await page.goto(`${url}#target`);
    await page.locator('#engine-status.ready').waitFor({ timeout: 60000 });
    const { form } = BOARDS[board];
    await page.selectOption('#target-kind', form.kind);
    for (const [name, value] of Object.entries(form)) {
      if (name === 'kind') continue;
      const sel = `#target-form [name=${name}]`;
      if (await page.$eval(sel, (e) => e.tagName) === 'SELECT') await page.selectOption(sel, value);
      else await page.fill(sel, value);
    }
    await page.waitForFunction((spec) => document.getElementById('target-spec').textContent.startsWith(`Target spec: ${spec} `), BOARDS[board].spec, { timeout: 20000 });
    await page.click('a[data-step=images]');
    await page.selectOption('#camera-resolution', `${w}x${h}`);
    await page.click('#camera-start');
    await page.waitForFunction(() => Number(document.getElementById('camera-status').dataset.detectFps) > 0, null, { timeout: 60000 });
    await page.waitForTimeout(3000); // warm-up: the rate windows fill
    const samples = [];
    for (let t = 0; t < seconds * 2; t++) {
      await page.waitForTimeout(500);
      samples.push(await page.$eval('#camera-status', (s) => ({
        fps: Number(s.dataset.fps), detect: Number(s.dataset.detectFps), state: s.dataset.state,
        ms: Number((/\((\d+) ms a frame/.exec(s.textContent) || [])[1]), size: (/· (\d+ × \d+) ·/.exec(s.textContent) || [])[1],
      })));
    }
    const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; };
    return {
      board, size: `${w}x${h}`, shown: samples[0].size, camera_fps: median(samples.map((s) => s.fps)),
      detect_fps: median(samples.map((s) => s.detect)), detect_ms: median(samples.map((s) => s.ms)),
      found: samples.filter((s) => s.state !== 'none').length / samples.length,
    };
  } finally {
    await browser.close();
  }
}

const server = await startServer();
const converter = await launch();
const convPage = await converter.newPage();
const rows = [];
try {
  for (const board of boards) {
    for (const [w, h] of sizes) {
      const dir = mkdtempSync(join(tmpdir(), 'robocal-live-'));
      try {
        execFileSync(CLI, ['render', '--out', dir, '--target', BOARDS[board].spec, '--views', String(VIEWS), '--seed', '3', '--camera', cameraFile(dir, w, h)], { stdio: 'ignore' });
        const video = await y4m(convPage, dir, w, h);
        const r = await measure(server.url, video, board, w, h);
        rows.push(r);
        console.log(JSON.stringify(r));
      } finally {
        rmSync(dir, { recursive: true, force: true });
      }
    }
  }
} finally {
  await converter.close();
  server.stop();
}
console.log('\n| board | frame | camera fps | detection fps | worker ms a frame | frames with the board |');
console.log('|---|---|---|---|---|---|');
for (const r of rows) console.log(`| ${r.board} | ${r.shown || r.size} | ${r.camera_fps.toFixed(1)} | ${r.detect_fps.toFixed(1)} | ${r.detect_ms} | ${Math.round(100 * r.found)} % |`);
