// A catalogue of bad inputs through the page (issue 17, part 3): each test
// gives the page one bad input where a user would give it, asserts the exact
// message the page shows, that what was loaded before is still there, and
// that a later good input still works. docs/bad-inputs-page.md lists the rows
// (same test names); docs/bad-inputs.md is the CLI's catalogue of the same
// inputs. The harness fails a test on any uncaught page error. This suite:
// files and forms (images, camera, share links, sessions, rig grouping,
// target, workflows); badposes.mjs: robot poses and hand-eye.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { crc32, deflateRawSync } from 'node:zlib';
import { root } from './harness.mjs';
import { makePng, makeBmp, checker } from '../support/images.mjs';
import {
  ready, cards, settled, board, png, text, BOARD_META, demo, loadBoard, solveCamera, loadDemoImages,
} from './badinput-helpers.mjs';

/** A real PNG whose IHDR (with a right CRC) claims `width` x `height` pixels. */
function pngClaiming(width, height) {
  const bytes = Buffer.from(makePng(4, 3, checker(1)));
  bytes.writeUInt32BE(width, 16);
  bytes.writeUInt32BE(height, 20);
  bytes.writeUInt32BE(crc32(bytes.subarray(12, 29)), 29);
  return bytes;
}

/** Images: board.png detected, then the bad file gets an error card; board.png stays; a later good image detects. */
function imageCase(file, message, { cls = 'card error' } = {}) {
  return async (page, { url, shot }) => {
    await loadBoard(page, url);
    await page.setInputFiles('#file-input', [file]);
    await settled(page, 2);
    const [kept, bad] = await cards(page);
    assert.deepEqual(bad, { name: file.name, cls, meta: message });
    assert.deepEqual([kept.name, kept.meta], ['board.png', BOARD_META]);
    await shot('bad');
    await page.setInputFiles('#file-input', [png('later.png', board({ x: 40, y: 30 }))]);
    await settled(page, 3);
    const later = (await cards(page))[2];
    assert.deepEqual([later.name, later.meta], ['later.png', BOARD_META]);
    assert.equal((await cards(page))[0].meta, BOARD_META);
  };
}

/** Target form: a good target, board.png detected with it, then a bad field value refused; the target in use and the detection kept. */
function targetCase(field, value, message) {
  return async (page, { url, shot }) => {
    await loadBoard(page, url);
    await page.click('a[data-step=target]');
    const spec = 'Target spec: chessboard:9x6:30mm (the same spelling works in the CLI: robocal detect --target chessboard:9x6:30mm; robocal target chessboard:9x6:30mm --svg board.svg prints this sheet)';
    assert.equal(await page.textContent('#target-spec'), spec);
    await page.fill(`#target-form input[name=${field}]`, value);
    await page.waitForFunction((m) => document.getElementById('target-error').textContent === m, message, { timeout: 10000 });
    assert.equal(await page.isDisabled('#print-target'), true);
    await shot('bad');
    // The target in use is still the good one: a new image is detected with it.
    assert.equal(await page.textContent('#target-spec'), spec);
    await page.click('a[data-step=images]');
    await page.setInputFiles('#file-input', [png('later.png', board({ x: 40, y: 30 }))]);
    await settled(page, 2);
    assert.deepEqual((await cards(page)).map((c) => c.meta), [BOARD_META, BOARD_META]);
    // A good value again: the sheet follows it.
    await page.click('a[data-step=target]');
    await page.fill('#target-form input[name=cols]', '9');
    await page.fill('#target-form input[name=square_mm]', '25');
    await page.waitForFunction(() => /^Target spec: chessboard:9x6:25mm /.test(document.getElementById('target-spec').textContent), null, { timeout: 10000 });
    assert.equal(await page.textContent('#target-error'), '');
    assert.equal(await page.isDisabled('#print-target'), false);
  };
}

/**
 * Workflows, planar: the seed-001 points solved, then the bad CSV (pasted
 * text, or {file} through the file input) refused with `message`, then the
 * good CSV solves again.
 */
