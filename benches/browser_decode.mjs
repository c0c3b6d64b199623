// The browser's image decoders against the core's (wasm), in headless
// Chromium, on the files given: per file the decode time of each path (the
// core: `image_info`, a whole decode to grey; the browser: createImageBitmap
// without colour conversion, drawn on an OffscreenCanvas, getImageData, and
// the core's luma in JavaScript), how many grey pixels differ and by how
// much, and how far the detected corners move between the two grey images.
// The measurement behind the page's choice of decoder
// (docs/architecture.md, "Image decoding in the page").
//
// Usage (crate root, after `make web cli` and `tools/setup.sh e2e`):
//   node benches/browser_decode.mjs [--reps N] SPEC FILE... [-- SPEC FILE...]
// e.g. node benches/browser_decode.mjs chessboard:9x6:30mm ../shared/datasets/opencv-left-right-9x6/*.jpg
// Only 8-bit grey or colour PNG and JPEG without EXIF orientation are
// compared (what a browser path could take); other files are listed as such.
import { readFileSync } from 'node:fs';
import { basename, resolve } from 'node:path';
import { startServer, launch } from '../tests/e2e/harness.mjs';

const args = process.argv.slice(2);
let reps = 5;
const groups = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--reps') { reps = Number(args[++i]); continue; }
  if (args[i] === '--') continue;
  if (!groups.length || /^[a-z_]+:/.test(args[i])) groups.push({ spec: args[i], files: [] });
  else groups[groups.length - 1].files.push(resolve(args[i])); // absolute: the page fetches it by its path
}
if (!groups.some((g) => g.files.length)) {
  console.log('usage: node benches/browser_decode.mjs [--reps N] SPEC FILE... [-- SPEC FILE...]');
  process.exit(2);
}

const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; };

