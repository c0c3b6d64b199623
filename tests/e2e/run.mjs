// Runs every browser test suite; exits non-zero on any failure.
import { run } from './harness.mjs';

const suites = ['foundation', 'workflows', 'flow'];
let failed = 0;
for (const suite of suites) {
  const { tests } = await import(`./${suite}.mjs`);
  failed += await run(suite, tests);
}
if (failed) {
  console.error(`e2e: ${failed} test(s) failed; screenshots in tests/e2e/screenshots/`);
  process.exit(1);
}
console.log('e2e: all browser tests passed');
