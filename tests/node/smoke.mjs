// Node tier: pack pkg/ with npm, install the tarball into a fresh folder, and
// call the package from both ESM and CommonJS, asserting real results.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, writeFileSync, readdirSync, readFileSync, copyFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { makePng } from '../support/images.mjs';

const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const work = mkdtempSync(join(tmpdir(), 'robocal-node-'));
const npm = (args, cwd) => execFileSync('npm', args, { cwd, stdio: ['ignore', 'pipe', 'inherit'] }).toString();

npm(['pack', join(root, 'pkg'), '--pack-destination', work, '--silent'], work);
const tarball = readdirSync(work).find((f) => f.endsWith('.tgz'));
if (!tarball) throw new Error('npm pack produced no tarball');
writeFileSync(join(work, 'package.json'), '{ "name": "robocal-smoke", "private": true }\n');
npm(['install', '--no-audit', '--no-fund', '--offline', join(work, tarball)], work);

writeFileSync(join(work, 'board.png'), makePng(64, 48, (x, y) => [x * 4, y * 5, 128]));
// A rendered ChArUco board with its exact corners (the CLI's renderer, `make
// test-node` builds it): one view, grey-level noise sigma 2.
execFileSync(join(root, 'target/release/robocal'), ['render', '--out', join(work, 'charuco'), '--target', 'charuco:8x6:30mm:22mm:DICT_5X5_100', '--views', '1', '--seed', '2', '--noise', '2'], { stdio: 'ignore' });

