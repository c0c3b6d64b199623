// Camera and robot pages on the demo data: the distortion field really
// draws, the undistorted preview comes back from the core, and the
// convention check names the right reading of a pose file written in a
// convention the file's layout does not reveal.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { root } from './harness.mjs';
import { makePng, checker } from '../support/images.mjs';

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });

async function demoSolved(page, url) {
  await page.goto(url);
  await ready(page);
  await page.click('#demo-button');
  await page.waitForFunction(() => /12 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 180000 });
  await page.click('a[data-step=camera]');
  await page.click('#solve-camera');
  await page.locator('#camera-params').waitFor({ timeout: 60000 });
}

/** Pixels of a canvas by kind: strongly red (plot vectors), not white, and the mean grey. */
export const canvasStats = (page, sel) => page.$eval(sel, (c) => {
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let red = 0, nonWhite = 0, sum = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (d[i] > 150 && d[i + 1] < 90 && d[i + 2] < 90) red++;
    if (d[i] < 240 || d[i + 1] < 240 || d[i + 2] < 240) nonWhite++;
    sum += d[i];
  }
  return { width: c.width, height: c.height, red, nonWhite, mean: sum / (d.length / 4) };
});

/** Mean absolute grey difference of two same-size canvases. */
const canvasDiff = (page, a, b) => page.evaluate(([a, b]) => {
  const get = (s) => { const c = document.querySelector(s); return c.getContext('2d').getImageData(0, 0, c.width, c.height).data; };
  const [x, y] = [get(a), get(b)];
  if (x.length !== y.length) return null;
  let s = 0;
  for (let i = 0; i < x.length; i += 4) s += Math.abs(x[i] - y[i]);
  return s / (x.length / 4);
}, [a, b]);

