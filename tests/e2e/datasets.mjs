// The public data set (OpenCV's left01..left14.jpg, 9x6 chessboard, 30 mm
// squares per its SOURCE.md) through the page: upload, detect, solve, and the
// displayed numbers equal the CLI's for the same images (same Rust core, so
// equal up to the page's display rounding). Plus a timing benchmark on 20
// rendered 1280x960 images (printed, not a pass/fail timer).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, readdirSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { root } from './harness.mjs';

const CLI = join(root, 'target/release/robocal');
const SPEC = 'chessboard:9x6:30mm';

/** ../shared/datasets beside the checkout (CI), else /work/shared/datasets; null when absent. */
export function datasetDir(name) {
  for (const base of [join(root, '..', 'shared', 'datasets'), '/work/shared/datasets']) {
    const dir = join(base, name);
    if (existsSync(dir)) return dir;
  }
  return null;
}

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });

/** The value column of the row named `name` in a parameter table, as shown. */
export const shownCell = (page, table, name) => page.$eval(`${table} tbody`, (tb, n) => {
  const row = [...tb.rows].find((r) => r.cells[0].textContent === n);
  return row ? row.cells[1].textContent : null;
}, name);

/**
 * The page prints 6 decimals (num(x, 6)), or 6 significant digits in
 * exponent form below 1e-4: the CLI's exact value must round to what is
 * shown. 1e-9 relative (and 1e-12 absolute, for components near 0) on top
 * covers wasm-vs-native libm differences in the last bits (the solver
 * converges to the same optimum). `slack`: what a solve's own stopping
 * precision adds where page and CLI run their own solve (the products'
 * sums differ in their last bits natively and in wasm, so each stops at
 * its own point within the stopping rule of a relative cost decrease of
 * 1e-12, about 1e-4 of the parameter's std with a few thousand residuals).
 */
export function assertShown(shown, exact, what, decimals = 6, slack = 0) {
  assert.ok(shown !== null, `${what}: not shown`);
  const x = Number(shown);
  const rounding = /e/.test(shown) ? 0.5 * 10 ** (1 - decimals) * Math.abs(exact) : 0.5 * 10 ** -decimals;
  const tol = rounding * 1.0001 + 1e-9 * Math.abs(exact) + 1e-12 + slack;
  assert.ok(Math.abs(x - exact) <= tol, `${what}: page ${shown}, CLI ${exact} (tolerance ${tol.toExponential(2)})`);
}

/** Upload files through the page's file input and wait until all are detected. */
export async function uploadAndDetect(page, files, timeout = 300000) {
  await page.setInputFiles('#file-input', files);
  const n = files.length;
  await page.waitForFunction((k) => document.getElementById('progress-text').textContent === `detected ${k} of ${k}`, n, { timeout });
}

async function setTarget(page, cols, rows, sizeMm) {
  await page.click('a[data-step=target]');
  await page.selectOption('#target-kind', 'chessboard');
  await page.fill('input[name=cols]', String(cols));
  await page.fill('input[name=rows]', String(rows));
  await page.fill('input[name=square_mm]', String(sizeMm));
  // The spec line is written after the core has checked the new fields (a
  // round trip to the worker): wait for it rather than read it at once.
  const want = `^Target spec: chessboard:${cols}x${rows}:${sizeMm}mm`;
  await page.waitForFunction((re) => new RegExp(re).test(document.getElementById('target-spec').textContent), want, { timeout: 20000 });
}

async function solveCamera(page) {
  await page.click('a[data-step=camera]');
  await page.click('#solve-camera');
  await page.locator('#camera-params').waitFor({ timeout: 120000 });
}

/** Largest RMS distance of the board's rows and columns of corners from their fitted straight lines, px. */
export function worstLineRms(points, cols, rows) {
  const byId = new Map(points.map((p) => [p.id, p]));
  const lines = [];
  for (let r = 0; r < rows; r++) lines.push([...Array(cols).keys()].map((c) => byId.get(r * cols + c)));
  for (let c = 0; c < cols; c++) lines.push([...Array(rows).keys()].map((r) => byId.get(r * cols + c)));
  let worst = 0;
  for (const line of lines) {
    const pts = line.filter(Boolean);
    if (pts.length < 3) continue;
    const mx = pts.reduce((s, p) => s + p.x_px, 0) / pts.length;
    const my = pts.reduce((s, p) => s + p.y_px, 0) / pts.length;
    let a = 0, b = 0, c = 0;
    for (const p of pts) { a += (p.x_px - mx) ** 2; b += (p.x_px - mx) * (p.y_px - my); c += (p.y_px - my) ** 2; }
    [a, b, c] = [a / pts.length, b / pts.length, c / pts.length];
    const smallest = (a + c) / 2 - Math.sqrt(((a - c) / 2) ** 2 + b * b);
    worst = Math.max(worst, Math.sqrt(Math.max(0, smallest)));
  }
  return worst;
}

