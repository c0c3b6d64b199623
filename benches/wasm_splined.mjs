// Time a splined fit in the wasm build (issue 41: "a splined fit of 40 views
// x 100 points in the browser under 10 s"): 40 views of a 10x10 board
// (30 mm pitch) through a fisheye (Kannala-Brandt, fx 420 on 1280x960),
// 0.1 px noise, every view with all 100 points in the image, solved with
// `calibrate_camera` and the default 12x8 cubic spline (its parametric
// pre-fit included).
// Usage (crate root, after `make pkg`):
//   node benches/wasm_splined.mjs [--repeat N] [--knots NXxNY] [--dump FILE] [PKG_JS]
// PKG_JS defaults to pkg/node/robocal.js. Prints each solve's time and the median.
// --dump FILE writes the input JSON and exits (the native timing reads it:
// `cargo run --release --example splined_time -- FILE`).
import { createRequire } from 'node:module';
import { writeFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { performance } from 'node:perf_hooks';

const args = process.argv.slice(2);
let repeat = 3;
let knots = null;
let dump = null;
while (args[0]?.startsWith('--')) {
  const [flag, value] = args.splice(0, 2);
  if (flag === '--repeat') repeat = Number(value);
  else if (flag === '--knots') knots = value.split('x').map(Number);
  else if (flag === '--dump') dump = value;
  else throw new Error(`unknown flag ${flag}`);
}

// A seeded generator (xorshift) and Gaussian noise (Box-Muller).
let state = 0x9e3779b9;
const uniform = () => {
  state ^= state << 13; state >>>= 0;
  state ^= state >>> 17;
  state ^= state << 5; state >>>= 0;
  return state / 4294967296;
};
const gaussian = (sigma) => sigma * Math.sqrt(-2 * Math.log(1 - uniform())) * Math.cos(2 * Math.PI * uniform());

const [W, H, fx, fy, cx, cy] = [1280, 960, 420, 419.5, 639.5, 479.5];
const k = [0.045, -0.012, 0.0021, -0.0004];
function project([x, y, z]) {
  const r = Math.hypot(x, y);
  const th = Math.atan2(r, z);
  const t2 = th * th;
  const d = th * (1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
  const s = r > 0 ? d / r : 1 / z;
  return [fx * x * s + cx, fy * y * s + cy];
}
// Rotation from Euler angles (x, then y, then z), applied to a point.
function rotate([a, b, c], [x, y, z]) {
  [y, z] = [Math.cos(a) * y - Math.sin(a) * z, Math.sin(a) * y + Math.cos(a) * z];
  [x, z] = [Math.cos(b) * x + Math.sin(b) * z, -Math.sin(b) * x + Math.cos(b) * z];
  [x, y] = [Math.cos(c) * x - Math.sin(c) * y, Math.sin(c) * x + Math.cos(c) * y];
  return [x, y, z];
}

const board = [];
for (let r = 0; r < 10; r++) for (let c = 0; c < 10; c++) board.push([c * 0.03, r * 0.03, 0]);
const views = [];
while (views.length < 40) {
  const angles = [0.7 * (uniform() - 0.5), 0.9 * (uniform() - 0.5), 0.6 * (uniform() - 0.5)];
  const depth = 0.18 + 0.25 * uniform();
  // The board's centre towards a random direction within about 70 deg.
  const dir = [1.8 * (uniform() - 0.5), 1.3 * (uniform() - 0.5), 1];
  const centre = dir.map((v) => (v * depth) / Math.hypot(...dir));
  const image = board.map((p) => {
    const q = rotate(angles, [p[0] - 0.135, p[1] - 0.135, 0]);
    return project([q[0] + centre[0], q[1] + centre[1], q[2] + centre[2]]);
  });
  if (!image.every(([u, v]) => u >= 0 && v >= 0 && u <= W - 1 && v <= H - 1)) continue;
  views.push({
    name: `v${views.length}`,
    object_m: board,
    image_px: image.map(([u, v]) => [u + gaussian(0.1), v + gaussian(0.1)]),
  });
}
const options = knots ? { spline_knots: knots } : {};
const input = JSON.stringify({ model: 'splined', options, views, image_size_px: [W, H] });
if (dump) {
  writeFileSync(dump, input);
  process.exit(0);
}
const robocal = createRequire(import.meta.url)(resolve(args[0] ?? 'pkg/node/robocal.js'));
const times = [];
let report;
for (let i = 0; i < repeat; i++) {
  const t0 = performance.now();
  const c0 = process.cpuUsage();
  report = JSON.parse(robocal.calibrate_camera(input)).report;
  times.push((performance.now() - t0) / 1000);
  // CPU time (the solve is single-threaded): the wall time on an idle
  // machine, whatever else the machine runs.
  const cpu = process.cpuUsage(c0);
  console.log(`splined fit ${i + 1}: ${times[i].toFixed(2)} s wall, ${((cpu.user + cpu.system) / 1e6).toFixed(2)} s CPU, rms ${report.rms_px.toFixed(4)} px, ${report.n_points} points`);
}
times.sort((a, b) => a - b);
console.log(`median ${times[Math.floor(repeat / 2)].toFixed(2)} s over ${repeat} fits of 40 views x 100 points (${report.distortion ? Object.keys(report.distortion).length : 0} spline coefficients)`);