/** 3x3 rotation from a rotation vector (radians). */
function rotvecMatrix([x, y, z]) {
  const t = Math.hypot(x, y, z);
  if (t < 1e-15) return [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  const [kx, ky, kz] = [x / t, y / t, z / t];
  const c = Math.cos(t), s = Math.sin(t), v = 1 - c;
  return [
    [c + kx * kx * v, kx * ky * v - kz * s, kx * kz * v + ky * s],
    [ky * kx * v + kz * s, c + ky * ky * v, ky * kz * v - kx * s],
    [kz * kx * v - ky * s, kz * ky * v + kx * s, c + kz * kz * v],
  ];
}

/** Angles a, b, c (deg) of R = Rz(a) Ry(b) Rx(c) (KUKA A B C; FANUC R P W). */
function zyxAngles(R) {
  const deg = 180 / Math.PI;
  const B = Math.atan2(-R[2][0], Math.hypot(R[0][0], R[1][0]));
  const A = Math.atan2(R[1][0], R[0][0]);
  const C = Math.atan2(R[2][1], R[2][2]);
  return [A * deg, B * deg, C * deg];
}

export const tests = [
  ['stereo & rig page: two cameras grouped into frames by the number in the names, a frame seen by one camera kept, refuses fewer than 3 frames, kept over a reload', async (page, { url, shot }) => {
    await page.goto(`${url}#stereo`);
    await ready(page);
    assert.equal(await page.isDisabled('#rig-solve'), true);
    const png = (name) => ({ name, mimeType: 'image/png', buffer: makePng(40, 30, checker(5)) });
    await page.setInputFiles('#rig-input-0', [png('cam_L_2.png'), png('cam_L_10.png')]);
    await page.waitForFunction(() => /^2 frames over 2 cameras/.test(document.getElementById('rig-grouping')?.textContent || ''), null, { timeout: 10000 });
    assert.equal(await page.textContent('#rig-missing'), 'Add images for camera cam1 to solve.');
    assert.equal(await page.textContent('#rig-too-few'), 'A rig calibration needs at least 3 frames: add 1 more frame (an image of each camera, numbered alike) to solve.');
    assert.equal(await page.isDisabled('#rig-solve'), true);
    // The core's rule (robocal::io::pairing, as robocal rig): left n with right
    // n, in numeric order; a camera may miss a frame (cam_R_7 has no left image).
    await page.setInputFiles('#rig-input-1', [png('cam_R_10.png'), png('cam_R_2.png'), png('cam_R_7.png')]);
    await page.waitForFunction(() => /^3 frames over 2 cameras, grouped by the number in the file names\.$/.test(document.getElementById('rig-grouping')?.textContent || ''), null, { timeout: 10000 });
    const cells = () => page.$$eval('#rig-frame-table tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
    assert.deepEqual(await cells(), [['2', 'cam_L_2.png: not detected yet', 'cam_R_2.png: not detected yet'], ['7', '—', 'cam_R_7.png: not detected yet'], ['10', 'cam_L_10.png: not detected yet', 'cam_R_10.png: not detected yet']]);
    assert.equal(await page.$('#rig-too-few'), null);
    assert.equal(await page.isDisabled('#rig-solve'), false);
    await page.setInputFiles('#rig-input-0', [png('cam_L_7.png')]);
    await page.waitForFunction(() => document.getElementById('rig-count-0')?.textContent === '3 images', null, { timeout: 10000 });
    await page.waitForFunction(() => document.querySelectorAll('#rig-frame-table tbody tr')[1]?.cells[1].textContent === 'cam_L_7.png: not detected yet', null, { timeout: 10000 });
    // Without a chessboard in the images, the solve says why instead of hanging (the CLI's words).
    await page.click('#rig-solve');
    await page.locator('#rig-error').waitFor({ timeout: 30000 });
    assert.equal(await page.textContent('#rig-error'), 'the target was found in no image of camera cam0');
    await shot('pairs');
    // The images and their detection results survive a reload.
    const before = await cells();
    assert.match(before[0][1], /^cam_L_2\.png: not found: .*(chessboard|target|found)/i);
    await page.waitForTimeout(500); // the store saves 300 ms after the last change
    await page.reload();
    await ready(page);
    await page.waitForFunction(() => /^3 frames/.test(document.getElementById('rig-grouping')?.textContent || ''), null, { timeout: 10000 });
    assert.deepEqual(await cells(), before);
    await page.click('#rig-clear');
    await page.waitForFunction(() => !document.getElementById('rig-frame-table'), null, { timeout: 10000 });
    assert.equal(await page.isDisabled('#rig-solve'), true);
  }],
  ['camera page: distortion field drawn, undistorted preview', async (page, { url, shot }) => {
    await demoSolved(page, url);
    // The demo lens has barrel distortion: the field's red vectors cover pixels.
    const field = await canvasStats(page, '#plot-distortion');
    assert.ok(field.red > 300, `distortion field: ${JSON.stringify(field)}`);
    const blank = await page.evaluate(() => { const c = document.createElement('canvas'); c.width = 460; c.height = 340; return c.toDataURL(); });
    assert.notEqual(await page.$eval('#plot-distortion', (c) => c.toDataURL()), blank);
    const options = await page.$$eval('#undistort-image option', (os) => os.map((o) => o.textContent));
    assert.equal(options.length, 12);
    await page.selectOption('#undistort-image', { label: options[3] });
    await page.click('#undistort-show');
    await page.waitForFunction(() => /undistorted at/.test(document.getElementById('undistort-status').textContent), null, { timeout: 30000 });
    assert.equal(await page.textContent('#undistort-status'), `${options[3]}: undistorted at 480×360 px (preview).`);
    const before = await canvasStats(page, '#undistort-before');
    const after = await canvasStats(page, '#undistort-after');
    assert.deepEqual([before.width, before.height, after.width, after.height], [480, 360, 480, 360]);
    // Same scene, resampled: similar brightness, but not the same pixels.
    assert.ok(Math.abs(before.mean - after.mean) < 40, `mean grey ${before.mean} vs ${after.mean}`);
    const diff = await canvasDiff(page, '#undistort-before', '#undistort-after');
    assert.ok(diff > 2, `undistortion changed nothing (mean difference ${diff})`);
    await page.locator('#undistort-after').scrollIntoViewIfNeeded();
    await shot('undistorted');
    // All methods side by side on the demo's flat board: the DLT cannot apply
    // and is left out, with the core's note said once under the table.
    await page.selectOption('#camera-method', 'all');
    await page.click('#solve-camera');
    await page.locator('#camera-methods-note').waitFor({ timeout: 120000 });
    const methods = await page.$$eval('#camera-methods tbody tr', (trs) => trs.map((tr) => tr.cells[0].textContent));
    assert.deepEqual(methods, ['zhang', 'tsai', 'ekf']);
    assert.equal(await page.textContent('#camera-methods-note'), 'dlt left out: the 12-parameter DLT needs target points off one plane (a 3-D target or XY-table positions), and every view here is a flat board');
  }],
  ['robot page: the convention check names the right reading', async (page, { url, shot }) => {
    // The demo's poses (UR: metres, rotation vectors), rewritten as a bare
    // FANUC file (X Y Z W P R, mm and degrees, R = Rz(R) Ry(P) Rx(W), no
    // header): six numbers a line fit several vendors' conventions, and the
    // most plausible reading of the layout is not FANUC's.
    const dir = mkdtempSync(join(tmpdir(), 'robocal-demo-'));
    let text;
    try {
      execFileSync(join(root, 'target/release/robocal'), ['render', '--out', dir, '--demo'], { stdio: 'ignore' });
      text = readFileSync(join(dir, 'poses.csv'), 'utf8');
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
    const [head, ...rows] = text.trim().split('\n').map((l) => l.split(','));
    const col = (n) => head.indexOf(n);
    assert.ok(['x', 'y', 'z', 'rx', 'ry', 'rz'].every((n) => col(n) >= 0), head.join(','));
    const fanuc = rows.map((r) => {
      const v = (n) => Number(r[col(n)]);
      const [a, b, c] = zyxAngles(rotvecMatrix([v('rx'), v('ry'), v('rz')]));
      return [v('x') * 1000, v('y') * 1000, v('z') * 1000, c, b, a].map((x) => x.toFixed(4)).join(' ');
    }).join('\n') + '\n';
    await demoSolved(page, url);
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', { name: 'poses_fanuc.txt', mimeType: 'text/plain', buffer: Buffer.from(fanuc) });
    await page.locator('#check-conventions').waitFor({ timeout: 20000 });
    const picked = (await page.$eval('#pose-candidate', (s) => s.options[s.selectedIndex].textContent)).split(' — ')[0];
    assert.notEqual(picked, 'fanuc, mm, deg');
    await page.click('#check-conventions');
    await page.locator('#convention-result table').waitFor({ timeout: 60000 });
    await shot('conventions');
    const recommendation = await page.textContent('#convention-result .msg-info');
    assert.match(recommendation, /^pose format 'fanuc, mm, deg' fits the camera motion best \(rotation RMS (\S+) deg/);
    const best = await page.$$eval('#convention-result tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
    assert.equal(best[0][0], 'fanuc, mm, deg');
    // The demo's robot poses are exact and its corners good to ~0.05 px: the
    // right reading fits to well under a degree and a millimetre. Euler
    // orders that permute the axes fit the rotations as well (see
    // rank_pose_candidates) but miss the translations by the lever arms.
    const [rot, trans] = [Number(best[0][1]), Number(best[0][2])];
    assert.ok(rot < 0.5 && trans < 1, JSON.stringify(best.slice(0, 3)));
    assert.ok(best.slice(1).every((r) => Number(r[1]) > 5 * rot || Number(r[2]) > 50 * trans), JSON.stringify(best.slice(0, 3)));
    console.log(`     convention check: the file's default reading was '${picked}'; the check names '${best[0][0]}' (rotation RMS ${best[0][1]} deg, next '${best[1][0]}' ${best[1][1]} deg)`);
  }],
  ['every control has an accessible name, every canvas a text alternative', async (page, { url, shot }) => {
    await demoSolved(page, url);
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-errors').waitFor({ timeout: 60000 });
    await page.click('a[data-step=export]');
    // Every step's DOM is built (hidden steps too): check them all at once.
    const problems = await page.evaluate(() => {
      const name = (el) => {
        if (el.getAttribute('aria-label')) return el.getAttribute('aria-label');
        const by = el.getAttribute('aria-labelledby');
        if (by) return by.split(/\s+/).map((id) => document.getElementById(id)?.textContent || '').join(' ').trim();
        if (el.labels && el.labels.length) return [...el.labels].map((l) => l.textContent).join(' ').trim();
        if (el.tagName === 'BUTTON' || el.tagName === 'A') return el.textContent.trim();
        return '';
      };
      const out = [];
      for (const el of document.querySelectorAll('input, select, textarea, button, a[href]')) {
        if (el.type === 'hidden') continue;
        if (!name(el)) out.push(`${el.tagName.toLowerCase()}#${el.id || '?'}.${el.className || ''} has no accessible name`);
      }
      for (const c of document.querySelectorAll('canvas')) {
        if (c.getAttribute('role') !== 'img' || !c.getAttribute('aria-label')) out.push(`canvas#${c.id || '?'} lacks role=img with an aria-label`);
      }
      return out;
    });
    assert.deepEqual(problems, []);
    // Keyboard: the step links are reachable with Tab from the top of the page.
    await page.goto(`${url}#camera`);
    await ready(page);
    const reached = new Set();
    for (let i = 0; i < 30; i++) {
      await page.keyboard.press('Tab');
      const step = await page.evaluate(() => document.activeElement?.dataset?.step || null);
      if (step) reached.add(step);
    }
    assert.deepEqual([...reached].sort(), ['camera', 'check', 'export', 'handeye', 'images', 'laser', 'robot', 'share', 'stereo', 'target', 'workflows']);
    await page.keyboard.press('Shift+Tab');
    await shot('keyboard');
  }],
];

/** The demo session as `robocal render --demo` writes it: its images ([{name, mimeType, buffer}]) and poses.csv's text. */
function renderedDemo() {
  const dir = mkdtempSync(join(tmpdir(), 'robocal-demo-'));
  try {
    execFileSync(join(root, 'target/release/robocal'), ['render', '--out', dir, '--demo'], { stdio: 'ignore' });
    const images = readdirSync(dir).filter((n) => n.endsWith('.png')).sort()
      .map((name) => ({ name, mimeType: 'image/png', buffer: readFileSync(join(dir, name)) }));
    return { images, poses: readFileSync(join(dir, 'poses.csv'), 'utf8') };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

/** Rotation vector (rad) -> quaternion [x, y, z, w]. */
function quaternionOf([x, y, z]) {
  const angle = Math.hypot(x, y, z);
  const s = angle < 1e-12 ? 0.5 : Math.sin(angle / 2) / angle;
  return [x * s, y * s, z * s, Math.cos(angle / 2)];
}

/** Drop `files` ([{name, text}]) on the element `selector` as a user's drag and drop would: dragover, then drop. Returns whether the zone was outlined during the drag. */
const dropFiles = (page, selector, files) => page.evaluate(([selector, files]) => {
  const dt = new DataTransfer();
  for (const f of files) dt.items.add(new File([f.text], f.name, { type: 'text/plain' }));
  const el = document.querySelector(selector);
  el.dispatchEvent(new DragEvent('dragover', { dataTransfer: dt, bubbles: true, cancelable: true }));
  const outlined = document.getElementById('step-robot').classList.contains('over');
  el.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
  return outlined;
}, [selector, files]);

tests.push(
  ['a reload during detection loses no image, and detection resumes for the images not yet detected', async (page, { url, shot }) => {
    const { images } = renderedDemo();
    // Two copies of the demo's 12 images: detection takes a few seconds.
    const files = [...images, ...images.map((f) => ({ ...f, name: f.name.replace('demo_', 'again_') }))];
    const n = files.length;
    await page.goto(`${url}#images`);
    await ready(page);
    // After the reload, before the page starts: what this browser's storage held.
    await page.addInitScript(() => {
      const req = indexedDB.open('robocal');
      req.onsuccess = () => {
        const db = req.result;
        const get = db.transaction('session').objectStore('session').get('current');
        get.onsuccess = () => {
          const images = (get.result && get.result.images) || [];
          window.__saved = { images: images.length, detected: images.filter((i) => i.detection).length };
          db.close();
        };
      };
    });
    await page.setInputFiles('#file-input', files);
    // The first image detected: reload at once, the others still to do.
    await page.waitForFunction(() => /\b[1-9]\d* with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 120000 });
    await page.reload();
    await ready(page);
    await page.waitForFunction(() => window.__saved, null, { timeout: 10000 });
    const saved = await page.evaluate(() => window.__saved);
    assert.equal(saved.images, n, 'every image added before the reload was kept');
    assert.ok(saved.detected < n, `the reload came during detection (${saved.detected} of ${n} detected)`);
    // Detection goes on for the rest, without a click.
    await page.waitForFunction((n) => document.getElementById('image-summary').textContent === `${n} files, ${n} decoded, ${n} with the target`
      && document.getElementById('progress-row').hidden, n, { timeout: 180000 });
    const metas = await page.$$eval('.card .meta', (ms) => ms.map((m) => m.textContent));
    assert.equal(metas.length, n);
    for (const m of metas) assert.match(m, /54 points/);
    await shot('resumed');
  }],
  ['pose files dropped on the robot step are read as if chosen: several one-pose files at once, one pose table', async (page, { url, shot }) => {
    const { poses } = renderedDemo();
    const [head, ...rows] = poses.trim().split('\n').map((l) => l.split(','));
    const col = (name) => head.indexOf(name);
    // One ROS pose YAML per image, named by the image's stem.
    const yaml = rows.map((r) => {
      const v = (k) => Number(r[col(k)]);
      const [qx, qy, qz, qw] = quaternionOf([v('rx'), v('ry'), v('rz')]);
      return { name: r[col('name')].replace('.png', '.yaml'), text: `position: {x: ${v('x')}, y: ${v('y')}, z: ${v('z')}}\norientation: {x: ${qx}, y: ${qy}, z: ${qz}, w: ${qw}}\n` };
    });
    await page.goto(`${url}#robot`);
    await ready(page);
    await page.locator('#pose-form').waitFor({ timeout: 10000 });
    const read = () => page.$$eval('#pose-table tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent).join(' ')));
    // The file picker first: what a drop must give.
    await page.setInputFiles('#pose-input', yaml.map((f) => ({ name: f.name, mimeType: 'text/plain', buffer: Buffer.from(f.text) })));
    await page.locator('#pose-table').waitFor({ timeout: 20000 });
    const chosen = { how: await page.textContent('#pose-format-used'), rows: await read() };
    assert.match(chosen.how, /^12 pose files: 12 poses read as /);
    assert.equal(chosen.rows.length, 12);
    // A pose table dropped on the step's text.
    assert.equal(await dropFiles(page, '#robot-title', [{ name: 'poses.csv', text: poses }]), true, 'the step is outlined while files are dragged over it');
    await page.waitForFunction(() => /^poses\.csv: 12 poses read as /.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    assert.equal(await page.textContent('#pose-file-name'), 'loaded: poses.csv');
    assert.equal(await page.$eval('#step-robot', (s) => s.classList.contains('over')), false);
    // The one-pose files dropped together: the same reading as chosen with the picker.
    await dropFiles(page, '#pose-form', yaml);
    await page.waitForFunction(() => /^12 pose files: /.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    assert.equal(await page.textContent('#pose-format-used'), chosen.how);
    assert.deepEqual(await read(), chosen.rows);
    assert.equal(await page.textContent('#pose-file-name'), 'loaded: 12 pose files');
    await shot('dropped');
  }],
);
