// Time to "engine ready" in headless Chromium: from the start of the
// navigation (the page's performance.timeOrigin) until app.js marks
// #engine-status with the class `ready` (the worker has fetched, compiled and
// instantiated the wasm, run `init` and answered `version`).
//
//   cold: a new browser with a new, empty --user-data-dir (no HTTP cache, no
//         service worker, no compiled-code cache), first load of the page;
//   warm: the next load(s) in the same browser profile, once the service
//         worker (www/sw.js) is active and its cache holds the wasm.
//
// Several builds are compared in one run: each is served from its own folder
// by `robocal serve --dir DIR --port 0` (one CLI for all of them, so only the
// page and the wasm differ), and the builds take turns, run by run (A B A B
// ...), so that a slow spell of the machine hits them alike.
//
// Usage (crate root, after `make web`, `make cli` and `tools/setup.sh e2e`):
//   node benches/engine_ready.mjs [--runs N] [--warm-loads K] [--cli PATH] [--throttle MBIT,RTT_MS] LABEL=DIR [LABEL=DIR ...]
// --throttle: Chromium's network emulation on the page (and its dedicated
// worker), e.g. 20,40 for 20 Mbit/s and 40 ms round trips; `robocal serve`
// sends files uncompressed, so this charges the raw size of the wasm.
// Without it, loads come over loopback at memory speed.
// e.g. node benches/engine_ready.mjs --runs 9 before=/tmp/before/www after=www
// Prints every run and the medians (ms) per build: cold, warm 1..K.
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';

const { chromium } = createRequire(resolve('tests/e2e/package.json'))('playwright-core');

const args = process.argv.slice(2);
let runs = 9;
let warmLoads = 2;
let cli = 'target/release/robocal';
let throttle = null; // [Mbit/s, round trip ms] for every load, through Chromium's network emulation
const builds = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--runs') runs = Number(args[++i]);
  else if (args[i] === '--warm-loads') warmLoads = Number(args[++i]);
  else if (args[i] === '--cli') cli = args[++i];
  else if (args[i] === '--throttle') throttle = args[++i].split(',').map(Number);
  else {
    const m = /^([^=]+)=(.+)$/.exec(args[i]);
    if (!m) {
      console.error(`not LABEL=DIR: ${args[i]}`);
      process.exit(2);
    }
    builds.push({ label: m[1], dir: resolve(m[2]), rows: [] });
  }
}
if (builds.length === 0) {
  console.error('usage: node benches/engine_ready.mjs [--runs N] [--warm-loads K] [--cli PATH] LABEL=DIR ...');
  process.exit(2);
}

const FLAGS = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
  '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic'];

