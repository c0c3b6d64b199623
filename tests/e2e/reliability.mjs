// Nothing falls over, nothing injects, nothing leaks (issue 17 §4, §5; issue
// 16 §4): stereo pairs grouped by the core's rule on the rig step, a corrupt JPEG and a wasm trap
// answered with messages while the page keeps working, crafted share links
// shown inertly in the page and in the report, and no request leaving
// 127.0.0.1 during a whole session.
import assert from 'node:assert/strict';
import { deflateRawSync } from 'node:zlib';
import { makePng, checker } from '../support/images.mjs';
import { newContext } from './harness.mjs';

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });

/** The 28-byte JPEG of issue 16: a DHT segment whose table overruns the file. */
const BAD_JPEG = Buffer.from([0xff, 0xd8, 0xff, 0xc4, 0x00, 0x16, 0x00, 0x02, 0x01, ...new Array(14).fill(0), 0x00, 0x01, 0x02, 0xff, 0xd9]);

/** A 9x6 inner-corner chessboard (10x7 squares of 24 px) on a white margin: the page's default target. */
function boardPng() {
  const s = 24, m = 36;
  return makePng(10 * s + 2 * m, 7 * s + 2 * m, (x, y) => {
    const [i, j] = [Math.floor((x - m) / s), Math.floor((y - m) / s)];
    const inside = x >= m && y >= m && i < 10 && j < 7;
    const v = inside && (i + j) % 2 === 0 ? 0 : 255;
    return [v, v, v];
  });
}

const cards = (page) => page.$$eval('.card', (els) => els.map((el) => ({
  name: el.querySelector('.name').textContent, cls: el.className, meta: el.querySelector('.meta').textContent,
})));

/** Wait until no card is pending or detecting. */
const settled = (page, n) => page.waitForFunction((n) => document.querySelectorAll('.card').length === n
  && !document.querySelector('.card.pending') && [...document.querySelectorAll('.card .meta')].every((m) => !/detecting/.test(m.textContent))
  && document.getElementById('progress-row').hidden, n, { timeout: 60000 });

/** A #share= fragment holding `payload`, as share.js writes it (deflate-raw, base64url). */
const shareFragment = (payload) => deflateRawSync(Buffer.from(JSON.stringify(payload))).toString('base64url');

const EVIL = {
  img: '<img src=x onerror="window.__pwned=1">',
  script: '</script><script>window.__pwned=2</script>',
  js: 'javascript:window.__pwned=3',
};

