#!/usr/bin/env python3
"""Who is closer to the truth on blurred JPEG chessboards: robocal or OpenCV?

On the public OpenCV left/right 9x6 JPEGs robocal's corners differ from
OpenCV's findChessboardCorners + cornerSubPix(11x11) by a per-image median
of up to ~0.15 px, and there is no ground truth. This script degrades the
rendered VGA set (benches/out/chessboard_vga, made by compare_opencv.py) the
way those photos are degraded (extra Gaussian blur and noise, then JPEG
at a given quality), runs both detectors and prints, per degradation: each detector's
error against the renderer's truth and the robocal-OpenCV distance (the
quantity measured on the public set). Blur is symmetric and JPEG noise has
no preferred direction, so the truth does not move.

Usage (crate root, after compare_opencv.py has rendered benches/out and a
release build exists): python3 benches/detect_jpeg_truth.py
"""
import json
import os
import subprocess

from opencv_venv import ensure_venv

ensure_venv()
import cv2  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out")
# (blur sigma px, JPEG quality or None for PNG, extra noise sigma grey levels)
CASES = [(0.0, None, 0), (0.0, 75, 0), (1.0, 90, 0), (1.0, 75, 0), (1.5, 75, 0), (2.0, 75, 0),
         (1.0, 75, 4), (1.5, 60, 6)]


def oriented(found, truth):
    """`found` in the truth's order (the detector may start at either end)."""
    f = np.asarray(found, float).reshape(-1, 2)
    return min((f, f[::-1]), key=lambda c: np.sqrt(((c - truth) ** 2).sum(1)).mean())


def main():
    truth = json.load(open(os.path.join(OUT, "truth.json")))["chessboard_vga"]
    robocal = os.path.join(ROOT, "target", "release", "robocal")
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-4)
    cv2.setNumThreads(1)
    print(f"OpenCV {cv2.__version__}; {len(truth['images'])} renders 640x480 (noise sigma 2), "
          "degraded by blur sigma, extra noise, then JPEG quality; errors in px")
    print(f"{'blur':>5s} {'jpeg':>5s} {'noise':>5s} | {'robocal vs truth':>17s} | {'OpenCV vs truth':>17s} | "
          f"{'robocal-OpenCV per-image median':>32s}")
    print(f"{'':5s} {'':5s} {'':5s} | {'mean':>8s} {'max':>8s} | {'mean':>8s} {'max':>8s} | "
          f"{'median':>10s} {'max':>10s} {'found':>9s}")
    rng = np.random.default_rng(7)
    for blur, quality, noise in CASES:
        d = os.path.join(OUT, f"jpeg_b{blur}_q{quality}_n{noise}")
        os.makedirs(d, exist_ok=True)
        files = []
        for im in truth["images"]:
            g = cv2.imread(im["file"], cv2.IMREAD_GRAYSCALE)
            if blur > 0:
                g = cv2.GaussianBlur(g, (0, 0), blur)
            if noise > 0:
                g = np.clip(g + rng.normal(0.0, noise, g.shape), 0, 255).round().astype(np.uint8)
            name = os.path.join(d, os.path.basename(im["file"]))
            if quality is None:
                cv2.imwrite(name, g)
            else:
                name = name.replace(".png", ".jpg")
                cv2.imwrite(name, g, [cv2.IMWRITE_JPEG_QUALITY, quality])
            files.append(name)
        out_json = os.path.join(d, "robocal.json")
        subprocess.run([robocal, "detect", "--threads", "1", "--target", truth["target"], "-o", out_json]
                       + files, cwd=ROOT, stderr=subprocess.DEVNULL, check=False)
        res = json.load(open(out_json))["images"]
        r_err, o_err, medians, found = [], [], [], [0, 0]
        for f, im, r in zip(files, truth["images"], res):
            t = np.asarray(im["points"], float)
            g = cv2.imread(f, cv2.IMREAD_GRAYSCALE)
            ok, c = cv2.findChessboardCorners(g, tuple(truth["opencv_pattern"]))
            rp = None
            if "detection" in r:
                found[0] += 1
                rp = oriented([[p["x_px"], p["y_px"]] for p in r["detection"]["points"]], t)
                r_err.append(np.sqrt(((rp - t) ** 2).sum(1)))
            if ok:
                found[1] += 1
                op = oriented(cv2.cornerSubPix(g, c, (11, 11), (-1, -1), crit), t)
                o_err.append(np.sqrt(((op - t) ** 2).sum(1)))
                if rp is not None:
                    medians.append(np.median(np.sqrt(((rp - op) ** 2).sum(1))))
        r_all, o_all = np.concatenate(r_err), np.concatenate(o_err)
        q = "png" if quality is None else str(quality)
        print(f"{blur:5.1f} {q:>5s} {noise:5d} | {r_all.mean():8.4f} {r_all.max():8.4f} | {o_all.mean():8.4f} "
              f"{o_all.max():8.4f} | {np.median(medians):10.4f} {np.max(medians):10.4f} "
              f"{found[0]:>3d}/{found[1]:<3d}")
    print("found = boards found by robocal / by OpenCV")


if __name__ == "__main__":
    main()
