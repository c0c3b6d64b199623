// Suite 'guidance' (was newcomer.mjs). Issue 23, first half: what a newcomer tripped over on the page. Images in
// natural order (numbered, movable, pairing follows), failed cards unticked,
// a remove button per card, a target change re-detecting and marking the
// result stale, "inner corners" in the labels and messages, a grid larger
// than the target, the demo over an open session, the outlier workflow
// (click a bar, exclude, solve again), the lens model as users know it, the
// model advice with its switch, the hand-eye modes with what each
// minimises, the closure chart showing the table's quantity, the wrong
// setup named and the joint refinement's intrinsic move warned about.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { root } from './harness.mjs';
import { makePng } from '../support/images.mjs';

const CLI = join(root, 'target/release/robocal');
const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
const png = (name, buffer) => ({ name, mimeType: 'image/png', buffer });
const text = (name, content) => ({ name, mimeType: 'text/plain', buffer: Buffer.from(content) });

/** The cards in page order as {name, order, meta, used}. */
const cards = (page) => page.$$eval('.card', (els) => els.map((el) => ({
  name: el.querySelector('.name').textContent, order: el.querySelector('.order').textContent,
  meta: el.querySelector('.meta').textContent, used: el.querySelector('.include input').checked,
})));

/** Wait until `n` cards are finished (error, warn, or with points) and nothing is detecting. */
const settled = (page, n) => page.waitForFunction((n) => {
  const all = [...document.querySelectorAll('.card')];
  return all.length === n && all.every((c) => /\b(error|warn)\b/.test(c.className) || / \d+ points/.test(c.querySelector('.meta').textContent))
    && ![...document.querySelectorAll('.card .meta')].some((m) => /detecting/.test(m.textContent));
}, n, { timeout: 90000 });

/** A 9x6 inner-corner chessboard (10x7 squares of 24 px) in a 312x240 white image, its top-left square at (x, y). */
function board({ x = 36, y = 36 } = {}) {
  const s = 24;
  return makePng(312, 240, (px, py) => {
    const [i, j] = [Math.floor((px - x) / s), Math.floor((py - y) / s)];
    const v = px >= x && py >= y && i < 10 && j < 7 && (i + j) % 2 === 0 ? 0 : 255;
    return [v, v, v];
  });
}

