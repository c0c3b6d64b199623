#!/usr/bin/env bash
# Prints the raw and gzip size of a wasm file (recorded in BENCHMARKS.md) and
# a WARNING line when the gzip size is over the budget of issue 9 (400 KB).
set -euo pipefail
f="$1"
budget_kb=400
raw=$(wc -c < "$f")
gz=$(gzip -9 -c "$f" | wc -c)
printf 'wasm size: %s raw %d KB, gzip %d KB\n' "$f" $((raw / 1024)) $((gz / 1024))
if [ $((gz / 1024)) -gt $budget_kb ]; then
  printf 'WARNING: %s is %d KB gzip, over the %d KB budget (see the wasm size section of BENCHMARKS.md)\n' "$f" $((gz / 1024)) $budget_kb
fi
