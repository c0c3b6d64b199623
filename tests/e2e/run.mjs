// Runs every browser test suite (or the ones named on the command line:
// `node tests/e2e/run.mjs datasets offline`); exits non-zero on any failure.
import { run } from './harness.mjs';

const all = ['foundation', 'workflows', 'flow', 'pages', 'datasets', 'offline', 'reliability', 'badinputs', 'badposes', 'guidance', 'reports', 'markers', 'boards', 'capture', 'rig', 'check', 'laser', 'video', 'lens'];
const wanted = process.argv.slice(2);
for (const w of wanted) if (!all.includes(w)) throw new Error(`unknown suite '${w}' (known: ${all.join(', ')})`);
const suites = wanted.length ? wanted : all;
let failed = 0;
for (const suite of suites) {
  // A suite may export `launchArgs`: Chromium flags of its own (the capture suite's fake camera).
  const { tests, launchArgs } = await import(`./${suite}.mjs`);
  failed += await run(suite, tests, launchArgs);
}
if (failed) {
  console.error(`e2e: ${failed} test(s) failed; screenshots in tests/e2e/screenshots/`);
  process.exit(1);
}
console.log('e2e: all browser tests passed');
