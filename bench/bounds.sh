#!/usr/bin/env bash
# Bounded time and memory of decode + detect (issue 17 §2): times the release
# CLI on blank and noise images up to 50 MP, median of RUNS runs, with peak RSS
# (GNU time %M). Usage: bench/bounds.sh [CLI] (default target/release/robocal).
# Prints a markdown table. Not a test: the machine is shared and noisy.
set -euo pipefail
CLI=${1:-target/release/robocal}
RUNS=${RUNS:-3}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$dir" <<'P'
import os, sys
d = sys.argv[1]
for name, side, noise in [("blank-4mp", 2000, False), ("noise-4mp", 2000, True),
                          ("blank-50mp", 7072, False), ("noise-50mp", 7072, True)]:
    px = os.urandom(side * side) if noise else b"\x80" * (side * side)
    open(f"{d}/{name}.pgm", "wb").write(b"P5 %d %d 255\n" % (side, side) + px)
P
echo "| image | command | median s | peak RSS MB |"
echo "|---|---|---|---|"
for img in blank-4mp noise-4mp blank-50mp noise-50mp; do
  for cmd in "info" "detect --target chessboard:9x6:30mm -o /dev/null" "detect --target circles:4x11:20mm:asymmetric -o /dev/null"; do
    times=(); rss=0
    for _ in $(seq "$RUNS"); do
      /usr/bin/time -o "$dir/t" -f "%e %M" $CLI $cmd "$dir/$img.pgm" >/dev/null 2>&1 || true
      out=$(tail -1 "$dir/t")
      times+=("${out% *}"); r=${out#* }; (( r > rss )) && rss=$r
    done
    med=$(printf '%s\n' "${times[@]}" | sort -g | sed -n "$(( (RUNS + 1) / 2 ))p")
    echo "| $img | ${cmd%% -o*} | $med | $((rss / 1024)) |"
  done
done
