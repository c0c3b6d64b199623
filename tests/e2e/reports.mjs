// Suite 'reports' (was newcomer2.mjs). Issue 23, second half: what a newcomer trips over in sharing, reports,
// reload, layout and keyboard use, the robust option's rejections and the
// frame names of the hand-eye exports. Each test asserts the fixed
// behaviour; the layout ones also save screenshots (looked at by hand).
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, writeFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { inflateRawSync } from 'node:zlib';
import { join } from 'node:path';
import { newContext, shotsDir } from './harness.mjs';
import { makePng } from '../support/images.mjs';

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 60000 });
const currentStep = (page) => page.$eval('#step-list a[aria-current]', (a) => a.dataset.step);
// The step `step` in the address and on screen: the page shows it on the
// hashchange event, a task after the address changes.
const shownStep = (page, step) => page.waitForFunction((s) => location.hash === `#${s}` && !document.getElementById(`step-${s}`).hidden, step);
const visibleStep = (page) => page.$$eval('section.step', (ss) => ss.filter((s) => !s.hidden).map((s) => s.id));

/** Demo loaded and detected, camera solved (optionally with the robust option), hand-eye solved. */
async function demoSolved(page, url, { robust = false } = {}) {
  await page.goto(url);
  await ready(page);
  await page.click('#demo-button');
  await page.waitForFunction(() => /12 with the target/.test(document.getElementById('image-summary').textContent)
    && !/in progress/.test(document.getElementById('image-summary').textContent), null, { timeout: 180000 });
  await page.click('a[data-step=camera]');
  if (robust) await page.check('#camera-form input[name=robust]');
  await page.click('#solve-camera');
  await page.locator('#camera-params').waitFor({ timeout: 60000 });
  await page.click('a[data-step=robot]');
  await page.locator('#pose-table').waitFor({ timeout: 20000 });
  await page.click('a[data-step=handeye]');
  await page.click('#solve-handeye');
  await page.locator('#handeye-errors').waitFor({ timeout: 120000 });
}

/** The text of a download triggered by clicking `selector`, and its suggested name. */
async function downloaded(page, selector) {
  const [dl] = await Promise.all([page.waitForEvent('download'), page.click(selector)]);
  const chunks = await (await dl.createReadStream()).toArray();
  return { name: dl.suggestedFilename(), text: Buffer.concat(chunks).toString('utf8') };
}

/** A white 640x360 image with a 10x7-square chessboard (9x6 inner corners, 24 px squares) at (60, 40). */
function boardPng() {
  return makePng(640, 360, (x, y) => {
    const [u, v] = [x - 60, y - 40];
    if (u < 0 || v < 0 || u >= 240 || v >= 168) return [255, 255, 255];
    const c = (Math.floor(u / 24) + Math.floor(v / 24)) % 2 ? 255 : 0;
    return [c, c, c];
  });
}

