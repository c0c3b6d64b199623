// Issue 21 on the page: live capture from a camera. Chromium's fake camera
// (`--use-fake-device-for-media-stream`) stands in for a webcam; the
// permission is granted per test (a context without it is refused, as a
// user pressing "Block" would). The camera source on the images step: the
// refused and no-camera messages, the device and resolution pickers, the
// live preview with the frame rates and the detection state, manual
// capture (button and space bar) into cards kept in IndexedDB, exclusion
// and the PNG download of the captured frames.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';

export const launchArgs = ['--use-fake-device-for-media-stream'];

const REFUSED = 'Camera access was refused. Allow the camera for this page (the camera icon in the address bar, or the site settings), then press Start camera again. Image files can still be added above.';
const NO_CAMERA = 'No camera was found. Connect a camera and press Start camera again, or add image files above.';

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });

/** The images step with the camera permission granted (or not). */
async function open(page, url, grant = true) {
  if (grant) await page.context().grantPermissions(['camera'], { origin: url });
  await page.goto(`${url}#images`);
  await ready(page);
}

/** Wait until the live status reports at least `frames` detections a second (the loop runs). */
const live = (page, detectFps = 1) => page.waitForFunction((min) => {
  const s = document.getElementById('camera-status');
  return s && Number(s.dataset.detectFps) >= min;
}, detectFps, { timeout: 30000 });

const cards = (page) => page.$$eval('.card', (els) => els.map((el) => ({
  name: el.querySelector('.name').textContent, meta: el.querySelector('.meta').textContent, used: el.querySelector('.include input').checked,
})));

/** Width and height of PNG bytes (the IHDR chunk). */
const pngSize = (buf) => [buf.readUInt32BE(16), buf.readUInt32BE(20)];

