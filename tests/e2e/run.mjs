// Runs every browser test suite (or the ones named on the command line:
// `node tests/e2e/run.mjs datasets offline`); exits non-zero on any failure.
//
// Suites run in E2E_JOBS lanes at once (default: 2, or 1 on a one-core
// machine). Each suite has its own `robocal serve` on a free port, its own
// Chromium and its own temporary folders, so lanes share nothing; every
// output line names its suite. The lanes are filled longest suite first from
// the seconds a suite's tests took one after another on the 2-core machine
// (`seconds` below, from s24's make test; a suite missing there counts as 30 s), so that they end at about the same time.
import { availableParallelism } from 'node:os';
import { run } from './harness.mjs';

const all = ['foundation', 'workflows', 'flow', 'pages', 'datasets', 'offline', 'reliability', 'badinputs', 'badposes', 'guidance', 'reports', 'markers', 'boards', 'capture', 'rig', 'check', 'laser', 'video', 'lens'];
const seconds = {
  badinputs: 97, capture: 69, badposes: 66, pages: 61, rig: 59, video: 49, datasets: 39, guidance: 36,
  flow: 29, reports: 27, reliability: 27, offline: 15, boards: 14, markers: 12, foundation: 9, lens: 8,
  check: 5, laser: 4, workflows: 3,
};
const wanted = process.argv.slice(2);
for (const w of wanted) if (!all.includes(w)) throw new Error(`unknown suite '${w}' (known: ${all.join(', ')})`);
const suites = wanted.length ? wanted : all;

const jobsEnv = process.env.E2E_JOBS;
if (jobsEnv !== undefined && !/^[1-9]\d*$/.test(jobsEnv)) throw new Error(`E2E_JOBS must be a whole number of lanes, 1 or more (got '${jobsEnv}')`);
const jobs = Math.min(suites.length, jobsEnv ? Number(jobsEnv) : Math.min(2, availableParallelism()));

// Longest first, each to the lane that ends soonest.
const lanes = Array.from({ length: jobs }, () => ({ suites: [], load: 0 }));
for (const suite of [...suites].sort((a, b) => (seconds[b] ?? 30) - (seconds[a] ?? 30))) {
  const lane = lanes.reduce((best, l) => (l.load < best.load ? l : best));
  lane.suites.push(suite);
  lane.load += seconds[suite] ?? 30;
}

async function runLane(lane) {
  let failed = 0;
  for (const suite of lane.suites) {
    // A suite may export `launchArgs`: Chromium flags of its own (the capture suite's fake camera).
    const { tests, launchArgs } = await import(`./${suite}.mjs`);
    const started = Date.now();
    try {
      failed += await run(suite, tests, launchArgs);
    } catch (e) {
      // The suite's server or Chromium did not start: its tests count as failed, the lane goes on.
      failed += tests.length;
      console.log(`FAIL ${suite}: did not run: ${String((e && e.message) || e).split('\n')[0]}`);
    }
    console.log(`---- ${suite}: ${((Date.now() - started) / 1000).toFixed(1)} s`);
  }
  return failed;
}

// An error thrown outside any test (a route or event handler of a page)
// fails the run but lets the other lane finish.
let stray = 0;
process.on('unhandledRejection', (e) => {
  stray++;
  console.log(`FAIL an error outside any test (a page's route or event handler): ${(e && e.stack) || e}`);
});

const started = Date.now();
if (jobs > 1) console.log(`e2e: ${suites.length} suites in ${jobs} lanes: ${lanes.map((l) => l.suites.join(' ')).join(' | ')}`);
const failed = (await Promise.all(lanes.map(runLane))).reduce((a, b) => a + b, 0) + stray;
console.log(`e2e: ${suites.length} suites in ${((Date.now() - started) / 1000).toFixed(0)} s`);
if (failed) {
  console.error(`e2e: ${failed} test(s) failed; screenshots in tests/e2e/screenshots/`);
  process.exit(1);
}
console.log('e2e: all browser tests passed');