const detectFile = (file, spec) => JSON.parse(execFileSync(CLI, ['detect', '--target', spec, file], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString()).images[0].detection;

const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];

export const tests = [
  ['OpenCV left images: page equals CLI', async (page, { url, shot }) => {
    const dir = datasetDir('opencv-left-right-9x6');
    if (!dir) { console.log('     skipped: opencv-left-right-9x6 not found in ../shared/datasets or /work/shared/datasets'); return; }
    const files = readdirSync(dir).filter((f) => /^left\d+\.jpg$/.test(f)).sort().map((f) => join(dir, f));
    assert.equal(files.length, 13);
    const cli = JSON.parse(execFileSync(CLI, ['intrinsics', '--target', SPEC, ...files], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
    await page.goto(url);
    await ready(page);
    await setTarget(page, 9, 6, 30);
    await page.click('a[data-step=images]');
    await uploadAndDetect(page, files);
    await shot('images');
    assert.match(await page.textContent('#image-summary'), new RegExp(`^13 files, 13 decoded, ${cli.views.length} with the target`));
    await solveCamera(page);
    await shot('camera');
    const heading = await page.textContent('#camera-results h3');
    const m = /^Result: RMS (\S+) px over (\d+) views$/.exec(heading);
    assert.ok(m, heading);
    assert.equal(Number(m[2]), cli.views.length);
    assertShown(m[1], cli.rms_px, 'RMS', 4);
    const K = cli.camera_matrix;
    const exact = { fx: K[0][0], fy: K[1][1], cx: K[0][2], cy: K[1][2], skew: K[0][1], ...cli.distortion };
    assert.deepEqual(Object.keys(cli.distortion).sort(), ['k1', 'k2', 'k3', 'p1', 'p2']);
    for (const [name, value] of Object.entries(exact)) assertShown(await shownCell(page, '#camera-params', name), value, name);
    for (const name of ['fx', 'fy', 'cx', 'cy', 'k1']) assertShown(await page.$eval('#camera-params tbody', (tb, n) => [...tb.rows].find((r) => r.cells[0].textContent === n).cells[2].textContent, name), cli.std[name], `std ${name}`, 3);
    // Sanity against OpenCV's published left_intrinsics.yml (fx = fy = 535.9,
    // cx 342.3, cy 235.6, rms 0.39 with fx = fy held): within a few pixels.
    const fx = Number(await shownCell(page, '#camera-params', 'fx'));
    assert.ok(Math.abs(fx - 535.9) < 5, `fx ${fx}`);
    // The undistorted preview straightens the board: take the image whose
    // rows and columns of corners bend most, undistort it on the page, and
    // detect the board in the result (the CLI, on the canvas's PNG).
    const bent = files.map((f) => ({ f, rms: worstLineRms(detectFile(f, SPEC).points, 9, 6) })).sort((x, y) => y.rms - x.rms)[0];
    const name = bent.f.split('/').pop();
    await page.selectOption('#undistort-image', { label: name });
    await page.click('#undistort-show');
    await page.waitForFunction((n) => document.getElementById('undistort-status').textContent === `${n}: undistorted at 480×360 px (preview).`, name, { timeout: 30000 });
    await page.locator('#undistort-after').scrollIntoViewIfNeeded();
    await shot('undistorted');
    const png = Buffer.from((await page.$eval('#undistort-after', (c) => c.toDataURL('image/png'))).split(',')[1], 'base64');
    const tmpDir = mkdtempSync(join(tmpdir(), 'robocal-undistort-'));
    let straight;
    try {
      writeFileSync(join(tmpDir, 'undistorted.png'), png);
      straight = worstLineRms(detectFile(join(tmpDir, 'undistorted.png'), SPEC).points, 9, 6);
    } finally {
      rmSync(tmpDir, { recursive: true, force: true });
    }
    // Barrel distortion (k1 -0.28) bends the board's edge rows by pixels;
    // undistorted, the lines are straight to the corner noise (~0.1 px at
    // 640 px, scaled by 0.75 in the preview, plus resampling).
    assert.ok(bent.rms > 1 && straight < 0.2, `worst line RMS ${bent.rms.toFixed(3)} px as taken, ${straight.toFixed(3)} px undistorted`);
    console.log(`     undistorted preview of ${name}: worst row/column line RMS ${bent.rms.toFixed(3)} px as taken -> ${straight.toFixed(3)} px undistorted`);
    // Square pixels, as OpenCV's left_intrinsics.yml was made (flags
    // CALIB_FIX_ASPECT_RATIO, aspect ratio 1): page = `--aspect-ratio 1`.
    const square = JSON.parse(execFileSync(CLI, ['intrinsics', '--target', SPEC, '--aspect-ratio', '1', ...files], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
    await page.check('#camera-form input[name=square_pixels]');
    await solveCamera(page);
    const Ks = square.camera_matrix;
    assert.equal(Ks[0][0], Ks[1][1]);
    for (const [name, value] of Object.entries({ fx: Ks[0][0], fy: Ks[1][1], cx: Ks[0][2], cy: Ks[1][2], ...square.distortion })) assertShown(await shownCell(page, '#camera-params', name), value, `square pixels: ${name}`);
    assert.equal(await shownCell(page, '#camera-params', 'fx'), await shownCell(page, '#camera-params', 'fy'));
    // Published: OpenCV's fx = fy = 535.916 (its corners, RMS 0.39 px; std of
    // fx ~0.9 px) and Bouguet's fc = (533.00, 533.15) (14 views, his
    // corners). With robocal's corners (RMS ~0.16 px) fx = fy lands between
    // them: within 3 px of both.
    assert.ok(Math.abs(Ks[0][0] - 535.916) < 3 && Math.abs(Ks[0][0] - 533.08) < 3, `fx = fy ${Ks[0][0]}`);
    await shot('square-pixels');
    console.log(`     left set: ${cli.views.length} views, page = CLI: fx ${K[0][0].toFixed(4)} fy ${K[1][1].toFixed(4)} cx ${K[0][2].toFixed(4)} cy ${K[1][2].toFixed(4)} k1 ${cli.distortion.k1.toFixed(6)} rms ${cli.rms_px.toFixed(5)} px; square pixels: fx = fy ${Ks[0][0].toFixed(4)} (OpenCV 535.916, Bouguet 533.0/533.2), cx ${Ks[0][2].toFixed(4)} cy ${Ks[1][2].toFixed(4)}, rms ${square.rms_px.toFixed(5)} px`);
  }],
  ['OpenCV left/right pairs: the rig step\'s 2-camera stereo pair equals robocal stereo', async (page, { url, shot }) => {
    const dir = datasetDir('opencv-left-right-9x6');
    if (!dir) { console.log('     skipped: opencv-left-right-9x6 not found in ../shared/datasets or /work/shared/datasets'); return; }
    const side = (s) => readdirSync(dir).filter((f) => new RegExp(`^${s}\\d+\\.jpg$`).test(f)).sort().map((f) => join(dir, f));
    const [left, right] = [side('left'), side('right')];
    assert.equal(left.length, 13);
    assert.equal(right.length, 13);
    const cli = JSON.parse(execFileSync(CLI, ['stereo', '--target', SPEC, '--left', ...left, '--right', ...right], { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
    await page.goto(`${url}#stereo`);
    await ready(page);
    // The rig step with its two cameras: right before left, the page groups by
    // the number in the names, not by upload order.
    for (const [k, name] of [[1, 'right'], [0, 'left']]) {
      await page.fill(`#rig-name-${k}`, name);
      await page.dispatchEvent(`#rig-name-${k}`, 'change');
    }
    await page.setInputFiles('#rig-input-1', right);
    await page.setInputFiles('#rig-input-0', left);
    // Either camera's files alone make 13 frames: wait for both cameras' counts too.
    await page.waitForFunction(() => /^13 frames over 2 cameras, grouped by the number in the file names/.test(document.getElementById('rig-grouping')?.textContent || '')
      && document.getElementById('rig-count-0')?.textContent === '13 images' && document.getElementById('rig-count-1')?.textContent === '13 images', null, { timeout: 30000 });
    await page.click('#rig-solve');
    await page.locator('#stereo-summary').waitFor({ timeout: 300000 });
    await shot('stereo');
    const summary = await page.textContent('#stereo-summary');
    const m = /^right_from_left: baseline (\S+) mm, RMS (\S+) px over (\d+) pairs$/.exec(summary);
    assert.ok(m, summary);
    assert.equal(Number(m[3]), cli.left.views.length);
    assertShown(m[1], cli.baseline_m * 1000, 'baseline (mm)', 4);
    assertShown(m[2], cli.rms_px, 'stereo RMS', 4);
    const cells = (sel) => page.$$eval(`${sel} tbody tr`, (trs) => trs.map((tr) => [...tr.cells].slice(1).map((c) => c.textContent)));
    const [T] = await cells('#stereo-translation');
    cli.right_from_left.translation_m.forEach((t, i) => assertShown(T[i], t * 1000, `T[${i}] (mm)`, 4));
    const R = await cells('#stereo-rotation');
    for (let r = 0; r < 3; r++) for (let c = 0; c < 3; c++) assertShown(R[r][c], cli.right_from_left.matrix_row_major[r][c], `R[${r}][${c}]`);
    const cams = await cells('#stereo-cameras');
    [cli.left, cli.right].forEach((cam, i) => {
      const K = cam.camera_matrix;
      [K[0][0], K[1][1], K[0][2], K[1][2]].forEach((v, j) => assertShown(cams[i][j], v, `${i ? 'right' : 'left'} ${['fx', 'fy', 'cx', 'cy'][j]}`, 4));
    });
    // The export page writes right_from_left like `robocal export stereo.json`.
    const tmp = mkdtempSync(join(tmpdir(), 'robocal-stereo-'));
    let cliMatrix;
    try {
      writeFileSync(join(tmp, 'stereo.json'), JSON.stringify(cli));
      cliMatrix = execFileSync(CLI, ['export', join(tmp, 'stereo.json'), '--format', 'matrix4', '--transform', 'right_from_left']).toString();
    } finally {
      rmSync(tmp, { recursive: true, force: true });
    }
    await page.click('a[data-step=export]');
    await page.selectOption('#export-transform', 'right_from_left');
    await page.$eval('#export-status', (el) => { el.textContent = ''; });
    await page.click('#transform-formats button[data-format=matrix4]');
    await page.waitForFunction(() => /^matrix4: /.test(document.getElementById('export-status').textContent), null, { timeout: 10000 });
    const numbers = (t) => (t.match(/-?\d+(\.\d+)?(e[-+]?\d+)?/gi) || []).map(Number);
    const [a, b] = [numbers(await page.textContent('#export-preview')), numbers(cliMatrix)];
    assert.equal(a.length, b.length, `${a.length} vs ${b.length} numbers`);
    // Same core, wasm vs native: equal to the last bits of libm (1e-9).
    a.forEach((x, i) => assert.ok(Math.abs(x - b[i]) <= 1e-9 * Math.max(1, Math.abs(b[i])), `matrix4 entry ${i}: page ${x}, CLI ${b[i]}`));
    await shot('stereo-export');
    // Bouguet's example 5 (SOURCE.md): T = [-99.80, 1.12, 0.05] mm +- [0.14, 0.11, 0.50].
    const t = cli.right_from_left.translation_m.map((v) => v * 1000);
    assert.ok(Math.abs(t[0] + 99.8) < 1.5 && Math.abs(t[1] - 1.12) < 1.5 && Math.abs(t[2]) < 3, `T ${t}`);
    console.log(`     stereo: ${cli.left.views.length} pairs, page = CLI: T [${t.map((v) => v.toFixed(3)).join(', ')}] mm, baseline ${(cli.baseline_m * 1000).toFixed(3)} mm, rms ${cli.rms_px.toFixed(4)} px`);
  }],
  ['RWHE CS_synthetic_1: hand-eye from images and robot poses, page = CLI, truth recovered', async (page, { url, shot }) => {
    const dir = datasetDir('rwhe-calib-cs-synthetic-1');
    if (!dir) { console.log('     skipped: rwhe-calib-cs-synthetic-1 not found in ../shared/datasets or /work/shared/datasets'); return; }
    // SOURCE.md: chessboard 9x6 inner corners, 200 mm squares; RobotPosesVec.txt
    // holds base_from_gripper as row-major 4x4 in metres, line k with im_k.
    const spec = 'chessboard:9x6:200mm';
    const images = readdirSync(dir).filter((f) => /^im_\d+\.png$/.test(f)).sort().map((f) => join(dir, f));
    assert.equal(images.length, 15);
    const poses = join(dir, 'RobotPosesVec.txt');
    const run = (args) => JSON.parse(execFileSync(CLI, args, { stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 << 20 }).toString());
    const camera = run(['intrinsics', '--target', spec, ...images]);
    assert.equal(camera.views.length, 15);
    const tmp = mkdtempSync(join(tmpdir(), 'robocal-rwhe-'));
    let cli, cliRefined;
    try {
      // The hand-eye from the same camera poses the page uses (its camera solve = the CLI's).
      const camPoses = join(tmp, 'camera_poses.txt');
      writeFileSync(camPoses, camera.views.map((v) => v.camera_from_target.matrix_row_major.flat().join(' ')).join('\n') + '\n');
      cli = run(['handeye', '--setup', 'eye-in-hand', '--poses', poses, '--camera-poses', camPoses, '--camera-pose-format', 'matrix']);
      // The refinement over the image points with that camera: its optimum
      // does not depend on where it starts (the CLI starts from PnP poses,
      // the page from the camera solve's), so page and CLI must agree.
      const camFile = join(tmp, 'camera.json');
      writeFileSync(camFile, JSON.stringify(camera));
      cliRefined = run(['handeye', '--setup', 'eye-in-hand', '--poses', poses, '--camera', camFile, '--target', spec, '--refine', 'trusted', ...images]);
    } finally {
      rmSync(tmp, { recursive: true, force: true });
    }
    await page.goto(url);
    await ready(page);
    await setTarget(page, 9, 6, 200);
    await page.click('a[data-step=images]');
    await uploadAndDetect(page, images);
    assert.match(await page.textContent('#image-summary'), /^15 files, 15 decoded, 15 with the target/);
    await solveCamera(page);
    const K = camera.camera_matrix;
    for (const [name, value] of Object.entries({ fx: K[0][0], fy: K[1][1], cx: K[0][2], cy: K[1][2] })) assertShown(await shownCell(page, '#camera-params', name), value, name, 6, 1e-4 * camera.std[name]);
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', poses);
    await page.locator('#pose-table').waitFor({ timeout: 20000 });
    assert.match(await page.textContent('#pose-format-used'), /^RobotPosesVec\.txt: 15 poses read as matrix4, lengths in m/);
    assert.match(await page.textContent('#pose-pairing'), /by order \(pose i with the i-th image of step 2\): 15 pairs usable/);
    await page.click('a[data-step=handeye]');
    const solveShown = async (refine) => {
      await page.selectOption('#handeye-refine', refine);
      await page.$eval('#handeye-results', (el) => el.replaceChildren());
      await page.click('#solve-handeye');
      await page.locator('#handeye-errors').waitFor({ timeout: 120000 });
      const text = (await page.$$eval('#handeye-results p', (ps) => ps.map((p) => p.textContent))).find((t) => t.startsWith('gripper_from_camera:')) || '';
      const m = /gripper_from_camera: translation (\S+), (\S+), (\S+) mm · quaternion \(x y z w\) (\S+), (\S+), (\S+), (\S+)/.exec(text);
      assert.ok(m, text.slice(0, 300));
      return m;
    };
    // The page's hand-eye starts from its own camera solve, whose poses
    // differ from the CLI's within that solve's stopping precision (about
    // 1e-9 relative here): a quaternion component may move by that much
    // (1e-9 rad is 6e-8 deg; measured 7e-11), far below what the shown
    // 6 significant digits of a component near 0 resolve.
    const assertX = (m, X, what) => {
      X.translation_m.forEach((t, i) => assertShown(m[1 + i], t * 1000, `${what} gripper_from_camera t[${i}] (mm)`, 3));
      X.quaternion_xyzw.forEach((q, i) => assertShown(m[4 + i], q, `${what} gripper_from_camera q[${i}]`, 6, 1e-9));
    };
    // Camera poses only (refine 'none': the pose refinement, the CLI's default
    // with --camera-poses): the page equals the CLI on the camera poses.
    assertX(await solveShown('none'), cli.gripper_from_camera, 'pose refinement');
    assert.equal((/^Result \((.*)\)$/.exec(await page.textContent('#handeye-results h3')) || [])[1], cli.method);
    // Refined over the image points, robot poses exact.
    const mRefined = await solveShown('trusted');
    await shot('handeye');
    assertX(mRefined, cliRefined.gripper_from_camera, 'refined');
    assert.match(await page.textContent('#handeye-refinement'), /^Refined \(over the image points, robot poses exact\) from \S+: reprojection RMS /);
    const X = cli.gripper_from_camera;
    // Ground truth (GroundTruth.txt): hand2eye = diag(1, -1, -1), zero
    // translation: quaternion (±1, 0, 0, 0). Rendered corners carry ~0.02 px
    // of error over a 2-6 m range: OpenCV's closed forms land within ~11 mm.
    const q = X.quaternion_xyzw;
    const angleDeg = 2 * Math.acos(Math.min(1, Math.abs(q[0]))) * 180 / Math.PI;
    const tMm = Math.hypot(...X.translation_m) * 1000;
    assert.ok(angleDeg < 0.05 && tMm < 15, `rotation off ${angleDeg} deg, translation ${tMm} mm`);
    console.log(`     RWHE: page = CLI (${cli.method}): gripper_from_camera off the truth by ${angleDeg.toFixed(4)} deg and ${tMm.toFixed(2)} mm`);
    const qr = cliRefined.gripper_from_camera.quaternion_xyzw;
    const refinedDeg = 2 * Math.acos(Math.min(1, Math.abs(qr[0]))) * 180 / Math.PI;
    const refinedMm = Math.hypot(...cliRefined.gripper_from_camera.translation_m) * 1000;
    console.log(`     RWHE refined (trusted, page = CLI): off the truth by ${refinedDeg.toFixed(4)} deg and ${refinedMm.toFixed(2)} mm`);
  }],
  ['benchmark: 20 rendered 1280x960 images detected and solved', async (page, { url, shot }) => {
    const dir = mkdtempSync(join(tmpdir(), 'robocal-bench-'));
    try {
      execFileSync(CLI, ['render', '--out', dir, '--camera', join(root, 'fixtures/exports/camera.ros.yaml'), '--views', '20', '--seed', '7'], { stdio: 'ignore' });
      const files = readdirSync(dir).filter((f) => f.endsWith('.png')).sort().map((f) => join(dir, f));
      assert.equal(files.length, 20);
      await page.goto(url);
      await ready(page);
      const runs = Number(process.env.ROBOCAL_BENCH_RUNS || 3);
      const detect = [];
      const solve = [];
      let fx = null;
      for (let run = 0; run < runs; run++) {
        await page.click('a[data-step=images]');
        await page.click('#clear-images');
        await page.waitForFunction(() => document.querySelectorAll('.card').length === 0 && document.getElementById('progress-row').hidden, null, { timeout: 10000 });
        await page.$eval('#progress-text', (el) => { el.textContent = ''; });
        const t0 = Date.now();
        await uploadAndDetect(page, files);
        detect.push(Date.now() - t0);
        assert.match(await page.textContent('#image-summary'), /^20 files, 20 decoded, 20 with the target/);
        const t1 = Date.now();
        await solveCamera(page);
        solve.push(Date.now() - t1);
        fx = Number(await shownCell(page, '#camera-params', 'fx'));
      }
      await shot('solved');
      // The fixture camera has fx = 1000.5: the renders' noise (2 grey levels)
      // keeps the estimate within a pixel.
      assert.ok(Math.abs(fx - 1000.5) < 2, `fx ${fx}`);
      console.log(`     benchmark (Chromium, ${runs} runs): upload + decode + detect 20 x 1280x960 PNG: median ${median(detect)} ms [${detect.join(', ')}]; camera solve (Zhang, brown): median ${median(solve)} ms [${solve.join(', ')}]; total median ${median(detect.map((d, i) => d + solve[i]))} ms`);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  }],
];