/** Files rendered by `robocal render ARGS` (PNG images and the text files), once per argument list. */
const rendered = new Map();
function render(args) {
  const key = args.join(' ');
  if (rendered.has(key)) return rendered.get(key);
  const dir = mkdtempSync(join(tmpdir(), 'robocal-newcomer-'));
  try {
    execFileSync(CLI, ['render', '--out', dir, ...args], { stdio: 'ignore' });
    const files = readdirSync(dir).sort();
    const out = {
      images: files.filter((f) => f.endsWith('.png')).map((f) => png(f, readFileSync(join(dir, f)))),
      text: Object.fromEntries(files.filter((f) => !f.endsWith('.png')).map((f) => [f, readFileSync(join(dir, f), 'utf8')])),
    };
    rendered.set(key, out);
    return out;
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

async function loadDemo(page) {
  await page.click('#demo-button');
  await page.waitForFunction(() => /^Demo loaded/.test(document.getElementById('engine-status').textContent)
    && /^12 files, 12 decoded, 12 with the target$/.test(document.getElementById('image-summary').textContent), null, { timeout: 180000 });
}

async function solveCamera(page) {
  await page.click('a[data-step=camera]');
  await page.$eval('#camera-results', (el) => el.replaceChildren());
  await page.click('#solve-camera');
  await page.waitForFunction(() => document.querySelector('#camera-params, #camera-results .msg-error'), null, { timeout: 90000 });
  const error = await page.$('#camera-results .msg-error');
  if (error) throw new Error(`camera: ${await error.textContent()}`);
}

async function solveHandeye(page) {
  await page.click('a[data-step=handeye]');
  await page.$eval('#handeye-results', (el) => el.replaceChildren());
  await page.click('#solve-handeye');
  await page.waitForFunction(() => document.querySelector('#handeye-errors, #handeye-results .msg-error'), null, { timeout: 90000 });
  const error = await page.$('#handeye-results .msg-error');
  return error ? error.textContent() : null;
}

const cell = (page, table, row, col) => page.$eval(table, (t, [row, col]) => {
  const tr = [...t.tBodies[0].rows].find((r) => r.cells[0].textContent === row);
  return tr ? tr.cells[col].textContent : null;
}, [row, col]);

export const tests = [
  ['images in natural order, numbered, movable and removable; pairing follows the order; a failed card is unticked', async (page, { url, shot }) => {
    await page.goto(`${url}#images`);
    await ready(page);
    // A file picker's order: im_10 first.
    await page.setInputFiles('#file-input', [png('im_10.png', board({ x: 40, y: 30 })), png('im_2.png', board()), png('broken.png', Buffer.from('not an image'))]);
    await settled(page, 3);
    let list = await cards(page);
    assert.deepEqual(list.map((c) => [c.order, c.name]), [['#1', 'broken.png'], ['#2', 'im_2.png'], ['#3', 'im_10.png']]);
    const broken = list[0];
    assert.equal(broken.used, false, 'a card that failed to decode is not ticked');
    assert.equal(broken.meta, 'not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP');
    assert.deepEqual(list.slice(1).map((c) => c.used), [true, true]);
    await shot('natural-order');
    // Robot poses without names pair with the images in this order.
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', text('poses.csv', 'x,y,z,qx,qy,qz,qw\n0.1,0.2,0.3,0,0,0,1\n0.2,0.2,0.3,0,0,0.1,0.995\n0.3,0.1,0.3,0.1,0,0,0.995\n'));
    await page.locator('#pairing-table').waitFor({ timeout: 20000 });
    const pairing = () => page.$$eval('#pairing-table tbody tr', (trs) => trs.map((tr) => [tr.cells[2].textContent, tr.cells[3].textContent]));
    assert.deepEqual(await pairing(), [
      ['broken.png', 'dropped: the image could not be read'], ['im_2.png', 'used'], ['im_10.png', 'used']]);
    // Remove the broken file, move im_10 first: the pairing follows.
    await page.click('a[data-step=images]');
    await page.click('button[aria-label="remove broken.png"]');
    await page.click('button[aria-label="move earlier: im_10.png"]');
    list = await cards(page);
    assert.deepEqual(list.map((c) => [c.order, c.name]), [['#1', 'im_10.png'], ['#2', 'im_2.png']]);
    await page.click('a[data-step=robot]');
    assert.deepEqual((await pairing()).slice(0, 2), [['im_10.png', 'used'], ['im_2.png', 'used']]);
    // Excluding a view keeps its pose: the others do not shift.
    await page.click('a[data-step=images]');
    await page.click('input[aria-label="use im_10.png in the calibration"]');
    await page.click('a[data-step=robot]');
    assert.deepEqual((await pairing()).slice(0, 2), [['im_10.png', 'dropped: the image is excluded in step 2'], ['im_2.png', 'used']]);
    await page.click('a[data-step=images]');
    await page.click('#sort-images');
    assert.deepEqual((await cards(page)).map((c) => c.name), ['im_2.png', 'im_10.png']);
    await shot('moved-and-sorted');
  }],

  ['target: inner-corner labels; squares counted said so; a change re-detects; a larger grid is used whole with a note', async (page, { url, shot }) => {
    await page.goto(`${url}#target`);
    await ready(page);
    const labels = () => page.$$eval('#target-form input[name=cols], #target-form input[name=rows]', (els) => els.map((e) => e.parentElement.firstChild.textContent.trim()));
    assert.deepEqual(await labels(), ['Inner corners across', 'Inner corners down']);
    assert.equal(await page.isVisible('#target-count-hint'), true);
    await page.selectOption('#target-kind', 'circle_grid');
    assert.deepEqual(await labels(), ['Circles across', 'Circles down']);
    assert.equal(await page.isVisible('#target-count-hint'), false);
    await page.selectOption('#target-kind', 'chessboard');
    await page.click('a[data-step=images]');
    await page.setInputFiles('#file-input', [png('board.png', board())]);
    await settled(page, 1);
    assert.match((await cards(page))[0].meta, / · 54 points$/);
    // The squares counted (10x7) instead of the inner corners: detected
    // again at once, and the message says what the spec counts.
    await page.click('a[data-step=target]');
    await page.fill('#target-form input[name=cols]', '10');
    await page.fill('#target-form input[name=rows]', '7');
    await page.waitForFunction(() => /^Target spec: chessboard:10x7:30mm/.test(document.getElementById('target-spec').textContent));
    await page.click('a[data-step=images]');
    await page.waitForFunction(() => /spec counts/.test(document.querySelector('.card .meta').textContent), null, { timeout: 30000 });
    let [card] = await cards(page);
    assert.ok(card.meta.endsWith('found 9x6 inner corners, not the 10x7 of the target: the spec counts inner corners (a board of 10x7 squares has 9x6): use chessboard:9x6:SIZE'), card.meta);
    assert.equal(card.used, false);
    await shot('squares-counted');
    // A target smaller than the board (8x6): the whole 9x6 grid is used, with a note.
    await page.click('a[data-step=target]');
    await page.fill('#target-form input[name=cols]', '8');
    await page.fill('#target-form input[name=rows]', '6');
    await page.click('a[data-step=images]');
    await page.waitForFunction(() => /more than the/.test(document.querySelector('.card .meta').textContent), null, { timeout: 30000 });
    [card] = await cards(page);
    assert.match(card.meta, / · 54 points · found 9x6 inner corners, more than the 8x6 of the target \(the board has more squares than the spec\): the whole grid is used for the camera calibration of this view; hand-eye leaves it out, because its point 0 need not be the same board corner as in the other views$/);
    assert.equal(card.used, true);
    await shot('larger-grid');
  }],

  ['demo over a session asks and starts anew; bar click excludes a view; k3 held; a target change marks the result stale; New session clears the demo note', async (page, { url, shot }) => {
    await page.goto(`${url}#images`);
    await ready(page);
    await page.setInputFiles('#file-input', [png('mine.png', board())]);
    await settled(page, 1);
    // Declined: nothing changes.
    let asked = null;
    page.once('dialog', (d) => { asked = d.message(); d.dismiss(); });
    await page.click('#demo-button');
    await page.waitForTimeout(300);
    assert.match(asked, /^Load the demo data\? It starts a new session/);
    assert.deepEqual((await cards(page)).map((c) => c.name), ['mine.png']);
    page.once('dialog', (d) => d.accept());
    await loadDemo(page);
    assert.ok(!(await cards(page)).some((c) => c.name === 'mine.png'), 'the demo is a session of its own');
    // The lens model as users know it; no "seed 000".
    await page.click('a[data-step=camera]');
    const models = await page.$$eval('#camera-model option', (os) => os.map((o) => o.textContent));
    assert.ok(models[0].startsWith('Brown-Conrady'), models[0]);
    assert.ok(models.some((m) => m.startsWith('Kannala-Brandt')), models.join(' | '));
    assert.ok(!models.some((m) => /seed/.test(m)), models.join(' | '));
    // The page keeps no list of its own: the camera and rig steps offer
    // exactly the core's table (the wasm call lens_models()), in its order.
    const table = await page.evaluate(async () => {
      const wasm = await import('./pkg/robocal.js');
      await wasm.default();
      return JSON.parse(wasm.lens_models()).map((m) => [m.name, m.description]);
    });
    assert.ok(table.length >= 7 && table[0][0] === 'brown', JSON.stringify(table));
    for (const select of ['#camera-model', '#rig-model']) {
      const offered = await page.$$eval(`${select} option`, (os) => os.map((o) => [o.value, o.textContent]));
      assert.deepEqual(offered, table, `${select} offers the core's lens models`);
    }
    await page.selectOption('#camera-radial', '2');
    await solveCamera(page);
    assert.equal(await cell(page, '#camera-params', 'k3', 1), '0.000000');
    assert.equal(await cell(page, '#camera-params', 'k3', 2), 'held');
    assert.notEqual(await cell(page, '#camera-params', 'p1', 2), 'held');
    await page.uncheck('#camera-form input[name=tangential]');
    await solveCamera(page);
    assert.equal(await cell(page, '#camera-params', 'p1', 2), 'held');
    assert.equal(await cell(page, '#camera-params', 'p2', 2), 'held');
    assert.match(await page.textContent('#camera-results h3'), /over 12 views$/);
    // Click the third bar of the per-view chart: that view is selected, then excluded and solved again.
    const [x, y] = await page.$eval('#plot-view-rms', (c) => {
      const w = c.width - 56 - 16; // the plot's left and right padding
      return [(56 + (2.5 * w) / 12) * (c.clientWidth / c.width), 0.8 * c.clientHeight];
    });
    await page.locator('#plot-view-rms').click({ position: { x, y } });
    assert.match(await page.textContent('#camera-view-selected'), /^View 3: demo_02\.png, reprojection RMS \S+ px/);
    await shot('view-selected');
    await page.click('#camera-exclude-view');
    await page.waitForFunction(() => /over 11 views$/.test(document.querySelector('#camera-results h3')?.textContent || ''), null, { timeout: 60000 });
    assert.equal(await page.isChecked('input[aria-label="use demo_02.png in the calibration"]'), false);
    // A target change: the result says it is stale, the images are detected again.
    // (8x6 for the demo's 9x6 board: every view is then a larger grid.)
    await page.click('a[data-step=target]');
    await page.fill('#target-form input[name=cols]', '8');
    await page.click('a[data-step=camera]');
    await page.waitForFunction(() => /^The target changed after this result was solved/.test(document.querySelector('#camera-results .msg-warning')?.textContent || ''), null, { timeout: 10000 });
    await shot('stale');
    await page.click('a[data-step=images]');
    await settled(page, 12);
    const metas = (await cards(page)).map((c) => c.meta);
    assert.equal(metas.filter((m) => / · 54 points · found 9x6 inner corners, more than the 8x6 of the target /.test(m)).length, 12, metas.join('\n'));
    // The camera uses the whole grids; hand-eye leaves them out and says why.
    await solveCamera(page);
    assert.equal(await page.$('#camera-results .msg-warning:text-matches("^The target changed")'), null);
    assert.match(await page.textContent('#camera-results h3'), /over 11 views$/);
    assert.match(await solveHandeye(page), /^requires at least 3 pose pairs, got 0/);
    assert.match(await page.textContent('#handeye-results .msg-info'), /^Left out of the hand-eye calibration: demo_00\.png, demo_01\.png, demo_03\.png, .*: the grid found there is larger than the target, so its point 0 \(the target's origin\) need not be the same board corner as in the other views/);
    await shot('handeye-left-out');
    // New session: the demo's note goes with it.
    page.once('dialog', (d) => d.accept());
    await page.click('#new-session');
    await page.waitForFunction(() => /^Calibration engine ready/.test(document.getElementById('engine-status').textContent), null, { timeout: 10000 });
    assert.match(await page.textContent('#image-summary'), /^0 files/);
  }],

  ['hand-eye: the wrong setup named, each mode explained with what it minimises, the per-pose chart = the table, the joint refinement warned', async (page, { url, shot }) => {
    await page.goto(url);
    await ready(page);
    await loadDemo(page);
    await solveCamera(page);
    // The demo is eye-in-hand: solved as eye-to-hand, the page names the setup that fits.
    await page.click('a[data-step=handeye]');
    await page.selectOption('#handeye-setup', 'eye-to-hand');
    const wrong = await solveHandeye(page);
    assert.ok(wrong && wrong.startsWith('robot poses: these poses fit eye-in-hand (the camera on the gripper), not the eye-to-hand chosen'), wrong);
    await page.selectOption('#handeye-setup', 'eye-in-hand');
    // Every mode in a sentence, and which to use.
    const help = async (mode) => { await page.selectOption('#handeye-refine', mode); return page.textContent('#handeye-refine-help'); };
    assert.match(await help('stochastic'), /^Minimises the reprojection error \(px\) plus a small correction per robot pose/);
    assert.match(await help('none'), /^Minimises the residuals of A X = Z B per pose/);
    assert.match(await help('ml'), /^Minimises the residuals of A X = Z B per pose, each camera pose weighted by its uncertainty from its detected points.*it is the default\.$/);
    assert.match(await help('trusted'), /^Minimises the reprojection error of every detected target point \(px\).*robot noise goes straight into the result\.$/);
    assert.equal(await solveHandeye(page), null);
    assert.match(await page.textContent('#handeye-measure'), /^This result: Minimises the reprojection error of every detected target point \(px\)/);
    assert.match(await page.textContent('#handeye-refinement'), /^Refined \(over the image points, robot poses exact\) from /);
    const columns = await page.$$eval('#handeye-methods thead th', (ths) => ths.map((t) => t.textContent));
    assert.deepEqual(columns.slice(0, 2), ['method', 'minimises']);
    assert.ok(columns.includes('reprojection RMS (px)'), columns.join(' | '));
    // Every closed form's reprojection RMS is shown and is not below the refined one (which minimises it).
    const refined = Number((await cell(page, '#handeye-errors', 'reprojection RMS', 1)).replace(' px', ''));
    const closed = await page.$$eval('#handeye-methods tbody tr', (trs) => trs.map((tr) => Number(tr.cells[7].textContent)));
    assert.ok(closed.length >= 6 && closed.every((v) => Number.isFinite(v) && v >= refined - 1e-4), `${refined} vs ${closed}`);
    // The chart is the table's quantity: closure per pose, one bar per pose.
    assert.equal(await page.getAttribute('#handeye-per-pose', 'aria-label'), 'closure residual per pose');
    await shot('handeye-modes');
    // Robot translations 3 % too long: the joint refinement lets fx absorb it, and says so.
    await page.click('a[data-step=robot]');
    const demoPoses = render(['--demo']).text['poses.csv'];
    const [head, ...rows] = demoPoses.trim().split('\n').map((l) => l.split(','));
    const xyz = ['x', 'y', 'z'].map((n) => head.indexOf(n));
    assert.ok(xyz.every((k) => k >= 0), head.join(','));
    const scaled = [head, ...rows.map((r) => r.map((v, k) => (xyz.includes(k) ? String(Number(v) * 1.03) : v)))].map((r) => r.join(',')).join('\n');
    await page.setInputFiles('#pose-input', text('scaled.csv', `${scaled}\n`));
    await page.waitForFunction(() => /^scaled\.csv: 12 poses/.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    await page.click('a[data-step=handeye]');
    await page.selectOption('#handeye-refine', 'joint_intrinsics');
    assert.equal(await solveHandeye(page), null);
    const warnings = await page.$$eval('#handeye-results .msg-warning', (els) => els.map((e) => e.textContent));
    const moved = warnings.find((w) => w.startsWith('the joint refinement moved the camera intrinsics far beyond their calibrated uncertainty: '));
    assert.ok(moved, warnings.join('\n'));
    assert.match(moved, /f[xy] from \S+ to \S+ px \(\d+ std\)/);
    await shot('joint-warning');
    // The convention check of an ambiguous pose file (six bare numbers a
    // line) with the wrong setup chosen: the setup is one of the candidates.
    await page.selectOption('#handeye-setup', 'eye-to-hand');
    await page.click('a[data-step=robot]');
    const bare = rows.map((r) => ['x', 'y', 'z', 'rx', 'ry', 'rz'].map((n) => r[head.indexOf(n)]).join(' ')).join('\n');
    await page.setInputFiles('#pose-input', text('bare.txt', `${bare}\n`));
    await page.locator('#check-conventions').waitFor({ timeout: 20000 });
    await page.click('#check-conventions');
    await page.locator('#convention-result table').waitFor({ timeout: 60000 });
    assert.match(await page.textContent('#convention-result .msg-info'), /^these poses fit eye-in-hand \(the camera on the gripper\), not the eye-to-hand chosen: .*choose the setup eye-in-hand, which solves gripper_from_camera/);
    await shot('convention-setup');
  }],

  ['lens model advice: too many parameters named with the model that fits, a fisheye through Brown-Conrady, each with a switch', async (page, { url, shot }) => {
    await page.goto(url);
    await ready(page);
    await loadDemo(page);
    await page.click('a[data-step=camera]');
    await page.selectOption('#camera-model', 'rational');
    await solveCamera(page);
    const advice = await page.$$eval('#camera-results .msg-warning', (els) => els.map((e) => e.textContent));
    const tooMany = advice.find((w) => w.startsWith('too many parameters for these views: the rational model'));
    assert.ok(tooMany, advice.join('\n'));
    const target = await page.getAttribute('#camera-results .switch-model', 'data-model');
    assert.ok(tooMany.includes(`(CLI: --model ${target})`), tooMany);
    await shot('too-many');
    await page.click('#camera-results .switch-model');
    await page.waitForFunction((m) => document.getElementById('camera-model').value === m && document.querySelector('#camera-params'), target, { timeout: 60000 });
    // A fisheye lens (Kannala-Brandt, fx 420 over 1280x960) under the default
    // Brown-Conrady: the residuals are far above detection noise; the advice
    // names the model that fits, by how much, and switches to it.
    const dir = mkdtempSync(join(tmpdir(), 'robocal-fisheye-'));
    const camera = join(dir, 'fisheye.json');
    writeFileSync(camera, JSON.stringify({ image_size_px: [1280, 960], camera_matrix: [[420, 0, 639], [0, 419.5, 481], [0, 0, 1]],
      model: 'kannala_brandt', distortion: { k1: 0.045, k2: -0.012, k3: 0.0021, k4: -0.0004 } }));
    let fisheye;
    try { fisheye = render(['--views', '10', '--camera', camera]); } finally { rmSync(dir, { recursive: true, force: true }); }
    page.once('dialog', (d) => d.accept());
    await page.click('#new-session');
    await page.waitForFunction(() => /^0 files/.test(document.getElementById('image-summary').textContent), null, { timeout: 10000 });
    await page.click('a[data-step=images]');
    await page.setInputFiles('#file-input', fisheye.images);
    await settled(page, 10);
    await page.click('a[data-step=camera]');
    assert.equal(await page.inputValue('#camera-model'), 'brown');
    await solveCamera(page);
    const rms = Number(/RMS (\S+) px/.exec(await page.textContent('#camera-results h3'))[1]);
    assert.ok(rms > 2, `Brown-Conrady on a fisheye: rms ${rms} px`);
    const far = (await page.$$eval('#camera-results .msg-warning', (els) => els.map((e) => e.textContent)))
      .find((w) => w.startsWith(`the residuals (rms ${rms.toFixed(3)} px) are far above detection noise: the Brown-Conrady model does not fit this lens; Kannala-Brandt (fisheye) fits the same views at `));
    assert.ok(far && /px \(\d+x lower\): switch the model to kannala_brandt \(CLI: --model kannala_brandt\)/.test(far), far);
    await shot('fisheye-advice');
    await page.click('#camera-results .switch-model[data-model=kannala_brandt]');
    await page.waitForFunction(() => document.getElementById('camera-model').value === 'kannala_brandt'
      && /RMS 0\.0\d+ px/.test(document.querySelector('#camera-results h3')?.textContent || ''), null, { timeout: 90000 });
    assert.match(await page.textContent('#camera-results h3'), /RMS 0\.0\d+ px over \d+ views$/);
  }],
];
