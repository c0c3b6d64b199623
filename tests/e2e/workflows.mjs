// The seed workflows page: the numbers the page shows equal the CLI's for
// the same CSV (the seed-001 Table 3 points), and an exact synthetic XY-table
// run recovers its projection with zero residual.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { root } from './harness.mjs';

const ready = (page) => page.locator('#engine-status.ready').waitFor({ timeout: 30000 });

/** x_mm,y_mm,z_mm,u_px,v_px rows projected by an exact pinhole 600 mm above the table. */
function xyTableCsv() {
  const f = 1200, cx = 640, cy = 480, dist = 600;
  const project = (x, y, z) => [cx + (f * x) / (dist - z), cy - (f * y) / (dist - z)];
  let csv = 'x_mm,y_mm,z_mm,u_px,v_px,role\n';
  for (const z of [0, 40]) for (const x of [-100, 0, 100]) for (const y of [-80, 0, 80]) {
    const [u, v] = project(x, y, z);
    csv += `${x},${y},${z},${u},${v},calibration\n`;
  }
  for (const [x, y] of [[-60, -50], [60, -50], [60, 50], [-60, 50]]) {
    const [u, v] = project(x, y, 20);
    csv += `${x},${y},20,${u},${v},verify\n`;
  }
  return csv;
}

export const tests = [
  ['planar at any height shows the same fit as the CLI', async (page, { url, shot }) => {
    const file = join(root, 'fixtures/seed001/table3_four_points.csv');
    const cli = JSON.parse(execFileSync(join(root, 'target/release/robocal'), ['planar', 'solve', file]).toString());
    await page.goto(`${url}#workflows`);
    await ready(page);
    await page.fill('#planar-csv', readFileSync(file, 'utf8'));
    await page.click('#planar-solve');
    await page.locator('#planar-fit').waitFor({ timeout: 20000 });
    await shot('planar');
    const rows = await page.$$eval('#planar-fit tbody tr', (trs) => trs.map((tr) => [...tr.children].map((td) => td.textContent)));
    assert.equal(rows.length, 6);
    // The page prints 6 decimals, or 4 significant digits in exponent form
    // for tiny values: equal to the CLI's number within that rounding.
    const close = (shown, exact, what) => assert.ok(Math.abs(Number(shown) - exact) <= 5e-7 + 5e-4 * Math.abs(exact), `${what}: page ${shown}, CLI ${exact}`);
    for (const [param, intercept, slope, r2] of rows) {
      const f = cli.fit[param];
      close(intercept, f.intercept, `${param} intercept`);
      close(slope, f.slope, `${param} slope`);
      close(r2, f.r2, `${param} R2`);
    }
    await page.fill('#predict-height', '45');
    await page.fill('#predict-u', '1284.804');
    await page.fill('#predict-v', '432.0025');
    await page.click('#planar-predict');
    await page.waitForFunction(() => /^At 45\.0 mm/.test(document.getElementById('predict-result').textContent), null, { timeout: 20000 });
    const cliPredict = JSON.parse(execFileSync(join(root, 'target/release/robocal'), ['planar', 'solve', file, '--predict', '45', '--point', '1284.804,432.0025']).toString()).predictions[0];
    const text = await page.textContent('#predict-result');
    assert.ok(text.includes(`X ${cliPredict.robot_mm[0].toFixed(3)} mm`), text);
    assert.ok(text.includes(`Y ${cliPredict.robot_mm[1].toFixed(3)} mm`), text);
  }],
  ['XY-table recovers an exact projection and its verification point', async (page, { url, shot }) => {
    await page.goto(`${url}#workflows`);
    await ready(page);
    await page.fill('#xytable-csv', xyTableCsv());
    await page.click('#xytable-solve');
    await page.locator('#xytable-verification').waitFor({ timeout: 20000 });
    await shot('xytable');
    const heads = await page.$$eval('#xytable-results h4', (hs) => hs.map((x) => x.textContent));
    // Noise-free data: both methods reproduce the pixels to rounding (< 1e-6 px).
    const rms = heads.map((t) => Number(/RMS (\S+) px/.exec(t)[1]));
    assert.ok(/^Batch least squares/.test(heads[0]) && /^Kalman filter/.test(heads[1]), heads.join(' | '));
    assert.ok(rms.every((x) => x < 1e-6), `RMS ${rms}`);
    const errs = await page.$$eval('#xytable-verification tbody tr td:last-child', (tds) => tds.map((t) => Number(t.textContent)));
    assert.ok(errs.slice(1).every((x) => x < 1e-6), `verification errors ${errs}`);
    await page.fill('#xytable-csv', 'x_mm,y_mm,z_mm,u_px,v_px\n0,0,0,1,1\n');
    await page.click('#xytable-solve');
    await page.locator('#xytable-results .msg-error').waitFor({ timeout: 20000 });
    assert.match(await page.textContent('#xytable-results .msg-error'), /6/);
  }],
];
