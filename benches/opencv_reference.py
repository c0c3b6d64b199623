#!/usr/bin/env python3
"""Write fixtures/opencv-left-right-9x6.json: OpenCV's refined chessboard
corners for the public OpenCV left/right 9x6 images, the reference that
tests/detect/detect_datasets.rs compares robocal's detector with.

Usage (from the crate root; runs in benches/.venv, see benches/opencv_venv.py):
  python3 benches/opencv_reference.py [DATASET_DIR]
"""
import json
import os
import sys

from opencv_venv import ensure_venv

ensure_venv()
import cv2  # noqa: E402  (after the venv switch)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DEFAULT = os.path.join(ROOT, "..", "shared", "datasets", "opencv-left-right-9x6")


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else DEFAULT
    if not os.path.isdir(data):
        data = "/work/shared/datasets/opencv-left-right-9x6"
    cv2.setNumThreads(1)
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-4)
    images = {}
    for name in sorted(os.listdir(data)):
        if not name.endswith(".jpg"):
            continue
        gray = cv2.imread(os.path.join(data, name), cv2.IMREAD_GRAYSCALE)
        ok, corners = cv2.findChessboardCorners(gray, (9, 6))
        if not ok:
            images[name] = None
            continue
        corners = cv2.cornerSubPix(gray, corners, (11, 11), (-1, -1), crit)
        images[name] = [[round(float(x), 4), round(float(y), 4)] for x, y in corners.reshape(-1, 2)]
    doc = {
        "provenance": "benches/opencv_reference.py with opencv-python-headless "
        + cv2.__version__
        + ": findChessboardCorners(9x6, default flags) + cornerSubPix(11x11, eps 1e-4, 100 iterations); "
        "corners in OpenCV's order (pixel centre = integer coordinates, as robocal); null = OpenCV found no board",
        "pattern": [9, 6],
        "images": images,
    }
    out = os.path.join(ROOT, "fixtures", "opencv-left-right-9x6.json")
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print("wrote", out, sum(v is not None for v in images.values()), "of", len(images), "boards")


if __name__ == "__main__":
    main()