const esm = `
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import robocal, { version, image_info } from 'robocal';
const expected = JSON.parse(readFileSync(new URL('./node_modules/robocal/package.json', import.meta.url))).version;
assert.equal(version(), expected);
assert.equal(typeof robocal.image_info, 'function');
const info = JSON.parse(image_info(readFileSync(new URL('./board.png', import.meta.url))));
assert.deepEqual([info.format, info.width, info.height, info.channels, info.bits_per_channel], ['png', 64, 48, 3, 8]);
assert.throws(() => image_info(new Uint8Array([1, 2, 3])), { message: 'not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP' });
// The README's example: detect, calibrate, export, on the seeded demo images.
const demo = robocal.render_demo(1);
const meta = JSON.parse(demo.json);
const all = demo.bytes;
const views = meta.images.map((im) => ({
  name: im.name,
  detection: JSON.parse(robocal.detect_target(all.subarray(im.offset, im.offset + im.length), meta.target_spec)),
}));
const { report } = JSON.parse(robocal.calibrate_camera(JSON.stringify({ model: 'brown', method: 'zhang', views })));
// Truth of the demo camera: fx = fy = 900 px, cx 511.5, cy 383.5 (src/synth/demo.rs);
// rendered corners are good to ~0.05 px, so the intrinsics land within 1.5 px.
assert.ok(Math.abs(report.camera_matrix[0][0] - 900) < 1.5, 'fx ' + report.camera_matrix[0][0]);
assert.ok(Math.abs(report.camera_matrix[0][2] - 511.5) < 1.5, 'cx ' + report.camera_matrix[0][2]);
assert.ok(report.rms_px < 0.2, 'rms ' + report.rms_px);
// The check of the saved calibration against five of the views (docs/check.md): ok, with the shift map.
const check = JSON.parse(robocal.check_camera(JSON.stringify({ calibration: JSON.stringify(report), views: views.slice(0, 5) })));
assert.equal(check.verdict, 'ok', check.reasons.join('; '));
assert.equal(check.projection_shift_px.map.length, 40);
assert.ok(check.projection_shift_px.worst < check.thresholds.shift_px, 'worst ' + check.projection_shift_px.worst);
// The hand-eye pose plan (docs/pose-plan.md) from the first demo view and its robot pose, and its UR script.
const robotPoses = JSON.parse(robocal.read_robot_poses(meta.poses_csv, '')).parsed.poses;
const boardM = JSON.parse(robocal.target_points(meta.target_spec)).map((p) => [p.x_m, p.y_m, 0]);
const planRequest = { setup: 'eye-in-hand', base_from_gripper: robotPoses[0].base_from_gripper, camera_from_target: report.views[0].camera_from_target, camera: report.camera, board_m: boardM, poses: 8 };
const plan = JSON.parse(robocal.plan_handeye_poses(JSON.stringify(planRequest)));
assert.equal(plan.kind, 'handeye-plan');
assert.equal(plan.poses.length, 8);
assert.ok(plan.predicted.bound95_mm > 0, 'predicted ' + JSON.stringify(plan.predicted));
const urScript = robocal.plan_move_list(JSON.stringify(plan), 'ur-script');
assert.equal(urScript.split('movel(p[').length - 1, 8);
assert.match(robocal.plan_move_list(JSON.stringify(plan), 'kuka'), /plan_08/);
assert.throws(() => robocal.plan_move_list(JSON.stringify(plan), 'lego'), { message: /not a pose format robocal reads nor a program/ });
const yaml = robocal.export_report(JSON.stringify(report), 'opencv-yaml', '');
assert.ok(yaml.startsWith('%YAML:1.0'), yaml.slice(0, 40));
assert.match(yaml, /camera_matrix: !!opencv-matrix/);
// The undistorted preview of a demo image through the calibrated camera (1024x768 -> 256x192).
const first = meta.images[0];
// Node has no ImageData: without one the call says what to do; with the README's class it works.
assert.throws(() => robocal.undistort_preview(all.subarray(first.offset, first.offset + first.length), JSON.stringify(report.camera), 256), { message: "this JavaScript host has no ImageData (node has none): set globalThis.ImageData to a class whose constructor takes (data: Uint8ClampedArray, width, height) first, e.g. the ImageData of @napi-rs/canvas or the one in robocal's README" });
globalThis.ImageData = class ImageData { constructor(data, width, height) { this.data = data; this.width = width; this.height = height; } };
const preview = robocal.undistort_preview(all.subarray(first.offset, first.offset + first.length), JSON.stringify(report.camera), 256);
assert.deepEqual([preview.width, preview.height, preview.data.length], [256, 192, 256 * 192 * 4]);
// The target calls of the page: the core's JSON, spec, points and printable sheet.
assert.deepEqual(JSON.parse(robocal.parse_target('chessboard:9x6:30mm')), { kind: 'chessboard', cols: 9, rows: 6, square_m: 0.03 });
assert.equal(robocal.target_spec('{"kind":"square_grid","cols":8,"rows":8,"side_m":0.0127,"pitch_m":0.0225778}'), 'squares:8x8:12.7mm:22.5778mm');
const points = JSON.parse(robocal.target_points('chessboard:9x6:30mm'));
assert.deepEqual([points.length, points[10]], [54, { id: 10, x_m: 0.03, y_m: 0.03 }]);
const svg = robocal.target_svg('chessboard:9x6:30mm');
assert.match(svg, /<rect class="check-bar" x="10" y="[0-9.]+" width="100" height="3"/);
assert.match(svg, />robocal target chessboard:9x6:30mm</);
// Marker boards: the ChArUco spec as the core's JSON and back, its sheet, and
// a rendered board detected against the render's exact corners.
const charucoSpec = 'charuco:8x6:30mm:22mm:DICT_5X5_100:first=4';
const charuco = JSON.parse(robocal.parse_target(charucoSpec));
assert.deepEqual(charuco, { kind: 'charuco', squares_x: 8, squares_y: 6, square_m: 0.03, marker_m: 0.022, dictionary: 'DICT_5X5_100', first_id: 4, legacy: false });
assert.equal(robocal.target_spec(JSON.stringify(charuco)), charucoSpec);
assert.equal(JSON.parse(robocal.target_points(charucoSpec)).length, 7 * 5);
assert.match(robocal.target_svg(charucoSpec), />robocal target charuco:8x6:30mm:22mm:DICT_5X5_100:first=4</);
assert.deepEqual(JSON.parse(robocal.parse_target('aprilgrid:6x6:88mm:0.3')), { kind: 'aprilgrid', tag_cols: 6, tag_rows: 6, tag_m: 0.088, spacing_ratio: 0.3, first_id: 0 });
assert.equal(JSON.parse(robocal.target_points('aprilgrid:6x6:88mm:0.3')).length, 4 * 36);
const truth = JSON.parse(readFileSync(new URL('./charuco/truth.json', import.meta.url)));
const found = JSON.parse(robocal.detect_target(readFileSync(new URL('./charuco/view_000.png', import.meta.url)), JSON.stringify(truth.target)));
const exact = new Map(truth.views[0].points.map((p) => [p.id, p]));
// The whole board is in view: every corner found, each on the truth.
assert.equal(found.points.length, 35, 'ChArUco corners found');
const errs = found.points.map((p) => Math.hypot(p.x_px - exact.get(p.id).x_px, p.y_px - exact.get(p.id).y_px));
const meanErr = errs.reduce((a, b) => a + b, 0) / errs.length;
// Noise sigma 2 grey levels gives saddle points good to a few hundredths of
// a pixel (BENCHMARKS.md: ~0.02 px mean); 0.1 px mean and 0.3 px at most
// leave room for a blurrier view yet catch a wrong id or a corner off by one square.
assert.ok(meanErr < 0.1 && Math.max(...errs) < 0.3, 'ChArUco corner error px: mean ' + meanErr + ', max ' + Math.max(...errs));
console.log('charuco detected: 35 corners, mean error ' + meanErr.toFixed(4) + ' px');
// detect_boards: one board in view, the same detection as detect_target's; a target with other ids finds it as another board.
const view0 = readFileSync(new URL('./charuco/view_000.png', import.meta.url));
assert.deepEqual(JSON.parse(robocal.detect_boards(view0, JSON.stringify(truth.target))), [found]);
const shifted = { ...truth.target, first_id: truth.target.first_id + 24 };
assert.deepEqual(JSON.parse(robocal.detect_boards(view0, JSON.stringify(shifted))).map((d) => [d.target.first_id, d.points.length]), [[truth.target.first_id, 35]]);
assert.throws(() => robocal.parse_target('chessboard:1x6:30mm'), { message: 'target: a grid needs 2 to 100000 points with at least 2 per side, got 1x6' });
// Stereo pairing, the rule of robocal stereo.
assert.deepEqual(JSON.parse(robocal.pair_images('["l10.png","l2.png"]', '["r2.png","r010.png"]')), { paired_by: 'number', pairs: [[0, 1], [1, 0]] });
assert.throws(() => robocal.pair_images('["l1.png"]', '["r1.png","r2.png"]'), { message: 'images: images are paired by the last number in their file names; no partner for: r2.png (right, number 2)' });
// max_pixels: over the limit the error names the image size and the limit.
assert.throws(() => robocal.image_info(readFileSync(new URL('./board.png', import.meta.url)), JSON.stringify({ max_pixels: 1000 })), { message: 'image is 64x48 = 3072 pixels, more than the limit of 1000 pixels: downscale it first, or raise the limit (--max-pixels in the CLI, "max_pixels" in the JSON options)' });
// The panic hook is installed by the module itself: last_panic_message is empty, and a trap is a RuntimeError.
assert.equal(robocal.last_panic_message(), '');
assert.throws(() => robocal.undistort_preview(readFileSync(new URL('./board.png', import.meta.url)), JSON.stringify(report.camera), 256), { message: 'image: the image is 64x48 px but the camera was calibrated on 1024x768 px images' });
// Stereo through the JSON API: the same views on both sides are refused
// (they would solve to a baseline of 0 m, issue 35).
assert.throws(() => robocal.calibrate_stereo(JSON.stringify({ left: views, right: views })), { message: 'right: the left and right images have identical detections in all 12 pairs: the same images were given for both cameras, which would solve to a baseline of 0 m; give each camera its own images' });
assert.throws(() => robocal.calibrate_stereo(JSON.stringify({ left: views, right: views.slice(1) })), { message: 'right: views are paired by order: 12 left views but 11 right views' });
console.log('esm ok (demo calibrated: fx ' + report.camera_matrix[0][0].toFixed(3) + ' px, rms ' + report.rms_px.toFixed(4) + ' px)');
`;
const cjs = `
const assert = require('node:assert/strict');
const { readFileSync } = require('node:fs');
const robocal = require('robocal');
const info = JSON.parse(robocal.image_info(readFileSync(__dirname + '/board.png')));
assert.equal(info.format_name, 'PNG');
assert.equal(info.width * info.height, 64 * 48);
console.log('cjs ok');
`;
writeFileSync(join(work, 'esm.mjs'), esm);
writeFileSync(join(work, 'cjs.cjs'), cjs);
for (const f of ['esm.mjs', 'cjs.cjs']) {
  process.stdout.write(execFileSync('node', [f], { cwd: work }).toString());
}