function planarCase(csv, message) {
  return async (page, { url, shot }) => {
    const good = readFileSync(join(root, 'fixtures/seed001/table3_four_points.csv'), 'utf8');
    await page.goto(`${url}#workflows`);
    await ready(page);
    await page.fill('#planar-csv', good);
    await page.click('#planar-solve');
    await page.locator('#planar-fit').waitFor({ timeout: 20000 });
    const fit = await page.textContent('#planar-fit');
    if (typeof csv === 'string') {
      await page.fill('#planar-csv', csv);
      await page.click('#planar-solve');
    } else {
      await page.setInputFiles('#planar-file', csv.file);
      // The text area keeps the points it had.
    }
    await page.locator('#planar-results .msg-error').waitFor({ timeout: 20000 });
    if (typeof csv !== 'string') assert.equal(await page.inputValue('#planar-csv'), good);
    assert.equal(await page.textContent('#planar-results'), message);
    await shot('bad');
    await page.fill('#planar-csv', good);
    await page.click('#planar-solve');
    await page.locator('#planar-fit').waitFor({ timeout: 20000 });
    assert.equal(await page.textContent('#planar-fit'), fit);
  };
}

/** Eight stage positions on two levels seen by an exact pinhole (f 1000 px, 500 mm above the table): an XY-table CSV that solves. */
function stageCsv() {
  let csv = 'x_mm,y_mm,z_mm,u_px,v_px\n';
  for (const z of [0, 30]) for (const [x, y] of [[-90, -60], [80, -70], [70, 65], [-85, 55]]) {
    const u = 640 + (1000 * x) / (500 - z);
    const v = 480 - (1000 * y) / (500 - z);
    csv += `${x},${y},${z},${u},${v}\n`;
  }
  return csv;
}

/**
 * A share link whose fragment is `fragment`: the page says what is wrong in
 * its banner, and the user's own session (board.png) is untouched.
 */
function shareCase(fragment, message) {
  return async (page, { url, shot }) => {
    await loadBoard(page, url);
    await page.waitForTimeout(500); // the store saves 300 ms after the last change
    await page.goto(`${url}#share=${fragment}`); // a new share fragment in an open tab reloads the page on it
    await page.locator('#readonly-banner:not([hidden])').waitFor({ timeout: 30000 });
    await page.waitForFunction(() => !/^You are viewing shared results/.test(document.getElementById('readonly-banner').textContent), null, { timeout: 10000 });
    assert.equal(await page.textContent('#readonly-banner'), `${message}. Start your own session at /.`);
    await shot('bad');
    await page.goto(url);
    await page.reload();
    await ready(page);
    await page.click('a[data-step=images]');
    await settled(page, 1);
    assert.deepEqual((await cards(page)).map((c) => [c.name, c.meta]), [['board.png', BOARD_META]]);
  };
}
const shareText = (bytes) => deflateRawSync(Buffer.from(bytes)).toString('base64url');

/** The rig step's two cameras: files added to each; returns the grouping text once it includes `expect`. */
async function rigAdd(page, left, right, expect) {
  const mk = (names) => names.map((n) => png(n, makePng(40, 30, checker(5))));
  if (left.length) await page.setInputFiles('#rig-input-0', mk(left));
  if (right.length) await page.setInputFiles('#rig-input-1', mk(right));
  // The page groups after each camera's files: wait until the table (when
  // the files group) holds every file given here, not only the first camera's.
  await page.waitForFunction(([e, files]) => {
    if (!(document.getElementById('rig-grouping')?.textContent || '').includes(e)) return false;
    const table = document.getElementById('rig-frame-table');
    if (!table) return true;
    const shown = [...table.querySelectorAll('tbody td')].map((td) => td.textContent.replace(/: .*$/, ''));
    return files.every((f) => shown.includes(f));
  }, [expect, [...left, ...right]], { timeout: 10000 });
  return page.textContent('#rig-grouping');
}

const MESSAGES = {
  empty: 'not an image: the file is empty',
  magic: 'not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP',
};

