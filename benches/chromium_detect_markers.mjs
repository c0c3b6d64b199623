// Time marker-board detection (ChArUco, AprilGrid) in headless Chromium
// (issue 18's goal: at most 15 ms per 1280x720 frame in wasm), the page's
// own wasm build (www/pkg, after `make web`) loaded in a page served by
// `robocal serve`. As benches/wasm_detect_markers.mjs does in node, each frame
// is timed twice: detect_target (PNG decode + detection) and image_info
// (the same decode alone); detection ~ the difference of the two medians.
// Usage (crate root, after `make web cli`; frames from `robocal render`):
//   node benches/chromium_detect_markers.mjs [--repeat N] [--www DIR] DIR...
// Each DIR's truth.json names the target; corners are checked against it.
import { createRequire } from "node:module";
import { spawn } from "node:child_process";
import { readFileSync } from "node:fs";
import { join, resolve } from "node:path";

const require = createRequire(import.meta.url);
const { chromium } = require("../tests/e2e/node_modules/playwright-core");

const args = process.argv.slice(2);
let repeat = 11;
let www = "www";
const dirs = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === "--repeat") repeat = Number(args[++i]);
  else if (args[i] === "--www") www = args[++i];
  else dirs.push(args[i]);
}

const port = 18000 + (process.pid % 1000);
const server = spawn("target/release/robocal", ["serve", resolve(www), "--port", String(port)], {
  stdio: ["ignore", "ignore", "inherit"],
});
const base = `http://127.0.0.1:${port}/`;
const browser = await chromium.launch({
  executablePath: "/usr/bin/chromium",
  args: [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
  ],
});

function median(xs) {
  const s = [...xs].sort((a, b) => a - b);
  return s[Math.floor(s.length / 2)];
}

try {
  const page = await browser.newPage();
  // The server needs a moment to bind: retry the first page load.
  for (let k = 0; ; k++) {
    try {
      await page.goto(base + "pkg/robocal.js");
      break;
    } catch (e) {
      if (k > 50) throw e;
      await new Promise((r) => setTimeout(r, 100));
    }
  }
  await page.evaluate(async () => {
    const m = await import("/pkg/robocal.js");
    await m.default();
    globalThis.robocal = m;
  });
  const version = await browser.version();
  for (const dir of dirs) {
    const truth = JSON.parse(readFileSync(join(dir, "truth.json"), "utf8"));
    const spec = truth.target.spec ?? truth.target;
    const specText = typeof spec === "string" ? spec : JSON.stringify(spec);
    const det = [];
    for (const view of truth.views) {
      const bytes = [...readFileSync(join(dir, view.image))];
      const r = await page.evaluate(
        ({ bytes, specText, repeat }) => {
          const data = new Uint8Array(bytes);
          const m = globalThis.robocal;
          const timed = (fn) => {
            const times = [];
            let out = null;
            for (let k = 0; k < repeat; k++) {
              const t0 = performance.now();
              out = fn();
              times.push(performance.now() - t0);
            }
            times.sort((a, b) => a - b);
            return [times[Math.floor(times.length / 2)], out];
          };
          const [decodeMs, info] = timed(() => JSON.parse(m.image_info(data)));
          const [allMs, points] = timed(() => {
            try {
              return JSON.parse(m.detect_target(data, specText)).points;
            } catch (e) {
              return [];
            }
          });
          return { decodeMs, allMs, points, width: info.width, height: info.height };
        },
        { bytes, specText, repeat },
      );
      const byId = new Map(view.points.map((p) => [p.id, p]));
      const errs = r.points
        .filter((p) => byId.has(p.id))
        .map((p) => Math.hypot(p.x_px - byId.get(p.id).x_px, p.y_px - byId.get(p.id).y_px));
      const mean = errs.reduce((a, b) => a + b, 0) / Math.max(errs.length, 1);
      det.push(r.allMs - r.decodeMs);
      console.log(
        `${join(dir, view.image)} ${r.width}x${r.height}: decode+detect ${r.allMs.toFixed(2)} ms, ` +
          `decode ${r.decodeMs.toFixed(2)} ms, detection ~${(r.allMs - r.decodeMs).toFixed(2)} ms; ` +
          `${r.points.length} of ${view.points.length} corners, mean error ${mean.toFixed(4)} px`,
      );
    }
    console.log(
      `${dir} (${specText}): median detection ${median(det).toFixed(2)} ms over ${det.length} frames ` +
        `(wasm, Chromium ${version}, page main thread, median of ${repeat} calls per frame)`,
    );
  }
} finally {
  await browser.close();
  server.kill();
}
