// Bad robot poses and hand-eye inputs through the page (issue 17, part 3),
// split from badinputs.mjs: each test gives the page one bad pose file or
// reading where a user would, asserts the exact message the page shows,
// that the images and the camera result are kept, and that a later good
// input still solves. docs/bad-inputs-page.md lists the rows (same test
// names). The harness fails a test on any uncaught page error.
import assert from 'node:assert/strict';
import {
  ready, cards, settled, board, png, text, BOARD_META, demo, loadBoard, solveCamera, loadDemoImages,
} from './badinput-helpers.mjs';

/** The demo's pose file without its name column: poses pair with the images by order. */
const namelessPoses = () => demo().poses.trim().split('\n').map((l) => l.split(',').slice(1).join(','));

/** Robot poses: a good file read, then the bad one refused with `message`, the image kept, then the good file again. */
const GOOD_POSES = 'x,y,z,qx,qy,qz,qw\n0.1,0.2,0.3,0,0,0,1\n0.2,0.2,0.3,0,0,0.1,0.995\n0.3,0.1,0.3,0.1,0,0,0.995\n';
function posesCase(file, message) {
  return async (page, { url, shot }) => {
    await loadBoard(page, url);
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', text('good.csv', GOOD_POSES));
    await page.waitForFunction(() => /^good\.csv: 3 poses read as /.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    await page.setInputFiles('#pose-input', file);
    await page.locator('#pose-results .msg-error').waitFor({ timeout: 20000 });
    assert.equal(await page.textContent('#pose-results'), `${file.name}: ${message}`);
    // Nothing of the bad file is used, nothing of the good one shown under its name.
    assert.equal(await page.$('#pose-table'), null);
    assert.equal(await page.textContent('#pose-pairing'), 'No poses yet.');
    await shot('bad');
    await page.click('a[data-step=images]');
    assert.deepEqual((await cards(page)).map((c) => c.meta), [BOARD_META]);
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', text('good.csv', GOOD_POSES));
    await page.waitForFunction(() => /^good\.csv: 3 poses read as /.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    assert.equal(await page.$('#pose-results .msg-error'), null);
    assert.equal(await page.$$eval('#pose-table tbody tr', (trs) => trs.length), 3);
  };
}

/** Hand-eye on the demo: camera solved, the good solve first, then `spoil` makes the solve fail with `message`; `mend` makes it solve again. */
function handeyeCase(spoil, message, mend) {
  return async (page, { url, shot }) => {
    await page.goto(url);
    await ready(page);
    await page.click('#demo-button');
    await page.waitForFunction(() => /^Demo loaded/.test(document.getElementById('engine-status').textContent), null, { timeout: 180000 });
    assert.equal(await solveCamera(page), null);
    const handeye = async () => {
      await page.click('a[data-step=handeye]');
      await page.evaluate(() => document.getElementById('handeye-results').replaceChildren());
      await page.click('#solve-handeye');
      await page.waitForFunction(() => document.querySelector('#handeye-errors, #handeye-results .msg-error'), null, { timeout: 60000 });
      const error = await page.$('#handeye-results .msg-error');
      return error ? error.textContent() : null;
    };
    assert.equal(await handeye(), null);
    await spoil(page);
    assert.equal(await handeye(), message);
    await shot('bad');
    // The camera result and the images are kept.
    await page.click('a[data-step=camera]');
    assert.match(await page.textContent('#camera-results h3'), /^Result: RMS \S+ px over 12 views$/);
    assert.match(await page.textContent('#image-summary'), /^12 files, 12 decoded, 12 with the target$/);
    await mend(page);
    assert.equal(await handeye(), null);
    assert.match(await page.textContent('#handeye-results h3'), /^Result \(/);
  };
}

/** Choose `value` in the select `id` (step 4's reading of the pose file, or step 5's setup); a new reading is waited for. */
const select = (id, value) => async (page) => {
  const handeye = id.startsWith('handeye');
  await page.click(`a[data-step=${handeye ? 'handeye' : 'robot'}]`);
  const before = handeye ? null : await page.textContent('#pose-format-used');
  await page.selectOption(`#${id}`, value);
  // The poses are read again in the worker: wait for the line that says how.
  if (!handeye) await page.waitForFunction((b) => !document.querySelector('#pose-results .msg-error') && document.getElementById('pose-format-used')?.textContent !== b, before, { timeout: 20000 });
};

export const tests = [
  // ---- step 4, robot poses: the file refused with the line, the images kept ----
  ['poses-empty', posesCase(text('empty.csv', ''), 'the file is empty: expected one robot pose a line, one per image')],
  ['poses-blank-lines', posesCase(text('blank.csv', '\n  \n\t\n'), 'the file is empty (only white space): expected one robot pose a line, one per image')],
  ['poses-not-utf8', posesCase(text('latin1.csv', Buffer.from('x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,1 # d\xe9j\xe0 vu\n', 'latin1')),
    'the file is not UTF-8 text: save it as UTF-8 (or plain ASCII) and load it again')],
  ['poses-nan', posesCase(text('nan.csv', 'x,y,z,qx,qy,qz,qw\n0.1,NaN,0.3,0,0,0,1\n'), "line 2, column 2: 'NaN' is not a number")],
  ['poses-inf', posesCase(text('inf.csv', 'x,y,z,qx,qy,qz,qw\n0.1,inf,0.3,0,0,0,1\n'), "line 2, column 2: 'inf' is not a number")],
  ['poses-zero-quaternion', posesCase(text('zeroq.csv', 'x,y,z,qx,qy,qz,qw\n0.1,0.2,0.3,0,0,0,0\n'), 'line 2, column 4: quaternion has norm 0: not a rotation')],
  ['poses-unknown-header', posesCase(text('header.csv', 'x y z\n1 2 3\n'),
    "line 1: the header 'x y z' names no known pose format; name the format, or use column names such as x,y,z,qx,qy,qz,qw or X,Y,Z,A,B,C")],
  ['poses-three-values', posesCase(text('three.txt', '1 2 3\n4 5 6\n'), 'line 1: 3 values, but pose formats have 6, 7, 12 or 16 values a line')],
  ['poses-not-a-rotation', posesCase(text('scaled.txt', '2 0 0 0.1 0 2 0 0.2 0 0 2 0.3 0 0 0 1\n'),
    'line 1: 4x4 matrix rotation block is not orthonormal: largest |RᵀR - I| entry is 3.000e0, tolerance 1e-3')],
  ['poses-count-mismatch', async (page, { url, shot }) => {
    await loadBoard(page, url);
    await page.setInputFiles('#file-input', [png('second.png', board({ x: 40, y: 30 }))]);
    await settled(page, 2);
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', text('three.csv', GOOD_POSES));
    await page.locator('#pose-pairing .msg-warning').waitFor({ timeout: 20000 });
    assert.equal(await page.textContent('#pose-pairing .msg-warning'), '3 poses but 2 images: pairing by order leaves some unpaired. Check that the pose file matches the images.');
    assert.deepEqual(await page.$$eval('#pairing-table tbody tr', (trs) => trs.map((tr) => tr.cells[3].textContent)), ['used', 'used', 'no image']);
    await shot('bad');
    await page.setInputFiles('#pose-input', text('two.csv', GOOD_POSES.split('\n').slice(0, 3).join('\n')));
    // The old file's pairing says "2 pairs usable" too (3 poses, 2 images): wait for the new file's
    // reading; the robot view draws its pairing in the same render, without the old warning.
    await page.waitForFunction(() => /^two\.csv: 2 poses read as /.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    assert.match(await page.textContent('#pose-pairing p'), /^Paired by order .*: 2 pairs usable\.$/);
    assert.equal(await page.$('#pose-pairing .msg-warning'), null);
  }],

  // ---- step 5, hand-eye on the demo: the consistency checks name the mistake ----
  ['handeye-metres-read-as-mm', handeyeCase(select('pose-length', 'mm'),
    'robot poses: the robot translations fit the camera motion only when scaled by 999.9030: the camera poses look like millimetres while the robot poses are metres: convert the camera translations to metres (divide by 1000)',
    select('pose-length', 'auto'))],
  ['handeye-radians-read-as-degrees', async (page, { url, shot }) => {
    // Not refused: the rotations, 57 times too small, are solved with a
    // warning only (reported to the core's owner; see docs/bad-inputs-page.md).
    await page.goto(url);
    await ready(page);
    await page.click('#demo-button');
    await page.waitForFunction(() => /^Demo loaded/.test(document.getElementById('engine-status').textContent), null, { timeout: 180000 });
    assert.equal(await solveCamera(page), null);
    await select('pose-angle', 'deg')(page);
    assert.equal(await page.textContent('#pose-format-used'), 'demo_poses.csv: 12 poses read as ur, lengths in m, angles in deg, the file holds base_from_gripper.');
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-errors').waitFor({ timeout: 60000 });
    const warnings = await page.$$eval('#handeye-results .msg', (e) => e.map((x) => [x.className, x.textContent]));
    assert.deepEqual(warnings.slice(0, 2), [
      ['msg msg-warning', '31 of 66 motion pairs were discarded because they rotate less than 2 deg'],
      // The rotations, 57 times too small, are named as weak geometry (issue 35).
      ['msg msg-warning', 'weak geometry: the largest rotation between two poses is 6.1 deg: with small rotations the hand-eye translation is poorly determined (its error grows as the rotations shrink); rotate the gripper by 30 deg or more about at least two axes'],
    ]);
    const texts = warnings.map((w) => w[1]);
    assert.ok(warnings.every((w) => w[0] === 'msg msg-warning'), JSON.stringify(warnings));
    assert.ok(texts.includes('pose refinement: view(s) 4, 6 fit the others poorly (whitened residual above 4.1) and were down-weighted as outliers; check those robot/camera pose pairs'), JSON.stringify(texts));
    // The transforms fitted to rotations 57 times too small put the board behind the camera in some view.
    assert.ok(texts.some((t) => /^pose refinement: no reprojection RMS of the refined transforms: through the solved transforms and view \d+ a target point lies behind the camera \(z = -\d+\.\d{4} m\); check the robot poses' units and convention$/.test(t)), JSON.stringify(texts));
    // ... and the leave-one-out spread far beyond the noise model (issue 35): five warnings in all.
    assert.equal(texts.length, 5, JSON.stringify(texts));
    assert.match(texts[3], /^uncertainty: the leave-one-out solutions spread \d+\.\d times wider than the noise model predicts/);
    // ... and the result is far off (the right reading closes to 0.005 deg).
    const rotationRms = await page.$eval('#handeye-errors', (t) => [...t.rows].find((r) => r.cells[0].textContent === 'rotation RMS').cells[1].textContent);
    assert.ok(Number(rotationRms.replace(/ deg$/, '')) > 10, rotationRms);
    await shot('bad');
    await select('pose-angle', 'auto')(page);
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.waitForFunction(() => document.getElementById('handeye-errors') && !document.querySelector('#handeye-results .msg'), null, { timeout: 60000 });
    const mended = await page.$eval('#handeye-errors', (t) => [...t.rows].find((r) => r.cells[0].textContent === 'rotation RMS').cells[1].textContent);
    assert.ok(Number(mended.replace(/ deg$/, '')) < 0.1, mended);
    // The camera result is kept throughout.
    assert.match(await page.textContent('#camera-results h3'), /^Result: RMS \S+ px over 12 views$/);
  }],
  ['handeye-poses-inverted', handeyeCase(select('pose-direction', 'gripper_from_base'),
    'robot poses: these poses fit eye-to-hand (the camera fixed, the target on the gripper), not the eye-in-hand chosen: as eye-to-hand they fit the camera motion with rotation RMS 0.005 deg, against 22.972 deg as eye-in-hand: choose the setup eye-to-hand, which solves base_from_camera. Inverting the poses instead would give the same numbers under the wrong frame names; do that only if the setup really is eye-in-hand and the file holds gripper_from_base',
    select('pose-direction', 'base_from_gripper'))],
  ['handeye-wrong-setup', handeyeCase(select('handeye-setup', 'eye-to-hand'),
    'robot poses: these poses fit eye-in-hand (the camera on the gripper), not the eye-to-hand chosen: as eye-in-hand they fit the camera motion with rotation RMS 0.005 deg, against 22.972 deg as eye-to-hand: choose the setup eye-in-hand, which solves gripper_from_camera. Inverting the poses instead would give the same numbers under the wrong frame names; do that only if the setup really is eye-to-hand and the file holds gripper_from_base',
    select('handeye-setup', 'eye-in-hand'))],
  ['handeye-pairing-shifted', handeyeCase(async (page) => {
    const [head, , ...rest] = namelessPoses();
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', text('shifted.csv', `${[head, ...rest].join('\n')}\n`));
    await page.waitForFunction(() => /^shifted\.csv: 11 poses read as ur/.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    assert.equal(await page.textContent('#pose-pairing .msg-warning'), '11 poses but 12 images: pairing by order leaves some unpaired. Check that the pose file matches the images.');
  }, 'robot poses: the pose file looks shifted by one against the images: pairing robot pose i with image i+1 fits with rotation RMS 0.005 deg, against 46.638 deg as given: remove the extra first image so that the lists pair up',
  async (page) => {
    // The fix the message names: without the extra first image the lists
    // pair up (removed: an excluded image keeps its place in the pairing).
    await page.click('a[data-step=images]');
    await page.click('button[aria-label="remove demo_00.png"]');
    assert.equal(await solveCamera(page), null);
  })],

  ['handeye-before-camera', async (page, { url, shot }) => {
    await loadBoard(page, url);
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-results .msg-error').waitFor({ timeout: 10000 });
    assert.equal(await page.textContent('#handeye-results'), 'solve the camera first (step 3): hand-eye uses the target pose of every view');
    await shot('bad');
    assert.deepEqual((await cards(page)).map((c) => c.meta), [BOARD_META]);
  }],
  ['handeye-without-poses', async (page, { url, shot }) => {
    await loadDemoImages(page, url);
    assert.equal(await solveCamera(page), null);
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-results .msg-error').waitFor({ timeout: 10000 });
    assert.equal(await page.textContent('#handeye-results'), 'load the robot poses first (step 4)');
    await shot('bad');
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', text('poses.csv', demo().poses));
    await page.waitForFunction(() => /^poses\.csv: 12 poses read as ur/.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-errors').waitFor({ timeout: 60000 });
    assert.equal(await page.$('#handeye-results .msg-error'), null);
    assert.match(await page.textContent('#camera-results h3'), /^Result: RMS \S+ px over 12 views$/);
  }],

  // ---- pairing (issue 35): names with folders pair by file name; two rows for one image are refused ----
  ['pose-names-with-folders', async (page, { url, shot }) => {
    await loadDemoImages(page, url);
    assert.equal(await solveCamera(page), null);
    await page.click('a[data-step=robot]');
    // The image column as a user's script writes it: a folder, Windows separators, a stem.
    const lines = demo().poses.trim().split('\n');
    const named = [lines[0], ...lines.slice(1).map((l, i) => {
      const rest = l.slice(l.indexOf(','));
      const name = i % 3 === 0 ? `images/demo_${String(i).padStart(2, '0')}.png` : i % 3 === 1 ? `C:\\cell\\demo_${String(i).padStart(2, '0')}.png` : `demo_${String(i).padStart(2, '0')}`;
      return name + rest;
    })];
    await page.setInputFiles('#pose-input', text('folders.csv', `${named.join('\n')}\n`));
    await page.waitForFunction(() => /Paired by the name column: 12 pairs usable/.test(document.getElementById('pose-pairing')?.textContent || ''), null, { timeout: 20000 });
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-errors').waitFor({ timeout: 60000 });
    assert.equal(await page.$('#handeye-results .msg-error'), null);
    // Two rows naming one image: refused, the rows named.
    await page.click('a[data-step=robot]');
    const twice = [...named];
    twice[3] = `images/demo_01.png${lines[3].slice(lines[3].indexOf(','))}`;
    await page.setInputFiles('#pose-input', text('twice.csv', `${twice.join('\n')}\n`));
    await page.waitForFunction(() => /two poses name the same image/.test(document.getElementById('pose-pairing')?.textContent || ''), null, { timeout: 20000 });
    await shot('bad');
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-results .msg-error').waitFor({ timeout: 10000 });
    assert.equal(await page.textContent('#handeye-results'), "pairing: two poses name the same image: rows 3, 4 all name 'demo_01.png': each image pairs with one robot pose; fix the image column");
  }],

  // ---- One pose per file (issue 36): ROS YAML files chosen together pair by stem; a bad file is named ----
  ['pose-files-one-per-image', async (page, { url, shot }) => {
    await loadDemoImages(page, url);
    assert.equal(await solveCamera(page), null);
    await page.click('a[data-step=robot]');
    const rows = demo().poses.trim().split('\n').slice(1).map((l) => l.split(','));
    const files = rows.map(([name, ...v], i) => {
      const [x, y, z, rx, ry, rz] = v.map(Number);
      const a = Math.hypot(rx, ry, rz);
      const k = a < 1e-12 ? 0.5 : Math.sin(a / 2) / a;
      const stem = name.replace(/\.[^.]*$/, '');
      const yaml = i % 2
        ? `position: {x: ${x}, y: ${y}, z: ${z}}\norientation: {x: ${rx * k}, y: ${ry * k}, z: ${rz * k}, w: ${Math.cos(a / 2)}}\n`
        : `header:\n  frame_id: base_link\npose:\n  position:\n    x: ${x}\n    y: ${y}\n    z: ${z}\n  orientation:\n    x: ${rx * k}\n    y: ${ry * k}\n    z: ${rz * k}\n    w: ${Math.cos(a / 2)}\n`;
      return text(`${stem}.yaml`, yaml);
    });
    // Chosen in reverse order: read in numeric order of the names.
    await page.setInputFiles('#pose-input', [...files].reverse());
    await page.waitForFunction(() => /^12 pose files: 12 poses read as xyz_quat_xyzw/.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    await page.waitForFunction(() => /Paired by the name column: 12 pairs usable/.test(document.getElementById('pose-pairing')?.textContent || ''), null, { timeout: 20000 });
    await page.click('a[data-step=handeye]');
    await page.click('#solve-handeye');
    await page.locator('#handeye-errors').waitFor({ timeout: 60000 });
    assert.equal(await page.$('#handeye-results .msg-error'), null);
    // A file whose quaternion is not a rotation: refused, the file and line named.
    await page.click('a[data-step=robot]');
    const bad = [...files];
    bad[4] = text(bad[4].name, 'position: {x: 0.1, y: 0.2, z: 0.3}\norientation:\n  {x: 0, y: 0, z: 0, w: 2}\n');
    await page.setInputFiles('#pose-input', bad);
    await page.locator('#pose-results .msg-error').waitFor({ timeout: 20000 });
    assert.equal(await page.textContent('#pose-results'), `'${bad[4].name}': line 3: quaternion has norm 2: not a rotation`);
    await shot('bad');
  }],

  // ---- New session (issue 34): every step starts anew, the hand-eye setup included ----
  ['new-session-resets-every-step', async (page, { url }) => {
    await loadDemoImages(page, url);
    assert.equal(await solveCamera(page), null);
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', text('poses.csv', demo().poses));
    await page.waitForFunction(() => /^poses\.csv: 12 poses read as ur/.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    await page.click('a[data-step=handeye]');
    await page.selectOption('#handeye-setup', 'eye-to-hand');
    page.once('dialog', (d) => d.accept());
    await page.click('#new-session');
    await page.waitForFunction(() => document.getElementById('handeye-setup')?.value === 'eye-in-hand', null, { timeout: 20000 });
    assert.equal(await page.textContent('#pose-file-name'), 'no file loaded');
    // The new session's images and pose file, eye-to-hand chosen anew: the
    // solve uses them (the demo is eye-in-hand, so eye-to-hand is refused by name).
    await page.setInputFiles('#file-input', demo().images);
    await settled(page, demo().images.length);
    assert.equal(await solveCamera(page), null);
    await page.click('a[data-step=robot]');
    await page.setInputFiles('#pose-input', text('new.csv', demo().poses));
    await page.waitForFunction(() => /^new\.csv: 12 poses read as ur/.test(document.getElementById('pose-format-used')?.textContent || ''), null, { timeout: 20000 });
    await page.click('a[data-step=handeye]');
    await page.selectOption('#handeye-setup', 'eye-to-hand');
    await page.click('#solve-handeye');
    await page.locator('#handeye-results .msg-error').waitFor({ timeout: 60000 });
    assert.match(await page.textContent('#handeye-results'), /^robot poses: these poses fit eye-in-hand \(the camera on the gripper\), not the eye-to-hand chosen/);
    await page.selectOption('#handeye-setup', 'eye-in-hand');
    await page.click('#solve-handeye');
    await page.locator('#handeye-errors').waitFor({ timeout: 60000 });
    assert.match(await page.textContent('#handeye-results'), /gripper_from_camera: translation/);
  }],
];
