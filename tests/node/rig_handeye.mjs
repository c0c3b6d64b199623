// Node tier: a camera rig on a robot through the npm package
// (`calibrate_rig_handeye`) against `robocal rig --setup ... --poses` on the
// same rendered images (`robocal render --rig`, four cameras, the release CLI
// of `make cli`). Run by smoke.mjs as `node rig_handeye.mjs WORK_DIR`.
// Same detections, same solver: gripper_from_rig and its std must agree with
// the CLI's to 1e-9 (m; relative for the std), solved from scratch and with
// the CLI's rig given back (`rig`). A camera the rig lacks is the exact error.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const work = process.argv[2];
if (!work) throw new Error('usage: node rig_handeye.mjs WORK_DIR (with robocal installed)');
const robocal = createRequire(join(work, 'package.json'))('robocal');
const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const cli = join(root, 'target/release/robocal');
const dir = join(work, 'rig-robot');
execFileSync(cli, ['render', '--out', dir, '--rig', '--views', '4', '--side-frames', '2', '--seed', '3'], { stdio: 'ignore' });
const truth = JSON.parse(readFileSync(join(dir, 'truth.json'), 'utf8'));

// 4x4 helpers (row-major arrays of rows).
const mul = (a, b) => a.map((r) => [0, 1, 2, 3].map((j) => r.reduce((s, v, k) => s + v * b[k][j], 0)));
const inv = (m) => {
  const R = [0, 1, 2].map((i) => [0, 1, 2].map((j) => m[j][i]));
  const t = [0, 1, 2].map((i) => -(R[i][0] * m[0][3] + R[i][1] * m[1][3] + R[i][2] * m[2][3]));
  return [...R.map((r, i) => [...r, t[i]]), [0, 0, 0, 1]];
};
const rotation = (rx, ry, rz) => {
  const th = Math.hypot(rx, ry, rz);
  const [x, y, z] = [rx / th, ry / th, rz / th];
  const c = Math.cos(th), s = Math.sin(th), v = 1 - c;
  return [
    [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
    [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
    [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
  ];
};
const pose = (R, t) => [...R.map((r, i) => [...r, t[i]]), [0, 0, 0, 1]];
// Eye-in-hand: gripper_from_rig x, base_from_target y; base_from_gripper = y * rig_from_target^-1 * x^-1.
const x = pose(rotation(0.3, -1.1, 0.4), [0.05, -0.12, 0.2]);
const y = pose(rotation(2.0, 0.2, -0.5), [0.8, 0.1, -0.3]);

// The frames with an image, in key order, and each camera's images.
const images = truth.cameras.flatMap((c) => c.images);
const keys = [...new Set(images.map((i) => i.frame))].sort((a, b) => Number(a) - Number(b));
const frames = Object.fromEntries(truth.frames.map((f) => [f.key, f.rig_from_target.matrix_row_major]));
const robot = keys.map((k) => mul(mul(y, inv(frames[k])), inv(x)));
writeFileSync(join(dir, 'robot.json'), JSON.stringify(robot));

// The CLI: detect, calibrate the rig, then the hand-eye.
const args = ['rig', '--target', truth.target];
for (const c of truth.cameras) args.push('--camera', c.name, ...c.images.map((i) => join(dir, i.image)));
const out = join(dir, 'rig.json');
execFileSync(cli, [...args, '--setup', 'eye-in-hand', '--poses', join(dir, 'robot.json'), '-o', out], { stdio: 'ignore' });
const expected = JSON.parse(readFileSync(out, 'utf8'));

// The package: the same images detected in wasm, the same poses.
const calibration = {
  target: truth.target,
  cameras: truth.cameras.map((c) => ({
    name: c.name,
    views: c.images.map((i) => ({
      key: i.frame,
      name: i.image,
      detection: JSON.parse(robocal.detect_target(readFileSync(join(dir, i.image)), truth.target)),
    })),
  })),
};
const base_from_gripper = robot.map((m) => ({ matrix_row_major: m }));
const input = { setup: 'eye-in-hand', base_from_gripper, calibration };
const solved = JSON.parse(robocal.calibrate_rig_handeye(JSON.stringify(input)));
const held = JSON.parse(robocal.calibrate_rig_handeye(JSON.stringify({ ...input, rig: expected })));

let worst = 0;
for (const [name, got] of [['solved', solved], ['held', held]]) {
  const h = got.handeye, e = expected.handeye;
  assert.equal(h.setup, 'eye-in-hand');
  assert.equal(h.rig_uncertainty.included, true, `${name}: ${h.rig_uncertainty.note}`);
  for (let i = 0; i < 3; i++) {
    const d = Math.abs(h.gripper_from_rig.translation_m[i] - e.gripper_from_rig.translation_m[i]);
    worst = Math.max(worst, d);
    assert.ok(d < 1e-9, `${name}: gripper_from_rig translation_m[${i}] off the CLI's by ${d} m`);
    for (let j = 0; j < 3; j++) {
      const r = Math.abs(h.gripper_from_rig.matrix_row_major[i][j] - e.gripper_from_rig.matrix_row_major[i][j]);
      assert.ok(r < 1e-9, `${name}: rotation entry ${i},${j} off by ${r}`);
    }
    for (const key of ['translation_mm', 'rotation_deg']) {
      const a = h.pose_refinement.camera_transform_std[key][i], b = e.pose_refinement.camera_transform_std[key][i];
      assert.ok(Math.abs(a - b) <= 1e-9 * b, `${name}: std ${key}[${i}] ${a} vs the CLI's ${b}`);
    }
  }
}
// Against the truth: the rendered rig's hand-eye within 3 mm (as tests/cli_rig.rs).
const tx = solved.handeye.gripper_from_rig.translation_m;
const dt = Math.hypot(tx[0] - x[0][3], tx[1] - x[1][3], tx[2] - x[2][3]);
assert.ok(dt < 3e-3, `gripper_from_rig ${dt} m from the truth`);

// A camera the rig does not have, and malformed input.
const renamed = { ...calibration, cameras: calibration.cameras.map((c, k) => (k === 3 ? { ...c, name: 'top' } : c)) };
assert.throws(
  () => robocal.calibrate_rig_handeye(JSON.stringify({ ...input, calibration: renamed, rig: expected })),
  { message: "calibration.cameras[3].name: camera 'top' is not in the rig (its cameras are cam0, cam1, cam2, cam3)" },
);
assert.throws(
  () => robocal.calibrate_rig_handeye(JSON.stringify({ ...input, setup: 'eye-on-hand' })),
  { message: /^line 1, column \d+: rig hand-eye input: unknown variant `eye-on-hand`, expected `eye-in-hand` or `eye-to-hand`/ },
);
assert.throws(
  () => robocal.calibrate_rig_handeye(JSON.stringify({ ...input, base_from_gripper: base_from_gripper.slice(1) })),
  { message: `poses: ${keys.length - 1} robot poses but ${keys.length} frames: give one robot pose per frame, in frame order` },
);
console.log(`rig hand-eye ok: ${keys.length} frames, package vs CLI worst ${worst.toExponential(1)} m, truth ${(dt * 1e3).toFixed(3)} mm`);
