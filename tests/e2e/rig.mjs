// The rig step (step 7, stereo pairs and rigs): a seeded four-camera rig
// rendered by the release CLI (`robocal render --rig`: two pairs facing each
// other, linked only by the side frames) through the page: cameras added,
// frames grouped by the number in the file names, detection and the joint
// solve in the worker. Every camera_from_rig is checked against the render's
// truth within 3 of the standard deviations the page reports, and against
// `robocal rig` on the same files (same core: equal to 1e-9); with k3 held
// (the lens choice of step 3) the page's solve equals `robocal rig --fix k3`
// and its Kalibr camchain the CLI's export. Without side frames the page
// shows the core's error naming the two groups. OpenCV's left/right set as a
// 2-camera rig gives the stereo result (right_from_left, its tables, the
// export step's transform), kept over a reload; an earlier session's stereo
// result still opens. The rig on a robot: a rendered rig carried by an
// eye-in-hand robot of known gripper_from_rig, solved in the page within
// 3 mm / 3 mrad of the truth and equal to `robocal rig --setup eye-in-hand
// --poses` to 1e-6. Held intrinsics: a pair whose second camera's frames
// disagree with the first's (half its images shifted, as a board that moved
// between the shots) draws the drift warning; holding the named camera from
// its own calibration (the warning's button) or from a camera file (that
// calibration saved) removes it, the camera's intrinsics exactly the held ones
// and the rig equal to `robocal rig --camera-file NAME=FILE`.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { root } from './harness.mjs';
import { datasetDir } from './datasets.mjs';

const CLI = join(root, 'target/release/robocal');
const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });

/** Renders a rig into a fresh folder; returns the folder, its truth and each camera's files. */
function renderRig(sideFrames) {
  const dir = mkdtempSync(join(tmpdir(), 'robocal-rig-e2e-'));
  execFileSync(CLI, ['render', '--out', dir, '--rig', '--views', '6', '--side-frames', String(sideFrames), '--seed', '5'], { stdio: ['ignore', 'ignore', 'pipe'] });
  const truth = JSON.parse(readFileSync(join(dir, 'truth.json'), 'utf8'));
  const files = truth.cameras.map((c) => readdirSync(join(dir, c.name)).sort().map((f) => join(dir, c.name, f)));
  return { dir, truth, files };
}

async function setTarget(page, cols, rows, squareMm) {
  await page.click('a[data-step=target]');
  await page.fill('#target-form input[name=cols]', String(cols));
  await page.fill('#target-form input[name=rows]', String(rows));
  await page.fill('#target-form input[name=square_mm]', String(squareMm));
  const want = `Target spec: chessboard:${cols}x${rows}:${squareMm}mm `;
  await page.waitForFunction((w) => document.getElementById('target-spec').textContent.startsWith(w), want, { timeout: 10000 });
  await page.click('a[data-step=stereo]');
}

/** Cameras named as given, each with its files. */
async function loadCameras(page, names, files) {
  for (let k = 2; k < names.length; k++) await page.click('#rig-add');
  for (let k = 0; k < names.length; k++) {
    await page.fill(`#rig-name-${k}`, names[k]);
    await page.dispatchEvent(`#rig-name-${k}`, 'change');
    await page.setInputFiles(`#rig-input-${k}`, files[k]);
    await page.waitForFunction(([k, n]) => document.getElementById(`rig-count-${k}`)?.textContent === `${n} images`, [k, files[k].length], { timeout: 20000 });
  }
}

/** The step reloaded at a phone's width (400 px) for a screenshot, then back at the suite's 1280 px. */
async function narrowShot(page, shot, label) {
  await page.waitForTimeout(500); // the store saves 300 ms after the last change
  for (const width of [400, 1280]) {
    await page.setViewportSize({ width, height: 900 });
    await page.reload();
    await ready(page);
    await page.locator('#rig-summary').waitFor({ timeout: 30000 });
    if (width === 400) await shot(label);
  }
}

/** rig.json as the page's export button downloads it. */
async function downloadedReport(page) {
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#rig-export-json')]);
  assert.equal(download.suggestedFilename(), 'rig.json');
  return JSON.parse(readFileSync(await download.path(), 'utf8'));
}

// Small rotation helpers on row-major 3x3 matrices.
const R3 = (m) => [0, 1, 2].map((i) => m[i].slice(0, 3));
const mulT = (a, b) => a.map((row) => [0, 1, 2].map((j) => row[0] * b[j][0] + row[1] * b[j][1] + row[2] * b[j][2])); // a b^T
/** log of a rotation matrix near the identity, as a rotation vector. */
function logSmall(r) {
  const angle = Math.acos(Math.max(-1, Math.min(1, (r[0][0] + r[1][1] + r[2][2] - 1) / 2)));
  const v = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]];
  const s = angle < 1e-12 ? 0.5 : angle / (2 * Math.sin(angle));
  return v.map((x) => x * s);
}

