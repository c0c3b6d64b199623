// Time the wasm build's detect_target (PNG decoding + detection) under node
// on rendered images; compare with the native
// `cargo run --release --example detect_time -- --decode FILES`.
// Usage (crate root, after `make pkg` and benches/compare_opencv.py):
//   node benches/wasm_detect.mjs [--repeat N] [--decode-only] FILES...
import { createRequire } from "node:module";
import { readFileSync } from "node:fs";
import { performance } from "node:perf_hooks";

const require = createRequire(import.meta.url);
const robocal = require("../pkg/node/robocal.js");

const args = process.argv.slice(2);
let repeat = 11;
// --decode-only: time image_info (the same full decode, no detection), so
// that detection alone ~ detect_target median - this median.
let decodeOnly = false;
const files = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === "--repeat") repeat = Number(args[++i]);
  else if (args[i] === "--decode-only") decodeOnly = true;
  else files.push(args[i]);
}
const medians = [];
for (const f of files) {
  const bytes = readFileSync(f);
  const times = [];
  let points = null;
  for (let k = 0; k < repeat; k++) {
    const t0 = performance.now();
    try {
      points = decodeOnly
        ? JSON.parse(robocal.image_info(bytes)).width
        : JSON.parse(robocal.detect_target(bytes, "chessboard:9x6:30mm")).points.length;
    } catch (e) {
      points = null;
    }
    times.push(performance.now() - t0);
  }
  times.sort((a, b) => a - b);
  const ms = times[Math.floor(repeat / 2)];
  medians.push(ms);
  console.log(`${f}: ${ms.toFixed(3)} ms, ${points} points`);
}
medians.sort((a, b) => a - b);
console.log(`median over ${medians.length} files: ${medians[Math.floor(medians.length / 2)].toFixed(3)} ms (wasm, node ${process.version}${decodeOnly ? ", decode only" : ""})`);
