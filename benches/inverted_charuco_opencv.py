#!/usr/bin/env python3
"""OpenCV's ChArUco detector on the caliscope inverted-board frames, for the
"Inverted boards" table of BENCHMARKS.md (robocal's side: `robocal detect`
on the same frames, see benches/inverted_charuco.sh).

usage: inverted_charuco_opencv.py FRAME.png...  (frames as benches/inverted_charuco.sh extracts them)
prints one line per camera (the file name's prefix before '_'):
frames, frames with a board, corners per frame with a board, mean.
OpenCV needs the image inverted by hand: cv2.aruco.CharucoDetector on 255 - grey.
"""
import collections
import sys

import cv2

board = cv2.aruco.CharucoBoard(
    (4, 5), 0.054, 0.0405, cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_1000)
)
detector = cv2.aruco.CharucoDetector(board)
per_camera = collections.defaultdict(list)
for path in sys.argv[1:]:
    grey = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    corners, ids, _, _ = detector.detectBoard(255 - grey)
    camera = path.rsplit("/", 1)[-1].split("_")[0]
    per_camera[camera].append(0 if ids is None else len(ids))
print(f"opencv {cv2.__version__}")
for camera, counts in sorted(per_camera.items()):
    found = [c for c in counts if c > 0]
    full = sum(1 for c in found if c == 12)
    mean = sum(found) / len(found) if found else 0.0
    print(f"{camera}: {len(counts)} frames, {len(found)} with a board, {full} with all 12 corners, {sum(found)} corners, {mean:.2f} per frame found")
