// The first slice: the page loads the engine in a worker, decodes uploaded
// images in Rust and shows thumbnails, and shows an error card for a file
// that is not an image.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { root } from './harness.mjs';
import { makePng, makeBmp, makeBmp8, checker } from '../support/images.mjs';

export const tests = [
  ['engine loads in a worker', async (page, { url, shot }) => {
    await page.goto(url);
    await page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
    assert.match(await page.textContent('#engine-status'), /^Calibration engine ready \(robocal \d+\.\d+\.\d+\)\.$/);
    await shot('loaded');
  }],
  ['a browser without WebAssembly SIMD is told which browsers the engine needs', async (page, { url }) => {
    // The worker's feature check answers as in a browser whose WebAssembly
    // validates no SIMD module (Chrome < 91, Firefox < 89, Safari < 16.4).
    const source = readFileSync(join(root, 'www/lib/wasm-features.js'), 'utf8');
    const patched = source.replace('!wasm.validate(SIMD_PROBE)', '!wasm.validate(new Uint8Array([0]))');
    assert.notEqual(patched, source);
    await page.route('**/lib/wasm-features.js', (route) => route.fulfill({ contentType: 'text/javascript', body: patched }));
    await page.goto(url);
    await page.locator('#engine-status.failed').waitFor({ timeout: 30000 });
    assert.equal(await page.textContent('#engine-status'), "The calibration engine could not start: this browser's WebAssembly lacks the SIMD instructions the calibration engine is built with: use Chrome or Edge 91+, Firefox 89+, Safari 16.4+, or update this one");
  }],
  ['two images decode, a corrupt file gets an error card', async (page, { url, shot }) => {
    await page.goto(url);
    await page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
    await page.setInputFiles('#file-input', [
      { name: 'board.png', mimeType: 'image/png', buffer: makePng(160, 120, checker(20)) },
      { name: 'plate.bmp', mimeType: 'image/bmp', buffer: makeBmp(90, 70, checker(10)) },
      { name: 'mono.bmp', mimeType: 'image/bmp', buffer: makeBmp8(80, 60, checker(10)) },
      { name: 'broken.jpg', mimeType: 'image/jpeg', buffer: Buffer.from('this is not a jpeg at all') },
    ]);
    await page.waitForFunction(() => document.querySelectorAll('.card.ok, .card.warn, .card.error').length === 4
      && !document.querySelector('.card.pending') && !/in progress/.test(document.getElementById('image-summary').textContent), null, { timeout: 30000 });
    await page.locator('#progress-row[hidden]').waitFor({ state: 'attached', timeout: 30000 });
    await shot('four-cards');
    const cards = await page.$$eval('.card', (els) => els.map((el) => ({
      name: el.querySelector('.name').textContent,
      error: el.classList.contains('error'),
      meta: el.querySelector('.meta').textContent.split(' · ').slice(0, 3).join(' · '),
      thumb: el.querySelector('canvas:not([hidden])') ? [el.querySelector('canvas').width, el.querySelector('canvas').height] : null,
    })));
    // The images decode (the default 9x6 chessboard is not in them: that is
    // reported on the card, but they are not decode errors).
    // (In name order, as the page puts one upload.)
    assert.deepEqual(cards, [
      { name: 'board.png', error: false, meta: 'PNG · 160×120 px · RGB, 8-bit', thumb: [160, 120] },
      { name: 'broken.jpg', error: true, meta: 'not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP', thumb: null },
      // An 8-bit palette of greys is listed as grey, not as the RGB the palette expands to.
      { name: 'mono.bmp', error: false, meta: 'BMP · 80×60 px · grey, 8-bit', thumb: [80, 60] },
      { name: 'plate.bmp', error: false, meta: 'BMP · 90×70 px · RGB, 8-bit', thumb: [90, 70] },
    ]);
    // The thumbnail holds the decoded pixels: a white square at (30, 10), black at (10, 10).
    const px = await page.$eval('.card canvas', (c) => {
      const ctx = c.getContext('2d');
      return [ctx.getImageData(10, 10, 1, 1).data[0], ctx.getImageData(30, 10, 1, 1).data[0]];
    });
    assert.deepEqual(px, [0, 255]);
    assert.match(await page.textContent("#image-summary"), /^4 files, 3 decoded, 1 failed/);
  }],
];

