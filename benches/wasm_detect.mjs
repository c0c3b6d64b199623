// Time the wasm build's detect_target (PNG decoding + detection) under node
// on rendered images; compare with the native
// `target/release/examples/detect_time --decode FILES` (decode + detect) and
// `detect_time FILES` (detection alone).
// Usage (crate root, after `make pkg`):
//   node benches/wasm_detect.mjs [--repeat N] [--target SPEC]
//        [--decode-only | --detect-only] FILES...
// --decode-only: time image_info (the same full decode, no detection).
// --detect-only: decode each file once (decode_image_preview keeping the
//   grey image), then time the preview's detect_target: detection alone,
//   plus the Detection JSON and the boundary crossing, no decode.
import { createRequire } from "node:module";
import { readFileSync } from "node:fs";
import { performance } from "node:perf_hooks";

const require = createRequire(import.meta.url);
const robocal = require("../pkg/node/robocal.js");

// node has no ImageData; the preview's thumbnail needs one.
globalThis.ImageData ??= class ImageData {
  constructor(data, width, height) {
    Object.assign(this, { data, width, height });
  }
};

const args = process.argv.slice(2);
let repeat = 11;
let target = "chessboard:9x6:30mm";
let mode = "decode+detect";
const files = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === "--repeat") repeat = Number(args[++i]);
  else if (args[i] === "--target") target = args[++i];
  else if (args[i] === "--decode-only") mode = "decode only";
  else if (args[i] === "--detect-only") mode = "detect only";
  else files.push(args[i]);
}
const medians = [];
for (const f of files) {
  const bytes = readFileSync(f);
  const preview = mode === "detect only" ? robocal.decode_image_preview(bytes, 64, undefined, true) : null;
  const times = [];
  let points = null;
  for (let k = 0; k < repeat; k++) {
    const t0 = performance.now();
    try {
      if (mode === "decode only") points = JSON.parse(robocal.image_info(bytes)).width;
      else if (preview) points = JSON.parse(preview.detect_target(target)).points.length;
      else points = JSON.parse(robocal.detect_target(bytes, target)).points.length;
    } catch (e) {
      points = null;
    }
    times.push(performance.now() - t0);
  }
  preview?.free();
  times.sort((a, b) => a - b);
  const ms = times[Math.floor(repeat / 2)];
  medians.push(ms);
  console.log(`${f}: ${ms.toFixed(3)} ms, ${points} points`);
}
medians.sort((a, b) => a - b);
console.log(`median over ${medians.length} files: ${medians[Math.floor(medians.length / 2)].toFixed(3)} ms (wasm, node ${process.version}, ${mode})`);
