#!/usr/bin/env python3
"""What robocal's saddle-fit window does on real photos and on renders
(issue 42 diagnosis). A numpy model of src/detect/refine.rs (a quadratic
surface fitted by Gaussian-weighted least squares, sigma = half the window,
to the image smoothed with sigma = window / 3.5, at whole-pixel offsets
around the estimate, moved to the saddle until the step is below 0.002 px;
the window is the local grid step / 6 clamped to [2.5, MAX] px, robocal's
MAX is 6) started from OpenCV's 15x15 cornerSubPix corners, for several
MAX. For each set and window: the corners' radial magnification about the
principal point against OpenCV's 15x15 corners (real photos) or the truth
(a robocal render folder), the corners' RMS distance to the truth (renders)
and a calibration from them (`robocal intrinsics --detections`, k1 k2 p1
p2, k3 held).

Usage (crate root):
  python3 benches/saddle_windows.py --robocal target/debug/robocal [--max 6,4,3]
      [--set left|right|DIR ...]   (DIR: a `robocal render` folder, truth.json)
"""
import argparse
import glob
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from corner_edges import calibrate, sample  # noqa: E402
from real_sets import cv2, dataset_dir  # noqa: E402  (settles the venv)
import numpy as np  # noqa: E402

COLS, ROWS = 9, 6
PP = {"left": (341.586, 234.259), "right": (326.472, 249.333)}  # Bouguet's example 5


def saddle(smooth, c, w):
    """The saddle fit at half-window w from c on the smoothed image."""
    n = int(np.floor(1.5 * w))
    t = np.arange(-n, n + 1.0)
    u, v = (a.ravel() for a in np.meshgrid(t, t))
    sw = np.sqrt(np.exp(-(u * u + v * v) / (2 * (0.5 * w) ** 2)))
    a = np.c_[u * u, u * v, v * v, u, v, np.ones_like(u)] * sw[:, None]
    for _ in range(10):
        z = sample(smooth, c[0] + u, c[1] + v)
        p = np.linalg.lstsq(a, z * sw, rcond=None)[0]
        step = -np.linalg.solve(np.array([[2 * p[0], p[1]], [p[1], 2 * p[2]]]), p[3:5])
        c = c + step
        if np.linalg.norm(step) < 0.002:
            break
    return c


def corner_sets(images, maxima):
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 50, 1e-5)
    out = {k: [] for k in ["cornerSubPix 15x15", *maxima]}
    names, size = [], None
    for path in images:
        gray = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        ok, c = cv2.findChessboardCorners(gray, (COLS, ROWS), None)
        if not ok:
            continue
        size = gray.shape[::-1]
        names.append(os.path.basename(path))
        ref = cv2.cornerSubPix(gray, c, (7, 7), (-1, -1), crit).reshape(-1, 2).astype(np.float64)
        g = ref.reshape(ROWS, COLS, 2)
        steps = np.r_[np.linalg.norm(np.diff(g, axis=1), axis=2).ravel(),
                      np.linalg.norm(np.diff(g, axis=0), axis=2).ravel()]
        out["cornerSubPix 15x15"].append(ref)
        for mx in maxima:
            w = min(max(np.median(steps) / 6.0, 2.5), mx)
            smooth = cv2.GaussianBlur(gray.astype(np.float64), (0, 0), max(w / 3.5, 1.0))
            out[mx].append(np.array([saddle(smooth, q.copy(), w) for q in ref]))
    return out, names, size


def magnification(views, bases, pp):
    p, b = np.vstack(views), np.vstack(bases)
    x = np.c_[b - pp, np.ones(len(b))]
    a = np.linalg.lstsq(x, p - b, rcond=None)[0]
    return 0.5 * (a[0, 0] + a[1, 1]), float(np.sqrt(((p - b) ** 2).sum(1).mean()))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robocal", default=os.path.join(os.path.dirname(HERE), "target", "debug", "robocal"))
    ap.add_argument("--max", default="6,4,3", help="window caps to try, px")
    ap.add_argument("--set", action="append", help="left, right or a render folder (default left, right)")
    a = ap.parse_args()
    maxima = [float(v) for v in a.max.split(",")]
    d = dataset_dir("opencv-left-right-9x6")
    for s in a.set or ["left", "right"]:
        truth = None
        if s in PP:
            if not d:
                print(f"skipped {s}: opencv-left-right-9x6 not found in ../shared/datasets")
                continue
            images, pp = sorted(glob.glob(os.path.join(d, f"{s}*.jpg"))), np.array(PP[s])
        else:
            t = json.load(open(os.path.join(s, "truth.json")))
            images = [os.path.join(s, v["image"]) for v in t["views"]]
            pp = np.array([t["camera"]["cx"], t["camera"]["cy"]])
            truth = {v["image"]: np.array([[p["x_px"], p["y_px"]] for p in v["points"]]) for v in t["views"]}
        sets, names, size = corner_sets(images, maxima)
        ids = [list(range(COLS * ROWS))] * len(names)
        print(f"{s}: {len(names)} views; magnification about the principal point against "
              f"{'the truth' if truth else 'cornerSubPix 15x15'}")
        for k, views in sets.items():
            if truth:
                bases = [np.array([truth[n][np.argmin(((truth[n] - q) ** 2).sum(1))] for q in v])
                         for n, v in zip(names, views)]
            else:
                bases = sets["cornerSubPix 15x15"]
            m, rms = magnification(views, bases, pp)
            r = calibrate(a.robocal, views, ids, size)
            label = k if isinstance(k, str) else f"saddle, window cap {k:g} px"
            extra = f", corner rms {rms:.4f} px" if truth else ""
            print(f"  {label:26s} magnification {m * 1e4:+.2f}e-4{extra}; fx {r['fx']:.3f} fy {r['fy']:.3f} "
                  f"(std {r['sfx']:.3f}) cx {r['cx']:.3f} cy {r['cy']:.3f}, calibration rms {r['rms']:.4f} px")


if __name__ == "__main__":
    main()
