#!/usr/bin/env python3
"""Chessboard corners from their edges' far field (issue 42 diagnosis):
each inner corner is where the two grid edge curves through it meet, each
curve a quadratic fitted to the gradient centroids of the edge between the
neighbouring corners, sampled away from the X-junctions (the middle half
of each edge segment). An asymmetric PSF (coma, field-dependent blur)
moves each blurred edge by the projection of the PSF's centroid and keeps
the edge straight, so these corners are the PSF centroid's projection,
the convention of edge- and centroid-based targets, with no dependence on
how the junction itself blurs. Compares robocal's corners and OpenCV's
cornerSubPix (several windows) with them as a radial magnification about
the principal point (robocal - edge, per unit radius) and an RMS distance.
On renders (a folder with truth.json) the edge corners are compared with
the truth too.

Usage (crate root):
  python3 benches/corner_edges.py --robocal target/debug/robocal --images 'DIR/left*.jpg' --pp 341.6,234.3
  python3 benches/corner_edges.py --robocal target/debug/robocal --render DIR   (a robocal render folder)
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from real_sets import cv2, dataset_dir  # noqa: E402  (settles the venv)
import numpy as np  # noqa: E402

COLS, ROWS = 9, 6


def sample(img, x, y):
    """Cubic-convolution (Keys, a = -0.5) interpolation of img at float
    coordinates x, y (pixel centres at integers, edges replicated)."""
    x, y = np.asarray(x, np.float64), np.asarray(y, np.float64)
    ix, iy = np.floor(x).astype(int), np.floor(y).astype(int)

    def weights(f):
        t = np.stack([1 + f, f, 1 - f, 2 - f])
        a = -0.5
        near = (a + 2) * t ** 3 - (a + 3) * t ** 2 + 1
        far = a * t ** 3 - 5 * a * t ** 2 + 8 * a * t - 4 * a
        return np.where(t <= 1, near, far)

    wx, wy = weights(x - ix), weights(y - iy)
    h, w = img.shape
    out = np.zeros_like(x)
    for j in range(4):
        yy = np.clip(iy + j - 1, 0, h - 1)
        for i in range(4):
            out += wy[j] * wx[i] * img[yy, np.clip(ix + i - 1, 0, w - 1)]
    return out


def edge_point(img, p, n, reach=7.0):
    """Gradient centroid of the profile through p along unit normal n."""
    s = np.arange(-reach, reach + 1e-9, 0.25)
    xy = p[None, :] + s[:, None] * n[None, :]
    v = sample(img, xy[:, 0], xy[:, 1])
    # The signed derivative, no threshold: a threshold or |d| would clip
    # the PSF's asymmetric tail or pull the centroid to the profile's middle.
    d = np.diff(v)
    d = d * np.sign(d.sum())
    if d.sum() <= 1e-9 * np.abs(d).sum() or d.sum() <= 0:
        return None
    sm = 0.5 * (s[1:] + s[:-1])
    return p + (d * sm).sum() / d.sum() * n


def edge_corner(img, g, i, j):
    """Meet of the grid-row and grid-column edge curves through corner (i, j).
    On the grid's border the edge still runs on across the board's outer
    squares: the missing neighbour is the mirror of the other one."""
    curves = []
    rows, cols = g.shape[:2]
    for di, dj in ((1, 0), (0, 1)):
        c = g[j, i]
        lo_ok = 0 <= i - di and 0 <= j - dj
        hi_ok = i + di < cols and j + dj < rows
        a = g[j - dj, i - di] if lo_ok else 2 * c - g[j + dj, i + di]
        b = g[j + dj, i + di] if hi_ok else 2 * c - a
        t = (b - a) / np.linalg.norm(b - a)
        n = np.array([-t[1], t[0]])
        pts = []
        for p0, p1 in ((a, c), (c, b)):
            for f in np.linspace(0.25, 0.75, 11):
                e = edge_point(img, p0 + f * (p1 - p0), n)
                if e is not None:
                    pts.append(e)
        pts = np.array(pts)
        u = (pts - c) @ t
        w = (pts - c) @ n
        coef = np.polyfit(u, w, 2)
        curves.append((c, t, n, coef))
    # Solve for the point on both curves (Newton from the middle corner).
    x = g[j, i].astype(float).copy()
    for _ in range(20):
        res, jac = [], []
        for c, t, n, coef in curves:
            u = (x - c) @ t
            w = (x - c) @ n
            res.append(w - np.polyval(coef, u))
            jac.append(n - np.polyval(np.polyder(coef), u) * t)
        step = np.linalg.solve(np.array(jac), -np.array(res))
        x += step
        if np.linalg.norm(step) < 1e-6:
            break
    return x


def magnification(p, ref, pp):
    """Least-squares a (q - pp) + b of p - ref: returns a (mean of the
    diagonal), b and the RMS distance."""
    d = p - ref
    x = np.c_[ref - pp, np.ones(len(ref))]
    a = np.linalg.lstsq(x, d, rcond=None)[0]
    return 0.5 * (a[0, 0] + a[1, 1]), a[2], float(np.sqrt((d ** 2).sum(1).mean()))


def calibrate(robocal, views, ids, size):
    det = {"images": [{"file": f"view{k + 1}", "detection": {
        "image_size_px": list(size), "polarity": "dark_on_light",
        "target": {"kind": "chessboard", "cols": COLS, "rows": ROWS, "square_m": 0.03},
        "points": [{"id": int(i), "x_px": float(q[0]), "y_px": float(q[1])} for i, q in zip(idv, pts)]}}
        for k, (pts, idv) in enumerate(zip(views, ids))]}
    with tempfile.TemporaryDirectory() as tmp:
        path, out = os.path.join(tmp, "det.json"), os.path.join(tmp, "cam.json")
        with open(path, "w") as f:
            json.dump(det, f)
        subprocess.run([robocal, "intrinsics", "--detections", path, "--fix", "k3", "-o", out], check=True,
                       capture_output=True)
        r = json.load(open(out))
    k = r["camera_matrix"]
    return {"fx": k[0][0], "fy": k[1][1], "cx": k[0][2], "cy": k[1][2], "sfx": r["std"]["fx"], "rms": r["rms_px"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robocal", default=os.path.join(os.path.dirname(HERE), "target", "debug", "robocal"))
    d = dataset_dir("opencv-left-right-9x6") or "."
    ap.add_argument("--images", default=os.path.join(d, "left*.jpg"))
    ap.add_argument("--pp", default="341.6,234.3", help="principal point for the magnification")
    ap.add_argument("--render", help="a robocal render folder (truth.json) instead of --images")
    ap.add_argument("--all-corners", action="store_true",
                    help="every corner, the grid's border too (its outer edge segments run across the outer squares)")
    ap.add_argument("--calib", action="store_true",
                    help="also calibrate (robocal intrinsics --detections, k1 k2 p1 p2, k3 held) from each set's "
                         "inner corners and print fx fy cx cy")
    a = ap.parse_args()
    truth = None
    if a.render:
        truth = json.load(open(os.path.join(a.render, "truth.json")))
        images = [os.path.join(a.render, v["image"]) for v in truth["views"]]
        pp = np.array([truth["camera"]["cx"], truth["camera"]["cy"]])
        truth = {v["image"]: np.array([[p["x_px"], p["y_px"]] for p in v["points"]]) for v in truth["views"]}
    else:
        images = sorted(glob.glob(a.images))
        pp = np.array([float(v) for v in a.pp.split(",")])
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "det.json")
        subprocess.run([a.robocal, "detect", "--target", f"chessboard:{COLS}x{ROWS}:30mm", "--threads", "2",
                        "-o", out, *images], check=True, capture_output=True)
        det = {os.path.basename(e["file"]): e.get("detection") for e in json.load(open(out))["images"]}
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 50, 1e-5)
    acc, ids, size = {}, [], None
    for path in images:
        name = os.path.basename(path)
        gray = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        ok, c = cv2.findChessboardCorners(gray, (COLS, ROWS), None)
        if not ok or not det.get(name):
            continue
        sets = {f"cornerSubPix {2 * h + 1}x{2 * h + 1}": cv2.cornerSubPix(gray, c.copy(), (h, h), (-1, -1), crit)
                .reshape(-1, 2).astype(np.float64) for h in (3, 5, 7)}
        g = sets["cornerSubPix 15x15"].reshape(ROWS, COLS, 2)
        img = gray.astype(np.float64)
        inner = [(i, j) for j in range(ROWS) for i in range(COLS)] if a.all_corners else \
            [(i, j) for j in range(1, ROWS - 1) for i in range(1, COLS - 1)]
        edge = np.array([edge_corner(img, g, i, j) for i, j in inner])
        rc = np.array([[p["x_px"], p["y_px"]] for p in det[name]["points"]])
        sets["robocal"] = rc
        if truth is not None:
            sets["truth"] = truth[name]
        for k, v in sets.items():
            m = np.array([v[np.argmin(((v - q) ** 2).sum(1))] for q in edge])
            acc.setdefault(k, []).append((edge, m))
        ids.append([j * COLS + i for i, j in inner])
        size = gray.shape[::-1]
    print(f"{len(acc.get('robocal', []))} images, inner corners; reference: the edge-curve corners; pp {pp}")
    for k, v in acc.items():
        ref = np.vstack([e for e, _ in v])
        p = np.vstack([m for _, m in v])
        s, b, rms = magnification(p, ref, pp)
        print(f"  {k:22s} - edge corners: magnification {s * 1e4:+.2f}e-4, shift {b[0]:+.3f} {b[1]:+.3f} px, "
              f"rms {rms:.3f} px")
    if a.calib:
        print("calibrations from the compared corners (k1 k2 p1 p2, k3 held):")
        for k, v in [("edge corners", [(e, e) for e, _ in acc["robocal"]]), *acc.items()]:
            r = calibrate(a.robocal, [m for _, m in v], ids, size)
            print(f"  {k:22s} fx {r['fx']:.3f} fy {r['fy']:.3f} cx {r['cx']:.3f} cy {r['cy']:.3f} "
                  f"(std fx {r['sfx']:.3f}), rms {r['rms']:.4f} px")


if __name__ == "__main__":
    main()