// 4x4 row-major poses for the robot of the rig on a robot.
const mul4 = (a, b) => a.map((row) => [0, 1, 2, 3].map((j) => row.reduce((s, v, k) => s + v * b[k][j], 0)));
function inv4(m) {
  const r = R3(m);
  const rt = [0, 1, 2].map((i) => [0, 1, 2].map((j) => r[j][i]));
  const t = [0, 1, 2].map((i) => -(rt[i][0] * m[0][3] + rt[i][1] * m[1][3] + rt[i][2] * m[2][3]));
  return [...rt.map((row, i) => [...row, t[i]]), [0, 0, 0, 1]];
}
/** The pose of a translation (m) and a rotation vector (rad). */
function pose4(t, w) {
  const a = Math.hypot(...w);
  const [x, y, z] = a < 1e-15 ? [0, 0, 0] : w.map((v) => v / a);
  const c = Math.cos(a), s = Math.sin(a), C = 1 - c;
  const r = [[c + x * x * C, x * y * C - z * s, x * z * C + y * s], [y * x * C + z * s, c + y * y * C, y * z * C - x * s], [z * x * C - y * s, z * y * C + x * s, c + z * z * C]];
  return [...r.map((row, i) => [...row, t[i]]), [0, 0, 0, 1]];
}
/** quaternion x, y, z, w of a rotation matrix (Shepperd). */
function quaternion(m) {
  const tr = m[0][0] + m[1][1] + m[2][2];
  if (tr > 0) { const s = 2 * Math.sqrt(tr + 1); return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4]; }
  if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) { const s = 2 * Math.sqrt(1 + m[0][0] - m[1][1] - m[2][2]); return [s / 4, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]; }
  if (m[1][1] > m[2][2]) { const s = 2 * Math.sqrt(1 + m[1][1] - m[0][0] - m[2][2]); return [(m[0][1] + m[1][0]) / s, s / 4, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]; }
  const s = 2 * Math.sqrt(1 + m[2][2] - m[0][0] - m[1][1]);
  return [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, s / 4, (m[1][0] - m[0][1]) / s];
}

/**
 * An eye-in-hand robot pose file for a rendered rig: base_from_gripper =
 * base_from_target * rig_from_target^-1 * gripper_from_rig^-1 per frame, in
 * metres and quaternions, each row naming an image of its frame (the robot
 * of the CLI's test: tests/cli/cli_rig.rs).
 */
function robotPoses(truth) {
  const gripperFromRig = pose4([0.05, -0.12, 0.2], [0.3, -1.1, 0.4]);
  const baseFromTarget = pose4([0.8, 0.1, -0.3], [2.0, 0.2, -0.5]);
  const imageOf = new Map();
  for (const c of truth.cameras) for (const i of c.images) if (!imageOf.has(i.frame)) imageOf.set(i.frame, i.image.split('/').pop());
  const rows = truth.frames.filter((f) => imageOf.has(f.key)).map((f) => {
    const m = mul4(mul4(baseFromTarget, inv4(f.rig_from_target.matrix_row_major)), inv4(gripperFromRig));
    return [imageOf.get(f.key), m[0][3], m[1][3], m[2][3], ...quaternion(m)].join(',');
  });
  return { gripperFromRig, csv: `image,x,y,z,qx,qy,qz,qw\n${rows.join('\n')}\n` };
}

/** PNG bytes with the picture moved `dx` px to the right (the uncovered band in the corner pixel's grey), drawn by the page's canvas. */
async function shiftedPng(page, bytes, dx) {
  const b64 = await page.evaluate(async ([data, dx]) => {
    const raw = Uint8Array.from(atob(data), (c) => c.charCodeAt(0));
    const bitmap = await createImageBitmap(new Blob([raw], { type: 'image/png' }));
    const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
    const ctx = canvas.getContext('2d');
    ctx.drawImage(bitmap, 0, 0);
    const [r, g, b] = ctx.getImageData(0, 0, 1, 1).data;
    ctx.fillStyle = `rgb(${r},${g},${b})`;
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    ctx.drawImage(bitmap, dx, 0);
    const out = new Uint8Array(await (await canvas.convertToBlob({ type: 'image/png' })).arrayBuffer());
    let s = '';
    for (let i = 0; i < out.length; i += 0x8000) s += String.fromCharCode(...out.subarray(i, i + 0x8000));
    return btoa(s);
  }, [Buffer.from(bytes).toString('base64'), dx]);
  return Buffer.from(b64, 'base64');
}

const DRIFT = /^camera (\S+): the joint rig fit moved its intrinsics beyond their own uncertainty/;

