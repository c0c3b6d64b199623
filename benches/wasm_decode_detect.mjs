// Decode and decode + detect in wasm (node), several builds in one process:
// per file, `image_info` (the full decode to grey, no detection),
// `decode_image_preview` (decode + grey + 256-px preview, what the page does
// per upload) and `detect_target` (decode + detection, what the web app's
// worker runs per image), the builds taking turns call by call (A B A B
// ...), so their ratio comes from the same run. Native counterpart:
// `target/release/examples/detect_time --decode --no-blank FILES`.
// (This replaces benches/wasm_jpeg.mjs, which timed decode_image_preview in
// two builds: --per-file prints that per-file table, for any format.)
// Usage (crate root; each PKG_JS a wasm-bindgen --target nodejs build, e.g.
// `make pkg`'s pkg/node/robocal.js):
//   node benches/wasm_decode_detect.mjs [--repeat N] [--target SPEC] [--per-file] LABEL=PKG_JS [LABEL=PKG_JS ...] FILES...
// Prints, per build, the median over files of the per-file medians (ms) and
// the ratios to the first build (median over files of the per-file ratios);
// with --per-file also one line per file and build.
// Builds from issue 16 on return the preview as a web_sys::ImageData, which
// node lacks: a minimal `ImageData` (data, width, height) is installed when
// there is none.
import { createRequire } from 'node:module';
import { readFileSync } from 'node:fs';
import { basename, resolve } from 'node:path';
import { performance } from 'node:perf_hooks';

if (typeof globalThis.ImageData === 'undefined') {
  globalThis.ImageData = class ImageData {
    constructor(data, width, height) {
      this.data = data;
      this.width = width;
      this.height = height;
    }
  };
}

const args = process.argv.slice(2);
let repeat = 11;
let spec = 'chessboard:9x6:30mm';
let perFile = false;
const builds = [];
const files = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--repeat') repeat = Number(args[++i]);
  else if (args[i] === '--target') spec = args[++i];
  else if (args[i] === '--per-file') perFile = true;
  else if (/^[^=/]+=.+\.js$/.test(args[i])) {
    const [label, path] = args[i].split(/=(.*)/s);
    builds.push({ label, wasm: createRequire(import.meta.url)(resolve(path)), decode: [], preview: [], detect: [], found: 0 });
  } else files.push(args[i]);
}
if (builds.length === 0 || files.length === 0) {
  console.error('usage: node benches/wasm_decode_detect.mjs [--repeat N] [--target SPEC] [--per-file] LABEL=PKG_JS ... FILES...');
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
const preview = (b, bytes) => b.wasm.decode_image_preview(bytes, 256).free();
const detectPoints = (b, bytes) => {
  try {
    return JSON.parse(b.wasm.detect_target(bytes, spec)).points.length;
  } catch {
    return 0;
  }
};

// Warm-up, not timed: every build decodes and detects every file once (V8
// compiles wasm functions lazily and tiers them up on first use).
for (const f of files) {
  const bytes = readFileSync(f);
  for (const b of builds) {
    b.wasm.image_info(bytes);
    preview(b, bytes);
    detectPoints(b, bytes);
  }
}

for (const f of files) {
  const bytes = readFileSync(f);
  const dec = builds.map(() => []);
  const pre = builds.map(() => []);
  const det = builds.map(() => []);
  const points = builds.map(() => 0);
  for (let k = 0; k < repeat; k++) {
    builds.forEach((b, i) => {
      dec[i].push(time(() => b.wasm.image_info(bytes))[0]);
      pre[i].push(time(() => preview(b, bytes))[0]);
      const [ms, n] = time(() => detectPoints(b, bytes));
      det[i].push(ms);
      points[i] = n;
    });
  }
  builds.forEach((b, i) => {
    b.decode.push(med(dec[i]));
    b.preview.push(med(pre[i]));
    b.detect.push(med(det[i]));
    if (points[i] > 0) b.found++;
    if (perFile) {
      const r = (key) => (i > 0 ? ` (${(b[key].at(-1) / builds[0][key].at(-1)).toFixed(2)})` : '');
      console.log(
        `${basename(f).padEnd(28)} ${b.label.padEnd(8)} decode ${b.decode.at(-1).toFixed(2)}${r('decode')}  preview ${b.preview.at(-1).toFixed(2)}${r('preview')}  dec+detect ${b.detect.at(-1).toFixed(2)}${r('detect')} ms  ${points[i]} points`,
      );
    }
  });
}

console.log(`${files.length} files, ${spec}, median of ${repeat} per file, node ${process.version}`);
console.log(`${'build'.padEnd(10)} ${'decode'.padStart(10)} ${'preview'.padStart(10)} ${'dec+detect'.padStart(10)} ${'detect'.padStart(10)}  found`);
for (const b of builds) {
  const d = med(b.decode);
  const p = med(b.preview);
  const dd = med(b.detect);
  console.log(`${b.label.padEnd(10)} ${d.toFixed(3).padStart(10)} ${p.toFixed(3).padStart(10)} ${dd.toFixed(3).padStart(10)} ${(dd - d).toFixed(3).padStart(10)}  ${b.found}/${files.length}`);
}
const base = builds[0];
for (const b of builds.slice(1)) {
  const ratio = (key) => med(b[key].map((x, i) => x / base[key][i])).toFixed(2);
  console.log(`${b.label}/${base.label}: decode ${ratio('decode')}, preview ${ratio('preview')}, decode+detect ${ratio('detect')} (median over files of per-file ratios)`);
}
