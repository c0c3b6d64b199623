// The page's check of what the engine needs (www/lib/wasm-features.js):
// node's WebAssembly (the same V8 as Chromium) passes it; a host without SIMD
// or without WebAssembly gets the message naming the browsers, not the
// compiler's "invalid opcode".
import assert from 'node:assert/strict';
import { missingWasmFeature, BROWSERS_NEEDED } from '../../www/lib/wasm-features.js';

assert.equal(missingWasmFeature(), null);
assert.equal(BROWSERS_NEEDED, 'Chrome or Edge 91+, Firefox 89+, Safari 16.4+');
// A WebAssembly that knows no SIMD: it refuses the probe module.
let probe = null;
const noSimd = { validate: (bytes) => { probe = bytes; return false; } };
assert.equal(missingWasmFeature(noSimd), "this browser's WebAssembly lacks the SIMD instructions the calibration engine is built with: use Chrome or Edge 91+, Firefox 89+, Safari 16.4+, or update this one");
// The validator reads the probe's SIMD instruction: with i32x4.splat
// (0xfd 0x11) replaced by i32x4.extadd_pairwise_i16x8_u (0xfd 0x7f), which
// takes a v128 where the probe pushes an i32, node refuses the module.
assert.equal(WebAssembly.validate(probe), true);
const broken = Uint8Array.from(probe);
broken[broken.indexOf(0xfd) + 1] = 0x7f;
assert.equal(WebAssembly.validate(broken), false);
assert.equal(missingWasmFeature(null), 'this browser has no WebAssembly, which the calibration engine runs on: use a current browser (Chrome or Edge 91+, Firefox 89+, Safari 16.4+)');
console.log('wasm feature check: SIMD found in node, the messages for its absence as written');
