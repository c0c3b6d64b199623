// Time marker-board detection (ChArUco, AprilGrid) in the wasm build under
// node on frames rendered by `robocal render` (issue 18's goal: at most
// 15 ms per 1280x720 frame). The wasm API takes image bytes, so each frame
// is timed twice: detect_target (PNG decode + detection) and image_info (the
// same decode alone); detection ~ the difference of the two medians.
// Usage (crate root, after `make pkg cli`):
//   robocal render --out DIR --target SPEC --camera cam1280x720.yaml --views N
//   node benches/wasm_detect_markers.mjs [--repeat N] DIR...
// Each DIR's truth.json names the target; corners are checked against it.
import { createRequire } from "node:module";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { performance } from "node:perf_hooks";

const require = createRequire(import.meta.url);
const robocal = require("../pkg/node/robocal.js");

const args = process.argv.slice(2);
let repeat = 11;
const dirs = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === "--repeat") repeat = Number(args[++i]);
  else dirs.push(args[i]);
}

function median(xs) {
  const s = [...xs].sort((a, b) => a - b);
  return s[Math.floor(s.length / 2)];
}

function timed(fn) {
  const times = [];
  let out = null;
  for (let k = 0; k < repeat; k++) {
    const t0 = performance.now();
    out = fn();
    times.push(performance.now() - t0);
  }
  return [median(times), out];
}

for (const dir of dirs) {
  const truth = JSON.parse(readFileSync(join(dir, "truth.json"), "utf8"));
  const spec = truth.target.spec ?? truth.target;
  const specText = typeof spec === "string" ? spec : JSON.stringify(spec);
  const det = [];
  for (const view of truth.views) {
    const bytes = readFileSync(join(dir, view.image));
    const [decodeMs, info] = timed(() => JSON.parse(robocal.image_info(bytes)));
    const [allMs, found] = timed(() => {
      try {
        return JSON.parse(robocal.detect_target(bytes, specText)).points;
      } catch (e) {
        return [];
      }
    });
    const byId = new Map(view.points.map((p) => [p.id, p]));
    const errs = found
      .filter((p) => byId.has(p.id))
      .map((p) => Math.hypot(p.x_px - byId.get(p.id).x_px, p.y_px - byId.get(p.id).y_px));
    const mean = errs.reduce((a, b) => a + b, 0) / Math.max(errs.length, 1);
    det.push(allMs - decodeMs);
    console.log(
      `${join(dir, view.image)} ${info.width}x${info.height}: decode+detect ${allMs.toFixed(2)} ms, ` +
        `decode ${decodeMs.toFixed(2)} ms, detection ~${(allMs - decodeMs).toFixed(2)} ms; ` +
        `${found.length} of ${view.points.length} corners, mean error ${mean.toFixed(4)} px`,
    );
  }
  console.log(`${dir} (${specText}): median detection ${median(det).toFixed(2)} ms over ${det.length} frames (wasm, node ${process.version}, median of ${repeat} calls per frame)`);
}
