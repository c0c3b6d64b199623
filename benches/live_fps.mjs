// Live detection frames per second on the page's camera source, in headless
// Chromium with its fake camera playing a Y4M video of a board.
//
// For each board and resolution: `robocal render --camera CAM --target SPEC`
// draws 4 views of the board through a camera of that image size; a first
// Chromium page turns them into a Y4M video (tests/e2e/y4m.mjs: grey as
// video-range luma, each view held for 10 frames at 30 fps, played in a loop);
// a second Chromium opens the app with
// `--use-fake-device-for-media-stream --use-file-for-fake-video-capture=VIDEO`,
// sets the target, starts the camera at that resolution, and after a warm-up
// reads the page's own counters for `--seconds` (the status line's
// data-fps / data-detect-fps: sliding 2 s windows) and the worker's
// milliseconds a frame (and the whole cycle's, from taking the frame to
// the drawn overlay), sampled every 500 ms. Printed: the median of each,
// and the share of frames the board was found in.
//
// Usage (crate root, after `make web cli` and `tools/setup.sh e2e`):
//   node benches/live_fps.mjs [--seconds N] [--sizes 640x480,1280x720,1920x1080] [--boards chessboard,charuco,aprilgrid] [--shots DIR]
// --shots: a screenshot of the page at the end of each measurement, to look at.
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startServer, launch } from '../tests/e2e/harness.mjs';
import { boardVideo, cameraJson } from '../tests/e2e/y4m.mjs';

const BOARDS = {
  chessboard: { spec: 'chessboard:9x6:30mm', form: { kind: 'chessboard', cols: '9', rows: '6', square_mm: '30' } },
  charuco: { spec: 'charuco:8x6:30mm:22mm:DICT_5X5_100', form: { kind: 'charuco', squares_x: '8', squares_y: '6', charuco_square_mm: '30', marker_mm: '22', dictionary: 'DICT_5X5_100' } },
  aprilgrid: { spec: 'aprilgrid:6x6:30mm:0.3', form: { kind: 'aprilgrid', tag_cols: '6', tag_rows: '6', tag_mm: '30', spacing_ratio: '0.3' } },
};
const VIEWS = 4;
const HOLD = 10; // frames per view

const args = process.argv.slice(2);
const opt = (name, dflt) => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : dflt; };
const seconds = Number(opt('--seconds', '10'));
const sizes = opt('--sizes', '640x480,1280x720,1920x1080').split(',').map((s) => s.split('x').map(Number));
const boards = opt('--boards', 'chessboard,charuco,aprilgrid').split(',');
const shots = opt('--shots', null);

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
        ms: Number((/\((\d+) ms a frame/.exec(s.textContent) || [])[1]), cycle: Number((/(\d+) ms in all/.exec(s.textContent) || [])[1]), size: (/· (\d+ × \d+) ·/.exec(s.textContent) || [])[1],
      })));
    }
    if (shots) await page.screenshot({ path: join(shots, `live-${board}-${w}x${h}.png`) });
    const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; };
    return {
      board, size: `${w}x${h}`, shown: samples[0].size, camera_fps: median(samples.map((s) => s.fps)),
      detect_fps: median(samples.map((s) => s.detect)), detect_ms: median(samples.map((s) => s.ms)), cycle_ms: median(samples.map((s) => s.cycle)),
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
        const { path: video } = await boardVideo(convPage, dir, { spec: BOARDS[board].spec, camera: cameraJson(w, h), views: VIEWS, hold: HOLD });
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
console.log('\n| board | frame | camera fps | detection fps | worker ms a frame | ms a frame in all | frames with the board |');
console.log('|---|---|---|---|---|---|---|');
for (const r of rows) console.log(`| ${r.board} | ${r.shown || r.size} | ${r.camera_fps.toFixed(1)} | ${r.detect_fps.toFixed(1)} | ${r.detect_ms} | ${r.cycle_ms} | ${Math.round(100 * r.found)} % |`);