export const tests = [
  ['permission refused: the message says what to do, file upload stays', async (page, { url, shot }) => {
    await open(page, url, false);
    await page.click('#camera-start');
    await page.locator('#camera-message:not([hidden])').waitFor({ timeout: 10000 });
    assert.equal(await page.textContent('#camera-message'), REFUSED);
    assert.equal(await page.getAttribute('#camera-message', 'role'), 'alert');
    assert.equal(await page.isVisible('#camera-live'), false, 'no preview without a camera');
    assert.equal(await page.isEnabled('#camera-start'), true, 'the user can try again');
    assert.equal(await page.isVisible('#choose-files'), true);
    await shot('refused');
  }],
  ['no camera: says so without asking for permission', async (page, { url, shot }) => {
    // A machine without any video input: enumerateDevices lists none.
    await page.addInitScript(() => {
      const md = navigator.mediaDevices;
      const all = md.enumerateDevices.bind(md);
      md.enumerateDevices = async () => (await all()).filter((d) => d.kind !== 'videoinput');
      md.getUserMedia = async () => { throw new Error('getUserMedia must not be called without a camera'); };
    });
    await open(page, url);
    await page.click('#camera-start');
    await page.locator('#camera-message:not([hidden])').waitFor({ timeout: 10000 });
    assert.equal(await page.textContent('#camera-message'), NO_CAMERA);
    await shot('no-camera');
  }],
  ['preview: device list, resolutions up to the maximum, frame rates, not-found state drawn', async (page, { url, shot }) => {
    await open(page, url);
    await page.click('#camera-start');
    await live(page, 2);
    const devices = await page.$$eval('#camera-device option', (os) => os.map((o) => o.textContent));
    assert.ok(devices.includes('fake_device_0'), `the fake camera is listed by its label: ${devices}`);
    const res = await page.$$eval('#camera-resolution option', (os) => os.map((o) => o.value));
    assert.equal(await page.inputValue('#camera-resolution'), '1280x720');
    assert.equal(res[res.length - 1], 'max', 'the maximum is offered last');
    const status = await page.$eval('#camera-status', (s) => ({ ...s.dataset, text: s.textContent }));
    assert.equal(status.state, 'none', 'the fake camera shows no board');
    assert.match(status.text, /^Board not found · 1280 × 720 · camera \d+\.\d fps · detection \d+\.\d fps \(\d+ ms a frame; frames dropped while busy: \d+\)$/);
    assert.ok(Number(status.fps) >= 5, `camera frame rate ${status.fps}`);
    // One detection in flight: the detection rate never exceeds the camera's.
    assert.ok(Number(status.detectFps) <= Number(status.fps) + 1, `detection ${status.detectFps} fps, camera ${status.fps} fps`);
    const overlay = await page.$eval('#camera-overlay', (c) => [c.width, c.height]);
    assert.deepEqual(overlay, [1280, 720], 'the overlay has the frame\'s pixels');
    assert.equal(await page.textContent('#camera-found'), 'Board not found');
    await shot('preview');
    // Another resolution: the camera is opened again at it.
    await page.selectOption('#camera-resolution', '640x480');
    await page.waitForFunction(() => /· 640 × 480 ·/.test(document.getElementById('camera-status').textContent), null, { timeout: 20000 });
    assert.deepEqual(await page.$eval('#camera-video', (v) => [v.videoWidth, v.videoHeight]), [640, 480]);
    await page.click('#camera-stop');
    assert.equal(await page.isVisible('#camera-live'), false);
  }],
  ['manual capture: button and space bar add PNG cards, kept after a reload, downloadable', async (page, { url, shot }) => {
    await open(page, url);
    await page.selectOption('#camera-resolution', '1920x1080');
    await page.click('#camera-start');
    await live(page);
    await page.click('#capture-frame');
    await page.locator('#step-images h2').click(); // focus off the button: space captures
    await page.keyboard.press('Space');
    await page.waitForFunction(() => [...document.querySelectorAll('.card .meta')].filter((m) => /board not found/.test(m.textContent)).length === 2, null, { timeout: 30000 });
    let list = await cards(page);
    assert.deepEqual(list.map((c) => c.name), ['capture_001.png', 'capture_002.png']);
    for (const c of list) assert.match(c.meta, /^PNG · 1920×1080 px · RGBA, 8-bit · /, 'full resolution');
    assert.equal(await page.textContent('#capture-count'), '2 frames captured');
    await shot('captured');
    // Without the board both are left out of the calibration, like uploads without it.
    assert.deepEqual(list.map((c) => c.used), [false, false]);
    const downloads = [];
    page.on('download', (d) => downloads.push(d));
    await page.click('#download-captures');
    for (let i = 0; i < 50 && downloads.length < 2; i++) await page.waitForTimeout(100);
    assert.deepEqual(downloads.map((d) => d.suggestedFilename()), ['capture_001.png', 'capture_002.png']);
    for (const d of downloads) assert.deepEqual(pngSize(readFileSync(await d.path())), [1920, 1080]);
    // Kept in IndexedDB: a reload shows them again and the numbering goes on.
    await page.waitForTimeout(500);
    await page.reload();
    await ready(page);
    await page.waitForFunction(() => document.querySelectorAll('.card').length === 2, null, { timeout: 30000 });
    list = await cards(page);
    assert.deepEqual(list.map((c) => [c.name, c.used]), [['capture_001.png', false], ['capture_002.png', false]]);
    await page.click('#camera-start');
    await live(page);
    await page.click('#capture-frame');
    await page.waitForFunction(() => document.querySelectorAll('.card').length === 3, null, { timeout: 30000 });
    assert.equal((await cards(page))[2].name, 'capture_003.png');
  }],
  ['hand-eye capture: a typed pose goes with its frame, a bad line captures nothing, the robot step reads the typed poses', async (page, { url, shot }) => {
    await open(page, url);
    await page.click('#camera-start');
    await live(page);
    await page.fill('#capture-pose', '0.4 0.1');
    await page.click('#capture-frame');
    await page.waitForFunction(() => /^Nothing captured/.test(document.getElementById('capture-pose-note').textContent), null, { timeout: 20000 });
    const note = await page.textContent('#capture-pose-note');
    assert.match(note, /^Nothing captured: the robot pose could not be read \(.+\)\. Correct the line, or empty it to capture without a pose\.$/);
    assert.equal(await page.$$eval('.card', (c) => c.length), 0, 'no frame without its pose');
    // Two UR poses (metres, rotation vector), the second one by Enter in the field.
    const poses = ['0.412,-0.105,0.331,2.2,-2.21,0.01', '0.5,0.0,0.4,0.0,3.1,0.2'];
    await page.fill('#capture-pose', poses[0]);
    await page.click('#capture-frame');
    await page.waitForFunction(() => document.querySelectorAll('.card').length === 1, null, { timeout: 20000 });
    assert.match(await page.textContent('#capture-pose-note'), /^capture_001\.png is paired with the pose read as /);
    assert.equal(await page.inputValue('#capture-pose'), '', 'the field is emptied for the next pose');
    await page.fill('#capture-pose', poses[1]);
    await page.press('#capture-pose', 'Enter');
    await page.waitForFunction(() => document.querySelectorAll('.card').length === 2, null, { timeout: 20000 });
    await shot('captured-with-poses');
    await page.click('a[data-step=robot]');
    await page.locator('#pose-table').waitFor({ timeout: 20000 });
    assert.match(await page.textContent('#pose-format-used'), /^poses typed at capture: 2 poses read as /);
    const rows = await page.$$eval('#pose-table tbody tr', (trs) => trs.map((tr) => [...tr.children].map((td) => td.textContent)));
    // x y z shown in mm: the typed metres times 1000.
    assert.deepEqual(rows.map((r) => r.slice(3, 6).map(Number)), [[412, -105, 331], [500, 0, 400]]);
    const pairing = await page.$$eval('#pairing-table tbody tr', (trs) => trs.map((tr) => tr.children[2].textContent));
    assert.deepEqual(pairing, ['capture_001.png', 'capture_002.png']);
    await shot('robot-step');
  }],
];
