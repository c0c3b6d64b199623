#!/usr/bin/env bash
# Prints the raw and gzip size of a wasm file (recorded in BENCHMARKS.md).
set -euo pipefail
f="$1"
raw=$(wc -c < "$f")
gz=$(gzip -9 -c "$f" | wc -c)
printf 'wasm size: %s raw %d KB, gzip %d KB\n' "$f" $((raw / 1024)) $((gz / 1024))
