// JPEG decoding in two wasm builds, alternated (the machine is noisy):
// decode_image_preview (decode + grey + 256-px preview, what the page does
// per upload) on each given file. Usage:
//   node bench/wasm_jpeg.mjs [--repeat N] OLD_PKG_JS NEW_PKG_JS FILES...
// JPEGs to try: `cargo bench -p robocal-vision --bench jpeg -- --write DIR`
// writes 1.2 MP and 12 MP ones; ../shared/datasets has camera photos.
import { createRequire } from 'node:module';
import { readFileSync } from 'node:fs';
import { resolve, basename } from 'node:path';
import { performance } from 'node:perf_hooks';

const args = process.argv.slice(2);
let repeat = 7;
if (args[0] === '--repeat') {
  repeat = Number(args[1]);
  args.splice(0, 2);
}
const [oldJs, newJs, ...files] = args;
const load = (p) => createRequire(import.meta.url)(resolve(p));
const builds = [load(oldJs), load(newJs)];
for (const f of files) {
  const bytes = readFileSync(f);
  const times = [[], []];
  for (let k = 0; k < repeat; k++) {
    for (const b of [0, 1]) {
      const t0 = performance.now();
      builds[b].decode_image_preview(bytes, 256).free();
      times[b].push(performance.now() - t0);
    }
  }
  const med = (t) => t.sort((a, b) => a - b)[Math.floor(t.length / 2)];
  const [a, b] = times.map(med);
  console.log(`${basename(f).padEnd(40)} old ${a.toFixed(1).padStart(7)} ms  new ${b.toFixed(1).padStart(7)} ms  new/old ${(b / a).toFixed(2)}`);
}
