// Issue 18 on the page: marker boards. The target step offers ChArUco
// (OpenCV) and AprilGrid (Kalibr) with their fields, a live drawing, the
// printable SVG and validation naming the field; images of a rendered
// ChArUco board (`robocal render --target charuco:...`) give cards with the
// corner count and ids, a partial view (the right 40 % of one image painted grey,
// as a gripper would hide it) is a valid detection, and the camera solved
// from them lands on the render's truth.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { root } from './harness.mjs';

const CLI = join(root, 'target/release/robocal');
const SPEC = 'charuco:8x6:30mm:22mm:DICT_5X5_100';
const CORNERS = 7 * 5;
const KALIBR_MISSING = "broken.yaml: Kalibr target: missing key 'tagSize'";
const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });

/** `robocal render --target SPEC --views 8 --noise 2` (seeded): the PNGs and truth.json. */
function render() {
  const dir = mkdtempSync(join(tmpdir(), 'robocal-markers-'));
  try {
    execFileSync(CLI, ['render', '--out', dir, '--target', SPEC, '--views', '8', '--seed', '5', '--noise', '2'], { stdio: 'ignore' });
    const images = readdirSync(dir).filter((f) => f.endsWith('.png')).sort()
      .map((name) => ({ name, mimeType: 'image/png', buffer: readFileSync(join(dir, name)) }));
    return { images, truth: JSON.parse(readFileSync(join(dir, 'truth.json'), 'utf8')) };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

/** The image with its right `fraction` painted mid-grey in the page (a canvas round trip), as PNG bytes. */
async function occlude(page, buffer, fraction) {
  const bytes = await page.evaluate(async ([data, fraction]) => {
    const bitmap = await createImageBitmap(new Blob([new Uint8Array(data)], { type: 'image/png' }));
    const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
    const ctx = canvas.getContext('2d');
    ctx.drawImage(bitmap, 0, 0);
    ctx.fillStyle = '#808080';
    ctx.fillRect(Math.round(bitmap.width * (1 - fraction)), 0, bitmap.width, bitmap.height);
    return [...new Uint8Array(await (await canvas.convertToBlob({ type: 'image/png' })).arrayBuffer())];
  }, [[...buffer], fraction]);
  return Buffer.from(bytes);
}

const cards = (page) => page.$$eval('.card', (els) => els.map((el) => ({
  name: el.querySelector('.name').textContent, meta: el.querySelector('.meta').textContent,
  cls: el.className, used: el.querySelector('.include input').checked,
})));

export const tests = [
  ['target step: ChArUco and AprilGrid fields, live drawing, spec round trip, printable SVG, messages naming the field', async (page, { url, shot }) => {
    await page.goto(`${url}#target`);
    await ready(page);
    const options = await page.$$eval('#target-kind option', (els) => els.map((e) => e.textContent));
    assert.ok(options.includes('ChArUco (OpenCV)') && options.includes('AprilGrid (Kalibr)'), options.join(', '));
    const dictionaries = await page.$$eval('#target-form select[name=dictionary] option', (els) => els.map((e) => e.value));
    assert.equal(dictionaries.length, 22, 'every OpenCV predefined dictionary');
    assert.deepEqual([dictionaries[0], dictionaries[15], dictionaries[21]], ['DICT_4X4_50', 'DICT_7X7_1000', 'DICT_ARUCO_MIP_36h12']);
    const specShown = (re) => page.waitForFunction((re) => new RegExp(re).test(document.getElementById('target-spec').textContent), re.source, { timeout: 20000 });
    const canvasSpec = () => page.$eval('#target-canvas', (c) => c.dataset.spec);

    // ChArUco with the form's defaults, then 8x6 squares, 30/22 mm, first id 4, legacy.
    await page.selectOption('#target-kind', 'charuco');
    await specShown(/^Target spec: charuco:12x9:20mm:15mm:DICT_5X5_100 /);
    assert.equal(await page.isVisible('#target-form input[name=cols]'), false, 'the grid fields of the other kinds are hidden');
    await page.fill('#target-form input[name=squares_x]', '8');
    await page.fill('#target-form input[name=squares_y]', '6');
    await page.fill('#target-form input[name=charuco_square_mm]', '30');
    await page.fill('#target-form input[name=marker_mm]', '22');
    await page.fill('#target-form input[name=first_id]', '4');
    await page.check('#target-form input[name=legacy]');
    await specShown(/^Target spec: charuco:8x6:30mm:22mm:DICT_5X5_100:first=4:legacy /);
    assert.equal(await canvasSpec(), 'charuco:8x6:30mm:22mm:DICT_5X5_100:first=4:legacy', 'the drawing is of the spec shown');
    // The drawing is a sheet with black squares and markers: some pixels dark.
    const dark = await page.$eval('#target-canvas', (c) => {
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) if (d[i] < 60 && d[i + 1] < 60 && d[i + 2] < 60) n++;
      return n / (c.width * c.height);
    });
    assert.ok(dark > 0.1 && dark < 0.6, `dark share of the drawing ${dark}`);
    // The session keeps the core's JSON: a reload puts it back in the form.
    await page.waitForTimeout(500);
    await page.reload();
    await ready(page);
    await specShown(/^Target spec: charuco:8x6:30mm:22mm:DICT_5X5_100:first=4:legacy /);
    assert.deepEqual(await page.$eval('#target-form', (f) => [f.elements.kind.value, f.elements.squares_x.value, f.elements.charuco_square_mm.value, f.elements.dictionary.value, f.elements.first_id.value, f.elements.legacy.checked]),
      ['charuco', '8', '30', 'DICT_5X5_100', '4', true]);
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#print-target')]);
    assert.equal(download.suggestedFilename(), 'robocal-target-charuco_8x6_30mm_22mm_DICT_5X5_100_first=4_legacy.svg');
    const svg = readFileSync(await download.path(), 'utf8');
    assert.match(svg, /robocal target charuco:8x6:30mm:22mm:DICT_5X5_100:first=4:legacy/);
    await shot('charuco-target');

    // Messages: a field left empty is named; the core's check (marker not smaller than the square) too.
    await page.fill('#target-form input[name=marker_mm]', '');
    await page.waitForFunction(() => document.getElementById('target-error').textContent !== '');
    assert.equal(await page.textContent('#target-error'), 'Marker side (mm): the field is empty or not a number; enter a size in millimetres, e.g. 30');
    assert.equal(await page.isDisabled('#print-target'), true);
    await page.fill('#target-form input[name=marker_mm]', '35');
    await page.waitForFunction(() => /marker side/.test(document.getElementById('target-error').textContent));
    assert.equal(await page.textContent('#target-error'), 'target: the marker side (35 mm) must be smaller than the square side (30 mm)');
    await page.fill('#target-form input[name=squares_x]', '2.5');
    await page.waitForFunction(() => /^Squares across/.test(document.getElementById('target-error').textContent));
    assert.equal(await page.textContent('#target-error'), 'Squares across: 2.5 is not a whole number; enter a whole number of squares, at least 2 (e.g. 12)');
    await page.selectOption('#target-form select[name=dictionary]', 'DICT_4X4_50');
    await page.fill('#target-form input[name=squares_x]', '12');
    await page.fill('#target-form input[name=squares_y]', '9');
    await page.fill('#target-form input[name=marker_mm]', '22');
    await page.waitForFunction(() => /too many markers/.test(document.getElementById('target-error').textContent));
    assert.equal(await page.textContent('#target-error'), 'target: too many markers: a 12x9 ChArUco board needs 54 markers from id 4, but DICT_4X4_50 has 50 (use a larger dictionary or fewer squares)');

    // AprilGrid: Kalibr's 6x6 board of 88 mm tags, spacing 0.3.
    await page.selectOption('#target-kind', 'aprilgrid');
    // The first id field is shared: it keeps the ChArUco board's 4.
    await specShown(/^Target spec: aprilgrid:6x6:88mm:0.3:first=4 /);
    assert.equal(await page.textContent('#target-error'), '');
    await page.fill('#target-form input[name=first_id]', '36');
    await specShown(/^Target spec: aprilgrid:6x6:88mm:0.3:first=36 /);
    await page.fill('#target-form input[name=spacing_ratio]', '1.5');
    await page.waitForFunction(() => /spacing ratio/.test(document.getElementById('target-error').textContent));
    assert.equal(await page.textContent('#target-error'), 'target: the AprilGrid spacing ratio must be in (0, 1] (Kalibr\'s tagSpacing), got 1.5');
    await page.fill('#target-form input[name=spacing_ratio]', '0.3');
    await specShown(/^Target spec: aprilgrid:6x6:88mm:0.3:first=36 /);
    const [grid] = await Promise.all([page.waitForEvent('download'), page.click('#print-target')]);
    assert.match(readFileSync(await grid.path(), 'utf8'), /robocal target aprilgrid:6x6:88mm:0.3:first=36/);
    await shot('aprilgrid-target');

    // Issue 36: OpenCV's ArUco GridBoard and ROS-Industrial's modified
    // circle grid are in the list, with their fields and specs.
    await page.selectOption('#target-kind', 'aruco_grid');
    await page.fill('#target-form input[name=first_id]', '0');
    await page.fill('#target-form input[name=marker_mm]', '40');
    await page.selectOption('#target-form select[name=dictionary]', 'DICT_6X6_250');
    await specShown(/^Target spec: arucogrid:5x7:40mm:10mm:DICT_6X6_250 /);
    await page.fill('#target-form input[name=markers_x]', '20');
    await page.fill('#target-form input[name=markers_y]', '20');
    await page.waitForFunction(() => /too many markers/.test(document.getElementById('target-error').textContent));
    assert.equal(await page.textContent('#target-error'), 'target: too many markers: a 20x20 ArUco grid needs 400 markers from id 0, but DICT_6X6_250 has 250 (use a larger dictionary or fewer markers)');
    await page.fill('#target-form input[name=markers_x]', '5');
    await page.fill('#target-form input[name=markers_y]', '7');
    await specShown(/^Target spec: arucogrid:5x7:40mm:10mm:DICT_6X6_250 /);
    const [arucoSheet] = await Promise.all([page.waitForEvent('download'), page.click('#print-target')]);
    assert.match(readFileSync(await arucoSheet.path(), 'utf8'), /robocal target arucogrid:5x7:40mm:10mm:DICT_6X6_250/);
    await page.selectOption('#target-kind', 'origin_dot_grid');
    await page.fill('#target-form input[name=cols]', '10');
    await page.fill('#target-form input[name=rows]', '10');
    await page.fill('#target-form input[name=spacing_mm]', '25');
    await specShown(/^Target spec: circles:10x10:25mm:origin-dot /);
    const [dotSheet] = await Promise.all([page.waitForEvent('download'), page.click('#print-target')]);
    assert.match(readFileSync(await dotSheet.path(), 'utf8'), /robocal target circles:10x10:25mm:origin-dot/);

    // Kalibr's own target file (its april_6x6.yaml template) fills the form.
    const yaml = (name, text) => ({ name, mimeType: 'text/yaml', buffer: Buffer.from(text) });
    await page.setInputFiles('#kalibr-input', yaml('april_6x6.yaml', "target_type: 'aprilgrid' #gridtype\ntagCols: 6               #number of apriltags\ntagRows: 5\ntagSize: 0.088           #size of apriltag, edge to edge [m]\ntagSpacing: 0.3          #ratio of space between tags to tagSize\n"));
    await specShown(/^Target spec: aprilgrid:6x5:88mm:0.3 /);
    assert.deepEqual(await page.$eval('#target-form', (f) => [f.elements.kind.value, f.elements.tag_cols.value, f.elements.tag_rows.value, f.elements.tag_mm.value, f.elements.spacing_ratio.value, f.elements.first_id.value]),
      ['aprilgrid', '6', '5', '88', '0.3', '0']);
    await page.setInputFiles('#kalibr-input', yaml('broken.yaml', "target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\ntagSpacing: 0.3\n"));
    await page.waitForFunction(() => /^broken.yaml: /.test(document.getElementById('target-error').textContent));
    assert.equal(await page.textContent('#target-error'), KALIBR_MISSING);
  }],

  ['ChArUco images: cards with corner counts and ids, a partial view accepted, the camera on the render\'s truth', async (page, { url, shot }) => {
    const { images, truth } = render();
    await page.goto(`${url}#target`);
    await ready(page);
    await page.selectOption('#target-kind', 'charuco');
    await page.fill('#target-form input[name=squares_x]', '8');
    await page.fill('#target-form input[name=squares_y]', '6');
    await page.fill('#target-form input[name=charuco_square_mm]', '30');
    await page.fill('#target-form input[name=marker_mm]', '22');
    await page.waitForFunction((s) => document.getElementById('target-canvas').dataset.spec === s, SPEC, { timeout: 20000 });
    // The last view with its right 40 % hidden.
    const last = images[images.length - 1];
    const partial = { ...last, name: 'view_partial.png', buffer: await occlude(page, last.buffer, 0.4) };
    await page.click('a[data-step=images]');
    await page.setInputFiles('#file-input', [...images, partial]);
    const n = images.length + 1;
    await page.waitForFunction((n) => {
      const all = [...document.querySelectorAll('.card')];
      return all.length === n && all.every((c) => /\b(error|warn)\b/.test(c.className) || / corners/.test(c.querySelector('.meta').textContent));
    }, n, { timeout: 120000 });
    const list = await cards(page);
    // Each rendered view: the corners in the image (truth.json lists those
    // inside the frame; one view of this seed has 31), found all but at most
    // 2 (a corner at the image border may lack its marker); the card says
    // "partial view" exactly when fewer than the board's 35.
    for (const v of truth.views) {
      const c = list.find((x) => x.name === v.image);
      const m = new RegExp(` · (\\d+) of ${CORNERS} corners( \\(partial view\\))? · ids [\\d, …-]+$`).exec(c.meta);
      assert.ok(m, `${c.name}: ${c.meta}`);
      const seen = Number(m[1]);
      assert.ok(seen <= v.points.length && seen >= v.points.length - 2, `${c.name}: ${seen} corners found, ${v.points.length} in the image`);
      assert.equal(!!m[2], seen < CORNERS, `${c.name}: ${c.meta}`);
      if (seen === CORNERS) assert.match(c.meta, / · ids 0-34$/);
      assert.match(c.cls, /\bok\b/, c.name);
      assert.equal(c.used, true, c.name);
    }
    const part = list.find((c) => c.name === 'view_partial.png');
    const m = / · (\d+) of 35 corners \(partial view\) · ids [\d, …-]+$/.exec(part.meta);
    assert.ok(m, part.meta);
    const seen = Number(m[1]);
    assert.ok(seen >= 8 && seen < CORNERS, `partial view: ${seen} corners`);
    assert.match(part.cls, /\bok\b/, 'a partial view is not flagged');
    assert.equal(part.used, true, 'a partial view is used');
    await shot('charuco-cards');
    // The inspector shows the partial view with its ids.
    await page.click('canvas[aria-label="thumbnail of view_partial.png"]');
    await page.waitForFunction(() => document.getElementById('inspector').open && /corners/.test(document.getElementById('inspector-info').textContent));
    assert.match(await page.textContent('#inspector-info'), new RegExp(`· ${seen} of 35 corners \\(partial view\\) · ids `));
    await shot('charuco-inspector');
    await page.click('#inspector-close');

    // The camera: every view, the partial one included.
    await page.click('a[data-step=camera]');
    await page.click('#solve-camera');
    await page.waitForFunction(() => document.querySelector('#camera-params, #camera-results .msg-error'), null, { timeout: 120000 });
    const error = await page.$('#camera-results .msg-error');
    if (error) throw new Error(`camera: ${await error.textContent()}`);
    const value = (name) => page.$eval('#camera-params', (t, name) => Number([...t.tBodies[0].rows].find((r) => r.cells[0].textContent === name).cells[1].textContent), name);
    // Truth: the render's camera. Corners of a noise-2 render are good to
    // ~0.02 px mean (0.07 px at most); the CLI on these 8 images lands
    // 0.37 px from fx = fy = 900 (robocal intrinsics, rms 0.018 px); 3 px
    // (0.3 %) bounds it with room for the partial view's weaker geometry.
    const [fx, fy] = [await value('fx'), await value('fy')];
    const [tfx, tfy] = [truth.camera.fx, truth.camera.fy];
    assert.ok(Math.abs(fx - tfx) < 3, `fx ${fx} px vs truth ${tfx} px`);
    assert.ok(Math.abs(fy - tfy) < 3, `fy ${fy} px vs truth ${tfy} px`);
    await shot('charuco-camera');
  }],
];
