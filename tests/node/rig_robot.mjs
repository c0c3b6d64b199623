// Node tier: the rig on a robot (`calibrate_rig_handeye`) on rendered
// images of known truth. `robocal render --rig` draws the seeded rig's first
// pair (cam0, cam1: 6 frames facing them); the package detects the board
// in every image, a fixed eye-to-hand cell gives the robot poses
// (base_from_gripper = base_from_rig * rig_from_target * gripper_from_target^-1
// per frame), and one call calibrates the rig and solves base_from_rig.
// Run by smoke.mjs as `node rig_robot.mjs WORK_DIR` (robocal installed, the
// release CLI built). Tolerance: 3 mm and 3 mrad, the rig calibration's own
// on these renders (tests/cli/cli_rig.rs); the truth within 4 reported std.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const work = process.argv[2];
if (!work) throw new Error('usage: node rig_robot.mjs WORK_DIR (with robocal installed)');
const robocal = createRequire(join(work, 'package.json'))('robocal');
const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const dir = join(work, 'rig');
execFileSync(join(root, 'target/release/robocal'), ['render', '--out', dir, '--rig', '--views', '6', '--side-frames', '0', '--seed', '7'], { stdio: 'ignore' });
const truth = JSON.parse(readFileSync(join(dir, 'truth.json'), 'utf8'));

// 4x4 row-major helpers.
const mul = (a, b) => a.map((row) => [0, 1, 2, 3].map((j) => row.reduce((s, v, k) => s + v * b[k][j], 0)));
function inv(m) {
  const rt = [0, 1, 2].map((i) => [0, 1, 2].map((j) => m[j][i]));
  const t = [0, 1, 2].map((i) => -(rt[i][0] * m[0][3] + rt[i][1] * m[1][3] + rt[i][2] * m[2][3]));
  return [...rt.map((row, i) => [...row, t[i]]), [0, 0, 0, 1]];
}
function pose(t, w) {
  const a = Math.hypot(...w);
  const [x, y, z] = w.map((v) => v / a);
  const c = Math.cos(a), s = Math.sin(a), C = 1 - c;
  const r = [[c + x * x * C, x * y * C - z * s, x * z * C + y * s], [y * x * C + z * s, c + y * y * C, y * z * C - x * s], [z * x * C - y * s, z * y * C + x * s, c + z * z * C]];
  return [...r.map((row, i) => [...row, t[i]]), [0, 0, 0, 1]];
}

const spec = truth.target;
const cameras = truth.cameras.slice(0, 2).map((c) => ({
  name: c.name,
  views: c.images.map((im) => ({ key: im.frame, name: im.image, detection: JSON.parse(robocal.detect_target(readFileSync(join(dir, im.image)), spec)) })),
}));
const keys = [...new Set(cameras.flatMap((c) => c.views.map((v) => v.key)))].sort((a, b) => Number(a) - Number(b));
const rigFromTarget = new Map(truth.frames.map((f) => [f.key, f.rig_from_target.matrix_row_major]));
const baseFromRig = pose([1.1, -0.4, 0.9], [2.2, -0.3, 0.5]);
const gripperFromTarget = pose([0.02, 0.05, 0.12], [0.4, 0.2, -0.9]);
const base_from_gripper = keys.map((k) => ({ matrix_row_major: mul(mul(baseFromRig, rigFromTarget.get(k)), inv(gripperFromTarget)) }));

const out = JSON.parse(robocal.calibrate_rig_handeye(JSON.stringify({ setup: 'eye-to-hand', base_from_gripper, calibration: { target: spec, cameras } })));
const he = out.handeye;
assert.equal(he.setup, 'eye-to-hand');
assert.deepEqual(he.frames.map((f) => f.key), keys);
assert.ok(he.frames.every((f) => f.used), JSON.stringify(he.frames));
const got = he.base_from_rig.matrix_row_major;
const dt = [0, 1, 2].map((i) => got[i][3] - baseFromRig[i][3]);
// The rotation error as a small-angle vector: R_got R_true^T.
const r = [0, 1, 2].map((i) => [0, 1, 2].map((j) => got[i][0] * baseFromRig[j][0] + got[i][1] * baseFromRig[j][1] + got[i][2] * baseFromRig[j][2]));
const dr = [(r[2][1] - r[1][2]) / 2, (r[0][2] - r[2][0]) / 2, (r[1][0] - r[0][1]) / 2];
const [t, w] = [Math.hypot(...dt), Math.hypot(...dr)];
assert.ok(t < 3e-3 && w < 3e-3, `base_from_rig off by ${t} m, ${w} rad`);
const std = he.pose_refinement.camera_transform_std;
dt.forEach((e, i) => assert.ok(Math.abs(e) * 1000 <= 4 * std.translation_mm[i], `T[${i}] off by ${e * 1000} mm, std ${std.translation_mm[i]} mm`));
assert.equal(he.rig_uncertainty.included, true, he.rig_uncertainty.note);
assert.deepEqual(he.cameras.map((c) => c.name), ['cam0', 'cam1']);
// The rig with its hand-eye exports like any rig report.
assert.match(robocal.export_report(JSON.stringify(out), 'urdf', ''), /<robot /);
console.log(`rig on a robot (rendered) ok: base_from_rig ${(t * 1000).toFixed(3)} mm, ${(w * 1000).toFixed(3)} mrad from the truth over ${keys.length} frames`);
