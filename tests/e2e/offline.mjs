// Offline use: the service worker precaches every file of the app, a new
// version's worker replaces the old cache, and once loaded the page starts
// and runs the demo flow with the network gone (the browser context offline
// AND the server stopped, so nothing can come from the network).
import assert from 'node:assert/strict';
import { readFileSync, readdirSync, statSync } from 'node:fs';
import { join, relative } from 'node:path';
import { root, startServer } from './harness.mjs';

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 60000 });
const www = join(root, 'www');

function filesUnder(dir) {
  return readdirSync(dir).flatMap((f) => {
    const p = join(dir, f);
    return statSync(p).isDirectory() ? filesUnder(p) : [relative(www, p)];
  });
}

/** Evaluates `fn(arg)` in the page (it may be async) until it returns true. */
async function poll(page, fn, arg, timeout = 30000) {
  const end = Date.now() + timeout;
  for (;;) {
    const value = await page.evaluate(fn, arg);
    if (value === true) return;
    if (Date.now() > end) throw new Error(`timed out; last value ${JSON.stringify(value)}`);
    await page.waitForTimeout(200);
  }
}

/** Waits until the page is controlled by the service worker of `version`. */
async function controlled(page) {
  await page.waitForFunction(() => navigator.serviceWorker.controller
    && /sw\.js\?v=\d+\.\d+\.\d+/.test(navigator.serviceWorker.controller.scriptURL), null, { timeout: 30000 });
}

export const tests = [
  ['the precache list names every file the app loads', async () => {
    const text = readFileSync(join(www, 'sw.js'), 'utf8');
    const list = JSON.parse(/const SHELL = (\[[^\]]*\]);/.exec(text)[1].replace(/'/g, '"').replace(/,\s*\]/, ']'));
    const app = filesUnder(www).filter((f) => /\.(html|css|js|wasm)$/.test(f) && f !== 'sw.js' && (!f.startsWith('pkg/') || /^pkg\/robocal(\.js|_bg\.wasm)$/.test(f)));
    assert.deepEqual(list.filter((f) => f !== './').sort(), app.sort());
  }],
  ['a new version replaces the old cache', async (page, { url }) => {
    await page.goto(url);
    await ready(page);
    // An older build's worker and cache, as a previous visit would have left them.
    await page.evaluate(async () => {
      for (const r of await navigator.serviceWorker.getRegistrations()) await r.unregister();
      for (const k of await caches.keys()) await caches.delete(k);
      await navigator.serviceWorker.register('./sw.js?v=0.0.1-old');
      await navigator.serviceWorker.ready;
    });
    await poll(page, async () => (await caches.keys()).includes('robocal-0.0.1-old') || (await caches.keys()));
    await page.reload();
    await ready(page);
    await controlled(page);
    const version = (await page.textContent('#version')).replace(/^robocal /, '');
    await poll(page, async (v) => JSON.stringify(await caches.keys()) === JSON.stringify([`robocal-${v}`]) || (await caches.keys()), version);
    const cached = await page.evaluate(async (v) => (await (await caches.open(`robocal-${v}`)).keys()).map((r) => new URL(r.url).pathname), version);
    // Every precached file (the shell, modules, the wasm) is in the new cache.
    for (const f of ['/', '/index.html', '/app.js', '/worker.js', '/pkg/robocal.js', '/pkg/robocal_bg.wasm', '/views/rig.js']) assert.ok(cached.includes(f), `${f} not cached: ${cached.join(' ')}`);
  }],
  ['loaded once, the app starts and runs the demo offline', async (page, { shot }) => {
    // A server of its own, stopped below: offline means no server at all.
    const server = await startServer();
    try {
      await page.goto(server.url);
      await ready(page);
      await controlled(page);
    } finally {
      server.stop();
    }
    await page.context().setOffline(true);
    await page.reload();
    await ready(page);
    assert.match(await page.textContent('#engine-status'), /^Calibration engine ready/);
    await page.click('#demo-button');
    await page.waitForFunction(() => /12 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 180000 });
    await page.click('a[data-step=camera]');
    await page.click('#solve-camera');
    await page.locator('#camera-params').waitFor({ timeout: 60000 });
    const fx = Number(await page.$eval('#camera-params tbody', (tb) => [...tb.rows].find((r) => r.cells[0].textContent === 'fx').cells[1].textContent));
    // The demo camera has fx = 900 px (src/synth/demo.rs).
    assert.ok(Math.abs(fx - 900) < 1.5, `fx ${fx}`);
    await shot('offline-solved');
  }],
];
