#!/bin/bash
# Leave-one-view-out refits against the reported std (issue 35, s25):
#   benches/view_spread.sh ROBOCAL TARGET 'DIR/PATTERN' [intrinsics flags...]
# calibrates every image the (quoted) pattern names, then once per image with
# that image left out, and prints per parameter fx, fy, cx, cy the
# jackknife spread sqrt((n-1)/n sum (v_i - mean)^2) of the refits over the
# std the full report gives. Reports go to a temporary folder.
set -euo pipefail
robocal=$1 target=$2 dir=$3
shift 3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# shellcheck disable=SC2206 # the pattern is expanded here on purpose
images=($dir)
"$robocal" intrinsics --target "$target" "$@" -o "$tmp/all.json" "${images[@]}" > /dev/null
for i in "${!images[@]}"; do
  rest=("${images[@]:0:$i}" "${images[@]:$((i + 1))}")
  "$robocal" intrinsics --target "$target" "$@" -o "$tmp/left_out_$i.json" "${rest[@]}" > /dev/null 2>&1 || true
done
python3 - "$tmp" "$dir" <<'PY'
import glob, json, math, sys
tmp, name = sys.argv[1], sys.argv[2]
full = json.load(open(f"{tmp}/all.json"))
refits = [json.load(open(f)) for f in sorted(glob.glob(f"{tmp}/left_out_*.json"))]
n = len(refits)
out = []
for p, (r, c) in [("fx", (0, 0)), ("fy", (1, 1)), ("cx", (0, 2)), ("cy", (1, 2))]:
    values = [f["camera_matrix"][r][c] for f in refits]
    mean = sum(values) / n
    spread = math.sqrt((n - 1) / n * sum((v - mean) ** 2 for v in values))
    out.append(f"{p} {spread:.3f} / {full['std'][p]:.3f} = {spread / full['std'][p]:.2f}")
print(f"{name}: {n} refits; spread / std: " + ", ".join(out))
PY
