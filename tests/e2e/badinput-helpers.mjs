// The page helpers the bad-input suites share (badinputs.mjs: files and
// forms; badposes.mjs: robot poses and hand-eye): the page made ready, the
// image cards read, a generated board image, the demo session rendered once
// by the CLI, the demo's images or one board loaded, the camera solved.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { root } from './harness.mjs';
import { makePng } from '../support/images.mjs';

export const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });

/** The image cards as {name, cls, meta}. */
export const cards = (page) => page.$$eval('.card', (els) => els.map((el) => ({
  name: el.querySelector('.name').textContent, cls: el.className, meta: el.querySelector('.meta').textContent,
})));

/**
 * Wait until there are `n` cards, each finished: not decoded (class error),
 * decoded without the target (class warn), or decoded with its points (a
 * card that is still decoding is pending; one being detected says
 * 'detecting…' and one between the two has no points yet).
 */
export const settled = (page, n) => page.waitForFunction((n) => {
  const all = [...document.querySelectorAll('.card')];
  return all.length === n && all.every((c) => /\b(error|warn)\b/.test(c.className) || / \d+ points$/.test(c.querySelector('.meta').textContent));
}, n, { timeout: 60000 });

/**
 * A 9x6 inner-corner chessboard (10x7 squares of 24 px) in a `w` x `h` white
 * image, its top-left square at (`x`, `y`): the page's default target.
 */
export function board({ x = 36, y = 36, w = 312, h = 240 } = {}) {
  const s = 24;
  return makePng(w, h, (px, py) => {
    const [i, j] = [Math.floor((px - x) / s), Math.floor((py - y) / s)];
    const inside = px >= x && py >= y && i < 10 && j < 7;
    const v = inside && (i + j) % 2 === 0 ? 0 : 255;
    return [v, v, v];
  });
}

export const png = (name, buffer) => ({ name, mimeType: 'image/png', buffer });
export const text = (name, content) => ({ name, mimeType: 'text/plain', buffer: Buffer.isBuffer(content) ? content : Buffer.from(content) });
export const BOARD_META = 'PNG · 312×240 px · RGB, 8-bit · 54 points';

/** The demo session as `robocal render --demo` writes it (the page's demo button renders the same): rendered once. */
let demoFiles = null;
export function demo() {
  if (demoFiles) return demoFiles;
  const dir = mkdtempSync(join(tmpdir(), 'robocal-badinputs-'));
  try {
    execFileSync(join(root, 'target/release/robocal'), ['render', '--out', dir, '--demo'], { stdio: 'ignore' });
    const images = readdirSync(dir).filter((f) => f.endsWith('.png')).sort().map((f) => png(f, readFileSync(join(dir, f))));
    demoFiles = { images, poses: readFileSync(join(dir, 'poses.csv'), 'utf8') };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
  return demoFiles;
}

export async function loadBoard(page, url, hash = '') {
  await page.goto(`${url}${hash}`);
  await ready(page);
  await page.click('a[data-step=images]');
  await page.setInputFiles('#file-input', [png('board.png', board())]);
  await settled(page, 1);
  assert.deepEqual((await cards(page)).map((c) => c.meta), [BOARD_META]);
}

export async function solveCamera(page) {
  await page.click('a[data-step=camera]');
  await page.evaluate(() => document.getElementById('camera-results').replaceChildren());
  await page.click('#solve-camera');
  await page.waitForFunction(() => document.querySelector('#camera-params, #camera-results .msg-error'), null, { timeout: 60000 });
  const error = await page.$('#camera-results .msg-error');
  return error ? error.textContent() : null;
}

export async function loadDemoImages(page, url, extra = [], only = null) {
  await page.goto(url);
  await ready(page);
  const images = only ? demo().images.slice(0, only) : demo().images;
  // The extra files after the demo's (one upload is sorted by name: the
  // extras would go first).
  await page.setInputFiles('#file-input', images);
  await settled(page, images.length);
  if (!extra.length) return;
  await page.setInputFiles('#file-input', extra);
  await settled(page, images.length + extra.length);
}
