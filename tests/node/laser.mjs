// Node tier: the laser-line calls of the npm package (issue 40) on the
// rendered scans of laser_scene.mjs, against the renderer's truth. Run by
// smoke.mjs as `node laser.mjs WORK_DIR` (robocal installed there).
// Tolerances as tests/cli/cli_laser.rs (same scene, the same core): the
// normal within 0.1 deg, the distance within 0.5 mm, every profile point
// within 0.5 mm of the true plane, the stripe centres within 0.25 px of the
// truth on average, per-image RMS under 1 px (measured there: 0.059 deg,
// 0.24 mm, 0.27 mm, 0.17 px, 0.13-0.79 px).
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { laserScene } from './laser_scene.mjs';

const work = process.argv[2];
if (!work) throw new Error('usage: node laser.mjs WORK_DIR (with robocal installed)');
const robocal = createRequire(join(work, 'package.json'))('robocal');
const scene = laserScene(work);
const nTrue = scene.truth.laser_plane.normal_camera;
const dTrue = scene.truth.laser_plane.distance_m;

// 1. The plane from four pairs.
const report = JSON.parse(robocal.laser_plane(JSON.stringify(scene.request), scene.images));
assert.equal(report.kind, 'laser_plane');
const n = report.laser_plane.normal_camera;
const angleDeg = Math.acos(Math.min(1, n[0] * nTrue[0] + n[1] * nTrue[1] + n[2] * nTrue[2])) * 180 / Math.PI;
const distanceMm = Math.abs(report.laser_plane.distance_m - dTrue) * 1e3;
assert.ok(angleDeg < 0.1, `normal off by ${angleDeg} deg`);
assert.ok(distanceMm < 0.5, `distance off by ${distanceMm} mm`);
assert.deepEqual(report.images.map((i) => i.name), ['view_001', 'view_002', 'view_003', 'view_004']);
for (const image of report.images) assert.ok(image.n_points > 100 && image.rms_px < 1, JSON.stringify(image));
assert.deepEqual(report.warnings, []);

// 2. The held-out pose's stripe: its centres against the truth, its points on the true plane.
const held = scene.truth.views[scene.held];
const [off, on] = scene.pairs[scene.held];
const stripe = JSON.parse(robocal.laser_stripe(on, off, ''));
assert.equal(stripe.axis, held.stripe_axis);
const truthAt = new Map(held.stripe_px.map(([x, y]) => [x, y]));
const errors = stripe.points.filter((p) => truthAt.has(p.x_px)).map((p) => Math.abs(p.y_px - truthAt.get(p.x_px)));
assert.ok(errors.length > 200, `${errors.length} centres matched`);
const meanPx = errors.reduce((a, b) => a + b, 0) / errors.length;
assert.ok(meanPx < 0.25, `mean centre error ${meanPx} px`);
const points = JSON.parse(robocal.laser_points(JSON.stringify({ camera: scene.camera, plane: report }), on, off));
assert.equal(points.kind, 'laser_points');
assert.equal(points.points.length, stripe.points.length - points.missed);
const worstMm = Math.max(...points.points.map(({ camera_m: x }) => Math.abs(x[0] * nTrue[0] + x[1] * nTrue[1] + x[2] * nTrue[2] - dTrue) * 1e3));
assert.ok(worstMm < 0.5, `a point ${worstMm} mm off the true plane`);
// With the mounting: flange_m = gripper_from_camera * camera_m (a 10 cm offset along z).
const mounted = JSON.parse(robocal.laser_points(JSON.stringify({ camera: scene.camera, plane: report, gripper_from_camera: { translation_m: [0, 0, 0.1], quaternion_xyzw: [0, 0, 0, 1] } }), on, off));
assert.ok(Math.abs(mounted.points[0].flange_m[2] - mounted.points[0].camera_m[2] - 0.1) < 1e-12);

// 3. The exports: the plane report by its kind.
const halcon = robocal.export_report(JSON.stringify(report), 'halcon', '');
assert.match(halcon, /^LightplanePose := \[/m);
const urdf = robocal.export_report(JSON.stringify(report), 'urdf', '');
assert.match(urdf, /<joint name="camera_to_laser_plane" type="fixed">\n  <parent link="camera"\/>\n  <child link="laser_plane"\/>/);
const [file] = JSON.parse(robocal.export_report_files(JSON.stringify(report), 'halcon', '', ''));
assert.deepEqual(file, { name: 'laser_plane_halcon.txt', text: halcon });
assert.throws(() => robocal.export_report(JSON.stringify(points), 'halcon', ''), { message: "kind: a 'laser_points' report holds 3-D points: export it as 'report', or export its laser plane report" });

// 4. Bad input: the message says what is wrong.
assert.throws(() => robocal.laser_plane(JSON.stringify(scene.request), scene.images.slice(0, 3)), { message: 'images: pairs needs an even number of images (board, stripe, board, stripe, ...), got 3' });
assert.throws(() => robocal.laser_plane(JSON.stringify({ ...scene.request, names: ['a'] }), scene.images), { message: 'names: 1 names for 4 poses: give one name per pose' });
assert.throws(() => robocal.laser_plane(JSON.stringify(scene.request), [...scene.images.slice(0, 2), new Uint8Array([1, 2, 3]), scene.images[3]]), { message: /^image 3: / });
console.log(`laser ok: normal ${angleDeg.toFixed(4)} deg, distance ${distanceMm.toFixed(3)} mm, held-out points within ${worstMm.toFixed(3)} mm of the true plane, centres ${meanPx.toFixed(3)} px`);
