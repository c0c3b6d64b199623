// Issue 39 on the page: the check step (10. Check). A saved calibration
// file is loaded and checked against the live camera, Chromium's fake camera
// playing rendered views of the board through that very camera: the verdict
// shows (ok: the camera is the calibrated one), with the projection-shift
// heat map and the refitted parameters. A second file gives the projection
// difference of the two calibrations.
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { launch, newContext, shotsDir } from './harness.mjs';
import { boardVideo, cameraJson } from './y4m.mjs';

export const launchArgs = ['--use-fake-device-for-media-stream'];

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
const file = (name, value) => ({ name, mimeType: 'application/json', buffer: Buffer.from(JSON.stringify(value)) });

/** A text file for the file input. */
const textFile = (name, text) => ({ name, mimeType: 'text/plain', buffer: Buffer.from(text) });

export const tests = [
  ['every camera format robocal exports loads as the saved calibration: HALCON .dat and tuple, MATLAB, text; a damaged file names what is missing', async (page, { url }) => {
    await page.goto(`${url}#check`);
    await ready(page);
    await page.locator('#step-check').waitFor({ state: 'visible', timeout: 10000 });
    // The pickers take the files' extensions (.dat, .hdev.txt, .m, .txt, .cameramodel).
    const accept = await page.getAttribute('#check-file', 'accept');
    for (const ext of ['.dat', '.txt', '.m', '.cameramodel', '.json', '.yaml', '.xml']) assert.ok(accept.split(',').includes(ext), `${ext} in ${accept}`);
    const info = async (f) => {
      await page.$eval('#check-file-info', (el) => { el.textContent = ''; });
      await page.setInputFiles('#check-file', f);
      await page.waitForFunction(() => document.getElementById('check-file-info').textContent !== '', null, { timeout: 10000 });
      return page.textContent('#check-file-info');
    };
    // HALCON's write_cam_par: Focus 8 mm over 8.3 um pixels, fx = 963.9 px.
    const dat = 'ParGroup: Camera: Parameter;\n\t"Internal camera parameters";\n\nFocus:foc:\t0.008;\n\tDOUBLE:0.0:;\n\t"Focal length of the lens [meter]";\n\n'
      + 'Kappa:kappa:\t-2500;\nSx:sx:\t8.3e-06;\nSy:sy:\t8.3e-06;\nCx:cx:\t371.5;\nCy:cy:\t243.25;\nImageWidth:imgw:\t752;\nImageHeight:imgh:\t480;\n';
    assert.equal(await info(textFile('camera.dat', dat)), 'camera.dat (halcon): 752 × 480, fx 963.9, fy 963.9, cx 371.5, cy 243.3');
    assert.equal(await info(textFile('camera.hdev.txt', "CameraParam := ['area_scan_division', 0.008, -2500, 8.3e-06, 8.3e-06, 371.5, 243.25, 752, 480]\n")),
      'camera.hdev.txt (halcon): 752 × 480, fx 963.9, fy 963.9, cx 371.5, cy 243.3');
    const m = 'focalLength = [900.0, 901.0];\nprincipalPoint = [321.5, 241.5];\nimageSize = [480, 640];\nradialDistortion = [-0.1, 0.02];\ntangentialDistortion = [0.0, 0.0];\nskew = 0.0;\n';
    assert.equal(await info(textFile('camera.m', m)), 'camera.m (matlab): 640 × 480, fx 900.0, fy 901.0, cx 320.5, cy 240.5');
    assert.equal(await info(textFile('K.txt', '900 0 319.5\n0 900 239.5\n0 0 1\n# image_size_px: 640 480\n')), 'K.txt (text): 640 × 480, fx 900.0, fy 900.0, cx 319.5, cy 239.5');
    await page.setInputFiles('#check-file', textFile('broken.dat', dat.replace('Sx:sx:\t8.3e-06;\n', '')));
    await page.locator('#check-result .msg-error').waitFor({ timeout: 10000 });
    assert.equal(await page.textContent('#check-result .msg-error'),
      "broken.dat: the HALCON camera file (area_scan_division) has no Sx entry ('Sx:sx: <value>;'): the file is truncated or not from write_cam_par");
    assert.equal(await page.textContent('#check-file-info'), 'No calibration loaded.');
  }],
  ['live check: a saved calibration against the fake camera shows a verdict, the shift map and the parameters', async (page, { url }) => {
    const dir = mkdtempSync(join(tmpdir(), 'robocal-check-'));
    let other = { close: async () => {} };
    try {
      // Six tilted views of the page's default board (chessboard 9x6, 30 mm), each held 10 frames.
      const camera = cameraJson(640, 480);
      const { path } = await boardVideo(page, dir, { spec: 'chessboard:9x6:30mm', camera, views: 6, hold: 10, seed: 7 });
      other = await launch([...launchArgs, `--use-file-for-fake-video-capture=${path}`]);
      const p = await (await newContext(other)).newPage();
      const errors = [];
      p.on('pageerror', (e) => errors.push(e.message));
      await p.context().grantPermissions(['camera'], { origin: url });
      await p.goto(`${url}#check`);
      await ready(p);
      await p.locator('#step-check').waitFor({ state: 'visible', timeout: 10000 });
      assert.equal(await p.isDisabled('#check-camera'), true, 'nothing to check before a calibration is loaded');
      await p.setInputFiles('#check-file', file('camera.json', camera));
      await p.waitForFunction(() => /^camera\.json \(json\): 640 × 480, fx 576\.0/.test(document.getElementById('check-file-info').textContent), null, { timeout: 10000 });
      const t0 = Date.now();
      await p.click('#check-camera');
      await p.locator('#check-verdict').waitFor({ timeout: 90000 });
      const seconds = (Date.now() - t0) / 1000;
      const verdict = await p.getAttribute('#check-verdict', 'data-verdict');
      const reasons = await p.$$eval('#check-reasons li', (els) => els.map((e) => e.textContent));
      console.log(`     live check: ${verdict} in ${seconds.toFixed(1)} s ${reasons.join('; ')}`);
      assert.ok(['ok', 'drifted', 'broken'].includes(verdict), verdict);
      assert.equal(verdict, 'ok', `the calibrated camera itself: ${reasons.join('; ')}`);
      assert.match(await p.textContent('#check-verdict'), /^OK: the camera agrees with its saved calibration\.$/);
      assert.equal(await p.isVisible('#check-map'), true, 'the shift heat map');
      assert.equal(await p.$$eval('#check-params tbody tr', (rows) => rows.length), 4);
      assert.equal(await p.isHidden('#check-live'), true, 'the camera stops once the views are in');
      await p.screenshot({ path: join(shotsDir, 'check-live-verdict.png'), fullPage: true });
      // Another calibration (focal 2 % longer): the projection difference and its map.
      const f = 0.9 * 640 * 1.02;
      await p.setInputFiles('#check-other', file('longer.json', cameraJson(640, 480, { camera_matrix: [[f, 0, 319.5], [0, f, 239.5], [0, 0, 1]] })));
      await p.locator('#check-diff').waitFor({ timeout: 10000 });
      assert.match(await p.textContent('#check-diff'), /^camera\.json against longer\.json: projection shift worst \d+\.\d\d px at /);
      assert.equal(await p.isVisible('#check-diff-map'), true);
      assert.deepEqual(errors, []);
    } finally {
      await other.close();
      rmSync(dir, { recursive: true, force: true });
    }
  }],
];

