#!/bin/sh
# The "Inverted boards" table of BENCHMARKS.md: caliscope's inverted ChArUco
# (../shared/datasets/caliscope-4cam-charuco-video, SOURCE.md), every third
# frame from frame 21 of each camera's video (30 per camera), detected by
# robocal without a print option and by OpenCV's CharucoDetector on the
# inverted frames (benches/inverted_charuco_opencv.py).
#
# usage: benches/inverted_charuco.sh [ROBOCAL]   (default target/release/robocal)
# needs ffmpeg and python3 with opencv-python-headless (4.14.0.94 for the table).
set -eu
robocal=${1:-target/release/robocal}
data=${ROBOCAL_DATASETS:-$(dirname "$0")/../../shared/datasets}/caliscope-4cam-charuco-video/video
spec=charuco:4x5:54mm:40.5mm:DICT_4X4_1000
[ -d "$data" ] || { echo "skipped: $data not found" >&2; exit 0; }
frames=$(mktemp -d)
trap 'rm -rf "$frames"' EXIT
for c in 0 1 2 3; do
    ffmpeg -v error -y -i "$data/cam_$c.mp4" -vf 'select=gte(n\,21)*not(mod(n\,3))' \
        -vsync 0 -frames:v 30 "$frames/cam${c}_%03d.png"
done
"$robocal" detect --target "$spec" --threads 1 "$frames"/*.png -o "$frames/robocal.json" 2>/dev/null || true
python3 - "$frames/robocal.json" <<'PY'
import collections, json, sys
per_camera = collections.defaultdict(list)
prints = collections.Counter()
ms = []
for image in json.load(open(sys.argv[1]))["images"]:
    camera = image["file"].rsplit("/", 1)[-1].split("_")[0]
    detection = image.get("detection")
    per_camera[camera].append(len(detection["points"]) if detection else 0)
    if detection:
        prints[detection.get("polarity")] += 1
    ms.append(image.get("detect_ms", 0.0))
print("robocal (no print option); prints found:", dict(prints))
for camera, counts in sorted(per_camera.items()):
    found = [c for c in counts if c > 0]
    full = sum(1 for c in found if c == 12)
    mean = sum(found) / len(found) if found else 0.0
    print(f"{camera}: {len(counts)} frames, {len(found)} with a board, {full} with all 12 corners, {sum(found)} corners, {mean:.2f} per frame found")
print(f"detect_ms: median {sorted(ms)[len(ms) // 2]:.1f}")
PY
python3 "$(dirname "$0")/inverted_charuco_opencv.py" "$frames"/*.png
