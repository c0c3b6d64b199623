#!/bin/bash
# CPU milliseconds a call, native against wasm (node), for detection and
# decoding: wall-clock medians (benches/wasm_detect.mjs, detect_time) swing
# by 2x when other builds share the cores, CPU time much less. Each figure
# is the mean over (20 x files) calls: the process's user + system CPU at
# --repeat 21 minus that at --repeat 1 (start-up, the first decode and the
# wasm compile cancel out), from /usr/bin/time (10 ms ticks: keep the
# totals in seconds).
# Usage (crate root, after `make pkg` and
# `cargo build --release --example detect_time`):
#   benches/wasm_native_cpu.sh SPEC MODE FILES...
# MODE: detect (detection alone), decode+detect, decode (wasm only: the
# native decode is decode+detect minus detect). PKG=DIR (default pkg) times
# another copy of the package (DIR/node/robocal.js).
set -euo pipefail
spec=$1 mode=$2
shift 2
n=$#
root=$(cd "$(dirname "$0")/.." && pwd)
pkg=${PKG:-$root/pkg}
cpu() { /usr/bin/time -f '%U %S' "$@" 2>&1 >/dev/null | tail -1 | awk '{print $1 + $2}'; }
per_call() { echo "scale=3; ($1 - $2) * 1000 / (20 * $n)" | bc -l; }
native() {
  local flag=()
  [ "$mode" = decode+detect ] && flag=(--decode)
  local dt=$root/target/release/examples/detect_time
  per_call "$(cpu "$dt" --target "$spec" --no-blank --repeat 21 "${flag[@]}" "$@")" \
    "$(cpu "$dt" --target "$spec" --no-blank --repeat 1 "${flag[@]}" "$@")"
}
wasm() {
  local flag=()
  [ "$mode" = detect ] && flag=(--detect-only)
  [ "$mode" = decode ] && flag=(--decode-only)
  local dir
  dir=$(mktemp -d)
  mkdir -p "$dir/benches" "$dir/pkg"
  cp "$root/benches/wasm_detect.mjs" "$dir/benches/"
  ln -s "$pkg/node" "$dir/pkg/node"
  per_call "$(cpu node "$dir/benches/wasm_detect.mjs" --target "$spec" --repeat 21 "${flag[@]}" "$@")" \
    "$(cpu node "$dir/benches/wasm_detect.mjs" --target "$spec" --repeat 1 "${flag[@]}" "$@")"
  rm -rf "$dir"
}
[ "$mode" = decode ] || echo "native $mode: $(native "$@") ms CPU a call ($n files)"
echo "wasm $mode: $(wasm "$@") ms CPU a call ($n files, $pkg)"
