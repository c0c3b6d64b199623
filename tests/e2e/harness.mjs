// A tiny harness for the browser tests: starts `robocal serve` on a free
// port, launches Debian's Chromium headless, gives each test a fresh page and
// saves a failing test's page (or, with E2E_SHOTS=steps, every step's) under
// tests/e2e/screenshots/.
import { spawn } from 'node:child_process';
import { mkdirSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const shotsDir = join(root, 'tests/e2e/screenshots');

export async function startServer() {
  const bin = join(root, 'target/release/robocal');
  const child = spawn(bin, ['serve', '--dir', join(root, 'www'), '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
  const url = await new Promise((resolve, reject) => {
    let out = '';
    child.stdout.on('data', (d) => {
      out += d;
      const m = /at (http:\/\/\S+)/.exec(out);
      if (m) resolve(m[1]);
    });
    child.on('exit', (code) => reject(new Error(`robocal serve exited with ${code}`)));
    setTimeout(() => reject(new Error('robocal serve did not print its URL within 10 s')), 10000);
  });
  return { url, stop: () => child.kill() };
}

/** Chromium, headless; `extraArgs` are a suite's own flags (the capture suite's fake camera). */
// Chromium has been seen to die while starting (SIGSEGV before its first
// page, once in about 90 launches, two lanes at once): a launch that fails is
// tried once more, and said; a second failure is the suite's.
export async function launch(extraArgs = []) {
  const options = {
    executablePath: '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic', ...extraArgs],
  };
  try {
    return await chromium.launch(options);
  } catch (e) {
    console.log(`     Chromium did not start (${String(e.message).split('\n')[0]}); trying once more`);
    return chromium.launch(options);
  }
}

// A full-page screenshot at every step a test names (`E2E_SHOTS=steps`), to
// look at the page as the test saw it; by default only a failing test's page
// is saved: the 130 full-page step shots are PNGs of pages up to 7,500 px
// tall, encoded while the test waits.
const stepShots = process.env.E2E_SHOTS === 'steps';

// Playwright's 30 s default for an action (e.g. setInputFiles, which needs
// the page's main thread) was exceeded twice in one run of two lanes while a
// build shared the two cores (load 8-10); every other step of those tests
// took seconds. A wait that fails still fails, only later.
const actionTimeoutMs = 90000;

/** A browser context as every suite uses it: the suites' viewport (unless `options` says otherwise) and the action timeout above. */
export async function newContext(browser, options = {}) {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 }, ...options });
  context.setDefaultTimeout(actionTimeoutMs);
  return context;
}

/** Runs `tests` ([name, fn(page, ctx)]) each in a fresh browser context of a Chromium launched with `launchArgs`. */
export async function run(suite, tests, launchArgs = []) {
  mkdirSync(shotsDir, { recursive: true });
  const server = await startServer();
  let browser;
  try {
    browser = await launch(launchArgs);
  } catch (e) {
    server.stop();
    throw e;
  }
  let failed = 0;
  try {
    for (const [name, fn] of tests) {
      const context = await newContext(browser);
      const page = await context.newPage();
      const consoleErrors = [];
      page.on('pageerror', (e) => consoleErrors.push(e.message));
      let step = 0;
      const file = (label) => join(shotsDir, `${suite}-${name.replace(/\W+/g, '_')}-${++step}-${label}.png`);
      const failureShot = () => page.screenshot({ path: file('failure'), fullPage: true });
      const shot = stepShots ? (label) => page.screenshot({ path: file(label), fullPage: true }) : async () => {};
      const started = Date.now();
      try {
        await fn(page, { url: server.url, shot, consoleErrors, browser });
        if (consoleErrors.length) throw new Error(`uncaught page errors: ${consoleErrors.join('; ')}`);
        console.log(`ok   ${suite}: ${name} (${Date.now() - started} ms)`);
      } catch (e) {
        failed++;
        await failureShot().catch(() => {});
        console.log(`FAIL ${suite}: ${name}\n     ${e.stack || e}`);
      } finally {
        await context.close();
      }
    }
  } finally {
    await browser.close();
    server.stop();
  }
  return failed;
}
