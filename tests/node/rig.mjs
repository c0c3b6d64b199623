// Node tier: the rig call of the npm package (`calibrate_rig`) and its
// exports (`export_report_files`), on the noise-free rig of rig_scene.mjs.
// Run by smoke.mjs as `node rig.mjs WORK_DIR` (robocal installed there).
// Noise-free points: every camera_from_rig must be exact to 1e-9 (m, and
// rotation matrix entries), the noise-free bound (measured: ~3e-14).
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { rigInput, rigOnRobot, truth } from './rig_scene.mjs';

const work = process.argv[2];
if (!work) throw new Error('usage: node rig.mjs WORK_DIR (with robocal installed)');
const robocal = createRequire(join(work, 'package.json'))('robocal');

const rig = JSON.parse(robocal.calibrate_rig(JSON.stringify(rigInput())));
assert.deepEqual(rig.cameras.map((c) => c.name), ['left', 'middle', 'right']);
assert.equal(rig.rig_frame, 'left');
assert.deepEqual(rig.co_observation.frames, [[7, 7, 4], [7, 10, 7], [4, 7, 7]]);
let worstT = 0, worstR = 0;
rig.cameras.forEach((c, k) => {
  const m = c.camera_from_rig.matrix_row_major;
  for (let i = 0; i < 3; i++) {
    worstT = Math.max(worstT, Math.abs(m[i][3] - truth[k].t[i]));
    for (let j = 0; j < 3; j++) worstR = Math.max(worstR, Math.abs(m[i][j] - truth[k].R[i][j]));
  }
  assert.ok(Math.abs(c.calibration.camera_matrix[0][0] - truth[k].f) < 1e-4, `${c.name} fx ${c.calibration.camera_matrix[0][0]}`);
});
assert.ok(worstT < 1e-9, 'camera_from_rig translation error m ' + worstT);
assert.ok(worstR < 1e-9, 'camera_from_rig rotation entry error ' + worstR);
assert.ok(rig.rms_px < 1e-6, 'rms px ' + rig.rms_px);
assert.equal(rig.cameras[0].camera_from_rig_std, null);

// The frame grouping proven from the data (issue 35): the right camera's
// images keyed one frame late are refused before the joint fit, naming the
// shift, through npm as through the CLI.
const shifted = rigInput();
shifted.cameras[2].views = shifted.cameras[2].views.map((v) => ({ ...v, key: String(Number(v.key) + 1) }));
assert.throws(() => robocal.calibrate_rig(JSON.stringify(shifted)), { message: /^rig frames: cameras middle and right: the board's motions agree only when right's frames are taken 1 frame late/ });

// Exports: the files robocal export -o DIR writes, the one-text form, the formats.
const report = JSON.stringify(rig);
assert.deepEqual(JSON.parse(robocal.rig_export_formats()), ['kalibr', 'opencv-yaml', 'ros', 'urdf', 'mrcal']);
const ros = JSON.parse(robocal.export_report_files(report, 'ros', '', JSON.stringify({ rig: 'camera_rig' })));
assert.deepEqual(ros.map((f) => f.name), ['left.yaml', 'middle.yaml', 'right.yaml', 'rig_tf.launch', 'rig_tf.launch.py']);
assert.match(ros[3].text, /args="[-0-9. ]+ camera_rig right"\/>/);
const kalibr = robocal.export_report(report, 'kalibr', '');
assert.equal(kalibr, JSON.parse(robocal.export_report_files(report, 'kalibr', '', ''))[0].text);
// T_cn_cnm1 of cam1 is middle_from_left = the middle camera's camera_from_rig (left is the rig).
const row0 = /cam1:\n  T_cn_cnm1:\n  - \[([^\]]+)\]/.exec(kalibr)[1].split(', ').map(Number);
assert.ok(Math.abs(row0[3] - truth[1].t[0]) < 1e-9 && Math.abs(row0[0] - truth[1].R[0][0]) < 1e-9, 'T_cn_cnm1 row 0: ' + row0);
assert.throws(() => robocal.export_report_files(report, 'ros', '', '["rig"]'), { message: /^frames: expected an object of frame names by role/ });
assert.throws(() => robocal.export_report(report, 'ros-yaml', ''), { message: "format: format 'ros-yaml' is not a rig format: a rig report exports as kalibr, opencv-yaml, ros, urdf, mrcal (or report)" });
console.log(`rig ok: 3 cameras, worst camera_from_rig error ${worstT.toExponential(1)} m, ${worstR.toExponential(1)} (rotation entries)`);

// The rig on a robot (`calibrate_rig_handeye`): the same frames as robot
// poses of an eye-in-hand cell with a known gripper_from_rig and
// base_from_target; noise-free, so gripper_from_rig must come back to 1e-6 m.
const { gripperFromRig, input: onRobotInput } = rigOnRobot();
const onRobot = JSON.parse(robocal.calibrate_rig_handeye(JSON.stringify(onRobotInput)));
const solved = onRobot.handeye.gripper_from_rig.matrix_row_major;
let handeyeErr = 0;
for (let i = 0; i < 3; i++) for (let j = 0; j < 4; j++) handeyeErr = Math.max(handeyeErr, Math.abs(solved[i][j] - gripperFromRig[i][j]));
assert.ok(handeyeErr < 1e-6, 'gripper_from_rig error ' + handeyeErr);
assert.deepEqual(onRobot.cameras.map((c) => c.name), ['left', 'middle', 'right']);
assert.throws(() => robocal.calibrate_rig_handeye(JSON.stringify({ ...onRobotInput, extra: 1 })), { message: /unknown field `extra`/ });
console.log(`rig on a robot ok: gripper_from_rig within ${handeyeErr.toExponential(1)} (m and rotation entries)`);
