// The whole flow on the demo data: load, detect, solve the camera, read the
// robot poses, solve the hand-eye, export every format, share a link that
// opens read-only with the same numbers, and reload to find the session;
// then plan robot poses for hand-eye from one demo view (docs/pose-plan.md):
// the plan back after a reload, in a share link, and a flange box no pose
// fits refused in the CLI's words.
// Ground truth is the demo scene's (src/synth/demo.rs): fx = fy = 900 px,
// cx 511.5, cy 383.5, gripper_from_camera translation (30, -20, 100) mm.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, writeFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { inflateRawSync } from 'node:zlib';
import { newContext, root } from './harness.mjs';

const CLI = join(root, 'target/release/robocal');

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
const cellValue = async (page, table, name) => Number(await page.$eval(`${table} tbody`, (tb, n) => {
  const row = [...tb.rows].find((r) => r.cells[0].textContent === n);
  return row ? row.cells[1].textContent : 'NaN';
}, name));

export const tests = [
  ['demo data from load to share', async (page, { url, shot, browser }) => {
    await page.goto(url);
    await ready(page);
    const t0 = Date.now();
    await page.click('#demo-button');
    await page.waitForFunction(() => /12 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 120000 });
    const detectMs = Date.now() - t0;
    await shot('images');
    await page.click('a[data-step=camera]');
    const t1 = Date.now();
    await page.click('#solve-camera');
    await page.locator('#camera-params').waitFor({ timeout: 60000 });
    const solveMs = Date.now() - t1;
    console.log(`     demo: render + decode + detect 12 images ${detectMs} ms, camera solve ${solveMs} ms`);
    await shot('camera');
    // Rendered with noise sigma 2 grey levels and blur: corners to ~0.05 px,
    // so the intrinsics land within a pixel of the truth.
    const fx = await cellValue(page, '#camera-params', 'fx');
    const cx = await cellValue(page, '#camera-params', 'cx');
    assert.ok(Math.abs(fx - 900) < 1.5, `fx ${fx}`);
    assert.ok(Math.abs(cx - 511.5) < 1.5, `cx ${cx}`);
    await page.click('a[data-step=robot]');
    await page.locator('#pose-table').waitFor({ timeout: 20000 });
    assert.match(await page.textContent('#pose-format-used'), /12 poses read as ur, lengths in m/);
    assert.match(await page.textContent('#pose-pairing'), /Paired by the name column: 12 pairs usable/);
    await shot('robot');
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-errors').waitFor({ timeout: 60000 });
    await shot('handeye');
    const text = await page.textContent('#handeye-results');
    const m = /gripper_from_camera: translation (\S+), (\S+), (\S+) mm/.exec(text);
    assert.ok(m, text.slice(0, 300));
    const t = m.slice(1, 4).map(Number);
    [30, -20, 100].forEach((want, i) => assert.ok(Math.abs(t[i] - want) < 2, `gripper_from_camera ${t} mm`));
    // The default: maximum likelihood over the poses, each camera pose
    // weighted by its PnP covariance from the detected points.
    assert.match(await page.textContent('#handeye-pose-refinement'), /^Refined over the poses from \S+ \(maximum likelihood; estimated robot noise /);
    // Its reprojection RMS: every corner through the refined transforms and its
    // robot pose (the demo's robot poses are exact: about the corner noise x sqrt 2).
    const rmsText = await page.$eval('#handeye-errors tbody', (tb) => [...tb.rows].find((r) => r.cells[0].textContent === 'reprojection RMS').cells[1].textContent);
    const rms = Number(rmsText.replace(' px', ''));
    assert.ok(rms > 0 && rms < 0.2, `reprojection RMS ${rmsText}`);
    assert.match(await page.textContent('#handeye-pose-refinement'), /Reprojection RMS \S+ px \(closed form \S+ px\) over \d+ views, each view's points projected through the refined transforms and its robot pose\.$/);
    assert.match(await page.textContent('#handeye-measure'), /^This result: Minimises the residuals of A X = Z B per pose, each camera pose weighted by its uncertainty from its detected points/);
    console.log(`     demo hand-eye (refined): gripper_from_camera ${t.join(', ')} mm (truth 30, -20, 100), reprojection RMS ${rmsText}`);
    // Every export format comes back from the core without an error.
    await page.click('a[data-step=export]');
    for (const sel of ['#camera-formats button', '#transform-formats button']) {
      const buttons = await page.$$(sel);
      assert.ok(buttons.length >= 9, sel);
      for (const b of buttons) {
        const format = await b.getAttribute('data-format');
        // Clear the status first, so the wait sees this format's answer, not the last one's.
        await page.$eval('#export-status', (el) => { el.textContent = ''; });
        await b.click();
        await page.waitForFunction(() => document.getElementById('export-status').textContent !== '', null, { timeout: 10000 });
        const status = await page.textContent('#export-status');
        // Kalibr refuses k3 != 0 with a reason: that is the one allowed refusal.
        if (format === 'kalibr' && /no k3/.test(status)) continue;
        assert.match(status, new RegExp(`^${format}: \\d+ bytes`), `${format}: ${status}`);
      }
    }
    await shot('export');
    await page.click('a[data-step=share]');
    await page.click('#make-share');
    await page.waitForFunction(() => document.getElementById('share-link').value.includes('#share='), null, { timeout: 10000 });
    const link = await page.inputValue('#share-link');
    const shared = await (await newContext(browser, { viewport: { width: 1280, height: 720 } })).newPage();
    await shared.goto(link);
    await shared.locator('#readonly-banner:not([hidden])').waitFor({ timeout: 20000 });
    await shared.locator('#camera-params').waitFor({ timeout: 20000 });
    assert.equal(await cellValue(shared, '#camera-params', 'fx'), fx);
    await shared.screenshot({ path: 'tests/e2e/screenshots/flow-shared.png', fullPage: true });
    await shared.context().close();
    // Reload: the session (images, detections, results) is intact.
    await page.waitForTimeout(500);
    await page.reload();
    await ready(page);
    await page.waitForFunction(() => /12 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 60000 });
    await page.click('a[data-step=camera]');
    assert.equal(await cellValue(page, '#camera-params', 'fx'), fx);
    await shot('reloaded');
  }],
  ['plan robot poses for hand-eye on the demo', async (page, { url, shot, browser }) => {
    await page.goto(url);
    await ready(page);
    await page.click('#demo-button');
    await page.waitForFunction(() => /12 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 120000 });
    await page.click('a[data-step=camera]');
    await page.click('#solve-camera');
    await page.locator('#camera-params').waitFor({ timeout: 60000 });
    await page.click('a[data-step=robot]');
    await page.locator('#pose-table').waitFor({ timeout: 20000 });
    await page.click('a[data-step=handeye]');
    // The rough hand-eye transform: the solved one.
    await page.click('#solve-handeye');
    await page.locator('#handeye-errors').waitFor({ timeout: 60000 });
    // The current view: the first paired image, its robot pose prefilled as x,y,z,qx,qy,qz,qw (m).
    await page.waitForFunction(() => document.getElementById('plan-view').options.length === 12, null, { timeout: 10000 });
    const now = await page.inputValue('#plan-robot-pose');
    assert.equal(now.split(',').length, 7, now);
    const N = 9;
    await page.fill('#plan-count', String(N));
    await page.fill('#plan-max-tilt', '35');
    await page.click('#plan-run');
    await page.waitForFunction(() => document.querySelector('#plan-poses, #plan-results .msg-error'), null, { timeout: 120000 });
    assert.equal(await page.$('#plan-results .msg-error'), null, await page.textContent('#plan-results'));
    assert.equal(await page.$$eval('#plan-poses tbody tr', (rows) => rows.length), N);
    const predicted = await page.textContent('#plan-predicted');
    const bound = Number(/work point: (\S+) mm \(95 %\)/.exec(predicted)[1]);
    assert.ok(bound > 0 && bound < 10, predicted);
    // The 3-D view: the flange frames drawn (coloured pixels on the light
    // background). draw3d is async (it asks the engine for the frames): wait
    // for the drawing, which once lagged the table under load.
    // The count when over `min`, else 0 (falsy: waitForFunction polls on).
    const colouredOver = (min) => {
      const c = document.getElementById('plan-3d');
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - d[i + 1]) > 40 || Math.abs(d[i + 1] - d[i + 2]) > 40) n++;
      return n > min ? n : 0;
    };
    await page.waitForFunction(colouredOver, 500, { timeout: 30000 }).catch(() => {});
    const drawn = await page.evaluate(colouredOver, -1);
    assert.ok(drawn > 500, `coloured pixels in the 3-D view: ${drawn}`);
    // The UR script: one movel per pose.
    await page.waitForFunction(() => /^ur-script: \d+ bytes/.test(document.getElementById('plan-move-status').textContent), null, { timeout: 10000 });
    const script = await page.textContent('#plan-move-list');
    assert.equal(script.split('\n').filter((l) => l.trim().startsWith('movel(p[')).length, N, script.slice(0, 300));
    // Another format: the KUKA KRL program, one LIN per pose.
    await page.selectOption('#plan-format', 'kuka-krl');
    await page.waitForFunction(() => /^kuka-krl: \d+ bytes/.test(document.getElementById('plan-move-status').textContent), null, { timeout: 10000 });
    const krl = await page.textContent('#plan-move-list');
    assert.equal(krl.split('\n').filter((l) => l.trim().startsWith('LIN ')).length, N, krl.slice(0, 300));
    console.log(`     demo plan: ${N} poses, ${predicted}`);
    await shot('plan');
    // The plan is kept in the session: after a reload its inputs and its poses are back.
    const rows = () => page.$$eval('#plan-poses tbody tr', (trs) => trs.map((r) => r.textContent));
    const planned = await rows();
    await page.waitForTimeout(500); // the session is saved 300 ms after a change
    await page.reload();
    await ready(page);
    await page.click('a[data-step=handeye]');
    await page.locator('#plan-poses').waitFor({ timeout: 60000 });
    assert.deepEqual(await rows(), planned);
    assert.equal(await page.textContent('#plan-predicted'), predicted);
    assert.equal(await page.inputValue('#plan-count'), String(N));
    assert.equal(await page.inputValue('#plan-max-tilt'), '35');
    await page.waitForFunction(() => document.getElementById('plan-view').options.length === 12, null, { timeout: 20000 });
    assert.equal(await page.inputValue('#plan-robot-pose'), now);
    await page.waitForFunction(() => /^ur-script: \d+ bytes/.test(document.getElementById('plan-move-status').textContent), null, { timeout: 10000 });
    await shot('plan-reloaded');
    // A share link carries the plan, inside the link budget (tests/e2e/reports.mjs);
    // the shared page shows it read-only.
    await page.click('a[data-step=share]');
    await page.click('#make-share');
    await page.waitForFunction(() => document.getElementById('share-link').value.includes('#share='), null, { timeout: 10000 });
    const link = await page.inputValue('#share-link');
    const payload = JSON.parse(inflateRawSync(Buffer.from(link.split('#share=')[1], 'base64url')).toString('utf8'));
    assert.equal(payload.plan.result.poses.length, N);
    // The link without a plan keeps its 6,500 characters (tests/e2e/reports.mjs);
    // the plan's poses add about 600, still far inside an 8 KB request line.
    assert.ok(link.length < 7000, `share link with the plan: ${link.length} characters`);
    console.log(`     share link with the plan: ${link.length} characters`);
    const shared = await (await newContext(browser, { viewport: { width: 1280, height: 720 } })).newPage();
    await shared.goto(link);
    await shared.locator('#readonly-banner:not([hidden])').waitFor({ timeout: 20000 });
    await shared.click('a[data-step=handeye]');
    await shared.locator('#plan-poses').waitFor({ timeout: 20000 });
    assert.equal(await shared.$$eval('#plan-poses tbody tr', (trs) => trs.length), N);
    assert.equal(await shared.textContent('#plan-predicted'), predicted);
    await shared.context().close();
    // A flange box that no candidate pose fits: the core's words, the same as the CLI's.
    await page.click('a[data-step=handeye]');
    for (const [k, v] of Object.entries({ x0: 5000, y0: 5000, z0: 5000, x1: 5001, y1: 5001, z1: 5001 })) await page.fill(`#plan-box-${k}`, String(v));
    await page.click('#plan-run');
    await page.locator('#plan-results .msg-error').waitFor({ timeout: 120000 });
    const refused = await page.textContent('#plan-results .msg-error');
    const dir = mkdtempSync(join(tmpdir(), 'robocal-plan-'));
    try {
      const file = (name, text) => { writeFileSync(join(dir, name), text); return join(dir, name); };
      const camera = file('camera.json', JSON.stringify({ model: 'none', image_size_px: [1024, 768], camera_matrix: [[900, 0, 511.5], [0, 900, 383.5], [0, 0, 1]], distortion: {} }));
      const view = file('view.txt', '1,0,0,-0.12,0,1,0,-0.075,0,0,1,0.6,0,0,0,1\n');
      const robot = file('now.csv', 'x,y,z,qx,qy,qz,qw\n0.4,0,0.5,1,0,0,0\n');
      const cli = spawnSync(CLI, ['plan', '--setup', 'eye-in-hand', '--robot-pose', robot, '--pose-format', 'xyz_quat_xyzw', '--pose-units', 'm', '--camera', camera,
        '--target', 'chessboard:9x6:30mm', '--camera-pose', view, '--poses', String(N), '--flange-box', '5000,5000,5000,5001,5001,5001mm'], { encoding: 'utf8' });
      assert.equal(cli.status, 1, cli.stderr);
      assert.equal(refused, cli.stderr.trim().replace(/^robocal: /, ''));
      assert.match(refused, /^only 0 candidate poses keep the whole target in view within the limits, 9 wanted: /);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
    // That refusal is saved too: the last plan's inputs, without a result.
    await shot('plan-box-refused');
  }],
];
