// Decode and decode + detect in wasm (node), several builds in one process:
// per file, `image_info` (the full decode to grey, no detection) and
// `detect_target` (decode + detection, what the web app's worker runs per
// image), the builds taking turns call by call (A B A B ...), so their
// ratio comes from the same run. Native counterpart:
// `target/release/examples/detect_time --decode --no-blank FILES`.
// Usage (crate root; each PKG_JS a wasm-bindgen --target nodejs build, e.g.
// `make pkg`'s pkg/node/robocal.js):
//   node bench/wasm_decode_detect.mjs [--repeat N] [--target SPEC] LABEL=PKG_JS [LABEL=PKG_JS ...] FILES...
// Prints, per build, the median over files of the per-file medians (ms) and
// the ratios to the first build (median over files of the per-file ratios).
import { createRequire } from 'node:module';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { performance } from 'node:perf_hooks';

const args = process.argv.slice(2);
let repeat = 11;
let spec = 'chessboard:9x6:30mm';
const builds = [];
const files = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--repeat') repeat = Number(args[++i]);
  else if (args[i] === '--target') spec = args[++i];
  else if (/^[^=/]+=.+\.js$/.test(args[i])) {
    const [label, path] = args[i].split(/=(.*)/s);
    builds.push({ label, wasm: createRequire(import.meta.url)(resolve(path)), decode: [], detect: [], found: 0 });
  } else files.push(args[i]);
}
if (builds.length === 0 || files.length === 0) {
  console.error('usage: node bench/wasm_decode_detect.mjs [--repeat N] [--target SPEC] LABEL=PKG_JS ... FILES...');
  process.exit(2);
}

const med = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const time = (f) => {
  const t0 = performance.now();
  const out = f();
  return [performance.now() - t0, out];
};

// Warm-up, not timed: every build decodes and detects every file once (V8
// compiles wasm functions lazily and tiers them up on first use).
for (const f of files) {
  const bytes = readFileSync(f);
  for (const b of builds) {
    b.wasm.image_info(bytes);
    try {
      b.wasm.detect_target(bytes, spec);
    } catch {}
  }
}

for (const f of files) {
  const bytes = readFileSync(f);
  const dec = builds.map(() => []);
  const det = builds.map(() => []);
  const points = builds.map(() => 0);
  for (let k = 0; k < repeat; k++) {
    builds.forEach((b, i) => {
      dec[i].push(time(() => b.wasm.image_info(bytes))[0]);
      const [ms, n] = time(() => {
        try {
          return JSON.parse(b.wasm.detect_target(bytes, spec)).points.length;
        } catch {
          return 0;
        }
      });
      det[i].push(ms);
      points[i] = n;
    });
  }
  builds.forEach((b, i) => {
    b.decode.push(med(dec[i]));
    b.detect.push(med(det[i]));
    if (points[i] > 0) b.found++;
  });
}

console.log(`${files.length} files, ${spec}, median of ${repeat} per file, node ${process.version}`);
console.log(`${'build'.padEnd(10)} ${'decode'.padStart(10)} ${'dec+detect'.padStart(10)} ${'detect'.padStart(10)}  found`);
for (const b of builds) {
  const d = med(b.decode);
  const dd = med(b.detect);
  console.log(`${b.label.padEnd(10)} ${d.toFixed(3).padStart(10)} ${dd.toFixed(3).padStart(10)} ${(dd - d).toFixed(3).padStart(10)}  ${b.found}/${files.length}`);
}
const base = builds[0];
for (const b of builds.slice(1)) {
  const ratio = (key) => med(b[key].map((x, i) => x / base[key][i])).toFixed(2);
  console.log(`${b.label}/${base.label}: decode ${ratio('decode')}, decode+detect ${ratio('detect')} (median over files of per-file ratios)`);
}
