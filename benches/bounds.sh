#!/usr/bin/env bash
# Bounded time and memory (issue 17 §2): times the release CLI, median of RUNS
# runs, with peak RSS (GNU time %M), on
#  - blank and noise images of 4, 50 and 99 MP (the native pixel limit is 100
#    MP) for every target kind;
#  - progressive JPEGs with 5,000 and 50,000 scans (benches/progressive_jpeg.py,
#    needs benches/.venv: created on first use);
#  - hostile and awkward image files (issue 37): a 4 MB PNG whose iCCP
#    profile inflates to 3.9 GiB, a 10000x10000 16-bit RGBA PNG (alone and
#    four at once on 4 threads), 3 GB of zeros named .png, /dev/zero, a FIFO
#    with no writer, a JPEG cut at 10 %;
#  - camera calibrations of 100 to 10,000 views (detections JSON of a 9x6
#    board, random poses), and the refusal above calib::json_api::MAX_VIEWS.
# Usage: benches/bounds.sh [CLI] (default target/release/robocal). Prints
# markdown tables. Not a test: the machine is shared and noisy.
set -euo pipefail
CLI=$(realpath "${1:-target/release/robocal}")
RUNS=${RUNS:-3}
HERE=$(dirname "$(realpath "$0")")
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

# time_row LABEL COMMAND...: one table row, the median time and the peak RSS.
time_row() {
  local label=$1; shift
  local times=() rss=0 out r
  for _ in $(seq "$RUNS"); do
    /usr/bin/time -o "$dir/t" -f "%e %M" "$@" >/dev/null 2>&1 || true
    out=$(tail -1 "$dir/t")
    times+=("${out% *}"); r=${out#* }; (( r > rss )) && rss=$r
  done
  local med
  med=$(printf '%s\n' "${times[@]}" | sort -g | sed -n "$(( (RUNS + 1) / 2 ))p")
  echo "$label | $med | $((rss / 1024)) |"
}

python3 - "$dir" <<'P'
import os, sys
d = sys.argv[1]
for name, side, noise in [("blank-4mp", 2000, False), ("noise-4mp", 2000, True),
                          ("blank-50mp", 7072, False), ("noise-50mp", 7072, True),
                          ("blank-99mp", 9950, False), ("noise-99mp", 9950, True)]:
    px = os.urandom(side * side) if noise else b"\x80" * (side * side)
    open(f"{d}/{name}.pgm", "wb").write(b"P5 %d %d 255\n" % (side, side) + px)
P

echo "## Images"
echo
echo "| image | command | median s | peak RSS MB |"
echo "|---|---|---|---|"
targets=("chessboard:9x6:30mm" "circles:4x11:20mm:asymmetric" "dots:7x7:25mm" "squares:8x8:12.7mm:22.5778mm" "circle:10mm")
for img in blank-4mp noise-4mp blank-50mp noise-50mp blank-99mp noise-99mp; do
  time_row "| $img | info" "$CLI" info "$dir/$img.pgm"
  for t in "${targets[@]}"; do
    time_row "| $img | detect --target $t" "$CLI" detect --target "$t" -o /dev/null "$dir/$img.pgm"
  done
done
(cd "$HERE" && python3 progressive_jpeg.py "$dir/prog-5k.jpg" 4000 5000 >&2 && python3 progressive_jpeg.py "$dir/prog-50k.jpg" 4000 50000 >&2 \
  && python3 progressive_jpeg.py "$dir/prog-99mp-5k.jpg" 9900 5000 >&2)
for img in prog-5k prog-50k prog-99mp-5k; do
  time_row "| $img.jpg | detect --target chessboard:9x6:30mm" "$CLI" detect --target chessboard:9x6:30mm -o /dev/null "$dir/$img.jpg"
done


echo
echo "## Hostile image files"
echo
python3 - "$dir" <<'P'
import os, struct, sys, zlib
d = sys.argv[1]
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
def png(path, w, h, depth, colour, row, extra=b""):
    z = zlib.compressobj(9)
    idat = b"".join(z.compress(b"\0" + row) for _ in range(h)) + z.flush()
    ihdr = struct.pack(">IIBBBBB", w, h, depth, colour, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + extra + chunk(b"IDAT", idat) + chunk(b"IEND", b""))
# The colour profile: 3.9 GiB of zeros, deflated in 64 MiB pieces.
z, block, parts = zlib.compressobj(9), bytes(64 << 20), []
for _ in range(62):
    parts.append(z.compress(block))
parts.append(z.flush())
png(f"{d}/iccp-bomb.png", 640, 480, 8, 0, bytes(640), chunk(b"iCCP", b"bomb\0\0" + b"".join(parts)))
png(f"{d}/rgba16-100mp.png", 10000, 10000, 16, 6, b"\x80\x00" * 40000)
P
for i in 1 2 3 4; do cp "$dir/rgba16-100mp.png" "$dir/rgba16-100mp-$i.png"; done
truncate -s 3G "$dir/junk-3gb.png"
mkfifo "$dir/fifo.png"
python3 -c "import sys; b = open(sys.argv[1], 'rb').read(); open(sys.argv[2], 'wb').write(b[:len(b) // 10])" \
  "$dir/prog-5k.jpg" "$dir/cut10.jpg"
echo "| file (bytes) | command | median s | peak RSS MB |"
echo "|---|---|---|---|"
time_row "| iccp-bomb.png ($(stat -c %s "$dir/iccp-bomb.png")) | info" "$CLI" info "$dir/iccp-bomb.png"
time_row "| iccp-bomb.png | detect --target chessboard:9x6:30mm" "$CLI" detect --target chessboard:9x6:30mm -o /dev/null "$dir/iccp-bomb.png"
time_row "| rgba16-100mp.png ($(stat -c %s "$dir/rgba16-100mp.png")) | info" "$CLI" info "$dir/rgba16-100mp.png"
time_row "| rgba16-100mp.png | detect --target chessboard:9x6:30mm" "$CLI" detect --target chessboard:9x6:30mm -o /dev/null "$dir/rgba16-100mp.png"
time_row "| 4 x rgba16-100mp.png | detect --threads 4 --target circles:4x11:20mm:asymmetric" "$CLI" detect --threads 4 --target circles:4x11:20mm:asymmetric -o /dev/null "$dir"/rgba16-100mp-?.png
time_row "| junk-3gb.png (3221225472) | info" "$CLI" info "$dir/junk-3gb.png"
time_row "| /dev/zero | info" "$CLI" info /dev/zero
time_row "| fifo.png (no writer) | info" timeout 10 "$CLI" info "$dir/fifo.png"
time_row "| cut10.jpg | info" "$CLI" info "$dir/cut10.jpg"
echo
for f in "$dir/iccp-bomb.png" "$dir/junk-3gb.png" /dev/zero "$dir/fifo.png" "$dir/cut10.jpg"; do
  echo "- \`robocal info $(basename "$f")\`: \`$(timeout 10 "$CLI" info "$f" 2>/dev/null | sed "s|$dir/||g")\`"
done

echo
echo "## Camera calibration (robocal intrinsics --detections, 9x6 board, Brown model)"
echo
echo "| views | median s | peak RSS MB |"
echo "|---|---|---|"
for n in 100 1000 5000 10000 100000; do
  python3 - "$dir/d$n.json" "$n" <<'P'
import json, math, random, sys
out, n = sys.argv[1], int(sys.argv[2])
random.seed(n)
f, cx, cy, W, H = 900.0, 639.5, 479.5, 1280, 960
def rot(a, b, c):
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    return [[cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa],
            [sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa],
            [-sb, cb * sa, cb * ca]]
images = []
while len(images) < n:
    R = rot(random.uniform(-.6, .6), random.uniform(-.6, .6), random.uniform(-.3, .3))
    t = [random.uniform(-.15, .05), random.uniform(-.1, .02), random.uniform(.45, .7)]
    pts = []
    for j in range(6):
        for i in range(9):
            X = (i * 0.03, j * 0.03, 0.0)
            P = [sum(R[a][b] * X[b] for b in range(3)) + t[a] for a in range(3)]
            pts.append({"id": i + 9 * j, "x_px": f * P[0] / P[2] + cx + random.gauss(0, 0.1),
                        "y_px": f * P[1] / P[2] + cy + random.gauss(0, 0.1)})
    if all(0 <= p["x_px"] < W - 1 and 0 <= p["y_px"] < H - 1 for p in pts):
        images.append({"file": f"v{len(images)}.png", "detection": {"image_size_px": [W, H],
            "target": {"kind": "chessboard", "cols": 9, "rows": 6, "square_m": 0.03}, "points": pts}})
json.dump({"images": images}, open(out, "w"))
P
  time_row "| $n" "$CLI" intrinsics --detections "$dir/d$n.json" -o /dev/null
done
echo
echo "100000 views: $("$CLI" intrinsics --detections "$dir/d100000.json" -o /dev/null 2>&1 | tail -1)"

echo
echo "## Workflows (seed 001 planar solve, seed 003 XY table)"
echo
echo "| command | points | median s | peak RSS MB |"
echo "|---|---|---|---|"
for n in 10000 100000; do
  python3 - "$dir" "$n" <<'P'
import random, sys
d, n = sys.argv[1], int(sys.argv[2])
random.seed(n)
with open(f"{d}/planar{n}.csv", "w") as f:
    f.write("height_mm,u_px,v_px,x_mm,y_mm\n")
    for _ in range(n):
        x, y, h = random.uniform(0, 500), random.uniform(0, 400), random.choice([0, 50])
        f.write(f"{h},{2 * x + random.gauss(0, .1)},{2 * y + random.gauss(0, .1)},{x},{y}\n")
with open(f"{d}/xy{n}.csv", "w") as f:
    f.write("x_mm,y_mm,z_mm,u_px,v_px\n")
    for _ in range(n):
        x, y, z = random.uniform(-200, 200), random.uniform(-150, 150), random.uniform(0, 100)
        f.write(f"{x},{y},{z},{800 * x / (1000 + z) + 640 + random.gauss(0, .1)},{800 * y / (1000 + z) + 480 + random.gauss(0, .1)}\n")
P
  time_row "| planar solve | $n" "$CLI" planar solve "$dir/planar$n.csv" -o /dev/null
  time_row "| xytable | $n" "$CLI" xytable "$dir/xy$n.csv" -o /dev/null
done
echo
echo "xytable, 100000 positions: $("$CLI" xytable "$dir/xy100000.csv" -o /dev/null 2>&1 | tail -1)"