export const tests = [
  ['four-camera rig: extrinsics within 3 reported std of the truth, page = robocal rig, co-observation, 3-D view, exports', async (page, { url, shot }) => {
    const { dir, truth, files } = renderRig(3);
    try {
      const names = truth.cameras.map((c) => c.name);
      await page.goto(`${url}#stereo`);
      await ready(page);
      await setTarget(page, 10, 7, 60);
      await loadCameras(page, names, files);
      const frames = new Set(truth.cameras.flatMap((c) => c.images.map((i) => i.frame))).size;
      await page.waitForFunction((t) => (document.getElementById('rig-grouping')?.textContent || '') === t, `${frames} frames over 4 cameras, grouped by the number in the file names.`, { timeout: 20000 });
      assert.equal(await page.isDisabled('#rig-solve'), false);
      await shot('loaded');
      await page.click('#rig-solve');
      await page.locator('#rig-summary').waitFor({ timeout: 600000 });
      await shot('solved');
      const report = await downloadedReport(page);
      const cli = JSON.parse(execFileSync(CLI, ['rig', ...files.flatMap((f, k) => ['--camera', names[k], ...f]), '--target', 'chessboard:10x7:60mm'], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
      assert.deepEqual(report.cameras.map((c) => c.name), names);
      assert.deepEqual(report.co_observation.frames, cli.co_observation.frames);
      // cam0 and cam1 never see a frame together with cam3 / cam2 across the pairs' backs.
      assert.equal(report.co_observation.frames[0][2], 0);
      assert.equal(report.co_observation.frames[1][3], 0);
      assert.ok(report.co_observation.frames[1][2] > 0, 'the side frames link cam1 and cam2');
      let worst = 0;
      report.cameras.forEach((c, k) => {
        const t = truth.cameras[k].camera_from_rig;
        // Same core on the same detections: the page's numbers are the CLI's.
        c.camera_from_rig.matrix_row_major.flat().forEach((x, i) => assert.ok(Math.abs(x - cli.cameras[k].camera_from_rig.matrix_row_major.flat()[i]) <= 1e-9, `${c.name} entry ${i}: page ${x}, CLI`));
        if (k === 0) { assert.equal(c.camera_from_rig_std, null); return; }
        const s = c.camera_from_rig_std;
        const dt = c.camera_from_rig.translation_m.map((x, i) => x - t.translation_m[i]);
        // std convention: R_true = exp(d) R_est.
        const dr = logSmall(mulT(R3(t.matrix_row_major), R3(c.camera_from_rig.matrix_row_major)));
        dt.forEach((e, i) => { worst = Math.max(worst, Math.abs(e) / s.translation_m[i]); assert.ok(Math.abs(e) <= 3 * s.translation_m[i], `${c.name} T[${i}] off by ${e} m, std ${s.translation_m[i]}`); });
        dr.forEach((e, i) => { worst = Math.max(worst, Math.abs(e) / s.rotation_rad[i]); assert.ok(Math.abs(e) <= 3 * s.rotation_rad[i], `${c.name} rotation[${i}] off by ${e} rad, std ${s.rotation_rad[i]}`); });
        // The table shows what the report holds (T in mm, 3 decimals).
        assert.ok(s.translation_m.every((v) => v > 0 && v < 0.01), `${c.name} std ${s.translation_m}`);
      });
      const rows = await page.$$eval('#rig-extrinsics tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
      report.cameras.forEach((c, k) => {
        assert.equal(rows[k][0], c.name);
        c.camera_from_rig.translation_m.forEach((v, i) => assert.equal(rows[k][1 + i], (v * 1000).toFixed(3)));
        if (k) c.camera_from_rig_std.translation_m.forEach((v, i) => assert.equal(rows[k][4 + i], (v * 1000).toFixed(3)));
      });
      const co = await page.$$eval('#rig-coobservation tbody tr', (trs) => trs.map((tr) => [...tr.cells].slice(1).map((c) => parseInt(c.textContent, 10))));
      assert.deepEqual(co, report.co_observation.frames);
      assert.equal(await page.locator('#rig-frame-residuals tbody tr').count(), report.frames.length);
      // The warnings are the CLI's, each solved camera's own advice among them, all shown.
      assert.deepEqual(report.warnings, cli.warnings);
      assert.ok(report.warnings.some((w) => /^camera cam\d: /.test(w) && !/left out/.test(w)), report.warnings.join('\n'));
      assert.deepEqual(await page.$$eval('#rig-results .msg-warning', (ps) => ps.map((p) => p.textContent)), report.warnings);
      // The 3-D view drew something on its canvas.
      const inked = await page.$eval('#rig-3d', (c) => { const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0; for (let i = 0; i < d.length; i += 4) if (d[i] < 200) n++; return n; });
      assert.ok(inked > 2000, `3-D view: ${inked} dark pixels`);
      await page.locator('#rig-3d').scrollIntoViewIfNeeded();
      await shot('3d');
      // OpenCV FileStorage from the page equals `robocal export rig.json --format opencv-yaml`.
      const [yaml] = await Promise.all([page.waitForEvent('download'), page.click('#rig-export-opencv-yaml')]);
      const pageYaml = readFileSync(await yaml.path(), 'utf8');
      writeFileSync(join(dir, 'rig.json'), JSON.stringify(report));
      const cliYaml = execFileSync(CLI, ['export', join(dir, 'rig.json'), '--format', 'opencv-yaml']).toString();
      assert.equal(pageYaml, cliYaml);
      assert.match(pageYaml, /^%YAML:1\.0/);
      // Kalibr's radtan has no k3: the page shows the core's refusal, as the CLI gives it.
      await page.click('#rig-export-kalibr');
      await page.waitForFunction(() => /^kalibr: /.test(document.getElementById('rig-export-status')?.textContent || ''), null, { timeout: 10000 });
      assert.equal(await page.textContent('#rig-export-status'), "kalibr: format: camera 'cam0': Kalibr's radtan model has no k3: calibrate with k3 fixed at 0 to export to Kalibr");
      await shot('exports');
      // Brown-Conrady with 2 radial terms (k3 held at 0, the control of step 3):
      // the page's solve is `robocal rig --fix k3`'s and exports to Kalibr's radtan.
      await page.click('#rig-lens-details summary');
      await page.selectOption('#rig-radial', '2');
      await page.$eval('#rig-results', (el) => el.replaceChildren());
      await page.click('#rig-solve');
      await page.locator('#rig-summary').waitFor({ timeout: 600000 });
      const held = await downloadedReport(page);
      const cliHeld = JSON.parse(execFileSync(CLI, ['rig', ...files.flatMap((f, k) => ['--camera', names[k], ...f]), '--target', 'chessboard:10x7:60mm', '--fix', 'k3'], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
      held.cameras.forEach((c, k) => {
        assert.equal(c.calibration.distortion.k3, 0, `${c.name} k3`);
        c.camera_from_rig.matrix_row_major.flat().forEach((x, i) => assert.ok(Math.abs(x - cliHeld.cameras[k].camera_from_rig.matrix_row_major.flat()[i]) <= 1e-9, `k3 held: ${c.name} entry ${i}: page ${x}, CLI`));
      });
      const [kalibr] = await Promise.all([page.waitForEvent('download'), page.click('#rig-export-kalibr')]);
      const pageKalibr = readFileSync(await kalibr.path(), 'utf8');
      writeFileSync(join(dir, 'rig_k3.json'), JSON.stringify(cliHeld));
      const cliKalibr = execFileSync(CLI, ['export', join(dir, 'rig_k3.json'), '--format', 'kalibr']).toString();
      const models = (y) => [...y.matchAll(/distortion_model: (\S+)/g)].map((m) => m[1]);
      const coeffs = (y) => [...y.matchAll(/distortion_coeffs: \[([^\]]*)\]/g)].map((m) => m[1].split(',').map(Number));
      assert.deepEqual(models(pageKalibr), ['radtan', 'radtan', 'radtan', 'radtan']);
      assert.deepEqual(models(cliKalibr), models(pageKalibr));
      const [pc, cc] = [coeffs(pageKalibr), coeffs(cliKalibr)];
      held.cameras.forEach((c, k) => {
        const d = c.calibration.distortion;
        // radtan is [k1, k2, p1, p2]: the page's file holds its report's numbers; the CLI's solve agrees to 1e-9 (wasm vs native libm).
        assert.deepEqual(pc[k], [d.k1, d.k2, d.p1, d.p2], `${c.name} radtan coefficients`);
        pc[k].forEach((x, i) => assert.ok(Math.abs(x - cc[k][i]) <= 1e-9, `${c.name} radtan[${i}]: page ${x}, CLI ${cc[k][i]}`));
      });
      assert.equal(await page.textContent('#rig-export-status'), 'kalibr: camchain.yaml');
      await shot('kalibr');
      await narrowShot(page, shot, 'narrow');
      console.log(`     rig: ${report.frames.length} frames, rms ${report.rms_px.toFixed(4)} px, worst extrinsic error ${worst.toFixed(2)} std`);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  }],
  ['four-camera rig without linking frames: the error names the two groups; a file without a number is named', async (page, { url, shot }) => {
    const { dir, truth, files } = renderRig(0);
    try {
      await page.goto(`${url}#stereo`);
      await ready(page);
      await setTarget(page, 10, 7, 60);
      await loadCameras(page, truth.cameras.map((c) => c.name), files);
      await page.click('#rig-solve');
      await page.locator('#rig-error').waitFor({ timeout: 600000 });
      await shot('disconnected');
      const error = await page.textContent('#rig-error');
      assert.match(error, /cameras are not connected by shared board views: \{cam0, cam1\} and \{cam2, cam3\}; add frames where a camera of each group sees the board/);
      // A file without a number cannot be put in a frame: the page names it.
      await page.setInputFiles('#rig-input-3', [{ name: 'extra.png', mimeType: 'image/png', buffer: readFileSync(files[3][0]) }]);
      await page.waitForFunction(() => /extra\.png/.test(document.querySelector('#rig-grouping.msg-error')?.textContent || ''), null, { timeout: 10000 });
      assert.equal(await page.textContent('#rig-grouping'), 'The images cannot be grouped into frames: images: frames are grouped by the last number in the file names, but camera cam3 has names without one: extra.png (group by number or last (the last number in the name, the default), first (the first number), order (the position in each camera\'s list), or a pattern with one (\\d+) such as sync(\\d+))');
      assert.equal(await page.isDisabled('#rig-solve'), true);
      // The other rules of robocal rig --group-by: by order every image has a
      // frame; a pattern no name has is named in the error.
      await page.selectOption('#rig-group-by', 'order');
      await page.waitForFunction(() => /grouped by order \(sorted names\)\.$/.test(document.getElementById('rig-grouping')?.textContent || ''), null, { timeout: 10000 });
      await page.selectOption('#rig-group-by', 'pattern');
      await page.fill('#rig-group-pattern', 'nothing(\\d+)');
      await page.dispatchEvent('#rig-group-pattern', 'change');
      await page.waitForFunction(() => /grouped by the number of the pattern nothing\(\\d\+\) in the file names, but camera cam0 has names without one/.test(document.querySelector('#rig-grouping.msg-error')?.textContent || ''), null, { timeout: 10000 });
      await page.selectOption('#rig-group-by', '');
      await page.waitForFunction(() => /extra\.png/.test(document.querySelector('#rig-grouping.msg-error')?.textContent || ''), null, { timeout: 10000 });
      await page.click('#rig-remove-3');
      await page.waitForFunction(() => /over 3 cameras/.test(document.getElementById('rig-grouping')?.textContent || ''), null, { timeout: 10000 });
      await shot('removed');
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  }],
  ['the rig on a robot: gripper_from_rig within 3 mm / 3 mrad of the truth, equal to robocal rig --setup eye-in-hand --poses to 1e-6', async (page, { url, shot }) => {
    const { dir, truth, files } = renderRig(3);
    try {
      const names = truth.cameras.map((c) => c.name);
      const { gripperFromRig, csv } = robotPoses(truth);
      const robotCsv = join(dir, 'robot.csv');
      writeFileSync(robotCsv, csv);
      await page.goto(`${url}#stereo`);
      await ready(page);
      await setTarget(page, 10, 7, 60);
      await loadCameras(page, names, files);
      await page.click('#rig-solve');
      await page.locator('#rig-summary').waitFor({ timeout: 600000 });
      // The rig on a robot: setup, the pose file (paired by the frame number of its image column), solve.
      await page.locator('#rig-robot').scrollIntoViewIfNeeded();
      await page.selectOption('#rig-robot-setup', 'eye-in-hand');
      await page.setInputFiles('#rig-robot-input', robotCsv);
      const frames = truth.frames.length;
      await page.waitForFunction((n) => (document.getElementById('rig-robot-poses')?.textContent || '').endsWith(`paired with the ${n} frames by the frame number of the image column.`), frames, { timeout: 20000 });
      assert.equal(await page.locator('#rig-robot-pairing-table tbody tr').count(), frames);
      assert.equal(await page.isDisabled('#rig-robot-solve'), false);
      await page.click('#rig-robot-solve');
      await page.locator('#rig-robot-summary').waitFor({ timeout: 600000 });
      await page.locator('#rig-robot-summary').scrollIntoViewIfNeeded();
      await shot('robot-solved');
      const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#rig-robot-export-json')]);
      assert.equal(dl.suggestedFilename(), 'rig_robot.json');
      const report = JSON.parse(readFileSync(await dl.path(), 'utf8'));
      const he = report.handeye;
      assert.equal(he.setup, 'eye-in-hand');
      assert.equal(he.frames.length, frames);
      const got = he.gripper_from_rig.matrix_row_major;
      // The truth: the rig is calibrated from the same renders, as in the CLI's test (3 mm, 3 mrad).
      const dt = Math.hypot(...[0, 1, 2].map((i) => got[i][3] - gripperFromRig[i][3]));
      const dr = Math.hypot(...logSmall(mulT(R3(got), R3(gripperFromRig))));
      assert.ok(dt < 3e-3 && dr < 3e-3, `gripper_from_rig off by ${dt} m, ${dr} rad`);
      // The CLI on the same files and poses: the same transform to 1e-6.
      const cli = JSON.parse(execFileSync(CLI, ['rig', ...files.flatMap((f, k) => ['--camera', names[k], ...f]), '--target', 'chessboard:10x7:60mm', '--setup', 'eye-in-hand', '--poses', robotCsv], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
      const want = cli.handeye.gripper_from_rig.matrix_row_major.flat();
      got.flat().forEach((x, i) => assert.ok(Math.abs(x - want[i]) <= 1e-6, `gripper_from_rig entry ${i}: page ${x}, CLI ${want[i]}`));
      ['translation_mm', 'rotation_deg'].forEach((k) => he.pose_refinement.camera_transform_std[k].forEach((v, i) => assert.ok(Math.abs(v - cli.handeye.pose_refinement.camera_transform_std[k][i]) <= 1e-6 * Math.max(1, v), `std ${k}[${i}]: page ${v}, CLI`)));
      assert.deepEqual(he.frames.map((f) => [f.key, f.used]), cli.handeye.frames.map((f) => [f.key, f.used]));
      // The page shows the report's numbers, its std and its warnings.
      const rows = await page.$$eval('#rig-robot-transform tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
      assert.deepEqual(rows[0], ['T (mm)', ...he.gripper_from_rig.translation_m.map((v) => (v * 1000).toFixed(3))]);
      assert.deepEqual(rows[1], ['std T (mm)', ...he.pose_refinement.camera_transform_std.translation_mm.map((v) => v.toFixed(3))]);
      assert.deepEqual(await page.$$eval('#rig-robot-results .msg-warning', (ps) => ps.map((p) => p.textContent)), he.warnings);
      assert.equal(await page.locator('#rig-robot-cameras tbody tr').count(), names.length);
      assert.equal(he.rig_uncertainty.included, true);
      assert.ok((await page.textContent('#rig-robot-uncertainty')).slice(1).startsWith(he.rig_uncertainty.note.slice(1)), he.rig_uncertainty.note);
      // An export of the rig with its hand-eye, as robocal export gives it.
      const [urdf] = await Promise.all([page.waitForEvent('download'), page.click('#rig-robot-export-urdf')]);
      writeFileSync(join(dir, 'rig_robot.json'), JSON.stringify(report));
      // (The same text but for the last digit of an angle: wasm's and the native libm's atan2.)
      const pageUrdf = readFileSync(await urdf.path(), 'utf8');
      const cliUrdf = execFileSync(CLI, ['export', join(dir, 'rig_robot.json'), '--format', 'urdf']).toString();
      const numbers = (t) => t.match(/-?\d+\.\d+(e-?\d+)?/g).map(Number);
      assert.equal(pageUrdf.replace(/-?\d+\.\d+(e-?\d+)?/g, '#'), cliUrdf.replace(/-?\d+\.\d+(e-?\d+)?/g, '#'));
      numbers(pageUrdf).forEach((x, i) => assert.ok(Math.abs(x - numbers(cliUrdf)[i]) <= 1e-12, `urdf number ${i}: page ${x}, CLI ${numbers(cliUrdf)[i]}`));
      // Kept in the session: after a reload the part shows the same result.
      const summary = await page.textContent('#rig-robot-summary');
      await page.waitForTimeout(500); // the store saves 300 ms after the last change
      await page.reload();
      await ready(page);
      await page.locator('#rig-robot-summary').waitFor({ timeout: 30000 });
      assert.equal(await page.textContent('#rig-robot-summary'), summary);
      assert.equal(await page.inputValue('#rig-robot-setup'), 'eye-in-hand');
      assert.equal(await page.isDisabled('#rig-robot-solve'), false);
      // A pose file that misses a frame: named, no solve.
      writeFileSync(robotCsv, csv.split('\n').filter((l, i) => i !== 2).join('\n'));
      await page.setInputFiles('#rig-robot-input', robotCsv);
      await page.locator('#rig-robot-pairing-error').waitFor({ timeout: 20000 });
      assert.match(await page.textContent('#rig-robot-pairing-error'), /^no robot pose for frame\(s\) \S+: give a pose for every frame, or leave those frames' images out$/);
      assert.equal(await page.isDisabled('#rig-robot-solve'), true);
      console.log(`     rig on a robot: gripper_from_rig ${(dt * 1000).toFixed(3)} mm, ${(dr * 1000).toFixed(3)} mrad from the truth`);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  }],
  ['held intrinsics: the drift warning names a camera; held from its own calibration or a camera file it is gone, the intrinsics exactly the held ones', async (page, { url, shot }) => {
    const { dir, truth, files } = renderRig(0);
    try {
      // cam0 and cam1 face the same frames: a pair. Every other image of
      // cam1 moved 6 px: its frames disagree with cam0's.
      const names = truth.cameras.slice(0, 2).map((c) => c.name);
      await page.goto(`${url}#stereo`);
      await ready(page);
      const moved = [];
      for (const [i, f] of files[1].entries()) {
        const out = join(dir, `moved_${f.split('/').pop()}`);
        writeFileSync(out, i % 2 ? await shiftedPng(page, readFileSync(f), 6) : readFileSync(f));
        moved.push(out);
      }
      const pair = [files[0], moved];
      await setTarget(page, 10, 7, 60);
      await loadCameras(page, names, pair);
      await page.click('#rig-solve');
      await page.locator('#rig-summary').waitFor({ timeout: 600000 });
      const first = await downloadedReport(page);
      const drifted = first.warnings.map((w) => DRIFT.exec(w)).filter(Boolean).map((m) => m[1]);
      assert.ok(drifted.length > 0, `no drift warning: ${first.warnings.join('\n')}`);
      const name = drifted[0];
      const k = names.indexOf(name);
      // The page names its per-camera control under the warning.
      assert.match(await page.textContent(`#rig-drift-hint-${k}`), new RegExp(`set camera ${k + 1} \\(${name}\\)'s intrinsics to "hold from its own calibration"`));
      await shot('drift');
      // Held from its own calibration (the warning's button): solved again.
      await page.$eval('#rig-summary', (el) => { el.id = 'rig-summary-before'; });
      await page.click(`#rig-hold-solo-${k}`);
      await page.locator('#rig-summary').waitFor({ timeout: 600000 });
      assert.equal(await page.inputValue(`#rig-intrinsics-${k}`), 'solo');
      const held = await downloadedReport(page);
      assert.ok(!held.warnings.some((w) => DRIFT.exec(w)?.[1] === name), held.warnings.join('\n'));
      assert.equal(held.cameras[k].intrinsics_held, true);
      const [saved] = await Promise.all([page.waitForEvent('download'), page.click(`#rig-solo-save-${k}`)]);
      const soloFile = join(dir, `${name}_calibration.json`);
      writeFileSync(soloFile, readFileSync(await saved.path()));
      const solo = JSON.parse(readFileSync(soloFile, 'utf8'));
      assert.deepEqual(held.cameras[k].calibration.camera, solo.camera);
      await shot('held-solo');
      // The same calibration as a camera file (robocal rig --camera-file NAME=FILE): the same rig, the CLI's too.
      await page.selectOption(`#rig-intrinsics-${k}`, 'file');
      await page.setInputFiles(`#rig-camera-file-${k}`, soloFile);
      await page.waitForFunction((k) => /^held from .*_calibration\.json \(json\): fx /.test(document.getElementById(`rig-held-${k}`)?.textContent || ''), k, { timeout: 10000 });
      await page.$eval('#rig-results', (el) => el.replaceChildren());
      await page.click('#rig-solve');
      await page.locator('#rig-summary').waitFor({ timeout: 600000 });
      const fromFile = await downloadedReport(page);
      assert.deepEqual(fromFile.cameras[k].calibration.camera, solo.camera);
      assert.ok(!fromFile.warnings.some((w) => DRIFT.exec(w)?.[1] === name), fromFile.warnings.join('\n'));
      const cli = JSON.parse(execFileSync(CLI, ['rig', ...pair.flatMap((f, j) => ['--camera', names[j], ...f]), '--target', 'chessboard:10x7:60mm', '--camera-file', `${name}=${soloFile}`], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
      fromFile.cameras.forEach((c, j) => c.camera_from_rig.matrix_row_major.flat().forEach((x, i) => assert.ok(Math.abs(x - cli.cameras[j].camera_from_rig.matrix_row_major.flat()[i]) <= 1e-9, `${c.name} entry ${i}: page ${x}, CLI`)));
      assert.deepEqual(cli.cameras[k].calibration.camera, solo.camera);
      // A file that is no camera: the core's words, nothing held.
      await page.setInputFiles(`#rig-camera-file-${k}`, { name: 'notes.txt', mimeType: 'text/plain', buffer: Buffer.from('hello\n') });
      await page.waitForFunction((k) => /^notes\.txt: not a camera file/.test(document.getElementById(`rig-held-${k}`)?.textContent || ''), k, { timeout: 10000 });
      await shot('held-file');
      console.log(`     held intrinsics: ${name} named (${drifted.join(', ')}), held from its own calibration and from a file`);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  }],
  ['OpenCV left/right as a 2-camera rig: the stereo right_from_left', async (page, { url, shot }) => {
    const dir = datasetDir('opencv-left-right-9x6');
    if (!dir) { console.log('     skipped: opencv-left-right-9x6 not found in ../shared/datasets or /work/shared/datasets'); return; }
    const side = (s) => readdirSync(dir).filter((f) => new RegExp(`^${s}\\d+\\.jpg$`).test(f)).sort().map((f) => join(dir, f));
    const [left, right] = [side('left'), side('right')];
    const stereo = JSON.parse(execFileSync(CLI, ['stereo', '--target', 'chessboard:9x6:30mm', '--left', ...left, '--right', ...right], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
    await page.goto(`${url}#stereo`);
    await ready(page);
    await loadCameras(page, ['left', 'right'], [left, right]);
    await page.click('#rig-solve');
    await page.locator('#rig-summary').waitFor({ timeout: 600000 });
    await shot('stereo-as-rig');
    const report = await downloadedReport(page);
    const got = report.cameras[1].camera_from_rig;
    // docs/rig.md: the 2-camera rig equals calibrate_stereo to 3e-16; 1e-9 covers wasm vs native libm.
    got.matrix_row_major.flat().forEach((x, i) => assert.ok(Math.abs(x - stereo.right_from_left.matrix_row_major.flat()[i]) <= 1e-9, `entry ${i}: rig ${x}, stereo`));
    assert.ok(Math.abs(report.rms_px - stereo.rms_px) <= 1e-9, `rms ${report.rms_px} vs ${stereo.rms_px}`);
    // Two cameras are a stereo pair: the stereo step's tables, kept over a reload.
    const pairText = `right_from_left: baseline ${(stereo.baseline_m * 1000).toFixed(4)} mm, RMS ${stereo.rms_px.toFixed(4)} px over 13 pairs`;
    assert.equal(await page.textContent('#stereo-summary'), pairText);
    // The pair in OpenCV's stereo file (K1 D1 K2 D2 R T E F, R1 R2 P1 P2 Q)
    // from the page = `robocal export` of robocal stereo's report, number by
    // number (1e-6 relative: the rig of two equals the stereo solve to 1e-9).
    const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#rig-export-stereo-opencv-yaml')]);
    assert.equal(dl.suggestedFilename(), 'stereo.opencv.yaml');
    const tmp = mkdtempSync(join(tmpdir(), 'robocal-stereo-e2e-'));
    try {
      writeFileSync(join(tmp, 'stereo.json'), JSON.stringify(stereo));
      const cliYaml = execFileSync(CLI, ['export', join(tmp, 'stereo.json'), '--format', 'opencv-yaml']).toString();
      const matrices = (text) => [...text.matchAll(/^(\w+): !!opencv-matrix[\s\S]*?data: \[ ([^\]]*) \]/gm)].map((m) => [m[1], m[2].split(',').map(Number)]);
      const [ours, theirs] = [matrices(readFileSync(await dl.path(), 'utf8')), matrices(cliYaml)];
      assert.deepEqual(ours.map(([k]) => k), ['K1', 'D1', 'K2', 'D2', 'R', 'T', 'E', 'F', 'R1', 'R2', 'P1', 'P2', 'Q']);
      assert.deepEqual(theirs.map(([k]) => k), ours.map(([k]) => k));
      ours.forEach(([k, a], m) => a.forEach((x, i) => {
        const y = theirs[m][1][i];
        assert.ok(Math.abs(x - y) <= 1e-6 * Math.max(1, Math.abs(y)), `${k}[${i}]: page ${x}, CLI ${y}`);
      }));
    } finally {
      rmSync(tmp, { recursive: true, force: true });
    }
    const tables = () => page.$$eval('#stereo-translation tbody tr, #stereo-rotation tbody tr, #stereo-cameras tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
    const shown = await tables();
    assert.deepEqual(shown[0], ['T (mm)', ...stereo.right_from_left.translation_m.map((v) => (v * 1000).toFixed(4))]);
    await page.waitForTimeout(500); // the store saves 300 ms after the last change
    await page.reload();
    await ready(page);
    await page.locator('#stereo-summary').waitFor({ timeout: 30000 });
    assert.equal(await page.textContent('#stereo-summary'), pairText);
    assert.deepEqual(await tables(), shown);
    await narrowShot(page, shot, 'stereo-narrow');
    // A session saved by the stereo step of an earlier version (its result is
    // `robocal stereo`'s report) opens on the rig step with that result, and
    // the export step still writes its right_from_left.
    const file0 = (side, i) => ({ id: `stereo-${side}-${i}`, name: `${side}0${i}.jpg`, detection: null, error: null, spec: 'chessboard:9x6:30mm' });
    const old = {
      kind: 'robocal-session', schema: 1, robocal_version: '0.1.0',
      session: {
        schema: 1, target: { kind: 'chessboard', cols: 9, rows: 6, square_m: 0.03 }, images: [],
        stereo: { model: 'brown', result: stereo, left: [file0('left', 1), file0('left', 2)], right: [file0('right', 1), file0('right', 2)] },
      },
    };
    const file = join(tmpdir(), `robocal-old-stereo-${process.pid}.json`);
    writeFileSync(file, JSON.stringify(old));
    try {
      page.on('dialog', (d) => d.accept());
      await page.click('#new-session');
      await page.waitForFunction(() => location.hash === '#target', null, { timeout: 10000 });
      await page.click('a[data-step=share]');
      await Promise.all([page.waitForEvent('load'), page.setInputFiles('#session-input', file)]);
    } finally {
      rmSync(file, { force: true });
    }
    await ready(page);
    await page.click('a[data-step=stereo]');
    await page.locator('#stereo-summary').waitFor({ timeout: 30000 });
    assert.equal(await page.textContent('#stereo-summary'), pairText);
    assert.match(await page.textContent('#stereo-results h3'), /earlier version/);
    assert.deepEqual(await page.$$eval('#rig-cameras input[type=text]', (els) => els.map((e) => e.value)), ['left', 'right']);
    await shot('old-stereo-session');
    await page.click('a[data-step=export]');
    await page.selectOption('#export-transform', 'right_from_left');
    await page.$eval('#export-status', (el) => { el.textContent = ''; });
    await page.click('#transform-formats button[data-format=matrix4]');
    await page.waitForFunction(() => /^matrix4: /.test(document.getElementById('export-status').textContent), null, { timeout: 10000 });
    const numbers = (await page.textContent('#export-preview')).match(/-?\d+(\.\d+)?(e[-+]?\d+)?/gi).map(Number).slice(-16);
    stereo.right_from_left.matrix_row_major.flat().forEach((x, i) => assert.ok(Math.abs(numbers[i] - x) <= 1e-12, `matrix4 entry ${i}: ${numbers[i]} vs ${x}`));
  }],
];