tests.push(
  ['a report loaded as the saved calibration is read by its kind: a rig\'s or a stereo pair\'s camera, old reports without kind, a report without a camera named', async (page, { url }) => {
    await page.goto(`${url}#check`);
    await ready(page);
    await page.locator('#step-check').waitFor({ state: 'visible', timeout: 10000 });
    const info = async (f) => {
      await page.$eval('#check-file-info', (el) => { el.textContent = ''; });
      await page.$eval('#check-result', (el) => { el.textContent = ''; });
      await page.setInputFiles('#check-file', f);
      await page.waitForFunction(() => document.getElementById('check-file-info').textContent !== '', null, { timeout: 10000 });
      return page.textContent('#check-file-info');
    };
    const error = async () => page.textContent('#check-result .msg-error');
    // Camera reports as robocal writes them: kind and robocal_version (a camera JSON export has neither).
    const a = { kind: 'camera', robocal_version: '0.1.0', ...cameraJson(640, 480) };
    const b = { kind: 'camera', robocal_version: '0.1.0', ...cameraJson(800, 600) };
    assert.equal(await info(file('camera.json', a)), 'camera.json (json): 640 × 480, fx 576.0, fy 576.0, cx 319.5, cy 239.5');
    const { kind, ...old } = a;
    assert.equal(await info(file('old-camera.json', { ...old, crate_version: '0.0.9' })), 'old-camera.json (json): 640 × 480, fx 576.0, fy 576.0, cx 319.5, cy 239.5');
    // A rig report: its first camera (the rig step takes the camera of its own name).
    const pose = { translation_m: [0, 0, 0], quaternion_xyzw: [0, 0, 0, 1] };
    const rig = { kind: 'rig', robocal_version: '0.1.0', cameras: [{ name: 'top', calibration: b, camera_from_rig: pose }, { name: 'side', calibration: a, camera_from_rig: pose }], co_observation: [] };
    assert.equal(await info(file('rig.json', rig)), 'rig.json (json: camera top (the first of 2) of a rig report): 800 × 600, fx 720.0, fy 720.0, cx 399.5, cy 299.5');
    // The same rig written before kind: recognised by its keys, as robocal export does.
    const { kind: k2, ...oldRig } = rig;
    assert.equal(await info(file('old-rig.json', oldRig)), 'old-rig.json (json: camera top (the first of 2) of a rig report): 800 × 600, fx 720.0, fy 720.0, cx 399.5, cy 299.5');
    const stereo = { left: b, right: a, right_from_left: pose };
    assert.equal(await info(file('stereo.json', stereo)), 'stereo.json (json: the left camera of a stereo report): 800 × 600, fx 720.0, fy 720.0, cx 399.5, cy 299.5');
    assert.equal(await info(file('stereo-kind.json', { kind: 'stereo', ...stereo })), 'stereo-kind.json (json: the left camera of a stereo report): 800 × 600, fx 720.0, fy 720.0, cx 399.5, cy 299.5');
    // A check report holds no camera; an unknown kind names the kinds.
    assert.equal(await info(file('check.json', { kind: 'check', verdict: 'ok' })), 'No calibration loaded.');
    assert.equal(await error(), "check.json: a 'check' report compares a calibration with the camera and holds no camera: load the calibration itself");
    assert.equal(await info(file('mono.json', { ...a, kind: 'mono' })), 'No calibration loaded.');
    assert.equal(await error(),
      "mono.json: kind: unknown report kind 'mono' (expected one of camera, stereo, rig, handeye, rig_handeye, check, diff, laser_plane, laser_points)");
    // After a refusal a report loads again, and the check is ready for it.
    assert.equal(await info(file('rig.json', rig)), 'rig.json (json: camera top (the first of 2) of a rig report): 800 × 600, fx 720.0, fy 720.0, cx 399.5, cy 299.5');
    assert.equal(await page.isEnabled('#check-images'), true);
    // A report given as a session file: named by its kind, and where it loads.
    await page.evaluate(() => { location.hash = 'share'; });
    await page.setInputFiles('#session-input', file('rig.json', rig));
    await page.waitForFunction(() => document.getElementById('session-status').textContent !== '', null, { timeout: 10000 });
    assert.equal(await page.textContent('#session-status'),
      "rig.json: this file is a robocal 'rig' report, not a session file: a report loads where the page takes a camera file (the check step, a rig camera's intrinsics, the laser step)");
  }],
);