export const tests = [
  // ---- step 2, images: an error card, the other images kept ----
  ['image-empty', imageCase(png('empty.png', Buffer.alloc(0)), MESSAGES.empty)],
  ['image-wrong-magic', imageCase(png('text.png', Buffer.from('hello, this is text\n')), MESSAGES.magic)],
  ['image-png-signature-only', imageCase(png('sig.png', board().subarray(0, 8)), 'the PNG file is truncated: it ends after 8 bytes, before the end of its image data (an interrupted copy or download?): copy it again from the camera or its source')],
  ['image-gif-truncated', imageCase({ name: 't.gif', mimeType: 'image/gif', buffer: Buffer.from('GIF89a\x10\x00\x10\x00\x80\x00\x00', 'latin1') },
    'corrupt or truncated GIF file: Format error decoding Gif: Unexpected End of File')],
  ['image-png-huge-header', imageCase(png('huge.png', pngClaiming(100000, 100000)),
    'image is 100000x100000 = 10000.0 MP, more than the limit of 64.0 MP: downscale it first, or raise the limit (--max-pixels in the CLI, "max_pixels" in the JSON options)')],
  ['image-pgm-huge-header', imageCase({ name: 'huge.pgm', mimeType: 'image/x-portable-graymap', buffer: Buffer.from('P5\n20000 20000\n255\n') },
    'image is 20000x20000 = 400.0 MP, more than the limit of 64.0 MP: downscale it first, or raise the limit (--max-pixels in the CLI, "max_pixels" in the JSON options)')],
  ['image-bmp-truncated', imageCase({ name: 'cut.bmp', mimeType: 'image/bmp', buffer: makeBmp(40, 30, checker(5)).subarray(0, 60) },
    'the BMP file is truncated: it ends after 60 bytes, before the end of its image data (an interrupted copy or download?): copy it again from the camera or its source')],
  ['image-tiff-truncated', imageCase({ name: 'cut.tif', mimeType: 'image/tiff', buffer: Buffer.from([0x49, 0x49, 0x2a, 0x00, 0x08, 0x00, 0x00, 0x00, 0x0a, 0x00]) },
    'the TIFF file is truncated: it ends after 10 bytes, before the end of its image data (an interrupted copy or download?): copy it again from the camera or its source')],
  ['image-no-target', imageCase(png('blank.png', makePng(64, 48, () => [255, 255, 255])),
    'PNG · 64×48 px · RGB, 8-bit · board not found: no 9x6 chessboard corners', { cls: 'card warn excluded' })],

  // ---- step 3, camera: the solve refuses, the images stay, a fix solves ----
  ['camera-one-view', async (page, { url, shot }) => {
    await loadDemoImages(page, url, [], 1);
    assert.equal(await solveCamera(page), "views: 1 view with the target found, a calibration needs at least 3 (10 or more from varied angles are recommended): add images in which the whole target is found, or check the target's size (inner corners for a chessboard)");
    await shot('bad');
    await page.click('a[data-step=images]');
    await page.setInputFiles('#file-input', demo().images.slice(1));
    await settled(page, 12);
    assert.equal((await cards(page))[0].name, 'demo_00.png');
    assert.equal(await solveCamera(page), null);
    assert.match(await page.textContent('#camera-results h3'), /^Result: RMS \S+ px over 12 views$/);
  }],
  ['camera-same-image-twice', async (page, { url, shot }) => {
    await loadDemoImages(page, url, [png('copy_of_demo_03.png', demo().images[3].buffer)]);
    assert.equal(await solveCamera(page), 'views: views 3 (demo_03.png) and 12 (copy_of_demo_03.png) have identical image points: the same image was given twice; remove one of them');
    await shot('bad');
    await page.click('a[data-step=images]');
    await page.click('input[aria-label="use copy_of_demo_03.png in the calibration"]');
    assert.equal(await solveCamera(page), null);
    assert.match(await page.textContent('#camera-results h3'), /^Result: RMS \S+ px over 12 views$/);
  }],
  ['camera-two-sizes', async (page, { url, shot }) => {
    await loadDemoImages(page, url, [png('board.png', board())]);
    assert.equal((await cards(page))[12].meta, BOARD_META);
    assert.equal(await solveCamera(page), 'image_size_px: the detections disagree: 1024x768 and 312x240 (board.png): one calibration takes the images of one camera at one resolution');
    await shot('bad');
    await page.click('a[data-step=images]');
    await page.click('input[aria-label="use board.png in the calibration"]');
    assert.equal(await solveCamera(page), null);
    assert.match(await page.textContent('#camera-results h3'), /^Result: RMS \S+ px over 12 views$/);
  }],

  // ---- a share link (#share=...): the banner says what is wrong, the own session is kept ----
  ['share-link-damaged', shareCase(shareText(JSON.stringify({ kind: 'robocal-share', schema: 1 })).slice(0, 12),
    'this share link is damaged (it may have been cut off when it was copied)')],
  ['share-link-not-robocal', shareCase(shareText(JSON.stringify({ hello: 1 })), 'this link does not hold robocal results')],
  ['share-link-not-json', shareCase(shareText('not json'), 'this link does not hold robocal results (its content is not JSON)')],
  ['share-link-null', shareCase(shareText('null'), 'this link does not hold robocal results')],

  // Wrong types in a link (issue 37): refused by field, never an uncaught TypeError or a stack overflow.
  ['share-link-wrong-types', shareCase(shareText(JSON.stringify({ kind: 'robocal-share', schema: 1, camera: { result: { camera_matrix: 'abc' } } })),
    "this link's results are damaged: camera.result.camera_matrix must be a list, got the text 'abc'")],
  ['share-link-views-not-a-list', shareCase(shareText(JSON.stringify({ kind: 'robocal-share', schema: 1, camera: { result: { camera_matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], views: {} } } })),
    "this link's results are damaged: camera.result.views must be a list, got an object")],
  ['share-link-200000-views', shareCase(shareText(JSON.stringify({ kind: 'robocal-share', schema: 1, camera: { result: { camera_matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], views: new Array(200000).fill(0) } } })),
    "this link's results are damaged: camera.result.views holds 200000 entries, more than the 10000 the page takes")],

  // ---- a damaged session (issue 37): refused by field, the current session kept, the page never bricked ----
  ['session-file-null-camera', async (page, { url, shot }) => {
    await loadBoard(page, url);
    await page.click('a[data-step=share]');
    const doc = { kind: 'robocal-session', schema: 1, robocal_version: 'x', session: { schema: 1, images: [], camera: null } };
    await page.setInputFiles('#session-input', text('damaged.json', JSON.stringify(doc)));
    await page.waitForFunction(() => /damaged/.test(document.getElementById('session-status')?.textContent || ''), null, { timeout: 10000 });
    assert.equal(await page.textContent('#session-status'), 'damaged.json: this session file is damaged: session.camera must be an object, got null; nothing was loaded, the current session is kept');
    await shot('bad');
    await page.click('a[data-step=images]');
    assert.deepEqual((await cards(page)).map((c) => c.name), ['board.png']);
  }],
  ['saved-session-damaged', async (page, { url, shot }) => {
    await loadBoard(page, url);
    await page.waitForTimeout(500); // saved 300 ms after the last change
    // The saved session damaged in storage (as a bad session file of an older page left it).
    await page.evaluate(() => new Promise((resolve, reject) => {
      const req = indexedDB.open('robocal', 1);
      req.onsuccess = () => {
        const t = req.result.transaction('session', 'readwrite');
        const s = t.objectStore('session');
        const get = s.get('current');
        get.onsuccess = () => { s.put({ ...get.result, robot: null }, 'current'); };
        t.oncomplete = () => resolve();
        t.onerror = () => reject(t.error);
      };
      req.onerror = () => reject(req.error);
    }));
    await page.reload();
    await ready(page);
    await page.locator('#storage-status:not([hidden])').waitFor({ timeout: 20000 });
    assert.match(await page.textContent('#storage-status'), /^The session saved in this browser could not be restored \(session\.robot must be an object, got null\); a new session was started\.Download the damaged session$/);
    assert.equal(await page.isVisible('#restoring'), false);
    await shot('bad');
    // The page works: the demo loads and the damaged session stays downloadable.
    await page.click('#demo-button');
    await page.waitForFunction(() => /12 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 120000 });
    const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#download-damaged-session')]);
    assert.equal(dl.suggestedFilename(), 'robocal-damaged-session.json');
  }],

  // ---- step 7, stereo pairs and rigs: the grouping refuses with the core's message ----
  ['rig-too-few-frames', async (page, { url, shot }) => {
    await page.goto(`${url}#stereo`);
    await ready(page);
    assert.equal(await rigAdd(page, ['l1.png', 'l2.png'], ['r1.png', 'r2.png'], '2 frames over 2 cameras'), '2 frames over 2 cameras, grouped by the number in the file names.');
    assert.equal(await page.textContent('#rig-too-few'), 'A rig calibration needs at least 3 frames: add 1 more frame (an image of each camera, numbered alike) to solve.');
    assert.equal(await page.isDisabled('#rig-solve'), true);
    await shot('bad');
    assert.equal(await rigAdd(page, ['l3.png'], ['r3.png'], '3 frames'), '3 frames over 2 cameras, grouped by the number in the file names.');
    assert.equal(await page.$('#rig-too-few'), null);
    assert.equal(await page.isDisabled('#rig-solve'), false);
  }],
  ['rig-number-twice', async (page, { url, shot }) => {
    await page.goto(`${url}#stereo`);
    await ready(page);
    await rigAdd(page, ['l1.png', 'l2.png', 'l3.png'], ['r1.png', 'r2.png', 'r3.png'], '3 frames');
    const error = await rigAdd(page, ['l01.png'], [], 'cannot be grouped');
    assert.equal(error, 'The images cannot be grouped into frames: images: frames are grouped by the last number in the file names, but number 1 is in two camera cam0 images: l1.png, l01.png (group by number or last (the last number in the name, the default), first (the first number), order (the position in each camera\'s list), or a pattern with one (\\d+) such as sync(\\d+))');
    assert.equal(await page.isDisabled('#rig-solve'), true);
    await shot('bad');
    // The files are kept (the message names them); removing them and loading a clean set groups.
    await page.click('#rig-clear');
    assert.equal(await rigAdd(page, ['l1.png', 'l2.png', 'l3.png'], ['r1.png', 'r2.png', 'r3.png'], '3 frames'), '3 frames over 2 cameras, grouped by the number in the file names.');
  }],
  ['rig-names-without-number', async (page, { url, shot }) => {
    await page.goto(`${url}#stereo`);
    await ready(page);
    // Some names have a number: frames go by the number, and the others are named.
    const error = await rigAdd(page, ['a.png', 'b.png', 'c3.png'], ['x1.png', 'y2.png', 'z3.png'], 'cannot be grouped');
    assert.equal(error, 'The images cannot be grouped into frames: images: frames are grouped by the last number in the file names, but camera cam0 has names without one: a.png, b.png (group by number or last (the last number in the name, the default), first (the first number), order (the position in each camera\'s list), or a pattern with one (\\d+) such as sync(\\d+))');
    assert.equal(await page.isDisabled('#rig-solve'), true);
    await shot('bad');
    // No name with a number: by order (sorted names); a camera with fewer images misses the last frames.
    await page.click('#rig-clear');
    assert.equal(await rigAdd(page, ['a.png', 'b.png', 'c.png'], ['x.png', 'y.png'], '3 frames'), '3 frames over 2 cameras, grouped by order (sorted names).');
    assert.equal(await page.isDisabled('#rig-solve'), false);
  }],

  // ---- step 1, target: the field refused, the target in use kept ----
  ['spec-zero-size', targetCase('square_mm', '0', 'target: the square size must be a positive length, got 0 mm')],
  ['spec-negative-size', targetCase('square_mm', '-30', 'target: the square size must be a positive length, got -30 mm')],
  ['spec-empty-size', targetCase('square_mm', '', 'Square size (mm): the field is empty or not a number; enter a size in millimetres, e.g. 30')],
  // The browser cannot hold 1e400 in a number field: its value is ''.
  ['spec-overflowing-size', targetCase('square_mm', '1e400', 'Square size (mm): the field is empty or not a number; enter a size in millimetres, e.g. 30')],
  // 1e-400 mm is 0 as a double.
  ['spec-underflowing-size', targetCase('square_mm', '1e-400', 'target: the square size must be a positive length, got 0 mm')],
  ['spec-one-column', targetCase('cols', '1', 'target: a grid needs 2 to 100000 points with at least 2 per side, got 1x6')],
  ['spec-size-in-exponent-form (a good input the page refused)', async (page, { url }) => {
    // "3e1" mm reached the core as null ("target JSON: invalid type: null,
    // expected f64"): the page appended "e-3" to the text.
    await page.goto(`${url}#target`);
    await ready(page);
    await page.fill('#target-form input[name=square_mm]', '3e1');
    await page.waitForFunction(() => /^Target spec: chessboard:9x6:30mm /.test(document.getElementById('target-spec').textContent), null, { timeout: 10000 });
    await page.fill('#target-form input[name=square_mm]', '2.5e+1');
    await page.waitForFunction(() => /^Target spec: chessboard:9x6:25mm /.test(document.getElementById('target-spec').textContent), null, { timeout: 10000 });
    assert.equal(await page.textContent('#target-error'), '');
  }],

  // ---- step 6, workflows: the CSV refused with line and column ----
  ['planar-csv-empty', planarCase('', 'the file is empty: expected a CSV header line')],
  ['planar-csv-missing-columns', planarCase('a,b\n1,2\n', 'line 1: missing column(s) height_mm, u_px, v_px, x_mm, y_mm (expected header height_mm,u_px,v_px,x_mm,y_mm, got a,b)')],
  ['planar-csv-not-a-number', planarCase('height_mm,u_px,v_px,x_mm,y_mm\n10,abc,3,4,5\n', "line 2, column 2: u_px: expected a finite number, got 'abc'")],
  ['planar-file-empty', planarCase({ file: text('points.csv', '') }, 'points.csv: the file is empty: expected a CSV file with the header height_mm,u_px,v_px,x_mm,y_mm')],
  ['planar-file-not-utf8', planarCase({ file: text('points.csv', Buffer.from('height_mm,u_px,v_px,x_mm,y_mm\n10,1,2,3,4 # \xb5m\n', 'latin1')) },
    'points.csv: the file is not UTF-8 text: save it as UTF-8 (or plain ASCII) and load it again')],
  ['xytable-too-few-positions', async (page, { url, shot }) => {
    await page.goto(`${url}#workflows`);
    await ready(page);
    await page.fill('#xytable-csv', stageCsv());
    await page.click('#xytable-solve');
    await page.waitForFunction(() => /^Batch least squares \(RMS /.test(document.querySelector('#xytable-results h4')?.textContent || ''), null, { timeout: 20000 });
    await page.fill('#xytable-csv', 'x_mm,y_mm,z_mm,u_px,v_px\n1,2,3,4,5\n');
    await page.click('#xytable-solve');
    await page.locator('#xytable-results .msg-error').waitFor({ timeout: 20000 });
    assert.equal(await page.textContent('#xytable-results'), 'requires at least 6 3-D/2-D point pairs, got 1');
    await shot('bad');
    await page.fill('#xytable-csv', stageCsv());
    await page.click('#xytable-solve');
    await page.waitForFunction(() => /^Batch least squares \(RMS /.test(document.querySelector('#xytable-results h4')?.textContent || ''), null, { timeout: 20000 });
  }],
  ['planar-csv-short-row', planarCase('height_mm,u_px,v_px,x_mm,y_mm\n10,1,2,3\n', 'line 2: expected 5 comma-separated fields like the header, got 4')],
];
