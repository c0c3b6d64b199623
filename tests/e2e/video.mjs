// Issue 36 on the page: video files as input. A WebM made here with ffmpeg
// (libvpx) from views rendered by `robocal render` is decoded by Chromium
// itself; the frames the live capture's rules keep (found, still, sharp,
// adding coverage) become cards named like the CLI's (`board.webm#frame0123`)
// and the camera solved from them lands on the render's truth. An MPEG-4
// Part 2 (`mp4v`) file, which browsers do not decode, is refused with the
// codec and the ffmpeg line that converts it.
import assert from 'node:assert/strict';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { execFileSync } from 'node:child_process';
import { root } from './harness.mjs';
import { cameraJson } from './y4m.mjs';

const CLI = join(root, 'target/release/robocal');
const FFMPEG = '/usr/bin/ffmpeg';
/** The videos' frame rate, and the frames each rendered view is held: 0.8 s, longer than the still rule's 500 ms. */
const FPS = 10;
const HOLD = 8;
const VIEWS = 10;

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
const cellValue = async (page, table, name) => Number(await page.$eval(`${table} tbody`, (tb, n) => {
  const row = [...tb.rows].find((r) => r.cells[0].textContent === n);
  return row ? row.cells[1].textContent : 'NaN';
}, name));

/** Render `views` views of the page's default target through `camera` into `dir`; returns the sorted PNG paths. */
function render(dir, camera, views, seed) {
  writeFileSync(join(dir, 'camera.json'), JSON.stringify(camera));
  execFileSync(CLI, ['render', '--out', dir, '--target', 'chessboard:9x6:30mm', '--views', String(views), '--seed', String(seed), '--noise', '2', '--camera', join(dir, 'camera.json')], { stdio: 'ignore' });
  return readdirSync(dir).filter((f) => f.endsWith('.png')).sort().map((f) => join(dir, f));
}

/** A video of `pngs`, each held `hold` frames at FPS, encoded by ffmpeg with `codecArgs` into `out`. */
function encode(pngs, hold, out, codecArgs) {
  const seq = mkdtempSync(join(tmpdir(), 'robocal-video-seq-'));
  try {
    let k = 0;
    for (const png of pngs) for (let i = 0; i < hold; i++) symlinkSync(png, join(seq, `f${String(k++).padStart(4, '0')}.png`));
    execFileSync(FFMPEG, ['-loglevel', 'error', '-y', '-framerate', String(FPS), '-i', join(seq, 'f%04d.png'), ...codecArgs, '-pix_fmt', 'yuv420p', out]);
  } finally {
    rmSync(seq, { recursive: true, force: true });
  }
  return out;
}