export const tests = [
  ['a new session opens on step 1; arrow keys move between the steps', async (page, { url, shot }) => {
    await page.goto(url);
    await ready(page);
    assert.equal(await currentStep(page), 'target');
    assert.deepEqual(await visibleStep(page), ['step-target']);
    await page.focus('#step-list a[data-step=target]');
    await page.keyboard.press('ArrowRight');
    await shownStep(page, 'images');
    assert.deepEqual(await visibleStep(page), ['step-images']);
    assert.equal(await page.evaluate(() => document.activeElement.dataset.step), 'images');
    await page.keyboard.press('ArrowRight');
    await shownStep(page, 'camera');
    await page.keyboard.press('ArrowLeft');
    await page.keyboard.press('ArrowLeft');
    await shownStep(page, 'target');
    // End: the last step, the laser-line sensor (step 11); before it the
    // field check of a saved calibration (step 10).
    await page.keyboard.press('End');
    await shownStep(page, 'laser');
    assert.deepEqual(await visibleStep(page), ['step-laser']);
    await page.keyboard.press('ArrowLeft');
    await shownStep(page, 'check');
    assert.deepEqual(await visibleStep(page), ['step-check']);
    await page.keyboard.press('ArrowLeft');
    await shownStep(page, 'share');
    assert.deepEqual(await visibleStep(page), ['step-share']);
    await shot('share-by-keys');
  }],
  ['keyboard: no invisible tab stops; the inspector keeps focus and Escape closes it', async (page, { url, shot }) => {
    await page.goto(`${url}#images`);
    await ready(page);
    await page.setInputFiles('#file-input', [{ name: 'board.png', mimeType: 'image/png', buffer: boardPng() }]);
    await page.waitForFunction(() => /1 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 30000 });
    // Every tab stop of the page is visible and has a size (the hidden file fields are not tab stops).
    const stops = [];
    await page.focus('body');
    for (let i = 0; i < 40; i++) {
      await page.keyboard.press('Tab');
      stops.push(await page.evaluate(() => {
        const e = document.activeElement;
        const r = e.getBoundingClientRect();
        const style = getComputedStyle(e);
        return { tag: e.tagName, id: e.id, type: e.type || '', w: r.width, h: r.height, visible: style.visibility !== 'hidden' && Number(style.opacity) > 0.05 };
      }));
    }
    const invisible = stops.filter((s) => s.tag !== 'BODY' && (s.w < 4 || s.h < 4 || !s.visible || s.type === 'file'));
    assert.deepEqual(invisible, [], 'invisible tab stops');
    assert.ok(stops.some((s) => s.id === 'choose-files') && stops.some((s) => s.id === 'choose-folder'), 'the two file buttons are tab stops');
    // The thumbnail opens the inspector with Enter; Tab and Shift+Tab stay inside it.
    await page.focus('.card canvas');
    await page.keyboard.press('Enter');
    await page.locator('#inspector[open]').waitFor({ timeout: 10000 });
    for (const key of ['Tab', 'Tab', 'Tab', 'Tab', 'Tab', 'Shift+Tab', 'Shift+Tab', 'Shift+Tab', 'Shift+Tab']) {
      await page.keyboard.press(key);
      assert.ok(await page.evaluate(() => document.getElementById('inspector').contains(document.activeElement)), `focus left the inspector after ${key}`);
    }
    await shot('inspector');
    await page.keyboard.press('Escape');
    await page.waitForFunction(() => !document.getElementById('inspector').open);
    assert.ok(await page.evaluate(() => document.activeElement.matches('.card canvas')), 'focus back on the thumbnail');
  }],
  ['the coverage map has the image\'s shape and a legend', async (page, { url, shot }) => {
    await page.goto(`${url}#images`);
    await ready(page);
    await page.setInputFiles('#file-input', [{ name: 'wide.png', mimeType: 'image/png', buffer: boardPng() }]);
    await page.waitForFunction(() => /1 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 30000 });
    // 640x360 (16:9): the map is 480x270, no dark band under the image.
    assert.deepEqual(await page.$eval('#coverage-canvas', (c) => [c.width, c.height]), [480, 270]);
    assert.match(await page.textContent('#coverage-legend'), /detected points, one colour per image .* where no point was found yet.* cells with points$/s);
    await page.locator('#coverage-canvas').scrollIntoViewIfNeeded();
    await shot('coverage');
  }],
  ['demo: robust rejections, frame names in the exports, the pose file named, 400 px layout', async (page, { url, shot }) => {
    await demoSolved(page, url, { robust: true });
    // A. How many points the robust option rejected, in which views, where.
    await page.click('a[data-step=camera]');
    const note = await page.textContent('#camera-rejected .msg');
    const m = /^robust loss: (\d+) of (\d+) points rejected \([\d.]+ %\), in (\d+) of 12 views: /.exec(note) || /^robust loss: no point rejected \(of (\d+)\)$/.exec(note);
    assert.ok(m, note);
    const rows = await page.$$eval('#camera-rejected-points tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
    if (/no point/.test(note)) assert.equal(rows.length, 0);
    else {
      assert.equal(rows.length, Number(m[1]));
      assert.equal(Number(m[2]), 12 * 54);
      assert.equal(new Set(rows.map((r) => r[0])).size, Number(m[3]));
      for (const r of rows) assert.match(r[2], /^\d+\.\d, \d+\.\d$/);
    }
    console.log(`     ${note.slice(0, 90)}`);
    // B. Frame names: defaults, editable, in every ROS/URDF export; URDF downloads as .urdf.
    await page.click('a[data-step=export]');
    assert.deepEqual(await page.$$eval('#frame-names input', (is) => is.map((i) => [i.id, i.value])),
      [['frame-base', 'base_link'], ['frame-gripper', 'tool0'], ['frame-camera', 'camera_optical_frame'], ['frame-target', 'calibration_target']]);
    await page.selectOption('#export-transform', 'gripper_from_camera');
    await page.click('#transform-formats button[data-format=ros1-static-tf]');
    await page.waitForFunction(() => /^ros1-static-tf: /.test(document.getElementById('export-status').textContent));
    assert.match(await page.textContent('#export-preview'), /^# gripper_from_camera \(ROS 1\): x y z \(m\) qx qy qz qw parent child\nrosrun tf2_ros static_transform_publisher (-?\d\S* ){7}tool0 camera_optical_frame\n$/);
    await page.fill('#frame-gripper', 'flange');
    await page.dispatchEvent('#frame-gripper', 'change');
    await page.waitForFunction(() => /flange camera_optical_frame/.test(document.getElementById('export-preview').textContent));
    await page.click('#transform-formats button[data-format=ros2-launch]');
    await page.waitForFunction(() => /'--frame-id', 'flange', '--child-frame-id', 'camera_optical_frame'/.test(document.getElementById('export-preview').textContent));
    await page.click('#transform-formats button[data-format=urdf-robot]');
    await page.waitForFunction(() => /<link name="flange"\/>/.test(document.getElementById('export-preview').textContent));
    const urdf = await downloaded(page, '#export-download');
    assert.equal(urdf.name, 'gripper_from_camera.urdf');
    assert.match(urdf.text, /^<\?xml version="1.0"\?>\n<robot name="robocal_calibration">\n  <link name="flange"\/>\n  <link name="camera_optical_frame"\/>\n  <joint name="flange_to_camera_optical_frame" type="fixed">/);
    // A name that would break the files is refused with the core's words.
    await page.fill('#frame-gripper', 'tool 0');
    await page.dispatchEvent('#frame-gripper', 'change');
    await page.waitForFunction(() => /is not a ROS frame name/.test(document.getElementById('export-status').textContent));
    await page.fill('#frame-gripper', 'tool0');
    await page.dispatchEvent('#frame-gripper', 'change');
    await shot('export-frames');
    // D. The pose file field names the loaded file (no "No file chosen").
    await page.click('a[data-step=robot]');
    assert.equal(await page.textContent('#pose-file-name'), 'loaded: demo_poses.csv');
    assert.equal(await page.isHidden('#pose-input'), true);
    // D. At 400 px wide, the camera, robot and hand-eye steps fit the screen.
    await page.setViewportSize({ width: 400, height: 800 });
    for (const step of ['target', 'images', 'camera', 'robot', 'handeye', 'export', 'share']) {
      await page.click(`a[data-step=${step}]`);
      await page.locator(`#step-${step}`).waitFor({ state: 'visible', timeout: 10000 });
      await page.waitForTimeout(200);
      const width = await page.evaluate(() => document.documentElement.scrollWidth);
      await shot(`narrow-${step}`);
      assert.ok(width <= 400, `${step} at 400 px: the page is ${width} px wide`);
    }
    // D. The 3-D view: large, zoom by buttons and keys, labels apart.
    await page.setViewportSize({ width: 1280, height: 900 });
    await page.click('a[data-step=handeye]');
    // The step changes on the hash change, a task after the click.
    await page.locator('#frames-3d').waitFor({ state: 'visible', timeout: 10000 });
    const size = await page.$eval('#frames-3d', (c) => [c.width, c.getBoundingClientRect().width]);
    assert.ok(size[0] >= 900 && size[1] >= 800, `3-D view ${size}`);
    const pixels = () => page.$eval('#frames-3d', (c) => c.toDataURL());
    const before = await pixels();
    await page.click('#frames-zoom-in');
    const zoomed = await pixels();
    assert.notEqual(zoomed, before, 'zoom in changed the view');
    await page.focus('#frames-3d');
    await page.keyboard.press('-');
    await page.keyboard.press('0');
    assert.equal(await pixels(), before, '0 resets the view');
    await page.locator('#frames-3d').scrollIntoViewIfNeeded();
    await shot('frames-3d');
  }],
  ['demo: a short share link, a session file that restores, a pasted link opens, a readable report, "restoring your session"', async (page, { url, shot, browser }) => {
    await demoSolved(page, url);
    await page.click('a[data-step=share]');
    await page.click('#make-share');
    await page.waitForFunction(() => document.getElementById('share-link').value.includes('#share='));
    const link = await page.inputValue('#share-link');
    const payload = JSON.parse(inflateRawSync(Buffer.from(link.split('#share=')[1], 'base64url')).toString('utf8'));
    const sizes = Object.fromEntries(['camera', 'handeye'].flatMap((k) => Object.entries(payload[k].result).map(([n, v]) => [`${k}.${n}`, JSON.stringify(v).length])));
    console.log(`     share link: ${link.length} characters (JSON ${JSON.stringify(payload).length} bytes)`);
    // Under 6,500 characters: far inside what browsers and servers take in a
    // URL (8 KB request lines), with the hand-eye's work-point error (its
    // verdict and advice, ~680 bytes of JSON) since session 21.
    assert.ok(link.length < 6500, `share link ${link.length} characters; JSON sizes ${JSON.stringify(sizes)}`);
    // What the link holds: the results, not the detections.
    assert.equal(payload.camera.result.views.length, 12);
    assert.equal(payload.camera.result.views[0].residuals_px, undefined);
    assert.ok(payload.handeye.result.gripper_from_camera.matrix_row_major, 'the transform');
    // The report: small, no inline JSON, the JSON as an attached download, std in significant digits.
    const report = await downloaded(page, '#download-report');
    console.log(`     HTML report: ${report.text.length} bytes`);
    assert.ok(report.text.length < 300 * 1024, `report ${report.text.length} bytes`);
    assert.ok(!/<pre/.test(report.text), 'no JSON printed inline');
    const dir = mkdtempSync(join(tmpdir(), 'robocal-newcomer-'));
    try {
      const reportPage = await page.context().newPage();
      await reportPage.setViewportSize({ width: 1000, height: 800 });
      await reportPage.setContent(report.text);
      const stds = await reportPage.$$eval('#report-params tbody tr', (trs) => trs.map((tr) => tr.cells[2].textContent));
      assert.ok(stds.length >= 9, stds.join());
      for (const s of stds) assert.ok(s === 'held' || !/^0\.0*$/.test(s), `std ${s}`);
      assert.equal(await reportPage.$$eval('#report-views tbody tr', (trs) => trs.length), 12);
      assert.ok(await reportPage.$$eval('img', (is) => is.length) >= 4, 'plots');
      const href = await reportPage.getAttribute('#results-json', 'href');
      const results = JSON.parse(Buffer.from(href.replace(/^data:application\/json;base64,/, ''), 'base64').toString('utf8'));
      assert.equal(results.kind, 'robocal-share');
      assert.ok(results.handeye.result.gripper_from_camera.translation_m, 'transform in the attached JSON');
      const height = await reportPage.evaluate(() => document.documentElement.scrollHeight);
      assert.ok(height < 8000, `report ${height} px tall`);
      await reportPage.screenshot({ path: join(shotsDir, 'reports-report.png'), fullPage: true });
      await reportPage.close();
      // The session file: detections (no image bytes); loading it restores the session.
      const session = await downloaded(page, '#download-session');
      const doc = JSON.parse(session.text);
      assert.equal(doc.kind, 'robocal-session');
      assert.equal(doc.session.images.length, 12);
      assert.equal(doc.session.images[0].detection.points.length, 54);
      const file = join(dir, 'robocal-session.json');
      writeFileSync(file, session.text);
      page.on('dialog', (d) => d.accept());
      await page.click('#new-session');
      await page.waitForFunction(() => location.hash === '#target' && document.getElementById('image-summary').textContent.startsWith('0 files'));
      await page.click('a[data-step=share]');
      await Promise.all([page.waitForEvent('load'), page.setInputFiles('#session-input', file)]);
      await ready(page);
      await page.locator('#camera-params').waitFor({ timeout: 30000 });
      assert.equal(await currentStep(page), 'camera');
      await page.waitForFunction(() => /^12 files/.test(document.getElementById('image-summary').textContent), null, { timeout: 30000 });
      assert.match(await page.textContent('.card .meta'), /from a session file/);
      // The detections solve again without the images.
      await page.click('#solve-camera');
      await page.waitForFunction(() => /over 12 views/.test(document.querySelector('#camera-results h3')?.textContent || ''), null, { timeout: 60000 });
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
    // Reload: "restoring your session" is said while the thumbnails decode.
    await page.click('a[data-step=images]');
    await page.waitForTimeout(500); // the store saves 300 ms after the last change
    await page.addInitScript(() => {
      window.__restoring = [];
      new MutationObserver(() => {
        const el = document.getElementById('restoring');
        if (el && !el.hidden && el.textContent) window.__restoring.push(el.textContent);
      }).observe(document, { subtree: true, childList: true, attributes: true, characterData: true });
    });
    await page.reload();
    await ready(page);
    await page.waitForFunction(() => document.getElementById('restoring').hidden, null, { timeout: 30000 });
    assert.ok((await page.evaluate(() => window.__restoring)).includes('Restoring your session (12 images)…'));
    // A share link pasted into this open tab opens it (only the fragment changes: no load without the hashchange).
    await page.evaluate((l) => { location.href = l; }, link);
    await page.locator('#readonly-banner:not([hidden])').waitFor({ timeout: 30000 });
    await page.locator('#camera-params').waitFor({ timeout: 20000 });
    assert.equal(await currentStep(page), 'camera');
    await shot('shared');
  }],
];

tests.push(
  ['the shared page shows what the link holds: residual plots from a sample, the hand-eye refinement over its views, the 3-D view of the robot poses', async (page, { url, shot, browser }) => {
    await demoSolved(page, url);
    const refinement = await page.textContent('#handeye-pose-refinement');
    assert.match(refinement, / over 12 views, /);
    const frames = await page.getAttribute('#frames-3d', 'data-frames');
    await page.click('a[data-step=share]');
    await page.click('#make-share');
    await page.waitForFunction(() => document.getElementById('share-link').value.includes('#share='));
    const link = await page.inputValue('#share-link');
    console.log(`     share link with the residual sample: ${link.length} characters`);
    assert.ok(link.length < 6500, `share link ${link.length} characters`);
    const payload = JSON.parse(inflateRawSync(Buffer.from(link.split('#share=')[1], 'base64url')).toString('utf8'));
    const sample = payload.camera.residualSample;
    assert.equal(sample.total, 12 * 54);
    assert.equal(sample.counts.length, 12);
    const kept = sample.counts.reduce((n, c) => n + c, 0);
    const total = sample.total;
    assert.equal(Buffer.from(sample.data, 'base64').length, 4 * kept);
    assert.ok(kept >= 30 && kept <= 240, `${kept} residuals in the link`);
    console.log(`     residuals in the link: ${kept} of ${total}`);
    assert.equal(payload.handeye.robotPoses.length, 8);
    const shared = await (await newContext(browser)).newPage();
    const errors = [];
    shared.on('pageerror', (e) => errors.push(e.message));
    await shared.goto(link);
    await shared.locator('#readonly-banner:not([hidden])').waitFor({ timeout: 20000 });
    await shared.locator('#camera-params').waitFor({ timeout: 20000 });
    // The residual plots draw the sample, and say it is one.
    assert.match(await shared.textContent('#camera-results h3'), / over 12 views$/);
    assert.equal(await shared.getAttribute('#plot-residuals', 'data-count'), String(kept));
    assert.equal(await shared.getAttribute('#plot-vectors', 'data-count'), String(kept));
    assert.equal(await shared.textContent('#camera-residual-sample'),
      `The residual plots show a sample of ${kept} of the ${total} points (a share link carries a sample; the session file holds them all).`);
    await shared.screenshot({ path: join(shotsDir, 'reports-shared-camera.png'), fullPage: true });
    // The hand-eye: its refinement over as many views as on the page, the 3-D view with the robot poses.
    await shared.click('a[data-step=handeye]');
    await shared.locator('#handeye-pose-refinement').waitFor({ timeout: 20000 });
    assert.equal(await shared.textContent('#handeye-pose-refinement'), refinement);
    assert.equal(await shared.getAttribute('#frames-3d', 'data-frames'), frames);
    assert.equal(frames, String(1 + 8 + 2), 'base, 8 grippers, camera and target');
    await shared.locator('#frames-3d').scrollIntoViewIfNeeded();
    await shared.screenshot({ path: join(shotsDir, 'reports-shared-3d.png'), fullPage: true });
    assert.deepEqual(errors, []);
    await shared.context().close();
    await shot('shared-link');
  }],
);
