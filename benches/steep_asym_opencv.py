#!/usr/bin/env python3
"""OpenCV's findCirclesGrid on the steep asymmetric circle grids that
`cargo run --release --example steep_asym_set` renders (the views of
tests/detect/detect_circles_asym.rs, 56-64 degrees of tilt).

Usage (crate root, after the example):
  /work/cvenv/bin/python benches/steep_asym_opencv.py [OUT_DIR]

Per view and flags (CALIB_CB_ASYMMETRIC_GRID alone, then with
CALIB_CB_CLUSTERING, OpenCV's choice for perspective-distorted grids; the
default blob detector, one thread; light-on-dark prints inverted by hand,
as OpenCV wants dark blobs): found or not, and for a found grid each
point's distance to the nearest truth point (OpenCV numbers an asymmetric
grid its own way). The total lines: views found, mean / max distance, px,
and per tilt.
"""
import json
import os
import sys

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "out", "steep_asym")


def run(views, flags, label):
    found, dists, by_tilt = 0, [], {}
    for v in views:
        g = cv2.imread(v["file"], cv2.IMREAD_GRAYSCALE)
        if v["light_on_dark"]:
            g = 255 - g
        ok, c = cv2.findCirclesGrid(g, tuple(v["opencv_pattern"]), flags=flags)
        t = np.asarray(v["points"], float)
        tilt = by_tilt.setdefault(v["tilt_deg"], [0, 0])
        tilt[1] += 1
        what = f'{label}: {os.path.basename(v["file"])} {v["target"]} {v["camera"]} ({v["tilt_deg"]} deg)'
        if not ok:
            print(f"{what}: not found")
            continue
        c = c.reshape(-1, 2)
        d = np.sqrt(((c[:, None, :] - t[None, :, :]) ** 2).sum(2)).min(1)
        print(f"{what}: found, worst {d.max():.4f} px")
        found += 1
        tilt[0] += 1
        dists.extend(d.tolist())
    mean = np.mean(dists) if dists else float("nan")
    mx = np.max(dists) if dists else float("nan")
    per_tilt = ", ".join(f"{k:g}: {f}/{n}" for k, (f, n) in sorted(by_tilt.items()))
    return f"OpenCV {cv2.__version__} findCirclesGrid {label}: {found} of {len(views)} views found, mean / max {mean:.4f} / {mx:.4f} px; per tilt (deg: found / views) {per_tilt}"


def main():
    cv2.setNumThreads(1)
    views = json.load(open(os.path.join(OUT, "truth.json")))
    lines = [
        run(views, cv2.CALIB_CB_ASYMMETRIC_GRID, "ASYMMETRIC_GRID"),
        run(views, cv2.CALIB_CB_ASYMMETRIC_GRID | cv2.CALIB_CB_CLUSTERING, "ASYMMETRIC_GRID | CLUSTERING"),
    ]
    print("\n".join(lines))


if __name__ == "__main__":
    main()
