// Time the wasm build's solvers (the code the `wasm` cargo profile builds
// for size) on the demo data: camera calibration (all four methods and the
// rational model), stereo, hand-eye from detections with refinement and
// bootstrap repeatability, joint refinement with intrinsics, planar fit.
// Usage (crate root, after `make pkg`):
//   node benches/wasm_solvers.mjs [--repeat N] [PKG_JS]
// PKG_JS defaults to pkg/node/robocal.js. Prints medians in ms.
import { createRequire } from 'node:module';
import { resolve } from 'node:path';
import { performance } from 'node:perf_hooks';

const args = process.argv.slice(2);
let repeat = 5;
if (args[0] === '--repeat') {
  repeat = Number(args[1]);
  args.splice(0, 2);
}
const robocal = createRequire(import.meta.url)(resolve(args[0] ?? 'pkg/node/robocal.js'));

function median(f) {
  const times = [];
  let out;
  for (let k = 0; k < repeat; k++) {
    const t0 = performance.now();
    out = f();
    times.push(performance.now() - t0);
  }
  times.sort((a, b) => a - b);
  return [times[Math.floor(repeat / 2)], out];
}
const call = (fn, request) => JSON.parse(robocal[fn](JSON.stringify(request)));

const demo = robocal.render_demo(1);
const meta = JSON.parse(demo.json);
const png = (im) => demo.bytes.subarray(im.offset, im.offset + im.length);
const detections = meta.images.map((im) => JSON.parse(robocal.detect_target(png(im), meta.target_spec)));
const views = meta.images.map((im, i) => ({ name: im.name, detection: detections[i] }));
const poses = JSON.parse(robocal.read_robot_poses(meta.poses_csv, '{}'));
const base_from_gripper = poses.parsed.poses.map((p) => p.base_from_gripper);
const board = (d) => d.points.map((p) => [(p.id % 9) * 0.03, Math.floor(p.id / 9) * 0.03, 0]);
const pixels = (d) => d.points.map((p) => [p.x_px, p.y_px]);

const rows = [];
const [allMs, all] = median(() => call('calibrate_camera', { model: 'brown', method: 'all', views }));
rows.push(['calibrate_camera (12 views, brown, all 4 methods)', allMs]);
const [ratMs] = median(() => call('calibrate_camera', { model: 'rational', views }));
rows.push(['calibrate_camera (12 views, rational)', ratMs]);
const [stereoMs] = median(() => call('calibrate_stereo', { left: views, right: views }));
rows.push(['calibrate_stereo (12 pairs, brown)', stereoMs]);
const [heMs, he] = median(() =>
  call('solve_handeye', { setup: 'eye-in-hand', base_from_gripper, detections, camera: all, bootstrap_samples: 20 }),
);
rows.push(['solve_handeye (12 poses, refined, 20 bootstrap samples)', heMs]);
const report = all.report;
const [jointMs] = median(() =>
  call('solve_handeye', {
    setup: 'eye-in-hand',
    base_from_gripper,
    camera_from_target: report.views.map((v) => v.camera_from_target),
    views: detections.map((d) => ({ object_m: board(d), image_px: pixels(d) })),
    camera: report.camera,
    refine: 'joint_intrinsics',
    bootstrap_samples: 0,
  }),
);
rows.push(['solve_handeye (joint with intrinsics)', jointMs]);
for (const [name, ms] of rows) console.log(`${name.padEnd(58)} ${ms.toFixed(1).padStart(8)} ms`);
console.log(`hand-eye translation ${JSON.stringify(he.gripper_from_camera?.translation_m)} (node ${process.version}, median of ${repeat})`);
