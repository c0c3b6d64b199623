// The first slice: the page loads the engine in a worker, decodes uploaded
// images in Rust and shows thumbnails, and shows an error card for a file
// that is not an image.
import assert from 'node:assert/strict';
import { makePng, makeBmp, checker } from '../support/images.mjs';

export const tests = [
  ['engine loads in a worker', async (page, { url, shot }) => {
    await page.goto(url);
    await page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
    assert.match(await page.textContent('#engine-status'), /^Calibration engine ready \(robocal \d+\.\d+\.\d+\)\.$/);
    await shot('loaded');
  }],
  ['two images decode, a corrupt file gets an error card', async (page, { url, shot }) => {
    await page.goto(url);
    await page.locator('#engine-status.ready').waitFor({ timeout: 30000 });
    await page.setInputFiles('#file-input', [
      { name: 'board.png', mimeType: 'image/png', buffer: makePng(160, 120, checker(20)) },
      { name: 'plate.bmp', mimeType: 'image/bmp', buffer: makeBmp(90, 70, checker(10)) },
      { name: 'broken.jpg', mimeType: 'image/jpeg', buffer: Buffer.from('this is not a jpeg at all') },
    ]);
    await page.waitForFunction(() => document.querySelectorAll('.card.ok, .card.error').length === 3, null, { timeout: 30000 });
    await shot('three-cards');
    const cards = await page.$$eval('.card', (els) => els.map((el) => ({
      name: el.querySelector('.name').textContent,
      cls: el.className,
      meta: el.querySelector('.meta').textContent,
      thumb: el.querySelector('canvas') ? [el.querySelector('canvas').width, el.querySelector('canvas').height] : null,
    })));
    assert.deepEqual(cards, [
      { name: 'board.png', cls: 'card ok', meta: 'PNG · 160×120 px · RGB, 8-bit', thumb: [160, 120] },
      { name: 'plate.bmp', cls: 'card ok', meta: 'BMP · 90×70 px · RGB, 8-bit', thumb: [90, 70] },
      { name: 'broken.jpg', cls: 'card error', meta: 'not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF', thumb: null },
    ]);
    // The thumbnail holds the decoded pixels: a white square at (30, 10), black at (10, 10).
    const px = await page.$eval('.card canvas', (c) => {
      const ctx = c.getContext('2d');
      return [ctx.getImageData(10, 10, 1, 1).data[0], ctx.getImageData(30, 10, 1, 1).data[0]];
    });
    assert.deepEqual(px, [0, 255]);
    assert.equal(await page.textContent('#image-summary'), '3 files, 2 decoded, 1 failed');
  }],
];
