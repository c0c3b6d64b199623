// A batch of images in the page, upload to result, with 1, 2, ... workers:
// headless Chromium opens the app with navigator.hardwareConcurrency set to
// the worker count (app.js sizes its EnginePool by it, at most 4), uploads
// every image of DIR, waits for "detected N of N", then solves the camera
// (Zhang, the default lens model). Printed per worker count: the median
// (and every run) of upload + decode + detect, of the solve and of the sum,
// and how the decode and detect requests spread over the workers (counted
// by wrapping the page's Worker class; nothing in the page is changed).
//
// Usage (crate root, after `make web cli` and `tools/setup.sh e2e`):
//   node benches/page_batch.mjs DIR [--workers 1,2] [--runs 3]
// DIR holds the images (.png/.jpg) of a chessboard 9x6 (the page's default
// target), e.g. `robocal render --out DIR --camera
// fixtures/exports/camera.ros.yaml --views 20 --seed 7`, converted to JPEG
// for a JPEG batch. The first run of each count starts the workers (wasm
// compile and instantiation): it is printed, the median is of every run.
import { readdirSync } from 'node:fs';
import { join } from 'node:path';
import { startServer, launch } from '../tests/e2e/harness.mjs';
import { uploadAndDetect } from '../tests/e2e/datasets.mjs';

const args = process.argv.slice(2);
const opt = (name, dflt) => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : dflt; };
const dir = args[0];
if (!dir || dir.startsWith('--')) {
  console.log('usage: node benches/page_batch.mjs DIR [--workers 1,2] [--runs 3]');
  process.exit(2);
}
const counts = opt('--workers', '1,2').split(',').map(Number);
const runs = Number(opt('--runs', '3'));
const files = readdirSync(dir).filter((f) => /\.(png|jpe?g)$/i.test(f)).sort().map((f) => join(dir, f));
const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; };

const server = await startServer();
const browser = await launch();
try {
  for (const n of counts) {
    const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
    await context.addInitScript((k) => {
      Object.defineProperty(Navigator.prototype, 'hardwareConcurrency', { get: () => k });
      // Which worker ran which request: every engine worker counts its posts.
      const Base = window.Worker;
      window.engineRequests = [];
      window.Worker = class extends Base {
        constructor(url, options) {
          super(url, options);
          const mine = {};
          window.engineRequests.push(mine);
          const post = this.postMessage.bind(this);
          this.postMessage = (msg, transfer) => { if (msg && msg.op) mine[msg.op] = (mine[msg.op] || 0) + 1; return post(msg, transfer); };
        }
      };
    }, n);
    const page = await context.newPage();
    await page.goto(server.url);
    await page.locator('#engine-status.ready').waitFor({ timeout: 60000 });
    const detect = [];
    const solve = [];
    for (let run = 0; run < runs; run++) {
      await page.click('a[data-step=images]');
      await page.click('#clear-images');
      await page.waitForFunction(() => document.querySelectorAll('.card').length === 0 && document.getElementById('progress-row').hidden, null, { timeout: 10000 });
      await page.$eval('#progress-text', (el) => { el.textContent = ''; });
      const t0 = Date.now();
      await uploadAndDetect(page, files);
      detect.push(Date.now() - t0);
      const summary = await page.textContent('#image-summary');
      if (!summary.startsWith(`${files.length} files, ${files.length} decoded, ${files.length} with the target`)) throw new Error(`not every image detected: ${summary}`);
      const t1 = Date.now();
      await page.click('a[data-step=camera]');
      await page.click('#solve-camera');
      await page.locator('#camera-params').waitFor({ timeout: 120000 });
      solve.push(Date.now() - t1);
    }
    const spread = await page.evaluate(() => window.engineRequests.map((r) => `${r.preview || 0}+${(r.detect || 0) + (r.boards || 0)}`));
    const total = detect.map((d, i) => d + solve[i]);
    console.log(`${n} worker${n === 1 ? '' : 's'}: ${files.length} files, upload + decode + detect median ${median(detect)} ms [${detect.join(', ')}], solve median ${median(solve)} ms [${solve.join(', ')}], `
      + `total median ${median(total)} ms [${total.join(', ')}]; previews+detections per worker over ${runs} runs: ${spread.join(', ')}`);
    await context.close();
  }
} finally {
  await browser.close();
  server.stop();
}