function craftedPayload() {
  return {
    kind: 'robocal-share', schema: 1, robocal_version: EVIL.script,
    target: { kind: 'chessboard', cols: 9, rows: 6, square_m: 0.03 },
    camera: {
      model: 'brown', method: 'zhang', comparison: null,
      result: {
        model: EVIL.img, image_size_px: [640, 480], rms_px: 0.5, method: EVIL.js,
        camera_matrix: [[500, 0, 320], [0, 500, 240], [0, 0, 1]],
        distortion: { k1: 0.1, [EVIL.script]: EVIL.img }, std: {}, views: [],
        warnings: [EVIL.img, { message: EVIL.js }],
      },
    },
    handeye: {
      setup: 'eye-in-hand',
      result: {
        method: EVIL.img,
        gripper_from_camera: { matrix_row_major: [[1, 0, 0, 0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], translation_m: [0.1, 0, 0], quaternion_xyzw: [0, 0, 0, 1] },
        errors: { [EVIL.img]: EVIL.js }, warnings: [EVIL.script],
      },
    },
    workflows: { planar: null, xytable: null },
  };
}

/** Nothing crafted became markup: no <img src=x>, no injected script, no javascript: link, nothing ran. */
async function assertInert(page, where) {
  const found = await page.evaluate(() => ({
    pwned: window.__pwned || null,
    imgX: [...document.querySelectorAll('img')].filter((i) => i.getAttribute('src') === 'x').length,
    scripts: [...document.querySelectorAll('script')].filter((s) => /__pwned/.test(s.textContent)).length,
    jsLinks: [...document.querySelectorAll('[href], [src]')].filter((e) => /^\s*javascript:/i.test(e.getAttribute('href') || e.getAttribute('src') || '')).length,
  }));
  assert.deepEqual(found, { pwned: null, imgX: 0, scripts: 0, jsLinks: 0 }, where);
}

async function trapSession(page, url, shot) {
  // Test-only: the served robocal.js is wrapped so that decoding bytes that
  // start with "TRAP" calls the wasm allocator with an impossible size,
  // which aborts the instance (a real `RuntimeError: unreachable` from
  // robocal's wasm). The normal build has no such path.
  // A route handler's error is not the test's: it would end the whole run as
  // an unhandled rejection (the context closing at the end of the test while
  // a worker still fetches robocal.js disposes the response). Without the
  // wrapper the trap never fires and the checks below fail instead.
  await page.route('**/pkg/robocal.js', async (route) => {
    try {
      const original = await (await route.fetch()).text();
      if (!/export function decode_image_preview\(/.test(original)) throw new Error('no decode_image_preview to wrap');
      const body = `${original.replace('export function decode_image_preview(', 'function real_decode_image_preview(')}
export function decode_image_preview(bytes, max_side, options) {
if (bytes[0] === 0x54 && bytes[1] === 0x52 && bytes[2] === 0x41 && bytes[3] === 0x50) wasm.__wbindgen_malloc(0xfffffff0, 1);
return real_decode_image_preview(bytes, max_side, options);
}
`;
      await route.fulfill({ status: 200, contentType: 'text/javascript', body });
    } catch (e) {
      if (!page.isClosed()) console.log(`     trap route: ${e.message}`);
      await route.abort().catch(() => {});
    }
  });
  await page.goto(url);
  await ready(page);
  await page.setInputFiles('#file-input', [
    { name: 'trap.png', mimeType: 'image/png', buffer: Buffer.from('TRAP and then anything') },
    { name: 'board.png', mimeType: 'image/png', buffer: boardPng() },
  ]);
  await settled(page, 2);
  // One upload is put in name order: board.png, trap.png.
  const byName = Object.fromEntries((await cards(page)).map((c) => [c.name, c]));
  const [trap, board] = [byName['trap.png'], byName['board.png']];
  assert.match(trap.cls, /\berror\b/);
  assert.equal(trap.meta, 'the calibration engine crashed while decoding trap.png (unreachable); it was restarted and your images and results are kept. Please report this with the file or data of that step.');
  assert.equal(board.meta, 'PNG · 312×240 px · RGB, 8-bit · 54 points');
  // One calibration takes one resolution: the board of another size goes before the demo.
  await page.click('a[data-step=images]'); // a new session opens on step 1 (the target)
  await page.click('input[aria-label="use board.png in the calibration"]');
  await shot('after-trap');
  // The replaced workers decode, detect and solve as before: the demo,
  // which over an open session asks and starts a new one.
  page.once('dialog', (d) => d.accept());
  await page.click('#demo-button');
  await page.waitForFunction(() => {
    const text = document.getElementById('image-summary').textContent;
    return /^12 files, 12 decoded, 12 with the target$/.test(text);
  }, null, { timeout: 180000 });
  await page.click('a[data-step=camera]');
  await page.click('#solve-camera');
  await page.locator('#camera-params').waitFor({ timeout: 60000 });
  // A second trap after all that is answered the same way.
  await page.click('a[data-step=images]');
  await page.setInputFiles('#file-input', [{ name: 'again.png', mimeType: 'image/png', buffer: Buffer.from('TRAP again') }]);
  await settled(page, 13);
  const again = (await cards(page)).find((c) => c.name === 'again.png');
  assert.match(again.meta, /^the calibration engine crashed while decoding again\.png \(unreachable\)/);
  assert.equal((await cards(page)).filter((c) => / points$/.test(c.meta)).length, 12, 'detections kept (the 12 demo images)');
  }

export const tests = [
  ['stereo pairs on the rig step by the core rule: shuffled numbered names group right, a frame seen by one camera is kept, a number twice shows the core message', async (page, { url, shot }) => {
    await page.goto(`${url}#stereo`);
    await ready(page);
    const png = (name) => ({ name, mimeType: 'image/png', buffer: makePng(40, 30, checker(5)) });
    const names = () => page.$$eval('#rig-frame-table tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent.replace(/: .*$/, ''))));
    await page.setInputFiles('#rig-input-0', [png('left_10.png'), png('left_2.png'), png('left_07.png')]);
    await page.setInputFiles('#rig-input-1', [png('right7.png'), png('right010.png'), png('right002.png')]);
    // The left images alone already make 3 frames over 2 cameras: wait for the right ones in the table too.
    await page.waitForFunction(() => /^3 frames over 2 cameras, grouped by the number in the file names\.$/.test(document.getElementById('rig-grouping')?.textContent || '')
      && [...document.querySelectorAll('#rig-frame-table tbody tr')].filter((tr) => /^right/.test(tr.cells[2]?.textContent || '')).length === 3, null, { timeout: 10000 });
    assert.deepEqual(await names(), [['2', 'left_2.png', 'right002.png'], ['7', 'left_07.png', 'right7.png'], ['10', 'left_10.png', 'right010.png']]);
    assert.equal(await page.isDisabled('#rig-solve'), false);
    // A right image without a left one: a frame only the right camera saw (a rig camera may miss any frame).
    await page.setInputFiles('#rig-input-1', [png('right11.png')]);
    await page.waitForFunction(() => /^4 frames/.test(document.getElementById('rig-grouping')?.textContent || ''), null, { timeout: 10000 });
    assert.deepEqual((await names())[3], ['11', '—', 'right11.png']);
    // Number 2 twice in the right camera: the core's error, naming both files.
    await page.setInputFiles('#rig-input-1', [png('right2.png')]);
    await page.waitForFunction(() => /cannot be grouped/.test(document.getElementById('rig-grouping')?.textContent || ''), null, { timeout: 10000 });
    assert.equal(await page.textContent('#rig-grouping'), 'The images cannot be grouped into frames: images: frames are grouped by the last number in the file names, but number 2 is in two camera cam1 images: right002.png, right2.png (group by number or last (the last number in the name, the default), first (the first number), order (the position in each camera\'s list), or a pattern with one (\\d+) such as sync(\\d+))');
    assert.equal(await page.isDisabled('#rig-solve'), true);
    await shot('mismatch');
    // No numbers anywhere: by order of the sorted names.
    await page.click('#rig-clear');
    await page.setInputFiles('#rig-input-0', [png('b.png'), png('a.png'), png('c.png')]);
    await page.setInputFiles('#rig-input-1', [png('z.png'), png('x.png'), png('y.png')]);
    // Again the left images alone make 3 frames: wait for the right camera's column to fill.
    await page.waitForFunction(() => /^3 frames over 2 cameras, grouped by order/.test(document.getElementById('rig-grouping')?.textContent || '')
      && [...document.querySelectorAll('#rig-frame-table tbody tr')].filter((tr) => /^[xyz]\.png/.test(tr.cells[2]?.textContent || '')).length === 3, null, { timeout: 10000 });
    assert.deepEqual(await names(), [['0', 'a.png', 'x.png'], ['1', 'b.png', 'y.png'], ['2', 'c.png', 'z.png']]);
  }],
  ['the 28-byte JPEG gets an error card naming format and defect; a later good image detects', async (page, { url, shot }) => {
    await page.goto(url);
    await ready(page);
    assert.equal(BAD_JPEG.length, 28);
    await page.setInputFiles('#file-input', [{ name: 'tiny.jpg', mimeType: 'image/jpeg', buffer: BAD_JPEG }]);
    await settled(page, 1);
    const [bad] = await cards(page);
    assert.match(bad.cls, /\berror\b/);
    assert.match(bad.meta, /^corrupt or truncated JPEG file: .*Huffman/);
    await shot('bad-jpeg');
    await page.setInputFiles('#file-input', [{ name: 'board.png', mimeType: 'image/png', buffer: boardPng() }]);
    await settled(page, 2);
    const [, good] = await cards(page);
    assert.deepEqual([good.name, good.meta], ['board.png', 'PNG · 312×240 px · RGB, 8-bit · 54 points']);
  }],
  ['a wasm trap: the worker is replaced, the file is named, the page detects and solves as before', async (_page, { url, shot: _shot, browser }) => {
    // No service worker: it would fetch robocal.js past the route below.
    const context = await newContext(browser, { serviceWorkers: 'block' });
    const page = await context.newPage();
    const shot = (label) => page.screenshot({ path: `tests/e2e/screenshots/reliability-trap-${label}.png`, fullPage: true });
    try { await trapSession(page, url, shot); } finally { await context.close(); }
  }],
  ['a crafted share link is shown inertly in the page and in the HTML report, which has a strict CSP', async (page, { url, shot }) => {
    await page.goto(`${url}#share=${shareFragment(craftedPayload())}`);
    await page.locator('#readonly-banner:not([hidden])').waitFor({ timeout: 30000 });
    await page.waitForTimeout(500);
    for (const step of ['camera', 'handeye', 'export', 'share']) {
      await page.evaluate((s) => { location.hash = s; }, step);
      await page.waitForTimeout(300);
      await assertInert(page, `page, step ${step}`);
    }
    // The crafted strings are on the page as text.
    const text = await page.textContent('body');
    assert.ok(text.includes(EVIL.img), 'the <img> string shown as text');
    await shot('shared');
    await page.evaluate(() => { location.hash = 'share'; });
    const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#download-report')]);
    const html = (await (await dl.createReadStream()).toArray()).join('');
    const csp = /<meta http-equiv="Content-Security-Policy" content="([^"]+)">/.exec(html);
    assert.ok(csp, 'report CSP meta');
    assert.match(csp[1], /^default-src 'none'; style-src 'sha256-[A-Za-z0-9+/=]+'; img-src data:; base-uri 'none'; form-action 'none'$/);
    assert.ok(!/<script/i.test(html), 'no <script> in the report');
    assert.ok(!/<img src="?x/i.test(html), 'no <img src=x> in the report');
    assert.ok(html.includes('&lt;img src=x onerror="window.__pwned=1"&gt;'), 'the <img> string escaped as text');
    assert.ok(html.includes('&lt;/script&gt;&lt;script&gt;window.__pwned=2&lt;/script&gt;'), 'the </script> string escaped as text');
    // Opened as a page, the report runs nothing and loads nothing.
    const report = await page.context().newPage();
    const requests = [];
    report.on('request', (r) => requests.push(r.url()));
    await report.setContent(html);
    await assertInert(report, 'report');
    assert.ok((await report.textContent('body')).includes(EVIL.js));
    assert.deepEqual(requests.filter((u) => !u.startsWith('data:')), []);
    await report.close();
  }],
  ['no request leaves 127.0.0.1 during a whole session (demo, upload, solve, export, share)', async (page, { url, shot }) => {
    const seen = [];
    page.context().on('request', (r) => seen.push(r.url()));
    await page.goto(url);
    await ready(page);
    // The page's own CSP has no unsafe-inline.
    const csp = await page.$eval('meta[http-equiv=Content-Security-Policy]', (m) => m.content);
    assert.ok(!/unsafe-inline/.test(csp), csp);
    assert.match(csp, /default-src 'self'/);
    await page.click('#demo-button');
    await page.waitForFunction(() => /12 with the target/.test(document.getElementById('image-summary').textContent), null, { timeout: 180000 });
    // An upload of another size (decoded, not used: one calibration takes one resolution).
    await page.setInputFiles('#file-input', [{ name: 'extra.png', mimeType: 'image/png', buffer: makePng(64, 48, checker(8)) }]);
    await page.waitForFunction(() => /^13 files, 13 decoded/.test(document.getElementById('image-summary').textContent), null, { timeout: 60000 });
    await page.click('a[data-step=camera]');
    await page.click('#solve-camera');
    await page.locator('#camera-params').waitFor({ timeout: 60000 });
    await page.click('a[data-step=export]');
    await page.locator('#export-preview').waitFor({ timeout: 10000 });
    await page.click('#camera-formats button[data-format=opencv-yaml]').catch(() => page.click('#camera-formats button'));
    await page.waitForFunction(() => /bytes, written by the robocal core/.test(document.getElementById('export-status').textContent), null, { timeout: 10000 });
    await page.click('a[data-step=share]');
    await page.click('#make-share');
    await page.waitForFunction(() => /^Link ready/.test(document.getElementById('share-status').textContent), null, { timeout: 10000 });
    const link = await page.inputValue('#share-link');
    const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#download-report')]);
    await dl.path();
    await page.goto(link); // a new share fragment in an open tab reloads the page on it
    await page.locator('#readonly-banner:not([hidden])').waitFor({ timeout: 30000 });
    await page.waitForTimeout(500);
    await shot('session-done');
    const origin = new URL(url).origin;
    const away = seen.filter((u) => !(u.startsWith(`${origin}/`) || u.startsWith('blob:') || u.startsWith('data:')));
    assert.deepEqual(away, [], 'requests that left 127.0.0.1');
    assert.ok(seen.length > 10, `requests seen: ${seen.length}`);
    assert.equal(new URL(url).hostname, '127.0.0.1');
  }],
];
