// Time the wasm build on the work the web app does, to compare wasm builds
// (opt-level, profile) by size AND speed: decode_image_preview and
// detect_target on the demo images and on dataset JPEGs, calibrate_camera
// (Zhang + refinement) on the demo detections, render_demo itself.
// Usage (crate root, after `make pkg` or a wasm-bindgen --target nodejs build):
//   node bench/wasm_profile.mjs [--repeat N] [PKG_JS] [IMAGES...]
// PKG_JS defaults to pkg/node/robocal.js. Prints medians in ms.
import { createRequire } from 'node:module';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { performance } from 'node:perf_hooks';

const args = process.argv.slice(2);
let repeat = 7;
if (args[0] === '--repeat') {
  repeat = Number(args[1]);
  args.splice(0, 2);
}
const pkg = args[0] && args[0].endsWith('.js') ? args.shift() : 'pkg/node/robocal.js';
const robocal = createRequire(import.meta.url)(resolve(pkg));

function median(f, n = repeat) {
  const times = [];
  let out;
  for (let k = 0; k < n; k++) {
    const t0 = performance.now();
    out = f();
    times.push(performance.now() - t0);
  }
  times.sort((a, b) => a - b);
  return [times[Math.floor(n / 2)], out];
}

// render_demo takes seconds: timed once.
const [renderMs, demo] = median(() => robocal.render_demo(1), 1);
const meta = JSON.parse(demo.json);
const images = meta.images.map((im) => demo.bytes.subarray(im.offset, im.offset + im.length));
const rows = [['render_demo (12 PNGs 1024x768, once)', renderMs]];
const [previewMs] = median(() => images.map((b) => robocal.decode_image_preview(b, 256)));
rows.push(['decode_image_preview x12 (PNG)', previewMs]);
const [detectMs, views] = median(() =>
  images.map((b, i) => ({ name: `v${i}`, detection: JSON.parse(robocal.detect_target(b, meta.target_spec)) })),
);
rows.push(['detect_target x12 (PNG 1024x768)', detectMs]);
const request = JSON.stringify({ model: 'brown', method: 'zhang', views });
const [calibMs, calib] = median(() => JSON.parse(robocal.calibrate_camera(request)));
rows.push(['calibrate_camera (12 views, brown, zhang)', calibMs]);
if (args.length > 0) {
  const files = args.map((f) => readFileSync(f));
  const [jpegMs, found] = median(() =>
    files.map((b) => {
      try {
        return JSON.parse(robocal.detect_target(b, 'chessboard:9x6:25mm')).points.length;
      } catch {
        return 0;
      }
    }),
  );
  rows.push([`detect_target x${files.length} (given files, ${found.filter((n) => n > 0).length} found)`, jpegMs]);
}
for (const [name, ms] of rows) console.log(`${name.padEnd(48)} ${ms.toFixed(1).padStart(8)} ms`);
console.log(`rms ${calib.report.rms_px.toFixed(6)} px, fx ${calib.report.camera_matrix[0][0].toFixed(6)} (node ${process.version}, median of ${repeat})`);