export const tests = [
  ['a WebM: frames kept by the capture rules, named like the CLI\'s, the camera solved near the truth', async (page, { url, shot }) => {
    const dir = mkdtempSync(join(tmpdir(), 'robocal-video-'));
    try {
      const camera = cameraJson(640, 480);
      mkdirSync(join(dir, 'views'));
      const pngs = render(join(dir, 'views'), camera, VIEWS, 7);
      const video = encode(pngs, HOLD, join(dir, 'board.webm'), ['-c:v', 'libvpx', '-quality', 'good', '-cpu-used', '4', '-crf', '4', '-b:v', '8M']);
      await page.goto(`${url}#images`);
      await ready(page);
      const t0 = Date.now();
      await page.setInputFiles('#video-input', video);
      await page.waitForFunction(() => ['done', 'refused'].includes(document.getElementById('video-status').dataset.state), null, { timeout: 240000 })
        .catch(async (e) => { throw new Error(`${await page.textContent('#video-status')} ${await page.textContent('#video-message')} (${e.message})`); });
      assert.equal(await page.textContent('#video-message'), '');
      const summary = await page.textContent('#video-status');
      console.log(`     ${summary} (${Date.now() - t0} ms)`);
      const m = /^board\.webm: (\d+) frames read \(640 × 480, V_VP8\), board in (\d+), (\d+) kept by the capture rules( \(left out: .+\))?\.$/.exec(summary);
      assert.ok(m, summary);
      const [read, found, kept] = m.slice(1, 4).map(Number);
      assert.equal(read, VIEWS * HOLD, 'every frame of the video is read');
      assert.ok(found >= (VIEWS - 1) * HOLD, `the board in ${found} frames`);
      assert.ok(kept >= 6 && kept <= VIEWS, `${kept} kept`);
      // Every kept frame waited for the board to be still: never a hold's first frames.
      await page.waitForFunction((n) => new RegExp(`\\b${n} with the target`).test(document.getElementById('image-summary').textContent), kept, { timeout: 60000 });
      const names = await page.$$eval('.card .name', (els) => els.map((el) => el.textContent));
      assert.equal(names.length, kept);
      const holds = new Set();
      for (const name of names) {
        const f = /^board\.webm#frame(\d{4})$/.exec(name);
        assert.ok(f, name);
        const index = Number(f[1]);
        assert.ok(index % HOLD >= 3, `${name}: kept before the board was still (250 ms)`);
        holds.add(Math.floor(index / HOLD));
      }
      assert.equal(holds.size, names.length, `one frame per held view: ${names}`);
      await shot('kept');
      await page.click('a[data-step=camera]');
      await page.click('#solve-camera');
      await page.locator('#camera-params').waitFor({ timeout: 120000 });
      const [f, cx0, cy0] = [camera.camera_matrix[0][0], camera.camera_matrix[0][2], camera.camera_matrix[1][2]];
      const got = { fx: await cellValue(page, '#camera-params', 'fx'), cx: await cellValue(page, '#camera-params', 'cx'), cy: await cellValue(page, '#camera-params', 'cy') };
      console.log(`     solved from ${kept} video frames: fx ${got.fx} (true ${f}), cx ${got.cx} (true ${cx0}), cy ${got.cy} (true ${cy0})`);
      assert.ok(Math.abs(got.fx - f) < 3, `fx ${got.fx} vs ${f}`);
      assert.ok(Math.abs(got.cx - cx0) < 3, `cx ${got.cx} vs ${cx0}`);
      assert.ok(Math.abs(got.cy - cy0) < 3, `cy ${got.cy} vs ${cy0}`);
      await shot('solved');
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  }],
  ['an mp4v file (MPEG-4 Part 2, OpenCV\'s and caliscope\'s): refused with its codec and the ffmpeg line, added with the images', async (page, { url, shot }) => {
    const dir = mkdtempSync(join(tmpdir(), 'robocal-video-'));
    try {
      mkdirSync(join(dir, 'views'));
      const pngs = render(join(dir, 'views'), cameraJson(320, 240), 2, 3);
      const video = encode(pngs, 3, join(dir, 'cam_0.mp4'), ['-c:v', 'mpeg4', '-tag:v', 'mp4v']);
      await page.goto(`${url}#images`);
      await ready(page);
      // Through the images' own input (as a drop): the video is routed to the video reader.
      await page.setInputFiles('#file-input', video);
      await page.locator('#video-message:not([hidden])').waitFor({ timeout: 60000 });
      assert.equal(await page.textContent('#video-message'), 'This browser cannot decode the video of cam_0.mp4 (codec mp4v, MPEG-4 Part 2). Convert it to VP9 in WebM with ffmpeg, then add the .webm file: ffmpeg -i cam_0.mp4 -c:v libvpx-vp9 cam_0.webm');
      assert.equal(await page.getAttribute('#video-status', 'data-state'), 'refused');
      assert.equal(await page.$$eval('.card', (els) => els.length), 0, 'no card for the video');
      await shot('refused');
      // caliscope's own recording (the shared datasets copy, when present): the same message.
      const caliscope = join(root, '..', 'shared', 'datasets', 'caliscope-4cam-charuco-video', 'video', 'cam_1.mp4');
      if (existsSync(caliscope)) {
        await page.setInputFiles('#video-input', caliscope);
        await page.waitForFunction(() => /cam_1\.mp4/.test(document.getElementById('video-message').textContent), null, { timeout: 60000 });
        assert.equal(await page.textContent('#video-message'), 'This browser cannot decode the video of cam_1.mp4 (codec mp4v, MPEG-4 Part 2). Convert it to VP9 in WebM with ffmpeg, then add the .webm file: ffmpeg -i cam_1.mp4 -c:v libvpx-vp9 cam_1.webm');
      }
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  }],
  ['two cameras\' WebMs and a timestamps file: rig frames by sync_index, the rig solved near the truth', async (page, { url, shot }) => {
    const dir = mkdtempSync(join(tmpdir(), 'robocal-video-rig-'));
    try {
      execFileSync(CLI, ['render', '--out', dir, '--rig', '--views', '6', '--side-frames', '0', '--seed', '5'], { stdio: 'ignore' });
      const truth = JSON.parse(readFileSync(join(dir, 'truth.json'), 'utf8'));
      const [c0, c1] = truth.cameras;
      const keys = [...new Set([...c0.images, ...c1.images].map((i) => i.frame))].sort((a, b) => a - b);
      const first = readFileSync(join(dir, c0.images[0].image.includes('/') ? c0.images[0].image : join(c0.name, c0.images[0].image)));
      const [w, hgt] = [first.readUInt32BE(16), first.readUInt32BE(20)];
      const grey = join(dir, 'grey.png');
      execFileSync(FFMPEG, ['-loglevel', 'error', '-y', '-f', 'lavfi', '-i', `color=c=gray:s=${w}x${hgt}`, '-frames:v', '1', grey]);
      const imageOf = (c, key) => { const i = c.images.find((im) => im.frame === key); return i ? join(dir, i.image.includes('/') ? i.image : join(c.name, i.image)) : grey; };
      // cam_1 started a hold earlier: its first HOLD frames (grey) have sync indices no cam_0 frame has.
      const vp8 = ['-c:v', 'libvpx', '-quality', 'good', '-cpu-used', '4', '-crf', '4', '-b:v', '8M'];
      const v0 = encode(keys.map((k) => imageOf(c0, k)), HOLD, join(dir, 'cam_0.webm'), vp8);
      const v1 = encode([grey, ...keys.map((k) => imageOf(c1, k))], HOLD, join(dir, 'cam_1.webm'), vp8);
      const rows = ['sync_index,cam_id,frame_index,frame_time'];
      const n = keys.length * HOLD;
      for (let j = 0; j < n; j++) rows.push(`${j},0,${j + 26},${(j / FPS).toFixed(4)}`);
      for (let j = 0; j < n + HOLD; j++) rows.push(`${j < HOLD ? 100000 + j : j - HOLD},1,${j + 26},${((j - HOLD) / FPS).toFixed(4)}`);
      writeFileSync(join(dir, 'timestamps.csv'), `${rows.join('\n')}\n`);
      await page.goto(`${url}#stereo`);
      await ready(page);
      await page.click('a[data-step=target]');
      await page.fill('#target-form input[name=cols]', '10');
      await page.fill('#target-form input[name=rows]', '7');
      await page.fill('#target-form input[name=square_mm]', '60');
      await page.waitForFunction(() => document.getElementById('target-spec').textContent.startsWith('Target spec: chessboard:10x7:60mm '), null, { timeout: 10000 });
      await page.click('a[data-step=stereo]');
      await page.setInputFiles('#rig-videos', [v0, v1, join(dir, 'timestamps.csv')]);
      await page.waitForFunction(() => ['done', 'refused'].includes(document.getElementById('rig-video-status').dataset.state), null, { timeout: 300000 });
      assert.equal(await page.textContent('#rig-video-message'), '', await page.textContent('#rig-video-message'));
      const status = await page.textContent('#rig-video-status');
      console.log(`     ${status}`);
      const m = / (\d+) rig frames from the videos \(a frame any camera kept, with every camera that found the board in it\), matched by the sync_index of timestamps\.csv\.$/.exec(status);
      assert.ok(m, status);
      const frames = Number(m[1]);
      assert.ok(frames >= 3, `${frames} rig frames`);
      await page.waitForFunction((t) => (document.getElementById('rig-grouping')?.textContent || '') === t, `${frames} frames over 2 cameras, grouped by the timestamps' sync_index (video frames).`, { timeout: 20000 });
      const table = await page.$$eval('#rig-frame-table tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
      for (const [key, a, b] of table) {
        assert.ok(Number(key) < 100000, `frame ${key}: a grey lead-in frame of cam_1 became a rig frame`);
        // The same view in both: cam_0's frame k is sync k, cam_1's is sync k + HOLD.
        const fa = /^cam_0\.webm#frame(\d{4}): /.exec(a);
        const fb = /^cam_1\.webm#frame(\d{4}): /.exec(b);
        if (fa) assert.equal(Number(fa[1]), Number(key), a);
        if (fb) assert.equal(Number(fb[1]), Number(key) + HOLD, b);
      }
      assert.deepEqual(await page.$$eval('.rig-camera input[type=text]', (els) => els.map((e) => e.value)), ['cam0', 'cam1']);
      await shot('grouped');
      await page.click('#rig-solve');
      await page.locator('#rig-summary').waitFor({ timeout: 600000 });
      await shot('solved');
      const [download] = await Promise.all([page.waitForEvent('download'), page.click('#rig-export-json')]);
      const report = JSON.parse(readFileSync(await download.path(), 'utf8'));
      const got = report.cameras[1].camera_from_rig.translation_m;
      const want = c1.camera_from_rig.translation_m.map((t, i) => t - c0.camera_from_rig.translation_m[i]);
      const off = Math.hypot(...got.map((t, i) => t - want[i]));
      console.log(`     cam1 from the rig (cam0): ${got.map((t) => (t * 1000).toFixed(2)).join(', ')} mm (truth ${want.map((t) => (t * 1000).toFixed(2)).join(', ')} mm), ${(off * 1000).toFixed(2)} mm off`);
      assert.ok(off < 0.003, `cam1's translation ${(off * 1000).toFixed(2)} mm from the truth`);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  }],
];