tests.push(
  ['the session survives a reload; new session clears it', async (page, { url, shot }) => {
    await page.goto(url);
    await page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
    await page.setInputFiles('#file-input', [{ name: 'kept.png', mimeType: 'image/png', buffer: makePng(40, 30, checker(5)) }]);
    await page.waitForFunction(() => /1 decoded/.test(document.getElementById('image-summary').textContent), null, { timeout: 30000 });
    await page.waitForTimeout(500); // the store saves 300 ms after the last change
    await page.reload();
    await page.waitForFunction(() => /^1 file, 1 decoded/.test(document.getElementById('image-summary').textContent), null, { timeout: 30000 });
    assert.equal(await page.textContent('.card .name'), 'kept.png');
    await shot('after-reload');
    page.once('dialog', (d) => d.accept());
    await page.click('#new-session');
    await page.waitForFunction(() => document.querySelectorAll('.card').length === 0, null, { timeout: 10000 });
    await page.reload();
    await page.waitForFunction(() => /^0 files/.test(document.getElementById('image-summary').textContent), null, { timeout: 30000 });
  }],
  ['target form asks the core: its spec, its errors, and the sheet of robocal target --svg', async (page, { url, shot }) => {
    await page.goto(`${url}#target`);
    await page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
    // The default target, spelled by the core.
    await page.waitForFunction(() => /^Target spec: chessboard:9x6:30mm /.test(document.getElementById('target-spec').textContent), null, { timeout: 10000 });
    await page.selectOption('#target-kind', 'circle_grid');
    await page.fill('input[name=cols]', '4');
    await page.fill('input[name=rows]', '11');
    await page.fill('input[name=spacing_mm]', '20');
    await page.selectOption('select[name=asymmetric]', 'true');
    await page.waitForFunction(() => /^Target spec: circles:4x11:20mm:asymmetric /.test(document.getElementById('target-spec').textContent), null, { timeout: 10000 });
    await page.waitForFunction(() => document.getElementById('target-canvas').dataset.spec === 'circles:4x11:20mm:asymmetric', null, { timeout: 10000 });
    await shot('circles');
    // The drawing is the core's sheet: not blank, origin marker (blue) drawn.
    const blue = await page.$eval('#target-canvas', (c) => {
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) if (d[i] === 0x1f && d[i + 1] === 0x77 && d[i + 2] === 0xb4) n++;
      return n;
    });
    assert.ok(blue > 20, `origin marker pixels: ${blue}`);
    const download = async () => {
      const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#print-target')]);
      return { name: dl.suggestedFilename(), svg: (await (await dl.createReadStream()).toArray()).join('') };
    };
    const cliSvg = (spec) => {
      const dir = mkdtempSync(join(tmpdir(), 'robocal-target-'));
      try {
        execFileSync(join(root, 'target/release/robocal'), ['target', spec, '--svg', join(dir, 'board.svg')]);
        return readFileSync(join(dir, 'board.svg'), 'utf8');
      } finally { rmSync(dir, { recursive: true, force: true }); }
    };
    const circles = await download();
    assert.equal(circles.name, 'robocal-target-circles_4x11_20mm_asymmetric.svg');
    // Byte for byte the CLI's sheet: true scale, 44 circles, the 100 mm bar, the spec.
    assert.equal(circles.svg, cliSvg('circles:4x11:20mm:asymmetric'));
    assert.match(circles.svg, /<svg xmlns="http:\/\/www.w3.org\/2000\/svg" width="200mm" height="293mm" viewBox="0 0 200 293">/);
    assert.equal((circles.svg.match(/<circle /g) || []).length, 44);
    assert.match(circles.svg, /<rect class="check-bar" x="10" y="[\d.]+" width="100" height="3"/);
    assert.match(circles.svg, />robocal target circles:4x11:20mm:asymmetric</);
    // The core's validation message, and no sheet for an invalid target.
    await page.fill('input[name=cols]', '1');
    await page.waitForFunction(() => document.getElementById('target-error').textContent !== '', null, { timeout: 10000 });
    assert.equal(await page.textContent('#target-error'), 'target: a grid needs 2 to 100000 points with at least 2 per side, got 1x11');
    assert.equal(await page.isDisabled('#print-target'), true);
    // Zhang's grid of separate squares: only its fields are shown; 22.5778 mm
    // crosses as the same metres as the CLI's spec (decimal shift, not / 1000).
    await page.selectOption('#target-kind', 'square_grid');
    await page.fill('input[name=cols]', '8');
    await page.fill('input[name=rows]', '8');
    await page.fill('input[name=side_mm]', '12.7');
    await page.fill('input[name=pitch_mm]', '22.5778');
    await page.waitForFunction(() => /^Target spec: squares:8x8:12.7mm:22.5778mm /.test(document.getElementById('target-spec').textContent), null, { timeout: 10000 });
    for (const name of ['asymmetric', 'polarity', 'dot_diameter_mm', 'spacing_mm', 'square_mm']) assert.equal(await page.isVisible(`#target-form [name=${name}]`), false, `${name} shown for square_grid`);
    assert.equal(await page.isVisible('#target-form [name=side_mm]'), true);
    await shot('squares');
    const squares = await download();
    assert.equal(squares.svg, cliSvg('squares:8x8:12.7mm:22.5778mm'));
    assert.equal((squares.svg.match(/<rect class="square" /g) || []).length, 64);
    await page.fill('input[name=side_mm]', '30');
    await page.waitForFunction(() => document.getElementById('target-error').textContent !== '', null, { timeout: 10000 });
    assert.equal(await page.textContent('#target-error'), 'target: the square side must be smaller than the pitch (the squares must not touch)');
    // The session holds the core's JSON: after a reload the form shows the last valid target.
    await page.fill('input[name=side_mm]', '12.7');
    await page.waitForFunction(() => document.getElementById('target-error').textContent === '', null, { timeout: 10000 });
    await page.waitForTimeout(500);
    await page.reload();
    await page.waitForFunction(() => /^Target spec: squares:8x8:12.7mm:22.5778mm /.test(document.getElementById('target-spec').textContent), null, { timeout: 30000 });
    assert.equal(await page.inputValue('input[name=pitch_mm]'), '22.5778');
  }],
);
