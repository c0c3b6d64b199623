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
    await page.waitForFunction(() => document.querySelectorAll('.card.ok, .card.warn, .card.error').length === 3
      && !document.querySelector('.card.pending') && !/in progress/.test(document.getElementById('image-summary').textContent), null, { timeout: 30000 });
    await page.locator('#progress-row[hidden]').waitFor({ state: 'attached', timeout: 30000 });
    await shot('three-cards');
    const cards = await page.$$eval('.card', (els) => els.map((el) => ({
      name: el.querySelector('.name').textContent,
      error: el.classList.contains('error'),
      meta: el.querySelector('.meta').textContent.split(' · ').slice(0, 3).join(' · '),
      thumb: el.querySelector('canvas:not([hidden])') ? [el.querySelector('canvas').width, el.querySelector('canvas').height] : null,
    })));
    // The images decode (the default 9x6 chessboard is not in them: that is
    // reported on the card, but they are not decode errors).
    assert.deepEqual(cards, [
      { name: 'board.png', error: false, meta: 'PNG · 160×120 px · RGB, 8-bit', thumb: [160, 120] },
      { name: 'plate.bmp', error: false, meta: 'BMP · 90×70 px · RGB, 8-bit', thumb: [90, 70] },
      { name: 'broken.jpg', error: true, meta: 'not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP', thumb: null },
    ]);
    // The thumbnail holds the decoded pixels: a white square at (30, 10), black at (10, 10).
    const px = await page.$eval('.card canvas', (c) => {
      const ctx = c.getContext('2d');
      return [ctx.getImageData(10, 10, 1, 1).data[0], ctx.getImageData(30, 10, 1, 1).data[0]];
    });
    assert.deepEqual(px, [0, 255]);
    assert.match(await page.textContent('#image-summary'), /^3 files, 2 decoded, 1 failed/);
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
  ['target form draws the board and makes a printable SVG at true scale', async (page, { url, shot }) => {
    await page.goto(`${url}#target`);
    await page.selectOption('#target-kind', 'circles');
    await page.fill('input[name=cols]', '4');
    await page.fill('input[name=rows]', '11');
    await page.fill('input[name=size_mm]', '20');
    await page.selectOption('select[name=layout]', 'asymmetric');
    assert.match(await page.textContent('#target-spec'), /^Target spec: circles:4x11:20mm:asymmetric /);
    await shot('circles');
    const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#print-target')]);
    const svg = (await (await dl.createReadStream()).toArray()).join('');
    // 4 columns asymmetric: x from 0 to (2*3+1)*20 = 140 mm plus 20 mm margins.
    assert.match(svg, /<svg xmlns="http:\/\/www.w3.org\/2000\/svg" width="180mm" height="240mm" viewBox="0 0 180 240">/);
    assert.equal((svg.match(/<circle /g) || []).length, 44);
    await page.fill('input[name=cols]', '1');
    assert.equal(await page.textContent('#target-error'), 'Columns must be a whole number from 2 to 100.');
    assert.equal(await page.isDisabled('#print-target'), true);
    // Zhang's grid of separate squares: the spec the CLI takes, 64 squares
    // at true scale (7 pitches + side + two pitches of margin).
    await page.selectOption('#target-kind', 'squares');
    await page.fill('input[name=cols]', '8');
    await page.fill('input[name=rows]', '8');
    await page.fill('input[name=size_mm]', '22.5');
    await page.fill('input[name=side_mm]', '12.5');
    assert.match(await page.textContent('#target-spec'), /^Target spec: squares:8x8:12.5mm:22.5mm /);
    // Only the fields of this kind are shown (the circle-grid and dot fields were visible before).
    for (const name of ['layout', 'polarity', 'diameter_mm']) assert.equal(await page.isVisible(`#target-form [name=${name}]`), false, `${name} shown for squares`);
    assert.equal(await page.isVisible('#target-form [name=side_mm]'), true);
    assert.equal(await page.textContent('#size-label'), 'Square pitch (mm)');
    await shot('squares');
    const [dl2] = await Promise.all([page.waitForEvent('download'), page.click('#print-target')]);
    const svg2 = (await (await dl2.createReadStream()).toArray()).join('');
    assert.match(svg2, /width="215mm" height="215mm" viewBox="0 0 215 215">/);
    assert.equal((svg2.match(/<rect /g) || []).length, 65);
    await page.fill('input[name=side_mm]', '30');
    assert.equal(await page.textContent('#target-error'), 'The square side must be smaller than the pitch (the squares must not touch).');
  }],
);
