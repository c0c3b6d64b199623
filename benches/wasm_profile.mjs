// Time the wasm build on the work the web app does, to compare wasm builds
// (opt-level, profile) by size AND speed: decode_image_preview and
// detect_target on the demo images and on dataset JPEGs, calibrate_camera
// (Zhang + refinement) on the demo detections, render_demo itself.
// Usage (crate root, after `make pkg` or a wasm-bindgen --target nodejs build):
//   node benches/wasm_profile.mjs [--repeat N] [PKG_JS ...] [IMAGES...]
// PKG_JS (any argument ending in .js) defaults to pkg/node/robocal.js. With
// several, every build is loaded into this one process and they take turns,
// repetition by repetition (A B C A B C ...), so that they are compared in
// the same run; the demo images and detections all come from the first
// build. Prints medians in ms, one column per build.
// Builds whose decode_image_preview returns a web_sys::ImageData (issue 16
// on) need an `ImageData` class, which node lacks: a minimal stand-in with
// the constructor (data, width, height) is installed when there is none.
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
const pkgPaths = [];
while (args[0] && args[0].endsWith('.js')) pkgPaths.push(args.shift());
if (pkgPaths.length === 0) pkgPaths.push('pkg/node/robocal.js');
if (typeof globalThis.ImageData === 'undefined') {
  globalThis.ImageData = class ImageData {
    constructor(data, width, height) {
      this.data = data;
      this.width = width;
      this.height = height;
    }
  };
}
const require = createRequire(import.meta.url);
const builds = pkgPaths.map((p) => require(resolve(p)));
const first = builds[0];

// Medians per build of f(build), the builds alternating within each repetition.
function medians(f, n = repeat) {
  const times = builds.map(() => []);
  const outs = [];
  for (let k = 0; k < n; k++) {
    builds.forEach((b, i) => {
      const t0 = performance.now();
      outs[i] = f(b);
      times[i].push(performance.now() - t0);
    });
  }
  return [times.map((t) => t.sort((a, b) => a - b)[Math.floor(n / 2)]), outs];
}

// render_demo takes seconds: timed once per build.
const [renderMs, demos] = medians((b) => b.render_demo(1), 1);
const demo = demos[0];
const meta = JSON.parse(demo.json);
const images = meta.images.map((im) => demo.bytes.subarray(im.offset, im.offset + im.length));
const rows = [['render_demo (12 PNGs 1024x768, once)', renderMs]];
const [previewMs] = medians((b) => images.map((x) => b.decode_image_preview(x, 256).free()));
rows.push(['decode_image_preview x12 (PNG)', previewMs]);
const [infoMs] = medians((b) => images.map((x) => b.image_info(x)));
rows.push(['image_info x12 (PNG decode only)', infoMs]);
const [detectMs] = medians((b) =>
  images.map((x, i) => ({ name: `v${i}`, detection: JSON.parse(b.detect_target(x, meta.target_spec)) })),
);
rows.push(['detect_target x12 (PNG 1024x768)', detectMs]);
const views = images.map((x, i) => ({ name: `v${i}`, detection: JSON.parse(first.detect_target(x, meta.target_spec)) }));
const request = JSON.stringify({ model: 'brown', method: 'zhang', views });
const [calibMs, calibs] = medians((b) => JSON.parse(b.calibrate_camera(request)));
rows.push(['calibrate_camera (12 views, brown, zhang)', calibMs]);
const requestAll = JSON.stringify({ model: 'brown', method: 'all', views });
const [calibAllMs] = medians((b) => JSON.parse(b.calibrate_camera(requestAll)));
rows.push(['calibrate_camera (12 views, brown, all 4 methods)', calibAllMs]);
if (args.length > 0) {
  const files = args.map((f) => readFileSync(f));
  const [jpegMs, found] = medians((b) =>
    files.map((x) => {
      try {
        return JSON.parse(b.detect_target(x, 'chessboard:9x6:25mm')).points.length;
      } catch {
        return 0;
      }
    }),
  );
  rows.push([`detect_target x${files.length} (given files, ${found[0].filter((n) => n > 0).length} found)`, jpegMs]);
}
if (builds.length > 1) {
  console.log(`${''.padEnd(48)} ${pkgPaths.map((_, i) => `build ${i + 1}`.padStart(11)).join('')}`);
  pkgPaths.forEach((p, i) => console.log(`  build ${i + 1}: ${p}`));
}
for (const [name, ms] of rows) console.log(`${name.padEnd(48)} ${ms.map((x) => `${x.toFixed(1).padStart(8)} ms`).join('')}`);
calibs.forEach((calib, i) =>
  console.log(`build ${i + 1}: rms ${calib.report.rms_px.toFixed(6)} px, fx ${calib.report.camera_matrix[0][0].toFixed(6)}`),
);
console.log(`node ${process.version}, median of ${repeat}`);
