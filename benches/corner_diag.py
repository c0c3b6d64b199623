#!/usr/bin/env python3
"""Per-corner comparison of robocal's chessboard corners with OpenCV's on
real photos (issue 42 diagnosis): cornerSubPix 15x15 and 11x11 and
findChessboardCornersSB, per image and per corner, split by ring (outer =
on the grid's border), by distance from the image centre and by local
square size; the offsets are projected on the direction away from the
board's corner centroid ("outward", what moves the focal length) and on the
two local grid directions.

--split: which part of the difference moves the calibration. Calibrations
(`robocal intrinsics --detections`, k1 k2 p1 p2, k3 held, all views'
corners with OpenCV's order as ids) from cornerSubPix 15x15's corners,
from robocal's, and from cornerSubPix's plus one part of the difference:
its per-image affine part (a least-squares affine map of each view's
corners: the board looking larger, shifted or sheared), its global radial
part about --pp (s1 r + s3 r^3) and the rest (per corner, not affine).

Usage (crate root): python3 benches/corner_diag.py --robocal target/debug/robocal
  [--images 'DIR/left*.jpg'] [--cols 9 --rows 6] [--per-image] [--split --pp 341.586,234.259]
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


def cv_corners(gray, cols, rows, half):
    ok, c = cv2.findChessboardCorners(gray, (cols, rows), None)
    if not ok:
        return None, None
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 0.0001)
    out = {}
    for h in half:
        out[h] = cv2.cornerSubPix(gray, c.copy(), (h, h), (-1, -1), crit).reshape(-1, 2).astype(np.float64)
    return c.reshape(-1, 2).astype(np.float64), out


def split(robocal, pairs, size, pp, cols, rows):
    import corner_edges

    corner_edges.COLS, corner_edges.ROWS = cols, rows
    ids = [list(range(cols * rows))] * len(pairs)
    cv = [c for c, _ in pairs]
    affine = []
    for c, r in pairs:
        x = np.c_[c - c.mean(0), np.ones(len(c))]
        affine.append(c + x @ np.linalg.lstsq(x, r - c, rcond=None)[0])
    p = np.vstack(cv) - pp
    d = np.vstack([r for _, r in pairs]) - np.vstack(cv)
    r2 = (p ** 2).sum(1) / 1e4
    x = np.r_[np.c_[p[:, 0], p[:, 0] * r2], np.c_[p[:, 1], p[:, 1] * r2]]
    s1, s3 = np.linalg.lstsq(x, np.r_[d[:, 0], d[:, 1]], rcond=None)[0]
    radial = [c + (c - pp) * (s1 + s3 * ((c - pp) ** 2).sum(1)[:, None] / 1e4) for c in cv]
    print(f"split: radial part of robocal - cornerSubPix 15x15 about {pp}: s1 {s1:.2e}, s3 {s3:.2e} per 1e4 px^2")
    for label, views in [("cornerSubPix 15x15", cv), ("robocal", [r for _, r in pairs]),
                         ("cornerSubPix + per-image affine part", affine),
                         ("cornerSubPix + global radial part", radial),
                         ("cornerSubPix + the rest (not affine)", [r - (a_ - c) for (c, r), a_ in zip(pairs, affine)])]:
        q = corner_edges.calibrate(robocal, views, ids, size)
        print(f"  {label:38s} fx {q['fx']:.3f} (std {q['sfx']:.3f}) fy {q['fy']:.3f} cx {q['cx']:.3f} cy {q['cy']:.3f}, "
              f"rms {q['rms']:.4f} px")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robocal", default=os.path.join(os.path.dirname(HERE), "target", "debug", "robocal"))
    d = dataset_dir("opencv-left-right-9x6") or "."
    ap.add_argument("--images", default=os.path.join(d, "left*.jpg"))
    ap.add_argument("--cols", type=int, default=9)
    ap.add_argument("--rows", type=int, default=6)
    ap.add_argument("--per-image", action="store_true")
    ap.add_argument("--dump", help="write every corner's offsets to this .npy")
    ap.add_argument("--split", action="store_true", help="calibrate from the parts of the difference (above)")
    ap.add_argument("--pp", default="341.586,234.259", help="principal point for --split's radial part")
    a = ap.parse_args()
    images = sorted(glob.glob(a.images))
    if not images:
        sys.exit(f"no images match {a.images}")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "det.json")
        subprocess.run([a.robocal, "detect", "--target", f"chessboard:{a.cols}x{a.rows}:30mm", "--threads", "2",
                        "-o", out, *images], check=True, capture_output=True)
        det = json.load(open(out))
    by_name = {os.path.basename(e["file"]): e.get("detection") for e in det["images"]}
    rows_out, pairs, size = [], [], None
    for path in images:
        gray = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        coarse, sub = cv_corners(gray, a.cols, a.rows, [7, 5])
        dd = by_name.get(os.path.basename(path))
        if coarse is None or not dd:
            print(f"{os.path.basename(path)}: skipped (opencv or robocal found no board)")
            continue
        ok, sb = cv2.findChessboardCornersSB(gray, (a.cols, a.rows), cv2.CALIB_CB_ACCURACY)
        rc_all = np.array([[p["x_px"], p["y_px"]] for p in dd["points"]])
        ref = sub[7]
        rc = np.array([rc_all[np.argmin(((rc_all - q) ** 2).sum(1))] for q in ref])
        pairs.append((ref, rc))
        size = gray.shape[::-1]
        sbm = None
        if ok:
            sb = sb.reshape(-1, 2).astype(np.float64)
            sbm = np.array([sb[np.argmin(((sb - q) ** 2).sum(1))] for q in ref])
        centroid = ref.mean(0)
        g = ref.reshape(a.rows, a.cols, 2)
        for k, q in enumerate(ref):
            i, j = k % a.cols, k // a.cols
            # Local grid directions and square size from the neighbours.
            ex = g[j, min(i + 1, a.cols - 1)] - g[j, max(i - 1, 0)]
            ey = g[min(j + 1, a.rows - 1), i] - g[max(j - 1, 0), i]
            ex_n = ex / np.hypot(*ex)
            ey_n = ey / np.hypot(*ey)
            step = 0.5 * (np.hypot(*ex) / (min(i + 1, a.cols - 1) - max(i - 1, 0))
                          + np.hypot(*ey) / (min(j + 1, a.rows - 1) - max(j - 1, 0)))
            u = q - centroid
            u = u / max(np.hypot(*u), 1e-9)
            outer = i in (0, a.cols - 1) or j in (0, a.rows - 1)
            offs = {"rc": rc[k] - q, "cv11": sub[5][k] - q}
            if sbm is not None:
                offs["sb"] = sbm[k] - q
            # Corner-local outward sign: towards the board's outside along
            # each grid direction (for the outer ring).
            rows_out.append({
                "img": os.path.basename(path), "i": i, "j": j, "x": q[0], "y": q[1], "outer": outer,
                "step": step, "r": np.hypot(*(q - np.array([319.5, 239.5]))),
                **{f"{n}_out": float(o @ u) for n, o in offs.items()},
                **{f"{n}_ex": float(o @ ex_n) for n, o in offs.items()},
                **{f"{n}_ey": float(o @ ey_n) for n, o in offs.items()},
                **{f"{n}_d": float(np.hypot(*o)) for n, o in offs.items()},
                "rc_dx": offs["rc"][0], "rc_dy": offs["rc"][1],
            })
    import collections
    if a.dump:
        np.save(a.dump, rows_out, allow_pickle=True)

    def summ(sel, label):
        if not sel:
            return
        line = f"{label:28s} n {len(sel):4d}"
        for n in ["rc", "cv11", "sb"]:
            v = [r[f"{n}_out"] for r in sel if f"{n}_out" in r]
            dd = [r[f"{n}_d"] for r in sel if f"{n}_d" in r]
            if v:
                line += f" | {n}: out {np.mean(v):+.3f} med|d| {np.median(dd):.3f}"
        print(line)

    print("offsets from cornerSubPix 15x15 (px): 'out' = mean offset away from the board's corner centroid")
    summ(rows_out, "all")
    summ([r for r in rows_out if r["outer"]], "outer ring")
    summ([r for r in rows_out if not r["outer"]], "inner")
    for lo, hi in [(0, 25), (25, 30), (30, 35), (35, 40), (40, 60)]:
        summ([r for r in rows_out if lo <= r["step"] < hi], f"square {lo}-{hi} px")
    for lo, hi in [(0, 100), (100, 200), (200, 300), (300, 800)]:
        summ([r for r in rows_out if lo <= r["r"] < hi], f"radius {lo}-{hi} px")
    if a.split:
        split(a.robocal, pairs, size, np.array([float(v) for v in a.pp.split(",")]), a.cols, a.rows)
    if a.per_image:
        by = collections.defaultdict(list)
        for r in rows_out:
            by[r["img"]].append(r)
        for k, v in by.items():
            summ(v, k)


if __name__ == "__main__":
    main()