const server = await startServer();
const browser = await launch();
try {
  const page = await browser.newPage();
  await page.route('**/bench-file/**', (route) => route.fulfill({ body: readFileSync(decodeURIComponent(new URL(route.request().url()).pathname.replace(/^\/bench-file/, ''))) }));
  // An empty page of the app's origin (the app itself is not started), importing its modules.
  await page.route('**/bench-blank.html', (route) => route.fulfill({ contentType: 'text/html', body: '<!doctype html><title>bench</title>' }));
  await page.goto(new URL('bench-blank.html', server.url).href);
  await page.evaluate(async () => {
    const pkg = await import('./pkg/robocal.js');
    await pkg.default();
    pkg.init();
    window.robocal = pkg;
    window.frames = await import('./lib/frames.js');
    // The core's luma (the `image` crate's): 0.2126 R + 0.7152 G + 0.0722 B in ten-thousandths, truncated.
    const coreGrey = (rgba, n) => {
      const grey = new Uint8Array(n);
      for (let i = 0, j = 0; i < n; i++, j += 4) grey[i] = (2126 * rgba[j] + 7152 * rgba[j + 1] + 722 * rgba[j + 2]) / 10000;
      return grey;
    };
    const browserGrey = async (info, bytes) => {
      const blob = new Blob([bytes], { type: info.format === 'png' ? 'image/png' : 'image/jpeg' });
      const bitmap = await createImageBitmap(blob, { colorSpaceConversion: 'none', premultiplyAlpha: 'none', imageOrientation: 'none' });
      const { width, height } = bitmap;
      const ctx = new OffscreenCanvas(width, height).getContext('2d', { willReadFrequently: true });
      ctx.drawImage(bitmap, 0, 0);
      bitmap.close();
      return { grey: coreGrey(ctx.getImageData(0, 0, width, height).data, width * height), width, height };
    };
    window.dec = { coreGrey, browserGrey };
  });
  const rows = [];
  for (const { spec, files } of groups) {
    for (const file of files) {
      const r = await page.evaluate(async ({ path, spec, reps }) => {
        const bytes = new Uint8Array(await (await fetch(`/bench-file${encodeURI(path)}`)).arrayBuffer());
        const { robocal, dec, frames } = window;
        const info = JSON.parse(robocal.image_info(bytes));
        const taken = ['png', 'jpeg'].includes(info.format) && info.bits_per_channel === 8 && [1, 3].includes(info.channels) && !info.exif_orientation;
        const time = async (fn) => { const ts = []; let out; for (let k = 0; k < reps; k++) { const t = performance.now(); out = await fn(); ts.push(performance.now() - t); } ts.sort((a, b) => a - b); return { ms: ts[Math.floor(ts.length / 2)], out }; };
        const wasm = await time(() => robocal.image_info(bytes));
        const res = { info, taken, wasmMs: wasm.ms };
        if (!taken) return res;
        const br = await time(() => dec.browserGrey(info, bytes).catch(() => null));
        res.browserMs = br.ms;
        if (!br.out || br.out.width !== info.width || br.out.height !== info.height) { res.failed = true; return res; }
        // The core's grey: its full-size RGBA preview through the core's luma (R = G = B for grey files).
        const p = robocal.decode_image_preview(bytes, Math.max(info.width, info.height));
        const core = dec.coreGrey(p.image.data, info.width * info.height);
        p.free();
        let differ = 0; let maxDiff = 0; let sum = 0;
        for (let i = 0; i < core.length; i++) { const d = Math.abs(core[i] - br.out.grey[i]); if (d) { differ++; sum += d; maxDiff = Math.max(maxDiff, d); } }
        Object.assign(res, { differ, maxDiff, meanDiff: sum / core.length, pixels: core.length });
        const detect = (b) => { try { return JSON.parse(robocal.detect_target(b, spec)).points; } catch (e) { return String(e.message || e); } };
        const a = detect(bytes);
        const b = detect(frames.pgm(br.out.grey, info.width, info.height));
        if (typeof a === 'string' || typeof b === 'string') {
          res.corners = typeof a === typeof b ? `neither found (${String(a).slice(0, 60)})` : `core: ${typeof a === 'string' ? 'none' : a.length}, browser: ${typeof b === 'string' ? 'none' : b.length}`;
        } else {
          const byId = new Map(b.map((q) => [q.id, q]));
          let move = 0; let same = a.length === b.length;
          for (const q of a) { const o = byId.get(q.id); if (!o) { same = false; continue; } move = Math.max(move, Math.hypot(q.x_px - o.x_px, q.y_px - o.y_px)); }
          res.corners = `${a.length}${same ? '' : ` vs ${b.length}`} corners, max move ${move.toExponential(2)} px`;
        }
        return res;
      }, { path: file, spec, reps });
      rows.push({ file, ...r });
      const what = `${r.info.format_name} ${r.info.width}x${r.info.height} ${r.info.channels}ch ${r.info.bits_per_channel}-bit`;
      if (!r.taken) console.log(`${basename(file)}: ${what}: not compared (not 8-bit grey or colour, or turned by EXIF); core ${r.wasmMs.toFixed(2)} ms`);
      else if (r.failed) console.log(`${basename(file)}: ${what}: the browser could not decode it; core ${r.wasmMs.toFixed(2)} ms`);
      else console.log(`${basename(file)}: ${what}: core ${r.wasmMs.toFixed(2)} ms, browser ${r.browserMs.toFixed(2)} ms; grey differs at ${r.differ} of ${r.pixels} px (max ${r.maxDiff}, mean ${r.meanDiff.toFixed(4)}); ${r.corners}`);
    }
  }
  const taken = rows.filter((r) => r.taken && !r.failed);
  if (taken.length) {
    console.log(`summary: ${taken.length} of ${rows.length} files compared; median decode core ${median(taken.map((r) => r.wasmMs)).toFixed(2)} ms, browser ${median(taken.map((r) => r.browserMs)).toFixed(2)} ms; `
      + `grey exact in ${taken.filter((r) => r.differ === 0).length}, largest difference ${Math.max(...taken.map((r) => r.maxDiff))} grey levels`);
  }
} finally {
  await browser.close();
  server.stop();
}