function serve(dir) {
  const child = spawn(resolve(cli), ['serve', '--dir', dir, '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
  return new Promise((ok, fail) => {
    let out = '';
    child.stdout.on('data', (d) => {
      out += d;
      const m = /at (http:\/\/\S+)/.exec(out);
      if (m) ok({ url: m[1], stop: () => child.kill() });
    });
    child.on('exit', (code) => fail(new Error(`robocal serve exited with ${code}`)));
    setTimeout(() => fail(new Error('robocal serve printed no URL within 10 s')), 10000);
  });
}

// Runs in the page before its own scripts: records performance.now() when
// #engine-status first carries the class `ready` (or `failed`).
function recordReady() {
  const watch = () => {
    const el = document.getElementById('engine-status');
    if (!el) return false;
    const check = () => {
      if (window.__engineReady === undefined && (el.classList.contains('ready') || el.classList.contains('failed'))) {
        window.__engineReady = performance.now();
        window.__engineState = el.classList.contains('ready') ? 'ready' : 'failed';
      }
    };
    new MutationObserver(check).observe(el, { attributes: true, attributeFilter: ['class'] });
    check();
    return true;
  };
  if (!watch()) document.addEventListener('DOMContentLoaded', watch);
}

async function load(context, url) {
  const page = await context.newPage();
  if (throttle) {
    const cdp = await context.newCDPSession(page);
    await cdp.send('Network.enable');
    await cdp.send('Network.emulateNetworkConditions', {
      offline: false,
      latency: throttle[1],
      downloadThroughput: (throttle[0] * 1e6) / 8,
      uploadThroughput: (throttle[0] * 1e6) / 8,
    });
  }
  await page.goto(url, { waitUntil: 'commit' });
  await page.waitForFunction(() => window.__engineReady !== undefined, null, { timeout: 60000 });
  const [ms, state, controlled] = await page.evaluate(() => [window.__engineReady, window.__engineState, !!navigator.serviceWorker.controller]);
  if (state !== 'ready') throw new Error(`engine failed to start at ${url}`);
  return { page, ms, controlled };
}

async function oneRun(build) {
  const profile = mkdtempSync(join(tmpdir(), 'robocal-ready-'));
  const context = await chromium.launchPersistentContext(profile, { executablePath: '/usr/bin/chromium', args: FLAGS, headless: true });
  try {
    await context.addInitScript(recordReady);
    const first = await load(context, build.url);
    // Wait until the service worker is active and its cache holds the wasm.
    await first.page.evaluate(async () => {
      await navigator.serviceWorker.ready;
      for (let k = 0; k < 200; k++) {
        for (const name of await caches.keys()) {
          if (await (await caches.open(name)).match('pkg/robocal_bg.wasm')) return;
        }
        await new Promise((r) => setTimeout(r, 50));
      }
      throw new Error('the service worker did not cache the wasm within 10 s');
    });
    await first.page.close();
    const row = { cold: first.ms, warm: [], controlled: [] };
    for (let k = 0; k < warmLoads; k++) {
      const next = await load(context, build.url);
      row.warm.push(next.ms);
      row.controlled.push(next.controlled);
      await next.page.close();
    }
    return row;
  } finally {
    await context.close();
    rmSync(profile, { recursive: true, force: true });
  }
}

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const fmt = (x) => x.toFixed(0).padStart(6);

for (const b of builds) {
  const server = await serve(b.dir);
  b.url = server.url;
  b.stop = server.stop;
}
try {
  for (let r = 0; r < runs; r++) {
    for (const b of builds) {
      const row = await oneRun(b);
      b.rows.push(row);
      const warn = row.controlled.every(Boolean) ? '' : '  (a warm load was not controlled by the service worker)';
      console.log(`run ${String(r + 1).padStart(2)} ${b.label.padEnd(10)} cold ${fmt(row.cold)} ms  warm ${row.warm.map(fmt).join(' ')} ms${warn}`);
    }
  }
} finally {
  for (const b of builds) b.stop();
}
console.log(`\nmedians over ${runs} runs (ms from navigation start to engine ready; Chromium headless${throttle ? `; throttled to ${throttle[0]} Mbit/s, ${throttle[1]} ms RTT` : ''})`);
console.log(`${'build'.padEnd(10)} ${'cold'.padStart(6)} ${Array.from({ length: warmLoads }, (_, k) => `warm${k + 1}`.padStart(6)).join(' ')}`);
for (const b of builds) {
  const cold = median(b.rows.map((r) => r.cold));
  const warm = Array.from({ length: warmLoads }, (_, k) => median(b.rows.map((r) => r.warm[k])));
  console.log(`${b.label.padEnd(10)} ${fmt(cold)} ${warm.map(fmt).join(' ')}`);
}
if (builds.length > 1) {
  // Ratios of medians against the first build, and the median of the per-run ratios (runs alternate, so run r of each build is a pair).
  const base = builds[0];
  for (const b of builds.slice(1)) {
    const pair = (f) => median(b.rows.map((row, i) => f(row) / f(base.rows[i])));
    const parts = [`cold ${pair((r) => r.cold).toFixed(2)}`];
    for (let k = 0; k < warmLoads; k++) parts.push(`warm${k + 1} ${pair((r) => r.warm[k]).toFixed(2)}`);
    console.log(`${b.label}/${base.label} (median of per-run ratios): ${parts.join(', ')}`);
  }
}
