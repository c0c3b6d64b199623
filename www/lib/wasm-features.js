// What the calibration engine needs from the browser: WebAssembly with its
// SIMD instructions (the core is built with simd128, .cargo/config.toml).
// Chrome and Edge 91+, Firefox 89+, Safari 16.4+ (iOS 16.4+) have them; an
// older browser would fail to compile the module with a message about an
// invalid opcode, so the engine asks first and says what is missing.

// The smallest module that uses SIMD: one function `() -> v128` whose body is
// `i32.const 0; i32x4.splat; end`. Only a browser with SIMD validates it.
const SIMD_PROBE = new Uint8Array([
  0x00, 0x61, 0x73, 0x6d, 0x01, 0x00, 0x00, 0x00, // "\0asm", version 1
  0x01, 0x05, 0x01, 0x60, 0x00, 0x01, 0x7b, // types: () -> v128
  0x03, 0x02, 0x01, 0x00, // functions: one, of type 0
  0x0a, 0x08, 0x01, 0x06, 0x00, 0x41, 0x00, 0xfd, 0x11, 0x0b, // code: no locals, i32.const 0, i32x4.splat, end
]);

export const BROWSERS_NEEDED = 'Chrome or Edge 91+, Firefox 89+, Safari 16.4+';

/**
 * Why this JavaScript host cannot run the engine, or null when it can:
 * WebAssembly itself and its SIMD instructions are checked.
 */
export function missingWasmFeature(wasm = globalThis.WebAssembly) {
  if (typeof wasm !== 'object' || !wasm || typeof wasm.validate !== 'function') {
    return `this browser has no WebAssembly, which the calibration engine runs on: use a current browser (${BROWSERS_NEEDED})`;
  }
  if (!wasm.validate(SIMD_PROBE)) {
    return `this browser's WebAssembly lacks the SIMD instructions the calibration engine is built with: use ${BROWSERS_NEEDED}, or update this one`;
  }
  return null;
}