// Types: tsc --strict on tests/node/types-check.ts and on the README's
// TypeScript example, against the installed package's index.d.ts; then the
// README example transpiled and run, and the real JSON outputs walked
// against the declarations (shapes.mjs).
const here = dirname(fileURLToPath(import.meta.url));
const ts = createRequire(join(here, 'package.json'))('typescript');
const readme = readFileSync(join(root, 'pkg-config', 'README.md'), 'utf8');
const example = /```ts\n([\s\S]*?)```/.exec(readme)?.[1];
if (!example) throw new Error('pkg-config/README.md has no ```ts example');
writeFileSync(join(work, 'readme-example.ts'), example);
copyFileSync(join(here, 'types-check.ts'), join(work, 'types-check.ts'));
const tsc = ['--noEmit', '--strict', '--target', 'es2022', '--lib', 'es2022,esnext.disposable,dom', '--module', 'nodenext', '--moduleResolution', 'nodenext'];
for (const f of ['types-check.ts', 'readme-example.ts']) {
  try {
    execFileSync('node', [join(here, 'node_modules', 'typescript', 'bin', 'tsc'), ...tsc, f], { cwd: work, stdio: ['ignore', 'pipe', 'pipe'] });
  } catch (e) {
    throw new Error(`tsc ${f}:\n${e.stdout}${e.stderr}`);
  }
  console.log(`tsc --strict ok: ${f} (typescript ${ts.version})`);
}
const js = ts.transpileModule(example, { compilerOptions: { module: ts.ModuleKind.ESNext, target: ts.ScriptTarget.ES2022 } }).outputText;
writeFileSync(join(work, 'readme-example.mjs'), js);
const printed = execFileSync('node', ['readme-example.mjs'], { cwd: work }).toString();
const [fxPrinted, cxPrinted, rmsPrinted, model] = printed.split('\n')[0].split(' ');
if (!(Math.abs(fxPrinted - 900) < 1.5 && Math.abs(cxPrinted - 511.5) < 1.5 && rmsPrinted < 0.2 && model === 'brown' && printed.includes('\n[ 0.0'))) {
  throw new Error(`README TypeScript example printed:\n${printed}`);
}
console.log('README TypeScript example ran: ' + printed.split('\n')[0]);
process.stdout.write(execFileSync('node', [join(here, 'shapes.mjs'), work]).toString());
process.stdout.write(execFileSync('node', [join(here, 'rig.mjs'), work]).toString());
// The rig on a robot on rendered images of known truth (the CLI's renderer).
process.stdout.write(execFileSync('node', [join(here, 'rig_robot.mjs'), work]).toString());
// Laser-line sensors on rendered scans of a known plane (laser_scene.mjs).
process.stdout.write(execFileSync('node', [join(here, 'laser.mjs'), work]).toString());
// LiveCapture on the renderer's test video (320x240, 5 fps: a hold is 5 frames).
execFileSync(join(root, 'target/release/robocal'), ['render', '--video', join(work, 'live.y4m'), '--size', '320x240', '--fps', '5', '--seed', '11'], { stdio: 'ignore' });
process.stdout.write(execFileSync('node', [join(here, 'live.mjs'), work]).toString());
// The page's WebAssembly SIMD check (www/lib/wasm-features.js).
process.stdout.write(execFileSync('node', [join(here, 'wasm_features.mjs')]).toString());
console.log(`node smoke test passed (${tarball})`);
